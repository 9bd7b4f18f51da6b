//! Special points along the periodic branches, each with the residual of its defining
//! condition: grazing orbits, smooth and discontinuous folds, other stability changes, and
//! the ends of branches at a grazing orbit.

use nalgebra::Complex;
use rotor_model::Model;
use serde::Serialize;

use crate::continuation::{Continuer, End, Node};
use crate::diagram::Branch;
use crate::{BifError, grazing};

/// What a special point is (its JSON `kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointKind {
    /// The equilibrium's complex pair crosses the imaginary axis.
    Hopf,
    /// The branch turns back in u: smooth (a multiplier 1) or discontinuous (at a grazing
    /// orbit, where a stable and an unstable branch meet).
    Fold,
    /// The cycle touches ω_l = 0.
    Grazing,
    /// The slipping branch meets the stuck set as ω → 0⁺.
    StickLimit,
    /// A multiplier leaves the unit circle other than at a fold or grazing point.
    StabilityChange,
    /// A branch stopped without a located cause.
    BranchEnd,
}

impl PointKind {
    /// The JSON and CSV name (`"stick_limit"`).
    pub fn as_str(self) -> &'static str {
        match self {
            PointKind::Hopf => "hopf",
            PointKind::Fold => "fold",
            PointKind::Grazing => "grazing",
            PointKind::StickLimit => "stick_limit",
            PointKind::StabilityChange => "stability_change",
            PointKind::BranchEnd => "branch_end",
        }
    }
}

impl std::fmt::Display for PointKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A special point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpecialPoint {
    pub kind: PointKind,
    pub u: f64,
    /// Folds only: `true` for a discontinuous fold (the branch turns at a grazing orbit,
    /// where a stable and an unstable branch meet), `false` for a smooth one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discontinuous: Option<bool>,
    /// Hopf: the equilibrium velocity \[rad/s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    /// Hopf: crossing frequency |Im λ| \[rad/s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// Period of the orbit (Hopf: 2π/frequency) \[s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_l_max: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_l_min: Option<f64>,
    /// The value of the defining condition at the located point (see `condition`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual: Option<f64>,
    /// What `residual` is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub condition: Option<&'static str>,
    /// Grazing orbits: ω_u where the orbit touches ω_l = 0 \[rad/s\] (the orbit's state there is
    /// `(T_sl/k_θ, ω_u, 0)`); a restart point for continuing the grazing condition.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub touch_omega_u: Option<f64>,
    /// Smooth folds: the cycle's state `[α, ω_u, ω_l]` on the section `ω_l = ω*(u)`; a restart
    /// point for continuing the fold condition.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section_state: Option<[f64; 3]>,
    pub detail: String,
}

impl SpecialPoint {
    pub(crate) fn new(kind: PointKind, u: f64, detail: String) -> SpecialPoint {
        SpecialPoint {
            kind,
            u,
            discontinuous: None,
            omega: None,
            frequency: None,
            period: None,
            omega_l_max: None,
            omega_l_min: None,
            residual: None,
            condition: None,
            touch_omega_u: None,
            section_state: None,
            detail,
        }
    }
}

/// Condition of a Hopf point.
pub(crate) const HOPF_CONDITION: &str = "Re lambda of the critical pair of the Jacobian [1/s]";
/// Condition of a grazing orbit.
const GRAZING_CONDITION: &str =
    "max(|min omega_l|, |omega_u(t_min) - omega_u(0)|) of the touching orbit [rad/s]";
/// Condition of a smooth fold.
const FOLD_CONDITION: &str =
    "u-component of the unit branch tangent (du/ds, proportional to det(dP/dz - I))";

/// The grazing orbit near a branch node (its u, and its ω_u on the section as the guess of
/// ω_u at the touch point: ω_u varies by a few per cent along these cycles).
pub fn grazing_near(model: &Model, n: &Node, tol: f64) -> Result<grazing::GrazingOrbit, BifError> {
    // Newton stops at |G|∞ ≤ 1e-13 rad/s (rounding of ω_l ~ 1e-15·|ω|max for |ω| ≤ 20) or
    // when its steps stop shrinking at rounding level.
    grazing::locate(model, n.y[0], n.y[2], tol, 1e-13)
}

fn grazing_point(g: &grazing::GrazingOrbit, detail: String) -> SpecialPoint {
    let mut p = SpecialPoint::new(PointKind::Grazing, g.u, detail);
    p.period = Some(g.period);
    p.omega_l_max = Some(g.omega_l_max);
    p.omega_l_min = Some(0.0);
    p.residual = Some(g.residual[0].abs().max(g.residual[1].abs()));
    p.condition = Some(GRAZING_CONDITION);
    p.touch_omega_u = Some(g.w);
    p
}

/// The discontinuous fold at grazing orbit `g` where the branches of nodes `a` and `b` meet;
/// `side_u` is the u of a branch point far enough from `g` (several steps) to tell on which
/// side of `g.u` the branches lie.
fn discontinuous_fold(g: &grazing::GrazingOrbit, a: &Node, b: &Node, side_u: f64) -> SpecialPoint {
    let side = |n: &Node| {
        if n.info.stable {
            if n.info.stick_slip {
                "a stable stick-slip"
            } else {
                "a stable slipping"
            }
        } else if n.info.stick_slip {
            "an unstable stick-slip"
        } else {
            "an unstable slipping"
        }
    };
    let mut p = grazing_point(
        g,
        format!(
            "discontinuous fold: {} branch and {} branch meet at the grazing orbit and both lie {} u = {}",
            side(a),
            side(b),
            if side_u > g.u { "above" } else { "below" },
            g.u
        ),
    );
    p.kind = PointKind::Fold;
    p.discontinuous = Some(true);
    p
}

/// Folds, grazing points and other stability changes along an ordered branch.
pub(crate) fn special_points(
    cont: &Continuer,
    branch: &[Node],
    point_tol: f64,
) -> Vec<SpecialPoint> {
    let model = cont.sh.model;
    let mut out = Vec::new();
    for w in branch.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        // The step from a to b: recompute it as the projection on a's tangent.
        let step = (0..3)
            .map(|k| (b.y[k] - a.y[k]) * a.tangent[k])
            .sum::<f64>();
        let mut b2 = b.clone();
        b2.step = step;
        let (ga, gb) = (a.info.grazing_indicator(), b.info.grazing_indicator());
        let grazes = ga * gb < 0.0 || (ga == 0.0) != (gb == 0.0);
        let mut explained = false;
        if grazes {
            // Start from the slipping node of the pair.
            let from = if a.info.stick_slip { b } else { a };
            match grazing_near(model, from, point_tol) {
                Ok(g) => {
                    explained = true;
                    out.push(grazing_point(
                        &g,
                        format!(
                            "the cycle touches omega_l = 0 (between branch points at u = {} and {})",
                            a.y[0], b.y[0]
                        ),
                    ));
                    if (a.y[0] - g.u) * (b.y[0] - g.u) > 0.0 {
                        out.push(discontinuous_fold(&g, a, b, a.y[0]));
                    }
                }
                Err(e) => {
                    let mut p = SpecialPoint::new(
                        PointKind::Grazing,
                        0.5 * (a.y[0] + b.y[0]),
                        format!("between u = {} and {}; not located: {e}", a.y[0], b.y[0]),
                    );
                    p.omega_l_min = Some(0.0);
                    out.push(p);
                }
            }
        }
        if !grazes
            && a.tangent[0] * b.tangent[0] < 0.0
            && let Ok(n) = cont.bisect_between(a, &b2, |n| n.tangent[0], 60)
        {
            explained = true;
            let crit = n
                .info
                .nontrivial
                .iter()
                .min_by(|x, y| {
                    (*x - Complex::new(1.0, 0.0))
                        .norm()
                        .total_cmp(&(*y - Complex::new(1.0, 0.0)).norm())
                })
                .copied()
                .unwrap_or_default();
            let mut p = point_at(
                PointKind::Fold,
                &n,
                format!(
                    "smooth fold: extremum of u along the branch; critical multiplier {:.12} {:+.1e}i",
                    crit.re, crit.im
                ),
            );
            p.discontinuous = Some(false);
            p.residual = Some(n.tangent[0]);
            p.condition = Some(FOLD_CONDITION);
            p.section_state = Some([n.y[1], n.y[2], n.c]);
            out.push(p);
        }
        if a.info.stable != b.info.stable && !explained {
            let g = |n: &Node| {
                n.info
                    .nontrivial
                    .iter()
                    .map(|l| l.norm())
                    .fold(0.0, f64::max)
                    - 1.0
            };
            let p = match cont.bisect_between(a, &b2, g, 60) {
                Ok(n) => {
                    let crit = n
                        .info
                        .nontrivial
                        .iter()
                        .max_by(|x, y| x.norm().total_cmp(&y.norm()))
                        .copied()
                        .unwrap_or_default();
                    let what = if crit.im.abs() > 1e-8 {
                        "a complex pair of multipliers crosses the unit circle (Neimark-Sacker)"
                    } else if crit.re < 0.0 {
                        "a multiplier crosses -1 (period doubling)"
                    } else {
                        "a multiplier crosses +1"
                    };
                    let mut p = point_at(PointKind::StabilityChange, &n, what.to_string());
                    p.residual = Some(g(&n));
                    p.condition = Some("largest nontrivial |multiplier| - 1");
                    p
                }
                Err(_) => point_at(
                    PointKind::StabilityChange,
                    b,
                    format!("between u = {} and u = {} (not refined)", a.y[0], b.y[0]),
                ),
            };
            out.push(p);
        }
    }
    out
}

/// Branch ends at a collapsed step: a non-smooth turning point at a grazing orbit. Each is
/// located as a grazing orbit; two ends at the same grazing orbit form a discontinuous fold.
pub(crate) fn stuck_end_points(
    model: &Model,
    branches: &[Branch],
    point_tol: f64,
) -> Vec<SpecialPoint> {
    // Each stuck end with the node 10 steps back (its side of the end in u).
    let ends: Vec<(&Node, &Node)> = branches
        .iter()
        .flat_map(|b| {
            let n = b.nodes.len();
            let back = 10.min(n.saturating_sub(1));
            let first = (b.ends[0] == End::Stuck && n > 0).then(|| (&b.nodes[0], &b.nodes[back]));
            let last = (b.ends[1] == End::Stuck && n > 0)
                .then(|| (&b.nodes[n - 1], &b.nodes[n - 1 - back]));
            first.into_iter().chain(last)
        })
        .collect();
    let located: Vec<Option<grazing::GrazingOrbit>> = ends
        .iter()
        .map(|(n, _)| grazing_near(model, n, point_tol).ok())
        .collect();
    let mut out = Vec::new();
    let mut paired = vec![false; ends.len()];
    for i in 0..ends.len() {
        if paired[i] {
            continue;
        }
        let (a, a_back) = ends[i];
        let Some(ga) = located[i] else {
            out.push(point_at(
                PointKind::BranchEnd,
                a,
                "the continuation step collapsed here; no grazing orbit found nearby".into(),
            ));
            continue;
        };
        // The same grazing orbit from another end: located from different starts, the two
        // agree to the Newton solve's accuracy (|G| ≤ 1e-13 with |∂G/∂(u, w)| ~ 1: 1e-12);
        // 1e-9 V leaves room for the integration error at point_tol ≤ 1e-10.
        let partner = (i + 1..ends.len()).find(|&j| {
            !paired[j]
                && located[j].is_some_and(|gb| {
                    (gb.u - ga.u).abs() < 1e-9 * ga.u.abs().max(1.0)
                        && (gb.w - ga.w).abs() < 1e-6 * ga.w.abs().max(1.0)
                })
        });
        out.push(grazing_point(
            &ga,
            format!(
                "a branch ends at this grazing orbit (continuation step collapsed at u = {}, stick time {:e} s, min omega_l {:e})",
                a.y[0], a.info.stick_time, a.info.omega_l_min
            ),
        ));
        if let Some(j) = partner {
            paired[j] = true;
            let (b, _) = ends[j];
            out.push(discontinuous_fold(&ga, a, b, a_back.y[0]));
        }
    }
    out
}

fn point_at(kind: PointKind, n: &Node, detail: String) -> SpecialPoint {
    let mut p = SpecialPoint::new(kind, n.y[0], detail);
    p.period = Some(n.info.period);
    p.omega_l_max = Some(n.info.omega_l_max);
    p.omega_l_min = Some(n.info.omega_l_min);
    p
}
