//! Snapshot records: per scenario and solver, the steady-state metrics rounded to the digits
//! the scenario's agreement tolerance justifies, and the solver's work counters.
//!
//! The metrics are rounded to `⌊−log10 steady_rel⌋` significant digits (the tightest
//! `steady_rel` of the scenario's pairs: 2e-6 → 5 digits), and values below the tightest
//! `steady_abs` are written as 0. A snapshot therefore changes only when a solver's answer
//! moves by about the agreement tolerance, not with the last bits of the floating-point
//! arithmetic of a machine.
//!
//! The counters are rounded to 3 significant digits: a last-bit change of the friction law
//! (measured: replacing libm's `tanh` by a one-`exp` form) moves step and evaluation counts
//! by up to 0.1 %, so 3 digits show any real change in the work a solver does (≥ 1 %) but
//! not another machine's `libm`. The event count is left out when the run settles on an
//! equilibrium: there the late extrema are round-off wiggles of amplitude ~1e-15 whose number
//! depends on the last bits (442 vs 301 on t1-u0.3-rest in that measurement).

use std::collections::BTreeMap;

use rotor_model::{Stats, SteadyState};
use serde::Serialize;

use crate::run::ScenarioResult;

/// One solver's record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverSnapshot {
    pub solver: &'static str,
    /// `equilibrium`, `limit_cycle`, `none` (no steady state measured) or `error`.
    pub steady: String,
    /// Rounded metrics, by name (empty on error).
    pub metrics: BTreeMap<&'static str, f64>,
    pub counters: Counters,
    /// The typed error, if the run failed.
    pub error: Option<String>,
}

/// The work counters a snapshot records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Counters {
    pub steps: u64,
    pub rejected: u64,
    pub rhs_evals: u64,
    /// `None` for a run that settles on an equilibrium (see the module docs).
    pub events: Option<u64>,
    pub lcp_solves: u64,
    pub lcp_skipped: u64,
}

/// Rounds a counter to 3 significant digits.
pub fn round_count(n: u64) -> u64 {
    let mut scale = 1;
    while n / scale >= 1000 {
        scale *= 10;
    }
    (n + scale / 2) / scale * scale
}

impl Counters {
    fn new(s: Stats, equilibrium: bool) -> Self {
        Counters {
            steps: round_count(s.steps),
            rejected: round_count(s.rejected),
            rhs_evals: round_count(s.rhs_evals),
            events: (!equilibrium).then_some(round_count(s.events)),
            lcp_solves: round_count(s.lcp_solves),
            lcp_skipped: round_count(s.lcp_skipped),
        }
    }
}

/// The snapshot of one scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScenarioSnapshot {
    pub scenario: String,
    /// Significant digits kept, and the absolute floor below which a metric is written as 0.
    pub digits: u32,
    pub floor: f64,
    pub solvers: Vec<SolverSnapshot>,
}

/// Rounds `v` to `digits` significant digits; `|v| < floor` gives 0 (never −0).
pub fn round_sig(v: f64, digits: u32, floor: f64) -> f64 {
    if !v.is_finite() || v.abs() < floor || v == 0.0 {
        return if v.is_finite() { 0.0 } else { v };
    }
    let e = v.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits as i32 - 1 - e);
    let r = (v * scale).round() / scale;
    // Re-parse the shortest decimal so the value prints as written (no 4.5778000000000001).
    let s = format!("{:.*e}", digits.saturating_sub(1) as usize, r);
    s.parse().unwrap_or(r)
}

/// Builds the snapshot of one scenario's results.
pub fn snapshot(r: &ScenarioResult) -> ScenarioSnapshot {
    let tols = r.scenario.tolerance.values();
    let rel = tols
        .clone()
        .filter_map(|t| t.steady_rel)
        .fold(f64::INFINITY, f64::min);
    let floor = tols
        .filter_map(|t| t.steady_abs)
        .fold(f64::INFINITY, f64::min);
    // No stated steady tolerance (a scenario without compare.steady_from has no metrics: the
    // loader requires steady_rel of every pair when it is set): 6 digits and a 1e-9 floor.
    let floor = if floor.is_finite() { floor } else { 1e-9 };
    let (digits, floor) = if rel.is_finite() && rel > 0.0 {
        ((-rel.log10()).floor().max(1.0) as u32, floor)
    } else {
        (6, 1e-9)
    };
    let solvers = r
        .runs
        .iter()
        .map(|run| match &run.result {
            Ok(t) => SolverSnapshot {
                solver: run.kind.name(),
                steady: t.metrics.map_or("none", |m| m.kind()).to_owned(),
                metrics: t
                    .metrics
                    .map(|m| {
                        m.values()
                            .into_iter()
                            .map(|(k, v)| (k, round_sig(v, digits, floor)))
                            .collect()
                    })
                    .unwrap_or_default(),
                counters: Counters::new(
                    t.stats,
                    matches!(t.metrics, Some(SteadyState::Equilibrium { .. })),
                ),
                error: None,
            },
            Err(e) => SolverSnapshot {
                solver: run.kind.name(),
                steady: "error".into(),
                metrics: BTreeMap::new(),
                counters: Counters::new(Stats::default(), false),
                error: Some(e.to_string()),
            },
        })
        .collect();
    ScenarioSnapshot {
        scenario: r.scenario.name.clone(),
        digits,
        floor,
        solvers,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_keeps_significant_digits_and_floors_small_values() {
        assert_eq!(round_sig(4.577757971, 5, 1e-9), 4.5778);
        assert_eq!(round_sig(-0.000123456789, 3, 1e-9), -0.000123);
        assert_eq!(round_sig(6.3361e-10, 5, 1e-9), 0.0);
        assert_eq!(round_sig(-3e-12, 5, 1e-9), 0.0);
        assert!(round_sig(-3e-12, 5, 1e-9).is_sign_positive());
        assert_eq!(round_sig(99999.7, 5, 1e-9), 100000.0);
        assert_eq!(format!("{}", round_sig(0.1 + 0.2, 5, 0.0)), "0.3");
    }

    #[test]
    fn counters_keep_three_significant_digits() {
        assert_eq!(round_count(0), 0);
        assert_eq!(round_count(999), 999);
        assert_eq!(round_count(1004), 1000);
        assert_eq!(round_count(1005), 1010);
        assert_eq!(round_count(4686628), 4690000);
    }
}
