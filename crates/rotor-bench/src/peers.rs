//! The repository's own peers, bench/peers/scipy_rotor.py (scipy `solve_ivp`, DOP853 with
//! event functions; also as `scipy-radau`, `scipy-bdf`, `scipy-lsoda` with `--method`),
//! bench/peers/siconos_rotor.py (Siconos `MoreauJeanOSI`) and bench/peers/octave_rotor.m
//! (GNU Octave's `ode45` with event functions, restarted at every mode switch): clients of
//! the same job-file protocol as any external solver, run when their interpreter imports
//! the library (Octave: when it has `ode45` and `jsondecode`).

use std::process::Command;

use crate::clients::{ClientReport, ClientStatus};
use crate::options::BenchOptions;
use rotor_protocol::ClientSpec;

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

/// The command line that starts the Octave peer's launcher, before the job file: no start-up
/// files, no banner, no history (Octave 7 reports an error at exit when it cannot save it).
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
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )),
        Err(e) => Err(format!("cannot run `{octave}`: {e}")),
    }
}

/// A peer to run: its client spec and ladder, or the report of a peer that is skipped.
pub(crate) type PeerLaunch = Result<(ClientSpec, Vec<f64>), Box<ClientReport>>;

/// The peers the options ask for, each with its ladder, or skipped with the reason.
pub(crate) fn peers(opts: &BenchOptions, progress: &mut impl FnMut(&str)) -> Vec<PeerLaunch> {
    let p = &opts.peers;
    let specs = [
        (
            "scipy",
            p.scipy,
            &p.python,
            "scipy",
            "scipy_rotor.py",
            false,
            &p.scipy_tols,
        ),
        (
            "scipy-radau",
            p.scipy && !p.scipy_method_tols.is_empty(),
            &p.python,
            "scipy",
            "scipy_rotor.py --method Radau",
            false,
            &p.scipy_method_tols,
        ),
        (
            "scipy-bdf",
            p.scipy && !p.scipy_method_tols.is_empty(),
            &p.python,
            "scipy",
            "scipy_rotor.py --method BDF",
            false,
            &p.scipy_method_tols,
        ),
        (
            "scipy-lsoda",
            p.scipy && !p.scipy_method_tols.is_empty(),
            &p.python,
            "scipy",
            "scipy_rotor.py --method LSODA",
            false,
            &p.scipy_method_tols,
        ),
        (
            "siconos",
            p.siconos,
            &p.siconos_python,
            "siconos.kernel",
            "siconos_rotor.py",
            true,
            &p.siconos_hs,
        ),
    ];
    let mut launches: Vec<PeerLaunch> = specs
        .into_iter()
        .map(|(name, on, python, module, script, fixed_step, ladder)| {
            // The script, then its own arguments (`--method M`).
            let mut words = script.split(' ');
            let script = words.next().unwrap_or_default();
            let mut argv = vec![python.clone(), p.dir.join(script).display().to_string()];
            argv.extend(words.map(str::to_owned));
            let spec = ClientSpec {
                name: name.into(),
                argv,
                fixed_step,
                peer: true,
            };
            if !on {
                return Err(Box::new(ClientReport::skipped(
                    &spec,
                    ClientStatus::Skipped,
                    "turned off in the options".into(),
                )));
            }
            if let Err(why) = available(python, module) {
                progress(&format!("{name} peer skipped: {why}"));
                return Err(Box::new(ClientReport::skipped(
                    &spec,
                    ClientStatus::Skipped,
                    why,
                )));
            }
            Ok((spec, ladder.clone()))
        })
        .collect();
    launches.push(octave(p, progress));
    launches
}

/// The Octave peer (`octave-cli ... bench/peers/octave_rotor_cli.m JOB`), or its skip.
fn octave(p: &crate::options::PeerOptions, progress: &mut impl FnMut(&str)) -> PeerLaunch {
    let mut argv = octave_argv(&p.octave_cli);
    argv.push(p.dir.join("octave_rotor_cli.m").display().to_string());
    let spec = ClientSpec {
        name: "octave".into(),
        argv,
        fixed_step: false,
        peer: true,
    };
    let skip = |why: String| {
        Err(Box::new(ClientReport::skipped(
            &spec,
            ClientStatus::Skipped,
            why,
        )))
    };
    if !p.octave {
        return skip("turned off in the options".into());
    }
    if let Err(why) = octave_available(&p.octave_cli) {
        progress(&format!("octave peer skipped: {why}"));
        return skip(why);
    }
    Ok((spec.clone(), p.octave_tols.clone()))
}
