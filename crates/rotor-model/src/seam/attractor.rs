//! What a run settles on, named once for every user: the plane's regions, the sweep's rows
//! and the steady-state probes.

use crate::seam::steady::{RigSteady, SteadyKind};

/// The attractor a run reaches, told apart by its steady-state metrics: both discs at rest,
/// a slipping equilibrium, or a cycle with or without a stick phase of the lower disc.
///
/// A run that reaches none of them (it failed, or gave no metrics) is `None` where an
/// `Option<Attractor>` is kept, and each user words that itself (`unresolved` in the plane,
/// `failed` in a sweep's rows).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Attractor {
    /// Both discs at rest: an equilibrium with ω_l = 0 exactly ([`RigSteady::is_stuck`]).
    Stuck,
    /// A slipping equilibrium.
    Equilibrium,
    /// A cycle in which the lower disc sticks (`stick_time > 0`).
    StickSlipCycle,
    /// A cycle without stick.
    SlippingCycle,
}

impl Attractor {
    /// The attractor whose steady-state metrics are `st`.
    pub fn of(st: &RigSteady) -> Attractor {
        match *st {
            _ if st.is_stuck() => Attractor::Stuck,
            RigSteady::Equilibrium { .. } => Attractor::Equilibrium,
            RigSteady::LimitCycle { stick_time, .. } if stick_time > 0.0 => {
                Attractor::StickSlipCycle
            }
            RigSteady::LimitCycle { .. } => Attractor::SlippingCycle,
        }
    }

    /// `stuck`, `equilibrium`, `stick-slip cycle` or `slipping cycle` (the words of the
    /// plane's region names).
    pub fn as_str(self) -> &'static str {
        match self {
            Attractor::Stuck => "stuck",
            Attractor::Equilibrium => "equilibrium",
            Attractor::StickSlipCycle => "stick-slip cycle",
            Attractor::SlippingCycle => "slipping cycle",
        }
    }

    /// The kind of its steady state: an equilibrium (stuck or slipping) or a limit cycle
    /// (with or without stick).
    pub fn steady_kind(self) -> SteadyKind {
        match self {
            Attractor::Stuck | Attractor::Equilibrium => SteadyKind::Equilibrium,
            Attractor::StickSlipCycle | Attractor::SlippingCycle => SteadyKind::LimitCycle,
        }
    }
}

impl std::fmt::Display for Attractor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stuck is an equilibrium with ω_l = 0 exactly (ω_u may still creep, as Table 1's
    /// viscous upper disc does); a cycle is stick-slip when it sticks at all.
    #[test]
    fn metrics_name_their_attractor() {
        let eq = |omega_u: f64, omega_l: f64| RigSteady::Equilibrium {
            omega_u,
            omega_l,
            alpha: 0.1,
        };
        let cycle = |stick_time: f64| RigSteady::LimitCycle {
            period: 4.5,
            omega_l_max: 2.0,
            omega_l_min: 0.0,
            omega_u_max: 1.5,
            omega_u_min: 0.5,
            stick_time,
        };
        for (st, a, word, kind) in [
            (eq(1e-16, 0.0), Attractor::Stuck, "stuck", "equilibrium"),
            (
                eq(0.0, 1e-16),
                Attractor::Equilibrium,
                "equilibrium",
                "equilibrium",
            ),
            (
                eq(1.2, 1.2),
                Attractor::Equilibrium,
                "equilibrium",
                "equilibrium",
            ),
            (
                cycle(1.3),
                Attractor::StickSlipCycle,
                "stick-slip cycle",
                "limit_cycle",
            ),
            (
                cycle(0.0),
                Attractor::SlippingCycle,
                "slipping cycle",
                "limit_cycle",
            ),
            (
                cycle(f64::NAN),
                Attractor::SlippingCycle,
                "slipping cycle",
                "limit_cycle",
            ),
        ] {
            assert_eq!(Attractor::of(&st), a, "{st:?}");
            assert_eq!((a.as_str(), a.to_string()), (word, word.to_owned()));
            assert_eq!(a.steady_kind().as_str(), kind);
            assert_eq!(a.steady_kind(), st.kind());
        }
    }
}
