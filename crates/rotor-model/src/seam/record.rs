//! The output contract of every solver, written once.
//!
//! A solver integrates and locates events; everything a [`Scene`] asks it to keep is the
//! [`Recorder`]'s job: samples on the output grid (from the step's own interpolant), the state
//! after every step, the event list, the steady-state metrics, the counter of located events,
//! and, for [`Output::Metrics`], the skip of whole converged periods ([`FastForward`]) with its
//! jump and undo. The solver hands over each accepted step ([`Recorder::step`]) and each event
//! in time order ([`Recorder::event`]), and lets [`Recorder::drive`] run it: the loop that
//! jumps, and goes back when a jump is not confirmed, is written here and nowhere else, over a
//! small [`Integration`] trait (advance, checkpoint, restore, shift).
//!
//! The solvers still share no integration code: what makes their comparison meaningful is
//! that they integrate independently, not that they record differently.

use crate::seam::event::{Event, EventKind, EventRef};
use crate::seam::fast_forward::{FastForward, Verdict};
use crate::seam::samples::Samples;
use crate::seam::scene::{Output, OutputGrid, Scene, SolveError, Stats, Trajectory};
use crate::seam::steady::MetricsAccumulator;
use crate::{Disc, Mode};

/// What a scene keeps of a run, collected as the solver goes.
#[derive(Debug, Clone)]
pub struct Recorder {
    grid: Option<OutputGrid>,
    keep_steps: bool,
    keep_events: bool,
    samples: Samples,
    /// A state the interpolant writes a grid sample into.
    scratch: Vec<f64>,
    events: Vec<Event>,
    metrics: Option<MetricsAccumulator>,
    fast_forward: Option<FastForward>,
    /// Located events, kept or not (`Stats::events`).
    count: u64,
    /// The fast-forward's verdict on the last event.
    verdict: Verdict,
    /// The event the last jump was decided on: its state's buffer is allocated with the
    /// recorder, so that a skip allocates nothing (the metrics-only run allocates no more
    /// than the full one).
    anchor: Event,
}

/// A solver's integration, as [`Recorder::drive`] runs it.
pub trait Integration {
    /// What the run goes back to when a jump is undone.
    type Checkpoint;

    /// Integrates on from the current point to the end of the scene, handing every accepted
    /// step and event to `rec`; returns early, after the event, when `rec` is
    /// [`halted`](Recorder::halted) (a jump or an undo was decided on that event).
    fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError>;

    /// The point to go back to if the jump decided on `anchor` is undone, taken where
    /// [`Integration::advance`] stopped.
    fn checkpoint(&self, anchor: &Event) -> Self::Checkpoint;

    /// Goes back to a checkpoint.
    fn restore(&mut self, checkpoint: Self::Checkpoint);

    /// Continues `dt` later (whole periods of the cycle) from where it stopped after `anchor`.
    fn shift(&mut self, anchor: &Event, dt: f64);
}

impl Recorder {
    /// The recorder of `scene`, whose run starts at `x0` (the state the solver starts from,
    /// kept as the first sample by [`Output::Grid`] and [`Output::Steps`]). `ff_tol` is the
    /// solver's error scale for the fast-forward (its tolerance; h² for Moreau–Jean), and
    /// `skip_verify` the number of those within which the return after a jump must confirm it
    /// ([`FastForward::verify_within`]).
    pub fn new(scene: &Scene, x0: &[f64], ff_tol: f64, skip_verify: f64) -> Recorder {
        let mut grid = scene.grid();
        let keep_steps = scene.output == Output::Steps;
        let mut samples =
            Samples::with_capacity(x0.len(), grid.map_or(usize::from(keep_steps), |g| g.len()));
        if keep_steps {
            samples.push(0.0, x0);
        }
        if let Some(g) = grid.as_mut()
            && g.peek().is_some_and(|t| t <= 0.0)
        {
            samples.push(0.0, x0);
            g.advance();
        }
        Recorder {
            grid,
            keep_steps,
            keep_events: scene.keeps_events(),
            samples,
            scratch: vec![0.0; x0.len()],
            events: Vec::new(),
            metrics: scene
                .metrics_start()
                .map(|t| MetricsAccumulator::for_discs(t, x0.len().div_ceil(2))),
            fast_forward: FastForward::for_scene(scene, ff_tol)
                .map(|f| f.verify_within(skip_verify)),
            count: 0,
            verdict: Verdict::Continue,
            anchor: Event::new(f64::NAN, x0, EventKind::StickEnd(Disc::LOWER)),
        }
    }

    /// Room for `n` more samples (a fixed-step solver knows its step count).
    pub fn reserve(&mut self, n: usize) {
        if self.keep_steps {
            self.samples.reserve(n);
        }
    }

    /// Whether events must be located at all: kept, or fed to the metrics.
    pub fn wants_events(&self) -> bool {
        self.keep_events || self.metrics.is_some()
    }

    /// Whether the extrema of the velocities must be located (for the metrics).
    pub fn wants_extrema(&self) -> bool {
        self.metrics.is_some()
    }

    /// An accepted step `[t0, t1]` ending at `x1`: the grid times in `(t0, t1]` are sampled
    /// from `interp`, the step's own interpolant, which writes the state at a time into a
    /// slice (`x1` at `t1` itself), and [`Output::Steps`] keeps `(t1, x1)`.
    pub fn step(&mut self, t0: f64, t1: f64, x1: &[f64], mut interp: impl FnMut(f64, &mut [f64])) {
        if let Some(g) = self.grid.as_mut() {
            while let Some(tg) = g.peek() {
                if tg > t1 {
                    break;
                }
                if tg == t1 {
                    self.samples.push(tg, x1);
                } else {
                    interp(tg.max(t0), &mut self.scratch);
                    self.samples.push(tg, &self.scratch);
                }
                g.advance();
            }
        }
        if self.keep_steps {
            self.samples.push(t1, x1);
        }
    }

    /// An event, in time order: counted, kept if the scene keeps events, fed to the metrics
    /// and to the fast-forward, whose verdict may halt the run after it.
    pub fn event<'a>(&mut self, e: impl Into<EventRef<'a>>) {
        let e = e.into();
        self.count += 1;
        if let Some(m) = self.metrics.as_mut() {
            m.push(e);
        }
        if let Some(ff) = self.fast_forward.as_mut() {
            self.verdict = ff.observe(e);
            // The anchor is read only when a jump is decided on it.
            if matches!(self.verdict, Verdict::Jump { .. }) {
                self.anchor.t = e.t;
                self.anchor.kind = e.kind;
                self.anchor.x.clear();
                self.anchor.x.extend_from_slice(e.x);
            }
        }
        if self.keep_events {
            self.events.push(e.to_event());
        }
    }

    /// A located switch that is not an event of the model (the switch model's band edges):
    /// counted in `Stats::events`, nothing else.
    pub fn count_switch(&mut self) {
        self.count += 1;
    }

    /// Whether the run must stop: a jump or an undo was decided on the last event.
    pub fn halted(&self) -> bool {
        self.verdict != Verdict::Continue
    }

    /// Runs `integ` to the end of the scene: after a jump decided on an anchor event it
    /// continues whole periods later (the metrics move with it), and after a jump that the
    /// next return does not confirm, or that the run's end leaves unconfirmed, it goes back to
    /// the checkpoint and integrates the skipped periods after all.
    ///
    /// # Example
    ///
    /// A toy "solver" that steps 1 s at a time along a known periodic solution, a triangle
    /// wave of period 4 s in ω_l with its maxima and minima as events. With
    /// [`Output::Metrics`] the recorder sees the cycle repeat, has the integration skip whole
    /// periods ([`Integration::shift`]), and still reports the cycle's metrics.
    ///
    /// ```
    /// use rotor_model::{Disc, DiscMode, Mode, State};
    /// use rotor_model::seam::{
    ///     Event, EventKind, EventRef, Integration, Output, Recorder, Scene, SolveError, Stats,
    ///     RigSteady,
    /// };
    ///
    /// /// ω_l = 2 + tri(t), tri of period 4 between −1 and 1: maxima at t = 1 + 4k.
    /// fn x(t: f64) -> State {
    ///     let s = t.rem_euclid(4.0);
    ///     let tri = if s < 1.0 { s } else if s < 3.0 { 2.0 - s } else { s - 4.0 };
    ///     State::new(0.0, 1.0, 2.0 + tri)
    /// }
    ///
    /// struct Toy {
    ///     t: f64,
    ///     t_end: f64,
    /// }
    ///
    /// impl Integration for Toy {
    ///     type Checkpoint = f64;
    ///     fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
    ///         while self.t < self.t_end {
    ///             let (t0, t1) = (self.t, self.t + 1.0);
    ///             // The exact solution is the interpolant.
    ///             rec.step(t0, t1, x(t1).as_slice(), |t, out| out.copy_from_slice(x(t).as_slice()));
    ///             self.t = t1;
    ///             let kind = match t1.rem_euclid(4.0) {
    ///                 1.0 => EventKind::Max(Disc::LOWER),
    ///                 3.0 => EventKind::Min(Disc::LOWER),
    ///                 _ => continue,
    ///             };
    ///             rec.event(EventRef { t: t1, x: x(t1).as_slice(), kind });
    ///             if rec.halted() {
    ///                 return Ok(()); // the recorder decided a jump (or an undo) here
    ///             }
    ///         }
    ///         Ok(())
    ///     }
    ///     fn checkpoint(&self, _anchor: &Event) -> f64 {
    ///         self.t
    ///     }
    ///     fn restore(&mut self, t: f64) {
    ///         self.t = t;
    ///     }
    ///     fn shift(&mut self, _anchor: &Event, dt: f64) {
    ///         self.t += dt;
    ///     }
    /// }
    ///
    /// let scene = Scene {
    ///     x0: x(0.0).as_slice().to_vec(),
    ///     t_end: 100.0,
    ///     output: Output::Metrics,
    ///     ..Scene::default()
    /// };
    /// let mut rec = Recorder::new(&scene, x(0.0).as_slice(), 1e-10, 3.0);
    /// let mut toy = Toy { t: 0.0, t_end: scene.t_end };
    /// rec.drive(&mut toy)?;
    /// let slip = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
    /// let tr = rec.finish(toy.t, x(toy.t).as_slice(), slip, Stats::default());
    ///
    /// assert_eq!(tr.t_final, 100.0);
    /// assert!(tr.stats.skipped_periods > 0, "whole periods were skipped, not integrated");
    /// let Some(RigSteady::LimitCycle { period, omega_l_max, omega_l_min, .. }) = tr.rig_metrics()
    /// else {
    ///     panic!("a cycle: {:?}", tr.rig_metrics())
    /// };
    /// assert_eq!((period, omega_l_max, omega_l_min), (4.0, 3.0, 1.0));
    /// # Ok::<(), SolveError>(())
    /// ```
    pub fn drive<I: Integration>(&mut self, integ: &mut I) -> Result<(), SolveError> {
        let mut saved: Option<(I::Checkpoint, Option<MetricsAccumulator>)> = None;
        loop {
            integ.advance(self)?;
            let mut verdict = std::mem::replace(&mut self.verdict, Verdict::Continue);
            if verdict == Verdict::Continue
                && let Some(ff) = self.fast_forward.as_mut()
            {
                verdict = ff.finish();
            }
            match verdict {
                Verdict::Continue => return Ok(()),
                Verdict::Jump { dt } => {
                    let anchor = &self.anchor;
                    saved = Some((integ.checkpoint(anchor), self.metrics));
                    if let Some(m) = self.metrics.as_mut() {
                        m.fast_forward(anchor, dt);
                    }
                    integ.shift(anchor, dt);
                }
                Verdict::Undo => {
                    let (c, metrics) = saved.take().expect("an undo follows a jump");
                    self.metrics = metrics;
                    integ.restore(c);
                }
            }
        }
    }

    /// The trajectory of a run that ended at `(t_final, x_final)` in `mode_final`, with the
    /// solver's own counters (`events`, `skipped_periods` and `undone_skips` are the
    /// recorder's). Grid times the run did not reach (none, for a run that reached `t_end`)
    /// get the final state.
    pub fn finish(
        mut self,
        t_final: f64,
        x_final: &[f64],
        mode_final: Mode,
        stats: Stats,
    ) -> Trajectory {
        if let Some(g) = self.grid.as_mut() {
            while let Some(tg) = g.peek() {
                self.samples.push(tg, x_final);
                g.advance();
            }
        }
        let metrics = self.metrics.as_ref().map(|m| m.finish_lists(x_final));
        Trajectory {
            samples: self.samples,
            events: self.events,
            t_final,
            x_final: x_final.to_vec(),
            mode_final,
            metrics,
            stats: FastForward::counted(
                self.fast_forward.as_ref(),
                Stats {
                    events: self.count,
                    ..stats
                },
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seam::event::EventKind;
    use crate::seam::steady::RigSteady;
    use crate::{Disc, DiscMode, State};

    /// A triangle wave of period 4 and amplitude 1 (exact in binary arithmetic).
    fn tri(t: f64) -> f64 {
        let s = t.rem_euclid(4.0);
        if s < 1.0 {
            s
        } else if s < 3.0 {
            2.0 - s
        } else {
            s - 4.0
        }
    }

    /// The "solution" of a test integration: ω_l = 2 + tri(t), maxima at 1 + 4k, minima at
    /// 3 + 4k, α = tri(t), ω_u = 1.
    fn x(t: f64) -> State {
        State::new(tri(t), 1.0, 2.0 + tri(t))
    }

    /// Steps of 1/4 s along [`x`] delayed by `offset`, its extrema as events; a jump adds
    /// `drift` to the delay (a phase error, so that the return after it does not confirm it).
    struct Triangle {
        t: f64,
        t_end: f64,
        offset: f64,
        drift: f64,
        steps: u64,
    }

    impl Integration for Triangle {
        type Checkpoint = (f64, f64);

        fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
            let offset = self.offset;
            let y = |t: f64| x(t - offset);
            while self.t < self.t_end {
                let t1 = (self.t + 0.25).min(self.t_end);
                // The next extremum: the odd integers of the delayed time.
                let mut k = (self.t - offset).floor() + 1.0;
                if k.rem_euclid(2.0) == 0.0 {
                    k += 1.0;
                }
                let te = k + offset;
                if te <= t1 {
                    let kind = if tri(k) > 0.0 {
                        EventKind::Max(Disc::LOWER)
                    } else {
                        EventKind::Min(Disc::LOWER)
                    };
                    rec.step(self.t, te, y(te).as_slice(), |t, o| {
                        o.copy_from_slice(y(t).as_slice())
                    });
                    self.steps += 1;
                    rec.event(&Event::new(te, y(te).as_slice(), kind));
                    self.t = te;
                    if rec.halted() {
                        return Ok(());
                    }
                    continue;
                }
                rec.step(self.t, t1, y(t1).as_slice(), |t, o| {
                    o.copy_from_slice(y(t).as_slice())
                });
                self.steps += 1;
                self.t = t1;
            }
            Ok(())
        }

        fn checkpoint(&self, anchor: &Event) -> (f64, f64) {
            assert_eq!(anchor.t, self.t, "the run stopped at its anchor");
            (self.t, self.offset)
        }

        fn restore(&mut self, (t, offset): (f64, f64)) {
            (self.t, self.offset) = (t, offset);
        }

        fn shift(&mut self, _anchor: &Event, dt: f64) {
            self.t += dt;
            self.offset += self.drift;
        }
    }

    const MODE: Mode = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);

    fn run(output: Output, drift: f64, verify: f64) -> (Trajectory, u64) {
        let scene = Scene {
            x0: x(0.0).as_slice().to_vec(),
            t_end: 100.0,
            output,
            metrics_from: (output != Output::Metrics).then_some(50.0),
            ..Scene::default()
        };
        let mut rec = Recorder::new(&scene, x(0.0).as_slice(), 1e-10, verify);
        let mut tri = Triangle {
            t: 0.0,
            t_end: 100.0,
            offset: 0.0,
            drift,
            steps: 0,
        };
        rec.drive(&mut tri).unwrap();
        let tr = rec.finish(
            tri.t,
            x(tri.t - tri.offset).as_slice(),
            MODE,
            Stats {
                steps: tri.steps,
                ..Stats::default()
            },
        );
        (tr, tri.steps)
    }

    #[test]
    fn grid_samples_come_from_the_interpolant_and_end_at_t_end() {
        let (tr, _) = run(Output::Grid { dt: 0.1 }, 0.0, 3.0);
        assert_eq!(tr.samples.len(), 1001);
        for (k, s) in tr.samples.iter().enumerate() {
            let t = if k == 1000 { 100.0 } else { k as f64 * 0.1 };
            assert_eq!(s.t, t);
            assert_eq!(s.x, x(t).as_slice(), "t = {t}");
        }
        assert_eq!(tr.events.len(), 50, "25 maxima and 25 minima in 100 s");
        assert_eq!(tr.stats.events, 50);
    }

    #[test]
    fn steps_keep_every_step_end_from_the_initial_state_on() {
        let (tr, steps) = run(Output::Steps, 0.0, 3.0);
        assert_eq!(tr.samples.len() as u64, steps + 1);
        assert_eq!((tr.samples.t(0), tr.samples.x(0)), (0.0, x(0.0).as_slice()));
        assert!(tr.samples.times().windows(2).all(|w| w[0] < w[1]));
        assert_eq!(tr.samples.last().unwrap().t, 100.0);
    }

    #[test]
    fn events_are_counted_even_when_not_kept() {
        let (fin, _) = run(Output::Final, 0.0, 3.0);
        assert!(fin.samples.is_empty() && fin.events.is_empty());
        assert_eq!(fin.stats.events, 50);
        let scene = Scene::default();
        let mut rec = Recorder::new(
            &Scene {
                output: Output::Final,
                ..scene
            },
            x(0.0).as_slice(),
            1e-10,
            3.0,
        );
        rec.count_switch();
        rec.count_switch();
        assert!(!rec.wants_events());
        let tr = rec.finish(1.0, x(0.0).as_slice(), MODE, Stats::default());
        assert_eq!((tr.stats.events, tr.events.len()), (2, 0));
    }

    #[test]
    fn metrics_are_those_of_the_last_cycle() {
        let (tr, _) = run(Output::Events, 0.0, 3.0);
        assert_eq!(
            tr.rig_metrics(),
            Some(RigSteady::LimitCycle {
                period: 4.0,
                omega_l_max: 3.0,
                omega_l_min: 1.0,
                omega_u_max: 1.0,
                omega_u_min: 1.0,
                stick_time: 0.0,
            })
        );
    }

    /// Metrics only: the cycle repeats exactly, so the run jumps 20 periods after four
    /// returns, integrates the cycle after the jump and the tail, and reports the full run's
    /// metrics.
    #[test]
    fn metrics_only_skips_converged_periods() {
        let (full, full_steps) = run(Output::Final, 0.0, 3.0);
        let (fast, steps) = run(Output::Metrics, 0.0, 3.0);
        assert_eq!(fast.rig_metrics(), full.rig_metrics());
        assert_eq!(
            (fast.stats.skipped_periods, fast.stats.undone_skips),
            (20, 0)
        );
        assert_eq!(
            steps,
            full_steps - 320,
            "80 s of 4 steps per second skipped"
        );
        assert!(fast.samples.is_empty() && fast.events.is_empty());
    }

    /// A jump whose next return does not confirm it (the integration lands 1 ms off after it)
    /// is undone: the run goes back and integrates the skipped periods, watches again, and
    /// ends with the full run's answer after at most three attempts.
    #[test]
    fn an_unconfirmed_jump_is_undone() {
        let (full, full_steps) = run(Output::Final, 0.0, 3.0);
        let (undone, steps) = run(Output::Metrics, 1e-3, 3.0);
        assert_eq!(undone.rig_metrics(), full.rig_metrics());
        assert_eq!(undone.stats.skipped_periods, 0);
        assert_eq!(
            undone.stats.undone_skips,
            u64::from(crate::seam::fast_forward::MAX_JUMPS)
        );
        assert!(
            steps > full_steps,
            "the cycles after each jump were integrated too"
        );
        assert_eq!(undone.x_final, full.x_final);
    }
}
