//! The steady state reached from an initial state, by any solver, with what stands behind
//! it: `rotor steady` (and the Python package's `steady`).
//!
//! * The event-driven solver refines: a settling run, then the fixed point of a return map,
//!   accepted only if stable ([`rotor_event::steady_state`]). Its Floquet multipliers are then
//!   computed independently, from the monodromy matrix of the variational equations with
//!   saltation matrices ([`crate::bifurcation::monodromy`]), and must agree that the cycle is
//!   stable.
//! * Every other solver simulates until its metrics stop changing ([`crate::steady::settle`]).
//!
//! Each answer says how it was obtained ([`SteadyMethod`]). A solver that cannot resolve the
//! steady state at its setting says so and why ([`SteadyError`]) rather than answering with a
//! different cycle.

use crate::bifurcation::continuation::{ContOptions, Continuer};
use crate::bifurcation::periodic::{Shooter, T_RETURN};
use nalgebra::Complex;
use rotor_model::seam::{RigSteady, Scene, SolveError, Stats};
use rotor_model::{Model, State};
use serde::Serialize;

use crate::solvers::registry::SolverKind;
use crate::steady::settle::{SettleError, SettleOptions, settle};

/// How a steady state was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SteadyMethod {
    /// From the equilibrium equations (or the stuck set), after a settling run.
    Equilibrium,
    /// A stable fixed point of a return map (event-driven solver).
    Refined,
    /// The last cycle of a run that settled to a cycle-to-cycle drift of 1e-10, where the
    /// refinement found no stable fixed point (event-driven solver).
    Settled,
    /// The metrics of a simulation once they stopped changing (see [`crate::steady::settle`]).
    Simulated,
    /// A periodic orbit found by shooting on the solver's own return map ([`shot`]), stable
    /// or not.
    Shoot,
}

/// Settings of [`steady`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SteadyOptions {
    /// The event-driven solver's refinement (its `tol` is the integration tolerance).
    pub event: rotor_event::SteadyOptions,
    /// The other solvers' settling runs.
    pub settle: SettleOptions,
}

/// A steady state as `rotor steady` prints it: the metrics, how they were obtained and, for a
/// refined cycle, its Floquet multipliers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SteadyAnswer {
    /// The metrics: an equilibrium's state, or a cycle's period, extremes and stick time.
    #[serde(flatten)]
    pub state: RigSteady,
    /// How they were obtained.
    pub method: SteadyMethod,
    /// Floquet multipliers `[re, im]` of a refined cycle, the trivial one (≈ 1) first, then by
    /// decreasing modulus: `[1, λ, 0]` with a stick phase, `[1, λ1, λ2]` without; `None` for an
    /// equilibrium and for a simulated cycle.
    #[serde(serialize_with = "complex_list")]
    pub multipliers: Option<Vec<Complex<f64>>>,
    /// Whether a cycle found by shooting is stable (every multiplier but the trivial one
    /// inside the unit circle); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stable: Option<bool>,
    /// Work counters of the run behind the answer where one is kept (a simulated answer, or
    /// a shot orbit's metrics run); zero otherwise.
    #[serde(skip)]
    pub stats: Stats,
    /// A state on a cycle (the fixed point of the return map, or a settled run's final
    /// state), from which one period of the solver's run returns to it
    /// ([`crate::steady::verify`]); `None` for an equilibrium.
    #[serde(skip)]
    pub on_cycle: Option<State>,
}

fn complex_list<S: serde::Serializer>(
    m: &Option<Vec<Complex<f64>>>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match m {
        Some(v) => s.collect_seq(v.iter().map(|z| [z.re, z.im])),
        None => s.serialize_none(),
    }
}

/// Why there is no steady state to report.
#[derive(Debug, thiserror::Error)]
pub enum SteadyError {
    /// A run failed, the scene is inadmissible, or the event-driven refinement found no
    /// steady state.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// Shooting found no periodic orbit (or the run settles to an equilibrium).
    #[error(
        "shooting found no periodic orbit (if the run settles to an equilibrium, --method \
         simulate answers it)"
    )]
    Shoot(#[from] crate::shoot::ShootError),
    /// A simulating solver's metrics did not settle ([`crate::steady::settle`]).
    #[error(transparent)]
    Settle(#[from] SettleError),
    /// The refined cycle's saltation multipliers put it outside the unit circle although the
    /// return map's differences did not: its stability is not decided at this tolerance.
    #[error(
        "the refined cycle's stability is undecided: its Floquet multipliers from the \
         monodromy matrix are {multipliers}, the return map's differences gave {estimate}; \
         the input is too close to a bifurcation of the cycle for this tolerance"
    )]
    Undecided {
        /// The monodromy matrix's multipliers, as printed.
        multipliers: String,
        /// The return map's difference estimate, as printed.
        estimate: String,
    },
    /// Shooting found a periodic orbit near where a run from the start went, but a multiplier
    /// lies on or outside the unit circle, and the run decays onto no stable equilibrium.
    #[error(
        "the periodic orbit shooting found (period {period:.6} s) is unstable: its Floquet \
         multipliers are {multipliers}; it is not the steady state"
    )]
    Unstable {
        /// The orbit's Floquet multipliers, as printed.
        multipliers: String,
        /// Its period \[s\].
        period: f64,
    },
    /// Shooting found a periodic orbit whose largest multiplier is too close to the unit
    /// circle for its differences to decide its stability, and the run from the start went
    /// to no attractor within the check's time.
    #[error(
        "the periodic orbit shooting found (period {period:.6} s) has a multiplier within \
         1e-3 of the unit circle ({multipliers}), closer than the return map's differences \
         resolve: its stability is undecided (the input is next to a bifurcation)"
    )]
    Neutral {
        /// The orbit's Floquet multipliers, as printed.
        multipliers: String,
        /// Its period \[s\].
        period: f64,
    },
    /// The orbit shooting found is stable, but a run from the start had not come to it (at
    /// the rate its multipliers predict, or within the solver's reproducibility) by `t`.
    #[error(
        "a run from the start has not reached the stable orbit shooting found (multipliers \
         {multipliers}) after {t} s: its last return is {distance:.2e} away and not yet \
         approaching at the multipliers' rate (a slow transient next to a special point)"
    )]
    NotReached {
        /// Simulated time from the start \[s\].
        t: f64,
        /// `|z − z*|∞` of the run's last return to the section from the orbit's fixed point
        /// (section coordinates, rad/s).
        distance: f64,
        /// The orbit's Floquet multipliers, as printed.
        multipliers: String,
    },
    /// The default method's two answers both failed: shooting found a stable orbit that a
    /// run from the start had not reached by the check's end ([`SteadyError::NotReached`]),
    /// and the simulation did not settle either.
    #[error(
        "no steady state confirmed from this start: {check}; and simulating on: {simulate}. \
         `--method shoot` answers the orbit shooting finds, without the check that the start \
         goes to it"
    )]
    Unconfirmed {
        /// The check's refusal.
        check: Box<SteadyError>,
        /// The simulation's.
        simulate: Box<SteadyError>,
    },
    /// The answer fails the model's own check ([`crate::steady::verify`]): an "equilibrium" where
    /// the field does not vanish, a "cycle" that does not return to its start.
    #[error("the {what} found is refuted by the model's own equations: {detail}")]
    Refuted {
        /// `equilibrium` or `cycle`.
        what: &'static str,
        /// The condition that failed, with its residual and the allowance.
        detail: String,
    },
    /// A value of the answer is not finite.
    #[error("the steady state has a non-finite {name}: {value}")]
    NonFinite {
        /// The metric ([`RigSteady::values`]'s name).
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

/// The steady state that `kind` reaches from `scene.x0` at `scene.u` (the scene's `tol` or
/// `h` is the solver's setting; its `t_end`, `output` and `metrics_from` are not used).
/// For the event-driven solver the integration tolerance is `opts.event.tol`.
///
/// # Example
///
/// Table 1 at 1.5 V from rest. The event-driven solver refines the stick-slip cycle as a
/// stable fixed point of its return map and gives its Floquet multipliers `[1, λ, 0]` (the
/// stick phase collapses one direction); Moreau–Jean (h = 1e-3) simulates until its metrics
/// settle and finds the same cycle to O(h²).
///
/// ```
/// use rotor_model::{Model, State};
/// use rotor_model::seam::{Scene, RigSteady};
/// use rotor_analysis::solvers::SolverKind;
/// use rotor_analysis::steady::{SteadyMethod, steady};
///
/// let model = Model::table1();
/// let scene = Scene { u: 1.5, x0: vec![0.0; 3], ..Scene::default() };
/// let a = steady(SolverKind::EVENT, &model, &scene, &Default::default())?;
/// let RigSteady::LimitCycle { period, stick_time, .. } = a.state else { panic!("{a:?}") };
/// assert!((period - 4.5777579).abs() < 1e-6); // the 1.5 V stick-slip cycle
/// assert!(stick_time > 0.0);
/// assert_eq!(a.method, SteadyMethod::Refined);
/// let mu = a.multipliers.expect("a refined cycle has its multipliers");
/// assert!((mu[0].re - 1.0).abs() < 1e-6, "the trivial multiplier, along the flow");
/// assert!(mu[1].norm() < 1.0, "stable: {mu:?}");
/// assert!(mu[2].norm() < 1e-12, "0 up to rounding: the stick phase");
///
/// let m = steady(SolverKind::MOREAU, &model, &scene, &Default::default())?;
/// assert_eq!(m.method, SteadyMethod::Simulated);
/// let RigSteady::LimitCycle { period: pm, .. } = m.state else { panic!("{m:?}") };
/// assert!((pm - period).abs() < 1e-5, "Moreau-Jean's period {pm} s");
/// # Ok::<(), rotor_analysis::steady::SteadyError>(())
/// ```
pub fn steady(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    opts: &SteadyOptions,
) -> Result<SteadyAnswer, SteadyError> {
    constant_input(scene)?;
    scene.validate()?;
    let answer = if kind == SolverKind::EVENT {
        refined(model, scene.u, scene.x0_state()?, opts)?
    } else {
        simulated(kind, model, scene, opts)?
    };
    crate::steady::verify::verify(kind, model, scene, &answer)?;
    Ok(answer)
}

/// Refuses a scene whose input changes in time ([`Scene::is_time_varying`]): a steady state
/// (an equilibrium or a cycle of the flow, shooting on its return map) is one of a
/// time-invariant system.
pub(crate) fn constant_input(scene: &Scene) -> Result<(), SteadyError> {
    if scene.is_time_varying() {
        return Err(SolveError::Unsupported {
            detail: "a steady state needs a constant input: this scene's input changes in time \
                     (input)"
                .into(),
        }
        .into());
    }
    Ok(())
}

/// How long the run from the start is before shooting starts from its last crossing of the
/// section \[s\]: enough to come near a cycle that attracts at a multiplier ≤ 0.99 per ~4.5 s
/// period from rest (e^(-0.01·300/4.5) ≈ 0.5 of the start's distance is left, which Newton
/// removes); a slower one needs a start nearer the cycle (`--x0`).
pub const SHOOT_RUN: f64 = 300.0;

/// The periodic orbit near the one a run from `scene.x0` approaches, by shooting on `kind`'s
/// own return map ([`crate::shoot`]), stable or not: its metrics (one run over two periods
/// from the fixed point), the Floquet multipliers `[1, λ, 0]` (a stick phase) or
/// `[1, λ1, λ2]`, and whether it is stable. An error when the run settles to an equilibrium.
pub fn shot(kind: SolverKind, model: &Model, scene: &Scene) -> Result<SteadyAnswer, SteadyError> {
    constant_input(scene)?;
    scene.validate()?;
    let solver = kind.solver();
    let opts = crate::shoot::ShootOptions::default();
    let (section, z0) =
        crate::shoot::Section::of_run(&*solver, model, scene, scene.x0_state()?, SHOOT_RUN)?;
    let orbit = crate::shoot::shoot(&*solver, model, scene, section, &z0, &opts)?;
    // The metrics of the orbit: its last complete cycle of a run over two periods.
    let t_end = 2.0 * orbit.period + opts.skip;
    let run = solver.simulate_finite(
        model,
        &Scene {
            x0: orbit.x.as_slice().to_vec(),
            t_end,
            output: rotor_model::seam::Output::Final,
            metrics_from: Some(0.0),
            ..scene.clone()
        },
    )?;
    let answer = shot_answer(&orbit, run, t_end)?;
    crate::steady::verify::verify(kind, model, scene, &answer)?;
    Ok(answer)
}

/// The steady state that `kind` settles on by simulating from `scene.x0` until its metrics
/// stop changing ([`crate::steady::settle`]), for every solver (the event-driven one included:
/// `rotor steady --method simulate`), checked against the model ([`crate::steady::verify`]).
pub fn simulated(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    opts: &SteadyOptions,
) -> Result<SteadyAnswer, SteadyError> {
    constant_input(scene)?;
    scene.validate()?;
    let s = settle(kind, model, scene, &opts.settle)?;
    let answer = SteadyAnswer {
        on_cycle: matches!(s.state, RigSteady::LimitCycle { .. }).then_some(s.x),
        state: s.state,
        method: SteadyMethod::Simulated,
        multipliers: None,
        stable: None,
        stats: s.stats,
    };
    crate::steady::verify::verify(kind, model, scene, &answer)?;
    Ok(answer)
}

/// The answer of a shot orbit: the metrics of `run` (two periods from the orbit's state,
/// `t_end` long) and the orbit's multipliers, with the trivial one first.
pub(crate) fn shot_answer(
    orbit: &crate::shoot::Orbit,
    run: rotor_model::seam::Trajectory,
    t_end: f64,
) -> Result<SteadyAnswer, SteadyError> {
    let state =
        run.rig_metrics()
            .ok_or(SteadyError::Shoot(crate::shoot::ShootError::NoReturn {
                what: orbit.section.as_str(),
                horizon: t_end,
                z: orbit.z.clone(),
            }))?;
    let mut multipliers = vec![Complex::new(1.0, 0.0)];
    multipliers.extend(orbit.multipliers.iter().map(|m| Complex::new(m[0], m[1])));
    if multipliers.len() == 2 {
        multipliers.push(Complex::new(0.0, 0.0));
    }
    Ok(SteadyAnswer {
        state,
        method: SteadyMethod::Shoot,
        multipliers: Some(multipliers),
        stable: Some(orbit.is_stable()),
        stats: run.stats,
        on_cycle: Some(orbit.x),
    })
}

/// The event-driven solver's refined steady state, with the saltation multipliers of a
/// refined cycle.
fn refined(
    model: &Model,
    u: f64,
    x0: State,
    opts: &SteadyOptions,
) -> Result<SteadyAnswer, SteadyError> {
    let st = rotor_event::steady_state(
        model,
        u,
        x0,
        &opts.event,
        &rotor_event::EventOptions::default(),
    )?;
    let mut answer = SteadyAnswer {
        state: st.state,
        method: match st.method {
            rotor_event::Method::Equilibrium => SteadyMethod::Equilibrium,
            rotor_event::Method::Refined => SteadyMethod::Refined,
            rotor_event::Method::Settled => SteadyMethod::Settled,
        },
        multipliers: None,
        stable: None,
        stats: Stats::default(),
        on_cycle: st.on_cycle,
    };
    let (rotor_event::Method::Refined, Some(x)) = (st.method, st.on_cycle) else {
        return Ok(answer);
    };
    let one = Complex::new(1.0, 0.0);
    // The difference estimate, completed with the trivial multiplier (and the 0 of a stick
    // phase): the answer when the monodromy matrix is not available (no section level, i.e.
    // no slipping equilibrium with ω > 0, as for u < 0).
    let mut estimate = vec![one];
    estimate.extend(&st.multipliers);
    if estimate.len() == 2 {
        estimate.push(Complex::new(0.0, 0.0));
    }
    match saltation_multipliers(model, u, x, opts.event.tol) {
        Some((m, true)) => answer.multipliers = Some(m),
        Some((m, false)) => {
            return Err(SteadyError::Undecided {
                multipliers: list(&m),
                estimate: list(&st.multipliers),
            });
        }
        None => answer.multipliers = Some(estimate),
    }
    Ok(answer)
}

/// The Floquet multipliers of the cycle through `x` from the monodromy matrix with saltation
/// matrices, on the section `ω_l = ω*(u)` as the bifurcation diagram computes them, and
/// whether the cycle is stable. `None` when the section or the monodromy is not available.
fn saltation_multipliers(
    model: &Model,
    u: f64,
    x: State,
    tol: f64,
) -> Option<(Vec<Complex<f64>>, bool)> {
    let sh = Shooter { model, tol };
    let c = sh.section_level(u).ok()?;
    let to_section = rotor_event::flow(
        model,
        u,
        tol,
        x,
        model.mode_at(&x, u),
        T_RETURN,
        rotor_event::StopAt::Section(c),
    )
    .ok()?;
    if !to_section.reached {
        return None;
    }
    let cont = Continuer {
        sh,
        // Only describes the cycle (multipliers): no Newton solve.
        opts: ContOptions::at(u, 0.0),
    };
    let info = cont
        .describe(u, c, [to_section.x[0], to_section.x[1]])
        .ok()?;
    Some((info.multipliers, info.stable))
}

fn list(m: &[Complex<f64>]) -> String {
    m.iter()
        .map(|z| format!("{:.6}{:+.6}i", z.re, z.im))
        .collect::<Vec<_>>()
        .join(", ")
}
