//! Two-parameter analysis: every codimension-one point of the u-diagram continued in the
//! plane of (p, u), for any parameter p of the file, and the codimension-two points where the
//! curves change type, turn, end or meet (`rotor bifurcation2`).
//!
//! Each curve is followed by pseudo-arclength ([`crate::arc`]) on its defining system, from the
//! point of the one-parameter diagram at the file's value of p (or, outside the range, at its
//! middle), in both directions:
//!
//! * **Hopf** (`hopf`): `y = (p, ω)`, `Re λ(ω; p) = 0` for the complex pair of the slipping
//!   equilibrium at velocity ω (the branch is explicit in ω, `u = u(ω; p)`). Each point carries
//!   its first Lyapunov coefficient `l1` (Kuznetsov's formula on the smooth slip field; `l1 < 0`
//!   supercritical), so a change of criticality is found as a sign change.
//! * **Grazing** (`grazing`, `discontinuous_fold`): `y = (p, u, w)`, the grazing system of
//!   [`crate::grazing`] (the cycle touches `ω_l = 0` at `(T_sl/k_θ, w, 0)` with `ω̇_l = 0`). Each
//!   point is classified by the one classifier of the u-diagram, Feigin's rule
//!   ([`crate::grazing::classify`], [`crate::feigin`]): a discontinuous fold where the real
//!   multipliers above 1 of the slipping and the stick-slip cycle at grazing add up to an odd
//!   number (as at the source's point E on the Stribeck set), persistence where even; the curve
//!   is split where that changes.
//! * **Smooth fold of cycles** (`fold`): `y = (p, α, ω_u, u)`, the cycle's fixed point on the
//!   section `ω_l = ω*(u)` and `det(∂P/∂z − I) = 0` (a multiplier 1).
//! * **Stuck boundary** (`stuck_boundary`): where the slipping branch meets the stuck set,
//!   `u = u(ω → 0⁺; p)`, explicit.
//!
//! Codimension-two points, located on the curves: a Hopf point changing criticality (`bautin`,
//! a sign change of l1, by bisection), a curve turning back in p (`hopf_merge` where two Hopf
//! points meet and vanish, `cusp` where two folds do), a grazing curve changing between
//! grazing and discontinuous fold (`grazing_fold`: a multiplier of one side at grazing crosses
//! 1, so Feigin's fold indicator `det(I − A)·det(I − B)` changes sign and a fold curve meets the
//! grazing curve), a curve ending at the stuck
//! boundary (`stuck_end`), and two curves meeting (`curves_meet`). Where the theory of such a
//! nonsmooth point is not settled the point only records where the curves meet and what was
//! seen; no normal form is claimed.

use nalgebra::{Matrix3, Vector3};
use rotor_model::{Model, Output, Params, Scene, Solver, State, SteadyState};
use serde::Serialize;

use crate::arc::{ArcEnd, ArcOptions, follow};
use crate::continuation::{ContOptions, Continuer, Multipliers};
pub use crate::equilibria::first_lyapunov;
use crate::feigin::{Feigin, GrazingType};
use crate::periodic::Shooter;
use crate::{BifError, DiagramOptions, PointKind, diagram, grazing};

/// What [`plane`] computes.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneOptions {
    /// The parameter: a field of the parameter file as a dotted path.
    pub param: String,
    pub p_min: f64,
    pub p_max: f64,
    pub u_min: f64,
    pub u_max: f64,
    /// Integration tolerance of the flows.
    pub tol: f64,
    /// Most points per curve direction.
    pub max_points: usize,
    /// Cells per axis of the coarse grid whose simulations name the regions.
    pub region_cells: usize,
    /// Where the curves are started (the one-parameter diagram is computed there); default
    /// the file's value if it lies in the range, else the middle of the range.
    pub p_start: Option<f64>,
}

impl PlaneOptions {
    /// Defaults for a parameter over `[p_min, p_max]` and u over `[0, 7]`.
    pub fn new(param: &str, p_min: f64, p_max: f64) -> PlaneOptions {
        PlaneOptions {
            param: param.to_owned(),
            p_min,
            p_max,
            u_min: 0.0,
            u_max: 7.0,
            tol: 1e-10,
            max_points: 60,
            region_cells: 8,
            p_start: None,
        }
    }
}

/// A kind of codimension-one curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    Hopf,
    Grazing,
    Fold,
    DiscontinuousFold,
    StuckBoundary,
}

/// One point of a curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePoint {
    pub p: f64,
    pub u: f64,
    /// The defining condition's value at the point (its largest component).
    pub residual: f64,
    /// Hopf: the equilibrium's velocity \[rad/s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    /// Hopf: the first Lyapunov coefficient (< 0: supercritical).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub l1: Option<f64>,
    /// Grazing: the largest modulus of the slipping cycle's nontrivial multipliers at the
    /// grazing orbit (for information: the type is Feigin's, `grazing_type`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiplier: Option<f64>,
    /// Grazing: Feigin's type (`persistence` or `nonsmooth_fold`, [`crate::feigin`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grazing_type: Option<GrazingType>,
    /// Grazing: a period-two orbit is born at the grazing orbit too (σ⁻ odd).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_doubling: Option<bool>,
    /// Grazing: σ⁺ of the slipping and of the stick-slip cycle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_plus: Option<[usize; 2]>,
    /// Grazing: σ⁻ of the slipping and of the stick-slip cycle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_minus: Option<[usize; 2]>,
    /// Grazing: ω_u at the touch point \[rad/s\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub touch_omega_u: Option<f64>,
    /// Fold: the cycle's `[α, ω_u]` on the section `ω_l = ω*(u)`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section_state: Option<[f64; 2]>,
}

/// A codimension-one curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    pub kind: CurveKind,
    /// `H1`, `G2`, `E`, `S`, … (as in the u-diagram: numbered by u at the start).
    pub label: String,
    pub points: Vec<CurvePoint>,
    /// Why each end of the curve ended (first end, last end).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ends: Vec<String>,
}

/// A kind of codimension-two point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Codim2Kind {
    /// The first Lyapunov coefficient changes sign along a Hopf curve.
    Bautin,
    /// A Hopf curve turns back in p: two Hopf points meet and vanish.
    HopfMerge,
    /// A fold curve turns back in p: two folds of cycles meet.
    Cusp,
    /// Another curve turns back in p.
    Turning,
    /// A Hopf curve reaches the stuck boundary (the equilibrium's velocity reaches 0).
    StuckEnd,
    /// A grazing curve turns into a discontinuous fold (a fold of cycles meets it).
    GrazingFold,
    /// Two curves cross.
    CurvesCross,
}

impl Codim2Kind {
    /// The name in the JSON and the report's table (`bautin`, `grazing_fold`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Codim2Kind::Bautin => "bautin",
            Codim2Kind::HopfMerge => "hopf_merge",
            Codim2Kind::Cusp => "cusp",
            Codim2Kind::Turning => "turning",
            Codim2Kind::StuckEnd => "stuck_end",
            Codim2Kind::GrazingFold => "grazing_fold",
            Codim2Kind::CurvesCross => "curves_cross",
        }
    }

    /// The words on the figure.
    pub fn title(self) -> &'static str {
        match self {
            Codim2Kind::Bautin => "Bautin",
            Codim2Kind::HopfMerge => "Hopf points meet",
            Codim2Kind::Cusp => "cusp",
            Codim2Kind::Turning => "turning point",
            Codim2Kind::StuckEnd => "Hopf meets stuck boundary",
            Codim2Kind::GrazingFold => "grazing turns fold",
            Codim2Kind::CurvesCross => "curves cross",
        }
    }
}

/// A codimension-two point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Codim2 {
    pub kind: Codim2Kind,
    pub p: f64,
    pub u: f64,
    /// The curves involved.
    pub curves: Vec<String>,
    pub detail: String,
}

/// A named region of the plane: one connected piece of it, named at the middle of its
/// tallest band, `[u_lo, u_hi]` at `p`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    pub name: String,
    pub p: f64,
    pub u: f64,
    pub u_lo: f64,
    pub u_hi: f64,
    /// Every band of the region, `[p, u_lo, u_hi]`, this one first, then the others in
    /// order of height (where the figure may write the name instead).
    #[serde(skip)]
    pub bands: Vec<[f64; 3]>,
}

/// The two-parameter picture (the JSON of `rotor bifurcation2`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plane {
    pub param: String,
    /// The parameter's value in the file.
    pub p_file: f64,
    /// The window computed: `[p_min, p_max]` and `[u_min, u_max]`.
    pub p_range: [f64; 2],
    pub u_range: [f64; 2],
    pub curves: Vec<Curve>,
    pub points: Vec<Codim2>,
    pub regions: Vec<Region>,
}

/// The parameter set with `name` = `p` (validated).
fn params_at(base: &Params, name: &str, p: f64) -> Result<Params, BifError> {
    base.with(name, p)
        .map_err(|e| BifError::Degenerate(format!("parameter {name} = {p}: {e}")))
}

/// Checks the options and that every parameter value of the range is admissible (both ends
/// and 64 values between).
pub fn validate(base: &Params, opts: &PlaneOptions) -> Result<(), BifError> {
    let bad = |field, value, reason| {
        Err(BifError::InvalidOption {
            field,
            value,
            reason,
        })
    };
    base.get(&opts.param)
        .map_err(|e| BifError::Degenerate(e.to_string()))?;
    // Each check names the option that is wrong.
    if !opts.p_min.is_finite() {
        return bad("p_min", opts.p_min, "must be finite");
    }
    if !opts.p_max.is_finite() {
        return bad("p_max", opts.p_max, "must be finite");
    }
    if opts.p_max <= opts.p_min {
        return bad("p_max", opts.p_max, "must be greater than p_min");
    }
    // The u window and the flows' tolerance are the one-parameter diagram's.
    DiagramOptions {
        u_min: opts.u_min,
        u_max: opts.u_max,
        tol: opts.tol,
        ..DiagramOptions::default()
    }
    .validate()?;
    if opts.max_points < 2 {
        return bad("max_points", opts.max_points as f64, "must be at least 2");
    }
    if let Some(p) = opts.p_start
        && !(opts.p_min..=opts.p_max).contains(&p)
    {
        return bad("p_start", p, "must lie in [p_min, p_max]");
    }
    for k in 0..=64 {
        let p = opts.p_min + (opts.p_max - opts.p_min) * k as f64 / 64.0;
        base.with(&opts.param, p).map_err(|e| {
            BifError::Degenerate(format!(
                "--param {} over [{}, {}]: {e}",
                opts.param,
                rotor_model::Num(opts.p_min),
                rotor_model::Num(opts.p_max)
            ))
        })?;
    }
    Ok(())
}

/// Hopf: `H(p, ω) = Re λ(ω; p)`.
fn hopf_system<'a>(
    base: &'a Params,
    name: &'a str,
) -> impl Fn(&[f64]) -> Result<Vec<f64>, BifError> + 'a {
    move |y| {
        let m = Model::new(params_at(base, name, y[0])?);
        if y[1] <= 0.0 {
            return Err(BifError::Degenerate(
                "omega <= 0: the stuck boundary".into(),
            ));
        }
        let l = crate::equilibria::complex_pair(&m, y[1])
            .ok_or_else(|| BifError::Degenerate("no complex pair".into()))?;
        Ok(vec![l.re])
    }
}

/// Grazing: `H(p, u, w) = G(u, w; p)`.
fn grazing_system<'a>(
    base: &'a Params,
    name: &'a str,
    tol: f64,
) -> impl Fn(&[f64]) -> Result<Vec<f64>, BifError> + 'a {
    move |y| {
        let m = Model::new(params_at(base, name, y[0])?);
        let (g, _, _) = grazing::residual(&m, y[1], y[2], tol)?;
        Ok(g.to_vec())
    }
}

fn continuer(model: &Model, tol: f64) -> Continuer<'_> {
    Continuer {
        sh: Shooter { model, tol },
        opts: ContOptions {
            u_min: 0.0,
            u_max: crate::U_MAX,
            h_max: 0.0,
            h_min: 0.0,
            newton_tol: 1e-10,
            amp_stop: 0.0,
            max_nodes: 0,
            fd_step: 1e-6,
            multipliers: Multipliers::Saltation,
        },
    }
}

/// Smooth fold: `H(p, α, ω_u, u) = (P(z) − z, det(∂P/∂z − I))` on the section `ω_l = ω*(u)`.
fn fold_system<'a>(
    base: &'a Params,
    name: &'a str,
    tol: f64,
) -> impl Fn(&[f64]) -> Result<Vec<f64>, BifError> + 'a {
    move |y| {
        let m = Model::new(params_at(base, name, y[0])?);
        let cont = continuer(&m, tol);
        let lin = cont.residual_jacobian(&[y[3], y[1], y[2]])?;
        let dz = lin.derivs.dz - nalgebra::Matrix2::identity();
        Ok(vec![lin.f[0], lin.f[1], dz.determinant()])
    }
}

fn arc_opts(max_points: usize) -> ArcOptions {
    ArcOptions {
        h0: 0.02,
        h_max: 0.1,
        h_min: 1e-5,
        max_points,
        tol: 1e-10,
        fd: 1e-7,
    }
}

/// Both directions of a curve from `y0`, joined into one ordered list (the backward part
/// reversed), with the reason each end ended.
fn both_ways(
    h: &crate::arc::System,
    y0: &[f64],
    scale: &[f64],
    opts: &ArcOptions,
    inside: &dyn Fn(&[f64]) -> bool,
) -> (Vec<Vec<f64>>, [ArcEnd; 2]) {
    let mut dir = vec![0.0; y0.len()];
    dir[0] = 1.0;
    let (fwd, e1) = follow(h, y0, &dir, scale, opts, inside);
    dir[0] = -1.0;
    let (bwd, e0) = follow(h, y0, &dir, scale, opts, inside);
    let mut pts: Vec<Vec<f64>> = bwd.into_iter().skip(1).rev().collect();
    pts.extend(fwd);
    (pts, [e0, e1])
}

fn end_text(e: &ArcEnd) -> String {
    match e {
        ArcEnd::Left => "left the range".into(),
        ArcEnd::MaxPoints => "point limit".into(),
        ArcEnd::Stuck(why) => format!("stopped: {why}"),
    }
}

/// The two-parameter picture (see the module docs).
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
    known: Option<&crate::Diagram>,
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
    let p_scale = p0.abs().max(1e-3 * (opts.p_max - opts.p_min)).max(1e-12);
    let inside_pu =
        |p: f64, u: f64| p >= opts.p_min && p <= opts.p_max && u >= opts.u_min && u <= opts.u_max;
    let ao = arc_opts(opts.max_points);
    let mut curves = Vec::new();
    let mut counts = std::collections::BTreeMap::<&str, usize>::new();
    let mut label = |prefix: &'static str| {
        let n = counts.entry(prefix).or_insert(0);
        *n += 1;
        format!("{prefix}{n}")
    };
    for sp in &d.points {
        match sp.kind {
            PointKind::Hopf => {
                let Some(w0) = sp.omega else { continue };
                let h = hopf_system(base, name);
                let inside = |y: &[f64]| {
                    y[1] > 0.0
                        && params_at(base, name, y[0]).is_ok_and(|pp| {
                            inside_pu(y[0], Model::new(pp).slip_equilibrium_at(y[1]).u)
                        })
                };
                let (pts, ends) = both_ways(&h, &[p0, w0], &[p_scale, w0.max(0.1)], &ao, &inside);
                let points = pts
                    .iter()
                    .filter_map(|y| {
                        let m = Model::new(params_at(base, name, y[0]).ok()?);
                        let res = h(y).ok()?[0];
                        Some(CurvePoint {
                            p: y[0],
                            u: m.slip_equilibrium_at(y[1]).u,
                            residual: res,
                            omega: Some(y[1]),
                            l1: first_lyapunov(&m, y[1]),
                            multiplier: None,
                            grazing_type: None,
                            period_doubling: None,
                            sigma_plus: None,
                            sigma_minus: None,
                            touch_omega_u: None,
                            section_state: None,
                        })
                    })
                    .collect();
                curves.push(Curve {
                    kind: CurveKind::Hopf,
                    label: label("H"),
                    points,
                    ends: ends.iter().map(end_text).collect(),
                });
            }
            PointKind::Grazing => {
                let Some(w0) = sp.touch_omega_u else { continue };
                let h = grazing_system(base, name, opts.tol);
                let inside = |y: &[f64]| inside_pu(y[0], y[1]);
                let (pts, ends) = both_ways(
                    &h,
                    &[p0, sp.u, w0],
                    &[p_scale, sp.u.max(1.0), w0.abs().max(1.0)],
                    &ao,
                    &inside,
                );
                let lab = label("G");
                let points: Vec<CurvePoint> = pts
                    .iter()
                    .filter_map(|y| {
                        let m = Model::new(params_at(base, name, y[0]).ok()?);
                        let g = h(y).ok()?;
                        let f = grazing::classify(&m, y[1], y[2], opts.tol).ok();
                        Some(CurvePoint {
                            p: y[0],
                            u: y[1],
                            residual: g[0].abs().max(g[1].abs()),
                            omega: None,
                            l1: None,
                            multiplier: f.map(|f| {
                                f.slipping
                                    .multipliers()
                                    .iter()
                                    .map(|z| z.norm())
                                    .fold(0.0, f64::max)
                            }),
                            grazing_type: f.map(|f| f.kind),
                            period_doubling: f.map(|f| f.period_doubling),
                            sigma_plus: f.map(|f| f.sigma_plus),
                            sigma_minus: f.map(|f| f.sigma_minus),
                            touch_omega_u: Some(y[2]),
                            section_state: None,
                        })
                    })
                    .collect();
                curves.extend(split_grazing(&lab, points, ends));
            }
            PointKind::Fold if sp.discontinuous == Some(false) => {
                let Some(z) = sp.section_state else { continue };
                let h = fold_system(base, name, opts.tol);
                let inside = |y: &[f64]| inside_pu(y[0], y[3]);
                let (pts, ends) = both_ways(
                    &h,
                    &[p0, z[0], z[1], sp.u],
                    &[
                        p_scale,
                        z[0].abs().max(1.0),
                        z[1].abs().max(1.0),
                        sp.u.max(1.0),
                    ],
                    &ao,
                    &inside,
                );
                let points = pts
                    .iter()
                    .filter_map(|y| {
                        let r = h(y).ok()?;
                        Some(CurvePoint {
                            p: y[0],
                            u: y[3],
                            residual: r.iter().fold(0.0f64, |a, v| a.max(v.abs())),
                            omega: None,
                            l1: None,
                            multiplier: None,
                            grazing_type: None,
                            period_doubling: None,
                            sigma_plus: None,
                            sigma_minus: None,
                            touch_omega_u: None,
                            section_state: Some([y[1], y[2]]),
                        })
                    })
                    .collect();
                curves.push(Curve {
                    kind: CurveKind::Fold,
                    label: label("F"),
                    points,
                    ends: ends.iter().map(end_text).collect(),
                });
            }
            PointKind::StickLimit => {
                let n = 41;
                let points = (0..n)
                    .filter_map(|k| {
                        let p = opts.p_min + (opts.p_max - opts.p_min) * k as f64 / (n - 1) as f64;
                        let m = Model::new(params_at(base, name, p).ok()?);
                        let u = m.slip_equilibrium_at(0.0).u;
                        (u >= opts.u_min && u <= opts.u_max).then_some(CurvePoint {
                            p,
                            u,
                            residual: 0.0,
                            omega: Some(0.0),
                            l1: None,
                            multiplier: None,
                            grazing_type: None,
                            period_doubling: None,
                            sigma_plus: None,
                            sigma_minus: None,
                            touch_omega_u: None,
                            section_state: None,
                        })
                    })
                    .collect();
                curves.push(Curve {
                    kind: CurveKind::StuckBoundary,
                    label: "S".into(),
                    points,
                    ends: Vec::new(),
                });
            }
            _ => {}
        }
    }
    let mut points = split_at_type_changes(base, name, &mut curves, opts.tol);
    points.extend(codim2(base, name, &curves, opts));
    points.sort_by(|a, b| a.p.total_cmp(&b.p));
    let regions = regions(base, name, opts, &curves)?;
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

/// A grazing curve split where its Feigin type changes between persistence (a plain grazing
/// curve) and a non-smooth fold ([`crate::feigin`]); points whose type could not be computed
/// keep the kind of the point before.
fn split_grazing(label: &str, points: Vec<CurvePoint>, ends: [ArcEnd; 2]) -> Vec<Curve> {
    let fold = |p: &CurvePoint| p.grazing_type.map(|t| t == GrazingType::NonsmoothFold);
    let mut out: Vec<Curve> = Vec::new();
    let mut current: Option<bool> = None;
    for p in points {
        let f = fold(&p).or(current).unwrap_or(false);
        if current != Some(f) {
            // The new piece starts at the last point of the old one, so the curve stays whole.
            let start = out.last().and_then(|c| c.points.last().cloned());
            out.push(Curve {
                kind: if f {
                    CurveKind::DiscontinuousFold
                } else {
                    CurveKind::Grazing
                },
                label: label.to_owned(),
                points: start.into_iter().collect(),
                ends: Vec::new(),
            });
            current = Some(f);
        }
        out.last_mut().expect("pushed above").points.push(p);
    }
    if let Some(first) = out.first_mut() {
        first.ends.push(end_text(&ends[0]));
    }
    if let Some(last) = out.last_mut() {
        last.ends.push(end_text(&ends[1]));
    }
    out
}

/// Where a grazing curve changes Feigin type (two consecutive pieces of one label and
/// different kinds): the point located by [`grazing_fold`] between the last vertex of one piece
/// and the second of the next (the first is shared and has the old type), made the end of the
/// first piece and the start of the second, so that each piece holds only points of its type
/// and the drawn type at any p is the classifier's. Returns the `grazing_fold` points.
fn split_at_type_changes(base: &Params, name: &str, curves: &mut [Curve], tol: f64) -> Vec<Codim2> {
    let mut out = Vec::new();
    for i in 1..curves.len() {
        let (head, tail) = curves.split_at_mut(i);
        let (a, b) = (&mut head[i - 1], &mut tail[0]);
        if a.label != b.label || a.kind == b.kind {
            continue;
        }
        let (Some(pa), Some(pb)) = (
            a.points.iter().rev().nth(1).or(a.points.last()).cloned(),
            b.points.get(1).cloned(),
        ) else {
            continue;
        };
        let located = grazing_fold(base, name, &pa, &pb, tol).and_then(|(p, u, w)| {
            let m = Model::new(params_at(base, name, p).ok()?);
            let (g, _, _) = grazing::residual(&m, u, w, tol).ok()?;
            Some((p, u, w, g[0].abs().max(g[1].abs())))
        });
        let (p, u) = match located {
            Some((p, u, w, residual)) => {
                let q = CurvePoint {
                    p,
                    u,
                    residual,
                    touch_omega_u: Some(w),
                    // On the border between the types: neither.
                    multiplier: None,
                    grazing_type: None,
                    period_doubling: None,
                    sigma_plus: None,
                    sigma_minus: None,
                    ..b.points[0].clone()
                };
                a.points.push(q.clone());
                b.points[0] = q;
                (p, u)
            }
            None => (b.points[0].p, b.points[0].u),
        };
        out.push(Codim2 {
            kind: Codim2Kind::GrazingFold,
            p,
            u,
            curves: vec![a.label.clone()],
            detail: format!(
                "the grazing orbit changes from {} to {}: a multiplier of the slipping or the \
                 stick-slip cycle at grazing crosses +1 (Feigin's sigma+ changes parity), so a \
                 fold of cycles meets the grazing curve",
                kind_name(a.kind),
                kind_name(b.kind)
            ),
        });
    }
    out
}

/// The codimension-two points on and between the curves.
fn codim2(base: &Params, name: &str, curves: &[Curve], opts: &PlaneOptions) -> Vec<Codim2> {
    let mut out = Vec::new();
    for c in curves {
        let pts = &c.points;
        for w in pts.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if let (Some(la), Some(lb)) = (a.l1, b.l1)
                && la * lb < 0.0
            {
                out.push(bautin(base, name, a, b, &c.label));
            }
        }
        // Turning points in p (interior extremum of p along the curve).
        for w in pts.windows(3) {
            let (a, b, cc) = (&w[0], &w[1], &w[2]);
            if (b.p - a.p) * (cc.p - b.p) < 0.0 {
                let (kind, what) = match c.kind {
                    CurveKind::Hopf => (Codim2Kind::HopfMerge, "two Hopf points meet and vanish"),
                    CurveKind::Fold => (Codim2Kind::Cusp, "two folds of cycles meet"),
                    _ => (Codim2Kind::Turning, "the curve turns back in the parameter"),
                };
                out.push(Codim2 {
                    kind,
                    p: b.p,
                    u: b.u,
                    curves: vec![c.label.clone()],
                    detail: format!(
                        "{what}: the extreme value of {name} along {} (to the step of the \
                         continuation)",
                        c.label
                    ),
                });
            }
        }
        // Hopf curves end where the equilibrium's velocity reaches 0: the stuck boundary.
        if c.kind == CurveKind::Hopf {
            for end in [pts.first(), pts.last()].into_iter().flatten() {
                if end.omega.is_some_and(|w| w < 1e-3) {
                    out.push(Codim2 {
                        kind: Codim2Kind::StuckEnd,
                        p: end.p,
                        u: end.u,
                        curves: vec![c.label.clone(), "S".into()],
                        detail: "the Hopf curve ends where the equilibrium's velocity reaches 0 \
                                 (the stuck boundary)"
                            .into(),
                    });
                }
            }
        }
    }
    // Curves of different labels that cross: at each point of one curve inside the other's
    // range of p, the other solved at that p exactly (its defining system from the
    // interpolation between its neighbouring points); a sign change of the difference in u
    // is bisected (on exact solves of both) to 1e-10 of the range of p. Two curves close
    // together (Stribeck's H1 and G1 are 2.4e-4 V apart) would cross spuriously as chords.
    for (i, a) in curves.iter().enumerate() {
        for b in curves.iter().skip(i + 1) {
            if a.label == b.label {
                continue;
            }
            let diff = |p: f64, near: f64| -> Option<(f64, f64)> {
                let ua = solve_u(base, name, a, p, near, opts.tol)?;
                let ub = solve_u(base, name, b, p, ua, opts.tol)?;
                Some((ua - ub, ua))
            };
            let mut prev: Option<(f64, f64)> = None;
            for q in &a.points {
                let Some((d, _)) = diff(q.p, q.u) else {
                    prev = None;
                    continue;
                };
                if let Some((pp, dp)) = prev
                    && dp * d < 0.0
                {
                    let (mut lo, mut hi, mut dlo) = (pp, q.p, dp);
                    let mut at = (0.5 * (lo + hi), q.u);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        let Some((dm, um)) = diff(mid, q.u) else {
                            break;
                        };
                        at = (mid, um);
                        if dm * dlo > 0.0 {
                            (lo, dlo) = (mid, dm);
                        } else {
                            hi = mid;
                        }
                        if (hi - lo).abs() <= 1e-10 * (opts.p_max - opts.p_min) {
                            break;
                        }
                    }
                    out.push(Codim2 {
                        kind: Codim2Kind::CurvesCross,
                        p: at.0,
                        u: at.1,
                        curves: vec![a.label.clone(), b.label.clone()],
                        detail: format!(
                            "{} ({}) and {} ({}) cross here; no normal form is claimed",
                            a.label,
                            kind_name(a.kind),
                            b.label,
                            kind_name(b.kind)
                        ),
                    });
                }
                prev = Some((q.p, d));
            }
        }
    }
    out.sort_by(|a, b| a.p.total_cmp(&b.p));
    out
}

/// u of curve `c` at parameter `p`, solved exactly from the interpolation between its two
/// points around `p` (the pair whose u is nearest `near` if the curve passes `p` more than
/// once): Hopf by a secant in ω on Re λ, grazing by the grazing Newton, the stuck boundary
/// explicitly, a fold by Newton on its augmented system. `None` outside the curve's range of p
/// or if the solve does not converge.
pub fn solve_u(base: &Params, name: &str, c: &Curve, p: f64, near: f64, tol: f64) -> Option<f64> {
    let seg = c
        .points
        .windows(2)
        .filter(|w| (w[0].p - p) * (w[1].p - p) <= 0.0 && w[0].p != w[1].p)
        .min_by(|x, y| {
            let ux = 0.5 * (x[0].u + x[1].u);
            let uy = 0.5 * (y[0].u + y[1].u);
            (ux - near).abs().total_cmp(&(uy - near).abs())
        })?;
    let (a, b) = (&seg[0], &seg[1]);
    let s = (p - a.p) / (b.p - a.p);
    let lerp = |x: f64, y: f64| x + s * (y - x);
    let m = Model::new(params_at(base, name, p).ok()?);
    match c.kind {
        CurveKind::StuckBoundary => Some(m.slip_equilibrium_at(0.0).u),
        CurveKind::Hopf => {
            let g = |w: f64| crate::equilibria::complex_pair(&m, w).map(|l| l.re);
            let w0 = lerp(a.omega?, b.omega?);
            let (mut x0, mut x1) = (w0, w0 * (1.0 + 1e-6) + 1e-9);
            let (mut f0, mut f1) = (g(x0)?, g(x1)?);
            for _ in 0..60 {
                if f1 == f0 || f1 == 0.0 {
                    break;
                }
                let x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
                (x0, f0, x1) = (x1, f1, x2);
                f1 = g(x1)?;
            }
            (f1.abs() < 1e-13).then(|| m.slip_equilibrium_at(x1).u)
        }
        CurveKind::Grazing | CurveKind::DiscontinuousFold => {
            let w0 = lerp(a.touch_omega_u?, b.touch_omega_u?);
            grazing::locate(&m, lerp(a.u, b.u), w0, tol, 1e-11)
                .ok()
                .map(|g| g.u)
        }
        CurveKind::Fold => {
            // Newton at fixed p on (P(z) − z, det(∂P/∂z − I)) in (α, ω_u, u).
            let (za, zb) = (a.section_state?, b.section_state?);
            let h = fold_system(base, name, tol);
            let mut y = [p, lerp(za[0], zb[0]), lerp(za[1], zb[1]), lerp(a.u, b.u)];
            for _ in 0..20 {
                let r = h(&y).ok()?;
                if r.iter().all(|v| v.abs() <= 1e-11) {
                    return Some(y[3]);
                }
                let mut j = Matrix3::zeros();
                for k in 0..3 {
                    let d = 1e-7 * y[k + 1].abs().max(1.0);
                    let mut yk = y;
                    yk[k + 1] += d;
                    let rk = h(&yk).ok()?;
                    for i in 0..3 {
                        j[(i, k)] = (rk[i] - r[i]) / d;
                    }
                }
                let dy = j.lu().solve(&Vector3::new(-r[0], -r[1], -r[2]))?;
                for k in 0..3 {
                    y[k + 1] += dy[k];
                }
            }
            None
        }
    }
}

fn kind_name(k: CurveKind) -> &'static str {
    match k {
        CurveKind::Hopf => "Hopf",
        CurveKind::Grazing => "grazing",
        CurveKind::Fold => "fold of cycles",
        CurveKind::DiscontinuousFold => "discontinuous fold",
        CurveKind::StuckBoundary => "stuck boundary",
    }
}

/// The point between two grazing points of different Feigin type: bisection in p on the sign
/// of Feigin's fold indicator `det(I − A)·det(I − B)` ([`Feigin::fold_indicator`]; it changes
/// sign where a multiplier of either side crosses +1), the grazing orbit located at each p
/// from the linear interpolation.
fn grazing_fold(
    base: &Params,
    name: &str,
    a: &CurvePoint,
    b: &CurvePoint,
    tol: f64,
) -> Option<(f64, f64, f64)> {
    let at = |p: f64, s: f64| -> Option<(f64, f64, Feigin)> {
        let m = Model::new(params_at(base, name, p).ok()?);
        let (u0, w0) = (
            a.u + s * (b.u - a.u),
            a.touch_omega_u? + s * (b.touch_omega_u? - a.touch_omega_u?),
        );
        let g = grazing::locate(&m, u0, w0, tol, 1e-11).ok()?;
        Some((g.u, g.w, grazing::classify(&m, g.u, g.w, tol).ok()?))
    };
    let sign_a = at(a.p, 0.0)?.2.fold_indicator();
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut best = (a.p, a.u, a.touch_omega_u?);
    for _ in 0..30 {
        let s = 0.5 * (lo + hi);
        let p = a.p + s * (b.p - a.p);
        let (u, w, f) = at(p, s)?;
        best = (p, u, w);
        if f.fold_indicator() * sign_a > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
    }
    Some(best)
}

/// The Bautin point between two points of a Hopf curve whose l1 differ in sign: bisection in
/// p on the segment, the Hopf condition solved for ω at each p (secant on Re λ).
fn bautin(base: &Params, name: &str, a: &CurvePoint, b: &CurvePoint, label: &str) -> Codim2 {
    let (mut pa, mut wa, mut la) = (a.p, a.omega.unwrap_or(0.0), a.l1.unwrap_or(0.0));
    let (mut pb, mut wb) = (b.p, b.omega.unwrap_or(0.0));
    let hopf_at = |p: f64, w0: f64| -> Option<(f64, f64, f64)> {
        let m = Model::new(params_at(base, name, p).ok()?);
        let g = |w: f64| crate::equilibria::complex_pair(&m, w).map(|l| l.re);
        let (mut x0, mut x1) = (w0, w0 * (1.0 + 1e-4) + 1e-8);
        let (mut f0, mut f1) = (g(x0)?, g(x1)?);
        for _ in 0..50 {
            if f1 == f0 {
                break;
            }
            let x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
            (x0, f0, x1) = (x1, f1, x2);
            f1 = g(x1)?;
            if f1.abs() < 1e-15 {
                break;
            }
        }
        Some((x1, m.slip_equilibrium_at(x1).u, first_lyapunov(&m, x1)?))
    };
    let mut best = (a.p, a.u);
    for _ in 0..40 {
        let pm = 0.5 * (pa + pb);
        let wm = 0.5 * (wa + wb);
        let Some((w, u, l)) = hopf_at(pm, wm) else {
            break;
        };
        best = (pm, u);
        if l * la > 0.0 {
            (pa, wa, la) = (pm, w, l);
        } else {
            (pb, wb) = (pm, w);
        }
    }
    Codim2 {
        kind: Codim2Kind::Bautin,
        p: best.0,
        u: best.1,
        curves: vec![label.to_owned()],
        detail: "the first Lyapunov coefficient changes sign: the Hopf point changes from \
                 super- to subcritical (a fold of small cycles is born here)"
            .into(),
    }
}

/// What the orbit from a start reaches: `stuck`, `equilibrium`, `stick-slip cycle` or
/// `slipping cycle` (event-driven solver, metrics only, 1500 s, metrics over the last 500 s:
/// long enough for the slow transients a few tenths of a volt from a Hopf point).
pub fn classify(model: &Model, u: f64, x0: State) -> &'static str {
    let scene = Scene {
        u,
        x0,
        t_end: 1500.0,
        tol: 1e-8,
        output: Output::Metrics,
        metrics_from: Some(1000.0),
        ..Scene::default()
    };
    match rotor_event::EventSolver::default()
        .simulate(model, &scene)
        .map(|t| t.metrics)
    {
        Ok(Some(m)) if m.is_stuck() => "stuck",
        Ok(Some(SteadyState::Equilibrium { .. })) => "equilibrium",
        Ok(Some(SteadyState::LimitCycle { stick_time, .. })) if stick_time > 0.0 => {
            "stick-slip cycle"
        }
        Ok(Some(SteadyState::LimitCycle { .. })) => "slipping cycle",
        _ => "unresolved",
    }
}

/// The region's name from what rest and the perturbed equilibrium reach.
pub fn region_name(from_rest: &str, from_eq: &str) -> String {
    match (from_rest, from_eq) {
        ("stuck", "stuck") => "both discs stuck".into(),
        (a, b) if a == b => format!("{a} only"),
        (a, b) => {
            let mut v = [a, b];
            v.sort_unstable();
            format!("bistable: {} and {}", v[0], v[1])
        }
    }
}

/// The u where the curves cross the vertical line at `p`, linear between curve points,
/// in increasing order (a vertex on the line counts once).
fn crossings(curves: &[Curve], p: f64) -> Vec<f64> {
    let mut v: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.points.windows(2))
        .filter_map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let hit = (a.p <= p && p < b.p) || (b.p <= p && p < a.p);
            hit.then(|| a.u + (p - a.p) / (b.p - a.p) * (b.u - a.u))
        })
        .filter(|u| u.is_finite())
        .collect();
    v.sort_by(f64::total_cmp);
    v
}

/// A band of one column of the plane with one name: column `col`, u from `lo` to `hi`.
struct Piece {
    col: usize,
    lo: f64,
    hi: f64,
    name: String,
}

/// Names the regions. The curves cut each of `region_cells` columns (p at the cells'
/// centres) into bands; each band is classified at its middle from rest and from the
/// perturbed equilibrium, and a band taller than a cell (1/`region_cells` of the u-window)
/// once per cell, so that a region no curve bounds is still found. A band thinner than
/// 1/1000 of the u-window is not named: a simulation there, between two curves that nearly
/// meet, says more about its transient than about the region. Bands of one name that
/// overlap in neighbouring columns are one region, named once at its tallest band (the one
/// nearest the middle column among those within 1 % of the tallest).
fn regions(
    base: &Params,
    name: &str,
    opts: &PlaneOptions,
    curves: &[Curve],
) -> Result<Vec<Region>, BifError> {
    let n = opts.region_cells.max(2);
    let (u_min, u_max) = (opts.u_min, opts.u_max);
    let cell = (u_max - u_min) / n as f64;
    let thin = 1e-3 * (u_max - u_min);
    let column = |j: usize| opts.p_min + (opts.p_max - opts.p_min) * (j as f64 + 0.5) / n as f64;
    let mut pieces: Vec<Piece> = Vec::new();
    for j in 0..n {
        let p = column(j);
        let m = Model::new(params_at(base, name, p)?);
        let mut edges = vec![u_min];
        edges.extend(
            crossings(curves, p)
                .into_iter()
                .filter(|&u| u > u_min && u < u_max),
        );
        edges.push(u_max);
        for w in edges.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            if hi - lo < thin {
                continue;
            }
            let k = ((hi - lo) / cell).ceil().max(1.0) as usize;
            let at = |i: usize| lo + (hi - lo) * i as f64 / k as f64;
            let mut start = lo;
            let mut prev: Option<String> = None;
            for i in 0..k {
                let u = 0.5 * (at(i) + at(i + 1));
                let here = region_name(
                    classify(&m, u, State::zeros()),
                    classify(&m, u, m.perturbed_equilibrium(u)),
                );
                match prev.take() {
                    Some(before) if before != here => {
                        pieces.push(Piece {
                            col: j,
                            lo: start,
                            hi: at(i),
                            name: before,
                        });
                        start = at(i);
                    }
                    _ => {}
                }
                prev = Some(here);
            }
            if let Some(last) = prev {
                pieces.push(Piece {
                    col: j,
                    lo: start,
                    hi,
                    name: last,
                });
            }
        }
    }
    // Connected pieces: union-find over neighbours in adjacent columns.
    let mut root: Vec<usize> = (0..pieces.len()).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for a in 0..pieces.len() {
        for b in a + 1..pieces.len() {
            let (x, y) = (&pieces[a], &pieces[b]);
            if y.col == x.col + 1 && x.name == y.name && x.lo < y.hi && y.lo < x.hi {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                root[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let group: Vec<usize> = (0..pieces.len()).map(|i| find(&mut root, i)).collect();
    let height = |q: &Piece| q.hi - q.lo;
    // Each region's bands, tallest first (those within 1 % of the tallest: nearest the
    // middle column first).
    let mid = 0.5 * (n as f64 - 1.0);
    let off_middle = |q: &Piece| (q.col as f64 - mid).abs();
    let mut members: std::collections::BTreeMap<usize, Vec<&Piece>> = Default::default();
    for (q, &g) in pieces.iter().zip(&group) {
        members.entry(g).or_default().push(q);
    }
    let mut out: Vec<Region> = members
        .into_values()
        .map(|mut v| {
            let tallest = v.iter().map(|q| height(q)).fold(0.0, f64::max);
            let rank = |q: &Piece| (height(q) < 0.99 * tallest, -height(q), off_middle(q));
            v.sort_by(|a, b| {
                let (ra, rb) = (rank(a), rank(b));
                ra.0.cmp(&rb.0).then(if ra.0 {
                    ra.1.total_cmp(&rb.1)
                } else {
                    ra.2.total_cmp(&rb.2)
                })
            });
            let q = v[0];
            Region {
                name: q.name.clone(),
                p: column(q.col),
                u: 0.5 * (q.lo + q.hi),
                u_lo: q.lo,
                u_hi: q.hi,
                bands: v.iter().map(|q| [column(q.col), q.lo, q.hi]).collect(),
            }
        })
        .collect();
    out.sort_by(|a, b| a.u.total_cmp(&b.u).then(a.p.total_cmp(&b.p)));
    Ok(out)
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

    /// The (p, u) plane as an SVG figure over the computed window: each curve in its kind's
    /// colour and named in the margin when it reaches the window's right edge, else at its
    /// left end; the codimension-two points marked and named (those nearer than 3 % of the
    /// window share a label); the file's value of p dashed, with a dot where each curve
    /// crosses it (the one-parameter diagram's points); each region named in its band.
    pub fn to_svg(&self, title: &str) -> String {
        use rotor_plot::{Band, EndLabel, Label, Panel, Series, merge_close, render};
        let color = |k: CurveKind| match k {
            CurveKind::Hopf => "#1f77b4",
            CurveKind::Grazing => "#2ca02c",
            CurveKind::Fold => "#d62728",
            CurveKind::DiscontinuousFold => "#9467bd",
            CurveKind::StuckBoundary => "#7f7f7f",
        };
        let ([p_lo, p_hi], [u_lo, u_hi]) = (self.p_range, self.u_range);
        let (span_p, span_u) = (p_hi - p_lo, u_hi - u_lo);
        let drawn: Vec<Vec<(f64, f64)>> = self
            .curves
            .iter()
            .map(|c| clip_p(&c.points, p_lo, p_hi))
            .collect();
        let mut series: Vec<Series> = self
            .curves
            .iter()
            .zip(&drawn)
            .map(|(c, pts)| Series::line("", color(c.kind), pts.clone()))
            .collect();
        for (kind, text) in [
            (CurveKind::Hopf, "Hopf"),
            (CurveKind::Grazing, "grazing"),
            (CurveKind::Fold, "fold of cycles"),
            (CurveKind::DiscontinuousFold, "discontinuous fold"),
            (CurveKind::StuckBoundary, "stuck boundary"),
        ] {
            if self.curves.iter().any(|c| c.kind == kind) {
                series.push(Series::line(text, color(kind), Vec::new()));
            }
        }
        if (p_lo..=p_hi).contains(&self.p_file) {
            series.push(Series {
                dash: Some("4 4"),
                width: 1.0,
                ..Series::line(
                    "file value",
                    "#000000",
                    vec![(self.p_file, u_lo), (self.p_file, u_hi)],
                )
            });
            let dots = crossings(&self.curves, self.p_file)
                .into_iter()
                .filter(|u| (u_lo..=u_hi).contains(u))
                .map(|u| (self.p_file, u))
                .collect();
            series.push(Series {
                width: 0.0,
                marker: Some(2.5),
                ..Series::line("", "#000000", dots)
            });
        }
        let mut panel = Panel::new(title.to_owned(), &self.param, "u [V]", series);
        panel.clear_x.push(self.p_file);
        for (c, pts) in self.curves.iter().zip(&drawn) {
            let finite = || pts.iter().filter(|q| q.0.is_finite() && q.1.is_finite());
            let right = finite().max_by(|a, b| a.0.total_cmp(&b.0));
            let left = finite().min_by(|a, b| a.0.total_cmp(&b.0));
            // Named in the margin if it reaches the right edge, else at its left end (its
            // right end is often a codimension-two point, already named).
            let (end, margin) = match right {
                Some(&q) if p_hi - q.0 <= 1e-9 * span_p => (Some(q), true),
                _ => (left.copied(), false),
            };
            if let Some((x, y)) = end {
                panel.ends.push(EndLabel {
                    x,
                    y,
                    text: c.label.clone(),
                    color: color(c.kind).to_owned(),
                    margin,
                });
            }
        }
        panel.labels = merge_close(
            self.points
                .iter()
                .filter(|q| (p_lo..=p_hi).contains(&q.p))
                .map(|q| Label {
                    x: q.p,
                    y: q.u,
                    text: q.kind.title().to_owned(),
                })
                .collect(),
            span_p,
            span_u,
            0.03,
        );
        panel.bands = self
            .regions
            .iter()
            .map(|r| Band {
                text: r.name.clone(),
                places: r.bands.iter().map(|b| (b[0], b[1], b[2])).collect(),
            })
            .collect();
        render(&[panel], 760.0, 560.0)
    }
}

/// A curve's points with p in `[lo, hi]`, cut where it leaves and enters that window (the
/// cut points interpolated on the edge, a NaN point between the pieces).
fn clip_p(points: &[CurvePoint], lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let inside = |p: f64| (lo..=hi).contains(&p);
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut push = |q: (f64, f64)| {
        if inside(q.0) {
            out.push(q);
        } else if out.last().is_some_and(|l| l.0.is_finite()) {
            out.push((f64::NAN, f64::NAN));
        }
    };
    for (i, b) in points.iter().enumerate() {
        if let Some(a) = i.checked_sub(1).map(|k| &points[k]) {
            let mut cuts: Vec<f64> = [lo, hi]
                .into_iter()
                .filter(|e| (a.p - e) * (b.p - e) < 0.0)
                .map(|e| (e - a.p) / (b.p - a.p))
                .collect();
            cuts.sort_by(f64::total_cmp);
            for s in cuts {
                // The edge itself, not its value rounded through s.
                let at = a.p + s * (b.p - a.p);
                let edge = if (at - lo).abs() < (at - hi).abs() {
                    lo
                } else {
                    hi
                };
                push((edge, a.u + s * (b.u - a.u)));
            }
        }
        push((b.p, b.u));
    }
    if out.last().is_some_and(|l| l.0.is_nan()) {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve is cut on the window's edges, the cut points on the edges exactly, with a pen
    /// lift between the pieces; a segment that crosses the whole window keeps both cuts.
    #[test]
    fn curves_are_clipped_to_the_window() {
        let pt = |p: f64, u: f64| CurvePoint {
            p,
            u,
            residual: 0.0,
            omega: None,
            l1: None,
            multiplier: None,
            grazing_type: None,
            period_doubling: None,
            sigma_plus: None,
            sigma_minus: None,
            touch_omega_u: None,
            section_state: None,
        };
        let c = [pt(-1.0, 0.0), pt(0.5, 1.5), pt(2.0, 3.0), pt(0.5, 4.5)];
        let out = clip_p(&c, 0.0, 1.0);
        let fin: Vec<(f64, f64)> = out.iter().copied().filter(|q| q.0.is_finite()).collect();
        assert_eq!(
            fin,
            [(0.0, 1.0), (0.5, 1.5), (1.0, 2.0), (1.0, 4.0), (0.5, 4.5)]
        );
        assert!(out[3].0.is_nan() && out.len() == 6, "{out:?}");
        let across = clip_p(&[pt(-1.0, 0.0), pt(3.0, 4.0)], 0.0, 1.0);
        assert_eq!(across, [(0.0, 1.0), (1.0, 2.0)]);
    }

    /// Each bad option is refused with its own name, whatever else is wrong or right.
    #[test]
    fn options_are_validated_with_the_field_named() {
        let base = Params::table1();
        let ok = PlaneOptions::new("k_theta", 0.05, 0.1);
        assert!(validate(&base, &ok).is_ok());
        type Spoil = fn(&mut PlaneOptions);
        let cases: [(Spoil, &str); 12] = [
            (|o| o.p_min = f64::NAN, "p_min"),
            (|o| o.p_max = f64::INFINITY, "p_max"),
            (|o| o.p_max = o.p_min, "p_max"),
            (|o| o.u_min = -5.0, "u_min"),
            (|o| o.u_min = f64::NAN, "u_min"),
            (|o| o.u_max = 1e300, "u_max"),
            (|o| o.u_max = 0.0, "u_max"),
            (|o| o.tol = 0.0, "tol"),
            (|o| o.max_points = 1, "max_points"),
            (|o| o.p_start = Some(1.0), "p_start"),
            (|o| o.p_start = Some(f64::NAN), "p_start"),
            (|o| o.p_min = -1.0, "k_theta"),
        ];
        for (spoil, field) in cases {
            let mut o = ok.clone();
            spoil(&mut o);
            let e = validate(&base, &o).unwrap_err();
            if let BifError::InvalidOption { field: f, .. } = e {
                assert_eq!(f, field);
            }
            assert!(e.to_string().contains(field), "{field}: {e}");
        }
        // Numbers are written as one would type them back, not in 300 digits.
        let mut o = ok.clone();
        o.u_max = 1e300;
        let e = validate(&base, &o).unwrap_err().to_string();
        assert_eq!(
            e,
            "invalid option u_max = 1e300: must be <= 1000 V: the Hopf search samples omega up \
             to 1e4 rad/s"
        );
        o = PlaneOptions::new("k_theta", -1e-300, 0.1);
        let e = validate(&base, &o).unwrap_err().to_string();
        assert!(
            e.starts_with("--param k_theta over [-1e-300, 0.1]: "),
            "{e}"
        );
    }
}
