//! How the reference's error falls with its tolerance on the scenarios whose reference at tol
//! 1e-12 is weakest (they start next to an unstable equilibrium): each run of the
//! event-driven solver at tol 1e-11 … 1e-14 against one at 1.2e-15, in the event times and
//! the trace. This is why `reference::TIGHT_REFERENCE_TOL` (5e-14) gains about 1.3 digits.
//!
//! ```sh
//! cargo run --release -p rotor-harness --example reference_tol [SCENARIO ...]
//! ```

use std::path::Path;

use rotor_analysis::solvers::registry::SolverKind;
use rotor_model::seam::{Accuracy, Output, Scene, Trajectory};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut names: Vec<String> = std::env::args().skip(1).collect();
    if names.is_empty() {
        names = ["st-u0.19-eq-pert", "t1-u0.4-eq-pert", "t1-u2.5-eq-pert"]
            .map(String::from)
            .to_vec();
    }
    let tols = [1e-11, 1e-12, 1e-13, 1e-14];
    let best_tol = rotor_harness::grade::reference::TIGHT_CHECK_TOL;
    for name in names {
        let path = root.join(format!("fixtures/scenarios/{name}.toml"));
        let sc = rotor_analysis::solvers::load_scenario(&path).unwrap_or_else(|e| panic!("{e}"));
        let run = |tol: f64| -> Trajectory {
            let scene = Scene {
                accuracy: Accuracy::Tol(tol),
                ..sc.scene(Output::Grid { dt: sc.compare.dt })
            };
            SolverKind::EVENT
                .solver()
                .simulate_finite(&sc.model, &scene)
                .unwrap_or_else(|e| panic!("{name} at tol {tol:e}: {e}"))
        };
        let switches = |tr: &Trajectory| -> Vec<f64> {
            tr.events
                .iter()
                .filter(|e| rotor_harness::grade::trace::event_row(e.kind).is_some())
                .map(|e| e.t)
                .collect()
        };
        let best = run(best_tol);
        let eb = switches(&best);
        println!("{name}: against tol {best_tol:e} ({} events)", eb.len());
        for tol in tols {
            let r = run(tol);
            let e = switches(&r);
            let de = if e.len() == eb.len() {
                e.iter()
                    .zip(&eb)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            } else {
                f64::NAN
            };
            let mut d = [0.0f64; 3];
            for (a, b) in r.samples.iter().zip(&best.samples) {
                for (i, di) in d.iter_mut().enumerate() {
                    *di = di.max((a.x[i] - b.x[i]).abs());
                }
            }
            println!(
                "  tol {tol:e}: event times {de:.2e} s, alpha {:.2e}, omega_u {:.2e}, \
                 omega_l {:.2e}",
                d[0], d[1], d[2]
            );
        }
    }
}
