//! Redraws the benchmark's figures from a report's JSON, without running anything: the
//! published figures follow a change of the figure code at no cost of a 6-minute suite run.
//!
//! ```sh
//! cargo run --release -p rotor-harness --example redraw -- reports/bench/bench.json reports/bench/bench.svg
//! ```
//!
//! writes `bench.svg` (the performance profile), `bench-<scene>.svg` and `bench-<name>.csv`
//! for every figure, and `bench.html`, beside the SVG path given.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [json, svg] = args.as_slice() else {
        return Err("usage: redraw REPORT.json OUT.svg".into());
    };
    let report: rotor_harness::bench::BenchReport =
        serde_json::from_str(&std::fs::read_to_string(json)?)?;
    let svg = Path::new(svg);
    let stem = svg
        .file_stem()
        .ok_or("OUT.svg needs a file name")?
        .to_string_lossy();
    let dir = svg.parent().unwrap_or(Path::new(""));
    std::fs::write(svg, report.to_svg()?)?;
    for f in report.figures()? {
        if f.name != "profile" {
            std::fs::write(dir.join(format!("{stem}-{}.svg", f.name)), &f.svg)?;
        }
        std::fs::write(dir.join(format!("{stem}-{}.csv", f.name)), &f.csv)?;
    }
    std::fs::write(dir.join(format!("{stem}.html")), report.to_html(&stem)?)?;
    Ok(())
}
