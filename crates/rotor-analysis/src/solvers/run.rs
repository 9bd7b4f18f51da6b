//! Running one scenario through every solver.

use std::time::Instant;

use rotor_model::Model;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Output, Scene, SolveError, Trajectory};

use crate::solvers::registry::{Knob, SOLVERS, SolverKind};

/// The accuracy setting (its tolerance or its step) of a solver in the comparison of a
/// scenario: the reference (the first of [`SOLVERS`]) at its comparison setting; every other
/// solver at its comparison setting unless the scenario file sets `tol` or `h`.
pub fn solver_setting(kind: SolverKind, sc: &Scenario) -> f64 {
    let info = kind.info();
    if kind == SOLVERS[0] {
        info.comparison
    } else {
        match info.knob {
            Knob::Tolerance => sc.tol.unwrap_or(info.comparison),
            Knob::Step => sc.h.unwrap_or(info.comparison),
        }
    }
}

/// One solver's run of one scenario.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The solver that ran.
    pub kind: SolverKind,
    /// Its trajectory on the scenario's comparison scene ([`scene_for`]), or why it failed
    /// (a finished run with a NaN or ∞ in its output counts as failed).
    pub result: Result<Trajectory, SolveError>,
    /// Wall-clock run time \[s\] (for the report; never asserted).
    pub seconds: f64,
}

/// All solvers' runs of one scenario.
#[derive(Debug, Clone)]
pub struct ScenarioResult {
    /// The scenario that was run.
    pub scenario: Scenario,
    /// One run per solver, in the order asked (the reference first).
    pub runs: Vec<RunResult>,
}

/// The scene of a scenario for one solver: the comparison grid, events, and metrics.
pub fn scene_for(kind: SolverKind, sc: &Scenario) -> Scene {
    Scene {
        accuracy: kind.accuracy(solver_setting(kind, sc)),
        ..sc.scene(Output::Grid { dt: sc.compare.dt })
    }
}

/// Runs a scenario through every solver of [`SOLVERS`].
pub fn run_scenario(sc: &Scenario) -> ScenarioResult {
    run_scenario_with(sc, &SOLVERS)
}

/// Runs a scenario through each of `solvers` (the first is the reference).
pub fn run_scenario_with(sc: &Scenario, solvers: &[SolverKind]) -> ScenarioResult {
    let runs = solvers
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
