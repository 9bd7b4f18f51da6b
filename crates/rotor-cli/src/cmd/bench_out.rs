//! What `rotor bench` writes, from a run or a merge: the table, the JSON, SVG and CSV
//! outputs, and the published-results page.

use std::path::Path;

use anyhow::{Context, Result};

use crate::common::say;

/// Prints a benchmark report's table and writes its files.
pub(crate) fn write_bench(
    report: &rotor_harness::bench::BenchReport,
    [json, svg, csv]: [Option<&Path>; 3],
) -> Result<()> {
    use rotor_harness::compare::report::write_output;
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
    if let Some(path) = svg.filter(|p| p.as_os_str() != "-") {
        write_figures(report, path)?;
    }
    Ok(())
}

/// Beside the summary figure `<stem>.svg`: every scene's figure `<stem>-<scene>.svg`, each
/// figure's data `<stem>-<name>.csv`, and the page `<stem>.html` that shows them all.
fn write_figures(report: &rotor_harness::bench::BenchReport, svg: &Path) -> Result<()> {
    use rotor_harness::compare::report::write_output;
    let stem = svg
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bench".into());
    let dir = svg.parent().unwrap_or(Path::new(""));
    let write = |name: String, bytes: &[u8]| {
        let path = dir.join(name);
        write_output(&path, bytes).with_context(|| format!("{}: cannot write", path.display()))
    };
    for f in report.figures()? {
        if f.name != "profile" {
            write(format!("{stem}-{}.svg", f.name), f.svg.as_bytes())?;
        }
        write(format!("{stem}-{}.csv", f.name), f.csv.as_bytes())?;
    }
    write(format!("{stem}.html"), report.to_html(&stem)?.as_bytes())
}

/// `--results FILE`: the published-results page.
pub(crate) fn write_results(
    report: &rotor_harness::bench::BenchReport,
    path: Option<&Path>,
) -> Result<()> {
    if let Some(path) = path {
        // The command that wrote it, as given (`just bench` runs the whole suite's).
        let args: Vec<String> = std::env::args().skip(1).collect();
        let command = format!("rotor {}", args.join(" "));
        rotor_harness::compare::report::write_output(
            path,
            report.to_results_md(&command)?.as_bytes(),
        )
        .with_context(|| format!("--results {}: cannot write", path.display()))?;
    }
    Ok(())
}
