//! The bifurcation diagram of the rotor over the motor input u (the source's Figure 3).
//!
//! * **Equilibria** ([`equilibria`]): the slipping branch, explicit in ω,
//!   `u(ω) = (T_fl(ω) + T_fu(ω))/k_m`, `α(ω) = T_fl(ω)/k_θ`, with its stability from the
//!   eigenvalues of the Jacobian; the stuck set (both discs at rest) where it exists; Hopf
//!   points as zeros of `Re λ(ω)` of the complex pair.
//! * **Periodic orbits** ([`periodic`]): shooting on the Poincaré section `ω_l = ω*(u)`
//!   (2-D map in (α, ω_u)) and on the lower disc's stick exit (1-D map in ω_u), with the
//!   exact Filippov flow of `rotor_event::flow`.
//! * **Floquet multipliers** ([`monodromy`]): the monodromy matrix from the variational
//!   equations with a saltation matrix at every switching event (one multiplier exactly 0
//!   for a cycle with a stick phase); finite differences of the return maps remain as a check
//!   ([`continuation::Multipliers::FiniteDifference`]).
//! * **Continuation** ([`continuation`]): pseudo-arclength in (u, α, ω_u), with the exact
//!   Jacobian of the section map from the same variational equations.
//! * **Special points**, each with the residual of its defining condition:
//!   Hopf points (`Re λ = 0`, bisection in ω to the last bit), smooth folds
//!   (`du/ds = 0 ⇔ det(∂P/∂z − I) = 0`, a multiplier 1; bisection in arclength), grazing
//!   orbits (`min ω_l = 0` of the slipping cycle, a 2×2 Newton solve, [`grazing`]) and
//!   discontinuous folds (a grazing orbit where the branch turns back in u: point E).
//!
//! [`diagram`] assembles everything into a [`Diagram`], which writes JSON (the CLI contract,
//! DESIGN.md §4), CSV and an SVG figure ([`Diagram::to_svg`]).
//!
//! # Cost
//!
//! The whole diagram over 0–7 V with the default options (200 equilibria; each periodic
//! branch at arclength steps ≤ 7/200, about 500 orbits with their monodromy matrices; every
//! special point located) takes 1.1 s for the Table 1 set and 1.6 s for the Stribeck set
//! (criterion medians, `cargo bench -p rotor-bifurcation`, benches/diagram.rs; release build,
//! one thread, on a 2-core machine shared with other jobs while measured).

pub mod continuation;
pub mod equilibria;
pub mod grazing;
pub mod monodromy;
pub mod periodic;
mod svg;

use std::io::Write;

use nalgebra::Complex;
use rotor_event::{StopAt, flow};
use rotor_model::{Model, State};
use serde::Serialize;
use thiserror::Error;

use continuation::{ContOptions, Continuer, End, Node};
use periodic::Shooter;

/// What can go wrong while computing the diagram.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BifError {
    #[error("the flow failed: {0}")]
    Solve(String),
    #[error("no slipping equilibrium at u = {u} (needed as the section level)")]
    NoEquilibrium { u: f64 },
    #[error("the orbit does not return to the section / stick exit at u = {u}")]
    NoReturn { u: f64 },
    #[error("no convergence at u = {u}: {detail}")]
    NoConvergence { u: f64, detail: String },
    #[error("invalid option {field} = {value}: {reason}")]
    InvalidOption {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error("the trajectory meets a switching surface tangentially at u = {u}, state {state:?}")]
    Grazing { u: f64, state: [f64; 3] },
    #[error("non-finite value in the diagram: {what} = {value}")]
    NonFinite { what: String, value: f64 },
    #[error("write failed: {0}")]
    Io(String),
}

/// Largest admissible `u_max` \[V\]: the Hopf search samples the slipping branch up to
/// ω = 1e4 rad/s (`equilibria::omega_reaching`), which Table 1 reaches well above 1000 V (at
/// 1e4 V both Hopf points were lost); 1000 V is 140 times the source's range.
pub const U_MAX: f64 = 1000.0;

/// Largest arclength step of the periodic branches: the default range's (7 V / 200).
const H_MAX: f64 = 7.0 / 200.0;

/// What [`diagram`] computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiagramOptions {
    /// Lower end of the input range \[V\].
    pub u_min: f64,
    /// Upper end of the input range \[V\].
    pub u_max: f64,
    /// Number of u values of the equilibrium table; the periodic branch gets at least this
    /// many points over the range it spans (arclength step ≤ (u_max − u_min)/n).
    pub n: usize,
    /// Integration tolerance of the flow along the branches.
    pub tol: f64,
    /// Integration tolerance when a special point (grazing orbit) is located.
    pub point_tol: f64,
    /// Where the first periodic branch is started (the attractor reached from rest there);
    /// outside `[u_min, u_max]` the middle of the range is used, and if no cycle is reached
    /// from rest the branches start from the Hopf points only.
    pub u_start: f64,
    /// ω_l amplitude at which the branch is stopped near a Hopf point \[rad/s\].
    pub amp_stop: f64,
}

impl Default for DiagramOptions {
    fn default() -> Self {
        DiagramOptions {
            u_min: 0.0,
            u_max: 7.0,
            n: 200,
            tol: 1e-11,
            point_tol: 1e-12,
            u_start: 1.5,
            amp_stop: 0.02,
        }
    }
}

impl DiagramOptions {
    /// Checks every field; the error names the first bad one and its value.
    pub fn validate(&self) -> Result<(), BifError> {
        let bad = |field, value, reason| {
            Err(BifError::InvalidOption {
                field,
                value,
                reason,
            })
        };
        if !self.u_min.is_finite() {
            return bad("u_min", self.u_min, "must be finite");
        }
        if !self.u_max.is_finite() {
            return bad("u_max", self.u_max, "must be finite");
        }
        if self.u_max <= self.u_min {
            return bad("u_max", self.u_max, "must be greater than u_min");
        }
        // The branches are traced with the lower disc driven upward (its stick exits and
        // sections are upward); for a law odd in ω the u < 0 half is the mirror image.
        if self.u_min < 0.0 {
            return bad(
                "u_min",
                self.u_min,
                "must be >= 0: the diagram covers u >= 0 (for a law odd in omega, u < 0 is its mirror image)",
            );
        }
        if self.u_max > U_MAX {
            return bad(
                "u_max",
                self.u_max,
                "must be <= 1000 V: the Hopf search samples omega up to 1e4 rad/s",
            );
        }
        if self.n < 2 {
            return bad("n", self.n as f64, "must be at least 2");
        }
        // DOP853 cannot resolve below ~1e-14 relative in double precision; above 1e-6 the
        // located points would not reach the promised 1e-8 V.
        for (field, v) in [("tol", self.tol), ("point_tol", self.point_tol)] {
            if !(1e-14..=1e-6).contains(&v) {
                return bad(field, v, "must lie in [1e-14, 1e-6]");
            }
        }
        if !self.u_start.is_finite() {
            return bad("u_start", self.u_start, "must be finite");
        }
        if !(self.amp_stop.is_finite() && self.amp_stop > 0.0) {
            return bad("amp_stop", self.amp_stop, "must be positive and finite");
        }
        Ok(())
    }
}

/// One equilibrium of the table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EquilibriumRow {
    pub u: f64,
    pub omega: f64,
    pub alpha: f64,
    pub stable: bool,
    /// `"slip"` (both discs at ω ≠ 0) or `"stuck"` (both at rest; `alpha` is the lower end
    /// of the stuck set and `alpha_max` the upper end).
    pub kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_max: Option<f64>,
}

/// One periodic orbit of the branch (in branch order).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodicRow {
    /// Index of the branch (0: the one started from a steady orbit; then one per Hopf point
    /// the first does not reach, started from the Hopf eigenvector).
    pub branch: usize,
    pub u: f64,
    pub period: f64,
    pub omega_l_max: f64,
    pub omega_l_min: f64,
    pub stable: bool,
    /// Floquet multipliers `[re, im]`, eigenvalues of the saltation monodromy matrix: the
    /// trivial one (≈ 1) first, then by decreasing modulus (`[≈1, λ, 0]` with a stick phase).
    pub multipliers: Vec<[f64; 2]>,
    pub stick_slip: bool,
    pub stick_time: f64,
    /// The orbit's state `[α, ω_u, ω_l]` on the section `ω_l = ω*(u)` (a restart point).
    pub section_state: [f64; 3],
}

/// A special point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpecialPoint {
    /// `"hopf"`, `"fold"`, `"grazing"`, `"stick_limit"` (the slipping branch meets the stuck
    /// set as ω → 0⁺), `"stability_change"` (a multiplier leaves the unit circle other than
    /// at a fold or grazing point), `"branch_end"` (a branch stopped without a located cause).
    pub kind: &'static str,
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
    pub detail: String,
}

impl SpecialPoint {
    fn new(kind: &'static str, u: f64, detail: String) -> SpecialPoint {
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
            detail,
        }
    }
}

/// The bifurcation diagram (DESIGN.md §4).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagram {
    pub equilibria: Vec<EquilibriumRow>,
    pub periodic: Vec<PeriodicRow>,
    pub points: Vec<SpecialPoint>,
}

impl PeriodicRow {
    fn of(n: &Node, branch: usize) -> PeriodicRow {
        PeriodicRow {
            branch,
            u: n.y[0],
            period: n.info.period,
            omega_l_max: n.info.omega_l_max,
            omega_l_min: n.info.omega_l_min,
            stable: n.info.stable,
            multipliers: n.info.multipliers.iter().map(|l| [l.re, l.im]).collect(),
            stick_slip: n.info.stick_slip,
            stick_time: n.info.stick_time,
            section_state: [n.y[1], n.y[2], n.c],
        }
    }
}

/// Condition of a Hopf point.
const HOPF_CONDITION: &str = "Re lambda of the critical pair of the Jacobian [1/s]";
/// Condition of a grazing orbit.
const GRAZING_CONDITION: &str =
    "max(|min omega_l|, |omega_u(t_min) - omega_u(0)|) of the touching orbit [rad/s]";
/// Condition of a smooth fold.
const FOLD_CONDITION: &str =
    "u-component of the unit branch tangent (du/ds, proportional to det(dP/dz - I))";

/// The equilibrium table at `n` values of u, and the Hopf and stick-limit points.
pub fn equilibrium_part(
    model: &Model,
    opts: &DiagramOptions,
) -> (Vec<EquilibriumRow>, Vec<SpecialPoint>) {
    let mut rows = Vec::new();
    for i in 0..opts.n {
        let u = opts.u_min + (opts.u_max - opts.u_min) * i as f64 / (opts.n.max(2) - 1) as f64;
        if let Some(s) = model.stuck_equilibria(u) {
            rows.push(EquilibriumRow {
                u,
                omega: 0.0,
                alpha: s.alpha_min,
                stable: true,
                kind: "stuck",
                alpha_max: Some(s.alpha_max),
            });
        }
        for e in model
            .slip_equilibria(u)
            .into_iter()
            .filter(|e| e.omega > 0.0)
        {
            rows.push(EquilibriumRow {
                u,
                omega: e.omega,
                alpha: e.alpha,
                stable: model.equilibrium_is_stable(&e),
                kind: "slip",
                alpha_max: None,
            });
        }
    }
    let mut points = Vec::new();
    let u0 = model.slip_equilibrium_at(f64::MIN_POSITIVE).u;
    if (opts.u_min..=opts.u_max).contains(&u0) {
        let mut p = SpecialPoint::new(
            "stick_limit",
            u0,
            "slipping branch meets the stuck set (omega -> 0+)".into(),
        );
        p.omega = Some(0.0);
        points.push(p);
    }
    if let Some(wmax) = equilibria::omega_reaching(model, opts.u_max) {
        for h in equilibria::hopf_points(model, wmax) {
            if !(opts.u_min..=opts.u_max).contains(&h.equilibrium.u) {
                continue;
            }
            let mut p = SpecialPoint::new(
                "hopf",
                h.equilibrium.u,
                format!(
                    "equilibrium {} stability with increasing u",
                    if h.stabilizing { "gains" } else { "loses" },
                ),
            );
            p.omega = Some(h.equilibrium.omega);
            p.frequency = Some(h.frequency);
            p.period = Some(2.0 * std::f64::consts::PI / h.frequency);
            p.residual = Some(h.re);
            p.condition = Some(HOPF_CONDITION);
            points.push(p);
        }
    }
    (rows, points)
}

/// A point on the section `ω_l = ω*(u)` near the attractor reached from rest at `u`.
pub fn start_point(sh: &Shooter, u: f64) -> Result<([f64; 2], f64), BifError> {
    let model = sh.model;
    let x0 = State::zeros();
    let e = |e: rotor_model::SolveError| BifError::Solve(e.to_string());
    let settled = flow(
        model,
        u,
        sh.tol.max(1e-9),
        x0,
        model.mode_at(&x0, u),
        400.0,
        StopAt::Time,
    )
    .map_err(e)?;
    let c = sh.section_level(u)?;
    let on = flow(
        model,
        u,
        sh.tol,
        settled.x,
        settled.mode,
        1000.0,
        StopAt::Section(c),
    )
    .map_err(e)?;
    if !on.reached {
        return Err(BifError::NoReturn { u });
    }
    Ok(([on.x[0], on.x[1]], c))
}

/// The bifurcation diagram over `[u_min, u_max]` (see the crate docs).
///
/// ```no_run
/// use rotor_bifurcation::{DiagramOptions, diagram};
/// let model = rotor_model::Model::table1();
/// let d = diagram(&model, &DiagramOptions { u_min: 0.0, u_max: 7.0, ..Default::default() })?;
/// std::fs::write("diagram.json", d.to_json()?).unwrap();
/// std::fs::write("diagram.svg", d.to_svg("Table 1")).unwrap();
/// # Ok::<(), rotor_bifurcation::BifError>(())
/// ```
pub fn diagram(model: &Model, opts: &DiagramOptions) -> Result<Diagram, BifError> {
    opts.validate()?;
    let (equilibria, mut points) = equilibrium_part(model, opts);
    let sh = Shooter {
        model,
        tol: opts.tol,
    };
    // The arclength step shrinks with the range but never grows past the default's (7 V over
    // 200): a coarser step walks past the grazing point near the lower Hopf point (at 0.6 V,
    // 0.22 V above it), which a 1.5 V step over [0, 300] V did.
    let h_max = ((opts.u_max - opts.u_min) / opts.n as f64).min(H_MAX);
    let cont = Continuer {
        sh,
        opts: ContOptions {
            u_min: opts.u_min,
            u_max: opts.u_max,
            h_max,
            h_min: 1e-9,
            newton_tol: 1e-9,
            amp_stop: opts.amp_stop,
            max_nodes: 20 * opts.n,
            fd_step: 1e-6,
            multipliers: continuation::Multipliers::Saltation,
        },
    };
    let mut branches = Vec::new();
    let u_start = if (opts.u_min..=opts.u_max).contains(&opts.u_start) {
        opts.u_start
    } else {
        0.5 * (opts.u_min + opts.u_max)
    };
    // The branch through the attractor reached from rest, if that is a cycle (a damped
    // approach to a stable equilibrium also crosses the section: its "fixed point" is the
    // equilibrium, of zero amplitude).
    let started = start_point(&sh, u_start).and_then(|(z0, c)| {
        let z = sh.section_fixed_point(u_start, c, z0, 1e-10)?;
        cont.node([u_start, z[0], z[1]], &[1.0, 0.0, 0.0], 0.0)
    });
    if let Ok(start) = started
        && start.info.omega_l_max - start.info.omega_l_min >= opts.amp_stop
    {
        let (down, end_down) = cont.follow(&start, &[-1.0, 0.0, 0.0]);
        let (up, end_up) = cont.follow(&start, &[1.0, 0.0, 0.0]);
        let mut nodes: Vec<Node> = down.into_iter().rev().collect();
        nodes.push(start);
        nodes.extend(up);
        branches.push(Branch {
            nodes,
            ends: [end_down, end_up],
        });
    }
    // Branches born at Hopf points that the first branch does not reach.
    let hopfs = equilibria::omega_reaching(model, opts.u_max)
        .map(|w| equilibria::hopf_points(model, w))
        .unwrap_or_default();
    let hopfs: Vec<_> = hopfs
        .into_iter()
        .filter(|h| (opts.u_min..=opts.u_max).contains(&h.equilibrium.u))
        .collect();
    for h in &hopfs {
        if nearest_hopf_end(&branches, &hopfs, h).is_some() {
            continue;
        }
        let eps = 2.0 * opts.amp_stop;
        let (Ok(y1), Ok(y2)) = (
            cont.hopf_cycle(h.equilibrium.omega, eps),
            cont.hopf_cycle(h.equilibrium.omega, 1.5 * eps),
        ) else {
            continue;
        };
        let along = [y2[0] - y1[0], y2[1] - y1[1], y2[2] - y1[2]];
        let Ok(first) = cont.node(y1, &along, 0.0) else {
            continue;
        };
        let (rest, end) = cont.follow(&first, &along);
        let mut nodes = vec![first];
        nodes.extend(rest);
        branches.push(Branch {
            nodes,
            ends: [End::Small, end],
        });
    }
    for b in &mut branches {
        orient(&mut b.nodes);
        points.extend(special_points(&cont, &b.nodes, opts.point_tol));
    }
    // Criticality of each Hopf point: from the stability of the cycles at the branch end
    // next to it.
    for p in points.iter_mut().filter(|p| p.kind == "hopf") {
        if let Some(h) = hopfs.iter().find(|h| h.equilibrium.u == p.u)
            && let Some(n) = nearest_hopf_end(&branches, &hopfs, h)
        {
            p.detail = format!(
                "{}; {} (cycles of amplitude {:.3} rad/s at u = {} are {})",
                if n.info.stable {
                    "supercritical"
                } else {
                    "subcritical"
                },
                p.detail,
                n.info.omega_l_max - n.info.omega_l_min,
                n.y[0],
                if n.info.stable { "stable" } else { "unstable" }
            );
        }
    }
    points.extend(stuck_end_points(model, &branches, opts.point_tol));
    let periodic = branches
        .iter()
        .enumerate()
        .flat_map(|(k, b)| b.nodes.iter().map(move |n| PeriodicRow::of(n, k)))
        .collect();
    Ok(Diagram {
        equilibria,
        periodic,
        points,
    })
}

/// A followed branch and why each of its ends ended.
struct Branch {
    nodes: Vec<Node>,
    ends: [End; 2],
}

/// Orients every tangent along the branch order.
fn orient(nodes: &mut [Node]) {
    if nodes.len() >= 2 {
        let (a, b) = (&nodes[0].y, &nodes[1].y);
        let t = nodes[0].tangent;
        if (0..3).map(|k| (b[k] - a[k]) * t[k]).sum::<f64>() < 0.0 {
            nodes[0].tangent = t.map(|v| -v);
        }
    }
    for i in 1..nodes.len() {
        let prev = nodes[i - 1].tangent;
        let t = &mut nodes[i].tangent;
        if t[0] * prev[0] + t[1] * prev[1] + t[2] * prev[2] < 0.0 {
            *t = t.map(|v| -v);
        }
    }
}

/// The branch end (stopped for small amplitude) whose nearest Hopf point is `h`, if any.
fn nearest_hopf_end<'a>(
    branches: &'a [Branch],
    hopfs: &[equilibria::HopfPoint],
    h: &equilibria::HopfPoint,
) -> Option<&'a Node> {
    let nearest = |u: f64| {
        hopfs
            .iter()
            .min_by(|a, b| {
                (a.equilibrium.u - u)
                    .abs()
                    .total_cmp(&(b.equilibrium.u - u).abs())
            })
            .map(|x| x.equilibrium.u)
    };
    branches.iter().find_map(|b| {
        let cands = [
            (b.ends[0] == End::Small).then(|| b.nodes.first()).flatten(),
            (b.ends[1] == End::Small).then(|| b.nodes.last()).flatten(),
        ];
        cands
            .into_iter()
            .flatten()
            .find(|n| nearest(n.y[0]) == Some(h.equilibrium.u))
    })
}

/// The grazing orbit near a branch node (its u, and its ω_u on the section as the guess of
/// ω_u at the touch point: ω_u varies by a few per cent along these cycles).
pub fn grazing_near(model: &Model, n: &Node, tol: f64) -> Result<grazing::GrazingOrbit, BifError> {
    // Newton stops at |G|∞ ≤ 1e-13 rad/s (rounding of ω_l ~ 1e-15·|ω|max for |ω| ≤ 20) or
    // when its steps stop shrinking at rounding level.
    grazing::locate(model, n.y[0], n.y[2], tol, 1e-13)
}

fn grazing_point(g: &grazing::GrazingOrbit, detail: String) -> SpecialPoint {
    let mut p = SpecialPoint::new("grazing", g.u, detail);
    p.period = Some(g.period);
    p.omega_l_max = Some(g.omega_l_max);
    p.omega_l_min = Some(0.0);
    p.residual = Some(g.residual[0].abs().max(g.residual[1].abs()));
    p.condition = Some(GRAZING_CONDITION);
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
    p.kind = "fold";
    p.discontinuous = Some(true);
    p
}

/// Folds, grazing points and other stability changes along an ordered branch.
fn special_points(cont: &Continuer, branch: &[Node], point_tol: f64) -> Vec<SpecialPoint> {
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
                        "grazing",
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
                "fold",
                &n,
                format!(
                    "smooth fold: extremum of u along the branch; critical multiplier {:.12} {:+.1e}i",
                    crit.re, crit.im
                ),
            );
            p.discontinuous = Some(false);
            p.residual = Some(n.tangent[0]);
            p.condition = Some(FOLD_CONDITION);
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
                    let mut p = point_at("stability_change", &n, what.to_string());
                    p.residual = Some(g(&n));
                    p.condition = Some("largest nontrivial |multiplier| - 1");
                    p
                }
                Err(_) => point_at(
                    "stability_change",
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
fn stuck_end_points(model: &Model, branches: &[Branch], point_tol: f64) -> Vec<SpecialPoint> {
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
                "branch_end",
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

fn point_at(kind: &'static str, n: &Node, detail: String) -> SpecialPoint {
    let mut p = SpecialPoint::new(kind, n.y[0], detail);
    p.period = Some(n.info.period);
    p.omega_l_max = Some(n.info.omega_l_max);
    p.omega_l_min = Some(n.info.omega_l_min);
    p
}

/// Every number of the diagram, named, for the finiteness check.
fn numbers(d: &Diagram) -> impl Iterator<Item = (String, f64)> + '_ {
    let eq = d.equilibria.iter().enumerate().flat_map(|(i, e)| {
        [
            (format!("equilibria[{i}].u"), e.u),
            (format!("equilibria[{i}].omega"), e.omega),
            (format!("equilibria[{i}].alpha"), e.alpha),
            (
                format!("equilibria[{i}].alpha_max"),
                e.alpha_max.unwrap_or(0.0),
            ),
        ]
    });
    let per = d.periodic.iter().enumerate().flat_map(|(i, p)| {
        let mut v = vec![
            (format!("periodic[{i}].u"), p.u),
            (format!("periodic[{i}].period"), p.period),
            (format!("periodic[{i}].omega_l_max"), p.omega_l_max),
            (format!("periodic[{i}].omega_l_min"), p.omega_l_min),
            (format!("periodic[{i}].stick_time"), p.stick_time),
        ];
        for (k, m) in p.multipliers.iter().enumerate() {
            v.push((format!("periodic[{i}].multipliers[{k}].re"), m[0]));
            v.push((format!("periodic[{i}].multipliers[{k}].im"), m[1]));
        }
        for (k, s) in p.section_state.iter().enumerate() {
            v.push((format!("periodic[{i}].section_state[{k}]"), *s));
        }
        v
    });
    let pts = d.points.iter().enumerate().flat_map(|(i, p)| {
        let opt = [
            ("omega", p.omega),
            ("frequency", p.frequency),
            ("period", p.period),
            ("omega_l_max", p.omega_l_max),
            ("omega_l_min", p.omega_l_min),
            ("residual", p.residual),
        ];
        std::iter::once((format!("points[{i}].u"), p.u)).chain(
            opt.into_iter()
                .filter_map(move |(k, v)| v.map(|v| (format!("points[{i}].{k}"), v))),
        )
    });
    eq.chain(per).chain(pts)
}

impl Diagram {
    /// The first non-finite number of the diagram, as an error naming it.
    pub fn check_finite(&self) -> Result<(), BifError> {
        match numbers(self).find(|(_, v)| !v.is_finite()) {
            Some((what, value)) => Err(BifError::NonFinite { what, value }),
            None => Ok(()),
        }
    }

    /// The diagram as pretty JSON (DESIGN.md §4): `{"equilibria": [{"u", "omega", "alpha",
    /// "stable", ...}], "periodic": [{"u", "period", "omega_l_max", "omega_l_min", "stable",
    /// "multipliers": [[re, im]...], ...}], "points": [{"kind", "u", ...}]}`. A non-finite
    /// number is an error (JSON has none; serde would write `null`).
    pub fn to_json(&self) -> Result<String, BifError> {
        self.check_finite()?;
        serde_json::to_string_pretty(self).map_err(|e| BifError::Io(e.to_string()))
    }

    /// Writes the three tables as CSV, one after another, each with a header line; the first
    /// column names the table (`equilibrium`, `periodic`, `point`). A non-finite number is
    /// an error, and nothing is written then.
    pub fn write_csv(&self, w: &mut impl Write) -> Result<(), BifError> {
        self.check_finite()?;
        self.write_csv_io(w)
            .map_err(|e| BifError::Io(e.to_string()))
    }

    fn write_csv_io(&self, w: &mut impl Write) -> std::io::Result<()> {
        writeln!(w, "table,u,omega,alpha,stable,kind")?;
        for e in &self.equilibria {
            writeln!(
                w,
                "equilibrium,{},{},{},{},{}",
                e.u, e.omega, e.alpha, e.stable, e.kind
            )?;
        }
        writeln!(
            w,
            "table,u,period,omega_l_max,omega_l_min,stable,stick_slip,stick_time,mult1_re,mult1_im,mult2_re,mult2_im,mult3_re,mult3_im"
        )?;
        for p in &self.periodic {
            write!(
                w,
                "periodic,{},{},{},{},{},{},{}",
                p.u, p.period, p.omega_l_max, p.omega_l_min, p.stable, p.stick_slip, p.stick_time
            )?;
            for m in &p.multipliers {
                write!(w, ",{},{}", m[0], m[1])?;
            }
            writeln!(w)?;
        }
        writeln!(
            w,
            "table,kind,u,discontinuous,omega,frequency,period,residual,detail"
        )?;
        let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
        for p in &self.points {
            writeln!(
                w,
                "point,{},{},{},{},{},{},{},\"{}\"",
                p.kind,
                p.u,
                p.discontinuous.map(|b| b.to_string()).unwrap_or_default(),
                opt(p.omega),
                opt(p.frequency),
                opt(p.period),
                opt(p.residual),
                p.detail.replace('"', "'")
            )?;
        }
        Ok(())
    }

    /// The diagram as an SVG figure like the source's Figure 3: ω of each equilibrium and the
    /// max and min of ω_l over each cycle against u, stable solid, unstable dashed (the dash
    /// switches where the stability changes), special points marked and labelled
    /// (`H1 Hopf 0.3835`, `G1 grazing 0.6031`, `F1 fold 4.8430`, `E fold (discontinuous)
    /// 3.8659`). Non-finite numbers are left out (the pen lifts), never written.
    pub fn to_svg(&self, title: &str) -> String {
        svg::render(self, title)
    }
}
