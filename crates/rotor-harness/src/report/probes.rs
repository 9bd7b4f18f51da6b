//! The section with the steady states probed next to the diagrams' special points.

use rotor_model::{Model, Params};

/// The report section with the steady states probed next to every special point of both
/// diagrams (`rotor_analysis::steady::probes`, all solvers, all offsets, both starts).
pub fn probe_section(
    sets: &[(&str, &str, Params)],
    diagrams: &[rotor_analysis::bifurcation::Diagram],
) -> crate::compare::report::Section {
    use rayon::prelude::*;
    use rotor_analysis::steady::probes;
    // Both sets at once (not one after the other), so that no core waits for the slowest
    // probe of the first set; rows in the sets' order.
    let rows: Vec<probes::ProbeRow> = sets
        .par_iter()
        .zip(diagrams)
        .map(|((_, slug, p), d)| {
            let m = Model::new(*p);
            let selected = probes::selection(d, true);
            probes::run_set(slug, &m, d, &selected, |jobs, f| {
                jobs.par_iter().map(f).collect()
            })
        })
        .collect::<Vec<_>>()
        .concat();
    let count =
        |f: &dyn Fn(&probes::Verdict) -> bool| rows.iter().filter(|r| f(&r.verdict)).count();
    let agree = count(&|v| matches!(v, probes::Verdict::Agrees { .. }));
    let refused = count(&|v| matches!(v, probes::Verdict::Refused { .. }));
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| !r.verdict.acceptable())
        .map(|r| {
            format!(
                "steady near {} of {} ({:+e} V, from {}): {} {:?}",
                r.probe.point.label,
                r.set,
                r.probe.offset,
                r.probe.start.as_str(),
                r.probe.kind.name(),
                r.verdict
            )
        })
        .collect();
    let slowest = rows.iter().map(|r| r.seconds).fold(0.0, f64::max);
    let total: f64 = rows.iter().map(|r| r.seconds).sum();
    crate::compare::report::Section {
        markdown: format!(
            "## Steady states near special points\n\n\
             `rotor steady` at ±1e-3, ±1e-4 and ±1e-6 V from every special point of both \
             diagrams, from rest and from the equilibrium perturbed by 1e-3 rad/s, for every \
             solver (module `rotor_analysis::steady::probes`): the event-driven solver by its \
             own refinement, the switch model and Moreau–Jean by shooting on their own return \
             maps, accepted only when a run from the start of at most 600 s is seen to go to \
             the orbit (module `checked`); each cell names the method. Each answer is checked against \
             what the continuation says is stable at that input (the stable equilibria, the \
             stuck set, the stable cycles found by Newton's method from the branch and from \
             the Hopf eigenvector): it must be one of them in kind, period and ω_l extremes \
             (within 1e-6 for the event-driven solver, 1e-5 for the switch model, 1e-4 for \
             Moreau–Jean, each well inside the distance to the nearest other cycle), or a \
             refusal that names its cause: a transient too slow to settle or to reach the \
             shot orbit in the time allowed (next to a Hopf point or a fold), no orbit found by \
             shooting, an orbit with a multiplier too near the unit circle to decide its \
             stability, no cycle next to a weakly unstable \
             equilibrium, or a stability the tolerance cannot decide. {} probes: {agree} \
             answers agree, {refused} refusals, {} wrong or failed.\n\n{}\n\
             Each probe:\n\n{}",
            rows.len(),
            bad.len(),
            probes::probe_summary_markdown(&rows, &rotor_analysis::solvers::SOLVERS),
            probes::probe_table_markdown(&rows, &rotor_analysis::solvers::SOLVERS)
        ),
        files: Vec::new(),
        timings: format!(
            "\n## Steady states near special points\n\n{} probes, {total:.1} s of solver \
             time in all, the slowest {slowest:.2} s.\n",
            rows.len()
        ),
        failures: bad,
    }
}
