//! The scenario files: the fixtures' TOML format (one scene, run by every solver), each
//! section validated on its own, and the comparison settings they carry (`[compare]`, the
//! `[tolerance.<pair>]` gates), which no solver reads.
//!
//! See docs/design.md, "Fixtures", and [`scene_file`] for the format; [`tolerance`] holds the
//! `[tolerance.<pair>]` tables.

#![warn(missing_docs)]

pub mod chain_scene;
pub mod compare;
pub mod error;
pub mod scene_file;
pub mod tolerance;

pub use chain_scene::ChainScenario;
pub use compare::CompareSpec;
pub use error::ScenarioError;
pub use scene_file::Scenario;
pub use tolerance::{
    CYCLE_KEYS, EQUILIBRIUM_KEYS, PairTolerance, RETIRED_KEYS, STEADY_QUANTITIES, SteadyQuantity,
    TOLERANCE_KEYS, WHOLE_KEYS,
};
