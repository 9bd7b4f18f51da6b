//! Peers in other languages, run as subprocesses in the same benchmark run: each prints one
//! JSON object with its own in-process run times (interpreter start-up excluded).

use std::path::Path;
use std::process::Command;

use serde::Deserialize;

use crate::BenchError;

/// What a peer script prints.
#[derive(Debug, Clone, Deserialize)]
pub struct PeerOutput {
    /// `"scipy"` or `"siconos"`.
    pub peer: String,
    /// Version of the library it drives.
    pub version: String,
    /// Integration method (`"DOP853"`, `"MoreauJeanOSI"`).
    pub method: String,
    /// One entry per accuracy setting.
    pub runs: Vec<PeerRun>,
}

/// One setting of a peer.
#[derive(Debug, Clone, Deserialize)]
pub struct PeerRun {
    /// rtol = atol, or h.
    pub setting: f64,
    /// Every timed run (s).
    pub seconds: Vec<f64>,
    /// Steady-state metrics of the last complete cycle, if a cycle was found.
    pub metrics: Option<PeerMetrics>,
    /// Accepted steps (all segments).
    pub steps: Option<u64>,
    /// Right-hand-side evaluations.
    pub rhs_evals: Option<u64>,
    /// Grid times of the transient window and ω_l there.
    pub t: Vec<f64>,
    pub omega_l: Vec<f64>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// A peer's cycle metrics.
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct PeerMetrics {
    pub period: f64,
    pub omega_l_max: f64,
}

/// Whether `python -c "import <module>"` works; the error says why not.
pub fn available(python: &str, module: &str) -> Result<(), String> {
    match Command::new(python)
        .args(["-c", &format!("import {module}")])
        .output()
    {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(format!(
            "`{python} -c \"import {module}\"` failed: {}",
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )),
        Err(e) => Err(format!("cannot run `{python}`: {e}")),
    }
}

/// Runs a peer script with arguments and parses its JSON.
pub fn run_script(python: &str, script: &Path, args: &[String]) -> Result<PeerOutput, BenchError> {
    let out = Command::new(python)
        .arg(script)
        .args(args)
        .output()
        .map_err(|e| BenchError::Peer {
            peer: script.display().to_string(),
            detail: format!("cannot run `{python}`: {e}"),
        })?;
    if !out.status.success() {
        return Err(BenchError::Peer {
            peer: script.display().to_string(),
            detail: format!(
                "exit status {}: {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        });
    }
    serde_json::from_slice(&out.stdout).map_err(|e| BenchError::Peer {
        peer: script.display().to_string(),
        detail: format!("unreadable JSON on stdout: {e}"),
    })
}

/// `1e-4,1e-5` for a command line (shortest round-trip form).
pub fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:e}"))
        .collect::<Vec<_>>()
        .join(",")
}
