#!/usr/bin/env python3
"""What many people try first, as a rotorbench client: the set-valued friction law replaced by
a smooth one, Sign(omega) -> tanh(omega / eps), and the whole model handed to scipy's
solve_ivp (LSODA, as the regularised law is stiff near omega = 0). A teaching example for
BENCHMARK.md: it runs, it is fast, and it fails the gates, because the regularised disc never
sticks: in what should be a stick phase it creeps at omega_l ~ eps, the spring winds up at the
wrong rate, and the stick phases, the period and the transient all move.

    python3 tanh_regularised.py JOB.json      (eps: the environment variable TANH_EPS, 1e-3)
"""
import json, math, os, sys, time
import numpy as np
from scipy.integrate import solve_ivp

job = json.load(open(sys.argv[1]))
P, u, tol = job["params"], job["u"], job["tol"] or 1e-8
if job.get("input") is not None or u is None:
    sys.exit("this client takes a constant u only (the job's input changes in time)")
eps = float(os.environ.get("TANH_EPS", "1e-3"))
up, lo = P["upper"], P["lower"]
Ju, Jl, km, k = P["j_u"], P["j_l"], P["k_m"], P["k_theta"]

def level(x):  # friction level of the lower disc at |omega_l| = x
    if lo["family"] == "exponential":
        return lo["t_s"] + lo["t_1"] * math.tanh(lo["w_1"] * x / 2) + lo["t_2"] * math.tanh(lo["w_2"] * x / 2)
    return lo["t_c"] + (lo["t_s"] - lo["t_c"]) * math.exp(-abs(x / lo["omega_s"]) ** lo["delta"])

def f(t, x):
    a, wu, wl = x
    tu = up["dt_s"] + up["db"] * abs(wu) + up["b"] * wu + up["t_s"] * math.tanh(wu / eps)
    tl = lo["b"] * wl + level(abs(wl)) * math.tanh(wl / eps)
    return [wu - wl, (km * u - k * a - tu) / Ju, (k * a - tl) / Jl]

n = round(job["t_end"] / job["dt"])
grid = np.arange(n + 1) * job["dt"]
grid[-1] = job["t_end"]
start = time.perf_counter()
sol = solve_ivp(f, (0.0, job["t_end"]), job["x0"], "LSODA", grid, rtol=tol, atol=tol)
solve = time.perf_counter() - start
if sol.status != 0:
    sys.exit(f"solve_ivp failed: {sol.message}")
with open(job["trace"], "w") as out:
    out.write("t,alpha,omega_u,omega_l\n")
    out.writelines(f"{grid[j]:.17g},{sol.y[0, j]:.17g},{sol.y[1, j]:.17g},{sol.y[2, j]:.17g}\n" for j in range(n + 1))
print(json.dumps({"solve_seconds": solve, "rhs_evals": int(sol.nfev), "method": f"solve_ivp LSODA, tanh(omega/{eps:g})"}))
