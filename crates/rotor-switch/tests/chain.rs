//! The switch model on chains of N discs: the rig's chain of two is the rig's run bit for bit,
//! a chain of three converges in the tolerance, a step of the input is two runs composed, and
//! what a chain cannot take is refused by name.

use rotor_model::seam::{Accuracy, Input, Output, Scene, SolveError, Solver, Trajectory};
use rotor_model::{ChainModel, ChainParams, Model, Params};
use rotor_switch::SwitchSolver;

fn chain3() -> ChainModel {
    let p = ChainParams::from_toml_str(rotor_testkit::CHAIN3, std::path::Path::new("chain3"))
        .expect("the chain of three loads");
    ChainModel::new(&p)
}

fn stribeck() -> Params {
    Params::from_toml_str(rotor_testkit::STRIBECK, std::path::Path::new("stribeck"))
        .expect("the Stribeck set loads")
}

fn chain_run(model: &ChainModel, scene: &Scene) -> Trajectory {
    SwitchSolver::default()
        .simulate_chain(model, scene)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Largest |a − b| over two runs' samples on one grid (∞ if the grids differ).
fn max_diff(a: &Trajectory, b: &Trajectory) -> f64 {
    if a.samples.len() != b.samples.len() {
        return f64::INFINITY;
    }
    a.samples
        .iter()
        .zip(b.samples.iter())
        .map(|(r, s)| {
            assert_eq!(r.t, s.t);
            r.x.iter()
                .zip(s.x)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// The rig run as a chain of two (a state of any size, on the heap) is the rig's own run (its
/// state on the stack), bit for bit: samples, events, final state and mode, and the work
/// counters, on Table 1 and on the Stribeck set (whose upper disc sticks as well), keeping
/// the grid and keeping the events. The two are one code path on two storages, so any
/// difference is a bug in the generic state, not a rounding.
#[test]
fn a_chain_of_two_is_the_rigs_run_bit_for_bit() {
    for (name, p) in [("table1", Params::table1()), ("stribeck", stribeck())] {
        let rig = Model::new(p);
        let chain = ChainModel::new(&ChainParams::from_params(&p));
        for output in [Output::Grid { dt: 0.01 }, Output::Events] {
            let scene = Scene {
                u: 1.5,
                t_end: 40.0,
                output,
                ..Scene::default()
            };
            let a = SwitchSolver::default().simulate(&rig, &scene).unwrap();
            let b = chain_run(&chain, &scene);
            assert!(!a.events.is_empty(), "{name}: the run sticks and slips");
            assert_eq!(a.samples, b.samples, "{name} {output:?}");
            assert_eq!(a.events, b.events, "{name} {output:?}");
            assert_eq!(a.x_final, b.x_final, "{name} {output:?}");
            assert_eq!(a.mode_final, b.mode_final, "{name} {output:?}");
            assert_eq!(a.stats, b.stats, "{name} {output:?}");
        }
    }
}

/// Self-convergence in the tolerance on the chain of three (a Stribeck disc at its end, a
/// viscous coupling): 20 s of stick-slip from rest, each run against one at tol 1e-13. DOPRI5
/// with tolerance proportionality gives a global error roughly proportional to tol, so every
/// 100× tighter tolerance must cut the difference by at least 10× (a decade of room for the
/// located stick events, whose timing error is the root finder's, not the stepper's), and at
/// the comparisons' tol 1e-10 the run must be within 1e-6 of the tight one (10⁴ tolerances:
/// the growth of a local error over 20 s of stick-slip; measured in the message).
#[test]
fn a_chain_of_three_converges_in_the_tolerance() {
    let model = chain3();
    let scene = |tol: f64| Scene {
        u: 1.5,
        x0: vec![0.0; model.dim()],
        t_end: 20.0,
        accuracy: Accuracy::Tol(tol),
        output: Output::Grid { dt: 0.05 },
        ..Scene::default()
    };
    let tight = chain_run(&model, &scene(1e-13));
    assert!(
        tight.events.len() > 4,
        "the chain sticks and slips: {} events",
        tight.events.len()
    );
    let errs: Vec<f64> = [1e-6, 1e-8, 1e-10]
        .iter()
        .map(|&tol| max_diff(&chain_run(&model, &scene(tol)), &tight))
        .collect();
    eprintln!("max |x − x_tight| at tol 1e-6, 1e-8, 1e-10: {errs:?}");
    for w in errs.windows(2) {
        assert!(w[1] < w[0] / 10.0, "{errs:?}");
    }
    assert!(errs[2] < 1e-6, "{errs:?}");
}

/// A step of the input at t = 10 s on the chain of three is the 1.5 V run to 10 s, then a
/// 2.5 V run from the state reached there: bit for bit before the step, and after it within
/// 1e-10, the rig's bound for the same composition (the stepped run counts time from 0, the
/// composed one from 10 s, so step ends round differently by ulp(20 s); the rig measured up to
/// 1.1e-11 over 20 s of stick-slip).
#[test]
fn a_step_of_the_input_is_two_runs_composed() {
    let model = chain3();
    let first = Scene {
        u: 1.5,
        x0: vec![0.0; model.dim()],
        t_end: 10.0,
        output: Output::Grid { dt: 0.01 },
        ..Scene::default()
    };
    let a = chain_run(&model, &first);
    let b = chain_run(
        &model,
        &Scene {
            u: 2.5,
            x0: a.x_final.clone(),
            ..first.clone()
        },
    );
    let stepped = chain_run(
        &model,
        &Scene {
            input: Some(Input::new(&[[0.0, 1.5], [10.0, 1.5], [10.0, 2.5]]).unwrap()),
            t_end: 20.0,
            ..first.clone()
        },
    );
    let n = a.samples.len();
    assert_eq!(stepped.samples.len(), n + b.samples.len() - 1);
    for i in 0..n {
        assert_eq!(stepped.samples.row(i), a.samples.row(i), "row {i}");
    }
    let after = stepped
        .samples
        .iter()
        .skip(n - 1)
        .zip(b.samples.iter())
        .map(|(r, s)| {
            r.x.iter()
                .zip(s.x)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    eprintln!("after the step: {after:e}");
    assert!(after <= 1e-10, "{after:e}");
}

/// An initial state of the wrong size, a non-finite value and bad options are errors naming
/// the field, never a run.
#[test]
fn a_chain_refuses_bad_input_by_name() {
    let model = chain3();
    let bad = |scene: Scene, needle: &str| {
        let e = SwitchSolver::default()
            .simulate_chain(&model, &scene)
            .unwrap_err();
        assert!(matches!(e, SolveError::InvalidScene(_)), "{e:?}");
        assert!(e.to_string().contains(needle), "{e}");
    };
    bad(Scene::default(), "a chain of 3 discs has 5");
    bad(
        Scene {
            x0: vec![0.0, f64::NAN, 0.0, 0.0, 0.0],
            ..Scene::default()
        },
        "x0[1]",
    );
    bad(
        Scene {
            x0: vec![0.0; 5],
            u: 1e308,
            ..Scene::default()
        },
        "k_m u overflows",
    );
    let mut s = SwitchSolver::default();
    s.options.eta = -1.0;
    let e = s
        .simulate_chain(
            &model,
            &Scene {
                x0: vec![0.0; 5],
                ..Scene::default()
            },
        )
        .unwrap_err();
    assert!(e.to_string().contains("eta"), "{e}");
}
