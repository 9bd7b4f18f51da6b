//! Equilibria of eqs. (1).
//!
//! Every equilibrium has `ω_u = ω_l = ω` (from α̇ = 0). For ω ≠ 0 both discs slip and
//!
//! ```text
//! k_θ α = T_fl(ω),     k_m u = T_fl(ω) + T_fu(ω)
//! ```
//!
//! so the slipping branch is explicit in ω: `u(ω) = (T_fl(ω) + T_fu(ω))/k_m`, `α(ω) = T_fl(ω)/k_θ`.
//! For ω = 0 (both discs stuck) the equilibria form the set of α with
//! `k_θ α ∈ I_l` and `k_m u − k_θ α ∈ I_u` (the stick intervals), possibly a segment.

use nalgebra::Complex;
use serde::Serialize;

use crate::dynamics::{DiscMode, Mode, Model, State};

/// A slipping equilibrium (both discs at the same velocity ω ≠ 0).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlipEquilibrium {
    /// u \[V\]: the input voltage at which this is an equilibrium,
    /// `u = (T_fl(ω) + T_fu(ω))/k_m`.
    pub u: f64,
    /// ω [rad/s]: the common velocity of both discs, ω_u = ω_l = ω ≠ 0.
    pub omega: f64,
    /// α \[rad\]: the spring's twist, `α = T_fl(ω)/k_θ`.
    pub alpha: f64,
}

impl SlipEquilibrium {
    /// As a state `[α, ω, ω]`.
    pub fn state(&self) -> State {
        State::new(self.alpha, self.omega, self.omega)
    }
}

/// The set of stuck equilibria `α ∈ [alpha_min, alpha_max]`, `ω_u = ω_l = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StuckSet {
    /// Smallest stuck twist \[rad\]: `max(T_l⁻/k_θ, (k_m u − T_u⁺)/k_θ)`, with `[T⁻, T⁺]` a
    /// disc's stick interval.
    pub alpha_min: f64,
    /// Largest stuck twist \[rad\]: `min(T_l⁺/k_θ, (k_m u − T_u⁻)/k_θ)`.
    pub alpha_max: f64,
}

impl Model {
    /// The slipping branch at velocity ω ≠ 0: `u(ω)`, `α(ω)`.
    pub fn slip_equilibrium_at(&self, omega: f64) -> SlipEquilibrium {
        let s = if omega < 0.0 { -1.0 } else { 1.0 };
        let tl = self.friction(crate::Disc::LOWER).torque(omega, s);
        let tu = self.friction(crate::Disc::UPPER).torque(omega, s);
        SlipEquilibrium {
            u: (tl + tu) / self.params.k_m,
            omega,
            alpha: tl / self.params.k_theta,
        }
    }

    /// `du/dω` along the slipping branch.
    pub fn du_domega(&self, omega: f64) -> f64 {
        let s = if omega < 0.0 { -1.0 } else { 1.0 };
        (self.friction(crate::Disc::LOWER).dtorque(omega, s)
            + self.friction(crate::Disc::UPPER).dtorque(omega, s))
            / self.params.k_m
    }

    /// All slipping equilibria at input u, ordered by ω. The branch `u(ω)` can fold
    /// (falling friction), so several may exist; each is refined to machine precision.
    pub fn slip_equilibria(&self, u: f64) -> Vec<SlipEquilibrium> {
        let mut out = self.scan_slip_equilibria(u, false);
        out.sort_by(|a, b| a.omega.total_cmp(&b.omega));
        out
    }

    /// The slipping equilibrium nearest rest at input u (smallest |ω|), if any: the first
    /// of [`Model::slip_equilibria`]'s scan, found without the rest of it (the sections of
    /// the continuation and the perturbed starts ask for this one only, thousands of times).
    pub fn slip_equilibrium_nearest_rest(&self, u: f64) -> Option<SlipEquilibrium> {
        self.scan_slip_equilibria(u, true).pop()
    }

    /// The roots of `u(sω) = u` (s = sign u) in scan order, |ω| increasing, on a grid in
    /// |ω| dense near 0 (where the friction varies fastest) out to where the viscous growth
    /// dominates every bounded friction term; each bracket bisected to adjacent doubles.
    /// With `first`, the scan stops at the first root.
    fn scan_slip_equilibria(&self, u: f64, first: bool) -> Vec<SlipEquilibrium> {
        if u == 0.0 {
            return Vec::new();
        }
        let s = u.signum();
        let bt = self.friction(crate::Disc::LOWER).viscous()
            + self.friction(crate::Disc::UPPER).viscous();
        let bound = self.params.upper.t_s.abs()
            + self.params.upper.dt_s.abs()
            + self.friction(crate::Disc::LOWER).level(0.0).abs()
            + match self.params.lower {
                crate::LowerFriction::Exponential { t_1, t_2, .. } => t_1.abs() + t_2.abs(),
                crate::LowerFriction::Stribeck { t_c, .. } => t_c.abs(),
            };
        let w_max = if bt > 0.0 {
            2.0 * (self.params.k_m * u).abs().max(bound) / bt + 1.0
        } else {
            1e4
        };
        let g = |w: f64| self.slip_equilibrium_at(s * w).u - u;
        let n = 4000;
        let mut ws: Vec<f64> = (0..=n)
            .map(|i| {
                let t = i as f64 / n as f64;
                1e-12 + w_max * t * t
            })
            .collect();
        ws.dedup();
        let mut out = Vec::new();
        let mut prev = (ws[0], g(ws[0]));
        for &w in &ws[1..] {
            let gw = g(w);
            if prev.1 == 0.0 {
                out.push(self.slip_equilibrium_at(s * prev.0));
            } else if prev.1 * gw < 0.0 {
                let root = bisect(&g, prev.0, w, prev.1, gw);
                out.push(self.slip_equilibrium_at(s * root));
            }
            if first && !out.is_empty() {
                break;
            }
            prev = (w, gw);
        }
        out
    }

    /// Eigenvalues of the Jacobian at a slipping equilibrium.
    pub fn equilibrium_eigenvalues(&self, e: &SlipEquilibrium) -> [Complex<f64>; 3] {
        let m = DiscMode::slip_of(e.omega);
        let j = self.jacobian(&e.state(), e.u, Mode::rig(m, m));
        let ev = j.complex_eigenvalues();
        [ev[0], ev[1], ev[2]]
    }

    /// Whether a slipping equilibrium is asymptotically stable (all eigenvalues in the open
    /// left half-plane).
    pub fn equilibrium_is_stable(&self, e: &SlipEquilibrium) -> bool {
        self.equilibrium_eigenvalues(e).iter().all(|l| l.re < 0.0)
    }

    /// The start "perturbed equilibrium" at input `u` (the sweeps, the region probes and the
    /// plane's regions): the slipping equilibrium nearest rest with ω_l raised by 1e-3 rad/s,
    /// or the middle of the stuck set (or rest) with it.
    pub fn perturbed_equilibrium(&self, u: f64) -> State {
        let base = self
            .slip_equilibrium_nearest_rest(u)
            .map(|e| e.state())
            .or_else(|| {
                self.stuck_equilibria(u)
                    .map(|s| State::new(0.5 * (s.alpha_min + s.alpha_max), 0.0, 0.0))
            })
            .unwrap_or_else(State::zeros);
        base + State::new(0.0, 0.0, 1e-3)
    }

    /// The set of equilibria with both discs at rest, if non-empty.
    pub fn stuck_equilibria(&self, u: f64) -> Option<StuckSet> {
        let k = self.params.k_theta;
        let (ll, lh) = self.friction(crate::Disc::LOWER).static_interval();
        let (ul, uh) = self.friction(crate::Disc::UPPER).static_interval();
        let km_u = self.params.k_m * u;
        let lo = (ll / k).max((km_u - uh) / k);
        let hi = (lh / k).min((km_u - ul) / k);
        (lo <= hi).then_some(StuckSet {
            alpha_min: lo,
            alpha_max: hi,
        })
    }
}

/// Bisection to the last representable bracket (robust; the function is cheap).
fn bisect(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64, mut ga: f64, _gb: f64) -> f64 {
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let gm = g(m);
        if gm == 0.0 {
            return m;
        }
        if ga * gm < 0.0 {
            b = m;
        } else {
            a = m;
            ga = gm;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The equilibrium nearest rest is the one of smallest |ω| among all of them, bit for
    /// bit (the same scan, stopped at its first root), on both parameter sets, for either
    /// sign of u, and where the branch folds and several coexist; none where none exists.
    #[test]
    fn nearest_rest_is_the_smallest_of_all() {
        let stribeck = crate::Params::from_file(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../fixtures/params/stribeck.toml"),
        )
        .unwrap();
        // Table 1 with a nearly frictionless upper disc: the lower law's falling part then
        // makes u(ω) fold, with several equilibria over a band of u.
        let folded = crate::Params::table1().with("upper.b", 1e-3).unwrap();
        let mut several = 0;
        for p in [crate::Params::table1(), stribeck, folded] {
            let m = Model::new(p);
            for i in -700..=700 {
                let u = i as f64 * 0.01;
                let all = m.slip_equilibria(u);
                several += usize::from(all.len() > 1);
                let smallest = all
                    .iter()
                    .copied()
                    .min_by(|a, b| a.omega.abs().total_cmp(&b.omega.abs()));
                assert_eq!(m.slip_equilibrium_nearest_rest(u), smallest, "u = {u}");
            }
        }
        assert!(several > 0, "no input with several equilibria was tried");
    }

    #[test]
    fn slip_equilibria_are_fixed_points() {
        let m = Model::table1();
        for u in [0.3, 1.5, 2.5, 4.5, 6.0, -1.5] {
            let eqs = m.slip_equilibria(u);
            assert!(!eqs.is_empty(), "u = {u}");
            for e in eqs {
                // u(ω) at the bisected ω: measured ≤ 8.9e-16 (1 ulp of 6); 1e-13 ≈ 110×.
                assert_relative_eq!(e.u, u, epsilon = 1e-13);
                let mode = m.mode_at(&e.state(), u);
                let f = m.rhs(&e.state(), u, mode);
                // Residual of the equilibrium equations at a bisected root: rounding level,
                // measured ≤ 7.5e-15; 1e-12 ≈ 130×.
                assert!(f.norm() < 1e-12, "u = {u}: |f| = {}", f.norm());
            }
        }
    }

    #[test]
    fn table1_is_unstable_at_2_5_and_stable_at_6() {
        // docs/model.md: with Table 1 the 2.5 V equilibrium is unstable (a cycle surrounds it),
        // 6 V lies above the subcritical Hopf point (stable).
        let m = Model::table1();
        let e = m.slip_equilibria(2.5);
        assert_eq!(e.len(), 1);
        assert!(!m.equilibrium_is_stable(&e[0]));
        let e = m.slip_equilibria(6.0);
        assert_eq!(e.len(), 1);
        assert!(m.equilibrium_is_stable(&e[0]));
    }

    #[test]
    fn stuck_sets() {
        let m = Model::table1();
        // Upper disc smooth: a single α = k_m u / k_θ while k_m u ≤ T_sl.
        let s = m.stuck_equilibria(0.02).unwrap();
        // α ≈ 1.1 from a couple of roundings either way (≤ 2 ulp = 4.4e-16); measured 0.
        assert_relative_eq!(s.alpha_min, 3.995 * 0.02 / 0.0727, epsilon = 1e-14);
        assert_relative_eq!(s.alpha_min, s.alpha_max, epsilon = 1e-14);
        assert!(m.stuck_equilibria(0.05).is_none()); // k_m u = 0.2 > T_sl = 0.1642
    }

    #[test]
    fn u_branch_derivative_matches_fd() {
        let m = Model::table1();
        for w in [0.1, 1.0, 5.0] {
            let fd = (m.slip_equilibrium_at(w + 1e-6).u - m.slip_equilibrium_at(w - 1e-6).u) / 2e-6;
            // Central differences: O(d²) truncation + ε|u|/d rounding (≲ 1e-9 at d = 1e-6);
            // measured ≤ 9.8e-11 (at ω = 5); 1e-8 = 100×.
            assert_relative_eq!(m.du_domega(w), fd, epsilon = 1e-8);
        }
    }
}
