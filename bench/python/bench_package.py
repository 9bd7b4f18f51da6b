#!/usr/bin/env python3
"""What the Python package costs, measured side by side in one Python process.

1. `rotorbench.simulate` (the 100 s, 1.5 V scene at tol 1e-10, event-driven) against the Rust
   solve alone (`rotorbench._rotorbench._solve_seconds`: the same solve timed inside Rust, no
   argument checks, no numpy), in alternating rounds; medians.
2. `rotorbench.simulate` against scipy `solve_ivp` at equal error: the repository's scipy peer
   (bench/peers/scipy_rotor.py: DOP853 between located events, exact sticking) over a ladder of
   tolerances; the error of each run is max |omega_l - reference| over the 0.01 s grid, the
   reference the event-driven solver at tol 1e-13; scipy's time at rotorbench's error is
   interpolated log-log between the ladder's neighbours.
3. A thread pool of 2 Python threads calling `simulate` against the same calls one by one, and
   `rotorbench.sweep` against a Python loop of `steady` (both use every core).

Run after `pip install ./crates/rotor-py scipy`:  python3 bench/python/bench_package.py
(a few seconds). The numbers quoted in the README come from this script.
"""

import math
import os
import statistics
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import rotorbench

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "peers"))
import scipy_rotor  # noqa: E402  (the repository's scipy peer)

U, T_END, DT, TOL = 1.5, 100.0, 0.01, 1e-10


def timed(f):
    t0 = time.perf_counter()
    r = f()
    return r, time.perf_counter() - t0


def overhead(rounds=41):
    py, rs = [], []
    for _ in range(3):  # warm-up
        rotorbench.simulate("event", U, t_end=T_END, dt=DT, tol=TOL)
    for _ in range(rounds):
        _, s = timed(lambda: rotorbench.simulate("event", U, t_end=T_END, dt=DT, tol=TOL))
        py.append(s)
        rs.extend(rotorbench._rotorbench._solve_seconds("event", U, T_END, DT, TOL, None, 1))
    return statistics.median(py), statistics.median(rs)


def scipy_at_equal_error(t_rotor):
    ref = rotorbench.simulate("event", U, t_end=T_END, dt=DT, tol=1e-13)["omega_l"]
    mine = rotorbench.simulate("event", U, t_end=T_END, dt=DT, tol=TOL)["omega_l"]
    err_rotor = float(np.max(np.abs(mine - ref)))
    rotor = scipy_rotor.Rotor(rotorbench.params(), U)
    grid = np.linspace(0.0, T_END, round(T_END / DT) + 1)
    ladder = []
    for tol in (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12):
        runs = []
        for _ in range(3):
            (y, _, _), s = timed(lambda: scipy_rotor.simulate(rotor, [0.0, 0.0, 0.0], T_END, grid, tol, "DOP853"))
            runs.append(s)
        err = float(np.max(np.abs(y[2] - ref)))
        ladder.append((tol, err, statistics.median(runs)))
    # scipy's time at rotorbench's error, log-log between the neighbouring ladder points.
    t_equal = None
    for (_, e0, s0), (_, e1, s1) in zip(ladder, ladder[1:]):
        if e1 <= err_rotor <= e0 and e1 < e0:
            w = math.log(e0 / err_rotor) / math.log(e0 / e1)
            t_equal = math.exp((1 - w) * math.log(s0) + w * math.log(s1))
    return err_rotor, ladder, t_equal


def threads(n=8):
    call = lambda u: rotorbench.simulate("event", u, t_end=20000.0, dt=1.0, tol=TOL)  # noqa: E731
    us = [1.0 + 0.25 * k for k in range(n)]
    call(1.5)
    _, one = timed(lambda: [call(u) for u in us])
    with ThreadPoolExecutor(max_workers=2) as pool:
        _, two = timed(lambda: list(pool.map(call, us)))
    return one, two


def sweep(n=32):
    us = list(np.linspace(0.2, 6.0, n))
    _, loop = timed(lambda: [rotorbench.steady(u=float(u)) for u in us])
    _, par = timed(lambda: rotorbench.sweep(us))
    return loop, par


def main():
    print(f"rotorbench {rotorbench.__version__}, numpy {np.__version__}, scipy {scipy_rotor.scipy.__version__}, "
          f"{os.cpu_count()} cores\n")
    t_py, t_rs = overhead()
    print(f"simulate(event, u = {U} V, t_end = {T_END} s, tol = {TOL:g}), medians of 41 alternating rounds:")
    print(f"  Rust solve alone        {1e3 * t_rs:8.3f} ms")
    print(f"  rotorbench.simulate     {1e3 * t_py:8.3f} ms   ({t_py / t_rs:.2f}x the solve)")
    err, ladder, t_equal = scipy_at_equal_error(t_py)
    print(f"\nerror of rotorbench at tol {TOL:g}: max |omega_l - ref| = {err:.2e} rad/s")
    print("  scipy solve_ivp DOP853 (bench/peers/scipy_rotor.py):")
    for tol, e, s in ladder:
        print(f"    tol {tol:7.0e}   error {e:9.2e}   {1e3 * s:9.1f} ms")
    if t_equal is None:
        print("  scipy's ladder does not bracket rotorbench's error: no ratio")
    else:
        print(f"  scipy at equal error: {1e3 * t_equal:.1f} ms = {t_equal / t_py:.0f}x rotorbench.simulate")
    one, two = threads()
    print(f"\n8 simulate calls (20 000 s each): one by one {one:.3f} s, 2 threads {two:.3f} s ({one / two:.2f}x)")
    loop, par = sweep()
    print(f"steady at 32 u values: Python loop {loop:.3f} s, rotorbench.sweep {par:.3f} s ({loop / par:.2f}x)")


if __name__ == "__main__":
    main()
