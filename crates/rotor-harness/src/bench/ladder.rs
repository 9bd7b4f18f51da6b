//! The reference run of a scene and each solver's ladder of settings, every point timed and
//! measured against the reference.

use crate::grade::check::{Level, check};
use crate::grade::gridmetrics::{StickExit, grid_metrics};
use crate::grade::reference::Reference;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Accuracy, Output, Scene, Stats};
use serde::{Deserialize, Serialize};

use crate::bench::BenchError;
use crate::bench::measure::{
    Errors, RefData, SteadyRef, Timing, run_point, scene_at, solver, timed, window,
};
use crate::bench::options::{BenchOptions, SceneSpec, SolverKind};

/// One scene: its reference and every ladder point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SceneReport {
    /// The scenario's name.
    pub name: String,
    /// `table1` or `full` ([`crate::bench::Tier`]).
    #[serde(default)]
    pub tier: String,
    /// The scenario's description.
    pub description: String,
    /// Motor input voltage u \[V\].
    pub u: f64,
    /// Initial state (`[α, ω_u, ω_l]` in rad, rad/s, rad/s on the rig; the model's size).
    pub x0: Vec<f64>,
    /// Horizon of every run (s).
    pub t_end: f64,
    /// Start of the steady-state window `[metrics_from, t_end]` (s).
    pub metrics_from: f64,
    /// Window `[t0, t1]` (s) on which the transient error is read.
    pub transient: [f64; 2],
    /// Grid step of the traces (s).
    pub dt: f64,
    /// The reference run.
    pub reference: ReferenceReport,
    /// Every solver's ladder points, solver by solver, in the order of the options' ladders.
    pub points: Vec<LadderPoint>,
}

/// The reference run and the estimate of its own error.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceReport {
    /// The reference solver (the event-driven one).
    pub solver: SolverKind,
    /// Its tolerance ([`BenchOptions::reference_tol`]).
    pub tol: f64,
    /// `limit_cycle` or `equilibrium` (the steady state over `[metrics_from, t_end]`).
    #[serde(
        default = "cycle_word",
        deserialize_with = "crate::bench::word::static_str"
    )]
    pub kind: crate::bench::word::Word,
    /// Period of the last complete cycle (s); `None` for an equilibrium.
    pub period: Option<f64>,
    /// Max ω_l over that cycle (rad/s); for an equilibrium its ω_l.
    pub omega_l_max: Option<f64>,
    /// One untimed run (s).
    pub seconds: f64,
    /// Work counters of that run.
    pub stats: Stats,
    /// Tolerance of the check run.
    pub check_tol: f64,
    /// Errors of the reference measured against the check run (swapped roles: the
    /// difference between the two, an estimate of the reference's own error).
    pub check: Option<Errors>,
    /// Why the check run failed, if it did.
    pub check_failure: Option<String>,
}

fn cycle_word() -> crate::bench::word::Word {
    "limit_cycle"
}

/// One solver at one accuracy setting.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LadderPoint {
    /// The solver.
    pub solver: SolverKind,
    /// `tol` or `h`.
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub setting_name: crate::bench::word::Word,
    /// The setting's value (h in s).
    pub setting: f64,
    /// `None` if the run failed.
    pub timing: Option<Timing>,
    /// Its errors against the reference (all `None` if the run failed).
    pub errors: Errors,
    /// Work counters of one run.
    pub stats: Stats,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
    /// Whether its trace passes the scenario's loose gate, graded as an external trace is
    /// (`rotor check`): the "solved" of the performance profile.
    pub passes_loose: Option<bool>,
    /// Whether it passes the strict level, graded the same way.
    #[serde(default)]
    pub passes_strict: Option<bool>,
    /// The trace's significant correct digits, as `rotor check` counts them (the fewest of
    /// any graded quantity, events included).
    #[serde(default)]
    pub digits: Option<f64>,
}

/// A loaded scene with its reference.
pub(crate) struct Loaded {
    pub(crate) scenario: Scenario,
    pub(crate) spec: SceneSpec,
    pub(crate) base: Scene,
    pub(crate) refd: RefData,
    /// The reference's metrics read off its grid as a trace's are
    /// ([`crate::grade::gridmetrics`]): what a trace-only client's errors are measured
    /// against, so that the reconstruction's own error cancels.
    pub(crate) grid_refd: RefData,
    /// The scene as a scenario (its horizon and windows) and the reference run as a
    /// reference, for grading traces as `rotor check` does.
    pub(crate) view: (Scenario, Reference),
}

pub(crate) fn load(
    opts: &BenchOptions,
    spec: &SceneSpec,
    progress: &mut impl FnMut(&str),
) -> Result<(Loaded, ReferenceReport), BenchError> {
    let scenario = rotor_analysis::solvers::load_scenario(&spec.scenario)?;
    let base = Scene {
        u: scenario.u,
        input: scenario.input.clone(),
        x0: scenario.x0.clone(),
        t_end: spec.t_end,
        accuracy: Accuracy::Tol(opts.reference_tol),
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
    let no_steady = || BenchError::NoReferenceCycle {
        scene: scenario.name.clone(),
    };
    progress(&format!(
        "{}: reference check (event, tol {:e})",
        scenario.name, opts.reference_check_tol
    ));
    let check_scene = Scene {
        accuracy: Accuracy::Tol(opts.reference_check_tol),
        ..base.clone()
    };
    let (check, check_failure) = match ev.simulate(&scenario.model, &check_scene) {
        Ok(c) => match RefData::new(&c, spec.transient, spec.dt) {
            // The reference measured against the tighter run.
            Some(cd) => (
                Some(cd.errors(
                    SteadyRef::of(tr.rig_metrics().as_ref()),
                    &window(&tr, spec.transient, spec.dt),
                )),
                None,
            ),
            None => (None, Some("the check run gives no steady state".into())),
        },
        Err(e) => (None, Some(e.to_string())),
    };
    let mut view_sc = scenario.clone();
    view_sc.t_end = spec.t_end;
    view_sc.compare = rotor_model::scenario::CompareSpec {
        transient: Some(spec.transient),
        dt: spec.dt,
        steady_from: Some(spec.metrics_from),
    };
    let view_ref = Reference::in_memory(&view_sc, &tr, opts.reference_tol);
    let exit = StickExit {
        model: &scenario.model,
        u: scenario.steady_u(),
    };
    // The reference's steady state read off its grid as a trace's is.
    let rig: Vec<_> = tr.samples.iter().map(|r| r.sample()).collect();
    let grid_steady = grid_metrics(&rig, spec.metrics_from, exit).map_err(|_| no_steady())?;
    let grid_refd = RefData {
        steady: SteadyRef::of(Some(&grid_steady)).ok_or_else(no_steady)?,
        ..refd.clone()
    };
    let reference = ReferenceReport {
        solver: SolverKind::EVENT,
        tol: opts.reference_tol,
        kind: match refd.steady {
            SteadyRef::Cycle { .. } => "limit_cycle",
            SteadyRef::Equilibrium { .. } => "equilibrium",
        },
        period: refd.steady.cycle().map(|c| c.0),
        omega_l_max: Some(match refd.steady {
            SteadyRef::Cycle { omega_l_max, .. } => omega_l_max,
            SteadyRef::Equilibrium { omega_l, .. } => omega_l,
        }),
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
            grid_refd,
            view: (view_sc, view_ref),
        },
        reference,
    ))
}

pub(crate) fn ladders(
    opts: &BenchOptions,
    l: &Loaded,
    progress: &mut impl FnMut(&str),
) -> Vec<LadderPoint> {
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
                Ok((tr, timing, errors)) => {
                    let (loose, strict, digits) = graded(l, &tr);
                    LadderPoint {
                        solver: kind,
                        setting_name: kind.setting_name(),
                        setting,
                        timing: Some(timing),
                        errors,
                        stats: tr.stats,
                        failure: None,
                        passes_loose: loose,
                        passes_strict: strict,
                        digits,
                    }
                }
                Err(e) => LadderPoint {
                    solver: kind,
                    setting_name: kind.setting_name(),
                    setting,
                    timing: None,
                    errors: Errors::default(),
                    stats: Stats::default(),
                    failure: Some(e.to_string()),
                    passes_loose: None,
                    passes_strict: None,
                    digits: None,
                },
            };
            points.push(point);
        }
    }
    points
}

/// A run's trace and events graded as `rotor check` grades an external trace: whether they
/// pass the loose and the strict level, and their digits (`None` where the grade cannot be
/// made).
fn graded(
    l: &Loaded,
    tr: &rotor_model::seam::Trajectory,
) -> (Option<bool>, Option<bool>, Option<f64>) {
    let (sc, r) = &l.view;
    let trace = crate::grade::trace::Trace::of_run("run", &tr.samples);
    let events = crate::grade::trace::EventsFile::of_run("run", &tr.events);
    let loose = check(sc, r, &trace, Some(&events), Level::Loose).ok();
    let strict = check(sc, r, &trace, Some(&events), Level::Strict).ok();
    (
        loose.as_ref().map(|c| c.passed),
        strict.map(|c| c.passed),
        loose.map(|c| c.digits),
    )
}
