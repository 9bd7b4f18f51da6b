//! `steady`'s answers next to special points: below Table 1's fold of cycles and grazing
//! end the event-driven solver's refined cycle is the switch model's settled one; next to
//! the first Hopf point it is the stable attractor the continuation expects
//! ([`rotor_analysis::steady::probes::expected`]: the small cycle above it, the equilibrium just
//! below); and the answer's JSON. (Integration tests: the Hopf test judges `steady` by the
//! probes' attractors, and the probes use `steady`.)

use rotor_analysis::solvers::SolverKind;
use rotor_analysis::steady::probes::{Expected, expected};
use rotor_analysis::steady::{SteadyAnswer, SteadyMethod, SteadyOptions, steady};
use rotor_model::Model;
use rotor_model::seam::{Attractor, RigSteady, Scene, SteadyKind};

fn answer(kind: SolverKind, m: &Model, u: f64) -> SteadyAnswer {
    let scene = Scene {
        u,
        ..Scene::default()
    };
    steady(kind, m, &scene, &SteadyOptions::default())
        .unwrap_or_else(|e| panic!("{} at {u} V: {e}", kind.name()))
}

fn cycle(st: &RigSteady) -> [f64; 3] {
    match *st {
        RigSteady::LimitCycle {
            period,
            omega_l_max,
            omega_l_min,
            ..
        } => [period, omega_l_max, omega_l_min],
        _ => panic!("not a cycle: {st:?}"),
    }
}

/// Largest difference of period and ω_l extremes, relative with a floor of 1.
fn diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1.0))
        .fold(0.0, f64::max)
}

/// The first Hopf point of Table 1 (supercritical) at full precision.
fn hopf1(m: &Model) -> f64 {
    rotor_analysis::bifurcation::equilibria::hopf_points(m, 20.0)[0]
        .equilibrium
        .u
}

/// At 1e-4 V above the first Hopf point every solver gave up after 20 000 s (the small
/// cycle grows at a rate proportional to u − u_H). The event-driven solver now answers
/// it: the stable cycle of the continuation at that input (Newton from the Hopf
/// eigenvector), within 1e-6 (its probe agreement); just below the Hopf point (1e-6 V) it
/// answers the equilibrium the orbit spirals into, which no run settles on in 20 000 s.
#[test]
fn next_to_the_first_hopf_point_the_event_solver_answers() {
    let m = Model::table1();
    let uh = hopf1(&m);
    let d = rotor_analysis::bifurcation::diagram(
        &m,
        &rotor_analysis::bifurcation::DiagramOptions::default(),
    )
    .unwrap();
    let above = uh + 1e-4;
    let ev = answer(SolverKind::EVENT, &m, above);
    let stable = expected(&m, &d, above);
    // The small cycle born at the supercritical Hopf point slips: no stick phase yet.
    let cycle_kinds: Vec<Attractor> = stable
        .iter()
        .map(Expected::attractor)
        .filter(|a| a.steady_kind() == SteadyKind::LimitCycle)
        .collect();
    assert_eq!(cycle_kinds, [Attractor::SlippingCycle]);
    let cycles: Vec<[f64; 3]> = stable
        .into_iter()
        .filter_map(|a| match a {
            Expected::Cycle {
                period,
                omega_l_max,
                omega_l_min,
                ..
            } => Some([period, omega_l_max, omega_l_min]),
            _ => None,
        })
        .collect();
    assert_eq!(cycles.len(), 1, "one stable cycle at {above} V");
    let dd = diff(cycle(&ev.state), cycles[0]);
    assert!(dd <= 1e-6, "{:?} vs {:?}: {dd:e}", ev.state, cycles[0]);
    assert!(ev.multipliers.unwrap()[1..].iter().all(|z| z.norm() < 1.0));

    let below = uh - 1e-6;
    let ev = answer(SolverKind::EVENT, &m, below);
    assert_eq!(ev.state.kind(), SteadyKind::Equilibrium, "{:?}", ev.state);
    let eq = m.slip_equilibria(below)[0];
    assert!(m.equilibrium_is_stable(&eq));
    let RigSteady::Equilibrium { omega_l, alpha, .. } = ev.state else {
        unreachable!()
    };
    assert_eq!((omega_l, alpha), (eq.omega, eq.alpha));
}

/// 2e-4 V below the fold of cycles E (4.8430 V) the stable and the unstable cycle lie
/// close together; the return-map Newton once converged to the unstable one (ω_l in
/// [0.519, 16.761]) while the switch model and Moreau–Jean, which only simulate, reached
/// [0.478, 16.801]. The refined answer is now the stable cycle: it agrees with the switch
/// model's settled run within the switch model's probe agreement, 1e-5 (the wrong cycle
/// is 2.4e-3 away), and its saltation multipliers lie inside the unit circle.
#[test]
fn below_the_fold_of_cycles_the_event_solver_answers_the_stable_cycle() {
    let m = Model::table1();
    let ev = answer(SolverKind::EVENT, &m, 4.8428);
    let sw = answer(SolverKind::SWITCH, &m, 4.8428);
    assert_eq!(ev.method, SteadyMethod::Refined);
    let d = diff(cycle(&ev.state), cycle(&sw.state));
    assert!(
        d <= 1e-5,
        "event {:?} vs switch {:?}: {d:e}",
        ev.state,
        sw.state
    );
    let mu = ev
        .multipliers
        .as_ref()
        .expect("a refined cycle has multipliers");
    assert_eq!(mu.len(), 3);
    // The trivial multiplier 1 (to the monodromy's accuracy, 1e-9 here) and the others
    // inside the unit circle.
    assert!(
        (mu[0].re - 1.0).abs() < 1e-9 && mu[0].im.abs() < 1e-9,
        "{mu:?}"
    );
    assert!(mu[1..].iter().all(|z| z.norm() < 1.0), "{mu:?}");
}

/// Just below the grazing end of the stick-slip branch (4.6153 V) the switch model once
/// answered a period-2 or period-3 cycle (period 8.43 or 12.64 s). Its answer is now the
/// one-period cycle of the event-driven solver: period and ω_l extremes within the switch
/// model's probe agreement, 1e-5 (a period-2 cycle is 100 % away).
#[test]
fn below_the_grazing_end_the_switch_model_answers_the_one_period_cycle() {
    let m = Model::table1();
    for u in [4.615_276_8, 4.615_276_875_05 - 1e-6] {
        let ev = answer(SolverKind::EVENT, &m, u);
        let sw = answer(SolverKind::SWITCH, &m, u);
        let d = diff(cycle(&ev.state), cycle(&sw.state));
        assert!(
            d <= 1e-5,
            "{u} V: event {:?} vs switch {:?}",
            ev.state,
            sw.state
        );
    }
}

/// The JSON of `rotor steady`: the metrics, then how they were obtained, then the
/// multipliers (`null` for a simulated answer).
#[test]
fn the_answer_serializes_with_method_and_multipliers() {
    let m = Model::table1();
    let ev = serde_json::to_value(answer(SolverKind::EVENT, &m, 1.5)).unwrap();
    assert_eq!(ev["kind"], "limit_cycle");
    assert_eq!(ev["method"], "refined");
    assert_eq!(ev["multipliers"].as_array().unwrap().len(), 3);
    let sw = serde_json::to_value(answer(SolverKind::SWITCH, &m, 1.5)).unwrap();
    assert_eq!(sw["method"], "simulated");
    assert!(sw["multipliers"].is_null());
}
