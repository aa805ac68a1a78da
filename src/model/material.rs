//! Linear elastic materials for DDA blocks and connection elements.

use serde::{Deserialize, Serialize};

use crate::limits::{DENSITY_RANGE, YOUNGS_MODULUS_RANGE};
use crate::{Error, Result};

/// Two-dimensional idealisation of the third direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum PlaneKind {
    /// Thin in the third direction (σz = 0): frames, walls. The paper's choice.
    #[default]
    Stress,
    /// Long in the third direction (εz = 0): dams, long foundations.
    Strain,
}

/// An isotropic linear elastic material (per unit thickness).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Mass density ρ, kg/m³ (mass per unit area per unit thickness).
    pub density: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus: f64,
    /// Poisson's ratio ν, in [0, 0.5).
    pub poisson_ratio: f64,
    /// Plane stress or plane strain.
    #[serde(default)]
    pub plane: PlaneKind,
}

impl Material {
    /// Checks the ranges; `owner` names the block or element in the message.
    pub fn validate(&self, owner: &str) -> Result<()> {
        let field = |f: &str| format!("{owner}.{f}");
        let (lo, hi) = DENSITY_RANGE;
        crate::error::require_range(&field("density"), self.density, lo, hi, "kg/m³")?;
        let (lo, hi) = YOUNGS_MODULUS_RANGE;
        crate::error::require_range(&field("youngs_modulus"), self.youngs_modulus, lo, hi, "Pa")?;
        if !(self.poisson_ratio.is_finite() && (0.0..0.5).contains(&self.poisson_ratio)) {
            return Err(Error::invalid(
                field("poisson_ratio"),
                format!("must be in [0, 0.5), got {}", self.poisson_ratio),
            ));
        }
        Ok(())
    }

    /// The 3×3 elasticity matrix C (σ = C ε, engineering shear strain), plane stress form
    /// with plane strain mapped through E' = E/(1 − ν²), ν' = ν/(1 − ν) (dda-theory §3).
    pub fn elasticity(&self) -> [[f64; 3]; 3] {
        let (e, nu) = match self.plane {
            PlaneKind::Stress => (self.youngs_modulus, self.poisson_ratio),
            PlaneKind::Strain => {
                let nu = self.poisson_ratio;
                (self.youngs_modulus / (1.0 - nu * nu), nu / (1.0 - nu))
            }
        };
        let c = e / (1.0 - nu * nu);
        [
            [c, c * nu, 0.0],
            [c * nu, c, 0.0],
            [0.0, 0.0, c * (1.0 - nu) / 2.0],
        ]
    }
}
