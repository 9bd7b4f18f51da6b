//! The special points located by the switch model and Moreau–Jean against the event-driven
//! continuation's (an independent method: variational equations with saltation matrices),
//! within the gates of `fixtures/gates/bifurcation.toml` (measured × margin; origins there).

use rotor_analysis::bifurcation::PointKind;
use rotor_analysis::solvers::SolverKind;
use rotor_analysis::steady::by_solver::BySolverOptions;
use rotor_analysis::steady::figure3::{gates, label_points, matching};
use rotor_analysis::steady::solver_points::locate;
use rotor_model::{Model, Params};

#[test]
fn every_gated_point_is_located_by_both_solvers_within_its_gate() {
    let gates = gates().unwrap();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/params/");
    for name in ["table1", "stribeck"] {
        let params =
            Params::from_file(std::path::Path::new(&format!("{root}{name}.toml"))).unwrap();
        let model = Model::new(params);
        let event = rotor_analysis::bifurcation::diagram(&model, &Default::default()).unwrap();
        let opts = BySolverOptions::default();
        let sw = locate(SolverKind::SWITCH, &model, &event, &opts);
        let mo = locate(SolverKind::MOREAU, &model, &event, &opts);
        let labels = label_points(&event.points);
        // H1, H2 are shared; Table 1: G1, G2, F1 (smooth); Stribeck: G1 = D1 and G2 = E
        // (discontinuous folds).
        let want: &[&str] = if name == "table1" {
            &["G1", "G2", "F1"]
        } else {
            &["G1", "D1", "G2", "E"]
        };
        for w in want {
            let (_, p) = labels.iter().find(|(l, _)| l == w).unwrap();
            let g = gates
                .iter()
                .find(|g| g.params == name && g.point == *w)
                .unwrap_or_else(|| panic!("no gate for {name} {w}"));
            for (solver, found, gate) in [("switch", &sw, g.switch), ("moreau", &mo, g.moreau)] {
                let q = matching(&found.points, p)
                    .unwrap_or_else(|| panic!("{solver} does not locate {name} {w}: {found:?}"));
                let du = (q.u - p.u).abs();
                assert!(du <= gate, "{name} {w}: {solver} {du:e} V > gate {gate:e}");
                // Its own classification agrees with the continuation's.
                assert_eq!(q.grazing_type, p.grazing_type, "{name} {w} {solver}");
            }
        }
        // Hopf points are shared, so not gated; every other labelled point that has a gate is
        // checked above.
        assert!(labels.iter().any(|(_, p)| p.kind == PointKind::Hopf));
    }
}

#[test]
fn the_gates_file_is_read_and_every_gate_is_positive() {
    let g = gates().unwrap();
    assert_eq!(g.len(), 7);
    assert!(g.iter().all(|g| g.switch > 0.0 && g.moreau > 0.0));
}
