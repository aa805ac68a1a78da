//! `slidebase sweep`: the paper's parameter grid (Figs 4–9) with both models, in parallel.

use rayon::prelude::*;

use super::run::run;
use crate::dda::Integrator;
use crate::limits::{MAX_LIST_VALUES, MAX_SWEEP_RUNS};
use crate::post::sweep::SweepRow;
use crate::setup::{ExcitationSpec, Frequency, ModelKind, RunSpec};
use crate::{Error, Result};

/// A grid of two-mass runs.
#[derive(Debug, Clone)]
pub struct SweepRequest {
    /// Mass ratios α.
    pub alphas: Vec<f64>,
    /// Friction coefficients ρ.
    pub frictions: Vec<f64>,
    /// Frequency ratios Ω/ω.
    pub freq_ratios: Vec<f64>,
    /// Harmonic amplitude, g.
    pub amplitude_g: f64,
    /// Structural damping ratio ζ of every run (both models), `None` undamped.
    pub damping: Option<f64>,
    /// Duration of every run, s (default: the harmonic default of the run set-up).
    pub duration: Option<f64>,
    /// DDA time step, s (default: the run set-up's).
    pub dt: Option<f64>,
    /// DDA integrator (default: the run set-up's).
    pub integrator: Option<Integrator>,
    /// Run even beyond the step limit.
    pub confirm_large: bool,
    /// Which models to run at every point.
    pub models: Vec<ModelKind>,
    /// Run only slice I of N (1-based): the grid's jobs I, I + N, I + 2N… so that a job
    /// array can share a sweep out and `slidebase merge` can join the pieces.
    pub shard: Option<(usize, usize)>,
}

/// One grid point that failed, with the reason.
#[derive(Debug, Clone)]
pub struct SweepFailure {
    /// Model.
    pub model: ModelKind,
    /// α.
    pub alpha: f64,
    /// ρ.
    pub friction: f64,
    /// Ω/ω.
    pub freq_ratio: f64,
    /// The error message.
    pub message: String,
}

/// Parses `0.1,0.5,0.9` into numbers, naming the flag in errors.
pub fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>> {
    let count = text.split(',').count();
    if count > MAX_LIST_VALUES {
        return Err(Error::invalid(
            flag,
            format!("{count} values; a list may have at most {MAX_LIST_VALUES}"),
        ));
    }
    if text.trim().is_empty() {
        return Err(Error::invalid(flag, "the list is empty"));
    }
    let values: Result<Vec<f64>> = text
        .split(',')
        .map(|s| s.trim())
        .enumerate()
        .map(|(k, s)| {
            if s.is_empty() {
                // `0.5,` or `,0.5`: a value left out, not a list of one.
                return Err(Error::invalid(
                    flag,
                    format!(
                        "value {} of '{text}' is empty; give numbers separated by commas",
                        k + 1
                    ),
                ));
            }
            s.parse::<f64>()
                .map_err(|_| Error::invalid(flag, format!("'{s}' is not a number")))
        })
        .collect();
    let values = values?;
    distinct(flag, &values)?;
    Ok(values)
}

/// A run's error in the words of the sweep's flags: a run's `--freq-ratio` is one of the
/// sweep's `--freq-ratios`, and a friction that never slides has no `--fixed-base` to
/// turn to in a sweep (the grid is of sliding bases).
fn as_sweep_error(e: Error) -> Error {
    match e {
        Error::InvalidParameter { field, message } => {
            let message = if field == "--friction" && message.contains("--fixed-base") {
                "inf: the sweep's grid is of sliding bases; give finite coefficients".into()
            } else {
                message
            };
            let field = if field == "--freq-ratio" {
                "--freq-ratios".into()
            } else {
                field
            };
            Error::InvalidParameter { field, message }
        }
        other => other,
    }
}

/// Refuses a value given twice: a grid runs each point once (a repeated value ran it
/// twice, and `merge` then refused the sweep's own table for its repeated rows).
fn distinct(flag: &str, values: &[f64]) -> Result<()> {
    for (k, v) in values.iter().enumerate() {
        if values[..k].contains(v) {
            return Err(Error::invalid(
                flag,
                format!("{v} is given twice; give each value once"),
            ));
        }
    }
    Ok(())
}

/// The frequency ratios at which a log-spaced grid is most often read and where the
/// errors are largest (the transitions between the regimes of Figs 4–9): the grid must
/// contain them, not step over them.
pub const KEY_RATIOS: [f64; 3] = [0.5, 2.0, 5.0];

/// The validation grid of Ω/ω: the paper's 25 log-spaced ratios from 0.1 to 10 (with 1,
/// resonance, in the middle), the point nearest to each of [`KEY_RATIOS`] moved onto it.
pub fn paper_ratios() -> Vec<f64> {
    let mut r = log_spaced(0.1, 10.0, 25);
    for key in KEY_RATIOS {
        let nearest = (0..r.len())
            .min_by(|&i, &j| (r[i] / key).ln().abs().total_cmp(&(r[j] / key).ln().abs()))
            .unwrap_or(0);
        r[nearest] = key;
    }
    r
}

/// `n` (≥ 2) log-spaced values from `lo` to `hi` inclusive.
fn log_spaced(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let (a, b) = (lo.log10(), hi.log10());
    (0..n)
        .map(|k| 10f64.powf(a + (b - a) * k as f64 / (n - 1) as f64))
        .collect()
}

/// Parses frequency ratios: `paper` is [`paper_ratios`]; `lo:hi:n` gives n log-spaced
/// values from lo to hi inclusive; anything else is a comma-separated list.
pub fn parse_ratios(flag: &str, text: &str) -> Result<Vec<f64>> {
    if text.trim() == "paper" {
        return Ok(paper_ratios());
    }
    let parts: Vec<&str> = text.split(':').collect();
    if parts.len() != 3 {
        return parse_list(flag, text);
    }
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| Error::invalid(flag, format!("'{s}' is not a number")))
    };
    let (lo, hi) = (num(parts[0])?, num(parts[1])?);
    let n: usize = parts[2].trim().parse().map_err(|_| {
        Error::invalid(
            flag,
            format!("'{}' is not a count (a whole number >= 1)", parts[2]),
        )
    })?;
    if !(lo > 0.0 && hi >= lo && lo.is_finite() && hi.is_finite()) || n == 0 {
        return Err(Error::invalid(
            flag,
            format!("expected lo:hi:n with 0 < lo <= hi and n >= 1, got '{text}'"),
        ));
    }
    if n > MAX_LIST_VALUES {
        return Err(Error::invalid(
            flag,
            format!("{n} values; a list may have at most {MAX_LIST_VALUES}"),
        ));
    }
    // One value, or several between equal ends, would drop `hi` or repeat `lo`.
    if (n == 1) != (lo == hi) {
        return Err(Error::invalid(
            flag,
            format!(
                "{lo}:{hi}:{n} — one value (n = 1) needs lo = hi, and n >= 2 values need \
                 lo < hi"
            ),
        ));
    }
    if n == 1 {
        return Ok(vec![lo]);
    }
    Ok(log_spaced(lo, hi, n))
}

/// Parses `I/N` (1 ≤ I ≤ N) for `--shard`.
pub fn parse_shard(text: &str) -> Result<(usize, usize)> {
    let bad = || {
        Error::invalid(
            "--shard",
            format!("expected I/N with 1 <= I <= N <= {MAX_SWEEP_RUNS} (e.g. 3/8), got '{text}'"),
        )
    };
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if i == 0 || i > n || n > MAX_SWEEP_RUNS {
        return Err(bad());
    }
    Ok((i, n))
}

impl SweepRequest {
    /// The run of one grid point, as every front end sets it up.
    pub fn spec(&self, model: ModelKind, alpha: f64, friction: f64, freq_ratio: f64) -> RunSpec {
        let dda = model == ModelKind::Dda;
        RunSpec {
            model,
            excitation: ExcitationSpec::Harmonic {
                amplitude_g: Some(self.amplitude_g),
                frequency: Some(Frequency::Ratio(freq_ratio)),
            },
            alpha: Some(alpha),
            friction: Some(friction),
            damping: self.damping,
            duration: self.duration,
            // The exact model has no time step or integrator.
            dt: if dda { self.dt } else { None },
            integrator: if dda { self.integrator } else { None },
            confirm_large: self.confirm_large,
            ..RunSpec::default()
        }
    }

    /// Checks the grid before any run starts: its size, and every value of every list
    /// through the run set-up (each α with the first ρ and Ω/ω, and so on, for each
    /// model), so that a bad value is reported with its flag at once, not as a failure of
    /// a run hours later.
    pub fn validate(&self) -> Result<()> {
        let runs = self.models.len() as f64
            * self.alphas.len() as f64
            * self.frictions.len() as f64
            * self.freq_ratios.len() as f64;
        if runs > MAX_SWEEP_RUNS as f64 {
            return Err(Error::invalid(
                "--alpha/--friction/--freq-ratios",
                format!("the grid has {runs:e} runs; a sweep may have at most {MAX_SWEEP_RUNS}"),
            ));
        }
        let (Some(&a0), Some(&f0), Some(&r0)) = (
            self.alphas.first(),
            self.frictions.first(),
            self.freq_ratios.first(),
        ) else {
            return Err(Error::invalid(
                "--alpha/--friction/--freq-ratios",
                "a list is empty",
            ));
        };
        for &model in &self.models {
            let points = self
                .alphas
                .iter()
                .map(|&a| (a, f0, r0))
                .chain(self.frictions.iter().map(|&f| (a0, f, r0)))
                .chain(self.freq_ratios.iter().map(|&r| (a0, f0, r)));
            for (a, f, r) in points {
                self.spec(model, a, f, r)
                    .prepare()
                    .map_err(as_sweep_error)?;
            }
        }
        Ok(())
    }

    /// Runs of the whole grid (every model at every point; a shard runs a part of them).
    /// Call after [`SweepRequest::validate`], which bounds it.
    pub fn grid_runs(&self) -> usize {
        self.models.len() * self.alphas.len() * self.frictions.len() * self.freq_ratios.len()
    }

    /// Every (model, α, ρ, Ω/ω) of the grid (or of this request's shard), mass-spring
    /// first (it is quick).
    pub fn jobs(&self) -> Vec<(ModelKind, f64, f64, f64)> {
        let mut jobs = Vec::new();
        for &model in &self.models {
            for &alpha in &self.alphas {
                for &friction in &self.frictions {
                    for &ratio in &self.freq_ratios {
                        jobs.push((model, alpha, friction, ratio));
                    }
                }
            }
        }
        match self.shard {
            // Interleaved, so every shard gets a fair mix of quick and slow runs.
            Some((i, n)) => jobs
                .into_iter()
                .enumerate()
                .filter(|(k, _)| k % n == i - 1)
                .map(|(_, j)| j)
                .collect(),
            None => jobs,
        }
    }
}

/// Runs the grid in parallel (rayon's pool); `tick` is called after each finished run.
pub fn run_sweep(
    req: &SweepRequest,
    tick: &(dyn Fn() + Sync),
) -> (Vec<SweepRow>, Vec<SweepFailure>) {
    let results: Vec<std::result::Result<SweepRow, SweepFailure>> = req
        .jobs()
        .par_iter()
        .map(|&(model, alpha, friction, freq_ratio)| {
            let request = req.spec(model, alpha, friction, freq_ratio);
            let out = run(&request);
            tick();
            let failure = |message: String| SweepFailure {
                model,
                alpha,
                friction,
                freq_ratio,
                message,
            };
            let o = out.map_err(|e| failure(e.to_string()))?;
            let s = &o.summary;
            match (
                s.us_max_over_d,
                s.ur_max_over_d,
                s.abase_over_aground,
                s.aroof_over_aground,
            ) {
                (Some(us), Some(ur), Some(ab), Some(ar)) if s.energy_residual_rel.is_finite() => {
                    Ok(SweepRow {
                        model: model.label().to_string(),
                        alpha,
                        friction,
                        freq_ratio,
                        damping: req.damping.unwrap_or(0.0),
                        us_max_over_d: us,
                        ur_max_over_d: ur,
                        abase_over_aground: ab,
                        aroof_over_aground: ar,
                        steps: s.steps,
                        wall_time_s: s.wall_time_s,
                        energy_residual_rel: s.energy_residual_rel,
                        amplitude_g: Some(s.amplitude_g),
                        duration_s: Some(s.duration_s),
                        dt_s: s.dt_s,
                        integrator: s.integrator.clone(),
                        grid_runs: Some(req.grid_runs() as u64),
                    })
                }
                _ => Err(failure(format!(
                    "a metric is undefined for this run ({})",
                    s.warnings.join("; ")
                ))),
            }
        })
        .collect();
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for r in results {
        match r {
            Ok(row) => rows.push(row),
            Err(f) => failures.push(f),
        }
    }
    (rows, failures)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_spaced_ratios_match_the_paper_grid() {
        let r = parse_ratios("--freq-ratios", "0.1:10:25").unwrap();
        assert_eq!(r.len(), 25);
        assert!((r[0] - 0.1).abs() < 1e-15 && (r[24] - 10.0).abs() < 1e-12);
        assert!((r[12] - 1.0).abs() < 1e-12, "the middle point is resonance");
        assert!(parse_ratios("--freq-ratios", "0:1:3").is_err());
        assert_eq!(
            parse_ratios("--freq-ratios", "0.5,2").unwrap(),
            vec![0.5, 2.0]
        );
        assert!(parse_list("--alpha", "0.1,x").is_err());
        // Left-out values, repeated values and a range that drops an end are refused.
        for bad in ["0.5,", ",0.5", "0.5,,0.6", "0.5,0.5", " "] {
            assert!(parse_list("--alpha", bad).is_err(), "{bad}");
        }
        for bad in ["0.1:10:1", "1:1:3", "0.5,2,0.5"] {
            assert!(parse_ratios("--freq-ratios", bad).is_err(), "{bad}");
        }
        assert_eq!(parse_ratios("--freq-ratios", "2:2:1").unwrap(), vec![2.0]);
    }

    #[test]
    fn the_paper_grid_contains_the_key_ratios() {
        let r = parse_ratios("--freq-ratios", "paper").unwrap();
        let log = parse_ratios("--freq-ratios", "0.1:10:25").unwrap();
        assert_eq!(r.len(), 25);
        for key in KEY_RATIOS.iter().chain(&[0.1, 1.0, 10.0]) {
            assert!(r.iter().any(|x| (x - key).abs() < 1e-12), "{key} missing");
        }
        // Only three points moved, each by less than half a grid interval (×10^(1/24)).
        let moved: Vec<f64> = r
            .iter()
            .zip(&log)
            .filter(|(a, b)| a != b)
            .map(|(a, b)| a / b)
            .collect();
        assert_eq!(moved.len(), 3);
        assert!(moved.iter().all(|m| m.log10().abs() < 1.0 / 24.0));
        assert!(r.windows(2).all(|w| w[0] < w[1]), "still increasing");
    }

    /// The shards of a grid are disjoint and together are the whole grid.
    #[test]
    fn shards_partition_the_grid() {
        let mut req = SweepRequest {
            alphas: vec![0.1, 0.5],
            frictions: vec![0.05, 0.1, 0.25],
            freq_ratios: vec![0.5, 1.0, 2.0],
            amplitude_g: 0.3,
            damping: None,
            duration: Some(1.0),
            dt: None,
            integrator: None,
            confirm_large: false,
            models: vec![ModelKind::MassSpring, ModelKind::Dda],
            shard: None,
        };
        let all = req.jobs();
        let mut joined = Vec::new();
        for i in 1..=4 {
            req.shard = Some((i, 4));
            joined.extend(req.jobs());
        }
        assert_eq!(joined.len(), all.len());
        for j in &all {
            assert_eq!(joined.iter().filter(|k| *k == j).count(), 1);
        }
        assert_eq!(parse_shard("3/8").unwrap(), (3, 8));
        for bad in ["0/4", "5/4", "x/4", "3"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        // More shards than runs: the last ones are empty (a job array of fixed size over
        // a small grid), which the command line says.
        assert_eq!(req.grid_runs(), 36);
        req.shard = Some((37, 37));
        assert!(req.jobs().is_empty());
    }
}
