//! CONTRIBUTING.md's "add a solver", followed: a fourth solver joins the comparison with its
//! own code (here a module standing in for its crate), one [`SolverInfo`] entry, and its
//! tolerances in a scenario file. Nothing else in the workspace is edited: the runner, the
//! gates, the snapshot and the report take it as they take the other three; so do the stress
//! cases and the steady-state probes.
//!
//! The solver is explicit Euler on the switch model (band η): first order, deliberately
//! crude, with a coarse gate measured on the scenario.

use rotor_analysis::solvers::registry::Style;
use rotor_analysis::solvers::{Knob, SolverInfo, SolverKind, load_scenario_for, run_scenario_with};
use rotor_harness::compare::gate::gate_scenario;
use rotor_harness::compare::margins::margins;
use rotor_harness::compare::report::{scenario_csv, scenario_svg};
use rotor_harness::compare::snapshot::snapshot;
use rotor_harness::compare::stress::{Gate, Measure, StressRow, cases_for, run_case};

/// The solver's "crate".
mod euler {
    use rotor_model::seam::{
        Event, EventKind, EventRef, Integration, Recorder, Scene, SolveError, Solver, Stats,
        Trajectory, check_finite,
    };
    use rotor_model::{Disc, DiscMode, Mode, Model, State};

    /// Half-width of the stick band [rad/s].
    const ETA: f64 = 1e-6;

    /// Explicit Euler on the switch model: a disc whose ω is within the band, or crossed 0 in
    /// the step, and whose applied torque lies in its stick interval is held at ω = 0;
    /// otherwise it slips on the smooth law. Events: stick onsets and exits (mode changes between steps), extrema of ω
    /// (sign changes of its increment).
    #[derive(Debug, Default)]
    pub struct EulerSolver;

    struct Run<'a> {
        model: &'a Model,
        u: f64,
        h: f64,
        t_end: f64,
        t: f64,
        x: State,
        mode: Mode,
        dw: [f64; 2],
        steps: u64,
    }

    impl Run<'_> {
        /// The mode at `x` reached from `prev`, with the band: within it (or across 0) and
        /// inside the stick interval, stuck.
        fn mode_at(&self, prev: &State, x: &mut State) -> Mode {
            let mut m = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
            for d in Disc::BOTH {
                let w = x[d.index()];
                let f = self.model.friction(d);
                let (lo, hi) = f.static_interval();
                let ta = self.model.applied_torque(d, x, self.u);
                let near = w.abs() <= ETA || w * prev[d.index()] < 0.0;
                let dm = if near && f.is_set_valued() && lo <= ta && ta <= hi {
                    x[d.index()] = 0.0;
                    DiscMode::Stick
                } else if near {
                    DiscMode::slip_of(ta - if ta > hi { hi } else { lo })
                } else {
                    DiscMode::slip_of(w)
                };
                m.set(d, dm);
            }
            m
        }
    }

    impl Integration for Run<'_> {
        type Checkpoint = (f64, State, Mode, [f64; 2]);

        fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
            while self.t < self.t_end {
                let h = self.h.min(self.t_end - self.t);
                let f = self.model.rhs(&self.x, self.u, self.mode);
                let (t0, x0) = (self.t, self.x);
                let mut x1 = x0 + f * h;
                let t1 = t0 + h;
                check_finite(t1, x1.as_slice())?;
                let mode = self.mode_at(&x0, &mut x1);
                self.steps += 1;
                // The step's interpolant, written into the recorder's slice: linear.
                rec.step(t0, t1, x1.as_slice(), |t, out| {
                    let s = (t - t0) / h;
                    for ((o, a), b) in out.iter_mut().zip(&x0).zip(&x1) {
                        *o = a + (b - a) * s;
                    }
                });
                for (i, d) in Disc::BOTH.into_iter().enumerate() {
                    let (a, b) = (self.mode.of(d), mode.of(d));
                    let kind = match (a, b) {
                        (DiscMode::Stick, DiscMode::Stick) => None,
                        (DiscMode::Stick, _) => Some(EventKind::StickEnd(d)),
                        (_, DiscMode::Stick) => Some(EventKind::StickStart(d)),
                        (a, b) if a != b => Some(EventKind::Reversal(d)),
                        _ => None,
                    };
                    let dw = x1[d.index()] - x0[d.index()];
                    let turn = if self.dw[i] > 0.0 && dw <= 0.0 {
                        Some(EventKind::Max(d))
                    } else if self.dw[i] < 0.0 && dw >= 0.0 {
                        Some(EventKind::Min(d))
                    } else {
                        None
                    };
                    self.dw[i] = if b == DiscMode::Stick { 0.0 } else { dw };
                    let wanted = if rec.wants_extrema() { turn } else { None };
                    for kind in [kind, wanted.filter(|_| kind.is_none())]
                        .into_iter()
                        .flatten()
                    {
                        rec.event(EventRef {
                            t: t0,
                            x: x0.as_slice(),
                            kind,
                        });
                    }
                }
                (self.t, self.x, self.mode) = (t1, x1, mode);
                if rec.halted() {
                    break;
                }
            }
            Ok(())
        }

        fn checkpoint(&self, _anchor: &Event) -> (f64, State, Mode, [f64; 2]) {
            (self.t, self.x, self.mode, self.dw)
        }

        fn restore(&mut self, (t, x, mode, dw): (f64, State, Mode, [f64; 2])) {
            (self.t, self.x, self.mode, self.dw) = (t, x, mode, dw);
        }

        fn shift(&mut self, _anchor: &Event, dt: f64) {
            self.t += dt;
        }
    }

    impl Solver for EulerSolver {
        fn name(&self) -> &'static str {
            "euler"
        }

        fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
            scene.validate_for(model)?;
            let h = scene.checked_step()?;
            let start = scene.x0_state()?;
            let mut run = Run {
                model,
                u: scene.u,
                h,
                t_end: scene.t_end,
                t: 0.0,
                x: start,
                mode: model.mode_at(&start, scene.u),
                dw: [0.0; 2],
                steps: 0,
            };
            let mut x0 = start;
            run.mode = run.mode_at(&start, &mut x0);
            run.x = x0;
            let mut rec = Recorder::new(scene, x0.as_slice(), h, 3.0);
            rec.drive(&mut run)?;
            let stats = Stats {
                steps: run.steps,
                rhs_evals: run.steps,
                ..Stats::default()
            };
            Ok(rec.finish(run.t, run.x.as_slice(), run.mode, stats))
        }
    }
}

/// The one entry.
static EULER: SolverInfo = SolverInfo {
    name: "euler",
    label: "explicit Euler",
    knob: Knob::Step,
    comparison: 1e-4,
    default: 1e-4,
    ladder: &[1e-3, 1e-4],
    style: Style {
        color: "#1a9641",
        dash: Some("1 3"),
        width: 1.5,
    },
    // A stuck disc is put at ω = 0 (see the module above).
    stuck_band: 0.0,
    // First order at h = 1e-4: its cycle metrics differ from the reference's by up to
    // 1.2e-4 (the gates below); 1e-3 is 8x that, and still 2x below the 2.4e-3 that tells
    // Table 1's stable cycle from the unstable one next to its fold.
    steady_agreement: 1e-3,
    make: || Box::new(euler::EulerSolver),
    // The rig's two discs only.
    chain: None,
};

/// The scenario's tolerances for the new pairs, by the fixtures' rule: each about 5x the
/// difference measured on this scenario at h = 1e-4 (first order: O(h) differences). The
/// reference's pair gates everything; the pairs with the other two solvers the whole run.
const EULER_TOLERANCES: &str = "
[tolerance.event-euler]
# Explicit Euler on the switch model, h = 1e-4, band 1e-6: first order.
transient_max = 4e-2      # measured 7.2e-03 rad/s, margin 5.5x
transient_rms = 9e-3      # measured 1.6e-03 rad/s, margin 5.5x
event_time = 7e-3         # measured 1.4e-03 s, margin 5.2x (9 stick events)
period_rel = 4e-4         # measured 7.5e-05 relative, margin 5.4x
omega_l_max_rel = 6e-4    # measured 1.2e-04 relative, margin 5.1x
omega_l_min = 0.0     # exact: omega_l min is 0, the lower disc sticks each cycle
omega_u_max_rel = 6e-5    # measured 1.1e-05 relative, margin 5.7x
omega_u_min_rel = 2e-5    # measured 2.8e-06 relative, margin 7.2x
stick_time = 3e-3         # measured 4.3e-04 s, margin 7.0x
steady_abs = 1e-12        # rounding floor of the relative gates: |difference| <= 1e-12 passes
# Whole run (rotor_harness::compare::whole), phase-aligned: Euler's shape and phase errors.
whole_alpha = 5e-3        # measured 9.4e-04 rad, margin 5.3x
whole_omega_u = 3e-3      # measured 4.5e-04 rad/s, margin 6.7x
whole_omega_l = 1e-2      # measured 2.0e-03 rad/s, margin 5.1x
whole_event_time = 8e-2   # measured 1.5e-02 s over 130 switches and maxima, margin 5.4x

# The new solver against each of the other two, over the whole run only: its own error
# dominates, so the same measurements.
[tolerance.switch-euler]
whole_alpha = 5e-3        # measured 9.4e-04 rad, margin 5.3x
whole_omega_u = 3e-3      # measured 4.5e-04 rad/s, margin 6.7x
whole_omega_l = 1e-2      # measured 2.0e-03 rad/s, margin 5.1x
whole_event_time = 8e-2   # measured 1.5e-02 s over 130 switches and maxima, margin 5.4x

[tolerance.moreau-euler]
whole_alpha = 5e-3        # measured 9.4e-04 rad, margin 5.3x
whole_omega_u = 3e-3      # measured 4.5e-04 rad/s, margin 6.7x
whole_omega_l = 1e-2      # measured 2.0e-03 rad/s, margin 5.1x
whole_event_time = 8e-2   # measured 1.5e-02 s over 130 switches and maxima, margin 5.4x
";

#[test]
fn a_fourth_solver_needs_its_crate_one_entry_and_its_tolerances() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let text = std::fs::read_to_string(root.join("scenarios/t1-u1.5-rest.toml")).unwrap();
    let dir = rotor_testkit::tmp_dir("rotor-fourth-solver");
    std::fs::copy(root.join("params/table1.toml"), dir.join("table1.toml")).unwrap();
    let file = dir.join("t1-u1.5-rest.toml");
    let text = text.replace("\"../params/table1.toml\"", "\"table1.toml\"");
    std::fs::write(&file, format!("{text}{EULER_TOLERANCES}")).unwrap();

    let solvers = [
        SolverKind::EVENT,
        SolverKind::SWITCH,
        SolverKind::MOREAU,
        SolverKind(&EULER),
    ];
    // The three solvers' loader refuses the new pair; with the fourth one it loads.
    let e = rotor_analysis::solvers::load_scenario(&file)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("event-euler") && e.contains("unknown solver pair"),
        "{e}"
    );
    let sc = load_scenario_for(&file, &solvers).unwrap();

    let r = run_scenario_with(&sc, &solvers);
    let (gates, fails) = gate_scenario(&r);
    for g in &gates {
        for m in &g.measured {
            println!(
                "{} {}: {:.2e} (gate {:.0e})",
                g.pair, m.quantity, m.diff, m.tol
            );
        }
    }
    assert!(fails.is_empty(), "{fails:#?}");
    // Its gates follow the fixtures' rule like the others (`rotor_harness::compare::margins`).
    let outside: Vec<String> = margins(&r).iter().filter_map(|m| m.violation()).collect();
    assert!(outside.is_empty(), "{outside:#?}");
    assert_eq!(
        gates.len(),
        6,
        "event-switch, event-moreau, event-euler, and switch-moreau, switch-euler, moreau-euler"
    );
    assert!(
        gates
            .iter()
            .any(|g| g.pair == "event-euler" && g.measured.len() == 9 + 4)
    );
    assert!(
        gates
            .iter()
            .any(|g| g.pair == "moreau-euler" && g.measured.len() == 4)
    );
    // Its negative control: twice its period gate moved fails.
    let mut p = r.clone();
    let run = p
        .runs
        .iter_mut()
        .find(|run| run.kind.name() == "euler")
        .unwrap();
    if let Some(rotor_model::seam::SteadyState::LimitCycle { period, .. }) =
        run.result.as_mut().unwrap().metrics.as_mut()
    {
        *period *= 1.0 + 8e-4;
    }
    assert!(gate_scenario(&p).1.iter().any(|f| f.pair == "event-euler"));
    // The snapshot, the CSV and the plot take it like the others.
    let snap = snapshot(&r);
    assert_eq!(snap.solvers.len(), 4);
    assert!(snap.differences.contains_key("event-euler"));
    assert!(scenario_csv(&r).starts_with("t,alpha_event,omega_u_event,omega_l_event,alpha_switch"));
    assert!(
        scenario_csv(&r)
            .lines()
            .next()
            .unwrap()
            .ends_with(",alpha_euler,omega_u_euler,omega_l_euler")
    );
    // Its figure: α, ω_u and ω_l overlaid over the whole run, each with a panel of every
    // solver's difference from the reference under it; the fourth solver in all six legends.
    let svg = scenario_svg(&r);
    assert_eq!(svg.matches(", difference from event-driven").count(), 3);
    assert_eq!(svg.matches(">explicit Euler (h 1e-4)</text>").count(), 6);
    std::fs::remove_dir_all(&dir).ok();
}

/// The stress cases and the steady-state probes take the fourth solver without an edit: one
/// row per stress case at its comparison setting (the mirror cases gated exactly, the others
/// reported: a fixed-step newcomer has no a-priori bound until its order and constant are
/// measured), and the probes a fixed-step solver gets, judged against the continuation with
/// the agreement its entry states.
#[test]
fn a_fourth_solver_gets_the_stress_cases_and_the_probes() {
    use rayon::prelude::*;
    let euler = SolverKind(&EULER);
    let cases = cases_for(false, &[SolverKind::EVENT, euler]);
    for c in &cases {
        let names: Vec<&str> = c.settings.iter().map(|s| s.kind.name()).collect();
        assert_eq!(
            names.iter().filter(|&&n| n == "euler").count(),
            1,
            "{}: {names:?}",
            c.name
        );
        assert!(
            !names.contains(&"switch") && !names.contains(&"moreau"),
            "{}: solvers not asked for are left out: {names:?}",
            c.name
        );
    }
    let rows: Vec<StressRow> = cases
        .par_iter()
        .flat_map(run_case)
        .filter(|r| r.solver.name() == "euler")
        .collect();
    println!(
        "{}",
        rotor_harness::compare::stress::stress_table_markdown(&rows)
    );
    assert_eq!(rows.len(), cases.len());
    for r in &rows {
        assert!(
            r.passes(),
            "{} / {}: {} ({:?})",
            r.case,
            r.setting,
            r.outcome,
            r.agreement
        );
    }
    // The mirror symmetry holds for it to the bit, as for every solver of the project.
    let mirror: Vec<&StressRow> = rows
        .iter()
        .filter(|r| matches!(r.gate_kind, Gate::Exact))
        .collect();
    assert_eq!(mirror.len(), 2);
    assert!(mirror.iter().all(|r| r.agreement == Some(0.0)));
    // The others are measured against the reference (or the exact solution), though not gated.
    for r in rows.iter().filter(|r| !matches!(r.gate_kind, Gate::Exact)) {
        assert!(matches!(r.gate_kind, Gate::Unresolved(_)), "{}", r.case);
        let measured = !matches!(
            cases.iter().find(|c| c.name == r.case).unwrap().measure,
            Measure::Mirror { .. }
        );
        assert!(
            measured && r.agreement.is_some(),
            "{}: not measured",
            r.case
        );
    }

    // The probes: Table 1's special points, from rest at ±1e-3 V (a fixed-step solver's share
    // in the fast form), each answer judged against the continuation with the agreement the
    // entry states.
    use rotor_analysis::steady::probes::{self, Verdict};
    let m = rotor_model::Model::table1();
    let d = rotor_analysis::bifurcation::diagram(
        &m,
        &rotor_analysis::bifurcation::DiagramOptions::default(),
    )
    .unwrap();
    let selected = probes::selection_for(&d, false, &[euler]);
    assert_eq!(selected.len(), 2 * probes::probe_points(&d).len());
    assert!(selected.iter().all(|p| p.kind.name() == "euler"));
    let rows = probes::run_set("table1", &m, &d, &selected, |jobs, f| {
        jobs.par_iter().map(f).collect()
    });
    println!("{}", probes::probe_table_markdown(&rows, &[euler]));
    for r in &rows {
        println!(
            "{} {:+e} V: {:?}",
            r.probe.point.label, r.probe.offset, r.verdict
        );
    }
    // Away from the delicate points it answers with the attractor: at the stick limit on
    // both sides, and below the first Hopf point (the focus).
    let agrees = |label: &str, offset: f64| {
        rows.iter().any(|r| {
            r.probe.point.label == label
                && r.probe.offset == offset
                && r.probe.point.u < 1.0
                && matches!(r.verdict, Verdict::Agrees { .. })
        })
    };
    assert!(agrees("stick_limit", -1e-3) && agrees("stick_limit", 1e-3) && agrees("hopf", -1e-3));
    // Near the Hopf points, the grazing and the fold a first-order solver at h = 1e-4 is not
    // good enough, and the probes say so: the cycle it finds is refuted by the model's own
    // equations, or differs from the continuation's by more than its agreement. The probes
    // are a test a crude solver can fail, not a formality.
    let caught: Vec<&Verdict> = rows
        .iter()
        .map(|r| &r.verdict)
        .filter(|v| !v.acceptable())
        .collect();
    assert!(!caught.is_empty());
    for v in caught {
        match v {
            Verdict::Wrong { .. } => {}
            Verdict::Failed { error } => assert!(
                error.contains("refuted by the model's own equations"),
                "{error}"
            ),
            other => panic!("not a verdict on the answer: {other:?}"),
        }
    }
}
