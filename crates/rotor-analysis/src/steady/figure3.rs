//! The source's Figure 3 cross-validated: the bifurcation diagram by the three methods
//! overlaid, and each special point by each method with the differences and the gates of
//! `fixtures/gates/bifurcation.toml` (measured × margin, each with its origin there).

use std::fmt::Write as _;

use crate::bifurcation::{Diagram, EquilibriumKind, PointKind, SpecialPoint};
use crate::plot::Label;
use crate::plot::overlay::Layer;
use crate::solvers::SolverKind;
use rotor_model::Model;
use serde::Deserialize;

use crate::steady::by_solver::{BySolverOptions, by_solver_with};

/// The gates file, embedded (its origins are comments there).
pub(crate) const GATES_TOML: &str = include_str!("../../../../fixtures/gates/bifurcation.toml");

/// The gate of one special point for each method pair (event vs switch, event vs Moreau–Jean).
#[derive(Debug, Clone, Deserialize, PartialEq)]
pub struct PointGate {
    /// The parameter set (`table1`, `stribeck`).
    pub params: String,
    /// The point's label ([`label_points`]).
    pub point: String,
    /// Largest |Δu| \[V\] of the switch model's point from the event method's.
    pub switch: f64,
    /// Largest |Δu| \[V\] of Moreau–Jean's point (h = 1e-3) from the event method's.
    pub moreau: f64,
}

#[derive(Deserialize)]
struct GateFile {
    point: Vec<PointGate>,
}

/// Why the gates could not be read.
#[derive(Debug, thiserror::Error)]
#[error("fixtures/gates/bifurcation.toml: {0}")]
pub struct GateError(String);

/// The gates of `fixtures/gates/bifurcation.toml`.
pub fn gates() -> Result<Vec<PointGate>, GateError> {
    let f: GateFile = toml::from_str(GATES_TOML).map_err(|e| GateError(e.to_string()))?;
    for g in &f.point {
        for (field, v) in [("switch", g.switch), ("moreau", g.moreau)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(GateError(format!(
                    "{} {}: {field} = {v}: a gate must be a positive number",
                    g.params, g.point
                )));
            }
        }
    }
    Ok(f.point)
}

/// The special points of the cycles and the Hopf points, labelled as in the figure: Hopf
/// points H1, H2, … and grazing orbits G1, G2, … in order of u; smooth folds F1, F2, …;
/// discontinuous folds D1, D2, … with the one at the largest u called E (the source's name).
pub fn label_points(points: &[SpecialPoint]) -> Vec<(String, &SpecialPoint)> {
    let mut out = Vec::new();
    let mut by = |pred: &dyn Fn(&SpecialPoint) -> bool, prefix: &str, last_e: bool| {
        let mut v: Vec<&SpecialPoint> = points.iter().filter(|p| pred(p)).collect();
        v.sort_by(|a, b| a.u.total_cmp(&b.u));
        let n = v.len();
        for (i, p) in v.into_iter().enumerate() {
            let name = if last_e && i + 1 == n {
                "E".to_string()
            } else {
                format!("{prefix}{}", i + 1)
            };
            out.push((name, p));
        }
    };
    by(&|p| p.kind == PointKind::Hopf, "H", false);
    by(&|p| p.kind == PointKind::Grazing, "G", false);
    by(
        &|p| p.kind == PointKind::Fold && p.discontinuous != Some(true),
        "F",
        false,
    );
    by(
        &|p| p.kind == PointKind::Fold && p.discontinuous == Some(true),
        "D",
        true,
    );
    out.sort_by(|a, b| a.1.u.total_cmp(&b.1.u));
    out
}

/// The point of `points` that is `p` by another method: the same kind (and for a fold the
/// same smoothness), nearest in u, within 0.01 V.
pub fn matching<'a>(points: &'a [SpecialPoint], p: &SpecialPoint) -> Option<&'a SpecialPoint> {
    points
        .iter()
        .filter(|q| q.kind == p.kind && q.discontinuous == p.discontinuous)
        .filter(|q| (q.u - p.u).abs() < 0.01)
        .min_by(|a, b| (a.u - p.u).abs().total_cmp(&(b.u - p.u).abs()))
}

/// A report section (the CLI turns it into its report's section type).
#[derive(Debug, Clone, Default)]
pub struct ReportSection {
    /// The section's text (headings, figure links, tables).
    pub markdown: String,
    /// Files the text links to, `(file name, bytes)`: one `figure3-<set>.svg` per parameter
    /// set.
    pub files: Vec<(String, Vec<u8>)>,
    /// Gates that failed, one line each.
    pub failures: Vec<String>,
    /// Run times (markdown; not committed).
    pub timings: String,
}

/// Rows re-shot per solver for the overlay in the report: every 16th (about 30 per set), to
/// keep the section within its time budget of the main job; the special points are located
/// whatever the stride.
pub(crate) const REPORT_STRIDE: usize = 16;

/// The section: per parameter set `(name, slug, model, event diagram)`, the overlay SVG and
/// the table of special points by method, with differences and gates.
pub fn figure3_section(sets: &[(&str, &str, &Model, &Diagram)]) -> ReportSection {
    let mut sec = ReportSection::default();
    let gates = match gates() {
        Ok(g) => g,
        Err(e) => {
            sec.failures.push(e.to_string());
            Vec::new()
        }
    };
    let md = &mut sec.markdown;
    md.push_str(
        "## Figure 3 by three methods\n\n\
         The periodic branches shot again on the switch model's and Moreau–Jean's own return \
         maps (`rotor bifurcation --solver switch|moreau`; every 16th orbit of the \
         continuation here) over the event-driven continuation, and each special point of \
         the cycles located again by each solver's own shooting (docs/methods.md §4b). Hopf \
         points are properties of the equilibria, shared by all three. Gates per point and \
         method pair: `fixtures/gates/bifurcation.toml` (measured × margin, origins there). \
         Switch model: tol 1e-10, η = 1e-10; Moreau–Jean: h = 1e-3.\n",
    );
    let opts = BySolverOptions {
        stride: REPORT_STRIDE,
        ..Default::default()
    };
    for (name, slug, model, event) in sets {
        let t0 = std::time::Instant::now();
        let (sw, mo) = rayon::join(
            || by_solver_with(SolverKind::SWITCH, model, event, &opts),
            || by_solver_with(SolverKind::MOREAU, model, event, &opts),
        );
        let _ = write!(
            sec.timings,
            "\n## Figure 3 by three methods, {name}\n\nSwitch and Moreau–Jean in {:.2} s.\n",
            t0.elapsed().as_secs_f64()
        );
        let panel = overlay_panel(name, event, &sw.diagram, &mo.diagram);
        sec.files.push((
            format!("figure3-{slug}.svg"),
            crate::plot::render(std::slice::from_ref(&panel), 900.0, 520.0).into_bytes(),
        ));
        sec.files.push((
            format!("figure3-{slug}.csv"),
            crate::plot::data_csv(std::slice::from_ref(&panel)).into_bytes(),
        ));
        let md = &mut sec.markdown;
        let _ = write!(
            md,
            "\n### {name}\n\n![Figure 3 by three methods, {name}](figure3-{slug}.svg)\n\n\
             | point | event u [V] | switch u [V] | Δ switch | gate | Moreau–Jean u [V] | Δ Moreau | gate |\n\
             |---|---|---|---|---|---|---|---|\n"
        );
        for (label, p) in label_points(&event.points) {
            let gate = gates.iter().find(|g| g.params == *slug && g.point == label);
            let mut cells = String::new();
            for (sname, d, gv) in [
                ("switch", &sw, gate.map(|g| g.switch)),
                ("moreau", &mo, gate.map(|g| g.moreau)),
            ] {
                match matching(&d.diagram.points, p) {
                    Some(q) => {
                        let du = (q.u - p.u).abs();
                        let at = (*name, label.as_str(), sname);
                        let gate_txt = gate_cell(at, p.kind, du, gv, &mut sec.failures);
                        let _ = write!(cells, " {:.9} | {du:.1e} | {gate_txt} |", q.u);
                    }
                    None => {
                        let _ = write!(cells, " not located | — | — |");
                    }
                }
            }
            let _ = writeln!(md, "| {label} ({}) | {:.9} |{cells}", p.kind, p.u);
        }
        let lost: Vec<String> = sw
            .not_found
            .iter()
            .map(|n| ("switch", n))
            .chain(mo.not_found.iter().map(|n| ("moreau", n)))
            .filter(|(_, n)| n.reason.contains("not located"))
            .map(|(s, n)| format!("- {s}: u = {:.6}: {}", n.u, n.reason))
            .collect();
        if !lost.is_empty() {
            let _ = writeln!(md, "\nNot located:\n\n{}", lost.join("\n"));
        }
    }
    sec
}

/// The gate cell of a point of kind `kind` that method `sname` places `du` \[V\] from the
/// event method's, at `(set name, point label, method)`: `shared` for a Hopf point, else the
/// gate `gv` (marked `FAIL` when `du` exceeds it) or `none`; a failed or missing gate is
/// added to `failures`.
fn gate_cell(
    (name, label, sname): (&str, &str, &str),
    kind: PointKind,
    du: f64,
    gv: Option<f64>,
    failures: &mut Vec<String>,
) -> String {
    if kind == PointKind::Hopf {
        "shared".to_string()
    } else if let Some(g) = gv {
        if du > g {
            failures.push(format!(
                "figure 3, {name} {label}: {sname} differs by {du:.1e} V \
                 from the event method, gate {g:.0e} V"
            ));
            format!("{g:e} FAIL")
        } else {
            format!("{g:e}")
        }
    } else {
        failures.push(format!(
            "figure 3, {name} {label}: no gate for {sname} in \
             fixtures/gates/bifurcation.toml"
        ));
        "none".to_string()
    }
}

/// The ω_l maximum and minimum of every periodic row of `d`, as points `(u, ω_l)`.
fn maxmin(d: &Diagram) -> Vec<(f64, f64)> {
    d.periodic
        .iter()
        .flat_map(|r| [(r.u, r.omega_l_max), (r.u, r.omega_l_min)])
        .collect()
}

/// The labels of the event diagram's special points ([`label_points`]) at their ω_l maximum
/// (a Hopf point at its ω, else 0), points closer than 2 % of the axis ranges sharing one
/// label (as in the diagram's own figure).
fn point_labels(event: &Diagram) -> Vec<Label> {
    let labels = label_points(&event.points)
        .into_iter()
        .map(|(l, p)| Label {
            x: p.u,
            y: p.omega_l_max.unwrap_or(if p.kind == PointKind::Hopf {
                p.omega.unwrap_or(0.0)
            } else {
                0.0
            }),
            text: l,
        })
        .collect();
    let y_span = event
        .periodic
        .iter()
        .map(|r| r.omega_l_max)
        .fold(1.0f64, f64::max);
    let x_span = event.periodic.iter().map(|r| r.u).fold(1.0f64, f64::max);
    crate::plot::merge_close(labels, x_span, y_span, 0.02)
}

/// The overlay of set `name`: the slipping equilibria, and the cycles' ω_l max / min of the
/// event continuation and of the switch model's (`sw`) and Moreau–Jean's (`mo`) shooting,
/// with the special points labelled.
fn overlay_panel(
    name: &str,
    event: &Diagram,
    sw: &Diagram,
    mo: &Diagram,
) -> crate::plot::Panel<'static> {
    let mut eq: Vec<_> = event
        .equilibria
        .iter()
        .filter(|e| e.kind == EquilibriumKind::Slip)
        .map(|e| (e.u, e.omega))
        .collect();
    eq.sort_by(|a, b| a.1.total_cmp(&b.1));
    crate::plot::overlay::overlay_panel(
        &format!("Figure 3 by three methods: {name}"),
        "u [V]",
        "max and min of ω_{l} [rad/s]",
        vec![
            Layer {
                label: "equilibria",
                color: "#999999",
                marker: 0.0,
                width: 1.0,
                points: eq,
            },
            Layer {
                label: "event-driven (continuation)",
                color: "#000000",
                marker: 1.0,
                width: 0.0,
                points: maxmin(event),
            },
            Layer {
                label: "switch model (shooting)",
                color: "#D55E00",
                marker: 3.5,
                width: 0.0,
                points: maxmin(sw),
            },
            Layer {
                label: "Moreau–Jean, h = 1e-3 (shooting)",
                color: "#0072B2",
                marker: 2.0,
                width: 0.0,
                points: maxmin(mo),
            },
        ],
        point_labels(event),
    )
}
