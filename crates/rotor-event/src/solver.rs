//! The [`Solver`] seam for the event-driven method.

use std::sync::Arc;

use nalgebra::{DVector, DefaultAllocator, Dim, Dyn, U3, allocator::Allocator};
use rotor_model::seam::{
    Event, EventRef, Input, Integration, Recorder, Scene, SolveError, Solver, Trajectory,
};
use rotor_model::{ChainModel, ChainParams, Mode, Model};

use crate::dop853::{Dense, Vector};
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

impl<D: Dim> Sink<D> for Recording<'_>
where
    DefaultAllocator: Allocator<D>,
{
    fn step(&mut self, dense: &Dense<D>, t0: f64, t1: f64, x1: &Vector<D>, _mode: Mode) {
        self.0
            .step(t0, t1, x1.as_slice(), |t, out| dense.eval_into(t, out));
    }

    fn event(&mut self, e: EventRef<'_>) {
        self.0.event(e);
    }

    fn stop_after(&mut self, _e: EventRef<'_>) -> bool {
        self.0.halted()
    }
}

/// The integration as the recorder drives it: runs of the Filippov integrator from `at`.
struct Run<'a, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    integ: Integrator<D>,
    t_end: f64,
    at: RunEnd<D>,
    /// A time-varying input, run one piece at a time (`None`: the constant input).
    input: Option<&'a Input>,
}

impl<D: Dim> Integration for Run<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Checkpoint = RunEnd<D>;

    /// With a time-varying input, one run per piece: a run ends on the next breakpoint and
    /// the next starts there on the new piece (its start re-checks the stick conditions at
    /// the new value, so a step of u that pushes a stuck disc's torque out of its interval
    /// ends the stick at once).
    fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        let Some(input) = self.input else {
            let RunEnd { t, x, mode } = self.at.clone();
            self.at = self
                .integ
                .run(t, x, mode, self.t_end, &mut Recording(rec))?;
            return Ok(());
        };
        loop {
            let RunEnd { t, x, mode } = self.at.clone();
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
    fn checkpoint(&self, _anchor: &Event) -> RunEnd<D> {
        self.at.clone()
    }

    fn restore(&mut self, at: RunEnd<D>) {
        self.at = at;
    }

    fn shift(&mut self, _anchor: &Event, dt: f64) {
        self.at.t += dt;
    }
}

impl EventSolver {
    /// Integrates a chain of N discs over `[0, t_end]` (state `[α_1 … α_{N−1}, ω_1 … ω_N]`),
    /// as [`Solver::simulate`] does the rig: a mode per disc, a velocity guard per slipping
    /// disc and two stick-exit guards per stuck one, all located on the dense output and
    /// refined. The rig's own run is this one on its chain of two, with the state on the
    /// stack.
    pub fn simulate_chain(
        &self,
        model: &ChainModel,
        scene: &Scene,
    ) -> Result<Trajectory, SolveError> {
        scene.validate_chain(model)?;
        let x0 = DVector::from_column_slice(&scene.x0);
        self.run::<Dyn>(Arc::new(model.clone()), scene, x0)
    }

    /// The run on `model` from `x0` (the scene's initial state, of the model's size).
    fn run<D: Dim>(
        &self,
        model: Arc<ChainModel>,
        scene: &Scene,
        x0: Vector<D>,
    ) -> Result<Trajectory, SolveError>
    where
        DefaultAllocator: Allocator<D>,
    {
        let tol = scene.tol();
        let mut rec = Recorder::new(scene, x0.as_slice(), tol, self.options.skip_verify);
        let mode = model.mode_at(x0.as_slice(), scene.u_at(0.0));
        let mut integ = Integrator::new(model, scene.u_at(0.0), tol, self.options);
        integ.extrema = rec.wants_extrema();
        let mut run = Run {
            integ,
            t_end: scene.t_end,
            at: RunEnd {
                t: 0.0,
                x: x0,
                mode,
            },
            input: scene.input.as_ref().filter(|_| scene.is_time_varying()),
        };
        rec.drive(&mut run)?;
        let RunEnd { t, x, mode } = run.at;
        Ok(rec.finish(t, x.as_slice(), mode, run.integ.stats))
    }
}

impl Solver for EventSolver {
    fn name(&self) -> &'static str {
        "event"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        let chain = ChainModel::new(&ChainParams::from_params(&model.params));
        self.run::<U3>(Arc::new(chain), scene, scene.x0_state()?)
    }
}
