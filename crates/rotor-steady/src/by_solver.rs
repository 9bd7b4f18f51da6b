//! The bifurcation diagram by any solver: the periodic branches recomputed by shooting on the
//! solver's own return map ([`rotor_shoot`]), each orbit from the event-driven continuation's
//! restart state at the same input, with its own multipliers and stability; and the special
//! points of the cycles (grazing orbits, smooth and discontinuous folds, other stability
//! changes) located again with that solver's own shooting and residuals
//! ([`crate::solver_points`]).
//!
//! The equilibria and the points that belong to them (Hopf, the stuck boundary) are
//! properties of the equations, not of an integrator, and are the continuation's (shared).

use rayon::prelude::*;
use rotor_bifurcation::{Diagram, PeriodicRow, PointKind};
use rotor_model::{Disc, EventKind, Model, OMEGA_L, OMEGA_U, Output, Scene, SteadyState};
use rotor_shoot::{Orbit, Section, ShootOptions, shoot};
use rotor_solvers::SolverKind;
use serde::Serialize;

use crate::solver_points;

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

/// A row or special point the solver's shooting did not reproduce, and why.
#[derive(Debug, Clone, Serialize)]
pub struct NotFound {
    /// The row's or point's input u \[V\].
    pub u: f64,
    /// Why the solver did not reproduce it (its error, or what it did not locate).
    pub reason: String,
}

/// Options of [`by_solver_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BySolverOptions {
    /// Re-shoot every `stride`-th periodic row of the continuation (1: every row). The
    /// special points are located whatever the stride.
    pub stride: usize,
    /// The switch model's (and the event solver's) tolerance: 1e-10, the comparisons'.
    pub tol: f64,
    /// Moreau–Jean's step \[s\]: 1e-3, the comparisons'.
    pub h: f64,
}

impl Default for BySolverOptions {
    fn default() -> Self {
        BySolverOptions {
            stride: 1,
            tol: 1e-10,
            h: 1e-3,
        }
    }
}

impl BySolverOptions {
    /// The scene of one solve at input `u`.
    pub fn scene(&self, u: f64) -> Scene {
        Scene {
            u,
            tol: self.tol,
            h: self.h,
            ..Scene::default()
        }
    }
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
                .map(|row| reshoot(&*kind.solver(), model, row, opts))
                .collect::<Vec<_>>()
        },
        || solver_points::locate(&*kind.solver(), model, event, opts),
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

/// Shooting options for an orbit of period about `period`: the first return is looked for
/// within 1.5 periods (plus 0.5 s) instead of the default 60 s horizon, which would integrate a
/// dozen periods to use one.
pub(crate) fn shoot_opts(period: f64) -> ShootOptions {
    ShootOptions {
        horizon: 1.5 * period + 0.5,
        ..ShootOptions::default()
    }
}

/// The section coordinates of the first crossing of `section` after the start (later than
/// `ShootOptions::skip`) of a run from `x` (a state on or near the orbit) at `scene.u`, within
/// 1.2 periods (plus 0.2 s): a start for shooting. One crossing rather than a settled run, so
/// that an unstable orbit's start has not drifted from it.
pub(crate) fn first_crossing(
    solver: &dyn rotor_model::Solver,
    model: &Model,
    scene: &Scene,
    x: [f64; 3],
    period: f64,
    section: Section,
) -> Result<Vec<f64>, String> {
    let t_end = 1.2 * period + 0.2;
    let run = solver
        .simulate_finite(
            model,
            &Scene {
                x0: rotor_model::State::new(x[0], x[1], x[2]),
                t_end,
                output: Output::Events,
                metrics_from: Some(0.0),
                ..*scene
            },
        )
        .map_err(|e| e.to_string())?;
    let (kind, pick): (EventKind, fn(&rotor_model::State) -> Vec<f64>) = match section {
        Section::StickExit => (EventKind::StickEnd(Disc::Lower), |x| vec![x[OMEGA_U]]),
        Section::LowerMax => (EventKind::Max(Disc::Lower), |x| {
            vec![x[OMEGA_U], x[OMEGA_L]]
        }),
    };
    run.events
        .iter()
        .find(|e| e.kind == kind && e.t > ShootOptions::default().skip)
        .map(|e| pick(&e.x))
        .ok_or_else(|| {
            format!(
                "no {} within {t_end:.3} s at u = {}",
                section.as_str(),
                scene.u
            )
        })
}

/// The section a continuation row's cycle is cut at.
pub(crate) fn section_of(row: &PeriodicRow) -> Section {
    if row.stick_slip {
        Section::StickExit
    } else {
        Section::LowerMax
    }
}

/// One periodic row, found again by this solver from the row's restart state.
fn reshoot(
    solver: &dyn rotor_model::Solver,
    model: &Model,
    row: &PeriodicRow,
    opts: &BySolverOptions,
) -> Result<PeriodicRow, String> {
    let scene = opts.scene(row.u);
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

/// The diagram row of a shot orbit: its metrics read off a run over two periods from the
/// fixed point, and its multipliers `[1, λ, 0]` (stick exit) or `[1, λ1, λ2]`.
pub(crate) fn row_of(
    solver: &dyn rotor_model::Solver,
    model: &Model,
    scene: &Scene,
    orbit: &Orbit,
    branch: usize,
) -> Result<PeriodicRow, String> {
    let skip = ShootOptions::default().skip;
    let run = solver
        .simulate_finite(
            model,
            &Scene {
                x0: orbit.x,
                t_end: 2.0 * orbit.period + skip,
                output: Output::Final,
                metrics_from: Some(0.0),
                ..*scene
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
        branch,
        u: scene.u,
        period,
        omega_l_max,
        omega_l_min,
        omega_u_min,
        stable: orbit.is_stable(),
        multipliers,
        stick_slip: orbit.section == Section::StickExit,
        stick_time,
        section_state: [orbit.x[0], orbit.x[1], orbit.x[2]],
    })
}
