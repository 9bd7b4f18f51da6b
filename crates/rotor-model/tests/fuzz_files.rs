//! Malformed and random parameter files: mutations of the real ones
//! ([`rotor_testkit::mutate`]). Reading a mutant never panics; it gives either an admissible
//! parameter set or an error whose message is one line and names the file. (Scenario files
//! are fuzzed in rotor_model::scenario's tests/fuzz_files.rs.)
//!
//! "Admissible" is checked independently of the loader: parameters pass `Params::validate`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use proptest::prelude::*;
use rotor_model::Params;
use rotor_testkit::mutate::{Mutation, apply, mutation};

/// The real parameter files, as `(relative path, text)`.
fn fixtures() -> &'static Vec<(String, String)> {
    static F: OnceLock<Vec<(String, String)>> = OnceLock::new();
    F.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
        let mut v = Vec::new();
        for sub in ["params"] {
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
        assert!(v.len() >= 2, "fixtures found: {}", v.len());
        v
    })
}

/// A scratch directory for the mutants.
fn scratch() -> &'static PathBuf {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| rotor_testkit::tmp_dir("rotor-model-fuzz"))
}

/// Reads a mutant of fixture `which` through `from_file` and checks the contract.
fn check(which: usize, muts: &[Mutation]) -> Result<(), TestCaseError> {
    let (_, text) = &fixtures()[which % fixtures().len()];
    let mut bytes = text.clone().into_bytes();
    for m in muts {
        bytes = apply(bytes, m);
    }
    let path = scratch().join(format!(
        "mutant-{}-{:?}.toml",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::write(&path, &bytes).unwrap();
    match Params::from_file(&path) {
        Ok(p) => prop_assert!(p.validate().is_ok(), "loaded but inadmissible: {p:?}"),
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(
                !msg.contains('\n') && !msg.contains('\r'),
                "not one line: {msg}"
            );
            let p = path.display().to_string();
            prop_assert!(msg.starts_with(&p), "does not name the file: {msg}");
        }
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
        bytes in prop::collection::vec(any::<u8>(), 0..256),
    ) {
        // Not a mutation of a fixture: pure noise.
        let path = scratch().join(format!("noise-{:?}.toml", std::thread::current().id()));
        std::fs::write(&path, &bytes).unwrap();
        let msg = Params::from_file(&path).map(|_| ()).map_err(|e| e.to_string());
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
