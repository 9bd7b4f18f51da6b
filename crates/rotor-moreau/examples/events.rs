//! Prints the events of one run after t_end/2 (`-- h t_end u`).
use rotor_model::{Model, Output, Scene, Solver, State};
use rotor_moreau::MoreauSolver;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let h: f64 = a.get(1).map_or(1e-3, |s| s.parse().unwrap());
    let t_end: f64 = a.get(2).map_or(20.0, |s| s.parse().unwrap());
    let u: f64 = a.get(3).map_or(1.5, |s| s.parse().unwrap());
    let scene = Scene {
        u,
        x0: State::zeros(),
        t_end,
        h,
        output: Output::Events,
        metrics_from: Some(t_end / 2.0),
        ..Scene::default()
    };
    let tr = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    for e in tr.events.iter().filter(|e| e.t > t_end / 2.0) {
        println!("{:>14.10} {:?} {:?}", e.t, e.kind, e.x.as_slice());
    }
}
