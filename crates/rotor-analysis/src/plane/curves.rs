//! The codimension-one curves in the (p, u) plane: their points ([`CurvePoint`]), their
//! defining systems (Hopf, grazing, smooth fold, the explicit stuck boundary), each curve
//! followed both ways from the one-parameter diagram's point, a grazing curve split where
//! its Feigin type changes, and u of a curve at a given p solved exactly ([`solve_u`]).

use crate::bifurcation::continuation::{ContOptions, Continuer, Multipliers};
use crate::bifurcation::equilibria::{complex_pair, first_lyapunov};
use crate::bifurcation::feigin::GrazingType;
use crate::bifurcation::periodic::Shooter;
use crate::bifurcation::{BifError, Diagram, PointKind, grazing};
use nalgebra::{Matrix3, Vector3};
use rotor_model::{Model, Params};
use serde::Serialize;

use crate::plane::arc::{ArcEnd, ArcOptions, System, follow};
use crate::plane::options::{PlaneOptions, params_at};

/// A kind of codimension-one curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// Hopf points of the slipping equilibrium.
    Hopf,
    /// Grazing orbits that persist (Feigin's persistence).
    Grazing,
    /// Smooth folds of cycles (a multiplier 1).
    Fold,
    /// Grazing orbits where the branch turns back (Feigin's non-smooth fold).
    DiscontinuousFold,
    /// Where the slipping branch meets the stuck set.
    StuckBoundary,
}

/// One point of a curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The parameter's value.
    pub p: f64,
    /// The input \[V\].
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
    /// Grazing: Feigin's type (`persistence` or `nonsmooth_fold`, [`crate::bifurcation::feigin`]).
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
    /// What the curve's points are.
    pub kind: CurveKind,
    /// `H1`, `G2`, `E`, `S`, … (as in the u-diagram: numbered by u at the start).
    pub label: String,
    /// Its points in order along the curve.
    pub points: Vec<CurvePoint>,
    /// Why each end of the curve ended (first end, last end).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ends: Vec<String>,
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
        let l =
            complex_pair(&m, y[1]).ok_or_else(|| BifError::Degenerate("no complex pair".into()))?;
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
            u_max: crate::bifurcation::U_MAX,
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
    h: &System,
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

/// Every codimension-one curve through the special points of `d`, the one-parameter diagram
/// at `p = p0`, followed both ways over the window of `opts` and labelled by kind in the
/// order of the diagram's points (`H1`, `G1`, `F1`, ...; `S` the stuck boundary, computed
/// explicitly at 41 values of p). A grazing curve comes as its pieces of one Feigin type
/// ([`split_grazing`]).
pub(crate) fn from_diagram(base: &Params, opts: &PlaneOptions, d: &Diagram, p0: f64) -> Vec<Curve> {
    let tracer = Tracer::new(base, opts, p0);
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
                curves.push(tracer.hopf(w0, label("H")));
            }
            PointKind::Grazing => {
                let Some(w0) = sp.touch_omega_u else { continue };
                curves.extend(tracer.grazing(sp.u, w0, &label("G")));
            }
            PointKind::Fold if sp.discontinuous == Some(false) => {
                let Some(z) = sp.section_state else { continue };
                curves.push(tracer.fold(sp.u, z, label("F")));
            }
            PointKind::StickLimit => curves.push(tracer.stuck_boundary()),
            _ => {}
        }
    }
    curves
}

impl CurvePoint {
    /// A point at `(p, u)` whose defining condition has the value `residual`, with none of
    /// the fields of a particular kind of curve.
    pub(crate) fn at(p: f64, u: f64, residual: f64) -> CurvePoint {
        CurvePoint {
            p,
            u,
            residual,
            omega: None,
            l1: None,
            multiplier: None,
            grazing_type: None,
            period_doubling: None,
            sigma_plus: None,
            sigma_minus: None,
            touch_omega_u: None,
            section_state: None,
        }
    }
}

/// Follows the curves through the special points of the one-parameter diagram at `p = p0`
/// over the window of `opts`, in parameter `name` of `base`.
struct Tracer<'a> {
    base: &'a Params,
    name: &'a str,
    opts: &'a PlaneOptions,
    p0: f64,
    /// The scale of p in a curve's steps: `max(|p0|, 1e-3·(p_max − p_min), 1e-12)`.
    p_scale: f64,
    ao: ArcOptions,
}

impl<'a> Tracer<'a> {
    /// The tracer of the curves through the diagram at `p0`.
    fn new(base: &'a Params, opts: &'a PlaneOptions, p0: f64) -> Self {
        Tracer {
            base,
            name: opts.param.as_str(),
            opts,
            p0,
            p_scale: p0.abs().max(1e-3 * (opts.p_max - opts.p_min)).max(1e-12),
            ao: arc_opts(opts.max_points),
        }
    }

    /// Whether `(p, u)` lies in the window.
    fn inside_pu(&self, p: f64, u: f64) -> bool {
        let o = self.opts;
        p >= o.p_min && p <= o.p_max && u >= o.u_min && u <= o.u_max
    }

    /// The Hopf curve through the diagram's Hopf point at ω = `w0`: `Re λ(ω; p) = 0` in
    /// `(p, ω)` ([`hopf_system`]), each point with its u, ω and first Lyapunov coefficient.
    fn hopf(&self, w0: f64, label: String) -> Curve {
        let (base, name) = (self.base, self.name);
        let h = hopf_system(base, name);
        let inside = |y: &[f64]| {
            y[1] > 0.0
                && params_at(base, name, y[0]).is_ok_and(|pp| {
                    self.inside_pu(y[0], Model::new(pp).slip_equilibrium_at(y[1]).u)
                })
        };
        let (pts, ends) = both_ways(
            &h,
            &[self.p0, w0],
            &[self.p_scale, w0.max(0.1)],
            &self.ao,
            &inside,
        );
        let points = pts
            .iter()
            .filter_map(|y| {
                let m = Model::new(params_at(base, name, y[0]).ok()?);
                let res = h(y).ok()?[0];
                Some(CurvePoint {
                    omega: Some(y[1]),
                    l1: first_lyapunov(&m, y[1]),
                    ..CurvePoint::at(y[0], m.slip_equilibrium_at(y[1]).u, res)
                })
            })
            .collect();
        Curve {
            kind: CurveKind::Hopf,
            label,
            points,
            ends: ends.iter().map(end_text).collect(),
        }
    }

    /// The grazing curve through the diagram's grazing orbit at `u`, touching at ω_u = `w0`:
    /// `G(u, w; p) = 0` in `(p, u, w)` ([`grazing_system`]), each point typed by Feigin's rule
    /// ([`grazing::classify`]) and the curve split where the type changes
    /// ([`split_grazing`]).
    fn grazing(&self, u: f64, w0: f64, label: &str) -> Vec<Curve> {
        let (base, name, tol) = (self.base, self.name, self.opts.tol);
        let h = grazing_system(base, name, tol);
        let inside = |y: &[f64]| self.inside_pu(y[0], y[1]);
        let (pts, ends) = both_ways(
            &h,
            &[self.p0, u, w0],
            &[self.p_scale, u.max(1.0), w0.abs().max(1.0)],
            &self.ao,
            &inside,
        );
        let points: Vec<CurvePoint> = pts
            .iter()
            .filter_map(|y| {
                let m = Model::new(params_at(base, name, y[0]).ok()?);
                let g = h(y).ok()?;
                let f = grazing::classify(&m, y[1], y[2], tol).ok();
                Some(CurvePoint {
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
                    ..CurvePoint::at(y[0], y[1], g[0].abs().max(g[1].abs()))
                })
            })
            .collect();
        split_grazing(label, points, ends)
    }

    /// The smooth-fold curve through the diagram's fold at `u` with section state `z`:
    /// `(P(z) − z, det(∂P/∂z − I)) = 0` in `(p, α, ω_u, u)` ([`fold_system`]), each point with
    /// its section state.
    fn fold(&self, u: f64, z: [f64; 3], label: String) -> Curve {
        let h = fold_system(self.base, self.name, self.opts.tol);
        let inside = |y: &[f64]| self.inside_pu(y[0], y[3]);
        let (pts, ends) = both_ways(
            &h,
            &[self.p0, z[0], z[1], u],
            &[
                self.p_scale,
                z[0].abs().max(1.0),
                z[1].abs().max(1.0),
                u.max(1.0),
            ],
            &self.ao,
            &inside,
        );
        let points = pts
            .iter()
            .filter_map(|y| {
                let r = h(y).ok()?;
                Some(CurvePoint {
                    section_state: Some([y[1], y[2]]),
                    ..CurvePoint::at(y[0], y[3], r.iter().fold(0.0f64, |a, v| a.max(v.abs())))
                })
            })
            .collect();
        Curve {
            kind: CurveKind::Fold,
            label,
            points,
            ends: ends.iter().map(end_text).collect(),
        }
    }

    /// The stuck boundary `S`, explicitly: u of the slipping equilibrium at ω = 0, at 41
    /// evenly spaced values of p over the window, where that u is in the window.
    fn stuck_boundary(&self) -> Curve {
        let (opts, n) = (self.opts, 41);
        let points = (0..n)
            .filter_map(|k| {
                let p = opts.p_min + (opts.p_max - opts.p_min) * k as f64 / (n - 1) as f64;
                let m = Model::new(params_at(self.base, self.name, p).ok()?);
                let u = m.slip_equilibrium_at(0.0).u;
                (u >= opts.u_min && u <= opts.u_max).then_some(CurvePoint {
                    omega: Some(0.0),
                    ..CurvePoint::at(p, u, 0.0)
                })
            })
            .collect();
        Curve {
            kind: CurveKind::StuckBoundary,
            label: "S".into(),
            points,
            ends: Vec::new(),
        }
    }
}

/// A grazing curve split where its Feigin type changes between persistence (a plain grazing
/// curve) and a non-smooth fold ([`crate::bifurcation::feigin`]); points whose type could not be computed
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
            let g = |w: f64| complex_pair(&m, w).map(|l| l.re);
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

/// The kind's words in a codimension-two point's detail.
pub(crate) fn kind_name(k: CurveKind) -> &'static str {
    match k {
        CurveKind::Hopf => "Hopf",
        CurveKind::Grazing => "grazing",
        CurveKind::Fold => "fold of cycles",
        CurveKind::DiscontinuousFold => "discontinuous fold",
        CurveKind::StuckBoundary => "stuck boundary",
    }
}
