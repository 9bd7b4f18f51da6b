//! `rotor`: the command-line front end (its contract: docs/design.md, "The CLI").

use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod open;
mod out;
mod scenarios;

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand};
use rotor_model::{Model, Params, State, SteadyState};
use rotor_solvers::SolverKind;

/// Two-disc rotor with set-valued friction: three independent solvers, cross-validated.
#[derive(Parser, Debug)]
#[command(name = "rotor", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Threads of the main job (no subcommand; default: SLURM_CPUS_PER_TASK when set, else
    /// the cores available to the process). The subcommands that run in parallel take their
    /// own `--threads`.
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    threads: Option<usize>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate one scene and write the trajectory as CSV (t,alpha,omega_u,omega_l).
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Horizon [s].
        #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
        t_end: f64,
        /// Output interval [s] (rows at 0, dt, 2dt, ..., t_end).
        #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
        dt: f64,
        /// Output CSV file (`-`: standard output).
        #[arg(long)]
        csv: PathBuf,
    },
    /// Run to steady state and print it as one JSON object.
    Steady {
        #[command(flatten)]
        common: Common,
        /// How: `simulate` (the default: the event-driven solver refines the cycle a run
        /// reaches on its own flow with saltation matrices; switch and moreau run until the
        /// metrics settle, which answers equilibria too), or `shoot` (Newton on the
        /// solver's own return map from a 300 s run's last section crossing: any solver, the
        /// orbit stable or not, in a few periods where settling next to a Hopf point takes
        /// thousands of seconds; the JSON adds "stable" and "multipliers").
        #[arg(long, value_name = "shoot|simulate")]
        method: Option<String>,
    },
    /// Bifurcation diagram over u: equilibria, periodic branches with Floquet multipliers,
    /// special points (Hopf, grazing, folds), as JSON, and optionally CSV and an SVG figure.
    Bifurcation {
        /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
        /// source's Table 1).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Lower end of the input range [V] (>= 0; for a law odd in omega, u < 0 is the mirror).
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        u_min: f64,
        /// Upper end of the input range [V] (at most 1000).
        #[arg(long, default_value_t = 7.0, allow_hyphen_values = true)]
        u_max: f64,
        /// Output JSON file (equilibria, periodic, points; `-`: standard output).
        #[arg(long)]
        json: PathBuf,
        /// Output SVG figure (max/min of omega_l against u, like the source's Figure 3;
        /// `-`: standard output).
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Output CSV of every branch point (`-`: standard output).
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Which solver computes the periodic branches: event (the continuation with
        /// saltation matrices; default), or switch or moreau (each orbit shot again on that
        /// solver's own return map, with its own multipliers, and the grazing orbits and folds
        /// located again by that solver's shooting; "not_found" in the JSON names what was not).
        #[arg(long, default_value = "event")]
        solver: String,
    },
    /// Two-parameter analysis: every codimension-one point of the u-diagram (Hopf, grazing,
    /// folds, the stuck boundary) continued in (p, u), and the codimension-two points where
    /// the curves change type, turn, end or cross; JSON, and an SVG of the plane.
    Bifurcation2 {
        /// The parameter: a field of the parameter file as a dotted path (k_theta, lower.t_s,
        /// upper.b, ...).
        #[arg(long)]
        param: String,
        /// Lower end of the parameter's range.
        #[arg(long, allow_hyphen_values = true)]
        p_min: f64,
        /// Upper end of the parameter's range.
        #[arg(long, allow_hyphen_values = true)]
        p_max: f64,
        /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
        /// source's Table 1).
        #[arg(long)]
        params: Option<PathBuf>,
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        u_min: f64,
        #[arg(long, default_value_t = 7.0, allow_hyphen_values = true)]
        u_max: f64,
        /// Output JSON file (`-`: standard output).
        #[arg(long)]
        json: PathBuf,
        /// Output SVG of the (p, u) plane (`-`: standard output).
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Brute force over a (u, p) grid: every point's steady state (metrics only), one CSV row
    /// per point (u,p,kind,period,omega_l_max,omega_l_min,stick_time), written as it goes.
    Sweep {
        /// The u axis, A:B:N (N values from A to B) [V].
        #[arg(long)]
        u: String,
        /// The parameter axis, NAME=A:B:N (NAME a field of the parameter file).
        #[arg(long)]
        param: String,
        /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
        /// source's Table 1).
        #[arg(long)]
        params: Option<PathBuf>,
        /// Initial state A,WU,WL (default rest), or `eq`: the perturbed equilibrium at each
        /// point (omega_l of the slipping equilibrium + 1e-3).
        #[arg(long, allow_hyphen_values = true)]
        x0: Option<String>,
        /// Solver (default event).
        #[arg(long, default_value = "event")]
        solver: String,
        /// Run only every N-th point from the I-th (I from 1), for job arrays.
        #[arg(long)]
        shard: Option<String>,
        /// Keep the rows already in the output and run only the rest.
        #[arg(long)]
        resume: bool,
        /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
        /// available to the process).
        #[arg(long, value_name = "N", value_parser = threads_arg)]
        threads: Option<usize>,
        /// Horizon of each run [s] (metrics over its second half).
        #[arg(long, default_value_t = 600.0, allow_hyphen_values = true)]
        t_end: f64,
        /// Output CSV (`-`: standard output).
        #[arg(long)]
        csv: PathBuf,
    },
    /// Join sweep shards into exactly what one unsharded run writes.
    Merge {
        /// The shard files.
        shards: Vec<PathBuf>,
        /// Output CSV (`-`: standard output).
        #[arg(long)]
        csv: PathBuf,
    },
    /// Work-precision benchmark: each solver over a ladder of tolerances / steps, error
    /// against a tight reference, median run time, counters; peers (scipy, Siconos) side by
    /// side when installed. Prints a table.
    Bench {
        /// Output JSON file (`-`: standard output).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Output SVG work-precision plot (error against run time, log-log; `-`: stdout).
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Output CSV file (`-`: standard output).
        #[arg(long)]
        csv: Option<PathBuf>,
        /// A short ladder over a 30 s horizon without peers (seconds instead of a minute).
        #[arg(long)]
        quick: bool,
        /// Skip the peers even when python3 with scipy / Siconos is installed.
        #[arg(long)]
        no_peers: bool,
        /// An external solver, NAME=COMMAND (split as a shell splits words; no shell is
        /// run), started once per scene and setting with a job file's path appended
        /// (BENCHMARK.md). Repeatable.
        #[arg(long = "external", value_name = "NAME=COMMAND")]
        external: Vec<String>,
        /// Treat the external solver NAME as fixed-step (ladder of h instead of tol).
        #[arg(long = "fixed-step", value_name = "NAME")]
        fixed_step: Vec<String>,
        /// Seconds after which a client's run is killed (with its process group).
        #[arg(long, default_value_t = 60.0, allow_hyphen_values = true)]
        timeout: f64,
        /// Benchmark these scenarios (files, or names in fixtures/scenarios; their horizon,
        /// windows and grid) instead of the default scenes. Repeatable.
        #[arg(long = "scenario", value_name = "SCENARIO.toml")]
        scenario: Vec<PathBuf>,
        /// Run only every N-th scene from the I-th (I from 1), for job arrays; the report
        /// records the shard, and `--merge` joins the shards' reports.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
        /// Keep every external run's files (job.json, trace.csv, events.csv, stderr.txt) in
        /// DIR/CLIENT/SCENE/runK instead of deleting them.
        #[arg(long, value_name = "DIR")]
        keep: Option<PathBuf>,
        /// Run nothing: join the reports of `--shard` runs (any order) into the report one
        /// run writes, timings aside (BENCHMARK.md), written with --json, --svg, --csv.
        #[arg(
            long,
            value_name = "SHARD.json",
            num_args = 1..,
            conflicts_with_all = ["shard", "quick", "no_peers", "external", "fixed_step", "scenario", "keep"]
        )]
        merge: Vec<PathBuf>,
    },
    /// Print the job file `rotor bench` hands an external client for a scenario (its own
    /// horizon and grid, as with `bench --scenario`), x0 at full precision (BENCHMARK.md).
    /// One of --tol and --h is required: it says which knob the client has.
    Job {
        /// Scenario file, or a name in fixtures/scenarios (`t1-u1.5-rest`).
        scenario: PathBuf,
        /// The tolerance of a client with a tolerance (the job's `h` is null).
        #[arg(
            long,
            value_name = "T",
            allow_hyphen_values = true,
            conflicts_with = "h"
        )]
        tol: Option<f64>,
        /// The step of a fixed-step client [s] (the job's `tol` is null).
        #[arg(long, value_name = "H", allow_hyphen_values = true)]
        h: Option<f64>,
        /// The path the client writes its trace to.
        #[arg(long, value_name = "P", default_value = "trace.csv")]
        trace: PathBuf,
        /// The path the client writes its events to.
        #[arg(long, value_name = "P", default_value = "events.csv")]
        events: PathBuf,
    },
    /// List the benchmark suite: every scenario with its tier (table1: only the lower disc
    /// sticks; full: both may), what it tests, and the suite's version.
    Scenarios {
        /// Also write the list as JSON (`-`: standard output).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Write the benchmark's reference data for every scenario: trace, events and steady
    /// state of the event-driven solver, with their stated errors.
    Reference {
        /// Output directory (default: fixtures/reference).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
        /// available to the process).
        #[arg(long, value_name = "N", value_parser = threads_arg)]
        threads: Option<usize>,
    },
    /// Grade one trace (CSV t,alpha,omega_u,omega_l on the scenario's grid) against the
    /// reference with the scenario's own gates. Exit 0: every gate passes; 1: a gate fails;
    /// 2: the input is unusable.
    Check {
        /// Scenario file, or a name in fixtures/scenarios (`t1-u1.5-rest`); its reference is
        /// read from the reference directory beside it.
        scenario: PathBuf,
        /// The trace to grade.
        #[arg(long)]
        trace: PathBuf,
        /// The trace's events (CSV t,disc,kind). Without them the verdict says "events not
        /// graded".
        #[arg(long)]
        events: Option<PathBuf>,
        /// The level: strict (7 significant digits on every quantity: a well-converged
        /// adaptive integrator) or loose (3: engineering accuracy).
        #[arg(long, default_value = "loose", conflicts_with = "digits")]
        gate: String,
        /// Pass when every graded quantity reaches N significant digits (instead of --gate).
        #[arg(long, value_name = "N")]
        digits: Option<String>,
        /// Write the verdict as JSON (`-`: standard output).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Run scenarios through the three solvers, gate their agreement, write the report.
    Compare {
        /// Scenario files or names in fixtures/scenarios (default: every one there).
        scenarios: Vec<PathBuf>,
        /// Report directory.
        #[arg(long, default_value = "reports")]
        report: PathBuf,
        /// Threads to run on (default: SLURM_CPUS_PER_TASK when set, else the cores
        /// available to the process).
        #[arg(long, value_name = "N", value_parser = threads_arg)]
        threads: Option<usize>,
    },
}

#[derive(clap::Args, Debug)]
struct Common {
    /// Solver: switch, event or moreau.
    #[arg(long)]
    solver: String,
    /// Motor input voltage [V].
    #[arg(long, allow_hyphen_values = true)]
    u: f64,
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Initial state alpha,omega_u,omega_l (default: rest).
    #[arg(long, allow_hyphen_values = true)]
    x0: Option<String>,
    /// Integration tolerance (switch, event).
    #[arg(long, allow_hyphen_values = true)]
    tol: Option<f64>,
    /// Step size (moreau) [s].
    #[arg(long, allow_hyphen_values = true)]
    h: Option<f64>,
}

fn kind_by_name(name: &str) -> Result<SolverKind> {
    rotor_jobs::request::solver_kind(name).map_err(|e| anyhow!(e.as_flag()))
}

/// Prints a command's summary: on standard output, unless one of its outputs goes there
/// (`-`), then on standard error.
pub(crate) fn say<const N: usize>(text: &str, outputs: [Option<&Path>; N]) -> std::io::Result<()> {
    if outputs.iter().flatten().any(|p| p.as_os_str() == "-") {
        eprint!("{text}");
        Ok(())
    } else {
        out::print(text)
    }
}

/// `--params`: a parameter file, or the name of one in `fixtures/params` (`stribeck`), as the
/// Python package takes it; default Table 1.
fn load_model(params: Option<&Path>) -> Result<Model> {
    let p = match params {
        Some(p) => Params::from_file(&fixture_path("--params", p, "params")?)?,
        None => Params::table1(),
    };
    Ok(Model::new(p))
}

/// The file a path argument names: a path, or the name of a file in `fixtures/KIND`
/// ([`rotor_solvers::fixtures::resolve`]). A name that is neither is an error naming `flag`
/// and listing the names there.
pub(crate) fn fixture_path(flag: &str, p: &Path, kind: &str) -> Result<PathBuf> {
    let dir = fixtures_dir()?.join(kind);
    rotor_solvers::fixtures::resolve(p, Some(&dir)).ok_or_else(|| {
        anyhow!(
            "{flag} {}: no such file, nor a name in {} (names: {})",
            p.display(),
            dir.canonicalize().unwrap_or_else(|_| dir.clone()).display(),
            rotor_solvers::fixtures::names(&dir).join(", ")
        )
    })
}

fn parse_x0(s: Option<&str>) -> Result<State> {
    let Some(s) = s else {
        return Ok(State::zeros());
    };
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        bail!("--x0 {s:?}: expected three comma-separated numbers alpha,omega_u,omega_l");
    }
    let mut x = State::zeros();
    for (i, p) in parts.iter().enumerate() {
        let v: f64 = p
            .parse()
            .map_err(|_| anyhow!("--x0 {s:?}: {p:?} is not a number"))?;
        if !v.is_finite() {
            bail!("--x0 {s:?}: {p:?} is not finite");
        }
        x[i] = v;
    }
    Ok(x)
}

/// Moreau–Jean steps whose step problem did not converge are answers to distrust: say so.
fn warn_inexact(stats: &rotor_model::Stats) {
    if let Some(w) = rotor_jobs::request::inexact_warning(stats, "--h") {
        eprintln!("warning: {w}");
    }
}

/// `--threads N`: a whole number from 1 (clap's error names the flag and the value).
fn threads_arg(s: &str) -> Result<usize, String> {
    rotor_compare::threads::parse_count(s)
}

/// Starts the thread pool of a command that runs in parallel: `--threads`, else
/// `SLURM_CPUS_PER_TASK`, else the cores available ([`rotor_compare::threads`]). Returns the
/// count in words ("1 thread", "8 threads, from SLURM_CPUS_PER_TASK") for the run's summary.
fn thread_pool(explicit: Option<usize>) -> Result<String> {
    use rotor_compare::threads::Source;
    let (n, src) = rotor_compare::threads::resolve(explicit).map_err(|e| anyhow!(e))?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| anyhow!("--threads {n}: cannot start the thread pool: {e}"))?;
    let count = if n == 1 {
        "1 thread".to_owned()
    } else {
        format!("{n} threads")
    };
    Ok(match src {
        Source::Explicit => count,
        other => format!("{count}, {}", other.describe()),
    })
}

/// Checks a numeric option: finite and in range, naming the flag and the value.
fn check(flag: &str, v: f64, ok: bool, what: &str) -> Result<()> {
    if !v.is_finite() || !ok {
        bail!("--{flag} {}: {what}", rotor_model::Num(v));
    }
    Ok(())
}

/// The checked request of `simulate` and `steady` (the same checks and words as the Python
/// package's), with a warning for a setting the solver ignores.
fn request(common: &Common) -> Result<rotor_jobs::request::Request<'_>> {
    let x = parse_x0(common.x0.as_deref())?;
    let req = rotor_jobs::request::Request {
        solver: &common.solver,
        u: common.u,
        x0: [x[0], x[1], x[2]],
        tol: common.tol,
        h: common.h,
    };
    if let Some(i) = req.ignored() {
        eprintln!("warning: {}", i.as_flag());
    }
    Ok(req)
}

fn simulate(common: &Common, t_end: f64, dt: f64, csv_path: &Path) -> Result<()> {
    let (kind, scene) = request(common)?
        .simulation(t_end, dt)
        .map_err(|e| anyhow!(e.as_flag()))?;
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

fn steady(common: &Common, method: Option<&str>) -> Result<()> {
    let shoot = match method {
        None | Some("simulate") => false,
        Some("shoot") => true,
        Some(other) => bail!("--method {other:?}: expected shoot or simulate"),
    };
    let (kind, scene, opts) = request(common)?
        .steady()
        .map_err(|e| anyhow!(e.as_flag()))?;
    let model = load_model(common.params.as_deref())?;
    let answer = if shoot {
        rotor_steady::shot(kind, &model, &scene)
    } else {
        rotor_steady::steady(kind, &model, &scene, &opts)
    }
    .with_context(|| format!("solver {}", kind.name()))?;
    warn_inexact(&answer.stats);
    out::line(format_args!("{}", steady_json(&answer)))?;
    Ok(())
}

fn bifurcation(
    solver: &str,
    params: Option<&Path>,
    u_min: f64,
    u_max: f64,
    json: &Path,
    svg: Option<&Path>,
    csv: Option<&Path>,
) -> Result<()> {
    use rotor_compare::report::write_output;
    let model = load_model(params)?;
    let opts = rotor_bifurcation::DiagramOptions {
        u_min,
        u_max,
        ..Default::default()
    };
    // The library names the field: "u_min = ...", which is the flag --u-min.
    opts.validate().map_err(|e| {
        anyhow!(
            "{}",
            e.to_string()
                .replace("u_min", "--u-min")
                .replace("u_max", "--u-max")
        )
    })?;
    let kind = rotor_jobs::request::solver_kind(solver).map_err(|e| anyhow!(e.as_flag()))?;
    let event = rotor_bifurcation::diagram(&model, &opts)?;
    let by = rotor_steady::by_solver::by_solver(kind, &model, &event);
    let d = &by.diagram;
    d.check_finite()?;
    let mut text = serde_json::to_string_pretty(&by)?;
    text.push('\n');
    write_output(json, text.as_bytes())
        .with_context(|| format!("{}: cannot write", json.display()))?;
    if let Some(path) = csv {
        let mut buf = Vec::new();
        d.write_csv(&mut buf)?;
        write_output(path, &buf).with_context(|| format!("{}: cannot write", path.display()))?;
    }
    if let Some(path) = svg {
        let name = params.map_or("Table 1".to_owned(), |p| p.display().to_string());
        write_output(
            path,
            d.to_svg(&format!("Bifurcation diagram: {name}")).as_bytes(),
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    let mut summary = format!(
        "{}: {} equilibria, {} periodic orbits, {} special points\n",
        by.solver,
        d.equilibria.len(),
        d.periodic.len(),
        d.points.len()
    );
    if !by.not_found.is_empty() {
        summary += &format!(
            "  {} orbits of the continuation not found by {}'s shooting (in the JSON)\n",
            by.not_found.len(),
            by.solver
        );
    }
    for p in &d.points {
        summary += &format!("  {}\n", serde_json::to_string(p)?);
    }
    say(&summary, [Some(json), csv, svg])?;
    Ok(())
}

fn bifurcation2(
    param: &str,
    [p_min, p_max, u_min, u_max]: [f64; 4],
    params: Option<&Path>,
    json: &Path,
    svg: Option<&Path>,
) -> Result<()> {
    use rotor_compare::report::write_output;
    let base = load_model(params)?.params;
    let opts = rotor_bifurcation::plane::PlaneOptions {
        u_min,
        u_max,
        ..rotor_bifurcation::plane::PlaneOptions::new(param, p_min, p_max)
    };
    rotor_bifurcation::plane::validate(&base, &opts).map_err(|e| {
        anyhow!(
            "{}",
            e.to_string()
                .replace("p_min", "--p-min")
                .replace("p_max", "--p-max")
                .replace("u_min", "--u-min")
                .replace("u_max", "--u-max")
        )
    })?;
    let t0 = std::time::Instant::now();
    let plane = rotor_bifurcation::plane::plane(&base, &opts)?;
    let secs = t0.elapsed().as_secs_f64();
    write_output(json, plane.to_json()?.as_bytes())
        .with_context(|| format!("{}: cannot write", json.display()))?;
    if let Some(path) = svg {
        let name = params.map_or("Table 1".to_owned(), |p| p.display().to_string());
        write_output(
            path,
            plane.to_svg(&format!("{name}: ({param}, u)")).as_bytes(),
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    let mut summary = format!(
        "{} curves, {} codimension-two points in {secs:.2} s\n",
        plane.curves.len(),
        plane.points.len()
    );
    for c in &plane.curves {
        summary.push_str(&format!(
            "  {} ({:?}): {} points\n",
            c.label,
            c.kind,
            c.points.len()
        ));
    }
    for q in &plane.points {
        summary.push_str(&format!(
            "  {} at {param} = {:.6}, u = {:.6}: {}\n",
            q.kind.name(),
            q.p,
            q.u,
            q.curves.join(", ")
        ));
    }
    say(&summary, [Some(json), svg])?;
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn sweep(
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
    use rotor_jobs::sweep::{Axis, Shard, Sweep, SweepStart, run};
    let base = load_model(params)?.params;
    let (name, range) = param
        .split_once('=')
        .ok_or_else(|| anyhow!("--param {param:?}: expected NAME=A:B:N"))?;
    check("t-end", t_end, t_end > 0.0, "must be positive and finite")?;
    let start = match x0 {
        Some("eq") => SweepStart::PerturbedEquilibrium,
        other => SweepStart::State(parse_x0(other)?),
    };
    let s = Sweep {
        base,
        u: Axis::parse("--u", u)?,
        param: name.to_owned(),
        p: Axis::parse("--param", range)?,
        start,
        solver: kind_by_name(solver)?,
        t_end,
    };
    let shard = shard.map(Shard::parse).transpose()?.unwrap_or(Shard::ALL);
    if resume && csv.as_os_str() == "-" {
        bail!("--resume needs an output file, not standard output");
    }
    let threads = thread_pool(threads)?;
    let total = shard.count(s.len());
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
    })?;
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

fn merge(shards: &[PathBuf], csv: &Path) -> Result<()> {
    if shards.is_empty() {
        bail!("merge: no shard files given");
    }
    let merged = rotor_jobs::sweep::merge(shards)?;
    rotor_compare::report::write_output_with(csv, |w| merged.write_to(w))
        .with_context(|| format!("{}: cannot write", csv.display()))?;
    Ok(())
}

/// `rotor bench`'s external clients and scenes.
struct BenchClients<'a> {
    external: &'a [String],
    fixed_step: &'a [String],
    timeout: f64,
    scenarios: &'a [PathBuf],
    shard: Option<&'a str>,
    keep: Option<&'a Path>,
}

fn bench(
    [json, svg, csv]: [Option<&Path>; 3],
    quick: bool,
    no_peers: bool,
    clients: BenchClients,
) -> Result<()> {
    let mut opts = if quick {
        rotor_bench::BenchOptions::quick()
    } else {
        rotor_bench::BenchOptions::default()
    };
    if no_peers {
        opts.peers.scipy = false;
        opts.peers.siconos = false;
    }
    check(
        "timeout",
        clients.timeout,
        clients.timeout > 0.0,
        "must be positive and finite",
    )?;
    opts.timeout = clients.timeout;
    for e in clients.external {
        opts.clients
            .push(rotor_bench::ClientSpec::parse(e, clients.fixed_step).map_err(|m| anyhow!(m))?);
    }
    for name in clients.fixed_step {
        if !opts.clients.iter().any(|c| &c.name == name) {
            bail!("--fixed-step {name:?}: no --external client of that name");
        }
    }
    if !clients.scenarios.is_empty() {
        opts.scenes = clients
            .scenarios
            .iter()
            .map(|p| {
                let p = fixture_path("--scenario", p, "scenarios")?;
                Ok(rotor_bench::SceneSpec::from_scenario(&p)?)
            })
            .collect::<Result<_>>()?;
    }
    opts.shard = clients
        .shard
        .map(rotor_jobs::sweep::Shard::parse)
        .transpose()?;
    opts.keep = clients.keep.map(Path::to_path_buf);
    let report = rotor_bench::run(&opts, |m| eprintln!("{m}"))?;
    write_bench(&report, [json, svg, csv])?;
    // The report is written first (nothing is lost); then a named client that placed no
    // point on any scene fails the command, by name (a peer that is not installed does not).
    let unsolved: Vec<String> = report
        .clients
        .iter()
        .filter(|c| !c.peer && c.status != rotor_bench::ClientStatus::Ran)
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

/// `rotor job`: the job file of a scenario, printed.
fn job(
    scenario: &Path,
    tol: Option<f64>,
    h: Option<f64>,
    trace: &Path,
    events: &Path,
) -> Result<()> {
    let (fixed_step, setting) = match (tol, h) {
        (Some(t), None) => {
            check("tol", t, t > 0.0, "must be a positive number")?;
            (false, t)
        }
        (None, Some(h)) => {
            check("h", h, h > 0.0, "must be a positive number of seconds")?;
            (true, h)
        }
        _ => bail!(
            "rotor job {}: give --tol T (a client with a tolerance) or --h H (a fixed-step \
             client), one of them",
            scenario.display()
        ),
    };
    for (flag, p) in [("--trace", trace), ("--events", events)] {
        if p.as_os_str().is_empty() {
            bail!("{flag} \"\": an empty path");
        }
    }
    let path = fixture_path("scenario", scenario, "scenarios")?;
    let job = rotor_bench::protocol::Job::for_scenario(
        &path,
        fixed_step,
        setting,
        trace.to_owned(),
        events.to_owned(),
    )?;
    out::print(&(job.to_json() + "\n"))?;
    Ok(())
}

/// `rotor bench --merge`: the shards' reports joined into one.
fn bench_merge(shards: &[PathBuf], outputs: [Option<&Path>; 3]) -> Result<()> {
    let reports = shards
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("--merge {}: cannot read", p.display()))?;
            let r: rotor_bench::BenchReport = serde_json::from_str(&text).with_context(|| {
                format!(
                    "--merge {}: not a report of rotor bench --json",
                    p.display()
                )
            })?;
            Ok((p.display().to_string(), r))
        })
        .collect::<Result<Vec<_>>>()?;
    let report = rotor_bench::merge(&reports)?;
    write_bench(&report, outputs)
}

/// Prints a benchmark report's table and writes its files.
fn write_bench(
    report: &rotor_bench::BenchReport,
    [json, svg, csv]: [Option<&Path>; 3],
) -> Result<()> {
    use rotor_compare::report::write_output;
    say(&report.table(), [json, svg, csv])?;
    for (path, text) in [
        (json, report.to_json()?),
        (svg, report.to_svg()?),
        (csv, report.to_csv()?),
    ] {
        if let Some(path) = path {
            write_output(path, text.as_bytes())
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
    }
    Ok(())
}

/// The checkout's fixtures directory, which `rotor reference` writes: ./fixtures when run in
/// the workspace root, else the one this binary was built from.
fn checkout_fixtures() -> PathBuf {
    let local = PathBuf::from("fixtures");
    if local.is_dir() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

/// The suite's directory, for scenarios and parameter sets given by name: ./fixtures in a
/// checkout's root, else what [`rotor_suite::locate`] finds (`$ROTORBENCH_FIXTURES`, the
/// checkout this binary was built from, or the suite embedded in it). With
/// `ROTORBENCH_SUITE=embedded`, always the embedded suite.
fn fixtures_dir() -> Result<PathBuf> {
    let local = PathBuf::from("fixtures");
    if std::env::var_os("ROTORBENCH_SUITE").is_none() && local.join("scenarios").is_dir() {
        return Ok(local);
    }
    Ok(rotor_suite::locate()?.dir)
}

/// The report section with the bifurcation diagrams of both parameter sets (the source's
/// Figure 3): SVG, JSON and CSV per set, and a table of the special points.
fn bifurcation_section(
    sets: &[(&str, &str, Params)],
) -> Result<(
    rotor_compare::report::Section,
    Vec<rotor_bifurcation::Diagram>,
)> {
    use rayon::prelude::*;
    use std::fmt::Write as _;
    let diagrams = sets
        .par_iter()
        .map(|(_, _, p)| {
            let t0 = std::time::Instant::now();
            let d = rotor_bifurcation::diagram(&Model::new(*p), &Default::default());
            (d, t0.elapsed().as_secs_f64())
        })
        .collect::<Vec<_>>();
    let mut sec = rotor_compare::report::Section::default();
    let mut out = Vec::new();
    sec.markdown
        .push_str("## Bifurcation diagrams (the source's Figure 3)\n\n");
    sec.markdown.push_str(
        "Computed by `rotor bifurcation` (crate `rotor-bifurcation`): the equilibrium branch with \
         its eigenvalues, periodic orbits by shooting with the exact Filippov flow, Floquet \
         multipliers from the monodromy matrix with saltation matrices, pseudo-arclength \
         continuation started at each Hopf point. Stable: solid; unstable: dashed. Each special \
         point is listed with the residual of its defining condition.\n",
    );
    for ((name, slug, _), (d, secs)) in sets.iter().zip(diagrams) {
        let d = d.with_context(|| format!("bifurcation diagram of the {name} set"))?;
        let _ = write!(
            sec.timings,
            "\n## Bifurcation diagram, {name}\n\nComputed in {secs:.2} s.\n"
        );
        let md = &mut sec.markdown;
        let _ = write!(
            md,
            "\n### {name}\n\n![bifurcation diagram, {name}](bifurcation-{slug}.svg)\n\n\
             {} equilibria, {} periodic orbits \
             ([JSON](bifurcation-{slug}.json), [CSV](bifurcation-{slug}.csv)).\n\n\
             | point | u [V] | residual | detail |\n|---|---|---|---|\n",
            d.equilibria.len(),
            d.periodic.len()
        );
        for p in &d.points {
            let v = serde_json::to_value(p)?;
            let get = |k: &str| v.get(k).and_then(|x| x.as_f64());
            let _ = writeln!(
                md,
                "| {} | {:.10} | {} | {} |",
                v.get("kind").and_then(|x| x.as_str()).unwrap_or("?"),
                get("u").unwrap_or(f64::NAN),
                get("residual").map_or("—".into(), |r| format!("{r:.1e}")),
                v.get("detail").and_then(|x| x.as_str()).unwrap_or("")
            );
        }
        let mut csv = Vec::new();
        d.write_csv(&mut csv)?;
        sec.files.push((
            format!("bifurcation-{slug}.svg"),
            d.to_svg(&format!("Bifurcation diagram: {name}"))
                .into_bytes(),
        ));
        sec.files.push((
            format!("bifurcation-{slug}.json"),
            d.to_json()?.into_bytes(),
        ));
        sec.files.push((format!("bifurcation-{slug}.csv"), csv));
        out.push(d);
    }
    Ok((sec, out))
}

/// The report section with Figure 3 by the three methods (`rotor_steady::figure3`).
fn figure3_section(
    sets: &[(&str, &str, Params)],
    diagrams: &[rotor_bifurcation::Diagram],
) -> rotor_compare::report::Section {
    let models: Vec<Model> = sets.iter().map(|(_, _, p)| Model::new(*p)).collect();
    let s: Vec<_> = (sets.iter().zip(&models).zip(diagrams))
        .map(|(((n, g, _), m), d)| (*n, *g, m, d))
        .collect();
    let r = rotor_steady::figure3::figure3_section(&s);
    let (markdown, files, failures, timings) = (r.markdown, r.files, r.failures, r.timings);
    rotor_compare::report::Section {
        markdown,
        files,
        failures,
        timings,
    }
}

/// The report section with the two-parameter pictures: (k_θ, u) and (T_sl, u) for both
/// parameter sets.
fn plane_section(sets: &[(&str, &str, Params)]) -> Result<rotor_compare::report::Section> {
    use rayon::prelude::*;
    use std::fmt::Write as _;
    let jobs: Vec<(&str, &str, Params, &str, f64, f64)> = sets
        .iter()
        .flat_map(|(name, slug, p)| {
            // T_sl over a range that keeps the law admissible and, for the Stribeck set,
            // reaches the cluster of codimension-two points near 0.13.
            let ts = if *slug == "stribeck" {
                (0.1, 0.45)
            } else {
                (0.1, 0.25)
            };
            [
                (*name, *slug, *p, "k_theta", 0.05, 0.11),
                (*name, *slug, *p, "lower.t_s", ts.0, ts.1),
            ]
        })
        .collect();
    let planes = jobs
        .par_iter()
        .map(|(_, _, p, param, a, b)| {
            let t0 = std::time::Instant::now();
            let pl = rotor_bifurcation::plane::plane(
                p,
                &rotor_bifurcation::plane::PlaneOptions::new(param, *a, *b),
            );
            (pl, t0.elapsed().as_secs_f64())
        })
        .collect::<Vec<_>>();
    let mut sec = rotor_compare::report::Section::default();
    sec.markdown.push_str(
        "## Two parameters (rotor bifurcation2)\n\n\
         Every codimension-one point of the u-diagram continued in the plane of (p, u) for the \
         stiffness k_θ and the lower disc's static level T_sl, \
         with the codimension-two points located on the curves and the regions named from \
         simulations from rest and from the perturbed equilibrium in every band the curves \
         bound (docs/methods.md, section 4a). The dashed line is the file's value; its dots \
         are the one-parameter diagram's points.\n",
    );
    for ((name, slug, _, param, a, b), (pl, secs)) in jobs.iter().zip(planes) {
        let pl = pl.with_context(|| format!("{name}: two-parameter analysis over {param}"))?;
        let file = format!("plane-{slug}-{}", param.replace('.', "_"));
        let _ = write!(
            sec.timings,
            "\n## Two parameters, {name}, {param}\n\nComputed in {secs:.2} s.\n"
        );
        let _ = write!(
            sec.markdown,
            "\n### {name}: ({param}, u), {param} in [{a:.4}, {b:.4}]\n\n![{name} {param}]({file}.svg)\n\n\
             {} curves ([JSON]({file}.json)); codimension-two points:\n\n",
            pl.curves.len()
        );
        if pl.points.is_empty() {
            sec.markdown.push_str("none in this range.\n");
        } else {
            sec.markdown
                .push_str("| kind | p | u [V] | curves | detail |\n|---|---|---|---|---|\n");
            for q in &pl.points {
                let _ = writeln!(
                    sec.markdown,
                    "| {} | {:.5} | {:.5} | {} | {} |",
                    q.kind.name(),
                    q.p,
                    q.u,
                    q.curves.join(", "),
                    q.detail
                );
            }
        }
        sec.files.push((
            format!("{file}.svg"),
            pl.to_svg(&format!("{name}: ({param}, u)")).into_bytes(),
        ));
        sec.files
            .push((format!("{file}.json"), pl.to_json()?.into_bytes()));
    }
    Ok(sec)
}

/// The report section with the steady states probed next to every special point of both
/// diagrams (`rotor_steady::probes`, all solvers, all offsets, both starts).
fn probe_section(
    sets: &[(&str, &str, Params)],
    diagrams: &[rotor_bifurcation::Diagram],
) -> rotor_compare::report::Section {
    use rayon::prelude::*;
    use rotor_steady::probes;
    let mut rows = Vec::new();
    for ((_, slug, p), d) in sets.iter().zip(diagrams) {
        let m = Model::new(*p);
        let selected = probes::selection(d, true);
        rows.extend(probes::run_set(slug, &m, d, &selected, |jobs, f| {
            jobs.par_iter().map(f).collect()
        }));
    }
    let count =
        |f: &dyn Fn(&probes::Verdict) -> bool| rows.iter().filter(|r| f(&r.verdict)).count();
    let agree = count(&|v| matches!(v, probes::Verdict::Agrees { .. }));
    let refused = count(&|v| matches!(v, probes::Verdict::Refused { .. }));
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| !r.verdict.acceptable())
        .map(|r| {
            format!(
                "steady near {} of {} ({:+e} V, from {}): {} {:?}",
                r.probe.point.label,
                r.set,
                r.probe.offset,
                r.probe.start.as_str(),
                r.probe.kind.name(),
                r.verdict
            )
        })
        .collect();
    let slowest = rows.iter().map(|r| r.seconds).fold(0.0, f64::max);
    let total: f64 = rows.iter().map(|r| r.seconds).sum();
    rotor_compare::report::Section {
        markdown: format!(
            "## Steady states near special points\n\n\
             `rotor steady` at ±1e-3, ±1e-4 and ±1e-6 V from every special point of both \
             diagrams, from rest and from the equilibrium perturbed by 1e-3 rad/s, for every \
             solver (crate `rotor-steady`, module `probes`). Each answer is checked against \
             what the continuation says is stable at that input (the stable equilibria, the \
             stuck set, the stable cycles found by Newton's method from the branch and from \
             the Hopf eigenvector): it must be one of them in kind, period and ω_l extremes \
             (within 1e-6 for the event-driven solver, 1e-5 for the switch model, 1e-4 for \
             Moreau–Jean, each well inside the distance to the nearest other cycle), or a \
             refusal that names its cause: a transient that decays or grows too slowly to \
             settle within 20 000 s (next to a Hopf point), a stick phase shorter than ten \
             steps (Moreau–Jean next to a grazing orbit), no cycle next to a weakly unstable \
             equilibrium, or a stability the tolerance cannot decide. {} probes: {agree} \
             answers agree, {refused} refusals, {} wrong or failed.\n\n{}\n\
             Each probe:\n\n{}",
            rows.len(),
            bad.len(),
            probes::probe_summary_markdown(&rows, &rotor_solvers::SOLVERS),
            probes::probe_table_markdown(&rows, &rotor_solvers::SOLVERS)
        ),
        files: Vec::new(),
        timings: format!(
            "\n## Steady states near special points\n\n{} probes, {total:.1} s of solver \
             time in all, the slowest {slowest:.2} s.\n",
            rows.len()
        ),
        failures: bad,
    }
}

/// The report section with the numerical stress cases in their fast form (the full form:
/// `just stress`).
fn stress_section() -> rotor_compare::report::Section {
    use rayon::prelude::*;
    use rotor_compare::stress;
    let rows: Vec<_> = stress::cases(false)
        .par_iter()
        .flat_map(stress::run_case)
        .collect();
    let failed = rows.iter().filter(|r| !r.passes()).count();
    rotor_compare::report::Section {
        markdown: format!(
            "## Numerical stress (fast form)\n\n\
             Each case pushes one thing to an extreme (crate `rotor-compare`, module `stress`; \
             the full form with long horizons and the widest ladders runs with `just stress`). \
             Every solver must finish with a finite state or a typed error that says why, and \
             where it finishes agree with the event-driven solver or an exact solution within \
             the stated gate. {} rows, {} outside their gate.\n\n{}",
            rows.len(),
            failed,
            stress::stress_table_markdown(&rows)
        ),
        files: Vec::new(),
        timings: format!(
            "\n## Numerical stress (fast form)\n\n{}",
            stress::stress_timings_markdown(&rows)
        ),
        failures: rows
            .iter()
            .filter(|r| !r.passes())
            .map(|r| {
                format!(
                    "stress {} ({}): {} at {}: {}",
                    r.case,
                    r.what,
                    r.solver.name(),
                    r.setting,
                    r.outcome
                )
            })
            .collect(),
    }
}

/// `rotor compare`; with `main_job`, the report also gets the bifurcation diagrams.
fn compare(files: &[PathBuf], report: &Path, main_job: bool, threads: Option<usize>) -> Result<()> {
    use rayon::prelude::*;
    let files = if files.is_empty() {
        let dir = fixtures_dir()?.join("scenarios");
        rotor_model::Scenario::list_dir(&dir)
            .with_context(|| format!("{}: cannot list scenarios", dir.display()))?
    } else {
        files
            .iter()
            .map(|f| fixture_path("scenario", f, "scenarios"))
            .collect::<Result<_>>()?
    };
    let scenarios = files
        .iter()
        .map(|f| rotor_solvers::load_scenario(f))
        .collect::<Result<Vec<_>, _>>()?;
    // Report files are named after the scenarios: two of one name would overwrite each other.
    for (i, a) in scenarios.iter().enumerate() {
        if let Some(b) = scenarios[..i].iter().find(|b| b.name == a.name) {
            bail!(
                "{}: name = {:?}: also the name of {}",
                a.path.display(),
                a.name,
                b.path.display()
            );
        }
    }
    let stribeck = Params::from_file(&fixtures_dir()?.join("params/stribeck.toml"))?;
    let threads = thread_pool(threads)?;
    eprintln!("{} scenarios on {threads}", scenarios.len());
    let t0 = std::time::Instant::now();
    let bar = progress_bar(scenarios.len() as u64, "scenarios");
    let sets = [
        ("Table 1", "table1", Params::table1()),
        ("Stribeck set", "stribeck", stribeck),
    ];
    // In parallel across scenarios (and with the diagrams); collected in input order, so the
    // output is deterministic.
    let (results, sections) = rayon::join(
        || {
            scenarios
                .par_iter()
                .map(|sc| {
                    let r = rotor_solvers::run_scenario(sc);
                    bar.inc(1);
                    r
                })
                .collect::<Vec<_>>()
        },
        || -> Result<Vec<rotor_compare::report::Section>> {
            if main_job {
                let (bif, (stress, plane)) = rayon::join(
                    || {
                        let (sec, diagrams) = bifurcation_section(&sets)?;
                        let (probes, fig3) = rayon::join(
                            || probe_section(&sets, &diagrams),
                            || figure3_section(&sets, &diagrams),
                        );
                        Ok::<_, anyhow::Error>((sec, probes, fig3))
                    },
                    || rayon::join(stress_section, || plane_section(&sets)),
                );
                let (bif, probes, fig3) = bif?;
                Ok(vec![bif, fig3, plane?, stress, probes])
            } else {
                Ok(Vec::new())
            }
        },
    );
    let sections = sections?;
    bar.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    let params = [
        ("Table 1 (exponential)", Params::table1()),
        ("Stribeck set (unverified)", stribeck),
    ];
    let fails = rotor_compare::report::write_report(report, &results, &params, &sections)
        .with_context(|| format!("{}: cannot write the report", report.display()))?;
    out::line(format_args!(
        "{:<18} {:<7} {:<12} {:>10} {:>12} {:>9}",
        "scenario", "solver", "steady", "period", "omega_l_max", "ms"
    ))?;
    for r in &results {
        for run in &r.runs {
            let (kind, period, wmax) = match run.result.as_ref().ok().and_then(|t| t.metrics) {
                Some(SteadyState::LimitCycle {
                    period,
                    omega_l_max,
                    ..
                }) => ("cycle", format!("{period:.6}"), format!("{omega_l_max:.6}")),
                Some(SteadyState::Equilibrium { omega_l, .. }) => {
                    ("equilibrium", "-".into(), format!("{omega_l:.6}"))
                }
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
        "{} scenarios, {} solvers, {:.2} s wall; report in {}",
        results.len(),
        rotor_solvers::SOLVERS.len(),
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

/// A progress bar on stderr when it is a terminal; hidden in CI and when piped, so logs and
/// captured output stay clean.
fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    let quiet = std::env::var_os("CI").is_some() || !std::io::stderr().is_terminal();
    if quiet {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed_precise}]")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_owned());
    bar
}

fn steady_json(st: &rotor_steady::SteadyAnswer) -> String {
    serde_json::to_string(st).expect("plain floats and strings serialize")
}

impl Command {
    /// The subcommand's name on the command line.
    fn name(&self) -> &'static str {
        use Command::*;
        match self {
            Simulate { .. } => "simulate",
            Steady { .. } => "steady",
            Bifurcation { .. } => "bifurcation",
            Bifurcation2 { .. } => "bifurcation2",
            Sweep { .. } => "sweep",
            Merge { .. } => "merge",
            Bench { .. } => "bench",
            Job { .. } => "job",
            Scenarios { .. } => "scenarios",
            Reference { .. } => "reference",
            Check { .. } => "check",
            Compare { .. } => "compare",
        }
    }

    /// Whether it runs in parallel (and takes `--threads`).
    fn parallel(&self) -> bool {
        use Command::*;
        matches!(self, Sweep { .. } | Reference { .. } | Compare { .. })
    }

    /// The output files the command writes, with their flags (directories it creates, as
    /// `compare --report` and `reference --out`, are not listed).
    fn outputs(&self) -> Vec<(&'static str, &Path)> {
        use Command::*;
        let (csv, json, svg) = match self {
            Simulate { csv, .. } | Sweep { csv, .. } | Merge { csv, .. } => (Some(csv), None, None),
            Bifurcation { json, svg, csv, .. } => (csv.as_ref(), Some(json), svg.as_ref()),
            Bifurcation2 { json, svg, .. } => (None, Some(json), svg.as_ref()),
            Bench { json, svg, csv, .. } => (csv.as_ref(), json.as_ref(), svg.as_ref()),
            Check { json, .. } | Scenarios { json } => (None, json.as_ref(), None),
            Steady { .. } | Compare { .. } | Reference { .. } | Job { .. } => (None, None, None),
        };
        [("--csv", csv), ("--json", json), ("--svg", svg)]
            .into_iter()
            .filter_map(|(flag, p)| Some((flag, p?.as_path())))
            .collect()
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // `rotor --threads N` is the main job's; a subcommand takes its own after its name.
    if cli.threads.is_some()
        && let Some(cmd) = &cli.command
    {
        eprintln!(
            "error: --threads before the subcommand sets the main job's threads; give it after \
             the subcommand's name (rotor {} ... --threads N){}",
            cmd.name(),
            if cmd.parallel() {
                ""
            } else {
                ", which runs on one thread and takes no --threads"
            }
        );
        return ExitCode::from(2);
    }
    // Outputs that cannot be written are refused before any work; for `check` that is
    // unusable input (exit 2).
    if let Some(cmd) = &cli.command
        && let Err(e) = cmd
            .outputs()
            .into_iter()
            .try_for_each(|(f, p)| out::writable(f, p))
    {
        eprintln!("error: {e:#}");
        let unusable = matches!(cmd, Command::Check { .. });
        return ExitCode::from(if unusable { 2 } else { 1 });
    }
    let res = match &cli.command {
        Some(Command::Simulate {
            common,
            t_end,
            dt,
            csv,
        }) => simulate(common, *t_end, *dt, csv),
        Some(Command::Steady { common, method }) => steady(common, method.as_deref()),
        Some(Command::Bifurcation {
            params,
            u_min,
            u_max,
            json,
            svg,
            csv,
            solver,
        }) => bifurcation(
            solver,
            params.as_deref(),
            *u_min,
            *u_max,
            json,
            svg.as_deref(),
            csv.as_deref(),
        ),
        Some(Command::Bench {
            json,
            svg,
            csv,
            quick,
            no_peers,
            external,
            fixed_step,
            timeout,
            scenario,
            shard,
            keep,
            merge,
        }) if merge.is_empty() => bench(
            [json.as_deref(), svg.as_deref(), csv.as_deref()],
            *quick,
            *no_peers,
            BenchClients {
                external,
                fixed_step,
                timeout: *timeout,
                scenarios: scenario,
                shard: shard.as_deref(),
                keep: keep.as_deref(),
            },
        ),
        Some(Command::Bench {
            json,
            svg,
            csv,
            merge,
            ..
        }) => bench_merge(merge, [json.as_deref(), svg.as_deref(), csv.as_deref()]),
        Some(Command::Job {
            scenario,
            tol,
            h,
            trace,
            events,
        }) => job(scenario, *tol, *h, trace, events),
        Some(Command::Scenarios { json }) => scenarios::run(json.as_deref()),
        Some(Command::Compare {
            scenarios,
            report,
            threads,
        }) => compare(scenarios, report, false, *threads),
        Some(Command::Sweep {
            u,
            param,
            params,
            x0,
            solver,
            shard,
            resume,
            threads,
            t_end,
            csv,
        }) => sweep(
            u,
            param,
            params.as_deref(),
            x0.as_deref(),
            solver,
            shard.as_deref(),
            (*resume, *t_end, *threads),
            csv,
        ),
        Some(Command::Merge { shards, csv }) => merge(shards, csv),
        Some(Command::Bifurcation2 {
            param,
            p_min,
            p_max,
            params,
            u_min,
            u_max,
            json,
            svg,
        }) => bifurcation2(
            param,
            [*p_min, *p_max, *u_min, *u_max],
            params.as_deref(),
            json,
            svg.as_deref(),
        ),
        Some(Command::Reference { out, threads }) => {
            let threads = match thread_pool(*threads) {
                Ok(t) => t,
                Err(e) => {
                    eprintln!("error: {e:#}");
                    return ExitCode::FAILURE;
                }
            };
            eprintln!("reference data on {threads}");
            let fixtures = checkout_fixtures();
            let out = out.clone().unwrap_or_else(|| open::default_out(&fixtures));
            open::write_reference(&fixtures.join("scenarios"), &out)
        }
        Some(Command::Check {
            scenario,
            trace,
            events,
            gate,
            digits,
            json,
        }) => {
            return open::check_trace(
                scenario,
                trace,
                events.as_deref(),
                gate,
                digits.as_deref(),
                json.as_deref(),
            );
        }
        None => compare(&[], Path::new("reports"), true, cli.threads),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output has gone: stop quietly, as a Unix tool does.
        Err(e) if out::is_closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
