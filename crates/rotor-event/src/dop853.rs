//! DOP853: the explicit Runge–Kutta pair of order 8(5,3) with step-size control and
//! 7th-order dense output, after Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10 and the
//! controller of their `dop853` code.
//!
//! The stepper is split so that the caller owns the loop (and so can stop at events):
//! [`Dop853::trial`] computes one step and its error, [`Dop853::accept`]/[`Dop853::reject`]
//! run the controller, [`Dop853::dense`] builds the continuous extension of an accepted step.
//!
//! The state is an `OVector<f64, D>`: fixed-size on the stack for the rig (no heap
//! allocation), a `DVector` for a chain of any size (one vector per stage). Every stage's
//! argument `y + h·Σ_j a_ij k_j` is summed component by component, left to right, the
//! order in which the fixed-size expressions summed it, so the rig's steps are the same to
//! the last bit whatever the storage.

use nalgebra::{DefaultAllocator, Dim, OVector, allocator::Allocator};

use crate::tableau::*;

/// A state of dimension `D`.
pub type Vector<D> = OVector<f64, D>;

/// `y + (Σ_j c_j·k_j)·h`, the sum taken component by component from the left.
#[inline(always)]
fn stage<D: Dim>(y: &Vector<D>, terms: &[(&Vector<D>, f64)], h: f64) -> Vector<D>
where
    DefaultAllocator: Allocator<D>,
{
    let mut out = y.clone();
    for (i, o) in out.iter_mut().enumerate() {
        let mut s = terms[0].0[i] * terms[0].1;
        for (k, c) in &terms[1..] {
            s += k[i] * *c;
        }
        *o += s * h;
    }
    out
}

/// `Σ_j c_j·k_j`, component by component from the left.
#[inline(always)]
fn combine<D: Dim>(terms: &[(&Vector<D>, f64)]) -> Vector<D>
where
    DefaultAllocator: Allocator<D>,
{
    let mut out = terms[0].0 * terms[0].1;
    for (i, o) in out.iter_mut().enumerate() {
        for (k, c) in &terms[1..] {
            *o += k[i] * *c;
        }
    }
    out
}

/// Step-size controller and tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop853 {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step.
    pub h_max: f64,
    /// Safety factor (0.9 in `dop853`).
    pub safety: f64,
    /// Bounds of the step ratio: `fac_min ≤ h_new/h ≤ fac_max` (0.333 and 6 in `dop853`).
    pub fac_min: f64,
    /// Upper bound of the step ratio `h_new/h` (6 in `dop853`); `fac_min` is the lower.
    pub fac_max: f64,
    /// Lund stabilisation exponent β (0 in `dop853`).
    pub beta: f64,
    fac_old: f64,
    last_rejected: bool,
}

/// A trial step: the new state, its scaled error, and the stages needed for dense output.
#[derive(Debug, Clone)]
pub struct Trial<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Start time of the step.
    pub t: f64,
    /// Step size; the step ends at `t + h`.
    pub h: f64,
    /// State at `t`.
    pub y0: Vector<D>,
    /// The 8th-order solution at `t + h`.
    pub y1: Vector<D>,
    /// Scaled error norm (≤ 1: acceptable).
    pub err: f64,
    /// Stages k1..k12 (index 0..11).
    k: [Vector<D>; 12],
}

/// The 7th-order continuous extension of one accepted step.
#[derive(Debug, Clone, PartialEq)]
pub struct Dense<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Start time of the step it interpolates.
    pub t0: f64,
    /// Length of that step; the interpolant covers `[t0, t0 + h]`.
    pub h: f64,
    c: [Vector<D>; 8],
}

impl<D: Dim> Dense<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The interpolant at time t (meant for `t ∈ [t0, t0 + h]`).
    #[inline]
    pub fn eval(&self, t: f64) -> Vector<D> {
        let mut out = self.c[0].clone();
        self.eval_into(t, out.as_mut_slice());
        out
    }

    /// [`Dense::eval`] written into `out` (of the state's size).
    #[inline]
    pub fn eval_into(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let c = &self.c;
        for (i, o) in out.iter_mut().enumerate() {
            let par = c[4][i] + (c[5][i] + (c[6][i] + c[7][i] * s) * s1) * s;
            *o = c[0][i] + (c[1][i] + (c[2][i] + (c[3][i] + par * s1) * s) * s1) * s;
        }
    }

    /// The interpolant and its time derivative at time t (meant for `t ∈ [t0, t0 + h]`):
    /// the nested form of [`Dense::eval`] differentiated term by term in s = (t − t0)/h
    /// (with ds₁/ds = −1), divided by h. At the ends the derivative is the field there, up
    /// to rounding: the interpolant is Hermite at both ends.
    #[inline]
    pub(crate) fn eval_with_rate(&self, t: f64) -> (Vector<D>, Vector<D>) {
        let mut x = self.c[0].clone();
        let mut r = self.c[0].clone();
        for i in 0..x.len() {
            (x[i], r[i]) = self.value_and_rate(t, i);
        }
        (x, r)
    }

    /// One component of the interpolant's time derivative at time t.
    #[inline]
    pub(crate) fn rate_of(&self, t: f64, i: usize) -> f64 {
        self.value_and_rate(t, i).1
    }

    /// Component `i` of the interpolant and of its time derivative at time t: the nested form
    /// of [`Dense::eval`] differentiated term by term in s (with ds₁/ds = −1), divided by h.
    #[inline(always)]
    fn value_and_rate(&self, t: f64, i: usize) -> (f64, f64) {
        let s = (t - self.t0) / self.h;
        let s1 = 1.0 - s;
        let c = &self.c;
        let p7 = c[6][i] + c[7][i] * s;
        let p6 = c[5][i] + p7 * s1;
        let d6 = c[7][i] * s1 - p7;
        let p5 = c[4][i] + p6 * s;
        let d5 = d6 * s + p6;
        let p4 = c[3][i] + p5 * s1;
        let d4 = d5 * s1 - p5;
        let p3 = c[2][i] + p4 * s;
        let d3 = d4 * s + p4;
        let p2 = c[1][i] + p3 * s1;
        let d2 = d3 * s1 - p3;
        (c[0][i] + p2 * s, (d2 * s + p2) / self.h)
    }

    /// The interpolant of a constant state on `[t0, t0 + h]`.
    pub fn constant(t0: f64, h: f64, y: &Vector<D>) -> Dense<D> {
        let zero = y * 0.0;
        let mut c = std::array::from_fn(|_| zero.clone());
        c[0] = y.clone();
        Dense { t0, h, c }
    }

    /// End time `t0 + h`.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }
}

impl Default for Dop853 {
    fn default() -> Self {
        Dop853::new(1e-10, 1e-10)
    }
}

impl Dop853 {
    /// A controller with `dop853`'s default constants.
    pub fn new(rtol: f64, atol: f64) -> Dop853 {
        Dop853 {
            rtol,
            atol,
            h_max: f64::INFINITY,
            safety: 0.9,
            fac_min: 0.333,
            fac_max: 6.0,
            beta: 0.0,
            fac_old: 1e-4,
            last_rejected: false,
        }
    }

    /// Resets the controller memory (after a discontinuity).
    pub fn restart(&mut self) {
        self.fac_old = 1e-4;
        self.last_rejected = false;
    }

    /// Hairer's initial step guess (`hinit` with order 8); one extra evaluation of f.
    pub fn initial_step<D: Dim>(
        &self,
        f: &mut impl FnMut(f64, &Vector<D>) -> Vector<D>,
        t: f64,
        y: &Vector<D>,
        f0: &Vector<D>,
    ) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        let n = y.len();
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for i in 0..n {
            let sk = self.atol + self.rtol * y[i].abs();
            dnf += (f0[i] / sk).powi(2);
            dny += (y[i] / sk).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(self.h_max);
        let y1 = stage(y, &[(f0, 1.0)], h);
        let f1 = f(t + h, &y1);
        let mut der2: f64 = 0.0;
        for i in 0..n {
            let sk = self.atol + self.rtol * y[i].abs();
            der2 += ((f1[i] - f0[i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            1e-6_f64.max(h.abs() * 1e-3)
        } else {
            (0.01 / der12).powf(1.0 / 8.0)
        };
        (100.0 * h.abs()).min(h1).min(self.h_max)
    }

    /// One trial step of size h from `(t, y)` with `f0 = f(t, y)`: 11 evaluations of f.
    pub fn trial<D: Dim>(
        &self,
        f: &mut impl FnMut(f64, &Vector<D>) -> Vector<D>,
        t: f64,
        y: &Vector<D>,
        f0: &Vector<D>,
        h: f64,
    ) -> Trial<D>
    where
        DefaultAllocator: Allocator<D>,
    {
        let k1 = f0.clone();
        let k2 = f(t + C2 * h, &stage(y, &[(&k1, h * A21)], 1.0));
        let k3 = f(t + C3 * h, &stage(y, &[(&k1, A31), (&k2, A32)], h));
        let k4 = f(t + C4 * h, &stage(y, &[(&k1, A41), (&k3, A43)], h));
        let k5 = f(
            t + C5 * h,
            &stage(y, &[(&k1, A51), (&k3, A53), (&k4, A54)], h),
        );
        let k6 = f(
            t + C6 * h,
            &stage(y, &[(&k1, A61), (&k4, A64), (&k5, A65)], h),
        );
        let k7 = f(
            t + C7 * h,
            &stage(y, &[(&k1, A71), (&k4, A74), (&k5, A75), (&k6, A76)], h),
        );
        let k8 = f(
            t + C8 * h,
            &stage(
                y,
                &[(&k1, A81), (&k4, A84), (&k5, A85), (&k6, A86), (&k7, A87)],
                h,
            ),
        );
        let k9 = f(
            t + C9 * h,
            &stage(
                y,
                &[
                    (&k1, A91),
                    (&k4, A94),
                    (&k5, A95),
                    (&k6, A96),
                    (&k7, A97),
                    (&k8, A98),
                ],
                h,
            ),
        );
        let k10 = f(
            t + C10 * h,
            &stage(
                y,
                &[
                    (&k1, A101),
                    (&k4, A104),
                    (&k5, A105),
                    (&k6, A106),
                    (&k7, A107),
                    (&k8, A108),
                    (&k9, A109),
                ],
                h,
            ),
        );
        let k11 = f(
            t + C11 * h,
            &stage(
                y,
                &[
                    (&k1, A111),
                    (&k4, A114),
                    (&k5, A115),
                    (&k6, A116),
                    (&k7, A117),
                    (&k8, A118),
                    (&k9, A119),
                    (&k10, A1110),
                ],
                h,
            ),
        );
        let k12 = f(
            t + h,
            &stage(
                y,
                &[
                    (&k1, A121),
                    (&k4, A124),
                    (&k5, A125),
                    (&k6, A126),
                    (&k7, A127),
                    (&k8, A128),
                    (&k9, A129),
                    (&k10, A1210),
                    (&k11, A1211),
                ],
                h,
            ),
        );
        let incr = combine(&[
            (&k1, B1),
            (&k6, B6),
            (&k7, B7),
            (&k8, B8),
            (&k9, B9),
            (&k10, B10),
            (&k11, B11),
            (&k12, B12),
        ]);
        let y1 = stage(y, &[(&incr, 1.0)], h);
        let e5 = combine(&[
            (&k1, ER1),
            (&k6, ER6),
            (&k7, ER7),
            (&k8, ER8),
            (&k9, ER9),
            (&k10, ER10),
            (&k11, ER11),
            (&k12, ER12),
        ]);
        let n = y.len();
        let mut err2 = 0.0;
        let mut err = 0.0;
        for i in 0..n {
            let e3 = incr[i] - k1[i] * BHH1 - k9[i] * BHH2 - k12[i] * BHH3;
            let sk = self.atol + self.rtol * y[i].abs().max(y1[i].abs());
            err2 += (e3 / sk).powi(2);
            err += (e5[i] / sk).powi(2);
        }
        let mut deno = err + 0.01 * err2;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let err = h.abs() * err * (1.0 / (n as f64 * deno)).sqrt();
        Trial {
            t,
            h,
            y0: y.clone(),
            y1,
            err,
            k: [k1, k2, k3, k4, k5, k6, k7, k8, k9, k10, k11, k12],
        }
    }

    /// Whether a trial is acceptable (`err ≤ 1` and finite).
    pub fn acceptable<D: Dim>(tr: &Trial<D>) -> bool
    where
        DefaultAllocator: Allocator<D>,
    {
        tr.err <= 1.0 && tr.y1.iter().all(|v| v.is_finite())
    }

    /// `err^(1/8 − 0.2 β)`; for β = 0 (the default) as three square roots, which are
    /// correctly rounded and several times cheaper than `powf`.
    #[inline]
    fn err_power(&self, err: f64) -> f64 {
        if self.beta == 0.0 {
            err.sqrt().sqrt().sqrt()
        } else {
            err.powf(1.0 / 8.0 - self.beta * 0.2)
        }
    }

    /// Controller after an accepted step: the next step size.
    pub fn accept(&mut self, err: f64, h: f64) -> f64 {
        let fac11 = self.err_power(err);
        let fac = if self.beta == 0.0 {
            fac11
        } else {
            fac11 / self.fac_old.powf(self.beta)
        };
        let fac = (1.0 / self.fac_max).max((1.0 / self.fac_min).min(fac / self.safety));
        let mut h_new = h / fac;
        self.fac_old = err.max(1e-4);
        if h_new.abs() > self.h_max {
            h_new = self.h_max * h_new.signum();
        }
        if self.last_rejected {
            h_new = h_new.abs().min(h.abs()) * h.signum();
        }
        self.last_rejected = false;
        h_new
    }

    /// Controller after a rejected step: the retry step size.
    pub fn reject(&mut self, err: f64, h: f64) -> f64 {
        self.last_rejected = true;
        if !err.is_finite() {
            return h * 0.1;
        }
        let fac11 = self.err_power(err);
        h / (1.0 / self.fac_min).min(fac11 / self.safety)
    }

    /// The continuous extension of an accepted trial, given `f1 = f(t + h, y1)`:
    /// 3 more evaluations of f.
    pub fn dense<D: Dim>(
        &self,
        f: &mut impl FnMut(f64, &Vector<D>) -> Vector<D>,
        tr: &Trial<D>,
        f1: &Vector<D>,
    ) -> Dense<D>
    where
        DefaultAllocator: Allocator<D>,
    {
        let (t, h, y) = (tr.t, tr.h, &tr.y0);
        let k = &tr.k;
        let k13 = f1;
        let k14 = f(
            t + C14 * h,
            &stage(
                y,
                &[
                    (&k[0], A141),
                    (&k[6], A147),
                    (&k[7], A148),
                    (&k[8], A149),
                    (&k[9], A1410),
                    (&k[10], A1411),
                    (&k[11], A1412),
                    (k13, A1413),
                ],
                h,
            ),
        );
        let k15 = f(
            t + C15 * h,
            &stage(
                y,
                &[
                    (&k[0], A151),
                    (&k[5], A156),
                    (&k[6], A157),
                    (&k[7], A158),
                    (&k[10], A1511),
                    (&k[11], A1512),
                    (k13, A1513),
                    (&k14, A1514),
                ],
                h,
            ),
        );
        let k16 = f(
            t + C16 * h,
            &stage(
                y,
                &[
                    (&k[0], A161),
                    (&k[5], A166),
                    (&k[6], A167),
                    (&k[7], A168),
                    (&k[8], A169),
                    (k13, A1613),
                    (&k14, A1614),
                    (&k15, A1615),
                ],
                h,
            ),
        );
        let stages = [
            &k[0], &k[5], &k[6], &k[7], &k[8], &k[9], &k[10], &k[11], k13, &k14, &k15, &k16,
        ];
        let mut c: [Vector<D>; 8] = std::array::from_fn(|_| y.clone());
        for i in 0..y.len() {
            let ydiff = tr.y1[i] - y[i];
            let bspl = k[0][i] * h - ydiff;
            c[1][i] = ydiff;
            c[2][i] = bspl;
            c[3][i] = ydiff - k13[i] * h - bspl;
            for (r, row) in crate::tableau::D.iter().enumerate() {
                // From 0, as the vector sum it replaces (0 + x = x to the bit).
                let mut acc = 0.0;
                for (w, st) in row.iter().zip(stages.iter()) {
                    acc += st[i] * *w;
                }
                c[4 + r][i] = acc * h;
            }
        }
        Dense { t0: t, h, c }
    }
}

/// Counters of one integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Evaluations of f (`nfcn` in `dop853`), the initial-step guess's included.
    pub fcn: u64,
    /// Trial steps, accepted or rejected (`nstep`).
    pub steps: u64,
    /// Accepted steps (`naccpt`).
    pub accepted: u64,
    /// Rejected steps after the first accepted one (`nrejct`: `dop853` does not count
    /// rejections before it).
    pub rejected: u64,
}

/// Integrates `y' = f(t, y)` from `t0` to `t1` with DOP853 the way Hairer's driver does
/// (no dense output), returning the final state and the counts. `h0 = 0` selects the
/// initial-step heuristic. For tests and simple smooth problems; the Filippov solver drives
/// the stepper itself.
pub fn integrate<D: Dim>(
    ctl: &mut Dop853,
    mut f: impl FnMut(f64, &Vector<D>) -> Vector<D>,
    t0: f64,
    y0: Vector<D>,
    t1: f64,
    h0: f64,
) -> (Vector<D>, Counts)
where
    DefaultAllocator: Allocator<D>,
{
    let mut n = Counts::default();
    let mut fc = |t: f64, y: &Vector<D>| {
        n.fcn += 1;
        f(t, y)
    };
    let mut t = t0;
    let mut y = y0;
    let mut f0 = fc(t, &y);
    let mut h = if h0 > 0.0 {
        h0
    } else {
        ctl.initial_step(&mut fc, t, &y, &f0)
    };
    ctl.restart();
    let mut last = false;
    loop {
        if (t + 1.01 * h - t1) > 0.0 {
            h = t1 - t;
            last = true;
        }
        let tr = ctl.trial(&mut fc, t, &y, &f0, h);
        n.steps += 1;
        if Dop853::acceptable(&tr) {
            let h_new = ctl.accept(tr.err, h);
            n.accepted += 1;
            y = tr.y1;
            t += h;
            if last {
                break;
            }
            f0 = fc(t, &y);
            h = h_new;
        } else {
            // dop853 counts rejections only after the first accepted step.
            if n.accepted >= 1 {
                n.rejected += 1;
            }
            h = ctl.reject(tr.err, h);
            last = false;
        }
    }
    let counts = Counts {
        fcn: n.fcn,
        steps: n.steps,
        accepted: n.accepted,
        rejected: n.rejected,
    };
    (y, counts)
}

#[cfg(test)]
#[allow(clippy::excessive_precision)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use rotor_testkit::arenstorf;

    /// The Arenstorf orbit is periodic: after one period the state returns to y0.
    /// The global error falls like tol (a few times tol for a proportional controller).
    #[test]
    fn arenstorf_returns_to_start() {
        for tol in [1e-8, 1e-10, 1e-12] {
            let mut c = Dop853::new(tol, tol);
            let (y, _) = integrate(
                &mut c,
                arenstorf::field,
                0.0,
                arenstorf::y0(),
                arenstorf::PERIOD,
                0.0,
            );
            let e = (y - arenstorf::y0()).amax();
            // This orbit amplifies local errors by ~1e3–1e4 (close passes to the moon), so
            // the bound is 1e4·tol; a wrong coefficient gives O(1) errors.
            assert!(e < 1e4 * tol, "tol {tol}: error {e}");
        }
    }

    /// Identical counts to an independent implementation of the same method whose counts
    /// match Hairer's Fortran `dop853` (russell_ode's DoPri8, used here only as an oracle).
    #[test]
    fn arenstorf_counts_match_reference_implementation() {
        use russell_lab::Vector;
        use russell_ode::{Method, OdeSolver, Params, Samples};
        let (system, x0, mut y0, x1, mut args, _) = Samples::arenstorf();
        let mut params = Params::new(Method::DoPri8);
        params.step.h_ini = 1e-4;
        params.set_tolerances(1e-7, 1e-7, None).unwrap();
        let mut solver = OdeSolver::new(params, system).unwrap();
        solver
            .solve(&mut y0, x0, x1, None, &mut args, None)
            .unwrap();
        let st = solver.stats();
        let mut c = Dop853::new(1e-7, 1e-7);
        let (y, n) = integrate(&mut c, arenstorf::field, x0, arenstorf::y0(), x1, 1e-4);
        let yr: &Vector = &y0;
        assert_eq!(n.accepted as usize, st.n_accepted);
        assert_eq!(n.rejected as usize, st.n_rejected);
        assert_eq!(n.fcn as usize, st.n_function);
        for i in 0..4 {
            // Identical step sequences (counts above), so the states differ only by rounding
            // in a different operation order, amplified by the orbit (measured 2.3e-10; the
            // integration error itself is ~1e-3 at this tolerance). 1e-8 still rejects any
            // different step or coefficient.
            assert!(
                (y[i] - yr[i]).abs() < 1e-8,
                "component {i}: {} vs {}",
                y[i],
                yr[i]
            );
        }
    }

    /// Dense output: a continuous extension of order 7, so its local error at an interior
    /// point is O(h^8): halving h divides it by about 2^8. Its derivative is the field at
    /// both ends (Hermite) and, as the derivative of an interpolant of order 7, has local
    /// error O(h^7) inside.
    #[test]
    fn dense_output_and_its_rate_on_harmonic_oscillator() {
        let mut f = |_t: f64, y: &Vector2<f64>| Vector2::new(y[1], -y[0]);
        let c = Dop853::new(1e-12, 1e-12);
        let y0 = Vector2::new(1.0, 0.0);
        let f0 = f(0.0, &y0);
        let mut err = |h: f64, s: f64| {
            let tr = c.trial(&mut f, 0.0, &y0, &f0, h);
            let f1 = f(h, &tr.y1);
            let d = c.dense(&mut f, &tr, &f1);
            // Endpoints are reproduced exactly by construction.
            assert_eq!(d.eval(0.0), y0);
            assert!((d.eval(h) - tr.y1).amax() < 1e-15);
            // The rate at the ends: the field there, to rounding (a few ulps of the O(1)
            // coefficients).
            assert!((d.eval_with_rate(0.0).1 - f0).amax() < 1e-14);
            assert!((d.eval_with_rate(h).1 - f1).amax() < 1e-14);
            let t = s * h;
            let (y, r) = d.eval_with_rate(t);
            // Same value as eval (a different association of the same polynomial).
            assert!((y - d.eval(t)).amax() < 1e-15);
            ((y[0] - t.cos()).abs(), (r[0] + t.sin()).abs())
        };
        for s in [0.1, 0.37, 0.5, 0.81] {
            let (big, small) = (err(0.8, s), err(0.4, s));
            // Asymptotic local orders 8 (state) and 7 (rate); at h = 0.8/0.4 the measured
            // values lie within ±0.6.
            let order = (big.0 / small.0).log2();
            assert!(
                (order - 8.0).abs() < 0.6,
                "s = {s}: observed local order {order}"
            );
            let order = (big.1 / small.1).log2();
            assert!(
                (order - 7.0).abs() < 0.6,
                "s = {s}: observed local order of the rate {order}"
            );
        }
    }

    /// Order 8: halving the step of a fixed-step run divides the error by about 2^8.
    #[test]
    fn observed_order_is_eight() {
        let mut f = |_t: f64, y: &Vector2<f64>| Vector2::new(y[1], -y[0]);
        let c = Dop853::new(1.0, 1.0);
        let run = |f: &mut dyn FnMut(f64, &Vector2<f64>) -> Vector2<f64>, n: usize| {
            let h = 4.0 / n as f64;
            let mut y = Vector2::new(1.0, 0.0);
            let mut g = |t: f64, y: &Vector2<f64>| f(t, y);
            for i in 0..n {
                let t = i as f64 * h;
                let f0 = g(t, &y);
                y = c.trial(&mut g, t, &y, &f0, h).y1;
            }
            (y[0] - 4.0_f64.cos()).abs()
        };
        let e1 = run(&mut f, 8);
        let e2 = run(&mut f, 16);
        let order = (e1 / e2).log2();
        // Asymptotic order 8; at these step sizes the measured ratio is within ±0.5 of it.
        assert!((order - 8.0).abs() < 0.5, "observed order {order}");
    }
}
