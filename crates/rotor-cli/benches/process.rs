//! The whole `rotor simulate` process against its in-process solve, side by side in one run
//! (a benchmark, not a test: these machines' timings move by ±15 %).
//!
//! ```sh
//! cargo bench -p rotor-cli --bench process
//! ```
//!
//! Scene: Table 1, u = 1.5 V from rest, 100 s, event-driven solver at tol 1e-12, the 0.01 s
//! trace (10 001 rows) written as CSV. Medians of 41 runs each:
//! * the solve in process (`EventSolver::simulate_finite`, the trace kept);
//! * the solve plus formatting the CSV in memory (the text alone, no file);
//! * the solve plus writing the CSV file in process (what the process does besides starting);
//! * the whole process, `rotor simulate ... --csv FILE`, spawned and waited for;
//! * an empty process, `rotor --version`: start-up and exit alone.
//!
//! And `rotor check` of a correct 200 s trace with its events (t1-u1.5-rest, 20 001 rows: the
//! reference's own files), as a whole process (target: under 50 ms), beside its grading in
//! process (reading the files, the grade, the dense reference orbit).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use rotor_model::Model;
use rotor_model::seam::{Output, Scene, Solver};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(n: usize, mut f: impl FnMut()) -> f64 {
    f();
    median(
        (0..n)
            .map(|_| {
                let t0 = Instant::now();
                f();
                t0.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn main() {
    let n = 41;
    let dir = rotor_testkit::tmp_dir("rotor-process-bench");
    let csv = dir.join("x.csv");
    let model = Model::table1();
    let scene = Scene {
        u: 1.5,
        t_end: 100.0,
        output: Output::Grid { dt: 0.01 },
        ..Scene::with_tol(1e-12)
    };
    let solver = rotor_event::EventSolver::default();
    let solve = time(n, || {
        std::hint::black_box(solver.simulate_finite(&model, &scene).unwrap());
    });
    let solve_format = time(n, || {
        let tr = solver.simulate_finite(&model, &scene).unwrap();
        std::hint::black_box(rotor_harness::grade::trace::write_trace(&tr.samples, 0.01));
    });
    let solve_write = time(n, || {
        let tr = solver.simulate_finite(&model, &scene).unwrap();
        rotor_harness::compare::report::write_output_with(&csv, |w| {
            rotor_harness::grade::trace::write_trace_to(w, &tr.samples, 0.01)
        })
        .unwrap();
    });
    let bin = Path::new(env!("CARGO_BIN_EXE_rotor"));
    let run = |args: &[&str]| {
        let st = Command::new(bin)
            .args(args)
            .stdout(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success());
    };
    let c = csv.to_str().unwrap();
    let args = [
        "simulate", "--solver", "event", "--u", "1.5", "--t-end", "100", "--tol", "1e-12", "--csv",
        c,
    ];
    let whole = time(n, || run(&args));
    let empty = time(n, || run(&["--version"]));
    let ms = |s: f64| s * 1e3;
    println!("rotor simulate --solver event --u 1.5 --t-end 100 --tol 1e-12 --csv FILE");
    println!("  in-process solve             {:7.3} ms", ms(solve));
    println!("  in-process solve + CSV text  {:7.3} ms", ms(solve_format));
    println!("  in-process solve + CSV file  {:7.3} ms", ms(solve_write));
    println!("  whole process                {:7.3} ms", ms(whole));
    println!("  empty process (--version)    {:7.3} ms", ms(empty));
    println!("  whole / solve                {:7.2}", whole / solve);
    println!(
        "  (whole - empty) / solve      {:7.2}",
        (whole - empty) / solve
    );
    // rotor check on a 200 s trace.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sc_path = root.join("fixtures/scenarios/t1-u1.5-rest.toml");
    let trace = root.join("fixtures/reference/t1-u1.5-rest.csv");
    let events = root.join("fixtures/reference/t1-u1.5-rest.events.csv");
    let (s, t, e) = (
        sc_path.to_str().unwrap(),
        trace.to_str().unwrap(),
        events.to_str().unwrap(),
    );
    let check_whole = time(n, || {
        run(&["check", s, "--trace", t, "--events", e, "--gate", "strict"])
    });
    let sc = rotor_analysis::solvers::load_scenario(&sc_path).unwrap();
    let r =
        rotor_harness::grade::reference::read(&root.join("fixtures/reference"), &sc.name).unwrap();
    let check_in = time(n, || {
        let tr = rotor_harness::grade::trace::read_trace(&trace, usize::MAX).unwrap();
        let ev = rotor_harness::grade::trace::read_events(&events).unwrap();
        let rep = rotor_harness::grade::check::check(
            &sc,
            &r,
            &tr,
            Some(&ev),
            rotor_harness::grade::check::Level::Strict,
        )
        .unwrap();
        assert!(rep.passed);
    });
    println!("rotor check t1-u1.5-rest --trace (200 s, 20 001 rows) --events --gate strict");
    println!("  whole process                {:7.3} ms", ms(check_whole));
    println!("  in process (read + grade)    {:7.3} ms", ms(check_in));
    std::fs::remove_dir_all(&dir).ok();
}
