//! Bad input through the `rotor` binary: bad parameter files, bad scenario files
//! and bad flags each give an error on stderr that names the file or flag, the field and the
//! value, with a non-zero exit code that is not a panic's (101) nor a signal's (an abort on a
//! failed allocation); `rotor compare --report DIR` with a bad scenario writes nothing into
//! DIR; and a report interrupted by SIGKILL leaves every file whole (old or new, never cut).
//!
//! The bad parameter and scenario files are `rotor-testkit`'s ([`bad_params_cases`],
//! [`bad_scenario_cases`]), the same ones the library's own bad-input test loads; the flags,
//! the report and the kill cases are the binary's own.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rotor_testkit::{
    SCENARIO, TABLE1, bad_pair_cases, bad_params_cases, bad_scenario_cases, edit, local_scenario,
    tmp_dir, write_scenario,
};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn rotor(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotor"))
        .args(args)
        .output()
        .unwrap()
}

/// An error exit: a code that is neither success, nor a panic (101), nor a signal; stderr's
/// first line starts with `error:` and contains every needle; no panic message anywhere.
fn assert_clean_error(o: &Output, what: &str, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    // Exit 2 for unusable input, whether clap refuses it while parsing (its message ends
    // with the hint to try --help) or rotor after (README, "Exit status"); never 1 (a
    // failed run), 101 (a panic) or a signal.
    let want = 2;
    assert_eq!(
        o.status.code(),
        Some(want),
        "{what}: exit {:?} (want {want}): {err}",
        o.status
    );
    assert!(!err.contains("panicked"), "{what}: {err}");
    let first = err.lines().next().unwrap_or("");
    assert!(first.starts_with("error:"), "{what}: {err}");
    for n in needles {
        assert!(first.contains(n), "{what}: first line lacks {n:?}: {err}");
    }
}

#[test]
fn bad_parameter_files_are_named_with_field_and_value() {
    let dir = tmp_dir("rotor-cli-bad-input");
    let cases = bad_params_cases();
    assert!(!cases.is_empty());
    for (i, c) in cases.iter().enumerate() {
        let what = c.name.as_str();
        let f = dir.join(format!("p{i}.toml"));
        std::fs::write(&f, &c.contents).unwrap();
        let fs = f.to_str().unwrap();
        let mut needles = c.needles.clone();
        needles.push(fs);
        let csv = dir.join(format!("p{i}.csv"));
        // A good chain of three is bad only where the rig is read (the sweep): every solver
        // simulates it and finds its steady state.
        let good_chain = std::str::from_utf8(&c.contents)
            .ok()
            .and_then(|t| rotor_model::ChainParams::from_toml_str(t, Path::new("c")).ok())
            .is_some_and(|p| p.len() > 2);
        if good_chain {
            let o = rotor(&[
                "sweep",
                "--u",
                "1:1:1",
                "--param",
                "k_m=3:3:1",
                "--params",
                fs,
                "--csv",
                csv.to_str().unwrap(),
            ]);
            assert_clean_error(&o, what, &needles);
            assert!(!csv.exists(), "{what}");
            continue;
        }
        let o = rotor(&["steady", "--solver", "event", "--u", "1", "--params", fs]);
        assert_clean_error(&o, what, &needles);
        let o = rotor(&[
            "simulate",
            "--solver",
            "event",
            "--u",
            "1",
            "--t-end",
            "1",
            "--params",
            fs,
            "--csv",
            csv.to_str().unwrap(),
        ]);
        assert_clean_error(&o, what, &needles);
        assert!(!csv.exists(), "{what}: no CSV on error");
    }
    // A path that does not exist.
    let none = dir.join("nothere.toml");
    let o = rotor(&[
        "steady",
        "--solver",
        "event",
        "--u",
        "1",
        "--params",
        none.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "missing file", &[none.to_str().unwrap(), "cannot read"]);
}

#[test]
fn bad_flags_name_the_flag_and_value() {
    let dir = tmp_dir("rotor-cli-bad-input");
    let csv = dir.join("out.csv");
    let csv_s = csv.to_str().unwrap();
    let cases: [(&[&str], &[&str]); 15] = [
        (&["--solver", "nope", "--u", "1"], &["--solver", "\"nope\""]),
        (&["--solver", "event", "--u", "nan"], &["--u", "NaN"]),
        (&["--solver", "event", "--u", "inf"], &["--u", "inf"]),
        // clap's own message for what is not a number at all.
        (&["--solver", "event", "--u", "fast"], &["'fast'", "--u"]),
        (&["--solver", "moreau", "--u", "1", "--h", "0"], &["--h 0"]),
        (
            &["--solver", "moreau", "--u", "1", "--h", "-1e-3"],
            &["--h -0.001"],
        ),
        (
            &["--solver", "moreau", "--u", "1", "--h", "5"],
            &["--h 5", "(0, 1] s"],
        ),
        (
            &["--solver", "event", "--u", "1", "--tol", "2"],
            &["--tol 2"],
        ),
        (
            &["--solver", "event", "--u", "1", "--tol", "0"],
            &["--tol 0"],
        ),
        (
            &["--solver", "event", "--u", "1", "--tol", "-1e-9"],
            &["--tol -1e-9"],
        ),
        (
            &["--solver", "event", "--u", "1", "--x0", "1,2"],
            &["--x0", "\"1,2\""],
        ),
        (
            &["--solver", "event", "--u", "1", "--x0", "1,a,2"],
            &["--x0", "\"a\""],
        ),
        (
            &["--solver", "event", "--u", "1", "--x0", "0,nan,0"],
            &["--x0", "\"nan\""],
        ),
        (
            &["--solver", "event", "--u", "1", "--t-end", "-1"],
            &["--t-end -1"],
        ),
        // A huge value reads as written, not as 309 digits.
        (
            &["--solver", "moreau", "--u", "1e308"],
            &["u = 1e308", "overflows"],
        ),
    ];
    for (args, needles) in cases {
        let mut a = vec!["simulate"];
        a.extend_from_slice(args);
        if !args.contains(&"--t-end") {
            a.extend(["--t-end", "1"]);
        }
        a.extend(["--csv", csv_s]);
        let o = rotor(&a);
        assert_clean_error(&o, &format!("{a:?}"), needles);
        assert!(!csv.exists(), "{a:?}: no CSV on error");
        // The same flags through `steady` (which has no --t-end).
        if !args.contains(&"--t-end") && !args.contains(&"5") {
            let mut a = vec!["steady"];
            a.extend_from_slice(args);
            assert_clean_error(&rotor(&a), &format!("{a:?}"), needles);
        }
    }
    // A grid of 1e14 rows used to abort the process on the failed allocation (signal 6).
    for dt in ["0", "1e-12"] {
        let o = rotor(&[
            "simulate", "--solver", "event", "--u", "1", "--t-end", "100", "--dt", dt, "--csv",
            csv_s,
        ]);
        assert_clean_error(&o, &format!("--dt {dt}"), &["dt"]);
    }
    // A horizon shorter than the default step is not an error when --h is not given.
    let o = rotor(&[
        "simulate", "--solver", "moreau", "--u", "1", "--t-end", "5e-4", "--csv", csv_s,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// An output that cannot be written (its directory missing, or a directory itself) is
/// refused before any work, by flag: a bench or a diagram does not run for minutes to fail at
/// its last write, and no earlier output of the same command is left behind.
#[test]
fn unwritable_outputs_are_refused_before_any_work() {
    let dir = tmp_dir("rotor-cli-bad-input");
    let json = dir.join("b.json");
    let (json_s, dir_s) = (json.to_str().unwrap(), dir.to_str().unwrap());
    let missing = dir.join("no-such-dir").join("x");
    let missing_s = missing.to_str().unwrap();
    let scenario = fixtures().join("scenarios/t1-u1.5-rest.toml");
    let trace = fixtures().join("reference/t1-u1.5-rest.csv");
    let (scenario, trace) = (scenario.to_str().unwrap(), trace.to_str().unwrap());
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["bifurcation", "--json", json_s, "--svg", missing_s],
            &["--svg", "no-such-dir", "does not exist"],
        ),
        (
            &["bench", "--quick", "--csv", dir_s],
            &["--csv", "is a directory"],
        ),
        (
            &[
                "bifurcation2",
                "--param",
                "k_theta",
                "--p-min",
                "0.05",
                "--p-max",
                "0.1",
                "--json",
                missing_s,
            ],
            &["--json", "does not exist"],
        ),
        (
            &[
                "simulate", "--solver", "event", "--u", "1", "--csv", missing_s,
            ],
            &["--csv", "does not exist"],
        ),
        (
            &[
                "sweep",
                "--u",
                "1:2:2",
                "--param",
                "k_theta=0.05:0.1:2",
                "--csv",
                dir_s,
            ],
            &["--csv", "is a directory"],
        ),
        (
            &["merge", "a.csv", "--csv", missing_s],
            &["--csv", "does not exist"],
        ),
    ];
    for (args, needles) in cases {
        let o = rotor(args);
        assert_clean_error(&o, &format!("{args:?}"), needles);
        assert!(
            o.stdout.is_empty(),
            "{args:?}: no work done, nothing printed"
        );
        assert!(!json.exists(), "{args:?}: no other output written");
    }
    // For `check` an unwritable --json is unusable input: exit 2, before grading.
    let o = rotor(&["check", scenario, "--trace", trace, "--json", missing_s]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--json"));
}

/// A file of fixtures/params or fixtures/scenarios may be given by its name, as in the
/// Python package: the same answer as its path. A name that is neither a file nor a fixture
/// is an error listing the names.
#[test]
fn fixtures_may_be_named() {
    let stribeck = fixtures().join("params/stribeck.toml");
    let steady = |params: &str| {
        rotor(&[
            "steady", "--solver", "event", "--u", "1.5", "--params", params,
        ])
    };
    let (by_name, by_path) = (steady("stribeck"), steady(stribeck.to_str().unwrap()));
    assert!(
        by_name.status.success(),
        "{}",
        String::from_utf8_lossy(&by_name.stderr)
    );
    assert_eq!(by_name.stdout, by_path.stdout);
    // And differs from Table 1's: the name was not ignored.
    assert_ne!(
        by_name.stdout,
        rotor(&["steady", "--solver", "event", "--u", "1.5"]).stdout
    );
    assert_clean_error(
        &steady("stribek"),
        "--params stribek",
        &["--params stribek", "names: stribeck, table1"],
    );
    let trace = fixtures().join("reference/t1-u1.5-rest.csv");
    let trace = trace.to_str().unwrap();
    let o = rotor(&["check", "t1-u1.5-rest", "--trace", trace]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rotor(&["check", "t1-u9-rest", "--trace", trace]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("t1-u1.5-rest,"));
}

/// Every non-hidden file of a directory with its bytes, sorted by name.
fn files_of(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<(String, Vec<u8>)> = rd
        .map(|e| e.unwrap().path())
        .filter(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p.file_name().unwrap().to_string_lossy().into_owned(), b)
        })
        .collect();
    v.sort();
    v
}

#[test]
fn compare_with_a_bad_scenario_writes_no_report() {
    let s = local_scenario();
    let cases: Vec<_> = bad_scenario_cases()
        .into_iter()
        .chain(bad_pair_cases())
        .collect();
    assert!(!cases.is_empty());
    for c in &cases {
        let what = c.name.as_str();
        let dir = tmp_dir("rotor-cli-bad-input");
        let f = write_scenario(&dir, &c.contents);
        // A good scenario first: it must not be reported either when a later one is bad.
        let good = dir.join("good.toml");
        std::fs::write(&good, &s).unwrap();
        let report = dir.join("report");
        let mut needles = c.needles.clone();
        let fs = f.to_str().unwrap();
        needles.push(fs);
        let o = rotor(&[
            "compare",
            good.to_str().unwrap(),
            fs,
            "--report",
            report.to_str().unwrap(),
        ]);
        assert_clean_error(&o, what, &needles);
        assert!(files_of(&report).is_empty(), "{what}: report written");
    }
    // A bad parameter file named by a scenario: both files named.
    let dir = tmp_dir("rotor-cli-bad-input");
    let f = write_scenario(&dir, edit(&s, "\"table1.toml\"", "\"bad.toml\"").as_bytes());
    std::fs::write(
        dir.join("bad.toml"),
        edit(TABLE1, "j_u = 0.4765", "j_u = 0.0"),
    )
    .unwrap();
    let report = dir.join("report");
    // An existing report stays as it was.
    std::fs::create_dir_all(&report).unwrap();
    std::fs::write(report.join("README.md"), "old report\n").unwrap();
    let o = rotor(&[
        "compare",
        f.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_clean_error(
        &o,
        "bad params",
        &[f.to_str().unwrap(), "bad.toml", "j_u = 0"],
    );
    assert_eq!(
        files_of(&report),
        vec![("README.md".to_string(), b"old report\n".to_vec())]
    );
    // Two scenarios of one name would overwrite each other's report files.
    let dir = tmp_dir("rotor-cli-bad-input");
    let f = write_scenario(&dir, s.as_bytes());
    let twin = dir.join("twin.toml");
    std::fs::write(&twin, &s).unwrap();
    let report = dir.join("report");
    let o = rotor(&[
        "compare",
        f.to_str().unwrap(),
        twin.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_clean_error(&o, "duplicate name", &["twin.toml", "t1-u1.5-rest"]);
    assert!(files_of(&report).is_empty());
}

/// Name, length and modification time of every entry of a directory (hidden ones too).
#[cfg(unix)]
fn listing(dir: &Path) -> Vec<(String, u64, std::time::SystemTime)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| {
                let e = e.ok()?;
                let m = e.metadata().ok()?;
                Some((
                    e.file_name().to_string_lossy().into_owned(),
                    m.len(),
                    m.modified().ok()?,
                ))
            })
            .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// SIGKILL during `rotor compare --report DIR` over an existing report leaves every report
/// file whole. Most attempts watch DIR and kill the moment anything in it changes (a temporary
/// file appears, or a file's length or time changes: a write is under way); the others kill
/// at spread-out moments of a run. The solvers are deterministic, so a whole CSV or SVG equals
/// the first run's bytes; README.md holds run times, so it must be whole by structure (same
/// number of lines, ends with a newline).
#[cfg(unix)]
#[test]
fn a_killed_compare_leaves_every_report_file_whole() {
    use std::os::unix::process::ExitStatusExt;
    use std::time::Instant;

    let dir = tmp_dir("rotor-cli-bad-input");
    let params = fixtures().join("params/table1.toml");
    // Large files (1e5 CSV rows, ~11 MB) so that writing them takes a while.
    let big = edit(
        &edit(SCENARIO, "name = \"t1-u1.5-rest\"", "name = \"kill-big\""),
        "\"../params/table1.toml\"",
        &format!("{:?}", params.to_str().unwrap()),
    );
    let big = edit(
        &big,
        "steady_from = 100.0",
        "steady_from = 100.0\ndt = 2e-3",
    );
    std::fs::write(dir.join("big.toml"), big).unwrap();
    let small = fixtures().join("scenarios/t1-u0.5-rest.toml");
    let report = dir.join("report");
    let args = [
        "compare".to_string(),
        dir.join("big.toml").to_string_lossy().into_owned(),
        small.to_string_lossy().into_owned(),
        "--report".to_string(),
        report.to_string_lossy().into_owned(),
    ];
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_rotor"))
            .args(&args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap()
    };
    let t0 = Instant::now();
    let status = spawn().wait().unwrap();
    // Used only to spread the timed kills over a run; never asserted.
    let run = t0.elapsed();
    assert!(status.success());
    let first = files_of(&report);
    let names: Vec<&str> = first.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "README.md",
            "friction.csv",
            "friction.svg",
            "index.html",
            "kill-big.csv",
            "kill-big.svg",
            "t1-u0.5-rest.csv",
            "t1-u0.5-rest.svg",
            "timings.md"
        ]
    );
    // The first run's files are whole.
    for (n, b) in &first {
        if n.ends_with(".svg") {
            assert!(b.ends_with(b"</svg>\n"), "{n}");
        }
        if n.ends_with(".html") {
            assert!(b.ends_with(b"</html>\n"), "{n}");
        }
    }
    let csv_rows = first
        .iter()
        .find(|(n, _)| n == "kill-big.csv")
        .map(|(_, b)| b.iter().filter(|&&c| c == b'\n').count())
        .unwrap();
    assert_eq!(csv_rows, 1 + 100_001, "header + 200 s / 2e-3 s + 1 rows");
    let lines = |b: &[u8]| String::from_utf8_lossy(b).lines().count();
    let check_whole = |k: usize| {
        let now = files_of(&report);
        let names_now: Vec<&str> = now.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names_now, names,
            "attempt {k}: the set of report files changed"
        );
        for ((n, b), (_, b0)) in now.iter().zip(&first) {
            if n == "timings.md" {
                assert_eq!(lines(b), lines(b0), "attempt {k}: timings.md cut");
                assert!(b.ends_with(b"\n"), "attempt {k}: timings.md cut");
            } else {
                assert!(
                    b == b0,
                    "attempt {k}: {n} has {} bytes, whole: {}",
                    b.len(),
                    b0.len()
                );
            }
        }
    };

    // Kills at the moment a write is seen under way.
    let mut caught_writing = 0;
    for k in 0..6 {
        let before = listing(&report);
        let mut child = spawn();
        loop {
            if child.try_wait().unwrap().is_some() {
                break;
            }
            if listing(&report) != before {
                let _ = child.kill();
                if child.wait().unwrap().signal() == Some(9) {
                    caught_writing += 1;
                }
                break;
            }
            std::thread::sleep(std::time::Duration::from_micros(100));
        }
        let _ = child.wait();
        check_whole(k);
    }
    // Kills at spread-out moments of a run (most land while the solvers compute).
    for k in 0..4 {
        let mut child = spawn();
        std::thread::sleep(run.mul_f64(0.2 + 0.2 * k as f64));
        let _ = child.kill();
        let _ = child.wait();
        check_whole(6 + k);
    }
    // Else no kill landed inside a write, and the test would have shown nothing.
    assert!(caught_writing >= 1, "no attempt was killed while writing");
}
