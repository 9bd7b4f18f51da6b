//! Periodic orbits of any solver by shooting on its Poincaré return map.
//!
//! A solver is only its [`Solver::simulate`]: the map is read off the events of a run, so
//! the same Newton iteration serves the event-driven solver, the switch model and
//! Moreau–Jean, and each answers with its own discretisation (the solvers still share no
//! integration code; this sits above the seam, as the recorder does).
//!
//! **Sections.** A cycle on which the lower disc sticks is cut at its stick exit: there
//! `ω_l = 0` and the spring holds the static bound, `k_θ α = T_hi` (the lower disc's stick
//! interval `[T_lo, T_hi]`), so the section is one-dimensional, `z = ω_u`, and the return
//! map `P(z)` is the upper disc's velocity at the next stick exit. A slipping cycle is cut at
//! a maximum of `ω_l`: there `ω̇_l = 0`, i.e. `k_θ α = T_fl(ω_l)`, so `z = (ω_u, ω_l)` and
//! `α` follows. [`Section::of_run`] picks the section from a run near the orbit.
//!
//! **Newton.** `z ← z − (DP − I)⁻¹ (P(z) − z)`, `DP` by forward differences of the solver's
//! own map (step `fd_rel·(1 + |z|)`), halving a step that does not reduce the residual. It
//! finds a fixed point whether the orbit is stable or not. At the fixed point, `DP` by central
//! differences gives the nontrivial Floquet multipliers (the other two are 1, along the
//! flow, and 0 on a stick-slip cycle, whose stick phase collapses `α` and `ω_l`); the orbit
//! is stable when all lie inside the unit circle.
//!
//! Newton converges from a start within a fraction of the cycle's size. Next to a Hopf point
//! the cycle is small: a start off by more than its amplitude can land on another fixed point
//! of the map (one 1 % off at 4e-5 V above H1 did), so a start there comes from a run near
//! the cycle or from the continuation's restart state.
//!
//! ```no_run
//! # fn f(solver: &dyn rotor_model::seam::Solver) -> Result<(), rotor_analysis::shoot::ShootError> {
//! use rotor_model::{Model, State};
//! use rotor_model::seam::Scene;
//! let model = Model::table1();
//! let scene = Scene { u: 1.5, ..Scene::with_tol(1e-10) };
//! let (section, z) = rotor_analysis::shoot::Section::of_run(solver, &model, &scene, State::zeros(), 200.0)?;
//! let orbit = rotor_analysis::shoot::shoot(solver, &model, &scene, section, &z, &Default::default())?;
//! println!("T = {} s, stable: {}", orbit.period, orbit.is_stable());
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

use rotor_model::seam::{EventKind, Output, Scene, SolveError, Solver};
use rotor_model::{Disc, Model, OMEGA_L, OMEGA_U, State};

/// Where a cycle is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    /// The lower disc's stick exit: `z = [ω_u]`.
    StickExit,
    /// A maximum of `ω_l` (a slipping cycle): `z = [ω_u, ω_l]`.
    LowerMax,
}

impl Section {
    /// What the section is, for messages (`"stick exit of the lower disc"`,
    /// `"maximum of omega_l"`).
    pub fn as_str(self) -> &'static str {
        match self {
            Section::StickExit => "stick exit of the lower disc",
            Section::LowerMax => "maximum of omega_l",
        }
    }

    fn event(self) -> EventKind {
        match self {
            Section::StickExit => EventKind::StickEnd(Disc::LOWER),
            Section::LowerMax => EventKind::Max(Disc::LOWER),
        }
    }

    /// The section's coordinates of a state on it.
    fn project(self, x: &State) -> Vec<f64> {
        match self {
            Section::StickExit => vec![x[OMEGA_U]],
            Section::LowerMax => vec![x[OMEGA_U], x[OMEGA_L]],
        }
    }

    /// The state of section coordinates `z`.
    pub fn lift(self, model: &Model, z: &[f64]) -> State {
        let k = model.params.k_theta;
        match self {
            Section::StickExit => {
                let (_, hi) = model.friction(Disc::LOWER).static_interval();
                State::new(hi / k, z[0], 0.0)
            }
            Section::LowerMax => {
                let w = z[1];
                let s = if w < 0.0 { -1.0 } else { 1.0 };
                let t = model.friction(Disc::LOWER).torque(w, s);
                State::new(t / k, z[0], w)
            }
        }
    }

    /// The section of the orbit a run from `x0` settles to, and the section coordinates of
    /// its last crossing in `[0, t_end]`: a start for [`shoot`]. `None` (an error) when the run
    /// neither sticks nor has a maximum of `ω_l` over its second half (an equilibrium).
    pub fn of_run(
        solver: &dyn Solver,
        model: &Model,
        scene: &Scene,
        x0: State,
        t_end: f64,
    ) -> Result<(Section, Vec<f64>), ShootError> {
        let run = solver.simulate_finite(
            model,
            &Scene {
                x0: x0.as_slice().to_vec(),
                t_end,
                output: Output::Events,
                metrics_from: Some(0.5 * t_end),
                ..scene.clone()
            },
        )?;
        for section in [Section::StickExit, Section::LowerMax] {
            if let Some(e) = run
                .events
                .iter()
                .rev()
                .find(|e| e.kind == section.event() && e.t >= 0.5 * t_end)
            {
                return Ok((section, section.project(&e.state())));
            }
        }
        Err(ShootError::NotACycle { t_end })
    }
}

/// Options of [`shoot`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShootOptions {
    /// Newton iterations at most.
    pub max_iter: usize,
    /// Converged when `|P(z) − z|∞ ≤ tol·(1 + |z|∞)` [rad/s, relative]. 1e-9 is within every
    /// solver's own map at the comparisons' settings (tol 1e-10, h = 1e-3), which differ from
    /// each other by far more.
    pub tol: f64,
    /// Relative finite-difference step for `DP`. 1e-6: the map's rounding (≈ the solver's
    /// tolerance, 1e-10) over the step stays ≤ 1e-4 of the derivative, and the truncation
    /// error (≈ step·|P''|) is as small.
    pub fd_rel: f64,
    /// Longest return time \[s\]; the periods here are 4–6 s.
    pub horizon: f64,
    /// Crossings earlier than this after the start \[s\] are the start itself (a solver may
    /// report the stick exit it starts on).
    pub skip: f64,
}

impl Default for ShootOptions {
    fn default() -> Self {
        ShootOptions {
            max_iter: 30,
            tol: 1e-9,
            fd_rel: 1e-6,
            horizon: 60.0,
            skip: 0.1,
        }
    }
}

/// A periodic orbit found by [`shoot`].
#[derive(Debug, Clone, PartialEq)]
pub struct Orbit {
    /// The section the orbit was cut at; `z` is in its coordinates.
    pub section: Section,
    /// The fixed point's section coordinates.
    pub z: Vec<f64>,
    /// The state there.
    pub x: State,
    /// The return time \[s\].
    pub period: f64,
    /// The nontrivial Floquet multipliers `[re, im]` (eigenvalues of `DP` at the fixed point).
    pub multipliers: Vec<[f64; 2]>,
    /// `|P(z) − z|∞` at the fixed point.
    pub residual: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Runs of the solver it took.
    pub runs: usize,
}

impl Orbit {
    /// Whether every multiplier lies inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.multipliers.iter().all(|m| m[0].hypot(m[1]) < 1.0)
    }
}

/// Why no orbit was found.
#[derive(Debug, thiserror::Error)]
pub enum ShootError {
    /// A run of the solver failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A run from a point on the section did not come back to it within the horizon.
    #[error("no {what} within {horizon} s of the start at z = {z:?}: the orbit left the section")]
    NoReturn {
        /// The section ([`Section::as_str`]).
        what: &'static str,
        /// [`ShootOptions::horizon`] \[s\].
        horizon: f64,
        /// The section coordinates the run started from.
        z: Vec<f64>,
    },
    /// Newton ran out of iterations.
    #[error(
        "Newton did not converge in {iterations} iterations: residual {residual:e} at z = {z:?}"
    )]
    NoConvergence {
        /// [`ShootOptions::max_iter`].
        iterations: usize,
        /// `|P(z) − z|∞` at the last iterate.
        residual: f64,
        /// The last iterate's section coordinates.
        z: Vec<f64>,
    },
    /// Newton's matrix is singular: `DP − I` for [`shoot`], `[∂P/∂z' − I', ∂P/∂u]` for
    /// [`shoot_with_u`].
    #[error("DP − I is singular at z = {z:?} (a multiplier at 1: a fold or a Hopf point)")]
    Singular {
        /// The iterate's section coordinates.
        z: Vec<f64>,
    },
    /// [`Section::of_run`] found no crossing of either section in the run's second half.
    #[error(
        "the run settles to no cycle by t = {t_end} s (no stick exit and no maximum of omega_l in its second half)"
    )]
    NotACycle {
        /// The run's horizon \[s\].
        t_end: f64,
    },
}

/// The first run's horizon before any return is known \[s\]: two of the longest periods
/// here (4–6 s) and a margin, a fifth of the default horizon.
const FIRST_WINDOW: f64 = 12.0;

/// How long before a run's end a return must lie to be the full horizon's return \[s\]. A
/// run's last step may be shortened to land on its end, and an extremum is located from the
/// steps around it, so events in the last steps of a short run can differ from a longer
/// run's; 1 s is a thousand of Moreau–Jean's steps at h = 1e-3 and more than any adaptive
/// step of the switch model or the event-driven solver at the shooting's tolerances.
const END_MARGIN: f64 = 1.0;

/// The return map of one solver on one section.
struct Map<'a> {
    solver: &'a dyn Solver,
    model: &'a Model,
    scene: Scene,
    section: Section,
    opts: ShootOptions,
    runs: usize,
    /// The last return time found.
    last_return: Option<f64>,
}

impl<'a> Map<'a> {
    /// The return map of `solver` on `section` at `scene` (its u and accuracy), before any run.
    fn new(
        solver: &'a dyn Solver,
        model: &'a Model,
        scene: &Scene,
        section: Section,
        opts: &ShootOptions,
    ) -> Map<'a> {
        Map {
            solver,
            model,
            scene: scene.clone(),
            section,
            opts: *opts,
            runs: 0,
            last_return: None,
        }
    }

    /// `P(z)` and the return time. Once one return is known, a run covers 1.5× its time (a
    /// run to the full horizon would integrate ten periods to use one); before that, a run
    /// covers [`FIRST_WINDOW`], and a return found there at least [`END_MARGIN`] before its
    /// end is taken: the steps before that are the full horizon's own, so the return is the
    /// one the full run would find. A return not found there is looked for over the whole
    /// horizon.
    fn at(&mut self, z: &[f64]) -> Result<(Vec<f64>, f64), ShootError> {
        if let Some(t) = self.last_return {
            let short = (1.5 * t + self.opts.skip).min(self.opts.horizon);
            if let Some(found) = self.run(z, short)? {
                return Ok(found);
            }
        } else if FIRST_WINDOW < self.opts.horizon
            && let Some(found) = self.run(z, FIRST_WINDOW)?
            && found.1 <= FIRST_WINDOW - END_MARGIN
        {
            self.last_return = Some(found.1);
            return Ok(found);
        }
        let found = self
            .run(z, self.opts.horizon)?
            .ok_or_else(|| ShootError::NoReturn {
                what: self.section.as_str(),
                horizon: self.opts.horizon,
                z: z.to_vec(),
            })?;
        self.last_return = Some(found.1);
        Ok(found)
    }

    /// The first return within `t_end`, if any.
    fn run(&mut self, z: &[f64], t_end: f64) -> Result<Option<(Vec<f64>, f64)>, ShootError> {
        self.runs += 1;
        let run = self.solver.simulate_finite(
            self.model,
            &Scene {
                x0: self.section.lift(self.model, z).as_slice().to_vec(),
                t_end,
                output: Output::Events,
                // Extrema are reported when metrics are asked.
                metrics_from: Some(0.0),
                ..self.scene.clone()
            },
        )?;
        Ok(run
            .events
            .iter()
            .find(|e| e.kind == self.section.event() && e.t > self.opts.skip)
            .map(|e| (self.section.project(&e.state()), e.t)))
    }

    /// The orbit through the fixed point `z` (`P(z)` in `pz`, residual `r` after `iterations`
    /// Newton steps), its multipliers from `DP` by central differences.
    fn orbit(
        &mut self,
        z: Vec<f64>,
        pz: &[f64],
        period: f64,
        r: f64,
        iterations: usize,
    ) -> Result<Orbit, ShootError> {
        let j = self.jacobian(&z, pz, true)?;
        Ok(Orbit {
            section: self.section,
            x: self.section.lift(self.model, &z),
            z,
            period,
            multipliers: eigenvalues(&j),
            residual: r,
            iterations,
            runs: self.runs,
        })
    }

    /// `DP(z)` by forward (`central = false`) or central differences, given `P(z)`.
    fn jacobian(
        &mut self,
        z: &[f64],
        pz: &[f64],
        central: bool,
    ) -> Result<Vec<Vec<f64>>, ShootError> {
        let n = z.len();
        let mut j = vec![vec![0.0; n]; n];
        let scale = 1.0 + z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = self.opts.fd_rel * scale;
        for c in 0..n {
            let mut zp = z.to_vec();
            zp[c] += d;
            let (pp, _) = self.at(&zp)?;
            let (pm, dd) = if central {
                let mut zm = z.to_vec();
                zm[c] -= d;
                (self.at(&zm)?.0, 2.0 * d)
            } else {
                (pz.to_vec(), d)
            };
            for r in 0..n {
                j[r][c] = (pp[r] - pm[r]) / dd;
            }
        }
        Ok(j)
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Solves `(J − I) s = r` for n ≤ 2; `None` when singular.
fn solve_shifted(j: &[Vec<f64>], r: &[f64]) -> Option<Vec<f64>> {
    match j.len() {
        1 => {
            let a = j[0][0] - 1.0;
            (a.abs() > 1e-12).then(|| vec![r[0] / a])
        }
        2 => {
            let (a, b, c, d) = (j[0][0] - 1.0, j[0][1], j[1][0], j[1][1] - 1.0);
            let det = a * d - b * c;
            let size = a.abs().max(b.abs()).max(c.abs()).max(d.abs());
            (det.abs() > 1e-12 * size * size.max(1.0))
                .then(|| vec![(d * r[0] - b * r[1]) / det, (a * r[1] - c * r[0]) / det])
        }
        _ => None,
    }
}

/// Eigenvalues `[re, im]` of a 1×1 or 2×2 matrix, by decreasing modulus.
fn eigenvalues(j: &[Vec<f64>]) -> Vec<[f64; 2]> {
    match j.len() {
        1 => vec![[j[0][0], 0.0]],
        _ => {
            let (tr, det) = (j[0][0] + j[1][1], j[0][0] * j[1][1] - j[0][1] * j[1][0]);
            let disc = 0.25 * tr * tr - det;
            let mut v = if disc >= 0.0 {
                let s = disc.sqrt();
                vec![[0.5 * tr + s, 0.0], [0.5 * tr - s, 0.0]]
            } else {
                let s = (-disc).sqrt();
                vec![[0.5 * tr, s], [0.5 * tr, -s]]
            };
            v.sort_by(|a, b| b[0].hypot(b[1]).total_cmp(&a[0].hypot(a[1])));
            v
        }
    }
}

/// The periodic orbit through the section near `z0`, by Newton on the solver's return map
/// (see the crate docs). `scene` gives u and the solver's own accuracy (`tol` or `h`); its
/// start, horizon and output are the shooting's.
pub fn shoot(
    solver: &dyn Solver,
    model: &Model,
    scene: &Scene,
    section: Section,
    z0: &[f64],
    opts: &ShootOptions,
) -> Result<Orbit, ShootError> {
    let mut map = Map::new(solver, model, scene, section, opts);
    let mut z = z0.to_vec();
    let (mut pz, mut period) = map.at(&z)?;
    let resid =
        |z: &[f64], pz: &[f64]| norm(&pz.iter().zip(z).map(|(p, q)| p - q).collect::<Vec<_>>());
    let mut r = resid(&z, &pz);
    for it in 0..=opts.max_iter {
        if r <= opts.tol * (1.0 + norm(&z)) {
            return map.orbit(z, &pz, period, r, it);
        }
        if it == opts.max_iter {
            break;
        }
        let j = map.jacobian(&z, &pz, false)?;
        let rhs: Vec<f64> = pz.iter().zip(&z).map(|(p, q)| p - q).collect();
        let step = solve_shifted(&j, &rhs).ok_or_else(|| ShootError::Singular { z: z.clone() })?;
        // z − (DP − I)⁻¹ (P(z) − z), halved while the residual does not fall.
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = z.iter().zip(&step).map(|(a, s)| a - lambda * s).collect();
            let next = map.at(&trial);
            if let Ok((pt, tt)) = next {
                let rt = resid(&trial, &pt);
                if rt < r || lambda < 1.0 / 64.0 {
                    (z, pz, period, r) = (trial, pt, tt, rt);
                    break;
                }
            } else if lambda < 1.0 / 64.0 {
                return Err(next.unwrap_err());
            }
            lambda *= 0.5;
        }
    }
    Err(ShootError::NoConvergence {
        iterations: opts.max_iter,
        residual: r,
        z,
    })
}

/// A periodic orbit found by [`shoot_with_u`]: the orbit and the input it is at.
#[derive(Debug, Clone, PartialEq)]
pub struct OrbitAtU {
    /// The input u \[V\] solved for.
    pub u: f64,
    /// The orbit at that u; its multipliers are those of `DP` at fixed u.
    pub orbit: Orbit,
}

/// Solves `A s = r` for n ≤ 2; `None` when singular.
fn solve_small(a: &[Vec<f64>], r: &[f64]) -> Option<Vec<f64>> {
    match a.len() {
        1 => (a[0][0].abs() > 1e-300).then(|| vec![r[0] / a[0][0]]),
        2 => {
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            let size = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            (det.abs() > 1e-14 * size * size).then(|| {
                vec![
                    (a[1][1] * r[0] - a[0][1] * r[1]) / det,
                    (a[0][0] * r[1] - a[1][0] * r[0]) / det,
                ]
            })
        }
        _ => None,
    }
}

/// The periodic orbit through the section with section coordinate `fix` held at `z0[fix]`
/// and the input u free: Newton on `F(z', u) = P(z; u) − z = 0` in the other coordinates `z'`
/// and u, its Jacobian `[∂P/∂z' − I', ∂P/∂u]` by forward differences of the solver's own map
/// (steps `fd_rel·(1 + |z|∞)` and `fd_rel·(1 + |u|)`), halving a step that does not reduce the
/// residual; converged at `|F|∞ ≤ tol·(1 + |z|∞)`.
///
/// Where the branch turns back in u (a fold, `det(∂P/∂z − I) = 0`), [`shoot`] at fixed u is
/// singular, but this system stays regular as long as the branch is not tangent to the
/// hyperplane `z[fix] = const`: u as a function of `z[fix]` has its extremum at the fold.
pub fn shoot_with_u(
    solver: &dyn Solver,
    model: &Model,
    scene: &Scene,
    section: Section,
    z0: &[f64],
    fix: usize,
    opts: &ShootOptions,
) -> Result<OrbitAtU, ShootError> {
    let n = z0.len();
    assert!(
        fix < n,
        "fix = {fix} is not a coordinate of a {n}-dimensional section"
    );
    let mut map = Map::new(solver, model, scene, section, opts);
    let free: Vec<usize> = (0..n).filter(|&c| c != fix).collect();
    let mut z = z0.to_vec();
    let mut u = scene.u;
    let eval = |map: &mut Map, z: &[f64], u: f64| {
        map.scene.u = u;
        map.at(z)
    };
    let (mut pz, mut period) = eval(&mut map, &z, u)?;
    let f = |z: &[f64], pz: &[f64]| pz.iter().zip(z).map(|(p, q)| p - q).collect::<Vec<_>>();
    let mut r = norm(&f(&z, &pz));
    for it in 0..=opts.max_iter {
        if r <= opts.tol * (1.0 + norm(&z)) {
            map.scene.u = u;
            let orbit = map.orbit(z, &pz, period, r, it)?;
            return Ok(OrbitAtU { u, orbit });
        }
        if it == opts.max_iter {
            break;
        }
        // Columns: the free coordinates, then u.
        let fz = f(&z, &pz);
        let dz = opts.fd_rel * (1.0 + norm(&z));
        let du = opts.fd_rel * (1.0 + u.abs());
        let mut a = vec![vec![0.0; n]; n];
        for (col, &c) in free.iter().enumerate() {
            let mut zp = z.clone();
            zp[c] += dz;
            let (pp, _) = eval(&mut map, &zp, u)?;
            let fp = f(&zp, &pp);
            for row in 0..n {
                a[row][col] = (fp[row] - fz[row]) / dz;
            }
        }
        let (pu, _) = eval(&mut map, &z, u + du)?;
        let fu = f(&z, &pu);
        for row in 0..n {
            a[row][n - 1] = (fu[row] - fz[row]) / du;
        }
        let step = solve_small(&a, &fz).ok_or_else(|| ShootError::Singular { z: z.clone() })?;
        let mut lambda = 1.0;
        loop {
            let mut trial = z.clone();
            for (col, &c) in free.iter().enumerate() {
                trial[c] -= lambda * step[col];
            }
            let ut = u - lambda * step[n - 1];
            let next = eval(&mut map, &trial, ut);
            if let Ok((pt, tt)) = next {
                let rt = norm(&f(&trial, &pt));
                if rt < r || lambda < 1.0 / 64.0 {
                    (z, u, pz, period, r) = (trial, ut, pt, tt, rt);
                    break;
                }
            } else if lambda < 1.0 / 64.0 {
                return Err(next.unwrap_err());
            }
            lambda *= 0.5;
        }
    }
    Err(ShootError::NoConvergence {
        iterations: opts.max_iter,
        residual: r,
        z,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_solves_and_eigenvalues() {
        let j = vec![vec![0.5, 0.2], vec![-0.1, 0.3]];
        let s = solve_shifted(&j, &[1.0, 2.0]).unwrap();
        // (J − I) s = r
        assert!(((j[0][0] - 1.0) * s[0] + j[0][1] * s[1] - 1.0).abs() < 1e-14);
        assert!((j[1][0] * s[0] + (j[1][1] - 1.0) * s[1] - 2.0).abs() < 1e-14);
        assert!(solve_shifted(&[vec![1.0]], &[1.0]).is_none());
        // A rotation by 0.3 rad scaled by 0.9: a complex pair of modulus 0.9.
        let (c, s) = (0.9 * 0.3f64.cos(), 0.9 * 0.3f64.sin());
        let ev = eigenvalues(&[vec![c, -s], vec![s, c]]);
        for e in &ev {
            assert!((e[0].hypot(e[1]) - 0.9).abs() < 1e-14);
        }
        assert!(ev[0][1] != 0.0);
        let real = eigenvalues(&[vec![2.0, 0.0], vec![0.0, -0.5]]);
        assert_eq!(real, vec![[2.0, 0.0], [-0.5, 0.0]]);
    }
}
