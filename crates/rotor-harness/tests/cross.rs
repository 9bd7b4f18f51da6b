//! Cross-solver checks of single solver features against the event-driven reference (the
//! solver crates test themselves; what needs a second solver lives here).

use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_model::seam::{Accuracy, EventKind, Output, Scene, Solver, Trajectory};
use rotor_model::{Disc, Model, OMEGA_L};

/// `scene` run by `kind` at `setting`, its tolerance or its step.
fn run(kind: SolverKind, setting: f64, scene: &Scene) -> Trajectory {
    kind.solver()
        .simulate(
            &Model::table1(),
            &Scene {
                accuracy: kind.accuracy(setting),
                ..scene.clone()
            },
        )
        .unwrap()
}

/// A lower disc spinning backward with a wound spring (k_θ α = 0.36 N m > T_sl) passes
/// through ω_l = 0 without sticking: the switch model reports the same single reversal as
/// the Filippov solver, at the same time up to what its band η explains.
#[test]
fn a_reversal_without_sticking_matches_the_event_solver() {
    let scene = Scene {
        u: 1.5,
        x0: vec![5.0, 0.0, -1.0],
        t_end: 1.0,
        output: Output::Events,
        ..Scene::default()
    };
    let lower = |t: &Trajectory| -> Vec<(f64, EventKind)> {
        t.events
            .iter()
            .filter(|e| {
                matches!(
                    e.kind,
                    EventKind::Reversal(Disc::LOWER)
                        | EventKind::StickStart(Disc::LOWER)
                        | EventKind::StickEnd(Disc::LOWER)
                )
            })
            .map(|e| (e.t, e.kind))
            .collect()
    };
    let switch_at = |eta: f64| {
        let solver = rotor_switch::SwitchSolver {
            options: rotor_switch::SwitchOptions {
                eta,
                ..Default::default()
            },
        };
        lower(
            &solver
                .simulate(
                    &Model::table1(),
                    &Scene {
                        accuracy: Accuracy::Tol(1e-10),
                        ..scene.clone()
                    },
                )
                .unwrap(),
        )
    };
    let event = lower(&run(SolverKind::EVENT, 1e-12, &scene));
    assert_eq!(event.len(), 1, "{event:?}");
    assert_eq!(event[0].1, EventKind::Reversal(Disc::LOWER));
    // The default band and a wide one (1e-7, so that the band's shift stands above the
    // integration error) both report the one reversal.
    let default_eta = rotor_switch::SwitchOptions::default().eta;
    let wide = 1e-7;
    let exact = switch_at(0.0);
    for eta in [default_eta, wide] {
        let switch = switch_at(eta);
        assert_eq!(switch.len(), 1, "eta {eta}: {switch:?}");
        assert_eq!(switch[0].1, EventKind::Reversal(Disc::LOWER));
    }
    // The band moves the crossing by at most η/|ω̇_l| (the switch model leaves the smooth law
    // for |ω_l| < η): |ω̇_l| ≈ (0.36 − 0.16)/0.0326 ≈ 6 rad/s² gives 1.7e-8 s at η = 1e-7.
    // On top of that, the switch model's own location error at tol 1e-10, measured by its
    // η = 0 run against the reference (≈ 4e-11 s), and the reference's (≤ 1e-12 s).
    let m = Model::table1();
    let ev = run(SolverKind::EVENT, 1e-12, &scene);
    let x = ev
        .events
        .iter()
        .find(|e| e.kind == EventKind::Reversal(Disc::LOWER))
        .unwrap()
        .state();
    let rate = m.rhs(&x, scene.u, m.mode_at(&x, scene.u))[OMEGA_L].abs();
    let located = (exact[0].0 - event[0].0).abs();
    assert!(
        located < 1e-9,
        "the switch model's η = 0 run: {located:e} s off"
    );
    let d = (event[0].0 - switch_at(wide)[0].0).abs();
    assert!(
        d <= wide / rate + located + 1e-12,
        "{d:e} vs eta/rate {:e} + {located:e}",
        wide / rate
    );
    // … and the shift is the band's: with η = 1e-7 it is well above the location error.
    assert!(d > 10.0 * located, "{d:e} vs {located:e}");
}

/// Grid samples between steps come from each solver's dense output: on a 0.3 s grid (which
/// falls between the steps), the switch model's samples agree with the event-driven
/// solver's within its tolerance-level error, and Moreau–Jean's within its O(h²).
#[test]
fn grid_samples_between_steps_match_the_event_solver() {
    let scene = Scene {
        u: 1.5,
        t_end: 20.0,
        output: Output::Grid { dt: 0.3 },
        ..Scene::default()
    };
    let reference = run(SolverKind::EVENT, 1e-12, &scene);
    for (kind, setting) in [(SolverKind::SWITCH, 1e-10), (SolverKind::MOREAU, 1e-3)] {
        let tr = run(kind, setting, &scene);
        let steps = run(
            kind,
            setting,
            &Scene {
                output: Output::Steps,
                ..scene.clone()
            },
        );
        let step_times: Vec<f64> = steps.samples.iter().map(|s| s.t).collect();
        let mid = tr
            .samples
            .iter()
            .filter(|s| step_times.binary_search_by(|t| t.total_cmp(&s.t)).is_err())
            .count();
        let worst = tr
            .samples
            .iter()
            .zip(&reference.samples)
            .map(|(a, b)| {
                assert_eq!(a.t, b.t);
                (a.state() - b.state()).amax()
            })
            .fold(0.0, f64::max);
        // A third or more of the grid times fall between steps (measured: 66 of 68 for the
        // switch model, 26 of 68 for Moreau–Jean), else the test would not look at the
        // interpolation at all.
        assert!(
            3 * mid >= tr.samples.len(),
            "{}: {mid} of {}",
            kind.name(),
            tr.samples.len()
        );
        // Measured 4.8e-9 rad/s (switch: DOPRI5's dense output and its tol 1e-10) and
        // 1.5e-5 (Moreau–Jean: linear interpolation between steps, O(h²|ẍ|/8) with
        // |ẍ| ≲ 100 rad/s³, and its O(h²) scheme error); gates 4x.
        let gate = if kind == SolverKind::SWITCH {
            2e-8
        } else {
            6e-5
        };
        assert!(worst <= gate, "{}: {worst:e} > {gate:e}", kind.name());
    }
}

/// The initial state is a list of the model's size: every solver refuses a list of another
/// size by name (the rig's state has three values), rather than reading past it or padding.
#[test]
fn every_solver_refuses_an_initial_state_of_the_wrong_size() {
    for kind in SOLVERS {
        for n in [2, 4] {
            let scene = Scene {
                x0: vec![0.0; n],
                accuracy: kind.accuracy(if kind.is_fixed_step() { 1e-3 } else { 1e-8 }),
                ..Scene::default()
            };
            let err = kind
                .solver()
                .simulate(&Model::table1(), &scene)
                .unwrap_err();
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("x0 = {n} values")),
                "{}: {msg}",
                kind.name()
            );
        }
    }
}
