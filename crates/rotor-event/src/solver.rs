//! The [`Solver`] seam for the event-driven method.

use rotor_model::seam::{
    Event, EventRef, Input, Integration, Recorder, Scene, SolveError, Solver, Trajectory,
};
use rotor_model::{Mode, Model, State};

use crate::dop853::Dense;
use crate::filippov::{EventOptions, Integrator, RunEnd, Sink};

/// The event-driven Filippov solver (Piiroinen & Kuznetsov): the project's accuracy reference.
///
/// # Example
///
/// A run through the [`Solver`] seam: Table 1's rotor at u = 1.5 V from rest settles on the
/// stick-slip limit cycle of the source's Fig. 4 (period 4.5778 s, the lower disc stuck
/// 0.87 s of it). [`Output::Metrics`](rotor_model::seam::Output::Metrics) keeps only the
/// steady-state metrics, read off the cycles after `metrics_from`.
///
/// ```
/// use rotor_event::EventSolver;
/// use rotor_model::{Model, State};
/// use rotor_model::seam::{Accuracy, Output, Scene, Solver, RigSteady};
///
/// let model = Model::table1();
/// let scene = Scene {
///     u: 1.5,                // V
///     x0: vec![0.0; 3],    // [α, ω_u, ω_l]: at rest
///     t_end: 60.0,           // s
///     accuracy: Accuracy::Tol(1e-10), // relative = absolute
///     output: Output::Metrics,
///     metrics_from: Some(30.0),
///     ..Scene::default()
/// };
/// let run = EventSolver::default().simulate(&model, &scene)?;
///
/// assert_eq!(run.t_final, 60.0);
/// let Some(RigSteady::LimitCycle { period, omega_l_min, stick_time, .. }) = run.rig_metrics()
/// else {
///     panic!("a stick-slip cycle: {:?}", run.rig_metrics())
/// };
/// assert!((period - 4.57776).abs() < 1e-4, "period {period} s");
/// assert_eq!(omega_l_min, 0.0, "the lower disc sticks exactly");
/// assert!((stick_time - 0.8708).abs() < 1e-3, "stuck {stick_time} s per period");
/// # Ok::<(), rotor_model::seam::SolveError>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EventSolver {
    /// Step-size limits, the Zeno guard, guard sampling and the fast-forward's check.
    pub options: EventOptions,
}

/// The recorder as the integrator's sink: steps with their dense output, events, and a stop
/// after an event on which the recorder's fast-forward decided to jump or go back.
struct Recording<'r>(&'r mut Recorder);

impl Sink for Recording<'_> {
    fn step(&mut self, dense: &Dense<3>, t0: f64, t1: f64, x1: &State, _mode: Mode) {
        self.0.step(t0, t1, x1.as_slice(), |t, out| {
            out.copy_from_slice(dense.eval(t).as_slice())
        });
    }

    fn event(&mut self, e: EventRef<'_>) {
        self.0.event(e);
    }

    fn stop_after(&mut self, _e: EventRef<'_>) -> bool {
        self.0.halted()
    }
}

/// The integration as the recorder drives it: runs of the Filippov integrator from `at`.
struct Run<'a> {
    integ: Integrator<'a>,
    t_end: f64,
    at: RunEnd,
    /// A time-varying input, run one piece at a time (`None`: the constant input).
    input: Option<&'a Input>,
}

impl Integration for Run<'_> {
    type Checkpoint = RunEnd;

    /// With a time-varying input, one run per piece: a run ends on the next breakpoint and
    /// the next starts there on the new piece (its start re-checks the stick conditions at
    /// the new value, so a step of u that pushes a stuck disc's torque out of its interval
    /// ends the stick at once).
    fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        let Some(input) = self.input else {
            let RunEnd { t, x, mode } = self.at;
            self.at = self
                .integ
                .run(t, x, mode, self.t_end, &mut Recording(rec))?;
            return Ok(());
        };
        loop {
            let RunEnd { t, x, mode } = self.at;
            let piece = input.piece(t);
            let end = piece.end.min(self.t_end);
            self.integ.piece = piece;
            self.at = self.integ.run(t, x, mode, end, &mut Recording(rec))?;
            if self.at.t < end || end >= self.t_end {
                return Ok(());
            }
        }
    }

    /// A run stops right after its anchor event, in the mode after it.
    fn checkpoint(&self, _anchor: &Event) -> RunEnd {
        self.at
    }

    fn restore(&mut self, at: RunEnd) {
        self.at = at;
    }

    fn shift(&mut self, _anchor: &Event, dt: f64) {
        self.at.t += dt;
    }
}

impl Solver for EventSolver {
    fn name(&self) -> &'static str {
        "event"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        let tol = scene.tol();
        let x0 = scene.x0_state()?;
        let mut rec = Recorder::new(scene, x0.as_slice(), tol, self.options.skip_verify);
        let mut integ = Integrator::new(model, scene.u_at(0.0), tol, self.options);
        integ.extrema = rec.wants_extrema();
        let at = RunEnd {
            t: 0.0,
            x: x0,
            mode: model.mode_at(&x0, scene.u_at(0.0)),
        };
        let mut run = Run {
            integ,
            t_end: scene.t_end,
            at,
            input: scene.input.as_ref().filter(|_| scene.is_time_varying()),
        };
        rec.drive(&mut run)?;
        let RunEnd { t, x, mode } = run.at;
        Ok(rec.finish(t, x.as_slice(), mode, run.integ.stats))
    }
}
