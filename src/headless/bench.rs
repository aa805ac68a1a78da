//! `slidebase bench`: how fast the solver is, measured the same way every time.
//!
//! Each workload is run several times and reported by its median (these machines are
//! shared and noisy; the minimum is given too). The scaling series runs generated scenes
//! of growing size (`frame:N`, `wall:N`) for a fixed window of simulated time and fits the
//! exponent of time per step against the number of unknowns.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::frame::run_frame;
use super::run::run;
use super::sweep::{SweepRequest, paper_ratios, parse_ratios, run_sweep};
use super::targets::{self, Bound, TargetCheck};
use crate::dda::{Dda, SolverParams};
use crate::ground_motion::{GroundMotion, Record, resolve_record};
use crate::model::Scene;
use crate::model::presets::resolve_scene;
use crate::post::output::Staged;
use crate::post::plot::{Figure, LegendCorner, Series};
use crate::setup::{ModelKind, RunSpec};
use crate::{Error, Result};

/// What to measure.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Fewer repeats, shorter windows, smaller scaling series and a reduced sweep.
    pub quick: bool,
    /// Repeats of each timed workload (the median is reported); also with `quick`
    /// (the command line's default is 3 there, 5 otherwise).
    pub repeats: usize,
    /// Threads for the sweep (0: all cores).
    pub jobs: usize,
    /// Run the Figs 4–9 sweep (the longest workload).
    pub sweep: bool,
    /// Run the scaling series.
    pub scaling: bool,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            quick: false,
            repeats: 5,
            jobs: 0,
            sweep: true,
            scaling: true,
        }
    }
}

/// One timed workload.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    /// Which workload, for the targets (`two-block`, `exact`, `three-storey-sliding`,
    /// `three-storey-fixed`).
    pub key: &'static str,
    /// What was run.
    pub name: String,
    /// How many times.
    pub runs: usize,
    /// Median wall time of one run, s.
    pub median_s: f64,
    /// Fastest run, s.
    pub min_s: f64,
    /// Time steps of one run (DDA) or propagation steps (exact model).
    pub steps: u64,
    /// Steps per second at the median.
    pub steps_per_s: f64,
    /// Simulated time of one run, s.
    pub simulated_s: f64,
    /// Simulated time / wall time at the median.
    pub realtime_factor: f64,
}

/// The Figs 4–9 sweep, timed.
#[derive(Debug, Clone, Serialize)]
pub struct SweepTiming {
    /// Runs of each model.
    pub runs_per_model: usize,
    /// Threads used.
    pub threads: usize,
    /// Wall time of the whole sweep, s.
    pub wall_s: f64,
    /// Sum of the DDA runs' own wall times, s: the sweep's work in single-run time (on
    /// a shared machine more than the CPU time it took, as each run's clock also counts
    /// the moments its thread waited for a core).
    pub dda_run_time_s: f64,
    /// Sum of the exact runs' own wall times, s (see `dda_run_time_s`).
    pub exact_run_time_s: f64,
    /// Runs that failed.
    pub failures: usize,
}

/// One point of the scaling series.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingPoint {
    /// Scene (`frame:N`, `wall:N`).
    pub scene: String,
    /// Family (`frame` or `wall`).
    pub family: String,
    /// Blocks (the ground included).
    pub blocks: usize,
    /// Unknowns of the system.
    pub unknowns: usize,
    /// Contacts found in the last step.
    pub contacts: usize,
    /// Model set-up and static settling, s.
    pub setup_s: f64,
    /// Steps timed (in each run).
    pub steps: u64,
    /// Runs of the window (see [`scaling_point`]); the times are their medians.
    pub runs: usize,
    /// Mean wall time per step, ms.
    pub mean_step_ms: f64,
    /// Median wall time per step, ms.
    pub median_step_ms: f64,
    /// Factorisations of the system matrix in the window.
    pub factorizations: u64,
}

/// Least-squares fit of log(time per step) against log(unknowns).
#[derive(Debug, Clone, Serialize)]
pub struct ExponentFit {
    /// Which points.
    pub family: String,
    /// Fitted exponent of the mean time per step (1 = linear).
    pub exponent: f64,
    /// Fitted exponent of the median time per step: the typical step, without the rare
    /// ones that factorise the matrix again (after a step cut or landed on an event).
    pub exponent_median: f64,
    /// The slope of the median time per step between the family's two largest models:
    /// the growth where the models are largest. The fit over all points is pulled down
    /// by the small models' fixed costs per step, and can read linear while the large end
    /// is not.
    pub largest_pair_median: Option<f64>,
    /// Points in the fit.
    pub points: usize,
}

/// Everything `slidebase bench` measured.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Cores seen by the program.
    pub cores: usize,
    /// A quick bench (`--quick`): shorter windows, a smaller scaling series and sweep,
    /// so its numbers are not the targets' (which it says).
    pub quick: bool,
    /// Repeats of each timed workload.
    pub repeats: usize,
    /// The timed workloads.
    pub workloads: Vec<Measurement>,
    /// The sweep, if run.
    pub sweep: Option<SweepTiming>,
    /// The scaling series.
    pub scaling: Vec<ScalingPoint>,
    /// Exponents of time per step against unknowns.
    pub exponents: Vec<ExponentFit>,
    /// The speed targets (issue 16, docs/performance.md) against this run's measurements.
    pub targets: Vec<TargetCheck>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Runs `f` `repeats` times; `f` returns (wall time, steps, simulated time).
fn measure(
    key: &'static str,
    name: &str,
    repeats: usize,
    mut f: impl FnMut() -> Result<(f64, u64, f64)>,
) -> Result<Measurement> {
    let mut times = Vec::with_capacity(repeats);
    let (mut steps, mut simulated) = (0, 0.0);
    for _ in 0..repeats.max(1) {
        let (t, s, sim) = f()?;
        times.push(t);
        (steps, simulated) = (s, sim);
    }
    let min_s = times.iter().copied().fold(f64::INFINITY, f64::min);
    let median_s = median(times.clone());
    Ok(Measurement {
        key,
        name: name.into(),
        runs: times.len(),
        median_s,
        min_s,
        steps,
        steps_per_s: steps as f64 / median_s,
        simulated_s: simulated,
        realtime_factor: simulated / median_s,
    })
}

/// The paper's two-block model (α = 0.5, ρ = 0.1, resonance, 0.3 g, 100 s).
fn two_block(model: ModelKind) -> Result<(f64, u64, f64)> {
    let req = RunSpec {
        duration: Some(100.0),
        model,
        ..RunSpec::default()
    };
    let start = Instant::now();
    let o = run(&req)?;
    Ok((start.elapsed().as_secs_f64(), o.summary.steps, 100.0))
}

/// The three-storey frame on El Centro, Δt = 1 ms.
fn three_storey(fixed_base: bool) -> Result<(f64, u64, f64)> {
    let req = RunSpec {
        fixed_base,
        ..RunSpec::scene("three-storey")
    };
    let start = Instant::now();
    let o = run_frame(&req)?;
    Ok((
        start.elapsed().as_secs_f64(),
        o.summary.steps,
        o.summary.duration_s,
    ))
}

/// A scaling point is run again until its runs have lasted this long in all: a small
/// wall's window is over in ~60 ms, and one slow stretch of this shared machine then
/// decided its median (wall:5 read 0.196 ms a step in one bench and 0.120 ms in the
/// next, which moved the fitted exponent by 0.07).
const SCALING_MIN_TOTAL_S: f64 = 1.0;

/// At most this many runs of a scaling point.
const SCALING_MAX_RUNS: usize = 9;

/// One timed run of a scaling point's window.
struct WindowRun {
    setup_s: f64,
    total_s: f64,
    mean_step_ms: f64,
    median_step_ms: f64,
    steps: u64,
    factorizations: u64,
}

/// One scaling point: the scene under El Centro for `window` seconds after settling, run
/// until [`SCALING_MIN_TOTAL_S`] have passed (at most [`SCALING_MAX_RUNS`] runs; every
/// run takes the same steps), reported by the medians over the runs.
pub fn scaling_point(scene_name: &str, window: f64) -> Result<ScalingPoint> {
    let scene = resolve_scene(scene_name)?;
    let record = Arc::new(resolve_record("el-centro")?);
    let (first, dda) = time_window(&scene, &record, window)?;
    let mut elapsed = first.setup_s + first.total_s;
    let mut runs = vec![first];
    while elapsed < SCALING_MIN_TOTAL_S && runs.len() < SCALING_MAX_RUNS {
        let (run, _) = time_window(&scene, &record, window)?;
        elapsed += run.setup_s + run.total_s;
        runs.push(run);
    }
    let over_runs = |f: fn(&WindowRun) -> f64| median(runs.iter().map(f).collect());
    Ok(ScalingPoint {
        scene: scene_name.into(),
        family: scene_name.split(':').next().unwrap_or("").into(),
        blocks: dda.blocks().len(),
        unknowns: dda.unknowns(),
        contacts: dda.last_report().contacts,
        setup_s: over_runs(|r| r.setup_s),
        steps: runs[0].steps,
        runs: runs.len(),
        mean_step_ms: over_runs(|r| r.mean_step_ms),
        median_step_ms: over_runs(|r| r.median_step_ms),
        factorizations: runs[0].factorizations,
    })
}

/// Sets the scene up, settles it and times each step of `window` seconds of `record`;
/// also returns the model (for its size and last contacts).
fn time_window(scene: &Scene, record: &Arc<Record>, window: f64) -> Result<(WindowRun, Dda)> {
    let setup = Instant::now();
    let mut dda = Dda::new(
        scene,
        Some(GroundMotion::Record(Arc::clone(record))),
        SolverParams {
            duration: window,
            ..SolverParams::for_scene(scene)
        },
    )?;
    let setup_s = setup.elapsed().as_secs_f64();
    let before = dda.counters();
    let mut step_times = Vec::new();
    let start = Instant::now();
    let mut last = Instant::now();
    dda.run_until(window, |_, _| {
        let now = Instant::now();
        step_times.push(now.duration_since(last).as_secs_f64());
        last = now;
    })?;
    let total_s = start.elapsed().as_secs_f64();
    let after = dda.counters();
    let steps = after.steps - before.steps;
    let run = WindowRun {
        setup_s,
        total_s,
        mean_step_ms: 1e3 * total_s / steps.max(1) as f64,
        median_step_ms: 1e3 * median(step_times),
        steps,
        factorizations: after.factorizations - before.factorizations,
    };
    Ok((run, dda))
}

/// Least-squares slope of log(y) against log(x) (the same fit as the observed order of
/// convergence).
pub fn fit_exponent(points: &[(f64, f64)]) -> Option<f64> {
    super::accuracy::observed_order(points, 0.0)
}

/// The log-log slope between the two points of largest x (the same fit as
/// [`fit_exponent`], on those two).
fn largest_pair_slope(points: &[(f64, f64)]) -> Option<f64> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    fit_exponent(&sorted[sorted.len().saturating_sub(2)..])
}

/// Runs the benchmark; `progress` is told what runs next.
pub fn run_bench(options: &BenchOptions, progress: &dyn Fn(&str)) -> Result<BenchReport> {
    let repeats = options.repeats;
    let mut workloads = Vec::new();
    progress("two-block DDA, 100 s");
    workloads.push(measure(
        "two-block",
        "two-block DDA (α = 0.5, ρ = 0.1, Ω = ω, 0.3 g), 100 s, Δt = 1 ms",
        repeats,
        || two_block(ModelKind::Dda),
    )?);
    progress("two-block exact model, 100 s");
    workloads.push(measure(
        "exact",
        "two-block exact mass-spring model, 100 s",
        repeats,
        || two_block(ModelKind::MassSpring),
    )?);
    progress("three-storey El Centro, sliding base");
    workloads.push(measure(
        "three-storey-sliding",
        "three-storey El Centro, sliding base (ρ = 0.01), Δt = 1 ms",
        repeats,
        || three_storey(false),
    )?);
    progress("three-storey El Centro, fixed base");
    workloads.push(measure(
        "three-storey-fixed",
        "three-storey El Centro, fixed base, Δt = 1 ms",
        repeats,
        || three_storey(true),
    )?);
    let sweep = if options.sweep {
        progress("Figs 4–9 sweep");
        Some(time_sweep(options)?)
    } else {
        None
    };
    let mut scaling = Vec::new();
    if options.scaling {
        let (window, scenes): (f64, &[&str]) = if options.quick {
            (
                0.1,
                &[
                    "frame:3", "frame:10", "frame:20", "wall:5", "wall:10", "wall:20",
                ],
            )
        } else {
            (
                0.5,
                &[
                    "frame:3", "frame:10", "frame:15", "frame:20", "wall:5", "wall:10", "wall:15",
                    "wall:22", "wall:31",
                ],
            )
        };
        for scene in scenes {
            progress(&format!("scaling: {scene}"));
            scaling.push(scaling_point(scene, window)?);
        }
    }
    let mut exponents = Vec::new();
    for family in ["frame", "wall", "all"] {
        let of = |f: fn(&ScalingPoint) -> f64| -> Vec<(f64, f64)> {
            scaling
                .iter()
                .filter(|p| family == "all" || p.family == family)
                .map(|p| (p.unknowns as f64, f(p)))
                .collect()
        };
        let (mean, med) = (of(|p| p.mean_step_ms), of(|p| p.median_step_ms));
        if let (Some(exponent), Some(exponent_median)) = (fit_exponent(&mean), fit_exponent(&med)) {
            exponents.push(ExponentFit {
                family: family.into(),
                exponent,
                exponent_median,
                largest_pair_median: largest_pair_slope(&med),
                points: mean.len(),
            });
        }
    }
    let targets = targets::check(&targets::Measured {
        workloads: &workloads,
        sweep: sweep.as_ref(),
        scaling: &scaling,
        exponents: &exponents,
        quick: options.quick,
    });
    Ok(BenchReport {
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        quick: options.quick,
        repeats,
        workloads,
        sweep,
        scaling,
        exponents,
        targets,
    })
}

/// The paper's grid (quick: a 2 × 2 × 5 corner of it), both models, on the thread pool.
fn time_sweep(options: &BenchOptions) -> Result<SweepTiming> {
    let (alphas, frictions, ratios) = if options.quick {
        (
            vec![0.1, 0.9],
            vec![0.05, 0.25],
            parse_ratios("", "0.1:10:5")?,
        )
    } else {
        (
            vec![0.1, 0.5, 0.9],
            vec![0.01, 0.05, 0.1, 0.25],
            paper_ratios(),
        )
    };
    let req = SweepRequest {
        alphas,
        frictions,
        freq_ratios: ratios,
        amplitude_g: 0.3,
        damping: None,
        duration: Some(100.0),
        dt: None,
        integrator: None,
        confirm_large: false,
        models: vec![ModelKind::MassSpring, ModelKind::Dda],
        shard: None,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs)
        .build()
        .map_err(|e| Error::invalid("--jobs", e.to_string()))?;
    let threads = pool.current_num_threads();
    let start = Instant::now();
    let (rows, failures) = pool.install(|| run_sweep(&req, &|| {}));
    let wall_s = start.elapsed().as_secs_f64();
    let run_time = |model: &str| {
        rows.iter()
            .filter(|r| r.model == model)
            .map(|r| r.wall_time_s)
            .sum()
    };
    Ok(SweepTiming {
        runs_per_model: req.jobs().len() / 2,
        threads,
        wall_s,
        dda_run_time_s: run_time("dda"),
        exact_run_time_s: run_time("mass-spring"),
        failures: failures.len(),
    })
}

/// The report as a text table.
pub fn report_text(r: &BenchReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "slidebase bench ({} cores)\n", r.cores);
    let _ = writeln!(
        s,
        "{:<66} {:>10} {:>10} {:>12} {:>9}",
        "workload", "median s", "min s", "steps/s", "× real"
    );
    for m in &r.workloads {
        let _ = writeln!(
            s,
            "{:<66} {:>10.4} {:>10.4} {:>12.0} {:>9.1}",
            m.name, m.median_s, m.min_s, m.steps_per_s, m.realtime_factor
        );
    }
    if let Some(sw) = &r.sweep {
        let _ = writeln!(
            s,
            "\nFigs 4–9 sweep: {} runs of each model on {} threads in {:.1} s wall \
             (DDA {:.1} s, exact {:.1} s of single-run time; {} failed)",
            sw.runs_per_model,
            sw.threads,
            sw.wall_s,
            sw.dda_run_time_s,
            sw.exact_run_time_s,
            sw.failures
        );
    }
    if !r.scaling.is_empty() {
        let _ = writeln!(
            s,
            "\n{:<10} {:>7} {:>9} {:>9} {:>9} {:>7} {:>5} {:>13} {:>15} {:>14}",
            "scene",
            "blocks",
            "unknowns",
            "contacts",
            "setup s",
            "steps",
            "runs",
            "mean ms/step",
            "median ms/step",
            "factorisations"
        );
        for p in &r.scaling {
            let _ = writeln!(
                s,
                "{:<10} {:>7} {:>9} {:>9} {:>9.3} {:>7} {:>5} {:>13.3} {:>15.3} {:>14}",
                p.scene,
                p.blocks,
                p.unknowns,
                p.contacts,
                p.setup_s,
                p.steps,
                p.runs,
                p.mean_step_ms,
                p.median_step_ms,
                p.factorizations
            );
        }
        for e in &r.exponents {
            let large = e.largest_pair_median.map_or(String::new(), |x| {
                format!("; ^{x:.2} between the two largest")
            });
            let _ = writeln!(
                s,
                "time per step ∝ unknowns^{:.2} (mean), ^{:.2} (median) ({}, {} points{large})",
                e.exponent, e.exponent_median, e.family, e.points
            );
        }
    }
    write_targets(&mut s, &r.targets);
    s
}

/// The targets as a table: goal, this run's measurement, how far off, met or not (or the
/// command that measures it).
fn write_targets(s: &mut String, checks: &[TargetCheck]) {
    let _ = writeln!(
        s,
        "\nSpeed targets (docs/performance.md) on this machine:\n\
         {:<48} {:>18} {:>12} {:>8}  met",
        "target", "goal", "measured", "off by"
    );
    for t in checks {
        let sign = match t.bound {
            Bound::AtMost => "≤",
            Bound::AtLeast => "≥",
        };
        let goal = format!("{sign} {} {}", t.goal, t.unit);
        let _ = match (t.measured, t.off_by, t.met) {
            (Some(v), Some(off), Some(met)) => writeln!(
                s,
                "{:<48} {:>18} {:>12} {:>7.1}×  {}",
                t.target,
                goal.trim_end(),
                format!("{v:.4} {}", t.unit).trim_end(),
                off,
                if met { "yes" } else { "no" }
            ),
            _ => writeln!(
                s,
                "{:<48} {:>18}  not measured here: {}",
                t.target,
                goal.trim_end(),
                t.how.unwrap_or("-")
            ),
        };
    }
}

/// Writes `bench.json`, `scaling.csv` and `scaling.png` into `out`.
pub fn write_bench(r: &BenchReport, out: &Path) -> Result<Vec<PathBuf>> {
    let mut staged = Staged::new(out)?;
    staged.write_json("bench.json", r)?;
    if r.scaling.is_empty() {
        return staged.commit();
    }
    staged.write_csv("scaling.csv", &r.scaling)?;
    let mut fig = Figure::new("Time per step against the size of the model", 1, 1);
    let p = &mut fig.panels[0];
    p.x_label = "unknowns (6 per block)".into();
    p.y_label = "wall time per step (ms)".into();
    p.x_log = true;
    p.y_log = true;
    // The cost rises to the right: the top-left corner is empty.
    p.legend = LegendCorner::UpperLeft;
    for (k, family) in ["frame", "wall"].iter().enumerate() {
        let pts: Vec<&ScalingPoint> = r.scaling.iter().filter(|p| p.family == *family).collect();
        if pts.is_empty() {
            continue;
        }
        let exponent =
            r.exponents
                .iter()
                .find(|e| e.family == *family)
                .map_or(String::new(), |e| {
                    let large = e
                        .largest_pair_median
                        .map_or(String::new(), |x| format!("; n^{x:.2} at the large end"));
                    format!(
                        " (∝ n^{:.2} mean, n^{:.2} median{large})",
                        e.exponent, e.exponent_median
                    )
                });
        let label = match *family {
            "frame" => format!("N-storey frames{exponent}"),
            _ => format!("walls of N courses{exponent}"),
        };
        p.series.push(Series::markers(
            format!("{label}, mean"),
            pts.iter().map(|p| p.unknowns as f64).collect(),
            pts.iter().map(|p| p.mean_step_ms).collect(),
            k,
        ));
        p.series.push(Series::line(
            format!("{label}, median"),
            pts.iter().map(|p| p.unknowns as f64).collect(),
            pts.iter().map(|p| p.median_step_ms).collect(),
            k,
        ));
    }
    // A linear reference through the smallest point.
    if let Some(first) = r.scaling.iter().min_by_key(|p| p.unknowns) {
        let largest = r
            .scaling
            .iter()
            .map(|p| p.unknowns)
            .max()
            .unwrap_or(first.unknowns);
        let x = vec![first.unknowns as f64, largest as f64];
        let y = x
            .iter()
            .map(|v| first.mean_step_ms * v / first.unknowns as f64)
            .collect();
        p.series.push(Series::line("linear", x, y, 6));
    }
    fig.save_png(&staged.path("scaling.png"), 1000, 700)?;
    staged.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [10.0, 100.0, 1000.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.3)))
            .collect();
        let e = fit_exponent(&pts).unwrap();
        assert!((e - 1.3).abs() < 1e-12);
        assert!(fit_exponent(&pts[..1]).is_none());
    }

    /// A fixed cost per step plus a superlinear part: the fit over all sizes reads near
    /// linear, the two largest show the growth (the walls' case: 0.98 against ~1.3).
    #[test]
    fn the_largest_pair_shows_what_a_fixed_cost_hides() {
        let pts: Vec<(f64, f64)> = [5000.0, 100.0, 1000.0, 10.0]
            .iter()
            .map(|&x: &f64| (x, 1.0 + 1e-4 * x.powf(1.5)))
            .collect();
        let all = fit_exponent(&pts).unwrap();
        let large = largest_pair_slope(&pts).unwrap();
        let exact = (1.0 + 1e-4 * 5000f64.powf(1.5)).ln() - (1.0 + 1e-4 * 1000f64.powf(1.5)).ln();
        assert!((large - exact / 5f64.ln()).abs() < 1e-12);
        assert!(all < 0.6 && large > 1.3, "fit {all}, largest pair {large}");
        assert!(largest_pair_slope(&pts[..1]).is_none());
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
