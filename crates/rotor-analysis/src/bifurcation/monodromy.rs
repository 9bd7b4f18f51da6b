//! Variational equations along a Filippov trajectory, with saltation matrices at every
//! switching event: the monodromy matrix of a cycle and the exact (to the integration
//! tolerance) derivatives of the return maps.
//!
//! Between two events the trajectory follows the smooth field `f_m(x, u)` of its mode `m`
//! (in a stick mode the stuck disc's velocity is held at 0 and its friction is the
//! equivalent control, `rotor_model::Model::rhs`). Along it the sensitivities to the initial
//! state, `X(t) = ∂x(t)/∂x₀`, and to the input, `p(t) = ∂x(t)/∂u`, obey
//!
//! ```text
//! Ẋ = J_m(x) X,            X(0) = I,
//! ṗ = J_m(x) p + ∂f_m/∂u,  p(0) = 0,       J_m = ∂f_m/∂x  (Model::jacobian).
//! ```
//!
//! On a stick segment `J_m` has a zero row and column for the stuck disc's velocity: the
//! variational dynamics is that of the sliding vector field.
//!
//! At an event on the surface `h(x, u) = 0`, with `n = ∇ₓh`, the pre-event field `f⁻` and the
//! post-event field `f⁺` (both at the event state), the perturbed trajectory reaches the
//! surface `δt = −(nᵀδx + h_u δu)/(nᵀf⁻)` later, so
//!
//! ```text
//! δx⁺ = S δx⁻ + (f⁺ − f⁻) h_u/(nᵀf⁻) δu,     S = I + (f⁺ − f⁻) nᵀ / (nᵀ f⁻).
//! ```
//!
//! The surfaces of the rotor:
//!
//! * **stick onset** of disc d (slip → stick) and **reversal** (slip± → slip∓): `h = ω_d`,
//!   `n = e_d`, `h_u = 0`. At a stick onset `f⁺ − f⁻ = −f⁻_d e_d` (only the stuck disc's
//!   acceleration changes, to 0; `α̇` is continuous since `ω_d = 0`), so `S = I − e_d e_dᵀ`:
//!   the normal direction is projected out, and a cycle with a stick phase has the Floquet
//!   multiplier exactly 0.
//! * **stick exit** (stick → slip): `h = T_ex,d(x, u) − T_bound`, with `T_ex,l = k_θ α`
//!   (`n = k_θ e_α`, `h_u = 0`) and `T_ex,u = k_m u − k_θ α` (`n = −k_θ e_α`, `h_u = k_m`).
//!   There the applied torque equals the friction bound, so the slip field starts with zero
//!   acceleration: `f⁺ = f⁻` and `S = I` (up to the rounding of the located exit).
//!
//! The Floquet multipliers of a cycle are the eigenvalues of the monodromy matrix
//! `Φ(T) = X(T)` taken over one period from a point of the cycle: one is 1 (the time shift,
//! eigenvector `f(x₀)`), the others are those of the Poincaré map.

use nalgebra::{Complex, Matrix3, SVector, Vector3};
use rotor_event::dop853::Dop853;
use rotor_model::seam::{Event, EventKind};
use rotor_model::{Disc, DiscMode, Mode, Model, State};

use crate::bifurcation::BifError;

/// Dimension of the augmented system: `x` (3), `X` column-major (9), `p` (3).
const DIM: usize = 15;
type Aug = SVector<f64, DIM>;

/// Most steps per smooth segment before the integration is abandoned.
const MAX_STEPS: usize = 1_000_000;

/// One switching event on the way, with its saltation matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switch {
    /// Time of the event from the start `x₀` of the piece \[s\].
    pub t: f64,
    /// The surface crossed, and by which disc ([`surface`]).
    pub kind: EventKind,
    /// Mode before the event (its field is `f⁻`).
    pub before: Mode,
    /// Mode after the event ([`mode_after`]; its field is `f⁺`).
    pub after: Mode,
    /// `S = I + (f⁺ − f⁻) nᵀ / (nᵀ f⁻)`.
    pub saltation: Matrix3<f64>,
}

/// Sensitivities of a trajectory piece of duration `t` from `x₀` (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Variational {
    /// Duration \[s\].
    pub t: f64,
    /// State at the end, as integrated with the variational equations.
    pub x_end: State,
    /// Mode at the end.
    pub mode_end: Mode,
    /// `X(t) = ∂x(t)/∂x₀`, saltation matrices included.
    pub phi: Matrix3<f64>,
    /// `p(t) = ∂x(t)/∂u` at fixed `x₀`.
    pub p: Vector3<f64>,
    /// The switching events, in time order.
    pub switches: Vec<Switch>,
}

impl Variational {
    /// Eigenvalues of `phi`: the Floquet multipliers when the piece is one period of a cycle.
    pub fn multipliers(&self) -> [Complex<f64>; 3] {
        let e = self.phi.complex_eigenvalues();
        [e[0], e[1], e[2]]
    }
}

/// The switching surface of an event: `(n, h_u)` with `n = ∇ₓh` and `h_u = ∂h/∂u`.
pub fn surface(model: &Model, kind: EventKind) -> Option<(Vector3<f64>, f64)> {
    let k = model.params.k_theta;
    match kind {
        EventKind::StickStart(d) | EventKind::Reversal(d) => {
            let mut n = Vector3::zeros();
            n[d.index()] = 1.0;
            Some((n, 0.0))
        }
        // The upper disc's applied torque is k_m u − k_θ α, the lower one's k_θ α.
        EventKind::StickEnd(d) if d == Disc::UPPER => {
            Some((Vector3::new(-k, 0.0, 0.0), model.params.k_m))
        }
        EventKind::StickEnd(_) => Some((Vector3::new(k, 0.0, 0.0), 0.0)),
        EventKind::Max(_) | EventKind::Min(_) => None,
    }
}

/// The mode after a switching event of `kind` at state `x` (the flow's own rules: a stick
/// onset sticks the disc, an exit slips it the way the applied torque pushes, a reversal
/// flips its slip branch).
pub fn mode_after(model: &Model, u: f64, x: &State, before: Mode, kind: EventKind) -> Mode {
    let mut m = before;
    match kind {
        EventKind::StickStart(d) => m.set(d, DiscMode::Stick),
        EventKind::StickEnd(d) => {
            let (lo, hi) = model.friction(d).static_interval();
            let t = model.applied_torque(d, x, u);
            m.set(
                d,
                if t >= 0.5 * (lo + hi) {
                    DiscMode::SlipPos
                } else {
                    DiscMode::SlipNeg
                },
            );
        }
        EventKind::Reversal(d) => m.set(
            d,
            match before.of(d) {
                DiscMode::SlipPos => DiscMode::SlipNeg,
                DiscMode::SlipNeg => DiscMode::SlipPos,
                DiscMode::Stick => DiscMode::Stick,
            },
        ),
        EventKind::Max(_) | EventKind::Min(_) => {}
    }
    m
}

/// The saltation matrix `S` and the jump `(f⁺ − f⁻) h_u/(nᵀf⁻)` of the u-sensitivity at an
/// event state `x` between the fields of `before` and `after`.
pub fn saltation(
    model: &Model,
    u: f64,
    x: &State,
    before: Mode,
    after: Mode,
    n: &Vector3<f64>,
    h_u: f64,
) -> Result<(Matrix3<f64>, Vector3<f64>), BifError> {
    let fm = model.rhs(x, u, before);
    let fp = model.rhs(x, u, after);
    let den = n.dot(&fm);
    if den == 0.0 || !den.is_finite() {
        return Err(BifError::Grazing {
            u,
            state: [x[0], x[1], x[2]],
        });
    }
    let df = fp - fm;
    Ok((
        Matrix3::identity() + df * n.transpose() / den,
        df * (h_u / den),
    ))
}

fn pack(x: &State, phi: &Matrix3<f64>, p: &Vector3<f64>) -> Aug {
    let mut y = Aug::zeros();
    y.fixed_rows_mut::<3>(0).copy_from(x);
    for c in 0..3 {
        for r in 0..3 {
            y[3 + 3 * c + r] = phi[(r, c)];
        }
    }
    y.fixed_rows_mut::<3>(12).copy_from(p);
    y
}

fn unpack(y: &Aug) -> (State, Matrix3<f64>, Vector3<f64>) {
    let x = State::new(y[0], y[1], y[2]);
    let phi = Matrix3::from_fn(|r, c| y[3 + 3 * c + r]);
    let p = Vector3::new(y[12], y[13], y[14]);
    (x, phi, p)
}

/// The augmented field `(f, J X, J p + f_u)` of one mode.
fn aug_rhs(model: &Model, u: f64, mode: Mode, y: &Aug) -> Aug {
    let (x, phi, p) = unpack(y);
    let f = model.rhs(&x, u, mode);
    let j = model.jacobian(&x, u, mode);
    pack(&f, &(j * phi), &(j * p + model.d_rhs_du(mode)))
}

/// Integrates the augmented system of one mode over `[0, len]` with DOP853 at `tol`.
fn segment(
    model: &Model,
    u: f64,
    tol: f64,
    mode: Mode,
    len: f64,
    y0: Aug,
) -> Result<Aug, BifError> {
    if len <= 0.0 {
        return Ok(y0);
    }
    let mut ctl = Dop853::new(tol, tol);
    let mut f = |_t: f64, y: &Aug| aug_rhs(model, u, mode, y);
    let mut y = y0;
    let mut t = 0.0;
    let mut f0 = f(t, &y);
    let mut h = ctl.initial_step(&mut f, t, &y, &f0).min(len);
    ctl.restart();
    for _ in 0..MAX_STEPS {
        let last = t + 1.01 * h >= len;
        if last {
            h = len - t;
        }
        let tr = ctl.trial(&mut f, t, &y, &f0, h);
        if Dop853::acceptable(&tr) {
            let h_new = ctl.accept(tr.err, h);
            y = tr.y1;
            if last {
                return Ok(y);
            }
            t += h;
            f0 = f(t, &y);
            h = h_new;
        } else {
            h = ctl.reject(tr.err, h);
        }
        if h.is_nan() || h <= 1e-14 * len.max(1.0) {
            break;
        }
    }
    Err(BifError::Degenerate(format!(
        "variational equations: step size collapsed at t = {t} of a {len} s segment (u = {u})"
    )))
}

/// Integrates the variational equations along a trajectory of the Filippov system from
/// `(x0, mode0)` for `t_end` seconds, whose switching events (as reported by
/// `rotor_event::flow`) are `events`. A disc stuck in `mode0` starts at velocity 0 whatever
/// `x0` says, so `X(0)` has its column zeroed. Each smooth piece restarts from the event state of the
/// flow (where the event condition holds to rounding), and each event applies its saltation
/// matrix.
pub fn along(
    model: &Model,
    u: f64,
    tol: f64,
    x0: State,
    mode0: Mode,
    events: &[Event],
    t_end: f64,
) -> Result<Variational, BifError> {
    let mut mode = mode0;
    let mut x = x0;
    // A disc stuck at the start has its velocity set to 0 (as the flow does): the initial
    // sensitivity is that map's derivative, I with the stuck discs' columns zeroed.
    let mut phi = Matrix3::identity();
    for d in Disc::BOTH {
        if mode.of(d) == DiscMode::Stick {
            x[d.index()] = 0.0;
            phi[(d.index(), d.index())] = 0.0;
        }
    }
    let mut p = Vector3::zeros();
    let mut t = 0.0;
    let mut switches = Vec::new();
    for e in events {
        let Some((n, h_u)) = surface(model, e.kind) else {
            continue;
        };
        let y = segment(model, u, tol, mode, e.t - t, pack(&x, &phi, &p))?;
        let (_, phi_m, p_m) = unpack(&y);
        let xe = e.state();
        let after = mode_after(model, u, &xe, mode, e.kind);
        let (s, jump) = saltation(model, u, &xe, mode, after, &n, h_u)?;
        phi = s * phi_m;
        p = s * p_m + jump;
        switches.push(Switch {
            t: e.t,
            kind: e.kind,
            before: mode,
            after,
            saltation: s,
        });
        x = xe;
        mode = after;
        t = e.t;
    }
    let y = segment(model, u, tol, mode, t_end - t, pack(&x, &phi, &p))?;
    let (x_end, phi, p) = unpack(&y);
    Ok(Variational {
        t: t_end,
        x_end,
        mode_end: mode,
        phi,
        p,
        switches,
    })
}

/// The Floquet multipliers ordered for reporting: the one nearest 1 (the trivial one, up to
/// the integration error) first, then the others by decreasing modulus.
pub(crate) fn order_multipliers(m: [Complex<f64>; 3]) -> [Complex<f64>; 3] {
    let one = Complex::new(1.0, 0.0);
    let mut v = m;
    let k = (0..3)
        .min_by(|&a, &b| (v[a] - one).norm().total_cmp(&(v[b] - one).norm()))
        .unwrap_or(0);
    v.swap(0, k);
    if v[2].norm() > v[1].norm() {
        v.swap(1, 2);
    }
    v
}
