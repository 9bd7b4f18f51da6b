//! Cross-validation of a chain scene: the three solvers, which share nothing but the chain's
//! model, must agree on every sample of every α_i and ω_i over the whole run and on the time
//! of every stick onset, stick exit and reversal, within gates derived from each one's own
//! accuracy on the scene.
//!
//! Each solver runs at its comparison setting (the scene's `tol` or `h` where it states one)
//! and at its tighter settings (tolerance/100; step/2, step/4 and step/8, [`chain_tighter`]);
//! its own error in a quantity is [`rotor_analysis::solvers::self_error`] of that quantity
//! between its successive runs, for a step also `8·d₃` ([`chain_self_error`]). The
//! gate of a pair `(a, b)` in a quantity is the rule of the rig's derived gates
//! ([`crate::compare::gate::derived_tolerance`]):
//!
//! ```text
//! 2·(e_a + e_b) + 1e-12 + (η_a + η_b)·max(1, t_end)
//! ```
//!
//! twice the two own errors, the rounding floor, and what a stick band η moves (the switch
//! model holds a stuck disc within η, and the spring drifts by η per second of stick). Event
//! times are compared between runs whose event sequences agree (disc and kind, in order); runs
//! with different sequences cannot be compared there, which fails the pair and says so.
//!
//! On a chain the band's term alone does not bound what the band moves: on the chain of four
//! with a Stribeck disc in the middle the switch model (tol 1e-10, η = 1e-10) differed from
//! the event-driven solver by 1.0e-7 rad/s in ω_3, 2.2× the gate with that term, while its own
//! runs at tol 1e-10 and 1e-12 (the same η) agreed far closer: the band's error is first
//! order in η and a tighter tolerance does not see it. The switch model's own error here
//! therefore adds its band's, measured: its run at η/10 ([`SWITCH_ETA_STUDY`]), the
//! difference times 10/9 (an error `C·η` differs from `C·η/10` by 0.9 of itself).
//!
//! A chaotic scene (`[chaos]`) is compared as it is graded
//! ([`crate::grade::chain`]): the samples and events up to its predictability horizon H under
//! the gates above (each solver's own error from its runs cut at H), and beyond, each disc's
//! mean velocity and fraction of time stuck over `[statistics_from, t_end]` within
//! [`crate::grade::chain::STATISTICS_SIGMA`] standard errors of the difference.

use std::collections::BTreeMap;

use rotor_analysis::solvers::{SOLVERS, SolverKind, self_error, tighter_settings};

/// A time-stepper's tighter settings on a chain: the rig's two halvings and a third.
///
/// Three runs at h, h/2 and h/4 can make the same discrete choice at a near-grazing velocity
/// reversal and agree exactly there, so their differences see no error where there is one:
/// on a user's chain of three at 2.0 V (Table 1's discs), Moreau–Jean at h = 1e-3, 5e-4 and
/// 2.5e-4 all held disc 2 stuck at the sample 1.2 ms after its reversal, 2.02e-4 rad/s off
/// the event solver each time (measured), so `max(2·d₁, 4·d₂)` at that sample was 0 and the
/// pair failed its gate by 2 %. At h/8 the choice changes (9.0e-5 off), and the third
/// difference, weighted as first order (`8·d₃`, the error at h when each halving halves it),
/// sees it.
pub fn chain_tighter(kind: SolverKind, setting: f64) -> Vec<f64> {
    let mut v = tighter_settings(kind, setting);
    if kind.is_fixed_step() {
        v.push(setting / 8.0);
    }
    v
}

/// A solver's own error in a quantity from its differences between successive settings
/// ([`chain_tighter`]): [`self_error`], and for a time-stepper also `8·d₃`.
pub fn chain_self_error(kind: SolverKind, steps: &[f64]) -> f64 {
    let e = self_error(kind, steps);
    match steps.get(2) {
        Some(&d3) if kind.is_fixed_step() => e.max(8.0 * d3),
        _ => e,
    }
}
use rotor_model::scenario::ChainScenario;
use rotor_model::seam::{Output, Scene, SolveError, Trajectory};
use serde::Serialize;

use crate::grade::chain::{
    STATISTICS_SIGMA, differences as diff_map, statistics, stuck_thresholds, until,
};

/// The rounding floor of a gate: 1e-12 (s, rad, rad/s).
pub const FLOOR: f64 = 1e-12;

/// The switch model's band is measured by a run at η divided by this.
pub const SWITCH_ETA_STUDY: f64 = 10.0;

/// One solver's runs of a chain scene.
#[derive(Debug, Clone)]
pub struct ChainRun {
    /// The solver.
    pub kind: SolverKind,
    /// Its setting (tolerance, or step in s).
    pub setting: f64,
    /// The run at the setting.
    pub run: Trajectory,
    /// The run up to a chaotic scene's horizon (the whole run otherwise): what is compared
    /// sample by sample.
    pub cut: Trajectory,
    /// Its own error per quantity (each column's name, `event_time`): from its runs at the
    /// tighter settings.
    pub own: BTreeMap<String, f64>,
    /// Wall time of the run at the setting \[s\].
    pub seconds: f64,
}

/// One gated quantity of one pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainGate {
    /// `event-switch`, `event-moreau`, `switch-moreau`.
    pub pair: String,
    /// A column's name, or `event_time`.
    pub quantity: String,
    /// The largest difference of the pair's runs (∞ where they cannot be compared).
    pub difference: f64,
    /// The gate.
    pub gate: f64,
    /// `difference ≤ gate`.
    pub passed: bool,
}

impl ChainGate {
    /// difference/gate: 0 where the two agree exactly (also against a gate of 0, as two
    /// stick fractions of a disc that never sticks), ∞ where they cannot be compared.
    pub fn ratio(&self) -> f64 {
        if self.difference == 0.0 {
            0.0
        } else if !self.difference.is_finite() {
            f64::INFINITY
        } else {
            self.difference / self.gate
        }
    }
}

/// A chain scene through the three solvers.
#[derive(Debug, Clone)]
pub struct ChainComparison {
    /// The scene.
    pub scenario: ChainScenario,
    /// Each solver's runs.
    pub runs: Vec<ChainRun>,
    /// Every pair's gates, pair by pair, quantities in the state's order then `event_time`
    /// (then, on a chaotic scene, the statistics).
    pub gates: Vec<ChainGate>,
    /// A chaotic scene's predictability horizon \[s\].
    pub horizon: Option<f64>,
}

impl ChainComparison {
    /// Whether every gate passes.
    pub fn passed(&self) -> bool {
        self.gates.iter().all(|g| g.passed)
    }

    /// One line per failed gate.
    pub fn failures(&self) -> Vec<String> {
        self.gates
            .iter()
            .filter(|g| !g.passed)
            .map(|g| {
                if g.difference.is_finite() {
                    format!(
                        "{} {} {}: difference {:.3e} > gate {:.3e}",
                        self.scenario.name, g.pair, g.quantity, g.difference, g.gate
                    )
                } else {
                    format!(
                        "{} {} {}: the two runs cannot be compared (another sequence of \
                         events, or a run that failed)",
                        self.scenario.name, g.pair, g.quantity
                    )
                }
            })
            .collect()
    }

    /// The worst gate of a pair: (quantity, difference/gate).
    pub fn worst(&self, pair: &str) -> Option<(&str, f64)> {
        self.gates
            .iter()
            .filter(|g| g.pair == pair)
            .map(|g| (g.quantity.as_str(), g.ratio()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// A solver's setting on a chain scene: the event solver's comparison tolerance; the others'
/// from the scene (`tol`, `h`) or their comparison settings.
pub fn chain_setting(kind: SolverKind, sc: &ChainScenario) -> f64 {
    let info = kind.info();
    if kind == SOLVERS[0] {
        return info.comparison;
    }
    let stated = if kind.is_fixed_step() { sc.h } else { sc.tol };
    stated.unwrap_or(info.comparison)
}

/// Each quantity's difference of two runs: every column (largest over the samples) and
/// `event_time` (∞ where the event sequences differ), in the state's order.
fn differences(names: &[String], a: &Trajectory, b: &Trajectory) -> Vec<(String, f64)> {
    let mut m = diff_map(names, a, b);
    let mut out: Vec<(String, f64)> = names
        .iter()
        .map(|n| (n.clone(), m.remove(n).unwrap_or(f64::INFINITY)))
        .collect();
    out.extend(m);
    out
}

fn solve(
    kind: SolverKind,
    sc: &ChainScenario,
    setting: f64,
    t_end: f64,
) -> Result<Trajectory, SolveError> {
    let scene = Scene {
        accuracy: kind.accuracy(setting),
        t_end,
        ..sc.scene(Output::Grid { dt: sc.dt })
    };
    kind.simulate_chain(&sc.model(), &scene)
}

/// One solver's runs: at its setting and the tighter ones, and its own error from them; on a
/// chaotic scene (`horizon` given) the tighter runs end at the first grid time past it, and
/// every run is compared up to it.
pub fn chain_run(
    kind: SolverKind,
    sc: &ChainScenario,
    horizon: Option<f64>,
) -> Result<ChainRun, SolveError> {
    let names = sc.model().state_names();
    let setting = chain_setting(kind, sc);
    let cut = |tr: Trajectory| horizon.map_or(tr.clone(), |h| until(&tr, h));
    let short = horizon.map_or(sc.t_end, |h| ((h / sc.dt).ceil() * sc.dt).min(sc.t_end));
    let t0 = std::time::Instant::now();
    let run = solve(kind, sc, setting, sc.t_end)?;
    let seconds = t0.elapsed().as_secs_f64();
    let head = cut(run.clone());
    let mut steps: Vec<Vec<(String, f64)>> = Vec::new();
    let mut prev = head.clone();
    for s in chain_tighter(kind, setting) {
        let t = cut(solve(kind, sc, s, short)?);
        steps.push(differences(&names, &prev, &t));
        prev = t;
    }
    // The switch model's band error, first order in η: its run at η/10 differs from the run
    // at η by 0.9 of it.
    let band: Option<Vec<(String, f64)>> = if kind.info().stuck_band > 0.0 {
        let mut options = rotor_switch::SwitchOptions::default();
        options.eta /= SWITCH_ETA_STUDY;
        let scene = Scene {
            accuracy: kind.accuracy(setting),
            t_end: short,
            ..sc.scene(Output::Grid { dt: sc.dt })
        };
        let narrow = rotor_switch::SwitchSolver { options }.simulate_chain(&sc.model(), &scene)?;
        Some(differences(&names, &head, &cut(narrow)))
    } else {
        None
    };
    let own = (0..steps[0].len())
        .map(|i| {
            let diffs: Vec<f64> = steps.iter().map(|m| m[i].1).collect();
            let band = band.as_ref().map_or(0.0, |b| {
                b[i].1 * SWITCH_ETA_STUDY / (SWITCH_ETA_STUDY - 1.0)
            });
            (steps[0][i].0.clone(), chain_self_error(kind, &diffs) + band)
        })
        .collect();
    Ok(ChainRun {
        kind,
        setting,
        run,
        cut: head,
        own,
        seconds,
    })
}

/// The gates of two runs: every quantity up to the horizon (the whole run where there is
/// none), and a chaotic scene's statistics beyond.
pub fn gates_of(sc: &ChainScenario, a: &ChainRun, b: &ChainRun) -> Vec<ChainGate> {
    let model = sc.model();
    let names = model.state_names();
    let pair = rotor_analysis::solvers::pair_name(a.kind, b.kind);
    let span = a.cut.samples.iter().next_back().map_or(sc.t_end, |r| r.t);
    let band = (a.kind.info().stuck_band + b.kind.info().stuck_band) * span.max(1.0);
    let mut gates: Vec<ChainGate> = differences(&names, &a.cut, &b.cut)
        .into_iter()
        .map(|(quantity, difference)| {
            let gate = 2.0 * (a.own[&quantity] + b.own[&quantity]) + FLOOR + band;
            ChainGate {
                pair: pair.clone(),
                // A NaN difference fails (`!(d > g)` would pass it), and so does one that
                // cannot be measured (event sequences that differ), even against a gate that
                // cannot be derived either: ∞ ≤ ∞ is no agreement.
                passed: difference.is_finite() && difference <= gate,
                quantity,
                difference,
                gate,
            }
        })
        .collect();
    if let Some(c) = sc.chaos {
        let stuck = stuck_thresholds(&model, &a.cut.samples);
        let window = (c.statistics_from, sc.t_end, c.batches);
        let (sa, sb) = (
            statistics(&model, &a.run.samples, window, &stuck),
            statistics(&model, &b.run.samples, window, &stuck),
        );
        for (p, q) in sa.iter().zip(&sb) {
            let difference = (p.mean - q.mean).abs();
            let gate = STATISTICS_SIGMA * p.standard_error.hypot(q.standard_error);
            gates.push(ChainGate {
                pair: pair.clone(),
                quantity: p.name.clone(),
                difference,
                gate,
                passed: difference <= gate,
            });
        }
    }
    gates
}

/// A chain scene through the three solvers, gated pair by pair.
pub fn compare_chain(sc: &ChainScenario) -> Result<ChainComparison, SolveError> {
    use rayon::prelude::*;
    // A chaotic scene's horizon, from the event solver's run at its setting.
    let horizon = match sc.chaos {
        None => None,
        Some(_) => {
            let event = solve(SOLVERS[0], sc, chain_setting(SOLVERS[0], sc), sc.t_end)?;
            Some(
                crate::grade::chain::horizon(sc, &event).map_err(|e| match e {
                    crate::grade::reference::ReferenceError::Solve { source, .. } => source,
                    other => SolveError::NoConvergence {
                        detail: other.to_string(),
                    },
                })?,
            )
        }
    };
    let runs = SOLVERS
        .par_iter()
        .map(|&k| chain_run(k, sc, horizon))
        .collect::<Result<Vec<_>, _>>()?;
    let mut gates = Vec::new();
    for (i, a) in runs.iter().enumerate() {
        for b in &runs[i + 1..] {
            gates.extend(gates_of(sc, a, b));
        }
    }
    Ok(ChainComparison {
        scenario: sc.clone(),
        runs,
        gates,
        horizon,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str) -> ChainScenario {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("../../fixtures/chain/scenarios/{name}.toml"));
        ChainScenario::from_file(&p).unwrap()
    }

    /// The gate's pieces: a tolerance's own error is the difference to its tighter run, a
    /// step's the larger of 2·d₁ and 4·d₂; the band adds η·t_end for the switch model.
    #[test]
    fn a_gate_is_twice_the_own_errors_plus_floor_and_band() {
        let sc = scene("chain3-u1.5-rest");
        let tr = solve(SolverKind::EVENT, &sc, 1e-6, sc.t_end).unwrap();
        let run = |kind: SolverKind, own: f64| ChainRun {
            kind,
            setting: 1.0,
            run: tr.clone(),
            cut: tr.clone(),
            own: sc
                .model()
                .state_names()
                .into_iter()
                .chain(["event_time".to_owned()])
                .map(|n| (n, own))
                .collect(),
            seconds: 0.0,
        };
        let g = gates_of(
            &sc,
            &run(SolverKind::EVENT, 1e-9),
            &run(SolverKind::MOREAU, 1e-6),
        );
        assert!(g.iter().all(|g| g.difference == 0.0 && g.passed));
        assert!(
            g.iter()
                .all(|g| (g.gate - (2.0 * (1e-9 + 1e-6) + FLOOR)).abs() < 1e-20)
        );
        let eta = SolverKind::SWITCH.info().stuck_band;
        let g = gates_of(
            &sc,
            &run(SolverKind::EVENT, 0.0),
            &run(SolverKind::SWITCH, 0.0),
        );
        assert!(g.iter().all(|g| g.gate == FLOOR + eta * sc.t_end));
    }
}
