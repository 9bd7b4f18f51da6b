//! The section with the numerical stress cases (fast form).

/// The report section with the numerical stress cases in their fast form (the full form:
/// `just stress`).
pub fn stress_section() -> crate::compare::report::Section {
    use crate::compare::stress;
    use rayon::prelude::*;
    let rows: Vec<_> = stress::cases(false)
        .par_iter()
        .flat_map(stress::run_case)
        .collect();
    let failed = rows.iter().filter(|r| !r.passes()).count();
    crate::compare::report::Section {
        markdown: format!(
            "## Numerical stress (fast form)\n\n\
             Each case pushes one thing to an extreme (module `rotor_harness::compare::stress`; \
             the full form with long horizons and the widest ladders runs with `just stress`). \
             Every solver must finish with a finite state or a typed error that says why, and \
             where it finishes agree with the event-driven solver or an exact solution within \
             the stated gate. {} rows, {} outside their gate.\n\n{}",
            rows.len(),
            failed,
            stress::stress_table_markdown(&rows)
        ),
        files: Vec::new(),
        timings: format!(
            "\n## Numerical stress (fast form)\n\n{}",
            stress::stress_timings_markdown(&rows)
        ),
        failures: rows
            .iter()
            .filter(|r| !r.passes())
            .map(|r| {
                format!(
                    "stress {} ({}): {} at {}: {}",
                    r.case,
                    r.what,
                    r.solver.name(),
                    r.setting,
                    r.outcome
                )
            })
            .collect(),
    }
}
