//! The first Lyapunov coefficient of the u-diagram's Hopf points, against the direction of
//! the small cycles the diagram finds by shooting.

use rotor_analysis::bifurcation::PointKind;
use rotor_analysis::bifurcation::equilibria::first_lyapunov;

use crate::common::{model, st_diagram, t1_diagram};

/// The u-diagram's Hopf points carry their first Lyapunov coefficient, and its sign (their
/// criticality) agrees with the direction of the small cycles the diagram finds by shooting:
/// Table 1's H1 supercritical (l1 < 0), H2 and both Hopf points of the Stribeck set
/// subcritical (l1 > 0). Table 1's H2 has l1 ≈ 1.7e-3 (an independent computation outside this
/// repository, to two digits).
#[test]
fn the_lyapunov_coefficient_agrees_with_the_cycles_direction() {
    for (name, d) in [("table1", t1_diagram()), ("stribeck", st_diagram())] {
        let m = model(name);
        for sp in d.points.iter().filter(|p| p.kind == PointKind::Hopf) {
            let l1 = first_lyapunov(&m, sp.omega.unwrap()).unwrap();
            assert_eq!(sp.l1, Some(l1), "{name} {sp:?}");
            let sup = sp.detail.starts_with("supercritical");
            assert!(
                sup == (l1 < 0.0)
                    && sp
                        .detail
                        .starts_with(if sup { "super" } else { "subcritical" }),
                "{name} at {}: l1 = {l1}, {}",
                sp.u,
                sp.detail
            );
            // The witness from shooting, in the same detail: stable small cycles ⇔ l1 < 0.
            let stable = sp.detail.contains("are stable)");
            assert!(
                stable || sp.detail.contains("are unstable)"),
                "{}",
                sp.detail
            );
            assert_eq!(stable, l1 < 0.0, "{name} at {}: {}", sp.u, sp.detail);
        }
    }
    let h2 = crate::common::points(t1_diagram(), "hopf")[1].l1.unwrap();
    // Two significant digits, as the independent computation gives it.
    assert!((h2 - 1.7e-3).abs() < 0.05e-3, "{h2}");
}
