//! The DDA model (`Dda`): its state, construction and accessors. The work of a step is in
//! the submodules, one job each.

mod analysis;
mod damping;
mod events;
mod iteration;
mod ledger;
mod mass;
mod stepping;
mod system;

use std::sync::Arc;

use iteration::Unsettled;

use nalgebra::DVector;
use serde::Serialize;
use smallvec::SmallVec;

use super::assembly::{DofMap, System};
use super::block::{
    Block, BlockRole, StepMap, Vec6, displacement_with_map, point_displacement, t_transpose_times,
};
use super::contact::{
    self, Contact, ContactMemories, ContactMemory, ContactPair, JointProps, dot6,
};
use super::energy::EnergyTerms;
use super::joints::{
    Bolt, Connection, ConnectionGroups, ElementTerms, FixedPoint, MAX_NODES, NodeMotion,
};
use super::judge::{ContactState, JudgeInput, judge};
use super::linear::{BlockPattern, LinearSolver, SolveError, TINY_LIMIT};
use super::params::{AlphaCoefficients, SolverParams};
use super::surface;
use crate::ground_motion::GroundMotion;
use crate::model::friction::FrictionLaw;
use crate::model::geometry::{self, Point};
use crate::model::scene::{FixedDirection, GroundKind, Scene};
use crate::{Error, Result};

/// Per-block values of one step (increments, velocities, centroids), inline for models of
/// up to four blocks: a two-block step is a few microseconds, and the heap traffic of a
/// handful of small vectors per step was 4 % of it. Larger models spill to the heap.
type PerBlock<T> = SmallVec<[T; 4]>;

/// The per-block vector of `value(b)` for `n` blocks. Up to four are written straight
/// into the inline buffer: `collect` pushes one at a time, testing the capacity and where
/// the values are stored at each push, which cost more than the values of a two-block
/// step's vectors themselves.
fn per_block<T: Copy + Default>(n: usize, mut value: impl FnMut(usize) -> T) -> PerBlock<T> {
    if n <= 4 {
        let values: [T; 4] = std::array::from_fn(|b| if b < n { value(b) } else { T::default() });
        SmallVec::from_buf_and_len(values, n)
    } else {
        // Collected as a `Vec` (one allocation of the exact size, no test per value)
        // and handed over: `SmallVec`'s own `collect` grows and tests at each push.
        SmallVec::from_vec((0..n).map(value).collect())
    }
}

/// State changes of one contact within one step after which its state is kept.
const MAX_FLIPS_PER_STEP: u32 = 4;

/// A constant point load carried by a block.
#[derive(Debug, Clone)]
struct PointLoad {
    block: usize,
    point: Point,
    force: Point,
}

/// What happened in one accepted step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StepReport {
    /// Time at the end of the step, s.
    pub time: f64,
    /// Step size actually used, s.
    pub dt: f64,
    /// Open-close passes in the accepted attempt.
    pub passes: usize,
    /// Δt cuts before the step was accepted.
    pub cuts: usize,
    /// Contacts found by the search.
    pub contacts: usize,
    /// Closed contacts.
    pub closed: usize,
    /// Sliding contacts.
    pub sliding: usize,
    /// Largest penetration of a closed contact / structure size.
    pub max_penetration_ratio: f64,
    /// Largest vertex displacement relative to the ground / structure size.
    pub max_displacement_ratio: f64,
    /// Energy terms after the step.
    pub energy: EnergyTerms,
}

/// Natural frequencies and mode shapes (see [`Dda::modes`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Frequencies, Hz, ascending.
    pub frequencies_hz: Vec<f64>,
    /// Mode shapes: per mode, per block, the six unknowns (M-normalised).
    pub shapes: Vec<Vec<Vec6>>,
}

/// Δt cuts by what forced them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct CutReasons {
    /// At the last of [`SolverParams::max_open_close_passes`] passes a contact, held in
    /// its state after flipping within the step, contradicted its gap (open while
    /// penetrating, or closed while apart) by more than the force tolerance.
    pub contradicted: u64,
    /// At the last pass a contact still changed state (opened or closed; in the static
    /// settle also stuck ↔ sliding).
    pub states_changing: u64,
    /// At the last pass every state held, but a sliding contact's friction force (its
    /// normal force or coefficient) still moved by more than the tolerance.
    pub friction_changing: u64,
    /// A vertex moved more than [`SolverParams::max_displacement_ratio`] of the structure
    /// in one step.
    pub too_far: u64,
}

impl CutReasons {
    /// The cuts because the open-close iteration did not settle (all but `too_far`).
    pub fn not_settled(&self) -> u64 {
        self.contradicted + self.states_changing + self.friction_changing
    }

    /// All cuts.
    pub fn total(&self) -> u64 {
        self.not_settled() + self.too_far
    }
}

/// Totals over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct RunCounters {
    /// Accepted steps.
    pub steps: u64,
    /// Open-close passes in accepted attempts.
    pub passes: u64,
    /// Δt cuts (by what forced them in [`RunCounters::cut_reasons`]).
    pub cuts: u64,
    /// What forced the Δt cuts.
    pub cut_reasons: CutReasons,
    /// Largest penetration / structure size seen.
    pub max_penetration_ratio: f64,
    /// Largest |energy residual| relative to the energy scale seen so far.
    pub max_energy_residual_rel: f64,
    /// Linear systems solved (one per open-close pass).
    pub linear_solves: u64,
    /// Numeric factorisations of the system matrix (the rest were solved by conjugate
    /// gradients preconditioned with a kept factor).
    pub factorizations: u64,
    /// Conjugate-gradient iterations with a kept factor.
    pub cg_iterations: u64,
    /// Augmented-Lagrangian solves (one per multiplier update).
    pub constraint_iterations: u64,
}

/// Which linear problem an iteration solves.
#[derive(Debug, Clone, Copy)]
enum Mode {
    /// A dynamic step of size dt.
    Dynamic { dt: f64 },
    /// Static equilibrium under gravity and loads, with every joint's friction coefficient
    /// replaced by `friction` when given (0: free to slip, ∞: held stuck).
    Static {
        /// Friction coefficient used instead of the joints' own.
        friction: Option<f64>,
    },
    /// The bare stiffness, for modal analysis.
    Modal,
}

/// Node motion of the current step (for moving joint nodes with their blocks).
struct StepMotion<'a> {
    centroids: &'a [Point],
    increments: &'a [Vec6],
    /// Each block's step map (exact or linear). Computed once per block, not per node
    /// (a frame has ~150 nodes).
    maps: &'a [StepMap],
}

impl NodeMotion for StepMotion<'_> {
    fn node_displacement(&self, b: usize, x: Point) -> Point {
        displacement_with_map(self.centroids[b], x, &self.increments[b], &self.maps[b])
    }

    fn linear_node_displacement(&self, b: usize, x: Point) -> Point {
        super::block::point_displacement(self.centroids[b], x, &self.increments[b])
    }
}

/// The DDA model of a scene, advancing in time.
#[derive(Debug, Clone)]
pub struct Dda {
    blocks: Vec<Block>,
    ground: usize,
    dofs: DofMap,
    /// Which blocks can couple in the system matrix (fixed for the run).
    pattern: Arc<BlockPattern>,
    /// Cholesky solver keeping its symbolic analysis and last factor.
    linear: LinearSolver,
    /// The system of the current open-close pass (kept to reuse its storage).
    pass_system: Option<System>,
    /// The step's system without contacts (kept to reuse its storage).
    base_system: Option<System>,
    /// The joints' terms (kept to reuse their storage).
    elements: Vec<ElementTerms>,
    /// `elements` are the terms of the joints as they are now: the rebalance after a step
    /// computes them at the new geometry, and the next step (or its cut retries) reuses
    /// them instead of computing them again. Only `commit_geometry` moves the joints.
    elements_current: bool,
    pairs: Vec<ContactPair>,
    contacts: Vec<Contact>,
    /// A second contact list, for the contacts of the geometry after a step while the
    /// step's own are still read (swapped, not copied).
    spare_contacts: Vec<Contact>,
    /// `spare_contacts` are the contacts of the current geometry, found by the rebalance
    /// after the last step with its memory and velocities, their penalties scaled for
    /// the integrator's β held here: the next step takes them instead of searching again
    /// (the search is a sixth of a large wall's step). Anything that changes the memory,
    /// the geometry or the velocities before that step drops it.
    detection_for_next_step: Option<f64>,
    memory: ContactMemories,
    bolts: Vec<Bolt>,
    fixed: Vec<FixedPoint>,
    connections: Vec<Connection>,
    /// Which connection triangles are assembled together (found once from the scene).
    connection_groups: ConnectionGroups,
    loads: Vec<PointLoad>,
    motion: Option<GroundMotion>,
    /// The vertical ground motion (up positive), if the ground also shakes vertically.
    vertical: Option<GroundMotion>,
    /// The frame's acceleration at the last two times a step kept it for (see
    /// [`Dda::frame_accel`]).
    frame_accel_memo: FrameAccelMemo,
    /// Rayleigh damping of the structure and its base slab's block index.
    rayleigh: Option<(super::rayleigh::RayleighDamping, usize)>,
    gravity: f64,
    params: SolverParams,
    coeffs: AlphaCoefficients,
    time: f64,
    dt_current: f64,
    structure_size: f64,
    search_distance: f64,
    energy: EnergyTerms,
    stored_reference: f64,
    energy_scale: f64,
    counters: RunCounters,
    last: StepReport,
    /// How the next step restarts the integrator after a contact event (if at all).
    restart: Restart,
    /// When the last step was landed on an event.
    last_landing: f64,
    /// The largest vertex displacement of the last accepted step over the structure's
    /// size: below the nominal step, the next one grows no further than the limit allows
    /// at that motion (see `grown_step`).
    accepted_displacement_ratio: f64,
    /// How many times the constraint penalties of the step being iterated exceed those
    /// of a nominal step (see `Dda::stiffen_constraints_for`).
    penalty_boost: f64,
    /// The contacts whose impacts steps were landed on within the last nominal step, and
    /// when (see `step_with_current_scheme`).
    recent_impacts: Vec<(contact::ContactKey, f64)>,
    /// The states contacts take at the event a shortened step is landed on.
    pending_events: Vec<(contact::ContactKey, ContactState)>,
    /// The stored accelerations are not yet those of the forces (a model that starts
    /// out of equilibrium): the first event resolution computes them.
    initial_accel_pending: bool,
}

/// Which state of the blocks a projection acts on.
#[derive(Clone, Copy)]
enum Field {
    Velocity,
    Response,
}

impl Field {
    fn of(self, b: &Block) -> Vec6 {
        match self {
            Field::Velocity => b.velocity,
            Field::Response => b.response_accel,
        }
    }

    fn of_mut(self, b: &mut Block) -> &mut Vec6 {
        match self {
            Field::Velocity => &mut b.velocity,
            Field::Response => &mut b.response_accel,
        }
    }
}

/// How a step restarts the time integrator after a contact event.
///
/// At an event the acceleration jumps (a raft that stops or reverses, a corner that hits
/// the ground); a second-order scheme carries the old acceleration into the new step and
/// misjudges the contact right at the event. A restart takes the step with a scheme that
/// does not use the old acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Restart {
    /// No event: the chosen integrator.
    None,
    /// A stick-slip event: the classic scheme (β = ½, γ = 1), whose end-of-step state does
    /// not depend on the old acceleration.
    Event,
    /// A contact closes (an impact): backward Euler on the velocities (v₁ = v₀ + Δt a₁,
    /// D = Δt v₁), which brings the approach velocity of the hitting vertex to zero within
    /// the step — a plastic impact, as of a rigid block on rigid ground (and, for a
    /// rocking block, exactly Housner's impact: angular momentum about the hitting corner
    /// is kept). The classic scheme would instead reverse the approach velocity (an elastic
    /// bounce), and the chosen scheme would add energy with the impulse's acceleration.
    /// The step after it restarts with [`Restart::AfterImpact`] to flush the impulse.
    Impact,
    /// The step after an impact: the classic scheme, like [`Restart::Event`]; the energy
    /// it removes (the ringing of the springs and blocks just hit) still counts as the
    /// impact's loss.
    AfterImpact,
}

impl Dda {
    /// Builds the model of `scene` driven by `motion` (None: gravity only).
    ///
    /// With `params.initial_equilibrium` the model first settles statically under gravity,
    /// so the dynamic run starts at rest with the penalty springs already carrying the
    /// weight.
    pub fn new(scene: &Scene, motion: Option<GroundMotion>, params: SolverParams) -> Result<Self> {
        scene.validate()?;
        params.validate()?;
        let ground = scene.block_index(&scene.ground.block)?;
        let mut blocks = Vec::with_capacity(scene.blocks.len());
        for (i, b) in scene.blocks.iter().enumerate() {
            let role = match (i == ground, scene.ground.kind) {
                (false, _) => BlockRole::Free,
                (true, GroundKind::Prescribed) => BlockRole::PrescribedGround,
                (true, GroundKind::LargeMass) => BlockRole::LargeMassGround,
            };
            let mut block = Block::new(&b.name, b.vertices.clone(), b.material, role)?;
            block.rigid = b.rigid;
            block.arcs = b.arcs.clone();
            blocks.push(block);
        }
        let structure: Vec<Point> = blocks
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != ground)
            .flat_map(|(_, b)| b.vertices.iter().copied())
            .collect();
        let structure_size = geometry::bounding_size(&structure);
        let structure_mass: f64 = blocks
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != ground)
            .map(|(_, b)| b.total_mass())
            .sum();

        let mut fixed = Vec::new();
        if scene.ground.kind == GroundKind::LargeMass {
            // The paper's ground: mass ratio × the structure, on vertical rollers at its two
            // lowest extreme corners (free to move horizontally, no rotation or bounce).
            let g = &mut blocks[ground];
            let target = scene.ground.mass_ratio * structure_mass;
            g.material.density = target / g.rest_area;
            g.mass = g.current_mass_matrix();
            let left = g
                .vertices
                .iter()
                .copied()
                .fold([f64::INFINITY, 0.0], |m, p| if p[0] < m[0] { p } else { m });
            let right = g
                .vertices
                .iter()
                .copied()
                .fold(
                    [f64::NEG_INFINITY, 0.0],
                    |m, p| if p[0] > m[0] { p } else { m },
                );
            let penalty = 100.0 * g.material.youngs_modulus;
            for p in [left, right] {
                fixed.push(FixedPoint {
                    block: ground,
                    point: p,
                    anchor: p,
                    direction: FixedDirection::Y,
                    penalty,
                });
            }
        }
        for f in &scene.fixed_points {
            let b = scene.block_index(&f.block)?;
            let penalty = f
                .penalty
                .unwrap_or(100.0 * blocks[b].material.youngs_modulus);
            fixed.push(FixedPoint {
                block: b,
                point: f.point,
                anchor: f.point,
                direction: f.direction,
                penalty,
            });
        }

        let mut pairs = Vec::new();
        for c in &scene.contacts {
            let a = scene.block_index(&c.blocks[0])?;
            let b = scene.block_index(&c.blocks[1])?;
            let e = blocks[a]
                .material
                .youngs_modulus
                .max(blocks[b].material.youngs_modulus);
            let normal = c.normal_penalty.unwrap_or(100.0 * e);
            let shear = c.shear_penalty.unwrap_or(normal / 2.5);
            pairs.push(ContactPair {
                blocks: [a, b],
                props: JointProps {
                    friction: c.friction,
                    normal_penalty: normal,
                    shear_penalty: shear,
                    bonded: c.bonded,
                    locate_events: c.locate_events,
                },
            });
        }
        let mut bolts = Vec::new();
        for b in &scene.bolts {
            let i = scene.block_index(&b.blocks[0])?;
            let j = scene.block_index(&b.blocks[1])?;
            bolts.push(Bolt {
                name: b.name.clone(),
                blocks: [i, j],
                points: b.points,
                rest: geometry::sub(b.points[1], b.points[0]),
                stiffness: b.stiffness,
                kind: b.kind,
                damping: b.damping,
            });
        }
        let mut connections = Vec::new();
        for c in &scene.connections {
            let mut owners = [0; 3];
            for k in 0..3 {
                owners[k] = scene.block_index(&c.nodes[k].block)?;
            }
            connections.push(Connection::new(
                owners,
                [c.nodes[0].point, c.nodes[1].point, c.nodes[2].point],
                c.material.elasticity(),
            ));
        }
        let mut loads = Vec::new();
        for l in &scene.point_loads {
            loads.push(PointLoad {
                block: scene.block_index(&l.block)?,
                point: l.point,
                force: l.force,
            });
        }
        let is_free: Vec<bool> = blocks
            .iter()
            .map(|b| b.role != BlockRole::PrescribedGround)
            .collect();
        let dofs = DofMap::new(
            &is_free,
            blocks.iter().map(Block::moving_unknowns).collect(),
        );
        let pattern = Arc::new(coupling_pattern(
            &dofs,
            &pairs,
            &bolts,
            &fixed,
            &connections,
            None,
        ));
        let linear = analysed(&pattern)?;
        let mut model = Self {
            blocks,
            ground,
            dofs,
            pattern,
            linear,
            pass_system: None,
            base_system: None,
            elements: Vec::new(),
            elements_current: false,
            pairs,
            contacts: Vec::new(),
            spare_contacts: Vec::new(),
            detection_for_next_step: None,
            memory: ContactMemories::default(),
            bolts,
            fixed,
            connection_groups: ConnectionGroups::new(&connections),
            connections,
            loads,
            motion,
            vertical: None,
            frame_accel_memo: FrameAccelMemo::default(),
            rayleigh: None,
            gravity: scene.gravity,
            coeffs: params.integrator.coefficients(),
            dt_current: params.dt,
            search_distance: 2.5 * params.max_displacement_ratio * structure_size,
            params,
            time: 0.0,
            structure_size,
            energy: EnergyTerms::default(),
            stored_reference: 0.0,
            energy_scale: 0.0,
            counters: RunCounters::default(),
            last: StepReport::default(),
            restart: Restart::None,
            last_landing: f64::NEG_INFINITY,
            accepted_displacement_ratio: 0.0,
            penalty_boost: 1.0,
            recent_impacts: Vec::new(),
            pending_events: Vec::new(),
            initial_accel_pending: false,
        };
        model.check_initial_overlap()?;
        if model.params.initial_equilibrium {
            model.settle()?;
        } else {
            // The stored accelerations (zero) are not those of the initial forces: the
            // first step restarts, so that it does not depend on them.
            model.restart = Restart::Event;
            model.initial_accel_pending = true;
        }
        model.reset_reference();
        Ok(model)
    }

    /// Drops the contacts the rebalance found for the next step: whatever changes the
    /// contact memory, the geometry or the velocities calls this, as the next step must
    /// then search again.
    pub(super) fn forget_next_step_detection(&mut self) {
        self.detection_for_next_step = None;
    }

    /// Puts back a contact memory saved earlier (and so forgets the next step's contacts).
    pub(super) fn restore_memory(&mut self, memory: ContactMemories) {
        self.forget_next_step_detection();
        self.memory = memory;
    }

    /// Finds the contacts of the current geometry (carrying over the memory of the last
    /// step's), or takes those the rebalance after the last step found at this very
    /// geometry (see `detection_for_next_step`).
    fn detect_contacts(&mut self) {
        self.penalty_boost = 1.0;
        if self.detection_for_next_step.take() == Some(self.coeffs.beta) {
            std::mem::swap(&mut self.contacts, &mut self.spare_contacts);
            return;
        }
        contact::detect(
            &self.blocks,
            &self.pairs,
            &self.memory,
            self.search_distance,
            &mut self.contacts,
        );
        if self.augmented() {
            self.scale_constraint_penalties();
        }
    }

    /// Raises the constraint penalties of a step of `dt` shorter than the nominal one by
    /// Δt_nominal/Δt. At the penalties of a nominal step, each multiplier update of a
    /// step cut to 1e-8 s closed a millionth of the violation (the inertia the contacts
    /// see grows as 1/Δt²), the updates ran out, and the normal force crept up by the
    /// same amount in every open-close pass, which then never settled (a toppling
    /// block's grazing corner; the cuts made it worse). Raised as 1/Δt, an update still
    /// closes a tenth of it there, while the multipliers' round-off (the penalty times
    /// the gaps' round-off) stays as small against the step's forces (which grow as
    /// 1/Δt) as in a nominal step: raised as 1/Δt², a bonded slider's contacts flipped on
    /// that noise. The judge still weighs the multipliers against the nominal penalty,
    /// so that a contact opens at the same tension.
    pub(super) fn stiffen_constraints_for(&mut self, dt: f64) {
        if !self.augmented() || dt >= self.params.dt {
            return;
        }
        let boost = self.params.dt / dt;
        for c in &mut self.contacts {
            c.props.normal_penalty *= boost;
            c.props.shear_penalty *= boost;
        }
        self.penalty_boost = boost;
    }

    /// With the augmented Lagrangian the penalties only set how fast the multipliers
    /// converge: each iteration shrinks the constraint violation by about k/(k + p), k
    /// the stiffness the contact sees (inertia M/(βΔt²) or block elasticity). They are
    /// raised to 1e4 times that, so that a few iterations reach round-off, yet not so
    /// far that the factorisation loses the soft directions (1e-16 · p/k).
    fn scale_constraint_penalties(&mut self) {
        const FACTOR: f64 = 1e4;
        let mass_factor = self.inertia_stiffness_factor();
        let stiffness = |b: &Block| {
            if b.role == BlockRole::PrescribedGround {
                0.0
            } else {
                (mass_factor * b.total_mass()).max(b.material.youngs_modulus)
            }
        };
        for c in &mut self.contacts {
            let k = stiffness(&self.blocks[c.key.vertex_block])
                .max(stiffness(&self.blocks[c.key.edge_block]));
            c.props.normal_penalty = c.props.normal_penalty.max(FACTOR * k);
            c.props.shear_penalty = c.props.normal_penalty;
        }
    }

    /// The stiffness a unit mass shows over a full step, 1/(βΔt²): what the constraint
    /// penalties are measured against.
    fn inertia_stiffness_factor(&self) -> f64 {
        1.0 / (self.coeffs.beta * self.params.dt * self.params.dt)
    }

    /// Starts the friction of each closed contact from its normal force extrapolated over
    /// this step of `dt` (rather than the force at the step start): the open-close
    /// iteration repeats a pass until the friction force uses the normal force the pass
    /// finds, and a sliding frame's normal forces change by more than that tolerance
    /// (1e-4) in most steps. The prediction is O(Δt²) close and saves the extra pass
    /// (three-storey frame on El Centro: 1.40 passes per step before, 1.02 with it).
    fn predict_friction_normals(&mut self, dt: f64) {
        let previous_dt = self.last.dt;
        if previous_dt <= 0.0 {
            return;
        }
        let augmented = self.augmented();
        for c in &mut self.contacts {
            if c.start_state.is_closed() {
                let predicted = c.start_normal + c.previous_normal_change * dt / previous_dt;
                c.friction_normal = predicted.max(0.0);
                // The multipliers start from the same prediction: the first solve then
                // misses the constraint by O(Δt²) of the force, not O(Δt).
                if augmented {
                    c.normal_multiplier = predicted;
                    if c.start_state == ContactState::Locked {
                        c.shear_multiplier =
                            c.start_shear_multiplier + c.previous_shear_change * dt / previous_dt;
                    }
                }
            }
        }
    }

    /// Takes the frames of contacts on a curved surface (a dish) again, about the middle
    /// of the slip this step of `dt` is expected to make (the slip speed at its start
    /// times Δt): the vertex then moves on a chord square to the normal it is held along,
    /// as it does on the circle (see [`crate::dda::surface`]). The prediction's error is
    /// O(Δt²) of the slip, and so is the turn of the normal it leaves. Only a contact that
    /// starts the step sliding is expected to slip: a stuck one's slip speed is round-off,
    /// and turning its frame by it fed back into it (a bonded slider's frame turned by
    /// radians within 50 steps, through the two corners' self-equilibrated multipliers).
    fn follow_curvature(&mut self, dt: f64) {
        let blocks = &self.blocks;
        for c in &mut self.contacts {
            if c.curvature == 0.0 || !matches!(c.start_state, ContactState::Sliding { .. }) {
                continue;
            }
            let ahead = 0.5 * c.start_slip_velocity * dt;
            let f = surface::frame_ahead(
                &blocks[c.key.vertex_block],
                &blocks[c.key.edge_block],
                c.point,
                c.key.edge,
                ahead,
            );
            (c.gap_i, c.gap_j, c.slip_i, c.slip_j) = (f.gap_i, f.gap_j, f.slip_i, f.slip_j);
        }
    }

    /// Refuses a scene whose blocks overlap at the start by more than a rounding error of
    /// the geometry: the penalty springs would throw them apart with an energy the scene
    /// never had (a vertex 1 cm inside a block on a 1e12 N/m spring stores 50 MJ).
    fn check_initial_overlap(&mut self) -> Result<()> {
        let tolerance = 1e-6 * self.structure_size;
        self.detect_contacts();
        let worst = self
            .contacts
            .iter()
            .filter(|c| !c.props.bonded)
            .min_by(|a, b| a.gap0.total_cmp(&b.gap0));
        match worst {
            Some(c) if c.gap0 < -tolerance => Err(Error::Scene(format!(
                "blocks overlap at the start: vertex {} of block '{}' at ({:.6}, {:.6}) lies \
                 {:.3e} m inside block '{}' (edge {}); move the blocks apart so that they only \
                 touch",
                c.key.vertex,
                self.blocks[c.key.vertex_block].name,
                c.point[0],
                c.point[1],
                -c.gap0,
                self.blocks[c.key.edge_block].name,
                c.key.edge
            ))),
            _ => Ok(()),
        }
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The blocks in scene order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Index of the ground block.
    pub fn ground(&self) -> usize {
        self.ground
    }

    /// Contacts of the last step (geometry at its start, state at its end).
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// The forces a contact of the last step carries: (normal force, compressive
    /// positive; tangential pull, N — the force the stick resists or friction opposes,
    /// positive along the edge tangent).
    pub fn contact_force(&self, c: &Contact) -> (f64, f64) {
        let normal = if !c.state.is_closed() {
            0.0
        } else if self.augmented() {
            c.normal_multiplier
        } else {
            c.friction_normal
        };
        let tangential = match c.state {
            ContactState::Open => 0.0,
            ContactState::Locked if self.augmented() => -c.shear_multiplier,
            ContactState::Locked => c.props.shear_penalty * c.shear0,
            ContactState::Sliding { direction } => {
                direction * c.sliding_coefficient * c.friction_normal
            }
        };
        (normal, tangential)
    }

    /// Bolts with their current end points.
    pub fn bolts(&self) -> &[Bolt] {
        &self.bolts
    }

    /// Connection elements with their current nodes.
    pub fn connections(&self) -> &[Connection] {
        &self.connections
    }

    /// Energy terms now.
    pub fn energy(&self) -> EnergyTerms {
        self.energy
    }

    /// Number of unknowns of the system (6 per free block).
    pub fn unknowns(&self) -> usize {
        self.dofs.n
    }

    /// Run totals.
    pub fn counters(&self) -> RunCounters {
        let linear = self.linear.stats();
        RunCounters {
            linear_solves: linear.solves,
            factorizations: linear.factorizations,
            cg_iterations: linear.iterations,
            ..self.counters
        }
    }

    /// The last step's report.
    pub fn last_report(&self) -> StepReport {
        self.last
    }

    /// Solver parameters.
    pub fn params(&self) -> &SolverParams {
        &self.params
    }

    /// Size of the structure (bounding diagonal of all blocks but the ground), m.
    pub fn structure_size(&self) -> f64 {
        self.structure_size
    }

    /// Index of a block by name.
    pub fn block_index(&self, name: &str) -> Result<usize> {
        self.blocks
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| Error::Scene(format!("unknown block '{name}'")))
    }

    /// Horizontal displacement of block `b`'s centroid relative to the ground's, m (the
    /// slip of a base block), since the reference state.
    pub fn displacement_relative_to_ground(&self, b: usize) -> f64 {
        self.blocks[b].centroid_displacement()[0]
            - self.blocks[self.ground].centroid_displacement()[0]
    }

    /// Absolute horizontal acceleration of block `b`'s centroid now, m/s²: the model
    /// moves with the ground (see [`Dda::frame_displacement`]), so the ground's
    /// acceleration is added to the block's.
    pub fn absolute_accel(&self, b: usize) -> f64 {
        self.blocks[b].response_accel[0] + self.ground_accel(self.time)
    }

    /// How far the model's frame has moved with the ground, m: the solver works in a
    /// frame that translates with the input ground motion (every block feels −m ü0), so
    /// absolute positions are the blocks' plus this.
    pub fn frame_displacement(&self) -> f64 {
        self.motion
            .as_ref()
            .map_or(0.0, |m| m.displacement(self.time))
    }

    /// Ground acceleration at time t (the input, not the large-mass ground's response).
    pub fn ground_accel(&self, t: f64) -> f64 {
        self.frame_accel(t)[0]
    }

    /// Vertical ground acceleration at time t, up positive (0 without vertical shaking).
    pub fn vertical_ground_accel(&self, t: f64) -> f64 {
        self.vertical.as_ref().map_or(0.0, |m| m.accel(t))
    }

    /// The ground's acceleration (horizontal, vertical) at time t: in the frame that moves
    /// with the ground every block feels it, reversed, as a body force per unit mass.
    ///
    /// A step asks for the same two times several times over (its end in the assembly,
    /// both ends for the work of the input, its end again for the response written out),
    /// so a step keeps its end time's value before its passes ([`Dda::keep_frame_accel`])
    /// and the previous step's is still kept for its start. A record's or a harmonic's
    /// value is a function of the time alone, so a kept value is the one computing it
    /// again would give, to the bit. Readers only read, so `Dda` stays `Sync`.
    fn frame_accel(&self, t: f64) -> [f64; 2] {
        self.frame_accel_memo
            .get(t)
            .unwrap_or_else(|| self.compute_frame_accel(t))
    }

    /// The ground's acceleration at time t, evaluated (see [`Dda::frame_accel`]).
    fn compute_frame_accel(&self, t: f64) -> [f64; 2] {
        [
            self.motion.as_ref().map_or(0.0, |m| m.accel(t)),
            self.vertical_ground_accel(t),
        ]
    }

    /// Keeps the ground's acceleration at time t for the readers of this step (see
    /// [`Dda::frame_accel`]); a time already kept is not evaluated again.
    fn keep_frame_accel(&mut self, t: f64) {
        if self.frame_accel_memo.get(t).is_none() {
            let accel = self.compute_frame_accel(t);
            self.frame_accel_memo.keep(t, accel);
        }
    }

    /// Shakes the ground vertically too (`None`: horizontally only), by `motion` (up
    /// positive). The frame that moves with the ground then accelerates vertically as
    /// well: every block feels −m·a_v, which adds to its weight, so the normal force of a
    /// resting block, and its friction capacity, follow N = m(g + a_v). Set it before the
    /// first step; it is refused for the paper's large-mass ground, which is driven
    /// horizontally on vertical rollers.
    pub fn set_vertical_motion(&mut self, motion: Option<GroundMotion>) -> Result<()> {
        if motion.is_some()
            && self
                .blocks
                .iter()
                .any(|b| b.role == BlockRole::LargeMassGround)
        {
            return Err(Error::invalid(
                "--ground large-mass",
                "the large-mass ground rides on vertical rollers and is driven horizontally \
                 only; vertical shaking needs the prescribed ground (--ground prescribed)",
            ));
        }
        self.vertical = motion;
        self.frame_accel_memo = FrameAccelMemo::default();
        Ok(())
    }

    /// Zeroes the strain entries of rigid blocks in a change of the right-hand side.
    fn hold_rigid_change(&self, change: &mut [f64]) {
        for (b, slot) in self.blocks.iter().zip(&self.dofs.slot) {
            if let (true, Some(s)) = (b.rigid, *slot) {
                change[s + 3..s + 6].fill(0.0);
            }
        }
    }

    /// Holds the strain unknowns of rigid blocks at zero in `sys`.
    fn hold_rigid_strains(&self, sys: &mut System) {
        for (b, slot) in self.blocks.iter().zip(&self.dofs.slot) {
            if let (true, Some(s)) = (b.rigid, *slot) {
                sys.hold_strains(s);
            }
        }
    }

    fn augmented(&self) -> bool {
        self.params.contact_enforcement == super::params::ContactEnforcement::AugmentedLagrangian
    }

    /// Whether block `b` moves in the model's frame (everything but a prescribed
    /// ground, which stands still in it): the energy balance is the balance of these.
    fn is_structure(&self, b: usize) -> bool {
        self.blocks[b].role != BlockRole::PrescribedGround
    }

    /// The blocks' centroids at the step start, the origins of their unknowns (a copy,
    /// so that the blocks can be moved while it is read).
    fn centroids(&self) -> PerBlock<Point> {
        per_block(self.blocks.len(), |b| self.blocks[b].moments.centroid)
    }

    /// Known increments of the blocks without unknowns: none move, since the model moves
    /// with the ground (see [`Dda::frame_displacement`]): a prescribed ground stands still
    /// in it, and the ground's acceleration acts on every block as a body force instead.
    fn known_increments(&self) -> PerBlock<Vec6> {
        per_block(self.blocks.len(), |_| [0.0; 6])
    }

    /// Sets the velocity of block `b`'s six unknowns (an initial condition: call before
    /// the first step).
    pub fn set_velocity(&mut self, b: usize, velocity: Vec6) -> Result<()> {
        let block = self
            .blocks
            .get_mut(b)
            .ok_or_else(|| Error::invalid("block index", format!("{b} is out of range")))?;
        if velocity.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid("velocity", "must be finite"));
        }
        block.velocity = velocity;
        self.forget_next_step_detection();
        Ok(())
    }

    /// Advances until `t_end`, calling `observe` after every step.
    pub fn run_until(
        &mut self,
        t_end: f64,
        mut observe: impl FnMut(&Dda, &StepReport),
    ) -> Result<()> {
        while self.time < t_end - 1e-9 * self.params.dt {
            let report = self.step(t_end - self.time)?;
            observe(self, &report);
        }
        Ok(())
    }
}

/// Adds a scalar contact force `amount`, acting along a contact's gradients on its two
/// blocks, to the generalised forces `rhs` (blocks without unknowns take none).
fn spread_force(dofs: &DofMap, rhs: &mut [f64], amount: f64, sides: [(usize, &Vec6); 2]) {
    for (block, grad) in sides {
        if let Some(s) = dofs.slot[block] {
            for k in 0..6 {
                rhs[s + k] += amount * grad[k];
            }
        }
    }
}

/// The linear solver's analysis of a pattern (symbolic once, numeric every pass).
fn analysed(pattern: &Arc<BlockPattern>) -> Result<LinearSolver> {
    LinearSolver::new(Arc::clone(pattern)).map_err(|e| Error::Solver {
        time: 0.0,
        reason: format!("cannot analyse the system matrix: {e:?}"),
    })
}

/// The block couplings the system matrix can have: joints between their blocks, each
/// declared contact pair (the only blocks contacts are searched between) and, with
/// Rayleigh damping on the structure over the block `damped_base`, that block with every
/// free block (the mass-proportional dashpots).
fn coupling_pattern(
    dofs: &DofMap,
    pairs: &[ContactPair],
    bolts: &[Bolt],
    fixed: &[FixedPoint],
    connections: &[Connection],
    damped_base: Option<usize>,
) -> BlockPattern {
    let free = |b: usize| dofs.slot[b].map(|s| s / 6);
    let mut couplings = Vec::new();
    let mut tie = |blocks: &[usize]| {
        for &a in blocks {
            for &b in blocks {
                if let (Some(i), Some(j)) = (free(a), free(b)) {
                    couplings.push((i, j));
                }
            }
        }
    };
    for p in pairs {
        tie(&p.blocks);
    }
    for b in bolts {
        tie(&b.blocks);
    }
    for f in fixed {
        tie(&[f.block]);
    }
    for c in connections {
        tie(&c.blocks);
    }
    if let Some(base) = damped_base {
        for b in 0..dofs.slot.len() {
            tie(&[base, b]);
        }
    }
    BlockPattern::new(dofs.n / 6, couplings)
}

/// The frame's acceleration at the last two times kept: (time, [x, y]). A plain value,
/// written only where the step holds `&mut Dda`, so that `Dda` stays `Sync`.
#[derive(Debug, Clone, Copy)]
struct FrameAccelMemo([(f64, [f64; 2]); 2]);

impl Default for FrameAccelMemo {
    /// Nothing kept (a NaN time equals no time).
    fn default() -> Self {
        Self([(f64::NAN, [0.0; 2]); 2])
    }
}

impl FrameAccelMemo {
    /// The value kept for exactly `t`, if any.
    fn get(&self, t: f64) -> Option<[f64; 2]> {
        self.0.iter().find(|(kept, _)| *kept == t).map(|&(_, a)| a)
    }

    /// Keeps `accel` for `t` in place of the older of the two.
    fn keep(&mut self, t: f64, accel: [f64; 2]) {
        self.0 = [(t, accel), self.0[0]];
    }
}

#[cfg(test)]
mod tests {
    use super::FrameAccelMemo;

    #[test]
    fn the_frame_accel_memo_keeps_the_last_two_times_exactly() {
        let mut memo = FrameAccelMemo::default();
        assert_eq!(memo.get(0.0), None, "nothing is kept at first");
        assert_eq!(memo.get(f64::NAN), None, "a NaN time matches nothing");
        memo.keep(0.001, [1.0, 2.0]);
        memo.keep(0.002, [3.0, 4.0]);
        assert_eq!(memo.get(0.001), Some([1.0, 2.0]));
        assert_eq!(memo.get(0.002), Some([3.0, 4.0]));
        // A time one ulp away is another time.
        assert_eq!(memo.get(f64::from_bits(0.002_f64.to_bits() + 1)), None);
        memo.keep(0.003, [5.0, 6.0]);
        assert_eq!(memo.get(0.001), None, "the oldest is dropped");
        assert_eq!(memo.get(0.002), Some([3.0, 4.0]));
        assert_eq!(memo.get(0.003), Some([5.0, 6.0]));
    }

    /// A solver can be shared between threads by reference (a study reading one model
    /// from several threads), so it keeps no interior mutability.
    #[test]
    fn the_solver_is_send_and_sync() {
        fn shareable<T: Send + Sync>() {}
        shareable::<super::Dda>();
    }
}
