//! What `rotor bench` writes, from a run or a merge: the table, the JSON, SVG and CSV
//! outputs, and the published-results page.

use std::path::Path;

use anyhow::{Context, Result};

use crate::common::say;

/// Prints a benchmark report's table and writes its files.
pub(crate) fn write_bench(
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

/// `--results FILE`: the published-results page.
pub(crate) fn write_results(report: &rotor_bench::BenchReport, path: Option<&Path>) -> Result<()> {
    if let Some(path) = path {
        // The command that wrote it, as given (`just bench` runs the whole suite's).
        let args: Vec<String> = std::env::args().skip(1).collect();
        let command = format!("rotor {}", args.join(" "));
        rotor_compare::report::write_output(path, report.to_results_md(&command)?.as_bytes())
            .with_context(|| format!("--results {}: cannot write", path.display()))?;
    }
    Ok(())
}
