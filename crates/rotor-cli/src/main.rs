//! `rotor`: the command-line front end (contract: DESIGN.md §4).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand};
use rotor_model::{Model, Output, Params, Scene, Solver, State, SteadyState};

/// Two-disc rotor with set-valued friction: three independent solvers, cross-validated.
#[derive(Parser, Debug)]
#[command(name = "rotor", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate one scene and write the trajectory as CSV (t,alpha,omega_u,omega_l).
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Horizon [s].
        #[arg(long, default_value_t = 100.0)]
        t_end: f64,
        /// Output interval [s] (rows at 0, dt, 2dt, ..., t_end).
        #[arg(long, default_value_t = 0.01)]
        dt: f64,
        /// Output CSV file.
        #[arg(long)]
        csv: PathBuf,
    },
    /// Run to steady state and print it as one JSON object.
    Steady {
        #[command(flatten)]
        common: Common,
    },
    /// Run scenarios through the three solvers, gate their agreement, write the report.
    Compare {
        /// Scenario files (default: every fixtures/scenarios/*.toml).
        scenarios: Vec<PathBuf>,
        /// Report directory.
        #[arg(long, default_value = "reports")]
        report: PathBuf,
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
    /// Parameter file (default: the source's Table 1).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Initial state alpha,omega_u,omega_l (default: rest).
    #[arg(long, allow_hyphen_values = true)]
    x0: Option<String>,
    /// Integration tolerance (switch, event).
    #[arg(long)]
    tol: Option<f64>,
    /// Step size (moreau) [s].
    #[arg(long)]
    h: Option<f64>,
}

const SOLVERS: [&str; 3] = ["switch", "event", "moreau"];

fn solver_by_name(name: &str) -> Result<Box<dyn Solver>> {
    match name {
        "event" => Ok(Box::new(rotor_event::EventSolver::default())),
        "switch" => Ok(Box::new(rotor_switch::SwitchSolver::default())),
        "moreau" => Ok(Box::new(rotor_moreau::MoreauSolver::default())),
        other => bail!(
            "--solver {other:?}: unknown solver (expected one of: {})",
            SOLVERS.join(", ")
        ),
    }
}

fn load_model(params: Option<&Path>) -> Result<Model> {
    let p = match params {
        Some(p) => Params::from_file(p)?,
        None => Params::table1(),
    };
    Ok(Model::new(p))
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

/// Checks a numeric option: finite and in range, naming the flag and the value.
fn check(flag: &str, v: f64, ok: bool, what: &str) -> Result<()> {
    if !v.is_finite() || !ok {
        bail!("--{flag} {v}: {what}");
    }
    Ok(())
}

fn scene_from(common: &Common, t_end: f64, output: Output) -> Result<Scene> {
    check("u", common.u, true, "must be a finite number")?;
    let d = Scene::default();
    let tol = common.tol.unwrap_or(d.tol);
    check("tol", tol, tol > 0.0 && tol < 1.0, "must lie in (0, 1)")?;
    let h = common.h.unwrap_or(d.h);
    check("h", h, h > 0.0 && h <= t_end, "must lie in (0, t_end]")?;
    Ok(Scene {
        u: common.u,
        x0: parse_x0(common.x0.as_deref())?,
        t_end,
        tol,
        h,
        output,
        metrics_from: None,
    })
}

fn simulate(common: &Common, t_end: f64, dt: f64, csv_path: &Path) -> Result<()> {
    check("t-end", t_end, t_end > 0.0, "must be positive")?;
    check("dt", dt, dt > 0.0, "must be positive")?;
    let solver = solver_by_name(&common.solver)?;
    let model = load_model(common.params.as_deref())?;
    let scene = scene_from(common, t_end, Output::Grid { dt })?;
    let traj = solver
        .simulate(&model, &scene)
        .with_context(|| format!("solver {}", solver.name()))?;
    let mut buf = Vec::with_capacity(traj.samples.len() * 64);
    writeln!(buf, "t,alpha,omega_u,omega_l")?;
    for s in &traj.samples {
        if !(s.t.is_finite() && s.x.iter().all(|v| v.is_finite())) {
            bail!(
                "solver {} produced a non-finite sample at t = {}",
                solver.name(),
                s.t
            );
        }
        writeln!(buf, "{},{},{},{}", s.t, s.x[0], s.x[1], s.x[2])?;
    }
    rotor_compare::report::write_atomic(csv_path, &buf)
        .with_context(|| format!("{}: cannot write", csv_path.display()))?;
    Ok(())
}

fn steady(common: &Common) -> Result<()> {
    let model = load_model(common.params.as_deref())?;
    let st = match common.solver.as_str() {
        "event" => {
            let mut opts = rotor_event::SteadyOptions::default();
            if let Some(tol) = common.tol {
                check("tol", tol, tol > 0.0 && tol < 1.0, "must lie in (0, 1)")?;
                opts.tol = tol;
            }
            let scene = scene_from(common, opts.settle, Output::Final)?;
            scene.validate()?;
            rotor_event::steady_state(
                &model,
                scene.u,
                scene.x0,
                &opts,
                &rotor_event::EventOptions::default(),
            )?
        }
        other => {
            let solver = solver_by_name(other)?;
            // From the simulated orbit: a long run, metrics over its second half.
            let t_end = 600.0;
            let mut scene = scene_from(common, t_end, Output::Final)?;
            scene.metrics_from = Some(0.5 * t_end);
            let traj = solver.simulate(&model, &scene)?;
            traj.metrics
                .ok_or_else(|| anyhow!("solver {other} returned no metrics"))?
        }
    };
    for (name, v) in st.values() {
        if !v.is_finite() {
            bail!("steady state has a non-finite {name}: {v}");
        }
    }
    println!("{}", steady_json(&st));
    Ok(())
}

/// The fixtures directory: next to the workspace root when run through cargo, else ./fixtures.
fn fixtures_dir() -> PathBuf {
    let local = PathBuf::from("fixtures");
    if local.is_dir() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn compare(files: &[PathBuf], report: &Path) -> Result<()> {
    use rayon::prelude::*;
    let files = if files.is_empty() {
        let dir = fixtures_dir().join("scenarios");
        rotor_model::Scenario::list_dir(&dir)
            .with_context(|| format!("{}: cannot list scenarios", dir.display()))?
    } else {
        files.to_vec()
    };
    let scenarios = files
        .iter()
        .map(|f| rotor_model::Scenario::from_file(f))
        .collect::<Result<Vec<_>, _>>()?;
    let t0 = std::time::Instant::now();
    let bar = progress_bar(scenarios.len() as u64, "scenarios");
    // In parallel across scenarios; collected in input order, so output is deterministic.
    let results: Vec<_> = scenarios
        .par_iter()
        .map(|sc| {
            let r = rotor_compare::run_scenario(sc);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    let params = [
        ("Table 1 (exponential)", Params::table1()),
        (
            "Stribeck set (unverified)",
            Params::from_file(&fixtures_dir().join("params/stribeck.toml"))?,
        ),
    ];
    let fails = rotor_compare::report::write_report(report, &results, &params)
        .with_context(|| format!("{}: cannot write the report", report.display()))?;
    println!(
        "{:<18} {:<7} {:<12} {:>10} {:>12} {:>9}",
        "scenario", "solver", "steady", "period", "omega_l_max", "ms"
    );
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
            println!(
                "{:<18} {:<7} {:<12} {:>10} {:>12} {:>9.1}",
                r.scenario.name,
                run.kind.name(),
                kind,
                period,
                wmax,
                run.seconds * 1e3
            );
        }
    }
    println!(
        "{} scenarios, 3 solvers, {:.2} s wall; report in {}",
        results.len(),
        wall,
        report.display()
    );
    if fails.is_empty() {
        println!("all agreement gates pass");
        Ok(())
    } else {
        for f in &fails {
            eprintln!("GATE FAILED: {f}");
        }
        bail!("{} agreement gate(s) failed", fails.len())
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

fn steady_json(st: &SteadyState) -> String {
    serde_json::to_string(st).expect("plain floats and strings serialize")
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let res = match &cli.command {
        Some(Command::Simulate {
            common,
            t_end,
            dt,
            csv,
        }) => simulate(common, *t_end, *dt, csv),
        Some(Command::Steady { common }) => steady(common),
        Some(Command::Compare { scenarios, report }) => compare(scenarios, report),
        None => compare(&[], Path::new("reports")),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
