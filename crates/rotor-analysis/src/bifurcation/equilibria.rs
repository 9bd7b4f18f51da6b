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

use nalgebra::{Complex, Matrix3, Vector3};
use rotor_model::{DiscMode, Mode, Model, SlipEquilibrium};

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
    /// The slipping equilibrium at the located ω: u \[V\], ω \[rad/s\], α \[rad\].
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
pub(crate) fn omega_grid(omega_max: f64, n: usize) -> Vec<f64> {
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

/// The first Lyapunov coefficient of the Hopf point of the slipping equilibrium at velocity
/// `omega` (Kuznetsov, *Elements of Applied Bifurcation Theory*, eq. (3.20)):
///
/// ```text
/// l1 = Re[⟨p, C(q,q,q̄)⟩ − 2⟨p, B(q, A⁻¹B(q,q̄))⟩ + ⟨p, B(q̄, (2iβ − A)⁻¹B(q,q))⟩] / (2β),
/// ```
///
/// with `Aq = iβq`, `Aᵀp = −iβp`, `⟨p, q⟩ = p̄ᵀq = 1`. In the slip field only the friction
/// torques are nonlinear, each in its own disc's velocity, so B and C are diagonal:
/// `B(x, y)_i = f_i'' x_i y_i`, `C(x, y, z)_i = f_i''' x_i y_i z_i` for the two velocity rows,
/// with `f_i'' = −T_fi''(ω)/J_i` (central differences of the branch torque, steps 1e-3 and
/// 2e-3 of 1 + |ω|: the torque is analytic on the branch). `None` if there is no complex pair.
pub fn first_lyapunov(model: &Model, omega: f64) -> Option<f64> {
    let e = model.slip_equilibrium_at(omega);
    let mode = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
    let a = model.jacobian(&e.state(), e.u, mode);
    let beta = complex_pair(model, omega)?.im;
    let c = |v: f64| Complex::new(v, 0.0);
    let ac: Matrix3<Complex<f64>> = a.map(c);
    let ib = Complex::new(0.0, beta);
    let null = |m: Matrix3<Complex<f64>>| -> Vector3<Complex<f64>> {
        let r = |i: usize| Vector3::new(m[(i, 0)], m[(i, 1)], m[(i, 2)]);
        [r(0).cross(&r(1)), r(0).cross(&r(2)), r(1).cross(&r(2))]
            .into_iter()
            .max_by(|x, y| x.norm().total_cmp(&y.norm()))
            .expect("three candidates")
    };
    let id = Matrix3::<Complex<f64>>::identity();
    let q = null(ac - id * ib);
    let q = q / c(q.norm());
    let p = null(ac.transpose() + id * ib);
    let dot = |x: &Vector3<Complex<f64>>, y: &Vector3<Complex<f64>>| {
        x.iter()
            .zip(y.iter())
            .map(|(a, b)| a.conj() * b)
            .sum::<Complex<f64>>()
    };
    let pq = dot(&p, &q);
    let p = p / pq.conj();
    // Second and third derivatives of the two velocity rows of f = rhs(x) in ω_u, ω_l.
    let d = |disc: rotor_model::Disc, j: f64| {
        let fr = model.friction(disc);
        let w = e.omega;
        let t = |x: f64| fr.torque(x, 1.0);
        let h2 = 1e-3 * (1.0 + w.abs());
        let second = (t(w + h2) - 2.0 * t(w) + t(w - h2)) / (h2 * h2);
        let h3 = 2e-3 * (1.0 + w.abs());
        let third = (t(w + 2.0 * h3) - 2.0 * t(w + h3) + 2.0 * t(w - h3) - t(w - 2.0 * h3))
            / (2.0 * h3 * h3 * h3);
        (-second / j, -third / j)
    };
    let (bu, cu) = d(rotor_model::Disc::UPPER, model.params.j_u);
    let (bl, cl) = d(rotor_model::Disc::LOWER, model.params.j_l);
    let b = |x: &Vector3<Complex<f64>>, y: &Vector3<Complex<f64>>| {
        Vector3::new(c(0.0), x[1] * y[1] * bu, x[2] * y[2] * bl)
    };
    let cc = |x: &Vector3<Complex<f64>>, y: &Vector3<Complex<f64>>, z: &Vector3<Complex<f64>>| {
        Vector3::new(c(0.0), x[1] * y[1] * z[1] * cu, x[2] * y[2] * z[2] * cl)
    };
    let qb = q.map(|z| z.conj());
    let inv_a = ac.try_inverse()?;
    let inv_2 = (id * (ib * c(2.0)) - ac).try_inverse()?;
    let term = dot(&p, &cc(&q, &q, &qb)) - dot(&p, &b(&q, &(inv_a * b(&q, &qb)))) * c(2.0)
        + dot(&p, &b(&qb, &(inv_2 * b(&q, &q))));
    Some(term.re / (2.0 * beta))
}
