//! Steady states of chains of N discs (`rotor_analysis::steady::chain`): a cycle of many
//! section crossings, the same by three independent solvers; an aperiodic orbit called so with
//! its evidence; equilibria checked against the model; and no cycle where the run does not
//! show one.

use rotor_analysis::solvers::SolverKind;
use rotor_analysis::steady::chain::{
    APERIODIC_GAP, ChainSteady, ChainSteadyError, ChainSteadyOptions, chain_steady,
};
use rotor_model::seam::{Accuracy, Scene};
use rotor_model::{ChainModel, ChainParams, Params};

/// The rig's top disc and N − 1 copies of its lower disc (Table 1).
fn rig_like(n: usize) -> ChainModel {
    ChainModel::new(&ChainParams::rig_copies(&Params::table1(), n))
}

fn steady_of(
    kind: SolverKind,
    model: &ChainModel,
    u: f64,
    accuracy: Accuracy,
    opts: &ChainSteadyOptions,
) -> Result<ChainSteady, ChainSteadyError> {
    let scene = Scene {
        u,
        x0: vec![0.0; model.dim()],
        accuracy,
        ..Scene::default()
    };
    chain_steady(kind, model, &scene, opts).map(|a| a.state)
}

/// The cycle's metrics as named values (period, then per disc).
fn values(st: &ChainSteady) -> Vec<(String, f64)> {
    let ChainSteady::LimitCycle {
        period,
        omega_max,
        omega_min,
        stick_time,
        ..
    } = st
    else {
        panic!("a cycle, not {st:?}");
    };
    let mut v = vec![("period".to_owned(), *period)];
    for i in 0..omega_max.len() {
        v.push((format!("omega_max[{}]", i + 1), omega_max[i]));
        v.push((format!("omega_min[{}]", i + 1), omega_min[i]));
        v.push((format!("stick_time[{}]", i + 1), stick_time[i]));
    }
    v
}

/// The chain of three rig-like discs at 1.5 V settles, after some 3,600 s, on a cycle of
/// period 188 s that crosses its section (the bottom disc's velocity maxima) 45 times per
/// period (an independent computation found the period ≈ 188 s, 45 crossings, after some
/// 3,500 s). The three solvers
/// find the same cycle, each on its own run: the switch model and Moreau–Jean agree with
/// the event-driven solver on every disc's metrics within twice the sum of the runs' own
/// errors (each against its tighter run: tol/100; h/2 with Richardson's first-order factor
/// 2), plus 1e-9 for the switch model's band (its stuck discs keep up to 1e-10 rad/s).
#[test]
fn a_chain_of_three_settles_on_a_cycle_of_many_crossings_by_every_solver() {
    let model = rig_like(3);
    let opts = ChainSteadyOptions::default();
    let run = |kind, a| steady_of(kind, &model, 1.5, a, &opts).unwrap();
    let ev = run(SolverKind::EVENT, Accuracy::Tol(1e-10));
    let ChainSteady::LimitCycle {
        period,
        crossings,
        return_distance,
        return_tolerance,
        settled_by,
        ..
    } = ev.clone()
    else {
        panic!("a cycle: {ev:?}");
    };
    eprintln!("event: period {period} s, {crossings} crossings, settled by {settled_by} s");
    // The independent computation's numbers: period ≈ 188 s (to the second), 45 crossings.
    assert_eq!(crossings, 45);
    assert!(return_distance <= return_tolerance);
    assert!((period - 188.0).abs() < 0.5, "{period}");
    let ev_tight = run(SolverKind::EVENT, Accuracy::Tol(1e-12));
    let own = |a: &ChainSteady, b: &ChainSteady, factor: f64| -> Vec<f64> {
        values(a)
            .iter()
            .zip(values(b))
            .map(|(p, q)| factor * (p.1 - q.1).abs())
            .collect()
    };
    let ev_est = own(&ev, &ev_tight, 1.0);
    for (kind, a, tight, factor) in [
        (
            SolverKind::SWITCH,
            Accuracy::Tol(1e-10),
            Accuracy::Tol(1e-12),
            1.0,
        ),
        (
            SolverKind::MOREAU,
            Accuracy::Step(1e-3),
            Accuracy::Step(5e-4),
            2.0,
        ),
    ] {
        let (m, mt) = (run(kind, a), run(kind, tight));
        let est = own(&m, &mt, factor);
        let mut worst = (0.0f64, String::new());
        for (k, ((q, v), (_, r))) in values(&m).iter().zip(values(&ev)).enumerate() {
            let gate = 2.0 * (est[k] + ev_est[k]) + 1e-9;
            let ratio = (v - r).abs() / gate;
            if ratio > worst.0 {
                worst = (ratio, format!("{q}: {v} vs {r}"));
            }
        }
        eprintln!(
            "{}: worst / gate = {:.3} ({})",
            kind.name(),
            worst.0,
            worst.1
        );
        assert!(worst.0 <= 1.0, "{}: {worst:?}", kind.name());
    }
}

/// Never a cycle that is not there: with the longest cycle looked for cut below the true
/// one (45 crossings), no shorter one returns, and the answer is a refusal naming the
/// closest return, not a cycle and not "aperiodic" (the orbit does come back, at 45).
/// Nor does a run cut short of the transient (2,000 s, the cycle reached after 3,600 s) give
/// one.
#[test]
fn no_cycle_is_reported_that_the_run_does_not_show() {
    let model = rig_like(3);
    for opts in [
        ChainSteadyOptions {
            max_crossings: 44,
            ..ChainSteadyOptions::default()
        },
        ChainSteadyOptions {
            horizon: 2000.0,
            ..ChainSteadyOptions::default()
        },
    ] {
        let got = steady_of(SolverKind::EVENT, &model, 1.5, Accuracy::Tol(1e-10), &opts);
        eprintln!("{opts:?}: {got:?}");
        assert!(
            matches!(got, Err(ChainSteadyError::Unsettled { .. })),
            "{got:?}"
        );
    }
}

/// The chain of eight rig-like discs at 2.5 V never repeats (an independent computation found
/// no cycle within 15,000 s, and runs at neighbouring tolerances parting ways): the answer is
/// "aperiodic", with no return closer than the gap over 16,000 s and the run at tol/10
/// parting ways after agreeing early on. At 1.5 V the same chain has a cycle (period ≈ 163 s,
/// 26 crossings, by the independent computation), which the same procedure finds.
#[test]
fn a_chain_of_eight_is_aperiodic_at_2_5_volts_and_periodic_at_1_5() {
    let model = rig_like(8);
    let opts = ChainSteadyOptions::default();
    let got = steady_of(SolverKind::EVENT, &model, 2.5, Accuracy::Tol(1e-10), &opts).unwrap();
    eprintln!("2.5 V: {}", serde_json::to_string(&got).unwrap());
    let ChainSteady::Aperiodic {
        closest_return,
        divergence,
        horizon,
        ..
    } = got
    else {
        panic!("aperiodic: {got:?}");
    };
    assert_eq!(horizon, opts.horizon);
    assert!(closest_return.distance > APERIODIC_GAP);
    // Early on the two runs agree to their tolerances (here 1e-7 rad/s), later by the
    // velocities' own size.
    assert!(divergence.early < 1e-5, "{divergence:?}");
    assert!(divergence.late > 1.0, "{divergence:?}");
    let cycle = steady_of(SolverKind::EVENT, &model, 1.5, Accuracy::Tol(1e-10), &opts).unwrap();
    let period = values(&cycle)[0].1;
    eprintln!("1.5 V: period {period}");
    // The independent computation's: ≈ 163 s (to the second), 26 crossings.
    assert!((period - 163.0).abs() < 0.5, "{period}");
    assert!(matches!(
        cycle,
        ChainSteady::LimitCycle { crossings: 26, .. }
    ));
}

/// An equilibrium read off a run satisfies the chain's Filippov system: at 0.02 V the motor's
/// torque (0.08 N m) is below the lower discs' static friction (0.1642 N m), so they stick and
/// the viscous top disc comes to rest on the spring; at 6 V every disc slips at one speed. By
/// every solver.
#[test]
fn equilibria_are_checked_against_the_model() {
    let model = rig_like(3);
    let opts = ChainSteadyOptions::default();
    for u in [0.02, 6.0] {
        for (kind, a) in [
            (SolverKind::EVENT, Accuracy::Tol(1e-10)),
            (SolverKind::SWITCH, Accuracy::Tol(1e-10)),
            (SolverKind::MOREAU, Accuracy::Step(1e-3)),
        ] {
            let got = steady_of(kind, &model, u, a, &opts).unwrap();
            eprintln!("{u} V, {}: {got:?}", kind.name());
            let ChainSteady::Equilibrium {
                omega, residual, ..
            } = got
            else {
                panic!("{u} V, {}: an equilibrium, not {got:?}", kind.name());
            };
            assert!(residual <= 1.0);
            let spread = omega
                .iter()
                .fold(0.0f64, |m, w| m.max((w - omega[0]).abs()));
            assert!(spread <= 1e-6, "{u} V: the discs turn together ({omega:?})");
            if u < 0.1 {
                // Stuck exactly (the switch model: within its band, set to 0 by the check).
                assert!(omega[1..].iter().all(|w| *w == 0.0), "{omega:?}");
            }
        }
    }
}

/// The cycle's multipliers from shooting on the k-th return map agree with how the run
/// itself approached the cycle, an independent measure: from one period to the next, the
/// run's return distance |x_{j+k} − x_j| at the section shrinks by the largest multiplier's
/// modulus (|μ_1|^p after p periods). On the chain of three at 1.5 V the event solver and the
/// switch model shoot to the same multipliers (their own maps; |μ_1| = 0.403), and the
/// event solver's run from rest contracts at that rate over its periods above the noise.
#[test]
fn the_multipliers_are_how_fast_the_run_approaches_the_cycle() {
    use rotor_model::Disc;
    use rotor_model::seam::{EventKind, Output};
    let model = rig_like(3);
    let opts = ChainSteadyOptions::default();
    let mu = |kind| {
        let st = steady_of(kind, &model, 1.5, Accuracy::Tol(1e-10), &opts).unwrap();
        let ChainSteady::LimitCycle {
            multipliers: Some(m),
            crossings,
            ..
        } = st
        else {
            panic!("{}: a shot cycle, not {st:?}", kind.name());
        };
        (m, crossings)
    };
    let ((ev, k), (sw, _)) = (mu(SolverKind::EVENT), mu(SolverKind::SWITCH));
    let modulus = |m: &[f64; 2]| m[0].hypot(m[1]);
    eprintln!("event {ev:?}\nswitch {sw:?}");
    // The switch model's map differs from the event solver's by its band and tolerance:
    // the leading multipliers agree to 1e-3 (measured 4e-5).
    assert!((modulus(&ev[0]) - modulus(&sw[0])).abs() < 1e-3);
    // The run's own contraction, period over period, at the section.
    let scene = Scene {
        u: 1.5,
        x0: vec![0.0; model.dim()],
        t_end: 4000.0,
        accuracy: Accuracy::Tol(1e-10),
        output: Output::Events,
        metrics_from: Some(0.0),
        ..Scene::default()
    };
    let run = SolverKind::EVENT.simulate_chain(&model, &scene).unwrap();
    // The section: the bottom disc's velocity maxima (located when metrics are asked).
    let exits: Vec<&[f64]> = run
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Max(Disc::at(2)))
        .map(|e| e.x.as_slice())
        .collect();
    let dist = |j: usize| {
        exits[j]
            .iter()
            .zip(exits[j - k])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    // Period-over-period ratios of the return distance, where it lies well above the run's
    // noise (1e-6) and below where the transient is still nonlinear (1e-4).
    let mut ratios = Vec::new();
    let last = exits.len() - 1;
    let mut j = last;
    while j >= 2 * k {
        let (a, b) = (dist(j), dist(j - k));
        if (1e-6..1e-4).contains(&a) && (1e-6..1e-4).contains(&b) {
            ratios.push(a / b);
        }
        j -= k;
    }
    eprintln!("contraction per period: {ratios:?}");
    assert!(ratios.len() >= 2, "{ratios:?}");
    for r in &ratios {
        // Within 5 % (measured 0.7 %): the distance over whole periods also holds the
        // decaying smaller modes and the solver's error (1e-8 here).
        assert!(
            (r / modulus(&ev[0]) - 1.0).abs() < 0.05,
            "{r} vs {:?}",
            ev[0]
        );
    }
}

/// On the rig written as a chain of two, the chain's steady state (a run, then Newton on the
/// event solver's own return map, multipliers by differences) is the rig's refined one (the
/// fixed point of its return map, multipliers from the monodromy matrix of the variational
/// equations with saltation matrices): two independent methods. At 1.5, 2.5 and 4 V (stick-
/// slip) the periods agree within the chain's return tolerance, and the nontrivial
/// multiplier within the chain's own error bound plus 1e-10, the tolerance both integrate
/// at (measured differences 7e-11, 1e-10 and 2e-12 against bounds of 1.5e-10 to 3.8e-10).
#[test]
fn on_the_rig_the_chains_cycle_is_the_rigs_refined_one() {
    use rotor_analysis::steady::{SteadyOptions, steady};
    use rotor_model::Model;
    let chain = rig_like(2);
    let opts = ChainSteadyOptions::default();
    for u in [1.5, 2.5, 4.0] {
        let got = steady_of(SolverKind::EVENT, &chain, u, Accuracy::Tol(1e-10), &opts).unwrap();
        let ChainSteady::LimitCycle {
            period,
            multipliers: Some(mu),
            multiplier_error: Some(mu_err),
            return_tolerance,
            ..
        } = got
        else {
            panic!("{u} V: a shot cycle, not {got:?}");
        };
        let scene = Scene {
            u,
            x0: vec![0.0; 3],
            accuracy: Accuracy::Tol(1e-10),
            ..Scene::default()
        };
        let rig = steady(
            SolverKind::EVENT,
            &Model::table1(),
            &scene,
            &SteadyOptions::default(),
        )
        .unwrap();
        let rig_period = rig.state.values()[0].1;
        // The rig's multipliers: the trivial one (≈ 1) first, then the nontrivial one.
        let rig_mu = rig.multipliers.as_ref().unwrap()[1].norm();
        eprintln!(
            "{u} V: period {period} vs {rig_period}; multiplier {:e} (± {mu_err:.1e}) vs {rig_mu:e}",
            mu[0][0]
        );
        assert!((period / rig_period - 1.0).abs() <= return_tolerance);
        assert!((mu[0][0].hypot(mu[0][1]) - rig_mu).abs() <= mu_err + 1e-10);
    }
}
