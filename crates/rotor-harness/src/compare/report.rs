//! Writing the report (CSV, SVG, README.md), atomically; the gates it shows are [`crate::compare::gate`]'s.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use rotor_model::scenario::Scenario;
use rotor_model::seam::RigSteady;
use rotor_model::{Disc, Friction, Model, Params, Rounding, round_sig};

use crate::compare::gate::{Failure, GateResult, gate_scenario};
use rotor_analysis::plot::{Panel, Series, render, render_rows};
use rotor_analysis::solvers::registry::SolverKind;
use rotor_analysis::solvers::run::{ScenarioResult, solver_setting};

/// One row of the report's gate table. A quantity that could not be measured (steady
/// states of different kinds, or missing: `diff` not finite) has no numbers, only its FAIL.
fn gate_row(
    scenario: &str,
    pair: &str,
    m: &crate::compare::gate::Measured,
    derived: bool,
) -> String {
    let numbers = if m.diff.is_finite() {
        let margin = match (m.diff > 0.0, m.tol == 0.0) {
            (true, _) => format!("{:.1}", m.tol / m.diff),
            (false, true) => "exact".into(),
            (false, false) => "—".into(),
        };
        format!("{:.2e} | {:.0e} | {margin}", m.diff, m.tol)
    } else {
        "— | — | —".into()
    };
    let verdict = if m.passes() { "ok" } else { "**FAIL**" };
    let key = m.key.map_or("—".into(), |k| format!("`{k}`"));
    let key = if derived {
        format!("{key} (derived)")
    } else {
        key
    };
    format!(
        "| {scenario} | {pair} | {} | {key} | {numbers} | {verdict} |",
        m.quantity
    )
}

/// The failures that have no row among the gates' measurements: runs that failed, pairs
/// without a stated tolerance. (A measured quantity that failed has its row already.)
fn unmeasured<'a>(gates: &[GateResult], fails: &'a [Failure]) -> Vec<&'a Failure> {
    let measured = |f: &Failure| {
        gates
            .iter()
            .any(|g| g.pair == f.pair && g.measured.iter().any(|m| m.quantity == f.quantity))
    };
    fails.iter().filter(|f| !measured(f)).collect()
}

/// Writes `bytes` to `path`, or to standard output if `path` is `-` (as Unix tools do);
/// a file through [`write_atomic`].
pub fn write_output(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_output_with(path, |w| w.write_all(bytes))
}

/// Writes what `fill` writes to `path`, or to standard output if `path` is `-`; a file
/// atomically ([`write_atomic`]'s temporary file and rename), so that a failed `fill`
/// leaves the previous file intact.
pub fn write_output_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if path.as_os_str() == "-" {
        let mut out = std::io::stdout().lock();
        fill(&mut out)?;
        return out.flush();
    }
    let tmp = temporary_for(path)?;
    let res = std::fs::File::create(&tmp).and_then(|mut f| fill(&mut f));
    match res {
        Ok(()) => std::fs::rename(&tmp, path),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// The temporary file next to `path` that [`write_atomic`] renames onto it.
fn temporary_for(path: &Path) -> std::io::Result<std::path::PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{}: not a file path", path.display()),
        )
    })?;
    Ok(dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Writes `bytes` to `path` through a temporary file and a rename, so an interrupted run
/// leaves the previous file intact: a reader sees the old file or the whole new one, never a
/// part. (Not `fsync`ed: the guarantee is against an interrupted or failed run, not a power
/// cut, and a sync costs about a millisecond per file here, more than a whole solve.)
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temporary_for(path)?;
    let mut f = std::fs::File::create(&tmp)?;
    f.write_all(bytes)?;
    drop(f);
    std::fs::rename(&tmp, path)
}

fn label(kind: SolverKind, sc: &Scenario) -> String {
    kind.label_at(solver_setting(kind, sc))
}

/// The per-solver columns of [`scenario_csv`], in the state's order (x = [α, ω_u, ω_l]).
const CSV_QUANTITIES: [&str; 3] = rotor_model::RIG_STATE_NAMES;

/// Per-scenario CSV, the data of [`scenario_svg`]'s figure: `t`, then for each solver that
/// finished, in the figure's order (the reference first), `alpha_<solver>` (α = θ_u − θ_l,
/// rad), `omega_u_<solver>` and `omega_l_<solver>` (rad/s) on the comparison grid. The
/// figure's difference panels are |x_solver − x_reference| of these columns. Each value to 12
/// significant digits (far below every gate's tolerance, so the committed report moves only
/// where an answer does); `t` to the grid's decimals.
pub fn scenario_csv(r: &ScenarioResult) -> String {
    let kinds: Vec<SolverKind> = r
        .runs
        .iter()
        .map(|run| run.kind)
        .filter(|k| r.traj(*k).is_some())
        .collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["t".to_string()];
    for k in &kinds {
        for q in CSV_QUANTITIES {
            header.push(format!("{q}_{}", k.name()));
        }
    }
    // Writing to memory cannot fail.
    w.write_record(&header).expect("in memory");
    let n = kinds
        .iter()
        .map(|k| r.traj(*k).map_or(0, |t| t.samples.len()))
        .min()
        .unwrap_or(0);
    let digits = crate::grade::trace::time_digits(r.scenario.compare.dt);
    let mut row: Vec<f64> = Vec::with_capacity(1 + CSV_QUANTITIES.len() * kinds.len());
    for i in 0..n {
        row.clear();
        let t = r.traj(kinds[0]).map_or(0.0, |tr| tr.samples.t(i));
        row.push(crate::grade::trace::round_to(t, digits));
        for k in &kinds {
            let x = r.traj(*k).map_or([0.0; 3].as_slice(), |tr| tr.samples.x(i));
            // The state's order is the columns' order: α, ω_u, ω_l.
            for v in [x[0], x[1], x[2]] {
                row.push(round_sig(v, 12, Rounding::Decimal { floor: 0.0 }));
            }
        }
        w.serialize(&row).expect("in memory");
    }
    String::from_utf8(w.into_inner().expect("in memory")).expect("ASCII")
}

/// Per-scenario SVG over the whole run: α, ω_u and ω_l of every solver overlaid (the source's
/// Figs. 4–7), each with a panel under it of every other solver's difference from the first
/// (the accuracy reference) on the comparison grid, log scale: the overlay shows that the
/// solvers agree, the difference panel by how much. A difference of exactly 0 (both stuck)
/// has no place on the log axis and leaves a gap.
pub fn scenario_svg(r: &ScenarioResult) -> String {
    let sc = &r.scenario;
    let labels: Vec<String> = r.runs.iter().map(|run| label(run.kind, sc)).collect();
    let reference = r.runs.first().and_then(|run| run.result.as_ref().ok());
    let quantities: [(usize, &str, &str, &str); 3] = [
        (0, "twist", "α [rad]", "|Δα| [rad]"),
        (1, "upper disc", "ω_{u} [rad/s]", "|Δω_{u}| [rad/s]"),
        (2, "lower disc", "ω_{l} [rad/s]", "|Δω_{l}| [rad/s]"),
    ];
    let mut panels = Vec::new();
    let mut heights = Vec::new();
    for (idx, name, y_label, d_label) in quantities {
        let overlay = r
            .runs
            .iter()
            .enumerate()
            .filter_map(|(i, run)| {
                let tr = run.result.as_ref().ok()?;
                let style = run.kind.info().style;
                Some(Series {
                    label: &labels[i],
                    color: style.color,
                    dash: style.dash,
                    width: style.width,
                    points: tr.samples.iter().map(|s| (s.t, s.x[idx])).collect(),
                    ..Series::default()
                })
            })
            .collect();
        panels.push(Panel::new(
            format!("{}: {name} (u = {} V)", sc.name, sc.u),
            "t [s]",
            y_label,
            overlay,
        ));
        heights.push(300.0);
        let Some(re) = reference else {
            continue;
        };
        let diffs: Vec<Series> = r
            .runs
            .iter()
            .enumerate()
            .skip(1)
            .filter_map(|(i, run)| {
                let tr = run.result.as_ref().ok()?;
                let style = run.kind.info().style;
                Some(Series {
                    label: &labels[i],
                    color: style.color,
                    width: 1.0,
                    points: tr
                        .samples
                        .iter()
                        .zip(&re.samples)
                        .map(|(a, b)| (a.t, (a.x[idx] - b.x[idx]).abs()))
                        .collect(),
                    ..Series::default()
                })
            })
            .collect();
        if diffs.is_empty() {
            continue;
        }
        let mut panel = Panel::new(
            format!("{}: {name}, difference from {}", sc.name, labels[0]),
            "t [s]",
            d_label,
            diffs,
        );
        panel.y_log = true;
        panels.push(panel);
        heights.push(230.0);
    }
    render_rows(&panels, 900.0, &heights)
}

/// Line styles of the parameter sets in the friction plot.
const SET_STYLES: [(&str, Option<&str>); 3] = [
    ("#000000", None),
    ("#D55E00", Some("6 3")),
    ("#0072B2", Some("2 2")),
];

/// The friction curves of both parameter sets (the source's Fig. 2).
pub(crate) fn friction_svg(sets: &[(&str, Params)]) -> String {
    render(&friction_panels(sets), 900.0, 340.0)
}

/// The friction figure's data ([`rotor_analysis::plot::data_csv`]).
pub(crate) fn friction_csv(sets: &[(&str, Params)]) -> String {
    rotor_analysis::plot::data_csv(&friction_panels(sets))
}

fn friction_panels<'a>(sets: &[(&'a str, Params)]) -> Vec<Panel<'a>> {
    let mut panels = Vec::new();
    for (disc, name) in [
        (Disc::UPPER, "upper disc T_fu"),
        (Disc::LOWER, "lower disc T_fl"),
    ] {
        let series = sets
            .iter()
            .enumerate()
            .map(|(i, (set, p))| {
                let m = Model::new(*p);
                let f: Friction = *m.friction(disc);
                let (lo, hi) = f.static_interval();
                let mut pts: Vec<(f64, f64)> = (-400..=400)
                    .map(|k| k as f64 * 0.025)
                    .filter(|w| *w != 0.0)
                    .map(|w| (w, f.curve(w)))
                    .collect();
                // The set-valued part at ω = 0: a vertical segment.
                let mid = pts.iter().position(|p| p.0 > 0.0).unwrap_or(0);
                pts.insert(mid, (0.0, hi));
                pts.insert(mid, (0.0, lo));
                let (color, dash) = SET_STYLES[i % SET_STYLES.len()];
                Series {
                    label: set,
                    color,
                    dash,
                    width: 1.8,
                    marker: None,
                    points: pts,
                    ..Series::default()
                }
            })
            .collect();
        panels.push(Panel::new(
            format!("Friction: {name} (Fig. 2)"),
            "ω [rad/s]",
            "torque [N m]",
            series,
        ));
    }
    panels
}

fn fmt_metrics(st: &Option<RigSteady>) -> String {
    match st {
        None => "—".into(),
        Some(RigSteady::Equilibrium {
            omega_u, omega_l, ..
        }) => {
            format!("equilibrium ω_u = {omega_u:.6}, ω_l = {omega_l:.6}")
        }
        Some(RigSteady::LimitCycle {
            period,
            omega_l_max,
            omega_l_min,
            stick_time,
            ..
        }) => format!(
            "cycle T = {period:.6} s, ω_l ∈ [{omega_l_min:.4}, {omega_l_max:.6}], stick {stick_time:.5} s"
        ),
    }
}

/// Removes the hidden temporaries (`.NAME.tmpPID`, see [`write_atomic`]) that a killed run
/// left behind. The report files themselves are never touched: they are whole, old or new.
fn remove_stale_temporaries(dir: &Path) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name.contains(".tmp") && entry.file_type()?.is_file() {
            std::fs::remove_file(entry.path())?;
        }
    }
    Ok(())
}

/// A further section of the report (the bifurcation diagrams, the stress table, ...): its
/// markdown, appended to `README.md`, and the files it links, written atomically beside it.
#[derive(Debug, Clone, Default)]
pub struct Section {
    /// Markdown, starting with its own `## ` heading.
    pub markdown: String,
    /// File name (relative to the report directory) and contents.
    pub files: Vec<(String, Vec<u8>)>,
    /// The section's own failed checks, one line each (the run fails after the report is
    /// written, as it does for a failed agreement gate).
    pub failures: Vec<String>,
    /// Its run times, markdown for `timings.md` (which is not committed: times change from
    /// run to run, and the committed report must change only when a result does).
    pub timings: String,
}

/// The file that holds the run's times beside the report (ignored by git).
pub(crate) const TIMINGS_FILE: &str = "timings.md";

/// The report's whole-run section: per scenario and pair of solvers, the differences over
/// every sample and event of `[0, t_end]` ([`crate::compare::whole`]): the matched events and their
/// largest time difference (the phase), the largest phase-aligned difference of α, ω_u, ω_l
/// (the shape; gated) and the largest difference at equal times (phase and shape together;
/// shown, not gated).
pub fn whole_run_table(results: &[ScenarioResult]) -> String {
    let mut md = String::from(
        "\n## The whole run, every pair of solvers\n\n\
         Every sample of α, ω_u, ω_l and every mode switch and maximum of ω_l over [0, t_end] \
         (`rotor_harness::compare::whole`, docs/methods.md \"The whole run\"). The matched events' time \
         differences are the phase between the two runs; the samples are compared after \
         taking that phase out to first order (r = B − A + Δt·f(A), Δt interpolated between \
         the matched stick exits and maxima of ω_l), which leaves the difference of shape. \
         Aligned differences and event times are gated (`whole_*`); the difference at equal \
         times, phase and shape together, is shown for comparison: it grows with the run's \
         length on a cycle (a relative period error ε shifts the phase by ε·t) and with the \
         amplification of an unstable start.\n\n\
         | scenario | pair | events matched | max Δt event [s] | aligned α [rad] | aligned ω_u \
         [rad/s] | aligned ω_l [rad/s] | equal-time α | equal-time ω_u | equal-time ω_l |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let sc = &r.scenario;
        let kinds: Vec<SolverKind> = r.runs.iter().map(|run| run.kind).collect();
        for (a, b) in rotor_analysis::solvers::all_pairs(&kinds) {
            let (Some(ta), Some(tb)) = (r.traj(a), r.traj(b)) else {
                continue;
            };
            let w = crate::compare::whole::whole_run(
                &sc.model,
                sc.u,
                ta,
                tb,
                crate::compare::gate::stuck_band(a, b),
            );
            let events = if !w.event_time.is_finite() {
                "sequences differ".to_owned()
            } else if w.maxima {
                format!("{} (switches and maxima)", w.events)
            } else {
                format!("{} (switches only)", w.events)
            };
            let e = |x: f64| {
                if x.is_finite() {
                    format!("{x:.1e}")
                } else {
                    "—".into()
                }
            };
            let _ = writeln!(
                md,
                "| {} | {} | {events} | {} | {} | {} | {} | {} | {} | {} |",
                sc.name,
                rotor_analysis::solvers::pair_name(a, b),
                e(w.event_time),
                e(w.aligned[0]),
                e(w.aligned[1]),
                e(w.aligned[2]),
                e(w.raw[0]),
                e(w.raw[1]),
                e(w.raw[2]),
            );
        }
    }
    md
}

/// Which scenes a report is of, which decides how it opens.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Scenes {
    /// The suite's scenarios (`fixtures/scenarios/`, the main job): the report opens with
    /// what Table 1 does against the source's prose, and names the suite's version.
    Suite,
    /// Scenes given by name or file (`rotor compare FILE…`, a user's own): the report opens
    /// with those scenes only, the rig's (the results) and these chain scenes' names.
    Given {
        /// The chain scenes given, by name (their section is among the report's sections).
        chains: Vec<String>,
    },
}

/// The opening of a report of the scenes given ([`Scenes::Given`]): what was run, by what,
/// and how it is gated, naming the scenes and nothing else.
fn given_intro(results: &[ScenarioResult], chains: &[String]) -> String {
    let names: Vec<String> = results
        .iter()
        .map(|r| &r.scenario.name)
        .chain(chains)
        .map(|n| format!("`{n}`"))
        .collect();
    format!(
        "# rotorbench report\n\nGenerated by `rotor compare` on the scene{} given: {}. \
         Each scene is run by three independent solvers (the event-driven Filippov solver, the \
         accuracy reference; Leine's switch model; Moreau–Jean time-stepping on the Lagrangian \
         form), and their θ̇_u, θ̇_l (a chain's every α_i, ω_i and event, section \"Chains of N \
         discs\") are compared under the tolerances each scene's file states{}.\n",
        if names.len() == 1 { "" } else { "s" },
        names.join(", "),
        if results.iter().any(|r| !r.tight.is_empty()) || !chains.is_empty() {
            ", or, for a pair a file states none for, under defaults derived from the two \
             solvers' own errors on the scene (the gates marked *derived*, next section)"
        } else {
            ""
        }
    )
}

/// Writes the whole report of `scenes` into `dir` and returns the failures.
pub fn write_report(
    dir: &Path,
    results: &[ScenarioResult],
    param_sets: &[(&str, Params)],
    sections: &[Section],
    scenes: Scenes,
) -> std::io::Result<Vec<Failure>> {
    std::fs::create_dir_all(dir)?;
    remove_stale_temporaries(dir)?;
    let mut md = String::new();
    let mut all_fails = Vec::new();
    match scenes {
        Scenes::Suite => {
            md.push_str(include_str!("report_intro.md"));
            md.push_str(&format!(
                "\nSuite: `{}` (the scenarios, parameter sets and reference data, named by \
                 their checksum; `rotor scenarios` lists them).\n",
                crate::grade::check::BENCHMARK
            ));
        }
        Scenes::Given { chains } => md.push_str(&given_intro(results, &chains)),
    }
    md.push_str("\n## Agreement and work per scenario\n\n");
    md.push_str("| scenario | solver | steady state (second half of the run) | steps | rejected | RHS evals | events | LCP solves / skipped |\n|---|---|---|---|---|---|---|---|\n");
    let mut times = String::from(
        "# Run times of the last report\n\nWritten by the run that wrote the report beside it, \
         not committed (times move by ±15 % from run to run on this machine).\n\n\
         ## Solver runs per scenario\n\n| scenario | solver | time [ms] |\n|---|---|---|\n",
    );
    for r in results {
        for run in &r.runs {
            let (st, stats) = match &run.result {
                Ok(t) => (fmt_metrics(&t.rig_metrics()), t.stats),
                Err(e) => (format!("**error: {e}**"), Default::default()),
            };
            let _ = writeln!(
                md,
                "| [{}]({}.svg) | {} | {} | {} | {} | {} | {} | {} / {} |",
                r.scenario.name,
                r.scenario.name,
                run.kind.name(),
                st,
                stats.steps,
                stats.rejected,
                stats.rhs_evals,
                stats.events,
                stats.lcp_solves,
                stats.lcp_skipped,
            );
            let _ = writeln!(
                times,
                "| {} | {} | {:.1} |",
                r.scenario.name,
                run.kind.name(),
                run.seconds * 1e3
            );
        }
    }
    md.push_str(
        "\n## Gates (measured difference, tolerance from the scenario file, margin)\n\n\
         One key of the scenario file per quantity. Each gate is 5x what it measures on its \
         scenario rounded up to one digit (margin 5-10x), at least the rounding floor (1e-13 \
         relative, 1e-12 s or rad/s), or 0 where every solver agrees exactly (the scenario \
         files give each one's origin); a test holds every gate between its measurement and \
         10x it (tests/fixtures.rs). Relative for the steady metrics except the stick time \
         (s), rad/s for the transient, s for events; the `whole_*` gates cover every sample \
         and event of [0, t_end], phase-aligned (the next section), for every pair of \
         solvers.\n\n",
    );
    if results.iter().any(|r| !r.tight.is_empty()) {
        md.push_str(
            "A gate marked *derived* is a default for a pair whose scenario file states no \
             tolerance (a scene never measured before): each of the two solvers ran again at \
             tighter settings (its tolerance 100x tighter; its step halved and quartered), its \
             own error in a quantity is that quantity between its runs (for a step the larger \
             of twice the first difference and four times the second, which covers order 1 \
             and a halving whose errors cancel by chance), and the gate is twice the two \
             errors' sum, plus the rounding \
             floor and, for the switch model, what its stick band moves that no tolerance \
             does (`rotor_harness::compare::gate::derived_tolerance`). The margin of a \
             derived gate says how far the two solvers agree beyond their own accuracy.\n\n",
        );
    }
    md.push_str(
        "| scenario | pair | quantity | key | difference | tolerance | margin | |\n|---|---|---|---|---|---|---|---|\n",
    );
    // Each scenario's trace and figure, rendered side by side (66 MB of CSV for the fixtures:
    // the main job's last step, which would otherwise leave a core idle).
    let rendered: Vec<(String, String)> = {
        use rayon::prelude::*;
        results
            .par_iter()
            .map(|r| (scenario_csv(r), scenario_svg(r)))
            .collect()
    };
    for (r, (csv, svg)) in results.iter().zip(rendered) {
        let (gates, fails) = gate_scenario(r);
        for g in &gates {
            for m in &g.measured {
                let _ = writeln!(md, "{}", gate_row(&r.scenario.name, &g.pair, m, g.derived));
            }
        }
        for f in unmeasured(&gates, &fails) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | — | — | — | — | **FAIL** |",
                f.scenario, f.pair, f.quantity
            );
        }
        all_fails.extend(fails);
        write_atomic(
            &dir.join(format!("{}.csv", r.scenario.name)),
            csv.as_bytes(),
        )?;
        write_atomic(
            &dir.join(format!("{}.svg", r.scenario.name)),
            svg.as_bytes(),
        )?;
    }
    md.push_str(&whole_run_table(results));
    write_atomic(
        &dir.join("friction.svg"),
        friction_svg(param_sets).as_bytes(),
    )?;
    write_atomic(
        &dir.join("friction.csv"),
        friction_csv(param_sets).as_bytes(),
    )?;
    for sec in sections {
        md.push('\n');
        md.push_str(&sec.markdown);
        times.push_str(&sec.timings);
        for (name, bytes) in &sec.files {
            write_atomic(&dir.join(name), bytes)?;
        }
    }
    write_atomic(&dir.join("README.md"), md.as_bytes())?;
    let names: Vec<&str> = results.iter().map(|r| r.scenario.name.as_str()).collect();
    let bench = dir.join("bench").join("bench.svg").is_file();
    let page = crate::compare::html::index_html(&md, &names, bench);
    write_atomic(&dir.join("index.html"), page.as_bytes())?;
    write_atomic(&dir.join(TIMINGS_FILE), times.as_bytes())?;
    Ok(all_fails)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::gate::Measured;

    /// Gate rows: a measurement shows its difference, tolerance and margin; a quantity that
    /// could not be measured (a NaN or infinite difference) shows no numbers, never "NaN"
    /// or a margin of "exact"; and the failures print as sentences, not "differs by inf".
    #[test]
    fn unmeasurable_gates_show_no_numbers() {
        let m = |quantity: &str, diff: f64, tol: f64| Measured {
            quantity: quantity.into(),
            key: quantity.ends_with("_rel").then_some("period_rel"),
            diff,
            tol,
        };
        assert_eq!(
            gate_row("s", "a-b", &m("period_rel", 2e-11, 1e-10), false),
            "| s | a-b | period_rel | `period_rel` | 2.00e-11 | 1e-10 | 5.0 | ok |"
        );
        assert_eq!(
            gate_row("s", "a-b", &m("stick_time", 0.0, 0.0), false),
            "| s | a-b | stick_time | — | 0.00e0 | 0e0 | exact | ok |"
        );
        for d in [f64::NAN, f64::INFINITY] {
            let row = gate_row(
                "s",
                "a-b",
                &m("steady kind (cycle vs equilibrium)", d, 0.0),
                false,
            );
            assert_eq!(
                row,
                "| s | a-b | steady kind (cycle vs equilibrium) | — | — | — | — | **FAIL** |"
            );
        }
        let f = |diff: f64| {
            Failure {
                scenario: "s".into(),
                pair: "event".into(),
                quantity: "run failed: step size underflow".into(),
                diff,
                tol: 0.0,
            }
            .to_string()
        };
        assert_eq!(
            f(f64::INFINITY),
            "s: event: run failed: step size underflow"
        );
        assert_eq!(f(f64::NAN), "s: event: run failed: step size underflow");
        // A failed measurement (here steady states of different kinds, an infinite
        // difference) has its gate row; only the failures without one get another row.
        let kinds = m("steady kind (cycle vs equilibrium)", f64::INFINITY, 0.0);
        let gates = [GateResult {
            pair: "a-b".into(),
            measured: vec![m("period_rel", 2e-11, 1e-10), kinds],
            derived: false,
        }];
        let mut fails = gates[0].failures("s");
        assert_eq!(fails.len(), 1);
        let run = Failure {
            scenario: "s".into(),
            pair: "a".into(),
            quantity: "run failed: step size underflow".into(),
            diff: f64::INFINITY,
            tol: 0.0,
        };
        fails.push(run.clone());
        assert_eq!(unmeasured(&gates, &fails), [&run]);
        assert_eq!(
            f(1.0),
            "s: event: run failed: step size underflow differs by 1.000e0 > tolerance 0.000e0"
        );
    }

    #[test]
    fn atomic_writes_replace_whole_files_and_stale_temporaries_go() {
        let dir = rotor_testkit::tmp_dir("rotor_harness::report");
        let file = dir.join("a.csv");
        write_atomic(&file, b"old\n").unwrap();
        write_atomic(&file, b"new\n").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"new\n");
        // What a killed run leaves: a hidden temporary. The next report removes it and
        // leaves the report files alone.
        let stale = dir.join(".a.csv.tmp12345");
        std::fs::write(&stale, b"partial").unwrap();
        remove_stale_temporaries(&dir).unwrap();
        assert!(!stale.exists());
        assert_eq!(std::fs::read(&file).unwrap(), b"new\n");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.csv")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The trace figure's data carries what the figure draws: `t`, then α, ω_u and ω_l of
    /// each solver, the reference first, one row per grid sample; each value is the run's
    /// state rounded to 12 significant digits (the report's rule), so that a reader who
    /// redraws the figure from the CSV draws the same curves, α included.
    #[test]
    fn the_trace_csv_holds_alpha_and_both_speeds_of_every_solver() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenarios/t1-u1.5-rest.toml");
        let mut sc = rotor_analysis::solvers::load_scenario(&path).unwrap();
        // Two seconds: the lower disc's first stick and slip, a few hundred samples; no
        // steady window (it lies past 2 s, and the CSV holds no metrics).
        sc.t_end = 2.0;
        sc.compare.steady_from = None;
        let r = rotor_analysis::solvers::run::run_scenario(&sc);
        let csv = scenario_csv(&r);
        let mut lines = csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "t,alpha_event,omega_u_event,omega_l_event,alpha_switch,omega_u_switch,\
             omega_l_switch,alpha_moreau,omega_u_moreau,omega_l_moreau"
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        let kinds = [SolverKind::EVENT, SolverKind::SWITCH, SolverKind::MOREAU];
        let samples = &r.traj(kinds[0]).unwrap().samples;
        assert_eq!(rows.len(), samples.len());
        assert_eq!(rows.len(), 201, "0, 0.01, ..., 2 s");
        let round = |v: f64| round_sig(v, 12, Rounding::Decimal { floor: 0.0 });
        let mut alpha_moves = false;
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), 1 + 3 * kinds.len());
            // The scenario's grid is 0.01 s; `t` is written to its two decimals (a double
            // nearest k/100, within 1e-15 of i·0.01).
            assert!(
                (row[0] - i as f64 * 0.01).abs() < 1e-15,
                "row {i}: t = {}",
                row[0]
            );
            for (j, k) in kinds.iter().enumerate() {
                let x = r.traj(*k).unwrap().samples.x(i);
                for q in 0..3 {
                    assert_eq!(
                        row[1 + 3 * j + q],
                        round(x[q]),
                        "row {i}, {}, column {q}",
                        k.name()
                    );
                }
            }
            alpha_moves |= row[1] != 0.0;
        }
        // The spring winds up from rest: α is a column of data, not of zeros.
        assert!(alpha_moves);
    }
}
