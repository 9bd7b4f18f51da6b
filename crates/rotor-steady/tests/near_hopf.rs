//! Next to Table 1's first Hopf point the event-driven solver's steady state is the stable
//! attractor the continuation expects ([`rotor_steady::probes::expected`]): the small cycle
//! above it, the equilibrium just below. (An integration test: it judges `steady` by the
//! probes' attractors, and the probes use `steady`.)

use rotor_model::{Attractor, Model, Scene, SteadyKind, SteadyState};
use rotor_solvers::SolverKind;
use rotor_steady::probes::{Expected, expected};
use rotor_steady::{SteadyAnswer, SteadyOptions, steady};

fn answer(kind: SolverKind, m: &Model, u: f64) -> SteadyAnswer {
    let scene = Scene {
        u,
        ..Scene::default()
    };
    steady(kind, m, &scene, &SteadyOptions::default())
        .unwrap_or_else(|e| panic!("{} at {u} V: {e}", kind.name()))
}

fn cycle(st: &SteadyState) -> [f64; 3] {
    match *st {
        SteadyState::LimitCycle {
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
    rotor_bifurcation::equilibria::hopf_points(m, 20.0)[0]
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
    let d = rotor_bifurcation::diagram(&m, &rotor_bifurcation::DiagramOptions::default()).unwrap();
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
    let SteadyState::Equilibrium { omega_l, alpha, .. } = ev.state else {
        unreachable!()
    };
    assert_eq!((omega_l, alpha), (eq.omega, eq.alpha));
}
