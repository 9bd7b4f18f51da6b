//! The codimension-two points on and between the curves: a Hopf curve changing criticality
//! (Bautin), a curve turning back in p, a grazing curve changing Feigin type (where its
//! pieces are joined exactly at the point located), a Hopf curve ending at the stuck
//! boundary, and two curves crossing.

use crate::bifurcation::equilibria::{complex_pair, first_lyapunov};
use crate::bifurcation::feigin::Feigin;
use crate::bifurcation::grazing;
use rotor_model::{Model, Params};
use serde::Serialize;

use crate::plane::curves::{Curve, CurveKind, CurvePoint, kind_name, solve_u};
use crate::plane::options::{PlaneOptions, params_at};

/// A kind of codimension-two point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Codim2Kind {
    /// The first Lyapunov coefficient changes sign along a Hopf curve.
    Bautin,
    /// A Hopf curve turns back in p: two Hopf points meet and vanish.
    HopfMerge,
    /// A fold curve turns back in p: two folds of cycles meet.
    Cusp,
    /// Another curve turns back in p.
    Turning,
    /// A Hopf curve reaches the stuck boundary (the equilibrium's velocity reaches 0).
    StuckEnd,
    /// A grazing curve turns into a discontinuous fold (a fold of cycles meets it).
    GrazingFold,
    /// Two curves cross.
    CurvesCross,
}

impl Codim2Kind {
    /// The name in the JSON and the report's table (`bautin`, `grazing_fold`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Codim2Kind::Bautin => "bautin",
            Codim2Kind::HopfMerge => "hopf_merge",
            Codim2Kind::Cusp => "cusp",
            Codim2Kind::Turning => "turning",
            Codim2Kind::StuckEnd => "stuck_end",
            Codim2Kind::GrazingFold => "grazing_fold",
            Codim2Kind::CurvesCross => "curves_cross",
        }
    }

    /// The words on the figure.
    pub fn title(self) -> &'static str {
        match self {
            Codim2Kind::Bautin => "Bautin",
            Codim2Kind::HopfMerge => "Hopf points meet",
            Codim2Kind::Cusp => "cusp",
            Codim2Kind::Turning => "turning point",
            Codim2Kind::StuckEnd => "Hopf meets stuck boundary",
            Codim2Kind::GrazingFold => "grazing turns fold",
            Codim2Kind::CurvesCross => "curves cross",
        }
    }
}

/// A codimension-two point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Codim2 {
    /// What happens there.
    pub kind: Codim2Kind,
    /// The parameter's value.
    pub p: f64,
    /// The input \[V\].
    pub u: f64,
    /// The curves involved.
    pub curves: Vec<String>,
    /// What was seen there, in words (the report's table).
    pub detail: String,
}

/// Where a grazing curve changes Feigin type (two consecutive pieces of one label and
/// different kinds): the point located by [`grazing_fold`] between the last vertex of one piece
/// and the second of the next (the first is shared and has the old type), made the end of the
/// first piece and the start of the second, so that each piece holds only points of its type
/// and the drawn type at any p is the classifier's. Returns the `grazing_fold` points.
pub(crate) fn split_at_type_changes(
    base: &Params,
    name: &str,
    curves: &mut [Curve],
    tol: f64,
) -> Vec<Codim2> {
    let mut out = Vec::new();
    for i in 1..curves.len() {
        let (head, tail) = curves.split_at_mut(i);
        let (a, b) = (&mut head[i - 1], &mut tail[0]);
        if a.label != b.label || a.kind == b.kind {
            continue;
        }
        let (Some(pa), Some(pb)) = (
            a.points.iter().rev().nth(1).or(a.points.last()).cloned(),
            b.points.get(1).cloned(),
        ) else {
            continue;
        };
        let located = grazing_fold(base, name, &pa, &pb, tol).and_then(|(p, u, w)| {
            let m = Model::new(params_at(base, name, p).ok()?);
            let (g, _, _) = grazing::residual(&m, u, w, tol).ok()?;
            Some((p, u, w, g[0].abs().max(g[1].abs())))
        });
        let (p, u) = match located {
            Some((p, u, w, residual)) => {
                let q = CurvePoint {
                    p,
                    u,
                    residual,
                    touch_omega_u: Some(w),
                    // On the border between the types: neither.
                    multiplier: None,
                    grazing_type: None,
                    period_doubling: None,
                    sigma_plus: None,
                    sigma_minus: None,
                    ..b.points[0].clone()
                };
                a.points.push(q.clone());
                b.points[0] = q;
                (p, u)
            }
            None => (b.points[0].p, b.points[0].u),
        };
        out.push(Codim2 {
            kind: Codim2Kind::GrazingFold,
            p,
            u,
            curves: vec![a.label.clone()],
            detail: format!(
                "the grazing orbit changes from {} to {}: a multiplier of the slipping or the \
                 stick-slip cycle at grazing crosses +1 (Feigin's sigma+ changes parity), so a \
                 fold of cycles meets the grazing curve",
                kind_name(a.kind),
                kind_name(b.kind)
            ),
        });
    }
    out
}

/// The codimension-two points on and between the curves (but the grazing curves' changes of
/// type: [`split_at_type_changes`]), in increasing p.
pub(crate) fn on_curves(
    base: &Params,
    name: &str,
    curves: &[Curve],
    opts: &PlaneOptions,
) -> Vec<Codim2> {
    let mut out = Vec::new();
    for c in curves {
        let pts = &c.points;
        for w in pts.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if let (Some(la), Some(lb)) = (a.l1, b.l1)
                && la * lb < 0.0
            {
                out.push(bautin(base, name, a, b, &c.label));
            }
        }
        // Turning points in p (interior extremum of p along the curve).
        for w in pts.windows(3) {
            let (a, b, cc) = (&w[0], &w[1], &w[2]);
            if (b.p - a.p) * (cc.p - b.p) < 0.0 {
                let (kind, what) = match c.kind {
                    CurveKind::Hopf => (Codim2Kind::HopfMerge, "two Hopf points meet and vanish"),
                    CurveKind::Fold => (Codim2Kind::Cusp, "two folds of cycles meet"),
                    _ => (Codim2Kind::Turning, "the curve turns back in the parameter"),
                };
                out.push(Codim2 {
                    kind,
                    p: b.p,
                    u: b.u,
                    curves: vec![c.label.clone()],
                    detail: format!(
                        "{what}: the extreme value of {name} along {} (to the step of the \
                         continuation)",
                        c.label
                    ),
                });
            }
        }
        // Hopf curves end where the equilibrium's velocity reaches 0: the stuck boundary.
        if c.kind == CurveKind::Hopf {
            for end in [pts.first(), pts.last()].into_iter().flatten() {
                if end.omega.is_some_and(|w| w < 1e-3) {
                    out.push(Codim2 {
                        kind: Codim2Kind::StuckEnd,
                        p: end.p,
                        u: end.u,
                        curves: vec![c.label.clone(), "S".into()],
                        detail: "the Hopf curve ends where the equilibrium's velocity reaches 0 \
                                 (the stuck boundary)"
                            .into(),
                    });
                }
            }
        }
    }
    // Curves of different labels that cross: at each point of one curve inside the other's
    // range of p, the other solved at that p exactly (its defining system from the
    // interpolation between its neighbouring points); a sign change of the difference in u
    // is bisected (on exact solves of both) to 1e-10 of the range of p. Two curves close
    // together (Stribeck's H1 and G1 are 2.4e-4 V apart) would cross spuriously as chords.
    for (i, a) in curves.iter().enumerate() {
        for b in curves.iter().skip(i + 1) {
            if a.label == b.label {
                continue;
            }
            let diff = |p: f64, near: f64| -> Option<(f64, f64)> {
                let ua = solve_u(base, name, a, p, near, opts.tol)?;
                let ub = solve_u(base, name, b, p, ua, opts.tol)?;
                Some((ua - ub, ua))
            };
            let mut prev: Option<(f64, f64)> = None;
            for q in &a.points {
                let Some((d, _)) = diff(q.p, q.u) else {
                    prev = None;
                    continue;
                };
                if let Some((pp, dp)) = prev
                    && dp * d < 0.0
                {
                    let (mut lo, mut hi, mut dlo) = (pp, q.p, dp);
                    let mut at = (0.5 * (lo + hi), q.u);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        let Some((dm, um)) = diff(mid, q.u) else {
                            break;
                        };
                        at = (mid, um);
                        if dm * dlo > 0.0 {
                            (lo, dlo) = (mid, dm);
                        } else {
                            hi = mid;
                        }
                        if (hi - lo).abs() <= 1e-10 * (opts.p_max - opts.p_min) {
                            break;
                        }
                    }
                    out.push(Codim2 {
                        kind: Codim2Kind::CurvesCross,
                        p: at.0,
                        u: at.1,
                        curves: vec![a.label.clone(), b.label.clone()],
                        detail: format!(
                            "{} ({}) and {} ({}) cross here; no normal form is claimed",
                            a.label,
                            kind_name(a.kind),
                            b.label,
                            kind_name(b.kind)
                        ),
                    });
                }
                prev = Some((q.p, d));
            }
        }
    }
    out.sort_by(|a, b| a.p.total_cmp(&b.p));
    out
}

/// The point between two grazing points of different Feigin type: bisection in p on the sign
/// of Feigin's fold indicator `det(I − A)·det(I − B)` ([`Feigin::fold_indicator`]; it changes
/// sign where a multiplier of either side crosses +1), the grazing orbit located at each p
/// from the linear interpolation.
fn grazing_fold(
    base: &Params,
    name: &str,
    a: &CurvePoint,
    b: &CurvePoint,
    tol: f64,
) -> Option<(f64, f64, f64)> {
    let at = |p: f64, s: f64| -> Option<(f64, f64, Feigin)> {
        let m = Model::new(params_at(base, name, p).ok()?);
        let (u0, w0) = (
            a.u + s * (b.u - a.u),
            a.touch_omega_u? + s * (b.touch_omega_u? - a.touch_omega_u?),
        );
        let g = grazing::locate(&m, u0, w0, tol, 1e-11).ok()?;
        Some((g.u, g.w, grazing::classify(&m, g.u, g.w, tol).ok()?))
    };
    let sign_a = at(a.p, 0.0)?.2.fold_indicator();
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut best = (a.p, a.u, a.touch_omega_u?);
    for _ in 0..30 {
        let s = 0.5 * (lo + hi);
        let p = a.p + s * (b.p - a.p);
        let (u, w, f) = at(p, s)?;
        best = (p, u, w);
        if f.fold_indicator() * sign_a > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
    }
    Some(best)
}

/// The Bautin point between two points of a Hopf curve whose l1 differ in sign: bisection in
/// p on the segment, the Hopf condition solved for ω at each p (secant on Re λ).
fn bautin(base: &Params, name: &str, a: &CurvePoint, b: &CurvePoint, label: &str) -> Codim2 {
    let (mut pa, mut wa, mut la) = (a.p, a.omega.unwrap_or(0.0), a.l1.unwrap_or(0.0));
    let (mut pb, mut wb) = (b.p, b.omega.unwrap_or(0.0));
    let hopf_at = |p: f64, w0: f64| -> Option<(f64, f64, f64)> {
        let m = Model::new(params_at(base, name, p).ok()?);
        let g = |w: f64| complex_pair(&m, w).map(|l| l.re);
        let (mut x0, mut x1) = (w0, w0 * (1.0 + 1e-4) + 1e-8);
        let (mut f0, mut f1) = (g(x0)?, g(x1)?);
        for _ in 0..50 {
            if f1 == f0 {
                break;
            }
            let x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
            (x0, f0, x1) = (x1, f1, x2);
            f1 = g(x1)?;
            if f1.abs() < 1e-15 {
                break;
            }
        }
        Some((x1, m.slip_equilibrium_at(x1).u, first_lyapunov(&m, x1)?))
    };
    let mut best = (a.p, a.u);
    for _ in 0..40 {
        let pm = 0.5 * (pa + pb);
        let wm = 0.5 * (wa + wb);
        let Some((w, u, l)) = hopf_at(pm, wm) else {
            break;
        };
        best = (pm, u);
        if l * la > 0.0 {
            (pa, wa, la) = (pm, w, l);
        } else {
            (pb, wb) = (pm, w);
        }
    }
    Codim2 {
        kind: Codim2Kind::Bautin,
        p: best.0,
        u: best.1,
        curves: vec![label.to_owned()],
        detail: "the first Lyapunov coefficient changes sign: the Hopf point changes from \
                 super- to subcritical (a fold of small cycles is born here)"
            .into(),
    }
}
