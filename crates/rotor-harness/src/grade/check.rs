//! Grading one external trace against the reference (`rotor check`), in significant digits.
//!
//! The grade covers everything the scenario defines, each as a *quantity* with its
//! difference from the reference, the scale it is measured against, and its significant
//! correct digits `−log10(difference / scale)`:
//!
//! * **`alpha`, `omega_u`, `omega_l`**: the largest difference over every sample of the run,
//!   `[0, t_end]`, at equal times. Scale: the variable's largest |value| in the reference run,
//!   at least [`FLOOR`] (a variable that stays near 0, as both discs stuck).
//! * **`events`** (when an events file is given): every stick onset, stick exit and reversal
//!   of either disc over `[0, t_end]`, matched one to one with the reference's by disc, kind
//!   and time; a missing, extra or unmatched event is named and fails the quantity. Scale:
//!   the motion's time scale [`time_scale`] (the reference cycle's period, else 1 s).
//! * **`stick_lower`, `stick_upper`**: the stick intervals visible in the trace (samples with
//!   |ω| ≤ [`stuck_threshold`], the level's tolerance of that disc's ω samples) matched one to
//!   one with the reference's (the same threshold), for every trace, with or without an events
//!   file. A sample grid shows an onset only to within one step, so the difference
//!   is how far the reference's exact onset (or exit) lies outside the step in which the trace
//!   shows it: a lower bound of the trace's own error, never blame for the grid.
//! * **steady state** over `[steady_from, t_end]`: the kind, each metric read off the grid by
//!   the same reconstruction for the trace and the reference ([`crate::grade::gridmetrics`]; scale:
//!   the period for times, the disc's scale for speeds), and **`orbit`**, the orbit's shape
//!   compared phase-free: each steady sample's offset from the reference's steady orbit (the
//!   sample minus the orbit's nearest point, in scaled coordinates) against the reference
//!   sample's offset at the same time, the largest difference
//!   ([`crate::grade::orbit::Orbit::largest_offset_difference`]).
//!
//! Every quantity but `steady_kind` (0 or ∞) has a stated, independently verified error in the
//! reference ([`reference_error`]; `crate::grade::reference`), and no level asks more digits of a
//! quantity than that error allows, less one ([`CheckError::BeyondReference`]).
//!
//! **Phase drift.** A stable cycle's phase is neutral, so a method whose period is off by a
//! relative ε drifts by ε·t: at time t its samples are off by up to `ε·t·max|ẋ|`. The
//! grade does not excuse this: at equal times it is an error of the trace, and a
//! converging method's drift vanishes with its error. The levels allow for it instead: at
//! the 1.5 V cycle `max|ω̇_l| ≈ 8 S_l/s`, so over 200 s the samples' digits are about
//! `log10(8·200) ≈ 3.2` fewer than the period's; the levels below were set knowing this
//! (`docs/methods.md`, section "The grade"), and the phase-free quantities (`orbit`, the
//! steady metrics) say how much of a trace's error is phase.
//!
//! The trace's `digits` are the fewest of any quantity. A **level** passes when every
//! quantity reaches its digits ([`Level`]); a quantity passes when `difference ≤ tolerance`,
//! with `tolerance = scale·10^−digits`.
//!
//! **The file's precision.** A trace written with fewer significant digits than a level
//! needs cannot show that the solver reaches it: [`check`] refuses it ([`CheckError::Precision`],
//! exit 2) and names the file's precision, instead of failing the solver. Grading at N digits
//! needs N + 1 written digits (a value rounded to P digits is off by up to half a unit in its
//! P-th digit, 10^(1−P)/2 of itself).

use std::path::PathBuf;

use rotor_model::Disc;
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Event, EventKind, RigSteady, Sample};
use serde::{Serialize, Serializer};

use crate::grade::gridmetrics::{StickExit, grid_metrics_at};
use crate::grade::orbit::Orbit;
use crate::grade::reference::Reference;
use crate::grade::trace::{At, EventsFile, Trace, disc_name, event_row};
use rotor_model::FieldError;

/// The benchmark's version: named in every verdict.
pub const BENCHMARK: &str = rotor_suite::VERSION;

/// Digits of the `loose` level: engineering accuracy, 0.1 % of each quantity's scale. What
/// any converging method reaches at a reasonable cost: a first-order time-stepper at
/// h = 1e-5 on the 1.5 V cycle (`bench/clients/first_order.c`, tested in
/// `crates/rotor-harness/tests/peers.rs`).
pub const LOOSE_DIGITS: u32 = 3;
/// Digits of the `strict` level: what a well-converged adaptive integrator reaches (the
/// event-driven solver at tol 1e-11, scipy's DOP853 at rtol 1e-11 restarted at each mode
/// switch). Every graded quantity of every reference is verified to at least
/// [`crate::grade::reference::REQUIRED_DIGITS`] = strict + 2 digits, so strict is a full digit inside
/// the most any reference can grade (its digits less one); the weakest is st-u2.5-rest's α
/// and ω_l, 9.2 digits (`cargo run --release -p rotor-harness --example grade_digits`,
/// "reference verified"; enforced by `tests/grade.rs`,
/// `strict_is_a_full_digit_inside_every_reference`).
pub const STRICT_DIGITS: u32 = 7;

/// Absolute floor of the scale of α \[rad\] and of ω_u, ω_l [rad/s]: for a variable that
/// stays near 0 over the whole run (both discs stuck), digits are counted against this.
pub const FLOOR: f64 = 1e-3;

/// A level: the significant digits every graded quantity must reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// [`STRICT_DIGITS`].
    Strict,
    /// [`LOOSE_DIGITS`].
    Loose,
    /// `--digits N`.
    Digits(u32),
}

impl Level {
    /// The digits the level asks of every quantity.
    pub fn digits(self) -> u32 {
        match self {
            Level::Strict => STRICT_DIGITS,
            Level::Loose => LOOSE_DIGITS,
            Level::Digits(n) => n,
        }
    }

    /// `strict`, `loose` or `digits=N`.
    pub fn name(self) -> String {
        match self {
            Level::Strict => "strict".into(),
            Level::Loose => "loose".into(),
            Level::Digits(n) => format!("digits={n}"),
        }
    }

    /// The level of a name (`strict`, `loose`, or `digits=N` with N in 1..=15), or a
    /// [`FieldError`] naming `gate` and the value.
    pub fn parse(s: &str) -> Result<Level, FieldError> {
        match s {
            "strict" => Ok(Level::Strict),
            "loose" => Ok(Level::Loose),
            _ => match s.strip_prefix("digits=") {
                Some(n) => Level::with_digits(n).map_err(|e| FieldError {
                    field: "gate".into(),
                    ..e
                }),
                None => Err(FieldError::new(
                    "gate",
                    format!("{s:?}"),
                    format!(
                        "expected strict ({STRICT_DIGITS} significant digits), loose \
                         ({LOOSE_DIGITS}) or digits=N"
                    ),
                )),
            },
        }
    }

    /// `--digits N`: N in 1..=15 (a double holds 15 to 17), or a [`FieldError`] naming `digits`.
    pub fn with_digits(n: &str) -> Result<Level, FieldError> {
        match n.trim().parse::<u32>() {
            Ok(d) if (1..=15).contains(&d) => Ok(Level::Digits(d)),
            _ => Err(FieldError::new(
                "digits",
                format!("{n:?}"),
                "expected a whole number of significant digits from 1 to 15",
            )),
        }
    }
}

impl Serialize for Level {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

/// One graded quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Graded {
    /// The quantity (`alpha`, `omega_l`, `events`, `stick_lower`, `period`, `orbit`, ...; see
    /// the module docs).
    pub name: String,
    /// The difference from the reference, in the quantity's unit (∞ when it cannot be
    /// measured: a missing event, another kind of steady state).
    pub difference: f64,
    /// What the difference is measured against (same unit).
    pub scale: f64,
    /// The largest difference the level allows: `scale·10^−digits`.
    pub tolerance: f64,
    /// Whether `difference ≤ tolerance`.
    pub passed: bool,
    /// Significant correct digits, `−log10(difference/scale)` (0 … 16, one decimal).
    pub digits: f64,
    /// Where the difference is largest \[s\], when it is at one time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<f64>,
    /// What went wrong, when the difference alone does not say (missing or extra events).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The verdict on one trace (the JSON of `rotor check --json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckReport {
    /// The scenario's name.
    pub scenario: String,
    /// The benchmark's version ([`BENCHMARK`]).
    pub benchmark: &'static str,
    /// Whether every graded quantity passed.
    pub passed: bool,
    /// The level's name: `strict`, `loose` or `digits=N`.
    pub gate: Level,
    /// The fewest digits of any graded quantity.
    pub digits: f64,
    /// What the scenario defines that was not graded (`events` without an events file).
    pub not_graded: Vec<String>,
    /// Significant digits the trace file is written with (17 for arrays).
    pub file_digits: u32,
    /// Every graded quantity, in a fixed order: the trace's variables, the events, the stick
    /// intervals, the steady state.
    pub quantities: Vec<Graded>,
}

impl CheckReport {
    /// The names of the failing quantities.
    pub fn failing(&self) -> Vec<&str> {
        self.quantities
            .iter()
            .filter(|q| !q.passed)
            .map(|q| q.name.as_str())
            .collect()
    }

    /// The verdict line: `PASSED`, `FAILED`, and what was not graded, if anything (never a
    /// plain `PASSED` for a partial grade).
    pub fn verdict(&self) -> String {
        let mut v = format!(
            "{}: {} at {} ({} digits), {:.1} digits",
            self.scenario,
            if self.passed { "PASSED" } else { "FAILED" },
            self.gate.name(),
            self.gate.digits(),
            self.digits,
        );
        for n in &self.not_graded {
            v.push_str(&format!("; {n} not graded"));
            if n == "events" {
                v.push_str(" (no events file)");
            }
        }
        v + &format!(" [{}]", self.benchmark)
    }

    /// A table for the terminal.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{}\n{:<20} {:>12} {:>12} {:>12} {:>7}  {}\n",
            self.verdict(),
            "quantity",
            "difference",
            "scale",
            "tolerance",
            "digits",
            "verdict"
        );
        for q in &self.quantities {
            out.push_str(&format!(
                "{:<20} {:>12.3e} {:>12.3e} {:>12.3e} {:>7.1}  {}{}{}\n",
                q.name,
                q.difference,
                q.scale,
                q.tolerance,
                q.digits,
                if q.passed { "pass" } else { "FAIL" },
                q.at.map_or(String::new(), |t| format!(" (at t = {} s)", grid_time(t))),
                q.note.as_ref().map_or(String::new(), |n| format!(": {n}")),
            ));
        }
        out
    }
}

/// A time as the trace writes it: rounded to 1e-9 s, the grid's time tolerance (a sample at
/// k·dt is 125.71000000000001 in floating point; the table shows 125.71).
fn grid_time(t: f64) -> f64 {
    let r = (t * 1e9).round() / 1e9;
    if r.is_finite() { r } else { t }
}

/// A trace (or events file) that cannot be graded; the message names the file and the line,
/// or the missing time.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckError {
    /// The trace or events file could not be read as one.
    #[error(transparent)]
    Trace(#[from] crate::grade::trace::TraceError),
    /// A row's time is not the reference's grid time at that row.
    #[error("{}: t = {found} is not the grid time {expected} (the scenario's grid: every {dt} s from 0 to {t_end} s, times within 1e-9 s)", At(.path, *.line))]
    OffGrid {
        /// The trace file (or [`crate::grade::trace::ARRAYS`]).
        path: PathBuf,
        /// The row's line (its index for arrays).
        line: u64,
        /// The row's time \[s\].
        found: f64,
        /// The grid time expected there \[s\].
        expected: f64,
        /// The scenario's grid step \[s\].
        dt: f64,
        /// The scenario's horizon \[s\].
        t_end: f64,
    },
    /// The trace stops before `t_end`.
    #[error("{}: the trace ends here (t = {last}); the grid time {missing} s and later are missing", At(.path, *.line))]
    Missing {
        /// The trace file (or [`crate::grade::trace::ARRAYS`]).
        path: PathBuf,
        /// The last row's line.
        line: u64,
        /// The last row's time \[s\].
        last: f64,
        /// The first grid time without a row \[s\].
        missing: f64,
    },
    /// The trace has rows past the grid's last time.
    #[error("{}: t = {found} is past the grid's last time {t_end} s", At(.path, *.line))]
    Extra {
        /// The trace file (or [`crate::grade::trace::ARRAYS`]).
        path: PathBuf,
        /// The first extra row's line.
        line: u64,
        /// Its time \[s\].
        found: f64,
        /// The scenario's horizon \[s\].
        t_end: f64,
    },
    /// An event lies outside the run or out of time order.
    #[error("{}: event time {t} is outside [0, {t_end}] s or before the previous event", At(.path, *.line))]
    EventTime {
        /// The events file (or [`crate::grade::trace::ARRAYS`]).
        path: PathBuf,
        /// The event's line.
        line: u64,
        /// Its time \[s\].
        t: f64,
        /// The scenario's horizon \[s\].
        t_end: f64,
    },
    /// The trace is written with too few digits to show the level ([`check`] refuses it rather
    /// than fail the solver).
    #[error(
        "{}: the trace is written with {digits} significant digits (printf's %g writes 6); \
         grading at {level} ({needed_digits} digits) needs at least {needed}: write every value \
         with %.17g or a shortest round-trip format",
        .path.display(), needed_digits = .needed - 1
    )]
    Precision {
        /// The trace file.
        path: PathBuf,
        /// Significant digits the file is written with ([`Trace::digits`]).
        digits: u32,
        /// The level asked ([`Level::name`]).
        level: String,
        /// Written digits the level needs: its digits + 1.
        needed: u32,
    },
    /// The level asks more digits of a quantity than the reference is verified to, less one.
    #[error(
        "{level} asks {asked} digits of {quantity}, but the reference of {scenario} is verified \
         to {verified:.1} digits there: it cannot grade more than {most} (one digit below its own)"
    )]
    BeyondReference {
        /// The scenario's name.
        scenario: String,
        /// The level asked ([`Level::name`]).
        level: String,
        /// The digits it asks of every quantity.
        asked: u32,
        /// The first quantity whose reference is not verified far enough.
        quantity: String,
        /// Digits to which the reference is verified there, `−log10(error/scale)`.
        verified: f64,
        /// The most digits that can be graded there: `verified − 1`, rounded down.
        most: u32,
    },
}

/// Times within this of the grid's are the grid's \[s\].
pub(crate) const TIME_TOL: f64 = 1e-9;

/// Checks that the trace has exactly the reference's grid times.
fn check_grid(trace: &Trace, reference: &[Sample], dt: f64, t_end: f64) -> Result<(), CheckError> {
    let times: Vec<f64> = trace.samples.iter().map(|s| s.t).collect();
    let ref_times: Vec<f64> = reference.iter().map(|s| s.t).collect();
    check_times(&trace.path, &trace.lines, &times, &ref_times, dt, t_end)
}

/// Checks that a trace's times (`times`, from the file `path`, row `k` on line `lines[k]`)
/// are exactly the reference's grid times `reference`.
pub(crate) fn check_times(
    path: &std::path::Path,
    lines: &[u64],
    times: &[f64],
    reference: &[f64],
    dt: f64,
    t_end: f64,
) -> Result<(), CheckError> {
    let path = || path.to_owned();
    for (i, &t) in times.iter().enumerate() {
        let line = lines[i];
        let Some(&r) = reference.get(i) else {
            return Err(CheckError::Extra {
                path: path(),
                line,
                found: t,
                t_end,
            });
        };
        if (t - r).abs() > TIME_TOL {
            return Err(CheckError::OffGrid {
                path: path(),
                line,
                found: t,
                expected: r,
                dt,
                t_end,
            });
        }
    }
    if times.len() < reference.len() {
        let i = times.len();
        return Err(CheckError::Missing {
            path: path(),
            line: lines.last().copied().unwrap_or(1),
            last: times.last().copied().unwrap_or(f64::NAN),
            missing: reference[i],
        });
    }
    Ok(())
}

/// Checks an events file's times (within the run, in order).
pub fn check_events(f: &EventsFile, t_end: f64) -> Result<(), CheckError> {
    let mut prev = f64::NEG_INFINITY;
    for (e, &line) in f.events.iter().zip(&f.lines) {
        if !(e.t >= -TIME_TOL && e.t <= t_end + TIME_TOL && e.t >= prev) {
            return Err(CheckError::EventTime {
                path: f.path.clone(),
                line,
                t: e.t,
                t_end,
            });
        }
        prev = e.t;
    }
    Ok(())
}

/// `−log10(diff/scale)`, one decimal (rounded down), within [0, 16].
pub fn digits(diff: f64, scale: f64) -> f64 {
    if !diff.is_finite() {
        return 0.0;
    }
    if diff == 0.0 {
        return 16.0;
    }
    let d = -(diff / scale.abs().max(f64::MIN_POSITIVE)).log10();
    (d.clamp(0.0, 16.0) * 10.0).floor() / 10.0 + 0.0
}

/// A quantity graded at `level`.
pub(crate) fn graded(name: &str, difference: f64, scale: f64, level: Level) -> Graded {
    let tolerance = scale * 10f64.powi(-(level.digits() as i32));
    Graded {
        name: name.to_owned(),
        difference,
        scale,
        tolerance,
        // `!(d > tol)` would pass a NaN: written so that a NaN fails.
        passed: difference <= tolerance,
        digits: digits(difference, scale),
        at: None,
        note: None,
    }
}

/// The scale of each state variable in the reference run: its largest |value|, at least
/// [`FLOOR`].
pub fn state_scales(reference: &[Sample]) -> [f64; 3] {
    let mut s = [FLOOR; 3];
    for r in reference {
        for (i, si) in s.iter_mut().enumerate() {
            *si = si.max(r.x[i].abs());
        }
    }
    s
}

/// The motion's time scale \[s\]: the period of the reference's steady cycle, else 1 s (a
/// transient to an equilibrium has no period to measure event times against).
pub fn time_scale(reference: &Reference) -> f64 {
    match reference.steady() {
        Some(RigSteady::LimitCycle { period, .. }) => period,
        _ => 1.0,
    }
}

/// The reference's stated error that bounds a quantity's (trace errors for the samples, event
/// times for events and stick intervals, the orbit's and each metric's own), if stated.
/// `steady_kind` has none: it is 0 or ∞, and the reference's kind is verified
/// (`tests/reference_verified.rs`).
pub fn reference_error(reference: &Reference, quantity: &str) -> Option<f64> {
    let e = |k: &str| reference.json.error.get(k).copied();
    match quantity {
        "alpha" | "omega_u" | "omega_l" | "orbit" => e(quantity),
        "events" | "stick_lower" | "stick_upper" => e("event_time"),
        "steady_kind" => None,
        q => {
            let m = q.strip_prefix("steady_")?;
            e(m)
        }
    }
}

/// Checks that a level asks no more digits of any quantity than the reference is verified
/// to, less one: `digits(reference error, scale) − 1`.
fn within_reference(
    sc: &Scenario,
    reference: &Reference,
    quantities: &[Graded],
    level: Level,
) -> Result<(), CheckError> {
    within_stated(&sc.name, quantities, level, |q| {
        reference_error(reference, q)
    })
}

/// [`within_reference`] for any reference: `error_of` gives a quantity's stated error (`None`:
/// not bounded by one).
pub(crate) fn within_stated(
    scenario: &str,
    quantities: &[Graded],
    level: Level,
    error_of: impl Fn(&str) -> Option<f64>,
) -> Result<(), CheckError> {
    for q in quantities {
        let Some(err) = error_of(&q.name) else {
            continue;
        };
        let verified = -(err / q.scale).log10();
        let most = (verified - 1.0).floor().max(0.0) as u32;
        if level.digits() > most {
            return Err(CheckError::BeyondReference {
                scenario: scenario.to_owned(),
                level: level.name(),
                asked: level.digits(),
                quantity: q.name.clone(),
                verified,
                most,
            });
        }
    }
    Ok(())
}

/// Refuses a trace written with fewer significant digits than `level` needs (its digits + 1).
pub(crate) fn written_enough(
    path: &std::path::Path,
    digits: u32,
    level: Level,
) -> Result<(), CheckError> {
    let needed = level.digits() + 1;
    if digits < needed {
        return Err(CheckError::Precision {
            path: path.to_owned(),
            digits,
            level: level.name(),
            needed,
        });
    }
    Ok(())
}

/// The largest |Δ| of each state variable over every sample, and where.
fn sample_differences(trace: &[Sample], reference: &[Sample]) -> [(f64, f64); 3] {
    let mut d = [(0.0f64, 0.0f64); 3];
    for (a, r) in trace.iter().zip(reference) {
        for (i, di) in d.iter_mut().enumerate() {
            let e = (a.x[i] - r.x[i]).abs();
            if e.is_nan() || e > di.0 {
                *di = (e, r.t);
            }
        }
    }
    d
}

/// An event as the files name it: `lower stick_start at 4.7677 s` (`disc 3 ...` in a chain
/// of `n` > 2 discs).
fn describe(e: &Event, n: usize) -> String {
    let (disc, kind) = event_row(e.kind).map_or(("?".into(), "?"), |(d, k)| {
        (if n == 2 { disc_name(d) } else { d.name_in(n) }, k)
    });
    format!("{disc} {kind} at {} s", e.t)
}

/// Names the first few of `events` (of a chain of `n` discs), and how many more there are.
fn name_some(what: &str, events: &[Event], n: usize) -> Option<String> {
    if events.is_empty() {
        return None;
    }
    let shown: Vec<String> = events.iter().take(3).map(|e| describe(e, n)).collect();
    let more = if events.len() > 3 {
        format!(" and {} more", events.len() - 3)
    } else {
        String::new()
    };
    Some(format!(
        "{} {what}: {}{more}",
        events.len(),
        shown.join(", ")
    ))
}

/// Matches two time-ordered lists one to one: each reference time with the next unused
/// trace time within `window` of it, in order. Returns the matched pairs' largest |Δt| and
/// the unmatched of each list (missing from the trace, extra in it).
fn match_in_order(reference: &[f64], trace: &[f64], window: f64) -> (f64, Vec<usize>, Vec<usize>) {
    let (mut i, mut j) = (0, 0);
    let (mut worst, mut missing, mut extra) = (0.0f64, Vec::new(), Vec::new());
    while i < reference.len() && j < trace.len() {
        let d = trace[j] - reference[i];
        if d.abs() <= window {
            worst = worst.max(d.abs());
            i += 1;
            j += 1;
        } else if d < 0.0 {
            extra.push(j);
            j += 1;
        } else {
            missing.push(i);
            i += 1;
        }
    }
    missing.extend(i..reference.len());
    extra.extend(j..trace.len());
    (worst, missing, extra)
}

/// The `events` quantity: every mode switch of any disc (of `n`) over the run, matched one to
/// one by disc and kind, each within half the shortest gap between two reference events of
/// its class (so that a match is never ambiguous).
pub(crate) fn grade_events(
    reference: &[Event],
    trace: &[Event],
    n: usize,
    t_scale: f64,
    level: Level,
) -> Graded {
    let switches = |ev: &[Event]| -> Vec<Event> {
        ev.iter()
            .filter(|e| event_row(e.kind).is_some())
            .cloned()
            .collect()
    };
    let (reference, trace) = (switches(reference), switches(trace));
    let mut classes: Vec<EventKind> = reference.iter().chain(&trace).map(|e| e.kind).collect();
    classes.sort_by_key(|k| (k.disc(), event_row(*k).map(|(_, name)| name)));
    classes.dedup();
    let (mut worst, mut missing, mut extra) = (0.0f64, Vec::new(), Vec::new());
    for kind in classes {
        let of = |ev: &[Event]| -> Vec<Event> {
            ev.iter().filter(|e| e.kind == kind).cloned().collect()
        };
        let (r, a) = (of(&reference), of(&trace));
        let gap = r
            .windows(2)
            .map(|w| w[1].t - w[0].t)
            .fold(t_scale, f64::min);
        let times = |ev: &[Event]| ev.iter().map(|e| e.t).collect::<Vec<_>>();
        let (w, m, x) = match_in_order(&times(&r), &times(&a), 0.5 * gap);
        worst = worst.max(w);
        missing.extend(m.into_iter().map(|k| r[k].clone()));
        extra.extend(x.into_iter().map(|k| a[k].clone()));
    }
    missing.sort_by(|a, b| a.t.total_cmp(&b.t));
    extra.sort_by(|a, b| a.t.total_cmp(&b.t));
    let unmatched = !missing.is_empty() || !extra.is_empty();
    let mut g = graded(
        "events",
        if unmatched { f64::INFINITY } else { worst },
        t_scale,
        level,
    );
    let notes: Vec<String> = [
        name_some("missing from the trace's events", &missing, n),
        name_some("extra (not in the reference)", &extra, n),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !notes.is_empty() {
        g.note = Some(notes.join("; "));
    }
    g
}

/// |ω| at or below which a sample of a disc counts as stuck at `level` \[rad/s\]: the level's
/// tolerance of that disc's ω samples, `S_ω·10^−digits` (`scale`: the disc's scale `S_ω`,
/// [`state_scales`]).
///
/// A stuck reference sample is exactly 0, so a trace sample within the level's sample
/// tolerance of 0 agrees with it at that level, whatever the trace's solver holds a stuck disc
/// at: exactly 0 (event-driven), its complementarity solver's rounding (≈ 1e-13, Moreau–Jean),
/// or anywhere in a band `|ω| ≤ η` (a switch model, Karnopp's law). A sample further from 0
/// fails the `omega_u`/`omega_l` quantity at that level anyway, so the stick intervals are
/// graded exactly as finely as the samples. Both traces are classified alike, so a slipping
/// sample of the reference inside the threshold (next to an onset or a reversal) is a stuck
/// sample of a correct trace too: only a trace whose error there exceeds the distance of the
/// reference's |ω| from the threshold sees another run, as with any threshold. Loose: 1e-3 of
/// the disc's scale (a few mrad/s); strict: 1e-7 of it (about 1e-6 rad/s on Table 1).
pub fn stuck_threshold(scale: f64, level: Level) -> f64 {
    scale * 10f64.powi(-(level.digits() as i32))
}

/// Runs of consecutive stuck samples of a velocity (|ω| ≤ `stuck`), as index pairs.
fn stuck_runs(omega: &[f64], stuck: f64) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut start = None;
    for (k, w) in omega.iter().enumerate() {
        match (w.abs() <= stuck, start) {
            (true, None) => start = Some(k),
            (false, Some(a)) => {
                runs.push((a, k - 1));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(a) = start {
        runs.push((a, omega.len() - 1));
    }
    runs
}

/// The stick intervals of one disc visible on the grid, graded against the reference's
/// exact ones (`None` when neither shows a stuck sample of that disc).
fn grade_stick(
    disc: Disc,
    trace: &[Sample],
    reference: &Reference,
    scale: [f64; 3],
    t_scale: f64,
    level: Level,
) -> Option<Graded> {
    let i = disc.index();
    let column = |s: &[Sample]| -> (Vec<f64>, Vec<f64>) { s.iter().map(|r| (r.t, r.x[i])).unzip() };
    grade_stick_of(
        &format!("stick_{}", disc_name(disc)),
        disc,
        column(trace),
        column(&reference.samples),
        &reference.events,
        scale[i],
        t_scale,
        level,
    )
}

/// The stick intervals of `disc` (named `name`): the trace's and the reference's samples of
/// its velocity as `(times, ω)`, the reference's exact events, the disc's velocity scale.
#[allow(clippy::too_many_arguments)]
pub(crate) fn grade_stick_of(
    name: &str,
    disc: Disc,
    (trace, trace_w): (Vec<f64>, Vec<f64>),
    (rs, rs_w): (Vec<f64>, Vec<f64>),
    events: &[Event],
    scale: f64,
    t_scale: f64,
    level: Level,
) -> Option<Graded> {
    let stuck = stuck_threshold(scale, level);
    let (ref_runs, runs) = (stuck_runs(&rs_w, stuck), stuck_runs(&trace_w, stuck));
    if ref_runs.is_empty() && runs.is_empty() {
        return None;
    }
    let last = rs.len() - 1;
    // The reference's exact onset and exit of a run: its events in the steps that bracket
    // the run's first and last stuck sample (0 and t_end at the run's ends).
    let exact = |(a, b): (usize, usize)| -> (f64, f64) {
        let find = |kind: EventKind, lo: f64, hi: f64, fallback: f64| {
            events
                .iter()
                .find(|e| e.kind == kind && e.t > lo - 1e-12 && e.t <= hi + 1e-12)
                .map_or(fallback, |e| e.t)
        };
        let on = if a == 0 {
            0.0
        } else {
            find(EventKind::StickStart(disc), rs[a - 1], rs[a], rs[a])
        };
        let off = if b == last {
            rs[last]
        } else {
            find(EventKind::StickEnd(disc), rs[b], rs[b + 1], rs[b])
        };
        (on, off)
    };
    // The steps in which the trace shows its onset and its exit.
    let bracket = |(a, b): (usize, usize)| -> ((f64, f64), (f64, f64)) {
        let on = if a == 0 {
            (0.0, 0.0)
        } else {
            (trace[a - 1], trace[a])
        };
        let off = if b + 1 >= trace.len() {
            (trace[b], trace[b])
        } else {
            (trace[b], trace[b + 1])
        };
        (on, off)
    };
    let outside = |t: f64, (lo, hi): (f64, f64)| (lo - t).max(t - hi).max(0.0);
    let (mut k, mut m) = (0, 0);
    let (mut worst, mut at, mut missing, mut extra) = (0.0f64, None, Vec::new(), Vec::new());
    while k < ref_runs.len() && m < runs.len() {
        let (ra, rb) = ref_runs[k];
        let (ta, tb) = runs[m];
        if ta <= rb + 1 && ra <= tb + 1 {
            let (on, off) = exact(ref_runs[k]);
            let (b_on, b_off) = bracket(runs[m]);
            for (d, t) in [(outside(on, b_on), on), (outside(off, b_off), off)] {
                if d > worst {
                    (worst, at) = (d, Some(t));
                }
            }
            k += 1;
            m += 1;
        } else if tb < ra {
            extra.push(trace[ta]);
            m += 1;
        } else {
            missing.push(exact(ref_runs[k]).0);
            k += 1;
        }
    }
    missing.extend(ref_runs[k..].iter().map(|&r| exact(r).0));
    extra.extend(runs[m..].iter().map(|&(a, _)| trace[a]));
    let unmatched = !missing.is_empty() || !extra.is_empty();
    let mut g = graded(
        name,
        if unmatched { f64::INFINITY } else { worst },
        t_scale,
        level,
    );
    g.at = if unmatched { None } else { at };
    let list = |v: &[f64]| {
        let shown: Vec<String> = v.iter().take(3).map(|t| format!("{t} s")).collect();
        let more = if v.len() > 3 {
            format!(" and {} more", v.len() - 3)
        } else {
            String::new()
        };
        format!("{}{more}", shown.join(", "))
    };
    let mut notes = Vec::new();
    if !missing.is_empty() {
        notes.push(format!(
            "{} stick interval(s) of the reference not in the trace (|omega| <= {stuck:.1e} rad/s \
             at this level), from {}",
            missing.len(),
            list(&missing)
        ));
    }
    if !extra.is_empty() {
        notes.push(format!(
            "{} stick interval(s) in the trace not in the reference, from {}",
            extra.len(),
            list(&extra)
        ));
    }
    if !notes.is_empty() {
        g.note = Some(notes.join("; "));
    }
    Some(g)
}

/// The steady state: kind, metrics and the orbit's shape.
fn grade_steady(
    sc: &Scenario,
    reference: &Reference,
    trace: &[Sample],
    from: f64,
    scale: [f64; 3],
    level: Level,
) -> Vec<Graded> {
    let exit = StickExit {
        model: &sc.model,
        u: sc.steady_u(),
    };
    let mut q = Vec::new();
    let stuck = stuck_threshold(scale[2], level);
    let (sa, sr) = (
        grid_metrics_at(trace, from, exit, stuck),
        grid_metrics_at(&reference.samples, from, exit, stuck),
    );
    let (Ok(a), Ok(r)) = (sa, sr) else {
        q.push(graded("steady_kind", f64::INFINITY, 1.0, level));
        return q;
    };
    if a.kind() != r.kind() {
        let mut g = graded("steady_kind", f64::INFINITY, 1.0, level);
        g.note = Some(format!(
            "the trace settles to {}, the reference to {}",
            a.kind().as_str(),
            r.kind().as_str()
        ));
        q.push(g);
        return q;
    }
    q.push(graded("steady_kind", 0.0, 1.0, level));
    let period = match r {
        RigSteady::LimitCycle { period, .. } => period,
        RigSteady::Equilibrium { .. } => 1.0,
    };
    for ((name, va), (_, vr)) in a.values().into_iter().zip(r.values()) {
        let s = match name {
            "period" | "stick_time" => period,
            "omega_l_max" | "omega_l_min" | "omega_l" => scale[2],
            "omega_u_max" | "omega_u_min" | "omega_u" => scale[1],
            _ => scale[0],
        };
        q.push(graded(&format!("steady_{name}"), (va - vr).abs(), s, level));
    }
    // The orbit's shape, phase-free (a cycle only: the equilibrium's samples are graded at
    // equal times above, and a slow focus is still on its way there at `steady_from`).
    let Some(distance) = orbit_distance(sc, reference, r, trace, from, scale) else {
        return q;
    };
    let mut g = match distance {
        Ok((d, at)) => {
            let mut g = graded("orbit", d, 1.0, level);
            g.at = Some(at).filter(|t| t.is_finite());
            g
        }
        Err(e) => {
            let mut g = graded("orbit", f64::INFINITY, 1.0, level);
            g.note = Some(format!("the reference orbit could not be computed: {e}"));
            g
        }
    };
    if g.difference.is_nan() {
        g.difference = f64::INFINITY;
    }
    q.push(g);
    q
}

/// The `orbit` quantity of `trace`: the largest difference between its samples' offsets at
/// `t ≥ from` from the reference's steady orbit and the reference samples' offsets at the same
/// times ([`Orbit::largest_offset_difference`]; the orbit recomputed by the reference solver
/// from the reference's sample at `from`, over the period of `reference`'s steady state, else
/// of `cycle`), in coordinates scaled by `scale`, and the time of the sample where it is.
/// `None` when the steady state is no cycle.
pub fn orbit_distance(
    sc: &Scenario,
    reference: &Reference,
    cycle: RigSteady,
    trace: &[Sample],
    from: f64,
    scale: [f64; 3],
) -> Option<Result<(f64, f64), rotor_model::seam::SolveError>> {
    let RigSteady::LimitCycle { period, .. } = reference.steady().unwrap_or(cycle) else {
        return None;
    };
    let window = &trace[trace.partition_point(|s| s.t < from - TIME_TOL)..];
    let rs = &reference.samples;
    let k = rs
        .partition_point(|s| s.t < from - TIME_TOL)
        .min(rs.len() - 1);
    Some(
        Orbit::cycle(sc, rs[k].x, period, reference.json.tol, scale)
            .map(|o| o.largest_offset_difference(window, &rs[k..])),
    )
}

/// Grades a trace (and optionally its events) against the reference of scenario `sc` at
/// `level` (see the module docs for what is graded and how).
///
/// ```
/// use rotor_harness::grade::check::{Level, check};
/// use rotor_harness::grade::{reference, trace};
/// let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
/// let sc = rotor_analysis::solvers::load_scenario(&fixtures.join("scenarios/t1-u1.5-rest.toml")).unwrap();
/// let r = reference::read(&fixtures.join("reference"), &sc.name).unwrap();
/// // The reference's own trace, read as a solver's would be: it passes the strict level.
/// let tr = trace::read_trace(&fixtures.join("reference/t1-u1.5-rest.csv"), usize::MAX).unwrap();
/// let report = check(&sc, &r, &tr, None, Level::Strict).unwrap();
/// assert!(report.passed && report.not_graded == ["events"]);
/// println!("{}", report.verdict());
/// ```
pub fn check(
    sc: &Scenario,
    reference: &Reference,
    trace: &Trace,
    events: Option<&EventsFile>,
    level: Level,
) -> Result<CheckReport, CheckError> {
    check_grid(trace, &reference.samples, sc.compare.dt, sc.t_end)?;
    if let Some(f) = events {
        check_events(f, sc.t_end)?;
    }
    written_enough(&trace.path, trace.digits, level)?;
    let scale = state_scales(&reference.samples);
    let t_scale = time_scale(reference);
    let mut q = Vec::new();
    let d = sample_differences(&trace.samples, &reference.samples);
    for (i, name) in rotor_model::RIG_STATE_NAMES.into_iter().enumerate() {
        let mut g = graded(name, d[i].0, scale[i], level);
        g.at = Some(d[i].1);
        q.push(g);
    }
    let mut not_graded = Vec::new();
    match events {
        Some(f) => q.push(grade_events(
            &reference.events,
            &f.events,
            2,
            t_scale,
            level,
        )),
        None => not_graded.push("events".to_owned()),
    }
    for disc in [Disc::LOWER, Disc::UPPER] {
        q.extend(grade_stick(
            disc,
            &trace.samples,
            reference,
            scale,
            t_scale,
            level,
        ));
    }
    if let Some(from) = sc.compare.steady_from {
        q.extend(grade_steady(
            sc,
            reference,
            &trace.samples,
            from,
            scale,
            level,
        ));
    }
    within_reference(sc, reference, &q, level)?;
    Ok(CheckReport {
        scenario: sc.name.clone(),
        benchmark: BENCHMARK,
        passed: q.iter().all(|g| g.passed),
        gate: level,
        digits: q.iter().map(|g| g.digits).fold(16.0, f64::min),
        not_graded,
        file_digits: trace.digits,
        quantities: q,
    })
}

/// Why a trace cannot be graded at all: the scenario or its reference cannot be read, or the
/// trace (or events) is unusable.
#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    /// The scenario file is not a valid scenario.
    #[error(transparent)]
    Scenario(#[from] rotor_model::scenario::ScenarioError),
    /// Its reference data cannot be read.
    #[error(transparent)]
    Reference(#[from] crate::grade::reference::ReferenceError),
    /// The trace (or events) cannot be graded.
    #[error(transparent)]
    Check(#[from] CheckError),
}

/// `rotor check`'s grading: the scenario file, its reference from `fixtures/reference` beside
/// it ([`crate::grade::reference::dir_for`]), and [`check`].
///
/// # Example
///
/// Grading a solver's run as an external trace: Moreau–Jean at h = 1e-3 on the named
/// scenario `t1-u1.5-rest` (Table 1, 1.5 V from rest, 200 s), with its events. A
/// second-order time-stepper at that step reaches the loose level (3 digits) on every
/// quantity, but not the strict one (7 digits).
///
/// ```
/// use rotor_harness::grade::check::{Level, grade};
/// use rotor_harness::grade::trace::{EventsFile, Trace};
/// use rotor_analysis::solvers::{SolverKind, load_scenario, run::scene_for};
///
/// let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
/// let path = fixtures.join("scenarios/t1-u1.5-rest.toml");
/// let sc = load_scenario(&path)?;
/// // The scenario's comparison scene: its grid (0.01 s), events and steady window.
/// let kind = SolverKind::MOREAU;
/// let run = kind.solver().simulate(&sc.model, &scene_for(kind, &sc))?;
/// let trace = Trace::of_run("moreau.csv", &run.samples);
/// let events = EventsFile::of_run("moreau.events.csv", &run.events);
///
/// let loose = grade(&path, &trace, Some(&events), Level::Loose)?;
/// println!("{}", loose.table());
/// assert!(loose.passed, "{}", loose.verdict());
/// assert!(loose.not_graded.is_empty(), "the events were graded too");
/// let strict = grade(&path, &trace, Some(&events), Level::Strict)?;
/// assert!(!strict.passed && !strict.failing().is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn grade(
    scenario: &std::path::Path,
    trace: &Trace,
    events: Option<&EventsFile>,
    level: Level,
) -> Result<CheckReport, GradeError> {
    let sc = rotor_analysis::solvers::load_scenario(scenario)?;
    let r = crate::grade::reference::read(&crate::grade::reference::dir_for(scenario), &sc.name)?;
    Ok(check(&sc, &r, trace, events, level)?)
}

#[cfg(test)]
mod time_format_tests {
    /// 12571 steps of 0.01 s are 125.71000000000001 in floating point; the table prints the
    /// grid's digits, and keeps a time no grid rounding applies to.
    #[test]
    fn grid_times_print_with_the_digits_they_have() {
        let t = 12571.0 * 0.01;
        assert_eq!(format!("{t}"), "125.71000000000001");
        assert_eq!(format!("{}", super::grid_time(t)), "125.71");
        assert_eq!(format!("{}", super::grid_time(0.035)), "0.035");
        assert_eq!(super::grid_time(1e300), 1e300);
    }
}
