//! What the test modules share: the fixture models and the two default diagrams, each
//! computed once for the whole test binary (they take seconds).

use std::sync::OnceLock;

use rotor_analysis::bifurcation::continuation::ContOptions;
use rotor_analysis::bifurcation::{Diagram, DiagramOptions, SpecialPoint, diagram};
use rotor_model::{Model, Params};

/// The model of `fixtures/params/{name}.toml`.
pub fn model(name: &str) -> Model {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../fixtures/params/{name}.toml"));
    Model::new(Params::from_file(&p).unwrap())
}

/// Continuation over [0, 7] V as the tests run it: the given arclength cap, Newton
/// tolerance and node count; the rest is the diagram's (h_min 1e-9, amp_stop 0.02 rad/s,
/// FD step 1e-6).
pub fn cont_options(h_max: f64, newton_tol: f64, max_nodes: usize) -> ContOptions {
    ContOptions {
        u_min: 0.0,
        u_max: 7.0,
        h_max,
        h_min: 1e-9,
        newton_tol,
        amp_stop: 0.02,
        max_nodes,
        fd_step: 1e-6,
        multipliers: Default::default(),
    }
}

/// The default diagram of Table 1.
pub fn t1_diagram() -> &'static Diagram {
    static D: OnceLock<Diagram> = OnceLock::new();
    D.get_or_init(|| diagram(&model("table1"), &DiagramOptions::default()).unwrap())
}

/// The default diagram of the Stribeck set.
pub fn st_diagram() -> &'static Diagram {
    static D: OnceLock<Diagram> = OnceLock::new();
    D.get_or_init(|| diagram(&model("stribeck"), &DiagramOptions::default()).unwrap())
}

/// The special points of one kind, by increasing u.
pub fn points<'a>(d: &'a Diagram, kind: &str) -> Vec<&'a SpecialPoint> {
    let mut v: Vec<_> = d
        .points
        .iter()
        .filter(|p| p.kind.as_str() == kind)
        .collect();
    v.sort_by(|a, b| a.u.total_cmp(&b.u));
    v
}
