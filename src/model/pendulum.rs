//! The friction pendulum scene (`friction-pendulum`, `friction-pendulum:R`): a thin slider
//! in a concave circular dish under El Centro.
//!
//! The dish is the ground block: its top is the circle of radius R_d about the dish's
//! centre C, drawn as a polyline of as many facets as a polygon may have (each chord
//! within 0.12 µm of the circle at R = 2 m). The slider's bottom meets the dish at its two
//! corners, both on the circle: two points held on a circle make the rigid slider turn
//! about C, the compound pendulum of the bearing catalogues. (A bottom of more facets, all
//! on the circle, is statically over-determined on the faceted dish: its middle vertices
//! open and close on the facets' sub-micrometre bumps and the open-close iteration does not
//! settle; see docs/friction-pendulum.md.)
//!
//! R is the **effective radius** the catalogues quote: the radius of the circle the
//! slider's centroid travels on (R_d less the distance from the slider's bottom to its
//! centroid). Its small free oscillations have the period 2π√((R² + k²)/(g R)), k the
//! slider's radius of gyration: 2π√(R/g) + 0.04 % for this thin slider. Friction acts on
//! the dish's surface, R_d/R = 1 + 0.5 % farther from C than the centroid, so that the
//! point-mass reference sees a coefficient about 0.5 % lower than the joint's.

use super::friction::Friction;
use super::geometry::moments;
use super::material::Material;
use super::scene::{
    ArcDef, BlockDef, ContactDef, ExcitationDef, GroundDef, GroundKind, Scene, SlidingBlockRoles,
};
use crate::ground_motion::STANDARD_GRAVITY;
use crate::{Error, Result};

/// The scene's name.
pub const NAME: &str = "friction-pendulum";

/// Default effective radius, m (a bearing of period 2π√(R/g) = 2.84 s).
pub const DEFAULT_RADIUS_M: f64 = 2.0;

/// Effective radii accepted, m: periods from 1.4 to 9 s, the range of catalogue bearings
/// and beyond.
pub const RADIUS_RANGE_M: (f64, f64) = (0.5, 20.0);

/// The slider: 0.2 m wide, 20 mm thick at its centre, 1000 kg per metre.
const SLIDER_WIDTH: f64 = 0.2;
const SLIDER_THICKNESS: f64 = 0.02;
const SLIDER_MASS: f64 = 1000.0;
/// Facets of the slider's bottom arc (every vertex on the dish's circle): one, a chord
/// whose two corners ride the circle (see the module's notes for why not more).
const SLIDER_FACETS: usize = 1;
/// The dish's half-opening: 20° from the bottom (a rim 0.68 m out at R = 2 m).
const DISH_HALF_ANGLE: f64 = std::f64::consts::PI / 9.0;
/// Facets of the dish: as many as the polygon-size limit leaves room for beside the
/// ground's four corners. Each facet's kink is a bump of the slider's path (R_d·Δφ²/8:
/// 0.12 µm at R = 2 m) that shakes it vertically as it slides; the more facets, the
/// smaller and faster the shaking.
const DISH_FACETS: usize = crate::limits::MAX_POLYGON_VERTICES - 5;

/// The largest gap between the dish's chords and its circle, m.
fn dish_sag(rd: f64) -> f64 {
    let facet_angle = 2.0 * DISH_HALF_ANGLE / DISH_FACETS as f64;
    rd * (1.0 - (0.5 * facet_angle).cos())
}

/// The friction pendulum of effective radius `radius` (m), named `friction-pendulum` (or
/// `friction-pendulum:R` off the default radius).
pub fn friction_pendulum(radius: f64) -> Result<Scene> {
    pendulum_of_radius(radius, "--radius")
}

/// [`friction_pendulum`], its radius given by `field` (the flag or the scene's spelling,
/// which an out-of-range radius is reported against).
fn pendulum_of_radius(radius: f64, field: &str) -> Result<Scene> {
    let (lo, hi) = RADIUS_RANGE_M;
    crate::error::require_range(field, radius, lo, hi, "m (the effective radius R)")?;
    let dish_radius = dish_radius_for(radius)?;
    let name = if radius == DEFAULT_RADIUS_M {
        NAME.to_string()
    } else {
        format!("{NAME}:{radius}")
    };
    let slider = slider_vertices(dish_radius);
    let area = moments(&slider, "slider")?.area;
    let scene = Scene {
        name,
        description: format!(
            "A friction pendulum: a thin slider in a concave dish of effective radius \
             {radius} m (period 2π√(R/g) = {:.2} s); El Centro 1940",
            2.0 * std::f64::consts::PI * (radius / STANDARD_GRAVITY).sqrt()
        ),
        gravity: STANDARD_GRAVITY,
        blocks: vec![
            BlockDef {
                name: "dish".into(),
                vertices: dish_vertices(dish_radius),
                material: Material {
                    density: 2000.0,
                    youngs_modulus: 1.0e9,
                    poisson_ratio: 0.2,
                    plane: Default::default(),
                },
                rigid: false,
                arcs: vec![dish_arc(dish_radius)],
            },
            BlockDef {
                name: "slider".into(),
                vertices: slider,
                material: Material {
                    density: SLIDER_MASS / area,
                    youngs_modulus: 1.0e12,
                    poisson_ratio: 0.2,
                    plane: Default::default(),
                },
                rigid: true,
                arcs: Vec::new(),
            },
        ],
        ground: GroundDef {
            block: "dish".into(),
            kind: GroundKind::Prescribed,
            mass_ratio: 1e4,
        },
        contacts: vec![ContactDef {
            name: "sliding-joint".into(),
            blocks: ["slider".into(), "dish".into()],
            friction: Friction::Coulomb(0.05),
            normal_penalty: Some(1.0e11),
            shear_penalty: Some(4.0e10),
            bonded: false,
            locate_events: true,
        }],
        bolts: Vec::new(),
        connections: Vec::new(),
        fixed_points: Vec::new(),
        point_loads: Vec::new(),
        excitation: ExcitationDef::Record {
            record: "el-centro".into(),
            scale: 1.0,
        },
        vertical_excitation: None,
        contact_enforcement: None,
        integrator: None,
        two_block: None,
        structure: None,
        sliding_block: Some(SlidingBlockRoles {
            block: "slider".into(),
            joint: "sliding-joint".into(),
            dish_radius: Some(radius),
        }),
    };
    scene.validate()?;
    Ok(scene)
}

/// The scene from its spelling: `friction-pendulum` (R = 2 m) or `friction-pendulum:R`.
pub fn resolve(name: &str) -> Option<Result<Scene>> {
    if name == NAME {
        return Some(friction_pendulum(DEFAULT_RADIUS_M));
    }
    let radius = name.strip_prefix(NAME)?.strip_prefix(':')?;
    Some(
        radius
            .parse::<f64>()
            .map_err(|_| {
                Error::invalid(
                    "--scene",
                    format!("'{name}': the radius after ':' must be a number of metres"),
                )
            })
            .and_then(|r| pendulum_of_radius(r, "--scene friction-pendulum:R")),
    )
}

/// A point of the circle of radius `r` about the dish's centre (0, r), at the angle `phi`
/// from the bottom (positive to the right).
fn on_circle(r: f64, phi: f64) -> [f64; 2] {
    [r * phi.sin(), r - r * phi.cos()]
}

/// The dish radius R_d that puts the slider's centroid at `radius` from the dish's
/// centre: a fixed-point iteration, as the slider's shape changes little with R_d.
fn dish_radius_for(radius: f64) -> Result<f64> {
    let mut rd = radius + 0.5 * SLIDER_THICKNESS;
    for _ in 0..50 {
        let centroid_height = moments(&slider_vertices(rd), "slider")?.centroid[1];
        let next = radius + centroid_height;
        if (next - rd).abs() < 1e-14 * radius {
            return Ok(next);
        }
        rd = next;
    }
    Ok(rd)
}

/// The slider on a dish of radius `rd`, centred at the bottom: its bottom an arc of
/// [`SLIDER_FACETS`] facets with every vertex on the dish's circle drawn in by 1.5× the
/// dish's chord sag (so that the vertices clear the dish's chords at the start and gravity
/// settles them on), its top flat at [`SLIDER_THICKNESS`] above the dish's lowest point
/// (counter-clockwise).
fn slider_vertices(rd: f64) -> Vec<[f64; 2]> {
    let clear = 1.5 * dish_sag(rd);
    let half = (0.5 * SLIDER_WIDTH / rd).asin();
    let mut v: Vec<[f64; 2]> = (0..=SLIDER_FACETS)
        .map(|k| {
            let [x, y] = on_circle(
                rd - clear,
                -half + 2.0 * half * k as f64 / SLIDER_FACETS as f64,
            );
            [x, y + clear]
        })
        .collect();
    let w = 0.5 * SLIDER_WIDTH;
    v.push([w, SLIDER_THICKNESS]);
    v.push([-w, SLIDER_THICKNESS]);
    v
}

/// The dish's circle: its chords are edges 3 to 2 + [`DISH_FACETS`] of [`dish_vertices`].
fn dish_arc(rd: f64) -> ArcDef {
    ArcDef {
        center: [0.0, rd],
        radius: rd,
        edges: [3, 2 + DISH_FACETS],
    }
}

/// The dish: a 1 m deep ground block whose top is the circle of radius `rd` between the
/// rims (20° either side), flat beyond them (counter-clockwise).
fn dish_vertices(rd: f64) -> Vec<[f64; 2]> {
    let rim = on_circle(rd, DISH_HALF_ANGLE);
    let half_length = 2.0 * rim[0];
    let mut v = vec![
        [-half_length, -1.0],
        [half_length, -1.0],
        [half_length, rim[1]],
    ];
    v.extend((0..=DISH_FACETS).map(|k| {
        on_circle(
            rd,
            DISH_HALF_ANGLE - 2.0 * DISH_HALF_ANGLE * k as f64 / DISH_FACETS as f64,
        )
    }));
    v.push([-half_length, rim[1]]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slider's centroid sits at the effective radius from the dish's centre, and
    /// every vertex of its bottom on the dish's circle.
    #[test]
    fn the_slider_centroid_travels_on_the_effective_radius() {
        for radius in [0.5, 2.0, 7.5] {
            let rd = dish_radius_for(radius).unwrap();
            let slider = slider_vertices(rd);
            let c = moments(&slider, "slider").unwrap().centroid;
            assert!((rd - c[1] - radius).abs() < 1e-12 * radius, "R {radius}");
            for p in &slider[..=SLIDER_FACETS] {
                let r = (p[0] * p[0] + (p[1] - rd).powi(2)).sqrt();
                let off = rd - r - 1.5 * dish_sag(rd);
                assert!(
                    off.abs() < 1e-12,
                    "R {radius}: vertex off the circle by {off:e}"
                );
            }
            // Both polygons counter-clockwise (moments refuses a non-positive area).
            assert!(moments(&dish_vertices(rd), "dish").is_ok());
        }
    }

    #[test]
    fn names_and_radii() {
        assert_eq!(resolve(NAME).unwrap().unwrap().name, NAME);
        let s = resolve("friction-pendulum:3.5").unwrap().unwrap();
        assert_eq!(s.sliding_block.unwrap().dish_radius, Some(3.5));
        assert!(resolve("friction-pendulum:x").unwrap().is_err());
        assert!(resolve("friction-pendulum:0.1").unwrap().is_err());
        assert!(resolve("two-block").is_none());
    }
}
