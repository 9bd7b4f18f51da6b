//! What is computed from the solvers: the registry that runs any of them by name
//! (`solvers`), shooting on their return maps (`shoot`), steady states checked against the
//! model (`steady`), bifurcation diagrams with Floquet multipliers (`bifurcation`), two-
//! parameter planes (`plane`), and the SVG writer the figures are drawn with (`plot`).

#![warn(missing_docs)]

pub mod bifurcation;
pub mod plane;
pub mod plot;
pub mod shoot;
pub mod solvers;
pub mod steady;
