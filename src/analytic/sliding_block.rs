//! Newmark's sliding block, solved exactly: a rigid block resting on a ground that shakes
//! horizontally (and, optionally, vertically), held by a friction law.
//!
//! In the ground's frame the block's slip s (block relative to ground, +x) obeys
//!
//! ```text
//! stuck:    s' = 0           while |a_g(t)| ≤ μ_s·N(t)
//! slipping: s'' = −a_g(t) − μ(|s'|)·N(t)·d,   d = sign(s') (constant within a slip phase)
//! ```
//!
//! with N(t) = g + a_v(t) the normal force per unit mass (a_v the vertical ground
//! acceleration, up positive): the sliding structure of [`super::stepped`] without
//! storeys. Its steps end on every kink of the inputs (record samples), so that within a
//! step a_g and N are linear; there the classical fourth-order Runge–Kutta step is exact
//! for the constant-coefficient laws (Coulomb, static-kinetic: s'' is then linear in t, s
//! a cubic) and converged to rounding for the velocity law, whose steps are also kept
//! short against its rate. This is the reference `--model mass-spring` reports for the
//! `block` scene.

use nalgebra::DMatrix;

use super::stepped::{SlidingStructure, SteppedOptions, SteppedResult, Surface, simulate_stepped};
use crate::Result;
use crate::ground_motion::GroundMotion;
use crate::model::friction::Friction;

/// The sliding block's inputs: its friction law, gravity and the ground motion.
#[derive(Debug, Clone)]
pub struct SlidingBlock<'a> {
    /// Friction law of the interface.
    pub friction: Friction,
    /// Gravity, m/s².
    pub gravity: f64,
    /// Horizontal ground acceleration.
    pub horizontal: &'a GroundMotion,
    /// Vertical ground acceleration (up positive), if the ground also shakes vertically.
    pub vertical: Option<&'a GroundMotion>,
    /// The surface it slides on: flat, or a friction pendulum's dish.
    pub surface: Surface,
}

impl<'a> SlidingBlock<'a> {
    /// The block as a sliding structure of unit mass without storeys (energies per kg).
    pub fn structure(&self) -> SlidingStructure<'a> {
        SlidingStructure {
            raft_mass: 1.0,
            storey_masses: Vec::new(),
            stiffness: DMatrix::zeros(0, 0),
            damping: DMatrix::zeros(0, 0),
            friction: self.friction,
            gravity: self.gravity,
            horizontal: self.horizontal,
            vertical: self.vertical,
            surface: self.surface,
        }
    }

    /// About how many steps the solution over `duration` takes (for the run-size check).
    pub fn steps(&self, duration: f64, options: &SteppedOptions) -> f64 {
        self.structure().steps(duration, options)
    }
}

/// Solves the sliding block from rest over `[0, duration]`, with output every
/// `output_dt` seconds (0: peaks only); energies per kg.
///
/// Errors: a normal force that reaches zero (the vertical motion lifts the block off the
/// ground; the message gives the time), or a run beyond [`SteppedOptions::max_steps`].
pub fn simulate_block(
    block: &SlidingBlock,
    duration: f64,
    output_dt: f64,
    options: &SteppedOptions,
) -> Result<SteppedResult> {
    simulate_stepped(&block.structure(), duration, output_dt, options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ground_motion::Harmonic;

    fn harmonic(amplitude_g: f64, hz: f64) -> GroundMotion {
        GroundMotion::Harmonic(Harmonic::from_g_hz(amplitude_g, hz).unwrap())
    }

    fn solve(friction: Friction, motion: &GroundMotion, duration: f64) -> SteppedResult {
        let block = SlidingBlock {
            friction,
            gravity: 9.81,
            horizontal: motion,
            vertical: None,
            surface: Surface::Flat,
        };
        simulate_block(&block, duration, 0.0, &SteppedOptions::default()).unwrap()
    }

    /// Below the sticking limit the block moves with the ground.
    #[test]
    fn a_weak_shake_never_moves_the_block() {
        let m = harmonic(0.1, 1.0);
        let r = solve(Friction::Coulomb(0.2), &m, 5.0);
        assert_eq!(r.max_slip, 0.0);
        assert!((r.peak_raft_accel - 0.1 * 9.80665).abs() < 1e-3);
    }

    /// Frictionless: the block stays where it was in space, so s = −u_g exactly.
    #[test]
    fn a_frictionless_block_stays_put_in_space() {
        let m = harmonic(0.3, 1.0);
        let r = solve(Friction::Coulomb(0.0), &m, 3.0);
        assert!((r.residual_slip + m.displacement(3.0)).abs() < 1e-9);
        assert!(r.peak_raft_accel < 1e-9);
    }

    /// A constant ground acceleration a > μg from rest: the block slips with
    /// s'' = −(a − μg), so s = −½(a − μg)t², and dissipates μg·|s|.
    #[test]
    fn a_constant_pull_gives_the_closed_form() {
        let record = crate::ground_motion::Record::new("step", 0.01, vec![3.0; 201]).unwrap();
        let m = GroundMotion::Record(std::sync::Arc::new(record));
        let mu = 0.2;
        let r = solve(Friction::Coulomb(mu), &m, 1.5);
        let expected = -0.5 * (3.0 - mu * 9.81) * 1.5 * 1.5;
        assert!((r.residual_slip - expected).abs() < 1e-12 * expected.abs().max(1.0));
        assert!((r.energy.friction_dissipated - mu * 9.81 * expected.abs()).abs() < 1e-9);
        assert!(r.energy.residual.abs() < 1e-12 * r.energy.input_work.abs());
    }

    /// Halving the step changes the slip of every law by rounding only.
    #[test]
    fn the_solution_does_not_depend_on_the_step() {
        let m = harmonic(0.4, 1.5);
        for law in [
            Friction::Coulomb(0.2),
            Friction::StaticKinetic {
                stick: 0.3,
                slide: 0.2,
            },
            Friction::Velocity {
                slow: 0.1,
                fast: 0.25,
                rate: 20.0,
            },
        ] {
            let block = SlidingBlock {
                friction: law,
                gravity: 9.81,
                horizontal: &m,
                vertical: None,
                surface: Surface::Flat,
            };
            let coarse = simulate_block(&block, 6.0, 0.0, &SteppedOptions::default()).unwrap();
            let fine_options = SteppedOptions {
                max_step: 2.5e-4,
                steps_per_period: 4000,
                ..SteppedOptions::default()
            };
            let fine = simulate_block(&block, 6.0, 0.0, &fine_options).unwrap();
            assert!(coarse.max_slip > 1e-3, "{law}: the block should slide");
            let d = (coarse.max_slip - fine.max_slip).abs() / fine.max_slip;
            let e = (coarse.residual_slip - fine.residual_slip).abs() / fine.max_slip;
            assert!(d < 1e-8 && e < 1e-8, "{law}: {d:e} {e:e}");
            let balance = coarse.energy.residual / coarse.energy.input_work.abs();
            assert!(balance.abs() < 1e-8, "{law}: energy residual {balance:e}");
        }
    }

    /// A vertical acceleration that exceeds g is a lift-off, reported with its time.
    #[test]
    fn lift_off_is_refused_with_its_time() {
        let h = harmonic(0.3, 1.0);
        let v = harmonic(1.2, 1.0);
        let block = SlidingBlock {
            friction: Friction::Coulomb(0.2),
            gravity: 9.80665,
            horizontal: &h,
            vertical: Some(&v),
            surface: Surface::Flat,
        };
        let err = simulate_block(&block, 2.0, 0.0, &SteppedOptions::default()).unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("lifts the structure off") && text.contains("t = "),
            "{text}"
        );
    }
}
