//! The near-special probes of both parameter sets (the main job's "Steady states near
//! special points"), with each solver's summed probe time and the verdicts counted: a timing
//! printed by a command, not a test. `V=1` lists every answer that does not agree.
//!
//! ```sh
//! cargo run --release -p rotor-analysis --example probe_times
//! ```

use rayon::prelude::*;
use rotor_analysis::solvers::SOLVERS;
use rotor_analysis::steady::probes::{self, SETS};
use rotor_model::{Model, Params};

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/params");
    let t0 = std::time::Instant::now();
    for (set, file) in SETS {
        let m = Model::new(Params::from_file(&dir.join(file)).expect("the fixture loads"));
        let d = rotor_analysis::bifurcation::diagram(&m, &Default::default()).expect("the diagram");
        let sel = probes::selection(&d, true);
        let rows = probes::run_set(set, &m, &d, &sel, |jobs, f| {
            jobs.par_iter().map(f).collect()
        });
        for k in SOLVERS {
            let s: f64 = rows
                .iter()
                .filter(|r| r.probe.kind == k)
                .map(|r| r.seconds)
                .sum();
            println!("{set} {}: {s:.2} s of probe time", k.name());
        }
        let agree = rows
            .iter()
            .filter(|r| matches!(r.verdict, probes::Verdict::Agrees { .. }))
            .count();
        let bad = rows.iter().filter(|r| !r.verdict.acceptable()).count();
        println!(
            "{set}: {} probes, {agree} agree, {bad} wrong or failed",
            rows.len()
        );
        if std::env::var_os("V").is_some() {
            for r in rows
                .iter()
                .filter(|r| !matches!(r.verdict, probes::Verdict::Agrees { .. }))
            {
                println!(
                    "  {} {} {:+e} {}: {:?}",
                    r.probe.kind.name(),
                    r.probe.point.label,
                    r.probe.offset,
                    r.probe.start.as_str(),
                    r.verdict
                );
            }
        }
    }
    println!("{:.2} s wall", t0.elapsed().as_secs_f64());
}
