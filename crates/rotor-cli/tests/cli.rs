//! The CLI contract of DESIGN.md §4: CSV format, steady JSON, and clear errors (never a panic).

use std::process::Command;

fn rotor(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rotor"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn simulate_writes_the_contract_csv() {
    let dir = std::env::temp_dir().join(format!("rotor-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("out.csv");
    for solver in ["event", "switch", "moreau"] {
        let o = rotor(&[
            "simulate",
            "--solver",
            solver,
            "--u",
            "1.5",
            "--t-end",
            "2",
            "--csv",
            csv.to_str().unwrap(),
        ]);
        assert!(
            o.status.success(),
            "{solver}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "t,alpha,omega_u,omega_l");
        // 0, 0.01, ..., 2.0: 201 rows plus the header.
        assert_eq!(lines.len(), 202, "{solver}");
        assert!(lines[1].starts_with("0,"));
        assert!(lines[201].starts_with("2,"));
    }
}

#[test]
fn steady_prints_one_json_object() {
    let o = rotor(&["steady", "--solver", "event", "--u", "6.0"]);
    assert!(o.status.success());
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.trim().starts_with("{\"kind\":\"equilibrium\""), "{out}");
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    for (args, needle) in [
        (vec!["steady", "--solver", "rk4", "--u", "1"], "rk4"),
        (
            vec!["steady", "--solver", "event", "--u", "1", "--tol", "2"],
            "--tol 2",
        ),
        (
            vec!["steady", "--solver", "event", "--u", "1", "--x0", "1,2"],
            "--x0",
        ),
        (
            vec![
                "steady",
                "--solver",
                "event",
                "--u",
                "1",
                "--params",
                "/no/such.toml",
            ],
            "/no/such.toml",
        ),
    ] {
        let o = rotor(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
