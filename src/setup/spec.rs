//! What a run is: the one specification the command line, the visualizer and the studies
//! fill in.

use serde::Serialize;

use crate::Result;
use crate::dda::Integrator;
use crate::model::Scene;
use crate::model::friction::Friction;
use crate::model::presets::resolve_scene;
use crate::model::scene::GroundKind;

/// Which model computes the response.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ModelKind {
    /// Discontinuous Deformation Analysis of the blocks.
    #[default]
    Dda,
    /// The exact (event-driven) solution of the mass-spring model: the paper's two-mass
    /// model (Appendix I) for a two-block scene, the equivalent shear building for a
    /// building scene.
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

/// Where the scene comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneSource {
    /// A built-in name (`two-block`, `three-storey`), a generated one (`frame:N`,
    /// `wall:N`) or a TOML file path.
    Named(String),
    /// A scene already in memory (the visualizer's, or a study's variant).
    Given(Box<Scene>),
}

impl SceneSource {
    /// Loads (or copies) the scene.
    pub fn load(&self) -> Result<Scene> {
        match self {
            SceneSource::Named(name) => resolve_scene(name),
            SceneSource::Given(scene) => Ok((**scene).clone()),
        }
    }
}

impl From<&str> for SceneSource {
    fn from(name: &str) -> Self {
        SceneSource::Named(name.to_string())
    }
}

impl From<String> for SceneSource {
    fn from(name: String) -> Self {
        SceneSource::Named(name)
    }
}

impl From<Scene> for SceneSource {
    fn from(scene: Scene) -> Self {
        SceneSource::Given(Box::new(scene))
    }
}

/// The frequency of a harmonic excitation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Frequency {
    /// Ω/ω: a multiple of a two-block scene's structure frequency.
    Ratio(f64),
    /// Hz.
    Hz(f64),
}

/// The ground motion of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ExcitationSpec {
    /// The scene's own excitation.
    #[default]
    Scene,
    /// Harmonic `a(t) = A sin(Ωt)` from rest; a `None` part is the scene's own (or the
    /// default of [`super::defaults`] when the scene's excitation is not harmonic).
    Harmonic {
        /// Amplitude, g.
        amplitude_g: Option<f64>,
        /// Frequency.
        frequency: Option<Frequency>,
    },
    /// A record: a built-in name or an AT2/CSV file, its accelerations times `scale`.
    Record {
        /// Built-in name or file path.
        source: String,
        /// Factor on the record's accelerations.
        scale: f64,
    },
}

impl ExcitationSpec {
    /// Harmonic input at Ω/ω = `ratio` with the scene's amplitude.
    pub fn ratio(ratio: f64) -> Self {
        ExcitationSpec::Harmonic {
            amplitude_g: None,
            frequency: Some(Frequency::Ratio(ratio)),
        }
    }

    /// A record, unscaled.
    pub fn record(source: impl Into<String>) -> Self {
        ExcitationSpec::Record {
            source: source.into(),
            scale: 1.0,
        }
    }
}

/// A vertical ground motion: a recorded vertical component (up positive).
#[derive(Debug, Clone, PartialEq)]
pub struct VerticalSpec {
    /// Built-in name (`el-centro-up`) or file path.
    pub source: String,
    /// Factor on the record's accelerations.
    pub scale: f64,
}

/// How much of the time history a run keeps in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HistoryPlan {
    /// Peaks only: no time history (what `run` without `--out` needs).
    #[default]
    PeaksOnly,
    /// Every n-th DDA step (n ≥ 1); the exact model outputs every n·Δt seconds.
    EverySteps(usize),
}

impl HistoryPlan {
    /// The DDA recording stride, 0 for none.
    pub fn stride(&self) -> usize {
        match *self {
            HistoryPlan::PeaksOnly => 0,
            HistoryPlan::EverySteps(n) => n,
        }
    }
}

/// Everything that defines a run. A `None` takes the scene's value or the default of
/// [`super::defaults`]; [`RunSpec::prepare`](super::RunSpec::prepare) checks the whole
/// specification against the scene (ranges, flags that do not apply, limits) before any
/// work starts.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunSpec {
    /// The scene.
    pub scene: SceneSource,
    /// DDA or the exact mass-spring model.
    pub model: ModelKind,
    /// The ground motion.
    pub excitation: ExcitationSpec,
    /// Vertical ground motion (default: the scene's `[vertical_excitation]`, if any).
    pub vertical: Option<VerticalSpec>,
    /// Mass ratio α = m/(M + m) (two-block scenes; default: the scene's).
    pub alpha: Option<f64>,
    /// Friction coefficient ρ of the sliding joint (default: the scene's).
    pub friction: Option<f64>,
    /// Friction law of the sliding joint (default: the scene's; not with `friction`).
    pub friction_law: Option<Friction>,
    /// Fix the base: the sliding joint is bonded and never slides.
    pub fixed_base: bool,
    /// Structural damping ratio ζ, in DDA and in the exact model alike (default 0):
    /// two-block scenes get a dashpot c = 2ζ√(k m) in parallel with the structure's
    /// spring, frames Rayleigh damping with ratio ζ at their first two fixed-base modes.
    pub damping: Option<f64>,
    /// The bearing under a frame's base slab (default: the scene's flat joint).
    pub bearing: Option<crate::model::bearing::Bearing>,
    /// Scale the ground motion to this peak ground acceleration over the run, g (default:
    /// as given).
    pub pga_g: Option<f64>,
    /// Ground model of a DDA run (default: the scene's).
    pub ground: Option<GroundKind>,
    /// Duration, s (default: the record's length, or [`super::defaults::HARMONIC_DURATION_S`]).
    pub duration: Option<f64>,
    /// DDA time step, s (default [`super::defaults::DT`]).
    pub dt: Option<f64>,
    /// DDA integrator (default: generalised-α, ρ∞ = 0).
    pub integrator: Option<Integrator>,
    /// How much history to keep.
    pub history: HistoryPlan,
    /// Run even beyond the step limit ([`crate::limits::MAX_STEPS`]).
    pub confirm_large: bool,
}

impl Default for SceneSource {
    fn default() -> Self {
        SceneSource::Named(super::defaults::SCENE.into())
    }
}

impl RunSpec {
    /// A specification of the named scene with everything else at its default.
    pub fn scene(scene: impl Into<SceneSource>) -> Self {
        Self {
            scene: scene.into(),
            ..Self::default()
        }
    }
}
