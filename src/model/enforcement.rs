//! How closed contacts carry their forces: penalty springs or exact constraints.
//!
//! A property of the contact model as much as of the solver: a scene of many
//! dry-stacked blocks names the enforcement its joints need (see [`crate::model::Scene`]).

use serde::{Deserialize, Serialize};

/// How closed contacts carry their forces.
///
/// The default is the augmented Lagrangian: a stuck joint is exactly stuck, so the
/// re-stick of the raft does not ring (with penalty springs a_base/a_g is +31 % at
/// Δt = 1e-4 with the trapezoidal rule; test
/// `augmented_lagrangian_contacts_do_not_ring_at_fine_steps`). The penalty method is kept
/// for comparison with Shi's DDA and with codes that use it (OpenSees' flat slider).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ContactEnforcement {
    /// Shi's penalty springs: a closed contact is a stiff spring, so a stuck joint is an
    /// oscillator (kHz) whose ringing at every re-stick equals the jump of the acceleration.
    Penalty,
    /// Augmented Lagrangian: the penalty springs only regularise the solve; multipliers
    /// carry the contact forces, iterated until the constraint (no penetration, no slip
    /// while stuck) holds to [`crate::dda::SolverParams::constraint_tolerance`]. A stuck
    /// joint is then exactly stuck.
    #[default]
    AugmentedLagrangian,
}
