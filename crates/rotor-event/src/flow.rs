//! The flow of the Filippov system as a function, for shooting and continuation.

use rotor_model::seam::{Event, EventKind, EventRef, SolveError, Stats};
use rotor_model::{Disc, Mode, Model, State};

use crate::filippov::{EventOptions, Integrator, Sink};
use nalgebra::U3;

/// Where a flow stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StopAt {
    /// At `t_max` only.
    Time,
    /// At the next exit of the lower disc from stick (or `t_max`).
    LowerStickExit,
    /// At the next upward crossing of `ω_l = c` (or `t_max`).
    Section(f64),
}

/// Where and how a flow ended.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowEnd {
    /// Time at the end \[s\], counted from the flow's start at t = 0 (so the return time
    /// when the stop condition was met).
    pub t: f64,
    /// The state `[α, ω_u, ω_l]` there.
    pub x: State,
    /// The friction modes there (after the stop event, for [`StopAt::LowerStickExit`]).
    pub mode: Mode,
    /// Whether the stop condition was met before `t_max`.
    pub reached: bool,
    /// Mode-switch events on the way (stick onsets and exits, reversals).
    pub events: Vec<Event>,
    /// Work counters of the flow (steps, evaluations, events).
    pub stats: Stats,
}

struct FlowSink {
    stop: StopAt,
    reached: bool,
    events: Vec<Event>,
}

impl Sink<U3> for FlowSink {
    fn event(&mut self, e: EventRef<'_>) {
        self.events.push(e.to_event());
    }
    fn stop_after(&mut self, e: EventRef<'_>) -> bool {
        let hit = self.stop == StopAt::LowerStickExit && e.kind == EventKind::StickEnd(Disc::LOWER);
        self.reached |= hit;
        hit
    }
    fn section(&mut self, _t: f64, _x: &State) -> bool {
        let hit = matches!(self.stop, StopAt::Section(_));
        self.reached |= hit;
        hit
    }
}

/// Integrates the Filippov system at input `u` from `(x, mode)` at t = 0 until `stop` or
/// `t_max`, with tolerance `tol`. In a stuck mode the disc's velocity is taken as 0.
pub fn flow(
    model: &Model,
    u: f64,
    tol: f64,
    x: State,
    mode: Mode,
    t_max: f64,
    stop: StopAt,
) -> Result<FlowEnd, SolveError> {
    let mut integ = Integrator::rig(model, u, tol, EventOptions::default());
    if let StopAt::Section(c) = stop {
        integ.section = Some(c);
    }
    let mut sink = FlowSink {
        stop,
        reached: false,
        events: Vec::new(),
    };
    let end = integ.run(0.0, x, mode, t_max, &mut sink)?;
    Ok(FlowEnd {
        t: end.t,
        x: end.x,
        mode: end.mode,
        reached: sink.reached,
        events: sink.events,
        stats: integ.stats,
    })
}
