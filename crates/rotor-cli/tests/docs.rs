//! The documentation's commands, run as they stand: the README's quick CLI block from an
//! empty directory, its long block (`minutes`) too when `ROTOR_README_LONG=1` (CI's long
//! step, `.ci/run`), and BENCHMARK.md's job file against what `rotor job` prints.

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

/// Runs one README line with `sh` in `dir`, as a newcomer would: the built `rotor` first on
/// the PATH, the suite taken from the binary itself (as for an installed `rotor`), a cache of
/// its own, and no pointer into the checkout.
fn run_in(dir: &Path, cmd: &str) -> std::process::Output {
    let bin = Path::new(env!("CARGO_BIN_EXE_rotor")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    Command::new("sh")
        .args(["-c", cmd])
        .current_dir(dir)
        .env("PATH", &path)
        .env("ROTORBENCH_SUITE", "embedded")
        .env("ROTORBENCH_CACHE", dir.join(".cache"))
        .env_remove("ROTORBENCH_FIXTURES")
        .output()
        .unwrap()
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
        let o = run_in(&dir, cmd);
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

/// The README's example of an input that changes in time (`cli-input`) runs as it stands,
/// every line in order (the `printf` that writes the input too), from an empty directory as
/// the quick block does, and its run is the stepped one: the trace covers the horizon on the
/// 0.01 s grid, and ω_u, which settles at 1.5 V, rises after the step at 60 s.
#[test]
fn readme_input_example_runs_from_an_empty_directory() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = marked(&readme, "cli-input");
    let lines: Vec<&str> = block
        .iter()
        .map(|l| split_comment(l).0)
        .filter(|c| !c.is_empty() && !c.starts_with("```"))
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines[1].contains("--input"), "{lines:?}");
    let dir = rotor_testkit::tmp_dir("rotor-cli-readme-input");
    for cmd in &lines {
        let o = run_in(&dir, cmd);
        assert!(
            o.status.success(),
            "{cmd}: exit {:?}: {}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let csv = std::fs::read_to_string(dir.join("step-run.csv")).unwrap();
    let mut rows = csv.lines();
    assert_eq!(rows.next(), Some("t,alpha,omega_u,omega_l"));
    let rows: Vec<Vec<f64>> = rows
        .map(|r| r.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // 0, 0.01, ..., 120
    assert_eq!(rows.len(), 12001);
    assert_eq!(rows.last().unwrap()[0], 120.0);
    // ω_u at 59 s is on the 1.5 V cycle (its values stay below the 2.5 V run's), and the
    // largest ω_u after the step exceeds every ω_u of the 50..60 s window: the input rose.
    let max_between = |a: f64, b: f64| {
        rows.iter()
            .filter(|r| r[0] >= a && r[0] < b)
            .map(|r| r[2])
            .fold(f64::MIN, f64::max)
    };
    assert!(max_between(60.0, 120.0) > max_between(50.0, 60.0) + 0.1);
    std::fs::remove_dir_all(&dir).ok();
}

/// The `rotor ...` lines of a marked block, split from their comments.
fn rotor_lines<'a>(block: &[&'a str]) -> Vec<(&'a str, &'a str)> {
    block
        .iter()
        .map(|l| split_comment(l))
        .filter(|(c, _)| c.starts_with("rotor "))
        .collect()
}

/// The value of `--flag VALUE` in a command line (the README's long commands quote no path).
fn flag_value<'a>(cmd: &'a str, flag: &str) -> Option<&'a str> {
    let mut words = cmd.split_whitespace();
    words.find(|w| *w == flag)?;
    words.next()
}

/// The README's long block (`cli-long`): every `rotor ...` line of it is marked `minutes`,
/// and every line of the README marked `minutes` that runs `rotor` is in it (so that CI's
/// long step runs them all). With `ROTOR_README_LONG=1` (CI's long step, `.ci/run`) each runs
/// as it stands, with `rotor` on the PATH and the suite taken from the binary, from an empty
/// directory of its own, `/path/to/minimal.py` being the checkout's
/// `bench/clients/minimal.py`; it must exit 0, write the files it names (`--json` a
/// benchmark report of every scene the command covers, each with points of the three
/// solvers; `--svg` an SVG), and its table must name every scene and client. Under
/// `ROTOR_REQUIRE_PEERS=1` (as in CI, which installs them) every peer must have run. Without
/// `ROTOR_README_LONG=1` the test says on stderr that it skipped them, in `cargo test`'s own
/// output (not the captured test output, which a passing test hides).
#[test]
fn readme_long_commands_run_in_ci_long_step() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = marked(&readme, "cli-long");
    let commands = rotor_lines(&block);
    assert!(!commands.is_empty(), "no command in the cli-long block");
    for (cmd, comment) in &commands {
        assert!(comment.contains("minutes"), "{cmd}: not marked `minutes`");
    }
    let mut in_sh = false;
    for line in readme.lines() {
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        let (cmd, comment) = split_comment(line);
        if in_sh && cmd.starts_with("rotor ") && comment.contains("minutes") {
            assert!(
                block.contains(&line),
                "{line}: marked `minutes` but outside the cli-long block (CI's long step would \
                 not run it)"
            );
        }
    }
    if std::env::var("ROTOR_README_LONG").as_deref() != Ok("1") {
        // Straight to the process's stderr: libtest captures `eprintln!` of a passing test.
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "readme_long_commands_run_in_ci_long_step: skipped the README's {} commands marked \
             `minutes` ({}); ROTOR_README_LONG=1 runs them (CI's long step, .ci/run)",
            commands.len(),
            commands
                .iter()
                .map(|(c, _)| *c)
                .collect::<Vec<_>>()
                .join("; ")
        );
        return;
    }
    let minimal = root()
        .join("bench/clients/minimal.py")
        .canonicalize()
        .unwrap();
    let require_peers = std::env::var("ROTOR_REQUIRE_PEERS").as_deref() == Ok("1");
    let suite_dir = root().join("fixtures/scenarios");
    for (cmd, _) in &commands {
        let run = cmd.replace("/path/to/minimal.py", &minimal.display().to_string());
        assert!(!run.contains("/path/to/"), "{cmd}: a placeholder path left");
        let dir = rotor_testkit::tmp_dir("rotor-cli-readme-long");
        let t0 = std::time::Instant::now();
        let o = run_in(&dir, &run);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd}: exit {:?}: {stderr}", o.status);
        // Its wall time, for whoever updates the README's stated one (never asserted).
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "{cmd}: {:.0} s wall",
            t0.elapsed().as_secs_f64()
        );
        let table = String::from_utf8(o.stdout).unwrap();
        // The scenes the command covers: the tier it names, else the whole suite.
        let tier = flag_value(cmd, "--tier").map(|t| rotor_harness::bench::Tier::parse(t).unwrap());
        let scenes: Vec<String> = rotor_harness::bench::suite(&suite_dir, tier)
            .unwrap()
            .iter()
            .map(|s| {
                s.scenario
                    .file_stem()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        for sc in &scenes {
            assert!(table.contains(sc.as_str()), "{cmd}: {sc} not in its table");
        }
        // `--external NAME=COMMAND`: the client's name.
        let externals: Vec<&str> = cmd
            .split(" --external ")
            .skip(1)
            .filter_map(|rest| rest.split('=').next())
            .collect();
        for name in &externals {
            assert!(
                table.contains(name),
                "{cmd}: client {name} not in its table"
            );
        }
        if let Some(svg) = flag_value(cmd, "--svg") {
            let text = std::fs::read_to_string(dir.join(svg)).unwrap();
            assert!(
                text.contains("<svg") && text.trim_end().ends_with("</svg>"),
                "{cmd}: {svg} is not a whole SVG"
            );
        }
        if let Some(json) = flag_value(cmd, "--json") {
            let text = std::fs::read_to_string(dir.join(json)).unwrap();
            let report: rotor_harness::bench::BenchReport = serde_json::from_str(&text)
                .unwrap_or_else(|e| panic!("{cmd}: {json} is not a benchmark report: {e}"));
            let names: Vec<&str> = report.scenes.iter().map(|s| s.name.as_str()).collect();
            assert_eq!(names.len(), scenes.len(), "{cmd}: {names:?}");
            for sc in &report.scenes {
                assert!(
                    scenes.contains(&sc.name),
                    "{cmd}: {} not asked for",
                    sc.name
                );
                for k in rotor_analysis::solvers::SOLVERS {
                    assert!(
                        sc.points.iter().any(|p| p.solver == k),
                        "{cmd}: {}: no point of {}",
                        sc.name,
                        k.name()
                    );
                }
            }
            if require_peers {
                for c in report.clients.iter().filter(|c| c.peer) {
                    assert_eq!(
                        c.status,
                        rotor_harness::bench::ClientStatus::Ran,
                        "{cmd}: peer {} did not run: {:?}",
                        c.name,
                        c.reason
                    );
                }
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }
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
