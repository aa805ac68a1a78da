//! The paper's mass-spring sliding models, solved exactly.
//!
//! A shear building of N storeys (masses m_i, storey stiffnesses k_i) stands on a raft of
//! mass M_b that rests on the ground with Coulomb friction ρ (Appendix I of the paper for
//! N = 1; Yang et al. 1990 for N > 1). Between switching events the motion is linear and
//! undamped, so it is propagated exactly (modal decomposition, homogeneous part in closed
//! form, forced part by Gauss–Legendre quadrature of the Duhamel integral over short steps
//! on which the forcing is smooth), and the stick/slip switching times are found by root
//! finding. This is the reference the DDA model is validated against.
//!
//! The sliding block (`block` scene) has its own exact solution with any friction law and
//! vertical shaking ([`simulate_block`]).

mod exact;
mod sdof;
mod sliding_block;
mod stepped;

pub use exact::{EnergyBalance, ExactOptions, ExactResult, Peaks, Phase, PhaseEvent, simulate};
pub use sdof::sdof_harmonic_from_rest;
pub use sliding_block::{SlidingBlock, simulate_block};
pub use stepped::{
    SlidingStructure, SteppedEnergy, SteppedOptions, SteppedResult, Surface, simulate_stepped,
};

use crate::ground_motion::STANDARD_GRAVITY;
use crate::{Error, Result};

/// A shear building on a sliding raft.
#[derive(Debug, Clone, PartialEq)]
pub struct ShearBuilding {
    /// Storey masses m_1..m_N, bottom to top, kg.
    pub storey_masses: Vec<f64>,
    /// Storey stiffnesses k_1..k_N (k_1 joins storey 1 to the raft), N/m.
    pub storey_stiffnesses: Vec<f64>,
    /// Raft mass M_b, kg.
    pub raft_mass: f64,
    /// Coulomb coefficient ρ (static = kinetic); `f64::INFINITY` for a fixed base.
    pub friction: f64,
    /// Gravity, m/s².
    pub gravity: f64,
}

impl ShearBuilding {
    /// The paper's two-mass model with total mass 1: roof m = α, raft M = 1 − α, and
    /// k = m ω² for the fixed-base frequency `structure_freq_hz`.
    pub fn two_mass(alpha: f64, structure_freq_hz: f64, friction: f64) -> Result<Self> {
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::invalid(
                "alpha",
                format!("must be in (0, 1), got {alpha}"),
            ));
        }
        crate::error::require_positive("structure frequency", structure_freq_hz)?;
        let omega = 2.0 * std::f64::consts::PI * structure_freq_hz;
        let b = Self {
            storey_masses: vec![alpha],
            storey_stiffnesses: vec![alpha * omega * omega],
            raft_mass: 1.0 - alpha,
            friction,
            gravity: STANDARD_GRAVITY,
        };
        b.validate()?;
        Ok(b)
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        if self.storey_masses.is_empty()
            || self.storey_masses.len() != self.storey_stiffnesses.len()
        {
            return Err(Error::invalid(
                "storeys",
                "need at least one storey and one stiffness per storey mass",
            ));
        }
        for (i, (&m, &k)) in self
            .storey_masses
            .iter()
            .zip(&self.storey_stiffnesses)
            .enumerate()
        {
            crate::error::require_positive(&format!("storey {} mass", i + 1), m)?;
            crate::error::require_positive(&format!("storey {} stiffness", i + 1), k)?;
        }
        crate::error::require_positive("raft mass", self.raft_mass)?;
        if self.friction.is_nan() || self.friction < 0.0 {
            return Err(Error::invalid(
                "friction",
                format!("must be >= 0, got {}", self.friction),
            ));
        }
        crate::error::require_non_negative("gravity", self.gravity)?;
        Ok(())
    }

    /// Total weight (M_b + Σm) g, N.
    pub fn weight(&self) -> f64 {
        (self.raft_mass + self.storey_masses.iter().sum::<f64>()) * self.gravity
    }

    /// This building as a [`SlidingStructure`] for the stepped solution: the joint's law
    /// `friction` instead of its Coulomb coefficient, the storeys' damping matrix
    /// `damping` (zeros: undamped), and the ground motions.
    pub fn sliding_structure<'a>(
        &self,
        friction: crate::model::friction::Friction,
        damping: nalgebra::DMatrix<f64>,
        horizontal: &'a crate::ground_motion::GroundMotion,
        vertical: Option<&'a crate::ground_motion::GroundMotion>,
    ) -> SlidingStructure<'a> {
        let (_, stiffness) = exact::stick_matrices(self);
        SlidingStructure {
            raft_mass: self.raft_mass,
            storey_masses: self.storey_masses.clone(),
            stiffness,
            damping,
            friction,
            gravity: self.gravity,
            horizontal,
            vertical,
            surface: Surface::Flat,
        }
    }

    /// The Rayleigh damping matrix C = a₀M + a₁K of the storeys (on their displacements
    /// relative to the raft, so the sliding is not damped), with ratio `zeta` at the first
    /// two fixed-base modes (at the only one of a single storey: a₀ = ζω, a₁ = ζ/ω), the
    /// same rule as the DDA frame's ([`crate::dda::RayleighDamping`]).
    pub fn rayleigh_damping(&self, zeta: f64) -> Result<nalgebra::DMatrix<f64>> {
        let omega: Vec<f64> = self
            .fixed_base_frequencies_hz()
            .iter()
            .map(|f| 2.0 * std::f64::consts::PI * f)
            .collect();
        let (w1, w2) = match omega.as_slice() {
            [w] => (*w, *w),
            [w1, w2, ..] => (*w1, *w2),
            [] => {
                return Err(Error::invalid(
                    "--damping",
                    "the shear building has no natural frequency to damp",
                ));
            }
        };
        let r = crate::dda::RayleighDamping::from_two_modes(zeta, w1, w2)?;
        let (m, k) = exact::stick_matrices(self);
        Ok(m * r.mass_coefficient + k * r.stiffness_coefficient)
    }

    /// Fixed-base natural frequencies, Hz, ascending.
    pub fn fixed_base_frequencies_hz(&self) -> Vec<f64> {
        let (m, k) = exact::stick_matrices(self);
        exact::modal(&m, &k)
            .map(|modes| {
                modes
                    .omega
                    .iter()
                    .map(|w| w / (2.0 * std::f64::consts::PI))
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// The paper's normalised peak responses of a two-mass run under harmonic input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperMetrics {
    /// max|u_s| / D, D = a_max/Ω².
    pub us_max_over_d: f64,
    /// max|u_r| / D.
    pub ur_max_over_d: f64,
    /// max|a_base| / a_max (absolute).
    pub abase_over_aground: f64,
    /// max|a_roof| / a_max (absolute).
    pub aroof_over_aground: f64,
}

/// Normalises the peaks as the paper does (D = a_max/Ω²).
pub fn paper_metrics(result: &ExactResult, ground_amplitude: f64, big_omega: f64) -> PaperMetrics {
    let d = ground_amplitude / (big_omega * big_omega);
    PaperMetrics {
        us_max_over_d: result.peaks.slip / d,
        ur_max_over_d: result.peaks.roof_drift / d,
        abase_over_aground: result.peaks.raft_accel / ground_amplitude,
        aroof_over_aground: result.peaks.roof_accel / ground_amplitude,
    }
}
