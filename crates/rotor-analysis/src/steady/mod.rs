//! Steady states: a cycle or equilibrium found by continuation (the event-driven solver) or
//! by simulating until the metrics stop changing (every solver), and the probes next to the
//! bifurcation diagram's special points.

#![warn(missing_docs)]

pub mod by_solver;
pub mod chain;
pub mod checked;
mod compute;
pub mod figure3;
mod orbit_rows;
pub mod probes;
mod settle;
pub mod solver_points;
pub mod verify;

pub use compute::{
    SHOOT_RUN, SteadyAnswer, SteadyError, SteadyMethod, SteadyOptions, shot, simulated, steady,
};
pub use settle::{SettleError, SettleOptions, Settled, Unsettled, settle};
