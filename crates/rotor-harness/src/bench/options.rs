//! What the benchmark runs: scenes, accuracy ladders, repetitions, peers.

use std::path::{Path, PathBuf};

use rotor_analysis::solvers::SOLVERS;
pub use rotor_analysis::solvers::SolverKind;

/// A scene's tier: which solvers it is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tier {
    /// Only the lower disc has static friction (one switching surface): what a solver written
    /// for Table 1 handles.
    Table1,
    /// The upper disc sticks too (two frictional contacts).
    Full,
}

impl Tier {
    /// `table1` or `full`.
    pub fn name(self) -> &'static str {
        match self {
            Tier::Table1 => "table1",
            Tier::Full => "full",
        }
    }

    /// A tier by its name (`--tier`).
    pub fn parse(s: &str) -> Result<Tier, String> {
        match s {
            "table1" => Ok(Tier::Table1),
            "full" => Ok(Tier::Full),
            _ => Err(format!("--tier {s:?}: expected table1 or full")),
        }
    }

    /// The tier of a scenario: `full` when its upper disc's friction is set-valued.
    pub fn of(sc: &rotor_model::scenario::Scenario) -> Tier {
        if sc.model.friction(rotor_model::Disc::UPPER).is_set_valued() {
            Tier::Full
        } else {
            Tier::Table1
        }
    }

    /// Whether a scene of tier `scene` belongs to this tier: the full tier holds every scene,
    /// the table1 tier its own.
    pub fn holds(self, scene: Tier) -> bool {
        self == Tier::Full || scene == Tier::Table1
    }
}

/// The scenes that lead the suite, in this order (the first is the output levels' scene):
/// the two stick-slip cycles at 1.5 V. The other scenes follow, table1 tier first, by name.
pub const LEAD_SCENES: [&str; 2] = ["t1-u1.5-rest", "st-u1.5-rest"];

/// One benchmark scene: a scenario file, a horizon, and the windows the errors are read on.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSpec {
    /// Scenario file (`fixtures/scenarios/*.toml`): parameters, u, x0.
    pub scenario: PathBuf,
    /// Horizon (s) (overrides the file's `t_end`).
    pub t_end: f64,
    /// Steady-state metrics (period, max ω_l) over `[metrics_from, t_end]` (s).
    pub metrics_from: f64,
    /// Window `[t0, t1]` (s) on which max |Δω_l| is read, on the grid `k·dt`.
    pub transient: [f64; 2],
    /// Grid step of the full trace (s).
    pub dt: f64,
}

impl SceneSpec {
    /// Table 1 at u = 1.5 V from rest over `t_end` seconds: a stick-slip cycle. Metrics over
    /// the second half, the transient over the first `min(20, t_end/5)` seconds.
    pub fn table1_u15(root: &Path, t_end: f64) -> SceneSpec {
        SceneSpec {
            scenario: root.join("fixtures/scenarios/t1-u1.5-rest.toml"),
            t_end,
            metrics_from: 0.5 * t_end,
            transient: [0.0, (0.2 * t_end).min(20.0)],
            dt: 0.01,
        }
    }

    /// A scenario file as it stands: its horizon, its steady window and transient window,
    /// its grid. The error names the file when it compares no transient or no steady state
    /// (the benchmark measures both).
    pub fn from_scenario(path: &Path) -> Result<SceneSpec, crate::bench::BenchError> {
        let sc = rotor_analysis::solvers::load_scenario(path)?;
        let (Some(transient), Some(metrics_from)) = (sc.compare.transient, sc.compare.steady_from)
        else {
            return Err(crate::bench::BenchError::Options(format!(
                "{}: the benchmark needs [compare] transient and steady_from",
                path.display()
            )));
        };
        Ok(SceneSpec {
            scenario: path.to_owned(),
            t_end: sc.t_end,
            metrics_from,
            transient,
            dt: sc.compare.dt,
        })
    }

    /// The Stribeck set at u = 1.5 V from rest over `t_end` seconds: both discs start stuck
    /// (the upper disc has static friction and breaks away first), then a stick-slip cycle.
    /// Windows as [`SceneSpec::table1_u15`].
    pub fn stribeck_u15(root: &Path, t_end: f64) -> SceneSpec {
        SceneSpec {
            scenario: root.join("fixtures/scenarios/st-u1.5-rest.toml"),
            ..SceneSpec::table1_u15(root, t_end)
        }
    }
}

/// The whole suite: every scenario of `dir` (`fixtures/scenarios`) as it stands
/// ([`SceneSpec::from_scenario`]), with its tier; [`LEAD_SCENES`] first, then the table1 tier,
/// then the full tier, each by name. `tier` keeps the scenes that tier holds.
pub fn suite(dir: &Path, tier: Option<Tier>) -> Result<Vec<SceneSpec>, crate::bench::BenchError> {
    let files = rotor_model::scenario::Scenario::list_dir(dir).map_err(|e| {
        crate::bench::BenchError::Options(format!(
            "{}: cannot list the scenarios: {e}",
            dir.display()
        ))
    })?;
    let mut scenes = Vec::new();
    for f in files {
        let sc = rotor_analysis::solvers::load_scenario(&f)?;
        let t = Tier::of(&sc);
        if tier.is_none_or(|want| want.holds(t)) {
            let lead = LEAD_SCENES.iter().position(|n| *n == sc.name);
            scenes.push((
                (lead.unwrap_or(LEAD_SCENES.len()), t == Tier::Full, sc.name),
                f,
            ));
        }
    }
    scenes.sort();
    scenes
        .into_iter()
        .map(|(_, f)| SceneSpec::from_scenario(&f))
        .collect()
}

/// The named scenario files as scenes (in the order given), keeping those `tier` holds; an
/// error names the tier when none is left.
pub fn select(
    paths: &[PathBuf],
    tier: Option<Tier>,
) -> Result<Vec<SceneSpec>, crate::bench::BenchError> {
    let mut scenes = Vec::new();
    for p in paths {
        let t = Tier::of(&rotor_analysis::solvers::load_scenario(p)?);
        if tier.is_none_or(|want| want.holds(t)) {
            scenes.push(SceneSpec::from_scenario(p)?);
        }
    }
    if scenes.is_empty()
        && let Some(t) = tier
    {
        return Err(crate::bench::BenchError::Options(format!(
            "--tier {}: none of the named scenes is in that tier",
            t.name()
        )));
    }
    Ok(scenes)
}

/// The suite's scenario directory: `fixtures/scenarios` of the workspace root
/// ([`workspace_root`]).
pub fn suite_dir() -> PathBuf {
    workspace_root().join("fixtures/scenarios")
}

/// Which peers to run next to the Rust solvers, and how.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerOptions {
    /// Run `bench/peers/scipy_rotor.py` if `python -c "import scipy"` works.
    pub scipy: bool,
    /// Interpreter for the scipy peer.
    pub python: String,
    /// rtol = atol ladder of the scipy peer (`solve_ivp`, DOP853).
    pub scipy_tols: Vec<f64>,
    /// Run `bench/peers/siconos_rotor.py` if `siconos_python -c "import siconos"` works.
    pub siconos: bool,
    /// Interpreter for the Siconos peer (Debian's python3-siconos lives in /usr/bin/python3).
    pub siconos_python: String,
    /// Step sizes at which Siconos and rotor-moreau are compared per step.
    pub siconos_hs: Vec<f64>,
    /// Run `bench/peers/octave_rotor.m` (GNU Octave's `ode45` with event functions) if
    /// `octave_cli` has `ode45` and `jsondecode` (GNU Octave 7 or later).
    pub octave: bool,
    /// The Octave interpreter (Debian's `octave` package installs `octave-cli`).
    pub octave_cli: String,
    /// RelTol = AbsTol ladder of the Octave peer.
    pub octave_tols: Vec<f64>,
    /// rtol = atol ladder of the scipy peer's implicit and switching methods (peers
    /// `scipy-radau`, `scipy-bdf`, `scipy-lsoda`: `scipy_rotor.py --method M`), run with
    /// `scipy`; empty: not run.
    pub scipy_method_tols: Vec<f64>,
    /// Directory holding the peer scripts.
    pub dir: PathBuf,
}

/// Everything [`crate::bench::run`] does.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchOptions {
    /// Scenes; the first one is also used for the output-level ratios and the peers.
    pub scenes: Vec<SceneSpec>,
    /// Each solver with its ladder of settings (tolerances or steps), in report order;
    /// default: every solver of `rotor_analysis::solvers::SOLVERS` with its own ladder.
    pub ladders: Vec<(SolverKind, Vec<f64>)>,
    /// Tolerance of the reference run (event-driven solver).
    pub reference_tol: f64,
    /// A tighter tolerance run once to estimate the reference's own error
    /// (`|ref(reference_tol) − ref(reference_check_tol)|`).
    pub reference_check_tol: f64,
    /// Timed repetitions per point (the median is reported).
    pub repeats: usize,
    /// Seconds of timing per point: a point whose single run takes longer is timed fewer
    /// times (down to its untimed-warm-up-free single run).
    pub time_budget: f64,
    /// Measure metrics-only vs full-trace run time for each solver at its default setting
    /// (`SolverInfo::default`).
    pub output_levels: bool,
    /// Peers.
    pub peers: PeerOptions,
    /// External solvers (`rotor bench --external NAME=COMMAND`).
    pub clients: Vec<crate::protocol::ClientSpec>,
    /// A client's run past this many seconds is killed, its process group with it.
    pub timeout: f64,
    /// The ladder of an external client with a tolerance (1e-3 … 1e-12).
    pub client_tols: Vec<f64>,
    /// The ladder of an external client with a step h (1e-2 … 1e-4).
    pub client_hs: Vec<f64>,
    /// Run only every N-th scene from the I-th (`rotor bench --shard I/N`, for job arrays);
    /// [`crate::bench::merge()`] joins the shards' reports.
    pub shard: Option<crate::jobs::sweep::Shard>,
    /// Where to keep every external run's files (`DIR/CLIENT/SCENE/runK`: job.json,
    /// trace.csv, events.csv, stderr.txt); `None`: a temporary directory, deleted after.
    pub keep: Option<std::path::PathBuf>,
    /// External clients (peers included) run side by side, each over its whole ladder; at
    /// least 1. Each client's runs stay one after the other, each process single-threaded
    /// ([`crate::protocol::SINGLE_THREAD_ENV`]); the Rust solvers are timed before any client
    /// starts, alone.
    pub jobs: usize,
}

/// The workspace root: the current directory if it holds `fixtures/`, else the checkout
/// this crate was built from.
pub fn workspace_root() -> PathBuf {
    let here = PathBuf::from(".");
    if here.join("fixtures/scenarios").is_dir() {
        return here;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

impl Default for BenchOptions {
    /// The whole suite ([`suite`]: every scenario of `fixtures/scenarios`, its own horizon,
    /// windows and grid; both tiers), with short ladders for the peers and clients (the whole
    /// run with every peer and two clients takes 6 to 9 minutes on two cores, BENCHMARK.md; most
    /// of it Octave, Radau, BDF, Siconos and the tanh client): event and switch at tol 1e-3 … 1e-12,
    /// Moreau–Jean at h = 1e-2 … 1e-4 (1-2-5), reference = event at tol 1e-13, median of up
    /// to 15 runs within 0.3 s per point (a run longer than that is timed once); the scipy
    /// peer at rtol = atol = 1e-4, 1e-7, 1e-10 (DOP853) and 1e-6, 1e-9 (Radau, BDF, LSODA),
    /// Siconos at h = 1e-2 and 2e-3, external clients at tol 1e-4, 1e-6, 1e-8, 1e-10 (four,
    /// so that a client ignoring its tolerance is told) or h = 1e-2, 1e-3, 1e-4. The Rust tolerance ladders start at
    /// 1e-3 so that the event solver has a point less accurate than scipy's loosest (tol
    /// 1e-4): the ratio there is then measured, not only bounded. (A scenario directory that
    /// cannot be read leaves the scene list empty: [`crate::bench::run`] then says "no scene".)
    fn default() -> Self {
        let root = workspace_root();
        BenchOptions {
            scenes: suite(&suite_dir(), None).unwrap_or_default(),
            ladders: SOLVERS
                .iter()
                .map(|k| {
                    // Moreau–Jean's h = 1e-5 (seconds a run on a 200 s scene) is left to
                    // `rotor bench --scenario` runs with a ladder of their own.
                    let fixed = k.is_fixed_step();
                    let l = k
                        .info()
                        .ladder
                        .iter()
                        .copied()
                        .filter(|&x| !fixed || x >= 1e-4);
                    (*k, l.collect())
                })
                .collect(),
            reference_tol: 1e-13,
            reference_check_tol: 1e-14,
            repeats: 15,
            time_budget: 0.3,
            output_levels: true,
            peers: PeerOptions {
                scipy: true,
                python: "python3".into(),
                scipy_tols: vec![1e-4, 1e-7, 1e-10],
                // Radau and BDF at 1e-10 took a third of all client time in a full run (up
                // to 60 s a run on one 200 s scene); 1e-9 costs about half and gives about a
                // digit less (Radau at 1e-10: 7.7-10.6 digits on the suite).
                scipy_method_tols: vec![1e-6, 1e-9],
                siconos: true,
                siconos_python: "/usr/bin/python3".into(),
                // Each divides the 0.01 s grid; h = 1e-3 takes 7 s a run on a 200 s scene.
                siconos_hs: vec![1e-2, 2e-3],
                octave: true,
                octave_cli: "octave-cli".into(),
                // Its run time is mostly Octave's own per output sample (its event function
                // is evaluated at every grid time), within 2x at every tolerance, and one run
                // of a 100 s scene takes 6-14 s: two settings, the loosest that reaches loose
                // and one that reaches strict on both default scenes (measured on
                // t1-u1.5-rest and st-u1.5-rest over 200 s: 4.6 and 5.4 digits at 1e-6, 6.5
                // and 7.1 at 1e-8, 7.8 and 8.3 at 1e-10).
                octave_tols: vec![1e-6, 1e-10],
                dir: root.join("bench/peers"),
            },
            clients: Vec::new(),
            timeout: 60.0,
            client_tols: vec![1e-4, 1e-6, 1e-8, 1e-10],
            // Steps that divide the 0.01 s output grid (every sample falls on a step end).
            client_hs: vec![1e-2, 1e-3, 1e-4],
            shard: None,
            keep: None,
            jobs: 1,
        }
    }
}

impl BenchOptions {
    /// A few-second variant for tests: 30 s horizon, three points per ladder, reference at
    /// tol 1e-12, median of 3 within 0.5 s, no peers.
    pub fn quick() -> Self {
        let root = workspace_root();
        let full = BenchOptions::default();
        BenchOptions {
            scenes: vec![SceneSpec::table1_u15(&root, 30.0)],
            ladders: vec![
                (SolverKind::EVENT, vec![1e-4, 1e-6, 1e-8]),
                (SolverKind::SWITCH, vec![1e-4, 1e-6, 1e-8]),
                (SolverKind::MOREAU, vec![1e-2, 5e-3, 1e-3]),
            ],
            reference_tol: 1e-12,
            reference_check_tol: 1e-13,
            repeats: 3,
            time_budget: 0.5,
            output_levels: true,
            peers: PeerOptions {
                scipy: false,
                siconos: false,
                octave: false,
                scipy_tols: vec![1e-4, 1e-6, 1e-8],
                scipy_method_tols: Vec::new(),
                ..full.peers.clone()
            },
            client_tols: vec![1e-4, 1e-6, 1e-8],
            client_hs: vec![1e-2, 1e-3],
            ..full
        }
    }

    /// The ladder of one solver (empty if it is not benchmarked).
    pub fn ladder(&self, kind: SolverKind) -> &[f64] {
        self.ladders
            .iter()
            .find(|(k, _)| *k == kind)
            .map_or(&[], |(_, l)| l.as_slice())
    }

    /// Sets the ladder of one solver (adding the solver if it has none).
    pub fn set_ladder(&mut self, kind: SolverKind, settings: Vec<f64>) {
        match self.ladders.iter_mut().find(|(k, _)| *k == kind) {
            Some(l) => l.1 = settings,
            None => self.ladders.push((kind, settings)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The suite is every scenario file, the two 1.5 V cycles first, then the table1 tier,
    /// then the full tier's own; the table1 tier is the `t1-*` scenes (Table 1 has no upper
    /// static friction), the full tier every scene.
    #[test]
    fn the_suite_leads_with_the_cycles_and_splits_into_tiers() {
        let dir = suite_dir();
        let n = rotor_model::scenario::Scenario::list_dir(&dir)
            .unwrap()
            .len();
        let name = |s: &SceneSpec| s.scenario.file_stem().unwrap().to_str().unwrap().to_owned();
        let all: Vec<String> = suite(&dir, None).unwrap().iter().map(name).collect();
        assert_eq!(all.len(), n);
        assert_eq!(all[..2], LEAD_SCENES.map(str::to_owned));
        let first_full = all
            .iter()
            .position(|s| s.starts_with("st-") && s != "st-u1.5-rest");
        assert!(
            all[2..first_full.unwrap()]
                .iter()
                .all(|s| s.starts_with("t1-")),
            "{all:?}"
        );
        let t1: Vec<String> = suite(&dir, Some(Tier::Table1))
            .unwrap()
            .iter()
            .map(name)
            .collect();
        assert!(t1.iter().all(|s| s.starts_with("t1-")), "{t1:?}");
        assert_eq!(
            t1.len(),
            all.iter().filter(|s| s.starts_with("t1-")).count()
        );
        assert_eq!(suite(&dir, Some(Tier::Full)).unwrap().len(), n);
        // A named selection keeps its order and drops what the tier does not hold.
        let named = [dir.join("st-u2.5-rest.toml"), dir.join("t1-u0.5-rest.toml")];
        let s = select(&named, Some(Tier::Table1)).unwrap();
        assert_eq!(s.iter().map(name).collect::<Vec<_>>(), ["t1-u0.5-rest"]);
        assert_eq!(select(&named, None).unwrap().len(), 2);
        let e = select(&named[..1], Some(Tier::Table1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--tier table1"), "{e}");
        assert!(Tier::parse("both").unwrap_err().contains("\"both\""));
    }

    /// The suite's ladders: the tolerance solvers keep their whole ladder (down to 1e-12),
    /// Moreau–Jean stops at h = 1e-4.
    #[test]
    fn the_suite_keeps_the_tolerance_ladders_whole() {
        let o = BenchOptions::default();
        for k in SOLVERS {
            let want: Vec<f64> = k.info().ladder.to_vec();
            if k.is_fixed_step() {
                assert_eq!(o.ladder(k).last(), Some(&1e-4));
            } else {
                assert_eq!(o.ladder(k), want.as_slice(), "{}", k.name());
                assert_eq!(o.ladder(k).last(), Some(&1e-12));
            }
        }
    }
}
