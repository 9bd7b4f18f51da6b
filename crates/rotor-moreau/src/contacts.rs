//! The one-step problem of N coupled frictional contacts, solved exactly without
//! enumerating modes: block principal pivoting on a tridiagonal M-matrix.
//!
//! A chain's Moreau–Jean step asks for the velocities `v` at the end of the step and the
//! friction impulses `r` of its N discs (docs/methods.md §3, docs/model.md §4a):
//!
//! ```text
//! A v = b + r,      lo_i ≤ r_i ≤ hi_i,
//! v_i > 0 ⇒ r_i = lo_i,     v_i < 0 ⇒ r_i = hi_i,     lo_i < r_i < hi_i ⇒ v_i = 0
//! ```
//!
//! with `A = M + θhC + θ²h²K` the iteration matrix (symmetric, tridiagonal in the discs:
//! each spring and coupling joins neighbours) and `[lo_i, hi_i]` disc i's friction impulse
//! interval over the step (`lo ≤ hi`). These are the optimality conditions of the strictly
//! convex problem `min ½vᵀAv − bᵀv + Σ_i ψ_i(v_i)` with `ψ_i(w) = −lo_i·w` for `w ≥ 0`,
//! `−hi_i·w` for `w < 0` (convex because `hi_i ≥ lo_i`), so the solution is unique.
//! Equivalently, for any `c_i > 0`, `r_i = clamp(r_i − c_i v_i, lo_i, hi_i)`.
//!
//! **The method**: block principal pivoting on the box (Júdice & Pires 1994, "A block
//! principal pivoting algorithm for large-scale strictly monotone linear complementarity
//! problems"). Given a mode per disc (stuck:
//! `v_i = 0`; slipping forward: `r_i = lo_i`; backward: `r_i = hi_i`), the conditions are
//! one linear system: the slipping discs' rows of `A v = b + r` with the stuck discs'
//! velocities 0, a tridiagonal solve in O(N); then each stuck disc's impulse is
//! `(A v − b)_i`. A disc's mode is wrong if it slips against its velocity's sign (it then
//! sticks) or is stuck with its impulse outside `[lo_i, hi_i]` (it then slips toward the
//! bound it crossed). When no mode is wrong the conditions hold exactly (to the rounding of
//! one tridiagonal solve): nothing is iterated to a tolerance. Changing every wrong mode at
//! once is what makes the method fast, but it can cycle; so, as Júdice & Pires do, the
//! block change is taken while the number of wrong modes falls (or for three more tries),
//! and after that only the first wrong disc changes its mode, Murty's single principal
//! pivot, which terminates for a P-matrix (`A` is symmetric positive definite). A first
//! version read the next mode off `r_i − A_ii v_i`, letting a disc jump from one slip
//! direction to the other: on a random two-disc problem it cycled for ever, single
//! changes included. Warm-started from the previous step's modes the method takes one or
//! two solves.
//!
//! Each iteration costs O(N), so a step costs O(N) times its iteration count, where
//! enumerating the modes costs 3^N solves.

use rotor_model::DiscMode;

/// Block changes allowed without a fall in the number of discs whose mode is wrong before
/// the solver changes one disc at a time (Júdice & Pires' safeguard).
const BLOCK_GRACE: usize = 3;

/// A symmetric tridiagonal matrix: `diag[i] = A_ii`, `off[i] = A_{i,i+1} = A_{i+1,i}`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tridiagonal {
    /// The diagonal, length N.
    pub diag: Vec<f64>,
    /// The off-diagonal, length N − 1.
    pub off: Vec<f64>,
}

impl Tridiagonal {
    /// `A x`, written into `out`.
    pub fn mul_into(&self, x: &[f64], out: &mut [f64]) {
        let n = self.diag.len();
        for i in 0..n {
            let mut s = self.diag[i] * x[i];
            if i > 0 {
                s += self.off[i - 1] * x[i - 1];
            }
            if i + 1 < n {
                s += self.off[i] * x[i + 1];
            }
            out[i] = s;
        }
    }

    /// Whether the matrix is a Z-matrix with a positive diagonal (off-diagonal ≤ 0), the
    /// structure of a chain's iteration matrix (springs and couplings pull neighbours
    /// together); a positive definite one is an M-matrix.
    pub fn is_z_matrix(&self) -> bool {
        self.diag.iter().all(|&d| d > 0.0) && self.off.iter().all(|&e| e <= 0.0)
    }
}

/// Why the one-step problem was not solved.
#[derive(Debug, Clone, PartialEq)]
pub enum ContactError {
    /// The sizes of `A`, `b`, `lo` and `hi` disagree, or an interval is empty.
    Shape(String),
    /// A mode was still wrong at the iteration cap (never seen in the tests).
    NotConverged {
        /// Iterations taken.
        iterations: usize,
    },
    /// A pivot of the tridiagonal solve vanished or a value is not finite.
    Singular,
}

impl std::fmt::Display for ContactError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ContactError::Shape(why) => write!(f, "contact problem: {why}"),
            ContactError::NotConverged { iterations } => write!(
                f,
                "contact problem: the modes did not settle in {iterations} iterations"
            ),
            ContactError::Singular => write!(f, "contact problem: singular or non-finite"),
        }
    }
}

impl std::error::Error for ContactError {}

/// The solver's workspace: the modes (kept between solves as the next warm start), the
/// solution and the scratch of the tridiagonal solve, allocated once for N contacts.
#[derive(Debug, Clone)]
pub struct ContactSolver {
    modes: Vec<DiscMode>,
    next: Vec<DiscMode>,
    v: Vec<f64>,
    r: Vec<f64>,
    av: Vec<f64>,
    c_prime: Vec<f64>,
    d_prime: Vec<f64>,
    iterations: usize,
}

impl ContactSolver {
    /// A solver for `n` contacts, cold (every disc stuck as the first guess).
    pub fn new(n: usize) -> ContactSolver {
        ContactSolver {
            modes: vec![DiscMode::Stick; n],
            next: vec![DiscMode::Stick; n],
            v: vec![0.0; n],
            r: vec![0.0; n],
            av: vec![0.0; n],
            c_prime: vec![0.0; n],
            d_prime: vec![0.0; n],
            iterations: 0,
        }
    }

    /// Sets the modes the next solve starts from (the previous step's, say).
    pub fn warm_start(&mut self, modes: &[DiscMode]) {
        self.modes.copy_from_slice(modes);
    }

    /// The velocities `v` of the last solve.
    pub fn v(&self) -> &[f64] {
        &self.v
    }

    /// The impulses `r` of the last solve.
    pub fn r(&self) -> &[f64] {
        &self.r
    }

    /// Each disc's mode in the last solve.
    pub fn modes(&self) -> &[DiscMode] {
        &self.modes
    }

    /// Linear solves the last solve took (1 when its first guess was right).
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Solves `A v = b + r` with each disc's impulse in `[lo_i, hi_i]` complementary to its
    /// velocity (module docs), starting from the modes held. The cap, `20N + 50` linear
    /// solves, is far above what the measurements need (`examples/contacts_scaling.rs`).
    pub fn solve(
        &mut self,
        a: &Tridiagonal,
        b: &[f64],
        lo: &[f64],
        hi: &[f64],
    ) -> Result<(), ContactError> {
        let n = self.modes.len();
        if a.diag.len() != n
            || a.off.len() + 1 != n.max(1)
            || b.len() != n
            || lo.len() != n
            || hi.len() != n
        {
            return Err(ContactError::Shape(format!(
                "{n} contacts, A {}×{} (off {}), b {}, lo {}, hi {}",
                a.diag.len(),
                a.diag.len(),
                a.off.len(),
                b.len(),
                lo.len(),
                hi.len()
            )));
        }
        if let Some(i) = (0..n).find(|&i| lo[i].is_nan() || hi[i].is_nan() || lo[i] > hi[i]) {
            return Err(ContactError::Shape(format!(
                "contact {}: interval [{}, {}] is empty",
                i + 1,
                lo[i],
                hi[i]
            )));
        }
        let cap = 20 * n + 50;
        // Block changes while they make progress; a single change otherwise (module docs).
        let (mut best, mut grace) = (usize::MAX, BLOCK_GRACE);
        for k in 1..=cap {
            self.iterations = k;
            self.solve_mode(a, b, lo, hi)?;
            for i in 0..n {
                let (v, r) = (self.v[i], self.r[i]);
                self.next[i] = match self.modes[i] {
                    DiscMode::SlipPos if v < 0.0 => DiscMode::Stick,
                    DiscMode::SlipNeg if v > 0.0 => DiscMode::Stick,
                    DiscMode::Stick if r < lo[i] => DiscMode::SlipPos,
                    DiscMode::Stick if r > hi[i] => DiscMode::SlipNeg,
                    m => m,
                };
            }
            let wrong = (0..n).filter(|&i| self.next[i] != self.modes[i]).count();
            if wrong == 0 {
                return Ok(());
            }
            if wrong < best {
                (best, grace) = (wrong, BLOCK_GRACE);
                self.modes.copy_from_slice(&self.next);
            } else if grace > 0 {
                grace -= 1;
                self.modes.copy_from_slice(&self.next);
            } else if let Some(i) = (0..n).find(|&i| self.next[i] != self.modes[i]) {
                self.modes[i] = self.next[i];
            }
        }
        Err(ContactError::NotConverged { iterations: cap })
    }

    /// The linear system of the held modes: slipping discs' impulses at their bound, stuck
    /// discs' velocities 0; a Thomas solve in which a stuck disc's row is `v_i = 0`, then the
    /// stuck discs' impulses from `A v − b`.
    fn solve_mode(
        &mut self,
        a: &Tridiagonal,
        b: &[f64],
        lo: &[f64],
        hi: &[f64],
    ) -> Result<(), ContactError> {
        let n = self.modes.len();
        for i in 0..n {
            self.r[i] = match self.modes[i] {
                DiscMode::SlipPos => lo[i],
                DiscMode::SlipNeg => hi[i],
                DiscMode::Stick => 0.0,
            };
        }
        // Row i: sub_i v_{i−1} + d_i v_i + sup_i v_{i+1} = rhs_i; a stuck row is v_i = 0
        // (and its column drops out of the other rows because its v is 0).
        let row = |i: usize, modes: &[DiscMode], r: &[f64]| -> (f64, f64, f64, f64) {
            if modes[i] == DiscMode::Stick {
                return (0.0, 1.0, 0.0, 0.0);
            }
            let sub = if i > 0 { a.off[i - 1] } else { 0.0 };
            let sup = if i + 1 < n { a.off[i] } else { 0.0 };
            (sub, a.diag[i], sup, b[i] + r[i])
        };
        for i in 0..n {
            let (sub, d, sup, rhs) = row(i, &self.modes, &self.r);
            let (cp, dp) = if i == 0 {
                (0.0, 0.0)
            } else {
                (self.c_prime[i - 1], self.d_prime[i - 1])
            };
            let piv = d - sub * cp;
            if piv == 0.0 || !piv.is_finite() {
                return Err(ContactError::Singular);
            }
            self.c_prime[i] = sup / piv;
            self.d_prime[i] = (rhs - sub * dp) / piv;
        }
        for i in (0..n).rev() {
            let next = if i + 1 < n { self.v[i + 1] } else { 0.0 };
            self.v[i] = self.d_prime[i] - self.c_prime[i] * next;
        }
        a.mul_into(&self.v, &mut self.av);
        let stuck = self.modes.iter().map(|&m| m == DiscMode::Stick);
        for (i, _) in stuck.enumerate().filter(|&(_, s)| s) {
            self.v[i] = 0.0;
            self.r[i] = self.av[i] - b[i];
        }
        if self.v.iter().chain(&self.r).all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(ContactError::Singular)
        }
    }
}

/// How far `(v, r)` is from solving the problem, relative to its size: the larger of the
/// equation's residual `|A v − b − r|` and the complementarity residual
/// `|r_i − clamp(r_i − A_ii v_i, lo_i, hi_i)|`, over `1 + max(|b|, |r|, |A_ii v_i|)`.
/// Computed from the problem alone, so it checks any solver's answer.
pub fn residual(a: &Tridiagonal, b: &[f64], lo: &[f64], hi: &[f64], v: &[f64], r: &[f64]) -> f64 {
    let n = b.len();
    let mut av = vec![0.0; n];
    a.mul_into(v, &mut av);
    let mut worst = 0.0f64;
    let mut scale = 1.0f64;
    for i in 0..n {
        let c = a.diag[i];
        scale = scale.max(b[i].abs()).max(r[i].abs()).max((c * v[i]).abs());
        let eq = (av[i] - b[i] - r[i]).abs();
        let comp = (r[i] - (r[i] - c * v[i]).clamp(lo[i], hi[i])).abs();
        worst = worst.max(eq).max(comp);
    }
    worst / scale
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The iteration matrix of a chain: `M + θ²h²K` (+ θhC), with `K` the springs' and `C`
    /// the couplings' Laplacian; an SPD M-matrix.
    fn chain_matrix(j: &[f64], k: &[f64], c: &[f64], h: f64) -> Tridiagonal {
        let n = j.len();
        let (th, th2) = (0.5 * h, 0.25 * h * h);
        let mut diag: Vec<f64> = j.to_vec();
        let mut off = vec![0.0; n - 1];
        for i in 0..n - 1 {
            let s = th2 * k[i] + th * c[i];
            diag[i] += s;
            diag[i + 1] += s;
            off[i] = -s;
        }
        Tridiagonal { diag, off }
    }

    /// Every one of the 3^N modes solved densely (Gaussian elimination on the full system,
    /// nothing shared with the solver's Thomas sweep), kept if its signs and bounds hold.
    fn enumerate(a: &Tridiagonal, b: &[f64], lo: &[f64], hi: &[f64]) -> Vec<(Vec<f64>, Vec<f64>)> {
        let n = b.len();
        let dense = |i: usize, j: usize| -> f64 {
            if i == j {
                a.diag[i]
            } else if i + 1 == j {
                a.off[i]
            } else if j + 1 == i {
                a.off[j]
            } else {
                0.0
            }
        };
        let mut found = Vec::new();
        for code in 0..3usize.pow(n as u32) {
            let mode: Vec<usize> = (0..n).map(|i| code / 3usize.pow(i as u32) % 3).collect();
            // Unknowns: v_i for slipping discs, r_i for stuck ones; A v − r = b.
            let mut m = vec![vec![0.0; n + 1]; n];
            for i in 0..n {
                let mut rhs = b[i];
                for j in 0..n {
                    match mode[j] {
                        2 => {}
                        _ => m[i][j] = dense(i, j),
                    }
                }
                match mode[i] {
                    0 => rhs += lo[i],
                    1 => rhs += hi[i],
                    _ => m[i][i] = -1.0,
                }
                m[i][n] = rhs;
            }
            // Column j of a stuck disc holds its r (coefficient −1 on its own row).
            for col in 0..n {
                let p = (col..n).max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs()));
                let p = p.unwrap();
                m.swap(col, p);
                let piv = m[col][col];
                assert!(piv != 0.0);
                let pivot_row = m[col].clone();
                for (row, line) in m.iter_mut().enumerate() {
                    if row != col {
                        let f = line[col] / piv;
                        for (x, p) in line[col..].iter_mut().zip(&pivot_row[col..]) {
                            *x -= f * p;
                        }
                    }
                }
            }
            let x: Vec<f64> = (0..n).map(|i| m[i][n] / m[i][i]).collect();
            let mut v = vec![0.0; n];
            let mut r = vec![0.0; n];
            let mut ok = true;
            for i in 0..n {
                match mode[i] {
                    0 => (v[i], r[i], ok) = (x[i], lo[i], ok && x[i] > 0.0),
                    1 => (v[i], r[i], ok) = (x[i], hi[i], ok && x[i] < 0.0),
                    _ => (r[i], ok) = (x[i], ok && lo[i] <= x[i] && x[i] <= hi[i]),
                }
            }
            if ok {
                found.push((v, r));
            }
        }
        found
    }

    fn problem(n: usize, seed: &[f64]) -> (Tridiagonal, Vec<f64>, Vec<f64>, Vec<f64>) {
        let at = |i: usize| seed[i % seed.len()];
        let j: Vec<f64> = (0..n).map(|i| 0.02 + 0.5 * at(i)).collect();
        let k: Vec<f64> = (0..n).map(|i| 0.05 + 2.0 * at(i + 1)).collect();
        let c: Vec<f64> = (0..n)
            .map(|i| {
                if at(i + 2) > 0.5 {
                    0.1 * at(i + 3)
                } else {
                    0.0
                }
            })
            .collect();
        let a = chain_matrix(&j, &k, &c, 0.2 + at(4));
        let b: Vec<f64> = (0..n).map(|i| 0.4 * (at(i + 5) - 0.5)).collect();
        let lo: Vec<f64> = (0..n).map(|i| -0.05 * at(i + 6)).collect();
        let hi: Vec<f64> = (0..n).map(|i| 0.05 * at(i + 7)).collect();
        (a, b, lo, hi)
    }

    /// A warm start drawn as indices: 0 forward, 1 backward, 2 stuck.
    fn modes_of(drawn: &[usize]) -> Vec<DiscMode> {
        let modes = [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick];
        drawn.iter().map(|&k| modes[k]).collect()
    }

    proptest! {
        /// Against the enumeration of all 3^N modes (N ≤ 5): exactly one mode is admissible
        /// (the problem is strictly convex), and the pivoting finds that one, cold and
        /// warm-started from any mode.
        #[test]
        fn the_pivoting_finds_the_unique_admissible_mode(
            n in 1usize..=5,
            seed in prop::collection::vec(0.0f64..1.0, 12),
            warm in prop::collection::vec(0usize..3, 5),
        ) {
            let (a, b, lo, hi) = problem(n, &seed);
            prop_assert!(a.is_z_matrix());
            let all = enumerate(&a, &b, &lo, &hi);
            prop_assert_eq!(all.len(), 1, "admissible modes: {:?}", all);
            let (v, r) = &all[0];
            for start in [None, Some(&warm)] {
                let mut s = ContactSolver::new(n);
                if let Some(w) = start {
                    s.warm_start(&modes_of(&w[..n]));
                }
                s.solve(&a, &b, &lo, &hi).unwrap();
                // Two eliminations of the same small system (pivoted dense, Thomas): their
                // results differ by rounding, ~1e-16 of the values (≤ 1); 1e-13 is ~500×.
                for i in 0..n {
                    prop_assert!((s.v()[i] - v[i]).abs() <= 1e-13, "v[{}]: {} vs {}", i, s.v()[i], v[i]);
                    prop_assert!((s.r()[i] - r[i]).abs() <= 1e-13, "r[{}]: {} vs {}", i, s.r()[i], r[i]);
                }
                // Exact: the residual of the conditions is rounding (ε ≈ 2.2e-16 times a few
                // terms per row); 1e-14 is ~50×.
                prop_assert!(residual(&a, &b, &lo, &hi, s.v(), s.r()) <= 1e-14);
            }
        }

        /// On the rig's two contacts with frozen bounds, the pivoting solver and the
        /// stepper's enumeration of the nine modes (`onestep`, written separately) solve
        /// the same problem: the same velocities and impulses.
        #[test]
        fn on_two_contacts_it_agrees_with_the_enumeration_of_the_stepper(
            seed in prop::collection::vec(0.0f64..1.0, 12),
            e in prop::collection::vec(-0.02f64..0.02, 2),
        ) {
            use crate::onestep::{Branch, OneStepProblem, StickData};
            let (a, b, _, _) = problem(2, &seed);
            let p = [0.05 * seed[8], 0.05 * seed[9]];
            // A branch's constant is the whole friction impulse on it, smooth plus contact:
            // e_i − s·P_i on branch s.
            let branch = |i: usize, s: f64| Branch { c: e[i] - s * p[i], d: 0.0, pc: p[i], pd: 0.0 };
            let step = OneStepProblem {
                a: nalgebra::Matrix2::new(a.diag[0], a.off[0], a.off[0], a.diag[1]),
                b: nalgebra::Vector2::new(b[0], b[1]),
                slip: [[branch(0, 1.0), branch(0, -1.0)], [branch(1, 1.0), branch(1, -1.0)]],
                stick: [StickData { e: e[0], p: p[0] }, StickData { e: e[1], p: p[1] }],
            };
            let want = step.solve().unwrap();
            // The smooth impulse e moves into the right-hand side; the bounds are ±P.
            let b2 = [b[0] + e[0], b[1] + e[1]];
            let mut s = ContactSolver::new(2);
            s.solve(&a, &b2, &[-p[0], -p[1]], &p).unwrap();
            // Two eliminations of a 2 × 2 system: rounding ~1e-16 of values ≤ 1; 1e-14 is
            // ~50×.
            for i in 0..2 {
                prop_assert!((s.v()[i] - want.v[i]).abs() <= 1e-14, "v: {:?} vs {:?}", s.v(), want.v);
                prop_assert!((s.r()[i] - want.r[i]).abs() <= 1e-14, "r: {:?} vs {:?}", s.r(), want.r);
            }
        }

        /// Long chains, strongly coupled at long steps, from any warm start: the solver
        /// ends (within its cap) at a residual of rounding.
        #[test]
        fn long_chains_end_exactly_from_any_start(
            n in 6usize..=64,
            seed in prop::collection::vec(0.0f64..1.0, 23),
            warm in prop::collection::vec(0usize..3, 64),
        ) {
            let (a, b, lo, hi) = problem(n, &seed);
            let mut s = ContactSolver::new(n);
            s.warm_start(&modes_of(&warm[..n]));
            s.solve(&a, &b, &lo, &hi).unwrap();
            // Rounding of a tridiagonal solve: 1e-14 relative is ~50 ε.
            prop_assert!(residual(&a, &b, &lo, &hi, s.v(), s.r()) <= 1e-14);
        }
    }

    /// A chain of 64 discs (the scaling benchmark's largest): cold-started, the residual is
    /// rounding and the iteration count stays far below the cap; warm-started from its own
    /// answer, one linear solve confirms it.
    #[test]
    fn a_chain_of_64_is_solved_exactly_and_a_warm_start_confirms_in_one_solve() {
        let seed: Vec<f64> = (0..97)
            .map(|i| ((i * 37 + 11) % 97) as f64 / 97.0)
            .collect();
        let (a, b, lo, hi) = problem(64, &seed);
        let mut s = ContactSolver::new(64);
        s.solve(&a, &b, &lo, &hi).unwrap();
        let cold = s.iterations();
        // Rounding of a tridiagonal solve of 64 rows: 1e-14 relative is ~50 ε.
        assert!(residual(&a, &b, &lo, &hi, s.v(), s.r()) <= 1e-14);
        assert!(cold <= 65, "{cold} iterations");
        let stuck = s.modes().iter().filter(|&&m| m == DiscMode::Stick).count();
        assert!(
            stuck > 0 && stuck < 64,
            "a test of both kinds of contact: {stuck} stuck"
        );
        let (v, r) = (s.v().to_vec(), s.r().to_vec());
        s.solve(&a, &b, &lo, &hi).unwrap();
        assert_eq!(s.iterations(), 1);
        assert_eq!((s.v(), s.r()), (&v[..], &r[..]));
    }

    /// The residual is a check, not a formality: each condition broken alone is reported.
    #[test]
    fn the_residual_sees_each_broken_condition() {
        let (a, b, lo, hi) = problem(4, &[0.3, 0.7, 0.1, 0.9, 0.5, 0.2, 0.8, 0.6]);
        let mut s = ContactSolver::new(4);
        s.solve(&a, &b, &lo, &hi).unwrap();
        let (v, r) = (s.v().to_vec(), s.r().to_vec());
        assert!(residual(&a, &b, &lo, &hi, &v, &r) <= 1e-14);
        for i in 0..4 {
            let mut bad_v = v.clone();
            bad_v[i] += 1e-6;
            assert!(residual(&a, &b, &lo, &hi, &bad_v, &r) > 1e-9, "v[{i}]");
            let mut bad_r = r.clone();
            bad_r[i] += 1e-6;
            assert!(residual(&a, &b, &lo, &hi, &v, &bad_r) > 1e-9, "r[{i}]");
        }
    }

    #[test]
    fn bad_shapes_and_empty_intervals_are_refused() {
        let (a, b, lo, hi) = problem(3, &[0.3, 0.7, 0.1, 0.9]);
        let mut s = ContactSolver::new(3);
        assert!(matches!(
            s.solve(&a, &b[..2], &lo, &hi),
            Err(ContactError::Shape(_))
        ));
        let err = s.solve(&a, &b, &hi, &lo).unwrap_err().to_string();
        assert!(err.contains("is empty"), "{err}");
    }
}
