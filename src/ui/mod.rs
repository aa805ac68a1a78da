//! The egui side of the visualizer: the controls, the timeline, the plots and the overlay
//! labels, around a central area where the wgpu renderer draws the scene. All state lives
//! in [`AppState`], which knows nothing about windows: it takes simulation messages in and
//! gives commands out, so its logic can be tested with a bare `egui::Context`.

mod plots;

use crate::dda::Integrator;
use crate::ground_motion::STANDARD_GRAVITY;
use crate::render::{ColorBy, Layers};
use crate::sim::{ExactOverlay, Excitation, FrameSet, SimCommand, SimConfig, SimMessage};

/// The scenes offered in the panel.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneChoice {
    /// The paper's three-storey frame.
    ThreeStorey,
    /// The paper's two-mass model (Fig. 2).
    TwoBlock,
    /// A scene file.
    File(String),
}

impl SceneChoice {
    fn name(&self) -> String {
        match self {
            SceneChoice::ThreeStorey => "three-storey".into(),
            SceneChoice::TwoBlock => "two-block".into(),
            SceneChoice::File(p) => p.clone(),
        }
    }
}

/// The ground motions offered in the panel.
#[derive(Debug, Clone, PartialEq)]
pub enum RecordChoice {
    /// A shipped record by name.
    Builtin(String),
    /// Harmonic input.
    Harmonic,
    /// A file (AT2 or CSV).
    File(String),
}

/// What the user has set in the panel (applied with a restart).
#[derive(Debug, Clone, PartialEq)]
pub struct Controls {
    /// Scene.
    pub scene: SceneChoice,
    /// Ground motion.
    pub record: RecordChoice,
    /// Harmonic amplitude, g.
    pub amplitude_g: f64,
    /// Harmonic frequency: Ω/ω for the two-block scene, Hz otherwise.
    pub frequency: f64,
    /// Friction coefficient of the sliding joint.
    pub friction: f64,
    /// Mass ratio α (two-block scene).
    pub alpha: f64,
    /// Integrator.
    pub integrator: Integrator,
    /// Time step, s.
    pub dt: f64,
    /// Run the fixed-base comparison beside the sliding model.
    pub compare_fixed: bool,
    /// Path typed in the file field.
    pub path_input: String,
}

impl Default for Controls {
    fn default() -> Self {
        Self {
            scene: SceneChoice::ThreeStorey,
            record: RecordChoice::Builtin("el-centro".into()),
            amplitude_g: 0.3,
            frequency: 1.0,
            friction: 0.01,
            alpha: 0.5,
            integrator: Integrator::default(),
            dt: 1e-3,
            compare_fixed: true,
            path_input: String::new(),
        }
    }
}

impl Controls {
    /// The simulation configuration these controls describe.
    pub fn config(&self) -> SimConfig {
        let two_block = self.scene == SceneChoice::TwoBlock;
        SimConfig {
            scene: self.scene.name(),
            friction: Some(self.friction),
            alpha: two_block.then_some(self.alpha),
            excitation: match &self.record {
                RecordChoice::Builtin(n) => Excitation::Record(n.clone()),
                RecordChoice::File(p) => Excitation::Record(p.clone()),
                RecordChoice::Harmonic => Excitation::Harmonic {
                    amplitude_g: self.amplitude_g,
                    frequency: self.frequency,
                },
            },
            integrator: self.integrator,
            dt: self.dt,
            compare_fixed: self.compare_fixed,
            duration: None,
            ..SimConfig::default()
        }
    }
}

/// Everything the simulation has published for the current run.
#[derive(Debug, Clone, Default)]
pub struct Timeline {
    /// Run generation (0: none yet).
    pub generation: u64,
    /// Model labels.
    pub labels: Vec<String>,
    /// All frames so far, in time order.
    pub frames: Vec<FrameSet>,
    /// Duration of the run, s.
    pub duration: f64,
    /// Exact mass-spring overlay (two-block).
    pub exact: Option<ExactOverlay>,
    /// Simulated seconds per wall second.
    pub sim_speed: f64,
    /// The run reached its end.
    pub finished: bool,
    /// The configuration of this run.
    pub config: Option<SimConfig>,
}

impl Timeline {
    /// Time of the last frame, s.
    pub fn available(&self) -> f64 {
        self.frames.last().map_or(0.0, |f| f.time)
    }

    /// Index of the frame shown at time `t` (the last one at or before it).
    pub fn index_at(&self, t: f64) -> Option<usize> {
        if self.frames.is_empty() {
            return None;
        }
        let k = self.frames.partition_point(|f| f.time <= t + 1e-9);
        Some(k.saturating_sub(1))
    }
}

/// The whole visualizer state.
pub struct AppState {
    /// Panel controls.
    pub controls: Controls,
    /// What the simulation published.
    pub timeline: Timeline,
    /// Time shown, s.
    pub play_time: f64,
    /// Playing (or paused).
    pub playing: bool,
    /// Playback speed (simulated s per wall s).
    pub speed: f64,
    /// Start again at the end.
    pub looping: bool,
    /// Layers drawn.
    pub layers: Layers,
    /// Deformation exaggeration.
    pub exaggeration: f32,
    /// Block colouring.
    pub color_by: ColorBy,
    /// Errors to show (bad file, solver stopped…).
    pub error: Option<String>,
    /// Smoothed frame time, ms.
    pub frame_ms: f64,
    /// Time to take in one batch of frames from the channel, µs (the state hand-off).
    pub handoff_us: f64,
    /// Mean time the simulation thread takes to copy a frame out of the solvers, µs.
    pub extract_us: f64,
    /// Where the named widgets were last drawn (for tests and automation that click them).
    pub widget_rects: std::collections::HashMap<&'static str, egui::Rect>,
    outbox: Vec<SimCommand>,
}

impl Default for AppState {
    fn default() -> Self {
        Self::new(Controls::default())
    }
}

impl AppState {
    /// A state that will start a run with these controls.
    pub fn new(controls: Controls) -> Self {
        let mut s = Self {
            controls,
            timeline: Timeline::default(),
            play_time: 0.0,
            playing: true,
            speed: 1.0,
            looping: true,
            layers: Layers::default(),
            exaggeration: 50.0,
            color_by: ColorBy::Strain,
            error: None,
            frame_ms: 0.0,
            handoff_us: 0.0,
            extract_us: 0.0,
            widget_rects: Default::default(),
            outbox: Vec::new(),
        };
        s.restart();
        s
    }

    /// Queues a run with the current controls (from t = 0, in the background).
    pub fn restart(&mut self) {
        self.error = None;
        self.outbox
            .push(SimCommand::Run(Box::new(self.controls.config())));
    }

    /// Commands for the simulation thread since the last call.
    pub fn take_commands(&mut self) -> Vec<SimCommand> {
        std::mem::take(&mut self.outbox)
    }

    /// Takes in a message from the simulation thread.
    pub fn ingest(&mut self, msg: SimMessage) {
        let t0 = std::time::Instant::now();
        match msg {
            SimMessage::Started {
                generation,
                config,
                duration,
                labels,
                exact,
                first,
            } => {
                self.timeline = Timeline {
                    generation,
                    labels,
                    frames: vec![*first],
                    duration,
                    exact: exact.map(|e| *e),
                    sim_speed: 0.0,
                    finished: false,
                    config: Some(*config),
                };
                self.play_time = 0.0;
            }
            SimMessage::Frames {
                generation,
                frames,
                speed,
                extract_us,
            } if generation == self.timeline.generation => {
                self.timeline.frames.extend(frames);
                self.timeline.sim_speed = speed;
                self.extract_us = extract_us;
                self.handoff_us = 0.9 * self.handoff_us + 0.1 * t0.elapsed().as_secs_f64() * 1e6;
            }
            SimMessage::Finished { generation, .. } if generation == self.timeline.generation => {
                self.timeline.finished = true;
            }
            SimMessage::Failed { message, .. } => self.error = Some(message),
            _ => {}
        }
    }

    /// Advances the playback clock by `wall_dt` seconds of wall time.
    pub fn advance(&mut self, wall_dt: f64) {
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * wall_dt * 1e3;
        if !self.playing {
            return;
        }
        let available = self.timeline.available();
        self.play_time += wall_dt * self.speed;
        if self.play_time >= self.timeline.duration - 1e-9 && self.timeline.finished && self.looping
        {
            self.play_time = 0.0;
        } else if self.play_time > available {
            // Wait for the simulation (it runs ahead in real time on this machine).
            self.play_time = available;
        }
    }

    /// The frame shown now.
    pub fn current(&self) -> Option<&FrameSet> {
        self.timeline
            .index_at(self.play_time)
            .map(|k| &self.timeline.frames[k])
    }

    /// Moves the time cursor by `frames` frames (keyboard stepping).
    pub fn step_frames(&mut self, frames: i64) {
        if let Some(k) = self.timeline.index_at(self.play_time) {
            let k = (k as i64 + frames).clamp(0, self.timeline.frames.len() as i64 - 1) as usize;
            self.play_time = self.timeline.frames[k].time;
        }
        self.playing = false;
    }

    /// Largest colour measure over all frames so far (a stable colour scale).
    pub fn color_max(&self) -> f32 {
        let mut m = f32::MIN_POSITIVE;
        for f in &self.timeline.frames {
            for model in &f.models {
                for b in model.blocks.iter().filter(|b| !b.is_ground) {
                    m = m.max(crate::render::geometry::color_measure(
                        self.color_by,
                        &b.stress,
                        &b.strain,
                    ));
                }
            }
        }
        m
    }

    /// Draws the whole UI; returns the rectangle (in points) left for the scene.
    pub fn ui(&mut self, ui: &mut egui::Ui) -> egui::Rect {
        self.keyboard(ui.ctx());
        egui::Panel::left("controls")
            .resizable(true)
            .default_size(290.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls_ui(ui));
            });
        egui::Panel::bottom("timeline").show(ui, |ui| self.timeline_ui(ui));
        egui::Panel::right("plots")
            .resizable(true)
            .default_size(460.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| plots::plots_ui(self, ui));
            });
        let response = egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| {
                let rect = ui.max_rect();
                self.overlay(ui, rect);
                rect
            });
        response.inner
    }

    fn keyboard(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (space, left, right, home) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::Space),
                i.key_pressed(egui::Key::ArrowLeft),
                i.key_pressed(egui::Key::ArrowRight),
                i.key_pressed(egui::Key::Home),
            )
        });
        if space {
            self.playing = !self.playing;
        }
        if left {
            self.step_frames(-1);
        }
        if right {
            self.step_frames(1);
        }
        if home {
            self.play_time = 0.0;
        }
    }

    fn controls_ui(&mut self, ui: &mut egui::Ui) {
        let before = self.controls.clone();
        ui.heading("slidebase");
        ui.label("A building on a sliding (friction) base under an earthquake, computed with DDA.");
        ui.separator();
        egui::ComboBox::from_label("scene")
            .selected_text(match &self.controls.scene {
                SceneChoice::ThreeStorey => "three-storey frame".to_string(),
                SceneChoice::TwoBlock => "two-block (paper Fig. 2)".to_string(),
                SceneChoice::File(p) => p.clone(),
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut self.controls.scene,
                    SceneChoice::ThreeStorey,
                    "three-storey frame",
                );
                ui.selectable_value(
                    &mut self.controls.scene,
                    SceneChoice::TwoBlock,
                    "two-block (paper Fig. 2)",
                );
            });
        let record_text = match &self.controls.record {
            RecordChoice::Builtin(n) => n.clone(),
            RecordChoice::Harmonic => "harmonic".into(),
            RecordChoice::File(p) => p.clone(),
        };
        egui::ComboBox::from_label("ground motion")
            .selected_text(record_text)
            .show_ui(ui, |ui| {
                for name in crate::ground_motion::builtin_names() {
                    ui.selectable_value(
                        &mut self.controls.record,
                        RecordChoice::Builtin(name.to_string()),
                        name,
                    );
                }
                ui.selectable_value(
                    &mut self.controls.record,
                    RecordChoice::Harmonic,
                    "harmonic",
                );
            });
        if self.controls.record == RecordChoice::Harmonic {
            ui.add(
                egui::Slider::new(&mut self.controls.amplitude_g, 0.01..=1.5).text("amplitude (g)"),
            );
            let label = if self.controls.scene == SceneChoice::TwoBlock {
                "Ω/ω"
            } else {
                "frequency (Hz)"
            };
            ui.add(
                egui::Slider::new(&mut self.controls.frequency, 0.1..=10.0)
                    .logarithmic(true)
                    .text(label),
            );
        }
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.controls.path_input)
                    .hint_text("AT2/CSV record or TOML scene")
                    .desired_width(170.0),
            );
            let load = ui.button("load");
            self.widget_rects.insert("load", load.rect);
            if load.clicked() {
                self.load_path();
            }
        });
        ui.separator();
        let r = ui.add(
            egui::Slider::new(&mut self.controls.friction, 0.0..=1.0)
                .logarithmic(true)
                .smallest_positive(0.001)
                .text("friction ρ"),
        );
        self.widget_rects.insert("friction", r.rect);
        if self.controls.scene == SceneChoice::TwoBlock {
            ui.add(egui::Slider::new(&mut self.controls.alpha, 0.05..=0.95).text("mass ratio α"));
        }
        egui::ComboBox::from_label("integrator")
            .selected_text(self.controls.integrator.label())
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut self.controls.integrator,
                    Integrator::default(),
                    "generalized-alpha (ρ∞ = 0)",
                );
                ui.selectable_value(
                    &mut self.controls.integrator,
                    Integrator::Trapezoidal,
                    "trapezoidal",
                );
                ui.selectable_value(
                    &mut self.controls.integrator,
                    Integrator::Classic,
                    "classic DDA (the paper's)",
                );
            });
        ui.add(
            egui::Slider::new(&mut self.controls.dt, 1e-4..=1e-2)
                .logarithmic(true)
                .text("Δt (s)"),
        );
        ui.checkbox(&mut self.controls.compare_fixed, "fixed-base comparison");
        if self.controls != before {
            // Any change of the physics restarts the run from t = 0, in the background.
            self.restart();
        }
        ui.separator();
        ui.label("view");
        ui.add(
            egui::Slider::new(&mut self.exaggeration, 1.0..=1000.0)
                .logarithmic(true)
                .text("exaggeration ×"),
        );
        egui::ComboBox::from_label("colour")
            .selected_text(format!("{:?}", self.color_by).to_lowercase())
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.color_by, ColorBy::Strain, "strain (this run)");
                ui.selectable_value(&mut self.color_by, ColorBy::Stress, "stress (with gravity)");
                ui.selectable_value(&mut self.color_by, ColorBy::Material, "material");
            });
        let l = &mut self.layers;
        ui.horizontal_wrapped(|ui| {
            ui.checkbox(&mut l.blocks, "blocks");
            ui.checkbox(&mut l.outlines, "outlines");
            ui.checkbox(&mut l.contacts, "contact springs");
            ui.checkbox(&mut l.slip, "slip");
            ui.checkbox(&mut l.bolts, "bolts");
            ui.checkbox(&mut l.connections, "connections");
            ui.checkbox(&mut l.ground, "ground");
        });
        ui.separator();
        ui.label(format!(
            "simulation: {:.1}× real time{}",
            self.timeline.sim_speed,
            if self.timeline.finished {
                " (done)"
            } else {
                ""
            }
        ));
        ui.label(format!(
            "frame time: {:.1} ms ({:.0} fps)",
            self.frame_ms,
            1000.0 / self.frame_ms.max(1e-3)
        ));
        ui.label(format!(
            "state hand-off: {:.0} µs to copy a frame out, {:.1} µs to take a batch in",
            self.extract_us, self.handoff_us
        ));
        if let Some(e) = &self.error {
            ui.separator();
            ui.colored_label(egui::Color32::from_rgb(200, 30, 30), e);
        }
    }

    /// Loads the path typed in the file field: a TOML scene or a record file. Errors are
    /// shown in the panel; nothing crashes.
    pub fn load_path(&mut self) {
        let path = self.controls.path_input.trim().to_string();
        if path.is_empty() {
            self.error = Some("type the path of an AT2/CSV record or a TOML scene first".into());
            return;
        }
        if path.to_lowercase().ends_with(".toml") {
            match crate::model::Scene::load(std::path::Path::new(&path)) {
                Ok(_) => {
                    self.controls.scene = SceneChoice::File(path);
                    self.restart();
                }
                Err(e) => self.error = Some(e.to_string()),
            }
            return;
        }
        match crate::ground_motion::read_record_file(std::path::Path::new(&path)) {
            Ok(_) => {
                self.controls.record = RecordChoice::File(path);
                self.restart();
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn timeline_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            if ui
                .button(if self.playing { "pause" } else { "play" })
                .clicked()
            {
                self.playing = !self.playing;
            }
            if ui.button("|<").on_hover_text("start (Home)").clicked() {
                self.play_time = 0.0;
            }
            if ui
                .button("<")
                .on_hover_text("one frame back (left arrow)")
                .clicked()
            {
                self.step_frames(-1);
            }
            if ui
                .button(">")
                .on_hover_text("one frame on (right arrow)")
                .clicked()
            {
                self.step_frames(1);
            }
            let max = self.timeline.duration.max(1e-3);
            let available = self.timeline.available();
            let mut t = self.play_time;
            let slider = egui::Slider::new(&mut t, 0.0..=max)
                .text("t (s)")
                .fixed_decimals(2);
            let r = ui.add_sized([ui.available_width() * 0.55, 20.0], slider);
            self.widget_rects.insert("time", r.rect);
            // Only the user moves the cursor: the slider also reports a change when it
            // rounds the playing time to its two decimals, which must not pause playback.
            let by_user = r.dragged() || r.drag_stopped() || r.clicked() || r.has_focus();
            if r.changed() && by_user {
                self.play_time = t.min(available);
                self.playing = false;
            }
            egui::ComboBox::from_id_salt("speed")
                .selected_text(format!("{}×", self.speed))
                .width(60.0)
                .show_ui(ui, |ui| {
                    for s in [0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0] {
                        ui.selectable_value(&mut self.speed, s, format!("{s}×"));
                    }
                });
            ui.checkbox(&mut self.looping, "loop");
            ui.label(format!("computed to {available:.1} / {max:.1} s"));
        });
    }

    /// Labels over the scene: panel names, time, peak values and the colour scale.
    fn overlay(&self, ui: &mut egui::Ui, rect: egui::Rect) {
        let Some(frame) = self.current() else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "starting…",
                egui::FontId::proportional(18.0),
                egui::Color32::DARK_GRAY,
            );
            return;
        };
        let n = frame.models.len().max(1) as f32;
        let stacked = crate::render::offscreen::stack_vertically(
            rect.width(),
            rect.height(),
            frame.models.len(),
        );
        let (w, hgt) = if stacked {
            (rect.width(), rect.height() / n)
        } else {
            (rect.width() / n, rect.height())
        };
        let painter = ui.painter_at(rect);
        for (k, model) in frame.models.iter().enumerate() {
            let label = self.timeline.labels.get(k).cloned().unwrap_or_default();
            let (x0, y0) = if stacked {
                (rect.left(), rect.top() + k as f32 * hgt)
            } else {
                (rect.left() + k as f32 * w, rect.top())
            };
            let text = format!(
                "{label}\nroof {:+.3} g   base {:+.3} g   slip {:+.3} m   drift {:+.4} m",
                model.probes.roof_accel / STANDARD_GRAVITY,
                model.probes.base_accel / STANDARD_GRAVITY,
                model.probes.slip,
                model.probes.drift
            );
            painter.text(
                egui::pos2(x0 + 10.0, y0 + 8.0),
                egui::Align2::LEFT_TOP,
                text,
                egui::FontId::proportional(14.0),
                egui::Color32::from_gray(30),
            );
            if k > 0 {
                let line = if stacked {
                    [egui::pos2(rect.left(), y0), egui::pos2(rect.right(), y0)]
                } else {
                    [egui::pos2(x0, rect.top()), egui::pos2(x0, rect.bottom())]
                };
                painter.line_segment(line, egui::Stroke::new(1.0, egui::Color32::from_gray(160)));
            }
        }
        painter.text(
            egui::pos2(rect.right() - 10.0, rect.bottom() - 10.0),
            egui::Align2::RIGHT_BOTTOM,
            format!(
                "t = {:.2} s   ground {:+.3} g   deformation ×{:.0}",
                frame.time,
                frame.models[0].probes.ground_accel / STANDARD_GRAVITY,
                self.exaggeration
            ),
            egui::FontId::proportional(14.0),
            egui::Color32::from_gray(30),
        );
        // Colour scale.
        if self.color_by != ColorBy::Material {
            let bar = egui::Rect::from_min_size(
                egui::pos2(rect.left() + 12.0, rect.bottom() - 34.0),
                egui::vec2(160.0, 10.0),
            );
            for i in 0..32 {
                let c = crate::render::geometry::colormap(i as f32 / 31.0);
                let srgb = |v: f32| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0) as u8;
                let r = egui::Rect::from_min_size(
                    egui::pos2(bar.left() + i as f32 * 5.0, bar.top()),
                    egui::vec2(5.0, 10.0),
                );
                painter.rect_filled(
                    r,
                    0.0,
                    egui::Color32::from_rgb(srgb(c[0]), srgb(c[1]), srgb(c[2])),
                );
            }
            let max = self.color_max();
            let unit = match self.color_by {
                ColorBy::Stress => format!("von Mises stress 0 … {:.2e} Pa", max),
                _ => format!("strain 0 … {:.2e}", max),
            };
            painter.text(
                egui::pos2(bar.left(), bar.bottom() + 3.0),
                egui::Align2::LEFT_TOP,
                unit,
                egui::FontId::proportional(12.0),
                egui::Color32::from_gray(30),
            );
        }
        let legend = [
            ("locked", crate::render::geometry::LOCKED),
            ("sliding", crate::render::geometry::SLIDING),
            ("open", crate::render::geometry::OPEN),
        ];
        for (i, (name, c)) in legend.iter().enumerate() {
            let srgb = |v: f32| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0) as u8;
            let pos = egui::pos2(rect.left() + 190.0 + i as f32 * 70.0, rect.bottom() - 30.0);
            painter.circle_filled(
                pos,
                5.0,
                egui::Color32::from_rgb(srgb(c[0]), srgb(c[1]), srgb(c[2])),
            );
            painter.text(
                pos + egui::vec2(8.0, 0.0),
                egui::Align2::LEFT_CENTER,
                *name,
                egui::FontId::proportional(12.0),
                egui::Color32::from_gray(30),
            );
        }
    }
}
