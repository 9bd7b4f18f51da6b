//! What the diagram by any solver ([`crate::steady::by_solver`]) and its special points
//! ([`crate::steady::solver_points`]) share: the options, a row not found, and re-shooting a
//! continuation's orbit on a solver's own map (a start one crossing from a state, the
//! shooting options for a period, the diagram row of a shot orbit).

use crate::bifurcation::PeriodicRow;
use crate::shoot::{Orbit, Section, ShootOptions};
use crate::solvers::{Knob, SolverKind};
use rotor_model::seam::{Accuracy, EventKind, Output, RigSteady, Scene};
use rotor_model::{Disc, Model, OMEGA_L, OMEGA_U};
use serde::Serialize;

/// A row or special point the solver's shooting did not reproduce, and why.
#[derive(Debug, Clone, Serialize)]
pub struct NotFound {
    /// The row's or point's input u \[V\].
    pub u: f64,
    /// Why the solver did not reproduce it (its error, or what it did not locate).
    pub reason: String,
}

/// Options of [`by_solver_with`](crate::steady::by_solver::by_solver_with).
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
    /// The scene of one solve by `kind` at input `u`, at its tolerance or its step.
    pub fn scene(&self, kind: SolverKind, u: f64) -> Scene {
        let accuracy = match kind.info().knob {
            Knob::Tolerance => Accuracy::Tol(self.tol),
            Knob::Step => Accuracy::Step(self.h),
        };
        Scene {
            u,
            accuracy,
            ..Scene::default()
        }
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
    solver: &dyn rotor_model::seam::Solver,
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
                x0: vec![x[0], x[1], x[2]],
                t_end,
                output: Output::Events,
                metrics_from: Some(0.0),
                ..scene.clone()
            },
        )
        .map_err(|e| e.to_string())?;
    let (kind, pick): (EventKind, fn(&rotor_model::State) -> Vec<f64>) = match section {
        Section::StickExit => (EventKind::StickEnd(Disc::LOWER), |x| vec![x[OMEGA_U]]),
        Section::LowerMax => (EventKind::Max(Disc::LOWER), |x| {
            vec![x[OMEGA_U], x[OMEGA_L]]
        }),
    };
    run.events
        .iter()
        .find(|e| e.kind == kind && e.t > ShootOptions::default().skip)
        .map(|e| pick(&e.state()))
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

/// The diagram row of a shot orbit: its metrics read off a run over two periods from the
/// fixed point, and its multipliers `[1, λ, 0]` (stick exit) or `[1, λ1, λ2]`.
pub(crate) fn row_of(
    solver: &dyn rotor_model::seam::Solver,
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
                x0: orbit.x.as_slice().to_vec(),
                t_end: 2.0 * orbit.period + skip,
                output: Output::Final,
                metrics_from: Some(0.0),
                ..scene.clone()
            },
        )
        .map_err(|e| e.to_string())?;
    let Some(RigSteady::LimitCycle {
        period,
        omega_l_max,
        omega_l_min,
        omega_u_min,
        stick_time,
        ..
    }) = run.rig_metrics()
    else {
        return Err(format!(
            "no cycle read off the orbit: {:?}",
            run.rig_metrics()
        ));
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
