//! The plane as an SVG figure ([`Plane::to_svg`], through rotor-plot): the curves clipped to
//! the window, the codimension-two points and the regions named, the file's value of p
//! dashed.

use rotor_plot::{Band, EndLabel, Label, Panel, Series, merge_close, render};

use crate::curves::{CurveKind, CurvePoint};
use crate::picture::Plane;
use crate::regions::crossings;

impl Plane {
    /// The (p, u) plane as an SVG figure over the computed window: each curve in its kind's
    /// colour and named in the margin when it reaches the window's right edge, else at its
    /// left end; the codimension-two points marked and named (those nearer than 3 % of the
    /// window share a label); the file's value of p dashed, with a dot where each curve
    /// crosses it (the one-parameter diagram's points); each region named in its band.
    pub fn to_svg(&self, title: &str) -> String {
        let color = |k: CurveKind| match k {
            CurveKind::Hopf => "#1f77b4",
            CurveKind::Grazing => "#2ca02c",
            CurveKind::Fold => "#d62728",
            CurveKind::DiscontinuousFold => "#9467bd",
            CurveKind::StuckBoundary => "#7f7f7f",
        };
        let ([p_lo, p_hi], [u_lo, u_hi]) = (self.p_range, self.u_range);
        let (span_p, span_u) = (p_hi - p_lo, u_hi - u_lo);
        let drawn: Vec<Vec<(f64, f64)>> = self
            .curves
            .iter()
            .map(|c| clip_p(&c.points, p_lo, p_hi))
            .collect();
        let mut series: Vec<Series> = self
            .curves
            .iter()
            .zip(&drawn)
            .map(|(c, pts)| Series::line("", color(c.kind), pts.clone()))
            .collect();
        for (kind, text) in [
            (CurveKind::Hopf, "Hopf"),
            (CurveKind::Grazing, "grazing"),
            (CurveKind::Fold, "fold of cycles"),
            (CurveKind::DiscontinuousFold, "discontinuous fold"),
            (CurveKind::StuckBoundary, "stuck boundary"),
        ] {
            if self.curves.iter().any(|c| c.kind == kind) {
                series.push(Series::line(text, color(kind), Vec::new()));
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
        let mut panel = Panel::new(title.to_owned(), &self.param, "u [V]", series);
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
                    color: color(c.kind).to_owned(),
                    margin,
                });
            }
        }
        panel.labels = merge_close(
            self.points
                .iter()
                .filter(|q| (p_lo..=p_hi).contains(&q.p))
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
                places: r.bands.iter().map(|b| (b[0], b[1], b[2])).collect(),
            })
            .collect();
        render(&[panel], 760.0, 560.0)
    }
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
