//! Criterion bench: the whole bifurcation diagram over 0–7 V with the default options
//! (200 equilibria, every periodic branch at arclength steps ≤ 7/200 V — about 500 orbits —
//! and every special point located), for the Table 1 set and the Stribeck set.
//!
//! `cargo bench -p rotor-analysis`. Ten samples per set: one diagram takes 1.1 s (Table 1)
//! and 1.6 s (Stribeck) as measured (see the crate docs).

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use rotor_analysis::bifurcation::{DiagramOptions, diagram};
use rotor_model::{Model, Params};

fn model(name: &str) -> Model {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../fixtures/params/{name}.toml"));
    Model::new(Params::from_file(&p).expect("the fixture loads"))
}

fn diagrams(c: &mut Criterion) {
    let opts = DiagramOptions::default();
    let mut g = c.benchmark_group("diagram_0-7V_n200");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for name in ["table1", "stribeck"] {
        let m = model(name);
        let d = diagram(&m, &opts).expect("the diagram");
        assert!(
            d.periodic.len() >= 200,
            "{name}: {} orbits",
            d.periodic.len()
        );
        g.bench_function(name, |b| {
            b.iter(|| diagram(black_box(&m), black_box(&opts)).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, diagrams);
criterion_main!(benches);
