//! Numerical stress: the three solvers on parameter sets, inputs, horizons and
//! accuracy settings far from the fixtures.
//!
//! Each [`StressCase`] says what it stresses, how answers are compared ([`Measure`]) and, per
//! solver setting, how the agreement is gated ([`Gate`]: derived from the solver's stated
//! accuracy and the case's dynamics; where no a-priori bound is tight enough to mean anything,
//! from the convergence measured on the case, with the numbers in the origin). [`run_case`]
//! runs a case and returns one [`StressRow`] per setting: a solver either finishes with finite
//! states, and then its agreement is measured and gated, or returns a typed [`SolveError`]
//! that says why. [`stress_table_markdown`] renders rows for the report.
//!
//! **Agreement** on sampled runs is the scaled difference
//! `max_t max_i |x_i(t) − x_ref,i(t)| / (1 + max_t |x_ref,i(t)|)` (absolute near rest,
//! relative for large states: the same mixed measure as the adaptive solvers' `rtol = atol`
//! error control).
//!
//! **Gates** (the derivations, with the measurements that back them, are in [`Gate`]'s docs).
//! `ω_f = √(k_θ (1/J_u + 1/J_l))` is the fastest natural frequency of the linear part, `T` the
//! horizon.
//!
//! [`cases`] has a fast form (short horizons, about a second in all, run by CI) and a full form
//! (`ROTOR_STRESS=full`: the 1e5 s horizon and the whole tolerance and step ladders).
//!
//! What the cases show (both forms) is summarised in `reports/measurements.md`.

use std::fmt::Write as _;
use std::time::Instant;

use nalgebra::{Matrix4, Vector4};
use rotor_model::seam::{
    Accuracy, Event, EventKind, Output, RigSteady, Scene, SolveError, Stats, Trajectory,
};
use rotor_model::{Disc, LowerFriction, Model, OMEGA_L, Params, State, UpperFriction};

use rotor_analysis::solvers::registry::{Knob, SOLVERS, SolverKind};

/// The event-driven reference's tolerance (as in the comparison, `run.rs`).
pub const REFERENCE_TOL: f64 = 1e-12;

/// Moreau–Jean's error constant on the period of the Table 1 cycle at u = 1.5 V:
/// `|ΔT| ≈ 0.62 s⁻¹ · h²` (order 1.99; `|ΔT|/h²` measured 0.57–0.64 for h = 1e-2 … 1e-4
/// against the event-driven solver; rotor-moreau's crate docs,
/// `rotor_harness::compare/tests/moreau_order.rs`).
pub const MOREAU_PERIOD_C: f64 = 0.62;

/// How a case's answers are compared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// Samples every `dt` against the event-driven solver at [`REFERENCE_TOL`].
    Transient {
        /// Sample spacing \[s\].
        dt: f64,
    },
    /// Samples every `dt` against the exact solution of the friction-free (linear) system:
    /// the matrix exponential of the affine system ([`linear_exact`]).
    Exact {
        /// Sample spacing \[s\].
        dt: f64,
    },
    /// The run from `(−u, −x0)` against the negated run from `(u, x0)` of the same solver,
    /// sample by sample and unscaled: the friction laws are odd, so this is exact.
    Mirror {
        /// Sample spacing \[s\].
        dt: f64,
    },
    /// The period over `[from, t_end]` against the event-driven solver's (relative).
    Period {
        /// Start of the measured window \[s\].
        from: f64,
    },
    /// A long run: the periods between successive lower-disc stick exits after `from`, their
    /// largest relative deviation from the event-driven solver's first period there (drift
    /// and bias together), and the number of events in each period (must not change).
    Drift {
        /// Start of the measured window \[s\].
        from: f64,
    },
}

impl Measure {
    /// What the agreement column measures.
    pub fn describe(&self) -> &'static str {
        match self {
            Measure::Transient { .. } => "scaled max abs dx vs event",
            Measure::Exact { .. } => "scaled max abs dx vs expm",
            Measure::Mirror { .. } => "max abs(x(-u,-x0) + x(u,x0))",
            Measure::Period { .. } => "rel. period vs event",
            Measure::Drift { .. } => "max rel. period dev. vs event",
        }
    }
}

/// How a setting's agreement is gated. Each variant is a derivation; the numbers quoted are
/// measurements that support it (the full-form table shows them for every case).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gate {
    /// The reference run itself: reported, not compared.
    Reference,
    /// Exactly 0 (mirror symmetry: the friction laws are odd functions and every solver's
    /// arithmetic is sign-symmetric).
    Exact,
    /// A tolerance-controlled solver at `tol`, against a reference at `tol_ref`:
    /// `4·max(1, ω_f T)·(tol + tol_ref)`, plus η for the switch model where the reference
    /// sticks.
    ///
    /// The solvers bound the local error per step by `tol` (mixed abs/rel); on this oscillating
    /// system the global error grows with the accumulated phase of the fastest mode, `ω_f T`
    /// radians. Measured `error / (tol·ω_f T)`: ≤ 0.34 on the Table 1 tolerance ladder
    /// (tol 1e-3 … 1e-13, `ω_f T` = 31), ≤ 0.43 on the linear case (`ω_f T` = 15 and 154),
    /// 0.34 for the light lower disc (745), 0.88–1.05 for the stiff spring over 5 s (770) and
    /// 2.1 over 20 s (3080, the largest): the factor 4 is about 2× that.
    /// η: the switch model holds `|ω| ≤ η` as stuck, so velocities differ from the Filippov
    /// solution by up to η near stick onsets (rotor-switch's η study; measured ≤ 0.8 η scaled);
    /// a run that never sticks is not affected by the band. On most cases this bound is more
    /// than 10× above what it measures (the stiff spring is its worst case); those cases are
    /// gated by [`Gate::Observed`] instead.
    Adaptive,
    /// Moreau–Jean (θ = 1/2) on a sampled run at step `h`:
    /// `ω_f³ h² T / 12 + Σ_reversals 2h·T_s/(J·(1 + max|ω|))`.
    ///
    /// First term: the trapezoidal rule's phase error on an undamped oscillator of frequency
    /// ω_f after time T (exact for the linear case; an upper bound when the modes are damped:
    /// 25× loose on the stiff spring). Second term: at a velocity reversal the one-step
    /// problem may hold the disc at ω = 0 for one step (a spurious one-step stick), i.e. the
    /// friction impulse over that step is off by up to `2h·T_s`, a velocity error of
    /// `2h·T_s/J` — first order in h. Counted from the reference's `Reversal` events (T_s the
    /// disc's static level; 0 without set-valued friction).
    Trapezoid,
    /// Moreau–Jean's period at step `h`: `2·0.62 h²/T_ref` ([`MOREAU_PERIOD_C`], factor 2 for
    /// extrapolating the measured constant to h = 0.5 and 1e-6), plus the reference floor 1e-10.
    MoreauPeriod,
    /// `c·s^p` (`s` the setting's step h, or its tolerance for the adaptive solvers) with the
    /// constant and order measured on the case itself (the origin says where), for dynamics
    /// where no a-priori bound is within 10× of what it measures.
    Measured {
        /// The constant c of `c·s^p`.
        c: f64,
        /// The order p of `c·s^p`.
        p: i32,
        /// Where c and p were measured.
        origin: &'static str,
    },
    /// A stated bound (in the measure's unit) with its origin.
    Fixed(f64, &'static str),
    /// [`OBSERVED_MARGIN`] × the difference measured on this very row (the value given, at
    /// least the rounding floor [`OBSERVED_FLOOR`]): where neither an a-priori bound nor a
    /// convergence law is within 10× of the measurement (the switch model's error, which is
    /// not proportional to its tolerance over the ladder; the reference's own drift).
    Observed(f64),
    /// Not gated: the setting does not resolve the case's time scale (the reason says why).
    /// Reported with its measured agreement; it must still finish with finite states.
    Unresolved(&'static str),
}

/// The margin of [`Gate::Observed`] over the measured difference.
pub const OBSERVED_MARGIN: f64 = 4.0;

/// The smallest [`Gate::Observed`]: scaled differences below 1e-12 are rounding of the runs
/// (event times are located to ~1e-13 s; states are O(1–10) with ~1e-15 rounding per step).
pub const OBSERVED_FLOOR: f64 = 1e-12;

/// Largest gate / measurement ratio the stress table accepts on a gated row (and a
/// measurement of 0 demands a gate of 0): a gate looser than this would pass a real
/// regression, so the tightness is tested along with the agreement.
pub const MAX_LOOSENESS: f64 = 10.0;

/// One solver at one accuracy setting, with its gate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// The solver.
    pub kind: SolverKind,
    /// The solver's tolerance (adaptive) or step (Moreau–Jean).
    pub accuracy: Accuracy,
    /// How its agreement is gated.
    pub gate: Gate,
}

impl Setting {
    /// The event-driven reference.
    pub fn reference() -> Setting {
        Setting {
            kind: SolverKind::EVENT,
            accuracy: Accuracy::Tol(REFERENCE_TOL),
            gate: Gate::Reference,
        }
    }

    /// An adaptive solver at `tol`, gated by [`Gate::Adaptive`].
    pub fn adaptive(kind: SolverKind, tol: f64) -> Setting {
        Setting {
            kind,
            accuracy: Accuracy::Tol(tol),
            gate: Gate::Adaptive,
        }
    }

    /// Every solver at the comparison-grade defaults (tol 1e-10, h = 1e-3), one gate.
    pub fn every_solver(gate: Gate) -> Vec<Setting> {
        SOLVERS
            .iter()
            .map(|&kind| Setting {
                kind,
                accuracy: kind.accuracy(kind.info().default),
                gate,
            })
            .collect()
    }

    /// Moreau–Jean at step `h` with a gate.
    pub fn moreau(h: f64, gate: Gate) -> Setting {
        Setting {
            kind: SolverKind::MOREAU,
            accuracy: Accuracy::Step(h),
            gate,
        }
    }

    fn label(&self) -> String {
        self.kind.setting_label(self.accuracy.value())
    }
}

/// A stress case: what it stresses, the model and scene, the measure, and the settings.
#[derive(Debug, Clone, PartialEq)]
pub struct StressCase {
    /// The case's name in the table (and the `stress_cases` test's messages).
    pub name: &'static str,
    /// One line for the table: what is stressed.
    pub what: String,
    /// Its parameter set (Table 1 or a variant of it that stresses something).
    pub params: Params,
    /// Motor input voltage u \[V\].
    pub u: f64,
    /// Initial state `[α, ω_u, ω_l]` (rad, rad/s, rad/s).
    pub x0: State,
    /// Horizon \[s\].
    pub t_end: f64,
    /// How the settings' answers are compared.
    pub measure: Measure,
    /// The solvers and accuracy settings run on it, each with its gate.
    pub settings: Vec<Setting>,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Finished; every kept state finite.
    Finished,
    /// The solver's typed error.
    Failed(SolveError),
}

impl Outcome {
    /// Short name of the outcome: `ok`, or the kind of error.
    pub fn kind(&self) -> &'static str {
        match self {
            Outcome::Finished => "ok",
            Outcome::Failed(e) => match e {
                SolveError::InvalidScene(_) => "invalid scene",
                SolveError::StepSizeUnderflow { .. } => "step size underflow",
                SolveError::NonFinite { .. } => "non-finite state",
                SolveError::Complementarity { .. } => "complementarity failure",
                SolveError::Zeno { .. } => "Zeno-like event accumulation",
                SolveError::TooManySteps { .. } => "step limit",
                SolveError::NoConvergence { .. } => "no convergence",
                SolveError::Unsupported { .. } => "unsupported",
                SolveError::NonFiniteOutput { .. } => "non-finite output",
            },
        }
    }

    /// Whether the outcome is acceptable on an admissible case: finished, or a typed error
    /// that names a numerical limit (not a refused scene, a NaN, or an unsupported request).
    pub fn acceptable(&self) -> bool {
        match self {
            Outcome::Finished => true,
            Outcome::Failed(e) => matches!(
                e,
                SolveError::StepSizeUnderflow { .. }
                    | SolveError::Complementarity { .. }
                    | SolveError::Zeno { .. }
                    | SolveError::TooManySteps { .. }
            ),
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Outcome::Finished => write!(f, "ok"),
            Outcome::Failed(e) => write!(f, "{e}"),
        }
    }
}

/// The result of one setting of one case.
#[derive(Debug, Clone, PartialEq)]
pub struct StressRow {
    /// The case's name ([`StressCase::name`]).
    pub case: &'static str,
    /// What the case stresses ([`StressCase::what`]).
    pub what: String,
    /// The solver run.
    pub solver: SolverKind,
    /// `tol 1e-10` or `h 1e-3`.
    pub setting: String,
    /// How the run ended.
    pub outcome: Outcome,
    /// Work counters of the run (Moreau's `inexact_steps` flags steps that fell back to a
    /// fixed-point iterate).
    pub stats: Stats,
    /// What `agreement` measures ([`Measure::describe`]).
    pub measure: &'static str,
    /// The measured agreement; `None` if not measured (the reference itself, or a run that
    /// did not finish on either side).
    pub agreement: Option<f64>,
    /// The gate's value for this run (`None` for the reference) and its kind.
    pub gate: Option<f64>,
    /// The gate's kind.
    pub gate_kind: Gate,
    /// Events per period seen in a [`Measure::Drift`] run: (min, max).
    pub events_per_period: Option<(usize, usize)>,
    /// Wall-clock run time \[s\] (reported, never asserted).
    pub seconds: f64,
}

impl StressRow {
    /// Finished within the gate (or the reference), or a typed error naming a numerical
    /// limit. A finished, gated run whose agreement could not be measured fails.
    pub fn passes(&self) -> bool {
        if !self.outcome.acceptable() {
            return false;
        }
        if self.outcome != Outcome::Finished {
            return true;
        }
        if let Some((lo, hi)) = self.events_per_period
            && lo != hi
        {
            return false;
        }
        match (self.agreement, self.gate) {
            (Some(a), Some(g)) => a <= g,
            (None, Some(_)) => false,
            (_, None) => true,
        }
    }
}

/// Runs one solver on a scene: the outcome, the trajectory if it finished with finite output,
/// and the run time.
fn run(kind: SolverKind, model: &Model, scene: &Scene) -> (Outcome, Option<Trajectory>, f64) {
    let t0 = Instant::now();
    let res = kind.solver().simulate_finite(model, scene);
    let seconds = t0.elapsed().as_secs_f64();
    match res {
        Err(e) => (Outcome::Failed(e), None, seconds),
        Ok(tr) => (Outcome::Finished, Some(tr), seconds),
    }
}

/// Scaled max difference of two sample lists on the same grid (see the module docs); the
/// scale is `b`'s. Different grids give ∞; a NaN propagates.
pub(crate) fn scaled_difference(a: &[(f64, State)], b: &[(f64, State)]) -> f64 {
    if a.len() != b.len() || a.iter().zip(b).any(|(p, q)| p.0 != q.0) {
        return f64::INFINITY;
    }
    let mut scale = [0.0f64; 3];
    for (_, x) in b {
        for (s, v) in scale.iter_mut().zip(x.iter()) {
            *s = s.max(v.abs());
        }
    }
    let mut d: f64 = 0.0;
    for ((_, x), (_, y)) in a.iter().zip(b) {
        for i in 0..3 {
            let e = (x[i] - y[i]).abs() / (1.0 + scale[i]);
            d = if e > d || e.is_nan() { e } else { d };
        }
    }
    d
}

/// `max |a + b|` over samples on the same grid, unscaled (the mirror measure).
fn mirror_difference(a: &[(f64, State)], b: &[(f64, State)]) -> f64 {
    if a.len() != b.len() || a.iter().zip(b).any(|(p, q)| p.0 != q.0) {
        return f64::INFINITY;
    }
    let mut d: f64 = 0.0;
    for ((_, x), (_, y)) in a.iter().zip(b) {
        for i in 0..3 {
            let e = (x[i] + y[i]).abs();
            d = if e > d || e.is_nan() { e } else { d };
        }
    }
    d
}

fn samples(tr: &Trajectory) -> Vec<(f64, State)> {
    tr.samples.iter().map(|s| (s.t, s.state())).collect()
}

/// The exact solution of the friction-free system at `times`: `x(t) = [exp(M t) z0]_{0..3}`
/// with `z = [α, ω_u, ω_l, 1]` and the affine system `α̇ = ω_u − ω_l`,
/// `J_u ω̇_u = k_m u − k_θ α`, `J_l ω̇_l = k_θ α` (friction parameters of `p` are ignored).
pub fn linear_exact(p: &Params, u: f64, x0: &State, times: &[f64]) -> Vec<(f64, State)> {
    #[rustfmt::skip]
    let m = Matrix4::new(
        0.0,                1.0, -1.0, 0.0,
        -p.k_theta / p.j_u, 0.0, 0.0,  p.k_m * u / p.j_u,
        p.k_theta / p.j_l,  0.0, 0.0,  0.0,
        0.0,                0.0, 0.0,  0.0,
    );
    let z0 = Vector4::new(x0[0], x0[1], x0[2], 1.0);
    times
        .iter()
        .map(|&t| {
            let z = (m * t).exp() * z0;
            (t, State::new(z[0], z[1], z[2]))
        })
        .collect()
}

/// Fastest natural frequency of the linear part, `√(k_θ (1/J_u + 1/J_l))` [rad/s].
pub(crate) fn omega_fast(p: &Params) -> f64 {
    (p.k_theta * (1.0 / p.j_u + 1.0 / p.j_l)).sqrt()
}

/// Periods between successive lower-disc stick exits at or after `from`, each with the
/// number of events inside it.
fn periods(events: &[Event], from: f64) -> Vec<(f64, usize)> {
    let mut out = Vec::new();
    let mut last: Option<(f64, usize)> = None;
    for (i, e) in events.iter().enumerate() {
        if e.t < from || e.kind != EventKind::StickEnd(Disc::LOWER) {
            continue;
        }
        if let Some((t0, i0)) = last {
            out.push((e.t - t0, i - i0));
        }
        last = Some((e.t, i));
    }
    out
}

fn period_of(tr: &Trajectory) -> Option<f64> {
    match tr.rig_metrics() {
        Some(RigSteady::LimitCycle { period, .. }) => Some(period),
        _ => None,
    }
}

/// The scene of a case for one setting, from `(u, x0)`.
fn scene_of(case: &StressCase, s: &Setting, u: f64, x0: State) -> Scene {
    let (output, metrics_from) = match case.measure {
        Measure::Transient { dt } | Measure::Exact { dt } | Measure::Mirror { dt } => {
            (Output::Grid { dt }, None)
        }
        Measure::Period { from } => (Output::Final, Some(from)),
        Measure::Drift { from } => (Output::Events, Some(from)),
    };
    Scene {
        u,
        input: None,
        x0: x0.as_slice().to_vec(),
        t_end: case.t_end,
        // A step longer than the horizon is cut to it.
        accuracy: match s.accuracy {
            Accuracy::Step(h) => Accuracy::Step(h.min(case.t_end)),
            tol => tol,
        },
        output,
        metrics_from,
    }
}

/// The reversal term of [`Gate::Trapezoid`] from a run's events (scaled like the measure).
fn reversal_term(p: &Params, events: &[Event], samples: &[(f64, State)], h: f64) -> f64 {
    let scale = |i: usize| 1.0 + samples.iter().map(|s| s.1[i].abs()).fold(0.0, f64::max);
    let mut sum = 0.0;
    for e in events {
        let (t_s, j, i) = match e.kind {
            EventKind::Reversal(Disc::UPPER) => (p.upper.t_s, p.j_u, 1),
            EventKind::Reversal(Disc::LOWER) => (p.lower.static_level(), p.j_l, OMEGA_L),
            _ => continue,
        };
        sum += 2.0 * h * t_s / (j * scale(i));
    }
    sum
}

/// The value of a gate for a finished run (`reference`: the event-driven reference, if the
/// measure has one; `run`: the run itself).
fn gate_value(
    case: &StressCase,
    s: &Setting,
    reference: Option<&Trajectory>,
    run: &Trajectory,
) -> Option<f64> {
    let p = &case.params;
    let phase = omega_fast(p) * case.t_end;
    match s.gate {
        Gate::Reference | Gate::Unresolved(_) => None,
        Gate::Exact => Some(0.0),
        Gate::Measured { c, p, .. } => Some(c * s.accuracy.value().powi(p)),
        Gate::Fixed(v, _) => Some(v),
        Gate::Observed(e) => Some((OBSERVED_MARGIN * e).max(OBSERVED_FLOOR)),
        Gate::Adaptive => {
            let tol_ref = match case.measure {
                Measure::Exact { .. } | Measure::Mirror { .. } => 0.0,
                _ => REFERENCE_TOL,
            };
            let sticks = reference.is_some_and(|r| {
                r.events
                    .iter()
                    .any(|e| matches!(e.kind, EventKind::StickStart(_)))
            });
            // a solver that holds a stuck disc in a band of its own adds that band
            let eta = if sticks {
                s.kind.info().stuck_band
            } else {
                0.0
            };
            Some(4.0 * phase.max(1.0) * (s.accuracy.tol() + tol_ref) + eta)
        }
        Gate::Trapezoid => {
            let w = omega_fast(p);
            let h = s.accuracy.step();
            let trapezoid = w.powi(3) * h * h * case.t_end / 12.0;
            let base = reference.unwrap_or(run);
            Some(trapezoid + reversal_term(p, &base.events, &samples(base), h))
        }
        Gate::MoreauPeriod => {
            let t_ref = reference.and_then(|r| {
                period_of(r).or_else(|| {
                    let ps = periods(&r.events, 0.0);
                    ps.first().map(|p| p.0)
                })
            })?;
            let h = s.accuracy.step();
            Some(2.0 * MOREAU_PERIOD_C * h * h / t_ref + 1e-10)
        }
    }
}

/// Runs a case: one row per setting, in order.
pub fn run_case(case: &StressCase) -> Vec<StressRow> {
    let model = Model::new(case.params);
    // The event-driven reference (the exact and mirror measures need none).
    let reference = match case.measure {
        Measure::Transient { .. } | Measure::Period { .. } | Measure::Drift { .. } => {
            let s = Setting::reference();
            run(
                SolverKind::EVENT,
                &model,
                &scene_of(case, &s, case.u, case.x0),
            )
            .1
        }
        Measure::Exact { .. } | Measure::Mirror { .. } => None,
    };
    case.settings
        .iter()
        .map(|s| {
            let scene = scene_of(case, s, case.u, case.x0);
            let (mut outcome, tr, mut seconds) = run(s.kind, &model, &scene);
            let mut agreement = None;
            let mut events_per_period = None;
            let mut gate = None;
            if let Some(tr) = &tr {
                gate = gate_value(case, s, reference.as_ref(), tr);
                match case.measure {
                    Measure::Transient { .. } => {
                        agreement = reference
                            .as_ref()
                            .map(|r| scaled_difference(&samples(tr), &samples(r)));
                    }
                    Measure::Exact { .. } => {
                        let times: Vec<f64> = tr.samples.iter().map(|s| s.t).collect();
                        let exact = linear_exact(&case.params, case.u, &case.x0, &times);
                        agreement = Some(scaled_difference(&samples(tr), &exact));
                    }
                    Measure::Mirror { .. } => {
                        let mirror = scene_of(case, s, -case.u, -case.x0);
                        let (o, m, sec) = run(s.kind, &model, &mirror);
                        seconds += sec;
                        match m {
                            Some(m) => {
                                agreement = Some(mirror_difference(&samples(tr), &samples(&m)))
                            }
                            None => outcome = o,
                        }
                    }
                    Measure::Period { .. } => {
                        agreement = match (period_of(tr), reference.as_ref().and_then(period_of)) {
                            (Some(a), Some(b)) => Some(((a - b) / b).abs()),
                            _ => None,
                        };
                    }
                    Measure::Drift { from } => {
                        let ps = periods(&tr.events, from);
                        let r = reference
                            .as_ref()
                            .and_then(|r| periods(&r.events, from).first().map(|p| p.0));
                        if let (Some(r), false) = (r, ps.is_empty()) {
                            agreement =
                                Some(ps.iter().map(|p| ((p.0 - r) / r).abs()).fold(0.0, f64::max));
                            let lo = ps.iter().map(|p| p.1).min().unwrap_or(0);
                            let hi = ps.iter().map(|p| p.1).max().unwrap_or(0);
                            events_per_period = Some((lo, hi));
                        }
                    }
                }
            }
            StressRow {
                case: case.name,
                what: case.what.clone(),
                solver: s.kind,
                setting: s.label(),
                outcome,
                stats: tr.as_ref().map(|t| t.stats).unwrap_or_default(),
                measure: case.measure.describe(),
                agreement,
                gate,
                gate_kind: s.gate,
                events_per_period,
                seconds,
            }
        })
        .collect()
}

fn gate_origin(g: Gate) -> String {
    match g {
        Gate::Reference => "reference".into(),
        Gate::Exact => "exact".into(),
        Gate::Adaptive => "4 max(1, w_f T)(tol + tol_ref) [+ eta if it sticks]".into(),
        Gate::Trapezoid => "w_f^3 h^2 T/12 + 2h T_s/J per reversal".into(),
        Gate::MoreauPeriod => "2 x 0.62 h^2 / period".into(),
        Gate::Measured { origin, .. } => origin.into(),
        Gate::Fixed(_, origin) => origin.into(),
        Gate::Observed(e) => format!("{OBSERVED_MARGIN}x measured {e:.2e}"),
        Gate::Unresolved(why) => why.into(),
    }
}

impl StressRow {
    /// gate / agreement: how loose the gate is on this row (`None` for rows without a gate or
    /// a measurement; ∞ for a positive gate on a measured 0).
    pub fn looseness(&self) -> Option<f64> {
        match (self.agreement, self.gate) {
            (Some(a), Some(g)) if a > 0.0 => Some(g / a),
            (Some(_), Some(g)) if g > 0.0 => Some(f64::INFINITY),
            (Some(_), Some(_)) => Some(1.0),
            _ => None,
        }
    }
}

/// The run time of every row, as a Markdown table (for the uncommitted timings file).
pub(crate) fn stress_timings_markdown(rows: &[StressRow]) -> String {
    let mut s = String::from("| case | solver | setting | time [ms] |\n|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} |",
            r.case,
            r.solver.name(),
            r.setting,
            r.seconds * 1e3
        );
    }
    s
}

/// The rows as a Markdown table (for the report): case, solver, setting, outcome, measured
/// agreement against its gate and the gate's origin.
pub fn stress_table_markdown(rows: &[StressRow]) -> String {
    let mut s = String::from(
        "| case | what | solver | setting | outcome | measure | agreement | gate | margin | gate origin | |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut last_case = "";
    for r in rows {
        let (case, what) = if r.case == last_case {
            ("", "")
        } else {
            (r.case, r.what.as_str())
        };
        last_case = r.case;
        let mut outcome = match &r.outcome {
            Outcome::Finished => "ok".to_string(),
            o => format!("{}: {}", o.kind(), o.to_string().replace('|', "/")),
        };
        if let Some((lo, hi)) = r.events_per_period {
            if lo == hi {
                let _ = write!(outcome, ", {lo} events/period");
            } else {
                let _ = write!(outcome, ", {lo}..{hi} events/period");
            }
        }
        if r.stats.inexact_steps > 0 {
            let _ = write!(outcome, ", {} inexact steps", r.stats.inexact_steps);
        }
        let num = |v: Option<f64>| v.map_or("—".into(), |v| format!("{v:.2e}"));
        let verdict = if r.passes() { "ok" } else { "**FAIL**" };
        let _ = writeln!(
            s,
            "| {case} | {what} | {} | {} | {outcome} | {} | {} | {} | {} | {} | {verdict} |",
            r.solver.name(),
            r.setting,
            r.measure,
            if r.gate_kind == Gate::Reference {
                "ref".into()
            } else {
                num(r.agreement)
            },
            num(r.gate),
            match r.looseness() {
                Some(l) if l.is_finite() && r.agreement.is_some_and(|a| a > 0.0) =>
                    format!("{l:.1}"),
                Some(l) if l.is_finite() => "exact".into(),
                Some(_) => "—".into(),
                None => "".into(),
            },
            gate_origin(r.gate_kind),
        );
    }
    s
}

// ---------------------------------------------------------------------------------------
// The cases.

/// Table 1 with the lower-disc law replaced (exponential family, Table 1's w_1, w_2).
fn with_lower(p: Params, t_s: f64, t_1: f64, t_2: f64, b: f64) -> Params {
    let (w_1, w_2) = match p.lower {
        LowerFriction::Exponential { w_1, w_2, .. } => (w_1, w_2),
        LowerFriction::Stribeck { .. } => (5.7468, 0.2941),
    };
    Params {
        lower: LowerFriction::Exponential {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            b,
        },
        ..p
    }
}

/// Whether the full form is asked (`ROTOR_STRESS=full`).
pub fn full_from_env() -> bool {
    std::env::var("ROTOR_STRESS").is_ok_and(|v| v == "full")
}

/// The event-driven reference, the switch model at 1e-10 with `switch` as its gate, and
/// Moreau–Jean at each step of `hs` with the trapezoid bound.
fn three(switch: Gate, hs: &[f64]) -> Vec<Setting> {
    let mut v = vec![
        Setting::reference(),
        Setting {
            gate: switch,
            ..Setting::adaptive(SolverKind::SWITCH, 1e-10)
        },
    ];
    v.extend(hs.iter().map(|&h| Setting::moreau(h, Gate::Trapezoid)));
    v
}

/// The errors measured on the tolerance ladder (u = 1.5 V from rest, 20 s, scaled max
/// difference against the reference at 1e-12): `(tol, event, switch)`. Neither solver's error
/// is proportional to its tolerance over the ladder (the switch model's saturates at 5.2e-5
/// for tol ≥ 1e-4; below 1e-11 the switch model's levels off at its band's 1e-10), so each
/// rung is gated by its own measurement ([`Gate::Observed`]). Re-measured (full ladder) with
/// the event solver's step bound tied to the friction law's scale: its error fell 3.8× at
/// 1e-9 and 5.3× at 1e-13 (the reference moved with it), and rose from 7.40e-6 to 9.75e-6 at
/// 1e-6, where the bound only reorders the long steps.
const LADDER: [(f64, f64, f64); 11] = [
    (1e-3, 1.77e-3, 5.24e-5),
    (1e-4, 4.10e-4, 5.24e-5),
    (1e-5, 5.15e-5, 1.37e-5),
    (1e-6, 9.75e-6, 1.76e-6),
    (1e-7, 2.44e-7, 3.10e-7),
    (1e-8, 4.61e-8, 5.92e-8),
    (1e-9, 2.19e-9, 7.13e-9),
    (1e-10, 4.95e-10, 6.44e-10),
    (1e-11, 7.62e-11, 7.53e-11),
    // The event-driven solver at the reference's own tolerance is the reference: 0. The
    // switch model's error levels off at its band's O(η) (η = 1e-10: a stuck disc keeps
    // ω = η, so the spring drifts).
    (1e-12, 0.0, 9.85e-11),
    (1e-13, 4.25e-12, 1.02e-10),
];

/// The stress cases for the project's solvers; `full` adds the long horizon and the whole
/// ladders.
pub fn cases(full: bool) -> Vec<StressCase> {
    cases_for(full, &SOLVERS)
}

/// The stress cases for any list of solvers. The project's solvers keep their settings and
/// their gates, measured or derived per case (rows of a project solver not in `kinds` are
/// left out; the event-driven reference runs regardless). Every other solver (a fourth one,
/// as `tests/fourth_solver.rs` adds) gets one row per case at its comparison setting, without
/// an edit here, gated by what holds for any solver ([`newcomer_gate`]).
pub fn cases_for(full: bool, kinds: &[SolverKind]) -> Vec<StressCase> {
    let listed = |k: SolverKind| kinds.iter().any(|o| o.name() == k.name());
    let project = |k: SolverKind| SOLVERS.iter().any(|o| o.name() == k.name());
    let mut v = project_cases(full);
    for case in &mut v {
        case.settings
            .retain(|s| s.gate == Gate::Reference || listed(s.kind));
        for &kind in kinds.iter().filter(|&&k| !project(k)) {
            case.settings.push(Setting {
                kind,
                accuracy: kind.accuracy(kind.info().comparison),
                gate: newcomer_gate(kind, case.measure),
            });
        }
    }
    v
}

/// The gate a solver that is not the project's gets on a case, from what holds for any
/// solver: the mirror symmetry exactly ([`Gate::Exact`]: the laws are odd, and sign-symmetric
/// arithmetic keeps it to the bit); a tolerance-controlled solver's a-priori bound
/// ([`Gate::Adaptive`], with its own stuck band); a fixed-step solver reported, not gated (no
/// a-priori bound without its order and constant: measure them and give it its gates).
pub fn newcomer_gate(kind: SolverKind, measure: Measure) -> Gate {
    match (measure, kind.info().knob) {
        (Measure::Mirror { .. }, _) => Gate::Exact,
        (_, Knob::Tolerance) => Gate::Adaptive,
        (_, Knob::Step) => Gate::Unresolved(
            "not gated: a fixed-step solver new to the project has no a-priori bound here; \
             measure its order and constant",
        ),
    }
}

/// The project's stress cases, with each solver's settings and gates.
fn project_cases(full: bool) -> Vec<StressCase> {
    let t1 = Params::table1();
    let rest = State::zeros();
    let pick = |fast: f64, long: f64| if full { long } else { fast };
    // Moreau–Jean steps that divide the 0.01 s grid (samples fall on step ends).
    let fine: &[f64] = if full {
        &[1e-3, 1e-4, 1e-5]
    } else {
        &[1e-3, 1e-4]
    };
    let mut v = vec![
        StressCase {
            name: "stiff-spring",
            what: "k_theta x 1e4 (w_f = 154 rad/s)".into(),
            params: Params {
                k_theta: t1.k_theta * 1e4,
                ..t1
            },
            u: 1.5,
            x0: rest,
            t_end: pick(5.0, 20.0),
            measure: Measure::Transient { dt: 0.01 },
            settings: {
                // The trapezoid bound is 25x above the measured error here: the fast mode is
                // damped, so its phase error does not grow over the whole horizon. Measured
                // convergence instead; over 20 s, h = 1e-3 is not yet asymptotic (its phase
                // error is O(1)), so it is gated by its own measurement.
                let mut s = three(Gate::Adaptive, &[]);
                if full {
                    s.push(Setting::moreau(1e-3, Gate::Observed(1.67e-1)));
                    let law = Gate::Measured {
                        c: 4.5e6,
                        p: 2,
                        origin: "4x measured e/h^2 = 1.12e6, 1.11e6 at h = 1e-4, 1e-5 (20 s)",
                    };
                    s.extend([1e-4, 1e-5].map(|h| Setting::moreau(h, law)));
                } else {
                    let law = Gate::Measured {
                        c: 2.5e5,
                        p: 2,
                        origin: "4x measured e/h^2 = 5.8e4, 6.3e4 at h = 1e-3, 1e-4 (5 s)",
                    };
                    s.extend([1e-3, 1e-4].map(|h| Setting::moreau(h, law)));
                }
                s
            },
        },
        StressCase {
            name: "light-lower-disc",
            what: "J_l x 1e-4 (w_f = 149 rad/s, J_l/b_l = 0.3 ms)".into(),
            params: Params {
                j_l: t1.j_l * 1e-4,
                ..t1
            },
            u: 1.5,
            x0: rest,
            // Not longer in the full form: the bursts of the slipping disc amplify errors
            // (Moreau at h = 1e-5: 7.8e-4 over 5 s, 1.4e-2 over 20 s), so the measured
            // constant below belongs to this horizon.
            t_end: 5.0,
            measure: Measure::Transient { dt: 0.01 },
            settings: {
                // The a-priori trapezoid bound is not one here: the slipping lower disc's
                // friction slope makes rates of |dT_fl/dw|/J_l ~ 1e4 /s (falling branch:
                // growing), far above w_f. So the gate is the measured convergence.
                let measured = Gate::Measured {
                    c: 4.0 * 7.8e6,
                    p: 2,
                    origin: "4x measured e/h^2 = 7.8e6, 7.5e6, 7.8e6 at h = 1e-4, 3e-5, 1e-5",
                };
                let mut s = three(Gate::Observed(3.56e-8), &[]);
                s.push(Setting::moreau(
                    1e-3,
                    Gate::Unresolved("not gated: h = 3 J_l/b_l, the disc's time scale"),
                ));
                let hs: &[f64] = if full { &[1e-4, 1e-5] } else { &[1e-4] };
                s.extend(hs.iter().map(|&h| Setting::moreau(h, measured)));
                s
            },
        },
    ];
    let linear = Params {
        upper: UpperFriction {
            t_s: 0.0,
            dt_s: 0.0,
            b: 0.0,
            db: 0.0,
        },
        ..with_lower(t1, 0.0, 0.0, 0.0, 0.0)
    };
    // Against the exact solution the event-driven solver is gated too. Both adaptive solvers'
    // errors are 5-20x below the a-priori tolerance bound (no stick, so no band either).
    let mut lin = three(Gate::Observed(pick(3.34e-10, 6.23e-9)), fine);
    lin[0] = Setting {
        gate: Gate::Observed(pick(6.66e-12, 2.40e-11)),
        ..Setting::adaptive(SolverKind::EVENT, REFERENCE_TOL)
    };
    v.push(StressCase {
        name: "zero-friction",
        what: "no friction: linear, against expm".into(),
        params: linear,
        u: 1.5,
        x0: State::new(0.1, 0.0, 0.0),
        t_end: pick(10.0, 100.0),
        measure: Measure::Exact { dt: 0.01 },
        settings: lin,
    });
    v.push(StressCase {
        name: "pure-coulomb",
        what: "T_1 = T_2 = b_l = 0: constant Coulomb level".into(),
        params: with_lower(t1, t1.lower.static_level(), 0.0, 0.0, 0.0),
        u: 1.5,
        x0: rest,
        t_end: pick(20.0, 60.0),
        measure: Measure::Transient { dt: 0.01 },
        settings: three(Gate::Observed(pick(4.16e-10, 1.02e-9)), fine),
    });
    v.push(StressCase {
        name: "large-input",
        what: "u = 100 V".into(),
        params: t1,
        u: 100.0,
        x0: rest,
        t_end: pick(5.0, 20.0),
        measure: Measure::Transient { dt: 0.01 },
        settings: three(Gate::Observed(pick(5.04e-11, 8.69e-11)), fine),
    });
    for (name, x0) in [
        ("mirror-rest", rest),
        ("mirror-moving", State::new(0.3, 1.0, -0.5)),
    ] {
        let exact = |kind, accuracy| Setting {
            kind,
            accuracy,
            gate: Gate::Exact,
        };
        v.push(StressCase {
            name,
            what: format!(
                "x(-u, -x0) = -x(u, x0) at u = 1.5 V, x0 = [{}, {}, {}]",
                x0[0], x0[1], x0[2]
            ),
            params: t1,
            u: 1.5,
            x0,
            t_end: pick(20.0, 100.0),
            measure: Measure::Mirror { dt: 0.01 },
            settings: vec![
                exact(SolverKind::EVENT, Accuracy::Tol(REFERENCE_TOL)),
                exact(SolverKind::SWITCH, Accuracy::Tol(1e-10)),
                exact(SolverKind::MOREAU, Accuracy::Step(1e-3)),
            ],
        });
    }
    v.push(StressCase {
        name: "far-from-rest",
        what: "x0 = [5 rad, 20 rad/s, -20 rad/s]: four reversals".into(),
        params: t1,
        u: 1.5,
        x0: State::new(5.0, 20.0, -20.0),
        t_end: pick(10.0, 40.0),
        measure: Measure::Transient { dt: 0.01 },
        settings: three(Gate::Observed(pick(1.16e-10, 3.55e-10)), fine),
    });
    let t_long = pick(1e3, 1e5);
    v.push(StressCase {
        name: "long-horizon",
        what: format!("u = 1.5 V over {t_long:.0e} s: period and events/period"),
        params: t1,
        u: 1.5,
        x0: rest,
        t_end: t_long,
        measure: Measure::Drift { from: 100.0 },
        settings: vec![
            // The reference against its own first period: drift and rounding only (over 1e3 s
            // at the rounding floor).
            Setting {
                gate: Gate::Observed(pick(1.52e-13, 3.06e-11)),
                ..Setting::reference()
            },
            Setting {
                gate: Gate::Observed(pick(2.83e-11, 1.12e-10)),
                ..Setting::adaptive(SolverKind::SWITCH, 1e-10)
            },
            Setting::moreau(1e-3, Gate::MoreauPeriod),
        ],
    });
    let rungs: Vec<(f64, f64, f64)> = LADDER
        .into_iter()
        .filter(|r| full || [1e-3, 1e-6, 1e-9, 1e-13].contains(&r.0))
        .collect();
    v.push(StressCase {
        name: "tolerance-ladder",
        what: "tol 1e-3 .. 1e-13, u = 1.5 V from rest".into(),
        params: t1,
        u: 1.5,
        x0: rest,
        t_end: 20.0,
        measure: Measure::Transient { dt: 0.01 },
        settings: rungs
            .iter()
            .flat_map(|&(tol, event, switch)| {
                let event_gate = if event == 0.0 {
                    Gate::Exact
                } else {
                    Gate::Observed(event)
                };
                [
                    Setting {
                        gate: event_gate,
                        ..Setting::adaptive(SolverKind::EVENT, tol)
                    },
                    Setting {
                        gate: Gate::Observed(switch),
                        ..Setting::adaptive(SolverKind::SWITCH, tol)
                    },
                ]
            })
            .collect(),
    });
    let steps: &[f64] = if full {
        &[0.5, 0.25, 0.1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
    } else {
        &[0.5, 0.1, 1e-2, 1e-3]
    };
    v.push(StressCase {
        name: "step-ladder",
        what: "Moreau-Jean h = 0.5 .. 1e-6 s, u = 1.5 V, period over [30, 60] s".into(),
        params: t1,
        u: 1.5,
        x0: rest,
        t_end: 60.0,
        measure: Measure::Period { from: 30.0 },
        settings: steps
            .iter()
            .map(|&h| Setting::moreau(h, Gate::MoreauPeriod))
            .collect(),
    });
    v
}
