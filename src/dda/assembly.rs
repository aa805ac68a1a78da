//! The global system of one step: assembly of 6×6 blocks and its solution.
//!
//! Unknowns are numbered per free block (6 each); a prescribed block's increment is known
//! and its couplings move to the right-hand side. Two primitives cover every term:
//! a *scalar spring* `½k q² + f0 q` with `q = a·D_i + b·D_j` (contact normal and shear
//! springs), and a *nodal element* whose nodes are points carried by blocks
//! (bolts, fixed points, connection elements).

use std::sync::Arc;

use nalgebra::DVector;

use super::block::{Mat6, Vec6, t_transpose_at};
use super::joints::{ElementTerms, MAX_NODES};
use super::linear::{BlockMatrix, BlockPattern};
use super::mat6::transpose;
use crate::model::geometry::{self, Point};

/// Maps blocks to unknowns and holds the known increments of prescribed blocks.
#[derive(Debug, Clone)]
pub struct DofMap {
    /// For each block, the index of its first unknown, or `None` when prescribed.
    pub slot: Vec<Option<usize>>,
    /// For each block, how many of its six unknowns the matrix needs
    /// ([`Block::moving_unknowns`](super::block::Block::moving_unknowns)): 3 for a rigid
    /// block, whose strain rows and columns are held (see [`System::hold_strains`], which
    /// overwrites whatever was added there), else 6.
    pub moving: Vec<usize>,
    /// Number of unknowns.
    pub n: usize,
}

impl DofMap {
    /// Numbers the free blocks in order; `moving` is each block's count of unknowns that
    /// move (see [`DofMap::moving`]).
    pub fn new(is_free: &[bool], moving: Vec<usize>) -> Self {
        let mut n = 0;
        let slot = is_free
            .iter()
            .map(|&f| {
                if f {
                    n += 6;
                    Some(n - 6)
                } else {
                    None
                }
            })
            .collect();
        Self { slot, moving, n }
    }
}

/// A linear system `K D = R` under assembly.
#[derive(Debug, Clone)]
pub struct System {
    /// Effective stiffness (symmetric, block-sparse).
    pub k: BlockMatrix,
    /// Right-hand side.
    pub r: DVector<f64>,
    /// Factor multiplying stiffness terms: 1 − αf (1 for the static solve).
    pub stiffness_factor: f64,
}

impl System {
    /// An all-zero system on a pattern.
    pub fn zeros(pattern: Arc<BlockPattern>, stiffness_factor: f64) -> Self {
        let n = pattern.unknowns();
        Self {
            k: BlockMatrix::zeros(pattern),
            r: DVector::zeros(n),
            stiffness_factor,
        }
    }

    /// Zeroes the matrix and right-hand side and sets the stiffness factor.
    pub fn clear(&mut self, stiffness_factor: f64) {
        self.k.clear();
        self.r.fill(0.0);
        self.stiffness_factor = stiffness_factor;
    }

    /// Copies another system of the same pattern without allocating.
    pub fn copy_from(&mut self, other: &System) {
        self.k.copy_from(&other.k);
        self.r.copy_from(&other.r);
        self.stiffness_factor = other.stiffness_factor;
    }

    /// Adds `scale · m` to the diagonal block of the unknowns starting at `s`.
    pub fn add_diag_block(&mut self, s: usize, m: &Mat6, scale: f64) {
        self.k.add(s / 6, s / 6, m, scale);
    }

    /// [`System::add_diag_block`] on the leading `moving × moving` part only (see
    /// [`DofMap::moving`]): for a system whose rigid blocks' strains will be held.
    pub fn add_diag_block_leading(&mut self, s: usize, m: &Mat6, scale: f64, moving: usize) {
        self.k.add_leading(s / 6, s / 6, m, scale, (moving, moving));
    }

    /// Holds the strain unknowns of the block whose unknowns start at `s` at zero (a
    /// rigid block, see [`BlockMatrix::hold_strains`]).
    pub fn hold_strains(&mut self, s: usize) {
        self.k.hold_strains(s / 6);
        for i in 3..6 {
            self.r[s + i] = 0.0;
        }
    }

    /// Adds `v` to the right-hand side of the unknowns starting at `s`.
    pub fn add_rhs(&mut self, s: usize, v: &Vec6, scale: f64) {
        for i in 0..6 {
            self.r[s + i] += scale * v[i];
        }
    }

    /// Scalar spring `½k q² + f0 q` with `q = a·D_i + b·D_j` (b/j optional).
    /// `known` gives the increments of all blocks (used for prescribed ones).
    pub fn add_scalar_spring(
        &mut self,
        dofs: &DofMap,
        known: &[Vec6],
        k: f64,
        f0: f64,
        a: (usize, &Vec6),
        b: Option<(usize, &Vec6)>,
    ) {
        self.add_scalar_spring_rhs(dofs, known, k, f0, a, b);
        self.add_scalar_spring_matrix(dofs, k, a, b);
    }

    /// The right-hand side part of [`System::add_scalar_spring`] alone: for a spring
    /// whose matrix part is already in (a new start force on the same springs).
    pub fn add_scalar_spring_rhs(
        &mut self,
        dofs: &DofMap,
        known: &[Vec6],
        k: f64,
        f0: f64,
        (bi, a): (usize, &Vec6),
        other: Option<(usize, &Vec6)>,
    ) {
        let c = self.stiffness_factor * k;
        let parts: [Option<(usize, &Vec6)>; 2] = [Some((bi, a)), other];
        for part in parts.iter() {
            let Some((bp, vp)) = *part else { continue };
            let Some(sp) = dofs.slot[bp] else { continue };
            for (ri, vi) in self.r.as_mut_slice()[sp..sp + 6].iter_mut().zip(vp) {
                *ri -= f0 * vi;
            }
            // Known increments: their couplings go to the right-hand side.
            for &(bq, vq) in parts.iter().flatten() {
                if dofs.slot[bq].is_none() {
                    let q_known: f64 = (0..6).map(|j| vq[j] * known[bq][j]).sum();
                    for i in 0..6 {
                        self.r[sp + i] -= c * vp[i] * q_known;
                    }
                }
            }
        }
    }

    /// The matrix part of [`System::add_scalar_spring`]: `c k a aᵀ` on the unknowns.
    pub fn add_scalar_spring_matrix(
        &mut self,
        dofs: &DofMap,
        k: f64,
        (bi, a): (usize, &Vec6),
        other: Option<(usize, &Vec6)>,
    ) {
        if let Some((bj, b)) = other {
            return self.add_scalar_springs_matrix(dofs, (bi, bj), [(k, a, b)]);
        }
        if let Some(s) = dofs.slot[bi] {
            let leading = (dofs.moving[bi], dofs.moving[bi]);
            let c = self.stiffness_factor * k;
            self.k.add_outer_leading(s / 6, s / 6, a, a, c, leading);
        }
    }

    /// The matrix parts of `N` scalar springs between the same two blocks `i` and `j`
    /// (`(k, a, b)`: stiffness and the directions on each), added block by block: each
    /// 6 × 6 block is found once for all of them, and each entry receives the springs in
    /// the order given — the sums of `N` calls of [`System::add_scalar_spring_matrix`].
    pub fn add_scalar_springs_matrix<const N: usize>(
        &mut self,
        dofs: &DofMap,
        (i, j): (usize, usize),
        springs: [(f64, &Vec6, &Vec6); N],
    ) {
        let c = springs.map(|(k, _, _)| self.stiffness_factor * k);
        for (bp, p) in [(i, 0), (j, 1)] {
            let Some(sp) = dofs.slot[bp] else { continue };
            for (bq, q) in [(i, 0), (j, 1)] {
                if let Some(sq) = dofs.slot[bq] {
                    let side =
                        |t: usize, s: usize| if s == 0 { springs[t].1 } else { springs[t].2 };
                    let terms: [(&Vec6, &Vec6, f64); N] =
                        std::array::from_fn(|t| (side(t, p), side(t, q), c[t]));
                    let leading = (dofs.moving[bp], dofs.moving[bq]);
                    self.k.add_outers_leading(sp / 6, sq / 6, terms, leading);
                }
            }
        }
    }

    /// Nodal element: nodes are points `x_k` of blocks `b_k`; the element has stiffness
    /// `ke` (2n×2n, row-major, on node displacements) and start-of-step force `fe` (2n).
    ///
    /// The block matrix of blocks p, q is `Σ T_kᵀ ke_kl T_l` over the nodes k on p and l
    /// on q. The nodes are grouped by block first, so that each block pair is formed and
    /// added once (a connection triangle has three nodes on two blocks: three 6×6 blocks
    /// instead of seven node-pair products — the assembly of the frame's 48 triangles was
    /// 40 % of its step).
    pub fn add_nodal_element(
        &mut self,
        dofs: &DofMap,
        known: &[Vec6],
        centroids: &[Point],
        element: &ElementTerms,
    ) {
        // At a node count fixed at compile time the loops over node pairs unroll (a
        // connection group has four nodes, a bolt two, a fixed point one).
        match element.nodes().len() {
            4 => self.add_nodal_element_of::<4>(dofs, known, centroids, element),
            3 => self.add_nodal_element_of::<3>(dofs, known, centroids, element),
            2 => self.add_nodal_element_of::<2>(dofs, known, centroids, element),
            1 => self.add_nodal_element_of::<1>(dofs, known, centroids, element),
            // `ElementTerms` holds 1 to `MAX_NODES` nodes.
            count => debug_assert!(false, "an element of {count} nodes"),
        }
    }

    /// [`System::add_nodal_element`] of an element of `N` nodes.
    fn add_nodal_element_of<const N: usize>(
        &mut self,
        dofs: &DofMap,
        known: &[Vec6],
        centroids: &[Point],
        element: &ElementTerms,
    ) {
        let (nodes, ke, fe) = (element.nodes(), element.ke(), element.fe());
        debug_assert_eq!(nodes.len(), N, "an element of N nodes");
        let n = N;
        let dim = 2 * n;
        let c = self.stiffness_factor;
        // Node offsets from their blocks' centroids: Tᵀ·v is formed from them directly.
        let mut offsets = [[0.0; 2]; MAX_NODES];
        for (o, &(b, x)) in offsets.iter_mut().zip(nodes) {
            *o = geometry::sub(x, centroids[b]);
        }
        let by_block = NodesByBlock::new(nodes);
        let (blocks, count, group) = (&by_block.blocks, by_block.count, &by_block.group);
        // s[k][g][r] = row r of Σ over the nodes l on block g of ke_kl T_l (2×6), i.e.
        // Σ_l T_lᵀ (ke[2k+r][2l], ke[2k+r][2l+1]).
        let mut s = [[[[0.0; 6]; 2]; MAX_NODES]; MAX_NODES];
        for k in 0..n {
            for l in 0..n {
                let skg = &mut s[k][group[l]];
                for r in 0..2 {
                    let row = (2 * k + r) * dim + 2 * l;
                    let t = t_transpose_at(offsets[l], [ke[row], ke[row + 1]]);
                    for j in 0..6 {
                        skg[r][j] += t[j];
                    }
                }
            }
        }
        for gp in 0..count {
            let Some(sp) = dofs.slot[blocks[gp]] else {
                continue;
            };
            // Start-of-step force.
            for &k in by_block.members(gp) {
                let f = t_transpose_at(offsets[k], [fe[2 * k], fe[2 * k + 1]]);
                for i in 0..6 {
                    self.r[sp + i] -= f[i];
                }
            }
            for gq in 0..count {
                let bq = blocks[gq];
                // Only the upper blocks are stored (the lower are their transposes).
                if dofs.slot[bq].is_some_and(|sq| sq < sp) {
                    continue;
                }
                let members = by_block.members(gp);
                match dofs.slot[bq] {
                    Some(sq) => {
                        // A rigid block's strain rows and columns are held: only the
                        // leading part is formed (the rest stays zero and is overwritten).
                        let leading = (dofs.moving[blocks[gp]], dofs.moving[bq]);
                        let m = match leading {
                            (3, 3) => pair_block::<3, 3>(members, &offsets, &s, gq),
                            (3, _) => pair_block::<3, 6>(members, &offsets, &s, gq),
                            (_, 3) => pair_block::<6, 3>(members, &offsets, &s, gq),
                            _ => pair_block::<6, 6>(members, &offsets, &s, gq),
                        };
                        self.k.add_leading(sp / 6, sq / 6, &m, c, leading);
                    }
                    None => {
                        let m = pair_block::<6, 6>(members, &offsets, &s, gq);
                        for i in 0..6 {
                            let s: f64 = (0..6).map(|j| m[i][j] * known[bq][j]).sum();
                            self.r[sp + i] -= c * s;
                        }
                    }
                }
            }
        }
    }
}

/// Block (p, q) of a nodal element, `m = Σ T_kᵀ s[k][q]` over the nodes k on block p (see
/// [`System::add_nodal_element`]), its leading `R` rows and `C` columns (the rest zero).
/// Formed column by column as the rows of its transpose (each column is adjacent sums).
fn pair_block<const R: usize, const C: usize>(
    members: &[usize],
    offsets: &[Point; MAX_NODES],
    s: &[[[[f64; 6]; 2]; MAX_NODES]; MAX_NODES],
    gq: usize,
) -> Mat6 {
    let mut m_t = [[0.0; 6]; 6];
    for &k in members {
        let skq = &s[k][gq];
        for (j, m_tj) in m_t.iter_mut().enumerate().take(C) {
            let column = t_transpose_at(offsets[k], [skq[0][j], skq[1][j]]);
            for (m_ij, c_i) in m_tj.iter_mut().zip(column).take(R) {
                *m_ij += c_i;
            }
        }
    }
    transpose(&m_t)
}

/// An element's nodes grouped by the block that carries them (first appearance order).
struct NodesByBlock {
    /// The distinct blocks.
    blocks: [usize; MAX_NODES],
    /// How many there are.
    count: usize,
    /// Which of them carries each node.
    group: [usize; MAX_NODES],
    /// The nodes each carries, in node order (the first `sizes[g]`).
    members: [[usize; MAX_NODES]; MAX_NODES],
    sizes: [usize; MAX_NODES],
}

impl NodesByBlock {
    fn new(nodes: &[(usize, Point)]) -> Self {
        let mut out = Self {
            blocks: [0; MAX_NODES],
            count: 0,
            group: [0; MAX_NODES],
            members: [[0; MAX_NODES]; MAX_NODES],
            sizes: [0; MAX_NODES],
        };
        for (k, &(b, _)) in nodes.iter().enumerate() {
            let g = match out.blocks[..out.count].iter().position(|&q| q == b) {
                Some(g) => g,
                None => {
                    out.blocks[out.count] = b;
                    out.count += 1;
                    out.count - 1
                }
            };
            out.group[k] = g;
            out.members[g][out.sizes[g]] = k;
            out.sizes[g] += 1;
        }
        out
    }

    /// The nodes on the `g`-th block.
    fn members(&self, g: usize) -> &[usize] {
        &self.members[g][..self.sizes[g]]
    }
}

/// Displacement of node `x` of block `b` given all blocks' increments.
pub fn node_displacement(centroids: &[Point], increments: &[Vec6], b: usize, x: Point) -> Point {
    super::block::point_displacement(centroids[b], x, &increments[b])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A contact's two springs added in one pass over the blocks they join are the same
    /// to the bit as added one after the other: between two free blocks (a rigid one,
    /// whose leading part only is added, and a deformable one) either way round, and
    /// against a prescribed block, with zero entries in the directions (rows skipped).
    #[test]
    fn springs_in_one_pass_are_the_springs_one_after_the_other() {
        let pattern = Arc::new(BlockPattern::new(2, [(0, 1)]));
        // Blocks 0 (rigid) and 1 (deformable) free, block 2 prescribed.
        let dofs = DofMap::new(&[true, true, false], vec![3, 6, 6]);
        let mut next = crate::dda::linear::tests::pseudo_random(5);
        let mut direction = || -> Vec6 {
            let mut v: Vec6 = std::array::from_fn(|_| next());
            v[4] = 0.0;
            v
        };
        let mut one_pass = System::zeros(Arc::clone(&pattern), 0.7);
        let mut one_by_one = System::zeros(Arc::clone(&pattern), 0.7);
        for (i, j) in [(0, 1), (1, 0), (1, 2), (2, 0)] {
            let (a, b, c, d) = (direction(), direction(), direction(), direction());
            let springs = [(1e9, &a, &b), (3e8, &c, &d)];
            one_pass.add_scalar_springs_matrix(&dofs, (i, j), springs);
            for (k, u, v) in springs {
                one_by_one.add_scalar_spring_matrix(&dofs, k, (i, u), Some((j, v)));
            }
        }
        let bits =
            |s: &System| -> Vec<u64> { s.k.to_dense().iter().map(|v| v.to_bits()).collect() };
        assert!(one_pass.k.to_dense().iter().all(|v| v.is_finite()));
        assert!(
            one_pass.k.to_dense()[(1, 7)] != 0.0,
            "the coupling block was added"
        );
        assert_eq!(bits(&one_pass), bits(&one_by_one));
    }
}
