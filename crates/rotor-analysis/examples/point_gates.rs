//! Measures how far each solver's special points lie from the event-driven continuation's:
//! the switch model at tol 1e-10 (η = 1e-10), Moreau–Jean at h = 2e-3, 1e-3 and 5e-4 with the
//! fitted order and constant `C` of `|Δu| ≈ C·h^p`. The gates in
//! `fixtures/gates/bifurcation.toml` are set from these numbers.
//!
//! `cargo run --release -p rotor-analysis --example point_gates`

use rotor_analysis::bifurcation::PointKind;
use rotor_analysis::solvers::SolverKind;
use rotor_analysis::steady::by_solver::BySolverOptions;
use rotor_analysis::steady::figure3::{label_points, matching};
use rotor_analysis::steady::solver_points::locate;
use rotor_model::{Model, Params};

fn main() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/params/");
    for name in ["table1", "stribeck"] {
        let params =
            Params::from_file(std::path::Path::new(&format!("{root}{name}.toml"))).expect("params");
        let model = Model::new(params);
        let event =
            rotor_analysis::bifurcation::diagram(&model, &Default::default()).expect("diagram");
        let labels = label_points(&event.points);
        let mut runs = vec![("switch", SolverKind::SWITCH, BySolverOptions::default())];
        for h in [2e-3, 1e-3, 5e-4] {
            runs.push((
                "moreau",
                SolverKind::MOREAU,
                BySolverOptions {
                    h,
                    ..Default::default()
                },
            ));
        }
        for (label, p) in &labels {
            if matches!(p.kind, PointKind::Hopf | PointKind::StickLimit) {
                continue;
            }
            let mut line = format!("{name} {label} u = {:.10}:", p.u);
            let mut moreau = Vec::new();
            for (sname, kind, opts) in &runs {
                let found = locate(*kind, &model, &event, opts);
                match matching(&found.points, p) {
                    Some(q) => {
                        let d = (q.u - p.u).abs();
                        line += &format!(" {sname}(h={:.0e}) {d:.2e}", opts.h);
                        if *sname == "moreau" {
                            moreau.push((opts.h, d));
                        }
                    }
                    None => line += &format!(" {sname}(h={:.0e}) not located", opts.h),
                }
            }
            if moreau.len() == 3 {
                let p_fit = (moreau[0].1 / moreau[2].1).ln() / (moreau[0].0 / moreau[2].0).ln();
                let c = moreau[1].1 / (moreau[1].0 * moreau[1].0);
                line += &format!("; moreau order {p_fit:.2}, C = |du|/h^2 at 1e-3 = {c:.3e}");
            }
            println!("{line}");
        }
    }
}
