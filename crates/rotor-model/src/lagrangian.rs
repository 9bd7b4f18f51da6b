//! The Lagrangian form of section 3 of the source, eqs. (6)–(15):
//!
//! ```text
//! M q̈ + C q̇ + K_s q + F_int(q̇) = F_ext + r,      q = [θ_u, θ_l, x_u, x_l]
//! ```
//!
//! `M = diag(J_u, J_l, 1, 1)`, `C = diag(b_u, b_l, 0, 0)`, `K_s` couples θ_u and θ_l through
//! k_θ, `F_ext = [k_m u, 0, 0, 0]`, output `y = Hᵀq̇ = [θ̇_u, θ̇_l]`.
//!
//! The extra DOFs x_u, x_l each press on a unilateral contact (gap `g_i = x_i ≥ 0`) with the
//! force `F_int[2+i]`, equal to the friction *level* N_i (T_su for the upper disc,
//! `T_cl(ω_l) − b_l|ω_l|` for the lower). Each disc's set-valued friction is the tangential
//! reaction of that contact, Coulomb with μ = 1, tangential velocity θ̇_i. The first row of
//! `F_int` carries the upper disc's smooth asymmetry `ΔT_su + Δb_u|θ̇_u|`.
//!
//! Mapping onto eqs. (1)–(5): in contact, ẍ_i = 0 gives the normal reaction `r_N,i = N_i`, and
//! the tangential reaction `r_T,i ∈ −N_i·Sign(θ̇_i)`, so
//! `J_i θ̈_i = … − b_i θ̇_i − a_i − N_i Sign(θ̇_i)` = eq. (1) with T_fi of eqs. (2)–(5).

use nalgebra::{Matrix2x4, Matrix4, Vector4};

use crate::dynamics::{Disc, Model, State};

/// Generalised coordinates `[θ_u, θ_l, x_u, x_l]`.
pub type Coords = Vector4<f64>;

/// The matrices and forces of eq. (6) for one parameter set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lagrangian {
    /// `M`, eq. (8).
    pub m: Matrix4<f64>,
    /// `C`, eq. (10).
    pub c: Matrix4<f64>,
    /// `K_s`, eq. (11).
    pub k: Matrix4<f64>,
    /// `Hᵀ` of eq. (14): `y = Hᵀ q̇`.
    pub h_t: Matrix2x4<f64>,
    model: Model,
}

impl Lagrangian {
    /// Builds eqs. (8)–(11), (15) from a model.
    pub fn new(model: &Model) -> Lagrangian {
        let p = &model.params;
        let m = Matrix4::from_diagonal(&Vector4::new(p.j_u, p.j_l, 1.0, 1.0));
        let c = Matrix4::from_diagonal(&Vector4::new(
            model.friction(Disc::UPPER).viscous(),
            model.friction(Disc::LOWER).viscous(),
            0.0,
            0.0,
        ));
        let mut k = Matrix4::zeros();
        k[(0, 0)] = p.k_theta;
        k[(0, 1)] = -p.k_theta;
        k[(1, 0)] = -p.k_theta;
        k[(1, 1)] = p.k_theta;
        let mut h_t = Matrix2x4::zeros();
        h_t[(0, 0)] = 1.0;
        h_t[(1, 1)] = 1.0;
        Lagrangian {
            m,
            c,
            k,
            h_t,
            model: *model,
        }
    }

    /// `F_ext = [k_m u, 0, 0, 0]`, eq. (13).
    pub fn f_ext(&self, u: f64) -> Coords {
        Coords::new(self.model.params.k_m * u, 0.0, 0.0, 0.0)
    }

    /// `F_int(q̇)`, eq. (12): `[ΔT_su + Δb_u|θ̇_u|, 0, N_u, N_l(θ̇_l)]`.
    pub fn f_int(&self, v: &Coords) -> Coords {
        let up = self.model.friction(Disc::UPPER);
        let lo = self.model.friction(Disc::LOWER);
        let s = if v[0] < 0.0 { -1.0 } else { 1.0 };
        Coords::new(up.offset(v[0], s), 0.0, up.level(v[0]), lo.level(v[1]))
    }

    /// The friction level (normal force of contact i) at tangential velocity `w`.
    pub fn normal_force(&self, d: Disc, w: f64) -> f64 {
        self.model.friction(d).level(w)
    }

    /// Coordinates from a state: `θ_l = 0` by convention (only α = θ_u − θ_l matters),
    /// contacts closed (`x_u = x_l = 0`). Returns `(q, q̇)`.
    pub fn from_state(x: &State) -> (Coords, Coords) {
        (
            Coords::new(x[0], 0.0, 0.0, 0.0),
            Coords::new(x[1], x[2], 0.0, 0.0),
        )
    }

    /// State `[θ_u − θ_l, θ̇_u, θ̇_l]` from coordinates.
    pub fn to_state(q: &Coords, v: &Coords) -> State {
        State::new(q[0] - q[1], v[0], v[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// With both contacts slipping (tangential reaction −N_i sign θ̇_i, normal reaction N_i),
    /// the Lagrangian form gives exactly the accelerations of eq. (1).
    #[test]
    fn slip_accelerations_match_eq1() {
        let st = crate::Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            std::path::Path::new("s"),
        )
        .unwrap();
        for model in [Model::table1(), Model::new(st)] {
            let l = Lagrangian::new(&model);
            let u = 1.7;
            for x in [State::new(0.9, 1.2, 3.4), State::new(-0.5, -0.7, 0.4)] {
                let (q, v) = Lagrangian::from_state(&x);
                let fi = l.f_int(&v);
                let mut r = Coords::zeros();
                r[0] = -fi[2] * v[0].signum();
                r[1] = -fi[3] * v[1].signum();
                r[2] = fi[2];
                r[3] = fi[3];
                let rhs = l.f_ext(u) + r - l.c * v - l.k * q - fi;
                let acc = l.m.try_inverse().unwrap() * rhs;
                let f = model.rhs(&x, u, model.mode_at(&x, u));
                // Same terms summed in another order: measured ≤ 3.6e-15 (1 ulp of |ω̇_u|
                // ≈ 18); 1e-13 ≈ 30×.
                assert_relative_eq!(acc[0], f[1], epsilon = 1e-13);
                assert_relative_eq!(acc[1], f[2], epsilon = 1e-13);
                assert_eq!(acc[2], 0.0);
                assert_eq!(acc[3], 0.0);
                let y = l.h_t * v;
                assert_eq!((y[0], y[1]), (x[1], x[2]));
            }
        }
    }
}
