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
//! ([`STEADY_QUANTITIES`](crate::scenario::STEADY_QUANTITIES)); the shared keys of old
//! ([`RETIRED_KEYS`](crate::scenario::RETIRED_KEYS)) are refused; the `[tolerance.<pair>]` tables
//! are read and checked in [`crate::scenario::tolerance`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::params::{Params, one_line, read_small, text_of};
use crate::seam::Input;
use crate::seam::scene::{DEFAULT_STEP, MIN_TOL, Output, Scene};
use crate::{FieldError, Model, Num, State};

use crate::scenario::compare::CompareSpec;
use crate::scenario::error::{Bad, ScenarioError};
use crate::scenario::tolerance::{PairTolerance, RawPairTolerance, check_pair};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: String,
    #[serde(default)]
    description: Option<String>,
    params: PathBuf,
    #[serde(default)]
    u: Option<f64>,
    #[serde(default)]
    input: Option<RawInput>,
    #[serde(default)]
    x0: Option<Vec<f64>>,
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

/// `input = "NAME.csv"` (a CSV `t,u` relative to the scenario file) or
/// `input = [[t, u], ...]` (the rows inline).
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum RawInput {
    File(PathBuf),
    Rows(Vec<[f64; 2]>),
}

/// A loaded, validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Its name: the report's file names (`<name>.csv`, `<name>.svg`); 1 to 100 characters
    /// of `A-Z a-z 0-9 . _ + -`, not starting with `.`.
    pub name: String,
    /// One line on what the scene shows (empty if the file gives none).
    pub description: String,
    /// The scenario file it was read from.
    pub path: PathBuf,
    /// The parameter file, resolved relative to the scenario file.
    pub params_path: PathBuf,
    /// The rotor model of that parameter file.
    pub model: Model,
    /// Motor input voltage u \[V\]; with `input`, its value at t = 0.
    pub u: f64,
    /// A time-varying input u(t) (`input = "NAME.csv"` or `input = [[t, u], ...]` instead of
    /// `u`); `None` for a constant one (a table of one value is read as `u`).
    pub input: Option<Input>,
    /// Initial state, a list of the model's size (`[α, ω_u, ω_l]` for the rig: rad, rad/s,
    /// rad/s): `x0`, or the slipping equilibrium at `u` plus `x0_from_equilibrium`, or rest.
    pub x0: Vec<f64>,
    /// Horizon \[s\]; runs cover `[0, t_end]`.
    pub t_end: f64,
    /// Tolerance for the adaptive solvers, if the file sets one.
    pub tol: Option<f64>,
    /// Step for the time-stepping solver, if the file sets one.
    pub h: Option<f64>,
    /// The `[compare]` table: transient window, grid step and steady-state window.
    pub compare: CompareSpec,
    /// Keyed by pair name, e.g. `"event-switch"`.
    pub tolerance: BTreeMap<String, PairTolerance>,
}

impl Scenario {
    /// The scene of this scenario keeping `output`: its input, initial state, horizon and
    /// steady-state window, at [`Scene::default`]'s accuracy (callers set their solver's).
    pub fn scene(&self, output: Output) -> Scene {
        Scene {
            u: self.u,
            input: self.input.clone(),
            x0: self.x0.clone(),
            t_end: self.t_end,
            output,
            metrics_from: self.compare.steady_from,
            ..Scene::default()
        }
    }

    /// The input over the steady-state window: `u`, or a time-varying input's value after
    /// its last breakpoint (which a scenario with `compare.steady_from` puts before it).
    pub fn steady_u(&self) -> f64 {
        self.input.as_ref().map_or(self.u, |i| i.at(self.t_end))
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
    ///
    /// Each section is validated on its own, in file order (the first bad value is the one
    /// reported): the name, the parameter file, the run settings (`u`, `t_end`, `tol`, `h`),
    /// the initial state, `[compare]`, and each `[tolerance.<pair>]` table.
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
        let bad = Bad(path);
        check_name(&raw.name, bad)?;
        let params_path = path.parent().unwrap_or(Path::new(".")).join(&raw.params);
        let params = Params::from_file(&params_path).map_err(|error| ScenarioError::Params {
            path: path.to_owned(),
            error,
        })?;
        let model = Model::new(params);
        let (u, input) = check_input(raw.u, raw.input.as_ref(), path, bad)?;
        let mut raw = raw;
        raw.u = Some(u);
        check_run(u, raw.t_end, raw.tol, raw.h, bad)?;
        let x0 = initial_state(&raw, &model, bad)?;
        raw.compare.check(raw.t_end, bad)?;
        // The steady window of a time-varying input lies after its last breakpoint: a steady
        // state is that of a constant input.
        if let (Some(i), Some(from)) = (&input, raw.compare.steady_from)
            && let Some(&(last, _)) = i.rows().last()
            && last > from
        {
            return Err(bad.at(
                "compare.steady_from",
                Num(from).to_string(),
                &format!(
                    "lies before the input's last breakpoint (t = {}): the steady window needs \
                     a constant input",
                    Num(last)
                ),
            ));
        }
        // A scene the project never measured (no [tolerance] table) that sets no steady
        // window has its steady state compared over the second half of the run, as every
        // scene of the suite does, under derived gates (`rotor compare`). An input in time
        // has no steady state unless the file says where it starts.
        if raw.tolerance.is_empty() && raw.compare.steady_from.is_none() && input.is_none() {
            raw.compare.steady_from = Some(0.5 * raw.t_end);
        }
        let mut tolerance = BTreeMap::new();
        for (pair, raw_tol) in &raw.tolerance {
            tolerance.insert(pair.clone(), check_pair(pair, raw_tol, &raw.compare, bad)?);
        }
        Ok(Scenario {
            name: raw.name,
            description: raw.description.unwrap_or_default(),
            path: path.to_owned(),
            params_path,
            model,
            u,
            input,
            x0,
            t_end: raw.t_end,
            tol: raw.tol,
            h: raw.h,
            compare: raw.compare,
            tolerance,
        })
    }

    /// Refuses `[tolerance.<pair>]` tables of pairs not in `known` (the pairs a runner gates):
    /// a misspelt pair name would leave that pair ungated. `whole_only` are the known pairs
    /// compared over the whole run alone (two non-reference solvers): their tables state the
    /// whole-run keys only, and every other known pair's table is more than that.
    pub fn check_pairs(
        &self,
        known: &[String],
        whole_only: &[String],
    ) -> Result<(), ScenarioError> {
        let invalid = |field: String, value: String, reason: String| ScenarioError::Invalid {
            path: self.path.clone(),
            error: FieldError::new(field, value, reason),
        };
        if let Some(pair) = self.tolerance.keys().find(|p| !known.contains(p)) {
            return Err(invalid(
                "tolerance".into(),
                format!("{pair:?}"),
                format!(
                    "unknown solver pair (expected one of {})",
                    known
                        .iter()
                        .map(|k| format!("{k:?}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        for (pair, tol) in &self.tolerance {
            let only = whole_only.contains(pair);
            if only && !tol.whole_only() {
                let (key, v) = tol
                    .stated()
                    .into_iter()
                    .find(|(k, _)| !crate::scenario::WHOLE_KEYS.contains(k))
                    .expect("a table that is not whole-run only states another key");
                return Err(invalid(
                    format!("tolerance.{pair}.{key}"),
                    Num(v).to_string(),
                    format!(
                        "this pair is compared over the whole run only: state {} alone",
                        crate::scenario::WHOLE_KEYS.join(", ")
                    ),
                ));
            }
            let windows = self.compare.transient.is_some() || self.compare.steady_from.is_some();
            if !only && windows && tol.whole_only() {
                return Err(invalid(
                    format!("tolerance.{pair}"),
                    "(whole-run keys only)".into(),
                    "the reference's pairs gate compare.transient and compare.steady_from too: \
                     state their tolerances"
                        .into(),
                ));
            }
        }
        Ok(())
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

/// `name`: it becomes the report's file names (`<name>.csv`, `<name>.svg`), so a path
/// separator or a leading dot would write outside the report or hide the file.
pub(crate) fn check_name(name: &str, bad: Bad) -> Result<(), ScenarioError> {
    let name_ok = !name.is_empty()
        && name.len() <= 100
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._+-".contains(c));
    if !name_ok {
        return Err(bad.at(
            "name",
            format!("{name:?}"),
            "must be 1 to 100 characters from A-Z a-z 0-9 . _ + - (it names the report's files), not starting with '.'",
        ));
    }
    Ok(())
}

/// The run settings: `u` finite, `t_end` positive and finite, `tol` in
/// `[MIN_TOL, 1)`, `h` in `(0, t_end]`, and without `h` a horizon that holds the default step.
pub(crate) fn check_run(
    u: f64,
    t_end: f64,
    tol: Option<f64>,
    h: Option<f64>,
    bad: Bad,
) -> Result<(), ScenarioError> {
    if !u.is_finite() {
        return Err(bad.at("u", Num(u).to_string(), "must be finite"));
    }
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(bad.at(
            "t_end",
            Num(t_end).to_string(),
            "must be positive and finite",
        ));
    }
    if let Some(tol) = tol
        && !(tol > 0.0 && tol < 1.0)
    {
        return Err(bad.at("tol", Num(tol).to_string(), "must lie in (0, 1)"));
    }
    if let Some(tol) = tol
        && tol < MIN_TOL
    {
        return Err(bad.at(
            "tol",
            Num(tol).to_string(),
            "is below 1.1e-15 (10 unit roundoffs): double precision cannot deliver it",
        ));
    }
    if let Some(h) = h
        && !(h > 0.0 && h <= t_end)
    {
        return Err(bad.at("h", Num(h).to_string(), "must lie in (0, t_end]"));
    }
    // Without `h`, the time-stepping solver takes the default step, which must fit in
    // the horizon (Scene::validate), or every run of the scenario would fail.
    let h_default = DEFAULT_STEP;
    if h.is_none() && t_end < h_default {
        return Err(bad.at(
            "t_end",
            Num(t_end).to_string(),
            &format!("is shorter than the default step h = {h_default}: set h"),
        ));
    }
    Ok(())
}

/// The input: `u = V`, or `input = "NAME.csv"` (relative to the scenario file) or
/// `input = [[t, u], ...]`, exactly one of them. Returns u at t = 0 and the input if it
/// changes in time (a table of one value is the constant u).
pub(crate) fn check_input(
    u: Option<f64>,
    input: Option<&RawInput>,
    path: &Path,
    bad: Bad,
) -> Result<(f64, Option<Input>), ScenarioError> {
    let input = match (&u, input) {
        (Some(u), None) => return Ok((*u, None)),
        (None, None) => {
            return Err(bad.at(
                "u",
                "(missing)".into(),
                "missing field `u`: give u = V, or input = \"NAME.csv\" or [[t, u], ...]",
            ));
        }
        (Some(u), Some(_)) => {
            return Err(bad.at(
                "input",
                "(with u)".into(),
                &format!("give u = {} or input, not both", Num(*u)),
            ));
        }
        (None, Some(RawInput::Rows(rows))) => {
            Input::new(rows).map_err(|e| ScenarioError::Invalid {
                path: path.to_owned(),
                error: e,
            })?
        }
        (None, Some(RawInput::File(file))) => {
            let p = path.parent().unwrap_or(Path::new(".")).join(file);
            let text = std::fs::read_to_string(&p).map_err(|e| {
                bad.at(
                    "input",
                    format!("{:?}", file.display().to_string()),
                    &format!("cannot read {}: {e}", crate::params::shown(&p)),
                )
            })?;
            Input::from_csv(&text, &crate::params::shown(file)).map_err(|e| {
                ScenarioError::Invalid {
                    path: path.to_owned(),
                    error: e,
                }
            })?
        }
    };
    Ok(match input.constant() {
        Some(u) => (u, None),
        None => (input.at(0.0), Some(input)),
    })
}

/// The initial state: `x0`, or the one slipping equilibrium at `u` plus the offset
/// `x0_from_equilibrium` (not both), or rest; every component finite.
fn initial_state(raw: &RawScenario, model: &Model, bad: Bad) -> Result<Vec<f64>, ScenarioError> {
    let names = model.state_names();
    let x0 = match (&raw.x0, raw.x0_from_equilibrium) {
        (Some(_), Some(_)) => {
            return Err(bad.at(
                "x0_from_equilibrium",
                "given".into(),
                "give either x0 or x0_from_equilibrium, not both",
            ));
        }
        (Some(x), None) if x.len() != names.len() => {
            let shown: Vec<String> = x.iter().map(|&v| Num(v).to_string()).collect();
            return Err(bad.at(
                "x0",
                format!("[{}]", shown.join(", ")),
                &format!(
                    "length {}: the model's state has {} values ({})",
                    x.len(),
                    names.len(),
                    names.join(", ")
                ),
            ));
        }
        (Some(x), None) => x.clone(),
        (None, Some(d)) => {
            let x = from_equilibrium(d, raw.u.unwrap_or(f64::NAN), model, bad)?;
            x.as_slice().to_vec()
        }
        (None, None) => vec![0.0; names.len()],
    };
    if let Some(i) = x0.iter().position(|v| !v.is_finite()) {
        return Err(bad.at(
            &format!("x0[{i}]"),
            Num(x0[i]).to_string(),
            "must be finite",
        ));
    }
    Ok(x0)
}

/// `x0_from_equilibrium = d`: the slipping equilibrium at `u` plus `d`, if there is exactly
/// one such equilibrium.
fn from_equilibrium(d: [f64; 3], u: f64, model: &Model, bad: Bad) -> Result<State, ScenarioError> {
    for (i, v) in d.iter().enumerate() {
        if !v.is_finite() {
            return Err(bad.at(
                &format!("x0_from_equilibrium[{i}]"),
                Num(*v).to_string(),
                "must be finite",
            ));
        }
    }
    match model.slip_equilibria(u).as_slice() {
        [e] => Ok(e.state() + State::new(d[0], d[1], d[2])),
        [] => Err(bad.at(
            "x0_from_equilibrium",
            format!("{d:?}"),
            "there is no slipping equilibrium at this u",
        )),
        _ => Err(bad.at(
            "x0_from_equilibrium",
            format!("{d:?}"),
            "several slipping equilibria exist at this u; give x0",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::tolerance::{
        CYCLE_KEYS, EQUILIBRIUM_KEYS, RETIRED_KEYS, STEADY_QUANTITIES,
    };

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

    /// The whole-run keys come as a set of four; a table of them alone is the table of a pair
    /// of two non-reference solvers, which `check_pairs` accepts only for those pairs, and
    /// a reference pair's table of them alone (its window and steady state ungated) is refused.
    #[test]
    fn whole_run_tables_are_checked_for_their_pair() {
        let ok = std::fs::read_to_string(fixtures().join("t1-u1.5-rest.toml")).unwrap();
        let sc = Scenario::from_toml_str(&ok, &fixtures().join("x.toml")).unwrap();
        let known = ["event-switch", "event-moreau", "switch-moreau"].map(String::from);
        let others = ["switch-moreau".to_owned()];
        sc.check_pairs(&known, &others).unwrap();
        assert!(sc.tolerance["switch-moreau"].whole_only());
        assert!(sc.tolerance["event-switch"].gates_whole());
        // One of the four missing.
        let e = err(&ok.replacen("whole_omega_u", "# whole_omega_u", 1));
        assert!(
            e.contains("tolerance.event-switch.whole_omega_u = (missing)")
                && e.contains("whole-run"),
            "{e}"
        );
        // Another key in the whole-run-only pair's table.
        let extra = ok.replace(
            "[tolerance.switch-moreau]\n",
            "[tolerance.switch-moreau]\nperiod_rel = 1e-6\n",
        );
        let e = Scenario::from_toml_str(&extra, &fixtures().join("x.toml"))
            .and_then(|sc| sc.check_pairs(&known, &others))
            .unwrap_err()
            .to_string();
        // (Refused as it is read: with a steady key the table must gate the window too.)
        assert!(
            e.contains("tolerance.switch-moreau.") && e.contains("non-reference"),
            "{e}"
        );
        // Whole-run-only in form but named for the reference: refused by the runner's check.
        let e = sc.check_pairs(&known, &[]).unwrap_err().to_string();
        assert!(
            e.contains("tolerance.switch-moreau") && e.contains("whole-run keys only"),
            "{e}"
        );
        // A reference pair stating only the whole-run keys.
        let i = ok.find("[tolerance.event-moreau]").unwrap();
        let j = ok.find("[tolerance.switch-moreau]").unwrap();
        let whole: String = ok[i..j]
            .lines()
            .filter(|l| l.starts_with('[') || l.starts_with("whole_"))
            .map(|l| format!("{l}\n"))
            .collect();
        let bare = format!("{}{whole}\n{}", &ok[..i], &ok[j..]);
        let e = Scenario::from_toml_str(&bare, &fixtures().join("x.toml"))
            .and_then(|sc| sc.check_pairs(&known, &others))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tolerance.event-moreau") && e.contains("whole-run keys only"),
            "{e}"
        );
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
        use crate::seam::RigSteady;
        let cycle = RigSteady::LimitCycle {
            period: 1.0,
            omega_l_max: 1.0,
            omega_l_min: 0.0,
            omega_u_max: 1.0,
            omega_u_min: 1.0,
            stick_time: 0.0,
        };
        let eq = RigSteady::Equilibrium {
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
