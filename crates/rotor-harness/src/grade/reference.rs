//! The benchmark's reference data (`rotor reference`, `fixtures/reference/`): for every
//! scenario the event-driven solver's trace on the scenario's grid, its events, and its steady
//! state, each with the reference's own error estimate and how it was obtained.
//!
//! * **Trace** `<name>.csv` (`t,alpha,omega_u,omega_l`, every `dt` over `[0, t_end]`) and
//!   **events** `<name>.events.csv` (`t,disc,kind`): the event-driven solver at
//!   [`REFERENCE_TOL`]. Values are rounded to the significant digits that the error estimate
//!   justifies (half a unit of the last digit is at most a tenth of the estimate).
//! * **Steady state** `<name>.json`: the metrics of the last complete cycle in
//!   `[steady_from, t_end]` as `rotor steady` prints them, with `error` (per quantity), how
//!   it was estimated, and the cross-check against the switch model and Moreau–Jean.
//!
//! The error estimate of each quantity is its difference from the same solver at the tighter
//! [`CHECK_TOL`], times [`ERROR_MARGIN`] (the tighter run is itself not exact), with a floor of
//! what double precision resolves on it. The cross-check is reported, not folded in: the
//! other two solvers are less accurate than the reference by design.
//!
//! Every stated error is verified, not only restated: `tests/reference_verified.rs` solves
//! each scenario again with an integrator that shares nothing with the reference's (s-stage
//! Gauss–Legendre collocation, order 10, fixed steps, events located by re-stepping), estimates
//! its own error by halving its step, and fails if the reference lies further from it than
//! stated. It found, and the estimate now covers, two gaps of the difference-to-tighter-run
//! rule: an equilibrium's `alpha`, `omega_u`, `omega_l` had replaced the trace's errors of the
//! same names (1e-14 stated, 1e-11 true), and a period or stick time near the end of a long
//! run had a floor relative to its own size, not to the times it is the difference of.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rotor_model::scenario::Scenario;
use rotor_model::seam::{Accuracy, Event, Output, RigSteady, Sample, Samples, Scene, SolveError};
use rotor_model::{Rounding, round_sig};
use serde::{Deserialize, Serialize};

use crate::grade::trace::{TraceError, parse_events, parse_trace, write_events};
use rotor_analysis::solvers::registry::SolverKind;

/// Tolerance of the reference run.
pub const REFERENCE_TOL: f64 = 1e-12;
/// Tolerance of the run the reference's error is estimated against: two decades tighter.
/// One decade was not enough: the extremes of a cycle converge erratically with the
/// tolerance, and at t1-u2.5-rest ω_l_max erred by 5.4e-13 at tol 1e-12 but still by 2.7e-13
/// at 1e-13 (1.4e-14 at 1e-14), so the difference of the two understated the error by half;
/// the independent check (tests/reference_verified.rs) found it.
pub const CHECK_TOL: f64 = 1e-14;
/// The difference to the tighter run times this is the stated error: the tighter run errs
/// by about a hundredth of the reference's (the event-driven solver's error is proportional to
/// its tolerance: `crates/rotor-event/tests/solver.rs`; erratically so for the extremes, a
/// tenth to a fortieth), so the difference is within a few % of the reference's true error,
/// and 2 covers that with room.
pub const ERROR_MARGIN: f64 = 2.0;
/// Smallest stated error, relative to the quantity's scale: about 90 units of double
/// rounding. A stated error must be verifiable: `tests/reference_verified.rs` asks the
/// independent solution's own error to be at most a tenth of it, and that solution resolves
/// about 1.1e-15 of the scale (its step-halving estimate on t1-u4.5-eq-pert's ω_u: 8.9e-15
/// of 8.1 rad/s, rounding-dominated). 1e-14 sat below ten times that once the event solver's
/// steps were bounded by the friction scale and its differences fell to the floor.
pub(crate) const FLOOR_REL: f64 = 2e-14;

/// Tolerance of the reference run of a scenario whose reference at [`REFERENCE_TOL`] is
/// verified to fewer than [`REQUIRED_DIGITS`] on some graded quantity: the three that start
/// next to an unstable equilibrium (st-u0.19-eq-pert, t1-u0.4-eq-pert, t1-u2.5-eq-pert), whose
/// growth away from it amplifies every early error. The event-driven solver's error is
/// proportional to its tolerance there (measured on those three against a run at 1.2e-15: a
/// factor 7.5–10.4 per decade from tol 1e-11 to 1e-13 in the event times and the trace;
/// `cargo run --release -p rotor-harness --example reference_tol`), so 5e-14 gains about 1.3
/// digits.
pub const TIGHT_REFERENCE_TOL: f64 = 5e-14;
/// The run the error of a [`TIGHT_REFERENCE_TOL`] reference is estimated against: 1.2e-15,
/// the smallest round tolerance the solvers accept (`rotor_model::seam::MIN_TOL` = 1.1e-15), 1.6
/// decades tighter (its error a 40th of the reference's: within the [`ERROR_MARGIN`]).
pub const TIGHT_CHECK_TOL: f64 = 1.2e-15;
/// Digits to which every graded quantity of every reference must be verified: the strict
/// level's, one more because no level is graded closer than one digit to the reference
/// ([`crate::grade::check`]'s `BeyondReference`), and one more so that strict is a full digit inside
/// what the reference can grade (a regenerated reference that loses a few tenths of a digit
/// does not stop grading strict). A reference below it at [`REFERENCE_TOL`] is computed at
/// [`TIGHT_REFERENCE_TOL`].
pub const REQUIRED_DIGITS: f64 = crate::grade::check::STRICT_DIGITS as f64 + 2.0;

/// The `<name>.json` of a reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceJson {
    /// The scenario's name (the file's stem).
    pub scenario: String,
    /// The steady state as `rotor steady` prints it (`kind` and its metrics), over the
    /// scenario's `[steady_from, t_end]`; absent when the scenario compares no steady state.
    #[serde(flatten)]
    pub steady: Option<RigSteady>,
    /// How the reference was computed.
    pub solver: String,
    /// The solver's tolerance ([`REFERENCE_TOL`] for the stored reference).
    pub tol: f64,
    /// Grid step of the trace \[s\] (the scenario's `compare.dt`).
    pub dt: f64,
    /// Horizon of the run \[s\].
    pub t_end: f64,
    /// Start of the steady-state window \[s\], if the scenario compares a steady state.
    pub steady_from: Option<f64>,
    /// The scenario's transient window `[t0, t1]` \[s\], if it has one.
    pub transient: Option<[f64; 2]>,
    /// Significant digits of the values in the trace file.
    pub trace_digits: u32,
    /// The stated error of each quantity (same units as the quantity): `alpha`, `omega_u`,
    /// `omega_l` (the trace, largest over the run), `event_time` (largest over the events),
    /// and each steady metric by its name.
    pub error: BTreeMap<String, f64>,
    /// How `error` was estimated, in words (the rule, its floor and its verification).
    pub error_method: String,
    /// Differences of the switch model and Moreau–Jean (at the scenario's settings) from the
    /// reference, per quantity as in `error`: the same answer from two independent methods.
    /// `null` where they cannot be compared (a different number of events or another kind of
    /// steady state).
    pub cross_check: BTreeMap<String, CrossCheck>,
}

/// One solver's differences from the reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCheck {
    /// `tol 1e-10` or `h 1e-3`.
    pub setting: String,
    /// Its largest difference from the reference per quantity (names and units as in
    /// [`ReferenceJson::error`]); `None` where not comparable.
    pub differences: BTreeMap<String, Option<f64>>,
}

/// A reference: what the three files hold.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// The trace: the state on the scenario's grid over `[0, t_end]`.
    pub samples: Vec<Sample>,
    /// The mode-switch events (stick onsets and exits, reversals; no extrema), in time order.
    pub events: Vec<Event>,
    /// The steady state, the stated errors and how they were obtained.
    pub json: ReferenceJson,
}

/// Why a reference cannot be computed or read.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// A reference run of the scenario failed.
    #[error("scenario {scenario}: {source}")]
    Solve {
        /// The scenario's name.
        scenario: String,
        /// Why the run failed.
        #[source]
        source: SolveError,
    },
    /// A stored trace or events file is not one.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// A stored file is missing, unreadable, or not a reference JSON.
    #[error("{}: {message}", .path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong, and how to make it (`rotor reference`).
        message: String,
    },
}

impl Reference {
    /// A reference held in memory only (the benchmark's own reference run on its scene):
    /// the run's grid samples and mode-switch events, and the steady state it reached; no
    /// error is stated.
    pub(crate) fn in_memory(
        sc: &Scenario,
        tr: &rotor_model::seam::Trajectory,
        tol: f64,
    ) -> Reference {
        Reference {
            samples: tr.samples.iter().map(|r| r.sample()).collect(),
            events: switches(&tr.events),
            json: ReferenceJson {
                scenario: sc.name.clone(),
                steady: sc.compare.steady_from.and(tr.rig_metrics()),
                solver: "event".into(),
                tol,
                dt: sc.compare.dt,
                t_end: sc.t_end,
                steady_from: sc.compare.steady_from,
                transient: sc.compare.transient,
                trace_digits: 17,
                error: BTreeMap::new(),
                error_method: "not estimated (in memory)".into(),
                cross_check: BTreeMap::new(),
            },
        }
    }

    /// The stated error of a quantity (0 if not stated).
    pub fn error(&self, name: &str) -> f64 {
        self.json.error.get(name).copied().unwrap_or(0.0)
    }

    /// The steady state, if the scenario compares one.
    pub fn steady(&self) -> Option<RigSteady> {
        self.json.steady
    }
}

/// The reference run of a scenario at tolerance `tol`: grid samples, events, metrics.
fn event_run(sc: &Scenario, tol: f64) -> Result<rotor_model::seam::Trajectory, ReferenceError> {
    let scene = Scene {
        accuracy: Accuracy::Tol(tol),
        ..sc.scene(Output::Grid { dt: sc.compare.dt })
    };
    SolverKind::EVENT
        .solver()
        .simulate_finite(&sc.model, &scene)
        .map_err(|source| ReferenceError::Solve {
            scenario: sc.name.clone(),
            source,
        })
}

/// Mode-switch events (no extrema), as the events file holds them.
pub(crate) fn switches(events: &[Event]) -> Vec<Event> {
    events
        .iter()
        .filter(|e| crate::grade::trace::event_row(e.kind).is_some())
        .cloned()
        .collect()
}

/// Largest |a − b| of each state component over two runs on the same grid (∞ if the grids
/// differ).
pub(crate) fn trace_differences(a: &Samples, b: &Samples) -> Vec<f64> {
    if a.len() != b.len() || a.dim() != b.dim() {
        return vec![f64::INFINITY; a.dim().max(b.dim())];
    }
    let mut d = vec![0.0f64; a.dim()];
    for (x, y) in a.iter().zip(b) {
        for (i, di) in d.iter_mut().enumerate() {
            *di = di.max((x.x[i] - y.x[i]).abs());
        }
    }
    d
}

/// Largest |Δt| of the events matched in order (∞ if their sequences differ).
pub(crate) fn event_difference(a: &[Event], b: &[Event]) -> f64 {
    if a.len() != b.len() || a.iter().zip(b).any(|(x, y)| x.kind != y.kind) {
        return f64::INFINITY;
    }
    a.iter()
        .zip(b)
        .map(|(x, y)| (x.t - y.t).abs())
        .fold(0.0, f64::max)
}

/// The differences of a run from the reference, per quantity (∞ where not comparable).
fn differences(
    r: &rotor_model::seam::Trajectory,
    reference: &rotor_model::seam::Trajectory,
) -> BTreeMap<String, f64> {
    let d = trace_differences(&r.samples, &reference.samples);
    let mut out: BTreeMap<String, f64> = rotor_model::RIG_STATE_NAMES
        .iter()
        .zip(d)
        .map(|(n, e)| ((*n).to_owned(), e))
        .collect();
    out.insert(
        "event_time".into(),
        event_difference(&switches(&r.events), &switches(&reference.events)),
    );
    if let (Some(a), Some(b)) = (r.rig_metrics(), reference.rig_metrics()) {
        if a.kind() == b.kind() {
            for ((name, va), (_, vb)) in a.values().into_iter().zip(b.values()) {
                // An equilibrium's `alpha`, `omega_u`, `omega_l` share their names with the
                // trace's: the stated error covers both (the larger), not the equilibrium's
                // alone. The trace's differ along the run far more than at its end (the
                // independent check, tests/reference_verified.rs, found 1e-11 against 1e-14).
                let d = (va - vb).abs();
                let e = out.entry(name.into()).or_insert(0.0);
                *e = e.max(d);
            }
        } else {
            out.insert("steady_kind".into(), f64::INFINITY);
        }
    }
    out
}

/// The fewest digits to which any graded quantity of `r` is verified: `−log10(error/scale)`
/// over the quantities of its own trace and events graded by [`crate::grade::check::check`] (their
/// scales are the grade's), 0 if they cannot be graded.
pub fn verified_digits(sc: &Scenario, r: &Reference) -> f64 {
    let trace = crate::grade::trace::Trace::of_samples("reference", r.samples.clone());
    let events = crate::grade::trace::EventsFile::of_run("reference.events", &r.events);
    let Ok(rep) = crate::grade::check::check(
        sc,
        r,
        &trace,
        Some(&events),
        crate::grade::check::Level::Digits(1),
    ) else {
        return 0.0;
    };
    rep.quantities
        .iter()
        .filter_map(|q| {
            crate::grade::check::reference_error(r, &q.name).map(|e| -(e / q.scale).log10())
        })
        .fold(f64::INFINITY, f64::min)
}

/// Computes the reference of a scenario: at [`REFERENCE_TOL`] (error against [`CHECK_TOL`]),
/// or, where that is verified to fewer than [`REQUIRED_DIGITS`] on some graded quantity
/// ([`verified_digits`]), at [`TIGHT_REFERENCE_TOL`] (against [`TIGHT_CHECK_TOL`]).
pub fn compute(sc: &Scenario) -> Result<Reference, ReferenceError> {
    let r = compute_at(sc, REFERENCE_TOL, CHECK_TOL)?;
    if verified_digits(sc, &r) >= REQUIRED_DIGITS {
        return Ok(r);
    }
    compute_at(sc, TIGHT_REFERENCE_TOL, TIGHT_CHECK_TOL)
}

/// The reference of a scenario at tolerance `tol`, its errors estimated against `check_tol`
/// (three event-driven runs: the reference, the tighter one, and the orbit; and the
/// cross-check runs of the other two solvers).
fn compute_at(sc: &Scenario, tol: f64, check_tol: f64) -> Result<Reference, ReferenceError> {
    let r = event_run(sc, tol)?;
    let tight = event_run(sc, check_tol)?;
    // The stated error: the difference to the tighter run, with a margin and a floor.
    let scale_of = |name: &str| -> f64 {
        let comp = match name {
            "alpha" => Some(0),
            "omega_u" => Some(1),
            "omega_l" => Some(2),
            _ => None,
        };
        match comp {
            Some(i) => r.samples.iter().map(|s| s.x[i].abs()).fold(1.0, f64::max),
            // Event times, and the period and stick time (differences of event times late in
            // the run): their rounding is relative to the time of the events, not to the
            // quantity's own size (a period of 4 s from exits near 200 s carries ulp(200 s)).
            None if matches!(name, "event_time" | "period" | "stick_time") => sc.t_end,
            None => r
                .rig_metrics()
                .map(|m| {
                    m.values()
                        .into_iter()
                        .find(|(n, _)| *n == name)
                        .map_or(1.0, |(_, v)| v.abs().max(1.0))
                })
                .unwrap_or(1.0),
        }
    };
    let error: BTreeMap<String, f64> = differences(&r, &tight)
        .into_iter()
        .map(|(name, e)| {
            let stated = (ERROR_MARGIN * e).max(FLOOR_REL * scale_of(&name));
            (name, stated)
        })
        .collect();
    if let Some((name, _)) = error.iter().find(|(_, e)| !e.is_finite()) {
        return Err(ReferenceError::Solve {
            scenario: sc.name.clone(),
            source: SolveError::NoConvergence {
                detail: format!(
                    "the reference and the run at tol {check_tol:e} differ in {name} (another \
                     event sequence or steady kind): no error can be stated"
                ),
            },
        });
    }
    // Trace digits: half a unit of the last digit ≤ a tenth of the smallest relative error
    // of the three components.
    let rel = rotor_model::RIG_STATE_NAMES
        .iter()
        .map(|n| error.get(*n).map_or(f64::INFINITY, |e| e / scale_of(n)))
        .fold(f64::INFINITY, f64::min);
    let trace_digits = ((0.5 / (0.1 * rel)).log10().ceil() as u32 + 1).clamp(6, 17);
    let samples: Vec<Sample> = r
        .samples
        .iter()
        .map(|s| Sample {
            t: s.t,
            x: s.state()
                .map(|v| round_sig(v, trace_digits, Rounding::Scaled)),
        })
        .collect();
    let mut cross_check = BTreeMap::new();
    for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
        let scene = rotor_analysis::solvers::run::scene_for(kind, sc);
        let run = kind
            .solver()
            .simulate_finite(&sc.model, &scene)
            .map_err(|source| ReferenceError::Solve {
                scenario: format!("{} ({})", sc.name, kind.name()),
                source,
            })?;
        cross_check.insert(
            kind.name().to_owned(),
            CrossCheck {
                setting: kind.setting_label(rotor_analysis::solvers::run::solver_setting(kind, sc)),
                differences: differences(&run, &r)
                    .into_iter()
                    .map(|(n, d)| (n, d.is_finite().then_some(d)))
                    .collect(),
            },
        );
    }
    // Metrics to the digits their error justifies (as the trace), errors and differences to
    // two: the file changes only when a result does, not with the last bits of a machine.
    let steady = sc.compare.steady_from.and(r.rig_metrics()).map(|m| {
        let rounded = |name: &str, v: f64| {
            let e = error.get(name).copied().unwrap_or(0.0);
            let d = if v == 0.0 || e == 0.0 {
                17
            } else {
                ((v.abs() / (0.1 * e)).log10().ceil() as u32 + 1).clamp(2, 17)
            };
            round_sig(v, d, Rounding::Scaled)
        };
        m.map(rounded)
    });
    let error: BTreeMap<String, f64> = error
        .into_iter()
        .map(|(n, e)| (n, round_sig(e, 2, Rounding::Up)))
        .collect();
    for c in cross_check.values_mut() {
        for d in c.differences.values_mut() {
            *d = d.map(|x| round_sig(x, 2, Rounding::Scaled));
        }
    }
    let mut json = ReferenceJson {
        scenario: sc.name.clone(),
        steady,
        solver: "event".into(),
        tol,
        dt: sc.compare.dt,
        t_end: sc.t_end,
        steady_from: sc.compare.steady_from,
        transient: sc.compare.transient,
        trace_digits,
        error,
        error_method: format!(
            "{ERROR_MARGIN} x the largest difference from the event-driven solver at tol \
             {check_tol:e} (trace: over every sample of the run; event_time: over the matched \
             events; steady metrics: the last complete cycle in [steady_from, t_end]; orbit: \
             the orbit quantity of `rotor check` of that run's trace, the distance of its \
             steady samples from this reference's orbit), at least {FLOOR_REL:e} of the \
             quantity's scale (event_time, period, stick_time: of t_end; orbit: of 1); an \
             equilibrium's alpha, omega_u, omega_l take the larger of theirs and the trace's; \
             the trace is rounded to {trace_digits} significant digits. Verified against an \
             independent solution (Gauss-Legendre collocation of order 10, own event \
             location, error estimated by step halving): \
             crates/rotor-harness/tests/reference_verified.rs"
        ),
        cross_check,
    };
    // The orbit: what `rotor check` charges the tighter run (nearly exact) in `orbit` is
    // what it charges an exact trace, up to the tighter run's own error: the error of this
    // reference's orbit quantity, stated as the others are.
    if let (Some(from), Some(RigSteady::LimitCycle { .. })) = (sc.compare.steady_from, steady) {
        let partial = Reference {
            samples: samples.clone(),
            events: switches(&r.events),
            json: json.clone(),
        };
        let scale = crate::grade::check::state_scales(&samples);
        let cycle = steady.expect("a cycle");
        let tight_samples: Vec<Sample> = tight.samples.iter().map(|r| r.sample()).collect();
        if let Some(d) =
            crate::grade::check::orbit_distance(sc, &partial, cycle, &tight_samples, from, scale)
        {
            let (d, _) = d.map_err(|source| ReferenceError::Solve {
                scenario: format!("{} (orbit)", sc.name),
                source,
            })?;
            let stated = (ERROR_MARGIN * d).max(FLOOR_REL);
            json.error
                .insert("orbit".into(), round_sig(stated, 2, Rounding::Up));
        }
    }
    Ok(Reference {
        samples,
        events: switches(&r.events),
        json,
    })
}

/// The three file names of a scenario's reference in `dir`.
pub fn paths(dir: &Path, name: &str) -> [PathBuf; 3] {
    [
        dir.join(format!("{name}.csv")),
        dir.join(format!("{name}.events.csv")),
        dir.join(format!("{name}.json")),
    ]
}

/// The reference's files as bytes (trace, events, JSON).
pub fn to_files(r: &Reference) -> [Vec<u8>; 3] {
    let json = serde_json::to_string_pretty(&r.json).expect("plain numbers and strings") + "\n";
    [
        crate::grade::trace::write_trace(&r.samples.iter().copied().collect(), r.json.dt),
        write_events(&r.events),
        json.into_bytes(),
    ]
}

/// Reads a scenario's reference from `dir`.
pub fn read(dir: &Path, name: &str) -> Result<Reference, ReferenceError> {
    let [trace, events, json] = paths(dir, name);
    let read = |p: &Path| {
        std::fs::read(p).map_err(|e| ReferenceError::File {
            path: p.to_owned(),
            message: format!("cannot read the reference ({e}); `rotor reference` writes it"),
        })
    };
    let samples = parse_trace(&read(&trace)?, &trace)?.samples;
    let events = parse_events(&read(&events)?, &events)?.events;
    let json: ReferenceJson =
        serde_json::from_slice(&read(&json)?).map_err(|e| ReferenceError::File {
            path: json.clone(),
            message: format!("not a reference JSON: {e}"),
        })?;
    Ok(Reference {
        samples,
        events,
        json,
    })
}

/// The reference directory of a scenario file: `fixtures/reference/` beside its
/// `fixtures/scenarios/`.
pub fn dir_for(scenario_path: &Path) -> PathBuf {
    scenario_path
        .parent()
        .and_then(Path::parent)
        .unwrap_or(Path::new("."))
        .join("reference")
}
