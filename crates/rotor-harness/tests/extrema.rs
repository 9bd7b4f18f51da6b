//! Extrema of ω while settling onto a stable slip equilibrium (Table 1, u = 0.3 V, from
//! rest), in every solver.
//!
//! The velocities oscillate about the equilibrium and decay with the rate σ of its slowest
//! eigenvalue (computed here from the model's linearisation, independently of any solver).
//! The initial amplitude is below 1 rad/s, so after ln(10¹⁶)/σ ≈ 98 s it is below rounding:
//! a turn reported there is noise, not dynamics. The adaptive solvers report an extremum
//! only when ω moved by more than 10 tolerances since the one before (their resolution); the
//! Moreau–Jean extrema are sign changes of the discrete acceleration, whose rounding noise
//! must not produce them either.

use rotor_analysis::solvers::{SOLVERS, SolverKind};
use rotor_model::seam::{Accuracy, EventKind, Output, Scene};
use rotor_model::{Disc, Model};

#[test]
fn no_solver_reports_turns_below_its_resolution() {
    let m = Model::table1();
    let u = 0.3;
    let eq = m.slip_equilibria(u);
    assert_eq!(eq.len(), 1, "one slip equilibrium at 0.3 V");
    let sigma = m
        .equilibrium_eigenvalues(&eq[0])
        .iter()
        .map(|l| -l.re)
        .fold(f64::INFINITY, f64::min);
    assert!(sigma > 0.0, "stable: σ = {sigma}");
    let t_noise = 16.0 * 10f64.ln() / sigma;
    assert!(
        t_noise < 100.0,
        "decay too slow for a 200 s run: {t_noise} s"
    );
    for kind in SOLVERS {
        // The comparison's settings: event tol 1e-12, switch tol 1e-10, Moreau h = 1e-3.
        let accuracy = match kind.name() {
            "event" => Accuracy::Tol(1e-12),
            "switch" => Accuracy::Tol(1e-10),
            "moreau" => Accuracy::Step(1e-3),
            other => panic!("no setting for {other}"),
        };
        let s = Scene {
            u,
            input: None,
            x0: vec![0.0; 3],
            t_end: 200.0,
            accuracy,
            output: Output::Events,
            metrics_from: Some(100.0),
        };
        let tr = kind.solver().simulate(&m, &s).unwrap();
        let ext: Vec<(f64, Disc, f64)> = tr
            .events
            .iter()
            .filter_map(|e| match e.kind {
                EventKind::Max(d) | EventKind::Min(d) => Some((e.t, d, e.x[d.index()])),
                _ => None,
            })
            .collect();
        let late: Vec<_> = ext.iter().filter(|e| e.0 > t_noise).collect();
        assert!(
            late.is_empty(),
            "{kind:?}: extrema at rounding level: {late:?}"
        );
        // Measured: 55 (event), 44 (switch), 41 (Moreau) resolved turns before t_noise.
        assert!(ext.len() > 10, "{kind:?}: {} extrema", ext.len());
        if kind == SolverKind::MOREAU {
            continue;
        }
        for d in Disc::BOTH {
            let w: Vec<f64> = ext.iter().filter(|e| e.1 == d).map(|e| e.2).collect();
            for p in w.windows(2) {
                assert!(
                    (p[1] - p[0]).abs() > 10.0 * s.tol() * (1.0 + p[1].abs()),
                    "{kind:?}, {d:?}: a turn of {:e} rad/s reported",
                    (p[1] - p[0]).abs()
                );
            }
        }
    }
}
