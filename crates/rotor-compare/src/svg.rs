//! A small, dependency-free SVG line-plot writer (pure Rust, no fonts needed: text is left to
//! the viewer's sans-serif).

use std::fmt::Write;

/// One polyline with a label and a style.
pub struct Series<'a> {
    pub label: &'a str,
    pub color: &'a str,
    pub dash: Option<&'a str>,
    pub width: f64,
    pub points: Vec<(f64, f64)>,
}

/// A panel: title, axis labels, series.
pub struct Panel<'a> {
    pub title: String,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: Vec<Series<'a>>,
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

/// Renders panels stacked vertically into one SVG document.
pub fn render(panels: &[Panel], width: f64, panel_height: f64) -> String {
    let height = panel_height * panels.len() as f64;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (k, p) in panels.iter().enumerate() {
        let oy = k as f64 * panel_height;
        let (l, r, t, b) = (70.0, width - 20.0, oy + 30.0, oy + panel_height - 45.0);
        let pts = p.series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in pts {
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if !x0.is_finite() {
            continue;
        }
        if y1 - y0 < 1e-9 {
            y0 -= 0.5;
            y1 += 0.5;
        }
        let pad = 0.05 * (y1 - y0);
        let (y0, y1) = (y0 - pad, y1 + pad);
        let sx = |x: f64| l + (x - x0) / (x1 - x0).max(1e-300) * (r - l);
        let sy = |y: f64| b - (y - y0) / (y1 - y0) * (b - t);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle" font-size="14">{}</text>"#,
            (l + r) / 2.0,
            oy + 20.0,
            esc(&p.title)
        );
        let _ = writeln!(
            s,
            r#"<rect x="{l}" y="{t}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            r - l,
            b - t
        );
        for tx in nice_ticks(x0, x1, 8) {
            let x = sx(tx);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{b}" x2="{x:.1}" y2="{t}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
                b + 15.0,
                fmt_tick(tx)
            );
        }
        for ty in nice_ticks(y0, y1, 6) {
            let y = sy(ty);
            let _ = writeln!(
                s,
                r##"<line x1="{l}" y1="{y:.1}" x2="{r}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
                l - 5.0,
                y + 4.0,
                fmt_tick(ty)
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            (l + r) / 2.0,
            b + 35.0,
            esc(p.x_label)
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle" transform="rotate(-90 {} {})">{}</text>"#,
            l - 50.0,
            (t + b) / 2.0,
            l - 50.0,
            (t + b) / 2.0,
            esc(p.y_label)
        );
        for (i, ser) in p.series.iter().enumerate() {
            let mut d = String::new();
            let mut pen_up = true;
            for &(x, y) in &ser.points {
                if !(x.is_finite() && y.is_finite()) {
                    pen_up = true;
                    continue;
                }
                let _ = write!(
                    d,
                    "{}{:.2},{:.2} ",
                    if pen_up { "M" } else { "L" },
                    sx(x),
                    sy(y)
                );
                pen_up = false;
            }
            let dash = ser
                .dash
                .map(|d| format!(r#" stroke-dasharray="{d}""#))
                .unwrap_or_default();
            let _ = writeln!(
                s,
                r#"<path d="{d}" fill="none" stroke="{}" stroke-width="{}"{dash}/>"#,
                ser.color, ser.width
            );
            let ly = t + 15.0 + 16.0 * i as f64;
            let _ = writeln!(
                s,
                r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="{}"{dash}/><text x="{}" y="{}">{}</text>"#,
                r - 150.0,
                r - 120.0,
                ser.color,
                ser.width.max(1.5),
                r - 115.0,
                ly + 4.0,
                esc(ser.label)
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

fn fmt_tick(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
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
            &[Panel {
                title: "a < b".into(),
                x_label: "t [s]",
                y_label: "w",
                series: vec![Series {
                    label: "x",
                    color: "red",
                    dash: None,
                    width: 1.0,
                    points: vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
                }],
            }],
            600.0,
            300.0,
        );
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a &lt; b"));
        assert!(!svg.contains("NaN"));
    }
}
