//! A time-varying input u(t): every row's time is a step end, and a step of u from rest
//! starts the motion at the step.

use rotor_model::seam::{Accuracy, Input, Output, Scene, Solver};
use rotor_model::{Model, State};

/// No step straddles a breakpoint: with a ramp that has kinks at t = 10 s and 30 s and a
/// step at 35 s, both times are step ends exactly.
#[test]
fn every_breakpoint_is_a_step_end() {
    let input = Input::new(&[[10.0, 1.5], [30.0, 2.5], [35.0, 2.5], [35.0, 2.0]]).unwrap();
    let scene = Scene {
        input: Some(input.clone()),
        t_end: 40.0,
        accuracy: Accuracy::Step(1e-3),
        output: Output::Steps,
        ..Scene::default()
    };
    let tr = rotor_moreau::MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    for b in input.breakpoints() {
        assert!(
            tr.samples.iter().any(|s| s.t == b),
            "no step ends on the breakpoint {b}"
        );
        assert!(
            !tr.samples.windows(2).any(|w| w[0].t < b && b < w[1].t),
            "a step straddles the breakpoint {b}"
        );
    }
}

/// At rest at u = 0 (nothing moves: the state stays exactly 0), then 2.5 V from t = 1 s:
/// the stick condition is read at the new value at the step itself, so the upper disc is
/// already moving one output interval later, and the state is exactly 0 up to the step.
/// (The 1.5 V cycle's upper disc never sticks, so at 2.5 V its applied torque exceeds what
/// friction holds at rest.)
#[test]
fn a_step_from_rest_starts_the_motion_at_the_step() {
    let input = Input::new(&[[1.0, 0.0], [1.0, 2.5]]).unwrap();
    let scene = Scene {
        input: Some(input),
        x0: State::zeros(),
        t_end: 1.5,
        accuracy: Accuracy::Step(1e-3),
        output: Output::Grid { dt: 0.01 },
        ..Scene::default()
    };
    let tr = rotor_moreau::MoreauSolver::default()
        .simulate(&Model::table1(), &scene)
        .unwrap();
    for s in tr.samples.iter().filter(|s| s.t <= 1.0) {
        assert_eq!(s.x, State::zeros(), "at t = {}", s.t);
    }
    let after = tr.samples.iter().find(|s| s.t > 1.0).unwrap();
    assert!(after.x[1] > 0.0, "{:?}", after);
    assert!(tr.samples.last().unwrap().x[1] > 0.1);
}
