//! Every fixture runs; large steps stay bounded; stuck equilibria stay exactly stuck.

use rotor_model::seam::{Accuracy, Output, Scene, Solver};
use rotor_moreau::MoreauSolver;

use crate::scenarios;

fn scene(sc: &rotor_model::scenario::Scenario, h: f64, output: Output) -> Scene {
    Scene {
        accuracy: Accuracy::Step(h),
        ..sc.scene(output)
    }
}

#[test]
fn every_fixture_runs_at_h_1e3() {
    let all = scenarios();
    assert!(all.len() >= 14, "fixtures missing: {}", all.len());
    for sc in &all {
        let tr = MoreauSolver::default()
            .simulate(&sc.model, &scene(sc, 1e-3, Output::Final))
            .unwrap_or_else(|e| panic!("{}: {e}", sc.name));
        assert_eq!(tr.t_final, sc.t_end);
        assert!(tr.x_final.iter().all(|v| v.is_finite()), "{}", sc.name);
        let m = tr.rig_metrics().expect("metrics asked");
        assert!(m.values().iter().all(|(_, v)| v.is_finite()), "{}", sc.name);
        assert_eq!(tr.stats.steps, (sc.t_end / 1e-3).round() as u64);
        assert!(tr.samples.is_empty() && tr.events.is_empty());
    }
}

#[test]
fn large_steps_stay_bounded() {
    let mut inexact_at_half = 0;
    for sc in &scenarios() {
        for h in [0.1, 0.25, 0.5] {
            let tr = MoreauSolver::default()
                .simulate(&sc.model, &scene(sc, h, Output::Steps))
                .unwrap_or_else(|e| panic!("{} h={h}: {e}", sc.name));
            // Up to h = 0.25 every step problem has a unique solution (θh|N'| < J_l on the
            // fixtures), so Newton must converge on every step; only h = 0.5 may fall back.
            if h <= 0.25 {
                assert_eq!(tr.stats.inexact_steps, 0, "{} h={h}", sc.name);
            } else {
                inexact_at_half += tr.stats.inexact_steps;
            }
            for s in &tr.samples {
                // The fixtures' largest speeds are ~16 rad/s (max ω_l at 4.5 V) and
                // |α| < 10 rad; 50 is far beyond any physical state, while an unstable
                // scheme would grow past it within the ≥ 100 steps of these runs.
                assert!(
                    s.x.iter().all(|v| v.is_finite() && v.abs() < 50.0),
                    "{} h={h}: t={} x={:?}",
                    sc.name,
                    s.t,
                    s.x
                );
            }
        }
    }
    // The fallback is counted, not hidden: at h = 0.5 some fixture steps do take it.
    assert!(inexact_at_half > 0);
}

#[test]
fn stable_equilibrium_is_a_fixed_point_at_any_step() {
    // t1-u6.0: a stable slip equilibrium. The θ-scheme keeps equilibria as fixed points, so
    // even h = 0.5 converges to it.
    let sc = scenarios()
        .into_iter()
        .find(|s| s.name == "t1-u6.0-rest")
        .unwrap();
    let eq = sc
        .model
        .slip_equilibria(sc.u)
        .into_iter()
        .find(|e| sc.model.equilibrium_is_stable(e))
        .unwrap();
    for h in [1e-2, 0.5] {
        let mut s = scene(&sc, h, Output::Final);
        s.t_end = 600.0;
        let tr = MoreauSolver::default().simulate(&sc.model, &s).unwrap();
        let err = (tr.final_state().unwrap() - eq.state()).amax();
        // After 600 s the transient (slowest decay ~0.05/s near this Hopf-free point) is
        // e^{−30} ≈ 1e-13 of the initial offset; the equilibrium is bisected to rounding.
        // Measured 5.4e-13 (h = 1e-2), 8.9e-15 (h = 0.5): 1e-11 ≈ 20×.
        assert!(
            err < 1e-11,
            "h={h}: {err:e}: {:?} vs {:?}",
            tr.x_final,
            eq.state()
        );
    }
}

#[test]
fn stribeck_u005_keeps_both_discs_stuck() {
    let sc = scenarios()
        .into_iter()
        .find(|s| s.name == "st-u0.05-rest")
        .unwrap();
    for h in [1e-3, 0.5] {
        let tr = MoreauSolver::default()
            .simulate(&sc.model, &scene(&sc, h, Output::Steps))
            .unwrap();
        assert!(tr.samples.len() > 1);
        for s in &tr.samples {
            assert_eq!(s.x, [0.0; 3], "t={}", s.t);
        }
        assert_eq!(tr.mode_final.upper(), rotor_model::DiscMode::Stick);
        assert_eq!(tr.mode_final.lower(), rotor_model::DiscMode::Stick);
        assert!(tr.events.is_empty());
    }
}
