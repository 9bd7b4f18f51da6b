"""Chains of N discs through the package: 2-D arrays, disc numbers, the CLI's numbers."""

import numpy as np
import pytest

import rotorbench

CHAIN3 = """name = "chain3"
k_m = 3.9950
[[disc]]
j = 0.4765
friction = { family = "upper", t_s = 0.0, dt_s = 0.0, b = 2.2247, db = 0.0 }
[[disc]]
j = 0.0326
k = 0.0727
friction = { family = "exponential", t_s = 0.1642, t_1 = 0.0603, t_2 = -0.2267, w_1 = 5.7468, w_2 = 0.2941, b = 0.0109 }
[[disc]]
j = 0.0326
k = 0.0727
c = 0.001
friction = { family = "stribeck", t_s = 0.2, t_c = 0.1, omega_s = 1.5, delta = 2.0, b = 0.01 }
"""

#: CHAIN3's discs as a dict's `disc` list (its first two are Table 1's rig).
DISCS = [
    {"j": 0.4765, "friction": {"family": "upper", "t_s": 0.0, "dt_s": 0.0, "b": 2.2247, "db": 0.0}},
    {"j": 0.0326, "k": 0.0727, "friction": {"family": "exponential", "t_s": 0.1642, "t_1": 0.0603,
                                             "t_2": -0.2267, "w_1": 5.7468, "w_2": 0.2941, "b": 0.0109}},
    {"j": 0.0326, "k": 0.0727, "c": 0.001, "friction": {"family": "stribeck", "t_s": 0.2, "t_c": 0.1,
                                                         "omega_s": 1.5, "delta": 2.0, "b": 0.01}},
]


def read_trace(text):
    lines = text.splitlines()
    header = lines[0].split(",")
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return header, rows


@pytest.fixture
def chain3(tmp_path):
    path = tmp_path / "chain3.toml"
    path.write_text(CHAIN3)
    return path


@pytest.mark.parametrize(
    "solver, knob", [("event", {"tol": 1e-9}), ("switch", {"tol": 1e-9}), ("moreau", {"h": 2e-3})]
)
def test_a_chain_gives_two_dimensional_arrays_with_the_clis_bits(cli, chain3, tmp_path, solver, knob):
    """alpha is (N - 1) x len(t) and omega N x len(t), the numbers those of `rotor simulate`
    bit for bit, from a file and from a dict of its keys alike."""
    (name, value), = knob.items()
    x0 = (0.1, 0.0, 0.5, 0.2, 0.0)
    r = rotorbench.simulate(solver, 1.5, params=str(chain3), x0=x0, t_end=20.0, dt=0.05, **knob)
    assert r["alpha"].shape == (2, 401) and r["omega"].shape == (3, 401)
    assert "omega_u" not in r
    out = tmp_path / "trace.csv"
    cli(
        "simulate", "--solver", solver, "--u", "1.5", "--params", chain3,
        "--x0", ",".join(map(repr, x0)), "--t-end", "20", "--dt", "0.05",
        f"--{name}", repr(value), "--csv", out,
    )
    header, rows = read_trace(out.read_text())
    assert header == ["t", "alpha_1", "alpha_2", "omega_1", "omega_2", "omega_3"]
    assert np.array_equal(r["t"], rows[:, 0])
    assert np.array_equal(r["alpha"], rows[:, 1:3].T)
    assert np.array_equal(r["omega"], rows[:, 3:].T)
    # The discs stick and slip, and events name them by number.
    discs = {e["disc"] for e in r["events"]}
    assert discs and discs <= {1, 2, 3}, r["events"][:5]
    params = {"k_m": 3.995, "disc": DISCS}
    d = rotorbench.simulate(solver, 1.5, params=params, x0=x0, t_end=20.0, dt=0.05, **knob)
    assert np.array_equal(d["omega"], r["omega"])


def test_a_chain_of_two_in_chain_form_is_the_rig():
    """The rig written as a chain of two gives the rig's numbers, as 2-D arrays."""
    params = {"k_m": 3.995, "disc": DISCS[:2]}
    rig = rotorbench.simulate("event", 1.5, t_end=10.0)
    chain = rotorbench.simulate("event", 1.5, params=params, t_end=10.0)
    assert np.array_equal(chain["alpha"][0], rig["alpha"])
    assert np.array_equal(chain["omega"][0], rig["omega_u"])
    assert np.array_equal(chain["omega"][1], rig["omega_l"])
    assert {e["disc"] for e in chain["events"]} <= {1, 2}


def test_a_chain_takes_an_input_in_time_on_every_solver(chain3):
    """A step of u at 1 s: up to it the run is the 1.5 V run to 1 s, bit for bit (both end
    a step on 1 s), and after it another than the constant one."""
    for solver in ("event", "switch", "moreau"):
        stepped = rotorbench.simulate(solver, params=str(chain3), t_end=2.0, input=[[0, 1.5], [1, 1.5], [1, 2.5]])
        before = rotorbench.simulate(solver, 1.5, params=str(chain3), t_end=1.0)
        assert np.array_equal(stepped["omega"][:, :101], before["omega"]), solver
        constant = rotorbench.simulate(solver, 1.5, params=str(chain3), t_end=2.0)
        assert not np.array_equal(stepped["omega"][:, -1], constant["omega"][:, -1]), solver


def test_a_chain_refuses_what_it_cannot_take_by_name(chain3):
    with pytest.raises(ValueError, match="x0"):
        rotorbench.simulate("switch", 1.5, params=str(chain3), x0=(0.0, 0.1, 0.0), t_end=1.0)
    with pytest.raises(TypeError, match=r"params\['disc'\]\[0\]"):
        rotorbench.simulate("switch", 1.5, params={"k_m": 1.0, "disc": [1.0, 2.0]}, t_end=1.0)


def test_steady_on_a_chain_gives_the_clis_lists(cli_json, tmp_path):
    """``steady`` of a chain returns the chain's lists, the same JSON as ``rotor steady``: the
    rig's top disc with two copies of its lower disc, at 2.5 V a cycle of 22 s."""
    params = {"k_m": 3.995, "disc": [DISCS[0], DISCS[1], DISCS[1]]}
    st = rotorbench.steady("event", 2.5, params=params)
    assert st["kind"] == "limit_cycle"
    assert all(len(st[k]) == 3 for k in ("omega_max", "omega_min", "stick_time"))
    assert st["return_distance"] <= st["return_tolerance"]
    path = tmp_path / "rig-like3.toml"
    disc = lambda d: "[[disc]]\nj = {}\n{}friction = {{ {} }}\n".format(
        d["j"],
        f"k = {d['k']}\n" if "k" in d else "",
        ", ".join(f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v}" for k, v in d["friction"].items()),
    )
    path.write_text('name = "rig-like3"\nk_m = 3.995\n' + disc(DISCS[0]) + disc(DISCS[1]) + disc(DISCS[1]))
    assert cli_json("steady", "--params", path, "--u", "2.5", "--solver", "event") == st
    with pytest.raises(ValueError, match="input"):
        rotorbench.steady("event", params=params, input=[[0, 1.5], [1, 2.5]])


def test_a_chain_scene_of_the_suite_is_graded_from_arrays():
    """`check` of a chain scene takes simulate's 2-D arrays and events (discs by number) and
    grades them as `rotor check` grades a chain's trace; a trace off in one disc fails that
    disc's column; the rig's arrays, wrong shapes and a NaN are refused by name."""
    sc = rotorbench.scenario("chain3-u1.5-rest")
    assert sc["discs"] == 3 and len(sc["x0"]) == 5 and sc["chaos"] is None
    chaos = rotorbench.scenario("chain8-u2.5-chaos")["chaos"]
    assert chaos == {"statistics_from": 1000.0, "batches": 10}
    assert sc["benchmark"].startswith("rotorbench-chain-1.0+")
    r = rotorbench.simulate(solver="event", u=sc["u"], params=sc["params"], x0=sc["x0"],
                            t_end=sc["t_end"], dt=sc["dt"], tol=1e-10)
    v = rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"], omega=r["omega"],
                         events=r["events"], gate="strict")
    assert v["passed"], v
    assert v["benchmark"] == sc["benchmark"] and v["not_graded"] == []
    names = [q["name"] for q in v["quantities"]]
    assert names[:5] == ["alpha_1", "alpha_2", "omega_1", "omega_2", "omega_3"]
    assert "events" in names and "stick_3" in names
    # Positionally, omega takes omega_u's place.
    assert rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"], r["omega"])["passed"]
    wrong = r["omega"].copy()
    wrong[1, 5000] += 1.0
    v = rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"], omega=wrong)
    assert not v["passed"]
    assert [q["name"] for q in v["quantities"] if not q["passed"]] == ["omega_2"]
    with pytest.raises(TypeError, match="omega="):
        rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"][0], r["omega"][0], r["omega"][1])
    with pytest.raises(ValueError, match=r"omega: shape \(2, 10001\), expected \(3, 10001\)"):
        rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"], omega=r["omega"][:2])
    nan = r["alpha"].copy()
    nan[1, 7] = np.nan
    with pytest.raises(ValueError, match=r"alpha\[1\]\[7\] = NaN"):
        rotorbench.check("chain3-u1.5-rest", r["t"], nan, omega=r["omega"])
    with pytest.raises(ValueError, match="the disc numbers 1 to 3"):
        rotorbench.check("chain3-u1.5-rest", r["t"], r["alpha"], omega=r["omega"],
                         events=[(1.0, "lower", "stick_start")])
    with pytest.raises(TypeError, match="omega_u and omega_l"):
        rotorbench.check("t1-u1.5-rest", r["t"], r["alpha"][0], omega=r["omega"])
