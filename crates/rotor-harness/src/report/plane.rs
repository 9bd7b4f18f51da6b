//! The section with the two-parameter pictures.

use rotor_model::Params;

use crate::report::ReportError;

/// The report section with the two-parameter pictures: (k_θ, u) and (T_sl, u) for both
/// parameter sets.
/// `diagrams` are the sets' one-parameter diagrams over u in [0, 7] (the bifurcation
/// section's), which the continuation starts from instead of computing them again.
pub fn plane_section(
    sets: &[(&str, &str, Params)],
    diagrams: &[rotor_analysis::bifurcation::Diagram],
) -> Result<crate::compare::report::Section, ReportError> {
    use rayon::prelude::*;
    use std::fmt::Write as _;
    let jobs: Vec<(
        &str,
        &str,
        Params,
        &str,
        f64,
        f64,
        &rotor_analysis::bifurcation::Diagram,
    )> = sets
        .iter()
        .zip(diagrams)
        .flat_map(|((name, slug, p), d)| {
            // T_sl over a range that keeps the law admissible and, for the Stribeck set,
            // reaches the cluster of codimension-two points near 0.13.
            let ts = if *slug == "stribeck" {
                (0.1, 0.45)
            } else {
                (0.1, 0.25)
            };
            [
                (*name, *slug, *p, "k_theta", 0.05, 0.11, d),
                (*name, *slug, *p, "lower.t_s", ts.0, ts.1, d),
            ]
        })
        .collect();
    let planes = jobs
        .par_iter()
        .map(|(_, _, p, param, a, b, d)| {
            let t0 = std::time::Instant::now();
            let pl = rotor_analysis::plane::plane_with(
                p,
                &rotor_analysis::plane::PlaneOptions::new(param, *a, *b),
                Some(d),
            );
            (pl, t0.elapsed().as_secs_f64())
        })
        .collect::<Vec<_>>();
    let mut sec = crate::compare::report::Section::default();
    sec.markdown.push_str(
        "## Two parameters (rotor bifurcation2)\n\n\
         Every codimension-one point of the u-diagram continued in the plane of (p, u) for the \
         stiffness k_θ and the lower disc's static level T_sl, \
         with the codimension-two points located on the curves and the regions named from \
         simulations from rest and from the perturbed equilibrium in every band the curves \
         bound (docs/methods.md, section 4a). The dashed line is the file's value; its dots \
         are the one-parameter diagram's points.\n",
    );
    for ((name, slug, _, param, a, b, _), (pl, secs)) in jobs.iter().zip(planes) {
        let pl = pl.map_err(|source| ReportError::Plane {
            set: name.to_string(),
            param: param.to_string(),
            source,
        })?;
        let file = format!("plane-{slug}-{}", param.replace('.', "_"));
        let _ = write!(
            sec.timings,
            "\n## Two parameters, {name}, {param}\n\nComputed in {secs:.2} s.\n"
        );
        let _ = write!(
            sec.markdown,
            "\n### {name}: ({param}, u), {param} in [{a:.4}, {b:.4}]\n\n![{name} {param}]({file}.svg)\n\n\
             {} curves ([JSON]({file}.json)); codimension-two points:\n\n",
            pl.curves.len()
        );
        if pl.points.is_empty() {
            sec.markdown.push_str("none in this range.\n");
        } else {
            sec.markdown
                .push_str("| kind | p | u [V] | curves | detail |\n|---|---|---|---|---|\n");
            for q in &pl.points {
                let _ = writeln!(
                    sec.markdown,
                    "| {} | {:.5} | {:.5} | {} | {} |",
                    q.kind.name(),
                    q.p,
                    q.u,
                    q.curves.join(", "),
                    q.detail
                );
            }
        }
        sec.files.push((
            format!("{file}.svg"),
            pl.to_svg(&format!("{name}: ({param}, u)")).into_bytes(),
        ));
        sec.files
            .push((format!("{file}.json"), pl.to_json()?.into_bytes()));
        sec.files.push((
            format!("{file}.csv"),
            pl.to_csv(&format!("{name}: ({param}, u)")).into_bytes(),
        ));
    }
    Ok(sec)
}
