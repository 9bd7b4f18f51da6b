//! What a solver is, in one place.
//!
//! Each entry of [`SOLVERS`] says a solver's name, label, accuracy knob (a tolerance or a step
//! size) with its settings and benchmark ladder, plot style, and how to make one. Everything
//! that lists solvers derives from it: the comparison's pairs (the first solver, the accuracy
//! reference, against each other one), the `[tolerance.<pair>]` tables a scenario may state,
//! plot styles, ladders, the CLI's `--solver` names. Adding a solver is one crate, one entry
//! here, and its tolerances in the fixtures (`CONTRIBUTING.md`; a test adds a fourth one).

use rotor_model::scenario::{Scenario, ScenarioError};
use rotor_model::seam::scene::{DEFAULT_STEP, DEFAULT_TOL};
use rotor_model::seam::{Accuracy, Solver};
use serde::{Serialize, Serializer};

/// What a solver's accuracy setting is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Knob {
    /// An error tolerance (relative = absolute): [`Accuracy::Tol`], the CLI's `--tol`.
    Tolerance,
    /// A fixed step size \[s\]: [`Accuracy::Step`], the CLI's `--h`.
    Step,
}

impl Knob {
    /// `"tol"` or `"h"`: the setting's name and CLI flag.
    pub fn name(self) -> &'static str {
        match self {
            Knob::Tolerance => "tol",
            Knob::Step => "h",
        }
    }

    /// A scene's accuracy with this knob at `setting`.
    pub fn accuracy(self, setting: f64) -> Accuracy {
        match self {
            Knob::Tolerance => Accuracy::Tol(setting),
            Knob::Step => Accuracy::Step(setting),
        }
    }
}

/// How a solver's curves are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// SVG colour, e.g. `"#e66101"`.
    pub color: &'static str,
    /// SVG dash pattern; `None` for a solid line.
    pub dash: Option<&'static str>,
    /// Stroke width (SVG user units, pixels at the reports' scale).
    pub width: f64,
}

/// One solver's capabilities.
#[derive(Debug, Clone, Copy)]
pub struct SolverInfo {
    /// Short name: the CLI's `--solver`, report columns, tolerance pair names.
    pub name: &'static str,
    /// For plots and tables (`"event-driven"`).
    pub label: &'static str,
    /// What its accuracy setting is: a tolerance (`tol`) or a step size (`h`).
    pub knob: Knob,
    /// The setting the comparison runs it at (the reference's is tighter than what a user
    /// asks by default; a scenario file may override a non-reference solver's `tol` or `h`).
    pub comparison: f64,
    /// The setting a scene gets when nobody asks (the CLI's default).
    pub default: f64,
    /// The benchmark's ladder of settings, loosest first.
    pub ladder: &'static [f64],
    /// How its curves are drawn in the reports.
    pub style: Style,
    /// The largest |ω| at which it holds a stuck disc, by construction \[rad/s\]: 0 for a
    /// method that puts a stuck disc at rest exactly, the band half-width η for the switch
    /// model (a stuck disc keeps the velocity it entered the band with). Two solvers' stuck
    /// velocities are no difference within the sum of their bands
    /// (`rotor_harness::compare::gate::steady_differences`).
    pub stuck_band: f64,
    /// The relative agreement asked of its steady answers (`rotor steady` at its comparison
    /// setting) with the attractors of the continuation, away from special points: its
    /// accuracy on steady metrics with a margin, well below the distance to the nearest other
    /// cycle (`rotor_analysis::steady::probes`, where each value's origin is given).
    pub steady_agreement: f64,
    /// A solver with its default options.
    pub make: fn() -> Box<dyn Solver>,
    /// Its run of a chain of N discs, with its default options; `None` for a solver that
    /// runs the rig's two discs only.
    pub chain: Option<ChainRun>,
}

/// A solver's run of a scene on a chain of N discs.
pub type ChainRun = fn(
    &rotor_model::ChainModel,
    &rotor_model::seam::Scene,
) -> Result<rotor_model::seam::Trajectory, rotor_model::seam::SolveError>;

const DECADES_3_12: [f64; 10] = [
    1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12,
];

/// The event-driven Filippov solver (DOP853): the accuracy reference.
pub static EVENT: SolverInfo = SolverInfo {
    name: "event",
    label: "event-driven",
    knob: Knob::Tolerance,
    comparison: 1e-12,
    default: DEFAULT_TOL,
    ladder: &DECADES_3_12,
    style: Style {
        color: "#000000",
        dash: None,
        width: 2.5,
    },
    stuck_band: 0.0,
    steady_agreement: 1e-6,
    make: || Box::new(rotor_event::EventSolver::default()),
    chain: Some(|model, scene| rotor_event::EventSolver::default().simulate_chain(model, scene)),
};

/// Leine's switch model as published (DOPRI5, band η = 1e-10).
pub static SWITCH: SolverInfo = SolverInfo {
    name: "switch",
    label: "switch model",
    knob: Knob::Tolerance,
    comparison: 1e-10,
    default: DEFAULT_TOL,
    ladder: &DECADES_3_12,
    style: Style {
        color: "#D55E00",
        dash: Some("6 3"),
        width: 1.5,
    },
    // SwitchOptions::default().eta (a unit test holds them equal).
    stuck_band: 1e-10,
    steady_agreement: 1e-5,
    make: || Box::new(rotor_switch::SwitchSolver::default()),
    chain: Some(|model, scene| rotor_switch::SwitchSolver::default().simulate_chain(model, scene)),
};

/// Moreau–Jean time-stepping on the Lagrangian form. Every step of its ladder divides the
/// 0.01 s grid, so its trace samples are step values; the smallest, 1e-5 (10⁷ steps over
/// 100 s), is timed once within the benchmark's budget.
pub static MOREAU: SolverInfo = SolverInfo {
    name: "moreau",
    label: "Moreau-Jean",
    knob: Knob::Step,
    comparison: 1e-3,
    default: DEFAULT_STEP,
    ladder: &[1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 1e-5],
    style: Style {
        color: "#0072B2",
        dash: Some("2 2"),
        width: 1.5,
    },
    stuck_band: 0.0,
    steady_agreement: 1e-4,
    make: || Box::new(rotor_moreau::MoreauSolver::default()),
    chain: Some(rotor_moreau::simulate_chain),
};

/// A solver, by its entry.
#[derive(Clone, Copy)]
pub struct SolverKind(pub &'static SolverInfo);

/// The solvers, the accuracy reference first.
pub static SOLVERS: [SolverKind; 3] = [SolverKind::EVENT, SolverKind::SWITCH, SolverKind::MOREAU];

impl SolverKind {
    /// The event-driven solver, [`EVENT`]: the accuracy reference.
    pub const EVENT: SolverKind = SolverKind(&EVENT);
    /// The switch model, [`SWITCH`].
    pub const SWITCH: SolverKind = SolverKind(&SWITCH);
    /// Moreau–Jean time-stepping, [`MOREAU`].
    pub const MOREAU: SolverKind = SolverKind(&MOREAU);

    /// Its entry.
    pub fn info(self) -> &'static SolverInfo {
        self.0
    }

    /// Short name (as the CLI's `--solver`).
    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// The solver with this name.
    pub fn by_name(name: &str) -> Option<SolverKind> {
        SOLVERS.iter().copied().find(|k| k.name() == name)
    }

    /// `scene` on a chain of N discs, by this solver's [`SolverInfo::chain`] (the event-driven
    /// solver's [`rotor_event::EventSolver::simulate_chain`], the switch model's
    /// [`rotor_switch::SwitchSolver::simulate_chain`], Moreau–Jean's
    /// [`rotor_moreau::simulate_chain`]); a solver without one says so. Steady-state metrics are
    /// every disc's, the cycle read off the bottom disc ([`rotor_model::seam::MetricsAccumulator`]).
    pub fn simulate_chain(
        self,
        model: &rotor_model::ChainModel,
        scene: &rotor_model::seam::Scene,
    ) -> Result<rotor_model::seam::Trajectory, rotor_model::seam::SolveError> {
        use rotor_model::seam::SolveError;
        let Some(chain) = self.0.chain else {
            return Err(SolveError::Unsupported {
                detail: format!(
                    "a run on a chain with {} discs by {} (not yet: the rig only)",
                    model.discs(),
                    self.name()
                ),
            });
        };
        let tr = chain(model, scene)?;
        tr.check_finite()?;
        Ok(tr)
    }

    /// The names of the solvers that run chains of N discs ([`SolverInfo::chain`]), joined
    /// by `sep`: what a refusal offers instead.
    pub fn chain_solver_names(sep: &str) -> String {
        SOLVERS
            .iter()
            .filter(|k| k.info().chain.is_some())
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(sep)
    }

    /// `"tol"` or `"h"`.
    pub fn setting_name(self) -> &'static str {
        self.0.knob.name()
    }

    /// Whether the accuracy knob is a fixed step h (else a tolerance).
    pub fn is_fixed_step(self) -> bool {
        self.0.knob == Knob::Step
    }

    /// A scene's accuracy at this solver's `setting` (its tolerance or its step).
    pub fn accuracy(self, setting: f64) -> Accuracy {
        self.0.knob.accuracy(setting)
    }

    /// The solver, with its default options. Every solver runs a [`rotor_model::seam::Scene`]
    /// through [`Solver::simulate`] and returns a [`rotor_model::seam::Trajectory`]:
    ///
    /// ```
    /// use rotor_model::Model;
    /// use rotor_model::seam::{Output, Scene};
    /// use rotor_analysis::solvers::SOLVERS;
    /// let scene = Scene { u: 1.5, t_end: 20.0, output: Output::Grid { dt: 0.01 }, ..Scene::default() };
    /// for kind in SOLVERS {
    ///     let tr = kind.solver().simulate(&Model::table1(), &scene).unwrap();
    ///     assert_eq!(tr.samples.len(), 2001); // 0, 0.01, ..., 20 s
    ///     println!("{}: {} steps, {} events", kind.name(), tr.stats.steps, tr.events.len());
    /// }
    /// ```
    pub fn solver(self) -> Box<dyn Solver> {
        (self.0.make)()
    }

    /// `"event-driven (tol 1e-12)"`.
    pub fn label_at(self, setting: f64) -> String {
        format!("{} ({} {setting:.0e})", self.0.label, self.setting_name())
    }

    /// `"tol 1e-10"` or `"h 1e-3"`.
    pub fn setting_label(self, setting: f64) -> String {
        format!("{} {setting:e}", self.setting_name())
    }
}

impl PartialEq for SolverKind {
    fn eq(&self, other: &Self) -> bool {
        self.0.name == other.0.name
    }
}

impl Eq for SolverKind {}

impl std::hash::Hash for SolverKind {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.name.hash(state);
    }
}

impl std::fmt::Debug for SolverKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0.name)
    }
}

impl Serialize for SolverKind {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0.name)
    }
}

/// A solver by its name, as it is serialised (a report read back: `rotor bench --merge`).
impl<'de> serde::Deserialize<'de> for SolverKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<SolverKind, D::Error> {
        let name = String::deserialize(d)?;
        SolverKind::by_name(&name).ok_or_else(|| {
            serde::de::Error::custom(format!("{name:?} is not a solver of this build"))
        })
    }
}

/// The gated pairs of a solver set: its first solver (the reference) against each other one.
pub fn pairs(solvers: &[SolverKind]) -> Vec<(SolverKind, SolverKind)> {
    match solvers.split_first() {
        Some((r, rest)) => rest.iter().map(|&s| (*r, s)).collect(),
        None => Vec::new(),
    }
}

/// A pair's name in `[tolerance.<pair>]` tables: `"event-switch"`.
pub fn pair_name(a: SolverKind, b: SolverKind) -> String {
    format!("{}-{}", a.name(), b.name())
}

/// The pair names of a solver set.
pub(crate) fn pair_names(solvers: &[SolverKind]) -> Vec<String> {
    pairs(solvers)
        .into_iter()
        .map(|(a, b)| pair_name(a, b))
        .collect()
}

/// Every pair of a solver set, each once, in the set's order: the reference against each
/// other solver ([`pairs`]) first, then each two of the others (`switch-moreau`), which are
/// compared over the whole run only (`rotor_harness::compare::whole`).
pub fn all_pairs(solvers: &[SolverKind]) -> Vec<(SolverKind, SolverKind)> {
    let mut v = pairs(solvers);
    for (i, &a) in solvers.iter().enumerate().skip(1) {
        for &b in &solvers[i + 1..] {
            v.push((a, b));
        }
    }
    v
}

/// Loads a scenario file whose `[tolerance.*]` tables may name only pairs of `solvers` (a
/// misspelt pair would leave a pair ungated); the pairs without the reference state the
/// whole-run tolerances alone.
pub fn load_scenario_for(
    path: &std::path::Path,
    solvers: &[SolverKind],
) -> Result<Scenario, ScenarioError> {
    let sc = Scenario::from_file(path)?;
    let names = |v: Vec<(SolverKind, SolverKind)>| -> Vec<String> {
        v.into_iter().map(|(a, b)| pair_name(a, b)).collect()
    };
    let all = names(all_pairs(solvers));
    let reference = pair_names(solvers);
    let others: Vec<String> = all
        .iter()
        .filter(|p| !reference.contains(p))
        .cloned()
        .collect();
    sc.check_pairs(&all, &others)?;
    Ok(sc)
}

/// Loads a scenario file for the project's solvers ([`SOLVERS`]).
pub fn load_scenario(path: &std::path::Path) -> Result<Scenario, ScenarioError> {
    load_scenario_for(path, &SOLVERS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_the_reference_against_each_other_solver() {
        assert_eq!(pair_names(&SOLVERS), ["event-switch", "event-moreau"]);
        let all: Vec<String> = all_pairs(&SOLVERS)
            .into_iter()
            .map(|(a, b)| pair_name(a, b))
            .collect();
        assert_eq!(all, ["event-switch", "event-moreau", "switch-moreau"]);
        assert_eq!(SolverKind::by_name("moreau"), Some(SolverKind::MOREAU));
        assert_eq!(SolverKind::by_name("rk4"), None);
        assert_eq!(
            SolverKind::EVENT.label_at(1e-12),
            "event-driven (tol 1e-12)"
        );
        assert_eq!(SolverKind::MOREAU.label_at(1e-3), "Moreau-Jean (h 1e-3)");
        // Names are unique and every solver makes the solver of its name.
        for (i, k) in SOLVERS.iter().enumerate() {
            assert_eq!(k.solver().name(), k.name());
            assert!(SOLVERS[..i].iter().all(|o| o.name() != k.name()));
        }
    }

    #[test]
    fn stuck_bands_are_the_solvers_own() {
        assert_eq!(
            SWITCH.stuck_band,
            rotor_switch::SwitchOptions::default().eta
        );
        assert_eq!((EVENT.stuck_band, MOREAU.stuck_band), (0.0, 0.0));
    }
}
