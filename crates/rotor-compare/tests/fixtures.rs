//! The CI gate: every fixture scenario through the three solvers, agreement asserted; and a
//! check that the gate catches a perturbed solver.

use std::path::Path;

use std::sync::OnceLock;

use rotor_compare::report::gate_scenario;
use rotor_compare::snapshot::snapshot;
use rotor_compare::{ScenarioResult, SolverKind, run_scenario};
use rotor_model::Scenario;

/// Every fixture through the three solvers, once per test binary (shared by the tests).
fn all() -> Vec<ScenarioResult> {
    static RESULTS: OnceLock<Vec<ScenarioResult>> = OnceLock::new();
    RESULTS
        .get_or_init(|| {
            use rayon::prelude::*;
            let files = Scenario::list_dir(&scenario_dir()).unwrap();
            assert!(files.len() >= 14);
            files
                .par_iter()
                .map(|f| run_scenario(&Scenario::from_file(f).unwrap()))
                .collect()
        })
        .clone()
}

fn scenario_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
}

/// Per scenario: each solver's steady-state metrics (rounded to the digits the scenario's
/// tolerance justifies, see `rotor_compare::snapshot`) and its counters. A solver change that
/// moves an answer by about the agreement tolerance, or changes how much work a solver does,
/// shows up here for review.
#[test]
fn snapshots_of_metrics_and_counters() {
    let results = all();
    for r in &results {
        insta::assert_yaml_snapshot!(r.scenario.name.clone(), snapshot(r));
    }
    // Every stored snapshot belongs to a fixture scenario: a renamed or deleted scenario
    // must take its snapshot with it (CI also runs `cargo insta test --unreferenced=reject`).
    let names: Vec<String> = results.iter().map(|r| r.scenario.name.clone()).collect();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            !file.ends_with(".snap.new"),
            "pending snapshot {file}: review it"
        );
        let stem = file
            .trim_start_matches("fixtures__")
            .trim_end_matches(".snap");
        assert!(
            names.iter().any(|n| n == stem),
            "unreferenced snapshot {file}"
        );
    }
}

#[test]
fn every_fixture_agrees_across_the_three_solvers_and_a_perturbation_is_caught() {
    let results = all();
    let mut fails = Vec::new();
    for r in &results {
        fails.extend(gate_scenario(r).1);
    }
    for f in &fails {
        eprintln!("{f}");
    }
    assert!(fails.is_empty(), "{} gate(s) failed", fails.len());

    // Inject a small error into one solver's result: 1e-5 rad/s on ω_l of the switch model
    // (100x its transient tolerance, far below anything visible in a plot) must fail.
    let mut r = results
        .into_iter()
        .find(|r| r.scenario.name == "t1-u1.5-rest")
        .unwrap();
    for run in &mut r.runs {
        if run.kind == SolverKind::Switch {
            let tr = run.result.as_mut().unwrap();
            for s in &mut tr.samples {
                if s.t > 5.0 && s.t < 6.0 {
                    s.x[2] += 1e-5;
                }
            }
            if let Some(rotor_model::SteadyState::LimitCycle { period, .. }) = tr.metrics.as_mut() {
                *period *= 1.0 + 1e-5;
            }
        }
    }
    let fails = gate_scenario(&r).1;
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch" && f.quantity.contains("transient max"))
    );
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch" && f.quantity.contains("period"))
    );
    assert!(
        fails.iter().all(|f| f.pair == "event-switch"),
        "only the perturbed pair fails"
    );
}
