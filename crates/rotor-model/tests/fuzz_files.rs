//! Malformed and random fixture text: mutations of the real parameter and scenario
//! files (deleted, duplicated and swapped lines, swapped values, random TOML values, random
//! bytes, truncation). Reading a mutant never panics; it gives either an admissible parameter
//! set / scenario, or an error whose message is one line and names the file.
//!
//! "Admissible" is checked independently of the loader: parameters pass `Params::validate`,
//! and a loaded scenario yields a `Scene` that the solvers accept (`Scene::validate`) at the
//! settings rotor-solvers runs it with (its own `tol`/`h`, else the defaults).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use proptest::prelude::*;
use rotor_model::{Output, Params, Scenario, Scene};

/// The real fixture files, as `(relative path, text)`.
fn fixtures() -> &'static Vec<(String, String)> {
    static F: OnceLock<Vec<(String, String)>> = OnceLock::new();
    F.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
        let mut v = Vec::new();
        for sub in ["params", "scenarios"] {
            let mut files: Vec<PathBuf> = std::fs::read_dir(root.join(sub))
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect();
            files.sort();
            for f in files {
                let name = format!("{sub}/{}", f.file_name().unwrap().to_string_lossy());
                v.push((name, std::fs::read_to_string(&f).unwrap()));
            }
        }
        assert!(v.len() >= 16, "fixtures found: {}", v.len());
        v
    })
}

/// A scratch copy of `fixtures/params` so that mutated scenarios resolve their params path.
fn scratch() -> &'static PathBuf {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("rotor-model-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(d.join("params")).unwrap();
        std::fs::create_dir_all(d.join("scenarios")).unwrap();
        for (name, text) in fixtures() {
            if name.starts_with("params/") {
                std::fs::write(d.join(name), text).unwrap();
            }
        }
        d
    })
}

/// TOML values of every type, and the numbers that break naive range checks.
fn toml_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("+inf".to_string()),
        Just("-inf".to_string()),
        Just("-0.0".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("1e-320".to_string()),
        Just("1e999".to_string()),
        Just("true".to_string()),
        Just("\"\"".to_string()),
        Just("\"stribeck\"".to_string()),
        Just("'../params/table1.toml'".to_string()),
        Just("[]".to_string()),
        Just("[1.0, 2.0]".to_string()),
        Just("[0.0, 0.0, 0.0, 0.0]".to_string()),
        Just("{ a = 1 }".to_string()),
        Just("1979-05-27T07:32:00Z".to_string()),
        Just("\"\"\"two\nlines\"\"\"".to_string()),
        Just("0x10".to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        (-1e3..1e3f64).prop_map(|v| format!("{v}")),
        "[a-z_]{0,8}".prop_map(|s| format!("\"{s}\"")),
    ]
}

/// One edit of a file's lines or bytes.
#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    /// Swap the values of two `key = value` lines.
    SwapValues(usize, usize),
    /// Replace the value of a `key = value` line.
    SetValue(usize, String),
    /// Insert a `key = value` line with a random key.
    InsertKey(usize, String, String),
    InsertBytes(usize, Vec<u8>),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let i = || any::<prop::sample::Index>();
    prop_oneof![
        i().prop_map(|i| Mutation::DeleteLine(i.index(1 << 16))),
        i().prop_map(|i| Mutation::DuplicateLine(i.index(1 << 16))),
        (i(), i()).prop_map(|(a, b)| Mutation::SwapLines(a.index(1 << 16), b.index(1 << 16))),
        (i(), i()).prop_map(|(a, b)| Mutation::SwapValues(a.index(1 << 16), b.index(1 << 16))),
        (i(), toml_value()).prop_map(|(a, v)| Mutation::SetValue(a.index(1 << 16), v)),
        (i(), "[a-z_]{1,8}", toml_value()).prop_map(|(a, k, v)| Mutation::InsertKey(
            a.index(1 << 16),
            k,
            v
        )),
        (i(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(a, b)| Mutation::InsertBytes(a.index(1 << 16), b)),
        i().prop_map(|i| Mutation::Truncate(i.index(1 << 16))),
    ]
}

/// Splits `key = value # comment` into (key part, value); `None` for other lines.
fn split_kv(line: &str) -> Option<(&str, &str)> {
    let (k, rest) = line.split_once('=')?;
    let v = rest.split('#').next().unwrap_or(rest).trim();
    Some((k, v))
}

fn apply(bytes: Vec<u8>, m: &Mutation) -> Vec<u8> {
    if let Mutation::InsertBytes(at, b) = m {
        let at = at % (bytes.len() + 1);
        let mut out = bytes[..at].to_vec();
        out.extend_from_slice(b);
        out.extend_from_slice(&bytes[at..]);
        return out;
    }
    if let Mutation::Truncate(at) = m {
        return bytes[..at % (bytes.len() + 1)].to_vec();
    }
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    if lines.is_empty() {
        return bytes;
    }
    let n = lines.len();
    // Indices of `key = value` lines, for the value mutations.
    let kv: Vec<usize> = (0..n).filter(|&i| split_kv(&lines[i]).is_some()).collect();
    match m {
        Mutation::DeleteLine(i) => {
            lines.remove(i % n);
        }
        Mutation::DuplicateLine(i) => {
            let l = lines[i % n].clone();
            lines.insert(i % n, l);
        }
        Mutation::SwapLines(a, b) => lines.swap(a % n, b % n),
        Mutation::SwapValues(a, b) if !kv.is_empty() => {
            let (a, b) = (kv[a % kv.len()], kv[b % kv.len()]);
            let (ka, va) = split_kv(&lines[a])
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .unwrap();
            let (kb, vb) = split_kv(&lines[b])
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .unwrap();
            lines[a] = format!("{ka}= {vb}");
            lines[b] = format!("{kb}= {va}");
        }
        Mutation::SetValue(a, v) if !kv.is_empty() => {
            let a = kv[a % kv.len()];
            let k = split_kv(&lines[a]).unwrap().0.to_owned();
            lines[a] = format!("{k}= {v}");
        }
        Mutation::InsertKey(a, k, v) => lines.insert(a % (n + 1), format!("{k} = {v}")),
        _ => {}
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out.into_bytes()
}

/// Reads a mutant of fixture `which` through `from_file` and checks the contract.
fn check(which: usize, muts: &[Mutation]) -> Result<(), TestCaseError> {
    let (name, text) = &fixtures()[which % fixtures().len()];
    let mut bytes = text.clone().into_bytes();
    for m in muts {
        bytes = apply(bytes, m);
    }
    // Mutants go next to the originals, so that `../params/...` resolves as in the fixtures.
    let sub = if name.starts_with("params/") {
        "params"
    } else {
        "scenarios"
    };
    let path = scratch().join(sub).join(format!(
        "mutant-{}-{:?}.toml",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::write(&path, &bytes).unwrap();
    let message = if sub == "params" {
        match Params::from_file(&path) {
            Ok(p) => {
                prop_assert!(p.validate().is_ok(), "loaded but inadmissible: {p:?}");
                None
            }
            Err(e) => Some(e.to_string()),
        }
    } else {
        match Scenario::from_file(&path) {
            Ok(sc) => {
                prop_assert!(sc.model.params.validate().is_ok());
                // The settings rotor-solvers runs a scenario with (run.rs solver_settings).
                let d = Scene::default();
                for (tol, h) in [
                    (1e-12, d.h),
                    (sc.tol.unwrap_or(1e-10), d.h),
                    (d.tol, sc.h.unwrap_or(1e-3)),
                ] {
                    let scene = Scene {
                        tol,
                        h,
                        ..sc.scene(Output::Grid { dt: sc.compare.dt })
                    };
                    prop_assert!(
                        scene.validate().is_ok(),
                        "scenario loads but its scene is refused: {}",
                        scene.validate().unwrap_err()
                    );
                }
                None
            }
            Err(e) => Some(e.to_string()),
        }
    };
    if let Some(msg) = message {
        prop_assert!(
            !msg.contains('\n') && !msg.contains('\r'),
            "not one line: {msg}"
        );
        let p = path.display().to_string();
        prop_assert!(msg.starts_with(&p), "does not name the file: {msg}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn mutated_fixtures_load_or_fail_with_a_one_line_message(
        which in any::<prop::sample::Index>(),
        muts in prop::collection::vec(mutation(), 1..4),
    ) {
        check(which.index(1 << 16), &muts)?;
    }

    #[test]
    fn random_bytes_fail_with_a_one_line_message(
        which in any::<bool>(),
        bytes in prop::collection::vec(any::<u8>(), 0..256),
    ) {
        // Not a mutation of a fixture: pure noise, under both readers.
        let dir = scratch().join(if which { "params" } else { "scenarios" });
        let path = dir.join(format!("noise-{:?}.toml", std::thread::current().id()));
        std::fs::write(&path, &bytes).unwrap();
        let msg = if which {
            Params::from_file(&path).map(|_| ()).map_err(|e| e.to_string())
        } else {
            Scenario::from_file(&path).map(|_| ()).map_err(|e| e.to_string())
        };
        let msg = msg.expect_err("noise is not a valid file");
        prop_assert!(!msg.contains('\n') && !msg.contains('\r'), "not one line: {msg}");
        prop_assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    }
}

#[test]
fn each_mutation_kind_changes_the_file() {
    // The strategy is not vacuous: every kind edits a fixture (so the property above is
    // exercised on text that differs from the originals).
    let text = fixtures()[0].1.clone().into_bytes();
    for m in [
        Mutation::DeleteLine(3),
        Mutation::DuplicateLine(3),
        Mutation::SwapLines(5, 9),
        Mutation::SwapValues(0, 3),
        Mutation::SetValue(2, "nan".into()),
        Mutation::InsertKey(4, "zz".into(), "1".into()),
        Mutation::InsertBytes(10, vec![0xff]),
        Mutation::Truncate(40),
    ] {
        assert_ne!(apply(text.clone(), &m), text, "{m:?}");
    }
}
