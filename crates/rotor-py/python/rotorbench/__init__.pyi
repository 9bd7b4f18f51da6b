"""Type stubs of rotorbench (the functions live in the native module rotorbench._rotorbench)."""

import os
from typing import Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str
#: The suite's directory (scenarios, params, reference): $ROTORBENCH_FIXTURES, the source
#: checkout the package was built from, or the suite embedded in the package (written once to
#: a cache directory; always that one with ROTORBENCH_SUITE=embedded); None if none can be given.
FIXTURES: Optional[str]
#: The suite's version, e.g. "rotorbench-1.0+646a96e8215c": the problem set's name and the
#: start of the sha256 of its files (as ``rotor scenarios`` prints it and every verdict holds).
SUITE_VERSION: str

Solver = Literal["event", "switch", "moreau"]
#: None (Table 1), a parameter file's path or name ("table1", "stribeck"), or a dict of its keys.
ParamsLike = Union[None, str, "os.PathLike[str]", Mapping[str, Any]]
ArrayLike = Union[Sequence[float], npt.NDArray[np.floating[Any]]]

class SolveError(RuntimeError):
    """A solver could not finish the run."""

    #: Time of the failure [s], where the failure records it.
    t: Optional[float]
    #: State (alpha, omega_u, omega_l) at the failure, where the failure records it.
    state: Optional[Tuple[float, float, float]]
    #: The input voltage of the failing point (``sweep`` only).
    u: float

class InternalError(RuntimeError):
    """A bug in rotorbench (a Rust panic caught before it reached Python)."""

class Event(TypedDict):
    t: float
    disc: Literal["upper", "lower"]
    kind: Literal["stick_start", "stick_end", "reversal"]

class Simulation(TypedDict):
    t: npt.NDArray[np.float64]
    alpha: npt.NDArray[np.float64]
    omega_u: npt.NDArray[np.float64]
    omega_l: npt.NDArray[np.float64]
    events: List[Event]
    stats: Dict[str, int]

class ChainEvent(TypedDict):
    t: float
    #: The disc's number, 1 (the driven one) to N.
    disc: int
    kind: Literal["stick_start", "stick_end", "reversal"]

class ChainSimulation(TypedDict):
    t: npt.NDArray[np.float64]
    #: (N - 1) x len(t): alpha_i = theta_i - theta_{i+1}.
    alpha: npt.NDArray[np.float64]
    #: N x len(t).
    omega: npt.NDArray[np.float64]
    events: List[ChainEvent]
    stats: Dict[str, int]

def simulate(
    solver: Solver = "event",
    u: float = 1.5,
    params: ParamsLike = None,
    x0: Sequence[float] = (0.0, 0.0, 0.0),
    t_end: float = 100.0,
    dt: float = 0.01,
    tol: Optional[float] = None,
    h: Optional[float] = None,
    input: Optional[Sequence[Sequence[float]]] = None,
) -> Union[Simulation, ChainSimulation]:
    """Simulates one scene; the trajectory on the grid 0, dt, ..., t_end.

    For a chain of N discs (``params`` in the chain form) the result is a ChainSimulation:
    ``alpha`` and ``omega`` as 2-D arrays, events with the disc's number; ``x0`` then holds
    2N - 1 values (the default, three zeros, is rest for any N). A chain longer than two runs
    on "switch" or "moreau".

    ``input``: an (n, 2) array or a list of [t, u] pairs, an input that changes in time in
    place of ``u`` (linear between rows, constant outside them, two rows at one t a step).

    ``tol`` is the adaptive solvers' tolerance (event, switch; default 1e-10), ``h``
    Moreau-Jean's step (default 1e-3 s). Returns numpy arrays t, alpha, omega_u, omega_l, the
    events (stick onsets and exits, reversals) and the work counters. Raises ValueError for bad
    input, SolveError when the run cannot finish. Releases the GIL.
    """

def steady(
    solver: Solver = "event",
    u: float = 1.5,
    params: ParamsLike = None,
    x0: Sequence[float] = (0.0, 0.0, 0.0),
    tol: Optional[float] = None,
    h: Optional[float] = None,
    input: Optional[Sequence[Sequence[float]]] = None,
) -> Dict[str, Any]:
    """The steady state reached from x0 at u, as ``rotor steady`` prints it.

    An ``input`` that changes in time is refused (ValueError naming it): a steady state needs
    a constant input.

    Keys: kind ("equilibrium" or "limit_cycle"), its metrics (omega_u, omega_l; or period,
    omega_l_max, omega_l_min, omega_u_max, omega_u_min, stick_time), method ("refined",
    "settled", "simulated") and multipliers ([re, im] pairs of a refined cycle, else None).
    """

def sweep(
    u: ArrayLike,
    solver: Solver = "event",
    params: ParamsLike = None,
    x0: Sequence[float] = (0.0, 0.0, 0.0),
    tol: Optional[float] = None,
    h: Optional[float] = None,
    threads: Optional[int] = None,
) -> List[Dict[str, Any]]:
    """``steady`` at every u, in parallel; one dict per u, in order.

    ``threads``: default ``SLURM_CPUS_PER_TASK`` when set, else the cores available.
    """

def bifurcation(
    params: ParamsLike = None, u_min: float = 0.0, u_max: float = 7.0, solver: Solver = "event"
) -> Dict[str, Any]:
    """The bifurcation diagram over u, as ``rotor bifurcation --solver`` writes it.

    Keys: solver, equilibria, periodic (with Floquet multipliers), points (Hopf, grazing,
    folds, each with the residual of its defining condition); for switch and moreau also
    not_located (the kinds of points they do not locate yet) and not_found, if any.
    """

def check(
    scenario: Union[str, "os.PathLike[str]"],
    t: ArrayLike,
    alpha: ArrayLike,
    omega_u: Optional[ArrayLike] = None,
    omega_l: Optional[ArrayLike] = None,
    gate: str = "loose",
    events: Optional[Sequence[Union[Event, Tuple[float, Union[str, int], str]]]] = None,
    omega: Optional[ArrayLike] = None,
) -> Dict[str, Any]:
    """Grades a trace on the scenario's grid against the reference, as ``rotor check --json``.

    A rig scene takes ``t, alpha, omega_u, omega_l``; a chain scene of the suite's chain tier
    (``"chain3-u1.5-rest"``) takes ``t``, ``alpha`` ((N - 1) rows) and ``omega`` (N rows) as
    2-D arrays, as ``simulate`` returns them for a chain, its events naming discs by number.

    ``gate`` is ``"loose"``, ``"strict"`` or ``"digits=N"``. Keys: scenario, benchmark,
    passed, gate, digits, not_graded, file_digits, quantities (name, difference, scale,
    tolerance, passed, digits, and at/note where they apply). A difference that cannot be
    measured (a missing stick interval or event) is None, as JSON's null; its digits are 0.
    """

def params(source: ParamsLike = None) -> Dict[str, Any]:
    """A parameter set as a dict of its file's keys (Table 1 by default)."""

def scenario(source: Union[str, "os.PathLike[str]"]) -> Dict[str, Any]:
    """A benchmark scenario: name, description, path, params, u, x0, t_end, dt, transient,
    steady_from; a chain scene: name, description, path, params (chain form), discs, u, input,
    x0, t_end, dt, benchmark, chaos."""
