//! The peers and external clients through the job-file protocol. The peers are tested when
//! installed (where they are not, these tests return after saying so, unless
//! `ROTOR_REQUIRE_PEERS=1` makes a missing peer a failure, as `.ci/run` does after installing
//! both). A peer that runs must compute the reference's answer, else its ratio is
//! meaningless.

use rotor_harness::bench::{
    BenchOptions, ClientReport, ClientSpec, ClientStatus, FailureKind, SolverKind, peer_available,
    run,
};

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
    o.set_ladder(SolverKind::MOREAU, vec![1e-2, 1e-3]);
    o.output_levels = false;
    o.repeats = 1;
    o.time_budget = 0.0;
    o.peers.scipy = false;
    o.peers.siconos = false;
    o
}

fn client<'a>(r: &'a rotor_harness::bench::BenchReport, name: &str) -> &'a ClientReport {
    r.clients.iter().find(|c| c.name == name).unwrap()
}

/// scipy's `solve_ivp` (DOP853, rtol = atol = 1e-11), through the protocol, passes the
/// scenario's strict gate, is more accurate at the tighter tolerance, and gets ratios at
/// equal error, in-process and whole-process.
#[test]
fn scipy_peer_passes_the_strict_gate_through_the_protocol() {
    let o = options();
    if !peer_present(&o.peers.python, "scipy") {
        return;
    }
    let o = BenchOptions {
        peers: rotor_harness::bench::PeerOptions {
            scipy: true,
            scipy_tols: vec![1e-6, 1e-11],
            ..o.peers.clone()
        },
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = client(&r, "scipy");
    assert_eq!(p.status, ClientStatus::Ran, "{:?}", p.reason);
    let pts = &p.scenes[0].points;
    assert_eq!(pts.len(), 2);
    assert_eq!(pts[1].passes_strict, Some(true), "{:?}", pts[1]);
    let e: Vec<f64> = pts
        .iter()
        .map(|q| q.errors.transient_max.unwrap())
        .collect();
    assert!(e[1] < e[0], "{e:?}");
    let ratios = &p.scenes[0].ratios;
    for time in ["in_process", "whole_process"] {
        assert!(
            ratios
                .iter()
                .any(|q| q.time == time && q.ratio.is_finite() && q.ratio > 0.0),
            "{time}: {ratios:?}"
        );
    }
    assert!(p.overhead.is_some_and(|o| o.process_s.is_some()));
}

/// Siconos' MoreauJeanOSI at h = 1e-3 passes the scenario's loose gate (its gate is sized for
/// this scheme at this step), and gets a per-step comparison with rotor-moreau at the same h,
/// whose answer is the same scheme's.
#[test]
fn siconos_peer_passes_the_loose_gate_through_the_protocol() {
    let o = options();
    if !peer_present(&o.peers.siconos_python, "siconos.kernel") {
        return;
    }
    let o = BenchOptions {
        peers: rotor_harness::bench::PeerOptions {
            siconos: true,
            siconos_hs: vec![1e-3],
            ..o.peers.clone()
        },
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = client(&r, "siconos");
    assert_eq!(p.status, ClientStatus::Ran, "{:?}", p.reason);
    assert_eq!(p.scenes[0].points[0].passes_loose, Some(true));
    assert_eq!(p.scenes[0].per_step.len(), 1);
    let s = &p.scenes[0].per_step[0];
    assert!(s.ratio.is_finite() && s.ratio > 0.0);
    // Same scheme (θ = 1/2, implicit level, exact one-step problem) at the same h: the
    // steady errors agree to within 10% (measured: equal to two digits).
    let (pe, me) = (
        s.client_errors.steady_rel.unwrap(),
        s.moreau_errors.steady_rel.unwrap(),
    );
    assert!((pe - me).abs() < 0.1 * me, "siconos {pe} vs moreau {me}");
}

/// `rotor bench --external` with a correct, a hanging and a crashing client finishes: the
/// correct one (the minimal client of BENCHMARK.md) is placed and passes the strict gate;
/// the hanging one is killed at the timeout and its tighter settings are not run; the
/// crashing one is recorded as a crash with its signal.
#[test]
fn external_clients_correct_hanging_and_crashing() {
    let o = options();
    if !peer_present(&o.peers.python, "scipy") {
        return;
    }
    let root = rotor_harness::bench::workspace_root();
    let minimal = root.join("bench/clients/minimal.py");
    let spec = |s: &str| ClientSpec::parse(s, &[]).unwrap();
    let o = BenchOptions {
        clients: vec![
            spec(&format!("minimal=python3 {}", minimal.display())),
            spec("hangs=sh -c 'sleep 60'"),
            spec("crashes=sh -c 'kill -SEGV $$'"),
        ],
        client_tols: vec![1e-6, 1e-10],
        // The minimal client takes 1.0 s here unloaded (python start, scipy import, 0.2 s
        // solve); with both cores busy with other tests and a cold cache after the install it
        // went past 2 s once in CI. 10 s leaves it 10x; the hanging client sleeps 60 s.
        timeout: 10.0,
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let good = client(&r, "minimal");
    assert_eq!(good.status, ClientStatus::Ran, "{:?}", good.reason);
    assert_eq!(good.scenes[0].points[1].passes_strict, Some(true));
    let hangs = client(&r, "hangs");
    assert_eq!(hangs.status, ClientStatus::Failed);
    let kinds: Vec<FailureKind> = hangs.scenes[0]
        .points
        .iter()
        .map(|p| p.failure.as_ref().unwrap().kind)
        .collect();
    assert_eq!(kinds, [FailureKind::Timeout, FailureKind::Skipped]);
    let crashes = client(&r, "crashes");
    assert_eq!(crashes.status, ClientStatus::Failed);
    let f = crashes.scenes[0].points[0].failure.as_ref().unwrap();
    assert_eq!(f.kind, FailureKind::Crash, "{f:?}");
    assert!(f.detail.contains("signal"), "{f:?}");
    // The report shows them, and the profile has the correct client.
    let table = r.table();
    assert!(
        table.contains("client hangs: failed") && table.contains("timeout"),
        "{table}"
    );
    assert!(r.profile.entries.iter().any(|e| e.name == "minimal"));
}

/// With `jobs = 2` two clients run side by side: client `a` waits (up to 5 s) for client
/// `b` to have started, which it sees only if they run at the same time; with `jobs = 1` it
/// does not. The reports keep the clients' order either way.
#[test]
fn two_jobs_run_two_clients_side_by_side() {
    for jobs in [1, 2] {
        let dir = std::env::temp_dir().join(format!("rotor-jobs-{}-{jobs}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let d = dir.display();
        let a = format!(
            "a=sh -c 'i=0; while [ ! -e {d}/b ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); \
             done; [ -e {d}/b ] && touch {d}/a-saw-b; exit 3'"
        );
        let b = format!("b=sh -c 'touch {d}/b; sleep 1; exit 3'");
        let o = BenchOptions {
            clients: vec![
                ClientSpec::parse(&a, &[]).unwrap(),
                ClientSpec::parse(&b, &[]).unwrap(),
            ],
            client_tols: vec![1e-6],
            timeout: 30.0,
            jobs,
            ..options()
        };
        let r = run(&o, |m| eprintln!("{m}")).unwrap();
        let names: Vec<&str> = r.clients.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names[names.len() - 2..], ["a", "b"], "jobs = {jobs}");
        assert_eq!(r.environment.jobs, jobs);
        for c in &r.clients[names.len() - 2..] {
            let f = c.scenes[0].points[0].failure.as_ref().unwrap();
            assert_eq!(f.kind, FailureKind::Exit, "jobs = {jobs}: {f:?}");
        }
        assert_eq!(dir.join("a-saw-b").exists(), jobs == 2, "jobs = {jobs}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// The regularised client (tanh(omega/1e-3), LSODA) runs, and fails the loose gate with the
/// failing quantities named: the spring (`alpha`) and `omega_l`, which wind up at the wrong
/// rate while its disc creeps instead of sticking. (Its creep, ≲ 1e-3 rad/s, is within the
/// loose level's stuck threshold, 1e-3 of ω_l's scale: at loose its stick intervals are
/// graded like a stuck disc's, and on this scene they pass.)
#[test]
fn the_regularised_client_fails_the_gates_with_the_quantities_named() {
    let o = options();
    if !peer_present(&o.peers.python, "scipy") {
        return;
    }
    let root = rotor_harness::bench::workspace_root();
    let script = root.join("bench/clients/tanh_regularised.py");
    let o = BenchOptions {
        clients: vec![
            ClientSpec::parse(&format!("tanh=python3 {}", script.display()), &[]).unwrap(),
        ],
        client_tols: vec![1e-8],
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = &client(&r, "tanh").scenes[0].points[0];
    assert_eq!(p.passes_loose, Some(false));
    let f = p.failure.as_ref().unwrap();
    assert_eq!(f.kind, FailureKind::FailsGate);
    assert!(
        ["alpha", "omega_l"]
            .iter()
            .all(|n| p.failing.iter().any(|q| q == n)),
        "{:?}",
        p.failing
    );
    assert!(f.detail.contains("omega_l"), "{f:?}");
    assert_eq!(p.passes_strict, Some(false));
}

/// The first-order client (`bench/clients/first_order.c`: backward Euler in the velocities
/// with the friction set taken at the end of the step, written from BENCHMARK.md alone),
/// built with the system's C compiler and run through its job file on t1-u1.5-rest: an
/// honest converging method of another kind. Its digits rise with 1/h, about one per
/// decade (first order: measured 1.8, 2.8, 3.8 at h = 1e-3, 1e-4, 1e-5), and it reaches
/// the loose level at h = 1e-5 with its events graded.
#[test]
fn the_first_order_client_converges_and_passes_loose_at_h_1e_5() {
    use rotor_harness::grade::check::{Level, check};
    let root = rotor_harness::bench::workspace_root();
    let dir = rotor_testkit::tmp_dir("rotor-first-order");
    let exe = dir.join("first_order");
    let built = std::process::Command::new("cc")
        .args(["-O2", "-o"])
        .arg(&exe)
        .arg(root.join("bench/clients/first_order.c"))
        .arg("-lm")
        .status();
    if !built.is_ok_and(|s| s.success()) {
        assert!(
            std::env::var("ROTOR_REQUIRE_PEERS").as_deref() != Ok("1"),
            "ROTOR_REQUIRE_PEERS=1 but the first-order client does not build with cc"
        );
        eprintln!("first-order client not tested: no C compiler");
        return;
    }
    let sc =
        rotor_analysis::solvers::load_scenario(&root.join("fixtures/scenarios/t1-u1.5-rest.toml"))
            .unwrap();
    let r =
        rotor_harness::grade::reference::read(&root.join("fixtures/reference"), &sc.name).unwrap();
    let digits: Vec<(f64, bool)> = [1e-3, 1e-4, 1e-5]
        .into_iter()
        .map(|h| {
            let job = rotor_harness::protocol::Job::new(
                &sc,
                sc.t_end,
                sc.compare.dt,
                true,
                h,
                dir.join(format!("trace-{h:e}.csv")),
                dir.join(format!("events-{h:e}.csv")),
            );
            let path = dir.join(format!("job-{h:e}.json"));
            std::fs::write(&path, serde_json::to_string(&job).unwrap()).unwrap();
            let st = std::process::Command::new(&exe)
                .arg(&path)
                .status()
                .unwrap();
            assert!(st.success());
            let t = rotor_harness::grade::trace::read_trace(&job.trace, usize::MAX).unwrap();
            let e = rotor_harness::grade::trace::read_events(&job.events).unwrap();
            let rep = check(&sc, &r, &t, Some(&e), Level::Loose).unwrap();
            assert!(rep.not_graded.is_empty());
            (rep.digits, rep.passed)
        })
        .collect();
    std::fs::remove_dir_all(&dir).ok();
    // First order: each decade of h gains one digit; 0.8 allows for the digits' rounding to
    // one decimal and for which sample happens to be worst.
    assert!(
        digits[1].0 - digits[0].0 >= 0.8 && digits[2].0 - digits[1].0 >= 0.8,
        "{digits:?}"
    );
    assert!(!digits[0].1 && digits[2].1, "{digits:?}");
}

/// The scipy peer handles the upper disc's static friction (a second switching surface), so
/// it runs the Stribeck set: on st-u1.5-rest it passes strict at tol 1e-10 (measured 8.8
/// digits over the 200 s scenario), and with scipy's stiff and multistep methods (`--method
/// Radau|BDF|LSODA`) it passes loose at tol 1e-8 (measured 7.5, 4.6 and 5.9 digits). Each is
/// a client of the same protocol, run over the scenario's own horizon and grid.
#[test]
fn scipy_peer_solves_the_stribeck_set_with_every_method() {
    let o = options();
    if !peer_present(&o.peers.python, "scipy") {
        return;
    }
    let root = rotor_harness::bench::workspace_root();
    let peer = root.join("bench/peers/scipy_rotor.py");
    let scene = rotor_harness::bench::SceneSpec::from_scenario(
        &root.join("fixtures/scenarios/st-u1.5-rest.toml"),
    )
    .unwrap();
    let spec = |name: &str, method: &str| {
        ClientSpec::parse(
            &format!("{name}=python3 {} --method {method}", peer.display()),
            &[],
        )
        .unwrap()
    };
    let strict = BenchOptions {
        scenes: vec![scene.clone()],
        clients: vec![spec("dop853", "DOP853")],
        client_tols: vec![1e-10],
        timeout: 60.0,
        ..options()
    };
    let r = run(&strict, |m| eprintln!("{m}")).unwrap();
    let p = &client(&r, "dop853").scenes[0].points[0];
    assert_eq!(p.passes_strict, Some(true), "{p:?}");
    let methods = [("radau", "Radau"), ("bdf", "BDF"), ("lsoda", "LSODA")];
    let loose = BenchOptions {
        scenes: vec![scene],
        clients: methods.iter().map(|(n, m)| spec(n, m)).collect(),
        client_tols: vec![1e-8],
        timeout: 60.0,
        ..options()
    };
    let r = run(&loose, |m| eprintln!("{m}")).unwrap();
    for (name, method) in methods {
        let c = client(&r, name);
        assert_eq!(c.status, ClientStatus::Ran, "{name}: {:?}", c.reason);
        let p = &c.scenes[0].points[0];
        assert_eq!(p.passes_loose, Some(true), "{name}: {p:?}");
        assert_eq!(
            c.method.as_deref(),
            Some(format!("solve_ivp {method}").as_str())
        );
    }
}

/// Whether the Octave peer can be tested; a missing `octave-cli` fails when
/// `ROTOR_REQUIRE_PEERS=1`.
fn octave_present(octave: &str) -> bool {
    match rotor_harness::bench::octave_available(octave) {
        Ok(()) => true,
        Err(why) if std::env::var("ROTOR_REQUIRE_PEERS").as_deref() == Ok("1") => {
            panic!("ROTOR_REQUIRE_PEERS=1 but the Octave peer cannot run: {why}")
        }
        Err(why) => {
            eprintln!("Octave peer not tested: {why}");
            false
        }
    }
}

/// The Octave peer's command line, before the job file (as `rotor bench` starts it).
fn octave_command(octave: &str) -> std::process::Command {
    let root = rotor_harness::bench::workspace_root();
    let mut c = std::process::Command::new(octave);
    c.args(["--norc", "--quiet", "--no-history"])
        .arg(root.join("bench/peers/octave_rotor_cli.m"));
    c
}

/// The Octave peer (GNU Octave's ode45 with event functions, restarted at every mode switch,
/// each event located again to the integration's accuracy) runs each scene of the bench's
/// pair over its whole 200 s scenario at RelTol = AbsTol = 1e-6, and passes the loose level
/// with its events graded: measured 4.6 digits on t1-u1.5-rest and 5.4 on st-u1.5-rest,
/// where the upper disc's static friction makes a second switching surface (and 7.8 and 8.3
/// digits, strict, at 1e-10; `rotor job` and `rotor check` by hand). One run per scene:
/// Octave's ode45 takes several seconds over 20 000 output samples.
#[test]
fn octave_peer_passes_loose_on_both_scenes() {
    use rotor_harness::grade::check::{Level, check};
    let o = options();
    if !octave_present(&o.peers.octave_cli) {
        return;
    }
    let root = rotor_harness::bench::workspace_root();
    let dir = rotor_testkit::tmp_dir("rotor-octave");
    for name in ["t1-u1.5-rest", "st-u1.5-rest"] {
        let sc = rotor_analysis::solvers::load_scenario(
            &root.join(format!("fixtures/scenarios/{name}.toml")),
        )
        .unwrap();
        let r = rotor_harness::grade::reference::read(&root.join("fixtures/reference"), &sc.name)
            .unwrap();
        let job = rotor_harness::protocol::Job::new(
            &sc,
            sc.t_end,
            sc.compare.dt,
            false,
            1e-6,
            dir.join(format!("{name}.csv")),
            dir.join(format!("{name}.events.csv")),
        );
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, serde_json::to_string(&job).unwrap()).unwrap();
        let out = octave_command(&o.peers.octave_cli)
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {stderr}");
        let says =
            rotor_harness::protocol::ClientSays::from_stdout(&String::from_utf8_lossy(&out.stdout));
        assert!(says.solve_seconds.is_some(), "{name}: no solve_seconds");
        let t = rotor_harness::grade::trace::read_trace(&job.trace, usize::MAX).unwrap();
        let e = rotor_harness::grade::trace::read_events(&job.events).unwrap();
        let rep = check(&sc, &r, &t, Some(&e), Level::Loose).unwrap();
        assert!(rep.not_graded.is_empty(), "{name}: {:?}", rep.not_graded);
        assert!(rep.passed, "{name}: {} digits", rep.digits);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The Octave peer as `rotor bench` runs it: found, run over its ladder on the bench scene,
/// graded, placed (it passes loose at 1e-6, as above) and given time ratios against the
/// event-driven solver.
#[test]
fn octave_peer_runs_in_the_bench() {
    let o = options();
    if !octave_present(&o.peers.octave_cli) {
        return;
    }
    let o = BenchOptions {
        peers: rotor_harness::bench::PeerOptions {
            octave: true,
            octave_tols: vec![1e-6],
            ..o.peers.clone()
        },
        ..o
    };
    let r = run(&o, |m| eprintln!("{m}")).unwrap();
    let p = client(&r, "octave");
    assert_eq!(p.status, ClientStatus::Ran, "{:?}", p.reason);
    assert_eq!(p.method.as_deref(), Some("ode45"));
    assert_eq!(p.scenes[0].points[0].passes_loose, Some(true));
    assert!(
        p.scenes[0]
            .ratios
            .iter()
            .any(|q| q.ratio.is_finite() && q.ratio > 0.0),
        "{:?}",
        p.scenes[0].ratios
    );
}

/// A bad job makes the Octave peer exit with status 2 (as the protocol's other clients) and
/// a message naming the field and its value, which `rotor bench` reports as the failure:
/// a job for a fixed-step client (`tol` null) and an unknown friction family.
#[test]
fn octave_peer_refuses_a_bad_job_by_name() {
    let o = options();
    if !octave_present(&o.peers.octave_cli) {
        return;
    }
    let root = rotor_harness::bench::workspace_root();
    let dir = rotor_testkit::tmp_dir("rotor-octave-bad");
    let sc =
        rotor_analysis::solvers::load_scenario(&root.join("fixtures/scenarios/t1-u1.5-rest.toml"))
            .unwrap();
    let job = |fixed_step: bool| {
        let j = rotor_harness::protocol::Job::new(
            &sc,
            1.0,
            0.01,
            fixed_step,
            1e-3,
            dir.join("trace.csv"),
            dir.join("events.csv"),
        );
        serde_json::to_value(&j).unwrap()
    };
    let mut family = job(false);
    family["params"]["lower"]["family"] = "coulomb".into();
    for (what, job, says) in [
        ("tol", job(true), "tol = null must be positive"),
        ("family", family, "lower.family = \"coulomb\""),
    ] {
        let path = dir.join(format!("{what}.json"));
        std::fs::write(&path, job.to_string()).unwrap();
        let out = octave_command(&o.peers.octave_cli)
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
        assert!(stderr.contains(says), "{what}: {stderr}");
        assert!(
            !dir.join("trace.csv").exists(),
            "{what}: a trace was written"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Siconos' MoreauJeanOSI on a chain (bench/peers/siconos_chain.py, one Lemke problem a step
/// coupling the contacts), through the scaling study: at Moreau–Jean's h, on its shorter
/// horizon, it is within the study's target error of the reference on every sample of every
/// state of chains of 2 and 3 discs (so its cost is at the study's error), and takes the steps
/// of its horizon.
#[test]
fn siconos_chain_peer_reaches_the_scaling_studys_error() {
    let o = options();
    if !peer_present(&o.peers.siconos_python, "siconos.kernel") {
        return;
    }
    use rotor_harness::bench::scaling::{ScalingOptions, SiconosOptions, run as scaling};
    let work = rotor_testkit::tmp_dir("siconos-chain");
    let opts = ScalingOptions {
        discs: vec![2, 3],
        t_end: 4.0,
        repeats: 1,
        siconos: Some(SiconosOptions {
            python: o.peers.siconos_python.clone(),
            dir: o.peers.dir.clone(),
            horizon: 0.4,
            timeout: 60.0,
            work: work.clone(),
        }),
        ..ScalingOptions::default()
    };
    let r = scaling(&opts, &mut |m| eprintln!("{m}")).unwrap();
    assert!(r.skipped.is_empty(), "{:?}", r.skipped);
    let peer: Vec<_> = r.points.iter().filter(|p| p.runner == "siconos").collect();
    assert_eq!(peer.len(), 2);
    for p in peer {
        assert!(p.error <= opts.target, "{p:?}");
        assert_eq!(p.horizon, 0.4, "{p:?}");
        assert_eq!(p.steps, (0.4 / p.setting).round() as u64, "{p:?}");
        assert!(p.per_step_ratio.is_some_and(|x| x.is_finite() && x > 0.0));
    }
    std::fs::remove_dir_all(&work).ok();
}
