//! The controls panel (left): what is simulated, what it is compared with, how it is
//! drawn. Every control has a tooltip in plain words. A change of the physics restarts the
//! run in the background and keeps the time cursor; typing a path restarts nothing until
//! "load" is pressed.

use super::{
    AppState, Comparison, Exaggeration, LawChoice, RecordChoice, SceneChoice, WINDOW_MAX_COURSES,
    WINDOW_MAX_STOREYS,
};
use crate::dda::Integrator;
use crate::render::{ColorBy, Follow};

/// Width of the combo boxes, points (long names are elided, with the full name on hover).
const COMBO_WIDTH: f32 = 170.0;

impl AppState {
    pub(super) fn controls_ui(&mut self, ui: &mut egui::Ui) {
        let before = self.controls.clone();
        ui.add_space(4.0);
        self.section_model(ui);
        ui.separator();
        self.section_ground(ui);
        ui.separator();
        self.section_compare(ui);
        egui::CollapsingHeader::new("solver settings")
            .default_open(false)
            .show(ui, |ui| self.section_solver(ui));
        if self.controls != before {
            self.preset = None;
            self.restart();
        }
        ui.separator();
        self.section_view(ui);
        ui.separator();
        self.section_export(ui);
        egui::CollapsingHeader::new("diagnostics")
            .default_open(self.view.show_diagnostics)
            .show(ui, |ui| self.section_diagnostics(ui));
        if let Some(e) = &self.error {
            ui.separator();
            ui.colored_label(ui.visuals().error_fg_color, e);
        }
    }

    fn section_model(&mut self, ui: &mut egui::Ui) {
        ui.strong("structure");
        let label = self.controls.scene.label();
        egui::ComboBox::from_id_salt("scene")
            .selected_text(label.clone())
            .width(COMBO_WIDTH)
            .truncate()
            .show_ui(ui, |ui| {
                let c = &mut self.controls.scene;
                ui.selectable_value(c, SceneChoice::ThreeStorey, SceneChoice::ThreeStorey.label())
                    .on_hover_text("the paper's frame: three storeys of slabs and columns on a base slab that can slide");
                ui.selectable_value(c, SceneChoice::TwoBlock, SceneChoice::TwoBlock.label())
                    .on_hover_text("the paper's simplest model: a mass on a spring over a raft that can slide; its exact solution is drawn dashed in the plots");
                ui.selectable_value(c, SceneChoice::Block, SceneChoice::Block.label())
                    .on_hover_text("Newmark's sliding block: one rigid block on the joint, the textbook starting point; its exact solution is in the plots");
                ui.selectable_value(c, SceneChoice::FrictionPendulum, SceneChoice::FrictionPendulum.label())
                    .on_hover_text("a thin slider in a concave dish of radius 2 m: gravity pulls it back to the middle (period 2π√(R/g) = 2.8 s)");
                let (storeys, courses) = self.generated_sizes;
                let frame = if let SceneChoice::Frame(n) = c { *n } else { storeys };
                ui.selectable_value(c, SceneChoice::Frame(frame), "frame of N storeys (generated)")
                    .on_hover_text("the paper's frame with any number of storeys");
                let wall = if let SceneChoice::Wall(n) = c { *n } else { courses };
                ui.selectable_value(c, SceneChoice::Wall(wall), "dry-stacked wall (generated)")
                    .on_hover_text("loose blocks stacked in running bond on a sliding slab: every touching pair can slide, open and close");
            })
            .response
            .on_hover_text(format!("the structure simulated: {label}"));
        match &mut self.controls.scene {
            SceneChoice::Frame(n) => {
                ui.add(egui::Slider::new(n, 1..=WINDOW_MAX_STOREYS).text("storeys"))
                    .on_hover_text(format!(
                        "how many storeys the generated frame has: 1 to {WINDOW_MAX_STOREYS} \
                         here, where the replay keeps every frame of both models (the \
                         command line runs up to frame:{}: slidebase run --scene frame:N)",
                        crate::model::generated::MAX_FRAME_STOREYS
                    ));
            }
            SceneChoice::Wall(n) => {
                ui.add(egui::Slider::new(n, 2..=WINDOW_MAX_COURSES).text("courses"))
                    .on_hover_text(format!(
                        "how many courses of blocks the wall has (about N² blocks): 2 to \
                         {WINDOW_MAX_COURSES} here, where the replay keeps every frame of both \
                         models (the command line runs up to wall:{}: slidebase run --scene \
                         wall:N)",
                        crate::model::generated::MAX_WALL
                    ));
            }
            _ => {}
        }
        match self.controls.scene {
            SceneChoice::Frame(n) => self.generated_sizes.0 = n,
            SceneChoice::Wall(n) => self.generated_sizes.1 = n,
            _ => {}
        }
        let r = ui
            .add(
                egui::Slider::new(&mut self.controls.friction, 0.001..=1.0)
                    .logarithmic(true)
                    .text("friction ρ"),
            )
            .on_hover_text(
                "the friction coefficient of the sliding joint under the base: the base slides \
                 once the ground would have to push it harder than ρ × its weight",
            );
        self.widget_rects.insert("friction", r.rect);
        self.law_controls(ui);
        if self.controls.scene == SceneChoice::TwoBlock {
            ui.add(egui::Slider::new(&mut self.controls.alpha, 0.05..=0.95).text("mass ratio α"))
                .on_hover_text("the structure's share of the total mass: α = m / (M + m)");
        }
        if self.controls.damping_applies() {
            let how = if self.controls.scene == SceneChoice::TwoBlock {
                "a dashpot beside the spring, ζ of critical. The exact solution drawn dashed \
                 is damped alike"
            } else {
                "Rayleigh damping of the frame, ζ of critical at its first two sway modes, \
                 acting on the floors' motion relative to the base slab"
            };
            let r = ui
                .add(egui::Slider::new(&mut self.controls.damping, 0.0..=0.2).text("damping ζ"))
                .on_hover_text(format!(
                    "structural damping: {how} (0.02 to 0.05 is typical of buildings); the \
                     sliding itself is never damped"
                ));
            self.widget_rects.insert("damping", r.rect);
        }
        if self.controls.bearing_applies() {
            self.bearing_controls(ui);
        }
    }

    /// The friction law of the joint, built on the ρ slider (its coefficient at rest).
    fn law_controls(&mut self, ui: &mut egui::Ui) {
        let law = &mut self.controls.law;
        let rho = self.controls.friction;
        let name = |l: &LawChoice| match l {
            LawChoice::Coulomb => "Coulomb (one ρ)",
            LawChoice::StaticKinetic { .. } => "static / kinetic",
            LawChoice::Velocity { .. } => "velocity dependent",
        };
        let r = egui::ComboBox::from_id_salt("friction law")
            .selected_text(name(law))
            .width(COMBO_WIDTH)
            .show_ui(ui, |ui| {
                let coulomb = LawChoice::Coulomb;
                ui.selectable_value(law, coulomb, name(&coulomb))
                    .on_hover_text("the paper's law: the joint sticks up to ρ·N and slides against ρ·N");
                let sk = LawChoice::StaticKinetic {
                    stick: (1.6 * rho).min(1.0),
                };
                if !matches!(law, LawChoice::StaticKinetic { .. }) {
                    ui.selectable_value(law, sk, name(&sk))
                } else {
                    ui.selectable_label(true, name(&sk))
                }
                .on_hover_text("sticks up to μ_s·N, then slides against the lower μ_k·N (μ_k is ρ): the base breaks loose with a jerk");
                let v = LawChoice::Velocity {
                    fast: (2.0 * rho).min(1.0),
                    rate: 20.0,
                };
                if !matches!(law, LawChoice::Velocity { .. }) {
                    ui.selectable_value(law, v, name(&v))
                } else {
                    ui.selectable_label(true, name(&v))
                }
                .on_hover_text("μ(v) = μ_fast − (μ_fast − ρ)·exp(−rate·|v|), as OpenSees' velocity-dependent friction of PTFE bearings: faster sliding, more friction");
            })
            .response
            .on_hover_text("the friction law of the sliding joint; the ρ slider is its coefficient at rest");
        self.widget_rects.insert("friction law", r.rect);
        match &mut self.controls.law {
            LawChoice::Coulomb => {}
            LawChoice::StaticKinetic { stick } => {
                ui.add(egui::Slider::new(stick, rho.max(0.001)..=1.0).logarithmic(true).text("static μ_s"))
                    .on_hover_text("the coefficient the joint sticks up to; once it slides, ρ (the kinetic one) acts");
            }
            LawChoice::Velocity { fast, rate } => {
                ui.add(
                    egui::Slider::new(fast, rho.max(0.001)..=1.0)
                        .logarithmic(true)
                        .text("μ_fast"),
                )
                .on_hover_text("the coefficient at high slip speed");
                ui.add(egui::Slider::new(rate, 1.0..=200.0).logarithmic(true).text("rate (s/m)"))
                    .on_hover_text("how fast μ rises from ρ to μ_fast with the slip speed: at v = 1/rate it is 63 % of the way");
            }
        }
    }

    /// The frame's bearings: the flat joint, or two friction pendulums of radius R.
    fn bearing_controls(&mut self, ui: &mut egui::Ui) {
        let mut pendulum = self.controls.bearing_radius.is_some();
        let r = ui
            .checkbox(&mut pendulum, "friction-pendulum bearings")
            .on_hover_text(
                "stand the base slab on two friction pendulums instead of the flat joint: \
                 pointed feet sliding in concave dishes. Gravity pulls the building back \
                 to the middle, so it does not stay where an earthquake left it",
            );
        self.widget_rects.insert("bearing", r.rect);
        if pendulum != self.controls.bearing_radius.is_some() {
            self.controls.bearing_radius =
                pendulum.then_some(crate::model::bearing::DEFAULT_RADIUS_M);
            if !pendulum && self.controls.comparison == Comparison::FlatJoint {
                self.controls.comparison = Comparison::FixedBase;
            }
        }
        if let Some(radius) = &mut self.controls.bearing_radius {
            ui.add(
                egui::Slider::new(radius, 0.5..=10.0)
                    .logarithmic(true)
                    .text("dish radius R (m)"),
            )
            .on_hover_text(
                "the bearings' effective radius: the building swings like a pendulum of \
                 this length, period 2π√(R/g) (2.8 s at 2 m); larger R, weaker recentring",
            );
        }
    }

    fn section_ground(&mut self, ui: &mut egui::Ui) {
        ui.strong("earthquake");
        let text = match &self.controls.record {
            RecordChoice::Builtin(n) => n.clone(),
            RecordChoice::Harmonic => "harmonic (sine wave)".into(),
            RecordChoice::File(p) => super::file_name(p),
        };
        let full = match &self.controls.record {
            RecordChoice::File(p) => p.clone(),
            _ => text.clone(),
        };
        egui::ComboBox::from_id_salt("ground motion")
            .selected_text(text)
            .width(COMBO_WIDTH)
            .truncate()
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
                    "harmonic (sine wave)",
                );
            })
            .response
            .on_hover_text(format!("the ground motion: {full}"));
        if self.controls.record == RecordChoice::Harmonic {
            ui.add(
                egui::Slider::new(&mut self.controls.amplitude_g, 0.01..=1.5).text("amplitude (g)"),
            )
            .on_hover_text("peak ground acceleration of the sine wave, in g (9.81 m/s²)");
            let two_block = self.controls.scene == SceneChoice::TwoBlock;
            let label = if two_block { "Ω/ω" } else { "frequency (Hz)" };
            ui.add(
                egui::Slider::new(&mut self.controls.frequency, 0.1..=10.0)
                    .logarithmic(true)
                    .text(label),
            )
            .on_hover_text(if two_block {
                "the ground's frequency over the structure's own (1 Hz): 1 is resonance"
            } else {
                "the ground's frequency, Hz (the three-storey frame's first is 0.64 Hz)"
            });
        } else {
            let info = &self.timeline.motion;
            if !info.name.is_empty() {
                let mut text = format!("PGA {:.2} g", info.pga_g);
                if let Some(dt) = info.dt {
                    text += &format!(", Δt {:.3} s", dt);
                }
                if let Some(d) = info.duration {
                    text += &format!(", {d:.1} s");
                }
                ui.label(text).on_hover_text(format!(
                    "peak ground acceleration, sample interval and length of the record as run{}",
                    if info.source.is_empty() {
                        String::new()
                    } else {
                        format!("\nsource: {}", info.source)
                    }
                ));
                if !info.source.is_empty() {
                    ui.add(
                        egui::Label::new(egui::RichText::new(&info.source).small().weak())
                            .truncate(),
                    )
                    .on_hover_text(&info.source);
                }
            }
            let mut scale = self.controls.pga_g.is_some();
            ui.horizontal(|ui| {
                ui.checkbox(&mut scale, "scale to PGA")
                    .on_hover_text("scale the whole record so that its peak ground acceleration is the value chosen");
                if scale {
                    let mut pga = self.controls.pga_g.unwrap_or(0.3);
                    ui.add(egui::DragValue::new(&mut pga).range(0.01..=2.0).speed(0.01).suffix(" g"))
                        .on_hover_text("the peak ground acceleration to scale the record to, g");
                    self.controls.pga_g = Some(pga);
                } else {
                    self.controls.pga_g = None;
                }
            });
            self.vertical_toggle(ui);
        }
        ui.horizontal(|ui| {
            let field = ui
                .add(
                    egui::TextEdit::singleline(&mut self.path_input)
                        .hint_text("record (AT2/CSV) or scene (TOML) file")
                        .desired_width((ui.available_width() - 50.0).max(80.0)),
                )
                .on_hover_text("type the path of a PEER .AT2 or two-column CSV record, or a TOML scene, or a scene's name (wall:8, frame:4), then press load");
            self.widget_rects.insert("path", field.rect);
            let enter = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            let load = ui
                .button("load")
                .on_hover_text("load the file typed on the left (restarts the run)");
            self.widget_rects.insert("load", load.rect);
            if load.clicked() || enter {
                self.load_path();
            }
        });
    }

    /// "vertical shaking": adds El Centro's vertical component (the normal force, and with
    /// it the friction capacity, follows the ground's vertical acceleration).
    fn vertical_toggle(&mut self, ui: &mut egui::Ui) {
        let available = self.controls.vertical_available();
        let r = ui
            .add_enabled(
                available,
                egui::Checkbox::new(&mut self.controls.vertical, "vertical shaking"),
            )
            .on_hover_text(
                "shake the ground up and down too, with the station's vertical record \
                 (el-centro-up): the weight on the sliding joint, and with it the friction \
                 that can hold the base, rises and falls with the ground",
            )
            .on_disabled_hover_text(
                "only the El Centro records come with their vertical component here",
            );
        self.widget_rects.insert("vertical", r.rect);
    }

    fn section_compare(&mut self, ui: &mut egui::Ui) {
        ui.strong("compare with");
        let pendulum = self.controls.bearing().is_some();
        let c = &mut self.controls.comparison;
        let kind = match c {
            Comparison::None => 0,
            Comparison::FixedBase => 1,
            Comparison::Friction(_) => 2,
            Comparison::FrictionAndFixed(_) => 3,
            Comparison::FlatJoint => 4,
        };
        let mut choice = kind;
        ui.horizontal_wrapped(|ui| {
            if pendulum {
                ui.radio_value(&mut choice, 4, "flat joint").on_hover_text(
                    "the same frame on the flat sliding joint, same friction: it slides as \
                     far but stays where the earthquake leaves it",
                );
            }
            ui.radio_value(&mut choice, 1, "fixed base").on_hover_text(
                "the same structure with its base fixed to the ground: what isolation saves",
            );
            ui.radio_value(&mut choice, 2, "other friction")
                .on_hover_text("the same structure sliding with another friction coefficient");
            ui.radio_value(&mut choice, 0, "nothing")
                .on_hover_text("only the sliding model (faster)");
        });
        let others = match c {
            Comparison::Friction(f) | Comparison::FrictionAndFixed(f) => f.clone(),
            _ => vec![0.1],
        };
        if choice != kind {
            *c = match choice {
                0 => Comparison::None,
                1 => Comparison::FixedBase,
                4 => Comparison::FlatJoint,
                _ => Comparison::Friction(others.clone()),
            };
        }
        if let Comparison::Friction(f) | Comparison::FrictionAndFixed(f) = c {
            // One slider per compared model (a preset can compare several).
            let names = ["second ρ", "third ρ", "fourth ρ", "fifth ρ"];
            for (k, rho) in f.iter_mut().enumerate() {
                ui.add(
                    egui::Slider::new(rho, 0.001..=1.0)
                        .logarithmic(true)
                        .text(names.get(k).copied().unwrap_or("another ρ")),
                )
                .on_hover_text(format!(
                    "the friction coefficient of model {} from the left",
                    k + 2
                ));
            }
        }
    }

    fn section_solver(&mut self, ui: &mut egui::Ui) {
        egui::ComboBox::from_id_salt("integrator")
            .selected_text(integrator_text(self.controls.integrator))
            .width(COMBO_WIDTH)
            .truncate()
            .show_ui(ui, |ui| {
                let choices = [
                    (None, "the scene's choice (generalized-α)"),
                    (
                        Some(Integrator::default()),
                        "generalized-α ρ∞ 0 (damps only numerical noise)",
                    ),
                    (
                        Some(Integrator::GeneralizedAlpha { rho_inf: 0.5 }),
                        "generalized-α ρ∞ 0.5 (rigid blocks)",
                    ),
                    (
                        Some(Integrator::Trapezoidal),
                        "trapezoidal (no numerical damping)",
                    ),
                    (
                        Some(Integrator::Classic),
                        "classic DDA (the paper's; damps strongly)",
                    ),
                ];
                for (value, label) in choices {
                    ui.selectable_value(&mut self.controls.integrator, value, label);
                }
            })
            .response
            .on_hover_text(
                "how the equations of motion are stepped in time. The scene's choice is \
                 generalized-α: ρ∞ 0 for deformable buildings (removes their unresolved \
                 high-frequency modes in one step), ρ∞ 0.5 for the rigid two-block model \
                 (more accurate at high excitation frequencies)",
            );
        ui.add(
            egui::Slider::new(&mut self.controls.dt, 1e-4..=1e-2)
                .logarithmic(true)
                .text("time step Δt (s)"),
        )
        .on_hover_text(
            "the solver's time step: smaller is more accurate and slower (1 ms is accurate)",
        );
    }

    fn section_view(&mut self, ui: &mut egui::Ui) {
        ui.strong("view");
        let v = &mut self.view;
        let mut auto = v.exaggeration == Exaggeration::Auto;
        let mut factor = match v.exaggeration {
            Exaggeration::Fixed(f) => f,
            Exaggeration::Auto => 50.0,
        };
        ui.horizontal(|ui| {
            ui.checkbox(&mut auto, "auto")
                .on_hover_text("choose the magnification so that the largest storey drift is drawn as about 8 % of the height");
            ui.add_enabled(
                !auto,
                egui::Slider::new(&mut factor, 1.0..=1000.0)
                    .logarithmic(true)
                    .text("deformation ×"),
            )
            .on_hover_text(
                "magnifies how the structure deforms (storey drift, strain) — not the slip or the \
                 ground motion, which are drawn true to scale",
            );
        });
        v.exaggeration = if auto {
            Exaggeration::Auto
        } else {
            Exaggeration::Fixed(factor)
        };
        egui::ComboBox::from_label("colour")
            .selected_text(match v.color_by {
                ColorBy::Strain => "strain",
                ColorBy::Stress => "stress",
                ColorBy::Material => "plain",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut v.color_by,
                    ColorBy::Strain,
                    "strain (from the earthquake)",
                );
                ui.selectable_value(&mut v.color_by, ColorBy::Stress, "stress (with gravity)");
                ui.selectable_value(&mut v.color_by, ColorBy::Material, "plain");
            })
            .response
            .on_hover_text("what the block colours show");
        egui::ComboBox::from_label("camera follows")
            .selected_text(match v.camera.follow {
                Follow::World => "nothing",
                Follow::Ground => "the ground",
                Follow::Base => "the base",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut v.camera.follow,
                    Follow::World,
                    "nothing (still camera)",
                )
                .on_hover_text("the ground shakes; a sliding building stays nearly still");
                ui.selectable_value(&mut v.camera.follow, Follow::Ground, "the ground")
                    .on_hover_text("the ground stays still; the base slides over it");
                ui.selectable_value(&mut v.camera.follow, Follow::Base, "the base")
                    .on_hover_text("the base stays still; the ground slides under it");
            })
            .response
            .on_hover_text("what stays still on the screen");
        ui.horizontal(|ui| {
            if ui
                .button("fit (F)")
                .on_hover_text("show the whole model again (after zooming with the wheel or panning with the mouse)")
                .clicked()
            {
                v.camera.fit();
            }
            ui.checkbox(&mut v.close_ups, "joint close-up")
                .on_hover_text("a magnified view of the sliding joint under each model, where the slip is large on screen");
        });
        let l = &mut v.layers;
        ui.horizontal_wrapped(|ui| {
            ui.checkbox(&mut l.blocks, "blocks")
                .on_hover_text("fill the blocks");
            ui.checkbox(&mut l.outlines, "outlines")
                .on_hover_text("outline the blocks");
            ui.checkbox(&mut l.contacts, "contacts")
                .on_hover_text("contact springs: blue stuck, orange sliding, grey open");
            ui.checkbox(&mut l.slip, "slip").on_hover_text(
                "where the base started (red mark) and how far it has slipped (yellow)",
            );
            ui.checkbox(&mut l.bolts, "springs")
                .on_hover_text("bolts and springs between blocks");
            ui.checkbox(&mut l.connections, "connections")
                .on_hover_text(
                    "outline the connection elements: the elastic triangles that join \
                     columns to slabs (always drawn filled with the blocks)",
                );
            ui.checkbox(&mut l.ground, "ground")
                .on_hover_text("the ground and its marks");
        });
        ui.checkbox(&mut v.dark, "dark theme")
            .on_hover_text("dark panels (the light theme reads better on a projector)");
    }

    fn section_export(&mut self, ui: &mut egui::Ui) {
        ui.strong("export");
        ui.horizontal(|ui| {
            ui.label("folder");
            ui.add(egui::TextEdit::singleline(&mut self.export_dir).desired_width(150.0))
                .on_hover_text("where screenshots and data files are written");
        });
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("📷 screenshot")
                .on_hover_text("save the whole window as a PNG picture in the export folder")
                .clicked()
            {
                self.request_screenshot();
            }
            if ui
                .button("💾 plot data (CSV)")
                .on_hover_text(
                    "save what the plots show: series.csv (time histories) and spectrum.csv \
                     (Fourier spectra)",
                )
                .clicked()
            {
                self.export_data();
            }
        });
        ui.label(
            egui::RichText::new(
                "video: slidebase render --from 0 --to 10 --fps 25 --out replay.mp4",
            )
            .small()
            .weak(),
        )
        .on_hover_text("replays are exported from the command line (MP4 with ffmpeg, else GIF)");
    }

    fn section_diagnostics(&mut self, ui: &mut egui::Ui) {
        self.view.show_diagnostics = true;
        let (kept, models) = (self.timeline.replayed_models, self.timeline.labels.len());
        ui.label(format!(
            "simulation: {:.1}× real time{}",
            self.timeline.sim_speed,
            match (self.timeline.finished, kept) {
                (true, 0) => " (done)".to_string(),
                (true, k) => format!(" (done; {k} of {models} models kept from the last run)"),
                (false, _) => String::new(),
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
        if let Some(c) = &self.timeline.config {
            ui.label(format!(
                "integrator {}, Δt {} s",
                integrator_text(c.integrator),
                crate::post::format_number(c.dt)
            ));
        }
    }
}

/// How a run's integrator choice reads in the panel: the scheme's command-line spelling,
/// or the scene's choice when the run names none.
fn integrator_text(integrator: Option<Integrator>) -> String {
    integrator.map_or("the scene's choice".to_string(), |i| i.label())
}
