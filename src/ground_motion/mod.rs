//! Horizontal ground motions: harmonic excitation and recorded accelerograms.
//!
//! A ground motion is a function of time, evaluated wherever the solver needs it: records
//! are linearly interpolated between samples (never indexed by step number), so the solver's
//! Δt need not equal the record's spacing. Velocity and displacement are the *exact*
//! integrals of that piecewise-linear acceleration from rest, which is what the
//! prescribed-motion ground and the analytic models need.
//!
//! Units: SI inside (m/s²); records are stored in g on disk and converted once, at load time.

mod readers;
mod record;

pub use readers::{
    builtin_names, builtin_record, parse_at2, parse_text, read_record_file, resolve_record,
};
pub use record::Record;

/// Standard gravity, m/s². Records in g are converted with this value.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Harmonic ground acceleration `a(t) = A sin(Ω t)` starting from rest at t = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// Amplitude A, m/s².
    pub amplitude: f64,
    /// Circular frequency Ω, rad/s.
    pub omega: f64,
}

impl Harmonic {
    /// Builds a harmonic motion from an amplitude in g and a frequency in Hz.
    pub fn from_g_hz(amplitude_g: f64, frequency_hz: f64) -> crate::Result<Self> {
        crate::error::require_positive("amplitude", amplitude_g)?;
        crate::error::require_positive("frequency", frequency_hz)?;
        Ok(Self {
            amplitude: amplitude_g * STANDARD_GRAVITY,
            omega: 2.0 * std::f64::consts::PI * frequency_hz,
        })
    }

    /// Acceleration, m/s².
    pub fn accel(&self, t: f64) -> f64 {
        self.amplitude * (self.omega * t).sin()
    }

    /// Velocity from rest: `A/Ω (1 − cos Ωt)`, m/s.
    pub fn velocity(&self, t: f64) -> f64 {
        // 2 sin²(x/2) instead of 1 − cos x: no cancellation near t = 0.
        let half = 0.5 * self.omega * t;
        self.amplitude / self.omega * 2.0 * half.sin() * half.sin()
    }

    /// Displacement from rest: `A/Ω² (Ωt − sin Ωt)`, m.
    pub fn displacement(&self, t: f64) -> f64 {
        let x = self.omega * t;
        // For small x, x − sin x loses all digits; use its series there.
        let x_minus_sin = if x.abs() < 1e-2 {
            let x3 = x * x * x;
            x3 / 6.0 - x3 * x * x / 120.0 + x3 * x * x * x * x / 5040.0
        } else {
            x - x.sin()
        };
        self.amplitude / (self.omega * self.omega) * x_minus_sin
    }
}

/// A horizontal ground motion, as the solvers see it.
#[derive(Debug, Clone)]
pub enum GroundMotion {
    /// `a(t) = A sin(Ωt)` from rest.
    Harmonic(Harmonic),
    /// A recorded accelerogram, interpolated linearly; zero after its last sample.
    Record(std::sync::Arc<Record>),
}

impl GroundMotion {
    /// Ground acceleration at time `t`, m/s².
    pub fn accel(&self, t: f64) -> f64 {
        match self {
            GroundMotion::Harmonic(h) => h.accel(t),
            GroundMotion::Record(r) => r.accel(t),
        }
    }

    /// Ground velocity at time `t` (exact integral of [`Self::accel`] from rest), m/s.
    pub fn velocity(&self, t: f64) -> f64 {
        match self {
            GroundMotion::Harmonic(h) => h.velocity(t),
            GroundMotion::Record(r) => r.velocity(t),
        }
    }

    /// Ground displacement at time `t` (exact double integral from rest), m.
    pub fn displacement(&self, t: f64) -> f64 {
        match self {
            GroundMotion::Harmonic(h) => h.displacement(t),
            GroundMotion::Record(r) => r.displacement(t),
        }
    }

    /// Rate of change of the acceleration (jerk) at `t`, m/s³: the derivative of the
    /// harmonic, or the slope of the record segment that starts at or before `t`.
    pub fn accel_rate(&self, t: f64) -> f64 {
        match self {
            GroundMotion::Harmonic(h) => h.amplitude * h.omega * (h.omega * t).cos(),
            GroundMotion::Record(r) => r.accel_rate(t),
        }
    }

    /// Largest |a| over `[0, until]`, m/s² (the paper's a_max).
    pub fn peak_accel(&self, until: f64) -> f64 {
        match self {
            GroundMotion::Harmonic(h) => {
                // |sin| reaches 1 at Ωt = π/2 unless the run ends before that.
                if h.omega * until >= std::f64::consts::FRAC_PI_2 {
                    h.amplitude.abs()
                } else {
                    h.accel(until).abs()
                }
            }
            GroundMotion::Record(r) => r.peak_accel(until),
        }
    }

    /// Largest |ground velocity| (from rest) over [0, `until`], m/s (a record's at its
    /// samples).
    pub fn peak_velocity(&self, until: f64) -> f64 {
        match self {
            // A/Ω (1 − cos Ωt) grows until Ωt = π.
            GroundMotion::Harmonic(h) => h
                .velocity(until.min(std::f64::consts::PI / h.omega.abs()))
                .abs(),
            GroundMotion::Record(r) => r.peak_velocity(until),
        }
    }

    /// Times in the open interval `(t0, t1)` where the acceleration has a kink (record
    /// samples). Exact integrators step onto these so that the forcing is smooth in between.
    pub fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        match self {
            GroundMotion::Harmonic(_) => Vec::new(),
            GroundMotion::Record(r) => r.breakpoints(t0, t1),
        }
    }

    /// Natural length of the motion: the record's duration, or `None` for harmonic input.
    pub fn duration(&self) -> Option<f64> {
        match self {
            GroundMotion::Harmonic(_) => None,
            GroundMotion::Record(r) => Some(r.duration()),
        }
    }

    /// A short human-readable label ("harmonic 0.300 g at 1.000 Hz", record name…).
    pub fn label(&self) -> String {
        match self {
            GroundMotion::Harmonic(h) => format!(
                "harmonic {:.3} g at {:.3} Hz",
                h.amplitude / STANDARD_GRAVITY,
                h.omega / (2.0 * std::f64::consts::PI)
            ),
            GroundMotion::Record(r) => r.name.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_integrals_match_finite_differences() {
        let h = Harmonic {
            amplitude: 2.9,
            omega: 3.7,
        };
        for &t in &[1e-4, 0.01, 0.3, 2.0, 17.5] {
            let e = 1e-5;
            let dv = (h.velocity(t + e) - h.velocity(t - e)) / (2.0 * e);
            let dd = (h.displacement(t + e) - h.displacement(t - e)) / (2.0 * e);
            assert!((dv - h.accel(t)).abs() < 1e-6 * h.amplitude, "t={t}");
            assert!((dd - h.velocity(t)).abs() < 1e-6 * h.amplitude, "t={t}");
        }
        assert_eq!(h.velocity(0.0), 0.0);
        assert_eq!(h.displacement(0.0), 0.0);
    }
}
