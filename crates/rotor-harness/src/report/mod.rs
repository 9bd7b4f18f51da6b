//! The main job's report (`cargo run --release`, and `rotor compare` without its sections):
//! every scenario through every solver, gated and written by [`crate::compare::report`], and
//! for the main job the analysis sections beside them: the bifurcation diagrams
//! ([`bifurcation`]), the same diagram by the three methods ([`figure3`]), the two-parameter pictures ([`plane`]), the numerical stress cases
//! ([`stress`]) and the steady states probed next to the special points ([`probes`]).
//!
//! The front end loads the scenarios and shows the progress; [`run()`] computes, [`write()`]
//! writes.

#![warn(missing_docs)]

pub mod bifurcation;
pub mod chain;
pub mod figure3;
mod job;
pub mod plane;
pub mod probes;
pub mod stress;

use std::path::PathBuf;

pub use bifurcation::bifurcation_section;
pub use chain::chain_section;
pub use figure3::figure3_section;
pub use job::{Compared, ParamSet, check_names, param_sets, run, sections, write};
pub use plane::plane_section;
pub use probes::probe_section;
pub use stress::stress_section;

/// Why the report could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// Two scenarios of one name: their report files would overwrite each other.
    #[error("{}: name = {name:?}: also the name of {}", path.display(), other.display())]
    DuplicateName {
        /// The later scenario's file.
        path: PathBuf,
        /// The name both have.
        name: String,
        /// The earlier scenario's file.
        other: PathBuf,
    },
    /// A parameter set's bifurcation diagram failed.
    #[error("bifurcation diagram of the {set} set")]
    Diagram {
        /// The parameter set's name.
        set: String,
        /// Why.
        #[source]
        source: rotor_analysis::bifurcation::BifError,
    },
    /// A two-parameter analysis failed.
    #[error("{set}: two-parameter analysis over {param}")]
    Plane {
        /// The parameter set's name.
        set: String,
        /// The parameter continued.
        param: String,
        /// Why.
        #[source]
        source: rotor_analysis::bifurcation::BifError,
    },
    /// A diagram or plane could not be written out as a file's contents.
    #[error(transparent)]
    Bifurcation(#[from] rotor_analysis::bifurcation::BifError),
    /// The report directory or one of its files could not be written.
    #[error("{}: cannot write the report", dir.display())]
    Write {
        /// The report directory.
        dir: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}
