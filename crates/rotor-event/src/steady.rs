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

use rotor_model::{
    Disc, DiscMode, Event, EventKind, MetricsAccumulator, Mode, Model, SolveError, State,
    SteadyState,
};

use crate::filippov::{EventOptions, Integrator, RunEnd, Sink};

/// Options of the steady-state refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Integration tolerance.
    pub tol: f64,
    /// Length of one settling chunk [s]; metrics are read over its second half.
    pub settle: f64,
    /// Longest total settling time [s] (a focus with Re λ = −1e-3 /s near a Hopf point
    /// decays by e^-20 in 20 000 s).
    pub max_settle: f64,
    /// Newton/secant stopping tolerance on the fixed-point residual (rad/s).
    pub fixed_point_tol: f64,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        SteadyOptions {
            tol: 1e-12,
            settle: 300.0,
            max_settle: 20_000.0,
            fixed_point_tol: 1e-11,
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

impl Sink for StopSink {
    fn event(&mut self, e: &Event) {
        if e.kind == EventKind::StickEnd(Disc::Lower) {
            self.lower_exits += 1;
        }
        if let Some(a) = self.acc.as_mut() {
            a.push(e);
        }
    }
    fn stop_after(&mut self, e: &Event) -> bool {
        self.stop == Stop::LowerStickExit && e.kind == EventKind::StickEnd(Disc::Lower)
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
    ) -> Result<(RunEnd, StopSink), SolveError> {
        let mut integ = Integrator::new(self.model, self.u, self.tol, self.ev);
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
    fn exit_state(&self, alpha: f64, w: f64, upper: DiscMode) -> (State, Mode) {
        let x = State::new(alpha, if upper == DiscMode::Stick { 0.0 } else { w }, 0.0);
        let lower = DiscMode::slip_of(self.model.applied_torque(Disc::Lower, &x, self.u));
        (x, Mode { upper, lower })
    }

    /// Return map at the lower disc's stick exit: ω_u at the next exit (and the mode there).
    fn stick_exit_map(&self, alpha: f64, w: f64, upper: DiscMode) -> Result<RunEnd, SolveError> {
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

/// The steady state reached from `x0` at input `u`, refined (see the module docs).
pub fn steady_state(
    model: &Model,
    u: f64,
    x0: State,
    opts: &SteadyOptions,
    ev: &EventOptions,
) -> Result<SteadyState, SolveError> {
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
    let (rough, last_exit, settled) = run.until(1e-6)?;
    let x = run.x;
    match rough {
        SteadyState::Equilibrium { .. } => Ok(refine_equilibrium(model, u, &x)),
        SteadyState::LimitCycle {
            stick_time,
            omega_l_max,
            omega_l_min,
            ..
        } => {
            let refined = if let (Some(exit), true) = (last_exit, stick_time > 0.0) {
                refine_stick_slip(&flow, &exit, opts)
            } else {
                refine_slipping(&flow, &x, 0.5 * (omega_l_max + omega_l_min), opts)
            };
            match refined {
                Ok(st) => Ok(st),
                // Near a Hopf point or a fold of cycles the section map's fixed point is
                // ill-conditioned (a multiplier near 1) and Newton may fail, or step out of
                // the cycle's basin in a bistable window. A run that has settled still
                // answers: it goes on until period and amplitude are steady to 1e-10 from one
                // cycle to the next, and the metrics of its last cycle are the answer.
                Err(_) if settled => match run.until(1e-10)? {
                    (st, _, true) => Ok(st),
                    (_, _, false) => Err(SolveError::NoConvergence {
                        detail: format!(
                            "the refinement failed and the run still drifts after {} s",
                            run.elapsed
                        ),
                    }),
                },
                Err(e) => Err(SolveError::NoConvergence {
                    detail: format!(
                        "not settled after {} s (period or amplitude still drifting), and the \
                         refinement failed: {e}",
                        run.elapsed
                    ),
                }),
            }
        }
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
type Rough = (SteadyState, Option<(Event, DiscMode)>, bool);

impl Settling<'_> {
    /// Runs chunks until the last cycle's period and amplitude drift by less than `drift`
    /// relative from the cycle before (or the orbit is at rest), or `max_settle` is reached.
    fn until(&mut self, drift: f64) -> Result<Rough, SolveError> {
        loop {
            let acc = MetricsAccumulator::new(0.5 * self.opts.settle);
            let f = self.flow;
            let mut integ = Integrator::new(f.model, f.u, f.tol, f.ev);
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
                SteadyState::Equilibrium { .. } => true,
                SteadyState::LimitCycle { .. } => d < drift,
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

impl Sink for LastExitSink {
    fn event(&mut self, e: &Event) {
        self.acc.push(e);
        if e.kind == EventKind::StickEnd(Disc::Lower) {
            let upper = if e.x[1] == 0.0 {
                DiscMode::Stick
            } else {
                DiscMode::slip_of(e.x[1])
            };
            self.last_exit = Some((*e, upper));
        }
    }
}

fn refine_equilibrium(model: &Model, u: f64, x: &State) -> SteadyState {
    // Lower disc stuck: a unique stuck equilibrium (smooth upper disc) is exact; within a
    // stuck *set* the orbit's own resting point is the answer.
    if x[2] == 0.0
        && let Some(set) = model.stuck_equilibria(u)
        && set.alpha_min == set.alpha_max
    {
        return SteadyState::Equilibrium {
            omega_u: 0.0,
            omega_l: 0.0,
            alpha: set.alpha_min,
        };
    }
    if x[1] == 0.0 && x[2] == 0.0 {
        return SteadyState::Equilibrium {
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
            return SteadyState::Equilibrium {
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
        Some(e) => SteadyState::Equilibrium {
            omega_u: e.omega,
            omega_l: e.omega,
            alpha: e.alpha,
        },
        None => SteadyState::Equilibrium {
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
) -> Result<SteadyState, SolveError> {
    let (e, upper) = *exit;
    let alpha = e.x[0];
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
    // One period from the fixed point, with extrema, into a fresh accumulator.
    let (x, mode) = flow.exit_state(alpha, w, upper_mode);
    let mut acc = MetricsAccumulator::new(0.0);
    acc.push(&Event {
        t: 0.0,
        x,
        kind: EventKind::StickEnd(Disc::Lower),
    });
    let (end, sink) = flow.run(x, mode, 1e4, Stop::LowerStickExit, true, None, Some(acc))?;
    Ok(sink.acc.expect("accumulator was given").finish(&end.x))
}

fn refine_slipping(
    flow: &Flow,
    x: &State,
    c: f64,
    opts: &SteadyOptions,
) -> Result<SteadyState, SolveError> {
    // A point on the section near the settled orbit.
    let start = flow.section_map([x[0], x[1]], c).or_else(|_| {
        let mode = flow.model.mode_at(x, flow.u);
        let (end, _) = flow.run(*x, mode, 1e4, Stop::Section, false, Some(c), None)?;
        Ok::<_, SolveError>([end.x[0], end.x[1]])
    })?;
    let mut z = start;
    let mut converged = false;
    for _ in 0..30 {
        let p = flow.section_map(z, c)?;
        let r = [p[0] - z[0], p[1] - z[1]];
        if r[0].abs().max(r[1].abs()) <= opts.fixed_point_tol {
            converged = true;
            break;
        }
        // Finite-difference Jacobian of P − I (step √tol-scaled: the map is smooth).
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
        let d0 = (-r[0] * j[1][1] + r[1] * j[0][1]) / det;
        let d1 = (-r[1] * j[0][0] + r[0] * j[1][0]) / det;
        z = [z[0] + d0, z[1] + d1];
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
    let mut integ = Integrator::new(flow.model, flow.u, flow.tol, flow.ev);
    integ.extrema = true;
    integ.section = Some(c);
    let mut sink = CountSections {
        acc,
        sections: 0,
        stop_at: 2,
    };
    let end = integ.run(0.0, x0, mode, 1e4, &mut sink)?;
    Ok(sink.acc.finish(&end.x))
}

struct CountSections {
    acc: MetricsAccumulator,
    sections: u32,
    stop_at: u32,
}

impl Sink for CountSections {
    fn event(&mut self, e: &Event) {
        self.acc.push(e);
    }
    fn section(&mut self, _t: f64, _x: &State) -> bool {
        self.sections += 1;
        self.sections >= self.stop_at
    }
}
