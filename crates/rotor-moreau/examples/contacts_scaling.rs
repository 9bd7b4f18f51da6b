//! The coupled-contact one-step solver against the number of contacts N: linear solves per
//! step (cold, from every disc stuck; warm, from the previous step's modes) and time per
//! solve, on the one-step problems of a chain of rig-like discs at steps of 0.01–0.5 s with
//! random free velocities.
//!
//! `cargo run --release -p rotor-moreau --example contacts_scaling [PROBLEMS]`
//!
//! Prints, per N: the largest and mean number of linear solves cold and warm, and the median
//! time per solve (warm) in microseconds, with its ratio to N = 2's over N / 2 (1 = linear).

use std::time::Instant;

use rotor_model::DiscMode;
use rotor_moreau::ContactSolver;
use rotor_moreau::contacts::{Tridiagonal, residual};

/// A small linear-congruential generator: the example needs no statistics, only many
/// different problems, reproducibly.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The rig's top disc, then N − 1 copies of its lower disc on its spring (Table 1), at step
/// h with θ = 1/2: `A = M + θ²h²K`; free velocities b/J uniform in ±5 rad/s; each disc's
/// impulse interval h·[−T, T] with the lower law's static level T = 0.1642 N m (the top
/// disc's law is viscous: interval 0).
fn problem(n: usize, h: f64, g: &mut Lcg) -> (Tridiagonal, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (j_top, j, k, t_s) = (0.4765, 0.0326, 0.0727, 0.1642);
    let inertia: Vec<f64> = (0..n).map(|i| if i == 0 { j_top } else { j }).collect();
    let s = 0.25 * h * h * k;
    let mut diag = inertia.clone();
    for i in 0..n - 1 {
        diag[i] += s;
        diag[i + 1] += s;
    }
    let a = Tridiagonal {
        diag,
        off: vec![-s; n - 1],
    };
    let b: Vec<f64> = inertia
        .iter()
        .map(|&m| m * 10.0 * (g.next() - 0.5))
        .collect();
    let level: Vec<f64> = (0..n).map(|i| if i == 0 { 0.0 } else { h * t_s }).collect();
    let lo = level.iter().map(|l| -l).collect();
    (a, b, lo, level)
}

fn main() {
    let problems: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2000);
    let mut g = Lcg(7);
    let mut base = None;
    println!("   N  cold max  cold mean  warm max  warm mean  µs/solve  (µs/solve)/(N/2)/N=2's");
    for n in [2usize, 4, 8, 16, 32, 64] {
        let (mut cold_max, mut cold_sum, mut warm_max, mut warm_sum) = (0, 0, 0, 0);
        let mut times = Vec::new();
        let mut s = ContactSolver::new(n);
        for p in 0..problems {
            let h = [0.01, 0.05, 0.1, 0.5][p % 4];
            let (a, b, lo, hi) = problem(n, h, &mut g);
            s.warm_start(&vec![DiscMode::Stick; n]);
            s.solve(&a, &b, &lo, &hi).expect("cold solve");
            cold_max = cold_max.max(s.iterations());
            cold_sum += s.iterations();
            // A nearby problem (the next step's): the free velocities moved by 1 %.
            let b2: Vec<f64> = b
                .iter()
                .map(|x| x * (1.0 + 0.02 * (g.next() - 0.5)))
                .collect();
            let t0 = Instant::now();
            s.solve(&a, &b2, &lo, &hi).expect("warm solve");
            times.push(t0.elapsed().as_secs_f64());
            warm_max = warm_max.max(s.iterations());
            warm_sum += s.iterations();
            assert!(residual(&a, &b2, &lo, &hi, s.v(), s.r()) <= 1e-14);
        }
        times.sort_by(f64::total_cmp);
        let us = 1e6 * times[times.len() / 2];
        let per = us / (n as f64 / 2.0);
        let base = *base.get_or_insert(per);
        println!(
            "{n:>4}  {cold_max:>8}  {:>9.2}  {warm_max:>8}  {:>9.2}  {us:>8.3}  {:>6.2}",
            cold_sum as f64 / problems as f64,
            warm_sum as f64 / problems as f64,
            per / base
        );
    }
}
