//! How many threads a parallel run uses: the one rule of the CLI's `--threads` and the Python
//! package's `threads=`.
//!
//! An explicit count wins. Without one, a Slurm task's `SLURM_CPUS_PER_TASK` (set when the
//! job asks for `--cpus-per-task`), else the cores available to the process
//! ([`std::thread::available_parallelism`]: its affinity mask and cgroup quota). On a cluster
//! that enforces no affinity, the cores of the whole node are "available" to every task, and
//! a task that took them all would oversubscribe the node: Slurm's variable says what the task
//! was given.

/// The largest count accepted (a typo such as `--threads 80000` is refused, not obeyed).
pub const MAX_THREADS: usize = 4096;

/// Where a thread count came from, for messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `--threads` / `threads=`.
    Explicit,
    /// `SLURM_CPUS_PER_TASK`.
    Slurm,
    /// The cores available to the process.
    Cores,
}

impl Source {
    /// The words a run's summary prints after the count.
    pub fn describe(self) -> &'static str {
        match self {
            Source::Explicit => "as asked",
            Source::Slurm => "from SLURM_CPUS_PER_TASK",
            Source::Cores => "the cores available",
        }
    }
}

/// Parses a thread count: a whole number from 1 to [`MAX_THREADS`]. The error says why, to be
/// put after the flag or variable and its value.
pub fn parse_count(text: &str) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| "expected a whole number of threads, at least 1".to_owned())?;
    check_count(n)
}

/// Checks a thread count given as a number.
pub fn check_count(n: usize) -> Result<usize, String> {
    if n == 0 {
        return Err("expected at least 1 thread".to_owned());
    }
    if n > MAX_THREADS {
        return Err(format!("at most {MAX_THREADS} threads"));
    }
    Ok(n)
}

/// The thread count of a run: `explicit` (already checked), else `SLURM_CPUS_PER_TASK`, else
/// the cores available. A bad `SLURM_CPUS_PER_TASK` is an error naming it and its value (and
/// how to override it); it is not read when a count is given.
pub fn resolve(explicit: Option<usize>) -> Result<(usize, Source), String> {
    resolve_with(explicit, std::env::var_os("SLURM_CPUS_PER_TASK"))
}

/// [`resolve`] with the variable's value given (for tests).
pub(crate) fn resolve_with(
    explicit: Option<usize>,
    slurm: Option<std::ffi::OsString>,
) -> Result<(usize, Source), String> {
    if let Some(n) = explicit {
        return Ok((check_count(n)?, Source::Explicit));
    }
    if let Some(v) = slurm {
        let text = v.to_string_lossy();
        return parse_count(&text)
            .map(|n| (n, Source::Slurm))
            .map_err(|why| {
                format!("SLURM_CPUS_PER_TASK={text:?}: {why} (or give the count with --threads N)")
            });
    }
    let n = std::thread::available_parallelism().map_or(1, |n| n.get());
    Ok((n.min(MAX_THREADS), Source::Cores))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explicit_wins_then_slurm_then_cores() {
        assert_eq!(
            resolve_with(Some(3), Some("7".into())),
            Ok((3, Source::Explicit))
        );
        assert_eq!(resolve_with(None, Some("7".into())), Ok((7, Source::Slurm)));
        let (n, src) = resolve_with(None, None).unwrap();
        assert!(n >= 1);
        assert_eq!(src, Source::Cores);
    }

    #[test]
    fn bad_counts_are_named() {
        for bad in ["0", "", "two", "-1", "1.5", "99999"] {
            let e = resolve_with(None, Some(bad.into())).unwrap_err();
            assert!(
                e.starts_with(&format!("SLURM_CPUS_PER_TASK={bad:?}: ")),
                "{e}"
            );
            assert!(parse_count(bad).is_err(), "{bad}");
        }
        // An explicit count makes a bad variable irrelevant.
        assert_eq!(
            resolve_with(Some(2), Some("x".into())),
            Ok((2, Source::Explicit))
        );
        assert!(check_count(0).is_err());
        assert_eq!(parse_count(" 8 "), Ok(8));
    }
}
