//! Running one scenario through every solver.

use std::time::Instant;

use rotor_model::{Model, Output, Scenario, Scene, SolveError, Solver, Trajectory};

/// The three solvers, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SolverKind {
    /// `rotor-event`: event-driven Filippov (DOP853), the accuracy reference.
    Event,
    /// `rotor-switch`: Leine's switch model (DOPRI5).
    Switch,
    /// `rotor-moreau`: Moreau–Jean time-stepping.
    Moreau,
}

impl SolverKind {
    /// All solvers, in report order.
    pub const ALL: [SolverKind; 3] = [SolverKind::Event, SolverKind::Switch, SolverKind::Moreau];

    /// Name of the accuracy setting: `tol` for the adaptive solvers, `h` for Moreau–Jean.
    pub fn setting_name(self) -> &'static str {
        match self {
            SolverKind::Moreau => "h",
            _ => "tol",
        }
    }

    /// Whether the accuracy knob is a fixed step h (else a tolerance).
    pub fn is_fixed_step(self) -> bool {
        self.setting_name() == "h"
    }

    /// Short name (as the CLI's `--solver`).
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::Event => "event",
            SolverKind::Switch => "switch",
            SolverKind::Moreau => "moreau",
        }
    }

    /// The solver of this kind, with its default options.
    pub fn solver(self) -> Box<dyn Solver> {
        match self {
            SolverKind::Event => Box::new(rotor_event::EventSolver::default()),
            SolverKind::Switch => Box::new(rotor_switch::SwitchSolver::default()),
            SolverKind::Moreau => Box::new(rotor_moreau::MoreauSolver::default()),
        }
    }
}

/// The accuracy setting of each solver in the comparison: the event-driven reference at
/// tol 1e-12; the switch model at tol 1e-10 with its default band η = 1e-7; Moreau–Jean at
/// h = 1e-3 (the step at which Siconos is benchmarked). A scenario file may override tol/h.
pub fn solver_settings(kind: SolverKind, sc: &Scenario) -> (f64, f64) {
    let d = Scene::default();
    match kind {
        SolverKind::Event => (1e-12, d.h),
        SolverKind::Switch => (sc.tol.unwrap_or(1e-10), d.h),
        SolverKind::Moreau => (d.tol, sc.h.unwrap_or(1e-3)),
    }
}

/// One solver's run of one scenario.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub kind: SolverKind,
    pub result: Result<Trajectory, SolveError>,
    /// Wall-clock run time [s] (for the report; never asserted).
    pub seconds: f64,
}

/// All solvers' runs of one scenario.
#[derive(Debug, Clone)]
pub struct ScenarioResult {
    pub scenario: Scenario,
    pub runs: Vec<RunResult>,
}

/// The scene of a scenario for one solver: the comparison grid, events, and metrics.
pub fn scene_for(kind: SolverKind, sc: &Scenario) -> Scene {
    let (tol, h) = solver_settings(kind, sc);
    Scene {
        tol,
        h,
        ..sc.scene(Output::Grid { dt: sc.compare.dt })
    }
}

/// Runs a scenario through every solver.
pub fn run_scenario(sc: &Scenario) -> ScenarioResult {
    let runs = SolverKind::ALL
        .iter()
        .map(|&kind| run_one(kind, &sc.model, &scene_for(kind, sc)))
        .collect();
    ScenarioResult {
        scenario: sc.clone(),
        runs,
    }
}

fn run_one(kind: SolverKind, model: &Model, scene: &Scene) -> RunResult {
    let t0 = Instant::now();
    // A finished run with a NaN in its output is a failed run: nothing of it is written.
    let result = kind.solver().simulate_finite(model, scene);
    RunResult {
        kind,
        result,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

impl ScenarioResult {
    /// The trajectory of one solver, if it finished.
    pub fn traj(&self, kind: SolverKind) -> Option<&Trajectory> {
        self.runs
            .iter()
            .find(|r| r.kind == kind)
            .and_then(|r| r.result.as_ref().ok())
    }
}
