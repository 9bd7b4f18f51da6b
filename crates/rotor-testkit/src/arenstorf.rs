//! The Arenstorf orbit (Hairer–Nørsett–Wanner I, eq. II.0.1): the restricted three-body
//! problem's periodic orbit that the DOP853 and DOPRI5 steppers of `rotor-event` and
//! `rotor-switch` are checked on (periodicity, and step counts against Hairer's codes).

use nalgebra::Vector4;

/// Mass ratio μ of the Moon.
const MU: f64 = 0.012277471;

/// The period, as published (HNW I, p. 130), with more digits than f64 holds.
#[allow(clippy::excessive_precision)]
pub const PERIOD: f64 = 17.0652165601579625588917206249;

/// The initial state `(y1, y2, y1', y2')`.
#[allow(clippy::excessive_precision)]
pub fn y0() -> Vector4<f64> {
    Vector4::new(0.994, 0.0, 0.0, -2.00158510637908252240537862224)
}

/// The vector field (autonomous; `t` is ignored).
pub fn field(_t: f64, y: &Vector4<f64>) -> Vector4<f64> {
    let mup = 1.0 - MU;
    let d1 = ((y[0] + MU).powi(2) + y[1].powi(2)).powf(1.5);
    let d2 = ((y[0] - mup).powi(2) + y[1].powi(2)).powf(1.5);
    Vector4::new(
        y[2],
        y[3],
        y[0] + 2.0 * y[3] - mup * (y[0] + MU) / d1 - MU * (y[0] - mup) / d2,
        y[1] - 2.0 * y[2] - mup * y[1] / d1 - MU * y[1] / d2,
    )
}
