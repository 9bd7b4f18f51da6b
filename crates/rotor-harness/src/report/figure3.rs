//! The section with Figure 3 by the three methods ([`rotor_analysis::steady::figure3`]).

use rotor_model::{Model, Params};

/// The report section with the bifurcation diagram by the event-driven solver, the switch
/// model and Moreau–Jean overlaid, and each special point by each method against its gate.
pub fn figure3_section(
    sets: &[(&str, &str, Params)],
    diagrams: &[rotor_analysis::bifurcation::Diagram],
) -> crate::compare::report::Section {
    let models: Vec<Model> = sets.iter().map(|(_, _, p)| Model::new(*p)).collect();
    let s: Vec<_> = (sets.iter().zip(&models).zip(diagrams))
        .map(|(((n, g, _), m), d)| (*n, *g, m, d))
        .collect();
    let r = rotor_analysis::steady::figure3::figure3_section(&s);
    crate::compare::report::Section {
        markdown: r.markdown,
        files: r.files,
        failures: r.failures,
        timings: r.timings,
    }
}
