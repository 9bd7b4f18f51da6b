//! Runs the benchmark and writes the report until `rotor bench` exists:
//! `cargo run --release -p rotor-bench --example bench -- [--quick] [--out DIR]`
//! (DIR gets bench.json, bench.csv, bench.svg and bench.txt; the table goes to stdout).

use std::path::PathBuf;

use rotor_bench::{BenchOptions, run};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut opts = if args.iter().any(|a| a == "--quick") {
        BenchOptions::quick()
    } else {
        BenchOptions::default()
    };
    if args.iter().any(|a| a == "--no-peers") {
        opts.peers.scipy = false;
        opts.peers.siconos = false;
    }
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from);
    let report = match run(&opts, |m| eprintln!("{m}")) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let table = report.table();
    print!("{table}");
    if let Some(dir) = out {
        let write = |name: &str, text: String| {
            let p = dir.join(name);
            if let Err(e) = std::fs::write(&p, text) {
                eprintln!("error: cannot write {}: {e}", p.display());
                std::process::exit(1);
            }
        };
        if let Err(e) = std::fs::create_dir_all(&dir) {
            eprintln!("error: cannot create {}: {e}", dir.display());
            std::process::exit(1);
        }
        write("bench.json", report.to_json());
        write("bench.csv", report.to_csv());
        write("bench.svg", report.to_svg());
        write("bench.txt", table);
    }
}
