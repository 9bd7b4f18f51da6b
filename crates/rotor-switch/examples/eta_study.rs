//! The band η of the switch model against the exact Filippov solution (η = 0): steady-state
//! metrics (relative differences; absolute where the exact value is 0) and cost (field
//! evaluations, wall time) on Table 1 and the Stribeck set (tol 1e-10, metrics from 100 s).
//!
//! ```sh
//! cargo run --release -p rotor-switch --example eta_study
//! ```

use std::path::Path;
use std::time::Instant;

use rotor_model::Model;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Output, Scene, Solver};
use rotor_switch::{SwitchOptions, SwitchSolver};

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    let st = Scenario::from_file(&dir.join("st-u1.5-rest.toml"))
        .unwrap()
        .model;
    let cases = [
        ("t1", Model::table1(), 1.5),
        ("t1", Model::table1(), 4.5),
        ("st", st, 1.5),
        ("st", st, 4.5),
    ];
    for (name, model, u) in &cases {
        let scene = Scene {
            u: *u,
            t_end: 200.0,
            output: Output::Final,
            metrics_from: Some(100.0),
            ..Scene::with_tol(1e-10)
        };
        let run = |eta: f64| {
            let s = SwitchSolver {
                options: SwitchOptions {
                    eta,
                    ..SwitchOptions::default()
                },
            };
            let t0 = Instant::now();
            let t = s.simulate(model, &scene).unwrap();
            (t, t0.elapsed().as_secs_f64())
        };
        let (exact, _) = run(0.0);
        let m0 = exact.rig_metrics().unwrap();
        println!(
            "{name} u={u}: exact {:?}  rhs {}",
            m0.values(),
            exact.stats.rhs_evals
        );
        {
            for eta in [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 5e-10, 1e-10] {
                let (t, secs) = run(eta);
                let m = t.rig_metrics().unwrap();
                let diffs: Vec<String> = m0
                    .values()
                    .iter()
                    .zip(m.values())
                    .map(|((k, a), (_, b))| {
                        let d = (a - b).abs() / a.abs().max(1e-300);
                        format!("{k}={:.1e}", if *a == 0.0 { (a - b).abs() } else { d })
                    })
                    .collect();
                println!(
                    "  eta={eta:.0e} rhs={:>8} t={secs:.3}s |wl_final|={:.1e} {}",
                    t.stats.rhs_evals,
                    t.x_final[2].abs(),
                    diffs.join(" ")
                );
            }
        }
    }
}
