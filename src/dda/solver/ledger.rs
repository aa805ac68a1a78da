//! The energy ledger: stored and kinetic energy, the reference state, one definition of the residual.

use super::*;

impl Dda {
    /// Makes the current state the reference: displacements and energies count from here.
    pub(super) fn reset_reference(&mut self) {
        self.forget_next_step_detection();
        for b in &mut self.blocks {
            b.reference_centroid = b.moments.centroid;
            b.rotation = 0.0;
            b.velocity = [0.0; 6];
            b.accel = [0.0; 6];
            b.response_accel = [0.0; 6];
        }
        self.energy = EnergyTerms::default();
        self.stored_reference = self.stored_energy();
        self.energy_scale = 0.0;
    }

    /// Elastic energy stored in blocks, joints and contact springs of the structure.
    pub(super) fn stored_energy(&self) -> f64 {
        let mut e = 0.0;
        for (bi, b) in self.blocks.iter().enumerate() {
            if self.is_structure(bi) {
                e += b.strain_energy();
            }
        }
        for b in &self.bolts {
            if b.blocks.iter().any(|&k| self.is_structure(k)) {
                e += b.energy();
            }
        }
        for f in &self.fixed {
            if self.is_structure(f.block) {
                e += f.energy();
            }
        }
        for c in &self.connections {
            if c.blocks.iter().any(|&k| self.is_structure(k)) {
                e += c.energy();
            }
        }
        // The memory holds exactly the contacts of the last step.
        for c in &self.contacts {
            let Some((_, m)) = self.memory.get_near(&c.key, c.memory_hint()) else {
                continue;
            };
            if !m.state.is_closed() {
                continue;
            }
            let p = c.props;
            if !self.augmented() {
                e += 0.5 * m.normal_force * m.normal_force / p.normal_penalty;
            }
            e += 0.5 * p.shear_penalty * m.shear * m.shear;
        }
        e
    }

    /// Kinetic energy of every block that moves in the model's frame.
    pub(super) fn kinetic_energy(&self) -> f64 {
        self.blocks
            .iter()
            .filter(|b| b.role != BlockRole::PrescribedGround)
            .map(Block::kinetic_energy)
            .sum()
    }

    /// Relative energy residual now: the residual over the largest energy that has passed
    /// through the model, or over a floor of 1e-12 of its weight times its size when
    /// nothing has (a model that never moves has no relative error to report).
    pub fn energy_residual_relative(&self) -> f64 {
        let weight: f64 = self
            .blocks
            .iter()
            .filter(|b| b.role != BlockRole::PrescribedGround)
            .map(|b| b.total_mass())
            .sum::<f64>()
            * self.gravity.max(1.0);
        let floor = 1e-12 * weight * self.structure_size;
        self.energy.residual() / self.energy_scale.max(floor)
    }
}
