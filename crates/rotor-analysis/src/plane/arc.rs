//! Pseudo-arclength continuation of a curve `H(y) = 0`, `H: Rⁿ → Rⁿ⁻¹`, with finite-difference
//! Jacobians: the workhorse of the two-parameter curves ([`crate::plane::curves`]).
//!
//! From a point `y_k` with unit tangent `t_k` (the null vector of `DH(y_k)`, oriented along
//! the previous one), predict `y_p = y_k + h t_k` and correct with Newton's method (chord: the
//! Jacobian at the predictor) on
//!
//! ```text
//! H(y) = 0,     t_k · (y − y_p) = 0.
//! ```
//!
//! All of it in scaled coordinates `y_i / s_i`, so that a parameter of size 0.07 and an input
//! of size 5 take comparable steps. The step grows by 1.5 after a correction in at most three
//! iterations and halves after a failure, down to `h_min`.

use nalgebra::{DMatrix, DVector};

use crate::bifurcation::BifError;

/// Continuation settings (in scaled coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcOptions {
    /// The first step.
    pub h0: f64,
    /// The largest step.
    pub h_max: f64,
    /// The smallest step: a correction that fails below it ends the curve.
    pub h_min: f64,
    /// Most points, the start included.
    pub max_points: usize,
    /// Newton stops at `|H|∞ ≤ tol` and a scaled update below `1e3·tol`.
    pub tol: f64,
    /// Relative finite-difference step of the Jacobian.
    pub fd: f64,
}

/// Why a curve ended.
#[derive(Debug, Clone, PartialEq)]
pub enum ArcEnd {
    /// It left the region (`inside` returned false).
    Left,
    /// The step collapsed below `h_min`: the defining system failed or became singular (a
    /// curve ending, meeting another, or losing its defining object).
    Stuck(String),
    /// The point limit.
    MaxPoints,
}

/// A defining system: `H(y)`.
pub(crate) type System<'a> = dyn Fn(&[f64]) -> Result<Vec<f64>, BifError> + 'a;

/// `DH(y)` by forward differences, `(n−1) × n`, in scaled coordinates.
fn jacobian(
    h: &System,
    y: &[f64],
    hy: &[f64],
    scale: &[f64],
    fd: f64,
) -> Result<DMatrix<f64>, BifError> {
    let n = y.len();
    let mut j = DMatrix::zeros(n - 1, n);
    for k in 0..n {
        let d = fd * scale[k].max(y[k].abs());
        let mut yk = y.to_vec();
        yk[k] += d;
        let hk = h(&yk)?;
        for i in 0..n - 1 {
            j[(i, k)] = (hk[i] - hy[i]) / d * scale[k];
        }
    }
    Ok(j)
}

/// The unit null vector of `j` (scaled), oriented along `along`.
fn tangent(j: &DMatrix<f64>, along: &[f64]) -> Result<Vec<f64>, BifError> {
    let n = j.ncols();
    let mut a = DMatrix::zeros(n, n);
    a.view_mut((0, 0), (n - 1, n)).copy_from(j);
    for k in 0..n {
        a[(n - 1, k)] = along[k];
    }
    let mut rhs = DVector::zeros(n);
    rhs[n - 1] = 1.0;
    let t = a
        .lu()
        .solve(&rhs)
        .ok_or_else(|| BifError::Degenerate("singular tangent system".into()))?;
    let norm = t.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(BifError::Degenerate("no tangent".into()));
    }
    Ok(t.iter().map(|v| v / norm).collect())
}

/// Follows `H(y) = 0` from `y0` (on the curve) in the direction `dir` (scaled, need not be a
/// tangent: the first tangent is oriented along it) while `inside(y)`; returns the points
/// (`y0` first) and why it ended.
pub fn follow(
    h: &System,
    y0: &[f64],
    dir: &[f64],
    scale: &[f64],
    opts: &ArcOptions,
    inside: &dyn Fn(&[f64]) -> bool,
) -> (Vec<Vec<f64>>, ArcEnd) {
    let n = y0.len();
    let to_y = |s: &[f64]| -> Vec<f64> { s.iter().zip(scale).map(|(v, c)| v * c).collect() };
    let to_s = |y: &[f64]| -> Vec<f64> { y.iter().zip(scale).map(|(v, c)| v / c).collect() };
    let mut pts = vec![y0.to_vec()];
    let start = (|| {
        let hy = h(y0)?;
        let j = jacobian(h, y0, &hy, scale, opts.fd)?;
        tangent(&j, dir)
    })();
    let mut t = match start {
        Ok(t) => t,
        Err(e) => return (pts, ArcEnd::Stuck(e.to_string())),
    };
    let mut ys = to_s(y0);
    let mut step = opts.h0;
    while pts.len() < opts.max_points {
        let pred: Vec<f64> = (0..n).map(|k| ys[k] + step * t[k]).collect();
        match correct(h, &pred, &t, scale, opts, &to_y) {
            Ok((next_s, its, j)) => {
                let y = to_y(&next_s);
                if !inside(&y) {
                    pts.push(y);
                    return (pts, ArcEnd::Left);
                }
                let new_t = match tangent(&j, &t) {
                    Ok(nt) => nt,
                    Err(e) => return (pts, ArcEnd::Stuck(e.to_string())),
                };
                // A sharp turn: retry with a shorter step.
                let turn: f64 = new_t.iter().zip(&t).map(|(a, b)| a * b).sum();
                if turn < 0.9 && step > 4.0 * opts.h_min {
                    step *= 0.5;
                    continue;
                }
                pts.push(y);
                ys = next_s;
                t = new_t;
                if its <= 3 {
                    step = (step * 1.5).min(opts.h_max);
                }
            }
            Err(e) => {
                step *= 0.5;
                if step < opts.h_min {
                    return (pts, ArcEnd::Stuck(e.to_string()));
                }
            }
        }
    }
    (pts, ArcEnd::MaxPoints)
}

/// Newton (chord) on `H(y) = 0`, `t·(y − pred) = 0` from the predictor (scaled); returns the
/// point, the iterations, and the Jacobian there.
fn correct(
    h: &System,
    pred: &[f64],
    t: &[f64],
    scale: &[f64],
    opts: &ArcOptions,
    to_y: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Result<(Vec<f64>, usize, DMatrix<f64>), BifError> {
    let n = pred.len();
    let mut ys = pred.to_vec();
    let y = to_y(&ys);
    let hy = h(&y)?;
    let j0 = jacobian(h, &y, &hy, scale, opts.fd)?;
    let mut a = DMatrix::zeros(n, n);
    a.view_mut((0, 0), (n - 1, n)).copy_from(&j0);
    for k in 0..n {
        a[(n - 1, k)] = t[k];
    }
    let lu = a.lu();
    let mut hy = hy;
    for it in 1..=10 {
        let mut rhs = DVector::zeros(n);
        for i in 0..n - 1 {
            rhs[i] = -hy[i];
        }
        rhs[n - 1] = -(0..n).map(|k| t[k] * (ys[k] - pred[k])).sum::<f64>();
        let d = lu
            .solve(&rhs)
            .ok_or_else(|| BifError::Degenerate("singular corrector".into()))?;
        for k in 0..n {
            ys[k] += d[k];
        }
        let y = to_y(&ys);
        hy = h(&y)?;
        let res = hy.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !res.is_finite() {
            return Err(BifError::Degenerate("non-finite residual".into()));
        }
        if res <= opts.tol && d.amax() <= 1e3 * opts.tol.max(1e-12) {
            let j = jacobian(h, &y, &hy, scale, opts.fd)?;
            return Ok((ys, it, j));
        }
    }
    Err(BifError::Degenerate(
        "the corrector did not converge in 10 iterations".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit circle x² + y² = 1 from (1, 0) counter-clockwise: every point on it, and the
    /// whole way round in steps of at most h_max.
    #[test]
    fn follows_a_circle() {
        let h = |y: &[f64]| Ok(vec![y[0] * y[0] + y[1] * y[1] - 1.0]);
        let opts = ArcOptions {
            h0: 0.05,
            h_max: 0.2,
            h_min: 1e-6,
            max_points: 200,
            tol: 1e-12,
            fd: 1e-7,
        };
        let (pts, end) = follow(&h, &[1.0, 0.0], &[0.0, 1.0], &[1.0, 1.0], &opts, &|y| {
            y[1] > -0.5 || y[0] > 0.0
        });
        assert_eq!(end, ArcEnd::Left);
        for p in &pts {
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-10, "{p:?}");
        }
        // Counter-clockwise: up first, round through (−1, 0).
        assert!(pts[1][1] > 0.0);
        assert!(pts.iter().any(|p| p[0] < -0.99));
    }
}
