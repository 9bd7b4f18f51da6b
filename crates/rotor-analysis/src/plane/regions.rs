//! The regions of the plane: each band the curves bound is named by what the orbits from
//! rest and from the perturbed equilibrium reach there ([`classify`], [`region_name`]), and
//! bands of one name in neighbouring columns are joined into one [`Region`].

use crate::bifurcation::BifError;
use rotor_model::seam::{Attractor, Output, Scene, Solver};
use rotor_model::{Model, Params, State};
use serde::Serialize;

use crate::plane::curves::Curve;
use crate::plane::options::{PlaneOptions, params_at};

/// A named region of the plane: one connected piece of it, named at the middle of its
/// tallest band, `[u_lo, u_hi]` at `p`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// What rest and the perturbed equilibrium reach ([`region_name`]).
    pub name: String,
    /// The parameter's value at the tallest band.
    pub p: f64,
    /// The middle of the tallest band \[V\].
    pub u: f64,
    /// The tallest band's lower end \[V\].
    pub u_lo: f64,
    /// The tallest band's upper end \[V\].
    pub u_hi: f64,
    /// Every band of the region, `[p, u_lo, u_hi]`, this one first, then the others in
    /// order of height (where the figure may write the name instead).
    #[serde(skip)]
    pub bands: Vec<[f64; 3]>,
}

/// What the orbit from a start reaches (event-driven solver, metrics only, 1500 s, metrics
/// over the last 500 s: long enough for the slow transients a few tenths of a volt from a
/// Hopf point); `None` if the run gives no steady state.
pub fn classify(model: &Model, u: f64, x0: State) -> Option<Attractor> {
    let scene = Scene {
        u,
        x0: x0.as_slice().to_vec(),
        t_end: 1500.0,
        output: Output::Metrics,
        metrics_from: Some(1000.0),
        ..Scene::with_tol(1e-8)
    };
    let metrics = rotor_event::EventSolver::default()
        .simulate(model, &scene)
        .map(|t| t.rig_metrics());
    metrics.ok().flatten().as_ref().map(Attractor::of)
}

/// The word of what a start reaches in a region's name: the attractor's, or `unresolved`.
fn word(a: Option<Attractor>) -> &'static str {
    a.map_or("unresolved", Attractor::as_str)
}

/// The region's name from what rest and the perturbed equilibrium reach: `both discs stuck`,
/// `<attractor> only`, or `bistable: <a> and <b>` (the two words in alphabetical order).
pub fn region_name(from_rest: Option<Attractor>, from_eq: Option<Attractor>) -> String {
    match (from_rest, from_eq) {
        (Some(Attractor::Stuck), Some(Attractor::Stuck)) => "both discs stuck".into(),
        (a, b) if a == b => format!("{} only", word(a)),
        (a, b) => {
            let mut v = [word(a), word(b)];
            v.sort_unstable();
            format!("bistable: {} and {}", v[0], v[1])
        }
    }
}

/// The u where the curves cross the vertical line at `p`, linear between curve points,
/// in increasing order (a vertex on the line counts once).
pub(crate) fn crossings(curves: &[Curve], p: f64) -> Vec<f64> {
    let mut v: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.points.windows(2))
        .filter_map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let hit = (a.p <= p && p < b.p) || (b.p <= p && p < a.p);
            hit.then(|| a.u + (p - a.p) / (b.p - a.p) * (b.u - a.u))
        })
        .filter(|u| u.is_finite())
        .collect();
    v.sort_by(f64::total_cmp);
    v
}

/// A band of one column of the plane with one name: column `col`, u from `lo` to `hi`.
struct Piece {
    col: usize,
    lo: f64,
    hi: f64,
    name: String,
}

/// Names the regions. The curves cut each of `region_cells` columns (p at the cells'
/// centres) into bands; each band is classified at its middle from rest and from the
/// perturbed equilibrium, and a band taller than a cell (1/`region_cells` of the u-window)
/// once per cell, so that a region no curve bounds is still found. A band thinner than
/// 1/1000 of the u-window is not named: a simulation there, between two curves that nearly
/// meet, says more about its transient than about the region. Bands of one name that
/// overlap in neighbouring columns are one region, named once at its tallest band (the one
/// nearest the middle column among those within 1 % of the tallest).
pub(crate) fn named(
    base: &Params,
    name: &str,
    opts: &PlaneOptions,
    curves: &[Curve],
) -> Result<Vec<Region>, BifError> {
    let n = opts.region_cells.max(2);
    let (u_min, u_max) = (opts.u_min, opts.u_max);
    let cell = (u_max - u_min) / n as f64;
    let thin = 1e-3 * (u_max - u_min);
    let column = |j: usize| opts.p_min + (opts.p_max - opts.p_min) * (j as f64 + 0.5) / n as f64;
    let mut pieces: Vec<Piece> = Vec::new();
    for j in 0..n {
        let p = column(j);
        let m = Model::new(params_at(base, name, p)?);
        let mut edges = vec![u_min];
        edges.extend(
            crossings(curves, p)
                .into_iter()
                .filter(|&u| u > u_min && u < u_max),
        );
        edges.push(u_max);
        for w in edges.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            if hi - lo < thin {
                continue;
            }
            let k = ((hi - lo) / cell).ceil().max(1.0) as usize;
            let at = |i: usize| lo + (hi - lo) * i as f64 / k as f64;
            let mut start = lo;
            let mut prev: Option<String> = None;
            for i in 0..k {
                let u = 0.5 * (at(i) + at(i + 1));
                let here = region_name(
                    classify(&m, u, State::zeros()),
                    classify(&m, u, m.perturbed_equilibrium(u)),
                );
                match prev.take() {
                    Some(before) if before != here => {
                        pieces.push(Piece {
                            col: j,
                            lo: start,
                            hi: at(i),
                            name: before,
                        });
                        start = at(i);
                    }
                    _ => {}
                }
                prev = Some(here);
            }
            if let Some(last) = prev {
                pieces.push(Piece {
                    col: j,
                    lo: start,
                    hi,
                    name: last,
                });
            }
        }
    }
    // Connected pieces: union-find over neighbours in adjacent columns.
    let mut root: Vec<usize> = (0..pieces.len()).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for a in 0..pieces.len() {
        for b in a + 1..pieces.len() {
            let (x, y) = (&pieces[a], &pieces[b]);
            if y.col == x.col + 1 && x.name == y.name && x.lo < y.hi && y.lo < x.hi {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                root[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let group: Vec<usize> = (0..pieces.len()).map(|i| find(&mut root, i)).collect();
    let height = |q: &Piece| q.hi - q.lo;
    // Each region's bands, tallest first (those within 1 % of the tallest: nearest the
    // middle column first).
    let mid = 0.5 * (n as f64 - 1.0);
    let off_middle = |q: &Piece| (q.col as f64 - mid).abs();
    let mut members: std::collections::BTreeMap<usize, Vec<&Piece>> = Default::default();
    for (q, &g) in pieces.iter().zip(&group) {
        members.entry(g).or_default().push(q);
    }
    let mut out: Vec<Region> = members
        .into_values()
        .map(|mut v| {
            let tallest = v.iter().map(|q| height(q)).fold(0.0, f64::max);
            let rank = |q: &Piece| (height(q) < 0.99 * tallest, -height(q), off_middle(q));
            v.sort_by(|a, b| {
                let (ra, rb) = (rank(a), rank(b));
                ra.0.cmp(&rb.0).then(if ra.0 {
                    ra.1.total_cmp(&rb.1)
                } else {
                    ra.2.total_cmp(&rb.2)
                })
            });
            let q = v[0];
            Region {
                name: q.name.clone(),
                p: column(q.col),
                u: 0.5 * (q.lo + q.hi),
                u_lo: q.lo,
                u_hi: q.hi,
                bands: v.iter().map(|q| [column(q.col), q.lo, q.hi]).collect(),
            }
        })
        .collect();
    out.sort_by(|a, b| a.u.total_cmp(&b.u).then(a.p.total_cmp(&b.p)));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names the report and the JSON carry, a run without a steady state included.
    #[test]
    fn regions_are_named_by_what_both_starts_reach() {
        use Attractor::*;
        for (rest, eq, name) in [
            (Some(Stuck), Some(Stuck), "both discs stuck"),
            (Some(Equilibrium), Some(Equilibrium), "equilibrium only"),
            (
                Some(SlippingCycle),
                Some(SlippingCycle),
                "slipping cycle only",
            ),
            (
                Some(StickSlipCycle),
                Some(Equilibrium),
                "bistable: equilibrium and stick-slip cycle",
            ),
            (
                Some(Equilibrium),
                Some(SlippingCycle),
                "bistable: equilibrium and slipping cycle",
            ),
            (
                Some(Stuck),
                Some(Equilibrium),
                "bistable: equilibrium and stuck",
            ),
            (None, None, "unresolved only"),
            (
                None,
                Some(StickSlipCycle),
                "bistable: stick-slip cycle and unresolved",
            ),
        ] {
            assert_eq!(region_name(rest, eq), name);
        }
    }
}
