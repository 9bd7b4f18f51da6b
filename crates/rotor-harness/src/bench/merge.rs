//! The suite in shards (`rotor bench --shard I/N`, every N-th scene from the I-th, for job
//! arrays) and the shards' reports joined into the report one run writes (`rotor bench
//! --merge`).
//!
//! A scene's solvers and clients all run in the same shard, so every time ratio (a client
//! against a Rust solver, a solver against the best on a scene) stays within one task on one
//! node. What is joined, and how:
//!
//! * `scenes`: every shard's scenes, put back in the suite's order.
//! * `output_levels`: shard 1's (they are measured on the suite's first scene; the other
//!   shards do not measure them).
//! * `clients`: per client, its scenes from every shard in the suite's order; its status,
//!   reason and protocol overhead recomputed from the joined points as one run computes
//!   them. A client that no shard ran (a peer not installed) is shard 1's entry as it is.
//! * `profile`: recomputed over the joined scenes, as one run computes it (a ratio there is
//!   against the best time on the same scene, so within one shard).
//! * `environment`: shard 1's, with the fewest `cores` of any shard, `debug_build` if any
//!   shard's was, and the highest load average any shard saw at its start and its end.
//!
//! Everything but the timings is then what one run writes (a test compares them). Shards
//! that do not fit together are refused, naming the file: a report written without
//! `--shard`, shards of different suites (scenes, horizons, ladders, references, repeats,
//! peers, clients) or of different counts N, a shard missing or given twice, a shard holding
//! the wrong number of scenes.

use serde::{Deserialize, Serialize};

use crate::bench::clients::{ClientReport, ClientStatus, summary};
use crate::bench::options::BenchOptions;
pub use crate::bench::word::Word;
use crate::bench::{BenchError, BenchReport, Environment};
use crate::jobs::sweep::Shard;

/// A shard's record in its report: which shard of which suite.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// I of `--shard I/N` (from 1).
    pub index: usize,
    /// N.
    pub count: usize,
    /// What every shard of one run shares: the suite's scenes (scenario file, horizon,
    /// windows, grid) and the options that decide what is measured.
    pub suite: serde_json::Value,
}

/// The record of shard `s` of the suite `opts` describes.
pub(crate) fn shard_info(opts: &BenchOptions, s: Shard) -> ShardInfo {
    let scenes: Vec<serde_json::Value> = opts
        .scenes
        .iter()
        .map(|sc| {
            serde_json::json!({
                "scenario": sc.scenario.file_stem().map(|f| f.to_string_lossy()),
                "t_end": sc.t_end,
                "metrics_from": sc.metrics_from,
                "transient": sc.transient,
                "dt": sc.dt,
            })
        })
        .collect();
    let ladders: Vec<(&str, &Vec<f64>)> = opts.ladders.iter().map(|(k, v)| (k.name(), v)).collect();
    let clients: Vec<serde_json::Value> = opts
        .clients
        .iter()
        .map(|c| serde_json::json!({"name": c.name, "command": c.command_line(), "fixed_step": c.fixed_step}))
        .collect();
    ShardInfo {
        index: s.i,
        count: s.n,
        suite: serde_json::json!({
            "scenes": scenes,
            "ladders": ladders,
            "reference_tol": opts.reference_tol,
            "reference_check_tol": opts.reference_check_tol,
            "repeats": opts.repeats,
            "time_budget": opts.time_budget,
            "output_levels": opts.output_levels,
            "peers": {
                "scipy": opts.peers.scipy,
                "scipy_tols": opts.peers.scipy_tols,
                "scipy_method_tols": opts.peers.scipy_method_tols,
                "siconos": opts.peers.siconos,
                "siconos_hs": opts.peers.siconos_hs,
                "octave": opts.peers.octave,
                "octave_tols": opts.peers.octave_tols,
            },
            "clients": clients,
            "timeout": opts.timeout,
            "client_tols": opts.client_tols,
            "client_hs": opts.client_hs,
        }),
    }
}

fn refuse(m: String) -> BenchError {
    BenchError::Merge(m)
}

/// Joins the reports of the shards of one run (each with the name of its file, for
/// messages), given in any order, into the report one run writes (timings aside; see the
/// module's text for what is joined and how).
pub fn merge(shards: &[(String, BenchReport)]) -> Result<BenchReport, BenchError> {
    let Some((first_name, first)) = shards.first() else {
        return Err(refuse("no shard given".into()));
    };
    let info = |(name, r): &(String, BenchReport)| {
        r.shard.clone().ok_or_else(|| {
            refuse(format!(
                "{name}: not a shard (a report written without --shard I/N)"
            ))
        })
    };
    let head = info(&shards[0])?;
    let n = head.count;
    let mut by_index: Vec<Option<&(String, BenchReport)>> = vec![None; n];
    for s in shards {
        let si = info(s)?;
        if si.count != n {
            return Err(refuse(format!(
                "{}: shard {}/{}, but {first_name} is shard {}/{n}: not shards of one run",
                s.0, si.index, si.count, head.index
            )));
        }
        if si.suite != head.suite {
            let what = differing_key(&si.suite, &head.suite);
            return Err(refuse(format!(
                "{}: a shard of a different suite than {first_name} (its {what} differ)",
                s.0
            )));
        }
        if si.index == 0 || si.index > n {
            return Err(refuse(format!(
                "{}: shard {}/{n} is not a shard of {n}",
                s.0, si.index
            )));
        }
        if let Some(other) = by_index[si.index - 1] {
            return Err(refuse(format!(
                "{} and {} are both shard {}/{n}",
                other.0, s.0, si.index
            )));
        }
        by_index[si.index - 1] = Some(s);
    }
    let missing: Vec<String> = (1..=n)
        .filter(|i| by_index[i - 1].is_none())
        .map(|i| format!("{i}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(refuse(format!(
            "shard(s) {} missing (given: {})",
            missing.join(", "),
            shards
                .iter()
                .map(|s| s.0.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let parts: Vec<&(String, BenchReport)> = by_index.into_iter().flatten().collect();
    let total = head.suite["scenes"].as_array().map_or(0, Vec::len);
    for (k, (name, r)) in parts.iter().enumerate() {
        let want = Shard { i: k + 1, n }.indices(total).count();
        if r.scenes.len() != want {
            return Err(refuse(format!(
                "{name}: holds {} scene(s), but shard {}/{n} of a suite of {total} holds {want}",
                r.scenes.len(),
                k + 1
            )));
        }
    }
    // Scene k of the suite is scene k / N of shard k % N + 1.
    let scene_of = |k: usize| &parts[k % n].1.scenes[k / n];
    let scenes: Vec<_> = (0..total).map(|k| scene_of(k).clone()).collect();
    for (name, r) in &parts {
        if r.benchmark != parts[0].1.benchmark {
            return Err(refuse(format!(
                "{name}: graded against {}, but {}: {}",
                r.benchmark, parts[0].0, parts[0].1.benchmark
            )));
        }
    }
    let names = |r: &BenchReport| r.clients.iter().map(|c| c.name.clone()).collect::<Vec<_>>();
    let client_names = names(&parts[0].1);
    for (name, r) in &parts {
        if names(r) != client_names {
            return Err(refuse(format!(
                "{name}: clients {:?}, but {}: {:?}",
                names(r),
                parts[0].0,
                client_names
            )));
        }
    }
    let clients = (0..client_names.len())
        .map(|c| join_client(&parts, c, total))
        .collect::<Vec<_>>();
    let (profile, profile_table1) = crate::bench::profile::by_tier(&scenes, &clients);
    let envs: Vec<&Environment> = parts.iter().map(|(_, r)| &r.environment).collect();
    let max_load = |pick: fn(&Environment) -> Option<[f64; 3]>| {
        envs.iter().filter_map(|e| pick(e)).reduce(|a, b| {
            let mut m = a;
            for i in 0..3 {
                m[i] = a[i].max(b[i]);
            }
            m
        })
    };
    let environment = Environment {
        cores: envs
            .iter()
            .map(|e| e.cores)
            .min()
            .unwrap_or(first.environment.cores),
        debug_build: envs.iter().any(|e| e.debug_build),
        load_start: max_load(|e| e.load_start),
        load_end: max_load(|e| e.load_end),
        ..parts[0].1.environment.clone()
    };
    Ok(BenchReport {
        benchmark: parts[0].1.benchmark.clone(),
        scenes,
        output_levels: parts[0].1.output_levels.clone(),
        clients,
        profile,
        profile_table1,
        environment,
        shard: None,
    })
}

/// Client `c` over the whole suite: its scenes from every shard, in the suite's order.
fn join_client(parts: &[&(String, BenchReport)], c: usize, total: usize) -> ClientReport {
    let n = parts.len();
    let entries: Vec<&ClientReport> = parts.iter().map(|(_, r)| &r.clients[c]).collect();
    let Some(template) = entries.iter().find(|e| e.status != ClientStatus::Skipped) else {
        return entries[0].clone();
    };
    let scenes: Vec<_> = (0..total)
        .filter_map(|k| {
            let scene = &parts[k % n].1.scenes[k / n].name;
            entries[k % n]
                .scenes
                .iter()
                .find(|s| &s.scene == scene)
                .cloned()
        })
        .collect();
    let (status, reason, overhead) = summary(&scenes);
    ClientReport {
        status,
        reason,
        overhead,
        version: entries.iter().find_map(|e| e.version.clone()),
        method: entries.iter().find_map(|e| e.method.clone()),
        scenes,
        ..(*template).clone()
    }
}

/// The first top-level key in which two suites differ (for the message).
fn differing_key(a: &serde_json::Value, b: &serde_json::Value) -> String {
    match (a.as_object(), b.as_object()) {
        (Some(x), Some(y)) => x
            .keys()
            .chain(y.keys())
            .find(|k| x.get(*k) != y.get(*k))
            .map_or("settings".into(), |k| k.replace('_', " ")),
        _ => "settings".into(),
    }
}
