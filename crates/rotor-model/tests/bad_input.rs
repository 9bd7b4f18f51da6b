//! Bad parameter and scenario files (issue #8): every kind of bad input is an error, never a
//! panic, and its message is one line that names the file, the field and the offending value.
//!
//! Each case is a mutation of a real fixture file, written to a temporary directory and read
//! back through `from_file`, so that the path in the message is the path of the file.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use rotor_model::scene::MAX_GRID_ROWS;
use rotor_model::{Output, Params, Scenario, Scene};

const TABLE1: &str = include_str!("../../../fixtures/params/table1.toml");
const STRIBECK: &str = include_str!("../../../fixtures/params/stribeck.toml");
const SCENARIO: &str = include_str!("../../../fixtures/scenarios/t1-u1.5-rest.toml");

/// A fresh directory per call (tests run in parallel).
fn tmp_dir() -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!(
        "rotor-model-bad-input-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Replaces `from` by `to`: the first line that starts with `from`, else the first
/// occurrence outside a comment; insists that there is one (so that a fixture edit cannot
/// silently turn a case into a no-op).
fn edit(text: &str, from: &str, to: &str) -> String {
    let mut starts = None;
    let mut inside = None;
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        if starts.is_none() && line.starts_with(from) {
            starts = Some(at);
        }
        let code = line.split('#').next().unwrap();
        if inside.is_none()
            && let Some(i) = code.find(from)
        {
            inside = Some(at + i);
        }
        at += line.len();
    }
    let i = starts
        .or(inside)
        .unwrap_or_else(|| panic!("fixture no longer contains {from:?} outside a comment"));
    format!("{}{}{}", &text[..i], to, &text[i + from.len()..])
}

/// The message must be one line, start with the file's path and contain every needle.
fn check_message(msg: &str, path: &Path, needles: &[&str]) {
    assert!(
        !msg.contains('\n') && !msg.contains('\r'),
        "one line: {msg}"
    );
    let p = path.display().to_string();
    assert!(msg.starts_with(&p), "starts with the file {p}: {msg}");
    for n in needles {
        assert!(msg.contains(n), "names {n:?}: {msg}");
    }
}

fn params_err(text: &[u8], needles: &[&str]) {
    let path = tmp_dir().join("p.toml");
    std::fs::write(&path, text).unwrap();
    match Params::from_file(&path) {
        Ok(p) => panic!("accepted {p:?} from {}", String::from_utf8_lossy(text)),
        Err(e) => check_message(&e.to_string(), &path, needles),
    }
}

/// Writes a scenario (and a good Table 1 parameter file next to it) and expects an error.
fn scenario_err(text: &[u8], needles: &[&str]) -> String {
    let dir = tmp_dir();
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    match Scenario::from_file(&path) {
        Ok(s) => panic!("accepted {}: {}", s.name, String::from_utf8_lossy(text)),
        Err(e) => {
            let msg = e.to_string();
            check_message(&msg, &path, needles);
            msg
        }
    }
}

/// The scenario fixture with its params path pointing at the copy next to it.
fn scenario() -> String {
    edit(SCENARIO, "../params/table1.toml", "table1.toml")
}

#[test]
fn the_unmutated_files_load() {
    // Guards every case below: each one differs from a file that loads only by its mutation.
    let dir = tmp_dir();
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    std::fs::write(dir.join("s.toml"), scenario()).unwrap();
    std::fs::write(dir.join("st.toml"), STRIBECK).unwrap();
    Scenario::from_file(&dir.join("s.toml")).unwrap();
    Params::from_file(&dir.join("table1.toml")).unwrap();
    Params::from_file(&dir.join("st.toml")).unwrap();
}

#[test]
fn params_unknown_keys() {
    params_err(
        edit(TABLE1, "j_u = 0.4765", "j_uu = 0.4765").as_bytes(),
        &["unknown field", "j_uu", "j_uu = 0.4765"],
    );
    params_err(
        edit(TABLE1, "db = 0.0", "db = 0.0\nbb = 1.0").as_bytes(),
        &["unknown field", "bb", "bb = 1.0"],
    );
    params_err(
        edit(TABLE1, "b = 0.0109", "b = 0.0109\nt_3 = 0.1").as_bytes(),
        &["unknown field", "t_3", "t_3 = 0.1"],
    );
    // A key of the other family.
    params_err(
        edit(TABLE1, "b = 0.0109", "b = 0.0109\ndelta = 2.0").as_bytes(),
        &["lower.delta", "= 2", "exponential"],
    );
}

#[test]
fn params_missing_keys() {
    params_err(
        edit(TABLE1, "j_u = 0.4765", "").as_bytes(),
        &["missing field", "j_u"],
    );
    params_err(
        edit(TABLE1, "b = 2.2247", "").as_bytes(),
        &["missing field", "`b`", "[upper]"],
    );
    params_err(
        edit(TABLE1, "family = \"exponential\"", "").as_bytes(),
        &["missing field", "family", "[lower]"],
    );
    params_err(
        edit(TABLE1, "w_2 = 0.2941", "").as_bytes(),
        &["lower.w_2", "missing"],
    );
    params_err(
        edit(STRIBECK, "omega_s =", "# omega_s =").as_bytes(),
        &["lower.omega_s", "missing", "stribeck"],
    );
    // A missing key's message must not quote a comment line as its context.
    let path = tmp_dir().join("p.toml");
    std::fs::write(&path, edit(TABLE1, "j_u = 0.4765", "")).unwrap();
    let e = Params::from_file(&path).unwrap_err().to_string();
    assert!(!e.contains("(in `#"), "{e}");
}

#[test]
fn params_wrong_types() {
    params_err(
        edit(TABLE1, "j_u = 0.4765", "j_u = \"heavy\"").as_bytes(),
        &["invalid type", "j_u = \"heavy\""],
    );
    params_err(
        edit(TABLE1, "k_m = 3.9950", "k_m = [3.995]").as_bytes(),
        &["invalid type", "k_m = [3.995]"],
    );
    params_err(
        edit(TABLE1, "family = \"exponential\"", "family = 3").as_bytes(),
        &["invalid type", "family = 3"],
    );
    params_err(
        edit(TABLE1, "k_theta = 0.0727", "k_theta = 0.0727 0.1").as_bytes(),
        &["k_theta = 0.0727 0.1"],
    );
}

#[test]
fn params_non_finite_values() {
    for (from, to, needles) in [
        (
            "k_theta = 0.0727",
            "k_theta = nan",
            ["k_theta = NaN", "finite"],
        ),
        (
            "k_theta = 0.0727",
            "k_theta = inf",
            ["k_theta = inf", "finite"],
        ),
        ("j_u = 0.4765", "j_u = -inf", ["j_u = -inf", "finite"]),
        ("t_2 = -0.2267", "t_2 = nan", ["lower.t_2 = NaN", "finite"]),
        ("b = 2.2247", "b = inf", ["upper.b = inf", "finite"]),
        ("j_l = 0.0326", "j_l = 1e999", ["j_l = 1e999", "overflow"]),
    ] {
        params_err(edit(TABLE1, from, to).as_bytes(), &needles);
    }
}

#[test]
fn params_out_of_range_values() {
    for (from, to, needles) in [
        ("j_u = 0.4765", "j_u = 0.0", ["j_u = 0", "positive"]),
        ("j_u = 0.4765", "j_u = -1.0", ["j_u = -1", "positive"]),
        ("j_l = 0.0326", "j_l = -0.5", ["j_l = -0.5", "positive"]),
        (
            "k_theta = 0.0727",
            "k_theta = 0.0",
            ["k_theta = 0", "positive"],
        ),
        (
            "k_theta = 0.0727",
            "k_theta = -0.07",
            ["k_theta = -0.07", "positive"],
        ),
        ("k_m = 3.9950", "k_m = 0.0", ["k_m = 0", "non-zero"]),
        ("t_s = 0.1642", "t_s = -0.1", ["lower.t_s = -0.1", ">= 0"]),
        ("t_s = 0.0 ", "t_s = -1e-3 ", ["upper.t_s = -0.001", ">= 0"]),
        ("dt_s = 0.0", "dt_s = 0.5", ["upper.dt_s = 0.5", "t_s"]),
        ("b = 2.2247", "b = -2.2", ["upper.b = -2.2", ">= 0"]),
        ("b = 0.0109", "b = -0.01", ["lower.b = -0.01", ">= 0"]),
        ("w_1 = 5.7468", "w_1 = 0.0", ["lower.w_1 = 0", "positive"]),
        (
            "w_2 = 0.2941",
            "w_2 = -0.3",
            ["lower.w_2 = -0.3", "positive"],
        ),
    ] {
        params_err(edit(TABLE1, from, to).as_bytes(), &needles);
    }
    for (from, to, needles) in [
        (
            "delta = 2.0575",
            "delta = 0.0",
            ["lower.delta = 0", "exponent"],
        ),
        (
            "delta = 2.0575",
            "delta = -1.0",
            ["lower.delta = -1", "exponent"],
        ),
        (
            "omega_s = 1.4302",
            "omega_s = 0.0",
            ["lower.omega_s = 0", "positive"],
        ),
        ("t_c = 0.0473", "t_c = -0.05", ["lower.t_c = -0.05", ">= 0"]),
    ] {
        params_err(edit(STRIBECK, from, to).as_bytes(), &needles);
    }
}

#[test]
fn params_unknown_family() {
    params_err(
        edit(TABLE1, "\"exponential\"", "\"dahl\"").as_bytes(),
        &["lower.family", "\"dahl\"", "unknown friction family"],
    );
    params_err(
        edit(TABLE1, "\"exponential\"", "\"Exponential\"").as_bytes(),
        &["lower.family", "\"Exponential\""],
    );
}

#[test]
fn params_unreadable_empty_and_binary_files() {
    let missing = tmp_dir().join("nothere.toml");
    let e = Params::from_file(&missing).unwrap_err().to_string();
    check_message(&e, &missing, &["cannot read"]);
    let dir = tmp_dir();
    let e = Params::from_file(&dir).unwrap_err().to_string();
    check_message(&e, &dir, &["cannot read"]);

    params_err(b"", &["empty"]);
    params_err(b"  \n\t\n", &["empty"]);
    params_err(b"# only a comment\n", &["missing field"]);
    // Not UTF-8: the offending byte and its offset.
    params_err(
        b"j_u = 0.4\n\xff\xfe\x00\x01",
        &["not a UTF-8", "0xff", "offset 10"],
    );
    // Valid UTF-8 with a NUL byte: a binary file.
    params_err(b"j_u = 0.4\n\x00\x01\x02", &["NUL byte", "offset 10"]);
    // Control characters in the echoed source line are escaped, not printed.
    params_err(b"j_u = 0.4\rk_m \x07= 1\n", &["\\u{7}"]);
}

#[test]
fn scenario_horizon_step_and_tolerance_out_of_range() {
    let s = scenario();
    for (to, needles) in [
        ("t_end = 0.0", vec!["t_end = 0", "positive"]),
        ("t_end = -5.0", vec!["t_end = -5", "positive"]),
        ("t_end = inf", vec!["t_end = inf"]),
        ("t_end = nan", vec!["t_end = NaN"]),
        ("t_end = 200.0\nh = 0.0", vec!["h = 0", "(0, t_end]"]),
        ("t_end = 200.0\nh = -1e-3", vec!["h = -0.001", "(0, t_end]"]),
        ("t_end = 200.0\nh = 300.0", vec!["h = 300", "(0, t_end]"]),
        ("t_end = 200.0\nh = nan", vec!["h = NaN"]),
        ("t_end = 200.0\ntol = 0.0", vec!["tol = 0", "(0, 1)"]),
        (
            "t_end = 200.0\ntol = -1e-6",
            vec!["tol = -0.000001", "(0, 1)"],
        ),
        ("t_end = 200.0\ntol = 1.0", vec!["tol = 1", "(0, 1)"]),
        ("t_end = 200.0\ntol = 2.0", vec!["tol = 2", "(0, 1)"]),
        ("t_end = 200.0\ntol = nan", vec!["tol = NaN"]),
        (
            "t_end = 200.0\ntol = 1e-16",
            vec!["tol = 0.0000000000000001", "roundoff"],
        ),
    ] {
        scenario_err(edit(&s, "t_end = 200.0", to).as_bytes(), &needles);
    }
    // A horizon shorter than the default Moreau step, without h: every run would fail.
    let short = edit(&s, "transient = [0.0, 20.0]", "transient = [0.0, 5e-4]");
    let short = edit(&short, "steady_from = 100.0", "");
    scenario_err(
        edit(&short, "t_end = 200.0", "t_end = 5e-4").as_bytes(),
        &["t_end = 0.0005", "set h"],
    );
    let dir = tmp_dir();
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        edit(&short, "t_end = 200.0", "t_end = 5e-4\nh = 1e-4"),
    )
    .unwrap();
    Scenario::from_file(&dir.join("s.toml")).unwrap();
}

#[test]
fn scenario_unknown_missing_and_mistyped_keys() {
    let s = scenario();
    // There is no solver key in a scenario (every scenario runs all three solvers).
    scenario_err(
        edit(&s, "t_end = 200.0", "t_end = 200.0\nsolver = \"rk4\"").as_bytes(),
        &["unknown field", "solver = \"rk4\""],
    );
    scenario_err(
        edit(&s, "u = 1.5", "uu = 1.5").as_bytes(),
        &["unknown field", "uu = 1.5"],
    );
    scenario_err(
        edit(&s, "steady_from = 100.0", "steady_from = 100.0\nwindow = 3").as_bytes(),
        &["unknown field", "window = 3"],
    );
    scenario_err(
        edit(&s, "transient_rms = 2e-8", "transient_rsm = 2e-8").as_bytes(),
        &["unknown field", "transient_rsm = 2e-8"],
    );
    for key in ["u = 1.5", "t_end = 200.0", "name = \"t1-u1.5-rest\""] {
        let field = key.split(' ').next().unwrap();
        scenario_err(
            edit(&s, key, "").as_bytes(),
            &["missing field", &format!("`{field}`")],
        );
    }
    scenario_err(
        edit(&s, "u = 1.5", "u = \"fast\"").as_bytes(),
        &["invalid type", "u = \"fast\""],
    );
    scenario_err(
        edit(&s, "x0 = [0.0, 0.0, 0.0]", "x0 = [0.0, 0.0]").as_bytes(),
        &["length 2", "x0 = [0.0, 0.0]"],
    );
    scenario_err(
        edit(&s, "x0 = [0.0, 0.0, 0.0]", "x0 = \"rest\"").as_bytes(),
        &["invalid type", "x0 = \"rest\""],
    );
    scenario_err(
        edit(&s, "\"table1.toml\"", "42").as_bytes(),
        &["invalid type", "params = 42"],
    );
}

#[test]
fn scenario_non_finite_values() {
    let s = scenario();
    scenario_err(edit(&s, "u = 1.5", "u = nan").as_bytes(), &["u = NaN"]);
    scenario_err(edit(&s, "u = 1.5", "u = -inf").as_bytes(), &["u = -inf"]);
    scenario_err(
        edit(&s, "x0 = [0.0, 0.0, 0.0]", "x0 = [0.0, inf, 0.0]").as_bytes(),
        &["x0[1] = inf"],
    );
    scenario_err(
        edit(
            &s,
            "x0 = [0.0, 0.0, 0.0]",
            "x0_from_equilibrium = [0.0, 0.0, nan]",
        )
        .as_bytes(),
        &["x0_from_equilibrium[2] = NaN"],
    );
}

#[test]
fn scenario_compare_and_tolerance_tables() {
    let s = scenario();
    scenario_err(
        edit(&s, "steady_from = 100.0", "steady_from = 100.0\ndt = 0.0").as_bytes(),
        &["compare.dt = 0"],
    );
    // 200 s at 1e-12 s would be 2e14 rows: refused before any allocation.
    scenario_err(
        edit(&s, "steady_from = 100.0", "steady_from = 100.0\ndt = 1e-12").as_bytes(),
        &["compare.dt = 0.000000000001", "1e7"],
    );
    scenario_err(
        edit(&s, "transient = [0.0, 20.0]", "transient = [0.0, 300.0]").as_bytes(),
        &["compare.transient = [0, 300]"],
    );
    scenario_err(
        edit(&s, "steady_from = 100.0", "steady_from = 250.0").as_bytes(),
        &["compare.steady_from = 250"],
    );
    scenario_err(
        edit(&s, "transient_max = 1e-7 ", "transient_max = -1e-7 ").as_bytes(),
        &["tolerance.event-switch.transient_max = -0.0000001"],
    );
    // A misspelt pair would leave the pair ungated: refused.
    scenario_err(
        edit(&s, "[tolerance.event-switch]", "[tolerance.event-swich]").as_bytes(),
        &["tolerance = \"event-swich\"", "unknown solver pair"],
    );
}

#[test]
fn scenario_names_that_cannot_name_report_files() {
    let s = scenario();
    for bad in ["", "../escape", "a/b", ".hidden", "a b", "x\\\\y"] {
        let to = format!("name = \"{bad}\"");
        let e = scenario_err(
            edit(&s, "name = \"t1-u1.5-rest\"", &to).as_bytes(),
            &["name = "],
        );
        assert!(e.contains("report"), "{e}");
    }
}

#[test]
fn scenario_params_path_and_bad_params_file() {
    let s = scenario();
    // The scenario file, the params file and the OS reason, once each.
    let e = scenario_err(
        edit(&s, "\"table1.toml\"", "\"nothere.toml\"").as_bytes(),
        &["params", "nothere.toml", "cannot read parameter file"],
    );
    assert_eq!(e.matches("nothere.toml").count(), 1, "{e}");
    // A parameter file with a bad value: named through the scenario.
    let dir = tmp_dir();
    std::fs::write(
        dir.join("bad.toml"),
        edit(TABLE1, "j_l = 0.0326", "j_l = 0.0"),
    )
    .unwrap();
    let path = dir.join("s.toml");
    std::fs::write(&path, edit(&s, "\"table1.toml\"", "\"bad.toml\"")).unwrap();
    let e = Scenario::from_file(&path).unwrap_err().to_string();
    check_message(&e, &path, &["bad.toml", "j_l = 0", "positive"]);
}

#[test]
fn control_characters_in_paths_are_escaped() {
    // A newline is legal in a Unix file name; the message stays one line.
    let dir = tmp_dir();
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    let path = dir.join("s.toml");
    std::fs::write(
        &path,
        edit(
            &scenario(),
            "\"table1.toml\"",
            "\"\"\"two\nlines.toml\"\"\"",
        ),
    )
    .unwrap();
    let e = Scenario::from_file(&path).unwrap_err().to_string();
    check_message(
        &e,
        &path,
        &["two\\nlines.toml", "cannot read parameter file"],
    );
    let odd = dir.join("a\rb.toml");
    let e = Params::from_file(&odd).unwrap_err().to_string();
    assert!(!e.contains('\r') && e.contains("a\\rb.toml"), "{e}");
}

#[test]
fn scenario_unreadable_empty_and_binary_files() {
    let missing = tmp_dir().join("nothere.toml");
    let e = Scenario::from_file(&missing).unwrap_err().to_string();
    check_message(&e, &missing, &["cannot read scenario file"]);
    scenario_err(b"", &["empty"]);
    scenario_err(b"\n\n   \n", &["empty"]);
    scenario_err(
        b"\x89PNG\r\n\x1a\n\x00\x00",
        &["not a UTF-8", "0x89", "offset 0"],
    );
    scenario_err(b"name = \"a\"\n\x00", &["NUL byte", "offset 11"]);
}

#[test]
fn scene_tolerance_below_roundoff_is_refused() {
    use rotor_model::scene::MIN_TOL;
    let at = |tol| {
        Scene {
            tol,
            ..Scene::default()
        }
        .validate()
    };
    assert!(at(1e-13).is_ok());
    assert!(at(MIN_TOL).is_ok());
    let e = at(1e-20).unwrap_err().to_string();
    assert!(
        e.contains("tol = 0.00000000000000000001") && e.contains("roundoff"),
        "{e}"
    );
}

#[test]
fn scene_grid_that_would_exhaust_memory_is_refused() {
    let ok = Scene {
        t_end: 100.0,
        output: Output::Grid {
            dt: 100.0 / MAX_GRID_ROWS,
        },
        ..Scene::default()
    };
    ok.validate().unwrap();
    let e = Scene {
        output: Output::Grid { dt: 1e-12 },
        ..ok.clone()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("dt = 0.000000000001") && e.contains("1e7"),
        "{e}"
    );
    let e = Scene {
        t_end: 1e300,
        h: 1.0,
        output: Output::Grid { dt: 1.0 },
        ..ok
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("dt = 1"), "{e}");
}
