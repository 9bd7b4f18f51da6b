//! Event-driven integration of the Filippov system with exact sliding (stick).
//!
//! After Piiroinen & Kuznetsov (ACM TOMS 34(3), 2008): the state carries a *mode* per disc
//! (slip+, slip−, stick). Between events the smooth field of the mode is integrated with
//! DOP853. In stick the disc's velocity is held at exactly 0 and its friction is Utkin's
//! equivalent control (the applied torque); stick ends when that torque leaves the stick
//! interval `[T_f(0⁻), T_f(0⁺)]`. Guards:
//!
//! * slipping disc on branch s: `g = s·ω` (reaches 0: stick or reversal, decided from the
//!   one-sided accelerations, i.e. whether the applied torque lies inside the interval);
//! * stuck disc: `g = T_f(0⁺) − T_ex` and `g = T_ex − T_f(0⁻)` (stick exit to slip±);
//! * when extrema are asked: `g = ω̇` of each slipping disc (maxima and minima; a turn of
//!   less than 10 tolerances since the previous extremum is below resolution and not
//!   reported);
//! * when a Poincaré section is asked: `g = ω_l − c`, upward (on a chain, the last disc).
//!
//! A chain of N discs has these guards per disc (its stick conditions are per disc: the
//! inertia is diagonal); the rig is the chain of two, with its state on the stack.
//!
//! Guards are sampled at interior points of the dense output and, for the velocity and
//! stick-exit guards, their derivative too, so that a shallow dip below zero inside one step
//! is not missed. A scan fires a guard that goes from positive to ≤ 0; guards that are
//! already at or past 0 at a switch or a run's start (simultaneous events, a disc stuck
//! exactly on an edge) are handled there, before the next step ([`Integrator::settle`]).
//! Guards are functions of the state along the dense output, so at interior samples their
//! rates come from the dense output's own derivative (no field evaluation); at the step's
//! ends that derivative is the field (the interpolant is Hermite). A located terminal root
//! is refined by re-taking the RK step exactly to it (8th-order state) plus a Newton
//! correction in time; an extremum, bracketed on the dense output's derivative, is moved by
//! Newton's method to the root of the field's acceleration along the dense output, its state
//! re-taken by an RK step to that time (the dense output's error is not controlled) and
//! polished once more from there. A section crossing is refined as a terminal root.

use nalgebra::{DefaultAllocator, Dim, U1, allocator::Allocator};
use rotor_model::seam::{EventKind, EventRef, Piece, SolveError, Stats, check_finite};
use rotor_model::{ChainModel, ChainParams, Disc, DiscMode, Mode, Model};
use std::cell::Cell;
use std::sync::Arc;

use crate::dop853::{Dense, Dop853, Vector};

/// Options of the event-driven solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventOptions {
    /// Largest step \[s\]; a quarter of the lower disc's natural period (2π/√(k_θ/J_l) ≈ 4.2 s)
    /// is far above what the tolerance allows on a cycle, so it only matters on equilibria.
    pub h_max: f64,
    /// The step bound's multiple `k` at tolerance 1e-10: while a disc slips, the step is at
    /// most `k·(tol/1e-10)^{1/8}·τ_fric` of its friction law ([`step_bound`],
    /// [`rotor_model::Model::time_scales`]) unless lifted (`lift`). ∞ turns the bound off.
    pub h_scale: f64,
    /// ε of the step bound's lift: the bound does not cap a step over which the slipping
    /// disc's velocity, predicted from its rate and acceleration at the step's start, moves by
    /// less than `ε·k·(tol/1e-10)^{1/8}·v` (the integrator's `ScaleBound`). 0 by default: the
    /// bound everywhere; [`LIFT_FRACTION`] is the measured candidate.
    pub lift: f64,
    /// `M` of the step bound's lift at the solver's resolution: the bound does not cap a step
    /// over which the slipping disc's velocity, predicted as for `lift`, moves by less than
    /// `M·tol·(1 + |ω|)`, motion the solver does not resolve (extrema closer than
    /// `EXTREMUM_RESOLUTION` = 10 tolerances are not reported). [`LIFT_RESOLUTION`] = 10 by
    /// default; 0 turns this lift off.
    pub lift_resolution: f64,
    /// Lift the step bound while the slipping disc cannot reach its law's steep region within
    /// the step: its speed lies beyond the region's edge at the tolerance
    /// ([`rotor_model::Friction::steep_edge`]) by more than its velocity, predicted as for
    /// `lift`, moves over the step. Off by default: it halves the work on a transient far from
    /// rest (Table 1 at 6 V) and doubles it, at equal error, on a small oscillation about an
    /// equilibrium (docs/methods.md §1a, "Only where the steep region is within reach").
    pub steep_lift: bool,
    /// The largest defect, in tolerances, between a step's dense output and the exact state
    /// re-taken to an event in it that lets the step stand; a larger one rejects the step
    /// ([`DEFECT_LIMIT`] by default, ∞ turns the check off).
    pub defect_limit: f64,
    /// Limit on accepted + rejected steps.
    pub max_steps: u64,
    /// Zeno guard: this many mode switches within `zeno_window` (relative to max(1, t)) is
    /// an error.
    pub zeno_count: u32,
    /// Zeno guard's window \[s\] at t ≤ 1 s; it widens in proportion to t beyond (the
    /// window is `zeno_window·max(1, t)`).
    pub zeno_window: f64,
    /// Sample intervals per step for guard detection (at most 64).
    pub guard_samples: usize,
    /// [`rotor_model::seam::Output::Metrics`]: how close, in tolerances, the first return after
    /// skipped periods must come to the return before them ([`rotor_model::seam::FastForward`]);
    /// 0 rejects every skip (a check of the undo).
    pub skip_verify: f64,
}

impl Default for EventOptions {
    fn default() -> Self {
        EventOptions {
            h_max: 1.0,
            h_scale: 8.0,
            // The lift at ε·k·v is off: it costs the reference accuracy on settled equilibria
            // (docs/methods.md §1a, "The lift").
            lift: 0.0,
            lift_resolution: LIFT_RESOLUTION,
            // Off: measured against the bound everywhere, it costs as much on the
            // equilibrium scenes as it saves on a transient far from rest (docs/methods.md
            // §1a, "Only where the steep region is within reach").
            steep_lift: false,
            defect_limit: DEFECT_LIMIT,
            max_steps: 50_000_000,
            zeno_count: 64,
            zeno_window: 1e-9,
            guard_samples: 4,
            skip_verify: rotor_model::seam::fast_forward::VERIFY_TOLERANCES,
        }
    }
}

/// The step bound tied to the friction laws' scales: in a mode where disc d slips, on a law
/// with a velocity scale,
///
/// ```text
/// h ≤ max(h_d, t_lift,d),   h_d = k·(tol/1e-10)^{1/8}·τ_fric,d,   τ_fric,d = v_d J_d/T_d,
/// t_lift,d:  |ω̇_d|·t + ½|ω̈_d|·t² = max(ε·k·(tol/1e-10)^{1/8}·v_d, M·tol·(1 + |ω_d|))
/// ```
///
/// ([`rotor_model::TimeScales`]; `ω̇, ω̈` at the step's start, `ω̈ = ((∂f/∂x)·f)_d`). `h_d` is
/// the time a disc accelerating at its scale `T_d/J_d` takes to cross k·(tol/1e-10)^{1/8} of
/// its law's velocity scale `v_d`; `t_lift,d` the time the disc, as it actually moves, takes to
/// cross ε = [`LIFT_FRACTION`] of that. A stuck disc's law does not enter the field (its
/// velocity is exactly 0 and its friction the applied torque), so it bounds nothing.
///
/// Why the bound: near rest the lower disc's law varies on v (the exponential family's
/// `2/w_1`). The step-size controller predicts the next step's error from the last one; a step
/// that crosses many v at once carries the field from where that variation is exponentially
/// small (and invisible to the error estimate) to where it is O(1), and was measured to be
/// accepted at 0.4 of the tolerance with a true error of 1e4 tolerances. A DOP853 step that
/// resolves a field varying on τ to a tolerance tol is ∝ τ·tol^{1/8}, so a fixed multiple of
/// it costs a fixed fraction at every tolerance. k = 8 measured (docs/methods.md, "Steps tied
/// to the model's scales"; `rotor_analysis::solvers/examples/step_scales.rs`): over 1000 random sets at
/// tol 1e-10 it brought the limit cycles whose metrics erred by more than 100 tolerances from
/// 25 to 2, for 14 % more field evaluations.
///
/// The lift at ε·k·v is off by default (`EventOptions::lift` = 0): it costs the reference
/// accuracy on settled equilibria (docs/methods.md §1a, "The lift"). On by default is the lift
/// at the solver's resolution, `M·tol·(1 + |ω_d|)` with M = [`LIFT_RESOLUTION`] = 10
/// (`EventOptions::lift_resolution`): motion below it is not resolved either way, and it
/// keeps every error measured. Why the lift: a step over which the velocity moves by at most ε·k·v (ε = 1e-5: 2.8e-5
/// rad/s on Table 1 at tol 1e-10) sees the law as linear, wherever it lies on it, and cannot
/// reach a part of it that the last step did not see. Such steps are those of a disc
/// settling onto a slipping equilibrium, where the bound cost up to 1.8× the unbounded
/// solver's work for nothing. ε is measured, not derived: 23 of the 25 cycles above are
/// oscillations of 1e-3 to 1e-2 rad/s far from rest (slow spirals still decaying at
/// 50–100 s), whose metrics err as tol/amplitude, and the bound repairs them only by its
/// shorter steps; a lift at ε = 1e-4 let 3 of them err again, ε = 1e-5 none.
///
/// Off by default is the lift away from the steep region (`EventOptions::steep_lift`): the
/// bound does not cap a step over which the disc cannot reach its law's steep region,
/// `|ω_d| ≤ e_d` with `e_d` the edge at the tolerance ([`rotor_model::Friction::steep_edge`]):
///
/// ```text
/// |ω_d| − e_d > 0  and  |ω̇_d|·h + ½|ω̈_d|·h² ≤ |ω_d| − e_d   ⇒   no bound from disc d.
/// ```
///
/// Beyond the edge the law varies only on its slower scales, which the error estimate sees.
/// What the bound guards against, a step from the flat part into the steep one, is what the
/// lift keeps. What it gives up is the bound's shorter steps on oscillations far from rest.
/// Their errors stay within 100 tolerances times the conditioning of what they report (a
/// period read from extrema of an oscillation of amplitude A is conditioned as
/// `(1 + |ω|)·T/(2π²A)`: an extremum's time moves by δω/(AΩ²)), but where such a small
/// oscillation is all that is measured, the bound's steps reach a given error with up to half
/// the work of a tighter tolerance. On Table 1 at 6 V from rest the lift halves the work at
/// equal error; 1e-3 rad/s from the equilibrium at 2.5 V it doubles it (docs/methods.md §1a,
/// "Only where the steep region is within reach").
#[derive(Debug, Clone)]
pub(crate) struct ScaleBound {
    /// `h_d = k·(tol/1e-10)^{1/8}·τ_fric,d` per disc (∞: no bound).
    per_disc: Vec<f64>,
    /// The velocity change `ε·k·(tol/1e-10)^{1/8}·v_d` below which the bound is lifted (0:
    /// never), per disc.
    lift: Vec<f64>,
    /// `M·tol`: the bound is also lifted where the velocity moves by less than
    /// `M·tol·(1 + |ω_d|)` (0: never).
    resolution: f64,
    /// The edge of each disc's steep region at the tolerance
    /// ([`rotor_model::Friction::steep_edge`]); ∞: never lifted for being far from it.
    steep: Vec<f64>,
}

/// The measured ε of the step bound's lift (`EventOptions::lift`, off by default): the bound
/// is lifted where the slipping disc's velocity moves by less than ε times what the bound lets
/// it move at its acceleration scale, `k·(tol/1e-10)^{1/8}·v`. Measured (docs/methods.md
/// §1a, "The lift").
pub const LIFT_FRACTION: f64 = 1e-5;

/// The `M` of the lift at the solver's resolution (`EventOptions::lift_resolution`, the
/// default): the bound is lifted where the slipping disc's velocity moves by less than
/// `M·tol·(1 + |ω|)` over the step, the resolution below which extrema are not reported
/// (`EXTREMUM_RESOLUTION`). Measured (docs/methods.md §1a, "The lift").
pub const LIFT_RESOLUTION: f64 = EXTREMUM_RESOLUTION;

/// The first time `t > 0` at which `|ω̇|·t + ½|ω̈|·t² = dv` (`dv > 0`): the velocity of a
/// disc starting with these rates cannot have moved by `dv` sooner if they stay below them
/// in magnitude (exact for a harmonic oscillation, `|Δω| ≤ |ω̇₀|t + ½|ω̈₀|t²`). ∞ if both
/// rates are 0. `2·dv/(|ω̇| + √(ω̇² + 2|ω̈|·dv))` avoids the cancellation of the textbook
/// root.
pub(crate) fn excursion_time(dv: f64, rate: f64, accel: f64) -> f64 {
    let r = rate.abs();
    let den = r + (r * r + 2.0 * accel.abs() * dv).sqrt();
    if den > 0.0 {
        2.0 * dv / den
    } else {
        f64::INFINITY
    }
}

impl ScaleBound {
    pub(crate) fn new(
        model: &ChainModel,
        tol: f64,
        k: f64,
        lift: f64,
        resolution: f64,
        steep: bool,
    ) -> ScaleBound {
        let k = k * (tol / 1e-10).powf(1.0 / 8.0);
        let scales: Vec<(f64, f64)> = (0..model.discs())
            .map(|i| model.friction_scales(i))
            .collect();
        ScaleBound {
            per_disc: scales.iter().map(|&(tau, _)| k * tau).collect(),
            lift: scales
                .iter()
                .map(|&(_, v)| {
                    let dv = lift * k * v;
                    if dv.is_finite() { dv } else { 0.0 }
                })
                .collect(),
            resolution: resolution * tol,
            steep: (0..model.discs())
                .map(|i| match model.friction(i).steep_edge(tol) {
                    Some(edge) if steep => edge,
                    _ => f64::INFINITY,
                })
                .collect(),
        }
    }

    /// The bound in `mode` at the state `x` with the field `f` there, for a step the
    /// controller would make `h` long: the shortest over the slipping discs of
    /// `max(h_d, t_lift,d)` ([`excursion_time`]), the lift's velocity change being
    /// `max(ε·k·(tol/1e-10)^{1/8}·v_d, M·tol·(1 + |ω_d|))`, or no bound from a disc that
    /// cannot reach its steep region within `h` (the same excursion against `|ω_d| − e_d`).
    /// `accel(i)` gives disc i's
    /// acceleration rate `((∂f/∂x)·f)_{ω_i}` at x; it is called only for a disc whose `h_d` is
    /// shorter than `h`.
    pub(crate) fn at(
        &self,
        model: &ChainModel,
        mode: Mode,
        x: &[f64],
        f: &[f64],
        h: f64,
        accel: impl Fn(usize) -> f64,
    ) -> f64 {
        let mut bound = f64::INFINITY;
        for (i, (&h_i, &lift)) in self.per_disc.iter().zip(&self.lift).enumerate() {
            if mode.is_stuck(Disc::at(i)) {
                continue;
            }
            let mut h_d = h_i;
            if h_d < h {
                let k = model.omega(i);
                let a = accel(i);
                let dv = lift.max(self.resolution * (1.0 + x[k].abs()));
                if dv > 0.0 {
                    h_d = h_d.max(excursion_time(dv, f[k], a));
                }
                let far = x[k].abs() - self.steep[i];
                if h_d < h && far > 0.0 && excursion_time(far, f[k], a) >= h {
                    // The step cannot carry the disc into its steep region: no bound from it.
                    h_d = f64::INFINITY;
                }
            }
            bound = bound.min(h_d);
        }
        bound
    }
}

/// The friction-scale step bound (the integrator's `ScaleBound`) with both discs slipping,
/// `k·(tol/1e-10)^{1/8}·min(τ_fric,u, τ_fric,l)`.
pub fn step_bound(model: &Model, tol: f64, k: f64) -> f64 {
    let s = model.time_scales();
    k * (tol / 1e-10).powf(1.0 / 8.0) * s.friction[0].min(s.friction[1])
}

/// The largest defect, in tolerances, between a step's dense output and the exact RK state
/// re-taken to an event in it (`Integrator::defect`) that lets the step stand. Measured (a
/// temporary log of every event's defect) over the metrics-only stress scene on 100 random
/// parameter sets at tol 1e-10 (`rotor_analysis::solvers/examples/step_scales.rs`): 9168 events on
/// steps under 0.25 s, median 0.03, 99.9th percentile and largest 4.35 (short steps whose
/// error estimate was 0.31); on the 0.7–1 s steps that the step bound now forbids, up to 180.
/// 10 lies above every trusted step. With the step bound on, the check fired 194 times in the
/// 2000 runs of 1000 draws (seed 5 of the example, which counts `defect_rejections`) at no
/// measurable cost, and the steady metrics' errors were the same with the check off
/// (`STEP_SCALES_DEFECT=inf`): the redone steps lie in transients or move the metrics by less
/// than their resolution. It stays as a cheap alarm that also corrects the step it catches.
pub const DEFECT_LIMIT: f64 = 10.0;

/// An extremum is reported only if the velocity moved by more than this many tolerances
/// (relative to 1 + |ω|) since the extremum found before it: the integration error in ω is
/// of the order of the tolerance, so smaller turns are not resolved (10: one decade of
/// margin). Settling onto an equilibrium, the velocity otherwise turns at rounding level
/// hundreds of times.
const EXTREMUM_RESOLUTION: f64 = 10.0;

/// Largest number of guard samples per step.
const MAX_GUARD_SAMPLES: usize = 64;

/// What to do with a run as it goes.
pub(crate) trait Sink<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// An accepted step `[t0, t1]` whose dense output is `dense` (valid on `[t0, t1]`).
    fn step(&mut self, _dense: &Dense<D>, _t0: f64, _t1: f64, _x1: &Vector<D>, _mode: Mode) {}
    /// An event (in time order).
    fn event(&mut self, _e: EventRef<'_>) {}
    /// Whether to stop after this event.
    fn stop_after(&mut self, _e: EventRef<'_>) -> bool {
        false
    }
    /// An upward crossing of the Poincaré section; whether to stop there.
    fn section(&mut self, _t: f64, _x: &Vector<D>) -> bool {
        false
    }
}

/// A run's end.
#[derive(Debug, Clone)]
pub(crate) struct RunEnd<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t: f64,
    pub x: Vector<D>,
    pub mode: Mode,
}

/// Which guard fired.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
enum Guard {
    /// Velocity of a slipping disc reached 0.
    Velocity(Disc),
    /// Applied torque of a stuck disc reached the upper / lower bound.
    ExitHi(Disc),
    ExitLo(Disc),
    /// Extremum of a slipping disc's velocity (max if `true`).
    Extremum(Disc, bool),
    /// Upward crossing of ω_l = c.
    #[default]
    Section,
}

impl Guard {
    fn terminal(self) -> bool {
        matches!(
            self,
            Guard::Velocity(_) | Guard::ExitHi(_) | Guard::ExitLo(_)
        )
    }
}

/// A guard event found in a step.
#[derive(Debug, Clone, Copy)]
struct Detected {
    /// Its time.
    t: f64,
    guard: Guard,
    /// Where a search for later events in the same step starts (at or after `t`).
    resume: f64,
}

/// Where a run is between steps.
struct Cursor<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    t: f64,
    x: Vector<D>,
    mode: Mode,
    /// The field at `(t, x)`.
    f0: Vector<D>,
    /// The next step size to try.
    h: f64,
    /// Time of the last mode switch: the acceleration of a disc leaving stick starts at 0, so
    /// its first sign is rounding; extremum roots right at a switch are not extrema.
    t_switch: f64,
}

/// How the events of an accepted step end it.
enum Scan<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// No terminal guard: the step stands.
    Through,
    /// The first terminal guard (a mode switch) at this time.
    Terminal(f64, Guard),
    /// The sink stopped the run after an event.
    Stop(RunEnd<D>),
}

/// The times of the last `n` mode switches (the Zeno guard).
struct Recent {
    times: [f64; 64],
    count: usize,
    n: usize,
}

impl Recent {
    fn new(n: usize) -> Recent {
        Recent {
            times: [f64::NEG_INFINITY; 64],
            count: 0,
            n,
        }
    }

    /// Records a switch at `t`: `n` of them within `window·max(1, |t|)` seconds is an error.
    fn record(&mut self, t: f64, window: f64) -> Result<(), SolveError> {
        self.times[self.count % self.n] = t;
        self.count += 1;
        if self.count >= self.n {
            let oldest = self.times[self.count % self.n];
            let window = window * t.abs().max(1.0);
            if t - oldest < window {
                return Err(SolveError::Zeno {
                    t,
                    count: self.n as u32,
                    window,
                });
            }
        }
        Ok(())
    }
}

/// Guards kept on the stack up to this many (a chain of up to 3 discs with every guard on);
/// a longer list goes on the heap.
const INLINE_GUARDS: usize = 8;

/// A list of `count` items: the array on the stack if it holds them, else `heap` grown to
/// them (so a short chain's step allocates nothing).
fn few<'b, T: Copy + Default>(
    count: usize,
    inline: &'b mut [T; INLINE_GUARDS],
    heap: &'b mut Vec<T>,
) -> &'b mut [T] {
    if count <= INLINE_GUARDS {
        &mut inline[..]
    } else {
        heap.resize(count, T::default());
        &mut heap[..]
    }
}

/// One integration run of the Filippov system on a chain of discs (the rig is the chain of
/// two), with states of dimension `D`: `U3` on the stack for the rig, `Dyn` for a chain.
pub(crate) struct Integrator<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub model: Arc<ChainModel>,
    /// The input's piece the run is on, `u(t) = u0 + slope·(t − t0)` (a run never crosses
    /// a breakpoint: the solver restarts it on the next piece there).
    pub piece: Piece,
    pub opts: EventOptions,
    pub ctl: Dop853,
    pub stats: Stats,
    pub extrema: bool,
    /// The Poincaré section `ω_N = c` of the last disc (the rig's lower disc), when asked.
    pub section: Option<f64>,
    /// Vector-field evaluations outside the integrator's stages (guard rates at event
    /// refinement, extremum polishing), added to `stats.rhs_evals` when a run returns.
    extra_evals: Cell<u64>,
    /// The step bound from the friction laws' scales.
    scale_bound: ScaleBound,
    /// Non-terminal events (extrema, section crossings) handed to the sink so far: a step
    /// that has handed one on can no longer be rejected.
    delivered: u64,
    /// Stick intervals `[T_f(0⁻), T_f(0⁺)]` of each disc (constant; the exit guards use them
    /// at every sample).
    stick_intervals: Vec<(f64, f64)>,
    /// The state's dimension `2N − 1` as `D`.
    dim: D,
    /// The velocity at the last extremum found per disc since the last mode switch: an
    /// extremum within EXTREMUM_RESOLUTION tolerances of it is below what the integration
    /// resolves (rounding-level turns of a velocity settling onto an equilibrium) and is not
    /// reported. Kept here, not per run, so that a run allocates nothing.
    last_extremum: Vec<Option<f64>>,
    /// A step's extremum memory before its scan, restored if the step is redone.
    saved_extrema: Vec<Option<f64>>,
}

impl Integrator<nalgebra::U3> {
    /// The rig's run: the integrator on the rig's chain of two, states on the stack.
    pub fn rig(model: &Model, u: f64, tol: f64, opts: EventOptions) -> Self {
        let chain = ChainModel::new(&ChainParams::from_params(&model.params));
        Integrator::new(Arc::new(chain), u, tol, opts)
    }
}

impl<D: Dim> Integrator<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The run on `model` at the constant input `u` (`D` must hold the model's `2N − 1`).
    pub fn new(model: Arc<ChainModel>, u: f64, tol: f64, opts: EventOptions) -> Self {
        let mut ctl = Dop853::new(tol, tol);
        ctl.h_max = opts.h_max;
        let n = model.discs();
        Integrator {
            piece: Piece::constant(u),
            opts,
            ctl,
            stats: Stats::default(),
            extrema: false,
            section: None,
            extra_evals: Cell::new(0),
            delivered: 0,
            scale_bound: ScaleBound::new(
                &model,
                tol,
                opts.h_scale,
                opts.lift,
                opts.lift_resolution,
                opts.steep_lift,
            ),
            stick_intervals: (0..n)
                .map(|i| model.friction(i).static_interval())
                .collect(),
            dim: D::from_usize(model.dim()),
            last_extremum: vec![None; n],
            saved_extrema: vec![None; n],
            model,
        }
    }

    /// Number of discs.
    #[inline(always)]
    fn discs(&self) -> usize {
        self.stick_intervals.len()
    }

    /// A zero state.
    #[inline(always)]
    fn zeros(&self) -> Vector<D> {
        Vector::<D>::zeros_generic(self.dim, U1)
    }

    /// The input at t, `u0 + slope·(t − t0)` on the current piece.
    #[inline(always)]
    fn u(&self, t: f64) -> f64 {
        self.piece.at(t)
    }

    #[inline]
    fn field(&self, t: f64, x: &Vector<D>, mode: Mode) -> Vector<D> {
        self.extra_evals.set(self.extra_evals.get() + 1);
        let mut out = self.zeros();
        self.model
            .rhs_into(x.as_slice(), self.u(t), mode, out.as_mut_slice());
        out
    }

    /// ∂/∂t of a disc's applied torque at fixed state: `k_m·du/dt` on the top disc (the
    /// motor's), 0 on the others.
    #[inline]
    fn torque_drift(&self, d: Disc) -> f64 {
        if d == Disc::UPPER {
            self.model.k_m() * self.piece.slope
        } else {
            0.0
        }
    }

    #[inline]
    fn stick_interval(&self, d: Disc) -> (f64, f64) {
        self.stick_intervals[d.position()]
    }

    /// Index of disc `d`'s velocity in the state.
    #[inline(always)]
    fn omega(&self, d: Disc) -> usize {
        self.discs() - 1 + d.position()
    }

    /// Value of a guard at state x at time t (in the current mode).
    #[inline(always)]
    fn guard(&self, g: Guard, t: f64, x: &Vector<D>, mode: Mode) -> f64 {
        match g {
            Guard::Velocity(d) => {
                let s = mode.of(d).branch().unwrap_or(1.0);
                s * x[self.omega(d)]
            }
            Guard::ExitHi(d) => {
                let (_, hi) = self.stick_interval(d);
                hi - self
                    .model
                    .applied_torque(d.position(), x.as_slice(), self.u(t))
            }
            Guard::ExitLo(d) => {
                let (lo, _) = self.stick_interval(d);
                self.model
                    .applied_torque(d.position(), x.as_slice(), self.u(t))
                    - lo
            }
            Guard::Extremum(d, _) => {
                self.extra_evals.set(self.extra_evals.get() + 1);
                self.model
                    .disc_accel(d.position(), x.as_slice(), self.u(t), mode)
            }
            Guard::Section => {
                x[self.omega(Disc::at(self.discs() - 1))] - self.section.unwrap_or(0.0)
            }
        }
    }

    /// Time derivative of a guard along the mode's field, given the field `f` at x: the
    /// rate through the state plus, for a guard holding the input, its rate through u(t)
    /// (`k_m·du/dt` in the top disc's applied torque; 0 for a constant input).
    #[inline(always)]
    fn guard_rate(&self, g: Guard, x: &Vector<D>, f: &Vector<D>, mode: Mode) -> f64 {
        match g {
            Guard::Velocity(d) => mode.of(d).branch().unwrap_or(1.0) * f[self.omega(d)],
            Guard::ExitHi(d) | Guard::ExitLo(d) => {
                // The springs (and couplings) move the applied torque with the state.
                let dt = self.model.applied_torque_rate(d.position(), f.as_slice())
                    + self.torque_drift(d);
                if matches!(g, Guard::ExitHi(_)) {
                    -dt
                } else {
                    dt
                }
            }
            Guard::Extremum(d, _) => {
                let i = d.position();
                let a = self.model.accel_rate(i, x.as_slice(), mode, f.as_slice());
                let drift = if mode.of(d) == DiscMode::Stick {
                    0.0
                } else {
                    self.torque_drift(d) / self.model.inertia(i)
                };
                a + drift
            }
            Guard::Section => f[self.omega(Disc::at(self.discs() - 1))],
        }
    }

    /// The guards active in a mode (at most `2N + 1`), written into `out` from the start
    /// (which must hold them); their number.
    fn guards(&self, mode: Mode, out: &mut [Guard]) -> usize {
        let mut n = 0;
        for d in Disc::all(self.discs()) {
            match mode.of(d) {
                DiscMode::Stick => {
                    out[n] = Guard::ExitHi(d);
                    out[n + 1] = Guard::ExitLo(d);
                    n += 2;
                }
                _ => {
                    // Also for a smooth law (zero-width interval): its sign change is reported
                    // as a reversal and switches the branch (exact for an asymmetric Δb_u).
                    out[n] = Guard::Velocity(d);
                    n += 1;
                    if self.extrema {
                        out[n] = Guard::Extremum(d, true);
                        n += 1;
                    }
                }
            }
        }
        if self.section.is_some() {
            out[n] = Guard::Section;
            n += 1;
        }
        n
    }

    /// The most guards any mode has: `2N + 1`.
    #[inline(always)]
    fn max_guards(&self) -> usize {
        2 * self.discs() + 1
    }

    /// Whether a guard's sign change from `a` to `b` is an event, and which.
    fn fires(g: Guard, a: f64, b: f64) -> Option<Guard> {
        match g {
            Guard::Extremum(d, _) => {
                if a > 0.0 && b <= 0.0 {
                    Some(Guard::Extremum(d, true))
                } else if a < 0.0 && b >= 0.0 {
                    Some(Guard::Extremum(d, false))
                } else {
                    None
                }
            }
            Guard::Section => (a < 0.0 && b >= 0.0).then_some(g),
            _ => (a > 0.0 && b <= 0.0).then_some(g),
        }
    }

    /// A crossing of a velocity or stick-exit guard that its samples at `ta` and `tb` do not
    /// show: a shallow dip below 0 between two positive samples (found at the minimum, the
    /// root of the guard's rate), or, for a velocity guard, an excursion from exactly 0 at
    /// `ta` that returns to ≤ 0 by `tb` (a reversal just past a stick boundary, whose short
    /// excursion ends in stick: the return root lies between the guard's positive maximum
    /// and `tb`). A stick-exit guard dips where the other disc's velocity turns through 0
    /// (its rate is ±k_θ α̇ with α̇ the other disc's velocity), so a spring torque that
    /// leaves the stick interval and comes back within one step, around the other disc's
    /// reversal, is found before that reversal. `rates` are the state's rates at the two
    /// samples. Returns the bracket, the guard's value at its start, and the guard.
    #[allow(clippy::too_many_arguments)]
    fn hidden_crossing(
        &self,
        d: &Dense<D>,
        g: Guard,
        mode: Mode,
        (ta, tb): (f64, f64),
        (ga, gb): (f64, f64),
        (xa, xb): (&Vector<D>, &Vector<D>),
        (fa, fb): (&Vector<D>, &Vector<D>),
    ) -> Option<(f64, f64, f64, Guard)> {
        if !matches!(g, Guard::Velocity(_) | Guard::ExitHi(_) | Guard::ExitLo(_)) {
            return None;
        }
        let (ra, rb) = (
            self.guard_rate(g, xa, fa, mode),
            self.guard_rate(g, xb, fb, mode),
        );
        let rate = |t: f64| {
            let (x, r) = d.eval_with_rate(t);
            self.guard_rate(g, &x, &r, mode)
        };
        if ga > 0.0 && gb > 0.0 && ra < 0.0 && rb > 0.0 {
            let tm = illinois(&rate, ta, tb, ra, rb);
            let gm = self.guard(g, tm, &d.eval(tm), mode);
            (gm <= 0.0).then_some((ta, tm, ga, g))
        } else if matches!(g, Guard::Velocity(_)) && ga == 0.0 && ra > 0.0 && gb <= 0.0 && rb < 0.0
        {
            let tm = illinois(&rate, ta, tb, ra, rb);
            let gm = self.guard(g, tm, &d.eval(tm), mode);
            (gm > 0.0).then_some((tm, tb, gm, g))
        } else {
            None
        }
    }

    /// The root of guard `g` (firing as `kind`) in the bracket `(a, b)` where it starts at
    /// `fa`: an extremum on the dense output's rate, polished onto the field's acceleration;
    /// any other guard on its value along the dense output.
    fn locate(
        &self,
        d: &Dense<D>,
        g: Guard,
        kind: Guard,
        (a, b): (f64, f64),
        fa: f64,
        step: (f64, f64),
        mode: Mode,
    ) -> Detected {
        match g {
            Guard::Extremum(disc, _) => {
                let k = self.omega(disc);
                let f = |t: f64| d.rate_of(t, k);
                let fb = f(b);
                let r = if fb == 0.0 {
                    b
                } else {
                    illinois(&f, a, b, fa, fb)
                };
                let is_max = matches!(kind, Guard::Extremum(_, true));
                let te = self.polish_extremum(disc, is_max, &|t| d.eval(t), r, step, mode);
                // The interpolant's root may lie after the polished one: a search resumed
                // before it would find this extremum again.
                Detected {
                    t: te,
                    guard: kind,
                    resume: te.max(r),
                }
            }
            _ => {
                let f = |t: f64| self.guard(g, t, &d.eval(t), mode);
                let fb = f(b);
                let t = if fb == 0.0 {
                    b
                } else {
                    illinois(&f, a, b, fa, fb)
                };
                Detected {
                    t,
                    guard: kind,
                    resume: t,
                }
            }
        }
    }

    /// Finds the earliest guard event in `[t0, t1]` of the step with dense output `d`. The
    /// step's end state and field `end = (y1, f1)` are known (the field was evaluated for
    /// the dense output), and so is the start's when `t0` is the step's start: those samples
    /// cost nothing, and the end sample is the state the next step starts from, so a guard
    /// sign at a step boundary is the same for both steps.
    fn detect(
        &self,
        d: &Dense<D>,
        t0: f64,
        t1: f64,
        mode: Mode,
        start: Option<(&Vector<D>, &Vector<D>)>,
        end: (&Vector<D>, &Vector<D>),
    ) -> Option<Detected> {
        // The guards and their values at the last sample: on the stack for a short chain.
        let count = self.max_guards();
        let (mut gs_inline, mut gs_heap) = ([Guard::Section; INLINE_GUARDS], Vec::new());
        let (mut ga_inline, mut ga_heap) = ([0.0; INLINE_GUARDS], Vec::new());
        let gs = few(count, &mut gs_inline, &mut gs_heap);
        let ga = few(count, &mut ga_inline, &mut ga_heap);
        let n = self.guards(mode, gs);
        let m = self.opts.guard_samples.clamp(1, MAX_GUARD_SAMPLES);
        // The samples' states and rates, shared by every guard. Guards are functions of the
        // state along the dense output (that is where their roots are located), so at an
        // interior sample the rate is the dense output's own derivative: no field evaluation.
        // At the step's ends it is the field, which the derivative equals there (Hermite).
        // The rates give the extremum guards' values and the velocity guards' dip test.
        let sample = |k: usize| -> (f64, Vector<D>, Vector<D>) {
            match (k, start) {
                (0, Some((x0, f0))) => (t0, x0.clone(), f0.clone()),
                _ if k == m => (t1, end.0.clone(), end.1.clone()),
                _ => {
                    let t = t0 + (t1 - t0) * k as f64 / m as f64;
                    let (x, r) = d.eval_with_rate(t);
                    (t, x, r)
                }
            }
        };
        let value = |g: Guard, t: f64, x: &Vector<D>, f: &Vector<D>| match g {
            Guard::Extremum(disc, _) => f[self.omega(disc)],
            _ => self.guard(g, t, x, mode),
        };
        // Sample intervals in time order; the first one where any guard fires holds the
        // earliest event (the earliest root among the guards firing there).
        let (mut ta, mut xa, mut fa_rate) = sample(0);
        for (j, &g) in gs[..n].iter().enumerate() {
            ga[j] = value(g, ta, &xa, &fa_rate);
        }
        for i in 1..=m {
            let (tb, xb, fb_rate) = sample(i);
            let mut best: Option<Detected> = None;
            for (j, &g) in gs[..n].iter().enumerate() {
                let gb = value(g, tb, &xb, &fb_rate);
                let hit = Self::fires(g, ga[j], gb)
                    .map(|kind| (ta, tb, ga[j], kind))
                    .or_else(|| {
                        self.hidden_crossing(
                            d,
                            g,
                            mode,
                            (ta, tb),
                            (ga[j], gb),
                            (&xa, &xb),
                            (&fa_rate, &fb_rate),
                        )
                    });
                ga[j] = gb;
                let Some((a, b, fa, kind)) = hit else {
                    continue;
                };
                let found = self.locate(d, g, kind, (a, b), fa, (t0, t1), mode);
                if best.is_none_or(|b| found.t < b.t) {
                    best = Some(found);
                }
            }
            if best.is_some() {
                return best;
            }
            (ta, xa, fa_rate) = (tb, xb, fb_rate);
        }
        None
    }

    /// An extremum of a disc's velocity, from a root `t` of the dense output's derivative
    /// (exact for the interpolant, whose derivative is of one order less than its state),
    /// moved to the root of the field's acceleration along `path` (the dense output, or a
    /// short line from an exact state), a(t) = ω̇(x(t)), by Newton's method with
    /// a'(t) = (J f)_d: from a start within the rate's interpolation error, two or three
    /// iterations reach rounding level. A step that would leave the searched interval `span`,
    /// or a vanishing a', keeps the current time.
    fn polish_extremum(
        &self,
        disc: Disc,
        is_max: bool,
        path: &impl Fn(f64) -> Vector<D>,
        mut t: f64,
        span: (f64, f64),
        mode: Mode,
    ) -> f64 {
        let (lo, hi) = (span.0.min(span.1), span.0.max(span.1));
        let i = self.omega(disc);
        // The acceleration at t (one field evaluation), kept for the fired-side test below.
        let mut at = (t, f64::NAN);
        let mut dt_prev = f64::INFINITY;
        for _ in 0..4 {
            let x = path(t);
            let f = self.field(t, &x, mode);
            at = (t, f[i]);
            let ar = self.guard_rate(Guard::Extremum(disc, is_max), &x, &f, mode);
            if ar == 0.0 || !ar.is_finite() {
                break;
            }
            let dt = -f[i] / ar;
            // Outside the searched interval, or no contraction (a at rounding level, as on
            // the decaying oscillation into an equilibrium): keep the current time.
            if !(lo..=hi).contains(&(t + dt)) || dt.abs() >= 0.5 * dt_prev {
                break;
            }
            t += dt;
            dt_prev = dt.abs();
            if dt.abs() <= 4.0 * f64::EPSILON * t.abs().max(1.0) {
                break;
            }
        }
        // Return a time where the guard has fired (a ≤ 0 after a maximum, a ≥ 0 after a
        // minimum), as a bracketing root finder does: a run restarted from this event must
        // not see it again. Newton ends within rounding of the root, so a few ulps suffice.
        let fired = |t: f64| {
            let a = if t == at.0 && !at.1.is_nan() {
                at.1
            } else {
                self.guard(Guard::Extremum(disc, is_max), t, &path(t), mode)
            };
            if is_max { a <= 0.0 } else { a >= 0.0 }
        };
        let mut nudge = 2.0 * f64::EPSILON * t.abs().max(1.0);
        while !fired(t) && t + nudge <= hi {
            t += nudge;
            nudge *= 2.0;
        }
        t
    }

    /// Integrates from `(t, x, mode)` to `t_end`, or until the sink asks to stop.
    pub fn run(
        &mut self,
        t_start: f64,
        x_start: Vector<D>,
        mode_start: Mode,
        t_end: f64,
        sink: &mut impl Sink<D>,
    ) -> Result<RunEnd<D>, SolveError> {
        let (model, piece, dim) = (Arc::clone(&self.model), self.piece, self.dim);
        let evals = Cell::new(0u64);
        let field = |t: f64, y: &Vector<D>, mode: Mode| {
            evals.set(evals.get() + 1);
            let mut out = Vector::<D>::zeros_generic(dim, U1);
            model.rhs_into(y.as_slice(), piece.at(t), mode, out.as_mut_slice());
            out
        };
        let end = self.steps(t_start, x_start, mode_start, t_end, &field, sink);
        self.stats.rhs_evals += evals.get() + self.extra_evals.take();
        end
    }

    /// [`Integrator::run`] with the counted field `field`.
    fn steps(
        &mut self,
        t_start: f64,
        x_start: Vector<D>,
        mode: Mode,
        t_end: f64,
        field: &impl Fn(f64, &Vector<D>, Mode) -> Vector<D>,
        sink: &mut impl Sink<D>,
    ) -> Result<RunEnd<D>, SolveError> {
        let mut x = x_start;
        let mut mode = mode;
        for d in Disc::all(self.discs()) {
            if mode.of(d) == DiscMode::Stick {
                x[self.omega(d)] = 0.0;
            }
        }
        let mut recent = Recent::new((self.opts.zeno_count as usize).clamp(2, 64));
        // Guards already at or past 0 at the start (a disc stuck exactly on an edge of its
        // interval with the applied torque moving out, a start in an inconsistent mode):
        // handled here, as after every switch.
        if let Some(end) = self.settle(t_start, &mut x, &mut mode, 0, &mut recent, sink)? {
            return Ok(end);
        }
        let f0 = field(t_start, &x, mode);
        let h = self
            .ctl
            .initial_step(&mut |t, y: &Vector<D>| field(t, y, mode), t_start, &x, &f0);
        self.ctl.restart();
        let mut c = Cursor {
            t: t_start,
            x,
            mode,
            f0,
            h,
            t_switch: t_start,
        };
        self.last_extremum.fill(None);
        let mut steps_total = 0u64;
        while c.t < t_end {
            // Every disc stuck: the state is frozen and, on a constant piece of the input,
            // so are the exit guards.
            if self.piece.slope == 0.0
                && Disc::all(self.discs()).all(|d| {
                    c.mode.is_stuck(d)
                        && self
                            .model
                            .stick_exit(d.position(), c.x.as_slice(), self.piece.u0)
                            .is_none()
                })
            {
                let d = Dense::constant(c.t, t_end - c.t, &c.x);
                sink.step(&d, c.t, t_end, &c.x, c.mode);
                c.t = t_end;
                break;
            }
            steps_total += 1;
            if steps_total > self.opts.max_steps {
                return Err(SolveError::TooManySteps {
                    t: c.t,
                    max_steps: self.opts.max_steps,
                });
            }
            if let Some(end) = self.step(&mut c, t_end, field, &mut recent, sink)? {
                return Ok(end);
            }
        }
        Ok(RunEnd {
            t: c.t,
            x: c.x,
            mode: c.mode,
        })
    }

    /// One step attempt from the cursor: rejected (a smaller step next), or accepted with
    /// its events; `Some` if the sink stopped the run at one of them.
    fn step(
        &mut self,
        c: &mut Cursor<D>,
        t_end: f64,
        field: &impl Fn(f64, &Vector<D>, Mode) -> Vector<D>,
        recent: &mut Recent,
        sink: &mut impl Sink<D>,
    ) -> Result<Option<RunEnd<D>>, SolveError> {
        let (x, f0) = (c.x.as_slice(), c.f0.as_slice());
        let bound = self.scale_bound.at(&self.model, c.mode, x, f0, c.h, |i| {
            self.model.accel_rate(i, x, c.mode, f0)
        });
        let mut h = c.h.min(bound);
        let mut last = false;
        if c.t + 1.01 * h >= t_end {
            h = t_end - c.t;
            last = true;
        }
        if h <= 4.0 * f64::EPSILON * c.t.abs().max(1.0) {
            return Err(SolveError::StepSizeUnderflow {
                t: c.t,
                h,
                x: c.x.as_slice().to_vec(),
            });
        }
        let mode = c.mode;
        let mut fm = |t: f64, y: &Vector<D>| field(t, y, mode);
        let tr = self.ctl.trial(&mut fm, c.t, &c.x, &c.f0, h);
        if !Dop853::acceptable(&tr) {
            self.stats.rejected += 1;
            c.h = self.ctl.reject(tr.err, h);
            return Ok(None);
        }
        let h_next = self.ctl.accept(tr.err, h);
        self.stats.steps += 1;
        let t1 = if last { t_end } else { c.t + h };
        let f1 = fm(t1, &tr.y1);
        let dense = self.ctl.dense(&mut fm, &tr, &f1);
        let delivered = self.delivered;
        self.saved_extrema.clone_from(&self.last_extremum);
        match self.scan(c, &dense, t1, (&tr.y1, &f1), sink) {
            Scan::Stop(end) => Ok(Some(end)),
            Scan::Through => {
                sink.step(&dense, c.t, t1, &tr.y1, mode);
                (c.t, c.x, c.f0, c.h) = (t1, tr.y1.clone(), f1, h_next);
                check_finite(c.t, c.x.as_slice())?;
                Ok(None)
            }
            Scan::Terminal(te, g) => {
                let (tev, xe, exact) = self.refine(c, g, te, t1, &tr.y1, &mut fm);
                let defect = self.defect(&exact, &dense.eval(te));
                if defect > self.opts.defect_limit && self.delivered == delivered {
                    // The step was misjudged (see DEFECT_LIMIT): redo it shorter, as a
                    // rejected step, the controller's reduction for an error of
                    // defect/defect_limit. Only before any event of the step reached the sink.
                    self.last_extremum.clone_from(&self.saved_extrema);
                    self.stats.rejected += 1;
                    self.stats.defect_rejections += 1;
                    c.h = self.ctl.reject(defect / self.opts.defect_limit, h);
                    return Ok(None);
                }
                sink.step(&dense, c.t, tev, &xe, mode);
                check_finite(tev, xe.as_slice())?;
                (c.t, c.x) = (tev, xe);
                if let Some(end) = self.switch(c, g, recent, sink)? {
                    return Ok(Some(end));
                }
                c.f0 = field(c.t, &c.x, c.mode);
                self.ctl.restart();
                c.h = h_next.min(h).max(1e-6 * h_next);
                Ok(None)
            }
        }
    }

    /// The events of an accepted step `[c.t, t1]` in time order: non-terminal ones (extrema,
    /// section crossings) go to the sink, which may stop the run there; the first terminal
    /// guard (a mode switch) ends the scan.
    fn scan(
        &mut self,
        c: &mut Cursor<D>,
        dense: &Dense<D>,
        t1: f64,
        end: (&Vector<D>, &Vector<D>),
        sink: &mut impl Sink<D>,
    ) -> Scan<D> {
        let (t, mode) = (c.t, c.mode);
        // Just past a root: where the search for the next one in the step starts.
        let past = |resume: f64| resume + 1e-12 * (t1 - t).abs().max(1e-300);
        let mut t_lo = t;
        while let Some(Detected {
            t: te,
            guard: g,
            resume,
        }) = self.detect(
            dense,
            t_lo,
            t1,
            mode,
            (t_lo == t).then_some((&c.x, &c.f0)),
            end,
        ) {
            if g.terminal() {
                return Scan::Terminal(te, g);
            }
            t_lo = past(resume);
            if matches!(g, Guard::Extremum(..)) && te - c.t_switch <= 1e-9 * te.abs().max(1.0) {
                if t_lo >= t1 {
                    break;
                }
                continue;
            }
            // Below resolution (judged on the dense output): skipped before paying for the
            // exact state.
            if let Guard::Extremum(d, _) = g {
                let w = dense.eval(te)[self.omega(d)];
                let resolvable = self.last_extremum[d.position()]
                    .replace(w)
                    .is_none_or(|w_prev| {
                        (w - w_prev).abs() > EXTREMUM_RESOLUTION * self.ctl.rtol * (1.0 + w.abs())
                    });
                if !resolvable {
                    if t_lo >= t1 {
                        break;
                    }
                    continue;
                }
            }
            let (te, xe) = self.event_state(c, g, te, t1, end.0);
            if let Guard::Extremum(d, _) = g {
                self.last_extremum[d.position()] = Some(xe[self.omega(d)]);
            }
            self.delivered += 1;
            let stop = if g == Guard::Section {
                sink.section(te, &xe)
            } else {
                let kind = match g {
                    Guard::Extremum(d, false) => EventKind::Min(d),
                    Guard::Extremum(d, true) => EventKind::Max(d),
                    _ => EventKind::Max(Disc::LOWER),
                };
                let ev = EventRef {
                    t: te,
                    x: xe.as_slice(),
                    kind,
                };
                self.stats.events += 1;
                sink.event(ev);
                sink.stop_after(ev)
            };
            if stop {
                sink.step(dense, t, te, &xe, mode);
                return Scan::Stop(RunEnd { t: te, x: xe, mode });
            }
            if t_lo >= t1 {
                break;
            }
        }
        Scan::Through
    }

    /// A non-terminal event found on the dense output at `te`: its time and state. The dense
    /// output alone would be cheaper, but its error is not controlled: on long steps it was
    /// found 300 tolerances off at an extremum of ω_u (tol 1e-10), where an RK step re-taken
    /// from the step's start to `te` is within one. An extremum takes that step and is
    /// polished again on the field's acceleration, along the first-order path `x + f·(t − te)`
    /// from the new state. The shift is the dense output's error in time, usually ~1e-10 s,
    /// where the path's error ½(t − te)²|ẍ| is far below rounding; on a flat extremum it can
    /// reach 1e-3 s, and while the error bound (|ẍ| from the field's change over the step, as
    /// in [`Integrator::refine`]) exceeds a thousandth of the tolerance the step is re-taken to
    /// the new time, at most twice more. A section crossing is refined as a terminal root is,
    /// so that its state lies on the section.
    fn event_state(
        &self,
        c: &Cursor<D>,
        g: Guard,
        te: f64,
        t1: f64,
        y1: &Vector<D>,
    ) -> (f64, Vector<D>) {
        let mode = c.mode;
        let mut fm = |t: f64, y: &Vector<D>| self.field(t, y, mode);
        let Guard::Extremum(disc, is_max) = g else {
            let (t, x, _) = self.refine(c, g, te, t1, y1, &mut fm);
            return (t, x);
        };
        let mut te = te;
        let mut round = 0;
        loop {
            let hh = te - c.t;
            let x = if hh > 0.0 {
                self.ctl.trial(&mut fm, c.t, &c.x, &c.f0, hh).y1
            } else {
                c.x.clone()
            };
            let f = self.field(te, &x, mode);
            let path = |t: f64| &x + &f * (t - te);
            let t = self.polish_extremum(disc, is_max, &path, te, (c.t, t1), mode);
            // At the step's start (no step to bound |ẍ| by) only a polish that stays is small.
            let small = self.taylor_is_small(c, hh, &f, &x, t - te) || t == te;
            if small || round == 2 {
                return (t, path(t));
            }
            te = t;
            round += 1;
        }
    }

    /// Whether the first-order move `x + f·dt` from the state `x` reached `hh` into the step
    /// from the cursor (field `f` there) errs by less than a thousandth of the tolerance: its
    /// error ½dt²|ẍ|, with |ẍ| bounded by the field's change over the step. `false` when
    /// `hh ≤ 0` (no step to bound |ẍ| by).
    fn taylor_is_small(
        &self,
        c: &Cursor<D>,
        hh: f64,
        f: &Vector<D>,
        x: &Vector<D>,
        dt: f64,
    ) -> bool {
        hh > 0.0
            && (0..x.len()).all(|i| {
                let acc = (f[i] - c.f0[i]).abs() / hh;
                0.5 * dt * dt * acc <= 1e-3 * self.ctl.rtol.min(self.ctl.atol) * (1.0 + x[i].abs())
            })
    }

    /// A terminal guard's root located to rounding: an exact RK step from the step's start to
    /// the root found on the dense output, then Newton corrections along the guard's rate.
    /// Returns the root's time and state, and the first exact state (at `te`, the dense
    /// output's root), which [`Integrator::defect`] compares with the dense output there.
    fn refine(
        &self,
        c: &Cursor<D>,
        g: Guard,
        te: f64,
        t1: f64,
        y1: &Vector<D>,
        fm: &mut impl FnMut(f64, &Vector<D>) -> Vector<D>,
    ) -> (f64, Vector<D>, Vector<D>) {
        let (t, mode) = (c.t, c.mode);
        let mut tev = te;
        let mut xe = y1.clone();
        let mut first = None;
        for round in 0..3 {
            let hh = tev - t;
            xe = if hh > 0.0 {
                self.ctl.trial(fm, t, &c.x, &c.f0, hh).y1
            } else {
                c.x.clone()
            };
            if first.is_none() {
                first = Some(xe.clone());
            }
            let fe = self.field(tev, &xe, mode);
            let gv = self.guard(g, tev, &xe, mode);
            let gr = self.guard_rate(g, &xe, &fe, mode);
            if gr == 0.0 || !gr.is_finite() {
                break;
            }
            let dt = -gv / gr;
            // Keep the correction inside the step and stop at rounding level.
            if tev + dt <= t || tev + dt > t1 {
                break;
            }
            if dt.abs() <= 1e-15 * tev.abs().max(1.0) {
                // A correction at the time's rounding level (1e-15·t is 6e-14 s at t = 60 s,
                // where the spring torque moves by 3e-14 N m): the time stays, but the state
                // still moves onto the guard along the field (the guards are linear in x), or
                // a stick exit would start 5e-13 rad inside the stick interval and stick again.
                xe += fe * dt;
                tev += dt;
                break;
            }
            // A correction far inside the tolerance: a first-order Taylor step along the
            // field instead of another RK step. Its error ½dt²|ẍ|, with |ẍ| bounded by the
            // field's change over the step, must be below a thousandth of the tolerance
            // (typically dt ~ 1e-12 s, error ~1e-23). The terminal guards are linear in x, so
            // the moved state meets the guard to rounding.
            let small = self.taylor_is_small(c, hh, &fe, &xe, dt);
            if small {
                tev += dt;
                xe += fe * dt;
                break;
            }
            if round == 2 {
                // No correction left to re-take the step with: the time stays where the
                // state is (a time moved without its state would put the state off the
                // trajectory by f·dt).
                break;
            }
            tev += dt;
        }
        let first = first.unwrap_or_else(|| xe.clone());
        (tev, xe, first)
    }

    /// The defect of a step's dense output at an event, in tolerances: the largest
    /// `|x_i − d_i|/(atol + rtol·|x_i|)` between the exact RK state `x` re-taken to the event
    /// and the dense output's value `d` there.
    fn defect(&self, x: &Vector<D>, d: &Vector<D>) -> f64 {
        (0..x.len())
            .map(|i| (x[i] - d[i]).abs() / (self.ctl.atol + self.ctl.rtol * x[i].abs()))
            .fold(0.0, f64::max)
    }

    /// The mode switch at the cursor (a terminal guard `g` located there): the new mode, the
    /// event, the Zeno guard; `Some` if the sink stops the run after the event.
    fn switch(
        &mut self,
        c: &mut Cursor<D>,
        g: Guard,
        recent: &mut Recent,
        sink: &mut impl Sink<D>,
    ) -> Result<Option<RunEnd<D>>, SolveError> {
        let (new_mode, kind) = self.transition(g, c.t, &mut c.x, c.mode);
        if let Some(kind) = kind {
            self.stats.events += 1;
            let ev = EventRef {
                t: c.t,
                x: c.x.as_slice(),
                kind,
            };
            sink.event(ev);
            recent.record(c.t, self.opts.zeno_window)?;
            if sink.stop_after(ev) {
                return Ok(Some(RunEnd {
                    t: c.t,
                    x: c.x.clone(),
                    mode: new_mode,
                }));
            }
        }
        c.mode = new_mode;
        c.t_switch = c.t;
        self.last_extremum.fill(None);
        let mut fresh = 0u64;
        if let Guard::Velocity(d) | Guard::ExitHi(d) | Guard::ExitLo(d) = g {
            fresh |= 1 << d.position();
        }
        self.settle(c.t, &mut c.x, &mut c.mode, fresh, recent, sink)
    }

    /// Guards that are already at or past 0 at a switch or a run's start, handled there: a
    /// scan only fires a guard that goes from positive to ≤ 0, so one that starts ≤ 0 would
    /// never fire. Such a guard is another disc's that crossed at the same instant, to
    /// rounding (both discs reaching ω = 0 together, a stick exit at the other disc's
    /// reversal), a disc that sticks exactly on an edge of its interval, or a start in an
    /// inconsistent mode. A guard below 0 fires at once. A guard exactly at 0 fires if it
    /// moves out: its rate is negative, or the rate is at rounding level and the second
    /// derivative is negative (a disc stuck on its edge while the other disc turns, α̇ = 0
    /// and α̈ outward). The velocity guard of a disc this switch has just put at ω = 0 in slip
    /// (`fresh`: a stick exit or a reversal) is left to the scan: the transition chose its
    /// branch from the applied torque, and its guard's rate is that branch's (rounding-level
    /// at a located exit; a scan sees an excursion that returns). Repeated until no guard
    /// fires (each disc switches at most twice at one instant); each switch is an event.
    fn settle(
        &mut self,
        t: f64,
        x: &mut Vector<D>,
        mode: &mut Mode,
        mut fresh: u64,
        recent: &mut Recent,
        sink: &mut impl Sink<D>,
    ) -> Result<Option<RunEnd<D>>, SolveError> {
        let (mut inline, mut heap) = ([Guard::Section; INLINE_GUARDS], Vec::new());
        let gs = few(self.max_guards(), &mut inline, &mut heap);
        for _ in 0..2 * self.discs() {
            let n = self.guards(*mode, gs);
            let mut f: Option<Vector<D>> = None;
            let mut hit = None;
            for &g in &gs[..n] {
                let (Guard::Velocity(d) | Guard::ExitHi(d) | Guard::ExitLo(d)) = g else {
                    continue;
                };
                let v = self.guard(g, t, x, *mode);
                let out = if v < 0.0 {
                    true
                } else if v > 0.0
                    || (matches!(g, Guard::Velocity(_)) && fresh & (1 << d.position()) != 0)
                {
                    false
                } else {
                    let f = f.get_or_insert_with(|| self.field(t, x, *mode));
                    self.moves_out(g, t, x, f, *mode)
                };
                if out {
                    hit = Some((g, d));
                    break;
                }
            }
            let Some((g, d)) = hit else {
                return Ok(None);
            };
            let (m, kind) = self.transition(g, t, x, *mode);
            let Some(kind) = kind else {
                // A velocity guard at a grazing contact from the side the applied torque
                // pushes back to: the disc stays (its velocity is now exactly 0).
                *mode = m;
                fresh |= 1 << d.position();
                continue;
            };
            *mode = m;
            fresh |= 1 << d.position();
            self.stats.events += 1;
            let ev = EventRef {
                t,
                x: x.as_slice(),
                kind,
            };
            sink.event(ev);
            recent.record(t, self.opts.zeno_window)?;
            if sink.stop_after(ev) {
                return Ok(Some(RunEnd {
                    t,
                    x: x.clone(),
                    mode: *mode,
                }));
            }
        }
        Ok(None)
    }

    /// Whether a guard at exactly 0 moves out (below 0) along the mode's field `f` at `x`:
    /// its rate is negative beyond rounding, or at rounding level with a negative second
    /// derivative. The rate's rounding level is that of the quantity it is computed from: a
    /// velocity guard's rate is (T_ex − T_f)/J, rounded at EPS·(|T_ex| + |T_f|)/J; an exit
    /// guard's is the rate of the springs' (and couplings') torques on the disc, a sum of
    /// ±k_j α̇_j (+ c_j α̈_j) over the disc's neighbours, with α̇_j = ω_j − ω_{j+1}, rounded at
    /// EPS·Σ_j k_j(|ω_j| + |ω_{j+1}|) (+ c_j(|ω̇_j| + |ω̇_{j+1}|)); on the rig ±k_θ α̇, rounded
    /// at EPS·k_θ(|ω_u| + |ω_l|). A margin of
    /// 64 covers the few operations behind each (a located stick exit leaves T_ex within a
    /// few ulps of the edge). The second derivative is the rate along J·f (the guards are
    /// linear in the state: a velocity, or the spring torque).
    fn moves_out(&self, g: Guard, t: f64, x: &Vector<D>, f: &Vector<D>, mode: Mode) -> bool {
        const MARGIN: f64 = 64.0 * f64::EPSILON;
        let r = self.guard_rate(g, x, f, mode);
        let noise = match g {
            Guard::Velocity(d) => {
                let (i, s) = (d.position(), mode.of(d).branch().unwrap_or(1.0));
                let tf = self.model.friction(i).torque(x[self.omega(d)], s);
                MARGIN * (self.model.applied_torque(i, x.as_slice(), self.u(t)).abs() + tf.abs())
                    / self.model.inertia(i)
            }
            Guard::ExitHi(d) | Guard::ExitLo(d) => {
                let i = d.position();
                let w = |j: usize| x[self.omega(Disc::at(j))].abs();
                let a = |j: usize| f[self.omega(Disc::at(j))].abs();
                let springs = i.saturating_sub(1)..i.min(self.discs() - 2) + 1;
                springs
                    .map(|j| {
                        let mut n = MARGIN * self.model.spring(j) * (w(j) + w(j + 1));
                        let c = self.model.coupling(j);
                        if c != 0.0 {
                            n += MARGIN * c * (a(j) + a(j + 1));
                        }
                        n
                    })
                    .sum()
            }
            _ => 0.0,
        };
        if r < -noise {
            return true;
        }
        if r > noise {
            return false;
        }
        // (The input's own second derivative is 0 on a piece.)
        let mut jf = self.zeros();
        self.model
            .jacobian_times(x.as_slice(), mode, f.as_slice(), jf.as_mut_slice());
        self.guard_rate(g, x, &jf, mode) < -self.second_noise(g, t, x, f, mode)
    }

    /// The rounding level of a guard's second derivative, the rate along `J·f`: the field's
    /// own rounding (each velocity's `EPS·(|ω_i| + |ω_{i+1}|)` in α̇, each slipping disc's
    /// `EPS·(|T_ex| + |T_f|)/J` in ω̇, and `EPS·|f|` for the product) carried through the
    /// Jacobian's magnitudes, then through the guard's magnitudes (with the margin of
    /// [`Integrator::moves_out`]). Without it a second derivative that is rounding of a
    /// rounding-level first derivative decides: a viscous disc at rest beside a disc that has
    /// just left stick at the edge of its interval (its ω̇ a few ulps either side of 0, a
    /// coupling passing it on) was reversed on that sign, and the wrong branch it was left in
    /// zeroed its velocity at the next switch. 0 on the rig's paths where nothing is at
    /// rounding level.
    fn second_noise(&self, g: Guard, t: f64, x: &Vector<D>, f: &Vector<D>, mode: Mode) -> f64 {
        const MARGIN: f64 = 64.0 * f64::EPSILON;
        let n = self.discs();
        let w = |j: usize| x[n - 1 + j].abs();
        let mut nf = self.zeros();
        for (i, v) in nf.as_mut_slice()[..n - 1].iter_mut().enumerate() {
            *v = MARGIN * (w(i) + w(i + 1) + f[i].abs());
        }
        for j in 0..n {
            let Some(s) = mode.of(Disc::at(j)).branch() else {
                continue;
            };
            let tf = self.model.friction(j).torque(x[n - 1 + j], s);
            let te = self.model.applied_torque(j, x.as_slice(), self.u(t));
            nf[n - 1 + j] =
                MARGIN * ((te.abs() + tf.abs()) / self.model.inertia(j) + f[n - 1 + j].abs());
        }
        let mut n2 = self.zeros();
        self.model
            .jacobian_abs_times(x.as_slice(), mode, nf.as_slice(), n2.as_mut_slice());
        match g {
            Guard::Velocity(d) => n2[n - 1 + d.position()],
            Guard::ExitHi(d) | Guard::ExitLo(d) => {
                let i = d.position();
                let mut total = 0.0;
                if i > 0 {
                    total += self.model.spring(i - 1) * n2[i - 1]
                        + self.model.coupling(i - 1) * (n2[n - 2 + i] + n2[n - 1 + i]);
                }
                if i + 1 < n {
                    total += self.model.spring(i) * n2[i]
                        + self.model.coupling(i) * (n2[n - 1 + i] + n2[n + i]);
                }
                total
            }
            _ => 0.0,
        }
    }

    /// The mode after a terminal guard, and the event to report.
    fn transition(
        &self,
        g: Guard,
        t: f64,
        x: &mut Vector<D>,
        mode: Mode,
    ) -> (Mode, Option<EventKind>) {
        let mut m = mode;
        match g {
            Guard::Velocity(d) => {
                let s = mode.of(d).branch().unwrap_or(1.0);
                x[self.omega(d)] = 0.0;
                let fr = self.model.friction(d.position());
                let t_ex = self
                    .model
                    .applied_torque(d.position(), x.as_slice(), self.u(t));
                let (lo, hi) = fr.static_interval();
                if fr.is_set_valued() && lo <= t_ex && t_ex <= hi {
                    m.set(d, DiscMode::Stick);
                    (m, Some(EventKind::StickStart(d)))
                } else if (s > 0.0 && t_ex < lo) || (s < 0.0 && t_ex > hi) {
                    // Both one-sided fields point the same way: crossing. A law without a
                    // stick interval (lo = hi) crosses by the same test, so that a root its
                    // applied torque does not carry through (a velocity at the dense
                    // output's rounding level, such as a disc deep in a chain just after a
                    // start from rest) reverses nothing and leaves no branch against ω.
                    m.set(
                        d,
                        if s > 0.0 {
                            DiscMode::SlipNeg
                        } else {
                            DiscMode::SlipPos
                        },
                    );
                    (m, Some(EventKind::Reversal(d)))
                } else {
                    // Grazing from the side the applied torque pushes back to: stay.
                    (m, None)
                }
            }
            Guard::ExitHi(d) => {
                x[self.omega(d)] = 0.0;
                m.set(d, DiscMode::SlipPos);
                (m, Some(EventKind::StickEnd(d)))
            }
            Guard::ExitLo(d) => {
                x[self.omega(d)] = 0.0;
                m.set(d, DiscMode::SlipNeg);
                (m, Some(EventKind::StickEnd(d)))
            }
            _ => (m, None),
        }
    }
}

/// Illinois (modified regula falsi) root of `f` on `[a, b]` with `f(a)·f(b) ≤ 0`, to the
/// last bits of the bracket.
pub(crate) fn illinois(
    f: &impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
) -> f64 {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let mut side = 0i8;
    for _ in 0..200 {
        let c = (a * fb - b * fa) / (fb - fa);
        let c = if c.is_finite() && c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() <= 2.0 * f64::EPSILON * a.abs().max(b.abs()).max(1e-300) {
            break;
        }
    }
    // The end where the guard has already fired (sign of f(b) at entry).
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_model::{LowerFriction, OMEGA_L, Params, State, UpperFriction};

    /// The stress test's drawn set (stress.proptest-regressions; w_1 = 9.47 s/rad), on which
    /// DOP853 at tol 1e-10 took one 0.31 s step from ω_l = 4.09 to 1.0 rad/s with a true
    /// error of 1e4 tolerances.
    fn seed_model() -> Model {
        Model::new(Params {
            j_u: 0.4069321222438779,
            k_m: 6.720280179348315,
            k_theta: 0.10457460398155585,
            j_l: 0.04485767839799535,
            upper: UpperFriction {
                t_s: 0.0,
                dt_s: 0.0,
                b: 3.2346445022822654,
                db: 0.0,
            },
            lower: LowerFriction::Exponential {
                t_s: 0.28080097270964993,
                t_1: 0.07545812043190267,
                t_2: -0.4237052317061559,
                w_1: 9.46871759777213,
                w_2: 0.18736328593501694,
                b: 0.019697737664125654,
            },
        })
    }

    const SLIP: Mode = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);

    fn chain(m: &Model) -> ChainModel {
        ChainModel::new(&ChainParams::from_params(&m.params))
    }

    /// The bound of `b` at x for a step the controller would make `h` long.
    fn bound_with(b: &ScaleBound, m: &Model, u: f64, x: &State, h: f64) -> f64 {
        let c = chain(m);
        let f = m.rhs(x, u, SLIP);
        b.at(&c, SLIP, x.as_slice(), f.as_slice(), h, |i| {
            c.accel_rate(i, x.as_slice(), SLIP, f.as_slice())
        })
    }

    /// The bound (with the lift at ε) at x for a step the controller would make `h` long.
    fn bound_at(m: &Model, u: f64, tol: f64, x: &State, h: f64) -> f64 {
        let b = ScaleBound::new(&chain(m), tol, 8.0, LIFT_FRACTION, 0.0, false);
        bound_with(&b, m, u, x, h)
    }

    /// Where the misjudged step started: the lower disc at 4.09 rad/s, braking at 10 rad/s²
    /// (the step's mean, (4.09 − 1.0)/0.31 s), which reaches the law's steep part within the
    /// 0.31 s step. The lift must not apply: the bound stays k·τ_fric = 0.097 s.
    #[test]
    fn the_bound_holds_on_a_step_that_would_brake_into_the_steep_region() {
        let (m, u, tol) = (seed_model(), 1.5 * 1.91649573917313, 1e-10);
        let w_l = 4.09;
        // k_θ α − T_f(ω_l) = J_l·ω̇_l with ω̇_l = −10 rad/s².
        let p = m.params;
        let alpha = (m.friction(Disc::LOWER).torque(w_l, 1.0) - 10.0 * p.j_l) / p.k_theta;
        let x = State::new(alpha, 2.0, w_l);
        assert!((m.rhs(&x, u, SLIP)[OMEGA_L] + 10.0).abs() < 1e-9);
        let fixed = step_bound(&m, tol, 8.0);
        // The measured bound on this set (docs/methods.md §1a): 0.097 s.
        assert!((fixed - 0.097).abs() < 5e-4, "{fixed}");
        assert_eq!(bound_at(&m, u, tol, &x, 0.31), fixed);
    }

    /// At a slipping equilibrium (Table 1, u = 6 V, ω_l = 10.7 rad/s) the field vanishes, the
    /// velocity does not move, and the bound is lifted: a 1 s step (h_max) stands. Just off it
    /// (ω_l raised by 1e-3 rad/s, an oscillation 36× larger than the lift's 2.8e-5 rad/s) the
    /// bound k·τ_fric = 0.20 s holds again.
    #[test]
    fn the_bound_is_lifted_where_the_velocity_does_not_move() {
        let (m, u, tol) = (Model::table1(), 6.0, 1e-10);
        let e = m.slip_equilibria(u)[0];
        let x = e.state();
        assert!(m.rhs(&x, u, SLIP).norm() < 1e-9);
        assert!(bound_at(&m, u, tol, &x, 1.0) >= 1.0);
        let fixed = step_bound(&m, tol, 8.0);
        let off = x + State::new(0.0, 0.0, 1e-3);
        assert_eq!(bound_at(&m, u, tol, &off, 1.0), fixed);
        assert!((fixed - 0.20).abs() < 0.005, "{fixed}");
        // The lift at the resolution alone (M = 10: 1.2e-8 rad/s here) does the same.
        let res = ScaleBound::new(&chain(&m), tol, 8.0, 0.0, LIFT_RESOLUTION, false);
        assert!(bound_with(&res, &m, u, &x, 1.0) >= 1.0);
        assert_eq!(bound_with(&res, &m, u, &off, 1.0), fixed);
        // Without either lift: the bound everywhere.
        let none = ScaleBound::new(&chain(&m), tol, 8.0, 0.0, 0.0, false);
        assert_eq!(bound_with(&none, &m, u, &x, 1.0), fixed);
    }

    /// The lift away from the steep region (`EventOptions::steep_lift`): just off Table 1's
    /// slipping equilibrium at 6 V (ω_l = 10.7 rad/s, 6.9 rad/s beyond the edge 3.78 rad/s at
    /// tol 1e-10) a 1 s step cannot reach the steep region and stands; inside the region
    /// (ω_l = 2 rad/s) the bound holds; and where the seed's step braked from 4.09 rad/s
    /// at 10 rad/s² into it (its edge at 2.3 rad/s, reached within the 0.31 s step) it holds
    /// too. The edges are `ln(2|T_1|/(tol·T))/w_1` evaluated by hand from the parameters.
    #[test]
    fn the_steep_lift_lifts_the_bound_only_where_the_steep_region_is_out_of_reach() {
        let (m, u, tol) = (Model::table1(), 6.0, 1e-10);
        let steep = ScaleBound::new(&chain(&m), tol, 8.0, 0.0, 0.0, true);
        let fixed = step_bound(&m, tol, 8.0);
        let edge = m.friction(Disc::LOWER).steep_edge(tol).unwrap();
        assert!((edge - 3.777).abs() < 1e-3, "{edge}");
        let off = m.slip_equilibria(u)[0].state() + State::new(0.0, 0.0, 1e-3);
        assert!(bound_with(&steep, &m, u, &off, 1.0) >= 1.0);
        let near = State::new(off[0], off[1], 2.0);
        assert_eq!(bound_with(&steep, &m, u, &near, 1.0), fixed);
        // Off (the default): the bound everywhere.
        let none = ScaleBound::new(&chain(&m), tol, 8.0, 0.0, 0.0, false);
        assert_eq!(bound_with(&none, &m, u, &off, 1.0), fixed);

        let (m, u) = (seed_model(), 1.5 * 1.91649573917313);
        let w_l = 4.09;
        let p = m.params;
        let alpha = (m.friction(Disc::LOWER).torque(w_l, 1.0) - 10.0 * p.j_l) / p.k_theta;
        let x = State::new(alpha, 2.0, w_l);
        let edge = m.friction(Disc::LOWER).steep_edge(tol).unwrap();
        assert!((edge - 2.3).abs() < 0.05, "{edge}");
        let steep = ScaleBound::new(&chain(&m), tol, 8.0, 0.0, 0.0, true);
        assert_eq!(
            bound_with(&steep, &m, u, &x, 0.31),
            step_bound(&m, tol, 8.0)
        );
    }

    /// `excursion_time` bounds the velocity change of a harmonic oscillation ω = A cos(Ωt + φ)
    /// exactly: |ω(t) − ω(0)| ≤ dv for t up to it (|Δω| ≤ |ω̇₀|t + ½|ω̈₀|t², from
    /// 1 − cos x ≤ x²/2 and |sin x| ≤ |x|), and equality is reached for φ = 0 up to the
    /// rounding of the root (relative 1e-12).
    #[test]
    fn excursion_time_bounds_a_harmonic_oscillation() {
        let (a, om, dv) = (0.3, 1.7, 1e-3);
        for n in 0..64 {
            let phi = n as f64 * std::f64::consts::TAU / 64.0;
            let w = |t: f64| a * (om * t + phi).cos();
            let rate = -a * om * phi.sin();
            let accel = -a * om * om * phi.cos();
            let t = excursion_time(dv, rate, accel);
            for k in 1..=100 {
                let s = t * k as f64 / 100.0;
                assert!(
                    (w(s) - w(0.0)).abs() <= dv * (1.0 + 1e-12),
                    "φ = {phi}, t = {s}"
                );
            }
        }
        assert_eq!(excursion_time(dv, 0.0, 0.0), f64::INFINITY);
        // φ = 0: ω(t) − ω(0) = A(cos Ωt − 1) ≈ −½AΩ²t², reached at t = √(2dv/(AΩ²)) to
        // O(t⁴); the exact |Δω| there is below dv by ≈ (Ωt)²/12 relative.
        let t = excursion_time(dv, 0.0, a * om * om);
        assert!((t - (2.0 * dv / (a * om * om)).sqrt()).abs() < 1e-12);
    }
}
