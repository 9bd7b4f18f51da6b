//! How the state's representation costs a 3-state run: the rig's field integrated by classic
//! RK4 (h = 1e-3 s, Table 1 at 1.5 V, both discs slipping, 200,000 steps) with
//!
//! * `vector3`: today's [`rotor_model::Model::rhs`] on `nalgebra::Vector3` (size in the type);
//! * `array`: [`rotor_model::ChainModel::rhs_into`] on stack arrays `[f64; 3]` (size as data
//!   inside the field, fixed at the caller);
//! * `dvector`: the same field on `nalgebra::DVector` buffers allocated once (size as data
//!   everywhere);
//! * `dvector-alloc`: `DVector` with a fresh vector per stage (what naive code does).
//!
//! The four run interleaved, 9 rounds each, in one process; it prints each one's median time
//! per step and its ratio to `vector3`. docs/design.md ("The seam's sizes") quotes the result.
//!
//! `cargo run --release -p rotor-model --example state_representation`

use std::hint::black_box;
use std::time::Instant;

use nalgebra::DVector;
use rotor_model::{ChainModel, ChainParams, DiscMode, Mode, Model, Params, State};

const STEPS: usize = 200_000;
const H: f64 = 1e-3;
const U: f64 = 1.5;

fn vector3(m: &Model) -> f64 {
    let mode = Mode::rig(DiscMode::SlipPos, DiscMode::SlipPos);
    let f = |x: &State| m.rhs(x, U, mode);
    let mut x = State::new(0.5, 2.0, 1.0);
    for _ in 0..STEPS {
        let k1 = f(&x);
        let k2 = f(&(x + k1 * (0.5 * H)));
        let k3 = f(&(x + k2 * (0.5 * H)));
        let k4 = f(&(x + k3 * H));
        x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (H / 6.0);
    }
    x[2]
}

fn array(m: &ChainModel) -> f64 {
    let modes = Mode::SLIP;
    let f = |x: &[f64; 3], out: &mut [f64; 3]| m.rhs_into(x, U, modes, out);
    let mut x = [0.5, 2.0, 1.0];
    let (mut k1, mut k2, mut k3, mut k4, mut y) =
        ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    for _ in 0..STEPS {
        f(&x, &mut k1);
        for r in 0..3 {
            y[r] = x[r] + 0.5 * H * k1[r];
        }
        f(&y, &mut k2);
        for r in 0..3 {
            y[r] = x[r] + 0.5 * H * k2[r];
        }
        f(&y, &mut k3);
        for r in 0..3 {
            y[r] = x[r] + H * k3[r];
        }
        f(&y, &mut k4);
        for r in 0..3 {
            x[r] += H / 6.0 * (k1[r] + 2.0 * k2[r] + 2.0 * k3[r] + k4[r]);
        }
    }
    x[2]
}

fn dvector(m: &ChainModel) -> f64 {
    let n = m.dim();
    let modes = Mode::uniform(m.discs(), DiscMode::SlipPos);
    let f = |x: &DVector<f64>, out: &mut DVector<f64>| {
        m.rhs_into(x.as_slice(), U, modes, out.as_mut_slice())
    };
    let mut x = DVector::from_vec(vec![0.5, 2.0, 1.0]);
    let mut k = [(); 4].map(|_| DVector::zeros(n));
    let mut y = DVector::zeros(n);
    for _ in 0..STEPS {
        f(&x, &mut k[0]);
        y.copy_from(&x);
        y.axpy(0.5 * H, &k[0], 1.0);
        f(&y, &mut k[1]);
        y.copy_from(&x);
        y.axpy(0.5 * H, &k[1], 1.0);
        f(&y, &mut k[2]);
        y.copy_from(&x);
        y.axpy(H, &k[2], 1.0);
        f(&y, &mut k[3]);
        x.axpy(H / 6.0, &k[0], 1.0);
        x.axpy(H / 3.0, &k[1], 1.0);
        x.axpy(H / 3.0, &k[2], 1.0);
        x.axpy(H / 6.0, &k[3], 1.0);
    }
    x[2]
}

fn dvector_alloc(m: &ChainModel) -> f64 {
    let n = m.dim();
    let modes = Mode::uniform(m.discs(), DiscMode::SlipPos);
    let f = |x: &DVector<f64>| {
        let mut out = DVector::zeros(n);
        m.rhs_into(x.as_slice(), U, modes, out.as_mut_slice());
        out
    };
    let mut x = DVector::from_vec(vec![0.5, 2.0, 1.0]);
    for _ in 0..STEPS {
        let k1 = f(&x);
        let k2 = f(&(&x + &k1 * (0.5 * H)));
        let k3 = f(&(&x + &k2 * (0.5 * H)));
        let k4 = f(&(&x + &k3 * H));
        x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (H / 6.0);
    }
    x[2]
}

fn main() {
    let p = Params::table1();
    let rig = Model::new(p);
    let chain = ChainModel::new(&ChainParams::from_params(&p));
    let names = ["vector3", "array", "dvector", "dvector-alloc"];
    let mut times: [Vec<f64>; 4] = Default::default();
    let mut ends = [0.0; 4];
    for _ in 0..9 {
        for (i, t) in times.iter_mut().enumerate() {
            let start = Instant::now();
            ends[i] = black_box(match i {
                0 => vector3(black_box(&rig)),
                1 => array(black_box(&chain)),
                2 => dvector(black_box(&chain)),
                _ => dvector_alloc(black_box(&chain)),
            });
            t.push(start.elapsed().as_secs_f64() / STEPS as f64);
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let base = median(&mut times[0].clone());
    for (i, name) in names.iter().enumerate() {
        let m = median(&mut times[i]);
        println!(
            "{name:>14}: {:6.1} ns/step, ratio {:.3}, final omega_l {:.15}",
            m * 1e9,
            m / base,
            ends[i]
        );
    }
}
