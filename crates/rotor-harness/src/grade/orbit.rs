//! The reference's steady orbit as a dense curve, the phase-free distance of a state from
//! it, and the `orbit` quantity of [`crate::grade::check`]: a trace's offsets from the curve against
//! the reference's own ([`Orbit::largest_offset_difference`]).
//!
//! The committed reference trace samples the orbit every 0.01 s, far too coarsely for a
//! distance good to 1e-9: a chord of a 0.01 s step misses the curve by up to
//! `dt²·|ÿ|/8 ≈ 1e-4` of the scale where ω_l turns fastest. So the orbit is computed again, by
//! the reference solver itself (the event-driven solver at the reference's tolerance), over
//! one period from the reference's state at `steady_from`, sampled every [`ORBIT_DT`] with its
//! mode switches inserted as vertices (the kinks of a stick onset or exit lie exactly on
//! the polyline). Between vertices the curve is smooth, so the polyline is within
//! `ORBIT_DT²·max|ÿ|/8` of it, `ÿ` in scaled units: the fixtures' fastest turns (ω_l's, up to
//! a few hundred rad/s³ against scales of 6 to 16 rad/s) bound that by about 3e-9.
//!
//! The reference's own steady samples lie off the polyline by that chord error and by what
//! is left of their transient (the orbit runs from the state at `steady_from`; a slowly
//! attracting cycle is still being approached later). Both are the reference's, not a
//! trace's, so the `orbit` quantity subtracts the reference's offset at the same time: the
//! reference scores exactly 0, an exact trace the reference's own error (stated as `orbit`
//! in its JSON, verified by `tests/reference_verified.rs`), and a trace shifted along the
//! orbit only the change of that offset between the two times (`tests/grade.rs`,
//! `the_orbit_sees_a_wrong_shape_and_not_a_phase`: it passes at the most digits the reference
//! allows).
//!
//! The distance is measured in coordinates scaled by each variable's scale
//! (`α/S_α, ω_u/S_u, ω_l/S_l`), so it is a relative error like the others.

use rotor_model::State;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Output, Sample, Scene, SolveError};

use rotor_analysis::solvers::registry::SolverKind;

/// Sampling step of the dense orbit \[s\].
pub const ORBIT_DT: f64 = 2e-5;

/// A closed orbit as a polyline in scaled coordinates, with the time of
/// each vertex along it.
#[derive(Debug, Clone)]
pub struct Orbit {
    /// Vertex times from the orbit's start, increasing.
    times: Vec<f64>,
    /// Vertices, scaled.
    points: Vec<[f64; 3]>,
    /// The period.
    period: f64,
    scale: [f64; 3],
}

fn scaled(x: &State, s: &[f64; 3]) -> [f64; 3] {
    [x[0] / s[0], x[1] / s[1], x[2] / s[2]]
}

/// Squared distance from `p` to the segment `a b`, and the segment parameter of the nearest
/// point.
fn to_segment(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let s = if dd > 0.0 {
        ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [w[0] - s * d[0], w[1] - s * d[1], w[2] - s * d[2]];
    (e[0] * e[0] + e[1] * e[1] + e[2] * e[2], s)
}

impl Orbit {
    /// The orbit of scenario `sc` through `x_start` (a state on the cycle) over one `period`
    /// and a little more (so that a search wraps around), computed by the reference solver
    /// at `tol`.
    pub fn cycle(
        sc: &Scenario,
        x_start: State,
        period: f64,
        tol: f64,
        scale: [f64; 3],
    ) -> Result<Orbit, SolveError> {
        let span = period * 1.05;
        let scene = Scene {
            u: sc.steady_u(),
            x0: x_start.as_slice().to_vec(),
            t_end: span,
            output: Output::Grid { dt: ORBIT_DT },
            metrics_from: None,
            ..Scene::with_tol(tol)
        };
        let tr = SolverKind::EVENT
            .solver()
            .simulate_finite(&sc.model, &scene)?;
        // The samples with the events merged in, in time order (both lists are).
        let mut all: Vec<Sample> = Vec::with_capacity(tr.samples.len() + tr.events.len());
        let mut events = tr.events.iter().peekable();
        for s in tr.samples.iter().map(|r| r.sample()) {
            while let Some(e) = events.next_if(|e| e.t < s.t) {
                all.push(Sample {
                    t: e.t,
                    x: e.state(),
                });
            }
            all.push(s);
        }
        all.extend(events.map(|e| Sample {
            t: e.t,
            x: e.state(),
        }));
        Ok(Orbit {
            times: all.iter().map(|s| s.t).collect(),
            points: all.iter().map(|s| scaled(&s.x, &scale)).collect(),
            period,
            scale,
        })
    }

    /// The distances of each of `samples` (consecutive trace samples on the cycle) from the
    /// orbit: the largest, and the time of the sample where it is.
    ///
    /// Each sample is looked for near where the previous one was found, advanced by the time
    /// between them (a window of ±`WINDOW` s along the orbit); when the nearest vertex lies
    /// at the window's edge, the whole orbit is searched.
    pub fn largest_distance(&self, samples: &[Sample]) -> (f64, f64) {
        let mut worst = (0.0f64, f64::NAN);
        let mut walk = Walk::default();
        for s in samples {
            let (d, _) = self.offset(&mut walk, s);
            if d.is_nan() || d > worst.0 {
                worst = (d, s.t);
            }
        }
        worst
    }

    /// The `orbit` quantity of a trace: its samples' offsets from the orbit (each sample minus
    /// the nearest point of the orbit, scaled) against the reference's offsets at the same
    /// times, `max_t |v(trace_t) − v(reference_t)|`, and the time where it is largest.
    ///
    /// The reference trajectory itself lies off the orbit by what is left of its transient
    /// (the orbit runs one period from its state at `steady_from`, and a slowly attracting
    /// cycle, as t1-u0.4-eq-pert's next to a Hopf point, is still approached by some 1e-9 of
    /// the scale 100 s later): that offset is the true solution's, so it is taken out, and an
    /// exact trace scores the reference's own error, not its transient. A move along the
    /// orbit (a phase) changes the offset only as the reference's offset changes along the
    /// orbit, by a fraction of that residue; a move across it changes the offset by itself.
    /// `trace` and `reference` are samples at the same times.
    pub fn largest_offset_difference(&self, trace: &[Sample], reference: &[Sample]) -> (f64, f64) {
        let mut worst = (0.0f64, f64::NAN);
        let (mut wa, mut wr) = (Walk::default(), Walk::default());
        for (a, r) in trace.iter().zip(reference) {
            let (_, va) = self.offset(&mut wa, a);
            let (_, vr) = self.offset(&mut wr, r);
            let d = ((va[0] - vr[0]).powi(2) + (va[1] - vr[1]).powi(2) + (va[2] - vr[2]).powi(2))
                .sqrt();
            if d.is_nan() || d > worst.0 {
                worst = (d, a.t);
            }
        }
        worst
    }

    /// The distance of sample `s` from the orbit and its offset (the sample minus the nearest
    /// point, scaled), searched near where `walk` last found a sample, advanced by the time
    /// between them.
    fn offset(&self, walk: &mut Walk, s: &Sample) -> (f64, [f64; 3]) {
        let p = scaled(&s.x, &self.scale);
        let (d, k) = match walk.guess {
            Some(tau) => {
                let mut tau = tau + (s.t - walk.prev_t);
                if tau > self.period {
                    tau -= self.period;
                }
                self.nearest_around(&p, tau)
            }
            None => self.nearest(&p, 0, self.points.len()),
        };
        walk.guess = Some(self.times[k]);
        walk.prev_t = s.t;
        let (a, b) = (
            &self.points[k],
            &self.points[(k + 1).min(self.points.len() - 1)],
        );
        let (_, t) = to_segment(&p, a, b);
        let v = [0, 1, 2].map(|i| p[i] - (a[i] + t * (b[i] - a[i])));
        (d, v)
    }

    /// The nearest segment to `p` near orbit time `tau`: in a window of ±[`WINDOW`] s, widened
    /// fourfold while the nearest vertex lies at its edge, up to the whole orbit.
    fn nearest_around(&self, p: &[f64; 3], tau: f64) -> (f64, usize) {
        let mut w = WINDOW;
        loop {
            let lo = self.times.partition_point(|&t| t < tau - w);
            let hi = self.times.partition_point(|&t| t <= tau + w);
            let whole = lo == 0 && hi == self.points.len();
            let (d, k) = self.nearest(p, lo, hi);
            if whole || (k > lo && k + 2 < hi) {
                return (d, k);
            }
            w *= 4.0;
        }
    }

    /// The distance from `p` to the polyline's segments `lo..hi`, and the first vertex of the
    /// nearest segment.
    fn nearest(&self, p: &[f64; 3], lo: usize, hi: usize) -> (f64, usize) {
        let hi = hi.min(self.points.len());
        let mut best = (f64::INFINITY, lo);
        for k in lo..hi.saturating_sub(1) {
            let (d2, _) = to_segment(p, &self.points[k], &self.points[k + 1]);
            if d2 < best.0 {
                best = (d2, k);
            }
        }
        (best.0.sqrt(), best.1)
    }
}

/// Where the previous sample of a walk along the orbit was found.
#[derive(Debug, Clone, Copy)]
struct Walk {
    guess: Option<f64>,
    prev_t: f64,
}

impl Default for Walk {
    fn default() -> Self {
        Walk {
            guess: None,
            prev_t: f64::NAN,
        }
    }
}

/// Half-width of the first search window along the orbit \[s\] (15 vertices each side): a
/// trace's phase relative to the reference moves by its period error per period, far less
/// than this between two samples.
const WINDOW: f64 = 3e-4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_is_the_perpendicular_or_the_nearest_end() {
        let (d, s) = to_segment(&[0.5, 2.0, 0.0], &[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0]);
        assert_eq!((d, s), (4.0, 0.5));
        let (d, s) = to_segment(&[3.0, 0.0, 0.0], &[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0]);
        assert_eq!((d, s), (4.0, 1.0));
    }

    #[test]
    fn a_circle_sampled_densely_is_found_from_any_phase() {
        // The unit circle in (α, ω_u) traversed in 2π s: a point at radius 1 + e is e away.
        let n = 20_000;
        let period = std::f64::consts::TAU;
        let times: Vec<f64> = (0..=n).map(|k| period * k as f64 / n as f64).collect();
        let orbit = Orbit {
            points: times.iter().map(|t| [t.cos(), t.sin(), 0.0]).collect(),
            times,
            period,
            scale: [1.0; 3],
        };
        let trace: Vec<Sample> = (0..500)
            .map(|k| {
                let t = 0.01 * k as f64 + 1.0;
                let r = if k == 321 { 1.0 + 1e-3 } else { 1.0 };
                Sample {
                    t,
                    x: State::new(r * t.cos(), r * t.sin(), 0.0),
                }
            })
            .collect();
        let (d, at) = orbit.largest_distance(&trace);
        // The chord sagitta of a step 2π/2e4 on the unit circle is (π/2e4)²/2 ≈ 1.2e-8.
        assert!((d - 1e-3).abs() < 2e-8, "{d}");
        assert!((at - 4.21).abs() < 1e-12, "{at}");
    }
}
