//! One Moreau–Jean step: θ-scheme on the Lagrangian form, friction level inside the Newton
//! loop (or explicit), one-step problem solved by exact enumeration.
//!
//! With `v = [ω_u, ω_l]` (the θ-block of q̇), `α = θ_u − θ_l`, and per disc i the smooth
//! friction force `g_i` and level `N_i` (see the crate docs), the step from `(α, v)` is
//!
//! ```text
//! M̂ v⁺ = b + hθ g(v⁺) + r,     M̂ = M + θhC + θ²h²K
//! b    = (M − (1−θ)hC − θ(1−θ)h²K) v − hK q + h F_ext + h(1−θ) g(v)
//! Coulomb: |r_i| ≤ P_i = h[(1−θ) N_i⁺(ω_i) + θ N_i⁺(ω_i⁺)]   (implicit level)
//!                  P_i = h N_i⁺(ω_i)                          (explicit level)
//! α⁺   = α + h[(1−θ)(ω_u − ω_l) + θ(ω_u⁺ − ω_l⁺)]
//! ```
//!
//! (`Kq = k_θ[α, −α]`, so only α is needed.) Newton on the step: at the iterate `w`, every
//! velocity-dependent term of a slip branch is linearised in the disc's own velocity, the
//! resulting piecewise-linear problem is solved exactly by [`OneStepProblem::solve`], and the
//! iteration stops when the mode repeats and the iterate's error is below `1e-12·(1 + |w|)`:
//! the update itself is, or the quadratic-convergence estimate of the next update is, or the
//! linearisation is exact (`Stepper::converged`) — a semi-smooth Newton method,
//! quadratic once the mode is settled.

use nalgebra::{Matrix2, Vector2};
use rotor_model::seam::SolveError;
use rotor_model::{Disc, DiscMode, Friction, Model, State};

use crate::onestep::{Branch, OneStepProblem, OneStepSolution, StickData};
use crate::{FrictionLevel, MoreauOptions};

/// Result of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// State `[α, ω_u, ω_l]` at the end of the step.
    pub x: State,
    /// Contact mode of each disc over the step (upper, lower).
    pub mode: [DiscMode; 2],
    /// Tangential contact impulses `r_T` (upper, lower).
    pub r: Vector2<f64>,
    /// Cone bounds `μ r_N = P_i` (upper, lower).
    pub p: Vector2<f64>,
    /// Whether the enumeration was run (`false`: the slip prediction was verified directly).
    pub used_enumeration: bool,
    /// Whether the step problem was solved exactly (Newton or Picard converged). `false`
    /// only for very large h with a falling friction level, where the step problem may have
    /// no or several solutions; the last Picard iterate is then taken.
    pub exact: bool,
    /// Whether Newton failed and the Picard fallback ran (`exact` then says whether it
    /// converged).
    pub picard: bool,
    /// Newton iterations (one linearised solve each).
    pub newton_iters: u32,
    /// Evaluations of the smooth friction forces and levels (one per disc and branch).
    pub evals: u32,
}

/// The smooth friction of one disc along branch s, its level, and their ω-derivatives.
#[derive(Debug, Clone, Copy, Default)]
struct BranchEval {
    /// Smooth offset force `−a^s(ω)` (enters the right-hand side).
    off: f64,
    d_off: f64,
    /// Level `N^s(ω) = level_ext(sω)`.
    level: f64,
    d_level: f64,
}

#[inline(always)]
fn eval_branch(f: &Friction, db: f64, w: f64, s: f64) -> BranchEval {
    let (level, slope) = f.level_ext_with_slope(s * w);
    BranchEval {
        off: -f.offset(w, s),
        d_off: -s * db,
        level,
        d_level: s * slope,
    }
}

/// What the slip branches of one step are built from: the step's constants and the
/// friction evaluations at the start velocity.
/// Counters of one step: friction evaluations and Newton (or Picard) iterations.
#[derive(Default)]
struct Counts {
    evals: u32,
    newton: u32,
}

/// The start-of-step terms of a step ([`Stepper::start_terms`]).
struct StartTerms {
    b: Vector2<f64>,
    p_start: [f64; 2],
    stick: [StickData; 2],
    start: [(f64, BranchEval); 2],
}

struct BranchCtx<'a> {
    stepper: &'a Stepper,
    /// `hθ`.
    ht: f64,
    implicit: bool,
    p_start: [f64; 2],
    v: Vector2<f64>,
    /// Branch sign and evaluation at the start velocity, per disc.
    start: [(f64, BranchEval); 2],
}

impl BranchCtx<'_> {
    /// The affine slip branch of disc i, sign s, linearised at w, from the friction
    /// evaluation `e` of that branch at w.
    #[inline(always)]
    fn affine(&self, i: usize, s: f64, w: f64, e: BranchEval) -> Branch {
        let ht = self.ht;
        // Total friction impulse φ(ω) = hθ·smooth(ω) − s·P(ω).
        let (mut phi, mut dphi) = (ht * e.off, ht * e.d_off);
        let (mut p, mut dp) = (self.p_start[i], 0.0);
        if self.implicit {
            if e.level > 0.0 {
                p += ht * e.level;
                dp = ht * e.d_level;
            } else {
                phi += -s * ht * e.level;
                dphi += -s * ht * e.d_level;
            }
        }
        phi -= s * p;
        dphi -= s * dp;
        Branch {
            c: phi - dphi * w,
            d: dphi,
            pc: p - dp * w,
            pd: dp,
        }
    }

    /// The branch of disc i, sign s, at w; `evals` counts fresh evaluations only. The
    /// start evaluation serves at w = v, and at any w when the law is affine (its
    /// linearisation at v is the branch itself).
    #[inline(always)]
    fn branch(&self, i: usize, s: f64, w: f64, evals: &mut u32) -> Branch {
        let st = self.stepper;
        let (s0, e0) = self.start[i];
        if s0 == s && (st.affine_law[i] || w.to_bits() == self.v[i].to_bits()) {
            return self.affine(i, s, self.v[i], e0);
        }
        *evals += 1;
        self.affine(i, s, w, eval_branch(&st.law[i], st.db[i], w, s))
    }
}

/// The data of one step size: `h`, the iteration matrix `M̂` and `W = M̂⁻¹`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSize {
    /// Step size \[s\].
    pub h: f64,
    /// The iteration matrix `M̂ = M + θhC + θ²h²K` on the velocities `[ω_u, ω_l]`
    /// ([`Stepper::iteration_matrix`]).
    pub a: Matrix2<f64>,
    /// Its inverse `W = M̂⁻¹` (the Delassus matrix of the two contacts).
    pub w_inv: Matrix2<f64>,
}

/// Precomputed data of one run: the Lagrangian matrices' entries and the friction laws.
#[derive(Debug, Clone, Copy)]
pub struct Stepper {
    theta: f64,
    level: FrictionLevel,
    max_newton: u32,
    skip_free: bool,
    estimate_stop: bool,
    /// Whether disc i's slip branches are affine in ω (the upper disc's law, eq. (4): a
    /// constant level and the offset `ΔT_su + Δb_u|ω|`): its linearisation is then exact.
    affine_law: [bool; 2],
    j: [f64; 2],
    c: [f64; 2],
    k: f64,
    f_ext: f64,
    /// The motor constant k_m: `F_ext = k_m u` for an input other than the stepper's own.
    k_m: f64,
    law: [Friction; 2],
    db: [f64; 2],
    /// `max(N_i(0), 0)`: the half-width of disc i's stick interval.
    n_zero: [f64; 2],
    /// `−a_i(0)`: the smooth friction force on a stuck disc.
    off_zero: [f64; 2],
}

impl Stepper {
    /// The stepper of a model at input `u`. `M`, `C`, `K`, `F_ext` are read from
    /// [`rotor_model::Lagrangian`].
    pub fn new(model: &Model, u: f64, options: &MoreauOptions) -> Stepper {
        let l = rotor_model::Lagrangian::new(model);
        let db_u = model.friction(Disc::UPPER).as_upper().map_or(0.0, |p| p.db);
        Stepper {
            theta: options.theta,
            level: options.friction_level,
            max_newton: options.max_newton,
            skip_free: options.skip_free_steps,
            estimate_stop: options.newton_estimate_stop,
            affine_law: [Disc::UPPER, Disc::LOWER].map(|d| model.friction(d).as_upper().is_some()),
            j: [l.m[(0, 0)], l.m[(1, 1)]],
            c: [l.c[(0, 0)], l.c[(1, 1)]],
            k: l.k[(0, 0)],
            f_ext: l.f_ext(u)[0],
            k_m: model.params.k_m,
            law: [*model.friction(Disc::UPPER), *model.friction(Disc::LOWER)],
            db: [db_u, 0.0],
            n_zero: [Disc::UPPER, Disc::LOWER].map(|d| model.friction(d).level(0.0).max(0.0)),
            off_zero: [Disc::UPPER, Disc::LOWER].map(|d| -model.friction(d).offset(0.0, 1.0)),
        }
    }

    /// `M̂ = M + θhC + θ²h²K` on the θ-block.
    pub fn iteration_matrix(&self, h: f64) -> Matrix2<f64> {
        let th = self.theta * h;
        let kk = th * th * self.k;
        Matrix2::new(
            self.j[0] + th * self.c[0] + kk,
            -kk,
            -kk,
            self.j[1] + th * self.c[1] + kk,
        )
    }

    /// The step-size dependent data: `M̂` and its inverse (`t` only names the time in the
    /// error). Computed once per run for the constant step.
    pub(crate) fn step_size(&self, t: f64, h: f64) -> Result<StepSize, SolveError> {
        let a = self.iteration_matrix(h);
        let w_inv = a.try_inverse().ok_or_else(|| SolveError::Complementarity {
            t,
            detail: format!("singular iteration matrix at h = {h:e}"),
        })?;
        Ok(StepSize { h, a, w_inv })
    }

    /// One step of size `h` from `x` (at time `t`, for error reports).
    pub fn step(&self, t: f64, x: &State, h: f64) -> Result<StepOutcome, SolveError> {
        self.step_with(t, x, &self.step_size(t, h)?)
    }

    /// One step from `x` with the precomputed [`StepSize`], at the stepper's own input.
    pub fn step_with(&self, t: f64, x: &State, size: &StepSize) -> Result<StepOutcome, SolveError> {
        self.step_with_force(t, x, size, self.f_ext)
    }

    /// The motor torque of a time-varying input over the step `[t, t + h]`, in the
    /// θ-method's weighting: `F = k_m·((1 − θ)·u(t) + θ·u(t + h))` (for the input linear in
    /// the step, as it is between breakpoints, h·F is the θ-rule's quadrature of ∫k_m u dt,
    /// exact at θ = ½). `u(t)` and `u(t + h)` are the values on the step's own piece.
    pub fn motor_force(&self, u_start: f64, u_end: f64) -> f64 {
        if u_start == u_end {
            self.k_m * u_start
        } else {
            self.k_m * ((1.0 - self.theta) * u_start + self.theta * u_end)
        }
    }

    /// [`Stepper::step_with`] with the motor torque `f_ext` over the step
    /// ([`Stepper::motor_force`]) instead of the stepper's constant one.
    pub(crate) fn step_with_force(
        &self,
        t: f64,
        x: &State,
        size: &StepSize,
        f_ext: f64,
    ) -> Result<StepOutcome, SolveError> {
        let th = self.theta;
        let implicit = self.level == FrictionLevel::Implicit;
        let v = Vector2::new(x[1], x[2]);
        let StepSize { h, a, w_inv } = *size;
        let mut n = Counts::default();
        let st = self.start_terms(x, h, f_ext, &mut n);
        let ctx = BranchCtx {
            stepper: self,
            ht: h * th,
            implicit,
            p_start: st.p_start,
            v,
            start: st.start,
        };
        // The step problem before any slip branch is linearised into it.
        let base = OneStepProblem {
            a,
            b: st.b,
            slip: [[Branch::default(); 2]; 2],
            stick: st.stick,
        };
        let mut result = None;
        if self.skip_free && self.no_contact_can_change(&ctx, st.b, &w_inv, &mut n) {
            result = self.newton_in_slip_mode(&ctx, &base, &mut n);
        }
        let (used_enumeration, mut exact, mut picard) = (result.is_none(), true, false);
        if result.is_none() {
            result = match self.semi_smooth_newton(&ctx, &base, &mut n) {
                Ok(sol) => Some(sol),
                Err(w) => {
                    let (sol, converged) = self.picard(&base, w, h, &st.p_start, t, &mut n)?;
                    exact = converged;
                    picard = true;
                    sol
                }
            };
        }
        let sol = result.ok_or_else(|| SolveError::NoConvergence {
            detail: format!("Moreau step at t = {t}: no iterate (max_newton = 0?)"),
        })?;
        debug_assert!(
            !exact || self.check_complementarity(&sol, &st.p_start, h),
            "chosen mode violates complementarity at t = {t}: {sol:?}"
        );

        let vp = sol.v;
        let alpha = x[0] + h * ((1.0 - th) * (v[0] - v[1]) + th * (vp[0] - vp[1]));
        Ok(StepOutcome {
            x: State::new(alpha, vp[0], vp[1]),
            mode: sol.mode,
            r: sol.r,
            p: sol.p,
            used_enumeration,
            exact,
            picard,
            newton_iters: n.newton,
            evals: n.evals,
        })
    }

    /// The start-of-step terms: the right-hand side `b`, the cone bound's start part and the
    /// stick data. The friction of branch `s0 = sign(v_i)` at the start velocity is evaluated
    /// once here and reused by the skip test and by the first Newton iteration (which
    /// linearise at `w = v` on the same branch): one evaluation per disc instead of three.
    fn start_terms(&self, x: &State, h: f64, f_ext: f64, n: &mut Counts) -> StartTerms {
        let th = self.theta;
        let implicit = self.level == FrictionLevel::Implicit;
        let v = Vector2::new(x[1], x[2]);
        let kv = self.k * (v[0] - v[1]);
        let kq = self.k * x[0];
        let mut b = Vector2::new(
            (self.j[0] - (1.0 - th) * h * self.c[0]) * v[0] - th * (1.0 - th) * h * h * kv - h * kq
                + h * f_ext,
            (self.j[1] - (1.0 - th) * h * self.c[1]) * v[1] + th * (1.0 - th) * h * h * kv + h * kq,
        );
        let mut p_start = [0.0; 2];
        let mut stick = [StickData::default(); 2];
        let mut start = [(1.0, BranchEval::default()); 2];
        for i in 0..2 {
            let s0 = if v[i] < 0.0 { -1.0 } else { 1.0 };
            let e0 = eval_branch(&self.law[i], self.db[i], v[i], s0);
            start[i] = (s0, e0);
            n.evals += 1;
            // Negative part of the level, as a smooth force −sign(ω)·min(N, 0).
            let neg0 = -s0 * e0.level.min(0.0);
            let npos0 = e0.level.max(0.0);
            // The level at ω = 0 (stick): N(0) ≥ 0 is the half-width of the interval.
            let (n_zero, off_zero) = (self.n_zero[i], self.off_zero[i]);
            if implicit {
                b[i] += h * (1.0 - th) * (e0.off + neg0);
                p_start[i] = h * (1.0 - th) * npos0;
                stick[i] = StickData {
                    e: h * th * off_zero,
                    p: p_start[i] + h * th * n_zero,
                };
            } else {
                b[i] += h * (1.0 - th) * e0.off + h * neg0;
                p_start[i] = h * npos0;
                stick[i] = StickData {
                    e: h * th * off_zero,
                    p: p_start[i],
                };
            }
        }
        StartTerms {
            b,
            p_start,
            stick,
            start,
        }
    }

    /// The skip test: the frozen-bound free velocity of each disc is more than twice as far
    /// from 0 as any admissible impulse can move it.
    fn no_contact_can_change(
        &self,
        ctx: &BranchCtx,
        b: Vector2<f64>,
        w_inv: &Matrix2<f64>,
        n: &mut Counts,
    ) -> bool {
        let v = ctx.v;
        let mut rhs = b;
        let mut pmax = [0.0; 2];
        for i in 0..2 {
            if v[i] == 0.0 {
                return false;
            }
            let s = v[i].signum();
            let br = ctx.branch(i, s, v[i], &mut n.evals);
            rhs[i] += br.c + br.d * v[i] + s * (br.pc + br.pd * v[i]);
            pmax[i] = (br.pc + br.pd * v[i]).abs();
        }
        let vf = w_inv * rhs;
        (0..2).all(|i| {
            let reach = 2.0 * (w_inv[(i, 0)].abs() * pmax[0] + w_inv[(i, 1)].abs() * pmax[1]);
            vf[i] * v[i] > 0.0 && vf[i].abs() > reach
        })
    }

    /// Newton in the fixed slip mode `sign(v)`, verified at convergence: `None` if it does
    /// not converge to an admissible solution.
    fn newton_in_slip_mode(
        &self,
        ctx: &BranchCtx,
        base: &OneStepProblem,
        n: &mut Counts,
    ) -> Option<OneStepSolution> {
        let v = ctx.v;
        let s = [v[0].signum(), v[1].signum()];
        let mode = [DiscMode::slip_of(v[0]), DiscMode::slip_of(v[1])];
        let mut w = v;
        let mut dv_prev = f64::INFINITY;
        let mut prob = *base;
        for _ in 0..self.max_newton {
            n.newton += 1;
            for i in 0..2 {
                let bi = if s[i] > 0.0 { 0 } else { 1 };
                prob.slip[i][bi] = ctx.branch(i, s[i], w[i], &mut n.evals);
            }
            let sol = prob.solve_mode(mode)?;
            let dv = (sol.v - w).amax();
            w = sol.v;
            let done = self.converged(mode, dv, dv_prev, w.amax());
            dv_prev = dv;
            if done {
                return OneStepProblem::is_admissible(&sol, 0.0, 0.0).then_some(sol);
            }
        }
        None
    }

    /// Semi-smooth Newton: linearise the slip branches at the iterate, solve the piecewise
    /// linear problem exactly. On failure, the iterate to start Picard iteration from (the
    /// start velocity if a linearised problem had no solution).
    fn semi_smooth_newton(
        &self,
        ctx: &BranchCtx,
        base: &OneStepProblem,
        n: &mut Counts,
    ) -> Result<OneStepSolution, Vector2<f64>> {
        let mut w = ctx.v;
        let mut prev: Option<[DiscMode; 2]> = None;
        let mut dv_prev = f64::INFINITY;
        let mut prob = *base;
        for _ in 0..self.max_newton {
            n.newton += 1;
            for i in 0..2 {
                prob.slip[i] = [
                    ctx.branch(i, 1.0, w[i], &mut n.evals),
                    ctx.branch(i, -1.0, w[i], &mut n.evals),
                ];
            }
            let Ok(sol) = prob.solve() else {
                return Err(ctx.v);
            };
            let dv = (sol.v - w).amax();
            let same = prev == Some(sol.mode);
            w = sol.v;
            prev = Some(sol.mode);
            // A mode change makes the previous update no Newton step of this mode.
            let done = self.converged(
                sol.mode,
                dv,
                if same { dv_prev } else { f64::INFINITY },
                w.amax(),
            );
            dv_prev = dv;
            if (same || self.exact_linearisation(sol.mode)) && done {
                return Ok(sol);
            }
        }
        Err(w)
    }

    /// Newton failed: with a level falling faster than M̂ can absorb (very large h) the
    /// linearised slip branches become ill-posed, and the nonlinear step problem itself may
    /// have no or several solutions. Picard iteration on the frozen problem from `w`: every
    /// mode of disc i sees the same smooth impulse g_i and the same bound P_i, evaluated at
    /// the iterate; that is the KKT system of a strictly convex box QP (W = M̂⁻¹ SPD), with
    /// exactly one solution. A fixed point is an exact solution of the step problem; if none
    /// is reached, the last iterate (the exact solution of a frozen problem, bounded) is
    /// taken and the second value, `StepOutcome::exact`, says so.
    fn picard(
        &self,
        base: &OneStepProblem,
        mut w: Vector2<f64>,
        h: f64,
        p_start: &[f64; 2],
        t: f64,
        n: &mut Counts,
    ) -> Result<(Option<OneStepSolution>, bool), SolveError> {
        let th = self.theta;
        let implicit = self.level == FrictionLevel::Implicit;
        let mut last: Option<OneStepSolution> = None;
        let mut prev: Option<[DiscMode; 2]> = None;
        for _ in 0..self.max_newton {
            n.newton += 1;
            let mut prob = *base;
            for i in 0..2 {
                let s = if w[i] < 0.0 { -1.0 } else { 1.0 };
                let e = eval_branch(&self.law[i], self.db[i], w[i], s);
                n.evals += 1;
                let (mut g, mut p) = (h * th * e.off, p_start[i]);
                if implicit {
                    g -= s * h * th * e.level.min(0.0);
                    p += h * th * e.level.max(0.0);
                }
                prob.slip[i] = [1.0, -1.0].map(|sb| Branch {
                    c: g - sb * p,
                    d: 0.0,
                    pc: p,
                    pd: 0.0,
                });
                prob.stick[i] = StickData { e: g, p };
            }
            let sol = prob.solve().map_err(|err| SolveError::Complementarity {
                t,
                detail: format!("frozen one-step problem (h = {h:e}): {err:?}"),
            })?;
            let dv = (sol.v - w).amax();
            let same = prev == Some(sol.mode);
            w = sol.v;
            prev = Some(sol.mode);
            last = Some(sol);
            if same && dv <= 1e-12 * (1.0 + w.amax()) {
                return Ok((last, true));
            }
        }
        Ok((last, false))
    }

    /// Whether the linearised step problem of `mode` is the step problem itself: explicit
    /// level, or every slipping disc has an affine law (a stuck disc's data are constants).
    fn exact_linearisation(&self, mode: [DiscMode; 2]) -> bool {
        self.level == FrictionLevel::Explicit
            || (0..2).all(|i| mode[i] == DiscMode::Stick || self.affine_law[i])
    }

    /// Newton's stopping rule on the iterate `w` reached by the update `dv` (after the
    /// update `dv_prev` in the same mode, ∞ if none), tolerance `1e-12·(1 + |w|)`: the
    /// update is below it, or (with [`MoreauOptions::newton_estimate_stop`]) the
    /// linearisation is exact, or the quadratic-convergence estimate of the *next* update,
    /// `dv³/dv_prev²` (κ ≈ dv/dv_prev², next ≈ κ·dv²), is below a tenth of it with a
    /// contraction dv/dv_prev ≤ 0.1 that shows the quadratic regime.
    fn converged(&self, mode: [DiscMode; 2], dv: f64, dv_prev: f64, w_max: f64) -> bool {
        let tol = 1e-12 * (1.0 + w_max);
        if dv <= tol {
            return true;
        }
        if !self.estimate_stop {
            return self.level == FrictionLevel::Explicit;
        }
        if self.exact_linearisation(mode) {
            return true;
        }
        // ρ = dv/dv_prev ≤ 0.1 and dv·ρ² ≤ 0.1·tol, multiplied out (no division).
        dv_prev.is_finite() && dv <= 0.1 * dv_prev && dv * dv * dv <= 0.1 * tol * dv_prev * dv_prev
    }

    /// Checks a converged solution against the exact (not linearised) Coulomb conditions:
    /// slip s ⇒ `s ω⁺ > 0` and `r = −s P(ω⁺)`; stick ⇒ `ω⁺ = 0` and `|r| ≤ P`.
    pub(crate) fn check_complementarity(
        &self,
        sol: &OneStepSolution,
        p_start: &[f64; 2],
        h: f64,
    ) -> bool {
        (0..2).all(|i| match sol.mode[i].branch() {
            None => sol.v[i] == 0.0 && sol.r[i].abs() <= sol.p[i] * (1.0 + 1e-12) + 1e-15 * h,
            Some(s) => {
                let p = match self.level {
                    FrictionLevel::Implicit => {
                        p_start[i] + h * self.theta * self.law[i].level_ext(s * sol.v[i]).max(0.0)
                    }
                    FrictionLevel::Explicit => p_start[i],
                };
                // Newton tolerance 1e-12 on ω times |dP/dω| ≤ h·O(1): far below 1e-9·h.
                s * sol.v[i] > 0.0 && (sol.r[i] + s * p).abs() <= 1e-9 * (h + p.abs())
            }
        })
    }
}
