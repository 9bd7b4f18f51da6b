//! The steady state of a plain simulation, read off only once it has settled.
//!
//! A solver without a return-map refinement (the switch model, Moreau–Jean) finds its steady
//! state by simulating: chunks of `chunk` seconds, each continuing from the previous one's
//! final state, with the metrics of each chunk's last complete cycle (its second half). The
//! run has settled when consecutive chunks give the same kind and the metrics' change, with
//! what is still to come if it falls geometrically, is within `rel` (relative, with `abs` as
//! a floor). A slow transient — a focus that decays over thousands of seconds near a Hopf
//! point — is followed until it has decayed, or reported as not settled at `max_time`,
//! instead of as a limit cycle.

use rotor_model::seam::{Output, RigSteady, Scene, SolveError, Stats};
use rotor_model::{Model, State};

use crate::solvers::registry::SolverKind;

/// Options of [`settle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SettleOptions {
    /// Length of one chunk \[s\]; its metrics are read over its second half.
    pub chunk: f64,
    /// Longest total simulated time \[s\].
    pub max_time: f64,
    /// Agreement of two consecutive chunks' metrics, relative.
    pub rel: f64,
    /// For Moreau–Jean the agreement is `max(rel, rel_per_h · h)`: its cycle-to-cycle jitter
    /// grows with the step.
    pub rel_per_h: f64,
    /// Absolute floor of that agreement [s or rad/s] (for metrics that are ~0).
    pub abs: f64,
}

impl Default for SettleOptions {
    fn default() -> Self {
        SettleOptions {
            // 300 s: more than 60 periods of the source's cycles (T ≈ 4–5 s).
            chunk: 300.0,
            // A focus with Re λ = −1e-3 /s decays by e^-20 in 20 000 s; slower ones are
            // reported as not settled. Moreau–Jean at h = 1e-3 takes ~3 s for this.
            max_time: 20_000.0,
            // Consecutive chunks of a settled orbit agree to the solver's own noise. Measured
            // at 0.3, 0.5, 1.5, 2.5, 4.5 and 6 V: ≤ 4e-12 relative for the switch model (tol
            // 1e-10), ≤ 2.5e-7 for Moreau–Jean at h = 1e-3 and ≤ 7e-6 at h = 1e-2 (its stick
            // exits fall between steps differently from cycle to cycle). 1e-5, and 1e-2·h for
            // Moreau–Jean: 40x and 14x its measured jitter at h = 1e-3 and 1e-2.
            rel: 1e-5,
            rel_per_h: 1e-2,
            abs: 1e-8,
        }
    }
}

/// Why a run did not give a steady state.
#[derive(Debug, thiserror::Error)]
pub enum SettleError {
    /// The solver failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The metrics still changed between the last two chunks at `max_time`.
    #[error(
        "not settled after {t} s: {what} still changes by {change:e} (relative) from one {chunk} s \
         chunk to the next; {cause}"
    )]
    NotSettled {
        /// Simulated time reached \[s\].
        t: f64,
        /// Length of a chunk \[s\] ([`SettleOptions::chunk`]).
        chunk: f64,
        /// The metric that changed most between the last two chunks (`the period`,
        /// `the omega_l amplitude`, ...).
        what: String,
        /// Its relative change between them.
        change: f64,
        /// Why it still changes, as far as the chunks tell.
        cause: Unsettled,
    },
}

/// Why a run did not settle, as far as its last two chunks tell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unsettled {
    /// A transient that decays or grows slowly: a focus next to a Hopf point, an orbit
    /// passing a fold of cycles.
    SlowTransient,
    /// A change that falls geometrically, by `per_chunk` per chunk, too slowly to settle
    /// before `max_time`: it would at about `needs` seconds.
    SlowDecay {
        /// The ratio of the last change to the one before it (< 1).
        per_chunk: f64,
        /// Simulated time \[s\] at which the change would fall within the agreement.
        needs: f64,
        /// The limit it exceeds, [`SettleOptions::max_time`] \[s\].
        max_time: f64,
    },
    /// An oscillation growing geometrically, by `per_chunk` per chunk, from a weakly
    /// unstable equilibrium: it would leave the equilibrium's neighbourhood (1 % of the mean
    /// velocity) only at about `needs` seconds.
    SlowGrowth {
        /// The ratio of the last ω_l amplitude to the one before it (> 1).
        per_chunk: f64,
        /// Simulated time \[s\] at which the amplitude would reach 1 % of the mean velocity.
        needs: f64,
        /// The limit it exceeds, [`SettleOptions::max_time`] \[s\].
        max_time: f64,
    },
    /// A fixed-step solver on a cycle that grazes ω_l = 0: its stick phase (`stick_time` per
    /// period, 0 if it only touches) is shorter than 10 steps of `h`, so whether and how long
    /// the disc sticks changes from period to period with where the steps fall.
    GrazingBelowStep {
        /// The last chunk's stick time per period \[s\].
        stick_time: f64,
        /// The solver's step \[s\].
        h: f64,
    },
}

impl std::fmt::Display for Unsettled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Unsettled::SlowTransient => f.write_str(
                "a slow transient (e.g. a focus near a Hopf point, or a passage near a fold of \
                 cycles), not a steady state",
            ),
            Unsettled::SlowDecay {
                per_chunk,
                needs,
                max_time,
            } => write!(
                f,
                "the change falls geometrically, by a factor {per_chunk:.4} per chunk, and at that \
                 rate the run would settle after about {needs:.1e} s, beyond the {max_time} s \
                 limit: a slowly decaying transient (e.g. a focus or cycle with a multiplier near \
                 1, next to a Hopf point or a fold), not yet a steady state"
            ),
            Unsettled::SlowGrowth {
                per_chunk,
                needs,
                max_time,
            } => write!(
                f,
                "the orbit leaves a weakly unstable equilibrium, its amplitude growing by a factor \
                 {per_chunk:.4} per chunk: it would reach 1 % of its mean velocity only after \
                 about {needs:.1e} s, beyond the {max_time} s limit (the input is next to a Hopf \
                 point)"
            ),
            Unsettled::GrazingBelowStep { stick_time, h } if stick_time > 0.0 => write!(
                f,
                "the cycle grazes omega_l = 0 with a stick phase of {stick_time:.2e} s per \
                 period, shorter than 10 steps of h = {h} s, so where the steps fall changes it \
                 from period to period: use h of a tenth of the stick phase or less, or the \
                 event-driven solver (exact sliding)"
            ),
            Unsettled::GrazingBelowStep { h, .. } => write!(
                f,
                "the cycle grazes omega_l = 0 (its minimum is within 1e-3 of its range from 0), \
                 and whether a step of h = {h} s lands the disc in stick changes from period to \
                 period: use a smaller h, or the event-driven solver (exact sliding)"
            ),
        }
    }
}

/// The cause of a run that has not settled, from its last chunk's metrics.
fn unsettled(fixed_step: bool, h: f64, last: &RigSteady) -> Unsettled {
    if let RigSteady::LimitCycle {
        omega_l_max,
        omega_l_min,
        stick_time,
        ..
    } = *last
    {
        // Touching: a stick phase under 10 steps, or a minimum of ω_l within 1e-3 of the
        // cycle's range from 0 (a step changes ω_l near its minimum by ~ω̈h²/2, 2e-5 rad/s
        // at h = 1e-3 on Table 1's cycles: a grazing minimum is not resolved below that).
        let touching =
            stick_time < 10.0 * h && omega_l_min.abs() <= 1e-3 * (omega_l_max - omega_l_min).abs();
        if fixed_step && touching {
            return Unsettled::GrazingBelowStep { stick_time, h };
        }
    }
    Unsettled::SlowTransient
}

/// The largest relative change between two steady states' metrics, and its name (an
/// infinite change when the kinds differ).
fn change(a: &RigSteady, b: &RigSteady, abs: f64) -> (String, f64) {
    if a.kind() != b.kind() {
        return (
            format!("the kind ({} then {})", a.kind(), b.kind()),
            f64::INFINITY,
        );
    }
    let mut worst = a
        .values()
        .into_iter()
        .zip(b.values())
        .map(|((name, va), (_, vb))| {
            let scale = va.abs().max(vb.abs()).max(abs);
            (name.to_string(), (va - vb).abs() / scale)
        })
        .fold(
            (String::new(), 0.0),
            |acc, x| if x.1 > acc.1 { x } else { acc },
        );
    // A cycle's amplitude relative to itself: a focus decaying near a Hopf point keeps its
    // mean velocity and period while its amplitude shrinks by a fixed factor per chunk.
    if let (
        RigSteady::LimitCycle {
            omega_l_max: a1,
            omega_l_min: a0,
            ..
        },
        RigSteady::LimitCycle {
            omega_l_max: b1,
            omega_l_min: b0,
            ..
        },
    ) = (a, b)
    {
        let (ra, rb) = (a1 - a0, b1 - b0);
        let c = (ra - rb).abs() / ra.abs().max(rb.abs()).max(abs);
        if c > worst.1 {
            worst = ("the omega_l amplitude".into(), c);
        }
    }
    worst
}

/// A settled steady state and the summed counters of its chunks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settled {
    /// The metrics of the last chunk's last complete cycle (or its final state, at rest).
    pub state: RigSteady,
    /// The work counters of all chunks, summed.
    pub stats: Stats,
    /// The last chunk's final state (on the cycle, for a cycle).
    pub x: State,
}

/// Simulates `base` (its `t_end`, `output` and `metrics_from` are replaced) in chunks until
/// its metrics settle; see the module docs.
pub fn settle(
    kind: SolverKind,
    model: &Model,
    base: &Scene,
    opts: &SettleOptions,
) -> Result<Settled, SettleError> {
    let solver = kind.solver();
    let rel = if kind.is_fixed_step() {
        opts.rel.max(opts.rel_per_h * base.step())
    } else {
        opts.rel
    };
    let mut x = base.x0_state()?;
    let mut t = 0.0;
    let mut stats = Stats::default();
    let mut prev: Option<RigSteady> = None;
    let mut history = History::new(rel, opts);
    loop {
        let scene = Scene {
            x0: x.as_slice().to_vec(),
            t_end: opts.chunk,
            output: Output::Final,
            metrics_from: Some(0.5 * opts.chunk),
            ..base.clone()
        };
        let tr = solver.simulate_finite(model, &scene)?;
        t += opts.chunk;
        stats += tr.stats;
        let st = tr.rig_metrics().ok_or(SolveError::Unsupported {
            detail: format!("{} returned no metrics", kind.name()),
        })?;
        if let Some(p) = prev {
            let (what, c) = change(&p, &st, opts.abs);
            let cause = unsettled(kind.is_fixed_step(), base.step(), &st);
            match history.judge(c, &st, t, cause) {
                Verdict::Settled => {
                    return Ok(Settled {
                        state: st,
                        stats,
                        x: tr.final_state()?,
                    });
                }
                Verdict::Running => {}
                Verdict::Unsettled(cause) => {
                    return Err(SettleError::NotSettled {
                        t,
                        chunk: opts.chunk,
                        what,
                        change: c,
                        cause,
                    });
                }
            }
        }
        prev = Some(st);
        x = tr.final_state()?;
    }
}

/// What a chunk's change says of the run.
enum Verdict {
    /// Settled: the chunk's metrics are the steady state.
    Settled,
    /// Not settled yet: simulate another chunk.
    Running,
    /// It will not settle within `max_time`, for this reason.
    Unsettled(Unsettled),
}

/// The changes of a run's metrics from chunk to chunk so far, which tell whether it has
/// settled, or when it would.
struct History {
    /// The agreement that counts as settled (relative).
    rel: f64,
    /// The run's options.
    opts: SettleOptions,
    /// The previous chunk's change (∞ before the second chunk).
    prev_change: f64,
    /// The last three ratios of consecutive changes, q.
    qs: [f64; 3],
    /// The last three ratios of consecutive ω_l ranges, r.
    rs: [f64; 3],
    /// The previous chunk's ω_l range (NaN at an equilibrium).
    prev_range: f64,
    /// Every chunk's change, for the jitter test.
    changes: Vec<f64>,
}

/// The ω_l range `max ω_l − min ω_l` of a cycle (NaN at an equilibrium).
fn omega_l_range(st: &RigSteady) -> f64 {
    match *st {
        RigSteady::LimitCycle {
            omega_l_max,
            omega_l_min,
            ..
        } => omega_l_max - omega_l_min,
        RigSteady::Equilibrium { .. } => f64::NAN,
    }
}

/// Whether the last three ratios `v` are one steady ratio `x = v[2]` a run can be
/// extrapolated by: `0 < x ≤ 0.99` and each within `0.1·(1 − x)` of it. A ratio above 0.99 is
/// a plateau rather than a decay that can be extrapolated (the passage near a fold's ghost
/// changes by a nearly constant amount).
fn steady_ratio(v: &[f64; 3]) -> bool {
    let x = v[2];
    x > 0.0 && x <= 0.99 && v.iter().all(|y| (y - x).abs() <= 0.1 * (1.0 - x))
}

impl History {
    /// No chunk compared yet, for a run settling to within `rel`.
    fn new(rel: f64, opts: &SettleOptions) -> Self {
        History {
            rel,
            opts: *opts,
            prev_change: f64::INFINITY,
            qs: [f64::NAN; 3],
            rs: [f64::NAN; 3],
            prev_range: f64::NAN,
            changes: Vec::new(),
        }
    }

    /// Records the change `c` of the chunk ending at `t` with metrics `st`, and judges the run:
    /// settled, running, or not settling ([`Self::slow_growth`], [`Self::slow_decay`], or
    /// `cause` once the run jitters or reaches `max_time`).
    fn judge(&mut self, c: f64, st: &RigSteady, t: f64, cause: Unsettled) -> Verdict {
        // Changes falling geometrically by q per chunk leave c·q/(1 − q) still to come:
        // settled when all of it is within `rel`. Changes that do not fall are the
        // solver's cycle-to-cycle jitter: settled when within `rel`.
        let q = c / self.prev_change;
        let settled = if q < 1.0 {
            c / (1.0 - q) <= self.rel
        } else {
            c <= self.rel
        };
        self.prev_change = c;
        if settled {
            return Verdict::Settled;
        }
        let range = omega_l_range(st);
        self.qs = [self.qs[1], self.qs[2], q];
        self.rs = [self.rs[1], self.rs[2], range / self.prev_range];
        self.prev_range = range;
        if let Some(why) = self.slow_growth(st, t).or_else(|| self.slow_decay(c, t)) {
            return Verdict::Unsettled(why);
        }
        // A fixed-step solver on a grazing cycle jitters from period to period with where
        // its steps fall: a change that has not halved over the last five chunks (ten
        // chunks into the run) will not fall below `rel` later either.
        self.changes.push(c);
        let n = self.changes.len();
        let jitter = matches!(cause, Unsettled::GrazingBelowStep { .. })
            && n >= 10
            && c >= 0.5 * self.changes[n - 6];
        if jitter || t >= self.opts.max_time {
            Verdict::Unsettled(cause)
        } else {
            Verdict::Running
        }
    }

    /// An amplitude growing geometrically, by `r ≥ 1.01` per chunk (the last three ratios
    /// within `0.1·(r − 1)` of it), while still below 1 % of the mean velocity `ω̄`: the orbit
    /// is leaving a weakly unstable equilibrium, and cannot settle before its amplitude `a`
    /// has grown to that 1 %, after `n = ln(0.01·ω̄/a) / ln r` chunks. Said now if that is
    /// past `max_time` (at the run's time `t`).
    fn slow_growth(&self, st: &RigSteady, t: f64) -> Option<Unsettled> {
        let (r, rs, range, opts) = (self.rs[2], &self.rs, self.prev_range, &self.opts);
        let growing = r >= 1.01
            && rs.iter().all(|y| (y - r).abs() <= 0.1 * (r - 1.0))
            && if let RigSteady::LimitCycle {
                omega_l_max,
                omega_l_min,
                ..
            } = *st
            {
                range < 0.01 * (0.5 * (omega_l_max + omega_l_min)).abs().max(1.0)
            } else {
                false
            };
        if !growing {
            return None;
        }
        let mean = match *st {
            RigSteady::LimitCycle {
                omega_l_max,
                omega_l_min,
                ..
            } => (0.5 * (omega_l_max + omega_l_min)).abs().max(1.0),
            RigSteady::Equilibrium { .. } => 1.0,
        };
        let n = (0.01 * mean / range).ln() / r.ln();
        (t + n * opts.chunk > opts.max_time).then_some(Unsettled::SlowGrowth {
            per_chunk: r,
            needs: t + n * opts.chunk,
            max_time: opts.max_time,
        })
    }

    /// A decay that settles only past `max_time` (at the run's time `t`, last change `c`).
    /// A change falling geometrically (three consecutive ratios q ≤ 0.99 within 10 % of
    /// 1 − q of each other) settles after n more chunks, `c·qⁿ/(1 − q) = rel`. An amplitude
    /// falling geometrically, by r per chunk (a focus decaying), changes by the same fraction
    /// 1 − r every chunk relative to itself; the run settles once it is below the amplitude
    /// that reads as an equilibrium, after `ln(a_eq/a)/ln r` chunks and two more to confirm.
    /// If either is past `max_time`, it is said now rather than after simulating up to it.
    /// (Three ratios, not two: a passage near the ghost of a fold slows down and then speeds
    /// up again.)
    fn slow_decay(&self, c: f64, t: f64) -> Option<Unsettled> {
        let (q, r, range, opts) = (self.qs[2], self.rs[2], self.prev_range, &self.opts);
        let projection = if steady_ratio(&self.qs) {
            Some((q, ((self.rel * (1.0 - q) / c).ln() / q.ln()).ceil()))
        } else if steady_ratio(&self.rs) {
            let a_eq = rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE;
            Some((r, (a_eq / range).ln() / r.ln() + 2.0))
        } else {
            None
        };
        let (q, n) = projection?;
        let needs = t + n * opts.chunk;
        (needs > opts.max_time).then_some(Unsettled::SlowDecay {
            per_chunk: q,
            needs,
            max_time: opts.max_time,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::{Model, State};

    fn base(u: f64) -> Scene {
        Scene {
            u,
            ..Scene::default()
        }
    }

    /// The event-driven solver's refined steady state from rest.
    fn event_steady(m: &Model, u: f64) -> RigSteady {
        rotor_event::steady_state(
            m,
            u,
            State::zeros(),
            &rotor_event::SteadyOptions::default(),
            &rotor_event::EventOptions::default(),
        )
        .unwrap()
        .state
    }

    /// Just below the first Hopf point (0.3835 V, Table 1) the equilibrium is a stable focus
    /// decaying at Re λ ≈ −1.7e-3 /s: a 600 s run still oscillates and reads as a limit
    /// cycle (what `rotor steady` reported for switch and Moreau–Jean); settling follows the
    /// decay to the equilibrium of the equilibrium equations.
    #[test]
    fn a_slowly_decaying_focus_settles_to_its_equilibrium() {
        let m = Model::table1();
        let u = 0.383;
        let eq = m
            .slip_equilibria(u)
            .into_iter()
            .find(|e| m.equilibrium_is_stable(e))
            .expect("a stable slipping equilibrium below the Hopf point");
        let one_run = SolverKind::SWITCH
            .solver()
            .simulate(
                &m,
                &Scene {
                    t_end: 600.0,
                    output: Output::Final,
                    metrics_from: Some(300.0),
                    ..base(u)
                },
            )
            .unwrap();
        assert_eq!(
            one_run.rig_metrics().unwrap().kind(),
            rotor_model::seam::SteadyKind::LimitCycle
        );
        for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
            let s = settle(kind, &m, &base(u), &SettleOptions::default()).unwrap();
            let RigSteady::Equilibrium { omega_l, alpha, .. } = s.state else {
                panic!("{kind:?}: {:?}", s.state);
            };
            // The settled state is within the settling agreement (1e-5 relative) of the
            // equilibrium; its residual decay is ~1e-6 (the amplitude below which no cycle is
            // read).
            assert!(
                ((omega_l - eq.omega) / eq.omega).abs() < 1e-5
                    && ((alpha - eq.alpha) / eq.alpha).abs() < 1e-5,
                "{kind:?}: {:?} vs {eq:?}",
                s.state
            );
        }
    }

    /// Stopped before the focus has decayed, the answer is an error naming the amplitude, not
    /// a limit cycle.
    #[test]
    fn a_transient_that_has_not_settled_is_an_error() {
        let m = Model::table1();
        let opts = SettleOptions {
            max_time: 1200.0,
            ..SettleOptions::default()
        };
        let e = settle(SolverKind::SWITCH, &m, &base(0.383), &opts).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, SettleError::NotSettled { t: 1200.0, .. }) && msg.contains("amplitude"),
            "{msg}"
        );
    }

    /// Near the bifurcations, where the event-driven solver's return-map refinement is
    /// ill-conditioned (it once failed at all three voltages): below the first Hopf point
    /// (a slowly decaying focus), just above it (a small cycle whose multiplier is near 1)
    /// and near the fold of cycles (4.7 V, bistable). Its answer has the switch model's kind
    /// and agrees within the settling agreement, 1e-5 relative (measured ≤ 5e-7).
    #[test]
    fn near_bifurcations_the_event_steady_state_agrees_with_a_settled_run() {
        let m = Model::table1();
        for u in [0.383, 0.385, 4.7] {
            let ev = event_steady(&m, u);
            let sw = settle(SolverKind::SWITCH, &m, &base(u), &SettleOptions::default()).unwrap();
            let (what, c) = change(&ev, &sw.state, 1e-8);
            assert!(
                c <= 1e-5,
                "{u} V: {what} differs by {c:e}: {ev:?} vs {sw:?}"
            );
        }
    }

    /// The Stribeck set at 0.12 V: the upper disc creeps onto the boundary of its stick
    /// interval (an approach that never ends in finite time, see rotor-event's steady
    /// state). The switch model's stick band and Moreau–Jean's finite steps stop it there;
    /// the event-driven solver takes the limit. All within the settling agreement: 1e-5
    /// relative, and for the velocities at rest its absolute floor, 1e-8 rad/s (measured:
    /// α within 2e-12 relative; Moreau–Jean's stuck ω_u is 1.1e-13 rad/s, rounding in its
    /// complementarity solve).
    #[test]
    fn creeping_onto_a_stick_boundary_every_solver_rests_at_the_same_point() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/params/stribeck.toml"
        );
        let m = Model::new(rotor_model::Params::from_file(std::path::Path::new(path)).unwrap());
        let ev = event_steady(&m, 0.12);
        assert!(matches!(ev, RigSteady::Equilibrium { .. }), "{ev:?}");
        let opts = SettleOptions::default();
        for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
            let s = settle(kind, &m, &base(0.12), &opts).unwrap();
            // The floor abs/rel makes a relative 1e-5 of it the absolute 1e-8.
            let (what, c) = change(&ev, &s.state, opts.abs / opts.rel);
            assert!(
                c <= opts.rel,
                "{kind:?}: {what} differs by {c:e}: {ev:?} vs {s:?}"
            );
        }
    }

    /// On the 1.5 V stick-slip cycle the settled metrics agree with the event-driven
    /// solver's refined fixed point within the fixtures' gates (switch 2e-6, Moreau–Jean
    /// 3e-6 relative; their origins are in fixtures/scenarios/t1-u1.5-rest.toml). ω_l's
    /// minimum is 0 in the reference and the stuck velocity η = 1e-10 rad/s in the switch
    /// model (measured Δ 1.0e-10 rad/s): it is compared absolutely, with the floor 1e-4 rad/s
    /// (below every other metric of this cycle, all > 0.8), so the gate 2e-6 reads as
    /// 2e-10 rad/s = 2η there.
    #[test]
    fn a_settled_cycle_agrees_with_the_refined_one() {
        let m = Model::table1();
        let reference = event_steady(&m, 1.5);
        for (kind, gate) in [(SolverKind::SWITCH, 2e-6), (SolverKind::MOREAU, 3e-6)] {
            let s = settle(kind, &m, &base(1.5), &SettleOptions::default()).unwrap();
            let (what, c) = change(&reference, &s.state, 1e-4);
            assert!(c <= gate, "{kind:?}: {what} differs by {c:e}");
        }
    }

    /// Table 1's first Hopf point (supercritical) at full precision.
    fn hopf(m: &Model, i: usize) -> f64 {
        crate::bifurcation::equilibria::hopf_points(m, 20.0)[i]
            .equilibrium
            .u
    }

    /// 1e-4 V below the first Hopf point the focus decays by a factor ≈ 0.9 per 300 s chunk
    /// (Re λ ≈ −3.3e-4 /s): settling would take ~4e4 s. The run says so as soon as three
    /// chunks show the geometric decay, long before the 20 000 s limit, and names it.
    #[test]
    fn a_slow_geometric_decay_is_refused_early_with_its_projection() {
        let m = Model::table1();
        let opts = SettleOptions::default();
        let e = settle(SolverKind::SWITCH, &m, &base(hopf(&m, 0) - 1e-4), &opts).unwrap_err();
        let SettleError::NotSettled { t, cause, .. } = e else {
            panic!("{e}")
        };
        let Unsettled::SlowDecay {
            per_chunk, needs, ..
        } = cause
        else {
            panic!("{cause:?}")
        };
        assert!(t < 0.25 * opts.max_time, "refused only at {t} s");
        assert!(per_chunk < 0.99 && needs > opts.max_time, "{cause:?}");
    }

    /// 1e-3 V below the second Hopf point (subcritical) the equilibrium repels at
    /// Re λ ≈ 7.7e-5 /s: from 1e-3 rad/s off it the oscillation grows by ≈ 2 % per chunk and
    /// would need ~5e4 s to leave the equilibrium's neighbourhood. Refused early, by name.
    #[test]
    fn a_slow_growth_from_an_unstable_equilibrium_is_refused_early() {
        let m = Model::table1();
        let u = hopf(&m, 1) - 1e-3;
        let eq = m.slip_equilibria(u)[0];
        let scene = Scene {
            x0: (eq.state() + State::new(0.0, 0.0, 1e-3))
                .as_slice()
                .to_vec(),
            ..base(u)
        };
        let opts = SettleOptions::default();
        let e = settle(SolverKind::SWITCH, &m, &scene, &opts).unwrap_err();
        let msg = e.to_string();
        let SettleError::NotSettled { t, cause, .. } = e else {
            panic!("{msg}")
        };
        assert!(
            matches!(cause, Unsettled::SlowGrowth { per_chunk, .. } if per_chunk > 1.01),
            "{msg}"
        );
        assert!(
            t < 0.25 * opts.max_time && msg.contains("unstable equilibrium"),
            "{msg}"
        );
    }

    /// 1e-4 V below the grazing end of the stick-slip branch (4.6153 V) the stick phase lasts
    /// 2.8 ms, under three Moreau–Jean steps at h = 1e-3: where the steps fall changes it from
    /// period to period by ~7e-4, above the settling agreement. The refusal names the step
    /// and what resolves it.
    #[test]
    fn moreau_on_a_cycle_grazing_below_its_step_says_so() {
        let m = Model::table1();
        let e = settle(
            SolverKind::MOREAU,
            &m,
            &base(4.615_276_875_05 - 1e-4),
            &SettleOptions::default(),
        )
        .unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(
                e,
                SettleError::NotSettled {
                    cause: Unsettled::GrazingBelowStep { h: 1e-3, .. },
                    ..
                }
            ) && msg.contains("h = 0.001")
                && msg.contains("event-driven"),
            "{msg}"
        );
    }
}
