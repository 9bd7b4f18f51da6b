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
    let parsed: PeerOutput = serde_json::from_slice(&out.stdout).map_err(|e| BenchError::Peer {
        peer: script.display().to_string(),
        detail: format!("unreadable JSON on stdout: {e}"),
    })?;
    parsed.validate().map_err(|detail| BenchError::Peer {
        peer: script.display().to_string(),
        detail,
    })?;
    Ok(parsed)
}

impl PeerOutput {
    /// Checks what the ratios are computed from: settings and run times positive and finite,
    /// step counts positive, metrics and samples finite, one ω_l per grid time. The error
    /// names the run and the field. (A failed run, with `failure` set, is only reported.)
    pub fn validate(&self) -> Result<(), String> {
        for (i, r) in self.runs.iter().enumerate() {
            let bad =
                |field: &str, v: String, why: &str| Err(format!("runs[{i}].{field} = {v}: {why}"));
            if !(r.setting > 0.0 && r.setting.is_finite()) {
                return bad(
                    "setting",
                    r.setting.to_string(),
                    "must be positive and finite",
                );
            }
            if r.failure.is_some() {
                continue;
            }
            if let Some(x) = r.seconds.iter().find(|x| !(**x > 0.0 && x.is_finite())) {
                return bad(
                    "seconds",
                    x.to_string(),
                    "run times must be positive and finite",
                );
            }
            if r.steps == Some(0) {
                return bad("steps", "0".into(), "a run takes at least one step");
            }
            if let Some(m) = r.metrics
                && !(m.period > 0.0 && m.period.is_finite() && m.omega_l_max.is_finite())
            {
                return bad(
                    "metrics",
                    format!("{m:?}"),
                    "must be finite, with a positive period",
                );
            }
            if r.t.len() != r.omega_l.len() {
                return bad(
                    "omega_l",
                    format!("{} values", r.omega_l.len()),
                    &format!("must be one per grid time ({} times)", r.t.len()),
                );
            }
            if let Some(x) = r.t.iter().chain(&r.omega_l).find(|x| !x.is_finite()) {
                return bad("t/omega_l", x.to_string(), "samples must be finite");
            }
        }
        Ok(())
    }
}

/// `1e-4,1e-5` for a command line (shortest round-trip form).
pub fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:e}"))
        .collect::<Vec<_>>()
        .join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> PeerOutput {
        serde_json::from_str(
            r#"{"peer": "scipy", "version": "1", "method": "DOP853", "runs": [
                {"setting": 1e-6, "seconds": [0.1, 0.2], "metrics": {"period": 4.5,
                 "omega_l_max": 6.3}, "steps": 10, "rhs_evals": 100, "t": [0.0, 0.01],
                 "omega_l": [0.0, 0.1], "failure": null},
                {"setting": 1e-4, "seconds": [], "metrics": null, "steps": null,
                 "rhs_evals": null, "t": [], "omega_l": [], "failure": "step too small"}]}"#,
        )
        .unwrap()
    }

    #[test]
    fn peer_output_is_checked_before_any_ratio() {
        assert_eq!(good().validate(), Ok(()));
        type Spoil = fn(&mut PeerRun);
        let cases: [(Spoil, &str); 7] = [
            (|r| r.setting = 0.0, "runs[0].setting = 0"),
            (|r| r.seconds[1] = f64::NAN, "runs[0].seconds = NaN"),
            (|r| r.seconds[0] = 0.0, "runs[0].seconds = 0"),
            (|r| r.steps = Some(0), "runs[0].steps = 0"),
            (
                |r| r.metrics.as_mut().unwrap().period = f64::INFINITY,
                "runs[0].metrics",
            ),
            (|r| r.omega_l.push(1.0), "runs[0].omega_l = 3 values"),
            (|r| r.t[1] = f64::NAN, "runs[0].t/omega_l = NaN"),
        ];
        for (spoil, needle) in cases {
            let mut o = good();
            spoil(&mut o.runs[0]);
            let e = o.validate().unwrap_err();
            assert!(e.contains(needle), "{e} lacks {needle}");
        }
    }
}
