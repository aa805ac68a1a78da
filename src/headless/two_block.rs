//! Runs of the two-mass sliding model (paper Fig. 2) with either model: the DDA blocks or
//! the exact mass-spring solution. Both produce the same summary and time histories, so
//! they can be compared point by point.

use std::time::Instant;

use serde::Serialize;

use crate::dda::{Dda, SolverParams};
use crate::ground_motion::GroundMotion;
use crate::model::Scene;
use crate::post::history::{History, PeakTracker};
use crate::{Error, Result};

/// Which model computes the response.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelKind {
    /// Discontinuous Deformation Analysis of the blocks.
    Dda,
    /// The exact (event-driven) solution of the Appendix-I mass-spring model.
    MassSpring,
}

impl ModelKind {
    /// Command-line spelling.
    pub fn label(&self) -> &'static str {
        match self {
            ModelKind::Dda => "dda",
            ModelKind::MassSpring => "mass-spring",
        }
    }
}

/// Peak responses of a two-mass run, SI units.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct TwoBlockPeaks {
    /// max |u_s|: raft slip relative to the ground, m.
    pub slip_m: f64,
    /// max |u_r|: roof relative to the raft, m.
    pub drift_m: f64,
    /// max |absolute raft acceleration|, m/s².
    pub base_accel: f64,
    /// max |absolute roof acceleration|, m/s².
    pub roof_accel: f64,
    /// max |ground acceleration| over the run, m/s².
    pub ground_accel: f64,
}

/// Result of one two-mass run.
#[derive(Debug, Clone)]
pub struct TwoBlockRun {
    /// Which model.
    pub model: ModelKind,
    /// Peak values.
    pub peaks: TwoBlockPeaks,
    /// Slip at the end of the run, m.
    pub residual_slip_m: f64,
    /// Time steps (DDA) or propagation steps (mass-spring).
    pub steps: u64,
    /// Open-close passes (DDA only).
    pub passes: u64,
    /// Δt cuts (DDA only).
    pub cuts: u64,
    /// Steps that ended with a sliding contact (DDA only; the exact model reports its
    /// slip phases through the slip history).
    pub sliding_steps: u64,
    /// Largest penetration / structure size (DDA only).
    pub max_penetration_ratio: f64,
    /// Energy residual relative to the energy that passed through the structure.
    pub energy_residual_rel: f64,
    /// Input work, J per m of thickness.
    pub input_work: f64,
    /// Friction dissipation, J per m.
    pub friction_dissipated: f64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// Recorded histories: time_s, ground_accel, slip, drift, base_accel, roof_accel.
    pub history: History,
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

/// Runs the DDA model of a two-mass scene; `record_every` > 0 keeps every n-th step.
pub fn run_dda(
    scene: &Scene,
    motion: &GroundMotion,
    params: SolverParams,
    record_every: usize,
) -> Result<TwoBlockRun> {
    let roles = scene.two_block.clone().ok_or_else(|| {
        Error::Scene(format!(
            "scene '{}' declares no [two_block] roles",
            scene.name
        ))
    })?;
    let start = Instant::now();
    let duration = params.duration;
    let mut dda = Dda::new(scene, Some(motion.clone()), params)?;
    let raft = dda.block_index(&roles.raft)?;
    let roof = dda.block_index(&roles.roof)?;
    let mut peaks = [PeakTracker::default(); 5];
    let mut history = History::new(&HISTORY_COLUMNS);
    let mut step = 0usize;
    let mut last_slip = 0.0;
    let mut sliding_steps = 0;
    dda.run_until(duration, |d, report| {
        if report.sliding > 0 {
            sliding_steps += 1;
        }
        let t = d.time();
        let slip = d.displacement_relative_to_ground(raft);
        let drift = d.displacement_relative_to_ground(roof) - slip;
        let row = [
            t,
            motion.accel(t),
            slip,
            drift,
            d.absolute_accel(raft),
            d.absolute_accel(roof),
        ];
        for (k, p) in peaks.iter_mut().enumerate() {
            // Columns 1..5 are tracked as ground, slip, drift, base, roof.
            p.offer(t, row[k + 1]);
        }
        if record_every > 0 && step.is_multiple_of(record_every) {
            history.push(&row);
        }
        step += 1;
        last_slip = slip;
    })?;
    let counters = dda.counters();
    let energy = dda.energy();
    Ok(TwoBlockRun {
        model: ModelKind::Dda,
        peaks: TwoBlockPeaks {
            ground_accel: peaks[0].value,
            slip_m: peaks[1].value,
            drift_m: peaks[2].value,
            base_accel: peaks[3].value,
            roof_accel: peaks[4].value,
        },
        residual_slip_m: last_slip,
        steps: counters.steps,
        passes: counters.passes,
        cuts: counters.cuts,
        sliding_steps,
        max_penetration_ratio: counters.max_penetration_ratio,
        energy_residual_rel: dda.energy_residual_relative(),
        input_work: energy.input_work,
        friction_dissipated: energy.friction_dissipated,
        wall_time_s: start.elapsed().as_secs_f64(),
        history,
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
) -> Result<TwoBlockRun> {
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
    let mut history = History::new(&HISTORY_COLUMNS);
    for k in 0..r.time.len() {
        let t = r.time[k];
        history.push(&[
            t,
            motion.accel(t),
            r.slip[k],
            r.storey_drift[0][k],
            r.raft_accel[k],
            r.storey_accel[0][k],
        ]);
    }
    // The model has total mass 1: energies scale with the scene's M + m.
    let e = r.energy;
    Ok(TwoBlockRun {
        model: ModelKind::MassSpring,
        peaks: TwoBlockPeaks {
            slip_m: r.peaks.slip,
            drift_m: r.peaks.roof_drift,
            base_accel: r.peaks.raft_accel,
            roof_accel: r.peaks.roof_accel,
            ground_accel: r.peaks.ground_accel,
        },
        residual_slip_m: r.residual_slip,
        steps: r.steps,
        passes: 0,
        cuts: 0,
        sliding_steps: 0,
        max_penetration_ratio: 0.0,
        energy_residual_rel: if e.input_work.abs() > 0.0 {
            e.residual / e.input_work.abs()
        } else {
            0.0
        },
        input_work: e.input_work * total_mass,
        friction_dissipated: e.friction_dissipated * total_mass,
        wall_time_s: start.elapsed().as_secs_f64(),
        history,
    })
}
