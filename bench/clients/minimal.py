#!/usr/bin/env python3
"""A minimal rotorbench client (BENCHMARK.md): python3 minimal.py JOB.json"""
import json, math, sys, time
import numpy as np
from scipy.integrate import solve_ivp

job = json.load(open(sys.argv[1]))
P, tol = job["params"], job["tol"] or 1e-10
R = job.get("input") or [[0.0, job["u"]]]  # u(t): rows [t, u], linear between; a step where two share a t
up, lo = P["upper"], P["lower"]
if up["t_s"] or up["dt_s"] or up["db"]:
    sys.exit("this client needs a smooth upper disc (upper t_s = dt_s = db = 0)")
Ju, Jl, km, k, Ts = P["j_u"], P["j_l"], P["k_m"], P["k_theta"], lo["t_s"]
def level(x):  # friction level of the lower disc at x = s * omega_l, smooth past 0
    if lo["family"] == "exponential":
        return Ts + lo["t_1"] * math.tanh(lo["w_1"] * x / 2) + lo["t_2"] * math.tanh(lo["w_2"] * x / 2)
    return lo["t_c"] + (Ts - lo["t_c"]) * math.exp(-abs(x / lo["omega_s"]) ** lo["delta"])
def piece(t):  # (t_a, u_a, slope, end): the linear piece of u(t) that holds from t on
    n = sum(r[0] <= t for r in R); a, b = R[max(n - 1, 0)], R[n] if n < len(R) else None
    return (a[0], a[1], 0.0, a[0]) if n == 0 else (a[0], a[1], (b[1] - a[1]) / (b[0] - a[0]) if b and b[1] != a[1] else 0.0, b[0] if b else math.inf)
def field(s, p):  # s = +1 / -1: the lower disc slips on that branch; s = 0: it sticks
    def f(t, x):
        dwl = (k * x[0] - lo["b"] * x[2] - s * level(s * x[2])) / Jl if s else 0.0
        return [x[1] - x[2], (km * (p[1] + p[2] * (t - p[0])) - k * x[0] - up["b"] * x[1]) / Ju, dwl]
    return f
def event(g, direction):  # a terminal event function with its crossing direction
    g.terminal, g.direction = True, direction
    return g
def mode(a, wl):  # slip by the sign of omega_l; at 0, stick while |k alpha| <= T_s
    return math.copysign(1, wl) if wl else (0 if abs(k * a) <= Ts else math.copysign(1, k * a))
n = round(job["t_end"] / job["dt"])
grid = np.arange(n + 1) * job["dt"]
grid[-1] = job["t_end"]
y, events, x, t, i = np.zeros((3, n + 1)), [], list(job["x0"]), 0.0, 0
s, start = mode(x[0], x[2]), time.perf_counter()
while True:
    evs = [event(lambda t, x: x[2], -s)] if s else [
        event(lambda t, x: k * x[0] - Ts, 1), event(lambda t, x: k * x[0] + Ts, -1)]
    p = piece(t); stop = min(p[3], job["t_end"]); te = grid[i:][grid[i:] <= stop]  # no step past a breakpoint
    at = te if len(te) and te[-1] == stop else np.append(te, stop)
    sol = solve_ivp(field(s, p), (t, stop), x, "DOP853", at, events=evs, rtol=tol, atol=tol)
    m = min(len(sol.t), len(te)); y[:, i:i + m] = sol.y[:, :m]; i += m
    if sol.status == 0 and stop >= job["t_end"]: break
    if sol.status == 0:  # a breakpoint of u: restart there on the next piece
        t, x = stop, [float(v) for v in sol.y[:, -1]]; continue
    j = next(j for j, te in enumerate(sol.t_events) if len(te))
    t, x = float(sol.t_events[j][0]), [float(v) for v in sol.y_events[j][0]]
    x[2], was = 0.0, s
    s = mode(x[0], 0.0) if was else (1 if j == 0 else -1)
    events.append((t, "stick_end" if not was else "stick_start" if s == 0 else "reversal"))
solve = time.perf_counter() - start
with open(job["trace"], "w") as f:
    f.write("t,alpha,omega_u,omega_l\n")
    f.writelines(f"{grid[k]:.17g},{y[0, k]:.17g},{y[1, k]:.17g},{y[2, k]:.17g}\n" for k in range(n + 1))
with open(job["events"], "w") as f:
    f.write("t,disc,kind\n")
    f.writelines(f"{te:.17g},lower,{kind}\n" for te, kind in events)
print(json.dumps({"solve_seconds": solve}))
