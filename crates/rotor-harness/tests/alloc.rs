//! No heap allocation per step: a final-state run (with or without metrics) over T and over
//! 10·T makes the same number of allocations, for each solver, and a metrics-only run as many. Ten times the steps with the same count
//! means the count does not depend on the number of steps: zero per step (and per event:
//! the 1.5 V stick-slip scene has about 2 stick phases per 4.6 s cycle, so 10·T also has
//! ten times the events).
//!
//! The counting allocator is `allocation-counter`'s (it counts this thread's allocations
//! only; the solvers are single-threaded).

use rotor_event::EventSolver;
use std::path::Path;

use rotor_model::seam::{Accuracy, Output, Scene, Solver};
use rotor_model::{Model, Params};
use rotor_moreau::MoreauSolver;
use rotor_switch::SwitchSolver;

// The crate replaces the global allocator; naming it here links it into this test binary.
use allocation_counter::measure;

fn scene(t_end: f64, metrics: bool) -> Scene {
    Scene {
        u: 1.5,
        input: None,
        x0: vec![0.0; 3],
        t_end,
        // Moreau–Jean takes the default step, 1e-3.
        accuracy: Accuracy::Tol(1e-10),
        output: Output::Final,
        metrics_from: metrics.then_some(0.5 * t_end),
    }
}

/// Table 1, and the Stribeck set (both discs stuck at the start: the upper disc's stick
/// phase and break-away take other code paths).
fn models() -> [(&'static str, Model); 2] {
    let st = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/params/stribeck.toml");
    [
        ("table1", Model::table1()),
        ("stribeck", Model::new(Params::from_file(&st).unwrap())),
    ]
}

/// Allocations of one run (after a warm-up run, so that one-time lazy initialisation is not
/// counted), and the run's step count.
fn allocations(solver: &dyn Solver, m: &Model, s: &Scene) -> (u64, u64) {
    solver.simulate(m, s).unwrap();
    let mut steps = 0;
    let info = measure(|| {
        let tr = solver.simulate(m, s).unwrap();
        steps = tr.stats.steps;
    });
    (info.count_total, steps)
}

fn check(solver: &dyn Solver) {
    // T = 20 s holds ~4 stick-slip cycles from rest; 10·T = 200 s.
    for (set, m) in models() {
        for metrics in [false, true] {
            let (a1, n1) = allocations(solver, &m, &scene(20.0, metrics));
            let (a10, n10) = allocations(solver, &m, &scene(200.0, metrics));
            eprintln!(
                "{} {set} (metrics {metrics}): {a1} allocations / {n1} steps; {a10} / {n10}",
                solver.name()
            );
            assert!(
                n10 >= 5 * n1,
                "{}: the long run must take many more steps ({n1} vs {n10})",
                solver.name()
            );
            assert_eq!(
                a1,
                a10,
                "{} {set} (metrics {metrics}): {a1} allocations over {n1} steps but {a10} \
                 over {n10}",
                solver.name()
            );
            if metrics {
                // Output::Metrics skips most of the 200 s, so it proves nothing per step by
                // itself; skipping (state on the stack) must allocate no more than the run.
                let sm = Scene {
                    output: Output::Metrics,
                    ..scene(200.0, true)
                };
                let (am, nm) = allocations(solver, &m, &sm);
                assert!(nm < n10, "{}: the metrics-only run skips", solver.name());
                assert_eq!(
                    am,
                    a10,
                    "{} {set}: Output::Metrics allocates",
                    solver.name()
                );
            }
        }
    }
}

#[test]
fn event_solver_allocates_nothing_per_step() {
    check(&EventSolver::default());
}

#[test]
fn switch_solver_allocates_nothing_per_step() {
    check(&SwitchSolver::default());
}

#[test]
fn moreau_solver_allocates_nothing_per_step() {
    check(&MoreauSolver::default());
}

/// The counter does count: a run that keeps a growing trace allocates more over 10·T
/// (so equal counts above are not an artefact of a counter that sees nothing).
#[test]
fn the_counter_sees_trace_growth() {
    let grid = |t_end| Scene {
        output: Output::Steps,
        ..scene(t_end, false)
    };
    let s = EventSolver::default();
    let m = Model::table1();
    let (a1, _) = allocations(&s, &m, &grid(20.0));
    let (a10, _) = allocations(&s, &m, &grid(200.0));
    assert!(a1 > 0 && a10 > a1, "{a1} vs {a10}");
}
