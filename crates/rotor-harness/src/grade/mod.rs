//! Grading of an external trace (`rotor check`, the open benchmark's grade): trace and
//! events files, the reference solution, the metrics read off a sample grid, the steady
//! orbit, and the grade in significant digits.

#![warn(missing_docs)]

pub mod chain;
pub mod check;
pub mod gridmetrics;
pub mod orbit;
pub mod reference;
pub mod trace;
