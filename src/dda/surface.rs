//! The interface geometry a contact sees: where a vertex is relative to the surface of the
//! other block, and how that changes with the step's unknowns.
//!
//! A block's boundary is a polygon, and a contact normally sees the edge under its vertex
//! (a flat surface). Some edges are facets of a circle — a friction pendulum's dish — and
//! a contact on them sees the circle itself: its gap and normal change smoothly as the
//! vertex slides from facet to facet, where the facets' kinks would shake it (a bump of
//! R·Δφ²/8 at each, and a normal that turns by Δφ within one step).
//!
//! Both surfaces give the gap and the slip linearised in the step's unknowns,
//! `g = g0 + gᵢ·Dᵢ + gⱼ·Dⱼ` and `Δs = sᵢ·Dᵢ + sⱼ·Dⱼ`. On a circle the linearisation is
//! taken about the middle of the step's slip ([`frame_ahead`]): a vertex that slides along
//! the circle moves on a chord, and the chord is square to the circle's normal at its
//! middle, not at its start. Linearised at the start, the step moved the vertex by κs²/2
//! along the start normal (s the slip, κ = 1/R), and the normal force did work on that
//! which the circle never asks for: N·κs²/2 per step, an energy error of O(Δt) (5e-4 of
//! the input work of the friction pendulum on El Centro at Δt = 1 ms).

use super::block::{Block, EdgeFrame, Vec6, t_transpose_times};
use crate::model::geometry::{Point, cross, dot, sub};
use crate::model::scene::ArcDef;

/// A contact's linearised geometry at the step start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceFrame {
    /// Gap at the step start, m (negative: penetration).
    pub gap0: f64,
    /// d(gap)/d(D_i), the vertex block's unknowns.
    pub gap_i: Vec6,
    /// d(gap)/d(D_j), the surface block's unknowns.
    pub gap_j: Vec6,
    /// d(slip)/d(D_i).
    pub slip_i: Vec6,
    /// d(slip)/d(D_j).
    pub slip_j: Vec6,
    /// The surface's unit tangent under the vertex (its outward normal is to the right).
    pub tangent: Point,
    /// Curvature of the surface under the vertex, 1/m: 0 for an edge, 1/R for a dish
    /// (whose frame is then taken again, ahead, once the step's slip can be predicted).
    pub curvature: f64,
}

/// Vertex `p1` of block `vblock` against edge `edge` of block `eblock`: the circle of the
/// edge's arc if it has one, else the edge itself; linearised where the vertex is.
pub fn frame(vblock: &Block, eblock: &Block, p1: Point, edge: usize) -> SurfaceFrame {
    frame_ahead(vblock, eblock, p1, edge, 0.0)
}

/// [`frame`] with a curved surface's normal and tangent taken `ahead` metres along it
/// from the point under the vertex (half the slip expected in the step: see the module's
/// notes). The gap at the start is the vertex's own; a flat edge ignores `ahead`.
pub fn frame_ahead(
    vblock: &Block,
    eblock: &Block,
    p1: Point,
    edge: usize,
    ahead: f64,
) -> SurfaceFrame {
    match eblock.arc_of(edge) {
        Some(arc) => on_circle(vblock, eblock, p1, arc, ahead),
        None => on_edge(vblock, eblock, p1, edge),
    }
}

/// Against a flat edge P2→P3 (length l, tangent t̂, outward normal n̂), w = P1 − P2:
/// gap `n̂·w = (w × (P3 − P2))/l`, with `g_j` the first-order change of that signed area
/// under the edge's own motion (its rotation included); slip along t̂ relative to the
/// edge's material point Q under P1.
fn on_edge(vblock: &Block, eblock: &Block, p1: Point, edge: usize) -> SurfaceFrame {
    let ne = eblock.vertices.len();
    let p2 = eblock.vertices[edge];
    let p3 = eblock.vertices[(edge + 1) % ne];
    let e = sub(p3, p2);
    let EdgeFrame {
        tangent: t,
        normal: n,
        length: l,
    } = eblock.edges[edge];
    let w = sub(p1, p2);
    let ci = vblock.moments.centroid;
    let cj = eblock.moments.centroid;
    let a = t_transpose_times(cj, p2, perp(sub(w, e)));
    let b = t_transpose_times(cj, p3, perp(w));
    let mut gap_j = [0.0; 6];
    for k in 0..6 {
        gap_j[k] = (a[k] - b[k]) / l;
    }
    let q = [p2[0] + dot(w, t) * t[0], p2[1] + dot(w, t) * t[1]];
    SurfaceFrame {
        gap0: cross(w, e) / l,
        gap_i: t_transpose_times(ci, p1, n),
        gap_j,
        slip_i: t_transpose_times(ci, p1, t),
        slip_j: t_transpose_times(cj, q, t).map(|v| -v),
        tangent: t,
        curvature: 0.0,
    }
}

/// Against a dish, the circle of radius R about C: with û = (P1 − C)/|P1 − C|, the
/// surface point under P1 is Q = C + Rû, the outward normal n̂ = −û (towards the centre)
/// and the gap `R − |P1 − C|`. Its first-order change is n̂·(ΔP1 − ΔQ), ΔQ the motion of
/// the dish's material point Q (a rigid turn about C does not move the circle). With
/// `ahead` ≠ 0, Q, n̂ and t̂ are those of the circle's point that far along t̂.
fn on_circle(vblock: &Block, eblock: &Block, p1: Point, arc: &ArcDef, ahead: f64) -> SurfaceFrame {
    let u = sub(p1, arc.center);
    let r = u[0].hypot(u[1]);
    let (gap0, under) = (arc.radius - r, [u[0] / r, u[1] / r]);
    // û turned by ahead/R towards the tangent, which is (û_y, −û_x) for n̂ = −û.
    let (sin, cos) = (ahead / arc.radius).sin_cos();
    let along = [under[1], -under[0]];
    let u_hat = [
        under[0] * cos + along[0] * sin,
        under[1] * cos + along[1] * sin,
    ];
    let n = [-u_hat[0], -u_hat[1]];
    // perp(t̂) = n̂, as for an edge.
    let t = [-n[1], n[0]];
    let q = [
        arc.center[0] - arc.radius * n[0],
        arc.center[1] - arc.radius * n[1],
    ];
    let ci = vblock.moments.centroid;
    let cj = eblock.moments.centroid;
    SurfaceFrame {
        gap0,
        gap_i: t_transpose_times(ci, p1, n),
        gap_j: t_transpose_times(cj, q, n).map(|v| -v),
        slip_i: t_transpose_times(ci, p1, t),
        slip_j: t_transpose_times(cj, q, t).map(|v| -v),
        tangent: t,
        curvature: 1.0 / arc.radius,
    }
}

#[inline]
fn perp(a: Point) -> Point {
    [a[1], -a[0]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dda::block::point_displacement;

    fn block(v: Vec<Point>) -> Block {
        Block::unit_for_tests(v)
    }

    /// A dish of radius 2 about (0, 2): 41 chords from −20° to 20°, on a 1 m deep block.
    fn dish() -> Block {
        let (r, n) = (2.0_f64, 40);
        let half = 20f64.to_radians();
        let rim = [r * half.sin(), r - r * half.cos()];
        let mut v = vec![[-2.0, -1.0], [2.0, -1.0], [2.0, rim[1]]];
        v.extend((0..=n).map(|k| {
            let phi = half - 2.0 * half * k as f64 / n as f64;
            [r * phi.sin(), r - r * phi.cos()]
        }));
        v.push([-2.0, rim[1]]);
        let mut b = block(v);
        b.arcs.push(ArcDef {
            center: [0.0, 2.0],
            radius: r,
            edges: [3, 3 + n - 1],
        });
        b
    }

    /// On a dish the gap is the distance inside the circle, and its linear part is exact
    /// to first order, while the slip's second-order part is the curvature's s²/(2R).
    #[test]
    fn a_dish_contact_sees_its_circle() {
        let dish = dish();
        // A vertex on the circle (2.86° from the bottom, over edge 20's facet).
        let on = [2.0 * 0.05_f64.sin(), 2.0 - 2.0 * 0.05_f64.cos()];
        let slider = block(vec![on, [0.3, 0.02], [0.2, 0.2]]);
        let p1 = slider.vertices[0];
        let f = frame(&slider, &dish, p1, 20);
        let r = (p1[0] * p1[0] + (p1[1] - 2.0) * (p1[1] - 2.0)).sqrt();
        assert!((f.gap0 - (2.0 - r)).abs() < 1e-15 && f.gap0.abs() < 1e-15);
        assert_eq!(f.curvature, 0.5);
        // A small motion of the vertex: the exact gap against the linear one.
        for d in [
            [1e-5, -2e-5, 1e-5, 0.0, 0.0, 0.0],
            [-3e-5, 1e-5, -2e-5, 1e-6, 0.0, -1e-6],
        ] {
            let u = point_displacement(slider.moments.centroid, p1, &d);
            let p = [p1[0] + u[0], p1[1] + u[1]];
            let exact = 2.0 - (p[0] * p[0] + (p[1] - 2.0) * (p[1] - 2.0)).sqrt();
            let linear = f.gap0 + dot6(&f.gap_i, &d);
            let slip = dot6(&f.slip_i, &d);
            let second = -0.5 * f.curvature * slip * slip;
            // What is left is third order: |D|³/R² ~ 1e-14 m.
            assert!(
                (exact - linear - second).abs() < 1e-13,
                "exact {exact:e}, linear {linear:e}, curvature part {second:e}"
            );
        }
        // Moving the dish with the vertex (a rigid translation of both) changes nothing.
        let d = [2e-4, -1e-4, 0.0, 0.0, 0.0, 0.0];
        let g = dot6(&f.gap_i, &d) + dot6(&f.gap_j, &d);
        let s = dot6(&f.slip_i, &d) + dot6(&f.slip_j, &d);
        assert!(g.abs() < 1e-18 && s.abs() < 1e-18, "gap {g:e}, slip {s:e}");
    }

    /// The tangent runs the way the facet under the vertex does (its outward normal to
    /// the right), so a contact keeps its slip direction when it moves from the facet to
    /// the circle.
    #[test]
    fn a_dish_tangent_runs_with_its_facets() {
        let dish = dish();
        let slider = block(vec![[0.1, 0.01], [0.3, 0.02], [0.2, 0.2]]);
        let p1 = slider.vertices[0];
        let curved = frame(&slider, &dish, p1, 20);
        let mut flat = dish.clone();
        flat.arcs.clear();
        let faceted = frame(&slider, &flat, p1, 20);
        assert!(dot(curved.tangent, faceted.tangent) > 0.999);
        assert!((curved.gap0 - faceted.gap0).abs() < 1e-4);
    }

    fn dot6(a: &Vec6, b: &Vec6) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }
}
