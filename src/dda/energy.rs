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
    /// Energy dissipated by the structure's own damping (the bolts' dashpots).
    pub structural_damping: f64,
    /// Energy lost in impacts: contacts that close are taken as plastic impacts (the
    /// hitting vertex's approach velocity is removed within the step), and the energy the
    /// impact steps remove is counted here rather than as numerical dissipation.
    pub impact_dissipated: f64,
    /// What the time integrator dissipated (positive) or created (negative), computed
    /// from its own states (see `Dda::commit_step`; zero for the trapezoidal rule), and
    /// the work of the exact constraints on the gaps and slips they close (the geometry update's
    /// departure from the linear step, a landing's leftover gap, the augmented
    /// Lagrangian's penetration; see `Dda::commit_step`).
    pub numerical_dissipated: f64,
}

impl EnergyTerms {
    /// What the balance does not account for: the input and external work less every
    /// energy stored and dissipated, the integrator's dissipation included. Zero to
    /// round-off for a model whose terms are all consistent; the rest is the model's
    /// inconsistency (geometric nonlinearity, unconverged constraints).
    pub fn residual(&self) -> f64 {
        self.input_work + self.external_work
            - self.kinetic
            - self.strain
            - self.friction_dissipated
            - self.contact_damping
            - self.structural_damping
            - self.impact_dissipated
            - self.numerical_dissipated
    }

    /// The energy that has passed through now: the larger of the works done and of what
    /// is stored and dissipated.
    pub fn scale(&self) -> f64 {
        self.input_work.abs().max(self.external_work.abs()).max(
            self.kinetic
                + self.strain.abs()
                + self.friction_dissipated.abs()
                + self.contact_damping.abs()
                + self.structural_damping.abs()
                + self.impact_dissipated.abs()
                + self.numerical_dissipated.abs(),
        )
    }
}
