//! The two-disc rotor benchmark model (drill-string set-up) with set-valued friction.
//!
//! See docs/model.md: state `x = [α, ω_u, ω_l]`, equations
//! `α̇ = ω_u − ω_l`, `J_u ω̇_u = k_m u − k_θ α − T_fu(ω_u)`, `J_l ω̇_l = k_θ α − T_fl(ω_l)`.
//!
//! This crate is the physics only: parameters, friction laws, the vector field per mode, its
//! Jacobians, the equilibria and the Lagrangian form. What a solver is asked and what it
//! returns (the solver seam) is the module `rotor_model::seam`, built on this one. Neither holds
//! integration code.

#![warn(missing_docs)]

pub mod chain;
pub mod scenario;
pub mod seam;

pub mod dynamics;
pub mod equilibrium;
pub mod field;
pub mod friction;
pub(crate) mod lagrangian;
pub mod num;
pub mod params;
pub mod scales;

pub use chain::{ChainModel, ChainParams};
pub use dynamics::{
    ALPHA, Disc, DiscMode, Mode, Model, OMEGA_L, OMEGA_U, RIG_STATE_NAMES, State, state_names,
};
pub use equilibrium::{SlipEquilibrium, StuckSet};
pub use field::FieldError;
pub use friction::Friction;
pub use lagrangian::{Coords, Lagrangian};
pub use num::{Num, Rounding, round_sig};
pub use params::{LowerFriction, Params, ParamsError, UpperFriction};
pub use scales::TimeScales;
