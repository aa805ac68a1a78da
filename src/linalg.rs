//! Small dense linear algebra shared by the solvers.

use nalgebra::DMatrix;

use crate::{Error, Result};

/// M-orthonormal modes of (M, K).
pub struct Modal {
    /// Columns are the mode shapes (Φᵀ M Φ = I).
    pub phi: DMatrix<f64>,
    /// Circular frequencies (0 for rigid modes), ascending.
    pub omega: Vec<f64>,
}

/// Solves K φ = ω² M φ for symmetric positive definite M and positive semi-definite K.
pub fn modal(m: &DMatrix<f64>, k: &DMatrix<f64>) -> Result<Modal> {
    let chol = m
        .clone()
        .cholesky()
        .ok_or_else(|| Error::invalid("mass matrix", "is not positive definite"))?;
    let l = chol.l();
    let l_inv = l
        .clone()
        .try_inverse()
        .ok_or_else(|| Error::invalid("mass matrix", "is singular"))?;
    let a = &l_inv * k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = a.symmetric_eigen();
    let n = m.nrows();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let lam_max = eig
        .eigenvalues
        .iter()
        .fold(0.0_f64, |acc, &v| acc.max(v.abs()));
    let mut phi = DMatrix::zeros(n, n);
    let mut omega = Vec::with_capacity(n);
    let lt_inv = l_inv.transpose();
    for (col, &i) in order.iter().enumerate() {
        let lam = eig.eigenvalues[i];
        // Rigid-body modes come out as ±1e-16·λmax: they are exactly zero.
        omega.push(if lam <= 1e-12 * lam_max {
            0.0
        } else {
            lam.sqrt()
        });
        let v = &lt_inv * eig.eigenvectors.column(i);
        phi.set_column(col, &v);
    }
    Ok(Modal { phi, omega })
}
