//! Every gate of every fixture beside what it measures: the measured difference, the gate
//! stated in the scenario file, their ratio (the margin), the gate the fixtures' rule gives
//! (5 × the measured difference, rounded up to one digit; the rounding floor below it; 0 where
//! the solvers agree exactly) and whether the gate is within what the test enforces
//! (`rotor_harness::compare::margins`). The whole-run gates (`whole_alpha`, `whole_omega_u`,
//! `whole_omega_l`, `whole_event_time`, of every pair of solvers, `switch-moreau` too) are rows
//! like the others; after the gates it prints the whole run's breakdown (events matched, the
//! phase-aligned differences that are gated and those at equal times that are not,
//! `rotor_harness::compare::whole`). Run it after a solver change to re-derive the `[tolerance.*]`
//! tables:
//!
//! ```sh
//! cargo run --release -p rotor-harness --example gate_margins
//! # and to set every gate outside the rule to the rule, in the scenario files:
//! cargo run --release -p rotor-harness --example gate_margins -- --write
//! ```
//!
//! `--write` rewrites only the lines of gates outside the rule whose measurement is not 0
//! (`key = <rule>  # measured <m> <unit>, margin <x>x`), and lists them; a gate that must
//! become 0 (exact agreement) needs its reason written by hand, and is listed too.

use std::path::Path;

use rotor_analysis::solvers::run_scenario;
use rotor_harness::compare::margins::{Margin, floor_violations, margins};
use rotor_harness::compare::report::whole_run_table;
use rotor_model::scenario::Scenario;

/// The unit a gate's comment states.
fn unit(m: &Margin) -> &'static str {
    match m.key.unwrap_or("") {
        _ if m.relative => "relative",
        "event_time" | "stick_time" | "whole_event_time" => "s",
        "whole_alpha" => "rad",
        _ => "rad/s",
    }
}

/// `text` with the line of `key` in the table `[tolerance.<pair>]` set to `gate` and its
/// measurement, or `None` if there is no such line.
fn rewrite(text: &str, pair: &str, key: &str, gate: f64, comment: &str) -> Option<String> {
    let header = format!("[tolerance.{pair}]");
    let mut in_table = false;
    let mut done = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with('[') {
            in_table = line.trim() == header;
        }
        let is_key = line.split_once('=').is_some_and(|(k, _)| k.trim() == key);
        if in_table && is_key && !done {
            let head = format!("{key} = {gate:e}").replace("e0", ".0");
            out.push_str(&format!("{head:<25} # {comment}\n"));
            done = true;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    done.then_some(out)
}

fn main() {
    let write = std::env::args().any(|a| a == "--write");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    let mut by_hand = Vec::new();
    println!(
        "{:<16} {:<13} {:<24} {:>10} {:>9} {:>7} {:>9}  verdict",
        "scenario", "pair", "key", "measured", "gate", "margin", "rule"
    );
    let (mut rows, mut bad, mut results) = (0, Vec::new(), Vec::new());
    for f in Scenario::list_dir(&dir).expect("fixtures/scenarios") {
        let sc = rotor_analysis::solvers::load_scenario(&f).unwrap_or_else(|e| panic!("{e}"));
        bad.extend(floor_violations(&sc));
        let r = run_scenario(&sc);
        let mut text = std::fs::read_to_string(&f).expect("the scenario file");
        let mut changed = false;
        for m in margins(&r) {
            rows += 1;
            let verdict = m.violation();
            println!(
                "{:<16} {:<13} {:<24} {:>10.3e} {:>9.0e} {:>7} {:>9.0e}  {}",
                m.scenario,
                m.pair,
                m.key.unwrap_or(&m.quantity),
                m.measured,
                m.gate,
                if m.measured == 0.0 && m.gate == 0.0 {
                    "exact".to_owned()
                } else {
                    format!("{:.1}", m.margin())
                },
                m.rule(),
                if verdict.is_some() { "OUTSIDE" } else { "ok" }
            );
            if write && verdict.is_some() {
                let key = m.key.unwrap_or("");
                let g = m.rule();
                let comment = format!(
                    "measured {:.1e} {}, margin {:.1}x",
                    m.measured,
                    unit(&m),
                    g / m.measured
                );
                match rewrite(&text, &m.pair, key, g, &comment) {
                    Some(t) if m.measured > 0.0 && m.measured.is_finite() => {
                        text = t;
                        changed = true;
                    }
                    _ => by_hand.push(format!("{} {} {key}", m.scenario, m.pair)),
                }
            }
            bad.extend(verdict);
        }
        if changed {
            std::fs::write(&f, text).expect("the scenario file written");
            println!("rewritten: {}", f.display());
        }
        results.push(r);
    }
    println!("\n{rows} gates, {} outside the rule", bad.len());
    for b in &bad {
        println!("  {b}");
    }
    if write {
        println!("\nto set by hand (a 0, with its reason): {by_hand:?}");
    }
    print!("{}", whole_run_table(&results));
}
