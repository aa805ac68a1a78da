//! Solver parameters, with defaults that say why they are what they are.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The four coefficients of the generalised-α family.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaCoefficients {
    /// Weight of the old acceleration in the inertia term.
    pub alpha_m: f64,
    /// Weight of the old state in the force terms.
    pub alpha_f: f64,
    /// Newmark β.
    pub beta: f64,
    /// Newmark γ.
    pub gamma: f64,
}

impl Integrator {
    /// The scheme's coefficients.
    pub fn coefficients(&self) -> AlphaCoefficients {
        match *self {
            Integrator::Classic => AlphaCoefficients {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta: 0.5,
                gamma: 1.0,
            },
            Integrator::Trapezoidal => AlphaCoefficients {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta: 0.25,
                gamma: 0.5,
            },
            Integrator::Hht { alpha } => AlphaCoefficients {
                alpha_m: 0.0,
                alpha_f: alpha,
                beta: (1.0 + alpha) * (1.0 + alpha) / 4.0,
                gamma: 0.5 + alpha,
            },
            Integrator::GeneralizedAlpha { rho_inf } => {
                let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
                let alpha_f = rho_inf / (rho_inf + 1.0);
                let gamma = 0.5 - alpha_m + alpha_f;
                AlphaCoefficients {
                    alpha_m,
                    alpha_f,
                    beta: 0.25 * (1.0 - alpha_m + alpha_f).powi(2),
                    gamma,
                }
            }
        }
    }
}

pub use crate::model::enforcement::ContactEnforcement;
pub use crate::model::integration::Integrator;

/// Everything that controls the DDA solver (not the physics of the scene).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverParams {
    /// Time step Δt, s. 1 ms is the paper's step: ≥ 100 steps per period up to 10 Hz.
    pub dt: f64,
    /// Simulated duration, s.
    pub duration: f64,
    /// Time integration scheme.
    pub integrator: Integrator,
    /// Open-close passes per step before Δt is cut. Shi's DDA uses 6 (+2 spare); the
    /// paper's models settle in 1–5. A wall under strong shaking needs more: its bed
    /// joints change between stuck and sliding one after another, and in the last quarter
    /// of the passes those changes are held so that the friction forces settle on them
    /// (wall:20 on Kobe, 9 s: 141 Δt cuts with 8 passes, 9 with 16, and fewer passes in
    /// all, since a cut throws its attempt's passes away). The static settle takes at most
    /// 8 (see `SETTLE_PASSES`).
    pub max_open_close_passes: usize,
    /// Factor by which Δt is cut when the open-close iteration does not settle.
    pub cut_factor: f64,
    /// Smallest Δt as a fraction of the nominal one before the solver gives up with an error.
    pub min_dt_fraction: f64,
    /// Largest displacement of any vertex relative to the ground in one step, as a
    /// fraction of the structure's size (DDA's "maximum displacement ratio"). Larger steps
    /// are cut because the linearised contact geometry stops being valid.
    pub max_displacement_ratio: f64,
    /// Begin from static equilibrium under gravity (no start-up bounce on the penalty
    /// springs, as in a building that has been standing before the earthquake).
    pub initial_equilibrium: bool,
    /// Shorten a step to land on a contact event (stick→slip, slip→stick, impact) found
    /// inside it, so that transitions are not delayed to the step end (O(Δt) → O(Δt²)).
    pub locate_events: bool,
    /// Restart the integrator at a landed contact event: the classic scheme after a
    /// stick-slip event (removes the O(1) misjudgement of stick vs. reversal at the event),
    /// backward Euler at an impact (a plastic impact, restitution 0, instead of the
    /// elastic or energy-gaining bounce of the penalty spring). See `Dda::step`.
    pub restart_after_events: bool,
    /// Damping ratio ζ of dashpots in parallel with the closed contacts' normal and (when
    /// stuck) shear penalty springs, relative to critical for half the lighter block on the
    /// spring. They act only on the relative motion across a joint (≈ 0 while stuck), so they
    /// do not damp the structure, but they stop the penalty springs ringing when a sliding
    /// joint re-sticks — which otherwise inflates peak accelerations.
    pub contact_damping: f64,
    /// Update vertices with the exact rotation (cos r − 1, sin r) instead of the linear
    /// map, which inflates areas by (1 + r²) per step under rotation.
    pub exact_rotation: bool,
    /// How closed contacts carry their forces.
    pub contact_enforcement: ContactEnforcement,
    /// Augmented Lagrangian: iterate until every closed contact's constraint violation,
    /// times its penalty, is below this fraction of the largest contact force.
    pub constraint_tolerance: f64,
}

impl SolverParams {
    /// The defaults, with the contact enforcement and the integrator the scene asks for
    /// (if it does).
    pub fn for_scene(scene: &crate::model::Scene) -> Self {
        let defaults = Self::default();
        Self {
            contact_enforcement: scene
                .contact_enforcement
                .unwrap_or(defaults.contact_enforcement),
            integrator: scene.integrator.unwrap_or(defaults.integrator),
            ..defaults
        }
    }
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            dt: 1e-3,
            duration: 10.0,
            integrator: Integrator::default(),
            max_open_close_passes: 16,
            cut_factor: 0.3,
            // Below 1e-4·Δt the problem is not one a smaller step will fix.
            min_dt_fraction: 1e-4,
            max_displacement_ratio: 0.01,
            initial_equilibrium: true,
            locate_events: true,
            restart_after_events: true,
            contact_damping: 0.0,
            exact_rotation: true,
            contact_enforcement: ContactEnforcement::default(),
            constraint_tolerance: 1e-10,
        }
    }
}

impl SolverParams {
    /// Checks ranges; errors name the field.
    pub fn validate(&self) -> Result<()> {
        crate::error::require_positive("dt", self.dt)?;
        crate::error::require_positive("duration", self.duration)?;
        self.integrator.validate()?;
        if self.max_open_close_passes < 2 {
            return Err(Error::invalid(
                "max_open_close_passes",
                "must be at least 2",
            ));
        }
        if !(self.cut_factor > 0.0 && self.cut_factor < 1.0) {
            return Err(Error::invalid(
                "cut_factor",
                format!("must be in (0, 1), got {}", self.cut_factor),
            ));
        }
        if !(self.min_dt_fraction > 0.0 && self.min_dt_fraction <= 1.0) {
            return Err(Error::invalid("min_dt_fraction", "must be in (0, 1]"));
        }
        crate::error::require_positive("max_displacement_ratio", self.max_displacement_ratio)?;
        crate::error::require_non_negative("contact_damping", self.contact_damping)?;
        // Below ~100 ulps the multipliers cannot settle to it; above a tenth the contacts
        // would leak a tenth of their force.
        if !(self.constraint_tolerance >= 1e-14 && self.constraint_tolerance <= 0.1) {
            return Err(Error::invalid(
                "constraint_tolerance",
                format!("must be in [1e-14, 0.1], got {}", self.constraint_tolerance),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generalized_alpha_limits() {
        // ρ∞ = 1 is the trapezoidal rule.
        let c = Integrator::GeneralizedAlpha { rho_inf: 1.0 }.coefficients();
        assert!((c.alpha_m - 0.5).abs() < 1e-15 && (c.alpha_f - 0.5).abs() < 1e-15);
        assert!((c.gamma - 0.5).abs() < 1e-15 && (c.beta - 0.25).abs() < 1e-15);
        // Second order requires γ = ½ − αm + αf.
        for rho in [0.0, 0.3, 0.8] {
            let c = Integrator::GeneralizedAlpha { rho_inf: rho }.coefficients();
            assert!((c.gamma - (0.5 - c.alpha_m + c.alpha_f)).abs() < 1e-15);
        }
    }
}
