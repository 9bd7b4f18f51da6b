"""What the rotorbench peer clients share: the job-file protocol of BENCHMARK.md.

A client is started as `python3 <script> JOB.json`. The job file holds the scenario name, the
parameter set (every field of the parameter file, friction family names included), u, x0,
t_end, dt, tol or h, and the paths of the trace and events files to write. The client writes
the trace (header t,alpha,omega_u,omega_l, one row per grid time 0, dt, ..., t_end) and, if it
locates them, the events (header t,disc,kind), and prints one JSON line with its in-process
time, `{"solve_seconds": S, ...}`.

Used by scipy_rotor.py, siconos_rotor.py and siconos_chain.py (each inserts its own directory at the front of
sys.path before importing this module, so they run from any working directory). Standard
library and numpy only: it imports without scipy or Siconos installed.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import time

import numpy as np


def read_job(argv):
    """The job of `argv[1]` as a dict; exits with status 2 and a message on a bad call."""
    if len(argv) != 2:
        print(f"usage: {argv[0]} JOB.json", file=sys.stderr)
        sys.exit(2)
    with open(argv[1]) as f:
        job = json.load(f)
    for key in ("params", "u", "x0", "t_end", "dt", "trace", "events"):
        if key not in job:
            print(f"{argv[1]}: the job has no {key!r}", file=sys.stderr)
            sys.exit(2)
    if job.get("input") is not None or job["u"] is None:
        # An input that changes in time (BENCHMARK.md): these peers take a constant u only.
        print(f"{argv[1]}: the job's input changes in time; this peer takes a constant u only",
              file=sys.stderr)
        sys.exit(2)
    for key in ("t_end", "dt"):
        if not (math.isfinite(job[key]) and job[key] > 0.0):
            print(f"{argv[1]}: {key} = {job[key]} must be positive", file=sys.stderr)
            sys.exit(2)
    return job


def build_model(job, build):
    """`build(params, u)`, or exit with status 2 naming the refused parameter."""
    try:
        return build(job["params"], job["u"])
    except (KeyError, ValueError) as e:
        print(f"parameters refused: {e}", file=sys.stderr)
        sys.exit(2)


def grid_times(dt, t_end):
    """The output grid 0, dt, 2 dt, ... ending exactly at t_end (as rotor-model's OutputGrid).

    The last multiple of dt is snapped to t_end when within 1e-9 dt of it; otherwise t_end is
    appended as a shorter last interval. Returns a numpy array.
    """
    n = math.floor((t_end / dt) * (1.0 + 1e-12) + 1e-9)
    g = np.arange(n + 1) * dt
    if abs(g[-1] - t_end) <= 1e-9 * dt:
        g[-1] = t_end
    else:
        g = np.append(g, t_end)
    return g


def write_trace(path, grid, y):
    """The trace file: `y` is a 3 x len(grid) array of alpha, omega_u, omega_l."""
    with open(path, "w") as f:
        f.write("t,alpha,omega_u,omega_l\n")
        for k, t in enumerate(grid):
            f.write(f"{float(t)!r},{float(y[0][k])!r},{float(y[1][k])!r},{float(y[2][k])!r}\n")


def write_events(path, events):
    """The events file: `events` is a list of (t, disc, kind) in time order."""
    with open(path, "w") as f:
        f.write("t,disc,kind\n")
        for t, disc, kind in events:
            f.write(f"{float(t)!r},{disc},{kind}\n")


def timed(once):
    """`once()` and the seconds it took (time.perf_counter())."""
    start = time.perf_counter()
    result = once()
    return result, time.perf_counter() - start


def report(solve_seconds, version, method, steps=None, rhs_evals=None):
    """The one JSON line the benchmark reads from standard output."""
    out = {"solve_seconds": solve_seconds, "version": version, "method": method}
    if steps is not None:
        out["steps"] = steps
    if rhs_evals is not None:
        out["rhs_evals"] = rhs_evals
    print(json.dumps(out))


def build_plugin(source, workdir):
    """Compiles the C plugin `source` (a file beside the peer scripts) with cc into `workdir`;
    returns the shared library's path (built before any timing)."""
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), source)
    out = os.path.join(workdir, os.path.splitext(source)[0] + ".so")
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        raise RuntimeError("no C compiler (cc/gcc) to build the Siconos plugin")
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", out, src, "-lm"], check=True)
    return out


def on_grid(step_ends, a0, grid, h):
    """A fixed-step run sampled on `grid`: `step_ends` yields each step's end as (t, state),
    `a0` is the state at t = 0; a grid time gets the linear interpolation between the step
    ends around it (the last state after the last end). Returns (the dim x len(grid) array,
    the number of steps)."""
    y = np.empty((len(a0), len(grid)))
    i = 0
    while i < len(grid) and grid[i] <= 0.0:
        y[:, i] = a0
        i += 1
    t_a, a_a = 0.0, a0
    steps = 0
    for t_b, a_b in step_ends:
        steps += 1
        while i < len(grid) and grid[i] <= t_b + 1e-12 * h:
            s = (grid[i] - t_a) / (t_b - t_a)
            y[:, i] = a_a + s * (a_b - a_a)
            i += 1
        t_a, a_a = t_b, a_b
    while i < len(grid):
        y[:, i] = a_a
        i += 1
    return y, steps
