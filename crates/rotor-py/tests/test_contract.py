"""The package's contract (docs/python.md): what each function takes and returns, and that it
returns what the command line computes for the same scene, bit for bit."""

import csv
import io
import math
import os

import numpy as np
import pytest

import rotorbench

COLUMNS = ("t", "alpha", "omega_u", "omega_l")


def read_csv_columns(text):
    """The trace CSV the CLI writes, as float64 columns (Python's float() is correctly
    rounded, and the CLI writes the shortest form that reads back to the same number)."""
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0] == list(COLUMNS)
    return {c: np.array([float(r[k]) for r in rows[1:]]) for k, c in enumerate(COLUMNS)}


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(
        a.view(np.uint64), b.view(np.uint64)
    )


def test_simulate_returns_numpy_columns_events_and_counters():
    r = rotorbench.simulate()
    assert set(r) == {"t", "alpha", "omega_u", "omega_l", "events", "stats"}
    for c in COLUMNS:
        assert isinstance(r[c], np.ndarray) and r[c].dtype == np.float64 and r[c].ndim == 1
        assert r[c].shape == (10001,)  # 0, 0.01, ..., 100 s
        assert r[c].flags.c_contiguous and r[c].flags.writeable
    assert r["t"][0] == 0.0 and r["t"][-1] == 100.0 and r["t"][300] == 3.0
    # From rest at 1.5 V the lower disc sticks and slips: stick ends and starts alternate.
    kinds = [e["kind"] for e in r["events"]]
    assert kinds[:4] == ["stick_end", "stick_start", "stick_end", "stick_start"]
    assert all(set(e) == {"t", "disc", "kind"} and e["disc"] == "lower" for e in r["events"])
    assert all(type(v) is int for v in r["stats"].values()) and r["stats"]["steps"] > 0
    assert np.all(r["omega_l"] >= 0.0)  # stick-slip forward only (Table 1, 1.5 V)


@pytest.mark.parametrize(
    "solver,knob",
    [("event", {"tol": 1e-12}), ("switch", {"tol": 1e-9}), ("moreau", {"h": 5e-4})],
)
def test_simulate_matches_the_cli_bit_for_bit(cli, solver, knob, tmp_path):
    """The same scene through `rotor simulate` and `rotorbench.simulate`: identical bits."""
    (name, value), = knob.items()
    kw = dict(solver=solver, u=2.5, x0=(0.1, 0.5, -0.2), t_end=30.0, dt=0.05, **knob)
    r = rotorbench.simulate(**kw)
    out = tmp_path / "trace.csv"
    cli(
        "simulate", "--solver", solver, "--u", "2.5", "--x0", "0.1,0.5,-0.2",
        "--t-end", "30", "--dt", "0.05", f"--{name}", repr(value), "--csv", out,
    )
    expected = read_csv_columns(out.read_text())
    for c in COLUMNS:
        assert same_bits(r[c], expected[c]), c


def test_every_solver_takes_its_knob():
    """tol steers the adaptive solvers and h Moreau-Jean: a looser setting moves the answer,
    within what the setting allows (the 1.5 V trace, max |omega_l| difference)."""
    ref = rotorbench.simulate(u=1.5, t_end=10.0, tol=1e-12)["omega_l"]
    for solver, loose, tight, bound in [
        # Bounds: the loose runs' differences measured when this test was written (event
        # 5.4e-5, switch 1.1e-5, moreau 9.2e-4 rad/s) times about 10: a regression bound.
        ("event", {"tol": 1e-6}, {"tol": 1e-11}, 5e-4),
        ("switch", {"tol": 1e-6}, {"tol": 1e-11}, 1e-4),
        ("moreau", {"h": 1e-2}, {"h": 1e-4}, 1e-2),
    ]:
        e_loose = np.max(np.abs(rotorbench.simulate(solver, 1.5, t_end=10.0, **loose)["omega_l"] - ref))
        e_tight = np.max(np.abs(rotorbench.simulate(solver, 1.5, t_end=10.0, **tight)["omega_l"] - ref))
        assert e_tight < e_loose < bound, (solver, e_tight, e_loose)


def test_params_as_none_name_path_or_dict_are_the_same_set():
    p = rotorbench.params()
    assert p["k_theta"] == 0.0727 and p["lower"]["family"] == "exponential"
    table1 = os.path.join(rotorbench.FIXTURES, "params", "table1.toml")
    for params in (None, "table1", table1, p):
        assert rotorbench.steady(u=1.5, params=params) == rotorbench.steady(u=1.5)
    s = rotorbench.params("stribeck")
    assert s["lower"]["family"] == "stribeck"
    # A changed value changes the answer: a stiffer shaft, a shorter period.
    stiff = dict(p, k_theta=0.09)
    assert rotorbench.steady(u=1.5, params=stiff)["period"] < rotorbench.steady(u=1.5)["period"]


def test_x0_takes_any_sequence_of_three():
    a = rotorbench.simulate(x0=(0.1, 0.0, 0.0), t_end=1.0)["omega_l"]
    for x0 in ([0.1, 0, 0], np.array([0.1, 0.0, 0.0])):
        assert same_bits(rotorbench.simulate(x0=x0, t_end=1.0)["omega_l"], a)


@pytest.mark.parametrize("solver", ["event", "switch", "moreau"])
def test_steady_is_what_rotor_steady_prints(cli_json, solver):
    args = ["steady", "--solver", solver, "--u", "4.5", "--params", "fixtures/params/stribeck.toml"]
    assert rotorbench.steady(solver, 4.5, params="stribeck") == cli_json(*args)


def test_steady_with_tol_and_x0_matches_the_cli(cli_json):
    expected = cli_json("steady", "--solver", "event", "--u", "2.5", "--x0", "0,0,1.2", "--tol", "1e-11")
    assert rotorbench.steady(u=2.5, x0=(0, 0, 1.2), tol=1e-11) == expected


def test_sweep_is_steady_at_each_u_in_order():
    us = np.linspace(0.5, 5.0, 7)
    got = rotorbench.sweep(us)
    assert got == [rotorbench.steady(u=float(u)) for u in us]
    assert [d["kind"] for d in got][:2] == ["limit_cycle", "limit_cycle"]
    assert rotorbench.sweep([1.5], solver="moreau", h=1e-3) == [rotorbench.steady("moreau", 1.5, h=1e-3)]


def test_bifurcation_is_what_rotor_bifurcation_writes(cli_json):
    d = rotorbench.bifurcation(u_min=0.0, u_max=7.0)
    assert d == cli_json("bifurcation", "--u-min", "0", "--u-max", "7", "--json", "-")
    assert {p["kind"] for p in d["points"]} >= {"hopf", "grazing"}


def test_check_grades_arrays_as_rotor_check_grades_the_file(cli, cli_json, tmp_path):
    sc = rotorbench.scenario("t1-u1.5-rest")
    assert (sc["u"], sc["x0"], sc["t_end"], sc["dt"]) == (1.5, (0.0, 0.0, 0.0), 200.0, 0.01)
    # Moreau-Jean at h = 2e-3: a run graded at both levels, some quantities failing strict.
    r = rotorbench.simulate("moreau", sc["u"], sc["params"], sc["x0"], sc["t_end"], sc["dt"], h=2e-3)
    trace = tmp_path / "trace.csv"
    cli("simulate", "--solver", "moreau", "--u", "1.5", "--t-end", "200", "--h", "2e-3", "--csv", trace)
    for gate in ("loose", "strict"):
        got = rotorbench.check("t1-u1.5-rest", r["t"], r["alpha"], r["omega_u"], r["omega_l"], gate=gate)
        p = cli("check", sc["path"], "--trace", trace, "--gate", gate, "--json", "-", check=False)
        assert p.returncode in (0, 1), p.stderr
        import json
        assert got == json.loads(p.stdout)
        assert got["passed"] == (p.returncode == 0)
    assert not got["passed"]  # h = 2e-3 misses the strict gate


def test_check_passes_the_reference_solver_with_its_events():
    sc = rotorbench.scenario("t1-u1.5-rest")
    r = rotorbench.simulate("event", sc["u"], sc["params"], sc["x0"], sc["t_end"], sc["dt"], tol=1e-12)
    got = rotorbench.check(sc["path"], r["t"], r["alpha"], r["omega_u"], r["omega_l"], gate="strict", events=r["events"])
    assert got["passed"], got
    assert "events" in {q["name"] for q in got["quantities"]} and got["not_graded"] == []
    # Lists and tuples grade the same as arrays.
    as_lists = rotorbench.check(
        sc["name"], list(r["t"]), list(r["alpha"]), list(r["omega_u"]), list(r["omega_l"]),
        gate="strict", events=[(e["t"], e["disc"], e["kind"]) for e in r["events"]],
    )
    assert as_lists == got


def test_the_package_is_typed_and_documented():
    import inspect
    import pathlib

    pkg = pathlib.Path(rotorbench.__file__).parent
    assert (pkg / "py.typed").is_file() and (pkg / "__init__.pyi").is_file()
    for name in ("simulate", "steady", "sweep", "bifurcation", "check", "params", "scenario"):
        f = getattr(rotorbench, name)
        assert f.__doc__ and len(f.__doc__) > 80, name
    assert str(inspect.signature(rotorbench.simulate)) == (
        "(solver='event', u=1.5, params=None, x0=(0.0, 0.0, 0.0), t_end=100.0, dt=0.01, tol=None, h=None, input=None)"
    )
    assert rotorbench.__version__ == "0.1.0"


def test_the_wheel_grades_by_name_from_any_directory_with_its_embedded_suite(tmp_path):
    """An installed package grades a scenario by name with the suite embedded in it, from an
    empty directory (ROTORBENCH_SUITE=embedded: as where no checkout is), and names the
    suite's version in the verdict, as the CLI does."""
    import json
    import subprocess
    import sys

    ref = os.path.join(rotorbench.FIXTURES, "reference", "t1-u1.5-rest.csv")
    code = (
        "import json, sys, numpy as np, rotorbench\n"
        "d = np.loadtxt(sys.argv[1], delimiter=',', skiprows=1)\n"
        "v = rotorbench.check('t1-u1.5-rest', d[:, 0], d[:, 1], d[:, 2], d[:, 3], gate='strict')\n"
        "print(json.dumps({'passed': v['passed'], 'benchmark': v['benchmark'],\n"
        "                  'version': rotorbench.SUITE_VERSION, 'fixtures': rotorbench.FIXTURES}))\n"
    )
    env = dict(os.environ, ROTORBENCH_SUITE="embedded", ROTORBENCH_CACHE=str(tmp_path / "cache"))
    env.pop("ROTORBENCH_FIXTURES", None)
    p = subprocess.run([sys.executable, "-c", code, ref], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["passed"] is True
    assert out["benchmark"] == out["version"] == rotorbench.SUITE_VERSION
    assert out["version"].startswith("rotorbench-1.0+")
    assert out["fixtures"].startswith(str(tmp_path / "cache"))


def test_bifurcation_by_solver_is_what_the_cli_writes(cli_json):
    d = rotorbench.bifurcation(u_min=1.45, u_max=1.55, solver="switch")
    assert d == cli_json("bifurcation", "--solver", "switch", "--u-min", "1.45", "--u-max", "1.55", "--json", "-")
    assert d["solver"] == "switch" and "not_located" not in d
    with pytest.raises(ValueError, match="solver"):
        rotorbench.bifurcation(solver="rk4")
