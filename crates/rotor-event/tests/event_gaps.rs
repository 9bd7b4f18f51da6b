//! Event-location gaps of the event-driven solver, each in a situation
//! built to provoke it, with the expected answer derived independently (a closed-form
//! solution, an exactly symmetric system, or the same state started in its consistent mode).

use std::path::Path;

use rotor_event::{EventOptions, EventSolver, StopAt, flow};
use rotor_model::seam::{EventKind, Output, Scene, Solver};
use rotor_model::{Disc, DiscMode, LowerFriction, Mode, Model, Params, State, UpperFriction};

fn fixtures() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn stribeck() -> Model {
    Model::new(Params::from_file(&fixtures().join("params/stribeck.toml")).unwrap())
}

/// The mode switches among a run's events (extrema left out).
fn switches(events: &[rotor_model::seam::Event]) -> Vec<rotor_model::seam::Event> {
    events
        .iter()
        .filter(|e| !matches!(e.kind, EventKind::Max(_) | EventKind::Min(_)))
        .cloned()
        .collect()
}

/// The float nearest to `hi / k` whose product with `k` is exactly `hi` (searched among a
/// few neighbours), so that a state sits exactly on a stick edge.
fn exact_edge(hi: f64, k: f64) -> f64 {
    let a = hi / k;
    let mut c = a;
    for _ in 0..8 {
        if k * c == hi {
            return c;
        }
        c = f64::from_bits(c.to_bits() + 1);
    }
    c = a;
    for _ in 0..8 {
        if k * c == hi {
            return c;
        }
        c = f64::from_bits(c.to_bits() - 1);
    }
    panic!("no float a with {k}·a == {hi}");
}

/// A stick-exit guard that dips below zero and back inside one step, at a reversal of the
/// other disc. Table 1, lower disc stuck, upper disc slipping forward: with ω_l = 0 the upper
/// disc obeys the linear J_u α̈ + b_u α̇ + k_θ α = k_m u (T_su = 0, so its friction is b_u ω),
/// overdamped, and α rises to a maximum where ω_u = 0 (the upper disc's reversal) and falls
/// back. The initial speed is chosen so that the maximum passes the lower disc's stick edge
/// T_sl/k_θ by 1e-8 rad: the spring torque leaves the stick interval for ~0.7 ms around the
/// reversal, far inside one step and one guard-sample interval. The lower disc must leave
/// stick at the closed-form root of α(t) = T_sl/k_θ, before the reversal. (Before the fix
/// the exit guard was never tested for a dip: the run stayed stuck through the excursion,
/// and the first switch was the reversal.)
#[test]
fn a_stick_exit_guard_dipping_inside_one_step_is_found() {
    let m = Model::table1();
    let p = m.params;
    let u = 0.02;
    let (jj, b, k) = (p.j_u, p.upper.b, p.k_theta);
    let a_star = p.k_m * u / k;
    let edge = m.friction(Disc::LOWER).static_interval().1 / k;
    // y = α − α*: y'' + (b/J) y' + (k/J) y = 0, y(0) = 0, y'(0) = v.
    let disc = (b * b - 4.0 * jj * k).sqrt();
    let (r1, r2) = ((-b + disc) / (2.0 * jj), (-b - disc) / (2.0 * jj));
    let shape = |t: f64| ((r1 * t).exp() - (r2 * t).exp()) / (r1 - r2);
    let slope = |t: f64| (r1 * (r1 * t).exp() - r2 * (r2 * t).exp()) / (r1 - r2);
    let t_max = (r2 / r1).ln() / (r1 - r2);
    let overshoot = 1e-8;
    let v = (edge - a_star + overshoot) / shape(t_max);
    // The exit: y(t) = edge − α* on the rising side, by Newton from the parabola's root.
    let curv = v * (r1 * r1 * (r1 * t_max).exp() - r2 * r2 * (r2 * t_max).exp()) / (r1 - r2);
    let mut t_exit = t_max - (2.0 * overshoot / curv.abs()).sqrt();
    for _ in 0..50 {
        t_exit -= (v * shape(t_exit) - (edge - a_star)) / (v * slope(t_exit));
    }
    let alpha_dot = v * slope(t_exit);
    assert!(t_exit < t_max && alpha_dot > 0.0);
    let tol = 1e-12;
    let scene = Scene {
        u,
        x0: vec![a_star, v, 0.0],
        t_end: 3.0,
        output: Output::Events,
        ..Scene::with_tol(tol)
    };
    for samples in [1, 4] {
        let solver = EventSolver {
            options: EventOptions {
                guard_samples: samples,
                ..EventOptions::default()
            },
        };
        let tr = solver.simulate(&m, &scene).unwrap();
        let sw = switches(&tr.events);
        let first = sw.first().expect("no switch");
        assert_eq!(
            first.kind,
            EventKind::StickEnd(Disc::LOWER),
            "{samples} samples: {sw:?}"
        );
        // The event's error in time is the state's error in α over α̇ at the root: the
        // integration error ~ tol·(1 + |α|) per unit time, times a 100 margin for its growth
        // over the 1 s run and the closed form's own rounding (~1e-16/α̇).
        let gate = 100.0 * tol * (1.0 + edge) / alpha_dot;
        assert!(
            (first.t - t_exit).abs() < gate,
            "{samples} samples: exit at {} s, closed form {t_exit} s (gate {gate:e} s; the \
             reversal is at {t_max} s)",
            first.t
        );
    }
}

/// A disc stuck exactly on an edge of its stick interval after a switch. Stribeck set at
/// 0.5 V, both discs stuck at ω = 0 with the spring torque exactly T_sl (α = T_sl/k_θ to
/// the last bit): the upper disc's applied torque k_m u − k_θ α = 1.88 N m is far above its
/// interval, so it leaves at once; after that switch α̈ = ω̇_u > 0, the spring torque moves
/// out of the lower disc's interval (at second order: α̇ = 0 there), and the lower disc must
/// leave too. The run must be the run started from the same state in the consistent mode,
/// both discs slipping forward. (Before the fix: the edge check ran at a run's start only,
/// required a first-order outward rate, and a guard already ≤ 0 never fired, so both discs
/// stayed stuck forever.) The same holds for a consistent start (upper slipping, lower on its
/// edge), where the old start check, wanting a first-order rate, kept the lower disc stuck
/// while the spring wound up.
#[test]
fn a_disc_stuck_on_its_edge_after_a_switch_leaves_at_once() {
    let m = stribeck();
    let u = 0.5;
    let hi = m.friction(Disc::LOWER).static_interval().1;
    let alpha = exact_edge(hi, m.params.k_theta);
    let x = State::new(alpha, 0.0, 0.0);
    let stuck = Mode::rig(DiscMode::Stick, DiscMode::Stick);
    let slipping = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
    let tol = 1e-12;
    let run = |mode| flow(&m, u, tol, x, mode, 10.0, StopAt::Time).unwrap();
    let a = run(stuck);
    let kinds: Vec<_> = a.events.iter().take(2).map(|e| (e.t, e.kind)).collect();
    assert_eq!(
        kinds,
        [
            (0.0, EventKind::StickEnd(Disc::UPPER)),
            (0.0, EventKind::StickEnd(Disc::LOWER))
        ]
    );
    let b = run(slipping);
    // Once both have left, the two runs take the same steps from the same state.
    assert_eq!(a.x, b.x, "from stick {:?}, from slip {:?}", a.x, b.x);
    // The consistent start, through the solver's own mode choice: lower stuck on its edge.
    let tr = EventSolver::default()
        .simulate(
            &m,
            &Scene {
                u,
                x0: x.as_slice().to_vec(),
                t_end: 10.0,
                output: Output::Events,
                ..Scene::with_tol(tol)
            },
        )
        .unwrap();
    let first = tr.events.first().cloned();
    assert!(
        first
            .as_ref()
            .is_some_and(|e| e.t == 0.0 && e.kind == EventKind::StickEnd(Disc::LOWER)),
        "{first:?}"
    );
    assert_eq!(tr.x_final, b.x.as_slice());
}

/// Both discs sticking at one instant. Equal inertias, equal friction laws (upper T_su =
/// 0.375 with b_u = 0.25; lower exponential family with t_1 = t_2 = 0, T_sl = 0.375, b_l =
/// 0.25) and k_m u − k_θ α = k_θ α = 0.25 N m: from equal speeds the two velocities are
/// equal to the last bit (the same operations on the same numbers), α stays constant, and
/// both discs obey ω̇ = −0.25 − 0.5 ω, reaching 0 together at t = 2 ln(1 + 2 ω₀). The applied
/// torque 0.25 N m lies inside both stick intervals, so both must stick there and the state
/// must freeze at (0.5, 0, 0). Whichever disc the solver switches first, the other's velocity
/// guard is then 0 or a rounding below it. (Before the fix a guard ≤ 0 at a switch never
/// fired: the other disc stayed in forward slip with a negative velocity, its friction
/// driving it, and ran away.)
#[test]
fn both_discs_sticking_at_one_instant_both_stick() {
    let m = Model::new(Params {
        j_u: 0.5,
        k_m: 1.0,
        k_theta: 0.5,
        j_l: 0.5,
        upper: UpperFriction {
            t_s: 0.375,
            dt_s: 0.0,
            b: 0.25,
            db: 0.0,
        },
        lower: LowerFriction::Exponential {
            t_s: 0.375,
            t_1: 0.0,
            t_2: 0.0,
            w_1: 1.0,
            w_2: 1.0,
            b: 0.25,
        },
    });
    let tol = 1e-12;
    for w0 in [0.3, 0.5, 1.0, 1.7, 2.0, 3.1, 5.0] {
        let tr = EventSolver::default()
            .simulate(
                &m,
                &Scene {
                    u: 0.5,
                    x0: vec![0.5, w0, w0],
                    t_end: 20.0,
                    output: Output::Events,
                    ..Scene::with_tol(tol)
                },
            )
            .unwrap();
        let sw = switches(&tr.events);
        let t_stick = 2.0 * (1.0 + 2.0 * w0).ln();
        assert_eq!(sw.len(), 2, "ω₀ = {w0}: {sw:?}");
        let mut kinds: Vec<_> = sw.iter().map(|e| e.kind).collect();
        kinds.sort_by_key(|k| k.disc());
        assert_eq!(
            kinds,
            [
                EventKind::StickStart(Disc::UPPER),
                EventKind::StickStart(Disc::LOWER)
            ],
            "ω₀ = {w0}"
        );
        // One instant: the second switch is taken at the first's time.
        assert_eq!(sw[0].t, sw[1].t, "ω₀ = {w0}: {sw:?}");
        // The time's error: the velocity's (~tol·(1 + ω₀)) over |ω̇| = 0.25 at the root,
        // times 100 for its growth over the run.
        let gate = 100.0 * tol * (1.0 + w0) / 0.25;
        assert!(
            (sw[0].t - t_stick).abs() < gate,
            "ω₀ = {w0}: {sw:?} vs {t_stick}"
        );
        assert_eq!(tr.x_final, [0.5, 0.0, 0.0], "ω₀ = {w0}");
    }
}
