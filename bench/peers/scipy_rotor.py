#!/usr/bin/env python3
"""The rotorbench rotor model in plain scipy: a peer client of `rotor bench` (BENCHMARK.md).

What a careful scipy user would write for the two-disc rotor with set-valued friction
(docs/model.md): state x = [alpha, omega_u, omega_l],

    alpha'         = omega_u - omega_l
    J_u omega_u'   = k_m u - k_theta alpha - T_fu(omega_u)
    J_l omega_l'   =         k_theta alpha - T_fl(omega_l)

integrated with `scipy.integrate.solve_ivp` (DOP853 by default) piece by piece between
events, switching vector fields at the events (Filippov's solution for this one switching
surface):

* slip on branch s = +1 / -1 (sign of omega_l): the friction law of the branch,
  T_fl = b_l omega + s N(s omega), with N the friction level of docs/model.md continued
  smoothly past omega = 0 so that the event function is smooth across its root;
  terminal event omega_l = 0 (direction -s);
* at omega_l = 0: stick if |k_theta alpha| <= N(0) = T_sl (the spring torque is inside the
  stick interval), else the disc reverses and slips on the other branch;
* stick: omega_l = 0 and omega_l' = 0 (the friction takes the spring torque: the equivalent
  control); terminal events k_theta alpha = +T_sl (exit to s = +1) and -T_sl (exit to s = -1);
* non-terminal event omega_l' = 0 from above (a maximum of omega_l) while slipping, for the
  steady-state metrics.

The upper disc must be smooth (Table 1: T_su = dT_su = db_u = 0, so T_fu = b_u omega_u);
a parameter file with upper static friction is refused (it needs a second switching surface).
The lower disc may use either family of docs/model.md (exponential: Table 1; stribeck).

A client of the benchmark's job-file protocol: `python3 scipy_rotor.py JOB.json` integrates
the job's scene at rtol = atol = the job's tol, writes the trace (alpha, omega_u, omega_l on
the grid) and the events it locates (stick onsets and exits, reversals of the lower disc),
and prints {"solve_seconds": S, ...}: time.perf_counter() around the simulation alone
(interpreter start-up, imports, reading the job and writing the files excluded).
"""

import math
import os
import sys

import numpy as np
import scipy
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peer_common as common  # noqa: E402  (shared set-up, next to this script)


class Rotor:
    """Parameters and the vector fields of each mode."""

    def __init__(self, params, u):
        self.j_u = params["j_u"]
        self.j_l = params["j_l"]
        self.k_m = params["k_m"]
        self.k_theta = params["k_theta"]
        up = params["upper"]
        for key in ("t_s", "dt_s", "db"):
            if up.get(key, 0.0) != 0.0:
                raise ValueError(
                    f"upper.{key} = {up[key]}: this peer implements a smooth upper disc "
                    "(T_su = dT_su = db_u = 0, as Table 1); upper static friction needs a "
                    "second switching surface"
                )
        self.b_u = up["b"]
        lo = params["lower"]
        self.family = lo["family"]
        self.b_l = lo["b"]
        self.t_sl = lo["t_s"]
        if self.family == "exponential":
            self.t_1, self.t_2 = lo["t_1"], lo["t_2"]
            self.w_1, self.w_2 = lo["w_1"], lo["w_2"]
        elif self.family == "stribeck":
            self.t_cl = lo["t_c"]
            self.omega_s = lo["omega_s"]
            self.delta = lo["delta"]
        else:
            raise ValueError(f"lower.family = {self.family!r}: expected exponential or stribeck")
        if self.t_sl <= 0.0:
            raise ValueError(f"lower.t_s = {self.t_sl}: the lower disc must have static friction")
        self.drive = self.k_m * u

    def level(self, x):
        """Friction level N(x) of the lower disc, x = s*omega (x >= 0 on the branch).

        Exponential (docs/model.md): T_sl + T_1 (1 - 2/(1 + e^{w_1 x})) + T_2 (1 - 2/(1 + e^{w_2 x})),
        written with 1 - 2/(1 + e^y) = tanh(y/2), which is odd in x: a smooth continuation.
        Stribeck: T_cl + (T_sl - T_cl) exp(-|x/omega_s|^delta) (even in x).
        """
        if self.family == "exponential":
            return (
                self.t_sl
                + self.t_1 * math.tanh(0.5 * self.w_1 * x)
                + self.t_2 * math.tanh(0.5 * self.w_2 * x)
            )
        return self.t_cl + (self.t_sl - self.t_cl) * math.exp(-abs(x / self.omega_s) ** self.delta)

    def upper_accel(self, alpha, w_u):
        return (self.drive - self.k_theta * alpha - self.b_u * w_u) / self.j_u

    def lower_accel(self, alpha, w_l, s):
        friction = self.b_l * w_l + s * self.level(s * w_l)
        return (self.k_theta * alpha - friction) / self.j_l

    def slip(self, s):
        def f(t, x):
            alpha, w_u, w_l = x
            return [w_u - w_l, self.upper_accel(alpha, w_u), self.lower_accel(alpha, w_l, s)]

        return f

    def stick(self, t, x):
        alpha, w_u, _ = x
        return [w_u, self.upper_accel(alpha, w_u), 0.0]


def slip_events(rotor, s):
    """Terminal omega_l = 0 (leaving branch s), and omega_l maxima (non-terminal)."""

    def zero(t, x):
        return x[2]

    zero.terminal = True
    zero.direction = -s

    def peak(t, x):
        return rotor.lower_accel(x[0], x[2], s)

    peak.terminal = False
    peak.direction = -1.0
    return [zero, peak]


def stick_events(rotor):
    """Terminal: the spring torque k_theta alpha reaches +T_sl or -T_sl."""

    def exit_hi(t, x):
        return rotor.k_theta * x[0] - rotor.t_sl

    exit_hi.terminal = True
    exit_hi.direction = 1.0

    def exit_lo(t, x):
        return rotor.k_theta * x[0] + rotor.t_sl

    exit_lo.terminal = True
    exit_lo.direction = -1.0
    return [exit_hi, exit_lo]


def initial_mode(rotor, x):
    """As rotor-model's Model::mode_at: slip by the sign of omega_l, else stick if the spring
    torque is inside the stick interval, else slip the way it pushes."""
    if x[2] > 0.0:
        return 1.0
    if x[2] < 0.0:
        return -1.0
    torque = rotor.k_theta * x[0]
    return 0.0 if abs(torque) <= rotor.t_sl else math.copysign(1.0, torque)


def simulate(rotor, x0, t_end, grid, tol, method):
    """One run: returns (the 3 x len(grid) solution on the grid, events, rhs evaluations)."""
    t = 0.0
    x = list(x0)
    mode = initial_mode(rotor, x)
    y = np.empty((3, len(grid)))
    i = 0  # next grid sample
    events = []  # (t, disc, kind)
    nfev = 0
    segments = 0
    while t < t_end:
        segments += 1
        if segments > 100_000:
            raise RuntimeError(f"more than 100000 segments by t = {t}: Zeno-like switching")
        if mode == 0.0:
            fun, evs = rotor.stick, stick_events(rotor)
        else:
            fun, evs = rotor.slip(mode), slip_events(rotor, mode)
        sol = solve_ivp(
            fun,
            (t, t_end),
            x,
            method=method,
            t_eval=grid[i:],
            events=evs,
            rtol=tol,
            atol=tol,
        )
        if sol.status < 0:
            raise RuntimeError(f"solve_ivp failed at t = {t}: {sol.message}")
        nfev += sol.nfev
        n = len(sol.t)
        y[:, i : i + n] = sol.y
        if mode == 0.0:
            y[2, i : i + n] = 0.0
        i += n
        if sol.status == 0:  # reached t_end
            break
        # A terminal event ended the segment.
        hit = [k for k, te in enumerate(sol.t_events) if evs[k].terminal and len(te)]
        k = hit[0]
        t = float(sol.t_events[k][-1])
        x = [float(v) for v in sol.y_events[k][-1]]
        x[2] = 0.0
        if mode == 0.0:
            events.append((t, "lower", "stick_end"))
            mode = 1.0 if k == 0 else -1.0
        else:
            torque = rotor.k_theta * x[0]
            if abs(torque) <= rotor.t_sl:
                events.append((t, "lower", "stick_start"))
                mode = 0.0
            else:
                events.append((t, "lower", "reversal"))
                mode = math.copysign(1.0, torque)
    if i < len(grid):
        raise RuntimeError(f"{len(grid) - i} grid samples missing at the end")
    return y, events, nfev


def main():
    job = common.read_job(sys.argv)
    tol = job.get("tol")
    if tol is None or not (math.isfinite(tol) and tol > 0.0):
        print(f"the job's tol = {tol} must be positive (this client has a tolerance)", file=sys.stderr)
        sys.exit(2)
    rotor = common.build_model(job, Rotor)
    grid = common.grid_times(job["dt"], job["t_end"])
    method = "DOP853"
    try:
        (y, events, nfev), seconds = common.timed(
            lambda: simulate(rotor, job["x0"], job["t_end"], grid, tol, method)
        )
    except (RuntimeError, ValueError, FloatingPointError) as e:
        print(f"the integration failed: {e}", file=sys.stderr)
        sys.exit(1)
    common.write_trace(job["trace"], grid, y)
    common.write_events(job["events"], events)
    common.report(seconds, scipy.__version__, f"solve_ivp {method}", rhs_evals=int(nfev))


if __name__ == "__main__":
    main()
