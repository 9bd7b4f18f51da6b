//! Each solver's and client's style in the benchmark's figures: a colour from a palette that
//! colour-blind readers can tell apart (Okabe–Ito's eight, then four of Tol's muted ones), and
//! a second channel that survives greyscale print, a marker shape and a dash pattern. No two
//! runners of the first twelve share a colour; each shape and dash pattern changes from one
//! runner to the next.

use rotor_analysis::plot::Shape;

/// How one runner's curves are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunnerStyle {
    /// SVG colour.
    pub color: &'static str,
    /// SVG dash pattern; `None` for a solid line.
    pub dash: Option<&'static str>,
    /// Marker shape.
    pub shape: Shape,
}

/// The runners the repository knows, in the order their styles are handed out.
const KNOWN: [&str; 12] = [
    "event",
    "switch",
    "moreau",
    "scipy",
    "scipy-radau",
    "scipy-bdf",
    "scipy-lsoda",
    "siconos",
    "octave",
    "tanh",
    "first_order",
    "minimal",
];

const COLORS: [&str; 12] = [
    "#000000", "#D55E00", "#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#7F7F7F",
    "#882255", "#44AA99", "#332288", "#999933",
];

const DASHES: [Option<&str>; 6] = [
    None,
    Some("6 3"),
    Some("2 2"),
    Some("8 3 2 3"),
    Some("4 2"),
    Some("1 3"),
];

/// The style of the runner `name`: fixed for the known ones; any other gets one fixed by
/// its name (a sum of its bytes).
pub fn style(name: &str) -> RunnerStyle {
    let i = KNOWN
        .iter()
        .position(|k| *k == name)
        .unwrap_or_else(|| name.bytes().map(usize::from).sum::<usize>() % COLORS.len());
    RunnerStyle {
        color: COLORS[i % COLORS.len()],
        dash: DASHES[i % DASHES.len()],
        shape: Shape::ALL[i % Shape::ALL.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every known runner has its own colour, and neighbours in the list differ in shape and
    /// dash too (the second channel).
    #[test]
    fn known_runners_are_told_apart_by_colour_and_by_a_second_channel() {
        let styles: Vec<RunnerStyle> = KNOWN.iter().map(|n| style(n)).collect();
        for (i, a) in styles.iter().enumerate() {
            for b in &styles[i + 1..] {
                assert_ne!(a.color, b.color);
                assert!(a.shape != b.shape || a.dash != b.dash, "{a:?} {b:?}");
            }
        }
    }

    /// The solvers look the same in every figure: the benchmark's style is their entry's.
    #[test]
    fn the_solvers_keep_their_entrys_style() {
        for kind in rotor_analysis::solvers::SOLVERS {
            let (a, b) = (style(kind.name()), kind.info().style);
            assert_eq!((a.color, a.dash), (b.color, b.dash), "{}", kind.name());
        }
    }
}
