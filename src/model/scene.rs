//! A scene is data: blocks, contacts, joints, supports, ground, gravity and excitation.
//!
//! Scenes load from TOML (the built-in presets in `assets/scenes/` use the same format).
//! A scene lists only the parts it has; the solver sets up and assembles only those kinds
//! of terms (no bolts → no bolt code runs; blocks joined only by connection elements get
//! no contact search, because contact search runs only on the declared contact pairs).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::enforcement::ContactEnforcement;
use super::friction::Friction;
use super::geometry::Point;
use super::integration::Integrator;
use super::material::Material;
use crate::ground_motion::STANDARD_GRAVITY;
use crate::limits::MAX_SCENE_FILE_BYTES;
use crate::{Error, Result};

/// A complete scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name (`two-block`, `three-storey`…).
    pub name: String,
    /// One or two sentences for people browsing scenes.
    #[serde(default)]
    pub description: String,
    /// Gravitational acceleration, m/s², acting in −y.
    #[serde(default = "default_gravity")]
    pub gravity: f64,
    /// The blocks (polygons with materials).
    #[serde(rename = "block")]
    pub blocks: Vec<BlockDef>,
    /// Which block is the ground and how it is driven.
    pub ground: GroundDef,
    /// Frictional contacts between named pairs of blocks.
    #[serde(rename = "contact", default)]
    pub contacts: Vec<ContactDef>,
    /// Bolts (springs between points of two blocks).
    #[serde(rename = "bolt", default)]
    pub bolts: Vec<BoltDef>,
    /// Connection elements (constant-strain triangles with nodes in 2–3 blocks).
    #[serde(rename = "connection", default)]
    pub connections: Vec<ConnectionDef>,
    /// Fixed points and rollers.
    #[serde(rename = "fixed_point", default)]
    pub fixed_points: Vec<FixedPointDef>,
    /// Constant point loads.
    #[serde(rename = "point_load", default)]
    pub point_loads: Vec<PointLoadDef>,
    /// The horizontal ground excitation.
    #[serde(default)]
    pub excitation: ExcitationDef,
    /// The vertical ground excitation, if the ground also shakes vertically.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertical_excitation: Option<VerticalExcitationDef>,
    /// Roles that let the command line re-parameterise a two-mass scene (α, ρ, Ω/ω).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_block: Option<TwoBlockRoles>,
    /// Roles of a building scene: which blocks are the base and the floors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub structure: Option<StructureRoles>,
    /// Roles of a sliding-block scene: the block and its joint (Newmark's sliding block).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sliding_block: Option<SlidingBlockRoles>,
    /// How the closed contacts carry their forces, when the scene needs a particular way
    /// (`"penalty"` or `"augmented-lagrangian"`; default: the solver's, the augmented
    /// Lagrangian). Walls of dry-stacked blocks ask for penalty springs: a block resting
    /// on two below touches them at several vertices per face, more constraints than it
    /// has freedoms, so the individual multipliers are not determined and their iteration
    /// stalls once the wall rocks (see [`crate::model::generated::wall`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_enforcement: Option<ContactEnforcement>,
    /// The time-integration scheme the scene's blocks need, written as on the command
    /// line (`"generalized-alpha:0.5"`; default: the solver's, generalised-α ρ∞ = 0,
    /// which annihilates deformable blocks' unresolved modes). `--integrator` overrides
    /// it. The two-block scene asks for ρ∞ = 0.5: its blocks are rigid, so there is
    /// nothing to annihilate, and the smaller error constant keeps the paper grid within
    /// 1 % where ρ∞ = 0 errs by 6 % (see [`Integrator`]'s default).
    #[serde(
        default,
        with = "super::integration::as_text",
        skip_serializing_if = "Option::is_none"
    )]
    pub integrator: Option<Integrator>,
}

/// Names the parts of a building so that runs can report slip, drift and floor responses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureRoles {
    /// The base slab (the block on the sliding joint).
    pub base: String,
    /// The floor slabs, bottom to top; the last one is the roof.
    pub floors: Vec<String>,
    /// The sliding joint (contact name).
    pub joint: String,
}

fn default_gravity() -> f64 {
    STANDARD_GRAVITY
}

/// One block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockDef {
    /// Unique name, used by contacts, joints and reports.
    pub name: String,
    /// Polygon vertices, counter-clockwise, m.
    #[serde(deserialize_with = "strict::points")]
    pub vertices: Vec<Point>,
    /// Its material.
    pub material: Material,
    /// A rigid block: its three strain unknowns are held at zero (the paper's
    /// mass-spring model has rigid masses). Default: deformable.
    #[serde(default)]
    pub rigid: bool,
    /// Runs of edges that are chords of a circle, concave as seen from outside the block
    /// (a dish): contacts on them see the circle, not the facets. Default: none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub arcs: Vec<ArcDef>,
}

/// A run of a block's edges that are chords of one circle (`[[block.arcs]]` in a scene
/// file): a dish, concave as seen from outside the block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArcDef {
    /// The circle's centre, m (on the free side of the edges).
    pub center: Point,
    /// The circle's radius, m.
    pub radius: f64,
    /// First and last edge of the run, inclusive, counted from 0 (edge k runs from the
    /// block's vertex k to vertex k + 1 of its `vertices` list).
    pub edges: [usize; 2],
}

impl ArcDef {
    /// Whether edge `k` is one of the arc's chords.
    pub fn holds_edge(&self, k: usize) -> bool {
        (self.edges[0]..=self.edges[1]).contains(&k)
    }
}

/// How the ground block moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GroundKind {
    /// The ground follows the (twice integrated) record exactly; its unknowns are known.
    /// No error from a finite ground mass: the accurate default.
    #[default]
    Prescribed,
    /// The paper's method (eq. 4): a large ground mass m_g driven by `f = m_g ü0(t)` on
    /// vertical rollers. Its acceleration differs from ü0 by O(m_structure / m_g).
    LargeMass,
}

/// The ground block and its driving.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundDef {
    /// Name of the ground block.
    pub block: String,
    /// Prescribed motion or large mass.
    #[serde(default)]
    pub kind: GroundKind,
    /// Large-mass ground only: ground mass / total structure mass (the paper's "large").
    #[serde(default = "default_mass_ratio")]
    pub mass_ratio: f64,
}

fn default_mass_ratio() -> f64 {
    // Large enough that the ground's recoil error (~1/ratio) is below the 1 % targets by
    // two orders of magnitude, small enough to keep the system well conditioned.
    1e4
}

/// A contact pair: vertices of each block against the edges of the other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactDef {
    /// Optional name (e.g. `sliding-joint`); the command line's `--friction` sets the
    /// joint named `sliding-joint`, or every contact when there is none.
    #[serde(default)]
    pub name: String,
    /// The two block names.
    #[serde(deserialize_with = "strict::name_pair")]
    pub blocks: [String; 2],
    /// The friction law: a number is Coulomb's coefficient ρ (static = kinetic, as in the
    /// paper; `inf` never slides); a string names another law
    /// (`"static-kinetic:0.6,0.4"`, `"velocity:0.05,0.1,20"`, see [`Friction`]).
    pub friction: Friction,
    /// Normal penalty spring, N/m per unit thickness. Default: 100 × the larger E of the
    /// two blocks (the paper's choice).
    #[serde(default)]
    pub normal_penalty: Option<f64>,
    /// Shear penalty spring, N/m. Default: normal / 2.5 (a common DDA ratio).
    #[serde(default)]
    pub shear_penalty: Option<f64>,
    /// Bonded joint: the contact never opens or slides (fixed base).
    #[serde(default)]
    pub bonded: bool,
    /// Land time steps on this joint's events (stick→slip, slip→stick, impact) when the
    /// solver locates events (the default). `false` takes them at the step end, as classic
    /// DDA does: meant for the many internal joints of a large model (dry-stacked
    /// masonry), where blocks resting at zero force chatter between states in almost every
    /// step and each landing costs a shortened step and new factorisations, while the
    /// response that matters is the sliding base's.
    #[serde(default = "yes")]
    pub locate_events: bool,
}

impl ContactDef {
    /// How a message names the contact: its name, or its two blocks when it has none
    /// (the generated walls' contacts are unnamed).
    pub fn label(&self) -> String {
        if self.name.is_empty() {
            format!("between '{}' and '{}'", self.blocks[0], self.blocks[1])
        } else {
            format!("'{}'", self.name)
        }
    }
}

fn yes() -> bool {
    true
}

/// How a bolt resists relative displacement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum BoltKind {
    /// Both components, as the paper's eq. (5): a zero-length spring in x and y.
    #[default]
    TwoComponent,
    /// Along the bolt's current direction only (the rock-mechanics convention).
    Axial,
}

/// A bolt between point A in block A and point B in block B.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoltDef {
    /// Optional name (a two-block scene names its spring here).
    #[serde(default)]
    pub name: String,
    /// The two block names.
    #[serde(deserialize_with = "strict::name_pair")]
    pub blocks: [String; 2],
    /// End points (in the respective blocks), m.
    #[serde(deserialize_with = "strict::point_pair")]
    pub points: [Point; 2],
    /// Spring constant, N/m per unit thickness.
    pub stiffness: f64,
    /// Two-component (paper) or axial.
    #[serde(default)]
    pub kind: BoltKind,
    /// A dashpot in parallel with the spring, on the relative velocity of the two points
    /// (both components, or along the axis for an axial bolt), N·s/m (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub damping: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A node of a connection element: a point carried by a block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConnectionNode {
    /// The block that carries this node.
    pub block: String,
    /// The node's position, m.
    #[serde(deserialize_with = "strict::point")]
    pub point: Point,
}

/// A constant-strain triangle whose nodes move with two or three blocks (paper eqs. 6–7).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConnectionDef {
    /// Three nodes, counter-clockwise.
    pub nodes: [ConnectionNode; 3],
    /// Elastic properties (density is ignored: the triangle's mass belongs to the blocks).
    pub material: Material,
}

/// Which directions a fixed point holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FixedDirection {
    /// Both directions: a pin.
    #[default]
    Both,
    /// Horizontal only: a roller on a vertical wall.
    X,
    /// Vertical only: a roller on a horizontal floor.
    Y,
}

/// A point of a block held in place by a stiff penalty spring.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedPointDef {
    /// Block name.
    pub block: String,
    /// The point, m.
    #[serde(deserialize_with = "strict::point")]
    pub point: Point,
    /// Pin or roller.
    #[serde(default)]
    pub direction: FixedDirection,
    /// Penalty, N/m. Default: 100 × the block's E (like contacts).
    #[serde(default)]
    pub penalty: Option<f64>,
}

/// A constant force at a point of a block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoadDef {
    /// Block name.
    pub block: String,
    /// Point of application, m.
    #[serde(deserialize_with = "strict::point")]
    pub point: Point,
    /// Force (Fx, Fy), N per unit thickness.
    #[serde(deserialize_with = "strict::point")]
    pub force: Point,
}

/// The horizontal ground excitation of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ExcitationDef {
    /// No ground motion (gravity only).
    #[default]
    None,
    /// `a(t) = A sin(2πf t)` from rest.
    Harmonic {
        /// Amplitude, g.
        amplitude_g: f64,
        /// Frequency, Hz.
        frequency_hz: f64,
    },
    /// A recorded accelerogram: a built-in name or a file path.
    Record {
        /// Built-in record name (`el-centro`…) or an AT2/CSV path.
        record: String,
        /// Scale factor on the record's accelerations.
        #[serde(default = "one")]
        scale: f64,
    },
}

fn one() -> f64 {
    1.0
}

/// The vertical ground excitation: a recorded vertical component (up positive), e.g.
/// `el-centro-up`. It adds to gravity in the frame that moves with the ground, so the
/// normal force of a joint, and with it its friction capacity, follows N = m(g + a_v).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VerticalExcitationDef {
    /// Built-in record name (`el-centro-up`…) or an AT2/CSV path.
    pub record: String,
    /// Scale factor on the record's accelerations.
    #[serde(default = "one")]
    pub scale: f64,
}

/// Points and pairs read strictly: exactly two coordinates (a third would otherwise be
/// dropped without a word: slidebase is two-dimensional), exactly two block names.
mod strict {
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer};

    use super::Point;

    fn exactly_two<E: serde::de::Error>(v: Vec<f64>) -> Result<Point, E> {
        match v.as_slice() {
            [x, y] => Ok([*x, *y]),
            _ => Err(E::custom(format!(
                "a point is [x, y] (two coordinates, m), got {} numbers",
                v.len()
            ))),
        }
    }

    pub fn point<'de, D: Deserializer<'de>>(d: D) -> Result<Point, D::Error> {
        exactly_two(Vec::<f64>::deserialize(d)?)
    }

    pub fn points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Point>, D::Error> {
        Vec::<Vec<f64>>::deserialize(d)?
            .into_iter()
            .map(exactly_two)
            .collect()
    }

    /// Two block names (a contact or a bolt joins two blocks; a third name would otherwise
    /// be dropped without a word).
    pub fn name_pair<'de, D: Deserializer<'de>>(d: D) -> Result<[String; 2], D::Error> {
        let v = Vec::<String>::deserialize(d)?;
        match <[String; 2]>::try_from(v) {
            Ok(pair) => Ok(pair),
            Err(v) => Err(D::Error::custom(format!(
                "`blocks` names the two blocks it joins, got {} names",
                v.len()
            ))),
        }
    }

    pub fn point_pair<'de, D: Deserializer<'de>>(d: D) -> Result<[Point; 2], D::Error> {
        let v = points(d)?;
        match v.as_slice() {
            [a, b] => Ok([*a, *b]),
            _ => Err(D::Error::custom(format!(
                "a bolt has two end points, got {}",
                v.len()
            ))),
        }
    }
}

/// Names the parts of a sliding-block scene: one block on the ground across a joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlidingBlockRoles {
    /// The sliding block.
    pub block: String,
    /// The joint between the block and the ground (contact name).
    pub joint: String,
    /// A friction pendulum: the effective radius R of the ground's dish, m — the radius of
    /// the circle the block's centroid travels on (the dish's radius less the distance from
    /// the block's bottom to its centroid). Absent: a flat joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dish_radius: Option<f64>,
}

/// Names the parts of a two-mass scene (paper Fig. 2) so that α, ρ and Ω/ω can be set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoBlockRoles {
    /// The base raft block (mass M).
    pub raft: String,
    /// The roof block (mass m).
    pub roof: String,
    /// The bolt that is the structure's spring k.
    pub spring: String,
    /// The sliding joint (contact name).
    pub joint: String,
    /// Fixed-base natural frequency √(k/m)/2π, Hz. The paper uses 1 Hz.
    pub structure_frequency_hz: f64,
    /// Total mass M + m per unit thickness, kg; kept when α changes.
    pub total_mass: f64,
}

impl Scene {
    /// Parses a scene from TOML text; `label` (file name) is used in error messages.
    pub fn from_toml(text: &str, label: &str) -> Result<Self> {
        let scene: Scene = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].lines().count().max(1))
                .unwrap_or(0);
            Error::parse(label, line, e.message().to_string())
        })?;
        super::validate::check(&scene).map_err(|i| i.into_error(Some((label, text))))?;
        Ok(scene)
    }

    /// Loads a scene from a TOML file (at most [`MAX_SCENE_FILE_BYTES`] of a regular file).
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::limits::read_text(path, MAX_SCENE_FILE_BYTES, "scene")?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Serialises the scene to TOML.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Scene(format!("cannot serialise scene: {e}")))
    }

    /// Mass of the named block as written (density × area), kg per metre of thickness.
    pub fn block_mass(&self, name: &str) -> Result<f64> {
        let b = &self.blocks[self.block_index(name)?];
        Ok(b.material.density * super::geometry::moments(&b.vertices, &b.name)?.area)
    }

    /// The diagonal of the box around every block but the ground's, m: the structure's
    /// size, of which the solver's tolerances and step limit are fractions.
    pub fn structure_size(&self) -> f64 {
        let structure: Vec<Point> = (self.blocks.iter())
            .filter(|b| b.name != self.ground.block)
            .flat_map(|b| b.vertices.iter().copied())
            .collect();
        super::geometry::bounding_size(&structure)
    }

    /// Index of the block with this name.
    pub fn block_index(&self, name: &str) -> Result<usize> {
        self.blocks
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| {
                Error::Scene(format!(
                    "unknown block '{name}' (blocks: {})",
                    self.blocks
                        .iter()
                        .map(|b| b.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }
}
