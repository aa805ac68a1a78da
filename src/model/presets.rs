//! Built-in scenes (written in the same TOML format as user scenes, embedded in the binary)
//! and the re-parameterisation of two-mass scenes.

use std::path::Path;

use super::friction::Friction;
use super::scene::{ExcitationDef, Scene};
use crate::{Error, Result};

/// The smallest mass ratio α = m/(M + m) taken: below it the roof's density falls under
/// the smallest a material may have (a millionth of the mass is already a weightless roof).
pub const MIN_ALPHA: f64 = 1e-6;

/// Checks a two-block mass ratio α: at least [`MIN_ALPHA`] and below 1 (the top end is
/// bounded by Δt, which must resolve the slip phase's period, shorter as α → 1).
pub fn check_alpha(alpha: f64) -> Result<()> {
    if alpha.is_finite() && (MIN_ALPHA..1.0).contains(&alpha) {
        return Ok(());
    }
    Err(Error::invalid(
        "--alpha",
        format!(
            "the mass ratio m/(M + m) must be in [{MIN_ALPHA:e}, 1), got {} (below \
             {MIN_ALPHA:e} the roof would be lighter than any material taken)",
            crate::error::show(alpha)
        ),
    ))
}

/// The built-in scenes: (name, TOML text).
const BUILTIN: &[(&str, &str)] = &[
    (
        "two-block",
        include_str!("../../assets/scenes/two-block.toml"),
    ),
    ("block", include_str!("../../assets/scenes/block.toml")),
    (
        "three-storey",
        include_str!("../../assets/scenes/three-storey.toml"),
    ),
];

/// Names of the built-in scenes.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN.iter().map(|(n, _)| *n).collect()
}

/// A built-in scene by name, a generated one (`frame:N`, `wall:N`), or a scene file by
/// path.
pub fn resolve_scene(name_or_path: &str) -> Result<Scene> {
    if let Some((name, text)) = BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
        return Scene::from_toml(text, &format!("<built-in {name}>"));
    }
    if let Some(generated) = super::generated::resolve_generated(name_or_path) {
        return generated;
    }
    let path = Path::new(name_or_path);
    if path.exists() {
        return Scene::load(path);
    }
    let known = format!(
        "{}, frame:N, wall:N, friction-pendulum[:R]",
        builtin_names().join(", ")
    );
    if crate::error::meant_as_path(name_or_path) {
        return Err(Error::missing_file("scene", name_or_path, &known));
    }
    Err(Error::Unknown {
        kind: "scene",
        name: name_or_path.to_string(),
        known,
    })
}

/// The paper's parameters of a two-mass run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoBlockParams {
    /// Mass ratio α = m/(M + m), in (0, 1).
    pub alpha: f64,
    /// Coulomb coefficient ρ ≥ 0 (`inf` for a fixed base).
    pub friction: f64,
    /// Excitation frequency over the structure frequency, Ω/ω > 0.
    pub freq_ratio: f64,
    /// Ground acceleration amplitude, g.
    pub amplitude_g: f64,
}

impl TwoBlockParams {
    /// Checks the ranges with the command-line names in the messages.
    pub fn validate(&self) -> Result<()> {
        check_alpha(self.alpha)?;
        if self.friction.is_nan() || self.friction < 0.0 {
            return Err(Error::invalid(
                "--friction",
                format!("must be >= 0, got {}", self.friction),
            ));
        }
        crate::error::require_positive("--freq-ratio", self.freq_ratio)?;
        crate::error::require_positive("--amplitude-g", self.amplitude_g)?;
        Ok(())
    }
}

/// Sets α, ρ, Ω/ω and the amplitude of a scene that declares `[two_block]` roles.
///
/// The raft and roof densities are rescaled so that M + m stays `total_mass`, the spring
/// becomes k = m ω² and the excitation becomes harmonic at Ω = ratio · ω.
pub fn apply_two_block(scene: &mut Scene, p: &TwoBlockParams) -> Result<()> {
    p.validate()?;
    let roles = scene.two_block.clone().ok_or_else(|| {
        Error::Scene(format!("scene '{}' has no [two_block] section", scene.name))
    })?;
    let m = p.alpha * roles.total_mass;
    let big_m = (1.0 - p.alpha) * roles.total_mass;
    let omega = 2.0 * std::f64::consts::PI * roles.structure_frequency_hz;
    for (name, mass) in [(&roles.raft, big_m), (&roles.roof, m)] {
        let i = scene.block_index(name)?;
        let b = &mut scene.blocks[i];
        let area = super::geometry::moments(&b.vertices, &b.name)?.area;
        b.material.density = mass / area;
    }
    for b in scene.bolts.iter_mut().filter(|b| b.name == roles.spring) {
        b.stiffness = m * omega * omega;
    }
    for c in scene.contacts.iter_mut().filter(|c| c.name == roles.joint) {
        c.friction = Friction::Coulomb(p.friction);
    }
    scene.excitation = ExcitationDef::Harmonic {
        amplitude_g: p.amplitude_g,
        frequency_hz: p.freq_ratio * roles.structure_frequency_hz,
    };
    scene.validate()
}

/// Makes the ground block at least `half_length` long on each side of the structure's
/// centre, by moving its leftmost and rightmost vertices outward. Used when a run is
/// expected to slide further than the scene's ground reaches.
pub fn extend_ground(scene: &mut Scene, half_length: f64) -> Result<()> {
    let g = scene.block_index(&scene.ground.block)?;
    let xs: Vec<f64> = scene
        .blocks
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != g)
        .flat_map(|(_, b)| b.vertices.iter().map(|p| p[0]))
        .collect();
    let centre = if xs.is_empty() {
        0.0
    } else {
        0.5 * (xs.iter().cloned().fold(f64::INFINITY, f64::min)
            + xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max))
    };
    let v = &mut scene.blocks[g].vertices;
    let lo = v.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let hi = v.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
    for p in v.iter_mut() {
        if p[0] == lo {
            p[0] = p[0].min(centre - half_length);
        } else if p[0] == hi {
            p[0] = p[0].max(centre + half_length);
        }
    }
    Ok(())
}
