//! Work-precision benchmark of the three rotor solvers (issue #7).
//!
//! [`run`] takes [`BenchOptions`] and returns a [`BenchReport`]:
//!
//! * **Ladders.** Each solver at a ladder of accuracy settings (event-driven and switch model:
//!   tolerance; Moreau–Jean: step h), on each scene (default: Table 1 at u = 1.5 V from rest
//!   over 100 s, a stick-slip cycle). Every point keeps the full 0.01 s trace and the
//!   steady-state metrics, so the timed run is the run whose errors are shown.
//! * **Errors** against a tight reference, the event-driven solver at tol 1e-13:
//!   the steady-state metrics of the last complete cycle in `[metrics_from, t_end]` (period,
//!   max ω_l; `steady_rel` is the larger relative error) and max |Δω_l| over a transient
//!   window on the common grid. The reference's own error is estimated by one run at a
//!   tenfold tighter tolerance ([`ReferenceReport::check`]).
//! * **Run time**: the median of repeated runs (`std::time::Instant`), after one untimed
//!   warm-up; the work counters ([`rotor_model::Stats`]).
//! * **Output levels**: per solver, metrics-only (`Output::Metrics`, which skips the periods
//!   of a converged cycle), final-only (`Output::Final`) and the full trace
//!   (`Output::Grid { dt: 0.01 }`), all with metrics, timed in turn.
//! * **Peers**, run as subprocesses in the same run: a plain scipy `solve_ivp` implementation
//!   (`bench/peers/scipy_rotor.py`) compared at equal error, and Siconos' `MoreauJeanOSI`
//!   (`bench/peers/siconos_rotor.py`) compared per step at equal h. A peer whose answer does
//!   not agree with the reference within the scenario's agreement gate gets no ratio.
//!   A peer that is not installed is skipped with the reason.
//!
//! Nothing here asserts a speed: ratios are measured side by side and reported.

mod measure;
mod options;
mod peers;
mod report;

use rotor_model::{
    Model, Output, PairTolerance, Scenario, ScenarioError, Scene, SolveError, State, Stats,
};
use serde::Serialize;
use thiserror::Error;

pub use measure::{Errors, RefData, Timing, solver, time_at_error, timed};
pub use options::{BenchOptions, PeerOptions, SceneSpec, SolverKind, workspace_root};
pub use peers::{PeerMetrics, PeerOutput, PeerRun, available as peer_available};

use measure::{cycle_metrics, run_point, scene_at, window};

/// Why the benchmark could not run.
#[derive(Debug, Error)]
pub enum BenchError {
    /// The options are not admissible.
    #[error("invalid benchmark options: {0}")]
    Options(String),
    /// A scenario file could not be loaded.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The reference run failed.
    #[error("reference run of {scene} (event, tol {tol:e}) failed: {source}")]
    Reference {
        scene: String,
        tol: f64,
        #[source]
        source: SolveError,
    },
    /// The reference run gives no limit cycle, or no sample in the transient window.
    #[error(
        "reference run of {scene} gives no limit cycle in [metrics_from, t_end] or no sample \
         in the transient window; choose a stick-slip scene and windows inside [0, t_end]"
    )]
    NoReferenceCycle { scene: String },
    /// A run outside the ladders failed (output-level timing).
    #[error("{solver} at {setting_name} = {setting:e} on {scene} failed: {source}")]
    Solve {
        solver: &'static str,
        setting_name: &'static str,
        setting: f64,
        scene: String,
        #[source]
        source: SolveError,
    },
    /// A peer script failed (recorded in the report, not returned by [`run`]).
    #[error("peer {peer}: {detail}")]
    Peer { peer: String, detail: String },
    /// The report holds a non-finite number (a bug): nothing is written.
    #[error("the benchmark report holds {path} = {value}: not written (JSON has no NaN)")]
    NonFinite { path: String, value: f64 },
    /// The report could not be serialised (a bug).
    #[error("the benchmark report cannot be serialised: {0}")]
    Serialise(String),
}

/// The whole benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Per scene: reference and ladders.
    pub scenes: Vec<SceneReport>,
    /// Metrics-only vs full-trace run time per solver (first scene).
    pub output_levels: Vec<OutputLevel>,
    /// Peers (first scene).
    pub peers: Vec<PeerReport>,
    /// Where and how it was measured.
    pub environment: Environment,
}

/// Conditions of the measurement.
#[derive(Debug, Clone, Serialize)]
pub struct Environment {
    /// Cores the process may use.
    pub cores: usize,
    /// Whether the library was built with debug assertions (times are then not meaningful).
    pub debug_build: bool,
    /// Timed repetitions per point (median reported; fewer for long runs).
    pub repeats: usize,
    /// Timing budget per point (s).
    pub time_budget_s: f64,
    /// `/proc/loadavg` (1, 5, 15 min) when the run started and ended: a load above the core
    /// count means the times are inflated by other processes (the ratios less so: the
    /// minima-based ones are the least sensitive).
    pub load_start: Option<[f64; 3]>,
    pub load_end: Option<[f64; 3]>,
}

/// The 1, 5 and 15 minute load averages, where the system reports them.
fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

/// One scene: its reference and every ladder point.
#[derive(Debug, Clone, Serialize)]
pub struct SceneReport {
    pub name: String,
    pub description: String,
    pub u: f64,
    pub x0: [f64; 3],
    pub t_end: f64,
    pub metrics_from: f64,
    pub transient: [f64; 2],
    pub dt: f64,
    pub reference: ReferenceReport,
    pub points: Vec<LadderPoint>,
}

/// The reference run and the estimate of its own error.
#[derive(Debug, Clone, Serialize)]
pub struct ReferenceReport {
    pub solver: SolverKind,
    pub tol: f64,
    /// Period of the last complete cycle (s).
    pub period: f64,
    /// Max ω_l over that cycle (rad/s).
    pub omega_l_max: f64,
    /// One untimed run (s).
    pub seconds: f64,
    pub stats: Stats,
    /// Tolerance of the check run.
    pub check_tol: f64,
    /// Errors of the reference measured against the check run (swapped roles: the
    /// difference between the two, an estimate of the reference's own error).
    pub check: Option<Errors>,
    /// Why the check run failed, if it did.
    pub check_failure: Option<String>,
}

/// One solver at one accuracy setting.
#[derive(Debug, Clone, Serialize)]
pub struct LadderPoint {
    pub solver: SolverKind,
    /// `tol` or `h`.
    pub setting_name: &'static str,
    pub setting: f64,
    /// `None` if the run failed.
    pub timing: Option<Timing>,
    pub errors: Errors,
    pub stats: Stats,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// Metrics-only vs final-state-only vs full-trace run of one solver (all with metrics).
#[derive(Debug, Clone, Serialize)]
pub struct OutputLevel {
    pub solver: SolverKind,
    pub setting_name: &'static str,
    pub setting: f64,
    /// `Output::Metrics`: skips whole periods once the cycle has converged.
    pub metrics_only: Timing,
    /// `Output::Final`: the whole horizon, nothing kept.
    pub final_only: Timing,
    /// `Output::Grid { dt }`.
    pub full_trace: Timing,
    /// full_trace / metrics_only (medians).
    pub ratio: f64,
    /// full_trace / final_only (medians): what keeping the trace costs.
    pub final_ratio: f64,
    /// Samples and events the metrics-only run kept (0 and 0 when the level is honoured).
    pub metrics_only_samples: usize,
    pub metrics_only_events: usize,
    /// Samples the full-trace run kept.
    pub full_trace_samples: usize,
    /// Whole periods the metrics-only run skipped, and skips it undid.
    pub skipped_periods: u64,
    pub undone_skips: u64,
    /// Largest difference of a metric between the metrics-only and the full-trace run,
    /// relative to max(|m|, 1); `None` if they do not report the same kind of steady state.
    pub metrics_diff: Option<f64>,
    /// Whether the final-only run reports the same metrics and final state as the full trace
    /// (keeping output must not perturb the integration).
    pub same_answer: bool,
}

/// A peer: what it computed, whether it agrees, and how it compares.
#[derive(Debug, Clone, Serialize)]
pub struct PeerReport {
    /// `"scipy"` or `"siconos"`.
    pub name: String,
    /// `"ran"`, `"skipped"` (not installed or turned off) or `"failed"`.
    pub status: String,
    /// Why it was skipped or failed.
    pub reason: Option<String>,
    pub version: Option<String>,
    pub method: Option<String>,
    /// `"tol"` (rtol = atol) or `"h"`.
    pub setting_name: &'static str,
    pub points: Vec<PeerPoint>,
    /// Agreement of the peer's most accurate run with the reference.
    pub agreement: Option<Agreement>,
    /// Run time at equal error vs a Rust solver (scipy vs event).
    pub ratios: Vec<Ratio>,
    /// Time per step at equal h vs rotor-moreau (Siconos).
    pub per_step: Vec<PerStep>,
}

/// One setting of a peer.
#[derive(Debug, Clone, Serialize)]
pub struct PeerPoint {
    pub setting: f64,
    pub timing: Option<Timing>,
    pub errors: Errors,
    pub steps: Option<u64>,
    pub rhs_evals: Option<u64>,
    pub failure: Option<String>,
}

/// Whether a peer computes the same answer as the reference.
#[derive(Debug, Clone, Serialize)]
pub struct Agreement {
    /// The peer setting checked (its most accurate one).
    pub setting: f64,
    pub period_rel: Option<f64>,
    pub omega_l_max_rel: Option<f64>,
    pub transient_max: Option<f64>,
    /// Gates, from the scenario file's tolerance table.
    pub gate_period_rel: f64,
    pub gate_omega_l_rel: f64,
    pub gate_transient_max: f64,
    /// Which table entry the gates come from.
    pub gate_origin: String,
    pub agrees: bool,
}

/// Peer time / Rust time at the peer's error.
#[derive(Debug, Clone, Serialize)]
pub struct Ratio {
    pub against: SolverKind,
    /// `"steady_rel"` or `"transient_max"`.
    pub error_kind: &'static str,
    pub peer_setting: f64,
    pub error: f64,
    pub peer_seconds: f64,
    /// The Rust solver's time at that error (interpolated on its work-precision front).
    pub rust_seconds: f64,
    /// The Rust solver's fastest point is already more accurate: `rust_seconds` is an upper
    /// bound, the ratio a lower bound.
    pub rust_is_bound: bool,
    /// peer_seconds / rust_seconds (medians).
    pub ratio: f64,
    /// The same from the fastest runs of each (less sensitive to other load on the machine).
    pub ratio_of_minima: Option<f64>,
}

/// Time per step of Siconos vs rotor-moreau at one h.
#[derive(Debug, Clone, Serialize)]
pub struct PerStep {
    pub h: f64,
    pub peer_s_per_step: f64,
    pub moreau_s_per_step: f64,
    /// peer / moreau time per step (medians).
    pub ratio: f64,
    /// The same from the fastest runs of each.
    pub ratio_of_minima: f64,
    pub peer_errors: Errors,
    pub moreau_errors: Errors,
}

/// A loaded scene with its reference.
struct Loaded {
    scenario: Scenario,
    spec: SceneSpec,
    base: Scene,
    refd: RefData,
}

fn validate(opts: &BenchOptions) -> Result<(), BenchError> {
    let bad = |m: String| Err(BenchError::Options(m));
    if opts.scenes.is_empty() {
        return bad("no scene".into());
    }
    for s in &opts.scenes {
        let [a, b] = s.transient;
        if !(s.t_end > 0.0 && s.metrics_from >= 0.0 && s.metrics_from < s.t_end) {
            return bad(format!(
                "{}: need 0 <= metrics_from < t_end (metrics_from = {}, t_end = {})",
                s.scenario.display(),
                s.metrics_from,
                s.t_end
            ));
        }
        if !(0.0 <= a && a < b && b <= s.t_end && s.dt > 0.0) {
            return bad(format!(
                "{}: need 0 <= transient[0] < transient[1] <= t_end and dt > 0 (transient = \
                 [{a}, {b}], dt = {})",
                s.scenario.display(),
                s.dt
            ));
        }
    }
    let ladders = opts
        .ladders
        .iter()
        .map(|(k, v)| (format!("ladders[{}]", k.name()), v));
    let peers = [
        ("peers.scipy_tols".to_string(), &opts.peers.scipy_tols),
        ("peers.siconos_hs".to_string(), &opts.peers.siconos_hs),
    ];
    for (name, v) in ladders.chain(peers) {
        if let Some(x) = v.iter().find(|x| !(**x > 0.0 && x.is_finite())) {
            return bad(format!("{name} holds {x}: every setting must be positive"));
        }
    }
    if !(opts.reference_tol > 0.0 && opts.reference_check_tol > 0.0) {
        return bad("reference tolerances must be positive".into());
    }
    if opts.repeats == 0 {
        return bad("repeats must be at least 1".into());
    }
    Ok(())
}

fn load(
    opts: &BenchOptions,
    spec: &SceneSpec,
    progress: &mut impl FnMut(&str),
) -> Result<(Loaded, ReferenceReport), BenchError> {
    let scenario = rotor_compare::load_scenario(&spec.scenario)?;
    let base = Scene {
        u: scenario.u,
        x0: scenario.x0,
        t_end: spec.t_end,
        tol: opts.reference_tol,
        h: Scene::default().h,
        output: Output::Grid { dt: spec.dt },
        metrics_from: Some(spec.metrics_from),
    };
    progress(&format!(
        "{}: reference (event, tol {:e})",
        scenario.name, opts.reference_tol
    ));
    let ev = solver(SolverKind::EVENT);
    let (tr, timing) = timed(1, 0.0, || ev.simulate(&scenario.model, &base)).map_err(|source| {
        BenchError::Reference {
            scene: scenario.name.clone(),
            tol: opts.reference_tol,
            source,
        }
    })?;
    let refd =
        RefData::new(&tr, spec.transient, spec.dt).ok_or_else(|| BenchError::NoReferenceCycle {
            scene: scenario.name.clone(),
        })?;
    progress(&format!(
        "{}: reference check (event, tol {:e})",
        scenario.name, opts.reference_check_tol
    ));
    let check_scene = Scene {
        tol: opts.reference_check_tol,
        ..base.clone()
    };
    let (check, check_failure) = match ev.simulate(&scenario.model, &check_scene) {
        Ok(c) => match RefData::new(&c, spec.transient, spec.dt) {
            // The reference measured against the tighter run.
            Some(cd) => (
                Some(cd.errors(
                    cycle_metrics(tr.metrics.as_ref()),
                    &window(&tr, spec.transient, spec.dt),
                )),
                None,
            ),
            None => (None, Some("the check run gives no cycle".into())),
        },
        Err(e) => (None, Some(e.to_string())),
    };
    let reference = ReferenceReport {
        solver: SolverKind::EVENT,
        tol: opts.reference_tol,
        period: refd.period,
        omega_l_max: refd.omega_l_max,
        seconds: timing.median_s,
        stats: tr.stats,
        check_tol: opts.reference_check_tol,
        check,
        check_failure,
    };
    Ok((
        Loaded {
            scenario,
            spec: spec.clone(),
            base,
            refd,
        },
        reference,
    ))
}

fn ladders(opts: &BenchOptions, l: &Loaded, progress: &mut impl FnMut(&str)) -> Vec<LadderPoint> {
    let mut points = Vec::new();
    for (kind, ladder) in &opts.ladders {
        let kind = *kind;
        for &setting in ladder {
            progress(&format!(
                "{}: {} {} = {setting:e}",
                l.scenario.name,
                kind.name(),
                kind.setting_name()
            ));
            let scene = scene_at(&l.base, kind, setting, l.base.output);
            let point = match run_point(
                kind,
                &scene,
                &l.scenario.model,
                &l.refd,
                l.spec.transient,
                opts.repeats,
                opts.time_budget,
            ) {
                Ok((tr, timing, errors)) => LadderPoint {
                    solver: kind,
                    setting_name: kind.setting_name(),
                    setting,
                    timing: Some(timing),
                    errors,
                    stats: tr.stats,
                    failure: None,
                },
                Err(e) => LadderPoint {
                    solver: kind,
                    setting_name: kind.setting_name(),
                    setting,
                    timing: None,
                    errors: Errors::default(),
                    stats: Stats::default(),
                    failure: Some(e.to_string()),
                },
            };
            points.push(point);
        }
    }
    points
}

/// A run's result with its timing.
type TimedRun<T> = (T, Timing);

/// Times the runs in turn (after one warm-up each), `n` rounds within the budget, so that
/// their ratios are measured side by side.
fn timed_together<T, const N: usize>(
    repeats: usize,
    budget: f64,
    runs: [&dyn Fn() -> Result<T, SolveError>; N],
) -> Result<[TimedRun<T>; N], SolveError> {
    let t0 = std::time::Instant::now();
    let mut first = Vec::with_capacity(N);
    for r in runs {
        first.push(r()?);
    }
    let once = t0.elapsed().as_secs_f64();
    let n = ((budget / once.max(1e-9)).floor() as usize).clamp(1, repeats.max(1));
    let mut times = vec![Vec::with_capacity(n); N];
    for _ in 0..n {
        for (r, t) in runs.iter().zip(&mut times) {
            let t0 = std::time::Instant::now();
            std::hint::black_box(r()?);
            t.push(t0.elapsed().as_secs_f64());
        }
    }
    let mut out = first
        .into_iter()
        .zip(times)
        .map(|(r, t)| (r, Timing::of(t)));
    Ok(std::array::from_fn(|_| out.next().expect("N runs")))
}

fn output_levels(
    opts: &BenchOptions,
    l: &Loaded,
    progress: &mut impl FnMut(&str),
) -> Result<Vec<OutputLevel>, BenchError> {
    let mut v = Vec::new();
    for (kind, _) in &opts.ladders {
        let kind = *kind;
        let setting = kind.info().default;
        progress(&format!(
            "{}: output levels, {} {} = {setting:e}",
            l.scenario.name,
            kind.name(),
            kind.setting_name()
        ));
        let s = solver(kind);
        let met = scene_at(&l.base, kind, setting, Output::Metrics);
        let fin = scene_at(&l.base, kind, setting, Output::Final);
        let full = scene_at(&l.base, kind, setting, Output::Grid { dt: l.spec.dt });
        let model = &l.scenario.model;
        let [(a, ta), (f, tf), (b, tb)] = timed_together(
            opts.repeats,
            3.0 * opts.time_budget,
            [
                &|| s.simulate(model, &met),
                &|| s.simulate(model, &fin),
                &|| s.simulate(model, &full),
            ],
        )
        .map_err(|source| BenchError::Solve {
            solver: kind.name(),
            setting_name: kind.setting_name(),
            setting,
            scene: l.scenario.name.clone(),
            source,
        })?;
        v.push(OutputLevel {
            solver: kind,
            setting_name: kind.setting_name(),
            setting,
            metrics_only: ta,
            final_only: tf,
            full_trace: tb,
            ratio: tb.median_s / ta.median_s,
            final_ratio: tb.median_s / tf.median_s,
            metrics_only_samples: a.samples.len(),
            metrics_only_events: a.events.len(),
            full_trace_samples: b.samples.len(),
            skipped_periods: a.stats.skipped_periods,
            undone_skips: a.stats.undone_skips,
            metrics_diff: metrics_difference(&a, &b),
            same_answer: f.metrics == b.metrics && f.x_final == b.x_final,
        });
    }
    Ok(v)
}

/// Largest `|m_a − m_b| / max(|m|, 1)` over the metrics of two runs; `None` if they differ in
/// kind or one has none.
fn metrics_difference(a: &rotor_model::Trajectory, b: &rotor_model::Trajectory) -> Option<f64> {
    match (a.metrics, b.metrics) {
        (Some(ma), Some(mb)) if ma.kind() == mb.kind() => Some(
            ma.values()
                .into_iter()
                .zip(mb.values())
                .map(|((_, x), (_, y))| (x - y).abs() / x.abs().max(y.abs()).max(1.0))
                .fold(0.0, f64::max),
        ),
        _ => None,
    }
}

fn x0_arg(x: &State) -> String {
    format!("{:e},{:e},{:e}", x[0], x[1], x[2])
}

/// Common command-line arguments of the peer scripts.
fn peer_args(l: &Loaded, repeats: usize, budget: f64) -> Vec<String> {
    let s = &l.spec;
    vec![
        "--params".into(),
        l.scenario.params_path.display().to_string(),
        "--u".into(),
        format!("{:e}", l.scenario.u),
        "--x0".into(),
        x0_arg(&l.scenario.x0),
        "--t-end".into(),
        format!("{:e}", s.t_end),
        "--metrics-from".into(),
        format!("{:e}", s.metrics_from),
        "--transient".into(),
        format!("{:e},{:e}", s.transient[0], s.transient[1]),
        "--dt".into(),
        format!("{:e}", s.dt),
        "--repeat".into(),
        repeats.to_string(),
        "--time-budget".into(),
        format!("{budget:e}"),
    ]
}

fn peer_points(l: &Loaded, out: &PeerOutput) -> Vec<PeerPoint> {
    out.runs
        .iter()
        .map(|r| {
            let samples: Vec<(f64, f64)> =
                r.t.iter().copied().zip(r.omega_l.iter().copied()).collect();
            let ok = r.failure.is_none() && !r.seconds.is_empty();
            PeerPoint {
                setting: r.setting,
                timing: ok.then(|| Timing::of(r.seconds.clone())),
                errors: if ok {
                    l.refd
                        .errors(r.metrics.map(|m| (m.period, m.omega_l_max)), &samples)
                } else {
                    Errors::default()
                },
                steps: r.steps,
                rhs_evals: r.rhs_evals,
                failure: r.failure.clone(),
            }
        })
        .collect()
}

fn agreement(points: &[PeerPoint], gate: Option<(&str, PairTolerance)>) -> Option<Agreement> {
    let best = points
        .iter()
        .filter(|p| p.timing.is_some())
        .min_by(|a, b| a.setting.total_cmp(&b.setting))?;
    let (origin, tol) = gate?;
    let gp = tol.period_rel?;
    let gw = tol.omega_l_rel?;
    let gt = tol.transient_max?;
    let e = &best.errors;
    let agrees = e.period_rel.is_some_and(|e| e <= gp)
        && e.omega_l_max_rel.is_some_and(|e| e <= gw)
        && e.transient_max.is_some_and(|e| e <= gt);
    Some(Agreement {
        setting: best.setting,
        period_rel: e.period_rel,
        omega_l_max_rel: e.omega_l_max_rel,
        transient_max: e.transient_max,
        gate_period_rel: gp,
        gate_omega_l_rel: gw,
        gate_transient_max: gt,
        gate_origin: origin.to_string(),
        agrees,
    })
}

fn skipped(name: &str, setting_name: &'static str, status: &str, reason: String) -> PeerReport {
    PeerReport {
        name: name.into(),
        status: status.into(),
        reason: Some(reason),
        version: None,
        method: None,
        setting_name,
        points: Vec::new(),
        agreement: None,
        ratios: Vec::new(),
        per_step: Vec::new(),
    }
}

/// One peer script to launch: whether it is on, its interpreter and the module that must
/// import, its script and ladder flag, and the scenario's tolerance pair it must agree within.
struct PeerLaunch<'a> {
    name: &'static str,
    setting_name: &'static str,
    enabled: bool,
    python: &'a str,
    module: &'static str,
    script: &'static str,
    flag: &'static str,
    settings: &'a [f64],
    pair: &'static str,
}

/// What a peer that ran gave: its output, the points measured against the reference, and
/// its agreement with the reference within the scenario's gate.
struct Launched {
    out: PeerOutput,
    points: Vec<PeerPoint>,
    agreement: Option<Agreement>,
}

/// Runs a peer script if it is turned on and its interpreter has the module; `Err` is the
/// report of a peer that was skipped or failed.
fn launch_peer(
    pl: &PeerLaunch,
    opts: &BenchOptions,
    l: &Loaded,
    progress: &mut impl FnMut(&str),
) -> Result<Launched, Box<PeerReport>> {
    let (name, setting) = (pl.name, pl.setting_name);
    if !pl.enabled {
        return Err(Box::new(skipped(
            name,
            setting,
            "skipped",
            "turned off in the options".into(),
        )));
    }
    if let Err(why) = peers::available(pl.python, pl.module) {
        progress(&format!("{name} peer skipped: {why}"));
        return Err(Box::new(skipped(name, setting, "skipped", why)));
    }
    let list = peers::list(pl.settings);
    progress(&format!(
        "{}: {name} peer, {setting} = {list}",
        l.scenario.name
    ));
    let mut args = peer_args(l, opts.repeats, opts.time_budget);
    args.extend([pl.flag.to_string(), list]);
    let out = peers::run_script(pl.python, &opts.peers.dir.join(pl.script), &args)
        .map_err(|e| Box::new(skipped(name, setting, "failed", e.to_string())))?;
    let points = peer_points(l, &out);
    let origin = format!("scenario [tolerance.{}]", pl.pair);
    let gate = l
        .scenario
        .tolerance
        .get(pl.pair)
        .map(|t| (origin.as_str(), *t));
    let agreement = agreement(&points, gate);
    Ok(Launched {
        out,
        points,
        agreement,
    })
}

fn scipy_peer(
    opts: &BenchOptions,
    l: &Loaded,
    points: &[LadderPoint],
    progress: &mut impl FnMut(&str),
) -> PeerReport {
    let p = &opts.peers;
    let launch = PeerLaunch {
        name: "scipy",
        setting_name: "tol",
        enabled: p.scipy,
        python: &p.python,
        module: "scipy",
        script: "scipy_rotor.py",
        flag: "--tol",
        settings: &p.scipy_tols,
        pair: "event-switch",
    };
    let Launched {
        out,
        points: pts,
        agreement,
    } = match launch_peer(&launch, opts, l, progress) {
        Ok(x) => x,
        Err(report) => return *report,
    };
    let mut ratios = Vec::new();
    if agreement.as_ref().is_some_and(|a| a.agrees) {
        for (kind_name, pick) in [
            (
                "steady_rel",
                (|e: &Errors| e.steady_rel) as fn(&Errors) -> Option<f64>,
            ),
            ("transient_max", |e: &Errors| e.transient_max),
        ] {
            let curve = |min: bool| -> Vec<(f64, f64)> {
                points
                    .iter()
                    .filter(|q| q.solver == SolverKind::EVENT)
                    .filter_map(|q| {
                        let t = q.timing?;
                        Some((pick(&q.errors)?, if min { t.min_s } else { t.median_s }))
                    })
                    .collect()
            };
            let (median_curve, min_curve) = (curve(false), curve(true));
            for pp in &pts {
                let (Some(e), Some(t)) = (pick(&pp.errors), pp.timing) else {
                    continue;
                };
                if let Some((rt, bound)) = time_at_error(&median_curve, e) {
                    ratios.push(Ratio {
                        against: SolverKind::EVENT,
                        error_kind: kind_name,
                        peer_setting: pp.setting,
                        error: e,
                        peer_seconds: t.median_s,
                        rust_seconds: rt,
                        rust_is_bound: bound,
                        ratio: t.median_s / rt,
                        ratio_of_minima: time_at_error(&min_curve, e).map(|(rm, _)| t.min_s / rm),
                    });
                }
            }
        }
    }
    PeerReport {
        name: "scipy".into(),
        status: "ran".into(),
        reason: None,
        version: Some(out.version),
        method: Some(out.method),
        setting_name: "tol",
        points: pts,
        agreement,
        ratios,
        per_step: Vec::new(),
    }
}

fn siconos_peer(opts: &BenchOptions, l: &Loaded, progress: &mut impl FnMut(&str)) -> PeerReport {
    let p = &opts.peers;
    let launch = PeerLaunch {
        name: "siconos",
        setting_name: "h",
        enabled: p.siconos,
        python: &p.siconos_python,
        module: "siconos.kernel",
        script: "siconos_rotor.py",
        flag: "--h",
        settings: &p.siconos_hs,
        pair: "event-moreau",
    };
    let Launched {
        out,
        points: pts,
        agreement,
    } = match launch_peer(&launch, opts, l, progress) {
        Ok(x) => x,
        Err(report) => return *report,
    };
    let mut per_step = Vec::new();
    for pp in &pts {
        let (Some(t), Some(steps)) = (pp.timing, pp.steps) else {
            continue;
        };
        progress(&format!(
            "{}: moreau at the siconos step h = {:e}",
            l.scenario.name, pp.setting
        ));
        let scene = scene_at(&l.base, SolverKind::MOREAU, pp.setting, l.base.output);
        if let Ok((tr, mt, me)) = run_point(
            SolverKind::MOREAU,
            &scene,
            &l.scenario.model,
            &l.refd,
            l.spec.transient,
            opts.repeats,
            opts.time_budget,
        ) {
            let peer_s = t.median_s / steps as f64;
            let ours = mt.median_s / tr.stats.steps as f64;
            per_step.push(PerStep {
                h: pp.setting,
                peer_s_per_step: peer_s,
                moreau_s_per_step: ours,
                ratio: peer_s / ours,
                ratio_of_minima: (t.min_s / steps as f64) / (mt.min_s / tr.stats.steps as f64),
                peer_errors: pp.errors,
                moreau_errors: me,
            });
        }
    }
    PeerReport {
        name: "siconos".into(),
        status: "ran".into(),
        reason: None,
        version: Some(out.version),
        method: Some(out.method),
        setting_name: "h",
        points: pts,
        agreement,
        ratios: Vec::new(),
        per_step,
    }
}

/// Runs the whole benchmark, reporting what it is doing through `progress` (one line per
/// step, for a CLI's stderr).
pub fn run(opts: &BenchOptions, mut progress: impl FnMut(&str)) -> Result<BenchReport, BenchError> {
    validate(opts)?;
    let load_start = load_average();
    let mut scenes = Vec::new();
    let mut first: Option<(Loaded, Vec<LadderPoint>)> = None;
    for spec in &opts.scenes {
        let (l, reference) = load(opts, spec, &mut progress)?;
        let points = ladders(opts, &l, &mut progress);
        scenes.push(SceneReport {
            name: l.scenario.name.clone(),
            description: l.scenario.description.clone(),
            u: l.scenario.u,
            x0: [l.scenario.x0[0], l.scenario.x0[1], l.scenario.x0[2]],
            t_end: spec.t_end,
            metrics_from: spec.metrics_from,
            transient: spec.transient,
            dt: spec.dt,
            reference,
            points: points.clone(),
        });
        if first.is_none() {
            first = Some((l, points));
        }
    }
    let (l, points) = first.ok_or_else(|| BenchError::Options("no scene".into()))?;
    let output_levels = if opts.output_levels {
        output_levels(opts, &l, &mut progress)?
    } else {
        Vec::new()
    };
    let peers = vec![
        scipy_peer(opts, &l, &points, &mut progress),
        siconos_peer(opts, &l, &mut progress),
    ];
    Ok(BenchReport {
        scenes,
        output_levels,
        peers,
        environment: Environment {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            debug_build: cfg!(debug_assertions),
            repeats: opts.repeats,
            time_budget_s: opts.time_budget,
            load_start,
            load_end: load_average(),
        },
    })
}

/// The model and base scene of a scene spec (for benches and tests that drive the solvers
/// directly): the spec's horizon, full trace on its grid, metrics on.
pub fn scene_of(spec: &SceneSpec) -> Result<(Model, Scene), BenchError> {
    let sc = rotor_compare::load_scenario(&spec.scenario)?;
    Ok((
        sc.model,
        Scene {
            u: sc.u,
            x0: sc.x0,
            t_end: spec.t_end,
            output: Output::Grid { dt: spec.dt },
            metrics_from: Some(spec.metrics_from),
            ..Scene::default()
        },
    ))
}
