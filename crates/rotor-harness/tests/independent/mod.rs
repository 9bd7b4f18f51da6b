//! An independent integrator of the Filippov system, written for verifying the reference
//! data (`tests/reference_verified.rs`). It shares nothing with the solvers but the model's
//! vector field per mode and its friction bounds (`rotor_model::Model`): that is the
//! formulation being solved, not a method of solving it.
//!
//! * **Method**: the s-stage Gauss–Legendre collocation method (order 2s, implicit,
//!   A-stable), its tableau computed here from the Legendre polynomial's roots (Newton on the
//!   three-term recurrence) and exact Gauss quadrature of the Lagrange basis; stages by
//!   fixed-point iteration to round-off; fixed steps that land on every grid point; the
//!   solution accumulated with compensated (Kahan) summation.
//! * **Modes** (Filippov, with exact sliding): a slipping disc follows the branch torque of
//!   its direction; a stuck disc has ω ≡ 0 and friction equal to the applied torque.
//! * **Events**: located by re-taking the step from its start with a fraction θ of it and a
//!   root finder (Illinois with bisection) on θ ↦ g(step(θ)), to 1e-15 of the step. Guards:
//!   a slipping disc's velocity reaching 0 (stick if the applied torque lies in the stick
//!   interval, else a reversal); a stuck disc's applied torque reaching a bound of the
//!   interval (exit). Guards are checked at the step's end and at its stage points.
//! * **Extrema** of each slipping disc's velocity (the steady metrics), located the same way
//!   on θ ↦ ω̇(step(θ)).

use rotor_model::seam::EventKind;
use rotor_model::{Disc, DiscMode, Mode, Model, State};

/// A Gauss–Legendre collocation tableau on [0, 1].
#[derive(Debug, Clone)]
pub struct Tableau {
    pub c: Vec<f64>,
    pub b: Vec<f64>,
    pub a: Vec<Vec<f64>>,
}

/// `(P_n(x), P_n'(x))` by the three-term recurrence `(k+1)P_{k+1} = (2k+1)xP_k − kP_{k−1}`.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 1..n {
        let k = k as f64;
        let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
        p0 = p1;
        p1 = p2;
    }
    let n = n as f64;
    (p1, n * (x * p1 - p0) / (x * x - 1.0))
}

impl Tableau {
    /// The s-stage Gauss–Legendre method: nodes the roots of `P_s(2c − 1)`, weights the Gauss
    /// weights, `a_ij = ∫_0^{c_i} l_j` (l_j the Lagrange basis on the nodes), integrated by the
    /// same Gauss rule scaled to [0, c_i] (exact: l_j has degree s − 1).
    pub fn gauss_legendre(s: usize) -> Tableau {
        let mut c = Vec::with_capacity(s);
        let mut b = Vec::with_capacity(s);
        for i in 0..s {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (s as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(s, x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-17 {
                    break;
                }
            }
            let (_, dp) = legendre(s, x);
            c.push(0.5 * (1.0 - x));
            // Gauss weight on [−1, 1] is 2/((1 − x²)P'²); on [0, 1] half of it.
            b.push(1.0 / ((1.0 - x * x) * dp * dp));
        }
        let lagrange = |j: usize, t: f64| -> f64 {
            (0..s)
                .filter(|&m| m != j)
                .map(|m| (t - c[m]) / (c[j] - c[m]))
                .product()
        };
        let a = (0..s)
            .map(|i| {
                (0..s)
                    .map(|j| c[i] * (0..s).map(|k| b[k] * lagrange(j, c[i] * c[k])).sum::<f64>())
                    .collect()
            })
            .collect();
        Tableau { c, b, a }
    }

    pub fn stages(&self) -> usize {
        self.c.len()
    }

    /// One step of `ẋ = f(x)` from `x0` over `h`: the increment `x1 − x0` and the stage
    /// states (approximations of x at `t0 + c_i h`).
    pub fn step(&self, f: &impl Fn(&State) -> State, x0: &State, h: f64) -> (State, Vec<State>) {
        let s = self.stages();
        let f0 = f(x0);
        let mut k = vec![f0; s];
        let mut xs = vec![*x0; s];
        let mut prev = f64::INFINITY;
        for it in 0..100 {
            for (xi, ai) in xs.iter_mut().zip(&self.a) {
                let d = ai
                    .iter()
                    .zip(&k)
                    .fold(State::zeros(), |d, (a, kj)| d + *a * kj);
                *xi = x0 + h * d;
            }
            let mut change = 0.0f64;
            let mut size = 0.0f64;
            for (ki, xi) in k.iter_mut().zip(&xs) {
                let new = f(xi);
                change = change.max((new - *ki).amax());
                size = size.max(new.amax());
                *ki = new;
            }
            // Converged once the change is at rounding level, or has stopped shrinking there
            // (a contraction h·L·ρ(A) ≈ 0.01 per sweep at the steps used: ~8 sweeps).
            if change <= 2.0 * f64::EPSILON * size
                || (it > 3 && change >= prev && change < 1e-13 * (1.0 + size))
            {
                break;
            }
            prev = change;
        }
        let d = self
            .b
            .iter()
            .zip(&k)
            .fold(State::zeros(), |d, (b, ki)| d + *b * ki);
        (h * d, xs)
    }
}

/// A state with its Kahan compensation.
#[derive(Debug, Clone, Copy)]
pub struct Comp {
    pub x: State,
    pub c: State,
}

impl Comp {
    fn plus(&self, d: &State) -> Comp {
        let y = d - self.c;
        let x = self.x + y;
        Comp {
            c: (x - self.x) - y,
            x,
        }
    }
}

/// An event found by the independent integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ev {
    pub t: f64,
    pub x: State,
    pub kind: EventKind,
}

/// A run's results.
#[derive(Debug, Clone)]
pub struct Run {
    /// The state at every grid point `k·dt`.
    pub samples: Vec<(f64, State)>,
    /// Mode switches (stick start, stick end, reversal), in time order.
    pub switches: Vec<Ev>,
    /// Switches and velocity extrema at `t ≥ from`, in time order.
    pub window: Vec<Ev>,
    pub final_state: State,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Guard {
    Velocity(Disc),
    ExitHi(Disc),
    ExitLo(Disc),
}

/// The problem: model, input, and the steps.
pub struct Problem<'a> {
    pub model: &'a Model,
    pub u: f64,
    pub tableau: &'a Tableau,
}

/// A velocity turn is recorded as an extremum only if the velocity moved by more than this
/// (relative to 1 + |ω|) since the last extremum of that disc: smaller turns are rounding
/// noise of a run settled on an equilibrium, and far below the 1e-6 rad/s amplitude at which
/// an oscillation counts as a cycle (rotor_model::seam::steady::EQUILIBRIUM_AMPLITUDE).
const TURN: f64 = 1e-10;

impl Problem<'_> {
    fn field(&self, x: &State, mode: Mode) -> State {
        self.model.rhs(x, self.u, mode)
    }

    /// The state after a step of `h` from `z` in `mode`, with its stage states.
    fn advance(&self, z: &Comp, h: f64, mode: Mode) -> (Comp, Vec<State>) {
        let (d, xs) = self.tableau.step(&|x| self.field(x, mode), &z.x, h);
        let mut next = z.plus(&d);
        for disc in Disc::BOTH {
            if mode.of(disc) == DiscMode::Stick {
                next.x[disc.index()] = 0.0;
                next.c[disc.index()] = 0.0;
            }
        }
        (next, xs)
    }

    fn guards(&self, mode: Mode) -> Vec<Guard> {
        let mut g = Vec::new();
        for d in Disc::BOTH {
            match mode.of(d) {
                DiscMode::Stick => {
                    g.push(Guard::ExitHi(d));
                    g.push(Guard::ExitLo(d));
                }
                _ => g.push(Guard::Velocity(d)),
            }
        }
        g
    }

    /// The guard's value, positive inside the mode.
    fn g(&self, guard: Guard, x: &State, mode: Mode) -> f64 {
        match guard {
            Guard::Velocity(d) => mode.of(d).branch().unwrap_or(1.0) * x[d.index()],
            Guard::ExitHi(d) => {
                self.model.friction(d).static_interval().1 - self.model.applied_torque(d, x, self.u)
            }
            Guard::ExitLo(d) => {
                self.model.applied_torque(d, x, self.u) - self.model.friction(d).static_interval().0
            }
        }
    }

    /// The root in θ ∈ (lo, hi] of `q(θ)` with `q(lo) ≥ 0 > q(hi)` (or the reverse signs),
    /// to 1e-15 in θ (≤ 5e-18 s at the steps used): Illinois, with a bisection every fourth
    /// iterate; returns the bracket's end past the root.
    fn root(&self, q: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
        let (mut qlo, mut qhi) = (q(lo), q(hi));
        let neg_hi = qhi < 0.0;
        let mut side = 0i32;
        for it in 0..300 {
            if hi - lo <= 1e-15 {
                break;
            }
            let secant = hi - qhi * (hi - lo) / (qhi - qlo);
            let m = if it % 4 == 3 || !(secant > lo && secant < hi) {
                0.5 * (lo + hi)
            } else {
                secant
            };
            if m <= lo || m >= hi {
                break;
            }
            let qm = q(m);
            if (qm < 0.0) == neg_hi {
                hi = m;
                qhi = qm;
                if side == 1 {
                    qlo *= 0.5;
                }
                side = 1;
            } else {
                lo = m;
                qlo = qm;
                if side == -1 {
                    qhi *= 0.5;
                }
                side = -1;
            }
        }
        hi
    }

    /// The earliest terminal guard that fires in the step of `hs` from `z`: `(θ, guard)`.
    fn first_guard(
        &self,
        z: &Comp,
        hs: f64,
        mode: Mode,
        z1: &Comp,
        stages: &[State],
    ) -> Option<(f64, Guard)> {
        let mut first: Option<(f64, Guard)> = None;
        for guard in self.guards(mode) {
            if self.g(guard, &z1.x, mode) >= 0.0
                && stages.iter().all(|xs| self.g(guard, xs, mode) >= 0.0)
            {
                continue;
            }
            let q = |th: f64| self.g(guard, &self.advance(z, th * hs, mode).0.x, mode);
            let mut hi = 1.0;
            if q(1.0) >= 0.0 {
                // A dip inside the step: bracket at the first stage point below 0.
                match (0..stages.len()).find(|&i| q(self.tableau.c[i]) < 0.0) {
                    Some(i) => hi = self.tableau.c[i],
                    None => continue,
                }
            }
            let th = self.root(&q, 0.0, hi);
            if first.is_none_or(|(t0, _)| th < t0) {
                first = Some((th, guard));
            }
        }
        first
    }

    /// Integrates from `x0` (in the mode `model.mode_at` gives) over the grid `k·dt`,
    /// `k = 0..=n`, with steps of at most `h`; extrema recorded from `from` on. Within a grid
    /// interval the time is kept as the elapsed time `r` from its start (rounding ε·dt, not
    /// ε·t), the steps dividing what is left of it equally.
    pub fn run(&self, x0: State, dt: f64, n: usize, h: f64, from: f64) -> Run {
        let model = self.model;
        let mut mode = model.mode_at(&x0, self.u);
        let mut z = Comp {
            x: x0,
            c: State::zeros(),
        };
        let mut samples = vec![(0.0, x0)];
        let mut switches = Vec::new();
        let mut window = Vec::new();
        let mut last_ext: [Option<f64>; 2] = [None, None];
        let mut switches_here = 0u32;
        let mut last_switch_t = f64::NAN;
        for k in 1..=n {
            let ta = (k - 1) as f64 * dt;
            let tb = k as f64 * dt;
            let len = tb - ta;
            let mut r = 0.0;
            while r < len {
                let m = ((len - r) / h * (1.0 - 1e-12)).ceil().max(1.0);
                let hs = (len - r) / m;
                let (z1, stages) = self.advance(&z, hs, mode);
                match self.first_guard(&z, hs, mode, &z1, &stages) {
                    Some((th, guard)) => {
                        let mut ze = self.advance(&z, th * hs, mode).0;
                        self.extrema(&z, th * hs, mode, ta + r, from, &mut last_ext, &mut window);
                        r += th * hs;
                        let te = ta + r;
                        let (new_mode, kind) = self.transition(guard, &mut ze.x, mode);
                        if te == last_switch_t {
                            switches_here += 1;
                            assert!(switches_here < 8, "Zeno at t = {te}");
                        } else {
                            switches_here = 0;
                        }
                        last_switch_t = te;
                        ze.c = State::zeros();
                        mode = new_mode;
                        last_ext = [None, None];
                        if let Some(kind) = kind {
                            let e = Ev {
                                t: te,
                                x: ze.x,
                                kind,
                            };
                            switches.push(e);
                            if te >= from {
                                window.push(e);
                            }
                        }
                        z = ze;
                    }
                    None => {
                        self.extrema(&z, hs, mode, ta + r, from, &mut last_ext, &mut window);
                        r = if m <= 1.0 { len } else { r + hs };
                        z = z1;
                    }
                }
            }
            samples.push((tb, z.x));
        }
        Run {
            samples,
            switches,
            window,
            final_state: z.x,
        }
    }

    /// Extrema of the slipping discs' velocities in the step `[t, t + h]` from `z`.
    #[allow(clippy::too_many_arguments)]
    fn extrema(
        &self,
        z: &Comp,
        h: f64,
        mode: Mode,
        t: f64,
        from: f64,
        last_ext: &mut [Option<f64>; 2],
        window: &mut Vec<Ev>,
    ) {
        if t + h < from {
            return;
        }
        for (n, d) in Disc::BOTH.into_iter().enumerate() {
            if mode.of(d) == DiscMode::Stick {
                continue;
            }
            let i = d.index();
            let rate = |th: f64| {
                let x = self.advance(z, th * h, mode).0.x;
                self.field(&x, mode)[i]
            };
            let (r0, r1) = (self.field(&z.x, mode)[i], rate(1.0));
            // A turn: the rate changes sign (strictly) over the step.
            if !(r0 > 0.0 && r1 <= 0.0 || r0 < 0.0 && r1 >= 0.0) {
                continue;
            }
            let th = if r1 == 0.0 {
                1.0
            } else {
                self.root(&rate, 0.0, 1.0)
            };
            let te = t + th * h;
            if te < from {
                continue;
            }
            let x = self.advance(z, th * h, mode).0.x;
            let w = x[i];
            if last_ext[n].is_some_and(|l| (w - l).abs() <= TURN * (1.0 + w.abs())) {
                continue;
            }
            last_ext[n] = Some(w);
            window.push(Ev {
                t: te,
                x,
                kind: if r0 > 0.0 {
                    EventKind::Max(d)
                } else {
                    EventKind::Min(d)
                },
            });
        }
    }

    /// The mode after a guard fired, and the event: Filippov's rule at ω = 0 (stick when the
    /// applied torque lies in the stick interval, else the disc crosses to the other branch).
    fn transition(&self, g: Guard, x: &mut State, mode: Mode) -> (Mode, Option<EventKind>) {
        let mut m = mode;
        match g {
            Guard::Velocity(d) => {
                x[d.index()] = 0.0;
                let fr = self.model.friction(d);
                let (lo, hi) = fr.static_interval();
                let t_ex = self.model.applied_torque(d, x, self.u);
                if fr.is_set_valued() && (lo..=hi).contains(&t_ex) {
                    m.set(d, DiscMode::Stick);
                    (m, Some(EventKind::StickStart(d)))
                } else {
                    let s = mode.of(d).branch().unwrap_or(1.0);
                    m.set(
                        d,
                        if s > 0.0 {
                            DiscMode::SlipNeg
                        } else {
                            DiscMode::SlipPos
                        },
                    );
                    (m, Some(EventKind::Reversal(d)))
                }
            }
            Guard::ExitHi(d) => {
                m.set(d, DiscMode::SlipPos);
                (m, Some(EventKind::StickEnd(d)))
            }
            Guard::ExitLo(d) => {
                m.set(d, DiscMode::SlipNeg);
                (m, Some(EventKind::StickEnd(d)))
            }
        }
    }
}
