//! The variational equations with saltation matrices along trajectories that are not cycles,
//! through the switches the cycles do not exercise: a reversal of the lower disc (slip+ to
//! slip− with a jump of the friction torque) and the upper disc's stick exit (a surface that
//! moves with u; the field is continuous there, so neither the state nor the u-sensitivity
//! jumps), starting with a stuck disc. Checked against central differences of the Filippov
//! flow over a fixed time.

use nalgebra::{Matrix3, Vector3};
use rotor_analysis::bifurcation::monodromy::{Variational, along};
use rotor_event::{StopAt, flow};
use rotor_model::seam::EventKind;
use rotor_model::{Disc, Mode, Model, State};

use crate::common::model;

const TOL: f64 = 1e-12;

fn end(m: &Model, u: f64, x0: State, mode: Mode, t: f64, tol: f64) -> State {
    flow(m, u, tol, x0, mode, t, StopAt::Time).unwrap().x
}

fn variational(m: &Model, u: f64, x0: State, mode: Mode, t: f64) -> Variational {
    let f = flow(m, u, TOL, x0, mode, t, StopAt::Time).unwrap();
    along(m, u, TOL, x0, mode, &f.events, t).unwrap()
}

/// Central differences of the end state in x₀ (columns 0..3) and u (column 3) with step h.
fn fd(m: &Model, u: f64, x0: State, mode: Mode, t: f64, h: f64) -> (Matrix3<f64>, Vector3<f64>) {
    let mut phi = Matrix3::zeros();
    for k in 0..3 {
        let mut e = State::zeros();
        e[k] = h;
        let col = (end(m, u, x0 + e, mode, t, TOL) - end(m, u, x0 - e, mode, t, TOL)) / (2.0 * h);
        phi.set_column(k, &col);
    }
    let p = (end(m, u + h, x0, mode, t, TOL) - end(m, u - h, x0, mode, t, TOL)) / (2.0 * h);
    (phi, p)
}

/// Same error model as the Floquet test: noise E/h with E the end state's global error
/// (against a 100× tighter run) plus the truncation estimated from the step 4h, doubled.
fn check(m: &Model, u: f64, x0: State, mode: Mode, t: f64, expect: EventKind) -> Matrix3<f64> {
    let v = variational(m, u, x0, mode, t);
    assert!(
        v.switches.iter().any(|s| s.kind == expect),
        "{:?}",
        v.switches
    );
    let e = (end(m, u, x0, mode, t, TOL) - end(m, u, x0, mode, t, TOL / 100.0))
        .amax()
        .max(TOL);
    let h = 1e-5;
    let (phi_h, p_h) = fd(m, u, x0, mode, t, h);
    let (phi_4h, p_4h) = fd(m, u, x0, mode, t, 4.0 * h);
    let bound = |a: f64, b: f64| 2.0 * (e / h + (b - a).abs() / 15.0);
    for r in 0..3 {
        for k in 0..3 {
            let b = bound(phi_h[(r, k)], phi_4h[(r, k)]);
            assert!(
                (v.phi[(r, k)] - phi_h[(r, k)]).abs() <= b,
                "{expect:?}: Phi[{r}{k}] = {} vs FD {} (bound {b:e})\n{}",
                v.phi[(r, k)],
                phi_h[(r, k)],
                v.phi
            );
        }
        let b = bound(p_h[r], p_4h[r]);
        assert!(
            (v.p[r] - p_h[r]).abs() <= b,
            "{expect:?}: p[{r}] = {} vs FD {} (bound {b:e})",
            v.p[r],
            p_h[r]
        );
    }
    // The saltation matrix of the switch, for the callers' structural checks.
    v.switches
        .iter()
        .find(|s| s.kind == expect)
        .unwrap()
        .saltation
}

#[test]
fn reversal_of_the_lower_disc() {
    // Table 1 at 1 V: k_θα = −0.218 N m < −T_sl = −0.164 N m, so the lower disc, slipping
    // forward at 0.05 rad/s, decelerates through 0 and slips backward (no stick).
    let m = model("table1");
    let x0 = State::new(-3.0, 1.0, 0.05);
    let mode = m.mode_at(&x0, 1.0);
    let s = check(&m, 1.0, x0, mode, 0.5, EventKind::Reversal(Disc::LOWER));
    // A genuine jump: f⁺₃ − f⁻₃ = 2T_sl/J_l ≈ 10 rad/s² against f⁻₃ ≈ −12 rad/s², so S
    // differs from I by O(1) (the comparison above fails if S is left out).
    assert!((s - Matrix3::identity()).amax() > 0.1, "{s}");
}

#[test]
fn stick_exit_of_the_upper_disc_moves_with_u() {
    // Stribeck set at 0.5 V: the upper disc stuck with its applied torque 0.01 N m below
    // the break-away level T_su + ΔT_su; the lower disc slipping forward lowers α, so the
    // applied torque k_m u − k_θα rises and the upper disc breaks away after ~0.13 s. The
    // exit surface depends on u (h_u = k_m) and the stick phase has ∂f/∂u = 0 for the upper
    // disc; the stuck start zeroes the ω_u column of X(0).
    let m = model("stribeck");
    let u = 0.5;
    let (_, hi) = m.friction(Disc::UPPER).static_interval();
    let alpha = (m.params.k_m * u - (hi - 0.01)) / m.params.k_theta;
    let x0 = State::new(alpha, 0.0, 1.0);
    let mode = m.mode_at(&x0, u);
    assert_eq!(mode.upper(), rotor_model::DiscMode::Stick);
    let s = check(&m, u, x0, mode, 0.5, EventKind::StickEnd(Disc::UPPER));
    // At an exit the applied torque equals the break-away level, which is also the slip
    // branch's torque at ω = 0⁺: f is continuous, so S = I and the u-jump vanishes (to the
    // rounding of the located exit, as for the lower disc).
    assert!((s - Matrix3::identity()).amax() < 1e-11, "{s}");
}
