//! `rotor job`: the job file `rotor bench` hands an external client.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::common::{check, scene_path};
use crate::out;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario file, or a name of the suite (`t1-u1.5-rest`, or a chain scene such as
    /// `chain3-u1.5-rest`).
    pub scenario: PathBuf,
    /// The tolerance of a client with a tolerance (the job's `h` is null).
    #[arg(
        long,
        value_name = "T",
        allow_hyphen_values = true,
        conflicts_with = "h"
    )]
    pub tol: Option<f64>,
    /// The step of a fixed-step client, in s (the job's `tol` is null).
    #[arg(long, value_name = "H", allow_hyphen_values = true)]
    pub h: Option<f64>,
    /// The path the client writes its trace to.
    #[arg(long, value_name = "P", default_value = "trace.csv")]
    pub trace: PathBuf,
    /// The path the client writes its events to.
    #[arg(long, value_name = "P", default_value = "events.csv")]
    pub events: PathBuf,
}

pub fn run(a: &Args) -> Result<()> {
    job(&a.scenario, a.tol, a.h, &a.trace, &a.events)
}

/// `rotor job`: the job file of a scenario, printed.
pub(crate) fn job(
    scenario: &Path,
    tol: Option<f64>,
    h: Option<f64>,
    trace: &Path,
    events: &Path,
) -> Result<()> {
    let (fixed_step, setting) = match (tol, h) {
        (Some(t), None) => {
            check("tol", t, t > 0.0, "must be a positive number")?;
            (false, t)
        }
        (None, Some(h)) => {
            check("h", h, h > 0.0, "must be a positive number of seconds")?;
            (true, h)
        }
        _ => crate::common::refuse!(
            "rotor job {}: give --tol T (a client with a tolerance) or --h H (a fixed-step \
             client), one of them",
            scenario.display()
        ),
    };
    for (flag, p) in [("--trace", trace), ("--events", events)] {
        if p.as_os_str().is_empty() {
            crate::common::refuse!("{flag} \"\": an empty path");
        }
    }
    let (path, is_chain) = scene_path("scenario", scenario)?;
    let job = if is_chain {
        let sc = rotor_model::scenario::ChainScenario::from_file(&path)?;
        rotor_harness::protocol::Job::for_chain(
            &sc,
            fixed_step,
            setting,
            trace.to_owned(),
            events.to_owned(),
        )
    } else {
        rotor_harness::bench::job_for_scenario(
            &path,
            fixed_step,
            setting,
            trace.to_owned(),
            events.to_owned(),
        )?
    };
    out::print(&(job.to_json() + "\n"))?;
    Ok(())
}
