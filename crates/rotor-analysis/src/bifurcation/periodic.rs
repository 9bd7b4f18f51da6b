//! Periodic orbits by shooting, and their Floquet multipliers.
//!
//! Two return maps, both evaluated with `rotor_event::flow` (the exact Filippov flow):
//!
//! * **Poincaré section** `Σ_c = {ω_l = c, ω̇_l > 0}`: the 2-D map
//!   `P_c(α, ω_u) = (α, ω_u)` at the next upward crossing. It serves slipping and stick-slip
//!   cycles alike, so the continuation uses it, with `c = c(u)` the equilibrium velocity
//!   `ω*(u)` (always inside the cycle's range of ω_l).
//! * **Stick exit** of the lower disc: there `ω_l = 0` and `k_θ α = T_sl` (the upper end of
//!   the stick interval) exactly, so the map is 1-D in ω_u: `w ↦ P(w)`, ω_u at the next exit.
//!
//! Floquet multipliers come from the monodromy matrix of the variational equations with a
//! saltation matrix at every switching event ([`crate::bifurcation::monodromy`]; the continuation's
//! default). For a stick-slip cycle the 3-D monodromy has one multiplier exactly 0 (the
//! stick phase collapses α and ω_l onto the exit point) and one exactly 1 (time shift); the
//! third is `λ = P'(w*)`. For a slipping cycle the multipliers are `1` and the two
//! eigenvalues of `DP_c(z*)`. Central differences of the return maps (`(P(w*+h) −
//! P(w*−h)) / 2h`) remain as an independent check
//! ([`crate::bifurcation::continuation::Multipliers::FiniteDifference`]).

use nalgebra::{Complex, Matrix2, Matrix3, Vector2, Vector3};
use rotor_event::{FlowEnd, StopAt, flow};
use rotor_model::seam::SolveError;
use rotor_model::{Disc, DiscMode, Mode, Model, OMEGA_L, State};

use crate::bifurcation::BifError;
use crate::bifurcation::monodromy::{self, Variational};

/// The section map at one point with its derivatives
/// ([`Shooter::section_derivatives`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SectionDerivs {
    /// The return itself: `P_c(z)`, the return time, whether the lower disc stuck.
    pub ret: Return,
    /// Variational data over the return time (the monodromy matrix at a fixed point).
    pub var: Variational,
    /// `∂P/∂z` (2×2): at a fixed point its eigenvalues are the nontrivial Floquet multipliers.
    pub dz: Matrix2<f64>,
    /// `∂P/∂u`, the section level moving with u included.
    pub du: Vector2<f64>,
}

/// Longest time a return may take \[s\] (periods here are a few seconds to a few tens).
pub(crate) const T_RETURN: f64 = 2000.0;

/// The shooting setup at one input u.
#[derive(Debug, Clone, Copy)]
pub struct Shooter<'a> {
    /// The rotor: parameters and friction laws.
    pub model: &'a Model,
    /// Integration tolerance of the flow.
    pub tol: f64,
}

/// One return to a section or stick exit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Return {
    /// State at the return.
    pub x: State,
    /// Return time \[s\].
    pub t: f64,
    /// Whether the lower disc stuck on the way.
    pub stuck: bool,
}

fn err(e: SolveError) -> BifError {
    BifError::Solve(e)
}

impl Shooter<'_> {
    /// The section velocity `c(u) = ω*(u)`: the velocity of the slipping equilibrium nearest
    /// rest.
    pub fn section_level(&self, u: f64) -> Result<f64, BifError> {
        self.model
            .slip_equilibrium_nearest_rest(u)
            .map(|e| e.omega)
            .filter(|w| *w > 0.0)
            .ok_or(BifError::NoEquilibrium { u })
    }

    /// `P_c(z)` at input `u`: the next upward crossing of `ω_l = c` from `[z0, z1, c]`.
    pub fn section_map(&self, u: f64, c: f64, z: [f64; 2]) -> Result<Return, BifError> {
        Ok(self.section_flow(u, c, z)?.0)
    }

    /// The flow from `[z0, z1, c]` to the next upward crossing of `ω_l = c`, with its start
    /// mode and its events.
    fn section_flow(
        &self,
        u: f64,
        c: f64,
        z: [f64; 2],
    ) -> Result<(Return, Mode, FlowEnd), BifError> {
        let x = State::new(z[0], z[1], c);
        let mode = self.model.mode_at(&x, u);
        let end = flow(
            self.model,
            u,
            self.tol,
            x,
            mode,
            T_RETURN,
            StopAt::Section(c),
        )
        .map_err(err)?;
        if !end.reached {
            return Err(BifError::NoReturn { u });
        }
        let stuck = end
            .events
            .iter()
            .any(|e| e.kind == rotor_model::seam::EventKind::StickStart(Disc::LOWER));
        Ok((
            Return {
                x: end.x,
                t: end.t,
                stuck,
            },
            mode,
            end,
        ))
    }

    /// The section map with its derivatives from the variational equations and saltation
    /// matrices ([`crate::bifurcation::monodromy`]), for the section level `c = c(u) = ω*(u)`.
    ///
    /// With `x₀ = (z₀, z₁, c(u))`, `X = ∂x(T)/∂x₀` and `p = ∂x(T)/∂u` over the return time T,
    /// `f = f(x(T))` and the projection along the flow onto the section
    /// `Π = I − f e₃ᵀ / f₃` (the return time moves by `δT = (c′δu − e₃ᵀδx(T))/f₃`):
    ///
    /// ```text
    /// ∂P/∂z = [Π X E]₀..₁,     ∂P/∂u = [Π (X e₃ c′ + p) + f c′/f₃]₀..₁,
    /// ```
    ///
    /// with `E = [e₁ e₂]` and `c′ = 1/(du/dω)` on the equilibrium branch at ω = c.
    pub fn section_derivatives(
        &self,
        u: f64,
        c: f64,
        z: [f64; 2],
    ) -> Result<SectionDerivs, BifError> {
        let (ret, mode, end) = self.section_flow(u, c, z)?;
        let x0 = State::new(z[0], z[1], c);
        let var = monodromy::along(self.model, u, self.tol, x0, mode, &end.events, end.t)?;
        let f = self.model.rhs(&end.x, u, end.mode);
        if f[OMEGA_L] <= 0.0 {
            return Err(BifError::Grazing {
                u,
                state: [end.x[0], end.x[1], end.x[2]],
            });
        }
        let proj = Matrix3::identity() - f * Vector3::z().transpose() / f[OMEGA_L];
        let dc = 1.0 / self.model.du_domega(c);
        let x = &var.phi;
        let dz = proj * x;
        let du = proj * (x.column(2) * dc + var.p) + f * (dc / f[OMEGA_L]);
        Ok(SectionDerivs {
            ret,
            dz: Matrix2::new(dz[(0, 0)], dz[(0, 1)], dz[(1, 0)], dz[(1, 1)]),
            du: Vector2::new(du[0], du[1]),
            var,
        })
    }

    /// α at every exit of the lower disc from stick (upward): `k_θ α = T_sl`.
    pub fn exit_alpha(&self) -> f64 {
        self.model.friction(Disc::LOWER).static_interval().1 / self.model.params.k_theta
    }

    /// State and mode just after the lower disc leaves stick with upper velocity `w`.
    pub fn exit_state(&self, w: f64) -> (State, Mode) {
        let upper = if w == 0.0 {
            DiscMode::Stick
        } else {
            DiscMode::slip_of(w)
        };
        (
            State::new(self.exit_alpha(), w, 0.0),
            Mode::rig(upper, DiscMode::SlipPos),
        )
    }

    /// The stick-exit map `P(w)`: ω_u at the next exit of the lower disc from stick.
    pub fn stick_exit_map(&self, u: f64, w: f64) -> Result<Return, BifError> {
        let (x, mode) = self.exit_state(w);
        self.flow_to_exit(u, x, mode)
    }

    /// The next stick exit reached from a state on the section `ω_l = c`.
    pub fn next_exit(&self, u: f64, x: State) -> Result<Return, BifError> {
        self.flow_to_exit(u, x, self.model.mode_at(&x, u))
    }

    /// The flow from `(x, mode)` to the lower disc's next stick exit (where ω_l = 0).
    fn flow_to_exit(&self, u: f64, x: State, mode: Mode) -> Result<Return, BifError> {
        let end = flow(
            self.model,
            u,
            self.tol,
            x,
            mode,
            T_RETURN,
            StopAt::LowerStickExit,
        )
        .map_err(err)?;
        if !end.reached || end.x[OMEGA_L] != 0.0 {
            return Err(BifError::NoReturn { u });
        }
        Ok(Return {
            x: end.x,
            t: end.t,
            stuck: true,
        })
    }

    /// Fixed point of the stick-exit map by the secant method from `w0`.
    pub fn stick_exit_fixed_point(&self, u: f64, w0: f64, tol: f64) -> Result<f64, BifError> {
        let mut a = w0;
        let mut fa = self.stick_exit_map(u, a)?.x[1] - a;
        if fa.abs() <= tol {
            return Ok(a);
        }
        let mut b = a + fa;
        for _ in 0..40 {
            let fb = self.stick_exit_map(u, b)?.x[1] - b;
            if fb.abs() <= tol {
                return Ok(b);
            }
            let next = if fb != fa {
                b - fb * (b - a) / (fb - fa)
            } else {
                b + fb
            };
            a = b;
            fa = fb;
            b = next;
        }
        Err(BifError::NoConvergence {
            u,
            detail: format!("stick-exit secant: residual {fa:e}"),
        })
    }

    /// `λ = P'(w)` of the stick-exit map by a central difference with step `h`.
    pub fn stick_exit_multiplier(&self, u: f64, w: f64, h: f64) -> Result<f64, BifError> {
        let p = self.stick_exit_map(u, w + h)?.x[1];
        let m = self.stick_exit_map(u, w - h)?.x[1];
        Ok((p - m) / (2.0 * h))
    }

    /// `DP_c(z)` of the section map by central differences with step `h`.
    pub fn section_jacobian(
        &self,
        u: f64,
        c: f64,
        z: [f64; 2],
        h: f64,
    ) -> Result<Matrix2<f64>, BifError> {
        let mut j = Matrix2::zeros();
        for k in 0..2 {
            let mut zp = z;
            let mut zm = z;
            zp[k] += h;
            zm[k] -= h;
            let p = self.section_map(u, c, zp)?.x;
            let m = self.section_map(u, c, zm)?.x;
            for i in 0..2 {
                j[(i, k)] = (p[i] - m[i]) / (2.0 * h);
            }
        }
        Ok(j)
    }

    /// Fixed point of the section map at `u` (with `c = c(u)`, the section level) by Newton's
    /// method with the Jacobian `∂P/∂z − I` from the variational equations
    /// ([`Shooter::section_derivatives`]): exact for the mode sequence of the current
    /// iterate, so it stays on a cycle family right up to its grazing orbit.
    pub fn section_fixed_point_exact(
        &self,
        u: f64,
        c: f64,
        z0: [f64; 2],
        tol: f64,
    ) -> Result<[f64; 2], BifError> {
        let mut z = z0;
        for _ in 0..30 {
            let d = self.section_derivatives(u, c, z)?;
            let r = Vector2::new(d.ret.x[0] - z[0], d.ret.x[1] - z[1]);
            if r.amax() <= tol {
                return Ok(z);
            }
            let step =
                (d.dz - Matrix2::identity())
                    .lu()
                    .solve(&(-r))
                    .ok_or(BifError::NoConvergence {
                        u,
                        detail: "singular section Jacobian".into(),
                    })?;
            z = [z[0] + step[0], z[1] + step[1]];
        }
        Err(BifError::NoConvergence {
            u,
            detail: "section Newton (variational Jacobian): 30 iterations".into(),
        })
    }

    /// Fixed point of the section map at fixed u by Newton with a forward-difference Jacobian.
    pub fn section_fixed_point(
        &self,
        u: f64,
        c: f64,
        z0: [f64; 2],
        tol: f64,
    ) -> Result<[f64; 2], BifError> {
        let mut z = z0;
        for _ in 0..30 {
            let p = self.section_map(u, c, z)?.x;
            let r = [p[0] - z[0], p[1] - z[1]];
            if r[0].abs().max(r[1].abs()) <= tol {
                return Ok(z);
            }
            let mut j = Matrix2::zeros();
            for k in 0..2 {
                let mut zk = z;
                let dz = 1e-7 * z[k].abs().max(1.0);
                zk[k] += dz;
                let pk = self.section_map(u, c, zk)?.x;
                for i in 0..2 {
                    j[(i, k)] = (pk[i] - p[i]) / dz - if i == k { 1.0 } else { 0.0 };
                }
            }
            let d = j.lu().solve(&nalgebra::Vector2::new(-r[0], -r[1])).ok_or(
                BifError::NoConvergence {
                    u,
                    detail: "singular section Jacobian".into(),
                },
            )?;
            z = [z[0] + d[0], z[1] + d[1]];
        }
        Err(BifError::NoConvergence {
            u,
            detail: "section Newton: 30 iterations".into(),
        })
    }
}

/// Eigenvalues of a 2×2 matrix.
pub fn eig2(j: &Matrix2<f64>) -> [Complex<f64>; 2] {
    let tr = j[(0, 0)] + j[(1, 1)];
    let det = j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)];
    let disc = Complex::new(tr * tr / 4.0 - det, 0.0).sqrt();
    let h = Complex::new(tr / 2.0, 0.0);
    [h + disc, h - disc]
}
