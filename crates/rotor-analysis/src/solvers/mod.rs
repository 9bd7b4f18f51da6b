//! The project's solvers behind one name: what a solver is ([`SolverKind`], [`SOLVERS`]),
//! scenario files loaded for them, one scenario run through each, and input refused before
//! any run.

#![warn(missing_docs)]

pub mod fixtures;
mod input;
pub mod registry;
pub mod run;

pub use input::{check_number, solver_kind};
pub use registry::{
    Knob, SOLVERS, SolverInfo, SolverKind, all_pairs, load_scenario, load_scenario_for, pair_name,
    pairs,
};
pub use run::{
    RunResult, ScenarioResult, run_scenario, run_scenario_with, self_error, solver_setting,
    tighter_settings, unstated,
};
