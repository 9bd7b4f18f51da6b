//! `rotor bifurcation2`: the two-parameter analysis, as JSON and SVG.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::common::{load_model, say};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The parameter: a field of the parameter file as a dotted path (k_theta, lower.t_s,
    /// upper.b, ...).
    #[arg(long)]
    pub param: String,
    /// Lower end of the parameter's range.
    #[arg(long, allow_hyphen_values = true)]
    pub p_min: f64,
    /// Upper end of the parameter's range.
    #[arg(long, allow_hyphen_values = true)]
    pub p_max: f64,
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long)]
    pub params: Option<PathBuf>,
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub u_min: f64,
    #[arg(long, default_value_t = 7.0, allow_hyphen_values = true)]
    pub u_max: f64,
    /// Output JSON file (`-`: standard output).
    #[arg(long)]
    pub json: PathBuf,
    /// Output SVG of the (p, u) plane (`-`: standard output).
    #[arg(long)]
    pub svg: Option<PathBuf>,
}

pub fn run(a: &Args) -> Result<()> {
    bifurcation2(
        &a.param,
        [a.p_min, a.p_max, a.u_min, a.u_max],
        a.params.as_deref(),
        &a.json,
        a.svg.as_deref(),
    )
}

pub(crate) fn bifurcation2(
    param: &str,
    [p_min, p_max, u_min, u_max]: [f64; 4],
    params: Option<&Path>,
    json: &Path,
    svg: Option<&Path>,
) -> Result<()> {
    use rotor_harness::compare::report::write_output;
    let base = load_model(params)?.params;
    let opts = rotor_analysis::plane::PlaneOptions {
        u_min,
        u_max,
        ..rotor_analysis::plane::PlaneOptions::new(param, p_min, p_max)
    };
    rotor_analysis::plane::validate(&base, &opts).map_err(|e| {
        crate::common::unusable(format_args!(
            "{}",
            e.to_string()
                .replace("p_min", "--p-min")
                .replace("p_max", "--p-max")
                .replace("u_min", "--u-min")
                .replace("u_max", "--u-max")
        ))
    })?;
    eprintln!(
        "bifurcation2: every codimension-one point of the u-diagram continued in ({param}, u) \
         for {param} in [{p_min}, {p_max}], then simulations in every band (about 1 s for \
         the README's ranges)"
    );
    let spinner = crate::common::progress_spinner("curves");
    let t0 = std::time::Instant::now();
    let plane = rotor_analysis::plane::plane(&base, &opts);
    spinner.finish_and_clear();
    let plane = plane?;
    let secs = t0.elapsed().as_secs_f64();
    write_output(json, plane.to_json()?.as_bytes())
        .with_context(|| format!("{}: cannot write", json.display()))?;
    if let Some(path) = svg {
        let name = params.map_or("Table 1".to_owned(), |p| p.display().to_string());
        write_output(
            path,
            plane.to_svg(&format!("{name}: ({param}, u)")).as_bytes(),
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    let mut summary = format!(
        "{} curves, {} codimension-two points in {secs:.2} s\n",
        plane.curves.len(),
        plane.points.len()
    );
    for c in &plane.curves {
        summary.push_str(&format!(
            "  {} ({:?}): {} points\n",
            c.label,
            c.kind,
            c.points.len()
        ));
    }
    for q in &plane.points {
        summary.push_str(&format!(
            "  {} at {param} = {:.6}, u = {:.6}: {}\n",
            q.kind.name(),
            q.p,
            q.u,
            q.curves.join(", ")
        ));
    }
    say(&summary, [Some(json), svg])?;
    Ok(())
}
