//! What the commands share: the scene's flags, loading a model, `--x0`, the thread pool,
//! the progress bar, where the fixtures are, and where a summary goes.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use rotor_analysis::solvers::SolverKind;
use rotor_model::{Model, Params};

use crate::out;

#[derive(clap::Args, Debug)]
pub(crate) struct Common {
    /// A scenario file, or a name in fixtures/scenarios (`t1-u1.5-rest`): its u, x0 and
    /// parameter set (and, for `simulate`, its horizon and grid, so that `rotor check` takes
    /// the trace). Without it, --u or --input is required.
    #[arg(value_name = "SCENARIO")]
    pub(crate) scenario: Option<PathBuf>,
    /// Solver: switch, event or moreau.
    #[arg(long)]
    pub(crate) solver: String,
    /// Motor input voltage, in V (the model describes the rig over a few volts: a warning
    /// above 10 V).
    #[arg(
        long,
        allow_hyphen_values = true,
        required_unless_present_any = ["scenario", "input"],
        conflicts_with = "scenario"
    )]
    pub(crate) u: Option<f64>,
    /// A motor input that changes in time, instead of --u: a CSV with header `t,u` (s, V),
    /// rows in non-decreasing t; u is linear between rows, constant before the first and
    /// after the last, and two rows at one t are a step (the second value holds from it).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["u", "scenario"])]
    pub(crate) input: Option<PathBuf>,
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long, conflicts_with = "scenario")]
    pub(crate) params: Option<PathBuf>,
    /// Initial state alpha,omega_u,omega_l (a chain's alpha_1,…,omega_N; default: rest).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "scenario")]
    pub(crate) x0: Option<String>,
    /// Integration tolerance (switch, event).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) tol: Option<f64>,
    /// Step size (moreau), in s.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) h: Option<f64>,
}

/// An input the command cannot use (a bad flag value, a file that is not what it should
/// be): exit status 2, as for what clap refuses. Every other error is a failure of the run
/// (exit 1). See [`exit_code`].
#[derive(Debug)]
pub(crate) struct Unusable(pub(crate) String);

impl std::fmt::Display for Unusable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Unusable {}

/// The error of an input the command cannot use ([`Unusable`], exit 2).
pub(crate) fn unusable(msg: impl std::fmt::Display) -> anyhow::Error {
    anyhow::Error::new(Unusable(msg.to_string()))
}

/// The exit status of an error: 2 when the input is unusable (a refused flag value, a
/// parameter or scenario file that does not load, shards that do not fit together), 1 when
/// the run failed (a solver, a gate, a client that solved nothing, a write).
pub(crate) fn exit_code(e: &anyhow::Error) -> u8 {
    let bad_input = e.chain().any(|c| {
        c.is::<Unusable>()
            || c.is::<rotor_model::ParamsError>()
            || c.is::<rotor_model::FieldError>()
            || c.is::<rotor_model::scenario::ScenarioError>()
            || c.is::<rotor_suite::SuiteError>()
            || invalid_scene(c)
            || matches!(
                c.downcast_ref::<rotor_harness::report::ReportError>(),
                Some(rotor_harness::report::ReportError::DuplicateName { .. })
            )
            || matches!(
                c.downcast_ref::<rotor_harness::bench::BenchError>(),
                Some(
                    rotor_harness::bench::BenchError::Options(_)
                        | rotor_harness::bench::BenchError::Scenario(_)
                )
            )
            || matches!(
                c.downcast_ref::<rotor_harness::jobs::sweep::SweepError>(),
                Some(
                    rotor_harness::jobs::sweep::SweepError::Arg(_)
                        | rotor_harness::jobs::sweep::SweepError::File { .. }
                        | rotor_harness::jobs::sweep::SweepError::Merge(_)
                )
            )
    });
    if bad_input { 2 } else { 1 }
}

/// Whether a solver refused the scene itself (an input it cannot run, as u = 1e308), also
/// where a steady-state error carries it transparently.
fn invalid_scene(c: &(dyn std::error::Error + 'static)) -> bool {
    use rotor_model::seam::SolveError::InvalidScene;
    matches!(c.downcast_ref(), Some(InvalidScene(_)))
        || matches!(
            c.downcast_ref(),
            Some(rotor_analysis::steady::SteadyError::Solve(InvalidScene(_)))
        )
        || matches!(
            c.downcast_ref(),
            Some(rotor_analysis::steady::SettleError::Solve(InvalidScene(_)))
        )
}

pub(crate) fn kind_by_name(name: &str) -> Result<SolverKind> {
    rotor_harness::jobs::request::solver_kind(name).map_err(flagged)
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
pub(crate) fn load_model(params: Option<&Path>) -> Result<Model> {
    let p = match params {
        Some(p) => Params::from_file(&fixture_path("--params", p, "params")?)?,
        None => Params::table1(),
    };
    Ok(Model::new(p))
}

/// The file a path argument names: a path, or the name of a file in `fixtures/KIND`
/// ([`rotor_analysis::solvers::fixtures::resolve`]). A name that is neither is an error naming `flag`
/// and listing the names there.
pub(crate) fn fixture_path(flag: &str, p: &Path, kind: &str) -> Result<PathBuf> {
    let dir = fixtures_dir()?.join(kind);
    rotor_analysis::solvers::fixtures::resolve(p, Some(&dir)).ok_or_else(|| {
        unusable(format_args!(
            "{flag} {}: no such file, nor a name in {} (names: {})",
            p.display(),
            dir.canonicalize().unwrap_or_else(|_| dir.clone()).display(),
            rotor_analysis::solvers::fixtures::names(&dir).join(", ")
        ))
    })
}

/// A scene argument: a scenario file, or a name of the suite's rig tier (`fixtures/scenarios`)
/// or chain tier (`fixtures/chain/scenarios`). The path, and whether it is a chain scene.
pub(crate) fn scene_path(flag: &str, p: &Path) -> Result<(PathBuf, bool)> {
    let fixtures = fixtures_dir()?;
    let rig = fixtures.join("scenarios");
    let chain = fixtures.join("chain/scenarios");
    let found = rotor_analysis::solvers::fixtures::resolve(p, Some(&rig))
        .or_else(|| rotor_analysis::solvers::fixtures::resolve(p, Some(&chain)));
    let Some(path) = found else {
        let mut names = rotor_analysis::solvers::fixtures::names(&rig);
        names.extend(rotor_analysis::solvers::fixtures::names(&chain));
        return Err(unusable(format_args!(
            "{flag} {}: no such file, nor a name of the suite in {} (names: {})",
            p.display(),
            fixtures
                .canonicalize()
                .unwrap_or_else(|_| fixtures.clone())
                .display(),
            names.join(", ")
        )));
    };
    let is_chain = rotor_model::scenario::ChainScenario::is_chain_scene(&path);
    Ok((path, is_chain))
}

/// `--x0`: the initial state as comma-separated numbers, one per component of the model's
/// state (`names`: the rig's `alpha,omega_u,omega_l`); rest when not given.
pub(crate) fn parse_x0(s: Option<&str>, names: &[&str]) -> Result<Vec<f64>> {
    let Some(s) = s else {
        return Ok(vec![0.0; names.len()]);
    };
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != names.len() {
        let count = match names.len() {
            3 => "three".to_owned(),
            n => n.to_string(),
        };
        return Err(unusable(format_args!(
            "--x0 {s:?}: expected {count} comma-separated numbers {}",
            names.join(",")
        )));
    }
    parts
        .iter()
        .map(|p| {
            let v: f64 = p
                .parse()
                .map_err(|_| unusable(format_args!("--x0 {s:?}: {p:?} is not a number")))?;
            if !v.is_finite() {
                return Err(unusable(format_args!("--x0 {s:?}: {p:?} is not finite")));
            }
            Ok(v)
        })
        .collect()
}

/// Moreau–Jean steps whose step problem did not converge are answers to distrust: say so.
pub(crate) fn warn_inexact(stats: &rotor_model::seam::Stats) {
    if let Some(w) = rotor_harness::jobs::request::inexact_warning(stats, "--h") {
        eprintln!("warning: {w}");
    }
}

/// `--threads N`: a whole number from 1 (clap's error names the flag and the value).
pub(crate) fn threads_arg(s: &str) -> Result<usize, String> {
    rotor_harness::compare::threads::parse_count(s)
}

/// Starts the thread pool of a command that runs in parallel: `--threads`, else
/// `SLURM_CPUS_PER_TASK`, else the cores available ([`rotor_harness::compare::threads`]). Returns the
/// count in words ("1 thread", "8 threads, from SLURM_CPUS_PER_TASK") for the run's summary.
pub(crate) fn thread_pool(explicit: Option<usize>) -> Result<String> {
    use rotor_harness::compare::threads::Source;
    let (n, src) = rotor_harness::compare::threads::resolve(explicit).map_err(unusable)?;
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

/// Checks a numeric option: finite and in range, else the refusal naming its flag
/// ([`flagged`]) and the value.
pub(crate) fn check(field: &str, v: f64, ok: bool, what: &str) -> Result<()> {
    rotor_harness::jobs::request::check_number(field, v, ok, what).map_err(flagged)
}

/// A bad input as the command line spells it: the field as its flag (`t_end` is `--t-end`).
pub(crate) fn flagged(e: rotor_model::FieldError) -> anyhow::Error {
    unusable(e.as_flag())
}

/// A sweep's error as the command line spells it: a refused argument names its flag
/// ([`flagged`]); the others keep their sources.
pub(crate) fn sweep_flagged(e: rotor_harness::jobs::sweep::SweepError) -> anyhow::Error {
    match e {
        rotor_harness::jobs::sweep::SweepError::Arg(f) => flagged(f),
        e => e.into(),
    }
}

/// The largest |u| \[V\] taken without a warning. Every special point of both parameter
/// sets lies below 5 V (the last, Table 1's fold E, at 4.84 V) and the bifurcation
/// diagrams span 0 to 7 V; above that the rotor only settles to a faster slipping
/// equilibrium, its speed growing as k_m u / (b_u + b_l) (about 1.8 rad/s per volt for
/// Table 1). Twice the last special point is far enough past all of it that a larger
/// value is more likely a slip of the keyboard (millivolts, a missing decimal point) than
/// a question about the rig.
pub(crate) const U_PLAUSIBLE: f64 = 10.0;

/// A warning for an input far outside what the model describes ([`U_PLAUSIBLE`]), with
/// the slipping speed it would give; `None` for a plausible one. `source` names where u came
/// from as the user wrote it (`--u`, `--input FILE`, the scenario).
pub(crate) fn implausible_u(u: f64, model: &Model, source: &str) -> Option<String> {
    if !u.is_finite() || u.abs() <= U_PLAUSIBLE {
        return None;
    }
    let p = &model.params;
    // The slipping equilibrium's speed when viscous friction dominates:
    // k_m u = (b_u + b_l) ω + the (bounded) Coulomb parts.
    let omega = p.k_m * u / (p.upper.b + p.lower.viscous());
    if !omega.is_finite() {
        return None; // the solvers refuse it, naming the overflow
    }
    let shown = if u.abs() > 1e6 {
        format!("{u:e}")
    } else {
        format!("{u}")
    };
    Some(format!(
        "{source} {shown}: far outside the few volts the model describes (every special point of \
         both parameter sets lies below 5 V, the bifurcation diagrams span 0 to 7 V; above \
         {U_PLAUSIBLE} V only a faster slipping equilibrium remains): the discs would slip at \
         about {omega:.2e} rad/s. Millivolts or a missing decimal point?"
    ))
}

/// What a run starts from: the scenario's u, x0 and model when one is given, else the
/// flags'. The scenario, if any, comes back for its horizon and grid.
pub(crate) struct Start {
    pub(crate) u: f64,
    /// A time-varying input (`--input`, or the scenario's `input`).
    pub(crate) input: Option<rotor_model::seam::Input>,
    pub(crate) x0: Vec<f64>,
    pub(crate) model: Model,
    pub(crate) scenario: Option<rotor_model::scenario::Scenario>,
}

/// Loads the start of `simulate` and `steady` ([`Start`]), warning about an implausible u.
pub(crate) fn start(common: &Common) -> Result<Start> {
    let s = match &common.scenario {
        Some(p) => {
            let sc =
                rotor_analysis::solvers::load_scenario(&fixture_path("SCENARIO", p, "scenarios")?)?;
            Start {
                u: sc.u,
                input: sc.input.clone(),
                x0: sc.x0.clone(),
                model: sc.model,
                scenario: Some(sc),
            }
        }
        None => {
            let input = common.input.as_deref().map(read_input).transpose()?;
            let model = load_model(common.params.as_deref())?;
            Start {
                // clap requires --u without a scenario.
                u: common.u.unwrap_or(f64::NAN),
                input,
                x0: parse_x0(common.x0.as_deref(), &model.state_names())?,
                model,
                scenario: None,
            }
        }
    };
    let u_max = s.input.as_ref().map_or(s.u, |i| i.max_abs());
    let source = match (&common.scenario, &common.input) {
        (Some(p), _) => format!("scenario {}: u reaches", p.display()),
        (None, Some(f)) => format!("--input {}: u reaches", f.display()),
        (None, None) => "--u".to_owned(),
    };
    if let Some(w) = implausible_u(u_max, &s.model, &source) {
        eprintln!("warning: {w}");
    }
    Ok(s)
}

/// `--input FILE`: the input table, read and checked (exit 2 naming the file, the row and
/// the bad value).
pub(crate) fn read_input(path: &Path) -> Result<rotor_model::seam::Input> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| unusable(format_args!("--input {}: cannot read: {e}", path.display())))?;
    rotor_model::seam::Input::from_csv(&text, &path.display().to_string())
        .map_err(|e| unusable(format_args!("--input: {e}")))
}

/// The checked request of `simulate` and `steady` (the same checks and words as the Python
/// package's), with a warning for a setting the solver ignores.
pub(crate) fn request<'a>(
    common: &'a Common,
    start: &Start,
) -> Result<rotor_harness::jobs::request::Request<'a>> {
    let req = rotor_harness::jobs::request::Request {
        solver: &common.solver,
        u: start.u,
        input: start.input.clone(),
        x0: start.x0.clone(),
        tol: common.tol,
        h: common.h,
    };
    if let Some(i) = req.ignored() {
        eprintln!("warning: {}", i.as_flag());
    }
    Ok(req)
}

/// Whether progress is shown: stderr is a terminal, and not in CI.
fn show_progress() -> bool {
    use std::io::IsTerminal;
    std::env::var_os("CI").is_none() && std::io::stderr().is_terminal()
}

/// A spinner with the elapsed time on stderr, for work whose size is not known in advance;
/// hidden as [`progress_bar`] is.
pub(crate) fn progress_spinner(what: &str) -> indicatif::ProgressBar {
    if !show_progress() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{spinner} {msg} [{elapsed_precise}]")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_owned());
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// A progress bar on stderr when it is a terminal; hidden in CI and when piped, so logs and
/// captured output stay clean.
pub(crate) fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    if !show_progress() {
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

/// The suite's directory, for scenarios and parameter sets given by name: ./fixtures in a
/// checkout's root, else what [`rotor_suite::locate`] finds (`$ROTORBENCH_FIXTURES`, the
/// checkout this binary was built from, or the suite embedded in it). With
/// `ROTORBENCH_SUITE=embedded`, always the embedded suite.
pub(crate) fn fixtures_dir() -> Result<PathBuf> {
    let local = PathBuf::from("fixtures");
    if std::env::var_os("ROTORBENCH_SUITE").is_none() && local.join("scenarios").is_dir() {
        return Ok(local);
    }
    Ok(rotor_suite::locate()?.dir)
}

/// Returns an [`Unusable`] error (exit 2) with a `format!` message: `bail!` for bad input.
macro_rules! refuse {
    ($($t:tt)*) => {
        return Err($crate::common::unusable(format_args!($($t)*)))
    };
}
pub(crate) use refuse;

/// The chain a `--params` file in chain form gives, with its path (`None` for a file in the
/// rig's form, or no `--params`). `simulate` runs a chain of two as the rig, its trace headed
/// with the chain's names; `steady` answers any chain file with the chain's lists.
pub(crate) fn chain_file(common: &Common) -> Result<Option<(PathBuf, rotor_model::ChainParams)>> {
    let Some(p) = common.params.as_deref() else {
        return Ok(None);
    };
    let path = fixture_path("--params", p, "params")?;
    let chain = rotor_model::ChainParams::from_file(&path)?;
    // The file loaded, so it is a small text file: read again to tell its form.
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    Ok(rotor_model::ChainParams::is_chain_form(&text).then_some((path, chain)))
}

/// The solver `--solver` names for a chain of `n` discs read from `path`: one that runs
/// chains, with its own setting only (`--tol` or `--h`; the other would be silently unused).
pub(crate) fn chain_solver(
    common: &Common,
    path: &Path,
    n: usize,
) -> Result<rotor_analysis::solvers::SolverKind> {
    let kind = rotor_analysis::solvers::solver_kind(&common.solver)?;
    if kind.info().chain.is_none() {
        return Err(unusable(format_args!(
            "--solver {}: {} is a chain with {n} discs, which {} does not run (--solver {})",
            kind.name(),
            path.display(),
            kind.name(),
            rotor_analysis::solvers::SolverKind::chain_solver_names(", ")
        )));
    }
    // Each solver's own setting only: the other one would be silently unused.
    match (
        kind.is_fixed_step(),
        common.tol.is_some(),
        common.h.is_some(),
    ) {
        (true, true, _) => {
            return Err(unusable(format_args!(
                "--tol: {} takes a step, --h",
                kind.name()
            )));
        }
        (false, _, true) => {
            return Err(unusable(format_args!(
                "--h: {} takes a tolerance, --tol",
                kind.name()
            )));
        }
        _ => {}
    }
    Ok(kind)
}

/// A chain run's request from the command line: the solver (as [`chain_solver`] admits it),
/// `--input` read, `--x0` of the chain's 2N − 1 values.
pub(crate) fn chain_request<'a>(
    common: &'a Common,
    path: &Path,
    model: &rotor_model::ChainModel,
) -> Result<(SolverKind, rotor_harness::jobs::request::Request<'a>)> {
    let kind = chain_solver(common, path, model.discs())?;
    let input = common.input.as_deref().map(read_input).transpose()?;
    let names = model.state_names();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let x0 = parse_x0(common.x0.as_deref(), &refs)?;
    let request = rotor_harness::jobs::request::Request {
        solver: &common.solver,
        // clap requires --u without a scenario or --input.
        u: common.u.unwrap_or(f64::NAN),
        input,
        x0,
        tol: common.tol,
        h: common.h,
    };
    Ok((kind, request))
}
