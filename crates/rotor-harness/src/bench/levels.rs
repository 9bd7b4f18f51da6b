//! Output levels: each solver's metrics-only, final-only and full-trace runs of the same
//! scene, timed side by side.

use rotor_model::seam::{Output, SolveError};
use serde::{Deserialize, Serialize};

use crate::bench::BenchError;
use crate::bench::ladder::Loaded;
use crate::bench::measure::{Timing, scene_at, solver};
use crate::bench::options::{BenchOptions, SolverKind};

/// Metrics-only vs final-state-only vs full-trace run of one solver (all with metrics).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OutputLevel {
    /// The solver.
    pub solver: SolverKind,
    /// `tol` or `h`.
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub setting_name: crate::bench::word::Word,
    /// The setting's value (h in s).
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
    /// Events the metrics-only run kept (see `metrics_only_samples`).
    pub metrics_only_events: usize,
    /// Samples the full-trace run kept.
    pub full_trace_samples: usize,
    /// Whole periods the metrics-only run skipped, and skips it undid.
    pub skipped_periods: u64,
    /// Skips the metrics-only run undid (see `skipped_periods`).
    pub undone_skips: u64,
    /// Largest difference of a metric between the metrics-only and the full-trace run,
    /// relative to max(|m|, 1); `None` if they do not report the same kind of steady state.
    pub metrics_diff: Option<f64>,
    /// Whether the final-only run reports the same metrics and final state as the full trace
    /// (keeping output must not perturb the integration).
    pub same_answer: bool,
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

pub(crate) fn output_levels(
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
            same_answer: f.rig_metrics() == b.rig_metrics() && f.x_final == b.x_final,
        });
    }
    Ok(v)
}

/// Largest `|m_a − m_b| / max(|m|, 1)` over the metrics of two runs; `None` if they differ in
/// kind or one has none.
fn metrics_difference(
    a: &rotor_model::seam::Trajectory,
    b: &rotor_model::seam::Trajectory,
) -> Option<f64> {
    match (a.rig_metrics(), b.rig_metrics()) {
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
