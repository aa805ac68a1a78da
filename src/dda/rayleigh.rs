//! Rayleigh damping of a structure: C = a₀·M + a₁·K.
//!
//! A building's structural damping is the classical Rayleigh form, with the ratio ζ at two
//! natural frequencies of its fixed-base frame (the first two sway modes). On a sliding
//! base two details matter, and both keep the sliding itself undamped (the "damping
//! leakage" that OpenSees' documentation warns about):
//!
//! - the mass-proportional part acts on each structural block's velocity *relative to the
//!   base slab* (a dashpot a₀·m from the block's centroid to the base slab's material point
//!   there, in x and y), and its reaction is on the base slab, so the damping forces are
//!   internal to the structure;
//! - the stiffness-proportional part acts on the blocks' strain rates and the connection
//!   elements' node velocities through their elastic stiffness, which a rigid motion of
//!   the whole structure does not strain.
//!
//! The solver's side is in `solver/damping.rs`.

use crate::{Error, Result};

/// Coefficients of Rayleigh damping, C = a₀·M + a₁·K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayleighDamping {
    /// a₀, 1/s: the mass-proportional part (relative to the base slab).
    pub mass_coefficient: f64,
    /// a₁, s: the stiffness-proportional part (blocks' elasticity and connections).
    pub stiffness_coefficient: f64,
}

impl RayleighDamping {
    /// The coefficients that give the damping ratio `zeta` at the two circular
    /// frequencies `omega1` ≤ `omega2` (rad/s): a₀ = 2ζω₁ω₂/(ω₁ + ω₂), a₁ = 2ζ/(ω₁ + ω₂)
    /// (for ω₁ = ω₂ = ω: a₀ = ζω, a₁ = ζ/ω, ζ at ω and above it elsewhere).
    /// Between them the ratio is a little less than ζ, above ω₂ it grows with ω (the
    /// high modes are damped more), below ω₁ it grows as 1/ω.
    pub fn from_two_modes(zeta: f64, omega1: f64, omega2: f64) -> Result<Self> {
        if !(zeta.is_finite() && zeta >= 0.0) {
            return Err(Error::invalid(
                "damping ratio",
                format!("{zeta} is not a damping ratio (0 or more)"),
            ));
        }
        if !(omega1.is_finite() && omega1 > 0.0 && omega2.is_finite() && omega2 >= omega1) {
            return Err(Error::invalid(
                "Rayleigh damping",
                format!(
                    "needs two positive natural frequencies ω₁ ≤ ω₂, got ω₁ = {omega1} and \
                     ω₂ = {omega2} rad/s"
                ),
            ));
        }
        let sum = omega1 + omega2;
        Ok(Self {
            mass_coefficient: 2.0 * zeta * omega1 * omega2 / sum,
            stiffness_coefficient: 2.0 * zeta / sum,
        })
    }

    /// The damping ratio these coefficients give a mode of circular frequency `omega`:
    /// ζ(ω) = a₀/(2ω) + a₁ω/2.
    pub fn ratio_at(&self, omega: f64) -> f64 {
        self.mass_coefficient / (2.0 * omega) + self.stiffness_coefficient * omega / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coefficients reproduce ζ at both frequencies, and less between them.
    #[test]
    fn the_ratio_is_zeta_at_both_frequencies() {
        let (w1, w2) = (4.0, 11.2);
        let r = RayleighDamping::from_two_modes(0.05, w1, w2).unwrap();
        assert!((r.ratio_at(w1) - 0.05).abs() < 1e-15);
        assert!((r.ratio_at(w2) - 0.05).abs() < 1e-15);
        assert!(r.ratio_at((w1 * w2).sqrt()) < 0.05);
        assert!(r.ratio_at(3.0 * w2) > 0.05);
    }

    #[test]
    fn bad_frequencies_are_refused() {
        assert!(RayleighDamping::from_two_modes(0.05, 4.0, 3.0).is_err());
        assert!(RayleighDamping::from_two_modes(0.05, f64::NAN, 4.0).is_err());
        assert!(RayleighDamping::from_two_modes(-0.1, 1.0, 4.0).is_err());
    }
}
