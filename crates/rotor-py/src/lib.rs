//! `rotorbench._rotorbench`: the native module of the Python package (docs/python.md).
//!
//! A thin layer. Every check, run and answer belongs to the Rust crates: the inputs go through
//! [`rotor_harness::jobs::request`] (the checks and the words of the command line), the runs through
//! the solvers, [`rotor_analysis::steady::steady`], [`rotor_analysis::bifurcation::diagram`] and
//! [`rotor_harness::grade::check::grade`]. This file converts arguments and results, releases the GIL
//! around every run, and maps errors to exceptions:
//!
//! * bad input → `ValueError` (a wrong type → `TypeError`), naming the argument or field and
//!   the value;
//! * a solver that cannot finish → `rotorbench.SolveError`, with the time `t` and the state
//!   `state` where the failure records them;
//! * a panic (a bug) → `rotorbench.InternalError`; it never unwinds into Python.

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::time::Instant;

use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyTypeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString};
use rayon::prelude::*;
use rotor_analysis::bifurcation::{BifError, DiagramOptions};
use rotor_analysis::steady::{SettleError, SteadyAnswer, SteadyError};
use rotor_harness::grade::check::{GradeError, Level};
use rotor_harness::grade::trace::{EventsFile, Trace, disc_name, event_row, round_to, time_digits};
use rotor_harness::jobs::request::Request;
use rotor_model::seam::Stats;
use rotor_model::{ChainModel, ChainParams, FieldError, Model, Params};

pyo3::create_exception!(
    rotorbench,
    SolveError,
    PyRuntimeError,
    "A solver could not finish the run. `t` is the time of the failure and `state` the state \
     (alpha, omega_u, omega_l) there, where the failure records them (else None)."
);

pyo3::create_exception!(
    rotorbench,
    InternalError,
    PyRuntimeError,
    "A bug in rotorbench (a Rust panic, caught before it reached Python): please report it \
     with the call that raised it."
);

/// Runs `f` with the GIL released, so that other Python threads run meanwhile; a panic in
/// `f` becomes an [`InternalError`] instead of unwinding into Python.
fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)))
        .map_err(|payload| {
            let what = payload
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| payload.downcast_ref::<&str>().copied())
                .unwrap_or("(no message)");
            InternalError::new_err(format!(
                "internal error (a bug in rotorbench; please report it): {what}"
            ))
        })
}

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn bad(e: FieldError) -> PyErr {
    value_error(e)
}

/// A [`SolveError`] with its `t` and `state` attributes.
fn solve_error(py: Python<'_>, message: String, t: Option<f64>, state: Option<Vec<f64>>) -> PyErr {
    let err = SolveError::new_err(message);
    let v = err.value(py);
    // Setting an attribute on a fresh exception instance cannot fail but for lack of
    // memory; then the exception still carries its message.
    let _ = v.setattr("t", t);
    let _ = v.setattr(
        "state",
        state.and_then(|s| pyo3::types::PyTuple::new(py, s).ok()),
    );
    err
}

fn from_solve(py: Python<'_>, e: rotor_model::seam::SolveError) -> PyErr {
    match e {
        rotor_model::seam::SolveError::InvalidScene(_) => value_error(e),
        _ => solve_error(py, e.to_string(), e.time(), e.state().map(<[f64]>::to_vec)),
    }
}

fn from_steady(py: Python<'_>, e: SteadyError) -> PyErr {
    match e {
        SteadyError::Solve(e) | SteadyError::Settle(SettleError::Solve(e)) => from_solve(py, e),
        SteadyError::Settle(SettleError::NotSettled { t, .. }) => {
            solve_error(py, e.to_string(), Some(t), None)
        }
        _ => solve_error(py, e.to_string(), None, None),
    }
}

fn from_bif(py: Python<'_>, e: BifError) -> PyErr {
    match e {
        BifError::InvalidOption(_) => value_error(e),
        BifError::Solve(e) => from_solve(py, e),
        BifError::Grazing { state, .. } => {
            solve_error(py, e.to_string(), None, Some(state.to_vec()))
        }
        _ => solve_error(py, e.to_string(), None, None),
    }
}

fn from_grade(e: GradeError) -> PyErr {
    use rotor_harness::grade::reference::ReferenceError;
    match e {
        GradeError::Scenario(rotor_model::scenario::ScenarioError::Io { .. })
        | GradeError::Reference(ReferenceError::File { .. }) => PyOSError::new_err(e.to_string()),
        _ => value_error(e),
    }
}

fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let message = CString::new(message.replace('\0', " "))?;
    PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, 1)
}

fn warn_ignored(py: Python<'_>, req: &Request<'_>) -> PyResult<()> {
    match req.ignored() {
        Some(i) => warn(py, &i.message()),
        None => Ok(()),
    }
}

fn warn_inexact(py: Python<'_>, stats: &Stats) -> PyResult<()> {
    match rotor_harness::jobs::request::inexact_warning(stats, "h") {
        Some(w) => warn(py, &w),
        None => Ok(()),
    }
}

/// The suite's fixtures ([`rotor_suite::locate`]): `$ROTORBENCH_FIXTURES`, else those of the
/// source checkout this module was built from, if it is still there, else the suite embedded
/// in the module (written once to a cache directory); always the embedded one with
/// `ROTORBENCH_SUITE=embedded`. `None` if none can be given (the cache is not writable).
fn fixtures() -> Option<PathBuf> {
    rotor_suite::locate().ok().map(|l| l.dir)
}

/// A file argument: a path, or the name of a file of `fixtures/<kind>/` (without `.toml`;
/// [`rotor_analysis::solvers::fixtures::resolve`]), else a `ValueError` naming the argument and what
/// was looked for.
fn resolve(arg: &str, value: &Bound<'_, PyAny>, kind: &str) -> PyResult<PathBuf> {
    let path: PathBuf = value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{arg}: expected a path or a name, got {}",
            type_name(value)
        ))
    })?;
    let dir = fixtures().map(|f| f.join(kind));
    if let Some(p) = rotor_analysis::solvers::fixtures::resolve(&path, dir.as_deref()) {
        return Ok(p);
    }
    let name = path.to_string_lossy().into_owned();
    let known = dir
        .as_deref()
        .map(|d| rotor_analysis::solvers::fixtures::names(d).join(", "));
    Err(PyValueError::new_err(match known {
        Some(known) => format!(
            "{arg} = {name:?}: no such file, nor a name in {} (names: {known})",
            dir.map(|d| d.display().to_string()).unwrap_or_default()
        ),
        None => format!(
            "{arg} = {name:?}: no such file, and the suite's files cannot be given: {}",
            rotor_suite::locate()
                .err()
                .map_or(String::new(), |e| e.to_string())
        ),
    }))
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// A dict of a parameter file's keys as a TOML table; `at` names it in messages
/// (`params['lower']`).
fn table_of(d: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!("{at}: keys must be strings, got {}", type_name(&k)))
        })?;
        let here = format!("{at}['{key}']");
        let value = if let Ok(sub) = v.cast::<PyDict>() {
            toml::Value::Table(table_of(sub, &here)?)
        } else if v.is_instance_of::<PyString>() {
            toml::Value::String(v.extract()?)
        } else if v.is_instance_of::<PyBool>() {
            return Err(PyTypeError::new_err(format!(
                "{here} = {v}: expected a number, got bool"
            )));
        } else if let (true, Ok(list)) = (key == "disc", v.cast::<PyList>()) {
            // A chain's `disc` list (the one list of a parameter file): one dict per disc.
            let mut items = Vec::with_capacity(list.len());
            for (i, item) in list.iter().enumerate() {
                let at = format!("{here}[{i}]");
                let Ok(sub) = item.cast::<PyDict>() else {
                    return Err(PyTypeError::new_err(format!(
                        "{at}: expected a dict of the disc's keys, got {}",
                        type_name(&item)
                    )));
                };
                items.push(toml::Value::Table(table_of(sub, &at)?));
            }
            toml::Value::Array(items)
        } else if let Ok(x) = v.extract::<f64>() {
            toml::Value::Float(x)
        } else {
            return Err(PyTypeError::new_err(format!(
                "{here}: expected a number, a string or a dict, got {}",
                type_name(&v)
            )));
        };
        table.insert(key, value);
    }
    Ok(table)
}

/// `params`: None (Table 1), a path or the name of a file in `fixtures/params`, or a dict of
/// the file's keys.
fn params_of(params: Option<&Bound<'_, PyAny>>) -> PyResult<Params> {
    let Some(p) = params.filter(|p| !p.is_none()) else {
        return Ok(Params::table1());
    };
    if let Ok(d) = p.cast::<PyDict>() {
        return Params::from_table(table_of(d, "params")?, Path::new("params"))
            .map_err(value_error);
    }
    let path = resolve("params", p, "params")?;
    Params::from_file(&path).map_err(value_error)
}

/// `params` as a chain, if it is written in the chain form (a file whose text is, or a dict
/// with a `disc` list); `None` for the rig's form.
fn chain_of(params: Option<&Bound<'_, PyAny>>) -> PyResult<Option<ChainParams>> {
    let Some(p) = params.filter(|p| !p.is_none()) else {
        return Ok(None);
    };
    if let Ok(d) = p.cast::<PyDict>() {
        if !d.contains("disc")? {
            return Ok(None);
        }
        return ChainParams::from_table(table_of(d, "params")?, Path::new("params"))
            .map(Some)
            .map_err(value_error);
    }
    let path = resolve("params", p, "params")?;
    // The reader takes both forms and bounds what it reads (a file that it refuses is the rig
    // reader's to report); one that loaded is a small text file, read again to tell its form.
    let Ok(chain) = ChainParams::from_file(&path) else {
        return Ok(None);
    };
    let text = std::fs::read_to_string(&path)
        .map_err(|e| PyValueError::new_err(format!("params = {}: {e}", path.display())))?;
    Ok(ChainParams::is_chain_form(&text).then_some(chain))
}

/// A JSON value as plain Python objects (dict, list, float, int, str, bool, None).
fn py_of<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| py_of(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, py_of(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// Any serializable answer as plain Python objects.
fn to_py<'py>(py: Python<'py>, v: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(v)
        .map_err(|e| InternalError::new_err(format!("internal error: {e}")))?;
    py_of(py, &value)
}

/// A run's output in the columns `simulate` returns.
struct Columns {
    t: Vec<f64>,
    alpha: Vec<f64>,
    omega_u: Vec<f64>,
    omega_l: Vec<f64>,
    events: Vec<(f64, std::borrow::Cow<'static, str>, &'static str)>,
    stats: Stats,
}

impl Columns {
    /// The samples as `rotor simulate` writes them: times rounded to the grid's decimals
    /// ([`time_digits`]), states as computed; the mode switches as in an events file.
    fn of(tr: rotor_model::seam::Trajectory, dt: f64) -> Columns {
        let digits = time_digits(dt);
        let n = tr.samples.len();
        let mut c = Columns {
            t: Vec::with_capacity(n),
            alpha: Vec::with_capacity(n),
            omega_u: Vec::with_capacity(n),
            omega_l: Vec::with_capacity(n),
            events: Vec::new(),
            stats: tr.stats,
        };
        for s in &tr.samples {
            c.t.push(round_to(s.t, digits));
            c.alpha.push(s.x[0]);
            c.omega_u.push(s.x[1]);
            c.omega_l.push(s.x[2]);
        }
        c.events = tr
            .events
            .iter()
            .filter_map(|e| event_row(e.kind).map(|(d, k)| (e.t, disc_name(d), k)))
            .collect();
        c
    }
}

/// ``input=``: an (n, 2) array or a list of ``[t, u]`` pairs, the input u(t) in place of
/// ``u`` (linear between rows, constant outside them, two rows at one t a step); bad rows
/// raise ValueError naming the row and the value.
fn input_of(rows: Option<Vec<[f64; 2]>>) -> PyResult<Option<rotor_model::seam::Input>> {
    rows.map(|r| rotor_model::seam::Input::new(&r).map_err(bad))
        .transpose()
}

/// Simulates one scene and returns the trajectory on the output grid.
///
/// Returns a dict: numpy float64 arrays ``t``, ``alpha``, ``omega_u``, ``omega_l`` at
/// ``0, dt, 2 dt, ..., t_end`` (times as ``rotor simulate`` writes them); ``events``, a list of
/// ``{"t", "disc", "kind"}`` (stick onsets and exits and reversals, as an events file);
/// ``stats``, a dict of the work counters.
///
/// ``solver`` is ``"event"`` (the accuracy reference), ``"switch"`` or ``"moreau"``; ``tol``
/// sets the adaptive solvers' tolerance (default 1e-10), ``h`` Moreau–Jean's step (default
/// 1e-3 s). ``params`` is None (Table 1), a parameter file's path or name (``"stribeck"``),
/// or a dict of its keys (see ``rotorbench.params()``). Bad input raises ValueError naming
/// the argument and the value; a failed run raises ``rotorbench.SolveError``. The GIL is
/// released during the run. ``input`` (an (n, 2) array or a list of ``[t, u]`` pairs) is an
/// input that changes in time, in place of ``u``: linear between rows, constant before the
/// first and after the last, two rows at one t a step.
///
/// A chain of N discs (``params`` in the chain form: a file of ``[[disc]]`` tables, or a dict
/// with a ``disc`` list) returns ``alpha`` ((N − 1) × len(t)) and ``omega`` (N × len(t)) as
/// 2-D arrays instead, events naming the disc by its number (1 … N); ``x0`` then holds its
/// 2N − 1 values ``alpha_1 … omega_N`` (the default, three zeros, is rest for any N). Every
/// solver runs chains, with a constant ``u`` or an ``input`` in time.
#[pyfunction]
#[pyo3(
    signature = (solver="event", u=1.5, params=None, x0=vec![0.0; 3], t_end=100.0, dt=0.01, tol=None, h=None, input=None),
    text_signature = "(solver='event', u=1.5, params=None, x0=(0.0, 0.0, 0.0), t_end=100.0, dt=0.01, tol=None, h=None, input=None)"
)]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    solver: &str,
    u: f64,
    params: Option<&Bound<'py, PyAny>>,
    x0: Vec<f64>,
    t_end: f64,
    dt: f64,
    tol: Option<f64>,
    h: Option<f64>,
    input: Option<Vec<[f64; 2]>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(chain) = chain_of(params)? {
        let x0 = chain_x0(x0, &chain);
        let req = Request {
            solver,
            u,
            input: input_of(input)?,
            x0,
            tol,
            h,
        };
        return simulate_chain(py, &req, &chain, t_end, dt);
    }
    let req = Request {
        solver,
        u,
        input: input_of(input)?,
        x0,
        tol,
        h,
    };
    let (kind, scene) = req.simulation(t_end, dt).map_err(bad)?;
    let model = Model::new(params_of(params)?);
    warn_ignored(py, &req)?;
    let columns = detached(py, move || {
        kind.solver()
            .simulate_finite(&model, &scene)
            .map(|tr| Columns::of(tr, dt))
    })?
    .map_err(|e| from_solve(py, e))?;
    warn_inexact(py, &columns.stats)?;
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, columns.t))?;
    out.set_item("alpha", PyArray1::from_vec(py, columns.alpha))?;
    out.set_item("omega_u", PyArray1::from_vec(py, columns.omega_u))?;
    out.set_item("omega_l", PyArray1::from_vec(py, columns.omega_l))?;
    let events = PyList::empty(py);
    for (t, disc, kind) in columns.events {
        let e = PyDict::new(py);
        e.set_item("t", t)?;
        e.set_item("disc", disc)?;
        e.set_item("kind", kind)?;
        events.append(e)?;
    }
    out.set_item("events", events)?;
    out.set_item("stats", to_py(py, &columns.stats)?)?;
    Ok(out)
}

/// A chain's initial state: the signature's default (three zeros, rest) is rest for a chain
/// of any size; any other list is the caller's.
fn chain_x0(x0: Vec<f64>, chain: &ChainParams) -> Vec<f64> {
    let rest = x0.len() == 3 && x0.iter().all(|&v| v == 0.0);
    if rest {
        vec![0.0; 2 * chain.len() - 1]
    } else {
        x0
    }
}

/// ``simulate`` of a chain given in the chain form: ``alpha`` ((N − 1) rows) and ``omega`` (N
/// rows) as 2-D arrays, events naming the disc by its number (1 … N). A chain of two in the
/// rig's shape runs as the rig (the same numbers, bit for bit, as ``rotor simulate`` writes
/// under the chain's names); a longer one by the solver's chain run.
fn simulate_chain<'py>(
    py: Python<'py>,
    req: &Request,
    chain: &ChainParams,
    t_end: f64,
    dt: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (kind, scene) = req.simulation(t_end, dt).map_err(bad)?;
    warn_ignored(py, req)?;
    let n = chain.len();
    let rig = chain.to_params();
    if rig.is_none() && kind.info().chain.is_none() {
        return Err(PyValueError::new_err(format!(
            "solver = {:?}: a chain with {n} discs runs on {}",
            kind.name(),
            rotor_analysis::solvers::SolverKind::chain_solver_names(", ")
        )));
    }
    let model = ChainModel::new(chain);
    let tr = detached(py, move || match rig {
        Some(p) => kind.solver().simulate_finite(&Model::new(p), &scene),
        None => kind.simulate_chain(&model, &scene),
    })?
    .map_err(|e| from_solve(py, e))?;
    warn_inexact(py, &tr.stats)?;
    let digits = time_digits(dt);
    let t: Vec<f64> = tr.samples.iter().map(|s| round_to(s.t, digits)).collect();
    let rows = |range: std::ops::Range<usize>| -> Vec<Vec<f64>> {
        range
            .map(|k| tr.samples.iter().map(|s| s.x[k]).collect())
            .collect()
    };
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, t))?;
    let array = |v: Vec<Vec<f64>>| PyArray2::from_vec2(py, &v).map_err(value_error);
    out.set_item("alpha", array(rows(0..n - 1))?)?;
    out.set_item("omega", array(rows(n - 1..2 * n - 1))?)?;
    let events = PyList::empty(py);
    for e in &tr.events {
        if let Some((d, k)) = event_row(e.kind) {
            let ev = PyDict::new(py);
            ev.set_item("t", e.t)?;
            ev.set_item("disc", d.number())?;
            ev.set_item("kind", k)?;
            events.append(ev)?;
        }
    }
    out.set_item("events", events)?;
    out.set_item("stats", to_py(py, &tr.stats)?)?;
    Ok(out)
}

/// The steady state reached from ``x0`` at input ``u``, as ``rotor steady`` prints it.
///
/// Returns a dict: ``kind`` (``"equilibrium"`` or ``"limit_cycle"``), its metrics
/// (``omega_u``/``omega_l`` of an equilibrium; ``period``, ``omega_l_max``, ``omega_l_min``,
/// ``omega_u_max``, ``omega_u_min``, ``stick_time`` of a cycle), ``method`` (how it was
/// obtained: ``"refined"``, ``"settled"`` or ``"simulated"``) and ``multipliers`` (Floquet
/// multipliers as ``[re, im]`` pairs of a refined cycle, else None).
///
/// The event-driven solver refines the cycle to a fixed point of its return map at ``tol``;
/// the others simulate until the metrics stop changing. Arguments as for ``simulate``; an
/// ``input`` that changes in time is refused (ValueError naming ``input``): a steady state
/// needs a constant input.
///
/// A chain of N discs (``params`` in the chain form) returns the chain's lists, read off the
/// solver's own run (``method`` ``"simulated"``): ``kind`` ``"equilibrium"`` (``alpha``,
/// ``omega``), ``"limit_cycle"`` (``period``, ``omega_max``, ``omega_min``, ``stick_time``
/// of N entries, ``crossings`` of its section per period, the ``return_distance`` it was
/// checked by) or ``"aperiodic"`` (the closest return and how runs at two settings part
/// ways), as ``rotor steady`` prints it.
#[pyfunction]
#[pyo3(
    signature = (solver="event", u=1.5, params=None, x0=vec![0.0; 3], tol=None, h=None, input=None),
    text_signature = "(solver='event', u=1.5, params=None, x0=(0.0, 0.0, 0.0), tol=None, h=None, input=None)"
)]
#[allow(clippy::too_many_arguments)]
fn steady<'py>(
    py: Python<'py>,
    solver: &str,
    u: f64,
    params: Option<&Bound<'py, PyAny>>,
    x0: Vec<f64>,
    tol: Option<f64>,
    h: Option<f64>,
    input: Option<Vec<[f64; 2]>>,
) -> PyResult<Bound<'py, PyAny>> {
    if let Some(chain) = chain_of(params)? {
        let x0 = chain_x0(x0, &chain);
        let req = Request {
            solver,
            u,
            input: input_of(input)?,
            x0,
            tol,
            h,
        };
        let (kind, scene, _) = req.steady().map_err(bad)?;
        if kind.info().chain.is_none() {
            return Err(PyValueError::new_err(format!(
                "solver = {solver:?}: a chain with {} discs runs on {}",
                chain.len(),
                rotor_analysis::solvers::SolverKind::chain_solver_names(", ")
            )));
        }
        warn_ignored(py, &req)?;
        let model = ChainModel::new(&chain);
        let answer = detached(py, move || {
            rotor_analysis::steady::chain::chain_steady(
                kind,
                &model,
                &scene,
                &rotor_analysis::steady::chain::ChainSteadyOptions::default(),
            )
        })?
        .map_err(|e| match e {
            rotor_analysis::steady::chain::ChainSteadyError::Solve(e) => from_solve(py, e),
            e => solve_error(py, e.to_string(), None, None),
        })?;
        return to_py(py, &answer);
    }
    let req = Request {
        solver,
        u,
        input: input_of(input)?,
        x0,
        tol,
        h,
    };
    let (kind, scene, opts) = req.steady().map_err(bad)?;
    let model = Model::new(params_of(params)?);
    warn_ignored(py, &req)?;
    let answer = detached(py, move || {
        // As `rotor steady` without --method: checked shooting, else simulation.
        rotor_analysis::steady::checked::checked_or_simulated(kind, &model, &scene, &opts)
    })?
    .map_err(|e| from_steady(py, e))?;
    warn_inexact(py, &answer.stats)?;
    to_py(py, &answer)
}

/// ``steady`` at every value of ``u`` (a sequence or 1-d array), in parallel.
///
/// Returns a list of dicts, one per u in order, each as ``steady`` returns it. A u at which
/// no steady state is found raises ``rotorbench.SolveError`` naming that u (its attribute
/// ``u``). ``threads``: how many threads (default: ``SLURM_CPUS_PER_TASK`` when set, else the
/// cores available to the process, as ``rotor sweep --threads``). Other arguments as for
/// ``steady``.
#[pyfunction]
#[pyo3(
    signature = (u, solver="event", params=None, x0=vec![0.0; 3], tol=None, h=None, threads=None),
    text_signature = "(u, solver='event', params=None, x0=(0.0, 0.0, 0.0), tol=None, h=None, threads=None)"
)]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    u: PyArrayLike1<'py, f64, AllowTypeChange>,
    solver: &str,
    params: Option<&Bound<'py, PyAny>>,
    x0: Vec<f64>,
    tol: Option<f64>,
    h: Option<f64>,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyList>> {
    let explicit = threads
        .map(|n| {
            usize::try_from(n)
                .map_err(|_| "expected at least 1 thread".to_owned())
                .and_then(rotor_harness::compare::threads::check_count)
                .map_err(|why| PyValueError::new_err(format!("threads = {n}: {why}")))
        })
        .transpose()?;
    let (n, _) =
        rotor_harness::compare::threads::resolve(explicit).map_err(PyValueError::new_err)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| PyValueError::new_err(format!("threads = {n}: cannot start them: {e}")))?;
    let us = u.as_array().to_vec();
    let mut jobs = Vec::with_capacity(us.len());
    for (i, &u) in us.iter().enumerate() {
        let req = Request {
            solver,
            u,
            input: None,
            x0: x0.clone(),
            tol,
            h,
        };
        jobs.push(req.steady().map_err(|e| match e.field.as_str() {
            "u" => PyValueError::new_err(format!("u[{i}] = {}: {}", e.value, e.reason)),
            _ => bad(e),
        })?);
        if i == 0 {
            warn_ignored(py, &req)?;
        }
    }
    let model = Model::new(params_of(params)?);
    let answers: Vec<Result<SteadyAnswer, SteadyError>> = detached(py, move || {
        pool.install(|| {
            jobs.par_iter()
                .map(|(kind, scene, opts)| {
                    rotor_analysis::steady::checked::checked_or_simulated(
                        *kind, &model, scene, opts,
                    )
                })
                .collect()
        })
    })?;
    let out = PyList::empty(py);
    let mut stats = Stats::default();
    for (answer, &u) in answers.into_iter().zip(&us) {
        match answer {
            Ok(a) => {
                stats += a.stats;
                out.append(to_py(py, &a)?)?;
            }
            Err(e) => {
                let err = from_steady(py, e);
                let msg = format!("u = {}: {}", rotor_model::Num(u), err.value(py));
                let tagged = if err.is_instance_of::<SolveError>(py) {
                    let v = err.value(py);
                    solve_error(
                        py,
                        msg,
                        v.getattr("t").ok().and_then(|t| t.extract().ok()),
                        v.getattr("state").ok().and_then(|s| s.extract().ok()),
                    )
                } else {
                    PyValueError::new_err(msg)
                };
                let _ = tagged.value(py).setattr("u", u);
                return Err(tagged);
            }
        }
    }
    warn_inexact(py, &stats)?;
    Ok(out)
}

/// The bifurcation diagram over ``u_min <= u <= u_max``, as ``rotor bifurcation`` writes it.
///
/// Returns a dict: ``solver``, ``equilibria`` (the equilibrium branch with its stability),
/// ``periodic`` (the periodic branches with Floquet multipliers and extrema of omega_l) and
/// ``points`` (Hopf, grazing and fold points, each with the residual of its defining
/// condition). ``solver="switch"`` or ``"moreau"`` shoots every periodic orbit again on that
/// solver's own return map (its own multipliers and stability) and locates the grazing
/// orbits and folds again with that solver's own shooting; ``not_found`` names any orbit or
/// special point it did not find, with the reason.
#[pyfunction]
#[pyo3(signature = (params=None, u_min=0.0, u_max=7.0, solver="event"))]
fn bifurcation<'py>(
    py: Python<'py>,
    params: Option<&Bound<'py, PyAny>>,
    u_min: f64,
    u_max: f64,
    solver: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let kind = rotor_harness::jobs::request::solver_kind(solver).map_err(bad)?;
    let model = Model::new(params_of(params)?);
    let opts = DiagramOptions {
        u_min,
        u_max,
        ..Default::default()
    };
    opts.validate().map_err(|e| from_bif(py, e))?;
    let d = detached(py, move || {
        let d = rotor_analysis::bifurcation::diagram(&model, &opts)?;
        let by = rotor_analysis::steady::by_solver::by_solver(kind, &model, &d);
        by.diagram.check_finite()?;
        Ok::<_, BifError>(by)
    })?
    .map_err(|e| from_bif(py, e))?;
    to_py(py, &d)
}

/// Events given to `check`: dicts ``{"t", "disc", "kind"}`` (as ``simulate`` returns them)
/// or tuples ``(t, disc, kind)``; a chain's (of `chain` discs) name the disc by its number, an
/// int or its digits.
fn events_of(events: &Bound<'_, PyAny>, chain: Option<usize>) -> PyResult<EventsFile> {
    let mut rows: Vec<(f64, String, String)> = Vec::new();
    // A disc given as a number reads as its digits.
    let disc_of = |v: Bound<'_, PyAny>| -> Option<String> {
        v.extract::<String>()
            .ok()
            .or_else(|| v.extract::<i64>().ok().map(|d| d.to_string()))
    };
    for (i, item) in events.try_iter()?.enumerate() {
        let item = item?;
        let shape_error = || {
            PyTypeError::new_err(format!(
                "events[{i}]: expected a dict with keys t, disc, kind or a tuple (t, disc, \
                 kind), got {}",
                type_name(&item)
            ))
        };
        let row = if let Ok(d) = item.cast::<PyDict>() {
            let get = |k: &str| d.get_item(k).ok().flatten().ok_or_else(shape_error);
            (
                get("t")?.extract().map_err(|_| shape_error())?,
                disc_of(get("disc")?).ok_or_else(shape_error)?,
                get("kind")?.extract().map_err(|_| shape_error())?,
            )
        } else {
            let (t, d, k): (f64, Bound<'_, PyAny>, String) =
                item.extract().map_err(|_| shape_error())?;
            (t, disc_of(d).ok_or_else(shape_error)?, k)
        };
        rows.push(row);
    }
    let refs: Vec<(f64, &str, &str)> = rows
        .iter()
        .map(|(t, d, k)| (*t, d.as_str(), k.as_str()))
        .collect();
    match chain {
        Some(n) => EventsFile::from_chain_rows(&refs, n),
        None => EventsFile::from_rows(&refs),
    }
    .map_err(value_error)
}

/// Grades a trace against the benchmark's reference, as ``rotor check --json`` does.
///
/// ``scenario`` is a scenario file's path or its name (``"t1-u1.5-rest"``, or a chain scene
/// such as ``"chain3-u1.5-rest"``; see ``rotorbench.scenario``); the trace is the arrays on the
/// scenario's grid (``scenario(...)["dt"]``, from 0 to ``t_end``): ``t``, ``alpha``,
/// ``omega_u``, ``omega_l`` for the rig; for a chain of N discs ``t``, ``alpha`` ((N − 1) rows)
/// and ``omega`` (N rows) as 2-D arrays, as ``simulate`` returns them. ``gate`` is
/// ``"loose"`` (3 significant digits), ``"strict"`` (7) or ``"digits=N"``; ``events``
/// optionally the trace's events (as ``simulate`` returns them; a chain's discs by number) to
/// grade every event, else ``not_graded`` names them. Returns the dict of ``rotor check
/// --json``: ``scenario``, ``benchmark``, ``passed``, ``gate``, ``digits``, ``not_graded``,
/// ``file_digits`` and ``quantities`` (each with ``name``, ``difference`` (None where it cannot
/// be measured), ``scale``, ``tolerance``, ``passed`` and ``digits``, the correct significant
/// digits). A trace that cannot be graded (off the grid, too short, a NaN) raises ValueError
/// naming the index.
#[pyfunction]
#[pyo3(signature = (scenario, t, alpha, omega_u=None, omega_l=None, gate="loose", events=None, omega=None))]
#[allow(clippy::too_many_arguments)]
fn check<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    t: PyArrayLike1<'py, f64, AllowTypeChange>,
    alpha: &Bound<'py, PyAny>,
    omega_u: Option<&Bound<'py, PyAny>>,
    omega_l: Option<&Bound<'py, PyAny>>,
    gate: &str,
    events: Option<&Bound<'py, PyAny>>,
    omega: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let level = Level::parse(gate).map_err(bad)?;
    let path = scene_path(scenario)?;
    let events = events.filter(|e| !e.is_none());
    if rotor_model::scenario::ChainScenario::is_chain_scene(&path) {
        let omega = match (omega, omega_u, omega_l) {
            (Some(w), None, None) | (None, Some(w), None) => w,
            _ => {
                return Err(PyTypeError::new_err(
                    "a chain scene's trace is t, alpha ((N − 1) rows) and omega (N rows): give                      omega=, not omega_u and omega_l",
                ));
            }
        };
        return check_chain_arrays(py, &path, t, alpha, omega, level, events);
    }
    let (Some(omega_u), Some(omega_l), None) = (omega_u, omega_l, omega) else {
        return Err(PyTypeError::new_err(
            "a rig scene's trace is t, alpha, omega_u and omega_l (omega= is a chain's)",
        ));
    };
    let column = |name: &str, c: &Bound<'py, PyAny>| -> PyResult<Vec<f64>> {
        let a: PyArrayLike1<'py, f64, AllowTypeChange> = c.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{name}: expected a 1-D array of numbers, got {}",
                type_name(c)
            ))
        })?;
        Ok(a.as_array().to_vec())
    };
    let cols = [
        t.as_array().to_vec(),
        column("alpha", alpha)?,
        column("omega_u", omega_u)?,
        column("omega_l", omega_l)?,
    ];
    let trace =
        Trace::from_columns([&cols[0], &cols[1], &cols[2], &cols[3]]).map_err(value_error)?;
    let events = events.map(|e| events_of(e, None)).transpose()?;
    let report = detached(py, move || {
        rotor_harness::grade::check::grade(&path, &trace, events.as_ref(), level)
    })?
    .map_err(from_grade)?;
    to_py(py, &report)
}

/// A scene argument: a path, or a name of the rig's tier or the chain tier.
fn scene_path(scenario: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    match resolve("scenario", scenario, "scenarios") {
        Ok(p) => Ok(p),
        Err(rig) => resolve("scenario", scenario, "chain/scenarios").map_err(|_| rig),
    }
}

/// `check` of a chain scene: the 2-D arrays into a chain's trace, graded as `rotor check`
/// grades a chain's trace file.
fn check_chain_arrays<'py>(
    py: Python<'py>,
    path: &Path,
    t: PyArrayLike1<'py, f64, AllowTypeChange>,
    alpha: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    level: Level,
    events: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = rotor_model::scenario::ChainScenario::from_file(path).map_err(value_error)?;
    let n = sc.discs();
    let t = t.as_array().to_vec();
    let rows = |name: &str, v: &Bound<'py, PyAny>, want: usize| -> PyResult<Vec<Vec<f64>>> {
        let a: PyArrayLike2<'py, f64, AllowTypeChange> = v.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{name}: expected a 2-D array of numbers ({want} rows), got {}",
                type_name(v)
            ))
        })?;
        let a = a.as_array();
        if a.nrows() != want || a.ncols() != t.len() {
            return Err(PyValueError::new_err(format!(
                "{name}: shape ({}, {}), expected ({want}, {}) for a chain of {n} discs and {} \
                 times",
                a.nrows(),
                a.ncols(),
                t.len(),
                t.len()
            )));
        }
        Ok(a.rows().into_iter().map(|r| r.to_vec()).collect())
    };
    let alpha = rows("alpha", alpha, n - 1)?;
    let omega = rows("omega", omega, n)?;
    if t.is_empty() {
        return Err(PyValueError::new_err("t: the arrays are empty"));
    }
    let mut samples = rotor_model::seam::Samples::with_capacity(2 * n - 1, t.len());
    let mut x = vec![0.0; 2 * n - 1];
    for (k, &tk) in t.iter().enumerate() {
        let row = alpha.iter().chain(&omega).map(|r| r[k]);
        for (slot, v) in x.iter_mut().zip(row) {
            *slot = v;
        }
        if !tk.is_finite() {
            return Err(PyValueError::new_err(format!(
                "t[{k}] = {tk}: not a finite number"
            )));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            let (name, row) = if i < n - 1 {
                ("alpha", i)
            } else {
                ("omega", i - (n - 1))
            };
            return Err(PyValueError::new_err(format!(
                "{name}[{row}][{k}] = {}: not a finite number",
                x[i]
            )));
        }
        samples.push(tk, &x);
    }
    let trace = rotor_harness::grade::trace::ChainTrace {
        path: rotor_harness::grade::trace::ARRAYS.into(),
        lines: (0..t.len() as u64).collect(),
        samples,
        digits: rotor_harness::grade::trace::FULL_DIGITS,
    };
    let events = events.map(|e| events_of(e, Some(n))).transpose()?;
    let path = path.to_owned();
    let report = detached(py, move || {
        let (sc, r) = rotor_harness::grade::chain::load(&path)?;
        Ok::<_, GradeError>(rotor_harness::grade::chain::check_chain(
            &sc,
            &r,
            &trace,
            events.as_ref(),
            level,
        )?)
    })?
    .map_err(from_grade)?;
    to_py(py, &report)
}

/// A parameter set as a dict of its file's keys: Table 1 (``None``), or a parameter file's
/// path or name (``"stribeck"``). Change a value and pass the dict as ``params``.
#[pyfunction]
#[pyo3(signature = (source=None))]
fn params<'py>(py: Python<'py>, source: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
    to_py(py, &params_of(source)?)
}

/// A benchmark scenario as a dict: ``name``, ``description``, ``path``, ``params`` (a dict),
/// ``u``, ``x0``, ``t_end``, ``dt`` (the grid a trace is graded on), ``transient`` (the
/// compared window ``[t0, t1]`` or None) and ``steady_from`` (where the steady-state metrics
/// start, or None). ``source`` is a scenario file's path or name (``"t1-u1.5-rest"``).
///
/// A chain scene (``"chain3-u1.5-rest"``) gives ``name``, ``description``, ``path``,
/// ``params`` (the chain form: ``k_m`` and a ``disc`` list), ``discs``, ``u`` (None for an
/// input in time), ``input`` (its ``[t, u]`` rows, or None), ``x0`` (2N − 1 values),
/// ``t_end``, ``dt``, ``benchmark`` (the chain tier's version) and ``chaos`` (a chaotic
/// scene's ``statistics_from`` and ``batches``, else None).
#[pyfunction]
fn scenario<'py>(py: Python<'py>, source: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let path = scene_path(source)?;
    if rotor_model::scenario::ChainScenario::is_chain_scene(&path) {
        let sc = rotor_model::scenario::ChainScenario::from_file(&path).map_err(value_error)?;
        let d = PyDict::new(py);
        d.set_item("name", &sc.name)?;
        d.set_item("description", &sc.description)?;
        d.set_item("path", sc.path.to_string_lossy().into_owned())?;
        d.set_item("params", to_py(py, &sc.params)?)?;
        d.set_item("discs", sc.discs())?;
        d.set_item("u", sc.input.is_none().then_some(sc.u))?;
        let rows: Option<Vec<[f64; 2]>> = sc
            .input
            .as_ref()
            .map(|i| i.rows().iter().map(|&(t, u)| [t, u]).collect());
        d.set_item("input", rows)?;
        d.set_item("x0", pyo3::types::PyTuple::new(py, &sc.x0)?)?;
        d.set_item("t_end", sc.t_end)?;
        d.set_item("dt", sc.dt)?;
        d.set_item("benchmark", rotor_suite::CHAIN_VERSION)?;
        let chaos = sc.chaos.map(|c| {
            let c_d = PyDict::new(py);
            c_d.set_item("statistics_from", c.statistics_from)?;
            c_d.set_item("batches", c.batches)?;
            Ok::<_, PyErr>(c_d)
        });
        d.set_item("chaos", chaos.transpose()?)?;
        return Ok(d);
    }
    let sc = rotor_analysis::solvers::load_scenario(&path).map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("name", &sc.name)?;
    d.set_item("description", &sc.description)?;
    d.set_item("path", sc.path.to_string_lossy().into_owned())?;
    d.set_item("params", to_py(py, &sc.model.params)?)?;
    d.set_item("u", sc.u)?;
    d.set_item("x0", pyo3::types::PyTuple::new(py, &sc.x0)?)?;
    d.set_item("t_end", sc.t_end)?;
    d.set_item("dt", sc.compare.dt)?;
    d.set_item("transient", sc.compare.transient)?;
    d.set_item("steady_from", sc.compare.steady_from)?;
    Ok(d)
}

/// Seconds of each of ``repeat`` runs of the Rust solve alone (no argument conversion, no
/// numpy): what ``simulate``'s overhead is measured against (bench/python/bench_package.py).
#[pyfunction]
#[pyo3(signature = (solver="event", u=1.5, t_end=100.0, dt=0.01, tol=None, h=None, repeat=1))]
fn _solve_seconds(
    py: Python<'_>,
    solver: &str,
    u: f64,
    t_end: f64,
    dt: f64,
    tol: Option<f64>,
    h: Option<f64>,
    repeat: usize,
) -> PyResult<Vec<f64>> {
    let req = Request {
        solver,
        u,
        input: None,
        x0: vec![0.0; 3],
        tol,
        h,
    };
    let (kind, scene) = req.simulation(t_end, dt).map_err(bad)?;
    let model = Model::new(Params::table1());
    detached(py, move || {
        let solver = kind.solver();
        (0..repeat)
            .map(|_| {
                let t0 = Instant::now();
                let tr = solver.simulate_finite(&model, &scene)?;
                let s = t0.elapsed().as_secs_f64();
                drop(tr);
                Ok(s)
            })
            .collect::<Result<Vec<f64>, rotor_model::seam::SolveError>>()
    })?
    .map_err(|e| from_solve(py, e))
}

/// Panics inside the guarded, GIL-free region every run goes through: shows (in the tests)
/// that a panic reaches Python as ``rotorbench.InternalError``, not as an unwinding crash.
#[pyfunction]
fn _panic(py: Python<'_>, message: String) -> PyResult<()> {
    detached(py, move || -> () { panic!("{message}") })
}

#[pymodule]
fn _rotorbench(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(steady, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(bifurcation, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(params, m)?)?;
    m.add_function(wrap_pyfunction!(scenario, m)?)?;
    m.add_function(wrap_pyfunction!(_solve_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(_panic, m)?)?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("SUITE_VERSION", rotor_suite::VERSION)?;
    m.add(
        "FIXTURES",
        fixtures().map(|p| p.to_string_lossy().into_owned()),
    )?;
    Ok(())
}
