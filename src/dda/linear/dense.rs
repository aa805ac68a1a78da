//! A dense Cholesky factor of a size fixed at compile time, factorised and solved in
//! place. It does nalgebra's `Cholesky::new` and `solve_mut` operation for operation (the
//! same products, sums and divisions in the same order, the same `+0.0` starts), so its
//! results are nalgebra's to the bit; what it saves is the moves. nalgebra's factor takes
//! its matrix by value and returns it in an `Option`, and the slot that keeps it receives
//! it by assignment: for the two-block model's 12 × 12 system that was five copies of
//! 1152 bytes per factorisation, a tenth of the run's time spent in `memcpy`
//! (docs/performance-log.md).

/// A Cholesky factor `L` (lower triangle, column by column) of an `N × N` symmetric
/// positive definite matrix.
#[derive(Clone)]
pub(crate) struct DenseCholesky<const N: usize> {
    /// `columns[j][i]` is `L[i][j]` for `i ≥ j`; the upper triangle is scratch.
    columns: [[f64; N]; N],
    /// Whether `columns` holds a factor (the last factorisation succeeded).
    ready: bool,
    /// The unknowns held at zero: a row and column of the identity (a rigid block's
    /// strains, see `BlockMatrix::hold_strains`). Their factor column is the identity's,
    /// and what they add to the others' is zero, so both are skipped: for the two-block
    /// model's two rigid blocks, half the unknowns and three quarters of the work.
    held: [bool; N],
}

impl<const N: usize> DenseCholesky<N> {
    /// No factor yet.
    pub(crate) fn empty() -> Self {
        Self {
            columns: [[0.0; N]; N],
            ready: false,
            held: [false; N],
        }
    }

    /// Zeroes the lower triangle, to be written by [`DenseCholesky::set`] and then
    /// factorised by [`DenseCholesky::factorize`].
    pub(crate) fn clear(&mut self) {
        for (j, column) in self.columns.iter_mut().enumerate() {
            column[j..].fill(0.0);
        }
        self.ready = false;
    }

    /// Sets the matrix entry in `row`, `column` of the lower triangle (`row ≥ column`).
    #[inline]
    pub(crate) fn set(&mut self, row: usize, column: usize, value: f64) {
        debug_assert!(row >= column, "the lower triangle only");
        self.columns[column][row] = value;
    }

    /// Factorises the matrix written since [`DenseCholesky::clear`], in place, holding
    /// the unknowns whose rows and columns are the identity's (found by looking). False
    /// (and no factor held) if it is not positive definite. The solver knows which it
    /// holds and calls [`DenseCholesky::factorize_holding`]; this is the tests' reference.
    #[cfg(test)]
    pub(crate) fn factorize(&mut self) -> bool {
        self.held = self.identity_rows();
        self.ready = self.factorize_in_place();
        self.ready
    }

    /// [`DenseCholesky::factorize`] for a matrix whose rows and columns `held` are the
    /// identity's by construction (the caller wrote them so).
    pub(crate) fn factorize_holding(&mut self, held: [bool; N]) -> bool {
        debug_assert!(
            held.iter()
                .zip(self.identity_rows())
                .all(|(&h, is)| !h || is),
            "a held unknown's row and column are the identity's"
        );
        self.held = held;
        self.ready = self.factorize_in_place();
        self.ready
    }

    /// Which unknowns have the identity's row and column (the rest of a row and column
    /// is looked at only where the diagonal is exactly one, which is rare otherwise).
    fn identity_rows(&self) -> [bool; N] {
        let c = &self.columns;
        std::array::from_fn(|j| {
            c[j][j] == 1.0
                && c[j][j + 1..].iter().all(|&v| v == 0.0)
                && (0..j).all(|k| c[k][j] == 0.0)
        })
    }

    /// nalgebra's `Cholesky::new_internal`: column `j` less `L[j][k]` times column `k`
    /// (as `(−L[j][k]) · L[i][k] + a[i][j]`), then divided by the root of its pivot.
    /// A held unknown's column is left as it is (its root is 1, its entries 0), and its
    /// update of another column is skipped: it would add `±0` to each entry (which can
    /// only turn a `−0.0` into a `+0.0`).
    fn factorize_in_place(&mut self) -> bool {
        let (c, held) = (&mut self.columns, &self.held);
        for j in 0..N {
            if held[j] {
                continue;
            }
            for k in 0..j {
                if held[k] {
                    continue;
                }
                let factor = -c[k][j];
                let (done, rest) = c.split_at_mut(j);
                let (column_k, column_j) = (&done[k], &mut rest[0]);
                for i in j..N {
                    // `+=` adds in either order: the same bits as nalgebra's `a·x + y`.
                    column_j[i] += factor * column_k[i];
                }
            }
            let pivot = c[j][j];
            // nalgebra's `try_sqrt` refuses a zero, negative or NaN pivot; an infinite one
            // is refused too (see `factorable`).
            if !crate::dda::mat6::factorable(pivot) {
                return false;
            }
            let root = pivot.sqrt();
            c[j][j] = root;
            for entry in &mut c[j][j + 1..] {
                *entry /= root;
            }
        }
        true
    }

    /// x ← (L Lᵀ)⁻¹ x (nothing if no factor is held): nalgebra's
    /// `solve_lower_triangular_unchecked_mut` then `ad_solve_lower_triangular_unchecked_mut`.
    /// A held unknown's rows are skipped: its value is its right-hand side's, and it
    /// adds `±0` to the others'.
    pub(crate) fn solve(&self, x: &mut [f64]) {
        if !self.ready {
            return;
        }
        let (c, held) = (&self.columns, &self.held);
        let x = &mut x[..N];
        for i in 0..N {
            if held[i] {
                continue;
            }
            let coefficient = x[i] / c[i][i];
            x[i] = coefficient;
            for r in i + 1..N {
                x[r] += -coefficient * c[i][r];
            }
        }
        for i in (0..N).rev() {
            if held[i] {
                continue;
            }
            let dot = unrolled_dot(&c[i][i + 1..], &x[i + 1..]);
            x[i] = (x[i] - dot) / c[i][i];
        }
    }
}

/// nalgebra's dot product of two dynamically sized views: eight running sums over
/// chunks of eight, combined pairwise into a `+0.0` start, then the remainder one by one.
fn unrolled_dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let mut acc = [0.0f64; 8];
    let mut i = 0;
    while n - i >= 8 {
        for (t, sum) in acc.iter_mut().enumerate() {
            *sum += a[i + t] * b[i + t];
        }
        i += 8;
    }
    let mut result = 0.0;
    for t in 0..4 {
        result += acc[t] + acc[t + 4];
    }
    for k in i..n {
        result += a[k] * b[k];
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite N × N matrix with every entry different.
    fn spd<const N: usize>(seed: u64) -> nalgebra::SMatrix<f64, N, N> {
        let mut next = crate::dda::linear::tests::pseudo_random(seed);
        let a = nalgebra::SMatrix::<f64, N, N>::from_fn(|_, _| next());
        a * a.transpose() + nalgebra::SMatrix::<f64, N, N>::identity() * 0.1
    }

    /// Factorises and solves `m` (with `rhs`) both ours and nalgebra's way and checks
    /// every entry of the factor and the solution with `same`.
    fn compare_with_nalgebra<const N: usize>(
        m: &nalgebra::SMatrix<f64, N, N>,
        rhs: &nalgebra::SVector<f64, N>,
        same: impl Fn(f64, f64) -> bool,
    ) -> DenseCholesky<N> {
        let mut ours = DenseCholesky::<N>::empty();
        ours.clear();
        for j in 0..N {
            for i in j..N {
                ours.set(i, j, m[(i, j)]);
            }
        }
        assert!(ours.factorize());
        let theirs = m.cholesky().expect("SPD");
        let l = theirs.l_dirty();
        for j in 0..N {
            for i in j..N {
                assert!(same(ours.columns[j][i], l[(i, j)]), "L[{i}][{j}]");
            }
        }
        let mut x = rhs.as_slice().to_vec();
        ours.solve(&mut x);
        let expected = theirs.solve(rhs);
        for i in 0..N {
            assert!(same(x[i], expected[i]), "x[{i}]");
        }
        ours
    }

    /// The factor and the solution are nalgebra's to the bit, at every size the solver
    /// uses (6 to 24), with right-hand sides that exercise the unrolled dot's chunks.
    fn same_bits_as_nalgebra<const N: usize>() {
        for seed in 1..6 {
            let rhs = nalgebra::SVector::<f64, N>::from_fn(|i, _| (i as f64 * 0.37).sin() - 0.2);
            compare_with_nalgebra(&spd::<N>(seed), &rhs, |a, b| a.to_bits() == b.to_bits());
        }
    }

    /// Held unknowns (identity rows and columns, as two rigid blocks' strains) are
    /// skipped, and the factor and solution are still nalgebra's: the same bits but for
    /// the sign of an exact zero.
    #[test]
    fn held_unknowns_are_skipped_with_the_same_result() {
        const N: usize = 12;
        let held = |i: usize| (3..6).contains(&i) || (9..12).contains(&i);
        for seed in 1..6 {
            let mut m = spd::<N>(seed);
            for i in (0..N).filter(|&i| held(i)) {
                for j in 0..N {
                    m[(i, j)] = 0.0;
                    m[(j, i)] = 0.0;
                }
                m[(i, i)] = 1.0;
            }
            let rhs = nalgebra::SVector::<f64, N>::from_fn(|i, _| {
                if held(i) {
                    0.0
                } else {
                    (i as f64 * 0.37).sin() - 0.2
                }
            });
            let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0);
            let ours = compare_with_nalgebra(&m, &rhs, same);
            assert_eq!(ours.held.iter().filter(|&&h| h).count(), 6);
        }
    }

    #[test]
    fn factors_and_solves_are_nalgebras_to_the_bit() {
        same_bits_as_nalgebra::<6>();
        same_bits_as_nalgebra::<12>();
        same_bits_as_nalgebra::<18>();
        same_bits_as_nalgebra::<24>();
    }

    /// A matrix that is not positive definite is refused, and nothing is then solved.
    #[test]
    fn an_indefinite_matrix_is_refused() {
        let mut f = DenseCholesky::<6>::empty();
        let mut diagonal = |d3: f64| {
            f.clear();
            for i in 0..6 {
                f.set(i, i, if i == 3 { d3 } else { 2.0 });
            }
            f.factorize()
        };
        assert!(diagonal(1.0));
        assert!(!diagonal(f64::NAN));
        assert!(!diagonal(0.0));
        assert!(!diagonal(-1.0));
        let mut x = [1.0; 6];
        f.solve(&mut x);
        assert_eq!(x, [1.0; 6]);
    }
}
