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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Time of the event \[s\], as the reporting solver located it.
    pub t: f64,
    /// The state `[α, ω_u, ω_l]` at `t` (rad, rad/s, rad/s).
    pub x: State,
    /// What happened, and to which disc.
    pub kind: EventKind,
}
