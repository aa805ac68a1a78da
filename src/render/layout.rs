//! Where things go on screen: the camera (zoom, pan, what it follows), the box that frames
//! a model, the joint close-up's scale, and the layout of the model panels and their
//! close-ups in an area. Plain CPU code shared by the window, the pictures and the tests.

use super::geometry::{PanelView, PixelRect, ViewBox, exaggerate, ground_top};
use crate::sim::ModelFrame;

/// What the camera keeps still on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Follow {
    /// The world: the ground shakes, a sliding building stays nearly still.
    #[default]
    World,
    /// The ground: the building slides over a still ground.
    Ground,
    /// The base: the ground slides under a still base.
    Base,
}

/// The user's camera, shared by all model panels so that they stay comparable: a zoom
/// factor over the fitted view and a pan, both applied to the fitted box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Magnification over the fitted view (1: the whole model fits).
    pub zoom: f32,
    /// Offset of the view centre from the fitted centre, m.
    pub pan: [f32; 2],
    /// What stays still.
    pub follow: Follow,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            pan: [0.0, 0.0],
            follow: Follow::World,
        }
    }
}

impl Camera {
    /// Back to the fitted view (keeps what it follows).
    pub fn fit(&mut self) {
        self.zoom = 1.0;
        self.pan = [0.0, 0.0];
    }

    /// The view of one model in a panel of `size` pixels.
    pub fn view(&self, frame: &ModelFrame, fit: &Fit, size: [f32; 2]) -> ViewBox {
        let mpp = fit.metres_per_pixel(size) / self.zoom.max(1e-3);
        let follow = match self.follow {
            Follow::World => 0.0,
            Follow::Ground => frame.probes.ground_disp as f32,
            Follow::Base => base_centre_x(frame),
        };
        ViewBox {
            centre: [
                fit.centre[0] + self.pan[0] + follow,
                fit.centre[1] + self.pan[1],
            ],
            metres_per_pixel: mpp,
        }
    }

    /// Zooms by `factor` keeping the world point under `pointer` (pixels from the panel
    /// centre, y down) where it is.
    pub fn zoom_about(&mut self, factor: f32, pointer: [f32; 2], view: &ViewBox) {
        let factor = factor.clamp(0.01, 100.0);
        let new_zoom = (self.zoom * factor).clamp(0.2, 5000.0);
        let applied = new_zoom / self.zoom;
        // World offset of the pointer from the centre, before and after.
        let dx = pointer[0] * view.metres_per_pixel;
        let dy = -pointer[1] * view.metres_per_pixel;
        self.pan[0] += dx * (1.0 - 1.0 / applied);
        self.pan[1] += dy * (1.0 - 1.0 / applied);
        self.zoom = new_zoom;
    }

    /// Pans by a pointer drag of `delta` pixels (y down).
    pub fn drag(&mut self, delta: [f32; 2], view: &ViewBox) {
        self.pan[0] -= delta[0] * view.metres_per_pixel;
        self.pan[1] += delta[1] * view.metres_per_pixel;
    }
}

/// The horizontal position of the base's centre now, m (frame coordinates).
pub fn base_centre_x(frame: &ModelFrame) -> f32 {
    frame.blocks.get(frame.base).map_or(0.0, |b| {
        b.vertices.iter().map(|v| v[0]).sum::<f32>() / b.vertices.len().max(1) as f32
    })
}

/// A world box that frames a model: centre and half extents, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// Centre, m.
    pub centre: [f32; 2],
    /// Half width and half height, m.
    pub half: [f32; 2],
}

impl Fit {
    /// Metres per pixel that fit the box into `size` pixels.
    pub fn metres_per_pixel(&self, size: [f32; 2]) -> f32 {
        (2.0 * self.half[0] / size[0].max(1.0)).max(2.0 * self.half[1] / size[1].max(1.0))
    }

    /// Whether `other` lies inside this box (with 5 % to spare).
    pub fn contains(&self, other: &Fit) -> bool {
        (0..2).all(|d| {
            (other.centre[d] - self.centre[d]).abs() + other.half[d] <= 1.05 * self.half[d]
        })
    }

    /// The box around all of `frames` as drawn with `exaggeration`, with a margin; the
    /// ground's top stays in view below the structure.
    pub fn of_frames<'a>(
        frames: impl IntoIterator<Item = &'a ModelFrame>,
        exaggeration: f32,
    ) -> Self {
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        let mut ground = 0.0f32;
        for frame in frames {
            ground = ground_top(frame).unwrap_or(ground);
            for b in frame.blocks.iter().filter(|b| !b.is_ground) {
                for (r, v) in b.rigid.iter().zip(&b.vertices) {
                    let p = exaggerate(*r, *v, exaggeration);
                    for d in 0..2 {
                        if p[d].is_finite() {
                            lo[d] = lo[d].min(p[d]);
                            hi[d] = hi[d].max(p[d]);
                        }
                    }
                }
            }
        }
        if !lo[0].is_finite() {
            return Self {
                centre: [0.0, 2.0],
                half: [5.0, 3.0],
            };
        }
        let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(0.5);
        let bottom = lo[1].min(ground) - 0.10 * size;
        // Room above for the model's title and readout, drawn over the panel's top.
        let top = hi[1] + 0.30 * size;
        let (left, right) = (lo[0] - 0.06 * size, hi[0] + 0.06 * size);
        Self {
            centre: [0.5 * (left + right), 0.5 * (bottom + top)],
            half: [0.5 * (right - left), 0.5 * (top - bottom)],
        }
    }
}

/// The view of a joint close-up in a panel of `size` pixels: wide enough for `slip_scale`
/// metres of slip either way (3.5 × the largest slip across), centred between where the
/// base's left end started and where it is, with the ground's top in its lower part.
pub fn close_up_view(frame: &ModelFrame, slip_scale: f32, size: [f32; 2]) -> ViewBox {
    let width = (3.5 * slip_scale.abs()).max(0.05);
    let mpp = width / size[0].max(1.0);
    let slip = frame.probes.slip as f32;
    let left_now = frame.blocks.get(frame.base).map_or(0.0, |b| {
        b.vertices
            .iter()
            .map(|v| v[0])
            .fold(f32::INFINITY, f32::min)
    });
    let top = ground_top(frame).unwrap_or(0.0);
    ViewBox {
        centre: [left_now - 0.5 * slip, top + 0.12 * size[1] * mpp],
        metres_per_pixel: mpp,
    }
}

/// Whether model panels are stacked one above the other (a tall area) rather than side by
/// side.
pub fn stack_vertically(width: f32, height: f32, panels: usize) -> bool {
    panels > 1 && height > 0.8 * width
}

/// Where one model goes: its main panel and, if shown, its joint close-up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// The model's panel.
    pub main: PixelRect,
    /// The close-up of its sliding joint.
    pub close_up: Option<PixelRect>,
}

/// Splits an area (x, y, w, h, pixels) into one cell per model: side by side, or stacked
/// in a tall area; each cell gives its lower part (or, stacked, its right part) to the
/// joint close-up when `close_ups` is set.
pub fn cells(area: PixelRect, models: usize, close_ups: bool) -> Vec<Cell> {
    let [x, y, w, h] = area;
    let n = models.max(1) as f32;
    let stacked = stack_vertically(w, h, models);
    (0..models)
        .map(|k| {
            let k = k as f32;
            let cell = if stacked {
                [x, y + k * h / n, w, h / n]
            } else {
                [x + k * w / n, y, w / n, h]
            };
            if !close_ups {
                return Cell {
                    main: cell,
                    close_up: None,
                };
            }
            let [cx, cy, cw, ch] = cell;
            if stacked {
                let side = (0.38 * cw).min(1.6 * ch);
                Cell {
                    main: [cx, cy, cw - side, ch],
                    close_up: Some([cx + cw - side, cy, side, ch]),
                }
            } else {
                let below = (0.32 * ch).min(0.6 * cw);
                Cell {
                    main: [cx, cy, cw, ch - below],
                    close_up: Some([cx, cy + ch - below, cw, below]),
                }
            }
        })
        .collect()
}

/// What the scene needs besides the frames: camera, per-model fits, close-up scale.
#[derive(Debug, Clone)]
pub struct SceneLayout {
    /// The cells, one per model.
    pub cells: Vec<Cell>,
    /// The views of the main panels.
    pub views: Vec<ViewBox>,
    /// The views of the close-ups.
    pub close_up_views: Vec<Option<ViewBox>>,
}

/// Lays the models out in `area` (pixels): cells, and the camera's view of each.
pub fn layout(
    frames: &[ModelFrame],
    fits: &[Fit],
    camera: &Camera,
    slip_scale: f32,
    area: PixelRect,
    close_ups: bool,
) -> SceneLayout {
    let cells = cells(area, frames.len(), close_ups);
    // One scale for all panels (the tightest fit), so that they compare.
    let mpp = cells
        .iter()
        .zip(fits)
        .map(|(c, f)| f.metres_per_pixel([c.main[2], c.main[3]]))
        .fold(0.0f32, f32::max);
    let views = frames
        .iter()
        .zip(&cells)
        .zip(fits)
        .map(|((frame, cell), fit)| {
            let mut v = camera.view(frame, fit, [cell.main[2], cell.main[3]]);
            v.metres_per_pixel = mpp / camera.zoom.max(1e-3);
            v
        })
        .collect();
    let close_up_views = frames
        .iter()
        .zip(&cells)
        .map(|(frame, cell)| {
            cell.close_up
                .map(|r| close_up_view(frame, slip_scale, [r[2], r[3]]))
        })
        .collect();
    SceneLayout {
        cells,
        views,
        close_up_views,
    }
}

impl SceneLayout {
    /// The panels to draw for `frames`, with the slip ranges reached so far.
    pub fn panels<'a>(
        &self,
        frames: &'a [ModelFrame],
        slip_ranges: &[[f32; 2]],
    ) -> Vec<PanelView<'a>> {
        let mut out = Vec::new();
        for (k, frame) in frames.iter().enumerate() {
            let (Some(cell), Some(view)) = (self.cells.get(k), self.views.get(k)) else {
                continue;
            };
            let slip_range = slip_ranges.get(k).copied().unwrap_or([0.0, 0.0]);
            out.push(PanelView {
                frame,
                rect: cell.main,
                view: *view,
                slip_range,
                close_up: false,
            });
            if let (Some(rect), Some(Some(view))) = (cell.close_up, self.close_up_views.get(k)) {
                out.push(PanelView {
                    frame,
                    rect,
                    view: *view,
                    slip_range,
                    close_up: true,
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_one_two_five() {
        use crate::render::geometry::nice_step;
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(0.011), 0.02);
        assert!((nice_step(3.2) - 5.0).abs() < 1e-6);
    }

    #[test]
    fn zooming_about_a_point_keeps_it_under_the_pointer() {
        let mut cam = Camera::default();
        let view = ViewBox {
            centre: [0.0, 0.0],
            metres_per_pixel: 0.01,
        };
        // The point 100 px right of the centre is at x = 1 m; after zooming ×2 about it,
        // it must still be 100 px right of the centre.
        cam.zoom_about(2.0, [100.0, 0.0], &view);
        let mpp = 0.01 / 2.0;
        let x_at_pointer = cam.pan[0] + 100.0 * mpp;
        assert!((x_at_pointer - 1.0).abs() < 1e-6, "{x_at_pointer}");
    }

    #[test]
    fn close_ups_take_the_lower_part_or_the_side() {
        let wide = cells([0.0, 0.0, 1000.0, 500.0], 2, true);
        assert_eq!(wide.len(), 2);
        let c = wide[1].close_up.unwrap();
        assert!(c[1] > wide[1].main[1] && (c[0] - 500.0).abs() < 1e-3);
        let tall = cells([0.0, 0.0, 500.0, 1000.0], 2, true);
        let c = tall[0].close_up.unwrap();
        assert!(c[0] > 0.0 && (c[1] - 0.0).abs() < 1e-3);
    }
}
