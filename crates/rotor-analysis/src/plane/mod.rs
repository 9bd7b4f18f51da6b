//! Two-parameter analysis: every codimension-one point of the u-diagram continued in the
//! plane of (p, u), for any parameter p of the file, and the codimension-two points where the
//! curves change type, turn, end or meet (`rotor bifurcation2`).
//!
//! Each curve is followed by pseudo-arclength ([`arc`]) on its defining system, from the
//! point of the one-parameter diagram at the file's value of p (or, outside the range, at its
//! middle), in both directions ([`curves`]):
//!
//! * **Hopf** (`hopf`): `y = (p, ω)`, `Re λ(ω; p) = 0` for the complex pair of the slipping
//!   equilibrium at velocity ω (the branch is explicit in ω, `u = u(ω; p)`). Each point carries
//!   its first Lyapunov coefficient `l1` (Kuznetsov's formula on the smooth slip field; `l1 < 0`
//!   supercritical), so a change of criticality is found as a sign change.
//! * **Grazing** (`grazing`, `discontinuous_fold`): `y = (p, u, w)`, the grazing system of
//!   [`crate::bifurcation::grazing`] (the cycle touches `ω_l = 0` at `(T_sl/k_θ, w, 0)` with
//!   `ω̇_l = 0`). Each point is classified by the one classifier of the u-diagram, Feigin's rule
//!   ([`crate::bifurcation::grazing::classify`], [`crate::bifurcation::feigin`]): a discontinuous
//!   fold where the real multipliers above 1 of the slipping and the stick-slip cycle at
//!   grazing add up to an odd number (as at the source's point E on the Stribeck set),
//!   persistence where even; the curve is split where that changes.
//! * **Smooth fold of cycles** (`fold`): `y = (p, α, ω_u, u)`, the cycle's fixed point on the
//!   section `ω_l = ω*(u)` and `det(∂P/∂z − I) = 0` (a multiplier 1).
//! * **Stuck boundary** (`stuck_boundary`): where the slipping branch meets the stuck set,
//!   `u = u(ω → 0⁺; p)`, explicit.
//!
//! Codimension-two points, located on the curves ([`codim2`]): a Hopf point changing
//! criticality (`bautin`, a sign change of l1, by bisection), a curve turning back in p
//! (`hopf_merge` where two Hopf points meet and vanish, `cusp` where two folds do), a grazing
//! curve changing between grazing and discontinuous fold (`grazing_fold`: a multiplier of one
//! side at grazing crosses 1, so Feigin's fold indicator `det(I − A)·det(I − B)` changes sign
//! and a fold curve meets the grazing curve), a curve ending at the stuck boundary
//! (`stuck_end`), and two curves meeting (`curves_cross`). Where the theory of such a nonsmooth
//! point is not settled the point only records where the curves meet and what was seen; no
//! normal form is claimed.
//!
//! The regions the curves bound are named from simulations ([`regions`]); [`picture`]
//! assembles the curves, the points and the regions into a [`Plane`] (its JSON), and
//! [`figure`] draws it.
//!
//! The modules use one another in one direction only: [`options`] and [`arc`] use no other
//! module, [`curves`] uses those two, [`codim2`] and [`regions`] use the curves, [`picture`]
//! uses all of these, and [`figure`] draws the picture.

#![warn(missing_docs)]

pub mod arc;
pub mod codim2;
pub mod curves;
pub mod figure;
pub mod options;
pub mod picture;
pub mod regions;

pub use crate::bifurcation::equilibria::first_lyapunov;
pub use codim2::{Codim2, Codim2Kind};
pub use curves::{Curve, CurveKind, CurvePoint, solve_u};
pub use options::{PlaneOptions, validate};
pub use picture::{Plane, plane, plane_with};
pub use regions::{Region, classify, region_name};
