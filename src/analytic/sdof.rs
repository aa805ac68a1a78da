//! Closed forms of the undamped single-degree-of-freedom oscillator.

/// Displacement and velocity of `ü + ω² u = −A sin(Ω t)` from rest at time `t`,
/// including resonance (Ω = ω). This is the fixed-base (ρ → ∞) two-mass response u_r.
pub fn sdof_harmonic_from_rest(omega: f64, amplitude: f64, big_omega: f64, t: f64) -> (f64, f64) {
    let (w, p, a) = (omega, big_omega, amplitude);
    if ((w - p) / w).abs() < 1e-9 {
        // Resonance: u = A/(2ω²) (ω t cos ωt − sin ωt).
        let (s, c) = (w * t).sin_cos();
        let u = a / (2.0 * w * w) * (w * t * c - s);
        let v = -a / 2.0 * t * s;
        return (u, v);
    }
    let factor = -a / (w * w - p * p);
    let u = factor * ((p * t).sin() - p / w * (w * t).sin());
    let v = factor * (p * (p * t).cos() - p * (w * t).cos());
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn satisfies_the_equation_of_motion() {
        for &(w, p) in &[(6.3, 3.1), (6.3, 6.3), (2.0, 20.0)] {
            let a = 2.9;
            for &t in &[0.3, 1.7, 9.1] {
                let e = 1e-4;
                let (u, _) = sdof_harmonic_from_rest(w, a, p, t);
                let (um, _) = sdof_harmonic_from_rest(w, a, p, t - e);
                let (up, _) = sdof_harmonic_from_rest(w, a, p, t + e);
                let acc = (up - 2.0 * u + um) / (e * e);
                let residual = acc + w * w * u + a * (p * t).sin();
                assert!(
                    residual.abs() < 1e-5 * a.max(w * w * u.abs()),
                    "w={w} p={p} t={t}: {residual}"
                );
                let (_, v) = sdof_harmonic_from_rest(w, a, p, t);
                assert!((v - (up - um) / (2.0 * e)).abs() < 1e-6 * (1.0 + v.abs()));
            }
        }
    }
}
