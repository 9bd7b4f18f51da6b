//! Prints the diagram's special points for a parameter file (exploration aid).
use rotor_bifurcation::{DiagramOptions, diagram};
use rotor_model::{Model, Params};

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("fixtures/params/table1.toml".into());
    let n: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(200);
    let model = Model::new(Params::from_file(std::path::Path::new(&path)).unwrap());
    let t = std::time::Instant::now();
    let d = diagram(
        &model,
        &DiagramOptions {
            n,
            ..Default::default()
        },
    )
    .unwrap();
    eprintln!("time {:?}, {} periodic", t.elapsed(), d.periodic.len());
    for p in &d.points {
        println!("{:?}", p);
    }
    for p in d.periodic.iter().step_by(10) {
        println!(
            "u {:.5} T {:.4} max {:.4} min {:.4} st {} ss {} m {:?}",
            p.u,
            p.period,
            p.omega_l_max,
            p.omega_l_min,
            p.stable,
            p.stick_slip,
            &p.multipliers[1..]
        );
    }
}
