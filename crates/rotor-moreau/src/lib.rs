//! Moreau–Jean time-stepping of the rotor model on its Lagrangian form (solver 3 of
//! rotorbench), after Siconos' `MoreauJeanOSI` with an exact one-step friction problem.
//!
//! # The Lagrangian form and how it maps onto eqs. (1)–(5)
//!
//! [`rotor_model::Lagrangian`]: `q = [θ_u, θ_l, x_u, x_l]`,
//!
//! ```text
//! M q̈ + C q̇ + K_s q + F_int(q̇) = F_ext + r,   M = diag(J_u, J_l, 1, 1), C = diag(b_u, b_l, 0, 0),
//! K_s q = k_θ [α, −α, 0, 0],  F_ext = [k_m u, 0, 0, 0],
//! F_int = [ΔT_su + Δb_u|θ̇_u|, 0, N_u, N_l(θ̇_l)]
//! ```
//!
//! Contact i (i = u, l) has the gap `x_i ≥ 0`, normal reaction `r_N,i` (on x_i) and tangential
//! reaction `r_T,i` (on θ_i, tangential velocity θ̇_i), Coulomb with μ = 1:
//! Signorini `0 ≤ x_i ⊥ r_N,i ≥ 0` (at velocity level in the scheme) and
//! `r_T,i ∈ −μ r_N,i Sign(θ̇_i)`. The extra DOF x_i is pressed onto its contact by the level
//! `N_i` ([`rotor_model::Friction::level`]: `T_su` for the upper disc,
//! `T_cl(ω_l) − b_l|ω_l|` for the lower). While the contact stays closed, `ẍ_i = 0` gives
//! `r_N,i = N_i`, hence `r_T,i ∈ −N_i Sign(θ̇_i)` and
//!
//! ```text
//! J_u θ̈_u = k_m u − k_θ α − b_u θ̇_u − (ΔT_su + Δb_u|θ̇_u|) − T_su Sign(θ̇_u)
//! J_l θ̈_l =         k_θ α − b_l θ̇_l − N_l(θ̇_l) Sign(θ̇_l)
//! ```
//!
//! which is eq. (1) with the friction laws (2)–(5): `T_f = a(ω) + bω + N(|ω|) Sign(ω)`.
//! Only `α = θ_u − θ_l` enters, so the stepper carries `[α, θ̇_u, θ̇_l]`; `x_u ≡ x_l ≡ 0` and
//! `ẋ_u ≡ ẋ_l ≡ 0` (the contacts never open, see below), and the normal impulse of each step
//! is `h·N_θ,i` (θ-weighted level) in closed form: the normal and tangential blocks of the
//! Delassus matrix are uncoupled (`M̂` is block diagonal between θ and x), and the normal
//! Signorini problem `ẋ⁺ = −hN_θ + r_N ≥ 0 ⊥ r_N ≥ 0` has the solution `r_N = h N_θ` when
//! `N_θ ≥ 0`.
//!
//! **Negative level.** With Table 1, `N_l(ω) = T_sl + T_1 tanh(w_1|ω|/2) + T_2 tanh(w_2|ω|/2)`
//! is negative for `|ω_l| ≳ 18 rad/s` (`T_sl + T_1 + T_2 < 0`). A unilateral contact pulled
//! by a negative normal force would open and lose that (negative) friction, which eq. (1)
//! keeps. So the contact carries `N⁺ = max(N, 0)` and the remainder is a smooth force:
//! `−N Sign(ω) = −N⁺ Sign(ω) − min(N, 0)·sign(ω)`, the last term single-valued because
//! `N < 0` only far from ω = 0. Both parts are θ-weighted like the rest. The scheme thus
//! integrates eq. (1) exactly as written. A contact with zero normal force (Table 1's upper
//! disc, `T_su = 0`) has zero friction: its disc just moves under its smooth forces.
//!
//! # The scheme
//!
//! Velocity-level θ-method (Jean & Moreau; Acary & Brogliato 2008, ch. 10), as
//! `MoreauJeanOSI`:
//!
//! ```text
//! M(v⁺ − v) + hK q_θ + hC v_θ + hF_int,θ = hF_ext + p,     v_θ = (1−θ)v + θv⁺,
//! q⁺ = q + h v_θ,   q_θ = (1−θ)q + θq⁺ = q + θh v_θ,    F_int,θ = (1−θ)F_int(v) + θF_int(v⁺)
//! ⇒ M̂ v⁺ = (M − (1−θ)hC − θ(1−θ)h²K) v − hKq + hF_ext − hF_int,θ + p,   M̂ = M + θhC + θ²h²K
//! ```
//!
//! θ ∈ [1/2, 1], default 1/2 (trapezoidal on the smooth part). With
//! [`FrictionLevel::Implicit`] (default) the level in `F_int` (hence the cone bound
//! `μ r_N = hN_θ`) and the smooth friction forces are θ-weighted between the two ends of the
//! step and solved *together* with the one-step problem by Newton on the step
//! ([`stepper`]); with [`FrictionLevel::Explicit`] the level is taken at the start of the step
//! (the step problem is then piecewise linear and solved in one pass). What is exact and what
//! is iterated: with the bounds and smooth forces frozen (the explicit level, or one
//! linearised Newton problem, or one Picard problem) the one-step problem (Signorini + Coulomb
//! on both contacts) is piecewise linear and solved exactly by enumerating the nine
//! stick/slip± modes ([`onestep`]), with no tolerance. The implicit level (the default) makes
//! the step problem nonlinear: it is solved by semi-smooth Newton over those exact solves,
//! stopped at a tolerance (`1e-12·(1 + |v|)`, [`stepper`]), with a Picard fallback when Newton
//! fails; a Picard run that does not converge is flagged (below).
//!
//! **Skipping the complementarity solve.** When both discs' frozen-bound free velocities
//! `v_free,i` satisfy `|v_free,i| > 2 Σ_j |W_ij| P_j` (W = M̂⁻¹, P_j the cone bounds), no
//! admissible impulse can bring a velocity to zero: the slip mode `sign(v)` is taken,
//! Newton runs in that mode only, and its result is checked against the sign conditions
//! (a failed check falls back to the enumeration). Counted in [`rotor_model::seam::Stats::lcp_skipped`]
//! (vs [`rotor_model::seam::Stats::lcp_solves`]).
//!
//! # Order
//!
//! With the default (θ = 1/2, implicit level) the scheme is second order on stick-slip and
//! slipping cycles: friction events keep the velocity continuous (no impacts), so the O(h²)
//! local error of a step containing a stick onset or exit does not spoil the global order.
//! The explicit level and θ = 1 are first order. **Not across a velocity reversal:** in the
//! step that contains the zero crossing of a disc that does not stick, the friction's sign
//! jumps inside the step, which the step's end-point weighting cannot place: a local error
//! O(h) that makes the global error first order. Depending on whether the friction cone can
//! absorb that step's impulse, the one-step problem either takes the disc from slip+ to slip−
//! within the step, or holds it at rest for one step (reported as a Reversal, see below).
//! The measured orders and constants (of the cycle metrics, and at the state level: the
//! trace's L∞ error over a cycle and the stick onsets, all second order), and the cost per
//! step, are in `reports/measurements.md` (measured by `rotor_harness::compare/tests/moreau_order.rs`
//! and the stress case "far from rest").
//!
//! **Very large steps.** Up to h = 0.25 s every step problem of the fixtures is solved
//! exactly. At h = 0.5 s a level falling faster than `M̂` can absorb (`θh|N'| > J_l`) makes
//! the nonlinear step problem non-monotone (it may have no or several solutions); the step
//! then falls back to a Picard iteration whose frozen problems are strictly convex, and if
//! that does not converge takes its last (bounded) iterate ([`StepOutcome::exact`] =
//! `false`): 29 of 6100 steps over all fixtures at h = 0.5 (`cargo run --release -p
//! rotor-moreau --example exactness`). The state stays bounded at any h. Such a step is not
//! hidden: it is counted in [`rotor_model::seam::Stats::inexact_steps`], which the CLI and the
//! Python module turn into a warning. `tests/integration/fallback.rs` checks at h = 0.5 on
//! every fixture that each step the fallback solved satisfies the step problem (its residual
//! computed independently of the stepper) and that each other step is flagged and counted.
//!
//! # Output and events
//!
//! Dense output is linear interpolation of the state between step ends (the scheme's own:
//! `q⁺ = q + h v_θ` is linear in time inside a step). Events, located between steps:
//!
//! * `StickEnd(d)`: a stuck disc slips at the end of the step. Located where the applied
//!   torque `T_ex` ([`rotor_model::Model::applied_torque`]) leaves the stick interval
//!   ([`rotor_model::Friction::static_interval`]) — equivalently where the tangential impulse
//!   leaves the cone — by linear interpolation (or extrapolation, by at most one step) of the
//!   excess between the two step ends: O(h²).
//! * `StickStart(d)`: a slipping disc ends the step stuck. Located at the zero of the
//!   velocity's second-order Taylor expansion `ω + aΔ + ½jΔ²` from the last slipping step
//!   end, with the acceleration `a` and its rate `j = ω̈` from the model's vector field and
//!   Jacobian in the slipping mode, clamped to the step: O(h²) or better.
//! * `Reversal(d)`: the velocity changes sign without sticking; linear interpolation: O(h²).
//!   A disc held at rest for exactly one step between slips of opposite sign also reverses
//!   (at the scheme's resolution): its stick onset is withdrawn and a Reversal is reported at
//!   the zero of ω interpolated between the two slipping step ends (O(h)). Reported as a stick
//!   phase, its exit would anchor a spurious cycle in the metrics (a random-parameter test found
//!   a 2.0 s "period" on a 7.4 s cycle).
//! * `Max(d)` / `Min(d)` (only when `scene.metrics_from` is set): a sign change of the
//!   discrete velocity increments while slipping; vertex of the parabola through the three
//!   step values.
//!
//! Events are fed in time order to a [`rotor_model::seam::MetricsAccumulator`] when metrics are asked.

#![warn(missing_docs)]

pub mod chain;
pub mod contacts;
pub mod onestep;
mod run;
pub mod stepper;

pub use chain::{ChainCounts, ChainStepError, ChainStepper, simulate_chain};
pub use contacts::{ContactError, ContactSolver, Tridiagonal};
pub use onestep::{Branch, EnumError, OneStepProblem, OneStepSolution, StickData};
pub use stepper::{StepOutcome, Stepper};

/// How the friction level (the contacts' normal force) enters a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrictionLevel {
    /// θ-weighted between the start and the end of the step, solved together with the
    /// one-step problem by Newton (as Siconos does with `F_int` in its Newton loop).
    /// Second order with θ = 1/2 (first order across a velocity reversal; see the crate docs).
    #[default]
    Implicit,
    /// Taken at the start of the step: first order, one linear pass per step.
    Explicit,
}

/// Options of [`MoreauSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoreauOptions {
    /// θ ∈ [1/2, 1] of the θ-scheme (default 1/2).
    pub theta: f64,
    /// Implicit (default) or explicit friction level.
    pub friction_level: FrictionLevel,
    /// Take the slip solution without the complementarity solve when no contact can change
    /// state in the step (default `true`; `false` enumerates on every step, for checks).
    pub skip_free_steps: bool,
    /// Maximum Newton iterations per step (default 50).
    pub max_newton: u32,
    /// Stop Newton on an *estimate* of the iterate's error (default `true`): at once when
    /// the linearisation is exact (every slipping disc's friction affine in its velocity,
    /// e.g. the upper disc of eq. (4), or a stuck disc), otherwise when two updates in one
    /// mode, `δ_{k−1}` then `δ_k`, contract quadratically so that the next one,
    /// `≈ δ_k³/δ_{k−1}²`, is below a tenth of the tolerance. `false`: iterate until the
    /// update itself is below the tolerance, one iteration more (for checks).
    pub newton_estimate_stop: bool,
    /// Maximum number of steps of one run (default 1e9).
    pub max_steps: u64,
    /// [`rotor_model::seam::Output::Metrics`]: how close, in units of h², the first return after skipped
    /// periods must come to the return before them ([`rotor_model::seam::FastForward`]); 0 rejects
    /// every skip (a check of the undo).
    pub skip_verify: f64,
}

impl Default for MoreauOptions {
    fn default() -> Self {
        MoreauOptions {
            theta: 0.5,
            friction_level: FrictionLevel::Implicit,
            skip_free_steps: true,
            max_newton: 50,
            newton_estimate_stop: true,
            max_steps: 1_000_000_000,
            skip_verify: rotor_model::seam::fast_forward::VERIFY_TOLERANCES,
        }
    }
}

/// The Moreau–Jean solver; step size [`Scene::step`](rotor_model::seam::Scene::step).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MoreauSolver {
    /// θ, the friction level, Newton's limits and the step limit.
    pub options: MoreauOptions,
}

impl MoreauSolver {
    /// A solver with the given options.
    pub fn new(options: MoreauOptions) -> MoreauSolver {
        MoreauSolver { options }
    }
}
