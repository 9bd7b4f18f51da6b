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
        if count_mismatch {
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
    if let (Some(sa), Some(sb)) = (a.metrics, b.metrics)
        && let Some(rel) = tol.steady_rel
    {
        let floor = tol.steady_abs.unwrap_or(0.0);
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
