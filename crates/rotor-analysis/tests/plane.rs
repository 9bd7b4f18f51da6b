//! The two-parameter curves: through the one-parameter points, with the grazing type the
//! one-parameter diagram finds independently, and the codimension-two points of the Stribeck
//! set over its lower static level.

use rotor_analysis::bifurcation::feigin::GrazingType;
use rotor_analysis::bifurcation::{DiagramOptions, PointKind, diagram};
use rotor_analysis::plane::{
    Codim2Kind, Curve, CurveKind, PlaneOptions, first_lyapunov, plane, solve_u,
};
use rotor_model::{Model, Params};

/// The model of `fixtures/params/{name}.toml`.
fn model(name: &str) -> Model {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../fixtures/params/{name}.toml"));
    Model::new(Params::from_file(&p).unwrap())
}

/// Started away from the file's value (at k_θ = 0.06 and lower.t_s = 0.25, from those
/// parameters' own one-parameter diagrams), the curves pass through the points of the
/// default diagram at the file's value to 1e-9 V: the Hopf, grazing and fold points of
/// Table 1, and the Hopf and grazing points of the Stribeck set.
#[test]
fn curves_started_elsewhere_pass_through_the_one_parameter_points() {
    for (name, param, range, start) in [
        ("table1", "k_theta", (0.05, 0.11), 0.06),
        ("stribeck", "lower.t_s", (0.2, 0.35), 0.25),
    ] {
        let d = diagram(&model(name), &DiagramOptions::default()).unwrap();
        let base = model(name).params;
        let p_file = base.get(param).unwrap();
        let opts = PlaneOptions {
            p_start: Some(start),
            region_cells: 2,
            ..PlaneOptions::new(param, range.0, range.1)
        };
        let pl = plane(&base, &opts).unwrap();
        let mut matched = 0;
        for sp in &d.points {
            let kind = match sp.kind {
                PointKind::Hopf => CurveKind::Hopf,
                PointKind::Grazing => CurveKind::Grazing,
                PointKind::Fold if sp.discontinuous == Some(false) => CurveKind::Fold,
                _ => continue,
            };
            let same_kind = |c: &&Curve| {
                c.kind == kind
                    || (kind == CurveKind::Grazing && c.kind == CurveKind::DiscontinuousFold)
            };
            let best = pl
                .curves
                .iter()
                .filter(same_kind)
                .filter_map(|c| solve_u(&base, param, c, p_file, sp.u, 1e-11))
                .map(|u| (u - sp.u).abs())
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-9, "{name} {:?} at {}: {best:e}", sp.kind, sp.u);
            matched += 1;
        }
        assert!(matched >= 4, "{name}: {matched}");
    }
}

/// Over the Stribeck set's lower static level T_sl ∈ [0.1, 0.45] the curves meet in a
/// cluster near T_sl ≈ 0.13: the first Hopf point changes criticality (l1 changes sign on
/// either side), both grazing curves change from grazing to discontinuous fold (the
/// slipping cycle's multiplier crosses 1), and the first Hopf and grazing curves cross (both
/// solved exactly there agree). At the file's T_sl both grazing points are discontinuous
/// folds, as the one-parameter diagram says.
#[test]
fn the_stribeck_set_has_its_codimension_two_points_where_the_curves_say() {
    let base = model("stribeck").params;
    let opts = PlaneOptions {
        region_cells: 2,
        ..PlaneOptions::new("lower.t_s", 0.1, 0.45)
    };
    let pl = plane(&base, &opts).unwrap();
    let kinds: Vec<Codim2Kind> = pl.points.iter().map(|q| q.kind).collect();
    // Its figure: the parameter's symbol and unit on the x axis, and a second panel with the
    // strip below ~0.3 V enlarged, where its Hopf, grazing and stuck-boundary curves and
    // three codimension-two points crowd into the lowest 5 % of the window.
    let svg = pl.to_svg("Stribeck set");
    assert!(svg.contains("static friction [N m] (lower.t_s)"), "x label");
    assert!(svg.contains("enlarged</text>"), "zoom panel");
    for k in [
        Codim2Kind::Bautin,
        Codim2Kind::GrazingFold,
        Codim2Kind::CurvesCross,
    ] {
        assert!(kinds.contains(&k), "{kinds:?}");
    }
    let h1 = pl.curves.iter().find(|c| c.label == "H1").unwrap();
    let g1 = pl
        .curves
        .iter()
        .filter(|c| c.label == "G1")
        .collect::<Vec<_>>();
    for q in &pl.points {
        match q.kind {
            Codim2Kind::Bautin => {
                let m = |p: f64| model_at(&base, p);
                let l1 = |p: f64| {
                    let u = solve_u(&base, "lower.t_s", h1, p, q.u, 1e-11).unwrap();
                    let w = m(p)
                        .slip_equilibria(u)
                        .into_iter()
                        .min_by(|a, b| a.omega.total_cmp(&b.omega))
                        .unwrap()
                        .omega;
                    first_lyapunov(&m(p), w).unwrap()
                };
                assert!(l1(q.p - 1e-3) * l1(q.p + 1e-3) < 0.0, "{q:?}");
            }
            Codim2Kind::CurvesCross => {
                let uh = solve_u(&base, "lower.t_s", h1, q.p, q.u, 1e-11).unwrap();
                let ug = g1
                    .iter()
                    .filter_map(|c| solve_u(&base, "lower.t_s", c, q.p, q.u, 1e-11))
                    .next()
                    .unwrap();
                // Located by bisection to 1e-10 of the range in p; the curves' slopes differ
                // by ~1 V per unit of T_sl, so they agree to ~1e-10 V there (bound 1e-8).
                assert!((uh - ug).abs() < 1e-8, "{q:?}: {uh} vs {ug}");
            }
            _ => {}
        }
        assert!((0.12..0.14).contains(&q.p), "{q:?}");
    }
    let at_file = |label: &str| {
        pl.curves
            .iter()
            .filter(|c| c.label == label)
            .find(|c| c.points.first().unwrap().p <= 0.2781 && c.points.last().unwrap().p >= 0.2781)
            .unwrap()
            .kind
    };
    assert_eq!(at_file("G1"), CurveKind::DiscontinuousFold);
    assert_eq!(at_file("G2"), CurveKind::DiscontinuousFold);
    // The pieces of a grazing curve meet exactly at their grazing_fold point, and every typed
    // point of a piece has the piece's type: the plane draws the classifier's type at every p.
    for w in pl.curves.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a.label == b.label && a.kind != b.kind {
            let (end, start) = (a.points.last().unwrap(), b.points.first().unwrap());
            assert_eq!((end.p, end.u), (start.p, start.u));
            assert!(
                pl.points
                    .iter()
                    .any(|q| q.kind == Codim2Kind::GrazingFold && q.p == end.p && q.u == end.u),
                "{:?}",
                pl.points
            );
        }
    }
    for c in pl.curves.iter().filter(|c| c.label.starts_with('G')) {
        let want = if c.kind == CurveKind::DiscontinuousFold {
            GrazingType::NonsmoothFold
        } else {
            GrazingType::Persistence
        };
        for q in c.points.iter().filter(|q| q.grazing_type.is_some()) {
            assert_eq!(q.grazing_type, Some(want), "{} {q:?}", c.label);
        }
    }
    // At T_sl = 0.128 the upper grazing curve is persistence, as the u-diagram says there
    // (points.rs: a_persistence_through_grazing_is_not_a_fold).
    let g2_at = |p: f64| {
        pl.curves
            .iter()
            .filter(|c| c.label == "G2")
            .find(|c| {
                let (lo, hi) = (c.points.first().unwrap().p, c.points.last().unwrap().p);
                lo.min(hi) <= p && p <= lo.max(hi)
            })
            .unwrap()
            .kind
    };
    assert_eq!(g2_at(0.128), CurveKind::Grazing);
}

fn model_at(base: &Params, p: f64) -> Model {
    Model::new(base.with("lower.t_s", p).unwrap())
}

/// Bad input is refused before any computation, naming the value.
#[test]
fn a_bad_parameter_or_range_is_refused_with_the_value() {
    let base = model("table1").params;
    let e = plane(&base, &PlaneOptions::new("lower.delta", 1.0, 2.0))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("\"lower.delta\"") && e.contains("valid: j_u"),
        "{e}"
    );
    let e = plane(&base, &PlaneOptions::new("k_theta", -0.01, 0.1))
        .unwrap_err()
        .to_string();
    assert!(e.contains("k_theta = -0.01: must be positive"), "{e}");
    let e = plane(&base, &PlaneOptions::new("lower.t_2", -1.0, -0.2))
        .unwrap_err()
        .to_string();
    assert!(e.contains("lower.t_2 = -1"), "{e}");
}
