//! `rotor simulate`: one scene's trajectory, written as CSV.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::common::{Common, load_model, request, warn_inexact};

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Horizon, in s.
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Output interval, in s (rows at 0, dt, 2dt, ..., t_end).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    pub dt: f64,
    /// Output CSV file (`-`: standard output).
    #[arg(long)]
    pub csv: PathBuf,
}

pub fn run(a: &Args) -> Result<()> {
    simulate(&a.common, a.t_end, a.dt, &a.csv)
}

pub(crate) fn simulate(common: &Common, t_end: f64, dt: f64, csv_path: &Path) -> Result<()> {
    let (kind, scene) = request(common)?
        .simulation(t_end, dt)
        .map_err(crate::common::flagged)?;
    let model = load_model(common.params.as_deref())?;
    let solver = kind.solver();
    let traj = solver
        .simulate_finite(&model, &scene)
        .with_context(|| format!("solver {}", solver.name()))?;
    warn_inexact(&traj.stats);
    rotor_compare::report::write_output_with(csv_path, |w| {
        rotor_grade::trace::write_trace_to(w, &traj.samples, dt)
    })
    .with_context(|| format!("{}: cannot write", csv_path.display()))?;
    Ok(())
}
