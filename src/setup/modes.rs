//! The fixed-base natural frequencies and floor mode shapes of a building scene, and the
//! Rayleigh damping they define (shared by the DDA run, its exact MDOF counterpart and the
//! `modes` command).

use serde::Serialize;

use crate::dda::{Dda, RayleighDamping, SolverParams};
use crate::model::Scene;
use crate::model::scene::StructureRoles;
use crate::{Error, Result};

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

/// A contact between two of a building's blocks other than its sliding joint: such a
/// building is a stack of blocks (the generated walls), not one elastic frame.
pub fn contact_within_structure<'a>(
    scene: &'a Scene,
    roles: &StructureRoles,
) -> Option<&'a crate::model::scene::ContactDef> {
    scene.contacts.iter().find(|c| c.name != roles.joint)
}

/// The structure roles of a building that is one elastic frame (blocks joined by
/// connection elements, as three-storey and frame:N are), or an error naming the scene:
/// natural frequencies, mode shapes and the equivalent shear building are those of such a
/// frame. A stack of blocks in contact (wall:N) has none: its stuck contacts' penalty
/// springs would be reported as its stiffness.
pub fn frame_roles(scene: &Scene) -> Result<StructureRoles> {
    let r = roles(scene)?;
    if let Some(c) = contact_within_structure(scene, &r) {
        return Err(Error::invalid(
            "--scene",
            format!(
                "scene '{}' is a stack of blocks in contact (contact {}), not a frame: \
                 its natural frequencies would be those of the contacts' penalty springs; \
                 modes, the equivalent shear building and the paper's report apply to \
                 frames joined by connection elements (three-storey, frame:N)",
                scene.name,
                c.label()
            ),
        ));
    }
    Ok(r)
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
    /// For the equivalent MDOF model ([`equivalent_mdof`]): the largest relative
    /// difference between its frequencies and the DDA frame's (0 up to rounding for
    /// frames that behave as shear buildings, like the paper's; larger for tall frames,
    /// whose overall bending no shear building has).
    pub mdof_fit_error: Option<f64>,
}

/// Modal analysis of a building scene from the DDA stiffness and mass (fixed base: the
/// sliding joint's springs held stuck).
pub fn modes(scene: &Scene) -> Result<ModesReport> {
    let r = frame_roles(scene)?;
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
        mdof_fit_error: None,
    })
}

/// Rayleigh damping of a building scene with ratio `zeta` at its first two fixed-base sway
/// modes (at its only one, for a one-storey frame: a₀ = ζω, a₁ = ζ/ω).
pub fn rayleigh_damping(scene: &Scene, zeta: f64) -> Result<RayleighDamping> {
    let report = modes(scene)?;
    let omega: Vec<f64> = report
        .frequencies_hz
        .iter()
        .map(|f| 2.0 * std::f64::consts::PI * f)
        .collect();
    match omega.as_slice() {
        [] => Err(Error::invalid(
            "--damping",
            format!(
                "the fixed-base frame of '{}' has no sway mode to damp",
                scene.name
            ),
        )),
        [w] => RayleighDamping::from_two_modes(zeta, *w, *w),
        [w1, w2, ..] => RayleighDamping::from_two_modes(zeta, *w1, *w2),
    }
}
