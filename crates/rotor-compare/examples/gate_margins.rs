//! Every gate of every fixture beside what it measures: the measured difference, the gate
//! stated in the scenario file, their ratio (the margin), and the gate the fixtures' rule
//! gives (5 × the measured difference, rounded up to one digit; the rounding floor below it).
//! Run it after a solver change to re-derive the `[tolerance.*]` tables:
//!
//! ```sh
//! cargo run --release -p rotor-compare --example gate_margins
//! ```

use std::path::Path;

use rotor_compare::report::gate_scenario;
use rotor_compare::run_scenario;
use rotor_model::Scenario;

/// The fixtures' rule: 5 × the measured difference rounded up to one significant digit, at
/// least the rounding floor; an exact 0 stays 0.
fn suggested(measured: f64, relative: bool) -> f64 {
    if measured == 0.0 {
        return 0.0;
    }
    let floor = if relative { 1e-13 } else { 1e-12 };
    let x = 5.0 * measured;
    let e = x.log10().floor();
    let g = (x / 10f64.powf(e) - 1e-9).ceil() * 10f64.powf(e);
    g.max(floor)
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    println!(
        "{:<16} {:<13} {:<42} {:>9} {:>9} {:>7} {:>9}",
        "scenario", "pair", "quantity", "measured", "gate", "margin", "rule"
    );
    for f in Scenario::list_dir(&dir).expect("fixtures/scenarios") {
        let sc = rotor_compare::load_scenario(&f).unwrap_or_else(|e| panic!("{e}"));
        let r = run_scenario(&sc);
        for g in gate_scenario(&r).0 {
            for m in &g.measured {
                let relative =
                    m.quantity.starts_with("steady ") && !m.quantity.contains("stick_time");
                let margin = if m.diff > 0.0 {
                    m.tol / m.diff
                } else {
                    f64::INFINITY
                };
                println!(
                    "{:<16} {:<13} {:<42} {:>9.2e} {:>9.0e} {:>7.1} {:>9.0e}",
                    sc.name,
                    g.pair,
                    m.quantity,
                    m.diff,
                    m.tol,
                    margin,
                    suggested(m.diff, relative)
                );
            }
        }
    }
}
