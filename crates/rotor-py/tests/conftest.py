"""Shared set-up of the rotorbench package tests: the repository and its `rotor` binary.

The tests compare the package with the command line on the same scene, so they need the CLI
built from the same checkout: $ROTOR_BIN, else target/release/rotor of the repository (which
`cargo test --release --workspace` or `cargo build --release` builds). A missing binary fails
the tests that need it, with the command that builds it: a comparison that is silently skipped
would prove nothing.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def rotor_bin():
    path = Path(os.environ.get("ROTOR_BIN", REPO / "target" / "release" / "rotor"))
    if not path.is_file():
        pytest.fail(f"{path}: the rotor CLI is not built; run `cargo build --release` in {REPO}")
    return path


@pytest.fixture(scope="session")
def cli(rotor_bin):
    """Runs `rotor ARGS...` in the repository; returns the CompletedProcess (text)."""

    def run(*args, check=True):
        p = subprocess.run(
            [str(rotor_bin), *map(str, args)],
            cwd=REPO,
            capture_output=True,
            text=True,
        )
        if check and p.returncode != 0:
            raise AssertionError(f"rotor {' '.join(map(str, args))} failed: {p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    def run(*args):
        return json.loads(cli(*args).stdout)

    return run
