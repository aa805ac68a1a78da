//! Joints between blocks and supports: bolts, fixed points/rollers, connection elements.
//!
//! Each is a *nodal element*: its nodes are points carried by blocks (moving with `T·D`),
//! it has a stiffness on the node displacements and a force from what it carried at the
//! start of the step. The assembly maps both onto the blocks' unknowns.

use super::block::Vec6;
use crate::model::geometry::{Point, sub};
use crate::model::scene::{BoltKind, FixedDirection};

/// A node displacement function: block index and point → displacement this step.
pub trait NodeMotion {
    /// Displacement of point `x` of block `b` in this step (with the block's rotation
    /// as the solver applies it to vertices: exact or linear).
    fn node_displacement(&self, b: usize, x: Point) -> Point;

    /// Displacement of point `x` of block `b` under the linear map `T·D` the step was
    /// solved with (a rotation r₀ moves a point by r₀ × its arm, to first order).
    fn linear_node_displacement(&self, b: usize, x: Point) -> Point;
}

/// Most nodes an element's terms hold: a connection's triangles over the four corners of
/// its gap, merged into one element (see [`ConnectionGroups`]).
pub const MAX_NODES: usize = 4;

/// Stiffness and start force of a nodal element (up to [`MAX_NODES`] nodes) for one step,
/// in fixed-size storage: elements are rebuilt every step, and allocating them would cost
/// more than computing them.
#[derive(Debug, Clone, Copy)]
pub struct ElementTerms {
    count: usize,
    nodes: [(usize, Point); MAX_NODES],
    /// Stiffness on node displacements, 2n × 2n row-major in the first (2n)² entries.
    ke: [f64; 4 * MAX_NODES * MAX_NODES],
    /// Node forces at the step start (∂E/∂u), 2n.
    fe: [f64; 2 * MAX_NODES],
}

impl ElementTerms {
    /// Terms with these nodes (1 to [`MAX_NODES`]) and zero stiffness and force.
    fn with_nodes(nodes: &[(usize, Point)]) -> Self {
        let mut all = [(0, [0.0; 2]); MAX_NODES];
        all[..nodes.len()].copy_from_slice(nodes);
        Self {
            count: nodes.len(),
            nodes: all,
            ke: [0.0; 4 * MAX_NODES * MAX_NODES],
            fe: [0.0; 2 * MAX_NODES],
        }
    }

    /// Entry `index` of `out` made the terms of `nodes` with zero stiffness and force:
    /// the entry there reused, or appended when `index` is `out.len()`. Built in place
    /// because the terms (~700 bytes) are larger than the work of filling them: built
    /// aside, every joint's were copied in at every step.
    pub fn entry<'a>(
        out: &'a mut Vec<ElementTerms>,
        index: usize,
        nodes: &[(usize, Point)],
    ) -> &'a mut ElementTerms {
        if index == out.len() {
            out.push(Self::with_nodes(nodes));
        } else {
            out[index].reset(nodes);
        }
        &mut out[index]
    }

    /// Makes these the terms of `nodes` with zero stiffness and force (as
    /// [`ElementTerms::with_nodes`], in place).
    fn reset(&mut self, nodes: &[(usize, Point)]) {
        let n = nodes.len();
        self.count = n;
        self.nodes = [(0, [0.0; 2]); MAX_NODES];
        self.nodes[..n].copy_from_slice(nodes);
        // All of it, as `with_nodes` does: the entry may have held a larger element.
        self.ke.fill(0.0);
        self.fe.fill(0.0);
    }

    /// Adds the stiffness and forces of connection `c`, whose node k is this element's
    /// node `map[k]` (a node's two entries stay side by side).
    fn add_connection(&mut self, c: &Connection, map: &[usize; MAX_NODES]) {
        let own_dim = 2 * self.count;
        c.for_each_row(|i, ke_row, f| {
            let own_i = 2 * map[i / 2] + i % 2;
            self.fe[own_i] += f;
            for (l, pair) in ke_row.chunks_exact(2).enumerate() {
                let at = own_i * own_dim + 2 * map[l];
                self.ke[at] += pair[0];
                self.ke[at + 1] += pair[1];
            }
        });
    }

    /// Nodes: (block, current position).
    pub fn nodes(&self) -> &[(usize, Point)] {
        &self.nodes[..self.count]
    }

    /// Stiffness on node displacements, 2n × 2n row-major.
    pub fn ke(&self) -> &[f64] {
        &self.ke[..4 * self.count * self.count]
    }

    /// Node forces at the step start (∂E/∂u), 2n.
    pub fn fe(&self) -> &[f64] {
        &self.fe[..2 * self.count]
    }

    /// These terms as a viscous element of damping coefficient `coefficient` times this
    /// stiffness (Rayleigh's a₁·K): the stiffness `coefficient · gain · ke` (`gain` =
    /// γ/(βΔt), the end velocity's share of the increment) and the start force
    /// `coefficient · ke · velocities` (the nodes' predicted velocities, flattened).
    pub fn as_dashpot(
        &self,
        coefficient: f64,
        gain: f64,
        velocities: &[f64; 2 * MAX_NODES],
    ) -> Self {
        let dim = 2 * self.count;
        let mut out = Self::with_nodes(self.nodes());
        for i in 0..dim {
            for j in 0..dim {
                let k = self.ke[i * dim + j];
                out.ke[i * dim + j] = coefficient * gain * k;
                out.fe[i] += coefficient * k * velocities[j];
            }
        }
        out
    }

    /// Node forces at the step start: fe (the first 2n entries).
    pub fn start_forces(&self) -> [f64; 2 * MAX_NODES] {
        self.fe
    }

    /// Node forces at the end of the step: fe + ke·u (the first 2n entries).
    pub fn end_forces(&self, u: &[Point]) -> [f64; 2 * MAX_NODES] {
        let dim = 2 * self.count;
        let mut flat = [0.0; 2 * MAX_NODES];
        for (pair, uk) in flat.chunks_exact_mut(2).zip(u) {
            pair.copy_from_slice(uk);
        }
        let mut out = [0.0; 2 * MAX_NODES];
        let rows = self.ke.chunks_exact(dim).take(dim);
        for (i, (o, ke_row)) in out.iter_mut().zip(rows).enumerate() {
            *o = self.fe[i] + ke_row.iter().zip(&flat).map(|(k, x)| k * x).sum::<f64>();
        }
        out
    }
}

/// The connection triangles that share their nodes, found once: each group is assembled
/// as one element of up to [`MAX_NODES`] nodes, its triangles' stiffnesses added on their
/// shared nodes (superposition). The frame's connections are four triangles over the four
/// corners of each gap; mapped onto the blocks one by one they were 30 % of its step.
/// Which triangle node is which group node depends only on which block carries it and
/// where (nodes move with their blocks), so it is decided from the start positions and
/// kept: symbolic once, numeric every step.
#[derive(Debug, Clone, Default)]
pub struct ConnectionGroups {
    groups: Vec<ConnectionGroup>,
}

/// One group: consecutive connections `first..first + len`.
#[derive(Debug, Clone)]
struct ConnectionGroup {
    first: usize,
    len: usize,
    /// Where each group node is: (connection, node of that connection).
    sources: [(usize, usize); MAX_NODES],
    /// Number of group nodes.
    nodes: usize,
    /// Per connection of the group (at most [`MAX_NODES`]), the group node of each of its
    /// three nodes.
    maps: [[usize; MAX_NODES]; MAX_NODES],
}

impl ConnectionGroups {
    /// Groups consecutive connections whose nodes (block and position) together number
    /// at most [`MAX_NODES`] and that number at most [`MAX_NODES`] triangles.
    pub fn new(connections: &[Connection]) -> Self {
        let mut groups: Vec<ConnectionGroup> = Vec::new();
        for (ci, c) in connections.iter().enumerate() {
            let nodes = c.node_list();
            let joined = groups
                .last_mut()
                .is_some_and(|g| g.join(connections, ci, &nodes));
            if !joined {
                let mut g = ConnectionGroup {
                    first: ci,
                    len: 0,
                    sources: [(ci, 0); MAX_NODES],
                    nodes: 0,
                    maps: [[0; MAX_NODES]; MAX_NODES],
                };
                let joined_new = g.join(connections, ci, &nodes);
                debug_assert!(joined_new, "a triangle's three nodes fit an empty group");
                groups.push(g);
            }
        }
        Self { groups }
    }

    /// Writes the terms of every group, at the connections' current geometry, into
    /// `out[from..]` (reusing the entries there, appending the rest) and truncates `out`
    /// after them.
    pub fn terms_into(&self, connections: &[Connection], out: &mut Vec<ElementTerms>, from: usize) {
        for (index, g) in (from..).zip(&self.groups) {
            let terms = ElementTerms::entry(out, index, &g.nodes(connections)[..g.nodes]);
            for (map, c) in g.maps.iter().zip(&connections[g.first..g.first + g.len]) {
                terms.add_connection(c, map);
            }
        }
        out.truncate(from + self.groups.len());
    }

    /// Moves every connection by this step's motion (see [`Connection::commit`]). A node
    /// shared by the triangles of a group is one point carried by one block, so its
    /// displacements are computed once for the group and handed to each triangle: the
    /// triangles' copies of it stay equal to the bit, as they were when grouped.
    pub fn commit(&self, connections: &mut [Connection], motion: &impl NodeMotion) {
        for g in &self.groups {
            let nodes = g.nodes(connections);
            let mut linear = [[0.0; 2]; MAX_NODES];
            let mut exact = [[0.0; 2]; MAX_NODES];
            for (k, &(b, x)) in nodes[..g.nodes].iter().enumerate() {
                linear[k] = motion.linear_node_displacement(b, x);
                exact[k] = motion.node_displacement(b, x);
            }
            let triangles = &mut connections[g.first..g.first + g.len];
            // In two passes over the group rather than triangle by triangle: each half's
            // divisions and roots then wait for nothing from the other triangles', and
            // the processor overlaps them (the same operations on each triangle).
            for (map, c) in g.maps.iter().zip(triangles.iter_mut()) {
                c.book_and_move(
                    std::array::from_fn(|k| linear[map[k]]),
                    std::array::from_fn(|k| exact[map[k]]),
                );
            }
            triangles.iter_mut().for_each(Connection::take_new_shape);
        }
    }
}

impl ConnectionGroup {
    /// The group's nodes (block, current position), read from the triangles that carry
    /// them; the first `self.nodes` are the group's.
    fn nodes(&self, connections: &[Connection]) -> [(usize, Point); MAX_NODES] {
        std::array::from_fn(|k| {
            let (ci, node) = self.sources[k];
            connections[ci].node(node)
        })
    }

    /// Adds connection `ci` (its `nodes`) when the group can take it.
    fn join(&mut self, connections: &[Connection], ci: usize, nodes: &[(usize, Point); 3]) -> bool {
        if self.len == MAX_NODES || ci != self.first + self.len {
            return false;
        }
        let (mut sources, mut count) = (self.sources, self.nodes);
        let mut map = [0usize; MAX_NODES];
        for (k, node) in nodes.iter().enumerate() {
            let known = sources[..count]
                .iter()
                .position(|&(cj, nj)| connections[cj].node_list()[nj] == *node);
            map[k] = match known {
                Some(i) => i,
                None if count < MAX_NODES => {
                    sources[count] = (ci, k);
                    count += 1;
                    count - 1
                }
                None => return false,
            };
        }
        self.sources = sources;
        self.nodes = count;
        self.maps[self.len] = map;
        self.len += 1;
        true
    }
}

/// A bolt between point P of block i and point Q of block j (paper eq. 5).
#[derive(Debug, Clone)]
pub struct Bolt {
    /// Name from the scene.
    pub name: String,
    /// Blocks (i, j).
    pub blocks: [usize; 2],
    /// Current end points.
    pub points: [Point; 2],
    /// Q − P in the unstressed configuration.
    pub rest: Point,
    /// Spring constant, N/m.
    pub stiffness: f64,
    /// Two-component or axial.
    pub kind: BoltKind,
    /// Dashpot in parallel with the spring, N·s/m (0: none).
    pub damping: f64,
}

impl Bolt {
    /// Elongation vector (Q − P) − rest.
    pub fn elongation(&self) -> Point {
        let d = sub(self.points[1], self.points[0]);
        sub(d, self.rest)
    }

    /// Force the bolt exerts on its Q end, N (equal and opposite on P).
    pub fn force_on_q(&self) -> Point {
        match self.kind {
            BoltKind::TwoComponent => {
                let e = self.elongation();
                [-self.stiffness * e[0], -self.stiffness * e[1]]
            }
            BoltKind::Axial => {
                let d = sub(self.points[1], self.points[0]);
                let l = d[0].hypot(d[1]);
                let l0 = self.rest[0].hypot(self.rest[1]);
                let f = self.stiffness * (l - l0);
                [-f * d[0] / l, -f * d[1] / l]
            }
        }
    }

    /// Writes this step's element terms into entry `index` of `out` (see
    /// [`ElementTerms::entry`]).
    pub fn terms_into(&self, out: &mut Vec<ElementTerms>, index: usize) {
        let k = self.stiffness;
        let nodes = [
            (self.blocks[0], self.points[0]),
            (self.blocks[1], self.points[1]),
        ];
        let terms = ElementTerms::entry(out, index, &nodes);
        // Stiffness pattern [[S, −S], [−S, S]] for a 2×2 S.
        let pattern = |ke: &mut [f64], s: [[f64; 2]; 2]| {
            for (a, sa) in [(0usize, 1.0), (1usize, -1.0)] {
                for (b, sb) in [(0usize, 1.0), (1usize, -1.0)] {
                    for i in 0..2 {
                        for j in 0..2 {
                            ke[(2 * a + i) * 4 + 2 * b + j] = sa * sb * s[i][j];
                        }
                    }
                }
            }
        };
        // fe = ∂E/∂u, ordered (P, Q): the bolt pulls Q with `f` and P with −f, and
        // ∂E/∂u is minus the force the bolt exerts on the node.
        let f = self.force_on_q();
        terms.fe[..4].copy_from_slice(&[f[0], f[1], -f[0], -f[1]]);
        let s = match self.kind {
            BoltKind::TwoComponent => [[k, 0.0], [0.0, k]],
            BoltKind::Axial => {
                let d = sub(self.points[1], self.points[0]);
                let l = d[0].hypot(d[1]).max(f64::MIN_POSITIVE);
                let u = [d[0] / l, d[1] / l];
                let l0 = self.rest[0].hypot(self.rest[1]);
                // Material stiffness k·uuᵀ plus the geometric stiffness of a bolt under
                // tension N: (N/l)(I − uuᵀ).
                let g = k * (l - l0) / l;
                let mut s = [[0.0; 2]; 2];
                for i in 0..2 {
                    for j in 0..2 {
                        let id = if i == j { 1.0 } else { 0.0 };
                        s[i][j] = k * u[i] * u[j] + g * (id - u[i] * u[j]);
                    }
                }
                s
            }
        };
        pattern(&mut terms.ke, s);
    }

    /// The directions the dashpot acts along: x and y for a two-component bolt, the axis
    /// (from P to Q) for an axial one; none without a dashpot.
    pub fn dashpot_directions(&self) -> smallvec::SmallVec<[Point; 2]> {
        if self.damping == 0.0 {
            return smallvec::SmallVec::new();
        }
        match self.kind {
            BoltKind::TwoComponent => smallvec::smallvec![[1.0, 0.0], [0.0, 1.0]],
            BoltKind::Axial => {
                let d = sub(self.points[1], self.points[0]);
                let l = d[0].hypot(d[1]).max(f64::MIN_POSITIVE);
                smallvec::smallvec![[d[0] / l, d[1] / l]]
            }
        }
    }

    /// Stored energy, J.
    pub fn energy(&self) -> f64 {
        match self.kind {
            BoltKind::TwoComponent => {
                let e = self.elongation();
                0.5 * self.stiffness * (e[0] * e[0] + e[1] * e[1])
            }
            BoltKind::Axial => {
                let d = sub(self.points[1], self.points[0]);
                let e = d[0].hypot(d[1]) - self.rest[0].hypot(self.rest[1]);
                0.5 * self.stiffness * e * e
            }
        }
    }

    /// Moves the end points with their blocks.
    pub fn commit(&mut self, motion: &impl NodeMotion) {
        for (p, &b) in self.points.iter_mut().zip(self.blocks.iter()) {
            let u = motion.node_displacement(b, *p);
            p[0] += u[0];
            p[1] += u[1];
        }
    }
}

/// A point of a block held near its anchor by a penalty spring (pin or roller).
#[derive(Debug, Clone)]
pub struct FixedPoint {
    /// The block.
    pub block: usize,
    /// The point's current position.
    pub point: Point,
    /// Where it is held.
    pub anchor: Point,
    /// Pin or roller.
    pub direction: FixedDirection,
    /// Penalty, N/m.
    pub penalty: f64,
}

impl FixedPoint {
    fn projector(&self) -> [[f64; 2]; 2] {
        match self.direction {
            FixedDirection::Both => [[1.0, 0.0], [0.0, 1.0]],
            FixedDirection::X => [[1.0, 0.0], [0.0, 0.0]],
            FixedDirection::Y => [[0.0, 0.0], [0.0, 1.0]],
        }
    }

    /// Writes this step's element terms into entry `index` of `out` (see
    /// [`ElementTerms::entry`]).
    pub fn terms_into(&self, out: &mut Vec<ElementTerms>, index: usize) {
        let p = self.projector();
        let c = sub(self.point, self.anchor);
        let terms = ElementTerms::entry(out, index, &[(self.block, self.point)]);
        terms.ke[..4].copy_from_slice(&[
            self.penalty * p[0][0],
            self.penalty * p[0][1],
            self.penalty * p[1][0],
            self.penalty * p[1][1],
        ]);
        terms.fe[..2].copy_from_slice(&[
            self.penalty * (p[0][0] * c[0] + p[0][1] * c[1]),
            self.penalty * (p[1][0] * c[0] + p[1][1] * c[1]),
        ]);
    }

    /// Stored energy, J.
    pub fn energy(&self) -> f64 {
        let p = self.projector();
        let c = sub(self.point, self.anchor);
        let pc = [
            p[0][0] * c[0] + p[0][1] * c[1],
            p[1][0] * c[0] + p[1][1] * c[1],
        ];
        0.5 * self.penalty * (pc[0] * c[0] + pc[1] * c[1])
    }

    /// Moves the point with its block.
    pub fn commit(&mut self, motion: &impl NodeMotion) {
        let u = motion.node_displacement(self.block, self.point);
        self.point[0] += u[0];
        self.point[1] += u[1];
    }
}

/// A constant-strain triangle whose nodes move with their blocks (paper eqs. 6–7).
///
/// Its strain is a function of its current shape (Biot's strain `V − I`, V the left
/// stretch of its deformation gradient from the unstressed triangle), not the sum of its
/// steps' increments as in the paper. The sum is not a function of the shape at second order: a step that shears the
/// triangle by Δγ and back the next keeps the summed strain but takes Δγ²/4 of the area
/// away for good. Under the trapezoidal rule (which leaves a shear mode at the step's
/// Nyquist frequency undamped) the three-storey frame's connections lost area at every
/// step with no stress to resist it; the floors' weight did work on the lost height and
/// fed the mode, and on the 90 s Chi-Chi record the frame sagged by 8.8 cm, gravity
/// doing 34 MJ of work against 3.5 MJ of input. With the strain from the shape, a lost
/// area is a compression, and the same run's floors stay within 0.04 mm.
#[derive(Debug, Clone)]
pub struct Connection {
    /// Blocks carrying the three nodes.
    pub blocks: [usize; 3],
    /// Current node positions (counter-clockwise).
    pub nodes: [Point; 3],
    /// Elasticity matrix C, Pa.
    pub elasticity: [[f64; 3]; 3],
    /// Strain (εx, εy, γxy) of the current shape: `ln V`, V the left stretch of the
    /// deformation gradient from the unstressed triangle (in global axes, so that it
    /// turns with the element). Hencky's `ln V` was tried in its place and rejected on
    /// measurement: the three-storey frame then rose by 7 mm over El Centro (trapezoidal
    /// rule, energy residual −5e-6), where with `V − I` its mean height moves by 6 µm
    /// (residual −8e-8).
    pub strain: [f64; 3],
    /// Stress `C ε`, Pa.
    pub stress: [f64; 3],
    /// Elastic energy stored, J: the work of the element's forces on its strain
    /// increments (see [`Connection::energy`]).
    pub stored_energy: f64,
    /// The inverse of the unstressed element's edge matrix (its reference shape), which
    /// every step's strain needs: computed once, the same values as at each step.
    rest_inverse: [[f64; 2]; 2],
}

/// A triangle's edge matrix: the edges from its first node as columns.
fn edges(n: &[Point; 3]) -> [[f64; 2]; 2] {
    [
        [n[1][0] - n[0][0], n[2][0] - n[0][0]],
        [n[1][1] - n[0][1], n[2][1] - n[0][1]],
    ]
}

/// The inverse of a triangle's edge matrix.
fn inverse_edges(n: &[Point; 3]) -> [[f64; 2]; 2] {
    let r = edges(n);
    let det = r[0][0] * r[1][1] - r[0][1] * r[1][0];
    [
        [r[1][1] / det, -r[0][1] / det],
        [-r[1][0] / det, r[0][0] / det],
    ]
}

impl Connection {
    /// An unstressed element on three nodes (counter-clockwise) carried by these blocks.
    pub fn new(blocks: [usize; 3], nodes: [Point; 3], elasticity: [[f64; 3]; 3]) -> Self {
        Self {
            blocks,
            nodes,
            elasticity,
            strain: [0.0; 3],
            stress: [0.0; 3],
            stored_energy: 0.0,
            rest_inverse: inverse_edges(&nodes),
        }
    }

    /// Strain of the current triangle from its deformation gradient F (current edges
    /// times the inverse of the rest edges): `V − I`, V the left stretch of the polar
    /// decomposition `F = V R`. A rigid turn has no strain, and to first order a step
    /// changes it by the increment `B u` the step was solved with.
    fn geometric_strain(&self) -> [f64; 3] {
        let (x, r_inv) = (edges(&self.nodes), &self.rest_inverse);
        let mut f = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                f[i][j] = x[i][0] * r_inv[0][j] + x[i][1] * r_inv[1][j];
            }
        }
        // The rotation of the polar decomposition, in closed form in 2D: its angle is
        // that of (F₀₀ + F₁₁, F₁₀ − F₀₁) (no trigonometry: this runs for every element
        // at every step).
        let (c, s) = (f[0][0] + f[1][1], f[1][0] - f[0][1]);
        let norm = (c * c + s * s).sqrt();
        let (sin, cos) = (s / norm, c / norm);
        // V = F Rᵀ (symmetric but for round-off).
        let v00 = f[0][0] * cos - f[0][1] * sin;
        let v11 = f[1][0] * sin + f[1][1] * cos;
        let v01 = f[0][0] * sin + f[0][1] * cos;
        let v10 = f[1][0] * cos - f[1][1] * sin;
        [v00 - 1.0, v11 - 1.0, v01 + v10]
    }

    /// Area and strain-displacement matrix B (3×6) of the current triangle.
    fn b_matrix(&self) -> (f64, [[f64; 6]; 3]) {
        let [p1, p2, p3] = self.nodes;
        let two_a = (p2[0] - p1[0]) * (p3[1] - p1[1]) - (p3[0] - p1[0]) * (p2[1] - p1[1]);
        let b = [p2[1] - p3[1], p3[1] - p1[1], p1[1] - p2[1]];
        let c = [p3[0] - p2[0], p1[0] - p3[0], p2[0] - p1[0]];
        let mut m = [[0.0; 6]; 3];
        for k in 0..3 {
            m[0][2 * k] = b[k] / two_a;
            m[1][2 * k + 1] = c[k] / two_a;
            m[2][2 * k] = c[k] / two_a;
            m[2][2 * k + 1] = b[k] / two_a;
        }
        (two_a / 2.0, m)
    }

    /// Element terms: `ke = A Bᵀ C B`, `fe = A Bᵀ σ`.
    pub fn terms(&self) -> ElementTerms {
        let (ke, fe) = self.local_terms();
        let mut terms = ElementTerms::with_nodes(&self.node_list());
        terms.ke[..36].copy_from_slice(&ke);
        terms.fe[..6].copy_from_slice(&fe);
        terms
    }

    /// Node `k` (0, 1 or 2) as (block, current position).
    pub fn node(&self, k: usize) -> (usize, Point) {
        (self.blocks[k], self.nodes[k])
    }

    /// The nodes as (block, current position).
    pub fn node_list(&self) -> [(usize, Point); 3] {
        std::array::from_fn(|k| self.node(k))
    }

    /// `ke = A Bᵀ C B` (6 × 6, row-major) and `fe = A Bᵀ σ` on the three nodes, node pair
    /// by node pair: B's node block is `[[b, 0], [0, c], [c, b]] / 2A`, so the pair (k, l)
    /// is `[[bₖ, 0, cₖ], [0, cₖ, bₖ]] C [[bₗ, 0], [0, cₗ], [cₗ, bₗ]] / 4A`.
    pub fn local_terms(&self) -> ([f64; 36], [f64; 6]) {
        let mut ke = [0.0; 36];
        let mut fe = [0.0; 6];
        self.for_each_row(|i, row, f| {
            ke[6 * i..6 * i + 6].copy_from_slice(row);
            fe[i] = f;
        });
        (ke, fe)
    }

    /// Hands each row `i` of [`Connection::local_terms`] to `put`: its six `ke` entries
    /// and its `fe`. A group adds them straight onto its own nodes (see
    /// [`ElementTerms::add_connection`]) rather than through a returned copy.
    #[inline(always)]
    fn for_each_row(&self, mut put: impl FnMut(usize, &[f64; 6], f64)) {
        let [p1, p2, p3] = self.nodes;
        let two_a = (p2[0] - p1[0]) * (p3[1] - p1[1]) - (p3[0] - p1[0]) * (p2[1] - p1[1]);
        let b = [p2[1] - p3[1], p3[1] - p1[1], p1[1] - p2[1]];
        let c = [p3[0] - p2[0], p1[0] - p3[0], p2[0] - p1[0]];
        // A row of the pair (k, l) block is (row₀ bₗ + row₂ cₗ, row₁ cₗ + row₂ bₗ): over the
        // three l at once, the alternating row entries times these, in vector lanes.
        let bc = [b[0], c[0], b[1], c[1], b[2], c[2]];
        let cb = [c[0], b[0], c[1], b[1], c[2], b[2]];
        let e = &self.elasticity;
        let scale = 1.0 / (2.0 * two_a);
        for k in 0..3 {
            // Bₖᵀ (2 × 3) times C, row by row.
            let rows = [
                [
                    b[k] * e[0][0] + c[k] * e[2][0],
                    b[k] * e[0][1] + c[k] * e[2][1],
                    b[k] * e[0][2] + c[k] * e[2][2],
                ],
                [
                    c[k] * e[1][0] + b[k] * e[2][0],
                    c[k] * e[1][1] + b[k] * e[2][1],
                    c[k] * e[1][2] + b[k] * e[2][2],
                ],
            ];
            let sigma = &self.stress;
            let fe = [
                0.5 * (b[k] * sigma[0] + c[k] * sigma[2]),
                0.5 * (c[k] * sigma[1] + b[k] * sigma[2]),
            ];
            for (r, row) in rows.iter().enumerate() {
                let alternating = [row[0], row[1], row[0], row[1], row[0], row[1]];
                let ke_row: [f64; 6] =
                    std::array::from_fn(|j| scale * (alternating[j] * bc[j] + row[2] * cb[j]));
                put(2 * k + r, &ke_row, fe[r]);
            }
        }
    }

    /// Elastic energy, J: the work the element's forces (`fe`, `ke` of each step) did on
    /// its strain increments, the work the step balanced. The area of a connection
    /// carrying a floor's weight changes by a few per cent, so ½ A εᵀ C ε of the current
    /// area would differ from that work by ½ ΔA εᵀCε at every step (the three-storey
    /// frame's connections: 6e-3 of the input energy over an earthquake).
    pub fn energy(&self) -> f64 {
        self.stored_energy
    }

    /// Books the work of this step's forces on its strain increment, moves the nodes and
    /// takes the strain and stress of the new shape.
    pub fn commit(&mut self, motion: &impl NodeMotion) {
        let at = |k: usize| (self.blocks[k], self.nodes[k]);
        let linear = std::array::from_fn(|k| {
            let (b, x) = at(k);
            motion.linear_node_displacement(b, x)
        });
        let exact = std::array::from_fn(|k| {
            let (b, x) = at(k);
            motion.node_displacement(b, x)
        });
        self.commit_displaced(linear, exact);
    }

    /// [`Connection::commit`] with the nodes' displacements given: `lin` under the
    /// linear map the step was solved with, `u` as the nodes move.
    fn commit_displaced(&mut self, lin: [Point; 3], u: [Point; 3]) {
        self.book_and_move(lin, u);
        self.take_new_shape();
    }

    /// The first half of a commit: books the work of the step on the element and moves
    /// its nodes by `u` (its long-latency part is the B matrix's six divisions).
    fn book_and_move(&mut self, lin: [Point; 3], u: [Point; 3]) {
        let (area, b) = self.b_matrix();
        // The strain increment from the linear node displacements the step was solved
        // with, so that the element stores the work the solve did on it. The exact ones
        // would strain a rigidly turning element by cos θ − 1, and a column connection
        // carrying a floor's weight would then take energy from gravity at every step
        // (the three-storey frame's fixed-base energy residual was 6e-2, O(Δt)).
        let flat: Vec6 = [
            lin[0][0], lin[0][1], lin[1][0], lin[1][1], lin[2][0], lin[2][1],
        ];
        let mut de = [0.0; 3];
        for i in 0..3 {
            de[i] = (0..6).map(|j| b[i][j] * flat[j]).sum();
        }
        for i in 0..3 {
            // The work of the step's force A(σ + ½CΔε) on Δε (exact for the linear update).
            let change: f64 = (0..3).map(|j| self.elasticity[i][j] * de[j]).sum();
            self.stored_energy += area * (self.stress[i] + 0.5 * change) * de[i];
        }
        for (p, d) in self.nodes.iter_mut().zip(u.iter()) {
            p[0] += d[0];
            p[1] += d[1];
        }
    }

    /// The second half of a commit: the strain and stress of the shape the nodes now
    /// have (its long-latency part is the polar rotation's root and divisions).
    fn take_new_shape(&mut self) {
        self.strain = self.geometric_strain();
        for i in 0..3 {
            self.stress[i] = (0..3)
                .map(|j| self.elasticity[i][j] * self.strain[j])
                .sum::<f64>();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Moves every node by a 2×2 map about the origin, linearly or exactly alike (the
    /// tests' steps are exact maps, their linear part the same map).
    struct Affine([[f64; 2]; 2]);

    impl NodeMotion for Affine {
        fn node_displacement(&self, _: usize, x: Point) -> Point {
            let m = self.0;
            [
                m[0][0] * x[0] + m[0][1] * x[1] - x[0],
                m[1][0] * x[0] + m[1][1] * x[1] - x[1],
            ]
        }

        fn linear_node_displacement(&self, b: usize, x: Point) -> Point {
            self.node_displacement(b, x)
        }
    }

    fn element() -> Connection {
        let c = [[2.0, 0.5, 0.0], [0.5, 2.0, 0.0], [0.0, 0.0, 0.75]];
        Connection::new([0, 1, 2], [[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]], c)
    }

    /// A triangle turned as a whole has no strain and no stress, however far it turns.
    #[test]
    fn a_turned_connection_is_unstrained() {
        let mut e = element();
        let (s, c) = 0.3_f64.sin_cos();
        for _ in 0..10 {
            e.commit(&Affine([[c, -s], [s, c]]));
        }
        assert!(
            e.strain.iter().chain(&e.stress).all(|v| v.abs() < 1e-14),
            "{e:?}"
        );
    }

    /// The strain is that of the shape. A stretch reads as the stretch; and steps that
    /// shear the element by `I ± [[0, g], [g, 0]]` in turn (a shear at the step's Nyquist
    /// frequency) shrink it by (1 − g²) per pair while their increments sum to zero: the
    /// summed strain stayed zero while the triangle lost 2e-3 of its area, and now it
    /// reads the compression.
    #[test]
    fn a_connection_strain_is_a_function_of_its_shape() {
        let mut e = element();
        e.commit(&Affine([[1.01, 0.0], [0.0, 0.98]]));
        assert!((e.strain[0] - 0.01).abs() < 1e-14 && (e.strain[1] + 0.02).abs() < 1e-14);
        let mut e = element();
        let g = 1e-3;
        for _ in 0..1000 {
            e.commit(&Affine([[1.0, g], [g, 1.0]]));
            e.commit(&Affine([[1.0, -g], [-g, 1.0]]));
        }
        let shrink = (1.0 - g * g).powi(1000) - 1.0;
        for (strain, expected) in e.strain.iter().zip([shrink, shrink, 0.0]) {
            assert!(
                (strain - expected).abs() < 1e-12,
                "{:?}, shrink {shrink:e}",
                e.strain
            );
        }
    }

    /// A group moves its triangles as each triangle's own commit would, to the bit (its
    /// shared nodes' displacements are computed once and handed round).
    #[test]
    fn a_group_commits_its_triangles_as_they_would_alone() {
        let c = [[2.0e9, 0.5e9, 0.0], [0.5e9, 2.0e9, 0.0], [0.0, 0.0, 0.75e9]];
        let n = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.1], [0.0, 0.1]];
        let triangle = |k: [usize; 3]| Connection::new([3; 3], k.map(|i| n[i]), c);
        let mut grouped = vec![
            triangle([0, 1, 2]),
            triangle([0, 2, 3]),
            triangle([0, 1, 3]),
            triangle([1, 2, 3]),
        ];
        let mut alone = grouped.clone();
        let groups = ConnectionGroups::new(&grouped);
        let (s, co) = 0.01_f64.sin_cos();
        for step in [
            Affine([[1.001, 2e-4], [-1e-4, 0.998]]),
            Affine([[co, -s], [s, co]]),
        ] {
            groups.commit(&mut grouped, &step);
            for t in &mut alone {
                t.commit(&step);
            }
        }
        for (g, a) in grouped.iter().zip(&alone) {
            assert_eq!(format!("{g:?}"), format!("{a:?}"));
        }
    }

    /// A gap's four triangles (both diagonal splits of the quadrilateral between two
    /// blocks) are one group of four nodes, and its terms act as the four triangles'
    /// together: the same node forces for any node displacements, to round-off. A fifth
    /// triangle on other nodes starts a group of its own.
    #[test]
    fn a_gaps_four_triangles_act_as_one_element() {
        let c = [[2.0e9, 0.5e9, 0.0], [0.5e9, 2.0e9, 0.0], [0.0, 0.0, 0.75e9]];
        // Nodes 0, 1 on block 3 (a slab's top), 2, 3 on block 5 (a column's foot).
        let n = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.1], [0.0, 0.1]];
        let on = [3, 3, 5, 5];
        let triangle = |k: [usize; 3]| Connection::new(k.map(|i| on[i]), k.map(|i| n[i]), c);
        let mut connections = vec![
            triangle([0, 1, 2]),
            triangle([0, 2, 3]),
            triangle([0, 1, 3]),
            triangle([1, 2, 3]),
            Connection::new([5, 5, 7], [[0.0, 3.0], [0.4, 3.0], [0.2, 3.1]], c),
        ];
        for (i, t) in connections.iter_mut().enumerate() {
            t.stress = [1e5 * i as f64, -2e5, 3e4];
        }
        let groups = ConnectionGroups::new(&connections);
        let mut terms = Vec::new();
        groups.terms_into(&connections, &mut terms, 0);
        assert_eq!(terms.len(), 2);
        assert_eq!(terms[0].nodes().len(), 4);
        let u: Vec<Point> = (0..4)
            .map(|k| [1e-4 * (k as f64 + 1.0), -2e-4 * k as f64])
            .collect();
        let node_of = |p: Point| n.iter().position(|q| *q == p).unwrap();
        let group_u: Vec<Point> = terms[0]
            .nodes()
            .iter()
            .map(|&(_, p)| u[node_of(p)])
            .collect();
        let merged = terms[0].end_forces(&group_u);
        let mut expected = [0.0; 2 * MAX_NODES];
        for t in &connections[..4] {
            let own = t.terms();
            let own_u: Vec<Point> = own.nodes().iter().map(|&(_, p)| u[node_of(p)]).collect();
            let f = own.end_forces(&own_u);
            for (k, &(_, p)) in own.nodes().iter().enumerate() {
                let g = terms[0].nodes().iter().position(|&(_, q)| q == p).unwrap();
                expected[2 * g] += f[2 * k];
                expected[2 * g + 1] += f[2 * k + 1];
            }
        }
        let scale = expected.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (a, b) in merged.iter().zip(&expected) {
            assert!(
                (a - b).abs() < 1e-12 * scale,
                "{merged:?} against {expected:?}"
            );
        }
    }
}
