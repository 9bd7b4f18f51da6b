//! Standard output that a closed pipe does not turn into a panic.
//!
//! `print!` panics when the reader of standard output has gone (`rotor steady ... | head -c
//! 10`, a pager quit early). A Unix tool stops writing quietly then: the work asked for is
//! done and the reader took what it wanted. Here a closed pipe ends output: this write and
//! all later ones are dropped, no error is printed, and the exit status is what it would
//! have been (for `rotor check`, the verdict). Any other write error is an error.

use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once a write to standard output met a closed pipe.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `text` to standard output; a closed pipe is not an error (see the module).
pub fn print(text: &str) -> std::io::Result<()> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut o = std::io::stdout().lock();
    closed_is_fine(o.write_all(text.as_bytes()).and_then(|()| o.flush()))
}

/// [`print()`] of `args` and a newline: `println!` that returns its error.
pub fn line(args: std::fmt::Arguments) -> std::io::Result<()> {
    print(&format!("{args}\n"))
}

/// `r`, with a closed pipe counted as success (and remembered, so later writes are dropped).
pub fn closed_is_fine(r: std::io::Result<()>) -> std::io::Result<()> {
    match r {
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        r => r,
    }
}

/// Whether `e` is, at its root, a write to a reader that has gone: the command stops there,
/// quietly and successfully, as a Unix tool does.
pub fn is_closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == ErrorKind::BrokenPipe)
    })
}

/// Checks, before any work, that `path` (given to `flag`) can be an output: standard output
/// (`-`), or a file whose directory exists and that is not itself a directory. A bench or a
/// diagram that runs for minutes must not find this out at its last write.
pub fn writable(flag: &str, path: &std::path::Path) -> anyhow::Result<()> {
    if path.as_os_str() == "-" {
        return Ok(());
    }
    if path.is_dir() {
        anyhow::bail!("{flag} {}: is a directory, not a file", path.display());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "{flag} {}: the directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}
