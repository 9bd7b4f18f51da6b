//! The two-parameter picture ([`Plane`], the JSON of `rotor bifurcation2`): the one-parameter
//! diagram at the start, the curves through its points, their codimension-two points and the
//! regions, assembled by [`plane`] (or [`plane_with`], given the diagram).

use crate::bifurcation::{BifError, Diagram, DiagramOptions, diagram};
use rotor_model::{Model, Params};
use serde::Serialize;

use crate::plane::codim2::{self, Codim2};
use crate::plane::curves::{self, Curve};
use crate::plane::options::{PlaneOptions, params_at, validate};
use crate::plane::regions::{self, Region};

/// The two-parameter picture (the JSON of `rotor bifurcation2`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plane {
    /// The parameter, as a dotted path of the parameter file.
    pub param: String,
    /// The parameter's value in the file.
    pub p_file: f64,
    /// The window computed: `[p_min, p_max]` and `[u_min, u_max]`.
    pub p_range: [f64; 2],
    /// See `p_range`.
    pub u_range: [f64; 2],
    /// The codimension-one curves (a grazing curve as its pieces of one type).
    pub curves: Vec<Curve>,
    /// The codimension-two points, in increasing p.
    pub points: Vec<Codim2>,
    /// The named regions, in increasing u.
    pub regions: Vec<Region>,
}

/// The two-parameter picture (see the crate docs).
pub fn plane(base: &Params, opts: &PlaneOptions) -> Result<Plane, BifError> {
    plane_with(base, opts, None)
}

/// [`plane`], given `known`: the one-parameter diagram of `base` itself over
/// `DiagramOptions { u_min, u_max, ..Default::default() }` from `opts` (the one
/// `rotor bifurcation` computes). The continuation starts from that diagram's special points
/// when it starts at the file's value of the parameter (`p_start` unset and the value in
/// range), so the result is the same as [`plane`]'s, without computing the diagram again;
/// otherwise `known` is not used.
pub fn plane_with(
    base: &Params,
    opts: &PlaneOptions,
    known: Option<&Diagram>,
) -> Result<Plane, BifError> {
    validate(base, opts)?;
    let name = opts.param.as_str();
    let p_file = base
        .get(name)
        .map_err(|e| BifError::Degenerate(e.to_string()))?;
    let p0 = match opts.p_start {
        Some(p) => p,
        None if (opts.p_min..=opts.p_max).contains(&p_file) => p_file,
        None => 0.5 * (opts.p_min + opts.p_max),
    };
    let computed;
    let d = match known {
        // The diagram at p0 is the file's own: the same inputs, so the same diagram.
        Some(d) if p0 == p_file => d,
        _ => {
            let model0 = Model::new(params_at(base, name, p0)?);
            computed = diagram(
                &model0,
                &DiagramOptions {
                    u_min: opts.u_min,
                    u_max: opts.u_max,
                    ..DiagramOptions::default()
                },
            )?;
            &computed
        }
    };
    let mut curves = curves::from_diagram(base, opts, d, p0);
    let mut points = codim2::split_at_type_changes(base, name, &mut curves, opts.tol);
    points.extend(codim2::on_curves(base, name, &curves, opts));
    points.sort_by(|a, b| a.p.total_cmp(&b.p));
    let regions = regions::named(base, name, opts, &curves)?;
    Ok(Plane {
        param: opts.param.clone(),
        p_file,
        p_range: [opts.p_min, opts.p_max],
        u_range: [opts.u_min, opts.u_max],
        curves,
        points,
        regions,
    })
}

impl Plane {
    /// The plane as JSON (`rotor bifurcation2`); a non-finite number is an error.
    pub fn to_json(&self) -> Result<String, BifError> {
        for c in &self.curves {
            for q in &c.points {
                for (what, v) in [("p", q.p), ("u", q.u), ("residual", q.residual)] {
                    if !v.is_finite() {
                        return Err(BifError::NonFinite {
                            what: format!("curve {} {what}", c.label),
                            value: v,
                        });
                    }
                }
            }
        }
        serde_json::to_string_pretty(self).map_err(|e| BifError::Io(e.to_string()))
    }
}
