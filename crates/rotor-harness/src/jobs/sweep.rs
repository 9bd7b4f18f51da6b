//! Brute force over a (u, p) grid (`rotor sweep`, `rotor merge`): every grid point's steady
//! state from the scene's initial state, metrics only, one CSV row per point.
//!
//! Rows are written in grid order (p outer, u inner: point `k = i_p·N_u + i_u`) as they are
//! finished, through a reorder buffer, so the file is always a prefix of the full output and
//! an interrupted sweep resumes where it stopped (`--resume`: the rows already there are
//! kept, a half-written last row is dropped). `--shard I/N` runs the points `k ≡ I − 1 (mod
//! N)`, for a Slurm job array or GNU parallel; [`merge`] joins the shards into exactly what
//! one unsharded run writes, and refuses shards that do not fit together.
//!
//! Beside each output file, `OUT.shard.json` records the grid, the settings and the shard,
//! so that [`merge`] can tell a missing shard from a smaller grid (a shard's own rows can
//! form a complete-looking grid of their own); without it, merge checks that the rows form a
//! full grid.

use std::io::{BufRead, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rotor_model::seam::{Attractor, Output, RigSteady, Scene};
use rotor_model::{FieldError, Model, Params, State};

use rotor_analysis::solvers::registry::SolverKind;

/// The header of a sweep file.
pub(crate) const HEADER: &str = "u,p,kind,period,omega_l_max,omega_l_min,stick_time";

/// Largest number of points one process is asked to run: more asks for sharding.
pub(crate) const MAX_POINTS: usize = 10_000_000;

/// Why a sweep or a merge cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// An argument is refused: the field as `rotor sweep` names it (`u`, `param`, `shard`;
    /// `u/param` for the size of the grid), its value quoted as given. The command line
    /// spells the field as its flag ([`FieldError::as_flag`]: `--shard "0/3": ...`).
    #[error(transparent)]
    Arg(FieldError),
    /// An output, shard record or input file cannot be read, or is not what it should be.
    #[error("{}: {message}", .path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Writing the rows failed: a full disk, or a reader of standard output that has gone.
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        /// The output file (or `-` for standard output).
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The shards given to [`merge`] do not make one grid; the text says why.
    #[error("the shards do not fit together: {0}")]
    Merge(String),
}

fn arg(field: &str, value: &str, reason: impl Into<String>) -> SweepError {
    SweepError::Arg(FieldError::new(field, format!("{value:?}"), reason))
}

/// One axis `A:B:N`: N values from A to B, both included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// The first value, A.
    pub a: f64,
    /// The last value, B.
    pub b: f64,
    /// The number of values, N ≥ 1 (A = B when N = 1).
    pub n: usize,
}

impl Axis {
    /// Parses `A:B:N`; `field` names the axis in the error (`u`, `param`).
    pub fn parse(field: &str, s: &str) -> Result<Axis, SweepError> {
        let parts: Vec<&str> = s.split(':').collect();
        let [a, b, n] = parts[..] else {
            return Err(arg(field, s, "expected A:B:N (from A to B in N values)"));
        };
        let num = |t: &str| {
            t.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| arg(field, s, format!("{t:?} is not a finite number")))
        };
        let n = n
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| n >= 1)
            .ok_or_else(|| arg(field, s, format!("N = {n:?} must be a whole number >= 1")))?;
        let (a, b) = (num(a)?, num(b)?);
        if n == 1 && a != b {
            return Err(arg(field, s, "N = 1 needs A = B"));
        }
        Ok(Axis { a, b, n })
    }

    /// The i-th value: `A + (B − A)·i/(N − 1)` (the same bits in every process), and B itself
    /// for the last, which that sum misses by an ulp for about a third of decimal ends
    /// (`7:0.3:N` would end at 0.2999999999999998).
    pub fn value(&self, i: usize) -> f64 {
        if i + 1 >= self.n {
            if self.n == 1 { self.a } else { self.b }
        } else {
            self.a + (self.b - self.a) * (i as f64 / (self.n - 1) as f64)
        }
    }
}

/// `I/N`: the I-th of N shards (I from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, I in 1..=N.
    pub i: usize,
    /// How many shards, N ≥ 1.
    pub n: usize,
}

impl Shard {
    /// `1/1`: the whole grid.
    pub const ALL: Shard = Shard { i: 1, n: 1 };

    /// Parses `I/N` (`--shard`), with I in 1..=N.
    pub fn parse(s: &str) -> Result<Shard, SweepError> {
        let bad = |why: &str| arg("shard", s, why);
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| bad("expected I/N, e.g. 3/8"))?;
        let i: usize = i
            .trim()
            .parse()
            .map_err(|_| bad("I must be a whole number"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N must be a whole number"))?;
        if n == 0 {
            return Err(bad("N must be at least 1"));
        }
        if i == 0 || i > n {
            return Err(bad("I must lie in 1..=N (shards count from 1)"));
        }
        Ok(Shard { i, n })
    }

    /// Whether grid point `k` belongs to this shard.
    pub fn owns(&self, k: usize) -> bool {
        k % self.n == self.i - 1
    }

    /// The points of a grid of `len` points that belong to this shard, in order: `I − 1`,
    /// `I − 1 + N`, ... (found by stepping, not by visiting the whole grid).
    pub fn indices(&self, len: usize) -> impl Iterator<Item = usize> {
        (self.i - 1..len).step_by(self.n)
    }

    /// How many points of a grid of `len` points belong to this shard.
    pub fn count(&self, len: usize) -> usize {
        len.saturating_sub(self.i - 1).div_ceil(self.n)
    }
}

/// Where each point starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SweepStart {
    /// The same state everywhere (`--x0 A,WU,WL`, default rest).
    State(State),
    /// The perturbed equilibrium at each point (`--x0 eq`): the slipping equilibrium nearest
    /// rest with ω_l raised by 1e-3 rad/s, or the middle of the stuck set.
    PerturbedEquilibrium,
}

/// A sweep: the grid, the parameter, the start and the solver.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The parameter set whose field `param` is varied.
    pub base: Params,
    /// The input voltages u \[V\] (inner axis).
    pub u: Axis,
    /// The varied parameter's dotted path (`k_theta`, `lower.t_s`; see
    /// [`Params::field_names`]).
    pub param: String,
    /// Its values, in its unit (outer axis).
    pub p: Axis,
    /// Where each point's run starts.
    pub start: SweepStart,
    /// The solver, at its default setting.
    pub solver: SolverKind,
    /// Horizon of each run \[s\]; the metrics are read over its second half.
    pub t_end: f64,
}

impl Sweep {
    /// The number of grid points.
    pub fn len(&self) -> usize {
        self.u.n.saturating_mul(self.p.n)
    }

    /// Whether the grid has no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// (u, p) of point k.
    pub fn point(&self, k: usize) -> (f64, f64) {
        (self.u.value(k % self.u.n), self.p.value(k / self.u.n))
    }

    /// Checks the grid before any run: the number of points one process runs first (so that
    /// a huge grid is refused at once, not after visiting it), then the parameter name and
    /// every parameter value this shard runs, and both ends of the parameter axis, so that
    /// every shard of a grid refuses the same bad range.
    pub fn validate(&self, shard: Shard) -> Result<(), SweepError> {
        self.base
            .get(&self.param)
            .map_err(|e| arg("param", &self.param, e.to_string()))?;
        let points = format!("{} x {} points", self.u.n, self.p.n);
        if self.u.n.checked_mul(self.p.n).is_none() {
            return Err(arg(
                "u/param",
                &points,
                format!("more points than this machine can count ({})", usize::MAX),
            ));
        }
        if shard.count(self.len()) > MAX_POINTS {
            return Err(arg(
                "u/param",
                &points,
                format!(
                    "more than {MAX_POINTS} points for one process: split the grid with \
                     --shard I/N (N >= {})",
                    self.len().div_ceil(MAX_POINTS).max(2)
                ),
            ));
        }
        let mut last = None;
        let ends = [0, self.p.n.saturating_sub(1)].into_iter();
        for i in ends.chain(shard.indices(self.len()).map(|k| k / self.u.n)) {
            if last == Some(i) {
                continue;
            }
            last = Some(i);
            let p = self.p.value(i);
            self.base
                .with(&self.param, p)
                .map_err(|e| arg("param", &format!("{}={p}", self.param), e.to_string()))?;
        }
        Ok(())
    }

    /// The CSV row of point k.
    pub fn row(&self, k: usize) -> String {
        let (u, p) = self.point(k);
        let mut b = zmij::Buffer::new();
        let mut s = format!("{},", b.format(u));
        s.push_str(b.format(p));
        let model = self
            .base
            .with(&self.param, p)
            .map(Model::new)
            .expect("validated before the run");
        let x0 = match self.start {
            SweepStart::State(x) => x,
            SweepStart::PerturbedEquilibrium => model.perturbed_equilibrium(u),
        };
        let scene = Scene {
            u,
            x0: x0.as_slice().to_vec(),
            t_end: self.t_end,
            output: Output::Metrics,
            metrics_from: Some(0.5 * self.t_end),
            ..Scene::default()
        };
        let f = |v: f64| zmij::Buffer::new().format(v).to_owned();
        let metrics = self.solver.solver().simulate_finite(&model, &scene);
        match metrics.ok().and_then(|tr| tr.rig_metrics()) {
            Some(m) => {
                s.push(',');
                s.push_str(kind_word(Attractor::of(&m)));
                match m {
                    RigSteady::LimitCycle {
                        period,
                        omega_l_max,
                        omega_l_min,
                        stick_time,
                        ..
                    } => s.push_str(&format!(
                        ",{},{},{},{}",
                        f(period),
                        f(omega_l_max),
                        f(omega_l_min),
                        f(stick_time)
                    )),
                    RigSteady::Equilibrium { .. } => s.push_str(",,,,"),
                }
            }
            None => s.push_str(",failed,,,,"),
        }
        s
    }
}

/// The `kind` column of a row: `stuck`, `equilibrium`, or `limit_cycle` for a cycle with or
/// without stick (its `stick_time` column tells them apart); a run without a steady state is
/// `failed`.
fn kind_word(a: Attractor) -> &'static str {
    match a {
        Attractor::Stuck | Attractor::Equilibrium => a.as_str(),
        Attractor::StickSlipCycle | Attractor::SlippingCycle => a.steady_kind().as_str(),
    }
}

/// What `OUT.shard.json` records.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShardInfo {
    /// The u axis as `A:B:N`.
    pub u: String,
    /// The parameter and its axis, `name=A:B:N`.
    pub param: String,
    /// The start: `A,WU,WL`, or `eq` for the perturbed equilibrium.
    pub x0: String,
    /// The solver's name.
    pub solver: String,
    /// Horizon of each run \[s\].
    pub t_end: f64,
    /// The parameter set, as a fingerprint of its fields.
    pub params: String,
    /// This shard, I (from 1).
    pub shard: usize,
    /// The number of shards, N.
    pub shards: usize,
}

impl Sweep {
    /// The shard file's record of this sweep.
    pub fn info(&self, shard: Shard) -> ShardInfo {
        let axis = |a: &Axis| {
            let mut b = zmij::Buffer::new();
            let mut s = format!("{}:", b.format(a.a));
            s.push_str(b.format(a.b));
            format!("{s}:{}", a.n)
        };
        ShardInfo {
            u: axis(&self.u),
            param: format!("{}={}", self.param, axis(&self.p)),
            x0: match self.start {
                SweepStart::State(x) => format!("{},{},{}", x[0], x[1], x[2]),
                SweepStart::PerturbedEquilibrium => "eq".into(),
            },
            solver: self.solver.name().into(),
            t_end: self.t_end,
            params: format!("{:?}", self.base),
            shard: shard.i,
            shards: shard.n,
        }
    }
}

/// The record beside an output file.
pub(crate) fn info_path(out: &Path) -> PathBuf {
    let mut s = out.as_os_str().to_owned();
    s.push(".shard.json");
    PathBuf::from(s)
}

/// Runs the points of `shard` into `out` (`-`: standard output, no resume), in parallel
/// through `map` (which must return `f` of each index, in any order), calling `progress`
/// with the number done. With `resume`, the rows already in `out` are kept (a half-written
/// last row is dropped) and only the rest run. Returns the number of points run.
pub fn run(
    sweep: &Sweep,
    shard: Shard,
    out: &Path,
    resume: bool,
    run_all: impl FnOnce(&[usize], &(dyn Fn(usize) -> String + Sync), &mut dyn FnMut(usize, String)),
) -> Result<usize, SweepError> {
    sweep.validate(shard)?;
    let mine: Vec<usize> = shard.indices(sweep.len()).collect();
    let io = |e: std::io::Error| SweepError::File {
        path: out.to_owned(),
        message: e.to_string(),
    };
    let stdout = out.as_os_str() == "-";
    let done = if resume && !stdout && out.exists() {
        resume_count(sweep, &mine, out)?
    } else {
        0
    };
    let mut w: Box<dyn Write> = if stdout {
        Box::new(std::io::stdout().lock())
    } else if done > 0 {
        Box::new(
            std::fs::OpenOptions::new()
                .append(true)
                .open(out)
                .map_err(io)?,
        )
    } else {
        Box::new(std::fs::File::create(out).map_err(io)?)
    };
    let write_err = |source| SweepError::Write {
        path: out.to_owned(),
        source,
    };
    if done == 0 {
        writeln!(w, "{HEADER}")
            .and_then(|()| w.flush())
            .map_err(write_err)?;
    }
    if !stdout {
        let text = serde_json::to_string_pretty(&sweep.info(shard)).expect("plain fields");
        crate::compare::report::write_atomic(&info_path(out), text.as_bytes()).map_err(|e| {
            SweepError::File {
                path: info_path(out),
                message: e.to_string(),
            }
        })?;
    }
    let todo = &mine[done..];
    write_rows(sweep, todo, &mut w, run_all).map_err(write_err)?;
    Ok(todo.len())
}

/// Runs the grid points `todo` through `run_all` and writes their rows to `w` in grid order.
/// Once a write fails (a full disk, a reader of standard output that has gone), the points
/// not yet started are not run (no one would read them) and the error is returned.
fn write_rows(
    sweep: &Sweep,
    todo: &[usize],
    w: &mut dyn Write,
    run_all: impl FnOnce(&[usize], &(dyn Fn(usize) -> String + Sync), &mut dyn FnMut(usize, String)),
) -> std::io::Result<()> {
    // Reorder buffer: rows arrive in any order and leave in grid order.
    let mut pending = std::collections::BTreeMap::new();
    let mut next = 0usize;
    let mut failed: Option<std::io::Error> = None;
    let stop = AtomicBool::new(false);
    let mut sink = |idx: usize, row: String| {
        pending.insert(idx, row);
        while let Some(r) = pending.remove(&next) {
            if failed.is_none()
                && let Err(e) = writeln!(w, "{r}").and_then(|_| w.flush())
            {
                failed = Some(e);
                stop.store(true, Ordering::Relaxed);
            }
            next += 1;
        }
    };
    let row = |i: usize| {
        if stop.load(Ordering::Relaxed) {
            String::new()
        } else {
            sweep.row(todo[i])
        }
    };
    let indices: Vec<usize> = (0..todo.len()).collect();
    run_all(&indices, &row, &mut sink);
    failed.map_or(Ok(()), Err)
}

/// How many of `mine` are complete in an existing output; a half-written last row is cut
/// off the file.
fn resume_count(sweep: &Sweep, mine: &[usize], out: &Path) -> Result<usize, SweepError> {
    let io = |e: std::io::Error| SweepError::File {
        path: out.to_owned(),
        message: e.to_string(),
    };
    // The file must start with the header, or be a cut-off start of it, before it is read
    // on or cut: a wrong path is refused as it is.
    let mut head = Vec::new();
    std::fs::File::open(out)
        .and_then(|f| f.take(HEADER.len() as u64 + 1).read_to_end(&mut head))
        .map_err(io)?;
    if !format!("{HEADER}\n").as_bytes().starts_with(&head) {
        let first = head.split(|&b| b == b'\n').next().unwrap_or_default();
        return Err(SweepError::File {
            path: out.to_owned(),
            message: format!(
                "line 1 begins {:?}, not the sweep header {HEADER:?}; not resumed, the file is \
                 left as it is",
                String::from_utf8_lossy(first)
            ),
        });
    }
    let bytes = std::fs::read(out).map_err(io)?;
    let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    if complete < bytes.len() {
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(out)
            .map_err(io)?;
        f.set_len(complete as u64).map_err(io)?;
    }
    let text = String::from_utf8_lossy(&bytes[..complete]);
    let mut lines = text.lines();
    // The header, checked above; none when the file was cut inside it.
    if lines.next().is_none() {
        return Ok(0);
    }
    let mut n = 0;
    let mut b = zmij::Buffer::new();
    for (line, &k) in lines.zip(mine) {
        let (u, p) = sweep.point(k);
        let head = format!("{},{},", b.format(u), zmij::Buffer::new().format(p));
        if !line.starts_with(&head) {
            return Err(SweepError::File {
                path: out.to_owned(),
                message: format!(
                    "line {}: {line:?} is not grid point {k} (u = {u}, p = {p}) of this sweep; \
                     not resumed",
                    n + 2
                ),
            });
        }
        n += 1;
    }
    Ok(n)
}

/// A row of a shard: its grid point, its text, and where it came from.
struct Row {
    u: f64,
    p: f64,
    line: String,
    /// Index of its file in the merge's list.
    file: usize,
    lineno: usize,
}

/// Shards merged: the rows of the whole grid in the order one unsharded run writes them.
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    lines: Vec<String>,
}

impl Merged {
    /// The number of rows (grid points).
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Writes the header and the rows, buffered.
    pub fn write_to(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, w);
        writeln!(w, "{HEADER}")?;
        for line in &self.lines {
            w.write_all(line.as_bytes())?;
            w.write_all(b"\n")?;
        }
        w.flush()
    }

    /// The bytes [`Merged::write_to`] writes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.write_to(&mut out).expect("writing to memory");
        out
    }
}

/// Merges shard files into the output of one unsharded run (row order included): the
/// rows' u and p values must form a full grid, each point once. The row order is the grid
/// order: p outer, u inner, each axis in the direction of the row of point 0 (the first row
/// of the shard that holds it). Each row's place is found by bisection on the sorted axes
/// and the rows are put in order by one sort, so that a map of 10^8 points merges in
/// O(n log n); a gap in the grid is counted without allocating the grid.
pub fn merge(paths: &[PathBuf]) -> Result<Merged, SweepError> {
    check_records(paths)?;
    let mut rows: Vec<Row> = Vec::new();
    let mut first_rows: Vec<(f64, f64)> = Vec::new();
    for (file, path) in paths.iter().enumerate() {
        let io = |e: std::io::Error| SweepError::File {
            path: path.clone(),
            message: e.to_string(),
        };
        let f = std::fs::File::open(path).map_err(io)?;
        // Lines are capped: a file without line ends fails at once instead of being read whole.
        let f = crate::grade::trace::LineCap::new(f, crate::grade::trace::MAX_LINE);
        let mut lines = std::io::BufReader::new(f).lines();
        match lines.next() {
            Some(Ok(h)) if h == HEADER => {}
            Some(Ok(h)) => {
                return Err(SweepError::File {
                    path: path.clone(),
                    message: format!("line 1: {h:?} is not the sweep header {HEADER:?}"),
                });
            }
            Some(Err(e)) => return Err(io(e)),
            None => {
                return Err(SweepError::File {
                    path: path.clone(),
                    message: "empty (no header)".into(),
                });
            }
        }
        let mut first = true;
        for (i, line) in lines.enumerate() {
            let line = line.map_err(io)?;
            if line.is_empty() {
                continue;
            }
            let bad = |m: String| SweepError::File {
                path: path.clone(),
                message: format!("line {}: {m}", i + 2),
            };
            let mut it = line.splitn(3, ',');
            // A sweep's grid values are finite; -0 and 0 are one value of an axis.
            let num = |t: Option<&str>, what: &str| {
                t.and_then(|t| t.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .map(|v| v + 0.0)
                    .ok_or_else(|| bad(format!("{what} is not a finite number: {line:?}")))
            };
            let u = num(it.next(), "u")?;
            let p = num(it.next(), "p")?;
            if first {
                first_rows.push((u, p));
                first = false;
            }
            rows.push(Row {
                u,
                p,
                line,
                file,
                lineno: i + 2,
            });
        }
    }
    // The grid: the distinct values of each axis, sorted upwards.
    let distinct = |f: fn(&Row) -> f64| {
        let mut v: Vec<f64> = rows.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let us = distinct(|r| r.u);
    let ps = distinct(|r| r.p);
    let (Some(&umin), Some(&pmin)) = (us.first(), ps.first()) else {
        return Err(SweepError::Merge("no rows".into()));
    };
    // Point 0 is (A_u, A_p); of the shards' first rows it is the one at a corner of the grid
    // where both values are ends of their axes. Its u and p tell each axis' direction.
    let corner = first_rows
        .iter()
        .find(|(u, p)| (*u == umin || Some(u) == us.last()) && (*p == pmin || Some(p) == ps.last()))
        .copied()
        .unwrap_or((umin, pmin));
    let u_axis = (us.as_slice(), corner.0 != umin);
    let p_axis = (ps.as_slice(), corner.1 != pmin);
    // The place of value x on an axis (sorted upwards; `down`: counted from its top end).
    let place = |(v, down): (&[f64], bool), x: f64| {
        let i = v
            .binary_search_by(|y| y.total_cmp(&x))
            .expect("every row's value is on its axis");
        if down { v.len() - 1 - i } else { i }
    };
    let value = |(v, down): (&[f64], bool), i: usize| if down { v[v.len() - 1 - i] } else { v[i] };
    let nu = us.len() as u128;
    let cells = nu * ps.len() as u128;
    let mut keyed: Vec<(u128, Row)> = rows
        .into_iter()
        .map(|r| {
            (
                place(p_axis, r.p) as u128 * nu + place(u_axis, r.u) as u128,
                r,
            )
        })
        .collect();
    // Stable: of two rows of one point, the one given first on the command line stays first.
    keyed.sort_by_key(|(k, _)| *k);
    if let Some(w) = keyed.windows(2).find(|w| w[0].0 == w[1].0) {
        let (a, b) = (&w[0].1, &w[1].1);
        return Err(SweepError::Merge(format!(
            "point u = {}, p = {} is in {}:{} and in {}:{}",
            b.u,
            b.p,
            paths[b.file].display(),
            b.lineno,
            paths[a.file].display(),
            a.lineno
        )));
    }
    let missing = cells - keyed.len() as u128;
    if missing > 0 {
        // The first few grid points that no row holds, found between consecutive keys.
        let mut examples = Vec::new();
        let mut next = 0u128;
        let keys = keyed.iter().map(|(k, _)| *k).chain([cells]);
        for k in keys {
            while next < k && examples.len() < 5 {
                let (i, j) = ((next % nu) as usize, (next / nu) as usize);
                examples.push(format!(
                    "u = {}, p = {}",
                    value(u_axis, i),
                    value(p_axis, j)
                ));
                next += 1;
            }
            if examples.len() == 5 {
                break;
            }
            next = k + 1;
        }
        return Err(SweepError::Merge(format!(
            "{missing} of the {} x {} grid's points are missing (a shard of another grid, or \
             one not given): {}{}",
            us.len(),
            ps.len(),
            examples.join("; "),
            if missing > 5 { "; ..." } else { "" }
        )));
    }
    Ok(Merged {
        lines: keyed.into_iter().map(|(_, r)| r.line).collect(),
    })
}

/// With a record beside every shard: the same sweep in each, and shards 1..=N each once.
fn check_records(paths: &[PathBuf]) -> Result<(), SweepError> {
    let mut infos = Vec::new();
    for p in paths {
        let ip = info_path(p);
        // A record is a few hundred bytes; the cap keeps a wrong file from being read whole.
        let mut text = String::new();
        let read = std::fs::File::open(&ip).and_then(|f| f.take(1 << 16).read_to_string(&mut text));
        if read.is_err() {
            return Ok(());
        }
        let info: ShardInfo = serde_json::from_str(&text).map_err(|e| SweepError::File {
            path: ip.clone(),
            message: format!("not a shard record: {e}"),
        })?;
        if info.shard == 0 || info.shard > info.shards {
            return Err(SweepError::File {
                path: ip.clone(),
                message: format!(
                    "not a shard record: shard {}/{} is not one of 1..={}",
                    info.shard, info.shards, info.shards
                ),
            });
        }
        infos.push((p, info));
    }
    let Some((p0, first)) = infos.first() else {
        return Ok(());
    };
    for (p, i) in &infos[1..] {
        let same = ShardInfo {
            shard: first.shard,
            ..i.clone()
        };
        if same != *first {
            return Err(SweepError::Merge(format!(
                "{} is a shard of another sweep than {} ({:?} vs {:?})",
                p.display(),
                p0.display(),
                (&i.u, &i.param, &i.x0, &i.solver, i.t_end, i.shards),
                (
                    &first.u,
                    &first.param,
                    &first.x0,
                    &first.solver,
                    first.t_end,
                    first.shards
                )
            )));
        }
    }
    let n = first.shards;
    // By shard number: a record may claim any number of shards, so nothing of size n is made.
    let mut seen: std::collections::BTreeMap<usize, Vec<String>> = Default::default();
    for (p, i) in &infos {
        seen.entry(i.shard)
            .or_default()
            .push(p.display().to_string());
    }
    if seen.len() < n {
        let missing: Vec<String> = (1..=n)
            .filter(|k| !seen.contains_key(k))
            .take(5)
            .map(|k| format!("{k}/{n}"))
            .collect();
        let more = if n - seen.len() > 5 {
            format!(", ... ({} in all)", n - seen.len())
        } else {
            String::new()
        };
        return Err(SweepError::Merge(format!(
            "shard(s) {}{more} of {n} are missing",
            missing.join(", ")
        )));
    }
    if let Some((k, files)) = seen.iter().find(|(_, f)| f.len() > 1) {
        return Err(SweepError::Merge(format!(
            "shard {k}/{n} is given twice: {}",
            files.join(" and ")
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotor_testkit::tmp_dir;

    /// A refused argument as the command line spells it.
    fn flag(e: SweepError) -> String {
        match e {
            SweepError::Arg(f) => f.as_flag(),
            e => panic!("not a refused argument: {e}"),
        }
    }

    #[test]
    fn axes_and_shards_parse_or_name_the_problem() {
        let a = Axis::parse("u", "0:2:5").unwrap();
        assert_eq!((a.value(0), a.value(2), a.value(4)), (0.0, 1.0, 2.0));
        assert_eq!(Axis::parse("u", "3:1:3").unwrap().value(1), 2.0);
        // Both ends are the numbers given, bit for bit (7 + (0.3 − 7)·1 is not 0.3).
        let a = Axis::parse("u", "7:0.3:4").unwrap();
        assert_eq!((a.value(0), a.value(3)), (7.0, 0.3));
        assert!(a.value(2) > a.value(3));
        for bad in ["0:1", "a:1:3", "0:1:0", "0:1:x", "0:inf:3", "0:1:1"] {
            let e = flag(Axis::parse("u", bad).unwrap_err());
            assert!(e.starts_with(&format!("--u {bad:?}")), "{e}");
        }
        assert_eq!(Shard::parse("2/3").unwrap(), Shard { i: 2, n: 3 });
        for bad in ["0/3", "4/3", "a/b", "3", "1/0"] {
            let e = flag(Shard::parse(bad).unwrap_err());
            assert!(e.starts_with(&format!("--shard {bad:?}")), "{e}");
        }
        let s = Shard { i: 2, n: 3 };
        assert_eq!((0..9).filter(|&k| s.owns(k)).collect::<Vec<_>>(), [1, 4, 7]);
        // The stepped enumeration and the count agree with the definition by `owns`.
        for len in 0..12 {
            for n in 1..6 {
                for i in 1..=n {
                    let s = Shard { i, n };
                    let by_owns: Vec<usize> = (0..len).filter(|&k| s.owns(k)).collect();
                    assert_eq!(s.indices(len).collect::<Vec<_>>(), by_owns, "{len} {i}/{n}");
                    assert_eq!(s.count(len), by_owns.len(), "{len} {i}/{n}");
                }
            }
        }
    }

    /// Below half the lower disc's static level over the motor constant, u < T_sl / (2 k_m),
    /// the motor's whole torque, which the spring carries at rest, cannot break the lower
    /// disc away: both discs end at rest. Every solver's sweep says `stuck` there, for Table 1
    /// too, whose upper disc has no static friction and so only comes to rest asymptotically.
    #[test]
    fn below_the_breakaway_torque_every_solver_says_stuck() {
        let stribeck = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/params/stribeck.toml"
        );
        for base in [
            Params::table1(),
            Params::from_file(std::path::Path::new(stribeck)).unwrap(),
        ] {
            let u = 0.5 * base.get("lower.t_s").unwrap() / base.get("k_m").unwrap();
            for solver in rotor_analysis::solvers::registry::SOLVERS {
                let sw = Sweep {
                    base,
                    u: Axis::parse("u", &format!("{u}:{}:2", 0.5 * u)).unwrap(),
                    solver,
                    ..sweep()
                };
                for k in 0..sw.len() {
                    let row = sw.row(k);
                    let name = solver.name();
                    assert_eq!(row.split(',').nth(2), Some("stuck"), "{name}: {row}");
                }
            }
        }
    }

    fn sweep() -> Sweep {
        Sweep {
            base: Params::table1(),
            u: Axis::parse("u", "0.5:6:4").unwrap(),
            param: "k_theta".into(),
            p: Axis::parse("param", "0.06:0.09:3").unwrap(),
            start: SweepStart::State(State::zeros()),
            solver: SolverKind::EVENT,
            t_end: 300.0,
        }
    }

    #[test]
    fn a_grid_too_large_or_out_of_range_is_refused_before_any_run() {
        let mut s = sweep();
        s.u.n = 5_000_000;
        s.p.n = 3;
        let e = s.validate(Shard::ALL).unwrap_err().to_string();
        assert!(e.contains("--shard I/N"), "{e}");
        assert!(s.validate(Shard { i: 1, n: 2 }).is_ok());
        // A grid of 1e22 points (beyond usize) and one of 1e12 parameter values are refused
        // without visiting them: this test would not end if either were walked. The second
        // can be split into shards, the first cannot.
        let mut s = sweep();
        s.u.n = 99_999_999_999;
        s.p.n = 99_999_999_999;
        let e = s.validate(Shard::ALL).unwrap_err().to_string();
        assert!(e.contains("more points than this machine can count"), "{e}");
        let mut s = sweep();
        s.u.n = 1;
        s.u.b = s.u.a;
        s.p.n = 1_000_000_000_000;
        let e = s.validate(Shard::ALL).unwrap_err().to_string();
        assert!(e.contains("--shard I/N (N >= 100000)"), "{e}");
        // One shard of it runs 10 points; only their parameter values and the axis ends are
        // checked.
        let one = Shard {
            i: 7,
            n: 100_000_000_000,
        };
        assert!(s.validate(one).is_ok());
        assert_eq!(one.count(s.len()), 10);
        // A bad end of the axis is refused by a shard that does not run it.
        s.p.b = -0.01;
        let e = s.validate(one).unwrap_err().to_string();
        assert!(e.contains("k_theta = -0.01: must be positive"), "{e}");
        let mut s = sweep();
        s.p = Axis::parse("param", "-0.01:0.09:3").unwrap();
        let e = s.validate(Shard::ALL).unwrap_err().to_string();
        assert!(e.contains("k_theta = -0.01: must be positive"), "{e}");
        let mut s = sweep();
        s.param = "lower.delta".into();
        let e = s.validate(Shard::ALL).unwrap_err().to_string();
        assert!(e.contains("valid: j_u"), "{e}");
    }

    fn run_serial(s: &Sweep, shard: Shard, out: &Path, resume: bool) -> usize {
        run(s, shard, out, resume, |idx, f, sink| {
            // Backwards, to exercise the reorder buffer.
            for &i in idx.iter().rev() {
                sink(i, f(i));
            }
        })
        .unwrap()
    }

    #[test]
    fn shards_merge_to_the_unsharded_file_and_a_cut_file_resumes() {
        let dir = tmp_dir("rotor-sweep");
        let s = sweep();
        let whole = dir.join("whole.csv");
        assert_eq!(run_serial(&s, Shard::ALL, &whole, false), 12);
        let bytes = std::fs::read(&whole).unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert_eq!(text.lines().count(), 13);
        assert!(text.starts_with(&format!("{HEADER}\n0.5,0.06,")), "{text}");
        let shards: Vec<PathBuf> = (1..=3)
            .map(|i| {
                let p = dir.join(format!("s{i}.csv"));
                run_serial(&s, Shard { i, n: 3 }, &p, false);
                p
            })
            .collect();
        // In any order on the command line.
        let merged = merge(&[shards[2].clone(), shards[0].clone(), shards[1].clone()]).unwrap();
        assert_eq!(merged.to_bytes(), bytes);
        // Cut in the middle of a row: the resumed run completes it to the same bytes.
        let cut = dir.join("cut.csv");
        std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
        let ran = run_serial(&s, Shard::ALL, &cut, true);
        assert!(ran < 12 && ran > 0, "{ran}");
        assert_eq!(std::fs::read(&cut).unwrap(), bytes);
        // Refusals: a missing shard, a duplicated one, another grid's shard.
        let e = merge(&shards[..2]).unwrap_err().to_string();
        assert!(e.contains("shard(s) 3/3 of 3 are missing"), "{e}");
        let e = merge(&[shards[0].clone(), shards[0].clone(), shards[1].clone()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("3/3") || e.contains("given twice"), "{e}");
        // Without the records, from the rows alone.
        for p in &shards {
            std::fs::remove_file(info_path(p)).unwrap();
        }
        let e = merge(&shards[..2]).unwrap_err().to_string();
        // The missing points are named in grid order: those of shard 3/3.
        let named: Vec<String> = Shard { i: 3, n: 3 }
            .indices(s.len())
            .map(|k| s.point(k))
            .map(|(u, p)| format!("u = {u}, p = {p}"))
            .collect();
        assert!(
            e.contains(&format!(
                "4 of the 4 x 3 grid's points are missing (a shard of another grid, or one not \
                 given): {}",
                named.join("; ")
            )),
            "{e}"
        );
        let e = merge(&[shards[0].clone(), shards[0].clone()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("is in") && e.contains("s1.csv"), "{e}");
        assert_eq!(
            merge(&[shards[2].clone(), shards[0].clone(), shards[1].clone()])
                .unwrap()
                .to_bytes(),
            bytes
        );
        let other = Sweep {
            u: Axis::parse("u", "0.5:6:5").unwrap(),
            ..sweep()
        };
        let o = dir.join("other.csv");
        run_serial(&other, Shard { i: 2, n: 3 }, &o, false);
        std::fs::remove_file(info_path(&o)).unwrap();
        let e = merge(&[shards[0].clone(), o.clone(), shards[2].clone()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("do not fit together") && e.contains("other.csv"),
            "{e}"
        );
        run_serial(&other, Shard { i: 2, n: 3 }, &o, false);
        for (i, p) in shards.iter().enumerate() {
            run_serial(&s, Shard { i: i + 1, n: 3 }, p, false);
        }
        let e = merge(&[shards[0].clone(), o, shards[2].clone()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("another sweep") && e.contains("other.csv"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Axes that run downwards merge in their own direction, as one unsharded run writes them.
    #[test]
    fn downward_axes_merge_in_their_direction() {
        let dir = tmp_dir("rotor-sweep-down");
        let s = Sweep {
            u: Axis::parse("u", "6:0.5:4").unwrap(),
            p: Axis::parse("param", "0.09:0.06:3").unwrap(),
            ..sweep()
        };
        let whole = dir.join("whole.csv");
        run_serial(&s, Shard::ALL, &whole, false);
        let shards: Vec<PathBuf> = (1..=2)
            .map(|i| {
                let p = dir.join(format!("s{i}.csv"));
                run_serial(&s, Shard { i, n: 2 }, &p, false);
                std::fs::remove_file(info_path(&p)).unwrap();
                p
            })
            .collect();
        let merged = merge(&[shards[1].clone(), shards[0].clone()]).unwrap();
        assert_eq!(merged.len(), 12);
        assert_eq!(merged.to_bytes(), std::fs::read(&whole).unwrap());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Rows and records that no sweep writes are refused by name, without a panic and without
    /// building anything of the size they claim.
    #[test]
    fn merge_refuses_impossible_rows_and_records_cheaply() {
        let dir = tmp_dir("rotor-merge-bad");
        let file = |name: &str, rows: &str| {
            let p = dir.join(name);
            std::fs::write(&p, format!("{HEADER}\n{rows}")).unwrap();
            p
        };
        // Values that are no grid's: NaN parses as a float but is on no axis.
        for (u, what) in [("NaN", "u"), ("inf", "u"), ("1.0,-inf", "p")] {
            let p = file(
                "bad.csv",
                &format!("0.5,0.06,equilibrium,,,,\n{u},0.06,stuck,,,,\n"),
            );
            let e = merge(&[p]).unwrap_err().to_string();
            assert!(
                e.contains(&format!("line 3: {what} is not a finite number")),
                "{u}: {e}"
            );
        }
        // 100 000 rows on a diagonal span a grid of 10^10 points: counted, not allocated
        // (allocating it needs 560 GB).
        let mut rows = String::new();
        for i in 0..100_000 {
            rows.push_str(&format!("{i},{i},stuck,,,,\n"));
        }
        let diag = file("diag.csv", &rows);
        let e = merge(std::slice::from_ref(&diag)).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "the shards do not fit together: 9999900000 of the 100000 x 100000 grid's \
                 points are missing (a shard of another grid, or one not given): u = 1, p = 0; \
                 u = 2, p = 0;"
            ),
            "{e}"
        );
        // -0 and 0 are one grid value: a grid of one point holding it twice.
        let zeros = file("zeros.csv", "-0.0,0.0,stuck,,,,\n0.0,-0.0,stuck,,,,\n");
        let e = merge(&[zeros]).unwrap_err().to_string();
        assert!(e.contains("point u = 0, p = 0 is in"), "{e}");
        // A record claiming 10^18 shards, or a shard outside 1..=N.
        let one = file("one.csv", "0.5,0.06,stuck,,,,\n");
        let info = sweep().info(Shard::ALL);
        for (shard, shards, want) in [
            (
                1,
                1_000_000_000_000_000_000,
                "shard(s) 2/1000000000000000000, 3/",
            ),
            (0, 3, "shard 0/3 is not one of 1..=3"),
            (4, 3, "shard 4/3 is not one of 1..=3"),
        ] {
            let rec = ShardInfo {
                shard,
                shards,
                ..info.clone()
            };
            std::fs::write(info_path(&one), serde_json::to_string(&rec).unwrap()).unwrap();
            let e = merge(std::slice::from_ref(&one)).unwrap_err().to_string();
            assert!(e.contains(want), "{shard}/{shards}: {e}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Once the output fails, the points not yet started are not run and the error comes
    /// back: a sweep to a closed pipe or a full disk does not run on for hours.
    #[test]
    fn a_failed_write_stops_the_sweep() {
        /// Takes two rows (a row ends with a flush), then fails as a closed pipe does.
        struct TwoRows(usize);
        impl Write for TwoRows {
            fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
                if self.0 < 2 {
                    Ok(buf.len())
                } else {
                    Err(std::io::ErrorKind::BrokenPipe.into())
                }
            }
            fn flush(&mut self) -> std::io::Result<()> {
                self.0 += 1;
                Ok(())
            }
        }
        let s = sweep();
        let todo: Vec<usize> = (0..s.len()).collect();
        let mut run = 0;
        let e = write_rows(&s, &todo, &mut TwoRows(0), |idx, f, sink| {
            for &i in idx {
                let row = f(i);
                run += usize::from(!row.is_empty());
                sink(i, row);
            }
        })
        .unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe);
        assert_eq!(
            run,
            3,
            "two rows written, the third failed, {} not run",
            todo.len() - 3
        );
    }

    /// A file that is not a sweep's output, given to `--resume` or to merge by mistake, is
    /// refused and left byte for byte as it was; one without line ends is not read whole.
    #[test]
    fn foreign_files_are_refused_untouched() {
        let dir = tmp_dir("rotor-sweep-foreign");
        let s = sweep();
        // A text file ending without a newline (resume would cut a half-written row), a
        // binary file without line ends, and a cut-off header (which resume does complete).
        let text = dir.join("notes.txt");
        let notes = b"keep these notes\nthe last line has no newline".to_vec();
        let blob = dir.join("blob.bin");
        let zeros = vec![0u8; 1 << 20];
        for (path, bytes) in [(&text, &notes), (&blob, &zeros)] {
            std::fs::write(path, bytes).unwrap();
            let e = run(&s, Shard::ALL, path, true, |_, _, _| {}).unwrap_err();
            assert!(e.to_string().contains("not the sweep header"), "{e}");
            assert_eq!(&std::fs::read(path).unwrap(), bytes);
        }
        let e = merge(std::slice::from_ref(&blob)).unwrap_err().to_string();
        assert!(e.contains("no line end"), "{e}");
        let cut = dir.join("cut.csv");
        std::fs::write(&cut, &HEADER.as_bytes()[..5]).unwrap();
        assert_eq!(run_serial(&s, Shard::ALL, &cut, true), 12);
        std::fs::remove_dir_all(&dir).ok();
    }
}
