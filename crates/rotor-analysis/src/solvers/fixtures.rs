//! Fixture files given by name (`stribeck`, `t1-u1.5-rest`), as the command line and the
//! Python package both take them.

use std::path::{Path, PathBuf};

/// The file a path argument names. `p` itself if it is a file; else, for a plain name (one
/// path component), `dir/<p>.toml` if that is a file; else `p` if it exists at all (a
/// directory, `/dev/zero`: its loader says what is wrong with it) or is more than a plain
/// name (its loader says that it is missing). `None`: a plain name that is neither a file
/// nor a fixture of `dir` (with no `dir`, none is looked up).
pub fn resolve(p: &Path, dir: Option<&Path>) -> Option<PathBuf> {
    if p.is_file() {
        return Some(p.to_owned());
    }
    let plain = p.components().count() == 1;
    if plain && let Some(dir) = dir {
        // Scenario names hold dots (`t1-u1.5-rest`): the extension is appended, not set.
        let named = dir.join(format!("{}.toml", p.display()));
        if named.is_file() {
            return Some(named);
        }
    }
    (p.exists() || !plain).then(|| p.to_owned())
}

/// The names of the TOML files in `dir` (their stems), sorted; none if it cannot be read.
pub fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(str::to_owned))?
        })
        .collect();
    names.sort();
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_resolve_to_fixture_files_and_files_win() {
        let dir = rotor_testkit::tmp_dir("rotor-fixtures");
        for f in ["t1-u1.5-rest.toml", "b.toml", "notes.txt"] {
            std::fs::write(dir.join(f), "").unwrap();
        }
        assert_eq!(names(&dir), ["b", "t1-u1.5-rest"]);
        let d = Some(dir.as_path());
        let name = Path::new("t1-u1.5-rest");
        assert_eq!(resolve(name, d), Some(dir.join("t1-u1.5-rest.toml")));
        assert_eq!(resolve(name, None), None);
        assert_eq!(resolve(Path::new("nope"), d), None);
        // A path of more than one component, or one that is there, goes to its loader.
        let file = dir.join("b.toml");
        assert_eq!(resolve(&file, d), Some(file.clone()));
        assert_eq!(
            resolve(Path::new("x/nope"), d),
            Some(PathBuf::from("x/nope"))
        );
        assert_eq!(resolve(&dir, d), Some(dir.clone()));
        std::fs::remove_dir_all(&dir).ok();
    }
}
