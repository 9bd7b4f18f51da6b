//! The fixtures' gate rule (CONTRIBUTING.md, "Gates and snapshots"), measured and enforced.
//!
//! Every `[tolerance.<pair>]` key of a fixture (the whole-run keys of [`crate::compare::whole`] too, in
//! rad, rad/s or s) is set to [`rule`] of what it measures on its scenario: [`MARGIN`] × the measurement, rounded up to one significant digit, at least the
//! rounding floor ([`RELATIVE_FLOOR`] for the relative steady metrics, [`ABSOLUTE_FLOOR`] s or
//! rad/s for the others), and 0 where the solvers agree exactly. A test
//! (`tests/fixtures.rs`) holds every gate to [`Margin::violation`]:
//!
//! * a measurement of exactly 0 demands a gate of exactly 0;
//! * otherwise `measured ≤ gate ≤ MAX_LOOSENESS × max(measured, floor)`
//!   ([`MAX_LOOSENESS`] = 10, the stress table's bound: the rule itself gives 5–10×);
//! * `steady_abs`, the absolute floor of the relative gates, is at most [`ABSOLUTE_FLOOR`].
//!
//! The measurement of a relative steady metric is `|a − b| / max(|a|, |b|)`, taken from the
//! two solvers' metrics: unlike the gate's own scaled difference ([`crate::compare::gate`]), it does not
//! depend on the gate through the `steady_abs` floor. A stuck disc's velocity that one solver
//! reports as 0 and the other holds inside its stuck band measures only what lies beyond the
//! band ([`beyond_stuck_band`]), as the gate does.

use rotor_model::scenario::{STEADY_QUANTITIES, Scenario};

use crate::compare::gate::{beyond_stuck_band, gate_scenario, stuck_band};
pub use crate::compare::stress::MAX_LOOSENESS;
use rotor_analysis::solvers::registry::{SolverKind, all_pairs, pair_name};
use rotor_analysis::solvers::run::ScenarioResult;

/// The rule's margin over the measured difference.
pub const MARGIN: f64 = 5.0;

/// Smallest gate of a relative steady metric: differences below it are rounding of the runs
/// (a few hundred ulps of O(1) values; [`crate::compare::snapshot::ROUNDING`]).
pub const RELATIVE_FLOOR: f64 = 1e-13;

/// Smallest gate in s or rad/s (transient, event times, stick time), and the largest
/// `steady_abs`: event times are located to ~1e-13 s, states of O(1–10) rad/s round to ~1e-15
/// per step ([`crate::compare::stress::OBSERVED_FLOOR`]).
pub const ABSOLUTE_FLOOR: f64 = 1e-12;

/// The gate the rule gives for `measured`: [`MARGIN`] × it rounded up to one significant
/// digit, at least `floor`; an exact 0 stays 0. Not finite for a measurement that is not.
pub fn rule(measured: f64, floor: f64) -> f64 {
    if measured == 0.0 {
        return 0.0;
    }
    let x = MARGIN * measured;
    let e = x.log10().floor();
    // 1e-9 below the digit: 5 × 2e-11 is 1e-10, not 2e-10, despite rounding.
    let g = (x / 10f64.powf(e) - 1e-9).ceil() * 10f64.powf(e);
    // Re-parse the one-digit decimal so that the value prints as written.
    let g: f64 = format!("{g:.0e}").parse().unwrap_or(g);
    g.max(floor)
}

/// One gate of one fixture beside what it measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Margin {
    /// The scenario's name.
    pub scenario: String,
    /// The solver pair (`event-switch`).
    pub pair: String,
    /// The scenario file's key; `None` for a check no key states (a steady kind that differs).
    pub key: Option<&'static str>,
    /// The quantity, as [`crate::compare::gate::Measured::quantity`] names it.
    pub quantity: String,
    /// Relative (the steady metrics but the stick time) or in s or rad/s.
    pub relative: bool,
    /// The measured difference, independent of the gate (see the module's documentation).
    pub measured: f64,
    /// The gate stated in the scenario file.
    pub gate: f64,
}

impl Margin {
    /// The rounding floor of this gate's unit.
    pub fn floor(&self) -> f64 {
        if self.relative {
            RELATIVE_FLOOR
        } else {
            ABSOLUTE_FLOOR
        }
    }

    /// What the rule gives for this measurement.
    pub fn rule(&self) -> f64 {
        rule(self.measured, self.floor())
    }

    /// The gate over the measurement (infinite for a non-zero gate over a measured 0).
    pub fn margin(&self) -> f64 {
        if self.measured > 0.0 {
            self.gate / self.measured
        } else if self.gate == 0.0 {
            1.0
        } else {
            f64::INFINITY
        }
    }

    /// Why the gate breaks the enforced rule, if it does: not measured, a measured 0 with a
    /// gate that is not 0, a gate below its measurement, or one above
    /// `MAX_LOOSENESS × max(measured, floor)`.
    pub fn violation(&self) -> Option<String> {
        let at = format!(
            "{} {} {} ({})",
            self.scenario,
            self.pair,
            self.key.unwrap_or("(no key)"),
            self.quantity
        );
        let (m, g) = (self.measured, self.gate);
        if self.key.is_none() || !m.is_finite() || g.is_nan() || g < 0.0 {
            return Some(format!("{at}: not measured ({m:e} against {g:e})"));
        }
        if m == 0.0 {
            return (g != 0.0).then(|| {
                format!("{at}: the solvers agree exactly, so the gate must be 0, not {g:e}")
            });
        }
        let widest = MAX_LOOSENESS * m.max(self.floor());
        // Neither is NaN from here on.
        if m > g {
            Some(format!(
                "{at}: gate {g:e} is narrower than the measured {m:.2e} (rule: {:e})",
                self.rule()
            ))
        } else if g > widest {
            Some(format!(
                "{at}: gate {g:e} is wider than {MAX_LOOSENESS} x max(measured {m:.2e}, floor {:e}) (rule: {:e})",
                self.floor(),
                self.rule()
            ))
        } else {
            None
        }
    }
}

/// Every gate of one scenario's results beside what it measures.
pub fn margins(r: &ScenarioResult) -> Vec<Margin> {
    let kinds: Vec<SolverKind> = r.runs.iter().map(|run| run.kind).collect();
    let gates = gate_scenario(r).0;
    let mut out = Vec::new();
    for (a, b) in all_pairs(&kinds) {
        let pair = pair_name(a, b);
        let (Some(g), Some(tol)) = (
            gates.iter().find(|g| g.pair == pair),
            r.scenario.tolerance.get(&pair),
        ) else {
            continue;
        };
        let band = stuck_band(a, b);
        let metrics = |k| r.traj(k).and_then(|t| t.rig_metrics()).map(|m| m.values());
        let (ma, mb) = (metrics(a), metrics(b));
        for m in &g.measured {
            let quantity = STEADY_QUANTITIES.iter().find(|q| Some(q.key) == m.key);
            let relative = quantity.is_some_and(|q| q.relative);
            let measured = match (quantity, &ma, &mb) {
                (Some(q), Some(ma), Some(mb)) if relative => {
                    let value = |v: &[(&str, f64)]| v.iter().find(|x| x.0 == q.metric).map(|x| x.1);
                    match (value(ma), value(mb)) {
                        (Some(va), Some(vb)) if va == vb => 0.0,
                        (Some(va), Some(vb)) => {
                            beyond_stuck_band(q.metric, va, vb, band) / va.abs().max(vb.abs())
                        }
                        _ => f64::NAN,
                    }
                }
                _ => m.diff,
            };
            out.push(Margin {
                scenario: r.scenario.name.clone(),
                pair: pair.clone(),
                key: m.key,
                quantity: m.quantity.clone(),
                relative,
                measured,
                gate: m.key.and_then(|k| tol.get(k)).unwrap_or(m.tol),
            });
        }
    }
    out
}

/// The `steady_abs` floors of a scenario above [`ABSOLUTE_FLOOR`]: a wider floor would let
/// every relative gate pass an absolute difference larger than rounding.
pub fn floor_violations(sc: &Scenario) -> Vec<String> {
    sc.tolerance
        .iter()
        .filter_map(|(pair, t)| {
            t.steady_abs.filter(|&f| f.is_nan() || f > ABSOLUTE_FLOOR).map(|f| {
                format!(
                    "{} {pair} steady_abs: {f:e} is above the rounding floor {ABSOLUTE_FLOOR:e}",
                    sc.name
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(relative: bool, measured: f64, gate: f64) -> Margin {
        Margin {
            scenario: "s".into(),
            pair: "a-b".into(),
            key: Some(if relative {
                "period_rel"
            } else {
                "transient_max"
            }),
            quantity: "q".into(),
            relative,
            measured,
            gate,
        }
    }

    #[test]
    fn the_rule_rounds_five_times_up_to_one_digit_above_the_floor() {
        assert_eq!(rule(0.0, 1e-13), 0.0);
        assert_eq!(rule(2.7e-12, 1e-13), 2e-11);
        assert_eq!(rule(2e-11, 1e-13), 1e-10);
        assert_eq!(rule(3.75e-8, 1e-13), 2e-7);
        assert_eq!(rule(6.74e-9, 1e-13), 4e-8);
        assert_eq!(rule(1e-16, 1e-13), 1e-13);
        assert_eq!(rule(1.15e-14, 1e-12), 1e-12);
        // The rule's own gates are within what the test enforces, 5-10x.
        for m in [1e-15, 1.0001e-12, 1.9999e-12, 2e-12, 3.3e-9, 9.99e-7] {
            for relative in [true, false] {
                let mut r = row(relative, m, 0.0);
                r.gate = r.rule();
                assert_eq!(r.violation(), None, "{r:?}");
            }
        }
    }

    /// Each way a gate can break the rule is caught, and only those.
    #[test]
    fn too_wide_too_narrow_and_non_zero_over_exact_are_violations() {
        assert_eq!(row(true, 2e-12, 1e-11).violation(), None);
        assert_eq!(row(true, 2e-12, 1.5e-11).violation(), None);
        assert_eq!(row(true, 0.0, 0.0).violation(), None);
        // Wider than 10x (gates once stated as 2e-11 over 3.05e-14 and 4e-8 over 7.42e-10).
        let e = row(true, 3.05e-14, 2e-11).violation().unwrap();
        assert!(e.contains("wider") && e.contains("period_rel"), "{e}");
        assert!(
            row(true, 7.42e-10, 4e-8)
                .violation()
                .unwrap()
                .contains("wider")
        );
        // Narrower than the measurement.
        let e = row(false, 3e-9, 2e-9).violation().unwrap();
        assert!(e.contains("narrower") && e.contains("transient_max"), "{e}");
        // Exact agreement with a gate that is not 0, and a gate of 0 over a difference.
        assert!(
            row(true, 0.0, 1e-13)
                .violation()
                .unwrap()
                .contains("must be 0")
        );
        assert!(
            row(true, 1e-15, 0.0)
                .violation()
                .unwrap()
                .contains("narrower")
        );
        // Below the floor, the floor counts: 10x the floor passes, 20x does not.
        assert_eq!(row(true, 1e-16, 1e-13).violation(), None);
        assert_eq!(row(false, 1e-15, 1e-12).violation(), None);
        assert!(
            row(true, 1e-16, 2e-12)
                .violation()
                .unwrap()
                .contains("wider")
        );
        assert!(
            row(false, 1e-15, 2e-11)
                .violation()
                .unwrap()
                .contains("wider")
        );
        // Not measured: fails, never passes as agreement.
        for m in [f64::NAN, f64::INFINITY] {
            assert!(
                row(true, m, 1.0)
                    .violation()
                    .unwrap()
                    .contains("not measured")
            );
        }
        let mut r = row(true, 1e-12, 1e-11);
        r.key = None;
        assert!(r.violation().unwrap().contains("not measured"));
    }
}
