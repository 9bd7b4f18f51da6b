//! Every gate of every fixture beside what it measures: the measured difference, the gate
//! stated in the scenario file, their ratio (the margin), the gate the fixtures' rule gives
//! (5 × the measured difference, rounded up to one digit; the rounding floor below it; 0 where
//! the solvers agree exactly) and whether the gate is within what the test enforces
//! (`rotor_compare::margins`). The whole-run gates (`whole_alpha`, `whole_omega_u`,
//! `whole_omega_l`, `whole_event_time`, of every pair of solvers, `switch-moreau` too) are rows
//! like the others; after the gates it prints the whole run's breakdown (events matched, the
//! phase-aligned differences that are gated and those at equal times that are not,
//! `rotor_compare::whole`). Run it after a solver change to re-derive the `[tolerance.*]`
//! tables:
//!
//! ```sh
//! cargo run --release -p rotor-compare --example gate_margins
//! ```

use std::path::Path;

use rotor_compare::margins::{floor_violations, margins};
use rotor_compare::report::whole_run_table;
use rotor_scenario::Scenario;
use rotor_solvers::run_scenario;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    println!(
        "{:<16} {:<13} {:<24} {:>10} {:>9} {:>7} {:>9}  verdict",
        "scenario", "pair", "key", "measured", "gate", "margin", "rule"
    );
    let (mut rows, mut bad, mut results) = (0, Vec::new(), Vec::new());
    for f in Scenario::list_dir(&dir).expect("fixtures/scenarios") {
        let sc = rotor_solvers::load_scenario(&f).unwrap_or_else(|e| panic!("{e}"));
        bad.extend(floor_violations(&sc));
        let r = run_scenario(&sc);
        for m in margins(&r) {
            rows += 1;
            let verdict = m.violation();
            println!(
                "{:<16} {:<13} {:<24} {:>10.3e} {:>9.0e} {:>7} {:>9.0e}  {}",
                m.scenario,
                m.pair,
                m.key.unwrap_or(&m.quantity),
                m.measured,
                m.gate,
                if m.measured == 0.0 && m.gate == 0.0 {
                    "exact".to_owned()
                } else {
                    format!("{:.1}", m.margin())
                },
                m.rule(),
                if verdict.is_some() { "OUTSIDE" } else { "ok" }
            );
            bad.extend(verdict);
        }
        results.push(r);
    }
    println!("\n{rows} gates, {} outside the rule", bad.len());
    for b in &bad {
        println!("  {b}");
    }
    print!("{}", whole_run_table(&results));
}
