//! `[tolerance.<pair>]` tables: the agreement tolerances of one solver pair, one key per
//! quantity, and their checks against the scenario's `[compare]` section.

use crate::Num;
use serde::Deserialize;

use crate::scenario::compare::CompareSpec;
use crate::scenario::error::{Bad, ScenarioError};

/// Agreement tolerances for one solver pair: one key per quantity, each with its origin in a
/// comment in the file. The steady-state ones are relative (with `steady_abs` as the floor for
/// values near 0), except `stick_time`, which is in seconds: a stick phase is located to an
/// absolute time, whatever its length.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PairTolerance {
    /// Max |Δω| (both discs) over the transient window [rad/s].
    pub transient_max: Option<f64>,
    /// RMS of Δω (both discs) over the transient window [rad/s].
    pub transient_rms: Option<f64>,
    /// Max difference of matched lower-disc stick event times in the window \[s\].
    pub event_time: Option<f64>,
    /// Period of a limit cycle, relative.
    pub period_rel: Option<f64>,
    /// Max of ω_l over a cycle, relative.
    pub omega_l_max_rel: Option<f64>,
    /// Min of ω_l over a cycle [rad/s], absolute: it is 0 (or the switch model's stuck
    /// velocity, ≤ its band η) on every cycle on which the lower disc sticks, where a relative
    /// difference is 0 or 1 and says nothing.
    pub omega_l_min: Option<f64>,
    /// Max of ω_u over a cycle, relative.
    pub omega_u_max_rel: Option<f64>,
    /// Min of ω_u over a cycle, relative.
    pub omega_u_min_rel: Option<f64>,
    /// Time per period with ω_l = 0 \[s\].
    pub stick_time: Option<f64>,
    /// The equilibrium's ω_u, relative.
    pub equilibrium_omega_u_rel: Option<f64>,
    /// The equilibrium's ω_l, relative.
    pub equilibrium_omega_l_rel: Option<f64>,
    /// The equilibrium's α, relative.
    pub equilibrium_alpha_rel: Option<f64>,
    /// Absolute floor of the relative steady-state tolerances [s or rad/s or rad]: a value
    /// that is ~0 is compared absolutely.
    pub steady_abs: Option<f64>,
    /// Max phase-aligned |Δα| over every sample of `[0, t_end]` \[rad\]
    /// (`rotor_harness::compare::whole`).
    pub whole_alpha: Option<f64>,
    /// Max phase-aligned |Δω_u| over every sample of `[0, t_end]` [rad/s].
    pub whole_omega_u: Option<f64>,
    /// Max phase-aligned |Δω_l| over every sample of `[0, t_end]` [rad/s].
    pub whole_omega_l: Option<f64>,
    /// Max |Δt| of the matched mode switches and ω_l maxima over `[0, t_end]` \[s\].
    pub whole_event_time: Option<f64>,
}

/// Keys of `[tolerance.<pair>]` tables that one quantity's key each replaced: a file that
/// still states one is refused with the keys to use instead (never read as one of them).
pub const RETIRED_KEYS: [(&str, &str); 4] = [
    ("omega_l_rel", "omega_l_max_rel and omega_l_min"),
    ("omega_l_min_rel", "omega_l_min (absolute, rad/s)"),
    ("omega_u_rel", "omega_u_max_rel and omega_u_min_rel"),
    (
        "equilibrium_rel",
        "equilibrium_omega_u_rel, equilibrium_omega_l_rel and equilibrium_alpha_rel",
    ),
];

/// A `[tolerance.<pair>]` table as written: [`PairTolerance`] and the [`RETIRED_KEYS`], so
/// that a retired key gets its own message rather than serde's "unknown field".
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawPairTolerance {
    transient_max: Option<f64>,
    transient_rms: Option<f64>,
    event_time: Option<f64>,
    period_rel: Option<f64>,
    omega_l_max_rel: Option<f64>,
    omega_l_min: Option<f64>,
    omega_u_max_rel: Option<f64>,
    omega_u_min_rel: Option<f64>,
    stick_time: Option<f64>,
    equilibrium_omega_u_rel: Option<f64>,
    equilibrium_omega_l_rel: Option<f64>,
    equilibrium_alpha_rel: Option<f64>,
    steady_abs: Option<f64>,
    whole_alpha: Option<f64>,
    whole_omega_u: Option<f64>,
    whole_omega_l: Option<f64>,
    whole_event_time: Option<f64>,
    omega_l_rel: Option<f64>,
    omega_l_min_rel: Option<f64>,
    omega_u_rel: Option<f64>,
    equilibrium_rel: Option<f64>,
}

impl RawPairTolerance {
    /// The tolerances, or the first retired key stated with its value.
    fn current(&self) -> Result<PairTolerance, (&'static str, f64)> {
        let retired = [
            self.omega_l_rel,
            self.omega_l_min_rel,
            self.omega_u_rel,
            self.equilibrium_rel,
        ];
        if let Some((i, v)) = retired
            .iter()
            .enumerate()
            .find_map(|(i, v)| v.map(|v| (i, v)))
        {
            return Err((RETIRED_KEYS[i].0, v));
        }
        Ok(PairTolerance {
            transient_max: self.transient_max,
            transient_rms: self.transient_rms,
            event_time: self.event_time,
            period_rel: self.period_rel,
            omega_l_max_rel: self.omega_l_max_rel,
            omega_l_min: self.omega_l_min,
            omega_u_max_rel: self.omega_u_max_rel,
            omega_u_min_rel: self.omega_u_min_rel,
            stick_time: self.stick_time,
            equilibrium_omega_u_rel: self.equilibrium_omega_u_rel,
            equilibrium_omega_l_rel: self.equilibrium_omega_l_rel,
            equilibrium_alpha_rel: self.equilibrium_alpha_rel,
            steady_abs: self.steady_abs,
            whole_alpha: self.whole_alpha,
            whole_omega_u: self.whole_omega_u,
            whole_omega_l: self.whole_omega_l,
            whole_event_time: self.whole_event_time,
        })
    }
}

/// Every key of a [`PairTolerance`], in file order.
pub const TOLERANCE_KEYS: [&str; 17] = [
    "transient_max",
    "transient_rms",
    "event_time",
    "period_rel",
    "omega_l_max_rel",
    "omega_l_min",
    "omega_u_max_rel",
    "omega_u_min_rel",
    "stick_time",
    "equilibrium_omega_u_rel",
    "equilibrium_omega_l_rel",
    "equilibrium_alpha_rel",
    "steady_abs",
    "whole_alpha",
    "whole_omega_u",
    "whole_omega_l",
    "whole_event_time",
];

/// The keys gating the whole run (every sample and every matched event over `[0, t_end]`,
/// phase-aligned): a table that states one must state all of them. A table may state these
/// alone: the pairs of two non-reference solvers (`switch-moreau`) are compared over the
/// whole run only.
pub const WHOLE_KEYS: [&str; 4] = [
    "whole_alpha",
    "whole_omega_u",
    "whole_omega_l",
    "whole_event_time",
];

/// The keys gating a limit cycle: a pair that states one must state all of them.
pub const CYCLE_KEYS: [&str; 6] = [
    "period_rel",
    "omega_l_max_rel",
    "omega_l_min",
    "omega_u_max_rel",
    "omega_u_min_rel",
    "stick_time",
];

/// The keys gating an equilibrium: a pair that states one must state all of them.
pub const EQUILIBRIUM_KEYS: [&str; 3] = [
    "equilibrium_omega_u_rel",
    "equilibrium_omega_l_rel",
    "equilibrium_alpha_rel",
];

/// The steady-state quantities a [`PairTolerance`] gates, one key per metric of
/// [`crate::seam::RigSteady::values`]: its key in the file, the metric, and whether the
/// tolerance is relative.
pub const STEADY_QUANTITIES: [SteadyQuantity; 9] = [
    SteadyQuantity::relative("period_rel", "period"),
    SteadyQuantity::relative("omega_l_max_rel", "omega_l_max"),
    SteadyQuantity {
        key: "omega_l_min",
        metric: "omega_l_min",
        relative: false,
    },
    SteadyQuantity::relative("omega_u_max_rel", "omega_u_max"),
    SteadyQuantity::relative("omega_u_min_rel", "omega_u_min"),
    SteadyQuantity {
        key: "stick_time",
        metric: "stick_time",
        relative: false,
    },
    SteadyQuantity::relative("equilibrium_omega_u_rel", "omega_u"),
    SteadyQuantity::relative("equilibrium_omega_l_rel", "omega_l"),
    SteadyQuantity::relative("equilibrium_alpha_rel", "alpha"),
];

/// One steady-state tolerance: its key in the file and the metric it gates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SteadyQuantity {
    /// The key in a `[tolerance.<pair>]` table (`period_rel`, `stick_time`, ...).
    pub key: &'static str,
    /// The [`crate::seam::RigSteady`] metric it gates (`period`, `stick_time`, ...).
    pub metric: &'static str,
    /// Whether the tolerance is relative to the metric (with `steady_abs` as its floor);
    /// otherwise it is absolute, in the metric's unit.
    pub relative: bool,
}

impl SteadyQuantity {
    const fn relative(key: &'static str, metric: &'static str) -> SteadyQuantity {
        SteadyQuantity {
            key,
            metric,
            relative: true,
        }
    }
}

impl PairTolerance {
    /// The tolerance stated under `key` (one of [`TOLERANCE_KEYS`]).
    pub fn get(&self, key: &str) -> Option<f64> {
        match key {
            "transient_max" => self.transient_max,
            "transient_rms" => self.transient_rms,
            "event_time" => self.event_time,
            "period_rel" => self.period_rel,
            "omega_l_max_rel" => self.omega_l_max_rel,
            "omega_l_min" => self.omega_l_min,
            "omega_u_max_rel" => self.omega_u_max_rel,
            "omega_u_min_rel" => self.omega_u_min_rel,
            "stick_time" => self.stick_time,
            "equilibrium_omega_u_rel" => self.equilibrium_omega_u_rel,
            "equilibrium_omega_l_rel" => self.equilibrium_omega_l_rel,
            "equilibrium_alpha_rel" => self.equilibrium_alpha_rel,
            "steady_abs" => self.steady_abs,
            "whole_alpha" => self.whole_alpha,
            "whole_omega_u" => self.whole_omega_u,
            "whole_omega_l" => self.whole_omega_l,
            "whole_event_time" => self.whole_event_time,
            _ => None,
        }
    }

    /// The tolerance under `key`, to set or clear (`None` for a key that is not one of
    /// [`TOLERANCE_KEYS`]).
    pub fn slot(&mut self, key: &str) -> Option<&mut Option<f64>> {
        Some(match key {
            "transient_max" => &mut self.transient_max,
            "transient_rms" => &mut self.transient_rms,
            "event_time" => &mut self.event_time,
            "period_rel" => &mut self.period_rel,
            "omega_l_max_rel" => &mut self.omega_l_max_rel,
            "omega_l_min" => &mut self.omega_l_min,
            "omega_u_max_rel" => &mut self.omega_u_max_rel,
            "omega_u_min_rel" => &mut self.omega_u_min_rel,
            "stick_time" => &mut self.stick_time,
            "equilibrium_omega_u_rel" => &mut self.equilibrium_omega_u_rel,
            "equilibrium_omega_l_rel" => &mut self.equilibrium_omega_l_rel,
            "equilibrium_alpha_rel" => &mut self.equilibrium_alpha_rel,
            "steady_abs" => &mut self.steady_abs,
            "whole_alpha" => &mut self.whole_alpha,
            "whole_omega_u" => &mut self.whole_omega_u,
            "whole_omega_l" => &mut self.whole_omega_l,
            "whole_event_time" => &mut self.whole_event_time,
            _ => return None,
        })
    }

    /// Every stated tolerance with its key, in file order.
    pub fn stated(&self) -> Vec<(&'static str, f64)> {
        TOLERANCE_KEYS
            .into_iter()
            .filter_map(|k| self.get(k).map(|v| (k, v)))
            .collect()
    }

    /// The steady-state quantity gating a metric of [`crate::seam::RigSteady::values`], and its
    /// tolerance if stated.
    pub fn for_metric(&self, metric: &str) -> Option<(SteadyQuantity, Option<f64>)> {
        STEADY_QUANTITIES
            .into_iter()
            .find(|q| q.metric == metric)
            .map(|q| (q, self.get(q.key)))
    }

    /// Whether any steady-state tolerance is stated.
    pub fn gates_steady(&self) -> bool {
        STEADY_QUANTITIES.iter().any(|q| self.get(q.key).is_some())
    }

    /// Whether every whole-run tolerance ([`WHOLE_KEYS`]) is stated.
    pub fn gates_whole(&self) -> bool {
        WHOLE_KEYS.iter().all(|k| self.get(k).is_some())
    }

    /// Whether the table states the whole-run tolerances and nothing else: the table of a pair
    /// of two non-reference solvers.
    pub fn whole_only(&self) -> bool {
        self.stated().iter().all(|(k, _)| WHOLE_KEYS.contains(k))
    }
}

/// One `[tolerance.<pair>]` table: the pair's name, no retired key, every value
/// non-negative and finite, every tolerance with something to measure and every compared
/// window and steady-state kind fully gated.
pub(crate) fn check_pair(
    pair: &str,
    raw: &RawPairTolerance,
    compare: &CompareSpec,
    bad: Bad,
) -> Result<PairTolerance, ScenarioError> {
    check_pair_name(pair, bad)?;
    // One key per quantity: a retired shared key is named with the keys that replaced it,
    // never read as one of them.
    let tol = raw.current().map_err(|(key, v)| {
        let instead = RETIRED_KEYS.iter().find(|r| r.0 == key).map_or("", |r| r.1);
        bad.at(
            &format!("tolerance.{pair}.{key}"),
            Num(v).to_string(),
            &format!(
                "is retired: it gated several quantities, and each has its own key now: {instead}"
            ),
        )
    })?;
    // Non-negative: 0 is a gate of exact agreement (both discs stuck from rest, where every
    // solver must return x = 0 exactly).
    for (name, v) in tol.stated() {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(bad.at(
                &format!("tolerance.{pair}.{name}"),
                Num(v).to_string(),
                "must be non-negative and finite",
            ));
        }
    }
    check_pair_coverage(pair, &tol, compare, bad)?;
    Ok(tol)
}

/// A solver pair is named `<reference>-<solver>`. Which solvers exist is the runner's
/// knowledge ([`Scenario::check_pairs`](crate::scenario::Scenario::check_pairs)); the form is checked here.
fn check_pair_name(pair: &str, bad: Bad) -> Result<(), ScenarioError> {
    let part = |p: &str| {
        !p.is_empty()
            && p.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
    };
    if !pair
        .split_once('-')
        .is_some_and(|(a, b)| part(a) && part(b))
    {
        return Err(bad.at(
            "tolerance",
            format!("{pair:?}"),
            "a solver pair is named <reference>-<solver>, e.g. \"event-switch\"",
        ));
    }
    Ok(())
}

/// Every tolerance must have something to measure, and every compared window a gate:
/// otherwise a pair would pass having measured nothing.
fn check_pair_coverage(
    pair: &str,
    tol: &PairTolerance,
    compare: &CompareSpec,
    bad: Bad,
) -> Result<(), ScenarioError> {
    let transient = compare.transient.is_some();
    let steady = compare.steady_from.is_some();
    for (name, v) in tol.stated() {
        let (needed, why) = match name {
            "transient_max" | "transient_rms" | "event_time" => {
                (transient, "needs compare.transient (the window it gates)")
            }
            k if WHOLE_KEYS.contains(&k) => (true, ""),
            "steady_abs" => (
                steady && tol.gates_steady(),
                "is the floor of the steady-state tolerances and needs one of them (and compare.steady_from)",
            ),
            _ => (steady, "needs compare.steady_from (the metrics it gates)"),
        };
        if !needed {
            return Err(bad.at(&format!("tolerance.{pair}.{name}"), Num(v).to_string(), why));
        }
    }
    // A table of the whole run alone (a pair of two non-reference solvers) gates no window and
    // no steady state; which pairs may have one, the runner knows
    // ([`Scenario::check_pairs`](crate::scenario::Scenario::check_pairs)).
    let whole_only = tol.whole_only() && !tol.stated().is_empty();
    if transient && !whole_only && tol.transient_max.is_none() {
        return Err(bad.at(
            &format!("tolerance.{pair}.transient_max"),
            "(missing)".into(),
            "is required when compare.transient is set: the window would be ungated (only the \
             table of two non-reference solvers states the whole-run keys alone)",
        ));
    }
    // A steady state is gated either as an equilibrium or as a cycle, with every metric of
    // its kind: a tolerance that is missing would leave that metric ungated (the gate fails
    // a steady state whose kind has no tolerances).
    if steady && !whole_only && !tol.gates_steady() {
        return Err(bad.at(
            &format!("tolerance.{pair}.{}", EQUILIBRIUM_KEYS[0]),
            "(missing)".into(),
            &format!(
                "is required when compare.steady_from is set, with {}, unless the cycle tolerances ({}) are given: the metrics would be ungated",
                EQUILIBRIUM_KEYS[1..].join(" and "),
                CYCLE_KEYS.join(", ")
            ),
        ));
    }
    for (group, what) in [
        (&CYCLE_KEYS[..], "cycle"),
        (&EQUILIBRIUM_KEYS[..], "equilibrium"),
        (&WHOLE_KEYS[..], "whole-run"),
    ] {
        if group.iter().any(|k| tol.get(k).is_some())
            && let Some(missing) = group.iter().find(|k| tol.get(k).is_none())
        {
            return Err(bad.at(
                &format!("tolerance.{pair}.{missing}"),
                "(missing)".into(),
                &format!(
                    "is required with the other {what} tolerances: that metric would be ungated"
                ),
            ));
        }
    }
    Ok(())
}
