//! The sparse Cholesky factor of a large system: faer's supernodal (or simplicial) factor
//! on a fill-reducing (AMD) ordering.
//!
//! faer's `factorize_numeric_llt` permutes the matrix into the factor's ordering at every
//! call: it recounts the permuted columns and moves every value (4 % of a wall's run under
//! strong shaking, where most open-close passes factorise). The permuted pattern depends
//! only on the block pattern, so it is computed here once, with the position each stored
//! value moves to; a factorisation then writes the values straight into their permuted
//! places and calls faer's numeric factorisation on the permuted matrix. Values are moved,
//! never combined, so the factor is the same to the bit.
//!
//! A simplicial factor is applied by our own triangular solves ([`solve_simplicial`]),
//! faer's operations in faer's order; a supernodal one by faer's.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky, simplicial, supernodal,
};
use faer::sparse::utils::{permute_self_adjoint_scratch, permute_self_adjoint_to_unsorted};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Par, Side};

use super::{BlockMatrix, BlockPattern, SolveError};

/// The matrix's pattern in the factor's ordering, on the side the numeric factorisation
/// reads, with where each value of the block pattern's compressed storage goes.
struct PermutedPattern {
    /// Columns' rows in the order faer's permutation leaves them (not sorted; the numeric
    /// factorisation does not need them sorted).
    symbolic: SymbolicSparseColMat<usize>,
    /// `position[p]`: the permuted place of the compressed value `p`.
    position: Vec<usize>,
}

impl PermutedPattern {
    /// Moves a matrix whose value `p` is `p` itself through faer's own permutation, so
    /// that the positions are those faer would produce (indices below 2⁵³ are exact).
    fn new(pattern: &BlockPattern, perm: PermRef<'_, usize>, out_side: Side) -> Self {
        let n = pattern.unknowns();
        let nnz = pattern.row_idx.len();
        let labels: Vec<f64> = (0..nnz).map(|p| p as f64).collect();
        let a = SparseColMatRef::new(pattern.symbolic(), &labels);
        let (mut values, mut col_ptr, mut row_idx) = (vec![0.0; nnz], vec![0; n + 1], vec![0; nnz]);
        let mut stack = MemBuffer::new(permute_self_adjoint_scratch::<usize>(n));
        permute_self_adjoint_to_unsorted(
            &mut values,
            &mut col_ptr,
            &mut row_idx,
            a,
            perm,
            Side::Upper,
            out_side,
            MemStack::new(&mut stack),
        );
        let mut position = vec![0; nnz];
        for (place, &label) in values.iter().enumerate() {
            position[label as usize] = place;
        }
        Self {
            symbolic: SymbolicSparseColMat::new_unsorted_checked(n, n, col_ptr, None, row_idx),
            position,
        }
    }
}

/// A sparse Cholesky factor with its symbolic analysis (shared between the solver's kept
/// factors) and the values of the matrix it last factorised, in the factor's ordering.
pub(super) struct SparseCholesky {
    symbolic: Arc<SymbolicCholesky<usize>>,
    permuted: Arc<PermutedPattern>,
    l_values: Vec<f64>,
    a_values: Vec<f64>,
    /// The right-hand side in the factor's ordering (a simplicial solve's).
    work: Vec<f64>,
}

impl SparseCholesky {
    /// The symbolic analysis of `pattern` (AMD ordering): enough to compare the factor's
    /// size with the envelope's before the factor itself is set up.
    pub(super) fn analyse(pattern: &BlockPattern) -> Result<SymbolicCholesky<usize>, SolveError> {
        factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|_| SolveError::OutsidePattern)
    }

    /// A factor on the analysis `symbolic` of `pattern`, with no numeric factor yet.
    pub(super) fn new(pattern: &BlockPattern, symbolic: SymbolicCholesky<usize>) -> Self {
        let identity: Vec<usize> = (0..pattern.unknowns()).collect();
        let perm = match symbolic.perm() {
            Some(perm) => perm,
            None => PermRef::new_checked(&identity, &identity, identity.len()),
        };
        let permuted = PermutedPattern::new(pattern, perm, read_side(&symbolic));
        Self {
            l_values: vec![0.0; symbolic.len_val()],
            a_values: vec![0.0; permuted.position.len()],
            work: Vec::new(),
            symbolic: Arc::new(symbolic),
            permuted: Arc::new(permuted),
        }
    }

    /// A factor on the same analysis, with no numeric factor.
    pub(super) fn empty_like(&self) -> Self {
        Self {
            symbolic: Arc::clone(&self.symbolic),
            permuted: Arc::clone(&self.permuted),
            l_values: vec![0.0; self.l_values.len()],
            a_values: vec![0.0; self.a_values.len()],
            work: Vec::new(),
        }
    }

    /// Number of values the factor L stores.
    pub(super) fn factor_nonzeros(&self) -> usize {
        self.l_values.len()
    }

    /// Workspace for [`SparseCholesky::factorize`] and [`SparseCholesky::solve`].
    pub(super) fn scratch(&self) -> StackReq {
        let numeric = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                simplicial::factorize_simplicial_numeric_llt_scratch::<usize, f64>(s.nrows())
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                supernodal::factorize_supernodal_numeric_llt_scratch::<usize, f64>(
                    s,
                    Par::Seq,
                    Default::default(),
                )
            }
        };
        StackReq::any_of(&[
            numeric,
            self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ])
    }

    /// Factorises `k`, whose pattern is the one analysed.
    pub(super) fn factorize(
        &mut self,
        k: &BlockMatrix,
        stack: &mut MemStack,
    ) -> Result<(), SolveError> {
        k.fill_compressed(&mut self.a_values, &self.permuted.position);
        let a = SparseColMatRef::new(self.permuted.symbolic.as_ref(), &self.a_values);
        let regularization = LltRegularization::default();
        let outcome = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => simplicial::factorize_simplicial_numeric_llt(
                &mut self.l_values,
                a,
                regularization,
                s,
                stack,
            ),
            SymbolicCholeskyRaw::Supernodal(s) => supernodal::factorize_supernodal_numeric_llt(
                &mut self.l_values,
                a,
                regularization,
                s,
                Par::Seq,
                stack,
                Default::default(),
            ),
        };
        outcome
            .map(|_| ())
            .map_err(|_| SolveError::NotPositiveDefinite)
    }

    /// x ← K⁻¹ x with the factor.
    pub(super) fn solve(&mut self, x: &mut [f64], stack: &mut MemStack) {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let perm = self.symbolic.perm().map(|p| p.arrays());
                solve_simplicial(s.factor(), &self.l_values, perm, x, &mut self.work);
            }
            SymbolicCholeskyRaw::Supernodal(_) => {
                let n = x.len();
                let rhs = faer::MatMut::from_column_major_slice_mut(x, n, 1);
                LltRef::<'_, usize, f64>::new(&self.symbolic, &self.l_values)
                    .solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
            }
        }
    }
}

/// x ← (L Lᵀ)⁻¹ x for a simplicial factor L (its columns' first entries the diagonal) on
/// the ordering `perm` (forward, inverse): faer's own solve, its operations in its order
/// (`solve_lower_triangular_in_place` and its transpose, one right-hand side), so the
/// same bits. Through faer it was compiled with the conjugation a run-time argument in
/// some builds of this crate and inlined in others, and the walls' solves moved by a
/// quarter of their instructions with unrelated edits; this one does not depend on that.
fn solve_simplicial(
    l: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    values: &[f64],
    perm: Option<(&[usize], &[usize])>,
    x: &mut [f64],
    work: &mut Vec<f64>,
) {
    let n = x.len();
    let (col_ptr, row_idx) = (l.col_ptr(), l.row_idx());
    let y: &mut [f64] = match perm {
        Some((forward, _)) => {
            work.clear();
            work.extend(forward.iter().map(|&from| x[from]));
            work
        }
        None => x,
    };
    let y = &mut y[..n];
    // Column j of L: its diagonal, then the rows below it and their values.
    let column = |j: usize| {
        let (start, end) = (col_ptr[j], col_ptr[j + 1]);
        (
            values[start],
            &row_idx[start + 1..end],
            &values[start + 1..end],
        )
    };
    // L y = x, column by column: times the diagonal's reciprocal, then the column below.
    for j in 0..n {
        let (diagonal, rows, below) = column(j);
        let yj = y[j] * diagonal.recip();
        y[j] = yj;
        for (&i, &lij) in rows.iter().zip(below) {
            y[i] -= lij * yj;
        }
    }
    // Lᵀ x = y, backwards: each column's dot product from its last entry up.
    for j in (0..n).rev() {
        let (diagonal, rows, below) = column(j);
        let mut sum = 0.0;
        for (&i, &lij) in rows.iter().zip(below).rev() {
            sum += lij * y[i];
        }
        y[j] = (y[j] - sum) * diagonal.recip();
    }
    if let Some((_, inverse)) = perm {
        for (xi, &from) in x.iter_mut().zip(inverse) {
            *xi = work[from];
        }
    }
}

/// The triangle faer's numeric factorisation reads: the upper one for a simplicial
/// factor, the lower one for a supernodal one (as `factorize_numeric_llt` arranges).
fn read_side(symbolic: &SymbolicCholesky<usize>) -> Side {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(_) => Side::Upper,
        SymbolicCholeskyRaw::Supernodal(_) => Side::Lower,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dda::linear::tests::{chain, springs};

    /// Our simplicial solve is faer's, to the bit, with and without a fill-reducing
    /// ordering, on factors faer analyses as simplicial (and faer's supernodal path is
    /// still taken for the rest).
    #[test]
    fn the_simplicial_solve_is_faer_s_own_to_the_bit() {
        let mut simplicial_cases = 0;
        for (k, seed) in [
            (chain(40, 7), 1),
            (chain(25, 2), 2),
            (springs(30, &[(0, 29)], 5), 3),
        ] {
            let pattern = k.pattern();
            let symbolic = SparseCholesky::analyse(pattern).unwrap();
            let mut ours = SparseCholesky::new(pattern, symbolic);
            let mut buffer = MemBuffer::new(ours.scratch());
            ours.factorize(&k, MemStack::new(&mut buffer)).unwrap();
            if !matches!(ours.symbolic.raw(), SymbolicCholeskyRaw::Simplicial(_)) {
                continue;
            }
            simplicial_cases += 1;
            assert!(ours.symbolic.perm().is_some(), "an AMD ordering");
            let mut next = crate::dda::linear::tests::pseudo_random(seed);
            let rhs: Vec<f64> = (0..pattern.unknowns()).map(|_| next() * 1e3).collect();
            let mut theirs = rhs.clone();
            let n = theirs.len();
            LltRef::<'_, usize, f64>::new(&ours.symbolic, &ours.l_values).solve_in_place_with_conj(
                Conj::No,
                faer::MatMut::from_column_major_slice_mut(&mut theirs, n, 1),
                Par::Seq,
                MemStack::new(&mut buffer),
            );
            let mut mine = rhs.clone();
            ours.solve(&mut mine, MemStack::new(&mut buffer));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&mine), bits(&theirs));
            // Without the ordering: the factor's own order.
            let SymbolicCholeskyRaw::Simplicial(s) = ours.symbolic.raw() else {
                unreachable!()
            };
            let mut plain = rhs.clone();
            let mut work = Vec::new();
            solve_simplicial(s.factor(), &ours.l_values, None, &mut plain, &mut work);
            let mut reference = rhs.clone();
            simplicial::SimplicialLltRef::<'_, usize, f64>::new(s, &ours.l_values)
                .solve_in_place_with_conj(
                    Conj::No,
                    faer::MatMut::from_column_major_slice_mut(&mut reference, n, 1),
                    Par::Seq,
                    MemStack::new(&mut buffer),
                );
            assert_eq!(bits(&plain), bits(&reference));
        }
        assert!(
            simplicial_cases >= 2,
            "simplicial factors: {simplicial_cases}"
        );
    }

    /// The factor from the values written in place is faer's own (which permutes the
    /// matrix at each call), to the bit, on a ring and on a grid of blocks.
    #[test]
    fn the_factor_is_faer_s_own_to_the_bit() {
        let grid: Vec<(usize, usize)> = (0..64)
            .flat_map(|b| [(b, b + 1), (b, b + 8)])
            .filter(|&(b, c)| c < 64 && (c != b + 1 || c % 8 != 0))
            .collect();
        for k in [chain(40, 7), springs(64, &grid, 3)] {
            let pattern = k.pattern();
            let symbolic = SparseCholesky::analyse(pattern).unwrap();
            let mut ours = SparseCholesky::new(pattern, symbolic);
            let mut buffer = MemBuffer::new(ours.scratch());
            ours.factorize(&k, MemStack::new(&mut buffer)).unwrap();

            let symbolic = &ours.symbolic;
            let identity: Vec<usize> = (0..pattern.row_idx.len()).collect();
            let mut values = vec![0.0; identity.len()];
            k.fill_compressed(&mut values, &identity);
            let a = SparseColMatRef::new(pattern.symbolic(), &values);
            let mut theirs = vec![0.0; symbolic.len_val()];
            let mut buffer = MemBuffer::new(
                symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            );
            symbolic
                .factorize_numeric_llt(
                    &mut theirs,
                    a,
                    Side::Upper,
                    LltRegularization::default(),
                    Par::Seq,
                    MemStack::new(&mut buffer),
                    Default::default(),
                )
                .unwrap();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&ours.l_values), bits(&theirs));
        }
    }
}
