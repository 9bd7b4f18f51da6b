//! Grazing orbits: the slipping cycle whose lowest lower-disc velocity is exactly 0.
//!
//! On a slipping cycle ω_l has its minimum where `ω̇_l = (k_θ α − T_fl(ω_l))/J_l = 0`. If that
//! minimum is `ω_l = 0`, then `k_θ α = T_fl(0⁺) = T_sl` there: the grazing orbit touches the
//! switching surface exactly at the lower disc's stick-exit point
//! `x_g(w) = (T_sl/k_θ, w, 0)`, whatever `w = ω_u` is. So the grazing orbit is the solution
//! `(u, w)` of two equations:
//!
//! ```text
//! G(u, w) = ( ω_l(t_m),  ω_u(t_m) − w ) = 0,
//! ```
//!
//! where `x(t)` is the *smooth* slip–slip flow (both discs on their positive slip branch, the
//! friction continued across ω_l = 0; `rotor_model::Friction::torque`) from `x_g(w)` and
//! `t_m > 0` is its next minimum of ω_l (the next upward zero of `ω̇_l` after a maximum).
//! `G₁ = ω_l(t_m)` is the cycle's minimum velocity (the grazing indicator), continued smoothly
//! through 0; `G₂` closes the orbit (with `ω̇_l(t_m) = 0` and `ω_l(t_m) = 0`, α(t_m) is the
//! start's α too). G is solved by Newton's method with a forward-difference Jacobian.
//!
//! A grazing orbit is where the stick phase of a stick-slip branch vanishes. What the branch
//! does there (passes through: persistence; turns back: a discontinuous fold, point E; or sheds
//! a period-two orbit) is decided by Feigin's rule on the multipliers of both sides
//! ([`classify`], [`crate::bifurcation::feigin`]).

use nalgebra::{Matrix2, Vector2};
use rotor_event::dop853::{Dense, Dop853};
use rotor_model::{Disc, DiscMode, Mode, Model, OMEGA_L, OMEGA_U, State};

use crate::bifurcation::BifError;
use crate::bifurcation::feigin::Feigin;

/// The located grazing orbit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrazingOrbit {
    /// Input \[V\].
    pub u: f64,
    /// ω_u at the touch point \[rad/s\].
    pub w: f64,
    /// Period \[s\] (time from the touch to the next minimum of ω_l).
    pub period: f64,
    /// Largest ω_l on the orbit \[rad/s\].
    pub omega_l_max: f64,
    /// `G(u, w)` at the located point: `[min ω_l, ω_u(t_m) − w]` \[rad/s\].
    pub residual: [f64; 2],
    /// Newton iterations taken.
    pub iterations: usize,
}

/// Most steps of one smooth run.
const MAX_STEPS: usize = 200_000;

/// The smooth slip–slip flow from `x_g(w)` to the next minimum of ω_l: `(x(t_m), t_m, max ω_l)`.
pub(crate) fn touch_to_min(
    model: &Model,
    u: f64,
    w: f64,
    tol: f64,
    t_max: f64,
) -> Result<(State, f64, f64), BifError> {
    let t_sl = model.friction(Disc::LOWER).static_interval().1;
    let x0 = State::new(t_sl / model.params.k_theta, w, 0.0);
    let mode = Mode::rig(DiscMode::slip_of(w), DiscMode::SlipPos);
    let s_u = mode.upper().branch().unwrap_or(1.0);
    let mut f = |_t: f64, x: &State| model.rhs(x, u, mode);
    let acc = |x: &State| model.rhs(x, u, mode)[OMEGA_L];
    let mut ctl = Dop853::new(tol, tol);
    let mut t = 0.0;
    let mut x = x0;
    let mut f0 = f(t, &x);
    let mut h = ctl.initial_step(&mut f, t, &x, &f0);
    ctl.restart();
    let mut past_max = false;
    let mut wl_max = f64::NAN;
    for _ in 0..MAX_STEPS {
        if t > t_max {
            break;
        }
        let tr = ctl.trial(&mut f, t, &x, &f0, h);
        if !Dop853::acceptable(&tr) {
            h = ctl.reject(tr.err, h);
            if h.is_nan() || h <= 1e-14 {
                break;
            }
            continue;
        }
        let h_new = ctl.accept(tr.err, h);
        let f1 = f(t + h, &tr.y1);
        let dense = ctl.dense(&mut f, &tr, &f1);
        // Sign changes of ω̇_l inside the step, on 8 sub-intervals of the dense output.
        let m = 8;
        let mut ta = t;
        let mut aa = acc(&x);
        for i in 1..=m {
            let tb = if i == m {
                t + h
            } else {
                t + h * i as f64 / m as f64
            };
            let xb = dense.eval(tb);
            let ab = acc(&xb);
            if !past_max && aa > 0.0 && ab <= 0.0 {
                past_max = true;
                let tx = root(&dense, &acc, ta, tb, aa, ab);
                wl_max = dense.eval(tx)[OMEGA_L];
            }
            if past_max && aa < 0.0 && ab >= 0.0 {
                let tm = root(&dense, &acc, ta, tb, aa, ab);
                let xm = dense.eval(tm);
                return Ok((xm, tm, wl_max));
            }
            if s_u * xb[OMEGA_U] <= 0.0 {
                return Err(BifError::NoConvergence {
                    u,
                    detail: "grazing orbit: the upper disc reaches zero velocity".into(),
                });
            }
            ta = tb;
            aa = ab;
        }
        t += h;
        x = tr.y1;
        f0 = f1;
        h = h_new;
    }
    Err(BifError::NoReturn { u })
}

/// The monodromy matrix `M = ∂x(T)/∂x(0)` of the grazing orbit at `(u, w)` as an orbit of the
/// smooth slip–slip flow, over one period `T` from its touch point `x_g(w)`: the variational
/// equations `Ẋ = J X`, `X(0) = I` ([`crate::bifurcation::monodromy::along`] with no event). Returns `(M, T)`.
pub fn touch_monodromy(
    model: &Model,
    u: f64,
    w: f64,
    tol: f64,
) -> Result<(nalgebra::Matrix3<f64>, f64), BifError> {
    let (_, period, _) = touch_to_min(model, u, w, tol, crate::bifurcation::periodic::T_RETURN)?;
    let t_sl = model.friction(Disc::LOWER).static_interval().1;
    let x0 = State::new(t_sl / model.params.k_theta, w, 0.0);
    let mode = Mode::rig(DiscMode::slip_of(w), DiscMode::SlipPos);
    let var = crate::bifurcation::monodromy::along(model, u, tol, x0, mode, &[], period)?;
    Ok((var.phi, period))
}

/// Feigin's classification ([`crate::bifurcation::feigin`]) of the grazing orbit at `(u, w)`: the slipping
/// cycle's nontrivial multipliers from [`touch_monodromy`] and the stick-slip cycle's as its
/// limit at the grazing orbit ([`crate::bifurcation::feigin::from_monodromy`]). The one classifier of the
/// u-diagram's grazing points and of the plane's grazing curves.
pub fn classify(model: &Model, u: f64, w: f64, tol: f64) -> Result<Feigin, BifError> {
    let (m, _) = touch_monodromy(model, u, w, tol)?;
    if m.iter().any(|v| !v.is_finite()) {
        return Err(BifError::NonFinite {
            what: format!("monodromy of the grazing orbit at u = {u}"),
            value: f64::NAN,
        });
    }
    Ok(crate::bifurcation::feigin::from_monodromy(&m, OMEGA_L))
}

/// Root of `ω̇_l` on `[a, b]` along the dense output (bisection then secant, to rounding).
fn root(
    d: &Dense<nalgebra::U3>,
    acc: &impl Fn(&State) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    for _ in 0..200 {
        let s = if fb != fa {
            b - fb * (b - a) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        // Keep the secant point well inside the bracket, else bisect.
        let lo = a + 0.01 * (b - a);
        let hi = b - 0.01 * (b - a);
        let c = if s > lo && s < hi { s } else { 0.5 * (a + b) };
        if c <= a || c >= b {
            break;
        }
        let fc = acc(&d.eval(c));
        if fc == 0.0 {
            return c;
        }
        if (fc < 0.0) == (fa < 0.0) {
            a = c;
            fa = fc;
        } else {
            b = c;
            fb = fc;
        }
    }
    if fa.abs() <= fb.abs() { a } else { b }
}

/// `G(u, w)` with the orbit's period and maximum of ω_l.
pub fn residual(model: &Model, u: f64, w: f64, tol: f64) -> Result<([f64; 2], f64, f64), BifError> {
    let (xm, tm, wmax) = touch_to_min(model, u, w, tol, crate::bifurcation::periodic::T_RETURN)?;
    Ok(([xm[OMEGA_L], xm[OMEGA_U] - w], tm, wmax))
}

/// Solves `G(u, w) = 0` by Newton's method from `(u0, w0)` (a nearby branch point: u and the
/// ω_u at its minimum of ω_l or at its stick exit), to `|G|∞ ≤ g_tol` or until the Newton
/// step stops decreasing.
pub fn locate(
    model: &Model,
    u0: f64,
    w0: f64,
    tol: f64,
    g_tol: f64,
) -> Result<GrazingOrbit, BifError> {
    let (mut u, mut w) = (u0, w0);
    let (mut g, mut period, mut wmax) = residual(model, u, w, tol)?;
    let mut last_step = f64::INFINITY;
    for it in 0..30 {
        let norm = g[0].abs().max(g[1].abs());
        if norm <= g_tol {
            return Ok(GrazingOrbit {
                u,
                w,
                period,
                omega_l_max: wmax,
                residual: g,
                iterations: it,
            });
        }
        // Forward differences: the flow is smooth (no events), so the error is the
        // integration noise over the step, tol/δ ≈ 1e-5 relative at δ = 1e-7: enough for Newton.
        let du = 1e-7 * u.abs().max(1.0);
        let dw = 1e-7 * w.abs().max(1.0);
        let (gu, _, _) = residual(model, u + du, w, tol)?;
        let (gw, _, _) = residual(model, u, w + dw, tol)?;
        let j = Matrix2::new(
            (gu[0] - g[0]) / du,
            (gw[0] - g[0]) / dw,
            (gu[1] - g[1]) / du,
            (gw[1] - g[1]) / dw,
        );
        let d = j
            .lu()
            .solve(&Vector2::new(-g[0], -g[1]))
            .ok_or(BifError::NoConvergence {
                u,
                detail: "grazing Newton: singular Jacobian".into(),
            })?;
        let step = d[0].abs().max(d[1].abs());
        // Converged to the noise floor: the step no longer shrinks and is at rounding level.
        if step >= last_step && step < 1e-12 {
            return Ok(GrazingOrbit {
                u,
                w,
                period,
                omega_l_max: wmax,
                residual: g,
                iterations: it,
            });
        }
        last_step = step;
        u += d[0];
        w += d[1];
        (g, period, wmax) = residual(model, u, w, tol)?;
    }
    Err(BifError::NoConvergence {
        u,
        detail: format!(
            "grazing Newton: 30 iterations, |G| = {:e}",
            g[0].abs().max(g[1].abs())
        ),
    })
}
