//! Steady-state metrics, accumulated from a run's events in O(1) memory.
//!
//! Solvers push their located events into a [`MetricsAccumulator`] (stick onsets and exits,
//! and the extrema of every disc's velocity, located between steps). A cycle is the interval
//! between two successive *anchors*: exits of the bottom disc (the rig's lower one) from
//! stick when it sticks, maxima of its velocity otherwise. The metrics of the last complete
//! cycle are reported, for every disc.

use serde::{Deserialize, Serialize};

use crate::seam::event::{Event, EventKind, EventRef};
use crate::{Disc, Mode, State};

/// A steady state of a chain of discs, as per-disc lists (disc order: 0 is the driven
/// disc at the top).
///
/// What a run measures of its steady state ([`crate::seam::Trajectory::metrics`]). Its JSON is
/// the chain's (`"omega_max": [..]`); the rig's two discs read it through [`RigSteady`], their
/// named fields, which is what `rotor steady` prints and the reference data stores for the
/// rig. A stick time is per disc and optional: the rig's data measure the lower disc's only,
/// and a list keeps what was measured, never a number that was not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SteadyState {
    /// A rest point: every twist `α_i` (N − 1, rad) and velocity `ω_i` (N, rad/s).
    Equilibrium {
        /// The springs' twists α_i = θ_i − θ_{i+1} \[rad\].
        alpha: Vec<f64>,
        /// The discs' velocities [rad/s] (a stuck disc's exactly 0).
        omega: Vec<f64>,
    },
    /// A periodic orbit: its period and, per disc, the extremes of ω and the time stuck per
    /// period.
    LimitCycle {
        /// Period \[s\].
        period: f64,
        /// Largest ω_i over the cycle [rad/s].
        omega_max: Vec<f64>,
        /// Smallest ω_i over the cycle [rad/s].
        omega_min: Vec<f64>,
        /// Time disc i spends stuck per period \[s\], where it was measured.
        stick_time: Vec<Option<f64>>,
    },
}

impl SteadyState {
    /// An equilibrium or a limit cycle.
    pub fn kind(&self) -> SteadyKind {
        match self {
            SteadyState::Equilibrium { .. } => SteadyKind::Equilibrium,
            SteadyState::LimitCycle { .. } => SteadyKind::LimitCycle,
        }
    }

    /// Whether every number is finite (a stick time not measured counts as finite).
    pub fn is_finite(&self) -> bool {
        match self {
            SteadyState::Equilibrium { alpha, omega } => {
                alpha.iter().chain(omega).all(|v| v.is_finite())
            }
            SteadyState::LimitCycle {
                period,
                omega_max,
                omega_min,
                stick_time,
            } => {
                period.is_finite()
                    && omega_max.iter().chain(omega_min).all(|v| v.is_finite())
                    && stick_time.iter().flatten().all(|v| v.is_finite())
            }
        }
    }

    /// The number of discs.
    pub fn discs(&self) -> usize {
        match self {
            SteadyState::Equilibrium { omega, .. } => omega.len(),
            SteadyState::LimitCycle { omega_max, .. } => omega_max.len(),
        }
    }

    /// The rig's view: its two discs' named fields, for a steady state of two discs (with
    /// the lower disc's stick time measured, for a cycle); `None` for any other.
    pub fn rig(&self) -> Option<RigSteady> {
        match self {
            SteadyState::Equilibrium { alpha, omega } => match (alpha.as_slice(), omega.as_slice())
            {
                (&[alpha], &[omega_u, omega_l]) => Some(RigSteady::Equilibrium {
                    omega_u,
                    omega_l,
                    alpha,
                }),
                _ => None,
            },
            SteadyState::LimitCycle {
                period,
                omega_max,
                omega_min,
                stick_time,
            } => match (
                omega_max.as_slice(),
                omega_min.as_slice(),
                stick_time.as_slice(),
            ) {
                (&[omega_u_max, omega_l_max], &[omega_u_min, omega_l_min], &[_, Some(stick)]) => {
                    Some(RigSteady::LimitCycle {
                        period: *period,
                        omega_l_max,
                        omega_l_min,
                        omega_u_max,
                        omega_u_min,
                        stick_time: stick,
                    })
                }
                _ => None,
            },
        }
    }
}

impl From<RigSteady> for SteadyState {
    /// The rig's steady state as lists: the upper disc first, and a stick time for the
    /// lower disc only (the rig's metrics measure no other).
    fn from(r: RigSteady) -> SteadyState {
        match r {
            RigSteady::Equilibrium {
                omega_u,
                omega_l,
                alpha,
            } => SteadyState::Equilibrium {
                alpha: vec![alpha],
                omega: vec![omega_u, omega_l],
            },
            RigSteady::LimitCycle {
                period,
                omega_l_max,
                omega_l_min,
                omega_u_max,
                omega_u_min,
                stick_time,
            } => SteadyState::LimitCycle {
                period,
                omega_max: vec![omega_u_max, omega_l_max],
                omega_min: vec![omega_u_min, omega_l_min],
                stick_time: vec![None, Some(stick_time)],
            },
        }
    }
}

/// The steady state of the rig's two discs by name: a view of [`SteadyState`]'s lists
/// ([`SteadyState::rig`]), as `rotor steady` prints it for the rig (docs/design.md, "The
/// CLI"), and as the reference data stores and reads it back.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RigSteady {
    /// An equilibrium (rad, rad/s): a run's final state when read off a run
    /// ([`MetricsAccumulator::finish`]), or the solved equilibrium.
    Equilibrium {
        /// ω_u [rad/s] (equal to ω_l at an equilibrium, up to how the run approached it).
        omega_u: f64,
        /// ω_l [rad/s]; exactly 0 when the lower disc is stuck.
        omega_l: f64,
        /// α \[rad\]: the spring's twist.
        alpha: f64,
    },
    /// A periodic orbit: period \[s\], extremes [rad/s], time per period with ω_l = 0 \[s\].
    LimitCycle {
        /// Period \[s\]: time between the last two anchors (lower-disc stick exits when the
        /// orbit sticks, ω_l maxima otherwise).
        period: f64,
        /// Largest ω_l over the last cycle [rad/s].
        omega_l_max: f64,
        /// Smallest ω_l over the last cycle [rad/s] (0 on a stick-slip cycle).
        omega_l_min: f64,
        /// Largest ω_u over the last cycle [rad/s].
        omega_u_max: f64,
        /// Smallest ω_u over the last cycle [rad/s].
        omega_u_min: f64,
        /// Time the lower disc spends stuck per period \[s\] (0 on a slipping cycle).
        stick_time: f64,
    },
}

impl RigSteady {
    /// The metrics as named values, in a fixed order (for comparisons and reports): the
    /// order of [`RigSteady::map`]'s calls.
    pub fn values(&self) -> Vec<(&'static str, f64)> {
        let mut out = Vec::with_capacity(6);
        self.map(|name, v| {
            out.push((name, v));
            v
        });
        out
    }

    /// The same steady state with every metric `v` named `name` replaced by `f(name, v)`,
    /// called once per metric in the order of the fields.
    pub fn map(self, mut f: impl FnMut(&'static str, f64) -> f64) -> RigSteady {
        match self {
            RigSteady::Equilibrium {
                omega_u,
                omega_l,
                alpha,
            } => RigSteady::Equilibrium {
                omega_u: f("omega_u", omega_u),
                omega_l: f("omega_l", omega_l),
                alpha: f("alpha", alpha),
            },
            RigSteady::LimitCycle {
                period,
                omega_l_max,
                omega_l_min,
                omega_u_max,
                omega_u_min,
                stick_time,
            } => RigSteady::LimitCycle {
                period: f("period", period),
                omega_l_max: f("omega_l_max", omega_l_max),
                omega_l_min: f("omega_l_min", omega_l_min),
                omega_u_max: f("omega_u_max", omega_u_max),
                omega_u_min: f("omega_u_min", omega_u_min),
                stick_time: f("stick_time", stick_time),
            },
        }
    }

    /// Both discs at rest with the lower one stuck: an equilibrium with ω_l = 0 exactly.
    /// Every solver sets a stuck disc's velocity to 0 exactly, and at an equilibrium
    /// α̇ = ω_u − ω_l = 0, so ω_u is 0 as well, up to how the run approached rest: an upper
    /// disc with only viscous friction (Table 1) never sticks, and its velocity decays to the
    /// rounding of α (1e-16 rad/s after 1500 s, 1e-10 in a Moreau–Jean run), never to 0.
    pub fn is_stuck(&self) -> bool {
        matches!(self, RigSteady::Equilibrium { omega_l, .. } if *omega_l == 0.0)
    }

    /// An equilibrium or a limit cycle.
    pub fn kind(&self) -> SteadyKind {
        match self {
            RigSteady::Equilibrium { .. } => SteadyKind::Equilibrium,
            RigSteady::LimitCycle { .. } => SteadyKind::LimitCycle,
        }
    }
}

/// What a steady state is (`"equilibrium"` or `"limit_cycle"` in JSON and reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SteadyKind {
    /// A rest point: [`RigSteady::Equilibrium`].
    Equilibrium,
    /// A periodic orbit: [`RigSteady::LimitCycle`].
    LimitCycle,
}

impl SteadyKind {
    /// `"equilibrium"` or `"limit_cycle"`.
    pub fn as_str(self) -> &'static str {
        match self {
            SteadyKind::Equilibrium => "equilibrium",
            SteadyKind::LimitCycle => "limit_cycle",
        }
    }
}

impl std::fmt::Display for SteadyKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The largest chain the metrics hold: the mode's bit sets' ([`Mode::MAX_DISCS`]), so that
/// the accumulator is a plain value, copied (not allocated) when a run saves it.
const DISCS: usize = Mode::MAX_DISCS;

/// Summary of one cycle between two anchors, per disc (the first `n` entries of each list).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cycle {
    start: f64,
    end: f64,
    max: [f64; DISCS],
    min: [f64; DISCS],
    /// Time stuck within the cycle.
    stick: [f64; DISCS],
}

/// One anchor stream (stick exits, or maxima, of the bottom disc) with the cycle in
/// progress.
#[derive(Debug, Clone, Copy)]
struct Stream {
    open: Option<Cycle>,
    last: [Option<Cycle>; 2],
    count: u64,
}

impl Stream {
    const fn new() -> Stream {
        Stream {
            open: None,
            last: [None, None],
            count: 0,
        }
    }

    fn anchor(&mut self, t: f64, x: &[f64], n: usize) {
        if let Some(mut c) = self.open.take() {
            c.end = t;
            c.include(x, n);
            self.last = [Some(c), self.last[0]];
            self.count += 1;
        }
        let mut c = Cycle {
            start: t,
            end: t,
            max: [f64::NEG_INFINITY; DISCS],
            min: [f64::INFINITY; DISCS],
            stick: [0.0; DISCS],
        };
        c.include(x, n);
        self.open = Some(c);
    }
}

impl Cycle {
    /// Takes in the velocities of a state of a chain of `n` discs (`[α_1 … α_{n−1}, ω_1 … ω_n]`).
    fn include(&mut self, x: &[f64], n: usize) {
        let omega = &x[n - 1..];
        for (i, &w) in omega.iter().enumerate() {
            self.max[i] = self.max[i].max(w);
            self.min[i] = self.min[i].min(w);
        }
    }

    /// The ω range of the bottom disc over the cycle.
    fn bottom_amplitude(&self, n: usize) -> f64 {
        self.max[n - 1] - self.min[n - 1]
    }
}

/// Accumulates steady-state metrics from events, in constant memory, for a chain of any
/// number of discs (the rig is the chain of two).
///
/// The cycles are read off the bottom disc (the rig's lower one): between its stick exits
/// when it sticks, else between its maxima. Each cycle holds every disc's largest and
/// smallest velocity and time stuck. The accumulator is a plain value (its lists are sized
/// for [`Mode::MAX_DISCS`]), so a run saves and restores it without allocating.
#[derive(Debug, Clone, Copy)]
pub struct MetricsAccumulator {
    t_from: f64,
    /// The number of discs.
    n: usize,
    stick_exits: Stream,
    maxima: Stream,
    /// Start of each disc's current stick phase (NaN while it slips).
    stick_since: [f64; DISCS],
}

/// Amplitude of ω_l [rad/s] below which an oscillation counts as an equilibrium: far below
/// any cycle of the source's diagram (the smallest slipping cycles near the Hopf point that
/// matter have amplitudes ≥ 1e-3) and far above what solver noise at an equilibrium gives.
pub const EQUILIBRIUM_AMPLITUDE: f64 = 1e-6;

impl MetricsAccumulator {
    /// Metrics of the rig (two discs) over events at `t ≥ t_from`.
    pub fn new(t_from: f64) -> MetricsAccumulator {
        MetricsAccumulator::for_discs(t_from, 2)
    }

    /// Metrics of a chain of `discs` discs (2 ≤ discs ≤ [`Mode::MAX_DISCS`]) over events at
    /// `t ≥ t_from`.
    ///
    /// # Panics
    ///
    /// If `discs` is outside that range: a chain is refused beyond it where it is read.
    pub fn for_discs(t_from: f64, discs: usize) -> MetricsAccumulator {
        assert!(
            (2..=DISCS).contains(&discs),
            "a chain of {discs} discs: the metrics hold 2 to {DISCS}"
        );
        MetricsAccumulator {
            t_from,
            n: discs,
            stick_exits: Stream::new(),
            maxima: Stream::new(),
            stick_since: [f64::NAN; DISCS],
        }
    }

    /// The number of discs.
    pub fn discs(&self) -> usize {
        self.n
    }

    /// Feeds one event (in time order).
    pub fn push<'a>(&mut self, e: impl Into<EventRef<'a>>) {
        let e = e.into();
        if e.t < self.t_from {
            return;
        }
        let n = self.n;
        for s in [&mut self.stick_exits, &mut self.maxima] {
            if let Some(c) = s.open.as_mut() {
                c.include(e.x, n);
            }
        }
        let bottom = Disc::at(n - 1);
        match e.kind {
            EventKind::StickStart(d) => self.stick_since[d.position()] = e.t,
            EventKind::StickEnd(d) => {
                let i = d.position();
                let t0 = std::mem::replace(&mut self.stick_since[i], f64::NAN);
                if !t0.is_nan() {
                    for s in [&mut self.stick_exits, &mut self.maxima] {
                        if let Some(c) = s.open.as_mut() {
                            c.stick[i] += e.t - t0.max(c.start);
                        }
                    }
                }
                if d == bottom {
                    self.stick_exits.anchor(e.t, e.x, n);
                }
            }
            EventKind::Max(d) if d == bottom => self.maxima.anchor(e.t, e.x, n),
            _ => {}
        }
    }

    /// The run skips `dt` (whole periods) right after `anchor`, the event pushed last, and
    /// continues from its state ([`crate::seam::FastForward`]): the cycles kept so far and the one in
    /// progress move by `dt`. An anchor before the window opens the window at its new time.
    pub fn fast_forward(&mut self, anchor: &Event, dt: f64) {
        if anchor.t < self.t_from {
            self.push(EventRef {
                t: anchor.t + dt,
                x: &anchor.x,
                kind: anchor.kind,
            });
            return;
        }
        for s in [&mut self.stick_exits, &mut self.maxima] {
            for c in s.open.iter_mut().chain(s.last.iter_mut().flatten()) {
                c.start += dt;
                c.end += dt;
            }
        }
        for t in &mut self.stick_since[..self.n] {
            *t += dt; // NaN (slipping) stays NaN
        }
    }

    /// The cycles the metrics are read from: between stick exits if the bottom disc sticks,
    /// else between its maxima.
    fn stream(&self) -> &Stream {
        if self.stick_exits.count >= 1 {
            &self.stick_exits
        } else {
            &self.maxima
        }
    }

    /// The steady state after a run ending at `x_final` (of the chain's size): the last
    /// complete cycle if the bottom disc still oscillates with amplitude above
    /// [`EQUILIBRIUM_AMPLITUDE`], else the final state. Every disc's stick time is measured.
    pub fn finish_lists(&self, x_final: &[f64]) -> SteadyState {
        let n = self.n;
        match self.stream().last[0] {
            Some(c) if c.bottom_amplitude(n) > EQUILIBRIUM_AMPLITUDE => SteadyState::LimitCycle {
                period: c.end - c.start,
                omega_max: c.max[..n].to_vec(),
                omega_min: c.min[..n].to_vec(),
                stick_time: c.stick[..n].iter().copied().map(Some).collect(),
            },
            _ => SteadyState::Equilibrium {
                alpha: x_final[..n - 1].to_vec(),
                omega: x_final[n - 1..].to_vec(),
            },
        }
    }

    /// The rig's steady state after a run ending at `(t, x)`: [`MetricsAccumulator::finish_lists`]
    /// in the rig's named view.
    ///
    /// # Panics
    ///
    /// If the accumulator is not the rig's (two discs).
    pub fn finish(&self, x_final: &State) -> RigSteady {
        assert_eq!(self.n, 2, "the rig's view of a chain of {} discs", self.n);
        self.finish_lists(x_final.as_slice())
            .rig()
            .expect("two discs with every stick time measured")
    }

    /// Relative change of the bottom disc's ω amplitude (max − min) between the last two
    /// complete cycles, if two exist: a focus decaying near a Hopf point keeps its period but
    /// not its amplitude.
    pub fn amplitude_drift(&self) -> Option<f64> {
        let [Some(a), Some(b)] = self.stream().last else {
            return None;
        };
        let (ra, rb) = (a.bottom_amplitude(self.n), b.bottom_amplitude(self.n));
        Some((ra - rb).abs() / ra.abs().max(rb.abs()).max(EQUILIBRIUM_AMPLITUDE))
    }

    /// Relative change of the period between the last two complete cycles (a convergence
    /// indicator), if two exist.
    pub fn period_drift(&self) -> Option<f64> {
        let [Some(a), Some(b)] = self.stream().last else {
            return None;
        };
        let (ta, tb) = (a.end - a.start, b.end - b.start);
        Some(((ta - tb) / ta).abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rig_view_of_the_lists_round_trips() {
        let cycle = RigSteady::LimitCycle {
            period: 5.0,
            omega_l_max: 7.0,
            omega_l_min: 0.0,
            omega_u_max: 2.5,
            omega_u_min: 2.0,
            stick_time: 1.5,
        };
        let lists = SteadyState::from(cycle);
        assert_eq!(
            lists,
            SteadyState::LimitCycle {
                period: 5.0,
                omega_max: vec![2.5, 7.0],
                omega_min: vec![2.0, 0.0],
                stick_time: vec![None, Some(1.5)],
            }
        );
        assert_eq!(lists.rig(), Some(cycle));
        let rest = RigSteady::Equilibrium {
            omega_u: 1.0,
            omega_l: 1.0,
            alpha: 0.3,
        };
        assert_eq!(SteadyState::from(rest).rig(), Some(rest));
        assert_eq!(SteadyState::from(rest).discs(), 2);
        // Three discs, or a cycle whose lower stick time was not measured, have no rig view.
        let chain = SteadyState::Equilibrium {
            alpha: vec![0.1, 0.2],
            omega: vec![1.0; 3],
        };
        assert_eq!((chain.rig(), chain.discs()), (None, 3));
        let unmeasured = SteadyState::LimitCycle {
            period: 5.0,
            omega_max: vec![2.5, 7.0],
            omega_min: vec![2.0, 0.0],
            stick_time: vec![None, None],
        };
        assert_eq!(unmeasured.rig(), None);
    }

    #[test]
    fn the_lists_print_as_the_chain_contract_names_them() {
        let json = serde_json::to_string(&SteadyState::LimitCycle {
            period: 5.0,
            omega_max: vec![2.5, 7.0],
            omega_min: vec![2.0, 0.0],
            stick_time: vec![None, Some(1.5)],
        })
        .unwrap();
        assert_eq!(
            json,
            r#"{"kind":"limit_cycle","period":5.0,"omega_max":[2.5,7.0],"omega_min":[2.0,0.0],"stick_time":[null,1.5]}"#
        );
    }

    fn ev(t: f64, x: [f64; 3], kind: EventKind) -> Event {
        Event::new(t, &x, kind)
    }

    #[test]
    fn values_name_every_field_once_in_field_order() {
        let eq = RigSteady::Equilibrium {
            omega_u: 1.0,
            omega_l: 2.0,
            alpha: 3.0,
        };
        assert_eq!(
            eq.values(),
            [("omega_u", 1.0), ("omega_l", 2.0), ("alpha", 3.0)]
        );
        let lc = RigSteady::LimitCycle {
            period: 1.0,
            omega_l_max: 2.0,
            omega_l_min: 3.0,
            omega_u_max: 4.0,
            omega_u_min: 5.0,
            stick_time: 6.0,
        };
        let names = [
            "period",
            "omega_l_max",
            "omega_l_min",
            "omega_u_max",
            "omega_u_min",
            "stick_time",
        ];
        let expected: Vec<_> = names
            .into_iter()
            .zip(1..)
            .map(|(n, k)| (n, f64::from(k)))
            .collect();
        assert_eq!(lc.values(), expected);
        // map hands each metric to f under its own name and puts the result back there.
        assert_eq!(lc.map(|_, v| 10.0 * v).values()[5], ("stick_time", 60.0));
    }

    #[test]
    fn stick_slip_cycle_from_events() {
        let mut m = MetricsAccumulator::new(1.0);
        let l = Disc::LOWER;
        let evs = [
            ev(0.5, [0.0, 1.0, 0.0], EventKind::StickEnd(l)), // before t_from: ignored
            ev(2.0, [2.2, 1.0, 0.0], EventKind::StickEnd(l)),
            ev(3.0, [1.0, 1.1, 3.0], EventKind::Max(l)),
            ev(4.0, [1.0, 0.9, 0.0], EventKind::StickStart(l)),
            ev(5.0, [2.2, 1.0, 0.0], EventKind::StickEnd(l)),
            ev(6.0, [1.0, 1.1, 3.0], EventKind::Max(l)),
            ev(7.5, [1.0, 0.9, 0.0], EventKind::StickStart(l)),
            ev(8.0, [2.2, 1.0, 0.0], EventKind::StickEnd(l)),
        ];
        for e in &evs {
            m.push(e);
        }
        let RigSteady::LimitCycle {
            period,
            omega_l_max,
            omega_l_min,
            omega_u_max,
            omega_u_min,
            stick_time,
        } = m.finish(&State::zeros())
        else {
            panic!("expected a cycle")
        };
        assert_eq!(period, 3.0);
        assert_eq!(stick_time, 0.5);
        assert_eq!((omega_l_max, omega_l_min), (3.0, 0.0));
        assert_eq!((omega_u_max, omega_u_min), (1.1, 0.9));
        assert_eq!(m.period_drift(), Some(0.0));
        assert_eq!(m.amplitude_drift(), Some(0.0));
    }

    /// A decaying focus: the same period, the ω_l amplitude halving from cycle to cycle
    /// (cycles between maxima, no stick).
    #[test]
    fn amplitude_drift_sees_a_decay_the_period_does_not() {
        let mut m = MetricsAccumulator::new(0.0);
        let l = Disc::LOWER;
        for (t, kind, w) in [
            (0.0, EventKind::Max(l), 5.0),
            (2.0, EventKind::Min(l), 1.0),
            (4.0, EventKind::Max(l), 4.0),
            (6.0, EventKind::Min(l), 2.0),
            (8.0, EventKind::Max(l), 3.5),
        ] {
            m.push(&ev(t, [0.0, 1.0, w], kind));
        }
        // Amplitudes 5 − 1 = 4 and 4 − 2 = 2 (each cycle's extremes include its end points).
        assert_eq!(m.period_drift(), Some(0.0));
        assert_eq!(m.amplitude_drift(), Some(0.5));
    }

    /// Skipping whole periods after an anchor gives the metrics of the full run, whether the
    /// anchor lies in the window or before it.
    #[test]
    fn fast_forward_keeps_the_metrics_of_the_skipped_run() {
        let l = Disc::LOWER;
        // A stick-slip cycle of period 3: exit, max, stick onset.
        let cycle = |k: f64| {
            [
                ev(3.0 * k, [2.2, 1.0, 0.0], EventKind::StickEnd(l)),
                ev(3.0 * k + 1.0, [1.0, 1.1, 3.0], EventKind::Max(l)),
                ev(3.0 * k + 2.5, [1.0, 0.9, 0.0], EventKind::StickStart(l)),
            ]
        };
        for t_from in [1.0, 20.0] {
            let mut full = MetricsAccumulator::new(t_from);
            for k in 0..12 {
                cycle(k as f64).iter().for_each(|e| full.push(e));
            }
            full.push(&cycle(12.0)[0]);
            // Skip cycles 3..=9 right after the exit at t = 9.
            let mut skip = MetricsAccumulator::new(t_from);
            for k in 0..3 {
                cycle(k as f64).iter().for_each(|e| skip.push(e));
            }
            let anchor = cycle(3.0)[0].clone();
            skip.push(&anchor);
            skip.fast_forward(&anchor, 21.0);
            for e in &cycle(10.0)[1..] {
                skip.push(e);
            }
            cycle(11.0).iter().for_each(|e| skip.push(e));
            skip.push(&cycle(12.0)[0]);
            let x = State::zeros();
            assert_eq!(skip.finish(&x), full.finish(&x), "t_from = {t_from}");
            assert!(
                matches!(full.finish(&x), RigSteady::LimitCycle { period, stick_time, .. }
                if period == 3.0 && stick_time == 0.5)
            );
        }
    }

    #[test]
    fn no_events_is_an_equilibrium() {
        let m = MetricsAccumulator::new(0.0);
        let x = State::new(1.0, 2.0, 2.0);
        assert_eq!(
            m.finish(&x),
            RigSteady::Equilibrium {
                omega_u: 2.0,
                omega_l: 2.0,
                alpha: 1.0
            }
        );
    }

    /// A chain of three: the cycle is anchored on the bottom disc (disc 3), every disc's
    /// extremes are kept, and each disc's stick time is its own; a stick exit of another disc
    /// is no anchor.
    #[test]
    fn a_chain_of_three_keeps_every_disc_and_anchors_on_the_bottom_one() {
        let mut m = MetricsAccumulator::for_discs(0.0, 3);
        let [d1, d2, d3] = [Disc::at(0), Disc::at(1), Disc::at(2)];
        // x = [α_1, α_2, ω_1, ω_2, ω_3]
        let x = |w1: f64, w2: f64, w3: f64| [0.1, 0.2, w1, w2, w3];
        let period = |k: f64| {
            let t = 10.0 * k;
            [
                Event::new(t, &x(1.0, 0.5, 0.0), EventKind::StickEnd(d3)),
                Event::new(t + 1.0, &x(1.2, 0.0, 0.4), EventKind::StickStart(d2)),
                Event::new(t + 3.0, &x(1.1, 0.0, 0.6), EventKind::StickEnd(d2)),
                Event::new(t + 4.0, &x(0.9, 2.0, 3.0), EventKind::Max(d3)),
                Event::new(t + 5.0, &x(0.8, 1.0, 2.0), EventKind::Max(d1)),
                Event::new(t + 6.0, &x(1.3, 0.7, 0.0), EventKind::StickStart(d3)),
            ]
        };
        for k in 0..4 {
            period(f64::from(k)).iter().for_each(|e| m.push(e));
        }
        m.push(&period(4.0)[0]);
        assert_eq!(
            m.finish_lists(&[0.0; 5]),
            SteadyState::LimitCycle {
                period: 10.0,
                omega_max: vec![1.3, 2.0, 3.0],
                omega_min: vec![0.8, 0.0, 0.0],
                stick_time: vec![Some(0.0), Some(2.0), Some(4.0)],
            }
        );
        assert_eq!(
            (m.period_drift(), m.amplitude_drift()),
            (Some(0.0), Some(0.0))
        );
        // Without events, the final state in the chain's lists.
        let rest = MetricsAccumulator::for_discs(0.0, 3);
        assert_eq!(
            rest.finish_lists(&x(1.0, 1.0, 1.0)),
            SteadyState::Equilibrium {
                alpha: vec![0.1, 0.2],
                omega: vec![1.0; 3],
            }
        );
    }
}
