//! Special points along the periodic branches, each with the residual of its defining
//! condition: grazing orbits, smooth and discontinuous folds, other stability changes, and
//! the ends of branches at a grazing orbit.

use nalgebra::Complex;
use rotor_model::Model;
use serde::Serialize;

use crate::bifurcation::branch::Branch;
use crate::bifurcation::continuation::{Continuer, End, Node};
use crate::bifurcation::feigin::{Feigin, GrazingType};
use crate::bifurcation::{BifError, grazing};

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
    /// What the point is; the fields that apply depend on it.
    pub kind: PointKind,
    /// Input at the located point \[V\].
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
    /// Points of the periodic branches: the cycle's largest lower-disc velocity \[rad/s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_l_max: Option<f64>,
    /// Points of the periodic branches: the cycle's smallest lower-disc velocity \[rad/s\] (0
    /// at a grazing orbit).
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
    /// Hopf: the first Lyapunov coefficient (Kuznetsov's formula on the smooth slip field;
    /// `l1 < 0` supercritical, `l1 > 0` subcritical).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub l1: Option<f64>,
    /// Grazing orbits and discontinuous folds: Feigin's type, `persistence` (the cycle passes
    /// through grazing) or `nonsmooth_fold` ([`crate::bifurcation::feigin`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grazing_type: Option<GrazingType>,
    /// Grazing orbits: whether a period-two orbit is born there too (σ⁻ odd).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_doubling: Option<bool>,
    /// Grazing orbits: σ⁺, the real multipliers above +1, of the slipping cycle and of the
    /// stick-slip cycle at the grazing orbit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_plus: Option<[usize; 2]>,
    /// Grazing orbits: σ⁻, the real multipliers below −1, in the same order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_minus: Option<[usize; 2]>,
    /// Grazing orbits: the slipping cycle's nontrivial multipliers at the grazing orbit,
    /// `[[re, im], [re, im]]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slipping_multipliers: Option<[[f64; 2]; 2]>,
    /// Grazing orbits: the stick-slip cycle's nontrivial multipliers at the grazing orbit (the
    /// limit of its saltation monodromy; one of them is 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stick_slip_multipliers: Option<[[f64; 2]; 2]>,
    /// A sentence for the reader: the point's character (Feigin's type and counts, a Hopf
    /// point's criticality), or why it was not located or classified.
    pub detail: String,
}

impl SpecialPoint {
    /// A point of this kind at `u` with no field set but its `detail`.
    pub fn new(kind: PointKind, u: f64, detail: String) -> SpecialPoint {
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
            l1: None,
            grazing_type: None,
            period_doubling: None,
            sigma_plus: None,
            sigma_minus: None,
            slipping_multipliers: None,
            stick_slip_multipliers: None,
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

/// Whether a branch point at `u` is resolved from the grazing orbit at `u_g`: more than 1e-8 V
/// (relative to max(1, |u_g|)) away, ten times the branches' own accuracy (1e-9 V at tol 1e-11).
/// Closer points (the branch steps shrink next to a grazing orbit) may lie on either side of it
/// by their error alone.
fn resolved(u: f64, u_g: f64) -> bool {
    (u - u_g).abs() > 1e-8 * u_g.abs().max(1.0)
}

/// Writes Feigin's classification into a grazing (or discontinuous fold) point.
fn set_feigin(p: &mut SpecialPoint, f: &Feigin) {
    let pair = |s: &crate::bifurcation::feigin::Side| s.multipliers().map(|z| [z.re, z.im]);
    p.grazing_type = Some(f.kind);
    p.period_doubling = Some(f.period_doubling);
    p.sigma_plus = Some(f.sigma_plus);
    p.sigma_minus = Some(f.sigma_minus);
    p.slipping_multipliers = Some(pair(&f.slipping));
    p.stick_slip_multipliers = Some(pair(&f.stick_slip));
}

/// Feigin's counts in words: `sigma+ = 1 + 0, sigma- = 0 + 0 (slipping + stick-slip)`, and
/// the multipliers of both sides.
fn counts(f: &Feigin) -> String {
    let m = |s: &crate::bifurcation::feigin::Side| {
        let [a, b] = s.multipliers();
        if a.im != 0.0 {
            format!("{:.6} ± {:.6}i", a.re, a.im.abs())
        } else {
            format!("{:.6}, {:.6}", a.re, b.re)
        }
    };
    format!(
        "Feigin: sigma+ = {} + {}, sigma- = {} + {} (slipping + stick-slip); multipliers {} \
         (slipping), {} (stick-slip)",
        f.sigma_plus[0],
        f.sigma_plus[1],
        f.sigma_minus[0],
        f.sigma_minus[1],
        m(&f.slipping),
        m(&f.stick_slip)
    )
}

fn stability(stable: bool, what: &str) -> String {
    if stable {
        format!("a stable {what}")
    } else {
        format!("an unstable {what}")
    }
}

/// The grazing point at `g` classified by Feigin's rule `f`, and for a non-smooth fold the
/// discontinuous fold point too. `sides` are the u of branch points of the two branch parts
/// meeting at the grazing orbit, resolved from it ([`resolved`]), if any: a check of the
/// classification, reported in the detail when the branch geometry disagrees.
fn classified(
    g: &grazing::GrazingOrbit,
    f: &Feigin,
    sides: [Option<f64>; 2],
    how: &str,
) -> Vec<SpecialPoint> {
    // Whether the two branch parts lie on the same side of u_g, if both are resolved.
    let below = sides.map(|u| u.map(|u| u < g.u));
    let same_side = match below {
        [Some(x), Some(y)] => Some(x == y),
        _ => None,
    };
    let slip = stability(f.slipping.stable(), "slipping");
    let stick = stability(f.stick_slip.stable(), "stick-slip");
    let pd = if f.period_doubling {
        "; a period-two orbit is born here (period-doubling-type grazing)"
    } else {
        ""
    };
    let mut out = Vec::new();
    match f.kind {
        GrazingType::Persistence => {
            let mut check = String::new();
            if same_side == Some(true) {
                check = format!(
                    "; NOTE: the branch points beside it both lie {} it, which the \
                     classification does not predict",
                    if below[0] == Some(true) {
                        "below"
                    } else {
                        "above"
                    }
                );
            }
            let mut p = grazing_point(
                g,
                format!(
                    "persistence: the cycle passes through grazing ({stick} cycle on one side, \
                     {slip} cycle on the other) {how}{pd}; {}{check}",
                    counts(f)
                ),
            );
            set_feigin(&mut p, f);
            out.push(p);
        }
        GrazingType::NonsmoothFold => {
            let mut p = grazing_point(
                g,
                format!("the cycle touches omega_l = 0 {how}; {}", counts(f)),
            );
            set_feigin(&mut p, f);
            out.push(p.clone());
            let side = match same_side {
                Some(true) => format!(
                    "both lie {} u = {}",
                    if below[0] == Some(true) {
                        "below"
                    } else {
                        "above"
                    },
                    g.u
                ),
                Some(false) => format!(
                    "NOTE: the branch points beside it lie on both sides of u = {}, which the \
                     classification does not predict",
                    g.u
                ),
                None => format!(
                    "their side of u = {} is not resolved (no branch point beside it more than \
                     1e-8 V away)",
                    g.u
                ),
            };
            p.kind = PointKind::Fold;
            p.discontinuous = Some(true);
            p.detail = format!(
                "discontinuous fold: {stick} branch and {slip} branch meet at the grazing orbit \
                 and {side}{pd}; {}",
                counts(f)
            );
            out.push(p);
        }
    }
    out
}

/// Folds, grazing points and other stability changes along an ordered branch.
pub(crate) fn special_points(
    cont: &Continuer,
    branch: &[Node],
    point_tol: f64,
) -> Vec<SpecialPoint> {
    let model = cont.sh.model;
    let mut out = Vec::new();
    for (i, w) in branch.windows(2).enumerate() {
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
                    let how = format!("(between branch points at u = {} and {})", a.y[0], b.y[0]);
                    match grazing::classify(model, g.u, g.w, point_tol) {
                        Ok(f) => {
                            // The first branch points outward from the window that are resolved
                            // from the grazing orbit (see `resolved`).
                            let before = branch[..=i].iter().rev().map(|n| n.y[0]);
                            let mut after = branch[i + 1..].iter().map(|n| n.y[0]);
                            let sides = [
                                before.clone().find(|&u| resolved(u, g.u)),
                                after.find(|&u| resolved(u, g.u)),
                            ];
                            out.extend(classified(&g, &f, sides, &how));
                        }
                        Err(e) => out.push(grazing_point(
                            &g,
                            format!("the cycle touches omega_l = 0 {how}; not classified: {e}"),
                        )),
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
        let (b_back, how) = match partner {
            Some(j) => {
                paired[j] = true;
                (
                    Some(ends[j].1),
                    format!(
                        "(two branches end here: continuation steps collapsed at u = {} and {})",
                        a.y[0], ends[j].0.y[0]
                    ),
                )
            }
            None => (
                None,
                format!(
                    "(a branch ends here: continuation step collapsed at u = {}, stick time {:e} \
                     s, min omega_l {:e})",
                    a.y[0], a.info.stick_time, a.info.omega_l_min
                ),
            ),
        };
        match (grazing::classify(model, ga.u, ga.w, point_tol), b_back) {
            (Ok(f), Some(b_back)) => {
                let sides = [a_back.y[0], b_back.y[0]].map(|u| resolved(u, ga.u).then_some(u));
                out.extend(classified(&ga, &f, sides, &how));
            }
            (Ok(f), None) => {
                let mut p = grazing_point(&ga, format!("{how}; {}", counts(&f)));
                set_feigin(&mut p, &f);
                out.push(p);
            }
            (Err(e), _) => out.push(grazing_point(&ga, format!("{how}; not classified: {e}"))),
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
