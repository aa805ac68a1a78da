//! The step's linear system `K D = R`: a symmetric matrix of 6×6 blocks on a pattern that
//! is fixed for the whole run, and its solution by Cholesky factors — of a fixed size for
//! the smallest models, on the envelope of the reordered matrix for small and banded ones
//! (`envelope.rs`), faer's sparse factor for the rest.
//!
//! Which blocks can couple is known when the model is built: every free block with
//! itself, the blocks a joint (bolt, support, connection element) ties together, and the
//! declared contact pairs. So the pattern — and the symbolic analysis of the sparse
//! Cholesky factorisation (fill-reducing ordering, elimination tree) — is computed once;
//! each step only refills the numbers.
//!
//! A numeric factorisation is also kept from one solve to the next and used as the
//! preconditioner of conjugate gradients on the new matrix. While the step size does not
//! change, the new matrix differs from the factorised one only by the drift of the
//! geometry (about the strain increment of a step) and by the springs of contacts that
//! changed state — a low-rank change, which preconditioned CG removes in about as many
//! iterations as springs changed. The iteration stops at a backward error near machine
//! precision, as good as a fresh factorisation; when it does not get there within a few
//! iterations, the matrix is factorised again and that factor is kept instead.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::SymbolicSparseColMatRef;

use super::block::Mat6;
pub(crate) use dense::DenseCholesky;
use envelope::{Envelope, EnvelopeCholesky};
use sparse::SparseCholesky;

mod dense;
mod envelope;
mod sparse;

/// Which 6×6 blocks of the matrix can be non-zero: pairs (i, j), i ≤ j, of free blocks
/// (numbered in unknown order: block k owns unknowns 6k..6k+6).
#[derive(Debug)]
pub struct BlockPattern {
    blocks: usize,
    /// Block pairs (i, j) with i ≤ j, sorted.
    entries: Vec<(usize, usize)>,
    /// Entries of block row i are `row_start[i]..row_start[i + 1]`, sorted by column.
    row_start: Vec<usize>,
    /// Upper triangle of the scalar matrix in compressed-column form (for faer).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// For each entry, where each of its 36 values goes in the compressed values
    /// (`usize::MAX` for the strictly lower part of a diagonal block).
    scatter: Vec<[usize; 36]>,
}

impl BlockPattern {
    /// The pattern of `blocks` free blocks with the given couplings (in any order, either
    /// way round, repeats allowed); the diagonal is always included.
    pub fn new(blocks: usize, couplings: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut entries: Vec<(usize, usize)> = (0..blocks).map(|i| (i, i)).collect();
        entries.extend(
            couplings
                .into_iter()
                .filter(|&(i, j)| i < blocks && j < blocks)
                .map(|(i, j)| (i.min(j), i.max(j))),
        );
        entries.sort_unstable();
        entries.dedup();
        let mut row_start = vec![0; blocks + 1];
        for &(i, _) in &entries {
            row_start[i + 1] += 1;
        }
        for i in 0..blocks {
            row_start[i + 1] += row_start[i];
        }
        // Column blocks: which row blocks (and entries) each one holds.
        let mut by_column: Vec<Vec<(usize, usize)>> = vec![Vec::new(); blocks];
        for (e, &(i, j)) in entries.iter().enumerate() {
            by_column[j].push((i, e));
        }
        let n = 6 * blocks;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut scatter = vec![[usize::MAX; 36]; entries.len()];
        col_ptr.push(0);
        for (j, rows) in by_column.iter().enumerate() {
            for b in 0..6 {
                for &(i, e) in rows {
                    for a in 0..6 {
                        if i == j && a > b {
                            continue;
                        }
                        scatter[e][6 * a + b] = row_idx.len();
                        row_idx.push(6 * i + a);
                    }
                }
                col_ptr.push(row_idx.len());
            }
            let _ = j;
        }
        Self {
            blocks,
            entries,
            row_start,
            col_ptr,
            row_idx,
            scatter,
        }
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        6 * self.blocks
    }

    /// Number of stored blocks (the diagonal and the upper triangle).
    pub fn stored_blocks(&self) -> usize {
        self.entries.len()
    }

    /// The entry holding block (i, j), i ≤ j.
    fn entry(&self, i: usize, j: usize) -> Option<usize> {
        let row = self.row_start.get(i..=i + 1)?;
        let slice = &self.entries[row[0]..row[1]];
        slice
            .binary_search_by(|&(_, col)| col.cmp(&j))
            .ok()
            .map(|k| row[0] + k)
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        let n = self.unknowns();
        SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx)
    }
}

/// A symmetric matrix stored as the 6×6 blocks of a [`BlockPattern`] (diagonal blocks in
/// full, the upper triangle of the rest).
#[derive(Debug, Clone)]
pub struct BlockMatrix {
    pattern: Arc<BlockPattern>,
    blocks: Vec<Mat6>,
    /// A coupling outside the pattern was added (a bug in the model setup): the solve
    /// refuses rather than silently dropping it.
    outside_pattern: bool,
    /// Per block, whether its strain unknowns are held ([`BlockMatrix::hold_strains`]):
    /// a small factor then neither copies nor looks for their identity rows.
    held_strains: Vec<bool>,
}

impl BlockMatrix {
    /// The zero matrix on a pattern.
    pub fn zeros(pattern: Arc<BlockPattern>) -> Self {
        let blocks = vec![[[0.0; 6]; 6]; pattern.entries.len()];
        let held_strains = vec![false; pattern.blocks];
        Self {
            pattern,
            blocks,
            outside_pattern: false,
            held_strains,
        }
    }

    /// The pattern.
    pub fn pattern(&self) -> &Arc<BlockPattern> {
        &self.pattern
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.pattern.unknowns()
    }

    /// Sets every value to zero.
    pub fn clear(&mut self) {
        self.blocks.iter_mut().for_each(|b| *b = [[0.0; 6]; 6]);
        self.outside_pattern = false;
        self.held_strains.fill(false);
    }

    /// Copies the values of `other` (same pattern) without allocating.
    pub fn copy_from(&mut self, other: &BlockMatrix) {
        self.blocks.copy_from_slice(&other.blocks);
        self.outside_pattern = other.outside_pattern;
        self.held_strains.copy_from_slice(&other.held_strains);
    }

    /// Adds `scale · m` to block (bi, bj) (block indices in unknown order). Only blocks
    /// with bi ≤ bj are stored: callers add both (bi, bj) and (bj, bi) of a symmetric
    /// term, and the lower one is the transpose of the upper.
    #[inline]
    pub fn add(&mut self, bi: usize, bj: usize, m: &Mat6, scale: f64) {
        self.add_leading(bi, bj, m, scale, (6, 6));
    }

    /// [`BlockMatrix::add`] on the leading `rows × cols` of the block only (3 or 6 each),
    /// for the same reason as [`BlockMatrix::add_outer_leading`].
    #[inline]
    pub fn add_leading(
        &mut self,
        bi: usize,
        bj: usize,
        m: &Mat6,
        scale: f64,
        (rows, cols): (usize, usize),
    ) {
        fn add<const R: usize, const C: usize>(b: &mut Mat6, m: &Mat6, scale: f64) {
            for r in 0..R {
                for c in 0..C {
                    b[r][c] += scale * m[r][c];
                }
            }
        }
        if let Some(b) = self.upper_block(bi, bj) {
            match (rows, cols) {
                (3, 3) => add::<3, 3>(b, m, scale),
                (3, _) => add::<3, 6>(b, m, scale),
                (_, 3) => add::<6, 3>(b, m, scale),
                _ => add::<6, 6>(b, m, scale),
            }
        }
    }

    /// Adds `scale · u vᵀ` to block (bi, bj) (same storage rule as [`BlockMatrix::add`]).
    #[inline]
    pub fn add_outer(&mut self, bi: usize, bj: usize, u: &[f64; 6], v: &[f64; 6], scale: f64) {
        self.add_outer_leading(bi, bj, u, v, scale, (6, 6));
    }

    /// [`BlockMatrix::add_outer`] on the leading `rows × cols` of the block only (3 or 6
    /// each): a rigid block's strain rows and columns are held afterwards
    /// ([`BlockMatrix::hold_strains`]), so what would be added there is never read. The
    /// entries it does add are the same sums in the same order.
    #[inline]
    pub fn add_outer_leading(
        &mut self,
        bi: usize,
        bj: usize,
        u: &[f64; 6],
        v: &[f64; 6],
        scale: f64,
        leading: (usize, usize),
    ) {
        self.add_outers_leading(bi, bj, [(u, v, scale)], leading);
    }

    /// [`BlockMatrix::add_outer_leading`] for `N` products `scale · u vᵀ` on the same
    /// block, found once: each entry receives them in the order given, so the sums are
    /// those of `N` calls one after the other (a contact's normal and shear springs).
    #[inline]
    pub fn add_outers_leading<const N: usize>(
        &mut self,
        bi: usize,
        bj: usize,
        terms: [(&[f64; 6], &[f64; 6], f64); N],
        (rows, cols): (usize, usize),
    ) {
        // Sizes fixed at compile time: the deformable blocks' 6 × 6 loop stays unrolled.
        fn add<const R: usize, const C: usize, const N: usize>(
            b: &mut Mat6,
            terms: &[(&[f64; 6], &[f64; 6], f64); N],
        ) {
            for r in 0..R {
                // Term after term along the row: each entry still receives them in order.
                for (u, v, scale) in terms {
                    let s = scale * u[r];
                    if s == 0.0 {
                        continue;
                    }
                    for c in 0..C {
                        b[r][c] += s * v[c];
                    }
                }
            }
        }
        if let Some(b) = self.upper_block(bi, bj) {
            match (rows, cols) {
                (3, 3) => add::<3, 3, N>(b, &terms),
                (3, _) => add::<3, 6, N>(b, &terms),
                (_, 3) => add::<6, 3, N>(b, &terms),
                _ => add::<6, 6, N>(b, &terms),
            }
        }
    }

    /// The stored block (bi, bj) when bi ≤ bj; `None` for the lower triangle (not stored)
    /// and, marking the matrix, for a block outside the pattern.
    #[inline]
    fn upper_block(&mut self, bi: usize, bj: usize) -> Option<&mut Mat6> {
        if bi > bj {
            return None;
        }
        match self.pattern.entry(bi, bj) {
            Some(e) => Some(&mut self.blocks[e]),
            None => {
                self.outside_pattern = true;
                None
            }
        }
    }

    /// Holds the strain unknowns (3..6) of block `bi` at zero: their rows and columns are
    /// cleared and their diagonal set to one, so that with a zero right-hand side they
    /// solve to zero exactly — the restriction of the system to a rigid block's three
    /// rigid-body unknowns, without a stiff (and ringing) mode in their place.
    pub fn hold_strains(&mut self, bi: usize) {
        self.held_strains[bi] = true;
        for (e, &(i, j)) in self.pattern.entries.iter().enumerate() {
            let b = &mut self.blocks[e];
            if i == bi {
                for row in b.iter_mut().skip(3) {
                    *row = [0.0; 6];
                }
            }
            if j == bi {
                for row in b.iter_mut() {
                    row[3..].fill(0.0);
                }
            }
            if i == bi && j == bi {
                for k in 3..6 {
                    b[k][k] = 1.0;
                }
            }
        }
    }

    /// The diagonal block of block `bi`, for in-place updates.
    #[inline]
    pub fn diagonal_mut(&mut self, bi: usize) -> &mut Mat6 {
        // The diagonal entries come first in each row of the sorted pattern.
        let e = self.pattern.row_start[bi];
        &mut self.blocks[e]
    }

    /// y = K x.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        // Each output's sum runs over the block's columns (rows, for the transpose) in
        // ascending order, as a row-by-row dot product would; the loops are nested the
        // other way round so that the six sums advance together (one vector operation
        // per column instead of six scalar chains: a wall's product took 9 % of its step).
        for (e, &(i, j)) in self.pattern.entries.iter().enumerate() {
            let b = &self.blocks[e];
            let (xi, xj) = (&x[6 * i..6 * i + 6], &x[6 * j..6 * j + 6]);
            let mut s = [0.0; 6];
            for (c, &xc) in xj.iter().enumerate() {
                for r in 0..6 {
                    s[r] += b[r][c] * xc;
                }
            }
            for (yr, sr) in y[6 * i..6 * i + 6].iter_mut().zip(s) {
                *yr += sr;
            }
            if i != j {
                let mut t = [0.0; 6];
                for (row, &xr) in b.iter().zip(xi) {
                    for c in 0..6 {
                        t[c] += row[c] * xr;
                    }
                }
                for (yc, tc) in y[6 * j..6 * j + 6].iter_mut().zip(t) {
                    *yc += tc;
                }
            }
        }
    }

    /// ‖K‖∞, the largest absolute row sum; `rows` (one per unknown) is scratch.
    pub fn norm_inf(&self, rows: &mut [f64]) -> f64 {
        rows.iter_mut().for_each(|v| *v = 0.0);
        // Row i's sums take each block row in column order and row j's (the transpose)
        // in row order, as one loop over the entries would; split in two loops, the
        // second adds whole rows at once.
        for (e, &(i, j)) in self.pattern.entries.iter().enumerate() {
            let b = &self.blocks[e];
            for (r, row) in b.iter().enumerate() {
                for v in row {
                    rows[6 * i + r] += v.abs();
                }
            }
            if i != j {
                for row in b {
                    for (sum, v) in rows[6 * j..6 * j + 6].iter_mut().zip(row) {
                        *sum += v.abs();
                    }
                }
            }
        }
        rows.iter().copied().fold(0.0, f64::max)
    }

    /// Whether every stored value is finite.
    pub fn is_finite(&self) -> bool {
        // No early exit: a fold over every value vectorises, and the check runs before
        // every factorisation (a short-circuiting `all` cost ~8 instructions a value).
        !self
            .blocks
            .iter()
            .flatten()
            .flatten()
            .fold(false, |bad, v| bad | !v.is_finite())
    }

    /// The full dense matrix (for modal analysis of small models).
    pub fn to_dense(&self) -> nalgebra::DMatrix<f64> {
        let n = self.unknowns();
        let mut m = nalgebra::DMatrix::zeros(n, n);
        for (e, &(i, j)) in self.pattern.entries.iter().enumerate() {
            for r in 0..6 {
                for c in 0..6 {
                    let v = self.blocks[e][r][c];
                    m[(6 * i + r, 6 * j + c)] = v;
                    m[(6 * j + c, 6 * i + r)] = v;
                }
            }
        }
        m
    }

    /// Calls `set(row, col, value)` for every stored value of the lower triangle (row ≥
    /// col) but those in the rows and columns of held strains (the identity's by
    /// construction); the entries not visited are zero or held.
    fn for_each_lower(&self, mut set: impl FnMut(usize, usize, f64)) {
        let moving = |b: usize| if self.held_strains[b] { 3 } else { 6 };
        for (e, &(i, j)) in self.pattern.entries.iter().enumerate() {
            for r in 0..moving(i) {
                for c in 0..moving(j) {
                    // Block (i, j) holds K[6i + r][6j + c]; its transpose is the lower part.
                    let (row, col) = (6 * j + c, 6 * i + r);
                    if row >= col {
                        set(row, col, self.blocks[e][r][c]);
                    }
                }
            }
        }
    }

    /// Which unknowns are held (the strains of the blocks held by
    /// [`BlockMatrix::hold_strains`]), for a system of `N` unknowns.
    fn held_unknowns<const N: usize>(&self) -> [bool; N] {
        std::array::from_fn(|u| u % 6 >= 3 && self.held_strains[u / 6])
    }

    /// Writes the stored values in compressed-column order, value `p` at `values[at[p]]`
    /// (a sparse factor's ordering).
    fn fill_compressed(&self, values: &mut [f64], at: &[usize]) {
        for (e, block) in self.blocks.iter().enumerate() {
            let map = &self.pattern.scatter[e];
            for r in 0..6 {
                for c in 0..6 {
                    let p = map[6 * r + c];
                    if p != usize::MAX {
                        values[at[p]] = block[r][c];
                    }
                }
            }
        }
    }
}

/// Why a solve failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveError {
    /// The matrix is not positive definite (an unsupported block, a negative constant).
    NotPositiveDefinite,
    /// A value is NaN or infinite.
    NonFinite,
    /// A term coupled blocks outside the pattern (a bug in the model setup).
    OutsidePattern,
}

/// Counters of the linear solver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Systems solved.
    pub solves: u64,
    /// Numeric factorisations.
    pub factorizations: u64,
    /// Conjugate-gradient iterations preconditioned with a kept factor.
    pub iterations: u64,
}

/// Systems up to this many unknowns are always factorised on their envelope: below it
/// the sparse machinery (supernodes, dispatch) costs more than the arithmetic it saves.
/// Larger ones are too when their envelope holds no more than the sparse factor does.
const ENVELOPE_LIMIT: usize = 120;

/// How many conjugate-gradient iterations one factorisation is worth, from operation
/// counts: the kept factor is used until the iterations spent on it would have paid for a
/// new factorisation (so the total never exceeds twice the better of the two policies, a
/// deterministic choice that does not depend on timings). An iteration costs two
/// triangular solves and a product, ~4·nnz(L) + 2·nnz(K); a factorisation costs what
/// the envelope counts, or ~nnz(L)²/n flops for a sparse factor, done at
/// [`SUPERNODAL_SPEEDUP`] times the rate of an iteration's.
fn iteration_budget(factorisation: f64, factor_nonzeros: usize, matrix_nonzeros: usize) -> usize {
    let (l, a) = (factor_nonzeros as f64, matrix_nonzeros as f64);
    let budget = (factorisation / (4.0 * l + 2.0 * a)).floor() as usize;
    // Before its first iteration an attempt applies the kept factor and forms a residual,
    // about one iteration's work: with a budget of one, a failed attempt costs twice a
    // factorisation's worth before the factorisation it then needs anyway (the frame's
    // step did exactly that, every step). Such a factor is renewed at every change.
    if budget < 2 { 0 } else { budget }
}

/// How many more flops per instruction a supernodal factorisation does than an
/// iteration's triangular solves and product: its dense kernels are blocked and
/// vectorised, the solves stream each stored value once. Measured on `wall:31` (n 5 862,
/// nnz(L) 744 696): a factorisation costs 43 M instructions, the work of 6–9 iterations
/// (a factor application is 4.4 M), where the flop counts alone price it at 29. Without
/// this factor a kept factor spent up to three factorisations' worth of iterations before
/// it was renewed (wall:20 on Kobe, first 7 s: 54–55 s, with it 40–46 s).
const SUPERNODAL_SPEEDUP: f64 = 3.0;

/// Backward error ‖R − K D‖ / (‖K‖‖D‖ + ‖R‖) accepted from the iteration: ~50 ε, what a
/// fresh factorisation achieves.
const BACKWARD_ERROR: f64 = 1e-14;

/// A kept factor whose own solution leaves a residual above this many times the accepted
/// one is not iterated on: the matrix has moved too far from it. Measured on `wall:22`
/// under the first 12 s of Kobe (29 693 attempts), by that first residual in tolerances:
/// below 1e3, 29 of 5 336 attempts failed; from 1e6 to 1e7 about half; above 1e8, 3 879
/// of 4 479, after the whole budget. Failed attempts had spent 56 198 iterations, ~¼ of
/// the run, before the factorisation they needed anyway; with this cut-off, 6 535.
const HOPELESS_RESIDUAL: f64 = 1e6;

/// Systems of up to four blocks (24 unknowns) are factorised densely at a size fixed at
/// compile time ([`DenseCholesky`], in place): at this size the set-up of a blocked,
/// vectorised factorisation costs more than the arithmetic.
pub(crate) const TINY_LIMIT: usize = 24;

/// The factor of a system of one to four blocks (held inline: it is one allocation-free
/// object per model, and the model keeps exactly one).
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
enum Tiny {
    B1(DenseCholesky<6>),
    B2(DenseCholesky<12>),
    B3(DenseCholesky<18>),
    B4(DenseCholesky<24>),
}

impl Tiny {
    fn new(n: usize) -> Option<Self> {
        Some(match n {
            6 => Tiny::B1(DenseCholesky::empty()),
            12 => Tiny::B2(DenseCholesky::empty()),
            18 => Tiny::B3(DenseCholesky::empty()),
            24 => Tiny::B4(DenseCholesky::empty()),
            _ => return None,
        })
    }

    /// The same size, no factor.
    fn empty_like(&self) -> Self {
        match self {
            Tiny::B1(_) => Tiny::B1(DenseCholesky::empty()),
            Tiny::B2(_) => Tiny::B2(DenseCholesky::empty()),
            Tiny::B3(_) => Tiny::B3(DenseCholesky::empty()),
            Tiny::B4(_) => Tiny::B4(DenseCholesky::empty()),
        }
    }

    fn factorize(&mut self, k: &BlockMatrix) -> Result<(), SolveError> {
        // The held unknowns are known from the matrix (a rigid block's strains): only the
        // rest is copied, and the held rows are written as the identity's they are.
        fn factor<const N: usize>(c: &mut DenseCholesky<N>, k: &BlockMatrix) -> bool {
            c.clear();
            k.for_each_lower(|row, column, value| c.set(row, column, value));
            let held = k.held_unknowns::<N>();
            for (u, _) in held.iter().enumerate().filter(|(_, h)| **h) {
                c.set(u, u, 1.0);
            }
            c.factorize_holding(held)
        }
        let factored = match self {
            Tiny::B1(c) => factor(c, k),
            Tiny::B2(c) => factor(c, k),
            Tiny::B3(c) => factor(c, k),
            Tiny::B4(c) => factor(c, k),
        };
        if factored {
            Ok(())
        } else {
            Err(SolveError::NotPositiveDefinite)
        }
    }

    fn solve(&self, x: &mut [f64]) {
        match self {
            Tiny::B1(c) => c.solve(x),
            Tiny::B2(c) => c.solve(x),
            Tiny::B3(c) => c.solve(x),
            Tiny::B4(c) => c.solve(x),
        }
    }
}

#[allow(clippy::large_enum_variant)]
enum Factor {
    Tiny(Tiny),
    Envelope(EnvelopeCholesky),
    Sparse(SparseCholesky),
}

/// Cholesky solver of [`BlockMatrix`] systems that keeps its symbolic analysis for the
/// pattern and its last numeric factor (see the module documentation).
pub struct LinearSolver {
    pattern: Arc<BlockPattern>,
    /// Two kept factors, least recently used replaced first: one for the nominal step and
    /// one for the odd step (a step shortened to land on an event, or cut), so that an odd
    /// step does not throw away the factor the next nominal step needs.
    slots: [Slot; 2],
    /// The slot the current solve uses.
    active: usize,
    scratch: MemBuffer,
    /// CG iterations one factorisation is worth (see [`iteration_budget`]).
    budget: usize,
    /// CG work vectors: residual, preconditioned residual, direction, K·direction.
    work: [Vec<f64>; 4],
    stats: SolverStats,
    /// The last solve factorised its matrix (rather than iterating on a kept factor).
    fresh: bool,
    /// Scratch for [`LinearSolver::solve_change`].
    change: Vec<f64>,
    /// ‖K‖∞ of the matrix of the last solve, once computed (a change solve reuses it).
    matrix_norm: Option<f64>,
}

/// A kept factor and what it is for.
struct Slot {
    factor: Factor,
    /// The factor holds a matrix of the structure identified by this key.
    factored: Option<u64>,
    /// CG iterations spent on this factor since it was made.
    spent: usize,
    /// When it was last used (the solver's solve count).
    used: u64,
    /// The matrix the factor was made of, block by block.
    matrix: Vec<Mat6>,
}

impl Slot {
    fn new(factor: Factor) -> Self {
        Self {
            factor,
            factored: None,
            spent: 0,
            used: 0,
            matrix: Vec::new(),
        }
    }

    /// Whether the factor keeps a copy of the matrix it was made of: not a tiny factor,
    /// which costs less to make again than to check.
    fn keeps_matrix(&self) -> bool {
        !matches!(self.factor, Factor::Tiny(_))
    }

    /// Records `k` as the matrix the factor was just made of (if it keeps one).
    fn remember(&mut self, k: &BlockMatrix) {
        if self.keeps_matrix() {
            self.matrix.clone_from(&k.blocks);
        }
    }

    /// Whether the factor is of this very matrix, to the bit (a factorisation of it again
    /// would give the same factor).
    fn holds(&self, k: &BlockMatrix) -> bool {
        self.keeps_matrix()
            && self.matrix.len() == k.blocks.len()
            && self.matrix.iter().zip(&k.blocks).all(|(a, b)| {
                a.iter()
                    .flatten()
                    .zip(b.iter().flatten())
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            })
    }
}

impl std::fmt::Debug for LinearSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinearSolver")
            .field("unknowns", &self.pattern.unknowns())
            .field(
                "sparse",
                &matches!(self.slots[0].factor, Factor::Sparse { .. }),
            )
            .field("tiny", &matches!(self.slots[0].factor, Factor::Tiny(_)))
            .field("stats", &self.stats)
            .finish()
    }
}

impl Factor {
    /// An empty factor of the same kind and size (sharing the symbolic analysis).
    fn empty_like(&self) -> Self {
        match self {
            Factor::Tiny(t) => Factor::Tiny(t.empty_like()),
            Factor::Envelope(l) => Factor::Envelope(l.empty_like()),
            Factor::Sparse(l) => Factor::Sparse(l.empty_like()),
        }
    }
}

impl Clone for LinearSolver {
    /// A solver for the same pattern (sharing the symbolic analysis) with no factor.
    fn clone(&self) -> Self {
        let factor = self.slots[0].factor.empty_like();
        Self {
            pattern: Arc::clone(&self.pattern),
            scratch: MemBuffer::new(scratch_size(&factor)),
            slots: [Slot::new(factor.empty_like()), Slot::new(factor)],
            active: 0,
            budget: self.budget,
            work: self.work.clone(),
            stats: self.stats,
            fresh: false,
            change: Vec::new(),
            matrix_norm: None,
        }
    }
}

fn scratch_size(factor: &Factor) -> StackReq {
    match factor {
        Factor::Tiny(_) | Factor::Envelope(_) => StackReq::EMPTY,
        Factor::Sparse(l) => l.scratch(),
    }
}

impl LinearSolver {
    /// A solver for matrices on `pattern`: a fixed-size factor for up to four blocks,
    /// else the factor on the envelope or the sparse one (see
    /// [`LinearSolver::envelope_or_sparse`]).
    pub fn new(pattern: Arc<BlockPattern>) -> Result<Self, SolveError> {
        let n = pattern.unknowns();
        let factor = match Tiny::new(n).filter(|_| n <= TINY_LIMIT) {
            Some(tiny) => Factor::Tiny(tiny),
            None => Self::envelope_or_sparse(&pattern)?,
        };
        let matrix_nonzeros = 36 * pattern.stored_blocks();
        let budget = match &factor {
            // Factorising a few blocks costs less than one iteration's bookkeeping.
            Factor::Tiny(_) => 0,
            Factor::Envelope(l) => {
                let envelope = l.envelope();
                let stored = 36 * envelope.stored_blocks();
                iteration_budget(envelope.factorisation_cost(), stored, matrix_nonzeros)
            }
            Factor::Sparse(l) => {
                let stored = l.factor_nonzeros() as f64;
                let flops = stored * stored / n as f64;
                iteration_budget(
                    flops / SUPERNODAL_SPEEDUP,
                    l.factor_nonzeros(),
                    matrix_nonzeros,
                )
            }
        };
        Ok(Self {
            scratch: MemBuffer::new(scratch_size(&factor)),
            slots: [Slot::new(factor.empty_like()), Slot::new(factor)],
            active: 0,
            budget,
            work: std::array::from_fn(|_| vec![0.0; n]),
            stats: SolverStats::default(),
            fresh: false,
            change: Vec::new(),
            matrix_norm: None,
            pattern,
        })
    }

    /// The factor of a system too large for [`Tiny`]: on its envelope when that is small
    /// or holds no more than the sparse factor, else sparse (with the symbolic analysis
    /// done here, once).
    fn envelope_or_sparse(pattern: &BlockPattern) -> Result<Factor, SolveError> {
        let envelope = Envelope::new(pattern);
        if pattern.unknowns() <= ENVELOPE_LIMIT {
            return Ok(Factor::Envelope(EnvelopeCholesky::new(Arc::new(envelope))));
        }
        let symbolic = SparseCholesky::analyse(pattern)?;
        if 36 * envelope.stored_blocks() <= symbolic.len_val() {
            return Ok(Factor::Envelope(EnvelopeCholesky::new(Arc::new(envelope))));
        }
        Ok(Factor::Sparse(SparseCholesky::new(pattern, symbolic)))
    }

    /// Whether the last solve was by conjugate gradients on a kept factor (whose residual
    /// is small relative to ‖K‖‖x‖, not row by row), rather than by a fresh factor.
    pub fn last_solve_iterated(&self) -> bool {
        !self.fresh
    }

    /// One step of iterative refinement for the residual `r` = R − K x of the last solve:
    /// adds F⁻¹ r to `x`, F the kept factor, if that at least halves the residual (the
    /// factor was made for a nearby matrix: the step is cheap, but a factor far from K
    /// could amplify the residual instead); false, `x` untouched, if not.
    pub fn refine(&mut self, k: &BlockMatrix, r: &[f64], x: &mut [f64]) -> bool {
        let norm = |v: &[f64]| v.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
        let [mut delta, z, p, mut q] = std::mem::take(&mut self.work);
        delta.copy_from_slice(r);
        self.apply_inverse(&mut delta);
        k.mul(&delta, &mut q);
        for (qi, ri) in q.iter_mut().zip(r) {
            *qi = ri - *qi;
        }
        let better = norm(&q) <= 0.5 * norm(r);
        if better {
            for (xi, di) in x.iter_mut().zip(&delta) {
                *xi += di;
            }
        }
        self.work = [delta, z, p, q];
        better
    }

    /// Counters so far.
    pub fn stats(&self) -> SolverStats {
        self.stats
    }

    /// Solves K x = rhs. `structure` identifies what changes the whole matrix rather
    /// than drifting it or changing it by a low rank (the step size, the scheme): a kept
    /// factor is only tried for a matrix with the same key.
    pub fn solve(
        &mut self,
        k: &BlockMatrix,
        rhs: &[f64],
        structure: u64,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        self.matrix_norm = None;
        self.solve_same_matrix(k, rhs, structure, x)
    }

    /// [`LinearSolver::solve`] for the very matrix of the last solve, unchanged to the
    /// bit (the caller's promise), with a new right-hand side: when that solve left a
    /// factor of it, the factor is applied without comparing the matrix with the one it
    /// was made of (the event projection's multiplier updates: a 16 KB comparison and a
    /// system copy per update on the three-storey frame). The result is the same as
    /// [`LinearSolver::solve`]'s.
    pub fn solve_unchanged(
        &mut self,
        k: &BlockMatrix,
        rhs: &[f64],
        structure: u64,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        let slot = &mut self.slots[self.active];
        // A tiny factor does not keep its matrix: `solve` would not find it held.
        if !(self.fresh && slot.factored == Some(structure) && slot.keeps_matrix()) {
            return self.solve(k, rhs, structure, x);
        }
        self.matrix_norm = None;
        self.stats.solves += 1;
        slot.used = self.stats.solves;
        x.copy_from_slice(rhs);
        self.apply_inverse(x);
        Ok(())
    }

    /// [`LinearSolver::solve`] for the matrix of the last solve (its norm is kept).
    fn solve_same_matrix(
        &mut self,
        k: &BlockMatrix,
        rhs: &[f64],
        structure: u64,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        if k.outside_pattern {
            return Err(SolveError::OutsidePattern);
        }
        self.stats.solves += 1;
        let kept = (0..2).find(|&i| self.slots[i].factored == Some(structure));
        if let Some(i) = kept {
            self.active = i;
            self.slots[i].used = self.stats.solves;
            // The same matrix solved again (the event projection's multiplier updates,
            // the two-block's repeated solves): its factor is the factorisation's result.
            if self.slots[i].holds(k) {
                self.fresh = true;
                x.copy_from_slice(rhs);
                self.apply_inverse(x);
                return Ok(());
            }
            if self.slots[i].spent < self.budget && self.iterate(k, rhs, x) {
                self.fresh = false;
                return Ok(());
            }
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        // A NaN or ∞ in the matrix makes the small and envelope factors fail (they refuse
        // an infinite pivot, and any other reaches one): the matrix is looked through only
        // when they do, to say why. faer's factor is not relied on for that.
        let sparse = matches!(self.slots[0].factor, Factor::Sparse(_));
        if sparse && !k.is_finite() {
            return Err(SolveError::NonFinite);
        }
        // Refactorise the slot of this structure, or the one used least recently.
        self.active = kept.unwrap_or_else(|| {
            if self.slots[0].used <= self.slots[1].used {
                0
            } else {
                1
            }
        });
        self.factorize(k).map_err(|e| {
            if k.is_finite() {
                e
            } else {
                SolveError::NonFinite
            }
        })?;
        let slot = &mut self.slots[self.active];
        slot.factored = Some(structure);
        slot.used = self.stats.solves;
        slot.remember(k);
        self.fresh = true;
        x.copy_from_slice(rhs);
        self.apply_inverse(x);
        Ok(())
    }

    /// Adds K⁻¹ δ to `x`, for the matrix of the last [`LinearSolver::solve`] (a change
    /// δ of its right-hand side): by the factor alone when that solve factorised this very
    /// matrix, else by conjugate gradients on the kept factor (to the same backward error,
    /// relative to the change), else by a new factorisation.
    pub fn solve_change(
        &mut self,
        k: &BlockMatrix,
        delta: &[f64],
        structure: u64,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        if delta.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        let mut change = std::mem::take(&mut self.change);
        change.resize(delta.len(), 0.0);
        let solved = if self.fresh {
            self.stats.solves += 1;
            change.copy_from_slice(delta);
            self.apply_inverse(&mut change);
            Ok(())
        } else {
            self.solve_same_matrix(k, delta, structure, &mut change)
        };
        for (xi, ci) in x.iter_mut().zip(&change) {
            *xi += ci;
        }
        self.change = change;
        solved
    }

    /// Conjugate gradients preconditioned with the kept factor; false if the backward
    /// error does not reach [`BACKWARD_ERROR`] within the iterations left in the budget.
    fn iterate(&mut self, k: &BlockMatrix, rhs: &[f64], x: &mut [f64]) -> bool {
        let norm = |v: &[f64]| v.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let rhs_norm = norm(rhs);
        let [mut r, mut z, mut p, mut q] = std::mem::take(&mut self.work);
        let k_norm = match self.matrix_norm {
            Some(norm) => norm,
            None => *self.matrix_norm.insert(k.norm_inf(&mut q)),
        };
        // Start from the kept factor's solution.
        x.copy_from_slice(rhs);
        self.apply_inverse(x);
        k.mul(x, &mut q);
        for ((ri, b), kx) in r.iter_mut().zip(rhs).zip(&q) {
            *ri = b - kx;
        }
        // The preconditioned residual z = F⁻¹ r (two triangular solves, the dearest part
        // of an iteration) is formed only once the residual is known not to be small
        // enough: a solve that converges in m iterations applies the factor 1 + m times,
        // not 2 + m (the frame's step: 3.5 → 2.5 per open-close pass).
        let mut rz = 0.0;
        let mut converged = false;
        let allowed = self.budget - self.slots[self.active].spent;
        for iteration in 0..=allowed {
            let (r_norm, x_norm) = (norm(&r), norm(x));
            if !r_norm.is_finite() {
                break;
            }
            let tolerance = BACKWARD_ERROR * (k_norm * x_norm + rhs_norm);
            if iteration == 0 && r_norm > HOPELESS_RESIDUAL * tolerance {
                break;
            }
            if r_norm <= tolerance {
                // Confirm with the true residual (the recursive one drifts); before the
                // first iteration r is the true residual.
                if iteration == 0 {
                    converged = true;
                    break;
                }
                k.mul(x, &mut q);
                let true_norm = rhs
                    .iter()
                    .zip(&q)
                    .fold(0.0_f64, |m, (b, kx)| m.max((b - kx).abs()));
                if true_norm <= tolerance {
                    converged = true;
                    break;
                }
            }
            if iteration == allowed {
                break;
            }
            z.copy_from_slice(&r);
            self.apply_inverse(&mut z);
            let rz_next = dot(&r, &z);
            if iteration == 0 {
                p.copy_from_slice(&z);
            } else {
                let beta = rz_next / rz;
                for i in 0..p.len() {
                    p[i] = z[i] + beta * p[i];
                }
            }
            rz = rz_next;
            self.stats.iterations += 1;
            self.slots[self.active].spent += 1;
            k.mul(&p, &mut q);
            let pq = dot(&p, &q);
            // Not positive (or NaN): the matrix is not what the factor was made for.
            if pq.is_nan() || pq <= 0.0 {
                break;
            }
            let alpha = rz / pq;
            for i in 0..x.len() {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            }
        }
        self.work = [r, z, p, q];
        converged
    }

    fn factorize(&mut self, k: &BlockMatrix) -> Result<(), SolveError> {
        self.stats.factorizations += 1;
        let slot = &mut self.slots[self.active];
        slot.factored = None;
        slot.spent = 0;
        let stack = MemStack::new(&mut self.scratch);
        match &mut slot.factor {
            Factor::Tiny(tiny) => tiny.factorize(k)?,
            Factor::Envelope(l) => l.factorize(k)?,
            Factor::Sparse(l) => l.factorize(k, stack)?,
        }
        Ok(())
    }

    /// x ← K⁻¹ x with the kept factor.
    fn apply_inverse(&mut self, x: &mut [f64]) {
        match &mut self.slots[self.active].factor {
            Factor::Tiny(tiny) => tiny.solve(x),
            Factor::Envelope(l) => l.solve(x),
            Factor::Sparse(l) => l.solve(x, MemStack::new(&mut self.scratch)),
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A random-ish SPD block matrix on a ring pattern (a chain closed on itself).
    pub(super) fn chain(blocks: usize, seed: u64) -> BlockMatrix {
        let ring: Vec<(usize, usize)> = (0..blocks).map(|i| (i, (i + 1) % blocks)).collect();
        springs(blocks, &ring, seed)
    }

    /// Reproducible numbers in [−0.5, 0.5) (a linear congruential generator).
    pub(crate) fn pseudo_random(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A random-ish SPD block matrix with a spring on each of the block pairs `pairs`.
    pub(super) fn springs(blocks: usize, pairs: &[(usize, usize)], seed: u64) -> BlockMatrix {
        let pattern = Arc::new(BlockPattern::new(blocks, pairs.iter().copied()));
        let mut k = BlockMatrix::zeros(pattern);
        let mut next = pseudo_random(seed);
        // A diagonal mass plus springs between the pairs (u uᵀ on the pair): SPD.
        for i in 0..blocks {
            let mut m = [[0.0; 6]; 6];
            for (r, row) in m.iter_mut().enumerate() {
                row[r] = 10.0 + next();
            }
            k.add(i, i, &m, 1.0);
        }
        for &(i, j) in pairs {
            let (u, v): ([f64; 6], [f64; 6]) = (
                std::array::from_fn(|_| next()),
                std::array::from_fn(|_| next()),
            );
            let w = 100.0;
            k.add_outer(i, i, &u, &u, w);
            k.add_outer(i, j, &u, &v, w);
            k.add_outer(j, i, &v, &u, w);
            k.add_outer(j, j, &v, &v, w);
        }
        k
    }

    /// `x` solves K x = rhs to 1e-10 of the solution's largest entry (against nalgebra's
    /// dense Cholesky solution).
    fn assert_solves(k: &BlockMatrix, rhs: &[f64], x: &[f64]) {
        let exact = k
            .to_dense()
            .cholesky()
            .unwrap()
            .solve(&nalgebra::DVector::from_column_slice(rhs));
        for i in 0..x.len() {
            assert!(
                (x[i] - exact[i]).abs() < 1e-10 * exact.amax(),
                "unknown {i}"
            );
        }
    }

    fn check_solves(blocks: usize) {
        check_solves_of(&chain(blocks, 7));
    }

    fn check_solves_of(k: &BlockMatrix) {
        let k = k.clone();
        let n = k.unknowns();
        let dense = k.to_dense();
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut solver = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
        let mut x = vec![0.0; n];
        solver.solve(&k, &rhs, 1, &mut x).unwrap();
        assert_solves(&k, &rhs, &x);
        // A slightly changed matrix with the same key is solved by preconditioned CG, to
        // the same accuracy, without a new factorisation.
        let mut k2 = k.clone();
        let mut bump = [[0.0; 6]; 6];
        bump[0][0] = 1e-7 * dense[(0, 0)];
        k2.add(0, 0, &bump, 1.0);
        let mut x2 = vec![0.0; n];
        solver.solve(&k2, &rhs, 1, &mut x2).unwrap();
        let kept = usize::from(solver.budget > 0);
        assert_eq!(solver.stats().factorizations, 2 - kept as u64);
        assert_solves(&k2, &rhs, &x2);
        // A new key factorises again.
        solver.solve(&k2, &rhs, 2, &mut x2).unwrap();
        assert_eq!(solver.stats().factorizations, 3 - kept as u64);
    }

    /// A matrix far from the kept factor's (every block's diagonal stiffened by 10–90 %,
    /// a change of full rank, like a wall's many contacts changing state at once) is
    /// factorised at once, with no iteration spent on the kept factor, and solved exactly.
    #[test]
    fn a_matrix_far_from_the_kept_factor_is_factorised_without_iterating() {
        let k = grid(20, 7);
        let n = k.unknowns();
        let mut solver = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
        assert!(solver.budget > 0, "this size keeps its factor");
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = vec![0.0; n];
        solver.solve(&k, &rhs, 1, &mut x).unwrap();
        let dense = k.to_dense();
        let mut random = pseudo_random(3);
        let mut far = k.clone();
        for b in 0..n / 6 {
            let mut bump = [[0.0; 6]; 6];
            for (j, row) in bump.iter_mut().enumerate() {
                row[j] = (0.1 + 0.8 * (random() + 0.5)) * dense[(6 * b + j, 6 * b + j)];
            }
            far.add(b, b, &bump, 1.0);
        }
        solver.solve(&far, &rhs, 1, &mut x).unwrap();
        let stats = solver.stats();
        assert_eq!((stats.factorizations, stats.iterations), (2, 0));
        assert_solves(&far, &rhs, &x);
    }

    /// The very matrix solved again (another right-hand side) takes the kept factor as
    /// it is, with no new factorisation and the solution a new factorisation would give,
    /// to the bit; a matrix that differs in one entry does not.
    #[test]
    fn the_same_matrix_again_reuses_its_factor() {
        for blocks in [8, 40] {
            let k = chain(blocks, 7);
            let n = k.unknowns();
            let mut solver = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
            let mut fresh = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
            let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
            let first: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let second: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
            solver.solve(&k, &first, 1, &mut x).unwrap();
            solver.solve(&k, &second, 1, &mut x).unwrap();
            assert_eq!(solver.stats().factorizations, 1, "{blocks} blocks");
            fresh.solve(&k, &second, 1, &mut y).unwrap();
            assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()));
            let mut changed = k.clone();
            let mut bump = [[0.0; 6]; 6];
            bump[3][3] = 1.0;
            changed.add(blocks - 1, blocks - 1, &bump, 1.0);
            assert!(!solver.slots[solver.active].holds(&changed));
        }
    }

    /// `solve_unchanged` gives what `solve` gives for the same matrix, to the bit, and
    /// the same counters, for every kind of factor (a tiny one, which keeps no copy of
    /// its matrix, goes the way `solve` does); after a solve that iterated on a kept
    /// factor, it does not take that factor as the matrix's own.
    #[test]
    fn solve_unchanged_matches_solve() {
        for (blocks, k) in [(2, chain(2, 11)), (8, chain(8, 11)), (400, grid(20, 11))] {
            let n = k.unknowns();
            let rhs: Vec<Vec<f64>> = (0..3)
                .map(|r| (0..n).map(|i| (i as f64 * 0.3 + r as f64).sin()).collect())
                .collect();
            let mut by_solve = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
            let mut by_unchanged = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
            // First a nearby matrix, so that `k`'s first solve may iterate on its factor.
            let mut nearby = k.clone();
            let mut bump = [[0.0; 6]; 6];
            bump[0][0] = 1e-9;
            nearby.add(0, 0, &bump, 1.0);
            for solver in [&mut by_solve, &mut by_unchanged] {
                let mut x = vec![0.0; n];
                solver.solve(&nearby, &rhs[0], 1, &mut x).unwrap();
            }
            for (r, b) in rhs.iter().enumerate() {
                let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
                by_solve.solve(&k, b, 1, &mut x).unwrap();
                if r == 0 {
                    by_unchanged.solve(&k, b, 1, &mut y).unwrap();
                } else {
                    by_unchanged.solve_unchanged(&k, b, 1, &mut y).unwrap();
                }
                let same = x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "{blocks} blocks, right-hand side {r}");
                assert_eq!(by_solve.stats(), by_unchanged.stats(), "{blocks} blocks");
            }
            // The grid's factor is worth iterating on: the fallback above was taken.
            assert_eq!(by_solve.stats().iterations > 0, blocks == 400);
        }
    }

    #[test]
    fn tiny_path_solves() {
        check_solves(2);
    }

    #[test]
    fn dense_path_solves_and_refines() {
        check_solves(8);
    }

    /// A 4 × 4 grid of blocks, each coupled to its right and lower neighbour (a wall's
    /// pattern, 96 unknowns: the envelope path): inside the band some rows do not reach
    /// back to a column their neighbours reach, which the factor must treat as zeros.
    #[test]
    fn envelope_path_solves_a_grid() {
        check_solves_of(&grid(4, 11));
    }

    /// A `side` × `side` grid of blocks, each coupled to its right and lower neighbour.
    fn grid(side: usize, seed: u64) -> BlockMatrix {
        let at = |r: usize, c: usize| r * side + c;
        let mut pairs = Vec::new();
        for r in 0..side {
            for c in 0..side {
                if c + 1 < side {
                    pairs.push((at(r, c), at(r, c + 1)));
                }
                if r + 1 < side {
                    pairs.push((at(r, c), at(r + 1, c)));
                }
            }
        }
        springs(side * side, &pairs, seed)
    }

    /// A star (one block coupled to four that are not coupled to each other): numbered
    /// leaf, leaf, leaf, centre, leaf, the band of the first column holds rows that do not
    /// reach back to it (their blocks are zero, with no products; counting them once
    /// overflowed the cost model).
    #[test]
    fn envelope_path_solves_a_star() {
        let star = [(0, 1), (0, 2), (0, 3), (0, 4)];
        let k = springs(5, &star, 5);
        let solver = LinearSolver::new(Arc::clone(k.pattern())).unwrap();
        assert!(matches!(solver.slots[0].factor, Factor::Envelope(_)));
        assert!(solver.budget < 100, "budget {}", solver.budget);
        check_solves_of(&k);
    }

    #[test]
    fn sparse_path_solves_and_refines() {
        check_solves(40);
    }

    #[test]
    fn block_product_matches_dense() {
        let k = chain(5, 3);
        let x: Vec<f64> = (0..30).map(|i| i as f64 - 7.5).collect();
        let mut y = vec![0.0; 30];
        k.mul(&x, &mut y);
        let yd = k.to_dense() * nalgebra::DVector::from_column_slice(&x);
        for i in 0..30 {
            assert!((y[i] - yd[i]).abs() < 1e-9 * yd.amax());
        }
    }

    #[test]
    fn not_positive_definite_is_an_error() {
        let pattern = Arc::new(BlockPattern::new(1, []));
        let mut k = BlockMatrix::zeros(Arc::clone(&pattern));
        let mut m = [[0.0; 6]; 6];
        for (r, row) in m.iter_mut().enumerate() {
            row[r] = if r == 3 { -1.0 } else { 1.0 };
        }
        k.add(0, 0, &m, 1.0);
        let mut solver = LinearSolver::new(pattern).unwrap();
        let mut x = [0.0; 6];
        assert_eq!(
            solver.solve(&k, &[1.0; 6], 0, &mut x),
            Err(SolveError::NotPositiveDefinite)
        );
    }

    /// A NaN or an infinity anywhere in the matrix — on a diagonal, below it in a
    /// diagonal block, in a coupling block — is refused as non-finite, whichever factor
    /// the size picks (small, envelope, sparse): the small and envelope factors find it
    /// by failing (see `mat6::cholesky`), not by a look through the matrix first.
    #[test]
    fn a_non_finite_matrix_is_refused_by_every_factor() {
        // 2 blocks: the small factor; 12 on a chain: the envelope; 40 on a chain with
        // chords across it: sparse (each checked below).
        let sizes: [(usize, &[(usize, usize)]); 3] = [
            (2, &[(0, 1)]),
            (12, &[]),
            (40, &[(0, 20), (5, 25), (10, 30), (15, 35)]),
        ];
        for (blocks, extra) in sizes {
            let mut pairs: Vec<(usize, usize)> = (0..blocks - 1).map(|i| (i, i + 1)).collect();
            pairs.extend_from_slice(extra);
            let base = springs(blocks, &pairs, 7);
            let kind = format!(
                "{:?}",
                LinearSolver::new(Arc::clone(base.pattern())).unwrap()
            );
            let expected = match blocks {
                2 => "sparse: false, tiny: true",
                12 => "sparse: false, tiny: false",
                _ => "sparse: true, tiny: false",
            };
            assert!(kind.contains(expected), "{blocks} blocks: {kind}");
            let positions = [(0, 0, 2, 2), (blocks - 1, blocks - 1, 5, 1), (0, 1, 3, 4)];
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for &(bi, bj, r, c) in &positions {
                    let mut k = BlockMatrix::zeros(Arc::clone(base.pattern()));
                    k.copy_from(&base);
                    let mut m = [[0.0; 6]; 6];
                    m[r][c] = bad;
                    k.add(bi, bj, &m, 1.0);
                    if bi != bj {
                        k.add(bj, bi, &crate::dda::mat6::transpose(&m), 1.0);
                    } else {
                        let mut t = [[0.0; 6]; 6];
                        t[c][r] = bad;
                        if r != c {
                            k.add(bi, bi, &t, 1.0);
                        }
                    }
                    let mut solver = LinearSolver::new(Arc::clone(base.pattern())).unwrap();
                    let mut x = vec![0.0; 6 * blocks];
                    let rhs = vec![1.0; 6 * blocks];
                    assert_eq!(
                        solver.solve(&k, &rhs, 0, &mut x),
                        Err(SolveError::NonFinite),
                        "{blocks} blocks, {bad} at block ({bi}, {bj}) entry ({r}, {c})"
                    );
                }
            }
            // And the same matrix without it solves.
            let mut solver = LinearSolver::new(Arc::clone(base.pattern())).unwrap();
            let mut x = vec![0.0; 6 * blocks];
            let rhs = vec![1.0; 6 * blocks];
            solver.solve(&base, &rhs, 0, &mut x).unwrap();
            assert_solves(&base, &rhs, &x);
        }
    }

    #[test]
    fn coupling_outside_the_pattern_is_refused() {
        let pattern = Arc::new(BlockPattern::new(2, []));
        let mut k = BlockMatrix::zeros(Arc::clone(&pattern));
        k.add(0, 1, &[[1.0; 6]; 6], 1.0);
        let mut solver = LinearSolver::new(pattern).unwrap();
        let mut x = [0.0; 12];
        assert_eq!(
            solver.solve(&k, &[1.0; 12], 0, &mut x),
            Err(SolveError::OutsidePattern)
        );
    }

    /// A rigid block's strain rows and columns are held after assembly, so its springs
    /// need only their leading part added, and the small factor need not copy the held
    /// rows nor look for them: the held matrix is the same to the bit as with everything
    /// added, and the solution the same to the bit as the factor that finds the identity
    /// rows by looking (`DenseCholesky::factorize`), with the held unknowns exactly zero.
    #[test]
    fn held_strains_need_not_be_assembled_or_copied() {
        // Block 0 rigid, block 1 deformable; a mass on each, a full coupling block and
        // random springs between.
        let pattern = Arc::new(BlockPattern::new(2, [(0, 1)]));
        let mut next = pseudo_random(11);
        let mut everything = BlockMatrix::zeros(Arc::clone(&pattern));
        let mut leading = BlockMatrix::zeros(Arc::clone(&pattern));
        let moving = [3, 6];
        for b in 0..2 {
            let mut m = [[0.0; 6]; 6];
            for (r, row) in m.iter_mut().enumerate() {
                row[r] = 10.0 + next();
            }
            everything.add(b, b, &m, 1.0);
            leading.add_leading(b, b, &m, 1.0, (moving[b], moving[b]));
        }
        let coupling: Mat6 = std::array::from_fn(|_| std::array::from_fn(|_| 0.1 * next()));
        everything.add(0, 1, &coupling, 1.0);
        leading.add_leading(0, 1, &coupling, 1.0, (moving[0], moving[1]));
        for _ in 0..4 {
            let u: [f64; 6] = std::array::from_fn(|_| next());
            let v: [f64; 6] = std::array::from_fn(|_| next());
            for (i, a, j, b) in [
                (0, &u, 0, &u),
                (0, &u, 1, &v),
                (1, &v, 0, &u),
                (1, &v, 1, &v),
            ] {
                everything.add_outer(i, j, a, b, 100.0);
                leading.add_outer_leading(i, j, a, b, 100.0, (moving[i], moving[j]));
            }
        }
        assert!(
            everything.blocks != leading.blocks,
            "the leading adds skip something"
        );
        everything.hold_strains(0);
        leading.hold_strains(0);
        let bits = |k: &BlockMatrix| -> Vec<u64> {
            k.blocks
                .iter()
                .flatten()
                .flatten()
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(&everything), bits(&leading));

        let rhs: Vec<f64> = (0..12)
            .map(|i| {
                if (3..6).contains(&i) {
                    0.0
                } else {
                    (i as f64 * 0.37).sin()
                }
            })
            .collect();
        let mut solver = LinearSolver::new(Arc::clone(&pattern)).unwrap();
        let mut x = vec![0.0; 12];
        solver.solve(&leading, &rhs, 0, &mut x).unwrap();
        // Every value copied (the held rows too, no flags), then found by looking.
        let mut looking = DenseCholesky::<12>::empty();
        looking.clear();
        let mut unflagged = everything.clone();
        unflagged.held_strains.fill(false);
        unflagged.for_each_lower(|row, column, value| looking.set(row, column, value));
        assert!(looking.factorize());
        let mut expected = rhs.clone();
        looking.solve(&mut expected);
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0);
        for i in 0..12 {
            assert!(
                same(x[i], expected[i]),
                "unknown {i}: {} vs {}",
                x[i],
                expected[i]
            );
        }
        assert!(x[3..6].iter().all(|&v| v == 0.0));
        assert_solves(&everything, &rhs, &x);
    }
}
