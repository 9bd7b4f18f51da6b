#!/usr/bin/env python3
"""Grade a scipy `solve_ivp` solution of the rotor with `rotorbench.check`.

The quickest way to a solution in scipy is to smooth the friction law's sign function,
sgn(w) ~ tanh(w / eps), and hand the now smooth (but stiff) system to an implicit integrator.
This script does that for a benchmark scenario and asks rotorbench how good the answer is:
every quantity the scenario grades (every sample, the stick intervals, the steady-state period,
extrema, stick time and orbit), its difference from the reference, the tolerance of the level
and the correct digits. A smoothed model creeps where the true one sticks, so expect its stick
intervals to be missing and the samples near stick to be what fails first; shrink EPS and
watch the run time grow.

Run after `pip install ./crates/rotor-py scipy`:

    python3 examples/python/grade_scipy.py [SCENARIO] [EPS]

SCENARIO is a benchmark scenario's name (default t1-u1.5-rest); EPS the smoothing velocity in
rad/s (default 1e-4).
"""

import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

import rotorbench

name = sys.argv[1] if len(sys.argv) > 1 else "t1-u1.5-rest"
eps = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-4
sc = rotorbench.scenario(name)
p = sc["params"]
lo, up = p["lower"], p["upper"]
if lo["family"] != "exponential" or up["t_s"] != 0.0:
    sys.exit(f"{name}: this example smooths Table 1's law (exponential lower disc, smooth upper)")


def level(w):
    """The lower disc's friction level T_cl(|w|) without the viscous part (docs/model.md)."""
    a = abs(w)
    return (
        lo["t_s"]
        + lo["t_1"] * (1.0 - 2.0 / (1.0 + math.exp(lo["w_1"] * a)))
        + lo["t_2"] * (1.0 - 2.0 / (1.0 + math.exp(lo["w_2"] * a)))
    )


def rhs(t, x):
    alpha, w_u, w_l = x
    spring = p["k_theta"] * alpha
    friction_l = lo["b"] * w_l + level(w_l) * math.tanh(w_l / eps)
    return [
        w_u - w_l,
        (p["k_m"] * sc["u"] - spring - up["b"] * w_u) / p["j_u"],
        (spring - friction_l) / p["j_l"],
    ]


n = round(sc["t_end"] / sc["dt"])
grid = np.linspace(0.0, sc["t_end"], n + 1)  # the scenario's grid: every dt from 0 to t_end
t0 = time.perf_counter()
sol = solve_ivp(rhs, (0.0, sc["t_end"]), sc["x0"], method="LSODA", t_eval=grid, rtol=1e-8, atol=1e-10)
seconds = time.perf_counter() - t0
if not sol.success:
    sys.exit(f"solve_ivp failed: {sol.message}")
alpha, w_u, w_l = sol.y
print(f"{name}: solve_ivp LSODA, tanh smoothing eps = {eps:g} rad/s, {seconds:.2f} s, {sol.nfev} evaluations")

for gate in ("loose", "strict"):
    v = rotorbench.check(name, grid, alpha, w_u, w_l, gate=gate)
    print(f"\n{gate} gate: {'PASSED' if v['passed'] else 'FAILED'}")
    print(f"  {'quantity':<18} {'difference':>11} {'tolerance':>11} {'digits':>6}")
    for q in v["quantities"]:
        mark = "" if q["passed"] else "  <- fails"
        # difference is None where it cannot be measured (JSON null: a missing stick
        # interval or event, another kind of steady state); its digits are then 0
        diff = "unmatched" if q["difference"] is None else f"{q['difference']:.2e}"
        print(f"  {q['name']:<18} {diff:>11} {q['tolerance']:>11.2e} {q['digits']:>6.1f}{mark}")

t0 = time.perf_counter()
ref = rotorbench.simulate("event", sc["u"], p, sc["x0"], sc["t_end"], sc["dt"])
seconds = time.perf_counter() - t0
v = rotorbench.check(name, ref["t"], ref["alpha"], ref["omega_u"], ref["omega_l"], gate="strict", events=ref["events"])
print(f"\nfor comparison, rotorbench's event-driven solver (tol 1e-10, {1e3 * seconds:.1f} ms): "
      f"strict gate {'PASSED' if v['passed'] else 'FAILED'}")
