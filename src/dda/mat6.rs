//! Kernels on the 6×6 blocks the systems are made of: a block's unknowns are its
//! translation, rotation and three strains. Written for the fixed size, so that the
//! compiler unrolls them; used by the envelope factor of the linear solver.

use super::block::{Mat6, Vec6};

/// mᵀ.
pub fn transpose(m: &Mat6) -> Mat6 {
    std::array::from_fn(|r| std::array::from_fn(|c| m[c][r]))
}

/// The start of a sum, as `Iterator::sum` starts one: with −0.0, the neutral element of
/// addition. [`cholesky`] and [`divide_by_transposed`] sum six dot products side by side
/// (so that the compiler can put them in vector lanes), each in the order `sum` would,
/// from the same start: the results are those of one dot product after the other, to the
/// bit.
const SUM_START: f64 = -0.0;

/// xᵀ m y. Row by row, then across: six short sums that the processor runs side by side
/// (one running sum of the 36 products waited on each addition in turn; the energy
/// ledger's three forms per block were 3 % of the three-storey's run).
pub fn quadratic_form(m: &Mat6, x: &Vec6, y: &Vec6) -> f64 {
    let rows: [f64; 6] = std::array::from_fn(|i| {
        let r = &m[i];
        x[i] * ((r[0] * y[0] + r[1] * y[1])
            + (r[2] * y[2] + r[3] * y[3])
            + (r[4] * y[4] + r[5] * y[5]))
    });
    (rows[0] + rows[1]) + (rows[2] + rows[3]) + (rows[4] + rows[5])
}

/// [`quadratic_form`] for vectors whose last three entries are zero (a rigid block's
/// strains, held at zero): the same sums without their zero terms, so the same value
/// (the terms left out are ±0).
pub fn quadratic_form_rigid(m: &Mat6, x: &Vec6, y: &Vec6) -> f64 {
    debug_assert!(
        x[3..].iter().chain(&y[3..]).all(|&v| v == 0.0),
        "strains held at zero"
    );
    let rows: [f64; 3] = std::array::from_fn(|i| {
        let r = &m[i];
        x[i] * ((r[0] * y[0] + r[1] * y[1]) + r[2] * y[2])
    });
    (rows[0] + rows[1]) + rows[2]
}

/// s ← s − a bᵀ.
pub fn subtract_product_transposed(s: &mut Mat6, a: &Mat6, b: &Mat6) {
    for (sr, ar) in s.iter_mut().zip(a) {
        for (src, bc) in sr.iter_mut().zip(b) {
            *src -= (0..6).map(|k| ar[k] * bc[k]).sum::<f64>();
        }
    }
}

/// Whether a Cholesky factor can take `pivot` as it comes to a diagonal entry: positive
/// and finite. Not NaN, and not infinite either: an infinite pivot's root would zero its
/// column (times 1/∞) and hide the infinity, while any other NaN or ∞ of the matrix
/// reaches a later pivot (as the square of its entry of L). So a factor made is finite,
/// and the matrix need not be looked through first. Every Cholesky factor here decides
/// by this.
pub fn factorable(pivot: f64) -> bool {
    pivot > 0.0 && pivot < f64::INFINITY
}

/// The lower Cholesky factor L of the symmetric positive definite `s` (its lower half
/// read), in place, its upper half zeroed; the reciprocals of L's diagonal into
/// `inverse`. `None` if `s` is not positive definite (or not finite). Column by column on
/// the transpose, the column's six dot products side by side (see [`SUM_START`]).
pub fn cholesky(s: &mut Mat6, inverse: &mut [f64; 6]) -> Option<()> {
    // Row k of the transpose is column k of L below the diagonal once it is computed.
    let mut s_t = transpose(s);
    for c in 0..6 {
        let mut dots = [SUM_START; 6];
        for k in 0..c {
            let l_ck = s_t[k][c];
            for (dot, &l_rk) in dots.iter_mut().zip(&s_t[k]) {
                *dot += l_rk * l_ck;
            }
        }
        let pivot = s_t[c][c] - dots[c];
        if !factorable(pivot) {
            return None;
        }
        let l = pivot.sqrt();
        s_t[c][c] = l;
        inverse[c] = 1.0 / l;
        for r in c + 1..6 {
            s_t[c][r] = (s_t[c][r] - dots[r]) * inverse[c];
        }
    }
    *s = std::array::from_fn(|r| std::array::from_fn(|c| if c <= r { s_t[c][r] } else { 0.0 }));
    Some(())
}

/// s ← s L⁻ᵀ for a lower triangular L (row by row: x Lᵀ = s is a forward substitution;
/// the six rows' substitutions run side by side, on the transpose).
pub fn divide_by_transposed(s: &mut Mat6, l: &Mat6, inverse: &[f64; 6]) {
    let mut s_t = transpose(s);
    for c in 0..6 {
        let mut dots = [SUM_START; 6];
        for k in 0..c {
            for (dot, &x) in dots.iter_mut().zip(&s_t[k]) {
                *dot += x * l[c][k];
            }
        }
        for (x, dot) in s_t[c].iter_mut().zip(dots) {
            *x = (*x - dot) * inverse[c];
        }
    }
    *s = transpose(&s_t);
}

/// y ← y − m x.
pub fn subtract_product(y: &mut Vec6, m: &Mat6, x: &Vec6) {
    for (yr, mr) in y.iter_mut().zip(m) {
        *yr -= (0..6).map(|c| mr[c] * x[c]).sum::<f64>();
    }
}

/// y ← y − mᵀ x.
pub fn subtract_transposed_product(y: &mut Vec6, m: &Mat6, x: &Vec6) {
    for (c, yc) in y.iter_mut().enumerate() {
        *yc -= (0..6).map(|r| m[r][c] * x[r]).sum::<f64>();
    }
}

/// y ← L⁻¹ y.
pub fn forward(l: &Mat6, inverse: &[f64; 6], y: &mut Vec6) {
    for c in 0..6 {
        y[c] = (y[c] - (0..c).map(|k| l[c][k] * y[k]).sum::<f64>()) * inverse[c];
    }
}

/// y ← L⁻ᵀ y.
pub fn backward(l: &Mat6, inverse: &[f64; 6], y: &mut Vec6) {
    for c in (0..6).rev() {
        y[c] = (y[c] - (c + 1..6).map(|k| l[k][c] * y[k]).sum::<f64>()) * inverse[c];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// m⁻¹ r by the factor and the two triangular solves.
    fn solve_spd(m: &Mat6, r: &Vec6) -> Option<Vec6> {
        let mut l = *m;
        let mut inverse = [0.0; 6];
        cholesky(&mut l, &mut inverse)?;
        let mut x = *r;
        forward(&l, &inverse, &mut x);
        backward(&l, &inverse, &mut x);
        Some(x)
    }

    /// An SPD matrix: a diagonal plus u uᵀ plus v vᵀ, as a block's mass matrix is.
    fn spd() -> Mat6 {
        let u = [1.0, -0.5, 0.25, 2.0, 0.0, 0.3];
        let v = [0.2, 0.1, -1.0, 0.0, 0.7, 0.4];
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                u[r] * u[c] + v[r] * v[c] + if r == c { 1.0 + r as f64 } else { 0.0 }
            })
        })
    }

    #[test]
    fn the_quadratic_form_is_x_m_y() {
        // With x = eᵢ and y = eⱼ it picks m's entry (i, j) exactly; on general vectors it
        // is the sum of the 36 products to within their rounding.
        let m = spd();
        for i in 0..6 {
            for j in 0..6 {
                let (mut x, mut y) = ([0.0; 6], [0.0; 6]);
                x[i] = 1.0;
                y[j] = 1.0;
                assert_eq!(quadratic_form(&m, &x, &y), m[i][j]);
            }
        }
        let (x, y) = (
            [1.0, -2.0, 0.5, 3.0, -0.25, 1.5],
            [0.3, 1.0, -1.0, 2.0, 0.0, -0.7],
        );
        let naive: f64 = (0..6)
            .flat_map(|i| (0..6).map(move |j| (i, j)))
            .map(|(i, j)| x[i] * m[i][j] * y[j])
            .sum();
        let scale: f64 = (0..6)
            .flat_map(|i| (0..6).map(move |j| (i, j)))
            .map(|(i, j)| (x[i] * m[i][j] * y[j]).abs())
            .sum();
        assert!((quadratic_form(&m, &x, &y) - naive).abs() <= 1e-14 * scale);
    }

    /// With the last three entries of both vectors zero (a rigid block's strains), the
    /// rigid form is the full form to the bit.
    #[test]
    fn the_rigid_form_is_the_full_form_without_strains() {
        let m = spd();
        let (x, y) = (
            [1.0, -2.0, 0.5, 0.0, 0.0, 0.0],
            [0.3, 1.0, -1.0, 0.0, 0.0, 0.0],
        );
        assert_eq!(
            quadratic_form_rigid(&m, &x, &y).to_bits(),
            quadratic_form(&m, &x, &y).to_bits()
        );
        assert_eq!(
            quadratic_form_rigid(&m, &x, &x).to_bits(),
            quadratic_form(&m, &x, &x).to_bits()
        );
    }

    #[test]
    fn the_factor_solves_the_system() {
        let m = spd();
        let r = [1.0, 2.0, 3.0, -1.0, 0.5, 0.0];
        let x = solve_spd(&m, &r).expect("positive definite");
        for i in 0..6 {
            let mx: f64 = (0..6).map(|j| m[i][j] * x[j]).sum();
            assert!(
                (mx - r[i]).abs() < 1e-13 * 3.0,
                "row {i}: {mx} against {}",
                r[i]
            );
        }
    }

    #[test]
    fn an_indefinite_or_nan_matrix_is_refused() {
        let mut m = spd();
        m[2][2] = -1.0;
        assert!(solve_spd(&m, &[0.0; 6]).is_none());
        let mut m = spd();
        m[4][4] = f64::NAN;
        assert!(solve_spd(&m, &[0.0; 6]).is_none());
    }

    #[test]
    fn the_factor_times_its_transpose_is_the_matrix() {
        let m = spd();
        let mut l = m;
        let mut inverse = [0.0; 6];
        cholesky(&mut l, &mut inverse).expect("positive definite");
        let mut llt = [[0.0; 6]; 6];
        subtract_product_transposed(&mut llt, &l, &l);
        for r in 0..6 {
            for c in 0..6 {
                assert!((-llt[r][c] - m[r][c]).abs() < 1e-13 * 10.0);
            }
        }
    }
}
