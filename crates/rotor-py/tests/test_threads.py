"""Runs release the GIL: Python threads run while a solve runs, and calls from a thread pool
give what the same calls give one after another."""

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import rotorbench


def test_a_thread_runs_while_another_solves():
    """A long solve (20 000 s at tol 1e-12, about 0.2 s) in one thread and a short one
    (1 s) in the main thread, started after it: with the GIL released the short one ends
    first; were the GIL held through the long solve, the main thread could not even start
    until it ended."""
    for _ in range(3):
        started = threading.Event()
        order = []

        def long_run():
            started.set()
            rotorbench.simulate(u=1.5, t_end=20000.0, dt=10.0, tol=1e-12)
            order.append("long")

        worker = threading.Thread(target=long_run)
        worker.start()
        started.wait()
        rotorbench.simulate(u=1.5, t_end=1.0)
        order.append("short")
        worker.join()
        assert order == ["short", "long"]


def test_a_thread_pool_gives_the_sequential_answers():
    us = [0.5, 1.5, 2.5, 3.5, 4.5, 5.5]
    one_by_one = [rotorbench.simulate(u=u, t_end=50.0)["omega_l"] for u in us]
    with ThreadPoolExecutor(max_workers=4) as pool:
        pooled = list(pool.map(lambda u: rotorbench.simulate(u=u, t_end=50.0)["omega_l"], us))
    for a, b in zip(one_by_one, pooled):
        assert np.array_equal(a.view(np.uint64), b.view(np.uint64))
    with ThreadPoolExecutor(max_workers=3) as pool:
        steadies = list(pool.map(lambda u: rotorbench.steady(u=u), us))
    assert steadies == rotorbench.sweep(us)


def test_sweep_threads_follow_the_argument_then_slurm(monkeypatch):
    """``sweep(threads=N)``, else ``SLURM_CPUS_PER_TASK``, else the cores: the same answers
    on any count; a bad count or variable is a ValueError naming it and its value."""
    import pytest

    us = [0.5, 1.5, 2.5]
    monkeypatch.delenv("SLURM_CPUS_PER_TASK", raising=False)
    whole = rotorbench.sweep(us)
    assert rotorbench.sweep(us, threads=1) == whole
    assert rotorbench.sweep(us, threads=3) == whole
    for bad in [0, -2, 100000]:
        with pytest.raises(ValueError, match=f"threads = {bad}: "):
            rotorbench.sweep(us, threads=bad)
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", "2")
    assert rotorbench.sweep(us) == whole
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", "lots")
    with pytest.raises(ValueError, match='SLURM_CPUS_PER_TASK="lots"'):
        rotorbench.sweep(us)
    # An explicit count does not read the variable.
    assert rotorbench.sweep(us, threads=2) == whole
