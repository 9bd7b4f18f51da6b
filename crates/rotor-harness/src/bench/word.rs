//! The report's fixed words (a setting's name, a ratio's kind, the profile's criterion),
//! shared when a report is read back (`rotor bench --merge`).

use serde::{Deserialize, Deserializer};

/// The profile of the Rust solvers and every client that ran.
/// What "solved" and "time" mean in the profile.
pub const CRITERION: &str = "fastest point whose trace passes the scene's loose gate \
                             (event-moreau tolerances, as rotor check); in-process time \
                             (solve_seconds, else wall)";

/// A `&'static str` field of the report (a setting's name, a ratio's kind). Named, so that
/// serde's derive reads it with `static_str` instead of borrowing it from the input.
pub type Word = &'static str;

/// Reads a `&'static str` field of a report back (a setting's name, a ratio's kind): the
/// known words are shared; any other (a report of another version) is kept for the life of
/// the process, which reads a handful of reports.
pub(crate) fn static_str<'de, D: Deserializer<'de>>(d: D) -> Result<&'static str, D::Error> {
    const KNOWN: [&str; 7] = [
        "tol",
        "h",
        "steady_rel",
        "transient_max",
        "in_process",
        "whole_process",
        CRITERION,
    ];
    let s = String::deserialize(d)?;
    Ok(KNOWN
        .into_iter()
        .find(|k| *k == s)
        .unwrap_or_else(|| Box::leak(s.into_boxed_str())))
}
