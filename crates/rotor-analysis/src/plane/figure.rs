//! The plane as an SVG figure ([`Plane::to_svg`], through rotor_analysis::plot): the curves clipped to
//! the window, the codimension-two points and the regions named, the file's value of p
//! dashed.

use crate::plot::{Band, EndLabel, Label, Panel, Series, merge_close, render_rows};

use crate::plane::curves::{CurveKind, CurvePoint};
use crate::plane::picture::Plane;
use crate::plane::regions::crossings;

impl Plane {
    /// The (p, u) plane as an SVG figure over the computed window: each curve in its kind's
    /// colour and dash and named in the margin when it reaches the window's right edge, else
    /// at its left end; the codimension-two points marked and named (those nearer than 3 % of
    /// the panel share a label); the file's value of p dashed, with a dot where each curve
    /// crosses it (the one-parameter diagram's points); each region named in its band.
    ///
    /// Where the codimension-two points crowd the bottom of the window (two or more in its
    /// lowest tenth of u, as the Stribeck set's Hopf, grazing and stick limits below 0.25 V),
    /// a second panel shows that strip enlarged.
    pub fn to_svg(&self, title: &str) -> String {
        let panels = self.panels(title);
        let heights: Vec<f64> = panels.iter().map(|_| 560.0).collect();
        render_rows(&panels, 760.0, &heights)
    }

    /// The figure's panels: the whole window, and the crowded strip enlarged if there is one.
    fn panels(&self, title: &str) -> Vec<Panel<'_>> {
        let [u_lo, u_hi] = self.u_range;
        let low: Vec<f64> = self
            .points
            .iter()
            .filter(|q| (self.p_range[0]..=self.p_range[1]).contains(&q.p))
            .map(|q| q.u)
            .filter(|&u| u <= u_lo + 0.1 * (u_hi - u_lo))
            .collect();
        let mut panels = vec![self.panel(title.to_owned(), [u_lo, u_hi])];
        if low.len() >= 2 {
            let top = low.iter().fold(u_lo, |a, &b| a.max(b));
            let zoom = [u_lo, top + 0.5 * (top - u_lo).max(1e-3 * (u_hi - u_lo))];
            panels.push(self.panel(format!("{title}, u ≤ {:.3} V enlarged", zoom[1]), zoom));
        }
        panels
    }

    /// The figure's data ([`crate::plot::data_csv`]): every drawn point of its panels.
    pub fn to_csv(&self, title: &str) -> String {
        crate::plot::data_csv(&self.panels(title))
    }

    /// One panel of the figure over `u ∈ window` (see [`Plane::to_svg`]).
    fn panel(&self, title: String, window: [f64; 2]) -> Panel<'_> {
        let ([p_lo, p_hi], [u_lo, u_hi]) = (self.p_range, window);
        let (span_p, span_u) = (p_hi - p_lo, u_hi - u_lo);
        let drawn: Vec<Vec<(f64, f64)>> = self
            .curves
            .iter()
            .map(|c| clip_u(clip_p(&c.points, p_lo, p_hi), u_lo, u_hi))
            .collect();
        let mut series: Vec<Series> = self
            .curves
            .iter()
            .zip(&drawn)
            .map(|(c, pts)| {
                let (color, dash) = style(c.kind);
                Series {
                    dash,
                    ..Series::line("", color, pts.clone())
                }
            })
            .collect();
        for (kind, text) in [
            (CurveKind::Hopf, "Hopf"),
            (CurveKind::Grazing, "grazing"),
            (CurveKind::Fold, "fold of cycles"),
            (CurveKind::DiscontinuousFold, "discontinuous fold"),
            (CurveKind::StuckBoundary, "stuck boundary"),
        ] {
            if self.curves.iter().any(|c| c.kind == kind) {
                let (color, dash) = style(kind);
                series.push(Series {
                    dash,
                    ..Series::line(text, color, Vec::new())
                });
            }
        }
        if (p_lo..=p_hi).contains(&self.p_file) {
            series.push(Series {
                dash: Some("4 4"),
                width: 1.0,
                ..Series::line(
                    "file value",
                    "#000000",
                    vec![(self.p_file, u_lo), (self.p_file, u_hi)],
                )
            });
            let dots = crossings(&self.curves, self.p_file)
                .into_iter()
                .filter(|u| (u_lo..=u_hi).contains(u))
                .map(|u| (self.p_file, u))
                .collect();
            series.push(Series {
                width: 0.0,
                marker: Some(2.5),
                ..Series::line("", "#000000", dots)
            });
        }
        let mut panel = Panel::new(title, "", "u [V]", series);
        panel.x_label = match axis_label(&self.param) {
            "" => &self.param,
            known => known,
        };
        panel.clear_x.push(self.p_file);
        for (c, pts) in self.curves.iter().zip(&drawn) {
            let finite = || pts.iter().filter(|q| q.0.is_finite() && q.1.is_finite());
            let right = finite().max_by(|a, b| a.0.total_cmp(&b.0));
            let left = finite().min_by(|a, b| a.0.total_cmp(&b.0));
            // Named in the margin if it reaches the right edge, else at its left end (its
            // right end is often a codimension-two point, already named).
            let (end, margin) = match right {
                Some(&q) if p_hi - q.0 <= 1e-9 * span_p => (Some(q), true),
                _ => (left.copied(), false),
            };
            if let Some((x, y)) = end {
                panel.ends.push(EndLabel {
                    x,
                    y,
                    text: c.label.clone(),
                    color: style(c.kind).0.to_owned(),
                    margin,
                });
            }
        }
        panel.labels = merge_close(
            self.points
                .iter()
                .filter(|q| (p_lo..=p_hi).contains(&q.p) && (u_lo..=u_hi).contains(&q.u))
                .map(|q| Label {
                    x: q.p,
                    y: q.u,
                    text: q.kind.title().to_owned(),
                })
                .collect(),
            span_p,
            span_u,
            0.03,
        );
        panel.bands = self
            .regions
            .iter()
            .map(|r| Band {
                text: r.name.clone(),
                places: r
                    .bands
                    .iter()
                    .filter_map(|b| {
                        let (lo, hi) = (b[1].max(u_lo), b[2].min(u_hi));
                        (lo < hi).then_some((b[0], lo, hi))
                    })
                    .collect(),
            })
            .collect();
        panel
    }
}

/// A curve kind's colour (Okabe–Ito's palette, which colour-blind readers tell apart) and
/// dash pattern (a second channel for greyscale print).
fn style(k: CurveKind) -> (&'static str, Option<&'static str>) {
    match k {
        CurveKind::Hopf => ("#0072B2", None),
        CurveKind::Grazing => ("#009E73", Some("6 3")),
        CurveKind::Fold => ("#D55E00", Some("2 2")),
        CurveKind::DiscontinuousFold => ("#CC79A7", Some("8 3 2 3")),
        CurveKind::StuckBoundary => ("#7F7F7F", Some("4 2")),
    }
}

/// The axis label of a parameter: its symbol and unit where the model names them, with the
/// parameter file's field in brackets; else the field itself.
fn axis_label(field: &str) -> &'static str {
    match field {
        "k_theta" => "k_{θ} [N m/rad] (k_theta)",
        "k_m" => "k_{m} [N m/V] (k_m)",
        "j_u" => "J_{u} [kg m²] (j_u)",
        "j_l" => "J_{l} [kg m²] (j_l)",
        "lower.t_s" => "T_{sl}, the lower disc's static friction [N m] (lower.t_s)",
        "upper.t_s" => "T_{su}, the upper disc's static friction [N m] (upper.t_s)",
        "lower.b" => "b_{l} [N m s/rad] (lower.b)",
        "upper.b" => "b_{u} [N m s/rad] (upper.b)",
        _ => "",
    }
}

/// `pts` with the points outside `u ∈ [lo, hi]` lifted out (NaN: the pen lifts there).
fn clip_u(pts: Vec<(f64, f64)>, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    pts.into_iter()
        .map(|q| {
            if q.1.is_finite() && !(lo..=hi).contains(&q.1) {
                (f64::NAN, f64::NAN)
            } else {
                q
            }
        })
        .collect()
}

/// A curve's points with p in `[lo, hi]`, cut where it leaves and enters that window (the
/// cut points interpolated on the edge, a NaN point between the pieces).
fn clip_p(points: &[CurvePoint], lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let inside = |p: f64| (lo..=hi).contains(&p);
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut push = |q: (f64, f64)| {
        if inside(q.0) {
            out.push(q);
        } else if out.last().is_some_and(|l| l.0.is_finite()) {
            out.push((f64::NAN, f64::NAN));
        }
    };
    for (i, b) in points.iter().enumerate() {
        if let Some(a) = i.checked_sub(1).map(|k| &points[k]) {
            let mut cuts: Vec<f64> = [lo, hi]
                .into_iter()
                .filter(|e| (a.p - e) * (b.p - e) < 0.0)
                .map(|e| (e - a.p) / (b.p - a.p))
                .collect();
            cuts.sort_by(f64::total_cmp);
            for s in cuts {
                // The edge itself, not its value rounded through s.
                let at = a.p + s * (b.p - a.p);
                let edge = if (at - lo).abs() < (at - hi).abs() {
                    lo
                } else {
                    hi
                };
                push((edge, a.u + s * (b.u - a.u)));
            }
        }
        push((b.p, b.u));
    }
    if out.last().is_some_and(|l| l.0.is_nan()) {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve is cut on the window's edges, the cut points on the edges exactly, with a pen
    /// lift between the pieces; a segment that crosses the whole window keeps both cuts.
    #[test]
    fn curves_are_clipped_to_the_window() {
        let pt = |p: f64, u: f64| CurvePoint::at(p, u, 0.0);
        let c = [pt(-1.0, 0.0), pt(0.5, 1.5), pt(2.0, 3.0), pt(0.5, 4.5)];
        let out = clip_p(&c, 0.0, 1.0);
        let fin: Vec<(f64, f64)> = out.iter().copied().filter(|q| q.0.is_finite()).collect();
        assert_eq!(
            fin,
            [(0.0, 1.0), (0.5, 1.5), (1.0, 2.0), (1.0, 4.0), (0.5, 4.5)]
        );
        assert!(out[3].0.is_nan() && out.len() == 6, "{out:?}");
        let across = clip_p(&[pt(-1.0, 0.0), pt(3.0, 4.0)], 0.0, 1.0);
        assert_eq!(across, [(0.0, 1.0), (1.0, 2.0)]);
    }
}
