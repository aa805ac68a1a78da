//! The plain-data state the simulation publishes: what a renderer or a plot needs of a
//! model at one instant, copied out of the solver (bevy's "extract" step), and the
//! full-rate samples (one row per solver step) that spectra and peaks are computed from.
//!
//! Exaggerated deformation needs, for every drawn point, where the rigid motion of its
//! structure would have put it. Blocks joined by connection elements, bolts or bonded
//! contacts form one structure whose rigid motion is that of its anchor (the base slab for
//! the building, the raft for the two-mass model); a block joined to nothing is its own
//! anchor. Drawing `rigid + factor·(actual − rigid)` then magnifies storey drift and strain
//! alike, and since `actual` and `rigid` are both continuous across a connection, connected
//! blocks stay joined at any factor.

use crate::dda::{Dda, EnergyTerms};
use crate::ground_motion::GroundMotion;
use crate::model::geometry::Point;

/// One block at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockFrame {
    /// Current vertices, m (relative to the frame's origin).
    pub vertices: Vec<[f32; 2]>,
    /// Where the vertices would be under the rigid motion of the block's structure alone
    /// (see the module docs): displayed as `rigid + factor·(vertices − rigid)`.
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
    /// Where the rigid motion of the vertex's structure would put it (for exaggeration).
    pub rigid: [f32; 2],
    /// Unit tangent of the edge.
    pub tangent: [f32; 2],
    /// Which way along `tangent` the edge lies from the contact point, +1 or −1: the
    /// shear spring is drawn over the edge (at a wall's end a contact sits at the edge's
    /// end, and a spring drawn the other way stood in the air outside the wall).
    pub along_edge: f32,
    /// Normal force, N.
    pub normal_force: f32,
    /// 0 open, 1 locked, 2 sliding.
    pub state: u8,
}

/// Points attached to blocks — a bolt's two ends, a connection element's three nodes —
/// where they are and where the rigid motion of their structure would put them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attached<const N: usize> {
    /// Current positions, m.
    pub points: [[f32; 2]; N],
    /// Rigid-motion positions, m (for exaggeration).
    pub rigid: [[f32; 2]; N],
}

/// Scalar responses at one instant (the plots' data).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Probes {
    /// Ground acceleration, m/s².
    pub ground_accel: f64,
    /// Vertical ground acceleration, m/s² (up positive; 0 without vertical shaking).
    pub ground_vertical_accel: f64,
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
    /// Index of the base block (the sliding slab or raft) in `blocks`.
    pub base: usize,
    /// The base is the whole structure (a lone sliding block or slider): it has no roof
    /// apart from itself and no drift.
    pub single_body: bool,
    /// The base's outline at t = 0 relative to the ground: drawn on the ground, moved
    /// with it, it shows where the base started (its "ghost").
    pub base_start: Vec<[f32; 2]>,
    /// Contacts of the last step.
    pub contacts: Vec<ContactFrame>,
    /// Bolts (end points).
    pub bolts: Vec<Attached<2>>,
    /// Connection elements (node positions).
    pub connections: Vec<Attached<3>>,
    /// Scalars for plots.
    pub probes: Probes,
}

/// Full-rate samples of one model: one row per solver step (steps need not be evenly
/// spaced; spectra resample them onto a uniform grid).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Samples {
    /// Time, s.
    pub time: Vec<f64>,
    /// Ground acceleration, m/s².
    pub ground_accel: Vec<f64>,
    /// Vertical ground acceleration, m/s² (up positive; 0 without vertical shaking).
    pub ground_vertical_accel: Vec<f64>,
    /// Absolute base acceleration, m/s².
    pub base_accel: Vec<f64>,
    /// Absolute roof acceleration, m/s².
    pub roof_accel: Vec<f64>,
    /// Slip of the base relative to the ground, m.
    pub slip: Vec<f64>,
    /// Roof displacement relative to the base, m.
    pub drift: Vec<f64>,
}

impl Samples {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Moves the rows of `other` to the end of these.
    pub fn append(&mut self, other: &mut Samples) {
        self.time.append(&mut other.time);
        self.ground_accel.append(&mut other.ground_accel);
        self.ground_vertical_accel
            .append(&mut other.ground_vertical_accel);
        self.base_accel.append(&mut other.base_accel);
        self.roof_accel.append(&mut other.roof_accel);
        self.slip.append(&mut other.slip);
        self.drift.append(&mut other.drift);
    }

    /// Appends copies of the rows `rows` of `other`.
    pub fn push_rows(&mut self, other: &Samples, rows: std::ops::Range<usize>) {
        let columns = [
            (&mut self.time, &other.time),
            (&mut self.ground_accel, &other.ground_accel),
            (
                &mut self.ground_vertical_accel,
                &other.ground_vertical_accel,
            ),
            (&mut self.base_accel, &other.base_accel),
            (&mut self.roof_accel, &other.roof_accel),
            (&mut self.slip, &other.slip),
            (&mut self.drift, &other.drift),
        ];
        for (to, from) in columns {
            to.extend_from_slice(&from[rows.clone()]);
        }
    }

    /// Number of rows with time ≤ `t`.
    pub fn count_until(&self, t: f64) -> usize {
        self.time.partition_point(|&s| s <= t + 1e-9)
    }

    fn push(&mut self, t: f64, p: &Probes) {
        self.time.push(t);
        self.ground_accel.push(p.ground_accel);
        self.ground_vertical_accel.push(p.ground_vertical_accel);
        self.base_accel.push(p.base_accel);
        self.roof_accel.push(p.roof_accel);
        self.slip.push(p.slip);
        self.drift.push(p.drift);
    }
}

/// A rigid motion of the plane: x ↦ c + R(θ)(X − c₀).
#[derive(Debug, Clone, Copy)]
struct RigidMotion {
    from: Point,
    to: Point,
    sin: f64,
    cos: f64,
}

impl RigidMotion {
    fn apply(&self, p: Point) -> Point {
        let (dx, dy) = (p[0] - self.from[0], p[1] - self.from[1]);
        [
            self.to[0] + self.cos * dx - self.sin * dy,
            self.to[1] + self.sin * dx + self.cos * dy,
        ]
    }
}

/// Union-find over block indices (the structures of a scene).
fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// What the extractor needs to know about a model once: which blocks are base and roof,
/// each block's anchor and the reference positions of everything drawn.
#[derive(Debug, Clone)]
pub struct Extractor {
    base: usize,
    roof: usize,
    /// Per block: the block whose rigid motion carries it (see the module docs).
    anchor: Vec<usize>,
    /// Per block: reference centroid and rotation (the anchors' are used).
    reference_pose: Vec<(Point, f64)>,
    /// Per block: vertices in the reference state.
    reference_vertices: Vec<Vec<Point>>,
    /// Bolts' ends and connection nodes in the reference state.
    reference_bolts: Vec<[Point; 2]>,
    reference_connections: Vec<[Point; 3]>,
    reference_strain: Vec<[f64; 3]>,
    /// World position subtracted from every coordinate (kept near the structure so f32 is
    /// precise to well below a millimetre).
    pub origin: Point,
}

impl Extractor {
    /// Captures the reference state of a freshly built model.
    pub fn new(dda: &Dda, base: usize, roof: usize) -> Self {
        let blocks = dda.blocks();
        let g = dda.ground();
        let mut parent: Vec<usize> = (0..blocks.len()).collect();
        let mut join = |a: usize, b: usize| {
            if a != g && b != g {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                parent[ra] = rb;
            }
        };
        for bolt in dda.bolts() {
            join(bolt.blocks[0], bolt.blocks[1]);
        }
        for c in dda.connections() {
            join(c.blocks[0], c.blocks[1]);
            join(c.blocks[1], c.blocks[2]);
        }
        for c in dda.contacts().iter().filter(|c| c.props.bonded) {
            join(c.key.vertex_block, c.key.edge_block);
        }
        // The anchor of a structure: the base if it belongs to it, else its largest block.
        let root_base = find(&mut parent, base);
        let mut anchor_of_root: Vec<Option<usize>> = vec![None; blocks.len()];
        anchor_of_root[root_base] = Some(base);
        for i in 0..blocks.len() {
            let r = find(&mut parent, i);
            let better = match anchor_of_root[r] {
                None => true,
                Some(a) => r != root_base && blocks[i].moments.area > blocks[a].moments.area,
            };
            if better {
                anchor_of_root[r] = Some(i);
            }
        }
        let anchor = (0..blocks.len())
            .map(|i| {
                let r = find(&mut parent, i);
                anchor_of_root[r].unwrap_or(i)
            })
            .collect();
        let origin = blocks[base].moments.centroid;
        Self {
            base,
            roof,
            anchor,
            reference_pose: blocks
                .iter()
                .map(|b| (b.moments.centroid, b.rotation))
                .collect(),
            reference_vertices: blocks.iter().map(|b| b.vertices.clone()).collect(),
            reference_bolts: dda.bolts().iter().map(|b| b.points).collect(),
            reference_connections: dda.connections().iter().map(|c| c.nodes).collect(),
            reference_strain: blocks.iter().map(|b| b.strain).collect(),
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

    /// The rigid motion of every block's anchor since the reference state.
    fn rigid_motions(&self, dda: &Dda) -> Vec<RigidMotion> {
        let blocks = dda.blocks();
        self.anchor
            .iter()
            .map(|&a| {
                let (c0, r0) = self.reference_pose[a];
                let (sin, cos) = (blocks[a].rotation - r0).sin_cos();
                RigidMotion {
                    from: c0,
                    to: blocks[a].moments.centroid,
                    sin,
                    cos,
                }
            })
            .collect()
    }

    /// The scalar responses now.
    pub fn probes(&self, dda: &Dda, motion: Option<&GroundMotion>) -> Probes {
        // Slip, drift and the accelerations as every front end defines them.
        let r = crate::setup::Probe {
            base: self.base,
            roof: self.roof,
        }
        .measure(dda, motion);
        Probes {
            ground_accel: r.ground_accel,
            ground_vertical_accel: dda.vertical_ground_accel(r.time),
            ground_disp: r.ground_disp,
            base_accel: r.base_accel,
            roof_accel: r.roof_accel,
            slip: r.slip,
            drift: r.drift,
            joint_force: 0.0,
            energy: EnergyTerms::default(),
        }
    }

    /// Appends the responses now to full-rate samples (call once per solver step).
    pub fn sample(&self, dda: &Dda, motion: Option<&GroundMotion>, into: &mut Samples) {
        into.push(dda.time(), &self.probes(dda, motion));
    }

    /// Copies the model's current state out.
    pub fn extract(&self, dda: &Dda, motion: Option<&GroundMotion>) -> ModelFrame {
        let t = dda.time();
        let g = dda.ground();
        let shift = dda.frame_displacement();
        let rigid = self.rigid_motions(dda);
        let carry = |block: usize, p: Point| {
            if block == g {
                self.local(p, shift)
            } else {
                self.local(rigid[block].apply(p), shift)
            }
        };
        let blocks = dda
            .blocks()
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let r = &self.reference_strain[i];
                let actual: Vec<[f32; 2]> =
                    b.vertices.iter().map(|&v| self.local(v, shift)).collect();
                BlockFrame {
                    rigid: if i == g {
                        actual.clone()
                    } else {
                        self.reference_vertices[i]
                            .iter()
                            .map(|&v| carry(i, v))
                            .collect()
                    },
                    vertices: actual,
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
                let vb = c.key.vertex_block;
                let reference = self.reference_vertices[vb]
                    .get(c.key.vertex)
                    .copied()
                    .unwrap_or(c.point);
                ContactFrame {
                    point: self.local(c.point, shift),
                    rigid: if vb == g {
                        self.local(c.point, shift)
                    } else {
                        carry(vb, reference)
                    },
                    tangent: [c.tangent[0] as f32, c.tangent[1] as f32],
                    along_edge: along_edge(dda, c),
                    normal_force: n as f32,
                    state: c.state.code(),
                }
            })
            .collect();
        let probes = Probes {
            joint_force,
            energy: dda.energy(),
            ..self.probes(dda, motion)
        };
        // Where the base would be had it not slipped: its start carried with the ground.
        let base_start = self.reference_vertices[self.base]
            .iter()
            .map(|&v| self.local(v, shift))
            .collect();
        ModelFrame {
            time: t,
            blocks,
            base: self.base,
            single_body: self.base == self.roof,
            base_start,
            contacts,
            bolts: dda
                .bolts()
                .iter()
                .zip(&self.reference_bolts)
                .map(|(b, r)| Attached {
                    points: b.points.map(|p| self.local(p, shift)),
                    rigid: [carry(b.blocks[0], r[0]), carry(b.blocks[1], r[1])],
                })
                .collect(),
            connections: dda
                .connections()
                .iter()
                .zip(&self.reference_connections)
                .map(|(c, r)| Attached {
                    points: c.nodes.map(|p| self.local(p, shift)),
                    rigid: [
                        carry(c.blocks[0], r[0]),
                        carry(c.blocks[1], r[1]),
                        carry(c.blocks[2], r[2]),
                    ],
                })
                .collect(),
            probes,
        }
    }
}

/// Which way along the contact's tangent its edge lies from the contact point (see
/// [`ContactFrame::along_edge`]): towards the edge's middle.
fn along_edge(dda: &Dda, c: &crate::dda::contact::Contact) -> f32 {
    let edge = &dda.blocks()[c.key.edge_block].vertices;
    let (a, b) = (edge[c.key.edge], edge[(c.key.edge + 1) % edge.len()]);
    let to_middle = [
        0.5 * (a[0] + b[0]) - c.point[0],
        0.5 * (a[1] + b[1]) - c.point[1],
    ];
    if to_middle[0] * c.tangent[0] + to_middle[1] * c.tangent[1] >= 0.0 {
        1.0
    } else {
        -1.0
    }
}
