//! The equilibrium branch over u and its Hopf points.
//!
//! Every slipping equilibrium has `ω_u = ω_l = ω`, and the branch is explicit in ω
//! (`rotor_model::equilibrium`):
//!
//! ```text
//! u(ω) = (T_fl(ω) + T_fu(ω)) / k_m,      α(ω) = T_fl(ω) / k_θ.
//! ```
//!
//! Its stability is that of the Jacobian `J(ω) = ∂f/∂x` of the slip–slip field at
//! `[α(ω), ω, ω]`. A Hopf point is a zero of `Re λ(ω)` of the complex pair of `J(ω)`; it is
//! located by bisection in ω (to the last representable bracket), and the crossing
//! frequency is `|Im λ|` there.

use nalgebra::Complex;
use rotor_model::{Model, SlipEquilibrium};

/// Real and imaginary part of the complex-conjugate pair of `J(ω)`, if the pair is complex.
pub fn complex_pair(model: &Model, omega: f64) -> Option<Complex<f64>> {
    let e = model.slip_equilibrium_at(omega);
    model
        .equilibrium_eigenvalues(&e)
        .into_iter()
        .filter(|l| l.im > 0.0)
        .max_by(|a, b| a.im.total_cmp(&b.im))
}

/// A located Hopf point of the slipping branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HopfPoint {
    pub equilibrium: SlipEquilibrium,
    /// Crossing frequency `|Im λ|` \[rad/s\]; the cycles born here have period ≈ 2π/frequency.
    pub frequency: f64,
    /// `Re λ` at the located point (the residual).
    pub re: f64,
    /// Whether the equilibrium gains stability as u increases through the point.
    pub stabilizing: bool,
}

/// The ω at which the slipping branch reaches `u_target` (u(ω) increasing past it), by
/// doubling then bisection; `None` if the branch never reaches it for ω ≤ 1e4.
pub fn omega_reaching(model: &Model, u_target: f64) -> Option<f64> {
    let mut hi = 1.0;
    while model.slip_equilibrium_at(hi).u < u_target {
        hi *= 2.0;
        if hi > 1e4 {
            return None;
        }
    }
    Some(hi)
}

/// Sample points of ω > 0 covering the branch up to `omega_max`, dense near 0 (where the
/// friction varies fastest).
pub fn omega_grid(omega_max: f64, n: usize) -> Vec<f64> {
    (1..=n)
        .map(|i| {
            let t = i as f64 / n as f64;
            omega_max * t * t
        })
        .collect()
}

/// All Hopf points of the slipping branch with `0 < ω ≤ omega_max`.
pub fn hopf_points(model: &Model, omega_max: f64) -> Vec<HopfPoint> {
    let ws = omega_grid(omega_max, 4000);
    let g = |w: f64| complex_pair(model, w).map(|l| l.re);
    let mut out = Vec::new();
    for pair in ws.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (Some(ga), Some(gb)) = (g(a), g(b)) else {
            continue;
        };
        if ga == 0.0 || ga * gb >= 0.0 {
            continue;
        }
        // Bisection in ω to the last representable bracket.
        let (mut lo, mut hi, mut glo) = (a, b, ga);
        loop {
            let m = 0.5 * (lo + hi);
            if m <= lo || m >= hi {
                break;
            }
            let Some(gm) = g(m) else { break };
            if gm == 0.0 {
                lo = m;
                hi = m;
                break;
            }
            if gm * glo < 0.0 {
                hi = m;
            } else {
                lo = m;
                glo = gm;
            }
        }
        let w = if g(lo).unwrap_or(f64::INFINITY).abs() <= g(hi).unwrap_or(f64::INFINITY).abs() {
            lo
        } else {
            hi
        };
        let l = complex_pair(model, w).expect("complex pair at a bracketed root");
        // Stability is gained with increasing u if Re λ goes from + to − along increasing u.
        let du = model.du_domega(w);
        let stabilizing = (gb - ga) * du < 0.0;
        out.push(HopfPoint {
            equilibrium: model.slip_equilibrium_at(w),
            frequency: l.im,
            re: l.re,
            stabilizing,
        });
    }
    out
}
