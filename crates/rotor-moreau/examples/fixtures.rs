//! Runs every fixture scenario at step h (`-- h`) and prints the final state and metrics.
use rotor_model::{Output, Scenario, Scene, Solver};
use rotor_moreau::{MoreauOptions, MoreauSolver};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let h: f64 = a.get(1).map_or(1e-3, |s| s.parse().unwrap());
    let theta: f64 = a.get(2).map_or(0.5, |s| s.parse().unwrap());
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    for p in Scenario::list_dir(&dir).unwrap() {
        let sc = Scenario::from_file(&p).unwrap();
        let scene = Scene {
            u: sc.u,
            x0: sc.x0,
            t_end: sc.t_end,
            h,
            output: Output::Final,
            metrics_from: sc.compare.steady_from,
            ..Scene::default()
        };
        let s = MoreauSolver::new(MoreauOptions {
            theta,
            ..Default::default()
        });
        match s.simulate(&sc.model, &scene) {
            Ok(tr) => println!(
                "{:20} x={:?} {:?} newton/step={:.2}",
                sc.name,
                tr.x_final.as_slice(),
                tr.metrics.map(|m| m.values()),
                tr.stats.newton_iters as f64 / tr.stats.steps as f64
            ),
            Err(e) => println!("{:20} ERROR {e}", sc.name),
        }
    }
}
