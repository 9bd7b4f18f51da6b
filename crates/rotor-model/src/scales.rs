//! The time scales of a parameter set: how fast the vector field can change, from the
//! parameters alone. The adaptive solvers bound their steps by a multiple of the friction
//! scales `τ_fric` (each with its own multiple and tolerance law; docs/methods.md, "Steps
//! tied to the model's scales"): they are the shortest on Table 1, the Stribeck set and 999
//! of 1001 random sets measured, and the only ones a step-size controller cannot see coming.

use crate::dynamics::{Disc, Model};

/// The time scales of a parameter set, in s: over each, some part of the vector field
/// `ẋ = f(x)` can change by a fraction O(1) of itself.
///
/// ```text
/// τ_osc    = 1/√(k_θ (1/J_u + 1/J_l))        the spring's fastest rate (both discs slipping;
///                                            with one disc stuck, 1/√(k_θ/J) is slower)
/// τ_visc,d = J_d/(b_d + |Δb_d|)              a disc's viscous decay time
/// τ_fric,d = v_d/(T_d/J_d) = v_d J_d/T_d     the time a disc slipping at the acceleration
///                                            scale T_d/J_d takes to cross the friction law's
///                                            velocity scale v_d
/// ```
///
/// with `v_d` the law's velocity scale ([`crate::Friction::velocity_scale`]: `2/w_i` of the
/// exponential family's terms, `ω_s/max(1, δ)` of the Stribeck family's fall) and `T_d` its
/// torque scale ([`crate::Friction::torque_scale`]: the level at rest plus the amplitudes of
/// its velocity-dependent terms). Near ω = 0 the level varies on `v_d` (the exponential
/// family's `tanh(w_1|ω|/2)`): a step on which the velocity moves by many `v_d` carries the
/// field from where that variation is exponentially small to where it is O(1) within one
/// step, faster than a step-size controller, which extrapolates the error of the last step,
/// can follow. The friction law's slope `max|N'|` needs no scale of its own: `|N'| ≲
/// T_d/v_d`, so `J_d/|N'| ≳ τ_fric,d`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeScales {
    /// `τ_osc = 1/√(k_θ (1/J_u + 1/J_l))` \[s\].
    pub oscillation: f64,
    /// `τ_visc = J/(b + |Δb|)` of the upper and lower disc \[s\] (∞ without viscous friction).
    pub viscous: [f64; 2],
    /// `τ_fric = v J/T` of the upper and lower disc \[s\] (∞ for a law without a velocity
    /// scale: the upper disc's eq. (4)).
    pub friction: [f64; 2],
    /// The friction laws' velocity scales `v` of the upper and lower disc \[rad/s\] (∞ for a
    /// law without one).
    pub velocity: [f64; 2],
    /// The discs' acceleration scales `T/J` \[rad/s²\]: `τ_fric = velocity/acceleration`.
    pub acceleration: [f64; 2],
}

impl TimeScales {
    /// The shortest of the scales, `τ = min(τ_osc, τ_visc,u, τ_visc,l, τ_fric,u, τ_fric,l)`.
    pub fn shortest(&self) -> f64 {
        [self.oscillation]
            .into_iter()
            .chain(self.viscous)
            .chain(self.friction)
            .fold(f64::INFINITY, f64::min)
    }
}

impl Model {
    /// The time scales of this parameter set ([`TimeScales`], which gives the equations).
    pub fn time_scales(&self) -> TimeScales {
        let p = &self.params;
        let oscillation = 1.0 / (p.k_theta * (1.0 / p.j_u + 1.0 / p.j_l)).sqrt();
        let per_disc = |f: fn(&Model, Disc) -> f64| Disc::BOTH.map(|d| f(self, d));
        let viscous = per_disc(|m, d| {
            let b = m.friction(d).viscous_bound();
            if b > 0.0 {
                m.inertia(d) / b
            } else {
                f64::INFINITY
            }
        });
        let velocity = per_disc(|m, d| m.friction(d).velocity_scale().unwrap_or(f64::INFINITY));
        let acceleration = per_disc(|m, d| m.friction(d).torque_scale() / m.inertia(d));
        let friction = [0, 1].map(|i| {
            if velocity[i].is_finite() && acceleration[i] > 0.0 {
                velocity[i] / acceleration[i]
            } else {
                f64::INFINITY
            }
        });
        TimeScales {
            oscillation,
            viscous,
            friction,
            velocity,
            acceleration,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{LowerFriction, Params};
    use approx::assert_relative_eq;

    /// Table 1 by hand: τ_osc = 1/√(0.0727·(1/0.4765 + 1/0.0326)) = 0.6481 s; τ_visc =
    /// 0.4765/2.2247 = 0.2142 s and 0.0326/0.0109 = 2.991 s; the lower law's fast term sets
    /// v = 2/5.7468 = 0.3480 rad/s, T = 0.1642 + 0.0603 + 0.2267 = 0.4512 N m, τ_fric =
    /// 0.3480·0.0326/0.4512 = 0.02515 s, the shortest.
    #[test]
    fn table1_scales_by_hand() {
        let s = Model::table1().time_scales();
        // Hand values to 4 digits: 1e-3 relative.
        assert_relative_eq!(s.oscillation, 0.6481, max_relative = 1e-3);
        assert_relative_eq!(s.viscous[0], 0.2142, max_relative = 1e-3);
        assert_relative_eq!(s.viscous[1], 2.991, max_relative = 1e-3);
        assert_eq!(s.friction[0], f64::INFINITY);
        assert_relative_eq!(s.friction[1], 0.02515, max_relative = 1e-3);
        assert_eq!(s.shortest(), s.friction[1]);
    }

    /// The Stribeck set: v = ω_s/δ = 1.4302/2.0575 = 0.6951 rad/s, T = 0.2781 + 0.2308 =
    /// 0.5089 N m, τ_fric = 0.6951·0.0326/0.5089 = 0.04453 s; the upper disc's viscous bound
    /// includes |Δb_u|: 0.4765/(2.4245 + 0.0084) = 0.1959 s.
    #[test]
    fn stribeck_scales_by_hand() {
        let p = Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            std::path::Path::new("s"),
        )
        .unwrap();
        let s = Model::new(p).time_scales();
        // Hand values to 4 digits: 1e-3 relative.
        assert_relative_eq!(s.friction[1], 0.04453, max_relative = 1e-3);
        assert_relative_eq!(s.viscous[0], 0.1959, max_relative = 1e-3);
        assert_eq!(s.shortest(), s.friction[1]);
    }

    /// A law whose level does not depend on ω (T_s = T_c, or both tanh amplitudes 0) has no
    /// velocity scale, and a law without viscous friction no viscous time: both ∞, and the
    /// shortest scale is then the spring's.
    #[test]
    fn flat_laws_have_no_friction_scale() {
        let mut p = Params::table1();
        p.upper.b = 0.0;
        p.lower = LowerFriction::Stribeck {
            t_s: 0.2,
            t_c: 0.2,
            omega_s: 1.0,
            delta: 2.0,
            b: 0.0,
        };
        let s = Model::new(p).time_scales();
        assert_eq!(s.friction, [f64::INFINITY; 2]);
        assert_eq!(s.viscous, [f64::INFINITY; 2]);
        assert_eq!(s.shortest(), s.oscillation);
    }
}
