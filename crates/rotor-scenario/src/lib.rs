//! The scenario files: the fixtures' TOML format (one scene, run by every solver), each
//! section validated on its own, and the comparison settings they carry (`[compare]`, the
//! `[tolerance.<pair>]` gates), which no solver reads.
//!
//! See docs/design.md, "Fixtures", and [`scenario`] for the format.

pub mod scenario;

pub use scenario::{
    CYCLE_KEYS, CompareSpec, EQUILIBRIUM_KEYS, PairTolerance, RETIRED_KEYS, STEADY_QUANTITIES,
    Scenario, ScenarioError, SteadyQuantity, TOLERANCE_KEYS,
};
