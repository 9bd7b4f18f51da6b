//! Peers in other languages, run as subprocesses in the same benchmark run: each prints one
//! JSON object with its own in-process run times (interpreter start-up excluded).

use std::path::Path;
use std::process::Command;

use rotor_model::{PairTolerance, State};
use serde::{Deserialize, Serialize};

use crate::BenchError;
use crate::ladder::{LadderPoint, Loaded};
use crate::measure::{Errors, Timing, run_point, scene_at, time_at_error};
use crate::options::{BenchOptions, SolverKind};

/// What a peer script prints.
#[derive(Debug, Clone, Deserialize)]
pub struct PeerOutput {
    /// `"scipy"` or `"siconos"`.
    pub peer: String,
    /// Version of the library it drives.
    pub version: String,
    /// Integration method (`"DOP853"`, `"MoreauJeanOSI"`).
    pub method: String,
    /// One entry per accuracy setting.
    pub runs: Vec<PeerRun>,
}

/// One setting of a peer.
#[derive(Debug, Clone, Deserialize)]
pub struct PeerRun {
    /// rtol = atol, or h.
    pub setting: f64,
    /// Every timed run (s).
    pub seconds: Vec<f64>,
    /// Steady-state metrics of the last complete cycle, if a cycle was found.
    pub metrics: Option<PeerMetrics>,
    /// Accepted steps (all segments).
    pub steps: Option<u64>,
    /// Right-hand-side evaluations.
    pub rhs_evals: Option<u64>,
    /// Grid times of the transient window and ω_l there.
    pub t: Vec<f64>,
    pub omega_l: Vec<f64>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// A peer's cycle metrics.
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct PeerMetrics {
    pub period: f64,
    pub omega_l_max: f64,
}

/// Whether `python -c "import <module>"` works; the error says why not.
pub fn available(python: &str, module: &str) -> Result<(), String> {
    match Command::new(python)
        .args(["-c", &format!("import {module}")])
        .output()
    {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(format!(
            "`{python} -c \"import {module}\"` failed: {}",
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )),
        Err(e) => Err(format!("cannot run `{python}`: {e}")),
    }
}

/// Runs a peer script with arguments and parses its JSON.
pub fn run_script(python: &str, script: &Path, args: &[String]) -> Result<PeerOutput, BenchError> {
    let out = Command::new(python)
        .arg(script)
        .args(args)
        .output()
        .map_err(|e| BenchError::Peer {
            peer: script.display().to_string(),
            detail: format!("cannot run `{python}`: {e}"),
        })?;
    if !out.status.success() {
        return Err(BenchError::Peer {
            peer: script.display().to_string(),
            detail: format!(
                "exit status {}: {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        });
    }
    let parsed: PeerOutput = serde_json::from_slice(&out.stdout).map_err(|e| BenchError::Peer {
        peer: script.display().to_string(),
        detail: format!("unreadable JSON on stdout: {e}"),
    })?;
    parsed.validate().map_err(|detail| BenchError::Peer {
        peer: script.display().to_string(),
        detail,
    })?;
    Ok(parsed)
}

impl PeerOutput {
    /// Checks what the ratios are computed from: settings and run times positive and finite,
    /// step counts positive, metrics and samples finite, one ω_l per grid time. The error
    /// names the run and the field. (A failed run, with `failure` set, is only reported.)
    pub fn validate(&self) -> Result<(), String> {
        for (i, r) in self.runs.iter().enumerate() {
            let bad =
                |field: &str, v: String, why: &str| Err(format!("runs[{i}].{field} = {v}: {why}"));
            if !(r.setting > 0.0 && r.setting.is_finite()) {
                return bad(
                    "setting",
                    r.setting.to_string(),
                    "must be positive and finite",
                );
            }
            if r.failure.is_some() {
                continue;
            }
            if let Some(x) = r.seconds.iter().find(|x| !(**x > 0.0 && x.is_finite())) {
                return bad(
                    "seconds",
                    x.to_string(),
                    "run times must be positive and finite",
                );
            }
            if r.steps == Some(0) {
                return bad("steps", "0".into(), "a run takes at least one step");
            }
            if let Some(m) = r.metrics
                && !(m.period > 0.0 && m.period.is_finite() && m.omega_l_max.is_finite())
            {
                return bad(
                    "metrics",
                    format!("{m:?}"),
                    "must be finite, with a positive period",
                );
            }
            if r.t.len() != r.omega_l.len() {
                return bad(
                    "omega_l",
                    format!("{} values", r.omega_l.len()),
                    &format!("must be one per grid time ({} times)", r.t.len()),
                );
            }
            if let Some(x) = r.t.iter().chain(&r.omega_l).find(|x| !x.is_finite()) {
                return bad("t/omega_l", x.to_string(), "samples must be finite");
            }
        }
        Ok(())
    }
}

/// `1e-4,1e-5` for a command line (shortest round-trip form).
pub fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:e}"))
        .collect::<Vec<_>>()
        .join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> PeerOutput {
        serde_json::from_str(
            r#"{"peer": "scipy", "version": "1", "method": "DOP853", "runs": [
                {"setting": 1e-6, "seconds": [0.1, 0.2], "metrics": {"period": 4.5,
                 "omega_l_max": 6.3}, "steps": 10, "rhs_evals": 100, "t": [0.0, 0.01],
                 "omega_l": [0.0, 0.1], "failure": null},
                {"setting": 1e-4, "seconds": [], "metrics": null, "steps": null,
                 "rhs_evals": null, "t": [], "omega_l": [], "failure": "step too small"}]}"#,
        )
        .unwrap()
    }

    #[test]
    fn peer_output_is_checked_before_any_ratio() {
        assert_eq!(good().validate(), Ok(()));
        type Spoil = fn(&mut PeerRun);
        let cases: [(Spoil, &str); 7] = [
            (|r| r.setting = 0.0, "runs[0].setting = 0"),
            (|r| r.seconds[1] = f64::NAN, "runs[0].seconds = NaN"),
            (|r| r.seconds[0] = 0.0, "runs[0].seconds = 0"),
            (|r| r.steps = Some(0), "runs[0].steps = 0"),
            (
                |r| r.metrics.as_mut().unwrap().period = f64::INFINITY,
                "runs[0].metrics",
            ),
            (|r| r.omega_l.push(1.0), "runs[0].omega_l = 3 values"),
            (|r| r.t[1] = f64::NAN, "runs[0].t/omega_l = NaN"),
        ];
        for (spoil, needle) in cases {
            let mut o = good();
            spoil(&mut o.runs[0]);
            let e = o.validate().unwrap_err();
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
    }
}

/// Whether a peer ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PeerStatus {
    Ran,
    /// Not installed, or turned off.
    Skipped,
    Failed,
}

impl PeerStatus {
    /// `"ran"`, `"skipped"` or `"failed"`.
    pub fn as_str(self) -> &'static str {
        match self {
            PeerStatus::Ran => "ran",
            PeerStatus::Skipped => "skipped",
            PeerStatus::Failed => "failed",
        }
    }
}

/// A peer: what it computed, whether it agrees, and how it compares.
#[derive(Debug, Clone, Serialize)]
pub struct PeerReport {
    /// `"scipy"` or `"siconos"`.
    pub name: String,
    pub status: PeerStatus,
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

fn skipped(
    name: &str,
    setting_name: &'static str,
    status: PeerStatus,
    reason: String,
) -> PeerReport {
    PeerReport {
        name: name.into(),
        status,
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
            PeerStatus::Skipped,
            "turned off in the options".into(),
        )));
    }
    if let Err(why) = available(pl.python, pl.module) {
        progress(&format!("{name} peer skipped: {why}"));
        return Err(Box::new(skipped(name, setting, PeerStatus::Skipped, why)));
    }
    let list = list(pl.settings);
    progress(&format!(
        "{}: {name} peer, {setting} = {list}",
        l.scenario.name
    ));
    let mut args = peer_args(l, opts.repeats, opts.time_budget);
    args.extend([pl.flag.to_string(), list]);
    let out = run_script(pl.python, &opts.peers.dir.join(pl.script), &args)
        .map_err(|e| Box::new(skipped(name, setting, PeerStatus::Failed, e.to_string())))?;
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

pub(crate) fn scipy_peer(
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
        status: PeerStatus::Ran,
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

pub(crate) fn siconos_peer(
    opts: &BenchOptions,
    l: &Loaded,
    progress: &mut impl FnMut(&str),
) -> PeerReport {
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
        status: PeerStatus::Ran,
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
