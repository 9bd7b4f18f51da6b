//! The bifurcation diagram of the rotor over the motor input u (the source's Figure 3).
//!
//! * **Equilibria** ([`equilibria`]): the slipping branch, explicit in ω,
//!   `u(ω) = (T_fl(ω) + T_fu(ω))/k_m`, `α(ω) = T_fl(ω)/k_θ`, with its stability from the
//!   eigenvalues of the Jacobian; the stuck set (both discs at rest) where it exists; Hopf
//!   points as zeros of `Re λ(ω)` of the complex pair.
//! * **Periodic orbits** ([`periodic`]): shooting on the Poincaré section `ω_l = ω*(u)`
//!   (2-D map in (α, ω_u)) and on the lower disc's stick exit (1-D map in ω_u), with the
//!   exact Filippov flow of `rotor_event::flow`.
//! * **Floquet multipliers** ([`monodromy`]): the monodromy matrix from the variational
//!   equations with a saltation matrix at every switching event (one multiplier exactly 0
//!   for a cycle with a stick phase); finite differences of the return maps remain as a check
//!   ([`continuation::Multipliers::FiniteDifference`]).
//! * **Continuation** ([`continuation`]): pseudo-arclength in (u, α, ω_u), with the exact
//!   Jacobian of the section map from the same variational equations.
//! * **Special points**, each with the residual of its defining condition:
//!   Hopf points (`Re λ = 0`, bisection in ω to the last bit), smooth folds
//!   (`du/ds = 0 ⇔ det(∂P/∂z − I) = 0`, a multiplier 1; bisection in arclength), grazing
//!   orbits (`min ω_l = 0` of the slipping cycle, a 2×2 Newton solve, [`grazing`]), each
//!   classified by Feigin's rule on the multipliers of both sides ([`feigin`]): persistence,
//!   or a discontinuous (non-smooth) fold where the branch turns back in u (point E), with or
//!   without period doubling.
//!
//! [`diagram`] assembles everything into a [`Diagram`], which writes JSON (the CLI's contract), CSV and an SVG figure ([`Diagram::to_svg`]).
//!
//! Its cost is benchmarked by `cargo bench -p rotor-analysis` (`benches/diagram.rs`);
//! the measurements are in `reports/measurements.md`.

#![warn(missing_docs)]

mod branch;
pub mod continuation;
mod diagram;
pub mod equilibria;
pub mod feigin;
pub mod grazing;
pub mod monodromy;
mod output;
pub mod periodic;
mod points;
mod svg;

use rotor_model::FieldError;
use rotor_model::seam::SolveError;
use thiserror::Error;

pub use diagram::{
    Diagram, DiagramOptions, EquilibriumKind, EquilibriumRow, PeriodicRow, U_MAX, diagram,
    equilibrium_part, start_point,
};
pub use points::{PointKind, SpecialPoint, grazing_near};

/// What can go wrong while computing the diagram.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BifError {
    /// The Filippov flow failed (`rotor_event::flow`, or the event solver measuring a cycle's
    /// extrema and stick time).
    #[error("the flow failed: {0}")]
    Solve(#[from] SolveError),
    /// A monodromy or shooting step that has no solution (a singular matrix, a degenerate
    /// crossing).
    #[error("{0}")]
    Degenerate(String),
    /// No slipping equilibrium with ω > 0 at `u`, so the section level `c(u) = ω*(u)` is
    /// undefined.
    #[error("no slipping equilibrium at u = {u} (needed as the section level)")]
    NoEquilibrium {
        /// The input \[V\].
        u: f64,
    },
    /// The trajectory does not reach its target (the upward crossing of the section, the
    /// lower disc's stick exit, a grazing orbit's minimum of ω_l) within the time or step
    /// limit.
    #[error("the orbit does not return to the section / stick exit at u = {u}")]
    NoReturn {
        /// The input \[V\].
        u: f64,
    },
    /// An iteration (Newton, secant, bisection, the continuation corrector) did not converge
    /// or met a singular matrix.
    #[error("no convergence at u = {u}: {detail}")]
    NoConvergence {
        /// The input where it stopped \[V\] (for the corrector, its last iterate's u).
        u: f64,
        /// Which solve failed and how (`corrector: 12 iterations`).
        detail: String,
    },
    /// An option outside its admissible range ([`DiagramOptions::validate`], and the options
    /// of callers built on this crate): the option's name (`u_max`), its value and the
    /// admissible range in words.
    #[error("invalid option {0}")]
    InvalidOption(FieldError),
    /// The trajectory meets a switching surface tangentially (`nᵀf⁻ = 0`, or it reaches the
    /// section with `ω̇_l ≤ 0`): there is no saltation matrix.
    #[error("the trajectory meets a switching surface tangentially at u = {u}, state {state:?}")]
    Grazing {
        /// The input \[V\].
        u: f64,
        /// The state `[α, ω_u, ω_l]` at the tangency (rad, rad/s, rad/s).
        state: [f64; 3],
    },
    /// A NaN or infinity in a result: a number of the diagram (checked before it is written),
    /// or a grazing orbit's monodromy matrix.
    #[error("non-finite value in the diagram: {what} = {value}")]
    NonFinite {
        /// Which number: its path in the diagram (`periodic[3].period`) or a description.
        what: String,
        /// The value (NaN when a whole matrix is meant).
        value: f64,
    },
    /// Serializing the diagram as JSON or writing its CSV failed; the underlying message.
    #[error("write failed: {0}")]
    Io(String),
}
