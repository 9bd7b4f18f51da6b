//! Cross-validation: identical scenarios through the three independent solvers, agreement
//! gates on θ̇_u and θ̇_l (a transient window, the steady state, and the whole run of every
//! pair of solvers, phase-aligned: [`whole`]), and the report.

#![warn(missing_docs)]

pub mod chain;
pub mod gate;
pub mod html;
pub mod margins;
pub mod report;
pub mod snapshot;
pub mod stress;
pub mod threads;
pub mod whole;

pub use gate::{Failure, GateResult, Measured, check_pair};
