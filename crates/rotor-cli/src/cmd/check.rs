//! `rotor check`: one trace graded against the reference (exit 0, 1 or 2).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use rotor_harness::grade::check::{CheckError, Level, check};
use rotor_harness::grade::reference;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario file, or a name of the suite (`t1-u1.5-rest`, or a chain scene such as
    /// `chain3-u1.5-rest`); its reference is read from the reference directory beside it. A
    /// chain's trace is headed `t,alpha_1,…,omega_N` and its events name discs `1` … `N`.
    pub scenario: PathBuf,
    /// The trace to grade.
    #[arg(long)]
    pub trace: PathBuf,
    /// The trace's events (CSV t,disc,kind). Without them the verdict says "events not
    /// graded".
    #[arg(long)]
    pub events: Option<PathBuf>,
    /// The level: strict (7 significant digits on every quantity: a well-converged
    /// adaptive integrator) or loose (3: engineering accuracy).
    #[arg(long, default_value = "loose", conflicts_with = "digits")]
    pub gate: String,
    /// Pass when every graded quantity reaches N significant digits (instead of --gate).
    #[arg(long, value_name = "N")]
    pub digits: Option<String>,
    /// Write the verdict as JSON (`-`: standard output).
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(a: &Args) -> ExitCode {
    check_trace(
        &a.scenario,
        &a.trace,
        a.events.as_deref(),
        &a.gate,
        a.digits.as_deref(),
        a.json.as_deref(),
    )
}

/// `rotor check`: 0 when the level is reached, 1 when not, 2 when the input is unusable.
pub fn check_trace(
    scenario: &Path,
    trace: &Path,
    events: Option<&Path>,
    gate: &str,
    digits: Option<&str>,
    json: Option<&Path>,
) -> ExitCode {
    match verdict(scenario, trace, events, gate, digits, json) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// The verdict (`Ok(passed)`), or why the input cannot be graded.
fn verdict(
    scenario: &Path,
    trace: &Path,
    events: Option<&Path>,
    gate: &str,
    digits: Option<&str>,
    json: Option<&Path>,
) -> Result<bool> {
    let level = match digits {
        Some(n) => Level::with_digits(n),
        None => Level::parse(gate),
    }
    .map_err(crate::common::flagged)?;
    // The scenario and its reference first: the trace is read up to one row past their grid.
    let (scenario, is_chain) = crate::common::scene_path("scenario", scenario)?;
    let report = if is_chain {
        let (sc, r) = rotor_harness::grade::chain::load(&scenario)?;
        let names = sc.model().state_names();
        let t = rotor_harness::grade::trace::read_chain_trace(trace, &names, r.grid_rows() + 1)
            .map_err(CheckError::from)?;
        let ev = events
            .map(|p| rotor_harness::grade::trace::read_chain_events(p, sc.discs()))
            .transpose()
            .map_err(CheckError::from)?;
        rotor_harness::grade::chain::check_chain(&sc, &r, &t, ev.as_ref(), level)?
    } else {
        let sc = rotor_analysis::solvers::load_scenario(&scenario)?;
        let r = reference::read(&reference::dir_for(&scenario), &sc.name)?;
        let t = rotor_harness::grade::trace::read_trace(trace, r.samples.len() + 1)
            .map_err(CheckError::from)?;
        let ev = events
            .map(rotor_harness::grade::trace::read_events)
            .transpose()
            .map_err(CheckError::from)?;
        check(&sc, &r, &t, ev.as_ref(), level)?
    };
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report)? + "\n";
        // A closed pipe on `--json -` does not hide the verdict's exit status.
        crate::out::closed_is_fine(rotor_harness::compare::report::write_output(
            path,
            text.as_bytes(),
        ))
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    let table = report.table();
    if json.is_some_and(|p| p.as_os_str() == "-") {
        eprint!("{table}");
    } else {
        crate::out::print(&table)?;
    }
    if !report.passed {
        eprintln!("failing: {}", report.failing().join(", "));
    }
    Ok(report.passed)
}
