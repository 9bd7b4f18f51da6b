//! Steady-state metrics read off a sampled trace, for traces that come without their
//! solver's events (an external solver's CSV).
//!
//! The benchmark grades a trace by comparing these metrics with the same metrics of the
//! reference trace on the same grid: the reconstruction's own error (of the order of the
//! grid step's powers) is then common to both and cancels to first order, and what remains
//! is the difference between the two solutions.
//!
//! Over the samples in `[from, t_end]`, with the solvers' own definitions
//! ([`rotor_model::seam::MetricsAccumulator`]), each event located on the model's field from the
//! sample before it (RK4, 200 steps per sample interval, within that interval):
//!
//! * the lower disc is stuck at a sample with |ω_l| ≤ a threshold (the grade's: the level's
//!   sample tolerance of ω_l, [`crate::grade::check::stuck_threshold`]; [`STUCK`] in
//!   [`grid_metrics`]). A stick phase starts where
//!   the slip field from the last moving sample brings ω_l to 0, and ends where the stick
//!   field from the last stuck sample (whose torque is still inside the stick interval) brings
//!   the applied torque `k_θ α` to the interval's edge;
//! * a cycle runs between two successive stick exits if the window holds two, else between
//!   two successive maxima of ω_l (where the slip field's ω̇_l reaches 0); the last complete
//!   cycle is reported: its period, its extremes of ω_l and ω_u (the extreme samples, moved
//!   to the vertex of the parabola through their neighbours when they are strict local
//!   extrema), and its stick time;
//! * an ω_l range of at most [`rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE`] (over the window,
//!   over the last cycle, or over the last cycle's length at the end of the window, where a
//!   focus has decayed), or fewer than two anchors, is an equilibrium: the last sample's
//!   state.
//!
//! Why integrate rather than interpolate: near ω_l = 0 the friction level changes fast
//! (its exponential terms), so a polynomial through samples 0.01 s apart misplaces a stick
//! onset by up to 3e-5 s, by an amount that depends on where the grid falls, and that does
//! not cancel between two traces whose onsets fall on different sides of a grid time. And ω_l
//! leaves 0 tangentially, ω_l ≈ c(t − t_exit)², so its root is ill conditioned (a difference δ
//! moves it by √(δ/c)), while the torque crosses its bound transversally. Integrating from
//! each trace's own sample makes the reconstruction as accurate as the sample. Anchoring as
//! the solvers do matters too: a time-stepping solver's single periods jitter with where its
//! steps fall, so another choice of anchor reads another period.

use rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE;
use rotor_model::seam::{RigSteady, Sample};
use rotor_model::{Disc, DiscMode, Model, OMEGA_L, OMEGA_U, State};

/// |ω_l| at or below which [`grid_metrics`] counts a sample as stuck [rad/s]: an event-driven
/// solver writes exactly 0, a time-stepping one its complementarity solver's rounding (≈ 1e-13
/// for Moreau–Jean and Siconos); a regularised friction law creeps far above it. The grade
/// (`rotor check`) uses [`grid_metrics_at`] with a threshold that follows its level instead.
pub const STUCK: f64 = 1e-9;

/// Why a trace has no steady metrics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridMetricsError {
    /// The trace ends before the steady-state window starts.
    #[error("no sample at or after t = {from} s")]
    Empty {
        /// Start of the window \[s\].
        from: f64,
    },
}

/// The model and input a trace was computed for: the stick interval of the lower disc, for
/// the end of a stick phase.
#[derive(Debug, Clone, Copy)]
pub struct StickExit<'a> {
    /// The rotor model (its lower friction law gives the stick interval).
    pub model: &'a Model,
    /// The motor input voltage \[V\].
    pub u: f64,
}

/// The steady-state metrics of `samples` over `t ≥ from` (see the module docs), a sample
/// counting as stuck at |ω_l| ≤ [`STUCK`].
pub fn grid_metrics(
    samples: &[Sample],
    from: f64,
    exit: StickExit,
) -> Result<RigSteady, GridMetricsError> {
    grid_metrics_at(samples, from, exit, STUCK)
}

/// [`grid_metrics`] with a sample counting as stuck at |ω_l| ≤ `stuck` \[rad/s\].
pub fn grid_metrics_at(
    samples: &[Sample],
    from: f64,
    exit: StickExit,
    stuck: f64,
) -> Result<RigSteady, GridMetricsError> {
    let start = samples.partition_point(|s| s.t < from - 1e-9);
    let w = &samples[start..];
    let last = w.last().ok_or(GridMetricsError::Empty { from })?;
    let equilibrium = RigSteady::Equilibrium {
        omega_u: last.x[OMEGA_U],
        omega_l: last.x[OMEGA_L],
        alpha: last.x[0],
    };
    let range = |s: &[Sample]| {
        let (lo, hi) = s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                (a.min(s.x[OMEGA_L]), b.max(s.x[OMEGA_L]))
            });
        hi - lo
    };
    if range(w) <= EQUILIBRIUM_AMPLITUDE {
        return Ok(equilibrium);
    }
    let phases = stick_phases(w, exit, stuck);
    // Anchors: (index of the sample at or after the anchor, time).
    let anchors: Vec<(usize, f64)> = if phases.iter().filter(|p| p.exit.is_some()).count() >= 2 {
        phases
            .iter()
            .filter_map(|p| p.exit.map(|t| (p.last + 1, t)))
            .collect()
    } else {
        maxima(w, exit, stuck)
    };
    let [.., (ka, ta), (kb, tb)] = anchors[..] else {
        return Ok(equilibrium);
    };
    // One sample beyond each anchor's bracketing pair, so that an extremum at an anchor has
    // both neighbours.
    let cycle = &w[ka.saturating_sub(2)..=(kb + 1).min(w.len() - 1)];
    let (wl_min, wl_max) = extremes(cycle, OMEGA_L, exit, stuck);
    let tail = &w[w.partition_point(|s| s.t < last.t - (tb - ta))..];
    if wl_max - wl_min <= EQUILIBRIUM_AMPLITUDE || range(tail) <= EQUILIBRIUM_AMPLITUDE {
        return Ok(equilibrium);
    }
    let (wu_min, wu_max) = extremes(cycle, OMEGA_U, exit, stuck);
    let stick_time = phases
        .iter()
        .filter_map(|p| Some((p.onset, p.exit?)))
        .filter(|&(_, e)| e > ta && e <= tb)
        .map(|(on, e)| e - on.max(ta))
        .sum::<f64>()
        + 0.0;
    Ok(RigSteady::LimitCycle {
        period: tb - ta,
        omega_l_max: wl_max,
        omega_l_min: wl_min,
        omega_u_max: wu_max,
        omega_u_min: wu_min,
        stick_time,
    })
}

/// One run of stuck samples, with its located onset and exit (none if it lasts to the end
/// of the samples).
struct StickPhase {
    last: usize,
    onset: f64,
    exit: Option<f64>,
}

/// The stick phases of the lower disc (see the module docs).
fn stick_phases(s: &[Sample], exit: StickExit, threshold: f64) -> Vec<StickPhase> {
    let stuck = |k: usize| s[k].x[OMEGA_L].abs() <= threshold;
    let mut out = Vec::new();
    let mut k = 0;
    while k < s.len() {
        if !stuck(k) {
            k += 1;
            continue;
        }
        let first = k;
        while k + 1 < s.len() && stuck(k + 1) {
            k += 1;
        }
        let last = k;
        let onset = if first >= 1 {
            let a = &s[first - 1];
            let lower = DiscMode::slip_of(a.x[OMEGA_L]);
            exit.crossing(a, s[first].t, lower, |x| a.x[OMEGA_L].signum() * x[OMEGA_L])
        } else {
            s[first].t
        };
        // The disc leaves 0 tangentially, so the first sample after the exit can still read as
        // stuck: integrate from the last stuck sample whose torque is inside the interval.
        let mut j = last;
        while j > first && exit.excess(&s[j].x) >= 0.0 {
            j -= 1;
        }
        let end = (j + 1 < s.len())
            .then(|| exit.crossing(&s[j], s[j + 1].t, DiscMode::Stick, |x| -exit.excess(x)));
        out.push(StickPhase {
            last,
            onset,
            exit: end,
        });
        k += 1;
    }
    out
}

/// The maxima of ω_l in slip: (index of the sample after, time where the slip field's ω̇_l
/// reaches 0 from the sample before).
fn maxima(s: &[Sample], exit: StickExit, stuck: f64) -> Vec<(usize, f64)> {
    let m = exit.model;
    let mut out = Vec::new();
    for k in 1..s.len().saturating_sub(1) {
        let (a, b, c) = (s[k - 1].x[OMEGA_L], s[k].x[OMEGA_L], s[k + 1].x[OMEGA_L]);
        if !(b > a && b >= c && b.abs() > stuck) {
            continue;
        }
        // The maximum lies in [t_{k−1}, t_{k+1}]: from the earlier sample, along the slip
        // field, to where ω̇_l turns negative.
        let lower = DiscMode::slip_of(b);
        let from = &s[k - 1];
        let upper = m.mode_at(&from.x, exit.u).upper();
        let mode = rotor_model::Mode::rig(upper, lower);
        let t = exit.crossing(from, s[k + 1].t, lower, |x| m.rhs(x, exit.u, mode)[OMEGA_L]);
        out.push((if t <= s[k].t { k } else { k + 1 }, t));
    }
    out
}

/// (min, max) of component `i` (ω_u or ω_l) over the samples. An extreme sample that is a
/// strict local extremum in slip, with both neighbours in the slice, is moved to the true
/// extremum: from the sample before it along the field to where the component's derivative
/// changes sign (a plateau, as in a stick phase, stays the sample's value).
fn extremes(s: &[Sample], i: usize, exit: StickExit, stuck: f64) -> (f64, f64) {
    let v = |k: usize| s[k].x[i];
    let (mut kmin, mut kmax) = (0, 0);
    for k in 1..s.len() {
        if v(k) < v(kmin) {
            kmin = k;
        }
        if v(k) > v(kmax) {
            kmax = k;
        }
    }
    let m = exit.model;
    let refine = |k: usize, sign: f64| {
        if k == 0 || k + 1 >= s.len() {
            return v(k);
        }
        let (a, b, c) = (v(k - 1), v(k), v(k + 1));
        let strict = sign * (b - a) > 0.0 && sign * (b - c) > 0.0;
        let moving = s[k - 1..=k + 1].iter().all(|q| q.x[OMEGA_L].abs() > stuck);
        if !strict || !moving {
            return b;
        }
        let from = &s[k - 1];
        let lower = DiscMode::slip_of(from.x[OMEGA_L]);
        let upper = m.mode_at(&from.x, exit.u).upper();
        let mode = rotor_model::Mode::rig(upper, lower);
        let (_, x) = exit.crossing_state(from, s[k + 1].t, lower, |x| {
            sign * m.rhs(x, exit.u, mode)[i]
        });
        sign * (sign * x[i]).max(sign * b)
    };
    (refine(kmin, -1.0), refine(kmax, 1.0))
}

impl StickExit<'_> {
    /// How far the applied torque on the lower disc is outside its stick interval (< 0
    /// inside).
    fn excess(&self, x: &State) -> f64 {
        let (lo, hi) = self.model.friction(Disc::LOWER).static_interval();
        let t = self.model.applied_torque(Disc::LOWER, x, self.u);
        (t - hi).max(lo - t)
    }

    /// Integrates the field with the lower disc in `lower` from sample `a` up to `t_max`, and
    /// returns where `g` first falls to 0 (linear within the RK4 step that brackets it), or
    /// `t_max` if it does not.
    fn crossing(&self, a: &Sample, t_max: f64, lower: DiscMode, g: impl Fn(&State) -> f64) -> f64 {
        self.crossing_state(a, t_max, lower, g).0
    }

    /// [`StickExit::crossing`] with the state there (linear within the bracketing step).
    fn crossing_state(
        &self,
        a: &Sample,
        t_max: f64,
        lower: DiscMode,
        g: impl Fn(&State) -> f64,
    ) -> (f64, State) {
        const STEPS: usize = 200;
        let m = self.model;
        let mut x = a.x;
        if lower == DiscMode::Stick {
            x[OMEGA_L] = 0.0;
        }
        let upper = m.mode_at(&x, self.u).upper();
        let mode = rotor_model::Mode::rig(upper, lower);
        let f = |x: &State| m.rhs(x, self.u, mode);
        let h = (t_max - a.t) / STEPS as f64;
        let mut t = a.t;
        let mut gx = g(&x);
        if gx <= 0.0 {
            return (t, x);
        }
        for _ in 0..STEPS {
            let k1 = f(&x);
            let k2 = f(&(x + k1 * (0.5 * h)));
            let k3 = f(&(x + k2 * (0.5 * h)));
            let k4 = f(&(x + k3 * h));
            let next = x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
            let gn = g(&next);
            if gn <= 0.0 {
                let r = gx / (gx - gn);
                return (t + h * r, x + (next - x) * r);
            }
            (x, gx, t) = (next, gn, t + h);
        }
        (t_max, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::State;

    /// Table 1's lower disc, for the stick exits of synthetic traces.
    fn exit(m: &Model) -> StickExit<'_> {
        StickExit { model: m, u: 0.0 }
    }

    fn sample(t: f64, wl: f64) -> Sample {
        Sample {
            t,
            x: State::new(0.0, 1.0 + 0.1 * wl, wl),
        }
    }

    /// The reconstruction on the event-driven solver's own 0.01 s trace against the metrics
    /// the solver located from its events: their largest difference per metric.
    fn reconstruction_error(u: f64) -> Vec<(&'static str, f64)> {
        use rotor_model::seam::{Output, Scene, Solver};
        let m = Model::table1();
        let scene = Scene {
            u,
            t_end: 200.0,
            output: Output::Grid { dt: 0.01 },
            metrics_from: Some(100.0),
            ..Scene::with_tol(1e-12)
        };
        let tr = rotor_event::EventSolver::default()
            .simulate(&m, &scene)
            .unwrap();
        let g = grid_metrics(
            &tr.samples.rig().unwrap(),
            100.0,
            StickExit { model: &m, u },
        )
        .unwrap();
        let exact = tr.rig_metrics().unwrap();
        assert_eq!(g.kind(), exact.kind(), "{g:?} vs {exact:?}");
        g.values()
            .into_iter()
            .zip(exact.values())
            .map(|((n, a), (_, b))| (n, (a - b).abs()))
            .collect()
    }

    /// On Table 1's 1.5 V stick-slip cycle and 0.5 V slipping cycle, the reconstruction from
    /// 0.01 s samples gives the metrics the event-driven solver located from its events.
    /// Measured: period ≤ 1.5e-10 s, stick time 1.6e-9 s, extremes ≤ 2.9e-9 rad/s (every
    /// event integrated on the model from samples of a run at tol 1e-12); bound 1e-8.
    #[test]
    fn on_sampled_cycles_the_metrics_are_the_located_ones() {
        for u in [1.5, 0.5] {
            let d = reconstruction_error(u);
            for (name, diff) in d {
                assert!(diff <= 1e-8, "{u} V: {name}: {diff:e}");
            }
        }
    }

    #[test]
    fn a_flat_window_or_a_single_rise_is_an_equilibrium() {
        let flat: Vec<Sample> = (0..100)
            .map(|k| sample(k as f64, 2.0 + 1e-8 * k as f64))
            .collect();
        let m = Model::table1();
        assert!(matches!(
            grid_metrics(&flat, 0.0, exit(&m)),
            Ok(RigSteady::Equilibrium { .. })
        ));
        // A monotone approach has no complete cycle: an equilibrium (its last state).
        let rise: Vec<Sample> = (0..100).map(|k| sample(k as f64, k as f64)).collect();
        assert!(matches!(
            grid_metrics(&rise, 0.0, exit(&m)),
            Ok(RigSteady::Equilibrium { omega_l: 99.0, .. })
        ));
        assert!(matches!(
            grid_metrics(&rise, 1000.0, exit(&m)),
            Err(GridMetricsError::Empty { .. })
        ));
    }
}
