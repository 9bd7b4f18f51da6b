//! Temporary: a fingerprint of every solver's output on every fixture, for a refactor that must not change them.
use rotor_compare::SOLVERS;
use rotor_compare::run::scene_for;
use rotor_model::{Output, Scenario, Scene};
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::Path;

fn h<T: Hash>(v: T) -> u64 {
    let mut s = DefaultHasher::new();
    v.hash(&mut s);
    s.finish()
}
fn bits(x: &rotor_model::State) -> [u64; 3] {
    [x[0].to_bits(), x[1].to_bits(), x[2].to_bits()]
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    for f in Scenario::list_dir(&dir).unwrap() {
        let sc = rotor_compare::load_scenario(&f).unwrap();
        for kind in SOLVERS {
            for (oname, output, mf) in [
                ("grid", Output::Grid { dt: 0.01 }, true),
                ("steps", Output::Steps, false),
                ("events", Output::Events, true),
                ("metrics", Output::Metrics, true),
                ("final", Output::Final, false),
                ("grid_nometrics", Output::Grid { dt: 0.3 }, false),
            ] {
                let base = scene_for(kind, &sc);
                let scene = Scene {
                    output,
                    metrics_from: if mf { base.metrics_from } else { None },
                    ..base
                };
                let tr = kind.solver().simulate(&sc.model, &scene).unwrap();
                let samples = h(tr
                    .samples
                    .iter()
                    .map(|s| (s.t.to_bits(), bits(&s.x)))
                    .collect::<Vec<_>>());
                let events = h(tr
                    .events
                    .iter()
                    .map(|e| (e.t.to_bits(), bits(&e.x), format!("{:?}", e.kind)))
                    .collect::<Vec<_>>());
                let metrics = h(format!(
                    "{:?}",
                    tr.metrics.map(|m| m
                        .values()
                        .iter()
                        .map(|v| v.1.to_bits())
                        .collect::<Vec<_>>())
                ));
                let fin = h((
                    tr.t_final.to_bits(),
                    bits(&tr.x_final),
                    format!("{:?}", tr.mode_final),
                ));
                println!(
                    "{} {} {oname} samples={} n={} events={} n={} metrics={metrics:x} final={fin:x} stats={:?}",
                    sc.name,
                    kind.name(),
                    samples,
                    tr.samples.len(),
                    events,
                    tr.events.len(),
                    tr.stats
                );
            }
        }
    }
}
