//! Special points located to 1e-8 V or better: the residual of each defining condition at
//! the located point, its convergence with the integration tolerance, and a check by an
//! independent route (sign changes of the condition on either side, the Filippov flow's own
//! stick detection).

use rotor_analysis::bifurcation::continuation::{Continuer, CycleInfo, Node};
use rotor_analysis::bifurcation::equilibria::complex_pair;
use rotor_analysis::bifurcation::feigin::{GrazingType, Side};
use rotor_analysis::bifurcation::grazing;
use rotor_analysis::bifurcation::periodic::Shooter;
use rotor_analysis::bifurcation::{Diagram, DiagramOptions, SpecialPoint, diagram};
use rotor_event::{StopAt, flow};
use rotor_model::Model;

use crate::common::{cont_options, model, points, st_diagram, t1_diagram};

/// The accuracy asked of every special point: 1e-8 V.
const GOAL: f64 = 1e-8;

#[test]
fn hopf_points_have_zero_real_part_and_change_sign_within_1e9_volt() {
    for (name, d) in [("table1", t1_diagram()), ("stribeck", st_diagram())] {
        let m = model(name);
        let hs = points(d, "hopf");
        assert_eq!(hs.len(), 2);
        for h in hs {
            // Residual: Re λ at rounding level of the 3×3 eigenvalue solver (ε·|J| ~ 2e-15).
            assert!(h.residual.unwrap().abs() < 1e-13, "{h:?}");
            // The condition changes sign between the equilibria 1e-9 V below and above (the
            // branch is explicit in ω: ω ± 1e-9/|du/dω|): located to 1e-9 V.
            let w = h.omega.unwrap();
            let dw = 1e-9 / m.du_domega(w).abs();
            let lo = complex_pair(&m, w - dw).unwrap().re;
            let hi = complex_pair(&m, w + dw).unwrap().re;
            assert!(lo * hi < 0.0, "{name} {h:?}: {lo:e} {hi:e}");
        }
    }
}

/// The section state of the grazing orbit `(u, w)` under the Filippov flow: from its touch
/// point (the stick-exit state) to the section `ω_l = c(u)`.
fn section_point(sh: &Shooter, u: f64, w: f64) -> ([f64; 2], f64) {
    let c = sh.section_level(u).unwrap();
    let (x, mode) = sh.exit_state(w);
    let end = flow(sh.model, u, sh.tol, x, mode, 100.0, StopAt::Section(c)).unwrap();
    assert!(end.reached);
    ([end.x[0], end.x[1]], c)
}

fn continuer(sh: Shooter<'_>) -> Continuer<'_> {
    Continuer {
        sh,
        opts: cont_options(0.01, 1e-11, 8),
    }
}

/// The Filippov cycle at `u` near the grazing orbit `(u_g, w)`, described (stick or not,
/// stability from its saltation multipliers). Newton from the grazing orbit's section point
/// with the variational Jacobian (which does not straddle the grazing as a difference quotient
/// would).
fn filippov_info_near(m: &Model, u: f64, w: f64) -> CycleInfo {
    let sh = Shooter {
        model: m,
        tol: 1e-12,
    };
    let (z0, c) = section_point(&sh, u, w);
    // Fixed point to 1e-12: far below the 1e-8 rad/s of min ω_l measured 1e-8 V from grazing.
    let z = sh.section_fixed_point_exact(u, c, z0, 1e-12).unwrap();
    continuer(sh).describe(u, c, z).unwrap()
}

/// The Filippov cycle at `u` near the grazing orbit `(u_g, w)`: slipping with `min ω_l`, or
/// stick-slip with its stick time ([`filippov_info_near`]).
fn filippov_cycle_near(m: &Model, u: f64, w: f64) -> (bool, f64) {
    let info = filippov_info_near(m, u, w);
    (info.stick_slip, info.grazing_indicator())
}

#[test]
fn grazing_points_solve_their_condition_and_are_confirmed_by_the_filippov_flow() {
    let m = model("table1");
    let graz = points(t1_diagram(), "grazing");
    assert_eq!(graz.len(), 2);
    for g in &graz {
        // Newton's residual |G|∞ (rad/s): stopped at ≤ 1e-13 or at its noise floor (the
        // integration error at point_tol = 1e-12 is ~1e-12).
        assert!(g.residual.unwrap() <= 1e-12, "{g:?}");
        // Recomputed from a nearby branch point at two tolerances: the located u moves by
        // the integration error only. At 1e-11 vs 1e-13 a 1e-9 V shift would already be
        // ten times the measured integration error of G (~1e-11 rad/s, |∂G/∂u| ~ 1).
        let w0 = m.slip_equilibria(g.u)[0].omega;
        let a = grazing::locate(&m, g.u, w0, 1e-11, 1e-13).unwrap();
        let b = grazing::locate(&m, g.u, w0, 1e-13, 1e-13).unwrap();
        assert!((a.u - b.u).abs() < 1e-9, "{a:?} vs {b:?}");
        assert!((b.u - g.u).abs() < 1e-9, "{b:?} vs {g:?}");
        // The Filippov flow (event solver, its own stick detection) on either side, 1e-8 V
        // away: slipping on one side with 0 < min ω_l (and min ω_l ≈ |∂G₁/∂u|·1e-8, of order
        // 1e-8 rad/s: below 1e-7), stick-slip on the other. So u_g is bracketed to 1e-8 V.
        let below = filippov_cycle_near(&m, g.u - GOAL, b.w);
        let above = filippov_cycle_near(&m, g.u + GOAL, b.w);
        assert_ne!(below.0, above.0, "{g:?}: {below:?} {above:?}");
        let slipping = if below.0 { above } else { below };
        assert!(
            0.0 < slipping.1 && slipping.1 < 1e-7,
            "{g:?}: min omega_l {}",
            slipping.1
        );
    }
}

#[test]
fn smooth_fold_is_a_multiplier_one_and_an_extremum_of_u() {
    let d = t1_diagram();
    let folds = points(d, "fold");
    assert_eq!(folds.len(), 1);
    let f = folds[0];
    assert_eq!(f.discontinuous, Some(false));
    // Residual: du/ds of the unit tangent, after bisection in arclength to 1e-12 relative;
    // |d²u/ds²| ≤ ~1e3 here (radius of the turn in the diagram's units), so ≤ 1e-9.
    assert!(f.residual.unwrap().abs() < 1e-9, "{f:?}");
    // Independent route: re-locate the fold from the last stable branch point before it with
    // a different tolerance (1e-12 instead of 1e-11) and steps (h_max 0.01 instead of
    // 0.035); the branch's u-maximum agrees to the integration error (well below 1e-8 V,
    // since u is quadratic in arclength there and the tangent is exact to ~tol).
    let m = model("table1");
    let sh = Shooter {
        model: &m,
        tol: 1e-12,
    };
    let cont = continuer(sh);
    let p = d
        .periodic
        .iter()
        .filter(|p| p.stable && p.u < f.u)
        .max_by(|a, b| a.u.total_cmp(&b.u))
        .unwrap();
    let y0 = [p.u, p.section_state[0], p.section_state[1]];
    let start = cont.node(y0, &[1.0, 0.0, 0.0], 0.0).unwrap();
    let (nodes, _) = cont.follow(&start, &[1.0, 0.0, 0.0]);
    let mut all: Vec<Node> = vec![start];
    all.extend(nodes);
    let w = all
        .windows(2)
        .find(|w| w[0].tangent[0] * w[1].tangent[0] < 0.0)
        .expect("the fold within 8 steps of 0.01");
    let (a, mut b) = (w[0].clone(), w[1].clone());
    b.step = (0..3).map(|k| (b.y[k] - a.y[k]) * a.tangent[k]).sum();
    let n = cont.bisect_between(&a, &b, |n| n.tangent[0], 60).unwrap();
    assert!((n.y[0] - f.u).abs() < 1e-9, "{} vs {}", n.y[0], f.u);
    // u is a maximum: both neighbours lie below (by more than the located point's error).
    assert!(a.y[0] < n.y[0] && b.y[0] < n.y[0]);
    // det(∂P/∂z − I) = 0: a nontrivial multiplier is 1 there. It moves linearly in
    // arclength (|dλ/ds| ~ 10-100), so after a 1e-12-relative bisection it is 1 to ~1e-9.
    let crit = n
        .info
        .nontrivial
        .iter()
        .map(|l| (l - 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(crit < 1e-8, "{:?}", n.info.nontrivial);
}

#[test]
fn discontinuous_folds_are_grazing_orbits_where_two_branches_turn() {
    let m = model("stribeck");
    let d = st_diagram();
    let folds = points(d, "fold");
    let graz = points(d, "grazing");
    assert_eq!(folds.len(), 2);
    for f in &folds {
        assert_eq!(f.discontinuous, Some(true));
        // The defining condition (the touching orbit): same residual bound as for grazing.
        assert!(f.residual.unwrap() <= 1e-12, "{f:?}");
        // Each is a grazing orbit of the diagram.
        assert!(graz.iter().any(|g| g.u == f.u));
    }
    // D: the unstable slipping branch and the stable stick-slip branch both lie above it; E:
    // the stable stick-slip branch and the unstable slipping branch both lie below it.
    for (f, side) in [(folds[0], "above"), (folds[1], "below")] {
        assert!(f.detail.contains(&format!("both lie {side}")), "{f:?}");
        assert!(
            f.detail.contains("a stable stick-slip") && f.detail.contains("an unstable slipping")
        );
    }
    let e = folds[1];
    // E located at two tolerances: agrees to < 1e-9 V (as for the grazing points).
    let w0 = m.slip_equilibria(e.u)[0].omega;
    let a = grazing::locate(&m, e.u, w0, 1e-11, 1e-13).unwrap();
    let b = grazing::locate(&m, e.u, w0, 1e-13, 1e-13).unwrap();
    assert!(
        (a.u - b.u).abs() < 1e-9 && (b.u - e.u).abs() < 1e-9,
        "{a:?} {b:?} {e:?}"
    );
    // Both branches meeting at E lie below it: the diagram's periodic points closest to E
    // on each branch are within 1e-6 V below it and none is above it by more than the
    // branch's own accuracy (tol 1e-11: 1e-9 V).
    for branch in [0, 1] {
        let near = d
            .periodic
            .iter()
            .filter(|p| p.branch == branch)
            .max_by(|p, q| p.u.total_cmp(&q.u))
            .unwrap();
        assert!(
            near.u < e.u + 1e-9 && e.u - near.u < 1e-6,
            "{near:?} vs {e:?}"
        );
    }
    // Independent route, 1e-8 V below E, with the Filippov flow: a stick-slip cycle with a
    // short stick phase (stick time ∝ √(u_E − u): ~1e-4 s here)...
    let (stuck, g) = filippov_cycle_near(&m, e.u - GOAL, b.w);
    assert!(stuck && -1e-3 < g && g < 0.0, "{stuck} {g:e}");
    let sh = Shooter {
        model: &m,
        tol: 1e-12,
    };
    let u = e.u - GOAL;
    // ... and the unstable slipping cycle about to graze, 0 < min ω_l < 1e-7: Newton from the
    // slipping branch's point nearest below u_E − 1e-7, moved to u along the branch tangent
    // `δz = −(∂P/∂z − I)⁻¹ ∂P/∂u δu` (so that no iterate dips into stick).
    let p = d
        .periodic
        .iter()
        .filter(|p| !p.stick_slip && p.u < e.u - 1e-7)
        .max_by(|p, q| p.u.total_cmp(&q.u))
        .unwrap();
    let zp = [p.section_state[0], p.section_state[1]];
    let dp = sh.section_derivatives(p.u, p.section_state[2], zp).unwrap();
    let dz = (dp.dz - nalgebra::Matrix2::identity())
        .lu()
        .solve(&(-dp.du * (u - p.u)))
        .unwrap();
    let c = sh.section_level(u).unwrap();
    let z = sh
        .section_fixed_point_exact(u, c, [zp[0] + dz[0], zp[1] + dz[1]], 1e-12)
        .unwrap();
    let info = continuer(sh).describe(u, c, z).unwrap();
    assert!(
        !info.stick_slip && 0.0 < info.omega_l_min && info.omega_l_min < 1e-7 && !info.stable,
        "{info:?}"
    );
    // The stick-slip cycle is stable (the stick-exit map's fixed point from the grazing
    // orbit's touch velocity and its derivative).
    let w = sh.stick_exit_fixed_point(u, b.w, 1e-12).unwrap();
    let r = sh.stick_exit_map(u, w).unwrap();
    assert!((r.x[1] - w).abs() <= 1e-11);
    let lam = sh.stick_exit_multiplier(u, w, 1e-7).unwrap();
    assert!(lam.abs() < 1.0, "stick-slip multiplier {lam}");
}

/// One special point as the snapshot pins it: its kind and its u to 1e-8 V (8 decimals).
#[derive(serde::Serialize)]
struct Pinned {
    kind: &'static str,
    u: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    discontinuous: Option<bool>,
}

/// Every special point of both diagrams, pinned to 1e-8 V: a change of any located point by
/// more than its last digit (or a point appearing or vanishing) shows up in review. The
/// points are located far more tightly than that (residuals below 1e-12; the tests above
/// confirm each to 1e-8 V or better by an independent route), so the eighth decimal is
/// stable across machines: the point closest to a rounding boundary, Table 1's upper grazing
/// point (4.6152768750508 V), is 5e-11 V from one, far more than rounding moves it (~1e-13).
#[test]
fn special_points_are_pinned_to_1e8_volt() {
    for (name, d) in [("table1", t1_diagram()), ("stribeck", st_diagram())] {
        let mut pts: Vec<Pinned> = d
            .points
            .iter()
            .map(|p| Pinned {
                kind: p.kind.as_str(),
                u: format!("{:.8}", p.u),
                discontinuous: p.discontinuous,
            })
            .collect();
        pts.sort_by(|a, b| a.u.cmp(&b.u).then(a.kind.cmp(b.kind)));
        assert!(pts.len() >= 6, "{name}: {} points", pts.len());
        insta::assert_yaml_snapshot!(format!("special_points_{name}"), pts);
    }
}

/// The Stribeck set with `lower.t_s = 0.128`: at u ≈ 1.95963 V the stable
/// stick-slip branch (below) and the stable slipping branch (above, turning back in a smooth
/// fold at ≈ 1.95972 V) are one branch passing through grazing. Feigin's counts say
/// persistence (σ⁺ = 0 + 0), and the Filippov flow confirms it 1e-8 V on either side.
#[test]
fn a_persistence_through_grazing_is_not_a_fold() {
    let m = Model::new(model("stribeck").params.with("lower.t_s", 0.128).unwrap());
    let d = diagram(&m, &DiagramOptions::default()).unwrap();
    // The values an independent computation gave, to its 5 decimals.
    let near = |p: &&SpecialPoint, u: f64| (p.u - u).abs() < 1e-5;
    let g: Vec<_> = points(&d, "grazing")
        .into_iter()
        .filter(|p| near(p, 1.95963))
        .collect();
    assert_eq!(g.len(), 1, "{g:?}");
    let g = g[0];
    assert_eq!(g.grazing_type, Some(GrazingType::Persistence), "{g:?}");
    assert_eq!((g.sigma_plus, g.sigma_minus), (Some([0, 0]), Some([0, 0])));
    assert_eq!(g.period_doubling, Some(false));
    assert!(g.detail.starts_with("persistence"), "{}", g.detail);
    // No discontinuous fold there; the smooth fold above it.
    let folds = points(&d, "fold");
    assert!(
        !folds
            .iter()
            .any(|f| f.discontinuous == Some(true) && (f.u - g.u).abs() < 1e-3),
        "{folds:?}"
    );
    let smooth = folds
        .iter()
        .find(|f| f.discontinuous == Some(false) && near(f, 1.95972))
        .unwrap_or_else(|| panic!("{folds:?}"));
    assert!(smooth.u > g.u);
    // Independent route: the Filippov flow (event solver, its own stick detection; saltation
    // multipliers) 1e-8 V below and above: a stable stick-slip cycle below, a stable slipping
    // one above. One cycle on each side, both stable: persistence, not a fold.
    let w = g.touch_omega_u.unwrap();
    let below = filippov_info_near(&m, g.u - GOAL, w);
    let above = filippov_info_near(&m, g.u + GOAL, w);
    assert!(below.stick_slip && below.stable, "{below:?}");
    assert!(!above.stick_slip && above.stable, "{above:?}");
}

/// The branch points of `d` nearest to the grazing orbit `g` with and without a stick phase,
/// nearest in (u, max ω_l) (in u alone, a point of another branch part can be nearer: Table 1's
/// unstable slipping cycles past its fold lie 4e-4 V from its upper grazing orbit).
fn nearest_rows<'a>(
    d: &'a Diagram,
    g: &SpecialPoint,
) -> [&'a rotor_analysis::bifurcation::PeriodicRow; 2] {
    let dist = |r: &rotor_analysis::bifurcation::PeriodicRow| {
        (r.u - g.u).abs() + (r.omega_l_max - g.omega_l_max.unwrap()).abs()
    };
    let nearest = |stick: bool| {
        d.periodic
            .iter()
            .filter(|r| r.stick_slip == stick)
            .min_by(|a, b| dist(a).total_cmp(&dist(b)))
            .unwrap()
    };
    [nearest(false), nearest(true)]
}

/// The shipped sets keep their types: the Stribeck set's D and E are non-smooth folds
/// (σ⁺ = 1 + 0: the slipping cycle at grazing has one real multiplier above 1), Table 1's two
/// grazing points are persistence (σ⁺ = 0 + 0). The classifier's two sides, computed at the
/// grazing orbit itself, are checked against the continuation's saltation multipliers of the
/// branch points nearest to it on each side: the same counts, and where those points lie within
/// 1e-6 V (branch ends at a collapsed step), the same values.
#[test]
fn the_shipped_sets_keep_their_grazing_types_and_both_sides_agree_with_the_branches() {
    let t128 = Model::new(model("stribeck").params.with("lower.t_s", 0.128).unwrap());
    let d128 = diagram(&t128, &DiagramOptions::default()).unwrap();
    for (name, d, want) in [
        ("table1", t1_diagram(), [GrazingType::Persistence; 2]),
        ("stribeck", st_diagram(), [GrazingType::NonsmoothFold; 2]),
        (
            "stribeck t_s 0.128",
            &d128,
            [GrazingType::NonsmoothFold, GrazingType::Persistence],
        ),
    ] {
        let g = points(d, "grazing");
        assert_eq!(g.len(), 2, "{name}");
        for (g, want) in g.iter().zip(want) {
            assert_eq!(g.grazing_type, Some(want), "{name} {g:?}");
            // A non-smooth fold is also a discontinuous fold point at the same u; persistence
            // is not.
            let fold_here = d
                .points
                .iter()
                .any(|p| p.discontinuous == Some(true) && p.u == g.u);
            assert_eq!(
                fold_here,
                want == GrazingType::NonsmoothFold,
                "{name} {g:?}"
            );
            let rows = nearest_rows(d, g);
            let sides = [
                g.slipping_multipliers.unwrap(),
                g.stick_slip_multipliers.unwrap(),
            ];
            for (row, side) in rows.iter().zip(sides) {
                let c = |m: [f64; 2]| nalgebra::Complex::new(m[0], m[1]);
                let from_row = Side::from_multipliers(c(row.multipliers[1]), c(row.multipliers[2]));
                let at_g = Side::from_multipliers(c(side[0]), c(side[1]));
                assert_eq!(
                    (from_row.sigma_plus(), from_row.sigma_minus()),
                    (at_g.sigma_plus(), at_g.sigma_minus()),
                    "{name} {g:?} {row:?}"
                );
                if (row.u - g.u).abs() <= 1e-6 {
                    // The row's cycle is up to 1e-6 V (stick time ≤ 1e-4 s) from grazing; the
                    // leading multiplier moves with it by ≤ 4e-4 relative (measured: slipping
                    // 1e-8, stick-slip 4e-4 at D, 6e-5 at E, 7e-5 at t_s = 0.128); bound 5e-3.
                    let (a, b) = (row.multipliers[1][0], side[0][0]);
                    assert!(
                        (a - b).abs() <= 5e-3 * b.abs(),
                        "{name} {g:?}: {a} (branch) vs {b} (at grazing)"
                    );
                }
            }
        }
    }
}

/// Near the Stribeck set's codimension-two cluster (lower.t_s ≈ 0.12-0.13): with t_s = 0.125
/// the low grazing orbit is a non-smooth fold (its slipping cycle, past the smooth fold 3.5e-6 V
/// above, has a real multiplier 1.0009 > 1), and both branch parts lie above it once the
/// branch points are resolved from it (> 1e-8 V away); the branch points of the step that
/// crossed it lie 1e-10 V on either side, which the old geometric rule took for a plain
/// grazing. With t_s = 0.131 a grazing orbit found both inside a step and at two collapsed
/// branch ends is written once.
#[test]
fn near_the_cluster_grazing_points_are_typed_by_the_rule_and_written_once() {
    let at = |ts: f64| {
        let m = Model::new(model("stribeck").params.with("lower.t_s", ts).unwrap());
        diagram(&m, &DiagramOptions::default()).unwrap()
    };
    let d = at(0.125);
    let low = points(&d, "grazing")[0];
    assert_eq!(
        low.grazing_type,
        Some(GrazingType::NonsmoothFold),
        "{low:?}"
    );
    assert_eq!(low.sigma_plus, Some([1, 0]));
    let fold = d
        .points
        .iter()
        .find(|p| p.discontinuous == Some(true) && p.u == low.u)
        .unwrap_or_else(|| panic!("{:?}", d.points));
    assert!(fold.detail.contains("both lie above"), "{}", fold.detail);
    assert!(!d.points.iter().any(|p| p.detail.contains("NOTE")));
    for d in [&d, &at(0.131)] {
        for (i, p) in d.points.iter().enumerate() {
            for q in &d.points[i + 1..] {
                assert!(
                    !(p.kind == q.kind
                        && p.discontinuous == q.discontinuous
                        && (p.u - q.u).abs() < 1e-9),
                    "{p:?} {q:?}"
                );
            }
        }
    }
}
