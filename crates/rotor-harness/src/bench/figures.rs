//! The benchmark's figures, one per file, each with its data as CSV beside it, and a page
//! that shows them all.
//!
//! * One work-precision figure per scene: steady-state error and transient error against run
//!   time, log–log, one line per solver and client in its own colour, dash and marker
//!   ([`crate::bench::colors`]). A filled marker passes the scene's loose gate; an open one fails it.
//! * The performance profile (the summary): per tier, the fraction of scenes each runner
//!   solves within τ times the best time.
//! * A page (`<stem>.html`) that shows the profile and links every scene's figure.
//!
//! The CSV of a figure holds exactly what it draws, for a reader who redraws it (matplotlib,
//! pgfplots): `examples/redraw_bench.py` does so from a scene's CSV.

use std::fmt::Write;

use rotor_analysis::plot::{Panel, Series, render};
use rotor_analysis::solvers::SOLVERS;

use crate::bench::colors::style;
use crate::bench::measure::Errors;
use crate::bench::report::placed;
use crate::bench::{BenchError, BenchReport, Profile, SceneReport};

/// One figure: the name that goes into its file names, the SVG and the CSV of its data.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// `profile`, or the scene's name: the files are `<stem>-<name>.svg` and `.csv`.
    pub name: String,
    /// What it shows, for the summary page.
    pub caption: String,
    /// The SVG document.
    pub svg: String,
    /// The drawn data as CSV, one row per point.
    pub csv: String,
}

/// One point of a work-precision figure.
struct Point<'a> {
    runner: &'a str,
    setting: f64,
    time: f64,
    errors: &'a Errors,
    passes: Option<bool>,
}

type Pick = fn(&Errors) -> Option<f64>;

/// The two quantities of a scene's figure: title, y label, which error.
const QUANTITIES: [(&str, &str, Pick); 2] = [
    (
        "steady-state error",
        "max(|ΔT|/T, |Δ max ω_{l}|/max ω_{l})",
        |e| e.steady_rel,
    ),
    ("transient error", "max |Δω_{l}| [rad/s]", |e| {
        e.transient_max
    }),
];

impl BenchReport {
    /// The summary figure: the performance profile of every tier (a non-finite number in the
    /// report is an error).
    pub fn to_svg(&self) -> Result<String, BenchError> {
        self.check_finite()?;
        let mut panels = vec![self.profile.panel()];
        if let Some(t1) = &self.profile_table1 {
            panels.push(t1.panel());
        }
        Ok(render(&panels, 760.0, 440.0))
    }

    /// Every figure: one per scene, then the profile's (see the module docs).
    pub fn figures(&self) -> Result<Vec<Figure>, BenchError> {
        self.check_finite()?;
        let mut out: Vec<Figure> = self.scenes.iter().map(|sc| self.scene_figure(sc)).collect();
        out.push(Figure {
            name: "profile".into(),
            caption: format!("performance profile: {}", crate::bench::profile::CRITERION),
            svg: self.to_svg()?,
            csv: profile_csv(std::iter::once(&self.profile).chain(self.profile_table1.as_ref())),
        });
        Ok(out)
    }

    fn points<'a>(&'a self, sc: &'a SceneReport) -> Vec<Point<'a>> {
        let mut pts = Vec::new();
        for kind in SOLVERS {
            for p in sc.points.iter().filter(|p| p.solver == kind) {
                if let Some(t) = p.timing {
                    pts.push(Point {
                        runner: kind.name(),
                        setting: p.setting,
                        time: t.median_s,
                        errors: &p.errors,
                        passes: p.passes_loose,
                    });
                }
            }
        }
        for c in &self.clients {
            let Some(cs) = c.scenes.iter().find(|s| s.scene == sc.name) else {
                continue;
            };
            for p in cs.points.iter().filter(|p| placed(p.failure.as_ref())) {
                if let Some(t) = p.time() {
                    pts.push(Point {
                        runner: &c.name,
                        setting: p.setting,
                        time: t.median_s,
                        errors: &p.errors,
                        passes: p.passes_loose,
                    });
                }
            }
        }
        pts
    }

    fn scene_figure(&self, sc: &SceneReport) -> Figure {
        let pts = self.points(sc);
        let mut runners: Vec<&str> = Vec::new();
        for p in &pts {
            if !runners.contains(&p.runner) {
                runners.push(p.runner);
            }
        }
        let panels: Vec<Panel> = QUANTITIES
            .iter()
            .enumerate()
            .map(|(k, &(what, y_label, pick))| {
                let mut series = Vec::new();
                for &r in &runners {
                    let st = style(r);
                    let mine: Vec<(f64, f64, bool)> = pts
                        .iter()
                        .filter(|p| p.runner == r)
                        .filter_map(|p| Some((p.time, pick(p.errors)?, p.passes.unwrap_or(true))))
                        .collect();
                    if mine.is_empty() {
                        continue;
                    }
                    series.push(Series {
                        label: r,
                        color: st.color,
                        dash: st.dash,
                        marker: Some(3.5),
                        shape: st.shape,
                        points: mine.iter().map(|&(x, y, _)| (x, y)).collect(),
                        ..Series::default()
                    });
                    let failing: Vec<(f64, f64)> = mine
                        .iter()
                        .filter(|p| !p.2)
                        .map(|&(x, y, _)| (x, y))
                        .collect();
                    if !failing.is_empty() {
                        series.push(Series {
                            color: st.color,
                            width: 0.0,
                            marker: Some(3.5),
                            shape: st.shape,
                            hollow: true,
                            points: failing,
                            ..Series::default()
                        });
                    }
                }
                let title = if k == 0 {
                    format!(
                        "{} (u = {} V, {} s): {what}; open markers fail the loose gate",
                        sc.name, sc.u, sc.t_end
                    )
                } else {
                    format!("{}: {what}", sc.name)
                };
                let mut panel = Panel::new(title, "run time [s] (median)", y_label, series);
                panel.x_log = true;
                panel.y_log = true;
                panel
            })
            .collect();
        let mut csv = String::from("runner,setting,time_s,steady_rel,transient_max,passes_loose\n");
        for p in &pts {
            let _ = writeln!(
                csv,
                "{},{:e},{:e},{},{},{}",
                p.runner,
                p.setting,
                p.time,
                opt(p.errors.steady_rel),
                opt(p.errors.transient_max),
                p.passes.map_or(String::new(), |b| b.to_string())
            );
        }
        Figure {
            name: sc.name.clone(),
            caption: format!(
                "{}: work precision (u = {} V, {} s)",
                sc.name, sc.u, sc.t_end
            ),
            svg: render(&panels, 760.0, 440.0),
            csv,
        }
    }

    /// The summary page: the profile and every scene's figure, each linked to its SVG and
    /// CSV, for files named `<stem>-<figure>.svg` beside it (the profile: `<stem>.svg`).
    pub fn to_html(&self, stem: &str) -> Result<String, BenchError> {
        let figures = self.figures()?;
        let mut h = String::from(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
             <title>rotorbench: work precision</title>\n<style>body{font-family:sans-serif;\
             max-width:800px;margin:2em auto}img{max-width:100%;border:1px solid #ddd}\
             figure{margin:2em 0}</style></head><body>\n<h1>Work precision</h1>\n",
        );
        let _ = writeln!(
            h,
            "<p>{} scene(s). Each figure is one file, with its data as CSV beside it. A filled \
             marker passes the scene's loose gate, an open one fails it.</p>",
            self.scenes.len()
        );
        for f in &figures {
            let svg = if f.name == "profile" {
                format!("{stem}.svg")
            } else {
                format!("{stem}-{}.svg", f.name)
            };
            let csv = format!("{stem}-{}.csv", f.name);
            let _ = writeln!(
                h,
                "<figure id=\"{n}\"><a href=\"{svg}\"><img src=\"{svg}\" alt=\"{c}\"></a>\
                 <figcaption>{c} (<a href=\"{svg}\">SVG</a>, <a href=\"{csv}\">CSV</a>)\
                 </figcaption></figure>",
                n = esc(&f.name),
                c = esc(&f.caption),
                svg = esc(&svg),
                csv = esc(&csv),
            );
        }
        h.push_str("</body></html>\n");
        Ok(h)
    }
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| format!("{x:e}"))
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The profiles' data: per tier, runner and scene, the runner's time and its ratio to the
/// best (empty where it did not solve the scene).
fn profile_csv<'a>(profiles: impl Iterator<Item = &'a Profile>) -> String {
    let mut csv = String::from("tier,runner,scene,time_s,ratio\n");
    for p in profiles {
        for e in &p.entries {
            for ((scene, t), r) in p.scenes.iter().zip(&e.times).zip(&e.ratios) {
                let _ = writeln!(
                    csv,
                    "{},{},{scene},{},{}",
                    if p.tier.is_empty() { "full" } else { &p.tier },
                    e.name,
                    opt(*t),
                    opt(*r)
                );
            }
        }
    }
    csv
}
