//! `slidebase run`: one simulation of a scene, summarised in the paper's terms.

use std::path::PathBuf;

use serde::Serialize;

use super::two_block::{self, ModelKind, TwoBlockRun};
use crate::dda::{Integrator, SolverParams};
use crate::ground_motion::{GroundMotion, Harmonic, STANDARD_GRAVITY, resolve_record};
use crate::model::presets::{TwoBlockParams, apply_two_block, extend_ground, resolve_scene};
use crate::model::scene::{ExcitationDef, GroundKind};
use crate::{Error, Result};

/// Everything a run needs; the command-line flags map one to one onto these fields.
#[derive(Debug, Clone)]
pub struct RunRequest {
    /// Built-in scene name or TOML path.
    pub scene: String,
    /// Mass ratio α = m/(M + m) (two-mass scenes).
    pub alpha: f64,
    /// Friction coefficient ρ of the sliding joint.
    pub friction: f64,
    /// Ω/ω of the harmonic excitation (two-mass scenes).
    pub freq_ratio: f64,
    /// Amplitude of the harmonic excitation, g.
    pub amplitude_g: f64,
    /// Duration, s; `None`: 100 s for harmonic input (the paper's), the record's length otherwise.
    pub duration: Option<f64>,
    /// Time step, s.
    pub dt: f64,
    /// Integrator.
    pub integrator: Integrator,
    /// DDA or the exact mass-spring model.
    pub model: ModelKind,
    /// Fixed base: the joint never slides.
    pub fixed_base: bool,
    /// A record (built-in name or file) instead of harmonic input.
    pub record: Option<String>,
    /// Ground model for DDA (None: the scene's).
    pub ground: Option<GroundKind>,
    /// Keep every n-th step in the recorded history.
    pub record_every: usize,
}

impl Default for RunRequest {
    fn default() -> Self {
        Self {
            scene: "two-block".into(),
            alpha: 0.5,
            friction: 0.1,
            freq_ratio: 1.0,
            amplitude_g: 0.3,
            duration: None,
            dt: 1e-3,
            integrator: Integrator::default(),
            model: ModelKind::Dda,
            fixed_base: false,
            record: None,
            ground: None,
            record_every: 10,
        }
    }
}

/// The one-object summary printed by `--json` and written by `--out`.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Scene name.
    pub scene: String,
    /// `dda` or `mass-spring`.
    pub model: String,
    /// Integrator (DDA).
    pub integrator: String,
    /// Mass ratio α.
    pub alpha: f64,
    /// Friction coefficient ρ (null when the base is fixed).
    pub friction: Option<f64>,
    /// Whether the base was fixed.
    pub fixed_base: bool,
    /// Ω/ω (harmonic input only).
    pub freq_ratio: Option<f64>,
    /// Excitation: `harmonic` or the record name.
    pub excitation: String,
    /// Peak ground acceleration, g.
    pub amplitude_g: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Nominal time step, s.
    pub dt_s: f64,
    /// max|u_s| / D with D = a_max/Ω² (harmonic input only).
    pub us_max_over_d: Option<f64>,
    /// max|u_r| / D (harmonic input only).
    pub ur_max_over_d: Option<f64>,
    /// max|a_base| / a_max (absolute accelerations).
    pub abase_over_aground: f64,
    /// max|a_roof| / a_max.
    pub aroof_over_aground: f64,
    /// max|u_s|, m.
    pub us_max_m: f64,
    /// max|u_r|, m.
    pub ur_max_m: f64,
    /// Slip at the end, m.
    pub residual_slip_m: f64,
    /// Time steps.
    pub steps: u64,
    /// Open-close passes (DDA).
    pub open_close_passes: u64,
    /// Δt cuts (DDA).
    pub dt_cuts: u64,
    /// Largest penetration / structure size (DDA).
    pub max_penetration_ratio: f64,
    /// Energy residual (numerical dissipation) relative to the energy through the system.
    pub energy_residual_rel: f64,
    /// Work done by the ground on the structure, J/m.
    pub input_work_j: f64,
    /// Energy dissipated by friction, J/m.
    pub friction_dissipated_j: f64,
    /// Wall-clock time of the solve, s.
    pub wall_time_s: f64,
}

/// A finished run: summary and histories.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The summary.
    pub summary: RunSummary,
    /// The full result (histories).
    pub run: TwoBlockRun,
}

/// The scene and motion of a two-mass request, ready to run.
#[derive(Debug, Clone)]
pub struct TwoBlockSetup {
    /// The scene with α, ρ, Ω/ω, ground and fixed base applied.
    pub scene: crate::model::Scene,
    /// The ground motion.
    pub motion: GroundMotion,
    /// Duration, s.
    pub duration: f64,
    /// Ω/ω (harmonic input only).
    pub freq_ratio: Option<f64>,
    /// `harmonic` or the record name.
    pub excitation: String,
    /// The scene's two-mass roles.
    pub roles: crate::model::scene::TwoBlockRoles,
    /// Friction actually used (∞ for a fixed base).
    pub friction: f64,
}

/// Builds the scene and motion of a two-mass request (shared by `run`, the accuracy and
/// stability studies).
pub fn two_block_setup(req: &RunRequest) -> Result<TwoBlockSetup> {
    crate::error::require_positive("--dt", req.dt)?;
    if let Some(d) = req.duration {
        crate::error::require_positive("--duration", d)?;
    }
    let friction = if req.fixed_base {
        f64::INFINITY
    } else {
        req.friction
    };
    let params = TwoBlockParams {
        alpha: req.alpha,
        friction,
        freq_ratio: req.freq_ratio,
        amplitude_g: req.amplitude_g,
    };
    params.validate()?;
    let mut scene = resolve_scene(&req.scene)?;
    let roles = scene.two_block.clone().ok_or_else(|| {
        Error::invalid(
            "--scene",
            format!(
                "scene '{}' is not a two-mass scene (no [two_block] section)",
                scene.name
            ),
        )
    })?;
    apply_two_block(&mut scene, &params)?;
    let structure_hz = roles.structure_frequency_hz;
    let (motion, omega_ratio, excitation) = match &req.record {
        None => {
            let h = Harmonic::from_g_hz(req.amplitude_g, req.freq_ratio * structure_hz)?;
            (
                GroundMotion::Harmonic(h),
                Some(req.freq_ratio),
                "harmonic".to_string(),
            )
        }
        Some(name) => {
            let r = resolve_record(name)?;
            let label = r.name.clone();
            scene.excitation = ExcitationDef::Record {
                record: name.clone(),
                scale: 1.0,
            };
            (GroundMotion::Record(std::sync::Arc::new(r)), None, label)
        }
    };
    let duration = match (req.duration, motion.duration()) {
        (Some(d), _) => d,
        (None, Some(d)) => d,
        (None, None) => 100.0,
    };
    // The raft can slide as far as the ground moves: make sure the ground is long enough.
    let travel = max_abs_displacement(&motion, duration);
    extend_ground(&mut scene, 1.2 * travel + 10.0)?;
    if req.fixed_base {
        for c in &mut scene.contacts {
            if c.name == roles.joint {
                c.bonded = true;
            }
        }
    }
    if let Some(kind) = req.ground {
        scene.ground.kind = kind;
    }
    Ok(TwoBlockSetup {
        scene,
        motion,
        duration,
        freq_ratio: omega_ratio,
        excitation,
        roles,
        friction,
    })
}

/// Runs one two-mass simulation as requested.
pub fn run(req: &RunRequest) -> Result<RunOutcome> {
    let TwoBlockSetup {
        scene,
        motion,
        duration,
        freq_ratio: omega_ratio,
        excitation,
        roles,
        friction,
    } = two_block_setup(req)?;
    let structure_hz = roles.structure_frequency_hz;
    let a_max = motion.peak_accel(duration);
    let run = match req.model {
        ModelKind::Dda => {
            let solver = SolverParams {
                dt: req.dt,
                duration,
                integrator: req.integrator,
                ..SolverParams::default()
            };
            two_block::run_dda(&scene, &motion, solver, req.record_every)?
        }
        ModelKind::MassSpring => two_block::run_exact(
            req.alpha,
            structure_hz,
            roles.total_mass,
            friction,
            &motion,
            duration,
            req.dt * req.record_every as f64,
        )?,
    };
    let d_scale = omega_ratio.map(|r| {
        let big_omega = 2.0 * std::f64::consts::PI * structure_hz * r;
        a_max / (big_omega * big_omega)
    });
    let summary = RunSummary {
        scene: scene.name.clone(),
        model: req.model.label().into(),
        integrator: req.integrator.label(),
        alpha: req.alpha,
        friction: if req.fixed_base {
            None
        } else {
            Some(req.friction)
        },
        fixed_base: req.fixed_base,
        freq_ratio: omega_ratio,
        excitation,
        amplitude_g: a_max / STANDARD_GRAVITY,
        duration_s: duration,
        dt_s: req.dt,
        us_max_over_d: d_scale.map(|d| run.peaks.slip_m / d),
        ur_max_over_d: d_scale.map(|d| run.peaks.drift_m / d),
        abase_over_aground: run.peaks.base_accel / a_max,
        aroof_over_aground: run.peaks.roof_accel / a_max,
        us_max_m: run.peaks.slip_m,
        ur_max_m: run.peaks.drift_m,
        residual_slip_m: run.residual_slip_m,
        steps: run.steps,
        open_close_passes: run.passes,
        dt_cuts: run.cuts,
        max_penetration_ratio: run.max_penetration_ratio,
        energy_residual_rel: run.energy_residual_rel,
        input_work_j: run.input_work,
        friction_dissipated_j: run.friction_dissipated,
        wall_time_s: run.wall_time_s,
    };
    Ok(RunOutcome { summary, run })
}

/// Largest |ground displacement| over [0, duration] (sampled finely enough for a bound).
fn max_abs_displacement(motion: &GroundMotion, duration: f64) -> f64 {
    let n = 2000;
    (0..=n)
        .map(|k| motion.displacement(duration * k as f64 / n as f64).abs())
        .fold(0.0, f64::max)
}

/// Writes a run's histories and summary into `dir`.
pub fn write_outputs(outcome: &RunOutcome, dir: &PathBuf) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let csv = dir.join("history.csv");
    outcome.run.history.write_csv(&csv)?;
    let json = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&outcome.summary)
        .map_err(|e| Error::Scene(format!("cannot serialise the summary: {e}")))?;
    std::fs::write(&json, text).map_err(|e| Error::io(&json, e))?;
    let mut files = vec![csv, json];
    if !outcome.run.history.is_empty() {
        let png = dir.join("history.png");
        history_figure(outcome).save_png(&png, 1400, 900)?;
        files.push(png);
    }
    Ok(files)
}

/// Time histories of a run: accelerations, slip and roof drift.
fn history_figure(outcome: &RunOutcome) -> crate::post::plot::Figure {
    use crate::post::plot::{Figure, Series};
    let h = &outcome.run.history;
    let s = &outcome.summary;
    let col = |name: &str| h.column(name).map(<[f64]>::to_vec).unwrap_or_default();
    let t = col("time_s");
    let g = |v: Vec<f64>| {
        v.into_iter()
            .map(|a| a / STANDARD_GRAVITY)
            .collect::<Vec<f64>>()
    };
    let mut fig = Figure::new(
        format!(
            "{} ({}), α = {}, ρ = {}, {}",
            s.scene,
            s.model,
            s.alpha,
            s.friction.map_or("∞".into(), |f| f.to_string()),
            s.excitation
        ),
        2,
        2,
    );
    let p = &mut fig.panels[0];
    p.title = "ground and base acceleration".into();
    p.x_label = "t (s)".into();
    p.y_label = "a (g)".into();
    p.series.push(Series::line(
        "ground",
        t.clone(),
        g(col("ground_accel_m_s2")),
        6,
    ));
    p.series.push(Series::line(
        "base",
        t.clone(),
        g(col("base_accel_m_s2")),
        1,
    ));
    let p = &mut fig.panels[1];
    p.title = "roof acceleration (absolute)".into();
    p.x_label = "t (s)".into();
    p.y_label = "a (g)".into();
    p.series.push(Series::line(
        "roof",
        t.clone(),
        g(col("roof_accel_m_s2")),
        0,
    ));
    let p = &mut fig.panels[2];
    p.title = format!("slip of the base u_s (peak {:.3e} m)", s.us_max_m);
    p.x_label = "t (s)".into();
    p.y_label = "u_s (m)".into();
    p.series.push(Series::line("", t.clone(), col("slip_m"), 2));
    let p = &mut fig.panels[3];
    p.title = format!("roof drift u_r (peak {:.3e} m)", s.ur_max_m);
    p.x_label = "t (s)".into();
    p.y_label = "u_r (m)".into();
    p.series.push(Series::line("", t, col("roof_drift_m"), 3));
    fig
}
