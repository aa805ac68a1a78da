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
    /// Outlines of the connection elements (their material is always drawn with the
    /// blocks: it is what joins a column to a slab).
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
            // Off by default: triangles drawn inside a joint look like bracing.
            connections: false,
            ground: true,
        }
    }
}

/// A rectangle of the target in pixels: x, y (top-left), width, height.
pub type PixelRect = [f32; 4];

/// The part of the world a panel shows: the world point at the panel's centre and the
/// scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewBox {
    /// World point at the centre of the panel, m.
    pub centre: [f32; 2],
    /// Metres per pixel.
    pub metres_per_pixel: f32,
}

/// One model drawn into one rectangle of the target.
#[derive(Debug, Clone)]
pub struct PanelView<'a> {
    /// The frame to draw.
    pub frame: &'a ModelFrame,
    /// Where, in target pixels.
    pub rect: PixelRect,
    /// What part of the world.
    pub view: ViewBox,
    /// Slip range reached so far (min, max), m: the trace on the ground.
    pub slip_range: [f32; 2],
    /// A close-up of the sliding joint: true scale (no exaggeration), the base's starting
    /// position drawn as a ghost on the ground and a slip arrow from it.
    pub close_up: bool,
}

/// Everything the renderer draws in one frame.
#[derive(Debug, Clone)]
pub struct SceneView<'a> {
    /// Panels.
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
const GHOST_FILL: [f32; 4] = [0.2, 0.2, 0.25, 0.12];
const GHOST_LINE: [f32; 4] = [0.15, 0.15, 0.2, 0.9];

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
    /// The panel in clip space (x0, y0, x1, y1): triangles are clipped to it.
    clip: [f32; 4],
}

impl Transform {
    fn new(panel: &PanelView<'_>, target: [f32; 2]) -> Self {
        let [x, y, w, h] = panel.rect;
        let mpp = panel.view.metres_per_pixel.max(1e-9);
        let px_per_m = 1.0 / mpp;
        // World → target pixel: px = x + w/2 + (X − cx)/mpp, py = y + h/2 − (Y − cy)/mpp.
        let sx = px_per_m * 2.0 / target[0];
        let sy = px_per_m * 2.0 / target[1];
        let ox = (x + 0.5 * w - panel.view.centre[0] * px_per_m) * 2.0 / target[0] - 1.0;
        let oy = 1.0 - (y + 0.5 * h + panel.view.centre[1] * px_per_m) * 2.0 / target[1];
        let to_clip = |px: f32, py: f32| [px * 2.0 / target[0] - 1.0, 1.0 - py * 2.0 / target[1]];
        let a = to_clip(x, y + h);
        let b = to_clip(x + w, y);
        Self {
            scale: [sx, sy],
            offset: [ox, oy],
            metres_per_pixel: mpp,
            clip: [a[0], a[1], b[0], b[1]],
        }
    }

    fn apply(&self, p: [f32; 2]) -> [f32; 2] {
        [
            p[0] * self.scale[0] + self.offset[0],
            p[1] * self.scale[1] + self.offset[1],
        ]
    }
}

/// Clips a convex polygon (clip space) to an axis-aligned box (Sutherland–Hodgman).
/// Whether a polygon turns the same way at every vertex (collinear vertices allowed).
fn is_convex(pts: &[[f32; 2]]) -> bool {
    let n = pts.len();
    let (mut left, mut right) = (false, false);
    for k in 0..n {
        let [a, b, c] = [pts[k], pts[(k + 1) % n], pts[(k + 2) % n]];
        let cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]);
        left |= cross > 0.0;
        right |= cross < 0.0;
    }
    !(left && right)
}

fn clip_polygon(points: &[[f32; 2]], clip: [f32; 4]) -> Vec<[f32; 2]> {
    let mut poly = points.to_vec();
    // (axis, bound, keep values >= bound?)
    for (axis, bound, keep_above) in [
        (0, clip[0], true),
        (0, clip[2], false),
        (1, clip[1], true),
        (1, clip[3], false),
    ] {
        if poly.is_empty() {
            break;
        }
        let inside = |p: &[f32; 2]| {
            if keep_above {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        let mut out = Vec::with_capacity(poly.len() + 2);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = out;
    }
    poly
}

/// Collects triangles for one panel.
struct Painter<'a> {
    out: &'a mut Vec<Vertex>,
    t: Transform,
}

impl Painter<'_> {
    fn triangle(&mut self, a: [f32; 2], b: [f32; 2], c: [f32; 2], color: [f32; 4]) {
        let pts = [self.t.apply(a), self.t.apply(b), self.t.apply(c)];
        let inside = |p: &[f32; 2]| {
            p[0] >= self.t.clip[0]
                && p[0] <= self.t.clip[2]
                && p[1] >= self.t.clip[1]
                && p[1] <= self.t.clip[3]
        };
        if pts.iter().all(inside) {
            for position in pts {
                self.out.push(Vertex { position, color });
            }
            return;
        }
        let poly = clip_polygon(&pts, self.t.clip);
        for k in 1..poly.len().saturating_sub(1) {
            for position in [poly[0], poly[k], poly[k + 1]] {
                self.out.push(Vertex { position, color });
            }
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

    /// A filled polygon: a fan from its vertex average when it is convex (every block of
    /// most scenes), ear clipping otherwise (a dish in the ground, a slab with feet), for
    /// which a fan would paint outside the polygon.
    fn polygon(&mut self, pts: &[[f32; 2]], color: [f32; 4]) {
        if pts.len() < 3 {
            return;
        }
        if !is_convex(pts) {
            let mut triangles: Vec<u32> = Vec::new();
            earcut::Earcut::new().earcut(pts.iter().copied(), &[], &mut triangles);
            for t in triangles.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| pts[i as usize]);
                self.triangle(a, b, c, color);
            }
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

/// The smallest top of the colour scale: a microstrain, or a kilopascal. Below it
/// nothing has deformed visibly, and a scale stretched over round-off (a rigid raft's
/// 1e-38) would paint noise.
pub fn color_scale_floor(color_by: ColorBy) -> f32 {
    match color_by {
        ColorBy::Material => f32::MIN_POSITIVE,
        ColorBy::Stress => 1e3,
        ColorBy::Strain => 1e-6,
    }
}

/// The colour measure of a block for the colour scale.
pub fn color_measure(color_by: ColorBy, stress: &[f32; 3], strain: &[f32; 3]) -> f32 {
    match color_by {
        ColorBy::Material => 0.0,
        ColorBy::Stress => von_mises(stress),
        ColorBy::Strain => equivalent_strain(strain),
    }
}

/// Displayed position of a point with the deformation exaggerated: its horizontal
/// displacement from where the rigid motion of its structure would put it, times `f`.
///
/// Only the horizontal part is magnified: that is the storey drift and shear a building
/// sways with. Vertical deformations (a slab flexing on its contact springs, columns
/// shortening) are micrometres; magnified they would sink the base into the ground, so
/// they are drawn true. The map stays affine on each block and continuous across joints,
/// so connected blocks stay joined at any factor.
pub fn exaggerate(rigid: [f32; 2], actual: [f32; 2], f: f32) -> [f32; 2] {
    [rigid[0] + f * (actual[0] - rigid[0]), actual[1]]
}

/// A spacing of `1, 2 or 5 × 10ⁿ` metres at least `min` long (ticks, scale bars).
pub fn nice_step(min: f32) -> f32 {
    if min.is_nan() || min <= 0.0 || !min.is_finite() {
        return 1.0;
    }
    let p = 10f32.powf(min.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= min)
        .unwrap_or(10.0 * p)
}

/// The height of the ground's top surface in a frame, m.
pub fn ground_top(frame: &ModelFrame) -> Option<f32> {
    frame.blocks.iter().find(|b| b.is_ground).map(|g| {
        g.vertices
            .iter()
            .map(|v| v[1])
            .fold(f32::NEG_INFINITY, f32::max)
    })
}

/// Tessellates a scene view for a target of `target` pixels (width, height).
pub fn build(view: &SceneView<'_>, target: [f32; 2]) -> Vec<Vertex> {
    let mut out = Vec::new();
    for panel in &view.panels {
        let mut p = Painter {
            out: &mut out,
            t: Transform::new(panel, target),
        };
        draw_panel(&mut p, panel, view);
    }
    out
}

fn draw_panel(p: &mut Painter<'_>, panel: &PanelView<'_>, view: &SceneView<'_>) {
    let frame = panel.frame;
    let [x, y, w, h] = panel.rect;
    let mpp = p.t.metres_per_pixel;
    // World box of the panel.
    let (cx, cy) = (panel.view.centre[0], panel.view.centre[1]);
    let (x0, x1) = (cx - 0.5 * w * mpp, cx + 0.5 * w * mpp);
    let (y0, y1) = (cy - 0.5 * h * mpp, cy + 0.5 * h * mpp);
    p.quad([x0, y0], [x1, y0], [x1, y1], [x0, y1], SKY);
    let _ = (x, y);
    let factor = if panel.close_up {
        1.0
    } else {
        view.exaggeration
    };
    let top = ground_top(frame);
    if view.layers.ground
        && let Some(g) = frame.blocks.iter().find(|b| b.is_ground)
    {
        p.polygon(&g.vertices, GROUND);
        // Marks that move with the ground, so its motion shows: spaced for the scale.
        let top = top.unwrap_or(0.0);
        let gx = frame.probes.ground_disp as f32;
        let step = nice_step(30.0 * mpp);
        let first = ((x0 - gx) / step).floor() as i64;
        let last = ((x1 - gx) / step).ceil() as i64;
        for k in first..=last.min(first + 400) {
            let xm = k as f32 * step + gx;
            let depth = if k % 5 == 0 { 14.0 } else { 7.0 } * mpp;
            p.line([xm, top], [xm, top - depth], 1.5, GROUND_MARK);
        }
    }
    if panel.close_up && view.layers.slip {
        // Where the base started, carried along by the ground: a ghost outline.
        let ghost = &frame.base_start;
        p.polygon(ghost, GHOST_FILL);
        dashed_outline(p, ghost, 2.0, 8.0, GHOST_LINE);
    }
    // The connection elements are elastic material between the blocks they join: filled
    // like an unstrained block, so that a column and its slab read as one structure.
    let connections: Vec<Vec<[f32; 2]>> = frame
        .connections
        .iter()
        .map(|c| {
            (0..3)
                .map(|k| exaggerate(c.rigid[k], c.points[k], factor))
                .collect()
        })
        .collect();
    if view.layers.blocks {
        let fill = match view.color_by {
            _ if panel.close_up => MATERIAL,
            ColorBy::Material => MATERIAL,
            _ => colormap(0.0),
        };
        for pts in &connections {
            p.polygon(pts, fill);
        }
    }
    for blk in frame.blocks.iter().filter(|b| !b.is_ground) {
        let pts: Vec<[f32; 2]> = blk
            .rigid
            .iter()
            .zip(&blk.vertices)
            .map(|(r, a)| exaggerate(*r, *a, factor))
            .collect();
        if view.layers.blocks {
            // The close-up is about positions, not strain: plain blocks let the ghost and
            // the slip arrow stand out.
            let color = match view.color_by {
                _ if panel.close_up => MATERIAL,
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
        for pts in &connections {
            p.outline(pts, 1.0, CONNECTION);
        }
    }
    if view.layers.bolts {
        for b in &frame.bolts {
            let a = exaggerate(b.rigid[0], b.points[0], factor);
            let c = exaggerate(b.rigid[1], b.points[1], factor);
            p.spring(a, c, 8.0, 6, 2.0, BOLT);
        }
    }
    if view.layers.contacts {
        for c in &frame.contacts {
            let at = exaggerate(c.rigid, c.point, factor);
            draw_contact(p, c, at);
        }
    }
    if view.layers.slip
        && let Some(top) = top
    {
        draw_slip(p, panel, top);
    }
}

/// A polygon's outline as dashes `dash_px` long.
fn dashed_outline(p: &mut Painter<'_>, pts: &[[f32; 2]], width_px: f32, dash_px: f32, c: [f32; 4]) {
    let dash = dash_px * p.t.metres_per_pixel;
    for k in 0..pts.len() {
        let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let n = (len / dash).floor().min(2000.0) as usize;
        for i in (0..n).step_by(2) {
            let (s0, s1) = (
                i as f32 * dash / len,
                ((i + 1) as f32 * dash / len).min(1.0),
            );
            let at = |s: f32| [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            p.line(at(s0), at(s1), width_px, c);
        }
    }
}

/// The slip: the range the base has slipped over (skid marks on the ground) and an arrow
/// from where the base started (on the ground) to where it is.
fn draw_slip(p: &mut Painter<'_>, panel: &PanelView<'_>, top: f32) {
    let frame = panel.frame;
    let mpp = p.t.metres_per_pixel;
    let slip = frame.probes.slip as f32;
    let Some(base) = frame.blocks.get(frame.base) else {
        return;
    };
    // A reference point of the base: its left end, now and at the start (on the ground).
    let left_now = base
        .vertices
        .iter()
        .map(|v| v[0])
        .fold(f32::INFINITY, f32::min);
    let left_start = left_now - slip;
    let [lo, hi] = panel.slip_range;
    if hi > lo {
        p.line(
            [left_start + lo, top - 4.0 * mpp],
            [left_start + hi, top - 4.0 * mpp],
            4.0,
            TRACE,
        );
    }
    let (height, width) = if panel.close_up {
        (24.0, 4.0)
    } else {
        (12.0, 2.0)
    };
    p.line(
        [left_start, top - height * mpp],
        [left_start, top + height * mpp],
        width,
        SLIP_ARROW,
    );
    if slip.abs() > 3.0 * mpp {
        let at = top + 0.6 * height * mpp;
        p.arrow([left_start, at], [left_now, at], 1.5 * width, SLIP_ARROW);
    }
}

/// A contact as a short normal spring (and a shear spring when stuck) at its point.
fn draw_contact(p: &mut Painter<'_>, c: &ContactFrame, a: [f32; 2]) {
    let color = match c.state {
        1 => LOCKED,
        2 => SLIDING,
        _ => OPEN,
    };
    let mpp = p.t.metres_per_pixel;
    let n = [c.tangent[1], -c.tangent[0]];
    // The vertex sits on the edge; the edge's outward normal points to the vertex block.
    let len = 18.0 * mpp;
    let b = [a[0] - n[0] * len, a[1] - n[1] * len];
    p.spring(b, a, 4.0, 3, 2.0, color);
    if c.state == 1 {
        let t = [c.along_edge * c.tangent[0], c.along_edge * c.tangent[1]];
        let s = [a[0] + t[0] * len, a[1] + t[1] * len];
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
