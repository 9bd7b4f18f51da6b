//! Embeds the suite: every file of `fixtures/params`, `fixtures/scenarios` and
//! `fixtures/reference`, with the sha256 of their concatenation in path order (the suite's
//! checksum, as `cat $(find fixtures/params fixtures/scenarios fixtures/reference -type f |
//! LC_ALL=C sort) | sha256sum` prints it); and the chain tier's files under `fixtures/chain/`
//! with their own checksum, computed the same way over `fixtures/chain`.

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
    let mut code = String::new();
    let rig = embed(&root, "", "FILES", "CHECKSUM", &mut code);
    let chain = embed(&root, "chain/", "CHAIN_FILES", "CHAIN_CHECKSUM", &mut code);
    let out = Path::new(&std::env::var("OUT_DIR").unwrap()).join("suite.rs");
    std::fs::write(out, code).unwrap();
    println!("cargo:rustc-env=ROTORBENCH_CHECKSUM12={}", &rig[..12]);
    println!(
        "cargo:rustc-env=ROTORBENCH_CHAIN_CHECKSUM12={}",
        &chain[..12]
    );
}

/// Appends to `code` the static `files` (every file of `<tier>params`, `<tier>scenarios`,
/// `<tier>reference` under `root`, in path order) and the const `checksum`, the sha256 of
/// their bytes concatenated in that order, which it returns.
fn embed(
    root: &Path,
    tier: &str,
    files_name: &str,
    checksum_name: &str,
    code: &mut String,
) -> String {
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for part in PARTS {
        let dir = root.join(format!("{tier}{part}"));
        println!("cargo:rerun-if-changed={}", dir.display());
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            if path.is_file() {
                let name = path.file_name().unwrap().to_str().unwrap().to_owned();
                files.push((format!("{tier}{part}/{name}"), path));
            }
        }
    }
    // `fixtures/<rel>` in byte order, as `LC_ALL=C sort` orders the paths.
    files.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut sha = Sha256::new();
    writeln!(
        code,
        "/// Every file of the {} its path under `fixtures/` and its bytes.",
        if tier.is_empty() {
            "suite's rig tier:"
        } else {
            "suite's chain tier:"
        }
    )
    .unwrap();
    writeln!(code, "pub static {files_name}: &[(&str, &[u8])] = &[").unwrap();
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
        "/// sha256 of these files concatenated in path order.\npub const {checksum_name}: &str = {digest:?};"
    )
    .unwrap();
    digest
}
