//! `rotor`: the command-line front end (its contract: docs/design.md, "The CLI"). Each
//! command is a module of [`cmd`] (its flags and its `run`); what they share is in
//! [`common`]; the main job's report is assembled by the `rotor_harness::report` crate.

use std::path::Path;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::common::threads_arg;

mod cmd;
mod common;
mod out;

/// Two-disc rotor with set-valued friction: three independent solvers, cross-validated.
#[derive(Parser, Debug)]
#[command(name = "rotor", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Threads of the main job (no subcommand; default: SLURM_CPUS_PER_TASK when set, else
    /// the cores available to the process). The subcommands that run in parallel take their
    /// own `--threads`.
    #[arg(long, value_name = "N", value_parser = threads_arg)]
    threads: Option<usize>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate one scene and write the trajectory as CSV (t,alpha,omega_u,omega_l).
    Simulate(cmd::simulate::Args),
    /// Run to steady state and print it as one JSON object. It takes no --t-end or --dt: it
    /// runs as long as its answer needs, and prints one state, not a trace.
    Steady(cmd::steady::Args),
    /// Bifurcation diagram over u: equilibria, periodic branches with Floquet multipliers,
    /// special points (Hopf, grazing, folds), as JSON, and optionally CSV and an SVG figure.
    Bifurcation(cmd::bifurcation::Args),
    /// Two-parameter analysis: every codimension-one point of the u-diagram (Hopf, grazing,
    /// folds, the stuck boundary) continued in (p, u), and the codimension-two points where
    /// the curves change type, turn, end or cross; JSON, and an SVG of the plane.
    Bifurcation2(cmd::bifurcation2::Args),
    /// Brute force over a (u, p) grid: every point's steady state (metrics only), one CSV row
    /// per point (u,p,kind,period,omega_l_max,omega_l_min,stick_time), written as it goes.
    Sweep(cmd::sweep::Args),
    /// Join sweep shards into exactly what one unsharded run writes.
    Merge(cmd::merge::Args),
    /// Work-precision benchmark: each solver over a ladder of tolerances / steps, error
    /// against a tight reference, median run time, counters; peers (scipy, Siconos, Octave)
    /// side by side when installed. Prints a table.
    Bench(cmd::bench::Args),
    /// Print the job file `rotor bench` hands an external client for a scenario (its own
    /// horizon and grid, as with `bench --scenario`), x0 at full precision (BENCHMARK.md).
    /// One of --tol and --h is required: it says which knob the client has.
    Job(cmd::job::Args),
    /// List the benchmark suite: every scenario with its tier (table1: only the lower disc
    /// sticks; full: both may), what it tests, and the suite's version.
    Scenarios(cmd::scenarios::Args),
    /// Write the benchmark's reference data for every scenario (or the --scenario ones):
    /// trace, events and steady state of the event-driven solver, with their stated errors,
    /// into --out DIR or the current directory (the checkout's own: --out
    /// fixtures/reference). About 3 s for the whole suite on 2 cores.
    Reference(cmd::reference::Args),
    /// Grade one trace (CSV t,alpha,omega_u,omega_l on the scenario's grid) against the
    /// reference with the scenario's own gates. Exit 0: every gate passes; 1: a gate fails;
    /// 2: the input is unusable.
    Check(cmd::check::Args),
    /// Run scenarios through the three solvers, gate their agreement, write the report.
    Compare(cmd::compare::Args),
}

impl Command {
    /// The subcommand's name on the command line.
    fn name(&self) -> &'static str {
        use Command::*;
        match self {
            Simulate(_) => "simulate",
            Steady(_) => "steady",
            Bifurcation(_) => "bifurcation",
            Bifurcation2(_) => "bifurcation2",
            Sweep(_) => "sweep",
            Merge(_) => "merge",
            Bench(_) => "bench",
            Job(_) => "job",
            Scenarios(_) => "scenarios",
            Reference(_) => "reference",
            Check(_) => "check",
            Compare(_) => "compare",
        }
    }

    /// Whether it runs in parallel (and takes `--threads`).
    fn parallel(&self) -> bool {
        use Command::*;
        matches!(self, Sweep(_) | Reference(_) | Compare(_))
    }

    /// The output files the command writes, with their flags (directories it creates, as
    /// `compare --report` and `reference --out`, are not listed).
    fn outputs(&self) -> Vec<(&'static str, &Path)> {
        use Command::*;
        let (csv, json, svg) = match self {
            Simulate(a) => (Some(&a.csv), None, None),
            Sweep(a) => (Some(&a.csv), None, None),
            Merge(a) => (Some(&a.csv), None, None),
            Bifurcation(a) => (a.csv.as_ref(), Some(&a.json), a.svg.as_ref()),
            Bifurcation2(a) => (None, Some(&a.json), a.svg.as_ref()),
            Bench(a) => (a.csv.as_ref(), a.json.as_ref(), a.svg.as_ref()),
            Check(a) => (None, a.json.as_ref(), None),
            Scenarios(a) => (None, a.json.as_ref(), None),
            Steady(_) | Compare(_) | Reference(_) | Job(_) => (None, None, None),
        };
        let results = match self {
            Bench(a) => a.results.as_ref(),
            _ => None,
        };
        [
            ("--csv", csv),
            ("--json", json),
            ("--svg", svg),
            ("--results", results),
        ]
        .into_iter()
        .filter_map(|(flag, p)| Some((flag, p?.as_path())))
        .collect()
    }
}

/// The commands that need a constant input (their answers are steady states of a
/// time-invariant system): `--input` given to one of them is refused, naming it, before
/// clap would report only a missing required argument.
const CONSTANT_INPUT_ONLY: [&str; 3] = ["bifurcation", "bifurcation2", "sweep"];

/// The refusal of `--input` for a [`CONSTANT_INPUT_ONLY`] command in `args` (the program's
/// arguments after its name), if any.
fn refused_input(args: &[String]) -> Option<String> {
    let cmd = args.iter().find(|a| !a.starts_with('-'))?;
    if !CONSTANT_INPUT_ONLY.contains(&cmd.as_str()) {
        return None;
    }
    let given = args
        .iter()
        .any(|a| a == "--input" || a.starts_with("--input="));
    given.then(|| {
        format!(
            "--input: {cmd} needs a constant input (its answers are steady states of a \
             time-invariant system); `rotor simulate --input` runs a time-varying one"
        )
    })
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args_os()
        .skip(1)
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    if let Some(msg) = refused_input(&args) {
        eprintln!("error: {msg}");
        return ExitCode::from(2);
    }
    let cli = Cli::parse();
    // `rotor --threads N` is the main job's; a subcommand takes its own after its name.
    if cli.threads.is_some()
        && let Some(cmd) = &cli.command
    {
        eprintln!(
            "error: --threads before the subcommand sets the main job's threads; give it after \
             the subcommand's name (rotor {} ... --threads N){}",
            cmd.name(),
            if cmd.parallel() {
                ""
            } else {
                ", which runs on one thread and takes no --threads"
            }
        );
        return ExitCode::from(2);
    }
    // Outputs that cannot be written are refused before any work: unusable input (exit 2).
    if let Some(cmd) = &cli.command
        && let Err(e) = cmd
            .outputs()
            .into_iter()
            .try_for_each(|(f, p)| out::writable(f, p))
    {
        eprintln!("error: {e:#}");
        return ExitCode::from(2);
    }
    let res = match &cli.command {
        Some(Command::Simulate(a)) => cmd::simulate::run(a),
        Some(Command::Steady(a)) => cmd::steady::run(a),
        Some(Command::Bifurcation(a)) => cmd::bifurcation::run(a),
        Some(Command::Bifurcation2(a)) => cmd::bifurcation2::run(a),
        Some(Command::Sweep(a)) => cmd::sweep::run(a),
        Some(Command::Merge(a)) => cmd::merge::run(a),
        Some(Command::Bench(a)) => cmd::bench::run(a),
        Some(Command::Job(a)) => cmd::job::run(a),
        Some(Command::Scenarios(a)) => cmd::scenarios::run(a),
        Some(Command::Reference(a)) => cmd::reference::run(a),
        Some(Command::Check(a)) => return cmd::check::run(a),
        Some(Command::Compare(a)) => cmd::compare::run(a),
        None => cmd::compare::main_job(cli.threads),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output has gone: stop quietly, as a Unix tool does.
        Err(e) if out::is_closed_pipe(&e) => ExitCode::SUCCESS,
        // One convention for every command (README, "Exit status"): 0 done, 1 the run
        // failed (a solver, a gate, a client), 2 the input is unusable (what clap refuses
        // while parsing, and a value or file refused after it).
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(common::exit_code(&e))
        }
    }
}
