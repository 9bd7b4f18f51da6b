//! `rotor bifurcation`: the diagram over u, as JSON, CSV and SVG.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::common::{load_model, say};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Parameter file, or the name of one in fixtures/params (`stribeck`; default: the
    /// source's Table 1).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Lower end of the input range, in V (>= 0; for a law odd in omega, u < 0 is the mirror).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub u_min: f64,
    /// Upper end of the input range, in V (at most 1000).
    #[arg(long, default_value_t = 7.0, allow_hyphen_values = true)]
    pub u_max: f64,
    /// Output JSON file (equilibria, periodic, points; `-`: standard output).
    #[arg(long)]
    pub json: PathBuf,
    /// Output SVG figure (max/min of omega_l against u, like the source's Figure 3;
    /// `-`: standard output).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Output CSV of every branch point (`-`: standard output).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Which solver computes the periodic branches: event (the continuation with
    /// saltation matrices; default), or switch or moreau (each orbit shot again on that
    /// solver's own return map, with its own multipliers, and the grazing orbits and folds
    /// located again by that solver's shooting; "not_found" in the JSON names what was not).
    #[arg(long, default_value = "event")]
    pub solver: String,
}

pub fn run(a: &Args) -> Result<()> {
    bifurcation(
        &a.solver,
        a.params.as_deref(),
        a.u_min,
        a.u_max,
        &a.json,
        a.svg.as_deref(),
        a.csv.as_deref(),
    )
}

pub(crate) fn bifurcation(
    solver: &str,
    params: Option<&Path>,
    u_min: f64,
    u_max: f64,
    json: &Path,
    svg: Option<&Path>,
    csv: Option<&Path>,
) -> Result<()> {
    use rotor_harness::compare::report::write_output;
    let model = load_model(params)?;
    let opts = rotor_analysis::bifurcation::DiagramOptions {
        u_min,
        u_max,
        ..Default::default()
    };
    // The library names the field: "u_min = ...", which is the flag --u-min.
    opts.validate().map_err(|e| {
        crate::common::unusable(format_args!(
            "{}",
            e.to_string()
                .replace("u_min", "--u-min")
                .replace("u_max", "--u-max")
        ))
    })?;
    let kind = rotor_harness::jobs::request::solver_kind(solver).map_err(crate::common::flagged)?;
    let event = rotor_analysis::bifurcation::diagram(&model, &opts)?;
    let by = rotor_analysis::steady::by_solver::by_solver(kind, &model, &event);
    let d = &by.diagram;
    d.check_finite()?;
    let mut text = serde_json::to_string_pretty(&by)?;
    text.push('\n');
    write_output(json, text.as_bytes())
        .with_context(|| format!("{}: cannot write", json.display()))?;
    if let Some(path) = csv {
        let mut buf = Vec::new();
        d.write_csv(&mut buf)?;
        write_output(path, &buf).with_context(|| format!("{}: cannot write", path.display()))?;
    }
    if let Some(path) = svg {
        let name = params.map_or("Table 1".to_owned(), |p| p.display().to_string());
        write_output(
            path,
            d.to_svg(&format!("Bifurcation diagram: {name}")).as_bytes(),
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    let mut summary = format!(
        "{}: {} equilibria, {} periodic orbits, {} special points\n",
        by.solver,
        d.equilibria.len(),
        d.periodic.len(),
        d.points.len()
    );
    if !by.not_found.is_empty() {
        summary += &format!(
            "  {} orbits of the continuation not found by {}'s shooting (in the JSON)\n",
            by.not_found.len(),
            by.solver
        );
    }
    for p in &d.points {
        summary += &format!("  {}\n", serde_json::to_string(p)?);
    }
    say(&summary, [Some(json), csv, svg])?;
    Ok(())
}
