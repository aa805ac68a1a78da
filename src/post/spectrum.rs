//! Fourier amplitude spectra (rustfft) and their peaks.

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use crate::{Error, Result};

/// A one-sided Fourier amplitude spectrum.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Spectrum {
    /// Frequencies, Hz (0 to Nyquist).
    pub freq_hz: Vec<f64>,
    /// |X(f)|·dt: the amplitude of the continuous Fourier transform, units × s.
    pub amplitude: Vec<f64>,
}

/// Fourier amplitude spectrum of uniformly sampled data (no window: a record is a transient
/// that starts and ends near zero, and this is the spectrum the paper shows).
pub fn fourier_amplitude(samples: &[f64], dt: f64) -> Result<Spectrum> {
    crate::error::require_positive("spectrum dt", dt)?;
    if samples.len() < 2 {
        return Err(Error::invalid("spectrum", "needs at least two samples"));
    }
    if samples.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid("spectrum", "the signal contains NaN or inf"));
    }
    let n = samples.len();
    let mut buffer: Vec<Complex<f64>> = samples.iter().map(|&v| Complex::new(v, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buffer);
    let half = n / 2 + 1;
    let df = 1.0 / (n as f64 * dt);
    Ok(Spectrum {
        freq_hz: (0..half).map(|k| k as f64 * df).collect(),
        amplitude: buffer[..half].iter().map(|c| c.norm() * dt).collect(),
    })
}

/// Resamples a history given at increasing times `t` onto a uniform grid of step `dt`
/// from `t[0]` (linear interpolation): solver steps are not uniform when Δt is cut or a
/// step lands on a contact event, but a Fourier transform needs uniform samples.
pub fn resample_uniform(t: &[f64], y: &[f64], dt: f64) -> Result<Vec<f64>> {
    crate::error::require_positive("resample dt", dt)?;
    if t.len() != y.len() || t.len() < 2 {
        return Err(Error::invalid(
            "resample",
            "needs matching time and value arrays of at least two samples",
        ));
    }
    let n = ((t[t.len() - 1] - t[0]) / dt).floor() as usize + 1;
    let mut out = Vec::with_capacity(n);
    let mut j = 0;
    for k in 0..n {
        let tk = t[0] + k as f64 * dt;
        while j + 2 < t.len() && t[j + 1] < tk {
            j += 1;
        }
        let span = t[j + 1] - t[j];
        let w = if span > 0.0 {
            ((tk - t[j]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(y[j] * (1.0 - w) + y[j + 1] * w);
    }
    Ok(out)
}

/// The Fourier amplitude spectrum of a history sampled at increasing times `t` (not
/// necessarily evenly), resampled onto a uniform grid of step `dt` first.
pub fn uniform_spectrum(t: &[f64], y: &[f64], dt: f64) -> Result<Spectrum> {
    fourier_amplitude(&resample_uniform(t, y, dt)?, dt)
}

/// Linear interpolation of a history (`t` increasing) at the times `at` (held constant
/// outside its range; NaN if it is empty).
pub fn interpolate(t: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let n = t.len().min(y.len());
    at.iter()
        .map(|&x| {
            if n == 0 {
                return f64::NAN;
            }
            let k = t[..n].partition_point(|&s| s < x);
            if k == 0 {
                return y[0];
            }
            if k >= n {
                return y[n - 1];
            }
            let span = t[k] - t[k - 1];
            let w = if span > 0.0 {
                (x - t[k - 1]) / span
            } else {
                1.0
            };
            y[k - 1] + w * (y[k] - y[k - 1])
        })
        .collect()
}

/// [`resample_uniform`] done on the fly: points are pushed as a run produces them and
/// only the uniform samples are kept, so a spectrum of a long run needs no stored history.
/// The samples are those `resample_uniform` gives for the same points. Beyond
/// `max_samples` every other sample is dropped and the spacing doubled, so memory stays
/// bounded however long the run (the spectrum then ends at a lower Nyquist frequency).
#[derive(Debug, Clone)]
pub struct UniformSeries {
    dt: f64,
    max_samples: usize,
    t0: f64,
    last: Option<(f64, f64)>,
    samples: Vec<f64>,
}

impl UniformSeries {
    /// An empty series with spacing `dt` (> 0) and at most `max_samples` (≥ 2) samples.
    pub fn new(dt: f64, max_samples: usize) -> Self {
        Self {
            dt,
            max_samples: max_samples.max(2),
            t0: 0.0,
            last: None,
            samples: Vec::new(),
        }
    }

    /// Adds the value `y` at time `t` (times must increase).
    pub fn push(&mut self, t: f64, y: f64) {
        let Some((tp, yp)) = self.last else {
            self.t0 = t;
            self.samples.push(y);
            self.last = Some((t, y));
            return;
        };
        let span = t - tp;
        loop {
            let tk = self.t0 + self.samples.len() as f64 * self.dt;
            if tk > t {
                break;
            }
            let w = if span > 0.0 {
                ((tk - tp) / span).clamp(0.0, 1.0)
            } else {
                0.0
            };
            self.samples.push(yp * (1.0 - w) + y * w);
            if self.samples.len() >= self.max_samples {
                self.decimate();
            }
        }
        self.last = Some((t, y));
    }

    fn decimate(&mut self) {
        let kept: Vec<f64> = self.samples.iter().step_by(2).copied().collect();
        self.samples = kept;
        self.dt *= 2.0;
    }

    /// The uniform samples from the first pushed time, and their spacing.
    pub fn finish(mut self) -> (Vec<f64>, f64) {
        if let Some((t_last, y_last)) = self.last {
            // The same count as `resample_uniform`: the last grid time not after the last
            // point (rounding can put one sample on either side).
            let n = ((t_last - self.t0) / self.dt).floor() as usize + 1;
            self.samples.truncate(n);
            while self.samples.len() < n {
                self.samples.push(y_last);
            }
        }
        (self.samples, self.dt)
    }
}

impl Spectrum {
    /// The highest peak with f in [f_min, f_max]: (frequency, amplitude), the frequency
    /// refined by a parabola through the peak bin and its neighbours (sub-bin accuracy).
    /// A peak is a local maximum: the highest bin of the window when it sits on the
    /// shoulder of a peak outside it is not one (the report's "peak below 1 Hz" was the
    /// 1 Hz edge of the 2.7 Hz peak's shoulder), and a window without one has none.
    pub fn peak(&self, f_min: f64, f_max: f64) -> Option<(f64, f64)> {
        let a = &self.amplitude;
        // The spectrum's own ends count (a constant peaks at 0 Hz); the window's do not.
        let local_max =
            |k: usize| (k == 0 || a[k] > a[k - 1]) && (k + 1 == a.len() || a[k] >= a[k + 1]);
        let k = (0..a.len())
            .filter(|&k| self.freq_hz[k] >= f_min && self.freq_hz[k] <= f_max && local_max(k))
            .max_by(|&x, &y| a[x].total_cmp(&a[y]))?;
        Some(self.refine(k))
    }

    /// Local maxima, highest first, each refined to sub-bin accuracy.
    pub fn peaks(&self, f_min: f64, f_max: f64, count: usize) -> Vec<(f64, f64)> {
        let a = &self.amplitude;
        let mut found: Vec<usize> = (1..a.len().saturating_sub(1))
            .filter(|&k| {
                self.freq_hz[k] >= f_min
                    && self.freq_hz[k] <= f_max
                    && a[k] > a[k - 1]
                    && a[k] >= a[k + 1]
            })
            .collect();
        found.sort_by(|&x, &y| a[y].total_cmp(&a[x]));
        found
            .into_iter()
            .take(count)
            .map(|k| self.refine(k))
            .collect()
    }

    fn refine(&self, k: usize) -> (f64, f64) {
        let a = &self.amplitude;
        if k == 0 || k + 1 >= a.len() {
            return (self.freq_hz[k], a[k]);
        }
        let (y0, y1, y2) = (a[k - 1], a[k], a[k + 1]);
        let denom = y0 - 2.0 * y1 + y2;
        let shift = if denom < 0.0 {
            (0.5 * (y0 - y2) / denom).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let df = self.freq_hz[1] - self.freq_hz[0];
        (self.freq_hz[k] + shift * df, y1 - 0.25 * (y0 - y2) * shift)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinusoid_peaks_at_its_frequency_with_amplitude_a_t_over_two() {
        let (dt, t_end, f, a) = (0.01, 40.0, 1.5, 2.0);
        let n = (t_end / dt) as usize;
        let x: Vec<f64> = (0..n)
            .map(|k| a * (2.0 * std::f64::consts::PI * f * k as f64 * dt).sin())
            .collect();
        let s = fourier_amplitude(&x, dt).unwrap();
        let (fp, amp) = s.peak(0.1, 10.0).unwrap();
        assert!((fp - f).abs() < 0.5 / t_end, "peak at {fp}");
        assert!(
            (amp - a * t_end / 2.0).abs() < 0.02 * a * t_end / 2.0,
            "amplitude {amp}"
        );
        let c = fourier_amplitude(&[1.0; 64], 0.1).unwrap();
        assert_eq!(c.peak(0.0, 100.0).unwrap().0, 0.0);
        // A window on a peak's shoulder holds no peak, however high its edge.
        let shoulder = Spectrum {
            freq_hz: vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5],
            amplitude: vec![0.5, 1.0, 2.0, 3.0, 2.0, 1.0],
        };
        assert_eq!(shoulder.peak(0.1, 1.2), None);
        assert_eq!(shoulder.peak(1.8, 3.0), None);
        assert_eq!(shoulder.peak(0.1, 3.0).map(|p| p.0), Some(1.5));
        assert_eq!(shoulder.peak(0.0, 0.2).map(|p| p.0), None);
        assert!(fourier_amplitude(&[1.0, f64::NAN], 0.1).is_err());
    }

    /// The on-the-fly series equals the resampling of the stored points.
    #[test]
    fn uniform_series_equals_resample_uniform() {
        let t: Vec<f64> = (0..500)
            .map(|k| 0.001 + 0.0013 * k as f64 + 1e-4 * (k % 3) as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|t| (7.0 * t).sin()).collect();
        let offline = resample_uniform(&t, &y, 0.005).unwrap();
        let mut online = UniformSeries::new(0.005, 1 << 20);
        for (&ti, &yi) in t.iter().zip(&y) {
            online.push(ti, yi);
        }
        let (samples, dt) = online.finish();
        assert_eq!(dt, 0.005);
        assert_eq!(samples, offline);
        // Bounded: 1000 points into at most 64 samples.
        let mut small = UniformSeries::new(0.001, 64);
        for k in 0..1000 {
            small.push(k as f64 * 0.001, 1.0);
        }
        let (samples, dt) = small.finish();
        assert!(
            samples.len() <= 64 && dt > 0.001,
            "{} samples at {dt}",
            samples.len()
        );
    }

    #[test]
    fn two_tones_give_two_peaks() {
        let dt = 0.005;
        let x: Vec<f64> = (0..40000)
            .map(|k| k as f64 * dt)
            .map(|t| {
                (2.0 * std::f64::consts::PI * 0.638 * t).sin()
                    + 0.3 * (2.0 * std::f64::consts::PI * 1.788 * t).sin()
            })
            .collect();
        let s = fourier_amplitude(&x, dt).unwrap();
        let p = s.peaks(0.1, 5.0, 2);
        assert!(
            (p[0].0 - 0.638).abs() < 0.002 && (p[1].0 - 1.788).abs() < 0.002,
            "{p:?}"
        );
    }
}
