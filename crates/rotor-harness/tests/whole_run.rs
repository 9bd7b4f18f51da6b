//! Negative controls of the whole-run gates (`rotor_harness::compare::whole`): a solver that goes wrong
//! only after the transient window [0, 20] s must fail, in each quantity alone, while every
//! gate of the window still passes. Before the whole-run gates such a solver passed CI.

use std::path::Path;
use std::sync::OnceLock;

use rotor_analysis::solvers::{ScenarioResult, SolverKind, run_scenario, run_scenario_with};
use rotor_harness::compare::gate::{Failure, gate_scenario};
use rotor_harness::compare::whole::{is_anchor, sample_mode};
use rotor_model::Model;
use rotor_model::seam::{Scene, SolveError, Solver, Trajectory};

/// The end of the fixtures' transient window \[s\].
const WINDOW_END: f64 = 20.0;

fn scenario(name: &str) -> rotor_model::scenario::Scenario {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    rotor_analysis::solvers::load_scenario(&dir.join(format!("{name}.toml"))).unwrap()
}

/// A stick-slip cycle (t1-u1.5-rest) and an orbit leaving an unstable equilibrium
/// (t1-u2.5-eq-pert), each through the three solvers once.
fn results() -> &'static [ScenarioResult] {
    static R: OnceLock<Vec<ScenarioResult>> = OnceLock::new();
    R.get_or_init(|| {
        ["t1-u1.5-rest", "t1-u2.5-eq-pert"]
            .iter()
            .map(|n| run_scenario(&scenario(n)))
            .collect()
    })
}

fn switch_run(r: &mut ScenarioResult) -> &mut Trajectory {
    r.runs
        .iter_mut()
        .find(|run| run.kind == SolverKind::SWITCH)
        .unwrap()
        .result
        .as_mut()
        .unwrap()
}

/// The gate stated for `key` of the event-switch pair, and what it measures unperturbed.
fn gate_and_measured(r: &ScenarioResult, key: &str) -> (f64, f64) {
    let g = gate_scenario(r).0;
    let m = g
        .iter()
        .find(|g| g.pair == "event-switch")
        .unwrap()
        .measured
        .iter()
        .find(|m| m.key == Some(key))
        .unwrap()
        .clone();
    (m.tol, m.diff)
}

/// The failures, which must all be whole-run gates of the switch model's pairs, and among them
/// the event-switch pair's `key`; returns the keys that failed.
fn whole_failures_only(fails: &[Failure], key: &str, what: &str) -> Vec<String> {
    assert!(!fails.is_empty(), "{what}: not caught");
    for f in fails {
        assert!(
            f.pair.contains("switch") && f.quantity.starts_with("whole "),
            "{what}: a gate other than the switch model's whole-run ones failed: {f}"
        );
    }
    let quantity = key.strip_prefix("whole_").unwrap().replace('_', " ");
    let quantity = if quantity == "event time" {
        "event times".to_owned()
    } else {
        quantity.replace("omega ", "omega_")
    };
    assert!(
        fails
            .iter()
            .any(|f| f.pair == "event-switch"
                && f.quantity.starts_with(&format!("whole {quantity}"))),
        "{what}: event-switch {key} did not fail: {fails:?}"
    );
    fails.iter().map(|f| f.quantity.clone()).collect()
}

/// An offset of α, ω_u or ω_l alone on every sample after the window, three times the
/// gate plus what it measures unperturbed: that quantity's whole-run gate fails, and no
/// other gate (the window's are untouched).
#[test]
fn a_late_offset_in_each_quantity_fails_that_quantity_alone() {
    for r in results() {
        assert!(gate_scenario(r).1.is_empty(), "{}", r.scenario.name);
        for (i, key) in ["whole_alpha", "whole_omega_u", "whole_omega_l"]
            .into_iter()
            .enumerate()
        {
            let (gate, measured) = gate_and_measured(r, key);
            let mut p = r.clone();
            for s in switch_run(&mut p).samples.iter_mut() {
                if s.t > WINDOW_END {
                    s.x[i] += 3.0 * gate + measured;
                }
            }
            let fails = gate_scenario(&p).1;
            let what = format!("{} {key}", r.scenario.name);
            let q = whole_failures_only(&fails, key, &what);
            let name = key.strip_prefix("whole_").unwrap();
            assert!(
                q.iter().all(|q| q.starts_with(&format!("whole {name} "))),
                "{what}: {q:?}"
            );
        }
    }
}

/// A pure phase error after the window: from the first phase anchor after 20 s the switch
/// model's run lags by a drift growing linearly to three times the event gate plus its
/// measurement at the last anchor (what a period error of that size does; held after it, as
/// the alignment holds the shift), samples and events alike (`B(t − δ) ≈ B(t) − δ·f(B(t))`).
/// The alignment takes the lag out of the samples, so only the event times fail: the phase is
/// gated where it is defined, not excused.
#[test]
fn a_late_phase_drift_fails_the_event_times_alone() {
    for r in results() {
        let sc = &r.scenario;
        let (gate, measured) = gate_and_measured(r, "whole_event_time");
        let end_lag = 3.0 * gate + measured;
        let mut p = r.clone();
        let tr = switch_run(&mut p);
        let anchors: Vec<f64> = tr
            .events
            .iter()
            .filter(|e| e.t > WINDOW_END && is_anchor(e.kind))
            .map(|e| e.t)
            .collect();
        let (t_s, t_last) = (anchors[0], anchors[anchors.len() - 1]);
        let lag = |t: f64| end_lag * ((t.min(t_last) - t_s) / (t_last - t_s)).max(0.0);
        let band = SolverKind::SWITCH.info().stuck_band;
        for s in tr.samples.iter_mut() {
            let x = rotor_model::State::from_column_slice(s.x);
            let f = sc
                .model
                .rhs(&x, sc.u, sample_mode(&sc.model, &x, sc.u, band));
            let d = lag(s.t);
            for i in 0..3 {
                s.x[i] -= d * f[i];
            }
        }
        for e in tr.events.iter_mut() {
            e.t += lag(e.t);
        }
        let fails = gate_scenario(&p).1;
        let what = format!("{} late phase drift", sc.name);
        let q = whole_failures_only(&fails, "whole_event_time", &what);
        assert!(
            q.iter().all(|q| q.starts_with("whole event times")),
            "{what}: {q:?}"
        );
    }
}

/// End of the wrong stretch \[s\]: well before the fixtures' `steady_from` (100 s), so that
/// the steady state (a stable cycle, which forgets a perturbation but its phase) is the right
/// one again, and the steady gates cannot see what went wrong.
const WRONG_UNTIL: f64 = 60.0;

/// The switch model that goes wrong after the window, for a while: it runs to 20 s, continues
/// from its state there to 60 s with the motor's input off by a relative `EPS` (a small offset
/// of the upper disc's torque, as a wrong friction level would be), then on with the right
/// input. With `EPS = 0` the restarts alone must pass every gate (so what fails below is the
/// offset, not the restarts).
struct LateOffset<const PPB: u32>;

impl<const PPB: u32> LateOffset<PPB> {
    /// The relative offset of u on [20, 60] s: `PPB` parts per 10⁹.
    const EPS: f64 = PPB as f64 * 1e-9;
}

impl<const PPB: u32> Solver for LateOffset<PPB> {
    fn name(&self) -> &'static str {
        "switch"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        let inner = (SolverKind::SWITCH.info().make)();
        let dt = match scene.output {
            rotor_model::seam::Output::Grid { dt } => dt,
            _ => unreachable!("the comparison asks for a grid"),
        };
        let segments = [
            (0.0, WINDOW_END, scene.u),
            (WINDOW_END, WRONG_UNTIL, scene.u * (1.0 + Self::EPS)),
            (WRONG_UNTIL, scene.t_end, scene.u),
        ];
        let mut out: Option<Trajectory> = None;
        for (t0, t1, u) in segments {
            let part = inner.simulate(
                model,
                &Scene {
                    u,
                    x0: out.as_ref().map_or(scene.x0.clone(), |o| o.x_final.clone()),
                    t_end: t1 - t0,
                    // Metrics asked in every part (so that the maxima of ω are reported);
                    // the last part's over the scene's window are the run's.
                    metrics_from: scene.metrics_from.map(|m| {
                        if m - t0 < t1 - t0 {
                            (m - t0).max(0.0)
                        } else {
                            0.0
                        }
                    }),
                    ..scene.clone()
                },
            )?;
            let Some(o) = out.as_mut() else {
                out = Some(part);
                continue;
            };
            // One grid, on the times the whole run would have (k·dt, not t0 + j·dt, which
            // differ in the last bits); the part's first sample is the previous one's last.
            for s in part.samples.iter().skip(1) {
                let k = o.samples.len();
                o.samples.push((k as f64 * dt).min(scene.t_end), s.x);
            }
            o.events
                .extend(part.events.iter().map(|e| rotor_model::seam::Event {
                    t: e.t + t0,
                    ..e.clone()
                }));
            o.t_final = t1;
            o.x_final = part.x_final;
            o.mode_final = part.mode_final;
            o.metrics = part.metrics;
        }
        Ok(out.expect("three parts"))
    }
}

/// The switch model's entry with another solver behind it (same name, so the same gates).
fn entry(make: fn() -> Box<dyn Solver>) -> SolverKind {
    let s = SolverKind::SWITCH.info();
    SolverKind(Box::leak(Box::new(rotor_analysis::solvers::SolverInfo {
        name: s.name,
        label: s.label,
        knob: s.knob,
        comparison: s.comparison,
        default: s.default,
        ladder: s.ladder,
        style: s.style,
        stuck_band: s.stuck_band,
        steady_agreement: s.steady_agreement,
        make,
        chain: None,
    })))
}

/// The late offset through the ordinary runner: the window's gates and the steady state's
/// pass, and before the whole-run gates so did the solver; now the whole-run gates fail
/// (event times and ω_l at least). The restarts without the offset pass every gate.
#[test]
fn a_solver_wrong_after_the_window_fails_the_whole_run_gates() {
    let sc = scenario("t1-u1.5-rest");
    let base = &results()[0];
    // Only the switch model runs again: the reference's and Moreau-Jean's runs are reused.
    let with = |make: fn() -> Box<dyn Solver>| {
        let mut all = base.clone();
        let late = run_scenario_with(&sc, &[entry(make)]);
        *switch_run(&mut all) = late.runs[0].result.clone().unwrap();
        all
    };
    let control = gate_scenario(&with(|| Box::new(LateOffset::<0>))).1;
    assert!(control.is_empty(), "the restart alone fails: {control:?}");
    let fails = gate_scenario(&with(|| Box::new(LateOffset::<1000>))).1;
    for f in &fails {
        eprintln!("{f}");
    }
    assert!(
        fails.iter().all(|f| f.quantity.starts_with("whole ")),
        "only the whole-run gates can see it: {fails:?}"
    );
    for q in ["whole event times", "whole omega_l"] {
        assert!(
            fails
                .iter()
                .any(|f| f.pair == "event-switch" && f.quantity.starts_with(q)),
            "{q} not caught: {fails:?}"
        );
    }
}

/// The report's whole-run table has a row per scenario and pair of solvers, with the phase
/// (event times), the aligned differences and those at equal times.
#[test]
fn the_report_shows_the_whole_run_of_every_pair() {
    let md = rotor_harness::compare::report::whole_run_table(results());
    for name in ["t1-u1.5-rest", "t1-u2.5-eq-pert"] {
        for pair in ["event-switch", "event-moreau", "switch-moreau"] {
            let row = md
                .lines()
                .find(|l| l.starts_with(&format!("| {name} | {pair} |")))
                .unwrap_or_else(|| panic!("{name} {pair}: no row in\n{md}"));
            assert!(row.contains("(switches and maxima)"), "{row}");
            assert_eq!(row.matches("e-").count(), 7, "{row}");
        }
    }
}
