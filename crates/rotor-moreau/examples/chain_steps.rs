//! Moreau–Jean on chains of N discs: the cost of a step against N, on the chain the scaling
//! benchmark names (the rig's top disc, then N − 1 copies of its lower disc, Table 1) at
//! 1.5 V from rest, step h = 1e-3, over 50 s (stick-slip throughout).
//!
//! `cargo run --release -p rotor-moreau --example chain_steps`
//!
//! Prints, per N: the one-step problems and linear solves per step, the median time per step
//! over five runs in microseconds, and that time over N = 2's times 2/N (1 = linear in N).
//! The chain of two here runs the chain stepper, not the rig's (which a chain of two in the
//! solvers will keep).

use std::time::Instant;

use rotor_model::Params;
use rotor_model::chain::{ChainModel, ChainParams};
use rotor_moreau::ChainStepper;

fn main() {
    let (h, t_end, u) = (1e-3, 50.0, 1.5);
    let steps = (t_end / h) as usize;
    let mut base = None;
    println!("    N  solves/step  linear/step  us/step  (us/step)/(N/2 * us_2)");
    for n in [2, 4, 8, 16, 32, 64] {
        let chain = ChainModel::new(&ChainParams::rig_copies(&Params::table1(), n));
        let mut times = Vec::new();
        let mut counts = None;
        for _ in 0..5 {
            let mut st = ChainStepper::new(&chain, h, 0.5);
            let mut x = vec![0.0; chain.dim()];
            let t0 = Instant::now();
            for _ in 0..steps {
                st.step(&mut x, u).expect("a step");
            }
            times.push(t0.elapsed().as_secs_f64() / steps as f64 * 1e6);
            assert!(x.iter().all(|v| v.is_finite()));
            counts = Some(st.counts());
        }
        times.sort_by(f64::total_cmp);
        let us = times[2];
        let c = counts.expect("five runs");
        let us_2 = *base.get_or_insert(us);
        println!(
            "{n:>5}  {:>11.3}  {:>11.3}  {us:>7.3}  {:>6.2}",
            c.solves as f64 / c.steps as f64,
            c.linear_solves as f64 / c.steps as f64,
            us / (us_2 * n as f64 / 2.0)
        );
    }
}
