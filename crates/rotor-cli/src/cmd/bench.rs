//! `rotor bench`: the work-precision benchmark (`--merge`: [`super::bench_merge`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use super::bench_out::{write_bench, write_results};
use crate::common::{check, fixture_path, fixtures_dir};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output JSON file (`-`: standard output).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Output SVG work-precision plot (error against run time, log-log; `-`: stdout).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Output CSV file (`-`: standard output).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// A short ladder over a 30 s horizon without peers (seconds instead of a minute).
    #[arg(long)]
    pub quick: bool,
    /// Skip the peers even when python3 with scipy / Siconos, or GNU Octave, is installed.
    #[arg(long)]
    pub no_peers: bool,
    /// An external solver, NAME=COMMAND (split as a shell splits words; no shell is
    /// run), started once per scene and setting with a job file's path appended
    /// (BENCHMARK.md). Repeatable.
    #[arg(long = "external", value_name = "NAME=COMMAND")]
    pub external: Vec<String>,
    /// Treat the external solver NAME as fixed-step (ladder of h instead of tol).
    #[arg(long = "fixed-step", value_name = "NAME")]
    pub fixed_step: Vec<String>,
    /// Seconds after which a client's run is killed (with its process group).
    #[arg(long, default_value_t = 60.0, allow_hyphen_values = true)]
    pub timeout: f64,
    /// Benchmark these scenarios (files, or names in fixtures/scenarios; their horizon,
    /// windows and grid) instead of the whole suite. Repeatable.
    #[arg(long = "scenario", value_name = "SCENARIO.toml")]
    pub scenario: Vec<PathBuf>,
    /// Only the scenes of this tier: table1 (only the lower disc sticks) or full (every
    /// rig scene); or chain: the chain tier's scenes (chains of N discs), each solver over
    /// its ladder and each --external client graded as `rotor check` grades a chain's trace
    /// (digits, loose, strict, run time), the table on stdout and --json, --svg, --csv
    /// written.
    #[arg(long, value_name = "TIER")]
    pub tier: Option<String>,
    /// Also write the published-results page (Markdown: digits per setting, cheapest
    /// setting per level, profiles per tier; reports/bench/results.md).
    #[arg(long, value_name = "FILE.md")]
    pub results: Option<PathBuf>,
    /// Run only every N-th scene from the I-th (I from 1), for job arrays; the report
    /// records the shard, and `--merge` joins the shards' reports.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Keep every external run's files (job.json, trace.csv, events.csv, stderr.txt) in
    /// DIR/CLIENT/SCENE/runK instead of deleting them.
    #[arg(long, value_name = "DIR")]
    pub keep: Option<PathBuf>,
    /// External clients (peers included) to run side by side, each single-threaded with
    /// its runs one after the other (default: 2, or 1 on a one-core machine). The Rust
    /// solvers are timed first, alone. 1 gives the quietest times.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Run the chain scaling study instead of the suite: chains of N = 2 … 64 discs (the
    /// rig's top disc and N − 1 copies of its lower disc), each solver that runs chains at
    /// the loosest setting within one error, and Siconos' MoreauJeanOSI at Moreau–Jean's h
    /// when installed (--no-peers: not); the table on stdout, --json, --svg and --csv
    /// written. With --quick: N = 2, 4, 8 over 5 s.
    #[arg(
        long,
        conflicts_with_all = ["shard", "external", "fixed_step", "scenario", "keep", "tier", "jobs", "results"]
    )]
    pub scaling: bool,
    /// Run nothing: join the reports of `--shard` runs (any order) into the report one
    /// run writes, timings aside (BENCHMARK.md), written with --json, --svg, --csv.
    #[arg(
        long,
        value_name = "SHARD.json",
        num_args = 1..,
        conflicts_with_all = ["shard", "quick", "no_peers", "external", "fixed_step", "scenario", "keep", "tier", "jobs", "scaling"]
    )]
    pub merge: Vec<PathBuf>,
}

pub fn run(a: &Args) -> Result<()> {
    let outputs = [a.json.as_deref(), a.svg.as_deref(), a.csv.as_deref()];
    if !a.merge.is_empty() {
        return super::bench_merge::bench_merge(&a.merge, outputs, a.results.as_deref());
    }
    if a.scaling {
        return scaling(outputs, a.quick, a.no_peers, a.timeout);
    }
    if a.tier.as_deref() == Some("chain") {
        for (flag, given) in [
            ("--shard", a.shard.is_some()),
            ("--results", a.results.is_some()),
            ("--keep", a.keep.is_some()),
            ("--jobs", a.jobs.is_some()),
        ] {
            if given {
                crate::common::refuse!("{flag}: not with --tier chain (the rig's suite only)");
            }
        }
        return chain_tier(outputs, a);
    }
    bench(
        outputs,
        a.quick,
        a.no_peers,
        BenchClients {
            external: &a.external,
            fixed_step: &a.fixed_step,
            timeout: a.timeout,
            scenarios: &a.scenario,
            shard: a.shard.as_deref(),
            keep: a.keep.as_deref(),
            jobs: a.jobs,
            tier: a.tier.as_deref(),
            results: a.results.as_deref(),
        },
    )
}

/// `rotor bench`'s external clients and scenes.
pub(crate) struct BenchClients<'a> {
    external: &'a [String],
    fixed_step: &'a [String],
    timeout: f64,
    scenarios: &'a [PathBuf],
    shard: Option<&'a str>,
    keep: Option<&'a Path>,
    jobs: Option<usize>,
    tier: Option<&'a str>,
    results: Option<&'a Path>,
}

pub(crate) fn bench(
    [json, svg, csv]: [Option<&Path>; 3],
    quick: bool,
    no_peers: bool,
    clients: BenchClients,
) -> Result<()> {
    let mut opts = if quick {
        rotor_harness::bench::BenchOptions::quick()
    } else {
        rotor_harness::bench::BenchOptions::default()
    };
    if no_peers {
        opts.peers.scipy = false;
        opts.peers.siconos = false;
        opts.peers.octave = false;
    }
    check(
        "timeout",
        clients.timeout,
        clients.timeout > 0.0,
        "must be positive and finite",
    )?;
    opts.timeout = clients.timeout;
    for e in clients.external {
        opts.clients.push(
            rotor_harness::bench::ClientSpec::parse(e, clients.fixed_step)
                .map_err(crate::common::flagged)?,
        );
    }
    for name in clients.fixed_step {
        if !opts.clients.iter().any(|c| &c.name == name) {
            crate::common::refuse!("--fixed-step {name:?}: no --external client of that name");
        }
    }
    let tier = clients
        .tier
        .map(rotor_harness::bench::Tier::parse)
        .transpose()
        .map_err(crate::common::unusable)?;
    if !clients.scenarios.is_empty() {
        let paths = clients
            .scenarios
            .iter()
            .map(|p| fixture_path("--scenario", p, "scenarios"))
            .collect::<Result<Vec<_>>>()?;
        opts.scenes = rotor_harness::bench::select(&paths, tier)?;
    } else if !quick {
        opts.scenes = rotor_harness::bench::suite(&fixtures_dir()?.join("scenarios"), tier)?;
    }
    opts.shard = clients
        .shard
        .map(rotor_harness::jobs::sweep::Shard::parse)
        .transpose()
        .map_err(crate::common::sweep_flagged)?;
    opts.keep = clients.keep.map(Path::to_path_buf);
    opts.jobs = match clients.jobs {
        Some(0) => crate::common::refuse!("--jobs 0: at least one client must run at a time"),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get().min(2)),
    };
    eprintln!("{}", plan(&opts));
    // One line per step, as always; on a terminal a spinner below them with the count and
    // the elapsed time, so a run of minutes shows that it moves.
    let spinner = crate::common::progress_spinner("bench");
    let mut steps = 0usize;
    let report = rotor_harness::bench::run(&opts, |m| {
        steps += 1;
        if spinner.is_hidden() {
            eprintln!("{m}");
        } else {
            spinner.println(m);
            spinner.set_message(format!("bench: {steps} steps"));
        }
    });
    spinner.finish_and_clear();
    let report = report?;
    write_bench(&report, [json, svg, csv])?;
    write_results(&report, clients.results)?;
    // The report is written first (nothing is lost); then a named client that placed no
    // point on any scene fails the command, by name (a peer that is not installed does not).
    let unsolved: Vec<String> = report
        .clients
        .iter()
        .filter(|c| !c.peer && c.status != rotor_harness::bench::ClientStatus::Ran)
        .map(|c| {
            format!(
                "{} ({})",
                c.name,
                c.reason.as_deref().unwrap_or("no usable trace")
            )
        })
        .collect();
    if !unsolved.is_empty() {
        bail!(
            "--external: solved no scene: {}{}",
            unsolved.join("; "),
            clients.keep.map_or(String::new(), |d| format!(
                " (runs kept in {})",
                d.display()
            ))
        );
    }
    Ok(())
}

/// What a bench will run, said before it starts: scenes, graded runs per scene (each
/// setting of each ladder, then timed again when fast), and the measured length of the
/// longest form.
fn plan(opts: &rotor_harness::bench::BenchOptions) -> String {
    let scenes = opts
        .shard
        .unwrap_or(rotor_harness::jobs::sweep::Shard::ALL)
        .count(opts.scenes.len().max(1));
    let ours: usize = opts.ladders.iter().map(|(_, l)| l.len()).sum();
    let clients: usize = opts
        .clients
        .iter()
        .map(|c| {
            if c.fixed_step {
                opts.client_hs.len()
            } else {
                opts.client_tols.len()
            }
        })
        .sum();
    let p = &opts.peers;
    let peers = usize::from(p.scipy) * (p.scipy_tols.len() + 3 * p.scipy_method_tols.len())
        + usize::from(p.siconos) * p.siconos_hs.len()
        + usize::from(p.octave) * p.octave_tols.len();
    let per_scene = ours + clients + peers;
    format!(
        "bench: {scenes} scene(s) x {per_scene} settings ({ours} of the three solvers, {clients} \
         of {} external client(s), up to {peers} of the peers that are installed) = up to {} \
         graded runs, each fast one timed again; the whole suite with every peer and two \
         clients took 6 to 9 minutes on 2 cores (BENCHMARK.md, section 5)",
        opts.clients.len(),
        scenes * per_scene
    )
}

/// `rotor bench --scaling`: the chain scaling study
/// ([`rotor_harness::bench::scaling`]), its table on stdout and its files written.
fn scaling(
    [json, svg, csv]: [Option<&Path>; 3],
    quick: bool,
    no_peers: bool,
    timeout: f64,
) -> Result<()> {
    use rotor_harness::bench::scaling::{ScalingOptions, SiconosOptions};
    check(
        "timeout",
        timeout,
        timeout > 0.0,
        "must be positive and finite",
    )?;
    let mut opts = ScalingOptions::default();
    if quick {
        opts.discs = vec![2, 4, 8];
        opts.t_end = 5.0;
    }
    let peer = rotor_harness::bench::BenchOptions::default().peers;
    let work = tempfile_dir()?;
    if !no_peers {
        match rotor_harness::protocol::peers::available(&peer.siconos_python, "siconos.kernel") {
            Ok(()) => {
                opts.siconos = Some(SiconosOptions {
                    python: peer.siconos_python.clone(),
                    dir: peer.dir.clone(),
                    // 0.4 s: 400 steps at h = 1e-3, about 55 s at N = 64 (0.14 s a step).
                    horizon: if quick { 0.2 } else { 0.4 },
                    timeout,
                    work: work.clone(),
                })
            }
            Err(why) => eprintln!("siconos peer skipped: {why}"),
        }
    }
    let report = rotor_harness::bench::scaling::run(&opts, &mut |m| eprintln!("{m}"));
    std::fs::remove_dir_all(&work).ok();
    let report = report?;
    let json_text = serde_json::to_string_pretty(&report)?;
    table_and_files(
        &report.to_markdown(),
        [json, svg, csv],
        [json_text, report.to_svg(), report.to_csv()],
    )
}

/// A study's table on stdout (unless an output is `-`) and its JSON, SVG and CSV written
/// where asked.
fn table_and_files(table: &str, outputs: [Option<&Path>; 3], texts: [String; 3]) -> Result<()> {
    crate::common::say(table, outputs)?;
    for (path, text) in outputs.into_iter().zip(texts) {
        if let Some(path) = path {
            rotor_harness::compare::report::write_output(path, text.as_bytes())
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
    }
    Ok(())
}

/// `rotor bench --tier chain`: the chain tier's work-precision bench
/// ([`rotor_harness::bench::chain_tier`]), its table on stdout and its files written.
fn chain_tier([json, svg, csv]: [Option<&Path>; 3], a: &Args) -> Result<()> {
    use rotor_harness::bench::chain_tier::{ChainTierOptions, chain_scenes, run};
    check(
        "timeout",
        a.timeout,
        a.timeout > 0.0,
        "must be positive and finite",
    )?;
    let scenes = if a.scenario.is_empty() {
        chain_scenes(&fixtures_dir()?)?
    } else {
        let mut v = Vec::new();
        for p in &a.scenario {
            let (path, is_chain) = crate::common::scene_path("--scenario", p)?;
            if !is_chain {
                crate::common::refuse!(
                    "--scenario {}: a rig scene; --tier chain runs chain scenes",
                    p.display()
                );
            }
            v.push(path);
        }
        v
    };
    let mut opts = if a.quick {
        ChainTierOptions::quick(scenes)
    } else {
        ChainTierOptions::new(scenes)
    };
    opts.timeout = a.timeout;
    for e in &a.external {
        opts.clients.push(
            rotor_harness::bench::ClientSpec::parse(e, &a.fixed_step)
                .map_err(crate::common::flagged)?,
        );
    }
    for name in &a.fixed_step {
        if !opts.clients.iter().any(|c| &c.name == name) {
            crate::common::refuse!("--fixed-step {name:?}: no --external client of that name");
        }
    }
    eprintln!(
        "bench --tier chain: {} scene(s), {} settings of the solvers, {} external client(s)",
        opts.scenes.len(),
        opts.ladders.iter().map(|(_, l)| l.len()).sum::<usize>(),
        opts.clients.len()
    );
    let report = run(&opts, &mut |m| eprintln!("{m}"))?;
    let json_text = serde_json::to_string_pretty(&report)? + "\n";
    table_and_files(
        &report.to_markdown(),
        [json, svg, csv],
        [json_text, report.to_svg(), report.to_csv()],
    )
}

/// A fresh working directory for the peer's job and trace files.
fn tempfile_dir() -> Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("rotor-scaling-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
