//! `rotor bench --merge`: the reports of `--shard` runs joined into one.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use super::bench_out::{write_bench, write_results};

/// `rotor bench --merge`: the shards' reports joined into one.
pub(crate) fn bench_merge(
    shards: &[PathBuf],
    outputs: [Option<&Path>; 3],
    results: Option<&Path>,
) -> Result<()> {
    let reports = shards
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("--merge {}: cannot read", p.display()))?;
            let r: rotor_harness::bench::BenchReport =
                serde_json::from_str(&text).with_context(|| {
                    format!(
                        "--merge {}: not a report of rotor bench --json",
                        p.display()
                    )
                })?;
            Ok((p.display().to_string(), r))
        })
        .collect::<Result<Vec<_>>>()?;
    let report = rotor_harness::bench::merge(&reports)?;
    write_bench(&report, outputs)?;
    write_results(&report, results)
}
