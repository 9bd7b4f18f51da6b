//! One classifier of grazing(-sliding) bifurcations, by Feigin's rule.
//!
//! Near a grazing orbit the Poincaré map of the rotor is, to lowest order, a *continuous*
//! piecewise-linear map (the grazing-sliding normal form, di Bernardo, Kowalczyk & Nordmark,
//! Physica D 170 (2002); di Bernardo, Budd, Champneys & Kowalczyk, *Piecewise-smooth Dynamical
//! Systems*, Springer 2008, ch. 8): `z ↦ A z + μ` on the side where the cycle slips
//! (`e₁ᵀz < 0`, say) and `z ↦ B z + μ` on the side where it sticks, with `μ ∝ u − u_g`.
//! Continuity across the border makes `B − A = w e₁ᵀ` of rank one. Feigin's classification of
//! such a border collision (Feigin 1970; di Bernardo, Feigin, Hogan & Homer, Chaos Solitons
//! Fractals 10 (1999); the book's ch. 3) follows from two determinants:
//!
//! * **Fixed points.** `z_A = (I − A)⁻¹μ` and `z_B = (I − B)⁻¹μ` have the same first component up
//!   to the factor `det(I − A)/det(I − B)` (the adjugate's first row is the same for A and B, since
//!   they differ only in the first column). Each is a cycle only on its own side, so exactly one
//!   of them exists for each sign of μ — **persistence** — when `det(I − A)·det(I − B) > 0`, and
//!   both on one side, none on the other — a **non-smooth (discontinuous) fold** — when it is
//!   negative. Since `det(I − A) = Π(1 − λ)`, whose sign is `(−1)^σ⁺` with σ⁺ the number of real
//!   multipliers above +1 (a complex pair contributes `|1 − λ|² > 0`), this is
//!   `σ⁺_A + σ⁺_B` even (persistence) or odd (fold).
//! * **Period-two orbits.** A 2-cycle `z₁ → z₂ → z₁` with one point on each side has, from
//!   `(I + A)(z₁ − z₂) = w e₁ᵀz₂` and `det(I + B) = det(I + A)(1 + e₁ᵀ(I + A)⁻¹w)`,
//!   `e₁ᵀz₁ = r·e₁ᵀz₂` with `r = det(I + B)/det(I + A)`: it exists (on one side of μ = 0) exactly
//!   when `r < 0`, i.e. `σ⁻_A + σ⁻_B` odd, σ⁻ counting the real multipliers below −1. This is the
//!   **period-doubling-type** grazing bifurcation; it occurs beside either of the first two.
//!
//! Only *real* multipliers count: a complex pair outside the unit circle changes neither
//! parity, and a multiplier below −1 changes σ⁻, not σ⁺. The modulus of the leading multiplier
//! (the classifier this replaces) mislabels both.
//!
//! The rotor's Poincaré maps are two-dimensional (the section `ω_l = ω*(u)` in (α, ω_u)), so each
//! side is given by the characteristic polynomial `λ² − s λ + p` of its Jacobian ([`Side`]):
//! the counts come from its real roots, computed from (s, p) in real arithmetic, with no
//! threshold on an imaginary part.

use nalgebra::{Complex, Matrix3};
use serde::Serialize;

/// The nontrivial multipliers of one side: the roots of `λ² − trace·λ + det`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Side {
    /// `s = λ₁ + λ₂`, the trace of the side's 2×2 Jacobian.
    pub trace: f64,
    /// `p = λ₁ λ₂`, its determinant (0 on the stick-slip side).
    pub det: f64,
}

impl Side {
    /// The side whose multipliers are `a` and `b` (real, or a conjugate pair `a = b̄`).
    pub fn from_multipliers(a: Complex<f64>, b: Complex<f64>) -> Side {
        Side {
            trace: (a + b).re,
            det: (a * b).re,
        }
    }

    /// The two roots, larger modulus first (as the diagram orders multipliers); a complex pair
    /// as `(re, +im), (re, −im)`.
    pub fn multipliers(&self) -> [Complex<f64>; 2] {
        let (s, p) = (self.trace, self.det);
        let disc = s * s - 4.0 * p;
        if disc < 0.0 {
            let im = (-disc).sqrt() / 2.0;
            [Complex::new(s / 2.0, im), Complex::new(s / 2.0, -im)]
        } else {
            // λ² − sλ + p: the root of larger modulus q = (s + sgn(s)√disc)/2 without
            // cancellation, the other p/q from the product.
            let sg = if s >= 0.0 { 1.0 } else { -1.0 };
            let q = 0.5 * (s + sg * disc.sqrt());
            let (r1, r2) = if q != 0.0 { (q, p / q) } else { (0.0, 0.0) };
            [Complex::new(r1, 0.0), Complex::new(r2, 0.0)]
        }
    }

    fn real_roots(&self) -> Vec<f64> {
        let m = self.multipliers();
        if m[0].im != 0.0 {
            Vec::new()
        } else {
            vec![m[0].re, m[1].re]
        }
    }

    /// σ⁺: the number of real multipliers greater than +1.
    pub fn sigma_plus(&self) -> usize {
        self.real_roots().into_iter().filter(|&r| r > 1.0).count()
    }

    /// σ⁻: the number of real multipliers less than −1.
    pub fn sigma_minus(&self) -> usize {
        self.real_roots().into_iter().filter(|&r| r < -1.0).count()
    }

    /// `det(I − A) = 1 − s + p`: its sign is `(−1)^σ⁺`.
    pub(crate) fn det_i_minus(&self) -> f64 {
        1.0 - self.trace + self.det
    }

    /// `det(I + A) = 1 + s + p`: its sign is `(−1)^σ⁻`.
    pub fn det_i_plus(&self) -> f64 {
        1.0 + self.trace + self.det
    }

    /// Both multipliers inside the unit circle.
    pub fn stable(&self) -> bool {
        self.multipliers().iter().all(|z| z.norm() < 1.0)
    }
}

/// What happens to the cycle at a grazing orbit (Feigin's rule on the parity of σ⁺).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GrazingType {
    /// σ⁺ even: one cycle on each side; it passes through grazing (its stability may change).
    Persistence,
    /// σ⁺ odd: both cycles lie on one side and meet at the grazing orbit (point E).
    NonsmoothFold,
}

impl GrazingType {
    /// The JSON and CSV name (`"nonsmooth_fold"`).
    pub fn as_str(self) -> &'static str {
        match self {
            GrazingType::Persistence => "persistence",
            GrazingType::NonsmoothFold => "nonsmooth_fold",
        }
    }
}

/// Feigin's classification at one grazing orbit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Feigin {
    /// Persistence (`σ⁺_A + σ⁺_B` even) or non-smooth fold (odd).
    pub kind: GrazingType,
    /// σ⁻ odd: a period-two orbit is born at the grazing orbit as well.
    pub period_doubling: bool,
    /// σ⁺ of the slipping cycle and of the stick-slip cycle.
    pub sigma_plus: [usize; 2],
    /// σ⁻ of the slipping cycle and of the stick-slip cycle.
    pub sigma_minus: [usize; 2],
    /// The slipping cycle's nontrivial multipliers.
    pub slipping: Side,
    /// The stick-slip cycle's nontrivial multipliers (one is 0: the stick phase).
    pub stick_slip: Side,
}

impl Feigin {
    /// A continuous function whose sign is the type: `det(I − A)·det(I − B)`, negative for a
    /// non-smooth fold (where it changes sign, a multiplier of one side crosses +1).
    pub fn fold_indicator(&self) -> f64 {
        self.slipping.det_i_minus() * self.stick_slip.det_i_minus()
    }

    /// `det(I + A)·det(I + B)`, negative where a period-two orbit is born.
    pub fn flip_indicator(&self) -> f64 {
        self.slipping.det_i_plus() * self.stick_slip.det_i_plus()
    }

    /// The words of the type (`persistence`, `nonsmooth fold`, with `and period doubling`).
    pub fn describe(&self) -> String {
        let base = match self.kind {
            GrazingType::Persistence => "persistence",
            GrazingType::NonsmoothFold => "nonsmooth fold",
        };
        if self.period_doubling {
            format!("{base} with period doubling")
        } else {
            base.to_owned()
        }
    }
}

/// Feigin's rule from the two sides' nontrivial multipliers (see the module docs).
pub fn classify(slipping: Side, stick_slip: Side) -> Feigin {
    let sigma_plus = [slipping.sigma_plus(), stick_slip.sigma_plus()];
    let sigma_minus = [slipping.sigma_minus(), stick_slip.sigma_minus()];
    Feigin {
        kind: if (sigma_plus[0] + sigma_plus[1]).is_multiple_of(2) {
            GrazingType::Persistence
        } else {
            GrazingType::NonsmoothFold
        },
        period_doubling: (sigma_minus[0] + sigma_minus[1]) % 2 == 1,
        sigma_plus,
        sigma_minus,
        slipping,
        stick_slip,
    }
}

/// Both sides from the grazing orbit's monodromy matrix `M` (3×3, one period of the slipping
/// flow from the touch point `x_g`, where `ω̇_l = 0`), and Feigin's rule on them.
///
/// * Slipping side: `M` has the trivial multiplier 1 (eigenvector `f(x_g)`), so its nontrivial
///   ones are the roots of `λ² − (tr M − 1)λ + det M`.
/// * Stick-slip side: as u → u_g the stick phase shrinks to the touch point; its saltation
///   at the onset is `P = I − e_l e_lᵀ` whatever the approach speed, the one at the exit is `I`,
///   and the flow over the vanishing stick phase tends to `I`, so the monodromy tends to `P M`.
///   `e_lᵀ f(x_g) = ω̇_l = 0` keeps 1 an eigenvalue, `det P M = 0` gives the multiplier 0, and
///   the third is `tr(P M) − 1 = tr M − M_ll − 1`.
///
/// `lower` is the index of ω_l in the state.
pub fn from_monodromy(m: &Matrix3<f64>, lower: usize) -> Feigin {
    let tr = m.trace();
    let slipping = Side {
        trace: tr - 1.0,
        det: m.determinant(),
    };
    let stick_slip = Side {
        trace: tr - m[(lower, lower)] - 1.0,
        det: 0.0,
    };
    classify(slipping, stick_slip)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    fn side(m: &Matrix2<f64>) -> Side {
        Side {
            trace: m.trace(),
            det: m.determinant(),
        }
    }

    /// The roots reproduce the polynomial they come from (real and complex cases) to rounding.
    #[test]
    fn roots_solve_their_polynomial() {
        for (s, p) in [(2.5, 1.0), (-2.5, 1.0), (0.3, 0.9), (1.0, 0.0), (0.0, -4.0)] {
            let r = Side { trace: s, det: p }.multipliers();
            // Vieta: sum and product to a few ulps of the inputs' scale.
            assert!(
                ((r[0] + r[1]).re - s).abs() < 1e-14 * (1.0 + s.abs()),
                "{s} {p}"
            );
            assert!(
                ((r[0] * r[1]).re - p).abs() < 1e-14 * (1.0 + p.abs()),
                "{s} {p}"
            );
        }
        let r = Side {
            trace: 2.5,
            det: 1.0,
        }
        .multipliers();
        assert_eq!([r[0].re, r[1].re], [2.0, 0.5]);
    }

    /// A complex pair outside the unit circle: the modulus rule would call it a fold; Feigin's
    /// rule counts no real multiplier above 1 on either side: persistence.
    #[test]
    fn a_complex_pair_outside_the_circle_is_persistence() {
        let a = Side::from_multipliers(Complex::new(0.3, 1.2), Complex::new(0.3, -1.2));
        assert!(a.multipliers()[0].norm() > 1.0);
        let b = Side {
            trace: 0.4,
            det: 0.0,
        };
        let f = classify(a, b);
        assert_eq!(f.sigma_plus, [0, 0]);
        assert_eq!(f.kind, GrazingType::Persistence);
        assert!(!f.period_doubling);
        assert!(f.fold_indicator() > 0.0 && f.flip_indicator() > 0.0);
    }

    /// A multiplier below −1 on the slipping side: no fold (σ⁺ = 0), but σ⁻ is odd: a
    /// period-doubling-type grazing. The modulus rule would call it a fold.
    #[test]
    fn a_minus_one_crossing_is_period_doubling_not_a_fold() {
        let a = Side::from_multipliers(Complex::new(-1.3, 0.0), Complex::new(0.2, 0.0));
        let b = Side {
            trace: -0.6,
            det: 0.0,
        };
        let f = classify(a, b);
        assert_eq!((f.sigma_plus, f.sigma_minus), ([0, 0], [1, 0]));
        assert_eq!(f.kind, GrazingType::Persistence);
        assert!(f.period_doubling);
        assert_eq!(f.describe(), "persistence with period doubling");
        // Both sides below −1: σ⁻ even, no 2-cycle.
        let b2 = Side {
            trace: -1.5,
            det: 0.0,
        };
        assert!(!classify(a, b2).period_doubling);
    }

    /// One real multiplier above 1 on one side only: a non-smooth fold; on both: persistence.
    #[test]
    fn one_multiplier_above_one_is_a_fold_two_are_not() {
        let a = Side::from_multipliers(Complex::new(1.7, 0.0), Complex::new(0.1, 0.0));
        let b = Side {
            trace: 0.5,
            det: 0.0,
        };
        assert_eq!(classify(a, b).kind, GrazingType::NonsmoothFold);
        let b2 = Side {
            trace: 1.2,
            det: 0.0,
        };
        assert_eq!(classify(a, b2).kind, GrazingType::Persistence);
        assert_eq!(classify(a, b2).sigma_plus, [1, 1]);
    }

    /// The slipping and limiting stick-slip sides from a 3×3 monodromy with a trivial
    /// multiplier 1 whose eigenvector has no ω_l component: built as `V diag(1, λ1, λ2) V⁻¹`.
    #[test]
    fn sides_from_a_monodromy_matrix() {
        let v = Matrix3::new(1.0, 0.3, -0.2, 0.5, 1.0, 0.4, 0.0, 0.7, 1.0);
        let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.6, 0.25));
        let m = v * d * v.try_inverse().unwrap();
        let f = from_monodromy(&m, 2);
        let r = f.slipping.multipliers();
        assert!(
            (r[0].re - 1.6).abs() < 1e-12 && (r[1].re - 0.25).abs() < 1e-12,
            "{r:?}"
        );
        // P M with P = I − e₃e₃ᵀ: its eigenvalues, computed directly, are {1, 0, λ_B}.
        let mut p = Matrix3::identity();
        p[(2, 2)] = 0.0;
        let ev = (p * m).complex_eigenvalues();
        let lb = f.stick_slip.multipliers()[0].re;
        let mut got: Vec<f64> = ev.iter().map(|z| z.re).collect();
        got.sort_by(f64::total_cmp);
        let mut want = vec![0.0, 1.0, lb];
        want.sort_by(f64::total_cmp);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }

    /// Constructed monodromy matrices (trivial multiplier 1 with an eigenvector free of ω_l):
    /// a complex pair of modulus 1.25 is persistence, not a fold; a slipping multiplier −1.4 with
    /// a stick-slip limit inside (−1, 1) is a period-doubling-type grazing. The modulus rule
    /// (`max |λ| > 1` ⇒ fold) called both folds.
    #[test]
    fn constructed_monodromies_with_a_complex_pair_and_a_minus_one_crossing() {
        let v = Matrix3::new(1.0, 0.2, 0.1, 0.4, 1.0, -0.3, 0.0, 0.5, 1.0);
        let vi = v.try_inverse().unwrap();
        // Complex pair r e^{±iθ}: a rotation block scaled by r = 1.25.
        let (r, th) = (1.25f64, 1.1f64);
        let mut d = Matrix3::zeros();
        d[(0, 0)] = 1.0;
        d[(1, 1)] = r * th.cos();
        d[(1, 2)] = -r * th.sin();
        d[(2, 1)] = r * th.sin();
        d[(2, 2)] = r * th.cos();
        let f = from_monodromy(&(v * d * vi), 2);
        let z = f.slipping.multipliers();
        assert!((z[0].norm() - r).abs() < 1e-12 && z[0].im != 0.0, "{z:?}");
        assert!(
            f.stick_slip.multipliers()[0].norm() < 1.0,
            "{:?}",
            f.stick_slip
        );
        assert_eq!((f.kind, f.sigma_plus), (GrazingType::Persistence, [0, 0]));
        assert!(!f.period_doubling);
        // A −1 crossing: diag(1, −1.2, 0.5); the stick-slip limit is then −0.935 (inside).
        let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, -1.2, 0.5));
        let f = from_monodromy(&(v * d * vi), 2);
        let lb = f.stick_slip.multipliers();
        assert!(lb[1].re == 0.0 && lb[0].re.abs() < 1.0, "{lb:?}");
        assert_eq!(f.sigma_minus, [1, 0]);
        assert_eq!(f.kind, GrazingType::Persistence);
        assert!(f.period_doubling && f.flip_indicator() < 0.0);
    }

    /// Feigin's rule checked against the piecewise-linear map itself: for random A, a rank-one
    /// B = A + w e₁ᵀ and μ = ±b, the admissible fixed points (first component < 0 for A, > 0 for
    /// B) and 2-cycles (one point on each side) are solved for directly, on both sides of μ = 0.
    /// Persistence ⇔ exactly one fixed point for each sign; fold ⇔ two for one sign, none for the
    /// other; period doubling ⇔ a 2-cycle for one sign of μ.
    #[test]
    fn the_rule_agrees_with_the_piecewise_linear_map() {
        // A small deterministic generator (xorshift) in [-2.5, 2.5].
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 5.0 - 2.5
        };
        let mut seen = [0usize; 4];
        for _ in 0..2000 {
            let a = Matrix2::new(rnd(), rnd(), rnd(), rnd());
            let w = Vector2::new(rnd(), rnd());
            let b = a + w * Vector2::new(1.0, 0.0).transpose();
            let base = Vector2::new(rnd(), rnd());
            let (sa, sb) = (side(&a), side(&b));
            // Skip near-degenerate draws (a multiplier within 1e-3 of ±1, or a fixed point on
            // the border), where the rule's parity is not decided by the draw's rounding.
            let dets = [
                sa.det_i_minus(),
                sb.det_i_minus(),
                sa.det_i_plus(),
                sb.det_i_plus(),
            ];
            if dets.iter().any(|d| d.abs() < 1e-3) {
                continue;
            }
            let f = classify(sa, sb);
            let id = Matrix2::identity();
            let fixed = |mu: Vector2<f64>| {
                let za = (id - a).lu().solve(&mu).unwrap();
                let zb = (id - b).lu().solve(&mu).unwrap();
                (za[0] < 0.0) as usize + (zb[0] > 0.0) as usize
            };
            // 2-cycle z1 (A side) → z2 = A z1 + μ (B side) → B z2 + μ = z1: a 4×4 linear system.
            let two_cycle = |mu: Vector2<f64>| {
                let mut m = nalgebra::Matrix4::<f64>::zeros();
                let mut r = nalgebra::Vector4::<f64>::zeros();
                // z2 − A z1 = μ
                for i in 0..2 {
                    for j in 0..2 {
                        m[(i, j)] = -a[(i, j)];
                        m[(2 + i, 2 + j)] = -b[(i, j)];
                    }
                    m[(i, 2 + i)] = 1.0;
                    m[(2 + i, i)] = 1.0;
                    r[i] = mu[i];
                    r[2 + i] = mu[i];
                }
                m.lu().solve(&r).is_some_and(|z| z[0] < 0.0 && z[2] > 0.0)
            };
            let (np, nm) = (fixed(base), fixed(-base));
            match f.kind {
                GrazingType::Persistence => assert!(np == 1 && nm == 1, "{a} {b} {np} {nm}"),
                GrazingType::NonsmoothFold => {
                    assert!(
                        (np, nm) == (2, 0) || (np, nm) == (0, 2),
                        "{a} {b} {np} {nm}"
                    )
                }
            }
            let pd = two_cycle(base) || two_cycle(-base);
            assert_eq!(pd, f.period_doubling, "{a} {b}");
            seen[(f.kind == GrazingType::NonsmoothFold) as usize * 2
                + f.period_doubling as usize] += 1;
        }
        // Every combination was drawn often enough to mean something.
        assert!(seen.iter().all(|&n| n >= 50), "{seen:?}");
    }
}
