//! The DDA time step: assembly, the open-close iteration, Δt control and the commit.

use std::sync::Arc;

use nalgebra::DVector;
use serde::Serialize;
use smallvec::SmallVec;

use super::assembly::{DofMap, System};
use super::block::{
    Block, BlockRole, Vec6, displacement_with_rotation, point_displacement, rotation_of,
    t_transpose_times,
};
use super::contact::{
    self, Contact, ContactMemories, ContactMemory, ContactPair, JointProps, dot6,
};
use super::energy::EnergyTerms;
use super::joints::{Bolt, Connection, ElementTerms, FixedPoint, NodeMotion};
use super::judge::{ContactState, JudgeInput, judge};
use super::linear::{BlockPattern, LinearSolver, SolveError, TINY_LIMIT};
use super::params::{AlphaCoefficients, SolverParams};
use crate::ground_motion::GroundMotion;
use crate::model::geometry::{self, Point};
use crate::model::scene::{FixedDirection, GroundKind, Scene};
use crate::{Error, Result};

/// Per-block values of one step (increments, velocities, centroids), inline for models of
/// up to four blocks: a two-block step is a few microseconds, and the heap traffic of a
/// handful of small vectors per step was 4 % of it. Larger models spill to the heap.
type PerBlock<T> = SmallVec<[T; 4]>;

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

/// Totals over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct RunCounters {
    /// Accepted steps.
    pub steps: u64,
    /// Open-close passes in accepted attempts.
    pub passes: u64,
    /// Δt cuts.
    pub cuts: u64,
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
    /// Each block's rotation as (sine, cosine): the exact rotation's, or `(r0, 1)` for
    /// the linear map. Computed once per block, not per node (a frame has ~150 nodes).
    rotations: &'a [(f64, f64)],
}

impl NodeMotion for StepMotion<'_> {
    fn node_displacement(&self, b: usize, x: Point) -> Point {
        displacement_with_rotation(self.centroids[b], x, &self.increments[b], self.rotations[b])
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
    /// The step's joint terms (kept to reuse their storage).
    elements: Vec<ElementTerms>,
    pairs: Vec<ContactPair>,
    contacts: Vec<Contact>,
    memory: ContactMemories,
    bolts: Vec<Bolt>,
    fixed: Vec<FixedPoint>,
    connections: Vec<Connection>,
    loads: Vec<PointLoad>,
    motion: Option<GroundMotion>,
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
    /// The states contacts take at the event a shortened step is landed on.
    pending_events: Vec<(contact::ContactKey, ContactState)>,
    /// The stored accelerations are not yet those of the forces (a model that starts
    /// out of equilibrium): the first event resolution computes them.
    initial_accel_pending: bool,
}

/// xᵀ M y for a block's 6×6 matrix.
fn quadratic(m: &super::block::Mat6, x: &Vec6, y: &Vec6) -> f64 {
    let mut sum = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            sum += x[i] * m[i][j] * y[j];
        }
    }
    sum
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
            g.material.density = target / g.moments.area;
            g.mass = super::block::mass_matrix(g.material.density, &g.moments);
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
            });
        }
        let mut connections = Vec::new();
        for c in &scene.connections {
            let mut owners = [0; 3];
            for k in 0..3 {
                owners[k] = scene.block_index(&c.nodes[k].block)?;
            }
            connections.push(Connection {
                blocks: owners,
                nodes: [c.nodes[0].point, c.nodes[1].point, c.nodes[2].point],
                elasticity: c.material.elasticity(),
                strain: [0.0; 3],
                stress: [0.0; 3],
            });
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
        let dofs = DofMap::new(&is_free);
        let pattern = Arc::new(coupling_pattern(
            &dofs,
            &pairs,
            &bolts,
            &fixed,
            &connections,
        ));
        let linear = LinearSolver::new(Arc::clone(&pattern)).map_err(|e| Error::Solver {
            time: 0.0,
            reason: format!("cannot analyse the system matrix: {e:?}"),
        })?;
        let mut model = Self {
            blocks,
            ground,
            dofs,
            pattern,
            linear,
            pass_system: None,
            base_system: None,
            elements: Vec::new(),
            pairs,
            contacts: Vec::new(),
            memory: ContactMemories::default(),
            bolts,
            fixed,
            connections,
            loads,
            motion,
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

    /// Finds the contacts of the current geometry (carrying over the memory of the last
    /// step's).
    fn detect_contacts(&mut self) {
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
                direction * c.props.friction.min(1e30) * c.friction_normal
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
        self.motion.as_ref().map_or(0.0, |m| m.accel(t))
    }

    /// Makes the current state the reference: displacements and energies count from here.
    fn reset_reference(&mut self) {
        for b in &mut self.blocks {
            b.reference_centroid = b.moments.centroid;
            b.rotation = 0.0;
            b.velocity = [0.0; 6];
            b.accel = [0.0; 6];
            b.response_accel = [0.0; 6];
        }
        self.energy = EnergyTerms::default();
        self.stored_reference = self.stored_energy();
        self.energy_scale = 0.0;
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
        self.blocks.iter().map(|b| b.moments.centroid).collect()
    }

    /// Known increments of the blocks without unknowns: none move, since the model moves
    /// with the ground (see [`Dda::frame_displacement`]): a prescribed ground stands still
    /// in it, and the ground's acceleration acts on every block as a body force instead.
    fn known_increments(&self) -> PerBlock<Vec6> {
        PerBlock::from_elem([0.0; 6], self.blocks.len())
    }

    fn element_terms(&self) -> Vec<ElementTerms> {
        let mut out = Vec::new();
        self.element_terms_into(&mut out);
        out
    }

    /// This step's terms of every joint, into `out` (cleared first).
    fn element_terms_into(&self, out: &mut Vec<ElementTerms>) {
        out.clear();
        out.extend(self.bolts.iter().map(Bolt::terms));
        out.extend(self.fixed.iter().map(FixedPoint::terms));
        out.extend(self.connections.iter().map(Connection::terms));
    }

    /// Assembles everything that does not depend on contact states (into a new system).
    fn assemble_base(&self, mode: Mode, known: &[Vec6], elements: &[ElementTerms]) -> System {
        let mut sys = System::zeros(Arc::clone(&self.pattern), 1.0);
        self.assemble_base_into(&mut sys, mode, known, elements);
        sys
    }

    /// Assembles everything that does not depend on contact states into `sys` (same
    /// pattern; its values are overwritten).
    fn assemble_base_into(
        &self,
        sys: &mut System,
        mode: Mode,
        known: &[Vec6],
        elements: &[ElementTerms],
    ) {
        let c = &self.coeffs;
        let (mass_factor, stiffness_factor) = match mode {
            Mode::Dynamic { dt } => (c.mass_factor(dt), 1.0 - c.alpha_f),
            // A vanishing "mass spring" (1 mHz) only so that unloaded rigid-body modes (a
            // roof hung on one bolt can still turn) do not make the static matrix singular.
            Mode::Static { .. } => ((2.0 * std::f64::consts::PI * 1e-3_f64).powi(2), 1.0),
            Mode::Modal => (0.0, 1.0),
        };
        sys.clear(stiffness_factor);
        for (bi, b) in self.blocks.iter().enumerate() {
            let Some(s) = self.dofs.slot[bi] else {
                continue;
            };
            sys.add_diag_block(s, &b.mass, mass_factor);
            // Elastic stiffness on the strain unknowns and the initial-stress force.
            let diagonal = sys.k.diagonal_mut(s / 6);
            for i in 0..3 {
                for j in 0..3 {
                    diagonal[3 + i][3 + j] +=
                        stiffness_factor * b.moments.area * b.elasticity[i][j];
                }
            }
            for i in 0..3 {
                sys.r[s + 3 + i] -= b.moments.area * b.stress[i];
            }
            // Gravity.
            sys.r[s + 1] -= b.total_mass() * self.gravity;
            if let Mode::Dynamic { dt } = mode {
                // Inertia from the previous step: −M[(1 − αm) ã + αm a].
                let mut w = [0.0; 6];
                for k in 0..6 {
                    w[k] = c.inertia_predictor(b.velocity[k], b.accel[k], dt);
                }
                for i in 0..6 {
                    let mw: f64 = (0..6).map(|j| b.mass[i][j] * w[j]).sum();
                    sys.r[s + i] -= mw;
                }
                // The frame moves with the ground: every block feels −m ü0. The paper's
                // large-mass ground is driven by f = m_g ü0 (eq. 4), which cancels it.
                if b.role != BlockRole::LargeMassGround {
                    let t_alpha = self.time + (1.0 - c.alpha_f) * dt;
                    sys.r[s] -= b.total_mass() * self.ground_accel(t_alpha);
                }
            }
        }
        let centroids = self.centroids();
        for e in elements {
            sys.add_nodal_element(&self.dofs, known, &centroids, e);
        }
        for l in &self.loads {
            if let Some(s) = self.dofs.slot[l.block] {
                let f = t_transpose_times(centroids[l.block], l.point, l.force);
                sys.add_rhs(s, &f, 1.0);
            }
        }
    }

    /// Adds the contact terms of the current trial states.
    fn add_contacts(&self, sys: &mut System, known: &[Vec6], mode: Mode) {
        for c in &self.contacts {
            if let Mode::Dynamic { dt } = mode {
                self.add_dashpots(sys, c, dt);
            }
            let (i, j) = (c.key.vertex_block, c.key.edge_block);
            // Augmented Lagrangian: the multipliers carry the force, the springs only
            // pull the iterate onto the constraint (energy ½p g² − λ g).
            let (lambda_n, lambda_s) = if self.augmented() {
                (c.normal_multiplier, c.shear_multiplier)
            } else {
                (0.0, 0.0)
            };
            match c.state {
                ContactState::Open => {}
                ContactState::Locked => {
                    let p = c.props.normal_penalty;
                    sys.add_scalar_spring(
                        &self.dofs,
                        known,
                        p,
                        p * c.gap0 - lambda_n,
                        (i, &c.gap_i),
                        Some((j, &c.gap_j)),
                    );
                    let ps = c.props.shear_penalty;
                    sys.add_scalar_spring(
                        &self.dofs,
                        known,
                        ps,
                        ps * c.shear0 - lambda_s,
                        (i, &c.slip_i),
                        Some((j, &c.slip_j)),
                    );
                }
                ContactState::Sliding { direction } => {
                    let p = c.props.normal_penalty;
                    sys.add_scalar_spring(
                        &self.dofs,
                        known,
                        p,
                        p * c.gap0 - lambda_n,
                        (i, &c.gap_i),
                        Some((j, &c.gap_j)),
                    );
                    // Friction: −δρN along the slip direction on the vertex, +δρN on the edge;
                    // as generalised forces that is −δρN·(slip_i, slip_j).
                    let friction = match mode {
                        Mode::Static { friction: Some(f) } => f,
                        _ => c.props.friction,
                    };
                    let f = -direction * friction * c.friction_normal;
                    if let Some(s) = self.dofs.slot[i] {
                        sys.add_rhs(s, &c.slip_i, f);
                    }
                    if let Some(s) = self.dofs.slot[j] {
                        sys.add_rhs(s, &c.slip_j, f);
                    }
                }
            }
        }
    }

    /// Dashpot coefficients (normal, shear) of a contact in its trial state.
    fn dashpot_coefficients(&self, c: &Contact) -> (f64, f64) {
        let zeta = self.params.contact_damping;
        if zeta == 0.0 || !c.state.is_closed() {
            return (0.0, 0.0);
        }
        let crit = |p: f64| 2.0 * zeta * (p * c.damping_mass).sqrt();
        let shear = if c.state == ContactState::Locked {
            crit(c.props.shear_penalty)
        } else {
            0.0
        };
        (crit(c.props.normal_penalty), shear)
    }

    /// Relative velocity along a contact direction: a·v_i + b·v_j.
    fn directional_velocity(
        &self,
        i: usize,
        a: &Vec6,
        j: usize,
        b: &Vec6,
        vel: &dyn Fn(usize) -> Vec6,
    ) -> f64 {
        dot6(a, &vel(i)) + dot6(b, &vel(j))
    }

    /// Adds the dashpots of a closed contact: force c·q̇ at the generalised-α point, with
    /// q̇ of a free block from the Newmark velocity update (linear in the increment) and of
    /// the prescribed ground from its motion.
    fn add_dashpots(&self, sys: &mut System, c: &Contact, dt: f64) {
        let (cn, cs) = self.dashpot_coefficients(c);
        let co = &self.coeffs;
        let (i, j) = (c.key.vertex_block, c.key.edge_block);
        for (damping, a, b) in [(cn, &c.gap_i, &c.gap_j), (cs, &c.slip_i, &c.slip_j)] {
            if damping == 0.0 {
                continue;
            }
            // v_{n+1} = γ/(βΔt)·D + w.
            let mut f0 = 0.0;
            let mut parts: Vec<(usize, &Vec6)> = Vec::with_capacity(2);
            for (blk, vec) in [(i, a), (j, b)] {
                let bl = &self.blocks[blk];
                // The prescribed ground (no unknowns) stands still in the moving frame.
                if self.dofs.slot[blk].is_some() {
                    let mut w = [0.0; 6];
                    for k in 0..6 {
                        w[k] = co.velocity_predictor(bl.velocity[k], bl.accel[k], dt);
                    }
                    f0 += damping
                        * ((1.0 - co.alpha_f) * dot6(vec, &w)
                            + co.alpha_f * dot6(vec, &bl.velocity));
                    parts.push((blk, vec));
                }
            }
            let k = damping * co.gamma / (co.beta * dt);
            match parts.as_slice() {
                [] => {}
                [p] => sys.add_scalar_spring(&self.dofs, &[], k, f0, (p.0, p.1), None),
                [p, q, ..] => {
                    sys.add_scalar_spring(&self.dofs, &[], k, f0, (p.0, p.1), Some((q.0, q.1)))
                }
            }
        }
    }

    /// Runs the open-close iteration. Returns the increments of all blocks and the number
    /// of passes, or `None` if the states did not settle within the allowed passes.
    fn iterate(&mut self, mode: Mode, known: &[Vec6]) -> Result<Option<(PerBlock<Vec6>, usize)>> {
        let mut elements = std::mem::take(&mut self.elements);
        self.element_terms_into(&mut elements);
        let mut base = self
            .base_system
            .take()
            .unwrap_or_else(|| System::zeros(Arc::clone(&self.pattern), 1.0));
        self.assemble_base_into(&mut base, mode, known, &elements);
        self.elements = elements;
        let result = self.open_close(mode, known, &base);
        self.base_system = Some(base);
        result
    }

    /// The open-close passes of one step on its base system.
    fn open_close(
        &mut self,
        mode: Mode,
        known: &[Vec6],
        base: &System,
    ) -> Result<Option<(PerBlock<Vec6>, usize)>> {
        let alpha_f = match mode {
            Mode::Dynamic { .. } => self.coeffs.alpha_f,
            Mode::Static { .. } | Mode::Modal => 0.0,
        };
        // A closed contact whose gap opens by less than this stays closed (so that one
        // resting at zero force does not flicker). Its spring then pulls, by at most
        // p·tolerance: 1e-12 of the size keeps that tension far below any force of
        // interest (0.3 mN per metre of size for p = 1e12 N/m; a tolerance of 1e-9 of
        // the size let a 2 m block hang on 2 kN and held it down past its uplift
        // threshold), yet well above the rounding of the gap (1e-16 of the size).
        let open_tolerance = 1e-12 * self.structure_size;
        let slip_tolerance = 1e-12 * self.structure_size;
        let max_passes = self.params.max_open_close_passes;
        // Inline for the systems the linear solver factorises on the stack.
        let mut solution: SmallVec<[f64; TINY_LIMIT]> = SmallVec::from_elem(0.0, self.dofs.n);
        for pass in 1..=max_passes {
            let increments = self.solve_pass(mode, known, base, &mut solution)?;
            let velocities = match mode {
                Mode::Dynamic { dt } => self.end_velocities(&increments, dt),
                Mode::Static { .. } | Mode::Modal => {
                    PerBlock::from_elem([0.0; 6], self.blocks.len())
                }
            };
            let augmented = self.augmented();
            let mut changed = false;
            let mut contradicted = false;
            let mut max_normal = 0.0_f64;
            for c in &self.contacts {
                max_normal = max_normal.max(c.friction_normal);
            }
            for c in &mut self.contacts {
                let di = &increments[c.key.vertex_block];
                let dj = &increments[c.key.edge_block];
                let gap = c.gap_end(di, dj);
                let slip = c.slip_increment(di, dj);
                let slip_velocity = dot6(&c.slip_i, &velocities[c.key.vertex_block])
                    + dot6(&c.slip_j, &velocities[c.key.edge_block]);
                // The forces the judge weighs: the springs' (penalty) or the multipliers'
                // (augmented Lagrangian, where a closed contact's gap is held at zero and
                // its force says whether it would rather open: the penalty-equivalent
                // gap −λ/p).
                let p = c.props.normal_penalty;
                let ps = c.props.shear_penalty;
                let (judged_gap, normal_force, shear_start, shear_force) =
                    if augmented && c.state.is_closed() {
                        (
                            -c.normal_multiplier / p,
                            c.normal_multiplier.max(0.0),
                            -c.start_shear_multiplier,
                            -c.shear_multiplier,
                        )
                    } else {
                        (
                            gap,
                            p * (-gap).max(0.0),
                            ps * c.shear0,
                            ps * (c.shear0 + slip),
                        )
                    };
                c.end_slip_velocity = slip_velocity;
                let new_state = judge(&JudgeInput {
                    state: c.state,
                    gap: judged_gap,
                    shear_force,
                    normal_force,
                    // The static settle holds every joint stuck: it finds the preload of
                    // the normal springs; whether friction can hold the blocks is decided
                    // by the first dynamic step (a block on a steep slope starts sliding).
                    friction: match mode {
                        Mode::Static { friction: Some(f) } => f,
                        Mode::Modal => f64::INFINITY,
                        _ => c.props.friction,
                    },
                    slip_increment: slip,
                    slip_velocity,
                    bonded: c.props.bonded,
                    open_tolerance,
                    slip_tolerance,
                });
                // Friction acts with the normal force at the generalised-α time point.
                let n_alpha = if augmented && c.state.is_closed() {
                    alpha_f * c.start_normal + (1.0 - alpha_f) * normal_force
                } else {
                    let gap_alpha = alpha_f * c.gap0 + (1.0 - alpha_f) * gap;
                    p * (-gap_alpha).max(0.0)
                };
                // The friction force uses the normal force of the previous pass (keeping K
                // symmetric); iterate until it moves by < 1e-4: the friction force is then
                // within 1e-4·ρN of the implicit one, far below the accuracy targets, while a
                // tighter bound only buys passes when the penalty springs ring.
                if let ContactState::Sliding { .. } = new_state
                    && (n_alpha - c.friction_normal).abs() > 1e-4 * max_normal.max(n_alpha)
                {
                    changed = true;
                }
                c.friction_normal = n_alpha;
                // A contact that keeps flipping within one step (stuck ↔ sliding with the
                // penalty spring's unresolved dynamics on either side of the limit) keeps
                // its latest state: the step is then decided, at a small cost in accuracy,
                // instead of being cut down to nothing.
                if new_state != c.state && c.flips >= MAX_FLIPS_PER_STEP {
                    // ...but never open while penetrating, nor closed while apart: the
                    // first lets the vertex pass into the other block unopposed (and the
                    // spring throws it back out with energy it never had), the second
                    // holds it with a spring in tension. The step is cut instead.
                    contradicted |= match c.state {
                        ContactState::Open => gap < 0.0,
                        _ => judged_gap > open_tolerance,
                    };
                    continue;
                }
                if new_state != c.state {
                    c.flips += 1;
                    if c.state == c.start_state {
                        c.event_fraction = match mode {
                            Mode::Dynamic { dt } => transition_fraction(
                                c,
                                new_state,
                                Transition {
                                    gap_end: gap,
                                    slip,
                                    slip_velocity_end: slip_velocity,
                                    shear_start,
                                    shear_end: shear_force,
                                    normal_end: normal_force,
                                },
                                dt,
                            ),
                            Mode::Static { .. } | Mode::Modal => 1.0,
                        };
                    }
                    changed = true;
                    // A contact that opens drops its multipliers; one that closes starts
                    // from none; one that starts to slide keeps its normal force.
                    if !new_state.is_closed() {
                        c.normal_multiplier = 0.0;
                        c.shear_multiplier = 0.0;
                    }
                    c.state = new_state;
                }
            }
            if contradicted {
                return Ok(None);
            }
            if !changed {
                return Ok(Some((increments, pass)));
            }
        }
        Ok(None)
    }

    /// Solves one open-close pass with the contacts' trial states: one linear solve with
    /// penalty springs, or, with the augmented Lagrangian, solves with the same matrix
    /// until every closed contact's constraint holds, updating the multipliers
    /// (λ ← λ − p·g) after each. Returns the increments of all blocks.
    fn solve_pass(
        &mut self,
        mode: Mode,
        known: &[Vec6],
        base: &System,
        solution: &mut SmallVec<[f64; TINY_LIMIT]>,
    ) -> Result<PerBlock<Vec6>> {
        const MAX_ITERATIONS: usize = 200;
        let mut sys = match self.pass_system.take() {
            Some(mut sys) => {
                sys.copy_from(base);
                sys
            }
            None => base.clone(),
        };
        self.add_contacts(&mut sys, known, mode);
        self.hold_rigid_strains(&mut sys);
        let structure = self.structure_key(mode);
        let solved = self
            .linear
            .solve(&sys.k, sys.r.as_slice(), structure, solution);
        let result = solved.map_err(|e| self.solve_error(e)).and_then(|()| {
            let mut increments = self.increments(solution, known);
            if !self.augmented() {
                return Ok(increments);
            }
            // Augmented Lagrangian: the matrix stays, only the multipliers' part of the
            // right-hand side changes (λ enters as −λ·∇g of the constraint energy).
            let mut change = vec![0.0; self.dofs.n];
            for _ in 0..MAX_ITERATIONS {
                self.counters.constraint_iterations += 1;
                change.fill(0.0);
                if self.update_multipliers(&increments, &mut change) {
                    break;
                }
                self.hold_rigid_change(&mut change);
                self.linear
                    .solve_change(&sys.k, &change, structure, solution)
                    .map_err(|e| self.solve_error(e))?;
                increments = self.increments(solution, known);
            }
            Ok(increments)
        });
        self.pass_system = Some(sys);
        result
    }

    /// One augmented-Lagrangian update, λ ← λ − p·g, of every closed contact's
    /// multipliers from the constraint violations g at `increments`; their change is
    /// added to `change` (a change of the right-hand side). True when the violations were
    /// already within the tolerance (the multipliers are then the forces of `increments`).
    fn update_multipliers(&mut self, increments: &[Vec6], change: &mut [f64]) -> bool {
        let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
        for c in &mut self.contacts {
            if !c.state.is_closed() {
                continue;
            }
            let (i, j) = (c.key.vertex_block, c.key.edge_block);
            let (di, dj) = (&increments[i], &increments[j]);
            let dn = -c.props.normal_penalty * c.gap_end(di, dj);
            c.normal_multiplier += dn;
            worst = worst.max(dn.abs());
            scale = scale.max(c.normal_multiplier.abs());
            let mut changes = [(dn, &c.gap_i, &c.gap_j), (0.0, &c.slip_i, &c.slip_j)];
            if c.state == ContactState::Locked {
                let ds = -c.props.shear_penalty * (c.shear0 + c.slip_increment(di, dj));
                c.shear_multiplier += ds;
                worst = worst.max(ds.abs());
                scale = scale.max(c.shear_multiplier.abs());
                changes[1].0 = ds;
            }
            for (amount, grad_i, grad_j) in changes {
                spread_force(&self.dofs, change, amount, [(i, grad_i), (j, grad_j)]);
            }
        }
        worst <= self.params.constraint_tolerance * scale
    }

    /// Identifies what changes the whole system matrix (rather than its drift with the
    /// geometry, or the low-rank change of contacts changing state): the problem solved,
    /// the step size and the scheme. The linear solver tries its kept factor only while
    /// this stays the same.
    fn structure_key(&self, mode: Mode) -> u64 {
        const PRIME: u64 = 0x0000_0100_0000_01b3;
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut mix = |v: u64| h = (h ^ v).wrapping_mul(PRIME);
        match mode {
            Mode::Dynamic { dt } => {
                mix(1);
                mix(dt.to_bits());
                mix(self.coeffs.beta.to_bits());
                mix(self.coeffs.alpha_m.to_bits());
                mix(self.coeffs.alpha_f.to_bits());
                mix(self.params.contact_damping.to_bits());
            }
            Mode::Static { friction } => {
                mix(2);
                mix(friction.map_or(u64::MAX, f64::to_bits));
            }
            Mode::Modal => mix(3),
        }
        h
    }

    /// A linear-solve failure as a solver error saying what to check.
    fn solve_error(&self, e: SolveError) -> Error {
        let reason = match e {
            SolveError::NotPositiveDefinite => {
                "the system matrix is not positive definite: a block is unsupported or a \
                 penalty/material constant is negative or far too large"
            }
            SolveError::NonFinite => {
                "the system contains a non-finite value (NaN/inf); check material constants, \
                 penalties and the time step"
            }
            SolveError::OutsidePattern => {
                "internal error: a joint or contact couples blocks the system pattern does \
                 not hold"
            }
        };
        Error::Solver {
            time: self.time,
            reason: reason.into(),
        }
    }

    /// Velocities at the end of a trial step (Newmark update; the prescribed ground's
    /// from the motion), used to judge slip reversals.
    fn end_velocities(&self, increments: &[Vec6], dt: f64) -> PerBlock<Vec6> {
        let c = &self.coeffs;
        self.blocks
            .iter()
            .zip(increments)
            .map(|(b, d)| match b.role {
                BlockRole::PrescribedGround => [0.0; 6],
                _ => {
                    let mut v = [0.0; 6];
                    for k in 0..6 {
                        let a_new = c.end_accel(d[k], b.velocity[k], b.accel[k], dt);
                        v[k] = c.end_velocity(b.velocity[k], b.accel[k], a_new, dt);
                    }
                    v
                }
            })
            .collect()
    }

    /// Increments of all blocks from the solution vector and the known ones.
    fn increments(&self, solution: &[f64], known: &[Vec6]) -> PerBlock<Vec6> {
        (0..self.blocks.len())
            .map(|b| match self.dofs.slot[b] {
                Some(s) => {
                    let mut d = [0.0; 6];
                    d.copy_from_slice(&solution[s..s + 6]);
                    d
                }
                None => known[b],
            })
            .collect()
    }

    /// Static equilibrium under gravity and loads (the ground does not move).
    fn settle(&mut self) -> Result<()> {
        // The weight is first let down on joints free to slip: a base slab that spreads
        // under its load (Poisson) then does not leave the joint's shear springs holding a
        // self-equilibrated force (at the frame's preload, most of ρN, so that the first
        // tremor of the ground would make its ends slip). The joints then start stuck with
        // no shear. Where that has no equilibrium (a block on a slope), the settle is done
        // with Coulomb's law, and where even that has none (a slope too steep to hold), with
        // every joint held; the first dynamic step then decides whether they slide.
        let saved_memory = self.memory.clone();
        if self.settle_with(Some(0.0)).is_ok() {
            for m in self.memory.values_mut() {
                if m.state.is_closed() {
                    m.state = ContactState::Locked;
                    m.shear = 0.0;
                }
            }
            return Ok(());
        }
        self.memory = saved_memory.clone();
        if self.settle_with(None).is_ok() {
            return Ok(());
        }
        self.memory = saved_memory;
        self.settle_with(Some(f64::INFINITY))
    }

    fn settle_with(&mut self, friction: Option<f64>) -> Result<()> {
        let known = vec![[0.0; 6]; self.blocks.len()];
        self.detect_contacts();
        let Some((increments, _)) = self.iterate(Mode::Static { friction }, &known)? else {
            return Err(Error::Solver {
                time: 0.0,
                reason:
                    "the initial equilibrium under gravity did not settle (contact states keep \
                         changing); check that blocks rest on each other, or set \
                         solver.initial_equilibrium = false"
                        .into(),
            });
        };
        let (block, ratio) = self.most_displaced_block(&increments);
        // Supported blocks settle by millimetres (a roof hung on a 1 Hz spring by 25 cm);
        // an unsupported one falls by g/(2π·1 mHz)² ≈ 250 km on the regularising spring.
        if ratio > 1.0 {
            return Err(Error::Solver {
                time: 0.0,
                reason: format!(
                    "block '{}' would move {ratio:.3e} structure sizes to reach equilibrium \
                     under gravity: it is not supported (declare a contact with the block it \
                     rests on, or a bolt or fixed point that holds it)",
                    self.blocks[block].name
                ),
            });
        }
        self.commit_geometry(&increments)?;
        Ok(())
    }

    /// Largest vertex displacement of the structure relative to the ground translation,
    /// as a fraction of the structure size.
    fn max_relative_displacement(&self, increments: &[Vec6], _known: &[Vec6]) -> f64 {
        self.most_displaced_block(increments).1
    }

    /// The block with the largest vertex displacement relative to the ground translation,
    /// and that displacement as a fraction of the structure size.
    fn most_displaced_block(&self, increments: &[Vec6]) -> (usize, f64) {
        let g = increments[self.ground];
        // Squared lengths compared, one square root at the end (this runs every step).
        let mut max = (self.ground, 0.0_f64);
        for (bi, b) in self.blocks.iter().enumerate() {
            if bi == self.ground {
                continue;
            }
            for &p in &b.vertices {
                let u = point_displacement(b.moments.centroid, p, &increments[bi]);
                let (dx, dy) = (u[0] - g[0], u[1] - g[1]);
                let d2 = dx * dx + dy * dy;
                if d2 > max.1 {
                    max = (bi, d2);
                }
            }
        }
        (max.0, max.1.sqrt() / self.structure_size)
    }

    /// Moves blocks and joints by the increments and updates the contact memory.
    fn commit_geometry(&mut self, increments: &[Vec6]) -> Result<()> {
        let centroids = self.centroids();
        let rotations: PerBlock<(f64, f64)> = increments
            .iter()
            .map(|d| rotation_of(d, self.params.exact_rotation))
            .collect();
        let motion = StepMotion {
            centroids: &centroids,
            increments,
            rotations: &rotations,
        };
        for b in &mut self.bolts {
            b.commit(&motion);
        }
        for f in &mut self.fixed {
            f.commit(&motion);
        }
        for c in &mut self.connections {
            c.commit(&motion);
        }
        for l in &mut self.loads {
            let u = motion.node_displacement(l.block, l.point);
            l.point[0] += u[0];
            l.point[1] += u[1];
        }
        for (b, d) in self.blocks.iter_mut().zip(increments) {
            b.apply_increment(d, self.params.exact_rotation)?;
        }
        self.memory.clear();
        let augmented = self.augmented();
        for c in &self.contacts {
            let di = &increments[c.key.vertex_block];
            let dj = &increments[c.key.edge_block];
            let gap = c.gap_end(di, dj);
            let stuck_stretch = c.shear0 + c.slip_increment(di, dj);
            let (shear, normal_force, shear_multiplier) = if augmented {
                // The stretch left is the constraint's residual (round-off), kept so the
                // next step pulls it back; a sliding contact carries its friction force
                // as the multiplier it sticks with.
                let normal = if c.state.is_closed() {
                    c.normal_multiplier
                } else {
                    0.0
                };
                match c.state {
                    ContactState::Open => (0.0, 0.0, 0.0),
                    ContactState::Locked => (stuck_stretch, normal, c.shear_multiplier),
                    ContactState::Sliding { direction } => {
                        let mu = if c.props.friction.is_finite() {
                            c.props.friction
                        } else {
                            0.0
                        };
                        (0.0, normal, -direction * mu * normal.max(0.0))
                    }
                }
            } else {
                (
                    yield_stretch(c, c.state, gap).unwrap_or(stuck_stretch),
                    c.props.normal_penalty * (-gap).max(0.0),
                    0.0,
                )
            };
            self.memory.insert(
                c.key,
                ContactMemory {
                    state: c.state,
                    shear,
                    normal_force,
                    normal_change: if c.start_state.is_closed() && c.state.is_closed() {
                        normal_force - c.start_normal
                    } else {
                        0.0
                    },
                    shear_change: if c.start_state == ContactState::Locked
                        && c.state == ContactState::Locked
                    {
                        shear_multiplier - c.start_shear_multiplier
                    } else {
                        0.0
                    },
                    shear_multiplier,
                },
            );
        }
        Ok(())
    }

    /// Elastic energy stored in blocks, joints and contact springs of the structure.
    fn stored_energy(&self) -> f64 {
        let mut e = 0.0;
        for (bi, b) in self.blocks.iter().enumerate() {
            if self.is_structure(bi) {
                e += b.strain_energy();
            }
        }
        for b in &self.bolts {
            if b.blocks.iter().any(|&k| self.is_structure(k)) {
                e += b.energy();
            }
        }
        for f in &self.fixed {
            if self.is_structure(f.block) {
                e += f.energy();
            }
        }
        for c in &self.connections {
            if c.blocks.iter().any(|&k| self.is_structure(k)) {
                e += c.energy();
            }
        }
        // The memory holds exactly the contacts of the last step.
        for c in &self.contacts {
            let Some(m) = self.memory.get(&c.key) else {
                continue;
            };
            if !m.state.is_closed() {
                continue;
            }
            let p = c.props;
            if !self.augmented() {
                e += 0.5 * m.normal_force * m.normal_force / p.normal_penalty;
            }
            e += 0.5 * p.shear_penalty * m.shear * m.shear;
        }
        e
    }

    /// Makes the contacts' trial states (found at the very start of a step) their start
    /// states for the retry of the step.
    fn adopt_trial_states(&mut self) {
        for c in &self.contacts {
            if c.state == c.start_state {
                continue;
            }
            let m = self.memory.entry(c.key).or_insert(ContactMemory {
                state: c.start_state,
                shear: 0.0,
                normal_force: 0.0,
                normal_change: 0.0,
                shear_multiplier: 0.0,
                shear_change: 0.0,
            });
            m.state = c.state;
            m.shear = 0.0;
            m.normal_change = 0.0;
            m.shear_change = 0.0;
            if !c.state.is_closed() {
                m.normal_force = 0.0;
                m.shear_multiplier = 0.0;
            }
        }
    }

    /// Resolves the contact states right after an event (the start of the step after a
    /// landing), exactly as the event-driven rigid-body model does: the velocities and
    /// accelerations are projected onto the constraints of the closed contacts (see
    /// [`Dda::project`]), and the contact forces that this takes are judged — a contact
    /// that would have to pull opens, one whose stick force exceeds ρN slides the way it
    /// is pulled — until the states agree with their forces. Any integrator then carries
    /// on from a consistent state instead of ringing on the acceleration before the event.
    fn resolve_event(&mut self) -> Result<()> {
        self.detect_contacts();
        let kinetic_before = self.kinetic_energy();
        // Each round starts again from the motion before the event: a projection is not
        // undone by projecting on fewer constraints.
        let before: Vec<[Vec6; 3]> = self
            .blocks
            .iter()
            .map(|b| [b.velocity, b.accel, b.response_accel])
            .collect();
        // The tangential force each contact carried before the event (on the vertex,
        // along t̂): a sliding contact's friction, a stuck one's multiplier.
        let forces_before: Vec<f64> = self
            .contacts
            .iter()
            .map(|c| c.start_shear_multiplier)
            .collect();
        let initial_forces = if self.initial_accel_pending {
            self.out_of_balance_forces()
        } else {
            Vec::new()
        };
        for _ in 0..=MAX_FLIPS_PER_STEP {
            for (b, saved) in self.blocks.iter_mut().zip(&before) {
                [b.velocity, b.accel, b.response_accel] = *saved;
            }
            // Friction that changes at the event (a slip that reverses, a stick that
            // breaks at a force other than ρN) changes the accelerations as well.
            let mut friction_change = vec![0.0; self.dofs.n];
            for (c, &old) in self.contacts.iter().zip(&forces_before) {
                if let ContactState::Sliding { direction } = c.start_state {
                    let change = -direction * c.props.friction.min(1e30) * c.start_normal - old;
                    spread_force(
                        &self.dofs,
                        &mut friction_change,
                        change,
                        [
                            (c.key.vertex_block, &c.slip_i),
                            (c.key.edge_block, &c.slip_j),
                        ],
                    );
                }
            }
            if self.initial_accel_pending {
                for (f, r) in friction_change.iter_mut().zip(&initial_forces) {
                    *f += r;
                }
            }
            self.hold_rigid_change(&mut friction_change);
            self.project(Field::Velocity, None)?;
            let changes = self.project(Field::Response, Some(&friction_change))?;
            // The integrator restarts from the event as from an initial state: its
            // acceleration variable is the acceleration that balances the forces (for the
            // generalised-α family the variable otherwise lags the forces).
            for b in &mut self.blocks {
                b.accel = b.response_accel;
            }
            let mut changed = false;
            for (c, [dn, ds]) in self.contacts.iter_mut().zip(changes) {
                if !c.start_state.is_closed() || c.props.bonded {
                    continue;
                }
                let normal = c.start_normal + dn;
                let shear = c.start_shear_multiplier + ds;
                let new_state = if normal < 0.0 {
                    ContactState::Open
                } else if c.start_state == ContactState::Locked
                    && shear.abs() > c.props.friction * normal * (1.0 + 1e-9)
                {
                    // The stick force on the vertex is −(pull): it slides the way pulled.
                    ContactState::Sliding {
                        direction: if shear > 0.0 { -1.0 } else { 1.0 },
                    }
                } else {
                    c.start_state
                };
                if new_state != c.start_state {
                    c.start_state = new_state;
                    c.state = new_state;
                    changed = true;
                }
                let shear_force = match new_state {
                    ContactState::Locked => shear,
                    ContactState::Sliding { direction } => {
                        -direction * c.props.friction.min(1e30) * normal
                    }
                    ContactState::Open => 0.0,
                };
                if let Some(m) = self.memory.get_mut(&c.key) {
                    m.state = new_state;
                    m.normal_force = if new_state.is_closed() { normal } else { 0.0 };
                    m.shear_multiplier = shear_force;
                    m.normal_change = 0.0;
                    m.shear_change = 0.0;
                }
            }
            if !changed {
                break;
            }
        }
        self.energy.impact_dissipated += kinetic_before - self.kinetic_energy();
        self.initial_accel_pending = false;
        Ok(())
    }

    /// The forces not in balance at the current state (loads, gravity, the ground's
    /// body force, less the internal forces), per degree of freedom; with the stored
    /// velocities they give the initial accelerations of a model released out of
    /// equilibrium.
    fn out_of_balance_forces(&self) -> Vec<f64> {
        let mode = Mode::Static { friction: None };
        let known = self.known_increments();
        let sys = self.assemble_base(mode, &known, &self.element_terms());
        let mut forces: Vec<f64> = sys.r.iter().copied().collect();
        for (bi, b) in self.blocks.iter().enumerate() {
            if let Some(s) = self.dofs.slot[bi]
                && b.role != BlockRole::LargeMassGround
            {
                forces[s] -= b.total_mass() * self.ground_accel(self.time);
            }
        }
        forces
    }

    /// Projects the velocities or accelerations of the free blocks onto the constraints
    /// of the contacts' start states (closed: no approach; locked: no slip), in the metric
    /// of the mass matrix: x⁺ = x − M⁻¹Gᵀ(GM⁻¹Gᵀ)⁻¹G x, solved by the augmented
    /// Lagrangian (redundant constraints, as a flat face on two corners, are fine).
    /// Returns, per contact, the change of its (normal, shear) force that the projection
    /// of the accelerations takes (in N; for velocities, the impulse in N·s).
    /// `extra`: generalised forces added to the field's momentum (M x + extra), for the
    /// accelerations the force changes the event makes besides the constraints'.
    fn project(&mut self, field: Field, extra: Option<&[f64]>) -> Result<Vec<[f64; 2]>> {
        let mut multipliers = vec![[0.0_f64; 2]; self.contacts.len()];
        if extra.is_none() && !self.contacts.iter().any(|c| c.start_state.is_closed()) {
            return Ok(multipliers);
        }
        let mass_factor = self.inertia_stiffness_factor();
        let still = vec![[0.0; 6]; self.blocks.len()];
        let mut base = System::zeros(Arc::clone(&self.pattern), 1.0);
        for (bi, b) in self.blocks.iter().enumerate() {
            if let Some(s) = self.dofs.slot[bi] {
                base.add_diag_block(s, &b.mass, 1.0);
                let x = field.of(b);
                let mut mx = [0.0; 6];
                for i in 0..6 {
                    mx[i] = (0..6).map(|j| b.mass[i][j] * x[j]).sum();
                }
                base.add_rhs(s, &mx, 1.0);
            }
        }
        if let Some(extra) = extra {
            for (r, e) in base.r.iter_mut().zip(extra) {
                *r += e;
            }
        }
        let mut solution: SmallVec<[f64; TINY_LIMIT]> = SmallVec::from_elem(0.0, self.dofs.n);
        let key = 0x5eed_0000_0000_0001 ^ mass_factor.to_bits();
        for _ in 0..200 {
            let mut sys = base.clone();
            for (c, m) in self.contacts.iter().zip(&multipliers) {
                let p = c.props.normal_penalty / mass_factor;
                let (i, j) = (c.key.vertex_block, c.key.edge_block);
                if c.start_state.is_closed() {
                    sys.add_scalar_spring(
                        &self.dofs,
                        &still,
                        p,
                        -m[0],
                        (i, &c.gap_i),
                        Some((j, &c.gap_j)),
                    );
                }
                if c.start_state == ContactState::Locked {
                    sys.add_scalar_spring(
                        &self.dofs,
                        &still,
                        p,
                        -m[1],
                        (i, &c.slip_i),
                        Some((j, &c.slip_j)),
                    );
                }
            }
            self.hold_rigid_strains(&mut sys);
            self.linear
                .solve(&sys.k, sys.r.as_slice(), key, &mut solution)
                .map_err(|e| self.solve_error(e))?;
            let x = self.increments(&solution, &still);
            let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
            for (c, m) in self.contacts.iter().zip(multipliers.iter_mut()) {
                let p = c.props.normal_penalty / mass_factor;
                let rate = |a: &Vec6, b: &Vec6| {
                    dot6(a, &x[c.key.vertex_block]) + dot6(b, &x[c.key.edge_block])
                };
                // Force (normal: pushing apart; shear: on the vertex along t̂) that the
                // constraint takes: λ ← λ − p·g, as for the step's contacts.
                if c.start_state.is_closed() {
                    let d = -p * rate(&c.gap_i, &c.gap_j);
                    m[0] += d;
                    worst = worst.max(d.abs());
                    scale = scale.max(m[0].abs());
                }
                if c.start_state == ContactState::Locked {
                    let d = -p * rate(&c.slip_i, &c.slip_j);
                    m[1] += d;
                    worst = worst.max(d.abs());
                    scale = scale.max(m[1].abs());
                }
            }
            if worst <= self.params.constraint_tolerance * scale || scale == 0.0 {
                for (bi, b) in self.blocks.iter_mut().enumerate() {
                    if self.dofs.slot[bi].is_some() {
                        *field.of_mut(b) = x[bi];
                    }
                }
                break;
            }
        }
        Ok(multipliers)
    }

    /// Kinetic energy of every block that moves in the model's frame.
    fn kinetic_energy(&self) -> f64 {
        self.blocks
            .iter()
            .filter(|b| b.role != BlockRole::PrescribedGround)
            .map(Block::kinetic_energy)
            .sum()
    }

    /// Advances one step (of at most `max_dt`), cutting Δt as needed.
    pub fn step(&mut self, max_dt: f64) -> Result<StepReport> {
        // The step after a landing on a contact event restarts the integrator (see
        // [`Restart`]).
        let scheme = self.coeffs;
        // An event at the very start of a step asks once for a restart; a second request
        // in the same step (restarts disabled, or the restart found the same event) is
        // taken as it comes, so a step always ends.
        let mut may_restart = self.params.restart_after_events;
        loop {
            let restart = if self.params.restart_after_events {
                self.restart
            } else {
                Restart::None
            };
            match restart {
                Restart::None => {}
                // With exact constraints a stick-slip event need not change the integrator:
                // the velocities and accelerations are made consistent with the new
                // contact states. An impact still restarts with backward Euler: projecting
                // the impulse puts energy into a deformable block's unresolved strain
                // modes, which the chosen scheme then amplifies (a toppling block gained
                // 20 kJ in one step); backward Euler removes it as the impact's loss.
                Restart::Event if self.augmented() => self.resolve_event()?,
                Restart::Event | Restart::AfterImpact => {
                    self.coeffs = super::params::Integrator::Classic.coefficients();
                }
                Restart::Impact => {
                    // Newmark β = γ = 1 with the old acceleration taken as zero is backward
                    // Euler: D = Δt v₀ + Δt² a₁, v₁ = v₀ + Δt a₁.
                    self.coeffs = AlphaCoefficients {
                        alpha_m: 0.0,
                        alpha_f: 0.0,
                        beta: 1.0,
                        gamma: 1.0,
                    };
                    for b in &mut self.blocks {
                        if b.role != BlockRole::PrescribedGround {
                            b.accel = [0.0; 6];
                        }
                    }
                }
            }
            let result = self.step_with_current_scheme(max_dt, restart, may_restart);
            self.coeffs = scheme;
            match result {
                Ok(Some(report)) => return Ok(report),
                // An event right at the step start: redo the step as a restart.
                Ok(None) => may_restart = false,
                Err(e) => return Err(e),
            }
        }
    }

    /// One step with the current coefficients (`restart` says how this step restarts the
    /// integrator); `Ok(None)` asks for a restart (an event at the very start of the step
    /// was found; only when `may_restart`).
    fn step_with_current_scheme(
        &mut self,
        max_dt: f64,
        restart: Restart,
        may_restart: bool,
    ) -> Result<Option<StepReport>> {
        let mut cuts = 0;
        let dt_min = self.params.dt * self.params.min_dt_fraction;
        let mut dt_override: Option<f64> = None;
        // How the step after this one restarts, when this one is landed on an event.
        let mut event_kind = Restart::Event;
        loop {
            let dt = dt_override.unwrap_or(self.dt_current).min(max_dt);
            let mode = Mode::Dynamic { dt };
            let known = self.known_increments();
            self.detect_contacts();
            self.predict_friction_normals(dt);
            let outcome = self.iterate(mode, &known)?;
            // Land the step on a stick-slip (or impact) event: a transition assumed at the
            // step end is O(Δt) late; cutting the step to where it happened makes it O(Δt²).
            // A restart step accepts the stick-slip transitions it meets (it starts at one,
            // and must not creep up on it) but still lands on a further impact: a contact
            // that closes inside a backward-Euler step would leave it with the velocity
            // that closes the gap, which the next step would turn into a bounce.
            // At most one landing per nominal step: with many contacts some contact has
            // an event in nearly every step (blocks that touch at zero force chatter
            // between stuck, sliding and open), and landing on each would cut the steps to
            // nothing; the events between landings are taken at the step ends.
            let may_land = self.time - self.last_landing >= self.params.dt * (1.0 - 1e-9);
            if outcome.is_some()
                && self.params.locate_events
                && dt_override.is_none()
                && (may_land || restart != Restart::None)
            {
                let (theta, impact) = self
                    .contacts
                    .iter()
                    .filter(|c| c.props.locate_events)
                    .map(|c| {
                        let theta = c.event_fraction_in_step();
                        (theta, c.start_state == ContactState::Open && theta < 1.0)
                    })
                    .filter(|&(_, impact)| restart == Restart::None || impact)
                    .fold((1.0_f64, false), |a, b| if b.0 < a.0 { b } else { a });
                event_kind = if impact {
                    Restart::Impact
                } else {
                    Restart::Event
                };
                let at_start = theta * dt <= 1e-6 * self.params.dt;
                if at_start && restart == Restart::None && may_restart {
                    // The event happened at the step start: restart from here.
                    self.restart = event_kind;
                    if self.augmented() {
                        self.adopt_trial_states();
                    }
                    return Ok(None);
                }
                // (In a restart step, an impact at its very start is part of this step.)
                if !at_start && theta < 1.0 {
                    // The states the contacts take at the event: given to them when the
                    // shortened step ends there (and resolved at the next step's start).
                    self.pending_events = self
                        .contacts
                        .iter()
                        .filter(|c| {
                            // Events within a thousandth of the step are one event (the
                            // two corners of a face stick together).
                            c.props.locate_events
                                && (c.event_fraction_in_step() - theta).abs() <= 1e-3
                        })
                        .map(|c| {
                            // A slip that reverses stops first: the event's resolution
                            // decides whether it sticks or slides back.
                            let state = match (c.start_state, c.state) {
                                (ContactState::Sliding { .. }, ContactState::Sliding { .. }) => {
                                    ContactState::Locked
                                }
                                (_, state) => state,
                            };
                            (c.key, state)
                        })
                        .collect();
                    if theta < 0.999 {
                        dt_override = Some(theta * dt);
                        self.last_landing = self.time + theta * dt;
                        continue;
                    }
                    // The event is at this step's end: the step is landed on it as it is,
                    // and the next step restarts from the event's states.
                    dt_override = Some(dt);
                }
            }
            let reason = match outcome {
                None => format!(
                    "the open-close iteration did not settle in {} passes",
                    self.params.max_open_close_passes
                ),
                Some((increments, passes)) => {
                    let ratio = self.max_relative_displacement(&increments, &known);
                    if ratio <= self.params.max_displacement_ratio {
                        let report = self.commit_step(
                            dt,
                            &increments,
                            passes,
                            cuts,
                            ratio,
                            matches!(restart, Restart::Impact | Restart::AfterImpact),
                        )?;
                        // The step after a landing starts at the event: its transition is
                        // accepted as it comes, so the solver does not creep up on it. An
                        // impact step is followed by a classic restart, which does not
                        // carry the impulse's acceleration on; so is a step in which a
                        // contact opened (its force dropped within the step, and the old
                        // acceleration would ring on as a decaying energy error).
                        let opened = self
                            .contacts
                            .iter()
                            .any(|c| c.start_state.is_closed() && c.state == ContactState::Open);
                        if self.augmented() && dt_override.is_some() {
                            for (key, state) in std::mem::take(&mut self.pending_events) {
                                if let Some(m) = self.memory.get_mut(&key)
                                    && m.state != state
                                {
                                    m.state = state;
                                    m.shear = 0.0;
                                    if !state.is_closed() {
                                        m.normal_force = 0.0;
                                        m.shear_multiplier = 0.0;
                                    }
                                }
                            }
                        }
                        self.restart = match (dt_override.is_some(), restart) {
                            (true, _) => event_kind,
                            (false, Restart::Impact) => Restart::AfterImpact,
                            (false, _) if opened => Restart::Event,
                            (false, _) => Restart::None,
                        };
                        // Grow back towards the nominal step after a cut.
                        self.dt_current = (self.dt_current * 1.5).min(self.params.dt);
                        return Ok(Some(report));
                    }
                    format!(
                        "a vertex moved {ratio:.2e} structure sizes in one step (limit {:.2e})",
                        self.params.max_displacement_ratio
                    )
                }
            };
            dt_override = None;
            cuts += 1;
            self.counters.cuts += 1;
            self.dt_current *= self.params.cut_factor;
            if self.dt_current < dt_min {
                return Err(Error::Solver {
                    time: self.time,
                    reason: format!(
                        "{reason}, even with Δt cut to {:.3e} s; the contact springs may be far too \
                         stiff or soft for this Δt, or blocks interpenetrate",
                        dt
                    ),
                });
            }
        }
    }

    /// Accepts a converged step: integrator update, energy bookkeeping, geometry.
    /// `impact`: the step is a plastic impact (or the step right after one), and the
    /// energy it removes is counted as impact loss.
    fn commit_step(
        &mut self,
        dt: f64,
        increments: &[Vec6],
        passes: usize,
        cuts: usize,
        ratio: f64,
        impact: bool,
    ) -> Result<StepReport> {
        let c = self.coeffs;
        let t_new = self.time + dt;
        let start: PerBlock<[Vec6; 2]> = self
            .blocks
            .iter()
            .map(|b| [b.velocity, b.response_accel])
            .collect();
        // Newmark update of velocities and accelerations.
        for (b, d) in self.blocks.iter_mut().zip(increments) {
            if b.role == BlockRole::PrescribedGround {
                b.velocity = [0.0; 6];
                b.accel = [0.0; 6];
                b.response_accel = [0.0; 6];
                continue;
            }
            for k in 0..6 {
                let (v0, a0) = (b.velocity[k], b.accel[k]);
                let a_new = c.end_accel(d[k], v0, a0, dt);
                b.velocity[k] = c.end_velocity(v0, a0, a_new, dt);
                b.response_accel[k] = c.balanced_accel(a0, a_new, b.response_accel[k]);
                b.accel[k] = a_new;
            }
        }
        // The integrator's own dissipation, from its states alone: the work of the average
        // of the forces at the step's ends (M â, with â the accelerations that balance
        // them) on the increment, less the change of kinetic energy (both with the step's
        // mass matrix). Zero for the trapezoidal rule; what the residual leaves is then
        // the model's own inconsistency, not the scheme's.
        let mut numerical = 0.0;
        for ((b, d), [v0, a0]) in self.blocks.iter().zip(increments).zip(&start) {
            if b.role == BlockRole::PrescribedGround {
                continue;
            }
            let mut a_mean = [0.0; 6];
            for k in 0..6 {
                a_mean[k] = 0.5 * (a0[k] + b.response_accel[k]);
            }
            numerical += quadratic(&b.mass, &a_mean, d)
                - 0.5 * quadratic(&b.mass, &b.velocity, &b.velocity)
                + 0.5 * quadratic(&b.mass, v0, v0);
        }
        // Friction and contact counts.
        let augmented = self.augmented();
        let mut dissipated = 0.0;
        let mut max_pen = 0.0_f64;
        let (mut closed, mut sliding) = (0, 0);
        for ct in &self.contacts {
            let (i, j) = (ct.key.vertex_block, ct.key.edge_block);
            let (di, dj) = (&increments[i], &increments[j]);
            let gap = ct.gap_end(di, dj);
            let slip = ct.slip_increment(di, dj);
            if ct.state.is_closed() {
                closed += 1;
                max_pen = max_pen.max(-gap);
            }
            if let ContactState::Sliding { direction } = ct.state {
                sliding += 1;
                let f = ct.props.friction * ct.friction_normal;
                dissipated += if augmented {
                    // The friction force on the vertex, averaged over the step's ends (at
                    // its start, whatever the contact carried then), times the slip.
                    -0.5 * (ct.start_shear_multiplier - direction * f) * slip
                } else {
                    // Plastic slip: the slip minus the change of the spring's stretch.
                    let elastic = yield_stretch(ct, ct.state, gap).unwrap_or(0.0) - ct.shear0;
                    f * (direction * (slip - elastic)).max(0.0)
                };
            }
        }
        // Contact dashpots: force c·q̇ at the α point times the relative displacement.
        let mut damped = 0.0;
        for ct in &self.contacts {
            let (cn, cs) = self.dashpot_coefficients(ct);
            let (i, j) = (ct.key.vertex_block, ct.key.edge_block);
            for (damping, a, b) in [(cn, &ct.gap_i, &ct.gap_j), (cs, &ct.slip_i, &ct.slip_j)] {
                if damping == 0.0 {
                    continue;
                }
                let q0 = self.directional_velocity(i, a, j, b, &|k| start[k][0]);
                let q1 = self.directional_velocity(i, a, j, b, &|k| self.blocks[k].velocity);
                let force = damping * ((1.0 - c.alpha_f) * q1 + c.alpha_f * q0);
                damped += force * (dot6(a, &increments[i]) + dot6(b, &increments[j]));
            }
        }
        // Work of the loads: gravity and point loads, and the ground's acceleration, which
        // in the frame moving with the ground is a body force −m ü0 on every block (but
        // the paper's large-mass ground, whose driving force m_g ü0 cancels it).
        let centroids = self.centroids();
        let mut external = 0.0;
        let mut input = 0.0;
        let ground_accel = 0.5 * (self.ground_accel(self.time) + self.ground_accel(t_new));
        for (b, d) in self.blocks.iter().zip(increments) {
            if b.role == BlockRole::PrescribedGround {
                continue;
            }
            external -= b.total_mass() * self.gravity * d[1];
            if b.role != BlockRole::LargeMassGround {
                input -= b.total_mass() * ground_accel * d[0];
            }
        }
        for l in &self.loads {
            let u = point_displacement(centroids[l.block], l.point, &increments[l.block]);
            external += l.force[0] * u[0] + l.force[1] * u[1];
        }
        self.commit_geometry(increments)?;
        self.time = t_new;

        let e = &mut self.energy;
        e.input_work += input;
        e.external_work += external;
        e.friction_dissipated += dissipated;
        e.contact_damping += damped;
        if impact {
            // A plastic impact step (penalty contacts): what the scheme removed is the
            // impact's loss.
            e.impact_dissipated += numerical;
        } else {
            e.numerical_dissipated += numerical;
        }
        let kinetic = self.kinetic_energy();
        let strain = self.stored_energy() - self.stored_reference;
        self.energy.kinetic = kinetic;
        self.energy.strain = strain;
        self.energy_scale = self.energy_scale.max(self.energy.scale());
        let residual_rel = self.energy_residual_relative().abs();
        if self.blocks.iter().any(|b| {
            b.velocity
                .iter()
                .chain(b.accel.iter())
                .any(|v| !v.is_finite())
        }) {
            return Err(Error::Solver {
                time: self.time,
                reason: "a velocity or acceleration became non-finite".into(),
            });
        }
        let report = StepReport {
            time: self.time,
            dt,
            passes,
            cuts,
            contacts: self.contacts.len(),
            closed,
            sliding,
            max_penetration_ratio: max_pen / self.structure_size,
            max_displacement_ratio: ratio,
            energy: self.energy,
        };
        self.counters.steps += 1;
        self.counters.passes += passes as u64;
        self.counters.max_penetration_ratio = self
            .counters
            .max_penetration_ratio
            .max(report.max_penetration_ratio);
        self.counters.max_energy_residual_rel =
            self.counters.max_energy_residual_rel.max(residual_rel);
        self.last = report;
        Ok(report)
    }

    /// Relative energy residual now: the residual over the largest energy that has passed
    /// through the model, or over a floor of 1e-12 of its weight times its size when
    /// nothing has (a model that never moves has no relative error to report).
    pub fn energy_residual_relative(&self) -> f64 {
        let weight: f64 = self
            .blocks
            .iter()
            .filter(|b| b.role != BlockRole::PrescribedGround)
            .map(|b| b.total_mass())
            .sum::<f64>()
            * self.gravity.max(1.0);
        let floor = 1e-12 * weight * self.structure_size;
        self.energy.residual() / self.energy_scale.max(floor)
    }

    /// Natural frequencies and mode shapes of the model about its current state, with every
    /// touching contact stuck (a fixed base when the joint is closed): the generalised
    /// eigenproblem K φ = ω² M φ of the tangent stiffness (see [`Dda::tangent_stiffness`])
    /// and the block mass matrices.
    pub fn modes(&self) -> Result<Modes> {
        let model = self.clone();
        let k = model.tangent_stiffness()?;
        let mut mass = System::zeros(Arc::clone(&model.pattern), 1.0);
        for (bi, b) in model.blocks.iter().enumerate() {
            if let Some(s) = model.dofs.slot[bi] {
                mass.add_diag_block(s, &b.mass, 1.0);
            }
        }
        let modal = crate::linalg::modal(&mass.k.to_dense(), &k)?;
        let mut frequencies_hz = Vec::new();
        let mut shapes = Vec::new();
        for (col, &w) in modal.omega.iter().enumerate() {
            frequencies_hz.push(w / (2.0 * std::f64::consts::PI));
            let shape: Vec<Vec6> = (0..model.blocks.len())
                .map(|bi| match model.dofs.slot[bi] {
                    Some(s) => {
                        let mut d = [0.0; 6];
                        for k in 0..6 {
                            d[k] = modal.phi[(s + k, col)];
                        }
                        d
                    }
                    None => [0.0; 6],
                })
                .collect();
            shapes.push(shape);
        }
        Ok(Modes {
            frequencies_hz,
            shapes,
        })
    }

    /// Out-of-balance force f_ext − f_int at the current state with every touching contact
    /// stuck: the right-hand side of a static step with zero increment.
    fn out_of_balance(&mut self) -> DVector<f64> {
        self.detect_contacts();
        for c in &mut self.contacts {
            if c.gap0 <= 0.0 || c.state.is_closed() {
                c.state = ContactState::Locked;
            }
        }
        let known = vec![[0.0; 6]; self.blocks.len()];
        let elements = self.element_terms();
        let mut sys = self.assemble_base(Mode::Modal, &known, &elements);
        self.add_contacts(&mut sys, &known, Mode::Modal);
        sys.r
    }

    /// Tangent stiffness of the model about its current state: the derivative of the
    /// internal forces with respect to the unknowns *through the solver's own update* (moved
    /// vertices, accumulated stresses, re-detected contacts), by central differences.
    /// Besides the elastic, joint and contact stiffness it contains the geometric stiffness
    /// of the stresses the model carries — under a heavy gravity preload, the P-Δ softening
    /// that the time stepping shows and a plain assembly of K would miss.
    pub fn tangent_stiffness(&self) -> Result<nalgebra::DMatrix<f64>> {
        let n = self.dofs.n;
        let mut base = self.clone();
        base.out_of_balance();
        let mut k = nalgebra::DMatrix::zeros(n, n);
        // Perturbations: small against the model (1e-7 of its size for translations, 1e-7
        // rad, 1e-9 strain) yet far above rounding of the forces they produce.
        let steps = [
            1e-7 * self.structure_size,
            1e-7 * self.structure_size,
            1e-7,
            1e-9,
            1e-9,
            1e-9,
        ];
        for (bi, slot) in self.dofs.slot.iter().enumerate() {
            let Some(s) = *slot else { continue };
            for dof in 0..6 {
                let h = steps[dof];
                let mut r = [DVector::zeros(0), DVector::zeros(0)];
                for (side, sign) in [(0, 1.0), (1, -1.0)] {
                    let mut m = base.clone();
                    let mut inc = vec![[0.0; 6]; m.blocks.len()];
                    inc[bi][dof] = sign * h;
                    m.commit_geometry(&inc)?;
                    r[side] = m.out_of_balance();
                }
                let col = (&r[0] - &r[1]) / (-2.0 * h);
                k.set_column(s + dof, &col);
            }
        }
        Ok((&k + k.transpose()) * 0.5)
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

/// What a trial solution says about a contact, for locating its event in the step.
struct Transition {
    gap_end: f64,
    slip: f64,
    slip_velocity_end: f64,
    /// Shear force (the pull on the stick) at the step start and end, N.
    shear_start: f64,
    shear_end: f64,
    /// Normal force at the step end, N.
    normal_end: f64,
}

/// Estimates where in a step a contact left its start state (0 = at the start, 1 = at the
/// end), from the trial solution that showed the change:
///
/// - locked → sliding: where the shear force, linear over the step, reaches ρN;
/// - sliding → locked: where the slip velocity, linear over the step (from its start value
///   and the slip increment), passes through zero;
/// - open → closed: where the gap, linear over the step, closes.
fn transition_fraction(c: &Contact, new_state: ContactState, t: Transition, dt: f64) -> f64 {
    let Transition {
        gap_end,
        slip,
        slip_velocity_end,
        shear_start,
        shear_end,
        normal_end,
    } = t;
    let theta = match (c.state, new_state) {
        (ContactState::Locked, ContactState::Sliding { .. }) => {
            let f0 = shear_start.abs();
            let f1 = shear_end.abs();
            let limit = c.props.friction * normal_end;
            if f1 > f0 {
                (limit - f0) / (f1 - f0)
            } else {
                1.0
            }
        }
        (ContactState::Sliding { direction }, ContactState::Locked) => {
            // The slip velocity, linear over the step, passes through zero.
            let v0 = c.start_slip_velocity * direction;
            let v1 = slip_velocity_end * direction;
            if v0 <= 0.0 {
                // Already reversing when the step began.
                0.0
            } else if v1 < v0 {
                v0 / (v0 - v1)
            } else {
                // Only the displacement reversed: s(τ) = v0 τ + ½ a τ² matches it at dt.
                let a = 2.0 * (slip * direction - v0 * dt) / (dt * dt);
                if v0 > 0.0 && a < 0.0 {
                    -v0 / a / dt
                } else {
                    1.0
                }
            }
        }
        (ContactState::Open, _) if c.gap0 > 0.0 && gap_end < 0.0 => c.gap0 / (c.gap0 - gap_end),
        _ => 1.0,
    };
    if theta.is_finite() {
        theta.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// The shear spring stretch of a contact that ends the step in `state`: the yield stretch
/// ±ρN/p_s when sliding, 0 when open, `None` when locked (the stretch is then whatever the
/// step left).
fn yield_stretch(c: &Contact, state: ContactState, gap_end: f64) -> Option<f64> {
    match state {
        ContactState::Open => Some(0.0),
        ContactState::Locked => None,
        ContactState::Sliding { direction } => {
            let n = c.props.normal_penalty * (-gap_end).max(0.0);
            let f = if c.props.friction.is_finite() {
                c.props.friction * n
            } else {
                0.0
            };
            Some(direction * f / c.props.shear_penalty)
        }
    }
}

/// The block couplings the system matrix can have: joints between their blocks, and each
/// declared contact pair (the only blocks contacts are searched between).
fn coupling_pattern(
    dofs: &DofMap,
    pairs: &[ContactPair],
    bolts: &[Bolt],
    fixed: &[FixedPoint],
    connections: &[Connection],
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
    BlockPattern::new(dofs.n / 6, couplings)
}
