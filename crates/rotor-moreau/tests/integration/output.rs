//! The scene's output levels, events, metrics and errors.

use rotor_model::seam::{Accuracy, EventKind, Output, OutputGrid, Scene, SolveError, Solver};
use rotor_model::{Disc, Model, OMEGA_U};
use rotor_moreau::{MoreauOptions, MoreauSolver, Stepper};

fn base() -> Scene {
    Scene {
        u: 1.5,
        x0: vec![0.0; 3],
        t_end: 1.0,
        output: Output::Final,
        metrics_from: None,
        ..Scene::with_step(0.003)
    }
}

/// The solver the CLI selects as "moreau" produces the Moreau–Jean scheme's steps: its Steps
/// output is, bit for bit, the default [`Stepper`] iterated by hand (333 steps of h, then the
/// shortened last one onto t_end).
#[test]
fn name_is_moreau_and_its_samples_are_the_steppers() {
    let solver = MoreauSolver::default();
    assert_eq!(solver.name(), "moreau");
    let scene = Scene {
        output: Output::Steps,
        ..base()
    };
    let tr = solver.simulate(&Model::table1(), &scene).unwrap();
    let model = Model::table1();
    let st = Stepper::new(&model, scene.u, &MoreauOptions::default());
    let mut x = scene.x0_state().unwrap();
    let samples = tr.samples.rig().unwrap();
    assert_eq!(samples[0].x, x);
    for (k, s) in samples.iter().enumerate().skip(1) {
        let t0 = samples[k - 1].t;
        let h = if k < 334 {
            scene.step()
        } else {
            scene.t_end - t0
        };
        x = st.step(t0, &x, h).unwrap().x;
        assert_eq!(s.x, x, "step {k} at t = {}", s.t);
    }
    assert_eq!(tr.samples.len(), 335);
    // Not a run at rest: the upper disc spins up (ω_u ≈ 2.6 rad/s at t = 1 s).
    assert!(x[OMEGA_U] > 1.0, "{x:?}");
}

#[test]
fn final_keeps_no_samples_and_no_events() {
    let scene = Scene {
        t_end: 30.0,
        metrics_from: Some(10.0),
        ..base()
    };
    let tr = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    assert!(tr.samples.is_empty());
    assert!(tr.events.is_empty());
    assert!(tr.rig_metrics().is_some());
    assert!(tr.stats.events > 0, "events are located for the metrics");
    assert_eq!(tr.t_final, 30.0);
}

#[test]
fn steps_keep_every_step_and_land_on_t_end() {
    let scene = Scene {
        output: Output::Steps,
        ..base()
    };
    let tr = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    // 1.0 / 0.003 = 333.3: 333 full steps and a shortened last one.
    assert_eq!(tr.stats.steps, 334);
    assert_eq!(tr.samples.len(), 335);
    assert_eq!(tr.samples.t(0), 0.0);
    let last = tr.samples.last().unwrap();
    assert_eq!(last.t, 1.0);
    assert_eq!(last.x, tr.x_final);
    for w in tr.samples.rig().unwrap().windows(2) {
        let dt = w[1].t - w[0].t;
        assert!(dt > 0.0 && dt <= 0.003 * (1.0 + 1e-12));
    }
    assert_eq!(
        tr.stats.lcp_solves + tr.stats.lcp_skipped,
        tr.stats.steps,
        "every step either solves or skips"
    );
}

#[test]
fn grid_matches_output_grid() {
    let scene = Scene {
        output: Output::Grid { dt: 0.01 },
        ..base()
    };
    let tr = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    let mut g = OutputGrid::new(0.01, 1.0);
    let mut times = Vec::new();
    while let Some(t) = g.peek() {
        times.push(t);
        g.advance();
    }
    let got: Vec<f64> = tr.samples.iter().map(|s| s.t).collect();
    assert_eq!(got, times);
    assert_eq!(tr.samples.last().unwrap().x, tr.x_final);
    // Linear interpolation between step ends: a grid sample lies between its neighbours'
    // step values; check against a Steps run.
    let steps = MoreauSolver::default()
        .simulate(
            &Model::table1(),
            &Scene {
                output: Output::Steps,
                ..base()
            },
        )
        .unwrap();
    let steps = steps.samples.rig().unwrap();
    for s in tr.samples.rig().unwrap() {
        let k = steps.partition_point(|p| p.t < s.t);
        let b = steps[k];
        let a = steps[k.saturating_sub(1)];
        let x = if b.t == a.t {
            b.x
        } else {
            a.x + (b.x - a.x) * ((s.t - a.t) / (b.t - a.t))
        };
        // Same formula, same data: equal to rounding.
        assert!((x - s.x).amax() <= 1e-13, "t={}: {:?} vs {:?}", s.t, x, s.x);
    }
}

#[test]
fn events_are_ordered_and_stick_phases_alternate() {
    let scene = Scene {
        t_end: 40.0,
        accuracy: Accuracy::Step(1e-3),
        output: Output::Events,
        ..base()
    };
    let tr = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    assert!(tr.samples.is_empty());
    assert!(tr.events.windows(2).all(|w| w[0].t <= w[1].t));
    assert!(
        !tr.events
            .iter()
            .any(|e| matches!(e.kind, EventKind::Max(_) | EventKind::Min(_))),
        "extrema only when metrics are asked"
    );
    let lower: Vec<EventKind> = tr
        .events
        .iter()
        .map(|e| e.kind)
        .filter(|k| {
            matches!(
                k,
                EventKind::StickStart(Disc::LOWER) | EventKind::StickEnd(Disc::LOWER)
            )
        })
        .collect();
    // From rest the lower disc starts stuck: exit, onset, exit, …
    assert!(lower.len() >= 10, "{lower:?}");
    for (i, k) in lower.iter().enumerate() {
        let want = if i % 2 == 0 {
            EventKind::StickEnd(Disc::LOWER)
        } else {
            EventKind::StickStart(Disc::LOWER)
        };
        assert_eq!(*k, want, "event {i}");
    }
    for e in &tr.events {
        if let EventKind::StickStart(d) | EventKind::StickEnd(d) | EventKind::Reversal(d) = e.kind {
            assert_eq!(e.x[d.index()], 0.0);
        }
    }
    let with_metrics = MoreauSolver::default()
        .simulate(
            &Model::table1(),
            &Scene {
                metrics_from: Some(20.0),
                ..scene
            },
        )
        .unwrap();
    let maxima: Vec<_> = with_metrics
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Max(Disc::LOWER))
        .collect();
    assert!(maxima.len() >= 7, "one per cycle of ~4.6 s");
    assert!(with_metrics.events.windows(2).all(|w| w[0].t <= w[1].t));
}

#[test]
fn skipping_changes_nothing() {
    let scene = Scene {
        t_end: 20.0,
        accuracy: Accuracy::Step(1e-3),
        output: Output::Steps,
        ..base()
    };
    let a = MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    let b = MoreauSolver::new(MoreauOptions {
        skip_free_steps: false,
        ..MoreauOptions::default()
    })
    .simulate(&Model::table1(), &scene)
    .unwrap();
    assert!(a.stats.lcp_skipped > a.stats.steps / 2, "{:?}", a.stats);
    assert!(a.stats.lcp_solves > 0);
    assert_eq!(b.stats.lcp_skipped, 0);
    let diff = a
        .samples
        .iter()
        .zip(&b.samples)
        .map(|(p, q)| (p.state() - q.state()).amax())
        .fold(0.0, f64::max);
    // Both paths converge Newton to 1e-12·(1 + |v|) per step; over 2e4 steps of a
    // contracting (dissipative) system that stays below 1e-9.
    assert!(diff < 1e-9, "{diff:e}");
}

#[test]
fn typed_errors() {
    let m = Model::table1();
    let s = MoreauSolver::default();
    assert!(matches!(
        s.simulate(&m, &Scene { accuracy: Accuracy::Step(0.0), ..base() }),
        Err(SolveError::InvalidScene(e)) if e.field == "h"
    ));
    assert!(matches!(
        s.simulate(
            &m,
            &Scene {
                x0: vec![0.0, f64::INFINITY, 0.0],
                ..base()
            }
        ),
        Err(SolveError::InvalidScene(_))
    ));
    let bad = MoreauSolver::new(MoreauOptions {
        theta: 0.3,
        ..MoreauOptions::default()
    });
    assert!(matches!(
        bad.simulate(&m, &base()),
        Err(SolveError::InvalidScene(e)) if e.field == "theta"
    ));
    let few = MoreauSolver::new(MoreauOptions {
        max_steps: 10,
        ..MoreauOptions::default()
    });
    assert!(matches!(
        few.simulate(&m, &base()),
        Err(SolveError::TooManySteps { .. })
    ));
}
