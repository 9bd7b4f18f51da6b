"""What the rotorbench peer scripts share: command line, output grid, metrics, timing, JSON.

Used by scipy_rotor.py and siconos_rotor.py (each inserts its own directory at the front of
sys.path before importing this module, so they run from any working directory). Standard
library and numpy only: it imports without scipy or Siconos installed.

The JSON written by `emit` is parsed by crates/rotor-bench/src/peers.rs (`PeerOutput`,
`PeerRun`, `PeerMetrics`); its keys must stay as they are.
"""

import argparse
import json
import math
import sys
import time
import tomllib

import numpy as np


def floats(text):
    """Parse a comma-separated list of numbers ("0,0.5,1e-3") into a list of floats.

    Used as an argparse `type`, so a malformed value becomes a usage error.
    """
    return [float(v) for v in text.split(",")]


def make_parser(description, setting_flag, setting_help, repeat_default):
    """The argument parser common to the peers, with one peer-specific accuracy ladder.

    Adds --params, --u, --x0, --t-end, --metrics-from, --transient, --dt, then the ladder
    `setting_flag` (a required comma-separated list, e.g. --tol or --h, described by
    `setting_help`), then --repeat (default `repeat_default`) and --time-budget, in this
    order so that --help lists them as before. A peer may add its own options afterwards;
    parse with `parse_args`.
    """
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--params", required=True, help="parameter TOML file (fixtures/params)")
    ap.add_argument("--u", type=float, required=True, help="motor input [V]")
    ap.add_argument("--x0", type=floats, default=[0.0, 0.0, 0.0], help="alpha,omega_u,omega_l")
    ap.add_argument("--t-end", type=float, required=True, help="horizon [s]")
    ap.add_argument("--metrics-from", type=float, required=True, help="metrics window start [s]")
    ap.add_argument("--transient", type=floats, required=True, help="t0,t1 of the printed trace")
    ap.add_argument("--dt", type=float, default=0.01, help="trace grid step [s]")
    ap.add_argument(setting_flag, type=floats, required=True, help=setting_help)
    ap.add_argument(
        "--repeat", type=int, default=repeat_default, help="timed runs per setting (median)"
    )
    ap.add_argument("--time-budget", type=float, default=3.0, help="seconds of timing per setting")
    return ap


def parse_args(ap):
    """Parse the command line with `ap` and check the list lengths of --x0 and --transient.

    Exits with argparse's usage error (status 2) unless --x0 has 3 values and --transient 2.
    """
    args = ap.parse_args()
    if len(args.x0) != 3 or len(args.transient) != 2:
        ap.error("--x0 needs 3 values and --transient 2")
    # The ladder (--tol or --h) and the horizon must be positive and finite: a negative
    # step would make a time-stepping peer loop forever.
    for name, values in (("--tol", getattr(args, "tol", None)), ("--h", getattr(args, "h", None)),
                         ("--t-end", [args.t_end]), ("--dt", [args.dt])):
        for v in values or []:
            if not (math.isfinite(v) and v > 0.0):
                ap.error(f"{name} must be positive and finite, got {v}")
    return args


def load_model(args, build):
    """Read the parameter TOML of --params and return `build(params, args.u)`.

    `build` is the peer's model constructor (a dict of the TOML and the motor input); a
    KeyError (missing parameter) or ValueError (parameters the peer refuses) is reported on
    stderr as "<params file>: <message>" and the process exits with status 2.
    """
    with open(args.params, "rb") as f:
        params = tomllib.load(f)
    try:
        return build(params, args.u)
    except (KeyError, ValueError) as e:
        print(f"{args.params}: {e}", file=sys.stderr)
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


def trace_window(grid, transient, dt):
    """Indices of the grid points inside the printed trace [t0, t1] = `transient`.

    The bounds are widened by 1e-9 dt so that grid points equal to t0 or t1 up to rounding
    are included.
    """
    t0, t1 = transient
    eps = 1e-9 * dt
    return [k for k, t in enumerate(grid) if t0 - eps <= t <= t1 + eps]


def cycle_metrics(exits, maxima, t_from, maxima_fallback=False):
    """Period and largest omega_l of the last complete cycle in [t_from, ...], or None.

    `exits` are stick exit times and `maxima` (t, omega_l) pairs at the located omega_l
    maxima. The cycle runs between the last two stick exits at or after t_from. With
    `maxima_fallback`, an orbit with fewer than two such exits is measured between its last
    two maxima instead (an orbit that never sticks). omega_l_max is the largest maximum in
    the cycle, and at least 0 (omega_l at a stick exit) whenever the run had two stick exits.
    Returns {"period": ..., "omega_l_max": ...}, or None if no cycle was found.
    """
    anchors = [t for t in exits if t >= t_from]
    if len(anchors) < 2 and maxima_fallback:
        anchors = [t for t, _ in maxima if t >= t_from]
    if len(anchors) < 2:
        return None
    a, b = anchors[-2], anchors[-1]
    peaks = [w for t, w in maxima if a <= t <= b]
    if len(exits) >= 2:
        peaks.append(0.0)
    return {"period": b - a, "omega_l_max": max(peaks)}


def time_runs(once, repeat, time_budget):
    """Time the simulation `once()`; return (result of its first call, list of seconds).

    The first call is a warm-up: its time is reported only if it alone takes `time_budget`
    seconds or more (then it is the only time). Otherwise `once()` runs
    max(1, min(repeat, time_budget / first)) more times, each timed with time.perf_counter(),
    and those times are reported (the caller takes their median). Exceptions from `once()`
    propagate to the caller.
    """
    start = time.perf_counter()
    result = once()
    first = time.perf_counter() - start
    seconds = []
    if first >= time_budget:
        seconds.append(first)
    else:
        n = max(1, min(repeat, int(time_budget / max(first, 1e-9))))
        for _ in range(n):
            start = time.perf_counter()
            once()
            seconds.append(time.perf_counter() - start)
    return result, seconds


def run_record(setting, seconds, metrics, grid, omega_l, window, steps=None, rhs_evals=None):
    """One successful entry of "runs" (a `PeerRun` in peers.rs).

    `setting` is the ladder value (rtol = atol, or h), `seconds` the timed runs, `metrics` the
    result of `cycle_metrics`, `omega_l` the solution on `grid`, of which the points with
    indices `window` are written as the trace; `steps` and `rhs_evals` are the counters the
    peer has (None otherwise).
    """
    return {
        "setting": setting,
        "seconds": seconds,
        "metrics": metrics,
        "steps": steps,
        "rhs_evals": rhs_evals,
        "t": [float(grid[k]) for k in window],
        "omega_l": [float(omega_l[k]) for k in window],
        "failure": None,
    }


def failed_record(setting, failure):
    """The entry of "runs" for a setting whose simulation raised: no times, no trace, and
    the reason `failure` (a string)."""
    return {
        "setting": setting,
        "seconds": [],
        "metrics": None,
        "steps": None,
        "rhs_evals": None,
        "t": [],
        "omega_l": [],
        "failure": failure,
    }


def emit(peer, version, method, runs):
    """Print the peer's JSON object ({"peer", "version", "method", "runs"}) and a newline on
    stdout: the one thing rotor-bench reads."""
    json.dump({"peer": peer, "version": version, "method": method, "runs": runs}, sys.stdout)
    print()
