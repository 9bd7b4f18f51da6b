//! Pseudo-arclength continuation of periodic orbits in `y = (u, α, ω_u)`.
//!
//! The periodic orbits at input u are the zeros of the section residual
//!
//! ```text
//! F(y) = P_{c(u)}(α, ω_u; u) − (α, ω_u) = 0,     F : R³ → R²,
//! ```
//!
//! a curve in R³. It is followed by pseudo-arclength: from a point `y_k` with unit tangent
//! `t_k` (the null vector of `DF(y_k)`: the cross product of its two rows, oriented along
//! the previous tangent), predict `y_p = y_k + h t_k` and correct with Newton (chord,
//! Jacobian at the predictor) on
//!
//! ```text
//! F(y) = 0,     t_k · (y − y_p) = 0.
//! ```
//!
//! `DF = [∂P/∂u, ∂P/∂z − I]` comes from the variational equations with saltation matrices
//! ([`Shooter::section_derivatives`]); a forward difference (step 1e-7) is kept as a check
//! ([`Continuer::jacobian_fd`]). The u-component of the tangent is, up to its norm,
//! `det(∂P/∂z − I)`, so it vanishes exactly where a Floquet multiplier of the section map is
//! 1: a fold in u is a sign change of it between two points, located by bisection on the
//! step length h from the earlier point. A grazing point (the cycle starts or stops touching
//! `ω_l = 0` with a stick phase) is a sign change of `g = ω_l,min` (slipping) / `−t_stick`
//! (stick-slip); it is located by [`crate::bifurcation::grazing`].
//!
//! Floquet multipliers of each point are the eigenvalues of the monodromy matrix from the
//! same variational integration ([`crate::bifurcation::monodromy`]); stability is read from the two
//! eigenvalues of `∂P/∂z` (the nontrivial multipliers). [`Multipliers::FiniteDifference`]
//! selects the earlier central differences of the return maps instead (a check).

use nalgebra::{Complex, Matrix3, Vector3};
use rotor_model::State;
use rotor_model::seam::{Output, RigSteady, Scene, Solver};

use crate::bifurcation::BifError;
use crate::bifurcation::monodromy::order_multipliers;
use crate::bifurcation::periodic::{SectionDerivs, Shooter, eig2};

/// How the Floquet multipliers of a cycle are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Multipliers {
    /// Eigenvalues of the monodromy matrix from the variational equations with saltation
    /// matrices ([`crate::bifurcation::monodromy`]).
    #[default]
    Saltation,
    /// Central differences of the return maps with step `ContOptions::fd_step`: the stick-exit
    /// map (1-D) for stick-slip cycles, the section map (2-D) for slipping ones.
    FiniteDifference,
}

/// What the diagram reports about one periodic orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleInfo {
    /// Period \[s\]: the return time to the section `ω_l = c(u)`.
    pub period: f64,
    /// Largest lower-disc velocity over the cycle \[rad/s\].
    pub omega_l_max: f64,
    /// Smallest lower-disc velocity over the cycle \[rad/s\]: 0 with a stick phase.
    pub omega_l_min: f64,
    /// Smallest upper-disc velocity over the cycle \[rad/s\] (the upper disc grazes ω_u = 0
    /// where it reaches 0).
    pub omega_u_min: f64,
    /// Time per period with the lower disc stuck \[s\].
    pub stick_time: f64,
    /// Whether the lower disc sticks on the cycle.
    pub stick_slip: bool,
    /// Floquet multipliers, the trivial one (nearest 1) first, then by decreasing modulus:
    /// `[≈1, λ, 0]` (stick-slip) or `[≈1, λ1, λ2]` (slipping).
    pub multipliers: Vec<Complex<f64>>,
    /// The nontrivial multipliers: eigenvalues of the section map's `∂P/∂z`.
    pub nontrivial: [Complex<f64>; 2],
    /// All nontrivial multipliers inside the unit circle.
    pub stable: bool,
}

impl CycleInfo {
    /// The grazing indicator: `ω_l,min > 0` for slipping cycles, `−t_stick ≤ 0` with stick.
    pub fn grazing_indicator(&self) -> f64 {
        if self.stick_slip {
            -self.stick_time
        } else {
            self.omega_l_min
        }
    }
}

/// One point of the periodic branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// `(u, α, ω_u)` on the section.
    pub y: [f64; 3],
    /// Section level `c(u)`.
    pub c: f64,
    /// Unit tangent of the branch.
    pub tangent: [f64; 3],
    /// Arclength step that produced this point from the previous one.
    pub step: f64,
    /// Period, extrema of ω_l, stick time and Floquet multipliers of the cycle.
    pub info: CycleInfo,
}

/// Why a branch direction ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// It left `[u_min, u_max]`.
    Range,
    /// Its amplitude fell below `amp_stop` (a Hopf point is near).
    Small,
    /// The step size collapsed (a non-smooth point: a grazing orbit where the branch turns).
    Stuck,
    /// The node limit.
    MaxNodes,
}

/// Continuation settings.
#[derive(Debug, Clone, Copy)]
pub struct ContOptions {
    /// Lower end of the input range \[V\]: a point below it ends the direction
    /// ([`End::Range`]).
    pub u_min: f64,
    /// Upper end of the input range \[V\]: a point above it ends the direction
    /// ([`End::Range`]).
    pub u_max: f64,
    /// Largest arclength step.
    pub h_max: f64,
    /// Smallest arclength step before the branch is given up.
    pub h_min: f64,
    /// Newton tolerance on |F|∞ \[rad, rad/s\].
    pub newton_tol: f64,
    /// ω_l amplitude below which a branch stops (it is about to end at a Hopf point) \[rad/s\].
    pub amp_stop: f64,
    /// Largest number of points per direction.
    pub max_nodes: usize,
    /// FD step of the Floquet multipliers (with [`Multipliers::FiniteDifference`]).
    pub fd_step: f64,
    /// How the multipliers are computed.
    pub multipliers: Multipliers,
}

impl ContOptions {
    /// Settings for work at the single input `u` (a Newton solve for a cycle, or describing
    /// one: multipliers by saltation matrices), not a continuation: every step and limit 0.
    pub fn at(u: f64, newton_tol: f64) -> ContOptions {
        ContOptions {
            u_min: u,
            u_max: u,
            h_max: 0.0,
            h_min: 0.0,
            newton_tol,
            amp_stop: 0.0,
            max_nodes: 0,
            fd_step: 0.0,
            multipliers: Multipliers::Saltation,
        }
    }
}

/// The residual of the continuation and its Jacobian at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearized {
    /// `F(y) = P_{c(u)}(z) − z`.
    pub f: [f64; 2],
    /// Section level `c(u)`.
    pub c: f64,
    /// `DF(y)`, rows `[∂F_i/∂u, ∂F_i/∂α, ∂F_i/∂ω_u]`.
    pub j: [[f64; 3]; 2],
    /// The section map's derivatives (and the monodromy matrix).
    pub derivs: SectionDerivs,
}

/// Pseudo-arclength continuation of the periodic orbits (see the module docs): the shooting
/// setup and the settings.
pub struct Continuer<'a> {
    /// The model and the integration tolerance of every return map.
    pub sh: Shooter<'a>,
    /// Steps, limits and how the multipliers are computed.
    pub opts: ContOptions,
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Continuer<'_> {
    /// `F(y)` and the section level used.
    pub fn residual(&self, y: &[f64; 3]) -> Result<([f64; 2], f64), BifError> {
        let c = self.sh.section_level(y[0])?;
        let r = self.sh.section_map(y[0], c, [y[1], y[2]])?;
        Ok(([r.x[0] - y[1], r.x[1] - y[2]], c))
    }

    /// `F(y)` with the section level, `DF(y)` (2×3) from the variational equations, and the
    /// section map's derivatives (monodromy included).
    pub fn residual_jacobian(&self, y: &[f64; 3]) -> Result<Linearized, BifError> {
        let c = self.sh.section_level(y[0])?;
        let d = self.sh.section_derivatives(y[0], c, [y[1], y[2]])?;
        let f = [d.ret.x[0] - y[1], d.ret.x[1] - y[2]];
        let row = |i: usize| {
            [
                d.du[i],
                d.dz[(i, 0)] - if i == 0 { 1.0 } else { 0.0 },
                d.dz[(i, 1)] - if i == 1 { 1.0 } else { 0.0 },
            ]
        };
        Ok(Linearized {
            f,
            c,
            j: [row(0), row(1)],
            derivs: d,
        })
    }

    /// `DF(y)` (2×3) by forward differences (step `1e-7·max(1, |y_k|)`), a check on
    /// [`Continuer::residual_jacobian`].
    pub fn jacobian_fd(&self, y: &[f64; 3], f0: &[f64; 2]) -> Result<[[f64; 3]; 2], BifError> {
        let mut j = [[0.0; 3]; 2];
        for k in 0..3 {
            let d = 1e-7 * y[k].abs().max(1.0);
            let mut yk = *y;
            yk[k] += d;
            let (fk, _) = self.residual(&yk)?;
            for i in 0..2 {
                j[i][k] = (fk[i] - f0[i]) / d;
            }
        }
        Ok(j)
    }

    /// Unit tangent (null vector of `DF`), oriented along `along`.
    pub fn tangent(j: &[[f64; 3]; 2], along: &[f64; 3]) -> [f64; 3] {
        let t = cross(&j[0], &j[1]);
        let n = dot(&t, &t).sqrt();
        let s = if dot(&t, along) < 0.0 { -1.0 } else { 1.0 };
        [s * t[0] / n, s * t[1] / n, s * t[2] / n]
    }

    /// Predictor–corrector step from `y` along `t` by `h`; returns the corrected point and
    /// the Newton iteration count.
    pub fn correct(
        &self,
        y: &[f64; 3],
        t: &[f64; 3],
        h: f64,
    ) -> Result<([f64; 3], usize), BifError> {
        let yp = [y[0] + h * t[0], y[1] + h * t[1], y[2] + h * t[2]];
        let Linearized { f, j, .. } = self.residual_jacobian(&yp)?;
        let a = Matrix3::new(
            j[0][0], j[0][1], j[0][2], j[1][0], j[1][1], j[1][2], t[0], t[1], t[2],
        );
        let lu = a.lu();
        let mut yc = yp;
        let mut f = f;
        for it in 0..12 {
            let g = Vector3::new(
                -f[0],
                -f[1],
                -(t[0] * (yc[0] - yp[0]) + t[1] * (yc[1] - yp[1]) + t[2] * (yc[2] - yp[2])),
            );
            let d = lu.solve(&g).ok_or(BifError::NoConvergence {
                u: yc[0],
                detail: "singular corrector matrix".into(),
            })?;
            for k in 0..3 {
                yc[k] += d[k];
            }
            f = self.residual(&yc)?.0;
            if f[0].abs().max(f[1].abs()) <= self.opts.newton_tol && d.amax() <= 1e-6 {
                return Ok((yc, it + 1));
            }
        }
        Err(BifError::NoConvergence {
            u: yc[0],
            detail: "corrector: 12 iterations".into(),
        })
    }

    /// Builds the node at a converged `y`: tangent, metrics, multipliers.
    pub fn node(&self, y: [f64; 3], along: &[f64; 3], step: f64) -> Result<Node, BifError> {
        let Linearized {
            c, j, derivs: d, ..
        } = self.residual_jacobian(&y)?;
        let tangent = Self::tangent(&j, along);
        let info = match self.opts.multipliers {
            Multipliers::Saltation => self.describe_from(y[0], c, [y[1], y[2]], &d)?,
            Multipliers::FiniteDifference => self.describe_fd(y[0], c, [y[1], y[2]])?,
        };
        Ok(Node {
            y,
            c,
            tangent,
            step,
            info,
        })
    }

    /// Period, extrema of ω_l, stick time and Floquet multipliers (saltation monodromy) of
    /// the cycle through `[z0, z1, c]` on the section.
    pub fn describe(&self, u: f64, c: f64, z: [f64; 2]) -> Result<CycleInfo, BifError> {
        let d = self.sh.section_derivatives(u, c, z)?;
        self.describe_from(u, c, z, &d)
    }

    /// [`Continuer::describe`] from already computed section derivatives.
    pub(crate) fn describe_from(
        &self,
        u: f64,
        c: f64,
        z: [f64; 2],
        d: &SectionDerivs,
    ) -> Result<CycleInfo, BifError> {
        let (wl_max, wl_min, wu_min, stick_time) = self.metrics(u, c, z, d.ret.t)?;
        let nontrivial = eig2(&d.dz);
        let multipliers = order_multipliers(d.var.multipliers()).to_vec();
        Ok(CycleInfo {
            period: d.ret.t,
            omega_l_max: wl_max,
            omega_l_min: wl_min,
            omega_u_min: wu_min,
            stick_time,
            stick_slip: d.ret.stuck,
            multipliers,
            stable: nontrivial.iter().all(|l| l.norm() < 1.0),
            nontrivial,
        })
    }

    /// Extrema of ω_l, the minimum of ω_u and stick time per period of the cycle through `[z0, z1, c]`, whose
    /// period is about `period`.
    fn metrics(
        &self,
        u: f64,
        c: f64,
        z: [f64; 2],
        period: f64,
    ) -> Result<(f64, f64, f64, f64), BifError> {
        let x0 = State::new(z[0], z[1], c);
        // Metrics over two periods: the accumulator needs two anchors (stick exits or ω_l
        // maxima), and the first comes within one period.
        let scene = Scene {
            u,
            x0: x0.as_slice().to_vec(),
            t_end: 2.05 * period,
            output: Output::Final,
            metrics_from: Some(0.0),
            ..Scene::with_tol(self.sh.tol)
        };
        let traj = rotor_event::EventSolver::default()
            .simulate(self.sh.model, &scene)
            .map_err(BifError::Solve)?;
        let (wl_max, wl_min, wu_min, stick_time) = match traj.rig_metrics() {
            Some(RigSteady::LimitCycle {
                omega_l_max,
                omega_l_min,
                omega_u_min,
                stick_time,
                ..
            }) => (omega_l_max, omega_l_min, omega_u_min, stick_time),
            _ => (c, c, z[1], 0.0),
        };
        Ok((wl_max, wl_min, wu_min, stick_time))
    }

    /// [`Continuer::describe`] with the multipliers from central differences of the return
    /// maps (step `fd_step`): `[1, λ, 0]` from the stick-exit map for a stick-slip cycle (its
    /// 0 and 1 are structural, not computed), `[1, λ1, λ2]` from the section map otherwise.
    pub(crate) fn describe_fd(&self, u: f64, c: f64, z: [f64; 2]) -> Result<CycleInfo, BifError> {
        let ret = self.sh.section_map(u, c, z)?;
        let (wl_max, wl_min, wu_min, stick_time) = self.metrics(u, c, z, ret.t)?;
        let x0 = State::new(z[0], z[1], c);
        let one = Complex::new(1.0, 0.0);
        let h = self.opts.fd_step;
        let nontrivial = if ret.stuck {
            let exit = self.sh.next_exit(u, x0)?;
            let lam = self.sh.stick_exit_multiplier(u, exit.x[1], h)?;
            [Complex::new(lam, 0.0), Complex::new(0.0, 0.0)]
        } else {
            let j = self.sh.section_jacobian(u, c, z, h)?;
            let mut e = eig2(&j);
            if e[1].norm() > e[0].norm() {
                e.swap(0, 1);
            }
            e
        };
        Ok(CycleInfo {
            period: ret.t,
            omega_l_max: wl_max,
            omega_l_min: wl_min,
            omega_u_min: wu_min,
            stick_time,
            stick_slip: ret.stuck,
            multipliers: vec![one, nontrivial[0], nontrivial[1]],
            stable: nontrivial.iter().all(|l| l.norm() < 1.0),
            nontrivial,
        })
    }

    /// Follows the branch from `start` in the direction `dir` (its u-component sign) until it
    /// leaves `[u_min, u_max]`, shrinks below `amp_stop`, or cannot be continued.
    pub fn follow(&self, start: &Node, along: &[f64; 3]) -> (Vec<Node>, End) {
        let mut out = Vec::new();
        let mut cur = start.clone();
        if dot(&cur.tangent, along) < 0.0 {
            cur.tangent = cur.tangent.map(|v| -v);
        }
        let mut end = End::MaxNodes;
        let mut h = self.opts.h_max * 0.25;
        while out.len() < self.opts.max_nodes {
            let step = self.correct(&cur.y, &cur.tangent, h).and_then(|(y, its)| {
                let n = self.node(y, &cur.tangent, h)?;
                Ok((n, its))
            });
            match step {
                Ok((n, its)) => {
                    let turn = dot(&n.tangent, &cur.tangent);
                    if turn < 0.8 && h > 4.0 * self.opts.h_min {
                        h *= 0.5;
                        continue;
                    }
                    if n.y[0] < self.opts.u_min || n.y[0] > self.opts.u_max {
                        end = End::Range;
                        break;
                    }
                    if n.info.omega_l_max - n.info.omega_l_min < self.opts.amp_stop {
                        end = End::Small;
                        break;
                    }
                    if its <= 3 {
                        h = (h * 1.5).min(self.opts.h_max);
                    }
                    cur = n.clone();
                    out.push(n);
                }
                Err(_) => {
                    h *= 0.5;
                    if h < self.opts.h_min {
                        end = End::Stuck;
                        break;
                    }
                }
            }
        }
        (out, end)
    }

    /// The cycle of amplitude ≈ `eps` (in ω_l) near a Hopf point at `omega_h`: the Hopf
    /// eigenvector `v` (`J v = iβ v`, scaled so that `v_l = −i`) gives the upward crossing of
    /// the section at `z ≈ z*(u) + ε (Re v_α, Re v_ωu)`; Newton on `F(y) = 0` with the
    /// amplitude condition `d̂·(z − z*(u)) = ε|d|`, `d = (Re v_α, Re v_ωu)`, fixes the point.
    pub fn hopf_cycle(&self, omega_h: f64, eps: f64) -> Result<[f64; 3], BifError> {
        use nalgebra::Complex;
        let m = self.sh.model;
        let e = m.slip_equilibrium_at(omega_h);
        let pair = crate::bifurcation::equilibria::complex_pair(m, omega_h).ok_or(
            BifError::NoConvergence {
                u: e.u,
                detail: "no complex pair at the Hopf point".into(),
            },
        )?;
        let mode = rotor_model::Mode::rig(
            rotor_model::DiscMode::SlipPos,
            rotor_model::DiscMode::SlipPos,
        );
        let j = m.jacobian(&e.state(), e.u, mode);
        let lam = Complex::new(0.0, pair.im);
        let row = |i: usize| -> [Complex<f64>; 3] {
            [0, 1, 2].map(|k| {
                Complex::new(j[(i, k)], 0.0) - if i == k { lam } else { Complex::new(0.0, 0.0) }
            })
        };
        let cr = |a: [Complex<f64>; 3], b: [Complex<f64>; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let cands = [cr(row(0), row(1)), cr(row(0), row(2)), cr(row(1), row(2))];
        let nrm = |v: &[Complex<f64>; 3]| v.iter().map(|c| c.norm_sqr()).sum::<f64>();
        let v = cands
            .into_iter()
            .max_by(|a, b| nrm(a).total_cmp(&nrm(b)))
            .expect("three candidates");
        let scale = Complex::new(0.0, -1.0) / v[2];
        let v = v.map(|c| c * scale);
        let d = [v[0].re, v[1].re];
        let dn = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let dh = [d[0] / dn, d[1] / dn];
        let target = eps * dn;
        let g = |y: &[f64; 3]| -> Result<[f64; 3], BifError> {
            let (f, c) = self.residual(y)?;
            let ze = m.slip_equilibrium_at(c);
            Ok([
                f[0],
                f[1],
                dh[0] * (y[1] - ze.alpha) + dh[1] * (y[2] - ze.omega) - target,
            ])
        };
        let mut y = [e.u, e.alpha + eps * d[0], e.omega + eps * d[1]];
        for _ in 0..30 {
            let g0 = g(&y)?;
            if g0[0].abs().max(g0[1].abs()).max(g0[2].abs()) <= self.opts.newton_tol {
                return Ok(y);
            }
            let mut a = Matrix3::zeros();
            for k in 0..3 {
                let dk = 1e-7 * y[k].abs().max(1.0);
                let mut yk = y;
                yk[k] += dk;
                let gk = g(&yk)?;
                for i in 0..3 {
                    a[(i, k)] = (gk[i] - g0[i]) / dk;
                }
            }
            let dy = a.lu().solve(&Vector3::new(-g0[0], -g0[1], -g0[2])).ok_or(
                BifError::NoConvergence {
                    u: y[0],
                    detail: "singular Hopf-start Jacobian".into(),
                },
            )?;
            for k in 0..3 {
                y[k] += dy[k];
            }
        }
        Err(BifError::NoConvergence {
            u: y[0],
            detail: "Hopf start: 30 Newton iterations".into(),
        })
    }

    /// Bisection on the step length from `a` (toward its successor `b`, reached with step
    /// `b.step`) for a sign change of `g`, to a bracket of `1e-12·max(1, b.step)` in arclength;
    /// returns the node at the located point (of the two bracketing nodes, the one with the
    /// smaller |g|).
    pub fn bisect_between(
        &self,
        a: &Node,
        b: &Node,
        g: impl Fn(&Node) -> f64,
        max_iter: usize,
    ) -> Result<Node, BifError> {
        let ga = g(a);
        let mut lo = 0.0;
        let mut hi = b.step;
        let mut lo_node = a.clone();
        let mut hi_node: Option<(f64, Node)> = None;
        for _ in 0..max_iter {
            let m = 0.5 * (lo + hi);
            // A failed corrector means the curve does not reach this far along a's tangent
            // (it turned back at a non-smooth point): treat it as past the sign change.
            match self
                .correct(&a.y, &a.tangent, m)
                .and_then(|(y, _)| self.node(y, &a.tangent, m))
            {
                Ok(n) if g(&n) * ga > 0.0 => {
                    lo = m;
                    lo_node = n;
                }
                Ok(n) => {
                    hi = m;
                    hi_node = Some((m, n));
                }
                Err(_) => hi = m,
            }
            if hi - lo < 1e-12 * b.step.abs().max(1.0) {
                break;
            }
        }
        match hi_node {
            Some((m, n)) if m - lo < 1e-8 => {
                if lo > 0.0 && g(&lo_node).abs() < g(&n).abs() {
                    Ok(lo_node)
                } else {
                    Ok(n)
                }
            }
            _ if lo > 0.0 => Ok(lo_node),
            _ => Err(BifError::NoConvergence {
                u: a.y[0],
                detail: "bisection found no sign change".into(),
            }),
        }
    }
}
