"""rotorbench: the two-disc rotor with set-valued friction, from Python.

Three cross-validated nonsmooth solvers (event-driven Filippov, Leine's switch model,
Moreau-Jean time-stepping), steady states with Floquet multipliers, bifurcation diagrams and
the open benchmark's grader, with numpy arrays in and out. Every function runs in Rust with
the GIL released::

    import rotorbench
    r = rotorbench.simulate(solver="event", u=1.5, t_end=100.0)
    r["t"], r["omega_l"]                    # numpy float64 arrays on the 0.01 s grid
    rotorbench.steady(u=1.5)["period"]      # 4.5777... s, refined to a fixed point
    p = rotorbench.params()                 # Table 1 as a dict; change it, pass it back
    p["k_theta"] = 0.08
    rotorbench.steady(u=1.5, params=p)

Bad input raises ValueError (TypeError for a wrong type) naming the argument or field and the
value; a run that cannot finish raises SolveError with the time ``t`` and ``state`` of the
failure. The model, the methods and the CLI these functions mirror are documented in the
repository's docs/ (docs/python.md for this package).
"""

from ._rotorbench import (
    FIXTURES,
    SUITE_VERSION,
    InternalError,
    SolveError,
    __version__,
    bifurcation,
    check,
    params,
    scenario,
    simulate,
    steady,
    sweep,
)

__all__ = [
    "FIXTURES",
    "SUITE_VERSION",
    "InternalError",
    "SolveError",
    "__version__",
    "bifurcation",
    "check",
    "params",
    "scenario",
    "simulate",
    "steady",
    "sweep",
]
