//! The speed targets (issue 16; docs/performance.md) set beside what `slidebase bench`
//! measured, so that a run of the bench says by itself which goals this machine meets (and
//! a pipeline can read it from the JSON). Two targets take longer than a bench or need a
//! display; they are listed with the command that measures them.

use serde::Serialize;

use super::bench::{ExponentFit, Measurement, ScalingPoint, SweepTiming};

/// Which way a goal bounds the measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Bound {
    /// The measurement must not exceed the goal (a time).
    AtMost,
    /// The measurement must reach the goal (a speed).
    AtLeast,
}

/// One speed target against this run's measurement.
#[derive(Debug, Clone, Serialize)]
pub struct TargetCheck {
    /// What the target is about.
    pub target: &'static str,
    /// The goal, in `unit`.
    pub goal: f64,
    /// Whether the goal is an upper or a lower bound.
    pub bound: Bound,
    /// Unit of the goal and of the measurement.
    pub unit: &'static str,
    /// What this run measured, in `unit`; `None` when the bench does not measure it.
    pub measured: Option<f64>,
    /// How far the measurement is from the goal, as a factor: above 1 the goal is missed
    /// by that much (measured / goal for a time, goal / measured for a speed).
    pub off_by: Option<f64>,
    /// Whether the goal is met.
    pub met: Option<bool>,
    /// How to measure the target when this run did not.
    pub how: Option<&'static str>,
}

impl TargetCheck {
    fn new(target: &'static str, goal: f64, bound: Bound, unit: &'static str) -> Self {
        Self {
            target,
            goal,
            bound,
            unit,
            measured: None,
            off_by: None,
            met: None,
            how: None,
        }
    }

    /// With this run's measurement (a non-finite or non-positive one is left unmeasured).
    fn measured(mut self, value: Option<f64>) -> Self {
        if let Some(v) = value.filter(|v| v.is_finite() && *v > 0.0) {
            let off_by = match self.bound {
                Bound::AtMost => v / self.goal,
                Bound::AtLeast => self.goal / v,
            };
            self.measured = Some(v);
            self.off_by = Some(off_by);
            self.met = Some(off_by <= 1.0);
        }
        self
    }

    /// If this run did not measure it: `how` says how to.
    fn elsewhere(mut self, how: &'static str) -> Self {
        if self.measured.is_none() {
            self.how = Some(how);
        }
        self
    }
}

/// How the walls' targets are measured.
const WITH_SCALING: &str = "slidebase bench (without --quick or --no-scaling)";

/// The largest wall of the full scaling series, whose median step the target bounds.
const LARGEST_WALL: &str = "wall:31";

/// What the bench measured, for [`check`].
pub struct Measured<'a> {
    /// The timed workloads, by [`Measurement::key`].
    pub workloads: &'a [Measurement],
    /// The sweep, if run.
    pub sweep: Option<&'a SweepTiming>,
    /// The scaling series.
    pub scaling: &'a [ScalingPoint],
    /// The exponents fitted to it.
    pub exponents: &'a [ExponentFit],
    /// A `--quick` bench: a reduced sweep and scaling series, which the sweep's and the
    /// walls' targets are not about.
    pub quick: bool,
}

/// The targets, each with this run's measurement where the bench made it.
pub fn check(m: &Measured<'_>) -> Vec<TargetCheck> {
    let workload = |key: &str| {
        m.workloads
            .iter()
            .find(|w| w.key == key)
            .map(|w| w.median_s)
    };
    let full = |v: Option<f64>| if m.quick { None } else { v };
    let wall = m.scaling.iter().find(|p| p.scene == LARGEST_WALL);
    let walls_growth = m
        .exponents
        .iter()
        .find(|e| e.family == "wall")
        .and_then(|e| e.largest_pair_median);
    use Bound::{AtLeast, AtMost};
    vec![
        TargetCheck::new("two-block DDA, 100 s at Δt = 1 ms", 0.02, AtMost, "s")
            .measured(workload("two-block")),
        TargetCheck::new("three-storey El Centro, sliding base", 0.3, AtMost, "s")
            .measured(workload("three-storey-sliding")),
        TargetCheck::new("three-storey El Centro, fixed base", 0.3, AtMost, "s")
            .measured(workload("three-storey-fixed")),
        TargetCheck::new(
            "Figs 4–9 sweep, 300 points of both models",
            10.0,
            AtMost,
            "s",
        )
        .measured(full(m.sweep.map(|s| s.wall_s)))
        .elsewhere("slidebase bench (without --quick or --no-sweep)"),
        TargetCheck::new("wall:31 (978 blocks), median step", 1.0, AtMost, "ms")
            .measured(full(wall.map(|p| p.median_step_ms)))
            .elsewhere(WITH_SCALING),
        TargetCheck::new(
            "walls' step ∝ unknowns^k, k of the two largest",
            1.0,
            AtMost,
            "",
        )
        .measured(full(walls_growth))
        .elsewhere(WITH_SCALING),
        TargetCheck::new("wall:30 on all of Kobe", 60.0, AtMost, "s").elsewhere(
            "slidebase run --scene wall:30 --record kobe-nishi-akashi-000 (about 10 minutes)",
        ),
        TargetCheck::new(
            "the window's default scene, first run",
            30.0,
            AtLeast,
            "× real time",
        )
        .elsewhere("SLIDEBASE_EXIT_AFTER=20 slidebase (with a display, or under xvfb-run)"),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn workload(key: &'static str, median_s: f64) -> Measurement {
        Measurement {
            key,
            name: key.into(),
            runs: 1,
            median_s,
            min_s: median_s,
            steps: 1,
            steps_per_s: 1.0,
            simulated_s: 1.0,
            realtime_factor: 1.0,
        }
    }

    /// Times against upper bounds: the ratio is measured / goal, met at or below 1; what a
    /// quick bench or the bench at all does not measure is left open with how to measure it.
    #[test]
    fn each_target_is_met_missed_or_left_to_its_command() {
        let workloads = [
            workload("two-block", 0.2),
            workload("three-storey-sliding", 0.3),
            workload("three-storey-fixed", f64::NAN),
        ];
        let sweep = SweepTiming {
            runs_per_model: 300,
            threads: 2,
            wall_s: 5.0,
            dda_run_time_s: 9.0,
            exact_run_time_s: 1.0,
            failures: 0,
        };
        let m = Measured {
            workloads: &workloads,
            sweep: Some(&sweep),
            scaling: &[],
            exponents: &[],
            quick: false,
        };
        let checks = check(&m);
        let by = |name: &str| checks.iter().find(|t| t.target.starts_with(name)).unwrap();
        let two_block = by("two-block");
        assert_eq!(two_block.measured, Some(0.2));
        assert!((two_block.off_by.unwrap() - 10.0).abs() < 1e-12);
        assert_eq!(two_block.met, Some(false));
        assert_eq!(by("three-storey El Centro, sliding").met, Some(true));
        // A failed (non-finite) measurement is not a measurement.
        assert_eq!(by("three-storey El Centro, fixed").met, None);
        let swept = by("Figs 4–9");
        assert_eq!((swept.met, swept.how), (Some(true), None));
        assert_eq!(by("wall:31").met, None);
        let kobe = by("wall:30");
        assert_eq!(kobe.met, None);
        assert!(kobe.how.unwrap().contains("--record kobe-nishi-akashi-000"));
        assert_eq!(by("the window").bound, Bound::AtLeast);
        // A quick bench's reduced sweep is not the target's sweep.
        let quick = check(&Measured { quick: true, ..m });
        let swept = quick.iter().find(|t| t.target.starts_with("Figs")).unwrap();
        assert_eq!(swept.met, None);
        assert!(swept.how.unwrap().contains("without --quick or --no-sweep"));
    }

    /// A speed's goal is a lower bound: 45× against 30× is met, off by 30/45.
    #[test]
    fn a_speed_is_met_from_below() {
        let t = TargetCheck::new("speed", 30.0, Bound::AtLeast, "×").measured(Some(45.0));
        assert_eq!(t.met, Some(true));
        assert!((t.off_by.unwrap() - 30.0 / 45.0).abs() < 1e-12);
        let slow = TargetCheck::new("speed", 30.0, Bound::AtLeast, "×").measured(Some(20.0));
        assert_eq!(slow.met, Some(false));
    }
}
