//! Prints the special points of the bifurcation diagram of a parameter file, and optionally
//! writes the JSON and CSV: `cargo run --release -p rotor-analysis --example explore --
//! fixtures/params/table1.toml [n] [out.json] [out.csv] [out.svg]`.
use rotor_analysis::bifurcation::{DiagramOptions, diagram};
use rotor_model::{Model, Params};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .map_or("fixtures/params/table1.toml", |s| s.as_str());
    let n: usize = args.get(2).map_or(200, |s| s.parse().expect("n"));
    let model = Model::new(Params::from_file(std::path::Path::new(path)).expect("params"));
    let t = std::time::Instant::now();
    let d = diagram(
        &model,
        &DiagramOptions {
            n,
            ..Default::default()
        },
    )
    .expect("diagram");
    eprintln!("{:?}, {} periodic orbits", t.elapsed(), d.periodic.len());
    for p in &d.points {
        println!(
            "{:<17} u = {:.12}  residual {:>9}  {}",
            p.kind,
            p.u,
            p.residual.map(|r| format!("{r:.1e}")).unwrap_or_default(),
            p.detail
        );
    }
    // Each file is complete in memory before it is written, through a temporary file and a
    // rename: a failure or an interruption leaves no partial file.
    let write = |path: &str, bytes: &[u8]| {
        let tmp = format!("{path}.tmp{}", std::process::id());
        std::fs::write(&tmp, bytes).expect("write");
        std::fs::rename(&tmp, path).expect("rename");
    };
    if let Some(j) = args.get(3) {
        write(j, d.to_json().expect("json").as_bytes());
    }
    if let Some(s) = args.get(5) {
        write(s, d.to_svg(path).as_bytes());
    }
    if let Some(c) = args.get(4) {
        let mut csv = Vec::new();
        d.write_csv(&mut csv).expect("csv");
        write(c, &csv);
    }
}
