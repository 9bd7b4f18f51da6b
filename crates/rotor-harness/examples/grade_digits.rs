//! The digits `rotor check` gives honest solvers of every kind on every fixture: the
//! event-driven solver at several tolerances, the switch model, Moreau–Jean at several steps.
//! Each run's grid trace and events are graded as an external trace is, at the strict level
//! (whose stuck threshold, `check::stuck_threshold`, is the finest any level uses). This is how the
//! levels' digits (`check::STRICT_DIGITS`, `check::LOOSE_DIGITS`) were chosen:
//!
//! ```sh
//! cargo run --release -p rotor-harness --example grade_digits
//! ```

use std::path::Path;

use rotor_analysis::solvers::registry::SolverKind;
use rotor_harness::grade::check::{Level, check, reference_error};
use rotor_harness::grade::trace::{EventsFile, Trace};
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Output, Scene};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let runs: Vec<(SolverKind, f64)> = vec![
        (SolverKind::EVENT, 1e-12),
        (SolverKind::EVENT, 1e-11),
        (SolverKind::EVENT, 1e-10),
        (SolverKind::EVENT, 1e-8),
        (SolverKind::SWITCH, 1e-10),
        (SolverKind::MOREAU, 1e-3),
        (SolverKind::MOREAU, 1e-4),
    ];
    for f in Scenario::list_dir(&root.join("fixtures/scenarios")).expect("fixtures") {
        let sc = rotor_analysis::solvers::load_scenario(&f).unwrap_or_else(|e| panic!("{e}"));
        let r = rotor_harness::grade::reference::read(&root.join("fixtures/reference"), &sc.name)
            .unwrap_or_else(|e| panic!("{e}"));
        println!("== {}", sc.name);
        for &(kind, setting) in &runs {
            let scene = Scene {
                accuracy: kind.accuracy(setting),
                ..sc.scene(Output::Grid { dt: sc.compare.dt })
            };
            let tr = match kind.solver().simulate_finite(&sc.model, &scene) {
                Ok(tr) => tr,
                Err(e) => {
                    println!("{:>8} {setting:e}: {e}", kind.name());
                    continue;
                }
            };
            let trace = Trace::of_run("run", &tr.samples);
            let events = EventsFile::of_run("run", &tr.events);
            match check(&sc, &r, &trace, Some(&events), Level::Strict) {
                Ok(rep) => {
                    let cols: Vec<String> = rep
                        .quantities
                        .iter()
                        .map(|q| {
                            format!("{}={:.1}", q.name.trim_start_matches("steady_"), q.digits)
                        })
                        .collect();
                    println!(
                        "{:>8} {setting:e}: digits {:.1}  {}{}",
                        kind.name(),
                        rep.digits,
                        cols.join(" "),
                        rep.quantities
                            .iter()
                            .filter_map(|q| q.note.as_ref())
                            .map(|n| format!("\n      {n}"))
                            .collect::<String>()
                    );
                }
                Err(e) => println!("{:>8} {setting:e}: {e}", kind.name()),
            }
        }
        // The reference's own verified digits per quantity: −log10(stated error / scale).
        if let Ok(rep) = check(
            &sc,
            &r,
            &Trace::of_samples("ref", r.samples.clone()),
            Some(&EventsFile::of_run("ref", &r.events)),
            Level::Strict,
        ) {
            let cols: Vec<String> = rep
                .quantities
                .iter()
                .filter_map(|q| {
                    let e = reference_error(&r, &q.name)?;
                    Some(format!("{}={:.1}", q.name, -(e / q.scale).log10()))
                })
                .collect();
            println!(
                "  reference verified (tol {:e}): {}",
                r.json.tol,
                cols.join(" ")
            );
            let orbit = rep.quantities.iter().find(|q| q.name == "orbit");
            println!(
                "  reference's own orbit distance: {:?}",
                orbit.map(|q| q.difference)
            );
        }
    }
}
