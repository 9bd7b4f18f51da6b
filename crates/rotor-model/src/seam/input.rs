//! A motor input that changes in time: the piecewise-linear signal u(t) of a table of rows
//! `(t_i, u_i)`.
//!
//! Between two rows u is linear in t; before the first row it is `u_0`, after the last
//! `u_{n−1}`. Two rows at the same t are a step: the first value is the limit from the left,
//! the second holds from that t on (u is right-continuous). Every row's time is a breakpoint
//! of the solvers: no step straddles it, and an integration reaching it restarts on the next
//! [`Piece`].

use std::fmt;
use std::sync::Arc;

use crate::FieldError;

/// A validated piecewise-linear input u(t) \[V\] over time \[s\].
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    rows: Arc<[(f64, f64)]>,
}

/// One linear piece of an [`Input`]: `u(t) = u0 + slope·(t − t0)` on `[t0, end)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Where the piece's line is anchored \[s\].
    pub t0: f64,
    /// The value at `t0` \[V\].
    pub u0: f64,
    /// du/dt on the piece \[V/s\] (0 for a constant piece).
    pub slope: f64,
    /// Where the piece ends: the next breakpoint, or +∞ \[s\].
    pub end: f64,
}

impl Piece {
    /// The constant input `u` for all time (slope 0, no end).
    pub fn constant(u: f64) -> Piece {
        Piece {
            t0: 0.0,
            u0: u,
            slope: 0.0,
            end: f64::INFINITY,
        }
    }

    /// `u(t) = u0 + slope·(t − t0)`. For a constant piece this is `u0` exactly (the product
    /// is +0 for any finite t), so a constant input evaluates to the very bits of `u`.
    #[inline(always)]
    pub fn at(&self, t: f64) -> f64 {
        self.u0 + self.slope * (t - self.t0)
    }
}

impl Input {
    /// The input of the rows `[t, u]`, checked: at least one row, every value finite, t
    /// non-decreasing, at most two rows at one t. The error names the row (`input[3].t`) and
    /// the bad value.
    pub fn new(rows: &[[f64; 2]]) -> Result<Input, FieldError> {
        if rows.is_empty() {
            return Err(FieldError::new(
                "input",
                "[]",
                "needs at least one row [t, u]",
            ));
        }
        for (i, &[t, u]) in rows.iter().enumerate() {
            if !t.is_finite() {
                return Err(FieldError::num(
                    format!("input[{i}].t"),
                    t,
                    "must be finite",
                ));
            }
            if !u.is_finite() {
                return Err(FieldError::num(
                    format!("input[{i}].u"),
                    u,
                    "must be finite",
                ));
            }
            if i > 0 && t < rows[i - 1][0] {
                return Err(FieldError::num(
                    format!("input[{i}].t"),
                    t,
                    format!(
                        "decreases (the row before has t = {}): rows must be in non-decreasing t",
                        rows[i - 1][0]
                    ),
                ));
            }
            if i > 1 && t == rows[i - 1][0] && t == rows[i - 2][0] {
                return Err(FieldError::num(
                    format!("input[{i}].t"),
                    t,
                    "is the third row at this t: a step takes exactly two rows",
                ));
            }
        }
        Ok(Input {
            rows: rows.iter().map(|&[t, u]| (t, u)).collect(),
        })
    }

    /// The rows `(t, u)`.
    pub fn rows(&self) -> &[(f64, f64)] {
        &self.rows
    }

    /// The value if the input is constant (every row the same u), else `None`.
    pub fn constant(&self) -> Option<f64> {
        let u = self.rows[0].1;
        self.rows.iter().all(|r| r.1 == u).then_some(u)
    }

    /// u(t) (right-continuous at a step).
    pub fn at(&self, t: f64) -> f64 {
        self.piece(t).at(t)
    }

    /// The piece that holds from `t` on: before the first row the constant `u_0` up to it;
    /// from the last row (the second of a step) with `t_i ≤ t` the line to the next row,
    /// ending there; after the last row the constant `u_{n−1}` for ever.
    pub fn piece(&self, t: f64) -> Piece {
        let r = &self.rows;
        let (t_first, u_first) = r[0];
        if t < t_first {
            return Piece {
                t0: t_first,
                u0: u_first,
                slope: 0.0,
                end: t_first,
            };
        }
        // The last row with t_i ≤ t (rows are sorted, so a partition point).
        let i = r.partition_point(|row| row.0 <= t) - 1;
        let (ti, ui) = r[i];
        match r.get(i + 1) {
            None => Piece {
                t0: ti,
                u0: ui,
                slope: 0.0,
                end: f64::INFINITY,
            },
            Some(&(tn, un)) => Piece {
                t0: ti,
                u0: ui,
                // tn > t ≥ ti, so tn > ti: a finite slope.
                slope: if un == ui { 0.0 } else { (un - ui) / (tn - ti) },
                end: tn,
            },
        }
    }

    /// The distinct row times, in order: the solvers' breakpoints.
    pub fn breakpoints(&self) -> impl Iterator<Item = f64> + '_ {
        let r = &self.rows;
        (0..r.len())
            .filter(move |&i| i == 0 || r[i].0 != r[i - 1].0)
            .map(move |i| r[i].0)
    }

    /// The first breakpoint after `t`, if any.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        let i = self.rows.partition_point(|row| row.0 <= t);
        self.rows.get(i).map(|r| r.0)
    }

    /// The largest |u| over all time (the rows' extreme values: u is linear between them).
    pub fn max_abs(&self) -> f64 {
        self.rows.iter().map(|r| r.1.abs()).fold(0.0, f64::max)
    }

    /// Parses the CSV of an input: header exactly `t,u`, then rows `t,u`. `source` names the
    /// file in errors (`ramp.csv line 3: …`).
    pub fn from_csv(text: &str, source: &str) -> Result<Input, FieldError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let Some((_, header)) = lines.next() else {
            return Err(FieldError::new(
                "input",
                source,
                "is empty: needs the header `t,u` and at least one row",
            ));
        };
        if header.split(',').map(str::trim).collect::<Vec<_>>() != ["t", "u"] {
            return Err(FieldError::new(
                format!("{source} header"),
                header,
                "must be exactly `t,u`",
            ));
        }
        let mut rows = Vec::new();
        for (n, line) in lines {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != 2 {
                return Err(FieldError::new(
                    format!("{source} line {n}"),
                    line,
                    "must hold two numbers `t,u`",
                ));
            }
            let num = |k: usize, name: &str| {
                cells[k].parse::<f64>().map_err(|_| {
                    FieldError::new(
                        format!("{source} line {n} {name}"),
                        cells[k],
                        "is not a number",
                    )
                })
            };
            rows.push([num(0, "t")?, num(1, "u")?]);
        }
        if rows.is_empty() {
            return Err(FieldError::new(
                "input",
                source,
                "has a header but no rows: needs at least one row `t,u`",
            ));
        }
        Input::new(&rows).map_err(|e| FieldError {
            field: format!("{source}: {}", e.field),
            ..e
        })
    }
}

impl fmt::Display for Input {
    /// The rows as the inline form `[[t, u], …]`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[")?;
        for (i, (t, u)) in self.rows.iter().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "[{t}, {u}]")?;
        }
        write!(f, "]")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_hold_before_between_and_after_the_rows() {
        let inp = Input::new(&[[1.0, 2.0], [3.0, 4.0], [3.0, 0.5], [5.0, 0.5]]).unwrap();
        assert_eq!(inp.at(-10.0), 2.0, "constant before the first row");
        assert_eq!(inp.at(1.0), 2.0);
        assert_eq!(inp.at(2.0), 3.0, "linear between rows");
        assert_eq!(
            inp.at(3.0),
            0.5,
            "a step: the second value holds from its t on"
        );
        assert_eq!(inp.piece(2.5).end, 3.0, "the ramp ends at the step");
        assert_eq!(inp.piece(2.5).at(3.0), 4.0, "the limit from the left");
        assert_eq!(inp.at(4.0), 0.5);
        assert_eq!(inp.at(100.0), 0.5, "constant after the last row");
        assert_eq!(inp.piece(0.0).end, 1.0);
        assert_eq!(inp.piece(5.0).end, f64::INFINITY);
        assert_eq!(inp.breakpoints().collect::<Vec<_>>(), vec![1.0, 3.0, 5.0]);
        assert_eq!(inp.next_breakpoint(1.0), Some(3.0));
        assert_eq!(inp.next_breakpoint(0.0), Some(1.0));
        assert_eq!(inp.next_breakpoint(5.0), None);
        assert_eq!(inp.constant(), None);
        assert_eq!(
            Input::new(&[[0.0, 1.5], [9.0, 1.5]]).unwrap().constant(),
            Some(1.5)
        );
    }

    #[test]
    fn a_constant_piece_gives_the_bits_of_u() {
        for u in [1.5, 0.1 + 0.2, -3.7e-9, 2.5] {
            let p = Piece::constant(u);
            for t in [0.0, 1e-300, 0.3, 4.5778, 1e9] {
                assert_eq!(p.at(t).to_bits(), u.to_bits());
            }
        }
    }

    #[test]
    fn bad_rows_are_refused_by_name_and_value() {
        let msg = |rows: &[[f64; 2]]| Input::new(rows).unwrap_err().to_string();
        assert!(msg(&[]).contains("input"), "{}", msg(&[]));
        let m = msg(&[[0.0, 1.0], [f64::NAN, 2.0]]);
        assert!(m.contains("input[1].t = NaN"), "{m}");
        let m = msg(&[[0.0, f64::INFINITY]]);
        assert!(m.contains("input[0].u = inf"), "{m}");
        let m = msg(&[[1.0, 1.0], [0.5, 2.0]]);
        assert!(
            m.contains("input[1].t = 0.5") && m.contains("decreases"),
            "{m}"
        );
        let m = msg(&[[1.0, 1.0], [1.0, 2.0], [1.0, 3.0]]);
        assert!(
            m.contains("input[2].t = 1") && m.contains("third row"),
            "{m}"
        );
    }

    #[test]
    fn csv_is_parsed_and_refused_by_name() {
        let inp = Input::from_csv("t,u\n0,1.5\n60,1.5\n60,2.5\n", "step.csv").unwrap();
        assert_eq!(inp.rows(), &[(0.0, 1.5), (60.0, 1.5), (60.0, 2.5)]);
        let err = |s: &str| Input::from_csv(s, "f.csv").unwrap_err().to_string();
        assert!(err("").contains("empty"), "{}", err(""));
        assert!(
            err("t,v\n0,1\n").contains("header"),
            "{}",
            err("t,v\n0,1\n")
        );
        assert!(err("t,u\n").contains("no rows"));
        let m = err("t,u\n0,1\n0,x\n");
        assert!(m.contains("line 3 u") && m.contains("x"), "{m}");
        let m = err("t,u\n0,1\n-1,2\n");
        assert!(m.contains("f.csv: input[1].t = -1"), "{m}");
        let m = err("t,u\n0,nan\n");
        assert!(m.contains("input[0].u = NaN"), "{m}");
        let m = err("t,u\n0,1,2\n");
        assert!(m.contains("line 2"), "{m}");
    }

    #[test]
    fn a_time_varying_input_turns_the_fast_forward_off() {
        use crate::seam::{FastForward, Output, Scene};
        let scene = Scene {
            output: Output::Metrics,
            ..Scene::default()
        };
        assert!(FastForward::for_scene(&scene, 1e-10).is_some());
        let step = Scene {
            input: Some(Input::new(&[[0.0, 1.5], [60.0, 1.5], [60.0, 2.5]]).unwrap()),
            ..scene.clone()
        };
        assert!(step.is_time_varying());
        assert!(FastForward::for_scene(&step, 1e-10).is_none());
        // A table of one value is the constant input: nothing to turn off.
        let flat = Scene {
            input: Some(Input::new(&[[0.0, 1.5], [9.0, 1.5]]).unwrap()),
            ..scene
        };
        assert!(!flat.is_time_varying());
        assert!(FastForward::for_scene(&flat, 1e-10).is_some());
    }
}
