//! The plain-data state the simulation publishes: what a renderer or a plot needs of a
//! model at one instant, copied out of the solver (bevy's "extract" step).

use crate::dda::{Dda, EnergyTerms};
use crate::ground_motion::GroundMotion;
use crate::model::geometry::Point;

/// One block at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockFrame {
    /// Current vertices, m (relative to the frame's origin).
    pub vertices: Vec<[f32; 2]>,
    /// Where the vertices would be under the block's rigid motion alone: displayed
    /// deformation is exaggerated as `rigid + factor·(vertices − rigid)`.
    pub rigid: Vec<[f32; 2]>,
    /// Stress (σx, σy, τxy), Pa.
    pub stress: [f32; 3],
    /// Strain since the reference state (εx, εy, γxy).
    pub strain: [f32; 3],
    /// Whether this is the ground.
    pub is_ground: bool,
}

/// One contact at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// The vertex in contact, m.
    pub point: [f32; 2],
    /// Unit tangent of the edge.
    pub tangent: [f32; 2],
    /// Normal force, N.
    pub normal_force: f32,
    /// 0 open, 1 locked, 2 sliding.
    pub state: u8,
}

/// Scalar responses at one instant (the plots' data).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Probes {
    /// Ground acceleration, m/s².
    pub ground_accel: f64,
    /// Ground displacement, m.
    pub ground_disp: f64,
    /// Absolute base acceleration, m/s².
    pub base_accel: f64,
    /// Absolute roof acceleration, m/s².
    pub roof_accel: f64,
    /// Slip of the base relative to the ground, m.
    pub slip: f64,
    /// Roof displacement relative to the base, m.
    pub drift: f64,
    /// Horizontal force the ground exerts on the base through the joint, N (m⁻¹).
    pub joint_force: f64,
    /// Energy terms.
    pub energy: EnergyTerms,
}

/// A model at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelFrame {
    /// Simulated time, s.
    pub time: f64,
    /// Blocks in scene order.
    pub blocks: Vec<BlockFrame>,
    /// Contacts of the last step.
    pub contacts: Vec<ContactFrame>,
    /// Bolts (end points).
    pub bolts: Vec<[[f32; 2]; 2]>,
    /// Connection elements (node positions).
    pub connections: Vec<[[f32; 2]; 3]>,
    /// Scalars for plots.
    pub probes: Probes,
}

/// What the extractor needs to know about a model once: which blocks are base and roof,
/// and the reference shapes for the rigid motion.
#[derive(Debug, Clone)]
pub struct Extractor {
    base: usize,
    roof: usize,
    /// Per block: vertex offsets from the centroid in the reference state.
    offsets: Vec<Vec<Point>>,
    reference_strain: Vec<[f64; 3]>,
    /// World position subtracted from every coordinate (kept near the structure so f32 is
    /// precise to well below a millimetre).
    pub origin: Point,
}

impl Extractor {
    /// Captures the reference state of a freshly built model.
    pub fn new(dda: &Dda, base: usize, roof: usize) -> Self {
        let offsets = dda
            .blocks()
            .iter()
            .map(|b| {
                b.vertices
                    .iter()
                    .map(|v| [v[0] - b.moments.centroid[0], v[1] - b.moments.centroid[1]])
                    .collect()
            })
            .collect();
        let reference_strain = dda.blocks().iter().map(|b| b.strain).collect();
        let origin = dda.blocks()[base].moments.centroid;
        Self {
            base,
            roof,
            offsets,
            reference_strain,
            origin: [origin[0], 0.0],
        }
    }

    /// A solver point in the picture's coordinates: the solver's frame moves with the
    /// ground by `shift` (see `Dda::frame_displacement`), the picture's does not.
    fn local(&self, p: Point, shift: f64) -> [f32; 2] {
        [
            (p[0] + shift - self.origin[0]) as f32,
            (p[1] - self.origin[1]) as f32,
        ]
    }

    /// Copies the model's current state out.
    pub fn extract(&self, dda: &Dda, motion: Option<&GroundMotion>) -> ModelFrame {
        let t = dda.time();
        let g = dda.ground();
        let shift = dda.frame_displacement();
        let blocks = dda
            .blocks()
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let c = b.moments.centroid;
                let (s, co) = b.rotation.sin_cos();
                let rigid = self.offsets[i]
                    .iter()
                    .map(|o| {
                        self.local(
                            [c[0] + co * o[0] - s * o[1], c[1] + s * o[0] + co * o[1]],
                            shift,
                        )
                    })
                    .collect();
                let r = &self.reference_strain[i];
                BlockFrame {
                    vertices: b.vertices.iter().map(|&v| self.local(v, shift)).collect(),
                    rigid,
                    stress: b.stress.map(|v| v as f32),
                    strain: [
                        (b.strain[0] - r[0]) as f32,
                        (b.strain[1] - r[1]) as f32,
                        (b.strain[2] - r[2]) as f32,
                    ],
                    is_ground: i == g,
                }
            })
            .collect();
        let mut joint_force = 0.0;
        let contacts = dda
            .contacts()
            .iter()
            .map(|c| {
                let (n, pull) = dda.contact_force(c);
                // Force on the structure: minus the spring (or friction) force along the
                // tangent on the vertex side; the reaction on the edge side.
                if c.key.edge_block == g {
                    joint_force -= pull * c.tangent[0];
                } else if c.key.vertex_block == g {
                    joint_force += pull * c.tangent[0];
                }
                ContactFrame {
                    point: self.local(c.point, shift),
                    tangent: [c.tangent[0] as f32, c.tangent[1] as f32],
                    normal_force: n as f32,
                    state: c.state.code(),
                }
            })
            .collect();
        // Slip, drift and the accelerations as every front end defines them.
        let r = crate::setup::Probe {
            base: self.base,
            roof: self.roof,
        }
        .measure(dda, motion);
        let probes = Probes {
            ground_accel: r.ground_accel,
            ground_disp: r.ground_disp,
            base_accel: r.base_accel,
            roof_accel: r.roof_accel,
            slip: r.slip,
            drift: r.drift,
            joint_force,
            energy: dda.energy(),
        };
        ModelFrame {
            time: t,
            blocks,
            contacts,
            bolts: dda
                .bolts()
                .iter()
                .map(|b| {
                    [
                        self.local(b.points[0], shift),
                        self.local(b.points[1], shift),
                    ]
                })
                .collect(),
            connections: dda
                .connections()
                .iter()
                .map(|c| c.nodes.map(|p| self.local(p, shift)))
                .collect(),
            probes,
        }
    }
}
