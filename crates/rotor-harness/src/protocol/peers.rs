//! The repository's own clients of the protocol, its peers: bench/peers/scipy_rotor.py (scipy
//! `solve_ivp`, DOP853 with event functions; also as `scipy-radau`, `scipy-bdf`,
//! `scipy-lsoda` with `--method`), bench/peers/siconos_rotor.py (Siconos `MoreauJeanOSI`)
//! and bench/peers/octave_rotor.m (GNU Octave's `ode45` with event functions, restarted at
//! every mode switch). Each is started like any external solver; this module knows their
//! command lines and how to tell whether their interpreter can run them. Which of them a
//! benchmark runs, and at which settings, is the benchmark's choice.

use std::path::Path;
use std::process::Command;

use crate::protocol::ClientSpec;

/// What runs a peer's script.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpreter {
    /// A Python interpreter that must import `module`.
    Python {
        /// The module the script needs (`scipy`, `siconos.kernel`).
        module: &'static str,
    },
    /// GNU Octave's command-line interpreter, version 7 or later.
    Octave,
}

/// One peer: its name in reports, what runs it, its script and the script's own arguments,
/// and its knob.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Peer {
    /// Its name in the report.
    pub name: &'static str,
    /// What runs its script.
    pub interpreter: Interpreter,
    /// The script in the peers' directory.
    pub script: &'static str,
    /// The script's own arguments, before the job file.
    pub args: &'static [&'static str],
    /// Whether its knob is a step h rather than a tolerance.
    pub fixed_step: bool,
}

/// Every peer of the repository, in report order.
pub(crate) const PEERS: [Peer; 6] = [
    Peer {
        name: "scipy",
        interpreter: Interpreter::Python { module: "scipy" },
        script: "scipy_rotor.py",
        args: &[],
        fixed_step: false,
    },
    Peer {
        name: "scipy-radau",
        interpreter: Interpreter::Python { module: "scipy" },
        script: "scipy_rotor.py",
        args: &["--method", "Radau"],
        fixed_step: false,
    },
    Peer {
        name: "scipy-bdf",
        interpreter: Interpreter::Python { module: "scipy" },
        script: "scipy_rotor.py",
        args: &["--method", "BDF"],
        fixed_step: false,
    },
    Peer {
        name: "scipy-lsoda",
        interpreter: Interpreter::Python { module: "scipy" },
        script: "scipy_rotor.py",
        args: &["--method", "LSODA"],
        fixed_step: false,
    },
    Peer {
        name: "siconos",
        interpreter: Interpreter::Python {
            module: "siconos.kernel",
        },
        script: "siconos_rotor.py",
        args: &[],
        fixed_step: true,
    },
    Peer {
        name: "octave",
        interpreter: Interpreter::Octave,
        // The launcher that reads the job file's path from Octave's argument list.
        script: "octave_rotor_cli.m",
        args: &[],
        fixed_step: false,
    },
];

impl Peer {
    /// Its client: `program` (the Python or Octave interpreter) with the script in `dir` and
    /// the script's arguments; the job file's path is appended at each run.
    pub fn spec(&self, program: &str, dir: &Path) -> ClientSpec {
        let mut argv = match self.interpreter {
            Interpreter::Python { .. } => vec![program.to_owned()],
            Interpreter::Octave => octave_argv(program),
        };
        argv.push(dir.join(self.script).display().to_string());
        argv.extend(self.args.iter().map(|a| (*a).to_owned()));
        ClientSpec {
            name: self.name.into(),
            argv,
            fixed_step: self.fixed_step,
            peer: true,
        }
    }

    /// Whether `program` can run it; the error says why not.
    pub fn available(&self, program: &str) -> Result<(), String> {
        match self.interpreter {
            Interpreter::Python { module } => available(program, module),
            Interpreter::Octave => octave_available(program),
        }
    }
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
            last_line(&o.stderr)
        )),
        Err(e) => Err(format!("cannot run `{python}`: {e}")),
    }
}

/// The command line that starts Octave before a script: no start-up files, no banner, no
/// history (Octave 7 reports an error at exit when it cannot save it).
fn octave_argv(octave: &str) -> Vec<String> {
    [octave, "--norc", "--quiet", "--no-history"]
        .map(String::from)
        .to_vec()
}

/// Whether `octave` runs and has what the Octave peer needs (`ode45`, and `jsondecode`,
/// which came with GNU Octave 7); the error says why not.
pub fn octave_available(octave: &str) -> Result<(), String> {
    let probe = "if exist('ode45') && exist('jsondecode'), exit(0); end; \
                 fputs(stderr, 'no ode45 or no jsondecode: GNU Octave >= 7 is needed'); exit(1);";
    match Command::new(octave)
        .args(octave_argv(octave).into_iter().skip(1))
        .args(["--eval", probe])
        .output()
    {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(format!(
            "`{octave}` cannot run the Octave peer: {}",
            last_line(&o.stderr)
        )),
        Err(e) => Err(format!("cannot run `{octave}`: {e}")),
    }
}

/// The last line of a probe's standard error.
fn last_line(stderr: &[u8]) -> String {
    String::from_utf8_lossy(stderr)
        .lines()
        .last()
        .unwrap_or("")
        .to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_are_the_script_in_the_directory_then_its_arguments() {
        let dir = Path::new("/p");
        let radau = PEERS.iter().find(|p| p.name == "scipy-radau").unwrap();
        assert_eq!(
            radau.spec("python3", dir).argv,
            ["python3", "/p/scipy_rotor.py", "--method", "Radau"]
        );
        let octave = PEERS.iter().find(|p| p.name == "octave").unwrap();
        assert_eq!(
            octave.spec("octave-cli", dir).argv,
            [
                "octave-cli",
                "--norc",
                "--quiet",
                "--no-history",
                "/p/octave_rotor_cli.m"
            ]
        );
        let siconos = PEERS.iter().find(|p| p.name == "siconos").unwrap();
        assert!(siconos.spec("python3", dir).fixed_step && siconos.spec("python3", dir).peer);
    }

    #[test]
    fn a_missing_interpreter_is_named() {
        let e = available("/nonexistent/python", "scipy").unwrap_err();
        assert!(e.contains("cannot run `/nonexistent/python`"), "{e}");
        let e = octave_available("/nonexistent/octave").unwrap_err();
        assert!(e.contains("cannot run `/nonexistent/octave`"), "{e}");
    }
}
