//! The steady state of a chain of N discs, by any solver: an equilibrium, a cycle of any
//! number of section crossings, or, where the run shows no cycle, "aperiodic" with the
//! evidence.
//!
//! A chain's cycles are rarely the rig's one-crossing cycle: a stick-slip wave running down
//! the chain can take dozens of returns to its Poincaré section before it repeats. So the
//! steady state is read off the solver's own run, not off one return:
//!
//! 1. **The run.** The solver runs from the start over horizons `T = first, 2·first, …`
//!    up to `horizon`, each from the start (no restart inside a run, so no event is lost or
//!    doubled at a seam), keeping every event (stick onsets and exits, reversals, each disc's
//!    velocity extrema) and the state once per second.
//! 2. **Equilibrium.** Over the run's last quarter every disc's velocity stays within
//!    [`EQUILIBRIUM_AMPLITUDE`] `= δ`: the final state must then satisfy the Filippov system
//!    (slipping discs' rates, within what a state δ away has, `2 |∂f/∂x| δ`; stuck discs'
//!    torques inside their stick intervals, within `k δ`).
//! 3. **A cycle of k crossings.** The section is the maxima of the bottom disc's velocity
//!    (where a stick-slip wave arrives, once or many times a period). The cycle is the smallest `k ≤
//!    max_crossings` for which each of the last `repeats · k` crossings returns to the state
//!    of the crossing `k` before it within `ρ (1 + |x|∞)`, `ρ` the solver's
//!    [`return_tolerance`].
//!    This is the cycle's check against the model: the solver's own run of one period from a
//!    state on it returns to that state, `repeats` periods over. The metrics (period, each
//!    disc's velocity range and time stuck) are those of the last period.
//! 4. **Aperiodic.** No cycle by `horizon`. The answer is "aperiodic" only if no return
//!    comes near (the closest, over every `k`, is farther than [`APERIODIC_GAP`]) *and* a
//!    second run at a tighter setting (tol/10, or h/2) from the same start parts ways with it
//!    by a tenth of the velocities' range although the two agree early on: the orbit is
//!    sensitive to its start (chaos). Divergence alone is no evidence: on a cycle, runs at
//!    two settings part ways too, as their periods differ and the phase drifts. Otherwise
//!    (a near return, runs that still agree, or runs that differ from the start) the answer
//!    is refused: a transient longer than the run, or a cycle the setting does not resolve.
//! 5. **Settled, not just returning.** Next to a Hopf point a cycle's multiplier is near 1,
//!    and returns differ by little while the orbit is still far from the cycle; the run's
//!    own contraction per period must bound the rest of the transient (`Section::cycle`).
//! 6. **Shot.** A cycle so found is refined by Newton on the solver's own k-th return map,
//!    with its Floquet multipliers and a bound on their error (`Shooter`); where that fails,
//!    the simulated cycle stands and says why.

use serde::Serialize;

use rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE;
use rotor_model::seam::{Accuracy, Event, EventKind, Output, Scene, SolveError, Trajectory};
use rotor_model::{ChainModel, Disc, DiscMode};

use crate::solvers::SolverKind;
use crate::steady::verify::answer_accuracy;

/// Settings of [`chain_steady`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainSteadyOptions {
    /// The first run's horizon \[s\]; each next run doubles it.
    pub first: f64,
    /// The longest run \[s\] before the answer is "aperiodic" (or refused as unsettled).
    pub horizon: f64,
    /// The longest cycle, in section crossings.
    pub max_crossings: usize,
    /// How many periods in a row must return within the accuracy.
    pub repeats: usize,
    /// Whether a cycle found is refined by shooting on the solver's own k-th return map
    /// (with its multipliers).
    pub shoot: bool,
}

impl Default for ChainSteadyOptions {
    fn default() -> Self {
        ChainSteadyOptions {
            // 2000 s: a chain of eight rig-like discs at 1.5 V repeats after some 1,000 s; a
            // chain of three needs 3,500 s (4,000 s, the second run).
            first: 2000.0,
            // 16,000 s: a chain of eight at 2.5 V shows no cycle within 15,000 s.
            horizon: 16_000.0,
            // 400 crossings: three times the longest cycle seen on these chains (129
            // crossings, a chain of eight at 4.5 V).
            max_crossings: 400,
            // Two periods in a row: a coincidental near-return of one crossing is not a cycle.
            repeats: 2,
            shoot: true,
        }
    }
}

/// What a chain settles on.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ChainSteady {
    /// A rest point.
    Equilibrium {
        /// The springs' twists α_i \[rad\] (N − 1).
        alpha: Vec<f64>,
        /// The discs' velocities \[rad/s\] (N; a stuck disc's 0).
        omega: Vec<f64>,
        /// The largest residual of the Filippov system at the state, as a fraction of its
        /// allowance (≤ 1).
        residual: f64,
    },
    /// A periodic orbit of `crossings` returns to its section.
    LimitCycle {
        /// Period \[s\].
        period: f64,
        /// Largest ω_i over the period \[rad/s\].
        omega_max: Vec<f64>,
        /// Smallest ω_i over the period \[rad/s\].
        omega_min: Vec<f64>,
        /// Time disc i spends stuck per period \[s\].
        stick_time: Vec<f64>,
        /// Section crossings per period.
        crossings: usize,
        /// The section (`"maximum of omega_N"`).
        section: String,
        /// The largest `|x_j − x_{j−k}|∞ / (1 + |x_j|∞)` over the periods checked.
        return_distance: f64,
        /// The accuracy it is held to (ρ).
        return_tolerance: f64,
        /// The start of the periods checked \[s\]: the run is on the cycle from there.
        settled_by: f64,
        /// Floquet multipliers `[re, im]` of the cycle, by decreasing modulus: the eigenvalues
        /// of the k-th return map's Jacobian in the section's coordinates (shooting); `None`
        /// when the cycle was not shot.
        multipliers: Option<Vec<[f64; 2]>>,
        /// A bound on the multipliers' error: the one-sided difference Jacobians' largest
        /// entry difference times the dimension (shooting); absent otherwise.
        #[serde(skip_serializing_if = "Option::is_none")]
        multiplier_error: Option<f64>,
        /// Whether every multiplier lies inside the unit circle (shooting); absent otherwise.
        #[serde(skip_serializing_if = "Option::is_none")]
        stable: Option<bool>,
    },
    /// No cycle within the horizon: the run never comes back near a state it passed, and
    /// runs at neighbouring settings part ways. A chaotic attractor, or a chaotic transient
    /// longer than the horizon (which the answer states).
    Aperiodic {
        /// The run's length \[s\].
        horizon: f64,
        /// Section crossings in the run's second half.
        crossings: usize,
        /// The section.
        section: String,
        /// The closest return found: the number of crossings and the distance (relative,
        /// as for a cycle) over the last ones.
        closest_return: ClosestReturn,
        /// How the runs at the solver's setting and at a tighter one parted.
        divergence: Divergence,
    },
}

/// The best candidate period of an orbit that has none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClosestReturn {
    /// Section crossings.
    pub crossings: usize,
    /// The largest relative return distance over the crossings checked.
    pub distance: f64,
    /// The accuracy a cycle would have to return within.
    pub tolerance: f64,
}

/// Two runs from one start, at the solver's setting and a tighter one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Divergence {
    /// The tighter run's setting (`"tol 1e-11"`, `"h 5e-4"`).
    pub tighter: String,
    /// Their largest velocity difference over the first 100 s \[rad/s\].
    pub early: f64,
    /// Their largest velocity difference over the run's last quarter \[rad/s\].
    pub late: f64,
    /// The first time they differ by a tenth of the velocities' range \[s\].
    pub parted_at: f64,
}

/// A chain's steady state as `rotor steady` prints it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainSteadyAnswer {
    /// What the chain settles on.
    #[serde(flatten)]
    pub state: ChainSteady,
    /// How: `"simulated"` (read off the solver's run), or `"shoot"` (a cycle so found, then
    /// refined by Newton on the solver's own k-th return map, with its multipliers).
    pub method: &'static str,
    /// Why a cycle found by simulation was not refined by shooting (the simulated answer
    /// stands); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_shot: Option<String>,
}

/// Why a chain's steady state is not given.
#[derive(Debug, thiserror::Error)]
pub enum ChainSteadyError {
    /// A run failed, or the scene is inadmissible.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A time-varying input has no steady state.
    #[error("input: the steady state of a time-varying input is not defined (give a constant --u)")]
    TimeVarying,
    /// No cycle and no equilibrium by the horizon, but a near return (within
    /// [`APERIODIC_GAP`]), a tighter run that agrees, or one that differs from the start: a
    /// transient longer than the horizon, or a cycle the setting does not resolve.
    #[error(
        "no steady state confirmed within {horizon} s: no cycle of up to {max_crossings} \
         section crossings returns within {tolerance:.1e} (the closest, {closest} crossings, \
         returns within {distance:.2e}; a run at {tighter} differs from it by {early:.2e} rad/s \
         over the first 100 s and {late:.2e} over the last quarter): a transient longer than \
         the run or a cycle not resolved at this setting, not an aperiodic orbit (which \
         returns nowhere within 1e-2, its runs at two settings close at first and parting \
         later)"
    )]
    Unsettled {
        /// The run's length \[s\].
        horizon: f64,
        /// The longest cycle looked for.
        max_crossings: usize,
        /// The accuracy a cycle must return within.
        tolerance: f64,
        /// The closest return's crossings.
        closest: usize,
        /// Its distance.
        distance: f64,
        /// The tighter run's setting.
        tighter: String,
        /// The runs' difference over the first 100 s \[rad/s\].
        early: f64,
        /// The runs' difference over the last quarter \[rad/s\].
        late: f64,
    },
    /// An option is out of its range.
    #[error("{0}")]
    Options(String),
    /// An equilibrium read off a run fails the Filippov system.
    #[error("the equilibrium found is refuted by the model's own equations: {detail}")]
    Refuted {
        /// The condition that failed, with its residual and the allowance.
        detail: String,
    },
}

/// The steady state `kind` reaches on `model` from `scene.x0` at the constant `scene.u`, at the
/// scene's setting (its `t_end`, `output` and `metrics_from` are not used): see the module
/// docs.
pub fn chain_steady(
    kind: SolverKind,
    model: &ChainModel,
    scene: &Scene,
    opts: &ChainSteadyOptions,
) -> Result<ChainSteadyAnswer, ChainSteadyError> {
    if scene.is_time_varying() {
        return Err(ChainSteadyError::TimeVarying);
    }
    if !(opts.first > 0.0 && opts.first <= opts.horizon && opts.horizon.is_finite()) {
        return Err(ChainSteadyError::Options(format!(
            "first = {}, horizon = {}: expected 0 < first <= horizon, finite",
            opts.first, opts.horizon
        )));
    }
    if opts.repeats == 0 || opts.max_crossings == 0 {
        return Err(ChainSteadyError::Options(format!(
            "repeats = {}, max_crossings = {}: each must be at least 1",
            opts.repeats, opts.max_crossings
        )));
    }
    let rho = return_tolerance(kind, scene);
    let mut t_end = opts.first.min(opts.horizon);
    loop {
        let run = run_for(kind, model, scene, scene.accuracy, t_end)?;
        if let Some(eq) = at_rest(&run, model, scene.u, kind.info().stuck_band)? {
            return Ok(ChainSteadyAnswer {
                state: eq,
                method: "simulated",
                not_shot: None,
            });
        }
        let section = Section::of(&run, model.discs());
        let closest = match section.cycle(opts, rho, return_floor(kind, scene)) {
            Ok(cycle) => {
                let simulated = cycle.metrics(&run, &section, model, rho);
                if !opts.shoot {
                    return Ok(ChainSteadyAnswer {
                        state: simulated,
                        method: "simulated",
                        not_shot: None,
                    });
                }
                let shooter = Shooter::new(kind, model, scene, (&run, &section), &cycle, rho);
                return Ok(match shooter.and_then(|s| s.shoot()) {
                    Ok(state) => ChainSteadyAnswer {
                        state,
                        method: "shoot",
                        not_shot: None,
                    },
                    Err(why) => ChainSteadyAnswer {
                        state: simulated,
                        method: "simulated",
                        not_shot: Some(why),
                    },
                });
            }
            Err(closest) => closest,
        };
        if t_end >= opts.horizon {
            let tighter = tighter(kind, scene);
            let other = run_for(kind, model, scene, tighter, t_end)?;
            let divergence = diverge(&run, &other, model, kind, tighter);
            let range = velocity_range(&run, model);
            // On a cycle, two runs at different settings part ways too: their periods differ,
            // and the phase drifts. So the orbit is aperiodic only if no return comes near
            // (the closest farther than APERIODIC_GAP), and the runs part ways as well.
            // They must also have followed one orbit at first (within 1 % of the velocities'
            // range over the first 100 s): runs that differ from the start say the setting is
            // too coarse, not that the orbit is sensitive.
            if closest.distance <= APERIODIC_GAP
                || divergence.late < 0.1 * range
                || divergence.early > 0.01 * range
            {
                return Err(ChainSteadyError::Unsettled {
                    horizon: t_end,
                    max_crossings: opts.max_crossings,
                    tolerance: rho,
                    closest: closest.crossings,
                    distance: closest.distance,
                    tighter: divergence.tighter,
                    early: divergence.early,
                    late: divergence.late,
                });
            }
            return Ok(ChainSteadyAnswer {
                state: ChainSteady::Aperiodic {
                    horizon: t_end,
                    crossings: section.crossings.len(),
                    section: section.name,
                    closest_return: closest,
                    divergence,
                },
                method: "simulated",
                not_shot: None,
            });
        }
        t_end = (2.0 * t_end).min(opts.horizon);
    }
}

/// The run of `kind` over `[0, t_end]` at `accuracy`, keeping every event (extrema
/// included) and the state once per second.
fn run_for(
    kind: SolverKind,
    model: &ChainModel,
    scene: &Scene,
    accuracy: Accuracy,
    t_end: f64,
) -> Result<Trajectory, SolveError> {
    let run = Scene {
        t_end,
        accuracy,
        output: Output::Grid { dt: 1.0 },
        metrics_from: Some(0.0),
        ..scene.clone()
    };
    kind.simulate_chain(model, &run)
}

/// The relative distance within which a chain's crossing must return to count as a cycle:
/// the accuracy every steady answer of the solver is held to ([`answer_accuracy`]), and for
/// Moreau–Jean at least `0.1·h`. Its located events fall between steps differently from one
/// return to the next, more so on a chain than on the rig: measured returns within 1.1e-5 on
/// the chain of eight rig-like discs and 4.2e-5 on the chain of three at 1.5 V and
/// h = 1e-3, against 2.5e-7 on the rig. 0.1·h is 2.4 times the larger.
pub fn return_tolerance(kind: SolverKind, scene: &Scene) -> f64 {
    let rho = answer_accuracy(kind, scene);
    if kind.is_fixed_step() {
        rho.max(0.1 * scene.step())
    } else {
        rho
    }
}

/// The return distance at which a solver's returns are noise: 1e3·tol for the adaptive
/// solvers (their reproducibility over a period, measured 5e-9 on the chain of three at tol
/// 1e-10), and for Moreau–Jean its whole return tolerance (its located stick exits jitter
/// from one return to the next by up to 4e-5 at h = 1e-3, the size of that tolerance).
fn return_floor(kind: SolverKind, scene: &Scene) -> f64 {
    if kind.is_fixed_step() {
        return_tolerance(kind, scene)
    } else {
        1e3 * scene.tol()
    }
}

/// The closest return (relative) above which an orbit without a cycle is called aperiodic:
/// 1e-2, a thousand times the adaptive solvers' return tolerance and a hundred times
/// Moreau–Jean's at h = 1e-3. Between the tolerance and this gap the orbit nearly repeats;
/// it may be a cycle converging too slowly for the horizon, or one at the solver's
/// resolution, and the answer is refused rather than called either.
pub const APERIODIC_GAP: f64 = 1e-2;

/// The setting next to the scene's, tighter: tol/10 (at least the smallest admissible), or
/// h/2.
fn tighter(kind: SolverKind, scene: &Scene) -> Accuracy {
    if kind.is_fixed_step() {
        Accuracy::Step(scene.step() / 2.0)
    } else {
        // Rounded to three digits, so that it prints as it reads (1e-11, not 1.0000000000000001e-11).
        let tol = format!("{:.2e}", scene.tol() / 10.0)
            .parse::<f64>()
            .unwrap_or(scene.tol() / 10.0);
        Accuracy::Tol(tol.max(rotor_model::seam::scene::MIN_TOL))
    }
}

/// The range of state component `k` over the run's samples and events from `from` on.
fn range_from(run: &Trajectory, k: usize, from: f64) -> f64 {
    let (lo, hi) = run
        .samples
        .iter()
        .filter(|r| r.t >= from)
        .map(|r| r.x[k])
        .chain(run.events.iter().filter(|e| e.t >= from).map(|e| e.x[k]))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), w| {
            (lo.min(w), hi.max(w))
        });
    hi - lo
}

/// The largest velocity range of any disc over the run's second half \[rad/s\].
fn velocity_range(run: &Trajectory, model: &ChainModel) -> f64 {
    let half = 0.5 * run.t_final;
    (0..model.discs())
        .map(|i| range_from(run, model.omega(i), half))
        .fold(0.0, f64::max)
}

/// How two runs on one grid part ways.
fn diverge(
    a: &Trajectory,
    b: &Trajectory,
    model: &ChainModel,
    kind: SolverKind,
    tighter: Accuracy,
) -> Divergence {
    let n = model.discs();
    let range = velocity_range(a, model);
    let (mut early, mut late, mut parted_at) = (0.0f64, 0.0f64, f64::INFINITY);
    let late_from = 0.75 * a.t_final;
    for (r, s) in a.samples.iter().zip(b.samples.iter()) {
        let d = (0..n)
            .map(|i| (r.x[model.omega(i)] - s.x[model.omega(i)]).abs())
            .fold(0.0, f64::max);
        if r.t <= 100.0 {
            early = early.max(d);
        }
        if r.t >= late_from {
            late = late.max(d);
        }
        if d >= 0.1 * range && parted_at.is_infinite() {
            parted_at = r.t;
        }
    }
    Divergence {
        tighter: kind.setting_label(tighter.value()),
        early,
        late,
        parted_at,
    }
}

/// The run's final state as an equilibrium, if every disc's velocity stays within δ over its
/// last quarter: checked against the Filippov system (module docs), refused if it fails.
fn at_rest(
    run: &Trajectory,
    model: &ChainModel,
    u: f64,
    band: f64,
) -> Result<Option<ChainSteady>, ChainSteadyError> {
    let n = model.discs();
    let from = 0.75 * run.t_final;
    let still = (0..n).all(|i| range_from(run, model.omega(i), from) <= EQUILIBRIUM_AMPLITUDE);
    if !still {
        return Ok(None);
    }
    let mut x = run.x_final.clone();
    // A disc within the solver's stuck band on a set-valued law is stuck: at rest, exactly.
    for i in 0..n {
        let k = model.omega(i);
        if model.friction(i).is_set_valued() && x[k].abs() <= band {
            x[k] = 0.0;
        }
    }
    let residual = equilibrium_residual(model, &x, u, band)?;
    Ok(Some(ChainSteady::Equilibrium {
        alpha: x[..n - 1].to_vec(),
        omega: x[n - 1..].to_vec(),
        residual,
    }))
}

/// The Filippov system at `x`, against its allowance for a state known within δ: the largest
/// residual over its allowance (≤ 1), or the refusal naming the condition that fails.
fn equilibrium_residual(
    model: &ChainModel,
    x: &[f64],
    u: f64,
    band: f64,
) -> Result<f64, ChainSteadyError> {
    let n = model.discs();
    let delta = EQUILIBRIUM_AMPLITUDE;
    let mode = model.mode_at(x, u);
    let mut f = vec![0.0; model.dim()];
    model.rhs_into(x, u, mode, &mut f);
    let mut allow = vec![0.0; model.dim()];
    model.jacobian_abs_times(x, mode, &vec![delta; model.dim()], &mut allow);
    let mut worst = 0.0f64;
    for (c, (fc, a)) in f.iter().zip(&allow).enumerate() {
        // Twice the first-order bound, plus the solvers' stuck bands in α̇.
        let allowance = 2.0 * a + 2.0 * band + f64::EPSILON * (1.0 + x[c].abs());
        let r = fc.abs() / allowance;
        if r > 1.0 {
            let what = if c < n - 1 {
                format!("alpha_{} rate", c + 1)
            } else {
                format!("omega_{} rate", c - (n - 1) + 1)
            };
            return Err(ChainSteadyError::Refuted {
                detail: format!("{what} = {fc:.3e}, beyond {allowance:.3e}"),
            });
        }
        worst = worst.max(r);
    }
    for i in 0..n {
        if mode.of(Disc::at(i)) != DiscMode::Stick {
            continue;
        }
        let (lo, hi) = model.friction(i).static_interval();
        let ta = model.applied_torque(i, x, u);
        // The torque moves by the attached springs' and couplings' stiffness times δ.
        let attached = |j: usize| model.spring(j) + model.coupling(j);
        let stiffness =
            if i > 0 { attached(i - 1) } else { 0.0 } + if i + 1 < n { attached(i) } else { 0.0 };
        let slack = 2.0 * stiffness * delta;
        let over = (lo - ta).max(ta - hi);
        if over > slack {
            return Err(ChainSteadyError::Refuted {
                detail: format!(
                    "disc {} is stuck with applied torque {ta:.6e} outside [{lo:.6e}, {hi:.6e}] \
                     by {over:.3e}, beyond {slack:.3e}",
                    i + 1
                ),
            });
        }
    }
    Ok(worst)
}

/// A run's returns to its section.
struct Section {
    name: String,
    /// The event that is a crossing.
    kind: EventKind,
    /// Each crossing's time and state, in the run's second half.
    crossings: Vec<(f64, Vec<f64>)>,
}

impl Section {
    /// The maxima of the bottom disc's velocity in the run's second half (of the lowest disc
    /// that has any, should the bottom one rest).
    fn of(run: &Trajectory, n: usize) -> Section {
        let half = 0.5 * run.t_final;
        let pick = |kind: EventKind| -> Vec<(f64, Vec<f64>)> {
            run.events
                .iter()
                .filter(|e| e.t >= half && e.kind == kind)
                .map(|e| (e.t, e.x.clone()))
                .collect()
        };
        let mut lowest = n;
        loop {
            let kind = EventKind::Max(Disc::at(lowest - 1));
            let crossings = pick(kind);
            if !crossings.is_empty() || lowest == 1 {
                return Section {
                    name: format!("maximum of omega_{lowest}"),
                    kind,
                    crossings,
                };
            }
            lowest -= 1;
        }
    }

    /// The smallest number of crossings `k` after which each of the last `repeats · k`
    /// crossings returns within `rho`; else the closest return.
    ///
    /// A return within `rho` is not yet the cycle when the orbit approaches it slowly: with a
    /// multiplier μ near 1 (next to a Hopf point) successive returns differ by (1 − μ) times
    /// the distance still to go. So the run's own contraction per period, `r = d_last /
    /// d_prev` (the largest return distance over the last period and over the one before), must
    /// also bound the rest of the transient, `d_last · r / (1 − r)`, within `rho` — unless the
    /// returns already lie at the solver's reproducibility `floor`, where their ratio is noise.
    /// A cycle that fails this is not settled yet: the search stops, and a longer run decides.
    fn cycle(
        &self,
        opts: &ChainSteadyOptions,
        rho: f64,
        floor: f64,
    ) -> Result<Cycle, ClosestReturn> {
        let m = self.crossings.len();
        let mut closest = ClosestReturn {
            crossings: 0,
            distance: f64::INFINITY,
            tolerance: rho,
        };
        for k in 1..=opts.max_crossings {
            let checked = opts.repeats * k;
            if checked + k > m {
                break;
            }
            let ret = |j: usize| {
                let (a, b) = (&self.crossings[j].1, &self.crossings[j - k].1);
                let scale = 1.0 + a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                let dist = a
                    .iter()
                    .zip(b)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max);
                dist / scale
            };
            let mut d = 0.0f64;
            for j in m - checked..m {
                d = d.max(ret(j));
                if d > rho && d > closest.distance {
                    break;
                }
            }
            if d <= rho {
                let d_prev = (m - checked..m - k).map(ret).fold(0.0, f64::max);
                let d_last = (m - k..m).map(ret).fold(0.0, f64::max);
                let r = d_last / d_prev;
                let settled = d_last <= floor || (r < 1.0 && d_last / (1.0 - r) <= rho);
                if !settled {
                    return Err(ClosestReturn {
                        crossings: k,
                        distance: d,
                        tolerance: rho,
                    });
                }
                return Ok(Cycle {
                    k,
                    distance: d,
                    start: self.crossings[m - 1 - checked].0,
                });
            }
            if d < closest.distance {
                closest = ClosestReturn {
                    crossings: k,
                    distance: d,
                    tolerance: rho,
                };
            }
        }
        Err(closest)
    }
}

/// A cycle found on a section.
struct Cycle {
    k: usize,
    distance: f64,
    start: f64,
}

impl Cycle {
    /// The metrics of the run's last period: from the crossing `k` before the last to the
    /// last.
    fn metrics(&self, run: &Trajectory, s: &Section, model: &ChainModel, rho: f64) -> ChainSteady {
        let m = s.crossings.len();
        let (a, b) = (&s.crossings[m - 1 - self.k], &s.crossings[m - 1]);
        let (max, min, stick) = period_metrics(run, (a.0, &a.1), (b.0, &b.1), model);
        ChainSteady::LimitCycle {
            period: b.0 - a.0,
            omega_max: max,
            omega_min: min,
            stick_time: stick,
            crossings: self.k,
            section: s.name.clone(),
            return_distance: self.distance,
            return_tolerance: rho,
            settled_by: self.start,
            multipliers: None,
            multiplier_error: None,
            stable: None,
        }
    }
}

/// Each disc's largest and smallest velocity and time stuck over `[ta, tb]` of `run`, whose
/// states at the ends are `xa` and `xb`: the extremes over the end states and the events and
/// samples between, the stick phases clipped to the interval (a disc stuck at `ta` was
/// stuck since its last onset before it).
#[allow(clippy::type_complexity)]
fn period_metrics(
    run: &Trajectory,
    (ta, xa): (f64, &[f64]),
    (tb, xb): (f64, &[f64]),
    model: &ChainModel,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = model.discs();
    let mut max = vec![f64::NEG_INFINITY; n];
    let mut min = vec![f64::INFINITY; n];
    let mut take = |x: &[f64]| {
        for i in 0..n {
            let w = x[model.omega(i)];
            max[i] = max[i].max(w);
            min[i] = min[i].min(w);
        }
    };
    take(xa);
    take(xb);
    let within = |e: &&Event| e.t >= ta && e.t <= tb;
    run.events.iter().filter(within).for_each(|e| take(&e.x));
    run.samples
        .iter()
        .filter(|r| r.t >= ta && r.t <= tb)
        .for_each(|r| take(r.x));
    let mut since: Vec<Option<f64>> = vec![None; n];
    let mut stick = vec![0.0; n];
    for e in run.events.iter().filter(|e| e.t <= tb) {
        match e.kind {
            EventKind::StickStart(d) => since[d.position()] = Some(e.t),
            EventKind::StickEnd(d) => {
                if let Some(t0) = since[d.position()].take()
                    && e.t > ta
                {
                    stick[d.position()] += e.t - t0.max(ta);
                }
            }
            _ => {}
        }
    }
    for (i, t0) in since.iter().enumerate() {
        if let Some(t0) = t0 {
            stick[i] += tb - t0.max(ta);
        }
    }
    (max, min, stick)
}

/// Newton on the solver's own k-th return map to the section, from a cycle found by
/// simulation.
///
/// The map `P^k` runs the solver from a state on a section until its k-th crossing. The
/// section shot on is the bottom disc's stick exit where it sticks within the period (k its
/// exits per period), else the run's own section of maxima. For the stick exit the
/// section's coordinates `z` are the state without the bottom
/// disc's velocity (0 there) and twist (its spring then holds the applied torque at the
/// limit the disc leaves at), so the map is smooth in them; for its maxima they are the whole
/// state. Newton solves `P^k(z) = z` with the Jacobian by forward differences of step
/// `√ν (1 + |z_j|)`, ν the map's reproducibility (1e3·tol for the adaptive solvers, ρ/10 for
/// Moreau–Jean), until the return is within `max(ν, ρ/100)·(1 + |z|∞)`. The multipliers are
/// the eigenvalues of `∂P^k/∂z` at the fixed point; the cycle is stable when every one lies
/// inside the unit circle. The metrics are those of the period the last map run covers.
struct Shooter<'a> {
    kind: SolverKind,
    model: &'a ChainModel,
    scene: &'a Scene,
    /// The section shot on, and its returns per period.
    anchor: EventKind,
    k: usize,
    /// The run's section crossings per period (what the answer reports).
    crossings: usize,
    period: f64,
    rho: f64,
    nu: f64,
    /// The bottom disc's applied torque at the exit (the stick-exit section), else `None`.
    exit_torque: Option<f64>,
    /// The state the shooting starts from (the run's last crossing of the section shot on).
    x0: Vec<f64>,
    section: String,
    /// When the simulation was on the cycle \[s\].
    settled_by: f64,
}

impl<'a> Shooter<'a> {
    /// The shooting of the cycle the run found: on the bottom disc's stick exits if it sticks
    /// within the period (from the last exit, with as many returns as the period holds exits),
    /// else on the run's own section.
    fn new(
        kind: SolverKind,
        model: &'a ChainModel,
        scene: &'a Scene,
        (run, section): (&Trajectory, &Section),
        cycle: &Cycle,
        rho: f64,
    ) -> Result<Shooter<'a>, String> {
        let m = section.crossings.len();
        let (ta, tb) = (
            section.crossings[m - 1 - cycle.k].0,
            section.crossings[m - 1].0,
        );
        let period = tb - ta;
        let n = model.discs();
        let exit = EventKind::StickEnd(Disc::at(n - 1));
        let exits: Vec<&Event> = run
            .events
            .iter()
            .filter(|e| e.kind == exit && e.t > ta && e.t <= tb)
            .collect();
        let (anchor, k, x0) = match exits.last() {
            Some(last) => (exit, exits.len(), last.x.clone()),
            None => (section.kind, cycle.k, section.crossings[m - 1].1.clone()),
        };
        let exit_torque = match anchor {
            EventKind::StickEnd(_) => {
                if model.spring(n - 2) <= 0.0 {
                    return Err("the bottom spring is 0: no section coordinates".to_owned());
                }
                let (lo, hi) = model.friction(n - 1).static_interval();
                let ta = model.applied_torque(n - 1, &x0, scene.u);
                // The limit it left at, biased by a few roundings outward so that a run from
                // the section leaves stick at once.
                let bound = if (ta - hi).abs() <= (ta - lo).abs() {
                    hi
                } else {
                    lo
                };
                Some(bound + 4.0 * f64::EPSILON * bound.abs().max(1.0) * bound.signum())
            }
            _ => None,
        };
        let nu = if kind.is_fixed_step() {
            0.1 * rho
        } else {
            1e3 * scene.tol()
        };
        Ok(Shooter {
            kind,
            model,
            scene,
            anchor,
            k,
            crossings: cycle.k,
            period,
            rho,
            nu,
            exit_torque,
            x0,
            section: section.name.clone(),
            settled_by: cycle.start,
        })
    }

    /// The state components that are the section's coordinates.
    fn free(&self) -> Vec<usize> {
        let n = self.model.discs();
        (0..self.model.dim())
            .filter(|&c| self.exit_torque.is_none() || (c != n - 2 && c != 2 * n - 2))
            .collect()
    }

    /// The state on the section with coordinates `z`.
    fn lift(&self, z: &[f64], free: &[usize]) -> Vec<f64> {
        let n = self.model.discs();
        let mut x = self.x0.clone();
        for (&c, v) in free.iter().zip(z) {
            x[c] = *v;
        }
        if let Some(t) = self.exit_torque {
            x[2 * n - 2] = 0.0;
            // T = k α + c (ω_{N−1} − ω_N), ω_N = 0.
            let c = self.model.coupling(n - 2) * x[2 * n - 3];
            x[n - 2] = (t - c) / self.model.spring(n - 2);
        }
        x
    }

    /// `P^k(x)`: the run from `x` to its k-th crossing, the state there and the run (kept
    /// with extrema when `metrics`).
    fn map(&self, x: &[f64], metrics: bool) -> Result<(Vec<f64>, f64, Trajectory), String> {
        let mut t_end = 1.5 * self.period;
        for _ in 0..3 {
            let scene = Scene {
                x0: x.to_vec(),
                t_end,
                output: if metrics {
                    Output::Grid { dt: 1.0 }
                } else {
                    Output::Events
                },
                // Extrema are located only for the metrics: a section of maxima needs them.
                metrics_from: (metrics || matches!(self.anchor, EventKind::Max(_))).then_some(0.0),
                ..self.scene.clone()
            };
            let run = self
                .kind
                .simulate_chain(self.model, &scene)
                .map_err(|e| format!("a run of the return map failed: {e}"))?;
            // A crossing at the very start is the start itself, not a return.
            let skip = 1e-6 * self.period;
            if let Some(e) = run
                .events
                .iter()
                .filter(|e| e.kind == self.anchor && e.t > skip)
                .nth(self.k - 1)
            {
                let (x, t) = (e.x.clone(), e.t);
                return Ok((x, t, run));
            }
            t_end *= 2.0;
        }
        Err(format!(
            "a run from the section does not return {} times within {:.0} s",
            self.k, t_end
        ))
    }

    /// `∂P^k/∂z` at `z` (where `P^k` lands at `p`) by one-sided differences, forward
    /// (`sign` 1) or backward (−1), of step `scale · √ν (1 + |z_j|)`.
    fn jacobian(
        &self,
        z: &[f64],
        p: &[f64],
        free: &[usize],
        sign: f64,
        scale: f64,
    ) -> Result<nalgebra::DMatrix<f64>, String> {
        let dim = free.len();
        let mut jac = nalgebra::DMatrix::<f64>::zeros(dim, dim);
        for j in 0..dim {
            let eps = sign * scale * self.nu.sqrt() * (1.0 + z[j].abs());
            let mut zj = z.to_vec();
            zj[j] += eps;
            let (pj, _, _) = self.map(&self.lift(&zj, free), false)?;
            for i in 0..dim {
                jac[(i, j)] = (pj[free[i]] - p[free[i]]) / eps;
            }
        }
        Ok(jac)
    }

    fn shoot(self) -> Result<ChainSteady, String> {
        let free = self.free();
        let pick = |x: &[f64]| -> Vec<f64> { free.iter().map(|&c| x[c]).collect() };
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut z = pick(&self.x0);
        let target = self.nu.max(0.01 * self.rho);
        let dim = free.len();
        for _ in 0..12 {
            let (p, _, _) = self.map(&self.lift(&z, &free), false)?;
            let f: Vec<f64> = pick(&p).iter().zip(&z).map(|(a, b)| a - b).collect();
            if norm(&f) <= target * (1.0 + norm(&z)) {
                return self.finish(&z, &p, &free);
            }
            let jac = self.jacobian(&z, &p, &free, 1.0, 1.0)?;
            let a = &jac - nalgebra::DMatrix::<f64>::identity(dim, dim);
            let rhs = nalgebra::DVector::from_iterator(dim, f.iter().map(|v| -v));
            let step = a
                .lu()
                .solve(&rhs)
                .ok_or("the return map's Jacobian has a multiplier at 1")?;
            for (zi, d) in z.iter_mut().zip(step.iter()) {
                *zi += d;
            }
        }
        Err(format!(
            "Newton on the {}-th return map did not converge in 12 steps",
            self.k
        ))
    }

    /// The multipliers at the fixed point `z` (where `P^k` lands at `p`), with a bound on
    /// their error: the eigenvalues of the central-difference Jacobian at the one of the steps
    /// `√ν`, `√ν/10`, `√ν/100` at which they are known best. The forward and backward
    /// Jacobians differ by the map's curvature and noise over the step, and by a jump where a
    /// step crosses into another sequence of events (a disc that sticks instead of
    /// reversing): their largest entry difference, times the dimension, bounds how far a
    /// multiplier may move (Bauer–Fike, up to the eigenvectors' conditioning). The
    /// multipliers count as resolved when that bound is below 0.1 and below the largest
    /// one's distance to the unit circle, which decides the cycle's stability; the bound is
    /// reported with them.
    fn multipliers(
        &self,
        z: &[f64],
        p: &[f64],
        free: &[usize],
    ) -> Result<(Vec<[f64; 2]>, f64), String> {
        let mut best: Option<(Vec<[f64; 2]>, f64)> = None;
        for scale in [1.0, 0.1, 0.01] {
            let forward = self.jacobian(z, p, free, 1.0, scale)?;
            let backward = self.jacobian(z, p, free, -1.0, scale)?;
            let jac = (&forward + &backward) * 0.5;
            let bound = (&forward - &backward).abs().max() * jac.nrows() as f64;
            if best.as_ref().is_some_and(|b| b.1 <= bound) {
                continue;
            }
            let mut mu: Vec<[f64; 2]> = jac
                .complex_eigenvalues()
                .iter()
                .map(|c| [c.re, c.im])
                .collect();
            mu.sort_by(|a, b| b[0].hypot(b[1]).total_cmp(&a[0].hypot(a[1])));
            best = Some((mu, bound));
        }
        let (mu, bound) = best.expect("three steps tried");
        let largest = mu.first().map_or(0.0, |m| m[0].hypot(m[1]));
        if bound < 0.1 && bound < (largest - 1.0).abs() {
            return Ok((mu, bound));
        }
        Err(format!(
            "the multipliers are not resolved: at the best difference step the one-sided \
             Jacobians differ by up to {bound:.1e} (times the dimension), the largest \
             multiplier being {largest:.3}"
        ))
    }

    /// The shot cycle: its metrics over the period from the fixed point, its return distance
    /// (checked against ρ) and its multipliers (stable, as the run that found it converged
    /// to it: a multiplier outside the unit circle contradicts the run and is refused).
    fn finish(&self, z: &[f64], p: &[f64], free: &[usize]) -> Result<ChainSteady, String> {
        let (mu, mu_error) = self.multipliers(z, p, free)?;
        let largest = mu.first().map_or(0.0, |m| m[0].hypot(m[1]));
        if largest >= 1.0 {
            return Err(format!(
                "shooting puts a multiplier at {largest:.3}, outside the unit circle, on the \
                 cycle the run converged to: the return map's differences are not to be \
                 trusted here"
            ));
        }
        let x = self.lift(z, free);
        let (p, period, run) = self.map(&x, true)?;
        let scale = 1.0 + x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let distance = x
            .iter()
            .zip(&p)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
        if distance > self.rho {
            return Err(format!(
                "the shot cycle returns within {distance:.2e}, beyond {:.1e}",
                self.rho
            ));
        }
        let (max, min, stick) = period_metrics(&run, (0.0, &x), (period, &p), self.model);
        Ok(ChainSteady::LimitCycle {
            period,
            omega_max: max,
            omega_min: min,
            stick_time: stick,
            crossings: self.crossings,
            section: self.section.clone(),
            return_distance: distance,
            return_tolerance: self.rho,
            settled_by: self.settled_by,
            multipliers: Some(mu),
            multiplier_error: Some(mu_error),
            stable: Some(true),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::{ChainParams, Params};

    fn chain3() -> ChainModel {
        ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 3))
    }

    /// The check refuses states that are not equilibria, naming the condition: a twist
    /// 1e-3 rad off the 6 V equilibrium (a spring rate no δ explains), and the 0.02 V rest
    /// with the first spring wound past the second disc's static friction. The equilibria
    /// themselves (read off a run at tol 1e-10) pass.
    #[test]
    fn the_equilibrium_check_refuses_what_is_not_one() {
        let model = chain3();
        let slipping = [
            3.6551602493454567,
            1.8275801246727403,
            10.655041061658956,
            10.655041061658912,
            10.655041061658931,
        ];
        assert!(equilibrium_residual(&model, &slipping, 6.0, 0.0).unwrap() <= 1.0);
        let mut off = slipping;
        off[0] += 1e-3;
        let e = equilibrium_residual(&model, &off, 6.0, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("omega_1 rate"), "{e}");
        let stuck = [1.0990371389270943, 0.0, 0.0, 0.0, 0.0];
        assert!(equilibrium_residual(&model, &stuck, 0.02, 0.0).unwrap() <= 1.0);
        // k α = 0.0727 · 3 = 0.22 N m on disc 2, beyond its static 0.1642 N m: it cannot
        // stick (the Filippov mode slips it, and its rate is then far from 0).
        let mut wound = stuck;
        wound[0] = 3.0;
        let e = equilibrium_residual(&model, &wound, 0.02, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rate"), "{e}");
    }
    /// Options out of range are refused by name, before any run.
    #[test]
    fn options_out_of_range_are_refused() {
        let model = chain3();
        let scene = Scene {
            x0: vec![0.0; 5],
            ..Scene::default()
        };
        for (opts, needle) in [
            (
                ChainSteadyOptions {
                    repeats: 0,
                    ..ChainSteadyOptions::default()
                },
                "repeats = 0",
            ),
            (
                ChainSteadyOptions {
                    first: 5e4,
                    ..ChainSteadyOptions::default()
                },
                "first = 50000",
            ),
            (
                ChainSteadyOptions {
                    horizon: f64::NAN,
                    ..ChainSteadyOptions::default()
                },
                "horizon = NaN",
            ),
        ] {
            let e = chain_steady(SolverKind::EVENT, &model, &scene, &opts)
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{e}");
        }
    }
}
