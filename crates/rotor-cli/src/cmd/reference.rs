//! `rotor reference`: the open benchmark's reference data, written for every scenario.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rayon::prelude::*;
use rotor_harness::grade::reference;

use crate::common::{fixtures_dir, progress_bar, scene_path, thread_pool, threads_arg};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory (default: the current directory). The checkout's own reference
    /// data is rewritten only when asked for: `--out fixtures/reference`.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Only these scenarios (files, or names of the suite; repeatable; default: every
    /// scenario of the tier). Chain scenes and rig scenes are not mixed in one call: their
    /// references live in different directories.
    #[arg(long = "scenario", value_name = "SCENARIO")]
    pub scenario: Vec<PathBuf>,
    /// The suite's tier: `rig` (fixtures/scenarios, references in fixtures/reference) or
    /// `chain` (fixtures/chain/scenarios, references in fixtures/chain/reference).
    #[arg(long, default_value = "rig", value_parser = ["rig", "chain"])]
    pub tier: String,
    /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
    /// available to the process).
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    pub threads: Option<usize>,
}

pub fn run(a: &Args) -> Result<()> {
    let chain = a.tier == "chain";
    let files: Vec<PathBuf> = if a.scenario.is_empty() {
        let dir = fixtures_dir()?.join(if chain {
            "chain/scenarios"
        } else {
            "scenarios"
        });
        rotor_model::scenario::Scenario::list_dir(&dir)
            .with_context(|| format!("{}: cannot list scenarios", dir.display()))?
    } else {
        let mut files = Vec::new();
        for p in &a.scenario {
            let (path, is_chain) = scene_path("--scenario", p)?;
            if is_chain != chain {
                crate::common::refuse!(
                    "--scenario {}: a {} scene; its reference is written with --tier {}",
                    p.display(),
                    if is_chain { "chain" } else { "rig" },
                    if is_chain { "chain" } else { "rig" }
                );
            }
            files.push(path);
        }
        files
    };
    let threads = thread_pool(a.threads)?;
    if chain {
        let out = a.out.clone().unwrap_or_else(|| PathBuf::from("."));
        eprintln!(
            "chain-tier reference data of {} scene(s) into {} on {threads}: each run by the \
             event-driven solver at two tolerances and cross-checked by the other two",
            files.len(),
            out.display()
        );
        return write_chain_reference(&files, &out);
    }
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("."));
    eprintln!(
        "reference data of {} scenario(s) into {} on {threads}: each run by the event-driven \
         solver at two tolerances and cross-checked by the other two (the whole suite: about 3 s \
         on 2 cores)",
        files.len(),
        out.display()
    );
    write_reference(&files, &out)
}

/// `rotor reference [--out DIR]`: the reference files of the scenarios in `files`.
pub fn write_reference(files: &[PathBuf], out: &Path) -> Result<()> {
    let scenarios = files
        .iter()
        .map(|f| rotor_analysis::solvers::load_scenario(f))
        .collect::<Result<Vec<_>, _>>()?;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let bar = progress_bar(scenarios.len() as u64, "scenarios");
    let refs = scenarios
        .par_iter()
        .map(|s| {
            let r = reference::compute(s);
            bar.inc(1);
            r
        })
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    for r in &refs {
        let name = &r.json.scenario;
        for (path, bytes) in reference::paths(out, name)
            .iter()
            .zip(reference::to_files(r))
        {
            rotor_harness::compare::report::write_atomic(path, &bytes)
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

/// `rotor reference --tier chain [--out DIR]`: the reference files of the chain scenes in
/// `files`.
pub fn write_chain_reference(files: &[PathBuf], out: &Path) -> Result<()> {
    let scenes = files
        .iter()
        .map(|f| rotor_model::scenario::ChainScenario::from_file(f))
        .collect::<Result<Vec<_>, _>>()?;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let bar = progress_bar(scenes.len() as u64, "scenes");
    let refs = scenes
        .par_iter()
        .map(|s| {
            let r = rotor_harness::grade::chain::compute(s);
            bar.inc(1);
            r
        })
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    for (sc, r) in scenes.iter().zip(&refs) {
        for (path, bytes) in reference::paths(out, &sc.name)
            .iter()
            .zip(rotor_harness::grade::chain::to_files(sc, r))
        {
            rotor_harness::compare::report::write_atomic(path, &bytes)
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
        let worst = |pre: &str| {
            r.json
                .error
                .iter()
                .filter(|(k, _)| k.starts_with(pre))
                .map(|(_, &e)| e)
                .fold(0.0, f64::max)
        };
        crate::out::line(format_args!(
            "{}: {} discs, {} samples, {} events, {} significant digits; stated error omega \
             {:.1e} rad/s, event times {:.1e} s (tol {:e})",
            sc.name,
            sc.discs(),
            r.samples.len(),
            r.events.len(),
            r.json.trace_digits,
            worst("omega_"),
            worst("event_time"),
            r.json.tol,
        ))?;
    }
    crate::out::line(format_args!(
        "{} chain references in {}",
        refs.len(),
        out.display()
    ))?;
    Ok(())
}
