//! Vertex-edge contacts: detection, persistent state, and the linearised gap and slip.
//!
//! Vertex P1 of block i against edge P2→P3 of block j (counter-clockwise polygons, so the
//! edge's outward normal n̂ is to the right of its direction t̂). The gap (negative when P1
//! penetrates) and the slip along t̂, linearised in the step's unknowns, come from the
//! surface the edge belongs to — the edge itself, or the circle of a dish whose chord it
//! is ([`super::surface`]).

use super::block::{Block, EdgeFrame, Vec6};
use super::judge::ContactState;
use super::surface::{self, SurfaceFrame};
use crate::model::friction::{Friction, FrictionLaw};
use crate::model::geometry::{Point, contains, cross, dot, sub};

pub use super::memory::ContactMemories;

/// Identifies a contact across steps: which vertex touches which edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ContactKey {
    /// Block owning the vertex.
    pub vertex_block: usize,
    /// Vertex index in that block.
    pub vertex: usize,
    /// Block owning the edge.
    pub edge_block: usize,
    /// Edge index (edge k runs from vertex k to vertex k+1).
    pub edge: usize,
}

#[cfg(test)]
impl ContactMemory {
    /// A stuck contact's memory with a unit normal force and no shear, at `gap` (a test
    /// fixture).
    pub(crate) fn stuck_for_test(gap: f64) -> Self {
        Self {
            state: ContactState::Locked,
            shear: 0.0,
            normal_force: 1.0,
            normal_change: 0.0,
            shear_multiplier: 0.0,
            shear_change: 0.0,
            gap,
        }
    }
}

/// Joint properties of a declared contact pair, resolved to numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointProps {
    /// The friction law (asked through [`super::FrictionLaw`]).
    pub friction: Friction,
    /// Normal penalty, N/m.
    pub normal_penalty: f64,
    /// Shear penalty, N/m.
    pub shear_penalty: f64,
    /// Never opens or slides.
    pub bonded: bool,
    /// Steps land on this joint's events (see `ContactDef::locate_events`).
    pub locate_events: bool,
}

/// A declared contact pair between two blocks.
#[derive(Debug, Clone)]
pub struct ContactPair {
    /// The two blocks.
    pub blocks: [usize; 2],
    /// Joint properties.
    pub props: JointProps,
}

/// What a contact remembers from one step to the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactMemory {
    /// State at the end of the last accepted step.
    pub state: ContactState,
    /// Shear spring stretch at the end of the last step, m: free while locked, the yield
    /// stretch ±ρN/p_s while sliding, 0 when open.
    pub shear: f64,
    /// Normal force at the end of the last step, N.
    pub normal_force: f64,
    /// How much the normal force changed over the last step, N: extrapolated, it predicts
    /// this step's normal force for the friction of the first open-close pass.
    pub normal_change: f64,
    /// Augmented Lagrangian: the shear force multiplier (force on the vertex along the
    /// edge tangent), N; while sliding, the friction force, so that a contact that sticks
    /// picks it up continuously.
    pub shear_multiplier: f64,
    /// How much the shear multiplier changed over the last step (while locked), N.
    pub shear_change: f64,
    /// Gap at the end of the last step as that step's linear motion put it, m (the
    /// geometry update departs from it, and the next step's constraint work closes it).
    pub gap: f64,
}

/// A contact during one step: geometry linearised at the step start plus its trial state.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Identity.
    pub key: ContactKey,
    /// Index of the declared pair (joint properties).
    pub pair: usize,
    /// Joint properties (copied for speed).
    pub props: JointProps,
    /// Gap at the step start, m.
    pub gap0: f64,
    /// d(gap)/d(D_i).
    pub gap_i: Vec6,
    /// d(gap)/d(D_j).
    pub gap_j: Vec6,
    /// d(slip)/d(D_i) = T_i(P1)ᵀ t̂.
    pub slip_i: Vec6,
    /// d(slip)/d(D_j) = −T_j(Q)ᵀ t̂.
    pub slip_j: Vec6,
    /// State at the step start.
    pub start_state: ContactState,
    /// Shear spring stretch at the step start, m.
    pub shear0: f64,
    /// Trial state for the current open-close pass.
    pub state: ContactState,
    /// Mass a dashpot on this contact acts against (half the lighter free block: two
    /// contacts usually share a face), kg.
    pub damping_mass: f64,
    /// State changes in the current step's open-close iteration.
    pub flips: u32,
    /// Normal force used for friction in the current pass, N.
    pub friction_normal: f64,
    /// The normal force the previous pass used for friction and the one it found, N,
    /// while the contact kept sliding (for the secant update of the open-close
    /// iteration).
    pub friction_trial: Option<(f64, f64)>,
    /// Sliding friction coefficient used in the current pass (the law's, at the end slip
    /// speed of the previous pass).
    pub sliding_coefficient: f64,
    /// Normal force at the step start (from the contact memory), N.
    pub start_normal: f64,
    /// Change of the normal force over the previous step, N (0 for a new contact).
    pub previous_normal_change: f64,
    /// Tangential slip velocity (vertex relative to edge) at the step start, m/s.
    pub start_slip_velocity: f64,
    /// Tangential slip velocity at the end of the last trial solution, m/s.
    pub end_slip_velocity: f64,
    /// Where in the step (fraction 0..1) the state first changed from the start state in
    /// the open-close iteration; 1 when it did not. Used to land steps on stick-slip events.
    pub event_fraction: f64,
    /// Augmented Lagrangian: normal force multiplier (compressive positive), N, of the
    /// current iterate.
    pub normal_multiplier: f64,
    /// Augmented Lagrangian: shear force multiplier (force on the vertex along t̂), N.
    pub shear_multiplier: f64,
    /// The shear multiplier at the step start.
    pub start_shear_multiplier: f64,
    /// Change of the shear multiplier over the previous step, N.
    pub previous_shear_change: f64,
    /// Contact point (P1) and edge tangent at the step start, for drawing and reports.
    pub point: Point,
    /// Edge unit tangent t̂.
    pub tangent: Point,
    /// Curvature of the surface under the vertex, 1/m (0 on a flat edge; see
    /// [`SurfaceFrame::curvature`]).
    pub curvature: f64,
    /// Where this contact's own memory was last seen in the contact memory: a hint for
    /// [`ContactMemories::get_near`] (checked against the key there, so a stale one only
    /// costs a lookup). 32 bits, as the memory's positions are: with a word here the
    /// contact was 512 bytes, a power of two, and the passes over a wall's contacts read
    /// each field at a stride that maps onto a few cache sets (wall:30 on Kobe 17 %
    /// slower).
    pub memory_slot: u32,
}

impl Contact {
    /// [`Contact::memory_slot`] as the position a lookup takes (`u32::MAX`, no memory
    /// seen, is a position no memory has).
    pub fn memory_hint(&self) -> usize {
        self.memory_slot as usize
    }

    /// Whether the contact started the step closed and carrying a force, and its trial
    /// state opens it.
    pub fn opens_under_load(&self) -> bool {
        self.start_state.is_closed() && self.start_normal > 0.0 && !self.state.is_closed()
    }

    /// Adds to `out` (per block) the generalised forces of a normal force `normal`
    /// (pushing apart) and a shear force `shear` (on the vertex along t̂) at this
    /// contact, along its gradients.
    pub fn add_forces(&self, normal: f64, shear: f64, out: &mut [Vec6]) {
        for (b, gap, slip) in [
            (self.key.vertex_block, &self.gap_i, &self.slip_i),
            (self.key.edge_block, &self.gap_j, &self.slip_j),
        ] {
            for k in 0..6 {
                out[b][k] += normal * gap[k] + shear * slip[k];
            }
        }
    }

    /// Gap at the end of the step for unknowns `di`, `dj`.
    pub fn gap_end(&self, di: &Vec6, dj: &Vec6) -> f64 {
        self.gap0 + dot6(&self.gap_i, di) + dot6(&self.gap_j, dj)
    }

    /// Where in the step (0..1) this contact had an event: the first change of state in
    /// the open-close iteration (for an open contact, its closing in any pass), or, for a
    /// contact that kept sliding, the zero of its slip
    /// velocity (linear over the step) when the velocity reversed but the increment not yet.
    pub fn event_fraction_in_step(&self) -> f64 {
        // An impact found in any pass counts even if the contact ends the iteration open
        // again (it bounced within the step): the step must land on it.
        if self.state != self.start_state || self.start_state == ContactState::Open {
            return self.event_fraction;
        }
        if let ContactState::Sliding { direction } = self.state {
            let (v0, v1) = (
                self.start_slip_velocity * direction,
                self.end_slip_velocity * direction,
            );
            if v0 > 0.0 && v1 < 0.0 {
                return v0 / (v0 - v1);
            }
        }
        1.0
    }

    /// Tangential slip increment for unknowns `di`, `dj`.
    pub fn slip_increment(&self, di: &Vec6, dj: &Vec6) -> f64 {
        dot6(&self.slip_i, di) + dot6(&self.slip_j, dj)
    }
}

/// Dot product of 6-vectors.
#[inline]
pub fn dot6(a: &Vec6, b: &Vec6) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// Axis-aligned bounding box (min, max).
fn aabb(vertices: &[Point]) -> (Point, Point) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in vertices {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// Finds the vertex-edge contacts of all declared pairs at the current geometry and
/// carries over the memory of contacts that existed in the previous step.
///
/// `search` is the distance within which a vertex is a candidate: a vertex farther than
/// that from an edge cannot reach it within one step (the step is limited by the maximum
/// displacement ratio).
pub fn detect(
    blocks: &[Block],
    pairs: &[ContactPair],
    memory: &ContactMemories,
    search: f64,
    out: &mut Vec<Contact>,
) {
    out.clear();
    let mut memory = InOrder { memory, next: 0 };
    for (pair_index, pair) in pairs.iter().enumerate() {
        let [a, b] = pair.blocks;
        let (alo, ahi) = aabb(&blocks[a].vertices);
        let (blo, bhi) = aabb(&blocks[b].vertices);
        if alo[0] > bhi[0] + search
            || blo[0] > ahi[0] + search
            || alo[1] > bhi[1] + search
            || blo[1] > ahi[1] + search
        {
            continue;
        }
        let mut one_way = |vertices: usize, edges: usize, out: &mut Vec<Contact>| {
            detect_one_way(
                blocks,
                vertices,
                edges,
                pair_index,
                pair.props,
                &mut memory,
                search,
                out,
            );
        };
        let first = out.len();
        one_way(a, b, out);
        let split = out.len();
        one_way(b, a, out);
        // A vertex of b that sits on a vertex of a already in contact would double the
        // same physical contact (vertex-vertex); keep the first one. Only this pair's
        // contacts are looked at, so the search stays linear in the number of pairs.
        let tolerance = 1e-9 * (1.0 + search);
        let mut write = split;
        for read in split..out.len() {
            let p = out[read].point;
            let duplicate = out[first..split].iter().any(|k| {
                let d = sub(k.point, p);
                d[0].hypot(d[1]) < tolerance
            });
            if !duplicate {
                // (A contact is large: moved only when an earlier one was dropped.)
                if write != read {
                    out.swap(write, read);
                }
                write += 1;
            }
        }
        out.truncate(write);
    }
}

/// A memory found, and its position in the contact memory.
type Found<'a> = (usize, &'a ContactMemory);

/// The contact memory read in the order it was written: the detection asks for the
/// contacts of the last step in the order it found them then, so the next memory is
/// looked for first where the last one found was followed.
struct InOrder<'a> {
    memory: &'a ContactMemories,
    /// The position after the last memory found.
    next: usize,
}

impl<'a> InOrder<'a> {
    /// The memory of `key` and its position, if it has one.
    fn get(&mut self, key: &ContactKey) -> Option<Found<'a>> {
        let found = self.memory.get_near(key, self.next);
        if let Some((at, _)) = found {
            self.next = at + 1;
        }
        found
    }
}

/// The edge a contact on edge `k` of `block` is known by: an arc's first edge for any of
/// its chords (the contact is with the circle, and keeps its memory however many facets a
/// step crosses: a slider at 1.4 m/s crosses more than one 1.4 mm facet per step), else
/// `k` itself.
fn surface_edge(block: &Block, k: usize) -> usize {
    block.arc_of(k).map_or(k, |a| a.edges[0])
}

/// What the contact `key` remembers from the last step: its own memory, or, for a vertex
/// that moved on to the neighbouring surface of the same block (`block`, the key's edge
/// block), that surface's memory if it was closed — the vertex keeps its state and forces.
/// An arc's neighbours are the edges before its first chord and after its last (the arc
/// is known by its first chord, so a vertex leaving it over its last end, or arriving
/// there, would otherwise not find it).
///
/// `hint`: where the key's own memory is expected (see [`ContactMemories::get_near`]).
pub fn remembered(
    memory: &ContactMemories,
    key: ContactKey,
    hint: usize,
    block: &Block,
) -> Option<ContactMemory> {
    memory
        .get_near(&key, hint)
        .map(|(_, m)| *m)
        .or_else(|| remembered_by_neighbour(memory, key, block))
}

/// The memory of the surface next to the key's edge, if that contact was closed: the
/// fallback of [`remembered`] for a key with no memory of its own.
fn remembered_by_neighbour(
    memory: &ContactMemories,
    key: ContactKey,
    block: &Block,
) -> Option<ContactMemory> {
    let n = block.vertices.len();
    let (first, last) = block
        .arc_of(key.edge)
        .map_or((key.edge, key.edge), |a| (a.edges[0], a.edges[1]));
    [(last + 1) % n, (first + n - 1) % n]
        .iter()
        .find_map(|&other| {
            let edge = surface_edge(block, other);
            memory
                .get(&ContactKey { edge, ..key })
                .copied()
                .filter(|m| m.state.is_closed())
        })
}

#[allow(clippy::too_many_arguments)]
fn detect_one_way(
    blocks: &[Block],
    vb: usize,
    eb: usize,
    pair: usize,
    props: JointProps,
    memory: &mut InOrder,
    search: f64,
    out: &mut Vec<Contact>,
) {
    let vblock = &blocks[vb];
    let eblock = &blocks[eb];
    let (lo, hi) = aabb(&eblock.vertices);
    let nv = vblock.vertices.len();
    let ne = eblock.vertices.len();
    for (vi, &p1) in vblock.vertices.iter().enumerate() {
        if p1[0] < lo[0] - search
            || p1[0] > hi[0] + search
            || p1[1] < lo[1] - search
            || p1[1] > hi[1] + search
        {
            continue;
        }
        let (before, after) = (&vblock.edges[(vi + nv - 1) % nv], &vblock.edges[vi]);
        let (n_prev, n_next) = (before.normal, after.normal);
        // A reflex vertex (the inside of a dish, a notch) cannot be the first point of
        // its block to touch an edge: its own two edges meet the other block first, and
        // the other block's vertices on them are the contacts.
        if cross(before.tangent, after.tangent) < -1e-12 {
            continue;
        }
        // Best candidate edge: smallest |gap|, preferring the edge this vertex touched last.
        let mut best: Option<(ContactKey, f64, Option<Found>)> = None;
        for ek in 0..ne {
            let p2 = eblock.vertices[ek];
            let EdgeFrame {
                tangent: t,
                normal: n,
                length: l,
            } = eblock.edges[ek];
            let w = sub(p1, p2);
            let gap = dot(n, w);
            if gap.abs() > search {
                continue;
            }
            let along = dot(t, w);
            let tol = 1e-9 * l;
            if along < -tol || along > l + tol {
                continue;
            }
            // The vertex must present a face to the edge: one of its two sides has to be
            // turned against the edge's outward normal.
            if dot(n, n_prev) > -0.2 && dot(n, n_next) > -0.2 {
                continue;
            }
            // A negative gap is a penetration only if the vertex is inside the block: a
            // vertex above a thin block is "behind" its far edge too (the slab's top corner
            // against the ground's bottom edge, a brick's corner against the far side of
            // its neighbour). Shallow penetrations (the penalty springs' ~1e-8 of the
            // size) are accepted without the test, which is ambiguous on the boundary.
            // (Tested last: it walks the whole polygon, the tests above are a few flops;
            // a wall's step spent 4 % of its instructions here.)
            if gap < -1e-3 * search && !contains(&eblock.vertices, p1) {
                continue;
            }
            let key = ContactKey {
                vertex_block: vb,
                vertex: vi,
                edge_block: eb,
                edge: surface_edge(eblock, ek),
            };
            let own = memory.get(&key);
            let known = own.is_some();
            let better = match best {
                None => true,
                Some((_, g, k)) => {
                    let k = k.is_some();
                    (known && !k) || (known == k && gap.abs() < g.abs())
                }
            };
            if better {
                best = Some((key, gap, own));
            }
        }
        let Some((key, _, own)) = best else { continue };
        // The candidates' lookups already found the key's own memory, if any.
        let mem = own
            .map(|(_, m)| *m)
            .or_else(|| remembered_by_neighbour(memory.memory, key, eblock));
        let mut contact = linearise(vblock, eblock, key, pair, props, mem);
        contact.memory_slot = own.map_or(u32::MAX, |(at, _)| at as u32);
        out.push(contact);
    }
}

/// Builds the linearised contact geometry at the step start.
fn linearise(
    vblock: &Block,
    eblock: &Block,
    key: ContactKey,
    pair: usize,
    props: JointProps,
    mem: Option<ContactMemory>,
) -> Contact {
    let p1 = vblock.vertices[key.vertex];
    let SurfaceFrame {
        gap0,
        gap_i,
        gap_j,
        slip_i,
        slip_j,
        tangent: t,
        curvature,
    } = surface::frame(vblock, eblock, p1, key.edge);
    let shear_change = mem.map_or(0.0, |m| m.shear_change);
    let (start_state, shear0, normal, normal_change, shear_multiplier) = match mem {
        // The shear spring is elastic-perfectly-plastic: while sliding it stays stretched
        // at its yield value (force ρN), so a contact that stops picks up the friction
        // force continuously instead of dropping it to zero and ringing.
        Some(m) => (
            m.state,
            m.shear,
            m.normal_force,
            m.normal_change,
            m.shear_multiplier,
        ),
        // Touching or overlapping when first seen: closed and stuck (blocks placed on each
        // other start in contact); otherwise open.
        None if gap0 <= 0.0 => (
            ContactState::Locked,
            0.0,
            props.normal_penalty * (-gap0),
            0.0,
            0.0,
        ),
        None => (ContactState::Open, 0.0, 0.0, 0.0, 0.0),
    };
    let start_state = if props.bonded {
        ContactState::Locked
    } else {
        start_state
    };
    let start_slip_velocity = dot6(&slip_i, &vblock.velocity) + dot6(&slip_j, &eblock.velocity);
    Contact {
        key,
        pair,
        props,
        gap0,
        gap_i,
        gap_j,
        slip_i,
        slip_j,
        start_state,
        shear0,
        state: start_state,
        friction_normal: normal,
        friction_trial: None,
        sliding_coefficient: props.friction.sliding_coefficient(start_slip_velocity),
        start_normal: normal,
        previous_normal_change: normal_change,
        damping_mass: {
            use super::block::BlockRole::Free;
            let (mi, mj) = (vblock.total_mass(), eblock.total_mass());
            0.5 * match (vblock.role == Free, eblock.role == Free) {
                (true, false) => mi,
                (false, true) => mj,
                _ => mi.min(mj),
            }
        },
        flips: 0,
        start_slip_velocity,
        end_slip_velocity: start_slip_velocity,
        event_fraction: 1.0,
        normal_multiplier: normal,
        shear_multiplier,
        start_shear_multiplier: shear_multiplier,
        previous_shear_change: shear_change,
        point: p1,
        tangent: t,
        curvature,
        memory_slot: u32::MAX,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dda::block::point_displacement;
    use crate::model::scene::ArcDef;

    fn block(v: Vec<Point>) -> Block {
        Block::unit_for_tests(v)
    }

    /// A vertex that leaves a dish's arc over either end, or arrives on it there, keeps
    /// the memory of the surface it came from (the arc is known by its first chord; over
    /// its last end the neighbour lookup once missed it).
    #[test]
    fn a_vertex_keeps_its_memory_across_either_end_of_an_arc() {
        // A dish: chords 1..=3 of a circle of radius 2 about (0, 2), between two flats.
        let r = 2.0_f64;
        let at = |deg: f64| {
            let a = deg.to_radians();
            [r * a.sin(), r - r * a.cos()]
        };
        // Counter-clockwise: the chords are edges 2..=4, the flats beside them 1 and 5.
        let mut dish = block(vec![
            [3.0, -1.0],
            [3.0, at(30.0)[1]],
            at(30.0),
            at(10.0),
            at(-10.0),
            at(-30.0),
            [-3.0, at(-30.0)[1]],
            [-3.0, -1.0],
        ]);
        dish.arcs = vec![ArcDef {
            center: [0.0, r],
            radius: r,
            edges: [2, 4],
        }];
        let key = |edge| ContactKey {
            vertex_block: 1,
            vertex: 0,
            edge_block: 0,
            edge,
        };
        let closed = ContactMemory::stuck_for_test(0.0);
        for (from, to) in [(2, 1), (2, 5), (1, 2), (5, 2)] {
            let mut memory = ContactMemories::default();
            memory.insert(key(from), closed);
            assert_eq!(
                remembered(&memory, key(to), 0, &dish),
                Some(closed),
                "from edge {from} to edge {to}"
            );
        }
        // Not from a surface two edges away.
        let mut memory = ContactMemories::default();
        memory.insert(key(6), closed);
        assert_eq!(remembered(&memory, key(2), 0, &dish), None);
    }

    /// The linearised gap matches the exact gap after small motions of both blocks.
    #[test]
    fn linearised_gap_is_first_order_accurate() {
        let i = block(vec![[0.0, 0.1], [1.0, 0.1], [1.0, 1.0], [0.0, 1.0]]);
        let j = block(vec![[-2.0, -1.0], [3.0, -1.2], [3.0, 0.0], [-2.0, 0.05]]);
        let props = JointProps {
            friction: Friction::Coulomb(0.3),
            normal_penalty: 1.0,
            shear_penalty: 1.0,
            bonded: false,
            locate_events: true,
        };
        let c = linearise(
            &i,
            &j,
            ContactKey {
                vertex_block: 0,
                vertex: 0,
                edge_block: 1,
                edge: 2,
            },
            0,
            props,
            None,
        );
        let di = [1e-4, -2e-4, 3e-4, 1e-4, -1e-4, 2e-4];
        let dj = [-1e-4, 1e-4, -2e-4, 2e-4, 1e-4, -1e-4];
        let mv = |b: &Block, k: usize, d: &Vec6| {
            let p = b.vertices[k];
            let u = point_displacement(b.moments.centroid, p, d);
            [p[0] + u[0], p[1] + u[1]]
        };
        let p1 = mv(&i, 0, &di);
        let p2 = mv(&j, 2, &dj);
        let p3 = mv(&j, 3, &dj);
        let e = sub(p3, p2);
        // DDA linearises the signed area and keeps the edge length of the step start (the
        // length change only matters times the gap, which is ~0 for a closed contact).
        let l0 = {
            let e0 = sub(j.vertices[3], j.vertices[2]);
            e0[0].hypot(e0[1])
        };
        let exact = cross(sub(p1, p2), e) / l0;
        let lin = c.gap_end(&di, &dj);
        // Second-order terms are ~|D|²·size ≈ 1e-6 m.
        assert!((exact - lin).abs() < 2e-6, "exact {exact} vs linear {lin}");
        assert!((c.gap0 - 0.1 + 0.05 * 2.0 / 5.0).abs() < 0.02);
    }
}
