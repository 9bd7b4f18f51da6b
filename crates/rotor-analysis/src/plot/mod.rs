//! A small, dependency-free SVG line-plot writer (pure Rust, no fonts needed: text is left to
//! the viewer's sans-serif).

#![warn(missing_docs)]

use std::fmt::Write;

pub mod overlay;

/// One polyline with a label and a style. A non-finite point lifts the pen (a gap).
pub struct Series<'a> {
    /// Legend text; an empty label keeps the series out of the legend.
    pub label: &'a str,
    /// SVG colour of the line and markers, e.g. `"#e66101"`.
    pub color: &'a str,
    /// SVG `stroke-dasharray`, e.g. `"6 4"`; `None` draws a solid line.
    pub dash: Option<&'a str>,
    /// Stroke width; `0.0` draws no line (markers only).
    pub width: f64,
    /// Draws a marker of this radius at every point (its shape: `shape`).
    pub marker: Option<f64>,
    /// The markers' shape: a second channel beside the colour, for greyscale print and
    /// colour-blind readers.
    pub shape: Shape,
    /// Markers drawn open (outline only, white inside): the figures use them for points that
    /// fail a gate, filled ones for points that pass.
    pub hollow: bool,
    /// The points `(x, y)` in data coordinates, in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// A marker's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shape {
    /// A circle.
    #[default]
    Circle,
    /// A square standing on a side.
    Square,
    /// A triangle pointing up.
    TriangleUp,
    /// A square standing on a corner.
    Diamond,
    /// A triangle pointing down.
    TriangleDown,
}

impl Shape {
    /// Every shape, in the order the figures hand them out.
    pub const ALL: [Shape; 5] = [
        Shape::Circle,
        Shape::Square,
        Shape::TriangleUp,
        Shape::Diamond,
        Shape::TriangleDown,
    ];
}

impl Default for Series<'_> {
    /// An unlabelled black solid line of width 1.5 without markers or points.
    fn default() -> Self {
        Self {
            label: "",
            color: "#000000",
            dash: None,
            width: 1.5,
            marker: None,
            shape: Shape::Circle,
            hollow: false,
            points: Vec::new(),
        }
    }
}

impl<'a> Series<'a> {
    /// A solid line of width 1.5.
    pub fn line(label: &'a str, color: &'a str, points: Vec<(f64, f64)>) -> Self {
        Self {
            label,
            color,
            points,
            ..Self::default()
        }
    }
}

/// A text label placed at a data point, drawn with a small cross.
pub struct Label {
    /// Abscissa of the point, in data coordinates.
    pub x: f64,
    /// Ordinate of the point, in data coordinates.
    pub y: f64,
    /// The label (escaped for SVG when written).
    pub text: String,
}

/// A region's name, centred in one of its vertical bands: `places` holds `(x, y_lo, y_hi)`
/// in order of preference, and the name goes to the first where it fits in 12 px text, covers
/// no line of [`Panel::clear_x`] and no name placed before (then the first that covers no
/// name, then the first). It is on a white halo, legible where it covers a curve; smaller
/// where the band is narrower than a line of text; left out where every band is thinner than
/// a pixel (it cannot be seen).
pub struct Band {
    /// The region's name.
    pub text: String,
    /// Candidate places `(x, y_lo, y_hi)` in data coordinates, best first: a vertical band at
    /// `x` from `y_lo` to `y_hi`.
    pub places: Vec<(f64, f64, f64)>,
}

/// A curve's name at one of its ends, in the curve's colour: in the right margin, joined to
/// the end by a thin line, if `margin` (the curve reaches the right edge), else beside it.
pub struct EndLabel {
    /// Abscissa of the curve's end, in data coordinates.
    pub x: f64,
    /// Ordinate of the curve's end, in data coordinates.
    pub y: f64,
    /// The curve's name.
    pub text: String,
    /// SVG colour, the curve's.
    pub color: String,
    /// Whether the name goes to the right margin (the curve reaches the right edge) rather
    /// than beside the end.
    pub margin: bool,
}

/// A panel: title, axis labels, series, and how each axis is scaled.
pub struct Panel<'a> {
    /// Title above the panel.
    pub title: String,
    /// Label of the x axis, below it (with its unit, as the caller writes it).
    pub x_label: &'a str,
    /// Label of the y axis, left of it and turned upright.
    pub y_label: &'a str,
    /// The curves, drawn in order (the last on top), with a legend row for the labelled ones.
    pub series: Vec<Series<'a>>,
    /// Labelled points (special points of a diagram, say).
    pub labels: Vec<Label>,
    /// Names of regions, each in its band.
    pub bands: Vec<Band>,
    /// Names of curves, at their ends.
    pub ends: Vec<EndLabel>,
    /// Vertical lines (at these x) that the names of regions are moved off.
    pub clear_x: Vec<f64>,
    /// Logarithmic axes: points with a non-positive coordinate are skipped.
    pub x_log: bool,
    /// Logarithmic y axis (see `x_log`).
    pub y_log: bool,
    /// The x axis's ticks at these data values, labelled as numbers, instead of the automatic
    /// ones (round steps, or decades on a log axis): a log axis over less than two decades,
    /// say, whose decades alone leave it with one tick.
    pub x_ticks: Vec<f64>,
}

impl<'a> Panel<'a> {
    /// A linear panel without labels.
    pub fn new(
        title: impl Into<String>,
        x_label: &'a str,
        y_label: &'a str,
        series: Vec<Series<'a>>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label,
            y_label,
            series,
            labels: Vec::new(),
            bands: Vec::new(),
            ends: Vec::new(),
            clear_x: Vec::new(),
            x_log: false,
            y_log: false,
            x_ticks: Vec::new(),
        }
    }
}

/// Maps a data coordinate to the axis coordinate (log10 on a log axis; NaN if not drawable).
fn axis(v: f64, log: bool) -> f64 {
    if !log {
        v
    } else if v > 0.0 {
        v.log10()
    } else {
        f64::NAN
    }
}

/// Ticks on a log axis: every decade in `[lo, hi]` (given as log10 values).
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut v = Vec::new();
    let mut e = lo.ceil();
    let step = ((hi - lo) / 8.0).ceil().max(1.0);
    while e <= hi + 1e-9 {
        v.push(e);
        e += step;
    }
    v
}

fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut v = Vec::new();
    let mut t = (lo / step).ceil() * step;
    while t <= hi + 1e-9 * span {
        v.push(if t.abs() < 1e-12 * span { 0.0 } else { t });
        t += step;
    }
    v
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Text with `_{…}` marking a subscript (`ω_{l}`), escaped for SVG, the subscripts as
/// lowered, smaller `tspan`s.
fn rich(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(k) = rest.find("_{") {
        let Some(close) = rest[k..].find('}') else {
            break;
        };
        out.push_str(&esc(&rest[..k]));
        out.push_str(r#"<tspan baseline-shift="sub" font-size="75%">"#);
        out.push_str(&esc(&rest[k + 2..k + close]));
        out.push_str("</tspan>");
        rest = &rest[k + close + 1..];
    }
    out.push_str(&esc(rest));
    out
}

/// The number of characters `s` shows (markup of [`rich`] aside), for width estimates.
fn shown_chars(s: &str) -> usize {
    s.chars().count() - 3 * s.matches("_{").count()
}

/// Renders panels stacked vertically into one SVG document.
pub fn render(panels: &[Panel], width: f64, panel_height: f64) -> String {
    let heights = vec![panel_height; panels.len()];
    render_rows(panels, width, &heights)
}

/// `v` to 9 significant digits, `1.25e-3` style: far finer than any figure shows, and
/// coarse enough that the last bits of a computation do not move the committed file.
fn sig9(v: f64) -> String {
    let s = format!("{v:.8e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    let m = if m.contains('.') {
        m.trim_end_matches('0').trim_end_matches('.')
    } else {
        m
    };
    format!("{m}e{e}")
}

/// A figure's data as CSV, for a reader who redraws it (matplotlib, pgfplots): one row per
/// drawn point, `panel,series,x,y` in long form (the panel's title, the series' label, or
/// `series <k>` for an unlabelled one), then the labelled points as series `label: <text>`;
/// numbers to 9 significant digits.
/// A point that lifts the pen is left out; quotes in names are doubled.
pub fn data_csv(panels: &[Panel]) -> String {
    let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    let mut out = String::from("panel,series,x,y\n");
    for p in panels {
        for (k, ser) in p.series.iter().enumerate() {
            let name = if ser.label.is_empty() {
                format!("series {k}")
            } else {
                ser.label.to_owned()
            };
            for &(x, y) in ser
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
            {
                let _ = writeln!(out, "{},{},{},{}", q(&p.title), q(&name), sig9(x), sig9(y));
            }
        }
        for lab in &p.labels {
            let _ = writeln!(
                out,
                "{},{},{},{}",
                q(&p.title),
                q(&format!("label: {}", lab.text)),
                sig9(lab.x),
                sig9(lab.y)
            );
        }
    }
    out
}

/// [`render`] with a height per panel (an error panel under its overlay, say).
pub fn render_rows(panels: &[Panel], width: f64, heights: &[f64]) -> String {
    let height: f64 = heights.iter().sum();
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let mut oy = 0.0;
    for (p, &panel_height) in panels.iter().zip(heights) {
        let top = oy;
        oy += panel_height;
        let Some(f) = Frame::fit(p, top, width, panel_height) else {
            continue;
        };
        write_axes(&mut s, p, &f);
        let legend = write_series(&mut s, &p.series, &f);
        write_legend(&mut s, &legend, &f);
        write_labels(&mut s, &p.labels, &f);
        let clear: Vec<f64> = p
            .clear_x
            .iter()
            .map(|&x| f.sx(x))
            .filter(|c| c.is_finite())
            .collect();
        write_bands(
            &mut s,
            &p.bands,
            &clear,
            (f.l, f.r),
            |x| f.sx(x),
            |y| f.sy(y),
        );
        write_ends(&mut s, &p.ends, &f);
    }
    s.push_str("</svg>\n");
    s
}

/// A panel's plot box in pixels and the ranges of its axes, which map data to pixels.
struct Frame {
    /// Top of the panel \[px\] (its title sits 20 px below).
    oy: f64,
    /// Width of the document \[px\]: the legend wraps before its right edge.
    width: f64,
    /// Centre of the turned y axis label \[px\], left of the widest tick label.
    y_label_x: f64,
    /// Left edge of the plot box \[px\].
    l: f64,
    /// Right edge of the plot box \[px\] (left of the margin for curve names).
    r: f64,
    /// Top edge of the plot box \[px\].
    t: f64,
    /// Bottom edge of the plot box \[px\].
    b: f64,
    /// The x axis's range, in axis coordinates (log10 on a log axis).
    x0: f64,
    /// Upper end of the x axis's range.
    x1: f64,
    /// The y axis's range, in axis coordinates, padded by 5 % each way.
    y0: f64,
    /// Upper end of the y axis's range.
    y1: f64,
    /// Whether the x axis is logarithmic.
    x_log: bool,
    /// Whether the y axis is logarithmic.
    y_log: bool,
    /// The x ticks asked for, in data coordinates (empty: automatic).
    x_ticks: Vec<f64>,
}

impl Frame {
    /// The frame of panel `p` at height `oy` in a document `width` wide: the axes span every
    /// drawable point of its series, labels, curve ends and bands (a flat range widened by
    /// ±0.5, the y range padded by 5 %), and the box leaves room for the legend above and the
    /// right margin's curve names. `None` if the panel has no drawable point.
    fn fit(p: &Panel, oy: f64, width: f64, panel_height: f64) -> Option<Frame> {
        let pts = p
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .chain(p.labels.iter().map(|l| (l.x, l.y)))
            .chain(p.ends.iter().map(|e| (e.x, e.y)))
            .chain(
                p.bands
                    .iter()
                    .flat_map(|n| n.places.iter().flat_map(|q| [(q.0, q.1), (q.0, q.2)])),
            )
            .map(|(x, y)| (axis(x, p.x_log), axis(y, p.y_log)));
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (x, y) in pts {
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if !x0.is_finite() {
            return None;
        }
        if y1 - y0 < 1e-9 {
            y0 -= 0.5;
            y1 += 0.5;
        }
        let pad = 0.05 * (y1 - y0);
        let (y0, y1) = (y0 - pad, y1 + pad);
        if x1 - x0 < 1e-12 {
            x0 -= 0.5;
            x1 += 0.5;
        }
        // Markers at the ends of the x range would be cut in half by the frame: pad by 3 %.
        if p.series.iter().any(|s| s.marker.is_some()) {
            let pad = 0.03 * (x1 - x0);
            x0 -= pad;
            x1 += pad;
        }
        // The plot box starts right of the widest y tick label, with the axis label left of it.
        let widest = tick_labels(y0, y1, p.y_log, 6)
            .iter()
            .map(|(_, t)| t.chars().count())
            .max()
            .unwrap_or(0) as f64;
        let l = (36.0 + CHAR * widest).max(70.0);
        let y_label_x = l - 17.0 - CHAR * widest;
        let rows = legend_layout(&p.series, l, width - 10.0)
            .last()
            .map_or(0, |e| e.1 + 1);
        let top = if rows > 0 {
            50.0 + LEGEND_ROW * (rows - 1) as f64
        } else {
            30.0
        };
        let (t, b) = (oy + top, oy + panel_height - 45.0);
        // Curve names whose curve reaches the right edge go into the margin.
        let margin_width = p
            .ends
            .iter()
            .filter(|e| e.margin)
            .map(|m| 12.0 + SMALL_CHAR * m.text.chars().count() as f64)
            .fold(0.0, f64::max);
        Some(Frame {
            oy,
            width,
            y_label_x,
            l,
            r: width - 20.0 - margin_width,
            t,
            b,
            x0,
            x1,
            y0,
            y1,
            x_log: p.x_log,
            y_log: p.y_log,
            x_ticks: p.x_ticks.clone(),
        })
    }

    /// Axis coordinate to pixels: `l + (x − x0) / (x1 − x0) · (r − l)`.
    fn ax(&self, x: f64) -> f64 {
        self.l + (x - self.x0) / (self.x1 - self.x0) * (self.r - self.l)
    }

    /// Axis coordinate to pixels: `b − (y − y0) / (y1 − y0) · (b − t)` (upward).
    fn ay(&self, y: f64) -> f64 {
        self.b - (y - self.y0) / (self.y1 - self.y0) * (self.b - self.t)
    }

    /// Data abscissa to pixels (NaN where a log axis cannot draw it).
    fn sx(&self, x: f64) -> f64 {
        self.ax(axis(x, self.x_log))
    }

    /// Data ordinate to pixels (NaN where a log axis cannot draw it).
    fn sy(&self, y: f64) -> f64 {
        self.ay(axis(y, self.y_log))
    }
}

/// Writes panel `p`'s title, plot box, ticks with their grid lines, and axis labels.
fn write_axes(s: &mut String, p: &Panel, f: &Frame) {
    let (l, r, t, b) = (f.l, f.r, f.t, f.b);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" font-size="14">{}</text>"#,
        (l + r) / 2.0,
        f.oy + 20.0,
        rich(&p.title)
    );
    let _ = writeln!(
        s,
        r#"<rect x="{l}" y="{t}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        r - l,
        b - t
    );
    write_ticks(s, f);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (l + r) / 2.0,
        b + 35.0,
        rich(p.x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" transform="rotate(-90 {} {})">{}</text>"#,
        f.y_label_x,
        (t + b) / 2.0,
        f.y_label_x,
        (t + b) / 2.0,
        rich(p.y_label)
    );
}

/// Writes the ticks of both axes, each with its grid line across the box and its value:
/// about 8 round steps in x and 6 in y on a linear axis, decades on a log axis.
fn write_ticks(s: &mut String, f: &Frame) {
    let (l, r, t, b) = (f.l, f.r, f.t, f.b);
    let x_ticks = if f.x_ticks.is_empty() {
        tick_labels(f.x0, f.x1, f.x_log, 8)
    } else {
        f.x_ticks
            .iter()
            .map(|&v| (axis(v, f.x_log), fmt_tick(v)))
            .filter(|(a, _)| a.is_finite())
            .collect()
    };
    for (tx, label) in x_ticks {
        let x = f.ax(tx);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{b}" x2="{x:.1}" y2="{t}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">{label}</text>"##,
            b + 15.0,
        );
    }
    for (ty, label) in tick_labels(f.y0, f.y1, f.y_log, 6) {
        let y = f.ay(ty);
        let _ = writeln!(
            s,
            r##"<line x1="{l}" y1="{y:.1}" x2="{r}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{label}</text>"##,
            l - 5.0,
            y + 4.0,
        );
    }
}

/// An axis's ticks over `[lo, hi]` (axis coordinates) with their labels: about `n` round
/// steps on a linear axis, decades on a log axis.
fn tick_labels(lo: f64, hi: f64, log: bool, n: usize) -> Vec<(f64, String)> {
    if log {
        log_ticks(lo, hi)
            .into_iter()
            .map(|v| (v, fmt_decade(v)))
            .collect()
    } else {
        nice_ticks(lo, hi, n)
            .into_iter()
            .map(|v| (v, fmt_tick(v)))
            .collect()
    }
}

/// Writes each series as a path (a non-drawable point lifts the pen) with its markers, and
/// returns the labelled series with their `stroke-dasharray` attribute, for the legend.
fn write_series<'s, 'a>(
    s: &mut String,
    series: &'s [Series<'a>],
    f: &Frame,
) -> Vec<(&'s Series<'a>, String)> {
    let mut legend = Vec::new();
    for ser in series {
        let mut d = String::new();
        let mut pen_up = true;
        let pixels: Vec<(f64, f64)> = ser
            .points
            .iter()
            .map(|&(x, y)| (f.sx(x), f.sy(y)))
            .collect();
        let drawn = if ser.marker.is_none() {
            thin(&pixels)
        } else {
            pixels
        };
        for (px, py) in drawn {
            if !(px.is_finite() && py.is_finite()) {
                pen_up = true;
                continue;
            }
            let _ = write!(d, "{}{px:.2},{py:.2} ", if pen_up { "M" } else { "L" });
            pen_up = false;
            if let Some(radius) = ser.marker {
                write_marker(s, ser, px, py, radius);
            }
        }
        let dash = ser
            .dash
            .map(|d| format!(r#" stroke-dasharray="{d}""#))
            .unwrap_or_default();
        if ser.width > 0.0 && !d.is_empty() {
            let _ = writeln!(
                s,
                r#"<path d="{d}" fill="none" stroke="{}" stroke-width="{}"{dash}/>"#,
                ser.color, ser.width
            );
        }
        if !ser.label.is_empty() {
            legend.push((ser, dash));
        }
    }
    legend
}

/// A line's points in pixels, thinned to what a pixel column can show: within each run of
/// drawable points, the points of one pixel column (x rounded down) become its first, lowest,
/// highest and last, in their order. The drawn line is the same to a pixel, and a 200 s
/// trace on a 0.01 s grid keeps ~4 points per column instead of ~25. A non-drawable point is
/// kept (it lifts the pen).
fn thin(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(pts.len().min(4096));
    let mut i = 0;
    while i < pts.len() {
        let (px, py) = pts[i];
        if !(px.is_finite() && py.is_finite()) {
            out.push(pts[i]);
            i += 1;
            continue;
        }
        let col = px.floor();
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while j < pts.len()
            && pts[j].0.is_finite()
            && pts[j].1.is_finite()
            && pts[j].0.floor() == col
        {
            if pts[j].1 < pts[lo].1 {
                lo = j;
            }
            if pts[j].1 > pts[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let mut keep = vec![i, lo, hi, j - 1];
        keep.sort_unstable();
        keep.dedup();
        out.extend(keep.into_iter().map(|k| pts[k]));
        i = j;
    }
    out
}

/// Height of a legend row \[px\].
const LEGEND_ROW: f64 = 16.0;

/// Where each labelled series' legend entry goes, `(x, row)` in series order: entries left to
/// right from `left`, a new row where the next would pass `right` (each entry a 30 px stretch
/// of line, its label at ~[`CHAR`] px a character, and an 18 px gap).
fn legend_layout(series: &[Series], left: f64, right: f64) -> Vec<(f64, usize)> {
    let mut out = Vec::new();
    let (mut x, mut row) = (left, 0);
    for ser in series.iter().filter(|s| !s.label.is_empty()) {
        let w = 35.0 + CHAR * shown_chars(ser.label) as f64;
        if x > left && x + w > right {
            x = left;
            row += 1;
        }
        out.push((x, row));
        x += w + 18.0;
    }
    out
}

/// Writes one marker of `ser`'s shape, colour and fill, centred at `(cx, cy)`.
fn write_marker(s: &mut String, ser: &Series, cx: f64, cy: f64, r: f64) {
    let fill = if ser.hollow { "white" } else { ser.color };
    let paint = format!(
        r#"fill="{fill}" stroke="{}" stroke-width="{}""#,
        ser.color,
        if ser.hollow { 1.3 } else { 0.0 }
    );
    let poly = |pts: &[(f64, f64)]| {
        pts.iter()
            .map(|(dx, dy)| format!("{:.2},{:.2}", cx + dx * r, cy + dy * r))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let _ = match ser.shape {
        Shape::Circle => writeln!(s, r#"<circle cx="{cx:.2}" cy="{cy:.2}" r="{r}" {paint}/>"#),
        Shape::Square => writeln!(
            s,
            r#"<polygon points="{}" {paint}/>"#,
            poly(&[(-0.9, -0.9), (0.9, -0.9), (0.9, 0.9), (-0.9, 0.9)])
        ),
        Shape::Diamond => writeln!(
            s,
            r#"<polygon points="{}" {paint}/>"#,
            poly(&[(0.0, -1.25), (1.25, 0.0), (0.0, 1.25), (-1.25, 0.0)])
        ),
        Shape::TriangleUp => writeln!(
            s,
            r#"<polygon points="{}" {paint}/>"#,
            poly(&[(0.0, -1.3), (1.15, 0.75), (-1.15, 0.75)])
        ),
        Shape::TriangleDown => writeln!(
            s,
            r#"<polygon points="{}" {paint}/>"#,
            poly(&[(0.0, 1.3), (1.15, -0.75), (-1.15, -0.75)])
        ),
    };
}

/// Writes the legend between the title and the plot box, so it never hides data: rows of
/// entries ([`legend_layout`]) that stay inside the document, each a 30 px stretch of its
/// line (and its marker) and its label.
fn write_legend(s: &mut String, legend: &[(&Series, String)], f: &Frame) {
    let series: Vec<&Series> = legend.iter().map(|(ser, _)| *ser).collect();
    let owned: Vec<Series> = series
        .iter()
        .map(|ser| Series {
            label: ser.label,
            ..Series::default()
        })
        .collect();
    let places = legend_layout(&owned, f.l, f.width - 10.0);
    for ((ser, dash), (lx, row)) in legend.iter().zip(places) {
        let ly = f.oy + 36.0 + LEGEND_ROW * row as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="{}"{dash}/><text x="{}" y="{}">{}</text>"#,
            lx + 30.0,
            ser.color,
            ser.width.max(1.5),
            lx + 35.0,
            ly + 4.0,
            rich(ser.label)
        );
        if let Some(radius) = ser.marker {
            write_marker(s, ser, lx + 15.0, ly, radius);
        }
    }
}

/// Writes each drawable labelled point as a small cross with its text on a white halo (a
/// curve through the text does not strike it through). The text goes to the first place,
/// in order of preference, that overlaps no label placed before and stays inside the plot
/// box: above right, below right, above left, below left, then further up or down; else the
/// first.
fn write_labels(s: &mut String, labels: &[Label], f: &Frame) {
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for lab in labels {
        let (px, py) = (f.sx(lab.x), f.sy(lab.y));
        if !(px.is_finite() && py.is_finite()) {
            continue;
        }
        let w = SMALL_CHAR * lab.text.chars().count() as f64;
        // (x of the text's start, baseline) relative to the point.
        let tries = [
            (6.0, -6.0),
            (6.0, 15.0),
            (-6.0 - w, -6.0),
            (-6.0 - w, 15.0),
            (6.0, -20.0),
            (6.0, 29.0),
            (-6.0 - w, -20.0),
            (-6.0 - w, 29.0),
        ];
        let boxed = |(dx, dy): (f64, f64)| [px + dx, px + dx + w, py + dy - 10.0, py + dy + 3.0];
        let free = |b: &[f64; 4]| {
            b[0] >= f.l
                && b[1] <= f.width - 2.0
                && b[2] >= f.t
                && b[3] <= f.b
                && !placed
                    .iter()
                    .any(|q| b[0] < q[1] && q[0] < b[1] && b[2] < q[3] && q[2] < b[3])
        };
        let (dx, dy) = tries
            .iter()
            .copied()
            .find(|&t| free(&boxed(t)))
            .unwrap_or(tries[0]);
        placed.push(boxed((dx, dy)));
        let _ = writeln!(
            s,
            r#"<path d="M{:.2},{:.2} L{:.2},{:.2} M{:.2},{:.2} L{:.2},{:.2}" stroke="black" stroke-width="1.5"/><text x="{:.2}" y="{:.2}" font-size="11" stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke">{}</text>"#,
            px - 4.0,
            py - 4.0,
            px + 4.0,
            py + 4.0,
            px - 4.0,
            py + 4.0,
            px + 4.0,
            py - 4.0,
            px + dx,
            py + dy,
            esc(&lab.text)
        );
    }
}

/// Writes the curves' names (see [`EndLabel`]): beside the end, or in the right margin on
/// rows [`spread`] a line apart, each joined to its curve's end by a thin line.
fn write_ends(s: &mut String, ends: &[EndLabel], f: &Frame) {
    for e in ends.iter().filter(|e| !e.margin) {
        let (px, py) = (f.sx(e.x), f.sy(e.y));
        if px.is_finite() && py.is_finite() {
            let _ = writeln!(
                s,
                r#"<text x="{:.2}" y="{:.2}" font-size="11" fill="{}">{}</text>"#,
                px + 4.0,
                py - 4.0,
                e.color,
                esc(&e.text)
            );
        }
    }
    let margin: Vec<&EndLabel> = ends.iter().filter(|e| e.margin).collect();
    let anchors: Vec<(f64, f64)> = margin.iter().map(|m| (f.sx(m.x), f.sy(m.y))).collect();
    let rows = spread(&anchors.iter().map(|a| a.1).collect::<Vec<_>>(), f.t, f.b);
    for ((m, (px, py)), ly) in margin.iter().zip(anchors).zip(rows) {
        if !(px.is_finite() && py.is_finite()) {
            continue;
        }
        let _ = writeln!(
            s,
            r#"<path d="M{px:.2},{py:.2} L{:.2},{ly:.2}" fill="none" stroke="{}" stroke-width="0.6"/><text x="{:.2}" y="{:.2}" font-size="11" fill="{}">{}</text>"#,
            f.r + 6.0,
            m.color,
            f.r + 8.0,
            ly + 4.0,
            m.color,
            esc(&m.text)
        );
    }
}

/// Writes the names of regions (see [`Band`]) into the box from `l` to `r` in x, keeping
/// clear of the vertical lines at pixels `clear`; `sx`, `sy` map data to pixels.
fn write_bands(
    s: &mut String,
    bands: &[Band],
    clear: &[f64],
    (l, r): (f64, f64),
    sx: impl Fn(f64) -> f64,
    sy: impl Fn(f64) -> f64,
) {
    // Boxes [x0, x1, y0, y1] of the region names placed so far.
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for band in bands {
        // Each visible place: (x, text baseline, font size, text box).
        let chars = band.text.chars().count() as f64;
        let tries: Vec<(f64, f64, f64, [f64; 4])> = band
            .places
            .iter()
            .filter_map(|&(x, y_lo, y_hi)| {
                let (lo, hi, px) = (sy(y_lo), sy(y_hi), sx(x));
                if !((lo - hi).is_finite() && px.is_finite()) || lo - hi < 1.0 {
                    return None;
                }
                // A smaller font where a line of text does not fit the band.
                let size = if lo - hi >= LINE + 3.0 { 12.0 } else { 10.0 };
                let half = 0.5 * size / 12.0 * CHAR * chars;
                let px = px.clamp(l + half + 3.0, (r - half - 3.0).max(l + half + 3.0));
                let py = 0.5 * (lo + hi) + 0.35 * size;
                Some((
                    px,
                    py,
                    size,
                    [px - half, px + half, py - size, py + 0.3 * size],
                ))
            })
            .collect();
        let covers_line = |b: &[f64; 4]| clear.iter().any(|&c| b[0] - 4.0 < c && c < b[1] + 4.0);
        let covers_name = |b: &[f64; 4]| {
            placed
                .iter()
                .any(|q| b[0] < q[1] && q[0] < b[1] && b[2] < q[3] && q[2] < b[3])
        };
        let pick = tries
            .iter()
            .find(|t| t.2 == 12.0 && !covers_line(&t.3) && !covers_name(&t.3))
            .or_else(|| {
                tries
                    .iter()
                    .find(|t| !covers_line(&t.3) && !covers_name(&t.3))
            })
            .or_else(|| tries.iter().find(|t| !covers_name(&t.3)))
            .or(tries.first());
        let Some(&(px, py, size, bx)) = pick else {
            continue;
        };
        placed.push(bx);
        let _ = writeln!(
            s,
            r#"<text x="{px:.2}" y="{py:.2}" text-anchor="middle" font-size="{size}" fill="{NOTE_COLOR}" stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke">{}</text>"#,
            esc(&band.text)
        );
    }
}

/// Height of a line of the 11 px text in the margin, and the widths of a character of the
/// 12 px and 11 px sans-serif (estimates: the viewer picks the font).
const LINE: f64 = 12.0;
const CHAR: f64 = 6.7;
const SMALL_CHAR: f64 = 6.2;
/// Grey of the region names.
const NOTE_COLOR: &str = "#555";

/// Rows for margin labels that want to sit level with `want` (pixels, any order): each as
/// near its wish as a line height between neighbours allows, all within `[top, bottom]` if
/// they fit there. Returned in the order of `want`; a non-finite wish keeps its place.
fn spread(want: &[f64], top: f64, bottom: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..want.len()).filter(|&i| want[i].is_finite()).collect();
    order.sort_by(|&a, &b| want[a].total_cmp(&want[b]));
    let mut y: Vec<f64> = order.iter().map(|&i| want[i]).collect();
    // Down from the top, then back up from the bottom: no two rows closer than a line.
    let mut floor = top + LINE / 2.0;
    for v in y.iter_mut() {
        *v = v.max(floor);
        floor = *v + LINE;
    }
    let mut ceiling = bottom;
    for v in y.iter_mut().rev() {
        *v = v.min(ceiling);
        ceiling = *v - LINE;
    }
    let mut out = want.to_vec();
    for (k, &i) in order.iter().enumerate() {
        out[i] = y[k];
    }
    out
}

/// Labels closer than `frac` of the spans `(span_x, span_y)` in both coordinates become one,
/// their texts joined by " / ", at the first one's x and the highest y of the group.
pub(crate) fn merge_close(labels: Vec<Label>, span_x: f64, span_y: f64, frac: f64) -> Vec<Label> {
    let mut out: Vec<Label> = Vec::new();
    for lab in labels {
        let near = |c: &&mut Label| {
            ((c.x - lab.x) / span_x).abs() < frac && ((c.y - lab.y) / span_y).abs() < frac
        };
        match out.iter_mut().find(near) {
            Some(c) => {
                c.text.push_str(" / ");
                c.text.push_str(&lab.text);
                c.y = c.y.max(lab.y);
            }
            None => out.push(lab),
        }
    }
    out
}

fn fmt_tick(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// `1e-3` style label for a decade exponent.
fn fmt_decade(e: f64) -> String {
    format!("1e{}", e.round() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_cover_range_with_round_steps() {
        assert_eq!(
            nice_ticks(0.0, 10.0, 5),
            vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
        );
        let t = nice_ticks(-0.3, 1.7, 4);
        assert_eq!(t, vec![0.0, 0.5, 1.0, 1.5]);
    }

    #[test]
    fn render_is_well_formed() {
        let svg = render(
            &[Panel::new(
                "a < b",
                "t [s]",
                "w",
                vec![Series::line(
                    "x",
                    "red",
                    vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
                )],
            )],
            600.0,
            300.0,
        );
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a &lt; b"));
        assert!(!svg.contains("NaN"));
    }

    /// Margin rows keep a line between neighbours, stay in the box when they fit, and move
    /// no label that has room.
    #[test]
    fn margin_rows_are_spread_a_line_apart() {
        let rows = spread(&[100.0, 101.0, 300.0, 99.0], 50.0, 400.0);
        assert_eq!(rows[2], 300.0);
        let mut near = [rows[0], rows[1], rows[3]];
        near.sort_by(f64::total_cmp);
        assert!(near[1] - near[0] >= LINE - 1e-9 && near[2] - near[1] >= LINE - 1e-9);
        // The lowest wish is the top row: order is kept.
        assert!(rows[3] < rows[0] && rows[0] < rows[1]);
        // Crowded at the bottom edge: pushed up, none below it.
        let rows = spread(&[399.0, 399.5, 400.0], 50.0, 400.0);
        assert!(rows.iter().all(|&y| y <= 400.0) && rows[0] <= 400.0 - 2.0 * LINE + 1e-9);
    }

    #[test]
    fn close_labels_merge_and_far_ones_do_not() {
        let lab = |x: f64, y: f64, t: &str| Label {
            x,
            y,
            text: t.into(),
        };
        let out = merge_close(
            vec![
                lab(0.0, 0.0, "a"),
                lab(0.01, 0.015, "b"),
                lab(0.5, 0.0, "c"),
            ],
            1.0,
            1.0,
            0.02,
        );
        assert_eq!(out.len(), 2);
        assert_eq!((out[0].text.as_str(), out[0].y), ("a / b", 0.015));
        assert_eq!(out[1].text, "c");
    }

    /// A region's name goes to its first band that keeps clear of the marked lines and of
    /// names already placed; a band thinner than a pixel is not written.
    #[test]
    fn region_names_avoid_lines_and_each_other() {
        let mut panel = Panel::new(
            "p",
            "x",
            "y",
            vec![Series::line("", "black", vec![(0.0, 0.0), (10.0, 10.0)])],
        );
        panel.clear_x.push(5.0);
        let band = |text: &str, places: Vec<(f64, f64, f64)>| Band {
            text: text.into(),
            places,
        };
        panel.bands = vec![
            // Its first place is on the line x = 5; the second is free.
            band("first", vec![(5.0, 4.0, 6.0), (1.0, 4.0, 6.0)]),
            // Its only free place is where "first" went; it takes the other one.
            band("second", vec![(1.0, 4.0, 6.0), (9.0, 4.0, 6.0)]),
            band("unseen", vec![(2.0, 1.0, 1.0 + 1e-9)]),
        ];
        panel.ends.push(EndLabel {
            x: 10.0,
            y: 10.0,
            text: "C1".into(),
            color: "red".into(),
            margin: true,
        });
        let svg = render(&[panel], 600.0, 400.0);
        let x_of = |text: &str| -> f64 {
            let at = svg.find(&format!(">{text}</text>")).unwrap();
            let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
            let x = tag.split("x=\"").nth(1).unwrap();
            x[..x.find('"').unwrap()].parse().unwrap()
        };
        // x = 1, 5 and 9 in pixels: the box runs from 70 to 600 − 20 − the margin's width.
        let r = 600.0 - 20.0 - (12.0 + SMALL_CHAR * 2.0);
        let px = |x: f64| 70.0 + x / 10.0 * (r - 70.0);
        // Positions are written with two decimals: equal to within 0.005 px.
        assert!((x_of("first") - px(1.0)).abs() < 0.01, "{svg}");
        assert!((x_of("second") - px(9.0)).abs() < 0.01, "{svg}");
        assert!(!svg.contains(">unseen<"));
        assert!(x_of("C1") > r);
    }

    #[test]
    fn log_axes_skip_nonpositive_points_and_label_decades() {
        let mut panel = Panel::new(
            "wp",
            "time",
            "error",
            vec![Series {
                marker: Some(3.0),
                ..Series::line("s", "blue", vec![(1e-3, 1e-2), (0.0, 1.0), (1e-1, 1e-8)])
            }],
        );
        panel.x_log = true;
        panel.y_log = true;
        panel.labels.push(Label {
            x: 1e-2,
            y: 1e-4,
            text: "A".into(),
        });
        let svg = render(&[panel], 600.0, 300.0);
        assert!(svg.contains(">1e-8<") && svg.contains(">1e-3<"));
        // Two drawable points (the one at x = 0 is skipped) and the legend's marker.
        assert_eq!(svg.matches("<circle").count(), 3);
        assert!(svg.contains(">A</text>"));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    /// Twelve long legend labels in a 600 px document wrap into rows, every entry's estimated
    /// extent inside the document, and the plot box moves down to make room.
    #[test]
    fn a_long_legend_wraps_inside_the_document() {
        let labels: Vec<String> = (0..12).map(|i| format!("runner number {i}")).collect();
        let series: Vec<Series> = labels
            .iter()
            .map(|l| Series::line(l, "red", vec![(0.0, 0.0), (1.0, 1.0)]))
            .collect();
        let places = legend_layout(&series, 70.0, 590.0);
        assert_eq!(places.len(), 12);
        for (ser, (x, _)) in series.iter().zip(&places) {
            assert!(x + 35.0 + CHAR * shown_chars(ser.label) as f64 <= 590.0);
        }
        let rows = places.last().unwrap().1 + 1;
        assert!(rows >= 3, "{rows}");
        let svg = render(&[Panel::new("t", "x", "y", series)], 600.0, 400.0);
        let top = 50.0 + LEGEND_ROW * (rows - 1) as f64;
        assert!(svg.contains(&format!(r#"<rect x="70" y="{top}""#)), "{svg}");
    }

    /// Markers: each shape is drawn as itself, an open one white inside with its colour's
    /// outline; markers at the ends of the x range stay off the frame (3 % padding).
    #[test]
    fn markers_have_shapes_open_ones_are_white_inside_and_none_sits_on_the_frame() {
        let pts = vec![(1.0, 1.0), (2.0, 2.0)];
        let series: Vec<Series> = Shape::ALL
            .iter()
            .map(|&shape| Series {
                color: "#123456",
                marker: Some(3.0),
                shape,
                hollow: shape == Shape::Square,
                points: pts.clone(),
                ..Series::default()
            })
            .collect();
        let svg = render(&[Panel::new("t", "x", "y", series)], 600.0, 400.0);
        assert_eq!(svg.matches("<circle").count(), 2);
        assert_eq!(svg.matches("<polygon").count(), 8);
        assert_eq!(
            svg.matches(r##"fill="white" stroke="#123456" stroke-width="1.3""##)
                .count(),
            2
        );
        // x = 1 maps 3 % of the range inside the box's left edge at 70 px.
        let first = svg.find("<circle cx=\"").unwrap();
        let cx: f64 = svg[first + 12..]
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(cx > 75.0, "{cx}");
    }

    #[test]
    fn subscripts_are_lowered_spans_and_text_is_escaped() {
        assert_eq!(
            rich("ω_{l} < 1"),
            r#"ω<tspan baseline-shift="sub" font-size="75%">l</tspan> &lt; 1"#
        );
        assert_eq!(shown_chars("max ω_{l}"), 6);
        assert_eq!(rich("a_b"), "a_b");
    }

    /// A 20 000-point trace over 600 pixel columns keeps at most 4 points a column, among
    /// them the extremes, and its gaps.
    #[test]
    fn a_dense_line_is_thinned_to_what_its_pixels_show() {
        let mut pts: Vec<(f64, f64)> = (0..20_000)
            .map(|i| {
                let x = 600.0 * f64::from(i) / 20_000.0;
                (x, (0.37 * x).sin() * 100.0)
            })
            .collect();
        pts[10_000].1 = f64::NAN;
        let t = thin(&pts);
        assert!(t.len() <= 4 * 601 + 1, "{}", t.len());
        let max = |v: &[(f64, f64)]| {
            v.iter()
                .map(|p| p.1)
                .filter(|y| y.is_finite())
                .fold(f64::MIN, f64::max)
        };
        let min = |v: &[(f64, f64)]| {
            v.iter()
                .map(|p| p.1)
                .filter(|y| y.is_finite())
                .fold(f64::MAX, f64::min)
        };
        assert_eq!(max(&t), max(&pts));
        assert_eq!(min(&t), min(&pts));
        assert_eq!(t.iter().filter(|p| p.1.is_nan()).count(), 1);
        assert!(t.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    /// Two labels at one point go to different places (the second below the first), on a
    /// white halo.
    #[test]
    fn labels_at_one_point_do_not_cover_each_other() {
        let mut panel = Panel::new(
            "t",
            "x",
            "y",
            vec![Series::line("", "black", vec![(0.0, 0.0), (10.0, 10.0)])],
        );
        for text in ["first label", "second label"] {
            panel.labels.push(Label {
                x: 5.0,
                y: 5.0,
                text: text.into(),
            });
        }
        let svg = render(&[panel], 600.0, 400.0);
        let ys: Vec<f64> = svg
            .match_indices(r#"font-size="11" stroke="white""#)
            .map(|(k, _)| {
                let tag = &svg[svg[..k].rfind("<text").unwrap()..k];
                let y = tag.split("y=\"").nth(1).unwrap().split('"').next().unwrap();
                y.parse().unwrap()
            })
            .collect();
        assert_eq!(ys.len(), 2);
        assert!((ys[1] - ys[0]).abs() >= 13.0, "{ys:?}");
    }

    #[test]
    fn a_figures_data_is_one_row_per_drawn_point() {
        let mut panel = Panel::new(
            "a \"b\"",
            "x",
            "y",
            vec![
                Series::line("s", "red", vec![(1.0, 2.0), (f64::NAN, 0.0), (3.0, 4.0)]),
                Series::line("", "red", vec![(5.0, 6.0)]),
            ],
        );
        panel.labels.push(Label {
            x: 7.0,
            y: 8.0,
            text: "H1".into(),
        });
        assert_eq!(
            data_csv(&[panel]),
            "panel,series,x,y\n\"a \"\"b\"\"\",\"s\",1e0,2e0\n\"a \"\"b\"\"\",\"s\",3e0,4e0\n\
             \"a \"\"b\"\"\",\"series 1\",5e0,6e0\n\"a \"\"b\"\"\",\"label: H1\",7e0,8e0\n"
        );
    }
}
