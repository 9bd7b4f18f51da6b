//! A run's samples as one buffer: the times, and the states of the model's size end to end.
//!
//! A run on the output grid keeps 10⁴–10⁵ rows; a row per allocation would cost more than the
//! solver's own work on a long fine grid. So [`Samples`] holds the states in one `Vec<f64>`
//! whose stride is the state's length (3 for the rig, 2N − 1 for a chain of N discs), and
//! hands out [`Row`]s that borrow it. The rig's readers, which still work on its
//! [`State`], take a row's [`Row::state`] or the whole run's [`Samples::rig`].

use crate::State;
use crate::seam::scene::{Sample, SolveError, rig_state};

/// The samples of a run: `(t_k, x_k)` for `k = 0 … len − 1`, each `x_k` of length
/// [`Samples::dim`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Samples {
    dim: usize,
    t: Vec<f64>,
    x: Vec<f64>,
}

/// One sample, borrowed from [`Samples`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row<'a> {
    /// Time \[s\].
    pub t: f64,
    /// The state at `t`, of the model's size (`[α, ω_u, ω_l]` for the rig).
    pub x: &'a [f64],
}

impl Row<'_> {
    /// The rig's state `[α, ω_u, ω_l]`.
    ///
    /// # Panics
    ///
    /// If the row is not of the rig's size: a reader of the rig's state must be handed a
    /// rig's run (the solvers refuse any other model by name before they run).
    pub fn state(&self) -> State {
        assert_eq!(self.x.len(), 3, "a rig's sample has 3 values");
        State::from_column_slice(self.x)
    }

    /// The row as the rig's [`Sample`] (see [`Row::state`]).
    pub fn sample(&self) -> Sample {
        Sample {
            t: self.t,
            x: self.state(),
        }
    }
}

/// One sample whose state may be changed (a test's perturbation of a run).
#[derive(Debug)]
pub struct RowMut<'a> {
    /// Time \[s\] (read only: [`Samples::t_mut`] changes it).
    pub t: f64,
    /// The state at `t`.
    pub x: &'a mut [f64],
}

/// The rows of [`Samples`] whose states may be changed, in order.
pub type RowsMut<'a> = std::iter::Map<
    std::iter::Zip<std::slice::Iter<'a, f64>, std::slice::ChunksExactMut<'a, f64>>,
    fn((&'a f64, &'a mut [f64])) -> RowMut<'a>,
>;

impl Samples {
    /// No samples yet, of states of length `dim`.
    pub fn new(dim: usize) -> Samples {
        Samples::with_capacity(dim, 0)
    }

    /// No samples yet, with room for `n` rows of length `dim`.
    pub fn with_capacity(dim: usize, n: usize) -> Samples {
        Samples {
            dim,
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n * dim),
        }
    }

    /// The rig's samples, from its [`Sample`]s.
    pub fn from_rig(samples: impl IntoIterator<Item = Sample>) -> Samples {
        let mut out = Samples::new(3);
        for s in samples {
            out.push(s.t, s.x.as_slice());
        }
        out
    }

    /// The length of each state.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Room for `n` more rows.
    pub fn reserve(&mut self, n: usize) {
        self.t.reserve(n);
        self.x.reserve(n * self.dim);
    }

    /// Appends the row `(t, x)`.
    ///
    /// # Panics
    ///
    /// If `x` is not of length [`Samples::dim`] (a solver's bug, never an input's).
    #[inline]
    pub fn push(&mut self, t: f64, x: &[f64]) {
        assert_eq!(x.len(), self.dim, "a sample's state has the run's size");
        self.t.push(t);
        self.x.extend_from_slice(x);
    }

    /// Row `k`.
    ///
    /// # Panics
    ///
    /// If `k ≥ len`.
    pub fn row(&self, k: usize) -> Row<'_> {
        Row {
            t: self.t[k],
            x: self.x(k),
        }
    }

    /// The time of row `k`.
    pub fn t(&self, k: usize) -> f64 {
        self.t[k]
    }

    /// The state of row `k`.
    pub fn x(&self, k: usize) -> &[f64] {
        &self.x[k * self.dim..(k + 1) * self.dim]
    }

    /// The time of row `k`, to change (a test's perturbation).
    pub fn t_mut(&mut self, k: usize) -> &mut f64 {
        &mut self.t[k]
    }

    /// The state of row `k`, to change (a test's perturbation).
    pub fn x_mut(&mut self, k: usize) -> &mut [f64] {
        &mut self.x[k * self.dim..(k + 1) * self.dim]
    }

    /// The first row, if any.
    pub fn first(&self) -> Option<Row<'_>> {
        (!self.is_empty()).then(|| self.row(0))
    }

    /// The last row, if any.
    pub fn last(&self) -> Option<Row<'_>> {
        self.len().checked_sub(1).map(|k| self.row(k))
    }

    /// Every time, in order.
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// The rows in order.
    pub fn iter(&self) -> Rows<'_> {
        Rows {
            t: self.t.iter(),
            x: self.x.chunks_exact(self.dim.max(1)),
        }
    }

    /// The rows in order, their states to change.
    pub fn iter_mut(&mut self) -> RowsMut<'_> {
        let dim = self.dim.max(1);
        self.t
            .iter()
            .zip(self.x.chunks_exact_mut(dim))
            .map(|(&t, x)| RowMut { t, x })
    }

    /// The last row, its state to change.
    pub fn last_mut(&mut self) -> Option<RowMut<'_>> {
        self.iter_mut().next_back()
    }

    /// Keeps the first `n` rows.
    pub fn truncate(&mut self, n: usize) {
        self.t.truncate(n);
        self.x.truncate(n * self.dim);
    }

    /// The rows as the rig's [`Sample`]s, for the readers that still work on its state (an
    /// error naming `samples` for a run of another model's size).
    pub fn rig(&self) -> Result<Vec<Sample>, SolveError> {
        if self.dim != 3 && !self.is_empty() {
            rig_state("samples", self.x(0))?;
        }
        Ok(self.iter().map(|r| r.sample()).collect())
    }
}

impl FromIterator<Sample> for Samples {
    /// The rig's samples (see [`Samples::from_rig`]).
    fn from_iter<I: IntoIterator<Item = Sample>>(iter: I) -> Samples {
        Samples::from_rig(iter)
    }
}

/// The rows of [`Samples`], in order.
#[derive(Debug, Clone)]
pub struct Rows<'a> {
    t: std::slice::Iter<'a, f64>,
    x: std::slice::ChunksExact<'a, f64>,
}

impl<'a> Iterator for Rows<'a> {
    type Item = Row<'a>;

    #[inline]
    fn next(&mut self) -> Option<Row<'a>> {
        Some(Row {
            t: *self.t.next()?,
            x: self.x.next()?,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.t.size_hint()
    }

    fn nth(&mut self, n: usize) -> Option<Row<'a>> {
        Some(Row {
            t: *self.t.nth(n)?,
            x: self.x.nth(n)?,
        })
    }
}

impl DoubleEndedIterator for Rows<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        Some(Row {
            t: *self.t.next_back()?,
            x: self.x.next_back()?,
        })
    }
}

impl ExactSizeIterator for Rows<'_> {}

impl<'a> IntoIterator for &'a Samples {
    type Item = Row<'a>;
    type IntoIter = Rows<'a>;

    fn into_iter(self) -> Rows<'a> {
        self.iter()
    }
}

impl<'a> IntoIterator for &'a mut Samples {
    type Item = RowMut<'a>;
    type IntoIter = RowsMut<'a>;

    fn into_iter(self) -> RowsMut<'a> {
        self.iter_mut()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_the_pushed_states_in_order() {
        let mut s = Samples::new(5);
        s.push(0.0, &[1.0, 2.0, 3.0, 4.0, 5.0]);
        s.push(0.5, &[6.0, 7.0, 8.0, 9.0, 10.0]);
        assert_eq!((s.len(), s.dim()), (2, 5));
        assert_eq!(s.row(1).x, &[6.0, 7.0, 8.0, 9.0, 10.0]);
        assert_eq!(s.times(), &[0.0, 0.5]);
        let ts: Vec<f64> = s.iter().rev().map(|r| r.t).collect();
        assert_eq!(ts, [0.5, 0.0]);
        s.x_mut(0)[4] = -1.0;
        assert_eq!(s.first().map(|r| r.x[4]), Some(-1.0));
        s.truncate(1);
        assert_eq!(s.last().map(|r| r.t), Some(0.0));
    }

    #[test]
    fn the_rig_view_round_trips_and_refuses_another_size() {
        let rig = Samples::from_rig([Sample {
            t: 1.0,
            x: State::new(0.1, 0.2, 0.3),
        }]);
        assert_eq!(rig.rig().unwrap()[0].x, State::new(0.1, 0.2, 0.3));
        let mut chain = Samples::new(5);
        chain.push(0.0, &[0.0; 5]);
        let err = chain.rig().unwrap_err().to_string();
        assert!(err.contains("samples") && err.contains("5 values"), "{err}");
    }

    #[test]
    #[should_panic(expected = "a sample's state has the run's size")]
    fn a_row_of_another_size_is_a_bug() {
        Samples::new(3).push(0.0, &[0.0; 2]);
    }
}
