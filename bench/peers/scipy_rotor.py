#!/usr/bin/env python3
"""The rotorbench rotor model in plain scipy: a peer for `rotor-bench`.

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

Steady-state metrics as rotor-model's MetricsAccumulator defines them: the last complete
cycle between two successive stick exits in [metrics_from, t_end] (between omega_l maxima if
the orbit never sticks); period = its length, omega_l_max = the largest located maximum in it.

Prints one JSON object on stdout. Run times are measured in-process with
time.perf_counter() around the whole simulation (all segments, the 0.01 s trace and the
metrics), after one untimed warm-up run; interpreter start-up and imports are excluded.

    python3 scipy_rotor.py --params ../../fixtures/params/table1.toml --u 1.5 --x0 0,0,0 \
        --t-end 100 --metrics-from 50 --transient 0,20 --dt 0.01 --tol 1e-6,1e-9 --repeat 3
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


def simulate(rotor, x0, t_end, grid, tol, method):
    """One run: returns (grid samples of omega_l, exit times, maxima, rhs evaluations)."""
    t = 0.0
    x = list(x0)
    # Initial mode: as rotor-model's Model::mode_at.
    if x[2] > 0.0:
        mode = 1.0
    elif x[2] < 0.0:
        mode = -1.0
    else:
        torque = rotor.k_theta * x[0]
        mode = 0.0 if abs(torque) <= rotor.t_sl else math.copysign(1.0, torque)
    omega_l = np.empty(len(grid))
    i = 0  # next grid sample
    exits = []  # stick exit times
    maxima = []  # (t, omega_l) at omega_l maxima
    nfev = 0
    segments = 0
    while t < t_end:
        segments += 1
        if segments > 100_000:
            raise RuntimeError(f"more than 100000 segments by t = {t}: Zeno-like switching")
        if mode == 0.0:
            fun, events = rotor.stick, stick_events(rotor)
        else:
            fun, events = rotor.slip(mode), slip_events(rotor, mode)
        sol = solve_ivp(
            fun,
            (t, t_end),
            x,
            method=method,
            t_eval=grid[i:],
            events=events,
            rtol=tol,
            atol=tol,
        )
        if sol.status < 0:
            raise RuntimeError(f"solve_ivp failed at t = {t}: {sol.message}")
        nfev += sol.nfev
        n = len(sol.t)
        omega_l[i : i + n] = sol.y[2]
        i += n
        if mode != 0.0:
            maxima.extend((te, ye[2]) for te, ye in zip(sol.t_events[1], sol.y_events[1]))
        if sol.status == 0:  # reached t_end
            break
        # A terminal event ended the segment.
        hit = [k for k, te in enumerate(sol.t_events) if events[k].terminal and len(te)]
        k = hit[0]
        t = float(sol.t_events[k][-1])
        x = [float(v) for v in sol.y_events[k][-1]]
        x[2] = 0.0
        if mode == 0.0:
            exits.append(t)
            mode = 1.0 if k == 0 else -1.0
        else:
            torque = rotor.k_theta * x[0]
            mode = 0.0 if abs(torque) <= rotor.t_sl else math.copysign(1.0, torque)
    if i < len(grid):
        raise RuntimeError(f"{len(grid) - i} grid samples missing at the end")
    return omega_l, exits, maxima, nfev


def run_setting(rotor, args, grid, window, tol):
    """Time one tolerance and return its entry of "runs" (a failed run's reason if it raised)."""
    try:
        (omega_l, exits, maxima, nfev), seconds = common.time_runs(
            lambda: simulate(rotor, args.x0, args.t_end, grid, tol, args.method),
            args.repeat,
            args.time_budget,
        )
    except (RuntimeError, ValueError, FloatingPointError) as e:
        return common.failed_record(tol, str(e))
    metrics = common.cycle_metrics(exits, maxima, args.metrics_from, maxima_fallback=True)
    return common.run_record(tol, seconds, metrics, grid, omega_l, window, rhs_evals=int(nfev))


def main():
    ap = common.make_parser(
        __doc__.splitlines()[0], "--tol", "rtol = atol ladder, comma-separated", repeat_default=5
    )
    ap.add_argument("--method", default="DOP853", help="solve_ivp method")
    args = common.parse_args(ap)
    rotor = common.load_model(args, Rotor)
    grid = common.grid_times(args.dt, args.t_end)
    window = common.trace_window(grid, args.transient, args.dt)
    runs = [run_setting(rotor, args, grid, window, tol) for tol in args.tol]
    common.emit("scipy", scipy.__version__, f"solve_ivp {args.method}", runs)


if __name__ == "__main__":
    main()
