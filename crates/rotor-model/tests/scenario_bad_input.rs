//! Bad scenario files: every kind of bad input is an error, never a panic, and its message
//! is one line that names the file, the field and the offending value.
//!
//! Each case is a mutation of a real fixture file, written to a temporary directory and read
//! back through `from_file`, so that the path in the message is the path of the file. The
//! cases that the `rotor` binary is held to as well are in `rotor-testkit`
//! ([`bad_scenario_cases`]); the ones here are the library's own.

use rotor_model::scenario::Scenario;
use rotor_testkit::{
    TABLE1, bad_scenario_cases, check_message, edit, local_scenario, short_horizon_scenario,
    tmp_dir, write_scenario,
};

/// Writes a scenario (and a good Table 1 parameter file next to it) and expects an error.
fn scenario_err(what: &str, text: &[u8], needles: &[&str]) -> String {
    let path = write_scenario(&tmp_dir("rotor-scenario-bad-input"), text);
    match Scenario::from_file(&path) {
        Ok(s) => panic!(
            "{what}: accepted {}: {}",
            s.name,
            String::from_utf8_lossy(text)
        ),
        Err(e) => {
            let msg = e.to_string();
            check_message(what, &msg, &path, needles);
            msg
        }
    }
}

#[test]
fn the_unmutated_file_loads() {
    // Guards every case: each one differs from a file that loads only by its mutation.
    Scenario::from_file(&write_scenario(
        &tmp_dir("rotor-scenario-bad-input"),
        local_scenario().as_bytes(),
    ))
    .unwrap();
}

#[test]
fn bad_scenario_files() {
    let cases = bad_scenario_cases();
    assert!(!cases.is_empty());
    for c in &cases {
        scenario_err(&c.name, &c.contents, &c.needles);
    }
}

#[test]
fn a_short_horizon_loads_once_h_is_set() {
    // The shared case refuses `short_horizon_scenario()` for the missing h alone.
    let path = write_scenario(
        &tmp_dir("rotor-scenario-bad-input"),
        edit(
            &short_horizon_scenario(),
            "t_end = 5e-4",
            "t_end = 5e-4\nh = 1e-4",
        )
        .as_bytes(),
    );
    Scenario::from_file(&path).unwrap();
}

#[test]
fn scenario_params_path_and_bad_params_file() {
    let s = local_scenario();
    // The shared case checks the scenario file, the params file and the OS reason; the
    // params file is named once.
    let e = scenario_err(
        "params path does not exist",
        edit(&s, "\"table1.toml\"", "\"nothere.toml\"").as_bytes(),
        &["nothere.toml"],
    );
    assert_eq!(e.matches("nothere.toml").count(), 1, "{e}");
    // A parameter file with a bad value: named through the scenario.
    let dir = tmp_dir("rotor-scenario-bad-input");
    std::fs::write(
        dir.join("bad.toml"),
        edit(TABLE1, "j_l = 0.0326", "j_l = 0.0"),
    )
    .unwrap();
    let path = write_scenario(&dir, edit(&s, "\"table1.toml\"", "\"bad.toml\"").as_bytes());
    let e = Scenario::from_file(&path).unwrap_err().to_string();
    check_message(
        "bad params file",
        &e,
        &path,
        &["bad.toml", "j_l = 0", "positive"],
    );
}

#[test]
fn a_missing_scenario_file() {
    let missing = tmp_dir("rotor-scenario-bad-input").join("nothere.toml");
    let e = Scenario::from_file(&missing).unwrap_err().to_string();
    check_message("missing file", &e, &missing, &["cannot read scenario file"]);
}

/// An input file whose name holds a line break (a fuzzed file found it): the message escapes
/// the name and stays one line.
#[test]
fn an_input_file_named_with_a_line_break_is_one_line() {
    let text = edit(
        &local_scenario(),
        "u = 1.5 ",
        "input = \"\"\"two\nlines\"\"\" ",
    );
    scenario_err(
        "input file with a line break",
        text.as_bytes(),
        &["input", "two\\nlines"],
    );
}
