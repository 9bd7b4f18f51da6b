#!/usr/bin/python3
"""The rotorbench rotor model in Siconos (MoreauJeanOSI): a peer for `rotor_harness::bench`.

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

A client of the benchmark's job-file protocol: `/usr/bin/python3 siconos_rotor.py JOB.json`
runs the job's scene at the job's step h, writes the trace (alpha = theta_u - theta_l,
omega_u, omega_l at the grid times, linear between step ends; no events file: a step end is
no event time) and prints {"solve_seconds": S, "steps": N, ...}: time.perf_counter() around
model construction and the time loop (plugin compilation, interpreter start-up, reading the
job and writing the trace excluded).
"""

import math
import os
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
    """One run. Returns (the 3 x len(grid) solution on the grid, steps)."""
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

    def step_ends():
        while sim.hasNextEvent():
            sim.computeOneStep()
            a_b = np.array([q[0] - q[1], v[0], v[1]])
            if abs(a_b[2]) <= STICK_V:
                a_b[2] = 0.0
            yield sim.nextTime(), a_b
            sim.nextStep()

    return common.on_grid(step_ends(), np.array([alpha0, wu0, wl0]), grid, h)


def main():
    job = common.read_job(sys.argv)
    h = job.get("h")
    if h is None or not (math.isfinite(h) and h > 0.0):
        print(f"the job's h = {h} must be positive (this client has a step)", file=sys.stderr)
        sys.exit(2)
    p = common.build_model(job, Params)
    sn.numerics_set_verbose(0)
    grid = common.grid_times(job["dt"], job["t_end"])
    with tempfile.TemporaryDirectory() as workdir:
        plugin = common.build_plugin("siconos_rotor_plugin.c", workdir)
        try:
            (y, steps), seconds = common.timed(
                lambda: simulate(p, plugin, job["x0"], job["t_end"], h, grid)
            )
        except Exception as e:  # Siconos raises its own exception types through SWIG
            print(f"the simulation failed: {type(e).__name__}: {e}", file=sys.stderr)
            sys.exit(1)
    common.write_trace(job["trace"], grid, y)
    try:
        version = metadata.version("siconos")
    except metadata.PackageNotFoundError:
        version = "unknown"
    common.report(
        seconds, version, "MoreauJeanOSI theta=1/2, FrictionContact(2) Lemke", steps=steps
    )


if __name__ == "__main__":
    main()
