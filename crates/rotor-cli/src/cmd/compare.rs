//! `rotor compare`, and the main job (`rotor` alone): the scenarios through every solver,
//! gated, and the report written ([`rotor_harness::report`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use rotor_model::Params;
use rotor_model::seam::RigSteady;

use crate::common::{fixtures_dir, progress_bar, scene_path, thread_pool, threads_arg};
use crate::out;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario files or names of the suite, rig or chain scenes (default: every scene of
    /// both tiers).
    pub scenarios: Vec<PathBuf>,
    /// Report directory.
    #[arg(long, default_value = "reports")]
    pub report: PathBuf,
    /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
    /// available to the process).
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    pub threads: Option<usize>,
}

pub fn run(a: &Args) -> Result<()> {
    compare(&a.scenarios, &a.report, false, a.threads)
}

/// The main job: `rotor compare` of every scenario into `reports/`, with the analysis
/// sections.
pub fn main_job(threads: Option<usize>) -> Result<()> {
    compare(&[], Path::new("reports"), true, threads)
}

/// `rotor compare`; with `main_job`, the report also gets the bifurcation diagrams.
pub(crate) fn compare(
    files: &[PathBuf],
    report: &Path,
    main_job: bool,
    threads: Option<usize>,
) -> Result<()> {
    // The rig's scenes and the chain tier's: every one of both by default.
    let whole_suite = files.is_empty();
    let (files, chain_files): (Vec<PathBuf>, Vec<PathBuf>) = if files.is_empty() {
        let list = |sub: &str| -> Result<Vec<PathBuf>> {
            let dir = fixtures_dir()?.join(sub);
            rotor_model::scenario::Scenario::list_dir(&dir)
                .with_context(|| format!("{}: cannot list scenarios", dir.display()))
        };
        (list("scenarios")?, list("chain/scenarios")?)
    } else {
        let mut rig = Vec::new();
        let mut chain = Vec::new();
        for f in files {
            let (path, is_chain) = scene_path("scenario", f)?;
            if is_chain { &mut chain } else { &mut rig }.push(path);
        }
        (rig, chain)
    };
    let mut chains = chain_files
        .iter()
        .map(|f| rotor_model::scenario::ChainScenario::from_file(f))
        .collect::<Result<Vec<_>, _>>()?;
    // A chaotic scene's statistics need every solver over its whole run (Moreau–Jean: 8·10⁶
    // steps, some 11 s): it is compared when named, not in the default run.
    if whole_suite {
        chains.retain(|c| c.chaos.is_none());
    }
    // A report of the suite opens with what Table 1 does; one of scenes given, with those.
    let scenes = if whole_suite {
        rotor_harness::compare::report::Scenes::Suite
    } else {
        rotor_harness::compare::report::Scenes::Given {
            chains: chains.iter().map(|c| c.name.clone()).collect(),
        }
    };
    let scenarios = files
        .iter()
        .map(|f| rotor_analysis::solvers::load_scenario(f))
        .collect::<Result<Vec<_>, _>>()?;
    // Report files are named after the scenarios: two of one name would overwrite each other.
    rotor_harness::report::check_names(&scenarios)?;
    let stribeck = Params::from_file(&fixtures_dir()?.join("params/stribeck.toml"))?;
    let threads = thread_pool(threads)?;
    eprintln!(
        "{} scenarios x {} solvers ({} runs){}{} on {threads}",
        scenarios.len(),
        rotor_analysis::solvers::SOLVERS.len(),
        scenarios.len() * rotor_analysis::solvers::SOLVERS.len(),
        if chains.is_empty() {
            String::new()
        } else {
            format!(
                ", {} chain scene(s) x 3 solvers at three settings each",
                chains.len()
            )
        },
        if main_job {
            ", then both bifurcation diagrams, the plane, the probes and the stress table \
             and the chain tier (about 13 s on 2 idle cores)"
        } else {
            ""
        }
    );
    let t0 = std::time::Instant::now();
    let bar = progress_bar(scenarios.len() as u64, "scenarios");
    let sets = rotor_harness::report::param_sets(stribeck);
    // The chain tier beside the rig's scenes and sections, so both cores stay busy.
    let (compared, chain) = rayon::join(
        || rotor_harness::report::run(&scenarios, &sets, main_job, &|| bar.inc(1)),
        || (!chains.is_empty()).then(|| rotor_harness::report::chain_section(&chains)),
    );
    let mut compared = compared?;
    bar.finish_and_clear();
    compared.sections.extend(chain);
    let wall = t0.elapsed().as_secs_f64();
    let fails = rotor_harness::report::write(report, &compared, stribeck, scenes)?;
    let (results, sections) = (&compared.results, &compared.sections);
    out::line(format_args!(
        "{:<18} {:<7} {:<12} {:>10} {:>12} {:>9}",
        "scenario", "solver", "steady", "period", "omega_l_max", "ms"
    ))?;
    for r in results {
        for run in &r.runs {
            let (kind, period, wmax) = match run.result.as_ref().ok().and_then(|t| t.rig_metrics())
            {
                Some(RigSteady::LimitCycle {
                    period,
                    omega_l_max,
                    ..
                }) => ("cycle", format!("{period:.6}"), format!("{omega_l_max:.6}")),
                Some(RigSteady::Equilibrium { omega_l, .. }) => {
                    ("equilibrium", "-".into(), format!("{omega_l:.6}"))
                }
                // A run without a steady window has no metrics; only a failed run is an error.
                None if run.result.is_ok() => ("-", "-".into(), "-".into()),
                None => ("error", "-".into(), "-".into()),
            };
            out::line(format_args!(
                "{:<18} {:<7} {:<12} {:>10} {:>12} {:>9.1}",
                r.scenario.name,
                run.kind.name(),
                kind,
                period,
                wmax,
                run.seconds * 1e3
            ))?;
        }
    }
    out::line(format_args!(
        "{} scenarios{}, {} solvers, {:.2} s wall; report in {}",
        results.len(),
        if chains.is_empty() {
            String::new()
        } else {
            format!(" and {} chain scene(s)", chains.len())
        },
        rotor_analysis::solvers::SOLVERS.len(),
        wall,
        report.display()
    ))?;
    let checks: Vec<&String> = sections.iter().flat_map(|s| &s.failures).collect();
    for f in &checks {
        eprintln!("CHECK FAILED: {f}");
    }
    for f in &fails {
        eprintln!("GATE FAILED: {f}");
    }
    match (fails.len(), checks.len()) {
        (0, 0) => {
            out::line(format_args!("all agreement gates pass"))?;
            Ok(())
        }
        (g, c) => bail!("{g} agreement gate(s) and {c} report check(s) failed"),
    }
}
