//! The [`Solver`] seam for the event-driven method.

use rotor_model::{
    Event, FastForward, MetricsAccumulator, Mode, Model, Output, OutputGrid, Sample, Scene,
    SolveError, Solver, State, Trajectory, Verdict,
};

use crate::dop853::Dense;
use crate::filippov::{EventOptions, Integrator, Sink};

/// The event-driven Filippov solver (Piiroinen & Kuznetsov): the project's accuracy reference.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EventSolver {
    pub options: EventOptions,
}

/// Collects what a scene asks for, and nothing else.
pub(crate) struct SceneSink {
    pub grid: Option<OutputGrid>,
    pub keep_steps: bool,
    pub keep_events: bool,
    pub samples: Vec<Sample>,
    pub events: Vec<Event>,
    pub metrics: Option<MetricsAccumulator>,
    /// Whole periods skipped for [`Output::Metrics`], and the verdict that stopped the run.
    pub fast_forward: Option<FastForward>,
    pub verdict: Verdict,
    pub anchor: Option<Event>,
}

impl SceneSink {
    pub fn new(scene: &Scene) -> SceneSink {
        let grid = scene.grid();
        let cap = match (grid, scene.output) {
            (Some(g), _) => g.len(),
            (None, Output::Steps) => 1024,
            _ => 0,
        };
        let mut s = SceneSink {
            grid,
            keep_steps: matches!(scene.output, Output::Steps),
            keep_events: scene.keeps_events(),
            samples: Vec::with_capacity(cap),
            events: Vec::new(),
            metrics: scene.metrics_start().map(MetricsAccumulator::new),
            fast_forward: None,
            verdict: Verdict::Continue,
            anchor: None,
        };
        if s.keep_steps {
            s.samples.push(Sample {
                t: 0.0,
                x: scene.x0,
            });
        }
        s
    }
}

impl Sink for SceneSink {
    fn step(&mut self, dense: &Dense<3>, t0: f64, t1: f64, x1: &State, _mode: Mode) {
        if let Some(g) = self.grid.as_mut() {
            while let Some(tg) = g.peek() {
                if tg > t1 {
                    break;
                }
                // Grid times before this step's start were written by the previous step.
                let x = if tg == t1 {
                    *x1
                } else {
                    dense.eval(tg.max(t0))
                };
                self.samples.push(Sample { t: tg, x });
                g.advance();
            }
        }
        if self.keep_steps {
            self.samples.push(Sample { t: t1, x: *x1 });
        }
    }

    fn event(&mut self, e: &Event) {
        if self.keep_events {
            self.events.push(*e);
        }
        if let Some(m) = self.metrics.as_mut() {
            m.push(e);
        }
    }

    fn stop_after(&mut self, e: &Event) -> bool {
        let Some(ff) = self.fast_forward.as_mut() else {
            return false;
        };
        self.verdict = ff.observe(e);
        self.anchor = Some(*e);
        self.verdict != Verdict::Continue
    }
}

impl Solver for EventSolver {
    fn name(&self) -> &'static str {
        "event"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        let mode0 = model.mode_at(&scene.x0, scene.u);
        let mut integ = Integrator::new(model, scene.u, scene.tol, self.options);
        integ.extrema = scene.metrics_start().is_some();
        let mut sink = SceneSink::new(scene);
        sink.fast_forward = FastForward::for_scene(scene, scene.tol)
            .map(|f| f.verify_within(self.options.skip_verify));
        let (mut t, mut x, mut mode) = (0.0, scene.x0, mode0);
        // The run end at a jump and the metrics there, to go back to if it is undone.
        let mut saved = None;
        let end = loop {
            let end = integ.run(t, x, mode, scene.t_end, &mut sink)?;
            let mut verdict = std::mem::replace(&mut sink.verdict, Verdict::Continue);
            if verdict == Verdict::Continue
                && let Some(ff) = sink.fast_forward.as_mut()
            {
                verdict = ff.finish();
            }
            match verdict {
                Verdict::Continue => break end,
                Verdict::Jump { dt } => {
                    saved = Some((end, sink.metrics));
                    if let (Some(m), Some(a)) = (sink.metrics.as_mut(), sink.anchor) {
                        m.fast_forward(&a, dt);
                    }
                    (t, x, mode) = (end.t + dt, end.x, end.mode);
                }
                Verdict::Undo => {
                    let (at, metrics) = saved.take().expect("a jump before its undo");
                    sink.metrics = metrics;
                    (t, x, mode) = (at.t, at.x, at.mode);
                }
            }
        };
        let metrics = sink.metrics.as_ref().map(|m| m.finish(&end.x));
        Ok(Trajectory {
            samples: sink.samples,
            events: sink.events,
            t_final: end.t,
            x_final: end.x,
            mode_final: end.mode,
            metrics,
            stats: FastForward::counted(sink.fast_forward.as_ref(), integ.stats),
        })
    }
}
