//! Work-precision benchmark of the rotor solvers.
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
//!   warm-up; the work counters ([`rotor_model::seam::Stats`]).
//! * **Output levels**: per solver, metrics-only (`Output::Metrics`, which skips the periods
//!   of a converged cycle), final-only (`Output::Final`) and the full trace
//!   (`Output::Grid { dt: 0.01 }`), all with metrics, timed in turn.
//! * **Clients**: external solvers through the job-file protocol ([`crate::protocol`]; BENCHMARK.md),
//!   each run in its own process with a timeout, over its ladder on every scene, graded as
//!   `rotor check` grades a trace, placed beside the three solvers, with time ratios at equal
//!   error (in-process and whole-process) and, for a fixed-step client that reports its
//!   steps, time per step against rotor-moreau. The repository's peers, a plain scipy
//!   `solve_ivp` (`bench/peers/scipy_rotor.py`), Siconos' `MoreauJeanOSI`
//!   (`bench/peers/siconos_rotor.py`) and GNU Octave's `ode45` with event functions
//!   (`bench/peers/octave_rotor.m`), are clients of the same protocol, run when installed.
//!   A failure (crash, non-zero exit, timeout, unusable trace, a trace failing the loose
//!   gate) is recorded with its reason; the bench goes on.
//! * **Performance profile** ([`profile`]) of the solvers and clients over the scenes.
//!
//! Nothing here asserts a speed: ratios are measured side by side and reported.

#![warn(missing_docs)]

pub mod chain_tier;
mod clients;
pub mod colors;
mod figures;
mod ladder;
mod levels;
mod measure;
pub mod merge;
mod options;
mod peers;
pub mod profile;
mod report;
mod results;
pub mod scaling;
mod word;

use rotor_model::Model;
use rotor_model::scenario::ScenarioError;
use rotor_model::seam::{Output, Scene, SolveError};
use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use crate::protocol::ClientSpec;
pub use crate::protocol::peers::available as peer_available;
pub use crate::protocol::peers::octave_available;
pub use clients::job_for_scenario;
pub use clients::{
    ClientPoint, ClientReport, ClientScene, ClientStatus, Failure, FailureKind, Overhead, PerStep,
    Ratio,
};
pub use figures::Figure;
pub use ladder::{LadderPoint, ReferenceReport, SceneReport};
pub use levels::OutputLevel;
pub use measure::{Errors, RefData, SteadyRef, Timing, solver, time_at_error, timed};
pub use merge::{ShardInfo, merge};
pub use options::{
    BenchOptions, LEAD_SCENES, PeerOptions, SceneSpec, SolverKind, Tier, select, suite, suite_dir,
    workspace_root,
};
pub use profile::Profile;

use ladder::{Loaded, ladders, load};
use levels::output_levels;

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
        /// The scene's name.
        scene: String,
        /// The reference's tolerance.
        tol: f64,
        /// Why the run failed.
        #[source]
        source: SolveError,
    },
    /// The reference run gives no steady state, or no sample in the transient window.
    #[error(
        "reference run of {scene} gives no steady state in [metrics_from, t_end] or no sample \
         in the transient window; choose windows inside [0, t_end]"
    )]
    NoReferenceCycle {
        /// The scene's name.
        scene: String,
    },
    /// A run outside the ladders failed (output-level timing).
    #[error("{solver} at {setting_name} = {setting:e} on {scene} failed: {source}")]
    Solve {
        /// The solver's name.
        solver: &'static str,
        /// `tol` or `h`.
        setting_name: &'static str,
        /// Its value (h in s).
        setting: f64,
        /// The scene's name.
        scene: String,
        /// Why the run failed.
        #[source]
        source: SolveError,
    },
    /// The clients' working directory cannot be made.
    #[error("{0}")]
    Work(String),
    /// The report holds a non-finite number (a bug): nothing is written.
    #[error("the benchmark report holds {path} = {value}: not written (JSON has no NaN)")]
    NonFinite {
        /// Where in the report, as a dotted path with indices (`scenes[0].ladders[1]...`).
        path: String,
        /// The value found there (NaN or ±∞).
        value: f64,
    },
    /// Shard reports that do not fit together (`rotor bench --merge`).
    #[error("{0}")]
    Merge(String),
    /// The report could not be serialised (a bug).
    #[error("the benchmark report cannot be serialised: {0}")]
    Serialise(String),
}

/// The whole benchmark's result.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchReport {
    /// The suite's version ([`crate::grade::check::BENCHMARK`]) the points were graded against.
    #[serde(default)]
    pub benchmark: String,
    /// Per scene: reference and ladders.
    pub scenes: Vec<SceneReport>,
    /// Metrics-only vs full-trace run time per solver (first scene).
    pub output_levels: Vec<OutputLevel>,
    /// The peers and the external clients, over every scene.
    pub clients: Vec<ClientReport>,
    /// The performance profile of solvers and clients over the scenes (the full tier: every
    /// scene of the run).
    pub profile: Profile,
    /// The same over the run's table1-tier scenes alone, when the run holds scenes of both
    /// tiers: a solver that treats only the lower disc's stick is ranked there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile_table1: Option<Profile>,
    /// Where and how it was measured.
    pub environment: Environment,
    /// Which part of the suite this report holds (`rotor bench --shard I/N`); absent from a
    /// whole run's report and from shards joined by [`merge()`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardInfo>,
}

/// Conditions of the measurement.
#[derive(Debug, Clone, Serialize, Deserialize)]
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
    /// The same when the run ended.
    pub load_end: Option<[f64; 3]>,
    /// External clients run side by side (`BenchOptions::jobs`; 1 in reports written before
    /// the option existed).
    #[serde(default = "one")]
    pub jobs: usize,
}

fn one() -> usize {
    1
}

/// The 1, 5 and 15 minute load averages, where the system reports them.
fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

fn validate(opts: &BenchOptions) -> Result<(), BenchError> {
    let bad = |m: String| Err(BenchError::Options(m));
    if opts.scenes.is_empty() {
        return bad("no scene".into());
    }
    if let Some(s) = opts.shard
        && s.n > opts.scenes.len()
    {
        return bad(format!(
            "--shard {}/{}: the suite has {n} scene(s), so N can be at most {n}",
            s.i,
            s.n,
            n = opts.scenes.len()
        ));
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
        ("peers.octave_tols".to_string(), &opts.peers.octave_tols),
        ("client_tols".to_string(), &opts.client_tols),
        ("client_hs".to_string(), &opts.client_hs),
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
    if !(opts.timeout > 0.0 && opts.timeout.is_finite()) {
        return bad(format!(
            "timeout = {}: must be positive and finite",
            opts.timeout
        ));
    }
    let mut names: Vec<&str> = opts.clients.iter().map(|c| c.name.as_str()).collect();
    names.extend([
        "scipy",
        "scipy-radau",
        "scipy-bdf",
        "scipy-lsoda",
        "siconos",
        "octave",
    ]);
    names.extend(rotor_analysis::solvers::SOLVERS.map(SolverKind::name));
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return bad(format!("two solvers or clients named {:?}", w[0]));
    }
    Ok(())
}

/// Runs the whole benchmark, reporting what it is doing through `progress` (one line per
/// step, for a CLI's stderr).
pub fn run(opts: &BenchOptions, mut progress: impl FnMut(&str)) -> Result<BenchReport, BenchError> {
    validate(opts)?;
    let shard = opts.shard.unwrap_or(crate::jobs::sweep::Shard::ALL);
    let shard_info = opts.shard.map(|s| merge::shard_info(opts, s));
    // The first scene of the suite is shard 1's: the output levels, measured on it, are
    // that shard's alone, so that the joined report holds them once.
    let mut opts = std::borrow::Cow::Borrowed(opts);
    if shard.i != 1 {
        opts.to_mut().output_levels = false;
    }
    let opts = &*opts;
    let load_start = load_average();
    let mut scenes = Vec::new();
    let mut loaded: Vec<(Loaded, Vec<LadderPoint>)> = Vec::new();
    for spec in shard.indices(opts.scenes.len()).map(|k| &opts.scenes[k]) {
        let (l, reference) = load(opts, spec, &mut progress)?;
        let points = ladders(opts, &l, &mut progress);
        scenes.push(SceneReport {
            name: l.scenario.name.clone(),
            tier: Tier::of(&l.scenario).name().to_owned(),
            description: l.scenario.description.clone(),
            u: l.scenario.u,
            x0: l.scenario.x0.clone(),
            t_end: spec.t_end,
            metrics_from: spec.metrics_from,
            transient: spec.transient,
            dt: spec.dt,
            reference,
            points: points.clone(),
        });
        loaded.push((l, points));
    }
    let (l, _) = loaded
        .first()
        .ok_or_else(|| BenchError::Options("no scene".into()))?;
    let output_levels = if opts.output_levels {
        output_levels(opts, l, &mut progress)?
    } else {
        Vec::new()
    };
    // One directory per run (runs may share a process: tests run in parallel).
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let work = opts.keep.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("rotor-bench-{}-{n}", std::process::id()))
    });
    std::fs::create_dir_all(&work)
        .map_err(|e| BenchError::Work(format!("{}: cannot create: {e}", work.display())))?;
    let mut launches = peers::peers(opts, &mut progress);
    launches.extend(opts.clients.iter().map(|spec| {
        let ladder = if spec.fixed_step {
            &opts.client_hs
        } else {
            &opts.client_tols
        };
        Ok((spec.clone(), ladder.clone()))
    }));
    let clients = run_clients(launches, opts, &loaded, &work, &mut progress);
    if opts.keep.is_none() {
        let _ = std::fs::remove_dir_all(&work);
    }
    let (profile, profile_table1) = profile::by_tier(&scenes, &clients);
    Ok(BenchReport {
        benchmark: crate::grade::check::BENCHMARK.to_owned(),
        scenes,
        output_levels,
        clients,
        profile,
        profile_table1,
        environment: Environment {
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            debug_build: cfg!(debug_assertions),
            repeats: opts.repeats,
            time_budget_s: opts.time_budget,
            load_start,
            load_end: load_average(),
            jobs: opts.jobs.max(1),
        },
        shard: shard_info,
    })
}

/// Runs every client that is not skipped over its ladder, `opts.jobs` clients side by side
/// (each on its own thread, its runs one after the other), and returns the reports in the
/// launches' order. The workers' progress lines reach `progress` on this thread.
fn run_clients(
    launches: Vec<peers::PeerLaunch>,
    opts: &BenchOptions,
    loaded: &[(Loaded, Vec<LadderPoint>)],
    work: &std::path::Path,
    progress: &mut impl FnMut(&str),
) -> Vec<ClientReport> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let reports: Vec<Mutex<Option<ClientReport>>> =
        launches.iter().map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    std::thread::scope(|scope| {
        for _ in 0..opts.jobs.max(1).min(launches.len()) {
            let tx = tx.clone();
            let (launches, reports, next) = (&launches, &reports, &next);
            scope.spawn(move || {
                let mut say = |m: &str| {
                    let _ = tx.send(m.to_owned());
                };
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(launch) = launches.get(k) else {
                        break;
                    };
                    let r = match launch {
                        Ok((spec, ladder)) => {
                            clients::run(spec, ladder, opts, loaded, work, &mut say)
                        }
                        Err(skipped) => (**skipped).clone(),
                    };
                    *reports[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                }
            });
        }
        drop(tx);
        for m in rx {
            progress(&m);
        }
    });
    reports
        .into_iter()
        .filter_map(|r| r.into_inner().unwrap_or_else(|e| e.into_inner()))
        .collect()
}

/// The model and base scene of a scene spec (for benches and tests that drive the solvers
/// directly): the spec's horizon, full trace on its grid, metrics on.
pub fn scene_of(spec: &SceneSpec) -> Result<(Model, Scene), BenchError> {
    let sc = rotor_analysis::solvers::load_scenario(&spec.scenario)?;
    Ok((
        sc.model,
        Scene {
            u: sc.u,
            input: sc.input.clone(),
            x0: sc.x0.clone(),
            t_end: spec.t_end,
            output: Output::Grid { dt: spec.dt },
            metrics_from: Some(spec.metrics_from),
            ..Scene::default()
        },
    ))
}
