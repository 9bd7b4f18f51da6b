//! `rotor reference`: the open benchmark's reference data, written for every scenario.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rayon::prelude::*;
use rotor_grade::reference;

use crate::common::{checkout_fixtures, thread_pool, threads_arg};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory (default: fixtures/reference).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
    /// available to the process).
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    pub threads: Option<usize>,
}

pub fn run(a: &Args) -> Result<()> {
    let threads = thread_pool(a.threads)?;
    eprintln!("reference data on {threads}");
    let fixtures = checkout_fixtures();
    let out = a.out.clone().unwrap_or_else(|| default_out(&fixtures));
    write_reference(&fixtures.join("scenarios"), &out)
}

/// `rotor reference [--out DIR]`: the reference files of every scenario.
pub fn write_reference(scenarios_dir: &Path, out: &Path) -> Result<()> {
    let files = rotor_scenario::Scenario::list_dir(scenarios_dir)
        .with_context(|| format!("{}: cannot list scenarios", scenarios_dir.display()))?;
    let scenarios = files
        .iter()
        .map(|f| rotor_solvers::load_scenario(f))
        .collect::<Result<Vec<_>, _>>()?;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let refs = scenarios
        .par_iter()
        .map(reference::compute)
        .collect::<Result<Vec<_>, _>>()?;
    for r in &refs {
        let name = &r.json.scenario;
        for (path, bytes) in reference::paths(out, name)
            .iter()
            .zip(reference::to_files(r))
        {
            rotor_compare::report::write_atomic(path, &bytes)
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
        let worst = |n: &str| r.error(n);
        crate::out::line(format_args!(
            "{name}: {} samples, {} events, {} significant digits; stated error omega_l {:.1e} \
             rad/s, event times {:.1e} s",
            r.samples.len(),
            r.events.len(),
            r.json.trace_digits,
            worst("omega_l"),
            worst("event_time"),
        ))?;
    }
    crate::out::line(format_args!(
        "{} references in {}",
        refs.len(),
        out.display()
    ))?;
    Ok(())
}

/// The default reference directory.
pub fn default_out(fixtures: &Path) -> PathBuf {
    fixtures.join("reference")
}
