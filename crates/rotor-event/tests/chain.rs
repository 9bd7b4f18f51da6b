//! The event-driven solver on chains of N discs: the rig's chain of two is the rig's run bit
//! for bit, a chain converges in the tolerance at the method's rate, a step of the input is
//! two runs composed, and what a chain cannot take is refused by name.

use rotor_event::EventSolver;
use rotor_model::seam::{
    Accuracy, EventKind, Input, Output, Scene, SolveError, Solver, Trajectory,
};
use rotor_model::{ChainModel, ChainParams, Model, Params};

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
    EventSolver::default()
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
/// state on the stack), bit for bit: samples, events (extrema included), final state and
/// mode, and the work counters, on Table 1 and on the Stribeck set (whose upper disc sticks as
/// well), at two tolerances, keeping the grid and keeping the events. The two are one code
/// path on two storages, so any difference is a bug in the generic state, not a rounding.
#[test]
fn a_chain_of_two_is_the_rigs_run_bit_for_bit() {
    for (name, p) in [("table1", Params::table1()), ("stribeck", stribeck())] {
        let rig = Model::new(p);
        let chain = ChainModel::new(&ChainParams::from_params(&p));
        for output in [Output::Grid { dt: 0.01 }, Output::Events] {
            for tol in [1e-8, 1e-12] {
                let scene = Scene {
                    u: 1.5,
                    t_end: 40.0,
                    accuracy: Accuracy::Tol(tol),
                    output,
                    ..Scene::default()
                };
                let a = EventSolver::default().simulate(&rig, &scene).unwrap();
                let b = chain_run(&chain, &scene);
                let what = format!("{name} {output:?} tol {tol:e}");
                assert!(
                    a.events
                        .iter()
                        .any(|e| matches!(e.kind, EventKind::StickStart(_))),
                    "{what}: the run sticks and slips"
                );
                assert_eq!(a.samples, b.samples, "{what}");
                assert_eq!(a.events, b.events, "{what}");
                assert_eq!(a.x_final, b.x_final, "{what}");
                assert_eq!(a.mode_final, b.mode_final, "{what}");
                assert_eq!(a.stats, b.stats, "{what}");
            }
        }
    }
}

/// Self-convergence in the tolerance on two chains: the chain of three (a Stribeck disc at its
/// end, a viscous coupling) and Table 1's rig with six more lower discs, over 20 s of
/// stick-slip from rest, each run against one at tol 1e-13. DOP853 with tolerance
/// proportionality and located events gives a global error roughly proportional to tol, so
/// every 100× tighter tolerance must cut the difference by at least 10× (a decade of room:
/// the stick events' timing is refined to rounding, but the error of each slip phase is
/// carried on), and at tol 1e-10 the run must be within 1e-7 of the tight one (10³
/// tolerances: the growth of a local error over 20 s of stick-slip; measured in the message).
#[test]
fn chains_converge_in_the_tolerance() {
    let chains = [
        ("chain of 3", chain3()),
        (
            "chain of 8",
            ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 8)),
        ),
    ];
    for (name, model) in chains {
        let scene = |tol: f64| Scene {
            u: 1.5,
            x0: vec![0.0; model.dim()],
            t_end: 20.0,
            accuracy: Accuracy::Tol(tol),
            output: Output::Grid { dt: 0.05 },
            ..Scene::default()
        };
        let tight = chain_run(&model, &scene(1e-13));
        let sticks = tight
            .events
            .iter()
            .filter(|e| matches!(e.kind, EventKind::StickStart(_)))
            .count();
        assert!(sticks >= 3, "{name}: the chain sticks and slips ({sticks})");
        let errs: Vec<f64> = [1e-6, 1e-8, 1e-10]
            .iter()
            .map(|&tol| max_diff(&chain_run(&model, &scene(tol)), &tight))
            .collect();
        eprintln!("{name}: max |x − x_tight| at tol 1e-6, 1e-8, 1e-10: {errs:?}");
        for w in errs.windows(2) {
            assert!(w[1] < w[0] / 10.0, "{name}: {errs:?}");
        }
        assert!(errs[2] < 1e-7, "{name}: {errs:?}");
    }
}

/// A step of the input at t = 10 s on the chain of three is the 1.5 V run to 10 s, then a
/// 2.5 V run from the state (and the modes) reached there: bit for bit before the step, and
/// after it within 1e-10, the bound the rig's same composition meets (the stepped run counts
/// time from 0, the composed one from 10 s, so step ends round differently by ulp(20 s)).
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

/// Every disc of a chain of eight has its own guards: the stick-slip wave running down Table
/// 1's rig with six more lower discs releases every lower disc from rest and sticks several
/// of them again, each event naming its disc, each disc's events alternating stick exit and
/// onset, and a stuck disc's velocity held at exactly 0 at every event of the others.
#[test]
fn every_disc_of_a_chain_sticks_and_slips_on_its_own_guards() {
    let model = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 8));
    let run = chain_run(
        &model,
        &Scene {
            u: 1.5,
            x0: vec![0.0; model.dim()],
            t_end: 40.0,
            output: Output::Events,
            ..Scene::default()
        },
    );
    for i in 1..8 {
        let own: Vec<&EventKind> = run
            .events
            .iter()
            .map(|e| &e.kind)
            .filter(|k| {
                matches!(k, EventKind::StickStart(d) | EventKind::StickEnd(d) if d.position() == i)
            })
            .collect();
        assert!(
            matches!(own.first(), Some(EventKind::StickEnd(_))),
            "disc {}: released from rest first: {own:?}",
            i + 1
        );
        for w in own.windows(2) {
            assert_ne!(
                std::mem::discriminant(w[0]),
                std::mem::discriminant(w[1]),
                "disc {}: onsets and exits alternate",
                i + 1
            );
        }
    }
    let sticks = run
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::StickStart(_)))
        .count();
    assert!(sticks >= 3, "the wave sticks discs again ({sticks})");
    // Replaying the modes along the events: a disc stuck at an event has ω exactly 0 there.
    let mut stuck = [true; 8];
    stuck[0] = false;
    for e in &run.events {
        for (i, &s) in stuck.iter().enumerate() {
            if s {
                assert_eq!(e.x[model.omega(i)], 0.0, "disc {} at t = {}", i + 1, e.t);
            }
        }
        match e.kind {
            EventKind::StickStart(d) => stuck[d.position()] = true,
            EventKind::StickEnd(d) => stuck[d.position()] = false,
            _ => {}
        }
    }
}

/// An initial state of the wrong size and a non-finite value are errors naming the field,
/// never a run.
#[test]
fn a_chain_refuses_bad_input_by_name() {
    let model = chain3();
    let bad = |scene: Scene, needle: &str| {
        let e = EventSolver::default()
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
}

/// Two discs switching within one step: at a loose tolerance (1e-5) the steps of the chain of
/// eight are long (the mean step is printed), and several stick onsets and exits of
/// different discs fall closer together than one of them. Each is located in turn (the step
/// ends at the earliest, the next starts there and finds the other) and the run gives the
/// tight run's events, disc by disc and in order, within the loose tolerance's error.
#[test]
fn two_discs_switching_within_one_step_are_both_found() {
    let model = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 8));
    let at = |tol: f64| {
        chain_run(
            &model,
            &Scene {
                u: 1.5,
                x0: vec![0.0; model.dim()],
                t_end: 40.0,
                accuracy: Accuracy::Tol(tol),
                output: Output::Events,
                ..Scene::default()
            },
        )
    };
    let (loose, tight) = (at(1e-5), at(1e-12));
    let switches = |t: &Trajectory| -> Vec<(usize, EventKind, f64)> {
        t.events
            .iter()
            .filter_map(|e| match e.kind {
                EventKind::StickStart(d) | EventKind::StickEnd(d) | EventKind::Reversal(d) => {
                    Some((d.position(), e.kind, e.t))
                }
                _ => None,
            })
            .collect()
    };
    let (a, b) = (switches(&loose), switches(&tight));
    let mean_step = 40.0 / loose.stats.steps as f64;
    let close = a
        .windows(2)
        .filter(|w| w[0].0 != w[1].0 && w[1].2 - w[0].2 < mean_step)
        .count();
    eprintln!(
        "{} switches, mean step {mean_step:.3} s, {close} pairs of discs closer than it",
        a.len()
    );
    assert!(
        close >= 2,
        "the loose run has discs switching within one step"
    );
    for d in 0..8 {
        let of = |v: &[(usize, EventKind, f64)]| -> Vec<(EventKind, f64)> {
            v.iter().filter(|e| e.0 == d).map(|e| (e.1, e.2)).collect()
        };
        let (la, tb) = (of(&a), of(&b));
        assert_eq!(
            la.iter().map(|e| e.0).collect::<Vec<_>>(),
            tb.iter().map(|e| e.0).collect::<Vec<_>>(),
            "disc {}",
            d + 1
        );
        for (p, q) in la.iter().zip(&tb) {
            // The loose run's event times err by its global error over 40 s of stick-slip:
            // the convergence test above measured 1.6e-4 in the state at tol 1e-6, so 1e-2 s
            // at 1e-5 leaves a decade for the time's division by the velocity's rate.
            assert!((p.1 - q.1).abs() < 1e-2, "disc {}: {p:?} vs {q:?}", d + 1);
        }
    }
}
