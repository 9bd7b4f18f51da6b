//! The solver seam: what a solver is asked ([`Scene`]) and what it returns ([`Trajectory`]).

use serde::Serialize;
use thiserror::Error;

use crate::FieldError;
use crate::seam::event::Event;
use crate::seam::input::{Input, Piece};
use crate::seam::steady::{RigSteady, SteadyState};
use crate::{Mode, Model, State};

/// What a solver keeps while it runs. Every level keeps the final state and the counters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Output {
    /// Only the final state and counters: no samples, no event list.
    Final,
    /// Only the steady-state metrics (over `[metrics_from, t_end]`, or the whole run if
    /// `metrics_from` is unset), no samples, no event list. Unlike [`Output::Final`], the
    /// adaptive solvers may skip whole periods once the orbit is on a cycle
    /// ([`crate::seam::FastForward`]): the metrics are those of an integrated cycle, and the final
    /// state carries the phase error of the skipped periods.
    Metrics,
    /// The list of events (stick onsets and exits, reversals, and extrema when metrics are
    /// asked), no samples.
    Events,
    /// Samples at `t = k·dt` for `k = 0, 1, …` and at `t_end`, plus events.
    Grid {
        /// Sample spacing \[s\]; at most [`MAX_GRID_ROWS`] rows over the horizon.
        dt: f64,
    },
    /// The state after every step, plus events.
    Steps,
}

/// Largest number of output rows `t_end/dt` a grid may ask for. A sample holds 32 bytes and a
/// CSV row about 80, so 1e7 rows are ~0.3 GB per trajectory in memory and ~1 GB on disk: far
/// above any report (the fixtures ask 2e4) and below what would abort the process on an
/// allocation failure. A `dt` that asks more is a typo (a unit slip), not a request.
pub const MAX_GRID_ROWS: f64 = 1e7;

/// Smallest admissible tolerance: 10 × the unit roundoff of f64 (1.1e-15), the bound below
/// which Hairer's DOP853 refuses to run ("tolerances are too small"): a relative error per
/// step smaller than a few roundoffs cannot be met, and a solver asked for it either
/// underflows its step or silently delivers less than it was asked.
pub const MIN_TOL: f64 = 10.0 * (f64::EPSILON / 2.0);

/// The tolerance a scene that sets a step gives the adaptive solvers ([`Scene::tol`]).
pub const DEFAULT_TOL: f64 = 1e-10;

/// The step a scene that sets a tolerance gives the time-stepping solver ([`Scene::step`]) \[s\].
pub const DEFAULT_STEP: f64 = 1e-3;

/// How accurately a scene is run: the knob of one kind of solver. A solver of the other kind
/// takes its own default ([`DEFAULT_TOL`], [`DEFAULT_STEP`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Accuracy {
    /// Tolerance of the adaptive solvers (relative = absolute).
    Tol(f64),
    /// Step size of the time-stepping solver \[s\].
    Step(f64),
}

impl Accuracy {
    /// The adaptive solvers' tolerance: this one's, or [`DEFAULT_TOL`] for a step.
    pub fn tol(self) -> f64 {
        match self {
            Accuracy::Tol(tol) => tol,
            Accuracy::Step(_) => DEFAULT_TOL,
        }
    }

    /// The time-stepping solver's step: this one's, or [`DEFAULT_STEP`] for a tolerance.
    pub fn step(self) -> f64 {
        match self {
            Accuracy::Step(h) => h,
            Accuracy::Tol(_) => DEFAULT_STEP,
        }
    }

    /// The number itself, the tolerance or the step.
    pub fn value(self) -> f64 {
        match self {
            Accuracy::Tol(v) | Accuracy::Step(v) => v,
        }
    }
}

/// One simulation request: input, initial state, horizon, accuracy, and what to keep.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Motor input voltage u \[V\], constant over the run (unless `input` is set).
    pub u: f64,
    /// A motor input that changes in time, u(t) ([`Input`]); when set it replaces `u`, which
    /// is then unused. `None` (the default) is the constant input `u`.
    pub input: Option<Input>,
    /// Initial state, a list of the model's size: `[α, ω_u, ω_l]` for the rig (rad, rad/s,
    /// rad/s); a solver reads it through [`Scene::x0_state`], which checks the size.
    pub x0: Vec<f64>,
    /// Horizon \[s\]; the run covers `[0, t_end]`.
    pub t_end: f64,
    /// The tolerance or the step ([`Scene::tol`], [`Scene::step`] read it for a solver).
    pub accuracy: Accuracy,
    /// What to keep.
    pub output: Output,
    /// If set, steady-state metrics over `[metrics_from, t_end]` (extrema located between
    /// steps, period from successive stick exits or ω_l maxima).
    pub metrics_from: Option<f64>,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            u: 1.5,
            input: None,
            x0: vec![0.0; 3],
            t_end: 100.0,
            accuracy: Accuracy::Tol(DEFAULT_TOL),
            output: Output::Grid { dt: 0.01 },
            metrics_from: None,
        }
    }
}

impl Scene {
    /// [`Scene::default`] at tolerance `tol` (for the adaptive solvers).
    pub fn with_tol(tol: f64) -> Scene {
        Scene {
            accuracy: Accuracy::Tol(tol),
            ..Scene::default()
        }
    }

    /// [`Scene::default`] at step `h` (for the time-stepping solver).
    pub fn with_step(h: f64) -> Scene {
        Scene {
            accuracy: Accuracy::Step(h),
            ..Scene::default()
        }
    }

    /// Whether the input changes in time: an [`Input`] whose rows are not all one value.
    /// What assumes a time-invariant system (the fast-forward, steady states) is off then.
    pub fn is_time_varying(&self) -> bool {
        self.input.as_ref().is_some_and(|i| i.constant().is_none())
    }

    /// The input u(t) \[V\]: `u`, or the [`Input`]'s value at t.
    pub fn u_at(&self, t: f64) -> f64 {
        match &self.input {
            None => self.u,
            Some(i) => i.at(t),
        }
    }

    /// The linear piece of the input that holds from `t` on ([`Input::piece`]); the constant
    /// `u` for ever without an [`Input`].
    pub fn piece(&self, t: f64) -> Piece {
        match &self.input {
            None => Piece::constant(self.u),
            Some(i) => i.piece(t),
        }
    }

    /// The first breakpoint of the input after `t` (a row's time), if any before `t_end`.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.input
            .as_ref()
            .and_then(|i| i.next_breakpoint(t))
            .filter(|&b| b < self.t_end)
    }

    /// The adaptive solvers' tolerance: the scene's, or [`DEFAULT_TOL`] if it sets a step.
    pub fn tol(&self) -> f64 {
        self.accuracy.tol()
    }

    /// The time-stepping solver's step: the scene's, or [`DEFAULT_STEP`] if it sets a
    /// tolerance.
    pub fn step(&self) -> f64 {
        self.accuracy.step()
    }

    /// [`Scene::step`], refused (as [`Scene::validate`] refuses a scene's own step) when it
    /// does not fit in the horizon: the check of the time-stepping solver, which takes the
    /// default step from a scene that sets a tolerance.
    pub fn checked_step(&self) -> Result<f64, SolveError> {
        let h = self.step();
        if !(h > 0.0 && h <= self.t_end) {
            return Err(FieldError::num("h", h, "must lie in (0, t_end]").into());
        }
        Ok(h)
    }

    /// Checks the scene, its own tolerance or step among the rest; the error names the field
    /// and the bad value.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |field: &str, value: f64, reason: &str| {
            Err(FieldError::num(field, value, reason).into())
        };
        if !self.u.is_finite() {
            return bad("u", self.u, "must be finite");
        }
        if let Some(i) = self.x0.iter().position(|v| !v.is_finite()) {
            // The rig's components by name, a longer state's by index.
            let name = match (self.x0.len(), i) {
                (3, 0) => "x0[alpha]".to_owned(),
                (3, 1) => "x0[omega_u]".to_owned(),
                (3, 2) => "x0[omega_l]".to_owned(),
                _ => format!("x0[{i}]"),
            };
            return bad(&name, self.x0[i], "must be finite");
        }
        if !(self.t_end > 0.0 && self.t_end.is_finite()) {
            return bad("t_end", self.t_end, "must be positive and finite");
        }
        match self.accuracy {
            Accuracy::Tol(tol) if !(tol > 0.0 && tol < 1.0) => {
                return bad("tol", tol, "must lie in (0, 1)");
            }
            Accuracy::Tol(tol) if tol < MIN_TOL => {
                return bad(
                    "tol",
                    tol,
                    "is below 1.1e-15 (10 unit roundoffs): double precision cannot deliver it",
                );
            }
            Accuracy::Tol(_) => {}
            Accuracy::Step(_) => {
                self.checked_step()?;
            }
        }
        if let Output::Grid { dt } = self.output {
            if !(dt > 0.0 && dt.is_finite()) {
                return bad("dt", dt, "must be positive and finite");
            }
            if self.t_end / dt > MAX_GRID_ROWS {
                return bad(
                    "dt",
                    dt,
                    "asks more than 1e7 output rows (t_end/dt): choose a larger dt",
                );
            }
        }
        if let Some(t) = self.metrics_from
            && !(t >= 0.0 && t < self.t_end)
        {
            return bad("metrics_from", t, "must lie in [0, t_end)");
        }
        Ok(())
    }

    /// [`Scene::validate`], and the scene against a model: the motor torque k_m·u and the
    /// initial spring torque k_θ·α must be finite (a huge u overflows k_m·u to ∞, and a
    /// time-stepping scheme would then silently stay at rest).
    pub fn validate_for(&self, model: &crate::Model) -> Result<(), SolveError> {
        self.validate()?;
        self.x0_state()?;
        if !(model.params.k_m * self.u).is_finite() {
            return Err(FieldError::num("u", self.u, "the motor torque k_m u overflows").into());
        }
        if let Some(i) = &self.input
            && !(model.params.k_m * i.max_abs()).is_finite()
        {
            return Err(FieldError::num(
                "input",
                i.max_abs(),
                "the motor torque k_m u overflows at this |u|",
            )
            .into());
        }
        if !(model.params.k_theta * self.x0[0]).is_finite() {
            return Err(FieldError::num(
                "x0[alpha]",
                self.x0[0],
                "the spring torque k_theta alpha overflows",
            )
            .into());
        }
        Ok(())
    }

    /// [`Scene::validate`], and the scene against a chain of N discs: `x0` holds the chain's
    /// `2N − 1` values, the motor torque k_m·u (at every value of the input) and the initial
    /// spring torques k_i·α_i are finite.
    pub fn validate_chain(&self, model: &crate::ChainModel) -> Result<(), SolveError> {
        self.validate()?;
        let n = model.discs();
        if self.x0.len() != model.dim() {
            return Err(FieldError::new(
                "x0",
                format!("{} values", self.x0.len()),
                format!(
                    "a chain of {n} discs has {} (alpha_1 … alpha_{}, omega_1 … omega_{n})",
                    model.dim(),
                    n - 1
                ),
            )
            .into());
        }
        if !(model.k_m() * self.u).is_finite() {
            return Err(FieldError::num("u", self.u, "the motor torque k_m u overflows").into());
        }
        if let Some(i) = &self.input
            && !(model.k_m() * i.max_abs()).is_finite()
        {
            return Err(FieldError::num(
                "input",
                i.max_abs(),
                "the motor torque k_m u overflows at this |u|",
            )
            .into());
        }
        for i in 0..n - 1 {
            if !(model.spring(i) * self.x0[i]).is_finite() {
                return Err(FieldError::num(
                    format!("x0[{i}]"),
                    self.x0[i],
                    "the spring torque k alpha overflows",
                )
                .into());
            }
        }
        Ok(())
    }

    /// The initial state as the rig's [`State`]; an error naming `x0` if the list does not
    /// hold the rig's three values.
    pub fn x0_state(&self) -> Result<State, SolveError> {
        rig_state("x0", &self.x0)
    }

    /// Number of grid intervals for `Output::Grid { dt }`: sample times are `k·dt` for
    /// `k = 0..=n` where `n·dt ≤ t_end` (within rounding), plus `t_end` if not on the grid.
    pub fn grid(&self) -> Option<OutputGrid> {
        match self.output {
            Output::Grid { dt } => Some(OutputGrid::new(dt, self.t_end)),
            _ => None,
        }
    }

    /// Whether the event list is kept.
    pub(crate) fn keeps_events(&self) -> bool {
        !matches!(self.output, Output::Final | Output::Metrics)
    }

    /// Start of the metrics window: `metrics_from`, or 0 for [`Output::Metrics`] without it;
    /// `None` if no metrics are asked.
    pub(crate) fn metrics_start(&self) -> Option<f64> {
        self.metrics_from
            .or((self.output == Output::Metrics).then_some(0.0))
    }
}

/// A list read as the rig's [`State`]; an error naming `field` if it does not hold three
/// values.
pub(crate) fn rig_state(field: &str, x: &[f64]) -> Result<State, SolveError> {
    if x.len() != 3 {
        return Err(FieldError::new(
            field,
            format!("{} values", x.len()),
            "the rig's state has 3 (alpha, omega_u, omega_l)",
        )
        .into());
    }
    Ok(State::from_column_slice(x))
}

/// The output grid `0, dt, 2dt, …, t_end`, walked without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputGrid {
    dt: f64,
    t_end: f64,
    n: u64,
    k: u64,
    done: bool,
}

impl OutputGrid {
    /// The grid for step `dt` over `[0, t_end]`.
    pub fn new(dt: f64, t_end: f64) -> OutputGrid {
        // A time within 1e-9·dt of t_end counts as t_end (so 200/0.01 gives 20001 rows).
        let n = ((t_end / dt) * (1.0 + 1e-12) + 1e-9).floor() as u64;
        OutputGrid {
            dt,
            t_end,
            n,
            k: 0,
            done: false,
        }
    }

    /// The next output time, if any.
    pub fn peek(&self) -> Option<f64> {
        if self.k < self.n {
            // Before the last point k·dt ≤ t_end − dt (up to 1e-12 relative): no snapping.
            return Some(self.k as f64 * self.dt);
        }
        if self.done {
            return None;
        }
        if self.k <= self.n {
            let t = self.k as f64 * self.dt;
            // The last grid point snaps to t_end when it is t_end up to rounding.
            Some(if (t - self.t_end).abs() <= 1e-9 * self.dt {
                self.t_end
            } else {
                t.min(self.t_end)
            })
        } else {
            Some(self.t_end)
        }
    }

    /// Advances past the current output time.
    pub fn advance(&mut self) {
        if self.k < self.n {
            self.k += 1;
            return;
        }
        if let Some(t) = self.peek() {
            if t >= self.t_end {
                self.done = true;
            }
            self.k += 1;
        }
    }

    /// Total number of rows the grid produces.
    pub fn len(&self) -> usize {
        let last = self.n as f64 * self.dt;
        self.n as usize + 1 + usize::from((last - self.t_end).abs() > 1e-9 * self.dt)
    }

    /// Whether the grid is empty (never: it always holds t = 0).
    pub fn is_empty(&self) -> bool {
        false
    }
}

/// One output sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Time \[s\].
    pub t: f64,
    /// The state `[α, ω_u, ω_l]` at `t` (rad, rad/s, rad/s).
    pub x: State,
}

/// Work counters, for benchmarks and snapshots.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (adaptive solvers).
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// Located events (mode switches and extrema).
    pub events: u64,
    /// One-step complementarity problems solved (Moreau–Jean).
    pub lcp_solves: u64,
    /// Steps on which the complementarity solve was skipped (no contact could change state).
    pub lcp_skipped: u64,
    /// Newton iterations (implicit steps, shooting).
    pub newton_iters: u64,
    /// Implicit steps whose nonlinear step problem did not converge, so that the last
    /// fixed-point iterate was taken (Moreau–Jean at very large h only). Zero in every
    /// scenario the agreement gates cover; nonzero flags an answer to distrust.
    pub inexact_steps: u64,
    /// Whole periods skipped by [`Output::Metrics`] ([`crate::seam::FastForward`]).
    pub skipped_periods: u64,
    /// Skips of [`Output::Metrics`] undone because the return after them did not confirm
    /// them: each cost a cycle, and the periods were integrated after all.
    pub undone_skips: u64,
    /// Steps rejected after they were accepted, because the exact state re-taken to an event
    /// in them differed from their dense output by more than the event solver's defect limit
    /// (also counted in `rejected`).
    #[serde(default)]
    pub defect_rejections: u64,
}

impl std::ops::AddAssign for Stats {
    /// The counters of two runs, summed (a run continued in chunks).
    fn add_assign(&mut self, o: Stats) {
        self.steps += o.steps;
        self.rejected += o.rejected;
        self.rhs_evals += o.rhs_evals;
        self.jac_evals += o.jac_evals;
        self.events += o.events;
        self.lcp_solves += o.lcp_solves;
        self.lcp_skipped += o.lcp_skipped;
        self.newton_iters += o.newton_iters;
        self.inexact_steps += o.inexact_steps;
        self.skipped_periods += o.skipped_periods;
        self.undone_skips += o.undone_skips;
        self.defect_rejections += o.defect_rejections;
    }
}

/// The result of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Samples, as asked by the scene's [`Output`].
    pub samples: crate::seam::samples::Samples,
    /// Events, unless the scene asked for [`Output::Final`] or [`Output::Metrics`].
    pub events: Vec<Event>,
    /// Final time (= t_end).
    pub t_final: f64,
    /// Final state, a list of the model's size (`[α, ω_u, ω_l]` for the rig).
    pub x_final: Vec<f64>,
    /// Final mode.
    pub mode_final: Mode,
    /// Steady-state metrics, if the scene asked for them: per-disc lists
    /// ([`Trajectory::rig_metrics`] is the rig's view).
    pub metrics: Option<SteadyState>,
    /// Work counters.
    pub stats: Stats,
}

impl Trajectory {
    /// The final state as the rig's [`State`] (an error naming `x_final` for a run of
    /// another model's size).
    pub fn final_state(&self) -> Result<State, SolveError> {
        rig_state("x_final", &self.x_final)
    }

    /// The steady-state metrics by the rig's names ([`SteadyState::rig`]): `None` where none
    /// were asked, or for a run of another size.
    pub fn rig_metrics(&self) -> Option<RigSteady> {
        self.metrics.as_ref().and_then(SteadyState::rig)
    }

    /// Checks the samples, the events, the final state and the metrics for NaN or ∞: a run
    /// that finished must deliver finite output. The error names the first offender and its
    /// time (`t_final` for the final state and the metrics).
    pub fn check_finite(&self) -> Result<(), SolveError> {
        let ok = |t: f64, x: &[f64]| t.is_finite() && x.iter().all(|v| v.is_finite());
        let bad = |t: f64, what| Err(SolveError::NonFiniteOutput { t, what });
        if let Some(s) = self.samples.iter().find(|s| !ok(s.t, s.x)) {
            return bad(s.t, "sample");
        }
        if let Some(e) = self.events.iter().find(|e| !ok(e.t, &e.x)) {
            return bad(e.t, "event");
        }
        if !ok(self.t_final, &self.x_final) {
            return bad(self.t_final, "final state");
        }
        if let Some(m) = &self.metrics
            && !m.is_finite()
        {
            return bad(self.t_final, "steady-state metrics");
        }
        Ok(())
    }
}

/// Why a solver could not finish.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SolveError {
    /// The scene (or a solver's option) is not admissible. (Boxed: the other variants are
    /// half its size, and a solver's inner loops return this type.)
    #[error("invalid scene: {0}")]
    InvalidScene(Box<FieldError>),
    /// The step size fell below what floating point resolves.
    #[error("step size underflow at t = {t}: h = {h:e} (state {x:?})")]
    StepSizeUnderflow {
        /// Time reached \[s\].
        t: f64,
        /// The step size that fell below a few roundoffs of `t` \[s\].
        h: f64,
        /// The state at `t` (`[α, ω_u, ω_l]` on the rig; its size is the model's).
        x: Vec<f64>,
    },
    /// The state became NaN or infinite.
    #[error("non-finite state at t = {t}: {x:?}")]
    NonFinite {
        /// Time at which the state was found non-finite \[s\].
        t: f64,
        /// That state (`[α, ω_u, ω_l]` on the rig; its size is the model's).
        x: Vec<f64>,
    },
    /// The one-step complementarity problem had no admissible solution.
    #[error("complementarity failure at t = {t}: {detail}")]
    Complementarity {
        /// Time of the step \[s\].
        t: f64,
        /// What the complementarity solver reported.
        detail: String,
    },
    /// Events accumulate (Zeno-like): too many in too short a time.
    #[error("Zeno-like event accumulation at t = {t}: {count} events within {window:e} s")]
    Zeno {
        /// Time of the last switch \[s\].
        t: f64,
        /// Number of switches that fell within `window`.
        count: u32,
        /// Length of the time window \[s\] they fell in.
        window: f64,
    },
    /// The run needed more steps than allowed.
    #[error("step limit {max_steps} reached at t = {t}")]
    TooManySteps {
        /// Time reached \[s\].
        t: f64,
        /// The solver's step limit.
        max_steps: u64,
    },
    /// A steady-state computation (shooting, Newton) did not converge.
    #[error("no convergence: {detail}")]
    NoConvergence {
        /// What did not converge, and why (a residual, a section never reached).
        detail: String,
    },
    /// The solver does not support what was asked.
    #[error("unsupported: {detail}")]
    Unsupported {
        /// What was asked that the solver does not do.
        detail: String,
    },
    /// The solver finished, but its output holds a NaN or ∞ (a solver bug, caught by
    /// [`Trajectory::check_finite`] before anything is written).
    #[error("non-finite output ({what}) at t = {t}: a solver bug")]
    NonFiniteOutput {
        /// Time of the first non-finite output \[s\] (`t_final` for the final state and the
        /// metrics).
        t: f64,
        /// Which output: `sample`, `event`, `final state` or `steady-state metrics`.
        what: &'static str,
    },
}

impl From<FieldError> for SolveError {
    fn from(e: FieldError) -> SolveError {
        SolveError::InvalidScene(Box::new(e))
    }
}

impl SolveError {
    /// The time at which the run failed, where the failure has one.
    pub fn time(&self) -> Option<f64> {
        match *self {
            SolveError::StepSizeUnderflow { t, .. }
            | SolveError::NonFinite { t, .. }
            | SolveError::Complementarity { t, .. }
            | SolveError::Zeno { t, .. }
            | SolveError::TooManySteps { t, .. }
            | SolveError::NonFiniteOutput { t, .. } => Some(t),
            SolveError::InvalidScene(_)
            | SolveError::NoConvergence { .. }
            | SolveError::Unsupported { .. } => None,
        }
    }

    /// The state at which the run failed (`[α, ω_u, ω_l]` on the rig), where the failure
    /// records it.
    pub fn state(&self) -> Option<&[f64]> {
        match self {
            SolveError::StepSizeUnderflow { x, .. } | SolveError::NonFinite { x, .. } => Some(x),
            _ => None,
        }
    }
}

/// A solver: takes a model and a scene and returns a trajectory.
///
/// The implementations live in crates of their own, which this one does not depend on:
/// `rotor_event::EventSolver` (the accuracy reference), `rotor_switch::SwitchSolver` and
/// `rotor_moreau::MoreauSolver`; `rotor_analysis::solvers::SOLVERS` lists them, with a constructor for
/// each. For a runnable example of [`Solver::simulate`] on a Table 1 scene see the docs of
/// `rotor_event::EventSolver`, and those of `rotor_analysis::solvers::SolverKind::solver` for all
/// three solvers in turn.
pub trait Solver: Sync {
    /// Short name (`"event"`, `"switch"`, `"moreau"`).
    fn name(&self) -> &'static str;
    /// Runs the scene: integrates from `scene.x0` at input `scene.u` over `[0, t_end]`, at
    /// the solver's accuracy knob (`tol` or `h`), keeping what `scene.output` and
    /// `scene.metrics_from` ask. An inadmissible scene is refused before any step
    /// ([`SolveError::InvalidScene`]).
    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError>;

    /// Runs the scene, and refuses a finished run whose output holds a NaN or ∞
    /// ([`Trajectory::check_finite`]): what every report and writer calls.
    fn simulate_finite(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        let tr = self.simulate(model, scene)?;
        tr.check_finite()?;
        Ok(tr)
    }
}

/// Checks a state for NaN/∞ and reports it as a [`SolveError::NonFinite`].
#[inline]
pub fn check_finite(t: f64, x: &[f64]) -> Result<(), SolveError> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SolveError::NonFinite { t, x: x.to_vec() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seam::{EventKind, RigSteady};
    use crate::{Disc, DiscMode};

    #[test]
    fn check_finite_names_the_first_non_finite_output() {
        let x = State::new(0.1, 2.0, 3.0);
        let good = Trajectory {
            samples: crate::seam::Samples::from_rig([Sample { t: 0.0, x }, Sample { t: 1.0, x }]),
            events: vec![Event::new(
                0.5,
                x.as_slice(),
                EventKind::StickStart(Disc::LOWER),
            )],
            t_final: 1.0,
            x_final: x.as_slice().to_vec(),
            mode_final: Mode::rig(DiscMode::SlipPos, DiscMode::Stick),
            metrics: Some(
                RigSteady::Equilibrium {
                    omega_u: 2.0,
                    omega_l: 3.0,
                    alpha: 0.1,
                }
                .into(),
            ),
            stats: Stats::default(),
        };
        assert_eq!(good.check_finite(), Ok(()));
        type Spoil = fn(&mut Trajectory);
        let spoilt: [(Spoil, f64, &str); 5] = [
            (|t| t.samples.x_mut(1)[2] = f64::NAN, 1.0, "sample"),
            (
                |t| *t.samples.t_mut(1) = f64::INFINITY,
                f64::INFINITY,
                "sample",
            ),
            (|t| t.events[0].x[0] = f64::NEG_INFINITY, 0.5, "event"),
            (|t| t.x_final[1] = f64::NAN, 1.0, "final state"),
            (
                |t| {
                    t.metrics = Some(
                        RigSteady::Equilibrium {
                            omega_u: 2.0,
                            omega_l: f64::NAN,
                            alpha: 0.1,
                        }
                        .into(),
                    )
                },
                1.0,
                "steady-state metrics",
            ),
        ];
        for (spoil, t, what) in spoilt {
            let mut tr = good.clone();
            spoil(&mut tr);
            assert_eq!(
                tr.check_finite(),
                Err(SolveError::NonFiniteOutput { t, what })
            );
        }
    }

    fn walk(dt: f64, t_end: f64) -> Vec<f64> {
        let mut g = OutputGrid::new(dt, t_end);
        let mut v = Vec::new();
        while let Some(t) = g.peek() {
            v.push(t);
            g.advance();
        }
        assert_eq!(v.len(), OutputGrid::new(dt, t_end).len());
        v
    }

    #[test]
    fn grid_includes_both_ends_once() {
        let v = walk(0.01, 200.0);
        assert_eq!(v.len(), 20001);
        assert_eq!(v[0], 0.0);
        assert_eq!(*v.last().unwrap(), 200.0);
        let v = walk(0.3, 1.0);
        assert_eq!(v, vec![0.0, 0.3, 0.6, 0.8999999999999999, 1.0]);
        let v = walk(2.0, 1.0);
        assert_eq!(v, vec![0.0, 1.0]);
    }

    /// Every point but the last is k·dt exactly, the times increase strictly, and the last
    /// is t_end (also where t_end/dt is an integer only up to rounding).
    #[test]
    fn grid_points_are_multiples_of_dt_then_t_end() {
        for (dt, t_end) in [
            (0.01, 100.0),
            (0.07, 1.0),
            (0.1, 0.3),
            (1e-3, 0.0101),
            (0.3, 0.9),
        ] {
            let v = walk(dt, t_end);
            let (last, inner) = v.split_last().unwrap();
            assert_eq!(*last, t_end, "dt {dt}, t_end {t_end}");
            for (k, t) in inner.iter().enumerate() {
                assert_eq!(*t, k as f64 * dt, "dt {dt}, t_end {t_end}, k {k}");
            }
            assert!(
                v.windows(2).all(|w| w[0] < w[1]),
                "dt {dt}, t_end {t_end}: {v:?}"
            );
        }
    }

    #[test]
    fn validation_names_field() {
        let s = Scene::with_tol(0.0);
        assert!(s.validate().unwrap_err().to_string().contains("tol = 0"));
        let s = Scene::with_step(1000.0);
        assert!(s.validate().unwrap_err().to_string().contains("h = 1000"));
        let s = Scene {
            x0: vec![0.0, f64::NAN, 0.0],
            ..Scene::default()
        };
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("x0[omega_u] = NaN")
        );
        // A state of another size: a non-finite value is named by its index, and the rig's
        // model refuses the size by name.
        let s = Scene {
            x0: vec![0.0, 0.0, 0.0, 0.0, f64::INFINITY],
            ..Scene::default()
        };
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("x0[4] = inf")
        );
        let m = crate::Model::table1();
        for n in [0, 2, 5] {
            let s = Scene {
                x0: vec![0.0; n],
                ..Scene::default()
            };
            let err = s.validate_for(&m).unwrap_err().to_string();
            assert!(
                err.contains(&format!("x0 = {n} values: the rig's state has 3")),
                "{err}"
            );
        }
        let s = Scene {
            x0: vec![0.5, 1.0, -2.0],
            ..Scene::default()
        };
        assert_eq!(s.x0_state().unwrap(), State::new(0.5, 1.0, -2.0));
    }
}
