//! `rotor steady`: the steady state as one JSON object.

use anyhow::{Context, Result, anyhow, bail};

use crate::common::{Common, load_model, request, warn_inexact};
use crate::out;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// How: `simulate` (the default: the event-driven solver refines the cycle a run
    /// reaches on its own flow with saltation matrices; switch and moreau run until the
    /// metrics settle, which answers equilibria too), or `shoot` (Newton on the
    /// solver's own return map from a 300 s run's last section crossing: any solver, the
    /// orbit stable or not, in a few periods where settling next to a Hopf point takes
    /// thousands of seconds; the JSON adds "stable" and "multipliers"). The default is
    /// the one that is right from every start: shoot is faster next to a special point
    /// but does not check that the start reaches the orbit (docs/methods.md, 4b).
    #[arg(long, value_name = "shoot|simulate")]
    pub method: Option<String>,
}

pub fn run(a: &Args) -> Result<()> {
    steady(&a.common, a.method.as_deref())
}

pub(crate) fn steady(common: &Common, method: Option<&str>) -> Result<()> {
    let shoot = match method {
        None | Some("simulate") => false,
        Some("shoot") => true,
        Some(other) => bail!("--method {other:?}: expected shoot or simulate"),
    };
    let (kind, scene, opts) = request(common)?
        .steady()
        .map_err(|e| anyhow!(e.as_flag()))?;
    let model = load_model(common.params.as_deref())?;
    let answer = if shoot {
        rotor_steady::shot(kind, &model, &scene)
    } else {
        rotor_steady::steady(kind, &model, &scene, &opts)
    }
    .with_context(|| format!("solver {}", kind.name()))?;
    warn_inexact(&answer.stats);
    out::line(format_args!("{}", steady_json(&answer)))?;
    Ok(())
}

pub(crate) fn steady_json(st: &rotor_steady::SteadyAnswer) -> String {
    serde_json::to_string(st).expect("plain floats and strings serialize")
}
