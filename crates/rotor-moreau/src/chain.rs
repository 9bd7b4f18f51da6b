//! Moreau–Jean on a chain of N discs: the rig's scheme, with the one-step problem of all N
//! contacts solved at once by [`ContactSolver`] instead of enumerating 3^N modes.
//!
//! With `v = [ω_1 … ω_N]`, `α = [α_1 … α_{N−1}]`, `(Dv)_i = v_i − v_{i+1}`, the diagonal
//! inertia `M`, viscous friction `B`, the spring and coupling Laplacians `L_K = DᵀKD` and
//! `L_C = DᵀCD` (tridiagonal), and `C = B + L_C`, the θ-step from `(α, v)` over `h` is the
//! rig's ([`crate::stepper`]) written for N discs:
//!
//! ```text
//! A v⁺ = E v − h DᵀKα + h k_m u e_1 + h[(1−θ) g(v) + θ g(v⁺)] + r
//! A = M + θhC + θ²h²L_K,      E = M − (1−θ)hC − θ(1−θ)h²L_K
//! −P_i ≤ r_i ≤ P_i,  P_i = h[(1−θ) N_i⁺(ω_i) + θ N_i⁺(ω_i⁺)],  r_i = ∓P_i where ω_i⁺ ≷ 0
//! α⁺ = α + h D[(1−θ) v + θ v⁺]
//! ```
//!
//! where disc i's friction is `T_fi = a_i(ω) + b_i ω + N_i(|ω|) Sign(ω)`, its smooth force
//! `g_i = −a_i(ω_i) − min(N_i, 0) sign(ω_i)` (the negative part of a level is a smooth force,
//! as in the rig), and `N⁺ = max(N, 0)`. With the level and the smooth forces frozen the step
//! is one box-constrained problem `A v⁺ = b + r` over all N contacts, `A` a symmetric
//! tridiagonal M-matrix, which [`ContactSolver`] solves exactly (block principal pivoting,
//! warm-started from the last step's modes). The level and smooth forces at the end of the
//! step are taken implicitly by fixed-point (Picard) iteration over those exact solves: each
//! iterate freezes them at the previous iterate's velocities, and the iteration stops when
//! the modes repeat and the velocities move by at most `1e-12·(1 + |v|)`, the rig's
//! stopping rule. The map contracts with the factor `θh|N'|/J` (about 3e-3 for the rig's
//! lower disc at h = 1e-3), so a step takes a few solves. The rig's stepper solves the same
//! equations by semi-smooth Newton over its nine modes; on a chain of two the two agree to
//! their stopping tolerance (a test).

use rotor_model::chain::ChainModel;
use rotor_model::seam::{EventKind, EventRef, Recorder, Scene, SolveError, Stats, Trajectory};
use rotor_model::{Disc, DiscMode, Mode};

use crate::contacts::{ContactError, ContactSolver, Tridiagonal};
use crate::run::{exit_time, onset_time, vertex};

/// Fixed-point iterations per step before the step is refused.
const MAX_ITERATIONS: usize = 60;

/// The stopping rule of the step's fixed-point iteration: `|Δv| ≤ STOP·(1 + |v|)`, the
/// rig's (`crate::stepper`).
const STOP: f64 = 1e-12;

/// Why a chain step failed.
#[derive(Debug, Clone, PartialEq)]
pub enum ChainStepError {
    /// The one-step problem could not be solved.
    Contacts(ContactError),
    /// The level's fixed-point iteration did not settle (a step far too large for the
    /// friction law's slope).
    NotConverged {
        /// Iterations taken.
        iterations: usize,
    },
}

impl std::fmt::Display for ChainStepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ChainStepError::Contacts(e) => write!(f, "{e}"),
            ChainStepError::NotConverged { iterations } => write!(
                f,
                "the step's friction levels did not settle in {iterations} iterations \
                 (the step is too large for the law's slope)"
            ),
        }
    }
}

impl std::error::Error for ChainStepError {}

/// Work counters of a chain run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ChainCounts {
    /// Steps taken.
    pub steps: u64,
    /// One-step problems solved (one per fixed-point iteration).
    pub solves: u64,
    /// Linear (tridiagonal) solves inside them.
    pub linear_solves: u64,
}

/// The Moreau–Jean stepper of one chain at step `h`: the matrices built once, the buffers of
/// a step allocated once.
#[derive(Debug, Clone)]
pub struct ChainStepper {
    model: ChainModel,
    h: f64,
    theta: f64,
    /// `A = M + θhC + θ²h²L_K`.
    a: Tridiagonal,
    /// `E = M − (1−θ)hC − θ(1−θ)h²L_K`.
    e: Tridiagonal,
    contacts: ContactSolver,
    base: Vec<f64>,
    b: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    g0: Vec<f64>,
    p0: Vec<f64>,
    w: Vec<f64>,
    modes: Vec<DiscMode>,
    counts: ChainCounts,
}

/// `sign(w)`, 0 at 0: the branch a velocity's friction is read on.
fn branch(w: f64) -> f64 {
    if w > 0.0 {
        1.0
    } else if w < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl ChainStepper {
    /// The stepper of `model` at step `h` and weight `θ` (`θ = 1/2`: trapezoidal on the
    /// smooth part, the rig's default).
    pub fn new(model: &ChainModel, h: f64, theta: f64) -> ChainStepper {
        let n = model.discs();
        // The Laplacians' diagonal and off-diagonal: disc i feels the springs above and below.
        let lap = |f: &dyn Fn(usize) -> f64| -> (Vec<f64>, Vec<f64>) {
            let diag = (0..n)
                .map(|i| {
                    let above = if i > 0 { f(i - 1) } else { 0.0 };
                    let below = if i + 1 < n { f(i) } else { 0.0 };
                    above + below
                })
                .collect();
            let off = (0..n - 1).map(|i| -f(i)).collect();
            (diag, off)
        };
        let (lk_d, lk_o) = lap(&|i| model.spring(i));
        let (lc_d, lc_o) = lap(&|i| model.coupling(i));
        let mat = |s_c: f64, s_k: f64| Tridiagonal {
            diag: (0..n)
                .map(|i| {
                    model.inertia(i) + s_c * (model.friction(i).viscous() + lc_d[i]) + s_k * lk_d[i]
                })
                .collect(),
            off: (0..n - 1).map(|i| s_c * lc_o[i] + s_k * lk_o[i]).collect(),
        };
        ChainStepper {
            model: model.clone(),
            h,
            theta,
            a: mat(theta * h, theta * theta * h * h),
            e: mat(-(1.0 - theta) * h, -theta * (1.0 - theta) * h * h),
            contacts: ContactSolver::new(n),
            base: vec![0.0; n],
            b: vec![0.0; n],
            lo: vec![0.0; n],
            hi: vec![0.0; n],
            g0: vec![0.0; n],
            p0: vec![0.0; n],
            w: vec![0.0; n],
            modes: vec![DiscMode::Stick; n],
            counts: ChainCounts::default(),
        }
    }

    /// The step size.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// The work so far.
    pub fn counts(&self) -> ChainCounts {
        self.counts
    }

    /// The iteration matrix `A = M + θhC + θ²h²L_K`.
    pub fn iteration_matrix(&self) -> &Tridiagonal {
        &self.a
    }

    /// The smooth force `g_i(ω)` and the level's positive part `N_i⁺(|ω|)` of disc i.
    fn friction_at(&self, i: usize, w: f64) -> (f64, f64) {
        let f = self.model.friction(i);
        let s = branch(w);
        let level = f.level(w);
        (-(f.offset(w, s) + level.min(0.0) * s), level.max(0.0))
    }

    /// One step of `x = [α, ω]` (of the chain's size, updated in place) at motor voltage `u`
    /// (the θ-weighted voltage over the step, for an input that changes in time).
    pub fn step(&mut self, x: &mut [f64], u: f64) -> Result<(), ChainStepError> {
        let n = self.model.discs();
        let (h, th) = (self.h, self.theta);
        let (alpha, v) = x.split_at_mut(n - 1);
        // The part of the right-hand side that does not depend on the end of the step.
        self.e.mul_into(v, &mut self.base);
        self.base[0] += h * self.model.k_m() * u;
        for (i, &a) in alpha.iter().enumerate() {
            let t = h * self.model.spring(i) * a;
            self.base[i] -= t;
            self.base[i + 1] += t;
        }
        for (i, &w) in v.iter().enumerate() {
            let (g, p) = self.friction_at(i, w);
            (self.g0[i], self.p0[i]) = (g, p);
        }
        self.w.copy_from_slice(v);
        let mut iterations = 0;
        loop {
            for i in 0..n {
                let (g1, p1) = self.friction_at(i, self.w[i]);
                self.b[i] = self.base[i] + h * ((1.0 - th) * self.g0[i] + th * g1);
                let p = h * ((1.0 - th) * self.p0[i] + th * p1);
                (self.lo[i], self.hi[i]) = (-p, p);
            }
            self.contacts
                .solve(&self.a, &self.b, &self.lo, &self.hi)
                .map_err(ChainStepError::Contacts)?;
            iterations += 1;
            self.counts.solves += 1;
            self.counts.linear_solves += self.contacts.iterations() as u64;
            let next = self.contacts.v();
            let settled = self.modes.as_slice() == self.contacts.modes()
                && next
                    .iter()
                    .zip(&self.w)
                    .all(|(a, b)| (a - b).abs() <= STOP * (1.0 + b.abs()));
            self.w.copy_from_slice(next);
            self.modes.copy_from_slice(self.contacts.modes());
            if settled {
                break;
            }
            if iterations >= MAX_ITERATIONS {
                return Err(ChainStepError::NotConverged { iterations });
            }
        }
        for (i, a) in alpha.iter_mut().enumerate() {
            let d0 = v[i] - v[i + 1];
            let d1 = self.w[i] - self.w[i + 1];
            *a += h * ((1.0 - th) * d0 + th * d1);
        }
        v.copy_from_slice(&self.w);
        self.counts.steps += 1;
        Ok(())
    }

    /// The modes of the last step (stuck, or slipping forward or backward, per disc).
    pub fn modes(&self) -> &[DiscMode] {
        &self.modes
    }
}

/// A step end of a chain run: its time, state and each disc's mode.
#[derive(Debug, Clone, Default)]
struct StepEnd {
    t: f64,
    x: Vec<f64>,
    modes: Vec<DiscMode>,
    /// The input there, as the step being read sees it (its start's value from the right,
    /// its end's from the left: a step of u lies between steps).
    u: f64,
}

/// An event found between step ends, not yet released.
#[derive(Debug, Clone)]
struct Found {
    t: f64,
    x: Vec<f64>,
    kind: EventKind,
}

/// The events of a chain run read off its steps, disc by disc, as the rig's run reads its two
/// (crate docs, "Events"): a stick exit where the applied torque's excess over the stick
/// interval crosses 0 (linear between the step's ends; it may lie in the step before, where
/// the disc was held one step too long); a stick onset at the zero of the second-order Taylor
/// expansion of ω from the last slipping step end ([`ChainEvents::onset_time`]); a
/// reversal at the zero of ω between the step's ends, or, for a disc held at rest for exactly
/// one step between slips of opposite sign, between the slipping ends of the two steps (its
/// stick onset withdrawn). The stuck disc's velocity in an event's state is 0. Events are kept
/// in time order and released once no later step can find an earlier one.
struct ChainEvents<'a> {
    model: &'a ChainModel,
    theta: f64,
    /// The step ends before the last (if any), the last, and the one being observed: three
    /// buffers made once and rotated, so that a step allocates nothing.
    back: Option<StepEnd>,
    cur: StepEnd,
    next: StepEnd,
    pending: Vec<Found>,
    /// Whether the extrema of the velocities are located too (for the metrics).
    extrema: bool,
}

impl<'a> ChainEvents<'a> {
    /// The locator of a run of `model` at input `u` and weight `theta` from `x0` at t = 0,
    /// each disc in its Filippov-consistent mode there.
    fn new(
        model: &'a ChainModel,
        u: f64,
        theta: f64,
        x0: &[f64],
        extrema: bool,
    ) -> ChainEvents<'a> {
        let start = model.mode_at(x0, u);
        let cur = StepEnd {
            t: 0.0,
            x: x0.to_vec(),
            modes: (0..model.discs()).map(|i| start.of(Disc::at(i))).collect(),
            u,
        };
        ChainEvents {
            model,
            theta,
            back: None,
            next: cur.clone(),
            cur,
            pending: Vec::new(),
            extrema,
        }
    }

    /// The step end at `t` with state `x` and modes `modes`: the events of the step to it,
    /// over which the input runs from `u0` to `u1`.
    fn observe(&mut self, t: f64, x: &[f64], modes: &[DiscMode], (u0, u1): (f64, f64)) {
        self.next.t = t;
        self.next.x.copy_from_slice(x);
        self.next.modes.copy_from_slice(modes);
        self.next.u = u1;
        self.cur.u = u0;
        let (cur, next) = (
            std::mem::take(&mut self.cur),
            std::mem::take(&mut self.next),
        );
        self.step(&cur, &next);
        // Rotate: the step before becomes the next step's buffer.
        let old_back = self.back.replace(cur);
        self.cur = next;
        self.next = old_back.unwrap_or_else(|| self.cur.clone());
    }

    /// Linear interpolation between two step ends at `t`.
    fn lerp(a: &StepEnd, b: &StepEnd, t: f64) -> Vec<f64> {
        let s = if b.t > a.t {
            (t - a.t) / (b.t - a.t)
        } else {
            1.0
        };
        a.x.iter().zip(&b.x).map(|(p, q)| p + (q - p) * s).collect()
    }

    fn push(&mut self, t: f64, mut x: Vec<f64>, kind: EventKind, at_rest: Option<usize>) {
        if let Some(k) = at_rest {
            x[k] = 0.0;
        }
        let i = self.pending.partition_point(|e| e.t <= t);
        self.pending.insert(i, Found { t, x, kind });
    }

    /// The events of disc changes in the step `cur → next`.
    fn step(&mut self, cur: &StepEnd, next: &StepEnd) {
        let model = self.model;
        for i in 0..model.discs() {
            let d = Disc::at(i);
            let k = model.omega(i);
            let (ma, mb) = (cur.modes[i], next.modes[i]);
            match (ma, mb) {
                (DiscMode::Stick, DiscMode::Stick) => {}
                (DiscMode::Stick, slip) => {
                    // Held at rest for exactly one step between slips of opposite sign: a
                    // reversal at the scheme's resolution, not a stick phase.
                    if let Some(b) = self
                        .back
                        .clone()
                        .filter(|b| b.modes[i] != DiscMode::Stick && b.modes[i] != slip)
                        && let Some(j) = self
                            .pending
                            .iter()
                            .rposition(|e| e.kind == EventKind::StickStart(d))
                    {
                        self.pending.remove(j);
                        let (wa, wb) = (b.x[k], next.x[k]);
                        let t = (b.t + wa * (next.t - b.t) / (wa - wb)).clamp(b.t, next.t);
                        self.push(t, Self::lerp(&b, next, t), EventKind::Reversal(d), Some(k));
                        continue;
                    }
                    let (lo, hi) = model.friction(i).static_interval();
                    let z = |x: &[f64], u: f64| {
                        let ta = model.applied_torque(i, x, u);
                        if slip == DiscMode::SlipPos {
                            ta - hi
                        } else {
                            lo - ta
                        }
                    };
                    let (za, zb) = (z(&cur.x, cur.u), z(&next.x, next.u));
                    let t0 = self.back.as_ref().map_or(cur.t, |b| b.t);
                    let t = exit_time(za, zb, (t0, cur.t, next.t), self.theta);
                    let x = match &self.back {
                        Some(b) if t < cur.t => Self::lerp(b, cur, t),
                        _ => Self::lerp(cur, next, t),
                    };
                    self.push(t, x, EventKind::StickEnd(d), None);
                }
                (slip, DiscMode::Stick) => {
                    let t = self.onset_time(i, slip, cur, next);
                    self.push(
                        t,
                        Self::lerp(cur, next, t),
                        EventKind::StickStart(d),
                        Some(k),
                    );
                }
                (a, b) if a != b => {
                    let (wa, wb) = (cur.x[k], next.x[k]);
                    let t = if wa != wb {
                        (cur.t + wa * (next.t - cur.t) / (wa - wb)).clamp(cur.t, next.t)
                    } else {
                        next.t
                    };
                    self.push(t, Self::lerp(cur, next, t), EventKind::Reversal(d), Some(k));
                }
                _ => {}
            }
            if self.extrema {
                self.extremum(i, cur, next);
            }
        }
    }

    /// An extremum of disc `i`'s velocity while it slips over the last three step ends: the
    /// vertex of the parabola through them (the rig's rule). The state there is the parabola's
    /// too, except for a disc whose mode changes over the three ends, whose velocity is
    /// interpolated on the step holding the vertex (a parabola across a stick onset would
    /// overshoot ω = 0).
    fn extremum(&mut self, i: usize, cur: &StepEnd, next: &StepEnd) {
        let Some(p) = self.back.as_ref() else {
            return;
        };
        if [p.modes[i], cur.modes[i], next.modes[i]].contains(&DiscMode::Stick) {
            return;
        }
        let k = self.model.omega(i);
        let Some((kind, t)) = vertex(
            Disc::at(i),
            [p.t, cur.t, next.t],
            [p.x[k], cur.x[k], next.x[k]],
        ) else {
            return;
        };
        let weight = |a: f64, b: f64, c: f64| (t - b) * (t - c) / ((a - b) * (a - c));
        let (la, lb, lc) = (
            weight(p.t, cur.t, next.t),
            weight(cur.t, p.t, next.t),
            weight(next.t, p.t, cur.t),
        );
        let mut x: Vec<f64> = (0..p.x.len())
            .map(|c| p.x[c] * la + cur.x[c] * lb + next.x[c] * lc)
            .collect();
        let (a, b) = if t <= cur.t { (p, cur) } else { (cur, next) };
        let changes = |j: usize| p.modes[j] != cur.modes[j] || cur.modes[j] != next.modes[j];
        if (0..self.model.discs()).any(changes) {
            let on_step = Self::lerp(a, b, t);
            for j in (0..self.model.discs()).filter(|&j| changes(j)) {
                let kj = self.model.omega(j);
                x[kj] = on_step[kj];
            }
        }
        self.push(t, x, kind, None);
    }

    /// Stick onset of disc `i` from `slip` within the step `cur → next`: the zero of
    /// `ω(t_k + Δ) ≈ ω + aΔ + ½jΔ²`, with `a` and `j = ω̈` from the chain's field and Jacobian
    /// in the step's modes with disc `i` slipping (the rig's rule).
    fn onset_time(&self, i: usize, slip: DiscMode, cur: &StepEnd, next: &StepEnd) -> f64 {
        let model = self.model;
        let k = model.omega(i);
        let w = cur.x[k];
        let mut mode = Mode::from_discs(&cur.modes);
        mode.set(Disc::at(i), slip);
        let mut f = vec![0.0; model.dim()];
        model.rhs_into(&cur.x, cur.u, mode, &mut f);
        let acc = f[k];
        let jac = model.jacobian(&cur.x, mode);
        let mut jerk: f64 = (0..model.dim()).map(|c| jac[(k, c)] * f[c]).sum();
        // The input's own rate adds k_m·du/dt / J_1 to the driven disc's ω̈.
        if i == 0 && next.u != cur.u {
            jerk += model.k_m() * (next.u - cur.u) / (next.t - cur.t) / model.inertia(0);
        }
        onset_time(w, acc, jerk, cur.t, next.t)
    }

    /// Releases the events before `t` (every event found later lies at or after it).
    fn release_before(&mut self, t: f64, rec: &mut Recorder) {
        let n = self.pending.partition_point(|e| e.t < t);
        for e in self.pending.drain(..n) {
            rec.event(EventRef {
                t: e.t,
                x: &e.x,
                kind: e.kind,
            });
        }
    }
}

/// Moreau–Jean on a chain of N discs: `scene` run at its step (the default one for a scene
/// that sets a tolerance), every step but the last of size h and the last landing on
/// `t_end`, the samples of the chain's size (between step ends, linear interpolation, as
/// the rig's run).
///
/// Its stick onsets and exits and reversals are read off the steps disc by disc, with the
/// rig's run's rules (crate docs, "Events"), and, when metrics are asked, each slipping
/// disc's velocity extrema (the vertex of the parabola through three step ends). An input
/// in time ends a step on each of its breakpoints, and each step's motor torque is the
/// θ-weighted input at its two ends, as in the rig's run.
pub fn simulate_chain(model: &ChainModel, scene: &Scene) -> Result<Trajectory, SolveError> {
    scene.validate_chain(model)?;
    let n = model.discs();
    let h = scene.checked_step()?;
    let t_end = scene.t_end;
    let theta = 0.5;
    let options = crate::MoreauOptions::default();
    // The segments between the input's breakpoints (one, [0, t_end], for a constant input):
    // each of full steps of h and a last one landing on its end.
    let mut ends: Vec<f64> = match scene.input.as_ref().filter(|_| scene.is_time_varying()) {
        Some(input) => input
            .breakpoints()
            .filter(|&t| t > 0.0 && t < t_end)
            .collect(),
        None => Vec::new(),
    };
    ends.dedup();
    ends.push(t_end);
    let mut segments = Vec::with_capacity(ends.len());
    let mut start = 0.0;
    let mut steps_total = 0.0;
    for &end in &ends {
        let steps = (((end - start) / h) - 1e-9).ceil().max(1.0);
        steps_total += steps;
        segments.push((start, end, steps as u64 - 1));
        start = end;
    }
    let max_steps = options.max_steps;
    if steps_total > max_steps as f64 {
        return Err(SolveError::TooManySteps { t: 0.0, max_steps });
    }
    let mut x = scene.x0.clone();
    let mut prev = x.clone();
    // (h² the fast-forward's error scale, as the rig's run; the skip is off for a chain.)
    let mut rec = Recorder::new(scene, &x, h * h, options.skip_verify);
    rec.reserve(steps_total as usize);
    let mut counts = ChainCounts::default();
    // The warm start of the first step's contacts (their solve is exact from any).
    let mut modes = vec![DiscMode::Stick; n];
    let mut events = rec
        .wants_events()
        .then(|| ChainEvents::new(model, scene.u_at(0.0), theta, &x, rec.wants_extrema()));
    let failed = |t: f64, e: ChainStepError| SolveError::Complementarity {
        t,
        detail: e.to_string(),
    };
    let mut full_stepper = ChainStepper::new(model, h, theta);
    for (base, end, full) in segments {
        // The input over the segment: its linear piece (constant for a constant input),
        // read at a step's two ends; the step's motor torque is θ-weighted, as the rig's.
        let piece = scene.piece(base);
        let last = end - (base + full as f64 * h);
        let mut last_stepper = ChainStepper::new(model, last, theta);
        for (st, steps) in [
            (&mut full_stepper, 0..full),
            (&mut last_stepper, full..full + 1),
        ] {
            st.contacts.warm_start(&modes);
            st.modes.copy_from_slice(&modes);
            for j in steps {
                let t0 = base + j as f64 * h;
                let t1 = if j == full { end } else { t0 + h };
                let (u0, u1) = (piece.at(t0), piece.at(t1));
                let u = if u0 == u1 {
                    u0
                } else {
                    (1.0 - theta) * u0 + theta * u1
                };
                prev.copy_from_slice(&x);
                st.step(&mut x, u).map_err(|e| failed(t0, e))?;
                counts.steps += 1;
                if let Some(ev) = events.as_mut() {
                    ev.observe(t1, &x, st.modes(), (u0, u1));
                    // Events found later lie at or after this step's start.
                    ev.release_before(t0, &mut rec);
                }
                rec.step(t0, t1, &x, |t, out| {
                    let s = (t - t0) / (t1 - t0);
                    for ((o, a), b) in out.iter_mut().zip(&prev).zip(&x) {
                        *o = a + (b - a) * s;
                    }
                });
            }
            modes.copy_from_slice(st.modes());
        }
        let c = last_stepper.counts();
        counts.solves += c.solves;
        counts.linear_solves += c.linear_solves;
    }
    let c = full_stepper.counts();
    counts.solves += c.solves;
    counts.linear_solves += c.linear_solves;
    if let Some(ev) = events.as_mut() {
        ev.release_before(f64::INFINITY, &mut rec);
    }
    let stats = Stats {
        steps: counts.steps,
        lcp_solves: counts.solves,
        ..Stats::default()
    };
    Ok(rec.finish(t_end, &x, Mode::from_discs(&modes), stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contacts::residual;
    use rotor_model::chain::ChainParams;
    use rotor_model::seam::Output;
    use rotor_model::{Model, Params, State};

    fn stribeck() -> Params {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/params/stribeck.toml");
        Params::from_file(&p).unwrap()
    }

    /// On a chain of two the stepper is the rig's scheme: it follows the rig's stepper,
    /// which solves the same step equations by Newton over its nine modes, on Table 1 and
    /// on the Stribeck set (whose upper disc sticks too), through stick-slip from rest.
    #[test]
    fn a_chain_of_two_follows_the_rigs_stepper() {
        for (name, p) in [("table1", Params::table1()), ("stribeck", stribeck())] {
            let model = Model::new(p);
            let chain = ChainModel::new(&ChainParams::from_params(&p));
            let (u, h) = (1.5, 1e-3);
            let rig = crate::Stepper::new(&model, u, &crate::MoreauOptions::default());
            let mut st = ChainStepper::new(&chain, h, 0.5);
            let mut x = State::zeros();
            let mut y = vec![0.0; 3];
            let (mut worst, mut stuck_steps) = (0.0f64, 0);
            for k in 0..20_000 {
                x = rig.step(k as f64 * h, &x, h).unwrap().x;
                st.step(&mut y, u).unwrap();
                worst = worst.max((0..3).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max));
                stuck_steps += usize::from(y[2] == 0.0);
            }
            eprintln!("{name}: max |x_rig - x_chain| over 20 s = {worst:e}, {stuck_steps} stuck");
            // Both stop their iteration at 1e-12 (1 + |v|) per step; over 2e4 steps of a
            // dissipative system the two stay within 1e-9 (the bound the rig's own two
            // solution paths are held to), unless a step's mode differed, which would show
            // as an O(h) = 1e-3 jump.
            assert!(worst <= 1e-9, "{name}: {worst:e}");
            assert!(
                stuck_steps > 1000,
                "{name}: the run sticks ({stuck_steps} steps)"
            );
        }
    }

    /// A chain's run samples what the stepper computes: the grid rows at step ends are the
    /// stepper's states, the last row lands on t_end, and what the chain's run does not do
    /// is refused by name.
    #[test]
    fn a_chain_run_records_the_steppers_states() {
        use rotor_model::seam::Accuracy;
        let chain = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 3));
        let scene = Scene {
            u: 1.5,
            x0: vec![0.0; 5],
            t_end: 1.0,
            accuracy: Accuracy::Step(1e-3),
            output: Output::Grid { dt: 0.1 },
            metrics_from: None,
            ..Scene::default()
        };
        let tr = simulate_chain(&chain, &scene).unwrap();
        assert_eq!((tr.samples.len(), tr.samples.dim()), (11, 5));
        assert_eq!(tr.stats.steps, 1000);
        let mut st = ChainStepper::new(&chain, 1e-3, 0.5);
        let mut x = vec![0.0; 5];
        for k in 1..=1000 {
            st.step(&mut x, 1.5).unwrap();
            if k % 100 == 0 {
                // 0.1 is k·h up to rounding: the row is the step end's state, or the
                // interpolant a rounding away from it.
                let row = tr.samples.x(k / 100);
                let d = row
                    .iter()
                    .zip(&x)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(d <= 1e-12, "row {}: {d:e}", k / 100);
            }
        }
        assert_eq!(tr.x_final, x);
        assert_eq!(tr.samples.last().unwrap().t, 1.0);
        let refused = |sc: Scene, what: &str| {
            let e = simulate_chain(&chain, &sc).unwrap_err().to_string();
            assert!(e.contains(what), "{e}");
        };
        refused(
            Scene {
                x0: vec![0.0; 3],
                ..scene.clone()
            },
            "x0 = 3 values: a chain of 3 discs has 5",
        );
        // A horizon of more steps than the rig's run allows is refused before it starts.
        refused(
            Scene {
                t_end: 1e12,
                output: Output::Final,
                ..scene
            },
            "step limit",
        );
    }

    /// Every step's one-step problem is solved exactly: its complementarity residual is at
    /// rounding level, on a chain of eight with couplings that sticks and slips.
    #[test]
    fn every_step_is_solved_to_rounding() {
        let mut p = ChainParams::rig_copies(&Params::table1(), 8);
        p.discs[4].c = 0.01;
        let chain = ChainModel::new(&p);
        let mut st = ChainStepper::new(&chain, 2e-3, 0.5);
        let mut x = vec![0.0; chain.dim()];
        let (mut worst, mut stuck) = (0.0f64, 0);
        for _ in 0..5_000 {
            st.step(&mut x, 1.5).unwrap();
            let r = residual(
                &st.a,
                &st.b,
                &st.lo,
                &st.hi,
                st.contacts.v(),
                st.contacts.r(),
            );
            worst = worst.max(r);
            stuck += st.modes().iter().filter(|m| **m == DiscMode::Stick).count();
        }
        assert!(x.iter().all(|v| v.is_finite()));
        assert!(stuck > 5_000, "discs stick along the run: {stuck}");
        // The residual is relative to the problem's scale (contacts::residual); a few
        // roundings of one tridiagonal solve.
        assert!(worst <= 1e-13, "{worst:e}");
    }

    /// On a chain of two the events are the rig's run's, read off the same steps: the same
    /// kinds in the same order, at times within 1e-9 s (measured 2.0e-12 and 7.2e-13: the
    /// two steppers agree to their stopping tolerance, 7e-12 in the state, and the rules are
    /// the rig's), on Table 1 and the Stribeck set (whose upper disc sticks).
    #[test]
    fn a_chain_of_two_has_the_rigs_events() {
        for p in [Params::table1(), stribeck()] {
            let chain = ChainModel::new(&ChainParams::from_params(&p));
            let scene = Scene {
                u: 1.5,
                t_end: 30.0,
                accuracy: rotor_model::seam::Accuracy::Step(1e-3),
                output: Output::Events,
                ..Scene::default()
            };
            let rig = crate::MoreauSolver::default();
            let a = rotor_model::seam::Solver::simulate(&rig, &Model::new(p), &scene).unwrap();
            let b = simulate_chain(&chain, &scene).unwrap();
            let kinds = |t: &Trajectory| -> Vec<EventKind> {
                t.events
                    .iter()
                    .map(|e| e.kind)
                    .filter(|k| !matches!(k, EventKind::Max(_) | EventKind::Min(_)))
                    .collect()
            };
            assert!(kinds(&a).len() > 5);
            assert_eq!(kinds(&a), kinds(&b));
            let times = |t: &Trajectory| -> Vec<f64> {
                t.events
                    .iter()
                    .filter(|e| !matches!(e.kind, EventKind::Max(_) | EventKind::Min(_)))
                    .map(|e| e.t)
                    .collect()
            };
            let worst = times(&a)
                .iter()
                .zip(times(&b))
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            eprintln!("largest event time difference {worst:e}");
            assert!(worst <= 1e-9, "{worst:e}");
        }
    }

    /// Second order in h on a chain of three through stick-slip: the differences between
    /// runs at h, h/2 and h/4 fall by about 4 (self-convergence; no other solver runs chains
    /// yet).
    #[test]
    fn a_chain_of_three_converges_at_second_order() {
        let chain = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 3));
        let t_end = 10.0;
        let run = |h: f64| {
            let mut st = ChainStepper::new(&chain, h, 0.5);
            let mut x = vec![0.0; chain.dim()];
            for _ in 0..(t_end / h).round() as usize {
                st.step(&mut x, 1.5).unwrap();
            }
            x
        };
        let xs: Vec<Vec<f64>> = [4e-3, 2e-3, 1e-3, 5e-4].iter().map(|&h| run(h)).collect();
        let d: Vec<f64> = xs
            .windows(2)
            .map(|w| {
                w[0].iter()
                    .zip(&w[1])
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        eprintln!("differences at t = {t_end}: {d:?}");
        for k in 0..d.len() - 1 {
            let ratio = d[k] / d[k + 1];
            // Order 2 gives 4; a first-order scheme would give 2. 3 leaves room for the
            // stick events, whose step-to-step timing is not smooth in h.
            assert!(
                ratio > 3.0,
                "ratio {ratio} between {:e} and {:e}",
                d[k],
                d[k + 1]
            );
        }
    }
    /// A step of the input at t = 10 s on a chain of three is the 1.5 V run to 10 s, then a
    /// 2.5 V run from the state reached there: bit for bit up to the step (the step ends on
    /// it, as the 10 s run's last step does), and after it within 1e-10 (the stepped run's
    /// steps after 10 s end at 10 + j h, the composed run's at j h: their last steps differ
    /// by the rounding of t, and the grid samples between steps with them).
    #[test]
    fn a_step_of_the_input_is_two_runs_composed() {
        let chain = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 3));
        let first = Scene {
            u: 1.5,
            x0: vec![0.0; 5],
            t_end: 10.0,
            accuracy: rotor_model::seam::Accuracy::Step(1e-3),
            output: Output::Grid { dt: 0.01 },
            ..Scene::default()
        };
        let a = simulate_chain(&chain, &first).unwrap();
        let b = simulate_chain(
            &chain,
            &Scene {
                u: 2.5,
                x0: a.x_final.clone(),
                ..first.clone()
            },
        )
        .unwrap();
        let input = rotor_model::seam::Input::new(&[[0.0, 1.5], [10.0, 1.5], [10.0, 2.5]]);
        let stepped = simulate_chain(
            &chain,
            &Scene {
                input: Some(input.unwrap()),
                t_end: 20.0,
                ..first.clone()
            },
        )
        .unwrap();
        let n = a.samples.len();
        assert_eq!(stepped.samples.len(), n + b.samples.len() - 1);
        for i in 0..n {
            assert_eq!(stepped.samples.row(i), a.samples.row(i), "row {i}");
        }
        let after = stepped
            .samples
            .iter()
            .skip(n - 1)
            .zip(b.samples.iter())
            .map(|(r, s)| {
                r.x.iter()
                    .zip(s.x)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        eprintln!("after the step: {after:e}");
        assert!(after <= 1e-10, "{after:e}");
    }

    /// A ramp of the input converges as the step falls: on a chain of three, u rising from
    /// 1 V to 3 V over [2, 8] s, the largest difference from the run at 2.5e-4 over 10 s falls
    /// by at least 3 at each halving of h = 4e-3, 2e-3, 1e-3: second order (a factor 4;
    /// measured 4.1 and 4.3), the input's kinks lying on step ends.
    #[test]
    fn a_ramp_of_the_input_converges_with_the_step() {
        let chain = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), 3));
        let ramp = rotor_model::seam::Input::new(&[[0.0, 1.0], [2.0, 1.0], [8.0, 3.0]]).unwrap();
        let run = |h: f64| {
            simulate_chain(
                &chain,
                &Scene {
                    input: Some(ramp.clone()),
                    x0: vec![0.0; 5],
                    t_end: 10.0,
                    accuracy: rotor_model::seam::Accuracy::Step(h),
                    output: Output::Grid { dt: 0.01 },
                    ..Scene::default()
                },
            )
            .unwrap()
        };
        let fine = run(2.5e-4);
        let errs: Vec<f64> = [4e-3, 2e-3, 1e-3]
            .iter()
            .map(|&h| {
                run(h)
                    .samples
                    .iter()
                    .zip(fine.samples.iter())
                    .map(|(r, s)| {
                        r.x.iter()
                            .zip(s.x)
                            .map(|(p, q)| (p - q).abs())
                            .fold(0.0, f64::max)
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        eprintln!("errors at h = 4e-3, 2e-3, 1e-3: {errs:?}");
        for w in errs.windows(2) {
            assert!(w[0] / w[1] >= 3.0, "{errs:?}");
        }
    }
}
