//! The commands, one module each: its flags (`Args`) and its `run`.

pub mod bench;
pub mod bench_merge;
mod bench_out;
pub mod bifurcation;
pub mod bifurcation2;
pub mod check;
pub mod compare;
pub mod job;
pub mod merge;
pub mod reference;
pub mod scenarios;
pub mod simulate;
pub mod steady;
pub mod sweep;
