//! Steady states probed next to the special points of a bifurcation diagram.
//!
//! The event-driven solver answers by its own refinement (Newton on its return map after a
//! settling run, saltation multipliers); the switch model and Moreau–Jean by shooting on
//! their own return maps, checked by a bounded simulation from the probe's start
//! ([`crate::steady::checked`]), so that no probe simulates 20 000 s.
//!
//! Away from bifurcations every solver's steady state is right to its tolerance; next to them
//! the dynamics are slow (a multiplier or eigenvalue near the unit circle), cycles meet (a
//! fold: a stable and an unstable one close together), or a stick phase shrinks to nothing
//! (a grazing orbit). Each probe asks `steady` (see [`crate::steady::steady`]) at an offset of
//! ±1e-3, ±1e-4 or ±1e-6 V from a special point, from rest and from the perturbed
//! equilibrium, and judges the answer against what the continuation says is stable at that
//! input ([`expected`]): the answer must be one of those attractors (its kind, period and
//! extremes), or a refusal that names its cause. A wrong or unstable cycle reported as the
//! steady state is a failure.

use crate::bifurcation::continuation::{ContOptions, Continuer};
use crate::bifurcation::periodic::Shooter;
use crate::bifurcation::{Diagram, PointKind};
use rotor_model::seam::{Attractor, RigSteady, Scene};
use rotor_model::{Model, State};

use crate::solvers::registry::SolverKind;
use crate::steady::checked::{CheckOptions, checked_shot};
use crate::steady::compute::{SteadyAnswer, SteadyError, SteadyOptions, steady};

/// The offsets from each special point \[V\].
pub const OFFSETS: [f64; 6] = [-1e-3, -1e-4, -1e-6, 1e-6, 1e-4, 1e-3];

/// Where a probe starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// `x0 = 0`.
    Rest,
    /// The slipping equilibrium at u (or, below the stick limit, the middle of the stuck
    /// set) with ω_l raised by 1e-3 rad/s, as the fixtures' `eq-pert` scenarios.
    PerturbedEquilibrium,
}

impl Start {
    /// The start's name in tables: `rest` or `eq+1e-3`.
    pub fn as_str(self) -> &'static str {
        match self {
            Start::Rest => "rest",
            Start::PerturbedEquilibrium => "eq+1e-3",
        }
    }

    /// The initial state at input `u`.
    pub fn state(self, model: &Model, u: f64) -> State {
        match self {
            Start::Rest => State::zeros(),
            Start::PerturbedEquilibrium => model.perturbed_equilibrium(u),
        }
    }
}

/// A special point to probe around: its label (e.g. `"hopf"`, or `"grazing/fold"` where two
/// coincide) and input.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbePoint {
    /// The kinds of special point here, joined by `/` (`hopf`, `grazing/fold`).
    pub label: String,
    /// Its input u \[V\].
    pub u: f64,
}

/// The distinct special points of a diagram (points within 1e-9 V of each other, such as a
/// grazing orbit and the discontinuous fold it is, are one probe point).
pub fn probe_points(d: &Diagram) -> Vec<ProbePoint> {
    let mut out: Vec<ProbePoint> = Vec::new();
    for p in &d.points {
        let name = match p.kind {
            PointKind::Fold if p.discontinuous == Some(true) => "discontinuous fold",
            k => k.as_str(),
        };
        match out.iter_mut().find(|q| (q.u - p.u).abs() <= 1e-9) {
            Some(q) => {
                if !q.label.split('/').any(|l| l == name) {
                    q.label = format!("{}/{name}", q.label);
                }
            }
            None => out.push(ProbePoint {
                label: name.to_owned(),
                u: p.u,
            }),
        }
    }
    out.sort_by(|a, b| a.u.total_cmp(&b.u));
    out
}

/// An attractor the continuation says is stable at a given input, with what the answer is
/// compared with: its kind is an [`Attractor`] ([`Expected::attractor`]), the data beside it
/// each kind's own.
#[derive(Debug, Clone, PartialEq)]
pub enum Expected {
    /// A stable slipping equilibrium.
    Equilibrium {
        /// The common velocity ω_u = ω_l \[rad/s\].
        omega: f64,
        /// The twist α \[rad\].
        alpha: f64,
    },
    /// Both discs at rest with α in the stuck set.
    Stuck {
        /// Smallest stuck twist \[rad\].
        alpha_min: f64,
        /// Largest stuck twist \[rad\].
        alpha_max: f64,
    },
    /// A stable periodic orbit (its nontrivial multipliers' largest modulus in `mu`).
    Cycle {
        /// Period \[s\].
        period: f64,
        /// Largest ω_l over the cycle [rad/s].
        omega_l_max: f64,
        /// Smallest ω_l over the cycle [rad/s] (0 with a stick phase).
        omega_l_min: f64,
        /// Time per period with the lower disc stuck \[s\].
        stick_time: f64,
        /// Largest modulus of the nontrivial Floquet multipliers (< 1).
        mu: f64,
    },
}

impl Expected {
    /// Which attractor it is, as the plane and the sweep name what a run reaches.
    pub fn attractor(&self) -> Attractor {
        match *self {
            Expected::Equilibrium { .. } => Attractor::Equilibrium,
            Expected::Stuck { .. } => Attractor::Stuck,
            Expected::Cycle { stick_time, .. } if stick_time > 0.0 => Attractor::StickSlipCycle,
            Expected::Cycle { .. } => Attractor::SlippingCycle,
        }
    }
}

impl std::fmt::Display for Expected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Expected::Equilibrium { omega, alpha } => {
                write!(f, "equilibrium (omega {omega:.6}, alpha {alpha:.6})")
            }
            Expected::Stuck {
                alpha_min,
                alpha_max,
            } => write!(f, "stuck (alpha in [{alpha_min:.6}, {alpha_max:.6}])"),
            Expected::Cycle {
                period,
                omega_l_max,
                omega_l_min,
                mu,
                ..
            } => write!(
                f,
                "cycle (T {period:.6}, omega_l in [{omega_l_min:.6}, {omega_l_max:.6}], |mu| {mu:.4})"
            ),
        }
    }
}

/// What the continuation says is stable at `u`: the stable equilibria (from their
/// eigenvalues), the stuck set, and the stable cycles, each found by Newton's method at `u`
/// from the diagram's neighbouring branch points (and the point between them) and kept if its
/// saltation multipliers lie inside the unit circle.
pub fn expected(model: &Model, d: &Diagram, u: f64) -> Vec<Expected> {
    let mut out = Vec::new();
    for e in model.slip_equilibria(u) {
        if model.equilibrium_is_stable(&e) {
            out.push(Expected::Equilibrium {
                omega: e.omega,
                alpha: e.alpha,
            });
        }
    }
    if let Some(s) = model.stuck_equilibria(u) {
        out.push(Expected::Stuck {
            alpha_min: s.alpha_min,
            alpha_max: s.alpha_max,
        });
    }
    let sh = Shooter { model, tol: 1e-12 };
    let Ok(c) = sh.section_level(u) else {
        return out;
    };
    let cont = Continuer {
        sh,
        // The Hopf start's Newton solve (`hopf_cycle`) stops at this residual.
        opts: ContOptions::at(u, 1e-10),
    };
    // Newton starts: every branch point within 0.02 V of u, nearest first, and where two
    // neighbours bracket u the point between them; next to a Hopf point, on the side its
    // cycles lie, the cycle from the Hopf eigenvector (the branch stops short of the Hopf
    // point, where its amplitude falls below the diagram's `amp_stop`).
    let mut starts: Vec<(f64, [f64; 2])> = Vec::new();
    for (i, a) in d.periodic.iter().enumerate() {
        let za = [a.section_state[0], a.section_state[1]];
        if (a.u - u).abs() <= 0.02 {
            starts.push(((a.u - u).abs(), za));
        }
        if let Some(b) = d.periodic.get(i + 1)
            && a.branch == b.branch
            && (u - a.u) * (u - b.u) <= 0.0
            && a.u != b.u
        {
            let s = (u - a.u) / (b.u - a.u);
            let zb = [b.section_state[0], b.section_state[1]];
            starts.push((
                0.0,
                [za[0] + s * (zb[0] - za[0]), za[1] + s * (zb[1] - za[1])],
            ));
        }
    }
    for p in d.points.iter().filter(|p| p.kind == PointKind::Hopf) {
        if let Some(z) = p.omega.and_then(|w| hopf_start(&cont, w, p.u, u)) {
            starts.push((0.0, z));
        }
    }
    starts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut found: Vec<[f64; 2]> = Vec::new();
    for (_, z0) in starts {
        let Ok(z) = sh.section_fixed_point_exact(u, c, z0, 1e-10) else {
            continue;
        };
        if found
            .iter()
            .any(|f| (f[0] - z[0]).abs().max((f[1] - z[1]).abs()) < 1e-7)
        {
            continue;
        }
        found.push(z);
        let Ok(info) = cont.describe(u, c, z) else {
            continue;
        };
        if info.stable {
            out.push(Expected::Cycle {
                period: info.period,
                omega_l_max: info.omega_l_max,
                omega_l_min: info.omega_l_min,
                stick_time: info.stick_time,
                mu: info.nontrivial.iter().map(|z| z.norm()).fold(0.0, f64::max),
            });
        }
    }
    out
}

/// A start for Newton's method at `u` on the small cycle born at the Hopf point `(u_h,
/// omega_h)`: its amplitude grows as √|u − u_h|, so the cycle of amplitude 0.01 rad/s (from
/// the Hopf eigenvector, [`Continuer::hopf_cycle`]) gives the scale `k = (u₁ − u_h)/0.01²`
/// and the amplitude at u is `√((u − u_h)/k)`. `None` on the side without cycles, or more
/// than 0.02 V away.
fn hopf_start(cont: &Continuer, omega_h: f64, u_h: f64, u: f64) -> Option<[f64; 2]> {
    if (u - u_h).abs() > 0.02 {
        return None;
    }
    let eps1 = 0.01;
    let y1 = cont.hopf_cycle(omega_h, eps1).ok()?;
    let k = (y1[0] - u_h) / (eps1 * eps1);
    let a2 = (u - u_h) / k;
    if a2.is_nan() || a2 <= 0.0 {
        return None;
    }
    let y = cont.hopf_cycle(omega_h, a2.sqrt()).ok()?;
    Some([y[1], y[2]])
}

/// Relative agreement asked of an answer with an attractor of the continuation, per solver
/// ([`crate::solvers::SolverInfo::steady_agreement`]): its accuracy on steady metrics away
/// from special points with a margin, and well below the distance to the nearest other cycle
/// in every probe (the unstable cycle 2e-4 V below the fold E of Table 1 differs from the
/// stable one by 2.4e-3 in max ω_l). The project's solvers:
///
/// * event-driven (tol 1e-12, fixed point to 1e-11) against Newton at 1e-10 on the section:
///   1e-6;
/// * switch model (tol 1e-10, band 1e-7): 1e-5;
/// * Moreau–Jean (h 1e-3; its cycle-to-cycle jitter is 2.5e-7 and its O(h²) error grows
///   as 1/(1 − μ) near a fold): 1e-4.
pub fn agreement(kind: SolverKind) -> f64 {
    kind.info().steady_agreement
}

/// A solver's answer to one probe, judged.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// The answer is the attractor named, within the solver's agreement (its largest
    /// relative difference in `diff`).
    Agrees {
        /// The attractor, as printed.
        attractor: String,
        /// The largest relative difference of period, ω_l extremes (or equilibrium state).
        diff: f64,
    },
    /// No answer, and the error names the cause (a transient too slow to settle, a stick
    /// phase below the step, no cycle next to a weakly unstable equilibrium, a stability the
    /// tolerance cannot decide).
    Refused {
        /// The error's message.
        cause: String,
        /// The cause in a few words, for a table cell (`slow transient`, ...).
        short: &'static str,
    },
    /// No answer, and the error is a failure of the solver rather than a named limit.
    Failed {
        /// The error's message.
        error: String,
    },
    /// An answer that is none of the stable attractors.
    Wrong {
        /// The answer's steady state, as printed.
        answer: String,
        /// The attractors expected at its input, as printed, joined by `; `.
        expected: String,
    },
}

impl Verdict {
    /// A right answer or a refusal that names its cause.
    pub fn acceptable(&self) -> bool {
        matches!(self, Verdict::Agrees { .. } | Verdict::Refused { .. })
    }

    /// A few words for a table cell.
    pub fn short(&self) -> String {
        match self {
            Verdict::Agrees { .. } => "agrees".into(),
            Verdict::Refused { short, .. } => format!("refuses: {short}"),
            Verdict::Failed { .. } => "FAILS".into(),
            Verdict::Wrong { .. } => "WRONG".into(),
        }
    }
}

/// The cause a refusal names, in a few words; `None` for an error that is not a named limit.
fn refusal(e: &SteadyError) -> Option<&'static str> {
    use crate::steady::settle::{SettleError, Unsettled};
    match e {
        SteadyError::Settle(SettleError::NotSettled { cause, .. }) => Some(match cause {
            Unsettled::SlowTransient => "slow transient",
            Unsettled::SlowDecay { .. } => "slow decay",
            Unsettled::SlowGrowth { .. } => "slow growth",
            Unsettled::GrazingBelowStep { .. } => "grazing below step",
        }),
        SteadyError::Undecided { .. } => Some("stability undecided"),
        SteadyError::Unstable { .. } => Some("unstable orbit"),
        SteadyError::Neutral { .. } => Some("stability undecided"),
        SteadyError::NotReached { .. } | SteadyError::Unconfirmed { .. } => Some("slow transient"),
        SteadyError::Shoot(_) => Some("no orbit by shooting"),
        SteadyError::Solve(rotor_model::seam::SolveError::NoConvergence { detail }) => {
            Some(if detail.contains("no cycle near the orbit") {
                "weakly unstable equilibrium"
            } else {
                "no stable fixed point"
            })
        }
        _ => None,
    }
}

/// The largest relative difference between an answer and an attractor (∞ if the kinds
/// differ); `floor` bounds the scale from below (rad/s, s).
fn distance(st: &RigSteady, a: &Expected, floor: f64) -> f64 {
    let rel = |x: f64, y: f64| (x - y).abs() / x.abs().max(y.abs()).max(floor);
    match (*st, a) {
        (
            RigSteady::Equilibrium {
                omega_u,
                omega_l,
                alpha,
            },
            Expected::Equilibrium { omega, alpha: a0 },
        ) => rel(omega_u, *omega)
            .max(rel(omega_l, *omega))
            .max(rel(alpha, *a0)),
        (
            RigSteady::Equilibrium {
                omega_u,
                omega_l,
                alpha,
            },
            Expected::Stuck {
                alpha_min,
                alpha_max,
            },
        ) => {
            let outside = (alpha_min - alpha).max(alpha - alpha_max).max(0.0);
            rel(omega_u, 0.0)
                .max(rel(omega_l, 0.0))
                .max(outside / alpha.abs().max(floor))
        }
        (
            RigSteady::LimitCycle {
                period,
                omega_l_max,
                omega_l_min,
                ..
            },
            Expected::Cycle {
                period: p0,
                omega_l_max: max0,
                omega_l_min: min0,
                ..
            },
        ) => rel(period, *p0)
            .max(rel(omega_l_max, *max0))
            .max(rel(omega_l_min, *min0)),
        _ => f64::INFINITY,
    }
}

/// Judges one answer against the attractors the continuation expects.
pub fn judge(
    kind: SolverKind,
    answer: &Result<SteadyAnswer, SteadyError>,
    expected: &[Expected],
) -> Verdict {
    let st = match answer {
        Ok(a) => a.state,
        Err(e) => {
            return match refusal(e) {
                Some(short) => Verdict::Refused {
                    cause: e.to_string(),
                    short,
                },
                None => Verdict::Failed {
                    error: e.to_string(),
                },
            };
        }
    };
    // Scale floor 1 rad/s (s): extremes near 0 (ω_l,min of a stick-slip cycle) are compared
    // absolutely.
    let best = expected
        .iter()
        .map(|a| (a, distance(&st, a, 1.0)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    match best {
        Some((a, diff)) if diff <= agreement(kind) => Verdict::Agrees {
            attractor: a.to_string(),
            diff,
        },
        _ => Verdict::Wrong {
            answer: format!("{st:?}"),
            expected: expected
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("; "),
        },
    }
}

/// One probe: a solver's steady state at `point.u + offset` from `start`.
#[derive(Debug, Clone, PartialEq)]
pub struct Probe {
    /// The special point probed around.
    pub point: ProbePoint,
    /// The offset from its input \[V\] (one of [`OFFSETS`]).
    pub offset: f64,
    /// Where the run starts.
    pub start: Start,
    /// The solver asked.
    pub kind: SolverKind,
}

impl Probe {
    /// The probe's input: `point.u + offset` \[V\].
    pub fn u(&self) -> f64 {
        self.point.u + self.offset
    }
}

/// Every probe of a diagram: each point × offset × start × solver.
pub fn probes(d: &Diagram, solvers: &[SolverKind]) -> Vec<Probe> {
    let mut out = Vec::new();
    for point in probe_points(d) {
        for offset in OFFSETS {
            for start in [Start::Rest, Start::PerturbedEquilibrium] {
                for &kind in solvers {
                    out.push(Probe {
                        point: point.clone(),
                        offset,
                        start,
                        kind,
                    });
                }
            }
        }
    }
    out
}

/// Runs one probe: the answer and its verdict against `expected` (the attractors at the
/// probe's input).
pub(crate) fn run_probe(
    model: &Model,
    probe: &Probe,
    expected: &[Expected],
) -> (Result<SteadyAnswer, SteadyError>, Verdict) {
    let u = probe.u();
    let scene = Scene {
        u,
        x0: probe.start.state(model, u).as_slice().to_vec(),
        ..Scene::default()
    };
    let answer = if probe.kind == SolverKind::EVENT {
        steady(probe.kind, model, &scene, &SteadyOptions::default())
    } else {
        checked_shot(probe.kind, model, &scene, &CheckOptions::default()).map(|c| c.answer)
    };
    let verdict = judge(probe.kind, &answer, expected);
    (answer, verdict)
}

/// One probe's outcome (for the report and the stress test).
#[derive(Debug, Clone)]
pub struct ProbeRow {
    /// The parameter set's name.
    pub set: String,
    /// What was probed.
    pub probe: Probe,
    /// The answer, judged.
    pub verdict: Verdict,
    /// How the answer was obtained, if there is one.
    pub method: Option<crate::steady::compute::SteadyMethod>,
    /// Wall-clock time of the probe \[s\] (for the timings file only).
    pub seconds: f64,
}

/// Runs `probes` of one parameter set (each with the attractors at its input computed once
/// per input) through `map`, which may run them in parallel: `map(&jobs, f)` must return
/// `jobs.iter().map(f)` in order.
pub fn run_set<M>(set: &str, model: &Model, d: &Diagram, probes: &[Probe], map: M) -> Vec<ProbeRow>
where
    M: Fn(&[Probe], &(dyn Fn(&Probe) -> ProbeRow + Sync)) -> Vec<ProbeRow>,
{
    let mut inputs: Vec<f64> = probes.iter().map(Probe::u).collect();
    inputs.sort_by(f64::total_cmp);
    inputs.dedup();
    // Computed by the first probe at each input that needs them (so in parallel across
    // inputs when `map` is parallel), once.
    let expect: Vec<(f64, std::sync::OnceLock<Vec<Expected>>)> = inputs
        .iter()
        .map(|&u| (u, std::sync::OnceLock::new()))
        .collect();
    let one = |p: &Probe| {
        let u = p.u();
        let attractors = expect
            .iter()
            .find(|(v, _)| *v == u)
            .map(|(_, a)| a.get_or_init(|| expected(model, d, u)).as_slice())
            .unwrap_or(&[]);
        let t = std::time::Instant::now();
        let (answer, verdict) = run_probe(model, p, attractors);
        ProbeRow {
            set: set.to_owned(),
            probe: p.clone(),
            method: answer.as_ref().ok().map(|a| a.method),
            verdict,
            seconds: t.elapsed().as_secs_f64(),
        }
    };
    map(probes, &one)
}

/// The report's table: one line per (set, point, offset, start), one column per solver.
pub fn probe_table_markdown(rows: &[ProbeRow], solvers: &[SolverKind]) -> String {
    let mut out = String::from("| set | point | u [V] | offset | start |");
    for k in solvers {
        out.push_str(&format!(" {} |", k.name()));
    }
    out.push_str("\n|---|---|---|---|---|");
    out.push_str(&"---|".repeat(solvers.len()));
    out.push('\n');
    let mut i = 0;
    while i < rows.len() {
        let r = &rows[i];
        let same = |q: &ProbeRow| {
            q.set == r.set
                && q.probe.point == r.probe.point
                && q.probe.offset == r.probe.offset
                && q.probe.start == r.probe.start
        };
        let group: Vec<&ProbeRow> = rows[i..].iter().take_while(|q| same(q)).collect();
        out.push_str(&format!(
            "| {} | {} | {:.6} | {:+.0e} | {} |",
            r.set,
            r.probe.point.label,
            r.probe.u(),
            r.probe.offset,
            r.probe.start.as_str()
        ));
        for k in solvers {
            let cell = group
                .iter()
                .find(|q| q.probe.kind == *k)
                .map_or("—".to_string(), |q| match q.method {
                    Some(m) => format!("{} ({})", q.verdict.short(), method_name(m)),
                    None => q.verdict.short(),
                });
            out.push_str(&format!(" {cell} |"));
        }
        out.push('\n');
        i += group.len();
    }
    out
}

/// How an answer was obtained, as the JSON of `rotor steady` names it.
fn method_name(m: crate::steady::compute::SteadyMethod) -> &'static str {
    use crate::steady::compute::SteadyMethod::*;
    match m {
        Equilibrium => "equilibrium",
        Refined => "refined",
        Settled => "settled",
        Simulated => "simulated",
        Shoot => "shoot",
    }
}

/// The probes of the stress test and the report: in the full form every point × offset ×
/// start × solver; in the fast form every probe of the event-driven and switch-model solvers
/// and Moreau–Jean's from rest at ±1e-3 V (its other probes cost most of a minute: a
/// transient too slow to settle is followed up to 20 000 s, 2·10⁷ steps).
pub fn selection(d: &Diagram, full: bool) -> Vec<Probe> {
    selection_for(d, full, &crate::solvers::SOLVERS)
}

/// [`selection`] for any list of solvers: a solver that is not the project's (a fourth one,
/// as `tests/fourth_solver.rs` adds) gets the same probes without an edit here; a fixed-step
/// one the fast form's subset, as Moreau–Jean.
pub fn selection_for(d: &Diagram, full: bool, kinds: &[SolverKind]) -> Vec<Probe> {
    probes(d, kinds)
        .into_iter()
        .filter(|p| {
            full || !p.kind.is_fixed_step() || (p.start == Start::Rest && p.offset.abs() == 1e-3)
        })
        .collect()
}

/// The parameter sets probed: Table 1 and the Stribeck set, by name and file (relative to
/// the repository's `fixtures/params/`).
pub const SETS: [(&str, &str); 2] = [("table1", "table1.toml"), ("stribeck", "stribeck.toml")];

/// The report's summary: one line per (set, point), one column per solver, with its answers
/// and refusals counted (refusals by cause).
pub fn probe_summary_markdown(rows: &[ProbeRow], solvers: &[SolverKind]) -> String {
    let mut out = String::from("| set | point | u [V] |");
    for k in solvers {
        out.push_str(&format!(" {} |", k.name()));
    }
    out.push_str("\n|---|---|---|");
    out.push_str(&"---|".repeat(solvers.len()));
    out.push('\n');
    let mut seen: Vec<(&str, &ProbePoint)> = Vec::new();
    for r in rows {
        if seen
            .iter()
            .any(|(s, p)| *s == r.set && **p == r.probe.point)
        {
            continue;
        }
        seen.push((&r.set, &r.probe.point));
        out.push_str(&format!(
            "| {} | {} | {:.6} |",
            r.set, r.probe.point.label, r.probe.point.u
        ));
        for k in solvers {
            let mine: Vec<&ProbeRow> = rows
                .iter()
                .filter(|q| q.set == r.set && q.probe.point == r.probe.point && q.probe.kind == *k)
                .collect();
            let agree = mine
                .iter()
                .filter(|q| matches!(q.verdict, Verdict::Agrees { .. }))
                .count();
            let mut parts = vec![format!("{agree}/{} agree", mine.len())];
            let mut causes: Vec<&str> = Vec::new();
            for q in &mine {
                if let Verdict::Refused { short, .. } = q.verdict
                    && !causes.contains(&short)
                {
                    causes.push(short);
                }
            }
            for c in causes {
                let n = mine
                    .iter()
                    .filter(|q| matches!(q.verdict, Verdict::Refused { short, .. } if short == c))
                    .count();
                parts.push(format!("{n} {c}"));
            }
            let bad = mine.iter().filter(|q| !q.verdict.acceptable()).count();
            if bad > 0 {
                parts.push(format!("**{bad} WRONG/FAILED**"));
            }
            out.push_str(&format!(" {} |", parts.join(", ")));
        }
        out.push('\n');
    }
    out
}
