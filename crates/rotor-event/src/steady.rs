//! Steady states refined rather than read off a long run.
//!
//! 1. A settling run classifies the attractor reached from `x0` (equilibrium, stick-slip
//!    cycle, slipping cycle).
//! 2. An equilibrium is taken from the equilibrium equations (the slipping branch
//!    `u(ω)` solved for ω, see `rotor_model::equilibrium`), or is the stuck state itself, or
//!    — for a disc creeping onto the boundary of its stick interval, which it approaches
//!    exponentially and never reaches — that boundary.
//! 3. A stick-slip cycle is the fixed point of the return map from one exit of the lower disc
//!    from stick to the next. At an exit `k_θ α = T_sl` and `ω_l = 0` are known exactly, so the
//!    map is one-dimensional in ω_u (zero-dimensional if the upper disc is stuck then); it is
//!    solved by the secant method.
//! 4. A slipping cycle is found by shooting on the Poincaré section `ω_l = c` (upward), a
//!    two-dimensional map in (α, ω_u), by Newton with a finite-difference Jacobian.
//!
//! The metrics are then measured over exactly one period from the fixed point.
//!
//! A fixed point is accepted only if it is stable: its nontrivial Floquet multipliers, the
//! eigenvalues of the return map's derivative at the fixed point (central differences), lie
//! inside the unit circle. A steady state reached from an initial state is an attractor, and
//! near a fold of cycles Newton's method converges to whichever of the stable and the
//! unstable cycle is nearer. When the refined cycle is unstable the settling run goes on (to a
//! cycle-to-cycle drift of 1e-10) and the refinement is tried again from there; if it still
//! finds only an unstable cycle, the settled run's own last cycle is the answer
//! ([`Method::Settled`]).

use rotor_model::seam::{Event, EventKind, EventRef, MetricsAccumulator, RigSteady, SolveError};
use rotor_model::{Disc, DiscMode, Mode, Model, SlipEquilibrium, State};

use nalgebra::{Complex, U3};

use crate::filippov::{EventOptions, Integrator, RunEnd, Sink};

/// How a steady state was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// An equilibrium from the equilibrium equations, the stuck set or its boundary.
    Equilibrium,
    /// A cycle refined as a stable fixed point of a return map.
    Refined,
    /// A cycle read off a run that settled to a cycle-to-cycle drift of 1e-10, where the
    /// refinement found no stable fixed point.
    Settled,
}

/// A refined steady state.
#[derive(Debug, Clone, PartialEq)]
pub struct Steady {
    /// The steady state's metrics (an equilibrium's state, or a cycle's period, extrema and
    /// stick time).
    pub state: RigSteady,
    /// How it was obtained.
    pub method: Method,
    /// A state on the cycle (at the fixed point of the return map, or the settled run's
    /// final state); `None` for an equilibrium.
    pub on_cycle: Option<State>,
    /// The nontrivial Floquet multipliers of a refined cycle from central differences of its
    /// return map: `P'(w*)` of the stick-exit map (one), or the eigenvalues of `DP(z*)` of
    /// the section map (two). Empty otherwise.
    pub multipliers: Vec<Complex<f64>>,
}

impl Steady {
    /// Whether every multiplier lies inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.multipliers.iter().all(|m| m.norm() < 1.0)
    }
}

/// Options of the steady-state refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Integration tolerance.
    pub tol: f64,
    /// Length of one settling chunk \[s\]; metrics are read over its second half.
    pub settle: f64,
    /// Longest total settling time \[s\] (a focus with Re λ = −1e-3 /s near a Hopf point
    /// decays by e^-20 in 20 000 s).
    pub max_settle: f64,
    /// Newton/secant stopping tolerance on the fixed-point residual (rad/s).
    pub fixed_point_tol: f64,
    /// The section Newton iteration also stops only once its step is below this, relative
    /// to `1 + |z|`: next to a Hopf point the map is nearly the identity and a residual below
    /// `fixed_point_tol` can still be far from a fixed point.
    pub fixed_point_step: f64,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        SteadyOptions {
            tol: 1e-12,
            settle: 300.0,
            max_settle: 20_000.0,
            fixed_point_tol: 1e-11,
            fixed_point_step: 1e-7,
        }
    }
}

#[derive(PartialEq)]
enum Stop {
    LowerStickExit,
    Section,
}

struct StopSink {
    stop: Stop,
    acc: Option<MetricsAccumulator>,
    lower_exits: u64,
}

impl Sink<U3> for StopSink {
    fn event(&mut self, e: EventRef<'_>) {
        if e.kind == EventKind::StickEnd(Disc::LOWER) {
            self.lower_exits += 1;
        }
        if let Some(a) = self.acc.as_mut() {
            a.push(e);
        }
    }
    fn stop_after(&mut self, e: EventRef<'_>) -> bool {
        self.stop == Stop::LowerStickExit && e.kind == EventKind::StickEnd(Disc::LOWER)
    }
    fn section(&mut self, _t: f64, _x: &State) -> bool {
        self.stop == Stop::Section
    }
}

struct Flow<'a> {
    model: &'a Model,
    u: f64,
    tol: f64,
    ev: EventOptions,
}

impl Flow<'_> {
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        x: State,
        mode: Mode,
        t_max: f64,
        stop: Stop,
        extrema: bool,
        section: Option<f64>,
        acc: Option<MetricsAccumulator>,
    ) -> Result<(RunEnd<U3>, StopSink), SolveError> {
        let mut integ = Integrator::rig(self.model, self.u, self.tol, self.ev);
        integ.extrema = extrema;
        integ.section = section;
        let mut sink = StopSink {
            stop,
            acc,
            lower_exits: 0,
        };
        let end = integ.run(0.0, x, mode, t_max, &mut sink)?;
        Ok((end, sink))
    }

    /// State and mode just after the lower disc leaves stick with upper velocity `w`, in the
    /// direction of the torque that breaks it loose (upward for u > 0, downward for u < 0).
    /// `alpha` is a located exit's; the state starts on the edge of the stick interval that
    /// exit leaves through ([`exit_alpha`]).
    fn exit_state(&self, alpha: f64, w: f64, upper: DiscMode) -> (State, Mode) {
        let alpha = exit_alpha(self.model, alpha);
        let x = State::new(alpha, if upper == DiscMode::Stick { 0.0 } else { w }, 0.0);
        let lower = DiscMode::slip_of(self.model.applied_torque(Disc::LOWER, &x, self.u));
        (x, Mode::rig(upper, lower))
    }

    /// Return map at the lower disc's stick exit: ω_u at the next exit (and the mode there).
    fn stick_exit_map(
        &self,
        alpha: f64,
        w: f64,
        upper: DiscMode,
    ) -> Result<RunEnd<U3>, SolveError> {
        let (x, mode) = self.exit_state(alpha, w, upper);
        let (end, sink) = self.run(x, mode, 1e4, Stop::LowerStickExit, false, None, None)?;
        if sink.lower_exits == 0 {
            return Err(SolveError::NoConvergence {
                detail: "the orbit no longer returns to a stick exit".into(),
            });
        }
        Ok(end)
    }

    /// Poincaré map on ω_l = c (upward): (α, ω_u) ↦ (α, ω_u) at the next crossing.
    fn section_map(&self, z: [f64; 2], c: f64) -> Result<[f64; 2], SolveError> {
        let x = State::new(z[0], z[1], c);
        let mode = self.model.mode_at(&x, self.u);
        let (end, _) = self.run(x, mode, 1e4, Stop::Section, false, Some(c), None)?;
        if end.t >= 1e4 {
            return Err(SolveError::NoConvergence {
                detail: format!("no return to the section omega_l = {c}"),
            });
        }
        Ok([end.x[0], end.x[1]])
    }
}

/// α on the edge of the lower disc's stick interval that an exit near `alpha` leaves
/// through: `k_θ α = T_hi` (or `T_lo`), rounded outward until the model's own stick test
/// ([`Model::stick_exit`]) says the disc leaves.
///
/// The stick-exit map's section is that edge, exactly: `k_θ α = T_sl` and `ω_l = 0` at every
/// exit. A located exit's α is only as exact as its time, `ulp(t)·k_θ·|α̇|` off the edge
/// (1.4e-13 rad at t = 300 s and ω_u = 2.4 rad/s), and may lie inside the interval by more
/// than the torque's rounding. A run started there in slip at `ω_l = 0` sees the disc stick
/// again at once and leave a few 1e-14 s later: a "return" of zero length, which the secant
/// method takes for a fixed point.
pub(crate) fn exit_alpha(model: &Model, alpha: f64) -> f64 {
    let (lo, hi) = model.friction(Disc::LOWER).static_interval();
    let k = model.params.k_theta;
    let x = |a: f64| State::new(a, 0.0, 0.0);
    let up = k * alpha >= 0.5 * (lo + hi);
    let mut a = if up { hi / k } else { lo / k };
    // The quotient is within an ulp or two of the edge: a few outward steps at most.
    for _ in 0..8 {
        if model.stick_exit(Disc::LOWER, &x(a), 0.0).is_some() {
            break;
        }
        a = if up { a.next_up() } else { a.next_down() };
    }
    a
}

/// The steady state reached from `x0` at input `u`, refined (see the module docs).
pub fn steady_state(
    model: &Model,
    u: f64,
    x0: State,
    opts: &SteadyOptions,
    ev: &EventOptions,
) -> Result<Steady, SolveError> {
    let flow = Flow {
        model,
        u,
        tol: opts.tol,
        ev: *ev,
    };
    // 1. Settle until the period and amplitude stop drifting (or the orbit is at rest).
    let mut run = Settling {
        flow: &flow,
        opts,
        x: x0,
        mode: model.mode_at(&x0, u),
        elapsed: 0.0,
    };
    let (rough, last_exit, _) = run.until(1e-6)?;
    if let RigSteady::Equilibrium { .. } = rough {
        return Ok(equilibrium(model, u, &run.x));
    }
    // 2. Refine; accept only a stable cycle.
    let first = match refine_cycle(&flow, &run, &rough, last_exit, opts) {
        Ok(Refined::Cycle(c)) if c.is_stable() => return Ok(c),
        Ok(Refined::Cycle(c)) => format!(
            "it converged to an unstable cycle (multipliers {})",
            list(&c.multipliers)
        ),
        Ok(Refined::Collapsed(e)) => match collapsed(model, &e) {
            Some(st) => return Ok(st),
            None => {
                let growth = model
                    .equilibrium_eigenvalues(&e)
                    .iter()
                    .map(|l| l.re)
                    .fold(f64::NEG_INFINITY, f64::max);
                format!(
                    "there is no cycle near the orbit: it circles the slipping equilibrium at \
                     omega = {:.6} rad/s, which is unstable but repels it only at Re lambda = \
                     {growth:.2e} /s (the input is next to a Hopf point)",
                    e.omega
                )
            }
        },
        Err(e) => e.to_string(),
    };
    // 3. Near a Hopf point or a fold of cycles the fixed point is ill-conditioned (a
    // multiplier near 1): Newton may fail, step out of the cycle's basin, or converge to the
    // unstable cycle nearby. The run goes on until period and amplitude are steady to 1e-10
    // from one cycle to the next, and the refinement is tried again from there.
    let (rough, last_exit, settled) = run.until(1e-10)?;
    if let RigSteady::Equilibrium { .. } = rough {
        return Ok(equilibrium(model, u, &run.x));
    }
    match refine_cycle(&flow, &run, &rough, last_exit, opts) {
        Ok(Refined::Cycle(c)) if c.is_stable() => return Ok(c),
        Ok(Refined::Collapsed(e)) => {
            if let Some(st) = collapsed(model, &e) {
                return Ok(st);
            }
        }
        _ => {}
    }
    if settled {
        return Ok(Steady {
            state: rough,
            method: Method::Settled,
            on_cycle: Some(run.x),
            multipliers: Vec::new(),
        });
    }
    Err(SolveError::NoConvergence {
        detail: format!(
            "the refinement failed ({first}) and the run still drifts after {} s",
            run.elapsed
        ),
    })
}

/// The steady state when Newton's method shrinks the orbit onto a slipping equilibrium: that
/// equilibrium if it is stable (a focus the orbit spirals into, too slowly to have settled:
/// next to a Hopf point the decay rate Re λ is proportional to the distance in u), else none.
fn collapsed(model: &Model, e: &SlipEquilibrium) -> Option<Steady> {
    model.equilibrium_is_stable(e).then(|| Steady {
        state: RigSteady::Equilibrium {
            omega_u: e.omega,
            omega_l: e.omega,
            alpha: e.alpha,
        },
        method: Method::Equilibrium,
        on_cycle: None,
        multipliers: Vec::new(),
    })
}

/// `(a+bi, …)` for messages.
fn list(m: &[Complex<f64>]) -> String {
    m.iter()
        .map(|z| {
            if z.im == 0.0 {
                format!("{:.6}", z.re)
            } else {
                format!("{:.6}{:+.6}i", z.re, z.im)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the refinement of a cycle found.
enum Refined {
    /// A fixed point of the return map (stable or not).
    Cycle(Steady),
    /// No cycle: Newton's method shrank the orbit onto this slipping equilibrium (a focus
    /// next to a Hopf point, around which the orbit decays or grows slowly).
    Collapsed(SlipEquilibrium),
}

/// The refined cycle through the settling run's orbit: the stick-exit map if the lower disc
/// sticks on it, else the section map on `ω_l = ω*` (the slipping equilibrium's velocity, if
/// it lies inside the orbit's range of ω_l, as in the bifurcation analysis) or on the middle
/// of that range.
fn refine_cycle(
    flow: &Flow,
    run: &Settling,
    rough: &RigSteady,
    last_exit: Option<(Event, DiscMode)>,
    opts: &SteadyOptions,
) -> Result<Refined, SolveError> {
    let RigSteady::LimitCycle {
        stick_time,
        omega_l_max,
        omega_l_min,
        ..
    } = *rough
    else {
        unreachable!("only cycles are refined")
    };
    match last_exit {
        Some(exit) if stick_time > 0.0 => refine_stick_slip(flow, &exit, opts).map(Refined::Cycle),
        _ => {
            let center = flow
                .model
                .slip_equilibria(flow.u)
                .into_iter()
                .find(|e| omega_l_min < e.omega && e.omega < omega_l_max);
            let c = center.map_or(0.5 * (omega_l_max + omega_l_min), |e| e.omega);
            refine_slipping(flow, (&run.x, run.mode), (c, center), opts)
        }
    }
}

fn equilibrium(model: &Model, u: f64, x: &State) -> Steady {
    Steady {
        state: refine_equilibrium(model, u, x),
        method: Method::Equilibrium,
        on_cycle: None,
        multipliers: Vec::new(),
    }
}

/// A settling run, continued chunk by chunk.
struct Settling<'a> {
    flow: &'a Flow<'a>,
    opts: &'a SteadyOptions,
    x: State,
    mode: Mode,
    elapsed: f64,
}

/// A chunk's rough steady state, its last stick exit of the lower disc, and whether the
/// run has settled.
type Rough = (RigSteady, Option<(Event, DiscMode)>, bool);

impl Settling<'_> {
    /// Runs chunks until the last cycle's period and amplitude drift by less than `drift`
    /// relative from the cycle before (or the orbit is at rest), or `max_settle` is reached.
    fn until(&mut self, drift: f64) -> Result<Rough, SolveError> {
        loop {
            let acc = MetricsAccumulator::new(0.5 * self.opts.settle);
            let f = self.flow;
            let mut integ = Integrator::rig(f.model, f.u, f.tol, f.ev);
            integ.extrema = true;
            let mut sink = LastExitSink {
                acc,
                last_exit: None,
            };
            let end = integ.run(0.0, self.x, self.mode, self.opts.settle, &mut sink)?;
            self.elapsed += self.opts.settle;
            self.x = end.x;
            self.mode = end.mode;
            let st = sink.acc.finish(&end.x);
            let d = sink
                .acc
                .period_drift()
                .unwrap_or(0.0)
                .max(sink.acc.amplitude_drift().unwrap_or(0.0));
            let settled = match st {
                RigSteady::Equilibrium { .. } => true,
                RigSteady::LimitCycle { .. } => d < drift,
            };
            if settled || self.elapsed >= self.opts.max_settle {
                return Ok((st, sink.last_exit, settled));
            }
        }
    }
}

struct LastExitSink {
    acc: MetricsAccumulator,
    last_exit: Option<(Event, DiscMode)>,
}

impl Sink<U3> for LastExitSink {
    fn event(&mut self, e: EventRef<'_>) {
        self.acc.push(e);
        if e.kind == EventKind::StickEnd(Disc::LOWER) {
            let upper = if e.x[1] == 0.0 {
                DiscMode::Stick
            } else {
                DiscMode::slip_of(e.x[1])
            };
            self.last_exit = Some((e.to_event(), upper));
        }
    }
}

fn refine_equilibrium(model: &Model, u: f64, x: &State) -> RigSteady {
    // Lower disc stuck: a unique stuck equilibrium (smooth upper disc) is exact; within a
    // stuck *set* the orbit's own resting point is the answer.
    if x[2] == 0.0
        && let Some(set) = model.stuck_equilibria(u)
        && set.alpha_min == set.alpha_max
    {
        return RigSteady::Equilibrium {
            omega_u: 0.0,
            omega_l: 0.0,
            alpha: set.alpha_min,
        };
    }
    if x[1] == 0.0 && x[2] == 0.0 {
        return RigSteady::Equilibrium {
            omega_u: 0.0,
            omega_l: 0.0,
            alpha: x[0],
        };
    }
    // One disc stuck, the other creeping onto the stuck set from outside it (α outside the
    // set violates the slipping disc's own stick condition: the stuck one's holds). Its slip
    // field `J ω̇ = T_ex(α) − T_c(ω)` with `α̇ = ±ω` comes to rest only where T_ex = T_c(0±),
    // the boundary of its stick interval, and approaches it along an overdamped slow mode
    // (e^{−k_θ t/b} for the Stribeck set's upper disc, 0.03 /s): exponentially, never in
    // finite time. The limit is that boundary, the set's end nearest α.
    if let Some(set) = model.stuck_equilibria(u)
        && (x[1] == 0.0) != (x[2] == 0.0)
    {
        let alpha_rate = x[1] - x[2];
        let limit = x[0].clamp(set.alpha_min, set.alpha_max);
        if (limit - x[0]) * alpha_rate > 0.0 {
            return RigSteady::Equilibrium {
                omega_u: 0.0,
                omega_l: 0.0,
                alpha: limit,
            };
        }
    }
    let best = model
        .slip_equilibria(u)
        .into_iter()
        .min_by(|a, b| (a.state() - x).norm().total_cmp(&(b.state() - x).norm()));
    match best {
        Some(e) => RigSteady::Equilibrium {
            omega_u: e.omega,
            omega_l: e.omega,
            alpha: e.alpha,
        },
        None => RigSteady::Equilibrium {
            omega_u: x[1],
            omega_l: x[2],
            alpha: x[0],
        },
    }
}

fn refine_stick_slip(
    flow: &Flow,
    exit: &(Event, DiscMode),
    opts: &SteadyOptions,
) -> Result<Steady, SolveError> {
    let (e, upper) = (&exit.0, exit.1);
    let alpha = exit_alpha(flow.model, e.x[0]);
    let mut w = e.x[1];
    let mut upper_mode = upper;
    if upper != DiscMode::Stick {
        // Secant on F(w) = P(w) − w.
        let p0 = flow.stick_exit_map(alpha, w, upper)?;
        let mut w0 = w;
        let mut f0 = p0.x[1] - w0;
        let mut w1 = p0.x[1];
        let mut converged = f0.abs() <= opts.fixed_point_tol;
        for _ in 0..30 {
            if converged {
                break;
            }
            let p1 = flow.stick_exit_map(alpha, w1, upper)?;
            let f1 = p1.x[1] - w1;
            if f1.abs() <= opts.fixed_point_tol {
                w0 = w1;
                converged = true;
                break;
            }
            let w2 = if f1 != f0 {
                w1 - f1 * (w1 - w0) / (f1 - f0)
            } else {
                p1.x[1]
            };
            w0 = w1;
            f0 = f1;
            w1 = w2;
        }
        if !converged {
            return Err(SolveError::NoConvergence {
                detail: format!("stick-exit return map: residual {f0:e} after 30 secant steps"),
            });
        }
        w = w0;
        upper_mode = DiscMode::slip_of(w);
    }
    // The multiplier: P'(w*) by central differences (the map is smooth in w); with the upper
    // disc stuck at the exit the map is 0-dimensional, every orbit leaves from the same
    // state, and the multiplier is 0.
    let multiplier = if upper_mode == DiscMode::Stick {
        0.0
    } else {
        let h = 1e-6 * w.abs().max(1.0);
        let hi = flow.stick_exit_map(alpha, w + h, upper_mode)?;
        let lo = flow.stick_exit_map(alpha, w - h, upper_mode)?;
        (hi.x[1] - lo.x[1]) / (2.0 * h)
    };
    // One period from the fixed point, with extrema, into a fresh accumulator.
    let (x, mode) = flow.exit_state(alpha, w, upper_mode);
    let mut acc = MetricsAccumulator::new(0.0);
    acc.push(&Event::new(
        0.0,
        x.as_slice(),
        EventKind::StickEnd(Disc::LOWER),
    ));
    let (end, sink) = flow.run(x, mode, 1e4, Stop::LowerStickExit, true, None, Some(acc))?;
    Ok(Steady {
        state: sink.acc.expect("accumulator was given").finish(&end.x),
        method: Method::Refined,
        on_cycle: Some(x),
        multipliers: vec![Complex::new(multiplier, 0.0)],
    })
}

fn refine_slipping(
    flow: &Flow,
    (x, mode): (&State, Mode),
    (c, center): (f64, Option<SlipEquilibrium>),
    opts: &SteadyOptions,
) -> Result<Refined, SolveError> {
    // The start: where the settled orbit itself next crosses the section (not the state's
    // (α, ω_u) moved onto the section: near a fold of cycles that point can lie beyond the
    // unstable cycle, and Newton converges to it).
    let (end, _) = flow.run(*x, mode, 1e4, Stop::Section, false, Some(c), None)?;
    if end.t >= 1e4 {
        return Err(SolveError::NoConvergence {
            detail: format!("the orbit does not reach the section omega_l = {c}"),
        });
    }
    let mut z = [end.x[0], end.x[1]];
    let mut converged = false;
    for _ in 0..40 {
        let p = flow.section_map(z, c)?;
        let r = [p[0] - z[0], p[1] - z[1]];
        // Forward-difference Jacobian of P − I (step 1e-6 relative: the map is smooth).
        let mut j = [[0.0; 2]; 2];
        for k in 0..2 {
            let dz = 1e-6 * z[k].abs().max(1.0);
            let mut zk = z;
            zk[k] += dz;
            let pk = flow.section_map(zk, c)?;
            for i in 0..2 {
                j[i][k] = (pk[i] - p[i]) / dz - if i == k { 1.0 } else { 0.0 };
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let d = [
            (-r[0] * j[1][1] + r[1] * j[0][1]) / det,
            (-r[1] * j[0][0] + r[0] * j[1][0]) / det,
        ];
        let next = [z[0] + d[0], z[1] + d[1]];
        let tol_step = opts.fixed_point_step * (1.0 + z[0].abs().max(z[1].abs()));
        // No cycle around a focus: Newton shrinks the orbit onto the equilibrium. A "cycle"
        // within 100 steps' tolerance of it is that collapse, not a cycle it can resolve.
        if let Some(e) = center
            && (next[0] - e.alpha).abs().max((next[1] - e.omega).abs()) <= 100.0 * tol_step
        {
            return Ok(Refined::Collapsed(e));
        }
        // Where the map is nearly the identity (a multiplier near 1: next to a Hopf point) a
        // small residual does not mean a nearby fixed point: the Newton step says how far it
        // is. Converged when both the residual and the step are small.
        if r[0].abs().max(r[1].abs()) <= opts.fixed_point_tol
            && d[0].abs().max(d[1].abs()) <= tol_step
        {
            converged = true;
            z = next;
            break;
        }
        z = next;
    }
    if !converged {
        return Err(SolveError::NoConvergence {
            detail: "slipping cycle: Poincare-section Newton did not converge".into(),
        });
    }
    // One period from the fixed point with extrema; anchors are the ω_l maxima, so run two
    // section returns and read the last complete maximum-to-maximum cycle.
    let x0 = State::new(z[0], z[1], c);
    let mode = flow.model.mode_at(&x0, flow.u);
    let acc = MetricsAccumulator::new(0.0);
    let mut integ = Integrator::rig(flow.model, flow.u, flow.tol, flow.ev);
    integ.extrema = true;
    integ.section = Some(c);
    let mut sink = CountSections {
        acc,
        sections: 0,
        stop_at: 2,
    };
    let end = integ.run(0.0, x0, mode, 1e4, &mut sink)?;
    Ok(Refined::Cycle(Steady {
        state: sink.acc.finish(&end.x),
        method: Method::Refined,
        on_cycle: Some(x0),
        multipliers: section_multipliers(flow, z, c)?.to_vec(),
    }))
}

/// Eigenvalues of `DP(z)` of the section map, `DP` by central differences (step 1e-6
/// relative: the map is smooth on a slipping cycle).
fn section_multipliers(flow: &Flow, z: [f64; 2], c: f64) -> Result<[Complex<f64>; 2], SolveError> {
    let mut j = [[0.0; 2]; 2];
    for k in 0..2 {
        let dz = 1e-6 * z[k].abs().max(1.0);
        let (mut zp, mut zm) = (z, z);
        zp[k] += dz;
        zm[k] -= dz;
        let (pp, pm) = (flow.section_map(zp, c)?, flow.section_map(zm, c)?);
        for i in 0..2 {
            j[i][k] = (pp[i] - pm[i]) / (2.0 * dz);
        }
    }
    // λ = tr/2 ± √(tr²/4 − det).
    let tr = j[0][0] + j[1][1];
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let root = Complex::new(0.25 * tr * tr - det, 0.0).sqrt();
    let half = Complex::new(0.5 * tr, 0.0);
    Ok([half + root, half - root])
}

struct CountSections {
    acc: MetricsAccumulator,
    sections: u32,
    stop_at: u32,
}

impl Sink<U3> for CountSections {
    fn event(&mut self, e: EventRef<'_>) {
        self.acc.push(e);
    }
    fn section(&mut self, _t: f64, _x: &State) -> bool {
        self.sections += 1;
        self.sections >= self.stop_at
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stribeck() -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/params/stribeck.toml");
        Model::new(rotor_model::Params::from_file(&path).unwrap())
    }

    /// A located exit 250 ulps inside the interval (as at t ≈ 300 s) and one as far outside
    /// both start on the edge, where the model's stick test says the disc leaves, within a
    /// few ulps of `T_hi/k_θ`; a downward exit starts on the lower edge.
    #[test]
    fn an_exit_starts_on_the_edge_of_the_stick_interval() {
        let m = stribeck();
        let (lo, hi) = m.friction(Disc::LOWER).static_interval();
        let k = m.params.k_theta;
        let edge = hi / k;
        let ulp = edge.next_up() - edge;
        for located in [edge - 250.0 * ulp, edge + 250.0 * ulp] {
            let a = exit_alpha(&m, located);
            let x = State::new(a, 0.0, 0.0);
            assert_eq!(m.stick_exit(Disc::LOWER, &x, 0.0), Some(DiscMode::SlipPos));
            assert!((a - edge).abs() <= 4.0 * ulp, "{a} vs {edge}");
        }
        let a = exit_alpha(&m, lo / k + 1e-13);
        let x = State::new(a, 0.0, 0.0);
        assert_eq!(m.stick_exit(Disc::LOWER, &x, 0.0), Some(DiscMode::SlipNeg));
    }

    /// The Stribeck set at 1.5 V from rest: a stick-slip cycle whose period is the one a
    /// plain run of the same solver shows between its last two stick exits. The refinement
    /// once started its return map inside the stick interval and answered an "equilibrium"
    /// on the stick boundary with ω_u = 2.43 rad/s.
    #[test]
    fn the_stribeck_stick_slip_cycle_is_refined_as_a_cycle() {
        let m = stribeck();
        let st = steady_state(
            &m,
            1.5,
            State::zeros(),
            &SteadyOptions::default(),
            &EventOptions::default(),
        )
        .unwrap();
        let RigSteady::LimitCycle { period, .. } = st.state else {
            panic!("{:?}", st.state)
        };
        let run = crate::flow::flow(
            &m,
            1.5,
            1e-12,
            State::zeros(),
            m.mode_at(&State::zeros(), 1.5),
            300.0,
            crate::flow::StopAt::Time,
        )
        .unwrap();
        let exits: Vec<f64> = run
            .events
            .iter()
            .filter(|e| e.kind == EventKind::StickEnd(Disc::LOWER))
            .map(|e| e.t)
            .collect();
        let plain = exits[exits.len() - 1] - exits[exits.len() - 2];
        // Both at tol 1e-12 on a cycle that attracts at multiplier 3e-8 per period: they
        // agree to the event times' accuracy, far below 1e-8 s.
        assert!((period - plain).abs() < 1e-8, "{period} vs {plain}");
    }
}
