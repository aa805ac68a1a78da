//! Friction-pendulum bearings under a frame (`--bearing pendulum:R`): the frame's flat
//! sliding joint replaced by two concave dishes in the ground, one under each end of the
//! base slab, on which the slab stands on two pointed feet.
//!
//! A foot's tip slides on its dish's circle (radius R about a centre R above the dish's
//! lowest point). Two tips on two congruent circles hold the slab level: the whole building
//! translates, every point of it on a circle of radius R, rising by R(1 − cos θ) as it
//! slides, so R is the bearings' effective radius, and the restoring force is W·sin θ ≈
//! W·x/R — the linearised friction-pendulum bearing of OpenSees and SAP2000
//! (`Surface::Linearised` of the MDOF counterpart). A real bearing's slider is articulated
//! for the same reason: the superstructure stays level.
//!
//! The dishes are drawn as polylines of as many facets as the ground polygon may hold; a
//! tip starts at the middle of the lowest facet, 1.5 chord sags above the circle, so that
//! it rests on the facet and not on a kink. The ground outside the dishes is lowered by
//! [`CLEARANCE_M`] below the slab, so that only the feet touch it.

use super::scene::{ArcDef, BlockDef, Scene};
use crate::{Error, Result};

/// The bearing under a frame's base slab.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Bearing {
    /// The flat Coulomb joint of the paper (the scene as written).
    #[default]
    Flat,
    /// Two friction-pendulum bearings of effective radius `radius`, m.
    Pendulum {
        /// Effective radius R, m.
        radius: f64,
    },
}

/// Default effective radius of `--bearing pendulum`, m (period 2π√(R/g) = 2.84 s).
pub const DEFAULT_RADIUS_M: f64 = 2.0;

/// Effective radii accepted, m.
pub const RADIUS_RANGE_M: (f64, f64) = (0.5, 20.0);

/// Half-width of each dish, m: its rim is this far either side of its lowest point (20° at
/// R = 2 m), wider than any slip of the frame on the shipped records.
const DISH_HALF_WIDTH_M: f64 = 0.7;

/// Gap between the slab's underside and the ground outside the dishes, m.
pub const CLEARANCE_M: f64 = 0.1;

/// Half-width of a foot at the slab's underside, m.
const FOOT_HALF_WIDTH_M: f64 = 0.15;

/// How far in from the slab's ends the feet stand, m (under the columns of the frames).
const FOOT_INSET_M: f64 = 0.3;

/// Facets of each dish: half of what a polygon may hold, less the ground's corners and
/// the dishes' rims. Odd, so that a lowest facet is level and a foot starts on it.
const DISH_FACETS: usize = (crate::limits::MAX_POLYGON_VERTICES - 12) / 2 / 2 * 2 - 1;

impl Bearing {
    /// Parses `flat`, `pendulum` (R = 2 m) or `pendulum:R`.
    pub fn parse(text: &str) -> Result<Self> {
        let refuse = || {
            Error::invalid(
                "--bearing",
                format!(
                    "'{text}' is not a bearing; use flat or pendulum:R (R the effective \
                     radius in m, {} to {})",
                    RADIUS_RANGE_M.0, RADIUS_RANGE_M.1
                ),
            )
        };
        let bearing = match text.split_once(':') {
            None if text == "flat" => Self::Flat,
            None if text == "pendulum" => Self::Pendulum {
                radius: DEFAULT_RADIUS_M,
            },
            Some(("pendulum", r)) => Self::Pendulum {
                radius: r.trim().parse().map_err(|_| refuse())?,
            },
            _ => return Err(refuse()),
        };
        bearing.validate()?;
        Ok(bearing)
    }

    /// Checks the radius against [`RADIUS_RANGE_M`].
    pub fn validate(&self) -> Result<()> {
        if let Self::Pendulum { radius } = self {
            let (lo, hi) = RADIUS_RANGE_M;
            crate::error::require_range(
                "--bearing",
                *radius,
                lo,
                hi,
                "m (the effective radius R)",
            )?;
        }
        Ok(())
    }

    /// The effective radius of a pendulum bearing (`None`: flat).
    pub fn radius(&self) -> Option<f64> {
        match self {
            Self::Flat => None,
            Self::Pendulum { radius } => Some(*radius),
        }
    }

    /// How the command line spells it.
    pub fn label(&self) -> String {
        match self {
            Self::Flat => "flat".into(),
            Self::Pendulum { radius } => format!("pendulum:{radius}"),
        }
    }
}

/// Puts the frame of `scene` on two friction-pendulum bearings of effective radius
/// `radius`: the ground block `ground` gets two dishes and the base slab `base` two feet.
/// The slab must be an axis-aligned rectangle resting on the ground's flat top.
pub fn apply_pendulum_bearings(
    scene: &mut Scene,
    ground: &str,
    base: &str,
    radius: f64,
) -> Result<()> {
    Bearing::Pendulum { radius }.validate()?;
    let refuse = |why: &str| {
        Error::invalid(
            "--bearing",
            format!(
                "pendulum bearings go under a frame whose base slab is a rectangle on a flat \
                 ground; in '{}' {why}",
                scene.name
            ),
        )
    };
    let slab = block(scene, base).ok_or_else(|| refuse("there is no base slab"))?;
    let [x0, y0, x1, y1] =
        rectangle_of(slab).ok_or_else(|| refuse("the base slab is not a rectangle"))?;
    let ground_block = block(scene, ground).ok_or_else(|| refuse("there is no ground block"))?;
    let [gx0, _, gx1, gy1] =
        rectangle_of(ground_block).ok_or_else(|| refuse("the ground is not a rectangle"))?;
    if (gy1 - y0).abs() > 1e-9 || gx0 > x0 - 10.0 || gx1 < x1 + 10.0 {
        return Err(refuse("the base slab does not rest on the ground's top"));
    }
    let half_angle = (DISH_HALF_WIDTH_M / radius).min(0.5).asin();
    let depth = radius * (1.0 - half_angle.cos());
    let centres = [x0 + FOOT_INSET_M, x1 - FOOT_INSET_M];
    let top = y0 - CLEARANCE_M;
    let bottom = top - depth;
    let ground_vertices = dished_ground([gx0, gx1], top, bottom, radius, half_angle, centres);
    let tip = bottom + 1.5 * chord_sag(radius, half_angle);
    let slab_vertices = footed_slab([x0, y0, x1, y1], tip, centres);
    let arcs = dish_arcs(bottom + radius, radius, centres);
    for b in &mut scene.blocks {
        if b.name == ground {
            b.vertices = ground_vertices.clone();
            b.arcs = arcs.clone();
        } else if b.name == base {
            b.vertices = slab_vertices.clone();
        }
    }
    scene.description = format!(
        "{} — on two friction-pendulum bearings of effective radius {radius} m (period \
         2π√(R/g) = {:.2} s)",
        scene.description,
        2.0 * std::f64::consts::PI * (radius / scene.gravity).sqrt()
    );
    scene.validate()
}

fn block<'a>(scene: &'a Scene, name: &str) -> Option<&'a BlockDef> {
    scene.blocks.iter().find(|b| b.name == name)
}

/// [x_min, y_min, x_max, y_max] of a block that is an axis-aligned rectangle.
fn rectangle_of(b: &BlockDef) -> Option<[f64; 4]> {
    if b.vertices.len() != 4 {
        return None;
    }
    let xs = b.vertices.iter().map(|p| p[0]);
    let ys = b.vertices.iter().map(|p| p[1]);
    let r = [
        xs.clone().fold(f64::INFINITY, f64::min),
        ys.clone().fold(f64::INFINITY, f64::min),
        xs.fold(f64::NEG_INFINITY, f64::max),
        ys.fold(f64::NEG_INFINITY, f64::max),
    ];
    let on_corner = |p: &[f64; 2]| (p[0] == r[0] || p[0] == r[2]) && (p[1] == r[1] || p[1] == r[3]);
    b.vertices.iter().all(on_corner).then_some(r)
}

/// The largest gap between a dish's chords and its circle, m.
fn chord_sag(radius: f64, half_angle: f64) -> f64 {
    let facet = 2.0 * half_angle / DISH_FACETS as f64;
    radius * (1.0 - (0.5 * facet).cos())
}

/// The ground, 1 m deep below `top`, with a dish of radius `radius` (lowest point at
/// `bottom`) centred at each x of `centres` (counter-clockwise).
fn dished_ground(
    [x0, x1]: [f64; 2],
    top: f64,
    bottom: f64,
    radius: f64,
    half_angle: f64,
    centres: [f64; 2],
) -> Vec<[f64; 2]> {
    let mut v = vec![[x0, top - 1.0], [x1, top - 1.0], [x1, top]];
    for &c in centres.iter().rev() {
        v.extend((0..=DISH_FACETS).map(|k| {
            let phi = half_angle - 2.0 * half_angle * k as f64 / DISH_FACETS as f64;
            [c + radius * phi.sin(), bottom + radius * (1.0 - phi.cos())]
        }));
    }
    v.push([x0, top]);
    v
}

/// The dishes' circles (centre height `centre_y`), in the order [`dished_ground`] lists
/// their chords: the right dish's from edge 3, then, past the flat between them, the
/// left one's.
fn dish_arcs(centre_y: f64, radius: f64, centres: [f64; 2]) -> Vec<ArcDef> {
    let right = [3, 2 + DISH_FACETS];
    let left = [right[1] + 2, right[1] + 1 + DISH_FACETS];
    [(centres[1], right), (centres[0], left)]
        .into_iter()
        .map(|(x, edges)| ArcDef {
            center: [x, centre_y],
            radius,
            edges,
        })
        .collect()
}

/// The base slab `[x0, y0, x1, y1]` with a pointed foot under each x of `centres`, its
/// tip at height `tip` (counter-clockwise).
fn footed_slab([x0, y0, x1, y1]: [f64; 4], tip: f64, centres: [f64; 2]) -> Vec<[f64; 2]> {
    let mut v = vec![[x0, y0]];
    for c in centres {
        v.push([c - FOOT_HALF_WIDTH_M, y0]);
        v.push([c, tip]);
        v.push([c + FOOT_HALF_WIDTH_M, y0]);
    }
    v.extend([[x1, y0], [x1, y1], [x0, y1]]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::resolve_scene;

    #[test]
    fn spellings() {
        assert_eq!(Bearing::parse("flat").unwrap(), Bearing::Flat);
        assert_eq!(
            Bearing::parse("pendulum").unwrap(),
            Bearing::Pendulum { radius: 2.0 }
        );
        assert_eq!(
            Bearing::parse("pendulum:3.5").unwrap(),
            Bearing::Pendulum { radius: 3.5 }
        );
        for bad in ["pendulum:0.1", "pendulum:x", "pendulum:NaN", "round", ""] {
            let e = Bearing::parse(bad).unwrap_err().to_string();
            assert!(e.contains("--bearing"), "{bad}: {e}");
        }
    }

    /// The feet's tips sit on their dishes' lowest facets, the slab clears the ground by
    /// [`CLEARANCE_M`], and the dishes' vertices lie on circles of radius R.
    #[test]
    fn the_feet_rest_in_the_dishes() {
        let mut scene = resolve_scene("three-storey").unwrap();
        apply_pendulum_bearings(&mut scene, "ground", "base-slab", 2.0).unwrap();
        let ground = block(&scene, "ground").unwrap();
        let slab = block(&scene, "base-slab").unwrap();
        assert!(ground.vertices.len() <= crate::limits::MAX_POLYGON_VERTICES);
        let tips: Vec<[f64; 2]> = slab
            .vertices
            .iter()
            .copied()
            .filter(|p| p[1] < -CLEARANCE_M)
            .collect();
        assert_eq!(tips.len(), 2);
        assert!((tips[0][0] + 12.0).abs() < 1e-12 && (tips[1][0] - 12.0).abs() < 1e-12);
        let lowest_dish = ground
            .vertices
            .iter()
            .filter(|p| p[1] > -1.0)
            .map(|p| p[1])
            .fold(f64::INFINITY, f64::min);
        // Odd facets: the lowest vertices are half a facet either side of the bottom, one
        // sag above the circle's lowest point; the tip is 1.5 sags above that point.
        let sag = chord_sag(2.0, (DISH_HALF_WIDTH_M / 2.0).asin());
        let gap = tips[0][1] - lowest_dish;
        assert!(
            (gap - 0.5 * sag).abs() < 1e-12,
            "the tip is just above the lowest facet: {gap}"
        );
        let centre_height = lowest_dish - sag + 2.0;
        for p in ground
            .vertices
            .iter()
            .filter(|p| p[1] < -CLEARANCE_M - 1e-12 && p[1] > -1.0)
        {
            let c = if p[0] < 0.0 { -12.0 } else { 12.0 };
            let r = ((p[0] - c).powi(2) + (p[1] - centre_height).powi(2)).sqrt();
            assert!(
                (r - 2.0).abs() < 1e-9,
                "{p:?} is {r} m from its dish's centre"
            );
        }
    }
}
