//! `rotor simulate`: one scene's trajectory, written as CSV.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::common::{Common, request, start, unusable, warn_inexact};

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Horizon, in s (default: the scenario's, else 100).
    #[arg(long, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// Output interval, in s (rows at 0, dt, 2dt, ..., t_end; it must divide t_end; default:
    /// the scenario's grid, else 0.01).
    #[arg(long, allow_hyphen_values = true)]
    pub dt: Option<f64>,
    /// Output CSV file (`-`: standard output).
    #[arg(long)]
    pub csv: PathBuf,
}

/// The horizon without a scenario or --t-end, in s.
pub const DEFAULT_T_END: f64 = 100.0;
/// The output interval without a scenario or --dt, in s.
pub const DEFAULT_DT: f64 = 0.01;

pub fn run(a: &Args) -> Result<()> {
    simulate(&a.common, a.t_end, a.dt, &a.csv)
}

/// Refuses an output interval given with --dt that does not divide the horizon: the rows
/// would leave the grid 0, dt, ..., t_end (dt = 5 over t_end = 1 wrote rows at 0 and 1).
/// The default interval (not asked for) draws a warning naming both instead. Within 1e-9 of
/// a whole number of steps, the grid's own time tolerance (BENCHMARK.md, the trace format).
pub(crate) fn check_grid(t_end: f64, dt: f64, given: bool) -> Result<()> {
    if !(t_end > 0.0 && dt > 0.0 && t_end.is_finite() && dt.is_finite()) {
        return Ok(()); // refused with its own words by the request's checks
    }
    let n = (t_end / dt).round();
    if n < 1.0 || (n * dt - t_end).abs() > 1e-9 * t_end.max(1.0) {
        if !given {
            eprintln!(
                "warning: the default --dt {dt} does not divide --t-end {t_end}: the last \
                 row, at t_end, is off the grid 0, dt, 2 dt, ..."
            );
            return Ok(());
        }
        return Err(unusable(format_args!(
            "--dt {dt}: does not divide --t-end {t_end} (the rows are at 0, dt, 2 dt, ..., \
             t_end; give a dt with t_end / dt a whole number)"
        )));
    }
    Ok(())
}

/// `rotor simulate` of a chain of N discs: `--x0` of the chain's 2N − 1 values, any solver
/// at its own setting (`--tol`, or `--h` for Moreau–Jean), a constant `--u` or an `--input`
/// in time; the trace headed with the chain's state names (`t,alpha_1,…,omega_N`).
fn simulate_chain(
    (kind, request): (
        rotor_analysis::solvers::SolverKind,
        rotor_harness::jobs::request::Request<'_>,
    ),
    chain: &rotor_model::ChainModel,
    (t_end, dt): (Option<f64>, Option<f64>),
    (scene_t_end, scene_dt): (f64, f64),
    csv_path: &Path,
) -> Result<()> {
    let t_end = t_end.unwrap_or(scene_t_end);
    let given = dt.is_some();
    let dt = dt.unwrap_or(scene_dt);
    check_grid(t_end, dt, given)?;
    let scene = request
        .scene(kind, t_end, rotor_model::seam::Output::Grid { dt })
        .map_err(crate::common::flagged)?;
    let traj = kind
        .simulate_chain(chain, &scene)
        .with_context(|| format!("solver {}", kind.name()))?;
    rotor_harness::compare::report::write_output_with(csv_path, |w| {
        rotor_harness::grade::trace::write_named_trace_to(
            w,
            &chain.state_names(),
            &traj.samples,
            dt,
        )
    })
    .with_context(|| format!("{}: cannot write", csv_path.display()))?;
    Ok(())
}

pub(crate) fn simulate(
    common: &Common,
    t_end: Option<f64>,
    dt: Option<f64>,
    csv_path: &Path,
) -> Result<()> {
    let chain = match &common.scenario {
        None => crate::common::chain_file(common)?,
        Some(p) => {
            // A scene of the chain tier: its chain, input, x0, horizon and grid, the solver's
            // own setting from the flags.
            let (path, is_chain) = crate::common::scene_path("SCENARIO", p)?;
            if is_chain {
                let sc = rotor_model::scenario::ChainScenario::from_file(&path)?;
                let model = sc.model();
                let kind = crate::common::chain_solver(common, &path, model.discs())?;
                let request = rotor_harness::jobs::request::Request {
                    solver: &common.solver,
                    u: sc.u,
                    input: sc.input.clone(),
                    x0: sc.x0.clone(),
                    tol: common.tol,
                    h: common.h,
                };
                return simulate_chain(
                    (kind, request),
                    &model,
                    (t_end, dt),
                    (sc.t_end, sc.dt),
                    csv_path,
                );
            }
            None
        }
    };
    if let Some((path, params)) = &chain
        && params.len() > 2
    {
        let model = rotor_model::ChainModel::new(params);
        let request = crate::common::chain_request(common, path, &model)?;
        return simulate_chain(
            request,
            &model,
            (t_end, dt),
            (DEFAULT_T_END, DEFAULT_DT),
            csv_path,
        );
    }
    let start = start(common)?;
    let sc = start.scenario.as_ref();
    let t_end = t_end.unwrap_or(sc.map_or(DEFAULT_T_END, |s| s.t_end));
    let given = dt.is_some();
    let dt = dt.unwrap_or(sc.map_or(DEFAULT_DT, |s| s.compare.dt));
    let (kind, scene) = request(common, &start)?
        .simulation(t_end, dt)
        .map_err(crate::common::flagged)?;
    check_grid(t_end, dt, given)?;
    let solver = kind.solver();
    let traj = solver
        .simulate_finite(&start.model, &scene)
        .with_context(|| format!("solver {}", solver.name()))?;
    warn_inexact(&traj.stats);
    // A chain file's columns are the chain's (a chain of two in chain form included); the
    // rig's file keeps the rig's names.
    let names = match &chain {
        Some((_, params)) => rotor_model::chain::chain_state_names(params.len()),
        None => rotor_model::state_names(traj.samples.dim()),
    };
    rotor_harness::compare::report::write_output_with(csv_path, |w| {
        rotor_harness::grade::trace::write_named_trace_to(w, &names, &traj.samples, dt)
    })
    .with_context(|| format!("{}: cannot write", csv_path.display()))?;
    Ok(())
}
