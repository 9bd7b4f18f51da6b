//! Scenario files: one scene, run by every solver (docs/design.md, "Fixtures").
//!
//! ```toml
//! name = "t1-u1.5-rest"
//! params = "../params/table1.toml"   # relative to this file
//! u = 1.5                            # V
//! x0 = [0.0, 0.0, 0.0]               # or: x0_from_equilibrium = [0.0, 0.0, 1e-3]
//! t_end = 200.0                      # s
//! [compare]
//! transient = [0.0, 20.0]            # s, compared sample by sample
//! steady_from = 100.0                # s, steady-state metrics over [steady_from, t_end]
//! [tolerance.event-switch]           # per solver pair and quantity, each with its origin
//! transient_max = 3e-8               # rad/s; also transient_rms, event_time (s)
//! period_rel = 2e-10                 # relative; also omega_l_max_rel, omega_u_max_rel,
//!                                    # omega_u_min_rel; omega_l_min is in rad/s
//! stick_time = 1e-7                  # s
//! steady_abs = 1e-12                 # absolute floor of the relative ones
//! ```
//!
//! An equilibrium is gated by `equilibrium_omega_u_rel`, `equilibrium_omega_l_rel` and
//! `equilibrium_alpha_rel` instead of the cycle's keys. One key gates one quantity
//! ([`STEADY_QUANTITIES`]); the shared keys of old ([`RETIRED_KEYS`]) are refused.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use thiserror::Error;

use rotor_model::params::{Params, ParamsError, one_line, read_small, shown, text_of};
use rotor_model::scene::{MAX_GRID_ROWS, MIN_TOL, Output, Scene};
use rotor_model::{Model, Num, State};

/// A scenario file could not be read or is not admissible.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{}: cannot read scenario file: {message}", shown(.path))]
    Io { path: PathBuf, message: String },
    /// Not valid TOML, or a key is unknown, missing or of the wrong type.
    #[error("{}: {message}", shown(.path))]
    Parse { path: PathBuf, message: String },
    /// A value is out of range.
    #[error("{}: {field} = {value}: {reason}", shown(.path))]
    Invalid {
        path: PathBuf,
        field: String,
        value: String,
        reason: String,
    },
    /// The parameter file it names is bad. (Not a `#[source]`: the message already holds
    /// it, and a reporter that prints the chain would print it twice.)
    #[error("{}: params: {error}", shown(.path))]
    Params { path: PathBuf, error: ParamsError },
}

/// What the comparison harness compares for this scene.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareSpec {
    /// Window `[t0, t1]` compared sample by sample on a common grid.
    #[serde(default)]
    pub transient: Option<[f64; 2]>,
    /// Grid step of the transient comparison and of the report's CSVs \[s\].
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Steady-state metrics over `[steady_from, t_end]`; `None`: no steady comparison.
    #[serde(default)]
    pub steady_from: Option<f64>,
}

fn default_dt() -> f64 {
    0.01
}

impl Default for CompareSpec {
    fn default() -> Self {
        CompareSpec {
            transient: None,
            dt: default_dt(),
            steady_from: None,
        }
    }
}

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
struct RawPairTolerance {
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
        })
    }
}

/// Every key of a [`PairTolerance`], in file order.
pub const TOLERANCE_KEYS: [&str; 13] = [
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
/// [`rotor_model::SteadyState::values`]: its key in the file, the metric, and whether the
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
    pub key: &'static str,
    pub metric: &'static str,
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

    /// The steady-state quantity gating a metric of [`rotor_model::SteadyState::values`], and its
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
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: String,
    #[serde(default)]
    description: Option<String>,
    params: PathBuf,
    u: f64,
    #[serde(default)]
    x0: Option<[f64; 3]>,
    #[serde(default)]
    x0_from_equilibrium: Option<[f64; 3]>,
    t_end: f64,
    #[serde(default)]
    tol: Option<f64>,
    #[serde(default)]
    h: Option<f64>,
    #[serde(default)]
    compare: CompareSpec,
    #[serde(default)]
    tolerance: BTreeMap<String, RawPairTolerance>,
}

/// A loaded, validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    pub path: PathBuf,
    pub params_path: PathBuf,
    pub model: Model,
    pub u: f64,
    pub x0: State,
    pub t_end: f64,
    /// Tolerance for the adaptive solvers, if the file sets one.
    pub tol: Option<f64>,
    /// Step for the time-stepping solver, if the file sets one.
    pub h: Option<f64>,
    pub compare: CompareSpec,
    /// Keyed by pair name, e.g. `"event-switch"`.
    pub tolerance: BTreeMap<String, PairTolerance>,
}

impl Scenario {
    /// The scene of this scenario keeping `output`: its input, initial state, horizon and
    /// steady-state window, at [`Scene::default`]'s accuracy (callers set `tol` or `h`).
    pub fn scene(&self, output: Output) -> Scene {
        Scene {
            u: self.u,
            x0: self.x0,
            t_end: self.t_end,
            output,
            metrics_from: self.compare.steady_from,
            ..Scene::default()
        }
    }

    /// Reads and validates a scenario file and the parameter file it names.
    pub fn from_file(path: &Path) -> Result<Scenario, ScenarioError> {
        let bytes = read_small(path).map_err(|e| ScenarioError::Io {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        let text = text_of(bytes).map_err(|message| ScenarioError::Parse {
            path: path.to_owned(),
            message,
        })?;
        Scenario::from_toml_str(&text, path)
    }

    /// Parses scenario TOML; `path` resolves the params path and names the file in messages.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Scenario, ScenarioError> {
        if text.trim().is_empty() {
            return Err(ScenarioError::Parse {
                path: path.to_owned(),
                message: "the file is empty".into(),
            });
        }
        let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: path.to_owned(),
            message: one_line(&e.to_string()),
        })?;
        let bad = |field: &str, value: String, reason: &str| ScenarioError::Invalid {
            path: path.to_owned(),
            field: field.to_owned(),
            value,
            reason: reason.to_owned(),
        };
        // The name becomes the report's file names (`<name>.csv`, `<name>.svg`): a path
        // separator or a leading dot would write outside the report or hide the file.
        let name_ok = !raw.name.is_empty()
            && raw.name.len() <= 100
            && !raw.name.starts_with('.')
            && raw
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "._+-".contains(c));
        if !name_ok {
            return Err(bad(
                "name",
                format!("{:?}", raw.name),
                "must be 1 to 100 characters from A-Z a-z 0-9 . _ + - (it names the report's files), not starting with '.'",
            ));
        }
        let params_path = path.parent().unwrap_or(Path::new(".")).join(&raw.params);
        let params = Params::from_file(&params_path).map_err(|error| ScenarioError::Params {
            path: path.to_owned(),
            error,
        })?;
        let model = Model::new(params);
        if !raw.u.is_finite() {
            return Err(bad("u", Num(raw.u).to_string(), "must be finite"));
        }
        if !(raw.t_end > 0.0 && raw.t_end.is_finite()) {
            return Err(bad(
                "t_end",
                Num(raw.t_end).to_string(),
                "must be positive and finite",
            ));
        }
        if let Some(tol) = raw.tol
            && !(tol > 0.0 && tol < 1.0)
        {
            return Err(bad("tol", Num(tol).to_string(), "must lie in (0, 1)"));
        }
        if let Some(tol) = raw.tol
            && tol < MIN_TOL
        {
            return Err(bad(
                "tol",
                Num(tol).to_string(),
                "is below 1.1e-15 (10 unit roundoffs): double precision cannot deliver it",
            ));
        }
        if let Some(h) = raw.h
            && !(h > 0.0 && h <= raw.t_end)
        {
            return Err(bad("h", Num(h).to_string(), "must lie in (0, t_end]"));
        }
        // Without `h`, the time-stepping solver takes the default step, which must fit in
        // the horizon (Scene::validate), or every run of the scenario would fail.
        let h_default = Scene::default().h;
        if raw.h.is_none() && raw.t_end < h_default {
            return Err(bad(
                "t_end",
                Num(raw.t_end).to_string(),
                &format!("is shorter than the default step h = {h_default}: set h"),
            ));
        }
        let x0 = match (raw.x0, raw.x0_from_equilibrium) {
            (Some(_), Some(_)) => {
                return Err(bad(
                    "x0_from_equilibrium",
                    "given".into(),
                    "give either x0 or x0_from_equilibrium, not both",
                ));
            }
            (Some(x), None) => State::new(x[0], x[1], x[2]),
            (None, Some(d)) => {
                for (i, v) in d.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(bad(
                            &format!("x0_from_equilibrium[{i}]"),
                            Num(*v).to_string(),
                            "must be finite",
                        ));
                    }
                }
                let eqs = model.slip_equilibria(raw.u);
                match eqs.as_slice() {
                    [e] => e.state() + State::new(d[0], d[1], d[2]),
                    [] => {
                        return Err(bad(
                            "x0_from_equilibrium",
                            format!("{d:?}"),
                            "there is no slipping equilibrium at this u",
                        ));
                    }
                    _ => {
                        return Err(bad(
                            "x0_from_equilibrium",
                            format!("{d:?}"),
                            "several slipping equilibria exist at this u; give x0",
                        ));
                    }
                }
            }
            (None, None) => State::zeros(),
        };
        for (i, n) in ["x0[0]", "x0[1]", "x0[2]"].iter().enumerate() {
            if !x0[i].is_finite() {
                return Err(bad(n, Num(x0[i]).to_string(), "must be finite"));
            }
        }
        if !(raw.compare.dt > 0.0 && raw.compare.dt.is_finite()) {
            return Err(bad(
                "compare.dt",
                Num(raw.compare.dt).to_string(),
                "must be positive",
            ));
        }
        if raw.t_end / raw.compare.dt > MAX_GRID_ROWS {
            return Err(bad(
                "compare.dt",
                Num(raw.compare.dt).to_string(),
                "asks more than 1e7 output rows (t_end/dt): choose a larger dt",
            ));
        }
        if let Some([a, b]) = raw.compare.transient
            && !(0.0 <= a && a < b && b <= raw.t_end)
        {
            return Err(bad(
                "compare.transient",
                format!("[{a}, {b}]"),
                "must satisfy 0 <= t0 < t1 <= t_end",
            ));
        }
        // A window shorter than the grid step may hold no sample: its gate would measure nothing.
        if let Some([a, b]) = raw.compare.transient
            && b - a < raw.compare.dt
        {
            return Err(bad(
                "compare.transient",
                format!("[{a}, {b}]"),
                "is shorter than compare.dt: it may hold no grid sample to compare",
            ));
        }
        if let Some(t) = raw.compare.steady_from
            && !(t >= 0.0 && t < raw.t_end)
        {
            return Err(bad(
                "compare.steady_from",
                Num(t).to_string(),
                "must lie in [0, t_end)",
            ));
        }
        let mut tolerance = BTreeMap::new();
        for (pair, raw_tol) in &raw.tolerance {
            // Which solvers exist is the runner's knowledge (`check_pairs`); the form is
            // checked here.
            let part = |p: &str| {
                !p.is_empty()
                    && p.chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
            };
            if !pair
                .split_once('-')
                .is_some_and(|(a, b)| part(a) && part(b))
            {
                return Err(bad(
                    "tolerance",
                    format!("{pair:?}"),
                    "a solver pair is named <reference>-<solver>, e.g. \"event-switch\"",
                ));
            }
            // One key per quantity: a retired shared key is named with the keys that replaced
            // it, never read as one of them.
            let tol = raw_tol.current().map_err(|(key, v)| {
                let instead = RETIRED_KEYS.iter().find(|r| r.0 == key).map_or("", |r| r.1);
                bad(
                    &format!("tolerance.{pair}.{key}"),
                    Num(v).to_string(),
                    &format!(
                        "is retired: it gated several quantities, and each has its own key now: {instead}"
                    ),
                )
            })?;
            // Non-negative: 0 is a gate of exact agreement (both discs stuck from rest, where
            // every solver must return x = 0 exactly).
            for (name, v) in tol.stated() {
                if !(v >= 0.0 && v.is_finite()) {
                    return Err(bad(
                        &format!("tolerance.{pair}.{name}"),
                        Num(v).to_string(),
                        "must be non-negative and finite",
                    ));
                }
            }
            // Every tolerance must have something to measure, and every compared window a
            // gate: otherwise a pair would pass having measured nothing.
            let transient = raw.compare.transient.is_some();
            let steady = raw.compare.steady_from.is_some();
            for (name, v) in tol.stated() {
                let (needed, why) = match name {
                    "transient_max" | "transient_rms" | "event_time" => {
                        (transient, "needs compare.transient (the window it gates)")
                    }
                    "steady_abs" => (
                        steady && tol.gates_steady(),
                        "is the floor of the steady-state tolerances and needs one of them (and compare.steady_from)",
                    ),
                    _ => (steady, "needs compare.steady_from (the metrics it gates)"),
                };
                if !needed {
                    return Err(bad(
                        &format!("tolerance.{pair}.{name}"),
                        Num(v).to_string(),
                        why,
                    ));
                }
            }
            if transient && tol.transient_max.is_none() {
                return Err(bad(
                    &format!("tolerance.{pair}.transient_max"),
                    "(missing)".into(),
                    "is required when compare.transient is set: the window would be ungated",
                ));
            }
            // A steady state is gated either as an equilibrium or as a cycle, with every
            // metric of its kind: a tolerance that is missing would leave that metric ungated
            // (the gate fails a steady state whose kind has no tolerances).
            if steady && !tol.gates_steady() {
                return Err(bad(
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
            ] {
                if group.iter().any(|k| tol.get(k).is_some())
                    && let Some(missing) = group.iter().find(|k| tol.get(k).is_none())
                {
                    return Err(bad(
                        &format!("tolerance.{pair}.{missing}"),
                        "(missing)".into(),
                        &format!(
                            "is required with the other {what} tolerances: that metric would be ungated"
                        ),
                    ));
                }
            }
            tolerance.insert(pair.clone(), tol);
        }
        Ok(Scenario {
            name: raw.name,
            description: raw.description.unwrap_or_default(),
            path: path.to_owned(),
            params_path,
            model,
            u: raw.u,
            x0,
            t_end: raw.t_end,
            tol: raw.tol,
            h: raw.h,
            compare: raw.compare,
            tolerance,
        })
    }

    /// Refuses `[tolerance.<pair>]` tables of pairs not in `known` (the pairs a runner gates):
    /// a misspelt pair name would leave that pair ungated.
    pub fn check_pairs(&self, known: &[String]) -> Result<(), ScenarioError> {
        match self.tolerance.keys().find(|p| !known.contains(p)) {
            None => Ok(()),
            Some(pair) => Err(ScenarioError::Invalid {
                path: self.path.clone(),
                field: "tolerance".into(),
                value: format!("{pair:?}"),
                reason: format!(
                    "unknown solver pair (expected one of {})",
                    known
                        .iter()
                        .map(|k| format!("{k:?}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }),
        }
    }

    /// All `*.toml` scenario files in a directory, sorted by file name.
    pub fn list_dir(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        v.sort();
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixtures() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
    }

    #[test]
    fn every_fixture_scenario_loads() {
        let files = Scenario::list_dir(&fixtures()).unwrap();
        assert!(files.len() >= 14, "found {}", files.len());
        for f in files {
            let s = Scenario::from_file(&f).unwrap_or_else(|e| panic!("{e}"));
            assert!(!s.name.is_empty());
        }
    }

    fn err(text: &str) -> String {
        Scenario::from_toml_str(text, &fixtures().join("x.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn bad_scenarios_name_the_field() {
        let ok = "name = \"a\"\nparams = \"../params/table1.toml\"\nu = 1.5\nt_end = 10.0\n";
        assert!(Scenario::from_toml_str(ok, &fixtures().join("x.toml")).is_ok());
        assert!(err(&ok.replace("t_end = 10.0", "t_end = -1.0")).contains("t_end = -1"));
        assert!(err(&ok.replace("t_end = 10.0", "t_end = 10.0\nh = 0.0")).contains("h = 0"));
        assert!(err(&ok.replace("t_end = 10.0", "t_end = 10.0\nh = 20.0")).contains("h = 20"));
        assert!(err(&ok.replace("t_end = 10.0", "t_end = 10.0\ntol = 1.0")).contains("tol = 1"));
        assert!(err(&ok.replace("u = 1.5", "uu = 1.5")).contains("uu"));
        let e = err(&ok.replace("table1", "nothere"));
        assert!(e.contains("nothere.toml") && e.contains("params"), "{e}");
        assert!(err("").contains("empty"));
    }

    /// A retired shared key is refused, naming itself, its value and the keys that replaced
    /// it; a misspelt key is an unknown field; a group with one key missing names that key.
    #[test]
    fn retired_and_unknown_tolerance_keys_are_refused() {
        let ok = std::fs::read_to_string(fixtures().join("t1-u1.5-rest.toml")).unwrap();
        assert!(Scenario::from_toml_str(&ok, &fixtures().join("x.toml")).is_ok());
        let table = "[tolerance.event-switch]\n";
        assert!(ok.contains(table));
        for (key, instead) in RETIRED_KEYS {
            let e = err(&ok.replace(table, &format!("{table}{key} = 2e-10\n")));
            assert!(
                e.contains(&format!("tolerance.event-switch.{key} = 2e-10"))
                    && e.contains("retired")
                    && e.contains(instead),
                "{e}"
            );
        }
        let e = err(&ok.replace("omega_u_min_rel", "omega_u_mni_rel"));
        assert!(
            e.contains("unknown field") && e.contains("omega_u_mni_rel"),
            "{e}"
        );
        let e = err(&ok.replacen("omega_l_min", "# omega_l_min", 1));
        assert!(
            e.contains("tolerance.event-moreau.omega_l_min = (missing)")
                || e.contains("tolerance.event-switch.omega_l_min = (missing)"),
            "{e}"
        );
        // An equilibrium's gates come as a set of three, too.
        let eq = std::fs::read_to_string(fixtures().join("t1-u6.0-rest.toml")).unwrap();
        assert!(Scenario::from_toml_str(&eq, &fixtures().join("x.toml")).is_ok());
        let e = err(&eq.replacen("equilibrium_alpha_rel", "# equilibrium_alpha_rel", 1));
        assert!(
            e.contains(".equilibrium_alpha_rel = (missing)") && e.contains("equilibrium"),
            "{e}"
        );
    }

    /// Every metric of both kinds of steady state has exactly one key, and no key gates two.
    #[test]
    fn one_key_per_steady_metric() {
        use rotor_model::SteadyState;
        let cycle = SteadyState::LimitCycle {
            period: 1.0,
            omega_l_max: 1.0,
            omega_l_min: 0.0,
            omega_u_max: 1.0,
            omega_u_min: 1.0,
            stick_time: 0.0,
        };
        let eq = SteadyState::Equilibrium {
            omega_u: 1.0,
            omega_l: 1.0,
            alpha: 0.1,
        };
        let mut keys: Vec<&str> = Vec::new();
        for (m, group) in [(cycle, &CYCLE_KEYS[..]), (eq, &EQUILIBRIUM_KEYS[..])] {
            for (name, _) in m.values() {
                let q = STEADY_QUANTITIES.iter().filter(|q| q.metric == name);
                let q: Vec<_> = q.collect();
                assert_eq!(q.len(), 1, "{name}");
                assert!(group.contains(&q[0].key), "{name}");
                keys.push(q[0].key);
            }
        }
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), STEADY_QUANTITIES.len());
    }
}
