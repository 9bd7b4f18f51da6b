//! The whole run compared: every sample of α, ω_u and ω_l over `[0, t_end]` and every mode
//! switch and maximum of ω_l, with the phase that legitimately separates two correct runs taken out by
//! derivation, not by a wider gate.
//!
//! **Why the samples at equal times are not the quantity to gate.** On a stable cycle the
//! phase is neutral: a run whose period is off by a relative ε falls behind by ε·t, so at time
//! t its samples differ from the other's by up to `ε·t·max|ẋ|` while its orbit is as good as
//! the other's. An orbit that leaves an unstable equilibrium (the `eq-pert` scenes) first
//! amplifies the two runs' tiny differences of the departure into a fixed time offset, which
//! it then carries for the rest of the run. Both effects are a shift in time, not an error of
//! the shape, and they grow with t_end (or with the instability's amplification): measured at
//! equal times, the difference on the hard scenes is 20–500× the transient window's, and a
//! gate set on it would be too wide to catch a real error anywhere else.
//!
//! **The shift, measured where it is defined.** The two runs' mode switches (stick onsets,
//! stick exits and reversals of both discs) and maxima of ω_l are matched one to one in order
//! ([`matched_events`]): both runs must switch in the same sequence, or the gate fails. Their
//! time differences `Δt_k = t_B,k − t_A,k` ARE the phase, sampled at the instants where it is
//! sharply located. Between two matched anchors (the stick exits and the maxima of ω_l, whose
//! times are well conditioned: [`is_anchor`]) the phase is interpolated linearly in t (a
//! constant period error drifts linearly); before the first and after the last it is held at
//! the nearest anchor's. `whole_event_time` gates `max_k |Δt_k|` over every matched event.
//! Where the runs report different numbers of maxima (an oscillation decaying toward a stable
//! equilibrium below a solver's reporting threshold) the switches are matched alone; the phase
//! does not drift there.
//!
//! **The shape, with the phase taken out.** If B lags A by Δt(t), then
//! `B(t) = A(t − Δt) + e(t) = A(t) − Δt·Ȧ(t) + O(Δt²·Ä) + e(t)`, where e is the difference of
//! the shapes. So the phase-aligned difference
//!
//! ```text
//! r(t) = B(t) − A(t) + Δt(t)·Ȧ(t),      Ȧ(t) = f_mode(A(t), u)
//! ```
//!
//! is the shape error plus a remainder `Δt²·|Ä|/2` (for the fixtures: Δt ≤ 1e-4 s, |Ä| ≤ a few
//! hundred rad/s³, so below 1e-6 and in fact orders below the measured r). Ȧ is the model's
//! vector field at A's sample in A's mode there (a disc within the pair's stuck band of 0 whose
//! applied torque is inside its stick interval is stuck), so nothing is fitted. The expansion
//! holds only where neither run switches mode between t − |Δt| and t + |Δt|: a sample
//! within `|Δt_k|` of either run's k-th switch (one that lies between the two runs' switches,
//! or one step of the shift away from them) is not compared sample-wise; there the two runs
//! differ by at most `|Δt_k|` times the jump of ẋ, which is what `whole_event_time` gates. On
//! the 0.01 s grid and Δt ≤ 1e-4 s that excludes at most one sample per switch (counted in
//! [`WholeRun::excluded`]). `whole_alpha`, `whole_omega_u` and `whole_omega_l` gate
//! `max_t |r(t)|` of each component over every other sample.
//!
//! A run that goes wrong after the transient window then fails: a changed input or friction
//! or an offset changes the shape (r) or the event times (Δt) or both, and neither is excused
//! by the other (`tests/whole_run.rs`; docs/methods.md §7 has the measurements).

use rotor_model::seam::{Event, EventKind, Trajectory};
use rotor_model::{Disc, DiscMode, Mode, Model, State};

/// The whole-run differences of two runs of the same scene on the same grid.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WholeRun {
    /// Events matched (mode switches, and the maxima of ω_l where both runs report the same
    /// sequence of them); 0 where the switches differ.
    pub events: usize,
    /// Largest |Δt| of the matched events \[s\]; ∞ if the runs switch in different
    /// sequences, 0 if nothing is matched.
    pub event_time: f64,
    /// Largest phase-aligned difference |r| of α \[rad\], ω_u and ω_l \[rad/s\] over every
    /// sample not excluded; NaN if the grids differ (nothing compared must not read as
    /// agreement).
    pub aligned: [f64; 3],
    /// Largest difference at equal times (not aligned), per component: for the report, to show
    /// how much of it is phase.
    pub raw: [f64; 3],
    /// Samples left out of the aligned comparison: within a shift of a switch.
    pub excluded: usize,
    /// Whether the maxima of ω_l were matched (see [`matched_events`]).
    pub maxima: bool,
}

/// Whether an event is a mode switch: a kink of the trajectory.
pub fn is_switch(kind: EventKind) -> bool {
    matches!(
        kind,
        EventKind::StickStart(_) | EventKind::StickEnd(_) | EventKind::Reversal(_)
    )
}

/// Whether an event is matched between the two runs: a mode switch or a maximum of ω_l.
pub fn is_matched(kind: EventKind) -> bool {
    is_switch(kind) || kind == EventKind::Max(Disc::LOWER)
}

/// Whether a matched event anchors the phase: a stick exit (the spring's torque crosses the
/// stick limit at the rate k_θ·(ω_u − ω_l) ≠ 0, so its time is well conditioned) or a
/// maximum of ω_l. A stick onset is not: ω arrives at 0 with ω̇ that may be near 0 (the
/// Stribeck scenes), and the switch model's band η moves it by η/|ω̇|.
pub fn is_anchor(kind: EventKind) -> bool {
    matches!(kind, EventKind::StickEnd(_) | EventKind::Max(Disc::LOWER))
}

/// The matched events of two runs as `(t_A, Δt = t_B − t_A, kind)`, in time order: every
/// mode switch and every maximum of ω_l ([`is_matched`]), paired in order. Where the two
/// runs report different sequences of maxima but the same switches, the switches alone
/// (`maxima` false): the adaptive solvers report a turn of ω only once it moved by 10 of
/// their tolerances, so on an oscillation decaying toward a stable equilibrium the runs
/// stop reporting maxima at different amplitudes; there the phase does not drift and the
/// samples are compared at the switches' shift. `None` if the switches differ.
pub fn matched_events(a: &Trajectory, b: &Trajectory) -> Option<Matched> {
    let pair = |keep: fn(EventKind) -> bool| -> Option<Vec<(f64, f64, EventKind)>> {
        let pick = |tr: &Trajectory| -> Vec<Event> {
            tr.events.iter().filter(|e| keep(e.kind)).cloned().collect()
        };
        let (ea, eb) = (pick(a), pick(b));
        if ea.len() != eb.len() || ea.iter().zip(&eb).any(|(x, y)| x.kind != y.kind) {
            return None;
        }
        Some(
            ea.iter()
                .zip(&eb)
                .map(|(x, y)| (x.t, y.t - x.t, x.kind))
                .collect(),
        )
    };
    match pair(is_matched) {
        Some(events) => Some(Matched {
            events,
            maxima: true,
        }),
        None => pair(is_switch).map(|events| Matched {
            events,
            maxima: false,
        }),
    }
}

/// The events two runs share ([`matched_events`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Matched {
    /// `(t_A, Δt = t_B − t_A, kind)` in time order.
    pub events: Vec<(f64, f64, EventKind)>,
    /// Whether the maxima of ω_l are among them (the runs report the same sequence).
    pub maxima: bool,
}

/// Largest |Δt| of the two runs' mode switches matched in order, ∞ if their sequences differ
/// (0 without switches): the `event_time` of the reference's `cross_check`
/// (`fixtures/reference/*.json`), which matches the switches alone.
pub fn switch_time_difference(a: &Trajectory, b: &Trajectory) -> f64 {
    let pick = |tr: &Trajectory| -> Vec<Event> {
        tr.events
            .iter()
            .filter(|e| is_switch(e.kind))
            .cloned()
            .collect()
    };
    let (ea, eb) = (pick(a), pick(b));
    if ea.len() != eb.len() || ea.iter().zip(&eb).any(|(x, y)| x.kind != y.kind) {
        return f64::INFINITY;
    }
    ea.iter()
        .zip(&eb)
        .map(|(x, y)| (y.t - x.t).abs())
        .fold(0.0, f64::max)
}

/// The shift Δt(t): linear between matched switches, held before the first and after the
/// last, 0 without switches.
pub(crate) fn shift_at(shifts: &[(f64, f64)], t: f64) -> f64 {
    let Some(&(t0, d0)) = shifts.first() else {
        return 0.0;
    };
    if t <= t0 {
        return d0;
    }
    let i = shifts.partition_point(|s| s.0 <= t);
    if i >= shifts.len() {
        return shifts[shifts.len() - 1].1;
    }
    let ((ta, da), (tb, db)) = (shifts[i - 1], shifts[i]);
    if tb > ta {
        da + (db - da) * (t - ta) / (tb - ta)
    } else {
        db
    }
}

/// The mode of a sample of run A: a disc within `band` of 0 whose applied torque lies inside
/// its stick interval is stuck; otherwise it slips by the sign of its velocity (at exactly 0,
/// the way [`Model::mode_at`] decides).
pub fn sample_mode(model: &Model, x: &State, u: f64, band: f64) -> Mode {
    let mut m = model.mode_at(x, u);
    for d in Disc::BOTH {
        if x[d.index()].abs() <= band
            && model.friction(d).is_set_valued()
            && model.can_stick(d, x, u)
        {
            m.set(d, DiscMode::Stick);
        }
    }
    m
}

/// Compares runs `a` and `b` of a scene of `model` at input `u` over their whole grids
/// (see the module documentation); `band` is the pair's stuck band
/// ([`crate::compare::gate::stuck_band`]).
pub fn whole_run(model: &Model, u: f64, a: &Trajectory, b: &Trajectory, band: f64) -> WholeRun {
    let matched = matched_events(a, b);
    let maxima = matched.as_ref().is_some_and(|m| m.maxima);
    let matched = matched.map(|m| m.events);
    let (events, event_time) = match &matched {
        None => (0, f64::INFINITY),
        Some(m) => (
            m.len(),
            m.iter()
                .map(|x| x.1.abs())
                .fold(0.0, |m: f64, d| if d > m || d.is_nan() { d } else { m }),
        ),
    };
    let same_grid = a.samples.len() == b.samples.len()
        && !a.samples.is_empty()
        && a.samples.iter().zip(&b.samples).all(|(x, y)| x.t == y.t);
    if !same_grid {
        return WholeRun {
            events,
            event_time,
            aligned: [f64::NAN; 3],
            raw: [f64::NAN; 3],
            excluded: 0,
            maxima,
        };
    }
    // Without matched events the phase is unknown: compare at equal times (the event gate
    // fails anyway).
    let matched = matched.unwrap_or_default();
    let shifts: Vec<(f64, f64)> = matched
        .iter()
        .filter(|m| is_anchor(m.2))
        .map(|m| (m.0, m.1))
        .collect();
    // The windows around each switch where the expansion does not hold: from the earlier of
    // the two runs' switch to the later, widened by the shift there.
    let windows: Vec<(f64, f64)> = matched
        .iter()
        .filter(|m| is_switch(m.2))
        .map(|&(t, d, _)| {
            let s = shift_at(&shifts, t).abs();
            (t.min(t + d) - s, t.max(t + d) + s)
        })
        .collect();
    let max_nan = |m: f64, d: f64| if d > m || d.is_nan() { d } else { m };
    let (mut aligned, mut raw, mut excluded) = ([0.0f64; 3], [0.0f64; 3], 0);
    for (sa, sb) in a.samples.iter().zip(&b.samples) {
        let t = sa.t;
        for (i, r) in raw.iter_mut().enumerate() {
            *r = max_nan(*r, (sb.x[i] - sa.x[i]).abs());
        }
        // Windows are in time order and short: the first that does not end before t decides.
        let k = windows.partition_point(|w| w.1 < t);
        if windows[k..].iter().take(2).any(|w| w.0 <= t && t <= w.1) {
            excluded += 1;
            continue;
        }
        let dt = shift_at(&shifts, t);
        let xa = sa.state();
        let xdot = model.rhs(&xa, u, sample_mode(model, &xa, u, band));
        for (i, r) in aligned.iter_mut().enumerate() {
            *r = max_nan(*r, (sb.x[i] - sa.x[i] + dt * xdot[i]).abs());
        }
    }
    WholeRun {
        events,
        event_time,
        aligned,
        raw,
        excluded,
        maxima,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::seam::{Sample, Stats};
    use rotor_model::{DiscMode, Mode, State};

    fn ev(t: f64, kind: EventKind) -> Event {
        Event {
            t,
            x: vec![0.0; 3],
            kind,
        }
    }

    fn traj(events: Vec<Event>) -> Trajectory {
        Trajectory {
            samples: (0..=100)
                .map(|k| Sample {
                    t: k as f64 * 0.01,
                    x: State::new(0.0, 1.0, 0.0),
                })
                .collect(),
            events,
            t_final: 1.0,
            x_final: (State::zeros()).as_slice().to_vec(),
            mode_final: Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos),
            metrics: None,
            stats: Stats::default(),
        }
    }

    #[test]
    fn the_shift_is_linear_between_anchors_and_held_outside() {
        let s = [(1.0, 2e-6), (3.0, 4e-6)];
        assert_eq!(shift_at(&[], 5.0), 0.0);
        assert_eq!(shift_at(&s, 0.0), 2e-6);
        assert!((shift_at(&s, 2.0) - 3e-6).abs() < 1e-18);
        assert_eq!(shift_at(&s, 3.0), 4e-6);
        assert_eq!(shift_at(&s, 9.0), 4e-6);
    }

    /// Maxima are matched with the switches where both runs report the same sequence; where
    /// they do not, the switches alone; switches that differ are not matched at all.
    #[test]
    fn maxima_are_matched_only_where_both_runs_report_them() {
        let exit = EventKind::StickEnd(Disc::LOWER);
        let max = EventKind::Max(Disc::LOWER);
        let a = traj(vec![ev(0.1, exit), ev(0.3, max), ev(0.6, max)]);
        let b = traj(vec![
            ev(0.1 + 1e-6, exit),
            ev(0.3 + 2e-6, max),
            ev(0.6, max),
        ]);
        let m = matched_events(&a, &b).unwrap();
        assert!(m.maxima && m.events.len() == 3);
        let dt = whole_run(&Model::table1(), 1.5, &a, &b, 0.0).event_time;
        assert!((dt - 2e-6).abs() < 1e-15, "{dt:e}");
        // One maximum fewer (a decay's last one, below the solver's resolution).
        let c = traj(vec![ev(0.1 + 1e-6, exit), ev(0.3 + 2e-6, max)]);
        let m = matched_events(&a, &c).unwrap();
        assert!(!m.maxima && m.events.len() == 1);
        // Another switch: nothing matched, the event gate is infinite.
        let d = traj(vec![ev(0.1, EventKind::StickStart(Disc::LOWER))]);
        assert!(matched_events(&a, &d).is_none());
        let w = whole_run(&Model::table1(), 1.5, &a, &d, 0.0);
        assert!(w.event_time.is_infinite() && w.events == 0);
        // Upper-disc extrema are not matched (their count depends on the tolerance too).
        let e = traj(vec![
            ev(0.1, exit),
            ev(0.2, EventKind::Max(Disc::UPPER)),
            ev(0.3, max),
            ev(0.6, max),
        ]);
        assert!(matched_events(&a, &e).unwrap().maxima);
    }

    /// Grids that differ are not compared (NaN, which fails every gate), never agreement.
    #[test]
    fn different_grids_compare_nothing() {
        let a = traj(Vec::new());
        let mut b = a.clone();
        b.samples.truncate(b.samples.len() - 1);
        let w = whole_run(&Model::table1(), 1.5, &a, &b, 0.0);
        assert!(w.aligned.iter().chain(&w.raw).all(|x| x.is_nan()));
        let w = whole_run(&Model::table1(), 1.5, &a, &a, 0.0);
        assert_eq!((w.aligned, w.raw, w.event_time), ([0.0; 3], [0.0; 3], 0.0));
    }

    /// A sample between the two runs' switch (one run switched, the other not yet) is left
    /// out of the aligned comparison; the others are compared.
    #[test]
    fn samples_within_a_shift_of_a_switch_are_excluded() {
        let start = EventKind::StickStart(Disc::LOWER);
        let a = traj(vec![ev(0.5 - 1e-3, start)]);
        let b = traj(vec![ev(0.5 + 1e-3, start)]);
        let w = whole_run(&Model::table1(), 1.5, &a, &b, 0.0);
        assert_eq!(w.excluded, 1);
        assert_eq!(w.events, 1);
    }
}
