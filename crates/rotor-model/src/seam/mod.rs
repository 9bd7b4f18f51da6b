//! The solver seam: what every solver of the two-disc rotor is asked ([`Scene`]), what it
//! returns ([`Trajectory`]: samples, [`Event`]s, counters, [`RigSteady`] metrics), and the
//! output contract written once for all of them ([`Recorder`], driven through a solver's
//! [`Integration`]).
//!
//! A solver crate depends on `rotor-model` for the equations and on this crate for its
//! interface, and on nothing else of the project's: the three solvers share no integration
//! code. docs/design.md describes the seam and why it is drawn here.

#![warn(missing_docs)]

pub mod attractor;
pub mod event;
pub mod fast_forward;
pub mod input;
pub mod record;
pub mod samples;
pub mod scene;
pub mod steady;

pub use attractor::Attractor;
pub use event::{Event, EventKind, EventRef};
pub use fast_forward::{FastForward, Verdict};
pub use input::{Input, Piece};
pub use record::{Integration, Recorder};
pub use samples::{Row, RowMut, Rows, RowsMut, Samples};
pub use scene::{
    Accuracy, Output, OutputGrid, Sample, Scene, SolveError, Solver, Stats, Trajectory,
    check_finite,
};
pub use steady::{MetricsAccumulator, RigSteady, SteadyKind, SteadyState};
