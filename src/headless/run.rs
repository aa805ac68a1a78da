//! `slidebase run`: one simulation of a scene, summarised in the paper's terms.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::block::{SlipOverlay, draw_overlays};
use super::simulate::{self, ModelRun, SolverCounts};
use crate::ground_motion::STANDARD_GRAVITY;
use crate::post::output::Staged;
use crate::setup::{ModelKind, RunSetup, RunSpec, defaults};
use crate::{Error, Result};

/// The one-object summary printed by `--json` and written by `--out`. A quantity that is
/// undefined for the run is left out (never `null`, NaN or inf); `warnings` says why when
/// it is not obvious, and what else the user should know.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Scene name.
    pub scene: String,
    /// `dda` or `mass-spring`.
    pub model: String,
    /// Integrator (DDA only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Mass ratio α.
    pub alpha: f64,
    /// Friction coefficient ρ (absent when the base is fixed); with a law other than
    /// Coulomb's, its sticking coefficient.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// The sliding joint's friction law when it is not Coulomb's (see
    /// [`reported_law`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<String>,
    /// Whether the base was fixed.
    pub fixed_base: bool,
    /// Ω/ω (harmonic input only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub freq_ratio: Option<f64>,
    /// Excitation: `harmonic` or the record name.
    pub excitation: String,
    /// The vertical ground motion (record name), when the ground also shakes vertically.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertical_record: Option<String>,
    /// Structural damping ratio ζ (`--damping`), when the structure is damped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Peak ground acceleration, g.
    pub amplitude_g: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Nominal time step, s (DDA only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt_s: Option<f64>,
    /// max|u_s| / D with D = a_max/Ω² (harmonic input only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub us_max_over_d: Option<f64>,
    /// max|u_r| / D (harmonic input only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ur_max_over_d: Option<f64>,
    /// max|a_base| / a_max (absolute accelerations; absent when a_max = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub abase_over_aground: Option<f64>,
    /// max|a_roof| / a_max (absent when a_max = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aroof_over_aground: Option<f64>,
    /// max|u_s|, m.
    pub us_max_m: f64,
    /// max|u_r|, m.
    pub ur_max_m: f64,
    /// Slip at the end, m.
    pub residual_slip_m: f64,
    /// Time steps.
    pub steps: u64,
    /// What the DDA solver did (left out for the exact model).
    #[serde(flatten)]
    pub solver: Option<SolverCounts>,
    /// Energy residual (numerical dissipation) relative to the energy through the system.
    pub energy_residual_rel: f64,
    /// Work done by the ground on the structure, J/m.
    pub input_work_j: f64,
    /// Energy dissipated by friction, J/m.
    pub friction_dissipated_j: f64,
    /// Wall-clock time of the solve, s.
    pub wall_time_s: f64,
    /// What the user should know: resolution, quantities left out and why.
    pub warnings: Vec<String>,
}

/// A finished run: summary and histories.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The summary.
    pub summary: RunSummary,
    /// The full result (histories).
    pub run: ModelRun,
}

/// Runs one two-mass simulation as specified.
pub fn run(spec: &RunSpec) -> Result<RunOutcome> {
    let setup = spec.prepare()?;
    run_setup(&setup)
}

/// Runs a prepared two-mass setup.
pub fn run_setup(setup: &RunSetup) -> Result<RunOutcome> {
    let (roles, alpha, freq_ratio) = setup.two_block().ok_or_else(|| {
        Error::invalid(
            "--scene",
            format!(
                "scene '{}' is not a two-mass scene (no [two_block] section)",
                setup.scene.name
            ),
        )
    })?;
    let structure_hz = roles.structure_frequency_hz;
    let duration = setup.duration;
    let a_max = setup.motion.peak_accel(duration);
    let run = match setup.model {
        ModelKind::Dda => simulate::run_dda(setup, &setup.scene, setup.solver_params())?,
        ModelKind::MassSpring => {
            simulate::run_exact_two_block(setup, setup.dt * setup.history.stride() as f64)?
        }
    };
    let d_scale = freq_ratio.map(|r| {
        let big_omega = 2.0 * std::f64::consts::PI * structure_hz * r;
        a_max / (big_omega * big_omega)
    });
    let mut warnings = setup.warnings.clone();
    warnings.extend(run.lift_off_warning(setup.vertical.is_some()));
    if a_max <= 0.0 {
        warnings.push(format!(
            "the ground does not accelerate in the first {duration} s: the ratios to its \
             peak (and to D) are undefined and left out"
        ));
    }
    let exact = setup.model == ModelKind::MassSpring;
    let ratio = |x: f64, by: f64| finite(x / by).filter(|_| by > 0.0);
    let summary = RunSummary {
        scene: setup.scene.name.clone(),
        model: setup.model.label().into(),
        integrator: (!exact).then(|| setup.integrator.label()),
        alpha,
        friction: reported_friction(setup, &mut warnings),
        friction_law: reported_law(setup),
        fixed_base: setup.fixed_base,
        freq_ratio,
        excitation: setup.excitation_label.clone(),
        vertical_record: setup.vertical.as_ref().map(|v| v.label()),
        damping: (setup.damping_ratio > 0.0).then_some(setup.damping_ratio),
        amplitude_g: a_max / STANDARD_GRAVITY,
        duration_s: duration,
        dt_s: (!exact).then_some(setup.dt),
        us_max_over_d: d_scale.and_then(|d| ratio(run.peaks.slip_m, d)),
        ur_max_over_d: d_scale.and_then(|d| ratio(run.peaks.drift_m, d)),
        abase_over_aground: ratio(run.peaks.base_accel, a_max),
        aroof_over_aground: ratio(run.peaks.roof_accel, a_max),
        us_max_m: run.peaks.slip_m,
        ur_max_m: run.peaks.drift_m,
        residual_slip_m: run.residual_slip_m,
        steps: run.steps,
        solver: run.solver,
        energy_residual_rel: run.energy_residual_rel,
        input_work_j: run.input_work,
        friction_dissipated_j: run.friction_dissipated,
        wall_time_s: run.wall_time_s,
        warnings,
    };
    check_finite(&summary, duration)?;
    Ok(RunOutcome { summary, run })
}

/// The friction a summary reports: none for a fixed base, and none (with a warning) for a
/// scene whose joint has `friction = inf`, which JSON cannot carry as a number.
pub fn reported_friction(setup: &RunSetup, warnings: &mut Vec<String>) -> Option<f64> {
    if setup.fixed_base {
        return None;
    }
    if setup.friction.is_infinite() {
        warnings.push(
            "the sliding joint's friction is inf in the scene: it never slides, as a fixed \
             base; `friction` is left out"
                .into(),
        );
        return None;
    }
    Some(setup.friction)
}

/// The sliding joint's law when it is not Coulomb's (`static-kinetic:μs,μk`,
/// `velocity:μslow,μfast,rate`): `friction` alone, its sticking coefficient, would hide
/// that the run slid against a lower or speed-dependent one.
pub fn reported_law(setup: &RunSetup) -> Option<String> {
    match setup.joint_law() {
        _ if setup.fixed_base => None,
        crate::model::friction::Friction::Coulomb(_) => None,
        law => Some(law.to_string()),
    }
}

/// `Some(x)` when x is finite.
pub fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The guarantee of every summary: its JSON carries no `null` (a NaN or inf would be
/// written as one). A run that produced a non-finite number is a solver failure, reported
/// as such rather than printed.
pub fn check_finite<T: Serialize>(summary: &T, end_time: f64) -> Result<()> {
    let value = serde_json::to_value(summary)
        .map_err(|e| Error::invalid("summary", format!("cannot serialise: {e}")))?;
    if let serde_json::Value::Object(map) = value
        && let Some((key, _)) = map.iter().find(|(_, v)| v.is_null())
    {
        return Err(Error::Solver {
            time: end_time,
            reason: format!("the run produced a non-finite {key}"),
        });
    }
    Ok(())
}

/// The history a two-block run written to a folder keeps.
pub const OUTPUT_HISTORY: crate::setup::HistoryPlan =
    crate::setup::HistoryPlan::EverySteps(defaults::TWO_BLOCK_HISTORY_EVERY);

/// The overlays a teacher wants on a two-block run's figure: the exact model of the same
/// inputs (for a DDA run), and when the structure is damped the exact model without the
/// damping, so that its effect shows. Each takes milliseconds.
pub fn standard_overlays(setup: &RunSetup) -> Result<Vec<SlipOverlay>> {
    let output_dt = setup.dt * OUTPUT_HISTORY.stride() as f64;
    let mut overlays = Vec::new();
    if setup.model == ModelKind::Dda {
        overlays.push(SlipOverlay {
            label: "exact".into(),
            run: simulate::run_exact_two_block(setup, output_dt)?,
            markers: true,
        });
    }
    if setup.damping_ratio > 0.0 {
        let undamped = RunSetup {
            damping_ratio: 0.0,
            ..setup.clone()
        };
        overlays.push(SlipOverlay {
            label: "exact, undamped".into(),
            run: simulate::run_exact_two_block(&undamped, output_dt)?,
            markers: false,
        });
    }
    Ok(overlays)
}

/// Every file a `run --out` may write (the two-block, building and block runs' together),
/// checked before the run: a folder of one of these names would fail only at the end.
pub const OUTPUT_FILES: [&str; 4] = ["history.csv", "summary.json", "history.png", "friction.png"];

/// Writes a run's histories and summary into `dir`; its figure draws `overlays` over the
/// run's slip and roof drift.
pub fn write_outputs(
    outcome: &RunOutcome,
    overlays: &[SlipOverlay],
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut staged = Staged::new(dir)?;
    outcome.run.history.write_csv(&staged.path("history.csv"))?;
    staged.write_json("summary.json", &outcome.summary)?;
    if !outcome.run.history.is_empty() {
        history_figure(outcome, overlays).save_png(&staged.path("history.png"), 1400, 900)?;
    }
    staged.commit()
}

/// Time histories of a run: accelerations, slip and roof drift (with the overlays').
fn history_figure(outcome: &RunOutcome, overlays: &[SlipOverlay]) -> crate::post::plot::Figure {
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
    let damped = s
        .damping
        .map_or(String::new(), |z| format!(", damping ζ = {z}"));
    let p = &mut fig.panels[2];
    p.title = format!("slip of the base u_s (peak {:.3e} m){damped}", s.us_max_m);
    p.x_label = "t (s)".into();
    p.y_label = "u_s (m)".into();
    p.series
        .push(Series::line(s.model.clone(), t.clone(), col("slip_m"), 2));
    draw_overlays(p, overlays, "slip_m");
    let p = &mut fig.panels[3];
    p.title = format!("roof drift u_r (peak {:.3e} m){damped}", s.ur_max_m);
    p.x_label = "t (s)".into();
    p.y_label = "u_r (m)".into();
    p.series
        .push(Series::line(s.model.clone(), t, col("roof_drift_m"), 3));
    draw_overlays(p, overlays, "roof_drift_m");
    fig
}
