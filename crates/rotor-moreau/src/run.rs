//! The run: steps of the [`Stepper`] on the grid `base + k·h`, the events located between step
//! ends (stick onsets and exits, reversals, extrema), released in time order to the
//! [`Recorder`], which keeps what the scene asks for and drives the metrics-only skip.

use rotor_model::seam::{
    Event, EventKind, EventRef, Input, Integration, Piece, Recorder, Scene, SolveError, Solver,
    Stats, Trajectory, check_finite,
};
use rotor_model::{Disc, DiscMode, FieldError, Mode, Model, State};

use crate::stepper::{StepSize, Stepper};
use crate::{MoreauOptions, MoreauSolver};

/// Capacity of the reorder buffer for events (a step detects at most six).
const PENDING: usize = 16;

/// An event as the stepper finds it, on the rig's state: a value the pending buffer copies
/// (the seam's [`Event`] is made from it when it is released to the recorder).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Found {
    t: f64,
    x: State,
    kind: EventKind,
}

/// Where released events go: the recorder (or a test's list).
trait Release {
    fn take(&mut self, e: &Found);
    /// Whether a jump or an undo waits for the end of the step (nothing more is released).
    fn halted(&self) -> bool;
}

impl Release for Recorder {
    fn take(&mut self, e: &Found) {
        self.event(EventRef {
            t: e.t,
            x: e.x.as_slice(),
            kind: e.kind,
        });
    }

    fn halted(&self) -> bool {
        Recorder::halted(self)
    }
}

/// Events detected but not yet released in time order.
#[derive(Clone, Copy)]
struct Pending {
    buf: [Option<Found>; PENDING],
    len: usize,
}

impl Pending {
    fn new() -> Pending {
        Pending {
            buf: [None; PENDING],
            len: 0,
        }
    }

    fn push(&mut self, e: Found, sink: &mut impl Release) {
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

    /// Releases the events with `t < t_limit`, earliest first; stops after an event on which
    /// the sink halts.
    fn release_before(&mut self, t_limit: f64, sink: &mut impl Release) {
        let mut n = 0;
        while n < self.len && self.buf[n].is_some_and(|e| e.t < t_limit) && !sink.halted() {
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

/// The extremum of disc `d`'s velocity `y` over three step ends at times `t`: a maximum or
/// minimum where the increments change sign (not by a few ulps, rounding noise), at the vertex
/// of the parabola through the three points (its slope between the first two taken at their
/// midpoint), clamped to the three ends. The rig's run and the chain's share it.
pub(crate) fn vertex(d: Disc, t: [f64; 3], y: [f64; 3]) -> Option<(EventKind, f64)> {
    let (d1, d2) = (y[1] - y[0], y[2] - y[1]);
    // Rounding noise filter: increments of a few ulps are no extremum.
    let noise = 8.0 * f64::EPSILON * (1.0 + y[1].abs());
    let kind = if d1 > 0.0 && d2 <= 0.0 {
        EventKind::Max(d)
    } else if d1 < 0.0 && d2 >= 0.0 {
        EventKind::Min(d)
    } else {
        return None;
    };
    if d1.abs().max(d2.abs()) <= noise {
        return None;
    }
    let (ha, hb) = (t[1] - t[0], t[2] - t[1]);
    let s1 = d1 / ha;
    let s2 = d2 / hb;
    let curv = (s2 - s1) / (0.5 * (ha + hb));
    let at = if curv != 0.0 {
        let tm1 = t[0] + 0.5 * ha; // slope s1 at the midpoint
        (tm1 - s1 / curv).clamp(t[0], t[2])
    } else {
        t[1]
    };
    Some((kind, at))
}

fn to_mode(m: &[DiscMode; 2]) -> Mode {
    Mode::rig(m[0], m[1])
}

/// What the run goes back to if a jump is undone: the end of the step on which it was
/// decided.
#[derive(Clone, Copy)]
struct Saved {
    cur: Point,
    prev: Option<Point>,
    pending: Pending,
    base: f64,
    k: u64,
    n: u64,
}

/// The integration as the recorder drives it: step `k` of `n` on the grid `base + k·h`, the
/// last landing on `t_end`; a jump moves the base.
struct Run<'a> {
    model: &'a Model,
    stepper: Stepper,
    /// The step size `h` with its factorisations (every step but the last).
    full: StepSize,
    /// The input's current piece (the constant input: one piece for ever).
    piece: Piece,
    /// A time-varying input, stepped one piece at a time (`None`: constant).
    input: Option<&'a Input>,
    h: f64,
    t_end: f64,
    /// Where the current piece ends (its next breakpoint, or `t_end`): the last step of the
    /// piece lands on it, and the step grid restarts there.
    seg_end: f64,
    theta: f64,
    base: f64,
    k: u64,
    n: u64,
    cur: Point,
    prev: Option<Point>,
    pending: Pending,
    /// After a jump, the events of the step's end that waited for it are released first.
    release_waiting: bool,
    stats: Stats,
}

/// Number of steps from `base` to `t_end`: the last one is shortened to land on `t_end` (a
/// remainder below 1e-9·h is merged into the previous step).
fn steps_to(t_end: f64, base: f64, h: f64) -> f64 {
    ((t_end - base) / h - 1e-9).ceil().max(1.0)
}

/// A stick exit within the step `t_a → t_b`: the zero of the applied torque's excess over the
/// stick interval, `z_a` at `t_a` and `z_b` at `t_b`, linear between the step's ends and
/// clamped to `[t_0, t_b]` (`t_0` the start of the step before: the disc may have been held
/// one step too long); where the excess does not grow over the step, the θ-point of the step.
pub(crate) fn exit_time(za: f64, zb: f64, (t0, ta, tb): (f64, f64, f64), theta: f64) -> f64 {
    if zb > za {
        (ta - za * (tb - ta) / (zb - za)).clamp(t0, tb)
    } else {
        ta + theta * (tb - ta)
    }
}

/// A stick onset within the step `t_a → t_b` of a disc at velocity `w` with acceleration
/// `acc` and jerk `jerk` at `t_a`: the zero of `ω(t_a + Δ) ≈ w + accΔ + ½jerkΔ²`, one Newton
/// correction from the linear zero `−w/acc` (the linear zero where the correction would
/// turn back), clamped to the step; `t_b` where the disc is not decelerating toward 0.
pub(crate) fn onset_time(w: f64, acc: f64, jerk: f64, ta: f64, tb: f64) -> f64 {
    if acc * w < 0.0 {
        let d1 = -w / acc;
        let den = acc + jerk * d1;
        let d2 = if den * acc > 0.0 {
            d1 - 0.5 * jerk * d1 * d1 / den
        } else {
            d1
        };
        (ta + d2).clamp(ta, tb)
    } else {
        tb
    }
}

impl Run<'_> {
    /// One step, its events (when the recorder wants them) and its samples.
    fn step(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        self.k += 1;
        let (k, n) = (self.k, self.n);
        let t_next = if k == n {
            self.seg_end
        } else {
            self.base + k as f64 * self.h
        };
        // Every step but the last has size h (t_next − t differs from h by roundings of t
        // only); the last lands on t_end.
        let out = match (self.input.is_some(), k < n) {
            (false, true) => self
                .stepper
                .step_with(self.cur.t, &self.cur.x, &self.full)?,
            (false, false) => self
                .stepper
                .step(self.cur.t, &self.cur.x, t_next - self.cur.t)?,
            // A time-varying input: the motor torque of this step, from u at its two ends.
            (true, not_last) => {
                let f = self
                    .stepper
                    .motor_force(self.piece.at(self.cur.t), self.piece.at(t_next));
                let size = if !not_last {
                    self.stepper.step_size(self.cur.t, t_next - self.cur.t)?
                } else {
                    self.full
                };
                self.stepper
                    .step_with_force(self.cur.t, &self.cur.x, &size, f)?
            }
        };
        check_finite(t_next, out.x.as_slice())?;
        let s = &mut self.stats;
        s.steps += 1;
        s.newton_iters += u64::from(out.newton_iters);
        s.rhs_evals += u64::from(out.evals);
        s.inexact_steps += u64::from(!out.exact);
        if out.used_enumeration {
            s.lcp_solves += 1;
        } else {
            s.lcp_skipped += 1;
        }
        let next = Point {
            t: t_next,
            x: out.x,
            mode: out.mode,
        };
        if rec.wants_events() {
            for (i, d) in Disc::BOTH.into_iter().enumerate() {
                self.mode_change(i, d, &next, rec);
                if rec.wants_extrema() {
                    self.extremum(i, d, &next, rec);
                }
            }
            // Events detected later are at t ≥ cur.t.
            self.pending.release_before(self.cur.t, rec);
        }
        let cur = self.cur;
        rec.step(cur.t, next.t, next.x.as_slice(), |t, out| {
            out.copy_from_slice(lerp(&cur, &next, t).as_slice())
        });
        self.prev = Some(cur);
        self.cur = next;
        Ok(())
    }

    /// The stick onset, stick exit or reversal of disc `d` (index `i`) in the step to `next`.
    fn mode_change(&mut self, i: usize, d: Disc, next: &Point, rec: &mut Recorder) {
        let (cur, prev) = (self.cur, self.prev);
        let wi = d.index();
        let (m_a, m_b) = (cur.mode[i], next.mode[i]);
        let kind_t = match (m_a, m_b) {
            (DiscMode::Stick, DiscMode::Stick) => None,
            (DiscMode::Stick, slip) => {
                Some((EventKind::StickEnd(d), self.exit_time(d, slip, next)))
            }
            (slip, DiscMode::Stick) => {
                Some((EventKind::StickStart(d), self.onset_time(d, slip, next)))
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
        // Held at rest for exactly one step between slips of opposite sign: a reversal at
        // the scheme's resolution (crate docs), not a stick phase.
        let reversal = matches!(kind_t, Some((EventKind::StickEnd(_), _)))
            && prev.is_some_and(|p| p.mode[i] != DiscMode::Stick && p.mode[i] != m_b)
            && self.pending.remove(EventKind::StickStart(d));
        if reversal && let Some(p) = prev {
            // Zero of ω between the slipping ends of the two steps.
            let (wa, wb) = (p.x[wi], next.x[wi]);
            let t = (p.t + wa * (next.t - p.t) / (wa - wb)).clamp(p.t, next.t);
            let mut x = lerp(&p, next, t);
            x[wi] = 0.0;
            let kind = EventKind::Reversal(d);
            self.pending.push(Found { t, x, kind }, rec);
        } else if let Some((kind, t)) = kind_t {
            let mut x = if t >= cur.t {
                lerp(&cur, next, t)
            } else {
                prev.map_or(cur.x, |p| lerp(&p, &cur, t))
            };
            x[wi] = 0.0;
            self.pending.push(Found { t, x, kind }, rec);
        }
    }

    /// Stick exit of disc `d` into `slip` within the step to `next`: the zero of the applied
    /// torque's excess over the stick interval, linear between the step's ends (it may lie in
    /// the step before: the disc may have been held one step too long).
    fn exit_time(&self, d: Disc, slip: DiscMode, next: &Point) -> f64 {
        let (model, cur) = (self.model, &self.cur);
        let (lo, hi) = model.friction(d).static_interval();
        let z = |x: &State, t: f64| {
            let ta = model.applied_torque(d, x, self.piece.at(t));
            if slip == DiscMode::SlipPos {
                ta - hi
            } else {
                lo - ta
            }
        };
        let (za, zb) = (z(&cur.x, cur.t), z(&next.x, next.t));
        let t0 = self.prev.map_or(cur.t, |p| p.t);
        exit_time(za, zb, (t0, cur.t, next.t), self.theta)
    }

    /// Stick onset of disc `d` from `slip` within the step to `next`: the zero of
    /// `ω(t_k + Δ) ≈ ω + aΔ + ½jΔ²`, with `a` and `j = ω̈` from the model's vector field and
    /// Jacobian in the slipping mode.
    fn onset_time(&self, d: Disc, slip: DiscMode, next: &Point) -> f64 {
        let (model, cur) = (self.model, &self.cur);
        let wi = d.index();
        let w = cur.x[wi];
        let mut mode = to_mode(&cur.mode);
        mode.set(d, slip);
        let f = model.rhs(&cur.x, self.piece.at(cur.t), mode);
        let acc = f[wi];
        // The input's own rate adds k_m·du/dt / J_u to the upper disc's ω̈.
        // The motor drives the top disc only.
        let drift = if d == Disc::UPPER {
            model.params.k_m * self.piece.slope / model.inertia(d)
        } else {
            0.0
        };
        let jerk = (model.jacobian(&cur.x, 0.0, mode) * f)[wi] + drift;
        onset_time(w, acc, jerk, cur.t, next.t)
    }

    /// An extremum of disc `d`'s velocity while it slips over the last three step ends: the
    /// vertex of the parabola through them.
    fn extremum(&mut self, i: usize, d: Disc, next: &Point, rec: &mut Recorder) {
        let cur = self.cur;
        let Some(p) = self.prev else {
            return;
        };
        if [p.mode[i], cur.mode[i], next.mode[i]].contains(&DiscMode::Stick) {
            return;
        }
        let wi = d.index();
        let Some((kind, t)) = vertex(d, [p.t, cur.t, next.t], [p.x[wi], cur.x[wi], next.x[wi]])
        else {
            return;
        };
        let mut x = quad([&p, &cur, next], t);
        // The other disc's velocity is smooth over the three points only if its mode is:
        // across its stick onset or exit the parabola would overshoot ω = 0 (a negative ω_l
        // in a stick-slip cycle's metrics, with no reversal). There it is interpolated on the
        // step that holds t, which keeps its sign.
        let o = 1 - i;
        if p.mode[o] != cur.mode[o] || cur.mode[o] != next.mode[o] {
            let (a, b) = if t <= cur.t { (&p, &cur) } else { (&cur, next) };
            x[1 + o] = lerp(a, b, t)[1 + o];
        }
        self.pending.push(Found { t, x, kind }, rec);
    }
}

impl Integration for Run<'_> {
    type Checkpoint = Saved;

    fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        if std::mem::take(&mut self.release_waiting) {
            self.pending.release_before(self.cur.t, rec);
            if rec.halted() {
                return Ok(());
            }
        }
        loop {
            while self.k < self.n {
                self.step(rec)?;
                if rec.halted() {
                    return Ok(());
                }
            }
            // A breakpoint of the input: the next piece, and the step grid from there, as a
            // run started there would step.
            let Some(input) = self.input.filter(|_| self.seg_end < self.t_end) else {
                break;
            };
            self.piece = input.piece(self.seg_end);
            self.base = self.seg_end;
            self.seg_end = self.piece.end.min(self.t_end);
            self.k = 0;
            self.n = steps_to(self.seg_end, self.base, self.h) as u64;
        }
        self.pending.release_before(f64::INFINITY, rec);
        Ok(())
    }

    /// The end of the step on which the jump was decided (its pending events included).
    fn checkpoint(&self, _anchor: &Event) -> Saved {
        Saved {
            cur: self.cur,
            prev: self.prev,
            pending: self.pending,
            base: self.base,
            k: self.k,
            n: self.n,
        }
    }

    fn restore(&mut self, sv: Saved) {
        (self.cur, self.prev, self.pending) = (sv.cur, sv.prev, sv.pending);
        (self.base, self.k, self.n) = (sv.base, sv.k, sv.n);
        self.release_waiting = false;
    }

    /// The step grid restarts at the shifted step end.
    fn shift(&mut self, _anchor: &Event, dt: f64) {
        self.cur.t += dt;
        if let Some(p) = self.prev.as_mut() {
            p.t += dt;
        }
        self.pending.shift(dt);
        (self.base, self.k) = (self.cur.t, 0);
        self.n = steps_to(self.t_end, self.base, self.h) as u64;
        self.release_waiting = true;
    }
}

impl MoreauOptions {
    /// Checks the options; the error names the field and the bad value.
    fn validate(&self) -> Result<(), SolveError> {
        if !(self.theta >= 0.5 && self.theta <= 1.0) {
            return Err(FieldError::num("theta", self.theta, "must lie in [1/2, 1]").into());
        }
        if self.max_newton == 0 {
            return Err(FieldError::num("max_newton", 0.0, "must be at least 1").into());
        }
        Ok(())
    }
}

impl Solver for MoreauSolver {
    fn name(&self) -> &'static str {
        "moreau"
    }

    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        // The scene's step, or the default one from a scene that sets a tolerance.
        let h = scene.checked_step()?;
        let x0 = scene.x0_state()?;
        check_finite(0.0, x0.as_slice())?;
        let o = &self.options;
        o.validate()?;
        let (u, t_end) = (scene.u_at(0.0), scene.t_end);
        let input = scene.input.as_ref().filter(|_| scene.is_time_varying());
        let piece = scene.piece(0.0);
        let seg_end = piece.end.min(t_end);
        // (The step count bounds the whole horizon; a piece's count is its share of it.)
        let n = steps_to(t_end, 0.0, h);
        if n.is_nan() || n > o.max_steps as f64 {
            return Err(SolveError::TooManySteps {
                t: 0.0,
                max_steps: o.max_steps,
            });
        }
        let n = steps_to(seg_end, 0.0, h) as u64;
        let stepper = Stepper::new(model, u, o);
        let full = stepper.step_size(0.0, h)?;
        // The scheme's error on the fixtures' cycles is second order, ≈ 0.6·h² in the period
        // (crate docs), so h² plays the adaptive solvers' tolerance.
        let mut rec = Recorder::new(scene, x0.as_slice(), h * h, o.skip_verify);
        rec.reserve(n as usize);
        let m0 = model.mode_at(&x0, u);
        let mut run = Run {
            model,
            stepper,
            full,
            piece,
            input,
            h,
            t_end,
            seg_end,
            theta: o.theta,
            base: 0.0,
            k: 0,
            n,
            cur: Point {
                t: 0.0,
                x: x0,
                mode: [m0.upper(), m0.lower()],
            },
            prev: None,
            pending: Pending::new(),
            release_waiting: false,
            stats: Stats::default(),
        };
        rec.drive(&mut run)?;
        let cur = run.cur;
        Ok(rec.finish(t_end, cur.x.as_slice(), to_mode(&cur.mode), run.stats))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A list of released events, halted while `halt` is set.
    struct List {
        events: Vec<Found>,
        halt: bool,
    }

    impl Release for List {
        fn take(&mut self, e: &Found) {
            self.events.push(*e);
        }

        fn halted(&self) -> bool {
            self.halt
        }
    }

    fn ev(t: f64) -> Found {
        Found {
            t,
            x: State::zeros(),
            kind: EventKind::Max(Disc::LOWER),
        }
    }

    /// Events come out in time order, an overfull buffer releases its earliest (even while a
    /// jump waits), and a waiting jump stops the ordinary release.
    #[test]
    fn pending_events_leave_in_time_order_and_never_overflow() {
        let times =
            |s: &List, from: usize| -> Vec<f64> { s.events[from..].iter().map(|e| e.t).collect() };
        let mut p = Pending::new();
        let mut s = List {
            events: Vec::new(),
            halt: true,
        };
        for k in 0..PENDING + 4 {
            p.push(ev(k as f64), &mut s);
        }
        assert_eq!(
            times(&s, 0),
            [0.0, 1.0, 2.0, 3.0],
            "the overflow released the earliest"
        );
        p.release_before(f64::INFINITY, &mut s);
        assert_eq!(times(&s, 0).len(), 4, "halted by the waiting jump");
        s.halt = false;
        p.release_before(8.0, &mut s);
        assert_eq!(times(&s, 4), [4.0, 5.0, 6.0, 7.0]);
        assert!(p.remove(EventKind::Max(Disc::LOWER)));
        assert!(!p.remove(EventKind::Min(Disc::LOWER)));
        p.shift(100.0);
        p.release_before(f64::INFINITY, &mut s);
        // 19 was the latest and was removed; the rest moved by 100 s.
        assert_eq!(times(&s, 8), (108..=118).map(f64::from).collect::<Vec<_>>());
    }
}
