//! Polygon geometry: validation and the area moments DDA needs.

use crate::{Error, Result};

/// A 2-D point or vector, metres.
pub type Point = [f64; 2];

/// Area moments of a polygon about its centroid (per unit thickness).
///
/// `s1 = ∫X² dA`, `s2 = ∫Y² dA`, `s3 = ∫XY dA` with X, Y measured from the centroid:
/// exactly the integrals that appear in the DDA mass matrix (dda-theory §2–3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// Area S, m².
    pub area: f64,
    /// Centroid (x0, y0), m.
    pub centroid: Point,
    /// ∫X² dA about the centroid, m⁴.
    pub s1: f64,
    /// ∫Y² dA about the centroid, m⁴.
    pub s2: f64,
    /// ∫XY dA about the centroid, m⁴.
    pub s3: f64,
}

/// Computes the moments of a counter-clockwise polygon by the edge sums of dda-theory §2.
///
/// The edge sums are evaluated relative to the first vertex, which keeps them accurate for
/// polygons far from the origin (a ground block that has travelled hundreds of metres).
/// Returns an error for fewer than three vertices, non-finite coordinates or a non-positive
/// area (clockwise or degenerate polygon). `label` names the polygon in the message.
pub fn moments(vertices: &[Point], label: &str) -> Result<Moments> {
    if vertices.len() < 3 {
        return Err(Error::Scene(format!(
            "block '{label}': a polygon needs at least 3 vertices, got {}",
            vertices.len()
        )));
    }
    if let Some(p) = vertices
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(Error::Scene(format!(
            "block '{label}': vertex ({}, {}) is not finite",
            p[0], p[1]
        )));
    }
    let origin = vertices[0];
    let (mut s, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 0..vertices.len() {
        let a = vertices[k];
        let b = vertices[(k + 1) % vertices.len()];
        let (xa, ya) = (a[0] - origin[0], a[1] - origin[1]);
        let (xb, yb) = (b[0] - origin[0], b[1] - origin[1]);
        let f = xa * yb - xb * ya;
        s += f / 2.0;
        sx += f * (xa + xb) / 6.0;
        sy += f * (ya + yb) / 6.0;
        sxx += f * (xa * xa + xb * xb + xa * xb) / 12.0;
        syy += f * (ya * ya + yb * yb + ya * yb) / 12.0;
        sxy += f * (2.0 * xa * ya + 2.0 * xb * yb + xa * yb + xb * ya) / 24.0;
    }
    let size = bounding_size(vertices);
    // A relative threshold: an area below 1e-12 of the bounding box is degenerate.
    if s.is_nan() || s <= 1e-12 * size * size {
        return Err(Error::Scene(format!(
            "block '{label}': polygon area is {s:.3e} m²; vertices must be listed \
             counter-clockwise and enclose a non-zero area"
        )));
    }
    let (x0, y0) = (sx / s, sy / s);
    Ok(Moments {
        area: s,
        centroid: [x0 + origin[0], y0 + origin[1]],
        s1: sxx - x0 * sx,
        s2: syy - y0 * sy,
        s3: sxy - x0 * sy,
    })
}

/// Checks that a polygon is simple: no two non-adjacent edges intersect and no edge has
/// zero length. DDA's contact logic assumes simple polygons.
pub fn check_simple(vertices: &[Point], label: &str) -> Result<()> {
    let n = vertices.len();
    let size = bounding_size(vertices);
    for k in 0..n {
        let a = vertices[k];
        let b = vertices[(k + 1) % n];
        if ((b[0] - a[0]).hypot(b[1] - a[1])) <= 1e-12 * size {
            return Err(Error::Scene(format!(
                "block '{label}': vertices {k} and {} coincide",
                (k + 1) % n
            )));
        }
    }
    for i in 0..n {
        for j in (i + 2)..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the wrap-around
            }
            let (p1, p2) = (vertices[i], vertices[(i + 1) % n]);
            let (q1, q2) = (vertices[j], vertices[(j + 1) % n]);
            if segments_intersect(p1, p2, q1, q2) {
                return Err(Error::Scene(format!(
                    "block '{label}': edges {i} and {j} cross; the polygon must be simple"
                )));
            }
        }
    }
    Ok(())
}

/// Diagonal of the axis-aligned bounding box, m.
pub fn bounding_size(vertices: &[Point]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in vertices {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// z-component of the cross product a × b.
#[inline]
pub fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// a − b.
#[inline]
pub fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

/// Dot product.
#[inline]
pub fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn segments_intersect(p1: Point, p2: Point, q1: Point, q2: Point) -> bool {
    let d1 = cross(sub(q2, q1), sub(p1, q1));
    let d2 = cross(sub(q2, q1), sub(p2, q1));
    let d3 = cross(sub(p2, p1), sub(q1, p1));
    let d4 = cross(sub(p2, p1), sub(q2, p1));
    ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0))
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: Point, a: Point, b: Point) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let s = if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + s * ab[0], a[1] + s * ab[1]];
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// Distance from `p` to the polygon's boundary.
pub fn boundary_distance(vertices: &[Point], p: Point) -> f64 {
    let n = vertices.len();
    (0..n)
        .map(|k| segment_distance(p, vertices[k], vertices[(k + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

/// How far `p` lies outside the polygon (0 inside or on the boundary).
pub fn distance_outside(vertices: &[Point], p: Point) -> f64 {
    if contains(vertices, p) {
        0.0
    } else {
        boundary_distance(vertices, p)
    }
}

/// Whether two segments cross each other at a single interior point, each end of either
/// clearly (by more than `tol`) on its own side of the other: touching, overlapping
/// collinear edges and shared vertices are not crossings.
pub fn segments_cross(p1: Point, p2: Point, q1: Point, q2: Point, tol: f64) -> bool {
    let side = |a: Point, b: Point, c: Point| {
        let ab = sub(b, a);
        let len = dot(ab, ab).sqrt();
        if len == 0.0 {
            0.0
        } else {
            cross(ab, sub(c, a)) / len
        }
    };
    let (d1, d2) = (side(q1, q2, p1), side(q1, q2, p2));
    let (d3, d4) = (side(p1, p2, q1), side(p1, p2, q2));
    ((d1 > tol && d2 < -tol) || (d1 < -tol && d2 > tol))
        && ((d3 > tol && d4 < -tol) || (d3 < -tol && d4 > tol))
}

/// Whether point `p` lies inside the polygon (crossing-number test).
pub fn contains(vertices: &[Point], p: Point) -> bool {
    let n = vertices.len();
    let mut inside = false;
    for k in 0..n {
        let a = vertices[k];
        let b = vertices[(k + 1) % n];
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_moments_are_textbook() {
        let (w, h) = (3.0, 2.0);
        let r = [
            [10.0, 5.0],
            [10.0 + w, 5.0],
            [10.0 + w, 5.0 + h],
            [10.0, 5.0 + h],
        ];
        let m = moments(&r, "r").unwrap();
        assert!((m.area - w * h).abs() < 1e-12);
        assert!((m.centroid[0] - 11.5).abs() < 1e-12 && (m.centroid[1] - 6.0).abs() < 1e-12);
        assert!((m.s1 - h * w.powi(3) / 12.0).abs() < 1e-10);
        assert!((m.s2 - w * h.powi(3) / 12.0).abs() < 1e-10);
        assert!(m.s3.abs() < 1e-10);
    }

    #[test]
    fn clockwise_and_degenerate_polygons_are_rejected() {
        let cw = [[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
        assert!(moments(&cw, "cw").is_err());
        let line = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        assert!(moments(&line, "line").is_err());
        let bow = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert!(check_simple(&bow, "bow").is_err());
    }
}
