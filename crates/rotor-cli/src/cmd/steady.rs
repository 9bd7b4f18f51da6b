//! `rotor steady`: the steady state as one JSON object.

use anyhow::{Context, Result};

use crate::common::{Common, request, start, unusable, warn_inexact};
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
    /// A parameter file in chain form is answered from the solver's own run, as the chain's
    /// lists: an equilibrium, a cycle of any number of returns to its section (then shot on
    /// the solver's k-th return map for its multipliers, unless `simulate`; with `shoot` the
    /// shooting must succeed), or "aperiodic" with the evidence.
    #[arg(long, value_name = "shoot|simulate")]
    pub method: Option<String>,
    /// Not taken (hidden from the help): `steady` runs as long as its answer needs. Given,
    /// it is refused with that reason instead of clap's bare "unexpected argument".
    #[arg(long, hide = true, allow_hyphen_values = true)]
    pub t_end: Option<String>,
    /// Not taken (hidden), as --t-end: `steady` prints one state, not a trace.
    #[arg(long, hide = true, allow_hyphen_values = true)]
    pub dt: Option<String>,
}

pub fn run(a: &Args) -> Result<()> {
    if let Some(v) = &a.t_end {
        return Err(unusable(format_args!(
            "--t-end {v}: steady takes no horizon; it runs until its answer settles (or \
             shoots), as long as that needs. `rotor simulate --t-end` runs a fixed horizon"
        )));
    }
    if let Some(v) = &a.dt {
        return Err(unusable(format_args!(
            "--dt {v}: steady prints one state, not a trace on a grid; `rotor simulate --dt` \
             writes one"
        )));
    }
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
        Some(other) => {
            return Err(unusable(format_args!(
                "--method {other:?}: expected shoot or simulate"
            )));
        }
    };
    if common.scenario.is_none()
        && let Some((path, chain)) = crate::common::chain_file(common)?
    {
        return steady_chain(common, method, &path, &chain);
    }
    let start = start(common)?;
    let (kind, scene, opts) = request(common, &start)?
        .steady()
        .map_err(crate::common::flagged)?;
    let model = start.model;
    let answer = match how {
        How::Shoot => rotor_analysis::steady::shot(kind, &model, &scene),
        How::Simulate => rotor_analysis::steady::simulated(kind, &model, &scene, &opts),
        How::Checked => {
            rotor_analysis::steady::checked::checked_or_simulated(kind, &model, &scene, &opts)
        }
    }
    .with_context(|| format!("solver {}", kind.name()))?;
    warn_inexact(&answer.stats);
    out::line(format_args!("{}", steady_json(&answer)))?;
    Ok(())
}

pub(crate) fn steady_json(st: &rotor_analysis::steady::SteadyAnswer) -> String {
    serde_json::to_string(st).expect("plain floats and strings serialize")
}

/// `rotor steady` of a parameter file in chain form: the steady state read off the solver's
/// own run ([`rotor_analysis::steady::chain`]), as the chain's lists (`omega_max: [N]`, ...):
/// an equilibrium, a cycle of any number of section crossings, or "aperiodic" with its
/// evidence. A cycle is then shot on the solver's own k-th return map for its multipliers
/// (without `--method`: if that fails, the simulated cycle stands and says why;
/// `--method shoot`: it must succeed; `--method simulate`: not shot).
fn steady_chain(
    common: &Common,
    method: Option<&str>,
    path: &std::path::Path,
    chain: &rotor_model::ChainParams,
) -> Result<()> {
    let model = rotor_model::ChainModel::new(chain);
    let (kind, request) = crate::common::chain_request(common, path, &model)?;
    let (_, scene, _) = request.steady().map_err(crate::common::flagged)?;
    let opts = rotor_analysis::steady::chain::ChainSteadyOptions {
        shoot: method != Some("simulate"),
        ..Default::default()
    };
    let answer = rotor_analysis::steady::chain::chain_steady(kind, &model, &scene, &opts)
        .with_context(|| format!("solver {}", kind.name()))?;
    // Asked to shoot, a cycle that could not be shot is no answer.
    if method == Some("shoot")
        && let Some(why) = &answer.not_shot
    {
        return Err(anyhow::anyhow!(
            "solver {}: the cycle the run found (period {}) was not shot: {why}",
            kind.name(),
            match &answer.state {
                rotor_analysis::steady::chain::ChainSteady::LimitCycle { period, .. } =>
                    format!("{period:.6} s"),
                _ => "?".to_owned(),
            }
        ));
    }
    out::line(format_args!(
        "{}",
        serde_json::to_string(&answer).expect("plain floats and strings serialize")
    ))?;
    Ok(())
}
