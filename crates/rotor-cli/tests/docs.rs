//! The documentation's commands, run as they stand: the README's quick CLI block from an
//! empty directory, and BENCHMARK.md's job file against what `rotor job` prints.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The lines between `<!-- NAME begin -->` and `<!-- NAME end -->` of a document.
fn marked<'a>(doc: &'a str, name: &str) -> Vec<&'a str> {
    let begin = format!("<!-- {name} begin -->");
    let end = format!("<!-- {name} end -->");
    let start = doc.find(&begin).unwrap_or_else(|| panic!("no {begin}")) + begin.len();
    let stop = start
        + doc[start..]
            .find(&end)
            .unwrap_or_else(|| panic!("no {end}"));
    doc[start..stop].lines().collect()
}

/// A command line of a `sh` block without its trailing `# comment` (a `#` after two spaces,
/// as the README writes them), and the comment.
fn split_comment(line: &str) -> (&str, &str) {
    match line.find("  #") {
        Some(i) => (line[..i].trim(), line[i + 3..].trim()),
        None => (line.trim(), ""),
    }
}

/// Every `rotor ...` line of the README's quick block (`cli-quick`) runs, in order, from an
/// empty directory with `rotor` on the PATH and the suite taken from the binary itself (as
/// for an installed `rotor`), and exits 0: names, not paths of the checkout, and pairs that
/// fit together (the `check` takes the `simulate` before it). Lines whose comment says
/// `minutes` are the README's long commands and are skipped; the quick block must hold none,
/// and the README's other `rotor bench` lines must be marked.
#[test]
fn readme_quick_commands_run_from_an_empty_directory() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = marked(&readme, "cli-quick");
    let commands: Vec<(&str, &str)> = block
        .iter()
        .map(|l| split_comment(l))
        .filter(|(c, _)| c.starts_with("rotor "))
        .collect();
    assert!(commands.len() >= 10, "{commands:?}");
    let dir = rotor_testkit::tmp_dir("rotor-cli-readme");
    let bin = Path::new(env!("CARGO_BIN_EXE_rotor")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    for (cmd, comment) in &commands {
        assert!(
            !comment.contains("minutes"),
            "{cmd}: a long command in the quick block"
        );
        // Every quick command says how long it takes: a time in its comment.
        assert!(
            comment.contains(" s)") || comment.contains(" s;") || comment.contains(" s,"),
            "{cmd}: its comment gives no time: {comment}"
        );
        let o = Command::new("sh")
            .args(["-c", cmd])
            .current_dir(&dir)
            .env("PATH", &path)
            .env("ROTORBENCH_SUITE", "embedded")
            .env("ROTORBENCH_CACHE", dir.join(".cache"))
            .env_remove("ROTORBENCH_FIXTURES")
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{cmd}: exit {:?}: {}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        );
    }
    // The long ones: every other line of the README that runs `rotor bench` without
    // --quick, or the whole reference, is marked as taking minutes.
    let mut in_sh = false;
    for line in readme.lines() {
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        let (cmd, comment) = split_comment(line);
        if in_sh
            && !block.contains(&line)
            && cmd.starts_with("rotor bench")
            && !cmd.contains("--quick")
            && !cmd.contains("--merge")
        {
            assert!(
                comment.contains("minutes"),
                "{line}: not marked as taking minutes"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// BENCHMARK.md's example job file is what `rotor job` prints for the command above it,
/// byte for byte, so it cannot go stale (a new suite version, a new field, another default
/// horizon: paste the command's output into the block).
#[test]
fn benchmark_md_job_example_is_what_rotor_job_prints() {
    let doc = std::fs::read_to_string(root().join("BENCHMARK.md")).unwrap();
    let block = marked(&doc, "job-example").join("\n");
    let fence = |lang: &str| {
        let open = format!("```{lang}\n");
        let start = block.find(&open).unwrap() + open.len();
        let stop = start + block[start..].find("\n```").unwrap();
        block[start..stop].to_owned()
    };
    let cmd = fence("sh");
    let args: Vec<&str> = cmd
        .strip_prefix("rotor ")
        .unwrap()
        .split_whitespace()
        .collect();
    let o = Command::new(env!("CARGO_BIN_EXE_rotor"))
        .args(&args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        fence("json").trim_end(),
        printed.trim_end(),
        "BENCHMARK.md's job example is stale: paste the output of `{cmd}`"
    );
    // What the page says about it holds: the scenario's own horizon, and the suite's version.
    let job: serde_json::Value = serde_json::from_str(&printed).unwrap();
    assert_eq!(job["benchmark"], rotor_suite::VERSION);
    assert_eq!(job["t_end"], 200.0);
}
