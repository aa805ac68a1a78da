//! How a long run tells how far it has come (the command line prints it on stderr).

use std::fmt;
use std::sync::Arc;

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

    /// Wall-clock time still to go if the rest runs at the pace so far, s (`None` before
    /// any simulated time has passed).
    pub fn remaining_s(&self) -> Option<f64> {
        let done = self.fraction();
        (done > 0.0).then(|| self.elapsed_s * (1.0 - done) / done)
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
        if let Some(left) = self.remaining_s() {
            write!(f, ", about {left:.0} s to go")?;
        }
        Ok(())
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
    fn the_time_to_go_is_the_pace_so_far() {
        let p = RunProgress {
            time_s: 10.0,
            duration_s: 40.0,
            steps: 10_000,
            cuts: 3,
            elapsed_s: 20.0,
        };
        assert_eq!(p.fraction(), 0.25);
        assert_eq!(p.remaining_s(), Some(60.0));
        let text = p.to_string();
        assert!(text.contains("t = 10.0 of 40.0 s (25 %)"), "{text}");
        assert!(text.contains("about 60 s to go"), "{text}");
        let start = RunProgress { time_s: 0.0, ..p };
        assert_eq!(start.remaining_s(), None);
    }
}
