//! Quick look: metrics and work counters of one run (`cargo run --release --example probe -- h theta explicit t_end`).
use rotor_model::{Model, Output, Scene, Solver, State};
use rotor_moreau::{FrictionLevel, MoreauOptions, MoreauSolver};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let h: f64 = a.get(1).map_or(1e-3, |s| s.parse().unwrap());
    let theta: f64 = a.get(2).map_or(0.5, |s| s.parse().unwrap());
    let explicit = a.get(3).is_some_and(|s| s == "explicit");
    let t_end: f64 = a.get(4).map_or(60.0, |s| s.parse().unwrap());
    let u: f64 = a.get(5).map_or(1.5, |s| s.parse().unwrap());
    let solver = MoreauSolver::new(MoreauOptions {
        theta,
        friction_level: if explicit {
            FrictionLevel::Explicit
        } else {
            FrictionLevel::Implicit
        },
        ..MoreauOptions::default()
    });
    let scene = Scene {
        u,
        x0: State::zeros(),
        t_end,
        h,
        output: Output::Final,
        metrics_from: Some(t_end / 2.0),
        ..Scene::default()
    };
    let t0 = std::time::Instant::now();
    let tr = solver.simulate(&Model::table1(), &scene).unwrap();
    println!("{:?}", tr.metrics);
    println!("{:?} x={:?}", tr.stats, tr.x_final);
    println!("elapsed {:?}", t0.elapsed());
}
