//! What the CLI writes: the JSON contract (docs/design.md), the CSV, the SVG figure, and the
//! option checks.

use rotor_analysis::bifurcation::{BifError, Diagram, DiagramOptions, diagram};
use rotor_model::Model;

use crate::common::{model, st_diagram, t1_diagram};
use serde_json::Value;

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

/// A JSON number against the value it was written from: the same f64. serde_json writes the
/// shortest decimal that reads back as it, and reads it back exactly with `float_roundtrip`
/// (the workspace enables it; the default parser was measured 1-2 ulp off on a few of ~10⁴).
fn same(json: f64, x: f64, what: &str) {
    assert!(json == x, "{what}: {json:e} vs {x:e}");
}

#[test]
fn json_follows_the_cli_contract() {
    for d in [t1_diagram(), st_diagram()] {
        let v: Value = serde_json::from_str(&d.to_json().unwrap()).unwrap();
        let eq = v["equilibria"].as_array().unwrap();
        assert_eq!(eq.len(), d.equilibria.len());
        for (e, row) in eq.iter().zip(&d.equilibria) {
            for (k, x) in [("u", row.u), ("omega", row.omega), ("alpha", row.alpha)] {
                same(num(e, k), x, k);
            }
            assert_eq!(e["stable"].as_bool(), Some(row.stable));
        }
        let per = v["periodic"].as_array().unwrap();
        assert_eq!(per.len(), d.periodic.len());
        assert!(per.len() >= 200);
        for (p, row) in per.iter().zip(&d.periodic) {
            for (k, x) in [
                ("u", row.u),
                ("period", row.period),
                ("omega_l_max", row.omega_l_max),
                ("omega_l_min", row.omega_l_min),
            ] {
                same(num(p, k), x, k);
            }
            assert_eq!(p["stable"].as_bool(), Some(row.stable));
            same(num(p, "omega_u_min"), row.omega_u_min, "omega_u_min");
            let m = p["multipliers"].as_array().unwrap();
            assert_eq!(m.len(), 3);
            for (x, want) in m.iter().zip(&row.multipliers) {
                let x = x.as_array().unwrap();
                assert_eq!(x.len(), 2);
                for (c, w) in x.iter().zip(want) {
                    same(c.as_f64().unwrap(), *w, "multiplier");
                }
            }
        }
        let pts = v["points"].as_array().unwrap();
        assert_eq!(pts.len(), d.points.len());
        for (p, row) in pts.iter().zip(&d.points) {
            let kind = p["kind"].as_str().unwrap();
            assert_eq!(kind, row.kind.as_str());
            assert!(
                [
                    "hopf",
                    "fold",
                    "grazing",
                    "stick_limit",
                    "stability_change",
                    "branch_end"
                ]
                .contains(&kind),
                "{kind}"
            );
            same(num(p, "u"), row.u, "u");
            // Folds say whether they are discontinuous; nothing else carries the field.
            assert_eq!(p["discontinuous"].is_boolean(), kind == "fold", "{p}");
            // Hopf points carry their first Lyapunov coefficient; grazing points and
            // discontinuous folds their Feigin type, counts and both sides' multipliers.
            assert_eq!(p["l1"].is_f64(), kind == "hopf", "{p}");
            let at_grazing = kind == "grazing" || p["discontinuous"] == true;
            let t = p["grazing_type"].as_str();
            assert_eq!(t.is_some(), at_grazing, "{p}");
            if at_grazing {
                assert!(matches!(t, Some("persistence" | "nonsmooth_fold")), "{p}");
                assert!(p["period_doubling"].is_boolean(), "{p}");
                for k in ["sigma_plus", "sigma_minus"] {
                    assert_eq!(p[k].as_array().map(|a| a.len()), Some(2), "{p}");
                }
                for k in ["slipping_multipliers", "stick_slip_multipliers"] {
                    let m = p[k].as_array().unwrap();
                    assert!(m.len() == 2 && m.iter().all(|z| z.as_array().unwrap().len() == 2));
                }
            }
        }
    }
    // The Stribeck set's E: a discontinuous fold.
    let v: Value = serde_json::from_str(&st_diagram().to_json().unwrap()).unwrap();
    assert!(
        v["points"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["kind"] == "fold" && p["discontinuous"] == true)
    );
}

#[test]
fn non_finite_numbers_are_refused_not_written() {
    let mut d = t1_diagram().clone();
    d.periodic[3].multipliers[1][0] = f64::NAN;
    match d.to_json() {
        Err(BifError::NonFinite { what, value }) => {
            assert_eq!(what, "periodic[3].multipliers[1].re");
            assert!(value.is_nan());
        }
        other => panic!("{other:?}"),
    }
    let mut out = Vec::new();
    assert!(matches!(
        d.write_csv(&mut out),
        Err(BifError::NonFinite { .. })
    ));
    assert!(out.is_empty());
    let mut d = t1_diagram().clone();
    d.points[0].residual = Some(f64::INFINITY);
    assert!(
        matches!(d.to_json(), Err(BifError::NonFinite { what, .. }) if what == "points[0].residual")
    );
}

#[test]
fn csv_has_one_row_per_item() {
    let d = t1_diagram();
    let mut out = Vec::new();
    d.write_csv(&mut out).unwrap();
    let csv = String::from_utf8(out).unwrap();
    let count = |p: &str| csv.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!(count("equilibrium,"), d.equilibria.len());
    assert_eq!(count("periodic,"), d.periodic.len());
    assert_eq!(count("point,"), d.points.len());
    assert_eq!(count("table,"), 3);
}

/// A minimal well-formedness check: every tag closes in order, attributes are quoted, text
/// has no bare `<` or `&`.
fn well_formed(svg: &str) -> Result<(), String> {
    let mut stack: Vec<String> = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find('<') {
        let text = &rest[..i];
        if let Some(j) = text.find('&') {
            let ent = &text[j..];
            if !["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                .iter()
                .any(|e| ent.starts_with(e))
            {
                return Err(format!("bare & in {text:?}"));
            }
        }
        let end = rest[i..].find('>').ok_or("unclosed tag")? + i;
        let tag = &rest[i + 1..end];
        if tag.contains('<') {
            return Err(format!("< inside a tag: {tag}"));
        }
        if !tag.matches('"').count().is_multiple_of(2) {
            return Err(format!("unbalanced quotes: {tag}"));
        }
        if let Some(name) = tag.strip_prefix('/') {
            match stack.pop() {
                Some(open) if open == name.trim() => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
        } else if !tag.ends_with('/') {
            let name = tag.split_whitespace().next().ok_or("empty tag")?;
            stack.push(name.to_string());
        }
        rest = &rest[end + 1..];
    }
    if stack.is_empty() && rest.trim().is_empty() {
        Ok(())
    } else {
        Err(format!("unclosed: {stack:?}"))
    }
}

/// The `d` attribute of the path drawn in `color` with a dash (the unstable cycles) or
/// without (the stable ones).
fn path_of<'a>(svg: &'a str, color: &str, dashed: bool) -> &'a str {
    svg.lines()
        .find(|l| {
            l.starts_with("<path d=")
                && l.contains(&format!("stroke=\"{color}\""))
                && l.contains("stroke-dasharray") == dashed
        })
        .unwrap_or_else(|| panic!("no path in {color}"))
}

/// Runs of equal stability along each branch: `(stable runs, unstable runs)`.
fn runs(d: &Diagram) -> (usize, usize) {
    let (mut s, mut u) = (0, 0);
    let branches = d
        .periodic
        .iter()
        .map(|p| p.branch)
        .max()
        .map_or(0, |b| b + 1);
    for b in 0..branches {
        let mut prev = None;
        for p in d.periodic.iter().filter(|p| p.branch == b) {
            if prev != Some(p.stable) {
                if p.stable { s += 1 } else { u += 1 }
            }
            prev = Some(p.stable);
        }
    }
    (s, u)
}

#[test]
fn svg_is_well_formed_labelled_and_dashed_where_unstable() {
    for (name, d) in [("Table 1", t1_diagram()), ("Stribeck", st_diagram())] {
        let svg = d.to_svg(&format!("{name} & <set>"));
        well_formed(&svg).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("&amp; &lt;set&gt;"));
        for bad in ["NaN", "inf"] {
            assert!(!svg.contains(bad), "{bad} in the SVG");
        }
        // Every Hopf point, grazing point and fold is labelled with its u.
        for p in &d.points {
            let text = match (p.kind.as_str(), p.discontinuous) {
                ("hopf", _) => format!("Hopf {:.4}", p.u),
                ("grazing", _) => format!("grazing {:.4}", p.u),
                ("fold", Some(true)) => format!("fold (discontinuous) {:.4}", p.u),
                ("fold", _) => format!("fold {:.4}", p.u),
                _ => continue,
            };
            assert!(svg.contains(&text), "{name}: no label {text:?}");
        }
        // Stable cycles solid, unstable dashed: one pen-down ("M") per run, for the max and
        // the min of ω_l.
        let (s, u) = runs(d);
        assert!(u >= 1 && s >= 1);
        assert_eq!(path_of(&svg, "#1f5fbf", false).matches('M').count(), 2 * s);
        assert_eq!(path_of(&svg, "#c0392b", true).matches('M').count(), 2 * u);
        // Both equilibrium styles appear (stable and unstable slipping equilibria).
        path_of(&svg, "black", false);
        path_of(&svg, "black", true);
    }
    assert!(st_diagram().to_svg("s").contains("E fold (discontinuous)"));
    assert!(t1_diagram().to_svg("t").contains("H1 Hopf"));
}

#[test]
fn options_are_validated_with_the_field_named() {
    let m = Model::table1();
    let cases: [(DiagramOptions, &str); 8] = [
        (
            DiagramOptions {
                u_min: 3.0,
                u_max: 2.0,
                ..Default::default()
            },
            "u_max",
        ),
        (
            DiagramOptions {
                u_min: f64::NAN,
                ..Default::default()
            },
            "u_min",
        ),
        (
            DiagramOptions {
                u_max: f64::INFINITY,
                ..Default::default()
            },
            "u_max",
        ),
        (
            DiagramOptions {
                u_min: -1.0,
                ..Default::default()
            },
            "u_min",
        ),
        (
            DiagramOptions {
                u_max: 2000.0,
                ..Default::default()
            },
            "u_max",
        ),
        (
            DiagramOptions {
                n: 1,
                ..Default::default()
            },
            "n",
        ),
        (
            DiagramOptions {
                tol: 0.0,
                ..Default::default()
            },
            "tol",
        ),
        (
            DiagramOptions {
                amp_stop: -1.0,
                ..Default::default()
            },
            "amp_stop",
        ),
    ];
    for (opts, field) in cases {
        match &diagram(&m, &opts) {
            Err(e @ BifError::InvalidOption(f)) => {
                assert_eq!(f.field, field);
                assert!(e.to_string().contains(field), "{e}");
            }
            other => panic!("{field}: {other:?}"),
        }
    }
    let e = DiagramOptions {
        u_min: 3.0,
        u_max: 2.0,
        ..Default::default()
    }
    .validate()
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "invalid option u_max = 2: must be greater than u_min"
    );
}

#[test]
fn a_window_above_the_start_voltage_still_finds_its_branch() {
    // u in [4, 6] (Table 1): the default start 1.5 V is outside, and from rest at the middle
    // (5 V) the motion settles on the equilibrium; the branch comes from Hopf point 2 and
    // reaches the same smooth fold as the full diagram, to the location accuracy (1e-9 V;
    // measured 1.7e-11 V).
    let d = diagram(
        &model("table1"),
        &DiagramOptions {
            u_min: 4.0,
            u_max: 6.0,
            n: 60,
            ..Default::default()
        },
    )
    .unwrap();
    let fold = |d: &Diagram| {
        d.points
            .iter()
            .find(|p| p.kind.as_str() == "fold" && p.discontinuous == Some(false))
            .map(|p| p.u)
    };
    let (a, b) = (fold(&d).unwrap(), fold(t1_diagram()).unwrap());
    assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    assert!(d.periodic.iter().all(|p| (4.0..=6.0).contains(&p.u)));
    assert!(d.to_json().is_ok());
}
