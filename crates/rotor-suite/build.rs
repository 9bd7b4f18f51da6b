//! Embeds the suite: every file of `fixtures/params`, `fixtures/scenarios` and
//! `fixtures/reference`, with the sha256 of their concatenation in path order (the suite's
//! checksum, as `cat $(find fixtures/params fixtures/scenarios fixtures/reference -type f |
//! LC_ALL=C sort) | sha256sum` prints it).

use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const PARTS: [&str; 3] = ["params", "scenarios", "reference"];

fn main() {
    let root = Path::new(&std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("../../fixtures");
    let root = root.canonicalize().unwrap_or_else(|e| {
        panic!(
            "{}: the suite's fixtures are not there ({e}); rotor-suite builds from the \
             repository's checkout",
            root.display()
        )
    });
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for part in PARTS {
        let dir = root.join(part);
        println!("cargo:rerun-if-changed={}", dir.display());
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            if path.is_file() {
                let name = path.file_name().unwrap().to_str().unwrap().to_owned();
                files.push((format!("{part}/{name}"), path));
            }
        }
    }
    // `fixtures/<rel>` in byte order, as `LC_ALL=C sort` orders the paths.
    files.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut sha = Sha256::new();
    let mut code =
        String::from("/// Every file of the suite: its path under `fixtures/` and its bytes.\n");
    code.push_str("pub static FILES: &[(&str, &[u8])] = &[\n");
    for (rel, path) in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        sha.update(std::fs::read(path).unwrap());
        writeln!(
            code,
            "    ({rel:?}, include_bytes!({:?})),",
            path.display().to_string()
        )
        .unwrap();
    }
    code.push_str("];\n");
    let digest: String = sha.finalize().iter().map(|b| format!("{b:02x}")).collect();
    writeln!(
        code,
        "/// sha256 of the suite's files concatenated in path order.\npub const CHECKSUM: &str = {digest:?};"
    )
    .unwrap();
    let out = Path::new(&std::env::var("OUT_DIR").unwrap()).join("suite.rs");
    std::fs::write(out, code).unwrap();
    println!("cargo:rustc-env=ROTORBENCH_CHECKSUM12={}", &digest[..12]);
}
