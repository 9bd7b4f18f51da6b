//! The open benchmark: the committed reference data against the event-driven solver, and
//! `check` on correct, perturbed and malformed traces.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use rayon::prelude::*;
use rotor_analysis::solvers::{SolverKind, load_scenario, run::scene_for};
use rotor_harness::grade::check::{CheckError, Level, check};
use rotor_harness::grade::reference::{self, Reference};
use rotor_harness::grade::trace::{
    EventsFile, Trace, parse_events, parse_trace, write_events, write_trace,
};
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Accuracy, Trajectory};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn scenarios() -> Vec<Scenario> {
    Scenario::list_dir(&fixtures().join("scenarios"))
        .unwrap()
        .iter()
        .map(|f| load_scenario(f).unwrap())
        .collect()
}

fn stored(sc: &Scenario) -> Reference {
    reference::read(&fixtures().join("reference"), &sc.name).unwrap()
}

/// A solver's run of a scenario as the files an external client would write.
fn as_files(sc: &Scenario, tr: &Trajectory) -> (Trace, EventsFile) {
    let t = parse_trace(
        &write_trace(&tr.samples, sc.compare.dt),
        Path::new("client.csv"),
    )
    .unwrap();
    let e = parse_events(&write_events(&tr.events), Path::new("client.events.csv")).unwrap();
    (t, e)
}

/// Whether `d` lies within `allowed` (a NaN does not).
fn within(d: f64, allowed: f64) -> bool {
    d <= allowed
}

/// The first way in which a recomputed reference differs from the stored one by more than
/// the stored error (the trace also by its rounding to `trace_digits`), if any.
fn mismatch(fresh: &Reference, old: &Reference) -> Option<String> {
    if fresh.samples.len() != old.samples.len() || fresh.events.len() != old.events.len() {
        return Some("a different number of samples or events".into());
    }
    for (a, b) in fresh.samples.iter().zip(&old.samples) {
        if (a.t - b.t).abs() > 1e-9 {
            return Some(format!("grid time {} vs {}", a.t, b.t));
        }
        for (i, name) in ["alpha", "omega_u", "omega_l"].iter().enumerate() {
            let allowed = old.error(name);
            let d = (a.x[i] - b.x[i]).abs();
            if !within(d, allowed) {
                return Some(format!("{name} at t = {}: {d:e} > {allowed:e}", a.t));
            }
        }
    }
    for (a, b) in fresh.events.iter().zip(&old.events) {
        let d = (a.t - b.t).abs();
        if a.kind != b.kind || !within(d, old.error("event_time")) {
            return Some(format!(
                "event {:?} at {} vs {:?} at {}",
                a.kind, a.t, b.kind, b.t
            ));
        }
    }
    match (fresh.steady(), old.steady()) {
        (None, None) => {}
        (Some(a), Some(b)) if a.kind() == b.kind() => {
            for ((name, va), (_, vb)) in a.values().into_iter().zip(b.values()) {
                let d = (va - vb).abs();
                if !within(d, old.error(name)) {
                    return Some(format!("steady {name}: {va} vs {vb}"));
                }
            }
        }
        (a, b) => return Some(format!("steady state {a:?} vs {b:?}")),
    }
    None
}

/// The committed reference is what the event-driven solver computes, within the error the
/// reference states for itself (`rotor reference` rewrites it after a solver change). And the
/// comparison is sharp: the same reference with one value moved by three times its stated
/// error is caught.
#[test]
fn reference_files_match_the_event_solver_within_their_stated_error() {
    let all = scenarios();
    assert_eq!(all.len(), 23);
    let bad: Vec<String> = all
        .par_iter()
        .filter_map(|sc| {
            let fresh = reference::compute(sc).unwrap();
            mismatch(&fresh, &stored(sc)).map(|m| format!("{}: {m}", sc.name))
        })
        .collect();
    assert!(
        bad.is_empty(),
        "rerun `rotor reference --out fixtures/reference`:\n{}",
        bad.join("\n")
    );
    let sc = all.iter().find(|s| s.name == "t1-u1.5-rest").unwrap();
    let old = stored(sc);
    let mut moved = old.clone();
    moved.samples[1000].x[2] += 3.0 * old.error("omega_l");
    assert!(mismatch(&moved, &old).is_some_and(|m| m.contains("omega_l")));
}

/// Honest solvers of every kind pass on every scenario, with their events: the event-driven
/// solver at tol 1e-11 (a well-converged adaptive integrator) the strict level, the switch
/// model and Moreau–Jean at the comparison's settings the loose one; the reference itself
/// has every difference 0.
#[test]
fn every_solver_passes_check_at_its_level() {
    let fails: Vec<String> = scenarios()
        .par_iter()
        .flat_map(|sc| {
            let r = stored(sc);
            let mut out = Vec::new();
            let tight = rotor_model::seam::Scene {
                accuracy: Accuracy::Tol(1e-11),
                ..scene_for(SolverKind::EVENT, sc)
            };
            for (kind, scene, level) in [
                (SolverKind::EVENT, tight, Level::Strict),
                (
                    SolverKind::SWITCH,
                    scene_for(SolverKind::SWITCH, sc),
                    Level::Loose,
                ),
                (
                    SolverKind::MOREAU,
                    scene_for(SolverKind::MOREAU, sc),
                    Level::Loose,
                ),
            ] {
                let tr = kind.solver().simulate(&sc.model, &scene).unwrap();
                let (t, e) = as_files(sc, &tr);
                let rep = check(sc, &r, &t, Some(&e), level).unwrap();
                if !rep.passed || !rep.not_graded.is_empty() {
                    out.push(format!("{} {}:\n{}", sc.name, kind.name(), rep.table()));
                }
            }
            let own = parse_trace(
                &write_trace(&r.samples.iter().copied().collect(), sc.compare.dt),
                Path::new("r.csv"),
            );
            let ev = parse_events(&write_events(&r.events), Path::new("r.events.csv")).unwrap();
            let rep = check(sc, &r, &own.unwrap(), Some(&ev), Level::Strict).unwrap();
            // Every difference is 0, the orbit's too: it compares the trace's offsets from
            // the orbit with the reference's own at the same times.
            if !rep.quantities.iter().all(|q| q.difference == 0.0) {
                out.push(format!("{} reference:\n{}", sc.name, rep.table()));
            }
            out
        })
        .collect();
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

fn check_text(trace: &str) -> Result<Vec<String>, CheckError> {
    let sc = scenarios()
        .into_iter()
        .find(|s| s.name == "t1-u0.02-rest")
        .unwrap();
    let r = stored(&sc);
    let t = parse_trace(trace.as_bytes(), Path::new("c.csv"))?;
    let rep = check(&sc, &r, &t, None, Level::Loose)?;
    Ok(rep.failing().iter().map(|s| s.to_string()).collect())
}

/// The reference trace of `t1-u0.02-rest` (100 s, 10 001 rows) as text.
fn good_text() -> String {
    let sc = scenarios()
        .into_iter()
        .find(|s| s.name == "t1-u0.02-rest")
        .unwrap();
    String::from_utf8(write_trace(
        &stored(&sc).samples.iter().copied().collect(),
        sc.compare.dt,
    ))
    .unwrap()
}

/// Unusable traces are errors that name the file and the line (or the missing time).
#[test]
fn malformed_traces_are_unusable_with_the_line_named() {
    let good = good_text();
    assert_eq!(check_text(&good).unwrap(), Vec::<String>::new());
    let lines: Vec<&str> = good.lines().collect();
    let with = |f: &dyn Fn(&mut Vec<String>)| {
        let mut v: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        f(&mut v);
        v.join("\n") + "\n"
    };
    let msg = |text: String| check_text(&text).unwrap_err().to_string();
    // A missing row (t = 1 s, line 102): the next row's time is not the grid time its
    // position asks for.
    let m = msg(with(&|v| {
        v.remove(101);
    }));
    assert!(
        m.contains("line 102: t = 1.01 is not the grid time 1 "),
        "{m}"
    );
    let m = msg(with(&|v| v.truncate(5000)));
    assert!(
        m.contains("line 5000: the trace ends here") && m.contains("49.99"),
        "{m}"
    );
    let m = msg(with(&|v| v.push("100.01,0,0,0".into())));
    assert!(m.contains("line 10003: t = 100.01 is past"), "{m}");
    let m = msg(with(&|v| v[7] = "0.0600001,0,0,0".into()));
    assert!(m.contains("line 8"), "{m}");
    let m = msg(with(&|v| v[3] = "0.02,0,NaN,0".into()));
    assert!(m.contains("line 4, column 3"), "{m}");
    let m = msg(with(&|v| v[0] = "time,alpha,omega_u,omega_l".into()));
    assert!(m.contains("line 1: the header"), "{m}");
    assert!(msg(String::new()).contains("empty"));
    let dir = std::env::temp_dir();
    let e = rotor_harness::grade::trace::read_trace(&dir, usize::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains(&dir.display().to_string()), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        ..ProptestConfig::default()
    })]

    /// Mutated traces (a line removed, duplicated or swapped with its neighbour, a field
    /// replaced, the file cut at a byte) never panic, and the verdict is the right one: a
    /// removed, duplicated or swapped row is refused, naming its line; a value replaced by a
    /// number fails the grade when it moved by more than the loose level allows and passes
    /// when it did not move; a cut file is refused unless the cut left every row whole.
    #[test]
    fn mutated_traces_get_the_right_verdict(
        op in 0usize..5,
        at in 1usize..10_000,
        field in 0usize..4,
        junk in prop::sample::select(vec!["", "x", "NaN", "inf", "1e400", "-0", "1,2", "0x10", " 3 "]),
        cut in 0usize..600_000,
    ) {
        let good = good_text();
        let mut lines: Vec<String> = good.lines().map(str::to_owned).collect();
        let text = match op {
            0 => { lines.remove(at); lines.join("\n") }
            1 => { let l = lines[at].clone(); lines.insert(at, l); lines.join("\n") }
            2 => { lines.swap(at, at + 1); lines.join("\n") }
            3 => {
                let mut f: Vec<String> = lines[at].split(',').map(str::to_owned).collect();
                f[field] = junk.to_owned();
                lines[at] = f.join(",");
                lines.join("\n")
            }
            _ => good[..cut.min(good.len())].to_owned(),
        };
        let verdict = check_text(&text);
        if let Err(e) = &verdict {
            let m = e.to_string();
            prop_assert!(m.contains("line") || m.contains("empty") || m.contains("no data"), "{}", m);
        }
        match op {
            0..=2 => prop_assert!(verdict.is_err(), "op {} at {} was graded", op, at),
            3 => {
                let old: f64 = good.lines().nth(at).unwrap().split(',').nth(field).unwrap().parse().unwrap();
                match junk.trim().parse::<f64>() {
                    Ok(new) if new.is_finite() && field > 0 => {
                        let failing = verdict.unwrap();
                        if new == old {
                            prop_assert!(failing.is_empty(), "{:?}", failing);
                        } else if (new - old).abs() > 1e-3 * 4.0 {
                            // 4 rad or rad/s bounds every scale of this scenario from above.
                            prop_assert!(!failing.is_empty(), "moved {} -> {}", old, new);
                        }
                    }
                    Ok(new) if new.is_finite() && new == old => prop_assert!(verdict.is_ok()),
                    // A time off the grid, a value that is no finite number.
                    _ => prop_assert!(verdict.is_err()),
                }
            }
            _ => {
                // Graded only if the cut fell inside the last row (a shortened last number).
                let last_row = good.trim_end().rfind('\n').unwrap();
                prop_assert!(verdict.is_err() || cut > last_row, "cut at {} of {}", cut, good.len());
            }
        }
    }
}
