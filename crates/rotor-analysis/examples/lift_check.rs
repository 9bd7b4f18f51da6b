//! What the event solver's lift of its step bound (`EventOptions::lift`, docs/methods.md §1a,
//! "The lift") does to a scene's accuracy: the scene's start and horizon, ω_l on its 0.01 s
//! grid at tolerance TOL with the bound everywhere (lift 0), lifted at ε =
//! `rotor_event::LIFT_FRACTION` and lifted at the resolution M = `rotor_event::LIFT_RESOLUTION`,
//! each against the event solver at tol 1e-13 with k = 2 and
//! no lift. Prints the largest |Δω_l| over the transient window and over the whole run, and
//! the field evaluations.
//!
//! `cargo run --release -p rotor-analysis --example lift_check -- fixtures/scenarios/NAME.toml TOL`

use rotor_event::{EventOptions, EventSolver};
use rotor_model::seam::{Accuracy, Output, Scene, Solver};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(tol)) = (args.get(1), args.get(2).and_then(|t| t.parse::<f64>().ok()))
    else {
        eprintln!("usage: lift_check SCENARIO.toml TOL");
        std::process::exit(2);
    };
    let sc = match rotor_analysis::solvers::load_scenario(std::path::Path::new(path)) {
        Ok(sc) => sc,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    let scene = sc.scene(Output::Grid { dt: 0.01 });
    let run = |k: f64, (lift, lift_resolution): (f64, f64), tol: f64| {
        EventSolver {
            options: EventOptions {
                h_scale: k,
                lift,
                lift_resolution,
                ..EventOptions::default()
            },
        }
        .simulate(
            &sc.model,
            &Scene {
                accuracy: Accuracy::Tol(tol),
                ..scene.clone()
            },
        )
        .expect("the event solver runs the scene")
    };
    let reference = run(2.0, (0.0, 0.0), 1e-13);
    let t_transient = sc.compare.transient.map_or(20.0, |w| w[1]);
    for lift in [
        (0.0, 0.0),
        (rotor_event::LIFT_FRACTION, 0.0),
        (0.0, rotor_event::LIFT_RESOLUTION),
    ] {
        let a = run(8.0, lift, tol);
        let (mut transient, mut whole) = (0.0f64, 0.0f64);
        for (s, q) in a.samples.iter().zip(&reference.samples) {
            let d = (s.x[2] - q.x[2]).abs();
            whole = whole.max(d);
            if s.t <= t_transient {
                transient = transient.max(d);
            }
        }
        println!(
            "{} tol {tol:e} lift (ε, M) = {lift:?}: transient max {transient:.2e}, whole max {whole:.2e}, rhs {}",
            sc.name, a.stats.rhs_evals
        );
    }
}
