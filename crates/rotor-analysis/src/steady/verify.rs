//! Every steady answer checked against the model before it is returned.
//!
//! However an answer was obtained (refined, shot, simulated, settled, from the equilibrium
//! equations), it must be what it claims to be:
//!
//! * **An equilibrium** `x* = (α, ω_u, ω_l)` satisfies the Filippov system: `α̇ = ω_u − ω_l =
//!   0`; a slipping disc `d` has `J_d ω̇_d = T_ex,d(x*) − T_f,d(ω_d) = 0`; a stuck disc
//!   (`|ω_d|` within the solver's stuck band, on a set-valued law) has its applied torque
//!   inside its stick interval `[T_lo, T_hi]`. An answer read off a run is known only to
//!   within [`EQUILIBRIUM_AMPLITUDE`] `= δ` (the amplitude below which a run counts as at
//!   rest), so each rate may be off by what a state within δ of the equilibrium has,
//!   `|f_i(x)| ≤ 2 Σ_j |∂f_i/∂x_j| δ` (twice the first-order bound), plus the solvers' stuck
//!   bands in `α̇`; a stuck disc's torque may lie `k_θ δ` outside its interval.
//! * **A cycle** returns to a state on it: the answering solver's own run of one reported
//!   period from that state ends within `ρ (1 + |x_c|∞) + ρ T |f(x_c)|∞` of it, where `ρ`
//!   is the relative accuracy every steady answer is held to (the settling criterion,
//!   [`SettleOptions::rel`], and `rel_per_h · h` for a time-stepper): the shape known to ρ,
//!   the period to ρT, which moves the end along the flow by `ρT |ẋ|`. Its metrics must also
//!   be a cycle's: a positive period, an ω_l range above δ, extrema in order, a stick time
//!   within the period.
//!
//! An answer that fails is refused with [`SteadyError::Refuted`], naming the condition and its
//! residual: never printed.

use crate::solvers::SolverKind;
use rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE;
use rotor_model::seam::{Output, RigSteady, Scene};
use rotor_model::{Disc, DiscMode, Mode, Model, State};

use crate::steady::compute::{SteadyAnswer, SteadyError};
use crate::steady::settle::SettleOptions;

/// The relative accuracy `ρ` a steady answer of `kind` at `scene`'s setting is held to: the
/// settling criterion ([`SettleOptions`]'s `rel`, or `rel_per_h · h` for a time-stepper).
pub fn answer_accuracy(kind: SolverKind, scene: &Scene) -> f64 {
    let o = SettleOptions::default();
    if kind.is_fixed_step() {
        o.rel.max(o.rel_per_h * scene.step())
    } else {
        o.rel
    }
}

/// Checks `answer`, given by `kind` for `scene`, against the model (see the module docs).
pub fn verify(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    answer: &SteadyAnswer,
) -> Result<(), SteadyError> {
    for (name, value) in answer.state.values() {
        if !value.is_finite() {
            return Err(SteadyError::NonFinite { name, value });
        }
    }
    match answer.state {
        RigSteady::Equilibrium {
            omega_u,
            omega_l,
            alpha,
        } => equilibrium(
            model,
            scene.u,
            &State::new(alpha, omega_u, omega_l),
            kind.info().stuck_band,
        ),
        RigSteady::LimitCycle { period, .. } => {
            metrics_of_a_cycle(&answer.state)?;
            let Some(x) = answer.on_cycle else {
                return Err(refuted(
                    "cycle",
                    "the answer carries no state on the cycle to check".into(),
                ));
            };
            returns(kind, model, scene, &x, period)
        }
    }
}

/// `upper` or `lower`, as in events.
fn disc_name(d: Disc) -> std::borrow::Cow<'static, str> {
    d.name_in(2)
}

fn refuted(what: &'static str, detail: String) -> SteadyError {
    SteadyError::Refuted { what, detail }
}

/// The equilibrium conditions at `x` (see the module docs), a disc with `|ω| ≤ band` on a
/// set-valued law counting as stuck.
pub fn equilibrium(model: &Model, u: f64, x: &State, band: f64) -> Result<(), SteadyError> {
    let delta = EQUILIBRIUM_AMPLITUDE;
    let mut mode = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
    let mut stuck = [false; 2];
    for d in Disc::BOTH {
        let w = x[d.index()];
        if model.friction(d).is_set_valued() && w.abs() <= band {
            stuck[d.index() - 1] = true;
            mode.set(d, DiscMode::Stick);
        } else {
            mode.set(d, DiscMode::slip_of(w));
        }
    }
    // The rate of α: bands' worth of velocity for stuck discs, δ's worth for slipping ones.
    let alpha_rate = x[1] - x[2];
    let alpha_allowed = 2.0 * delta + 2.0 * band;
    if alpha_rate.abs() > alpha_allowed {
        return Err(refuted(
            "equilibrium",
            format!(
                "alpha' = omega_u - omega_l = {alpha_rate:e} rad/s at (alpha, omega_u, \
                 omega_l) = ({}, {}, {}), allowed {alpha_allowed:.1e}",
                x[0], x[1], x[2]
            ),
        ));
    }
    let f = model.rhs(x, u, mode);
    let jac = model.jacobian(x, u, mode);
    for d in Disc::BOTH {
        let i = d.index();
        if stuck[i - 1] {
            let (lo, hi) = model.friction(d).static_interval();
            let t = model.applied_torque(d, x, u);
            let slack = model.params.k_theta * delta;
            if t < lo - slack || t > hi + slack {
                return Err(refuted(
                    "equilibrium",
                    format!(
                        "the {} disc is stuck (omega = {}) but its applied torque {t} N m lies \
                         outside its stick interval [{lo}, {hi}] by more than {slack:.1e}",
                        disc_name(d),
                        x[i]
                    ),
                ));
            }
        } else {
            let row: f64 = (0..3).map(|j| jac[(i, j)].abs()).sum();
            let allowed = 2.0 * row * delta + 1e-12 * (1.0 + f[i].abs());
            if f[i].abs() > allowed {
                return Err(refuted(
                    "equilibrium",
                    format!(
                        "the {} disc slips at omega = {} with acceleration {:e} rad/s^2, \
                         allowed {allowed:.1e}",
                        disc_name(d),
                        x[i],
                        f[i]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A cycle's metrics are a cycle's: a positive finite period, an ω_l range above the
/// equilibrium amplitude, extrema in order, a stick time in `[0, period]`.
fn metrics_of_a_cycle(st: &RigSteady) -> Result<(), SteadyError> {
    let RigSteady::LimitCycle {
        period,
        omega_l_max,
        omega_l_min,
        omega_u_max,
        omega_u_min,
        stick_time,
    } = *st
    else {
        return Ok(());
    };
    let bad = if period <= 0.0 {
        Some(format!("its period is {period} s"))
    } else if omega_l_max - omega_l_min <= EQUILIBRIUM_AMPLITUDE {
        Some(format!(
            "its omega_l range {omega_l_min}..{omega_l_max} is not above \
             {EQUILIBRIUM_AMPLITUDE:e} rad/s (an equilibrium's)"
        ))
    } else if omega_u_max < omega_u_min {
        Some(format!("omega_u max {omega_u_max} < min {omega_u_min}"))
    } else if !(0.0..=period).contains(&stick_time) {
        Some(format!(
            "its stick time {stick_time} s is outside [0, {period}]"
        ))
    } else {
        None
    };
    bad.map_or(Ok(()), |detail| Err(refuted("cycle", detail)))
}

/// One period of `kind`'s own run from `x` returns to `x` (see the module docs).
fn returns(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    x: &State,
    period: f64,
) -> Result<(), SteadyError> {
    let run = kind.solver().simulate_finite(
        model,
        &Scene {
            x0: x.as_slice().to_vec(),
            t_end: period,
            output: Output::Final,
            metrics_from: None,
            ..scene.clone()
        },
    )?;
    let rho = answer_accuracy(kind, scene);
    let speed = model.rhs(x, scene.u, model.mode_at(x, scene.u)).amax();
    let allowed = rho * (1.0 + x.amax()) + rho * period * speed;
    let gap = (run.final_state()? - x).amax();
    if gap.is_nan() || gap > allowed {
        return Err(refuted(
            "cycle",
            format!(
                "one period ({period} s) from ({}, {}, {}) ends {gap:.2e} away, allowed \
                 {allowed:.1e}",
                x[0], x[1], x[2]
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::steady::compute::SteadyMethod;

    fn stribeck() -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/params/stribeck.toml");
        Model::new(rotor_model::Params::from_file(&path).unwrap())
    }

    fn answer(state: RigSteady, on_cycle: Option<State>) -> SteadyAnswer {
        SteadyAnswer {
            state,
            method: SteadyMethod::Simulated,
            multipliers: None,
            stable: None,
            stats: Default::default(),
            on_cycle,
        }
    }

    fn is_refuted(r: Result<(), SteadyError>, what: &str) -> bool {
        matches!(r, Err(SteadyError::Refuted { what: w, .. }) if w == what)
    }

    /// The answer the event-driven refinement once gave on the Stribeck set at 1.5 V: the
    /// lower disc on its stick boundary, the upper one turning at 2.43 rad/s.
    #[test]
    fn a_stick_exit_read_as_an_equilibrium_is_refuted() {
        let m = stribeck();
        let x = State::new(3.708, 2.4288098165338288, 0.0);
        assert!(is_refuted(equilibrium(&m, 1.5, &x, 0.0), "equilibrium"));
        // With the upper disc at rest too it is the stuck set's edge: an equilibrium.
        let x = State::new(3.708, 0.0, 0.0);
        let r = equilibrium(&m, 1.5, &x, 0.0);
        let (lo, hi) = m.friction(Disc::UPPER).static_interval();
        let t = m.applied_torque(Disc::UPPER, &x, 1.5);
        assert_eq!(r.is_ok(), lo <= t && t <= hi, "{r:?}");
    }

    /// Every slipping equilibrium of Table 1 passes; moved by 1e-4 rad/s along ω (100 δ,
    /// beyond the allowance of a state within δ) it fails on the acceleration, and with the
    /// discs' velocities apart by 1e-4 it fails on α̇.
    #[test]
    fn slipping_equilibria_pass_and_states_off_them_fail() {
        let m = Model::table1();
        for u in [0.5, 1.5, 2.5, 6.0] {
            for e in m.slip_equilibria(u) {
                let x = e.state();
                equilibrium(&m, u, &x, 0.0).unwrap_or_else(|err| panic!("{u} V: {err}"));
                let both = x + State::new(0.0, 1e-4, 1e-4);
                assert!(is_refuted(equilibrium(&m, u, &both, 0.0), "equilibrium"));
                let apart = x + State::new(0.0, 1e-4, 0.0);
                assert!(is_refuted(equilibrium(&m, u, &apart, 0.0), "equilibrium"));
            }
        }
    }

    /// A stuck state inside the stuck set passes; with the spring torque beyond the lower
    /// disc's stick interval by 1e-3 N m it fails; a switch-model state with ω_l = η passes
    /// with η's band and fails without it.
    #[test]
    fn stuck_states_pass_inside_their_interval_only() {
        let m = Model::table1();
        let u = 0.02;
        let set = m.stuck_equilibria(u).expect("Table 1 sticks at 0.02 V");
        let x = State::new(set.alpha_min, 0.0, 0.0);
        equilibrium(&m, u, &x, 0.0).unwrap();
        let (_, hi) = m.friction(Disc::LOWER).static_interval();
        let beyond = State::new((hi + 1e-3) / m.params.k_theta, 0.0, 0.0);
        let r = equilibrium(&m, u, &beyond, 0.0);
        assert!(r.is_err(), "{r:?}");
        let banded = State::new(set.alpha_min, 0.0, 1e-10);
        if m.friction(Disc::LOWER).is_set_valued() {
            equilibrium(&m, u, &banded, 1e-10).unwrap();
        }
    }

    #[test]
    fn metrics_that_are_no_cycle_are_refused() {
        let cycle = RigSteady::LimitCycle {
            period: 4.5,
            omega_l_max: 3.0,
            omega_l_min: 0.0,
            omega_u_max: 1.6,
            omega_u_min: 1.4,
            stick_time: 1.0,
        };
        metrics_of_a_cycle(&cycle).unwrap();
        // The cycle with one metric replaced.
        let with = |name: &str, value: f64| cycle.map(|n, v| if n == name { value } else { v });
        for bad in [
            with("period", 0.0),
            with("omega_l_max", 1e-7),
            with("omega_u_max", 1.0),
            with("stick_time", 5.0),
        ] {
            assert!(is_refuted(metrics_of_a_cycle(&bad), "cycle"), "{bad:?}");
        }
    }

    /// The event-driven solver's refined 1.5 V cycle of Table 1 returns to its state after
    /// one period; the same metrics with a state 1e-3 rad/s off the cycle do not.
    #[test]
    fn a_cycle_must_return_to_its_start() {
        let m = Model::table1();
        let scene = Scene {
            u: 1.5,
            ..Scene::default()
        };
        let a = crate::steady::steady(SolverKind::EVENT, &m, &scene, &Default::default()).unwrap();
        verify(SolverKind::EVENT, &m, &scene, &a).unwrap();
        let x = a.on_cycle.expect("a refined cycle has a state on it");
        let off = answer(a.state, Some(x + State::new(0.0, 1e-3, 0.0)));
        assert!(is_refuted(
            verify(SolverKind::EVENT, &m, &scene, &off),
            "cycle"
        ));
        let without = answer(a.state, None);
        assert!(is_refuted(
            verify(SolverKind::EVENT, &m, &scene, &without),
            "cycle"
        ));
    }
}
