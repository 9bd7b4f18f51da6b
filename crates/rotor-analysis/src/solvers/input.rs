//! Input refused before any run, worded once for every front end: a [`FieldError`] names the
//! input (as the Python argument: `t_end`, `x0`), its value and why.

use rotor_model::FieldError;

use crate::solvers::registry::{SOLVERS, SolverKind};

/// Checks a number: finite and `ok`, else a [`FieldError`] naming it.
pub fn check_number(name: &str, v: f64, ok: bool, reason: &str) -> Result<(), FieldError> {
    if !v.is_finite() || !ok {
        return Err(FieldError::num(name, v, reason));
    }
    Ok(())
}

/// The solver of a name, or a [`FieldError`] listing the names.
pub fn solver_kind(name: &str) -> Result<SolverKind, FieldError> {
    SolverKind::by_name(name).ok_or_else(|| {
        FieldError::new(
            "solver",
            format!("{name:?}"),
            format!(
                "unknown solver (expected one of: {})",
                SOLVERS.map(SolverKind::name).join(", ")
            ),
        )
    })
}
