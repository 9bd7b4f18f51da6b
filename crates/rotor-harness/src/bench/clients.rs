//! External solvers (and the repository's peers) through the job-file protocol
//! ([`crate::protocol`]): each over its ladder on each scene, graded as `rotor check` grades a
//! trace, placed beside the three solvers, with the ratios at equal error.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::grade::check::{CheckError, Level, check};
use crate::grade::gridmetrics::{StickExit, grid_metrics};
use crate::grade::trace::{read_events, read_trace};
use crate::protocol::{ClientSays, ClientSpec, Ended, Job, RunOutput, run_client, tail};
use serde::{Deserialize, Serialize};

use crate::bench::ladder::{LadderPoint, Loaded};
use crate::bench::measure::{Errors, SteadyRef, Timing, run_point, scene_at, time_at_error};
use crate::bench::options::{BenchOptions, SceneSpec, SolverKind};

/// Why a run gave no usable point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// The command could not be started.
    Spawn,
    /// It was killed by a signal.
    Crash,
    /// It exited non-zero.
    Exit,
    /// It ran past the timeout.
    Timeout,
    /// Its trace (or events file) cannot be graded: missing, malformed, off the grid.
    Unusable,
    /// Its trace fails the scenario's loose gate (the point is still placed).
    FailsGate,
    /// Not run: an earlier setting of the same client on this scene timed out.
    Skipped,
}

impl FailureKind {
    /// The report's and the JSON's name (`"fails_gate"`).
    pub fn as_str(self) -> &'static str {
        match self {
            FailureKind::Spawn => "spawn",
            FailureKind::Crash => "crash",
            FailureKind::Exit => "exit",
            FailureKind::Timeout => "timeout",
            FailureKind::Unusable => "unusable",
            FailureKind::FailsGate => "fails_gate",
            FailureKind::Skipped => "skipped",
        }
    }
}

/// A run's failure with its reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// What kind of failure.
    pub kind: FailureKind,
    /// The reason: the exit status, the grade's error, the tail of standard error, ...
    pub detail: String,
}

/// One setting of a client on one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClientPoint {
    /// The client's tolerance, or its step h (s).
    pub setting: f64,
    /// Wall time of the whole process (from the spawn to the exit).
    pub wall: Option<Timing>,
    /// The client's own in-process time (`solve_seconds`), when every timed run gave one.
    pub solve: Option<Timing>,
    /// Its errors against the reference, measured as the Rust solvers' are.
    pub errors: Errors,
    /// The steps it reported taking.
    pub steps: Option<u64>,
    /// The right-hand-side evaluations it reported.
    pub rhs_evals: Option<u64>,
    /// The trace's significant correct digits, as `rotor check` counts them (the fewest of
    /// any graded quantity).
    pub digits: Option<f64>,
    /// Whether the trace passes the strict and loose levels (as `rotor check`).
    pub passes_strict: Option<bool>,
    /// Whether the trace passes the loose level (see `passes_strict`).
    pub passes_loose: Option<bool>,
    /// The quantities failing the loose gate.
    pub failing: Vec<String>,
    /// Why the run gave no usable point, or fails the gate.
    pub failure: Option<Failure>,
    /// The protocol's own cost of this run, not the client's: writing the job file, and
    /// reading and grading the trace \[s\].
    pub protocol_s: Option<f64>,
}

impl ClientPoint {
    /// The point's time for ratios and profiles: in-process if the client reports it,
    /// else the whole process.
    pub fn time(&self) -> Option<Timing> {
        self.solve.or(self.wall)
    }
}

/// Client time / Rust time at the client's error.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ratio {
    /// The Rust solver of the client's class: event-driven for a tolerance, Moreau–Jean for
    /// a step.
    pub against: SolverKind,
    /// `"steady_rel"` or `"transient_max"`.
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub error_kind: crate::bench::word::Word,
    /// `"in_process"` (the client's `solve_seconds`) or `"whole_process"` (its wall time).
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub time: crate::bench::word::Word,
    /// The client point's setting (tolerance, or h in s).
    pub setting: f64,
    /// Its error of kind `error_kind`.
    pub error: f64,
    /// Its time (s), median of the timed runs.
    pub client_seconds: f64,
    /// The Rust solver's time at that error (interpolated on its work-precision front).
    pub rust_seconds: f64,
    /// The Rust solver's fastest point is already more accurate: `rust_seconds` is an upper
    /// bound, the ratio a lower bound.
    pub rust_is_bound: bool,
    /// client_seconds / rust_seconds (medians).
    pub ratio: f64,
    /// The same from the fastest runs of each.
    pub ratio_of_minima: Option<f64>,
}

/// Time per step of a fixed-step client vs rotor-moreau at one h.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PerStep {
    /// The step (s).
    pub h: f64,
    /// The client's in-process time over its reported steps (s, median).
    pub client_s_per_step: f64,
    /// rotor-moreau's time over its steps at the same h (s, median).
    pub moreau_s_per_step: f64,
    /// client / moreau time per step (medians, the client's in-process time).
    pub ratio: f64,
    /// The same from the fastest runs of each.
    pub ratio_of_minima: f64,
    /// The client's errors at that h.
    pub client_errors: Errors,
    /// rotor-moreau's errors at that h.
    pub moreau_errors: Errors,
}

/// A client on one scene.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ClientScene {
    /// The scene's name.
    pub scene: String,
    /// One point per setting of the client's ladder.
    pub points: Vec<ClientPoint>,
    /// Time ratios at equal error against the Rust solver of its class.
    pub ratios: Vec<Ratio>,
    /// Time per step against rotor-moreau (fixed-step clients that report their steps).
    pub per_step: Vec<PerStep>,
}

/// Whether a client ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClientStatus {
    /// At least one point was placed.
    Ran,
    /// A peer that is not installed, or turned off.
    Skipped,
    /// No run gave a usable trace.
    Failed,
}

impl ClientStatus {
    /// The report's name: `ran`, `skipped` or `failed`.
    pub fn as_str(self) -> &'static str {
        match self {
            ClientStatus::Ran => "ran",
            ClientStatus::Skipped => "skipped",
            ClientStatus::Failed => "failed",
        }
    }
}

/// The protocol's overhead for one client, medians over its runs \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Overhead {
    /// Writing the job file, reading and grading the trace.
    pub protocol_s: f64,
    /// The process beyond the client's own solve: start-up, reading the job, writing the
    /// trace (wall − solve_seconds); `None` if the client reports no solve time.
    pub process_s: Option<f64>,
}

/// One client over every scene.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ClientReport {
    /// The client's name.
    pub name: String,
    /// Its command line, as it is run (without the job file's path).
    pub command: String,
    /// Whether it is one of the repository's peers (scipy, Siconos, Octave).
    pub peer: bool,
    /// Whether its knob is a step h rather than a tolerance.
    pub fixed_step: bool,
    /// `"tol"` or `"h"`.
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub setting_name: crate::bench::word::Word,
    /// Whether it ran.
    pub status: ClientStatus,
    /// Why it was skipped or failed.
    pub reason: Option<String>,
    /// Its version, as it reported it.
    pub version: Option<String>,
    /// Its method, as it named it.
    pub method: Option<String>,
    /// Its points and ratios, scene by scene.
    pub scenes: Vec<ClientScene>,
    /// The protocol's and the process's overhead, if it ran.
    pub overhead: Option<Overhead>,
}

impl ClientReport {
    /// A client that did not run.
    pub fn skipped(spec: &ClientSpec, status: ClientStatus, reason: String) -> ClientReport {
        ClientReport {
            name: spec.name.clone(),
            command: spec.command_line(),
            peer: spec.peer,
            fixed_step: spec.fixed_step,
            setting_name: if spec.fixed_step { "h" } else { "tol" },
            status,
            reason: Some(reason),
            version: None,
            method: None,
            scenes: Vec::new(),
            overhead: None,
        }
    }
}

/// Where a client's runs write their files.
fn run_dir(work: &Path, client: &str, scene: &str, k: usize) -> PathBuf {
    work.join(client).join(scene).join(format!("run{k}"))
}

/// The job of one run.
fn job_for(l: &Loaded, spec: &ClientSpec, setting: f64, dir: &Path) -> Job {
    Job::new(
        &l.scenario,
        l.spec.t_end,
        l.spec.dt,
        spec.fixed_step,
        setting,
        dir.join("trace.csv"),
        dir.join("events.csv"),
    )
}

/// The job `rotor bench --scenario PATH` hands a client of that knob on that scene (the
/// scenario's own horizon and grid): what `rotor job` prints.
pub fn job_for_scenario(
    path: &Path,
    fixed_step: bool,
    setting: f64,
    trace: PathBuf,
    events: PathBuf,
) -> Result<Job, crate::bench::BenchError> {
    let spec = SceneSpec::from_scenario(path)?;
    let sc = rotor_analysis::solvers::load_scenario(path)?;
    Ok(Job::new(
        &sc, spec.t_end, spec.dt, fixed_step, setting, trace, events,
    ))
}

/// Runs once: writes the job, starts the client. `Err` is the failure of the run.
pub(crate) fn run_once(
    spec: &ClientSpec,
    job: &Job,
    dir: &Path,
    timeout: f64,
) -> Result<(RunOutput, f64), Failure> {
    let t0 = Instant::now();
    let fail = |kind, detail: String| Failure { kind, detail };
    std::fs::create_dir_all(dir)
        .map_err(|e| fail(FailureKind::Spawn, format!("{}: {e}", dir.display())))?;
    for p in [&job.trace, &job.events] {
        let _ = std::fs::remove_file(p);
    }
    let path = dir.join("job.json");
    std::fs::write(&path, job.to_json())
        .map_err(|e| fail(FailureKind::Spawn, format!("{}: {e}", path.display())))?;
    let write_s = t0.elapsed().as_secs_f64();
    let out = run_client(&spec.argv, &path, timeout).map_err(|e| fail(FailureKind::Spawn, e))?;
    // Kept with the run's other files (`--keep`): what the client said about a failure.
    let _ = std::fs::write(dir.join("stderr.txt"), &out.stderr);
    match &out.ended {
        Ended::TimedOut => Err(fail(
            FailureKind::Timeout,
            format!("killed after the {timeout} s timeout"),
        )),
        Ended::Exited(st) if !st.success() => {
            let why = tail(&out.stderr, 3);
            match st.code() {
                Some(code) => Err(fail(
                    FailureKind::Exit,
                    format!("exit status {code}: {why}"),
                )),
                None => Err(fail(
                    FailureKind::Crash,
                    format!("killed by a signal ({st}): {why}"),
                )),
            }
        }
        Ended::Exited(_) => Ok((out, write_s)),
    }
}

/// What grading a run's files gives.
struct Grade {
    /// The errors against the reference (as the Rust points).
    errors: Errors,
    /// The trace's digits (as `rotor check`).
    digits: f64,
    /// Whether it reaches the strict level: `false` too when its file's precision cannot
    /// show that level (a `%g` trace), which is no failure of the run.
    strict: bool,
    loose: bool,
    /// The quantities failing the loose level.
    failing: Vec<String>,
    /// The seconds grading took.
    seconds: f64,
}

/// Grades a run's files as `rotor check` does.
fn grade(l: &Loaded, job: &Job) -> Result<Grade, Failure> {
    let t0 = Instant::now();
    let unusable = |detail: String| Failure {
        kind: FailureKind::Unusable,
        detail,
    };
    let (sc, r) = &l.view;
    // Up to one row past the grid: a client that writes on and on costs no more than the grid.
    let trace = read_trace(&job.trace, r.samples.len() + 1).map_err(|e| unusable(e.to_string()))?;
    let events = if job.events.exists() {
        Some(read_events(&job.events).map_err(|e| unusable(e.to_string()))?)
    } else {
        None
    };
    let verdict = |gate| check(sc, r, &trace, events.as_ref(), gate);
    let loose = verdict(Level::Loose).map_err(|e| unusable(e.to_string()))?;
    let strict = match verdict(Level::Strict) {
        Ok(v) => v.passed,
        Err(CheckError::Precision { .. }) => false,
        Err(e) => return Err(unusable(e.to_string())),
    };
    let exit = StickExit {
        model: &sc.model,
        u: sc.steady_u(),
    };
    let steady = grid_metrics(&trace.samples, l.spec.metrics_from, exit).ok();
    let metrics = SteadyRef::of(steady.as_ref());
    let window: Vec<(f64, f64)> = trace
        .samples
        .iter()
        .filter(|s| {
            s.t >= l.spec.transient[0] - 1e-9 * l.spec.dt
                && s.t <= l.spec.transient[1] + 1e-9 * l.spec.dt
        })
        .map(|s| (s.t, s.x[2]))
        .collect();
    let errors = l.grid_refd.errors(metrics, &window);
    let failing = loose.failing().iter().map(|s| s.to_string()).collect();
    Ok(Grade {
        errors,
        digits: loose.digits,
        strict,
        loose: loose.passed,
        failing,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// One setting: the first run graded, then timed runs within the budget.
fn point(
    spec: &ClientSpec,
    opts: &BenchOptions,
    l: &Loaded,
    setting: f64,
    dir: &Path,
    says: &mut ClientSays,
) -> ClientPoint {
    let job = job_for(l, spec, setting, dir);
    let mut p = ClientPoint {
        setting,
        wall: None,
        solve: None,
        errors: Errors::default(),
        steps: None,
        rhs_evals: None,
        digits: None,
        passes_strict: None,
        passes_loose: None,
        failing: Vec::new(),
        failure: None,
        protocol_s: None,
    };
    let (first, write_s) = match run_once(spec, &job, dir, opts.timeout) {
        Ok(x) => x,
        Err(f) => {
            p.failure = Some(f);
            return p;
        }
    };
    let Grade {
        errors,
        digits,
        strict,
        loose,
        failing,
        seconds: grade_s,
    } = match grade(l, &job) {
        Ok(g) => g,
        Err(f) => {
            p.failure = Some(f);
            return p;
        }
    };
    let first_says = ClientSays::from_stdout(&first.stdout);
    p.errors = errors;
    p.digits = Some(digits);
    p.passes_strict = Some(strict);
    p.passes_loose = Some(loose);
    p.protocol_s = Some(write_s + grade_s);
    p.steps = first_says.steps;
    p.rhs_evals = first_says.rhs_evals;
    if says.version.is_none() {
        says.version.clone_from(&first_says.version);
        says.method.clone_from(&first_says.method);
    }
    if !loose {
        p.failure = Some(Failure {
            kind: FailureKind::FailsGate,
            detail: format!("fails the loose gate in {}", failing.join(", ")),
        });
    }
    p.failing = failing;
    // Timed runs: as many as the budget allows after the first (which is not timed: a cold
    // start of an interpreter is not the client's speed), at least one; a first run longer
    // than the whole budget is its own timing (its start-up is a small part of it), as the
    // Rust solvers' warm-up run is.
    let n = ((opts.time_budget / first.wall_s.max(1e-9)).floor() as usize).clamp(1, opts.repeats);
    let (mut walls, mut solves) = (Vec::new(), Vec::new());
    if first.wall_s >= opts.time_budget {
        p.wall = Some(Timing::of(vec![first.wall_s]));
        p.solve = first_says.solve_seconds.map(|s| Timing::of(vec![s]));
        return p;
    }
    for _ in 0..n {
        match run_once(spec, &job, dir, opts.timeout) {
            Ok((out, _)) => {
                walls.push(out.wall_s);
                if let Some(s) = ClientSays::from_stdout(&out.stdout).solve_seconds {
                    solves.push(s);
                }
            }
            Err(f) => {
                p.failure = Some(f);
                return p;
            }
        }
    }
    p.wall = Some(Timing::of(walls.clone()));
    if solves.len() == walls.len() {
        p.solve = Some(Timing::of(solves));
    }
    p
}

/// The ratios of a client's points (those passing the loose gate) to the Rust solver of its
/// class (event-driven for a tolerance, Moreau–Jean for a step), at equal error, for the
/// in-process and the whole-process time.
fn ratios(points: &[ClientPoint], rust: &[LadderPoint], fixed_step: bool) -> Vec<Ratio> {
    let against = if fixed_step {
        SolverKind::MOREAU
    } else {
        SolverKind::EVENT
    };
    type Pick = fn(&Errors) -> Option<f64>;
    let kinds: [(&'static str, Pick); 2] = [
        ("steady_rel", |e| e.steady_rel),
        ("transient_max", |e| e.transient_max),
    ];
    let mut out = Vec::new();
    for (error_kind, pick) in kinds {
        let curve = |min: bool| -> Vec<(f64, f64)> {
            rust.iter()
                .filter(|q| q.solver == against)
                .filter_map(|q| {
                    let t = q.timing?;
                    Some((pick(&q.errors)?, if min { t.min_s } else { t.median_s }))
                })
                .collect()
        };
        let (median_curve, min_curve) = (curve(false), curve(true));
        for time in ["in_process", "whole_process"] {
            for p in points.iter().filter(|p| p.passes_loose == Some(true)) {
                let t = if time == "in_process" {
                    p.solve
                } else {
                    p.wall
                };
                let (Some(e), Some(t)) = (pick(&p.errors), t) else {
                    continue;
                };
                if let Some((rt, bound)) = time_at_error(&median_curve, e) {
                    out.push(Ratio {
                        against,
                        error_kind,
                        time,
                        setting: p.setting,
                        error: e,
                        client_seconds: t.median_s,
                        rust_seconds: rt,
                        rust_is_bound: bound,
                        ratio: t.median_s / rt,
                        ratio_of_minima: time_at_error(&min_curve, e).map(|(rm, _)| t.min_s / rm),
                    });
                }
            }
        }
    }
    out
}

/// For a fixed-step client that reports its steps: rotor-moreau at the same h, time per
/// step side by side.
fn per_step(
    points: &[ClientPoint],
    opts: &BenchOptions,
    l: &Loaded,
    progress: &mut impl FnMut(&str),
) -> Vec<PerStep> {
    let mut out = Vec::new();
    for p in points {
        let (Some(t), Some(steps)) = (p.solve, p.steps) else {
            continue;
        };
        progress(&format!(
            "{}: moreau at the client's step h = {:e}",
            l.scenario.name, p.setting
        ));
        let scene = scene_at(&l.base, SolverKind::MOREAU, p.setting, l.base.output);
        if let Ok((tr, mt, me)) = run_point(
            SolverKind::MOREAU,
            &scene,
            &l.scenario.model,
            &l.refd,
            l.spec.transient,
            opts.repeats,
            opts.time_budget,
        ) {
            let client = t.median_s / steps as f64;
            let ours = mt.median_s / tr.stats.steps as f64;
            out.push(PerStep {
                h: p.setting,
                client_s_per_step: client,
                moreau_s_per_step: ours,
                ratio: client / ours,
                ratio_of_minima: (t.min_s / steps as f64) / (mt.min_s / tr.stats.steps as f64),
                client_errors: p.errors,
                moreau_errors: me,
            });
        }
    }
    out
}

/// Why the rest of a tolerance ladder is not run when the client's answer does not move.
pub(crate) const KNOB_IGNORED: &str = "not run: the same answer at four tolerances in a row: the \
     client ignores tol (a fixed-step client? declare it as NAME:h=COMMAND or --fixed-step NAME)";

/// Whether the last four points of a tolerance ladder are one answer: each placed, with equal
/// errors and digits. A client that ignores `tol` (a fixed-step one run the naive way, at its
/// own default step) gives that; an adaptive one moves within four decades (this project's
/// switch model repeats itself at two: tol 1e-3 and 1e-4, where h_max binds).
pub(crate) fn ignores_its_knob(points: &[ClientPoint]) -> bool {
    let Some(last) = points.len().checked_sub(4).map(|i| &points[i..]) else {
        return false;
    };
    last.iter().all(|p| p.wall.is_some())
        && last
            .windows(2)
            .all(|w| w[0].errors == w[1].errors && w[0].digits == w[1].digits)
}

/// Runs one client over its ladder on every scene.
pub(crate) fn run(
    spec: &ClientSpec,
    ladder: &[f64],
    opts: &BenchOptions,
    scenes: &[(Loaded, Vec<LadderPoint>)],
    work: &Path,
    progress: &mut impl FnMut(&str),
) -> ClientReport {
    let mut says = ClientSays::default();
    let mut out = Vec::new();
    for (l, rust) in scenes {
        let mut points: Vec<ClientPoint> = Vec::new();
        let mut stop: Option<&'static str> = None;
        for (k, &setting) in ladder.iter().enumerate() {
            let setting_name = if spec.fixed_step { "h" } else { "tol" };
            if let Some(why) = stop {
                points.push(ClientPoint {
                    failure: Some(Failure {
                        kind: FailureKind::Skipped,
                        detail: why.into(),
                    }),
                    ..skipped_point(setting)
                });
                continue;
            }
            progress(&format!(
                "{}: {} {setting_name} = {setting:e}",
                l.scenario.name, spec.name
            ));
            let dir = run_dir(work, &spec.name, &l.scenario.name, k);
            let p = point(spec, opts, l, setting, &dir, &mut says);
            // A timeout: the tighter settings would take longer still. The same failure at
            // two settings in a row (a client refusing the scene's parameters, say): the
            // rest would repeat it.
            let same_twice = |a: &ClientPoint, b: &ClientPoint| match (&a.failure, &b.failure) {
                (Some(x), Some(y)) => {
                    x == y && matches!(x.kind, FailureKind::Exit | FailureKind::Crash)
                }
                _ => false,
            };
            if p.failure
                .as_ref()
                .is_some_and(|f| f.kind == FailureKind::Timeout)
            {
                stop = Some("not run: a looser setting timed out");
            } else if points.last().is_some_and(|q| same_twice(q, &p)) {
                stop = Some("not run: the same failure at the two settings before");
            }
            points.push(p);
            if stop.is_none() && !spec.fixed_step && ignores_its_knob(&points) {
                stop = Some(KNOB_IGNORED);
            }
        }
        let ratios = ratios(&points, rust, spec.fixed_step);
        let per_step = if spec.fixed_step {
            per_step(&points, opts, l, progress)
        } else {
            Vec::new()
        };
        out.push(ClientScene {
            scene: l.scenario.name.clone(),
            points,
            ratios,
            per_step,
        });
    }
    let (status, reason, overhead) = summary(&out);
    ClientReport {
        name: spec.name.clone(),
        command: spec.command_line(),
        peer: spec.peer,
        fixed_step: spec.fixed_step,
        setting_name: if spec.fixed_step { "h" } else { "tol" },
        status,
        reason,
        version: says.version,
        method: says.method,
        scenes: out,
        overhead,
    }
}

/// A client's status, the reason it placed no point (if so) and the protocol's overhead, from
/// its points over every scene (for one run, and for shards joined by [`crate::bench::merge`]).
pub(crate) fn summary(out: &[ClientScene]) -> (ClientStatus, Option<String>, Option<Overhead>) {
    let all: Vec<&ClientPoint> = out.iter().flat_map(|s| &s.points).collect();
    let placed = all.iter().any(|p| p.wall.is_some());
    let median = |mut v: Vec<f64>| -> Option<f64> {
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(v[v.len() / 2])
    };
    let overhead =
        median(all.iter().filter_map(|p| p.protocol_s).collect()).map(|protocol_s| Overhead {
            protocol_s,
            process_s: median(
                all.iter()
                    .filter_map(|p| Some(p.wall?.median_s - p.solve?.median_s))
                    .collect(),
            ),
        });
    let reason = (!placed).then(|| {
        all.iter()
            .find_map(|p| p.failure.as_ref().map(|f| f.detail.clone()))
            .unwrap_or_else(|| "no setting".into())
    });
    let status = if placed {
        ClientStatus::Ran
    } else {
        ClientStatus::Failed
    };
    (status, reason, overhead)
}

fn skipped_point(setting: f64) -> ClientPoint {
    ClientPoint {
        setting,
        wall: None,
        solve: None,
        errors: Errors::default(),
        steps: None,
        rhs_evals: None,
        digits: None,
        passes_strict: None,
        passes_loose: None,
        failing: Vec::new(),
        failure: None,
        protocol_s: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table's name of a failure kind is the one its JSON carries (and `--merge` reads
    /// back): each variant serialised by serde against `as_str`.
    #[test]
    fn failure_kind_names_are_the_json_names() {
        use FailureKind::*;
        for k in [Spawn, Crash, Exit, Timeout, Unusable, FailsGate, Skipped] {
            assert_eq!(
                serde_json::to_value(k).unwrap(),
                serde_json::Value::from(k.as_str()),
                "{k:?}"
            );
        }
    }

    fn placed(steady: f64, digits: f64) -> ClientPoint {
        ClientPoint {
            wall: Some(Timing {
                median_s: 0.1,
                min_s: 0.1,
                repeats: 1,
            }),
            errors: Errors {
                steady_rel: Some(steady),
                ..Errors::default()
            },
            digits: Some(digits),
            ..skipped_point(1e-3)
        }
    }

    /// Four identical answers in a row stop a tolerance ladder; three do not (this project's
    /// switch model repeats one at two tolerances), nor four with one that moved or one
    /// that failed.
    #[test]
    fn four_identical_answers_mean_an_ignored_knob() {
        let same = placed(1e-4, 3.2);
        assert!(ignores_its_knob(&vec![same.clone(); 4]));
        assert!(ignores_its_knob(&[
            placed(1e-2, 1.0),
            same.clone(),
            same.clone(),
            same.clone(),
            same.clone()
        ]));
        assert!(!ignores_its_knob(&vec![same.clone(); 3]));
        let mut moved = vec![same.clone(); 4];
        moved[3] = placed(9e-5, 3.2);
        assert!(!ignores_its_knob(&moved));
        let mut digits = vec![same.clone(); 4];
        digits[2] = placed(1e-4, 3.3);
        assert!(!ignores_its_knob(&digits));
        let mut failed = vec![same.clone(); 4];
        failed[0] = skipped_point(1e-3);
        assert!(!ignores_its_knob(&failed));
    }
}
