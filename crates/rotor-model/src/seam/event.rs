//! What happened during a run: the events a solver reports.

use crate::{Disc, State};

/// What happened at an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// The disc's velocity reached 0 and it sticks.
    StickStart(Disc),
    /// The stuck disc's applied torque left the stick interval; it slips again.
    StickEnd(Disc),
    /// The disc's velocity crossed 0 without sticking.
    Reversal(Disc),
    /// A local maximum of the disc's velocity (only when metrics are asked). The adaptive
    /// solvers report a turn only if ω moved by more than 10 tolerances since the extremum
    /// before it: smaller ones are below their resolution (rounding noise near equilibria).
    Max(Disc),
    /// A local minimum of the disc's velocity (only when metrics are asked).
    Min(Disc),
}

impl EventKind {
    /// The disc the event happened to.
    pub fn disc(self) -> Disc {
        match self {
            EventKind::StickStart(d)
            | EventKind::StickEnd(d)
            | EventKind::Reversal(d)
            | EventKind::Max(d)
            | EventKind::Min(d) => d,
        }
    }
}

/// An event with its time and the state there.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Time of the event \[s\], as the reporting solver located it.
    pub t: f64,
    /// The state at `t`, of the model's size (`[α, ω_u, ω_l]` for the rig: rad, rad/s,
    /// rad/s).
    pub x: Vec<f64>,
    /// What happened, and to which disc.
    pub kind: EventKind,
}

/// An event whose state is borrowed: what a solver hands to the [`crate::seam::Recorder`],
/// which copies the state only if it keeps the event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventRef<'a> {
    /// Time of the event \[s\].
    pub t: f64,
    /// The state at `t`, of the model's size.
    pub x: &'a [f64],
    /// What happened, and to which disc.
    pub kind: EventKind,
}

impl EventRef<'_> {
    /// The event with its own copy of the state.
    pub fn to_event(&self) -> Event {
        Event::new(self.t, self.x, self.kind)
    }
}

impl<'a> From<&'a Event> for EventRef<'a> {
    fn from(e: &'a Event) -> EventRef<'a> {
        EventRef {
            t: e.t,
            x: &e.x,
            kind: e.kind,
        }
    }
}

impl Event {
    /// The event `kind` at `(t, x)`.
    pub fn new(t: f64, x: &[f64], kind: EventKind) -> Event {
        Event {
            t,
            x: x.to_vec(),
            kind,
        }
    }

    /// The rig's state `[α, ω_u, ω_l]` at the event.
    ///
    /// # Panics
    ///
    /// If the event is not of the rig's size: a reader of the rig's state must be handed a
    /// rig's run.
    pub fn state(&self) -> State {
        assert_eq!(self.x.len(), 3, "a rig's event has 3 values");
        State::from_column_slice(&self.x)
    }
}
