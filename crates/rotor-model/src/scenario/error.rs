//! What a bad scenario file is refused with: [`ScenarioError`], and the helper that builds
//! its `Invalid` variant at a file's path.

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::FieldError;
use crate::params::{ParamsError, shown};

/// A scenario file could not be read or is not admissible.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{}: cannot read scenario file: {message}", shown(.path))]
    Io {
        /// The scenario file.
        path: PathBuf,
        /// The operating system's reason (not found, permission denied, too large, ...).
        message: String,
    },
    /// Not valid TOML, or a key is unknown, missing or of the wrong type.
    #[error("{}: {message}", shown(.path))]
    Parse {
        /// The scenario file.
        path: PathBuf,
        /// The parser's message on one line, naming the key.
        message: String,
    },
    /// A value is out of range.
    #[error("{}: {error}", shown(.path))]
    Invalid {
        /// The scenario file.
        path: PathBuf,
        /// The key at fault (`u`, `compare.dt`, `x0[2]`, ...), its value and why.
        error: FieldError,
    },
    /// The parameter file it names is bad. (Not a `#[source]`: the message already holds
    /// it, and a reporter that prints the chain would print it twice.)
    #[error("{}: params: {error}", shown(.path))]
    Params {
        /// The scenario file that names the parameter file.
        path: PathBuf,
        /// What is wrong with the parameter file (it names that file).
        error: ParamsError,
    },
}

/// Builds the [`ScenarioError::Invalid`] of the file at its path: the field, the value as
/// written back, and the reason.
#[derive(Clone, Copy)]
pub(crate) struct Bad<'a>(pub(crate) &'a Path);

impl Bad<'_> {
    pub(crate) fn at(self, field: &str, value: String, reason: &str) -> ScenarioError {
        ScenarioError::Invalid {
            path: self.0.to_owned(),
            error: FieldError::new(field, value, reason),
        }
    }
}
