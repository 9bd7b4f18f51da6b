//! The CI gate: every fixture scenario through the three solvers, agreement asserted; and a
//! check that the gate catches a perturbed solver.

use std::path::Path;

use std::sync::OnceLock;

use rotor_analysis::solvers::{
    SOLVERS, ScenarioResult, SolverKind, all_pairs, pair_name, run_scenario,
};
use rotor_harness::compare::gate::gate_scenario;
use rotor_harness::compare::margins::{MAX_LOOSENESS, floor_violations, margins};
use rotor_harness::compare::snapshot::snapshot;
use rotor_model::Disc;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Event, EventKind, RigSteady, Trajectory};

/// Every fixture through the three solvers, once per test binary (shared by the tests).
fn all() -> Vec<ScenarioResult> {
    static RESULTS: OnceLock<Vec<ScenarioResult>> = OnceLock::new();
    RESULTS
        .get_or_init(|| {
            use rayon::prelude::*;
            let files = Scenario::list_dir(&scenario_dir()).unwrap();
            assert!(files.len() >= 14);
            files
                .par_iter()
                .map(|f| run_scenario(&rotor_analysis::solvers::load_scenario(f).unwrap()))
                .collect()
        })
        .clone()
}

fn scenario_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
}

/// Per scenario: each solver's steady-state metrics (rounded to the digits the scenario's
/// tolerance justifies, see `rotor_harness::compare::snapshot`) and its counters. A solver change that
/// moves an answer by about the agreement tolerance, or changes how much work a solver does,
/// shows up here for review.
#[test]
fn snapshots_of_metrics_and_counters() {
    let results = all();
    for r in &results {
        insta::assert_yaml_snapshot!(r.scenario.name.clone(), snapshot(r));
    }
    // Every stored snapshot belongs to a fixture scenario: a renamed or deleted scenario
    // must take its snapshot with it (CI also rejects any snapshot no test reads: .ci/snapshots).
    let names: Vec<String> = results.iter().map(|r| r.scenario.name.clone()).collect();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            !file.ends_with(".snap.new"),
            "pending snapshot {file}: review it"
        );
        let stem = file
            .trim_start_matches("fixtures__")
            .trim_end_matches(".snap");
        assert!(
            names.iter().any(|n| n == stem),
            "unreferenced snapshot {file}"
        );
    }
}

#[test]
fn every_fixture_agrees_across_the_three_solvers_and_a_perturbation_is_caught() {
    let results = all();
    let mut fails = Vec::new();
    for r in &results {
        fails.extend(gate_scenario(r).1);
    }
    for f in &fails {
        eprintln!("{f}");
    }
    assert!(fails.is_empty(), "{} gate(s) failed", fails.len());

    // Inject a small error into one solver's result: 1e-5 rad/s on ω_l of the switch model
    // (100x its transient tolerance, far below anything visible in a plot) must fail.
    let mut r = results
        .into_iter()
        .find(|r| r.scenario.name == "t1-u1.5-rest")
        .unwrap();
    for run in &mut r.runs {
        if run.kind == SolverKind::SWITCH {
            let tr = run.result.as_mut().unwrap();
            for s in &mut tr.samples {
                if s.t > 5.0 && s.t < 6.0 {
                    s.x[2] += 1e-5;
                }
            }
            if let Some(rotor_model::seam::SteadyState::LimitCycle { period, .. }) =
                tr.metrics.as_mut()
            {
                *period *= 1.0 + 1e-5;
            }
        }
    }
    let fails = gate_scenario(&r).1;
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch" && f.quantity.contains("transient max"))
    );
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch" && f.quantity.contains("period"))
    );
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch" && f.quantity.starts_with("whole omega_l")),
        "{fails:?}"
    );
    assert!(
        fails.iter().all(|f| f.pair.contains("switch")),
        "only the perturbed solver's pairs fail: {fails:?}"
    );
}

/// `gate_margins` as a test: every gate of every fixture is within the rule that
/// `rotor_harness::compare::margins` enforces (a measured 0 has a gate of 0; otherwise
/// measured <= gate <= 10 x max(measured, rounding floor); `steady_abs` at most 1e-12). So a
/// gate cannot drift wider than its measurement justifies (a real regression would pass), nor
/// narrower than it (the previous test fails then too).
#[test]
fn gate_margins_every_gate_is_within_its_rule() {
    let results = all();
    let rows: Vec<_> = results.iter().flat_map(margins).collect();
    let mut bad: Vec<String> = rows.iter().filter_map(|m| m.violation()).collect();
    for r in &results {
        bad.extend(floor_violations(&r.scenario));
    }
    assert!(
        bad.is_empty(),
        "{} of {} gates outside the rule (re-measure: cargo run --release -p rotor-harness \
         --example gate_margins):\n{}",
        bad.len(),
        rows.len(),
        bad.join("\n")
    );
    // 14 fixtures x 2 pairs x (3 transient + 3 equilibrium or 6 cycle metrics), each its own
    // key: no gate left unchecked.
    assert!(rows.len() >= 14 * 2 * 6, "{}", rows.len());
    assert!(rows.iter().all(|m| m.key.is_some()));

    // Negative controls on the fixtures themselves: each stated gate in turn, made 2x wider
    // than the test allows, or half its measurement, is reported, and only that gate.
    let mut checked = 0;
    for r in &results {
        for m in margins(r) {
            let key = m.key.unwrap();
            let too_wide = MAX_LOOSENESS * m.measured.max(m.floor()) * 2.0;
            let wide = if m.measured == 0.0 {
                "must be 0"
            } else {
                "wider"
            };
            let mut bad_gates = vec![(too_wide, wide)];
            if m.measured > 0.0 {
                bad_gates.push((0.5 * m.measured, "narrower"));
            }
            for (gate, what) in bad_gates {
                let mut p = r.clone();
                let tol = p.scenario.tolerance.get_mut(&m.pair).unwrap();
                *tol.slot(key).unwrap() = Some(gate);
                let v: Vec<String> = margins(&p).iter().filter_map(|m| m.violation()).collect();
                assert!(
                    v.len() == 1 && v[0].contains(what) && v[0].contains(key),
                    "{} {} {key} at {gate:e}: {v:?}",
                    m.scenario,
                    m.pair
                );
                checked += 1;
            }
        }
    }
    assert!(checked > rows.len(), "{checked}");
    // A floor above the rounding floor is reported too.
    let mut sc = results[0].scenario.clone();
    for t in sc.tolerance.values_mut() {
        t.steady_abs = Some(1e-10);
    }
    assert_eq!(floor_violations(&sc).len(), sc.tolerance.len());
}

/// Moves one metric of a steady state by `by` (absolute).
fn shift_metric(m: &mut RigSteady, name: &str, by: f64) {
    let v = match (m, name) {
        (RigSteady::Equilibrium { omega_u, .. }, "omega_u") => omega_u,
        (RigSteady::Equilibrium { omega_l, .. }, "omega_l") => omega_l,
        (RigSteady::Equilibrium { alpha, .. }, "alpha") => alpha,
        (RigSteady::LimitCycle { period, .. }, "period") => period,
        (RigSteady::LimitCycle { omega_l_max, .. }, "omega_l_max") => omega_l_max,
        (RigSteady::LimitCycle { omega_l_min, .. }, "omega_l_min") => omega_l_min,
        (RigSteady::LimitCycle { omega_u_max, .. }, "omega_u_max") => omega_u_max,
        (RigSteady::LimitCycle { omega_u_min, .. }, "omega_u_min") => omega_u_min,
        (RigSteady::LimitCycle { stick_time, .. }, "stick_time") => stick_time,
        (m, n) => panic!("{n} is not a metric of {m:?}"),
    };
    *v += by;
}

/// The negative control of every gate of every fixture: each stated tolerance, one at a time,
/// is exceeded (three times the gate, plus the measured difference) in one solver's result,
/// and exactly that quantity must fail. So no gate is stated but not applied, or applied to
/// another quantity. The whole-run gates are exceeded after the transient window (the last
/// sample, the last matched event): what a solver that goes wrong after it would do. Moving
/// solver b's result may also fail the whole-run gates of b's other pair (`switch-moreau`
/// shares b), never anything else of another pair.
#[test]
fn every_gate_of_every_fixture_fails_its_negative_control() {
    let results = all();
    let mut checked = 0;
    for r in &results {
        let sc = &r.scenario;
        let [t0, t1] = sc.compare.transient.unwrap();
        for (a, b) in all_pairs(&SOLVERS) {
            let pair = pair_name(a, b);
            let tol = sc.tolerance[&pair];
            let base = gate_scenario(r)
                .0
                .into_iter()
                .find(|g| g.pair == pair)
                .unwrap();
            for m in &base.measured {
                let mut p = r.clone();
                let run = p.runs.iter_mut().find(|run| run.kind == b).unwrap();
                let tr: &mut Trajectory = run.result.as_mut().unwrap();
                let excess = 3.0 * m.tol + m.diff + 1e-12;
                let q = m.quantity.as_str();
                if q.starts_with("transient max") {
                    let s = tr
                        .samples
                        .iter_mut()
                        .find(|s| s.t >= t0 && s.t <= t1)
                        .unwrap();
                    s.x[2] += excess;
                } else if q.starts_with("transient rms") {
                    for s in tr.samples.iter_mut().filter(|s| s.t >= t0 && s.t <= t1) {
                        s.x[2] += excess;
                    }
                } else if q.starts_with("stick event times") {
                    match tr.events.iter_mut().find(|e| {
                        e.t >= t0
                            && e.t <= t1
                            && matches!(e.kind, EventKind::StickStart(Disc::LOWER))
                    }) {
                        Some(e) => e.t += excess,
                        // No stick event in the window: one that appears must fail.
                        None => tr.events.push(Event {
                            t: 0.5 * (t0 + t1),
                            x: vec![0.0; 3],
                            kind: EventKind::StickStart(Disc::LOWER),
                        }),
                    }
                } else if let Some(rest) = q.strip_prefix("whole ") {
                    if rest.starts_with("event times") {
                        let last = tr
                            .events
                            .iter_mut()
                            .rev()
                            .find(|e| rotor_harness::compare::whole::is_switch(e.kind));
                        match last {
                            Some(e) if e.t > t1 => e.t += excess,
                            // No switch after the window: one that appears must fail.
                            _ => tr.events.push(Event {
                                t: 0.5 * (t1 + sc.t_end),
                                x: vec![0.0; 3],
                                kind: EventKind::StickStart(Disc::LOWER),
                            }),
                        }
                    } else {
                        let i = ["alpha", "omega_u", "omega_l"]
                            .iter()
                            .position(|c| rest.starts_with(&format!("{c} ")))
                            .unwrap_or_else(|| panic!("{q}"));
                        tr.samples.last_mut().unwrap().x[i] += excess;
                    }
                } else if let Some(name) = q.strip_prefix("steady ") {
                    let mut metrics = tr.rig_metrics().unwrap();
                    let v = metrics
                        .values()
                        .into_iter()
                        .find(|v| v.0 == name)
                        .unwrap()
                        .1;
                    let (quantity, gate) = tol.for_metric(name).unwrap();
                    assert_eq!(m.key, Some(quantity.key), "{q}");
                    let gate = gate.unwrap();
                    // A stuck disc's velocity is compared beyond the two solvers' stuck
                    // bands (the switch model's η): the excess goes beyond the band too.
                    let band = if matches!(name, "omega_u" | "omega_l") {
                        rotor_harness::compare::gate::stuck_band(a, b)
                    } else {
                        0.0
                    };
                    let by = if quantity.relative {
                        3.0 * (gate * v.abs()).max(tol.steady_abs.unwrap_or(0.0))
                            + m.diff * v.abs()
                            + 1e-12
                            + band
                    } else {
                        excess
                    };
                    shift_metric(&mut metrics, name, by);
                    tr.metrics = Some(metrics.into());
                } else {
                    panic!("{}: unknown quantity {q}", sc.name);
                }
                let fails = gate_scenario(&p).1;
                assert!(
                    fails.iter().any(|f| f.pair == pair
                        && f.quantity
                            .starts_with(&q[..q.find(" (").unwrap_or(q.len())])),
                    "{} {pair}: {q} exceeded but not caught: {fails:?}",
                    sc.name
                );
                assert!(
                    fails.iter().all(|f| f.pair == pair
                        || (f.pair.split('-').any(|s| s == b.name())
                            && f.quantity.starts_with("whole "))),
                    "{} {pair}: {q}: another pair failed: {fails:?}",
                    sc.name
                );
                checked += 1;
            }
        }
    }
    // 14 fixtures x 2 pairs x (3 transient + 3 equilibrium or 6 cycle metrics), and 3 pairs x
    // 4 whole-run gates.
    assert!(checked >= 14 * (2 * 6 + 3 * 4), "{checked}");
}

/// A shift of 1e-6 (relative) of a cycle's period in all three solvers alike passes every pair
/// gate (they compare solvers with each other); the snapshot must see it.
#[test]
fn a_shift_of_every_solver_alike_changes_the_snapshot() {
    let results = all();
    let mut cycles = 0;
    for r in &results {
        let mut p = r.clone();
        let mut any = false;
        for run in &mut p.runs {
            if let Some(rotor_model::seam::SteadyState::LimitCycle { period, .. }) =
                run.result.as_mut().unwrap().metrics.as_mut()
            {
                *period *= 1.0 + 1e-6;
                any = true;
            }
        }
        if !any {
            continue;
        }
        cycles += 1;
        assert!(gate_scenario(&p).1.is_empty(), "{}", r.scenario.name);
        // The reference and the switch model keep the digits of the tight event-switch gate;
        // Moreau-Jean's value keeps those of its own (looser) gate and may not move.
        let (a, b) = (snapshot(r), snapshot(&p));
        for (sa, sb) in a.solvers.iter().zip(&b.solvers).take(2) {
            assert_ne!(
                sa.metrics["period"], sb.metrics["period"],
                "{} {}: the snapshot does not see a 1e-6 shift",
                r.scenario.name, sa.solver
            );
        }
    }
    assert!(cycles >= 7, "{cycles}");
}

/// The reference's recorded cross-check (`fixtures/reference/<name>.json`, `cross_check`: the
/// switch model's and Moreau-Jean's largest differences from the reference over the whole run,
/// per trace component, over the mode switches and per steady metric) is what the comparison
/// measures now. The reference run is the comparison's event-driven run (the same solver,
/// tolerance 1e-12, scene and grid), so the two must agree to the two significant digits the
/// file keeps: within half a unit of the second digit, 5 % of the value. A solver change that
/// moves a whole-run difference therefore fails here until the reference is regenerated
/// (`rotor reference`), and every recorded event time is within the whole-run event gate.
#[test]
fn the_reference_cross_check_is_what_the_comparison_measures() {
    let results = all();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/reference");
    let (mut checked, mut nonzero) = (0, 0);
    let mut bad = Vec::new();
    for r in &results {
        let reference = rotor_harness::grade::reference::read(&dir, &r.scenario.name)
            .unwrap_or_else(|e| panic!("{}: {e}", r.scenario.name));
        let c = stale_cross_check(r, &reference.json);
        checked += c.checked;
        nonzero += c.nonzero;
        bad.extend(c.stale);
    }
    assert!(
        bad.is_empty(),
        "{} of {checked} recorded cross-check differences are stale (regenerate with `rotor \
         reference`):\n{}",
        bad.len(),
        bad.join("\n")
    );
    // 22 references x 2 solvers x (4 trace and event + 3 or 6 steady metrics), most of them
    // not 0.
    assert!(
        checked >= 22 * 2 * 4 && nonzero > checked / 2,
        "{checked} {nonzero}"
    );

    // Negative control: the switch model's ω_l off by 1e-5 rad/s after 20 s (3x the recorded
    // whole-run difference at t1-u1.5-rest) makes the record stale, in omega_l alone.
    let mut p = results
        .into_iter()
        .find(|r| r.scenario.name == "t1-u1.5-rest")
        .unwrap();
    for run in &mut p.runs {
        if run.kind == SolverKind::SWITCH {
            for s in &mut run.result.as_mut().unwrap().samples {
                if s.t > 20.0 {
                    s.x[2] += 1e-5;
                }
            }
        }
    }
    let reference = rotor_harness::grade::reference::read(&dir, "t1-u1.5-rest").unwrap();
    let c = stale_cross_check(&p, &reference.json);
    assert!(
        c.stale.len() == 1 && c.stale[0].contains("switch: omega_l "),
        "{:?}",
        c.stale
    );
}

/// What [`stale_cross_check`] found.
struct CrossCheckAudit {
    checked: usize,
    nonzero: usize,
    stale: Vec<String>,
}

/// Each recorded difference of a reference's `cross_check` against the comparison's runs now:
/// the trace's largest difference per component at equal times, the mode switches' largest
/// time difference, and each steady metric's absolute difference.
fn stale_cross_check(
    r: &ScenarioResult,
    json: &rotor_harness::grade::reference::ReferenceJson,
) -> CrossCheckAudit {
    use rotor_harness::compare::whole::{switch_time_difference, whole_run};
    let sc = &r.scenario;
    let event = r.traj(SolverKind::EVENT).unwrap();
    let mut audit = CrossCheckAudit {
        checked: 0,
        nonzero: 0,
        stale: Vec::new(),
    };
    for kind in [SolverKind::SWITCH, SolverKind::MOREAU] {
        let other = r.traj(kind).unwrap();
        let recorded = &json.cross_check[kind.name()].differences;
        let band = rotor_harness::compare::gate::stuck_band(SolverKind::EVENT, kind);
        let w = whole_run(&sc.model, sc.u, event, other, band);
        let mut now: Vec<(String, f64)> = vec![
            ("alpha".into(), w.raw[0]),
            ("omega_u".into(), w.raw[1]),
            ("omega_l".into(), w.raw[2]),
            ("event_time".into(), switch_time_difference(event, other)),
        ];
        // The steady metrics, absolute; an equilibrium's alpha, omega_u, omega_l share the
        // trace's names and the file keeps the larger.
        if let (Some(ma), Some(mb)) = (event.rig_metrics(), other.rig_metrics()) {
            for ((name, va), (_, vb)) in ma.values().into_iter().zip(mb.values()) {
                let d = (va - vb).abs();
                match now.iter_mut().find(|x| x.0 == name) {
                    Some(x) => x.1 = x.1.max(d),
                    None => now.push((name.into(), d)),
                }
            }
        }
        for (name, m) in &now {
            let rec = recorded.get(name).copied().flatten();
            // Two significant digits: within half a unit of the second, 5 % of the value.
            let agree = match rec {
                None => !m.is_finite(),
                Some(rec) => (rec - m).abs() <= 0.05 * m.abs(),
            };
            if !agree {
                audit.stale.push(format!(
                    "{} {}: {name} recorded {rec:?}, measured now {m:.3e}",
                    sc.name,
                    kind.name()
                ));
            }
            audit.checked += 1;
            audit.nonzero += usize::from(*m > 0.0);
        }
        // Every recorded event time lies within the pair's whole-run event gate.
        let gate = sc.tolerance[&pair_name(SolverKind::EVENT, kind)]
            .whole_event_time
            .unwrap();
        if let Some(Some(rec)) = recorded.get("event_time") {
            assert!(
                *rec <= gate,
                "{} {}: recorded event_time {rec:e} over the gate {gate:e}",
                sc.name,
                kind.name()
            );
        }
    }
    audit
}
