//! The equations of motion (1) of the source, per friction mode.
//!
//! State `x = [α, ω_u, ω_l]`, `α = θ_u − θ_l`:
//!
//! ```text
//! α̇       = ω_u − ω_l
//! J_u ω̇_u = k_m u − k_θ α − T_fu(ω_u)
//! J_l ω̇_l =          k_θ α − T_fl(ω_l)
//! ```
//!
//! In a *slip* mode with branch `s = ±1` the friction is the branch torque `T_f^s(ω)`
//! (smooth, continued across ω = 0). In *stick* the disc's velocity is held at exactly 0
//! and its friction equals the applied torque (Utkin's equivalent control), so ω̇ = 0.
//! Because the mass matrix is diagonal and the discs couple only through α, the two stick
//! torques are independent: `T_ex,u = k_m u − k_θ α`, `T_ex,l = k_θ α`.

use nalgebra::{Matrix3, Vector3};

use crate::friction::Friction;
use crate::params::Params;

/// State `[α, ω_u, ω_l]` in rad, rad/s, rad/s.
pub type State = Vector3<f64>;

/// Index of α in [`State`].
pub const ALPHA: usize = 0;
/// Index of ω_u in [`State`].
pub const OMEGA_U: usize = 1;
/// Index of ω_l in [`State`].
pub const OMEGA_L: usize = 2;

/// One of the two discs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Disc {
    /// The motor-driven disc (J_u, ω_u, friction T_fu, eq. (4)).
    Upper,
    /// The disc at the end of the string, loaded by the brake (J_l, ω_l, friction T_fl).
    Lower,
}

impl Disc {
    /// Both discs, upper first.
    pub const BOTH: [Disc; 2] = [Disc::Upper, Disc::Lower];

    /// Index of this disc's velocity in [`State`].
    pub fn index(self) -> usize {
        match self {
            Disc::Upper => OMEGA_U,
            Disc::Lower => OMEGA_L,
        }
    }
}

/// Friction mode of one disc.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscMode {
    /// ω > 0 (branch s = +1).
    SlipPos,
    /// ω < 0 (branch s = −1).
    SlipNeg,
    /// ω ≡ 0, friction = applied torque.
    Stick,
}

impl DiscMode {
    /// The slip branch `s` (±1), or `None` in stick.
    pub fn branch(self) -> Option<f64> {
        match self {
            DiscMode::SlipPos => Some(1.0),
            DiscMode::SlipNeg => Some(-1.0),
            DiscMode::Stick => None,
        }
    }

    /// The slip mode of velocity `w` (≠ 0); `w = 0` gives `SlipPos`.
    pub fn slip_of(w: f64) -> DiscMode {
        if w < 0.0 {
            DiscMode::SlipNeg
        } else {
            DiscMode::SlipPos
        }
    }
}

/// Friction modes of both discs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Mode {
    /// Mode of the upper disc.
    pub upper: DiscMode,
    /// Mode of the lower disc.
    pub lower: DiscMode,
}

impl Mode {
    /// Mode of one disc.
    pub fn of(&self, d: Disc) -> DiscMode {
        match d {
            Disc::Upper => self.upper,
            Disc::Lower => self.lower,
        }
    }

    /// Sets the mode of one disc.
    pub fn set(&mut self, d: Disc, m: DiscMode) {
        match d {
            Disc::Upper => self.upper = m,
            Disc::Lower => self.lower = m,
        }
    }
}

/// The rotor model: a validated parameter set with the vector fields built on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    /// The parameter set the friction laws were built from.
    pub params: Params,
    upper: Friction,
    lower: Friction,
}

impl Model {
    /// Builds the model of a validated parameter set.
    pub fn new(params: Params) -> Model {
        Model {
            params,
            upper: Friction::upper(params.upper),
            lower: Friction::lower(params.lower),
        }
    }

    /// The Table 1 model.
    pub fn table1() -> Model {
        Model::new(Params::table1())
    }

    /// Friction law of a disc.
    #[inline]
    pub fn friction(&self, d: Disc) -> &Friction {
        match d {
            Disc::Upper => &self.upper,
            Disc::Lower => &self.lower,
        }
    }

    /// Inertia of a disc.
    #[inline]
    pub fn inertia(&self, d: Disc) -> f64 {
        match d {
            Disc::Upper => self.params.j_u,
            Disc::Lower => self.params.j_l,
        }
    }

    /// Torque on a disc from everything but its own friction:
    /// `T_ex,u = k_m u − k_θ α`, `T_ex,l = k_θ α`.
    #[inline]
    pub fn applied_torque(&self, d: Disc, x: &State, u: f64) -> f64 {
        let spring = self.params.k_theta * x[ALPHA];
        match d {
            Disc::Upper => self.params.k_m * u - spring,
            Disc::Lower => spring,
        }
    }

    /// Whether the applied torque lies inside the disc's stick interval (so stick persists).
    pub fn can_stick(&self, d: Disc, x: &State, u: f64) -> bool {
        let (lo, hi) = self.friction(d).static_interval();
        let t = self.applied_torque(d, x, u);
        lo <= t && t <= hi
    }

    /// The slip direction a stuck disc leaves toward, if the applied torque is outside the
    /// stick interval: `SlipPos` above it, `SlipNeg` below it, `None` inside.
    pub fn stick_exit(&self, d: Disc, x: &State, u: f64) -> Option<DiscMode> {
        let (lo, hi) = self.friction(d).static_interval();
        let t = self.applied_torque(d, x, u);
        if t > hi {
            Some(DiscMode::SlipPos)
        } else if t < lo {
            Some(DiscMode::SlipNeg)
        } else {
            None
        }
    }

    /// Acceleration of one disc in a given mode: `(T_ex − T_f^s(ω))/J`, or 0 in stick.
    #[inline]
    pub fn disc_accel(&self, d: Disc, x: &State, u: f64, m: DiscMode) -> f64 {
        match m.branch() {
            None => 0.0,
            Some(s) => {
                let w = x[d.index()];
                (self.applied_torque(d, x, u) - self.friction(d).torque(w, s)) / self.inertia(d)
            }
        }
    }

    /// The smooth vector field of a mode, `ẋ = f_mode(x, u)`. In stick the disc's velocity
    /// is taken as exactly 0 (whatever is stored in `x`).
    #[inline]
    pub fn rhs(&self, x: &State, u: f64, mode: Mode) -> State {
        let wu = if mode.upper == DiscMode::Stick {
            0.0
        } else {
            x[OMEGA_U]
        };
        let wl = if mode.lower == DiscMode::Stick {
            0.0
        } else {
            x[OMEGA_L]
        };
        State::new(
            wu - wl,
            self.disc_accel(Disc::Upper, x, u, mode.upper),
            self.disc_accel(Disc::Lower, x, u, mode.lower),
        )
    }

    /// Analytic Jacobian `∂f_mode/∂x`.
    pub fn jacobian(&self, x: &State, _u: f64, mode: Mode) -> Matrix3<f64> {
        let p = &self.params;
        let mut j = Matrix3::zeros();
        if let Some(s) = mode.upper.branch() {
            j[(ALPHA, OMEGA_U)] = 1.0;
            j[(OMEGA_U, ALPHA)] = -p.k_theta / p.j_u;
            j[(OMEGA_U, OMEGA_U)] = -self.upper.dtorque(x[OMEGA_U], s) / p.j_u;
        }
        if let Some(s) = mode.lower.branch() {
            j[(ALPHA, OMEGA_L)] = -1.0;
            j[(OMEGA_L, ALPHA)] = p.k_theta / p.j_l;
            j[(OMEGA_L, OMEGA_L)] = -self.lower.dtorque(x[OMEGA_L], s) / p.j_l;
        }
        j
    }

    /// `∂f_mode/∂u`.
    pub fn d_rhs_du(&self, mode: Mode) -> State {
        let mut v = State::zeros();
        if mode.upper != DiscMode::Stick {
            v[OMEGA_U] = self.params.k_m / self.params.j_u;
        }
        v
    }

    /// The Filippov-consistent mode at a state: slip by the sign of each velocity; a disc at
    /// ω = 0 sticks if the applied torque is inside its interval, else slips toward the exit.
    pub fn mode_at(&self, x: &State, u: f64) -> Mode {
        let mut m = Mode {
            upper: DiscMode::SlipPos,
            lower: DiscMode::SlipPos,
        };
        for d in Disc::BOTH {
            let w = x[d.index()];
            let dm = if w != 0.0 {
                DiscMode::slip_of(w)
            } else if !self.friction(d).is_set_valued() {
                // Zero-width interval: no stick; slip the way the applied torque pushes.
                let (_, hi) = self.friction(d).static_interval();
                DiscMode::slip_of(self.applied_torque(d, x, u) - hi)
            } else {
                self.stick_exit(d, x, u).unwrap_or(DiscMode::Stick)
            };
            m.set(d, dm);
        }
        m
    }

    /// Mechanical energy `½J_u ω_u² + ½J_l ω_l² + ½k_θ α²`.
    pub fn energy(&self, x: &State) -> f64 {
        let p = &self.params;
        0.5 * p.j_u * x[OMEGA_U].powi(2)
            + 0.5 * p.j_l * x[OMEGA_L].powi(2)
            + 0.5 * p.k_theta * x[ALPHA].powi(2)
    }

    /// Power balance `dE/dt = k_m u ω_u − T_fu ω_u − T_fl ω_l` along a mode's field.
    pub fn power(&self, x: &State, u: f64, mode: Mode) -> f64 {
        let f = self.rhs(x, u, mode);
        let p = &self.params;
        p.j_u * x[OMEGA_U] * f[OMEGA_U]
            + p.j_l * x[OMEGA_L] * f[OMEGA_L]
            + p.k_theta * x[ALPHA] * f[ALPHA]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn models() -> Vec<Model> {
        let st = Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            std::path::Path::new("s"),
        )
        .unwrap();
        vec![Model::table1(), Model::new(st)]
    }

    /// docs/model.md §3.1: Table 1 has T_su = ΔT_su = 0. With upper static friction c =
    /// T_su + ΔT_su (and Δb_u = 0) the upper law is c + b_u ω while ω_u > 0, so the field of
    /// every mode with the upper disc slipping forward is Table 1's at u − c/k_m: every
    /// u-location moves up by c/k_m. Checked on the fields (to rounding: the two sides add
    /// the same terms in another order) and on the slipping equilibria.
    #[test]
    fn upper_static_friction_shifts_every_u_location_by_its_level_over_k_m() {
        let t1 = Model::table1();
        let mut p = Params::table1();
        (p.upper.t_s, p.upper.dt_s) = (0.37975, -0.00575); // the Stribeck set's values
        let with = Model::new(p);
        let shift = (p.upper.t_s + p.upper.dt_s) / p.k_m;
        for u in [0.5, 1.5, 2.5, 4.5] {
            for x in [
                State::new(0.3, 2.0, 1.0),
                State::new(-1.0, 0.7, -3.0),
                State::new(2.5, 5.0, 0.0),
            ] {
                for lower in [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick] {
                    let m = Mode {
                        upper: DiscMode::SlipPos,
                        lower,
                    };
                    let (a, b) = (with.rhs(&x, u, m), t1.rhs(&x, u - shift, m));
                    // 1e-14: a few ulps of the O(1) accelerations.
                    assert!(
                        (a - b).amax() < 1e-14,
                        "u={u} x={x:?} {m:?}: {a:?} vs {b:?}"
                    );
                }
            }
            let (e, f) = (with.slip_equilibria(u), t1.slip_equilibria(u - shift));
            assert_eq!(e.len(), f.len(), "u={u}");
            for (e, f) in e.iter().zip(&f) {
                // The same cubic-like root found from shifted data: 1e-12 relative.
                assert_relative_eq!(e.omega, f.omega, max_relative = 1e-12);
                assert_relative_eq!(e.alpha, f.alpha, max_relative = 1e-12);
            }
        }
    }

    fn all_modes() -> Vec<Mode> {
        let ms = [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick];
        let mut v = Vec::new();
        for upper in ms {
            for lower in ms {
                v.push(Mode { upper, lower });
            }
        }
        v
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for m in models() {
            for mode in all_modes() {
                for x in [
                    State::new(1.3, 0.7, 2.1),
                    State::new(-0.4, -0.3, -1.6),
                    State::new(4.0, 3.0, 0.2),
                ] {
                    let u = 1.5;
                    let j = m.jacobian(&x, u, mode);
                    for k in 0..3 {
                        let d = 1e-6;
                        let mut xp = x;
                        let mut xm = x;
                        xp[k] += d;
                        xm[k] -= d;
                        let col = (m.rhs(&xp, u, mode) - m.rhs(&xm, u, mode)) / (2.0 * d);
                        for r in 0..3 {
                            // Central differences: O(d²) truncation + ε|f|/d rounding ≈ 4e-9
                            // (|f| ≲ 20); measured ≤ 2.1e-9 absolute, 1.0e-8 relative: 50×, 100×.
                            assert_relative_eq!(
                                j[(r, k)],
                                col[r],
                                epsilon = 1e-7,
                                max_relative = 1e-6
                            );
                        }
                    }
                    let du = (m.rhs(&x, u + 1e-6, mode) - m.rhs(&x, u - 1e-6, mode)) / 2e-6;
                    // f is linear in u: rounding ε|f|/d only; measured ≤ 1.8e-9, 1e-7 = 55×.
                    assert_relative_eq!(m.d_rhs_du(mode), du, epsilon = 1e-7);
                }
            }
        }
    }

    #[test]
    fn stick_holds_velocity_and_uses_equivalent_control() {
        let m = Model::table1();
        let x = State::new(1.0, 0.5, 0.0);
        let mode = Mode {
            upper: DiscMode::SlipPos,
            lower: DiscMode::Stick,
        };
        let f = m.rhs(&x, 1.5, mode);
        assert_eq!(f[OMEGA_L], 0.0);
        assert_eq!(f[ALPHA], 0.5);
        // Stick persists while |k_θ α| ≤ T_sl = 0.1642: α = 1 gives 0.0727 (inside).
        assert!(m.can_stick(Disc::Lower, &x, 1.5));
        let x_out = State::new(3.0, 0.5, 0.0); // k_θ α = 0.218 > T_sl
        assert_eq!(
            m.stick_exit(Disc::Lower, &x_out, 1.5),
            Some(DiscMode::SlipPos)
        );
    }

    #[test]
    fn power_balance_is_work_minus_dissipation() {
        for m in models() {
            let x = State::new(0.8, 1.1, 2.3);
            let u = 2.0;
            let mode = m.mode_at(&x, u);
            let p = &m.params;
            let expect = p.k_m * u * x[OMEGA_U]
                - m.friction(Disc::Upper).curve(x[OMEGA_U]) * x[OMEGA_U]
                - m.friction(Disc::Lower).curve(x[OMEGA_L]) * x[OMEGA_L];
            // Two sums of the same terms (≲ 10): measured ≤ 8.9e-16 (1 ulp of 5.7); 1e-13 ≈ 110×.
            assert_relative_eq!(m.power(&x, u, mode), expect, epsilon = 1e-13);
        }
    }
}
