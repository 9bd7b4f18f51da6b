//! `rotor bench --tier chain`: work against precision on the suite's chain scenes.
//!
//! Each solver that runs chains climbs its ladder of settings on each chain scene; each
//! external client (the job-file protocol, [`crate::protocol::Job::for_chain`]) climbs its own.
//! Every run's trace and events are graded as `rotor check` grades them
//! ([`crate::grade::chain::check_chain`]): its digits (the fewest of any quantity: every
//! column, the events, every disc's stick intervals) and whether it reaches the loose and
//! strict levels. The run time is the median of timed runs after one untimed warm-up (a
//! client's: its own `solve_seconds` when it prints them, else the process's wall time).
//!
//! Nothing here asserts a speed: the points are measured side by side and reported.

use std::path::{Path, PathBuf};

use rotor_analysis::plot::{Panel, Series, render};
use rotor_model::scenario::ChainScenario;
use rotor_model::seam::{Output, Scene};
use serde::Serialize;

use crate::bench::BenchError;
use crate::bench::measure::timed;
use crate::bench::options::SolverKind;
use crate::grade::chain::{CHAIN_BENCHMARK, ChainReference, check_chain};
use crate::grade::check::{CheckError, Level};
use crate::grade::trace::{ChainTrace, EventsFile, read_chain_events, read_chain_trace};
use crate::protocol::{ClientSays, ClientSpec, Job};

/// What the chain tier's bench runs.
#[derive(Debug, Clone)]
pub struct ChainTierOptions {
    /// The chain scenes (scenario files).
    pub scenes: Vec<PathBuf>,
    /// Each solver's ladder of settings (tolerances, or steps in s).
    pub ladders: Vec<(SolverKind, Vec<f64>)>,
    /// External clients.
    pub clients: Vec<ClientSpec>,
    /// The ladder of a client with a tolerance.
    pub client_tols: Vec<f64>,
    /// The ladder of a fixed-step client \[s\].
    pub client_hs: Vec<f64>,
    /// Timed runs per point (fewer when a run is long: [`ChainTierOptions::time_budget`]).
    pub repeats: usize,
    /// Seconds of timed runs per point at most.
    pub time_budget: f64,
    /// Seconds after which a client's run is killed.
    pub timeout: f64,
    /// Where the clients' job, trace and events files are written.
    pub work: PathBuf,
}

impl ChainTierOptions {
    /// Every solver that runs chains over its whole ladder on `scenes`, 5 timed runs within
    /// 2 s a point, clients over tol 1e-3 … 1e-12 or h 1e-2 … 1e-4.
    pub fn new(scenes: Vec<PathBuf>) -> ChainTierOptions {
        ChainTierOptions {
            scenes,
            ladders: rotor_analysis::solvers::SOLVERS
                .iter()
                .copied()
                .filter(|k| k.info().chain.is_some())
                .map(|k| (k, k.info().ladder.to_vec()))
                .collect(),
            clients: Vec::new(),
            client_tols: (3..=12).map(|k| 10f64.powi(-k)).collect(),
            client_hs: vec![1e-2, 1e-3, 1e-4],
            repeats: 5,
            time_budget: 2.0,
            timeout: 60.0,
            work: std::env::temp_dir().join(format!("rotor-chain-tier-{}", std::process::id())),
        }
    }

    /// Three settings a solver (tol 1e-4, 1e-8, 1e-12; h 1e-2, 1e-3, 1e-4), one timed run:
    /// seconds, for a check.
    pub fn quick(scenes: Vec<PathBuf>) -> ChainTierOptions {
        let mut o = ChainTierOptions::new(scenes);
        for (kind, l) in &mut o.ladders {
            *l = if kind.is_fixed_step() {
                vec![1e-2, 1e-3, 1e-4]
            } else {
                vec![1e-4, 1e-8, 1e-12]
            };
        }
        o.client_tols = vec![1e-4, 1e-8];
        o.client_hs = vec![1e-2, 1e-3];
        o.repeats = 1;
        o.time_budget = 0.5;
        o
    }
}

/// One run of one runner at one setting on one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainPoint {
    /// The solver's or client's name.
    pub runner: String,
    /// `tol` or `h`.
    pub knob: &'static str,
    /// The setting's value.
    pub setting: f64,
    /// Median run time \[s\] (a client's in-process time when it reports one).
    pub seconds: Option<f64>,
    /// Correct significant digits, the fewest of any graded quantity.
    pub digits: Option<f64>,
    /// Whether it reaches the loose level (3 digits).
    pub loose: Option<bool>,
    /// Whether it reaches the strict level (7 digits).
    pub strict: Option<bool>,
    /// The quantities failing loose.
    pub failing: Vec<String>,
    /// Why the run has no grade (a crash, a timeout, an unusable file).
    pub failure: Option<String>,
}

/// One chain scene's points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainSceneReport {
    /// The scene's name.
    pub scenario: String,
    /// Number of discs.
    pub discs: usize,
    /// Horizon \[s\].
    pub t_end: f64,
    /// Every runner's points, runner by runner, each over its ladder.
    pub points: Vec<ChainPoint>,
}

/// The chain tier's bench.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainTierReport {
    /// The chain tier's version.
    pub benchmark: &'static str,
    /// One report per scene.
    pub scenes: Vec<ChainSceneReport>,
}

/// The grade of a run's files: digits, loose, strict, failing quantities.
fn grade_run(
    sc: &ChainScenario,
    r: &ChainReference,
    trace: &ChainTrace,
    events: Option<&EventsFile>,
) -> Result<(f64, bool, bool, Vec<String>), CheckError> {
    // The digits as the loose level reads them (its stuck threshold), as the rig's bench
    // does: a coarser level counts other samples stuck, and its digits would disagree with
    // the loose verdict.
    let loose = check_chain(sc, r, trace, events, Level::Loose)?;
    let digits = loose.digits;
    let strict = match check_chain(sc, r, trace, events, Level::Strict) {
        Ok(v) => v.passed,
        Err(CheckError::Precision { .. }) => false,
        Err(e) => return Err(e),
    };
    let failing = loose.failing().iter().map(|s| s.to_string()).collect();
    Ok((digits, loose.passed, strict, failing))
}

fn empty_point(runner: &str, knob: &'static str, setting: f64) -> ChainPoint {
    ChainPoint {
        runner: runner.to_owned(),
        knob,
        setting,
        seconds: None,
        digits: None,
        loose: None,
        strict: None,
        failing: Vec::new(),
        failure: None,
    }
}

/// A solver's point: one graded run, timed within the budget.
fn solver_point(
    opts: &ChainTierOptions,
    sc: &ChainScenario,
    r: &ChainReference,
    kind: SolverKind,
    setting: f64,
) -> ChainPoint {
    let mut p = empty_point(kind.name(), kind.setting_name(), setting);
    let model = sc.model();
    let scene = Scene {
        accuracy: kind.accuracy(setting),
        ..sc.scene(Output::Grid { dt: sc.dt })
    };
    match timed(opts.repeats, opts.time_budget, || {
        kind.simulate_chain(&model, &scene)
    }) {
        Err(e) => p.failure = Some(e.to_string()),
        Ok((tr, timing)) => {
            p.seconds = Some(timing.median_s);
            let events = EventsFile::of_run("run.events.csv", &tr.events);
            let trace = ChainTrace::of_run("run.csv", tr.samples);
            match grade_run(sc, r, &trace, Some(&events)) {
                Ok((d, loose, strict, failing)) => {
                    (p.digits, p.loose, p.strict, p.failing) =
                        (Some(d), Some(loose), Some(strict), failing);
                }
                Err(e) => p.failure = Some(e.to_string()),
            }
        }
    }
    p
}

/// A client's point: one graded run, then timed runs within the budget.
fn client_point(
    opts: &ChainTierOptions,
    sc: &ChainScenario,
    r: &ChainReference,
    spec: &ClientSpec,
    setting: f64,
) -> ChainPoint {
    let knob = if spec.fixed_step { "h" } else { "tol" };
    let mut p = empty_point(&spec.name, knob, setting);
    let dir = opts.work.join(&spec.name).join(&sc.name);
    let job = Job::for_chain(
        sc,
        spec.fixed_step,
        setting,
        dir.join("trace.csv"),
        dir.join("events.csv"),
    );
    let first = match crate::bench::clients::run_once(spec, &job, &dir, opts.timeout) {
        Ok((out, _)) => out,
        Err(f) => {
            p.failure = Some(format!("{:?}: {}", f.kind, f.detail));
            return p;
        }
    };
    let names = sc.model().state_names();
    let graded = read_chain_trace(&job.trace, &names, r.grid_rows() + 1)
        .map_err(|e| e.to_string())
        .and_then(|t| {
            let ev = if job.events.exists() {
                Some(read_chain_events(&job.events, sc.discs()).map_err(|e| e.to_string())?)
            } else {
                None
            };
            grade_run(sc, r, &t, ev.as_ref()).map_err(|e| e.to_string())
        });
    match graded {
        Ok((d, loose, strict, failing)) => {
            (p.digits, p.loose, p.strict, p.failing) =
                (Some(d), Some(loose), Some(strict), failing);
        }
        Err(e) => {
            p.failure = Some(format!("unusable: {e}"));
            return p;
        }
    }
    let seconds = |out: &crate::protocol::RunOutput| {
        ClientSays::from_stdout(&out.stdout)
            .solve_seconds
            .unwrap_or(out.wall_s)
    };
    let mut times = vec![seconds(&first)];
    if first.wall_s < opts.time_budget {
        let n =
            ((opts.time_budget / first.wall_s.max(1e-9)).floor() as usize).clamp(1, opts.repeats);
        times.clear();
        for _ in 0..n {
            match crate::bench::clients::run_once(spec, &job, &dir, opts.timeout) {
                Ok((out, _)) => times.push(seconds(&out)),
                Err(f) => {
                    p.failure = Some(format!("{:?}: {}", f.kind, f.detail));
                    return p;
                }
            }
        }
    }
    p.seconds = Some(crate::bench::Timing::of(times).median_s);
    p
}

/// Runs the chain tier's bench; `say` hears one line per scene and runner.
pub fn run(
    opts: &ChainTierOptions,
    say: &mut dyn FnMut(String),
) -> Result<ChainTierReport, BenchError> {
    if opts.scenes.is_empty() {
        return Err(BenchError::Options("no chain scene to run".into()));
    }
    if !(opts.timeout > 0.0 && opts.timeout.is_finite()) {
        return Err(BenchError::Options(format!(
            "timeout = {}: must be positive and finite",
            opts.timeout
        )));
    }
    let mut scenes = Vec::new();
    for path in &opts.scenes {
        let (sc, r) = crate::grade::chain::load(path)
            .map_err(|e| BenchError::Options(format!("{}: {e}", path.display())))?;
        let mut points = Vec::new();
        for (kind, ladder) in &opts.ladders {
            for &s in ladder {
                points.push(solver_point(opts, &sc, &r, *kind, s));
            }
            say(format!(
                "{}: {} over {} settings",
                sc.name,
                kind.name(),
                ladder.len()
            ));
        }
        for spec in &opts.clients {
            let ladder = if spec.fixed_step {
                &opts.client_hs
            } else {
                &opts.client_tols
            };
            for &s in ladder {
                points.push(client_point(opts, &sc, &r, spec, s));
            }
            say(format!(
                "{}: {} over {} settings",
                sc.name,
                spec.name,
                ladder.len()
            ));
        }
        scenes.push(ChainSceneReport {
            scenario: sc.name.clone(),
            discs: sc.discs(),
            t_end: sc.t_end,
            points,
        });
    }
    std::fs::remove_dir_all(&opts.work).ok();
    Ok(ChainTierReport {
        benchmark: CHAIN_BENCHMARK,
        scenes,
    })
}

/// A number for a table: `—` for none.
fn cell(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or("—".into(), f)
}

impl ChainTierReport {
    /// The runners, in order of first appearance.
    fn runners(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for p in self.scenes.iter().flat_map(|s| &s.points) {
            if !out.contains(&p.runner.as_str()) {
                out.push(&p.runner);
            }
        }
        out
    }

    /// The cheapest point of `runner` on `scene` that passes the loose level, or with
    /// `strict` the strict one.
    pub fn cheapest(&self, scene: &ChainSceneReport, runner: &str, strict: bool) -> Option<f64> {
        scene
            .points
            .iter()
            .filter(|p| p.runner == runner)
            .filter(|p| if strict { p.strict } else { p.loose } == Some(true))
            .filter_map(|p| p.seconds)
            .min_by(f64::total_cmp)
    }

    /// Markdown: per scene, each point's digits and time, then the cheapest run reaching
    /// loose and strict per runner.
    pub fn to_markdown(&self) -> String {
        let mut out = format!("# Chain tier ({})\n\n", self.benchmark);
        for s in &self.scenes {
            out.push_str(&format!(
                "## {} ({} discs, {} s)\n\n| runner | setting | digits | loose | strict | time [s] | note |\n|---|---|---:|:-:|:-:|---:|---|\n",
                s.scenario, s.discs, s.t_end
            ));
            for p in &s.points {
                let yes = |b: Option<bool>| match b {
                    Some(true) => "yes",
                    Some(false) => "no",
                    None => "—",
                };
                out.push_str(&format!(
                    "| {} | {} {:e} | {} | {} | {} | {} | {} |\n",
                    p.runner,
                    p.knob,
                    p.setting,
                    cell(p.digits, |d| format!("{d:.1}")),
                    yes(p.loose),
                    yes(p.strict),
                    cell(p.seconds, |t| format!("{t:.3e}")),
                    p.failure
                        .clone()
                        .unwrap_or_else(|| p.failing.join(", "))
                        .replace('|', "/")
                ));
            }
            out.push_str(
                "\n| runner | cheapest loose [s] | cheapest strict [s] |\n|---|---:|---:|\n",
            );
            for r in self.runners() {
                out.push_str(&format!(
                    "| {r} | {} | {} |\n",
                    cell(self.cheapest(s, r, false), |t| format!("{t:.3e}")),
                    cell(self.cheapest(s, r, true), |t| format!("{t:.3e}")),
                ));
            }
            out.push('\n');
        }
        out
    }

    /// CSV: one row per point.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "scenario,discs,runner,knob,setting,digits,loose,strict,seconds,failure\n",
        );
        for s in &self.scenes {
            for p in &s.points {
                out.push_str(&format!(
                    "{},{},{},{},{:e},{},{},{},{},{}\n",
                    s.scenario,
                    s.discs,
                    p.runner,
                    p.knob,
                    p.setting,
                    p.digits.map_or(String::new(), |d| d.to_string()),
                    p.loose.map_or(String::new(), |b| b.to_string()),
                    p.strict.map_or(String::new(), |b| b.to_string()),
                    p.seconds.map_or(String::new(), |t| t.to_string()),
                    p.failure.as_deref().unwrap_or("").replace([',', '\n'], ";"),
                ));
            }
        }
        out
    }

    /// Work against precision, one panel per scene: digits (up) against run time (right,
    /// log), one line per runner in its registry style.
    pub fn to_svg(&self) -> String {
        let runners = self.runners();
        let panels: Vec<Panel> = self
            .scenes
            .iter()
            .map(|s| {
                let series = runners
                    .iter()
                    .map(|r| {
                        let (color, dash) = SolverKind::by_name(r)
                            .map_or(("#7a3e9d", Some("2 3")), |k| {
                                (k.info().style.color, k.info().style.dash)
                            });
                        let mut pts: Vec<(f64, f64)> = s
                            .points
                            .iter()
                            .filter(|p| p.runner == *r)
                            .filter_map(|p| Some((p.seconds?, p.digits?)))
                            .collect();
                        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                        Series {
                            dash,
                            marker: Some(3.0),
                            ..Series::line(r, color, pts)
                        }
                    })
                    .collect();
                let mut panel = Panel::new(
                    format!("{} ({} discs)", s.scenario, s.discs),
                    "run time [s]",
                    "correct digits (fewest of any graded quantity)",
                    series,
                );
                panel.x_log = true;
                panel
            })
            .collect();
        render(&panels, 640.0, 300.0)
    }
}

/// The chain scenes of a suite directory (`chain/scenarios/*.toml`) that a default bench runs:
/// all but the chaotic ones, whose 8,000 s at every rung of a ladder (Moreau–Jean at h = 1e-5:
/// 8·10⁸ steps) would take hours; name one with `--scenario` to bench it.
pub fn chain_scenes(fixtures: &Path) -> Result<Vec<PathBuf>, BenchError> {
    let dir = crate::grade::chain::tier_dir(fixtures).join("scenarios");
    let all = rotor_model::scenario::Scenario::list_dir(&dir).map_err(|e| {
        BenchError::Options(format!(
            "{}: cannot list the chain scenes: {e}",
            dir.display()
        ))
    })?;
    let mut out = Vec::new();
    for p in all {
        let sc = ChainScenario::from_file(&p)
            .map_err(|e| BenchError::Options(format!("{}: {e}", p.display())))?;
        if sc.chaos.is_none() {
            out.push(p);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixtures() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
    }

    /// A quick bench over one chain scene: every solver places graded points, the tightest
    /// settings reach strict (event, switch) or loose (Moreau–Jean at h = 1e-4), and a client
    /// that does not exist is recorded as a failure with its reason, the bench going on.
    #[test]
    fn a_quick_chain_bench_grades_every_runner_and_records_failures() {
        let scene = fixtures().join("chain/scenarios/chain3-u1.5-rest.toml");
        let mut opts = ChainTierOptions::quick(vec![scene]);
        opts.clients
            .push(ClientSpec::parse("ghost=/nonexistent/solver", &[]).unwrap());
        opts.client_tols = vec![1e-6];
        let r = run(&opts, &mut |_| {}).unwrap();
        assert_eq!(r.benchmark, rotor_suite::CHAIN_VERSION);
        let s = &r.scenes[0];
        for kind in ["event", "switch", "moreau"] {
            let best = s
                .points
                .iter()
                .filter(|p| p.runner == kind)
                .filter_map(|p| p.digits)
                .fold(0.0, f64::max);
            let need = if kind == "moreau" { 3.0 } else { 7.0 };
            assert!(best >= need, "{kind}: {best} digits");
        }
        let ghost: Vec<&ChainPoint> = s.points.iter().filter(|p| p.runner == "ghost").collect();
        assert_eq!(ghost.len(), 1);
        assert!(ghost[0].failure.is_some() && ghost[0].digits.is_none());
        assert!(r.to_markdown().contains("| ghost |"));
        assert!(r.to_svg().starts_with("<svg"));
        assert_eq!(r.to_csv().lines().count(), 1 + s.points.len());
    }

    #[test]
    fn no_scene_and_a_bad_timeout_are_refused() {
        assert!(run(&ChainTierOptions::new(Vec::new()), &mut |_| {}).is_err());
        let mut o = ChainTierOptions::new(chain_scenes(&fixtures()).unwrap());
        o.timeout = f64::NAN;
        let e = run(&o, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains("timeout = NaN"), "{e}");
    }
}
