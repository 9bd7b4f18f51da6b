//! Bad parameter files: every kind of bad input is an error, never a panic, and its message
//! is one line that names the file, the field and the offending value. (Bad scenario files
//! are rotor_model::scenario's tests/bad_input.rs; bad scenes, rotor_model::seam's.)
//!
//! Each case is a mutation of a real fixture file, written to a temporary directory and read
//! back through `from_file`, so that the path in the message is the path of the file. The
//! cases that the `rotor` binary is held to as well are in `rotor-testkit`
//! ([`bad_params_cases`]); the ones here are the library's own.

use rotor_model::Params;
use rotor_testkit::{STRIBECK, TABLE1, bad_params_cases, check_message, edit, tmp_dir};

/// Writes a parameter file and expects an error.
fn params_err(what: &str, text: &[u8], needles: &[&str]) {
    let path = tmp_dir("rotor-model-bad-input").join("p.toml");
    std::fs::write(&path, text).unwrap();
    match Params::from_file(&path) {
        Ok(p) => panic!(
            "{what}: accepted {p:?} from {}",
            String::from_utf8_lossy(text)
        ),
        Err(e) => check_message(what, &e.to_string(), &path, needles),
    }
}

#[test]
fn the_unmutated_files_load() {
    // Guards every case: each one differs from a file that loads only by its mutation.
    let dir = tmp_dir("rotor-model-bad-input");
    std::fs::write(dir.join("table1.toml"), TABLE1).unwrap();
    std::fs::write(dir.join("st.toml"), STRIBECK).unwrap();
    Params::from_file(&dir.join("table1.toml")).unwrap();
    Params::from_file(&dir.join("st.toml")).unwrap();
}

#[test]
fn bad_parameter_files() {
    let cases = bad_params_cases();
    assert!(!cases.is_empty());
    for c in &cases {
        params_err(&c.name, &c.contents, &c.needles);
    }
}

#[test]
fn a_missing_key_is_not_quoted_from_a_comment() {
    let path = tmp_dir("rotor-model-bad-input").join("p.toml");
    std::fs::write(&path, edit(TABLE1, "j_u = 0.4765", "")).unwrap();
    let e = Params::from_file(&path).unwrap_err().to_string();
    assert!(!e.contains("(in `#"), "{e}");
}

#[test]
fn params_paths_that_cannot_be_read() {
    let missing = tmp_dir("rotor-model-bad-input").join("nothere.toml");
    let e = Params::from_file(&missing).unwrap_err().to_string();
    check_message("missing file", &e, &missing, &["cannot read"]);
    let dir = tmp_dir("rotor-model-bad-input");
    let e = Params::from_file(&dir).unwrap_err().to_string();
    check_message("a directory", &e, &dir, &["cannot read"]);
}

#[test]
fn control_characters_in_params_paths_are_escaped() {
    // (A newline in a scenario's params path is a shared scenario case.)
    let odd = tmp_dir("rotor-model-bad-input").join("a\rb.toml");
    let e = Params::from_file(&odd).unwrap_err().to_string();
    assert!(!e.contains('\r') && e.contains("a\\rb.toml"), "{e}");
}
