//! The suite's chain tier: reference data of chains of N discs (`fixtures/chain/`) and the
//! grade of a chain's trace against it, by the rules of the rig's ([`crate::grade::reference`],
//! [`crate::grade::check`]) with the chain's columns.
//!
//! * **Reference** `<name>.csv` (`t,alpha_1,…,alpha_{N−1},omega_1,…,omega_N` on the scene's
//!   grid), `<name>.events.csv` (`t,disc,kind`, disc `1` … `N`) and `<name>.json`: the
//!   event-driven solver at [`REFERENCE_TOL`], each quantity's error the difference to the run
//!   at [`CHECK_TOL`] times [`ERROR_MARGIN`] with the floor of double rounding, and at
//!   [`TIGHT_REFERENCE_TOL`] where that is verified to fewer than [`REQUIRED_DIGITS`]. The
//!   switch model and Moreau–Jean at their comparison settings are reported beside it
//!   (`cross_check`), and `tests/chain_reference_verified.rs` verifies every stated error
//!   against an integrator that shares nothing with the event solver.
//! * **Grade**: every column over every sample (scale: its largest |value| in the reference,
//!   at least [`FLOOR`]), the events matched one to one by disc and kind (scale 1 s: a chain
//!   scene has no steady cycle to give a period), and each disc's stick intervals seen on the
//!   grid (`stick_<i>`), as the rig's are. The levels are the rig's, and none asks more digits
//!   than the reference is verified to, less one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rotor_analysis::solvers::registry::SolverKind;
use rotor_model::scenario::ChainScenario;
use rotor_model::seam::{Accuracy, Event, Output, Samples, Scene, SolveError, Trajectory};
use rotor_model::{ChainModel, Disc, Rounding, round_sig};
use serde::{Deserialize, Serialize};

use crate::grade::check::{
    CheckError, CheckReport, FLOOR, Graded, Level, check_events, check_times, grade_events,
    grade_stick_of, graded,
};
use crate::grade::reference::{
    CHECK_TOL, CrossCheck, ERROR_MARGIN, FLOOR_REL, REFERENCE_TOL, REQUIRED_DIGITS, ReferenceError,
    TIGHT_CHECK_TOL, TIGHT_REFERENCE_TOL, event_difference, switches, trace_differences,
};
use crate::grade::trace::{
    ChainTrace, EventsFile, parse_chain_events, parse_chain_trace, write_chain_events,
    write_named_trace_to,
};

/// The chain tier's version: named in every chain verdict, job file and report.
pub const CHAIN_BENCHMARK: &str = rotor_suite::CHAIN_VERSION;

/// Events of a chain scene are measured against 1 s: the scene compares no steady cycle
/// whose period could be the scale, as a rig scene's transient to an equilibrium.
pub const CHAIN_TIME_SCALE: f64 = 1.0;

/// The `<name>.json` of a chain reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChainReferenceJson {
    /// The scenario's name (the file's stem).
    pub scenario: String,
    /// Number of discs N.
    pub discs: usize,
    /// How the reference was computed.
    pub solver: String,
    /// The solver's tolerance.
    pub tol: f64,
    /// Grid step of the trace \[s\].
    pub dt: f64,
    /// Horizon of the run \[s\].
    pub t_end: f64,
    /// Significant digits of the values in the trace file.
    pub trace_digits: u32,
    /// The stated error of each quantity: every column by its name (largest over the run)
    /// and `event_time` (largest over the events).
    pub error: BTreeMap<String, f64>,
    /// How `error` was estimated, in words.
    pub error_method: String,
    /// Differences of the switch model and Moreau–Jean (at their comparison settings) from
    /// the reference, per quantity as in `error`; `null` where not comparable (another event
    /// sequence).
    pub cross_check: BTreeMap<String, CrossCheck>,
}

/// A chain reference: what its three files hold.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainReference {
    /// The trace on the scene's grid over `[0, t_end]`.
    pub samples: Samples,
    /// The mode-switch events, in time order.
    pub events: Vec<Event>,
    /// The stated errors and how they were obtained.
    pub json: ChainReferenceJson,
}

impl ChainReference {
    /// The stated error of a graded quantity: a column's own, `event_time` for the events
    /// and the stick intervals.
    pub fn error_of(&self, quantity: &str) -> Option<f64> {
        let key = if quantity == "events" || quantity.starts_with("stick_") {
            "event_time"
        } else {
            quantity
        };
        self.json.error.get(key).copied()
    }
}

/// The event-driven run of a chain scene at `tol` on its grid.
fn event_run(
    sc: &ChainScenario,
    model: &ChainModel,
    tol: f64,
) -> Result<Trajectory, ReferenceError> {
    let scene = Scene {
        accuracy: Accuracy::Tol(tol),
        ..sc.scene(Output::Grid { dt: sc.dt })
    };
    SolverKind::EVENT
        .simulate_chain(model, &scene)
        .map_err(|source| ReferenceError::Solve {
            scenario: sc.name.clone(),
            source,
        })
}

/// Each quantity's difference of run `a` from run `b`: every column, and `event_time` (∞
/// where the event sequences differ).
fn differences(names: &[String], a: &Trajectory, b: &Trajectory) -> BTreeMap<String, f64> {
    let mut out: BTreeMap<String, f64> = names
        .iter()
        .cloned()
        .zip(trace_differences(&a.samples, &b.samples))
        .collect();
    out.insert(
        "event_time".into(),
        event_difference(&switches(&a.events), &switches(&b.events)),
    );
    out
}

/// Largest |value| of each column over the samples, at least `floor`.
fn column_scales(samples: &Samples, floor: f64) -> Vec<f64> {
    let mut s = vec![floor; samples.dim()];
    for r in samples {
        for (si, v) in s.iter_mut().zip(r.x) {
            *si = si.max(v.abs());
        }
    }
    s
}

/// The fewest digits to which any graded quantity of `r` is verified, as the grade's scales
/// measure them.
pub fn verified_digits(sc: &ChainScenario, r: &ChainReference) -> f64 {
    let trace = ChainTrace::of_run("reference", r.samples.clone());
    let events = EventsFile::of_run("reference.events", &r.events);
    let Ok(rep) = check_chain(sc, r, &trace, Some(&events), Level::Digits(1)) else {
        return 0.0;
    };
    rep.quantities
        .iter()
        .filter_map(|q| r.error_of(&q.name).map(|e| -(e / q.scale).log10()))
        .fold(f64::INFINITY, f64::min)
}

/// Computes a chain scene's reference at [`REFERENCE_TOL`], or at [`TIGHT_REFERENCE_TOL`]
/// where that is verified to fewer than [`REQUIRED_DIGITS`].
pub fn compute(sc: &ChainScenario) -> Result<ChainReference, ReferenceError> {
    let r = compute_at(sc, REFERENCE_TOL, CHECK_TOL)?;
    if verified_digits(sc, &r) >= REQUIRED_DIGITS {
        return Ok(r);
    }
    compute_at(sc, TIGHT_REFERENCE_TOL, TIGHT_CHECK_TOL)
}

fn compute_at(
    sc: &ChainScenario,
    tol: f64,
    check_tol: f64,
) -> Result<ChainReference, ReferenceError> {
    let model = sc.model();
    let names = model.state_names();
    let r = event_run(sc, &model, tol)?;
    let tight = event_run(sc, &model, check_tol)?;
    // As the rig's: columns against their largest |value| (at least 1), event times against
    // t_end (their rounding is relative to the time they happen at).
    let scales = column_scales(&r.samples, 1.0);
    let scale_of = |name: &str| {
        names
            .iter()
            .position(|n| n == name)
            .map_or(sc.t_end, |i| scales[i])
    };
    let error: BTreeMap<String, f64> = differences(&names, &r, &tight)
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
                     event sequence): no error can be stated"
                ),
            },
        });
    }
    // Half a unit of the last digit ≤ a tenth of the smallest relative column error.
    let rel = names
        .iter()
        .map(|n| error[n] / scale_of(n))
        .fold(f64::INFINITY, f64::min);
    let trace_digits = ((0.5 / (0.1 * rel)).log10().ceil() as u32 + 1).clamp(6, 17);
    let mut samples = Samples::with_capacity(r.samples.dim(), r.samples.len());
    let mut row = vec![0.0; r.samples.dim()];
    for s in &r.samples {
        for (o, v) in row.iter_mut().zip(s.x) {
            *o = round_sig(*v, trace_digits, Rounding::Scaled);
        }
        samples.push(s.t, &row);
    }
    let mut cross_check = BTreeMap::new();
    for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
        let setting = kind.info().comparison;
        let scene = Scene {
            accuracy: kind.accuracy(setting),
            ..sc.scene(Output::Grid { dt: sc.dt })
        };
        let run = kind
            .simulate_chain(&model, &scene)
            .map_err(|source| ReferenceError::Solve {
                scenario: format!("{} ({})", sc.name, kind.name()),
                source,
            })?;
        cross_check.insert(
            kind.name().to_owned(),
            CrossCheck {
                setting: kind.setting_label(setting),
                differences: differences(&names, &run, &r)
                    .into_iter()
                    .map(|(n, d)| (n, d.is_finite().then(|| round_sig(d, 2, Rounding::Scaled))))
                    .collect(),
            },
        );
    }
    let error = error
        .into_iter()
        .map(|(n, e)| (n, round_sig(e, 2, Rounding::Up)))
        .collect();
    Ok(ChainReference {
        samples,
        events: switches(&r.events),
        json: ChainReferenceJson {
            scenario: sc.name.clone(),
            discs: model.discs(),
            solver: "event".into(),
            tol,
            dt: sc.dt,
            t_end: sc.t_end,
            trace_digits,
            error,
            error_method: format!(
                "{ERROR_MARGIN} x the largest difference from the event-driven solver at tol \
                 {check_tol:e} (columns: over every sample of the run; event_time: over the \
                 matched events), at least {FLOOR_REL:e} of the quantity's scale (a column's \
                 largest |value|, at least 1; event_time: t_end); the trace is rounded to \
                 {trace_digits} significant digits. Verified against an independent solution \
                 (Gauss-Legendre collocation of order 10, own event location, error estimated \
                 by step halving): crates/rotor-harness/tests/chain_reference_verified.rs"
            ),
            cross_check,
        },
    })
}

/// The reference's files as bytes (trace, events, JSON).
pub fn to_files(sc: &ChainScenario, r: &ChainReference) -> [Vec<u8>; 3] {
    let mut trace = Vec::new();
    write_named_trace_to(&mut trace, &sc.model().state_names(), &r.samples, r.json.dt)
        .expect("in memory");
    let json = serde_json::to_string_pretty(&r.json).expect("plain numbers and strings") + "\n";
    [trace, write_chain_events(&r.events), json.into_bytes()]
}

/// Reads a chain scene's reference from `dir`.
pub fn read(dir: &Path, sc: &ChainScenario) -> Result<ChainReference, ReferenceError> {
    let [trace, events, json] = crate::grade::reference::paths(dir, &sc.name);
    let read = |p: &Path| {
        std::fs::read(p).map_err(|e| ReferenceError::File {
            path: p.to_owned(),
            message: format!("cannot read the reference ({e}); `rotor reference` writes it"),
        })
    };
    let names = sc.model().state_names();
    let samples = parse_chain_trace(&read(&trace)?, &trace, &names)?.samples;
    let events = parse_chain_events(&read(&events)?, &events, sc.discs())?.events;
    let json: ChainReferenceJson =
        serde_json::from_slice(&read(&json)?).map_err(|e| ReferenceError::File {
            path: json.clone(),
            message: format!("not a chain reference JSON: {e}"),
        })?;
    Ok(ChainReference {
        samples,
        events,
        json,
    })
}

/// Grades a chain's trace (and events, if given) against the reference at `level`: every
/// column over every sample, the events, each disc's stick intervals.
pub fn check_chain(
    sc: &ChainScenario,
    reference: &ChainReference,
    trace: &ChainTrace,
    events: Option<&EventsFile>,
    level: Level,
) -> Result<CheckReport, CheckError> {
    let times = |s: &Samples| s.iter().map(|r| r.t).collect::<Vec<f64>>();
    let ref_times = times(&reference.samples);
    check_times(
        &trace.path,
        &trace.lines,
        &times(&trace.samples),
        &ref_times,
        sc.dt,
        sc.t_end,
    )?;
    if let Some(f) = events {
        check_events(f, sc.t_end)?;
    }
    let needed = level.digits() + 1;
    if trace.digits < needed {
        return Err(CheckError::Precision {
            path: trace.path.clone(),
            digits: trace.digits,
            level: level.name(),
            needed,
        });
    }
    let model = sc.model();
    let names = model.state_names();
    let scale = column_scales(&reference.samples, FLOOR);
    let mut q: Vec<Graded> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let (mut worst, mut at) = (0.0f64, 0.0);
        for (a, r) in trace.samples.iter().zip(&reference.samples) {
            let e = (a.x[i] - r.x[i]).abs();
            if e.is_nan() || e > worst {
                (worst, at) = (e, r.t);
            }
        }
        let mut g = graded(name, worst, scale[i], level);
        g.at = Some(at);
        q.push(g);
    }
    let n = model.discs();
    let mut not_graded = Vec::new();
    match events {
        Some(f) => q.push(grade_events(
            &reference.events,
            &f.events,
            n,
            CHAIN_TIME_SCALE,
            level,
        )),
        None => not_graded.push("events".to_owned()),
    }
    let column =
        |s: &Samples, i: usize| -> (Vec<f64>, Vec<f64>) { s.iter().map(|r| (r.t, r.x[i])).unzip() };
    for disc in Disc::all(n) {
        let i = model.omega(disc.position());
        q.extend(grade_stick_of(
            &format!("stick_{}", disc.number()),
            disc,
            column(&trace.samples, i),
            column(&reference.samples, i),
            &reference.events,
            scale[i],
            CHAIN_TIME_SCALE,
            level,
        ));
    }
    for g in &q {
        let Some(err) = reference.error_of(&g.name) else {
            continue;
        };
        let verified = -(err / g.scale).log10();
        let most = (verified - 1.0).floor().max(0.0) as u32;
        if level.digits() > most {
            return Err(CheckError::BeyondReference {
                scenario: sc.name.clone(),
                level: level.name(),
                asked: level.digits(),
                quantity: g.name.clone(),
                verified,
                most,
            });
        }
    }
    Ok(CheckReport {
        scenario: sc.name.clone(),
        benchmark: CHAIN_BENCHMARK,
        passed: q.iter().all(|g| g.passed),
        gate: level,
        digits: q.iter().map(|g| g.digits).fold(16.0, f64::min),
        not_graded,
        file_digits: trace.digits,
        quantities: q,
    })
}

/// The chain scene and its reference for a scenario file (the reference from `reference/`
/// beside its `scenarios/`, [`crate::grade::reference::dir_for`]).
pub fn load(
    path: &Path,
) -> Result<(ChainScenario, ChainReference), crate::grade::check::GradeError> {
    let sc = ChainScenario::from_file(path)?;
    let r = read(&crate::grade::reference::dir_for(path), &sc)?;
    Ok((sc, r))
}

/// Where the chain tier lives in a suite directory (`chain/` beside `scenarios/`).
pub fn tier_dir(fixtures: &Path) -> PathBuf {
    fixtures.join("chain")
}
