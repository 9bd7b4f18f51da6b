//! Floquet multipliers from the saltation monodromy matrix, checked against its structure
//! (exact zero with a stick phase, trivial multiplier 1) and against finite differences of
//! the return maps, on slipping and stick-slip cycles of both parameter sets.

use nalgebra::{Complex, Matrix3};
use rotor_analysis::bifurcation::continuation::{Continuer, End};
use rotor_analysis::bifurcation::equilibria::{hopf_points, omega_reaching};
use rotor_analysis::bifurcation::periodic::{SectionDerivs, Shooter, eig2};
use rotor_analysis::bifurcation::start_point;
use rotor_model::seam::EventKind;
use rotor_model::{Disc, State};

use crate::common::{cont_options, model};

/// Flow tolerance of these checks.
const TOL: f64 = 1e-12;

/// A cycle: its input, section level and fixed point on the section.
struct Cycle {
    u: f64,
    c: f64,
    z: [f64; 2],
}

/// The cycle reached from rest at `u`, refined by Newton on the section map.
fn attractor(sh: &Shooter, u: f64) -> Cycle {
    let (z0, c) = start_point(sh, u).unwrap();
    // Fixed point to 1e-11 rad, rad/s: the FD steps below are 1e-5 and larger.
    let z = sh.section_fixed_point(u, c, z0, 1e-11).unwrap();
    Cycle { u, c, z }
}

fn continuer<'a>(sh: Shooter<'a>, max_nodes: usize) -> Continuer<'a> {
    Continuer {
        sh,
        opts: cont_options(0.035, 1e-10, max_nodes),
    }
}

/// An unstable slipping cycle of the Stribeck set: followed from its (subcritical) upper
/// Hopf point C for 12 continuation steps (it cannot be reached by simulation).
fn stribeck_unstable_cycle(sh: Shooter) -> Cycle {
    let m = sh.model;
    let hs = hopf_points(m, omega_reaching(m, 7.0).unwrap());
    let c_point = hs
        .iter()
        .max_by(|a, b| a.equilibrium.u.total_cmp(&b.equilibrium.u))
        .unwrap();
    let cont = continuer(sh, 12);
    let y1 = cont.hopf_cycle(c_point.equilibrium.omega, 0.04).unwrap();
    let y2 = cont.hopf_cycle(c_point.equilibrium.omega, 0.06).unwrap();
    let along = [y2[0] - y1[0], y2[1] - y1[1], y2[2] - y1[2]];
    let first = cont.node(y1, &along, 0.0).unwrap();
    let (nodes, end) = cont.follow(&first, &along);
    assert_eq!(end, End::MaxNodes);
    let n = nodes.last().unwrap();
    assert!(!n.info.stick_slip && !n.info.stable, "{:?}", n.info);
    Cycle {
        u: n.y[0],
        c: n.c,
        z: [n.y[1], n.y[2]],
    }
}

fn derivs(sh: &Shooter, cy: &Cycle) -> SectionDerivs {
    sh.section_derivatives(cy.u, cy.c, cy.z).unwrap()
}

fn by_modulus(mut v: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
    v.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    v
}

/// (a) Structure of the monodromy of a stick-slip cycle.
fn check_stick_slip_structure(sh: &Shooter, cy: &Cycle) {
    let d = derivs(sh, cy);
    assert!(d.ret.stuck);
    let kinds: Vec<_> = d.var.switches.iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        [
            EventKind::StickStart(Disc::LOWER),
            EventKind::StickEnd(Disc::LOWER)
        ]
    );
    // Entering stick: S = I − e₃e₃ᵀ exactly (f⁺ − f⁻ = −f⁻₃e₃ with ω_l = 0 set exactly at
    // the event, and −a/a = −1 in floating point).
    let onset = d.var.switches[0].saltation;
    let projector = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, 0.0));
    assert_eq!(onset, projector);
    // Leaving stick: f⁺ = f⁻ at the exit (the applied torque equals T_sl there), so S = I up
    // to the rounding of the located exit: |k_θα − T_sl| ≤ a few ulps of T_sl (~1e-16 N m),
    // over J_l (0.03) and n·f⁻ = k_θ ω_u (≥ 0.004 here): ≤ 1e-11.
    let exit = d.var.switches[1].saltation;
    assert!((exit - Matrix3::identity()).amax() < 1e-11, "{exit}");

    let mu = by_modulus(d.var.multipliers().to_vec());
    // One multiplier exactly 0: the monodromy is a product with the rank-2 projector, so the
    // third eigenvalue is at the rounding level of the eigenvalue solver, ε·‖Φ‖ (100ε‖Φ‖
    // allows for the accumulated products).
    let round = 100.0 * f64::EPSILON * d.var.phi.norm();
    assert!(mu[0].norm() <= round, "{mu:?}, bound {round:e}");
    // The trivial multiplier 1 (eigenvector f(x₀)), to the integration error: DOP853 at TOL
    // commits ≤ TOL per step over the O(100) steps of a period, plus the fixed-point
    // residual 1e-11: 100·TOL + 1e-11.
    let one = mu
        .iter()
        .min_by(|a, b| (*a - 1.0).norm().total_cmp(&(*b - 1.0).norm()))
        .unwrap();
    assert!((one - 1.0).norm() <= 100.0 * TOL + 1e-11, "{mu:?}");
}

#[test]
fn stick_slip_monodromy_has_exact_zero_and_one() {
    let t1 = model("table1");
    let st = model("stribeck");
    for (m, u) in [(&t1, 1.5), (&t1, 4.5), (&st, 1.5), (&st, 2.5)] {
        let sh = Shooter { model: m, tol: TOL };
        check_stick_slip_structure(&sh, &attractor(&sh, u));
    }
}

#[test]
fn slipping_monodromy_has_trivial_one_and_no_switch() {
    let m = model("table1");
    let sh = Shooter {
        model: &m,
        tol: TOL,
    };
    let d = derivs(&sh, &attractor(&sh, 0.5));
    assert!(!d.ret.stuck && d.var.switches.is_empty());
    let mu = d.var.multipliers();
    let one = mu
        .iter()
        .min_by(|a, b| (*a - 1.0).norm().total_cmp(&(*b - 1.0).norm()))
        .unwrap();
    // Same origin as for the stick-slip cycle.
    assert!((one - 1.0).norm() <= 100.0 * TOL + 1e-11, "{mu:?}");
    // The other two are the eigenvalues of ∂P/∂z (projection along the flow): the same
    // matrices up to the projection's rounding and the trivial one's error.
    let mut rest: Vec<_> = mu
        .iter()
        .copied()
        .filter(|l| !std::ptr::eq(l, one))
        .collect();
    rest = by_modulus(rest);
    let e = by_modulus(eig2(&d.dz).to_vec());
    for k in 0..2 {
        assert!(
            (rest[k] - e[k]).norm() <= 100.0 * TOL + 1e-11,
            "{rest:?} vs {e:?}"
        );
    }
}

/// A-posteriori global error of the return state at TOL: against a 100× tighter run.
fn return_error(sh: &Shooter, cy: &Cycle) -> f64 {
    let fine = Shooter {
        model: sh.model,
        tol: TOL / 100.0,
    };
    let a = sh.section_map(cy.u, cy.c, cy.z).unwrap().x;
    let b = fine.section_map(cy.u, cy.c, cy.z).unwrap().x;
    (a - b).amax()
}

/// The finite-difference bound on a derivative from central differences with step h:
/// noise `E/h` (each return carries a global error ≤ E, the difference of two over 2h) plus
/// the truncation `c h²`, estimated from the step 4h (`D(4h) − D(h) = 15 c h²`), both
/// doubled because they are estimates.
fn fd_bound(e: f64, h: f64, d_h: f64, d_4h: f64) -> f64 {
    2.0 * (e / h + (d_4h - d_h).abs() / 15.0)
}

/// (b) Nontrivial multipliers of the saltation monodromy against finite differences.
fn check_against_fd(sh: &Shooter, cy: &Cycle) {
    let d = derivs(sh, cy);
    let e = return_error(sh, cy).max(TOL);
    let h = 1e-5;
    let salt = by_modulus(eig2(&d.dz).to_vec());
    // The section map's Jacobian entry by entry, and its eigenvalues (well separated here,
    // so an eigenvalue moves by no more than the entries: bound × 2 for the 2×2 sum).
    let jh = sh.section_jacobian(cy.u, cy.c, cy.z, h).unwrap();
    let j4 = sh.section_jacobian(cy.u, cy.c, cy.z, 4.0 * h).unwrap();
    let mut worst = 0.0_f64;
    for r in 0..2 {
        for k in 0..2 {
            let b = fd_bound(e, h, jh[(r, k)], j4[(r, k)]);
            worst = worst.max(b);
            assert!(
                (d.dz[(r, k)] - jh[(r, k)]).abs() <= b,
                "u = {}: dP/dz[{r}{k}] saltation {} vs FD {} (bound {b:e})",
                cy.u,
                d.dz[(r, k)],
                jh[(r, k)]
            );
        }
    }
    let fd = by_modulus(eig2(&jh).to_vec());
    for k in 0..2 {
        assert!(
            (salt[k] - fd[k]).norm() <= 2.0 * worst,
            "u = {}: {salt:?} vs FD {fd:?} (bound {:e})",
            cy.u,
            2.0 * worst
        );
    }
    if d.ret.stuck {
        // The 1-D stick-exit map: its derivative is the one nonzero nontrivial multiplier.
        let exit = sh
            .next_exit(cy.u, State::new(cy.z[0], cy.z[1], cy.c))
            .unwrap();
        let w = sh.stick_exit_fixed_point(cy.u, exit.x[1], 1e-12).unwrap();
        let l_h = sh.stick_exit_multiplier(cy.u, w, h).unwrap();
        let l_4h = sh.stick_exit_multiplier(cy.u, w, 4.0 * h).unwrap();
        let b = fd_bound(e, h, l_h, l_4h);
        assert!(
            (salt[1].re - l_h).abs() <= b && salt[1].im == 0.0,
            "u = {}: {salt:?} vs stick-exit FD {l_h} (bound {b:e})",
            cy.u
        );
    }
}

#[test]
fn saltation_multipliers_match_finite_differences_table1() {
    let m = model("table1");
    let sh = Shooter {
        model: &m,
        tol: TOL,
    };
    // 0.5 V: a slipping cycle; 1.5 V and 4.5 V: stick-slip cycles (simulated facts).
    for u in [0.5, 1.5, 4.5] {
        check_against_fd(&sh, &attractor(&sh, u));
    }
}

#[test]
fn saltation_multipliers_match_finite_differences_stribeck() {
    let m = model("stribeck");
    let sh = Shooter {
        model: &m,
        tol: TOL,
    };
    check_against_fd(&sh, &attractor(&sh, 1.5));
    check_against_fd(&sh, &stribeck_unstable_cycle(sh));
}
