//! The published results (`rotor bench --results FILE`, reports/bench/results.md): every
//! solver, peer and client on every scene, as a Markdown page a new solver's author places
//! a row in.
//!
//! Per tier, the performance profile (the fraction of scenes solved within τ of the best,
//! at τ = 1, 2, 10, 100, 10³, 10⁴). Per scene, one row per solver: its digits at each setting of
//! its ladder (as `rotor check` counts them: the fewest of any graded quantity, events
//! included), the cheapest setting that passes the loose and the strict level with its
//! time, and its time at the loosest setting. Digits are printed to one decimal (a tenth of
//! a digit is below what a run's own rounding moves), times to 2 significant digits (the
//! spread of repeated timings on a shared machine is larger).

use std::fmt::Write;

use crate::bench::profile::Profile;
use crate::bench::word::Word;
use crate::bench::{BenchReport, SceneReport};

/// One solver's points on one scene: (setting, digits, passes loose, passes strict, time).
type Row = Vec<(f64, Option<f64>, Option<bool>, Option<bool>, Option<f64>)>;

fn time(s: Option<f64>) -> String {
    match s {
        None => "–".into(),
        Some(s) if s >= 1.0 => format!("{s:.2} s"),
        Some(s) => format!("{:.2} ms", 1e3 * s),
    }
}

fn digits(d: Option<f64>) -> String {
    d.map_or("–".into(), |d| format!("{d:.1}"))
}

/// The cheapest point of a row passing a level (`pick`): its setting and time.
fn cheapest(
    row: &Row,
    pick: impl Fn(&(f64, Option<f64>, Option<bool>, Option<bool>, Option<f64>)) -> bool,
) -> String {
    row.iter()
        .filter(|p| pick(p))
        .filter_map(|p| Some((p.0, p.4?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or("–".into(), |(x, t)| {
            format!("{x:.0e} ({})", time(Some(t)))
        })
}

fn profile_table(s: &mut String, p: &Profile) {
    // The Rust solvers take microseconds to milliseconds where an interpreter's run takes
    // a second: the columns reach τ = 10⁴.
    let taus = [1.0, 2.0, 10.0, 100.0, 1e3, 1e4];
    let _ = writeln!(
        s,
        "| solver | solved | ρ(1) | ρ(2) | ρ(10) | ρ(100) | ρ(10³) | ρ(10⁴) |\n\
         |---|---|---|---|---|---|---|---|"
    );
    for e in &p.entries {
        let solved = e.ratios.iter().filter(|r| r.is_some()).count();
        let cells: Vec<String> = taus
            .iter()
            .map(|&t| format!("{:.2}", Profile::rho(e, t)))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {solved}/{} | {} |",
            e.name,
            e.ratios.len(),
            cells.join(" | ")
        );
    }
}

impl BenchReport {
    /// The results page (Markdown): `command` is the command that regenerates it.
    pub fn to_results_md(&self, command: &str) -> Result<String, crate::bench::BenchError> {
        self.check_finite()?;
        let mut s = String::new();
        self.write_intro(&mut s, command);
        self.write_solvers(&mut s);
        self.write_profiles(&mut s);
        let _ = writeln!(s, "## Scenes\n");
        for sc in &self.scenes {
            self.write_scene(&mut s, sc);
        }
        Ok(s)
    }

    /// The page's title, what the suite is and how it was measured (`command` wrote it),
    /// and how a new solver's author places a row.
    fn write_intro(&self, s: &mut String, command: &str) {
        let env = &self.environment;
        let _ = writeln!(
            s,
            "# rotorbench results: every solver on every scene\n\n\
             Suite **{}**, {} scenes, written by `{command}`. `just bench` regenerates it \
             over the whole suite, with `bench.json`, `bench.csv`, `bench.svg` (the \
             performance profiles), `bench-<scene>.svg` (each scene's work precision, its \
             data in `bench-<scene>.csv`), `bench.html` (all of them) and `bench.txt`.\n\n\
             Measured on {} core(s), {}, load average {} at the start and {} at \
             the end; times are the median of up to {} runs within {} s per point (a run longer \
             than that is timed once), in-process (`solve_seconds`) where a client reports it. \
             Absolute times move with the machine; compare ratios measured in one run.\n",
            self.benchmark,
            self.scenes.len(),
            env.cores,
            if env.jobs > 1 {
                format!(
                    "the Rust solvers alone, then {} external clients side by side (each \
                     single-threaded, its own runs one at a time)",
                    env.jobs
                )
            } else {
                "one run at a time".to_owned()
            },
            env.load_start
                .map_or("?".into(), |l| format!("{:.1}", l[0])),
            env.load_end.map_or("?".into(), |l| format!("{:.1}", l[0])),
            env.repeats,
            env.time_budget_s
        );
        let _ = writeln!(
            s,
            "**Placing your row.** Run `rotor bench --external NAME=COMMAND` (or \
             `NAME:h=COMMAND` for a fixed-step solver; BENCHMARK.md section 5) with the same \
             suite version: your client gets the same scenes and ladders and is graded the \
             same way, and its rows and profile entries appear beside these. Or grade single \
             runs with `rotor check SCENE --trace T.csv --events E.csv --json V.json` and read \
             `digits` and `passed`. **digits** are significant correct digits, as `rotor check` \
             counts them (the fewest of any graded quantity, events included; 0 where a \
             quantity cannot be measured, e.g. a missing stick interval); **loose** = 3 digits, \
             **strict** = 7. \"cheapest\" is the setting whose run passes the level in the \
             least time, with that time.\n"
        );
    }

    /// The table of solvers: the Rust solvers, then every peer and client with its method
    /// and version (or its command), its knob and its status.
    fn write_solvers(&self, s: &mut String) {
        let _ = writeln!(
            s,
            "## Solvers\n\n| solver | kind | knob | status |\n|---|---|---|---|"
        );
        for k in rotor_analysis::solvers::SOLVERS {
            let _ = writeln!(
                s,
                "| {} | this repository (Rust) | {} | ran |",
                k.name(),
                k.setting_name()
            );
        }
        for c in &self.clients {
            let what = match (&c.method, &c.version) {
                (Some(m), Some(v)) => format!("{m}, {v}"),
                _ => c.command.clone(),
            };
            let _ = writeln!(
                s,
                "| {} | {} ({}) | {} | {}{} |",
                c.name,
                if c.peer { "peer" } else { "client" },
                what.replace('|', "\\|"),
                c.setting_name,
                c.status.as_str(),
                c.reason
                    .as_ref()
                    .map_or(String::new(), |r| format!(": {}", r.replace('|', "\\|")))
            );
        }
    }

    /// The performance profiles: the full suite's, then the `table1` tier's if there is one.
    fn write_profiles(&self, s: &mut String) {
        let _ = writeln!(s, "\n## Performance profiles\n");
        let _ = writeln!(
            s,
            "ρ(τ): the fraction of the tier's scenes a solver solves (its fastest point passing \
             the loose level) within τ times the best time on that scene.\n"
        );
        for p in std::iter::once(&self.profile).chain(&self.profile_table1) {
            let tier = if p.tier.is_empty() { "full" } else { &p.tier };
            let _ = writeln!(
                s,
                "### Tier `{tier}` ({} scenes{})\n",
                p.scenes.len(),
                if tier == "table1" {
                    ": only the lower disc has static friction"
                } else {
                    ": every scene"
                }
            );
            profile_table(s, p);
            let _ = writeln!(s);
        }
    }

    /// Scene `sc`'s heading and table: per solver, its digits at each setting and its
    /// cheapest setting passing the loose and the strict level.
    fn write_scene(&self, s: &mut String, sc: &SceneReport) {
        let _ = writeln!(
            s,
            "### {} (tier `{}`)\n\n{}. u = {} V, {} s.\n",
            sc.name,
            if sc.tier.is_empty() { "?" } else { &sc.tier },
            sc.description,
            sc.u,
            sc.t_end
        );
        let _ = writeln!(
            s,
            "| solver | digits at each setting | cheapest loose | cheapest strict |\n|---|---|---|---|"
        );
        for (name, knob, row) in &self.scene_rows(sc) {
            let cells: Vec<String> = row
                .iter()
                .map(|p| format!("{} {:.0e}: {}", knob, p.0, digits(p.1)))
                .collect();
            let _ = writeln!(
                s,
                "| {name} | {} | {} | {} |",
                if cells.is_empty() {
                    "–".into()
                } else {
                    cells.join(", ")
                },
                cheapest(row, |p| p.2 == Some(true)),
                cheapest(row, |p| p.3 == Some(true))
            );
        }
        let _ = writeln!(s);
    }

    /// Every solver's points on scene `sc` with its name and knob: the Rust solvers', then
    /// those of each client that ran the scene.
    fn scene_rows(&self, sc: &SceneReport) -> Vec<(String, Word, Row)> {
        let mut rows: Vec<(String, Word, Row)> = Vec::new();
        for k in rotor_analysis::solvers::SOLVERS {
            let row: Row = sc
                .points
                .iter()
                .filter(|p| p.solver == k)
                .map(|p| {
                    (
                        p.setting,
                        p.digits,
                        p.passes_loose,
                        p.passes_strict,
                        p.timing.map(|t| t.median_s),
                    )
                })
                .collect();
            rows.push((k.name().to_owned(), k.setting_name(), row));
        }
        for c in &self.clients {
            let Some(cs) = c.scenes.iter().find(|x| x.scene == sc.name) else {
                continue;
            };
            let row: Row = cs
                .points
                .iter()
                .map(|p| {
                    (
                        p.setting,
                        p.digits,
                        p.passes_loose,
                        p.passes_strict,
                        p.time().map(|t| t.median_s),
                    )
                })
                .collect();
            rows.push((c.name.clone(), c.setting_name, row));
        }
        rows
    }
}
