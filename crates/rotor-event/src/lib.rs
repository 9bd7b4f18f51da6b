//! Event-driven Filippov solver for the rotor, after Piiroinen & Kuznetsov, "An event-driven
//! method to simulate Filippov systems with accurate computing of sliding motions",
//! ACM TOMS 34(3), 2008: exact sliding (stick) by Utkin's equivalent control, events located
//! on a 7th-order dense output and refined, DOP853 between events. The project's accuracy
//! reference.

#![warn(missing_docs)]

pub mod dop853;
mod filippov;
pub mod flow;
mod solver;
pub mod steady;
mod tableau;

pub use filippov::{DEFECT_LIMIT, EventOptions, LIFT_FRACTION, LIFT_RESOLUTION, step_bound};
pub use flow::{FlowEnd, StopAt, flow};
pub use solver::EventSolver;
pub use steady::{Method, Steady, SteadyOptions, steady_state};
