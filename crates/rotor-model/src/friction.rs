//! Set-valued friction laws, split as
//!
//! ```text
//! T_f(ω) ∈ a(ω) + b·ω + N(|ω|)·Sign(ω)
//! ```
//!
//! with a smooth offset `a` (the upper disc's asymmetry ΔT_su + Δb_u|ω|), a viscous
//! coefficient `b`, and an even friction *level* `N ≥ 0` at ω = 0 (the normal force of the
//! Lagrangian form's Coulomb contact). `Sign(0) = [−1, 1]`.
//!
//! A solver that tracks a slip branch `s ∈ {+1, −1}` evaluates the branch torque
//! `T_f^s(ω) = a^s(ω) + b ω + s·N(sω)`, a smooth continuation of the law from the side `sω > 0`
//! across ω = 0, so that event location can evaluate the field slightly past the surface.

use crate::params::{LowerFriction, UpperFriction};

/// Friction law of one disc: the upper disc's law (eq. (4)) or one of the lower disc's two
/// families.
///
/// The coefficients sit in one flat record with every field set (the ones a family does not
/// use are 0), not in an enum of the families. An enum value holds only its own variant's
/// bytes; the rest is uninitialised, and the compiler may evaluate a branch it then discards on
/// those bytes. Measured: Moreau–Jean's step took 45 % longer in one binary than in another,
/// because the tail of the upper disc's enum held the bit pattern of a subnormal float, and
/// each discarded multiplication by it cost a microcode assist.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    family: Family,
    /// Static level: `T_su` (upper), `T_sl` (lower).
    t_s: f64,
    /// Viscous coefficient `b`.
    b: f64,
    /// Upper disc: `ΔT_su`, `Δb_u`.
    dt_s: f64,
    db: f64,
    /// Exponential family: `T_1, T_2, w_1, w_2`.
    t_1: f64,
    t_2: f64,
    w_1: f64,
    w_2: f64,
    /// Stribeck family: `T_cl, ω_sl, δ_sl`.
    t_c: f64,
    omega_s: f64,
    delta: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Family {
    Upper,
    Exponential,
    Stribeck,
}

impl Friction {
    const ZERO: Friction = Friction {
        family: Family::Upper,
        t_s: 0.0,
        b: 0.0,
        dt_s: 0.0,
        db: 0.0,
        t_1: 0.0,
        t_2: 0.0,
        w_1: 0.0,
        w_2: 0.0,
        t_c: 0.0,
        omega_s: 0.0,
        delta: 0.0,
    };

    /// The upper disc's law (eq. (4)): `T_f = ΔT_su + Δb_u|ω| + b_u ω + T_su·Sign(ω)`.
    pub fn upper(p: UpperFriction) -> Friction {
        Friction {
            family: Family::Upper,
            t_s: p.t_s,
            b: p.b,
            dt_s: p.dt_s,
            db: p.db,
            ..Friction::ZERO
        }
    }

    /// The lower disc's law: the exponential or the Stribeck level, plus `b_l ω`.
    pub fn lower(l: LowerFriction) -> Friction {
        match l {
            LowerFriction::Exponential {
                t_s,
                t_1,
                t_2,
                w_1,
                w_2,
                b,
            } => Friction {
                family: Family::Exponential,
                t_s,
                b,
                t_1,
                t_2,
                w_1,
                w_2,
                ..Friction::ZERO
            },
            LowerFriction::Stribeck {
                t_s,
                t_c,
                omega_s,
                delta,
                b,
            } => Friction {
                family: Family::Stribeck,
                t_s,
                b,
                t_c,
                omega_s,
                delta,
                ..Friction::ZERO
            },
        }
    }

    /// The upper disc's parameters, if this is the upper disc's law.
    pub fn as_upper(&self) -> Option<UpperFriction> {
        (self.family == Family::Upper).then_some(UpperFriction {
            t_s: self.t_s,
            dt_s: self.dt_s,
            b: self.b,
            db: self.db,
        })
    }

    /// The lower disc's parameters, if this is a lower disc's law.
    pub fn as_lower(&self) -> Option<LowerFriction> {
        match self.family {
            Family::Upper => None,
            Family::Exponential => Some(LowerFriction::Exponential {
                t_s: self.t_s,
                t_1: self.t_1,
                t_2: self.t_2,
                w_1: self.w_1,
                w_2: self.w_2,
                b: self.b,
            }),
            Family::Stribeck => Some(LowerFriction::Stribeck {
                t_s: self.t_s,
                t_c: self.t_c,
                omega_s: self.omega_s,
                delta: self.delta,
                b: self.b,
            }),
        }
    }
}

/// `tanh y = sign(y)·(1 − 2/(e^{2|y|} + 1))`: one `exp` instead of libm's `expm1`-based
/// `tanh` (the friction law is the solvers' hot spot). Absolute error ≤ 2 ulp of 1, which is
/// all the level `T_s + T_1 tanh(..) + ..` needs (its relative error near y = 0 is not used).
#[inline]
fn tanh_fast(y: f64) -> f64 {
    let e = (2.0 * y.abs()).exp();
    // 2·(1/(e + 1)) rounds exactly as 2/(e + 1) (scaling by 2 commutes with rounding):
    // the same bits as tanh_sech2's tanh, from one division there.
    (1.0 - 2.0 * (1.0 / (e + 1.0))).copysign(y)
}

/// `(tanh y, sech² y)` from one `exp`: with `e = e^{2|y|}`, `tanh y` as in [`tanh_fast`] and
/// `sech² y = 4/(e^y + e^{−y})² = 4e/(e + 1)²` (0 once `e` overflows, where sech² < 1e-300).
#[inline]
fn tanh_sech2(y: f64) -> (f64, f64) {
    let e = (2.0 * y.abs()).exp();
    let inv = 1.0 / (e + 1.0);
    // e·inv < 1 first: 4e alone overflows for e > 4.5e307 while e is still finite.
    let sech2 = if e.is_finite() {
        4.0 * (e * inv) * inv
    } else {
        0.0
    };
    ((1.0 - 2.0 * inv).copysign(y), sech2)
}

impl Friction {
    /// Viscous coefficient `b` (the C matrix entry of the Lagrangian form).
    pub fn viscous(&self) -> f64 {
        self.b
    }

    /// Friction level `N(|ω|)` (even in ω); `N(0)` is the half-width of the stick interval.
    ///
    /// Exponential family: `T_sl + T_1 tanh(w_1|ω|/2) + T_2 tanh(w_2|ω|/2)`
    /// (since `1 − 2/(1+e^x) = tanh(x/2)`); Stribeck: `T_cl + (T_sl − T_cl) e^{−|ω/ω_s|^δ}`;
    /// upper disc: `T_su`.
    ///
    /// Note: with Table 1, N turns negative above |ω| ≈ 18 rad/s (T_sl + T_1 + T_2 < 0);
    /// the viscous term keeps the total torque dissipative.
    pub fn level(&self, w: f64) -> f64 {
        self.level_ext(w.abs())
    }

    /// The level as a function of `x = s·ω` continued to `x < 0`: analytic for the exponential
    /// family (tanh is odd), even (|x|^δ) for the Stribeck family, constant for the upper disc.
    /// Equals `N(|ω|)` for `x ≥ 0`.
    pub fn level_ext(&self, x: f64) -> f64 {
        let Friction {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            t_c,
            omega_s,
            delta,
            ..
        } = *self;
        match self.family {
            Family::Upper => t_s,
            Family::Exponential => {
                t_s + t_1 * tanh_fast(0.5 * w_1 * x) + t_2 * tanh_fast(0.5 * w_2 * x)
            }
            Family::Stribeck => t_c + (t_s - t_c) * (-(x.abs() / omega_s).powf(delta)).exp(),
        }
    }

    /// `d level_ext / dx`.
    pub(crate) fn dlevel_ext(&self, x: f64) -> f64 {
        self.level_ext_with_slope(x).1
    }

    /// `(level_ext(x), d level_ext/dx)` together, sharing the exponentials: one `exp` per
    /// tanh term of the exponential family, whose slope is `(w/2)·T·sech²(wx/2)` with
    /// `sech² y = 4e/(e + 1)²`, `e = e^{2|y|}` (the `e` of `tanh_fast`); one `exp` and one
    /// `powf` for the Stribeck family. The level equals [`Friction::level_ext`] bit for bit.
    #[inline]
    pub fn level_ext_with_slope(&self, x: f64) -> (f64, f64) {
        let Friction {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            t_c,
            omega_s,
            delta,
            ..
        } = *self;
        match self.family {
            Family::Upper => (t_s, 0.0),
            Family::Exponential => {
                let (th1, sech1) = tanh_sech2(0.5 * w_1 * x);
                let (th2, sech2) = tanh_sech2(0.5 * w_2 * x);
                (
                    t_s + t_1 * th1 + t_2 * th2,
                    0.5 * t_1 * w_1 * sech1 + 0.5 * t_2 * w_2 * sech2,
                )
            }
            Family::Stribeck => {
                let a = x.abs();
                let r = (a / omega_s).powf(delta);
                let decay = (-r).exp();
                let level = t_c + (t_s - t_c) * decay;
                if a == 0.0 {
                    // d/da e^{-(a/ω_s)^δ} at 0: 0 for δ > 1, −1/ω_s for δ = 1, −∞ for δ < 1.
                    let slope = if delta > 1.0 {
                        0.0
                    } else if delta == 1.0 {
                        -(t_s - t_c) / omega_s
                    } else {
                        f64::NEG_INFINITY * (t_s - t_c).signum()
                    };
                    return (level, slope);
                }
                if decay == 0.0 {
                    // r overflowed (or e^{−r} underflowed): the slope is 0, not 0·∞.
                    return (level, 0.0);
                }
                (level, -(t_s - t_c) * decay * delta * r / a * x.signum())
            }
        }
    }

    /// Smooth offset `a^s(ω)` on branch s: `ΔT_su + s·Δb_u·ω` for the upper disc, 0 for the lower.
    pub fn offset(&self, w: f64, s: f64) -> f64 {
        match self.family {
            Family::Upper => self.dt_s + s * self.db * w,
            _ => 0.0,
        }
    }

    /// Branch torque `T_f^s(ω) = a^s(ω) + b ω + s·N(sω)` (see the module docs).
    #[inline]
    pub fn torque(&self, w: f64, s: f64) -> f64 {
        self.offset(w, s) + self.viscous() * w + s * self.level_ext(s * w)
    }

    /// `dT_f^s/dω`.
    #[inline]
    pub(crate) fn dtorque(&self, w: f64, s: f64) -> f64 {
        let da = match self.family {
            Family::Upper => s * self.db,
            _ => 0.0,
        };
        // d/dω [s·N(sω)] = s·s·N'(sω) = N'(sω).
        da + self.viscous() + self.dlevel_ext(s * w)
    }

    /// The velocity scale of the law's level, in rad/s: the width over which the level
    /// changes by a fraction O(1) of its amplitude, or `None` for a law without one.
    ///
    /// * Exponential family: `min_i 2/w_i` over the terms with `T_i ≠ 0`
    ///   (`tanh(w_i|ω|/2)` goes from 0 to tanh 1 ≈ 0.76 over `|ω| = 2/w_i`);
    /// * Stribeck family: `ω_s/max(1, δ)` if `T_s ≠ T_c` (the fall `e^{−(|ω|/ω_s)^δ}` takes
    ///   place around `ω_s`, over a width that narrows as `1/δ` for `δ > 1`);
    /// * upper disc (eq. (4)): none; its law is linear in ω on each side of 0.
    pub fn velocity_scale(&self) -> Option<f64> {
        match self.family {
            Family::Upper => None,
            Family::Exponential => [(self.t_1, self.w_1), (self.t_2, self.w_2)]
                .into_iter()
                .filter(|&(t, w)| t != 0.0 && w > 0.0)
                .map(|(_, w)| 2.0 / w)
                .reduce(f64::min),
            Family::Stribeck => (self.t_s != self.t_c).then(|| self.omega_s / self.delta.max(1.0)),
        }
    }

    /// The edge of the law's steep region at tolerance `tol`: the speed `|ω|` beyond which the
    /// terms that set [`Friction::velocity_scale`] lie within `tol·T` of their limits
    /// (`T` = [`Friction::torque_scale`]), so that the law varies there only on its slower
    /// scales. `None` for a law without a velocity scale.
    ///
    /// * Exponential family, a term `T_i·tanh(w_i|ω|/2)` with `2/w_i = v`: its distance to
    ///   `T_i` is `2|T_i|/(1 + e^{w_i|ω|}) < 2|T_i|·e^{−w_i|ω|}`, which is `tol·T` at
    ///   `|ω| = ln(2|T_i|/(tol·T))/w_i`;
    /// * Stribeck family: `|T_s − T_c|·e^{−(|ω|/ω_s)^δ} = tol·T` at
    ///   `|ω| = ω_s·ln(|T_s − T_c|/(tol·T))^{1/δ}`.
    ///
    /// 0 where even the term's amplitude is below `tol·T`.
    pub fn steep_edge(&self, tol: f64) -> Option<f64> {
        let v = self.velocity_scale()?;
        let floor = tol * self.torque_scale();
        let edge = match self.family {
            Family::Upper => return None,
            Family::Exponential => [(self.t_1, self.w_1), (self.t_2, self.w_2)]
                .into_iter()
                .filter(|&(t, w)| t != 0.0 && w > 0.0 && 2.0 / w <= v)
                .map(|(t, w)| (2.0 * t.abs() / floor).ln().max(0.0) / w)
                .fold(0.0, f64::max),
            Family::Stribeck => {
                let r = ((self.t_s - self.t_c).abs() / floor).ln().max(0.0);
                self.omega_s * r.powf(1.0 / self.delta)
            }
        };
        Some(edge)
    }

    /// The torque scale of the law's level, in N m: its value at rest plus the amplitudes of
    /// its velocity-dependent terms, `T_s + |T_1| + |T_2|` (exponential), `T_s + |T_s − T_c|`
    /// (Stribeck), `|ΔT_s| + T_s` (upper disc). A spring torque balanced against the law at
    /// one velocity and the law at another differ by at most about this much, so `T/J` is the
    /// scale of the disc's acceleration while it slips across the law's velocity scale.
    pub fn torque_scale(&self) -> f64 {
        match self.family {
            Family::Upper => self.dt_s.abs() + self.t_s.abs(),
            Family::Exponential => self.t_s.abs() + self.t_1.abs() + self.t_2.abs(),
            Family::Stribeck => self.t_s.abs() + (self.t_s - self.t_c).abs(),
        }
    }

    /// The largest viscous coefficient on either side of ω = 0, `b + |Δb|` (N m s/rad).
    pub(crate) fn viscous_bound(&self) -> f64 {
        self.b.abs() + self.db.abs()
    }

    /// The stick interval `[T_f(0⁻), T_f(0⁺)] = a(0) + N(0)·[−1, 1]`.
    pub fn static_interval(&self) -> (f64, f64) {
        let a0 = self.offset(0.0, 1.0);
        let n0 = self.level(0.0);
        (a0 - n0, a0 + n0)
    }

    /// Whether the law has a set-valued part at ω = 0 (an interval of positive width).
    pub fn is_set_valued(&self) -> bool {
        self.level(0.0) > 0.0
    }

    /// The single-valued law for ω ≠ 0, `T_f(ω) = T_f^{sign ω}(ω)`; at ω = 0 the midpoint of
    /// the stick interval (for plotting).
    pub fn curve(&self, w: f64) -> f64 {
        if w > 0.0 {
            self.torque(w, 1.0)
        } else if w < 0.0 {
            self.torque(w, -1.0)
        } else {
            self.offset(0.0, 1.0)
        }
    }

    /// The magnitude `T_c(ω)` of eqs. (4)–(5): `T_f(ω) = T_c(ω)·sign(ω)`.
    pub fn magnitude(&self, w: f64) -> f64 {
        let s = if w < 0.0 { -1.0 } else { 1.0 };
        s * self.torque(w, s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use approx::assert_relative_eq;

    #[test]
    fn tanh_fast_matches_libm_to_a_few_ulp_absolute() {
        let mut y = -40.0;
        while y <= 40.0 {
            let d = (tanh_fast(y) - y.tanh()).abs();
            // tanh_fast's 2 ulp of 1 (its docs) plus libm's own error; measured ≤ 1 ε.
            assert!(d <= 4.0 * f64::EPSILON, "y = {y}: {d:e}");
            y += 0.0137;
        }
        assert_eq!(tanh_fast(0.0), 0.0);
        assert_eq!(tanh_fast(1e300), 1.0);
        assert_eq!(tanh_fast(-1e300), -1.0);
    }

    fn laws() -> Vec<Friction> {
        let t1 = Params::table1();
        let st = Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            std::path::Path::new("s"),
        )
        .unwrap();
        vec![
            Friction::upper(t1.upper),
            Friction::lower(t1.lower),
            Friction::upper(st.upper),
            Friction::lower(st.lower),
        ]
    }

    /// At the steep region's edge the fast term's distance to its limit is `tol·T`, measured
    /// on the law itself (the level with that term at its limit subtracted), and beyond the
    /// edge it is smaller; the upper disc has no edge.
    #[test]
    fn at_the_steep_edge_the_fast_term_is_within_the_tolerance_of_its_limit() {
        let [up, exp, _, strib] = laws()[..] else {
            unreachable!()
        };
        assert_eq!(up.steep_edge(1e-10), None);
        for tol in [1e-6, 1e-10, 1e-13] {
            let t = exp.torque_scale();
            // Table 1: the fast term is T_1 (w_1 = 5.7468), the slow one T_2 stays.
            let gap = |w: f64| {
                let slow = exp.t_s + exp.t_2 * (0.5 * exp.w_2 * w).tanh();
                (exp.level(w) - slow - exp.t_1).abs()
            };
            let e = exp.steep_edge(tol).unwrap();
            // 2|T_1|/(1 + e^{w ω}) against its bound 2|T_1|e^{−wω}: relative 1/e^{wω} ≤ 1e-5
            // here; the level's own rounding, 1e-16 N m, is below 1e-3 of tol·T at 1e-13.
            assert_relative_eq!(gap(e), tol * t, max_relative = 1e-3);
            assert!(gap(1.1 * e) < tol * t, "{tol}");
            let e = strib.steep_edge(tol).unwrap();
            let t = strib.torque_scale();
            let gap = (strib.level(e) - strib.t_c).abs();
            assert_relative_eq!(gap, tol * t, max_relative = 1e-3);
        }
    }

    #[test]
    fn exponential_matches_reconstructed_form() {
        // The tanh form against the 1 − 2/(1+e^x) form, evaluated literally. That form is not
        // in the source (which gives only eq. (5), the Stribeck law): it is a reconstruction
        // that Table 1's parameters T_1, T_2, w_1, w_2 require, after N. Mihajlović, PhD
        // thesis, TU Eindhoven 2005, and Mihajlović, van Veggel, van de Wouw, Nijmeijer,
        // "Analysis of friction-induced limit cycling in an experimental drill-string
        // system", J. Dyn. Sys. Meas. Control 126 (2004) 709–720.
        let LowerFriction::Exponential {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            b,
        } = Params::table1().lower
        else {
            unreachable!()
        };
        let f = Friction::lower(Params::table1().lower);
        for w in [0.0, 0.01, 0.3, 1.0, 4.0, 12.0, 30.0] {
            let src = t_s
                + t_1 * (1.0 - 2.0 / (1.0 + (w_1 * w).exp()))
                + t_2 * (1.0 - 2.0 / (1.0 + (w_2 * w).exp()))
                + b * w;
            // Both forms in double precision: agree to a few ulps of the O(0.2) value
            // (1e-15 ≈ 18 ulp of 0.2); measured 0: tanh_fast evaluates the same 1 − 2/(1+eˣ).
            assert_relative_eq!(f.magnitude(w), src, epsilon = 1e-15);
            assert_relative_eq!(f.magnitude(-w), src, epsilon = 1e-15);
        }
        assert_eq!(f.static_interval(), (-t_s, t_s));
    }

    #[test]
    fn upper_matches_eq4() {
        let p = UpperFriction {
            t_s: 0.37975,
            dt_s: -0.00575,
            b: 2.4245,
            db: -0.0084,
        };
        let f = Friction::upper(p);
        for w in [-3.0, -0.2, 0.2, 3.0_f64] {
            let tcu = p.t_s + p.dt_s * w.signum() + p.b * w.abs() + p.db * w;
            // The same four terms in another order: measured ≤ 8.9e-16 (1 ulp at |T| ≈ 7.7);
            // 1e-15, or ε relative (assert_relative_eq's default), admits that ulp only.
            assert_relative_eq!(f.curve(w), tcu * w.signum(), epsilon = 1e-15);
        }
        // T_cu(0+) = T_su + ΔT_su and −T_cu(0−) = −T_su + ΔT_su (source, below eq. 5).
        let (lo, hi) = f.static_interval();
        assert_relative_eq!(hi, p.t_s + p.dt_s);
        assert_relative_eq!(lo, -p.t_s + p.dt_s);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for f in laws() {
            for s in [1.0, -1.0] {
                for w in [0.05, 0.4, 1.3, 5.0, 17.0] {
                    let w = s * w;
                    let d = 1e-6;
                    let fd = (f.torque(w + d, s) - f.torque(w - d, s)) / (2.0 * d);
                    // Central difference: truncation O(d²·T''') ~ 1e-10, rounding ε|T|/d ≲ 1e-8
                    // (|T| ≲ 45 at ω = 17); measured ≤ 4.1e-9 absolute, 1.8e-9 relative (55×).
                    assert_relative_eq!(f.dtorque(w, s), fd, epsilon = 1e-8, max_relative = 1e-7);
                }
            }
        }
    }

    #[test]
    fn level_with_slope_matches_the_separate_forms() {
        for f in laws() {
            for x in [
                // 123.4 puts w_1·x/2 (Table 1, w_1 = 5.7468) where e^{w_1 x} is finite but
                // 4·e^{w_1 x} is not.
                -1e300, -40.0, -3.0, -0.2, 0.0, 1e-9, 0.2, 3.0, 40.0, 123.4, 700.0, 1e300,
            ] {
                let (n, dn) = f.level_ext_with_slope(x);
                // The level is the same expression: bit for bit.
                assert_eq!(n.to_bits(), f.level_ext(x).to_bits(), "{f:?} x={x}");
                assert!(dn.is_finite(), "{f:?} x={x}: slope {dn}");
                // The exponential family's slope against the textbook form (w/2)·T/cosh²:
                // both are a few roundings of the same quantity, 1e-14 relative (measured ≤ 2e-16).
                if let Some(LowerFriction::Exponential {
                    t_1, t_2, w_1, w_2, ..
                }) = f.as_lower()
                {
                    let c1 = (0.5 * w_1 * x).cosh();
                    let c2 = (0.5 * w_2 * x).cosh();
                    let text = 0.5 * t_1 * w_1 / (c1 * c1) + 0.5 * t_2 * w_2 / (c2 * c2);
                    assert_relative_eq!(dn, text, epsilon = 1e-300, max_relative = 1e-14);
                }
            }
        }
    }

    #[test]
    fn branch_continuation_is_smooth_at_zero() {
        // The branch torque is continuous across ω = 0 (needed for event location).
        for f in laws() {
            for s in [1.0, -1.0] {
                let l = f.torque(-1e-9, s);
                let r = f.torque(1e-9, s);
                // Smooth: |l − r| ≈ 2e-9·|T'(0)|, measured ≤ 4.9e-9 (|T'| ≤ 2.5); 1e-7 = 20×,
                // while a sign slip would jump by 2N(0) (0.33 for Table 1's lower disc).
                assert!((l - r).abs() < 1e-7, "{f:?} s={s}: {l} vs {r}");
            }
        }
    }
}
