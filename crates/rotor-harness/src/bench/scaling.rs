//! The chain scaling study: how each method's cost grows with the number of discs N, at equal
//! error. This is where event-driven and time-stepping methods part ways: one pays for every
//! event, whose number grows with the contacts; the other for a one-step problem that couples
//! them.
//!
//! The chain is the rig's top disc followed by N − 1 copies of its lower disc (Table 1), driven
//! at `u`, every disc spinning at `omega0` with the springs relaxed at t = 0: every contact
//! then slips, sticks and breaks away (from rest, the stick-slip wave reaches only the first
//! few discs within the horizon: 6 of 64 in 20 s, and the others' contacts never change).
//! For each N:
//!
//! 1. a reference: the event-driven solver, the project's accuracy reference, at
//!    `reference_tol` (its own error there is ~1e-10 over the horizon, its chain tests'
//!    tolerance study; cross-validated on chains against the switch model and Moreau–Jean);
//! 2. for each solver with a chain run ([`rotor_analysis::solvers::SolverInfo::chain`]), the
//!    loosest setting of its ladder whose error is within `target` (the error: the largest
//!    |Δ| over every sample of every state against the reference), timed `repeats` times (the
//!    median); its cost per simulated second and per step;
//! 3. Siconos' MoreauJeanOSI (bench/peers/siconos_chain.py, a θ = 1/2 scheme with one Lemke
//!    problem a step coupling the contacts) on a shorter horizon (its cost per step grows
//!    fast with N), at the loosest step from Moreau–Jean's chosen h down whose error against
//!    the reference on that horizon is within the target; its cost per step beside
//!    Moreau–Jean's at that step, timed in this process on the same horizon.
//!
//! A slope is the least-squares fit of log(cost per simulated second) against log N.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rotor_analysis::plot::{Panel, Series, render};
use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_model::seam::{Output, Scene, Trajectory};
use rotor_model::{ChainModel, ChainParams, Params};
use serde::Serialize;

use crate::bench::BenchError;
use crate::bench::colors::style;
use crate::protocol::{ClientSays, Ended, Job, run_client};

/// What the study runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingOptions {
    /// The chains' numbers of discs.
    pub discs: Vec<usize>,
    /// The motor's input \[V\].
    pub u: f64,
    /// Every disc's velocity at t = 0 \[rad/s\] (the springs relaxed).
    pub omega0: f64,
    /// The horizon \[s\].
    pub t_end: f64,
    /// The sample grid \[s\].
    pub dt: f64,
    /// The error every solver's setting must reach.
    pub target: f64,
    /// The reference's tolerance (event-driven solver).
    pub reference_tol: f64,
    /// Timed runs per point (the median is kept).
    pub repeats: usize,
    /// The Siconos peer, if it runs.
    pub siconos: Option<SiconosOptions>,
}

/// How the Siconos peer runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SiconosOptions {
    /// The Python that imports `siconos.kernel`.
    pub python: String,
    /// The directory of the peer scripts (`bench/peers`).
    pub dir: PathBuf,
    /// Its horizon \[s\], shorter than the study's (its cost per step grows fast with N: about
    /// 0.1 s a step at N = 64).
    pub horizon: f64,
    /// A run's timeout \[s\].
    pub timeout: f64,
    /// Where the job and trace files go (a temporary directory: not reported).
    #[serde(skip)]
    pub work: PathBuf,
}

impl Default for ScalingOptions {
    /// N = 2 … 64, 1.5 V with every disc at 1 rad/s over 20 s on a 0.01 s grid, every solver
    /// within 1e-4 of a reference at tol 1e-12, 3 timed runs; no peer.
    fn default() -> Self {
        ScalingOptions {
            discs: vec![2, 4, 8, 16, 32, 64],
            u: 1.5,
            omega0: 1.0,
            t_end: 20.0,
            dt: 0.01,
            target: 1e-4,
            reference_tol: 1e-12,
            repeats: 3,
            siconos: None,
        }
    }
}

/// One solver at one N.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingPoint {
    /// The number of discs.
    pub discs: usize,
    /// The solver's or peer's name.
    pub runner: String,
    /// `tol` or `h`.
    pub setting_name: &'static str,
    /// Its value.
    pub setting: f64,
    /// The simulated horizon \[s\].
    pub horizon: f64,
    /// Steps taken.
    pub steps: u64,
    /// The run's time (median) \[s\].
    pub seconds: f64,
    /// Cost per simulated second \[s/s\].
    pub per_second: f64,
    /// Cost per step \[s\].
    pub per_step: f64,
    /// Largest |Δ| over every sample of every state against the reference (over the peer's
    /// shorter horizon for the peer).
    pub error: f64,
    /// For the peer: its cost per step over Moreau–Jean's on the same horizon.
    pub per_step_ratio: Option<f64>,
}

/// The study's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingReport {
    /// What ran.
    pub options: ScalingOptions,
    /// Every point, by N then solver.
    pub points: Vec<ScalingPoint>,
    /// Why a runner did not run at some N.
    pub skipped: Vec<String>,
}

/// The chain of the study: the rig's top disc and N − 1 copies of its lower disc (Table 1).
pub fn chain(n: usize) -> ChainParams {
    ChainParams::rig_copies(&Params::table1(), n)
}

/// The initial state: relaxed springs, every disc at `omega0`.
fn x0(n: usize, omega0: f64) -> Vec<f64> {
    let mut x = vec![0.0; 2 * n - 1];
    x[n - 1..].fill(omega0);
    x
}

/// Per state component, the largest |a − b| over two runs on one grid, the largest of them.
fn max_diff(a: &Trajectory, b: &Trajectory) -> f64 {
    a.samples
        .iter()
        .zip(b.samples.iter())
        .flat_map(|(r, s)| r.x.iter().zip(s.x).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One timed run: the trajectory and the seconds it took.
fn timed(
    kind: SolverKind,
    model: &ChainModel,
    scene: &Scene,
) -> Result<(Trajectory, f64), BenchError> {
    let start = Instant::now();
    let tr = kind
        .simulate_chain(model, scene)
        .map_err(|source| BenchError::Solve {
            solver: kind.name(),
            setting_name: kind.setting_name(),
            setting: match scene.accuracy {
                rotor_model::seam::Accuracy::Tol(v) | rotor_model::seam::Accuracy::Step(v) => v,
            },
            scene: format!("chain of {}", model.discs()),
            source,
        })?;
    Ok((tr, start.elapsed().as_secs_f64()))
}

/// Runs the study, reporting progress.
pub fn run(
    opts: &ScalingOptions,
    progress: &mut impl FnMut(&str),
) -> Result<ScalingReport, BenchError> {
    if opts
        .discs
        .iter()
        .any(|&n| !(2..=rotor_model::Mode::MAX_DISCS).contains(&n))
    {
        return Err(BenchError::Options(format!(
            "discs = {:?}: each must lie in 2..={}",
            opts.discs,
            rotor_model::Mode::MAX_DISCS
        )));
    }
    if !(opts.target > 0.0 && opts.t_end > 0.0 && opts.dt > 0.0 && opts.repeats >= 1) {
        return Err(BenchError::Options(format!(
            "target = {}, t_end = {}, dt = {}, repeats = {}: each must be positive",
            opts.target, opts.t_end, opts.dt, opts.repeats
        )));
    }
    let mut points = Vec::new();
    let mut skipped = Vec::new();
    for &n in &opts.discs {
        let params = chain(n);
        let model = ChainModel::new(&params);
        let scene = |accuracy, t_end| Scene {
            u: opts.u,
            x0: x0(model.discs(), opts.omega0),
            t_end,
            accuracy,
            output: Output::Grid { dt: opts.dt },
            ..Scene::default()
        };
        progress(&format!(
            "N = {n}: reference (event, tol {:e})",
            opts.reference_tol
        ));
        let (reference, _) = timed(
            SolverKind::EVENT,
            &model,
            &scene(SolverKind::EVENT.accuracy(opts.reference_tol), opts.t_end),
        )?;
        let mut moreau_h = None;
        for kind in SOLVERS.iter().copied().filter(|k| k.info().chain.is_some()) {
            // The loosest setting of the ladder within the target.
            let mut chosen = None;
            for &setting in kind.info().ladder {
                let sc = scene(kind.accuracy(setting), opts.t_end);
                let (tr, _) = timed(kind, &model, &sc)?;
                let error = max_diff(&tr, &reference);
                if error <= opts.target {
                    chosen = Some((setting, sc, tr, error));
                    break;
                }
            }
            let Some((setting, sc, tr, error)) = chosen else {
                skipped.push(format!(
                    "{} at N = {n}: no setting of its ladder within {:e}",
                    kind.name(),
                    opts.target
                ));
                continue;
            };
            let mut times = Vec::with_capacity(opts.repeats);
            for _ in 0..opts.repeats {
                times.push(timed(kind, &model, &sc)?.1);
            }
            let seconds = median(times);
            progress(&format!(
                "N = {n}: {} at {} = {setting:e}: {seconds:.3e} s, error {error:.1e}",
                kind.name(),
                kind.setting_name()
            ));
            if kind == SolverKind::MOREAU {
                moreau_h = Some(setting);
            }
            points.push(ScalingPoint {
                discs: n,
                runner: kind.name().to_owned(),
                setting_name: kind.setting_name(),
                setting,
                horizon: opts.t_end,
                steps: tr.stats.steps,
                seconds,
                per_second: seconds / opts.t_end,
                per_step: seconds / tr.stats.steps.max(1) as f64,
                error,
                per_step_ratio: None,
            });
        }
        if let (Some(sic), Some(h)) = (&opts.siconos, moreau_h) {
            match siconos_point(opts, sic, (&params, &model), h, &reference, progress) {
                Ok(p) => points.push(p),
                Err(why) => skipped.push(format!("siconos at N = {n}: {why}")),
            }
        }
    }
    Ok(ScalingReport {
        options: opts.clone(),
        points,
        skipped,
    })
}

/// One run of the Siconos peer at step `h` over `horizon`: its trace's rows, its steps and
/// its in-process seconds.
fn siconos_run(
    opts: &ScalingOptions,
    sic: &SiconosOptions,
    (params, model): (&ChainParams, &ChainModel),
    h: f64,
    horizon: f64,
) -> Result<(Vec<Vec<f64>>, u64, f64), String> {
    let n = model.discs();
    std::fs::create_dir_all(&sic.work).map_err(|e| format!("{}: {e}", sic.work.display()))?;
    let trace = sic.work.join(format!("siconos-chain-{n}.csv"));
    let job_path = sic.work.join(format!("siconos-chain-{n}.json"));
    let job = Job {
        benchmark: crate::grade::check::BENCHMARK,
        scenario: format!("chain-{n}"),
        params: serde_json::to_value(params).map_err(|e| e.to_string())?,
        u: Some(opts.u),
        input: None,
        x0: x0(n, opts.omega0),
        t_end: horizon,
        dt: opts.dt,
        tol: None,
        h: Some(h),
        trace: trace.clone(),
        events: sic.work.join(format!("siconos-chain-{n}-events.csv")),
    };
    std::fs::write(&job_path, job.to_json()).map_err(|e| e.to_string())?;
    let argv = vec![
        sic.python.clone(),
        sic.dir.join("siconos_chain.py").display().to_string(),
    ];
    let out = run_client(&argv, &job_path, sic.timeout)?;
    if !matches!(out.ended, Ended::Exited(s) if s.success()) {
        return Err(format!(
            "the client failed ({:?}): {}",
            out.ended,
            crate::protocol::tail(&out.stderr, 3)
        ));
    }
    let says = ClientSays::from_stdout(&out.stdout);
    let Some(secs) = says.solve_seconds.filter(|s| s.is_finite() && *s > 0.0) else {
        return Err("the client printed no solve_seconds".into());
    };
    let rows = read_trace(&trace, &model.state_names())?;
    Ok((rows, says.steps.unwrap_or(0), secs))
}

/// The Siconos peer over `sic.horizon`: at the loosest step of Moreau–Jean's ladder, from
/// Moreau–Jean's chosen `h` down, whose error against the reference over that horizon is
/// within the target; its cost per step beside Moreau–Jean's at the same step and horizon.
/// A run that takes longer than 10 s is timed once (its noise is far below the ratios read
/// from it).
fn siconos_point(
    opts: &ScalingOptions,
    sic: &SiconosOptions,
    chain: (&ChainParams, &ChainModel),
    h: f64,
    reference: &Trajectory,
    progress: &mut impl FnMut(&str),
) -> Result<ScalingPoint, String> {
    let model = chain.1;
    let n = model.discs();
    // A whole number of grid intervals, at least one.
    let horizon = ((sic.horizon / opts.dt + 1e-9).floor().max(1.0) * opts.dt).min(opts.t_end);
    let error_of = |rows: &[Vec<f64>]| -> Result<f64, String> {
        // The reference's samples are on the same grid from t = 0.
        let mut worst = 0.0f64;
        for (p, r) in rows.iter().zip(reference.samples.iter()) {
            if (p[0] - r.t).abs() > 1e-9 * opts.dt {
                return Err(format!(
                    "its trace has a row at t = {}, the grid's is {}",
                    p[0], r.t
                ));
            }
            for (a, b) in p[1..].iter().zip(r.x) {
                worst = worst.max((a - b).abs());
            }
        }
        Ok(worst)
    };
    let ladder = SolverKind::MOREAU.info().ladder;
    let mut found = None;
    for &step in ladder.iter().filter(|&&s| s <= h) {
        progress(&format!(
            "N = {n}: siconos at h = {step:e} over {horizon} s"
        ));
        let (rows, steps, secs) = siconos_run(opts, sic, chain, step, horizon)?;
        if rows.len() != (horizon / opts.dt).round() as usize + 1 {
            return Err(format!("its trace has {} rows", rows.len()));
        }
        let error = error_of(&rows)?;
        if error <= opts.target {
            found = Some((step, steps, secs, error));
            break;
        }
        progress(&format!(
            "N = {n}: siconos at h = {step:e}: error {error:.1e}"
        ));
    }
    let Some((step, steps, first, error)) = found else {
        return Err(format!(
            "no step of the ladder down to {:e} within {:e} over {horizon} s",
            ladder[ladder.len() - 1],
            opts.target
        ));
    };
    let mut times = vec![first];
    while first < 10.0 && times.len() < opts.repeats {
        times.push(siconos_run(opts, sic, chain, step, horizon)?.2);
    }
    let seconds = median(times);
    let moreau_scene = Scene {
        u: opts.u,
        x0: x0(n, opts.omega0),
        t_end: horizon,
        accuracy: SolverKind::MOREAU.accuracy(step),
        output: Output::Grid { dt: opts.dt },
        ..Scene::default()
    };
    let mut mj = Vec::with_capacity(opts.repeats);
    let mut mj_steps = 0;
    for _ in 0..opts.repeats {
        let (tr, s) = timed(SolverKind::MOREAU, model, &moreau_scene).map_err(|e| e.to_string())?;
        mj.push(s);
        mj_steps = tr.stats.steps;
    }
    let per_step = seconds / steps.max(1) as f64;
    let mj_per_step = median(mj) / mj_steps.max(1) as f64;
    Ok(ScalingPoint {
        discs: n,
        runner: "siconos".into(),
        setting_name: "h",
        setting: step,
        horizon,
        steps,
        seconds,
        per_second: seconds / horizon,
        per_step,
        error,
        per_step_ratio: Some(per_step / mj_per_step),
    })
}

/// A chain trace written by a client: its rows (t first), the header checked against the
/// chain's names.
fn read_trace(path: &Path, names: &[String]) -> Result<Vec<Vec<f64>>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let want = format!("t,{}", names.join(","));
    match lines.next() {
        Some(h) if h.trim() == want => {}
        h => {
            return Err(format!(
                "{}: header {h:?}, expected {want:?}",
                path.display()
            ));
        }
    }
    lines
        .enumerate()
        .map(|(i, l)| {
            l.split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<Vec<f64>, _>>()
                .ok()
                .filter(|r| r.len() == names.len() + 1 && r.iter().all(|v| v.is_finite()))
                .ok_or_else(|| {
                    format!(
                        "{}: row {} is not {} numbers",
                        path.display(),
                        i + 2,
                        names.len() + 1
                    )
                })
        })
        .collect()
}

/// Least-squares slope of `log y` against `log x`.
fn log_slope(pts: &[(f64, f64)]) -> Option<f64> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

impl ScalingReport {
    /// The runners, in the order they first appear.
    fn runners(&self) -> Vec<&str> {
        let mut v: Vec<&str> = Vec::new();
        for p in &self.points {
            if !v.contains(&p.runner.as_str()) {
                v.push(&p.runner);
            }
        }
        v
    }

    /// A runner's log–log slope against N of one cost of its points.
    fn slope_of(&self, runner: &str, cost: fn(&ScalingPoint) -> f64) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.runner == runner)
            .map(|p| (p.discs as f64, cost(p)))
            .collect();
        log_slope(&pts)
    }

    /// A runner's slope of cost per simulated second against N (log–log), over its points.
    pub fn slope(&self, runner: &str) -> Option<f64> {
        self.slope_of(runner, |p| p.per_second)
    }

    /// A runner's slope of cost per step against N (log–log).
    pub fn step_slope(&self, runner: &str) -> Option<f64> {
        self.slope_of(runner, |p| p.per_step)
    }

    /// The points as CSV, one row each.
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "discs,runner,setting_name,setting,horizon_s,steps,seconds,per_second,per_step,\
             error,per_step_ratio\n",
        );
        for p in &self.points {
            s.push_str(&format!(
                "{},{},{},{:e},{},{},{:.4e},{:.4e},{:.4e},{:.2e},{}\n",
                p.discs,
                p.runner,
                p.setting_name,
                p.setting,
                p.horizon,
                p.steps,
                p.seconds,
                p.per_second,
                p.per_step,
                p.error,
                p.per_step_ratio
                    .map_or(String::new(), |r| format!("{r:.1}"))
            ));
        }
        s
    }

    /// A table of the points and the slopes, in Markdown.
    pub fn to_markdown(&self) -> String {
        let o = &self.options;
        let mut s = format!(
            "Chains of N discs (the rig's top disc and N − 1 copies of its lower disc, Table 1), \
             {} V, every disc at {} rad/s with the springs relaxed at t = 0, over {} s; every solver at the loosest setting of its ladder within \
             {:e} of the event-driven solver at tol {:e} (largest |Δ| over every sample of every \
             state). Siconos runs at Moreau–Jean's h on a shorter horizon (its error is \
             against the reference over that horizon).\n\n\
             | N | runner | setting | horizon [s] | steps | cost per simulated s [s] | cost \
             per step [µs] | error | per step vs Moreau–Jean |\n\
             |---:|---|---|---:|---:|---:|---:|---:|---:|\n",
            o.u, o.omega0, o.t_end, o.target, o.reference_tol
        );
        for p in &self.points {
            s.push_str(&format!(
                "| {} | {} | {} = {:e} | {} | {} | {:.3e} | {:.2} | {:.1e} | {} |\n",
                p.discs,
                p.runner,
                p.setting_name,
                p.setting,
                p.horizon,
                p.steps,
                p.per_second,
                p.per_step * 1e6,
                p.error,
                p.per_step_ratio.map_or("".into(), |r| format!("{r:.0}×"))
            ));
        }
        s.push_str("\nSlopes (log–log least squares against N):\n\n");
        for r in self.runners() {
            s.push_str(&format!(
                "* {r}: cost per simulated second {}, cost per step {}\n",
                self.slope(r).map_or("–".into(), |v| format!("{v:.2}")),
                self.step_slope(r).map_or("–".into(), |v| format!("{v:.2}"))
            ));
        }
        for w in &self.skipped {
            s.push_str(&format!("* skipped: {w}\n"));
        }
        s
    }

    /// The figure: cost per simulated second against N, log–log, one line per runner.
    pub fn to_svg(&self) -> String {
        let runners = self.runners();
        let labels: Vec<String> = runners
            .iter()
            .map(|r| match self.slope(r) {
                Some(v) => format!("{r} (slope {v:.2})"),
                None => (*r).to_owned(),
            })
            .collect();
        let series: Vec<Series> = runners
            .iter()
            .zip(&labels)
            .map(|(r, label)| {
                let st = style(r);
                Series {
                    dash: st.dash,
                    marker: Some(3.5),
                    shape: st.shape,
                    ..Series::line(
                        label,
                        st.color,
                        self.points
                            .iter()
                            .filter(|p| p.runner == *r)
                            .map(|p| (p.discs as f64, p.per_second))
                            .collect(),
                    )
                }
            })
            .collect();
        let mut panel = Panel::new(
            format!(
                "Cost against the number of discs, at error ≤ {:e}",
                self.options.target
            ),
            "discs N",
            "run time per simulated second [s]",
            series,
        );
        panel.x_log = true;
        panel.y_log = true;
        panel.x_ticks = self.options.discs.iter().map(|&n| n as f64).collect();
        render(&[panel], 640.0, 400.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let pts: Vec<(f64, f64)> = [2.0, 4.0, 8.0, 64.0]
            .iter()
            .map(|&n: &f64| (n, 3.0 * n.powf(1.5)))
            .collect();
        assert!((log_slope(&pts).unwrap() - 1.5).abs() < 1e-12);
        assert_eq!(log_slope(&pts[..1]), None);
    }

    /// A small study without the peer: every solver with a chain run has a point at every N,
    /// within the target, with its costs; the table, the CSV and the figure hold them.
    #[test]
    fn a_small_study_reaches_the_target_with_every_chain_solver() {
        let opts = ScalingOptions {
            discs: vec![2, 3],
            t_end: 4.0,
            repeats: 1,
            ..ScalingOptions::default()
        };
        let r = run(&opts, &mut |_| {}).unwrap();
        let chain_solvers = SOLVERS.iter().filter(|k| k.info().chain.is_some()).count();
        assert_eq!(r.points.len(), 2 * chain_solvers, "{:?}", r.skipped);
        for p in &r.points {
            assert!(p.error <= opts.target, "{p:?}");
            assert!(
                p.per_second > 0.0 && p.per_step > 0.0 && p.steps > 0,
                "{p:?}"
            );
        }
        let md = r.to_markdown();
        assert!(
            md.contains("| 3 | moreau |") && md.contains("| 2 | switch |"),
            "{md}"
        );
        assert_eq!(r.to_csv().lines().count(), r.points.len() + 1);
        assert!(r.to_svg().starts_with("<svg"));
    }

    #[test]
    fn bad_options_are_refused_by_name() {
        let e = run(
            &ScalingOptions {
                discs: vec![1],
                ..ScalingOptions::default()
            },
            &mut |_| {},
        )
        .unwrap_err();
        assert!(e.to_string().contains("discs = [1]"), "{e}");
    }
}
