//! Convergence order of the Moreau–Jean solver measured against the event-driven solver (the
//! accuracy reference), on the steady-state metrics of the Table 1 stick-slip cycle at
//! u = 1.5 V from rest: `e(h) = |m_moreau(h) − m_event|` for h = 1e-2 … 1e-4, fitted as
//! `e ≈ C·h^p` by least squares in log–log.
//!
//! Why not h = 1e-5: there the second-order error (≈ 6e-11) is no larger than the scheme's
//! own rounding noise over 6·10⁶ steps. Two runs whose step sizes differ by one part in 10⁹
//! (which moves the discretisation error by 2e-9 of itself) differ in the metrics by up to
//! 5e-11, and in the state by 1e-9 after 60 s (the phase drifts). Every fit point must stand
//! clear of that floor, measured the same way at the smallest h.
//!
//! The fitted constants are quoted in `rotor_moreau`'s crate docs; the fixtures' event–moreau
//! tolerances at h = 1e-3 are derived from them (see the scenario files).

use rotor_event::EventSolver;
use rotor_model::{Model, Output, Scene, Solver, State, SteadyState};
use rotor_moreau::{FrictionLevel, MoreauOptions, MoreauSolver};

const HS: [f64; 5] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4];

/// The scene: from rest, the cycle is reached within ~20 s; metrics over [30, 60] s.
fn scene(h: f64, tol: f64) -> Scene {
    Scene {
        u: 1.5,
        x0: State::zeros(),
        t_end: 60.0,
        tol,
        h,
        output: Output::Final,
        metrics_from: Some(30.0),
    }
}

fn cycle(tr: &rotor_model::Trajectory, who: &str) -> (f64, f64) {
    match tr.metrics {
        Some(SteadyState::LimitCycle {
            period,
            omega_l_max,
            ..
        }) => (period, omega_l_max),
        ref m => panic!("{who}: expected a limit cycle, got {m:?}"),
    }
}

/// The event-driven reference at tol = 1e-13, and an upper estimate of its own error: the
/// difference to tol = 1e-12. The solver's error falls with tol (rotor-event's
/// tolerance-convergence test), so that difference is dominated by the tol = 1e-12 run's
/// error and bounds the tighter run's error from above.
fn reference() -> ((f64, f64), f64) {
    let model = Model::table1();
    let run = |tol| {
        cycle(
            &EventSolver::default()
                .simulate(&model, &scene(1e-3, tol))
                .unwrap(),
            "event",
        )
    };
    let tight = run(1e-13);
    let loose = run(1e-12);
    let err = (tight.0 - loose.0).abs().max((tight.1 - loose.1).abs());
    (tight, err)
}

/// Least-squares slope and constant of log e = log C + p log h.
fn fit(h: &[f64], e: &[f64]) -> (f64, f64) {
    let n = h.len() as f64;
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let p = sxy / sxx;
    (p, (my - p * mx).exp())
}

/// Errors against the reference at every h, and the fitted (order, constant) of the period
/// and of max ω_l.
fn orders(options: MoreauOptions, label: &str) -> [(f64, f64); 2] {
    let ((p_ref, w_ref), ref_err) = reference();
    let model = Model::table1();
    let mut ep = Vec::new();
    let mut ew = Vec::new();
    let run = |h: f64| {
        let tr = MoreauSolver::new(options)
            .simulate(&model, &scene(h, 1e-10))
            .unwrap();
        assert_eq!(tr.stats.inexact_steps, 0, "{label} h={h}");
        cycle(&tr, label)
    };
    let mut last = (0.0, 0.0);
    for h in HS {
        last = run(h);
        ep.push((last.0 - p_ref).abs());
        ew.push((last.1 - w_ref).abs());
    }
    // Rounding noise of the scheme at the smallest h (the most steps): the same run with h
    // changed by 1e-9 relative, a change of the discretisation error far below the noise.
    let nudged = run(HS[HS.len() - 1] * (1.0 + 1e-9));
    let noise = (nudged.0 - last.0).abs().max((nudged.1 - last.1).abs());
    let r = [fit(&HS, &ep), fit(&HS, &ew)];
    eprintln!(
        "{label} (reference period {p_ref:.9}, max omega_l {w_ref:.9}, error <= {ref_err:.1e}; \
         rounding noise at h = {:.0e}: {noise:.1e}): period errors {ep:?} -> order {:.3}, \
         C {:.3e}; omega_l_max errors {ew:?} -> order {:.3}, C {:.3e}",
        HS[HS.len() - 1],
        r[0].0,
        r[0].1,
        r[1].0,
        r[1].1
    );
    // The smallest error measured must stand well above the reference's own error, or the
    // fit would measure the reference. A factor 5 perturbs ln e at the smallest h by at most
    // ln 1.2 = 0.18; that point's weight in the least-squares slope over the five points
    // (log10 h = −2, −2.52, −3, −3.52, −4) is |x − x̄|/Sxx = ln 10/(2(1 + 0.48²)(ln 10)²)
    // = 0.18, so the slope moves by < 0.04.
    // The same argument covers the scheme's rounding noise, largest at the smallest h.
    let smallest = ep.iter().chain(&ew).cloned().fold(f64::INFINITY, f64::min);
    assert!(
        smallest > 5.0 * (ref_err + noise),
        "{label}: error {smallest:.2e} not resolved by the reference ({ref_err:.2e}) and \
         above the rounding noise ({noise:.2e})"
    );
    r
}

#[test]
fn moreau_theta_half_implicit_level_converges_at_second_order_to_the_event_solver() {
    let r = orders(MoreauOptions::default(), "theta=1/2 implicit");
    for (p, c) in r {
        // The bar (Siconos' MoreauJeanOSI reaches ≈ 2 here): a fitted slope ≥ 1.8
        // over two decades excludes any first-order scheme.
        assert!(p >= 1.8, "order {p}");
        // The fixtures' event–moreau steady_rel = 3e-6 at h = 1e-3 allows C·h² ≤ 3e-6 × (period
        // 4.58 s, max ω_l 6.34 rad/s), i.e. C ≤ 13.7 on the period and ≤ 19 on max ω_l; the
        // fit (C ≈ 0.6–0.7) must stay inside that, with the 20× margin kept for the other
        // fixtures' cycles.
        assert!(c < 13.7, "constant {c}");
    }
}

#[test]
fn moreau_explicit_level_converges_at_first_order_to_the_event_solver() {
    let r = orders(
        MoreauOptions {
            friction_level: FrictionLevel::Explicit,
            ..MoreauOptions::default()
        },
        "theta=1/2 explicit",
    );
    for (p, _) in r {
        // First order expected (the level lags by one step): 1 ± 0.2 separates it from both
        // order 2 and order 1/2 over two decades of h.
        assert!((0.8..=1.2).contains(&p), "order {p}");
    }
}

#[test]
fn moreau_theta_one_converges_at_first_order_to_the_event_solver() {
    let r = orders(
        MoreauOptions {
            theta: 1.0,
            ..MoreauOptions::default()
        },
        "theta=1 implicit",
    );
    for (p, _) in r {
        // Backward-Euler velocity update: first order; same band as above.
        assert!((0.8..=1.2).contains(&p), "order {p}");
    }
}
