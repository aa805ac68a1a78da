//! The step controller: Δt cuts, event landing, integrator restarts, and the commit of a converged step (integrator update, energy booking, geometry).

use super::iteration::yield_stretch;
use super::mass::{solve_mass, solve_masses_into};
use super::*;

impl Dda {
    /// Largest vertex displacement of the structure relative to the ground translation,
    /// as a fraction of the structure size.
    pub(super) fn max_relative_displacement(&self, increments: &[Vec6], _known: &[Vec6]) -> f64 {
        self.most_displaced_block(increments).1
    }

    /// The block with the largest vertex displacement relative to the ground translation,
    /// and that displacement as a fraction of the structure size.
    pub(super) fn most_displaced_block(&self, increments: &[Vec6]) -> (usize, f64) {
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
    pub(super) fn commit_geometry(&mut self, increments: &[Vec6]) -> Result<()> {
        self.forget_next_step_detection();
        let centroids = self.centroids();
        let exact = self.params.exact_rotation;
        let maps: PerBlock<StepMap> =
            per_block(increments.len(), |b| StepMap::new(&increments[b], exact));
        let motion = StepMotion {
            centroids: &centroids,
            increments,
            maps: &maps,
        };
        self.elements_current = false;
        for b in &mut self.bolts {
            b.commit(&motion);
        }
        for f in &mut self.fixed {
            f.commit(&motion);
        }
        self.connection_groups
            .commit(&mut self.connections, &motion);
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
        for c in &mut self.contacts {
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
                        // A speed-dependent law: the coefficient the step was solved with (at
                        // the end slip speed, as iterated), so that the next step starts from the
                        // force this one used and booked. (A constant law's own value also
                        // after a settle that overrode it: see NOTES-issue-13.)
                        let mu = if c.props.friction.depends_on_speed() {
                            c.sliding_coefficient
                        } else {
                            c.props.friction.sliding_coefficient(c.end_slip_velocity)
                        };
                        // With the normal force it used (within the open-close
                        // iteration's tolerance of the one it found): the step's end
                        // acceleration holds that force, and the next step's ledger
                        // averages with it (at the one found, the three-storey frame
                        // on Northridge gained 2.5e-5 of its energy).
                        (0.0, normal, -direction * mu * c.friction_normal)
                    }
                }
            } else {
                (
                    yield_stretch(c, c.state, gap).unwrap_or(stuck_stretch),
                    c.props.normal_penalty * (-gap).max(0.0),
                    0.0,
                )
            };
            // Written in the contacts' order: the position is the hint the step's later
            // lookups (the ledger's) and the next detection find it by.
            let slot = self.memory.insert(
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
                    gap,
                },
            );
            // (Positions fit in 32 bits: the memory indexes them so.)
            c.memory_slot = slot as u32;
        }
        Ok(())
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
                    self.coeffs = crate::dda::params::Integrator::Classic.coefficients();
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
                Ok(Some(report)) => {
                    if let Some(reason) = self.rim_passed() {
                        return Err(Error::Solver {
                            time: self.time,
                            reason,
                        });
                    }
                    return Ok(report);
                }
                // An event right at the step start: redo the step as a restart.
                Ok(None) => may_restart = false,
                Err(e) => return Err(e),
            }
        }
    }

    /// One step with the current coefficients (`restart` says how this step restarts the
    /// integrator); `Ok(None)` asks for a restart (an event at the very start of the step
    /// was found; only when `may_restart`).
    pub(super) fn step_with_current_scheme(
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
        let classic = crate::dda::params::Integrator::Classic.coefficients();
        // The start state before contacts were released (see `release_opening_contacts`),
        // and the step size they were released for.
        let mut release: Option<(f64, Released)> = None;
        // The open-close iteration's increments, filled in place by each attempt.
        let mut increments: PerBlock<Vec6> = PerBlock::new();
        loop {
            let dt = step_size(dt_override.unwrap_or(self.dt_current), max_dt);
            if let Some((_, before)) = release.take_if(|(at, _)| *at != dt) {
                self.undo_release(before);
            }
            let mode = Mode::Dynamic { dt };
            self.keep_frame_accel(self.time + dt);
            let known = self.known_increments();
            self.detect_contacts();
            self.stiffen_constraints_for(dt);
            self.predict_friction_normals(dt);
            self.follow_curvature(dt);
            let outcome = self.iterate(mode, &known, &mut increments)?;
            // A loaded contact that opens: the chosen scheme would apply half its start
            // force while the vertex moves off, a push the contact cannot give (a toppling
            // block's two corners, holding 1.2e7 N after an impact, threw it up with 1.6 kJ
            // more than it had). The trapezoidal rule takes the step again without that
            // force (`release_opening_contacts`); the others take it with the classic
            // scheme, whose end state does not depend on the start's accelerations. So
            // does a step that starts at a resolved event, whatever the scheme: released
            // there, the toppling grid gained up to 2e-5 of its energy (not traced);
            // taken as it came, the push went unbooked.
            if outcome.is_ok() && self.coeffs != classic && self.opens_a_loaded_contact() {
                if restart == Restart::None
                    && self.may_release_opening_contacts()
                    && let Some(before) = self.release_opening_contacts()
                {
                    release.get_or_insert((dt, before));
                    continue;
                }
                if matches!(restart, Restart::None | Restart::Event) {
                    self.coeffs = classic;
                    continue;
                }
            }
            // Land the step on a stick-slip (or impact) event: a transition assumed at the
            // step end is O(Δt) late; cutting the step to where it happened makes it O(Δt²).
            // A restart step accepts the stick-slip transitions it meets (it starts at one,
            // and must not creep up on it) but still lands on a further impact: a contact
            // that closes inside a backward-Euler step would leave it with the velocity
            // that closes the gap, which the next step would turn into a bounce.
            // At most one landing per nominal step: with many contacts some contact has
            // an event in nearly every step (blocks that touch at zero force chatter
            // between stuck, sliding and open), and landing on each would cut the steps to
            // nothing; the events between landings are taken at the step ends. An impact
            // is still landed on if its contact's last impact was not: taken at the step
            // end by the chosen scheme, its impulse would stay in the end acceleration and
            // be applied again when the contact opens (a toppling block's far corner hitting
            // while its pivot corner grazes, landed on every few microseconds, stored 5 kJ of
            // strain and came off with 57 kJ more kinetic energy).
            let horizon = self.params.dt * (1.0 - 1e-9);
            let may_land = self.time - self.last_landing >= horizon;
            let now = self.time;
            self.recent_impacts.retain(|&(_, t)| now - t < horizon);
            if outcome.is_ok() && self.params.locate_events && dt_override.is_none() {
                let fresh = |c: &Contact| self.recent_impacts.iter().all(|&(k, _)| k != c.key);
                let (theta, impact, primary) = self
                    .contacts
                    .iter()
                    .filter(|c| c.props.locate_events)
                    .map(|c| {
                        let theta = c.event_fraction_in_step();
                        let impact = c.start_state == ContactState::Open && theta < 1.0;
                        (theta, impact, impact && fresh(c), Some(c.key))
                    })
                    .filter(|&(_, impact, fresh, _)| {
                        if restart != Restart::None {
                            impact
                        } else {
                            may_land || fresh
                        }
                    })
                    .map(|(theta, impact, _, key)| (theta, impact, key))
                    .fold((1.0_f64, false, None), |a, b| if b.0 < a.0 { b } else { a });
                event_kind = if impact {
                    Restart::Impact
                } else {
                    Restart::Event
                };
                let at_start = theta * dt <= 1e-6 * self.params.dt;
                if at_start && restart == Restart::None && may_restart {
                    // The event happened at the step start: restart from here.
                    self.restart = event_kind;
                    if let Some((_, before)) = release.take() {
                        self.undo_release(before);
                    }
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
                    // The contact whose event the step lands on comes first.
                    if let Some(at) = self
                        .pending_events
                        .iter()
                        .position(|e| Some(e.0) == primary)
                    {
                        self.pending_events.swap(0, at);
                    }
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
                Err(why) => self.count_unsettled(why),
                Ok(passes) => {
                    let ratio = self.max_relative_displacement(&increments, &known);
                    if ratio <= self.params.max_displacement_ratio {
                        self.accepted_displacement_ratio = ratio;
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
                        if dt_override.is_some() {
                            self.adopt_event_states(event_kind == Restart::Impact);
                        }
                        self.restart = match (dt_override.is_some(), restart) {
                            (true, _) => event_kind,
                            (false, Restart::Impact) => Restart::AfterImpact,
                            (false, _) if opened => Restart::Event,
                            (false, _) => Restart::None,
                        };
                        // Grow back towards the nominal step after a cut.
                        self.dt_current = self.grown_step();
                        return Ok(Some(report));
                    }
                    self.counters.cut_reasons.too_far += 1;
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
                let cause = self.rim_reached().unwrap_or_else(|| {
                    "the contact springs may be far too stiff or soft for this Δt, or blocks \
                     interpenetrate"
                        .into()
                });
                return Err(Error::Solver {
                    time: self.time,
                    reason: format!("{reason}, even with Δt cut to {dt:.3e} s; {cause}"),
                });
            }
        }
    }

    /// Counts a cut because the open-close iteration did not settle; returns why, in words.
    fn count_unsettled(&mut self, why: Unsettled) -> String {
        let reasons = &mut self.counters.cut_reasons;
        let what = match why {
            Unsettled::Contradicted => {
                reasons.contradicted += 1;
                "a contact held in its state contradicted its gap (open while penetrating, or \
                 closed while apart)"
            }
            Unsettled::StatesChanging => {
                reasons.states_changing += 1;
                "contacts still changed state"
            }
            Unsettled::FrictionChanging => {
                reasons.friction_changing += 1;
                "friction forces still moved"
            }
        };
        format!(
            "the open-close iteration did not settle in {} passes ({what})",
            self.params.max_open_close_passes
        )
    }

    /// Whether a contact that started the step carrying a force ends it open.
    fn opens_a_loaded_contact(&self) -> bool {
        self.contacts.iter().any(Contact::opens_under_load)
    }

    /// Whether a step in which a loaded contact opens is taken again by the same scheme,
    /// without that contact's start force (see [`Dda::release_opening_contacts`]): with
    /// exact constraints, and a scheme whose acceleration variable is the balanced
    /// acceleration (no α filter), so that taking a force off the one takes it off the
    /// other. The trapezoidal rule.
    fn may_release_opening_contacts(&self) -> bool {
        self.augmented() && self.coeffs.alpha_m == 0.0 && self.coeffs.alpha_f == 0.0
    }

    /// Takes the start forces of the contacts that open in this step's attempt off the
    /// start accelerations and out of the memory, so that the step is taken again by the
    /// same scheme without them; returns the start state as it was, or `None` if none
    /// of them had a memory to release (a contact carried onto a polyline's next facet
    /// reads its old edge's; such a step falls back on the classic scheme).
    ///
    /// Why not the classic scheme, as the others: its numerical term, ½Δt (a₀ − a₁)·M v̄
    /// per step, has no sign. On a block toppling under the trapezoidal rule a closed
    /// pivot's multiplier rings with period two (600 ↔ 2 400 N): the high half opens it
    /// in the trapezoidal attempt, the classic redo keeps it closed at the low half, and
    /// the alternation gained energy in 22 of 36 overturning runs (down to −4.5e-3 of the
    /// input). Released, the step is the trapezoidal rule's on the remaining forces: its
    /// numerical term stays zero, and the force the contact no longer gives is taken off
    /// the ledger's start forces with it (the memory), so every booked term agrees with
    /// the motion. The cost is the timing of the opening: the force is dropped at the
    /// step's start instead of somewhere in it, O(Δt) as with the classic scheme.
    fn release_opening_contacts(&mut self) -> Option<Released> {
        let releasable = |c: &Contact| c.opens_under_load() && self.memory.contains_key(&c.key);
        if !self.contacts.iter().any(releasable) {
            return None;
        }
        let before = Released {
            accelerations: self
                .blocks
                .iter()
                .map(|b| [b.accel, b.response_accel])
                .collect(),
            memory: self.memory.clone(),
        };
        let mut released: PerBlock<Vec6> = per_block(self.blocks.len(), |_| [0.0; 6]);
        for c in &self.contacts {
            if !c.opens_under_load() {
                continue;
            }
            let Some(m) = self.memory.get_mut(&c.key) else {
                continue;
            };
            c.add_forces(m.normal_force, m.shear_multiplier, &mut released);
            m.normal_force = 0.0;
            m.shear_multiplier = 0.0;
            m.normal_change = 0.0;
            m.shear_change = 0.0;
        }
        for (b, f) in self.blocks.iter_mut().zip(&released) {
            if b.role == BlockRole::PrescribedGround || f.iter().all(|&x| x == 0.0) {
                continue;
            }
            let Some(x) = solve_mass(b, f) else {
                continue;
            };
            for k in 0..6 {
                b.accel[k] -= x[k];
                b.response_accel[k] -= x[k];
            }
        }
        self.forget_next_step_detection();
        Some(before)
    }

    /// Puts back the start state a release changed.
    fn undo_release(&mut self, before: Released) {
        for (b, [accel, response]) in self.blocks.iter_mut().zip(before.accelerations) {
            b.accel = accel;
            b.response_accel = response;
        }
        self.restore_memory(before.memory);
    }

    /// Gives the contacts of the event a step was just landed on the states they take
    /// there (`pending_events`, the landed-on contact first). A contact that was apart
    /// joins an impact only if it is as close as the one that made it (twice its gap, or
    /// the open tolerance): the second corner of a face joined by its event fraction
    /// alone up to a millimetre apart (3.7 µm on a block lying down at 0.6 g), and its
    /// constraint then pulled it shut with energy no force supplied. Left open, it lands
    /// its own impact when it closes. `impact`: the event is an impact, whose contacts
    /// are not landed on again within a nominal step.
    fn adopt_event_states(&mut self, impact: bool) {
        self.forget_next_step_detection();
        let pending = std::mem::take(&mut self.pending_events);
        let Some(&(primary, _)) = pending.first() else {
            return;
        };
        let reach = self
            .memory
            .get(&primary)
            .map_or(0.0, |m| 2.0 * m.gap.max(0.0))
            + self.open_tolerance();
        let augmented = self.augmented();
        for (key, state) in pending {
            let Some(m) = self.memory.get_mut(&key) else {
                continue;
            };
            if state.is_closed() && !m.state.is_closed() && m.gap > reach {
                continue;
            }
            if impact {
                self.recent_impacts.push((key, self.time));
            }
            if !augmented || m.state == state {
                continue;
            }
            // A contact the landed step closed and left carrying a force keeps it: the
            // step's end accelerations balance that force, and opening it here would
            // leave them holding a force no contact carries (the next step's ledger then
            // booked half its work: a toppling block lost 93 J unbooked). The next step
            // judges it.
            if !state.is_closed() && m.state.is_closed() && m.normal_force > 0.0 {
                continue;
            }
            m.state = state;
            m.shear = 0.0;
            if !state.is_closed() {
                m.normal_force = 0.0;
                m.shear_multiplier = 0.0;
            }
        }
    }

    /// Why a step may fail that the solver cannot help: a vertex at the end of a dish's
    /// curved surface (within 1 % of its radius of the rim) is being carried out of it.
    fn rim_reached(&self) -> Option<String> {
        self.vertex_at_rim(false)
    }

    /// A vertex carried over a dish's rim (past the end of its arc, within 1 % of the
    /// radius of it): the run stops there, as a slider that leaves its dish is no longer a
    /// friction pendulum (a real bearing meets its restrainer ring, which is not
    /// modelled). Landing on two points of the circle no longer fails the step at the
    /// rim, and a slider let on over it was thrown at 4e4 g.
    pub(super) fn rim_passed(&self) -> Option<String> {
        if self.blocks.iter().all(|b| b.arcs.is_empty()) {
            return None;
        }
        self.vertex_at_rim(true)
    }

    /// A contact's vertex within 1 % of its radius of an end of a dish's arc (and, with
    /// `past_only`, outside the arc's span), in words.
    fn vertex_at_rim(&self, past_only: bool) -> Option<String> {
        self.contacts.iter().find_map(|c| {
            let dish = &self.blocks[c.key.edge_block];
            let p = c.point;
            let near = dish.arcs.iter().any(|arc| {
                let ends = [
                    dish.vertices[arc.edges[0]],
                    dish.vertices[(arc.edges[1] + 1) % dish.vertices.len()],
                ];
                let at_an_end = ends.iter().any(|e| {
                    let d = geometry::sub(p, *e);
                    d[0].hypot(d[1]) < 0.01 * arc.radius
                });
                at_an_end && (!past_only || !within_span(arc.center, ends, p))
            });
            near.then(|| {
                format!(
                    "vertex {} of block '{}' has reached the rim of the dish in block '{}' at \
                     ({:.3}, {:.3}) m: the motion carries it out of the dish (a larger radius or \
                     a weaker record keeps it in)",
                    c.key.vertex, self.blocks[c.key.vertex_block].name, dish.name, p[0], p[1]
                )
            })
        })
    }

    /// Accepts a converged step: integrator update, energy bookkeeping, geometry.
    /// `impact`: the step is a plastic impact (or the step right after one), and the
    /// energy it removes is counted as impact loss.
    pub(super) fn commit_step(
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
        let start: PerBlock<[Vec6; 2]> = per_block(self.blocks.len(), |b| {
            [self.blocks[b].velocity, self.blocks[b].response_accel]
        });
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
            numerical += b.mass_form(&a_mean, d) - 0.5 * b.mass_form(&b.velocity, &b.velocity)
                + 0.5 * b.mass_form(v0, v0);
        }
        // Friction and contact counts.
        let augmented = self.augmented();
        let mut dissipated = 0.0;
        // The part of the friction's step-average an impact step does not apply.
        let mut relabelled = 0.0;
        // The work of the closed contacts' normal forces (the average of the step's ends,
        // as every force of the ledger) on the gap the step closes. No force term books it,
        // yet the inertia's ½(F₀ + F₁)·D contains it: a gap the geometry update opened
        // (the finite rotation lifts a bonded corner by ~θ²h/2 per step: 54 J over El
        // Centro on the fixed-base frame), one a landing left (the second corner of a
        // face joins its first's event up to a millimetre apart), and the augmented
        // Lagrangian's unconverged penetration and its recovery in the next step (a
        // 6.6e9 N impulse 0.23 µm deep: +808 J, then −766 J). A discretisation error,
        // not a model loss: booked with the scheme's own dissipation (an impact's in an
        // impact step). The tangential forces of stuck and opening contacts add theirs
        // (`tangential_work`).
        let mut constraint_work = 0.0;
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
            if matches!(ct.state, ContactState::Sliding { .. }) {
                sliding += 1;
            }
            if augmented && (ct.state.is_closed() || ct.start_state.is_closed()) {
                // The forces the contact ends the step with (none if it opens: its start
                // force pushed the vertex off while the gap opened, as the scheme applies
                // it); the tangential one as a multiplier, the negative of the pull.
                let (end_normal, end_pull) = self.contact_force(ct);
                constraint_work += 0.5 * (ct.start_normal + end_normal) * (ct.gap0 - gap);
                let (friction, constraint, relabel) = tangential_work(ct, -end_pull, slip, impact);
                dissipated += friction;
                constraint_work += constraint;
                relabelled += relabel;
            } else if let ContactState::Sliding { direction } = ct.state {
                // Plastic slip: the slip minus the change of the spring's stretch.
                let f = ct.sliding_coefficient * ct.friction_normal;
                let elastic = yield_stretch(ct, ct.state, gap).unwrap_or(0.0) - ct.shear0;
                dissipated += f * (direction * (slip - elastic)).max(0.0);
            }
        }
        // Dashpots: like every other force of the ledger, the average of the force at the
        // step's two ends, c·½(q̇₀ + q̇₁), times the relative displacement. (The force at
        // the end, which the step applies, differs from it by what the integrator
        // dissipates, and that is its own term; booking the end force left the damped
        // two-block's balance off by 3e-6, stuck steps gaining what sliding ones lost.)
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
                let force = damping * 0.5 * (q0 + q1);
                damped += force * (dot6(a, &increments[i]) + dot6(b, &increments[j]));
            }
        }
        // The structure's damping, the same way, booked apart from the joints'.
        let structural = self.structural_damping_work(&start, increments);
        // Work of the loads: gravity and point loads, and the ground's acceleration, which
        // in the frame moving with the ground is a body force −m ü0 on every block (but
        // the paper's large-mass ground, whose driving force m_g ü0 cancels it).
        let centroids = self.centroids();
        let mut external = 0.0;
        let mut input = 0.0;
        let [ax0, ay0] = self.frame_accel(self.time);
        let [ax1, ay1] = self.frame_accel(t_new);
        let ground_accel = [0.5 * (ax0 + ax1), 0.5 * (ay0 + ay1)];
        for (b, d) in self.blocks.iter().zip(increments) {
            if b.role == BlockRole::PrescribedGround {
                continue;
            }
            external -= b.total_mass() * self.gravity * d[1];
            if b.role != BlockRole::LargeMassGround {
                input -= b.total_mass() * (ground_accel[0] * d[0] + ground_accel[1] * d[1]);
            }
        }
        for l in &self.loads {
            let u = point_displacement(centroids[l.block], l.point, &increments[l.block]);
            external += l.force[0] * u[0] + l.force[1] * u[1];
        }
        // The forces this step balanced at its end, to be compared with those of the
        // geometry it moves to (see `rebalance_accelerations`).
        let mut before = PerBlock::new();
        self.configuration_forces(Some(increments), &mut before);
        let old_inertia: PerBlock<Vec6> = per_block(self.blocks.len(), |bi| {
            let b = &self.blocks[bi];
            let mut f = [0.0; 6];
            for i in 0..6 {
                f[i] = (0..6).map(|j| b.mass[i][j] * b.response_accel[j]).sum();
            }
            f
        });
        self.commit_geometry(increments)?;
        // The contacts' forces at the step's end (in the memory just written) along the
        // step's gradients.
        self.add_contact_forces(&mut before);
        let mut after = PerBlock::new();
        self.configuration_forces(None, &mut after);
        self.rebalance_accelerations(&old_inertia, &before, &mut after);
        self.time = t_new;

        let e = &mut self.energy;
        e.input_work += input;
        e.external_work += external;
        e.friction_dissipated += dissipated;
        e.contact_damping += damped;
        e.structural_damping += structural;
        if impact {
            // A plastic impact step (penalty contacts): what the scheme removed is the
            // impact's loss.
            e.impact_dissipated += numerical + constraint_work + relabelled;
        } else {
            e.numerical_dissipated += numerical + constraint_work;
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
}

impl Dda {
    /// The generalised forces that the configuration exerts on each block: the block
    /// stresses, the joints and the point loads (not gravity or the ground's body force,
    /// which do not depend on it). With `increments`, their linearised values at the end
    /// of the step the increments were solved with (the forces that step balanced; the
    /// contacts' are added by the caller once their memory holds the end values);
    /// without, their values at the current geometry, contacts included (the forces the
    /// next step starts from). Written into `out` (filled in place: a two-block step's
    /// forces returned by value were a 200-byte copy each).
    pub(super) fn configuration_forces(
        &mut self,
        increments: Option<&[Vec6]>,
        out: &mut PerBlock<Vec6>,
    ) {
        out.clear();
        out.resize(self.blocks.len(), [0.0; 6]);
        let centroids = self.centroids();
        let zero = [0.0; 6];
        let inc = |b: usize| increments.map_or(&zero, |d| &d[b]);
        for (bi, (b, f)) in self.blocks.iter().zip(out.iter_mut()).enumerate() {
            let d = inc(bi);
            for i in 0..3 {
                let stress =
                    b.stress[i] + (0..3).map(|j| b.elasticity[i][j] * d[3 + j]).sum::<f64>();
                f[3 + i] -= b.moments.area * stress;
            }
        }
        // The step's own terms (kept from its assembly) for its end forces; those of the
        // current geometry otherwise (kept for the next step's assembly).
        if increments.is_none() {
            self.refresh_element_terms();
        }
        let elements = std::mem::take(&mut self.elements);
        // Plain slices: indexing a SmallVec branches on where it is stored, every time.
        let (centroids, totals) = (centroids.as_slice(), out.as_mut_slice());
        for e in &elements {
            let nodes = e.nodes();
            let forces = match increments {
                // The terms were computed at this geometry: their force is the start force.
                None => e.start_forces(),
                Some(d) => {
                    let mut u = [[0.0; 2]; MAX_NODES];
                    for (uk, &(b, x)) in u.iter_mut().zip(nodes) {
                        *uk = point_displacement(centroids[b], x, &d[b]);
                    }
                    e.end_forces(&u[..nodes.len()])
                }
            };
            for (k, &(b, x)) in nodes.iter().enumerate() {
                let g = t_transpose_times(centroids[b], x, [forces[2 * k], forces[2 * k + 1]]);
                for (total, gi) in totals[b].iter_mut().zip(g) {
                    *total -= gi;
                }
            }
        }
        self.elements = elements;
        for l in &self.loads {
            let g = t_transpose_times(centroids[l.block], l.point, l.force);
            for i in 0..6 {
                out[l.block][i] += g[i];
            }
        }
        if increments.is_none() {
            // The contacts' forces act along directions that turn with the blocks: at the
            // current geometry the contacts are found again, into the spare list (the
            // step's own, which the caller still reads, are set aside meanwhile).
            std::mem::swap(&mut self.contacts, &mut self.spare_contacts);
            self.detect_contacts();
            // Along the directions the next step will hold them along, so that its forces
            // at both ends act along the same normal (square to a dish contact's chord).
            self.follow_curvature(self.grown_step());
            self.add_contact_forces(out);
            std::mem::swap(&mut self.contacts, &mut self.spare_contacts);
            self.detection_for_next_step = Some(self.coeffs.beta);
        }
    }

    /// The nominal size of the step after an accepted one: back towards Δt after a cut,
    /// by at most 1.5× a step, and below Δt no further than to 0.9 of the displacement
    /// limit at the motion of the step just taken (a vertex's displacement grows with the
    /// step). Growing blindly, a ground too fast for Δt grew into a cut every third step
    /// (20 g at Ω/ω = 0.01: 5.6 M cuts in 16.5 M steps).
    fn grown_step(&self) -> f64 {
        let grown = (self.dt_current * 1.5).min(self.params.dt);
        let ratio = self.accepted_displacement_ratio;
        if self.dt_current >= self.params.dt || ratio <= 0.0 {
            return grown;
        }
        let room = 0.9 * self.params.max_displacement_ratio / ratio;
        grown.min(self.dt_current * room.max(1.0))
    }

    /// Adds the generalised forces the closed contacts exert on the blocks: the normal
    /// and shear forces of their memory along the gradients of `self.contacts`. (A vertex
    /// that has just moved on to the next edge of a polyline — a dish's next facet —
    /// carries the old edge's memory: missing its force here once made the dish's slider
    /// lose its weight for a step at every facet it crossed.)
    fn add_contact_forces(&self, out: &mut [Vec6]) {
        for c in &self.contacts {
            let Some(m) = contact::remembered(
                &self.memory,
                c.key,
                c.memory_hint(),
                &self.blocks[c.key.edge_block],
            ) else {
                continue;
            };
            if !m.state.is_closed() {
                continue;
            }
            let shear = m.shear_multiplier - c.props.shear_penalty * m.shear;
            c.add_forces(m.normal_force, shear, out);
        }
    }

    /// Makes the integrator's accelerations balance the forces of the geometry a step has
    /// just moved to. A step balances the forces linearised about its start (`before`,
    /// from [`Dda::configuration_forces`] with its increments); at the moved geometry the
    /// same stresses give slightly different forces (`after`: the joints have turned, the
    /// blocks' areas changed). Carrying the old accelerations into the next step would
    /// apply that difference as an unbooked impulse: it did work of O(Δt) per unit time
    /// against a gravity preload (the three-storey frame gained energy from gravity and
    /// crept from its settled state). The accelerations take up the difference instead,
    /// so each step's trapezoidal work is exactly the change of the stored energy.
    /// `after` is overwritten with the forces the accelerations take up.
    pub(super) fn rebalance_accelerations(
        &mut self,
        old_inertia: &[Vec6],
        before: &[Vec6],
        after: &mut [Vec6],
    ) {
        for ((f, old), before) in after.iter_mut().zip(old_inertia).zip(before) {
            *f = std::array::from_fn(|i| old[i] + f[i] - before[i]);
        }
        let forces = after;
        let moving = |b: &Block| b.role != BlockRole::PrescribedGround;
        let mut solved = PerBlock::new();
        solve_masses_into(&self.blocks, forces, moving, &mut solved);
        for (b, x) in self.blocks.iter_mut().zip(&solved) {
            let Some(x) = x else {
                continue;
            };
            for (i, &xi) in x.iter().enumerate().take(b.moving_unknowns()) {
                b.accel[i] += xi - b.response_accel[i];
                b.response_accel[i] = xi;
            }
        }
    }
}

/// The start state of a step before its opening contacts were released.
pub(super) struct Released {
    accelerations: Vec<[Vec6; 2]>,
    memory: ContactMemories,
}

/// The size of a step of nominal size `nominal` that may not go past `max_dt`. A remainder
/// up to a millionth longer than the nominal step is taken whole: the times a run is asked
/// to reach (the visualizer's frames, 0.01 s apart) are sums of steps that round, and
/// stopping one nominal step short of them left a step of 1e-12 s, whose acceleration on
/// a stiff contact is noise (a 2.5 g spike in a bonded slider's replay, 930 g on screen).
fn step_size(nominal: f64, max_dt: f64) -> f64 {
    if max_dt <= nominal * (1.0 + 1e-6) {
        max_dt
    } else {
        nominal
    }
}

/// The work of a closed (augmented-Lagrangian) contact's tangential force on its slip
/// over a step, split as the ledger books it: `(friction, constraint, relabelled)`.
/// `end_force`: the tangential multiplier it ends the step with.
///
/// Like every force of the ledger, the force is the average of the step's two ends: the
/// multiplier the contact started with and the one it ends with (the friction of a
/// sliding end, the stick force of a locked one, none for an open one). A contact that
/// slides and ends closed dissipates it as friction. A stuck contact's, and that of one
/// that opens, is the work of a constraint the scheme applied (on an unconverged slip, or
/// at half its start value while the vertex moves off), booked with the normal
/// constraint work: a toppling block's corners, sliding under 2e6 N after it landed on
/// its side, lift off within a step while their slip reverses, and their start
/// friction's average (a 156 J gain) was booked nowhere. An impact step applies its end
/// force only (its start force can be an impulse over 1e-7 s, whose average with the end
/// over a full step booked 1.2 MJ of friction against 14 kJ of input): its friction is
/// the end force's work and the rest of the average is relabelled as the impact's.
fn tangential_work(ct: &Contact, end_force: f64, slip: f64, impact: bool) -> (f64, f64, f64) {
    let average = -0.5 * (ct.start_shear_multiplier + end_force) * slip;
    let slid_to_a_close = ct.state.is_closed()
        && [ct.state, ct.start_state]
            .iter()
            .any(|s| matches!(s, ContactState::Sliding { .. }));
    if !slid_to_a_close {
        (0.0, average, 0.0)
    } else if impact {
        let end = -end_force * slip;
        (end, 0.0, average - end)
    } else {
        (average, 0.0, 0.0)
    }
}

/// Whether `p` lies within the angle the radii from `center` to the arc's `ends` span
/// (an arc of less than half a turn, as a dish's is).
fn within_span(center: Point, ends: [Point; 2], p: Point) -> bool {
    let [v0, v1] = ends.map(|e| geometry::sub(e, center));
    let vp = geometry::sub(p, center);
    let turn = geometry::cross(v0, v1).signum();
    geometry::cross(v0, vp) * turn >= 0.0 && geometry::cross(vp, v1) * turn >= 0.0
}

#[cfg(test)]
mod step_size_tests {
    use super::step_size;

    #[test]
    fn a_remainder_a_hair_past_the_step_is_taken_whole() {
        assert_eq!(step_size(1e-3, 1e-3 + 1e-12), 1e-3 + 1e-12);
        assert_eq!(step_size(1e-3, 5e-4), 5e-4);
        assert_eq!(step_size(1e-3, 2.5e-3), 1e-3);
    }
}
