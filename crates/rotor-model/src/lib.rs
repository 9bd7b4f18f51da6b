//! The two-disc rotor benchmark model (drill-string set-up) with set-valued friction.
//!
//! See docs/model.md: state `x = [α, ω_u, ω_l]`, equations
//! `α̇ = ω_u − ω_l`, `J_u ω̇_u = k_m u − k_θ α − T_fu(ω_u)`, `J_l ω̇_l = k_θ α − T_fl(ω_l)`.
//!
//! This crate is shared by all solvers and holds no integration code.

#![warn(missing_docs)]

pub mod attractor;
pub mod dynamics;
pub mod equilibrium;
pub mod event;
pub mod fast_forward;
pub mod field;
pub mod friction;
pub mod lagrangian;
pub mod num;
pub mod params;
pub mod record;
pub mod scene;
pub mod steady;

pub use attractor::Attractor;
pub use dynamics::{ALPHA, Disc, DiscMode, Mode, Model, OMEGA_L, OMEGA_U, State};
pub use equilibrium::{SlipEquilibrium, StuckSet};
pub use event::{Event, EventKind};
pub use fast_forward::{FastForward, Verdict};
pub use field::FieldError;
pub use friction::Friction;
pub use lagrangian::{Coords, Lagrangian};
pub use num::{Num, Rounding, round_sig};
pub use params::{LowerFriction, Params, ParamsError, UpperFriction};
pub use record::{Integration, Recorder};
pub use scene::{
    Accuracy, Output, OutputGrid, Sample, Scene, SolveError, Solver, Stats, Trajectory,
    check_finite,
};
pub use steady::{MetricsAccumulator, SteadyKind, SteadyState};
