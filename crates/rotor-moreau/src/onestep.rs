//! The one-step nonsmooth problem of the two frictional contacts, solved exactly by
//! enumerating the 3 × 3 stick/slip± modes.
//!
//! After the normal problem is solved (each contact stays closed, its normal impulse is the
//! θ-weighted level `h·N_θ`, see the crate docs), what remains on the two disc velocities
//! `v⁺ = [ω_u⁺, ω_l⁺]` is
//!
//! ```text
//! A v⁺ = b + f(v⁺) + r,     A = M̂ = M + θhC + θ²h²K  (2 × 2, the θ-block of the iteration matrix)
//! ```
//!
//! where `f` collects the smooth friction impulses and `r` the tangential contact impulses, with
//! the Coulomb law per disc i:
//!
//! ```text
//! stick:  v_i⁺ = 0,   |r_i| ≤ P_i            (P_i = μ r_N,i, μ = 1)
//! slip s: s·v_i⁺ > 0, r_i = −s·P_i
//! ```
//!
//! Along a slip branch the (possibly velocity dependent) friction impulse, smooth part plus
//! contact part, is handed over *affine* in the disc's own velocity ([`Branch`]): exact when the
//! level is explicit, the Newton linearisation when it is implicit. In stick the velocity is 0,
//! so the smooth impulse `e_i` and the bound `P_i` are plain numbers ([`StickData`]).
//!
//! **Delassus matrix.** Eliminating `v⁺ = v_free + W r` gives `W = A⁻¹`:
//!
//! ```text
//! A = [ J_u + θh b_u + θ²h² k_θ      −θ²h² k_θ            ]
//!     [ −θ²h² k_θ                    J_l + θh b_l + θ²h² k_θ ]
//! W = A⁻¹ = (1/det A)·[ A_ll  θ²h²k_θ ; θ²h²k_θ  A_uu ]
//! ```
//!
//! symmetric positive definite with a *positive* off-diagonal entry of order `h²k_θ/(J_u J_l)`:
//! the contacts couple through the spring inside one step, so the enumeration is done on the
//! full 2 × 2 problem (a diagonal W would decouple it into two scalar problems). With
//! frozen bounds (`d = pd = 0`) the problem is the KKT system of the strictly convex box QP
//! `min ½rᵀWr + rᵀv_free, |r_i| ≤ P_i`, whose solution is unique: exactly one mode is
//! admissible (up to ties on the boundary between two modes, where both give the same
//! solution).

use nalgebra::{Matrix2, Vector2};
use rotor_model::DiscMode;

/// The three candidate modes of one contact, in enumeration order.
pub(crate) const DISC_MODES: [DiscMode; 3] =
    [DiscMode::Stick, DiscMode::SlipPos, DiscMode::SlipNeg];

/// The friction impulse on one disc along a slip branch, affine in the disc velocity ω:
/// total (smooth + contact) impulse `c + d·ω`, of which the contact (tangential) impulse is
/// `r = −s·(pc + pd·ω)`, i.e. `P(ω) = pc + pd·ω` is the cone bound `μ r_N`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Branch {
    /// Constant part of the total friction impulse `c + d·ω` \[N m s\].
    pub c: f64,
    /// Its slope in ω, in the units of `A` (kg m²): in a mode where the disc slips on this
    /// branch, its diagonal entry of `A` becomes `A_ii − d` and its right-hand side `b_i + c`.
    pub d: f64,
    /// Constant part of the cone bound `P(ω) = pc + pd·ω` \[N m s\].
    pub pc: f64,
    /// Slope of the cone bound in ω (kg m²).
    pub pd: f64,
}

/// A stuck disc (ω⁺ = 0): smooth friction impulse `e` and cone bound `p ≥ 0`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StickData {
    /// The smooth friction impulse `e_i` of the stuck disc \[N m s\].
    pub e: f64,
    /// The cone bound `P_i ≥ 0` \[N m s\]: stick holds while `|r_i| ≤ P_i`.
    pub p: f64,
}

/// The one-step problem `A v⁺ = b + f(v⁺) + r` with the Coulomb law on both discs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneStepProblem {
    /// Iteration matrix (θ-block of `M̂`, minus nothing: the slip slopes are in [`Branch`]).
    pub a: Matrix2<f64>,
    /// Right-hand side (everything known at the start of the step).
    pub b: Vector2<f64>,
    /// `slip[i][0]`: branch s = +1 of disc i, `slip[i][1]`: s = −1.
    pub slip: [[Branch; 2]; 2],
    /// Stick data of disc i.
    pub stick: [StickData; 2],
}

/// A candidate (or the) solution of the one-step problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneStepSolution {
    /// Mode of each disc (upper, lower).
    pub mode: [DiscMode; 2],
    /// End-of-step velocities `v⁺`.
    pub v: Vector2<f64>,
    /// Tangential contact impulses `r`.
    pub r: Vector2<f64>,
    /// Cone bounds `P_i` at the solution.
    pub p: Vector2<f64>,
}

/// Why the enumeration gave no answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EnumError {
    /// No mode satisfies all complementarity conditions.
    NoneAdmissible,
    /// Several modes are admissible with different solutions.
    Several {
        /// How many of the nine modes were admissible (at the slack of the failing test).
        count: usize,
    },
}

fn branch_index(m: DiscMode) -> usize {
    match m {
        DiscMode::SlipNeg => 1,
        _ => 0,
    }
}

impl OneStepProblem {
    /// The linear solve of one mode: slipping discs' velocities and stuck discs' impulses.
    /// `None` if the mode's matrix is singular or not positive on its diagonal (no solution
    /// of that mode then exists in the sense of a well-posed branch).
    #[inline]
    pub(crate) fn solve_mode(&self, mode: [DiscMode; 2]) -> Option<OneStepSolution> {
        let mut v = Vector2::zeros();
        let mut r = Vector2::zeros();
        let mut p = Vector2::zeros();
        let slip: [Option<(f64, Branch)>; 2] = [0, 1].map(|i| {
            mode[i]
                .branch()
                .map(|s| (s, self.slip[i][branch_index(mode[i])]))
        });
        match (slip[0], slip[1]) {
            (Some((_, b0)), Some((_, b1))) => {
                let m = Matrix2::new(
                    self.a[(0, 0)] - b0.d,
                    self.a[(0, 1)],
                    self.a[(1, 0)],
                    self.a[(1, 1)] - b1.d,
                );
                let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
                if !(det > 0.0 && m[(0, 0)] > 0.0 && m[(1, 1)] > 0.0) {
                    return None;
                }
                let y0 = self.b[0] + b0.c;
                let y1 = self.b[1] + b1.c;
                let inv_det = 1.0 / det;
                v[0] = (m[(1, 1)] * y0 - m[(0, 1)] * y1) * inv_det;
                v[1] = (m[(0, 0)] * y1 - m[(1, 0)] * y0) * inv_det;
            }
            (Some((_, bi)), None) | (None, Some((_, bi))) => {
                let i = if slip[0].is_some() { 0 } else { 1 };
                let diag = self.a[(i, i)] - bi.d;
                if diag.is_nan() || diag <= 0.0 {
                    return None;
                }
                v[i] = (self.b[i] + bi.c) / diag;
            }
            (None, None) => {}
        }
        for i in 0..2 {
            match slip[i] {
                Some((s, bi)) => {
                    p[i] = bi.pc + bi.pd * v[i];
                    r[i] = -s * p[i];
                }
                None => {
                    // Row i with v_i = 0: r_i = (A v)_i − b_i − e_i.
                    r[i] =
                        self.a[(i, 0)] * v[0] + self.a[(i, 1)] * v[1] - self.b[i] - self.stick[i].e;
                    p[i] = self.stick[i].p;
                }
            }
        }
        Some(OneStepSolution { mode, v, r, p })
    }

    /// Scales for the tie-breaking slack: (velocity, impulse).
    fn scales(&self) -> (f64, f64) {
        let mut sv: f64 = 0.0;
        let mut sr: f64 = 0.0;
        for i in 0..2 {
            let bi = self.b[i].abs() + self.stick[i].p + self.stick[i].e.abs();
            sr = sr.max(bi);
            sv = sv.max(bi / self.a[(i, i)].abs().max(f64::MIN_POSITIVE));
        }
        (sv.max(f64::MIN_POSITIVE), sr.max(f64::MIN_POSITIVE))
    }

    /// Whether a candidate satisfies every complementarity condition, up to slacks
    /// `(slack_v, slack_r)` (zero for the strict test):
    /// stick ⇒ `|r_i| ≤ P_i`, slip s ⇒ `s·v_i > 0` and `P_i ≥ 0`.
    pub fn is_admissible(sol: &OneStepSolution, slack_v: f64, slack_r: f64) -> bool {
        (0..2).all(|i| match sol.mode[i].branch() {
            None => sol.v[i] == 0.0 && sol.r[i].abs() <= sol.p[i] + slack_r,
            Some(s) => {
                s * sol.v[i] > -slack_v
                    && (s * sol.v[i] > 0.0 || slack_v > 0.0)
                    && sol.p[i] >= -slack_r
            }
        })
    }

    /// Enumerates the nine modes and returns the admissible one.
    ///
    /// Strict conditions first; if none holds strictly (a solution exactly on the boundary
    /// between modes, up to rounding) the conditions are relaxed by 1e-12 of the problem's
    /// scale. Several admissible modes are accepted only if their solutions coincide (to the
    /// same slack), and then the one with most stuck discs is returned (exact zeros).
    pub fn solve(&self) -> Result<OneStepSolution, EnumError> {
        let mut cands: [Option<OneStepSolution>; 9] = [None; 9];
        let mut k = 0;
        for mu in DISC_MODES {
            for ml in DISC_MODES {
                cands[k] = self.solve_mode([mu, ml]);
                k += 1;
            }
        }
        let (sv, sr) = self.scales();
        // 1e-12 relative: ~4500 ulps, far above the rounding of a 2 × 2 solve, far below
        // any physical velocity or impulse the scheme resolves.
        let rel = 1e-12;
        for (slack_v, slack_r) in [(0.0, 0.0), (rel * sv, rel * sr)] {
            let mut best: Option<OneStepSolution> = None;
            let mut count = 0usize;
            let mut distinct = false;
            for c in cands.iter().flatten() {
                if !Self::is_admissible(c, slack_v, slack_r) {
                    continue;
                }
                count += 1;
                match best {
                    None => best = Some(*c),
                    Some(b) => {
                        let same = (b.v - c.v).amax() <= 4.0 * rel * sv
                            && (b.r - c.r).amax() <= 4.0 * rel * sr;
                        if !same {
                            distinct = true;
                        }
                        let sticks =
                            |m: &[DiscMode; 2]| m.iter().filter(|d| **d == DiscMode::Stick).count();
                        if sticks(&c.mode) > sticks(&b.mode) {
                            best = Some(*c);
                        }
                    }
                }
            }
            if distinct {
                return Err(EnumError::Several { count });
            }
            if let Some(b) = best {
                return Ok(b);
            }
        }
        Err(EnumError::NoneAdmissible)
    }

    /// Number of modes admissible under the strict conditions (for tests).
    pub fn count_admissible(&self) -> usize {
        let mut n = 0;
        for mu in DISC_MODES {
            for ml in DISC_MODES {
                if let Some(c) = self.solve_mode([mu, ml])
                    && Self::is_admissible(&c, 0.0, 0.0)
                {
                    n += 1;
                }
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frozen(a: Matrix2<f64>, b: Vector2<f64>, p: [f64; 2]) -> OneStepProblem {
        let br = |i: usize, s: f64| Branch {
            c: -s * p[i],
            d: 0.0,
            pc: p[i],
            pd: 0.0,
        };
        OneStepProblem {
            a,
            b,
            slip: [[br(0, 1.0), br(0, -1.0)], [br(1, 1.0), br(1, -1.0)]],
            stick: [StickData { e: 0.0, p: p[0] }, StickData { e: 0.0, p: p[1] }],
        }
    }

    #[test]
    fn decoupled_scalar_cases() {
        let a = Matrix2::new(2.0, 0.0, 0.0, 1.0);
        // Disc 0: free velocity 3/2 > bound 1/2 → slip+, v = (3 − 1)/2 = 1.
        // Disc 1: free velocity 0.2 < bound 0.5 → stick, r = −0.2.
        let s = frozen(a, Vector2::new(3.0, 0.2), [1.0, 0.5])
            .solve()
            .unwrap();
        assert_eq!(s.mode, [DiscMode::SlipPos, DiscMode::Stick]);
        assert_eq!(s.v, Vector2::new(1.0, 0.0));
        assert_eq!(s.r, Vector2::new(-1.0, -0.2));
    }

    #[test]
    fn zero_bound_contact_has_zero_friction() {
        let a = Matrix2::new(1.0, -0.1, -0.1, 1.0);
        let s = frozen(a, Vector2::new(0.3, -2.0), [0.0, 0.1])
            .solve()
            .unwrap();
        assert_eq!(s.r[0], 0.0);
        assert!(s.v[0] > 0.0);
        // At rest with zero bound and zero load: stuck with zero impulse.
        let s = frozen(a, Vector2::new(0.0, 0.0), [0.0, 0.1])
            .solve()
            .unwrap();
        assert_eq!(s.mode, [DiscMode::Stick, DiscMode::Stick]);
        assert_eq!(s.r, Vector2::zeros());
    }
}
