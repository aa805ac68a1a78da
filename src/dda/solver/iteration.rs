//! The open-close iteration of one step: solve, judge the contacts, update the multipliers, repeat until the states hold.

use super::*;

/// The relative tolerance of the contact forces within a step, as a fraction of the largest
/// normal force of the pass: a friction normal that moved by less is settled, and a frozen
/// contact whose state is off by a smaller force is accepted (see `open_close`).
const FORCE_TOLERANCE: f64 = 1e-4;

/// The most passes a static solve takes. The settle reads an iteration that does not
/// settle as "no equilibrium under this friction" and falls back (free to slip, then
/// Coulomb, then every joint held): given 16 passes, the settle of a box on a 30°
/// incline with μ = 0.3 (which cannot hold it) no longer fell back and failed.
const SETTLE_PASSES: usize = 8;

/// Why the open-close iteration did not settle (what its last pass left undecided).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Unsettled {
    /// A contact held after flipping contradicted its gap beyond the force tolerance.
    Contradicted,
    /// A contact still changed state.
    StatesChanging,
    /// Only a sliding contact's friction force still moved.
    FrictionChanging,
}

/// The outcome of an open-close iteration: the number of passes (the increments of all
/// blocks are in the caller's vector), or what kept it from settling.
pub(super) type Settled = std::result::Result<usize, Unsettled>;

impl Dda {
    /// Runs the open-close iteration (see [`Settled`]); the last pass's increments of all
    /// blocks are left in `increments` (filled in place: handed back by value, they were
    /// copied at every level of the call).
    pub(super) fn iterate(
        &mut self,
        mode: Mode,
        known: &[Vec6],
        increments: &mut PerBlock<Vec6>,
    ) -> Result<Settled> {
        self.refresh_element_terms();
        let elements = std::mem::take(&mut self.elements);
        let mut base = self
            .base_system
            .take()
            .unwrap_or_else(|| System::zeros(Arc::clone(&self.pattern), 1.0));
        self.assemble_base_into(&mut base, mode, known, &elements);
        self.elements = elements;
        let result = self.open_close(mode, known, &base, increments);
        self.base_system = Some(base);
        result
    }

    /// The gap by which a closed contact must open to open: one opening by less stays
    /// closed (so that one resting at zero force does not flicker). Its spring then
    /// pulls, by at most p·tolerance: 1e-12 of the size keeps that tension far below any
    /// force of interest (0.3 mN per metre of size for p = 1e12 N/m; a tolerance of 1e-9
    /// of the size let a 2 m block hang on 2 kN and held it down past its uplift
    /// threshold), yet well above the rounding of the gap (1e-16 of the size).
    pub(super) fn open_tolerance(&self) -> f64 {
        1e-12 * self.structure_size
    }

    /// The open-close passes of one step on its base system.
    pub(super) fn open_close(
        &mut self,
        mode: Mode,
        known: &[Vec6],
        base: &System,
        increments: &mut PerBlock<Vec6>,
    ) -> Result<Settled> {
        let open_tolerance = self.open_tolerance();
        let slip_tolerance = 1e-12 * self.structure_size;
        let max_passes = match mode {
            Mode::Dynamic { .. } => self.params.max_open_close_passes,
            Mode::Static { .. } | Mode::Modal => {
                self.params.max_open_close_passes.min(SETTLE_PASSES)
            }
        };
        // Inline for the systems the linear solver factorises on the stack. These and the
        // per-block vectors below are filled in place at every pass: a two-block step's
        // vectors are ~200 bytes each, and handing them out by value copied each one
        // (with the step's other such copies, 7–10 % of its time).
        let mut solution: SmallVec<[f64; TINY_LIMIT]> = SmallVec::new();
        solution.resize(self.dofs.n, 0.0);
        let mut velocities: PerBlock<Vec6> = PerBlock::new();
        let mut unsettled = Unsettled::StatesChanging;
        // In a dynamic step's last quarter of the passes (at least its last pass) a contact
        // still changing between stuck and sliding keeps its state (see below): the passes
        // left then settle the friction forces and the open/closed states on them.
        let holds_stick_slip_from = max_passes - max_passes / 4 + 1;
        for pass in 1..=max_passes {
            let holding_stick_slip =
                pass >= holds_stick_slip_from && matches!(mode, Mode::Dynamic { .. });
            self.solve_pass(mode, known, base, &mut solution, increments)?;
            match mode {
                Mode::Dynamic { dt } => self.end_velocities_into(increments, dt, &mut velocities),
                Mode::Static { .. } | Mode::Modal => {
                    velocities.clear();
                    velocities.resize(self.blocks.len(), [0.0; 6]);
                }
            }
            let augmented = self.augmented();
            let mut states_changed = false;
            let mut friction_changed = false;
            let mut contradicted = false;
            // The scale of the friction normals' tolerance: the largest normal force the
            // pass found. (The forces it used may be predictions extrapolated from an
            // impulse, 1e11 N a step after an impact: a tolerance of 1e-4 of that let a
            // sliding corner keep a friction force of 0 against its 3e6 N normal force.)
            let max_normal = self
                .contacts
                .iter()
                .map(|c| {
                    if augmented {
                        // (An open contact carries nothing, whatever its trial gap.)
                        if c.state.is_closed() {
                            c.normal_multiplier.max(0.0)
                        } else {
                            0.0
                        }
                    } else {
                        let gap = c.gap_end(
                            &increments[c.key.vertex_block],
                            &increments[c.key.edge_block],
                        );
                        c.props.normal_penalty * (-gap).max(0.0)
                    }
                })
                .fold(0.0_f64, f64::max);
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
                let p = c.props.normal_penalty / self.penalty_boost;
                let ps = c.props.shear_penalty / self.penalty_boost;
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
                        _ => c.props.friction.sticking_coefficient(),
                    },
                    slip_increment: slip,
                    slip_velocity,
                    bonded: c.props.bonded,
                    open_tolerance,
                    slip_tolerance,
                    curved: c.curvature != 0.0,
                });
                // Friction acts with the normal force at the step's end, where every force
                // of the step is balanced (see the integrator).
                let n_end = if augmented && c.state.is_closed() {
                    normal_force
                } else {
                    p * (-gap).max(0.0)
                };
                // The friction force uses the normal force of the previous pass (keeping K
                // symmetric); iterate until it moves by < 1e-4: the friction force is then
                // within 1e-4·ρN of the implicit one, far below the accuracy targets, while a
                // tighter bound only buys passes when the penalty springs ring.
                // The sliding coefficient, at the end's slip speed, settles the same way.
                let mu_end = match mode {
                    Mode::Static { friction: Some(f) } => f,
                    _ => c.props.friction.sliding_coefficient(slip_velocity),
                };
                let sliding = matches!(new_state, ContactState::Sliding { .. });
                let mu_moved = (mu_end - c.sliding_coefficient).abs()
                    > 1e-4 * mu_end.max(c.sliding_coefficient);
                let used_normal = c.friction_normal;
                let changed_normal =
                    (n_end - used_normal).abs() > FORCE_TOLERANCE * max_normal.max(n_end);
                if sliding && (mu_moved || changed_normal) {
                    friction_changed = true;
                }
                // A normal force within the tolerance is left as the solve used it, as the
                // coefficient below: the friction work booked is then the work of the
                // force the step applied (booked at the found one, a sliding corner's
                // friction in an impact step, whose tolerance the impulse of the other
                // corner sets, was 1 kJ more than the step dissipated).
                // (The secant needs two passes at one coefficient: a velocity law's moves
                // the found force as well, and a secant across it drifted a box on a
                // slope 0.2 % off its closed-form speed.)
                // A contact closing straight into sliding (on a dish) has no normal force
                // yet: its pass's n_end is the spring of a penetration no contact
                // resisted (7e10 N for a slider's corner landing 7 µm deep), which as
                // friction threw the slider 1.9 m within a step. Its first closed pass
                // slides without friction, and the next uses the force that pass found.
                let held = sliding && new_state == c.state && !mu_moved;
                c.friction_normal = match (held, changed_normal) {
                    _ if sliding && c.state == ContactState::Open => 0.0,
                    (true, true) => next_friction_normal(c.friction_trial, used_normal, n_end),
                    (true, false) => used_normal,
                    (false, _) => n_end,
                };
                c.friction_trial = held.then_some((used_normal, n_end));
                // A coefficient within the tolerance is left as the solve used it, so that
                // the friction work booked and the force carried into the next step are
                // the ones the step was solved with (the energy balance of a velocity law
                // closed to 1e-6 only when the settled pass's re-evaluation was booked).
                if mu_moved || !sliding {
                    c.sliding_coefficient = mu_end;
                }
                // A contact that keeps flipping within one step (stuck ↔ sliding with the
                // penalty spring's unresolved dynamics on either side of the limit) keeps
                // its latest state: the step is then decided, at a small cost in accuracy,
                // instead of being cut down to nothing.
                // So does a contact still changing between stuck and sliding in a dynamic
                // step's last passes: the flips cascade through a wall's bed joints one
                // contact at a time, and a cut Δt did not settle them sooner (wall:20 on
                // Kobe, 9 s: 883 cuts before, 285 with this in the last of 8 passes and the
                // force tolerance below; 9 with it in the last 4 of 16 passes, where the
                // friction forces settle on the held states instead of cutting Δt).
                // (The static settle keeps its own test of settled states.)
                let stick_slip = c.state.is_closed() && new_state.is_closed();
                let frozen = c.flips >= MAX_FLIPS_PER_STEP || (holding_stick_slip && stick_slip);
                if new_state != c.state && frozen {
                    // ...but never open while penetrating, nor closed while apart: the
                    // first lets the vertex pass into the other block unopposed (and the
                    // spring throws it back out with energy it never had), the second
                    // holds it with a spring in tension. The step is cut instead, unless
                    // the force so missed or pulled (p·|gap|) is within the tolerance the
                    // friction normals are settled to: a wall's corners resting at zero
                    // force chatter between open and closed by 1e-11 m (20 N against
                    // 5e5 N in the wall's joints), and cutting Δt for them, as before,
                    // did not stop the chatter but cut wall:30 on Kobe into thousands of
                    // tiny steps.
                    let contradicts = match c.state {
                        ContactState::Open => gap < -open_tolerance,
                        _ => judged_gap > open_tolerance,
                    };
                    let beyond = contradicts && p * judged_gap.abs() > FORCE_TOLERANCE * max_normal;
                    if !beyond {
                        continue;
                    }
                    if pass == max_passes {
                        contradicted = true;
                        continue;
                    }
                    // Before the last pass, a contradiction beyond the tolerance takes
                    // the state its gap asks for and is solved once more.
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
                    states_changed = true;
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
                return Ok(Err(Unsettled::Contradicted));
            }
            if !states_changed && !friction_changed {
                return Ok(Ok(pass));
            }
            unsettled = if states_changed {
                Unsettled::StatesChanging
            } else {
                Unsettled::FrictionChanging
            };
        }
        Ok(Err(unsettled))
    }

    /// Solves one open-close pass with the contacts' trial states: one linear solve with
    /// penalty springs, or, with the augmented Lagrangian, solves with the same matrix
    /// until every closed contact's constraint holds, updating the multipliers
    /// (λ ← λ − p·g) after each. Writes the increments of all blocks into `increments`.
    pub(super) fn solve_pass(
        &mut self,
        mode: Mode,
        known: &[Vec6],
        base: &System,
        solution: &mut SmallVec<[f64; TINY_LIMIT]>,
        increments: &mut PerBlock<Vec6>,
    ) -> Result<()> {
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
            self.increments_into(solution, known, increments);
            if !self.augmented() {
                if self.linear.last_solve_iterated() {
                    let mut residual = vec![0.0; self.dofs.n];
                    self.add_residual(&sys, solution, &mut residual);
                    self.solve_correction(&sys, &residual, structure, solution, true)?;
                    self.increments_into(solution, known, increments);
                }
                return Ok(());
            }
            self.settle_multipliers(&sys, known, structure, solution, increments)
        });
        self.pass_system = Some(sys);
        result
    }

    /// Augmented Lagrangian: solves with the same matrix until every closed contact's
    /// constraint holds, updating the multipliers (λ ← λ − p·g) after each solve; the
    /// matrix stays, only the multipliers' part of the right-hand side changes (λ enters
    /// as −λ·∇g of the constraint energy). A first solve by conjugate gradients is
    /// refined: its residual is solved with the first change of the multipliers, or
    /// alone if they need none. `increments` are those of `solution` and are kept so.
    fn settle_multipliers(
        &mut self,
        sys: &System,
        known: &[Vec6],
        structure: u64,
        solution: &mut [f64],
        increments: &mut PerBlock<Vec6>,
    ) -> Result<()> {
        const MAX_ITERATIONS: usize = 200;
        // Inline for the systems the linear solver factorises on the stack (a heap vector
        // was the two-block's one allocation a step).
        let mut change: SmallVec<[f64; TINY_LIMIT]> = SmallVec::new();
        change.resize(self.dofs.n, 0.0);
        let mut refine = self.linear.last_solve_iterated();
        for _ in 0..MAX_ITERATIONS {
            self.counters.constraint_iterations += 1;
            change.fill(0.0);
            let settled = self.update_multipliers(increments, &mut change);
            if settled && !refine {
                break;
            }
            self.hold_rigid_change(&mut change);
            if refine {
                // (The right-hand side is still the assembled one: no change solved yet.)
                self.add_residual(sys, solution, &mut change);
            }
            self.solve_correction(sys, &change, structure, solution, settled)?;
            refine = false;
            self.increments_into(solution, known, increments);
        }
        Ok(())
    }

    /// Adds the residual R − K x of the pass's system at `solution` to `out`. Conjugate
    /// gradients stop at a backward error relative to ‖K‖‖x‖, and ‖K‖ is that of the
    /// stiffest rows (augmented-Lagrangian penalties ~5e17): they left up to 3 kN
    /// unbalanced on the storeys of the fixed-base three-storey frame, whose work over El
    /// Centro (20 J, 1.4e-6 of the energy through it) went unbooked. A fresh factor's
    /// residual is far smaller.
    fn add_residual(&self, sys: &System, solution: &[f64], out: &mut [f64]) {
        let mut product = vec![0.0; solution.len()];
        sys.k.mul(solution, &mut product);
        for ((o, r), kx) in out.iter_mut().zip(sys.r.iter()).zip(&product) {
            *o += r - kx;
        }
    }

    /// Adds K⁻¹ `change` to `solution`. A `residual` alone is first tried with one
    /// refinement step on the kept factor (a matrix-vector product and a factor solve,
    /// where conjugate gradients to a backward error relative to the correction's size
    /// cost several, and used up the factor's budget: the fixed-base frame then took 40 %
    /// longer).
    fn solve_correction(
        &mut self,
        sys: &System,
        change: &[f64],
        structure: u64,
        solution: &mut [f64],
        residual: bool,
    ) -> Result<()> {
        if residual && self.linear.refine(&sys.k, change, solution) {
            return Ok(());
        }
        self.linear
            .solve_change(&sys.k, change, structure, solution)
            .map_err(|e| self.solve_error(e))
    }

    /// One augmented-Lagrangian update, λ ← λ − p·g, of every closed contact's
    /// multipliers from the constraint violations g at `increments`; their change is
    /// added to `change` (a change of the right-hand side). True when the violations were
    /// already within the tolerance (the multipliers are then the forces of `increments`).
    pub(super) fn update_multipliers(&mut self, increments: &[Vec6], change: &mut [f64]) -> bool {
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
    pub(super) fn structure_key(&self, mode: Mode) -> u64 {
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
    pub(super) fn solve_error(&self, e: SolveError) -> Error {
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
    /// from the motion), used to judge slip reversals, into `out`.
    fn end_velocities_into(&self, increments: &[Vec6], dt: f64, out: &mut PerBlock<Vec6>) {
        let c = &self.coeffs;
        out.clear();
        out.extend(
            self.blocks
                .iter()
                .zip(increments)
                .map(|(b, d)| match b.role {
                    BlockRole::PrescribedGround => [0.0; 6],
                    _ => std::array::from_fn(|k| {
                        let a_new = c.end_accel(d[k], b.velocity[k], b.accel[k], dt);
                        c.end_velocity(b.velocity[k], b.accel[k], a_new, dt)
                    }),
                }),
        );
    }

    /// Increments of all blocks from the solution vector and the known ones.
    pub(super) fn increments(&self, solution: &[f64], known: &[Vec6]) -> PerBlock<Vec6> {
        let mut out = PerBlock::new();
        self.increments_into(solution, known, &mut out);
        out
    }

    /// [`Dda::increments`] into `out`.
    fn increments_into(&self, solution: &[f64], known: &[Vec6], out: &mut PerBlock<Vec6>) {
        out.clear();
        out.extend(
            self.dofs
                .slot
                .iter()
                .zip(known)
                .map(|(slot, known)| match *slot {
                    Some(s) => std::array::from_fn(|k| solution[s + k]),
                    None => *known,
                }),
        );
    }
}

/// What a trial solution says about a contact, for locating its event in the step.
pub(super) struct Transition {
    pub(super) gap_end: f64,
    pub(super) slip: f64,
    pub(super) slip_velocity_end: f64,
    /// Shear force (the pull on the stick) at the step start and end, N.
    pub(super) shear_start: f64,
    pub(super) shear_end: f64,
    /// Normal force at the step end, N.
    pub(super) normal_end: f64,
}

/// The normal force the next pass uses for a sliding contact's friction: the one this
/// pass found, `found`, or, after a pass before it, the secant estimate of the fixed
/// point N = f(N) of the passes' map from the normal force used to the one found. A
/// corner sliding into a slender rotating block feeds its friction back into its normal
/// force (a gain of 0.65 per pass was measured on a toppling block), and plain passes
/// then needed some twenty passes to settle within 1e-4, more than the step allows; for
/// one contact the map is linear and the secant lands on its fixed point.
fn next_friction_normal(previous: Option<(f64, f64)>, used: f64, found: f64) -> f64 {
    let Some((used_before, found_before)) = previous else {
        return found;
    };
    let step = used - used_before;
    if step == 0.0 {
        return found;
    }
    let gain = (found - found_before) / step;
    // A gain near or above 1 has no fixed point nearby (the secant would throw the force
    // far away); a steeply negative one is an oscillation the plain pass handles no worse.
    if !(-10.0..0.999).contains(&gain) {
        return found;
    }
    (used + (found - used) / (1.0 - gain)).max(0.0)
}

/// Estimates where in a step a contact left its start state (0 = at the start, 1 = at the
/// end), from the trial solution that showed the change:
///
/// - locked → sliding: where the shear force, linear over the step, reaches ρN;
/// - sliding → locked: where the slip velocity, linear over the step (from its start value
///   and the slip increment), passes through zero;
/// - open → closed: where the gap, linear over the step, closes.
pub(super) fn transition_fraction(
    c: &Contact,
    new_state: ContactState,
    t: Transition,
    dt: f64,
) -> f64 {
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
            let limit = c.props.friction.sticking_coefficient() * normal_end;
            if f0 >= limit {
                // Already past the limit when the step began (a stuck start that the
                // judge lets go at once, or a normal force that fell): the event is here.
                0.0
            } else if f1 > f0 {
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
pub(super) fn yield_stretch(c: &Contact, state: ContactState, gap_end: f64) -> Option<f64> {
    match state {
        ContactState::Open => Some(0.0),
        ContactState::Locked => None,
        ContactState::Sliding { direction } => {
            let n = c.props.normal_penalty * (-gap_end).max(0.0);
            let f = c.props.friction.sliding_coefficient(c.end_slip_velocity) * n;
            Some(direction * f / c.props.shear_penalty)
        }
    }
}
