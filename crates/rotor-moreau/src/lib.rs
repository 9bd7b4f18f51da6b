//! Moreau–Jean time-stepping of the rotor model on its Lagrangian form (solver 3 of
//! rotorbench), after Siconos' `MoreauJeanOSI` with an exact one-step friction problem.
//!
//! # The Lagrangian form and how it maps onto eqs. (1)–(5)
//!
//! [`rotor_model::Lagrangian`]: `q = [θ_u, θ_l, x_u, x_l]`,
//!
//! ```text
//! M q̈ + C q̇ + K_s q + F_int(q̇) = F_ext + r,   M = diag(J_u, J_l, 1, 1), C = diag(b_u, b_l, 0, 0),
//! K_s q = k_θ [α, −α, 0, 0],  F_ext = [k_m u, 0, 0, 0],
//! F_int = [ΔT_su + Δb_u|θ̇_u|, 0, N_u, N_l(θ̇_l)]
//! ```
//!
//! Contact i (i = u, l) has the gap `x_i ≥ 0`, normal reaction `r_N,i` (on x_i) and tangential
//! reaction `r_T,i` (on θ_i, tangential velocity θ̇_i), Coulomb with μ = 1:
//! Signorini `0 ≤ x_i ⊥ r_N,i ≥ 0` (at velocity level in the scheme) and
//! `r_T,i ∈ −μ r_N,i Sign(θ̇_i)`. The extra DOF x_i is pressed onto its contact by the level
//! `N_i` ([`rotor_model::Friction::level`]: `T_su` for the upper disc,
//! `T_cl(ω_l) − b_l|ω_l|` for the lower). While the contact stays closed, `ẍ_i = 0` gives
//! `r_N,i = N_i`, hence `r_T,i ∈ −N_i Sign(θ̇_i)` and
//!
//! ```text
//! J_u θ̈_u = k_m u − k_θ α − b_u θ̇_u − (ΔT_su + Δb_u|θ̇_u|) − T_su Sign(θ̇_u)
//! J_l θ̈_l =         k_θ α − b_l θ̇_l − N_l(θ̇_l) Sign(θ̇_l)
//! ```
//!
//! which is eq. (1) with the friction laws (2)–(5): `T_f = a(ω) + bω + N(|ω|) Sign(ω)`.
//! Only `α = θ_u − θ_l` enters, so the stepper carries `[α, θ̇_u, θ̇_l]`; `x_u ≡ x_l ≡ 0` and
//! `ẋ_u ≡ ẋ_l ≡ 0` (the contacts never open, see below), and the normal impulse of each step
//! is `h·N_θ,i` (θ-weighted level) in closed form: the normal and tangential blocks of the
//! Delassus matrix are uncoupled (`M̂` is block diagonal between θ and x), and the normal
//! Signorini problem `ẋ⁺ = −hN_θ + r_N ≥ 0 ⊥ r_N ≥ 0` has the solution `r_N = h N_θ` when
//! `N_θ ≥ 0`.
//!
//! **Negative level.** With Table 1, `N_l(ω) = T_sl + T_1 tanh(w_1|ω|/2) + T_2 tanh(w_2|ω|/2)`
//! is negative for `|ω_l| ≳ 18 rad/s` (`T_sl + T_1 + T_2 < 0`). A unilateral contact pulled
//! by a negative normal force would open and lose that (negative) friction, which eq. (1)
//! keeps. So the contact carries `N⁺ = max(N, 0)` and the remainder is a smooth force:
//! `−N Sign(ω) = −N⁺ Sign(ω) − min(N, 0)·sign(ω)`, the last term single-valued because
//! `N < 0` only far from ω = 0. Both parts are θ-weighted like the rest. The scheme thus
//! integrates eq. (1) exactly as written. A contact with zero normal force (Table 1's upper
//! disc, `T_su = 0`) has zero friction: its disc just moves under its smooth forces.
//!
//! # The scheme
//!
//! Velocity-level θ-method (Jean & Moreau; Acary & Brogliato 2008, ch. 10), as
//! `MoreauJeanOSI`:
//!
//! ```text
//! M(v⁺ − v) + hK q_θ + hC v_θ + hF_int,θ = hF_ext + p,     v_θ = (1−θ)v + θv⁺,
//! q⁺ = q + h v_θ,   q_θ = (1−θ)q + θq⁺ = q + θh v_θ,    F_int,θ = (1−θ)F_int(v) + θF_int(v⁺)
//! ⇒ M̂ v⁺ = (M − (1−θ)hC − θ(1−θ)h²K) v − hKq + hF_ext − hF_int,θ + p,   M̂ = M + θhC + θ²h²K
//! ```
//!
//! θ ∈ [1/2, 1], default 1/2 (trapezoidal on the smooth part). With
//! [`FrictionLevel::Implicit`] (default) the level in `F_int` (hence the cone bound
//! `μ r_N = hN_θ`) and the smooth friction forces are θ-weighted between the two ends of the
//! step and solved *together* with the one-step problem by Newton on the step
//! ([`stepper`]); with [`FrictionLevel::Explicit`] the level is taken at the start of the step
//! (the step problem is then piecewise linear and solved in one pass). The one-step problem
//! (Signorini + Coulomb on both contacts) is solved exactly by enumerating the nine
//! stick/slip± modes ([`onestep`]), never by an iteration with a tolerance.
//!
//! **Skipping the complementarity solve.** When both discs' frozen-bound free velocities
//! `v_free,i` satisfy `|v_free,i| > 2 Σ_j |W_ij| P_j` (W = M̂⁻¹, P_j the cone bounds), no
//! admissible impulse can bring a velocity to zero: the slip mode `sign(v)` is taken,
//! Newton runs in that mode only, and its result is checked against the sign conditions
//! (a failed check falls back to the enumeration). Counted in [`Stats::lcp_skipped`]
//! (vs [`Stats::lcp_solves`]).
//!
//! # Orders measured (`rotor-compare/tests/moreau_order.rs`)
//!
//! Against the event-driven solver (tol = 1e-13, its own error ≤ 1e-11) on Table 1,
//! u = 1.5 V from rest, 60 s, metrics over [30, 60] s (period 4.5778 s, max ω_l 6.3361 rad/s):
//! the errors `e(h) = |m(h) − m_event|` for h = 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, fitted as
//! `e ≈ C·h^p`:
//!
//! | scheme | period: p, C (s) | max ω_l: p, C (rad/s) | period e(1e-2), e(1e-3), e(1e-4) |
//! |---|---|---|---|
//! | θ = 1/2, implicit level (default) | 1.99, 0.57 | 2.01, 0.65 | 6.2e-5, 5.7e-7, 6.3e-9 |
//! | θ = 1/2, explicit level | 1.00, 0.62 | 1.00, 0.65 | 6.2e-3, 6.1e-4, 6.1e-5 |
//! | θ = 1, implicit level | 1.00, 3.3 | 1.00, 7.3 | 3.4e-2, 3.4e-3, 3.4e-4 |
//!
//! Pointwise, `e/h²` of the default's period lies in 0.57–0.64. Below h = 1e-4 the error
//! meets the scheme's rounding noise: at h = 1e-5 (6·10⁶ steps, e ≈ 6e-11) two runs whose
//! steps differ by one part in 10⁹ differ in the metrics by up to 5e-11, so h = 1e-5 is no
//! fit point.
//!
//! The default matches the second-order behaviour measured with Siconos 4.4's
//! `MoreauJeanOSI` on this model (6e-5, 8e-7, 1e-8). Friction events keep the velocity
//! continuous (no impacts), so the O(h²) local error of a step containing a stick onset or
//! exit does not spoil the global order. **Not across a velocity reversal:** a disc whose
//! velocity passes through zero without sticking is held at rest for the one step that
//! contains the reversal (reported as a Reversal, see below), a local
//! error O(h) that makes the global error first order (measured by rotor-compare's stress
//! case "far from rest": 2.2e-4, 1.9e-5, 3.8e-6 rad/s at h = 1e-3, 1e-4, 1e-5). No fixture
//! scenario has a reversal; the second order above holds on stick-slip and slipping cycles.
//! Cost: about 0.14 µs per step (h = 1e-3, 100 s: 1e5 steps in 13.6 ms on one core,
//! `rotor bench`), ≈ 1.8 Newton iterations and 1.8 evaluations of the lower disc's friction
//! law per step, and about 80 % of the steps skip the enumeration.
//!
//! **Very large steps.** Up to h = 0.25 s every step problem of the fixtures is solved
//! exactly. At h = 0.5 s a level falling faster than `M̂` can absorb (`θh|N'| > J_l`) makes
//! the nonlinear step problem non-monotone (it may have no or several solutions); the step
//! then falls back to a Picard iteration whose frozen problems are strictly convex, and if
//! that does not converge takes its last (bounded) iterate ([`StepOutcome::exact`] =
//! `false`): 29 of 6100 steps over all fixtures at h = 0.5 (`cargo run --release -p
//! rotor-moreau --example exactness`). The state stays bounded at any h.
//!
//! # Output and events
//!
//! Dense output is linear interpolation of the state between step ends (the scheme's own:
//! `q⁺ = q + h v_θ` is linear in time inside a step). Events, located between steps:
//!
//! * `StickEnd(d)`: a stuck disc slips at the end of the step. Located where the applied
//!   torque `T_ex` ([`rotor_model::Model::applied_torque`]) leaves the stick interval
//!   ([`rotor_model::Friction::static_interval`]) — equivalently where the tangential impulse
//!   leaves the cone — by linear interpolation (or extrapolation, by at most one step) of the
//!   excess between the two step ends: O(h²).
//! * `StickStart(d)`: a slipping disc ends the step stuck. Located at the zero of the
//!   velocity's first-order Taylor expansion from the last slipping step end, with the
//!   model's acceleration there ([`rotor_model::Model::disc_accel`]), clamped to the step: O(h²).
//! * `Reversal(d)`: the velocity changes sign without sticking; linear interpolation: O(h²).
//!   A disc held at rest for exactly one step between slips of opposite sign also reverses
//!   (at the scheme's resolution): its stick onset is withdrawn and a Reversal is reported at
//!   the zero of ω interpolated between the two slipping step ends (O(h)). Reported as a stick
//!   phase, its exit would anchor a spurious cycle in the metrics (a random-parameter test found
//!   a 2.0 s "period" on a 7.4 s cycle).
//! * `Max(d)` / `Min(d)` (only when `scene.metrics_from` is set): a sign change of the
//!   discrete velocity increments while slipping; vertex of the parabola through the three
//!   step values.
//!
//! Events are fed in time order to a [`rotor_model::MetricsAccumulator`] when metrics are asked.

pub mod onestep;
pub mod stepper;

use rotor_model::{
    Disc, DiscMode, Event, EventKind, FastForward, MetricsAccumulator, Mode, Model, Output, Sample,
    Scene, SolveError, Solver, State, Stats, Trajectory, Verdict, check_finite,
};

pub use onestep::{Branch, EnumError, OneStepProblem, OneStepSolution, StickData};
pub use stepper::{StepOutcome, Stepper};

/// How the friction level (the contacts' normal force) enters a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrictionLevel {
    /// θ-weighted between the start and the end of the step, solved together with the
    /// one-step problem by Newton (as Siconos does with `F_int` in its Newton loop).
    /// Second order with θ = 1/2 (first order across a velocity reversal; see the crate docs).
    #[default]
    Implicit,
    /// Taken at the start of the step: first order, one linear pass per step.
    Explicit,
}

/// Options of [`MoreauSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoreauOptions {
    /// θ ∈ [1/2, 1] of the θ-scheme (default 1/2).
    pub theta: f64,
    /// Implicit (default) or explicit friction level.
    pub friction_level: FrictionLevel,
    /// Take the slip solution without the complementarity solve when no contact can change
    /// state in the step (default `true`; `false` enumerates on every step, for checks).
    pub skip_free_steps: bool,
    /// Maximum Newton iterations per step (default 50).
    pub max_newton: u32,
    /// Stop Newton on an *estimate* of the iterate's error (default `true`): at once when
    /// the linearisation is exact (every slipping disc's friction affine in its velocity,
    /// e.g. the upper disc of eq. (4), or a stuck disc), otherwise when two updates in one
    /// mode, `δ_{k−1}` then `δ_k`, contract quadratically so that the next one,
    /// `≈ δ_k³/δ_{k−1}²`, is below a tenth of the tolerance. `false`: iterate until the
    /// update itself is below the tolerance, one iteration more (for checks).
    pub newton_estimate_stop: bool,
    /// Maximum number of steps of one run (default 1e9).
    pub max_steps: u64,
    /// [`Output::Metrics`]: how close, in units of h², the first return after skipped
    /// periods must come to the return before them ([`rotor_model::FastForward`]); 0 rejects
    /// every skip (a check of the undo).
    pub skip_verify: f64,
}

impl Default for MoreauOptions {
    fn default() -> Self {
        MoreauOptions {
            theta: 0.5,
            friction_level: FrictionLevel::Implicit,
            skip_free_steps: true,
            max_newton: 50,
            newton_estimate_stop: true,
            max_steps: 1_000_000_000,
            skip_verify: rotor_model::fast_forward::VERIFY_TOLERANCES,
        }
    }
}

/// The Moreau–Jean solver; step size `scene.h`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MoreauSolver {
    pub options: MoreauOptions,
}

impl MoreauSolver {
    /// A solver with the given options.
    pub fn new(options: MoreauOptions) -> MoreauSolver {
        MoreauSolver { options }
    }
}

/// Capacity of the reorder buffer for events (a step detects at most six).
const PENDING: usize = 16;

/// Events detected but not yet released in time order.
#[derive(Clone, Copy)]
struct Pending {
    buf: [Option<Event>; PENDING],
    len: usize,
}

impl Pending {
    fn new() -> Pending {
        Pending {
            buf: [None; PENDING],
            len: 0,
        }
    }

    fn push(&mut self, e: Event, sink: &mut Sink) {
        if self.len == PENDING {
            // Never with a step's at most six events; released even while a jump waits, so
            // that the buffer cannot overflow.
            if let Some(first) = self.buf[0] {
                sink.take(&first);
            }
            self.buf.copy_within(1.., 0);
            self.len -= 1;
            self.buf[self.len] = None;
        }
        // Insertion into the time-ordered buffer.
        let mut i = self.len;
        while i > 0 && self.buf[i - 1].is_some_and(|p| p.t > e.t) {
            self.buf[i] = self.buf[i - 1];
            i -= 1;
        }
        self.buf[i] = Some(e);
        self.len += 1;
    }

    /// Removes the latest pending event of `kind`; whether there was one.
    fn remove(&mut self, kind: EventKind) -> bool {
        let Some(i) = (0..self.len)
            .rev()
            .find(|&i| self.buf[i].is_some_and(|e| e.kind == kind))
        else {
            return false;
        };
        for j in i + 1..self.len {
            self.buf[j - 1] = self.buf[j];
        }
        self.len -= 1;
        self.buf[self.len] = None;
        true
    }

    /// Moves the pending events by `dt` (a jump of whole periods).
    fn shift(&mut self, dt: f64) {
        for e in self.buf[..self.len].iter_mut().flatten() {
            e.t += dt;
        }
    }

    /// Releases up to `max` events with `t < t_limit`, earliest first; stops after an event
    /// on which the sink asks to jump or to go back.
    fn release_before(&mut self, t_limit: f64, sink: &mut Sink, max: usize) {
        let mut n = 0;
        while n < max.min(self.len) && self.buf[n].is_some_and(|e| e.t < t_limit) && !sink.halted()
        {
            if let Some(e) = self.buf[n] {
                sink.take(&e);
            }
            n += 1;
        }
        if n > 0 {
            for i in n..self.len {
                self.buf[i - n] = self.buf[i];
            }
            for i in self.len - n..self.len {
                self.buf[i] = None;
            }
            self.len -= n;
        }
    }
}

/// Where released events go.
struct Sink {
    events: Option<Vec<Event>>,
    metrics: Option<MetricsAccumulator>,
    count: u64,
    /// Whole periods skipped for [`Output::Metrics`]: a jump decided on an anchor event (its
    /// length and the event), or a jump to undo.
    fast_forward: Option<FastForward>,
    jump: Option<(f64, Event)>,
    undo: bool,
}

impl Sink {
    fn take(&mut self, e: &Event) {
        self.count += 1;
        if let Some(v) = self.events.as_mut() {
            v.push(*e);
        }
        if let Some(m) = self.metrics.as_mut() {
            m.push(e);
        }
        if let Some(ff) = self.fast_forward.as_mut() {
            match ff.observe(e) {
                Verdict::Continue => {}
                Verdict::Jump { dt } => self.jump = Some((dt, *e)),
                Verdict::Undo => self.undo = true,
            }
        }
    }

    /// Whether a jump or an undo waits for the end of the step.
    fn halted(&self) -> bool {
        self.jump.is_some() || self.undo
    }
}

/// The run at the end of the step on which a jump was decided, to go back to if it is undone.
struct Saved {
    cur: Point,
    prev: Option<Point>,
    pending: Pending,
    metrics: Option<MetricsAccumulator>,
    base: f64,
    k: u64,
    n: u64,
}

/// A step end kept for event location.
#[derive(Debug, Clone, Copy)]
struct Point {
    t: f64,
    x: State,
    mode: [DiscMode; 2],
}

fn lerp(a: &Point, b: &Point, t: f64) -> State {
    let dt = b.t - a.t;
    if dt <= 0.0 {
        return b.x;
    }
    let s = (t - a.t) / dt;
    a.x + (b.x - a.x) * s
}

/// Quadratic (Lagrange) interpolation through three points.
fn quad(p: [&Point; 3], t: f64) -> State {
    let [a, b, c] = p;
    let la = (t - b.t) * (t - c.t) / ((a.t - b.t) * (a.t - c.t));
    let lb = (t - a.t) * (t - c.t) / ((b.t - a.t) * (b.t - c.t));
    let lc = (t - a.t) * (t - b.t) / ((c.t - a.t) * (c.t - b.t));
    a.x * la + b.x * lb + c.x * lc
}

fn to_mode(m: &[DiscMode; 2]) -> Mode {
    Mode {
        upper: m[0],
        lower: m[1],
    }
}

impl Solver for MoreauSolver {
    fn name(&self) -> &'static str {
        "moreau"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        check_finite(0.0, &scene.x0)?;
        let o = &self.options;
        if !(o.theta >= 0.5 && o.theta <= 1.0) {
            return Err(SolveError::InvalidScene {
                field: "theta",
                value: o.theta,
                reason: "must lie in [1/2, 1]",
            });
        }
        if o.max_newton == 0 {
            return Err(SolveError::InvalidScene {
                field: "max_newton",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        let u = scene.u;
        let h = scene.h;
        let t_end = scene.t_end;
        // Number of steps: the last one is shortened to land on t_end (a remainder below
        // 1e-9·h is merged into the previous step).
        let n_f = (t_end / h - 1e-9).ceil().max(1.0);
        if n_f.is_nan() || n_f > o.max_steps as f64 {
            return Err(SolveError::TooManySteps {
                t: 0.0,
                max_steps: o.max_steps,
            });
        }
        let mut n = n_f as u64;
        let stepper = Stepper::new(model, u, o);
        let full = stepper.step_size(0.0, h)?;
        let keep_events = scene.keeps_events();
        let want_extrema = scene.metrics_start().is_some();

        let mut samples = Vec::new();
        let mut grid = scene.grid();
        match scene.output {
            Output::Grid { .. } => samples.reserve(grid.map_or(0, |g| g.len())),
            Output::Steps => samples.reserve(n as usize + 1),
            _ => {}
        }
        let mut sink = Sink {
            events: keep_events.then(Vec::new),
            metrics: scene.metrics_start().map(MetricsAccumulator::new),
            count: 0,
            // The scheme's error on the fixtures' cycles is second order, ≈ 0.6·h² in the
            // period (crate docs), so h² plays the adaptive solvers' tolerance.
            fast_forward: FastForward::for_scene(scene, h * h)
                .map(|f| f.verify_within(o.skip_verify)),
            jump: None,
            undo: false,
        };
        let mut pending = Pending::new();

        let m0 = model.mode_at(&scene.x0, u);
        let mut cur = Point {
            t: 0.0,
            x: scene.x0,
            mode: [m0.upper, m0.lower],
        };
        let mut prev: Option<Point> = None;
        match scene.output {
            Output::Steps => samples.push(Sample { t: 0.0, x: cur.x }),
            Output::Grid { .. } => {
                if let Some(g) = grid.as_mut()
                    && let Some(tg) = g.peek()
                    && tg <= 0.0
                {
                    samples.push(Sample { t: 0.0, x: cur.x });
                    g.advance();
                }
            }
            _ => {}
        }

        let mut stats = Stats::default();
        // Steps are taken at base + k·h, k = 1..=n, the last landing on t_end; a jump moves
        // the base.
        let (mut base, mut k) = (0.0, 0u64);
        let mut saved: Option<Saved> = None;
        'run: loop {
            while k < n {
                k += 1;
                let t_next = if k == n { t_end } else { base + k as f64 * h };
                let hk = t_next - cur.t;
                // Every step but the last has size h (t_next − t differs from h by roundings of
                // t only); the last lands on t_end.
                let out = if k < n {
                    stepper.step_with(cur.t, &cur.x, &full)?
                } else {
                    stepper.step(cur.t, &cur.x, hk)?
                };
                check_finite(t_next, &out.x)?;
                stats.steps += 1;
                stats.newton_iters += u64::from(out.newton_iters);
                stats.rhs_evals += u64::from(out.evals);
                stats.inexact_steps += u64::from(!out.exact);
                if out.used_enumeration {
                    stats.lcp_solves += 1;
                } else {
                    stats.lcp_skipped += 1;
                }
                let next = Point {
                    t: t_next,
                    x: out.x,
                    mode: out.mode,
                };

                if keep_events || want_extrema {
                    for (i, d) in Disc::BOTH.into_iter().enumerate() {
                        let wi = d.index();
                        let (m_a, m_b) = (cur.mode[i], next.mode[i]);
                        let kind_t = match (m_a, m_b) {
                            (DiscMode::Stick, DiscMode::Stick) => None,
                            (DiscMode::Stick, slip) => {
                                // Excess of the applied torque over the interval, at both ends.
                                let (lo, hi) = model.friction(d).static_interval();
                                let z = |x: &State| {
                                    let ta = model.applied_torque(d, x, u);
                                    if slip == DiscMode::SlipPos {
                                        ta - hi
                                    } else {
                                        lo - ta
                                    }
                                };
                                let (za, zb) = (z(&cur.x), z(&next.x));
                                let t0 = prev.map_or(cur.t, |p| p.t);
                                let t = if zb > za {
                                    (cur.t - za * (next.t - cur.t) / (zb - za)).clamp(t0, next.t)
                                } else {
                                    cur.t + o.theta * (next.t - cur.t)
                                };
                                Some((EventKind::StickEnd(d), t))
                            }
                            (slip, DiscMode::Stick) => {
                                // Zero of ω(t_k + Δ) ≈ ω + aΔ + ½jΔ², a and j = ω̈ from the
                                // model's vector field and Jacobian in the slipping mode.
                                let w = cur.x[wi];
                                let mut mode = to_mode(&cur.mode);
                                mode.set(d, slip);
                                let f = model.rhs(&cur.x, u, mode);
                                let acc = f[wi];
                                let jerk = (model.jacobian(&cur.x, u, mode) * f)[wi];
                                let t = if acc * w < 0.0 {
                                    let d1 = -w / acc;
                                    let den = acc + jerk * d1;
                                    let d2 = if den * acc > 0.0 {
                                        d1 - 0.5 * jerk * d1 * d1 / den
                                    } else {
                                        d1
                                    };
                                    (cur.t + d2).clamp(cur.t, next.t)
                                } else {
                                    next.t
                                };
                                Some((EventKind::StickStart(d), t))
                            }
                            (a, b) if a != b => {
                                let (wa, wb) = (cur.x[wi], next.x[wi]);
                                let t = if wa != wb {
                                    (cur.t + wa * (next.t - cur.t) / (wa - wb)).clamp(cur.t, next.t)
                                } else {
                                    next.t
                                };
                                Some((EventKind::Reversal(d), t))
                            }
                            _ => None,
                        };
                        // Held at rest for exactly one step between slips of opposite sign: a
                        // reversal at the scheme's resolution (crate docs), not a stick phase.
                        let reversal = matches!(kind_t, Some((EventKind::StickEnd(_), _)))
                            && prev
                                .is_some_and(|p| p.mode[i] != DiscMode::Stick && p.mode[i] != m_b)
                            && pending.remove(EventKind::StickStart(d));
                        if reversal && let Some(p) = prev {
                            // Zero of ω between the slipping ends of the two steps.
                            let (wa, wb) = (p.x[wi], next.x[wi]);
                            let t = (p.t + wa * (next.t - p.t) / (wa - wb)).clamp(p.t, next.t);
                            let mut x = lerp(&p, &next, t);
                            x[wi] = 0.0;
                            let kind = EventKind::Reversal(d);
                            pending.push(Event { t, x, kind }, &mut sink);
                        } else if let Some((kind, t)) = kind_t {
                            let mut x = if t >= cur.t {
                                lerp(&cur, &next, t)
                            } else {
                                prev.map_or(cur.x, |p| lerp(&p, &cur, t))
                            };
                            x[wi] = 0.0;
                            pending.push(Event { t, x, kind }, &mut sink);
                        }
                        // Extrema of the velocity while slipping.
                        if want_extrema
                            && let Some(p) = prev
                            && p.mode[i] != DiscMode::Stick
                            && m_a != DiscMode::Stick
                            && m_b != DiscMode::Stick
                        {
                            let (y0, y1, y2) = (p.x[wi], cur.x[wi], next.x[wi]);
                            let (d1, d2) = (y1 - y0, y2 - y1);
                            // Rounding noise filter: increments of a few ulps are no extremum.
                            let noise = 8.0 * f64::EPSILON * (1.0 + y1.abs());
                            let kind = if d1 > 0.0 && d2 <= 0.0 {
                                Some(EventKind::Max(d))
                            } else if d1 < 0.0 && d2 >= 0.0 {
                                Some(EventKind::Min(d))
                            } else {
                                None
                            };
                            if let Some(kind) = kind
                                && d1.abs().max(d2.abs()) > noise
                            {
                                // Vertex of the parabola through the three points.
                                let (ha, hb) = (cur.t - p.t, next.t - cur.t);
                                let s1 = d1 / ha;
                                let s2 = d2 / hb;
                                let curv = (s2 - s1) / (0.5 * (ha + hb));
                                let t = if curv != 0.0 {
                                    let tm1 = p.t + 0.5 * ha; // slope s1 at the midpoint
                                    (tm1 - s1 / curv).clamp(p.t, next.t)
                                } else {
                                    cur.t
                                };
                                let mut x = quad([&p, &cur, &next], t);
                                // The other disc's velocity is smooth over the three points
                                // only if its mode is: across its stick onset or exit the
                                // parabola would overshoot ω = 0 (a negative ω_l in a
                                // stick-slip cycle's metrics, with no reversal). There it
                                // is interpolated on the step that holds t, which keeps its
                                // sign.
                                let o = 1 - i;
                                if p.mode[o] != cur.mode[o] || cur.mode[o] != next.mode[o] {
                                    let (a, b) = if t <= cur.t {
                                        (&p, &cur)
                                    } else {
                                        (&cur, &next)
                                    };
                                    x[1 + o] = lerp(a, b, t)[1 + o];
                                }
                                pending.push(Event { t, x, kind }, &mut sink);
                            }
                        }
                    }
                    // Events detected later are at t ≥ cur.t.
                    pending.release_before(cur.t, &mut sink, usize::MAX);
                }

                match scene.output {
                    Output::Steps => samples.push(Sample {
                        t: next.t,
                        x: next.x,
                    }),
                    Output::Grid { .. } => {
                        if let Some(g) = grid.as_mut() {
                            while let Some(tg) = g.peek() {
                                if tg > next.t {
                                    break;
                                }
                                samples.push(Sample {
                                    t: tg,
                                    x: lerp(&cur, &next, tg.max(cur.t)),
                                });
                                g.advance();
                            }
                        }
                    }
                    _ => {}
                }
                prev = Some(cur);
                cur = next;
                if let Some((dt, anchor)) = sink.jump.take() {
                    saved = Some(Saved {
                        cur,
                        prev,
                        pending,
                        metrics: sink.metrics,
                        base,
                        k,
                        n,
                    });
                    if let Some(m) = sink.metrics.as_mut() {
                        m.fast_forward(&anchor, dt);
                    }
                    cur.t += dt;
                    if let Some(p) = prev.as_mut() {
                        p.t += dt;
                    }
                    pending.shift(dt);
                    (base, k) = (cur.t, 0);
                    n = ((t_end - base) / h - 1e-9).ceil().max(1.0) as u64;
                    // Events of the step's end that waited for the jump.
                    pending.release_before(cur.t, &mut sink, usize::MAX);
                }
                if sink.undo {
                    break;
                }
            }
            // (Nothing is released while an undo waits.)
            pending.release_before(f64::INFINITY, &mut sink, usize::MAX);
            if sink.undo
                || sink.fast_forward.as_mut().map(FastForward::finish) == Some(Verdict::Undo)
            {
                let sv = saved.take().expect("a jump before its undo");
                (cur, prev, pending) = (sv.cur, sv.prev, sv.pending);
                (base, k, n) = (sv.base, sv.k, sv.n);
                sink.metrics = sv.metrics;
                sink.undo = false;
                continue 'run;
            }
            break;
        }
        if let Some(g) = grid.as_mut() {
            while let Some(tg) = g.peek() {
                samples.push(Sample { t: tg, x: cur.x });
                g.advance();
            }
        }
        stats.events = sink.count;
        let stats = FastForward::counted(sink.fast_forward.as_ref(), stats);
        let metrics = sink.metrics.map(|m| m.finish(&cur.x));
        Ok(Trajectory {
            samples,
            events: sink.events.unwrap_or_default(),
            t_final: t_end,
            x_final: cur.x,
            mode_final: to_mode(&cur.mode),
            metrics,
            stats,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sink() -> Sink {
        Sink {
            events: Some(Vec::new()),
            metrics: None,
            count: 0,
            fast_forward: None,
            jump: None,
            undo: false,
        }
    }

    fn ev(t: f64) -> Event {
        Event {
            t,
            x: State::zeros(),
            kind: EventKind::Max(Disc::Lower),
        }
    }

    /// Events come out in time order, an overfull buffer releases its earliest (even while a
    /// jump waits), and a waiting jump stops the ordinary release.
    #[test]
    fn pending_events_leave_in_time_order_and_never_overflow() {
        let times = |s: &Sink, from: usize| -> Vec<f64> {
            s.events.as_ref().unwrap()[from..]
                .iter()
                .map(|e| e.t)
                .collect()
        };
        let mut p = Pending::new();
        let mut s = sink();
        s.jump = Some((1.0, ev(0.0)));
        for k in 0..PENDING + 4 {
            p.push(ev(k as f64), &mut s);
        }
        assert_eq!(
            times(&s, 0),
            [0.0, 1.0, 2.0, 3.0],
            "the overflow released the earliest"
        );
        p.release_before(f64::INFINITY, &mut s, usize::MAX);
        assert_eq!(times(&s, 0).len(), 4, "halted by the waiting jump");
        s.jump = None;
        p.release_before(8.0, &mut s, usize::MAX);
        assert_eq!(times(&s, 4), [4.0, 5.0, 6.0, 7.0]);
        assert!(p.remove(EventKind::Max(Disc::Lower)));
        assert!(!p.remove(EventKind::Min(Disc::Lower)));
        p.shift(100.0);
        p.release_before(f64::INFINITY, &mut s, usize::MAX);
        // 19 was the latest and was removed; the rest moved by 100 s.
        assert_eq!(times(&s, 8), (108..=118).map(f64::from).collect::<Vec<_>>());
    }
}
