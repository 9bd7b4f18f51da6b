//! The `[compare]` section of a scenario file: what the comparison harness compares.

use serde::Deserialize;

use crate::Num;
use crate::seam::scene::MAX_GRID_ROWS;

use crate::scenario::error::{Bad, ScenarioError};

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

impl CompareSpec {
    /// `[compare]` for a horizon `t_end`: `dt` positive and at most 1e7 rows, the transient
    /// window `0 <= t0 < t1 <= t_end` and at least `dt` long, `steady_from` in `[0, t_end)`.
    pub(crate) fn check(&self, t_end: f64, bad: Bad) -> Result<(), ScenarioError> {
        if !(self.dt > 0.0 && self.dt.is_finite()) {
            return Err(bad.at("compare.dt", Num(self.dt).to_string(), "must be positive"));
        }
        if t_end / self.dt > MAX_GRID_ROWS {
            return Err(bad.at(
                "compare.dt",
                Num(self.dt).to_string(),
                "asks more than 1e7 output rows (t_end/dt): choose a larger dt",
            ));
        }
        if let Some([a, b]) = self.transient
            && !(0.0 <= a && a < b && b <= t_end)
        {
            return Err(bad.at(
                "compare.transient",
                format!("[{a}, {b}]"),
                "must satisfy 0 <= t0 < t1 <= t_end",
            ));
        }
        // A window shorter than the grid step may hold no sample: its gate would measure
        // nothing.
        if let Some([a, b]) = self.transient
            && b - a < self.dt
        {
            return Err(bad.at(
                "compare.transient",
                format!("[{a}, {b}]"),
                "is shorter than compare.dt: it may hold no grid sample to compare",
            ));
        }
        if let Some(t) = self.steady_from
            && !(t >= 0.0 && t < t_end)
        {
            return Err(bad.at(
                "compare.steady_from",
                Num(t).to_string(),
                "must lie in [0, t_end)",
            ));
        }
        Ok(())
    }
}
