//! A followed branch of periodic orbits, shared by the diagram and its special points.

use crate::bifurcation::continuation::{End, Node};

/// A followed branch and why each of its ends ended.
pub(crate) struct Branch {
    pub(crate) nodes: Vec<Node>,
    pub(crate) ends: [End; 2],
}
