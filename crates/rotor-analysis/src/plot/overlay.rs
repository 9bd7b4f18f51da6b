//! Several diagrams of one quantity overlaid in one panel, one marker and colour per source
//! (the bifurcation diagram by each solver, say): each layer is a set of points drawn as
//! markers, optionally joined.

use crate::plot::{Label, Panel, Series, render};

/// One source's points.
pub struct Layer<'a> {
    /// Legend text.
    pub label: &'a str,
    /// SVG colour of the markers and line.
    pub color: &'a str,
    /// Marker radius \[px\]; 0 for none.
    pub marker: f64,
    /// Line width; 0 for no line (a NaN point lifts the pen).
    pub width: f64,
    /// The points `(x, y)` in data coordinates.
    pub points: Vec<(f64, f64)>,
}

/// One SVG panel with every layer, in order (the last on top), and labelled points.
pub fn overlay(
    title: &str,
    x_label: &str,
    y_label: &str,
    layers: Vec<Layer<'_>>,
    labels: Vec<Label>,
    width: f64,
    height: f64,
) -> String {
    render(
        &[overlay_panel(title, x_label, y_label, layers, labels)],
        width,
        height,
    )
}

/// The panel [`overlay`] draws (for its data, [`crate::plot::data_csv`]).
pub(crate) fn overlay_panel<'a>(
    title: &str,
    x_label: &'a str,
    y_label: &'a str,
    layers: Vec<Layer<'a>>,
    labels: Vec<Label>,
) -> Panel<'a> {
    let series = layers
        .into_iter()
        .map(|l| Series {
            label: l.label,
            color: l.color,
            dash: None,
            width: l.width,
            marker: (l.marker > 0.0).then_some(l.marker),
            points: l.points,
            ..Series::default()
        })
        .collect();
    let mut panel = Panel::new(title, x_label, y_label, series);
    panel.labels = labels;
    panel
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_layer_is_drawn_with_its_colour() {
        let svg = overlay(
            "t",
            "u",
            "w",
            vec![
                Layer {
                    label: "a",
                    color: "#112233",
                    marker: 2.0,
                    width: 0.0,
                    points: vec![(0.0, 1.0), (1.0, 2.0)],
                },
                Layer {
                    label: "b",
                    color: "#445566",
                    marker: 0.0,
                    width: 1.0,
                    points: vec![(0.0, 0.0), (1.0, 1.0)],
                },
            ],
            vec![],
            400.0,
            300.0,
        );
        assert!(svg.contains("#112233") && svg.contains("#445566"));
        assert!(svg.starts_with("<svg") || svg.contains("<svg"));
    }
}
