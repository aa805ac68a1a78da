//! The friction side of the contact law: the two questions the solver asks of a joint's
//! friction, behind a trait so that the judge, the assembly, the event resolution and the
//! energy ledger never look at a law's parameters.
//!
//! The open-close judge compares a stuck contact's tangential force with the sticking
//! coefficient times N; a sliding contact carries the sliding coefficient at its slip speed
//! times N, evaluated at the integrator's α point and iterated within the step like the
//! normal force it multiplies (dda-theory §6).

use crate::model::friction::Friction;

/// A friction law as the solver sees it.
pub trait FrictionLaw {
    /// Coefficient of the largest tangential force a stuck contact holds, per unit normal
    /// force (+∞: never slides; 0: always slides).
    fn sticking_coefficient(&self) -> f64;

    /// Coefficient of the friction force of a contact slipping at `slip_speed` (m/s, either
    /// sign), per unit normal force; finite.
    fn sliding_coefficient(&self, slip_speed: f64) -> f64;

    /// Whether the sliding coefficient changes with the slip speed (the open-close
    /// iteration then also waits for it to settle).
    fn depends_on_speed(&self) -> bool;
}

impl FrictionLaw for Friction {
    fn sticking_coefficient(&self) -> f64 {
        self.sticking()
    }

    fn sliding_coefficient(&self, slip_speed: f64) -> f64 {
        self.sliding(slip_speed)
    }

    fn depends_on_speed(&self) -> bool {
        Friction::depends_on_speed(self)
    }
}
