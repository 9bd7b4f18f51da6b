//! `rotor merge`: sweep shards joined into what one unsharded run writes.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The shard files.
    pub shards: Vec<PathBuf>,
    /// Output CSV (`-`: standard output).
    #[arg(long)]
    pub csv: PathBuf,
}

pub fn run(a: &Args) -> Result<()> {
    merge(&a.shards, &a.csv)
}

pub(crate) fn merge(shards: &[PathBuf], csv: &Path) -> Result<()> {
    if shards.is_empty() {
        crate::common::refuse!("merge: no shard files given");
    }
    let merged = rotor_harness::jobs::sweep::merge(shards)?;
    rotor_harness::compare::report::write_output_with(csv, |w| merged.write_to(w))
        .with_context(|| format!("{}: cannot write", csv.display()))?;
    Ok(())
}
