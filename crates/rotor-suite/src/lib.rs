//! The benchmark suite as one versioned, self-contained problem set: every scenario, parameter
//! set and reference file of `fixtures/`, embedded in whatever links this crate (the `rotor`
//! binary, the Python package), so that an installed binary or a wheel built elsewhere grades
//! a scenario by name from any directory.
//!
//! The suite's version is [`VERSION`], `rotorbench-1.0+<12 hex digits>`: the problem set's
//! name and the start of [`CHECKSUM`], the sha256 of every file of `fixtures/params`,
//! `fixtures/scenarios` and `fixtures/reference` concatenated in path order, which anyone can
//! recompute:
//!
//! ```sh
//! cat $(find fixtures/params fixtures/scenarios fixtures/reference -type f | LC_ALL=C sort) | sha256sum
//! ```
//!
//! Two results that name the same version were graded against the same problems and the
//! same reference data, byte for byte.
//!
//! The chain tier (chains of N discs, `fixtures/chain/{params,scenarios,reference}`) has its
//! own entry, [`CHAIN_VERSION`], `rotorbench-chain-1.0+<12 hex digits>` of [`CHAIN_CHECKSUM`]
//! (`cat $(find fixtures/chain -type f | LC_ALL=C sort) | sha256sum`): the rig's version does
//! not move when a chain scene is added, and a chain scene's verdict names the chain tier's.
//!
//! The loaders of the other crates read files, so [`locate`] gives a directory: the one
//! `$ROTORBENCH_FIXTURES` names, else the repository's own `fixtures/` when this crate was
//! built from a checkout that is still there, else the embedded files written once to a cache
//! directory named by the version (written to a temporary directory and renamed into place,
//! so an interrupted or concurrent extraction never leaves a partial suite).

#![warn(missing_docs)]

use std::path::{Path, PathBuf};

include!(concat!(env!("OUT_DIR"), "/suite.rs"));

/// The problem set's name, without the checksum.
pub const SUITE: &str = "rotorbench-1.0";

/// The suite's version: [`SUITE`] and the first 12 hex digits of [`CHECKSUM`].
pub const VERSION: &str = concat!("rotorbench-1.0+", env!("ROTORBENCH_CHECKSUM12"));

/// The chain tier's name, without the checksum.
pub const CHAIN_SUITE: &str = "rotorbench-chain-1.0";

/// The chain tier's version: [`CHAIN_SUITE`] and the first 12 hex digits of
/// [`CHAIN_CHECKSUM`].
pub const CHAIN_VERSION: &str =
    concat!("rotorbench-chain-1.0+", env!("ROTORBENCH_CHAIN_CHECKSUM12"));

/// The embedded suite's directory name in the cache: both tiers' versions, so that a change
/// to either is extracted afresh.
pub const CACHE_NAME: &str = concat!(
    "rotorbench-1.0+",
    env!("ROTORBENCH_CHECKSUM12"),
    "+chain-",
    env!("ROTORBENCH_CHAIN_CHECKSUM12")
);

/// Why the suite's directory cannot be given.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// `$ROTORBENCH_FIXTURES` names this path, which is not a directory.
    #[error("ROTORBENCH_FIXTURES = {0}: not a directory")]
    NotADirectory(PathBuf),
    /// `$ROTORBENCH_SUITE` is set to this, not to `embedded`.
    #[error("ROTORBENCH_SUITE = {0:?}: expected embedded (or unset)")]
    Choice(String),
    /// The embedded suite could not be written to the cache.
    #[error(
        "{path}: cannot write the embedded suite there ({source}); set ROTORBENCH_CACHE to a \
         writable directory, or ROTORBENCH_FIXTURES to a copy of the suite's fixtures/"
    )]
    Extract {
        /// The file or directory that could not be created, written or renamed into place.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

/// Where the suite's files were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `$ROTORBENCH_FIXTURES`.
    Environment,
    /// The `fixtures/` of the checkout this crate was built from.
    Checkout,
    /// The embedded files, written to the cache.
    Embedded,
}

impl Source {
    /// Where, in words for messages (`"ROTORBENCH_FIXTURES"`, `"the source checkout"`,
    /// `"embedded in this build"`).
    pub fn as_str(self) -> &'static str {
        match self {
            Source::Environment => "ROTORBENCH_FIXTURES",
            Source::Checkout => "the source checkout",
            Source::Embedded => "embedded in this build",
        }
    }
}

/// The suite's directory (holding `params/`, `scenarios/`, `reference/`, and the chain tier's
/// `chain/params/`, `chain/scenarios/`, `chain/reference/`) and where it came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Located {
    /// The directory holding `params/`, `scenarios/` and `reference/`.
    pub dir: PathBuf,
    /// Where it came from.
    pub source: Source,
}

/// The suite's directory: the embedded suite when `ROTORBENCH_SUITE=embedded` (to grade
/// against exactly this build's version, even inside a checkout), else `$ROTORBENCH_FIXTURES`,
/// else the checkout's `fixtures/`, else the embedded files in the cache (`$ROTORBENCH_CACHE`, else `$XDG_CACHE_HOME/rotorbench`, else
/// `~/.cache/rotorbench`, each in a directory named by [`CACHE_NAME`]).
pub fn locate() -> Result<Located, SuiteError> {
    match std::env::var("ROTORBENCH_SUITE").as_deref() {
        Ok("embedded") => {
            return Ok(Located {
                dir: extract(&cache_root())?,
                source: Source::Embedded,
            });
        }
        Ok(other) => return Err(SuiteError::Choice(other.to_owned())),
        Err(_) => {}
    }
    if let Some(dir) = std::env::var_os("ROTORBENCH_FIXTURES") {
        let dir = PathBuf::from(dir);
        if !dir.is_dir() {
            return Err(SuiteError::NotADirectory(dir));
        }
        return Ok(Located {
            dir,
            source: Source::Environment,
        });
    }
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    if checkout.join("scenarios").is_dir() {
        return Ok(Located {
            dir: checkout.canonicalize().unwrap_or(checkout),
            source: Source::Checkout,
        });
    }
    Ok(Located {
        dir: extract(&cache_root())?,
        source: Source::Embedded,
    })
}

/// The cache's root directory.
fn cache_root() -> PathBuf {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("ROTORBENCH_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("rotorbench")))
        .or_else(|| var("HOME").map(|d| d.join(".cache/rotorbench")))
        .unwrap_or_else(|| std::env::temp_dir().join("rotorbench-cache"))
}

/// Writes the embedded suite (both tiers) to `root/CACHE_NAME` unless it is there complete, and returns that
/// directory. The files go to a temporary sibling first, which is renamed into place: a
/// reader sees the whole suite or none of it.
pub fn extract(root: &Path) -> Result<PathBuf, SuiteError> {
    let target = root.join(CACHE_NAME);
    let complete = |d: &Path| d.join(".complete").is_file();
    if complete(&target) {
        return Ok(target);
    }
    let err = |path: &Path| {
        let path = path.to_owned();
        move |source| SuiteError::Extract { path, source }
    };
    let tmp = root.join(format!(".{CACHE_NAME}.{}.tmp", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    for (rel, bytes) in FILES.iter().chain(CHAIN_FILES) {
        let path = tmp.join(rel);
        let parent = path.parent().expect("a file under a part");
        std::fs::create_dir_all(parent).map_err(err(parent))?;
        std::fs::write(&path, bytes).map_err(err(&path))?;
    }
    std::fs::write(tmp.join(".complete"), CACHE_NAME).map_err(err(&tmp))?;
    match std::fs::rename(&tmp, &target) {
        Ok(()) => Ok(target),
        // Another process put it there first (or an incomplete one is in the way).
        Err(e) => {
            let _ = std::fs::remove_dir_all(&tmp);
            if complete(&target) {
                Ok(target)
            } else {
                Err(err(&target)(e))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checkout() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
    }

    /// The files of a tier (`""` or `"chain/"`) in the checkout, sorted by path.
    fn on_disk(tier: &str) -> Vec<(String, Vec<u8>)> {
        let mut on_disk = Vec::new();
        for part in ["params", "scenarios", "reference"] {
            for e in std::fs::read_dir(checkout().join(format!("{tier}{part}"))).unwrap() {
                let p = e.unwrap().path();
                on_disk.push((
                    format!("{tier}{part}/{}", p.file_name().unwrap().to_str().unwrap()),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
        on_disk.sort();
        on_disk
    }

    /// Every file of the checkout's suite is embedded, byte for byte, each tier in its own
    /// list, and nothing else.
    #[test]
    fn the_embedded_suite_is_the_checkouts() {
        for (tier, files) in [("", FILES), ("chain/", CHAIN_FILES)] {
            let embedded: Vec<(String, Vec<u8>)> = files
                .iter()
                .map(|(r, b)| ((*r).to_owned(), b.to_vec()))
                .collect();
            let on_disk = on_disk(tier);
            assert_eq!(embedded.len(), on_disk.len(), "tier {tier:?}");
            assert!(
                embedded == on_disk,
                "an embedded file of tier {tier:?} differs from fixtures/"
            );
        }
        assert!(
            CHAIN_FILES
                .iter()
                .any(|(r, _)| *r == "chain/scenarios/chain3-u1.5-rest.toml")
        );
        assert!(
            FILES
                .iter()
                .any(|(r, _)| *r == "scenarios/t1-u1.5-rest.toml")
        );
        assert!(
            FILES
                .iter()
                .any(|(r, _)| *r == "reference/t1-u1.5-rest.csv")
        );
    }

    /// Each version names its tier's checksum, which is the sha256 of the tier's files in path
    /// order (recomputed here with the sha2 crate's one-shot digest, apart from the build
    /// script); the rig's covers no chain file.
    #[test]
    fn the_version_carries_the_checksum() {
        use sha2::Digest as _;
        for (files, checksum, version, suite) in [
            (FILES, CHECKSUM, VERSION, SUITE),
            (CHAIN_FILES, CHAIN_CHECKSUM, CHAIN_VERSION, CHAIN_SUITE),
        ] {
            let all: Vec<u8> = files.iter().flat_map(|(_, b)| b.iter().copied()).collect();
            let digest: String = sha2::Sha256::digest(&all)
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect();
            assert_eq!(checksum, digest);
            assert_eq!(version, format!("{suite}+{}", &digest[..12]));
            let paths: Vec<&str> = files.iter().map(|(r, _)| *r).collect();
            assert!(paths.windows(2).all(|w| w[0].as_bytes() < w[1].as_bytes()));
        }
        assert!(FILES.iter().all(|(r, _)| !r.starts_with("chain/")));
        assert!(CHAIN_FILES.iter().all(|(r, _)| r.starts_with("chain/")));
        assert_eq!(
            CACHE_NAME,
            format!("{VERSION}+chain-{}", &CHAIN_CHECKSUM[..12])
        );
    }

    /// Extraction writes the whole suite once, then finds it complete; a leftover partial
    /// directory in the way is not taken for the suite.
    #[test]
    fn extraction_is_whole_and_reused() {
        let root = std::env::temp_dir().join(format!("rotor-suite-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let dir = extract(&root).unwrap();
        assert_eq!(dir, root.join(CACHE_NAME));
        for (rel, bytes) in FILES.iter().chain(CHAIN_FILES) {
            assert_eq!(&std::fs::read(dir.join(rel)).unwrap()[..], *bytes, "{rel}");
        }
        // Reused as it is: a marker written into it survives a second call.
        std::fs::write(dir.join("marker"), "x").unwrap();
        assert_eq!(extract(&root).unwrap(), dir);
        assert!(dir.join("marker").is_file());
        // An incomplete directory (no .complete) is refused, not used.
        std::fs::remove_file(dir.join(".complete")).unwrap();
        assert!(matches!(extract(&root), Err(SuiteError::Extract { .. })));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
