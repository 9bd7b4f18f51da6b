//! `rotor steady`: the steady state as one JSON object.

use anyhow::{Context, Result, bail};

use crate::common::{Common, load_model, request, warn_inexact};
use crate::out;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// How. Without it, the fastest that is right from every start: the event-driven
    /// solver refines the cycle a run reaches on its own flow (saltation multipliers); switch
    /// and moreau shoot on their own return map from a 100 s run and accept the orbit only
    /// when a run from the start of at most 600 s is seen to go to it (or to a stable
    /// equilibrium), and fall back to `simulate` when that check refuses (a slow transient,
    /// an unstable or neutral orbit); "method" says which answered ("shoot" with "stable"
    /// and "multipliers", or "simulated"). `simulate`: every solver, the event-driven one
    /// too, runs until its metrics settle (right from every start, slow next to a special
    /// point). `shoot`: Newton on the solver's own return map from a 300 s run's last section
    /// crossing, unchecked: the orbit stable or not (docs/methods.md, 4b). Every answer is
    /// checked against the model's equations before it is printed (an equilibrium's field
    /// vanishes, a cycle returns to its start after one period); one that fails is refused.
    #[arg(long, value_name = "shoot|simulate")]
    pub method: Option<String>,
}

pub fn run(a: &Args) -> Result<()> {
    steady(&a.common, a.method.as_deref())
}

pub(crate) fn steady(common: &Common, method: Option<&str>) -> Result<()> {
    enum How {
        Checked,
        Shoot,
        Simulate,
    }
    let how = match method {
        None => How::Checked,
        Some("simulate") => How::Simulate,
        Some("shoot") => How::Shoot,
        Some(other) => bail!("--method {other:?}: expected shoot or simulate"),
    };
    let (kind, scene, opts) = request(common)?.steady().map_err(crate::common::flagged)?;
    let model = load_model(common.params.as_deref())?;
    let answer = match how {
        How::Shoot => rotor_steady::shot(kind, &model, &scene),
        How::Simulate => rotor_steady::simulated(kind, &model, &scene, &opts),
        How::Checked => rotor_steady::checked::checked_or_simulated(kind, &model, &scene, &opts),
    }
    .with_context(|| format!("solver {}", kind.name()))?;
    warn_inexact(&answer.stats);
    out::line(format_args!("{}", steady_json(&answer)))?;
    Ok(())
}

pub(crate) fn steady_json(st: &rotor_steady::SteadyAnswer) -> String {
    serde_json::to_string(st).expect("plain floats and strings serialize")
}
