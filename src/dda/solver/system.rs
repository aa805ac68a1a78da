//! Assembling a step's linear system: elements, contacts, dashpots.

use super::*;

impl Dda {
    pub(super) fn element_terms(&self) -> Vec<ElementTerms> {
        let mut out = Vec::new();
        self.element_terms_into(&mut out);
        out
    }

    /// This step's terms of every joint, into `out` (its entries are overwritten: the
    /// connections' terms are rebuilt in place, see
    /// [`crate::dda::joints::ConnectionGroups::terms_into`]).
    pub(super) fn element_terms_into(&self, out: &mut Vec<ElementTerms>) {
        for (index, bolt) in self.bolts.iter().enumerate() {
            bolt.terms_into(out, index);
        }
        for (index, point) in (self.bolts.len()..).zip(&self.fixed) {
            point.terms_into(out, index);
        }
        // A connection's triangles share their nodes: merged, each gap is one element.
        let from = self.bolts.len() + self.fixed.len();
        self.connection_groups
            .terms_into(&self.connections, out, from);
    }

    /// Makes `self.elements` the terms of the joints as they are now (computing them only
    /// if the joints moved since they were last computed).
    pub(super) fn refresh_element_terms(&mut self) {
        if !self.elements_current {
            let mut elements = std::mem::take(&mut self.elements);
            self.element_terms_into(&mut elements);
            self.elements = elements;
            self.elements_current = true;
        }
    }

    /// Assembles everything that does not depend on contact states (into a new system).
    pub(super) fn assemble_base(
        &self,
        mode: Mode,
        known: &[Vec6],
        elements: &[ElementTerms],
    ) -> System {
        let mut sys = System::zeros(Arc::clone(&self.pattern), 1.0);
        self.assemble_base_into(&mut sys, mode, known, elements);
        sys
    }

    /// Assembles everything that does not depend on contact states into `sys` (same
    /// pattern; its values are overwritten).
    pub(super) fn assemble_base_into(
        &self,
        sys: &mut System,
        mode: Mode,
        known: &[Vec6],
        elements: &[ElementTerms],
    ) {
        let c = &self.coeffs;
        let (mass_factor, stiffness_factor) = match mode {
            // Every force at the step's end (see the integrator): the stiffness is whole.
            Mode::Dynamic { dt } => (c.mass_factor(dt), 1.0),
            // A vanishing "mass spring" (1 mHz) only so that unloaded rigid-body modes (a
            // roof hung on one bolt can still turn) do not make the static matrix singular.
            Mode::Static { .. } => ((2.0 * std::f64::consts::PI * 1e-3_f64).powi(2), 1.0),
            Mode::Modal => (0.0, 1.0),
        };
        sys.clear(stiffness_factor);
        // The ground's acceleration at the step's end, once for all blocks.
        let frame_accel = match mode {
            Mode::Dynamic { dt } => self.frame_accel(self.time + dt),
            _ => [0.0; 2],
        };
        for (bi, b) in self.blocks.iter().enumerate() {
            let Some(s) = self.dofs.slot[bi] else {
                continue;
            };
            // A rigid block's strain rows and columns are held after assembly (see
            // `DofMap::moving`): its mass there and its elastic stiffness are not added.
            let moving = self.dofs.moving[bi];
            sys.add_diag_block_leading(s, &b.mass, mass_factor, moving);
            // Elastic stiffness on the strain unknowns and the initial-stress force.
            if moving == 6 {
                let diagonal = sys.k.diagonal_mut(s / 6);
                for i in 0..3 {
                    for j in 0..3 {
                        diagonal[3 + i][3 + j] +=
                            stiffness_factor * b.moments.area * b.elasticity[i][j];
                    }
                }
            }
            for i in 0..3 {
                sys.r[s + 3 + i] -= b.moments.area * b.stress[i];
            }
            // Gravity.
            sys.r[s + 1] -= b.total_mass() * self.gravity;
            if let Mode::Dynamic { dt } = mode {
                // Inertia from the previous step: the balanced end acceleration's part
                // that does not grow with the increment.
                let mut w = [0.0; 6];
                for k in 0..6 {
                    w[k] = c.inertia_predictor(b.velocity[k], b.accel[k], b.response_accel[k], dt);
                }
                for i in 0..6 {
                    let mw: f64 = (0..6).map(|j| b.mass[i][j] * w[j]).sum();
                    sys.r[s + i] -= mw;
                }
                // The frame moves with the ground: every block feels −m ü0 (both
                // components when the ground also shakes vertically). The paper's
                // large-mass ground is driven by f = m_g ü0 (eq. 4), which cancels it.
                if b.role != BlockRole::LargeMassGround {
                    let [ax, ay] = frame_accel;
                    sys.r[s] -= b.total_mass() * ax;
                    sys.r[s + 1] -= b.total_mass() * ay;
                }
            }
        }
        let centroids = self.centroids();
        for e in elements {
            sys.add_nodal_element(&self.dofs, known, &centroids, e);
        }
        if let Mode::Dynamic { dt } = mode {
            self.add_structural_damping(sys, elements, dt);
        }
        for l in &self.loads {
            if let Some(s) = self.dofs.slot[l.block] {
                let f = t_transpose_times(centroids[l.block], l.point, l.force);
                sys.add_rhs(s, &f, 1.0);
            }
        }
    }

    /// Adds the contact terms of the current trial states.
    pub(super) fn add_contacts(&self, sys: &mut System, known: &[Vec6], mode: Mode) {
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
            // Every closed contact resists approach; what acts along it depends on the state.
            let p = c.props.normal_penalty;
            let normal = (p, p * c.gap0 - lambda_n, &c.gap_i, &c.gap_j);
            match c.state {
                ContactState::Open => {}
                ContactState::Locked => {
                    let ps = c.props.shear_penalty;
                    let shear = (ps, ps * c.shear0 - lambda_s, &c.slip_i, &c.slip_j);
                    // Both springs' matrices in one pass over the pair's four blocks.
                    for (k, f0, a, b) in [normal, shear] {
                        sys.add_scalar_spring_rhs(&self.dofs, known, k, f0, (i, a), Some((j, b)));
                    }
                    let springs = [normal, shear].map(|(k, _, a, b)| (k, a, b));
                    sys.add_scalar_springs_matrix(&self.dofs, (i, j), springs);
                }
                ContactState::Sliding { direction } => {
                    let (k, f0, a, b) = normal;
                    sys.add_scalar_spring(&self.dofs, known, k, f0, (i, a), Some((j, b)));
                    // Friction: −δρN along the slip direction on the vertex, +δρN on the edge;
                    // as generalised forces that is −δρN·(slip_i, slip_j).
                    let friction = match mode {
                        Mode::Static { friction: Some(f) } => f,
                        _ => c.sliding_coefficient,
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
            if let (Mode::Static { .. }, true) = (mode, c.state.is_closed()) {
                self.add_curvature_stiffness(sys, known, c);
            }
        }
    }

    /// A static solve's stiffness of a closed contact on a curved surface along its
    /// slip: the normal force N turns with the vertex as it slides, by κ per metre, and
    /// pulls it back with N·κ per metre (a dish's pendulum stiffness, W/R for a slider).
    /// The linear solve has no other stiffness there: two corners of a rigid slider free
    /// to slip on a dish leave it a mechanism about the dish's centre, held only by the
    /// settle's 1 mHz mass spring, ~1e-18 of the constraint penalties, and whether the
    /// factorisation saw it as positive depended on round-off (six radii of 60 between
    /// 0.5 and 1.3 m did not start). The term acts on the increments only, so the
    /// refined equilibrium is the same. N is the normal multiplier where the last pass
    /// found one, else the vertex block's weight (the first pass after closing).
    fn add_curvature_stiffness(&self, sys: &mut System, known: &[Vec6], c: &Contact) {
        if c.curvature == 0.0 {
            return;
        }
        let (i, j) = (c.key.vertex_block, c.key.edge_block);
        let normal = if c.normal_multiplier > 0.0 {
            c.normal_multiplier
        } else {
            self.blocks[i].total_mass() * self.gravity.abs()
        };
        let k = normal * c.curvature;
        sys.add_scalar_spring(
            &self.dofs,
            known,
            k,
            0.0,
            (i, &c.slip_i),
            Some((j, &c.slip_j)),
        );
    }

    /// Dashpot coefficients (normal, shear) of a contact in its trial state.
    pub(super) fn dashpot_coefficients(&self, c: &Contact) -> (f64, f64) {
        let zeta = self.params.contact_damping;
        if zeta == 0.0 || !c.state.is_closed() {
            return (0.0, 0.0);
        }
        // (At the penalties of a nominal step: a shortened step's stiffer constraints
        // are an iteration device, not a stiffer contact.)
        let crit = |p: f64| 2.0 * zeta * (p / self.penalty_boost * c.damping_mass).sqrt();
        let shear = if c.state == ContactState::Locked {
            crit(c.props.shear_penalty)
        } else {
            0.0
        };
        (crit(c.props.normal_penalty), shear)
    }

    /// Relative velocity along a contact direction: a·v_i + b·v_j.
    pub(super) fn directional_velocity(
        &self,
        i: usize,
        a: &Vec6,
        j: usize,
        b: &Vec6,
        vel: &dyn Fn(usize) -> Vec6,
    ) -> f64 {
        dot6(a, &vel(i)) + dot6(b, &vel(j))
    }

    /// Adds the dashpots of a closed contact (see [`Dda::add_dashpot`]).
    pub(super) fn add_dashpots(&self, sys: &mut System, c: &Contact, dt: f64) {
        let (cn, cs) = self.dashpot_coefficients(c);
        let (i, j) = (c.key.vertex_block, c.key.edge_block);
        for (damping, a, b) in [(cn, &c.gap_i, &c.gap_j), (cs, &c.slip_i, &c.slip_j)] {
            self.add_dashpot(sys, damping, (i, a), (j, b), dt);
        }
    }

    /// Adds a dashpot of coefficient `damping` on the relative velocity q = a·v_i + b·v_j:
    /// force c·q at the step's end, with the velocity of a free block from the
    /// Newmark update (linear in the increment) and that of the prescribed ground (which
    /// stands still in the moving frame) zero.
    pub(super) fn add_dashpot(
        &self,
        sys: &mut System,
        damping: f64,
        (i, a): (usize, &Vec6),
        (j, b): (usize, &Vec6),
        dt: f64,
    ) {
        if damping == 0.0 {
            return;
        }
        let co = &self.coeffs;
        // v_{n+1} = γ/(βΔt)·D + w.
        let mut f0 = 0.0;
        let mut parts: SmallVec<[(usize, &Vec6); 2]> = SmallVec::new();
        for (blk, vec) in [(i, a), (j, b)] {
            let bl = &self.blocks[blk];
            if self.dofs.slot[blk].is_some() {
                let mut w = [0.0; 6];
                for k in 0..6 {
                    w[k] = co.velocity_predictor(bl.velocity[k], bl.accel[k], dt);
                }
                f0 += damping * dot6(vec, &w);
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
