//! The global system of one step: assembly of 6×6 blocks and its solution.
//!
//! Unknowns are numbered per free block (6 each); a prescribed block's increment is known
//! and its couplings move to the right-hand side. Two primitives cover every term:
//! a *scalar spring* `½k q² + f0 q` with `q = a·D_i + b·D_j` (contact normal and shear
//! springs), and a *nodal element* whose nodes are points carried by blocks
//! (bolts, fixed points, connection elements).

use std::sync::Arc;

use nalgebra::DVector;

use super::block::{Mat6, Vec6, t_matrix};
use super::joints::ElementTerms;
use super::linear::{BlockMatrix, BlockPattern};
use crate::model::geometry::Point;

/// Maps blocks to unknowns and holds the known increments of prescribed blocks.
#[derive(Debug, Clone)]
pub struct DofMap {
    /// For each block, the index of its first unknown, or `None` when prescribed.
    pub slot: Vec<Option<usize>>,
    /// Number of unknowns.
    pub n: usize,
}

impl DofMap {
    /// Numbers the free blocks in order.
    pub fn new(is_free: &[bool]) -> Self {
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
        Self { slot, n }
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
        (bi, a): (usize, &Vec6),
        other: Option<(usize, &Vec6)>,
    ) {
        let c = self.stiffness_factor * k;
        let parts: [Option<(usize, &Vec6)>; 2] = [Some((bi, a)), other];
        for part in parts.iter() {
            let Some((bp, vp)) = *part else { continue };
            let Some(sp) = dofs.slot[bp] else { continue };
            for i in 0..6 {
                self.r[sp + i] -= f0 * vp[i];
            }
            for qpart in parts.iter() {
                let Some((bq, vq)) = *qpart else { continue };
                match dofs.slot[bq] {
                    Some(sq) => self.k.add_outer(sp / 6, sq / 6, vp, vq, c),
                    None => {
                        // Known increment: the coupling goes to the right-hand side.
                        let q_known: f64 = (0..6).map(|j| vq[j] * known[bq][j]).sum();
                        for i in 0..6 {
                            self.r[sp + i] -= c * vp[i] * q_known;
                        }
                    }
                }
            }
        }
    }

    /// Nodal element: nodes are points `x_k` of blocks `b_k`; the element has stiffness
    /// `ke` (2n×2n, row-major, on node displacements) and start-of-step force `fe` (2n).
    pub fn add_nodal_element(
        &mut self,
        dofs: &DofMap,
        known: &[Vec6],
        centroids: &[Point],
        element: &ElementTerms,
    ) {
        let (nodes, ke, fe) = (element.nodes(), element.ke(), element.fe());
        let n = nodes.len();
        let dim = 2 * n;
        let c = self.stiffness_factor;
        let mut ts = [[[0.0; 6]; 2]; 3];
        for (t, &(b, x)) in ts.iter_mut().zip(nodes) {
            *t = t_matrix(centroids[b], x);
        }
        for (k, &(bk, _)) in nodes.iter().enumerate() {
            let Some(sk) = dofs.slot[bk] else { continue };
            let tk = &ts[k];
            // Start-of-step force.
            for i in 0..6 {
                self.r[sk + i] -= tk[0][i] * fe[2 * k] + tk[1][i] * fe[2 * k + 1];
            }
            for (l, &(bl, _)) in nodes.iter().enumerate() {
                // Only the upper blocks are stored (the lower are their transposes).
                let upper = dofs.slot[bl].is_some_and(|sl| sk <= sl);
                if dofs.slot[bl].is_some() && !upper {
                    continue;
                }
                let tl = &ts[l];
                // 2×2 sub-block of ke between nodes k and l.
                let sub = [
                    [ke[(2 * k) * dim + 2 * l], ke[(2 * k) * dim + 2 * l + 1]],
                    [
                        ke[(2 * k + 1) * dim + 2 * l],
                        ke[(2 * k + 1) * dim + 2 * l + 1],
                    ],
                ];
                // m = T_kᵀ sub T_l (6×6).
                let mut m = [[0.0; 6]; 6];
                for i in 0..6 {
                    let a0 = tk[0][i] * sub[0][0] + tk[1][i] * sub[1][0];
                    let a1 = tk[0][i] * sub[0][1] + tk[1][i] * sub[1][1];
                    if a0 == 0.0 && a1 == 0.0 {
                        continue;
                    }
                    for j in 0..6 {
                        m[i][j] = a0 * tl[0][j] + a1 * tl[1][j];
                    }
                }
                match dofs.slot[bl] {
                    Some(sl) => self.k.add(sk / 6, sl / 6, &m, c),
                    None => {
                        for i in 0..6 {
                            let s: f64 = (0..6).map(|j| m[i][j] * known[bl][j]).sum();
                            self.r[sk + i] -= c * s;
                        }
                    }
                }
            }
        }
    }
}

/// Displacement of node `x` of block `b` given all blocks' increments.
pub fn node_displacement(centroids: &[Point], increments: &[Vec6], b: usize, x: Point) -> Point {
    super::block::point_displacement(centroids[b], x, &increments[b])
}
