//! The switch-model field, its guards, and the event-located integration loop.

use nalgebra::{Const, DefaultAllocator, Dim, Dyn, allocator::Allocator};
use rotor_model::seam::{
    Event, EventKind, EventRef, Input, Integration, Piece, Recorder, Scene, SolveError, Solver,
    Stats, Trajectory,
};
use rotor_model::{ChainModel, ChainParams, Disc, DiscMode, FieldError, Mode, Model};

use crate::dopri5::{Dopri5, Dopri5Error, Dopri5Options, Vector};

/// An extremum is reported only if ω moved by more than this many tolerances (relative to
/// 1 + |ω|) since the extremum found before it, without a region change between: the
/// integration error in ω is of the order of the tolerance, so smaller turns are not
/// resolved (10: one decade of margin).
const EXTREMUM_RESOLUTION: f64 = 10.0;

/// The step bound tied to the friction laws' scales, `k·(tol/1e-10)^{1/5}·min_d τ_fric,d`
/// with `τ_fric,d = v_d J_d/T_d` of [`rotor_model::TimeScales`] (docs/methods.md, "Steps tied
/// to the model's scales"): the time a disc accelerating at its scale takes to cross its
/// friction law's velocity scale. A step much longer than the one that resolves the field on
/// that scale (∝ τ·tol^{1/5} for DOPRI5) can cross the law's steep part near rest before the
/// controller sees it. k = 8, as for the event solver; at the comparisons' tol 1e-10 the
/// default h_max = 0.1 s is shorter on almost every parameter set (measured: +0.2 % field
/// evaluations over 1000 random sets, `rotor_analysis::solvers/examples/step_scales.rs`).
pub fn step_bound(model: &Model, tol: f64, k: f64) -> f64 {
    let s = model.time_scales();
    k * (tol / 1e-10).powf(1.0 / 5.0) * s.friction[0].min(s.friction[1])
}

/// [`step_bound`] for a chain: `k·(tol/1e-10)^{1/5}·min_i τ_fric,i` over its discs, with
/// `τ_fric,i = v_i/(T_i/J_i)` (the law's velocity scale over the disc's acceleration scale,
/// as [`rotor_model::TimeScales`] defines it for the rig; ∞ for a law without a velocity
/// scale). On a chain of two it is the rig's bound to the last bit.
pub fn chain_step_bound(model: &ChainModel, tol: f64, k: f64) -> f64 {
    let tau = (0..model.discs())
        .map(|i| model.friction_scales(i).0)
        .fold(f64::INFINITY, f64::min);
    k * (tol / 1e-10).powf(1.0 / 5.0) * tau
}

/// Settings of the switch-model solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwitchOptions {
    /// Half-width η of the stick band `|ω| ≤ η` [rad/s]; 0 gives the exact Filippov solution.
    ///
    /// Default `1e-10`. A stuck disc keeps the velocity it entered the band with (|ω| ≤ η,
    /// ω̇ = 0), so the spring drifts by up to η·t_stick per stick phase and every steady
    /// metric differs from the exact Filippov solution (η = 0) at first order in η (period
    /// ≈ 0.07·η relative, stick time ≤ 4·η relative; `tests/switch.rs`,
    /// `eta_convergence_study`; `examples/eta_study.rs`). The cost does not depend on η
    /// (ω̇ = 0 is not stiff: field evaluations within 1 % from η = 1e-5 to 1e-10), so η is
    /// the smallest that keeps this error below the integration error at the comparisons'
    /// tol 1e-10 (≈ 7e-12 relative on the period), and the stuck velocity (≤ η) 10× below
    /// the 1e-9 rad/s at which the grade counts a sample stuck.
    pub eta: f64,
    /// Largest number of step attempts.
    pub max_steps: u64,
    /// Largest step, in s; also bounds the gap between guard samples (≤ h_max/`guard_samples`).
    pub h_max: f64,
    /// The step bound's multiple `k` at tolerance 1e-10: the step is at most
    /// `min(h_max, k·(tol/1e-10)^{1/5}·τ_fric)` ([`step_bound`],
    /// [`rotor_model::Model::time_scales`]). ∞ turns the bound off.
    pub h_scale: f64,
    /// Number of equal sub-intervals of each step on which guards are sampled (≥ 1), so that
    /// a guard that dips below 0 and back inside one step is still seen.
    pub guard_samples: usize,
    /// Zeno guard: this many switches within `zeno_window` seconds is an error.
    pub zeno_count: u32,
    /// Zeno guard window, in s.
    pub zeno_window: f64,
    /// [`rotor_model::seam::Output::Metrics`]: how close, in tolerances, the first return after
    /// skipped periods must come to the return before them ([`rotor_model::seam::FastForward`]);
    /// 0 rejects every skip (a check of the undo).
    pub skip_verify: f64,
}

impl Default for SwitchOptions {
    fn default() -> Self {
        SwitchOptions {
            eta: 1e-10,
            max_steps: 20_000_000,
            h_max: 0.1,
            h_scale: 8.0,
            guard_samples: 5,
            zeno_count: 1000,
            zeno_window: 1e-9,
            skip_verify: rotor_model::seam::fast_forward::VERIFY_TOLERANCES,
        }
    }
}

/// The switch-model solver (name `"switch"`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SwitchSolver {
    /// The band η, step and Zeno limits, guard sampling and the fast-forward's check.
    pub options: SwitchOptions,
}

/// Region of one disc (see the crate docs); `s = ±1` is a side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Region {
    /// `s·ω > η`: the smooth branch `T_f^s(ω)`.
    Slip(f64),
    /// `|ω| ≤ η` (ω held where it entered the band), `T_ex` inside the stick interval:
    /// `T_f = T_ex`.
    Stick,
    /// `|ω| ≤ η`, `T_ex` beyond the bound on side `s`: `T_f` = that bound.
    Trans(f64),
    /// Held at `ω = s·η` with `T_ex` in the band's sliver beyond the bound: `T_f = T_ex`.
    Edge(f64),
}

impl Region {
    fn disc_mode(self) -> DiscMode {
        match self {
            Region::Stick => DiscMode::Stick,
            Region::Slip(s) | Region::Trans(s) | Region::Edge(s) => DiscMode::slip_of(s),
        }
    }
}

/// Friction data of one disc, precomputed.
#[derive(Debug, Clone, Copy)]
struct Law {
    disc: Disc,
    /// The disc's position (its index in the model), and its velocity's index in the state.
    pos: usize,
    idx: usize,
    j: f64,
    lo: f64,
    hi: f64,
    set_valued: bool,
    /// `T_f^+(η)` and `T_f^−(−η)`: the slip torques at the band edges.
    edge_pos: f64,
    edge_neg: f64,
}

impl Law {
    fn bound(&self, s: f64) -> f64 {
        if s > 0.0 { self.hi } else { self.lo }
    }
    fn edge_torque(&self, s: f64) -> f64 {
        if s > 0.0 {
            self.edge_pos
        } else {
            self.edge_neg
        }
    }
}

/// What a guard does when it reaches 0 (each guard is `> 0` inside its region).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Guard {
    /// Set-valued disc in `Slip(s)`: `g = s·ω − η` (band entry).
    BandEntry(f64),
    /// Smooth disc in `Slip(s)`: `g = s·ω + ν` (branch flip, reversal; ν the
    /// resolution margin, `Field::zero_margin`).
    Zero(f64),
    /// `Stick`: `g = s·(bound_s − T_ex)` (break-away toward side s).
    StickExit(f64),
    /// `Trans(s)`: `g = η − s·ω` (leaves the band on side s).
    TransOut(f64),
    /// `Trans(s)` or `Edge(s)`: `g = s·(T_ex − bound_s)` (T_ex back inside: stick).
    Back(f64),
    /// `Edge(s)`: `g = s·(T_f^s(sη) − T_ex)` (the slip field points outward: slip).
    EdgeOut(f64),
}

/// The switch-model vector field with the current regions, one per disc of a chain (the rig
/// is its chain of two, whose field [`ChainModel`] evaluates bit for bit as the rig's).
#[derive(Debug, Clone)]
struct Field<'a> {
    model: &'a ChainModel,
    /// The input's piece, `u(t) = u0 + slope·(t − t0)` up to the next breakpoint.
    piece: Piece,
    eta: f64,
    laws: Vec<Law>,
    regions: Vec<Region>,
    /// Per disc: its `Trans` region began at rest (a stick exit, or the start of the run in
    /// the band), so a sign change of ω inside the band is the stuck velocity's, not a
    /// reversal (a stuck disc keeps the velocity it entered the band with, which may lie on
    /// either side of 0).
    from_rest: Vec<bool>,
    /// ν: how far past 0 the velocity of a disc without a stick interval must go before
    /// its branch flips, the absolute tolerance. The step control holds a velocity's error
    /// to about that, so a sign inside it is not resolved: a disc deep in a chain just after
    /// a start from rest has ω ~ 1e-23 rad/s whose sign the steps' rounding decides, and a
    /// guard at exactly 0 flipped it back and forth a hundred times a millisecond. The law
    /// is continuous across 0 there, so the branch a margin late changes the torque by at
    /// most `2|Δb|·ν`, and the reversal is reported `ν/|ω̇|` late (a first-order error in
    /// the tolerance, which the run at a tighter tolerance measures).
    zero_margin: f64,
}

impl Field<'_> {
    /// The applied torque on disc k at time t, state x (the input at t on the piece).
    #[inline]
    fn tex(&self, k: usize, t: f64, x: &[f64]) -> f64 {
        self.model
            .applied_torque(self.laws[k].pos, x, self.piece.at(t))
    }

    /// `ω̇_i = (T_ex,i − T_f,i)/J_i` with the region's friction (table in the crate docs).
    fn accel(&self, k: usize, t: f64, x: &[f64]) -> f64 {
        let l = &self.laws[k];
        let tex = self.tex(k, t, x);
        match self.regions[k] {
            Region::Slip(s) => (tex - self.model.friction(l.pos).torque(x[l.idx], s)) / l.j,
            Region::Stick | Region::Edge(_) => 0.0,
            Region::Trans(s) => (tex - l.bound(s)) / l.j,
        }
    }

    /// `ẋ = [ω_1 − ω_2, …, ω_{N−1} − ω_N, ω̇_1, …, ω̇_N]` (the rig: `[ω_u − ω_l, ω̇_u, ω̇_l]`),
    /// written into `dx`.
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        let n = self.laws.len();
        for i in 0..n - 1 {
            dx[i] = x[n - 1 + i] - x[n + i];
        }
        for (k, l) in self.laws.iter().enumerate() {
            dx[l.idx] = self.accel(k, t, x);
        }
    }

    /// The guards of disc k in its region (at most two).
    fn guards(&self, k: usize) -> [Option<Guard>; 2] {
        let l = &self.laws[k];
        match self.regions[k] {
            Region::Slip(s) if l.set_valued => [Some(Guard::BandEntry(s)), None],
            Region::Slip(s) => [Some(Guard::Zero(s)), None],
            Region::Stick => [Some(Guard::StickExit(1.0)), Some(Guard::StickExit(-1.0))],
            Region::Trans(s) => [Some(Guard::TransOut(s)), Some(Guard::Back(s))],
            Region::Edge(s) => [Some(Guard::EdgeOut(s)), Some(Guard::Back(s))],
        }
    }

    fn guard_value(&self, k: usize, g: Guard, t: f64, x: &[f64]) -> f64 {
        let l = &self.laws[k];
        let w = x[l.idx];
        match g {
            Guard::BandEntry(s) => s * w - self.eta,
            Guard::Zero(s) => s * w + self.zero_margin,
            Guard::StickExit(s) => s * (l.bound(s) - self.tex(k, t, x)),
            Guard::TransOut(s) => self.eta - s * w,
            Guard::Back(s) => s * (self.tex(k, t, x) - l.bound(s)),
            Guard::EdgeOut(s) => s * (l.edge_torque(s) - self.tex(k, t, x)),
        }
    }

    /// Region of a set-valued disc found inside the band (|ω| ≤ η) with applied torque `tex`,
    /// having arrived from side `from` (0: no side, e.g. at t = 0). Returns the region and
    /// the velocity to set (None: keep).
    fn band_region(&self, k: usize, tex: f64, from: f64) -> (Region, Option<f64>) {
        let l = &self.laws[k];
        if l.lo <= tex && tex <= l.hi {
            return (Region::Stick, self.stick_velocity());
        }
        let side = if tex > l.hi { 1.0 } else { -1.0 };
        if side == from {
            // Beyond the bound on the side it came from: the sliver (see crate docs).
            return self.edge_or_slip(k, tex, side);
        }
        if self.eta == 0.0 {
            (Region::Slip(side), None)
        } else {
            (Region::Trans(side), None)
        }
    }

    /// The velocity set on entering `Stick`: none, ω keeps the value it entered the band
    /// with (Leine's published model); with η = 0 the band is the point 0 and ω is put on it
    /// (a change at the event-location rounding).
    fn stick_velocity(&self) -> Option<f64> {
        if self.eta == 0.0 { Some(0.0) } else { None }
    }

    /// At the band edge `ω = sη`: slip if the slip field points outward, else hold (Edge).
    fn edge_or_slip(&self, k: usize, tex: f64, s: f64) -> (Region, Option<f64>) {
        let l = &self.laws[k];
        if self.eta == 0.0 || s * (tex - l.edge_torque(s)) >= 0.0 {
            (Region::Slip(s), None)
        } else {
            (Region::Edge(s), Some(s * self.eta))
        }
    }

    /// Initial region of disc k at state x at the start time t (0, or a breakpoint of the
    /// input); the velocity to set (η = 0 stick: 0).
    fn initial_region(&self, k: usize, t: f64, x: &[f64]) -> (Region, Option<f64>) {
        let l = &self.laws[k];
        let w = x[l.idx];
        let tex = self.tex(k, t, x);
        if !l.set_valued {
            let s = if w > 0.0 {
                1.0
            } else if w < 0.0 {
                -1.0
            } else if tex - l.hi >= 0.0 {
                1.0
            } else {
                -1.0
            };
            return (Region::Slip(s), None);
        }
        if w.abs() > self.eta {
            return (Region::Slip(w.signum()), None);
        }
        self.band_region(k, tex, 0.0)
    }

    /// The switch when guard g of disc k fires at state x: new region, velocity to set (the
    /// band edge `sη` exactly for `Edge`; 0 for stick only when η = 0), event.
    fn fire(
        &self,
        k: usize,
        g: Guard,
        t: f64,
        x: &[f64],
    ) -> (Region, Option<f64>, Option<EventKind>) {
        let d = self.laws[k].disc;
        let tex = self.tex(k, t, x);
        match g {
            Guard::BandEntry(s) => {
                let (r, w) = self.band_region(k, tex, s);
                let ev = match r {
                    Region::Stick => Some(EventKind::StickStart(d)),
                    // η = 0: passing straight through ω = 0.
                    Region::Slip(s2) if s2 != s => Some(EventKind::Reversal(d)),
                    _ => None,
                };
                (r, w, ev)
            }
            Guard::Zero(s) => (Region::Slip(-s), None, Some(EventKind::Reversal(d))),
            Guard::StickExit(s) => {
                let r = if self.eta == 0.0 {
                    Region::Slip(s)
                } else {
                    Region::Trans(s)
                };
                (r, None, Some(EventKind::StickEnd(d)))
            }
            Guard::TransOut(s) => {
                let (r, w) = self.edge_or_slip(k, tex, s);
                (r, w, None)
            }
            Guard::Back(_) => (
                Region::Stick,
                self.stick_velocity(),
                Some(EventKind::StickStart(d)),
            ),
            Guard::EdgeOut(s) => (Region::Slip(s), None, None),
        }
    }
}

/// Illinois (modified regula falsi) on a bracket `g(ta)·g(tb) < 0`, `ta < tb`, to
/// `|t_b − t_a| ≤ 1e-14·max(1, |t|)`. Returns the bracket end on `tb`'s side of the root
/// (so the state there has crossed). The second value counts evaluations of `g`.
fn illinois(mut g: impl FnMut(f64) -> f64, ta: f64, ga: f64, tb: f64, gb: f64) -> (f64, u64) {
    if gb == 0.0 {
        return (tb, 0);
    }
    let after_pos = gb > 0.0;
    let (mut x0, mut f0, mut x1, mut f1) = (ta, ga, tb, gb);
    let tol = 1e-14 * tb.abs().max(1.0);
    let mut side = 0i8;
    let mut n = 0;
    for _ in 0..200 {
        if (x1 - x0).abs() <= tol {
            break;
        }
        let (lo, hi) = (x0.min(x1), x0.max(x1));
        let mut c = (x0 * f1 - x1 * f0) / (f1 - f0);
        if !(c > lo && c < hi) {
            c = 0.5 * (lo + hi);
            if !(c > lo && c < hi) {
                break;
            }
        }
        let fc = g(c);
        n += 1;
        if fc == 0.0 {
            return (c, n);
        }
        if (fc > 0.0) == (f1 > 0.0) {
            x1 = c;
            f1 = fc;
            if side == -1 {
                f0 *= 0.5;
            }
            side = -1;
        } else {
            x0 = c;
            f0 = fc;
            if side == 1 {
                f1 *= 0.5;
            }
            side = 1;
        }
    }
    if (f0 > 0.0) == after_pos {
        (x0, n)
    } else {
        (x1, n)
    }
}

/// First crossing of a guard `g` (`> 0` inside its region) to `≤ 0`, given its samples
/// `(t_j, g_j)` over one step. The sign at `t_0` is not trusted (after a restart on the
/// guard's own surface it is ±rounding): the first sample `j ≥ 1` with `g_j ≤ 0` is sought;
/// its bracket `[t_{j−1}, t_j]` is refined by [`illinois`], or, if `g` was already `≤ 0` at
/// `t_0` and still is at `t_1`, the crossing is `t_0` itself. Interior samples catch a guard
/// that dips below 0 and back within the step (both ends positive). A guard that stays
/// exactly 0 (a disc at rest on its own switching surface, e.g. a smooth law at u = 0) has
/// not crossed: firing it would flip the region back and forth forever.
fn first_crossing(vals: &[(f64, f64)], g: impl FnMut(f64) -> f64) -> Option<f64> {
    let j =
        (1..vals.len()).find(|&j| vals[j].1 < 0.0 || (vals[j].1 == 0.0 && vals[j - 1].1 > 0.0))?;
    let (ta, ga) = vals[j - 1];
    let (tb, gb) = vals[j];
    if ga <= 0.0 {
        return Some(ta);
    }
    Some(illinois(g, ta, ga, tb, gb).0)
}

/// Equally spaced points `t0 + j (t1 − t0)/m`, `j = 0..=m` (m ≤ 16).
fn sample_times(t0: f64, t1: f64, m: usize) -> impl Iterator<Item = f64> {
    (0..=m).map(move |j| {
        if j == m {
            t1
        } else {
            t0 + (t1 - t0) * (j as f64 / m as f64)
        }
    })
}

/// The time of each of the last `count` switches: that many within `window` seconds is a
/// Zeno-like accumulation.
struct Zeno {
    times: Vec<f64>,
    next: usize,
    count: u32,
    window: f64,
}

impl Zeno {
    fn new(count: u32, window: f64) -> Zeno {
        Zeno {
            times: vec![f64::NEG_INFINITY; count.max(1) as usize],
            next: 0,
            count,
            window,
        }
    }

    /// Records a switch at `t`; the error if it completes an accumulation.
    fn record(&mut self, t: f64) -> Result<(), SolveError> {
        let oldest = std::mem::replace(&mut self.times[self.next], t);
        self.next = (self.next + 1) % self.times.len();
        if t - oldest < self.window {
            return Err(SolveError::Zeno {
                t,
                count: self.count,
                window: self.window,
            });
        }
        Ok(())
    }
}

/// What the run goes back to if a jump is undone: the anchor's time and state, and the
/// regions and extremum memory there.
struct Saved<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    t: f64,
    y: Vector<D>,
    regions: PerDisc<Region>,
    last_extremum: PerDisc<Option<f64>>,
}

/// Per-disc values kept at a checkpoint: inline for the rig's two discs, so that a skip of
/// whole periods allocates nothing (the skip runs on the rig only), on the heap for a chain.
#[derive(Debug, Clone)]
enum PerDisc<T: Copy> {
    Two([T; 2]),
    Any(Vec<T>),
}

impl<T: Copy> PerDisc<T> {
    fn of(v: &[T]) -> PerDisc<T> {
        match v {
            [a, b] => PerDisc::Two([*a, *b]),
            _ => PerDisc::Any(v.to_vec()),
        }
    }

    fn copy_to(&self, out: &mut [T]) {
        match self {
            PerDisc::Two(a) => out.copy_from_slice(a),
            PerDisc::Any(v) => out.copy_from_slice(v),
        }
    }
}

fn map_err(e: Dopri5Error, x: &[f64]) -> SolveError {
    match e {
        Dopri5Error::StepSizeUnderflow { t, h } => SolveError::StepSizeUnderflow {
            t,
            h,
            x: x.to_vec(),
        },
        Dopri5Error::TooManySteps { t, max_steps } => SolveError::TooManySteps { t, max_steps },
    }
}

/// An error naming the state if it holds a value that is not finite.
fn check_finite(t: f64, x: &[f64]) -> Result<(), SolveError> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SolveError::NonFinite { t, x: x.to_vec() })
    }
}

/// The switch-model integration: DOPRI5 on the field of the current regions, cut at every
/// region change (the earliest guard root on the step's dense output) and restarted there.
/// `D` is the state's size: `Const<3>` for the rig (on the stack), `Dyn` for a chain.
struct Run<'a, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    field: Field<'a>,
    integ: Dopri5<D>,
    t_end: f64,
    /// Where the current piece of the input ends: its next breakpoint, or `t_end`.
    seg_end: f64,
    /// A time-varying input (`None`: the constant input, one piece to `t_end`).
    input: Option<&'a Input>,
    tol: f64,
    /// Guard samples per step.
    samples: usize,
    zeno: Zeno,
    /// ω at the last extremum found per disc since the disc's last region change: an
    /// extremum within EXTREMUM_RESOLUTION tolerances of it is not resolved by the
    /// integration (rounding-level turns while settling onto an equilibrium).
    last_extremum: Vec<Option<f64>>,
    /// Markers found in one step (reused): time, disc, kind.
    found: Vec<(f64, usize, EventKind)>,
    /// The dense output at a step's guard samples, and one more state (reused).
    xs: Vec<Vector<D>>,
    y: Vector<D>,
}

impl<D: Dim> Run<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Restarts the integration at `(t, y)` with the current regions' field.
    fn restart(&mut self, t: f64, y: &Vector<D>) {
        let f = &self.field;
        self.integ
            .restart(t, y, &mut |t, y: &Vector<D>, dy: &mut Vector<D>| {
                f.rhs(t, y.as_slice(), dy.as_mut_slice())
            });
    }

    /// One accepted step, up to its first region change: the markers before it, the samples,
    /// the switch itself, and the restart after it.
    fn step(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        let f = &self.field;
        self.integ
            .step(
                &mut |t, y: &Vector<D>, dy: &mut Vector<D>| {
                    f.rhs(t, y.as_slice(), dy.as_mut_slice())
                },
                self.seg_end,
            )
            .map_err(|e| {
                // A failed step leaves the stepper where it was: its state is the one before.
                let t = self.integ.t();
                let y = self.integ.y().as_slice();
                let mut dy = y.to_vec();
                f.rhs(t, y, &mut dy);
                if dy.iter().any(|v| !v.is_finite()) {
                    SolveError::NonFinite { t, x: y.to_vec() }
                } else {
                    map_err(e, y)
                }
            })?;
        check_finite(self.integ.t(), self.integ.y().as_slice())?;
        let (t0, t1) = self.integ.last_step();
        let hit = self.first_switch(t0, t1);
        let te = hit.map_or(t1, |h| h.0);
        if rec.wants_events() && te > t0 {
            self.markers(rec, t0, t1, te);
            if rec.halted() {
                return Ok(());
            }
        }
        let integ = &self.integ;
        let dense = |t: f64, out: &mut [f64]| integ.dense_into(t, out);
        let Some((tr, k, g)) = hit else {
            rec.step(t0, t1, integ.y().as_slice(), dense);
            return Ok(());
        };
        if tr == t1 {
            self.y.copy_from(integ.y());
        } else {
            integ.dense_into(tr, self.y.as_mut_slice());
        }
        let f = &self.field;
        let (r, w, ev) = f.fire(k, g, tr, self.y.as_slice());
        if let Some(w) = w {
            self.y[f.laws[k].idx] = w;
        }
        rec.step(t0, tr, self.y.as_slice(), dense);
        self.field.regions[k] = r;
        self.field.from_rest[k] = matches!(g, Guard::StickExit(_));
        self.last_extremum[k] = None;
        match ev {
            Some(kind) => rec.event(EventRef {
                t: tr,
                x: self.y.as_slice(),
                kind,
            }),
            None => rec.count_switch(),
        }
        self.zeno.record(tr)?;
        if rec.halted() {
            return Ok(());
        }
        let f = &self.field;
        self.integ
            .restart(tr, &self.y, &mut |t, y: &Vector<D>, dy: &mut Vector<D>| {
                f.rhs(t, y.as_slice(), dy.as_mut_slice())
            });
        check_finite(tr, self.y.as_slice())
    }

    /// At a breakpoint of the input (the run's step ended on it): the next piece, and a
    /// restart as at the start of a run, the regions chosen afresh from the state and the new
    /// value (a stuck disc whose applied torque a step of u put out of its interval leaves
    /// stick here, reported as a stick exit; one put back into it sticks) and the first step
    /// from Hairer's heuristic again.
    fn breakpoint(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        let Some(input) = self.input else {
            return Ok(());
        };
        let t = self.integ.t();
        let before = self.field.regions.clone();
        self.field.piece = input.piece(t);
        self.seg_end = self.field.piece.end.min(self.t_end);
        self.y.copy_from(self.integ.y());
        self.field.start(t, self.y.as_mut_slice());
        for (k, was) in before.into_iter().enumerate() {
            let d = self.field.laws[k].disc;
            let is = self.field.regions[k];
            let kind = match (was, is) {
                (Region::Stick, Region::Stick) => None,
                (Region::Stick, _) => Some(EventKind::StickEnd(d)),
                (_, Region::Stick) => Some(EventKind::StickStart(d)),
                _ => None,
            };
            if let Some(kind) = kind {
                rec.event(EventRef {
                    t,
                    x: self.y.as_slice(),
                    kind,
                });
            }
        }
        // As a fresh run: no extremum remembered.
        self.last_extremum.fill(None);
        let f = &self.field;
        self.integ.reinit(
            t,
            &self.y,
            self.seg_end,
            &mut |t, y: &Vector<D>, dy: &mut Vector<D>| f.rhs(t, y.as_slice(), dy.as_mut_slice()),
        );
        check_finite(t, self.y.as_slice())
    }

    /// The earliest guard root on the dense output of `[t0, t1]`: its time, disc and guard.
    fn first_switch(&mut self, t0: f64, t1: f64) -> Option<(f64, usize, Guard)> {
        let m = self.samples;
        for (j, t) in sample_times(t0, t1, m).enumerate() {
            if j == m {
                self.xs[j].copy_from(self.integ.y());
            } else {
                self.integ.dense_into(t, self.xs[j].as_mut_slice());
            }
        }
        let (f, integ, xs) = (&self.field, &self.integ, &self.xs);
        let mut hit: Option<(f64, usize, Guard)> = None;
        for k in 0..f.laws.len() {
            for g in f.guards(k).into_iter().flatten() {
                let mut vals = [(0.0, 0.0); 17];
                for (j, t) in sample_times(t0, t1, m).enumerate() {
                    vals[j] = (t, f.guard_value(k, g, t, xs[j].as_slice()));
                }
                let guard = |tt: f64| f.guard_value(k, g, tt, integ.dense(tt).as_slice());
                let root =
                    first_crossing(&vals[..=m], guard).or_else(|| self.dip(k, g, &vals[..=m]));
                if let Some(tr) = root
                    && hit.is_none_or(|h| tr < h.0)
                {
                    hit = Some((tr, k, g));
                }
            }
        }
        hit
    }

    /// A velocity guard (`s·ω − η`, `s·ω` or `η − s·ω`) that dips below 0 and back between
    /// two samples, as an orbit does that grazes the band. Without this check a tangential
    /// approach that spends less than a sample interval inside the band (1.6e-4 s near the
    /// grazing orbit at 4.6153 V, Table 1) passes through it unseen, with ω_l below 0 and no
    /// stick; and a disc in `Trans` whose applied torque comes back inside the stick interval
    /// soon after it entered the band (so ω turns back before the next sample) leaves the band
    /// on the far side unseen and is then held stuck there by `Back`, outside the band
    /// (ω_l = −3.5e-7 rad/s with η = 1e-10, found by the random energy-balance test).
    ///
    /// Where the slope of `σ·ω` (σ = s, or −s for `TransOut`) on the dense output turns from
    /// negative to positive between two samples, its minimum is located (Illinois on the
    /// slope) and the guard evaluated there; if it is negative, its root before the minimum is
    /// the crossing. The slope is the interpolant's derivative ([`Dopri5::dense_slope`]): no
    /// field evaluation.
    fn dip(&self, k: usize, g: Guard, vals: &[(f64, f64)]) -> Option<f64> {
        let s = match g {
            Guard::BandEntry(s) | Guard::Zero(s) => s,
            Guard::TransOut(s) => -s,
            _ => return None,
        };
        let (f, integ) = (&self.field, &self.integ);
        let idx = f.laws[k].idx;
        let slope = |t: f64| s * integ.dense_slope(t, idx);
        let mut prev = slope(vals[0].0);
        for j in 1..vals.len() {
            let cur = slope(vals[j].0);
            if prev < 0.0 && cur > 0.0 && vals[j - 1].1 > 0.0 {
                let (ta, tb) = (vals[j - 1].0, vals[j].0);
                let (tm, _) = illinois(slope, ta, prev, tb, cur);
                let gm = f.guard_value(k, g, tm, integ.dense(tm).as_slice());
                if gm < 0.0 {
                    let guard = |tt: f64| f.guard_value(k, g, tt, integ.dense(tt).as_slice());
                    return Some(illinois(guard, ta, vals[j - 1].1, tm, gm).0);
                }
            }
            prev = cur;
        }
        None
    }

    /// Markers in `(t0, te]` (reversals inside the band, extrema of ω when metrics are asked),
    /// in time order, to the recorder; stops after an event on which it halts.
    fn markers(&mut self, rec: &mut Recorder, t0: f64, t1: f64, te: f64) {
        let m = self.samples;
        let extrema = rec.wants_extrema();
        self.found.clear();
        let mut extra_rhs = 0u64;
        let f = &self.field;
        for k in 0..f.laws.len() {
            let l = f.laws[k];
            let (kind_pos, kind_neg, sign): (EventKind, EventKind, f64) = match f.regions[k] {
                Region::Trans(s) if !f.from_rest[k] => {
                    (EventKind::Reversal(l.disc), EventKind::Reversal(l.disc), s)
                }
                Region::Slip(_) if extrema => (EventKind::Max(l.disc), EventKind::Min(l.disc), 0.0),
                _ => continue,
            };
            let integ = &self.integ;
            // Reversal: g = s·ω upward through 0; extrema: g = ω̇, either way.
            let mut gfun = |t: f64| {
                let y = if t == t1 {
                    integ.y().clone()
                } else {
                    integ.dense(t)
                };
                if sign != 0.0 {
                    sign * y[l.idx]
                } else {
                    extra_rhs += 1;
                    f.accel(k, t, y.as_slice())
                }
            };
            let mut prev = (t0, gfun(t0));
            for t in sample_times(t0, te, m).skip(1) {
                let gv = gfun(t);
                let crossing = if sign != 0.0 {
                    prev.1 < 0.0 && gv >= 0.0
                } else {
                    prev.1 != 0.0 && (gv == 0.0 || (prev.1 > 0.0) != (gv > 0.0))
                };
                if crossing {
                    let (tr, _) = illinois(&mut gfun, prev.0, prev.1, t, gv);
                    let kind = if sign != 0.0 || prev.1 > 0.0 {
                        kind_pos
                    } else {
                        kind_neg
                    };
                    self.found.push((tr, k, kind));
                }
                prev = (t, gv);
            }
        }
        self.integ.count_rhs(extra_rhs);
        self.found.sort_by(|a, b| a.0.total_cmp(&b.0));
        for i in 0..self.found.len() {
            let (t, k, kind) = self.found[i];
            self.integ.dense_into(t, self.y.as_mut_slice());
            if let EventKind::Max(_) | EventKind::Min(_) = kind {
                let w = self.y[self.field.laws[k].idx];
                let slot = &mut self.last_extremum[k];
                let resolvable = slot.replace(w).is_none_or(|w_prev| {
                    (w - w_prev).abs() > EXTREMUM_RESOLUTION * self.tol * (1.0 + w.abs())
                });
                if !resolvable {
                    continue;
                }
            }
            rec.event(EventRef {
                t,
                x: self.y.as_slice(),
                kind,
            });
            if rec.halted() {
                return;
            }
        }
    }
}

impl<D: Dim> Integration for Run<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    type Checkpoint = Saved<D>;

    fn advance(&mut self, rec: &mut Recorder) -> Result<(), SolveError> {
        while self.integ.t() < self.t_end {
            self.step(rec)?;
            if rec.halted() {
                break;
            }
            if self.integ.t() == self.seg_end && self.seg_end < self.t_end {
                self.breakpoint(rec)?;
            }
        }
        Ok(())
    }

    /// The anchor's time and state (the run stops at the event it halts on).
    fn checkpoint(&self, anchor: &Event) -> Saved<D> {
        Saved {
            t: anchor.t,
            y: self.state_of(&anchor.x),
            regions: PerDisc::of(&self.field.regions),
            last_extremum: PerDisc::of(&self.last_extremum),
        }
    }

    fn restore(&mut self, sv: Saved<D>) {
        sv.regions.copy_to(&mut self.field.regions);
        sv.last_extremum.copy_to(&mut self.last_extremum);
        self.restart(sv.t, &sv.y);
    }

    fn shift(&mut self, anchor: &Event, dt: f64) {
        let y = self.state_of(&anchor.x);
        self.restart(anchor.t + dt, &y);
    }
}

impl<D: Dim> Run<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// A state of the run's size holding `x` (on the stack for the rig).
    fn state_of(&self, x: &[f64]) -> Vector<D> {
        let mut y = self.y.clone();
        y.as_mut_slice().copy_from_slice(x);
        y
    }
}

impl SwitchOptions {
    /// Checks the options; the error names the field and the bad value.
    fn validate(&self) -> Result<(), SolveError> {
        let bad = |field: &str, value: f64, reason: &str| {
            Err(FieldError::num(field, value, reason).into())
        };
        if !(self.eta >= 0.0 && self.eta.is_finite()) {
            return bad("eta", self.eta, "must be finite and >= 0");
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max", self.h_max, "must be positive");
        }
        if self.h_scale.is_nan() || self.h_scale <= 0.0 {
            return bad("h_scale", self.h_scale, "must be positive");
        }
        if self.zeno_window.is_nan() || self.zeno_window < 0.0 {
            return bad("zeno_window", self.zeno_window, "must be >= 0");
        }
        Ok(())
    }
}

impl<'a> Field<'a> {
    /// The field of `model` at input `u` with band `eta` and branch margin `zero_margin`
    /// (ν), every disc in `Stick` until
    /// [`Field::start`] sets their regions.
    fn new(model: &'a ChainModel, piece: Piece, eta: f64, zero_margin: f64) -> Field<'a> {
        let n = model.discs();
        let law = |pos: usize| {
            let f = model.friction(pos);
            let (lo, hi) = f.static_interval();
            Law {
                disc: Disc::at(pos),
                pos,
                idx: model.omega(pos),
                j: model.inertia(pos),
                lo,
                hi,
                set_valued: f.is_set_valued(),
                edge_pos: f.torque(eta, 1.0),
                edge_neg: f.torque(-eta, -1.0),
            }
        };
        Field {
            model,
            piece,
            eta,
            laws: (0..n).map(law).collect(),
            regions: vec![Region::Stick; n],
            from_rest: vec![true; n],
            zero_margin,
        }
    }

    /// Sets the initial regions at `x` at time `t` and puts into `x` the state the run starts
    /// from (a velocity in the band is kept; with η = 0 a stuck disc's is 0).
    fn start(&mut self, t: f64, x: &mut [f64]) {
        for k in 0..self.laws.len() {
            let (r, w) = self.initial_region(k, t, x);
            self.regions[k] = r;
            self.from_rest[k] = true;
            if let Some(w) = w {
                x[self.laws[k].idx] = w;
            }
        }
    }

    /// The mode of every disc, from its region.
    fn mode(&self) -> Mode {
        let modes: Vec<DiscMode> = self.regions.iter().map(|r| r.disc_mode()).collect();
        Mode::from_discs(&modes)
    }
}

impl SwitchSolver {
    /// Integrates the switch model of a chain of N discs over `[0, t_end]` (state
    /// `[α_1 … α_{N−1}, ω_1 … ω_N]`), as [`Solver::simulate`] does the rig: one region per
    /// disc, each disc's guards located on the dense output. The rig's own run is this one on
    /// its chain of two, with the state on the stack.
    pub fn simulate_chain(
        &self,
        model: &ChainModel,
        scene: &Scene,
    ) -> Result<Trajectory, SolveError> {
        scene.validate_chain(model)?;
        let bound = chain_step_bound(model, scene.tol(), self.options.h_scale);
        let x0 = nalgebra::DVector::from_column_slice(&scene.x0);
        self.run::<Dyn>(model, scene, x0, bound)
    }

    /// The run on `model` from `x0` (the scene's initial state, of the model's size), with the
    /// step bounded by `bound` as well as by `h_max`.
    fn run<D: Dim>(
        &self,
        model: &ChainModel,
        scene: &Scene,
        mut x0: Vector<D>,
        bound: f64,
    ) -> Result<Trajectory, SolveError>
    where
        DefaultAllocator: Allocator<D>,
    {
        let o = self.options;
        o.validate()?;
        let varying = scene.input.as_ref().filter(|_| scene.is_time_varying());
        let piece = scene.piece(0.0);
        let tol = scene.tol();
        let mut field = Field::new(model, piece, o.eta, tol);
        field.start(0.0, x0.as_mut_slice());
        check_finite(0.0, x0.as_slice())?;
        let mut rec = Recorder::new(scene, x0.as_slice(), tol, o.skip_verify);
        let dopts = Dopri5Options {
            rtol: tol,
            atol: tol,
            h0: None,
            h_max: o.h_max.min(bound),
            max_steps: o.max_steps,
            ..Dopri5Options::default()
        };
        let seg_end = piece.end.min(scene.t_end);
        let integ = Dopri5::new(dopts, 0.0, x0.clone(), seg_end, &mut |t,
                                                                       y: &Vector<D>,
                                                                       dy: &mut Vector<
            D,
        >| {
            field.rhs(t, y.as_slice(), dy.as_mut_slice())
        });
        let samples = o.guard_samples.clamp(1, 16);
        let n = model.discs();
        let mut run = Run {
            field,
            integ,
            t_end: scene.t_end,
            seg_end,
            input: varying,
            tol,
            samples,
            zeno: Zeno::new(o.zeno_count, o.zeno_window),
            last_extremum: vec![None; n],
            found: Vec::new(),
            xs: vec![x0.clone(); samples + 1],
            y: x0,
        };
        rec.drive(&mut run)?;
        let x_final = run.integ.y().as_slice();
        check_finite(run.integ.t(), x_final)?;
        let c = run.integ.counters();
        let stats = Stats {
            steps: c.accepted,
            rejected: c.rejected,
            rhs_evals: c.rhs_evals,
            ..Stats::default()
        };
        Ok(rec.finish(scene.t_end, x_final, run.field.mode(), stats))
    }
}

impl Solver for SwitchSolver {
    fn name(&self) -> &'static str {
        "switch"
    }

    /// Integrates the switch model over `[0, t_end]` with DOPRI5 at `rtol = atol = scene.tol()`,
    /// locating every region change (guards of the crate docs) and restarting there.
    fn simulate(&self, model: &Model, scene: &Scene) -> Result<Trajectory, SolveError> {
        scene.validate_for(model)?;
        let chain = ChainModel::new(&ChainParams::from_params(&model.params));
        let bound = step_bound(model, scene.tol(), self.options.h_scale);
        self.run::<Const<3>>(&chain, scene, scene.x0_state()?, bound)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn illinois_finds_the_root_to_1e14_and_returns_the_crossed_side() {
        let g = |t: f64| t.cos();
        let (t, n) = illinois(g, 1.0, g(1.0), 2.0, g(2.0));
        // Tolerance 1e-14·max(1, t) is the documented stopping width; +1 ulp-scale slack
        // (measured 2.2e-16: the bracket closes well inside it).
        assert!((t - std::f64::consts::FRAC_PI_2).abs() <= 2e-14, "{t}");
        assert!(g(t) <= 0.0, "on the crossed side");
        // Illinois converges superlinearly: far fewer than the ~47 bisections needed.
        assert!(n < 20, "{n} evaluations");
    }

    #[test]
    fn interior_samples_catch_a_shallow_dip() {
        // g > 0 at both ends of [0, 1], < 0 on (0.5 − √0.02, 0.5 + √0.02).
        let g = |t: f64| (t - 0.5).powi(2) - 0.02;
        let sampled = |m: usize| -> Vec<(f64, f64)> {
            sample_times(0.0, 1.0, m).map(|t| (t, g(t))).collect()
        };
        assert_eq!(first_crossing(&sampled(1), g), None, "ends alone miss it");
        let t = first_crossing(&sampled(5), g).expect("interior samples see it");
        // Illinois' documented stopping width 1e-14·max(1, t) (measured 5.6e-17).
        assert!((t - (0.5 - 0.02f64.sqrt())).abs() < 1e-14, "{t}");
    }

    #[test]
    fn a_guard_resting_on_its_surface_has_not_crossed() {
        let vals = [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0)];
        assert_eq!(first_crossing(&vals, |_| unreachable!()), None);
        // Reaching 0 from inside still fires.
        let vals = [(0.0, 1.0), (0.5, 0.0), (1.0, 0.0)];
        assert_eq!(first_crossing(&vals, |_| unreachable!()), Some(0.5));
    }

    #[test]
    fn guard_already_crossed_at_restart_fires_at_once() {
        let vals = [(0.0, -1e-17), (0.5, -1.0), (1.0, -2.0)];
        assert_eq!(first_crossing(&vals, |_| unreachable!()), Some(0.0));
        // …but rounding at t_0 alone (the guard then positive) is ignored.
        let vals = [(0.0, -1e-17), (0.5, 1.0), (1.0, 2.0)];
        assert_eq!(first_crossing(&vals, |_| unreachable!()), None);
    }
}
