//! The open benchmark's commands: `rotor reference` and `rotor check`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use rayon::prelude::*;
use rotor_grade::check::{CheckError, Level, check};
use rotor_grade::reference;

/// `rotor reference [--out DIR]`: the reference files of every scenario.
pub fn write_reference(scenarios_dir: &Path, out: &Path) -> Result<()> {
    let files = rotor_model::Scenario::list_dir(scenarios_dir)
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
    .map_err(|e| anyhow::anyhow!(e.as_flag()))?;
    // The scenario and its reference first: the trace is read up to one row past their grid.
    let scenario = crate::fixture_path("scenario", scenario, "scenarios")?;
    let sc = rotor_solvers::load_scenario(&scenario)?;
    let r = reference::read(&reference::dir_for(&scenario), &sc.name)?;
    let t = rotor_grade::trace::read_trace(trace, r.samples.len() + 1).map_err(CheckError::from)?;
    let ev = events
        .map(rotor_grade::trace::read_events)
        .transpose()
        .map_err(CheckError::from)?;
    let report = check(&sc, &r, &t, ev.as_ref(), level)?;
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report)? + "\n";
        // A closed pipe on `--json -` does not hide the verdict's exit status.
        crate::out::closed_is_fine(rotor_compare::report::write_output(path, text.as_bytes()))
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

/// The default reference directory.
pub fn default_out(fixtures: &Path) -> PathBuf {
    fixtures.join("reference")
}
