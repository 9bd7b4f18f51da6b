//! Every solver's steady answer agrees with what its own simulation settles on, on every
//! fixture scene and across the Stribeck set's range of inputs, and every answer has passed
//! the model's own check ([`rotor_analysis::steady::verify`], run inside each answering function).
//!
//! The default answer (refined for the event-driven solver, checked shooting for the others)
//! and `--method simulate`'s settled run are obtained independently of each other; both are
//! held to the settling criterion's relative accuracy ρ
//! ([`rotor_analysis::steady::verify::answer_accuracy`]), so they agree within 2ρ relative to the
//! larger of the two values and 1 (the metrics near 0 — a stuck ω_l min, a stick time of a
//! slipping cycle — compared absolutely), plus the stuck bands of the solver, which hold a
//! stuck disc at up to η ≠ 0.

use rayon::prelude::*;
use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_analysis::steady::checked::checked_or_simulated;
use rotor_analysis::steady::verify::answer_accuracy;
use rotor_analysis::steady::{SteadyAnswer, SteadyOptions, simulated};
use rotor_model::Model;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{RigSteady, Scene};

/// `(kind, values)` of an answer: an equilibrium's (α, ω_u, ω_l), a cycle's six metrics.
fn values(a: &SteadyAnswer) -> (&'static str, Vec<(&'static str, f64)>) {
    let kind = match a.state {
        RigSteady::Equilibrium { .. } => "equilibrium",
        RigSteady::LimitCycle { .. } => "cycle",
    };
    (kind, a.state.values().to_vec())
}

/// The default answer and the simulated one of `kind` for `scene`, compared (see the module
/// docs); `Err` says what differs.
fn agree(kind: SolverKind, model: &Model, scene: &Scene) -> Result<(), String> {
    let opts = SteadyOptions::default();
    let by_default =
        checked_or_simulated(kind, model, scene, &opts).map_err(|e| format!("default: {e}"))?;
    let by_simulation =
        simulated(kind, model, scene, &opts).map_err(|e| format!("simulate: {e}"))?;
    let (ka, va) = values(&by_default);
    let (kb, vb) = values(&by_simulation);
    if ka != kb {
        return Err(format!(
            "default gives {ka} {:?}, simulation {kb} {:?}",
            by_default.state, by_simulation.state
        ));
    }
    let rho = answer_accuracy(kind, scene);
    let band = kind.info().stuck_band;
    for ((name, a), (_, b)) in va.iter().zip(&vb) {
        let allowed = 2.0 * rho * a.abs().max(b.abs()).max(1.0) + 2.0 * band;
        if (a - b).abs() > allowed {
            return Err(format!(
                "{name}: default {a}, simulation {b}, differ by {:.2e} > {allowed:.1e}",
                (a - b).abs()
            ));
        }
    }
    Ok(())
}

fn fixture_scenes() -> Vec<Scenario> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    let mut v: Vec<Scenario> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| Scenario::from_file(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
        .collect();
    v.sort_by(|a, b| a.name.cmp(&b.name));
    v
}

fn failures(cases: Vec<(String, SolverKind, Model, Scene)>) -> Vec<String> {
    cases
        .par_iter()
        .filter_map(|(name, kind, model, scene)| {
            agree(*kind, model, scene)
                .err()
                .map(|e| format!("{name}, {}: {e}", kind.name()))
        })
        .collect()
}

#[test]
fn on_every_fixture_scene_each_solvers_steady_answer_is_what_its_simulation_settles_on() {
    let scenes = fixture_scenes();
    assert!(
        scenes.len() >= 20,
        "the suite has 23 scenes: {}",
        scenes.len()
    );
    let cases = scenes
        .iter()
        .flat_map(|s| {
            SOLVERS.iter().map(|&k| {
                let scene = Scene {
                    u: s.u,
                    x0: s.x0.clone(),
                    ..Scene::default()
                };
                (s.name.clone(), k, s.model, scene)
            })
        })
        .collect();
    let bad = failures(cases);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The Stribeck set from rest at 0.2, 0.4, …, 4.4 V: stick-slip cycles up to 3.8 V, the
/// slipping equilibrium from 4.0 V. At 1.5 and 3.0 V the event-driven refinement once answered
/// a stick exit as an "equilibrium" (α on the lower disc's stick boundary, α̇ = 2.43 rad/s).
#[test]
fn the_stribeck_set_from_rest_every_solver_agrees_with_its_simulation() {
    let model = Model::new(
        rotor_model::Params::from_file(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../fixtures/params/stribeck.toml"),
        )
        .unwrap(),
    );
    let cases = (1..=22)
        .flat_map(|i| {
            let u = 0.2 * f64::from(i);
            SOLVERS.iter().map(move |&k| {
                let scene = Scene {
                    u,
                    x0: vec![0.0; 3],
                    ..Scene::default()
                };
                (format!("{u:.1} V"), k, model, scene)
            })
        })
        .collect();
    let bad = failures(cases);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
