//! `rotor sweep`: a (u, p) grid of steady states, one CSV row per point.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::common::{
    check, kind_by_name, load_model, parse_x0, progress_bar, sweep_flagged, thread_pool,
    threads_arg,
};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The u axis, A:B:N (N values from A to B), in V.
    #[arg(long)]
    pub u: String,
    /// The parameter axis, NAME=A:B:N (NAME a field of the parameter file).
    #[arg(long)]
    pub param: String,
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Initial state A,WU,WL (default rest), or `eq`: the perturbed equilibrium at each
    /// point (omega_l of the slipping equilibrium + 1e-3).
    #[arg(long, allow_hyphen_values = true)]
    x0: Option<String>,
    /// Solver (default event).
    #[arg(long, default_value = "event")]
    pub solver: String,
    /// Run only every N-th point from the I-th (I from 1), for job arrays.
    #[arg(long)]
    pub shard: Option<String>,
    /// Keep the rows already in the output and run only the rest.
    #[arg(long)]
    pub resume: bool,
    /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
    /// available to the process).
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    pub threads: Option<usize>,
    /// Horizon of each run, in s (metrics over its second half).
    #[arg(long, default_value_t = 600.0, allow_hyphen_values = true)]
    pub t_end: f64,
    /// Output CSV (`-`: standard output).
    #[arg(long)]
    pub csv: PathBuf,
}

pub fn run(a: &Args) -> Result<()> {
    sweep(
        &a.u,
        &a.param,
        a.params.as_deref(),
        a.x0.as_deref(),
        &a.solver,
        a.shard.as_deref(),
        (a.resume, a.t_end, a.threads),
        &a.csv,
    )
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep(
    u: &str,
    param: &str,
    params: Option<&Path>,
    x0: Option<&str>,
    solver: &str,
    shard: Option<&str>,
    (resume, t_end, threads): (bool, f64, Option<usize>),
    csv: &Path,
) -> Result<()> {
    use rayon::prelude::*;
    use rotor_harness::jobs::sweep::{Axis, Shard, Sweep, SweepStart, run};
    let model = load_model(params)?;
    let base = model.params;
    let (name, range) = param.split_once('=').ok_or_else(|| {
        crate::common::unusable(format_args!("--param {param:?}: expected NAME=A:B:N"))
    })?;
    check("t_end", t_end, t_end > 0.0, "must be positive and finite")?;
    let start = match x0 {
        Some("eq") => SweepStart::PerturbedEquilibrium,
        other => SweepStart::State(rotor_model::State::from_column_slice(&parse_x0(
            other,
            &model.state_names(),
        )?)),
    };
    let s = Sweep {
        base,
        u: Axis::parse("u", u).map_err(sweep_flagged)?,
        param: name.to_owned(),
        p: Axis::parse("param", range).map_err(sweep_flagged)?,
        start,
        solver: kind_by_name(solver)?,
        t_end,
    };
    let shard = shard
        .map(Shard::parse)
        .transpose()
        .map_err(sweep_flagged)?
        .unwrap_or(Shard::ALL);
    if resume && csv.as_os_str() == "-" {
        crate::common::refuse!("--resume needs an output file, not standard output");
    }
    let threads = thread_pool(threads)?;
    let total = shard.count(s.len());
    eprintln!(
        "sweep: {total} grid points to run ({} u x {} {name}{}) on {threads}",
        s.u.n,
        s.p.n,
        if total < s.len() {
            ", this shard's"
        } else {
            ""
        }
    );
    let bar = progress_bar(total as u64, "points");
    let t0 = std::time::Instant::now();
    let ran = run(&s, shard, csv, resume, |idx, f, sink| {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::scope(|scope| {
            scope.spawn(move || {
                idx.par_iter().for_each_with(tx, |tx, &i| {
                    let _ = tx.send((i, f(i)));
                });
            });
            for (i, row) in rx {
                bar.inc(1);
                sink(i, row);
            }
        });
    })
    .map_err(sweep_flagged)?;
    bar.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    eprintln!(
        "{ran} points in {secs:.2} s ({:.3} ms per point on {threads}){}",
        1e3 * secs / ran.max(1) as f64,
        if ran < total {
            format!("; {} already in {}", total - ran, csv.display())
        } else {
            String::new()
        }
    );
    Ok(())
}
