//! Numerical stress of the steady states. The test name contains `stress`, so
//! `cargo test --release -p rotor-analysis stress` runs it; `ROTOR_STRESS=full` selects the
//! full form of the probe list (`just stress`).

use rayon::prelude::*;
use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_harness::compare::stress::full_from_env;
use rotor_model::{Model, Params};

/// Steady states next to every special point of both parameter sets
/// (`rotor_analysis::steady::probes`): at ±1e-3, ±1e-4 and ±1e-6 V from each, from rest and from the
/// perturbed equilibrium, every solver's answer is an attractor the continuation says is
/// stable there (kind, period, extremes within the solver's agreement) or a refusal that
/// names its cause; a wrong or unstable cycle, or an unexplained failure, fails. The fast
/// form leaves out most of Moreau–Jean's probes (see `probes::selection`).
///
/// And the reference answers where it matters most: the event-driven solver gives the
/// attractor at every probe around Table 1's first Hopf point (H1, supercritical: the small
/// stable cycle above it, the slowly decaying focus below) and around its fold of cycles (E).
#[test]
fn stress_cases_near_special_points_are_attractors_or_named_refusals() {
    use rotor_analysis::steady::probes::{self, ProbeRow, SETS, Verdict};
    let full = full_from_env();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/params");
    let mut bad = Vec::new();
    for (set, file) in SETS {
        let m = Model::new(Params::from_file(&dir.join(file)).unwrap());
        let d = rotor_analysis::bifurcation::diagram(
            &m,
            &rotor_analysis::bifurcation::DiagramOptions::default(),
        )
        .unwrap();
        let selected = probes::selection(&d, full);
        let rows = probes::run_set(set, &m, &d, &selected, |jobs, f| {
            jobs.par_iter().map(f).collect()
        });
        println!(
            "{set}: {} probes\n{}",
            rows.len(),
            probes::probe_table_markdown(&rows, &SOLVERS)
        );
        bad.extend(
            rows.iter()
                .filter(|r| !r.verdict.acceptable())
                .map(|r| format!("{set} {:?}: {:?}", r.probe, r.verdict)),
        );
        if set == "table1" {
            let hopf1 = probes::probe_points(&d)
                .into_iter()
                .find(|p| p.label == "hopf")
                .unwrap();
            let key: Vec<&ProbeRow> = rows
                .iter()
                .filter(|r| {
                    r.probe.kind == SolverKind::EVENT
                        && (r.probe.point == hopf1 || r.probe.point.label == "fold")
                })
                .collect();
            assert_eq!(key.len(), 24);
            for r in key {
                assert!(
                    matches!(r.verdict, Verdict::Agrees { .. }),
                    "event near {} {:+e} V from {}: {:?}",
                    r.probe.point.label,
                    r.probe.offset,
                    r.probe.start.as_str(),
                    r.verdict
                );
            }
        }
    }
    assert!(bad.is_empty(), "{} probes:\n{}", bad.len(), bad.join("\n"));
}
