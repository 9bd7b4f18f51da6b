//! The diagram written out: JSON (the CLI contract), CSV and SVG, refusing any non-finite
//! number.

use std::io::Write;

use crate::bifurcation::svg;

/// A float as the csv writer prints it (the shortest form that reads back the same).
fn num(v: f64) -> String {
    zmij::Buffer::new().format(v).to_owned()
}
use crate::bifurcation::{BifError, Diagram};

/// Every number of the diagram, named, for the finiteness check.
fn numbers(d: &Diagram) -> impl Iterator<Item = (String, f64)> + '_ {
    let eq = d.equilibria.iter().enumerate().flat_map(|(i, e)| {
        [
            (format!("equilibria[{i}].u"), e.u),
            (format!("equilibria[{i}].omega"), e.omega),
            (format!("equilibria[{i}].alpha"), e.alpha),
            (
                format!("equilibria[{i}].alpha_max"),
                e.alpha_max.unwrap_or(0.0),
            ),
        ]
    });
    let per = d.periodic.iter().enumerate().flat_map(|(i, p)| {
        let mut v = vec![
            (format!("periodic[{i}].u"), p.u),
            (format!("periodic[{i}].period"), p.period),
            (format!("periodic[{i}].omega_l_max"), p.omega_l_max),
            (format!("periodic[{i}].omega_l_min"), p.omega_l_min),
            (format!("periodic[{i}].omega_u_min"), p.omega_u_min),
            (format!("periodic[{i}].stick_time"), p.stick_time),
        ];
        for (k, m) in p.multipliers.iter().enumerate() {
            v.push((format!("periodic[{i}].multipliers[{k}].re"), m[0]));
            v.push((format!("periodic[{i}].multipliers[{k}].im"), m[1]));
        }
        for (k, s) in p.section_state.iter().enumerate() {
            v.push((format!("periodic[{i}].section_state[{k}]"), *s));
        }
        v
    });
    let pts = d.points.iter().enumerate().flat_map(|(i, p)| {
        let opt = [
            ("omega", p.omega),
            ("frequency", p.frequency),
            ("period", p.period),
            ("omega_l_max", p.omega_l_max),
            ("omega_l_min", p.omega_l_min),
            ("residual", p.residual),
            ("l1", p.l1),
        ];
        let pairs = [
            ("slipping_multipliers", p.slipping_multipliers),
            ("stick_slip_multipliers", p.stick_slip_multipliers),
        ];
        let multipliers = pairs.into_iter().flat_map(move |(k, v)| {
            v.into_iter().flat_map(move |m| {
                (0..2).flat_map(move |j| {
                    [
                        (format!("points[{i}].{k}[{j}].re"), m[j][0]),
                        (format!("points[{i}].{k}[{j}].im"), m[j][1]),
                    ]
                })
            })
        });
        std::iter::once((format!("points[{i}].u"), p.u)).chain(
            opt.into_iter()
                .filter_map(move |(k, v)| v.map(|v| (format!("points[{i}].{k}"), v)))
                .chain(multipliers),
        )
    });
    eq.chain(per).chain(pts)
}

impl Diagram {
    /// The first non-finite number of the diagram, as an error naming it.
    pub fn check_finite(&self) -> Result<(), BifError> {
        match numbers(self).find(|(_, v)| !v.is_finite()) {
            Some((what, value)) => Err(BifError::NonFinite { what, value }),
            None => Ok(()),
        }
    }

    /// The diagram as pretty JSON (the CLI contract, docs/design.md): `{"equilibria": [{"u", "omega", "alpha",
    /// "stable", ...}], "periodic": [{"u", "period", "omega_l_max", "omega_l_min", "stable",
    /// "multipliers": [[re, im]...], ...}], "points": [{"kind", "u", ...}]}`. A non-finite
    /// number is an error (JSON has none; serde would write `null`).
    pub fn to_json(&self) -> Result<String, BifError> {
        self.check_finite()?;
        serde_json::to_string_pretty(self).map_err(|e| BifError::Io(e.to_string()))
    }

    /// Writes the three tables as CSV, one after another, each with a header line; the first
    /// column names the table (`equilibrium`, `periodic`, `point`). A non-finite number is
    /// an error, and nothing is written then.
    pub fn write_csv(&self, w: &mut impl Write) -> Result<(), BifError> {
        self.check_finite()?;
        self.write_csv_rows(w)
            .map_err(|e| BifError::Io(e.to_string()))
    }

    fn write_csv_rows(&self, w: &mut impl Write) -> csv::Result<()> {
        // Three tables of different widths in one file.
        let mut c = csv::WriterBuilder::new().flexible(true).from_writer(w);
        c.write_record(["table", "u", "omega", "alpha", "stable", "kind"])?;
        for e in &self.equilibria {
            c.serialize((
                "equilibrium",
                e.u,
                e.omega,
                e.alpha,
                e.stable,
                e.kind.as_str(),
            ))?;
        }
        c.write_record([
            "table",
            "u",
            "period",
            "omega_l_max",
            "omega_l_min",
            "stable",
            "stick_slip",
            "stick_time",
            "mult1_re",
            "mult1_im",
            "mult2_re",
            "mult2_im",
            "mult3_re",
            "mult3_im",
        ])?;
        for p in &self.periodic {
            let mut row = vec![
                "periodic".to_string(),
                num(p.u),
                num(p.period),
                num(p.omega_l_max),
                num(p.omega_l_min),
                p.stable.to_string(),
                p.stick_slip.to_string(),
                num(p.stick_time),
            ];
            row.extend(p.multipliers.iter().flat_map(|m| [num(m[0]), num(m[1])]));
            c.write_record(&row)?;
        }
        c.write_record([
            "table",
            "kind",
            "u",
            "discontinuous",
            "omega",
            "frequency",
            "period",
            "residual",
            "detail",
        ])?;
        for p in &self.points {
            c.serialize((
                "point",
                p.kind.as_str(),
                p.u,
                p.discontinuous,
                p.omega,
                p.frequency,
                p.period,
                p.residual,
                &p.detail,
            ))?;
        }
        c.flush()?;
        Ok(())
    }

    /// The diagram as an SVG figure like the source's Figure 3: ω of each equilibrium and the
    /// max and min of ω_l over each cycle against u, stable solid, unstable dashed (the dash
    /// switches where the stability changes), special points marked and labelled
    /// (`H1 Hopf 0.3835`, `G1 grazing 0.6031`, `F1 fold 4.8430`, `E fold (discontinuous)
    /// 3.8659`). Non-finite numbers are left out (the pen lifts), never written.
    pub fn to_svg(&self, title: &str) -> String {
        svg::render(self, title)
    }
}
