//! M⁻¹ f for the blocks' mass matrices: the accelerations that balance given forces
//! (each step rebalances every block's, see `Dda::rebalance_accelerations`).
//!
//! A block's mass matrix does not couple its translations with anything, so each is
//! factorised as two roots and a 4 × 4 factor of the rotation and strains. The 4 × 4
//! factors of several blocks are made side by side, one block per vector lane: every
//! lane does the operations of [`DenseCholesky`], in its order, so each block gets the
//! bits it gets alone; but the chains of roots and divisions of different blocks, each
//! waiting on the last, now overlap (they were a tenth of the three-storey frame's time).

use super::PerBlock;
use crate::dda::block::{Block, Mat6, Vec6};
use crate::dda::linear::DenseCholesky;
use crate::dda::mat6::factorable;

/// Blocks factorised side by side: four, two vectors of two `f64` in the baseline
/// x86-64 build (one vector where AVX is enabled), whose chains overlap.
const LANES: usize = 4;

/// [`solve_masses_into`], returned (the tests' form).
#[cfg(test)]
pub(super) fn solve_masses(
    blocks: &[Block],
    forces: &[Vec6],
    wanted: impl Fn(&Block) -> bool,
) -> PerBlock<Option<Vec6>> {
    let mut out = PerBlock::new();
    solve_masses_into(blocks, forces, wanted, &mut out);
    out
}

/// M⁻¹ f of every block for which `wanted` holds (`None` for the others, and for a
/// block whose mass matrix is not positive definite), each the same, to the bit, as
/// [`solve_mass`] of that block alone, written into `out` (filled in place: returned, a
/// two-block step's solutions were copied twice).
pub(super) fn solve_masses_into(
    blocks: &[Block],
    forces: &[Vec6],
    wanted: impl Fn(&Block) -> bool,
    out: &mut PerBlock<Option<Vec6>>,
) {
    out.clear();
    out.resize(blocks.len(), None);
    // Deformable blocks of the usual mass matrix go in lanes; the rest one by one.
    let mut lanes: PerBlock<usize> = PerBlock::new();
    for (i, b) in blocks.iter().enumerate().filter(|(_, b)| wanted(b)) {
        if !b.rigid && translations_uncoupled(&b.mass) {
            lanes.push(i);
        } else {
            out[i] = solve_mass(b, &forces[i]);
        }
    }
    for chunk in lanes.chunks(LANES) {
        // A short last chunk repeats its last block in the spare lanes (their results
        // are dropped).
        let pick = |l: usize| chunk[l.min(chunk.len() - 1)];
        let masses = std::array::from_fn(|l| &blocks[pick(l)].mass);
        let chunk_forces = std::array::from_fn(|l| &forces[pick(l)]);
        match solve_deformable_lanes::<LANES>(masses, chunk_forces) {
            Some(x) => {
                for (&i, xi) in chunk.iter().zip(x) {
                    out[i] = Some(xi);
                }
            }
            // A lane not positive definite (not a model's block): each alone, to say which.
            None => {
                for &i in chunk {
                    out[i] = solve_mass(&blocks[i], &forces[i]);
                }
            }
        }
    }
}

/// Whether the translations' rows and columns of `m` are zero but for their diagonal (a
/// block's mass matrix: its first moments about its centroid vanish, see
/// [`crate::dda::block::mass_matrix`]).
fn translations_uncoupled(m: &Mat6) -> bool {
    (0..2).all(|i| (0..6).all(|j| i == j || (m[i][j] == 0.0 && m[j][i] == 0.0)))
}

/// M⁻¹ f on translation `i` alone (0 or 1: its own 1 × 1 factor), the root's forward
/// then backward substitution, as a 6 × 6 factor does them. `None` if the pivot cannot be
/// factorised.
fn solve_translation(m: &Mat6, f: &Vec6, i: usize) -> Option<f64> {
    let pivot = m[i][i];
    if !factorable(pivot) {
        return None;
    }
    let root = pivot.sqrt();
    Some(f[i] / root / root)
}

/// The forces `f` on the first `moving` unknowns, zero on the held ones (the right-hand
/// side a held factor solves). Picked one by one: a copy of a length known only at run
/// time would call `memcpy`, for a few bytes.
fn moving_forces(f: &Vec6, moving: usize) -> Vec6 {
    std::array::from_fn(|i| if i < moving { f[i] } else { 0.0 })
}

/// Makes `factor` the factor of M's unknowns `from..from + N`, holding those from
/// `moving` on (a rigid block's strains: the identity's rows in the factor). False if not
/// positive definite. (Written into the caller's factor: returned, it was copied.)
fn held_factor<const N: usize>(
    m: &Mat6,
    from: usize,
    moving: usize,
    factor: &mut DenseCholesky<N>,
) -> bool {
    let n = moving - from;
    for j in 0..N {
        factor.set(j, j, if j < n { m[from + j][from + j] } else { 1.0 });
        for i in j + 1..n {
            factor.set(i, j, m[from + i][from + j]);
        }
    }
    factor.factorize_holding(std::array::from_fn(|j| j >= n))
}

/// [`solve_mass`] of `L` deformable blocks whose translations are uncoupled, lane by
/// lane: the same operations in the same order as [`DenseCholesky`]'s factorisation and
/// solve (held nothing, `N` = 4) on each lane. `None` if a lane's matrix is not positive
/// definite.
fn solve_deformable_lanes<const L: usize>(m: [&Mat6; L], f: [&Vec6; L]) -> Option<[Vec6; L]> {
    let mut x = [[0.0; 6]; L];
    for (l, xl) in x.iter_mut().enumerate() {
        for i in 0..2 {
            xl[i] = solve_translation(m[l], f[l], i)?;
        }
    }
    // c[j][i][l]: column j, row i ≥ j of lane l's 4 × 4 factor (its matrix at first).
    let mut c = [[[0.0; L]; 4]; 4];
    for j in 0..4 {
        for i in j..4 {
            c[j][i] = std::array::from_fn(|l| m[l][i + 2][j + 2]);
        }
    }
    for j in 0..4 {
        for k in 0..j {
            let factor: [f64; L] = std::array::from_fn(|l| -c[k][j][l]);
            for i in j..4 {
                for l in 0..L {
                    c[j][i][l] += factor[l] * c[k][i][l];
                }
            }
        }
        let mut ok = true;
        for l in 0..L {
            ok &= factorable(c[j][j][l]);
        }
        if !ok {
            return None;
        }
        let root: [f64; L] = std::array::from_fn(|l| c[j][j][l].sqrt());
        c[j][j] = root;
        for i in j + 1..4 {
            for l in 0..L {
                c[j][i][l] /= root[l];
            }
        }
    }
    // y[i][l]: the rotation and strains of lane l, solved in place.
    let mut y: [[f64; L]; 4] = std::array::from_fn(|i| std::array::from_fn(|l| f[l][i + 2]));
    for i in 0..4 {
        let coefficient: [f64; L] = std::array::from_fn(|l| y[i][l] / c[i][i][l]);
        y[i] = coefficient;
        for r in i + 1..4 {
            for l in 0..L {
                y[r][l] += -coefficient[l] * c[i][r][l];
            }
        }
    }
    for i in (0..4).rev() {
        // `DenseCholesky`'s dot product of fewer than eight terms: from +0, in order.
        let mut dot = [0.0; L];
        for k in i + 1..4 {
            for l in 0..L {
                dot[l] += c[i][k][l] * y[k][l];
            }
        }
        for l in 0..L {
            y[i][l] = (y[i][l] - dot[l]) / c[i][i][l];
        }
    }
    for (l, xl) in x.iter_mut().enumerate() {
        for i in 0..4 {
            xl[i + 2] = y[i][l];
        }
    }
    Some(x)
}

/// M⁻¹ f for a free block's mass matrix M, on the unknowns that move: a rigid block's
/// strain rows are held (the identity in the factor), and their entries come back zero.
/// `None` if the mass matrix is not positive definite.
///
/// A block's mass matrix does not couple its translations with anything (its first
/// moments about its centroid vanish: see [`crate::dda::block::mass_matrix`]). Its factor
/// is then two roots and the factor of the rotation-and-strains block: the same
/// operations a 6 × 6 factor does, without the ones by the exact zeros, which add ±0
/// (the same bits). As one 6 × 6 factor, each division waited on the translations' rows
/// (see the module's documentation).
pub(super) fn solve_mass(b: &Block, f: &Vec6) -> Option<Vec6> {
    let m = &b.mass;
    if !translations_uncoupled(m) {
        return solve_mass_coupled(b, f);
    }
    let moving = b.moving_unknowns();
    let mut x = moving_forces(f, moving);
    for i in 0..2 {
        x[i] = solve_translation(m, f, i)?;
    }
    let mut rest = DenseCholesky::<4>::empty();
    if !held_factor(m, 2, moving, &mut rest) {
        return None;
    }
    rest.solve(&mut x[2..]);
    Some(x)
}

/// [`solve_mass`] for a mass matrix that couples the translations (not one the model
/// makes): one 6 × 6 factor.
fn solve_mass_coupled(b: &Block, f: &Vec6) -> Option<Vec6> {
    let moving = b.moving_unknowns();
    let mut mass = DenseCholesky::<6>::empty();
    if !held_factor(&b.mass, 0, moving, &mut mass) {
        return None;
    }
    let mut x = moving_forces(f, moving);
    mass.solve(&mut x);
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::{solve_mass, solve_mass_coupled};
    use crate::dda::block::Block;

    /// Blocks of several shapes and densities, turned and strained so that every entry of
    /// the rotation-and-strains part of the mass matrix is non-zero.
    fn blocks() -> Vec<Block> {
        let shapes = [
            vec![[0.0, 0.0], [3.0, 0.5], [2.5, 2.0], [0.8, 2.6], [-0.4, 1.1]],
            vec![[-12.3, 0.0], [12.3, 0.0], [12.3, 0.3], [-12.3, 0.3]],
            vec![[1.0, 1.0], [1.4, 1.0], [1.4, 3.5]],
        ];
        let mut out = Vec::new();
        for (k, shape) in shapes.into_iter().enumerate() {
            let mut b = Block::unit_for_tests(shape);
            b.material.density = 10f64.powi(k as i32 * 3);
            b.apply_increment(&[0.1, -0.2, 0.3, 1e-3, -2e-3, 3e-3], true)
                .expect("a small increment");
            out.push(b.clone());
            b.rigid = true;
            out.push(b);
        }
        out
    }

    #[test]
    fn the_split_mass_solve_is_the_full_one_to_the_bit() {
        let forces = [
            [1.0, -2.0, 3.0, -4.0, 5.0, -6.0],
            [1e-9, 7.0, -1e3, 0.5, 1e-12, 2.0],
            [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        ];
        for b in blocks() {
            for f in &forces {
                let split = solve_mass(&b, f).expect("positive definite");
                let full = solve_mass_coupled(&b, f).expect("positive definite");
                let bits = |x: [f64; 6]| x.map(f64::to_bits);
                assert_eq!(
                    bits(split),
                    bits(full),
                    "block {:?} rigid {}",
                    b.mass,
                    b.rigid
                );
                // And it is a solution: M x = f on the unknowns that move.
                for i in 0..b.moving_unknowns() {
                    let mx: f64 = (0..6).map(|j| b.mass[i][j] * split[j]).sum();
                    assert!((mx - f[i]).abs() <= 1e-9 * (1.0 + f[i].abs()), "row {i}");
                }
            }
        }
    }

    /// An infinite or NaN pivot is refused by the split solve as by the whole one (the
    /// rule every factor here decides by, `mat6::factorable`).
    #[test]
    fn the_split_and_the_whole_solve_refuse_the_same_pivots() {
        let f = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        for (i, bad) in [
            (0, f64::INFINITY),
            (1, f64::NAN),
            (1, 0.0),
            (4, f64::INFINITY),
        ] {
            let mut b = blocks().remove(0);
            b.mass[i][i] = bad;
            assert_eq!(solve_mass(&b, &f), None, "M[{i}][{i}] = {bad}");
            assert_eq!(solve_mass_coupled(&b, &f), None, "M[{i}][{i}] = {bad}");
        }
    }

    #[test]
    fn a_mass_matrix_that_couples_the_translations_is_solved_whole() {
        let mut b = blocks().remove(0);
        b.mass[0][2] = 0.1 * b.mass[0][0];
        b.mass[2][0] = b.mass[0][2];
        let f = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let x = solve_mass(&b, &f).expect("positive definite");
        for i in 0..6 {
            let mx: f64 = (0..6).map(|j| b.mass[i][j] * x[j]).sum();
            assert!(
                (mx - f[i]).abs() <= 1e-9 * f[i].abs(),
                "row {i}: {mx} vs {}",
                f[i]
            );
        }
    }
}

#[cfg(test)]
mod lane_tests {
    use super::{solve_mass, solve_masses};
    use crate::dda::block::{Block, BlockRole};

    /// Blocks of every kind the lanes sort: deformable (in lanes), rigid and with coupled
    /// translations (alone), prescribed (not wanted), in a mixed order.
    fn mixed(count: usize) -> Vec<Block> {
        (0..count)
            .map(|k| {
                let w = 1.0 + 0.37 * k as f64;
                let mut b = Block::unit_for_tests(vec![
                    [0.0, 0.0],
                    [w, 0.1 * k as f64],
                    [0.8 * w, 1.0 + 0.2 * k as f64],
                    [-0.3, 0.7],
                ]);
                b.material.density = 1.0 + k as f64;
                let d = 1e-3 * (k as f64 + 1.0);
                b.apply_increment(&[d, -d, 2.0 * d, d, -0.5 * d, 0.7 * d], true)
                    .expect("a small increment");
                match k % 7 {
                    2 => b.rigid = true,
                    4 => {
                        b.mass[0][3] = 0.05 * b.mass[0][0];
                        b.mass[3][0] = b.mass[0][3];
                    }
                    6 => b.role = BlockRole::PrescribedGround,
                    _ => {}
                }
                b
            })
            .collect()
    }

    #[test]
    fn blocks_solved_in_lanes_get_the_bits_they_get_alone() {
        for count in (1..=13).chain([40, 41]) {
            let blocks = mixed(count);
            // Entries of both signs over twelve orders of magnitude, so that the sums
            // of the solve round differently in any other order.
            let mut state = 0x2545_f491_4f6c_dd1d_u64 ^ count as u64;
            let mut next = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
                (unit - 0.5) * 10f64.powf(12.0 * unit - 6.0)
            };
            let forces: Vec<[f64; 6]> = (0..count)
                .map(|_| std::array::from_fn(|_| next()))
                .collect();
            let wanted = |b: &Block| b.role != BlockRole::PrescribedGround;
            let together = solve_masses(&blocks, &forces, wanted);
            for (k, (b, x)) in blocks.iter().zip(&together).enumerate() {
                let alone = wanted(b).then(|| solve_mass(b, &forces[k])).flatten();
                assert_eq!(
                    x.map(|x| x.map(f64::to_bits)),
                    alone.map(|x| x.map(f64::to_bits)),
                    "{count} blocks, block {k}"
                );
                assert_eq!(x.is_some(), wanted(b), "block {k}");
            }
        }
    }

    #[test]
    fn a_lane_that_cannot_be_factorised_leaves_the_others_solved() {
        let mut blocks = mixed(4);
        blocks[1].mass[4][4] = -1.0;
        let forces = vec![[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]; 4];
        let x = solve_masses(&blocks, &forces, |_| true);
        assert!(x[1].is_none());
        for k in [0, 3] {
            assert_eq!(x[k], solve_mass(&blocks[k], &forces[k]), "block {k}");
            assert!(x[k].is_some());
        }
    }
}
