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
//! * **Continuation** ([`continuation`]): pseudo-arclength in (u, α, ω_u) with folds and
//!   grazing points located by bisection.
//!
//! [`diagram`] assembles everything into a [`Diagram`] (serde-serializable, DESIGN.md §4),
//! which also writes CSV.

pub mod continuation;
pub mod equilibria;
pub mod monodromy;
pub mod periodic;

use std::io::Write;

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
    #[error("invalid options: {0}")]
    Options(String),
    #[error("the trajectory meets a switching surface tangentially at u = {u}, state {state:?}")]
    Grazing { u: f64, state: [f64; 3] },
}

/// What [`diagram`] computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiagramOptions {
    /// Range of the input voltage [V].
    pub u_min: f64,
    pub u_max: f64,
    /// Number of u values of the equilibrium table; the periodic branch gets at least this
    /// many points over the range it spans (arclength step ≤ (u_max − u_min)/n).
    pub n: usize,
    /// Integration tolerance of the flow.
    pub tol: f64,
    /// Where the periodic branch is started (a steady orbit is reached from rest there).
    pub u_start: f64,
    /// ω_l amplitude at which the branch is stopped near a Hopf point [rad/s].
    pub amp_stop: f64,
}

impl Default for DiagramOptions {
    fn default() -> Self {
        DiagramOptions {
            u_min: 0.0,
            u_max: 7.0,
            n: 200,
            tol: 1e-11,
            u_start: 1.5,
            amp_stop: 0.02,
        }
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
    /// set as ω → 0⁺), `"stability_change"` (between two branch points, not refined).
    pub kind: &'static str,
    pub u: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    /// Hopf: crossing frequency |Im λ| [rad/s].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// Period of the orbit at a fold or grazing point [s].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_l_max: Option<f64>,
    pub detail: String,
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
        points.push(SpecialPoint {
            kind: "stick_limit",
            u: u0,
            omega: Some(0.0),
            frequency: None,
            period: None,
            omega_l_max: None,
            detail: "slipping branch meets the stuck set (omega -> 0+)".into(),
        });
    }
    if let Some(wmax) = equilibria::omega_reaching(model, opts.u_max) {
        for h in equilibria::hopf_points(model, wmax) {
            if !(opts.u_min..=opts.u_max).contains(&h.equilibrium.u) {
                continue;
            }
            points.push(SpecialPoint {
                kind: "hopf",
                u: h.equilibrium.u,
                omega: Some(h.equilibrium.omega),
                frequency: Some(h.frequency),
                period: Some(2.0 * std::f64::consts::PI / h.frequency),
                omega_l_max: None,
                detail: format!(
                    "equilibrium {} stability with increasing u; Re lambda = {:e}",
                    if h.stabilizing { "gains" } else { "loses" },
                    h.re
                ),
            });
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
pub fn diagram(model: &Model, opts: &DiagramOptions) -> Result<Diagram, BifError> {
    if !(opts.u_max > opts.u_min && opts.n >= 2 && opts.tol > 0.0) {
        return Err(BifError::Options(format!("{opts:?}")));
    }
    let (equilibria, mut points) = equilibrium_part(model, opts);
    let sh = Shooter {
        model,
        tol: opts.tol,
    };
    let h_max = (opts.u_max - opts.u_min) / opts.n as f64;
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
    let (z0, c) = start_point(&sh, opts.u_start)?;
    let z = sh.section_fixed_point(opts.u_start, c, z0, 1e-10)?;
    let start = cont.node([opts.u_start, z[0], z[1]], &[1.0, 0.0, 0.0], 0.0)?;
    let (down, end_down) = cont.follow(&start, &[-1.0, 0.0, 0.0]);
    let (up, end_up) = cont.follow(&start, &[1.0, 0.0, 0.0]);
    let mut nodes: Vec<Node> = down.into_iter().rev().collect();
    nodes.push(start);
    nodes.extend(up);
    let mut branches = vec![Branch {
        nodes,
        ends: [end_down, end_up],
    }];
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
        points.extend(special_points(&cont, &b.nodes));
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
    // Branch ends at a collapsed step: a non-smooth turning point at a grazing orbit. Two such
    // ends at the same u form a discontinuous fold.
    let stuck_ends: Vec<&Node> = branches
        .iter()
        .flat_map(|b| {
            let first = (b.ends[0] == End::Stuck).then(|| b.nodes.first()).flatten();
            let last = (b.ends[1] == End::Stuck).then(|| b.nodes.last()).flatten();
            first.into_iter().chain(last)
        })
        .collect();
    for (i, a) in stuck_ends.iter().enumerate() {
        points.push(point_at(
            "grazing",
            a,
            &format!(
                "a branch ends at a grazing orbit (continuation step collapsed; stick time {:e} s, min omega_l {:e})",
                a.info.stick_time, a.info.omega_l_min
            ),
        ));
        for b in &stuck_ends[i + 1..] {
            if (a.y[0] - b.y[0]).abs() < 1e-4 {
                let mut p = point_at(
                    "fold",
                    a,
                    &format!(
                        "discontinuous fold: a {} and a {} branch meet at the grazing orbit (u = {} and {})",
                        if a.info.stable { "stable" } else { "unstable" },
                        if b.info.stable { "stable" } else { "unstable" },
                        a.y[0],
                        b.y[0]
                    ),
                );
                p.u = 0.5 * (a.y[0] + b.y[0]);
                points.push(p);
            }
        }
    }
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

/// Folds, grazing points and stability changes along an ordered branch.
fn special_points(cont: &Continuer, branch: &[Node]) -> Vec<SpecialPoint> {
    let mut out = Vec::new();
    for w in branch.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        // The step from a to b: recompute it as the projection on a's tangent.
        let step = (0..3)
            .map(|k| (b.y[k] - a.y[k]) * a.tangent[k])
            .sum::<f64>();
        let mut b2 = b.clone();
        b2.step = step;
        if a.tangent[0] * b.tangent[0] < 0.0
            && let Ok(n) = cont.bisect_between(a, &b2, |n| n.tangent[0], 40)
        {
            out.push(point_at(
                "fold",
                &n,
                "extremum of u along the periodic branch",
            ));
        }
        let (ga, gb) = (a.info.grazing_indicator(), b.info.grazing_indicator());
        if ga * gb < 0.0 || (ga == 0.0) != (gb == 0.0) {
            let g = |n: &Node| {
                let v = n.info.grazing_indicator();
                if v == 0.0 { -1e-300 } else { v }
            };
            if let Ok(n) = cont.bisect_between(a, &b2, g, 40) {
                out.push(point_at("grazing", &n, "the cycle touches omega_l = 0"));
            }
        }
        if a.info.stable != b.info.stable {
            let mut p = point_at(
                "stability_change",
                b,
                &format!("between u = {} and u = {} (not refined)", a.y[0], b.y[0]),
            );
            p.u = 0.5 * (a.y[0] + b.y[0]);
            out.push(p);
        }
    }
    out
}

fn point_at(kind: &'static str, n: &Node, detail: &str) -> SpecialPoint {
    SpecialPoint {
        kind,
        u: n.y[0],
        omega: None,
        frequency: None,
        period: Some(n.info.period),
        omega_l_max: Some(n.info.omega_l_max),
        detail: detail.to_string(),
    }
}

impl Diagram {
    /// The diagram as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("plain data serializes")
    }

    /// Writes the three tables as CSV, one after another, each with a header line; the first
    /// column names the table (`equilibrium`, `periodic`, `point`).
    pub fn write_csv(&self, w: &mut impl Write) -> std::io::Result<()> {
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
        writeln!(w, "table,kind,u,omega,frequency,period,detail")?;
        let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
        for p in &self.points {
            writeln!(
                w,
                "point,{},{},{},{},{},\"{}\"",
                p.kind,
                p.u,
                opt(p.omega),
                opt(p.frequency),
                opt(p.period),
                p.detail.replace('"', "'")
            )?;
        }
        Ok(())
    }
}
