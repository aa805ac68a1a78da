//! From a [`RunSpec`] to a [`RunSetup`]: the scene with the parameters applied, the
//! ground motion and everything else a run needs, built the same way for every front end.

use std::sync::Arc;

use super::progress::ProgressReporter;
use super::response::Probe;
use super::spec::{ExcitationSpec, Frequency, HistoryPlan, ModelKind, RunSpec};
use super::{check, defaults};
use crate::analytic::{ShearBuilding, SlidingBlock, SlidingStructure, Surface};
use crate::dda::{Dda, Integrator, RayleighDamping, SolverParams};
use crate::ground_motion::{GroundMotion, Harmonic, resolve_record};
use crate::model::Scene;
use crate::model::bearing::apply_pendulum_bearings;
use crate::model::friction::{Friction, FrictionLaw};
use crate::model::presets::{TwoBlockParams, apply_two_block, extend_ground};
use crate::model::scene::GroundKind;
use crate::model::scene::{ExcitationDef, SlidingBlockRoles, StructureRoles, TwoBlockRoles};
use crate::{Error, Result};

/// What kind of scene a run is on, with its roles.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneRoles {
    /// The paper's two-mass model (a `[two_block]` scene).
    TwoBlock {
        /// The scene's roles.
        roles: TwoBlockRoles,
        /// Mass ratio α = m/(M + m) as run.
        alpha: f64,
        /// Ω/ω of a harmonic excitation (`None` for a record).
        freq_ratio: Option<f64>,
    },
    /// A building (a `[structure]` scene).
    Building(StructureRoles),
    /// Newmark's sliding block (a `[sliding_block]` scene).
    Block(SlidingBlockRoles),
}

/// A run ready to start: validated, with every default resolved.
#[derive(Debug, Clone)]
pub struct RunSetup {
    /// The scene as run: parameters applied, ground long enough, joint bonded for a fixed
    /// base.
    pub scene: Scene,
    /// The ground motion.
    pub motion: GroundMotion,
    /// The vertical ground motion (up positive), if the ground also shakes vertically.
    pub vertical: Option<GroundMotion>,
    /// Duration, s.
    pub duration: f64,
    /// DDA time step, s.
    pub dt: f64,
    /// DDA integrator.
    pub integrator: Integrator,
    /// DDA or the exact model.
    pub model: ModelKind,
    /// How much history to keep.
    pub history: HistoryPlan,
    /// The scene's roles.
    pub roles: SceneRoles,
    /// The base block (on the sliding joint).
    pub base: String,
    /// The roof block (top of the structure).
    pub roof: String,
    /// The sliding joint (contact name).
    pub joint: String,
    /// Friction coefficient of the sliding joint as run (∞ for a fixed base).
    pub friction: f64,
    /// Whether the joint is bonded.
    pub fixed_base: bool,
    /// Structural damping ratio ζ (0: undamped).
    pub damping_ratio: f64,
    /// A building's Rayleigh damping (ratio ζ at its first two fixed-base sway modes);
    /// `None` for undamped runs and other scenes (a two-block scene's damping is the
    /// dashpot beside its spring).
    pub rayleigh: Option<RayleighDamping>,
    /// The effective radius of a frame's friction-pendulum bearings (`None`: the flat
    /// joint); the exact MDOF model then has the linearised bearing's restoring force.
    pub bearing_radius: Option<f64>,
    /// `harmonic` or the record's name.
    pub excitation_label: String,
    /// Factor applied to the ground motion to reach [`RunSpec::pga_g`] (1: as given).
    pub motion_scale: f64,
    /// Things the user should know about the run (resolution, applicability).
    pub warnings: Vec<String>,
    /// The user confirmed a run beyond the step limit (`--confirm-large`).
    pub confirm_large: bool,
    /// Told how the DDA run advances, on long runs (default: nobody).
    pub progress: Option<ProgressReporter>,
}

impl RunSpec {
    /// Checks the specification against its scene and builds the run. Nothing is solved
    /// yet; every error a run can see before it starts is reported here.
    pub fn prepare(&self) -> Result<RunSetup> {
        check::check_ranges(self)?;
        let scene = self.scene.load()?;
        check::check_applicable(self, &scene)?;
        let dt = self.dt.unwrap_or(defaults::DT);
        let integrator = self.integrator.or(scene.integrator).unwrap_or_default();
        let mut setup = if let Some(roles) = scene.two_block.clone() {
            self.two_block(scene, roles)?
        } else if let Some(roles) = scene.structure.clone() {
            self.building(scene, roles)?
        } else if let Some(roles) = scene.sliding_block.clone() {
            self.sliding_block(scene, roles)?
        } else {
            return Err(Error::invalid(
                "--scene",
                format!(
                    "scene '{}' declares no [two_block], [structure] or [sliding_block] \
                     roles, so a run does not know which blocks are the base and the roof",
                    scene.name
                ),
            ));
        };
        setup.dt = dt;
        setup.integrator = integrator;
        if let Some(pga_g) = self.pga_g {
            let (motion, factor) = scale_to_pga(&setup.motion, pga_g, setup.duration)?;
            setup.motion = motion;
            setup.motion_scale = factor;
        }
        // A sliding base travels at most as far as the ground moves: make sure the ground
        // block is long enough.
        let travel = max_abs_displacement(&setup.motion, setup.duration);
        let half_length = defaults::GROUND_TRAVEL_FACTOR * travel + defaults::GROUND_MARGIN_M;
        extend_ground(&mut setup.scene, half_length)?;
        if self.fixed_base {
            for c in setup.scene.contacts.iter_mut() {
                if c.name == setup.joint {
                    c.bonded = true;
                }
            }
        }
        if let Some(kind) = self.ground {
            setup.scene.ground.kind = kind;
        }
        self.check_dish_on_large_mass(&setup.scene)?;
        setup.vertical = self.vertical_motion(&setup.scene)?;
        setup.warnings = check::check_setup(&setup, self.confirm_large)?;
        // After the step count: a run too long to compute is told so first.
        check_ground_travel(half_length, travel, setup.duration)?;
        Ok(setup)
    }

    /// The two-mass model: α, ρ, Ω/ω and the amplitude rescale the scene.
    fn two_block(&self, mut scene: Scene, roles: TwoBlockRoles) -> Result<RunSetup> {
        let alpha = match self.alpha {
            Some(a) => a,
            None => scene_alpha(&scene, &roles)?,
        };
        let law = self.run_law(&scene, &roles.joint);
        let friction = if self.fixed_base {
            f64::INFINITY
        } else {
            law.sticking_coefficient()
        };
        let structure_hz = roles.structure_frequency_hz;
        // The scene's own harmonic input, as (amplitude, Ω/ω).
        let (scene_amplitude, scene_ratio) = match &scene.excitation {
            ExcitationDef::Harmonic {
                amplitude_g,
                frequency_hz,
            } => (*amplitude_g, frequency_hz / structure_hz),
            _ => (defaults::AMPLITUDE_G, defaults::FREQ_RATIO),
        };
        let record = match &self.excitation {
            ExcitationSpec::Record { source, scale } => Some((source.clone(), *scale)),
            ExcitationSpec::Scene => match &scene.excitation {
                ExcitationDef::Record { record, scale } => Some((record.clone(), *scale)),
                _ => None,
            },
            ExcitationSpec::Harmonic { .. } => None,
        };
        let (amplitude_g, ratio) = match &self.excitation {
            ExcitationSpec::Harmonic {
                amplitude_g,
                frequency,
            } => (
                amplitude_g.unwrap_or(scene_amplitude),
                match frequency {
                    Some(Frequency::Ratio(r)) => *r,
                    Some(Frequency::Hz(f)) => f / structure_hz,
                    None => scene_ratio,
                },
            ),
            _ => (scene_amplitude, scene_ratio),
        };
        let (lo, hi) = crate::limits::FREQUENCY_RANGE_HZ;
        let hz = ratio * structure_hz;
        if record.is_none() && !(ratio.is_finite() && (lo..=hi).contains(&hz)) {
            return Err(Error::invalid(
                "--freq-ratio",
                format!(
                    "Ω/ω = {} is {} Hz for this structure ({} Hz); the excitation frequency \
                     must be in [{lo:e}, {hi}] Hz",
                    crate::error::show(ratio),
                    crate::error::show(hz),
                    structure_hz
                ),
            ));
        }
        let params = TwoBlockParams {
            alpha,
            friction,
            freq_ratio: ratio,
            amplitude_g,
        };
        params.validate()?;
        apply_two_block(&mut scene, &params)?;
        if let Some(zeta) = self.damping {
            set_structure_damping(&mut scene, &roles, alpha, zeta);
        }
        if !self.fixed_base {
            // The two-mass parameters set a Coulomb coefficient; the run's law is the one.
            set_joint_law(&mut scene, &roles.joint, law);
        }
        let (motion, freq_ratio, excitation_label) = match record {
            None => (
                GroundMotion::Harmonic(Harmonic::from_g_hz(amplitude_g, ratio * structure_hz)?),
                Some(ratio),
                "harmonic".to_string(),
            ),
            Some((source, scale)) => {
                let r = load_record(&source, scale)?;
                let label = r.name.clone();
                scene.excitation = ExcitationDef::Record {
                    record: source,
                    scale,
                };
                (GroundMotion::Record(Arc::new(r)), None, label)
            }
        };
        let blocks = [roles.raft.clone(), roles.roof.clone(), roles.joint.clone()];
        let roles = SceneRoles::TwoBlock {
            roles,
            alpha,
            freq_ratio,
        };
        Ok(self.setup(scene, motion, roles, blocks, friction, excitation_label))
    }

    /// The set-up of a scene whose parameters are applied; `blocks` are the base, the roof
    /// and the sliding joint.
    fn setup(
        &self,
        scene: Scene,
        motion: GroundMotion,
        roles: SceneRoles,
        blocks: [String; 3],
        friction: f64,
        excitation_label: String,
    ) -> RunSetup {
        let duration = self
            .duration
            .or(motion.duration())
            .unwrap_or(defaults::HARMONIC_DURATION_S);
        let [base, roof, joint] = blocks;
        RunSetup {
            scene,
            motion,
            vertical: None,
            duration,
            dt: defaults::DT,
            integrator: Integrator::default(),
            model: self.model,
            history: self.history,
            roles,
            base,
            roof,
            joint,
            friction,
            fixed_base: self.fixed_base,
            damping_ratio: self.damping.unwrap_or(0.0),
            rayleigh: None,
            bearing_radius: None,
            excitation_label,
            motion_scale: 1.0,
            warnings: Vec::new(),
            confirm_large: self.confirm_large,
            progress: None,
        }
    }

    /// A building: friction, fixed base and excitation set on the scene as it is.
    fn building(&self, mut scene: Scene, roles: StructureRoles) -> Result<RunSetup> {
        let bearing_radius = self.bearing.and_then(|b| b.radius());
        if let Some(radius) = bearing_radius {
            let ground = scene.ground.block.clone();
            apply_pendulum_bearings(&mut scene, &ground, &roles.base, radius)?;
        }
        if let Some(law) = self.law_given() {
            set_joint_law(&mut scene, &roles.joint, law);
        }
        let motion = self.scene_or_given_motion(&scene)?;
        let friction = if self.fixed_base {
            f64::INFINITY
        } else {
            self.run_law(&scene, &roles.joint).sticking_coefficient()
        };
        let roof = roles.floors.last().unwrap_or(&roles.base).clone();
        let blocks = [roles.base.clone(), roof, roles.joint.clone()];
        let label = motion.label();
        let rayleigh = match self.damping {
            Some(zeta) if zeta > 0.0 => Some(super::modes::rayleigh_damping(&scene, zeta)?),
            _ => None,
        };
        let mut setup = self.setup(
            scene,
            motion,
            SceneRoles::Building(roles),
            blocks,
            friction,
            label,
        );
        setup.rayleigh = rayleigh;
        setup.bearing_radius = bearing_radius;
        Ok(setup)
    }

    /// Refuses a dish (a friction pendulum's, or `--bearing pendulum:R`) on the large-mass
    /// ground: that ground rides on rollers and is pushed along one line, and a block
    /// climbing its dish pushes it down and sideways as well — the run failed at its first
    /// step, or gave a roof acceleration six times the exact model's.
    fn check_dish_on_large_mass(&self, scene: &Scene) -> Result<()> {
        let ground = &scene.ground;
        let has_dish = scene
            .blocks
            .iter()
            .any(|b| b.name == ground.block && !b.arcs.is_empty());
        if ground.kind != GroundKind::LargeMass || !has_dish {
            return Ok(());
        }
        let (what, accepted) = if self.ground.is_some() {
            ("--ground", "leave out --ground or give --ground prescribed")
        } else {
            (
                "ground.kind",
                "set ground.kind = \"prescribed\" in the scene file",
            )
        };
        let dish = if self.bearing.is_some_and(|b| b.radius().is_some()) {
            "the pendulum bearings' dish (--bearing)"
        } else {
            "the ground block's dish"
        };
        Err(Error::invalid(
            what,
            format!(
                "large-mass: {dish} needs a prescribed ground (the large-mass ground moves \
                 on rollers along one line and takes flat joints only); {accepted}"
            ),
        ))
    }

    /// The vertical ground motion: the specification's, or the scene's.
    fn vertical_motion(&self, scene: &Scene) -> Result<Option<GroundMotion>> {
        let (source, scale) = match (&self.vertical, &scene.vertical_excitation) {
            (Some(v), _) => (v.source.as_str(), v.scale),
            (None, Some(v)) => (v.record.as_str(), v.scale),
            (None, None) => return Ok(None),
        };
        crate::error::require_range("--vertical-scale", scale, 1e-6, 1e3, "")?;
        let record = load_record(source, scale)?;
        Ok(Some(GroundMotion::Record(Arc::new(record))))
    }

    /// The ground motion of a building or block scene: the specification's, or the
    /// scene's own.
    fn scene_or_given_motion(&self, scene: &Scene) -> Result<GroundMotion> {
        let motion = match (&self.excitation, &scene.excitation) {
            (ExcitationSpec::Record { source, scale }, _)
            | (
                ExcitationSpec::Scene,
                ExcitationDef::Record {
                    record: source,
                    scale,
                },
            ) => GroundMotion::Record(Arc::new(load_record(source, *scale)?)),
            (
                ExcitationSpec::Scene,
                ExcitationDef::Harmonic {
                    amplitude_g,
                    frequency_hz,
                },
            ) => GroundMotion::Harmonic(Harmonic::from_g_hz(*amplitude_g, *frequency_hz)?),
            (ExcitationSpec::Scene, ExcitationDef::None) => {
                return Err(Error::invalid(
                    "--record",
                    "the scene has no ground motion; give one with --record",
                ));
            }
            (
                ExcitationSpec::Harmonic {
                    amplitude_g,
                    frequency,
                },
                own,
            ) => {
                let (own_amplitude, own_hz) = match own {
                    ExcitationDef::Harmonic {
                        amplitude_g,
                        frequency_hz,
                    } => (Some(*amplitude_g), Some(*frequency_hz)),
                    _ => (None, None),
                };
                let hz = match frequency {
                    Some(Frequency::Hz(f)) => *f,
                    Some(Frequency::Ratio(_)) => {
                        return Err(Error::invalid(
                            "--freq-ratio",
                            format!(
                                "a frequency ratio needs a two-block scene's structure \
                                 frequency; '{}' is a building (give the frequency in Hz)",
                                scene.name
                            ),
                        ));
                    }
                    None => own_hz.ok_or_else(|| {
                        Error::invalid(
                            "frequency",
                            "the scene's excitation is not harmonic; give the frequency in Hz",
                        )
                    })?,
                };
                let amplitude = amplitude_g
                    .or(own_amplitude)
                    .unwrap_or(defaults::AMPLITUDE_G);
                GroundMotion::Harmonic(Harmonic::from_g_hz(amplitude, hz)?)
            }
        };
        Ok(motion)
    }

    /// Newmark's sliding block: friction and excitation set on the scene as it is.
    fn sliding_block(&self, mut scene: Scene, roles: SlidingBlockRoles) -> Result<RunSetup> {
        if let Some(law) = self.law_given() {
            set_joint_law(&mut scene, &roles.joint, law);
        }
        let motion = self.scene_or_given_motion(&scene)?;
        let friction = if self.fixed_base {
            f64::INFINITY
        } else {
            self.run_law(&scene, &roles.joint).sticking_coefficient()
        };
        // The block is its own base and roof: drift is zero, the base acceleration is the
        // block's.
        let blocks = [
            roles.block.clone(),
            roles.block.clone(),
            roles.joint.clone(),
        ];
        let label = motion.label();
        Ok(self.setup(
            scene,
            motion,
            SceneRoles::Block(roles),
            blocks,
            friction,
            label,
        ))
    }

    /// The sliding joint's law as the run specification gives it (`--friction ρ` is
    /// Coulomb's), if it does.
    fn law_given(&self) -> Option<Friction> {
        self.friction.map(Friction::Coulomb).or(self.friction_law)
    }

    /// The friction law of the named joint as the run will have it: the specification's,
    /// or the scene's.
    fn run_law(&self, scene: &Scene, joint: &str) -> Friction {
        match self.law_given() {
            Some(law) => law,
            // The scene's validation makes sure the joint exists.
            None => scene
                .contacts
                .iter()
                .find(|c| c.name == joint)
                .map_or(Friction::Coulomb(0.0), |c| c.friction),
        }
    }
}

/// Refuses a ground motion that travels so far that the ground block, lengthened to
/// `half_length` each side, would pass the largest coordinate a scene may have (it was
/// reported as a bad vertex of a block the user never wrote).
fn check_ground_travel(half_length: f64, travel: f64, duration: f64) -> Result<()> {
    // A margin for the structure's own offset from the origin.
    let limit = 0.99 * crate::limits::MAX_COORDINATE_M;
    if half_length <= limit {
        return Ok(());
    }
    Err(Error::invalid(
        "ground motion",
        format!(
            "the ground would move up to {travel:.3e} m in {} s, and the ground \
             block under a sliding base would have to reach beyond ±{:e} m, the largest \
             coordinate a scene may have: lower the amplitude (--amplitude-g, --pga), raise \
             the frequency (--freq-ratio) or shorten --duration",
            crate::error::show(duration),
            crate::limits::MAX_COORDINATE_M
        ),
    ))
}

impl RunSetup {
    /// The solver parameters of the run (the solver's own defaults otherwise).
    pub fn solver_params(&self) -> SolverParams {
        SolverParams {
            dt: self.dt,
            duration: self.duration,
            integrator: self.integrator,
            ..SolverParams::for_scene(&self.scene)
        }
    }

    /// The DDA model of `scene` (the run's scene or a variant of it) under the run's
    /// motion, with the blocks it is measured on.
    pub fn build_dda(&self, scene: &Scene, params: SolverParams) -> Result<(Dda, Probe)> {
        let mut dda = Dda::new(scene, Some(self.motion.clone()), params)?;
        dda.set_vertical_motion(self.vertical.clone())?;
        if let Some(damping) = self.rayleigh {
            dda.set_rayleigh_damping(damping, &self.base)?;
        }
        let probe = Probe {
            base: dda.block_index(&self.base)?,
            roof: dda.block_index(&self.roof)?,
        };
        Ok((dda, probe))
    }

    /// The sliding joint's friction law as run (Coulomb's ∞ for a fixed base).
    pub fn joint_law(&self) -> Friction {
        if self.fixed_base {
            return Friction::Coulomb(f64::INFINITY);
        }
        self.scene
            .contacts
            .iter()
            .find(|c| c.name == self.joint)
            .map_or(Friction::Coulomb(self.friction), |c| c.friction)
    }

    /// Whether the mass-spring model of this run needs the stepped solution: a friction
    /// law other than Coulomb's, vertical shaking or damping, which the closed-form
    /// propagation does not have.
    pub fn needs_stepped_exact(&self) -> bool {
        !matches!(self.joint_law(), Friction::Coulomb(_))
            || self.vertical.is_some()
            || self.damping_ratio > 0.0
            || self.bearing_radius.is_some()
    }

    /// The rigid sliding block of a `block` run (its exact model's input).
    pub fn sliding_block(&self) -> SlidingBlock<'_> {
        SlidingBlock {
            friction: self.joint_law(),
            gravity: self.scene.gravity,
            horizontal: &self.motion,
            vertical: self.vertical.as_ref(),
            surface: self
                .dish_radius()
                .map_or(Surface::Flat, |radius| Surface::Circle { radius }),
        }
    }

    /// The effective radius of a friction pendulum's dish (`None`: a flat joint).
    pub fn dish_radius(&self) -> Option<f64> {
        match &self.roles {
            SceneRoles::Block(roles) => roles.dish_radius,
            SceneRoles::TwoBlock { .. } | SceneRoles::Building(_) => None,
        }
    }

    /// The two-mass model of a two-block run as a sliding structure for the stepped
    /// solution (unit total mass, the run's law, damping and motions); `None` for other
    /// scenes.
    pub fn two_block_structure(&self) -> Option<Result<SlidingStructure<'_>>> {
        let (roles, alpha, _) = self.two_block()?;
        let hz = roles.structure_frequency_hz;
        Some(ShearBuilding::two_mass(alpha, hz, 0.0).map(|building| {
            // c = 2ζ√(k m) = 2ζ·m·ω on the unit-mass model (m = α).
            let omega = 2.0 * std::f64::consts::PI * hz;
            let damping = 2.0 * self.damping_ratio * alpha * omega;
            building.sliding_structure(
                self.joint_law(),
                nalgebra::DMatrix::from_element(1, 1, damping),
                &self.motion,
                self.vertical.as_ref(),
            )
        }))
    }

    /// The run's scene with the sliding joint bonded (the fixed-base comparison).
    pub fn fixed_base_scene(&self) -> Scene {
        let mut scene = self.scene.clone();
        for c in scene.contacts.iter_mut().filter(|c| c.name == self.joint) {
            c.bonded = true;
        }
        scene
    }

    /// The run's scene with the sliding joint's friction coefficient set to `friction`
    /// (a side-by-side comparison of friction values).
    pub fn friction_variant_scene(&self, friction: f64) -> Result<Scene> {
        crate::error::require_range(
            "--compare-friction",
            friction,
            0.0,
            crate::limits::MAX_FRICTION,
            "",
        )?;
        let mut scene = self.scene.clone();
        set_joint_law(&mut scene, &self.joint, Friction::Coulomb(friction));
        Ok(scene)
    }

    /// The two-block roles, α and Ω/ω, when this is a two-block run.
    pub fn two_block(&self) -> Option<(&TwoBlockRoles, f64, Option<f64>)> {
        match &self.roles {
            SceneRoles::TwoBlock {
                roles,
                alpha,
                freq_ratio,
            } => Some((roles, *alpha, *freq_ratio)),
            SceneRoles::Building(_) | SceneRoles::Block(_) => None,
        }
    }
}

/// α = m/(M + m) of a two-block scene as written (roof and raft masses).
fn scene_alpha(scene: &Scene, roles: &TwoBlockRoles) -> Result<f64> {
    let (m, big_m) = (
        scene.block_mass(&roles.roof)?,
        scene.block_mass(&roles.raft)?,
    );
    Ok(m / (m + big_m))
}

/// A dashpot c = 2ζ√(k m) = 2ζ·m·ω in parallel with a two-block scene's spring (its
/// parameters already applied).
fn set_structure_damping(scene: &mut Scene, roles: &TwoBlockRoles, alpha: f64, zeta: f64) {
    let m = alpha * roles.total_mass;
    let omega = 2.0 * std::f64::consts::PI * roles.structure_frequency_hz;
    for b in scene.bolts.iter_mut().filter(|b| b.name == roles.spring) {
        b.damping = 2.0 * zeta * m * omega;
    }
}

/// Gives the named joint the friction law `law`.
fn set_joint_law(scene: &mut Scene, joint: &str, law: Friction) {
    for c in scene.contacts.iter_mut().filter(|c| c.name == joint) {
        c.friction = law;
    }
}

/// A record by name or file, scaled.
fn load_record(source: &str, scale: f64) -> Result<crate::ground_motion::Record> {
    let r = resolve_record(source)?;
    if scale != 1.0 { r.scaled(scale) } else { Ok(r) }
}

/// Largest |ground displacement| over [0, duration] (sampled finely enough for a bound).
fn max_abs_displacement(motion: &GroundMotion, duration: f64) -> f64 {
    let n = defaults::GROUND_TRAVEL_SAMPLES;
    (0..=n)
        .map(|k| motion.displacement(duration * k as f64 / n as f64).abs())
        .fold(0.0, f64::max)
}

/// The ground motion scaled to a peak acceleration of `pga_g` over `duration`, and the
/// factor applied.
fn scale_to_pga(motion: &GroundMotion, pga_g: f64, duration: f64) -> Result<(GroundMotion, f64)> {
    let peak = motion.peak_accel(duration) / crate::ground_motion::STANDARD_GRAVITY;
    if !(peak.is_finite() && peak > 0.0) {
        return Err(Error::invalid(
            "--pga",
            "the ground motion is zero over the run; there is nothing to scale",
        ));
    }
    let factor = pga_g / peak;
    let scaled = match motion {
        GroundMotion::Record(r) => GroundMotion::Record(Arc::new(r.scaled(factor)?)),
        GroundMotion::Harmonic(h) => GroundMotion::Harmonic(Harmonic {
            amplitude: h.amplitude * factor,
            ..*h
        }),
    };
    Ok((scaled, factor))
}
