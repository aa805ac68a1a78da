//! Newmark's sliding block (`--scene block`): the DDA model of one block on its joint, or
//! its exact event-driven rigid-block solution, summarised in the same terms.

use std::time::Instant;

use serde::Serialize;

use super::simulate::{self, ModelRun, SolverCounts};
use crate::analytic::{SlidingBlock, SteppedOptions, Surface, simulate_block};
use crate::ground_motion::STANDARD_GRAVITY;
use crate::post::history::History;
use crate::post::plot::{Figure, Panel, Series};
use crate::setup::{ModelKind, RunSetup, RunSpec, SceneRoles};
use crate::{Error, Result};

/// Summary of a sliding-block run (the JSON object of `run --json`). A quantity that is
/// undefined for the run is left out (never `null`), and `warnings` says why.
#[derive(Debug, Clone, Serialize)]
pub struct BlockSummary {
    /// Scene.
    pub scene: String,
    /// `dda` or `mass-spring` (the exact rigid block).
    pub model: String,
    /// Integrator (DDA only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Record name (or the harmonic input).
    pub record: String,
    /// The vertical ground motion (record name), when the ground also shakes vertically.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertical_record: Option<String>,
    /// The joint's friction law as written (`0.15`, `static-kinetic:0.3,0.2`…; absent for
    /// a fixed base).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<String>,
    /// Its sticking coefficient (absent for a fixed base).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Fixed base (the joint bonded).
    pub fixed_base: bool,
    /// Duration, s.
    pub duration_s: f64,
    /// Nominal time step, s (DDA only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt_s: Option<f64>,
    /// Largest |slip| of the block relative to the ground, m.
    pub max_slip_m: f64,
    /// Slip at the end (block relative to ground, +x, signed), m.
    pub residual_slip_m: f64,
    /// Peak |absolute horizontal acceleration of the block|, g.
    pub peak_base_accel_g: f64,
    /// Peak ground acceleration, g.
    pub peak_ground_accel_g: f64,
    /// Time steps (DDA) or integration steps (exact model).
    pub steps: u64,
    /// What the DDA solver did (left out for the exact model).
    #[serde(flatten)]
    pub solver: Option<SolverCounts>,
    /// Energy residual relative to the energy through the block.
    pub energy_residual_rel: f64,
    /// Work done by the ground on the block, J per m of thickness.
    pub input_work_j: f64,
    /// Energy dissipated by friction, J/m.
    pub friction_dissipated_j: f64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// What the user should know.
    pub warnings: Vec<String>,
}

/// A finished sliding-block run.
#[derive(Debug, Clone)]
pub struct BlockOutcome {
    /// Summary.
    pub summary: BlockSummary,
    /// The full run (histories: [`HISTORY_COLUMNS`], the block as base and roof).
    pub run: ModelRun,
}

/// Runs a sliding-block scene with the model the specification names.
pub fn run_block(spec: &RunSpec) -> Result<BlockOutcome> {
    run_block_setup(&spec.prepare()?)
}

/// Runs a prepared sliding-block setup.
pub fn run_block_setup(setup: &RunSetup) -> Result<BlockOutcome> {
    if !matches!(setup.roles, SceneRoles::Block(_)) {
        return Err(Error::invalid(
            "--scene",
            format!(
                "scene '{}' is not a sliding-block scene (no [sliding_block] section)",
                setup.scene.name
            ),
        ));
    }
    let run = match setup.model {
        ModelKind::Dda => simulate::run_dda(setup, &setup.scene, setup.solver_params())?,
        ModelKind::MassSpring => run_exact_block(setup, setup.dt * setup.history.stride() as f64)?,
    };
    let summary = summarise(setup, &run);
    super::run::check_finite(&summary, setup.duration)?;
    Ok(BlockOutcome { summary, run })
}

/// Another run's history drawn over a run's in its figure (its slip, and for two-block
/// runs its roof drift).
#[derive(Debug, Clone)]
pub struct SlipOverlay {
    /// Legend label.
    pub label: String,
    /// The run whose slip is drawn.
    pub run: ModelRun,
    /// Drawn as markers (a reference the run should match) rather than a line (a variant
    /// to contrast it with).
    pub markers: bool,
}

/// The overlays a teacher wants on a block run's figure: the exact block of the same
/// inputs (for a DDA run), the exact block without the vertical shaking (when there is
/// some), so that its effect shows, and on a friction pendulum's dish the exact block on
/// a flat joint of the same friction, so that the dish's recentring shows. Each takes
/// milliseconds.
pub fn standard_overlays(setup: &RunSetup) -> Result<Vec<SlipOverlay>> {
    let mut overlays = Vec::new();
    if setup.model == ModelKind::Dda {
        overlays.push(SlipOverlay {
            label: match setup.dish_radius() {
                Some(r) => format!("exact point mass on the circle R = {r} m"),
                None => "exact rigid block".into(),
            },
            run: run_exact_block(setup, setup.dt)?,
            markers: true,
        });
    }
    if setup.vertical.is_some() {
        let horizontal_only = RunSetup {
            vertical: None,
            ..setup.clone()
        };
        overlays.push(SlipOverlay {
            label: "exact, without vertical shaking".into(),
            run: run_exact_block(&horizontal_only, setup.dt)?,
            markers: false,
        });
    }
    if setup.dish_radius().is_some() {
        overlays.push(SlipOverlay {
            label: "exact, on a flat joint".into(),
            run: run_exact_block_on(setup, Surface::Flat, setup.dt)?,
            markers: false,
        });
    }
    Ok(overlays)
}

/// Writes a sliding-block run's history, summary and figures into `dir` (all or nothing):
/// `history.png` draws `overlays` over the run's slip, `friction.png` (flat joints) the
/// friction hysteresis, F/N against the slip speed, with the exact block's and the law's.
pub fn write_outputs(
    setup: &RunSetup,
    outcome: &BlockOutcome,
    overlays: &[SlipOverlay],
    dir: &std::path::Path,
) -> Result<Vec<std::path::PathBuf>> {
    let mut staged = crate::post::output::Staged::new(dir)?;
    outcome.run.history.write_csv(&staged.path("history.csv"))?;
    staged.write_json("summary.json", &outcome.summary)?;
    if !outcome.run.history.is_empty() {
        history_figure(setup, outcome, overlays).save_png(
            &staged.path("history.png"),
            1400,
            900,
        )?;
    }
    if let Some(fig) = super::friction_figure::friction_figure(setup, outcome, overlays) {
        fig.save_png(&staged.path("friction.png"), 1200, 900)?;
    }
    staged.commit()
}

/// The block's acceleration against the ground's, and its slip (with the overlays').
fn history_figure(setup: &RunSetup, outcome: &BlockOutcome, overlays: &[SlipOverlay]) -> Figure {
    let s = &outcome.summary;
    let column = |h: &History, name: &str| h.column(name).map(<[f64]>::to_vec).unwrap_or_default();
    let h = &outcome.run.history;
    let t = column(h, "time_s");
    let in_g = |v: Vec<f64>| {
        v.into_iter()
            .map(|a| a / STANDARD_GRAVITY)
            .collect::<Vec<_>>()
    };
    let law = s.friction_law.as_deref().unwrap_or("bonded");
    let vertical = s
        .vertical_record
        .as_ref()
        .map_or(String::new(), |v| format!(" + vertical {v}"));
    let what = match setup.dish_radius() {
        Some(r) => format!("friction pendulum (R = {r} m)"),
        None => "sliding block".into(),
    };
    let mut fig = Figure::new(
        format!(
            "{what} ({}), friction {law}, {}{vertical}",
            s.model, s.record
        ),
        2,
        1,
    );
    let p = &mut fig.panels[0];
    p.title = format!(
        "ground and block acceleration (block peak {:.3} g, ground {:.3} g)",
        s.peak_base_accel_g, s.peak_ground_accel_g
    );
    p.x_label = "t (s)".into();
    p.y_label = "a (g)".into();
    p.series.push(Series::line(
        "ground",
        t.clone(),
        in_g(column(h, "ground_accel_m_s2")),
        6,
    ));
    p.series.push(Series::line(
        "block",
        t.clone(),
        in_g(column(h, "base_accel_m_s2")),
        1,
    ));
    let p = &mut fig.panels[1];
    p.title = format!(
        "slip of the block relative to the ground (peak {:.2} mm, residual {:.2} mm)",
        1e3 * s.max_slip_m,
        1e3 * s.residual_slip_m
    );
    p.x_label = "t (s)".into();
    p.y_label = "slip (m)".into();
    p.series
        .push(Series::line(s.model.clone(), t, column(h, "slip_m"), 2));
    draw_overlays(p, overlays, "slip_m");
    fig
}

/// Draws the overlays' column `name` against their time on panel `p`: the first in one
/// colour, the others in another; references as markers.
pub fn draw_overlays(p: &mut Panel, overlays: &[SlipOverlay], name: &str) {
    let column = |h: &History, name: &str| h.column(name).map(<[f64]>::to_vec).unwrap_or_default();
    for (k, o) in overlays.iter().enumerate() {
        let (ot, os) = (
            column(&o.run.history, "time_s"),
            column(&o.run.history, name),
        );
        let color = if k == 0 { 0 } else { 4 };
        p.series.push(if o.markers {
            // About 120 markers, so that the curves stay apart to the eye where they agree.
            let every = (ot.len() / 120).max(1);
            let pick = |v: Vec<f64>| v.into_iter().step_by(every).collect::<Vec<_>>();
            Series::markers(o.label.clone(), pick(ot), pick(os), color)
        } else {
            Series::line(o.label.clone(), ot, os, color)
        });
    }
}

/// The exact rigid block of a sliding-block setup, as a run (output every `output_dt`
/// seconds, none if ≤ 0). Energies per unit mass are scaled by the DDA block's mass.
pub fn run_exact_block(setup: &RunSetup, output_dt: f64) -> Result<ModelRun> {
    run_exact_block_on(setup, setup.sliding_block().surface, output_dt)
}

/// [`run_exact_block`] with the block on `surface` instead of the scene's.
fn run_exact_block_on(setup: &RunSetup, surface: Surface, output_dt: f64) -> Result<ModelRun> {
    let start = Instant::now();
    let output_dt = simulate::exact_output_dt(output_dt, setup.duration);
    let options = SteppedOptions::default();
    let block = SlidingBlock {
        surface,
        ..setup.sliding_block()
    };
    let r = simulate_block(&block, setup.duration, output_dt, &options)?;
    let mass = setup.scene.block_mass(&setup.base)?;
    Ok(simulate::stepped_model_run(
        &r,
        &setup.motion,
        setup.duration,
        true,
        mass,
        start,
    ))
}

fn summarise(setup: &RunSetup, run: &ModelRun) -> BlockSummary {
    let mut warnings = setup.warnings.clone();
    let dda = setup.model == ModelKind::Dda;
    let friction = super::run::reported_friction(setup, &mut warnings);
    BlockSummary {
        scene: setup.scene.name.clone(),
        model: setup.model.label().into(),
        integrator: dda.then(|| setup.integrator.label()),
        record: setup.motion.label(),
        vertical_record: setup.vertical.as_ref().map(|v| v.label()),
        friction_law: friction.map(|_| setup.joint_law().to_string()),
        friction,
        fixed_base: setup.fixed_base,
        duration_s: setup.duration,
        dt_s: dda.then_some(setup.dt),
        max_slip_m: run.peaks.slip_m,
        residual_slip_m: run.residual_slip_m,
        peak_base_accel_g: run.peaks.base_accel / STANDARD_GRAVITY,
        peak_ground_accel_g: setup.motion.peak_accel(setup.duration) / STANDARD_GRAVITY,
        steps: run.steps,
        solver: run.solver,
        energy_residual_rel: run.energy_residual_rel,
        input_work_j: run.input_work,
        friction_dissipated_j: run.friction_dissipated,
        wall_time_s: run.wall_time_s,
        warnings,
    }
}
