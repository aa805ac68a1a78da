//! The structure's own damping in a step: the bolts' dashpots and Rayleigh damping (see
//! [`crate::dda::rayleigh`]), assembled into the step's system and booked in the ledger.
//!
//! Every damping force is c·v at the step's end (where the integrator balances every
//! force), with the end velocity of a free block from the Newmark update,
//! v₁ = γ/(βΔt)·D + w (linear in the increment D), so a dashpot adds c·γ/(βΔt) to the
//! stiffness and its predictor part to the right-hand side. The ledger books, like every
//! other force, the average of the force at the step's two ends times the increment.

use super::*;
use crate::dda::rayleigh::RayleighDamping;

/// One scalar dashpot: coefficient, block i and the map of its unknowns to the relative
/// velocity, block j and its map (q̇ = a·v_i + b·v_j).
type DashpotRow = (f64, usize, Vec6, usize, Vec6);

impl Dda {
    /// Rayleigh damping of the structure standing on the block `base` (its base slab): a
    /// mass-proportional dashpot from every other free block's centroid to the base slab,
    /// and a stiffness-proportional one on every free block's strain and every connection
    /// element. Set it before the first step. The ground and the sliding joint are never
    /// damped by it.
    pub fn set_rayleigh_damping(&mut self, damping: RayleighDamping, base: &str) -> Result<()> {
        let [a0, a1] = [damping.mass_coefficient, damping.stiffness_coefficient];
        if !(a0.is_finite() && a0 >= 0.0 && a1.is_finite() && a1 >= 0.0) {
            return Err(Error::invalid(
                "Rayleigh damping",
                format!("coefficients must be finite and not negative, got a₀ = {a0}, a₁ = {a1}"),
            ));
        }
        let base = self.block_index(base)?;
        if self.dofs.slot[base].is_none() {
            return Err(Error::invalid(
                "Rayleigh damping",
                "the base slab must be a free block, not the ground",
            ));
        }
        self.rayleigh = Some((damping, base));
        // The mass-proportional dashpots couple the base slab with every block.
        self.pattern = Arc::new(coupling_pattern(
            &self.dofs,
            &self.pairs,
            &self.bolts,
            &self.fixed,
            &self.connections,
            Some(base),
        ));
        self.linear = analysed(&self.pattern)?;
        self.pass_system = None;
        self.base_system = None;
        Ok(())
    }

    /// The structure's scalar dashpots: the bolts' (along their directions, between their
    /// two points) and Rayleigh's mass-proportional ones (x and y, from each free block's
    /// centroid to the base slab's material point there), at the step start.
    pub(super) fn structural_dashpot_rows(&self) -> Vec<DashpotRow> {
        let centroids = self.centroids();
        let mut rows = Vec::new();
        for bolt in &self.bolts {
            let [i, j] = bolt.blocks;
            for e in bolt.dashpot_directions() {
                let a = t_transpose_times(centroids[i], bolt.points[0], [-e[0], -e[1]]);
                let b = t_transpose_times(centroids[j], bolt.points[1], e);
                rows.push((bolt.damping, i, a, j, b));
            }
        }
        if let Some((
            RayleighDamping {
                mass_coefficient, ..
            },
            base,
        )) = self.rayleigh
        {
            for (i, block) in self.blocks.iter().enumerate() {
                if i == base || self.dofs.slot[i].is_none() || mass_coefficient == 0.0 {
                    continue;
                }
                let c = mass_coefficient * block.total_mass();
                for e in [[1.0, 0.0], [0.0, 1.0]] {
                    let a = t_transpose_times(centroids[i], centroids[i], [-e[0], -e[1]]);
                    let b = t_transpose_times(centroids[base], centroids[i], e);
                    rows.push((c, i, a, base, b));
                }
            }
        }
        rows
    }

    /// The connections' part of the joints' terms (listed after the bolts' and fixed
    /// points', as [`Dda::element_terms_into`] lists them).
    fn connection_terms<'a>(&self, elements: &'a [ElementTerms]) -> &'a [ElementTerms] {
        &elements[self.bolts.len() + self.fixed.len()..]
    }

    /// Adds the structure's damping to a dynamic step's system: its scalar dashpots and
    /// Rayleigh's stiffness-proportional part. `elements` are the step's joint terms
    /// (bolts, fixed points, then connections, as [`Dda::element_terms_into`] lists them).
    pub(super) fn add_structural_damping(
        &self,
        sys: &mut System,
        elements: &[ElementTerms],
        dt: f64,
    ) {
        for (damping, i, a, j, b) in self.structural_dashpot_rows() {
            self.add_dashpot(sys, damping, (i, &a), (j, &b), dt);
        }
        let Some((
            RayleighDamping {
                stiffness_coefficient: a1,
                ..
            },
            _,
        )) = self.rayleigh
        else {
            return;
        };
        if a1 == 0.0 {
            return;
        }
        let co = &self.coeffs;
        let gain = co.gamma / (co.beta * dt);
        // The end velocity less its increment part.
        let predicted: PerBlock<Vec6> = self
            .blocks
            .iter()
            .enumerate()
            .map(|(bi, b)| match self.dofs.slot[bi] {
                Some(_) => {
                    std::array::from_fn(|k| co.velocity_predictor(b.velocity[k], b.accel[k], dt))
                }
                None => [0.0; 6],
            })
            .collect();
        for (bi, b) in self.blocks.iter().enumerate() {
            let Some(s) = self.dofs.slot[bi] else {
                continue;
            };
            let c = a1 * b.moments.area;
            let k = sys.stiffness_factor * c * gain;
            let diagonal = sys.k.diagonal_mut(s / 6);
            for i in 0..3 {
                for j in 0..3 {
                    diagonal[3 + i][3 + j] += k * b.elasticity[i][j];
                }
            }
            for i in 0..3 {
                let f: f64 = (0..3)
                    .map(|j| b.elasticity[i][j] * predicted[bi][3 + j])
                    .sum();
                sys.r[s + 3 + i] -= c * f;
            }
        }
        let centroids = self.centroids();
        // The ground stands still in the moving frame: its known increment is zero here.
        let still: PerBlock<Vec6> = self.blocks.iter().map(|_| [0.0; 6]).collect();
        for terms in self.connection_terms(elements) {
            let velocities = node_velocities(terms, &centroids, &predicted);
            let damped = terms.as_dashpot(a1, gain, &velocities);
            sys.add_nodal_element(&self.dofs, &still, &centroids, &damped);
        }
    }

    /// The work of the structure's damping in a step (booked as `structural_damping`):
    /// the average of its forces at the step's two ends times the increments. `start`
    /// holds the blocks' velocities at the step start; the blocks hold the end ones.
    pub(super) fn structural_damping_work(&self, start: &[[Vec6; 2]], increments: &[Vec6]) -> f64 {
        let mut work = 0.0;
        for (damping, i, a, j, b) in self.structural_dashpot_rows() {
            let q0 = self.directional_velocity(i, &a, j, &b, &|k| start[k][0]);
            let q1 = self.directional_velocity(i, &a, j, &b, &|k| self.blocks[k].velocity);
            work +=
                damping * 0.5 * (q0 + q1) * (dot6(&a, &increments[i]) + dot6(&b, &increments[j]));
        }
        let Some((
            RayleighDamping {
                stiffness_coefficient: a1,
                ..
            },
            _,
        )) = self.rayleigh
        else {
            return work;
        };
        let mean: PerBlock<Vec6> = self
            .blocks
            .iter()
            .zip(start)
            .map(|(b, [v0, _])| std::array::from_fn(|k| 0.5 * (v0[k] + b.velocity[k])))
            .collect();
        for (bi, b) in self.blocks.iter().enumerate() {
            if self.dofs.slot[bi].is_none() {
                continue;
            }
            let d = &increments[bi];
            for i in 0..3 {
                for j in 0..3 {
                    work += a1 * b.moments.area * mean[bi][3 + i] * b.elasticity[i][j] * d[3 + j];
                }
            }
        }
        let centroids = self.centroids();
        // The step's own connection terms (the joints have not moved since its assembly).
        debug_assert!(self.elements_current);
        for terms in self.connection_terms(&self.elements) {
            let v = node_velocities(terms, &centroids, &mean);
            let u = node_velocities(terms, &centroids, increments);
            let ke = terms.ke();
            let n = 2 * terms.nodes().len();
            for r in 0..n {
                for s in 0..n {
                    work += a1 * v[r] * ke[r * n + s] * u[s];
                }
            }
        }
        work
    }
}

/// The velocities (or displacements) of an element's nodes, flattened (x₁, y₁, x₂, …),
/// from their blocks' generalised velocities.
fn node_velocities(
    terms: &ElementTerms,
    centroids: &[Point],
    per_block: &[Vec6],
) -> [f64; 2 * MAX_NODES] {
    let mut out = [0.0; 2 * MAX_NODES];
    for (k, &(b, x)) in terms.nodes().iter().enumerate() {
        let v = point_displacement(centroids[b], x, &per_block[b]);
        out[2 * k] = v[0];
        out[2 * k + 1] = v[1];
    }
    out
}
