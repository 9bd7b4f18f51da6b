//! Skipping whole periods of a converged cycle when a scene asks for the steady state only
//! ([`Output::Metrics`]).
//!
//! The metrics of a run are those of its last complete cycle in `[metrics_from, t_end]`
//! ([`crate::seam::MetricsAccumulator`]). Once the orbit is on a periodic orbit, every later cycle
//! repeats it, and integrating them changes nothing but the rounding. A [`FastForward`]
//! watches the run's returns to an *anchor*: the lower disc's exits from stick, or the maxima
//! of ω_l if the lower disc never sticks (the anchors the metrics use). Return n has the
//! signature `s_n = (x_n, P_n)`: the state there and the time since the previous return.
//!
//! **When to skip.** With the increments `d_n = ‖s_n − s_{n−1}‖` in units of the tolerance
//! (`max_i |Δs_i| / (tol·(1 + |s_i|))`, the solvers' own error norm) and their ratio
//! `ρ = d_n/d_{n−1}`, a return map that contracts geometrically by ρ per cycle has its fixed
//! point within `d_n·ρ/(1 − ρ)` of `s_n`. The ratio is read only while `d_{n−1}` stands above
//! the integration's noise ([`MIN_MEASURED_INCREMENT`] tolerances), and later returns keep
//! the last ratio so read: a ratio of two noise-level increments is no contraction rate. When
//! the bound is at most one tolerance and `ρ ≤ 1/2`, and the cycle's ω_l amplitude is at
//! least [`MIN_AMPLITUDE`] tolerances (not a focus closing onto an equilibrium), the orbit is
//! on its cycle to within one local error of the integration, and the run continues from
//! `(t_n + m·P_n, x_n)`: `m ≥ 1` whole periods later, chosen so that one complete cycle and the
//! tail to `t_end` are still integrated (the reported cycle is an integrated one) and that
//! cycle lies in the metrics window. A stick-slip orbit of the source's diagram contracts by
//! its nontrivial Floquet multiplier, 1e-5 (Table 1, 1.5 V) or 3e-8 (Stribeck), per cycle:
//! four returns (three increments) after the transient suffice. A slow cycle next to a special
//! point (ρ ≈ 0.65 just above H1, ≈ 0.9 next to the fold E) is not skipped: its ratio, read
//! above the noise, exceeds 1/2, and its increments fall into the noise before its bound
//! could be trusted.
//!
//! **Verification.** The first return after the jump must come back within
//! [`VERIFY_TOLERANCES`] of `s_n`. If it does not, or the run ends before it returns, the
//! solver goes back to the return it jumped from and integrates the skipped periods after all
//! ([`Verdict::Undo`]), watching the returns again: at most [`MAX_JUMPS`] jumps per run. A
//! false convergence (a ratio estimated from a transient cycle, a spiralling approach) costs
//! time, never accuracy. How often it undoes is in
//! `reports/measurements.md`.
//!
//! **What it changes.** The metrics (period, extremes, stick time) are invariant under the
//! shift; the skip moves them by the convergence bound, ≤ one tolerance, and the integration
//! of the cycle after it differs from a full run's by that run's own error. The final
//! state carries the phase error of the skipped periods, `m·|P_n − P*|`, of the same order as
//! the phase error a full run accumulates over those periods.

use crate::seam::event::{EventKind, EventRef};
use crate::seam::scene::{Output, Scene, Stats};
use crate::{Disc, OMEGA_L};

/// A return after the jump must lie within this many tolerances of the return before it: both
/// lie within one tolerance of the fixed point (the skip criterion), and the integration adds
/// at most about one more.
pub const VERIFY_TOLERANCES: f64 = 3.0;

/// Most jumps per run: after an undo the run watches its returns again (a ratio estimated
/// from a transient cycle may have been too small; later returns give a better one), at most
/// this many times in all.
pub const MAX_JUMPS: u32 = 3;

/// Largest contraction ratio per cycle for which the geometric bound is trusted. A choice, not
/// a derived value: the bound assumes one dominant multiplier, and a ratio misread from two
/// increments matters most when the contraction is slow, so slow ones (ρ > 1/2, where the
/// bound d_n·ρ/(1 − ρ) would exceed d_n itself) are not skipped; whatever passes wrongly is
/// caught by the check after the jump. The cycles skipped in practice contract by 1e-5 and
/// 3e-8 per period, so the value does not bind on them.
pub const MAX_RATIO: f64 = 0.5;

/// Smallest increment, in tolerances, from which the contraction ratio is taken. Once the
/// returns are within the integration's noise of the fixed point, their increments are that
/// noise (measured at the comparison settings: ≤ 0.3 tolerances for the adaptive solvers,
/// ≤ 0.05 h² for Moreau–Jean), and the ratio of two of them says nothing about the
/// contraction: a slow cycle (ρ ≈ 0.9 next to the fold E) shows ratios below
/// [`MAX_RATIO`] there by chance, while its returns are still d/(1 − ρ), several
/// tolerances, from the fixed point. So the ratio is the latest one whose older increment
/// stands at least this far above the noise (a factor of 7 over the largest noise seen),
/// and a cycle whose increments never do is not skipped. A choice, not a derived value.
pub const MIN_MEASURED_INCREMENT: f64 = 2.0;

/// Smallest ω_l amplitude of a cycle that may be skipped, in tolerances (relative to
/// 1 + |ω_l|). A focus decaying onto an equilibrium also has converging returns, but towards a
/// point: when the bound is below one tolerance, its amplitude is of the order of that
/// tolerance, and skipping would freeze an oscillation a full run damps out (and reports as an
/// equilibrium). A genuine cycle keeps its amplitude; the one integrated after the skip differs
/// from it by about two tolerances, ≤ 2 % of an amplitude of 100.
pub const MIN_AMPLITUDE: f64 = 100.0;

/// What a solver does after an event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Go on.
    Continue,
    /// Stop at this event and continue from its state `dt` later (whole periods).
    Jump {
        /// The time skipped \[s\]: a whole number of periods of the detected cycle.
        dt: f64,
    },
    /// The return after the jump does not confirm it: go back to the state at the jump and
    /// integrate from there, without skipping again.
    Undo,
}

/// The returns to one anchor.
#[derive(Debug, Clone, Copy)]
struct Track {
    kind: EventKind,
    /// Time of the last return.
    last: Option<f64>,
    /// Signature of the last return (needs the one before it).
    sig: Option<[f64; 4]>,
    /// Increment at the last return, in tolerances.
    d: Option<f64>,
    /// The latest contraction ratio `d_n/d_{n−1}` taken with `d_{n−1}` at least
    /// [`MIN_MEASURED_INCREMENT`] tolerances.
    rho: Option<f64>,
    /// Range of ω_l over the events since the last return.
    lo: f64,
    hi: f64,
}

impl Track {
    const fn new(kind: EventKind) -> Track {
        Track {
            kind,
            last: None,
            sig: None,
            d: None,
            rho: None,
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Phase {
    Watching,
    /// Jumped from the return with signature `sig` to `t_jump`; waiting for the next return.
    Verifying {
        track: usize,
        sig: [f64; 4],
        t_jump: f64,
    },
    Done,
}

/// Decides when a run may skip whole periods of a converged cycle (module docs).
#[derive(Debug, Clone, Copy)]
pub struct FastForward {
    tol: f64,
    t_from: f64,
    t_end: f64,
    tracks: [Track; 2],
    phase: Phase,
    verify: f64,
    jumps: u32,
    undos: u64,
    periods: u64,
}

impl FastForward {
    /// For a scene asking [`Output::Metrics`], with the solver's tolerance `tol` (relative =
    /// absolute); `None` for every other output, which integrates the whole horizon, and for a
    /// time-varying input ([`Scene::is_time_varying`]), whose run is not periodic.
    pub(crate) fn for_scene(scene: &Scene, tol: f64) -> Option<FastForward> {
        // A time-varying input breaks the premise of a skip: one period is not the next. The
        // returns are read on the rig's state (a chain's cycles cross their section many
        // times, and are not skipped).
        (scene.output == Output::Metrics && !scene.is_time_varying() && scene.x0.len() == 3)
            .then(|| FastForward::new(tol, scene.metrics_start().unwrap_or(0.0), scene.t_end))
    }

    /// Watches returns for metrics over `[t_from, t_end]` at tolerance `tol`.
    pub fn new(tol: f64, t_from: f64, t_end: f64) -> FastForward {
        FastForward {
            tol,
            t_from,
            t_end,
            tracks: [
                Track::new(EventKind::StickEnd(Disc::LOWER)),
                Track::new(EventKind::Max(Disc::LOWER)),
            ],
            phase: Phase::Watching,
            verify: VERIFY_TOLERANCES,
            jumps: 0,
            undos: 0,
            periods: 0,
        }
    }

    /// The same, with the return after a jump checked to within `v` tolerances instead of
    /// [`VERIFY_TOLERANCES`] (0 rejects every jump: a check of the solvers' undo).
    pub fn verify_within(self, v: f64) -> FastForward {
        FastForward { verify: v, ..self }
    }

    /// Skipped whole periods (0 if no jump, or if the jump was undone).
    pub fn skipped_periods(&self) -> u64 {
        self.periods
    }

    /// Jumps undone (each cost the cycle after it, and the skipped periods were integrated).
    pub fn undone_jumps(&self) -> u64 {
        self.undos
    }

    /// The counters of a run that may have skipped: `skipped_periods` and `undone_skips`.
    pub fn counted(ff: Option<&FastForward>, stats: Stats) -> Stats {
        Stats {
            skipped_periods: ff.map_or(0, |f| f.periods),
            undone_skips: ff.map_or(0, |f| f.undos),
            ..stats
        }
    }

    /// `‖a − b‖` in tolerances (module docs).
    fn distance(&self, a: &[f64; 4], b: &[f64; 4]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs() / (self.tol * (1.0 + x.abs().max(y.abs()))))
            .fold(0.0, f64::max)
    }

    /// Feeds an event (in time order, after the metrics have seen it).
    pub(crate) fn observe<'a>(&mut self, e: impl Into<EventRef<'a>>) -> Verdict {
        let e = e.into();
        match self.phase {
            Phase::Done => Verdict::Continue,
            Phase::Verifying { track, sig, t_jump } => {
                if e.kind != self.tracks[track].kind {
                    return Verdict::Continue;
                }
                let s = [e.x[0], e.x[1], e.x[2], e.t - t_jump];
                self.phase = Phase::Done;
                if self.distance(&s, &sig) <= self.verify {
                    Verdict::Continue
                } else {
                    self.undone();
                    Verdict::Undo
                }
            }
            Phase::Watching => self.watch(&e),
        }
    }

    fn watch(&mut self, e: &EventRef) -> Verdict {
        let w = e.x[OMEGA_L];
        for tr in &mut self.tracks {
            (tr.lo, tr.hi) = (tr.lo.min(w), tr.hi.max(w));
        }
        // Stick exits when the lower disc sticks at all, else maxima (as the metrics).
        let i = match e.kind {
            k if k == self.tracks[0].kind => 0,
            k if k == self.tracks[1].kind && self.tracks[0].last.is_none() => 1,
            _ => return Verdict::Continue,
        };
        let mut verdict = Verdict::Continue;
        let tr = self.tracks[i];
        let mut next = Track {
            last: Some(e.t),
            lo: w,
            hi: w,
            ..tr
        };
        let amplitude = tr.hi - tr.lo;
        let cycle = amplitude >= MIN_AMPLITUDE * self.tol * (1.0 + tr.lo.abs().max(tr.hi.abs()));
        if let Some(tp) = tr.last {
            let s = [e.x[0], e.x[1], e.x[2], e.t - tp];
            if let Some(sp) = tr.sig {
                let d = self.distance(&s, &sp);
                // The ratio of two increments is the contraction's only while the older one
                // stands above the integration's noise; two returns that repeat bit for bit
                // are a fixed point of the computed return map.
                if let Some(dp) = tr.d {
                    if dp >= MIN_MEASURED_INCREMENT {
                        next.rho = Some(d / dp);
                    } else if d == 0.0 && dp == 0.0 {
                        next.rho = Some(0.0);
                    }
                }
                if let Some(rho) = next.rho
                    && cycle
                    && rho <= MAX_RATIO
                    && d * rho / (1.0 - rho) <= 1.0
                {
                    verdict = self.jump(i, e.t, s);
                }
                next.d = Some(d);
            }
            next.sig = Some(s);
        }
        self.tracks[i] = next;
        verdict
    }

    /// The jump from a converged return at `t` with signature `s`, if the horizon leaves room
    /// for whole periods to skip.
    fn jump(&mut self, track: usize, t: f64, s: [f64; 4]) -> Verdict {
        let p = s[3];
        // Returns still to come in a full run: ⌊(t_end − t)/P⌋ (with a margin of 1e-6 P so
        // that the return after the jump is not lost to the phase error at t_end). Skip all
        // but the last, whose cycle is integrated.
        let m = ((self.t_end - t) / p - 1e-6).floor() - 1.0;
        if !(m >= 1.0 && p > 0.0) {
            return Verdict::Continue;
        }
        let dt = m * p;
        if t + dt < self.t_from {
            return Verdict::Continue;
        }
        self.phase = Phase::Verifying {
            track,
            sig: s,
            t_jump: t + dt,
        };
        self.periods = m as u64;
        self.jumps += 1;
        Verdict::Jump { dt }
    }

    /// At the end of the run: [`Verdict::Undo`] if a jump is still unconfirmed.
    pub fn finish(&mut self) -> Verdict {
        if let Phase::Verifying { .. } = self.phase {
            self.undone();
            Verdict::Undo
        } else {
            Verdict::Continue
        }
    }

    /// The run goes back to the return it jumped from, whose track is as it was then; it
    /// watches again unless it has jumped [`MAX_JUMPS`] times.
    fn undone(&mut self) {
        self.periods = 0;
        self.undos += 1;
        self.phase = if self.jumps < MAX_JUMPS {
            Phase::Watching
        } else {
            Phase::Done
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seam::Event;

    fn exit(t: f64, w: f64) -> Event {
        Event::new(t, &[2.0, w, 0.0], EventKind::StickEnd(Disc::LOWER))
    }

    /// Returns `t_n = n·P + c·ρⁿ`, `ω_n = w* + ρⁿ`: a return map contracting by ρ.
    fn returns(rho: f64, n: usize) -> Vec<Event> {
        (0..n)
            .map(|k| {
                let r = rho.powi(k as i32);
                exit(k as f64 * 4.0 + 0.1 * r, 2.5 + r)
            })
            .collect()
    }

    /// Feeds `evs` (with a maximum ω_l = 6 between successive stick exits) until a jump;
    /// the index is into `evs`.
    fn first_jump(ff: &mut FastForward, evs: &[Event]) -> Option<(usize, f64)> {
        evs.iter().enumerate().find_map(|(k, e)| {
            if e.kind == EventKind::StickEnd(Disc::LOWER) {
                let mut max = e.clone();
                (max.t, max.x[2], max.kind) = (e.t - 2.0, 6.0, EventKind::Max(Disc::LOWER));
                assert_eq!(ff.observe(&max), Verdict::Continue);
            }
            match ff.observe(e) {
                Verdict::Jump { dt } => Some((k, dt)),
                _ => None,
            }
        })
    }

    #[test]
    fn a_contraction_jumps_at_the_first_return_whose_bound_is_below_one_tolerance() {
        let tol = 1e-10;
        // t_end = 102, not on a return (a return at t_end exactly is the margin's case).
        let mut ff = FastForward::new(tol, 50.0, 102.0);
        // ρ = 0.01: the period increments dominate, P_k − P_{k−1} = 0.1·ρ^(k−2)·(1 − ρ)², so
        // d_k ≈ 0.098·ρ^(k−2)/(tol·(1 + 4)) and the bound d_k·ρ/(1−ρ) ≈ 2e8·ρ^(k−1) is
        // ≈ 2 at k = 5 and ≈ 0.02 at k = 6.
        let evs = returns(0.01, 12);
        let (k, dt) = first_jump(&mut ff, &evs).expect("a jump");
        assert_eq!(k, 6);
        let d = |k: usize| {
            let (a, b) = (&evs[k], &evs[k - 1]);
            let (c, e) = (&evs[k - 1], &evs[k - 2]);
            ff.distance(
                &[a.x[0], a.x[1], a.x[2], a.t - c.t],
                &[b.x[0], b.x[1], b.x[2], c.t - e.t],
            )
        };
        let bound = |k: usize| {
            let rho = d(k) / d(k - 1);
            d(k) * rho / (1.0 - rho)
        };
        assert!(
            bound(6) <= 1.0 && bound(5) > 1.0,
            "{} {}",
            bound(6),
            bound(5)
        );
        assert!(true_distance(&ff, &evs, k) <= 1.0);
        // m whole periods (of the last measured period, 4 s up to 1e-9), leaving one cycle
        // and the tail before t_end = 102, in the window [50, 102].
        let t = evs[k].t;
        let p = t - evs[k - 1].t;
        let m = dt / p;
        assert!((m - m.round()).abs() < 1e-12, "dt = {dt}");
        assert!(
            t + dt + p <= 102.0 && t + dt + 2.0 * p > 102.0,
            "t = {t}, dt = {dt}"
        );
        assert!(t + dt >= 50.0);
        // The next return (one period after the jump, the same state) confirms it.
        let back = exit(t + dt + p, evs[k].x[1]);
        assert_eq!(ff.observe(&back), Verdict::Continue);
        assert_eq!(ff.finish(), Verdict::Continue);
        assert_eq!(ff.skipped_periods() as f64 * p, dt);
        assert_eq!(ff.skipped_periods() as f64, m.round());
    }

    /// Distance in tolerances of return k's signature from the fixed point of [`returns`],
    /// `(2, 2.5, 0, 4)`.
    fn true_distance(ff: &FastForward, evs: &[Event], k: usize) -> f64 {
        let (a, b) = (&evs[k], &evs[k - 1]);
        ff.distance(&[a.x[0], a.x[1], a.x[2], a.t - b.t], &[2.0, 2.5, 0.0, 4.0])
    }

    #[test]
    fn a_slow_contraction_jumps_only_once_its_returns_repeat() {
        // ρ = 0.9 > MAX_RATIO: the ratio read while the increments stand above the noise is
        // kept, so the run does not jump on the geometric bound. It jumps once the returns
        // repeat bit for bit (a fixed point of the computed map; these returns carry no
        // noise), and then they are within a tolerance of the fixed point.
        let mut ff = FastForward::new(1e-10, 0.0, 1e6);
        let evs = returns(0.9, 400);
        let (k, _) = first_jump(&mut ff, &evs).expect("a jump once the returns repeat");
        let sig = |j: usize| [evs[j].x[1], evs[j].t - evs[j - 1].t];
        assert!(sig(k) == sig(k - 1) && sig(k - 1) == sig(k - 2), "k = {k}");
        assert!(true_distance(&ff, &evs, k) <= 1.0, "k = {k}");
    }

    #[test]
    fn noise_level_increments_give_no_contraction_ratio() {
        // A slow contraction (ρ = 0.9) whose returns carry an integration noise of up to 0.3
        // tolerances (a fixed pseudo-random sequence, as the switch model shows next to the
        // fold E). Once the contraction's own increments are below the noise, ratios of two
        // noisy increments fall below MAX_RATIO by chance while the returns are still
        // several tolerances from the fixed point; taken as the contraction's, they would
        // jump there (checked below with the ratio read at any increment).
        let tol = 1e-10;
        let noise = |k: usize| 0.3 * tol * 3.5 * ((k * 7919 % 101) as f64 / 50.0 - 1.0);
        let evs: Vec<Event> = (0..300)
            .map(|k| {
                let r = 1e-8 * 0.9f64.powi(k as i32);
                exit(k as f64 * 4.0, 2.5 + r + noise(k))
            })
            .collect();
        let mut ff = FastForward::new(tol, 0.0, 1e6);
        assert_eq!(first_jump(&mut ff, &evs), None);
        // The same returns, the ratio read from any two increments: a jump, from a return
        // more than a tolerance from the fixed point.
        let (k, _) = noisy_ratio_jump(&evs).expect("a jump on a noise-level ratio");
        assert!(true_distance(&ff, &evs, k) > 1.0, "k = {k}");
    }

    /// The first return at which the skip criterion holds with ρ read from the last two
    /// increments whatever their size (the rule without [`MIN_MEASURED_INCREMENT`]).
    fn noisy_ratio_jump(evs: &[Event]) -> Option<(usize, f64)> {
        let ff = FastForward::new(1e-10, 0.0, 1e6);
        let sig = |k: usize| {
            let (a, b) = (&evs[k], &evs[k - 1]);
            [a.x[0], a.x[1], a.x[2], a.t - b.t]
        };
        (3..evs.len()).find_map(|k| {
            let d = ff.distance(&sig(k), &sig(k - 1));
            let rho = d / ff.distance(&sig(k - 1), &sig(k - 2));
            (rho <= MAX_RATIO && d * rho / (1.0 - rho) <= 1.0).then_some((k, d))
        })
    }

    #[test]
    fn a_return_that_does_not_confirm_the_jump_undoes_it_and_watching_resumes() {
        let mut ff = FastForward::new(1e-10, 0.0, 1000.0);
        let evs = returns(1e-5, 30);
        let mut rest = &evs[..];
        let mut jumps = 0;
        while let Some((k, dt)) = first_jump(&mut ff, rest) {
            jumps += 1;
            // The return after the jump is 1e-8 rad/s off (≈ 30 tolerances): undone.
            let off = exit(rest[k].t + dt + 4.0, rest[k].x[1] + 1e-8);
            assert_eq!(ff.observe(&off), Verdict::Undo);
            assert_eq!(ff.skipped_periods(), 0);
            assert_eq!(ff.undone_jumps(), jumps as u64);
            // The run goes on from the return it jumped from.
            rest = &rest[k + 1..];
        }
        assert_eq!(jumps, MAX_JUMPS);
    }

    #[test]
    fn a_run_that_ends_before_the_confirming_return_undoes_the_jump() {
        let mut ff = FastForward::new(1e-10, 0.0, 100.0);
        first_jump(&mut ff, &returns(1e-5, 10)).expect("a jump");
        assert_eq!(ff.finish(), Verdict::Undo);
    }

    #[test]
    fn no_room_before_t_end_or_before_the_window_means_no_jump() {
        // The first possible jump is at the fourth return (t = 12, three increments); less
        // than two periods are left after it: nothing to skip.
        let mut ff = FastForward::new(1e-10, 0.0, 12.0 + 1.9 * 4.0);
        let evs = returns(1e-5, 5);
        assert_eq!(first_jump(&mut ff, &evs), None);
        // The metrics window starts after where the jump would land.
        let mut ff = FastForward::new(1e-10, 99.0, 100.0);
        assert_eq!(first_jump(&mut ff, &returns(1e-5, 10)), None);
    }

    /// Maxima of ω_l = 1 + a_k and minima 1 − a_k between them, every 4 s.
    fn slipping(a: impl Fn(usize) -> f64, n: usize) -> Vec<Event> {
        let ev = |t: f64, w: f64, kind| Event::new(t, &[2.0, 2.5, w], kind);
        (0..n)
            .flat_map(|k| {
                let t = 4.0 * k as f64;
                [
                    ev(t, 1.0 + a(k), EventKind::Max(Disc::LOWER)),
                    ev(t + 2.0, 1.0 - a(k), EventKind::Min(Disc::LOWER)),
                ]
            })
            .collect()
    }

    #[test]
    fn a_focus_decaying_onto_an_equilibrium_is_not_skipped() {
        // Returns converge geometrically (ρ = 0.3) — but to a point: the amplitude vanishes
        // with the distance, so it is below MIN_AMPLITUDE tolerances whenever the bound is met.
        let mut ff = FastForward::new(1e-10, 0.0, 1e6);
        let evs = slipping(|k| 0.3f64.powi(k as i32), 60);
        assert_eq!(first_jump(&mut ff, &evs), None);
    }

    #[test]
    fn maxima_anchor_only_an_orbit_without_stick() {
        // Maxima alone: a slipping cycle, jumps.
        let mut ff = FastForward::new(1e-10, 0.0, 100.0);
        let evs = slipping(|_| 0.5, 10);
        assert!(first_jump(&mut ff, &evs).is_some());
        // Once a stick exit has been seen, maxima are ignored.
        let mut ff = FastForward::new(1e-10, 0.0, 100.0);
        ff.observe(&exit(0.5, 2.5));
        assert_eq!(first_jump(&mut ff, &evs), None);
    }
}
