//! Agreement gates between two solvers' results on one scenario.
//!
//! (a) the transient window, sample by sample on the common grid: max and RMS of the
//! difference in ω_u and ω_l; (b) the steady state: kind, and every metric within
//! `steady_rel` relative (with `steady_abs` as a floor); (c) events: lower-disc stick
//! onsets and exits in the transient window matched one to one within `event_time`.
//! Every comparison is written `!(diff <= tol)` so that a NaN fails.

use rotor_model::{Disc, EventKind, PairTolerance, SteadyState, Trajectory};

/// A measured difference with its gate.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Measured {
    pub quantity: String,
    pub diff: f64,
    pub tol: f64,
}

impl Measured {
    pub fn passes(&self) -> bool {
        self.diff <= self.tol
    }
}

/// A failed gate: which quantity, the measured difference and the tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub scenario: String,
    pub pair: String,
    pub quantity: String,
    pub diff: f64,
    pub tol: f64,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {}: {} differs by {:.3e} > tolerance {:.3e}",
            self.scenario, self.pair, self.quantity, self.diff, self.tol
        )
    }
}

/// All measurements of one pair on one scenario.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GateResult {
    pub pair: String,
    pub measured: Vec<Measured>,
}

impl GateResult {
    pub fn failures(&self, scenario: &str) -> Vec<Failure> {
        self.measured
            .iter()
            .filter(|m| !m.passes())
            .map(|m| Failure {
                scenario: scenario.to_owned(),
                pair: self.pair.clone(),
                quantity: m.quantity.clone(),
                diff: m.diff,
                tol: m.tol,
            })
            .collect()
    }
}

/// Compares two trajectories of the same scenario under a pair's tolerances.
/// `transient` is the sample-by-sample window; quantities without a tolerance are skipped.
pub fn check_pair(
    pair: &str,
    a: &Trajectory,
    b: &Trajectory,
    transient: Option<[f64; 2]>,
    tol: &PairTolerance,
) -> GateResult {
    let mut m = Vec::new();
    if let Some([t0, t1]) = transient {
        let mut max: f64 = 0.0;
        let mut sq = 0.0;
        let mut n = 0usize;
        let mut count_mismatch = a.samples.len() != b.samples.len();
        for (sa, sb) in a.samples.iter().zip(&b.samples) {
            if sa.t != sb.t {
                count_mismatch = true;
                break;
            }
            if sa.t < t0 || sa.t > t1 {
                continue;
            }
            for i in [1, 2] {
                let d = (sa.x[i] - sb.x[i]).abs();
                // NaN propagates into max through this form.
                max = if d > max || d.is_nan() { d } else { max };
                sq += d * d;
                n += 1;
            }
        }
        // No sample in the window (or grids that differ): nothing was compared, which must
        // not read as agreement.
        if count_mismatch || n == 0 {
            max = f64::NAN;
        }
        let rms = if n > 0 {
            (sq / n as f64).sqrt()
        } else {
            f64::NAN
        };
        if let Some(t) = tol.transient_max {
            m.push(Measured {
                quantity: "transient max abs d_omega".into(),
                diff: max,
                tol: t,
            });
        }
        if let Some(t) = tol.transient_rms {
            m.push(Measured {
                quantity: "transient rms d_omega".into(),
                diff: rms,
                tol: t,
            });
        }
        if let Some(t) = tol.event_time {
            let pick = |tr: &Trajectory| -> Vec<(f64, EventKind)> {
                tr.events
                    .iter()
                    .filter(|e| {
                        e.t >= t0
                            && e.t <= t1
                            && matches!(
                                e.kind,
                                EventKind::StickStart(Disc::Lower)
                                    | EventKind::StickEnd(Disc::Lower)
                            )
                    })
                    .map(|e| (e.t, e.kind))
                    .collect()
            };
            let (ea, eb) = (pick(a), pick(b));
            let diff = if ea.len() != eb.len() || ea.iter().zip(&eb).any(|(x, y)| x.1 != y.1) {
                f64::INFINITY
            } else {
                ea.iter()
                    .zip(&eb)
                    .map(|(x, y)| (x.0 - y.0).abs())
                    .fold(0.0, f64::max)
            };
            m.push(Measured {
                quantity: format!("stick event times ({} vs {} events)", ea.len(), eb.len()),
                diff,
                tol: t,
            });
        }
    }
    if let Some(rel) = tol.steady_rel {
        let floor = tol.steady_abs.unwrap_or(0.0);
        let (Some(sa), Some(sb)) = (a.metrics, b.metrics) else {
            // A gated steady state that a solver did not deliver fails the gate.
            let which = |tr: &Trajectory| if tr.metrics.is_some() { "yes" } else { "none" };
            m.push(Measured {
                quantity: format!("steady metrics ({} vs {})", which(a), which(b)),
                diff: f64::NAN,
                tol: rel,
            });
            return GateResult {
                pair: pair.to_owned(),
                measured: m,
            };
        };
        if sa.kind() != sb.kind() {
            m.push(Measured {
                quantity: format!("steady kind ({} vs {})", sa.kind(), sb.kind()),
                diff: f64::INFINITY,
                tol: 0.0,
            });
        } else {
            for ((name, va), (_, vb)) in sa.values().into_iter().zip(sb.values()) {
                // Scaled so that `diff ≤ rel` ⇔ |va − vb| ≤ max(rel·max(|va|,|vb|), floor).
                let scale = (va.abs().max(vb.abs()) * rel).max(floor);
                let diff = if scale > 0.0 {
                    (va - vb).abs() / scale * rel
                } else {
                    (va - vb).abs()
                };
                m.push(Measured {
                    quantity: format!("steady {name}"),
                    diff,
                    tol: rel,
                });
            }
        }
    }
    GateResult {
        pair: pair.to_owned(),
        measured: m,
    }
}

/// The steady metrics of a trajectory, if computed.
pub fn metrics(tr: &Trajectory) -> Option<SteadyState> {
    tr.metrics
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::{DiscMode, Mode, Sample, State, Stats};

    /// A trajectory with samples every 0.01 s on [0, 1] and the given metrics.
    fn traj(metrics: Option<SteadyState>) -> Trajectory {
        let samples = (0..=100)
            .map(|k| {
                let t = k as f64 * 0.01;
                Sample {
                    t,
                    x: State::new(0.0, 1.0, t.sin()),
                }
            })
            .collect();
        Trajectory {
            samples,
            events: Vec::new(),
            t_final: 1.0,
            x_final: State::zeros(),
            mode_final: Mode {
                upper: DiscMode::SlipPos,
                lower: DiscMode::SlipPos,
            },
            metrics,
            stats: Stats::default(),
        }
    }

    const EQ: SteadyState = SteadyState::Equilibrium {
        omega_u: 1.0,
        omega_l: 1.0,
        alpha: 0.1,
    };

    /// Gates for synthetic data: identical inputs differ by exactly 0, the perturbation below
    /// is 1e-6, so any gate between the two tells them apart; 1e-9 is one.
    fn tol() -> PairTolerance {
        PairTolerance {
            transient_max: Some(1e-9),
            steady_rel: Some(1e-9),
            ..PairTolerance::default()
        }
    }

    #[test]
    fn identical_results_pass_and_a_difference_fails() {
        let a = traj(Some(EQ));
        let g = check_pair("p", &a, &a, Some([0.0, 1.0]), &tol());
        // Both the window and the metrics were measured, and passed.
        assert_eq!(g.measured.len(), 1 + EQ.values().len());
        assert!(g.failures("s").is_empty());
        let mut b = a.clone();
        b.samples[50].x[2] += 1e-6;
        let f = check_pair("p", &a, &b, Some([0.0, 1.0]), &tol()).failures("s");
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].quantity.contains("transient max"));
    }

    #[test]
    fn a_window_without_samples_fails_rather_than_passing_empty() {
        let a = traj(Some(EQ));
        // Between grid points 0.50 and 0.51: no sample to compare.
        let f = check_pair("p", &a, &a, Some([0.501, 0.509]), &tol()).failures("s");
        assert!(
            f.iter().any(|f| f.quantity.contains("transient max")),
            "{f:?}"
        );
    }

    #[test]
    fn gated_metrics_missing_on_one_side_fail() {
        let (a, b) = (traj(Some(EQ)), traj(None));
        for (x, y) in [(&a, &b), (&b, &a), (&b, &b)] {
            let f = check_pair("p", x, y, None, &tol()).failures("s");
            assert!(
                f.len() == 1 && f[0].quantity.contains("steady metrics"),
                "{f:?}"
            );
        }
    }
}
