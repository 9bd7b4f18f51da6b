//! The speeds `rotor steady` and `rotor bifurcation` aim at, as whole processes (a benchmark, not a test: these machines'
//! timings move by ±15 %, and more when the cores are shared).
//!
//! ```sh
//! cargo bench -p rotor-cli --bench steady              # steady next to H1, bifurcation
//! ROTOR_BENCH_MAIN=1 cargo bench -p rotor-cli --bench steady   # and the main job
//! ```
//!
//! * `rotor bifurcation --solver S` on Table 1 over u ∈ [0, 7] (the command's defaults), for
//!   every solver: the median wall time of 3 processes and their mean CPU time;
//! * `rotor steady --solver S --u V` at 1e-4 V above Table 1's first Hopf point H1, from
//!   rest, for every solver, by `--method shoot`, by the default (checked shooting, falling
//!   back to simulation when the check refuses) and by `--method simulate`: the median wall
//!   time of 5 processes each for shoot and the default, `simulate` (the slow transient next
//!   to H1) once; and the CPU time (user + system) of each, summed over its processes;
//! * with `ROTOR_BENCH_MAIN=1`, the main job (`rotor` with no arguments) once, in a temporary
//!   directory (the embedded suite; the report goes there): its wall time and the CPU time
//!   of the process tree (`/proc/self` children's utime + stime after it ends, on Linux).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use rotor_model::Model;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median wall time of `n` processes, which must succeed, and their mean CPU time (user +
/// system; `NaN` where `/proc` is not there).
fn timed(bin: &Path, args: &[&str], dir: &Path, n: usize) -> (f64, f64) {
    let c0 = children_cpu();
    let w = median((0..n).map(|_| run(bin, args, dir)).collect());
    let cpu = children_cpu()
        .zip(c0)
        .map_or(f64::NAN, |(a, b)| (a - b) / n as f64);
    (w, cpu)
}

/// Wall time of one process, which must succeed.
fn run(bin: &Path, args: &[&str], dir: &Path) -> f64 {
    let t0 = Instant::now();
    let st = Command::new(bin)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("rotor starts");
    let t = t0.elapsed().as_secs_f64();
    assert!(st.success(), "rotor {args:?} failed");
    t
}

/// CPU seconds (user + system) of this process's waited-for children so far, from
/// `/proc/self/stat` (fields 16 and 17, cutime and cstime, in clock ticks of 100 Hz).
fn children_cpu() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // Fields after the name start at field 3; cutime is field 16, cstime 17.
    let cu: f64 = f.get(13)?.parse().ok()?;
    let cs: f64 = f.get(14)?.parse().ok()?;
    Some((cu + cs) / 100.0)
}

fn main() {
    let bin = Path::new(env!("CARGO_BIN_EXE_rotor"));
    let dir = rotor_testkit::tmp_dir("rotor-steady-bench");
    let h1 = rotor_analysis::bifurcation::equilibria::hopf_points(&Model::table1(), 20.0)[0]
        .equilibrium
        .u;
    let u = format!("{}", h1 + 1e-4);
    println!(
        "rotor steady at u = {u} V (1e-4 V above H1), from rest; wall (median of 5; simulate \
         once) and CPU per process:"
    );
    for solver in ["event", "switch", "moreau"] {
        let base = ["steady", "--solver", solver, "--u", &u];
        let shoot: Vec<&str> = [&base[..], &["--method", "shoot"]].concat();
        let simulate: Vec<&str> = [&base[..], &["--method", "simulate"]].concat();
        let (s, sc) = timed(bin, &shoot, &dir, 5);
        let (d, dc) = timed(bin, &base, &dir, 5);
        let (m, mc) = timed(bin, &simulate, &dir, 1);
        println!(
            "  {solver:<7} shoot {s:>7.3} s ({sc:.3} s CPU)   default {d:>7.3} s ({dc:.3} s CPU)   \
             simulate {m:>7.3} s ({mc:.3} s CPU)"
        );
    }
    println!("rotor bifurcation, Table 1, u in [0, 7]; wall (median of 3) and CPU per process:");
    let json = dir.join("diagram.json");
    let json = json.to_str().expect("a UTF-8 temporary path");
    for solver in ["event", "switch", "moreau"] {
        let (w, c) = timed(
            bin,
            &["bifurcation", "--solver", solver, "--json", json],
            &dir,
            3,
        );
        println!("  {solver:<7} {w:>7.3} s ({c:.3} s CPU)");
    }
    if std::env::var_os("ROTOR_BENCH_MAIN").is_some() {
        let c0 = children_cpu();
        let w = run(bin, &[], &dir);
        let cpu = children_cpu().zip(c0).map(|(a, b)| a - b);
        println!(
            "main job: {w:.1} s wall, {} CPU (user + system)",
            cpu.map_or("?".into(), |c| format!("{c:.1} s"))
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
