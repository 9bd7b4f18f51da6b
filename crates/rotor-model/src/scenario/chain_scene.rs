//! Scenario files of chains of N discs: one scene on a parameter file in chain form, run by
//! every solver and graded as the rig's scenes are (the suite's chain tier).
//!
//! ```toml
//! name = "chain3-u1.5-rest"
//! description = "a chain of three rig-like discs, 1.5 V from rest"
//! params = "../params/chain3.toml"   # a chain-form parameter file, relative to this file
//! u = 1.5                            # V; or input = "NAME.csv" | [[t, u], ...]
//! x0 = [0.0, 0.0, 0.0, 0.0, 0.0]     # alpha_1..alpha_{N-1}, omega_1..omega_N (default: rest)
//! t_end = 100.0                      # s
//! [compare]
//! dt = 0.01                          # s, the reference grid (default 0.01)
//! ```
//!
//! A chaotic scene adds
//!
//! ```toml
//! [chaos]
//! statistics_from = 1000.0           # s: statistics over [statistics_from, t_end]
//! batches = 10                       # equal batches, for the statistics' standard errors
//! ```
//!
//! The keys mean what they mean in the rig's files ([`crate::scenario::scene_file`]), with the
//! chain's state of 2N − 1 values. A chain scene states no agreement gates: its references are
//! graded by the levels of `rotor check`, and the solvers' agreement on it by gates derived from
//! each solver's stated accuracy.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::chain::{ChainModel, ChainParams};
use crate::params::{one_line, read_small, text_of};
use crate::scenario::error::{Bad, ScenarioError};
use crate::scenario::scene_file::{RawInput, check_input, check_name, check_run};
use crate::seam::Input;
use crate::seam::scene::{Output, Scene};
use crate::{FieldError, Num};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChainScenario {
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
    t_end: f64,
    #[serde(default)]
    tol: Option<f64>,
    #[serde(default)]
    h: Option<f64>,
    #[serde(default)]
    compare: RawChainCompare,
    #[serde(default)]
    chaos: Option<RawChaos>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChaos {
    statistics_from: f64,
    batches: usize,
}

/// A chaotic scene's grade beyond its predictability horizon (`[chaos]`): statistics over
/// `[statistics_from, t_end]` from `batches` equal batches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chaos {
    /// Start of the statistics' window \[s\].
    pub statistics_from: f64,
    /// Number of equal batches the window is cut into (their means give each statistic's
    /// standard error).
    pub batches: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChainCompare {
    #[serde(default = "default_dt")]
    dt: f64,
}

impl Default for RawChainCompare {
    fn default() -> Self {
        RawChainCompare { dt: default_dt() }
    }
}

fn default_dt() -> f64 {
    0.01
}

/// The most rows a chain scene's grid may hold (`t_end / dt`): a reference of 2N columns.
const MAX_ROWS: f64 = 1e6;

/// A loaded, validated chain scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainScenario {
    /// Its name (the reference's file names), as a rig scene's.
    pub name: String,
    /// One line on what the scene shows (empty if the file gives none).
    pub description: String,
    /// The scenario file it was read from.
    pub path: PathBuf,
    /// The parameter file, resolved relative to the scenario file.
    pub params_path: PathBuf,
    /// The chain of that parameter file.
    pub params: ChainParams,
    /// Motor input voltage u \[V\]; with `input`, its value at t = 0.
    pub u: f64,
    /// A time-varying input u(t); `None` for a constant one.
    pub input: Option<Input>,
    /// Initial state `[α_1 … α_{N−1}, ω_1 … ω_N]` (rad, rad/s): `x0`, or rest.
    pub x0: Vec<f64>,
    /// Horizon \[s\]; runs cover `[0, t_end]`.
    pub t_end: f64,
    /// Tolerance for the adaptive solvers, if the file sets one.
    pub tol: Option<f64>,
    /// Step for the time-stepping solver, if the file sets one.
    pub h: Option<f64>,
    /// The grid step of the reference trace \[s\].
    pub dt: f64,
    /// `[chaos]`: the scene is chaotic, graded sample by sample up to its predictability
    /// horizon and on statistics beyond; `None` for a scene graded over the whole run.
    pub chaos: Option<Chaos>,
}

impl ChainScenario {
    /// The chain's model.
    pub fn model(&self) -> ChainModel {
        ChainModel::new(&self.params)
    }

    /// Number of discs.
    pub fn discs(&self) -> usize {
        self.params.len()
    }

    /// The scene of this scenario keeping `output`: its input, initial state and horizon, at
    /// [`Scene::default`]'s accuracy (callers set their solver's).
    pub fn scene(&self, output: Output) -> Scene {
        Scene {
            u: self.u,
            input: self.input.clone(),
            x0: self.x0.clone(),
            t_end: self.t_end,
            output,
            metrics_from: None,
            ..Scene::default()
        }
    }

    /// Whether the scenario file at `path` names a parameter file in chain form (a scene of
    /// the chain tier). `false` where either file cannot be read or parsed: the rig's loader
    /// then names what is wrong.
    pub fn is_chain_scene(path: &Path) -> bool {
        let Ok(text) = std::fs::read_to_string(path) else {
            return false;
        };
        let Some(params) = text
            .parse::<toml::Table>()
            .ok()
            .and_then(|t| t.get("params").and_then(|p| p.as_str()).map(PathBuf::from))
        else {
            return false;
        };
        let p = path.parent().unwrap_or(Path::new(".")).join(params);
        std::fs::read_to_string(p).is_ok_and(|t| ChainParams::is_chain_form(&t))
    }

    /// Reads and validates a chain scenario file and the parameter file it names.
    pub fn from_file(path: &Path) -> Result<ChainScenario, ScenarioError> {
        let bytes = read_small(path).map_err(|e| ScenarioError::Io {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        let text = text_of(bytes).map_err(|message| ScenarioError::Parse {
            path: path.to_owned(),
            message,
        })?;
        ChainScenario::from_toml_str(&text, path)
    }

    /// Parses chain scenario TOML; `path` resolves the params path and names the file in
    /// messages. Validated in file order as a rig scene is: the name, the parameter file (in
    /// chain form), the input and run settings, the initial state, `[compare]`.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<ChainScenario, ScenarioError> {
        let raw: RawChainScenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: path.to_owned(),
            message: one_line(&e.to_string()),
        })?;
        let bad = Bad(path);
        check_name(&raw.name, bad)?;
        let params_path = path.parent().unwrap_or(Path::new(".")).join(&raw.params);
        let params =
            ChainParams::from_file(&params_path).map_err(|error| ScenarioError::Params {
                path: path.to_owned(),
                error,
            })?;
        let form = std::fs::read_to_string(&params_path).unwrap_or_default();
        if !ChainParams::is_chain_form(&form) {
            return Err(bad.at(
                "params",
                format!("{:?}", raw.params.display().to_string()),
                "is a parameter file in the rig's form: a chain scene names one in chain form \
                 ([[disc]] tables)",
            ));
        }
        let (u, input) = check_input(raw.u, raw.input.as_ref(), path, bad)?;
        check_run(u, raw.t_end, raw.tol, raw.h, bad)?;
        let n = params.len();
        let names = crate::chain::chain_state_names(n);
        let x0 = match raw.x0 {
            Some(x) if x.len() != names.len() => {
                let shown: Vec<String> = x.iter().map(|&v| Num(v).to_string()).collect();
                return Err(bad.at(
                    "x0",
                    format!("[{}]", shown.join(", ")),
                    &format!(
                        "length {}: a chain of {n} discs has {} state values ({})",
                        x.len(),
                        names.len(),
                        names.join(", ")
                    ),
                ));
            }
            Some(x) => x,
            None => vec![0.0; names.len()],
        };
        if let Some(i) = x0.iter().position(|v| !v.is_finite()) {
            return Err(bad.at(
                &format!("x0[{i}]"),
                Num(x0[i]).to_string(),
                "must be finite",
            ));
        }
        let dt = raw.compare.dt;
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(bad.at("compare.dt", Num(dt).to_string(), "must be positive"));
        }
        if raw.t_end / dt > MAX_ROWS {
            return Err(bad.at(
                "compare.dt",
                Num(dt).to_string(),
                "asks more than 1e6 rows (t_end/dt): choose a larger dt",
            ));
        }
        let steps = raw.t_end / dt;
        if (steps - steps.round()).abs() > 1e-9 * steps.max(1.0) {
            return Err(ScenarioError::Invalid {
                path: path.to_owned(),
                error: FieldError::new(
                    "compare.dt",
                    Num(dt).to_string(),
                    format!("must divide t_end = {}", Num(raw.t_end)),
                ),
            });
        }
        let chaos = match raw.chaos {
            None => None,
            Some(c) => {
                if !(c.statistics_from >= 0.0 && c.statistics_from < raw.t_end) {
                    return Err(bad.at(
                        "chaos.statistics_from",
                        Num(c.statistics_from).to_string(),
                        "must lie in [0, t_end)",
                    ));
                }
                let per_batch = (raw.t_end - c.statistics_from) / c.batches.max(1) as f64;
                if !(2..=1000).contains(&c.batches) || per_batch < 2.0 * dt {
                    return Err(bad.at(
                        "chaos.batches",
                        c.batches.to_string(),
                        "must be 2 to 1000, each batch at least two grid steps long",
                    ));
                }
                Some(Chaos {
                    statistics_from: c.statistics_from,
                    batches: c.batches,
                })
            }
        };
        Ok(ChainScenario {
            name: raw.name,
            description: raw.description.unwrap_or_default(),
            path: path.to_owned(),
            params_path,
            params,
            u,
            input,
            x0,
            t_end: raw.t_end,
            tol: raw.tol,
            h: raw.h,
            dt,
            chaos,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/chain/scenarios")
    }

    fn load(text: &str) -> Result<ChainScenario, String> {
        ChainScenario::from_toml_str(text, &dir().join("x.toml")).map_err(|e| e.to_string())
    }

    const OK: &str = "name = \"c\"\nparams = \"../params/chain3.toml\"\nu = 1.5\nt_end = 10.0\n";

    #[test]
    fn every_chain_scene_of_the_suite_loads() {
        let files = crate::scenario::Scenario::list_dir(&dir()).unwrap();
        assert!(files.len() >= 3, "found {}", files.len());
        for f in files {
            let s = ChainScenario::from_file(&f).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(s.x0.len(), 2 * s.discs() - 1, "{}", s.name);
            assert!(
                s.discs() >= 3,
                "{}: the chain tier has chains beyond the rig",
                s.name
            );
        }
    }

    #[test]
    fn chain_scenes_are_told_from_the_rigs() {
        for f in crate::scenario::Scenario::list_dir(&dir()).unwrap() {
            assert!(ChainScenario::is_chain_scene(&f), "{}", f.display());
        }
        let rig = dir().join("../../scenarios/t1-u1.5-rest.toml");
        assert!(rig.is_file() && !ChainScenario::is_chain_scene(&rig));
        assert!(!ChainScenario::is_chain_scene(&dir().join("nothere.toml")));
    }

    #[test]
    fn a_minimal_chain_scene_loads_at_rest() {
        let s = load(OK).unwrap();
        assert_eq!(s.discs(), 3);
        assert_eq!(s.x0, vec![0.0; 5]);
        assert_eq!(s.dt, 0.01);
    }

    #[test]
    fn bad_chain_scenes_name_the_field_and_value() {
        for (from, to, needle) in [
            ("u = 1.5", "u = nan", "u = NaN"),
            ("t_end = 10.0", "t_end = -1.0", "t_end = -1"),
            (
                "t_end = 10.0",
                "t_end = 10.0\nx0 = [0.0, 1.0]",
                "x0 = [0, 1]: length 2",
            ),
            (
                "t_end = 10.0",
                "t_end = 10.0\nx0 = [0.0, 0.0, 0.0, 0.0, inf]",
                "x0[4] = inf",
            ),
            (
                "t_end = 10.0",
                "t_end = 10.0\n[compare]\ndt = 0.03",
                "compare.dt = 0.03: must divide",
            ),
            (
                "t_end = 10.0",
                "t_end = 10.0\n[compare]\ndt = 0.0",
                "compare.dt = 0",
            ),
            (
                "t_end = 10.0",
                "t_end = 10.0\n[compare]\nsteady_from = 5.0",
                "steady_from",
            ),
            ("chain3", "../../params/table1", "rig's form"),
            ("chain3", "nothere", "nothere.toml"),
            ("u = 1.5", "uu = 1.5", "uu"),
            (
                "t_end = 10.0",
                "t_end = 10.0\n[chaos]\nstatistics_from = 10.0\nbatches = 4",
                "chaos.statistics_from = 10",
            ),
            (
                "t_end = 10.0",
                "t_end = 10.0\n[chaos]\nstatistics_from = 5.0\nbatches = 1",
                "chaos.batches = 1",
            ),
        ] {
            let text = OK.replace(from, to);
            let e = load(&text).unwrap_err();
            assert!(e.contains(needle), "{to}: {e}");
        }
    }
}
