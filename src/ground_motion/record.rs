//! A recorded accelerogram: uniform samples, linear interpolation, exact integrals.

use super::STANDARD_GRAVITY;
use crate::limits::{MAX_ACCEL_G, MAX_RECORD_SAMPLES, RECORD_DT_RANGE};
use crate::{Error, Result};

/// A uniformly sampled ground-acceleration record starting from rest at t = 0.
///
/// Between samples the acceleration is linear; after the last sample it is zero (the
/// structure then vibrates freely). Velocity and displacement are the exact integrals of
/// that piecewise-linear function, precomputed at the samples.
#[derive(Debug, Clone)]
pub struct Record {
    /// Short name used on the command line and in reports (e.g. `el-centro`).
    pub name: String,
    /// Where the data came from (event, station, component, source package), for reports.
    pub provenance: String,
    /// Where it was read: the file's path as given (its name for a built-in record);
    /// errors about the whole record point there.
    pub source: String,
    /// Sample spacing, s.
    pub dt: f64,
    /// Acceleration samples at t = k·dt, m/s².
    accel: Vec<f64>,
    /// Velocity at the samples, m/s.
    vel: Vec<f64>,
    /// Displacement at the samples, m.
    disp: Vec<f64>,
}

impl Record {
    /// Builds a record from samples in m/s² at spacing `dt`, the first at t = 0.
    ///
    /// Fails on fewer than two or more than [`MAX_RECORD_SAMPLES`] samples, a `dt` outside
    /// [`RECORD_DT_RANGE`], or a sample that is not finite or beyond ±[`MAX_ACCEL_G`] g.
    pub fn new(name: impl Into<String>, dt: f64, accel: Vec<f64>) -> Result<Self> {
        let name = name.into();
        let (lo, hi) = RECORD_DT_RANGE;
        if !(dt.is_finite() && (lo..=hi).contains(&dt)) {
            return Err(Error::record(
                &name,
                0,
                format!("time step must be in [{lo:e}, {hi}] s, got {dt}"),
            ));
        }
        if accel.len() < 2 || accel.len() > MAX_RECORD_SAMPLES {
            return Err(Error::record(
                &name,
                0,
                format!(
                    "a record needs 2 to {MAX_RECORD_SAMPLES} samples, got {}",
                    accel.len()
                ),
            ));
        }
        let limit = MAX_ACCEL_G * STANDARD_GRAVITY;
        if let Some(k) = accel
            .iter()
            .position(|a| !(a.is_finite() && a.abs() <= limit))
        {
            return Err(Error::record(
                &name,
                0,
                format!(
                    "sample {k} ({} m/s²) is not finite or beyond ±{MAX_ACCEL_G} g",
                    accel[k]
                ),
            ));
        }
        let n = accel.len();
        let mut vel = vec![0.0; n];
        let mut disp = vec![0.0; n];
        for k in 1..n {
            let (a0, a1) = (accel[k - 1], accel[k]);
            vel[k] = vel[k - 1] + dt * 0.5 * (a0 + a1);
            disp[k] = disp[k - 1] + dt * vel[k - 1] + dt * dt * (2.0 * a0 + a1) / 6.0;
        }
        Ok(Self {
            source: name.clone(),
            name,
            provenance: String::new(),
            dt,
            accel,
            vel,
            disp,
        })
    }

    /// Attaches a provenance note.
    pub fn with_provenance(mut self, provenance: impl Into<String>) -> Self {
        self.provenance = provenance.into();
        self
    }

    /// Records where the record was read (see [`Record::source`]).
    pub fn with_source(mut self, source: impl Into<String>) -> Self {
        self.source = source.into();
        self
    }

    /// Multiplies every sample by `factor` (e.g. to scale a record to a target PGA).
    pub fn scaled(&self, factor: f64) -> Result<Self> {
        crate::error::require_positive("record scale factor", factor)?;
        let accel = self.accel.iter().map(|a| a * factor).collect();
        Ok(Self::new(self.name.clone(), self.dt, accel)?
            .with_provenance(self.provenance.clone())
            .with_source(self.source.clone()))
    }

    /// Whether the record says it is a vertical component: a `component:` note naming it
    /// up, down or vertical (the shipped CSV files), or a PEER AT2 title line ending in
    /// `UP`, `DWN` or `V`. Such a record is refused as horizontal input (it is the
    /// vertical excitation's).
    pub fn is_vertical(&self) -> bool {
        self.provenance.split(['\n', '/']).any(|line| {
            let lower = line.trim().to_lowercase();
            if let Some(component) = lower.strip_prefix("component:") {
                let words: Vec<&str> = component
                    .split(|c: char| !c.is_alphanumeric())
                    .filter(|w| !w.is_empty())
                    .collect();
                return words
                    .iter()
                    .any(|w| matches!(*w, "up" | "dwn" | "down" | "vertical" | "vert"));
            }
            let last = lower.rsplit(',').next().unwrap_or("").trim();
            lower.contains(',') && matches!(last, "up" | "dwn" | "down" | "v" | "vert" | "vertical")
        })
    }

    /// Acceleration samples, m/s².
    pub fn samples(&self) -> &[f64] {
        &self.accel
    }

    /// Time of the last sample, s.
    pub fn duration(&self) -> f64 {
        (self.accel.len() - 1) as f64 * self.dt
    }

    /// Locates `t` in the record: segment index k and local time τ ∈ [0, dt).
    /// Returns `None` before 0 or after the last sample.
    fn locate(&self, t: f64) -> Option<(usize, f64)> {
        if t < 0.0 || self.accel.len() < 2 || t >= self.duration() {
            return None;
        }
        let k = ((t / self.dt).floor() as usize).min(self.accel.len() - 2);
        Some((k, t - k as f64 * self.dt))
    }

    /// Acceleration at time `t`, linearly interpolated, m/s². Zero outside the record.
    pub fn accel(&self, t: f64) -> f64 {
        match self.locate(t) {
            Some((k, tau)) => {
                let s = tau / self.dt;
                self.accel[k] * (1.0 - s) + self.accel[k + 1] * s
            }
            None if t >= 0.0 && t <= self.duration() => self.accel[self.accel.len() - 1],
            None => 0.0,
        }
    }

    /// Slope of the acceleration on the segment containing `t` (right-continuous at
    /// samples), m/s³. Zero outside the record.
    pub fn accel_rate(&self, t: f64) -> f64 {
        match self.locate(t) {
            Some((k, _)) => (self.accel[k + 1] - self.accel[k]) / self.dt,
            None => 0.0,
        }
    }

    /// Velocity at time `t` from rest, m/s (constant after the record ends).
    pub fn velocity(&self, t: f64) -> f64 {
        match self.locate(t) {
            Some((k, tau)) => {
                let (a0, a1) = (self.accel[k], self.accel[k + 1]);
                let slope = (a1 - a0) / self.dt;
                self.vel[k] + a0 * tau + 0.5 * slope * tau * tau
            }
            None if t < 0.0 => 0.0,
            None => self.end_velocity(),
        }
    }

    /// Displacement at time `t` from rest, m (drifts linearly after the record ends if the
    /// final velocity is not zero, as the uncorrected record implies).
    pub fn displacement(&self, t: f64) -> f64 {
        match self.locate(t) {
            Some((k, tau)) => {
                let (a0, a1) = (self.accel[k], self.accel[k + 1]);
                let slope = (a1 - a0) / self.dt;
                self.disp[k]
                    + self.vel[k] * tau
                    + 0.5 * a0 * tau * tau
                    + slope * tau * tau * tau / 6.0
            }
            None if t < 0.0 => 0.0,
            None => {
                let n = self.accel.len() - 1;
                self.disp[n] + self.end_velocity() * (t - self.duration())
            }
        }
    }

    fn end_velocity(&self) -> f64 {
        self.vel[self.vel.len() - 1]
    }

    /// Largest |a| over samples with t ≤ `until`, m/s².
    pub fn peak_accel(&self, until: f64) -> f64 {
        let last = ((until / self.dt).floor() as usize).min(self.accel.len() - 1);
        self.accel[..=last]
            .iter()
            .fold(0.0_f64, |m, a| m.max(a.abs()))
    }

    /// Largest |v| (from rest) over samples with t ≤ `until`, m/s.
    pub fn peak_velocity(&self, until: f64) -> f64 {
        let last = ((until / self.dt).floor() as usize).min(self.vel.len() - 1);
        self.vel[..=last]
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    /// Sample times strictly inside `(t0, t1)`.
    pub fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        let first = ((t0 / self.dt).floor() as i64 + 1).max(0) as usize;
        (first..self.accel.len())
            .map(|k| k as f64 * self.dt)
            .take_while(|&t| t < t1)
            .filter(|&t| t > t0)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrals_are_exact_for_a_linear_ramp() {
        // a(t) = t on [0, 1] sampled every 0.1: v = t²/2, d = t³/6 exactly.
        let samples: Vec<f64> = (0..=10).map(|k| k as f64 * 0.1).collect();
        let r = Record::new("ramp", 0.1, samples).unwrap();
        for &t in &[0.0, 0.05, 0.33, 0.999] {
            assert!((r.accel(t) - t).abs() < 1e-12);
            assert!((r.velocity(t) - t * t / 2.0).abs() < 1e-12);
            assert!((r.displacement(t) - t * t * t / 6.0).abs() < 1e-12);
        }
        // After the end: a = 0, v constant, d linear.
        assert_eq!(r.accel(1.5), 0.0);
        assert!((r.velocity(1.5) - 0.5).abs() < 1e-12);
        assert!((r.displacement(1.5) - (1.0 / 6.0 + 0.5 * 0.5)).abs() < 1e-12);
    }

    #[test]
    fn breakpoints_are_interior_samples() {
        let r = Record::new("r", 0.02, vec![0.0; 11]).unwrap();
        let b = r.breakpoints(0.03, 0.09);
        assert_eq!(b.len(), 3);
        assert!((b[0] - 0.04).abs() < 1e-12 && (b[2] - 0.08).abs() < 1e-12);
    }
}
