//! Brute force against the two-parameter curves: a (k_θ, u) sweep of Table 1 from rest and
//! from the perturbed equilibrium classifies every grid point as the region the curves say
//! it lies in, except within one grid cell of a curve.

use rayon::prelude::*;
use rotor_analysis::plane::{CurveKind, PlaneOptions, plane, solve_u};
use rotor_analysis::solvers::SolverKind;
use rotor_harness::jobs::sweep::{Axis, Sweep, SweepStart};
use rotor_model::{Params, State};

#[test]
fn a_sweep_classifies_every_point_as_the_curves_region() {
    let base = Params::table1();
    let opts = PlaneOptions {
        u_min: 0.0,
        u_max: 6.0,
        region_cells: 2,
        ..PlaneOptions::new("k_theta", 0.05, 0.11)
    };
    let pl = plane(&base, &opts).unwrap();
    let curve = |label: &str| pl.curves.iter().find(|c| c.label == label).unwrap();
    let (s, h1, h2) = (curve("S"), curve("H1"), curve("H2"));
    let f1 = pl
        .curves
        .iter()
        .find(|c| c.kind == CurveKind::Fold)
        .unwrap();
    let sweep = |start| Sweep {
        base,
        u: Axis::parse("u", "0.02:6:13").unwrap(),
        param: "k_theta".into(),
        p: Axis::parse("param", "0.05:0.11:9").unwrap(),
        start,
        solver: SolverKind::EVENT,
        t_end: 1500.0,
    };
    let (rest, eq) = (
        sweep(SweepStart::State(State::zeros())),
        sweep(SweepStart::PerturbedEquilibrium),
    );
    let du = (6.0 - 0.02) / 12.0;
    let kinds = |sw: &Sweep| -> Vec<String> {
        (0..sw.len())
            .into_par_iter()
            .map(|k| sw.row(k).split(',').nth(2).unwrap().to_owned())
            .collect()
    };
    let (kr, ke) = (kinds(&rest), kinds(&eq));
    let mut checked = 0;
    let mut bad = Vec::new();
    for k in 0..rest.len() {
        let (u, p) = rest.point(k);
        let at = |c| solve_u(&base, "k_theta", c, p, u, 1e-10).unwrap();
        let (us, uh1, uh2, uf) = (at(s), at(h1), at(h2), at(f1));
        // Within one grid cell of a curve the answer may go either way (slow transients).
        if [us, uh1, uh2, uf].iter().any(|c| (u - c).abs() < du) {
            continue;
        }
        let expected = if u < us {
            ("stuck", "stuck")
        } else if u < uh1 {
            ("equilibrium", "equilibrium")
        } else if u < uh2 {
            ("limit_cycle", "limit_cycle")
        } else if u < uf {
            ("limit_cycle", "equilibrium")
        } else {
            ("equilibrium", "equilibrium")
        };
        checked += 1;
        if (kr[k].as_str(), ke[k].as_str()) != expected {
            bad.push(format!(
                "k_theta {p}, u {u}: rest {}, eq {} vs {expected:?}",
                kr[k], ke[k]
            ));
        }
    }
    assert!(checked > 60, "{checked} points checked");
    assert!(bad.is_empty(), "{}", bad.join("\n"));

    // The named regions: every band the curves bound is one region, named where the curves
    // and the one-parameter diagram say (H1 supercritical: a slipping cycle above it, turned
    // stick-slip at G1; H2 subcritical: the equilibrium stable again above it, beside the
    // stick-slip cycle, which stops sticking at G2 and ends in the fold F1).
    let (g1, g2) = (curve("G1"), curve("G2"));
    let mut names = Vec::new();
    for r in &pl.regions {
        let at = |c| solve_u(&base, "k_theta", c, r.p, r.u, 1e-10).unwrap();
        let edges = [at(s), at(h1), at(g1), at(h2), at(g2), at(f1)];
        let expected = [
            "both discs stuck",
            "equilibrium only",
            "slipping cycle only",
            "stick-slip cycle only",
            "bistable: equilibrium and stick-slip cycle",
            "bistable: equilibrium and slipping cycle",
            "equilibrium only",
        ][edges.iter().filter(|&&e| e < r.u).count()];
        assert_eq!(r.name, expected, "{r:?} between {edges:?}");
        assert!(r.u_lo <= r.u && r.u <= r.u_hi, "{r:?}");
        names.push(expected);
    }
    // Each of the seven bands, once (the equilibrium alone below H1 and above F1).
    assert_eq!(names.len(), 7, "{:?}", pl.regions);
}
