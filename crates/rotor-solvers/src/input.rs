//! Input refused before any run, worded once for every front end: a [`BadInput`] names the
//! input (as the Python argument: `t_end`, `x0`), its value and why.

use rotor_model::Num;
use thiserror::Error;

use crate::solvers::{SOLVERS, SolverKind};

/// An input refused before any run: its name (as the Python argument: `t_end`, `x0`), its
/// value as typed or printed, and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{name} = {value}: {reason}")]
pub struct BadInput {
    /// The input's name as the Python argument (`t_end`, `x0`); the command line's flag is
    /// the same with `-` for `_` ([`BadInput::as_flag`]).
    pub name: &'static str,
    /// The value as typed, or as [`Num`] prints a number.
    pub value: String,
    /// Why it is refused (the admissible range, or the valid names).
    pub reason: String,
}

impl BadInput {
    fn num(name: &'static str, v: f64, reason: impl Into<String>) -> BadInput {
        BadInput {
            name,
            value: Num(v).to_string(),
            reason: reason.into(),
        }
    }

    /// The same message as the command line spells it: `--t-end 0: must be positive and
    /// finite`.
    pub fn as_flag(&self) -> String {
        format!(
            "--{} {}: {}",
            self.name.replace('_', "-"),
            self.value,
            self.reason
        )
    }
}

/// Checks a number: finite and `ok`, else a [`BadInput`] naming it.
pub fn check_number(name: &'static str, v: f64, ok: bool, reason: &str) -> Result<(), BadInput> {
    if !v.is_finite() || !ok {
        return Err(BadInput::num(name, v, reason));
    }
    Ok(())
}

/// The solver of a name, or a [`BadInput`] listing the names.
pub fn solver_kind(name: &str) -> Result<SolverKind, BadInput> {
    SolverKind::by_name(name).ok_or_else(|| BadInput {
        name: "solver",
        value: format!("{name:?}"),
        reason: format!(
            "unknown solver (expected one of: {})",
            SOLVERS.map(SolverKind::name).join(", ")
        ),
    })
}
