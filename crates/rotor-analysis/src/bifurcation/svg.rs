//! The diagram as an SVG figure like the source's Figure 3, drawn with `crate::plot`.
//!
//! * Equilibria: ω (= ω_l) of each slipping equilibrium against u, in order of ω along the
//!   branch; the stuck set at ω_l = 0.
//! * Periodic orbits: the maximum and the minimum of ω_l over each cycle, in branch order.
//! * Stable solid, unstable dashed: each curve is cut into runs of equal stability, and a run
//!   ends at the first point of the next one, so the curve stays connected and the dash
//!   switches at the stability change.
//! * Special points are marked and labelled: `H1 Hopf 0.3835` at the equilibrium, grazing
//!   points `G1 grazing 0.6031` at ω_l = 0 (where the cycle touches), folds `F1 fold 4.8430` and
//!   discontinuous folds `E fold (discontinuous) 3.8659` (the one at the largest u is E, the
//!   source's name; others are D1, D2, ...) at the cycle's maximum of ω_l. Points closer than
//!   2 % of the axis ranges share one label.

use crate::plot::{Label, Panel, Series, merge_close, render as plot};

use crate::bifurcation::{Diagram, EquilibriumKind, PointKind};

const UNSTABLE_DASH: &str = "6 4";

/// Appends the runs of `pts` (point, stable) to the stable and unstable polylines, with a
/// pen lift (a NaN point) after each run.
fn split_runs(
    pts: &[((f64, f64), bool)],
    stable: &mut Vec<(f64, f64)>,
    unstable: &mut Vec<(f64, f64)>,
) {
    let gap = (f64::NAN, f64::NAN);
    let mut i = 0;
    while i < pts.len() {
        let s = pts[i].1;
        let mut j = i;
        while j < pts.len() && pts[j].1 == s {
            j += 1;
        }
        let out = if s { &mut *stable } else { &mut *unstable };
        out.extend(pts[i..j].iter().map(|p| p.0));
        if j < pts.len() {
            out.push(pts[j].0);
        }
        out.push(gap);
        i = j;
    }
}

pub(crate) fn render(d: &Diagram, title: &str) -> String {
    let (mut eq_s, mut eq_u) = (Vec::new(), Vec::new());
    let mut slip: Vec<_> = d
        .equilibria
        .iter()
        .filter(|e| e.kind == EquilibriumKind::Slip)
        .collect();
    slip.sort_by(|a, b| a.omega.total_cmp(&b.omega));
    let pts: Vec<_> = slip.iter().map(|e| ((e.u, e.omega), e.stable)).collect();
    split_runs(&pts, &mut eq_s, &mut eq_u);
    let mut stuck: Vec<_> = d
        .equilibria
        .iter()
        .filter(|e| e.kind == EquilibriumKind::Stuck)
        .collect();
    stuck.sort_by(|a, b| a.u.total_cmp(&b.u));
    let pts: Vec<_> = stuck.iter().map(|e| ((e.u, 0.0), e.stable)).collect();
    split_runs(&pts, &mut eq_s, &mut eq_u);

    let (mut cy_s, mut cy_u) = (Vec::new(), Vec::new());
    let n_branches = d.periodic.iter().map(|p| p.branch + 1).max().unwrap_or(0);
    for b in 0..n_branches {
        let rows: Vec<_> = d.periodic.iter().filter(|p| p.branch == b).collect();
        for pick in [
            |p: &crate::bifurcation::PeriodicRow| p.omega_l_max,
            |p: &crate::bifurcation::PeriodicRow| p.omega_l_min,
        ] {
            let pts: Vec<_> = rows.iter().map(|p| ((p.u, pick(p)), p.stable)).collect();
            split_runs(&pts, &mut cy_s, &mut cy_u);
        }
    }

    // Labels: discontinuous folds in order of u are D1, D2, ..., the last one E (the
    // source's name); points closer than 2 % of the axis ranges share one label.
    let n_disc = d
        .points
        .iter()
        .filter(|p| p.kind == PointKind::Fold && p.discontinuous == Some(true))
        .count();
    let mut order: Vec<_> = d.points.iter().collect();
    order.sort_by(|a, b| a.u.total_cmp(&b.u));
    let mut marks: Vec<(f64, f64, String)> = Vec::new();
    let mut count = std::collections::HashMap::new();
    for p in order {
        let k = count.entry((p.kind, p.discontinuous)).or_insert(0);
        *k += 1;
        let (y, text) = match (p.kind, p.discontinuous) {
            (PointKind::Hopf, _) => (p.omega, format!("H{k} Hopf {:.4}", p.u)),
            (PointKind::Grazing, _) => (Some(0.0), format!("G{k} grazing {:.4}", p.u)),
            (PointKind::Fold, Some(true)) => (
                p.omega_l_max,
                format!(
                    "{} fold (discontinuous) {:.4}",
                    if *k == n_disc {
                        "E".to_string()
                    } else {
                        format!("D{k}")
                    },
                    p.u
                ),
            ),
            (PointKind::Fold, _) => (p.omega_l_max, format!("F{k} fold {:.4}", p.u)),
            // Where the stuck equilibrium ends and the lower disc starts to slip: ω_l = 0.
            (PointKind::StickLimit, _) => (Some(0.0), format!("S stick limit {:.4}", p.u)),
            _ => (None, String::new()),
        };
        if let Some(y) = y
            && y.is_finite()
            && p.u.is_finite()
        {
            marks.push((p.u, y, text));
        }
    }
    let finite = |v: &Vec<(f64, f64)>| {
        v.iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect::<Vec<_>>()
    };
    let all: Vec<(f64, f64)> = [&eq_s, &eq_u, &cy_s, &cy_u]
        .into_iter()
        .flat_map(finite)
        .chain(marks.iter().map(|m| (m.0, m.1)))
        .collect();
    let span = |f: fn(&(f64, f64)) -> f64| {
        let lo = all.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        if hi > lo { hi - lo } else { 1.0 }
    };
    let (sx, sy) = (span(|p| p.0), span(|p| p.1));
    let labels = merge_close(
        marks
            .iter()
            .map(|(x, y, text)| Label {
                x: *x,
                y: *y,
                text: text.clone(),
            })
            .collect(),
        sx,
        sy,
        0.02,
    );
    let markers = Series {
        width: 0.0,
        marker: Some(3.0),
        ..Series::line("", "black", marks.iter().map(|m| (m.0, m.1)).collect())
    };

    let series = vec![
        Series::line("equilibria, stable", "black", eq_s),
        Series {
            dash: Some(UNSTABLE_DASH),
            ..Series::line("equilibria, unstable", "black", eq_u)
        },
        Series::line("cycles, stable", "#1f5fbf", cy_s),
        Series {
            dash: Some(UNSTABLE_DASH),
            ..Series::line("cycles, unstable", "#c0392b", cy_u)
        },
        markers,
    ];
    let mut panel = Panel::new(
        title,
        "u [V]",
        "ω_l of the equilibria; max and min of ω_l over each cycle [rad/s]",
        series,
    );
    panel.labels = labels;
    plot(&[panel], 900.0, 600.0)
}
