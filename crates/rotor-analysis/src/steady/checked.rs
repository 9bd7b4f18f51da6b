//! The steady state by shooting, checked by simulation: the near-special probes' method for
//! the solvers without a return-map refinement of their own (the switch model, Moreau–Jean).
//!
//! Shooting ([`crate::shoot`]) finds a periodic orbit near a start in a few periods, stable or
//! not, but Newton's basin is not the orbit's basin of attraction: a start next to a fold of
//! cycles, or in a bistable band, may go to another attractor than the orbit Newton finds. So
//! the answer is accepted only when a bounded simulation from the start itself is seen to go
//! to it:
//!
//! 1. a run of [`CheckOptions::first_run`] seconds from the start. If it crosses neither
//!    section (no stick exit, no maximum of ω_l) in its second half, it is at or approaching
//!    an equilibrium: one it has come to rest at is the answer as in step 3, and otherwise
//!    the simulation method ([`crate::steady::settle`]) continues it until it settles;
//! 2. otherwise Newton on the solver's own return map from the run's last section crossing.
//!    An orbit is taken as stable only with every multiplier inside the circle of radius
//!    `1 − NEUTRAL` ([`NEUTRAL`]: closer to 1, the differences cannot decide);
//! 3. the run is continued in chunks up to [`CheckOptions::max_time`], and after each chunk:
//!    * an equilibrium the run has come to rest at (ω_l amplitude ≤ 1e-6 rad/s over the
//!      chunk's second half) is the answer if it is the stuck set or a slipping equilibrium
//!      whose eigenvalues say it is stable;
//!    * the run's returns to the stable orbit's section `z_n` are compared with its fixed
//!      point `z*`. With `e_n = z_n − z*`, the run goes to the orbit when either
//!      `|e_n|∞ ≤ floor·(1 + |z*|∞)` at its last two returns ([`floor`]: on the orbit to the
//!      solver's own reproducibility), or the last returns follow the linearised map at the
//!      rate its multipliers predict: `e_{n+1} = λ e_n` (a one-dimensional map, stick exit)
//!      or, by Cayley–Hamilton for the 2 × 2 map, `e_{n+2} − (λ1 + λ2) e_{n+1} + λ1 λ2 e_n
//!      = 0`, each within `rate_tol·(1 − ρ)` of the deviation (ρ the largest |λ|), with `|e|`
//!      falling ([`goes_to`]). That is a run inside the orbit's linear neighbourhood, where a
//!      stable orbit attracts. Where the returns jitter by more than that relation resolves
//!      (Moreau–Jean's, by ~1e-5) and the orbit contracts slowly, the same rate is asked of a
//!      least-squares fit of `ln |e_n|` over the last 64–96 returns, and of each half of them
//!      alone (one real dominant multiplier; `fitted_rate`);
//!    * a run whose oscillation decays onto a stable slipping equilibrium at the rate its
//!      slowest eigenvalue predicts (`a_{k+1}/a_k = e^{σ (t_{k+1} − t_k)}` for the amplitudes
//!      `a_k` of ω_l at its maxima, within `rate_tol·|σ|`) answers that equilibrium.
//!
//! A run that has done none of these by `max_time`, or whose distance from the orbit (or
//! amplitude about the equilibrium) falls by less than 1 % over a chunk, is a refusal that
//! names what it saw: the stable orbit not reached (and how far the run still is), an
//! unstable orbit, a multiplier too near 1 to decide, or no orbit found. The probes do not
//! wait 20 000 s for a slow transient.

use crate::shoot::{Orbit, Section, ShootOptions, shoot};
use crate::solvers::SolverKind;
use nalgebra::Complex;
use rotor_model::seam::{Event, RigSteady};
use rotor_model::seam::{EventKind, Output, Scene, Solver};
use rotor_model::{Disc, Model, OMEGA_L, OMEGA_U, State};

use crate::steady::compute::{SteadyAnswer, SteadyError, SteadyMethod};

/// Settings of [`checked_shot`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckOptions {
    /// The first run from the start, before shooting from its last crossing \[s\]: about 20
    /// periods of the source's cycles (4–6 s), enough for the fast transients to die out.
    pub first_run: f64,
    /// Each further chunk of the check run \[s\] (about 10 periods).
    pub chunk: f64,
    /// The longest check run from the start \[s\]. 600 s is ~130 periods: a stable orbit with
    /// multiplier ≤ 0.95 is reached to 1e-3 of the start's distance within 135 periods; next
    /// to a Hopf point or a fold the run is refused instead (Moreau–Jean: 6·10⁵ steps,
    /// ~0.1 s).
    pub max_time: f64,
    /// The rate check's tolerance, as a fraction of the contraction `1 − ρ`: 0.25 tells a
    /// run converging to the orbit (its rate → 1 − ρ) from one passing it, and from one still
    /// in the nonlinear approach, whose rate differs by the relative distance (≥ 25 %).
    pub rate_tol: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            first_run: 100.0,
            chunk: 50.0,
            max_time: 600.0,
            rate_tol: 0.25,
        }
    }
}

/// How close a run's returns must come to the shot fixed point to be on the orbit, relative
/// to `1 + |z*|`: the solver's reproducibility of a return. The switch model's returns in a
/// long run repeat to ~1e-10 (its tolerance; settled metrics agree to 4e-12): 1e-7, 100× the
/// shooting tolerance 1e-9. Moreau–Jean's stick exits fall between its steps differently
/// from cycle to cycle (its metrics jitter by 2.5e-7 at h = 1e-3, `SettleOptions`): 1e-5,
/// 40× that, and still about 17× below the distance between the stable and the unstable
/// cycle 1e-6 V from Table 1's fold E (~1.7e-4 in max ω_l: a fold's square-root law applied
/// to the 2.4e-3 measured 2e-4 V below it), so a run within the floor of one is not near the
/// other.
pub fn floor(kind: SolverKind) -> f64 {
    if kind.is_fixed_step() { 1e-5 } else { 1e-7 }
}

/// What the check saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reached {
    /// The last returns lie within the floor of the fixed point.
    OnOrbit,
    /// The last returns follow the linearised map at the multipliers' rate.
    AtRate,
    /// The last returns' deviations fall at the dominant multiplier's rate on average (a
    /// least-squares fit over many returns, [`goes_to`]).
    AtRateFit,
    /// An equilibrium the run came to rest at.
    AtRest,
    /// An equilibrium the run's oscillation decays onto at its eigenvalues' rate.
    Decaying,
    /// No oscillation to shoot: the simulation method's settled equilibrium.
    Settled,
}

/// An answer of [`checked_shot`], with its check.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The steady state.
    pub answer: SteadyAnswer,
    /// How the run from the start confirmed it.
    pub reached: Reached,
    /// Simulated time from the start when the check passed \[s\].
    pub t: f64,
}

/// Runs from the start, kept as one time line.
struct Run<'a> {
    solver: Box<dyn Solver>,
    model: &'a Model,
    scene: Scene,
    events: Vec<Event>,
    t: f64,
    x: State,
    last_metrics: Option<RigSteady>,
    /// The slipping equilibria at the scene's input, found once: the checks ask for them
    /// after every chunk, and each search scans the branch `u(ω)` on 4000 points.
    equilibria: std::cell::OnceCell<Vec<rotor_model::SlipEquilibrium>>,
}

impl<'a> Run<'a> {
    /// A run of `kind` from the scene's start, nothing simulated yet.
    fn new(kind: SolverKind, model: &'a Model, scene: &Scene) -> Result<Run<'a>, SteadyError> {
        Ok(Run {
            solver: kind.solver(),
            model,
            scene: scene.clone(),
            events: Vec::new(),
            t: 0.0,
            x: scene.x0_state()?,
            last_metrics: None,
            equilibria: std::cell::OnceCell::new(),
        })
    }

    /// The slipping equilibria at the scene's input ([`Model::slip_equilibria`]).
    fn equilibria(&self) -> &[rotor_model::SlipEquilibrium] {
        self.equilibria
            .get_or_init(|| self.model.slip_equilibria(self.scene.u))
    }

    fn extend(&mut self, dt: f64) -> Result<(), SteadyError> {
        let tr = self.solver.simulate_finite(
            self.model,
            &Scene {
                x0: self.x.as_slice().to_vec(),
                t_end: dt,
                output: Output::Events,
                metrics_from: Some(0.5 * dt),
                ..self.scene.clone()
            },
        )?;
        let t0 = self.t;
        let x = tr.final_state()?;
        self.last_metrics = tr.rig_metrics();
        self.events.extend(tr.events.into_iter().map(|mut e| {
            e.t += t0;
            e
        }));
        self.t += dt;
        self.x = x;
        Ok(())
    }

    /// The returns to `section` after `from` \[s\]: time and section coordinates.
    fn returns(&self, section: Section, from: f64) -> Vec<(f64, Vec<f64>)> {
        let kind = match section {
            Section::StickExit => EventKind::StickEnd(Disc::LOWER),
            Section::LowerMax => EventKind::Max(Disc::LOWER),
        };
        self.events
            .iter()
            .filter(|e| e.kind == kind && e.t >= from)
            .map(|e| (e.t, project(section, &e.state())))
            .collect()
    }
}

fn project(section: Section, x: &State) -> Vec<f64> {
    match section {
        Section::StickExit => vec![x[OMEGA_U]],
        Section::LowerMax => vec![x[OMEGA_U], x[OMEGA_L]],
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Whether the returns `z` (time order) go to the fixed point `zs` of an orbit with
/// nontrivial multipliers `mult`: on the orbit (`floor`) or at the linearised rate (see the
/// module docs). `None` when neither yet.
pub fn goes_to(
    z: &[Vec<f64>],
    zs: &[f64],
    mult: &[[f64; 2]],
    floor_rel: f64,
    rate_tol: f64,
) -> Option<Reached> {
    let e: Vec<Vec<f64>> = z
        .iter()
        .map(|zi| zi.iter().zip(zs).map(|(a, b)| a - b).collect())
        .collect();
    let n = e.len();
    let floor = floor_rel * (1.0 + norm(zs));
    if n >= 2 && norm(&e[n - 1]) <= floor && norm(&e[n - 2]) <= floor {
        return Some(Reached::OnOrbit);
    }
    let rho = mult.iter().map(|m| m[0].hypot(m[1])).fold(0.0, f64::max);
    if rho >= 1.0 {
        return None;
    }
    let tol = rate_tol * (1.0 - rho);
    let residual = |k: usize| -> f64 {
        // k indexes the newest deviation of the relation.
        if zs.len() == 1 {
            (e[k][0] - mult[0][0] * e[k - 1][0]).abs() / e[k - 1][0].abs().max(e[k][0].abs())
        } else {
            let (l1, l2) = (
                Complex::new(mult[0][0], mult[0][1]),
                Complex::new(mult[1][0], mult[1][1]),
            );
            let (tr, det) = ((l1 + l2).re, (l1 * l2).re);
            let r: Vec<f64> = (0..2)
                .map(|c| e[k][c] - tr * e[k - 1][c] + det * e[k - 2][c])
                .collect();
            norm(&r) / norm(&e[k]).max(norm(&e[k - 1])).max(norm(&e[k - 2]))
        }
    };
    // Two consecutive relations, each past the floor, and the deviation falling.
    let need = if zs.len() == 1 { 3 } else { 4 };
    if n < need {
        return None;
    }
    let last = n - 1;
    let above = e[n - need..].iter().all(|d| norm(d) > floor);
    let falling = norm(&e[last]) < norm(&e[n - need]);
    if above && falling && residual(last) <= tol && residual(last - 1) <= tol {
        return Some(Reached::AtRate);
    }
    fitted_rate(&e, mult, floor, tol)
}

/// The fewest and the most returns [`fitted_rate`] fits.
const FIT_MIN: usize = 64;
const FIT_MAX: usize = 96;

/// The rate check averaged over many returns, for a solver whose returns jitter by more than
/// the two-step relation resolves (Moreau–Jean's stick exits and extrema fall between its
/// steps: ~1e-5 of `1 + |z*|`, [`floor`]) on an orbit that contracts slowly (a multiplier near
/// 1, next to a Hopf point). With one real dominant multiplier `λ1` (`|λ2| ≤ |λ1|/2`: the
/// other component has died out after the run's first returns), the deviations of the last
/// `K` returns (`FIT_MIN ≤ K ≤ FIT_MAX`) follow `|e_n| = c·|λ1|^n`: the least-squares slope
/// of `ln |e_n|` against `n` must be `ln |λ1|` within `tol` (`rate_tol·(1 − ρ)`, as for the
/// two-step relation), and so must the slopes of the window's first and second halves, each
/// alone (a run still in the nonlinear approach changes its rate along the window). Every
/// deviation must be above 100 floors and the last below the first. So the error of
/// `ln |e_n|` is at most σ = 0.01, and the slope of a half window of at least 32 returns is
/// good to σ·√(12/32³) = 1.9e-4, a third of the tolerance next to Table 1's H1 (0.25 ×
/// 2.6e-3 = 6.5e-4) and less elsewhere.
fn fitted_rate(e: &[Vec<f64>], mult: &[[f64; 2]], floor: f64, tol: f64) -> Option<Reached> {
    let l1 = mult.first()?;
    let rho = l1[0].hypot(l1[1]);
    let real = l1[1] == 0.0 && mult.get(1).is_none_or(|l2| l2[0].hypot(l2[1]) <= 0.5 * rho);
    let n = e.len();
    if !real || n < FIT_MIN || rho >= 1.0 || rho <= 0.0 {
        return None;
    }
    let w: Vec<f64> = e[n - n.min(FIT_MAX)..].iter().map(|d| norm(d)).collect();
    if w.iter().any(|&d| d <= 100.0 * floor) || w[w.len() - 1] >= w[0] {
        return None;
    }
    let slope = |ys: &[f64]| {
        let k = ys.len() as f64;
        let mean_x = 0.5 * (k - 1.0);
        let mean_y = ys.iter().map(|y| y.ln()).sum::<f64>() / k;
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (i, y) in ys.iter().enumerate() {
            let dx = i as f64 - mean_x;
            sxy += dx * (y.ln() - mean_y);
            sxx += dx * dx;
        }
        sxy / sxx
    };
    let half = w.len() / 2;
    [&w[..], &w[..half], &w[half..]]
        .iter()
        .all(|part| (slope(part) - rho.ln()).abs() <= tol)
        .then_some(Reached::AtRateFit)
}

/// The slipping equilibrium of the run's input nearest ω, if it is stable.
fn stable_equilibrium(run: &Run, omega: f64) -> Option<rotor_model::SlipEquilibrium> {
    let e = *run
        .equilibria()
        .iter()
        .min_by(|a, b| (a.omega - omega).abs().total_cmp(&(b.omega - omega).abs()))?;
    run.model.equilibrium_is_stable(&e).then_some(e)
}

fn equilibrium_answer(e: &rotor_model::SlipEquilibrium) -> SteadyAnswer {
    SteadyAnswer {
        state: RigSteady::Equilibrium {
            omega_u: e.omega,
            omega_l: e.omega,
            alpha: e.alpha,
        },
        method: SteadyMethod::Equilibrium,
        multipliers: None,
        stable: None,
        stats: Default::default(),
        on_cycle: None,
    }
}

/// Whether the run's oscillation decays onto the stable slipping equilibrium nearest its
/// last ω_l maximum at the rate of the equilibrium's slowest eigenvalue (see the module
/// docs).
fn decays_onto(run: &Run, rate_tol: f64) -> Option<rotor_model::SlipEquilibrium> {
    let model = run.model;
    let maxima = run.returns(Section::LowerMax, 0.5 * run.t);
    let last = maxima.last()?;
    let e = stable_equilibrium(run, last.1[1])?;
    let sigma = model
        .equilibrium_eigenvalues(&e)
        .iter()
        .map(|l| l.re)
        .fold(f64::NEG_INFINITY, f64::max);
    let n = maxima.len();
    if n < 3 || sigma >= 0.0 {
        return None;
    }
    let amp = |k: usize| (maxima[k].1[1] - e.omega).abs();
    let ok = (n - 2..n).all(|k| {
        let (a0, a1) = (amp(k - 1), amp(k));
        let dt = maxima[k].0 - maxima[k - 1].0;
        a1 < a0 && ((a1 / a0).ln() / dt - sigma).abs() <= rate_tol * sigma.abs()
    });
    ok.then_some(e)
}

/// The steady state `kind` reaches from `scene.x0` at `scene.u`, by shooting on its own
/// return map and checked by a bounded simulation from the start (see the module docs), and
/// against the model ([`crate::steady::verify`]).
pub fn checked_shot(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    opts: &CheckOptions,
) -> Result<Checked, SteadyError> {
    let c = shot_and_checked(kind, model, scene, opts)?;
    crate::steady::verify::verify(kind, model, scene, &c.answer)?;
    Ok(c)
}

fn shot_and_checked(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    opts: &CheckOptions,
) -> Result<Checked, SteadyError> {
    scene.validate()?;
    let mut run = Run::new(kind, model, scene)?;
    run.extend(opts.first_run)?;
    // Shooting from the last crossing of the first run's second half.
    let half = 0.5 * run.t;
    let start = [Section::StickExit, Section::LowerMax]
        .into_iter()
        .find_map(|s| run.returns(s, half).last().map(|r| (s, r.1.clone())));
    let shot = start.map(|(section, z0)| {
        shoot(
            &*run.solver,
            model,
            scene,
            section,
            &z0,
            &ShootOptions {
                // The most iterations a converging Newton took over all the probes was 14
                // (measured); a start that needs more is outside its basin, and failing
                // sooner saves up to 30 runs of the horizon.
                max_iter: 16,
                ..ShootOptions::default()
            },
        )
    });
    // An orbit whose largest multiplier is within `NEUTRAL` of the unit circle has a
    // stability the differences cannot decide.
    let orbit = match &shot {
        Some(Ok(o)) if o.is_stable() && spectral_radius(o) < 1.0 - NEUTRAL => Some(o),
        _ => None,
    };
    if shot.is_none() {
        // No crossing of either section in the run's second half: no cycle to shoot, an
        // equilibrium being approached (a disc creeping into the stuck set, say), or one
        // already reached, which the loop below would answer at once.
        if let Some(e) = at_rest(&run) {
            return Ok(Checked {
                answer: e,
                reached: Reached::AtRest,
                t: run.t,
            });
        }
        // The simulation method answers the approach, continuing the run, with its own
        // check that the run has settled ([`crate::steady::settle`]).
        let s = crate::steady::settle::settle(
            kind,
            model,
            &Scene {
                x0: run.x.as_slice().to_vec(),
                ..scene.clone()
            },
            &crate::steady::settle::SettleOptions {
                // An equilibrium has no period for a chunk to span: 100 s chunks (the
                // default's 300 s is 60 periods of a cycle) gave every probe the same verdict.
                chunk: 100.0,
                ..Default::default()
            },
        )?;
        return Ok(Checked {
            t: run.t,
            answer: SteadyAnswer {
                state: s.state,
                on_cycle: matches!(s.state, RigSteady::LimitCycle { .. }).then_some(s.x),
                method: SteadyMethod::Simulated,
                multipliers: None,
                stable: None,
                stats: s.stats,
            },
            reached: Reached::Settled,
        });
    }
    let fl = floor(kind);
    // The distance of the latest return from the orbit at the end of the previous chunk.
    let mut previous = f64::INFINITY;
    loop {
        if let Some(e) = at_rest(&run) {
            return Ok(Checked {
                answer: e,
                reached: Reached::AtRest,
                t: run.t,
            });
        }
        if let Some(o) = orbit {
            let z: Vec<Vec<f64>> = run
                .returns(o.section, 0.0)
                .into_iter()
                .map(|r| r.1)
                .collect();
            if let Some(r) = goes_to(&z, &o.z, &o.multipliers, fl, opts.rate_tol) {
                return Ok(Checked {
                    answer: orbit_answer(&*run.solver, model, scene, o)?,
                    reached: r,
                    t: run.t,
                });
            }
        }
        if let Some(e) = decays_onto(&run, opts.rate_tol) {
            return Ok(Checked {
                answer: equilibrium_answer(&e),
                reached: Reached::Decaying,
                t: run.t,
            });
        }
        // A run that is not coming nearer to the orbit (by 1 % per chunk, ~10 periods) will
        // not reach it by `max_time` either: a slow transient or another attractor.
        // Without an orbit, the same for the oscillation's decay onto an equilibrium.
        let d = orbit.map_or_else(|| amplitude(&run), |o| distance(&run, o));
        if run.t >= opts.max_time || (d.is_finite() && d > 0.99 * previous) {
            break;
        }
        previous = d;
        run.extend(opts.chunk)?;
    }
    Err(match shot {
        Some(Ok(o)) if orbit.is_some() => SteadyError::NotReached {
            t: run.t,
            distance: distance(&run, &o),
            multipliers: multipliers_text(&o),
        },
        Some(Ok(o)) if o.is_stable() || spectral_radius(&o) <= 1.0 + NEUTRAL => {
            SteadyError::Neutral {
                multipliers: multipliers_text(&o),
                period: o.period,
            }
        }
        Some(Ok(o)) => SteadyError::Unstable {
            multipliers: multipliers_text(&o),
            period: o.period,
        },
        Some(Err(e)) => SteadyError::Shoot(e),
        None => SteadyError::Shoot(crate::shoot::ShootError::NotACycle { t_end: run.t }),
    })
}

/// `rotor steady`'s default: the fastest method that is right from every start. The
/// event-driven solver answers by its own refinement ([`crate::steady::steady()`], which checks on its
/// own flow that the run reaches the cycle); the switch model and Moreau–Jean by
/// [`checked_shot`], which answers only a stable orbit (or a stable equilibrium) that a run
/// from the start is seen to go to, in a few hundred seconds of simulated time where settling
/// next to a Hopf point takes thousands. When the check refuses (a transient too slow for its
/// `max_time`, an unstable or neutral orbit, no orbit found), the answer is the simulation
/// method's ([`crate::steady::steady()`] with `opts`), which is right from every start but slow there:
/// so the default never answers an unstable orbit, and answers whatever `--method simulate`
/// would where the check cannot decide. The answer's `method` says which answered.
pub fn checked_or_simulated(
    kind: SolverKind,
    model: &Model,
    scene: &Scene,
    opts: &crate::steady::compute::SteadyOptions,
) -> Result<SteadyAnswer, SteadyError> {
    crate::steady::compute::constant_input(scene)?;
    if kind == SolverKind::EVENT {
        return crate::steady::compute::steady(kind, model, scene, opts);
    }
    // A check run of up to 3000 s, five times the probes': next to a Hopf point a run from
    // rest needs ~2000 s to come close enough to the small cycle for its returns to fall at
    // the multiplier's rate (Table 1, 1e-4 V above H1: multiplier 0.9974, accepted by the
    // fitted rate after ~520 returns), and 3000 s of Moreau–Jean's steps cost about as much
    // as the first 400 s of the simulation that would follow (which settles there after
    // ~12 000 s).
    let opts_check = CheckOptions {
        max_time: 3000.0,
        ..CheckOptions::default()
    };
    match checked_shot(kind, model, scene, &opts_check) {
        Ok(c) => Ok(c.answer),
        // A stable orbit not yet reached: if the simulation does not settle either, the
        // refusal says both, and that shooting has an orbit.
        Err(check @ SteadyError::NotReached { .. }) => {
            crate::steady::compute::steady(kind, model, scene, opts).map_err(|simulate| {
                match simulate {
                    SteadyError::Settle(_) => SteadyError::Unconfirmed {
                        check: Box::new(check),
                        simulate: Box::new(simulate),
                    },
                    other => other,
                }
            })
        }
        Err(SteadyError::Neutral { .. } | SteadyError::Unstable { .. } | SteadyError::Shoot(_)) => {
            crate::steady::compute::steady(kind, model, scene, opts)
        }
        Err(e) => Err(e),
    }
}

/// How close to the unit circle a multiplier may come before shooting cannot tell a stable
/// orbit from an unstable one: the return map's differences are accurate to ~1e-4 of the
/// derivative (`ShootOptions::fd_rel`: the map's rounding over the step), so 1e-3.
pub const NEUTRAL: f64 = 1e-3;

/// The amplitude of ω_l at the run's latest maximum about the nearest slipping
/// equilibrium (∞ without one).
fn amplitude(run: &Run) -> f64 {
    let Some(last) = run.returns(Section::LowerMax, 0.0).pop() else {
        return f64::INFINITY;
    };
    let w = last.1[1];
    run.equilibria()
        .iter()
        .map(|e| (w - e.omega).abs())
        .fold(f64::INFINITY, f64::min)
}

/// `|z_n − z*|∞` of the run's latest return to the orbit's section.
fn distance(run: &Run, o: &Orbit) -> f64 {
    run.returns(o.section, 0.0)
        .last()
        .map_or(f64::INFINITY, |zl| {
            norm(
                &zl.1
                    .iter()
                    .zip(&o.z)
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            )
        })
}

fn spectral_radius(o: &Orbit) -> f64 {
    o.multipliers
        .iter()
        .map(|m| m[0].hypot(m[1]))
        .fold(0.0, f64::max)
}

/// The equilibrium the run has come to rest at (its last chunk's ω_l amplitude ≤ 1e-6
/// rad/s): the stuck set, or a slipping equilibrium whose eigenvalues say it is stable.
fn at_rest(run: &Run) -> Option<SteadyAnswer> {
    let (model, u) = (run.model, run.scene.u);
    let Some(RigSteady::Equilibrium { omega_l, alpha, .. }) = run.last_metrics else {
        return None;
    };
    if omega_l == 0.0 {
        let s = model.stuck_equilibria(u)?;
        return (s.alpha_min..=s.alpha_max)
            .contains(&alpha)
            .then(|| SteadyAnswer {
                state: run.last_metrics.expect("matched"),
                method: SteadyMethod::Equilibrium,
                multipliers: None,
                stable: None,
                stats: Default::default(),
                on_cycle: None,
            });
    }
    let e = stable_equilibrium(run, omega_l)?;
    ((e.omega - omega_l).abs() <= 1e-6).then(|| equilibrium_answer(&e))
}

fn multipliers_text(o: &Orbit) -> String {
    o.multipliers
        .iter()
        .map(|m| format!("{:.6}{:+.6}i", m[0], m[1]))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The orbit's metrics (its last complete cycle of a run over two periods from the fixed
/// point) and multipliers `[1, λ, 0]` or `[1, λ1, λ2]`.
pub(crate) fn orbit_answer(
    solver: &dyn Solver,
    model: &Model,
    scene: &Scene,
    orbit: &Orbit,
) -> Result<SteadyAnswer, SteadyError> {
    let skip = ShootOptions::default().skip;
    let t_end = 2.0 * orbit.period + skip;
    let run = solver.simulate_finite(
        model,
        &Scene {
            x0: orbit.x.as_slice().to_vec(),
            t_end,
            output: Output::Final,
            metrics_from: Some(0.0),
            ..scene.clone()
        },
    )?;
    crate::steady::compute::shot_answer(orbit, run, t_end)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rate check on made-up returns of a one-dimensional map with multiplier 0.9: a
    /// geometric approach passes, an approach at another rate (to a different fixed point)
    /// and a growing deviation do not; returns within the floor pass as on the orbit.
    #[test]
    fn the_rate_check_tells_an_approach_at_the_multipliers_rate() {
        let zs = [1.0];
        let mult = [[0.9, 0.0]];
        let geo: Vec<Vec<f64>> = (0..5).map(|k| vec![1.0 + 0.1 * 0.9f64.powi(k)]).collect();
        assert_eq!(goes_to(&geo, &zs, &mult, 1e-7, 0.25), Some(Reached::AtRate));
        // The same returns converging to 1.05 instead: deviations from 1.0 fall at another
        // rate.
        let elsewhere: Vec<Vec<f64>> = (0..5).map(|k| vec![1.05 + 0.05 * 0.9f64.powi(k)]).collect();
        assert_eq!(goes_to(&elsewhere, &zs, &mult, 1e-7, 0.25), None);
        let growing: Vec<Vec<f64>> = (0..5).map(|k| vec![1.0 + 1e-3 * 1.1f64.powi(k)]).collect();
        assert_eq!(goes_to(&growing, &zs, &mult, 1e-7, 0.25), None);
        let on = vec![vec![1.0 + 1e-9], vec![1.0 - 1e-9]];
        assert_eq!(goes_to(&on, &zs, &mult, 1e-7, 0.25), Some(Reached::OnOrbit));
        // An unstable orbit is never gone to at a rate.
        assert_eq!(goes_to(&geo, &zs, &[[1.1, 0.0]], 1e-7, 0.25), None);
    }

    /// Table 1 at 4.5 V is bistable (between H2 and G2): from rest the run goes to the
    /// stick-slip cycle, from the perturbed equilibrium it stays at the stable equilibrium
    /// (the fixtures t1-u4.5-rest and t1-u4.5-eq-pert). Shooting from rest finds the cycle and
    /// the check passes; the run from the perturbed equilibrium never comes to that cycle, so
    /// the same orbit is refused as its steady state, and its checked answer is the
    /// equilibrium.
    #[test]
    fn the_check_refuses_an_orbit_the_start_does_not_go_to() {
        let m = Model::table1();
        let u = 4.5;
        for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
            let rest = Scene {
                u,
                ..Scene::default()
            };
            let c = checked_shot(kind, &m, &rest, &CheckOptions::default()).unwrap();
            assert_eq!(c.answer.method, SteadyMethod::Shoot, "{c:?}");
            assert_eq!(c.answer.stable, Some(true));
            // The cycle, shot again from the rest run to have its fixed point.
            let solver = kind.solver();
            let (section, z0) =
                Section::of_run(&*solver, &m, &rest, State::zeros(), 100.0).unwrap();
            let orbit = shoot(&*solver, &m, &rest, section, &z0, &Default::default()).unwrap();
            // Returns of a run from the perturbed equilibrium to that orbit's section.
            let pert = Scene {
                x0: m.perturbed_equilibrium(u).as_slice().to_vec(),
                ..rest.clone()
            };
            let mut run = Run::new(kind, &m, &pert).unwrap();
            run.extend(600.0).unwrap();
            let z: Vec<Vec<f64>> = run.returns(section, 0.0).into_iter().map(|r| r.1).collect();
            assert_eq!(
                goes_to(&z, &orbit.z, &orbit.multipliers, floor(kind), 0.25),
                None,
                "{}: the run from the equilibrium was taken to go to the cycle",
                kind.name()
            );
            let c = checked_shot(kind, &m, &pert, &CheckOptions::default()).unwrap();
            assert_eq!(c.answer.method, SteadyMethod::Equilibrium, "{c:?}");
        }
    }

    /// A start that comes to rest without crossing either section (Table 1, 1e-3 V above the
    /// stick limit, from the perturbed equilibrium: the disturbance dies out without a maximum
    /// of ω_l) is answered by the at-rest test after the first run, as the chunks' loop would
    /// answer it, not by 200 s more of settling; the answer is the slipping equilibrium the
    /// model computes, to the at-rest test's 1e-6 rad/s. A start that does not come to rest
    /// by then (from rest, where the lower disc creeps for longer) still settles.
    #[test]
    fn a_start_at_rest_after_the_first_run_is_answered_there() {
        let m = Model::new(rotor_model::Params::table1());
        // The stick limit as the diagram finds it.
        let u = m.slip_equilibrium_at(f64::MIN_POSITIVE).u + 1e-3;
        let e = m.slip_equilibria(u)[0];
        for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
            let scene = Scene {
                u,
                x0: m.perturbed_equilibrium(u).as_slice().to_vec(),
                ..Scene::default()
            };
            let opts = CheckOptions::default();
            let c = checked_shot(kind, &m, &scene, &opts).unwrap();
            assert_eq!(
                (c.reached, c.answer.method, c.t),
                (Reached::AtRest, SteadyMethod::Equilibrium, opts.first_run),
                "{}: {c:?}",
                kind.name()
            );
            let RigSteady::Equilibrium { omega_l, .. } = c.answer.state else {
                panic!("{}: not an equilibrium: {c:?}", kind.name());
            };
            assert!(
                (omega_l - e.omega).abs() <= 1e-6,
                "{}: {omega_l} vs {}",
                kind.name(),
                e.omega
            );
        }
    }

    /// `rotor steady`'s default from a start on the unstable slipping cycle near 4.40 V of
    /// Table 1 (continued from the subcritical Hopf point H2; its multiplier ≈ 1.11, as the
    /// rotor_analysis::shoot tests find): Newton from that start finds the unstable cycle, but the
    /// default must not answer it. Its answer is stable, and for the switch model the same
    /// attractor as the simulation method's (kind, and period within 1e-5 relative: the
    /// probes' agreement for the switch model).
    #[test]
    fn the_default_never_answers_the_unstable_cycle() {
        let m = Model::table1();
        let d = crate::bifurcation::diagram(
            &m,
            &crate::bifurcation::DiagramOptions {
                u_min: 4.2,
                u_max: 4.45,
                n: 20,
                u_start: 4.3,
                ..Default::default()
            },
        )
        .unwrap();
        let row = d
            .periodic
            .iter()
            .filter(|r| !r.stable && !r.stick_slip)
            .min_by(|a, b| (a.u - 4.4).abs().total_cmp(&(b.u - 4.4).abs()))
            .unwrap();
        assert!(row.multipliers[1][0] > 1.05, "{:?}", row.multipliers);
        let x0 = State::new(
            row.section_state[0],
            row.section_state[1],
            row.section_state[2],
        );
        let scene = Scene {
            u: row.u,
            x0: x0.as_slice().to_vec(),
            ..Scene::default()
        };
        for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
            let solver = kind.solver();
            // Next to it: Newton from one period's run finds the unstable cycle.
            let (section, z0) =
                Section::of_run(&*solver, &m, &scene, x0, 2.0 * row.period).unwrap();
            let o = shoot(&*solver, &m, &scene, section, &z0, &Default::default()).unwrap();
            assert!(!o.is_stable(), "{}: {:?}", kind.name(), o.multipliers);
            let a = checked_or_simulated(kind, &m, &scene, &Default::default()).unwrap();
            assert_ne!(a.stable, Some(false), "{}: {a:?}", kind.name());
            if let RigSteady::LimitCycle { period, .. } = a.state {
                // Not the unstable cycle: its period differs by far more than any solver's
                // error (1e-4 s, Moreau–Jean's O(h²) period error is ~6e-7 s).
                assert!((period - row.period).abs() > 1e-4, "{}: {a:?}", kind.name());
            }
            if kind == SolverKind::SWITCH {
                let sim =
                    crate::steady::compute::steady(kind, &m, &scene, &Default::default()).unwrap();
                match (a.state, sim.state) {
                    (
                        RigSteady::LimitCycle { period: p, .. },
                        RigSteady::LimitCycle { period: q, .. },
                    ) => assert!((p - q).abs() <= 1e-5 * q, "{a:?} vs {sim:?}"),
                    (RigSteady::Equilibrium { .. }, RigSteady::Equilibrium { .. }) => {}
                    _ => panic!("default {a:?} vs simulation {sim:?}"),
                }
            }
        }
    }

    /// The fitted rate: a slow geometric approach seen through a jitter the two-step relation
    /// cannot see through passes; an algebraic approach, another rate, returns within a
    /// hundred floors and a complex pair do not.
    #[test]
    fn the_fitted_rate_sees_a_slow_approach_through_jitter() {
        // A one-dimensional map with multiplier 0.997 (next to a Hopf point), deviations from
        // 1e-2 down, each return off by up to 2e-3 of itself (a deterministic jitter, Moreau–
        // Jean's kind): the two-step relation's residual is then up to ~4e-3 of the
        // deviation, over the 0.25·(1 − 0.997) = 7.5e-4 it allows.
        let mult = [[0.997, 0.0]];
        let jitter = |k: usize| 2e-3 * ((k as f64 * 2.399).sin());
        let returns = |dev: &dyn Fn(usize) -> f64| -> Vec<Vec<f64>> {
            (0..96)
                .map(|k| vec![1.0 + dev(k) * (1.0 + jitter(k))])
                .collect()
        };
        let slow = returns(&|k| 1e-2 * 0.997f64.powi(k as i32));
        assert_eq!(
            goes_to(&slow, &[1.0], &mult, 1e-5, 0.25),
            Some(Reached::AtRateFit)
        );
        // Its first eight returns, too few for the fit: the two-step relation alone does not
        // see the approach.
        assert_eq!(goes_to(&slow[..8], &[1.0], &mult, 1e-5, 0.25), None);
        let e: Vec<Vec<f64>> = slow.iter().map(|z| vec![z[0] - 1.0]).collect();
        // Still in the nonlinear approach: an algebraic decay, whose rate changes along the
        // window (the run from rest next to a Hopf point, far from the small cycle).
        let algebraic = returns(&|k| 2e-2 / (1.0 + 0.01 * k as f64));
        assert_eq!(goes_to(&algebraic, &[1.0], &mult, 1e-5, 0.25), None);
        // Geometric at another rate (to another fixed point, or the nonlinear regime).
        let faster = returns(&|k| 1e-2 * 0.99f64.powi(k as i32));
        assert_eq!(goes_to(&faster, &[1.0], &mult, 1e-5, 0.25), None);
        // Within a hundred floors of the orbit: the jitter could be much of it.
        assert_eq!(goes_to(&slow, &[1.0], &mult, 1e-4, 0.25), None);
        // A complex pair: the norm rotates, so no fit.
        assert_eq!(
            fitted_rate(&e, &[[0.9, 0.3], [0.9, -0.3]], 1e-5, 0.25 * 0.05),
            None
        );
    }

    /// The default's refusal when neither shooting's check nor the simulation answers names
    /// both, and the way to the unchecked orbit.
    #[test]
    fn an_unconfirmed_orbit_names_both_refusals() {
        let e = SteadyError::Unconfirmed {
            check: Box::new(SteadyError::NotReached {
                t: 3000.0,
                distance: 2e-3,
                multipliers: "0.999+0i".into(),
            }),
            simulate: Box::new(SteadyError::Shoot(crate::shoot::ShootError::NotACycle {
                t_end: 1.0,
            })),
        }
        .to_string();
        for needle in [
            "has not reached the stable orbit",
            "shooting found no",
            "--method shoot",
        ] {
            assert!(e.contains(needle), "{needle}: {e}");
        }
    }

    /// A 2 × 2 map with a complex pair of modulus 0.8: its deviations rotate, so their size
    /// is not monotone, but they satisfy Cayley–Hamilton's relation.
    #[test]
    fn the_rate_check_follows_a_rotating_approach() {
        let (c, s) = (0.8 * 0.5f64.cos(), 0.8 * 0.5f64.sin());
        let mut e = [1e-2, 0.0];
        let mut z = Vec::new();
        for _ in 0..8 {
            z.push(vec![2.0 + e[0], 3.0 + e[1]]);
            e = [c * e[0] - s * e[1], s * e[0] + c * e[1]];
        }
        let mult = [[c, s], [c, -s]];
        assert_eq!(
            goes_to(&z, &[2.0, 3.0], &mult, 1e-9, 0.25),
            Some(Reached::AtRate)
        );
        // Against the wrong multipliers (a real pair 0.8, 0.1) it does not pass.
        assert_eq!(
            goes_to(&z, &[2.0, 3.0], &[[0.8, 0.0], [0.1, 0.0]], 1e-9, 0.25),
            None
        );
    }
}
