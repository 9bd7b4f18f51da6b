//! Agreement gates between two solvers' results on one scenario.
//!
//! (a) the transient window, sample by sample on the common grid: max and RMS of the
//! difference in ω_u and ω_l; (b) the steady state: kind, and each metric within its own
//! tolerance, one key per metric (period, each extreme of ω_l and ω_u, and each of the
//! equilibrium's ω_u, ω_l and α relative with `steady_abs` as a floor, a stuck disc's
//! velocity beyond the solvers' stuck bands only, the stick time in seconds); (c) events: lower-disc stick onsets and exits in
//! the transient window matched one to one within `event_time`; (d) the whole run
//! ([`crate::compare::whole`]): every mode switch and ω_l maximum over `[0, t_end]` matched one to one
//! within `whole_event_time`, and every sample of α, ω_u and ω_l, phase-aligned by the matched
//! events, within `whole_alpha`, `whole_omega_u` and `whole_omega_l`. (d) is measured for
//! every pair of solvers (`switch-moreau` too: [`rotor_analysis::solvers::all_pairs`]), (a)–(c) for the
//! reference's pairs.
//! Every comparison is written `!(diff <= tol)` so that a NaN fails.

use rotor_model::Disc;
use rotor_model::scenario::PairTolerance;
use rotor_model::seam::{EventKind, RigSteady, Trajectory};

use rotor_analysis::solvers::registry::{SolverKind, all_pairs, pair_name, pairs};
use rotor_analysis::solvers::run::ScenarioResult;
use rotor_model::Model;

use crate::compare::whole::whole_run;

/// A measured difference with its gate.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Measured {
    /// What was compared, as the report names it (`transient max abs d_omega`,
    /// `steady period`, `steady kind (limit_cycle vs equilibrium)`, ...).
    pub quantity: String,
    /// The scenario file's key that states `tol` (`tolerance.<pair>.<key>`); `None` for the
    /// checks that no key states (steady states of different kinds, or missing).
    pub key: Option<&'static str>,
    /// The difference: rad/s for the transient, s for event and stick times, relative for
    /// the relative steady metrics; NaN or ∞ where nothing could be compared.
    pub diff: f64,
    /// Its tolerance, in the same unit.
    pub tol: f64,
}

impl Measured {
    /// Whether `diff ≤ tol` (false for a NaN difference).
    pub fn passes(&self) -> bool {
        self.diff <= self.tol
    }
}

/// A failed gate: which quantity, the measured difference and the tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// The scenario's name.
    pub scenario: String,
    /// The solver pair (`event-switch`).
    pub pair: String,
    /// The quantity ([`Measured::quantity`]), or what went wrong when nothing was measured.
    pub quantity: String,
    /// The measured difference; not finite when nothing could be measured.
    pub diff: f64,
    /// The tolerance it exceeds.
    pub tol: f64,
}

impl std::fmt::Display for Failure {
    /// A measured difference over its tolerance, or, where nothing could be measured (a run
    /// that failed, steady states of different kinds: `diff` not finite), what went wrong.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.diff.is_finite() {
            write!(
                f,
                "{}: {}: {} differs by {:.3e} > tolerance {:.3e}",
                self.scenario, self.pair, self.quantity, self.diff, self.tol
            )
        } else {
            write!(f, "{}: {}: {}", self.scenario, self.pair, self.quantity)
        }
    }
}

/// All measurements of one pair on one scenario.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GateResult {
    /// The solver pair (`event-switch`).
    pub pair: String,
    /// Every quantity gated, passing or not.
    pub measured: Vec<Measured>,
    /// Whether the tolerances are defaults derived from the two solvers' own errors on this
    /// scene ([`derived_tolerance`]), the scenario file stating none for this pair.
    pub derived: bool,
}

impl GateResult {
    /// The measurements that fail, as failures of `scenario`.
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
/// `stuck_band` is the sum of the two solvers' [`SolverInfo::stuck_band`]s
/// ([`steady_differences`]).
///
/// [`SolverInfo::stuck_band`]: rotor_analysis::solvers::SolverInfo::stuck_band
pub fn check_pair(
    pair: &str,
    a: &Trajectory,
    b: &Trajectory,
    transient: Option<[f64; 2]>,
    tol: &PairTolerance,
    stuck_band: f64,
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
                key: Some("transient_max"),
                diff: max,
                tol: t,
            });
        }
        if let Some(t) = tol.transient_rms {
            m.push(Measured {
                quantity: "transient rms d_omega".into(),
                key: Some("transient_rms"),
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
                                EventKind::StickStart(Disc::LOWER)
                                    | EventKind::StickEnd(Disc::LOWER)
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
                key: Some("event_time"),
                diff,
                tol: t,
            });
        }
    }
    if tol.gates_steady() {
        let floor = tol.steady_abs.unwrap_or(0.0);
        let (Some(sa), Some(sb)) = (a.rig_metrics(), b.rig_metrics()) else {
            // A gated steady state that a solver did not deliver fails the gate.
            let which = |tr: &Trajectory| {
                if tr.rig_metrics().is_some() {
                    "yes"
                } else {
                    "none"
                }
            };
            m.push(Measured {
                quantity: format!("steady metrics ({} vs {})", which(a), which(b)),
                key: None,
                diff: f64::NAN,
                tol: 0.0,
            });
            return GateResult {
                pair: pair.to_owned(),
                measured: m,
                derived: false,
            };
        };
        if sa.kind() != sb.kind() {
            m.push(Measured {
                quantity: format!("steady kind ({} vs {})", sa.kind(), sb.kind()),
                key: None,
                diff: f64::INFINITY,
                tol: 0.0,
            });
        } else {
            m.extend(steady_differences(&sa, &sb, tol, floor, stuck_band));
        }
    }
    GateResult {
        pair: pair.to_owned(),
        measured: m,
        derived: false,
    }
}

/// The whole-run gates of a pair ([`crate::compare::whole`]): the matched events' times and the
/// phase-aligned samples of α, ω_u and ω_l over `[0, t_end]`, each against its key. A key
/// that the table does not state is measured against 0 and fails: every pair must gate the
/// whole run.
pub fn check_whole(
    model: &Model,
    u: f64,
    a: &Trajectory,
    b: &Trajectory,
    tol: &PairTolerance,
    stuck_band: f64,
) -> Vec<Measured> {
    let w = whole_run(model, u, a, b, stuck_band);
    let events = if w.event_time.is_finite() {
        format!("whole event times ({} matched)", w.events)
    } else {
        "whole event times (sequences differ)".to_owned()
    };
    [
        (
            "whole alpha (phase-aligned)".to_owned(),
            "whole_alpha",
            w.aligned[0],
        ),
        (
            "whole omega_u (phase-aligned)".to_owned(),
            "whole_omega_u",
            w.aligned[1],
        ),
        (
            "whole omega_l (phase-aligned)".to_owned(),
            "whole_omega_l",
            w.aligned[2],
        ),
        (events, "whole_event_time", w.event_time),
    ]
    .into_iter()
    .map(|(quantity, key, diff)| match tol.get(key) {
        Some(t) => Measured {
            quantity,
            key: Some(key),
            diff,
            tol: t,
        },
        None => Measured {
            quantity: format!("{quantity} (no {key} stated)"),
            key: Some(key),
            diff: f64::INFINITY,
            tol: 0.0,
        },
    })
    .collect()
}

/// The steady metrics of two results of the same kind, each against its own tolerance
/// ([`PairTolerance::for_metric`]). A relative difference is scaled so that `diff ≤ tol` ⇔
/// `|va − vb| ≤ max(tol·max(|va|, |vb|), floor)`; `stick_time` is absolute. A metric whose
/// tolerance the file does not state is measured against 0 and fails: the file must gate
/// every metric of the steady state it reaches.
///
/// A disc at rest at an equilibrium: where one solver reports its velocity (`omega_u`,
/// `omega_l`) as 0 exactly and the other within `stuck_band` of 0 (the two solvers'
/// [`SolverInfo::stuck_band`]s summed: the switch model holds a stuck disc at the velocity it
/// entered its band with, |ω| ≤ η), only the part of the difference beyond the band counts
/// ([`beyond_stuck_band`]). Relative to a value that is 0 by construction, the band itself
/// would read as a difference of 100 %, which no gate could tell from a real one.
///
/// [`SolverInfo::stuck_band`]: rotor_analysis::solvers::SolverInfo::stuck_band
pub fn steady_differences(
    sa: &RigSteady,
    sb: &RigSteady,
    tol: &PairTolerance,
    floor: f64,
    stuck_band: f64,
) -> Vec<Measured> {
    sa.values()
        .into_iter()
        .zip(sb.values())
        .map(|((name, va), (_, vb))| {
            let (q, t) = tol
                .for_metric(name)
                .expect("every metric of RigSteady::values has a quantity");
            let t = t.unwrap_or(0.0);
            let d = beyond_stuck_band(name, va, vb, stuck_band);
            let diff = if !q.relative {
                d
            } else {
                let scale = va
                    .abs()
                    .max(vb.abs())
                    .max(if t > 0.0 { floor / t } else { 0.0 });
                if scale > 0.0 { d / scale } else { d }
            };
            let missing = if tol.get(q.key).is_none() {
                format!(" (no {} stated)", q.key)
            } else {
                String::new()
            };
            Measured {
                quantity: format!("steady {name}{missing}"),
                key: Some(q.key),
                diff: if missing.is_empty() {
                    diff
                } else {
                    f64::INFINITY
                },
                tol: t,
            }
        })
        .collect()
}

/// The band within which a pair's stuck velocities are no difference: the sum of the two
/// solvers' [`SolverInfo::stuck_band`]s (see [`steady_differences`]).
///
/// [`SolverInfo::stuck_band`]: rotor_analysis::solvers::SolverInfo::stuck_band
pub fn stuck_band(a: SolverKind, b: SolverKind) -> f64 {
    a.info().stuck_band + b.info().stuck_band
}

/// `|va − vb|`, less `stuck_band` (not below 0) where `name` is an equilibrium's disc
/// velocity (`omega_u`, `omega_l`) that one of the two reports as 0 exactly: a stuck disc
/// that the other solver holds inside its band (see [`steady_differences`]). A NaN stays NaN.
pub fn beyond_stuck_band(name: &str, va: f64, vb: f64, stuck_band: f64) -> f64 {
    let d = (va - vb).abs();
    let stuck = matches!(name, "omega_u" | "omega_l") && (va == 0.0 || vb == 0.0);
    if stuck && d <= stuck_band {
        0.0
    } else if stuck {
        d - stuck_band
    } else {
        d
    }
}

/// The steady metrics of a trajectory, if computed.
pub fn metrics(tr: &Trajectory) -> Option<RigSteady> {
    tr.rig_metrics()
}

/// Gates every pair of one scenario. A solver error is a failure too. A pair without a
/// `[tolerance]` table in the scenario file (a scene the project never measured) is gated by
/// defaults derived from the two solvers' own errors on it ([`derived_tolerance`]); where
/// none can be derived, that is a failure.
pub fn gate_scenario(r: &ScenarioResult) -> (Vec<GateResult>, Vec<Failure>) {
    let sc = &r.scenario;
    let mut gates = Vec::new();
    let mut fails = Vec::new();
    for run in &r.runs {
        if let Err(e) = &run.result {
            fails.push(Failure {
                scenario: sc.name.clone(),
                pair: run.kind.name().into(),
                quantity: format!("run failed: {e}"),
                diff: f64::INFINITY,
                tol: 0.0,
            });
        }
    }
    let kinds: Vec<SolverKind> = r.runs.iter().map(|run| run.kind).collect();
    let reference = pairs(&kinds);
    for (a, b) in all_pairs(&kinds) {
        let pair = pair_name(a, b);
        let (Some(ta), Some(tb)) = (r.traj(a), r.traj(b)) else {
            continue;
        };
        let windows = reference.contains(&(a, b));
        let (tol, derived) = match sc.tolerance.get(&pair) {
            Some(tol) => (*tol, false),
            None => match derived_tolerance(r, a, b, windows) {
                Ok(tol) => (tol, true),
                Err(why) => {
                    fails.push(Failure {
                        scenario: sc.name.clone(),
                        pair: pair.clone(),
                        quantity: format!(
                            "no [tolerance] stated for this pair in the scenario file, and \
                             none derived: {why}"
                        ),
                        diff: f64::INFINITY,
                        tol: 0.0,
                    });
                    continue;
                }
            },
        };
        let band = stuck_band(a, b);
        let mut g = if windows {
            check_pair(&pair, ta, tb, sc.compare.transient, &tol, band)
        } else {
            GateResult {
                pair: pair.clone(),
                measured: Vec::new(),
                derived,
            }
        };
        g.derived = derived;
        g.measured
            .extend(check_whole(&sc.model, sc.u, ta, tb, &tol, band));
        fails.extend(g.failures(&sc.name));
        gates.push(g);
    }
    (gates, fails)
}

/// The rounding floor of a derived gate: 1e-13 for a relative quantity, 1e-12 s, rad or
/// rad/s for an absolute one (the floors of the suite's stated gates).
fn rounding_floor(key: &str) -> f64 {
    if key.ends_with("_rel") { 1e-13 } else { 1e-12 }
}

/// Every quantity a pair can gate on this scenario, each with an infinite tolerance: what a
/// solver's run is measured against its own tighter run on. The transient keys where the
/// file sets `compare.transient`, the steady keys where it sets `compare.steady_from`, the
/// whole-run keys always.
fn measure_everything(sc: &rotor_model::scenario::Scenario, windows: bool) -> PairTolerance {
    use rotor_model::scenario::{CYCLE_KEYS, EQUILIBRIUM_KEYS, WHOLE_KEYS};
    let mut all = PairTolerance::default();
    let mut keys: Vec<&str> = WHOLE_KEYS.to_vec();
    if windows && sc.compare.transient.is_some() {
        keys.extend(["transient_max", "transient_rms", "event_time"]);
    }
    if windows && sc.compare.steady_from.is_some() {
        keys.extend(CYCLE_KEYS);
        keys.extend(EQUILIBRIUM_KEYS);
    }
    for k in keys {
        if let Some(slot) = all.slot(k) {
            *slot = Some(f64::INFINITY);
        }
    }
    all
}

/// Default gates for a pair `(a, b)` that the scenario file does not state, derived from the
/// two solvers' own errors on this scene: each solver also ran at its tighter settings
/// ([`rotor_analysis::solvers::tighter_settings`]: tolerance/100; step/2 and step/4), and its
/// own error in a quantity is [`rotor_analysis::solvers::self_error`] of that quantity
/// measured between its successive runs (the difference for a tolerance; for a step the
/// larger of twice the first and four times the second). The gate of each quantity is
///
/// ```text
/// 2·(e_a + e_b) + floor + band
/// ```
///
/// twice the sum of the two errors (the rule of the chain cross-validation), the rounding
/// floor (1e-13 relative, 1e-12 absolute), and, for a solver that holds a stuck disc within a band η
/// (the switch model), what the band moves that a tighter tolerance does not: the spring
/// drifts by η per second of stick, so `(η_a + η_b)·max(1, t_end)` on an absolute quantity
/// and `10·(η_a + η_b)` on a relative one (its steady metrics differ from the exact solution
/// by at most 4η relative; `rotor_switch::SwitchOptions::eta`). `steady_abs` is the rounding
/// floor, 1e-12. A solver whose two runs cannot be compared in some quantity (a failed run,
/// different steady kinds, event sequences that differ) leaves no gate to derive: the error
/// says which.
pub fn derived_tolerance(
    r: &ScenarioResult,
    a: SolverKind,
    b: SolverKind,
    windows: bool,
) -> Result<PairTolerance, String> {
    let sc = &r.scenario;
    let all = measure_everything(sc, windows);
    // The events the pair matches over the whole run; each solver's own runs must match as
    // many, or its own error in their times says nothing of some of them (maxima of ω_l on a
    // decaying oscillation, which runs at two settings resolve in different numbers).
    let (Some(ta), Some(tb)) = (r.traj(a), r.traj(b)) else {
        return Err("a run did not finish".into());
    };
    let pair_events = whole_run(&sc.model, sc.u, ta, tb, stuck_band(a, b)).events;
    let own = |k: SolverKind| -> Result<Vec<(&'static str, f64)>, String> {
        let run = r
            .traj(k)
            .ok_or_else(|| format!("{} did not finish", k.name()))?;
        let tight: Vec<&Trajectory> = r
            .tight_runs(k)
            .into_iter()
            .map(|t| t.result.as_ref().ok())
            .collect::<Option<_>>()
            .filter(|v: &Vec<&Trajectory>| !v.is_empty())
            .ok_or_else(|| format!("{} did not finish at its tighter settings", k.name()))?;
        let band = k.info().stuck_band * 2.0;
        // The quantities between each run and the next tighter one.
        let mut steps: Vec<Vec<crate::compare::gate::Measured>> = Vec::new();
        let mut prev = run;
        for t in tight {
            let own_events = whole_run(&sc.model, sc.u, prev, t, band).events;
            if own_events < pair_events {
                return Err(format!(
                    "{}'s own runs match {own_events} of the {pair_events} events the pair \
                     matches (maxima of ω_l its settings resolve differently), so its error \
                     in their times is not estimated: state the pair's tolerances",
                    k.name()
                ));
            }
            let mut m = check_pair("", prev, t, sc.compare.transient, &all, band).measured;
            m.extend(check_whole(&sc.model, sc.u, prev, t, &all, band));
            steps.push(m);
            prev = t;
        }
        steps[0]
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let diffs: Vec<f64> = steps.iter().map(|m| m[i].diff).collect();
                match q.key {
                    Some(key) if diffs.iter().all(|d| d.is_finite()) => {
                        Ok((key, rotor_analysis::solvers::self_error(k, &diffs)))
                    }
                    _ => Err(format!(
                        "{}'s own runs at its setting and tighter ones differ in {}",
                        k.name(),
                        q.quantity
                    )),
                }
            })
            .collect()
    };
    let (ea, eb) = (own(a)?, own(b)?);
    let eta = a.info().stuck_band + b.info().stuck_band;
    let mut tol = PairTolerance::default();
    for (key, e) in &ea {
        let Some(&(_, f)) = eb.iter().find(|(k, _)| k == key) else {
            return Err(format!(
                "{} measures {key} and {} does not (their steady states differ in kind)",
                a.name(),
                b.name()
            ));
        };
        let band = if key.ends_with("_rel") {
            10.0 * eta
        } else {
            eta * sc.t_end.max(1.0)
        };
        if let Some(slot) = tol.slot(key) {
            *slot = Some(2.0 * (e + f) + rounding_floor(key) + band);
        }
    }
    if tol.gates_steady() {
        tol.steady_abs = Some(1e-12);
    }
    Ok(tol)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::seam::{Sample, Stats};
    use rotor_model::{DiscMode, Mode, State};

    /// A trajectory with samples every 0.01 s on [0, 1] and the given metrics.
    fn traj(metrics: Option<RigSteady>) -> Trajectory {
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
            x_final: (State::zeros()).as_slice().to_vec(),
            mode_final: Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos),
            metrics: metrics.map(Into::into),
            stats: Stats::default(),
        }
    }

    const EQ: RigSteady = RigSteady::Equilibrium {
        omega_u: 1.0,
        omega_l: 1.0,
        alpha: 0.1,
    };

    /// Gates for synthetic data: identical inputs differ by exactly 0, the perturbation below
    /// is 1e-6, so any gate between the two tells them apart; 1e-9 is one.
    fn tol() -> PairTolerance {
        PairTolerance {
            transient_max: Some(1e-9),
            equilibrium_omega_u_rel: Some(1e-9),
            equilibrium_omega_l_rel: Some(1e-9),
            equilibrium_alpha_rel: Some(1e-9),
            ..PairTolerance::default()
        }
    }

    #[test]
    fn identical_results_pass_and_a_difference_fails() {
        let a = traj(Some(EQ));
        let g = check_pair("p", &a, &a, Some([0.0, 1.0]), &tol(), 0.0);
        // Both the window and the metrics were measured, and passed.
        assert_eq!(g.measured.len(), 1 + EQ.values().len());
        assert!(g.failures("s").is_empty());
        let mut b = a.clone();
        b.samples.x_mut(50)[2] += 1e-6;
        let f = check_pair("p", &a, &b, Some([0.0, 1.0]), &tol(), 0.0).failures("s");
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(f[0].quantity.contains("transient max"));
    }

    #[test]
    fn a_window_without_samples_fails_rather_than_passing_empty() {
        let a = traj(Some(EQ));
        // Between grid points 0.50 and 0.51: no sample to compare.
        let f = check_pair("p", &a, &a, Some([0.501, 0.509]), &tol(), 0.0).failures("s");
        assert!(
            f.iter().any(|f| f.quantity.contains("transient max")),
            "{f:?}"
        );
    }

    const CYCLE: RigSteady = RigSteady::LimitCycle {
        period: 4.5,
        omega_l_max: 6.3,
        omega_l_min: 0.0,
        omega_u_max: 2.7,
        omega_u_min: 2.5,
        stick_time: 0.87,
    };

    /// Each steady metric is gated by its own tolerance: a shift of twice a metric's gate
    /// fails exactly that metric, a shift of half of it passes, and a metric whose kind has
    /// no tolerance in the file fails.
    #[test]
    fn each_steady_metric_has_its_own_gate() {
        let tol = PairTolerance {
            period_rel: Some(1e-10),
            omega_l_max_rel: Some(1e-9),
            omega_l_min: Some(3e-9),
            omega_u_max_rel: Some(1e-11),
            omega_u_min_rel: Some(3e-11),
            stick_time: Some(1e-8),
            steady_abs: Some(1e-12),
            ..PairTolerance::default()
        };
        let a = traj(Some(CYCLE));
        assert!(
            check_pair("p", &a, &a, None, &tol, 0.0)
                .failures("s")
                .is_empty()
        );
        type Shift = fn(&mut RigSteady, f64);
        let shifts: [(&str, Shift, f64); 6] = [
            (
                "period",
                |m, f| {
                    if let RigSteady::LimitCycle { period, .. } = m {
                        *period *= 1.0 + f
                    }
                },
                1e-10,
            ),
            (
                "omega_l_max",
                |m, f| {
                    if let RigSteady::LimitCycle { omega_l_max, .. } = m {
                        *omega_l_max *= 1.0 + f
                    }
                },
                1e-9,
            ),
            (
                "omega_l_min",
                |m, f| {
                    if let RigSteady::LimitCycle { omega_l_min, .. } = m {
                        *omega_l_min += f
                    }
                },
                3e-9,
            ),
            (
                "omega_u_max",
                |m, f| {
                    if let RigSteady::LimitCycle { omega_u_max, .. } = m {
                        *omega_u_max *= 1.0 + f
                    }
                },
                1e-11,
            ),
            // Its own gate, 3x omega_u_max's: 1.5e-11 passes here and would fail there.
            (
                "omega_u_min",
                |m, f| {
                    if let RigSteady::LimitCycle { omega_u_min, .. } = m {
                        *omega_u_min *= 1.0 + f
                    }
                },
                3e-11,
            ),
            (
                "stick_time",
                |m, f| {
                    if let RigSteady::LimitCycle { stick_time, .. } = m {
                        *stick_time += f
                    }
                },
                1e-8,
            ),
        ];
        for (name, shift, gate) in shifts {
            for (factor, fails) in [(2.0, true), (0.5, false)] {
                let mut b = a.clone();
                let mut m = b.rig_metrics().unwrap();
                shift(&mut m, factor * gate);
                b.metrics = Some(m.into());
                let f = check_pair("p", &a, &b, None, &tol, 0.0).failures("s");
                // ω_l's minimum is gated absolutely (rad/s) by its own 3e-9, not through
                // the relative gates' floor: 6e-9 fails and 1.5e-9 passes.
                assert_eq!(!f.is_empty(), fails, "{name} x{factor}: {f:?}");
                if fails {
                    assert!(
                        f.len() == 1 && f[0].quantity == format!("steady {name}"),
                        "{f:?}"
                    );
                }
            }
        }
        // An equilibrium gated with cycle tolerances only: its metrics are not gated, so fail.
        let e = traj(Some(EQ));
        let f = check_pair("p", &e, &e, None, &tol, 0.0).failures("s");
        assert_eq!(f.len(), 3, "{f:?}");
        assert!(
            f[0].quantity.contains("no equilibrium_omega_u_rel stated"),
            "{f:?}"
        );
    }

    /// A stuck disc: the reference at rest (ω = 0), the other solver inside its stuck band.
    /// Within the band its velocity passes a gate of 0; beyond it, the excess fails, and only
    /// that quantity. A slipping equilibrium (neither at 0) is compared as before, band or not.
    #[test]
    fn a_stuck_disc_inside_the_band_agrees_and_the_excess_fails() {
        let tol = PairTolerance {
            equilibrium_omega_u_rel: Some(0.0),
            equilibrium_omega_l_rel: Some(0.0),
            equilibrium_alpha_rel: Some(1e-9),
            steady_abs: Some(1e-12),
            ..PairTolerance::default()
        };
        let eq = |w_u: f64, w_l: f64| {
            traj(Some(RigSteady::Equilibrium {
                omega_u: w_u,
                omega_l: w_l,
                alpha: -0.08,
            }))
        };
        let fails = |a: &Trajectory, b: &Trajectory, band: f64| -> Vec<String> {
            check_pair("p", a, b, None, &tol, band)
                .failures("s")
                .into_iter()
                .map(|f| f.quantity)
                .collect()
        };
        let rest = eq(0.0, 0.0);
        let eta = 1e-10;
        // Held at 0.99999 η and −η: inside the band.
        assert!(fails(&rest, &eq(0.99999 * eta, -eta), eta).is_empty());
        // Without the band the same is a 100 % difference.
        assert_eq!(fails(&rest, &eq(0.99999 * eta, -eta), 0.0).len(), 2);
        // 1.01 η: the excess fails, in ω_l alone.
        assert_eq!(
            fails(&rest, &eq(eta, 1.01 * eta), eta),
            ["steady omega_l".to_owned()]
        );
        // A slipping equilibrium is not stuck: 1e-11 apart fails a gate of 0 whatever the
        // band.
        assert_eq!(fails(&eq(2.0, 2.0), &eq(2.0, 2.0 + 1e-11), eta).len(), 1);
        assert!((beyond_stuck_band("omega_l", 0.0, 3e-10, eta) - 2e-10).abs() < 1e-25);
        assert_eq!(beyond_stuck_band("alpha", 0.0, 3e-10, eta), 3e-10);
        assert!(beyond_stuck_band("omega_u", 0.0, f64::NAN, eta).is_nan());
    }

    /// The transient gates: max, RMS, and the stick event times (count and kind too).
    #[test]
    fn transient_and_event_gates_each_fail_their_negative_control() {
        let tol = PairTolerance {
            transient_max: Some(1e-6),
            transient_rms: Some(1e-7),
            event_time: Some(1e-5),
            ..PairTolerance::default()
        };
        let mut a = traj(None);
        let ev = |t: f64, kind| rotor_model::seam::Event {
            t,
            x: vec![0.0; 3],
            kind,
        };
        a.events = vec![
            ev(0.2, EventKind::StickStart(Disc::LOWER)),
            ev(0.4, EventKind::StickEnd(Disc::LOWER)),
        ];
        assert!(
            check_pair("p", &a, &a, Some([0.0, 1.0]), &tol, 0.0)
                .failures("s")
                .is_empty()
        );
        let fails = |b: &Trajectory| {
            check_pair("p", &a, b, Some([0.0, 1.0]), &tol, 0.0)
                .failures("s")
                .into_iter()
                .map(|f| f.quantity)
                .collect::<Vec<_>>()
        };
        // One sample off by 2e-6: the max fails; the RMS over 202 values is 1.4e-7 and fails too.
        let mut b = a.clone();
        b.samples.x_mut(10)[1] += 2e-6;
        assert_eq!(fails(&b).len(), 2, "{:?}", fails(&b));
        // Every sample off by 2e-7: max passes, RMS fails.
        let mut b = a.clone();
        (0..b.samples.len()).for_each(|k| b.samples.x_mut(k)[2] += 2e-7);
        assert_eq!(fails(&b), vec!["transient rms d_omega"]);
        // An event 2e-5 s late; one missing; one of another kind.
        let mut b = a.clone();
        b.events[1].t += 2e-5;
        assert!(
            fails(&b)[0].starts_with("stick event times"),
            "{:?}",
            fails(&b)
        );
        let mut b = a.clone();
        b.events.pop();
        assert!(fails(&b)[0].contains("(2 vs 1 events)"), "{:?}", fails(&b));
        let mut b = a.clone();
        b.events[1].kind = EventKind::StickStart(Disc::LOWER);
        assert!(
            fails(&b)[0].starts_with("stick event times"),
            "{:?}",
            fails(&b)
        );
        // Half the gate passes.
        let mut b = a.clone();
        b.events[1].t += 5e-6;
        b.samples.x_mut(10)[1] += 5e-7;
        assert!(fails(&b).is_empty(), "{:?}", fails(&b));
    }

    /// A gate of 0 is exact agreement: any difference fails it.
    #[test]
    fn a_zero_gate_demands_exact_agreement() {
        let tol = PairTolerance {
            transient_max: Some(0.0),
            equilibrium_omega_u_rel: Some(0.0),
            equilibrium_omega_l_rel: Some(0.0),
            equilibrium_alpha_rel: Some(0.0),
            ..PairTolerance::default()
        };
        let a = traj(Some(EQ));
        assert!(
            check_pair("p", &a, &a, Some([0.0, 1.0]), &tol, 0.0)
                .failures("s")
                .is_empty()
        );
        let mut b = a.clone();
        // Sample 0 has ω_l = sin 0 = 0, so 1e-300 is representable there.
        b.samples.x_mut(0)[2] += 1e-300;
        assert_eq!(
            check_pair("p", &a, &b, Some([0.0, 1.0]), &tol, 0.0)
                .failures("s")
                .len(),
            1
        );
    }

    #[test]
    fn gated_metrics_missing_on_one_side_fail() {
        let (a, b) = (traj(Some(EQ)), traj(None));
        for (x, y) in [(&a, &b), (&b, &a), (&b, &b)] {
            let f = check_pair("p", x, y, None, &tol(), 0.0).failures("s");
            assert!(
                f.len() == 1 && f[0].quantity.contains("steady metrics"),
                "{f:?}"
            );
        }
    }
}
