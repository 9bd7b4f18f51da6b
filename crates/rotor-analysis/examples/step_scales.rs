//! How the adaptive solvers' step bound `min(h_max, k·τ)` (τ: the model's shortest time
//! scale, `Model::time_scales`) trades cost for trust, measured on random parameter sets: the
//! metrics-only stress scene (Table 1 with every parameter scaled by a factor in [0.5, 2],
//! u = 1.5·[0.5, 2] V from rest, 100 s, metrics over [50, 100] s, tol 1e-10), for several k.
//!
//! Per solver and k: the largest error of the steady metrics (relative to max(|m|, 1))
//! against the event solver at tol 1e-13 with k = 2 and no lift (the bound everywhere), the
//! event solver's lift ε from `STEP_SCALES_LIFT` (default `EventOptions::default().lift`, off; the
//! measured candidate is `rotor_event::LIFT_FRACTION` = 1e-5), the largest difference between the
//! metrics-only and the full run (the stress test's gate is 1e-7), the number of draws over
//! that gate, the draws whose error exceeds 100 tolerances (cycles of amplitude ≥ 1e-3 rad/s)
//! and 100 tolerances times the conditioning of a period read from extrema, and the field
//! evaluations of the full runs summed, relative to k = ∞. `STEP_SCALES_STEEP=1` turns on the
//! lift away from the steep region (`EventOptions::steep_lift`), `STEP_SCALES_LIST=1` lists
//! the draws over either count.
//!
//! `cargo run --release -p rotor-analysis --example step_scales -- [DRAWS] [SEED] [TOL]`

use rotor_event::{EventOptions, EventSolver};
use rotor_model::seam::{Accuracy, Output, RigSteady, Scene, Solver};
use rotor_model::{LowerFriction, Model, Params, UpperFriction};
use rotor_switch::{SwitchOptions, SwitchSolver};

/// xorshift64*: a reproducible draw without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn factor(&mut self) -> f64 {
        0.5 + 1.5 * self.next()
    }
}

/// The stress test's generator: Table 1, each parameter scaled in [0.5, 2], admissible sets.
fn draw(rng: &mut Rng) -> (Params, f64) {
    loop {
        let t = Params::table1();
        let LowerFriction::Exponential {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            b,
        } = t.lower
        else {
            unreachable!()
        };
        let f: Vec<f64> = (0..12).map(|_| rng.factor()).collect();
        let p = Params {
            j_u: t.j_u * f[0],
            k_m: t.k_m * f[1],
            k_theta: t.k_theta * f[2],
            j_l: t.j_l * f[3],
            upper: UpperFriction {
                b: t.upper.b * f[4],
                ..t.upper
            },
            lower: LowerFriction::Exponential {
                t_s: t_s * f[5],
                t_1: t_1 * f[6],
                t_2: t_2 * f[7],
                w_1: w_1 * f[8],
                w_2: w_2 * f[9],
                b: b * f[10],
            },
        };
        if p.validate().is_ok() {
            return (p, 1.5 * f[11]);
        }
    }
}

/// The seed the stress test found (stress.proptest-regressions).
fn seed_set() -> (Params, f64) {
    let p = Params {
        j_u: 0.4069321222438779,
        k_m: 6.720280179348315,
        k_theta: 0.10457460398155585,
        j_l: 0.04485767839799535,
        upper: UpperFriction {
            t_s: 0.0,
            dt_s: 0.0,
            b: 3.2346445022822654,
            db: 0.0,
        },
        lower: LowerFriction::Exponential {
            t_s: 0.28080097270964993,
            t_1: 0.07545812043190267,
            t_2: -0.4237052317061559,
            w_1: 9.46871759777213,
            w_2: 0.18736328593501694,
            b: 0.019697737664125654,
        },
    };
    (p, 1.5 * 1.91649573917313)
}

fn values(m: &Option<RigSteady>) -> Vec<f64> {
    m.as_ref()
        .map(|s| s.values().into_iter().map(|(_, v)| v).collect())
        .unwrap_or_default()
}

fn diff(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1.0))
        .fold(0.0, f64::max)
}

fn event(k: f64) -> Box<dyn Solver> {
    // STEP_SCALES_LIFT=0 keeps the bound everywhere (ε of EventOptions::lift).
    let lift = std::env::var("STEP_SCALES_LIFT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(EventOptions::default().lift);
    // STEP_SCALES_LIFT_RES=M lifts it at M·tol·(1 + |ω|) too (EventOptions::lift_resolution).
    let resolution = std::env::var("STEP_SCALES_LIFT_RES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(EventOptions::default().lift_resolution);
    // STEP_SCALES_STEEP=1 lifts it where the steep region is out of reach
    // (EventOptions::steep_lift); 0 keeps it there.
    let steep =
        std::env::var("STEP_SCALES_STEEP").map_or(EventOptions::default().steep_lift, |v| v != "0");
    event_with(k, lift, resolution, steep)
}

/// The event solver with the bound's multiple k, its lift's ε and M and the lift away from
/// the steep region (0, 0, false: the bound everywhere).
fn event_with(k: f64, lift: f64, lift_resolution: f64, steep_lift: bool) -> Box<dyn Solver> {
    Box::new(EventSolver {
        options: EventOptions {
            h_scale: k,
            lift,
            lift_resolution,
            steep_lift,
            // STEP_SCALES_DEFECT=inf turns the defect check at events off.
            defect_limit: std::env::var("STEP_SCALES_DEFECT")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(rotor_event::DEFECT_LIMIT),
            ..EventOptions::default()
        },
    })
}

fn switch(k: f64) -> Box<dyn Solver> {
    Box::new(SwitchSolver {
        options: SwitchOptions {
            h_scale: k,
            ..SwitchOptions::default()
        },
    })
}

/// A solver with the step bound's multiple k.
type MakeSolver = fn(f64) -> Box<dyn Solver>;

#[derive(Default, Clone, Copy)]
struct Tally {
    err: f64,
    split: f64,
    over: u32,
    /// Draws whose error exceeds 100 tolerances, among the cycles of amplitude ≥ 1e-3 rad/s
    /// (a smaller one, onto an equilibrium, has a period conditioned as tol/amplitude).
    wrong: u32,
    /// Draws whose error exceeds 100 tolerances times the condition of a cycle's period
    /// read from extrema, `max(1, (1 + |ω̄|)·T/(2π²A))` (ω̄ the mean of ω_l's extremes, A
    /// half their distance, T the period): an extremum's time moves by δω/(AΩ²) for an error
    /// δω ≈ tol·(1 + |ω̄|) in ω.
    beyond: u32,
    evals: u64,
    defects: u64,
    worst: usize,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let draws: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let tol: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1e-10);
    // The multiples k tried (∞ first: the costs are relative to it); STEP_SCALES_K="16,8,4".
    let ks: Vec<f64> = std::iter::once(f64::INFINITY)
        .chain(
            std::env::var("STEP_SCALES_K")
                .unwrap_or_else(|_| "32,16,8,4".into())
                .split(',')
                .filter_map(|k| k.trim().parse().ok()),
        )
        .collect();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ seed);
    let sets: Vec<(Params, f64)> = std::iter::once(seed_set())
        .chain((0..draws).map(|_| draw(&mut rng)))
        .collect();
    let kinds: [(&str, MakeSolver); 2] = [("event", event), ("switch", switch)];
    let mut tally = [
        vec![Tally::default(); ks.len()],
        vec![Tally::default(); ks.len()],
    ];
    let mut taus = Vec::new();
    // Sets on which a friction scale τ_fric is the shortest of the model's time scales.
    let mut friction_shortest = 0;
    for (n, (p, u)) in sets.iter().enumerate() {
        let m = Model::new(*p);
        let ts = m.time_scales();
        taus.push(ts.shortest());
        friction_shortest += usize::from(ts.shortest() == ts.friction[0].min(ts.friction[1]));
        let scene = Scene {
            u: *u,
            input: None,
            x0: vec![0.0; 3],
            t_end: 100.0,
            accuracy: Accuracy::Tol(tol),
            output: Output::Final,
            metrics_from: Some(50.0),
        };
        // The reference keeps the bound everywhere, whatever the variant measured.
        let reference = event_with(2.0, 0.0, 0.0, false)
            .simulate(
                &m,
                &Scene {
                    accuracy: Accuracy::Tol(1e-13),
                    ..scene.clone()
                },
            )
            .map(|r| values(&r.rig_metrics()));
        let Ok(reference) = reference else {
            eprintln!("draw {n}: reference failed");
            continue;
        };
        for (s, (name, make)) in kinds.iter().enumerate() {
            for (i, &k) in ks.iter().enumerate() {
                let solver = make(k);
                let (Ok(full), Ok(fast)) = (
                    solver.simulate(&m, &scene),
                    solver.simulate(
                        &m,
                        &Scene {
                            output: Output::Metrics,
                            ..scene.clone()
                        },
                    ),
                ) else {
                    eprintln!("draw {n}: {name} k = {k} failed");
                    continue;
                };
                let (a, b) = (values(&full.rig_metrics()), values(&fast.rig_metrics()));
                let t = &mut tally[s][i];
                let e = diff(&a, &reference);
                let split = diff(&a, &b);
                let show = std::env::var("STEP_SCALES_SHOW")
                    .ok()
                    .and_then(|v| v.parse::<usize>().ok());
                if show == Some(n) {
                    println!("set {n}: {name} k = {k}: {a:?} ({e:.1e}); ref {reference:?}");
                }
                if n == 0 {
                    println!(
                        "seed set: {name} k = {k}: error {e:.1e}, metrics-only vs full {split:.1e}, {} evals",
                        full.stats.rhs_evals
                    );
                }
                if e > t.err {
                    t.worst = n;
                }
                t.err = t.err.max(e);
                let amplitude = if reference.len() == 6 {
                    reference[1] - reference[2]
                } else {
                    1.0
                };
                t.wrong += u32::from(amplitude >= 1e-3 && e > 100.0 * tol);
                let condition = if reference.len() == 6 && amplitude > 0.0 {
                    let mean = 0.5 * (reference[1] + reference[2]);
                    let pi2 = 2.0 * std::f64::consts::PI.powi(2);
                    ((1.0 + mean.abs()) * reference[0] / (pi2 * 0.5 * amplitude)).max(1.0)
                } else {
                    1.0
                };
                t.beyond += u32::from(e > 100.0 * tol * condition);
                if std::env::var_os("STEP_SCALES_LIST").is_some() && e > 100.0 * tol * condition {
                    println!(
                        "beyond: {name} k = {k} set {n}: error {e:.1e}, condition {condition:.1e}"
                    );
                }
                if std::env::var_os("STEP_SCALES_LIST").is_some()
                    && amplitude >= 1e-3
                    && e > 100.0 * tol
                {
                    println!(
                        "wrong: {name} k = {k} set {n}: {} values, error {e:.1e}, amplitude {amplitude:.2e} rad/s, reference {reference:?}",
                        a.len()
                    );
                }
                t.split = t.split.max(split);
                t.over += u32::from(split > 1e-7);
                t.evals += full.stats.rhs_evals;
                t.defects += full.stats.defect_rejections + fast.stats.defect_rejections;
            }
        }
    }
    taus.sort_by(f64::total_cmp);
    println!(
        "{} sets (seed set + {draws} draws, seed {seed}), tol {tol:e}; shortest time scale τ from {:.4} to {:.4} s (median {:.4})",
        sets.len(),
        taus[0],
        taus[taus.len() - 1],
        taus[taus.len() / 2]
    );
    println!(
        "τ_fric is the shortest scale on {friction_shortest} of {} sets",
        sets.len()
    );
    println!(
        "solver      k   max error (set)  max split  over 1e-7  err>100tol  err>100tol·cond  evals/evals(k=∞)  defect rejections"
    );
    for (s, (name, _)) in kinds.iter().enumerate() {
        for (i, k) in ks.iter().enumerate() {
            let t = tally[s][i];
            println!(
                "{name:<7} {k:>5}   {:9.1e} ({:>4})  {:9.1e}  {:9}  {:9}  {:15}  {:.3}  {}",
                t.err,
                t.worst,
                t.split,
                t.over,
                t.wrong,
                t.beyond,
                t.evals as f64 / tally[s][0].evals as f64,
                t.defects
            );
        }
    }
}
