//! The report's section on the suite's chain tier: each chain scene through the three solvers,
//! every α_i and ω_i and every event gated pair by pair ([`crate::compare::chain`]), with a
//! figure of every disc's velocity by each solver and the largest difference from the
//! event-driven reference.

use std::fmt::Write as _;

use rotor_analysis::plot::{Panel, Series, render_rows};
use rotor_model::scenario::ChainScenario;
use rotor_model::{Rounding, round_sig};

use crate::compare::chain::{ChainComparison, compare_chain};
use crate::compare::report::Section;

/// The figure of a chain scene: a panel per disc with its ω by each solver overlaid, then the
/// largest |Δω_i| over the discs of each solver from the event-driven run (log scale).
pub fn chain_svg(c: &ChainComparison) -> String {
    let sc = &c.scenario;
    let model = sc.model();
    let labels: Vec<String> = c.runs.iter().map(|r| r.kind.label_at(r.setting)).collect();
    let mut panels = Vec::new();
    let mut heights = Vec::new();
    for disc in 0..model.discs() {
        let i = model.omega(disc);
        let series = c
            .runs
            .iter()
            .zip(&labels)
            .map(|(r, label)| {
                let style = r.kind.info().style;
                Series {
                    label,
                    color: style.color,
                    dash: style.dash,
                    width: style.width,
                    points: r.run.samples.iter().map(|s| (s.t, s.x[i])).collect(),
                    ..Series::default()
                }
            })
            .collect();
        panels.push(Panel::new(
            format!("{}: disc {}", sc.name, disc + 1),
            "t [s]",
            "ω [rad/s]",
            series,
        ));
        heights.push(200.0);
    }
    if let Some(reference) = c.runs.first() {
        let omegas: Vec<usize> = (0..model.discs()).map(|d| model.omega(d)).collect();
        let diffs = c
            .runs
            .iter()
            .zip(&labels)
            .skip(1)
            .map(|(r, label)| {
                let style = r.kind.info().style;
                Series {
                    label,
                    color: style.color,
                    width: 1.0,
                    points: r
                        .run
                        .samples
                        .iter()
                        .zip(&reference.run.samples)
                        .map(|(a, b)| {
                            let d = omegas
                                .iter()
                                .map(|&i| (a.x[i] - b.x[i]).abs())
                                .fold(0.0, f64::max);
                            (a.t, d)
                        })
                        .collect(),
                    ..Series::default()
                }
            })
            .collect();
        let mut panel = Panel::new(
            format!(
                "{}: largest |Δω_i| over the discs, from {}",
                sc.name, labels[0]
            ),
            "t [s]",
            "max_i |Δω_i| [rad/s]",
            diffs,
        );
        panel.y_log = true;
        panels.push(panel);
        heights.push(230.0);
    }
    render_rows(&panels, 900.0, &heights)
}

/// The data of [`chain_svg`]: `t`, then for each solver every ω_i (`omega_<i>_<solver>`), to
/// 12 significant digits (far below every gate, so the committed report moves only where an
/// answer does).
pub fn chain_csv(c: &ChainComparison) -> String {
    let model = c.scenario.model();
    let omegas: Vec<usize> = (0..model.discs()).map(|d| model.omega(d)).collect();
    let mut out = String::from("t");
    for r in &c.runs {
        for d in 1..=model.discs() {
            let _ = write!(out, ",omega_{d}_{}", r.kind.name());
        }
    }
    out.push('\n');
    let n = c
        .runs
        .iter()
        .map(|r| r.run.samples.len())
        .min()
        .unwrap_or(0);
    let digits = crate::grade::trace::time_digits(c.scenario.dt);
    for k in 0..n {
        let t = c.runs[0].run.samples.t(k);
        let _ = write!(out, "{}", crate::grade::trace::round_to(t, digits));
        for r in &c.runs {
            let x = r.run.samples.x(k);
            for &i in &omegas {
                let _ = write!(
                    out,
                    ",{}",
                    round_sig(x[i], 12, Rounding::Decimal { floor: 0.0 })
                );
            }
        }
        out.push('\n');
    }
    out
}

/// A difference or gate as the report prints it: two significant digits.
fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.1e}")
    } else {
        "—".into()
    }
}

/// The section of the chain tier's scenes: each through the three solvers, gated.
pub fn chain_section(scenes: &[ChainScenario]) -> Section {
    use rayon::prelude::*;
    let t0 = std::time::Instant::now();
    let results: Vec<_> = scenes.par_iter().map(compare_chain).collect();
    let mut sec = Section {
        markdown: String::new(),
        files: Vec::new(),
        failures: Vec::new(),
        timings: String::new(),
    };
    let md = &mut sec.markdown;
    let _ = write!(
        md,
        "## Chains of N discs: the suite's chain tier\n\n\
         Chain tier `{}` (`rotor scenarios`). Each chain scene runs through the three solvers, \
         which share nothing but the chain's model; they must agree on every sample of every \
         α_i and ω_i over the whole run and on the time of every stick onset, stick exit and \
         reversal, pair by pair, within `2·(e_a + e_b) + 1e-12 + (η_a + η_b)·max(1, t_end)`: \
         twice the two solvers' own errors on the scene (each from its runs at tighter settings: \
         tolerance/100; step/2, step/4 and step/8; the switch model's also with its band's error, \
         measured by a run at η/10), the rounding floor, and the switch model's stick band \
         (docs/methods.md, \"Chains in the suite\"). The *margin* is gate/difference; the \
         worst quantity of each pair is named.\n\n\
         | scene | discs | pair | worst quantity | difference | gate | margin | event times: difference | gate |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        crate::grade::chain::CHAIN_BENCHMARK
    );
    let mut ok = Vec::new();
    for (sc, r) in scenes.iter().zip(results) {
        match r {
            Ok(c) => ok.push(c),
            Err(e) => sec
                .failures
                .push(format!("chain scene {}: a run failed: {e}", sc.name)),
        }
    }
    for c in &ok {
        let sc = &c.scenario;
        let pairs: Vec<String> = {
            let mut v: Vec<String> = Vec::new();
            for g in &c.gates {
                if !v.contains(&g.pair) {
                    v.push(g.pair.clone());
                }
            }
            v
        };
        for pair in &pairs {
            let of_pair: Vec<_> = c.gates.iter().filter(|g| &g.pair == pair).collect();
            let worst = of_pair
                .iter()
                .filter(|g| g.quantity != "event_time")
                .max_by(|a, b| a.ratio().total_cmp(&b.ratio()));
            let ev = of_pair.iter().find(|g| g.quantity == "event_time");
            if let Some(w) = worst {
                let _ = writeln!(
                    md,
                    "| [{}]({}.svg) | {} | {pair} | {} | {} | {} | {} | {} | {} |",
                    sc.name,
                    sc.name,
                    sc.discs(),
                    w.quantity,
                    sci(w.difference),
                    sci(w.gate),
                    margin(w.difference, w.gate),
                    ev.map_or("—".into(), |g| sci(g.difference)),
                    ev.map_or("—".into(), |g| sci(g.gate)),
                );
            }
        }
        sec.failures.extend(c.failures());
        sec.files
            .push((format!("{}.svg", sc.name), chain_svg(c).into_bytes()));
        sec.files
            .push((format!("{}.csv", sc.name), chain_csv(c).into_bytes()));
    }
    md.push_str(
        "\n| scene | solver | setting | steps | events | own error, largest ω_i [rad/s] |\n\
         |---|---|---|---|---|---|\n",
    );
    for c in &ok {
        for r in &c.runs {
            let own = r
                .own
                .iter()
                .filter(|(k, _)| k.starts_with("omega_"))
                .map(|(_, &v)| v)
                .fold(0.0, f64::max);
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} |",
                c.scenario.name,
                r.kind.name(),
                r.kind.setting_label(r.setting),
                r.run.stats.steps,
                crate::grade::reference::switches(&r.run.events).len(),
                sci(own),
            );
        }
    }
    md.push('\n');
    let _ = write!(
        sec.timings,
        "\n## Chain tier\n\n{} scenes through three solvers (each at three settings) in {:.2} s.\n",
        scenes.len(),
        t0.elapsed().as_secs_f64()
    );
    for c in &ok {
        for r in &c.runs {
            let _ = writeln!(
                sec.timings,
                "- {} {}: {:.1} ms",
                c.scenario.name,
                r.kind.name(),
                r.seconds * 1e3
            );
        }
    }
    sec
}

/// gate/difference to two digits (`∞` where they agree exactly, `0` where they cannot be
/// compared).
fn margin(d: f64, g: f64) -> String {
    if d == 0.0 {
        "∞".into()
    } else if !d.is_finite() {
        "0".into()
    } else {
        format!("{:.2}", round_sig(g / d, 2, Rounding::Scaled))
    }
}
