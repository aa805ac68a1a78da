//! One DDA block: 6 unknowns at the centroid, its mass and elastic matrices.

use crate::Result;
use crate::model::geometry::{self, Moments, Point};
use crate::model::material::Material;
use crate::model::scene::ArcDef;

/// Six block unknowns `(u0, v0, r0, εx, εy, γxy)` or a 6-vector of generalised forces.
pub type Vec6 = [f64; 6];
/// A 6×6 block of the global matrix.
pub type Mat6 = [[f64; 6]; 6];

/// The 2×6 displacement map T(x, y) of dda-theory §1 about centroid `c`.
#[inline]
pub fn t_matrix(c: Point, p: Point) -> [[f64; 6]; 2] {
    let (x, y) = (p[0] - c[0], p[1] - c[1]);
    [
        [1.0, 0.0, -y, x, 0.0, y / 2.0],
        [0.0, 1.0, x, 0.0, y, x / 2.0],
    ]
}

/// `T(p)ᵀ f`: the generalised force of a point force `f` at `p`, or the 6-vector whose dot
/// product with D gives the displacement of `p` along `f`.
#[inline]
pub fn t_transpose_times(c: Point, p: Point, f: Point) -> Vec6 {
    t_transpose_at(geometry::sub(p, c), f)
}

/// `T(p)ᵀ f` for a point at `offset` = p − c from its block's centroid. The rows of
/// [`t_matrix`] are `[1, 0, −y, x, 0, y/2]` and `[0, 1, x, 0, y, x/2]`, so this is six
/// products instead of twelve (the skipped terms are exact multiplications by one and
/// zero). The frame's connection assembly runs it ~20 times per element per step, and the
/// contact linearisation five times per contact.
#[inline]
pub fn t_transpose_at(offset: Point, f: Point) -> Vec6 {
    let (x, y) = (offset[0], offset[1]);
    let (a, b) = (f[0], f[1]);
    [
        a,
        b,
        -y * a + x * b,
        x * a,
        y * b,
        y / 2.0 * a + x / 2.0 * b,
    ]
}

/// Displacement of point `p` under block unknowns `d` (linear map T·D).
#[inline]
pub fn point_displacement(c: Point, p: Point, d: &Vec6) -> Point {
    let t = t_matrix(c, p);
    let mut u = [0.0; 2];
    for k in 0..6 {
        u[0] += t[0][k] * d[k];
        u[1] += t[1][k] * d[k];
    }
    u
}

/// The map a step applies to a block's points about its centroid: `x − c ↦ (R + S)(x − c)`
/// plus the translation, computed once per block and step rather than per vertex.
///
/// With the exact update, R is the true rotation by `r0` (a turning block keeps its area)
/// and S the strain increment `ΔE = [[εx, γ/2], [γ/2, εy]]` applied as `exp(ΔE) − I` to
/// second order, `ΔE + ½ΔE²`. Applied as plain `ΔE`, the step would scale the area by
/// `det(I + ΔE)`, which loses `γ²/4` at every step a shear increment γ takes, whatever its
/// sign: a shear that alternates from step to step (a stiff mode at the step's Nyquist
/// frequency, which the trapezoidal rule does not damp) shrank the three-storey frame's
/// columns by 4.6e-7 of their area over the Chi-Chi record with no stress to resist it.
/// `det(exp(ΔE)) = exp(εx + εy)`, so the area follows the accumulated volumetric strain
/// (to third order per step) whatever path it took. The departure from the linear
/// motion the step was solved with is second order, as the rotation's is, and the
/// contacts book it the same way (the constraint work in `Dda::commit_step`).
///
/// The classic update is the paper's linear map `T·D`: R = I + r0·J and S = ΔE.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepMap {
    /// Sine of the rotation (r0 itself for the linear map).
    pub sin: f64,
    /// Cosine of the rotation (1 for the linear map).
    pub cos: f64,
    /// The strain part S of the map, symmetric.
    pub strain: [[f64; 2]; 2],
}

impl StepMap {
    /// The map of increment `d`, exact or the paper's linear one.
    #[inline]
    pub fn new(d: &Vec6, exact: bool) -> Self {
        let (ex, ey, g) = (d[3], d[4], d[5] / 2.0);
        if !exact {
            return Self {
                sin: d[2],
                cos: 1.0,
                strain: [[ex, g], [g, ey]],
            };
        }
        let (sin, cos) = d[2].sin_cos();
        // ΔE² = [[εx² + g², g(εx + εy)], [g(εx + εy), εy² + g²]].
        let off = g + 0.5 * g * (ex + ey);
        Self {
            sin,
            cos,
            strain: [
                [ex + 0.5 * (ex * ex + g * g), off],
                [off, ey + 0.5 * (ey * ey + g * g)],
            ],
        }
    }

    /// The 2×2 matrix `R + S` that maps arms from the centroid.
    fn matrix(&self) -> [[f64; 2]; 2] {
        let s = self.strain;
        [
            [self.cos + s[0][0], -self.sin + s[0][1]],
            [self.sin + s[1][0], self.cos + s[1][1]],
        ]
    }
}

/// Displacement of `p` under `d` with the block's step map (see [`StepMap`]).
#[inline]
pub fn displacement_with_map(c: Point, p: Point, d: &Vec6, map: &StepMap) -> Point {
    let (x, y) = (p[0] - c[0], p[1] - c[1]);
    let m = map.matrix();
    [
        d[0] + (m[0][0] - 1.0) * x + m[0][1] * y,
        d[1] + m[1][0] * x + (m[1][1] - 1.0) * y,
    ]
}

/// The velocity unknowns of a block after it has moved by the increment `d` under the
/// step map `map` (see [`StepMap`]), carried so that
/// every material point keeps its velocity's size and its kinetic energy is unchanged.
///
/// The unknowns describe the velocity field `v₀ + G (x − c)` about the current centroid,
/// `G = [[ε̇x, γ̇/2 − ṙ], [γ̇/2 + ṙ, ε̇y]]`. The step maps the block affinely by
/// `F = [[cos + εx, −sin + γ/2], [sin + γ/2, cos + εy]]`; taking the field to the new
/// geometry as `G' = R G F⁻¹` (R the step's rotation) keeps `tr(G J Gᵀ)` (J the second
/// moments of the mass, which become `F J Fᵀ`), hence the kinetic energy, exactly, and
/// keeps a rigid block's spin a spin. Left as they were, the unknowns would meet a mass
/// matrix turned and stretched by the step, and the kinetic energy would jump by
/// ½ vᵀ ΔM v at every step.
pub fn transport_velocity(v: &Vec6, map: &StepMap) -> Vec6 {
    let f = map.matrix();
    let det = f[0][0] * f[1][1] - f[0][1] * f[1][0];
    let f_inv = [
        [f[1][1] / det, -f[0][1] / det],
        [-f[1][0] / det, f[0][0] / det],
    ];
    let norm = map.sin.hypot(map.cos);
    let (s, c) = (map.sin / norm, map.cos / norm);
    let rot = [[c, -s], [s, c]];
    let g = [[v[3], v[5] / 2.0 - v[2]], [v[5] / 2.0 + v[2], v[4]]];
    let mul = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
        let mut m = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
            }
        }
        m
    };
    let g = mul(mul(rot, g), f_inv);
    [
        v[0],
        v[1],
        (g[1][0] - g[0][1]) / 2.0,
        g[0][0],
        g[1][1],
        g[0][1] + g[1][0],
    ]
}

/// Mass matrix `ρ ∫ TᵀT dA` for a block with these moments (dda-theory §3). Sparse because
/// T is taken about the centroid.
pub fn mass_matrix(density: f64, m: &Moments) -> Mat6 {
    let (s, s1, s2, s3) = (m.area, m.s1, m.s2, m.s3);
    let mut k = [[0.0; 6]; 6];
    k[0][0] = s;
    k[1][1] = s;
    k[2][2] = s1 + s2;
    k[2][3] = -s3;
    k[2][4] = s3;
    k[2][5] = (s1 - s2) / 2.0;
    k[3][3] = s1;
    k[3][5] = s3 / 2.0;
    k[4][4] = s2;
    k[4][5] = s3 / 2.0;
    k[5][5] = (s1 + s2) / 4.0;
    for i in 0..6 {
        for j in 0..i {
            k[i][j] = k[j][i];
        }
    }
    for row in k.iter_mut() {
        for v in row.iter_mut() {
            *v *= density;
        }
    }
    k
}

/// The frame of one polygon edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeFrame {
    /// Unit tangent, from the edge's first vertex to its second.
    pub tangent: Point,
    /// Outward unit normal (to the right of the tangent, the polygon being
    /// counter-clockwise).
    pub normal: Point,
    /// Length, m.
    pub length: f64,
}

/// The edge frames of a counter-clockwise polygon.
pub fn edge_frames(vertices: &[Point]) -> Vec<EdgeFrame> {
    let mut edges = Vec::with_capacity(vertices.len());
    update_edge_frames(vertices, &mut edges);
    edges
}

/// Recomputes the edge frames of a polygon in place.
fn update_edge_frames(vertices: &[Point], edges: &mut Vec<EdgeFrame>) {
    let n = vertices.len();
    edges.clear();
    edges.extend((0..n).map(|k| {
        let e = geometry::sub(vertices[(k + 1) % n], vertices[k]);
        // (Not `hypot`: its guard against overflow costs 50 instructions per edge per step,
        // and an edge of a validated polygon is nowhere near 1e150 m.)
        let length = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let tangent = [e[0] / length, e[1] / length];
        EdgeFrame {
            tangent,
            normal: [tangent[1], -tangent[0]],
            length,
        }
    }));
}

/// What drives a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlockRole {
    /// An ordinary block: its 6 unknowns are solved for.
    Free,
    /// The ground with prescribed motion: its unknowns are known each step.
    PrescribedGround,
    /// The paper's large-mass ground: solved for, driven by `m_g ü0(t)`.
    LargeMassGround,
}

/// A block's current state.
#[derive(Debug, Clone)]
pub struct Block {
    /// Name from the scene.
    pub name: String,
    /// Current vertices, counter-clockwise, m.
    pub vertices: Vec<Point>,
    /// Current moments (recomputed after every step).
    pub moments: Moments,
    /// Material.
    pub material: Material,
    /// Elasticity matrix C (σ = Cε), Pa.
    pub elasticity: [[f64; 3]; 3],
    /// Accumulated stress (σx, σy, τxy), Pa.
    pub stress: [f64; 3],
    /// Accumulated strain (εx, εy, γxy).
    pub strain: [f64; 3],
    /// Velocity of the 6 unknowns.
    pub velocity: Vec6,
    /// The integrator's acceleration variable of the 6 unknowns (for the generalised-α
    /// family it is not the acceleration at the step end: see `response_accel`).
    pub accel: Vec6,
    /// The acceleration at the current time: the one that balances the forces now.
    pub response_accel: Vec6,
    /// Mass matrix for the current geometry.
    pub mass: Mat6,
    /// Free, prescribed ground or large-mass ground.
    pub role: BlockRole,
    /// Unit tangent, outward normal and length of each edge (edge k runs from vertex k
    /// to vertex k + 1), kept with the vertices for the contact search.
    pub edges: Vec<EdgeFrame>,
    /// Centroid at the reference time (after initial equilibrium), m.
    pub reference_centroid: Point,
    /// Accumulated rotation r0 since the reference time, rad.
    pub rotation: f64,
    /// Rigid: the strain unknowns are held at zero.
    pub rigid: bool,
    /// Area of the unstressed block (as built), m²: a strained block keeps its mass,
    /// density × this area.
    pub rest_area: f64,
    /// Elastic energy stored in the block's strains, J per unit thickness: the work of
    /// its stresses on the strain increments (see [`Block::strain_energy`]).
    pub elastic_energy: f64,
    /// Runs of edges that are chords of a circle (a dish), which contacts see as the
    /// circle itself (see [`crate::dda::surface`]); each centre is a material point of
    /// the block, moved with it.
    pub arcs: Vec<ArcDef>,
}

impl Block {
    /// Builds a block at rest from its polygon and material.
    pub fn new(
        name: &str,
        vertices: Vec<Point>,
        material: Material,
        role: BlockRole,
    ) -> Result<Self> {
        let moments = geometry::moments(&vertices, name)?;
        Ok(Self {
            edges: edge_frames(&vertices),
            name: name.to_string(),
            mass: mass_matrix(material.density, &moments),
            reference_centroid: moments.centroid,
            vertices,
            moments,
            elasticity: material.elasticity(),
            material,
            stress: [0.0; 3],
            strain: [0.0; 3],
            velocity: [0.0; 6],
            accel: [0.0; 6],
            response_accel: [0.0; 6],
            role,
            rotation: 0.0,
            rigid: false,
            rest_area: moments.area,
            elastic_energy: 0.0,
            arcs: Vec::new(),
        })
    }

    /// Total mass per unit thickness, kg (constant: the density is that of the
    /// unstressed block, and a strained block keeps its mass).
    pub fn total_mass(&self) -> f64 {
        self.material.density * self.rest_area
    }

    /// Mass matrix of the current geometry: `ρ ∫ TᵀT dA` with the density the block's
    /// mass spread over its current area.
    pub fn current_mass_matrix(&self) -> Mat6 {
        mass_matrix(
            self.material.density * self.rest_area / self.moments.area,
            &self.moments,
        )
    }

    /// Centroid displacement since the reference time, m.
    pub fn centroid_displacement(&self) -> Point {
        geometry::sub(self.moments.centroid, self.reference_centroid)
    }

    /// Elastic energy of the block's strains, J per unit thickness: the work its stresses
    /// did on the strain increments, step by step, with the forces the steps balanced
    /// (`S σ` and the stiffness `S C`, S the area at the step start). For a block whose
    /// area does not change this is `½ S εᵀ C ε`; a strained block's area does change
    /// (2.4 % in the three-storey frame's columns under the floors' weight), and the
    /// closed form then differs from the work done on the block by ½ ΔS εᵀCε at each
    /// step — 1e-3 of the input energy over an earthquake, not a loss of the model but
    /// of the formula: the stress is accumulated from increments (hypo-elastic), so its
    /// energy is too.
    pub fn strain_energy(&self) -> f64 {
        self.elastic_energy
    }

    /// The unknowns that move: a rigid block's translation and rotation (its strains
    /// are held at zero), all six of a deformable one's.
    pub fn moving_unknowns(&self) -> usize {
        if self.rigid { 3 } else { 6 }
    }

    /// Kinetic energy `½ vᵀ M v`, J per unit thickness.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass_form(&self.velocity, &self.velocity)
    }

    /// `xᵀ M y` with the block's mass matrix, for vectors of its unknowns (a rigid
    /// block's strain entries are held at zero, and their terms are left out).
    pub fn mass_form(&self, x: &Vec6, y: &Vec6) -> f64 {
        if self.rigid {
            super::mat6::quadratic_form_rigid(&self.mass, x, y)
        } else {
            super::mat6::quadratic_form(&self.mass, x, y)
        }
    }

    /// A free block of unit density and stiffness (the geometry tests' block).
    #[cfg(test)]
    pub(crate) fn unit_for_tests(vertices: Vec<Point>) -> Self {
        let material = Material {
            density: 1.0,
            youngs_modulus: 1.0,
            poisson_ratio: 0.0,
            plane: Default::default(),
        };
        Self::new("b", vertices, material, BlockRole::Free).expect("a valid test polygon")
    }

    /// The arc whose chord edge `k` is, if any.
    pub fn arc_of(&self, k: usize) -> Option<&ArcDef> {
        self.arcs.iter().find(|a| a.holds_edge(k))
    }

    /// Moves the block by the step's unknowns `d`: vertices, stress, strain, moments and
    /// mass matrix are updated; velocity and acceleration are set by the integrator.
    pub fn apply_increment(&mut self, d: &Vec6, exact_rotation: bool) -> Result<()> {
        // A block that did not move and has no speed (the prescribed ground, every step)
        // keeps its geometry, moments, mass and velocity to the bit: recomputing them
        // from the same vertices gives the same values, at ~1 200 instructions a block.
        // (A moving block's velocity transport is not the identity to the bit.)
        if d.iter().chain(&self.velocity).all(|&x| x == 0.0) {
            return Ok(());
        }
        let c = self.moments.centroid;
        // The rotation's sine and cosine once for all vertices.
        let map = StepMap::new(d, exact_rotation);
        for p in self.vertices.iter_mut() {
            let u = displacement_with_map(c, *p, d, &map);
            p[0] += u[0];
            p[1] += u[1];
        }
        // An arc's centre moves as a material point (its radius is kept: the strain of a
        // dish, a ground block, is far below what would change its curvature).
        for arc in &mut self.arcs {
            let u = displacement_with_map(c, arc.center, d, &map);
            arc.center[0] += u[0];
            arc.center[1] += u[1];
        }
        let de = [d[3], d[4], d[5]];
        // The work of the step's strain forces S(σ + ½CΔε) on Δε (trapezoidal in σ, exact
        // for the linear stress update below).
        for i in 0..3 {
            let half_change: f64 = (0..3).map(|j| 0.5 * self.elasticity[i][j] * de[j]).sum();
            self.elastic_energy += self.moments.area * (self.stress[i] + half_change) * de[i];
        }
        for i in 0..3 {
            self.strain[i] += de[i];
            for j in 0..3 {
                self.stress[i] += self.elasticity[i][j] * de[j];
            }
        }
        self.rotation += d[2];
        // (The linear map of the rotation is kept as the paper's: it inflates a turning
        // block, and its spin is left as it was rather than carried.)
        if exact_rotation {
            self.velocity = transport_velocity(&self.velocity, &map);
            if self.rigid {
                self.velocity[3..].fill(0.0);
            }
        }
        update_edge_frames(&self.vertices, &mut self.edges);
        self.moments = geometry::moments(&self.vertices, &self.name)?;
        self.mass = self.current_mass_matrix();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form mass matrix equals `ρ∫TᵀT dA` integrated numerically over a
    /// non-symmetric polygon (so that S3 ≠ 0 and every entry is exercised).
    #[test]
    fn mass_matrix_matches_numerical_integration() {
        let poly = vec![[0.0, 0.0], [3.0, 0.5], [2.5, 2.0], [0.8, 2.6], [-0.4, 1.1]];
        let m = geometry::moments(&poly, "p").unwrap();
        let rho = 7.0;
        let exact = mass_matrix(rho, &m);
        // Midpoint rule on a fine grid, counting cells whose centre is inside.
        let n = 1200;
        let (x0, x1, y0, y1) = (-0.4, 3.0, 0.0, 2.6);
        let (hx, hy) = ((x1 - x0) / n as f64, (y1 - y0) / n as f64);
        let mut num = [[0.0; 6]; 6];
        for i in 0..n {
            for j in 0..n {
                let p = [x0 + (i as f64 + 0.5) * hx, y0 + (j as f64 + 0.5) * hy];
                if geometry::contains(&poly, p) {
                    let t = t_matrix(m.centroid, p);
                    for a in 0..6 {
                        for b in 0..6 {
                            num[a][b] += rho * (t[0][a] * t[0][b] + t[1][a] * t[1][b]) * hx * hy;
                        }
                    }
                }
            }
        }
        let scale = exact[2][2];
        for a in 0..6 {
            for b in 0..6 {
                assert!(
                    (num[a][b] - exact[a][b]).abs() < 2e-3 * scale,
                    "M[{a}][{b}]: numeric {} vs closed form {}",
                    num[a][b],
                    exact[a][b]
                );
            }
        }
    }

    #[test]
    fn exact_rotation_preserves_area() {
        let mut b = Block::new(
            "b",
            vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
            Material {
                density: 1.0,
                youngs_modulus: 1.0,
                poisson_ratio: 0.2,
                plane: Default::default(),
            },
            BlockRole::Free,
        )
        .unwrap();
        for _ in 0..100 {
            b.apply_increment(&[0.0, 0.0, 0.01, 0.0, 0.0, 0.0], true)
                .unwrap();
        }
        assert!((b.moments.area - 2.0).abs() < 1e-12);
    }

    /// A block sheared back and forth at every step keeps its area (the increment applied
    /// as `ΔE` lost γ²/4 of it per step: 1e-3 after 4 000 steps of γ = 1e-3; the
    /// second-order map leaves (γ/2)⁴/4 per step, 6e-11), and its area follows its
    /// volumetric strain, `exp(εx + εy)`.
    #[test]
    fn alternating_shear_keeps_a_block_area() {
        let mut b = Block::unit_for_tests(vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]);
        for k in 0..4000 {
            let gamma = if k % 2 == 0 { 1e-3 } else { -1e-3 };
            b.apply_increment(&[0.0, 0.0, 0.0, 0.0, 0.0, gamma], true)
                .unwrap();
        }
        assert!((b.moments.area - 2.0).abs() < 2e-10, "{}", b.moments.area);
        for _ in 0..100 {
            b.apply_increment(&[0.0, 0.0, 0.0, 1e-3, -4e-4, 0.0], true)
                .unwrap();
        }
        // Third order per step: (εx³ + εy³)/6 of the area, 1.7e-8 over the 100 steps.
        let expected = 2.0 * (b.strain[0] + b.strain[1]).exp();
        let third_order = 100.0 * (1e-9 + 6.4e-11) / 6.0;
        assert!(
            (b.moments.area / expected - 1.0).abs() < 1.1 * third_order,
            "{} vs {expected}",
            b.moments.area
        );
    }
}
