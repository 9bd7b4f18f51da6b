#!/usr/bin/python3
"""The rotorbench rotor model in Siconos (MoreauJeanOSI): a peer for `rotor-bench`.

The Lagrangian form of section 3 of the source (docs/model.md; rotor-model's
lagrangian.rs), as a Siconos user would set it up:

    M q'' + F_int(q, q') = F_ext + r,      q = [theta_u, theta_l, x_u, x_l]
    M = diag(J_u, J_l, 1, 1),  F_ext = [k_m u, 0, 0, 0],
    F_int = [b_u v_u + k_theta alpha (+ dT_su + db_u |v_u|),  b_l v_l - k_theta alpha,
             T_su,  N_l(|v_l|)]

* one `LagrangianDS` with F_int and both Jacobians as a compiled C plugin
  (siconos_rotor_plugin.c, built with gcc into a temporary directory before timing);
* per disc with a friction level (the lower always, the upper if T_su > 0) a 2-D frictional
  contact: `LagrangianLinearTIR` with normal x_i and tangent theta_i,
  `NewtonImpactFrictionNSL(e_n = 0, e_t = 0, mu = 1)`; the x_i DOF is pressed onto it by the
  level, so the normal reaction equals the level and the tangential one is the set-valued
  friction;
* `MoreauJeanOSI(theta = 1/2)`, `TimeStepping` with its Newton loop (the friction level is
  implicit, inside the Newton iterations, as in rotor-moreau's default), one-step problem
  `FrictionContact(2)` solved by `SICONOS_FRICTION_2D_LEMKE` (Lemke was the clean
  one-step solver on this model; NSGS printed warnings, the 2-D enumeration gave wrong
  dynamics).

Events and metrics from the steps, as rotor-moreau locates them: the lower disc is stuck on
a step when |theta_l'| <= STICK_V; a stick exit is located where k_theta alpha crosses the
stick bound by linear interpolation over the step it leaves stick on; omega_l maxima by the
vertex of the parabola through three slipping steps. Metrics of the last complete cycle
between two stick exits in [metrics_from, t_end]. The 0.01 s trace is the linear
interpolation of the step ends.

Prints one JSON object on stdout with each setting's run times (time.perf_counter() around
model construction and the whole time loop, after one untimed warm-up; plugin compilation
and interpreter start-up excluded) and its number of steps.

    /usr/bin/python3 siconos_rotor.py --params ../../fixtures/params/table1.toml --u 1.5 \
        --x0 0,0,0 --t-end 100 --metrics-from 50 --transient 0,20 --dt 0.01 --h 1e-2,1e-3
"""

import os
import shutil
import subprocess
import sys
import tempfile
from importlib import metadata

import numpy as np
import siconos.kernel as sk
import siconos.numerics as sn

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peer_common as common  # noqa: E402  (shared set-up, next to this script)

# A stuck step's tangential velocity: Lemke solves the 2x2 problem exactly, and stuck
# velocities came out at |theta_l'| <= 2e-18 rad/s in trial runs; the first slipping step
# after a (tangential) stick exit has theta_l' ~ (k_theta omega_u / 2 J_l) h^2 >= 7e-11 rad/s
# at h = 1e-5. 1e-14 separates the two by three decades on both sides.
STICK_V = 1e-14


def build_plugin(workdir):
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "siconos_rotor_plugin.c")
    out = os.path.join(workdir, "siconos_rotor_plugin.so")
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        raise RuntimeError("no C compiler (cc/gcc) to build the Siconos plugin")
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", out, src, "-lm"], check=True)
    return out


class Params:
    def __init__(self, params, u):
        self.j_u = params["j_u"]
        self.j_l = params["j_l"]
        self.k_m = params["k_m"]
        self.k_theta = params["k_theta"]
        up, lo = params["upper"], params["lower"]
        self.t_su = up["t_s"]
        family = lo["family"]
        if family not in ("exponential", "stribeck"):
            raise ValueError(f"lower.family = {family!r}: expected exponential or stribeck")
        self.t_sl = lo["t_s"]
        self.u = u
        # z vector of the plugin (see siconos_rotor_plugin.c).
        self.z = np.array(
            [
                self.k_theta,
                up["b"],
                lo["b"],
                up["t_s"],
                up["dt_s"],
                up["db"],
                0.0 if family == "exponential" else 1.0,
                lo["t_s"],
                lo.get("t_1", 0.0),
                lo.get("t_2", 0.0),
                lo.get("w_1", 0.0),
                lo.get("w_2", 0.0),
                lo.get("t_c", 0.0),
                lo.get("omega_s", 1.0),
                lo.get("delta", 1.0),
            ]
        )


def simulate(p, plugin, x0, t_end, h, grid):
    """One run. Returns (omega_l on the grid, exit times, maxima, steps)."""
    alpha0, wu0, wl0 = x0
    q0 = np.array([alpha0, 0.0, 0.0, 0.0])
    v0 = np.array([wu0, wl0, 0.0, 0.0])
    ds = sk.LagrangianDS(q0, v0, np.diag([p.j_u, p.j_l, 1.0, 1.0]))
    z = p.z.copy()
    ds.setzPtr(z)
    ds.setComputeFIntFunction(plugin, "rotor_fint")
    ds.setComputeJacobianFIntqFunction(plugin, "rotor_jac_q")
    ds.setComputeJacobianFIntqDotFunction(plugin, "rotor_jac_v")
    ds.setFExtPtr(np.array([p.k_m * p.u, 0.0, 0.0, 0.0]))
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    nsds.insertDynamicalSystem(ds)
    contacts = [(3, 1)] + ([(2, 0)] if p.t_su > 0.0 else [])  # (normal x_i, tangent theta_i)
    for normal, tangent in contacts:
        hm = np.zeros((2, 4))
        hm[0, normal] = 1.0
        hm[1, tangent] = 1.0
        inter = sk.Interaction(
            sk.NewtonImpactFrictionNSL(0.0, 0.0, 1.0, 2), sk.LagrangianLinearTIR(hm)
        )
        nsds.link(inter, ds)
    osi = sk.MoreauJeanOSI(0.5)
    td = sk.TimeDiscretisation(0.0, h)
    osnspb = sk.FrictionContact(2, sn.SICONOS_FRICTION_2D_LEMKE)
    sim = sk.TimeStepping(nsds, td, osi, osnspb)
    sim.setNewtonTolerance(1e-12)
    sim.setNewtonMaxIteration(50)

    q = ds.q()
    v = ds.velocity()
    kt, bound = p.k_theta, p.t_sl
    omega_l = np.empty(len(grid))
    i = 0
    while i < len(grid) and grid[i] <= 0.0:
        omega_l[i] = wl0
        i += 1
    # Previous two step ends: (t, omega_l, spring torque excess).
    t_a, w_a, g_a = 0.0, wl0, kt * alpha0 - bound
    prev = None  # the step end before (t_a, w_a)
    exits, maxima = [], []
    steps = 0
    while sim.hasNextEvent():
        sim.computeOneStep()
        steps += 1
        t_b = sim.nextTime()
        w_b = v[1]
        g_b = kt * (q[0] - q[1]) - bound
        while i < len(grid) and grid[i] <= t_b + 1e-12 * h:
            s = (grid[i] - t_a) / (t_b - t_a)
            omega_l[i] = w_a + s * (w_b - w_a)
            i += 1
        stuck_a, stuck_b = abs(w_a) <= STICK_V, abs(w_b) <= STICK_V
        if stuck_a and not stuck_b and w_b > 0.0:
            # Leaves stick upward: zero of the torque excess on the line through the two ends.
            if g_b > g_a:
                t_x = t_a - g_a * (t_b - t_a) / (g_b - g_a)
                t_x = min(max(t_x, prev[0] if prev else t_a), t_b)
            else:
                t_x = t_a + 0.5 * (t_b - t_a)
            exits.append(t_x)
        if prev is not None and not stuck_a and not stuck_b and abs(prev[1]) > STICK_V:
            t_0, w_0 = prev[0], prev[1]
            d1, d2 = w_a - w_0, w_b - w_a
            if d1 > 0.0 and d2 <= 0.0:
                # Vertex of the parabola through the three step ends.
                ha, hb = t_a - t_0, t_b - t_a
                s1, s2 = d1 / ha, d2 / hb
                curv = (s2 - s1) / (0.5 * (ha + hb))
                tm = t_0 + 0.5 * ha - s1 / curv if curv != 0.0 else t_a
                tm = min(max(tm, t_0), t_b)
                la = (tm - t_a) * (tm - t_b) / ((t_0 - t_a) * (t_0 - t_b))
                lb = (tm - t_0) * (tm - t_b) / ((t_a - t_0) * (t_a - t_b))
                lc = (tm - t_0) * (tm - t_a) / ((t_b - t_0) * (t_b - t_a))
                maxima.append((tm, w_0 * la + w_a * lb + w_b * lc))
        prev = (t_a, w_a)
        t_a, w_a, g_a = t_b, w_b, g_b
        sim.nextStep()
    while i < len(grid):
        omega_l[i] = w_a
        i += 1
    return omega_l, exits, maxima, steps


def run_setting(p, plugin, args, grid, window, h):
    """Time one step size and return its entry of "runs" (a failed run's reason if it raised)."""
    try:
        (omega_l, exits, maxima, steps), seconds = common.time_runs(
            lambda: simulate(p, plugin, args.x0, args.t_end, h, grid),
            args.repeat,
            args.time_budget,
        )
    except Exception as e:  # Siconos raises its own exception types through SWIG
        return common.failed_record(h, f"{type(e).__name__}: {e}")
    metrics = common.cycle_metrics(exits, maxima, args.metrics_from)
    return common.run_record(h, seconds, metrics, grid, omega_l, window, steps=steps)


def main():
    ap = common.make_parser(
        __doc__.splitlines()[0], "--h", "step sizes, comma-separated", repeat_default=3
    )
    args = common.parse_args(ap)
    p = common.load_model(args, Params)
    sn.numerics_set_verbose(0)
    grid = common.grid_times(args.dt, args.t_end)
    window = common.trace_window(grid, args.transient, args.dt)
    with tempfile.TemporaryDirectory() as workdir:
        plugin = build_plugin(workdir)
        runs = [run_setting(p, plugin, args, grid, window, h) for h in args.h]
    try:
        version = metadata.version("siconos")
    except metadata.PackageNotFoundError:
        version = "unknown"
    common.emit("siconos", version, "MoreauJeanOSI theta=1/2, FrictionContact(2) Lemke", runs)


if __name__ == "__main__":
    main()
