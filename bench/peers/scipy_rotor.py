#!/usr/bin/env python3
"""The rotorbench rotor model in plain scipy: a peer client of `rotor bench` (BENCHMARK.md).

What a careful scipy user would write for the two-disc rotor with set-valued friction
(docs/model.md): state x = [alpha, omega_u, omega_l],

    alpha'         = omega_u - omega_l
    J_u omega_u'   = k_m u - k_theta alpha - T_fu(omega_u)
    J_l omega_l'   =         k_theta alpha - T_fl(omega_l)

integrated with `scipy.integrate.solve_ivp` (DOP853 by default; `--method Radau|BDF|LSODA|
RK45|RK23` for another) piece by piece between events, switching vector fields at the events
(Filippov's solution; each disc has its own switching surface omega = 0):

* each disc is in a mode: slip on branch s = +1 / -1 (the sign of its omega), or stick;
* slip on branch s: the disc's friction law on that branch, T_f = a(omega) + b omega +
  s N(s omega), with N the friction level of docs/model.md continued smoothly past omega = 0
  so that the event function is smooth across its root; terminal event omega = 0
  (direction -s);
* at omega = 0: stick if the applied torque T_ex (k_theta alpha on the lower disc,
  k_m u - k_theta alpha on the upper) lies in the disc's stick interval [lo, hi] =
  a(0) + N(0) [-1, 1], else slip the way it pushes (a reversal, or passing a kink);
* stick: omega = 0 and omega' = 0 (the friction takes the applied torque: the equivalent
  control); terminal events T_ex = hi (exit to s = +1) and T_ex = lo (exit to s = -1). The
  discs couple only through alpha, so a stuck disc's friction never enters the other's
  equation, and each disc's mode is decided alone;
* non-terminal event omega_l' = 0 from above (a maximum of omega_l) while slipping.

A smooth upper disc (Table 1: T_su = dT_su = db_u = 0, so T_fu = b_u omega_u) has no
switching surface and is integrated straight through omega_u = 0. The lower disc may use
either family of docs/model.md (exponential: Table 1; stribeck); the upper disc's law is
T_fu = dT_su + s db_u omega + b_u omega + s T_su on branch s.

A client of the benchmark's job-file protocol: `python3 scipy_rotor.py [--method M] JOB.json`
integrates the job's scene at rtol = atol = the job's tol, writes the trace (alpha, omega_u,
omega_l on the grid) and the events it locates (stick onsets and exits, reversals of either
disc), and prints {"solve_seconds": S, ...}: time.perf_counter() around the simulation alone
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


UPPER, LOWER = 0, 1
DISC_NAMES = ("upper", "lower")
METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")


class Rotor:
    """Parameters and the vector fields of each mode."""

    def __init__(self, params, u):
        self.j_u = params["j_u"]
        self.j_l = params["j_l"]
        self.k_m = params["k_m"]
        self.k_theta = params["k_theta"]
        up = params["upper"]
        self.b_u = up["b"]
        self.t_su = up.get("t_s", 0.0)
        self.dt_su = up.get("dt_s", 0.0)
        self.db_u = up.get("db", 0.0)
        if self.t_su < 0.0:
            raise ValueError(f"upper.t_s = {self.t_su}: must not be negative")
        # A smooth upper disc has no switching surface (Table 1).
        self.upper_smooth = self.t_su == 0.0 and self.dt_su == 0.0 and self.db_u == 0.0
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
        # Stick intervals [lo, hi] of each disc.
        self.interval = (
            (self.dt_su - self.t_su, self.dt_su + self.t_su),
            (-self.t_sl, self.t_sl),
        )

    def level(self, x):
        """Friction level N(x) of the lower disc, x = s*omega (x >= 0 on the branch).

        Exponential (docs/model.md): T_sl + T_1 tanh(w_1 x / 2) + T_2 tanh(w_2 x / 2), which
        is odd in x: a smooth continuation. Stribeck: T_cl + (T_sl - T_cl)
        exp(-|x/omega_s|^delta) (even in x).
        """
        if self.family == "exponential":
            return (
                self.t_sl
                + self.t_1 * math.tanh(0.5 * self.w_1 * x)
                + self.t_2 * math.tanh(0.5 * self.w_2 * x)
            )
        return self.t_cl + (self.t_sl - self.t_cl) * math.exp(-abs(x / self.omega_s) ** self.delta)

    def applied(self, disc, alpha):
        """T_ex of a disc: what its friction must take for it to stay stuck."""
        spring = self.k_theta * alpha
        return self.drive - spring if disc == UPPER else spring

    def friction(self, disc, w, s):
        """The friction torque on branch s (s = 0: the smooth upper law)."""
        if disc == UPPER:
            if s == 0.0:
                return self.b_u * w
            return self.dt_su + s * self.db_u * w + self.b_u * w + s * self.t_su
        return self.b_l * w + s * self.level(s * w)

    def accel(self, disc, x, s):
        """omega' of a disc in mode s (0 for a stuck set-valued disc)."""
        if s is None:
            return 0.0
        j = self.j_u if disc == UPPER else self.j_l
        w = x[1 + disc]
        return (self.applied(disc, x[0]) - self.friction(disc, w, s)) / j

    def field(self, modes):
        """The vector field of a mode pair; a mode is +1/-1 (slip), None (stuck), or 0 for
        the smooth upper disc (no switching surface)."""

        def f(t, x):
            return [x[1] - x[2], self.accel(UPPER, x, modes[0]), self.accel(LOWER, x, modes[1])]

        return f

    def mode_at(self, disc, x):
        """As rotor-model's Model::mode_at: slip by the sign of omega, else stick if the
        applied torque is inside the stick interval, else slip the way it pushes."""
        w = x[1 + disc]
        if w > 0.0:
            return 1.0
        if w < 0.0:
            return -1.0
        return self.at_rest(disc, x)

    def at_rest(self, disc, x):
        """The mode of a disc at omega = 0: stuck (None) or the branch it slips on."""
        torque = self.applied(disc, x[0])
        lo, hi = self.interval[disc]
        if lo <= torque <= hi:
            return None
        return 1.0 if torque > hi else -1.0


def events_of(rotor, modes):
    """The event functions of a mode pair, each tagged (disc, what): terminal omega = 0 for a
    slipping disc with a switching surface, terminal stick exits for a stuck disc, and the
    non-terminal maxima of omega_l while it slips."""
    evs, tags = [], []
    for disc in (UPPER, LOWER):
        s = modes[disc]
        if s == 0.0:
            continue
        if s is None:
            lo, hi = rotor.interval[disc]
            for bound, side in ((hi, 1.0), (lo, -1.0)):

                def leave(t, x, d=disc, b=bound):
                    return rotor.applied(d, x[0]) - b

                leave.terminal = True
                leave.direction = side
                evs.append(leave)
                tags.append((disc, "exit", side))
        else:

            def zero(t, x, d=disc):
                return x[1 + d]

            zero.terminal = True
            zero.direction = -s
            evs.append(zero)
            tags.append((disc, "zero", s))
    if modes[LOWER] not in (None, 0.0):

        def peak(t, x, s=modes[LOWER]):
            return rotor.accel(LOWER, x, s)

        peak.terminal = False
        peak.direction = -1.0
        evs.append(peak)
        tags.append((LOWER, "peak", 0.0))
    return evs, tags


def simulate(rotor, x0, t_end, grid, tol, method):
    """One run: returns (the 3 x len(grid) solution on the grid, events, rhs evaluations)."""
    t = 0.0
    x = list(x0)
    modes = [0.0 if rotor.upper_smooth else rotor.mode_at(UPPER, x), rotor.mode_at(LOWER, x)]
    y = np.empty((3, len(grid)))
    i = 0  # next grid sample
    events = []  # (t, disc, kind)
    nfev = 0
    segments = 0
    while t < t_end:
        segments += 1
        if segments > 100_000:
            raise RuntimeError(f"more than 100000 segments by t = {t}: Zeno-like switching")
        for disc in (UPPER, LOWER):
            if modes[disc] is None:
                x[1 + disc] = 0.0
        evs, tags = events_of(rotor, modes)
        sol = solve_ivp(
            rotor.field(modes),
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
        for disc in (UPPER, LOWER):
            if modes[disc] is None:
                y[1 + disc, i : i + n] = 0.0
        i += n
        if sol.status == 0:  # reached t_end
            break
        # A terminal event ended the segment: the earliest (two at one instant: both).
        hits = [
            (float(sol.t_events[k][-1]), k)
            for k, te in enumerate(sol.t_events)
            if evs[k].terminal and len(te)
        ]
        t_hit = min(th for th, _ in hits)
        k0 = min(hits)[1]
        t = t_hit
        x = [float(v) for v in sol.y_events[k0][-1]]
        for th, k in sorted(hits):
            if th != t_hit:
                continue
            disc, what, side = tags[k]
            name = DISC_NAMES[disc]
            x[1 + disc] = 0.0
            if what == "exit":
                events.append((t, name, "stick_end"))
                modes[disc] = side
            else:
                new = rotor.at_rest(disc, x)
                if new is None:
                    events.append((t, name, "stick_start"))
                else:
                    events.append((t, name, "reversal"))
                modes[disc] = new
    if i < len(grid):
        raise RuntimeError(f"{len(grid) - i} grid samples missing at the end")
    return y, events, nfev


def options(argv):
    """`[--method M] JOB.json`: the method and the argv left for the job reader."""
    args = argv[1:]
    method = "DOP853"
    if len(args) >= 2 and args[0] == "--method":
        method = args[1]
        args = args[2:]
        if method not in METHODS:
            print(f"--method {method}: expected one of {', '.join(METHODS)}", file=sys.stderr)
            sys.exit(2)
    return method, [argv[0], *args]


def main():
    method, argv = options(sys.argv)
    job = common.read_job(argv)
    tol = job.get("tol")
    if tol is None or not (math.isfinite(tol) and tol > 0.0):
        print(f"the job's tol = {tol} must be positive (this client has a tolerance)", file=sys.stderr)
        sys.exit(2)
    rotor = common.build_model(job, Rotor)
    grid = common.grid_times(job["dt"], job["t_end"])
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
