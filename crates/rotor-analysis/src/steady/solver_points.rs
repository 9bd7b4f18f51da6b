//! The special points of the cycles located by any solver, with its own shooting
//! ([`crate::shoot`]) and its own residuals. The event-driven continuation's point is only the
//! place to look; every number reported comes from the solver's own return map.
//!
//! * **Grazing orbit** (G): the slipping cycle's `min ω_l = 0`. The solver shoots its
//!   slipping cycle (section: a maximum of ω_l) at `u_g + s·4δ`, `+ s·2δ`, `+ s·δ` on the side
//!   `s` where the continuation has slipping cycles (δ = 1e-4 V, or 5 % of the distance to the
//!   nearest other special point), reads `m(u) = min ω_l` off each orbit, and takes the root
//!   of the quadratic through the three; one more shot at `δ/8` beyond that root and the
//!   quadratic through the last three gives the point. If a shot lands on the stick-slip
//!   cycle, δ shrinks 10× (twice); last, the shots are taken at the u of three continuation
//!   rows at least 1e-5 V away, each from its own row's state (the Stribeck set's E, whose
//!   slipping cycle's multiplier 4.65 amplifies a start shifted in u). `m(u)` is smooth on the slipping side,
//!   so the quadratic's error is `O(δ³)`; the residual is the change of the root between the
//!   two fits \[V\].
//! * **Type** (Feigin's rule, [`crate::bifurcation::feigin`]): σ⁺ = the number of real
//!   multipliers above +1 of the solver's slipping cycle (its closest shot) and of its
//!   stick-slip cycle (section: the stick exit) shot `δ` from the point on the side where the
//!   continuation has stick-slip cycles. σ⁺ odd: a non-smooth fold, written as a `grazing`
//!   point and a `fold` point with `discontinuous: true` (point E); even: persistence. Whether
//!   the stick-slip cycle lies on the slipping side (the fold's geometry) is checked and said.
//! * **Smooth fold** (F): a multiplier through +1, where u is extremal along the branch. The
//!   solver holds the last section coordinate `s` and solves for the cycle and u
//!   ([`crate::shoot::shoot_with_u`]), at `s₀ − d`, `s₀`, `s₀ + d`; the parabola's vertex is
//!   the next `s₀`, and `d` shrinks 4× per round (3 rounds, `d₀ = 2e-3·(1 + |s₀|)`). The
//!   residual is the change of the vertex's u in the last round \[V\]; the multiplier nearest
//!   +1 at the vertex is in the detail.
//! * **Stability change** elsewhere: consecutive re-shot rows of one branch whose stability
//!   differs, more than one row spacing (at least 0.05 V) from any fold, grazing or Hopf
//!   point; reported between the rows, not refined (neither parameter set has one).

use crate::bifurcation::feigin::GrazingType;
use crate::bifurcation::{Diagram, PeriodicRow, PointKind, SpecialPoint};
use crate::shoot::{Orbit, Section, shoot, shoot_with_u};
use crate::solvers::SolverKind;
use rayon::prelude::*;
use rotor_model::Model;

use crate::steady::orbit_rows::{BySolverOptions, NotFound, first_crossing, row_of, shoot_opts};

/// The condition of a grazing point located by a solver.
pub(crate) const GRAZING_CONDITION: &str = "min omega_l = 0 of the solver's slipping cycle, root of the quadratic through its last three shots; residual: change of the root from the previous fit [V]";
/// The condition of a smooth fold located by a solver.
pub(crate) const FOLD_CONDITION: &str = "u extremal along the solver's branch (shooting with u free at a fixed section coordinate), parabola vertex; residual: change of the vertex's u in the last refinement [V]";

/// The points one solver located, and those it did not.
#[derive(Debug, Clone, Default)]
pub struct Located {
    /// The special points the solver located, with their conditions and residuals.
    pub points: Vec<SpecialPoint>,
    /// The continuation's points it did not locate, each with the reason.
    pub not_found: Vec<NotFound>,
}

/// Every grazing orbit and smooth fold of the event-driven continuation, located again by
/// `kind` (see the module docs); discontinuous folds come with their grazing orbit.
pub fn locate(kind: SolverKind, model: &Model, event: &Diagram, opts: &BySolverOptions) -> Located {
    let jobs: Vec<&SpecialPoint> = event
        .points
        .iter()
        .filter(|p| {
            p.kind == PointKind::Grazing
                || (p.kind == PointKind::Fold && p.discontinuous == Some(false))
        })
        .collect();
    let results: Vec<Result<Vec<SpecialPoint>, String>> = jobs
        .par_iter()
        .map(|p| {
            if p.kind == PointKind::Grazing {
                grazing(kind, model, event, p, opts)
            } else {
                smooth_fold(kind, model, p, opts)
            }
        })
        .collect();
    let mut out = Located::default();
    for (p, r) in jobs.iter().zip(results) {
        match r {
            Ok(v) => out.points.extend(v),
            Err(e) => out.not_found.push(NotFound {
                u: p.u,
                reason: format!("{} not located: {e}", p.kind),
            }),
        }
    }
    out
}

/// Real multipliers above +1 (σ⁺) and below −1 (σ⁻).
fn sigma(m: &[[f64; 2]]) -> (usize, usize) {
    let real = m.iter().filter(|z| z[1] == 0.0);
    (
        real.clone().filter(|z| z[0] > 1.0).count(),
        real.filter(|z| z[0] < -1.0).count(),
    )
}

fn pair(m: &[[f64; 2]]) -> [[f64; 2]; 2] {
    [
        m.first().copied().unwrap_or([0.0, 0.0]),
        m.get(1).copied().unwrap_or([0.0, 0.0]),
    ]
}

/// The root near `x` of the quadratic through three points `(u, m)`: Newton on it from the
/// secant root of the last two.
fn quadratic_root(p: &[(f64, f64)]) -> Result<f64, String> {
    let [(u0, m0), (u1, m1), (u2, m2)] = [p[0], p[1], p[2]];
    let f01 = (m1 - m0) / (u1 - u0);
    let f12 = (m2 - m1) / (u2 - u1);
    let f012 = (f12 - f01) / (u2 - u0);
    let q = |u: f64| m0 + f01 * (u - u0) + f012 * (u - u0) * (u - u1);
    let dq = |u: f64| f01 + f012 * (2.0 * u - u0 - u1);
    let mut x = u2 - m2 / f12;
    for _ in 0..50 {
        let dx = q(x) / dq(x);
        x -= dx;
        if dx.abs() <= 1e-15 * x.abs().max(1.0) {
            break;
        }
    }
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("no root of min omega_l through the shots {p:?}"))
    }
}

/// The continuation's slipping and stick-slip rows beside the grazing orbit at `u`, each
/// ordered outward from it: where one branch passes through it, the rows of the step that
/// crosses it walked outward along their own part of the branch; where branches end at it,
/// the rows of the branch whose end is nearest. Only rows resolved from `u` are kept (at least
/// 1e-8 V (relative) away, and each at least 1.5× farther than the one before, up to 0.05 V): the rows of
/// the crossing step may lie on either side of `u` by their error alone (1e-10 V).
fn beside(event: &Diagram, u: f64) -> (Vec<&PeriodicRow>, Vec<&PeriodicRow>) {
    let rows = &event.periodic;
    let crossing = (0..rows.len().saturating_sub(1))
        .filter(|&i| {
            rows[i].branch == rows[i + 1].branch && rows[i].stick_slip != rows[i + 1].stick_slip
        })
        .map(|i| (i, (rows[i].u - u).abs().max((rows[i + 1].u - u).abs())))
        .filter(|(_, d)| *d < 0.1)
        .min_by(|a, b| a.1.total_cmp(&b.1));
    // Rows from index k in direction dir while on k's branch and kind.
    let walk = |k: usize, dir: isize| {
        let (b, ss) = (rows[k].branch, rows[k].stick_slip);
        let mut out = Vec::new();
        let mut j = k as isize;
        while j >= 0 && (j as usize) < rows.len() {
            let r = &rows[j as usize];
            if r.branch != b || r.stick_slip != ss {
                break;
            }
            out.push(r);
            j += dir;
        }
        out
    };
    let end_of = |ss: bool| {
        let k = (0..rows.len())
            .filter(|&i| rows[i].stick_slip == ss)
            .min_by(|&a, &b| (rows[a].u - u).abs().total_cmp(&(rows[b].u - u).abs()));
        k.map(|k| {
            // Outward: the direction along the list in which the distance grows.
            // A neighbour on another branch or of the other kind counts as no neighbour.
            let next = |d: isize| {
                let j = k as isize + d;
                (j >= 0 && (j as usize) < rows.len())
                    .then(|| &rows[j as usize])
                    .filter(|r| r.branch == rows[k].branch && r.stick_slip == ss)
                    .map(|r| (r.u - u).abs())
            };
            let dir = if next(1).unwrap_or(-1.0) >= next(-1).unwrap_or(-1.0) {
                1
            } else {
                -1
            };
            walk(k, dir)
        })
        .unwrap_or_default()
    };
    let (slip, stick) = match crossing {
        Some((i, _)) if rows[i].stick_slip => (walk(i + 1, 1), walk(i, -1)),
        Some((i, _)) => (walk(i, -1), walk(i + 1, 1)),
        None => (end_of(false), end_of(true)),
    };
    fn spaced(v: Vec<&PeriodicRow>, u: f64) -> Vec<&PeriodicRow> {
        let mut out: Vec<&PeriodicRow> = Vec::new();
        for r in v {
            let d = (r.u - u).abs();
            let last = out.last().map_or(0.0, |l: &&PeriodicRow| (l.u - u).abs());
            if d > 1e-8 * u.abs().max(1.0) && d >= 1.5 * last && d <= 0.05 {
                out.push(r);
            }
        }
        out
    }
    (spaced(slip, u), spaced(stick, u))
}

/// One shot of the solver's cycle: its input u \[V\], its diagram row and its orbit.
type Shot = (f64, PeriodicRow, Orbit);

/// A grazing point fitted from shots: the root of the quadratic through the first three
/// shots, the root through the last three (the point), and the four shots.
type Fit = (f64, f64, Vec<Shot>);

/// One solver shooting the cycles beside one grazing point.
struct Shooting<'a> {
    kind: SolverKind,
    solver: &'a dyn rotor_model::seam::Solver,
    model: &'a Model,
    opts: &'a BySolverOptions,
}

impl Shooting<'_> {
    /// The solver's slipping cycle (section: a maximum of ω_l) at `u`, from `z0` or else from
    /// the first crossing of a run from `row`'s state (one crossing on: an unstable cycle's
    /// start has not drifted); an error if the cycle it finds sticks.
    fn slipping(&self, u: f64, z0: Option<&[f64]>, row: &PeriodicRow) -> Result<Shot, String> {
        let (solver, model) = (self.solver, self.model);
        let sc = self.opts.scene(self.kind, u);
        let z = match z0 {
            Some(z) => z.to_vec(),
            None => first_crossing(
                solver,
                model,
                &sc,
                row.section_state,
                row.period,
                Section::LowerMax,
            )?,
        };
        let o = shoot(
            solver,
            model,
            &sc,
            Section::LowerMax,
            &z,
            // Finite-difference steps 1e-7·(1 + |z|) rather than 1e-6: a step must not make
            // a cycle within 1e-5 rad/s of ω_l = 0 stick (the map is not smooth across
            // that); the map's rounding (≈ tol 1e-10) over the step stays ≤ 1e-3 of the
            // derivative.
            &crate::shoot::ShootOptions {
                fd_rel: 1e-7,
                ..shoot_opts(row.period)
            },
        )
        .map_err(|e| format!("slipping cycle at u = {u}: {e}"))?;
        let r = row_of(solver, model, &sc, &o, row.branch)?;
        if r.stick_time > 0.0 {
            return Err(format!(
                "the cycle shot at u = {u} sticks (stick time {:.3e} s, period {:.6} s, \
                 multipliers {:?}, start row at u = {})",
                r.stick_time, r.period, o.multipliers, row.u
            ));
        }
        Ok((u, r, o))
    }

    /// The solver's stick-slip cycle (section: the stick exit) at the first of the nearest
    /// eight continuation rows `sticks` that it sees sticking (a stick phase shorter than
    /// Moreau–Jean's step is not seen).
    fn stick_slip(&self, sticks: &[&PeriodicRow]) -> Result<Shot, String> {
        let (solver, model) = (self.solver, self.model);
        let mut why = String::from("no stick-slip cycle of the continuation beside it");
        for row in sticks.iter().take(8) {
            let sc = self.opts.scene(self.kind, row.u);
            let sec = Section::StickExit;
            let r = first_crossing(solver, model, &sc, row.section_state, row.period, sec)
                .and_then(|z2| {
                    let o = shoot(solver, model, &sc, sec, &z2, &shoot_opts(row.period))
                        .map_err(|e| format!("stick-slip cycle at u = {}: {e}", sc.u))?;
                    let r = row_of(solver, model, &sc, &o, row.branch)?;
                    Ok((sc.u, r, o))
                });
            match r {
                Ok(v) => return Ok(v),
                Err(e) => why = e,
            }
        }
        Err(why)
    }
}

/// The points `(u, m(u))` of shots, `m(u) = min ω_l` of the shot's cycle.
fn min_omega(shots: &[Shot]) -> Vec<(f64, f64)> {
    shots.iter().map(|(u, r, _)| (*u, r.omega_l_min)).collect()
}

/// The fit from three slipping shots (outermost first, on the side `s` of the point): `r1`
/// the root of the quadratic through them; one more shot `step/8` beyond `r1` on side `s`,
/// from the nearest shot's fixed point (at `row`'s period); `r2` the root through the last
/// three. An error if `r2` is not beyond the slipping cycles' side of that last shot.
fn refine(
    sh: &Shooting,
    mut shots: Vec<Shot>,
    s: f64,
    step: f64,
    row: &PeriodicRow,
) -> Result<Fit, String> {
    let r1 = quadratic_root(&min_omega(&shots))?;
    let z_near = shots[2].2.z.clone();
    shots.push(sh.slipping(r1 + s * step / 8.0, Some(&z_near), row)?);
    let r2 = quadratic_root(&min_omega(&shots[1..]))?;
    if s * (shots[3].0 - r2) <= 0.0 {
        return Err(format!(
            "the root u = {r2} of min omega_l is not beyond the slipping cycles' side"
        ));
    }
    Ok((r1, r2, shots))
}

/// The fit from shots at `u_g + s·4δ`, `+ s·2δ`, `+ s·δ`, each from the state of the
/// continuation row `slips` nearest in u (at a non-smooth fold the stick-slip cycle lies as
/// close to the grazing orbit as the slipping one, so a start from the grazing orbit itself
/// could reach either).
fn fit_at_offsets(
    sh: &Shooting,
    ug: f64,
    s: f64,
    slips: &[&PeriodicRow],
    delta: f64,
) -> Result<Fit, String> {
    let mut shots: Vec<Shot> = Vec::new();
    for d in [4.0, 2.0, 1.0] {
        let u = ug + s * d * delta;
        let row = slips
            .iter()
            .min_by(|a, b| (a.u - u).abs().total_cmp(&(b.u - u).abs()))
            .expect("not empty");
        shots.push(sh.slipping(u, None, row)?);
    }
    refine(sh, shots, s, delta, slips[0])
}

/// The fit from shots at the u of three continuation rows `slips` themselves (at least 1e-5 V
/// from the point, so that their min ω_l stays well above the finite-difference steps), each
/// from its own row's state: no start is off by a change of u, which a strongly unstable
/// cycle amplifies 4.65× per period (E).
fn fit_at_rows(sh: &Shooting, ug: f64, s: f64, slips: &[&PeriodicRow]) -> Result<Fit, String> {
    let rows: Vec<&PeriodicRow> = slips
        .iter()
        .copied()
        .filter(|r| (r.u - ug).abs() >= 1e-5)
        .take(3)
        .collect();
    if rows.len() < 3 {
        return Err("fewer than three slipping rows 1e-5 V or more from it".into());
    }
    let mut shots = Vec::new();
    for row in rows.iter().rev() {
        shots.push(sh.slipping(row.u, None, row)?);
    }
    let d = (rows[0].u - ug).abs();
    refine(sh, shots, s, d, rows[0])
}

/// The grazing point `u_g` of the solver's slipping cycles (on side `s`, rows `slips`):
/// [`fit_at_offsets`] with δ = 1e-4 V, or 5 % of the distance to the nearest other special
/// point of `event` (the Stribeck set's low grazing orbit lies 2.4e-4 V from its Hopf point),
/// then δ/10 and δ/100; last [`fit_at_rows`]. The errors of every try, if all fail.
fn fit_grazing(
    sh: &Shooting,
    event: &Diagram,
    ug: f64,
    s: f64,
    slips: &[&PeriodicRow],
) -> Result<Fit, String> {
    let other = event
        .points
        .iter()
        .map(|p| (p.u - ug).abs())
        .filter(|d| *d > 1e-6)
        .fold(f64::INFINITY, f64::min);
    let first = 1e-4f64.min(0.05 * other);
    // Close to a non-smooth fold whose slipping cycle is strongly unstable (the Stribeck
    // set's E, multiplier 4.65) the shots at 1e-4 V can fall onto the stick-slip cycle; δ
    // then shrinks 10× per try, down to 1e-6 V (still far above the solvers' shifts of the
    // point, ≤ 2e-7 V measured).
    let mut last_err = String::new();
    for delta in [first, first / 10.0, first / 100.0] {
        match fit_at_offsets(sh, ug, s, slips, delta) {
            Ok(v) => return Ok(v),
            Err(e) => {
                if !last_err.is_empty() {
                    last_err.push_str("; ");
                }
                last_err += &format!("delta {delta:e}: {e}");
            }
        }
    }
    fit_at_rows(sh, ug, s, slips)
        .map_err(|e| last_err + &format!("; at the continuation's rows: {e}"))
}

/// The continuation's grazing orbit `g` located again by solver `kind` (see the module docs):
/// the solver's grazing point, and with a non-smooth fold its discontinuous fold too.
fn grazing(
    kind: SolverKind,
    model: &Model,
    event: &Diagram,
    g: &SpecialPoint,
    opts: &BySolverOptions,
) -> Result<Vec<SpecialPoint>, String> {
    let solver = kind.solver();
    let sh = Shooting {
        kind,
        solver: &*solver,
        model,
        opts,
    };
    let ug = g.u;
    let (slips, sticks) = beside(event, ug);
    if slips.is_empty() {
        return Err("no slipping cycle of the continuation beside it".into());
    }
    let s = (slips[0].u - ug).signum();
    let (r1, r2, shots) = fit_grazing(&sh, event, ug, s, &slips)?;
    let stick_slip = sh.stick_slip(&sticks)?;
    Ok(grazing_points(ug, s, (r1, r2), &shots[3], &stick_slip))
}

/// The grazing point at `r2` (residual `|r2 − r1|`) from the solver's slipping cycle `slip`
/// (on side `s` of `u_g`) and its stick-slip cycle `stick_slip`, typed by Feigin's rule:
/// σ⁺ (slipping) + σ⁺ (stick-slip) odd is a non-smooth fold, also written as a discontinuous
/// fold point; even is persistence. Whether the stick-slip cycle's side fits the type is said.
fn grazing_points(
    ug: f64,
    s: f64,
    (r1, r2): (f64, f64),
    slip: &Shot,
    stick_slip: &Shot,
) -> Vec<SpecialPoint> {
    let (u_slip, slip_row, slip_orbit) = slip;
    let (u_ss, ss_row, ss_orbit) = stick_slip;
    let s2 = (u_ss - ug).signum();
    let (p_slip, m_slip) = sigma(&slip_orbit.multipliers);
    let (p_ss, m_ss) = sigma(&ss_orbit.multipliers);
    let kind = if (p_slip + p_ss) % 2 == 1 {
        GrazingType::NonsmoothFold
    } else {
        GrazingType::Persistence
    };
    let same_side = s2 == s;
    let check = match (kind, same_side) {
        (GrazingType::NonsmoothFold, true) | (GrazingType::Persistence, false) => "",
        _ => "; NOTE: the side of the stick-slip cycle does not fit the classification",
    };
    let fmt = |m: &[[f64; 2]]| {
        m.iter()
            .map(|z| format!("{:.6}", z[0]))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let counts = format!(
        "Feigin: sigma+ = {p_slip} + {p_ss}, sigma- = {m_slip} + {m_ss} (slipping + \
         stick-slip); multipliers {} (slipping, at u = {}), {} (stick-slip, at u = {u_ss}, \
         stick time {:.3e} s){check}",
        fmt(&slip_orbit.multipliers),
        u_slip,
        fmt(&ss_orbit.multipliers),
        ss_row.stick_time
    );
    let mut p = SpecialPoint::new(
        PointKind::Grazing,
        r2,
        format!(
            "{}: the solver's slipping cycle touches omega_l = 0; {counts}",
            kind.as_str()
        ),
    );
    p.period = Some(slip_row.period);
    p.omega_l_max = Some(slip_row.omega_l_max);
    p.omega_l_min = Some(0.0);
    p.residual = Some((r2 - r1).abs());
    p.condition = Some(GRAZING_CONDITION);
    p.grazing_type = Some(kind);
    p.period_doubling = Some((m_slip + m_ss) % 2 == 1);
    p.sigma_plus = Some([p_slip, p_ss]);
    p.sigma_minus = Some([m_slip, m_ss]);
    p.slipping_multipliers = Some(pair(&slip_orbit.multipliers));
    p.stick_slip_multipliers = Some(pair(&ss_orbit.multipliers));
    let mut out = vec![p.clone()];
    if kind == GrazingType::NonsmoothFold {
        p.kind = PointKind::Fold;
        p.discontinuous = Some(true);
        p.detail = format!(
            "discontinuous fold: the solver's slipping and stick-slip branches meet at its \
             grazing orbit, both {} it; {counts}",
            if s > 0.0 { "above" } else { "below" }
        );
        out.push(p);
    }
    out
}

fn smooth_fold(
    kind: SolverKind,
    model: &Model,
    f: &SpecialPoint,
    opts: &BySolverOptions,
) -> Result<Vec<SpecialPoint>, String> {
    let solver = &*kind.solver();
    let x = f
        .section_state
        .ok_or("the continuation gives no state on the fold's cycle")?;
    let period = f
        .period
        .ok_or("the continuation gives no period of the fold's cycle")?;
    let sc = opts.scene(kind, f.u);
    let section = if f.omega_l_min.is_some_and(|m| m > 0.0) {
        Section::LowerMax
    } else {
        Section::StickExit
    };
    let mut z = first_crossing(solver, model, &sc, x, period, section)?;
    let fix = z.len() - 1;
    let mut s0 = z[fix];
    let so = shoot_opts(period);
    let mut u_of = |s: f64, u0: f64| -> Result<crate::shoot::OrbitAtU, String> {
        let mut zs = z.clone();
        zs[fix] = s;
        let r = shoot_with_u(solver, model, &opts.scene(kind, u0), section, &zs, fix, &so)
            .map_err(|e| format!("at {} = {s}: {e}", section.as_str()))?;
        z = r.orbit.z.clone();
        Ok(r)
    };
    let mut d = 2e-3 * (1.0 + s0.abs());
    let mut u_est = f.u;
    let mut change = f64::NAN;
    let mut turn = 0.0;
    for _ in 0..3 {
        let um = u_of(s0 - d, u_est)?.u;
        let uc = u_of(s0, u_est)?.u;
        let up = u_of(s0 + d, u_est)?.u;
        // u ≈ uc + b t + a t² with t = s − s0.
        let a = (up + um - 2.0 * uc) / (2.0 * d * d);
        let b = (up - um) / (2.0 * d);
        if a == 0.0 || !a.is_finite() {
            return Err(format!("u does not turn at {} near {s0}", section.as_str()));
        }
        let t = -b / (2.0 * a);
        turn = a;
        let vertex = uc - b * b / (4.0 * a);
        change = (vertex - u_est).abs();
        s0 += t;
        u_est = vertex;
        d /= 4.0;
    }
    let at = u_of(s0, u_est)?;
    let crit = at
        .orbit
        .multipliers
        .iter()
        .min_by(|p, q| {
            (p[0] - 1.0)
                .hypot(p[1])
                .total_cmp(&(q[0] - 1.0).hypot(q[1]))
        })
        .copied()
        .unwrap_or([f64::NAN, 0.0]);
    let row = row_of(solver, model, &opts.scene(kind, at.u), &at.orbit, 0)?;
    let mut p = SpecialPoint::new(
        PointKind::Fold,
        u_est,
        format!(
            "smooth fold: extremum of u along the solver's branch ({} at {} = {s0:.9}); \
             critical multiplier {:.6} {:+.1e}i (1 at a fold; finite differences of the map \
             with u shot {:.1e} V from the vertex)",
            if turn < 0.0 { "maximum" } else { "minimum" },
            section.as_str(),
            crit[0],
            crit[1],
            (at.u - u_est).abs()
        ),
    );
    p.discontinuous = Some(false);
    p.period = Some(row.period);
    p.omega_l_max = Some(row.omega_l_max);
    p.omega_l_min = Some(row.omega_l_min);
    p.residual = Some(change);
    p.condition = Some(FOLD_CONDITION);
    p.section_state = Some([at.orbit.x[0], at.orbit.x[1], at.orbit.x[2]]);
    Ok(vec![p])
}

/// Stability changes between consecutive re-shot rows of one branch that no fold, grazing or
/// Hopf point explains (see the module docs).
pub(crate) fn stability_changes(
    rows: &[PeriodicRow],
    points: &[SpecialPoint],
) -> Vec<SpecialPoint> {
    let mut out = Vec::new();
    for w in rows.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a.branch != b.branch || a.stable == b.stable {
            continue;
        }
        let pad = (a.u - b.u).abs().max(0.05);
        let (lo, hi) = (a.u.min(b.u) - pad, a.u.max(b.u) + pad);
        let explained = points.iter().any(|p| {
            matches!(
                p.kind,
                PointKind::Fold | PointKind::Grazing | PointKind::Hopf
            ) && (lo..=hi).contains(&p.u)
        });
        if !explained {
            let mut p = SpecialPoint::new(
                PointKind::StabilityChange,
                0.5 * (a.u + b.u),
                format!(
                    "the solver's cycles change stability between u = {} and {} (not refined)",
                    a.u, b.u
                ),
            );
            p.period = Some(0.5 * (a.period + b.period));
            out.push(p);
        }
    }
    out
}
