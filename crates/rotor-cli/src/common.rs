//! What the commands share: the scene's flags, loading a model, `--x0`, the thread pool,
//! the progress bar, where the fixtures are, and where a summary goes.

use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow, bail};
use rotor_model::{Model, Params, State};
use rotor_solvers::SolverKind;

use crate::out;

#[derive(clap::Args, Debug)]
pub(crate) struct Common {
    /// Solver: switch, event or moreau.
    #[arg(long)]
    pub(crate) solver: String,
    /// Motor input voltage, in V.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) u: f64,
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long)]
    pub(crate) params: Option<PathBuf>,
    /// Initial state alpha,omega_u,omega_l (default: rest).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) x0: Option<String>,
    /// Integration tolerance (switch, event).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) tol: Option<f64>,
    /// Step size (moreau), in s.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) h: Option<f64>,
}

pub(crate) fn kind_by_name(name: &str) -> Result<SolverKind> {
    rotor_jobs::request::solver_kind(name).map_err(flagged)
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

pub(crate) fn parse_x0(s: Option<&str>) -> Result<State> {
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
pub(crate) fn warn_inexact(stats: &rotor_seam::Stats) {
    if let Some(w) = rotor_jobs::request::inexact_warning(stats, "--h") {
        eprintln!("warning: {w}");
    }
}

/// `--threads N`: a whole number from 1 (clap's error names the flag and the value).
pub(crate) fn threads_arg(s: &str) -> Result<usize, String> {
    rotor_compare::threads::parse_count(s)
}

/// Starts the thread pool of a command that runs in parallel: `--threads`, else
/// `SLURM_CPUS_PER_TASK`, else the cores available ([`rotor_compare::threads`]). Returns the
/// count in words ("1 thread", "8 threads, from SLURM_CPUS_PER_TASK") for the run's summary.
pub(crate) fn thread_pool(explicit: Option<usize>) -> Result<String> {
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

/// Checks a numeric option: finite and in range, else the refusal naming its flag
/// ([`flagged`]) and the value.
pub(crate) fn check(field: &str, v: f64, ok: bool, what: &str) -> Result<()> {
    rotor_jobs::request::check_number(field, v, ok, what).map_err(flagged)
}

/// A bad input as the command line spells it: the field as its flag (`t_end` is `--t-end`).
pub(crate) fn flagged(e: rotor_model::FieldError) -> anyhow::Error {
    anyhow!(e.as_flag())
}

/// A sweep's error as the command line spells it: a refused argument names its flag
/// ([`flagged`]); the others keep their sources.
pub(crate) fn sweep_flagged(e: rotor_jobs::sweep::SweepError) -> anyhow::Error {
    match e {
        rotor_jobs::sweep::SweepError::Arg(f) => flagged(f),
        e => e.into(),
    }
}

/// The checked request of `simulate` and `steady` (the same checks and words as the Python
/// package's), with a warning for a setting the solver ignores.
pub(crate) fn request(common: &Common) -> Result<rotor_jobs::request::Request<'_>> {
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

/// A progress bar on stderr when it is a terminal; hidden in CI and when piped, so logs and
/// captured output stay clean.
pub(crate) fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
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

/// The checkout's fixtures directory, which `rotor reference` writes: ./fixtures when run in
/// the workspace root, else the one this binary was built from.
pub(crate) fn checkout_fixtures() -> PathBuf {
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
pub(crate) fn fixtures_dir() -> Result<PathBuf> {
    let local = PathBuf::from("fixtures");
    if std::env::var_os("ROTORBENCH_SUITE").is_none() && local.join("scenarios").is_dir() {
        return Ok(local);
    }
    Ok(rotor_suite::locate()?.dir)
}
