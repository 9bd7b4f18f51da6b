//! The performance profile (Dolan & Moré, 2002) over the benchmark's scenes: for each solver
//! and client p, `ρ_p(τ)` is the fraction of scenes it solves within a factor τ of the best
//! time on that scene.
//!
//! "Solved" is the same for everyone: a point whose trace passes the scene's loose gate (the
//! scenario's event-moreau tolerances, graded as `rotor check` grades a trace). Its time is
//! that of the fastest such point: the in-process time (the Rust solvers' median, a client's
//! `solve_seconds`, or its wall time when it reports none).

use rotor_analysis::plot::{Panel, Series, render};
use serde::{Deserialize, Serialize};

use crate::bench::clients::ClientReport;
use crate::bench::ladder::SceneReport;
pub use crate::bench::word::CRITERION;

/// One solver or client in the profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileEntry {
    /// The solver's or client's name.
    pub name: String,
    /// Its time per scene \[s\] (`None`: not solved).
    pub times: Vec<Option<f64>>,
    /// Its time over the best time per scene (`None`: not solved).
    pub ratios: Vec<Option<f64>>,
}

/// The performance profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// The tier whose scenes it is over (`full`: every scene of the run; `table1`).
    #[serde(default)]
    pub tier: String,
    /// What counts as solved, and which time is taken ([`CRITERION`]).
    #[serde(deserialize_with = "crate::bench::word::static_str")]
    pub criterion: crate::bench::word::Word,
    /// The scenes' names, in the order of each entry's `times` and `ratios`.
    pub scenes: Vec<String>,
    /// The solvers first, then the clients that ran.
    pub entries: Vec<ProfileEntry>,
}

impl Profile {
    /// `ρ(τ)`: the fraction of scenes `e` solves within τ times the best.
    pub fn rho(e: &ProfileEntry, tau: f64) -> f64 {
        if e.ratios.is_empty() {
            return 0.0;
        }
        e.ratios
            .iter()
            .filter(|r| r.is_some_and(|r| r <= tau))
            .count() as f64
            / e.ratios.len() as f64
    }

    /// The profile as an SVG figure: ρ(τ) against τ (log), one step line per entry.
    pub fn to_svg(&self) -> String {
        render(&[self.panel()], 760.0, 440.0)
    }

    /// The profile's plot panel.
    pub fn panel(&self) -> Panel<'_> {
        let tau_max = self
            .entries
            .iter()
            .flat_map(|e| e.ratios.iter().flatten())
            .fold(2.0f64, |a, &r| a.max(2.0 * r));
        let series: Vec<Series> = self
            .entries
            .iter()
            .map(|e| {
                let mut taus: Vec<f64> = e.ratios.iter().flatten().copied().collect();
                taus.sort_by(f64::total_cmp);
                let mut pts = vec![(1.0, Profile::rho(e, 1.0))];
                for t in taus {
                    pts.push((t, pts.last().map_or(0.0, |p| p.1)));
                    pts.push((t, Profile::rho(e, t)));
                }
                pts.push((tau_max, Profile::rho(e, tau_max)));
                let st = crate::bench::colors::style(&e.name);
                Series {
                    dash: st.dash,
                    ..Series::line(&e.name, st.color, pts)
                }
            })
            .collect();
        let mut panel = Panel::new(
            format!(
                "Performance profile, tier {}, over {} scene(s): solved = passes the loose gate",
                if self.tier.is_empty() {
                    "full"
                } else {
                    &self.tier
                },
                self.scenes.len()
            ),
            "τ (time / best time on the scene)",
            "fraction of scenes solved within τ",
            series,
        );
        panel.x_log = true;
        panel
    }
}

/// The profiles per tier: over every scene (the full tier), and over the table1-tier scenes
/// alone when the scenes are of both tiers.
pub(crate) fn by_tier(
    scenes: &[SceneReport],
    clients: &[ClientReport],
) -> (Profile, Option<Profile>) {
    let full = Profile {
        tier: "full".into(),
        ..profile(scenes, clients)
    };
    let t1: Vec<SceneReport> = scenes
        .iter()
        .filter(|s| s.tier == "table1")
        .cloned()
        .collect();
    let table1 = (!t1.is_empty() && t1.len() < scenes.len()).then(|| Profile {
        tier: "table1".into(),
        ..profile(&t1, clients)
    });
    (full, table1)
}

/// The profile of the solvers and clients over the scenes.
pub fn profile(scenes: &[SceneReport], clients: &[ClientReport]) -> Profile {
    let fastest = |times: Vec<f64>| times.into_iter().reduce(f64::min);
    let mut entries: Vec<(String, Vec<Option<f64>>)> = Vec::new();
    for kind in rotor_analysis::solvers::SOLVERS {
        let times = scenes
            .iter()
            .map(|sc| {
                fastest(
                    sc.points
                        .iter()
                        .filter(|p| p.solver == kind && p.passes_loose == Some(true))
                        .filter_map(|p| Some(p.timing?.median_s))
                        .collect(),
                )
            })
            .collect();
        entries.push((kind.name().to_owned(), times));
    }
    for c in clients.iter().filter(|c| !c.scenes.is_empty()) {
        let times = scenes
            .iter()
            .map(|sc| {
                let cs = c.scenes.iter().find(|s| s.scene == sc.name)?;
                fastest(
                    cs.points
                        .iter()
                        .filter(|p| p.passes_loose == Some(true))
                        .filter_map(|p| Some(p.time()?.median_s))
                        .collect(),
                )
            })
            .collect();
        entries.push((c.name.clone(), times));
    }
    let best: Vec<Option<f64>> = (0..scenes.len())
        .map(|k| entries.iter().filter_map(|(_, t)| t[k]).reduce(f64::min))
        .collect();
    Profile {
        tier: String::new(),
        criterion: CRITERION,
        scenes: scenes.iter().map(|s| s.name.clone()).collect(),
        entries: entries
            .into_iter()
            .map(|(name, times)| ProfileEntry {
                ratios: times
                    .iter()
                    .zip(&best)
                    .map(|(t, b)| Some(t.as_ref()? / b.as_ref()?))
                    .collect(),
                name,
                times,
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_counts_scenes_within_tau() {
        let e = ProfileEntry {
            name: "x".into(),
            times: vec![Some(1.0), Some(3.0), None, Some(2.0)],
            ratios: vec![Some(1.0), Some(3.0), None, Some(1.5)],
        };
        assert_eq!(Profile::rho(&e, 1.0), 0.25);
        assert_eq!(Profile::rho(&e, 2.0), 0.5);
        assert_eq!(Profile::rho(&e, 10.0), 0.75);
    }
}
