//! The peers, when installed (where they are not, these tests return after saying so, unless
//! `ROTOR_REQUIRE_PEERS=1` makes a missing peer a failure, as `.ci/run` does after installing
//! both). A peer that runs must compute the reference's answer, else
//! its ratio is meaningless.

use rotor_bench::{BenchOptions, SolverKind, peer_available, run};

/// Whether the peer can be tested; a missing peer fails when `ROTOR_REQUIRE_PEERS=1`.
fn peer_present(python: &str, module: &str) -> bool {
    match peer_available(python, module) {
        Ok(()) => true,
        Err(why) if std::env::var("ROTOR_REQUIRE_PEERS").as_deref() == Ok("1") => {
            panic!("ROTOR_REQUIRE_PEERS=1 but {module} is missing: {why}")
        }
        Err(why) => {
            eprintln!("{module} peer not tested: {why}");
            false
        }
    }
}

fn options() -> BenchOptions {
    let mut o = BenchOptions::quick();
    o.set_ladder(SolverKind::EVENT, vec![1e-6, 1e-8, 1e-10]);
    o.set_ladder(SolverKind::SWITCH, vec![1e-6]);
    o.set_ladder(SolverKind::MOREAU, vec![1e-2]);
    o.output_levels = false;
    o.repeats = 1;
    o.time_budget = 0.0;
    o.peers.scipy = false;
    o.peers.siconos = false;
    o
}

/// scipy's `solve_ivp` (DOP853, rtol = atol = 1e-10) agrees with the event-driven reference
/// within the scenario's event-switch gate, and gets ratios at equal error.
#[test]
fn scipy_peer_agrees_with_the_reference() {
    let o = options();
    if !peer_present(&o.peers.python, "scipy") {
        return;
    }
    let o = BenchOptions {
        peers: rotor_bench::PeerOptions {
            scipy: true,
            scipy_tols: vec![1e-6, 1e-10],
            ..o.peers.clone()
        },
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = &r.peers[0];
    assert_eq!(p.name, "scipy");
    assert_eq!(p.status.as_str(), "ran", "{:?}", p.reason);
    assert_eq!(p.points.len(), 2);
    let a = p.agreement.as_ref().expect("the scenario has gates");
    assert!(a.agrees, "{a:?}");
    // The tighter tolerance is more accurate.
    let e: Vec<f64> = p
        .points
        .iter()
        .map(|q| q.errors.transient_max.unwrap())
        .collect();
    assert!(e[1] < e[0], "{e:?}");
    assert!(!p.ratios.is_empty());
    assert!(
        p.ratios
            .iter()
            .all(|q| q.ratio.is_finite() && q.ratio > 0.0)
    );
}

/// Siconos' MoreauJeanOSI at h = 1e-3 agrees with the reference within the scenario's
/// event-moreau gate (the gate's setting), and gets a per-step comparison with rotor-moreau
/// at the same h, whose answer is the same scheme's.
#[test]
fn siconos_peer_agrees_with_the_reference() {
    let o = options();
    if !peer_present(&o.peers.siconos_python, "siconos.kernel") {
        return;
    }
    let o = BenchOptions {
        peers: rotor_bench::PeerOptions {
            siconos: true,
            siconos_hs: vec![1e-3],
            ..o.peers.clone()
        },
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = &r.peers[1];
    assert_eq!(p.name, "siconos");
    assert_eq!(p.status.as_str(), "ran", "{:?}", p.reason);
    let a = p.agreement.as_ref().expect("the scenario has gates");
    assert!(a.agrees, "{a:?}");
    assert_eq!(p.per_step.len(), 1);
    let s = &p.per_step[0];
    assert!(s.ratio.is_finite() && s.ratio > 0.0);
    // Same scheme (θ = 1/2, implicit level, exact one-step problem) at the same h: the
    // steady errors agree to within 10% (measured: equal to two digits).
    let (pe, me) = (
        s.peer_errors.steady_rel.unwrap(),
        s.moreau_errors.steady_rel.unwrap(),
    );
    assert!((pe - me).abs() < 0.1 * me, "siconos {pe} vs moreau {me}");
}
