//! `rotor scenarios`: the versioned suite, scene by scene.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rotor_model::Disc;
use rotor_model::scenario::Scenario;
use serde::Serialize;

/// A scene's tier: `table1` when only the lower disc has static friction (what a solver that
/// treats one switching surface handles), `full` when the upper disc sticks too.
pub fn tier(sc: &Scenario) -> &'static str {
    if sc.model.friction(Disc::UPPER).is_set_valued() {
        "full"
    } else {
        "table1"
    }
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Also write the list as JSON (`-`: standard output).
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(a: &Args) -> Result<()> {
    scenarios(a.json.as_deref())
}

#[derive(Serialize)]
struct Row<'a> {
    name: &'a str,
    tier: &'static str,
    /// The version of the scene's tier (the rig's suite, or the chain tier's own).
    version: &'static str,
    /// Number of discs (2 for the rig).
    discs: usize,
    description: &'a str,
    /// The constant input \[V\], or null for an input that changes in time (as in the job
    /// file).
    u: Option<f64>,
    /// The rows `[t, u]` of an input that changes in time.
    #[serde(skip_serializing_if = "Option::is_none")]
    input: Option<Vec<[f64; 2]>>,
    t_end: f64,
}

#[derive(Serialize)]
struct Listing<'a> {
    benchmark: &'static str,
    checksum: &'static str,
    /// The chain tier's version and checksum.
    chain_benchmark: &'static str,
    chain_checksum: &'static str,
    source: &'static str,
    dir: String,
    scenarios: Vec<Row<'a>>,
}

/// Lists every scenario of the suite (name, tier, version, what it tests): the rig's scenes,
/// then the chain tier's (`tier` = `chain`, with their own version), with where the files were
/// found; `--json` writes the same as JSON.
pub fn scenarios(json: Option<&Path>) -> Result<()> {
    let (dir, source) = match std::env::var_os("ROTORBENCH_SUITE") {
        None if Path::new("fixtures/scenarios").is_dir() => {
            (Path::new("fixtures").to_owned(), "./fixtures")
        }
        _ => {
            let l = rotor_suite::locate()?;
            (l.dir, l.source.as_str())
        }
    };
    let files = Scenario::list_dir(&dir.join("scenarios"))
        .with_context(|| format!("{}: cannot list the scenarios", dir.display()))?;
    let scenarios = files
        .iter()
        .map(|f| rotor_analysis::solvers::load_scenario(f))
        .collect::<Result<Vec<_>, _>>()?;
    let chain_files = Scenario::list_dir(&dir.join("chain/scenarios")).unwrap_or_default();
    let chains = chain_files
        .iter()
        .map(|f| rotor_model::scenario::ChainScenario::from_file(f))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows: Vec<Row> = scenarios
        .iter()
        .map(|sc| Row {
            name: &sc.name,
            tier: tier(sc),
            version: rotor_suite::VERSION,
            discs: 2,
            description: &sc.description,
            u: sc.input.is_none().then_some(sc.u),
            input: sc
                .input
                .as_ref()
                .map(|i| i.rows().iter().map(|&(t, u)| [t, u]).collect()),
            t_end: sc.t_end,
        })
        .collect();
    rows.extend(chains.iter().map(|sc| {
        Row {
            name: &sc.name,
            tier: "chain",
            version: rotor_suite::CHAIN_VERSION,
            discs: sc.discs(),
            description: &sc.description,
            u: sc.input.is_none().then_some(sc.u),
            input: sc
                .input
                .as_ref()
                .map(|i| i.rows().iter().map(|&(t, u)| [t, u]).collect()),
            t_end: sc.t_end,
        }
    }));
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(4).max(18);
    let mut text = format!(
        "{} ({} scenarios; {source}: {})\nchain tier {} ({} scenes)\n{:<width$} {:<7} {:>5} {:>6}  {}\n",
        rotor_suite::VERSION,
        scenarios.len(),
        dir.display(),
        rotor_suite::CHAIN_VERSION,
        chains.len(),
        "name",
        "tier",
        "u [V]",
        "t_end",
        "what it tests"
    );
    for r in &rows {
        text.push_str(&format!(
            "{:<width$} {:<7} {:>5} {:>6}  {}\n",
            r.name,
            r.tier,
            // an input that changes in time: its description says how
            r.u.map_or("u(t)".to_owned(), |u| u.to_string()),
            r.t_end,
            r.description
        ));
    }
    crate::common::say(&text, [json])?;
    if let Some(path) = json {
        let listing = Listing {
            benchmark: rotor_suite::VERSION,
            checksum: rotor_suite::CHECKSUM,
            chain_benchmark: rotor_suite::CHAIN_VERSION,
            chain_checksum: rotor_suite::CHAIN_CHECKSUM,
            source,
            dir: dir.display().to_string(),
            scenarios: rows,
        };
        let mut s = serde_json::to_string_pretty(&listing)?;
        s.push('\n');
        rotor_harness::compare::report::write_output(path, s.as_bytes())
            .with_context(|| format!("--json {}: cannot write", path.display()))?;
    }
    Ok(())
}
