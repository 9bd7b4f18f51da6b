//! The CI gate: every fixture scenario through the three solvers, agreement asserted; and a
//! check that the gate catches a perturbed solver.

use std::path::Path;

use rotor_compare::report::gate_scenario;
use rotor_compare::{ScenarioResult, SolverKind, run_scenario};
use rotor_model::Scenario;

fn all() -> Vec<ScenarioResult> {
    use rayon::prelude::*;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    let files = Scenario::list_dir(&dir).unwrap();
    assert!(files.len() >= 14);
    files
        .par_iter()
        .map(|f| run_scenario(&Scenario::from_file(f).unwrap()))
        .collect()
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
