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
//! * **A chaotic scene** (`[chaos]`): no run, not even the reference, can be followed sample by
//!   sample for long, since any two runs part at the rate of the largest Lyapunov exponent. So
//!   it is graded as above up to its **predictability horizon** H, and on **statistics**
//!   beyond. H is derived, not chosen: the first time at which the event solver's runs at tol
//!   1e-10 and 1e-11 (two honest runs of a well-converged adaptive integrator) differ by
//!   [`HORIZON_SPREAD`] of the largest |ω|, a tenth of what the strict level allows a sample,
//!   moved to the middle of the gap between two events of the reference around it. The
//!   reference's files hold its trace and events on `[0, H]`; its JSON holds H and, per disc,
//!   the mean velocity and the fraction of samples stuck over `[statistics_from, t_end]`, each
//!   with its standard error from the means of equal batches. A trace's statistics, computed
//!   the same way from its own samples, pass when within [`STATISTICS_SIGMA`] standard errors
//!   of the difference of the reference's.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rotor_analysis::solvers::registry::SolverKind;
use rotor_model::scenario::ChainScenario;
use rotor_model::seam::{Accuracy, Event, Output, Samples, Scene, SolveError, Trajectory};
use rotor_model::{ChainModel, Disc, Rounding, round_sig};
use serde::{Deserialize, Serialize};

use crate::grade::check::{
    CheckError, CheckReport, FLOOR, Graded, Level, check_events, check_times, grade_events,
    grade_stick_of, graded, within_stated, written_enough,
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

/// The predictability horizon is where runs at tol 1e-10 and 1e-11 first differ by this much
/// of the largest |ω| of the run: a tenth of the strict level's sample tolerance (1e-7 of it),
/// so that an adaptive solver at tol 1e-10 stays within strict up to it.
pub const HORIZON_SPREAD: f64 = 1e-8;

/// The tolerances of the two runs whose spread gives the horizon.
pub const HORIZON_TOLS: [f64; 2] = [1e-10, 1e-11];

/// A statistic passes within this many standard errors of the difference: a family-wise
/// confidence above 99.8 % over the 16 statistics of a chain of eight (two-sided normal tail
/// at 4σ: 6.3e-5 each, by Bonferroni), so that an honest solver fails by chance about once in
/// 1000 gradings.
pub const STATISTICS_SIGMA: f64 = 4.0;

/// A sample counts stuck in the statistics when |ω_i| is within this much of the disc's
/// largest |ω| on `[0, H]`: the loose level's threshold, which every level's samples meet
/// (the statistics do not change with the level).
pub const STUCK_FRACTION: f64 = 1e-3;

/// One statistic of a chaotic scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Statistic {
    /// `mean_omega_<i>` \[rad/s\] or `stick_fraction_<i>` (of the samples).
    pub name: String,
    /// Its value: the mean of the batches' values.
    pub mean: f64,
    /// Its standard error: the batches' standard deviation over √(batches).
    pub standard_error: f64,
}

/// What a chaotic scene's reference states beyond its horizon (`<name>.json`'s `chaos`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChaosReference {
    /// The predictability horizon H \[s\]: the trace and events are graded on `[0, H]`.
    pub horizon: f64,
    /// How H was derived, in words.
    pub horizon_method: String,
    /// Start of the statistics' window \[s\].
    pub statistics_from: f64,
    /// Number of batches.
    pub batches: usize,
    /// The statistics, disc by disc: mean velocity, then fraction stuck.
    pub statistics: Vec<Statistic>,
}

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
    /// A chaotic scene's horizon and statistics (absent for a scene graded over the whole
    /// run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chaos: Option<ChaosReference>,
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
    /// The rows of the scene's grid, `t_end/dt + 1`: what a trace must hold (a chaotic
    /// scene's reference holds only those up to its horizon). A reader reads one more, to name
    /// a trace that runs on past the grid.
    pub fn grid_rows(&self) -> usize {
        match self.json.chaos {
            None => self.samples.len(),
            Some(_) => (self.json.t_end / self.json.dt).round() as usize + 1,
        }
    }

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
pub(crate) fn differences(
    names: &[String],
    a: &Trajectory,
    b: &Trajectory,
) -> BTreeMap<String, f64> {
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
/// measure them (on `[0, H]` for a chaotic scene).
pub fn verified_digits(sc: &ChainScenario, r: &ChainReference) -> f64 {
    let events = EventsFile::of_run("reference.events", &r.events);
    let Ok(q) = pointwise(sc, r, &r.samples, Some(&events), Level::Digits(1)) else {
        return 0.0;
    };
    q.iter()
        .filter_map(|q| r.error_of(&q.name).map(|e| -(e / q.scale).log10()))
        .fold(f64::INFINITY, f64::min)
}

/// A run cut at `h`: its samples and events at t ≤ h.
pub(crate) fn until(tr: &Trajectory, h: f64) -> Trajectory {
    let mut samples = Samples::with_capacity(tr.samples.dim(), tr.samples.len());
    for r in tr.samples.iter().filter(|r| r.t <= h) {
        samples.push(r.t, r.x);
    }
    Trajectory {
        samples,
        events: tr.events.iter().filter(|e| e.t <= h).cloned().collect(),
        ..tr.clone()
    }
}

/// The predictability horizon of a chaotic scene (see the module docs): where the event
/// solver's runs at [`HORIZON_TOLS`] first differ by [`HORIZON_SPREAD`] of the largest |ω|,
/// moved to the middle of the gap between the reference's events around it. An error where
/// they never part that far: the scene is not chaotic over its run.
pub fn horizon(sc: &ChainScenario, reference: &Trajectory) -> Result<f64, ReferenceError> {
    let model = sc.model();
    let [a, b] = HORIZON_TOLS.map(|tol| event_run(sc, &model, tol));
    let (a, b) = (a?, b?);
    let omegas: Vec<usize> = (0..model.discs()).map(|d| model.omega(d)).collect();
    let largest = reference
        .samples
        .iter()
        .flat_map(|r| omegas.iter().map(move |&i| r.x[i].abs()))
        .fold(0.0, f64::max);
    let parted = a.samples.iter().zip(b.samples.iter()).find(|(p, q)| {
        omegas
            .iter()
            .any(|&i| (p.x[i] - q.x[i]).abs() > HORIZON_SPREAD * largest)
    });
    let Some((at, _)) = parted else {
        return Err(ReferenceError::Solve {
            scenario: sc.name.clone(),
            source: SolveError::NoConvergence {
                detail: format!(
                    "[chaos]: the runs at tol {:e} and {:e} stay within {HORIZON_SPREAD:e} of \
                     the largest |omega| over the whole run; the scene is graded over the whole \
                     run without [chaos]",
                    HORIZON_TOLS[0], HORIZON_TOLS[1]
                ),
            },
        });
    };
    let h0 = at.t;
    let times: Vec<f64> = switches(&reference.events).iter().map(|e| e.t).collect();
    Ok(match times.iter().position(|&t| t > h0) {
        Some(k) if k > 0 => 0.5 * (times[k - 1] + times[k]),
        _ => h0,
    })
}

/// Per disc, the mean velocity and the fraction of samples stuck (|ω_i| ≤ `stuck[i]`) over
/// `[from, t_end]`, each with its standard error from `batches` equal batches.
pub fn statistics(
    model: &ChainModel,
    samples: &Samples,
    (from, t_end, batches): (f64, f64, usize),
    stuck: &[f64],
) -> Vec<Statistic> {
    let len = (t_end - from) / batches as f64;
    let n = model.discs();
    // Per batch and disc: (sum of ω, stuck samples, samples).
    let mut acc = vec![vec![(0.0, 0usize, 0usize); n]; batches];
    for r in samples.iter().filter(|r| r.t >= from - 1e-9) {
        let b = (((r.t - from) / len).floor() as usize).min(batches - 1);
        for (d, a) in acc[b].iter_mut().enumerate() {
            let w = r.x[model.omega(d)];
            a.0 += w;
            a.1 += usize::from(w.abs() <= stuck[d]);
            a.2 += 1;
        }
    }
    let summary = |name: String, v: Vec<f64>| {
        let k = v.len() as f64;
        let mean = v.iter().sum::<f64>() / k;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
        Statistic {
            name,
            mean,
            standard_error: (var / k).sqrt(),
        }
    };
    let mut out = Vec::with_capacity(2 * n);
    for d in 0..n {
        let of = |f: &dyn Fn(&(f64, usize, usize)) -> f64| -> Vec<f64> {
            acc.iter().map(|b| f(&b[d])).collect()
        };
        out.push(summary(
            format!("mean_omega_{}", d + 1),
            of(&|a| a.0 / a.2.max(1) as f64),
        ));
        out.push(summary(
            format!("stick_fraction_{}", d + 1),
            of(&|a| a.1 as f64 / a.2.max(1) as f64),
        ));
    }
    out
}

/// The thresholds of the statistics' stuck samples: [`STUCK_FRACTION`] of each disc's largest
/// |ω| in the (stored) reference trace.
pub(crate) fn stuck_thresholds(model: &ChainModel, reference: &Samples) -> Vec<f64> {
    let scales = column_scales(reference, FLOOR);
    (0..model.discs())
        .map(|d| STUCK_FRACTION * scales[model.omega(d)])
        .collect()
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
    let full = event_run(sc, &model, tol)?;
    // A chaotic scene: the reference on [0, H], its statistics over the whole window.
    let horizon = sc.chaos.map(|_| horizon(sc, &full)).transpose()?;
    let cut = |tr: Trajectory| match horizon {
        Some(h) => until(&tr, h),
        None => tr,
    };
    let r = cut(full.clone());
    let tight = cut(event_run(sc, &model, check_tol)?);
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
        // A chaotic scene's cross-check runs to the grid time past H only.
        let t_end = horizon.map_or(sc.t_end, |h| ((h / sc.dt).ceil() * sc.dt).min(sc.t_end));
        let scene = Scene {
            accuracy: kind.accuracy(setting),
            t_end,
            ..sc.scene(Output::Grid { dt: sc.dt })
        };
        let run = kind
            .simulate_chain(&model, &scene)
            .map_err(|source| ReferenceError::Solve {
                scenario: format!("{} ({})", sc.name, kind.name()),
                source,
            })?;
        let run = cut(run);
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
    let chaos = match (sc.chaos, horizon) {
        (Some(c), Some(h)) => {
            let stuck = stuck_thresholds(&model, &samples);
            let statistics = statistics(
                &model,
                &full.samples,
                (c.statistics_from, sc.t_end, c.batches),
                &stuck,
            )
            .into_iter()
            .map(|s| Statistic {
                mean: round_sig(s.mean, 6, Rounding::Scaled),
                standard_error: round_sig(s.standard_error, 2, Rounding::Up),
                ..s
            })
            .collect();
            Some(ChaosReference {
                horizon: h,
                horizon_method: format!(
                    "the first grid time at which the event-driven solver's runs at tol {:e} and \
                     {:e} differ by {HORIZON_SPREAD:e} of the largest |omega| of the run (a tenth \
                     of the strict level's sample tolerance), moved to the middle of the gap \
                     between the reference's events around it; statistics: each disc's mean \
                     omega and fraction of samples with |omega| <= {STUCK_FRACTION:e} of its \
                     largest |omega| on [0, horizon], over [statistics_from, t_end] in equal \
                     batches, the standard error the batch means' standard deviation over \
                     sqrt(batches); the reference's run itself at tol {tol:e}",
                    HORIZON_TOLS[0], HORIZON_TOLS[1]
                ),
                statistics_from: c.statistics_from,
                batches: c.batches,
                statistics,
            })
        }
        _ => None,
    };
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
            chaos,
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
/// column over every sample, the events, each disc's stick intervals; for a chaotic scene
/// those on `[0, H]`, and the statistics beyond.
pub fn check_chain(
    sc: &ChainScenario,
    reference: &ChainReference,
    trace: &ChainTrace,
    events: Option<&EventsFile>,
    level: Level,
) -> Result<CheckReport, CheckError> {
    let times: Vec<f64> = trace.samples.iter().map(|r| r.t).collect();
    // The scene's grid: the reference's rows, or, for a chaotic scene whose reference ends at
    // its horizon, every k·dt to t_end.
    let grid: Vec<f64> = match reference.json.chaos {
        None => reference.samples.iter().map(|r| r.t).collect(),
        Some(_) => {
            let n = (sc.t_end / sc.dt).round() as usize;
            (0..=n).map(|k| k as f64 * sc.dt).collect()
        }
    };
    check_times(&trace.path, &trace.lines, &times, &grid, sc.dt, sc.t_end)?;
    if let Some(f) = events {
        check_events(f, sc.t_end)?;
    }
    written_enough(&trace.path, trace.digits, level)?;
    // The samples and events graded one by one: the reference's span.
    let mut head = Samples::with_capacity(trace.samples.dim(), reference.samples.len());
    for r in trace.samples.iter().take(reference.samples.len()) {
        head.push(r.t, r.x);
    }
    let horizon = reference.json.chaos.as_ref().map(|c| c.horizon);
    let cut_events = events.map(|f| EventsFile {
        events: f
            .events
            .iter()
            .filter(|e| horizon.is_none_or(|h| e.t <= h))
            .cloned()
            .collect(),
        ..f.clone()
    });
    let mut q = pointwise(sc, reference, &head, cut_events.as_ref(), level)?;
    // The fewest digits of the quantities graded one by one: a statistic passes or fails on
    // its standard errors, and its digits say how closely it was measured, not the trace.
    let digits = q.iter().map(|g| g.digits).fold(16.0, f64::min);
    if let Some(c) = &reference.json.chaos {
        let model = sc.model();
        let stuck = stuck_thresholds(&model, &reference.samples);
        let mine = statistics(
            &model,
            &trace.samples,
            (c.statistics_from, sc.t_end, c.batches),
            &stuck,
        );
        let scales = column_scales(&reference.samples, FLOOR);
        for (s, r) in mine.iter().zip(&c.statistics) {
            let scale = if s.name.starts_with("mean_omega_") {
                let d: usize = s.name["mean_omega_".len()..].parse().unwrap_or(1);
                scales[model.omega(d - 1)]
            } else {
                1.0
            };
            let sigma = s.standard_error.hypot(r.standard_error);
            let difference = (s.mean - r.mean).abs();
            let tolerance = STATISTICS_SIGMA * sigma;
            q.push(Graded {
                name: s.name.clone(),
                difference,
                scale,
                tolerance,
                passed: difference <= tolerance,
                digits: crate::grade::check::digits(difference, scale),
                at: None,
                note: Some(format!(
                    "over [{}, {}] s beyond the horizon {:.1} s: {:.6} against the \
                     reference's {:.6}, {:.1} standard errors of the difference",
                    c.statistics_from,
                    sc.t_end,
                    c.horizon,
                    s.mean,
                    r.mean,
                    difference / sigma.max(f64::MIN_POSITIVE)
                )),
            });
        }
    }
    let mut not_graded = Vec::new();
    if events.is_none() {
        not_graded.push("events".to_owned());
    }
    Ok(CheckReport {
        scenario: sc.name.clone(),
        benchmark: CHAIN_BENCHMARK,
        passed: q.iter().all(|g| g.passed),
        gate: level,
        digits,
        not_graded,
        file_digits: trace.digits,
        quantities: q,
    })
}

/// The quantities graded one by one on the reference's span: every column over every
/// sample, the events (when given), each disc's stick intervals; refused where the level asks
/// more digits than the reference is verified to, less one.
fn pointwise(
    sc: &ChainScenario,
    reference: &ChainReference,
    trace: &Samples,
    events: Option<&EventsFile>,
    level: Level,
) -> Result<Vec<Graded>, CheckError> {
    let model = sc.model();
    let names = model.state_names();
    let scale = column_scales(&reference.samples, FLOOR);
    let mut q: Vec<Graded> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let (mut worst, mut at) = (0.0f64, 0.0);
        for (a, r) in trace.iter().zip(&reference.samples) {
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
    if let Some(f) = events {
        q.push(grade_events(
            &reference.events,
            &f.events,
            n,
            CHAIN_TIME_SCALE,
            level,
        ));
    }
    let column =
        |s: &Samples, i: usize| -> (Vec<f64>, Vec<f64>) { s.iter().map(|r| (r.t, r.x[i])).unzip() };
    for disc in Disc::all(n) {
        let i = model.omega(disc.position());
        q.extend(grade_stick_of(
            &format!("stick_{}", disc.number()),
            disc,
            column(trace, i),
            column(&reference.samples, i),
            &reference.events,
            scale[i],
            CHAIN_TIME_SCALE,
            level,
        ));
    }
    within_stated(&sc.name, &q, level, |name| reference.error_of(name))?;
    Ok(q)
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
