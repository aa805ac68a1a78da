//! The Cholesky factor of a small or banded system in 6×6 blocks, cut to its envelope.
//!
//! Reordered so that coupled blocks are numbered close together (reverse Cuthill–McKee on
//! the block graph), a symmetric matrix keeps its Cholesky fill within its *envelope*:
//! block row I of L starts no earlier than block row I of K does. The factor is stored
//! as dense 6×6 blocks, column by column, from the diagonal down to the last row that
//! reaches the column, and factorised and applied with loops over fixed-size blocks that
//! the compiler unrolls. On the three-storey frame (slabs and columns coupled storey by
//! storey, a band of three blocks) that is 25 of the 55 blocks of a full triangle, and a
//! triangular solve costs ~0.2 µs where a general dense one, blocked and dispatched for
//! large matrices, took ~1 µs — a quarter of the whole run.

use std::sync::Arc;

use super::{BlockMatrix, BlockPattern, SolveError};
use crate::dda::block::Mat6;
use crate::dda::mat6::{
    backward, cholesky, divide_by_transposed, forward, subtract_product,
    subtract_product_transposed, subtract_transposed_product, transpose,
};

/// The reordering and the block structure of the factor, shared by the factors of one
/// pattern.
#[derive(Debug)]
pub(super) struct Envelope {
    /// The free block at each position of the reordered system.
    order: Vec<usize>,
    /// First block column of each block row (reordered).
    first: Vec<usize>,
    /// Block column J holds block rows J, J + 1, … at `column_start[J]..column_start[J + 1]`.
    column_start: Vec<usize>,
    /// Where each stored block (I, J) of the factor takes its block of K from: a pattern
    /// entry and whether that entry is stored transposed; `None` for fill.
    source: Vec<Option<(usize, bool)>>,
    /// Multiply-adds of one factorisation.
    factorisation_cost: f64,
}

impl Envelope {
    /// The envelope of matrices on `pattern`.
    pub(super) fn new(pattern: &BlockPattern) -> Self {
        let blocks = pattern.blocks;
        let mut neighbours = vec![Vec::new(); blocks];
        for &(i, j) in pattern.entries.iter().filter(|(i, j)| i != j) {
            neighbours[i].push(j);
            neighbours[j].push(i);
        }
        let order = reverse_cuthill_mckee(&neighbours);
        let mut position = vec![0; blocks];
        for (p, &b) in order.iter().enumerate() {
            position[b] = p;
        }
        let mut first: Vec<usize> = (0..blocks).collect();
        for &(i, j) in &pattern.entries {
            let (a, b) = (position[i], position[j]);
            first[a.max(b)] = first[a.max(b)].min(a.min(b));
        }
        // The last block row each block column reaches.
        let mut last: Vec<usize> = (0..blocks).collect();
        for (row, &from) in first.iter().enumerate() {
            for reach in &mut last[from..row] {
                *reach = row;
            }
        }
        let mut column_start = vec![0];
        let mut source = Vec::new();
        let mut factorisation_cost = 0.0;
        for column in 0..blocks {
            for row in column..=last[column] {
                let (a, b) = (order[row], order[column]);
                // K's block (a, b) is stored as (min, max); the diagonal is read from its
                // upper half, i.e. transposed, as the lower half is not kept.
                source.push(pattern.entry(a.min(b), a.max(b)).map(|e| (e, a >= b)));
                // A row inside the band need not reach back to this column (its block is
                // then fill from the rows below it, or zero): no products for it.
                let products = column.saturating_sub(first[row].max(first[column]));
                factorisation_cost += 216.0 * products as f64 + 126.0;
            }
            column_start.push(source.len());
        }
        Self {
            order,
            first,
            column_start,
            source,
            factorisation_cost,
        }
    }

    /// Stored blocks of the factor.
    pub(super) fn stored_blocks(&self) -> usize {
        self.source.len()
    }

    /// Multiply-adds of one factorisation.
    pub(super) fn factorisation_cost(&self) -> f64 {
        self.factorisation_cost
    }

    /// Index of the stored block (row, column), row ≥ column within the envelope.
    fn at(&self, row: usize, column: usize) -> usize {
        self.column_start[column] + row - column
    }

    /// Block rows stored in a block column (the diagonal included).
    fn rows(&self, column: usize) -> usize {
        self.column_start[column + 1] - self.column_start[column]
    }
}

/// Blocks numbered by reverse Cuthill–McKee: breadth first from a block of least degree,
/// neighbours by increasing degree, the whole order reversed (each component in turn).
fn reverse_cuthill_mckee(neighbours: &[Vec<usize>]) -> Vec<usize> {
    let n = neighbours.len();
    let degree = |b: usize| neighbours[b].len();
    let mut order = Vec::with_capacity(n);
    let mut placed = vec![false; n];
    while let Some(start) = (0..n)
        .filter(|&b| !placed[b])
        .min_by_key(|&b| (degree(b), b))
    {
        placed[start] = true;
        order.push(start);
        let mut head = order.len() - 1;
        while head < order.len() {
            let mut next: Vec<usize> = neighbours[order[head]]
                .iter()
                .copied()
                .filter(|&c| !placed[c])
                .collect();
            next.sort_unstable_by_key(|&c| (degree(c), c));
            for c in next {
                placed[c] = true;
                order.push(c);
            }
            head += 1;
        }
    }
    order.reverse();
    order
}

/// L with K = L Lᵀ (reordered), in 6×6 blocks on an [`Envelope`].
#[derive(Clone)]
pub(super) struct EnvelopeCholesky {
    envelope: Arc<Envelope>,
    /// The stored blocks; a diagonal block holds its lower triangle.
    blocks: Vec<Mat6>,
    /// 1 / L[c][c] of each diagonal block.
    inverse_diagonal: Vec<[f64; 6]>,
    /// The right-hand side in the factor's order.
    work: Vec<[f64; 6]>,
}

impl EnvelopeCholesky {
    /// An empty factor on `envelope`.
    pub(super) fn new(envelope: Arc<Envelope>) -> Self {
        let blocks = envelope.order.len();
        Self {
            blocks: vec![[[0.0; 6]; 6]; envelope.stored_blocks()],
            inverse_diagonal: vec![[0.0; 6]; blocks],
            work: vec![[0.0; 6]; blocks],
            envelope,
        }
    }

    /// An empty factor on the same envelope.
    pub(super) fn empty_like(&self) -> Self {
        Self::new(Arc::clone(&self.envelope))
    }

    /// The envelope.
    pub(super) fn envelope(&self) -> &Envelope {
        &self.envelope
    }

    /// Factorises `k` (left-looking, a block column at a time).
    pub(super) fn factorize(&mut self, k: &BlockMatrix) -> Result<(), SolveError> {
        let envelope = Arc::clone(&self.envelope);
        for column in 0..envelope.order.len() {
            for row in column..column + envelope.rows(column) {
                let mut s = match envelope.source[envelope.at(row, column)] {
                    None => [[0.0; 6]; 6],
                    Some((e, false)) => k.blocks[e],
                    Some((e, true)) => transpose(&k.blocks[e]),
                };
                let from = envelope.first[row].max(envelope.first[column]);
                for inner in from..column {
                    let l_row = &self.blocks[envelope.at(row, inner)];
                    let l_column = &self.blocks[envelope.at(column, inner)];
                    subtract_product_transposed(&mut s, l_row, l_column);
                }
                if row == column {
                    cholesky(&mut s, &mut self.inverse_diagonal[column])
                        .ok_or(SolveError::NotPositiveDefinite)?;
                } else {
                    let diagonal = &self.blocks[envelope.at(column, column)];
                    divide_by_transposed(&mut s, diagonal, &self.inverse_diagonal[column]);
                }
                self.blocks[envelope.at(row, column)] = s;
            }
        }
        Ok(())
    }

    /// x ← K⁻¹ x.
    pub(super) fn solve(&mut self, x: &mut [f64]) {
        let Self {
            envelope,
            blocks,
            inverse_diagonal,
            work: y,
        } = self;
        for (yb, &b) in y.iter_mut().zip(&envelope.order) {
            yb.copy_from_slice(&x[6 * b..6 * b + 6]);
        }
        let columns = envelope.order.len();
        // Forward, L z = y, from the first block that is not zero: before it z is zero,
        // and its products add ±0 to the rows below (the same values). A change of the
        // right-hand side by contact forces touches the blocks in contact only, which
        // reverse Cuthill–McKee tends to number last (a block of least degree starts the
        // breadth-first order that is then reversed: the frame's base slab).
        let nonzero = y.iter().position(|block| block.iter().any(|&v| v != 0.0));
        for column in nonzero.unwrap_or(columns)..columns {
            let diagonal = &blocks[envelope.at(column, column)];
            forward(diagonal, &inverse_diagonal[column], &mut y[column]);
            let solved = y[column];
            for row in column + 1..column + envelope.rows(column) {
                subtract_product(&mut y[row], &blocks[envelope.at(row, column)], &solved);
            }
        }
        // Backward, Lᵀ x = z.
        for column in (0..columns).rev() {
            let mut acc = y[column];
            for row in column + 1..column + envelope.rows(column) {
                subtract_transposed_product(&mut acc, &blocks[envelope.at(row, column)], &y[row]);
            }
            let diagonal = &blocks[envelope.at(column, column)];
            backward(diagonal, &inverse_diagonal[column], &mut acc);
            y[column] = acc;
        }
        for (yb, &b) in y.iter().zip(&envelope.order) {
            x[6 * b..6 * b + 6].copy_from_slice(yb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three-storey frame's block graph: slab i coupled to the two columns above and
    /// below it, numbered slabs first as the scene lists them.
    fn frame_pattern() -> BlockPattern {
        let column = |storey: usize, side: usize| 4 + 2 * (storey - 1) + side;
        let couplings = (1..4).flat_map(|storey| {
            (0..2).flat_map(move |side| {
                [
                    (column(storey, side), storey - 1),
                    (column(storey, side), storey),
                ]
            })
        });
        BlockPattern::new(10, couplings)
    }

    #[test]
    fn the_frame_is_factorised_on_a_band_of_three_blocks() {
        let envelope = Envelope::new(&frame_pattern());
        // Storey by storey: slab, two columns, slab, … — 10 diagonal blocks, and each
        // column block reaches the next two (fill between the two columns of a storey).
        assert_eq!(envelope.stored_blocks(), 25);
    }

    #[test]
    fn reverse_cuthill_mckee_numbers_a_scrambled_chain_in_order() {
        // 2 - 0 - 3 - 1
        let neighbours = vec![vec![2, 3], vec![3], vec![0], vec![0, 1]];
        let order = reverse_cuthill_mckee(&neighbours);
        assert!(order == [2, 0, 3, 1] || order == [1, 3, 0, 2], "{order:?}");
    }
}
