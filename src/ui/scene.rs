//! The scene: the models drawn by the wgpu renderer (through an egui paint callback, so the
//! same code draws into the window, into pictures and into video frames) with their
//! overlays — a header (time, ground acceleration, record, the headline result), a title
//! and readout per model, the joint close-ups with their scale bars, and a footer legend
//! (contact states, colour bar, what is magnified). Wheel or pinch zooms about the pointer,
//! dragging pans, a double click fits.

use crate::ground_motion::STANDARD_GRAVITY;
use crate::render::Renderer;
use crate::render::geometry::{self, ColorBy, Layers, PanelView, SceneView, Vertex, ViewBox};
use crate::render::layout::{Camera, Fit, SceneLayout, layout};
use crate::sim::FrameSet;

use super::AppState;

/// The renderer's part of an egui frame: triangles tessellated on the UI thread, uploaded
/// and drawn by the [`Renderer`] kept in egui-wgpu's callback resources.
pub struct SceneCallback {
    vertices: Vec<Vertex>,
}

impl egui_wgpu::CallbackTrait for SceneCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = resources.get_mut::<Renderer>() {
            r.upload(device, queue, &self.vertices);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(r) = resources.get::<Renderer>() {
            r.draw(pass);
        }
    }
}

/// What a picture of the scene needs (the window, `render` pictures and video frames).
#[derive(Debug, Clone)]
pub struct SceneInputs {
    /// The models at one time.
    pub frames: FrameSet,
    /// One label per model.
    pub labels: Vec<String>,
    /// The record or excitation, for the header.
    pub motion: String,
    /// The headline result, if any.
    pub headline: Option<String>,
    /// Per model: the box that frames it.
    pub fits: Vec<Fit>,
    /// The camera.
    pub camera: Camera,
    /// Deformation exaggeration.
    pub exaggeration: f32,
    /// Block colouring and the top of its scale.
    pub color_by: ColorBy,
    /// Top of the colour scale.
    pub color_max: f32,
    /// Layers.
    pub layers: Layers,
    /// Draw the joint close-ups.
    pub close_ups: bool,
    /// Largest |slip| of the run (sets the close-ups' scale, the same for all).
    pub slip_scale: f32,
    /// Per model: the slip range reached so far.
    pub slip_ranges: Vec<[f32; 2]>,
    /// A note for the header ("computing up to 9.84 s…").
    pub note: Option<String>,
    /// The unit the readouts give the drift in: mm, or µm for a structure as stiff as a
    /// block wall, whose drift would read "+0.0 mm" (chosen once for the run so far, so
    /// that it does not switch as the drift swings through zero).
    pub drift_unit: DriftUnit,
}

/// Text colour over the (light) sky.
const INK: egui::Color32 = egui::Color32::from_gray(25);

fn srgb(c: [f32; 4]) -> egui::Color32 {
    let f = |v: f32| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0) as u8;
    egui::Color32::from_rgb(f(c[0]), f(c[1]), f(c[2]))
}

/// Points → pixels for the renderer: panels relative to the callback rectangle.
fn to_pixels<'a>(panels: Vec<PanelView<'a>>, origin: egui::Pos2, ppp: f32) -> Vec<PanelView<'a>> {
    panels
        .into_iter()
        .map(|mut p| {
            p.rect = [
                (p.rect[0] - origin.x) * ppp,
                (p.rect[1] - origin.y) * ppp,
                p.rect[2] * ppp,
                p.rect[3] * ppp,
            ];
            p.view = ViewBox {
                centre: p.view.centre,
                metres_per_pixel: p.view.metres_per_pixel / ppp,
            };
            p
        })
        .collect()
}

/// Lays out `text` wrapped to `width` points.
fn galley(
    ui: &egui::Ui,
    text: String,
    size: f32,
    color: egui::Color32,
    width: f32,
) -> std::sync::Arc<egui::Galley> {
    ui.painter().layout(
        text,
        egui::FontId::proportional(size),
        color,
        width.max(20.0),
    )
}

/// Draws the scene with its overlays into `rect`; returns the layout used (in points).
pub fn draw_scene(ui: &mut egui::Ui, rect: egui::Rect, s: &SceneInputs) -> SceneLayout {
    // No fill: the window is cleared with the panel colour (see `unfilled_panel`).
    let painter = ui.painter_at(rect);
    let big = (rect.width() / 55.0).clamp(13.0, 22.0);
    let small = (big * 0.72).clamp(11.0, 15.0);
    // Header: time, ground, record; the headline below.
    let ground = s
        .frames
        .models
        .first()
        .map_or(0.0, |m| m.probes.ground_accel / STANDARD_GRAVITY);
    let mut header = format!(
        "t = {:.2} s    ground {:+.3} g    {}",
        s.frames.time, ground, s.motion
    );
    if let Some(note) = &s.note {
        header += &format!("    {note}");
    }
    let text = ui.visuals().strong_text_color();
    let g_header = galley(ui, header, big, text, rect.width() - 16.0);
    let g_headline = s.headline.as_ref().map(|h| {
        galley(
            ui,
            h.clone(),
            big * 0.9,
            super::plots::model_color(0),
            rect.width() - 16.0,
        )
    });
    let mut header_h = 6.0 + g_header.size().y + 4.0;
    if let Some(g) = &g_headline {
        header_h += g.size().y + 2.0;
    }
    // Footer: the legend, laid out in a flow.
    let footer = footer_items(ui, s, small);
    let footer_h = flow_height(&footer, rect.width() - 16.0) + 8.0;
    let area = egui::Rect::from_min_max(
        rect.min + egui::vec2(0.0, header_h),
        rect.max - egui::vec2(0.0, footer_h),
    );
    let lay = layout(
        &s.frames.models,
        &s.fits,
        &s.camera,
        s.slip_scale,
        [area.left(), area.top(), area.width(), area.height()],
        s.close_ups && s.layers.slip,
    );
    let ppp = ui.ctx().pixels_per_point();
    let panels = to_pixels(lay.panels(&s.frames.models, &s.slip_ranges), rect.min, ppp);
    let view = SceneView {
        panels,
        exaggeration: s.exaggeration,
        color_by: s.color_by,
        color_max: s.color_max,
        layers: s.layers,
    };
    let vertices = geometry::build(&view, [rect.width() * ppp, rect.height() * ppp]);
    painter.add(egui_wgpu::Callback::new_paint_callback(
        rect,
        SceneCallback { vertices },
    ));
    // Header and headline.
    let mut y = rect.top() + 6.0;
    painter.galley(egui::pos2(rect.left() + 8.0, y), g_header.clone(), text);
    y += g_header.size().y + 4.0;
    if let Some(g) = g_headline {
        painter.galley(egui::pos2(rect.left() + 8.0, y), g, text);
    }
    model_labels(ui, &painter, &lay, s, big, small);
    close_up_labels(ui, &painter, &lay, s, small);
    draw_flow(
        &painter,
        &footer,
        egui::pos2(rect.left() + 8.0, rect.bottom() - footer_h + 4.0),
        rect.width() - 16.0,
    );
    lay
}

/// Title and readout of each model, over its panel; separators between panels.
fn model_labels(
    ui: &egui::Ui,
    painter: &egui::Painter,
    lay: &SceneLayout,
    s: &SceneInputs,
    big: f32,
    small: f32,
) {
    for (k, (model, cell)) in s.frames.models.iter().zip(&lay.cells).enumerate() {
        let [x, y, w, h] = cell.main;
        let label = s.labels.get(k).cloned().unwrap_or_default();
        let color = super::plots::model_color(k);
        let title = galley(ui, label, big, color, w - 16.0);
        let p = model.probes;
        let readout = if model.single_body {
            format!(
                "block {} g   slip {} m",
                signed(p.base_accel / STANDARD_GRAVITY, 3),
                signed(p.slip, 3)
            )
        } else {
            format!(
                "roof {} g   base {} g   slip {} m   drift {} {}",
                signed(p.roof_accel / STANDARD_GRAVITY, 3),
                signed(p.base_accel / STANDARD_GRAVITY, 3),
                signed(p.slip, 3),
                signed(p.drift * s.drift_unit.per_metre(), 1),
                s.drift_unit.symbol()
            )
        };
        let g_readout = galley(ui, readout, small, INK, w - 16.0);
        let pos = egui::pos2(x + 8.0, y + 4.0);
        let back = egui::Rect::from_min_size(
            pos - egui::vec2(4.0, 2.0),
            egui::vec2(
                title.size().x.max(g_readout.size().x) + 8.0,
                title.size().y + g_readout.size().y + 6.0,
            ),
        );
        painter.rect_filled(back, 3.0, egui::Color32::from_white_alpha(230));
        painter.galley(pos, title.clone(), color);
        painter.galley(pos + egui::vec2(0.0, title.size().y + 2.0), g_readout, INK);
        if k > 0 {
            painter.line_segment(
                if cell.main[0] > lay.cells[0].main[0] {
                    [egui::pos2(x, y), egui::pos2(x, y + h)]
                } else {
                    [egui::pos2(x, y), egui::pos2(x + w, y)]
                },
                egui::Stroke::new(2.0, ui.visuals().panel_fill),
            );
        }
    }
}

/// The close-ups' titles, scale bars, slip values and the ghost's label.
fn close_up_labels(
    ui: &egui::Ui,
    painter: &egui::Painter,
    lay: &SceneLayout,
    s: &SceneInputs,
    small: f32,
) {
    for ((model, cell), (view, main)) in s
        .frames
        .models
        .iter()
        .zip(&lay.cells)
        .zip(lay.close_up_views.iter().zip(&lay.views))
    {
        let (Some(r), Some(view)) = (cell.close_up, view) else {
            continue;
        };
        let rect = egui::Rect::from_min_size(egui::pos2(r[0], r[1]), egui::vec2(r[2], r[3]));
        painter.rect_stroke(
            rect.shrink(1.0),
            0.0,
            egui::Stroke::new(2.0, ui.visuals().panel_fill),
            egui::StrokeKind::Inside,
        );
        let magnification = main.metres_per_pixel / view.metres_per_pixel;
        let title = galley(
            ui,
            format!(
                "sliding joint, close-up ×{:.0} (true scale)   slip {:+.3} m",
                magnification, model.probes.slip
            ),
            small,
            INK,
            rect.width() - 16.0,
        );
        let pos = rect.left_top() + egui::vec2(8.0, 4.0);
        painter.rect_filled(
            egui::Rect::from_min_size(
                pos - egui::vec2(3.0, 1.0),
                title.size() + egui::vec2(6.0, 2.0),
            ),
            3.0,
            egui::Color32::from_white_alpha(230),
        );
        painter.galley(pos, title, INK);
        // Scale bar: about a quarter of the width, a round length.
        let metres = geometry::nice_step(0.22 * rect.width() * view.metres_per_pixel);
        let len = metres / view.metres_per_pixel;
        let y = rect.bottom() - 10.0;
        let x1 = rect.right() - 12.0;
        let x0 = x1 - len;
        let bar = egui::Stroke::new(3.0, INK);
        painter.line_segment([egui::pos2(x0, y), egui::pos2(x1, y)], bar);
        for x in [x0, x1] {
            painter.line_segment([egui::pos2(x, y - 5.0), egui::pos2(x, y + 1.0)], bar);
        }
        let label = if metres >= 1.0 {
            format!("{} m", crate::post::format_number(metres as f64))
        } else {
            format!("{} cm", crate::post::format_number(100.0 * metres as f64))
        };
        painter.text(
            egui::pos2(0.5 * (x0 + x1), y - 6.0),
            egui::Align2::CENTER_BOTTOM,
            label,
            egui::FontId::proportional(small),
            INK,
        );
        // "start" over the ghost's left end.
        if let Some(gx) = model.base_start.iter().map(|v| v[0]).reduce(f32::min) {
            let sx = rect.center().x + (gx - view.centre[0]) / view.metres_per_pixel;
            if sx > rect.left() + 20.0 && sx < rect.right() - 20.0 {
                let top = geometry::ground_top(model).unwrap_or(0.0);
                let sy = rect.center().y - (top - view.centre[1]) / view.metres_per_pixel;
                painter.text(
                    egui::pos2(sx, sy + 26.0),
                    egui::Align2::CENTER_TOP,
                    "start",
                    egui::FontId::proportional(small),
                    egui::Color32::from_rgb(200, 20, 20),
                );
            }
        }
    }
}

/// One legend item: a swatch (dot or colour ramp) and its text.
enum Swatch {
    Dot(egui::Color32),
    Ramp,
    None,
}

fn footer_items(
    ui: &egui::Ui,
    s: &SceneInputs,
    size: f32,
) -> Vec<(Swatch, std::sync::Arc<egui::Galley>)> {
    let mut items = Vec::new();
    let mut add = |sw, text: String| {
        items.push((
            sw,
            galley(ui, text, size, ui.visuals().text_color(), f32::INFINITY),
        ))
    };
    if s.layers.contacts {
        add(Swatch::Dot(srgb(geometry::LOCKED)), "stuck".into());
        add(Swatch::Dot(srgb(geometry::SLIDING)), "sliding".into());
        add(Swatch::Dot(srgb(geometry::OPEN)), "open".into());
    }
    if s.layers.slip {
        add(
            Swatch::Dot(egui::Color32::from_rgb(217, 26, 26)),
            "where the base started".into(),
        );
        add(
            Swatch::Dot(egui::Color32::from_rgb(242, 191, 51)),
            "slipped over".into(),
        );
    }
    match s.color_by {
        ColorBy::Strain => add(Swatch::Ramp, format!("strain 0 … {:.1e}", s.color_max)),
        ColorBy::Stress => add(
            Swatch::Ramp,
            format!("von Mises stress 0 … {:.2} MPa", s.color_max / 1e6),
        ),
        ColorBy::Material => {}
    }
    add(
        Swatch::None,
        format!(
            "deformation ×{} (slip and ground motion true scale)",
            crate::post::format_number(s.exaggeration as f64)
        ),
    );
    items
}

const SWATCH_W: f32 = 40.0;

fn item_width(item: &(Swatch, std::sync::Arc<egui::Galley>)) -> f32 {
    let sw = match item.0 {
        Swatch::Dot(_) => 14.0,
        Swatch::Ramp => SWATCH_W + 6.0,
        Swatch::None => 0.0,
    };
    sw + item.1.size().x + 16.0
}

fn flow_height(items: &[(Swatch, std::sync::Arc<egui::Galley>)], width: f32) -> f32 {
    let line = items.iter().map(|i| i.1.size().y).fold(0.0, f32::max) + 2.0;
    let mut x = 0.0;
    let mut lines = 1.0;
    for item in items {
        let w = item_width(item);
        if x > 0.0 && x + w > width {
            lines += 1.0;
            x = 0.0;
        }
        x += w;
    }
    lines * line
}

fn draw_flow(
    painter: &egui::Painter,
    items: &[(Swatch, std::sync::Arc<egui::Galley>)],
    origin: egui::Pos2,
    width: f32,
) {
    let line = items.iter().map(|i| i.1.size().y).fold(0.0, f32::max) + 2.0;
    let (mut x, mut y) = (0.0, 0.0);
    for item in items {
        let w = item_width(item);
        if x > 0.0 && x + w > width {
            x = 0.0;
            y += line;
        }
        let at = origin + egui::vec2(x, y);
        let mid = at.y + 0.5 * item.1.size().y;
        let mut tx = at.x;
        match item.0 {
            Swatch::Dot(c) => {
                painter.circle_filled(egui::pos2(at.x + 5.0, mid), 5.0, c);
                tx += 14.0;
            }
            Swatch::Ramp => {
                for i in 0..20 {
                    let c = srgb(geometry::colormap(i as f32 / 19.0));
                    let r = egui::Rect::from_min_size(
                        egui::pos2(at.x + i as f32 * SWATCH_W / 20.0, mid - 5.0),
                        egui::vec2(SWATCH_W / 20.0 + 0.5, 10.0),
                    );
                    painter.rect_filled(r, 0.0, c);
                }
                tx += SWATCH_W + 6.0;
            }
            Swatch::None => {}
        }
        painter.galley(
            egui::pos2(tx, at.y),
            item.1.clone(),
            egui::Color32::PLACEHOLDER,
        );
        x += w;
    }
}

/// The slip range of each model up to time `t`, and the largest |slip| of the whole run
/// computed (the close-ups' scale).
pub fn slip_extent(state: &AppState, t: f64) -> (Vec<[f32; 2]>, f32) {
    let mut scale = 0.0f32;
    let ranges = state
        .timeline
        .samples
        .iter()
        .map(|s| {
            let n = s.count_until(t);
            for v in &s.slip {
                scale = scale.max(v.abs() as f32);
            }
            s.slip[..n].iter().fold([0.0f32, 0.0], |r, &v| {
                [r[0].min(v as f32), r[1].max(v as f32)]
            })
        })
        .collect();
    (ranges, scale)
}

/// What the scene shows for `state` at its time cursor (None before the first frame).
pub fn inputs_of(state: &mut AppState) -> Option<SceneInputs> {
    let frames = state.current()?.clone();
    let mut fits = state.fits(false);
    // A model that grows out of its box (resonance) gets a new fit, unless the user zoomed.
    if state.view.camera.zoom == 1.0 {
        let f = state.exaggeration();
        let outgrown = frames
            .models
            .iter()
            .zip(&fits)
            .any(|(m, fit)| !fit.contains(&Fit::of_frames([m], f)));
        if outgrown {
            fits = state.fits(true);
        }
    }
    let (slip_ranges, slip_scale) = slip_extent(state, state.play_time);
    let motion = &state.timeline.motion;
    let mut motion_text = if motion.scale != 1.0 {
        format!("{} scaled to PGA {:.2} g", motion.name, motion.pga_g)
    } else {
        format!("{} (PGA {:.2} g)", motion.name, motion.pga_g)
    };
    if let Some((name, peak)) = &motion.vertical {
        motion_text.push_str(&format!(" + vertical {name} ({peak:.2} g)"));
    }
    Some(SceneInputs {
        frames,
        labels: state.timeline.labels.clone(),
        motion: motion_text,
        headline: state.headline().map(|h| h.0),
        fits,
        camera: state.view.camera,
        exaggeration: state.exaggeration(),
        color_by: state.view.color_by,
        color_max: state.color_max(),
        layers: state.view.layers,
        close_ups: state.view.close_ups,
        slip_scale,
        slip_ranges,
        note: state.picture_note(),
        drift_unit: DriftUnit::for_peak(state.timeline.peak_drift()),
    })
}

/// The scene area of the window: the picture, then camera input.
pub fn scene_ui(state: &mut AppState, ui: &mut egui::Ui) {
    let rect = ui.max_rect();
    let Some(inputs) = inputs_of(state) else {
        let text = match &state.error {
            Some(e) => e.clone(),
            None => "starting…".into(),
        };
        ui.painter().text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            text,
            egui::FontId::proportional(18.0),
            ui.visuals().text_color(),
        );
        return;
    };
    let response = ui.interact(
        rect,
        ui.scope_id().with("scene"),
        egui::Sense::click_and_drag(),
    );
    state.widget_rects.insert("scene", rect);
    let lay = draw_scene(ui, rect, &inputs);
    // The camera: wheel or pinch zooms about the pointer, drag pans, double click fits.
    let hovered_panel = response.hover_pos().and_then(|pos| {
        lay.cells.iter().zip(&lay.views).find_map(|(c, v)| {
            let r = egui::Rect::from_min_size(
                egui::pos2(c.main[0], c.main[1]),
                egui::vec2(c.main[2], c.main[3]),
            );
            r.contains(pos).then_some((r, *v, pos))
        })
    });
    if let Some((r, view, pos)) = hovered_panel {
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        let factor = (scroll * 0.003).exp() * pinch;
        if (factor - 1.0).abs() > 1e-4 {
            let offset = pos - r.center();
            state
                .view
                .camera
                .zoom_about(factor, [offset.x, offset.y], &view);
        }
        if response.dragged() {
            let d = response.drag_delta();
            state.view.camera.drag([d.x, d.y], &view);
        }
    }
    if response.double_clicked() {
        state.view.camera.fit();
    }
}

/// The unit of the readouts' drift (see [`SceneInputs::drift_unit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriftUnit {
    /// Millimetres: a frame's drift.
    Millimetre,
    /// Micrometres: a block wall's, below 0.1 mm at its peak.
    Micrometre,
}

impl DriftUnit {
    /// The unit for a run whose largest drift so far is `peak_m` metres.
    pub fn for_peak(peak_m: f64) -> Self {
        if peak_m > 0.0 && peak_m < 1e-4 {
            DriftUnit::Micrometre
        } else {
            DriftUnit::Millimetre
        }
    }

    fn per_metre(self) -> f64 {
        match self {
            DriftUnit::Millimetre => 1e3,
            DriftUnit::Micrometre => 1e6,
        }
    }

    fn symbol(self) -> &'static str {
        match self {
            DriftUnit::Millimetre => "mm",
            DriftUnit::Micrometre => "µm",
        }
    }
}

/// `value` with its sign and `decimals` decimals, a value that rounds to zero as "+0.000"
/// (not "-0.000": a readout that flickers between −0 and +0 says nothing).
pub fn signed(value: f64, decimals: usize) -> String {
    let scale = 10f64.powi(decimals as i32);
    let rounded = (value * scale).round() / scale;
    let shown = if rounded == 0.0 { 0.0 } else { rounded };
    format!("{shown:+.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::{DriftUnit, signed};

    #[test]
    fn readouts_have_no_negative_zero_and_a_wall_drifts_in_micrometres() {
        assert_eq!(signed(-0.00004, 3), "+0.000");
        assert_eq!(signed(-0.0006, 3), "-0.001");
        assert_eq!(signed(0.25, 1), "+0.3");
        assert_eq!(DriftUnit::for_peak(2.4e-6), DriftUnit::Micrometre);
        assert_eq!(DriftUnit::for_peak(0.0148), DriftUnit::Millimetre);
        assert_eq!(DriftUnit::for_peak(0.0), DriftUnit::Millimetre);
    }
}
