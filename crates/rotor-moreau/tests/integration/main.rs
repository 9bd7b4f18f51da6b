//! Integration tests of the Moreau–Jean solver (one test binary).

mod fallback;
mod output;
mod properties;
mod scenarios;

use rotor_model::scenario::Scenario;
use rotor_model::{Model, Params};
use std::path::{Path, PathBuf};

/// The fixture directory of the workspace.
pub fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

/// Every scenario fixture.
pub fn scenarios() -> Vec<Scenario> {
    Scenario::list_dir(&fixtures().join("scenarios"))
        .expect("fixture directory")
        .iter()
        .map(|p| Scenario::from_file(p).expect("valid scenario"))
        .collect()
}

/// The Stribeck model of the fixtures.
pub fn stribeck() -> Model {
    Model::new(Params::from_file(&fixtures().join("params/stribeck.toml")).expect("stribeck"))
}
