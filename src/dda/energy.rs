//! Energy bookkeeping: where the earthquake's work goes.

use serde::Serialize;

/// Cumulative energy terms of the structure (all blocks but the ground, plus every spring
/// that touches them), J per unit thickness, measured from the reference state (after
/// initial equilibrium).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EnergyTerms {
    /// Work done on the structure by the ground through contacts and joints.
    pub input_work: f64,
    /// Work of gravity and point loads on the structure.
    pub external_work: f64,
    /// Kinetic energy now.
    pub kinetic: f64,
    /// Elastic energy now, relative to the reference state: blocks, connection elements,
    /// bolts, supports and contact penalty springs.
    pub strain: f64,
    /// Energy dissipated by Coulomb friction (including the shear-spring energy released
    /// when a stuck contact starts to slide).
    pub friction_dissipated: f64,
    /// Energy dissipated by the contact dashpots (relative motion across closed joints).
    pub contact_damping: f64,
    /// Energy lost in impacts: contacts that close are taken as plastic impacts (the
    /// hitting vertex's approach velocity is removed within the step), and the energy the
    /// impact steps remove is counted here rather than as numerical dissipation.
    pub impact_dissipated: f64,
}

impl EnergyTerms {
    /// Numerical dissipation: what the integrator lost (positive) or created (negative).
    /// Zero to round-off for the trapezoidal rule on a linear problem.
    pub fn residual(&self) -> f64 {
        self.input_work + self.external_work
            - self.kinetic
            - self.strain
            - self.friction_dissipated
            - self.contact_damping
            - self.impact_dissipated
    }

    /// Residual relative to the energy that passed through the system.
    pub fn residual_relative(&self) -> f64 {
        let scale = self.input_work.abs().max(self.external_work.abs()).max(
            self.kinetic
                + self.strain.abs()
                + self.friction_dissipated
                + self.contact_damping
                + self.impact_dissipated,
        );
        if scale > 0.0 {
            self.residual() / scale
        } else {
            0.0
        }
    }
}
