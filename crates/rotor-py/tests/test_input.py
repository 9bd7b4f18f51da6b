"""input= in place of u=: a motor input that changes in time."""

import numpy as np
import pytest

import rotorbench


def test_a_one_valued_table_is_u_and_a_step_changes_the_run_after_it():
    by_u = rotorbench.simulate(u=1.5, t_end=20.0, dt=0.1)
    flat = rotorbench.simulate(input=[[0.0, 1.5], [10.0, 1.5]], t_end=20.0, dt=0.1)
    for k in ("t", "alpha", "omega_u", "omega_l"):
        assert np.array_equal(by_u[k], flat[k]), k
    # A step at t = 10 s, as a list of pairs and as an (n, 2) array: the same run, which is
    # the 1.5 V run up to the step (the solver restarts there as a run from it would).
    to_step = rotorbench.simulate(u=1.5, t_end=10.0, dt=0.1)
    rows = [[10.0, 1.5], [10.0, 2.5]]
    step = rotorbench.simulate(input=rows, t_end=20.0, dt=0.1)
    arr = rotorbench.simulate(input=np.array(rows), t_end=20.0, dt=0.1)
    n = len(to_step["t"])
    for k in ("t", "alpha", "omega_u", "omega_l"):
        assert np.array_equal(step[k], arr[k]), k
        assert np.array_equal(step[k][:n], to_step[k]), k
    assert step["omega_u"][-1] != by_u["omega_u"][-1]


def test_bad_rows_and_steady_are_refused_naming_input():
    with pytest.raises(ValueError, match=r"input\[1\]\.t = 0\.5"):
        rotorbench.simulate(input=[[1.0, 1.0], [0.5, 2.0]], t_end=5.0)
    with pytest.raises(ValueError, match=r"input\[0\]\.u = NaN"):
        rotorbench.simulate(input=[[0.0, float("nan")]], t_end=5.0)
    with pytest.raises(ValueError, match="input"):
        rotorbench.simulate(input=[], t_end=5.0)
    with pytest.raises(ValueError, match="input.*constant input"):
        rotorbench.steady(input=[[10.0, 1.5], [10.0, 2.5]])
