//! The report as a text table, JSON and CSV (its figures: [`crate::bench::figures`]).

use std::fmt::Write;

use crate::bench::clients::{ClientReport, FailureKind};
use crate::bench::measure::Errors;
use crate::bench::{BenchError, BenchReport, OutputLevel, Profile, SceneReport};

fn e(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.1e}"))
}

fn ms(s: f64) -> String {
    format!("{:.3}", 1e3 * s)
}

/// One row of the benchmark's CSV (an empty field where a value does not apply).
#[derive(serde::Serialize)]
struct CsvRow<'a> {
    scene: &'a str,
    source: &'a str,
    setting_name: &'a str,
    setting: f64,
    median_s: Option<f64>,
    min_s: Option<f64>,
    repeats: Option<usize>,
    err_period_s: Option<f64>,
    err_omega_l_max: Option<f64>,
    err_steady_rel: Option<f64>,
    err_transient_max: Option<f64>,
    steps: Option<u64>,
    rejected: Option<u64>,
    rhs_evals: Option<u64>,
    events: Option<u64>,
    lcp_solves: Option<u64>,
    newton_iters: Option<u64>,
    failure: &'a str,
}

impl<'a> CsvRow<'a> {
    fn new(
        scene: &'a str,
        source: &'a str,
        setting_name: &'a str,
        setting: f64,
        t: Option<crate::bench::Timing>,
        er: &Errors,
        c: [Option<u64>; 6],
        failure: Option<&'a str>,
    ) -> CsvRow<'a> {
        CsvRow {
            scene,
            source,
            setting_name,
            setting,
            median_s: t.map(|t| t.median_s),
            min_s: t.map(|t| t.min_s),
            repeats: t.map(|t| t.repeats),
            err_period_s: er.period,
            err_omega_l_max: er.omega_l_max,
            err_steady_rel: er.steady_rel,
            err_transient_max: er.transient_max,
            steps: c[0],
            rejected: c[1],
            rhs_evals: c[2],
            events: c[3],
            lcp_solves: c[4],
            newton_iters: c[5],
            failure: failure.unwrap_or(""),
        }
    }
}

impl BenchReport {
    /// A readable text table: per scene the reference and the ladders, then the output-level
    /// ratios and the peers.
    pub fn table(&self) -> String {
        let mut s = String::new();
        if !self.benchmark.is_empty() {
            let _ = writeln!(s, "suite {}\n", self.benchmark);
        }
        for sc in &self.scenes {
            scene_table(&mut s, sc);
        }
        if !self.output_levels.is_empty() {
            output_levels_table(&mut s, &self.output_levels);
        }
        for p in &self.clients {
            client_table(&mut s, p);
        }
        for prof in std::iter::once(&self.profile).chain(&self.profile_table1) {
            if !prof.entries.is_empty() {
                profile_table(&mut s, prof);
            }
        }
        self.environment_lines(&mut s);
        s
    }

    /// The table's last lines: where and how it was measured, and the shard.
    fn environment_lines(&self, s: &mut String) {
        let env = &self.environment;
        let load =
            |l: Option<[f64; 3]>| l.map_or("?".into(), |[a, b, c]| format!("{a:.2} {b:.2} {c:.2}"));
        let _ = writeln!(
            s,
            "measured on {} core(s){}{}, median of up to {} runs per point within {} s; load \
             average {} at the start, {} at the end",
            env.cores,
            if env.jobs > 1 {
                format!(", {} external clients side by side", env.jobs)
            } else {
                String::new()
            },
            if env.debug_build {
                ", DEBUG BUILD (times not meaningful)"
            } else {
                ""
            },
            env.repeats,
            env.time_budget_s,
            load(env.load_start),
            load(env.load_end)
        );
        if let Some(sh) = &self.shard {
            let _ = writeln!(
                s,
                "shard {}/{} of a suite of {} scene(s): rotor bench --merge joins the shards' \
                 --json reports",
                sh.index,
                sh.count,
                sh.suite["scenes"].as_array().map_or(0, Vec::len)
            );
        }
    }

    /// The first non-finite number of the report, as an error naming its path (e.g.
    /// `output_levels[0].ratio`). JSON has no NaN: serde_json would write `null`, the same as
    /// an absent value, so every writer checks this first. (The walk goes through a
    /// `toml::Value`, which keeps non-finite floats and skips absent fields.)
    pub fn check_finite(&self) -> Result<(), BenchError> {
        let v = toml::Value::try_from(self).map_err(|e| BenchError::Serialise(e.to_string()))?;
        match first_non_finite(&v, String::new()) {
            Some((path, value)) => Err(BenchError::NonFinite { path, value }),
            None => Ok(()),
        }
    }

    /// The report as pretty JSON (absent values are `null`; a non-finite number is an error).
    pub fn to_json(&self) -> Result<String, BenchError> {
        self.check_finite()?;
        serde_json::to_string_pretty(self).map_err(|e| BenchError::Serialise(e.to_string()))
    }

    /// Every point (ladders and peers) as CSV rows (a non-finite number is an error).
    pub fn to_csv(&self) -> Result<String, BenchError> {
        self.check_finite()?;
        let mut w = csv::Writer::from_writer(Vec::new());
        let counts = |st: &rotor_model::seam::Stats| {
            [
                Some(st.steps),
                Some(st.rejected),
                Some(st.rhs_evals),
                Some(st.events),
                Some(st.lcp_solves),
                Some(st.newton_iters),
            ]
        };
        let mut rows = Vec::new();
        for sc in &self.scenes {
            for p in &sc.points {
                rows.push(CsvRow::new(
                    &sc.name,
                    p.solver.name(),
                    p.setting_name,
                    p.setting,
                    p.timing,
                    &p.errors,
                    p.timing.map_or([None; 6], |_| counts(&p.stats)),
                    p.failure.as_deref(),
                ));
            }
        }
        for c in &self.clients {
            for cs in &c.scenes {
                for p in &cs.points {
                    rows.push(CsvRow::new(
                        &cs.scene,
                        &c.name,
                        c.setting_name,
                        p.setting,
                        p.time(),
                        &p.errors,
                        [p.steps, None, p.rhs_evals, None, None, None],
                        p.failure.as_ref().map(|f| f.detail.as_str()),
                    ));
                }
            }
        }
        let ser = |e: csv::Error| BenchError::Serialise(e.to_string());
        for r in &rows {
            w.serialize(r).map_err(ser)?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| BenchError::Serialise(e.to_string()))?;
        String::from_utf8(bytes).map_err(|e| BenchError::Serialise(e.to_string()))
    }
}

/// Depth-first: the path and value of the first non-finite float in `v`.
fn first_non_finite(v: &toml::Value, path: String) -> Option<(String, f64)> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((path, *x)),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, e)| first_non_finite(e, format!("{path}[{i}]"))),
        toml::Value::Table(t) => t.iter().find_map(|(k, e)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            first_non_finite(e, p)
        }),
        _ => None,
    }
}

/// One scene's block of [`BenchReport::table`]: the scene, its reference, and each solver's
/// ladder.
fn scene_table(s: &mut String, sc: &SceneReport) {
    let r = &sc.reference;
    let _ = writeln!(
        s,
        "scene {}: u = {} V, x0 = {:?}, {} s; metrics over [{}, {}] s, transient \
             [{}, {}] s on a {} s grid",
        sc.name,
        sc.u,
        sc.x0,
        sc.t_end,
        sc.metrics_from,
        sc.t_end,
        sc.transient[0],
        sc.transient[1],
        sc.dt
    );
    let steady = match (r.period, r.omega_l_max) {
        (Some(p), Some(w)) => format!("period {p:.12} s, max omega_l {w:.12} rad/s"),
        (_, w) => format!(
            "equilibrium, omega_l {} rad/s",
            w.map_or("?".into(), |w| format!("{w:.12}"))
        ),
    };
    let _ = writeln!(
        s,
        "reference: event tol {:e}: {steady} ({} steps, {} ms)",
        r.tol,
        r.stats.steps,
        ms(r.seconds)
    );
    match (&r.check, &r.check_failure) {
        (Some(c), _) => {
            let _ = writeln!(
                s,
                "reference error estimate (vs tol {:e}): steady {} rel, transient {} \
                     rad/s",
                r.check_tol,
                e(c.steady_rel),
                e(c.transient_max)
            );
        }
        (None, f) => {
            let _ = writeln!(
                s,
                "reference check at tol {:e} failed: {}",
                r.check_tol,
                f.as_deref().unwrap_or("?")
            );
        }
    }
    let _ = writeln!(
        s,
        "\n{:<7} {:>11} {:>11} {:>4} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} {:>9} {:>7}",
        "solver",
        "setting",
        "time [ms]",
        "runs",
        "steady rel",
        "period [s]",
        "wl max",
        "transient",
        "steps",
        "rejected",
        "rhs",
        "events"
    );
    for p in &sc.points {
        let setting = format!("{} {:.0e}", p.setting_name, p.setting);
        match (&p.timing, &p.failure) {
            (Some(t), _) => {
                let _ = writeln!(
                    s,
                    "{:<7} {:>11} {:>11} {:>4} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} \
                         {:>9} {:>7}",
                    p.solver.name(),
                    setting,
                    ms(t.median_s),
                    t.repeats,
                    e(p.errors.steady_rel),
                    e(p.errors.period),
                    e(p.errors.omega_l_max),
                    e(p.errors.transient_max),
                    p.stats.steps,
                    p.stats.rejected,
                    p.stats.rhs_evals,
                    p.stats.events
                );
            }
            (None, f) => {
                let _ = writeln!(
                    s,
                    "{:<7} {:>11} failed: {}",
                    p.solver.name(),
                    setting,
                    f.as_deref().unwrap_or("?")
                );
            }
        }
    }
    let _ = writeln!(
        s,
        "(errors vs the reference: steady rel = max(|dT|/T, |d max wl|/max wl); \
             transient = max |d omega_l| [rad/s]; time = median wall clock)\n"
    );
}

/// The output levels' block of [`BenchReport::table`].
fn output_levels_table(s: &mut String, levels: &[OutputLevel]) {
    let _ = writeln!(
        s,
        "output levels (first scene, metrics on): metrics-only = Output::Metrics (skips \
             whole periods once the cycle has converged), final = Output::Final (whole \
             horizon, nothing kept), full trace = Output::Grid"
    );
    let _ = writeln!(
        s,
        "{:<7} {:>11} {:>13} {:>9} {:>13} {:>7} {:>7} {:>8} {:>9} {:>8} {:>6}",
        "solver",
        "setting",
        "metrics-only",
        "final",
        "full trace",
        "ratio",
        "final",
        "skipped",
        "metrics",
        "kept",
        "same"
    );
    let _ = writeln!(
        s,
        "{:<7} {:>11} {:>13} {:>9} {:>13} {:>7} {:>7} {:>8} {:>9} {:>8} {:>6}",
        "", "", "ms", "ms", "ms", "", "ratio", "periods", "diff", "", ""
    );
    for o in levels {
        let _ = writeln!(
            s,
            "{:<7} {:>11} {:>13} {:>9} {:>13} {:>7.2} {:>7.2} {:>8} {:>9} {:>8} {:>6}",
            o.solver.name(),
            format!("{} {:.0e}", o.setting_name, o.setting),
            ms(o.metrics_only.median_s),
            ms(o.final_only.median_s),
            ms(o.full_trace.median_s),
            o.ratio,
            o.final_ratio,
            if o.undone_skips > 0 {
                format!("{} ({} undone)", o.skipped_periods, o.undone_skips)
            } else {
                o.skipped_periods.to_string()
            },
            o.metrics_diff.map_or("KIND".into(), |d| format!("{d:.1e}")),
            format!(
                "{}/{}/{}",
                o.metrics_only_samples, o.metrics_only_events, o.full_trace_samples
            ),
            if o.same_answer { "yes" } else { "NO" }
        );
    }
    let _ = writeln!(
        s,
        "(ratio = full trace / metrics-only, final ratio = full trace / final; metrics \
             diff = largest |metrics-only - full trace| / max(|m|, 1); kept = samples/events \
             of the metrics-only run / samples of the trace; same = the final run has the \
             trace's metrics and final state)\n"
    );
}

/// The performance profile's block of [`BenchReport::table`].
fn profile_table(s: &mut String, profile: &Profile) {
    let _ = writeln!(
        s,
        "performance profile, tier {}, over {} scene(s) (solved: {}); time / best time \
         per scene:",
        if profile.tier.is_empty() {
            "full"
        } else {
            &profile.tier
        },
        profile.scenes.len(),
        profile.criterion
    );
    let _ = writeln!(s, "{:<12} {}", "", profile.scenes.join("  "));
    for en in &profile.entries {
        let cells: Vec<String> = en
            .ratios
            .iter()
            .map(|r| r.map_or("unsolved".into(), |r| format!("{r:.2}")))
            .collect();
        let _ = writeln!(s, "{:<12} {}", en.name, cells.join("  "));
    }
    let _ = writeln!(s);
}

fn client_table(s: &mut String, p: &ClientReport) {
    let _ = write!(
        s,
        "{} {}: {}",
        if p.peer { "peer" } else { "client" },
        p.name,
        p.status.as_str()
    );
    if let Some(r) = &p.reason {
        let _ = write!(s, " ({r})");
    }
    if let (Some(v), Some(m)) = (&p.version, &p.method) {
        let _ = write!(s, ", version {v}, {m}");
    }
    let _ = writeln!(s, "\n  command: {} <job.json>", p.command);
    if let Some(o) = p.overhead {
        let _ = writeln!(
            s,
            "  protocol overhead per run: {} ms (job file, reading and grading the trace); \
             process beyond the solve: {}",
            ms(o.protocol_s),
            o.process_s
                .map_or("- (no solve_seconds)".into(), |x| format!("{} ms", ms(x)))
        );
    }
    for sc in &p.scenes {
        let _ = writeln!(s, "  scene {}:", sc.scene);
        let _ = writeln!(
            s,
            "{:>11} {:>10} {:>10} {:>4} {:>10} {:>10} {:>9} {:>6} {:>9}  failure",
            "setting",
            "solve ms",
            "wall ms",
            "runs",
            "steady rel",
            "transient",
            "steps",
            "digits",
            "level"
        );
        for q in &sc.points {
            let gates = match (q.passes_strict, q.passes_loose) {
                (Some(true), _) => "strict",
                (_, Some(true)) => "loose",
                (Some(false), Some(false)) => "none",
                _ => "-",
            };
            let _ = writeln!(
                s,
                "{:>11} {:>10} {:>10} {:>4} {:>10} {:>10} {:>9} {:>6} {:>9}  {}",
                format!("{} {:.0e}", p.setting_name, q.setting),
                q.solve.map_or("-".into(), |t| ms(t.median_s)),
                q.wall.map_or("-".into(), |t| ms(t.median_s)),
                q.wall.map_or(0, |t| t.repeats),
                e(q.errors.steady_rel),
                e(q.errors.transient_max),
                q.steps.map_or("-".into(), |v| v.to_string()),
                q.digits.map_or("-".into(), |d| format!("{d:.1}")),
                gates,
                q.failure.as_ref().map_or(String::new(), |f| format!(
                    "{}: {}",
                    f.kind.as_str(),
                    f.detail
                ))
            );
        }
        if !sc.ratios.is_empty() {
            let _ = writeln!(
                s,
                "  time ratio {} / {} at equal error (Rust time interpolated on its \
                 work-precision front; '>=' where the Rust solver's fastest point is already \
                 more accurate):",
                p.name,
                sc.ratios[0].against.name()
            );
            let _ = writeln!(
                s,
                "{:>14} {:>14} {:>11} {:>9} {:>11} {:>11} {:>9} {:>9}",
                "error kind",
                "time",
                "setting",
                "error",
                "client ms",
                "rust ms",
                "ratio",
                "of minima"
            );
            for r in &sc.ratios {
                let ge = if r.rust_is_bound { ">=" } else { "" };
                let _ = writeln!(
                    s,
                    "{:>14} {:>14} {:>11} {:>9} {:>11} {:>11} {:>9} {:>9}",
                    r.error_kind,
                    r.time,
                    format!("{} {:.0e}", p.setting_name, r.setting),
                    format!("{:.1e}", r.error),
                    ms(r.client_seconds),
                    ms(r.rust_seconds),
                    format!("{ge}{}", ratio3(r.ratio)),
                    r.ratio_of_minima
                        .map_or("-".into(), |m| format!("{ge}{}", ratio3(m)))
                );
            }
        }
        if !sc.per_step.is_empty() {
            let _ = writeln!(s, "  time per step {} / moreau at equal h:", p.name);
            let _ = writeln!(
                s,
                "{:>9} {:>15} {:>15} {:>8} {:>10} {:>13} {:>14}",
                "h",
                "client us/step",
                "moreau us/step",
                "ratio",
                "of minima",
                "client steady",
                "moreau steady"
            );
            for q in &sc.per_step {
                let _ = writeln!(
                    s,
                    "{:>9} {:>15.3} {:>15.4} {:>8} {:>10} {:>13} {:>14}",
                    format!("{:.0e}", q.h),
                    1e6 * q.client_s_per_step,
                    1e6 * q.moreau_s_per_step,
                    ratio3(q.ratio),
                    ratio3(q.ratio_of_minima),
                    e(q.client_errors.steady_rel),
                    e(q.moreau_errors.steady_rel)
                );
            }
        }
    }
    let _ = writeln!(s);
}

/// A time ratio to 3 significant digits (`0.482`, `1.23`, `12.3`, `148`; whole numbers from
/// 100 up): timings on a shared machine vary by more than that, and a whole number alone
/// hides a ratio near 1.
pub(crate) fn ratio3(x: f64) -> String {
    if !x.is_finite() || x <= 0.0 {
        return format!("{x}");
    }
    let decimals = (2 - x.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    // 9.996 rounds to "10.00": one digit too many.
    match s.split_once('.') {
        Some((whole, frac)) if whole.trim_start_matches('0').len() + frac.len() > 3 => {
            format!("{x:.*}", decimals.saturating_sub(1))
        }
        _ => s,
    }
}

/// Whether a point is placed on the plots: it ran and gave a usable trace.
pub(crate) fn placed(f: Option<&crate::bench::clients::Failure>) -> bool {
    f.is_none_or(|f| f.kind == FailureKind::FailsGate)
}

#[cfg(test)]
mod ratio_tests {
    use super::ratio3;

    #[test]
    fn ratios_have_three_significant_digits() {
        for (x, want) in [
            (0.48249, "0.482"),
            (1.234, "1.23"),
            (1.0, "1.00"),
            (9.996, "10.0"),
            (12.34, "12.3"),
            (99.96, "100"),
            (148.4, "148"),
            (3483.2, "3483"),
        ] {
            assert_eq!(ratio3(x), want, "{x}");
        }
    }
}
