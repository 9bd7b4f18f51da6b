//! The external-solver protocol (BENCHMARK.md): a client is a command, started once per
//! (scene, setting) with the path of a job file as its last argument; it writes the trace
//! (and optionally the events) named in the job and may print `{"solve_seconds": S}` on
//! standard output.
//!
//! Each run is its own process group, killed as a whole (SIGKILL) when it runs past the
//! timeout; its wall time is measured from the spawn to its exit.

#![warn(missing_docs)]

pub mod peers;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rotor_model::FieldError;
use serde::Serialize;

/// An external solver: its name, the command (split into words), and whether its accuracy
/// knob is a step `h` rather than a tolerance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClientSpec {
    /// Its name in the report (`NAME` of `--external NAME=COMMAND`).
    pub name: String,
    /// The command split into words; the job file's path is appended at each run.
    pub argv: Vec<String>,
    /// Whether its knob is a step h (its ladder is then h = 1e-2, 1e-3, 1e-4) rather than a
    /// tolerance.
    pub fixed_step: bool,
    /// One of the repository's own peers (scipy, Siconos, Octave), run when installed.
    pub peer: bool,
}

impl ClientSpec {
    /// `NAME=COMMAND` as given to `--external`; a refusal names the field `external`. The
    /// client is fixed-step when `fixed` names it, or when its name says so (it contains
    /// `fixed`, `moreau`, `siconos` or ends in `:h`, which is removed).
    pub fn parse(arg: &str, fixed: &[String]) -> Result<ClientSpec, FieldError> {
        let bad = |reason: String| FieldError::new("external", format!("{arg:?}"), reason);
        let (name, command) = arg
            .split_once('=')
            .ok_or_else(|| bad("expected NAME=COMMAND".into()))?;
        let name = name.trim();
        if name.is_empty() || name.contains(['/', '\\', ' ']) {
            return Err(bad(format!(
                "the name {name:?} must be non-empty, without spaces or slashes"
            )));
        }
        let argv = split_words(command).map_err(bad)?;
        if argv.is_empty() {
            return Err(bad("the command is empty".into()));
        }
        let (name, by_suffix) = match name.strip_suffix(":h") {
            Some(n) => (n, true),
            None => (name, false),
        };
        let lower = name.to_lowercase();
        let fixed_step = by_suffix
            || fixed.iter().any(|f| f == name)
            || ["fixed", "moreau", "siconos"]
                .iter()
                .any(|w| lower.contains(w));
        Ok(ClientSpec {
            name: name.to_owned(),
            argv,
            fixed_step,
            peer: false,
        })
    }

    /// The command as one line, words quoted where needed.
    pub(crate) fn command_line(&self) -> String {
        self.argv
            .iter()
            .map(|w| {
                if !w.is_empty()
                    && w.chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
                {
                    w.clone()
                } else {
                    format!("'{}'", w.replace('\'', "'\\''"))
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Splits a command line into words as a POSIX shell does, without running one: blanks
/// separate words; `'…'` is literal; `"…"` is literal except `\"`, `\\`, `\$` and `` \` ``;
/// outside quotes `\` escapes the next character. No expansion of any kind.
pub(crate) fn split_words(s: &str) -> Result<Vec<String>, String> {
    let mut words = Vec::new();
    let mut cur = String::new();
    let mut in_word = false;
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        match c {
            ' ' | '\t' | '\n' => {
                if in_word {
                    words.push(std::mem::take(&mut cur));
                    in_word = false;
                }
            }
            '\'' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => cur.push(c),
                        None => return Err("unterminated single quote".into()),
                    }
                }
            }
            '"' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\' | '$' | '`')) => cur.push(c),
                            Some(c) => {
                                cur.push('\\');
                                cur.push(c);
                            }
                            None => return Err("unterminated double quote".into()),
                        },
                        Some(c) => cur.push(c),
                        None => return Err("unterminated double quote".into()),
                    }
                }
            }
            '\\' => {
                in_word = true;
                match chars.next() {
                    Some(c) => cur.push(c),
                    None => return Err("a trailing backslash".into()),
                }
            }
            c => {
                in_word = true;
                cur.push(c);
            }
        }
    }
    if in_word {
        words.push(cur);
    }
    Ok(words)
}

/// The job file of one run (BENCHMARK.md).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Job {
    /// The suite's version ([`crate::grade::check::BENCHMARK`]; a chain scene's, the chain
    /// tier's [`crate::grade::chain::CHAIN_BENCHMARK`]).
    pub benchmark: &'static str,
    /// The scenario's name.
    pub scenario: String,
    /// Every field of the parameter file, friction family names included.
    pub params: serde_json::Value,
    /// Motor input voltage u (V); `null` when the scene's input changes in time (`input`).
    pub u: Option<f64>,
    /// The input u(t) as rows `[t, u]` (s, V) when it changes in time: linear between rows,
    /// constant before the first and after the last, two rows at one t a step; each row's
    /// time is a breakpoint. Absent for a constant input.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<Vec<[f64; 2]>>,
    /// Initial state, at full precision: `[α, ω_u, ω_l]` (rad, rad/s, rad/s) on the rig,
    /// `[α_1 … α_{N−1}, ω_1 … ω_N]` on a chain of N.
    pub x0: Vec<f64>,
    /// Horizon (s): the trace covers `[0, t_end]`.
    pub t_end: f64,
    /// Grid step of the trace (s): a row at every `k·dt`.
    pub dt: f64,
    /// Tolerance to run at, for a client with a tolerance knob (else `null`).
    pub tol: Option<f64>,
    /// Step to run at (s), for a fixed-step client (else `null`).
    pub h: Option<f64>,
    /// Where to write the trace (`t,alpha,omega_u,omega_l`; a chain's `t,alpha_1,…,omega_N`).
    pub trace: PathBuf,
    /// Where to write the events (`t,disc,kind`; a chain names discs `1` … `N`), if the
    /// client locates them.
    pub events: PathBuf,
}

impl Job {
    /// The job of a scene: the scenario's parameters, u (or its input rows) and x0 (absolute), the scene's
    /// horizon and grid, and the client's knob: `tol` set and `h` null, or the reverse.
    pub fn new(
        sc: &rotor_model::scenario::Scenario,
        t_end: f64,
        dt: f64,
        fixed_step: bool,
        setting: f64,
        trace: PathBuf,
        events: PathBuf,
    ) -> Job {
        Job {
            benchmark: crate::grade::check::BENCHMARK,
            scenario: sc.name.clone(),
            params: serde_json::to_value(sc.model.params).expect("plain numbers and strings"),
            u: sc.input.is_none().then_some(sc.u),
            input: sc
                .input
                .as_ref()
                .map(|i| i.rows().iter().map(|&(t, u)| [t, u]).collect()),
            x0: sc.x0.clone(),
            t_end,
            dt,
            tol: (!fixed_step).then_some(setting),
            h: fixed_step.then_some(setting),
            trace,
            events,
        }
    }

    /// The job of a chain scene (the chain tier): its parameters in chain form (`k_m` and the
    /// `disc` list), u or its input rows, x0 of 2N − 1 values, the scene's horizon and grid,
    /// and the client's knob; `benchmark` names the chain tier's version.
    pub fn for_chain(
        sc: &rotor_model::scenario::ChainScenario,
        fixed_step: bool,
        setting: f64,
        trace: PathBuf,
        events: PathBuf,
    ) -> Job {
        Job {
            benchmark: crate::grade::chain::CHAIN_BENCHMARK,
            scenario: sc.name.clone(),
            params: serde_json::to_value(&sc.params).expect("plain numbers and strings"),
            u: sc.input.is_none().then_some(sc.u),
            input: sc
                .input
                .as_ref()
                .map(|i| i.rows().iter().map(|&(t, u)| [t, u]).collect()),
            x0: sc.x0.clone(),
            t_end: sc.t_end,
            dt: sc.dt,
            tol: (!fixed_step).then_some(setting),
            h: fixed_step.then_some(setting),
            trace,
            events,
        }
    }

    /// The job file's text (numbers as the shortest decimal that reads back to the same
    /// double: x0 at full precision).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("plain numbers and strings")
    }
}

/// How a client's process ended.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Ended {
    /// It exited with this status.
    Exited(ExitStatus),
    /// It ran past the timeout and was killed with its process group.
    TimedOut,
}

/// One run of a client.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RunOutput {
    /// How the process ended.
    pub ended: Ended,
    /// From the spawn to the exit (or the kill) \[s\].
    pub wall_s: f64,
    /// Its standard output (the first MiB, lossily decoded).
    pub stdout: String,
    /// Its standard error (the first MiB, lossily decoded).
    pub stderr: String,
}

/// What the client printed on standard output: the last line that is a JSON object with
/// `solve_seconds` (and the optional `steps`, `rhs_evals`, `version`, `method`).
#[derive(Debug, Clone, Default, PartialEq, serde::Deserialize)]
pub struct ClientSays {
    /// Its in-process solve time (s), start-up excluded.
    pub solve_seconds: Option<f64>,
    /// The steps it took (a fixed-step client's are compared per step with Moreau–Jean).
    pub steps: Option<u64>,
    /// Its right-hand-side evaluations.
    pub rhs_evals: Option<u64>,
    /// Its version, as it reports it.
    pub version: Option<String>,
    /// Its method, as it names it (`DOP853`, `MoreauJeanOSI`, ...).
    pub method: Option<String>,
}

impl ClientSays {
    /// Reads the last JSON line with a positive, finite `solve_seconds`; an absent or
    /// unreadable line gives the default (no in-process time).
    pub fn from_stdout(out: &str) -> ClientSays {
        out.lines()
            .rev()
            .filter_map(|l| serde_json::from_str::<ClientSays>(l.trim()).ok())
            .find(|s| s.solve_seconds.is_some_and(|x| x > 0.0 && x.is_finite()))
            .unwrap_or_default()
    }
}

/// Keeps at most this many bytes of a client's standard output and error.
const KEEP: usize = 1 << 20;

fn drain(mut r: impl Read + Send + 'static) -> std::thread::JoinHandle<String> {
    std::thread::spawn(move || {
        let mut buf = Vec::new();
        let mut chunk = [0u8; 8192];
        while let Ok(n) = r.read(&mut chunk) {
            if n == 0 {
                break;
            }
            if buf.len() < KEEP {
                buf.extend_from_slice(&chunk[..n.min(KEEP - buf.len())]);
            }
        }
        String::from_utf8_lossy(&buf).into_owned()
    })
}

/// The thread-count variables of the usual BLAS and OpenMP runtimes. Every client runs with
/// each one set to 1 unless the bench's own environment sets it: the bench times
/// single-threaded solvers (the Rust ones are), and a 2 × 2 or 4 × 4 system gains nothing
/// from threads but loses to their start-up and spinning. Measured: Siconos 4.5's
/// `TimeStepping` on st-u2.5-rest at h = 1e-2 took 4.8 s with OpenBLAS's default threads
/// (1.9 s of it in the kernel, 576 507 `sched_yield` calls) and 1.2 s with one; scipy's
/// Radau and BDF and Octave's ode45 ran in the same CPU time either way.
pub const SINGLE_THREAD_ENV: [&str; 4] = [
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "BLIS_NUM_THREADS",
];

/// Runs `argv` with the job file's path appended, in its own process group, for at most
/// `timeout` seconds, with [`SINGLE_THREAD_ENV`] set to 1 where the bench's environment does
/// not set them. `Err` if it cannot be started.
pub(crate) fn run_client(argv: &[String], job: &Path, timeout: f64) -> Result<RunOutput, String> {
    let mut cmd = Command::new(&argv[0]);
    cmd.args(&argv[1..])
        .arg(job)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for var in SINGLE_THREAD_ENV {
        if std::env::var_os(var).is_none() {
            cmd.env(var, "1");
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        cmd.process_group(0);
    }
    let t0 = Instant::now();
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start {:?}: {e}", argv[0]))?;
    let pid = child.id();
    let out = drain(child.stdout.take().expect("piped"));
    let err = drain(child.stderr.take().expect("piped"));
    let (tx, rx) = mpsc::channel();
    let waiter = std::thread::spawn(move || {
        let status = child.wait();
        let _ = tx.send((status, t0.elapsed().as_secs_f64()));
    });
    let (ended, wall_s) = match rx.recv_timeout(Duration::from_secs_f64(timeout.max(0.0))) {
        Ok((Ok(status), wall)) => (Ended::Exited(status), wall),
        Ok((Err(e), _)) => return Err(format!("waiting for {:?}: {e}", argv[0])),
        Err(_) => {
            kill_group(pid);
            let _ = rx.recv();
            (Ended::TimedOut, t0.elapsed().as_secs_f64())
        }
    };
    let _ = waiter.join();
    // The process group is gone, so the pipes close once any grandchildren it left are
    // killed too (they were, with the group).
    let stdout = out.join().unwrap_or_default();
    let stderr = err.join().unwrap_or_default();
    Ok(RunOutput {
        ended,
        wall_s,
        stdout,
        stderr,
    })
}

/// SIGKILL to the whole process group of `pid` (the client and anything it started), by
/// the POSIX `kill` utility with a negative process id (the group id is the client's pid:
/// it was started with `process_group(0)`); no unsafe code.
fn kill_group(pid: u32) {
    let _ = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pid}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
}

/// The last `n` non-empty lines of a text, joined with " | " (for failure messages).
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_split_as_a_shell_splits_them() {
        let w = |s: &str| split_words(s).unwrap();
        assert_eq!(w("python3 client.py"), ["python3", "client.py"]);
        assert_eq!(w("  a   b\tc "), ["a", "b", "c"]);
        assert_eq!(
            w("julia --project='my dir' x.jl"),
            ["julia", "--project=my dir", "x.jl"]
        );
        assert_eq!(
            w(r#"sh -c "echo \"hi\" \$x""#),
            ["sh", "-c", r#"echo "hi" $x"#]
        );
        assert_eq!(w(r"a\ b c"), ["a b", "c"]);
        assert_eq!(w("''"), [""]);
        assert!(split_words("'open").is_err());
        assert!(split_words("\"open").is_err());
        assert!(split_words("end\\").is_err());
    }

    #[test]
    fn external_specs_name_the_bad_part() {
        let s = ClientSpec::parse("mine=python3 my client.py", &[]).unwrap();
        assert_eq!(s.name, "mine");
        assert_eq!(s.argv, ["python3", "my", "client.py"]);
        assert!(!s.fixed_step);
        assert!(
            ClientSpec::parse("stepper:h=./run", &[])
                .unwrap()
                .fixed_step
        );
        assert!(
            ClientSpec::parse("my_moreau=./run", &[])
                .unwrap()
                .fixed_step
        );
        assert!(
            ClientSpec::parse("x=./run", &["x".into()])
                .unwrap()
                .fixed_step
        );
        for (bad, needle) in [
            ("no-equals", "NAME=COMMAND"),
            ("=cmd", "must be non-empty"),
            ("a b=cmd", "without spaces"),
            ("x=", "empty"),
            ("x='oops", "unterminated"),
        ] {
            let e = ClientSpec::parse(bad, &[]).unwrap_err().as_flag();
            assert!(e.contains(needle), "{bad}: {e}");
        }
    }

    #[test]
    fn a_client_that_hangs_is_killed_with_its_children_at_the_timeout() {
        let dir = std::env::temp_dir();
        // The shell starts a grandchild that would outlive a kill of the shell alone.
        let argv: Vec<String> = ["sh", "-c", "sleep 30 & sleep 30; true"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let t = Instant::now();
        let r = run_client(&argv, &dir, 0.3).unwrap();
        assert_eq!(r.ended, Ended::TimedOut);
        // The pipes closed: the grandchild was killed with the group (else this would wait
        // for its 30 s).
        assert!(t.elapsed().as_secs_f64() < 10.0);
        let ok = run_client(
            &[
                "sh".into(),
                "-c".into(),
                "echo '{\"solve_seconds\": 0.25}'; exit 3".into(),
            ],
            &dir,
            10.0,
        )
        .unwrap();
        let Ended::Exited(st) = ok.ended else {
            panic!()
        };
        assert_eq!(st.code(), Some(3));
        assert_eq!(
            ClientSays::from_stdout(&ok.stdout).solve_seconds,
            Some(0.25)
        );
        assert!(run_client(&["/no/such/binary".into()], &dir, 1.0).is_err());
    }

    /// A client sees each thread-count variable as 1, or as the bench's environment sets
    /// it (the sh client prints them; the job path it is given is ignored).
    #[test]
    fn a_client_runs_single_threaded_unless_told_otherwise() {
        let script = SINGLE_THREAD_ENV
            .iter()
            .map(|v| format!("echo {v}=${{{v}:-unset}}"))
            .collect::<Vec<_>>()
            .join("; ");
        let argv: Vec<String> = vec!["sh".into(), "-c".into(), script];
        let r = run_client(&argv, &std::env::temp_dir(), 10.0).unwrap();
        for v in SINGLE_THREAD_ENV {
            let want = std::env::var(v).unwrap_or_else(|_| "1".into());
            assert!(
                r.stdout.lines().any(|l| l == format!("{v}={want}")),
                "{v}: {}",
                r.stdout
            );
        }
    }
}
