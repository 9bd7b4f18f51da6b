//! Test support for the bad-input tests of `rotor-model` and `rotor_model::scenario` (through
//! `from_file`) and `rotor-cli` (through the `rotor` binary).
//!
//! They test the same bad files; this crate holds them once, so that the library and the
//! binary are held to the same cases. Each case is a real fixture with one mutation (or a
//! few raw bytes) and the needles, the substrings its error message must contain. What is
//! checked around the needles (one line starting with the path, an `error:` line on stderr
//! with a clean exit code, no report written) stays with each test's own harness.
//!
//! It also holds `mutate` (feature `mutate`), the fixture edits of both readers' fuzz tests, and [`arenstorf`],
//! the standard orbit both Runge–Kutta steppers are checked on.
//!
//! Dev-dependency only; nothing here is part of the published crates.

#![warn(missing_docs)]

pub mod arenstorf;
#[cfg(feature = "mutate")]
pub mod mutate;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The Table 1 parameter file (exponential family), `fixtures/params/table1.toml`.
pub const TABLE1: &str = include_str!("../../../fixtures/params/table1.toml");
/// The Stribeck-family parameter file, `fixtures/params/stribeck.toml`.
pub const STRIBECK: &str = include_str!("../../../fixtures/params/stribeck.toml");
/// The scenario `fixtures/scenarios/t1-u1.5-rest.toml` (its params path is
/// `../params/table1.toml`, relative to the fixtures; see [`local_scenario`]).
pub const SCENARIO: &str = include_str!("../../../fixtures/scenarios/t1-u1.5-rest.toml");

/// A bad-input message (of a parameter or scenario file) must be one line, start with the file's path and contain every needle.
pub fn check_message(what: &str, msg: &str, path: &std::path::Path, needles: &[&str]) {
    assert!(
        !msg.contains('\n') && !msg.contains('\r'),
        "{what}: one line: {msg}"
    );
    let p = path.display().to_string();
    assert!(
        msg.starts_with(&p),
        "{what}: starts with the file {p}: {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "{what}: names {n:?}: {msg}");
    }
}

/// A fresh, existing directory under the system's temporary directory, named
/// `{prefix}-{pid}-{n}` with `n` counting the calls of this process, so that tests running in
/// parallel (and test binaries running at the same time) never share one.
pub fn tmp_dir(prefix: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!(
        "{prefix}-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `text` with `from` replaced by `to`: the first line that starts with `from`, else the
/// first occurrence of `from` outside a comment (the part of a line before any `#`).
///
/// # Panics
///
/// If `from` occurs in neither place, so that a fixture edit cannot silently turn a case into
/// a no-op (the unmutated file loads, so the case would fail for a different reason or not
/// at all).
pub fn edit(text: &str, from: &str, to: &str) -> String {
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

/// [`SCENARIO`] with its params path changed to `table1.toml`, the file that
/// [`write_scenario`] puts next to it. Loads as it is; every scenario case is a mutation of it.
pub fn local_scenario() -> String {
    edit(SCENARIO, "\"../params/table1.toml\"", "\"table1.toml\"")
}

/// Writes [`TABLE1`] as `dir/table1.toml` and `contents` as `dir/s.toml`, the layout every
/// scenario case assumes; returns the path of the scenario file.
pub fn write_scenario(dir: &Path, contents: &[u8]) -> PathBuf {
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    let f = dir.join("s.toml");
    std::fs::write(&f, contents).unwrap();
    f
}

/// [`local_scenario`] with a horizon of 5e-4 s, shorter than the default Moreau step, and no
/// `h`: every run would fail, so the file is refused. With `h = 1e-4` added after `t_end` it
/// loads (the library test checks that, so that this case fails only for the missing `h`).
/// Its transient window is the whole horizon on a 1e-4 s grid, and it has no steady state
/// (nor the steady tolerances, which would gate nothing).
pub fn short_horizon_scenario() -> String {
    let s = local_scenario();
    let s = edit(
        &s,
        "transient = [0.0, 20.0]",
        "transient = [0.0, 5e-4]\ndt = 1e-4",
    );
    let s = edit(&s, "steady_from = 100.0", "");
    let s: String = s
        .lines()
        .filter(|l| !STEADY_KEYS.iter().any(|k| l.starts_with(k)))
        .map(|l| format!("{l}\n"))
        .collect();
    edit(&s, "t_end = 200.0", "t_end = 5e-4")
}

/// Scenario files that load but name a solver pair the runner does not have: a misspelt pair
/// would leave that pair ungated. The loaders that know the solvers (rotor_analysis::solvers', the
/// CLI's) refuse them.
pub fn bad_pair_cases() -> Vec<BadFile> {
    vec![edited(
        "t1-u1.5-rest",
        &local_scenario(),
        "[tolerance.event-switch]",
        "[tolerance.event-swich]",
        &["tolerance = \"event-swich\"", "unknown solver pair"],
    )]
}

/// The keys of a `[tolerance.*]` table that gate the steady state.
const STEADY_KEYS: [&str; 13] = [
    "period_rel",
    "omega_l_max_rel",
    "omega_l_min",
    "omega_u_max_rel",
    "omega_u_min_rel",
    "stick_time",
    "equilibrium_omega_u_rel",
    "equilibrium_omega_l_rel",
    "equilibrium_alpha_rel",
    "steady_abs",
    // Retired shared keys: none may be left in the file either.
    "omega_l_rel",
    "omega_u_rel",
    "equilibrium_rel",
];

/// [`local_scenario`] with the steady-state tolerances of its first pair commented out, except
/// those in `keep`.
fn without_steady_gates(keep: &[&str]) -> String {
    let mut s = local_scenario();
    for k in STEADY_KEYS.iter().filter(|k| !keep.contains(k)) {
        if s.lines().any(|l| l.starts_with(&format!("{k} = "))) {
            s = edit(&s, &format!("{k} = "), &format!("# {k} = "));
        }
    }
    s
}

/// One bad file: its contents and what the error message must contain.
#[derive(Clone, Debug)]
pub struct BadFile {
    /// Says which case failed: the edit (`fixture: \`from\` -> \`to\``) or a description.
    pub name: String,
    /// The whole file, bytes because some cases are not UTF-8.
    pub contents: Vec<u8>,
    /// Substrings the error message must contain (besides the path, which each harness adds).
    pub needles: Vec<&'static str>,
}

/// A case made by one [`edit`] of `fixture` (called `fixture_name` in the case's name).
fn edited(
    fixture_name: &str,
    fixture: &str,
    from: &str,
    to: &str,
    needles: &[&'static str],
) -> BadFile {
    BadFile {
        name: format!("{fixture_name}: `{from}` -> `{to}`").replace('\n', "\\n"),
        contents: edit(fixture, from, to).into_bytes(),
        needles: needles.to_vec(),
    }
}

/// A case given whole.
fn raw(name: &str, contents: impl Into<Vec<u8>>, needles: &[&'static str]) -> BadFile {
    BadFile {
        name: name.to_string(),
        contents: contents.into(),
        needles: needles.to_vec(),
    }
}

/// Bad parameter files: mutations of [`TABLE1`] and [`STRIBECK`] (unknown, missing and
/// mistyped keys, non-finite and out-of-range values, an unknown family) and empty, binary
/// and control-character files; chains in chain form that the rig's readers refuse
/// ([`CHAIN3`], which `rotor simulate --solver moreau` runs as a chain). Each is a whole
/// parameter file, to be loaded on its own.
pub fn bad_params_cases() -> Vec<BadFile> {
    let t1 = |from: &str, to: &str, needles: &[&'static str]| {
        edited("table1", TABLE1, from, to, needles)
    };
    let st = |from: &str, to: &str, needles: &[&'static str]| {
        edited("stribeck", STRIBECK, from, to, needles)
    };
    vec![
        // Unknown keys.
        t1(
            "j_u = 0.4765",
            "j_uu = 0.4765",
            &["unknown field", "j_uu", "j_uu = 0.4765"],
        ),
        t1(
            "db = 0.0",
            "db = 0.0\nbb = 1.0",
            &["unknown field", "bb", "bb = 1.0"],
        ),
        t1(
            "b = 0.0109",
            "b = 0.0109\nt_3 = 0.1",
            &["unknown field", "t_3", "t_3 = 0.1"],
        ),
        // A key of the other family.
        t1(
            "b = 0.0109",
            "b = 0.0109\ndelta = 2.0",
            &["lower.delta", "= 2", "exponential"],
        ),
        // Missing keys.
        t1("j_u = 0.4765", "", &["missing field", "j_u"]),
        t1("k_m = 3.9950", "", &["missing field", "k_m"]),
        t1("b = 2.2247", "", &["missing field", "`b`", "[upper]"]),
        t1(
            "family = \"exponential\"",
            "",
            &["missing field", "family", "[lower]"],
        ),
        t1("w_2 = 0.2941", "", &["lower.w_2", "missing"]),
        st(
            "omega_s =",
            "# omega_s =",
            &["lower.omega_s", "missing", "stribeck"],
        ),
        // Wrong types.
        t1(
            "j_u = 0.4765",
            "j_u = \"heavy\"",
            &["invalid type", "j_u = \"heavy\""],
        ),
        t1(
            "k_m = 3.9950",
            "k_m = [3.995]",
            &["invalid type", "k_m = [3.995]"],
        ),
        t1(
            "family = \"exponential\"",
            "family = 3",
            &["invalid type", "family = 3"],
        ),
        t1(
            "k_theta = 0.0727",
            "k_theta = 0.0727 0.1",
            &["k_theta = 0.0727 0.1"],
        ),
        // Non-finite values.
        t1(
            "k_theta = 0.0727",
            "k_theta = nan",
            &["k_theta = NaN", "finite"],
        ),
        t1(
            "k_theta = 0.0727",
            "k_theta = inf",
            &["k_theta = inf", "finite"],
        ),
        t1("j_u = 0.4765", "j_u = -inf", &["j_u = -inf", "finite"]),
        t1("t_2 = -0.2267", "t_2 = nan", &["lower.t_2 = NaN", "finite"]),
        t1("b = 2.2247", "b = inf", &["upper.b = inf", "finite"]),
        t1("j_l = 0.0326", "j_l = 1e999", &["j_l = 1e999", "overflow"]),
        // Out-of-range values.
        t1("j_u = 0.4765", "j_u = 0.0", &["j_u = 0", "positive"]),
        t1("j_u = 0.4765", "j_u = -1.0", &["j_u = -1", "positive"]),
        t1("j_l = 0.0326", "j_l = -0.5", &["j_l = -0.5", "positive"]),
        t1(
            "k_theta = 0.0727",
            "k_theta = 0.0",
            &["k_theta = 0", "positive"],
        ),
        t1(
            "k_theta = 0.0727",
            "k_theta = -0.07",
            &["k_theta = -0.07", "positive"],
        ),
        t1("k_m = 3.9950", "k_m = 0.0", &["k_m = 0", "non-zero"]),
        t1("t_s = 0.1642", "t_s = -0.1", &["lower.t_s = -0.1", ">= 0"]),
        t1(
            "t_s = 0.0 ",
            "t_s = -1e-3 ",
            &["upper.t_s = -0.001", ">= 0"],
        ),
        t1("dt_s = 0.0", "dt_s = 0.5", &["upper.dt_s = 0.5", "t_s"]),
        t1("b = 2.2247", "b = -2.2", &["upper.b = -2.2", ">= 0"]),
        t1("b = 0.0109", "b = -0.01", &["lower.b = -0.01", ">= 0"]),
        t1(
            "t_2 = -0.2267",
            "t_2 = -0.5",
            &["lower.t_2 = -0.5", "friction law negative"],
        ),
        t1("w_1 = 5.7468", "w_1 = 0.0", &["lower.w_1 = 0", "positive"]),
        t1(
            "w_2 = 0.2941",
            "w_2 = -0.3",
            &["lower.w_2 = -0.3", "positive"],
        ),
        st(
            "delta = 2.0575",
            "delta = 0.0",
            &["lower.delta = 0", "exponent"],
        ),
        st(
            "delta = 2.0575",
            "delta = -1.0",
            &["lower.delta = -1", "exponent"],
        ),
        st(
            "omega_s = 1.4302",
            "omega_s = 0.0",
            &["lower.omega_s = 0", "positive"],
        ),
        st(
            "t_c = 0.0473",
            "t_c = -0.05",
            &["lower.t_c = -0.05", ">= 0"],
        ),
        // Unknown friction families.
        t1(
            "\"exponential\"",
            "\"dahl\"",
            &["lower.family", "\"dahl\"", "unknown friction family"],
        ),
        t1(
            "\"exponential\"",
            "\"Exponential\"",
            &["lower.family", "\"Exponential\""],
        ),
        // Empty, binary and control-character files.
        raw("empty", "", &["empty"]),
        raw("whitespace only", "  \n\t\n", &["empty"]),
        raw("a comment only", "# only a comment\n", &["missing field"]),
        raw(
            "not UTF-8 after a line",
            &b"j_u = 0.4\n\xff\xfe\x00\x01"[..],
            &["not a UTF-8", "0xff", "offset 10"],
        ),
        raw(
            "an ELF header",
            &b"\x7fELF\x02\x01\x01\x00\xff\xfe"[..],
            &["not a UTF-8", "offset"],
        ),
        // Valid UTF-8 with a NUL byte: a binary file.
        raw(
            "a NUL byte",
            &b"j_u = 0.4\n\x00\x01\x02"[..],
            &["NUL byte", "offset 10"],
        ),
        // Control characters in the echoed source line are escaped, not printed.
        raw(
            "a BEL after a bare CR",
            &b"j_u = 0.4\rk_m \x07= 1\n"[..],
            &["\\u{7}"],
        ),
        too_large(),
        // Chain form: a chain where the rig is read (the analysis commands), and a bad value
        // of one disc.
        raw("a chain of three discs", CHAIN3, &["a chain with 3 discs"]),
        edited(
            "chain3",
            CHAIN3,
            "t_s = 0.2,",
            "t_s = -1,",
            &["disc 3: friction.t_s = -1: static level must be >= 0"],
        ),
        edited(
            "chain3",
            CHAIN3,
            "j = 0.4765",
            "j = 0.4765\nk = 1.0",
            &["disc 1: k = 1", "no disc above"],
        ),
    ]
}

/// A chain of three discs in chain form: Table 1's rig with a Stribeck disc below it.
pub const CHAIN3: &str = r#"name = "chain3"
k_m = 3.9950
[[disc]]
j = 0.4765
friction = { family = "upper", t_s = 0.0, dt_s = 0.0, b = 2.2247, db = 0.0 }
[[disc]]
j = 0.0326
k = 0.0727
friction = { family = "exponential", t_s = 0.1642, t_1 = 0.0603, t_2 = -0.2267, w_1 = 5.7468, w_2 = 0.2941, b = 0.0109 }
[[disc]]
j = 0.0326
k = 0.0727
c = 0.001
friction = { family = "stribeck", t_s = 0.2, t_c = 0.1, omega_s = 1.5, delta = 2.0, b = 0.01 }
"#;

/// 2 MiB of comment lines: valid TOML, but no parameter or scenario file is that large, and
/// the readers refuse it (at 1 MiB) before reading on.
fn too_large() -> BadFile {
    raw(
        "2 MiB of comments",
        format!("{}\n", "#".repeat(63)).repeat(1 << 15),
        &["larger than", "not a TOML file of this kind"],
    )
}

/// Bad scenario files: mutations of [`local_scenario`] (horizon, step and tolerance out of
/// range, unknown, missing and mistyped keys, non-finite values, bad `[compare]` and
/// `[tolerance]` tables, names that cannot name report files, params paths that cannot be
/// read) and empty and binary files. Each is to be written by [`write_scenario`], so that
/// `table1.toml` next to it is a good parameter file.
pub fn bad_scenario_cases() -> Vec<BadFile> {
    let s = local_scenario();
    let sc =
        |from: &str, to: &str, needles: &[&'static str]| edited("scenario", &s, from, to, needles);
    let mut v = vec![
        // Horizon, step and tolerance.
        sc("t_end = 200.0", "t_end = 0.0", &["t_end = 0", "positive"]),
        sc("t_end = 200.0", "t_end = -5.0", &["t_end = -5", "positive"]),
        sc("t_end = 200.0", "t_end = inf", &["t_end = inf"]),
        sc("t_end = 200.0", "t_end = nan", &["t_end = NaN"]),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\nh = 0.0",
            &["h = 0", "(0, t_end]"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\nh = -1e-3",
            &["h = -0.001", "(0, t_end]"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\nh = 250.0",
            &["h = 250", "(0, t_end]"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\nh = 300.0",
            &["h = 300", "(0, t_end]"],
        ),
        sc("t_end = 200.0", "t_end = 200.0\nh = nan", &["h = NaN"]),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = 0.0",
            &["tol = 0", "(0, 1)"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = -1e-6",
            &["tol = -1e-6", "(0, 1)"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = -1e-9",
            &["tol = -1e-9", "(0, 1)"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = 1.0",
            &["tol = 1", "(0, 1)"],
        ),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = 2.0",
            &["tol = 2", "(0, 1)"],
        ),
        sc("t_end = 200.0", "t_end = 200.0\ntol = nan", &["tol = NaN"]),
        sc(
            "t_end = 200.0",
            "t_end = 200.0\ntol = 1e-16",
            &["tol = 1e-16", "roundoff"],
        ),
        raw(
            "horizon shorter than the default step, without h",
            short_horizon_scenario(),
            &["t_end = 0.0005", "set h"],
        ),
        // Unknown keys. There is no solver key (every scenario runs all three solvers).
        sc(
            "t_end = 200.0",
            "t_end = 200.0\nsolver = \"rk4\"",
            &["unknown field", "solver = \"rk4\""],
        ),
        sc("u = 1.5", "uu = 1.5", &["unknown field", "uu = 1.5"]),
        sc(
            "steady_from = 100.0",
            "steady_from = 100.0\nwindow = 3",
            &["unknown field", "window = 3"],
        ),
        sc(
            "transient_rms = ",
            "transient_rsm = ",
            &["unknown field", "transient_rsm = "],
        ),
        // Missing keys.
        sc("u = 1.5", "", &["missing field", "`u`"]),
        sc("t_end = 200.0", "", &["missing field", "`t_end`"]),
        sc("name = \"t1-u1.5-rest\"", "", &["missing field", "`name`"]),
        // Wrong types.
        sc("u = 1.5", "u = \"fast\"", &["invalid type", "u = \"fast\""]),
        sc(
            "x0 = [0.0, 0.0, 0.0]",
            "x0 = [0.0, 0.0]",
            &["x0 = [0, 0]: length 2: the model's state has 3 values (alpha, omega_u, omega_l)"],
        ),
        sc(
            "x0 = [0.0, 0.0, 0.0]",
            "x0 = \"rest\"",
            &["invalid type", "x0 = \"rest\""],
        ),
        sc("\"table1.toml\"", "42", &["invalid type", "params = 42"]),
        // Non-finite values.
        sc("u = 1.5", "u = nan", &["u = NaN"]),
        sc("u = 1.5", "u = -inf", &["u = -inf"]),
        sc(
            "x0 = [0.0, 0.0, 0.0]",
            "x0 = [0.0, inf, 0.0]",
            &["x0[1] = inf"],
        ),
        sc(
            "x0 = [0.0, 0.0, 0.0]",
            "x0_from_equilibrium = [0.0, 0.0, nan]",
            &["x0_from_equilibrium[2] = NaN"],
        ),
        // [compare] and [tolerance] tables.
        sc(
            "steady_from = 100.0",
            "steady_from = 100.0\ndt = 0.0",
            &["compare.dt = 0"],
        ),
        // 200 s at 1e-12 s would be 2e14 rows: refused before any allocation.
        sc(
            "steady_from = 100.0",
            "steady_from = 100.0\ndt = 1e-12",
            &["compare.dt = 1e-12", "1e7"],
        ),
        sc(
            "transient = [0.0, 20.0]",
            "transient = [0.0, 300.0]",
            &["compare.transient = [0, 300]"],
        ),
        sc(
            "steady_from = 100.0",
            "steady_from = 250.0",
            &["compare.steady_from = 250"],
        ),
        sc(
            "transient_max = ",
            "transient_max = -",
            &["tolerance.event-switch.transient_max = -", "non-negative"],
        ),
        sc(
            "stick_time = ",
            "stick_time = inf #",
            &[
                "tolerance.event-switch.stick_time = inf",
                "non-negative and finite",
            ],
        ),
        // A window that may hold no grid sample, tolerances without the window they gate,
        // and windows without a gate: each would let a pair pass having measured nothing.
        sc(
            "transient = [0.0, 20.0]",
            "transient = [0.0, 0.005]",
            &["compare.transient = [0, 0.005]", "shorter than compare.dt"],
        ),
        sc(
            "transient = [0.0, 20.0]",
            "",
            &["transient_max = ", "needs compare.transient"],
        ),
        sc(
            "steady_from = 100.0",
            "",
            &["period_rel = ", "needs compare.steady_from"],
        ),
        sc(
            "transient_max = ",
            "# transient_max = ",
            &[
                "tolerance.event-switch.transient_max = (missing)",
                "ungated",
            ],
        ),
        // A cycle gated without one of its metrics, or a steady state without any gate.
        sc(
            "period_rel = ",
            "# period_rel = ",
            &[
                "tolerance.event-switch.period_rel = (missing)",
                "other cycle tolerances",
            ],
        ),
        // A retired shared key: refused with the keys that replaced it, never read as one.
        sc(
            "period_rel = ",
            "omega_u_rel = 2e-11\nperiod_rel = ",
            &[
                "tolerance.event-switch.omega_u_rel = 2e-11",
                "retired",
                "omega_u_max_rel and omega_u_min_rel",
            ],
        ),
        raw(
            "the steady floor without a steady tolerance",
            without_steady_gates(&["steady_abs"]),
            &["tolerance.event-switch.steady_abs = ", "needs one of them"],
        ),
        raw(
            "no steady tolerance while compare.steady_from is set",
            without_steady_gates(&[]),
            &[
                "tolerance.event-switch.equilibrium_omega_u_rel = (missing)",
                "ungated",
            ],
        ),
        // A pair is named <reference>-<solver> (which solvers exist, the runner knows:
        // `bad_pair_cases`).
        sc(
            "[tolerance.event-switch]",
            "[tolerance.event_switch]",
            &["tolerance = \"event_switch\"", "<reference>-<solver>"],
        ),
    ];
    // Names that cannot name report files.
    for (to, needle) in [
        ("name = \"\"", "name = \"\""),
        ("name = \"../escape\"", "name = \"../escape\""),
        ("name = \"a/b\"", "name = \"a/b\""),
        ("name = \".hidden\"", "name = \".hidden\""),
        ("name = \"a b\"", "name = \"a b\""),
        ("name = \"x\\\\y\"", "name = "),
    ] {
        v.push(sc("name = \"t1-u1.5-rest\"", to, &[needle, "report"]));
    }
    v.extend([
        // Params paths that cannot be read: the scenario file, the params file and the OS
        // reason. A newline (legal in a Unix file name) is escaped: the message stays one line.
        sc(
            "\"table1.toml\"",
            "\"nothere.toml\"",
            &["params", "nothere.toml", "cannot read parameter file"],
        ),
        sc(
            "\"table1.toml\"",
            "\"\"\"two\nlines.toml\"\"\"",
            &["two\\nlines.toml", "cannot read parameter file"],
        ),
        // Empty and binary files.
        raw("empty", "", &["empty"]),
        raw("blank lines only", "\n\n   \n", &["empty"]),
        raw(
            "a PNG signature",
            &b"\x89PNG\r\n\x1a\n\x00\x00"[..],
            &["not a UTF-8", "0x89", "offset 0"],
        ),
        raw(
            "a PNG signature and IHDR",
            &b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"[..],
            &["not a UTF-8"],
        ),
        raw(
            "a NUL byte",
            &b"name = \"a\"\n\x00"[..],
            &["NUL byte", "offset 11"],
        ),
        too_large(),
    ]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_prefers_a_line_start_and_skips_comments() {
        let text = "# a = 1 in a comment\nb = 2 # a = 1 here too\na = 1\n";
        // The line that starts with the key wins over earlier occurrences.
        assert_eq!(
            edit(text, "a = 1", "a = 7"),
            "# a = 1 in a comment\nb = 2 # a = 1 here too\na = 7\n"
        );
        // Otherwise the first occurrence outside a comment.
        assert_eq!(edit("x = [a, b] # a\n", "b", "c"), "x = [a, c] # a\n");
    }

    #[test]
    #[should_panic(expected = "no longer contains")]
    fn edit_refuses_a_string_found_only_in_a_comment() {
        edit("# k = 1\n", "k = 1", "k = 2");
    }

    /// Every case is a real change of its fixture (a case equal to a good file would test
    /// nothing), has a name unique in its list (failures say which case) and a needle.
    #[test]
    fn every_case_changes_its_file_and_names_what_to_find() {
        let good: Vec<Vec<u8>> = [TABLE1, STRIBECK, SCENARIO, &local_scenario()]
            .iter()
            .map(|t| t.as_bytes().to_vec())
            .collect();
        for list in [bad_params_cases(), bad_scenario_cases()] {
            let mut names = std::collections::HashSet::new();
            for c in &list {
                assert!(!good.contains(&c.contents), "{}: unchanged fixture", c.name);
                assert!(!c.needles.is_empty(), "{}: no needle", c.name);
                assert!(names.insert(c.name.clone()), "{}: name used twice", c.name);
            }
            // 46 parameter and 51 scenario cases today: a list that shrinks below 40 has lost
            // cases by accident (an edit that drops entries), not by design.
            assert!(names.len() >= 40, "{} cases", names.len());
        }
    }

    #[test]
    fn tmp_dirs_are_fresh() {
        let (a, b) = (tmp_dir("rotor-testkit"), tmp_dir("rotor-testkit"));
        assert!(a != b && a.is_dir() && b.is_dir());
        let f = write_scenario(&a, local_scenario().as_bytes());
        assert!(f.is_file() && a.join("table1.toml").is_file());
    }
}
