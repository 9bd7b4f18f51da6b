//! Timed runs and errors against the reference.

use std::time::Instant;

use rotor_model::OMEGA_L;
use rotor_model::seam::{Output, RigSteady, Scene, SolveError, Solver, Trajectory};
use serde::{Deserialize, Serialize};

use crate::bench::options::SolverKind;

/// Run time of one setting: the median of `repeats` timed runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Median wall-clock time of one run (s).
    pub median_s: f64,
    /// Fastest run (s).
    pub min_s: f64,
    /// Number of timed runs.
    pub repeats: usize,
}

impl Timing {
    /// The median and minimum of a list of run times (non-empty).
    pub fn of(mut times: Vec<f64>) -> Timing {
        times.sort_by(f64::total_cmp);
        let n = times.len();
        let median_s = if n % 2 == 1 {
            times[n / 2]
        } else {
            0.5 * (times[n / 2 - 1] + times[n / 2])
        };
        Timing {
            median_s,
            min_s: times[0],
            repeats: n,
        }
    }
}

/// Runs `f` once untimed (warm-up; its result is returned), then times it `repeats` times,
/// fewer if one run takes more than `budget / repeats` seconds; a run longer than `budget` is
/// timed by its warm-up run alone (its caches are warm after the first milliseconds).
pub fn timed<T, E>(
    repeats: usize,
    budget: f64,
    mut f: impl FnMut() -> Result<T, E>,
) -> Result<(T, Timing), E> {
    let t0 = Instant::now();
    let out = f()?;
    let first = t0.elapsed().as_secs_f64();
    if first >= budget {
        return Ok((out, Timing::of(vec![first])));
    }
    let n = ((budget / first.max(1e-9)).floor() as usize).clamp(1, repeats.max(1));
    let mut times = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        std::hint::black_box(f()?);
        times.push(t.elapsed().as_secs_f64());
    }
    Ok((out, Timing::of(times)))
}

/// The solver of a kind, with its default options.
pub fn solver(kind: SolverKind) -> Box<dyn Solver> {
    kind.solver()
}

/// The scene for one solver at one accuracy setting (its tolerance or its step).
pub(crate) fn scene_at(base: &Scene, kind: SolverKind, setting: f64, output: Output) -> Scene {
    Scene {
        accuracy: kind.accuracy(setting),
        output,
        ..base.clone()
    }
}

/// A steady state as the errors read it: a cycle's period and max ω_l, or an equilibrium's
/// state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SteadyRef {
    /// The last complete cycle: period (s), max ω_l (rad/s).
    Cycle {
        /// Period (s).
        period: f64,
        /// Largest ω_l over the cycle (rad/s).
        omega_l_max: f64,
    },
    /// The equilibrium (or the stuck set): α (rad), ω_u, ω_l (rad/s).
    Equilibrium {
        /// α (rad).
        alpha: f64,
        /// ω_u (rad/s).
        omega_u: f64,
        /// ω_l (rad/s).
        omega_l: f64,
    },
}

impl SteadyRef {
    /// The steady state of a run's metrics (`None`: the run reports none).
    pub fn of(m: Option<&RigSteady>) -> Option<SteadyRef> {
        match m? {
            RigSteady::LimitCycle {
                period,
                omega_l_max,
                ..
            } => Some(SteadyRef::Cycle {
                period: *period,
                omega_l_max: *omega_l_max,
            }),
            RigSteady::Equilibrium {
                omega_u,
                omega_l,
                alpha,
            } => Some(SteadyRef::Equilibrium {
                alpha: *alpha,
                omega_u: *omega_u,
                omega_l: *omega_l,
            }),
        }
    }

    /// The cycle's (period, max ω_l), if it is a cycle.
    pub fn cycle(&self) -> Option<(f64, f64)> {
        match *self {
            SteadyRef::Cycle {
                period,
                omega_l_max,
            } => Some((period, omega_l_max)),
            SteadyRef::Equilibrium { .. } => None,
        }
    }
}

/// What errors are measured against: the reference's steady state and its ω_l on the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct RefData {
    /// The steady state over `[metrics_from, t_end]`.
    pub steady: SteadyRef,
    /// Grid step of the samples (s).
    pub dt: f64,
    /// Grid index of the first sample in the window.
    pub k0: i64,
    /// ω_l at the grid times `(k0 + i)·dt` in the transient window.
    pub omega_l: Vec<f64>,
}

/// The (t, ω_l) samples of a trajectory inside `[t0, t1]` (with a rounding margin).
pub fn window(tr: &Trajectory, [t0, t1]: [f64; 2], dt: f64) -> Vec<(f64, f64)> {
    let eps = 1e-9 * dt;
    tr.samples
        .iter()
        .filter(|s| s.t >= t0 - eps && s.t <= t1 + eps)
        .map(|s| (s.t, s.x[OMEGA_L]))
        .collect()
}

/// The floor of an equilibrium coordinate's scale in its relative error (rad, rad/s): a stuck
/// disc's ω = 0 is compared absolutely, as `rotor check` floors a variable's scale at 1e-3.
const EQUILIBRIUM_SCALE_FLOOR: f64 = 1e-3;

impl RefData {
    /// Reads the reference from a full-trace run with metrics; `None` if it reports no steady
    /// state or the window holds no sample.
    pub fn new(tr: &Trajectory, transient: [f64; 2], dt: f64) -> Option<RefData> {
        let steady = SteadyRef::of(tr.rig_metrics().as_ref())?;
        let w = window(tr, transient, dt);
        let k0 = grid_index(w.first()?.0, dt)?;
        Some(RefData {
            steady,
            dt,
            k0,
            omega_l: w.into_iter().map(|(_, v)| v).collect(),
        })
    }

    /// Errors of a candidate: its steady state and its (t, ω_l) samples in the window.
    ///
    /// A cycle: |ΔT|, |Δ max ω_l| and `steady_rel` = max(|ΔT|/T, |Δ max ω_l|/max ω_l). An
    /// equilibrium: `steady_rel` = max over α, ω_u, ω_l of |Δx| / max(|x_ref|, 1e-3). A
    /// candidate of the other kind (or none) has no steady error.
    pub fn errors(&self, steady: Option<SteadyRef>, samples: &[(f64, f64)]) -> Errors {
        let mut e = Errors {
            transient_max: self.transient_max(samples),
            ..Errors::default()
        };
        match (self.steady, steady) {
            (
                SteadyRef::Cycle {
                    period: p0,
                    omega_l_max: w0,
                },
                Some(SteadyRef::Cycle {
                    period,
                    omega_l_max,
                }),
            ) => {
                let (dp, dw) = ((period - p0).abs(), (omega_l_max - w0).abs());
                e.period = Some(dp);
                e.omega_l_max = Some(dw);
                e.period_rel = Some(dp / p0);
                e.omega_l_max_rel = Some(dw / w0.abs());
                e.steady_rel = Some((dp / p0).max(dw / w0.abs()));
            }
            (
                SteadyRef::Equilibrium {
                    alpha: a0,
                    omega_u: u0,
                    omega_l: l0,
                },
                Some(SteadyRef::Equilibrium {
                    alpha,
                    omega_u,
                    omega_l,
                }),
            ) => {
                let rel = |x: f64, r: f64| (x - r).abs() / r.abs().max(EQUILIBRIUM_SCALE_FLOOR);
                e.steady_rel = Some(rel(alpha, a0).max(rel(omega_u, u0)).max(rel(omega_l, l0)));
            }
            _ => {}
        }
        e
    }

    /// Max |ω_l − ω_l,ref| over the window; `None` unless the samples are exactly the
    /// reference's grid times.
    fn transient_max(&self, samples: &[(f64, f64)]) -> Option<f64> {
        if samples.len() != self.omega_l.len() {
            return None;
        }
        let mut worst = 0.0f64;
        for (i, &(t, w)) in samples.iter().enumerate() {
            if grid_index(t, self.dt)? != self.k0 + i as i64 || !w.is_finite() {
                return None;
            }
            worst = worst.max((w - self.omega_l[i]).abs());
        }
        Some(worst)
    }
}

/// The grid index k of a time `t ≈ k·dt` (within 1e-6·dt), else `None`.
fn grid_index(t: f64, dt: f64) -> Option<i64> {
    let k = (t / dt).round();
    ((t - k * dt).abs() <= 1e-6 * dt).then_some(k as i64)
}

/// Errors of one run against the reference (absent where the run gives no cycle or its
/// samples do not match the grid).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// |T − T_ref| (s).
    pub period: Option<f64>,
    /// |max ω_l − ref| (rad/s).
    pub omega_l_max: Option<f64>,
    /// |ΔT|/T_ref.
    pub period_rel: Option<f64>,
    /// |Δ max ω_l|/max ω_l,ref.
    pub omega_l_max_rel: Option<f64>,
    /// The steady-state error: max(|ΔT|/T_ref, |Δ max ω_l|/max ω_l,ref) on a cycle; on an
    /// equilibrium the largest |Δx|/max(|x_ref|, 1e-3) of α, ω_u, ω_l.
    pub steady_rel: Option<f64>,
    /// max |ω_l − ω_l,ref| over the transient window (rad/s).
    pub transient_max: Option<f64>,
}

/// Runs a scene through a solver and measures its errors.
pub(crate) fn run_point(
    kind: SolverKind,
    scene: &Scene,
    model: &rotor_model::Model,
    refd: &RefData,
    transient: [f64; 2],
    repeats: usize,
    budget: f64,
) -> Result<(Trajectory, Timing, Errors), SolveError> {
    let s = solver(kind);
    let (tr, timing) = timed(repeats, budget, || s.simulate(model, scene))?;
    let errors = refd.errors(
        SteadyRef::of(tr.rig_metrics().as_ref()),
        &window(&tr, transient, refd.dt),
    );
    Ok((tr, timing, errors))
}

/// Time at a given error on a work-precision curve: the Pareto front of `(error, time)`
/// points (each faster point less accurate), interpolated linearly in log–log. Returns the
/// time and whether it is only an upper bound (the fastest point is already more accurate
/// than asked); `None` if the curve never reaches that error.
pub fn time_at_error(points: &[(f64, f64)], error: f64) -> Option<(f64, bool)> {
    let mut pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(e, t)| e.is_finite() && *e > 0.0 && t.is_finite() && *t > 0.0)
        .collect();
    pts.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in pts {
        if front.last().is_none_or(|l| p.0 < l.0) {
            front.push(p);
        }
    }
    let first = *front.first()?;
    if error >= first.0 {
        return Some((first.1, true));
    }
    for w in front.windows(2) {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        if error <= e0 && error >= e1 {
            let s = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return Some(((t0.ln() + s * (t1.ln() - t0.ln())).exp(), false));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(Timing::of(vec![3.0, 1.0, 2.0]).median_s, 2.0);
        let t = Timing::of(vec![4.0, 1.0, 2.0, 3.0]);
        assert_eq!((t.median_s, t.min_s, t.repeats), (2.5, 1.0, 4));
    }

    #[test]
    fn time_at_error_interpolates_on_the_front() {
        // (error, time): a clean curve e = 1e-2/t^2, plus a dominated point.
        let pts = [(1e-2, 1.0), (1e-4, 10.0), (1e-6, 100.0), (1e-3, 50.0)];
        let (t, bound) = time_at_error(&pts, 1e-3).unwrap();
        assert!(!bound);
        assert!((t - 10f64.sqrt()).abs() < 1e-12, "{t}");
        assert_eq!(time_at_error(&pts, 1.0), Some((1.0, true)));
        assert_eq!(time_at_error(&pts, 1e-7), None);
    }

    #[test]
    fn grid_index_accepts_rounded_times_only() {
        assert_eq!(grid_index(0.07, 0.01), Some(7));
        assert_eq!(grid_index(19.999999999999996, 0.01), Some(2000));
        assert_eq!(grid_index(0.075, 0.01), None);
    }

    #[test]
    fn errors_need_the_reference_grid() {
        let r = RefData {
            steady: SteadyRef::Cycle {
                period: 2.0,
                omega_l_max: 4.0,
            },
            dt: 0.5,
            k0: 0,
            omega_l: vec![0.0, 1.0, 2.0],
        };
        let cyc = |period, omega_l_max| {
            Some(SteadyRef::Cycle {
                period,
                omega_l_max,
            })
        };
        let e = r.errors(cyc(2.1, 3.0), &[(0.0, 0.0), (0.5, 1.5), (1.0, 2.0)]);
        assert!((e.period.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(e.omega_l_max, Some(1.0));
        assert_eq!(e.steady_rel, Some(0.25));
        assert_eq!(e.transient_max, Some(0.5));
        // Shifted or short sample sets give no transient error, and no cycle no steady one.
        let e = r.errors(None, &[(0.5, 0.0), (1.0, 1.0), (1.5, 2.0)]);
        assert_eq!((e.transient_max, e.steady_rel), (None, None));
        assert_eq!(r.errors(None, &[(0.0, 0.0)]).transient_max, None);
    }

    /// An equilibrium's error is the largest relative one of its coordinates, a zero velocity
    /// (a stuck disc) compared against the 1e-3 floor; a cycle against it has none.
    #[test]
    fn equilibrium_errors_are_relative_with_a_floor() {
        let r = RefData {
            steady: SteadyRef::Equilibrium {
                alpha: 2.0,
                omega_u: 0.0,
                omega_l: 0.0,
            },
            dt: 0.5,
            k0: 0,
            omega_l: vec![0.0],
        };
        let eq = SteadyRef::Equilibrium {
            alpha: 2.002,
            omega_u: 1e-5,
            omega_l: 0.0,
        };
        let e = r.errors(Some(eq), &[(0.0, 0.0)]);
        // alpha: 0.002 / 2 = 1e-3; omega_u: 1e-5 / 1e-3 (the floor) = 1e-2.
        assert!((e.steady_rel.unwrap() - 1e-2).abs() < 1e-12, "{e:?}");
        assert_eq!((e.period, e.omega_l_max), (None, None));
        let cycle = SteadyRef::Cycle {
            period: 4.0,
            omega_l_max: 1.0,
        };
        assert_eq!(r.errors(Some(cycle), &[(0.0, 0.0)]).steady_rel, None);
    }
}
