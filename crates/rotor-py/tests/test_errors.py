"""Bad input: ValueError (TypeError for a wrong type) naming the argument or field and the
value, worded as the command line words it; solver failures as SolveError; panics as
InternalError, never a crash."""

import math
import os
import warnings

import numpy as np
import pytest

import rotorbench


@pytest.mark.parametrize(
    "kwargs,flags,value,reason",
    [
        ({"solver": "rk4"}, ["--solver", "rk4"], '"rk4"', "unknown solver (expected one of: event, switch, moreau)"),
        ({"t_end": 0.0}, ["--t-end", "0"], "0", "must be positive and finite"),
        ({"dt": -0.01}, ["--dt", "-0.01"], "-0.01", "must be positive and finite"),
        ({"tol": 2.0}, ["--tol", "2"], "2", "must lie in (0, 1)"),
        ({"solver": "moreau", "h": 200.0}, ["--h", "200"], "200", "must lie in (0, 100] s (the run's horizon)"),
        ({"u": math.inf}, ["--u", "inf"], "inf", "must be a finite number"),
    ],
)
def test_bad_arguments_name_the_argument_as_the_cli_does(cli, kwargs, flags, value, reason):
    with pytest.raises(ValueError) as e:
        rotorbench.simulate(**kwargs)
    name = next(iter(k for k in kwargs if k != "solver" or len(kwargs) == 1))
    assert str(e.value) == f"{name} = {value}: {reason}"
    args = {"--solver": kwargs.get("solver", "event"), "--u": "1.5"}
    args.update(dict(zip(flags[::2], flags[1::2])))
    p = cli("simulate", *[x for kv in args.items() for x in kv], "--csv", "/dev/null", check=False)
    assert p.returncode == 2  # unusable input (README, "Exit status")
    assert f"{flags[0]} {value}: {reason}" in p.stderr, p.stderr


def test_bad_params_name_the_field_and_value():
    p = rotorbench.params()
    with pytest.raises(ValueError, match=r"^params: k_theta = -1: must be positive$"):
        rotorbench.simulate(params=dict(p, k_theta=-1.0))
    with pytest.raises(ValueError, match=r"unknown field `k_thta`"):
        rotorbench.simulate(params=dict(p, k_thta=1.0))
    lower = dict(p["lower"], family="dahl")
    with pytest.raises(ValueError, match=r'lower.family = "dahl": unknown friction family'):
        rotorbench.simulate(params=dict(p, lower=lower))
    with pytest.raises(TypeError, match=r"params\['lower'\]\['t_s'\]: expected a number"):
        rotorbench.simulate(params=dict(p, lower=dict(p["lower"], t_s=[1.0])))
    with pytest.raises(ValueError, match=r"^params = \"nope\": no such file, nor a name in .*table1"):
        rotorbench.simulate(params="nope")
    # A path that is there but is no parameter file: what is wrong with it, not "no such file".
    with pytest.raises(ValueError, match=r"cannot read parameter file: Is a directory"):
        rotorbench.simulate(params=os.path.dirname(__file__))
    with pytest.raises(ValueError, match=r"larger than 1048576 bytes"):
        rotorbench.simulate(params="/dev/zero")
    with pytest.raises(TypeError, match=r"params: expected a path or a name, got int"):
        rotorbench.simulate(params=5)
    with pytest.raises(ValueError, match=r"params: k_theta = NaN: must be a finite number"):
        rotorbench.steady(params=dict(p, k_theta=float("nan")))


def test_wrong_types_are_type_errors_naming_the_argument():
    with pytest.raises(TypeError, match="'u'"):
        rotorbench.simulate(u="1.5")
    with pytest.raises(TypeError, match="'x0'"):
        rotorbench.simulate(x0="abc")
    with pytest.raises(ValueError, match=r"^x0 = .*component 2 \(omega_u\) is not finite"):
        rotorbench.simulate(x0=(0.0, math.nan, 0.0))
    with pytest.raises(TypeError, match="'solver'"):
        rotorbench.steady(solver=3)


def test_sweep_names_the_bad_u_by_index():
    with pytest.raises(ValueError, match=r"^u\[2\] = NaN: must be a finite number$"):
        rotorbench.sweep([1.0, 2.0, math.nan])
    with pytest.raises(ValueError, match=r"^tol = 0: must lie in \(0, 1\)$"):
        rotorbench.sweep([1.0], tol=0.0)


def test_a_failed_run_is_a_solve_error_with_time_and_state():
    # u = 1e150 V: the motor torque is finite, the acceleration is not resolvable: the
    # step size underflows at once.
    with pytest.raises(rotorbench.SolveError) as e:
        rotorbench.simulate(u=1e150, t_end=1.0)
    assert "step size underflow" in str(e.value)
    assert e.value.t == 0.0 and e.value.state == (0.0, 0.0, 0.0)
    assert isinstance(e.value, RuntimeError)
    with pytest.raises(rotorbench.SolveError) as e:
        rotorbench.sweep([1.5, 1e150])
    assert str(e.value).startswith("u = 1e150: ") and e.value.u == 1e150


def test_gate_and_trace_errors_name_what_is_wrong(cli):
    sc = rotorbench.scenario("t1-u0.02-rest")
    r = rotorbench.simulate(u=sc["u"], t_end=sc["t_end"], dt=sc["dt"])
    cols = [r[c] for c in ("t", "alpha", "omega_u", "omega_l")]
    with pytest.raises(ValueError) as e:
        rotorbench.check(sc["name"], *cols, gate="medium")
    assert str(e.value) == 'gate = "medium": expected strict (7 significant digits), loose (3) or digits=N'
    p = cli("check", sc["path"], "--trace", "/dev/null", "--gate", "medium", check=False)
    assert p.returncode == 2 and 'expected strict (7 significant digits), loose (3) or digits=N' in p.stderr
    bad = cols[3].copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match=r"^omega_l\[5\] = NaN: not a finite number$"):
        rotorbench.check(sc["name"], *cols[:3], bad)
    with pytest.raises(ValueError, match="omega_u has 3"):
        rotorbench.check(sc["name"], cols[0], cols[1], cols[2][:3], cols[3])
    t = cols[0].copy()
    t[102] += 1e-3
    with pytest.raises(ValueError, match=r"^index 102: t = 1.021 is not the grid time 1.02 "):
        rotorbench.check(sc["name"], t, *cols[1:])
    with pytest.raises(ValueError, match=r"^index 4999: the trace ends here \(t = 49.99\)"):
        rotorbench.check(sc["name"], *[c[:5000] for c in cols])
    with pytest.raises(ValueError, match=r'^scenario = "t9-nothing": no such file'):
        rotorbench.check("t9-nothing", *cols)
    with pytest.raises(ValueError, match=r'^events\[0\]\["kind"\] = "stick": not one of'):
        rotorbench.check(sc["name"], *cols, events=[(1.0, "lower", "stick")])
    with pytest.raises(TypeError, match=r"^events\[0\]: expected a dict"):
        rotorbench.check(sc["name"], *cols, events=[1.0])


def test_an_ignored_setting_warns_as_the_cli_does(cli):
    with pytest.warns(UserWarning, match=r"^tol is ignored by moreau \(fixed steps: its accuracy is set by h\)$"):
        rotorbench.simulate("moreau", t_end=1.0, tol=1e-8)
    with pytest.warns(UserWarning, match=r"^h is ignored by event"):
        rotorbench.steady(h=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rotorbench.simulate("moreau", t_end=1.0, h=1e-3)
    p = cli("simulate", "--solver", "moreau", "--u", "1.5", "--t-end", "1", "--tol", "1e-8", "--csv", "/dev/null")
    assert "--tol is ignored by moreau (fixed steps: its accuracy is set by --h)" in p.stderr


def test_a_panic_becomes_an_exception_not_a_crash():
    with pytest.raises(rotorbench.InternalError, match=r"internal error \(a bug in rotorbench; please report it\): boom"):
        rotorbench._rotorbench._panic("boom")
    # The interpreter and the package work on after it.
    assert rotorbench.steady(u=1.5)["kind"] == "limit_cycle"


def test_an_initial_state_of_the_wrong_size_is_refused_by_name():
    # x0 is a list of the model's size; the rig's state has three values.
    for x0 in ((1.0, 2.0), [0.0] * 5):
        with pytest.raises(ValueError, match=rf"x0 = {len(x0)} values: the rig's state has 3"):
            rotorbench.simulate(x0=x0, t_end=1.0)
        with pytest.raises(ValueError, match=rf"x0 = {len(x0)} values"):
            rotorbench.steady(x0=x0)
