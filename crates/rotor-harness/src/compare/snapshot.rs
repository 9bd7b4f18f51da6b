//! Snapshot records: per scenario and solver, the steady-state metrics rounded to the digits
//! that metric's agreement tolerance justifies, the solver's work counters, and each pair's
//! measured differences to one significant digit.
//!
//! **Metrics.** Each metric is rounded by the tightest tolerance stated for it among the pairs
//! the solver belongs to (the event-driven reference: both pairs; the others: their pair with
//! the reference): a relative tolerance `r` keeps `⌊−log10 r⌋` significant digits (at most
//! [`MAX_DIGITS`]), the absolute `stick_time` tolerance `a` keeps `⌊−log10 a⌋` decimals, and
//! values below the scenario's `steady_abs` floor are written as 0. A snapshot therefore moves
//! when a solver's answer moves by about its gate — also when all three move alike, which no
//! pair gate can see — and not with the last bits of another machine's arithmetic.
//!
//! **Differences.** Every gated quantity of every pair, to one significant digit: a change in
//! how well two solvers agree shows in review even while it stays inside the gate. A
//! difference below [`ROUNDING`] is written as 0: there it is floating-point rounding of the
//! runs, which another machine's `libm` changes.
//!
//! **Counters** are rounded to 3 significant digits: a last-bit change of the friction law
//! (measured: replacing libm's `tanh` by a one-`exp` form) moves step and evaluation counts
//! by up to 0.1 %, so 3 digits show any real change in the work a solver does (≥ 1 %) but
//! not another machine's `libm`. The event count is left out when the run settles on an
//! equilibrium: there the late extrema are round-off wiggles of amplitude ~1e-15 whose number
//! depends on the last bits (442 vs 301 on t1-u0.3-rest in that measurement).

use std::collections::BTreeMap;

use rotor_model::seam::{RigSteady, Stats};
use rotor_model::{Rounding, round_sig};
use serde::Serialize;

use rotor_analysis::solvers::run::ScenarioResult;

/// One solver's record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverSnapshot {
    /// The solver's name.
    pub solver: &'static str,
    /// `equilibrium`, `limit_cycle`, `none` (no steady state measured) or `error`.
    pub steady: String,
    /// Rounded metrics, by name (empty on error).
    pub metrics: BTreeMap<&'static str, f64>,
    /// Digits kept per metric: significant digits, or decimals for `stick_time`.
    pub digits: BTreeMap<&'static str, u32>,
    /// Its work counters, rounded to 3 significant digits.
    pub counters: Counters,
    /// The typed error, if the run failed.
    pub error: Option<String>,
}

/// The work counters a snapshot records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Counters {
    /// Accepted steps ([`Stats::steps`]).
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// `None` for a run that settles on an equilibrium (see the module docs).
    pub events: Option<u64>,
    /// One-step complementarity problems solved (Moreau–Jean).
    pub lcp_solves: u64,
    /// Steps whose complementarity solve was skipped (Moreau–Jean).
    pub lcp_skipped: u64,
}

/// Rounds a counter to 3 significant digits.
pub(crate) fn round_count(n: u64) -> u64 {
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
    /// The scenario's name.
    pub scenario: String,
    /// Metrics below this are written as 0 (the scenario's tightest `steady_abs`).
    pub floor: f64,
    /// One record per solver, the reference first.
    pub solvers: Vec<SolverSnapshot>,
    /// Per pair, every gated quantity's measured difference to one significant digit
    /// (written `4e-11`; `0` below [`ROUNDING`]).
    pub differences: BTreeMap<String, BTreeMap<String, String>>,
}

/// Most significant digits a metric keeps: independent runs that converge to the same
/// equilibrium agree to ~1e-14 relative (a few dozen ulps), so a 13th digit would change
/// with another machine's rounding.
pub const MAX_DIGITS: u32 = 12;

/// Differences below this are floating-point rounding of the runs (a few hundred ulps of
/// O(1) values, measured up to 5e-15 between two solvers on the same equilibrium).
pub const ROUNDING: f64 = 1e-13;

/// A difference to one significant digit, as `4e-11`; `0` below [`ROUNDING`].
pub(crate) fn one_digit(d: f64) -> String {
    if d.is_finite() && d < ROUNDING {
        "0".into()
    } else {
        format!("{:.0e}", d)
    }
}

/// Rounds `v` to `decimals` decimal places (never −0).
pub(crate) fn round_decimals(v: f64, decimals: u32) -> f64 {
    if !v.is_finite() {
        return v;
    }
    let s = format!("{:.*}", decimals as usize, v);
    let r: f64 = s.parse().unwrap_or(v);
    if r == 0.0 { 0.0 } else { r }
}

/// Digits a tolerance justifies: `⌊−log10 tol⌋`, at least 1, at most [`MAX_DIGITS`]
/// (a tolerance of 0, exact agreement, keeps the most).
pub(crate) fn digits_for(tol: f64) -> u32 {
    if tol > 0.0 {
        ((-tol.log10()).floor().max(1.0) as u32).min(MAX_DIGITS)
    } else {
        MAX_DIGITS
    }
}

/// The snapshot of one scenario's results (the differences from [`crate::compare::gate::gate_scenario`]).
pub fn snapshot(r: &ScenarioResult) -> ScenarioSnapshot {
    let sc = &r.scenario;
    let floor = sc
        .tolerance
        .values()
        .filter_map(|t| t.steady_abs)
        .fold(f64::INFINITY, f64::min);
    let floor = if floor.is_finite() { floor } else { 0.0 };
    let solvers = r
        .runs
        .iter()
        .map(|run| {
            // The tolerances of the pairs this solver is in.
            let tols: Vec<_> = sc
                .tolerance
                .iter()
                .filter(|(pair, _)| pair.split('-').any(|s| s == run.kind.name()))
                .map(|(_, t)| *t)
                .collect();
            match &run.result {
                Ok(t) => {
                    let mut metrics = BTreeMap::new();
                    let mut digits = BTreeMap::new();
                    for (name, v) in t.rig_metrics().map(|m| m.values()).unwrap_or_default() {
                        let tightest = tols
                            .iter()
                            .filter_map(|p| p.for_metric(name).and_then(|(_, t)| t))
                            .fold(f64::INFINITY, f64::min);
                        let relative = tols
                            .first()
                            .and_then(|p| p.for_metric(name))
                            .is_none_or(|(q, _)| q.relative);
                        let d = digits_for(tightest);
                        let rounded = if relative {
                            round_sig(v, d, Rounding::Decimal { floor })
                        } else {
                            round_decimals(v, d)
                        };
                        metrics.insert(name, rounded);
                        digits.insert(name, d);
                    }
                    SolverSnapshot {
                        solver: run.kind.name(),
                        steady: t
                            .rig_metrics()
                            .map_or("none", |m| m.kind().as_str())
                            .to_owned(),
                        metrics,
                        digits,
                        counters: Counters::new(
                            t.stats,
                            matches!(t.rig_metrics(), Some(RigSteady::Equilibrium { .. })),
                        ),
                        error: None,
                    }
                }
                Err(e) => SolverSnapshot {
                    solver: run.kind.name(),
                    steady: "error".into(),
                    metrics: BTreeMap::new(),
                    digits: BTreeMap::new(),
                    counters: Counters::new(Stats::default(), false),
                    error: Some(e.to_string()),
                },
            }
        })
        .collect();
    let differences = crate::compare::gate::gate_scenario(r)
        .0
        .into_iter()
        .map(|g| {
            let q = g
                .measured
                .iter()
                .map(|m| (m.quantity.clone(), one_digit(m.diff)))
                .collect();
            (g.pair, q)
        })
        .collect();
    ScenarioSnapshot {
        scenario: sc.name.clone(),
        floor,
        solvers,
        differences,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn differences_keep_one_digit_and_drop_rounding() {
        assert_eq!(one_digit(3.22e-11), "3e-11");
        assert_eq!(one_digit(5.59e-9), "6e-9");
        assert_eq!(one_digit(5.4e-15), "0");
        assert_eq!(one_digit(0.0), "0");
        assert_eq!(one_digit(f64::INFINITY), "inf");
        assert_eq!(one_digit(f64::NAN), "NaN");
    }

    #[test]
    fn decimals_and_digits_from_tolerances() {
        assert_eq!(round_decimals(0.870771234, 7), 0.8707712);
        assert_eq!(round_decimals(-1e-12, 7), 0.0);
        assert!(round_decimals(-1e-12, 7).is_sign_positive());
        assert_eq!(digits_for(2e-10), 9);
        assert_eq!(digits_for(1e-6), 6);
        assert_eq!(digits_for(0.5), 1);
        assert_eq!(digits_for(1e-20), MAX_DIGITS);
        assert_eq!(digits_for(0.0), MAX_DIGITS);
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
