//! The trace file format of the benchmark: CSV with the header `t,alpha,omega_u,omega_l` and
//! one row per output time, written and read with the `csv` crate (floats in the shortest
//! form that reads back to the same number).
//!
//! Reading is strict, because a trace graded against the reference must be what it claims:
//! a wrong header, a field that is not a finite number, a row of the wrong length or an empty
//! file is an error naming the file, the line and the column.
//!
//! The events file of the benchmark (`t,disc,kind`, disc `upper|lower`, kind
//! `stick_start|stick_end|reversal`) is written and read here as well.

use std::io::Read;
use std::path::{Path, PathBuf};

use rotor_model::seam::{Event, EventKind, Sample, Samples};
use rotor_model::{Disc, State};
use thiserror::Error;

/// The header of a trace file.
pub(crate) const TRACE_HEADER: [&str; 4] = ["t", "alpha", "omega_u", "omega_l"];

/// Decimals that print a grid time `k·dt` without its binary noise: six past the first
/// significant digit of dt (the grid's times are k·dt within an ulp, so the printed time is
/// within 1e-6 dt of the time the state was taken at).
pub fn time_digits(dt: f64) -> i32 {
    (6.0 - dt.log10().floor()).clamp(0.0, 300.0) as i32
}

/// `t` rounded to `digits` decimals: `3 × 0.3 = 0.8999999999999999` prints as `0.9`.
/// (Division of an integer-valued float by a power of ten is correctly rounded, so the
/// result is the float nearest the decimal, which prints as that decimal. Where t·10^digits
/// exceeds 2^53 the value is already an integer multiple of the spacing and stays.)
pub fn round_to(t: f64, digits: i32) -> f64 {
    let scale = 10f64.powi(digits);
    let r = (t * scale).round() / scale;
    if r.is_finite() { r } else { t }
}

/// The samples of a run on the grid of step `dt` as a trace file (times rounded to the
/// grid's decimals, [`time_digits`]), its header the state's names for its size
/// ([`rotor_model::state_names`]: `t,alpha,omega_u,omega_l` for the rig).
pub fn write_trace(samples: &Samples, dt: f64) -> Vec<u8> {
    let mut out = Vec::with_capacity(samples.len() * (24 * samples.dim() + 8) + 32);
    write_trace_to(&mut out, samples, dt).expect("in memory");
    out
}

/// [`write_trace`] into a writer, row by row: the trace never sits in memory as text (fresh
/// memory costs a page fault per 4 kB; for 10⁴ rows that is a fair part of the solve).
pub fn write_trace_to(w: impl std::io::Write, samples: &Samples, dt: f64) -> std::io::Result<()> {
    write_named_trace_to(w, &rotor_model::state_names(samples.dim()), samples, dt)
}

/// [`write_trace_to`] with the state's columns named `names` (a model's own names: a chain
/// of two written in chain form is headed `alpha_1,omega_1,omega_2`, not the rig's names).
pub fn write_named_trace_to(
    mut w: impl std::io::Write,
    names: &[String],
    samples: &Samples,
    dt: f64,
) -> std::io::Result<()> {
    debug_assert_eq!(names.len(), samples.dim(), "a name per state value");
    let mut header = String::from("t");
    for n in names {
        header.push(',');
        header.push_str(n);
    }
    header.push('\n');
    w.write_all(header.as_bytes())?;
    write_rows(&mut w, samples, time_digits(dt))?;
    w.flush()
}

/// The rows of `samples` (no header) into `w`, through the csv writer.
fn write_rows(w: impl std::io::Write, samples: &Samples, digits: i32) -> std::io::Result<()> {
    // Numbers never need quotes: the writer skips scanning for them.
    let mut w = csv::WriterBuilder::new()
        .quote_style(csv::QuoteStyle::Never)
        .buffer_capacity(1 << 16)
        .from_writer(w);
    let mut t_buf = zmij::Buffer::new();
    let mut bufs: Vec<zmij::Buffer> = (0..samples.dim()).map(|_| zmij::Buffer::new()).collect();
    for s in samples {
        let t = t_buf.format(round_to(s.t, digits));
        let xs = bufs.iter_mut().zip(s.x).map(|(b, &v)| b.format(v));
        w.write_record(std::iter::once(t).chain(xs))?;
    }
    w.flush()
}

/// The name of a trace given as arrays (the Python package's `check`) instead of a file: its
/// rows are named by their index, not a line.
pub const ARRAYS: &str = "<arrays>";

/// Where a row is, for messages: `trace.csv: line 7`, or `index 5` for a trace given as
/// arrays ([`ARRAYS`]).
#[derive(Debug, Clone, Copy)]
pub struct At<'a>(pub &'a Path, pub u64);

impl std::fmt::Display for At<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0 == Path::new(ARRAYS) {
            write!(f, "index {}", self.1)
        } else {
            write!(f, "{}: line {}", self.0.display(), self.1)
        }
    }
}

/// A trace file could not be read, or is not a trace.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TraceError {
    /// The file could not be opened or read (or a line ran past the length cap).
    #[error("{}: cannot read: {message}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's (or the reader's) reason.
        message: String,
    },
    /// The file holds nothing, not even a header.
    #[error("{}: the file is empty (expected the header t,alpha,omega_u,omega_l)", .path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The first line is not the expected header.
    #[error("{}: line {line}: the header is {found:?}, expected {expected:?}", .path.display())]
    Header {
        /// The file.
        path: PathBuf,
        /// The header's line.
        line: u64,
        /// The header as found, its fields joined by commas.
        found: String,
        /// The header expected (`t,alpha,omega_u,omega_l`, a chain's, or `t,disc,kind`).
        expected: String,
    },
    /// A field that must be a number is not a finite one.
    #[error("{}: line {line}, column {column} ({name}): {value:?} is not a finite number", .path.display())]
    Value {
        /// The file.
        path: PathBuf,
        /// The row's line (1-based; the header is line 1).
        line: u64,
        /// The field's column (1-based).
        column: usize,
        /// The column's name in the header (`t`, `alpha`, ...).
        name: String,
        /// The field as written.
        value: String,
    },
    /// An events file's `disc` or `kind` field is not one of its words.
    #[error("{}: line {line}, column {column} ({name}): {value:?} is not one of {expected}", .path.display())]
    Word {
        /// The file.
        path: PathBuf,
        /// The row's line (1-based; the header is line 1).
        line: u64,
        /// The field's column (1-based).
        column: usize,
        /// The column's name, `disc` or `kind`.
        name: &'static str,
        /// The field as written.
        value: String,
        /// The words allowed (`upper, lower`; `1 … N`; `stick_start, stick_end, reversal`).
        expected: String,
    },
    /// A row has the wrong number of fields.
    #[error("{}: line {line}: {found} fields, expected {expected}", .path.display())]
    Fields {
        /// The file.
        path: PathBuf,
        /// The row's line (1-based; the header is line 1).
        line: u64,
        /// The number of fields in the row.
        found: usize,
        /// The number expected, with the header (`4 (t,alpha,omega_u,omega_l)`).
        expected: String,
    },
    /// The CSV reader refused the file (an unterminated quote, invalid UTF-8, ...).
    #[error("{}: line {line}: {message}", .path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The line where the reader stopped (0 if it did not say).
        line: u64,
        /// The reader's message.
        message: String,
    },
    /// The file has a header and no data row.
    #[error("{}: no data rows after the header", .path.display())]
    NoRows {
        /// The file.
        path: PathBuf,
    },
    /// An events file holds more than [`MAX_EVENTS`] events; reading stopped there.
    #[error(
        "{}: line {line}: more than {limit} events, more than any run of this benchmark holds",
        .path.display()
    )]
    TooMany {
        /// The file.
        path: PathBuf,
        /// The line of the first event past the limit.
        line: u64,
        /// The limit, [`MAX_EVENTS`] for a file.
        limit: usize,
    },
    /// A trace given as arrays: one value is not finite.
    #[error("{name}[{index}] = {value}: not a finite number")]
    Column {
        /// The array's name (`t`, `alpha`, `omega_u`, `omega_l`).
        name: &'static str,
        /// The value's index (0-based).
        index: usize,
        /// The value (NaN or ±∞).
        value: f64,
    },
    /// Events given as a list: an entry's time is not finite, or its disc or kind is not one
    /// of its words.
    #[error("events[{index}][{name:?}] = {value:?}: not one of {expected}")]
    Entry {
        /// The entry's index in the list (0-based).
        index: usize,
        /// The entry's field (`t`, `disc` or `kind`).
        name: &'static str,
        /// The field's value as given.
        value: String,
        /// What it must be: the words allowed, or `the finite numbers` for `t`.
        expected: String,
    },
    /// A trace given as arrays: the arrays are empty or of different lengths.
    #[error("{message}")]
    Arrays {
        /// What is wrong with the lengths.
        message: String,
    },
}

/// A trace as read: the samples with the line each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The file it was read from ([`ARRAYS`] for a trace given as arrays).
    pub path: PathBuf,
    /// Its rows: time \[s\] and state `[α, ω_u, ω_l]` (rad, rad/s, rad/s).
    pub samples: Vec<Sample>,
    /// The file line of each sample (1-based; the header is line 1).
    pub lines: Vec<u64>,
    /// Significant digits the values are written with: the most that any value of α, ω_u or
    /// ω_l shows (17 for arrays, and for a file of exact zeros). A writer uses one format:
    /// `%g` shows at most 6, a shortest round-trip one up to 17, though it writes a round
    /// number short (`1`).
    pub digits: u32,
}

impl Trace {
    /// A run's grid samples as a trace (rows numbered as in a file written from them, at full
    /// precision): how this project's own runs are graded as external traces are.
    ///
    /// # Panics
    ///
    /// If the run is not the rig's (the grade reads the rig's state).
    pub fn of_run(path: &str, samples: &Samples) -> Trace {
        Trace::of_samples(path, samples.iter().map(|r| r.sample()).collect())
    }

    /// The rig's samples as a trace, numbered as [`Trace::of_run`] numbers a run's.
    pub fn of_samples(path: &str, samples: Vec<Sample>) -> Trace {
        Trace {
            path: path.into(),
            lines: (2..samples.len() as u64 + 2).collect(),
            samples,
            digits: FULL_DIGITS,
        }
    }

    /// A trace from its four columns (the Python package's arrays): of equal, nonzero
    /// lengths, every value finite. Its rows are named by index ([`ARRAYS`]).
    pub fn from_columns(columns: [&[f64]; 4]) -> Result<Trace, TraceError> {
        let n = columns[0].len();
        if columns.iter().any(|c| c.len() != n) {
            let lengths: Vec<String> = TRACE_HEADER
                .iter()
                .zip(&columns)
                .map(|(name, c)| format!("{name} has {}", c.len()))
                .collect();
            return Err(TraceError::Arrays {
                message: format!(
                    "the four arrays must have one length: {}",
                    lengths.join(", ")
                ),
            });
        }
        if n == 0 {
            return Err(TraceError::Arrays {
                message: "the arrays are empty".into(),
            });
        }
        for (name, c) in TRACE_HEADER.iter().zip(&columns) {
            if let Some(index) = c.iter().position(|v| !v.is_finite()) {
                return Err(TraceError::Column {
                    name,
                    index,
                    value: c[index],
                });
            }
        }
        let [t, a, wu, wl] = columns;
        Ok(Trace {
            path: ARRAYS.into(),
            samples: (0..n)
                .map(|i| Sample {
                    t: t[i],
                    x: State::new(a[i], wu[i], wl[i]),
                })
                .collect(),
            lines: (0..n as u64).collect(),
            digits: FULL_DIGITS,
        })
    }
}

/// Significant digits of a double written in full (17 always round-trip).
pub const FULL_DIGITS: u32 = 17;

/// The significant digits a number is written with: the mantissa's digits from the first
/// nonzero one (`0.00125` has 3, `1.50` has 3, `2.5e-7` has 2, `0` has none).
pub(crate) fn written_digits(field: &str) -> u32 {
    let mantissa = field.split(['e', 'E']).next().unwrap_or("");
    let digits = mantissa
        .bytes()
        .filter(u8::is_ascii_digit)
        .skip_while(|&b| b == b'0');
    digits.count() as u32
}

/// The precision of a trace whose values show at most `most` digits ([`FULL_DIGITS`] when
/// every value is 0).
fn file_digits(most: u32) -> u32 {
    if most == 0 { FULL_DIGITS } else { most }
}

impl EventsFile {
    /// A run's events as an events file (its mode switches; extrema are no rows of one).
    pub fn of_run(path: &str, events: &[Event]) -> EventsFile {
        let events: Vec<Event> = events
            .iter()
            .filter(|e| event_row(e.kind).is_some())
            .cloned()
            .collect();
        EventsFile {
            path: path.into(),
            lines: (2..events.len() as u64 + 2).collect(),
            events,
        }
    }

    /// Events given as a list (the Python package's `check`): each `(t, disc, kind)` with disc
    /// `upper|lower` and kind `stick_start|stick_end|reversal`, as in an events file. Named by
    /// index ([`ARRAYS`]); the times are checked by [`crate::grade::check::check_events`].
    pub fn from_rows(rows: &[(f64, &str, &str)]) -> Result<EventsFile, TraceError> {
        EventsFile::from_rows_with(rows, DiscWords::Rig)
    }

    /// [`EventsFile::from_rows`] of a chain of `n` discs: discs by number, `"1"` … `"n"`.
    pub fn from_chain_rows(rows: &[(f64, &str, &str)], n: usize) -> Result<EventsFile, TraceError> {
        EventsFile::from_rows_with(rows, DiscWords::Chain(n))
    }

    fn from_rows_with(
        rows: &[(f64, &str, &str)],
        discs: DiscWords,
    ) -> Result<EventsFile, TraceError> {
        let mut events = Vec::with_capacity(rows.len());
        for (index, &(t, disc, kind)) in rows.iter().enumerate() {
            let bad = |name, value: &str, expected| TraceError::Entry {
                index,
                name,
                value: value.to_owned(),
                expected,
            };
            if !t.is_finite() {
                return Err(TraceError::Entry {
                    index,
                    name: "t",
                    value: t.to_string(),
                    expected: "the finite numbers".into(),
                });
            }
            let disc = discs
                .parse(disc)
                .ok_or_else(|| bad("disc", disc, discs.words()))?;
            let kind = kind_of(kind, disc).ok_or_else(|| bad("kind", kind, KIND_WORDS.into()))?;
            // An events file carries no state: the rig's zeros stand for it.
            events.push(Event::new(t, &[0.0; 3], kind));
        }
        Ok(EventsFile {
            path: ARRAYS.into(),
            lines: (0..events.len() as u64).collect(),
            events,
        })
    }
}

/// Reads a trace file, streaming: a file that is not a trace fails at its first line, and a
/// file without line ends (a binary file, `/dev/zero`) fails after [`MAX_LINE`] bytes instead
/// of being read into memory whole.
///
/// At most `max_rows` rows are read; the rest of the file is not. A caller grading against a
/// grid of n times passes n + 1: a trace that runs on past the grid is then named by its
/// first extra row, and a client that writes without end (or a file of 10⁹ rows) costs no
/// more than the grid.
pub fn read_trace(path: &Path, max_rows: usize) -> Result<Trace, TraceError> {
    trace_from(open(path)?, path, max_rows)
}

/// Parses trace bytes; `path` names the file in messages.
pub fn parse_trace(bytes: &[u8], path: &Path) -> Result<Trace, TraceError> {
    trace_from(bytes, path, usize::MAX)
}

/// Parses at most `max_rows` rows of a trace from `input`; `path` names it in messages.
fn trace_from(input: impl Read, path: &Path, max_rows: usize) -> Result<Trace, TraceError> {
    let mut samples = Vec::new();
    let mut lines = Vec::new();
    let mut most = 0u32;
    let layout = Layout {
        header: &TRACE_HEADER,
    };
    csv_rows(input, path, layout, max_rows, |line, rec| {
        let mut v = [0.0; 4];
        for (k, field) in rec.iter().enumerate() {
            v[k] = number(field).ok_or_else(|| TraceError::Value {
                path: path.to_owned(),
                line,
                column: k + 1,
                name: TRACE_HEADER[k].to_owned(),
                value: field.to_owned(),
            })?;
            if k > 0 {
                most = most.max(written_digits(field));
            }
        }
        samples.push(Sample {
            t: v[0],
            x: State::new(v[1], v[2], v[3]),
        });
        lines.push(line);
        Ok(())
    })?;
    if samples.is_empty() {
        return Err(TraceError::NoRows {
            path: path.to_owned(),
        });
    }
    Ok(Trace {
        path: path.to_owned(),
        samples,
        lines,
        digits: file_digits(most),
    })
}

/// A chain's trace as read (`t,alpha_1,…,alpha_{N−1},omega_1,…,omega_N`): the samples
/// with the line each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainTrace {
    /// The file it was read from.
    pub path: PathBuf,
    /// Its rows: time \[s\] and the state of 2N − 1 values.
    pub samples: Samples,
    /// The file line of each sample (1-based; the header is line 1).
    pub lines: Vec<u64>,
    /// Significant digits the values are written with, as [`Trace::digits`].
    pub digits: u32,
}

impl ChainTrace {
    /// A run's grid samples as a trace, numbered as a file written from them.
    pub fn of_run(path: &str, samples: Samples) -> ChainTrace {
        ChainTrace {
            path: path.into(),
            lines: (2..samples.len() as u64 + 2).collect(),
            samples,
            digits: FULL_DIGITS,
        }
    }
}

/// Reads a chain's trace file, its columns named `names` after `t` (the chain's state names),
/// streaming and capped at `max_rows` rows as [`read_trace`] is.
pub fn read_chain_trace(
    path: &Path,
    names: &[String],
    max_rows: usize,
) -> Result<ChainTrace, TraceError> {
    chain_trace_from(open(path)?, path, names, max_rows)
}

/// Parses a chain's trace bytes; `path` names the file in messages.
pub fn parse_chain_trace(
    bytes: &[u8],
    path: &Path,
    names: &[String],
) -> Result<ChainTrace, TraceError> {
    chain_trace_from(bytes, path, names, usize::MAX)
}

fn chain_trace_from(
    input: impl Read,
    path: &Path,
    names: &[String],
    max_rows: usize,
) -> Result<ChainTrace, TraceError> {
    let header: Vec<&str> = std::iter::once("t")
        .chain(names.iter().map(String::as_str))
        .collect();
    let mut samples = Samples::new(names.len());
    let mut lines = Vec::new();
    let mut most = 0u32;
    let mut v = vec![0.0; header.len()];
    csv_rows(
        input,
        path,
        Layout { header: &header },
        max_rows,
        |line, rec| {
            for (k, field) in rec.iter().enumerate() {
                v[k] = number(field).ok_or_else(|| TraceError::Value {
                    path: path.to_owned(),
                    line,
                    column: k + 1,
                    name: header[k].to_owned(),
                    value: field.to_owned(),
                })?;
                if k > 0 {
                    most = most.max(written_digits(field));
                }
            }
            samples.push(v[0], &v[1..]);
            lines.push(line);
            Ok(())
        },
    )?;
    if samples.is_empty() {
        return Err(TraceError::NoRows {
            path: path.to_owned(),
        });
    }
    Ok(ChainTrace {
        path: path.to_owned(),
        samples,
        lines,
        digits: file_digits(most),
    })
}

/// A finite number, or `None`.
fn number(field: &str) -> Option<f64> {
    field.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// The file at `path` opened for reading, or an error naming it.
fn open(path: &Path) -> Result<std::fs::File, TraceError> {
    std::fs::File::open(path).map_err(|e| TraceError::Io {
        path: path.to_owned(),
        message: e.to_string(),
    })
}

/// The longest run of bytes without a line end that a trace or events file may hold. A row of
/// four numbers in any float format is under 200 bytes; the cap is what keeps a file that is
/// not text from being read into memory whole in search of a line end.
pub const MAX_LINE: usize = 4096;

/// Bytes the CSV reader takes from its input at a time. A line inside one chunk is bounded
/// by the chunk; [`LineCap`] bounds a line that crosses chunks.
const CHUNK: usize = 1 << 13;

/// A reader that fails once more than `limit` bytes have passed without a line end (`\n` or
/// `\r`), counted across reads. A line that lies inside one read is not measured: it is
/// bounded by the read's size. So the CSV reader above never holds more than `limit` plus
/// one chunk of a line.
pub struct LineCap<R> {
    inner: R,
    limit: usize,
    /// Bytes since the last line end.
    run: usize,
    /// Bytes read in all.
    offset: u64,
}

impl<R: Read> LineCap<R> {
    /// `inner`, failing once a line runs past `limit` bytes.
    pub fn new(inner: R, limit: usize) -> LineCap<R> {
        LineCap {
            inner,
            limit,
            run: 0,
            offset: 0,
        }
    }
}

impl<R: Read> Read for LineCap<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let chunk = &buf[..n];
        // Scanning from the end stops within one line's length of it.
        self.run = match chunk.iter().rposition(|&b| b == b'\n' || b == b'\r') {
            Some(i) => n - 1 - i,
            None => self.run + n,
        };
        self.offset += n as u64;
        if self.run > self.limit {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "no line end in bytes {}..{}: not a CSV text file",
                    self.offset - self.run as u64,
                    self.offset
                ),
            ));
        }
        Ok(n)
    }
}

/// The shape of a CSV file: its header, the header as written in messages, and the field
/// count as written in messages.
#[derive(Clone, Copy)]
struct Layout<'a> {
    header: &'a [&'a str],
}

impl Layout<'_> {
    /// The header as a line, `t,alpha,omega_u,omega_l`.
    fn joined(&self) -> String {
        self.header.join(",")
    }

    /// The number of fields with the header, `4 (t,alpha,omega_u,omega_l)`.
    fn fields(&self) -> String {
        format!("{} ({})", self.header.len(), self.joined())
    }
}

/// Hands each data row of a CSV file laid out as `layout` to `row` with its file line
/// (1-based; the header is line 1), after checking the header and the row's field count. A
/// blank line (a trailing newline) is no row. Stops after `max_rows` rows, reading no further.
/// `path` names the file in messages.
fn csv_rows(
    input: impl Read,
    path: &Path,
    layout: Layout<'_>,
    max_rows: usize,
    mut row: impl FnMut(u64, &csv::StringRecord) -> Result<(), TraceError>,
) -> Result<(), TraceError> {
    let p = || path.to_owned();
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .buffer_capacity(CHUNK)
        .from_reader(LineCap::new(input, MAX_LINE));
    let mut records = r.records();
    let line_of = |rec: &csv::StringRecord| rec.position().map_or(0, |pos| pos.line());
    let csv_err = |e: csv::Error| match e.kind() {
        csv::ErrorKind::Io(io) => TraceError::Io {
            path: p(),
            message: io.to_string(),
        },
        _ => TraceError::Csv {
            path: p(),
            line: e.position().map_or(0, |pos| pos.line()),
            message: e.to_string(),
        },
    };
    // A line of blanks (the csv reader skips empty lines but not lines of spaces).
    let blank = |rec: &csv::StringRecord| rec.len() == 1 && rec[0].is_empty();
    let header = records
        .next()
        .ok_or_else(|| TraceError::Empty { path: p() })?
        .map_err(csv_err)?;
    if blank(&header) {
        // Blank lines to the end: the file is empty; else a blank line is a wrong header.
        let mut only_blank = true;
        for rec in records.by_ref() {
            if !blank(&rec.map_err(csv_err)?) {
                only_blank = false;
                break;
            }
        }
        if only_blank {
            return Err(TraceError::Empty { path: p() });
        }
    }
    if !header.iter().eq(layout.header.iter().copied()) {
        return Err(TraceError::Header {
            path: p(),
            line: line_of(&header),
            found: header.iter().collect::<Vec<_>>().join(","),
            expected: layout.joined(),
        });
    }
    drop(records);
    let mut rows = 0;
    // One record, refilled row by row: no allocation per row (a 20 001-row trace reads in
    // 9.3 ms instead of 10.5 through the allocating iterator).
    let mut rec = csv::StringRecord::new();
    while rows < max_rows && r.read_record(&mut rec).map_err(csv_err)? {
        let line = line_of(&rec);
        if rec.len() == 1 && rec[0].is_empty() {
            continue;
        }
        rows += 1;
        if rec.len() != layout.header.len() {
            return Err(TraceError::Fields {
                path: p(),
                line,
                found: rec.len(),
                expected: layout.fields(),
            });
        }
        row(line, &rec)?;
    }
    Ok(())
}

/// The header of an events file.
pub(crate) const EVENTS_HEADER: [&str; 3] = ["t", "disc", "kind"];

/// The rig's word for a disc, `upper` or `lower`, as an events file names it.
pub fn disc_name(d: Disc) -> std::borrow::Cow<'static, str> {
    d.name_in(2)
}

/// The disc and the events-file name of a mode-switch event (`None` for extrema, which the
/// file does not hold).
pub fn event_row(kind: EventKind) -> Option<(Disc, &'static str)> {
    match kind {
        EventKind::StickStart(d) => Some((d, "stick_start")),
        EventKind::StickEnd(d) => Some((d, "stick_end")),
        EventKind::Reversal(d) => Some((d, "reversal")),
        EventKind::Max(_) | EventKind::Min(_) => None,
    }
}

/// The events file of a run: one row per stick onset, stick exit and reversal of either disc,
/// in time order (extrema are left out), times in the shortest round-trip form.
pub fn write_events(events: &[Event]) -> Vec<u8> {
    let mut out = String::from("t,disc,kind\n");
    let mut b = zmij::Buffer::new();
    for e in events {
        if let Some((d, k)) = event_row(e.kind) {
            out.push_str(b.format(e.t));
            out.push(',');
            out.push_str(&disc_name(d));
            out.push(',');
            out.push_str(k);
            out.push('\n');
        }
    }
    out.into_bytes()
}

/// An events file as read: the events with the line each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct EventsFile {
    /// The file it was read from.
    pub path: PathBuf,
    /// Its events, in file order; each carries no state (the file has none: `x` is zero).
    pub events: Vec<Event>,
    /// The file line of each event (1-based; the header is line 1).
    pub lines: Vec<u64>,
}

/// The most events an events file may hold: a run of the longest grid (10⁷ steps of the
/// output interval) with an event in every interval. A file with more is refused after this
/// many rows, not read to its end.
pub const MAX_EVENTS: usize = 10_000_000;

/// Reads an events file, streaming as [`read_trace`] does, up to [`MAX_EVENTS`] events.
pub fn read_events(path: &Path) -> Result<EventsFile, TraceError> {
    events_from(open(path)?, path, MAX_EVENTS)
}

/// The words of an events file's `disc` column, as written in messages.
const DISC_WORDS: &str = "upper, lower";
/// The words of an events file's `kind` column, as written in messages.
const KIND_WORDS: &str = "stick_start, stick_end, reversal";

/// The disc named `word` ([`disc_name`] read back).
fn disc_of(word: &str) -> Option<Disc> {
    match word {
        "upper" => Some(Disc::UPPER),
        "lower" => Some(Disc::LOWER),
        _ => None,
    }
}

/// The mode-switch event of `disc` named `word` ([`event_row`] read back).
fn kind_of(word: &str, disc: Disc) -> Option<EventKind> {
    match word {
        "stick_start" => Some(EventKind::StickStart(disc)),
        "stick_end" => Some(EventKind::StickEnd(disc)),
        "reversal" => Some(EventKind::Reversal(disc)),
        _ => None,
    }
}

/// Parses an events file (the events' states are not in the file: they are zero). An empty
/// list of events after the header is valid (a run without a stick or a reversal).
pub fn parse_events(bytes: &[u8], path: &Path) -> Result<EventsFile, TraceError> {
    events_from(bytes, path, MAX_EVENTS)
}

/// How an events file names its discs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscWords {
    /// The rig's `upper`, `lower`.
    Rig,
    /// A chain's numbers `1` … `N`.
    Chain(usize),
}

impl DiscWords {
    /// The disc `word` names.
    fn parse(self, word: &str) -> Option<Disc> {
        match self {
            DiscWords::Rig => disc_of(word),
            DiscWords::Chain(n) => word
                .parse::<usize>()
                .ok()
                .filter(|k| (1..=n).contains(k))
                .map(|k| Disc::at(k - 1)),
        }
    }

    /// The words allowed, for messages.
    fn words(self) -> String {
        match self {
            DiscWords::Rig => DISC_WORDS.into(),
            DiscWords::Chain(n) => format!("the disc numbers 1 to {n}"),
        }
    }

    /// The word of disc `d`.
    pub fn name(self, d: Disc) -> std::borrow::Cow<'static, str> {
        match self {
            DiscWords::Rig => disc_name(d),
            DiscWords::Chain(_) => d.number().to_string().into(),
        }
    }
}

/// Parses an events file from `input`; `path` names it in messages.
fn events_from(input: impl Read, path: &Path, limit: usize) -> Result<EventsFile, TraceError> {
    events_with(input, path, limit, DiscWords::Rig)
}

/// Reads an events file of a chain of `n` discs (disc numbers `1` … `n`), streaming as
/// [`read_events`] does.
pub fn read_chain_events(path: &Path, n: usize) -> Result<EventsFile, TraceError> {
    events_with(open(path)?, path, MAX_EVENTS, DiscWords::Chain(n))
}

/// Parses an events file of a chain of `n` discs; `path` names it in messages.
pub fn parse_chain_events(bytes: &[u8], path: &Path, n: usize) -> Result<EventsFile, TraceError> {
    events_with(bytes, path, MAX_EVENTS, DiscWords::Chain(n))
}

/// The events file of a chain's run: as [`write_events`], discs by number.
pub fn write_chain_events(events: &[Event]) -> Vec<u8> {
    let mut out = String::from("t,disc,kind\n");
    let mut b = zmij::Buffer::new();
    for e in events {
        if let Some((d, k)) = event_row(e.kind) {
            out.push_str(b.format(e.t));
            out.push(',');
            out.push_str(&d.number().to_string());
            out.push(',');
            out.push_str(k);
            out.push('\n');
        }
    }
    out.into_bytes()
}

/// Parses an events file from `input` whose discs are named as `discs` says.
fn events_with(
    input: impl Read,
    path: &Path,
    limit: usize,
    discs: DiscWords,
) -> Result<EventsFile, TraceError> {
    let mut out = Vec::new();
    let mut lines = Vec::new();
    let layout = Layout {
        header: &EVENTS_HEADER,
    };
    csv_rows(input, path, layout, limit.saturating_add(1), |line, rec| {
        if out.len() == limit {
            return Err(TraceError::TooMany {
                path: path.to_owned(),
                line,
                limit,
            });
        }
        let t = number(&rec[0]).ok_or_else(|| TraceError::Value {
            path: path.to_owned(),
            line,
            column: 1,
            name: "t".into(),
            value: rec[0].to_owned(),
        })?;
        let word = |column: usize, name: &'static str, expected: String| TraceError::Word {
            path: path.to_owned(),
            line,
            column,
            name,
            value: rec[column - 1].to_owned(),
            expected,
        };
        let disc = discs
            .parse(&rec[1])
            .ok_or_else(|| word(2, "disc", discs.words()))?;
        let kind = kind_of(&rec[2], disc).ok_or_else(|| word(3, "kind", KIND_WORDS.into()))?;
        out.push(Event::new(t, &[0.0; 3], kind));
        lines.push(line);
        Ok(())
    })?;
    Ok(EventsFile {
        path: path.to_owned(),
        events: out,
        lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(t: f64, a: f64, wu: f64, wl: f64) -> Sample {
        Sample {
            t,
            x: State::new(a, wu, wl),
        }
    }

    #[test]
    fn written_traces_read_back_exactly_with_grid_times_as_decimals() {
        let samples = [
            s(0.0, 0.0, 0.0, 0.0),
            s(3.0 * 0.1, 0.1 + 0.2, -1.5e-7, 6.336105049),
            s(0.8999999999999999, 1e300, -2.5, 1.0 / 3.0),
        ];
        let bytes = write_trace(&samples.iter().copied().collect(), 0.1);
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(
            text.starts_with("t,alpha,omega_u,omega_l\n0.0,0.0,0.0,0.0\n"),
            "{text}"
        );
        assert!(text.contains("\n0.3,0.30000000000000004,"), "{text}");
        assert!(text.contains("\n0.9,"), "{text}");
        let back = parse_trace(&bytes, Path::new("x.csv")).unwrap();
        assert_eq!(back.samples.len(), 3);
        for (a, b) in samples.iter().zip(&back.samples) {
            assert_eq!(a.x, b.x);
            assert_eq!(round_to(a.t, 7), b.t);
        }
        assert_eq!(back.lines, [2, 3, 4]);
    }

    /// A trace longer than the writer's buffer reads back row for row.
    #[test]
    fn a_long_trace_is_written_in_order() {
        let samples: Vec<Sample> = (0..10_001)
            .map(|k| {
                s(
                    k as f64 * 0.01,
                    (k as f64).sin(),
                    1.0 / (1.0 + k as f64),
                    -(k as f64),
                )
            })
            .collect();
        let bytes = write_trace(&samples.iter().copied().collect(), 0.01);
        let back = parse_trace(&bytes, Path::new("x.csv")).unwrap();
        assert_eq!(back.samples.len(), 10_001);
        assert_eq!(back.samples[5000].x, samples[5000].x);
        assert_eq!(back.samples[10_000].t, 100.0);
    }

    #[test]
    fn malformed_traces_name_the_line_and_column() {
        let err = |text: &str| {
            parse_trace(text.as_bytes(), Path::new("x.csv"))
                .unwrap_err()
                .to_string()
        };
        let ok = "t,alpha,omega_u,omega_l\n0,0,0,0\n0.01,1,2,3\n";
        assert!(parse_trace(ok.as_bytes(), Path::new("x.csv")).is_ok());
        assert!(err("").contains("empty"));
        assert!(err("\n \n").contains("empty"));
        assert!(err("t,a,omega_u,omega_l\n0,0,0,0\n").contains("line 1: the header"));
        assert!(err("t,alpha,omega_u,omega_l\n").contains("no data rows"));
        let e = err("t,alpha,omega_u,omega_l\n0,0,0,0\n0.01,1,x,3\n");
        assert!(e.contains("line 3, column 3 (omega_u): \"x\""), "{e}");
        let e = err("t,alpha,omega_u,omega_l\n0,0,0,NaN\n");
        assert!(e.contains("line 2, column 4 (omega_l): \"NaN\""), "{e}");
        let e = err("t,alpha,omega_u,omega_l\n0,0,0,inf\n");
        assert!(e.contains("column 4"), "{e}");
        let e = err("t,alpha,omega_u,omega_l\n0,0,0\n");
        assert!(e.contains("line 2: 3 fields"), "{e}");
        let e = err("t,alpha,omega_u,omega_l\n0,0,0,0,0\n");
        assert!(e.contains("line 2: 5 fields"), "{e}");
        let e = err("t,alpha,omega_u,omega_l\n0,0,0,\n");
        assert!(e.contains("line 2, column 4"), "{e}");
    }

    #[test]
    fn blank_lines_before_a_header_are_a_wrong_header_not_an_empty_file() {
        let e = parse_trace(
            b"  \nt,alpha,omega_u,omega_l\n0,0,0,0\n",
            Path::new("x.csv"),
        );
        let e = e.unwrap_err().to_string();
        assert!(e.contains("line 1: the header is \"\""), "{e}");
        let e = parse_events(b" \n\t\n", Path::new("e.csv")).unwrap_err();
        assert!(matches!(e, TraceError::Empty { .. }), "{e}");
    }

    /// A file without line ends is refused after at most [`MAX_LINE`] plus one chunk of bytes,
    /// not read whole: 64 MiB of zeros (`/dev/zero`, cut short so that a reader that read it
    /// whole would fail with another error instead of hanging).
    #[test]
    fn input_without_line_ends_is_refused_early() {
        let zeros = std::io::repeat(0).take(64 << 20);
        let mut counted = Counted(zeros, 0);
        let e = trace_from(&mut counted, Path::new("zero"), usize::MAX).unwrap_err();
        assert!(
            matches!(&e, TraceError::Io { message, .. } if message.contains("no line end")),
            "{e}"
        );
        assert!(
            counted.1 <= (MAX_LINE + 2 * CHUNK) as u64,
            "read {} bytes",
            counted.1
        );
        // A trace whose second row runs past the cap across chunks, and the same row padded
        // to just under it, which reads.
        let row = |pad: usize| {
            format!(
                "t,alpha,omega_u,omega_l\n0,0,0,0\n{}0.01,1,2,3\n",
                " ".repeat(pad)
            )
        };
        let long = row(3 * CHUNK);
        let e = parse_trace(long.as_bytes(), Path::new("x.csv")).unwrap_err();
        assert!(matches!(&e, TraceError::Io { .. }), "{e}");
        let e = parse_events(long.as_bytes(), Path::new("e.csv")).unwrap_err();
        assert!(matches!(&e, TraceError::Io { .. }), "{e}");
        let fits = parse_trace(row(MAX_LINE - 20).as_bytes(), Path::new("x.csv")).unwrap();
        assert_eq!(fits.samples[1].x, State::new(1.0, 2.0, 3.0));
    }

    /// Rows without end: a client that never stops writing, or a file of 10⁹ rows. The trace
    /// is read up to the rows asked for (a grid and one more), the events up to their cap;
    /// neither read would end without its bound.
    #[test]
    fn endless_rows_are_read_only_up_to_their_bound() {
        /// `head`, then `row(i)` for i = 0, 1, 2, ... forever.
        struct Endless<F> {
            pending: Vec<u8>,
            i: u64,
            row: F,
        }
        impl<F: Fn(u64) -> String> Read for Endless<F> {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                while self.pending.len() < buf.len() {
                    self.pending.extend((self.row)(self.i).bytes());
                    self.i += 1;
                }
                buf.copy_from_slice(&self.pending[..buf.len()]);
                self.pending.drain(..buf.len());
                Ok(buf.len())
            }
        }
        let rows = |head: &str, row: fn(u64) -> String| Endless {
            pending: head.as_bytes().to_vec(),
            i: 0,
            row,
        };
        let trace = rows("t,alpha,omega_u,omega_l\n", |i| {
            format!("{},0,0,0\n", i as f64 / 100.0)
        });
        let t = trace_from(trace, Path::new("x.csv"), 10_002).unwrap();
        assert_eq!(t.samples.len(), 10_002);
        assert_eq!((t.samples[10_001].t, t.lines[10_001]), (100.01, 10_003));
        let events = rows("t,disc,kind\n", |i| format!("{i},lower,stick_start\n"));
        let e = events_from(events, Path::new("e.csv"), 1000).unwrap_err();
        assert_eq!(
            e.to_string(),
            "e.csv: line 1002: more than 1000 events, more than any run of this benchmark holds"
        );
    }

    /// A reader that counts the bytes it hands out.
    struct Counted<R>(R, u64);

    impl<R: Read> Read for Counted<R> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.0.read(buf)?;
            self.1 += n as u64;
            Ok(n)
        }
    }

    #[test]
    fn events_files_round_trip_and_name_bad_fields() {
        let ev = |t: f64, kind: EventKind| Event {
            t,
            x: vec![0.0; 3],
            kind,
        };
        let events = vec![
            ev(0.5, EventKind::StickStart(Disc::LOWER)),
            ev(0.75, EventKind::Max(Disc::LOWER)),
            ev(1.0 / 3.0, EventKind::StickEnd(Disc::LOWER)),
            ev(2.0, EventKind::Reversal(Disc::UPPER)),
        ];
        let bytes = write_events(&events);
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert_eq!(
            text,
            "t,disc,kind\n0.5,lower,stick_start\n0.3333333333333333,lower,stick_end\n\
             2.0,upper,reversal\n"
        );
        let back = parse_events(&bytes, Path::new("e.csv")).unwrap();
        assert_eq!(back.lines, [2, 3, 4]);
        let kinds: Vec<(f64, EventKind)> = back.events.iter().map(|e| (e.t, e.kind)).collect();
        assert_eq!(
            kinds,
            [
                (0.5, EventKind::StickStart(Disc::LOWER)),
                (1.0 / 3.0, EventKind::StickEnd(Disc::LOWER)),
                (2.0, EventKind::Reversal(Disc::UPPER)),
            ]
        );
        assert!(
            parse_events(b"t,disc,kind\n", Path::new("e.csv"))
                .unwrap()
                .events
                .is_empty()
        );
        let err = |text: &str| {
            parse_events(text.as_bytes(), Path::new("e.csv"))
                .unwrap_err()
                .to_string()
        };
        assert!(err("t,d,kind\n").contains("line 1: the header"));
        let e = err("t,disc,kind\n1,middle,stick_start\n");
        assert!(e.contains("line 2, column 2 (disc): \"middle\""), "{e}");
        let e = err("t,disc,kind\n1,lower,stop\n");
        assert!(e.contains("line 2, column 3 (kind)"), "{e}");
        let e = err("t,disc,kind\nx,lower,stick_end\n");
        assert!(e.contains("line 2, column 1 (t)"), "{e}");
        let e = err("t,disc,kind\n1,lower\n");
        assert!(e.contains("line 2: 2 fields, expected 3"), "{e}");
    }

    /// Arrays make the same trace as the file of the same numbers; bad arrays name the array
    /// and the index.
    #[test]
    fn traces_from_arrays_match_files_and_name_bad_entries() {
        let samples = [s(0.0, 0.0, 0.0, 0.0), s(0.1, 0.5, -1.5e-7, 6.3)];
        let file = parse_trace(
            &write_trace(&samples.iter().copied().collect(), 0.1),
            Path::new("x.csv"),
        )
        .unwrap();
        let col = |k: usize| -> Vec<f64> {
            samples
                .iter()
                .map(|s| if k == 0 { s.t } else { s.x[k - 1] })
                .collect()
        };
        let (t, a, wu, wl) = (col(0), col(1), col(2), col(3));
        let arrays = Trace::from_columns([&t, &a, &wu, &wl]).unwrap();
        assert_eq!(arrays.samples, file.samples);
        assert_eq!(arrays.lines, [0, 1]);
        let e = Trace::from_columns([&t, &a, &wu[..1], &wl]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the four arrays must have one length: t has 2, alpha has 2, omega_u has 1, \
             omega_l has 2"
        );
        let nan = [0.0, f64::NAN];
        let e = Trace::from_columns([&t, &a, &wu, &nan]).unwrap_err();
        assert_eq!(e.to_string(), "omega_l[1] = NaN: not a finite number");
        let empty: [f64; 0] = [];
        let e = Trace::from_columns([&empty; 4]).unwrap_err();
        assert_eq!(e.to_string(), "the arrays are empty");
        assert_eq!(At(Path::new(ARRAYS), 7).to_string(), "index 7");
        assert_eq!(At(Path::new("x.csv"), 7).to_string(), "x.csv: line 7");

        let ev = EventsFile::from_rows(&[(0.5, "lower", "stick_start")]).unwrap();
        let back = parse_events(b"t,disc,kind\n0.5,lower,stick_start\n", Path::new("e")).unwrap();
        assert_eq!(ev.events, back.events);
        let e =
            EventsFile::from_rows(&[(0.5, "lower", "stick"), (1.0, "x", "reversal")]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "events[0][\"kind\"] = \"stick\": not one of stick_start, stick_end, reversal"
        );
    }
}
