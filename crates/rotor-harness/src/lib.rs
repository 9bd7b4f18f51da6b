//! What is built around the solvers to judge them: the grade of outside traces (`grade`),
//! the cross-solver comparison and its gates (`compare`), the open benchmark's protocol and
//! job files (`protocol`, `jobs`), work-precision benchmarks (`bench`) and the report the
//! main job writes (`report`).

#![warn(missing_docs)]

pub mod bench;
pub mod compare;
pub mod grade;
pub mod jobs;
pub mod protocol;
pub mod report;
