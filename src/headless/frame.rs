//! Building scenes (a frame of blocks on a sliding base slab): natural frequencies, runs
//! under a record with sliding or fixed base, and the equivalent MDOF mass-spring model.

use std::time::Instant;

use serde::Serialize;

use super::simulate::{self, ModelRun, SPECTRUM_DT, SPECTRUM_MAX_SAMPLES, SolverCounts};
use crate::analytic::{ExactOptions, ShearBuilding, simulate};
use crate::dda::{Dda, FrictionLaw, Integrator, SolverParams};
use crate::ground_motion::STANDARD_GRAVITY;
use crate::model::Scene;
use crate::model::scene::ExcitationDef;
use crate::post::history::History;
use crate::post::spectrum::{UniformSeries, fourier_amplitude, resample_uniform};
use crate::setup::{ModelKind, RunSetup, RunSpec};
use crate::{Error, Result};

/// The paper's natural frequencies of its three-storey frame, Hz.
pub const PAPER_FREQUENCIES_HZ: [f64; 3] = [0.638, 1.788, 2.583];

/// The paper's frequencies to set beside the scene asked for as `scene` (a name or a
/// file): only its own frame, the built-in `three-storey`. A file that kept the name, or
/// another frame, is not the paper's (a copy with heavier floors was shown "paper 0.638 Hz
/// (−24 %)" as if the frame were off; `frame:5` beside 0.638 Hz).
pub fn paper_frequencies_for(scene: &str) -> Option<[f64; 3]> {
    (scene == "three-storey").then_some(PAPER_FREQUENCIES_HZ)
}

pub use crate::setup::modes::{ModesReport, frame_roles, modes, roles};

/// Summary of a building run (the JSON object of `run --json`). A quantity that is
/// undefined for the run is left out (never `null`), and `warnings` says why.
#[derive(Debug, Clone, Serialize)]
pub struct FrameSummary {
    /// Scene.
    pub scene: String,
    /// `dda` or `mass-spring` (the equivalent MDOF model).
    pub model: String,
    /// Integrator (DDA only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Record name (or the harmonic input).
    pub record: String,
    /// The vertical ground motion (record name), when the ground also shakes vertically.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertical_record: Option<String>,
    /// Structural damping ratio ζ (`--damping`), when the structure is damped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// The bearing under the base slab, `pendulum:R`, when it is not the flat joint.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing: Option<String>,
    /// Friction coefficient (absent for a fixed base); with a law other than Coulomb's,
    /// its sticking coefficient.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// The sliding joint's friction law when it is not Coulomb's (see
    /// [`super::run::reported_law`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<String>,
    /// Fixed base.
    pub fixed_base: bool,
    /// Duration, s.
    pub duration_s: f64,
    /// Largest |slip| of the base relative to the ground, m.
    pub max_slip_m: f64,
    /// Slip at the end, m.
    pub residual_slip_m: f64,
    /// Peak |absolute roof acceleration|, g.
    pub peak_roof_accel_g: f64,
    /// Peak |absolute base acceleration|, g.
    pub peak_base_accel_g: f64,
    /// Peak |absolute roof acceleration| low-passed at 25 Hz, g (DDA): robust to the
    /// one-step spikes of impacts and stick events, whose heights depend on Δt and on the
    /// solver's path (see [`crate::post::filter`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_roof_accel_25hz_g: Option<f64>,
    /// Peak |absolute base acceleration| low-passed at 25 Hz, g (DDA).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_base_accel_25hz_g: Option<f64>,
    /// Peak ground acceleration, g.
    pub peak_ground_accel_g: f64,
    /// Peak |roof displacement relative to the base|, m.
    pub peak_roof_drift_m: f64,
    /// Frequency of the largest Fourier amplitude of the base acceleration between 0.05
    /// and 20 Hz (absent when the run is too short for a spectrum).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_accel_peak_freq_hz: Option<f64>,
    /// Time steps.
    pub steps: u64,
    /// What the DDA solver did (left out for the exact model).
    #[serde(flatten)]
    pub solver: Option<SolverCounts>,
    /// Energy residual relative to the energy through the structure.
    pub energy_residual_rel: f64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// What the user should know: resolution, quantities left out and why.
    pub warnings: Vec<String>,
}

/// A finished building run.
#[derive(Debug, Clone)]
pub struct FrameOutcome {
    /// Summary.
    pub summary: FrameSummary,
    /// Histories, [`HISTORY_COLUMNS`] (SI), as the setup's history plan asked.
    pub history: History,
}

/// Writes a building run's history and summary into `dir` (all or nothing).
pub fn write_outputs(
    outcome: &FrameOutcome,
    dir: &std::path::Path,
) -> Result<Vec<std::path::PathBuf>> {
    let mut staged = crate::post::output::Staged::new(dir)?;
    outcome.history.write_csv(&staged.path("history.csv"))?;
    staged.write_json("summary.json", &outcome.summary)?;
    staged.commit()
}

/// Runs a building scene with the model the specification names (DDA or the equivalent
/// MDOF mass-spring model).
pub fn run_building(spec: &RunSpec) -> Result<FrameOutcome> {
    let setup = spec.prepare()?;
    run_building_setup(&setup)
}

/// Runs a prepared building setup.
pub fn run_building_setup(setup: &RunSetup) -> Result<FrameOutcome> {
    if !matches!(setup.roles, crate::setup::SceneRoles::Building(_)) {
        return Err(Error::invalid(
            "--scene",
            format!(
                "scene '{}' is not a building (no [structure] section)",
                setup.scene.name
            ),
        ));
    }
    match setup.model {
        ModelKind::Dda => run_frame_setup(setup),
        ModelKind::MassSpring => run_mdof_setup(setup),
    }
}

/// Runs the DDA model of a building scene (whatever model the specification names).
pub fn run_frame(spec: &RunSpec) -> Result<FrameOutcome> {
    run_frame_setup(&spec.prepare()?)
}

fn run_frame_setup(setup: &RunSetup) -> Result<FrameOutcome> {
    let run = simulate::run_dda(setup, &setup.scene, setup.solver_params())?;
    let series = run.base_accel_series.clone();
    let summary = summarise(setup, ModelKind::Dda, &run, series)?;
    super::run::check_finite(&summary, setup.duration)?;
    Ok(FrameOutcome {
        summary,
        history: run.history,
    })
}

/// The summary of a building run from its peaks and the resampled base acceleration.
fn summarise(
    setup: &RunSetup,
    model: ModelKind,
    run: &ModelRun,
    base_accel: Option<UniformSeries>,
) -> Result<FrameSummary> {
    let mut warnings = setup.warnings.clone();
    warnings.extend(run.lift_off_warning(setup.vertical.is_some()));
    let peak_freq = base_accel.and_then(|series| {
        let (samples, dt) = series.finish();
        let peak = fourier_amplitude(&samples, dt)
            .ok()
            .and_then(|s| s.peak(0.05, 20.0))
            .map(|p| p.0);
        if peak.is_none() {
            warnings.push(format!(
                "the run ({} s) is too short for a spectrum of the base acceleration: \
                 base_accel_peak_freq_hz is left out",
                setup.duration
            ));
        }
        peak
    });
    let p = &run.peaks;
    let low_passed = run.low_passed;
    if model == ModelKind::Dda && low_passed.is_none() {
        warnings.push(format!(
            "the run ({} s) is too short to low-pass its accelerations (two {} ms cells at \
             least): peak_roof_accel_25hz_g and peak_base_accel_25hz_g are left out",
            setup.duration,
            crate::post::filter::CELL_S * 1e3
        ));
    }
    let in_g = |a: f64| a / STANDARD_GRAVITY;
    Ok(FrameSummary {
        scene: setup.scene.name.clone(),
        model: model.label().into(),
        integrator: (model == ModelKind::Dda).then(|| setup.integrator.label()),
        record: setup.motion.label(),
        vertical_record: setup.vertical.as_ref().map(|v| v.label()),
        damping: (setup.damping_ratio > 0.0).then_some(setup.damping_ratio),
        bearing: setup.bearing_radius.map(|r| format!("pendulum:{r}")),
        friction: super::run::reported_friction(setup, &mut warnings),
        friction_law: super::run::reported_law(setup),
        fixed_base: setup.fixed_base,
        duration_s: setup.duration,
        max_slip_m: p.slip_m,
        residual_slip_m: run.residual_slip_m,
        peak_roof_accel_g: p.roof_accel / STANDARD_GRAVITY,
        peak_base_accel_g: p.base_accel / STANDARD_GRAVITY,
        peak_roof_accel_25hz_g: low_passed.map(|l| in_g(l.roof_accel)),
        peak_base_accel_25hz_g: low_passed.map(|l| in_g(l.base_accel)),
        peak_ground_accel_g: setup.motion.peak_accel(setup.duration) / STANDARD_GRAVITY,
        peak_roof_drift_m: p.drift_m,
        base_accel_peak_freq_hz: peak_freq,
        steps: run.steps,
        solver: run.solver,
        energy_residual_rel: run.energy_residual_rel,
        wall_time_s: run.wall_time_s,
        warnings,
    })
}

/// The equivalent MDOF mass-spring model of a building scene: floor masses lumped from the
/// DDA blocks (each slab plus half of the columns above and below it), storey stiffnesses
/// fitted so that the shear building has the DDA frame's natural frequencies.
pub fn equivalent_mdof(scene: &Scene) -> Result<(ShearBuilding, ModesReport)> {
    equivalent_mdof_with(scene, modes(scene)?)
}

/// [`equivalent_mdof`] from the scene's modes already computed.
pub fn equivalent_mdof_with(
    scene: &Scene,
    report: ModesReport,
) -> Result<(ShearBuilding, ModesReport)> {
    let r = frame_roles(scene)?;
    if let Some(f) = report
        .frequencies_hz
        .iter()
        .find(|f| f.partial_cmp(&&0.0) != Some(std::cmp::Ordering::Greater))
    {
        return Err(Error::invalid(
            "--scene",
            format!(
                "the fixed-base frame of '{}' has a sway mode of frequency {f} Hz: under its \
                 own weight it is at or past its buckling load (the geometric P-Δ softening \
                 of the gravity load cancels the columns' stiffness), so no shear building \
                 is equivalent to it; run it with --model dda",
                scene.name
            ),
        ));
    }
    let dda = Dda::new(scene, None, SolverParams::default())?;
    let level_names: Vec<&str> = std::iter::once(r.base.as_str())
        .chain(r.floors.iter().map(String::as_str))
        .collect();
    let levels: Vec<usize> = level_names
        .iter()
        .map(|n| dda.block_index(n))
        .collect::<Result<_>>()?;
    let heights: Vec<f64> = levels
        .iter()
        .map(|&b| dda.blocks()[b].moments.centroid[1])
        .collect();
    let mut masses: Vec<f64> = levels
        .iter()
        .map(|&b| dda.blocks()[b].total_mass())
        .collect();
    // Every other structural block (columns) goes half to the level below and half to the
    // level above its centroid.
    for (bi, b) in dda.blocks().iter().enumerate() {
        if bi == dda.ground() || levels.contains(&bi) {
            continue;
        }
        let y = b.moments.centroid[1];
        let above = heights
            .iter()
            .position(|&h| h > y)
            .unwrap_or(heights.len() - 1);
        let below = above.saturating_sub(1);
        masses[below] += 0.5 * b.total_mass();
        masses[above] += 0.5 * b.total_mass();
    }
    let friction = scene
        .contacts
        .iter()
        .find(|c| c.name == r.joint)
        .map_or(0.0, |c| c.friction.sticking_coefficient());
    let storey_masses = masses[1..].to_vec();
    let (stiffnesses, fit_error) = fit_storey_stiffnesses(&storey_masses, &report.frequencies_hz)?;
    let report = ModesReport {
        mdof_fit_error: Some(fit_error),
        ..report
    };
    let building = ShearBuilding {
        storey_masses,
        storey_stiffnesses: stiffnesses,
        raft_mass: masses[0],
        friction,
        gravity: scene.gravity,
    };
    building.validate()?;
    Ok((building, report))
}

/// Storey stiffnesses of a shear building with these floor masses whose fixed-base
/// frequencies are `target_hz`, and the largest relative frequency mismatch left:
/// Levenberg–Marquardt on ln f(ln k), from a uniform guess. A frame that is a shear
/// building is matched to rounding; one that is not (a tall frame bends as a whole) gets
/// the shear building nearest to it in the least-squares sense of the log frequencies.
fn fit_storey_stiffnesses(masses: &[f64], target_hz: &[f64]) -> Result<(Vec<f64>, f64)> {
    let n = masses.len();
    if target_hz.len() < n {
        return Err(Error::Solver {
            time: 0.0,
            reason: format!(
                "the modal analysis found {} sway modes for {n} floors",
                target_hz.len()
            ),
        });
    }
    let freqs = |k: &[f64]| -> Vec<f64> {
        ShearBuilding {
            storey_masses: masses.to_vec(),
            storey_stiffnesses: k.to_vec(),
            raft_mass: 1.0,
            friction: f64::INFINITY,
            gravity: STANDARD_GRAVITY,
        }
        .fixed_base_frequencies_hz()
    };
    let residuals = |k: &[f64]| -> Option<Vec<f64>> {
        let f = freqs(k);
        let r: Vec<f64> = (0..n)
            .map(|i| Some(f.get(i)?.ln() - target_hz[i].ln()))
            .collect::<Option<_>>()?;
        r.iter().all(|x| x.is_finite()).then_some(r)
    };
    let cost = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    // Uniform guess from the first mode.
    let w1 = 2.0 * std::f64::consts::PI * target_hz[0];
    let mut k: Vec<f64> = vec![w1 * w1 * masses.iter().sum::<f64>() / n as f64 * 2.0; n];
    let scale0 = target_hz[0] / freqs(&k)[0];
    for v in &mut k {
        *v *= scale0 * scale0;
    }
    let mut res = residuals(&k).ok_or_else(|| Error::Solver {
        time: 0.0,
        reason: "the storey-stiffness fit has no valid starting point".into(),
    })?;
    let mut lambda = 1e-3;
    for _ in 0..200 {
        if res.iter().all(|r| r.abs() < 1e-12) {
            break;
        }
        // Jacobian d ln f / d ln k by finite differences.
        let h = 1e-6_f64;
        let mut jac = nalgebra::DMatrix::zeros(n, n);
        for j in 0..n {
            let mut kp = k.clone();
            kp[j] *= 1.0 + h;
            let Some(rp) = residuals(&kp) else { continue };
            for i in 0..n {
                jac[(i, j)] = (rp[i] - res[i]) / h.ln_1p();
            }
        }
        let jt = jac.transpose();
        let g = &jt * nalgebra::DVector::from_column_slice(&res);
        let jtj = &jt * &jac;
        let mut improved = false;
        for _ in 0..20 {
            let mut a = jtj.clone();
            for d in 0..n {
                a[(d, d)] += lambda * (1.0 + jtj[(d, d)]);
            }
            let Some(step) = a.lu().solve(&(-&g)) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = (0..n)
                .map(|j| k[j] * step[j].clamp(-0.5, 0.5).exp())
                .collect();
            if let Some(r) = residuals(&trial)
                && cost(&r) < cost(&res)
            {
                (k, res) = (trial, r);
                lambda = (lambda * 0.3).max(1e-12);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    let f = freqs(&k);
    let error = (0..n)
        .map(|i| (f[i] / target_hz[i] - 1.0).abs())
        .fold(0.0, f64::max);
    if !error.is_finite() || k.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(Error::Solver {
            time: 0.0,
            reason: format!("no shear building was found near the frequencies {target_hz:?}"),
        });
    }
    Ok((k, error))
}

/// A fit of the equivalent shear building to the DDA frequencies within this relative
/// error is exact for every purpose; beyond it, runs and `modes` say how close it is.
pub const MDOF_FIT_TOLERANCE: f64 = 1e-6;

/// The warning of an inexact equivalent shear building.
pub fn mdof_fit_warning(error: f64) -> String {
    format!(
        "no shear building has exactly the DDA frame's frequencies (the frame bends as a \
         whole); the equivalent MDOF model is the nearest one, its frequencies within {:.2} %",
        100.0 * error
    )
}

/// Output interval of the MDOF model's time history, s: the base-acceleration spectrum is
/// computed from it.
const MDOF_OUTPUT_DT: f64 = 0.002;

/// Runs the equivalent MDOF mass-spring model of a building scene (whatever model the
/// specification names).
pub fn run_mdof(spec: &RunSpec) -> Result<FrameOutcome> {
    run_mdof_setup(&spec.prepare()?)
}

fn run_mdof_setup(setup: &RunSetup) -> Result<FrameOutcome> {
    let start = Instant::now();
    let (mut building, report) = equivalent_mdof(&setup.scene)?;
    let mut setup = setup.clone();
    if let Some(e) = report.mdof_fit_error.filter(|&e| e > MDOF_FIT_TOLERANCE) {
        setup.warnings.push(mdof_fit_warning(e));
    }
    let setup = &setup;
    if setup.fixed_base {
        building.friction = f64::INFINITY;
    }
    let motion = &setup.motion;
    let output_dt = simulate::exact_output_dt(MDOF_OUTPUT_DT, setup.duration);
    let keep = setup.history.stride() > 0;
    let (run, raft_accel) = if setup.needs_stepped_exact() {
        let damping = building.rayleigh_damping(setup.damping_ratio)?;
        let mut structure =
            building.sliding_structure(setup.joint_law(), damping, motion, setup.vertical.as_ref());
        if let Some(radius) = setup.bearing_radius {
            structure.surface = crate::analytic::Surface::Linearised { radius };
        }
        let options = crate::analytic::SteppedOptions::default();
        let r = crate::analytic::simulate_stepped(&structure, setup.duration, output_dt, &options)?;
        let run = simulate::stepped_model_run(&r, motion, setup.duration, keep, 1.0, start);
        (run, (r.time, r.raft_accel))
    } else {
        let r = simulate(
            &building,
            motion,
            setup.duration,
            output_dt,
            &ExactOptions::default(),
        )?;
        let residual = r.energy.residual_relative();
        let run = simulate::exact_model_run(&r, motion, keep, 1.0, residual, start);
        (run, (r.time, r.raft_accel))
    };
    let mut series = UniformSeries::new(SPECTRUM_DT, SPECTRUM_MAX_SAMPLES);
    for (&t, &a) in raft_accel.0.iter().zip(&raft_accel.1) {
        series.push(t, a);
    }
    let summary = summarise(setup, ModelKind::MassSpring, &run, Some(series))?;
    super::run::check_finite(&summary, setup.duration)?;
    Ok(FrameOutcome {
        summary,
        history: run.history,
    })
}

/// Natural frequencies measured from a free-vibration run of the fixed-base frame (an
/// independent check of [`modes`]): the roof is given a horizontal velocity and left to
/// vibrate for `duration` seconds (trapezoidal rule: no numerical damping); the highest
/// peaks of the Fourier spectrum of the roof drift are the natural frequencies.
pub fn free_vibration_frequencies(
    scene: &Scene,
    duration: f64,
    dt: f64,
    count: usize,
) -> Result<Vec<f64>> {
    let r = frame_roles(scene)?;
    let mut scene = scene.clone();
    for c in scene.contacts.iter_mut().filter(|c| c.name == r.joint) {
        c.bonded = true;
    }
    scene.excitation = ExcitationDef::None;
    let params = SolverParams {
        dt,
        duration,
        integrator: Integrator::Trapezoidal,
        ..SolverParams::default()
    };
    let mut dda = Dda::new(&scene, None, params)?;
    let base = dda.block_index(&r.base)?;
    let roof = dda.block_index(r.floors.last().map_or(&r.base, |s| s))?;
    // Alternating floor velocities excite all sway modes, not mostly the first.
    for (k, name) in r.floors.iter().enumerate() {
        let v = if k % 2 == 0 { 0.05 } else { -0.05 };
        dda.set_velocity(dda.block_index(name)?, [v, 0.0, 0.0, 0.0, 0.0, 0.0])?;
    }
    let (mut t, mut drift) = (vec![0.0], vec![0.0]);
    dda.run_until(duration, |d, _| {
        t.push(d.time());
        drift.push(
            d.displacement_relative_to_ground(roof) - d.displacement_relative_to_ground(base),
        );
    })?;
    let uniform = resample_uniform(&t, &drift, dt)?;
    let spectrum = fourier_amplitude(&uniform, dt)?;
    let mut peaks: Vec<f64> = spectrum
        .peaks(0.05, 20.0, count)
        .into_iter()
        .map(|p| p.0)
        .collect();
    peaks.sort_by(f64::total_cmp);
    Ok(peaks)
}
