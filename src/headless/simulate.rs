//! Running a prepared setup: the DDA model of any scene, or the exact two-mass model, with
//! the same peaks, counters and time histories, so that they compare point by point.

use std::time::Instant;

use crate::Result;
use crate::analytic::ExactResult;
use crate::dda::{CutReasons, RunCounters, SolverParams};
use crate::ground_motion::GroundMotion;
use crate::limits::MAX_HISTORY_ROWS;
use crate::model::Scene;
use crate::post::filter::{self, CellAverages};
use crate::post::history::{History, PeakTracker};
use crate::post::spectrum::UniformSeries;
use crate::setup::{ModelKind, RemainingTime, RunProgress, RunSetup};

/// Peak responses of a run, SI units.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Peaks {
    /// max |u_s|: base slip relative to the ground, m.
    pub slip_m: f64,
    /// max |u_r|: roof relative to the base, m.
    pub drift_m: f64,
    /// max |absolute base acceleration|, m/s².
    pub base_accel: f64,
    /// max |absolute roof acceleration|, m/s².
    pub roof_accel: f64,
    /// max |ground acceleration| over the run, m/s².
    pub ground_accel: f64,
}

/// Result of one run.
#[derive(Debug, Clone)]
pub struct ModelRun {
    /// Which model.
    pub model: ModelKind,
    /// Peak values.
    pub peaks: Peaks,
    /// Slip at the end of the run, m.
    pub residual_slip_m: f64,
    /// Time steps (DDA) or propagation steps (mass-spring).
    pub steps: u64,
    /// The DDA solver's counters; `None` for an exact model, which has none.
    pub solver: Option<SolverCounts>,
    /// Steps that ended with a sliding contact (DDA only; the exact model reports its
    /// slip phases through the slip history).
    pub sliding_steps: u64,
    /// Energy residual relative to the energy that passed through the structure.
    pub energy_residual_rel: f64,
    /// Input work, J per m of thickness.
    pub input_work: f64,
    /// Friction dissipation, J per m.
    pub friction_dissipated: f64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// Recorded histories, [`HISTORY_COLUMNS`] (empty when only peaks were asked for).
    pub history: History,
    /// The base acceleration resampled every [`SPECTRUM_DT`] seconds, for its spectrum
    /// (DDA only).
    pub base_accel_series: Option<UniformSeries>,
    /// Peaks of the absolute base and roof accelerations low-passed at 25 Hz (DDA only,
    /// and only when the run is long enough to filter; see [`crate::post::filter`]).
    pub low_passed: Option<LowPassedPeaks>,
    /// When the base first lifted off the ground at a corner (DDA only, and only for a
    /// structure whose only contacts are its sliding joint's: fewer of them closed than
    /// at the first step), s. The exact models keep the base flat on the ground.
    pub lift_off_time_s: Option<f64>,
}

/// What a DDA run's solver did, as a run's summary reports it (flattened into its JSON
/// object). An exact model has none of it, and its summary leaves these keys out rather
/// than report zeros.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SolverCounts {
    /// Open-close passes.
    pub open_close_passes: u64,
    /// Δt cuts.
    pub dt_cuts: u64,
    /// What forced the Δt cuts.
    pub dt_cut_reasons: CutReasons,
    /// Numeric factorisations of the system matrix: the passes' solves that did not
    /// reuse a kept factor, and those of the event projections (so they can exceed the
    /// passes when every solve factorises, as a frame's does).
    pub factorizations: u64,
    /// Largest penetration / structure size.
    pub max_penetration_ratio: f64,
}

impl SolverCounts {
    /// The counters a DDA run reports, from the solver's totals.
    pub fn of(counters: &RunCounters) -> Self {
        Self {
            open_close_passes: counters.passes,
            dt_cuts: counters.cuts,
            dt_cut_reasons: counters.cut_reasons,
            factorizations: counters.factorizations,
            max_penetration_ratio: counters.max_penetration_ratio,
        }
    }
}

impl ModelRun {
    /// The warning a run's summary carries when its base lifted off at a corner (not for
    /// vertical shaking, whose lift-off is warned of before the run).
    pub fn lift_off_warning(&self, vertical: bool) -> Option<String> {
        let t = self.lift_off_time_s.filter(|_| !vertical)?;
        Some(format!(
            "the base lifted off the ground at a corner at t = {t:.3} s: the structure rocks \
             (its overturning moment exceeded the weight's restoring moment), so the slip \
             and accelerations include rocking, which the exact model does not have; lower \
             the friction or the shaking to stay within sliding"
        ))
    }
}

/// Peaks of accelerations low-passed at [`crate::post::filter::CUTOFF_HZ`], m/s².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LowPassedPeaks {
    /// Absolute base acceleration.
    pub base_accel: f64,
    /// Absolute roof acceleration.
    pub roof_accel: f64,
}

/// Columns of the recorded history.
pub const HISTORY_COLUMNS: [&str; 6] = [
    "time_s",
    "ground_accel_m_s2",
    "slip_m",
    "roof_drift_m",
    "base_accel_m_s2",
    "roof_accel_m_s2",
];

/// Sample spacing of the base-acceleration series whose spectrum building runs report,
/// s (Nyquist 100 Hz, far above the 20 Hz the peak is looked for in).
pub const SPECTRUM_DT: f64 = 0.005;

/// Most samples kept of that series (2²² = 5.8 h of run at 5 ms; longer runs keep every
/// other sample, and so on).
pub const SPECTRUM_MAX_SAMPLES: usize = 1 << 22;

/// Runs the DDA model of `scene` (the setup's scene or a study's variant of it) under the
/// setup's motion; the history is kept as the setup's plan says.
pub fn run_dda(setup: &RunSetup, scene: &Scene, params: SolverParams) -> Result<ModelRun> {
    let start = Instant::now();
    let duration = params.duration;
    let (mut dda, probe) = setup.build_dda(scene, params)?;
    let motion = &setup.motion;
    let mut record_every = setup.history.stride();
    let mut peaks = [PeakTracker::default(); 5];
    let mut history = History::new(&HISTORY_COLUMNS);
    let mut series = UniformSeries::new(SPECTRUM_DT, SPECTRUM_MAX_SAMPLES);
    let mut base_cells = CellAverages::new(filter::CELL_S, filter::MAX_CELLS);
    let mut roof_cells = base_cells.clone();
    let mut step = 0usize;
    let mut last_slip = 0.0;
    // The last step's row when the stride skipped it: a history ends where the run ends
    // (one that stopped a few steps short made comparisons of histories clamp there).
    let mut unrecorded = None;
    let mut sliding_steps = 0;
    // A corner of the base lifting off: fewer closed contacts than at the first step,
    // where the sliding joint's are the only contacts (a wall's own open and close).
    let joint_only = scene.contacts.iter().all(|c| c.name == setup.joint);
    let mut closed_at_start = None;
    let mut lift_off_time_s = None;
    let mut next_report = setup.progress.as_ref().map(|p| p.first_after_s);
    // Built at the first report: a run that never reports never samples its motion.
    let mut remaining: Option<RemainingTime> = None;
    dda.run_until(duration, |d, report| {
        // The clock is read every 16 steps (~40 µs of the smallest model; a large wall
        // under strong shaking takes seconds for them).
        if let (Some(reporter), Some(due)) = (&setup.progress, next_report.as_mut())
            && step.is_multiple_of(16)
        {
            let elapsed_s = start.elapsed().as_secs_f64();
            if elapsed_s >= *due {
                *due = elapsed_s + reporter.every_s;
                let estimate =
                    remaining.get_or_insert_with(|| RemainingTime::new(motion, duration));
                reporter.report(&RunProgress {
                    time_s: report.time,
                    duration_s: duration,
                    steps: step as u64,
                    cuts: d.counters().cuts,
                    elapsed_s,
                    remaining_s: estimate.observe(report.time, elapsed_s),
                    harder_shaking_ahead: estimate.harder_shaking_ahead(report.time),
                });
            }
        }
        if report.sliding > 0 {
            sliding_steps += 1;
        }
        if joint_only && lift_off_time_s.is_none() {
            let start = *closed_at_start.get_or_insert(report.closed);
            if report.closed < start {
                lift_off_time_s = Some(report.time);
            }
        }
        let r = probe.measure(d, Some(motion));
        let row = [
            r.time,
            r.ground_accel,
            r.slip,
            r.drift,
            r.base_accel,
            r.roof_accel,
        ];
        for (k, p) in peaks.iter_mut().enumerate() {
            // Columns 1..5 are tracked as ground, slip, drift, base, roof.
            p.offer(r.time, row[k + 1]);
        }
        series.push(r.time, r.base_accel);
        base_cells.push(r.time, r.base_accel);
        roof_cells.push(r.time, r.roof_accel);
        if record_every > 0 && step.is_multiple_of(record_every) {
            history.push(&row);
            unrecorded = None;
            // Bounded memory: past the limit, every other row goes and the interval
            // doubles (the kept rows are those of the doubled interval).
            if history.len() >= MAX_HISTORY_ROWS {
                history.decimate();
                record_every *= 2;
            }
        } else {
            unrecorded = Some(row);
        }
        step += 1;
        last_slip = r.slip;
    })?;
    if let (true, Some(row)) = (record_every > 0, unrecorded) {
        history.push(&row);
    }
    // Before the clock is read: the filter is part of the run's cost.
    let low_passed = base_cells
        .low_passed_peak()
        .zip(roof_cells.low_passed_peak())
        .map(|(base_accel, roof_accel)| LowPassedPeaks {
            base_accel,
            roof_accel,
        });
    let counters = dda.counters();
    let energy = dda.energy();
    Ok(ModelRun {
        model: ModelKind::Dda,
        peaks: Peaks {
            ground_accel: peaks[0].value,
            slip_m: peaks[1].value,
            drift_m: peaks[2].value,
            base_accel: peaks[3].value,
            roof_accel: peaks[4].value,
        },
        residual_slip_m: last_slip,
        steps: counters.steps,
        solver: Some(SolverCounts::of(&counters)),
        sliding_steps,
        energy_residual_rel: dda.energy_residual_relative(),
        input_work: energy.input_work,
        friction_dissipated: energy.friction_dissipated,
        wall_time_s: start.elapsed().as_secs_f64(),
        history,
        base_accel_series: Some(series),
        low_passed,
        lift_off_time_s,
    })
}

/// Runs the exact mass-spring model (paper Appendix I) with the same outputs as the DDA
/// run; `output_dt` ≤ 0 records no history. Energies are scaled to `total_mass` (M + m).
pub fn run_exact(
    alpha: f64,
    structure_freq_hz: f64,
    total_mass: f64,
    friction: f64,
    motion: &GroundMotion,
    duration: f64,
    output_dt: f64,
) -> Result<ModelRun> {
    use crate::analytic::{ExactOptions, ShearBuilding, simulate};
    let start = Instant::now();
    let building = ShearBuilding::two_mass(alpha, structure_freq_hz, friction)?;
    let r = simulate(
        &building,
        motion,
        duration,
        output_dt,
        &ExactOptions::default(),
    )?;
    let residual = r.energy.residual_relative();
    Ok(exact_model_run(
        &r, motion, true, total_mass, residual, start,
    ))
}

/// The exact model's result as a run: its peaks and counters, and (with `keep_history`)
/// its outputs as a history of the top storey. Energies are multiplied by
/// `energy_scale`; `energy_residual_rel` is the caller's.
pub fn exact_model_run(
    r: &ExactResult,
    motion: &GroundMotion,
    keep_history: bool,
    energy_scale: f64,
    energy_residual_rel: f64,
    start: Instant,
) -> ModelRun {
    let top = r.storey_drift.len().saturating_sub(1);
    let columns = [
        &r.slip,
        &r.storey_drift[top],
        &r.raft_accel,
        &r.storey_accel[top],
    ];
    let history = exact_history(keep_history, &r.time, motion, columns);
    ModelRun::exact(
        Peaks {
            slip_m: r.peaks.slip,
            drift_m: r.peaks.roof_drift,
            base_accel: r.peaks.raft_accel,
            roof_accel: r.peaks.roof_accel,
            ground_accel: r.peaks.ground_accel,
        },
        r.residual_slip,
        r.steps,
        ExactEnergy {
            residual_rel: energy_residual_rel,
            input_work: r.energy.input_work * energy_scale,
            friction_dissipated: r.energy.friction_dissipated * energy_scale,
        },
        history,
        start,
    )
}

/// The energies an exact model reports, J per m of thickness.
#[derive(Debug, Clone, Copy)]
pub struct ExactEnergy {
    /// Residual relative to the energy through the model.
    pub residual_rel: f64,
    /// Input work.
    pub input_work: f64,
    /// Friction dissipation.
    pub friction_dissipated: f64,
}

impl ModelRun {
    /// The run of an exact (event-driven) model, which has none of DDA's counters;
    /// `start` is when it began (for the wall time).
    pub fn exact(
        peaks: Peaks,
        residual_slip_m: f64,
        steps: u64,
        energy: ExactEnergy,
        history: History,
        start: Instant,
    ) -> Self {
        Self {
            model: ModelKind::MassSpring,
            peaks,
            residual_slip_m,
            steps,
            solver: None,
            sliding_steps: 0,
            energy_residual_rel: energy.residual_rel,
            input_work: energy.input_work,
            friction_dissipated: energy.friction_dissipated,
            wall_time_s: start.elapsed().as_secs_f64(),
            history,
            base_accel_series: None,
            low_passed: None,
            lift_off_time_s: None,
        }
    }
}

/// An exact model's outputs as a history ([`HISTORY_COLUMNS`]): slip, roof drift, raft
/// and roof accelerations at `time` (empty unless `keep`).
fn exact_history(
    keep: bool,
    time: &[f64],
    motion: &GroundMotion,
    columns: [&Vec<f64>; 4],
) -> History {
    let mut history = History::new(&HISTORY_COLUMNS);
    if keep {
        for (k, &t) in time.iter().enumerate() {
            let [slip, drift, raft, roof] = columns.map(|c| c[k]);
            history.push(&[t, motion.accel(t), slip, drift, raft, roof]);
        }
    }
    history
}

/// The stepped mass-spring solution ([`crate::analytic::simulate_stepped`]) of a run
/// `duration` seconds long, as a run, with (when `keep_history`) its outputs as a history
/// of the top storey. Energies are multiplied by `energy_scale`.
pub fn stepped_model_run(
    r: &crate::analytic::SteppedResult,
    motion: &GroundMotion,
    duration: f64,
    keep_history: bool,
    energy_scale: f64,
    start: Instant,
) -> ModelRun {
    let columns = [&r.slip, &r.roof_drift, &r.raft_accel, &r.roof_accel];
    let history = exact_history(keep_history, &r.time, motion, columns);
    let e = &r.energy;
    // Relative to the energy that passed through the model (as the DDA ledger's).
    let scale = e
        .input_work
        .abs()
        .max(e.friction_dissipated + e.damping_dissipated + e.kinetic + e.strain);
    let energy = ExactEnergy {
        residual_rel: if scale > 0.0 { e.residual / scale } else { 0.0 },
        input_work: e.input_work * energy_scale,
        friction_dissipated: e.friction_dissipated * energy_scale,
    };
    let peaks = Peaks {
        slip_m: r.max_slip,
        drift_m: r.max_roof_drift,
        base_accel: r.peak_raft_accel,
        roof_accel: r.peak_roof_accel,
        ground_accel: motion.peak_accel(duration),
    };
    ModelRun::exact(peaks, r.residual_slip, r.steps, energy, history, start)
}

/// The output interval of the exact model: `wanted`, or longer so that a long run keeps
/// at most [`MAX_HISTORY_ROWS`] rows (0: no output).
pub fn exact_output_dt(wanted: f64, duration: f64) -> f64 {
    if wanted > 0.0 {
        wanted.max(duration / MAX_HISTORY_ROWS as f64)
    } else {
        0.0
    }
}

/// The exact model of a two-block setup (output every `output_dt` seconds, none if ≤ 0;
/// longer for long runs, see [`exact_output_dt`]).
pub fn run_exact_two_block(setup: &RunSetup, output_dt: f64) -> Result<ModelRun> {
    let (roles, alpha, _) = setup.two_block().ok_or_else(|| {
        crate::Error::invalid(
            "--model",
            "the exact two-mass model needs a two-block scene",
        )
    })?;
    let output_dt = exact_output_dt(output_dt, setup.duration);
    let Some(structure) = setup
        .two_block_structure()
        .filter(|_| setup.needs_stepped_exact())
    else {
        return run_exact(
            alpha,
            roles.structure_frequency_hz,
            roles.total_mass,
            setup.friction,
            &setup.motion,
            setup.duration,
            output_dt,
        );
    };
    let start = Instant::now();
    let options = crate::analytic::SteppedOptions::default();
    let r = crate::analytic::simulate_stepped(&structure?, setup.duration, output_dt, &options)?;
    Ok(stepped_model_run(
        &r,
        &setup.motion,
        setup.duration,
        true,
        roles.total_mass,
        start,
    ))
}
