//! The bifurcation diagram by any solver: the periodic branches recomputed by shooting on the
//! solver's own return map ([`rotor_shoot`]), each orbit from the event-driven continuation's
//! restart state at the same input, with its own multipliers and stability.
//!
//! The equilibria and the points that belong to them (Hopf, the stuck boundary) are
//! properties of the equations, not of an integrator, and are the continuation's. Grazing
//! orbits and folds are properties of the cycles: this module does not locate them per
//! solver yet, and says so (`not_located`).

use rotor_bifurcation::{Diagram, PeriodicRow, PointKind};
use rotor_model::{Model, Output, Scene, SteadyState};
use rotor_shoot::{Section, ShootOptions, shoot};
use rotor_solvers::SolverKind;
use serde::Serialize;

/// A diagram and the solver that computed it (the JSON of `rotor bifurcation --solver`).
#[derive(Debug, Clone, Serialize)]
pub struct SolverDiagram {
    pub solver: &'static str,
    #[serde(flatten)]
    pub diagram: Diagram,
    /// Kinds of special points this solver's diagram does not locate (empty for the event
    /// solver, whose continuation locates every one).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_located: Vec<&'static str>,
    /// Periodic rows of the continuation whose orbit this solver's shooting did not find
    /// (an orbit too close to a special point for a start one period off, say).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_found: Vec<NotFound>,
}

/// A row the solver's shooting did not reproduce, and why.
#[derive(Debug, Clone, Serialize)]
pub struct NotFound {
    pub u: f64,
    pub reason: String,
}

/// The event-driven continuation's diagram as one solver computes it (see the module docs).
pub fn by_solver(kind: SolverKind, model: &Model, event: &Diagram) -> SolverDiagram {
    if kind == SolverKind::EVENT {
        return SolverDiagram {
            solver: kind.name(),
            diagram: event.clone(),
            not_located: Vec::new(),
            not_found: Vec::new(),
        };
    }
    let solver = kind.solver();
    let mut periodic = Vec::new();
    let mut not_found = Vec::new();
    for row in &event.periodic {
        match reshoot(&*solver, model, row) {
            Ok(r) => periodic.push(r),
            Err(reason) => not_found.push(NotFound { u: row.u, reason }),
        }
    }
    let points = event
        .points
        .iter()
        .filter(|p| matches!(p.kind, PointKind::Hopf | PointKind::StickLimit))
        .cloned()
        .collect();
    SolverDiagram {
        solver: kind.name(),
        diagram: Diagram {
            equilibria: event.equilibria.clone(),
            periodic,
            points,
        },
        not_located: vec!["grazing", "fold", "stability_change"],
        not_found,
    }
}

/// One periodic row, found again by this solver from the row's restart state.
fn reshoot(
    solver: &dyn rotor_model::Solver,
    model: &Model,
    row: &PeriodicRow,
) -> Result<PeriodicRow, String> {
    let scene = Scene {
        u: row.u,
        tol: 1e-10,
        h: 1e-3,
        ..Scene::default()
    };
    let start = rotor_model::State::new(
        row.section_state[0],
        row.section_state[1],
        row.section_state[2],
    );
    let (section, z0) = Section::of_run(solver, model, &scene, start, 2.0 * row.period + 0.2)
        .map_err(|e| e.to_string())?;
    let opts = ShootOptions::default();
    let orbit = shoot(solver, model, &scene, section, &z0, &opts).map_err(|e| e.to_string())?;
    let run = solver
        .simulate_finite(
            model,
            &Scene {
                x0: orbit.x,
                t_end: 2.0 * orbit.period + opts.skip,
                output: Output::Final,
                metrics_from: Some(0.0),
                ..scene
            },
        )
        .map_err(|e| e.to_string())?;
    let Some(SteadyState::LimitCycle {
        period,
        omega_l_max,
        omega_l_min,
        omega_u_min,
        stick_time,
        ..
    }) = run.metrics
    else {
        return Err(format!("no cycle read off the orbit: {:?}", run.metrics));
    };
    let mut multipliers = vec![[1.0, 0.0]];
    multipliers.extend(orbit.multipliers.iter().copied());
    if multipliers.len() == 2 {
        multipliers.push([0.0, 0.0]);
    }
    Ok(PeriodicRow {
        branch: row.branch,
        u: row.u,
        period,
        omega_l_max,
        omega_l_min,
        omega_u_min,
        stable: orbit.is_stable(),
        multipliers,
        stick_slip: section == Section::StickExit,
        stick_time,
        section_state: [orbit.x[0], orbit.x[1], orbit.x[2]],
    })
}
