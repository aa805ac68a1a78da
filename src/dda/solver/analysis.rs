//! Analyses outside the time stepping: static equilibrium (settle), the tangent stiffness and the modes.

use super::*;

impl Dda {
    /// Static equilibrium under gravity and loads (the ground does not move).
    pub(super) fn settle(&mut self) -> Result<()> {
        self.forget_next_step_detection();
        // The weight is first let down on joints free to slip: a base slab that spreads
        // under its load (Poisson) then does not leave the joint's shear springs holding a
        // self-equilibrated force (at the frame's preload, most of ρN, so that the first
        // tremor of the ground would make its ends slip). The joints then start stuck with
        // no shear. Where that has no equilibrium (a block on a slope), the settle is done
        // with Coulomb's law, and where even that has none (a slope too steep to hold), with
        // every joint held; the first dynamic step then decides whether they slide.
        let saved_memory = self.memory.clone();
        if self.settle_with(Some(0.0)).is_ok() {
            // Refined free to slip too where that converges: each refinement moves the
            // blocks a little (the frame's connections take the strain of their moved
            // shape), and refined on held joints those moves were left to the joints'
            // shear springs — a self-equilibrated shear of ~40 J that a frictionless run
            // let go in its first steps, ringing the frame. Where the refinements free to
            // slip do not converge, they are undone. (A frame on pendulum bearings drifted
            // down its dishes' slope while their contacts had no curvature stiffness:
            // see `Dda::add_curvature_stiffness`.)
            let settled = self.clone();
            if !self.refines_free_to_slip() {
                *self = settled;
            }
            self.forget_next_step_detection();
            for m in self.memory.values_mut() {
                if m.state.is_closed() {
                    m.state = ContactState::Locked;
                    m.shear = 0.0;
                }
            }
            return self.refine_settlement(Some(f64::INFINITY));
        }
        self.restore_memory(saved_memory.clone());
        if self.settle_with(None).is_ok() {
            return self.refine_settlement(None);
        }
        self.restore_memory(saved_memory);
        self.settle_with(Some(f64::INFINITY))?;
        self.refine_settlement(Some(f64::INFINITY))
    }

    /// Repeats the static solve from the settled geometry until it no longer moves. One
    /// solve balances the forces linearised about the unloaded geometry; at the geometry
    /// it reaches, the stresses it carries give slightly different forces (the joints
    /// turned, the blocks changed area: 2 % under the frame's heavy floors), and a dynamic
    /// step would start out of balance and ring. Each repetition solves for that
    /// remainder (a Newton iteration without the geometric stiffness, converging as the
    /// preload is far from buckling).
    fn refine_settlement(&mut self, friction: Option<f64>) -> Result<()> {
        self.refine(friction, false).map(|_| ())
    }

    /// Refines the settlement with every joint free to slip while each refinement moves
    /// the blocks less than the one before; whether it came to rest.
    fn refines_free_to_slip(&mut self) -> bool {
        self.refine(Some(0.0), true).unwrap_or(false)
    }

    /// The refinements of [`Dda::refine_settlement`]; whether they came to rest: a move
    /// below 1e-14 of the structure's size, or one that no longer shrinks below 1e-12 (the
    /// connections' strain is read from the nodes' positions, whose round-off leaves
    /// moves of a few 1e-14). With `stop_if_growing`, a move larger than the one before
    /// ends them (not at rest).
    fn refine(&mut self, friction: Option<f64>, stop_if_growing: bool) -> Result<bool> {
        const MAX_REFINEMENTS: usize = 50;
        let mut previous = f64::INFINITY;
        for _ in 0..MAX_REFINEMENTS {
            let ratio = self.settle_with(friction)?;
            if ratio <= 1e-14 || (ratio >= previous && previous <= 1e-12) {
                return Ok(true);
            }
            if ratio >= previous && stop_if_growing {
                return Ok(false);
            }
            previous = ratio;
        }
        Ok(false)
    }

    /// One static solve and its commit; returns the largest vertex displacement it made,
    /// over the structure size.
    pub(super) fn settle_with(&mut self, friction: Option<f64>) -> Result<f64> {
        let known = vec![[0.0; 6]; self.blocks.len()];
        self.detect_contacts();
        let mut increments = PerBlock::new();
        let Ok(_) = self.iterate(Mode::Static { friction }, &known, &mut increments)? else {
            return Err(Error::Solver {
                time: 0.0,
                reason: "the initial equilibrium under gravity did not settle (contact states \
                         keep changing); check that blocks rest on each other"
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
                     under gravity: it is not supported ({})",
                    self.blocks[block].name,
                    self.support_hint(block)
                ),
            });
        }
        self.commit_geometry(&increments)?;
        Ok(ratio)
    }

    /// What to do about an unsupported `block`: declare a contact if it has none; if it
    /// has some but touches none of those blocks at the start, it floats above them.
    fn support_hint(&self, block: usize) -> String {
        let partners: Vec<&str> = (self.pairs.iter())
            .filter_map(|p| match p.blocks {
                [a, b] if a == block => Some(b),
                [a, b] if b == block => Some(a),
                _ => None,
            })
            .map(|other| self.blocks[other].name.as_str())
            .collect();
        let touches = (self.contacts.iter())
            .any(|c| c.key.vertex_block == block || c.key.edge_block == block);
        match (partners.is_empty(), touches) {
            (true, _) => "declare a contact with the block it rests on, or a bolt or fixed \
                          point that holds it"
                .into(),
            (false, false) => format!(
                "it has contacts with '{}' but touches none of them at the start: place it \
                 on the block it rests on, or hold it with a bolt or fixed point",
                partners.join("', '")
            ),
            (false, true) => "the blocks under it are not held either: declare their \
                              contacts down to the ground, or bolts or fixed points"
                .into(),
        }
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
    pub(super) fn out_of_balance(&mut self) -> DVector<f64> {
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
}
