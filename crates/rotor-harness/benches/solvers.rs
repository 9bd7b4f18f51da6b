//! Criterion benches: each solver on Table 1 at u = 1.5 V from rest over 100 s at its
//! default setting (event and switch tol 1e-10, Moreau–Jean h = 1e-3), with the full 0.01 s
//! trace and metrics; then metrics-only (`Output::Metrics`), final-only (`Output::Final`) and
//! full trace per solver.
//!
//! `cargo bench -p rotor-harness` (all), `cargo bench -p rotor-harness -- output` (one group).
//! The work-precision ladders and the peers are in `rotor_harness::bench::run`, not here.

use rotor_analysis::solvers::SOLVERS;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use rotor_harness::bench::{SceneSpec, scene_of, solver, workspace_root};
use rotor_model::Model;
use rotor_model::seam::{Output, Scene};

fn setup() -> (Model, Scene) {
    let spec = SceneSpec::table1_u15(&workspace_root(), 100.0);
    scene_of(&spec).expect("the Table 1 fixture loads")
}

fn solvers(c: &mut Criterion) {
    let (model, scene) = setup();
    let mut g = c.benchmark_group("solver_u1.5_100s_trace");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    for kind in SOLVERS {
        let s = solver(kind);
        g.bench_function(kind.name(), |b| {
            b.iter(|| s.simulate(&model, black_box(&scene)).unwrap())
        });
    }
    g.finish();
}

fn output_levels(c: &mut Criterion) {
    let (model, scene) = setup();
    let mut g = c.benchmark_group("output_level_u1.5_100s");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    for kind in SOLVERS {
        let s = solver(kind);
        for (name, output) in [
            ("metrics_only", Output::Metrics),
            ("final_only", Output::Final),
            ("full_trace", Output::Grid { dt: 0.01 }),
        ] {
            let sc = Scene {
                output,
                ..scene.clone()
            };
            g.bench_function(format!("{}/{name}", kind.name()), |b| {
                b.iter(|| s.simulate(&model, black_box(&sc)).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group!(benches, solvers, output_levels);
criterion_main!(benches);
