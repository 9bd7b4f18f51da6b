//! The section with the bifurcation diagrams of both parameter sets.

use rotor_model::{Model, Params};

use crate::report::ReportError;

/// The report section with the bifurcation diagrams of both parameter sets (the source's
/// Figure 3): SVG, JSON and CSV per set, and a table of the special points.
pub fn bifurcation_section(
    sets: &[(&str, &str, Params)],
) -> Result<
    (
        crate::compare::report::Section,
        Vec<rotor_analysis::bifurcation::Diagram>,
    ),
    ReportError,
> {
    use rayon::prelude::*;
    use std::fmt::Write as _;
    let diagrams = sets
        .par_iter()
        .map(|(_, _, p)| {
            let t0 = std::time::Instant::now();
            let d = rotor_analysis::bifurcation::diagram(&Model::new(*p), &Default::default());
            (d, t0.elapsed().as_secs_f64())
        })
        .collect::<Vec<_>>();
    let mut sec = crate::compare::report::Section::default();
    let mut out = Vec::new();
    sec.markdown
        .push_str("## Bifurcation diagrams (the source's Figure 3)\n\n");
    sec.markdown.push_str(
        "Computed by `rotor bifurcation` (module `rotor_analysis::bifurcation`): the equilibrium branch with \
         its eigenvalues, periodic orbits by shooting with the exact Filippov flow, Floquet \
         multipliers from the monodromy matrix with saltation matrices, pseudo-arclength \
         continuation started at each Hopf point. Stable: solid; unstable: dashed. Each special \
         point is listed with the residual of its defining condition.\n",
    );
    for ((name, slug, _), (d, secs)) in sets.iter().zip(diagrams) {
        let d = d.map_err(|source| ReportError::Diagram {
            set: name.to_string(),
            source,
        })?;
        let _ = write!(
            sec.timings,
            "\n## Bifurcation diagram, {name}\n\nComputed in {secs:.2} s.\n"
        );
        let md = &mut sec.markdown;
        let _ = write!(
            md,
            "\n### {name}\n\n![bifurcation diagram, {name}](bifurcation-{slug}.svg)\n\n\
             {} equilibria, {} periodic orbits \
             ([JSON](bifurcation-{slug}.json), [CSV](bifurcation-{slug}.csv)).\n\n\
             | point | u [V] | residual | detail |\n|---|---|---|---|\n",
            d.equilibria.len(),
            d.periodic.len()
        );
        for p in &d.points {
            let _ = writeln!(
                md,
                "| {} | {:.10} | {} | {} |",
                p.kind.as_str(),
                p.u,
                p.residual.map_or("—".into(), |r| format!("{r:.1e}")),
                p.detail
            );
        }
        let mut csv = Vec::new();
        d.write_csv(&mut csv)?;
        sec.files.push((
            format!("bifurcation-{slug}.svg"),
            d.to_svg(&format!("Bifurcation diagram: {name}"))
                .into_bytes(),
        ));
        sec.files.push((
            format!("bifurcation-{slug}.json"),
            d.to_json()?.into_bytes(),
        ));
        sec.files.push((format!("bifurcation-{slug}.csv"), csv));
        out.push(d);
    }
    Ok((sec, out))
}
