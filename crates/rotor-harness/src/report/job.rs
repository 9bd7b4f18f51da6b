//! The runs of a report and its analysis sections, in parallel, and the report written.

use std::path::Path;

use crate::compare::report::Section;
use rotor_analysis::solvers::ScenarioResult;
use rotor_model::Params;
use rotor_model::scenario::Scenario;

use crate::report::{
    ReportError, bifurcation_section, figure3_section, plane_section, probe_section, stress_section,
};

/// A parameter set of the analysis sections: its name in the report, the slug of its files,
/// and the parameters.
pub type ParamSet<'a> = (&'a str, &'a str, Params);

/// The two parameter sets the main job analyses: Table 1 and the Stribeck set.
pub fn param_sets(stribeck: Params) -> [ParamSet<'static>; 2] {
    [
        ("Table 1", "table1", Params::table1()),
        ("Stribeck set", "stribeck", stribeck),
    ]
}

/// Refuses two scenarios of one name: report files are named after the scenarios, so they
/// would overwrite each other.
pub fn check_names(scenarios: &[Scenario]) -> Result<(), ReportError> {
    for (i, a) in scenarios.iter().enumerate() {
        if let Some(b) = scenarios[..i].iter().find(|b| b.name == a.name) {
            return Err(ReportError::DuplicateName {
                path: a.path.clone(),
                name: a.name.clone(),
                other: b.path.clone(),
            });
        }
    }
    Ok(())
}

/// The main job's analysis sections of `sets`, computed in parallel, in the report's order:
/// bifurcation diagrams, the diagrams by three methods, two parameters, stress, probes. The
/// diagrams first (with the stress cases beside them), since the probes, the planes and the
/// three-method diagrams start from them; then those three together (probes beside the
/// planes and the three-method diagrams, the longest first), so both cores stay busy until
/// the end.
pub fn sections(sets: &[ParamSet]) -> Result<Vec<Section>, ReportError> {
    let (bif, stress) = rayon::join(|| bifurcation_section(sets), stress_section);
    let (bif, diagrams) = bif?;
    let (probes, (plane, fig3)) = rayon::join(
        || probe_section(sets, &diagrams),
        || {
            rayon::join(
                || plane_section(sets, &diagrams),
                || figure3_section(sets, &diagrams),
            )
        },
    );
    Ok(vec![bif, fig3, plane?, stress, probes])
}

/// What [`run`] computed: each scenario's runs, in input order, and the sections.
#[derive(Debug)]
pub struct Compared {
    /// Every scenario through every solver, in the order given.
    pub results: Vec<ScenarioResult>,
    /// The analysis sections ([`sections`]); none for a plain `rotor compare`.
    pub sections: Vec<Section>,
}

/// Every scenario through every solver, in parallel, and with `main_job` the analysis
/// sections of `sets` beside them; `on_scenario` is called as each scenario's runs end (a
/// progress bar). Collected in input order, so the output is deterministic.
pub fn run(
    scenarios: &[Scenario],
    sets: &[ParamSet],
    main_job: bool,
    on_scenario: &(dyn Fn() + Sync),
) -> Result<Compared, ReportError> {
    use rayon::prelude::*;
    // In parallel across scenarios (and with the diagrams); collected in input order, so the
    // output is deterministic.
    let (results, sections) = rayon::join(
        || {
            scenarios
                .par_iter()
                .map(|sc| {
                    let r = rotor_analysis::solvers::run_scenario(sc);
                    on_scenario();
                    r
                })
                .collect::<Vec<_>>()
        },
        || -> Result<Vec<Section>, ReportError> {
            if main_job {
                sections(sets)
            } else {
                Ok(Vec::new())
            }
        },
    );
    Ok(Compared {
        results,
        sections: sections?,
    })
}

/// Writes the report of `compared`, a run of `scenes`, to `dir`
/// ([`crate::compare::report::write_report`], with the friction curves of Table 1 and of
/// `stribeck`); returns the failed agreement gates.
pub fn write(
    dir: &Path,
    compared: &Compared,
    stribeck: Params,
    scenes: crate::compare::report::Scenes,
) -> Result<Vec<crate::compare::Failure>, ReportError> {
    let params = [
        ("Table 1 (exponential)", Params::table1()),
        ("Stribeck set (unverified)", stribeck),
    ];
    crate::compare::report::write_report(
        dir,
        &compared.results,
        &params,
        &compared.sections,
        scenes,
    )
    .map_err(|source| ReportError::Write {
        dir: dir.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario(name: &str) -> Scenario {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
        rotor_analysis::solvers::load_scenario(&dir.join(format!("{name}.toml"))).unwrap()
    }

    /// Two scenarios of one name are refused, naming both files; distinct names pass.
    #[test]
    fn a_name_twice_is_refused_naming_both_files() {
        let a = scenario("t1-u1.5-rest");
        let b = scenario("t1-u0.3-rest");
        assert!(check_names(&[a.clone(), b.clone()]).is_ok());
        let mut twin = b.clone();
        twin.path = "elsewhere/twin.toml".into();
        let e = check_names(&[a, b.clone(), twin]).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "elsewhere/twin.toml: name = \"{}\": also the name of {}",
                b.name,
                b.path.display()
            )
        );
    }
}
