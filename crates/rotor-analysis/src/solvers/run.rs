//! Running one scenario through every solver.

use std::time::Instant;

use rotor_model::Model;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Output, Scene, SolveError, Trajectory};

use crate::solvers::registry::{Knob, SOLVERS, SolverKind, all_pairs, pair_name};

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
    /// For a pair whose gates the scenario file does not state (a scene the project never
    /// measured), each of its solvers' runs at its [`tighter_settings`], in order: the gates
    /// are derived from the solvers' own errors, estimated from these ([`self_error`]).
    /// Empty when every pair is stated.
    pub tight: Vec<RunResult>,
}

/// The settings against which a solver's own error at `setting` is estimated, tightest
/// last: its tolerance 100× tighter (not below 1e-14, near DOP853's rounding); its step
/// halved and quartered ([`self_error`]).
pub fn tighter_settings(kind: SolverKind, setting: f64) -> Vec<f64> {
    match kind.info().knob {
        Knob::Tolerance => vec![(setting / 100.0).max(1e-14)],
        Knob::Step => vec![setting / 2.0, setting / 4.0],
    }
}

/// A solver's own error in a quantity at its setting, from that quantity measured between
/// its successive runs at the setting and the [`tighter_settings`] (`steps[0]` between the
/// setting and the first, `steps[1]` between the first and the second):
///
/// * a tolerance: `steps[0]` (a tolerance-proportional method 100× tighter leaves a
///   hundredth of the error, so the difference is 0.99 of it);
/// * a step: `max(2·d₁, 4·d₂)`. At order p the error at h is `C·h^p`, so
///   `d₁ = C·h^p·(1 − 2^−p)` and the error is `d₁·2^p/(2^p − 1) ≤ 2·d₁` for every p ≥ 1;
///   `d₂ = d₁/2^p`, and `4·d₂` is the error at order 1. The second guards the estimate
///   against one halving whose two errors cancel by chance (a stick phase located on the
///   step grid: on the Stribeck set at 3.85 V from rest, Moreau–Jean's stick time moved by
///   8e-8 from h = 1e-3 to h/2 while it erred by 1.1e-6).
pub fn self_error(kind: SolverKind, steps: &[f64]) -> f64 {
    match kind.info().knob {
        Knob::Tolerance => steps[0],
        Knob::Step => (2.0 * steps[0]).max(4.0 * steps.get(1).copied().unwrap_or(f64::NAN)),
    }
}

/// The solvers of `solvers` in a pair whose `[tolerance.<pair>]` table the scenario does not
/// state, in order.
pub fn unstated(sc: &Scenario, solvers: &[SolverKind]) -> Vec<SolverKind> {
    let mut v: Vec<SolverKind> = Vec::new();
    for (a, b) in all_pairs(solvers) {
        if !sc.tolerance.contains_key(&pair_name(a, b)) {
            for k in [a, b] {
                if !v.contains(&k) {
                    v.push(k);
                }
            }
        }
    }
    solvers.iter().copied().filter(|k| v.contains(k)).collect()
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
/// A solver of a pair the file does not state also runs at its [`tighter_settings`]
/// ([`ScenarioResult::tight`]).
pub fn run_scenario_with(sc: &Scenario, solvers: &[SolverKind]) -> ScenarioResult {
    let runs = solvers
        .iter()
        .map(|&kind| run_one(kind, &sc.model, &scene_for(kind, sc)))
        .collect();
    let tight = unstated(sc, solvers)
        .into_iter()
        .flat_map(|kind| {
            tighter_settings(kind, solver_setting(kind, sc))
                .into_iter()
                .map(move |setting| (kind, setting))
        })
        .map(|(kind, setting)| {
            let scene = Scene {
                accuracy: kind.accuracy(setting),
                ..scene_for(kind, sc)
            };
            run_one(kind, &sc.model, &scene)
        })
        .collect();
    ScenarioResult {
        scenario: sc.clone(),
        runs,
        tight,
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

    /// The runs of one solver at its [`tighter_settings`], in order (empty if it has none).
    pub fn tight_runs(&self, kind: SolverKind) -> Vec<&RunResult> {
        self.tight.iter().filter(|r| r.kind == kind).collect()
    }
}
