//! How a long run tells how far it has come (the command line prints it on stderr), and
//! how long it has still to go.

use std::fmt;
use std::sync::Arc;

use crate::ground_motion::GroundMotion;

/// How far a run has come.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunProgress {
    /// Simulated time reached, s.
    pub time_s: f64,
    /// Simulated time the run goes to, s.
    pub duration_s: f64,
    /// Steps taken.
    pub steps: u64,
    /// Steps cut for convergence so far (see [`crate::dda::RunCounters::cuts`]).
    pub cuts: u64,
    /// Wall-clock time since the run started, s.
    pub elapsed_s: f64,
    /// Wall-clock time still to go, s, as [`RemainingTime`] estimates it (`None` before
    /// any simulated time has passed); while `harder_shaking_ahead`, the pace so far,
    /// which the run will likely exceed.
    pub remaining_s: Option<f64>,
    /// The ground has still to shake much harder than it has so far (see
    /// [`RemainingTime::harder_shaking_ahead`]): nothing so far tells what the strong
    /// motion costs, and `remaining_s` is then the pace so far, which it will likely
    /// exceed (not a bound: a step's cost does not grow with every stronger shake).
    pub harder_shaking_ahead: bool,
}

impl RunProgress {
    /// Fraction of the simulated time done, 0 to 1.
    pub fn fraction(&self) -> f64 {
        if self.duration_s > 0.0 {
            (self.time_s / self.duration_s).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }
}

impl fmt::Display for RunProgress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "t = {:.1} of {:.1} s ({:.0} %), {} steps, {} Δt cuts, {:.0} s so far",
            self.time_s,
            self.duration_s,
            100.0 * self.fraction(),
            self.steps,
            self.cuts,
            self.elapsed_s
        )?;
        match (self.remaining_s, self.harder_shaking_ahead) {
            (Some(left), _) if left < 0.5 => write!(f, ", under a second to go")?,
            (Some(left), false) => write!(f, ", about {left:.0} s to go")?,
            (Some(left), true) => write!(
                f,
                ", {left:.0} s to go at the pace so far, likely more (harder shaking is still \
                 to come)"
            )?,
            (None, _) => {}
        }
        Ok(())
    }
}

/// Most points of the shaking's running integral kept (2¹⁶: 1 ms apart up to 65 s of
/// run; a longer run spaces them wider).
const MAX_INTENSITY_POINTS: usize = 1 << 16;

/// How much harder, on average, the shaking still to come must be than the shaking so far
/// for the time left to be given as a lower bound (see
/// [`RemainingTime::harder_shaking_ahead`]).
pub const HARDER_AHEAD: f64 = 2.0;

/// Spacing of the running integral's points, s (a record's own sampling is 5–20 ms).
const INTENSITY_SPACING_S: f64 = 1e-3;

/// Estimates the wall-clock time a run has left from its pace so far and how strongly the
/// ground still has to shake.
///
/// A step's cost grows with the shaking: contacts that open, close and slip take more
/// passes and factorisations. The pace of a calm start therefore underestimates a strong
/// middle, and the pace of a strong middle overestimates a calm end (`wall:30` under Kobe
/// took 416 s for its first 20 s and 123 s for its last 21 s). So the elapsed time is
/// modelled as `a·t + b·J(t)`, with `J(t) = ∫₀ᵗ |a_g| dτ` the shaking done by simulated time
/// `t`, and `a, b ≥ 0` fitted by least squares to the reports so far. The time left is
/// then `a·(T − t) + b·(J(T) − J(t))`.
///
/// Measured under all of Kobe, reports every 5 s, over the reports with more than 10 s
/// left (docs/performance-log.md): on `wall:30` the estimate was 0.39–1.56 times the true
/// time left, median 1.20, where the plain pace was 0.38–3.17 times, median 2.37; on
/// `wall:20` 0.56–1.41 (median 1.25) against 0.56–2.80 (2.12). Under steady shaking (a
/// harmonic) `J` grows like `t` and the estimate is the pace.
///
/// Before the strong motion nothing so far tells its cost, and the fit then swings both
/// ways (`wall:30` under Kobe, stop 59: 0.37, 3.82, 0.37, 0.42, 0.76, then 1.08–1.36 times
/// the truth in the last second before the strong motion, where the cost of a step
/// saturates). While the shaking still to come is [`HARDER_AHEAD`] times the shaking so
/// far, the time left is therefore the pace so far, said to be "likely more": the shaking
/// ahead usually costs more a second than the shaking done (0.35–0.93 times the truth in
/// that run; 0.53–0.96 on `wall:30` under Northridge, Sylmar 032, stop 61, whose fit was
/// then 0.88–1.75 times the truth, median 1.04). It is not a bound: a step's cost does not
/// grow with every stronger shake (`wall:15` on the first 14 s of Kobe had 4.2 s left
/// where the pace said 5 s).
#[derive(Debug, Clone)]
pub struct RemainingTime {
    /// J at `spacing_s` apart from t = 0, in m/s.
    cumulative: Vec<f64>,
    spacing_s: f64,
    duration_s: f64,
    /// Σt², Σt·J, ΣJ², Σt·E, ΣJ·E over the reports (E the elapsed time).
    sums: [f64; 5],
}

impl RemainingTime {
    /// For a run of `duration_s` of simulated time under `motion` (its horizontal
    /// shaking; a vertical one adds little to the contacts' work).
    pub fn new(motion: &GroundMotion, duration_s: f64) -> Self {
        // Not finite: J stays zero and no time left is estimated.
        let span = if duration_s.is_finite() {
            duration_s.max(0.0)
        } else {
            0.0
        };
        let intervals =
            ((span / INTENSITY_SPACING_S).ceil() as usize).clamp(1, MAX_INTENSITY_POINTS - 1);
        let spacing_s = span / intervals as f64;
        let mut cumulative = Vec::with_capacity(intervals + 1);
        let mut total = 0.0;
        let mut last = motion.accel(0.0).abs();
        cumulative.push(0.0);
        for i in 1..=intervals {
            let next = motion.accel(i as f64 * spacing_s).abs();
            total += 0.5 * (last + next) * spacing_s;
            cumulative.push(total);
            last = next;
        }
        Self {
            cumulative,
            spacing_s,
            duration_s,
            sums: [0.0; 5],
        }
    }

    /// The shaking done by simulated time `t`, J(t) (interpolated between the points).
    fn shaking_until(&self, t: f64) -> f64 {
        let last = self.cumulative.len() - 1;
        if last == 0 || self.spacing_s <= 0.0 {
            return 0.0;
        }
        let x = (t / self.spacing_s).clamp(0.0, last as f64);
        let i = (x.floor() as usize).min(last - 1);
        let (j0, j1) = (self.cumulative[i], self.cumulative[i + 1]);
        j0 + (x - i as f64) * (j1 - j0)
    }

    /// Takes in that `elapsed_s` of wall-clock time had passed at simulated time `time_s`,
    /// and returns the time left: the fit's, or while
    /// [`RemainingTime::harder_shaking_ahead`] the pace so far (likely below the truth).
    pub fn observe(&mut self, time_s: f64, elapsed_s: f64) -> Option<f64> {
        let (t, j, e) = (time_s, self.shaking_until(time_s), elapsed_s);
        for (sum, term) in self
            .sums
            .iter_mut()
            .zip([t * t, t * j, j * j, t * e, j * e])
        {
            *sum += term;
        }
        let (a, b) = self.fit()?;
        if !self.duration_s.is_finite() {
            return None;
        }
        if self.harder_shaking_ahead(t) {
            return Some((e / t * (self.duration_s - t)).max(0.0));
        }
        let left = a * (self.duration_s - t) + b * (self.shaking_until(self.duration_s) - j);
        Some(left.max(0.0))
    }

    /// Whether the shaking still to come after simulated time `time_s` is, on average, at
    /// least [`HARDER_AHEAD`] times as strong as the shaking so far (mean |a_g| over the
    /// rest of the run against over `[0, t]`). Before the strong motion of a record the
    /// fit has seen nothing of what it costs, and the time left is then given as the pace
    /// so far, "likely more" (see [`RemainingTime`]).
    pub fn harder_shaking_ahead(&self, time_s: f64) -> bool {
        let (t, end) = (time_s, self.duration_s);
        if !(t > 0.0 && end.is_finite() && end > t) {
            return false;
        }
        let (done, all) = (self.shaking_until(t), self.shaking_until(end));
        (all - done) / (end - t) >= HARDER_AHEAD * done / t
    }

    /// The least-squares `a, b ≥ 0`: the pair of the normal equations when both are
    /// non-negative, else the better of the fits by `t` alone and by `J` alone (with a
    /// single report, or no shaking yet, `t` and `J` cannot be told apart: the pace).
    fn fit(&self) -> Option<(f64, f64)> {
        let [stt, stj, sjj, ste, sje] = self.sums;
        if stt.is_nan() || stt <= 0.0 {
            return None;
        }
        let det = stt * sjj - stj * stj;
        if det > 1e-9 * stt * sjj {
            let (a, b) = ((ste * sjj - sje * stj) / det, (sje * stt - ste * stj) / det);
            if a >= 0.0 && b >= 0.0 {
                return Some((a, b));
            }
        }
        // Each one-variable fit leaves Σe² − (Σx·e)²/Σx²: the larger (Σx·e)²/Σx² fits better.
        // A tie (a single report, where both fit exactly) is the pace: by J alone, a first
        // report in a calm start would promise the strong motion at the calm pace.
        let by_time = (ste.max(0.0) / stt, 0.0);
        if sjj > 0.0 && sje * sje / sjj > (1.0 + 1e-9) * (ste * ste / stt) {
            return Some((0.0, sje.max(0.0) / sjj));
        }
        Some(by_time)
    }
}

/// Told how a run advances: first after `first_after_s` of wall-clock time, then every
/// `every_s` (a short run says nothing).
#[derive(Clone)]
pub struct ProgressReporter {
    /// Wall-clock time before the first report, s.
    pub first_after_s: f64,
    /// Wall-clock time between reports, s.
    pub every_s: f64,
    report: Arc<dyn Fn(&RunProgress) + Send + Sync>,
}

impl ProgressReporter {
    /// A reporter that calls `report`.
    pub fn new(
        first_after_s: f64,
        every_s: f64,
        report: impl Fn(&RunProgress) + Send + Sync + 'static,
    ) -> Self {
        Self {
            first_after_s,
            every_s,
            report: Arc::new(report),
        }
    }

    /// Reports `progress`.
    pub fn report(&self, progress: &RunProgress) {
        (self.report)(progress)
    }
}

impl fmt::Debug for ProgressReporter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ProgressReporter")
            .field("first_after_s", &self.first_after_s)
            .field("every_s", &self.every_s)
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_report_reads_as_a_sentence() {
        let p = RunProgress {
            time_s: 10.0,
            duration_s: 40.0,
            steps: 10_000,
            cuts: 3,
            elapsed_s: 20.0,
            remaining_s: Some(60.0),
            harder_shaking_ahead: false,
        };
        assert_eq!(p.fraction(), 0.25);
        let text = p.to_string();
        assert!(text.contains("t = 10.0 of 40.0 s (25 %)"), "{text}");
        assert!(text.contains("about 60 s to go"), "{text}");
        assert!(!text.contains("likely more"), "{text}");
        let early = RunProgress {
            harder_shaking_ahead: true,
            ..p
        };
        assert!(
            early.to_string().ends_with(
                "60 s to go at the pace so far, likely more (harder shaking is still to come)"
            ),
            "{early}"
        );
        // Nothing left to speak of is not "about 0 s" (nor "at least 0 s").
        let ending = RunProgress {
            remaining_s: Some(0.3),
            ..early
        };
        assert!(
            ending.to_string().ends_with("under a second to go"),
            "{ending}"
        );
        let start = RunProgress {
            remaining_s: None,
            ..p
        };
        assert!(!start.to_string().contains("to go"));
    }

    /// A quiet second, a strong second, a quiet second (record samples 10 ms apart).
    fn burst() -> GroundMotion {
        let accel = (0..=300)
            .map(|i| if (100..200).contains(&i) { 3.0 } else { 0.1 })
            .collect();
        GroundMotion::Record(Arc::new(
            crate::ground_motion::Record::new("burst", 0.01, accel).unwrap(),
        ))
    }

    /// A run whose cost is exactly `a·t + b·J(t)` is predicted exactly once two reports
    /// tell the terms apart: here late in the strong second, where the pace so far would
    /// overestimate the calm end 2.5 times.
    #[test]
    fn a_cost_that_follows_the_shaking_is_predicted_exactly() {
        let motion = burst();
        let mut estimate = RemainingTime::new(&motion, 3.0);
        let (a, b) = (2.0, 5.0);
        let elapsed = |e: &RemainingTime, t: f64| a * t + b * e.shaking_until(t);
        for t in [0.5, 1.0, 1.9] {
            let e = elapsed(&estimate, t);
            let left = estimate.observe(t, e).unwrap();
            if t == 0.5 {
                // One report cannot tell the terms apart: the pace.
                let pace = e * (3.0 - t) / t;
                assert!((left - pace).abs() < 1e-12 * pace, "{left} vs {pace}");
            }
            if t == 1.9 {
                let truth = elapsed(&estimate, 3.0) - e;
                assert!((left - truth).abs() < 1e-9 * truth, "{left} vs {truth}");
                let pace = e * (3.0 - t) / t;
                assert!(
                    pace > 2.0 * truth,
                    "the pace {pace} would have been close too"
                );
            }
        }
        // J by the trapezoidal rule on the record's own samples: 0.1 for 1 s, 3.0 for 1 s.
        assert!((estimate.shaking_until(2.0) - 3.1).abs() < 0.03);
    }

    /// Steady shaking: a cost proportional to the time is the pace so far, and no harder
    /// shaking lies ahead.
    #[test]
    fn under_a_harmonic_the_estimate_is_the_pace() {
        let motion =
            GroundMotion::Harmonic(crate::ground_motion::Harmonic::from_g_hz(0.3, 1.7).unwrap());
        let mut estimate = RemainingTime::new(&motion, 40.0);
        for t in [2.0, 5.0, 9.0, 14.0] {
            let left = estimate.observe(t, 3.0 * t).unwrap();
            let pace = 3.0 * (40.0 - t);
            assert!((left - pace).abs() < 1e-9 * pace, "t {t}: {left} vs {pace}");
            assert!(!estimate.harder_shaking_ahead(t), "t {t}");
        }
    }

    /// In the quiet second before the burst the shaking ahead is ~15 times the shaking so
    /// far (mean |a_g| 1.55 against 0.1 m/s²): flagged. Late in the burst what is left is
    /// milder than what was done: not flagged. At the start, and past the end, nothing is.
    #[test]
    fn harder_shaking_ahead_is_flagged_before_the_burst_only() {
        let estimate = RemainingTime::new(&burst(), 3.0);
        assert!(estimate.harder_shaking_ahead(0.5));
        assert!(estimate.harder_shaking_ahead(0.99));
        assert!(!estimate.harder_shaking_ahead(1.9));
        assert!(!estimate.harder_shaking_ahead(2.5));
        assert!(!estimate.harder_shaking_ahead(0.0));
        assert!(!estimate.harder_shaking_ahead(3.0));
    }

    /// A cost that saturates in the strong motion (as a wall's does once it factorises at
    /// every step): before it, the fit learns a large cost per unit of shaking from the
    /// shaking's rise and would promise more than three times the truth; the time left is
    /// the pace instead, a lower bound of the truth.
    #[test]
    fn before_the_strong_motion_the_time_left_is_a_lower_bound() {
        let accel = (0..=300)
            .map(|i| match i {
                0..50 => 0.1,
                50..100 => 0.2,
                100..200 => 3.0,
                _ => 0.1,
            })
            .collect();
        let motion = GroundMotion::Record(Arc::new(
            crate::ground_motion::Record::new("rising burst", 0.01, accel).unwrap(),
        ));
        // Wall-clock seconds per simulated second: 1 + 10 |a_g|, at most 4.
        let rate = |t: f64| (1.0 + 10.0 * motion.accel(t).abs()).min(4.0);
        let elapsed = |t: f64| -> f64 {
            let n = (t / 1e-4).round() as usize;
            (0..n).map(|i| rate((i as f64 + 0.5) * 1e-4) * 1e-4).sum()
        };
        let total = elapsed(3.0);
        let mut estimate = RemainingTime::new(&motion, 3.0);
        for t in [0.3, 0.6, 0.8, 0.95] {
            assert!(estimate.harder_shaking_ahead(t), "t {t}");
            let e = elapsed(t);
            let left = estimate.observe(t, e).unwrap();
            let pace = e / t * (3.0 - t);
            assert!(
                (left - pace).abs() < 1e-12 * pace,
                "t {t}: {left} vs {pace}"
            );
            assert!(left < total - e, "t {t}: {left} against {}", total - e);
        }
        let (a, b) = estimate.fit().unwrap();
        let fitted = a * 2.05 + b * (estimate.shaking_until(3.0) - estimate.shaking_until(0.95));
        assert!(
            fitted > 3.0 * (total - elapsed(0.95)),
            "the fit alone would have promised {fitted}"
        );
    }

    /// Before any shaking J is zero: the time alone fits, and a first report is the pace.
    #[test]
    fn without_shaking_yet_the_estimate_is_the_pace() {
        let still = GroundMotion::Record(Arc::new(
            crate::ground_motion::Record::new("still", 0.01, vec![0.0; 101]).unwrap(),
        ));
        let mut estimate = RemainingTime::new(&still, 4.0);
        assert_eq!(estimate.observe(0.0, 0.5), None);
        let left = estimate.observe(1.0, 2.0).unwrap();
        assert!((left - 6.0).abs() < 1e-12, "{left}");
        // A zero-length run has nothing left.
        let mut none = RemainingTime::new(&still, 0.0);
        assert_eq!(none.observe(0.0, 1.0), None);
    }
}
