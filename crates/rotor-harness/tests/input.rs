//! Inputs that change in time, u(t), across the three solvers: every row's time is a step
//! end, a step of u is the composition of two constant-input runs, a ramp converges at each
//! solver's order, the metrics-only fast-forward stays off, and a step from rest starts the
//! motion at the step.

use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_model::Model;
use rotor_model::seam::{Accuracy, Input, Output, Row, Scene, Trajectory};

/// Table 1's rig at 1.5 V from rest (its stick-slip cycle), stepped to 2.5 V at t = 60 s.
fn step_input() -> Input {
    Input::new(&[[60.0, 1.5], [60.0, 2.5]]).unwrap()
}

/// Each solver's own accuracy for the step test: tight, so that the comparison measures the
/// breakpoint handling, not a loose run's sensitivity.
fn accuracy(kind: SolverKind) -> Accuracy {
    if kind.is_fixed_step() {
        Accuracy::Step(1e-3)
    } else {
        Accuracy::Tol(1e-11)
    }
}

fn run(kind: SolverKind, scene: &Scene) -> Trajectory {
    kind.solver()
        .simulate_finite(&Model::table1(), scene)
        .unwrap_or_else(|e| panic!("{}: {e}", kind.name()))
}

/// The largest |Δx| between two sample lists of the same length.
fn max_diff<'a>(
    a: impl ExactSizeIterator<Item = Row<'a>>,
    b: impl ExactSizeIterator<Item = Row<'a>>,
) -> f64 {
    assert_eq!(a.len(), b.len());
    a.zip(b)
        .flat_map(|(p, q)| p.x.iter().zip(q.x).map(|(v, w)| (v - w).abs()))
        .fold(0.0, f64::max)
}

/// A step of u at t = 60 s gives, for each solver, the trace of two constant-input runs
/// composed: 1.5 V to t = 60 s, then 2.5 V from the state reached there, over the whole run
/// (20 s past the step, in which the rig leaves the 1.5 V cycle).
///
/// Each solver restarts at a breakpoint as a fresh run does (the event solver re-chooses the
/// mode and the first step; the switch model re-chooses the regions and Hairer's initial
/// step; Moreau–Jean restarts its step grid there), so the two traces are the same
/// computation: before the step bit for bit, after it up to where the clocks differ. The
/// composed run counts time from 0, the stepped one from 60 s: its step ends `60 + t` are
/// rounded to ulp(80 s) = 1.4e-14 s, which moves an interpolated grid sample by
/// |ẋ|·1.4e-14 ≤ 1e-12 (|ẋ| ≤ 30 rad/s² on this run) and the last, shortened step's size by
/// as much; a solver whose steps do not depend on t (all three, on a constant piece) keeps
/// that difference at that level. The bound 1e-10 leaves room for the growth of such a
/// rounding difference over 20 s of stick-slip: measured 9.2e-13 (event, tol 1e-11),
/// 1.1e-11 (switch, tol 1e-11), 1.3e-13 (Moreau–Jean, h = 1e-3).
#[test]
fn a_step_is_two_constant_runs_composed() {
    for kind in SOLVERS {
        let dt = 0.01;
        let stepped = Scene {
            input: Some(step_input()),
            t_end: 80.0,
            accuracy: accuracy(kind),
            output: Output::Grid { dt },
            ..Scene::default()
        };
        let first = Scene {
            u: 1.5,
            t_end: 60.0,
            accuracy: accuracy(kind),
            output: Output::Grid { dt },
            ..Scene::default()
        };
        let a = run(kind, &first);
        let second = Scene {
            u: 2.5,
            x0: a.x_final.clone(),
            t_end: 20.0,
            ..first.clone()
        };
        let b = run(kind, &second);
        let full = run(kind, &stepped);
        let n = a.samples.len();
        assert_eq!(full.samples.len(), n + b.samples.len() - 1);
        let first_diff = (0..n).find(|&i| full.samples.row(i) != a.samples.row(i));
        assert_eq!(
            first_diff,
            None,
            "{}: up to the step, the stepped run is the 1.5 V run: {:?}",
            kind.name(),
            first_diff.map(|i| (full.samples.row(i), a.samples.row(i)))
        );
        let after = max_diff(full.samples.iter().skip(n - 1), b.samples.iter());
        eprintln!(
            "{}: composition max |dx| after the step {after:e}",
            kind.name()
        );
        assert!(after <= 1e-10, "{}: {after:e}", kind.name());
        // The step does change the run: 2.5 V is not 1.5 V.
        let unstepped = run(
            kind,
            &Scene {
                u: 1.5,
                t_end: 80.0,
                ..first.clone()
            },
        );
        assert!(max_diff(full.samples.iter(), unstepped.samples.iter()) > 0.1);
    }
}

/// A ramp with kinks: 1.5 V to t = 10 s, up to 2.5 V at t = 30 s, held to 40 s.
fn ramp() -> Input {
    Input::new(&[[10.0, 1.5], [30.0, 2.5]]).unwrap()
}

fn ramp_scene(accuracy: Accuracy) -> Scene {
    Scene {
        input: Some(ramp()),
        t_end: 40.0,
        accuracy,
        output: Output::Grid { dt: 0.05 },
        ..Scene::default()
    }
}

/// Least-squares slope of log e against log s.
fn order(s: &[f64], e: &[f64]) -> f64 {
    let n = s.len() as f64;
    let x: Vec<f64> = s.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// On a ramp (u linear in t between breakpoints, so the field depends on t there), each
/// solver converges at its order against the event solver at tol 1e-13: the grid's L∞
/// error over the run, fitted as `e ≈ C·s^p` in log–log.
///
/// Expected orders: the adaptive solvers' global error is proportional to their tolerance
/// (p ≈ 1: a local error per unit step held at tol by the controller, summed over a
/// horizon of fixed length; Hairer, Nørsett & Wanner I, II.4), which holds only if u(t) is
/// evaluated at the stage times (a u frozen per step would add an O(h) local error that
/// the controller does not see). Moreau–Jean at θ = ½ is of order 2 in h on smooth slip
/// (the θ-rule with the motor torque weighted as the θ-method weights it, exact for u
/// linear in the step), and its stick onsets and exits at step resolution cost an O(h)
/// local error once per event, O(h) globally only in phase; the rotor_moreau crate docs
/// measure ≈ 2 on this rig's cycle. The fits are taken above each solver's error floor
/// (the switch model's band η = 1e-10 and rounding for the adaptive ones; h ≥ 3e-4 for
/// Moreau–Jean, where its error stays ≥ 1e-7). The acceptance windows are the expected
/// order ± 0.3 (tolerance proportionality is approximate: the controller's safety factors
/// and rejected steps move the exponent by ~0.1–0.2 on smooth problems).
#[test]
fn a_ramp_converges_at_each_solvers_order() {
    let reference = run(SolverKind::EVENT, &ramp_scene(Accuracy::Tol(1e-13)));
    let tols = [1e-6, 1e-7, 1e-8, 1e-9];
    let hs = [1e-2, 5e-3, 2.5e-3, 1.25e-3];
    for kind in SOLVERS {
        let (ladder, expected): (Vec<Accuracy>, f64) = if kind.is_fixed_step() {
            (hs.iter().map(|&h| Accuracy::Step(h)).collect(), 2.0)
        } else {
            (tols.iter().map(|&t| Accuracy::Tol(t)).collect(), 1.0)
        };
        let errors: Vec<f64> = ladder
            .iter()
            .map(|&a| {
                max_diff(
                    run(kind, &ramp_scene(a)).samples.iter(),
                    reference.samples.iter(),
                )
            })
            .collect();
        let knobs: Vec<f64> = ladder.iter().map(|a| a.value()).collect();
        let p = order(&knobs, &errors);
        eprintln!(
            "{}: errors {:?} at {knobs:?}: order {p:.2}",
            kind.name(),
            errors
                .iter()
                .map(|e| format!("{e:.3e}"))
                .collect::<Vec<_>>()
        );
        assert!(
            (p - expected).abs() <= 0.3,
            "{}: order {p:.2}, expected {expected}",
            kind.name()
        );
    }
}

/// `Output::Metrics` skips whole periods of a converged cycle for a constant input, and not
/// for a time-varying one (a skip assumes one period is the next): the same rig, the same
/// horizon, once at 1.5 V and once with a step at a time past the horizon's end's reach
/// (t = 1000 s, so that u is 1.5 V throughout the run and only the skip can differ).
#[test]
fn the_fast_forward_is_off_for_a_time_varying_input() {
    for kind in SOLVERS {
        let constant = Scene {
            t_end: 300.0,
            accuracy: accuracy(kind),
            output: Output::Metrics,
            metrics_from: Some(100.0),
            ..Scene::default()
        };
        let varying = Scene {
            input: Some(Input::new(&[[150.0, 1.5], [150.0, 1.5 + 1e-12]]).unwrap()),
            ..constant.clone()
        };
        assert!(varying.is_time_varying());
        let c = run(kind, &constant);
        let v = run(kind, &varying);
        assert!(
            c.stats.skipped_periods > 0,
            "{}: the constant run skips",
            kind.name()
        );
        assert_eq!(v.stats.skipped_periods, 0, "{}", kind.name());
        assert!(v.stats.steps > c.stats.steps, "{}", kind.name());
    }
}

/// No step straddles a breakpoint: with a ramp that has kinks at t = 10 s and 30 s and a
/// step at 35 s, every row's time is a step end exactly, in every solver (the adaptive ones
/// at tol 1e-12, Moreau–Jean at h = 1e-3).
#[test]
fn every_breakpoint_is_a_step_end() {
    let input = Input::new(&[[10.0, 1.5], [30.0, 2.5], [35.0, 2.5], [35.0, 2.0]]).unwrap();
    for kind in SOLVERS {
        let scene = Scene {
            input: Some(input.clone()),
            t_end: 40.0,
            accuracy: if kind.is_fixed_step() {
                Accuracy::Step(1e-3)
            } else {
                Accuracy::Tol(1e-12)
            },
            output: Output::Steps,
            ..Scene::default()
        };
        let tr = run(kind, &scene);
        for b in input.breakpoints() {
            assert!(
                tr.samples.iter().any(|s| s.t == b),
                "{}: no step ends on the breakpoint {b}",
                kind.name()
            );
            assert!(
                !tr.samples.times().windows(2).any(|w| w[0] < b && b < w[1]),
                "{}: a step straddles the breakpoint {b}",
                kind.name()
            );
        }
    }
}

/// A rig at rest that a step of u sets moving starts at the step itself, in every solver
/// (the stick condition read at the new u).
#[test]
fn a_step_from_rest_starts_the_motion_at_the_step() {
    // Rest at u = 0 (nothing moves), then 2.5 V from t = 1 s, where the upper disc slips
    // (it never sticks on the 1.5 V cycle either): exactly at rest up to t = 1 s.
    let input = Input::new(&[[1.0, 0.0], [1.0, 2.5]]).unwrap();
    for kind in SOLVERS {
        let scene = Scene {
            input: Some(input.clone()),
            x0: vec![0.0; 3],
            t_end: 2.0,
            accuracy: accuracy(kind),
            output: Output::Grid { dt: 0.01 },
            ..Scene::default()
        };
        let tr = run(kind, &scene);
        for s in &tr.samples {
            if s.t <= 1.0 {
                assert_eq!(s.x, [0.0; 3], "{} at {}", kind.name(), s.t);
            }
        }
        // Already moving one output interval after the step.
        let after = tr.samples.iter().find(|s| s.t > 1.0).unwrap();
        assert!(after.x[1] > 0.0, "{}: {:?}", kind.name(), after);
        let last = tr.samples.last().unwrap();
        assert!(last.x[1] > 0.1, "{}: {:?}", kind.name(), last.x);
    }
}
