//! Each solver's and client's colour in the report's figures (the ladders and the
//! performance profile draw every runner in the same colour).

use crate::options::SolverKind;

/// A solver's colour from its entry; the peers' own.
pub(crate) fn color(name: &str) -> &'static str {
    const OTHERS: [&str; 7] = [
        "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
    ];
    match (SolverKind::by_name(name), name) {
        (Some(k), _) => k.info().style.color,
        (None, "scipy") => "#d62728",
        (None, "siconos") => "#2ca02c",
        (None, "octave") => "#1f77b4",
        // Any other client: a colour fixed by its name (a sum of its bytes).
        (None, _) => OTHERS[name.bytes().map(usize::from).sum::<usize>() % OTHERS.len()],
    }
}
