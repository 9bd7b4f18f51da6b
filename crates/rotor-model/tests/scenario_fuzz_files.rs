//! Malformed and random scenario files: mutations of the real ones
//! ([`rotor_testkit::mutate`]). Reading a mutant never panics; it gives either an admissible
//! scenario or an error whose message is one line and names the file. (Parameter files are
//! fuzzed in rotor-model's tests/fuzz_files.rs.)
//!
//! "Admissible" is checked independently of the loader: its parameters pass
//! `Params::validate`, and a loaded scenario yields a `Scene` that the solvers accept (`Scene::validate`) at the
//! settings rotor_analysis::solvers runs it with (its own `tol`/`h`, else the defaults).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use proptest::prelude::*;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Accuracy, Output, Scene};
use rotor_testkit::mutate::{Mutation, apply, mutation};

/// The real scenario files, as `(relative path, text)`.
fn fixtures() -> &'static Vec<(String, String)> {
    static F: OnceLock<Vec<(String, String)>> = OnceLock::new();
    F.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
        let mut v = Vec::new();
        for sub in ["scenarios"] {
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
        assert!(v.len() >= 14, "fixtures found: {}", v.len());
        v
    })
}

/// A scratch copy of `fixtures/params` so that mutated scenarios resolve their params path.
fn scratch() -> &'static PathBuf {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = rotor_testkit::tmp_dir("rotor-scenario-fuzz");
        std::fs::create_dir_all(d.join("params")).unwrap();
        std::fs::create_dir_all(d.join("scenarios")).unwrap();
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/params");
        for f in std::fs::read_dir(root).unwrap() {
            let f = f.unwrap().path();
            std::fs::copy(&f, d.join("params").join(f.file_name().unwrap())).unwrap();
        }
        d
    })
}

/// Reads a mutant of fixture `which` through `from_file` and checks the contract.
fn check(which: usize, muts: &[Mutation]) -> Result<(), TestCaseError> {
    let (_, text) = &fixtures()[which % fixtures().len()];
    let mut bytes = text.clone().into_bytes();
    for m in muts {
        bytes = apply(bytes, m);
    }
    // Mutants go next to the originals, so that `../params/...` resolves as in the fixtures.
    let path = scratch().join("scenarios").join(format!(
        "mutant-{}-{:?}.toml",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::write(&path, &bytes).unwrap();
    let message = match Scenario::from_file(&path) {
        Ok(sc) => {
            prop_assert!(sc.model.params.validate().is_ok());
            // The settings rotor_analysis::solvers runs a scenario with (run.rs solver_setting).
            for accuracy in [
                Accuracy::Tol(1e-12),
                Accuracy::Tol(sc.tol.unwrap_or(1e-10)),
                Accuracy::Step(sc.h.unwrap_or(1e-3)),
            ] {
                let scene = Scene {
                    accuracy,
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
        bytes in prop::collection::vec(any::<u8>(), 0..256),
    ) {
        // Not a mutation of a fixture: pure noise.
        let path = scratch()
            .join("scenarios")
            .join(format!("noise-{:?}.toml", std::thread::current().id()));
        std::fs::write(&path, &bytes).unwrap();
        let msg = Scenario::from_file(&path).map(|_| ()).map_err(|e| e.to_string());
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
