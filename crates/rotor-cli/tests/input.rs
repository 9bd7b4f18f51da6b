//! `--input FILE` and a scenario's `input`: a motor input that changes in time, through the
//! `rotor` binary.

use std::path::Path;
use std::process::{Command, Output};

use rotor_testkit::{local_scenario, tmp_dir, write_scenario};

fn rotor(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotor"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit 2 (unusable input), no panic, and the first line names every needle.
fn refused(o: &Output, what: &str, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    let first = err.lines().next().unwrap_or("");
    assert!(first.starts_with("error:"), "{what}: {err}");
    for n in needles {
        assert!(first.contains(n), "{what}: {n:?} missing: {err}");
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

fn simulate(args: &[&str], t_end: &str, csv: &Path) -> String {
    let mut all = vec!["simulate"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--t-end", t_end, "--dt", "0.1", "--csv"]);
    all.push(csv.to_str().unwrap());
    let o = rotor(&all);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    std::fs::read_to_string(csv).unwrap()
}

/// `simulate --input` writes the same CSV form as `--u`; a table of one value is `--u`
/// itself, byte for byte; a step at t = 10 s gives, up to it, the rows of a 1.5 V run that
/// ends there (the solvers restart at a breakpoint as a run from it would start), and
/// differs after it.
#[test]
fn simulate_takes_an_input_file_in_place_of_u() {
    let dir = tmp_dir("rotor-cli-input");
    let flat = write(&dir, "flat.csv", "t,u\n0,1.5\n10,1.5\n");
    let step = write(&dir, "step.csv", "t,u\n10,1.5\n10,2.5\n");
    for solver in ["event", "switch", "moreau"] {
        let csv = dir.join(format!("{solver}.csv"));
        let by_u = simulate(&["--solver", solver, "--u", "1.5"], "20", &csv);
        let by_flat = simulate(&["--solver", solver, "--input", &flat], "20", &csv);
        assert_eq!(by_u, by_flat, "{solver}: a one-valued table is u");
        let to_step = simulate(&["--solver", solver, "--u", "1.5"], "10", &csv);
        let by_step = simulate(&["--solver", solver, "--input", &step], "20", &csv);
        assert_eq!(by_step.lines().next(), Some("t,alpha,omega_u,omega_l"));
        assert_eq!(by_step.lines().count(), by_u.lines().count());
        let rows = |s: &str| s.lines().map(str::to_owned).collect::<Vec<_>>();
        let (a, b) = (rows(&to_step), rows(&by_step));
        assert_eq!(a.len(), 102);
        assert_eq!(a[..], b[..102], "{solver}: up to the step");
        assert_ne!(rows(&by_u).last(), b.last(), "{solver}: after the step");
    }
}

/// `--u` and `--input` together: clap's refusal (exit 2) naming both.
#[test]
fn u_and_input_are_mutually_exclusive() {
    let dir = tmp_dir("rotor-cli-input");
    let step = write(&dir, "step.csv", "t,u\n10,1.5\n10,2.5\n");
    let o = rotor(&[
        "simulate", "--solver", "event", "--u", "1.5", "--input", &step, "--csv", "-",
    ]);
    refused(&o, "both", &["--u", "--input"]);
}

/// A bad input file is refused (exit 2) naming the file, the field and the bad value.
#[test]
fn bad_input_files_are_named_with_the_row_and_value() {
    let dir = tmp_dir("rotor-cli-input");
    let cases: [(&str, &str, &[&str]); 7] = [
        ("empty", "", &["empty"]),
        ("header", "t,v\n0,1\n", &["header", "t,v", "t,u"]),
        ("no rows", "t,u\n", &["no rows"]),
        (
            "decreasing",
            "t,u\n1,1\n0.5,2\n",
            &["input[1].t = 0.5", "decreases"],
        ),
        ("nan", "t,u\n0,NaN\n", &["input[0].u = NaN", "finite"]),
        (
            "triple",
            "t,u\n1,1\n1,2\n1,3\n",
            &["input[2].t = 1", "third row"],
        ),
        (
            "word",
            "t,u\n0,fast\n",
            &["line 2 u", "fast", "not a number"],
        ),
    ];
    for (i, (what, text, needles)) in cases.into_iter().enumerate() {
        let f = write(&dir, &format!("bad{i}.csv"), text);
        let o = rotor(&["simulate", "--solver", "event", "--input", &f, "--csv", "-"]);
        let mut all = vec!["--input"];
        all.extend_from_slice(needles);
        refused(&o, what, &all);
    }
    let o = rotor(&[
        "simulate",
        "--solver",
        "event",
        "--input",
        "/nonexistent/u.csv",
        "--csv",
        "-",
    ]);
    refused(&o, "missing file", &["--input", "/nonexistent/u.csv"]);
}

/// `steady`, `bifurcation`, `bifurcation2` and `sweep` need a constant input: `--input` is
/// refused with exit 2 naming it.
#[test]
fn the_analysis_commands_refuse_an_input() {
    let dir = tmp_dir("rotor-cli-input");
    let step = write(&dir, "step.csv", "t,u\n10,1.5\n10,2.5\n");
    let o = rotor(&["steady", "--solver", "event", "--input", &step]);
    refused(&o, "steady", &["--input", "constant input"]);
    for cmd in ["bifurcation", "bifurcation2", "sweep"] {
        let o = rotor(&[cmd, "--input", &step]);
        refused(&o, cmd, &["--input", cmd, "constant input"]);
    }
}

/// A scenario file says `input = "NAME.csv"` (relative to the scenario file) or
/// `input = [[t, u], ...]` instead of `u = V`; both run the same scene, and the step makes
/// it differ from the constant one.
#[test]
fn a_scenario_file_takes_an_input_file_or_inline_rows() {
    let dir = tmp_dir("rotor-cli-input");
    write(&dir, "step.csv", "t,u\n10,1.5\n10,2.5\n");
    let base = local_scenario()
        .replace("t_end = 200.0", "t_end = 20.0")
        .replace("steady_from = 100.0", "steady_from = 10.0");
    let by_file = base.replace("\nu = 1.5 ", "\ninput = \"step.csv\" ");
    let inline = base.replace("\nu = 1.5 ", "\ninput = [[10.0, 1.5], [10.0, 2.5]] ");
    assert_ne!(by_file, base);
    let mut out = Vec::new();
    for (i, text) in [by_file, inline, base].into_iter().enumerate() {
        let sub = dir.join(format!("s{i}"));
        std::fs::create_dir_all(&sub).unwrap();
        if i == 0 {
            std::fs::copy(dir.join("step.csv"), sub.join("step.csv")).unwrap();
        }
        let f = write_scenario(&sub, text.as_bytes());
        let csv = sub.join("out.csv");
        let o = rotor(&[
            "simulate",
            f.to_str().unwrap(),
            "--solver",
            "event",
            "--dt",
            "0.1",
            "--csv",
            csv.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "scenario {i}: {}", stderr(&o));
        out.push(std::fs::read_to_string(&csv).unwrap());
    }
    assert_eq!(out[0], out[1], "file and inline rows are the same input");
    assert_ne!(out[0], out[2], "the step changes the run");
    // Both u and input, or a bad inline row: refused naming the field.
    let sub = dir.join("bad");
    std::fs::create_dir_all(&sub).unwrap();
    let both = local_scenario().replace("\nu = 1.5 ", "\nu = 1.5\ninput = [[0.0, 1.0]] ");
    let f = write_scenario(&sub, both.as_bytes());
    let o = rotor(&[
        "simulate",
        f.to_str().unwrap(),
        "--solver",
        "event",
        "--csv",
        "-",
    ]);
    refused(&o, "u and input", &["input", "not both"]);
    let bad = local_scenario().replace("\nu = 1.5 ", "\ninput = [[1.0, 1.0], [0.0, 2.0]] ");
    let f = write_scenario(&sub, bad.as_bytes());
    let o = rotor(&[
        "simulate",
        f.to_str().unwrap(),
        "--solver",
        "event",
        "--csv",
        "-",
    ]);
    refused(&o, "decreasing row", &["input[1].t = 0", "decreases"]);
}

/// A scenario with a time-varying input: `rotor job` writes `"u": null` and the rows as
/// `"input"`, `rotor reference` writes its reference, and `rotor check` grades a trace
/// against it like any other: the event solver's own trace passes at the strict gate, and
/// the trace of the constant 1.5 V run (no step) fails.
#[test]
fn job_reference_and_check_take_a_scene_with_an_input() {
    let dir = tmp_dir("rotor-cli-input");
    let text = local_scenario()
        .replace("name = \"t1-u1.5-rest\"", "name = \"t1-step\"")
        .replace("\nu = 1.5 ", "\ninput = [[20.0, 1.5], [20.0, 2.5]] ")
        .replace("t_end = 200.0", "t_end = 60.0")
        .replace("steady_from = 100.0", "steady_from = 30.0")
        .replace("transient = [0.0, 20.0]", "transient = [0.0, 30.0]");
    // The suite's layout: scenarios/ beside reference/, where `check` looks.
    let scenarios = dir.join("scenarios");
    std::fs::create_dir_all(&scenarios).unwrap();
    let f = write_scenario(&scenarios, text.as_bytes());
    let s = f.to_str().unwrap();
    let o = rotor(&["job", s, "--tol", "1e-8"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let job: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(job["u"], serde_json::Value::Null);
    assert_eq!(job["input"], serde_json::json!([[20.0, 1.5], [20.0, 2.5]]));
    let refdir = dir.join("reference");
    let o = rotor(&[
        "reference",
        "--scenario",
        s,
        "--out",
        refdir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let graded = |args: &[&str]| {
        let csv = dir.join("trace.csv");
        let mut all = vec!["simulate", s];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--csv", csv.to_str().unwrap()]);
        let o = rotor(&all);
        assert!(o.status.success(), "{}", stderr(&o));
        Command::new(env!("CARGO_BIN_EXE_rotor"))
            .args([
                "check",
                s,
                "--trace",
                csv.to_str().unwrap(),
                "--gate",
                "strict",
            ])
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let own = graded(&["--solver", "event"]);
    assert_eq!(own.status.code(), Some(0), "{}", stderr(&own));
    // The same run without the step: a constant scenario's trace against the step's
    // reference.
    let constant = text.replace("\ninput = [[20.0, 1.5], [20.0, 2.5]] ", "\nu = 1.5 ");
    std::fs::write(scenarios.join("c.toml"), constant).unwrap();
    let csv = dir.join("c.csv");
    let o = rotor(&[
        "simulate",
        scenarios.join("c.toml").to_str().unwrap(),
        "--solver",
        "event",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = Command::new(env!("CARGO_BIN_EXE_rotor"))
        .args(["check", s, "--trace", csv.to_str().unwrap()])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
}
