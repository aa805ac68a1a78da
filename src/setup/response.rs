//! The responses every front end reports, defined once: slip, drift, base and roof
//! acceleration of a DDA model at its current state.

use crate::dda::Dda;
use crate::ground_motion::GroundMotion;

/// The measured responses at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Response {
    /// Time, s.
    pub time: f64,
    /// Ground acceleration, m/s² (0 without ground motion).
    pub ground_accel: f64,
    /// Ground displacement, m (0 without ground motion).
    pub ground_disp: f64,
    /// Slip u_s: horizontal displacement of the base's centroid relative to the ground, m.
    pub slip: f64,
    /// Drift u_r: horizontal displacement of the roof's centroid relative to the base's, m.
    pub drift: f64,
    /// Absolute horizontal acceleration of the base, m/s².
    pub base_accel: f64,
    /// Absolute horizontal acceleration of the roof, m/s².
    pub roof_accel: f64,
}

/// Which blocks of a model are measured: the base (on the sliding joint) and the roof.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Probe {
    /// Block index of the base (raft or base slab).
    pub base: usize,
    /// Block index of the roof (roof block or top floor).
    pub roof: usize,
}

impl Probe {
    /// The responses of `dda` now.
    pub fn measure(&self, dda: &Dda, motion: Option<&GroundMotion>) -> Response {
        let t = dda.time();
        let base = &dda.blocks()[self.base];
        let roof = &dda.blocks()[self.roof];
        let ground_disp = motion.map_or(0.0, |m| m.displacement(t));
        let base_x = base.centroid_displacement()[0];
        Response {
            time: t,
            ground_accel: motion.map_or(0.0, |m| m.accel(t)),
            ground_disp,
            slip: base_x - ground_disp,
            drift: roof.centroid_displacement()[0] - base_x,
            base_accel: base.accel[0],
            roof_accel: roof.accel[0],
        }
    }
}
