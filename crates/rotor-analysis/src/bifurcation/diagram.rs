//! The diagram: the equilibrium table, the periodic branches from the attractor reached from
//! rest and from each Hopf point, and their special points.

use rotor_event::{StopAt, flow};
use rotor_model::{FieldError, Model, State};
use serde::Serialize;

use crate::bifurcation::branch::Branch;
use crate::bifurcation::continuation::{self, ContOptions, Continuer, End, Node};
use crate::bifurcation::periodic::Shooter;
use crate::bifurcation::points::{
    HOPF_CONDITION, PointKind, SpecialPoint, special_points, stuck_end_points,
};
use crate::bifurcation::{BifError, equilibria};

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
        let bad = |field: &str, value: f64, reason: &str| {
            Err(BifError::InvalidOption(FieldError::num(
                field, value, reason,
            )))
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

/// An equilibrium of the table (its JSON `kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EquilibriumKind {
    /// Both discs at ω ≠ 0.
    Slip,
    /// Both at rest: `alpha` is the lower end of the stuck set and `alpha_max` the upper end.
    Stuck,
}

impl EquilibriumKind {
    /// The JSON and CSV name.
    pub fn as_str(self) -> &'static str {
        match self {
            EquilibriumKind::Slip => "slip",
            EquilibriumKind::Stuck => "stuck",
        }
    }
}

/// One equilibrium of the table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EquilibriumRow {
    /// Input \[V\]: one of the table's `n` values.
    pub u: f64,
    /// Common velocity of both discs `ω_u = ω_l` \[rad/s\]: > 0 slipping, 0 stuck.
    pub omega: f64,
    /// Spring twist \[rad\]: `T_fl(ω)/k_θ` slipping, the stuck set's lower end stuck.
    pub alpha: f64,
    /// Slipping: all eigenvalues of the Jacobian in the open left half-plane. The stuck set
    /// is always reported stable.
    pub stable: bool,
    /// Slipping equilibrium or stuck set.
    pub kind: EquilibriumKind,
    /// Stuck set only: its upper end \[rad\]; left out of the JSON for a slipping equilibrium.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_max: Option<f64>,
}

/// One periodic orbit of the branch (in branch order).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodicRow {
    /// Index of the branch (0: the one started from a steady orbit; then one per Hopf point
    /// the first does not reach, started from the Hopf eigenvector).
    pub branch: usize,
    /// Input \[V\].
    pub u: f64,
    /// Period \[s\]: the return time to the section.
    pub period: f64,
    /// Largest lower-disc velocity over the cycle \[rad/s\].
    pub omega_l_max: f64,
    /// Smallest lower-disc velocity over the cycle \[rad/s\]: 0 with a stick phase.
    pub omega_l_min: f64,
    /// Smallest ω_u over the cycle \[rad/s\]: the upper disc would graze ω_u = 0 (where the
    /// Stribeck set has static friction) if it reached 0.
    pub omega_u_min: f64,
    /// Both nontrivial multipliers (eigenvalues of the section map's `∂P/∂z`) inside the unit
    /// circle.
    pub stable: bool,
    /// Floquet multipliers `[re, im]`, eigenvalues of the saltation monodromy matrix: the
    /// trivial one (≈ 1) first, then by decreasing modulus (`[≈1, λ, 0]` with a stick phase).
    pub multipliers: Vec<[f64; 2]>,
    /// Whether the lower disc sticks on the cycle.
    pub stick_slip: bool,
    /// Time per period with the lower disc stuck \[s\].
    pub stick_time: f64,
    /// The orbit's state `[α, ω_u, ω_l]` on the section `ω_l = ω*(u)` (a restart point).
    pub section_state: [f64; 3],
}

/// The bifurcation diagram (the JSON of `rotor bifurcation`, docs/design.md).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagram {
    /// The equilibrium table: at each of the `n` values of u, the stuck set (if any) and the
    /// slipping equilibria with ω > 0.
    pub equilibria: Vec<EquilibriumRow>,
    /// The periodic orbits, branch after branch, each branch in its order along the arclength.
    pub periodic: Vec<PeriodicRow>,
    /// The special points: stick limit and Hopf points of the equilibria, then those of the
    /// periodic branches (grazing orbits, folds, stability changes, branch ends).
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
            omega_u_min: n.info.omega_u_min,
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
                kind: EquilibriumKind::Stuck,
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
                kind: EquilibriumKind::Slip,
                alpha_max: None,
            });
        }
    }
    let mut points = Vec::new();
    let u0 = model.slip_equilibrium_at(f64::MIN_POSITIVE).u;
    if (opts.u_min..=opts.u_max).contains(&u0) {
        let mut p = SpecialPoint::new(
            PointKind::StickLimit,
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
                PointKind::Hopf,
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
    let e = BifError::Solve;
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
/// # Example
///
/// Table 1 over 0.3–0.8 V, coarsely (10 table values, tolerance 1e-8; 0.1 s in release):
/// the slipping equilibrium loses stability at the Hopf point near 0.38 V, and the periodic
/// branch grazes ω_l = 0 near 0.60 V, above which the cycles stick.
///
/// ```
/// use rotor_analysis::bifurcation::{DiagramOptions, PointKind, diagram};
///
/// let model = rotor_model::Model::table1();
/// let opts = DiagramOptions {
///     u_min: 0.3, // V
///     u_max: 0.8, // V
///     n: 10,
///     tol: 1e-8,
///     point_tol: 1e-8,
///     ..Default::default()
/// };
/// let d = diagram(&model, &opts)?;
///
/// let at = |kind| d.points.iter().find(|p| p.kind == kind).map(|p| p.u);
/// let hopf = at(PointKind::Hopf).expect("a Hopf point");
/// let grazing = at(PointKind::Grazing).expect("a grazing orbit");
/// assert!((hopf - 0.383547).abs() < 1e-6, "Hopf at {hopf} V");
/// assert!((grazing - 0.603147).abs() < 1e-5, "grazing at {grazing} V");
/// // Above the grazing point the cycles have a stick phase (ω_l reaches 0 and stays).
/// assert!(d.periodic.iter().filter(|r| r.u > grazing + 0.01).all(|r| r.omega_l_min == 0.0));
/// println!("{}", d.to_json()?);
/// # Ok::<(), rotor_analysis::bifurcation::BifError>(())
/// ```
///
/// The default options give the source's Figure 3 over 0–7 V, written as JSON and SVG:
///
/// ```no_run
/// use rotor_analysis::bifurcation::{DiagramOptions, diagram};
/// let model = rotor_model::Model::table1();
/// let d = diagram(&model, &DiagramOptions { u_min: 0.0, u_max: 7.0, ..Default::default() })?;
/// std::fs::write("diagram.json", d.to_json()?).unwrap();
/// std::fs::write("diagram.svg", d.to_svg("Table 1")).unwrap();
/// # Ok::<(), rotor_analysis::bifurcation::BifError>(())
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
    // Criticality of each Hopf point: the sign of its first Lyapunov coefficient (Kuznetsov's
    // formula, `equilibria::first_lyapunov`). The stability of the computed cycles at the branch end
    // next to it is reported beside it: at amplitudes of 0.02-0.08 rad/s it is a weaker witness
    // (Table 1's H2 has l1 = 1.7e-3), so it is shown, not used.
    for p in points.iter_mut().filter(|p| p.kind == PointKind::Hopf) {
        let l1 = p
            .omega
            .and_then(|w| crate::bifurcation::equilibria::first_lyapunov(model, w))
            .filter(|l| l.is_finite());
        p.l1 = l1;
        let cycles = hopfs
            .iter()
            .find(|h| h.equilibrium.u == p.u)
            .and_then(|h| nearest_hopf_end(&branches, &hopfs, h))
            .map(|n| {
                format!(
                    "cycles of amplitude {:.3} rad/s at u = {} are {}",
                    n.info.omega_l_max - n.info.omega_l_min,
                    n.y[0],
                    if n.info.stable { "stable" } else { "unstable" }
                )
            });
        let crit = match l1 {
            Some(l) if l < 0.0 => format!("supercritical (l1 = {l:.3e} < 0)"),
            Some(l) if l > 0.0 => format!("subcritical (l1 = {l:.3e} > 0)"),
            Some(_) => "degenerate (l1 = 0: a Bautin point)".to_owned(),
            None => "criticality not computed (no first Lyapunov coefficient)".to_owned(),
        };
        p.detail = match cycles {
            Some(c) => format!("{crit}; {} ({c})", p.detail),
            None => format!("{crit}; {}", p.detail),
        };
    }
    // A grazing orbit found both inside a step and at a collapsed branch end is written once:
    // the same kind within 1e-9 V (the two locations agree to the Newton solve's 1e-12 V, see
    // `stuck_end_points`).
    for p in stuck_end_points(model, &branches, opts.point_tol) {
        let seen = points.iter().any(|q| {
            q.kind == p.kind
                && q.discontinuous == p.discontinuous
                && (q.u - p.u).abs() < 1e-9 * p.u.abs().max(1.0)
        });
        if !seen {
            points.push(p);
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
