//! Tessellation of a scene view into coloured triangles (pure CPU code, testable without a
//! GPU): blocks filled by stress or strain with outlines, the ground and its markings,
//! contact springs coloured by state, the slip arrow and trace, bolts as springs and
//! connection elements. Only the layers a scene has are drawn.

use crate::sim::{ContactFrame, ModelFrame};

/// One vertex: clip-space position and linear RGBA colour.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// Clip-space position.
    pub position: [f32; 2],
    /// Linear RGBA.
    pub color: [f32; 4],
}

/// What colours the blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorBy {
    /// Material colours.
    Material,
    /// Von Mises stress (total, including the gravity preload).
    Stress,
    /// Equivalent strain since the start of the run (the earthquake's deformation).
    Strain,
}

/// Which layers to draw (a layer the scene does not have is skipped anyway).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layers {
    /// Blocks (filled).
    pub blocks: bool,
    /// Block outlines.
    pub outlines: bool,
    /// Contact springs.
    pub contacts: bool,
    /// Slip arrow and trace.
    pub slip: bool,
    /// Bolts.
    pub bolts: bool,
    /// Connection elements.
    pub connections: bool,
    /// Ground and its markings.
    pub ground: bool,
}

impl Default for Layers {
    fn default() -> Self {
        Self {
            blocks: true,
            outlines: true,
            contacts: true,
            slip: true,
            bolts: true,
            connections: true,
            ground: true,
        }
    }
}

/// A rectangle of the target in pixels: x, y (top-left), width, height.
pub type PixelRect = [f32; 4];

/// One model drawn into one rectangle of the target.
#[derive(Debug, Clone)]
pub struct PanelView<'a> {
    /// The frame to draw.
    pub frame: &'a ModelFrame,
    /// Where, in target pixels.
    pub rect: PixelRect,
    /// World window around the base: (half width, bottom, top), m.
    pub window: [f32; 3],
    /// Slip range reached so far (min, max), m: the trace on the ground.
    pub slip_range: [f32; 2],
}

/// Everything the renderer draws in one frame.
#[derive(Debug, Clone)]
pub struct SceneView<'a> {
    /// Panels (side by side).
    pub panels: Vec<PanelView<'a>>,
    /// Deformation exaggeration factor (1 = true scale).
    pub exaggeration: f32,
    /// Block colouring.
    pub color_by: ColorBy,
    /// Stress (Pa) or strain at the top of the colour scale.
    pub color_max: f32,
    /// Layers.
    pub layers: Layers,
}

/// State colours of contacts (locked, sliding, open), linear RGB.
pub const LOCKED: [f32; 4] = [0.05, 0.35, 0.85, 1.0];
/// Sliding contact colour.
pub const SLIDING: [f32; 4] = [0.95, 0.35, 0.05, 1.0];
/// Open contact colour.
pub const OPEN: [f32; 4] = [0.55, 0.55, 0.55, 1.0];
const SKY: [f32; 4] = [0.93, 0.95, 0.98, 1.0];
const GROUND: [f32; 4] = [0.42, 0.33, 0.25, 1.0];
const GROUND_MARK: [f32; 4] = [0.28, 0.21, 0.15, 1.0];
const OUTLINE: [f32; 4] = [0.08, 0.08, 0.1, 1.0];
const MATERIAL: [f32; 4] = [0.72, 0.74, 0.78, 1.0];
const BOLT: [f32; 4] = [0.15, 0.5, 0.2, 1.0];
const CONNECTION: [f32; 4] = [0.45, 0.45, 0.5, 1.0];
const SLIP_ARROW: [f32; 4] = [0.85, 0.1, 0.1, 1.0];
const TRACE: [f32; 4] = [0.95, 0.75, 0.2, 1.0];

/// A colour map from 0 to 1 (a perceptually ordered blue–teal–yellow–red ramp), linear RGB.
pub fn colormap(t: f32) -> [f32; 4] {
    let stops: [[f32; 3]; 5] = [
        [0.10, 0.20, 0.55],
        [0.10, 0.55, 0.70],
        [0.45, 0.75, 0.35],
        [0.95, 0.80, 0.20],
        [0.85, 0.15, 0.10],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (stops.len() - 1) as f32;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| stops[i][k] * (1.0 - f) + stops[i + 1][k] * f;
    [c(0), c(1), c(2), 1.0]
}

/// Maps world coordinates of one panel to clip space.
struct Transform {
    scale: [f32; 2],
    offset: [f32; 2],
    /// World metres per pixel.
    metres_per_pixel: f32,
}

impl Transform {
    fn new(panel: &PanelView<'_>, target: [f32; 2], centre_x: f32) -> Self {
        let [x, y, w, h] = panel.rect;
        let [half, bottom, top] = panel.window;
        // Keep the aspect ratio: metres per pixel from the tighter direction.
        let mpp = (2.0 * half / w.max(1.0)).max((top - bottom) / h.max(1.0));
        let world_w = w * mpp;
        let world_h = h * mpp;
        let left = centre_x - world_w / 2.0;
        let low = bottom - (world_h - (top - bottom)) / 2.0;
        // world → pixel → clip.
        let px_per_m = 1.0 / mpp;
        let sx = px_per_m * 2.0 / target[0];
        let sy = px_per_m * 2.0 / target[1];
        let ox = (x - left * px_per_m) * 2.0 / target[0] - 1.0;
        let oy = 1.0 - (y + h + low * px_per_m) * 2.0 / target[1];
        Self {
            scale: [sx, sy],
            offset: [ox, oy],
            metres_per_pixel: mpp,
        }
    }

    fn apply(&self, p: [f32; 2]) -> [f32; 2] {
        [
            p[0] * self.scale[0] + self.offset[0],
            p[1] * self.scale[1] + self.offset[1],
        ]
    }
}

/// Collects triangles for one panel.
struct Painter<'a> {
    out: &'a mut Vec<Vertex>,
    t: Transform,
}

impl Painter<'_> {
    fn triangle(&mut self, a: [f32; 2], b: [f32; 2], c: [f32; 2], color: [f32; 4]) {
        for p in [a, b, c] {
            self.out.push(Vertex {
                position: self.t.apply(p),
                color,
            });
        }
    }

    fn quad(&mut self, a: [f32; 2], b: [f32; 2], c: [f32; 2], d: [f32; 2], color: [f32; 4]) {
        self.triangle(a, b, c, color);
        self.triangle(a, c, d, color);
    }

    /// A line `width_px` pixels wide.
    fn line(&mut self, a: [f32; 2], b: [f32; 2], width_px: f32, color: [f32; 4]) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 || !len.is_finite() {
            return;
        }
        let h = 0.5 * width_px * self.t.metres_per_pixel;
        let (nx, ny) = (-dy / len * h, dx / len * h);
        self.quad(
            [a[0] + nx, a[1] + ny],
            [b[0] + nx, b[1] + ny],
            [b[0] - nx, b[1] - ny],
            [a[0] - nx, a[1] - ny],
            color,
        );
    }

    /// A filled polygon (fan from its centroid: exact for the convex and star-shaped
    /// blocks of the built-in scenes).
    fn polygon(&mut self, pts: &[[f32; 2]], color: [f32; 4]) {
        if pts.len() < 3 {
            return;
        }
        let n = pts.len() as f32;
        let c = [
            pts.iter().map(|p| p[0]).sum::<f32>() / n,
            pts.iter().map(|p| p[1]).sum::<f32>() / n,
        ];
        for k in 0..pts.len() {
            self.triangle(c, pts[k], pts[(k + 1) % pts.len()], color);
        }
    }

    fn outline(&mut self, pts: &[[f32; 2]], width_px: f32, color: [f32; 4]) {
        for k in 0..pts.len() {
            self.line(pts[k], pts[(k + 1) % pts.len()], width_px, color);
        }
    }

    /// A zigzag spring from a to b, `amplitude_px` wide, with `turns` zigzags.
    fn spring(
        &mut self,
        a: [f32; 2],
        b: [f32; 2],
        amplitude_px: f32,
        turns: usize,
        width_px: f32,
        color: [f32; 4],
    ) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 || !len.is_finite() {
            return;
        }
        let amp = amplitude_px * self.t.metres_per_pixel;
        let (nx, ny) = (-dy / len * amp, dx / len * amp);
        let n = 2 * turns + 2;
        let mut prev = a;
        for k in 1..=n {
            let s = k as f32 / n as f32;
            let side = if k == n {
                0.0
            } else if k % 2 == 0 {
                -1.0
            } else {
                1.0
            };
            let p = [a[0] + dx * s + nx * side, a[1] + dy * s + ny * side];
            self.line(prev, p, width_px, color);
            prev = p;
        }
    }

    fn arrow(&mut self, a: [f32; 2], b: [f32; 2], width_px: f32, color: [f32; 4]) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 || !len.is_finite() {
            return;
        }
        let head = (10.0 * self.t.metres_per_pixel).min(0.5 * len);
        let (ux, uy) = (dx / len, dy / len);
        let base = [b[0] - ux * head, b[1] - uy * head];
        self.line(a, base, width_px, color);
        let w = 0.5 * head;
        self.triangle(
            b,
            [base[0] - uy * w, base[1] + ux * w],
            [base[0] + uy * w, base[1] - ux * w],
            color,
        );
    }
}

fn von_mises(s: &[f32; 3]) -> f32 {
    (s[0] * s[0] - s[0] * s[1] + s[1] * s[1] + 3.0 * s[2] * s[2])
        .max(0.0)
        .sqrt()
}

fn equivalent_strain(e: &[f32; 3]) -> f32 {
    (e[0] * e[0] + e[1] * e[1] + 0.5 * e[2] * e[2]).sqrt()
}

/// The colour measure of a block for the colour scale.
pub fn color_measure(color_by: ColorBy, stress: &[f32; 3], strain: &[f32; 3]) -> f32 {
    match color_by {
        ColorBy::Material => 0.0,
        ColorBy::Stress => von_mises(stress),
        ColorBy::Strain => equivalent_strain(strain),
    }
}

/// Displayed position of a vertex with the deformation exaggerated.
fn exaggerate(rigid: [f32; 2], actual: [f32; 2], f: f32) -> [f32; 2] {
    [
        rigid[0] + f * (actual[0] - rigid[0]),
        rigid[1] + f * (actual[1] - rigid[1]),
    ]
}

/// Tessellates a scene view for a target of `target` pixels (width, height).
pub fn build(view: &SceneView<'_>, target: [f32; 2]) -> Vec<Vertex> {
    let mut out = Vec::new();
    for panel in &view.panels {
        let frame = panel.frame;
        // The camera follows the base (the first non-ground block's centroid region).
        let centre_x = frame.blocks.iter().find(|b| !b.is_ground).map_or(0.0, |b| {
            b.vertices.iter().map(|v| v[0]).sum::<f32>() / b.vertices.len().max(1) as f32
        });
        let mut p = Painter {
            out: &mut out,
            t: Transform::new(panel, target, centre_x),
        };
        let [x, y, w, h] = panel.rect;
        // Background: the panel rectangle in clip space directly.
        let to_clip = |px: f32, py: f32| [px * 2.0 / target[0] - 1.0, 1.0 - py * 2.0 / target[1]];
        let (a, b, c, d) = (
            to_clip(x, y),
            to_clip(x + w, y),
            to_clip(x + w, y + h),
            to_clip(x, y + h),
        );
        for q in [a, b, c, a, c, d] {
            p.out.push(Vertex {
                position: q,
                color: SKY,
            });
        }
        let ground = frame.blocks.iter().find(|b| b.is_ground);
        if view.layers.ground
            && let Some(g) = ground
        {
            p.polygon(&g.vertices, GROUND);
            // Markings every metre near the structure, so the ground's motion shows.
            let top = g
                .vertices
                .iter()
                .map(|v| v[1])
                .fold(f32::NEG_INFINITY, f32::max);
            let gx = frame.probes.ground_disp as f32;
            let half = panel.window[0] * 3.0;
            let start = ((centre_x - half - gx).floor()) as i64;
            for k in 0..(2.0 * half) as i64 + 2 {
                let xm = (start + k) as f32 + gx;
                let depth = if (start + k) % 5 == 0 { 0.6 } else { 0.3 };
                p.line([xm, top], [xm, top - depth], 1.5, GROUND_MARK);
            }
        }
        for blk in frame.blocks.iter().filter(|b| !b.is_ground) {
            let pts: Vec<[f32; 2]> = blk
                .rigid
                .iter()
                .zip(&blk.vertices)
                .map(|(r, a)| exaggerate(*r, *a, view.exaggeration))
                .collect();
            if view.layers.blocks {
                let color = match view.color_by {
                    ColorBy::Material => MATERIAL,
                    c => colormap(
                        color_measure(c, &blk.stress, &blk.strain)
                            / view.color_max.max(f32::MIN_POSITIVE),
                    ),
                };
                p.polygon(&pts, color);
            }
            if view.layers.outlines {
                p.outline(&pts, 1.5, OUTLINE);
            }
        }
        if view.layers.connections {
            for tri in &frame.connections {
                p.outline(tri, 1.0, CONNECTION);
            }
        }
        if view.layers.bolts {
            for bolt in &frame.bolts {
                p.spring(bolt[0], bolt[1], 8.0, 6, 2.0, BOLT);
            }
        }
        if view.layers.contacts {
            for c in &frame.contacts {
                draw_contact(&mut p, c);
            }
        }
        if view.layers.slip
            && let Some(g) = ground
        {
            let top = g
                .vertices
                .iter()
                .map(|v| v[1])
                .fold(f32::NEG_INFINITY, f32::max);
            let slip = frame.probes.slip as f32;
            let gx = frame.probes.ground_disp as f32;
            // Trace: the range of base positions on the ground so far (skid marks).
            let lift = 4.0 * p.t.metres_per_pixel;
            let [lo, hi] = panel.slip_range;
            if hi > lo {
                p.line(
                    [centre_x - slip + lo, top - lift],
                    [centre_x - slip + hi, top - lift],
                    4.0,
                    TRACE,
                );
            }
            // Arrow from where the base started on the ground to where it is now.
            let mark = centre_x - slip;
            p.line(
                [mark, top - 3.0 * lift],
                [mark, top + 3.0 * lift],
                2.0,
                SLIP_ARROW,
            );
            if slip.abs() > 2.0 * p.t.metres_per_pixel {
                p.arrow(
                    [mark, top + 2.0 * lift],
                    [centre_x, top + 2.0 * lift],
                    3.0,
                    SLIP_ARROW,
                );
            }
            let _ = gx;
        }
    }
    out
}

/// A contact as a short normal spring (and a shear spring when stuck) at its point.
fn draw_contact(p: &mut Painter<'_>, c: &ContactFrame) {
    let color = match c.state {
        1 => LOCKED,
        2 => SLIDING,
        _ => OPEN,
    };
    let mpp = p.t.metres_per_pixel;
    let n = [c.tangent[1], -c.tangent[0]];
    // The vertex sits on the edge; the edge's outward normal points to the vertex block.
    let len = 18.0 * mpp;
    let a = c.point;
    let b = [a[0] - n[0] * len, a[1] - n[1] * len];
    p.spring(b, a, 4.0, 3, 2.0, color);
    if c.state == 1 {
        let s = [a[0] - c.tangent[0] * len, a[1] - c.tangent[1] * len];
        p.spring(s, a, 3.0, 2, 1.5, color);
    }
    let dot = 3.0 * mpp;
    p.quad(
        [a[0] - dot, a[1] - dot],
        [a[0] + dot, a[1] - dot],
        [a[0] + dot, a[1] + dot],
        [a[0] - dot, a[1] + dot],
        color,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormap_is_ordered_and_clamped() {
        assert_eq!(colormap(-1.0), colormap(0.0));
        assert_eq!(colormap(2.0), colormap(1.0));
        assert_eq!(colormap(f32::NAN), colormap(0.0));
        // Red grows from the cold to the hot end.
        assert!(colormap(1.0)[0] > colormap(0.0)[0]);
    }
}
