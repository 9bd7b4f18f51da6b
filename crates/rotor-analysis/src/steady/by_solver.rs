//! The bifurcation diagram by any solver: the periodic branches recomputed by shooting on the
//! solver's own return map ([`crate::shoot`]), each orbit from the event-driven continuation's
//! restart state at the same input, with its own multipliers and stability; and the special
//! points of the cycles (grazing orbits, smooth and discontinuous folds, other stability
//! changes) located again with that solver's own shooting and residuals
//! ([`crate::steady::solver_points`]).
//!
//! The equilibria and the points that belong to them (Hopf, the stuck boundary) are
//! properties of the equations, not of an integrator, and are the continuation's (shared).

use crate::bifurcation::{Diagram, PeriodicRow, PointKind};
use crate::shoot::{Section, shoot};
use crate::solvers::SolverKind;
use rayon::prelude::*;
use rotor_model::Model;
use serde::Serialize;

pub use crate::steady::orbit_rows::{BySolverOptions, NotFound};
use crate::steady::orbit_rows::{first_crossing, row_of, section_of, shoot_opts};
use crate::steady::solver_points;

/// A diagram and the solver that computed it (the JSON of `rotor bifurcation --solver`).
#[derive(Debug, Clone, Serialize)]
pub struct SolverDiagram {
    /// The solver's name (`event`, `switch`, `moreau`).
    pub solver: &'static str,
    /// Its diagram: branches, periodic rows and special points.
    #[serde(flatten)]
    pub diagram: Diagram,
    /// Kinds of special points this solver's diagram does not locate (empty: every solver
    /// now locates grazing orbits, folds and stability changes itself).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_located: Vec<&'static str>,
    /// Periodic rows of the continuation whose orbit this solver's shooting did not find
    /// (an orbit too close to a special point for a start one period off, say), and special
    /// points of the continuation this solver did not locate, each with the reason.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_found: Vec<NotFound>,
}

/// The event-driven continuation's diagram as one solver computes it (see the module docs),
/// every row re-shot.
pub fn by_solver(kind: SolverKind, model: &Model, event: &Diagram) -> SolverDiagram {
    by_solver_with(kind, model, event, &BySolverOptions::default())
}

/// [`by_solver`] with options (a stride over the rows, the solvers' accuracy). Rows and
/// points are computed in parallel on rayon's pool; the result does not depend on it.
pub fn by_solver_with(
    kind: SolverKind,
    model: &Model,
    event: &Diagram,
    opts: &BySolverOptions,
) -> SolverDiagram {
    if kind == SolverKind::EVENT {
        return SolverDiagram {
            solver: kind.name(),
            diagram: event.clone(),
            not_located: Vec::new(),
            not_found: Vec::new(),
        };
    }
    let stride = opts.stride.max(1);
    let n = event.periodic.len();
    // Every stride-th row, and the last one (a branch's end).
    let picked: Vec<&PeriodicRow> = event
        .periodic
        .iter()
        .enumerate()
        .filter(|(i, _)| i % stride == 0 || i + 1 == n)
        .map(|(_, r)| r)
        .collect();
    let (rows, located) = rayon::join(
        || {
            picked
                .par_iter()
                .map(|row| reshoot(kind, model, row, opts))
                .collect::<Vec<_>>()
        },
        || solver_points::locate(kind, model, event, opts),
    );
    let mut periodic = Vec::new();
    let mut not_found = Vec::new();
    for (row, r) in picked.iter().zip(rows) {
        match r {
            Ok(r) => periodic.push(r),
            Err(reason) => not_found.push(NotFound { u: row.u, reason }),
        }
    }
    let mut points: Vec<_> = event
        .points
        .iter()
        .filter(|p| matches!(p.kind, PointKind::Hopf | PointKind::StickLimit))
        .cloned()
        .collect();
    points.extend(located.points);
    not_found.extend(located.not_found);
    points.extend(solver_points::stability_changes(&periodic, &points));
    points.sort_by(|a, b| a.u.total_cmp(&b.u));
    SolverDiagram {
        solver: kind.name(),
        diagram: Diagram {
            equilibria: event.equilibria.clone(),
            periodic,
            points,
        },
        not_located: Vec::new(),
        not_found,
    }
}

/// One periodic row, found again by this solver from the row's restart state.
fn reshoot(
    kind: SolverKind,
    model: &Model,
    row: &PeriodicRow,
    opts: &BySolverOptions,
) -> Result<PeriodicRow, String> {
    let solver = &*kind.solver();
    let scene = opts.scene(kind, row.u);
    // The continuation's section first; next to a grazing orbit a stick phase shorter than
    // Moreau–Jean's step is not seen, so the other one second.
    let first = section_of(row);
    let other = match first {
        Section::StickExit => Section::LowerMax,
        Section::LowerMax => Section::StickExit,
    };
    let (section, z0) = first_crossing(solver, model, &scene, row.section_state, row.period, first)
        .map(|z| (first, z))
        .or_else(|e| {
            first_crossing(solver, model, &scene, row.section_state, row.period, other)
                .map(|z| (other, z))
                .map_err(|_| e)
        })?;
    let orbit = shoot(solver, model, &scene, section, &z0, &shoot_opts(row.period))
        .map_err(|e| e.to_string())?;
    row_of(solver, model, &scene, &orbit, row.branch)
}
