#!/usr/bin/python3
"""A chain of N discs in Siconos (MoreauJeanOSI): the peer of the chain scaling benchmark.

The chain's Lagrangian form (docs/model.md §4a), set up as siconos_rotor.py sets up the rig:

    M q'' + F_int(q, q') = F_ext + r,   q = [theta_1 .. theta_N, x_1 .. x_N]
    M = diag(J_1 .. J_N, 1 .. 1),       F_ext = [k_m u, 0, ..., 0]

* one `LagrangianDS` with F_int and both Jacobians as a compiled C plugin
  (siconos_chain_plugin.c, built with cc into a temporary directory before timing);
* per disc with a friction level (a static level t_s > 0) a 2-D frictional contact:
  `LagrangianLinearTIR` with normal x_i and tangent theta_i,
  `NewtonImpactFrictionNSL(e_n = 0, e_t = 0, mu = 1)`; the level presses x_i onto it, so the
  normal reaction is the level and the tangential one the set-valued friction;
* `MoreauJeanOSI(theta = 1/2)`, `TimeStepping` with its Newton loop (the level implicit), and
  one `FrictionContact(2)` problem a step coupling every contact, solved by
  `SICONOS_FRICTION_2D_LEMKE`.

A client of the job-file protocol: `/usr/bin/python3 siconos_chain.py JOB.json` runs the
job's chain (its "params" in chain form: "k_m" and a "disc" list, each with "j", "k", "c" and
"friction") at the job's step h, writes the trace (header t,alpha_1,...,alpha_{N-1},
omega_1,...,omega_N; linear between step ends) and prints {"solve_seconds": S, "steps": N,
...}: time.perf_counter() around model construction and the time loop.
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

# A stuck step's velocity (Lemke solves exactly; see siconos_rotor.py's STICK_V).
STICK_V = 1e-14
FAMILIES = {"viscous": 0.0, "upper": 1.0, "exponential": 2.0, "stribeck": 3.0}
FIELDS = ["k", "c", "b", "t_s", "dt_s", "db", "t_1", "t_2", "w_1", "w_2", "t_c", "omega_s",
          "delta"]


class Chain:
    def __init__(self, params, u):
        discs = params["disc"]
        if len(discs) < 2:
            raise ValueError(f"disc: {len(discs)} discs, a chain has at least 2")
        self.n = len(discs)
        self.j = [d["j"] for d in discs]
        self.k_m = params["k_m"]
        self.u = u
        z = [float(self.n)]
        self.contact = []
        for i, d in enumerate(discs):
            f = d["friction"]
            fam = f["family"]
            if fam not in FAMILIES:
                raise ValueError(f"disc {i + 1}: friction.family = {fam!r}")
            values = {"k": d.get("k", 0.0), "c": d.get("c", 0.0), "omega_s": 1.0, "delta": 1.0}
            values.update({key: v for key, v in f.items() if key != "family"})
            z.append(FAMILIES[fam])
            z.extend(float(values.get(key, 0.0)) for key in FIELDS)
            self.contact.append(fam != "viscous" and values.get("t_s", 0.0) > 0.0)
        self.z = np.array(z)


def simulate(c, plugin, x0, t_end, h, grid):
    """One run. Returns (the (2N-1) x len(grid) solution on the grid, steps)."""
    n = c.n
    alpha0, omega0 = np.array(x0[: n - 1]), np.array(x0[n - 1 :])
    theta0 = np.zeros(n)
    for i in range(n - 2, -1, -1):
        theta0[i] = theta0[i + 1] + alpha0[i]
    q0 = np.concatenate([theta0, np.zeros(n)])
    v0 = np.concatenate([omega0, np.zeros(n)])
    ds = sk.LagrangianDS(q0, v0, np.diag(c.j + [1.0] * n))
    z = c.z.copy()
    ds.setzPtr(z)
    ds.setComputeFIntFunction(plugin, "chain_fint")
    ds.setComputeJacobianFIntqFunction(plugin, "chain_jac_q")
    ds.setComputeJacobianFIntqDotFunction(plugin, "chain_jac_v")
    fext = np.zeros(2 * n)
    fext[0] = c.k_m * c.u
    ds.setFExtPtr(fext)
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    nsds.insertDynamicalSystem(ds)
    for i in range(n):
        if not c.contact[i]:
            continue
        hm = np.zeros((2, 2 * n))
        hm[0, n + i] = 1.0
        hm[1, i] = 1.0
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
            a_b = np.empty(2 * n - 1)
            a_b[: n - 1] = [q[k] - q[k + 1] for k in range(n - 1)]
            a_b[n - 1 :] = [v[k] for k in range(n)]
            a_b[n - 1 :][np.abs(a_b[n - 1 :]) <= STICK_V] = 0.0
            yield sim.nextTime(), a_b
            sim.nextStep()

    return common.on_grid(step_ends(), np.concatenate([alpha0, omega0]), grid, h)


def write_trace(path, grid, y, n):
    names = [f"alpha_{k}" for k in range(1, n)] + [f"omega_{k}" for k in range(1, n + 1)]
    with open(path, "w") as f:
        f.write("t," + ",".join(names) + "\n")
        for k, t in enumerate(grid):
            f.write(",".join([repr(float(t))] + [repr(float(v)) for v in y[:, k]]) + "\n")


def main():
    job = common.read_job(sys.argv)
    h = job.get("h")
    if h is None or not (math.isfinite(h) and h > 0.0):
        print(f"the job's h = {h} must be positive (this client has a step)", file=sys.stderr)
        sys.exit(2)
    c = common.build_model(job, Chain)
    if len(job["x0"]) != 2 * c.n - 1:
        print(f"x0: {len(job['x0'])} values; a chain of {c.n} discs has {2 * c.n - 1}",
              file=sys.stderr)
        sys.exit(2)
    sn.numerics_set_verbose(0)
    grid = common.grid_times(job["dt"], job["t_end"])
    with tempfile.TemporaryDirectory() as workdir:
        plugin = common.build_plugin("siconos_chain_plugin.c", workdir)
        try:
            (y, steps), seconds = common.timed(
                lambda: simulate(c, plugin, job["x0"], job["t_end"], h, grid)
            )
        except Exception as e:  # Siconos raises its own exception types through SWIG
            print(f"the simulation failed: {type(e).__name__}: {e}", file=sys.stderr)
            sys.exit(1)
    write_trace(job["trace"], grid, y, c.n)
    try:
        version = metadata.version("siconos")
    except metadata.PackageNotFoundError:
        version = "unknown"
    common.report(
        seconds, version, "MoreauJeanOSI theta=1/2, FrictionContact(2) Lemke", steps=steps
    )


if __name__ == "__main__":
    main()
