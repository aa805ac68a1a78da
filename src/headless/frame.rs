//! Building scenes (a frame of blocks on a sliding base slab): natural frequencies, runs
//! under a record with sliding or fixed base, and the equivalent MDOF mass-spring model.

use std::time::Instant;

use serde::Serialize;

use crate::analytic::{ExactOptions, ShearBuilding, simulate};
use crate::dda::{Dda, Integrator, SolverParams};
use crate::ground_motion::{GroundMotion, STANDARD_GRAVITY, resolve_record};
use crate::model::Scene;
use crate::model::presets::resolve_scene;
use crate::model::scene::{ExcitationDef, StructureRoles};
use crate::post::history::{History, PeakTracker};
use crate::post::spectrum::{fourier_amplitude, resample_uniform};
use crate::{Error, Result};

/// The paper's natural frequencies of its three-storey frame, Hz.
pub const PAPER_FREQUENCIES_HZ: [f64; 3] = [0.638, 1.788, 2.583];

/// The structure roles of a scene, or an error naming the scene.
pub fn roles(scene: &Scene) -> Result<StructureRoles> {
    scene.structure.clone().ok_or_else(|| {
        Error::invalid(
            "--scene",
            format!(
                "scene '{}' is not a building scene (no [structure] section)",
                scene.name
            ),
        )
    })
}

/// Natural frequencies and floor mode shapes of a building's fixed-base frame.
#[derive(Debug, Clone, Serialize)]
pub struct ModesReport {
    /// Scene name.
    pub scene: String,
    /// The lowest sway frequencies, Hz (as many as there are floors).
    pub frequencies_hz: Vec<f64>,
    /// Per mode: horizontal displacement of the base and each floor, normalised so that the
    /// largest is 1 (roof positive).
    pub shapes: Vec<Vec<f64>>,
    /// Names of the base and floors, in the order of the shapes.
    pub levels: Vec<String>,
}

/// Modal analysis of a building scene from the DDA stiffness and mass (fixed base: the
/// sliding joint's springs held stuck).
pub fn modes(scene: &Scene) -> Result<ModesReport> {
    let r = roles(scene)?;
    let dda = Dda::new(scene, None, SolverParams::default())?;
    let modes = dda.modes()?;
    let levels: Vec<String> = std::iter::once(r.base.clone())
        .chain(r.floors.iter().cloned())
        .collect();
    let idx: Vec<usize> = levels
        .iter()
        .map(|n| dda.block_index(n))
        .collect::<Result<_>>()?;
    let mut frequencies_hz = Vec::new();
    let mut shapes = Vec::new();
    // Sway modes: the floors move horizontally as slabs (rather than a column or the base
    // slab vibrating on its own).
    for (f, shape) in modes.frequencies_hz.iter().zip(&modes.shapes) {
        if frequencies_hz.len() == r.floors.len() {
            break;
        }
        let u: Vec<f64> = idx.iter().map(|&b| shape[b][0]).collect();
        let floor_energy: f64 = u.iter().map(|x| x * x).sum();
        let total: f64 = shape
            .iter()
            .map(|d| d.iter().map(|x| x * x).sum::<f64>())
            .sum();
        if floor_energy < 0.05 * total {
            continue;
        }
        let peak = u
            .iter()
            .fold(0.0_f64, |m, x| if x.abs() > m.abs() { *x } else { m });
        let sign = if u[u.len() - 1] < 0.0 { -1.0 } else { 1.0 };
        shapes.push(u.iter().map(|x| sign * x / peak.abs()).collect());
        frequencies_hz.push(*f);
    }
    Ok(ModesReport {
        scene: scene.name.clone(),
        frequencies_hz,
        shapes,
        levels,
    })
}

/// A run of a building scene.
#[derive(Debug, Clone)]
pub struct FrameRequest {
    /// Built-in scene name or TOML path.
    pub scene: String,
    /// Record (built-in name or file); `None`: the scene's excitation.
    pub record: Option<String>,
    /// Friction coefficient of the sliding joint; `None`: the scene's.
    pub friction: Option<f64>,
    /// Fixed base: the joint is bonded.
    pub fixed_base: bool,
    /// Time step, s.
    pub dt: f64,
    /// Integrator.
    pub integrator: Integrator,
    /// Duration, s; `None`: the record's length.
    pub duration: Option<f64>,
}

impl Default for FrameRequest {
    fn default() -> Self {
        Self {
            scene: "three-storey".into(),
            record: None,
            friction: None,
            fixed_base: false,
            dt: 1e-3,
            integrator: Integrator::default(),
            duration: None,
        }
    }
}

/// Summary of a building run (the JSON object of `run --json`).
#[derive(Debug, Clone, Serialize)]
pub struct FrameSummary {
    /// Scene.
    pub scene: String,
    /// `dda` or `mass-spring` (the equivalent MDOF model).
    pub model: String,
    /// Integrator.
    pub integrator: String,
    /// Record name.
    pub record: String,
    /// Friction coefficient (null for a fixed base).
    pub friction: Option<f64>,
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
    /// Peak ground acceleration, g.
    pub peak_ground_accel_g: f64,
    /// Peak |roof displacement relative to the base|, m.
    pub peak_roof_drift_m: f64,
    /// Frequency of the largest Fourier amplitude of the base acceleration, Hz.
    pub base_accel_peak_freq_hz: f64,
    /// Time steps.
    pub steps: u64,
    /// Open-close passes (DDA).
    pub open_close_passes: u64,
    /// Δt cuts (DDA).
    pub dt_cuts: u64,
    /// Numeric factorisations of the system matrix (DDA; the other passes were solved
    /// with a kept factor).
    pub factorizations: u64,
    /// Largest penetration / structure size (DDA).
    pub max_penetration_ratio: f64,
    /// Energy residual relative to the energy through the structure.
    pub energy_residual_rel: f64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
}

/// A finished building run.
#[derive(Debug, Clone)]
pub struct FrameOutcome {
    /// Summary.
    pub summary: FrameSummary,
    /// Histories: time_s, ground_accel, slip, base_accel, roof_accel, roof_drift (SI).
    pub history: History,
}

/// History columns of a building run.
pub const FRAME_COLUMNS: [&str; 6] = [
    "time_s",
    "ground_accel_m_s2",
    "slip_m",
    "base_accel_m_s2",
    "roof_accel_m_s2",
    "roof_drift_m",
];

/// Loads the scene and motion of a request, applying friction, fixed base and record.
pub fn prepare(req: &FrameRequest) -> Result<(Scene, StructureRoles, GroundMotion, f64)> {
    crate::error::require_positive("--dt", req.dt)?;
    let mut scene = resolve_scene(&req.scene)?;
    let r = roles(&scene)?;
    if let Some(f) = req.friction {
        if f.is_nan() || f < 0.0 {
            return Err(Error::invalid(
                "--friction",
                format!("must be >= 0, got {f}"),
            ));
        }
        for c in scene.contacts.iter_mut().filter(|c| c.name == r.joint) {
            c.friction = f;
        }
    }
    if req.fixed_base {
        for c in scene.contacts.iter_mut().filter(|c| c.name == r.joint) {
            c.bonded = true;
        }
    }
    let (record, scale) = match (&req.record, &scene.excitation) {
        (Some(name), _) => (name.clone(), 1.0),
        (None, ExcitationDef::Record { record, scale }) => (record.clone(), *scale),
        (None, _) => {
            return Err(Error::invalid(
                "--record",
                "the scene has no record; give one with --record",
            ));
        }
    };
    let mut rec = resolve_record(&record)?;
    if scale != 1.0 {
        rec = rec.scaled(scale)?;
    }
    let motion = GroundMotion::Record(std::sync::Arc::new(rec));
    let duration = match req.duration {
        Some(d) => crate::error::require_positive("--duration", d)?,
        None => motion.duration().unwrap_or(30.0),
    };
    Ok((scene, r, motion, duration))
}

/// Runs the DDA model of a building scene.
pub fn run_frame(req: &FrameRequest) -> Result<FrameOutcome> {
    let (scene, r, motion, duration) = prepare(req)?;
    let start = Instant::now();
    let params = SolverParams {
        dt: req.dt,
        duration,
        integrator: req.integrator,
        ..SolverParams::default()
    };
    let mut dda = Dda::new(&scene, Some(motion.clone()), params)?;
    let base = dda.block_index(&r.base)?;
    let roof = dda.block_index(r.floors.last().map_or(&r.base, |s| s))?;
    let mut history = History::new(&FRAME_COLUMNS);
    let (mut slip_pk, mut base_pk, mut roof_pk, mut drift_pk) = Default::default();
    let mut last_slip = 0.0;
    dda.run_until(duration, |d, _| {
        let t = d.time();
        let slip = d.displacement_relative_to_ground(base);
        let drift = d.displacement_relative_to_ground(roof) - slip;
        let (a_base, a_roof) = (d.absolute_accel(base), d.absolute_accel(roof));
        PeakTracker::offer(&mut slip_pk, t, slip);
        PeakTracker::offer(&mut base_pk, t, a_base);
        PeakTracker::offer(&mut roof_pk, t, a_roof);
        PeakTracker::offer(&mut drift_pk, t, drift);
        history.push(&[t, motion.accel(t), slip, a_base, a_roof, drift]);
        last_slip = slip;
    })?;
    let counters = dda.counters();
    let summary = summarise(
        &scene,
        "dda",
        req,
        &motion,
        duration,
        &history,
        [slip_pk, base_pk, roof_pk, drift_pk],
        last_slip,
        counters.steps,
        start,
    )?;
    Ok(FrameOutcome {
        summary: FrameSummary {
            open_close_passes: counters.passes,
            dt_cuts: counters.cuts,
            factorizations: counters.factorizations,
            max_penetration_ratio: counters.max_penetration_ratio,
            energy_residual_rel: dda.energy_residual_relative(),
            ..summary
        },
        history,
    })
}

#[allow(clippy::too_many_arguments)]
fn summarise(
    scene: &Scene,
    model: &str,
    req: &FrameRequest,
    motion: &GroundMotion,
    duration: f64,
    history: &History,
    peaks: [PeakTracker; 4],
    residual_slip: f64,
    steps: u64,
    start: Instant,
) -> Result<FrameSummary> {
    let t = history.column("time_s").unwrap_or_default();
    let a = history.column("base_accel_m_s2").unwrap_or_default();
    let fft_dt = 0.005;
    let uniform = resample_uniform(t, a, fft_dt)?;
    let peak_freq = fourier_amplitude(&uniform, fft_dt)?
        .peak(0.05, 20.0)
        .map_or(f64::NAN, |p| p.0);
    let [slip, base, roof, drift] = peaks;
    Ok(FrameSummary {
        scene: scene.name.clone(),
        model: model.into(),
        integrator: req.integrator.label(),
        record: motion.label(),
        friction: if req.fixed_base {
            None
        } else {
            scene
                .structure
                .as_ref()
                .and_then(|r| scene.contacts.iter().find(|c| c.name == r.joint))
                .map(|c| c.friction)
        },
        fixed_base: req.fixed_base,
        duration_s: duration,
        max_slip_m: slip.value,
        residual_slip_m: residual_slip,
        peak_roof_accel_g: roof.value / STANDARD_GRAVITY,
        peak_base_accel_g: base.value / STANDARD_GRAVITY,
        peak_ground_accel_g: motion.peak_accel(duration) / STANDARD_GRAVITY,
        peak_roof_drift_m: drift.value,
        base_accel_peak_freq_hz: peak_freq,
        steps,
        open_close_passes: 0,
        dt_cuts: 0,
        factorizations: 0,
        max_penetration_ratio: 0.0,
        energy_residual_rel: 0.0,
        wall_time_s: start.elapsed().as_secs_f64(),
    })
}

/// The equivalent MDOF mass-spring model of a building scene: floor masses lumped from the
/// DDA blocks (each slab plus half of the columns above and below it), storey stiffnesses
/// fitted so that the shear building has the DDA frame's natural frequencies.
pub fn equivalent_mdof(scene: &Scene) -> Result<(ShearBuilding, ModesReport)> {
    let r = roles(scene)?;
    let report = modes(scene)?;
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
        .map_or(0.0, |c| c.friction);
    let storey_masses = masses[1..].to_vec();
    let stiffnesses = fit_storey_stiffnesses(&storey_masses, &report.frequencies_hz)?;
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
/// frequencies are `target_hz` (Newton's method on log k, from a uniform guess).
fn fit_storey_stiffnesses(masses: &[f64], target_hz: &[f64]) -> Result<Vec<f64>> {
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
    // Uniform guess from the first mode.
    let w1 = 2.0 * std::f64::consts::PI * target_hz[0];
    let mut k: Vec<f64> = vec![w1 * w1 * masses.iter().sum::<f64>() / n as f64 * 2.0; n];
    let scale0 = target_hz[0] / freqs(&k)[0];
    for v in &mut k {
        *v *= scale0 * scale0;
    }
    for _ in 0..50 {
        let f = freqs(&k);
        let res: Vec<f64> = (0..n).map(|i| f[i].ln() - target_hz[i].ln()).collect();
        if res.iter().all(|r| r.abs() < 1e-12) {
            break;
        }
        // Jacobian d ln f / d ln k by finite differences.
        let mut jac = nalgebra::DMatrix::zeros(n, n);
        for j in 0..n {
            let mut kp = k.clone();
            kp[j] *= 1.0 + 1e-6;
            let fp = freqs(&kp);
            for i in 0..n {
                jac[(i, j)] = (fp[i].ln() - f[i].ln()) / (1e-6_f64).ln_1p();
            }
        }
        let rhs = nalgebra::DVector::from_iterator(n, res.iter().map(|r| -r));
        let step = jac.lu().solve(&rhs).ok_or_else(|| Error::Solver {
            time: 0.0,
            reason: "the storey-stiffness fit is singular".into(),
        })?;
        for j in 0..n {
            k[j] *= step[j].clamp(-0.5, 0.5).exp();
        }
    }
    let f = freqs(&k);
    if (0..n).any(|i| (f[i] / target_hz[i] - 1.0).abs() > 1e-6) {
        return Err(Error::Solver {
            time: 0.0,
            reason: format!("no shear building has the frequencies {target_hz:?} (best fit {f:?})"),
        });
    }
    Ok(k)
}

/// Runs the equivalent MDOF mass-spring model of a building scene on the same record.
pub fn run_mdof(req: &FrameRequest) -> Result<FrameOutcome> {
    let (scene, _, motion, duration) = prepare(req)?;
    let start = Instant::now();
    let (mut building, _) = equivalent_mdof(&scene)?;
    if req.fixed_base {
        building.friction = f64::INFINITY;
    }
    let out_dt = 0.002;
    let r = simulate(
        &building,
        &motion,
        duration,
        out_dt,
        &ExactOptions::default(),
    )?;
    let top = building.storey_masses.len() - 1;
    let mut history = History::new(&FRAME_COLUMNS);
    for k in 0..r.time.len() {
        let t = r.time[k];
        history.push(&[
            t,
            motion.accel(t),
            r.slip[k],
            r.raft_accel[k],
            r.storey_accel[top][k],
            r.storey_drift[top][k],
        ]);
    }
    let pk = |v: f64| PeakTracker {
        value: v,
        time: 0.0,
    };
    let mut summary = summarise(
        &scene,
        "mass-spring",
        req,
        &motion,
        duration,
        &history,
        [
            pk(r.peaks.slip),
            pk(r.peaks.raft_accel),
            pk(r.peaks.roof_accel),
            pk(r.peaks.roof_drift),
        ],
        r.residual_slip,
        r.steps,
        start,
    )?;
    summary.energy_residual_rel = if r.energy.input_work != 0.0 {
        r.energy.residual / r.energy.input_work
    } else {
        0.0
    };
    Ok(FrameOutcome { summary, history })
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
    let r = roles(scene)?;
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
            d.blocks()[roof].centroid_displacement()[0]
                - d.blocks()[base].centroid_displacement()[0],
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
