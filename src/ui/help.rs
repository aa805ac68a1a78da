//! The top bar (presets, panel toggles, help) and the two help windows: the keyboard
//! shortcuts and "what am I looking at".

use super::{AppState, presets::presets};

/// The keyboard shortcuts, as shown in the help window.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("Space", "play / pause (at the end: play again)"),
    ("Left / Right arrow", "one frame (10 ms) back / on"),
    ("Shift + Left / Right", "one second back / on"),
    ("Home / End", "start / end of what is computed"),
    ("mouse wheel, pinch", "zoom the scene about the pointer"),
    ("drag", "pan the scene"),
    ("F, double click", "fit the whole model again"),
    ("F11", "full-screen scene (panels hidden)"),
    ("Esc", "close this help, leave full screen"),
    ("H or ?", "show / hide this help"),
    ("Ctrl + Q", "quit"),
    ("Ctrl + / Ctrl −", "larger / smaller text and controls"),
];

const ABOUT: &str = "\
A building stands on a slab that rests on the ground with friction. When the ground shakes, \
the friction has to pull the slab along. As long as the force needed stays below ρ × weight \
(ρ is the friction coefficient), the slab sticks and the building feels the whole earthquake. \
Above it, the slab slides: the force passed up is capped, and so is the acceleration of the \
building. That is sliding isolation.

The panels show the same building side by side: on a sliding base, and (by default) with its \
base fixed to the ground. The deformation of the structure is magnified (the factor is in the \
footer) so that you can see the storeys sway; the slip and the ground's motion are drawn true \
to scale, so the close-up under each model magnifies the sliding joint: the dashed outline is \
where the base started (it moves with the ground), the red arrow is the slip.

Colours: blocks by strain (blue small, red large); contact springs blue when stuck, orange \
when sliding, grey when open. The headline compares the peak roof acceleration of the first \
model with the last one's. The plots on the right follow the time cursor. Where blocks hit \
or a base sticks, an acceleration can spike for a step or two; its height then depends on \
the time step, so the legend also gives the peak low-passed at 25 Hz, as a shake-table \
accelerometer would read it.

The numbers come from Discontinuous Deformation Analysis (DDA): every block moves and deforms, \
contacts are springs that stick, slide or open, checked against the exact solution of the \
paper's mass-spring model.";

impl AppState {
    pub(super) fn top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.heading("slidebase");
            let current = self.preset.unwrap_or("lecture presets…");
            egui::ComboBox::from_id_salt("preset")
                .selected_text(current)
                .width(300.0)
                .truncate()
                .show_ui(ui, |ui| {
                    for p in presets() {
                        let chosen = ui
                            .selectable_label(self.preset == Some(p.name), p.name)
                            .on_hover_text(p.point);
                        if chosen.clicked() {
                            self.controls = p.controls.clone();
                            self.preset = Some(p.name);
                            self.restart();
                        }
                    }
                })
                .response
                .on_hover_text("ready-made set-ups for a lecture, each making one point");
            ui.separator();
            ui.toggle_value(&mut self.view.show_controls, "controls")
                .on_hover_text("show or hide the controls on the left");
            ui.toggle_value(&mut self.view.show_plots, "plots")
                .on_hover_text("show or hide the plots on the right");
            if ui
                .button("full screen")
                .on_hover_text("the scene alone, full screen (F11; Esc to leave)")
                .clicked()
            {
                self.set_full_screen(true);
            }
            if ui
                .button("📷")
                .on_hover_text("save a screenshot of the window (PNG) in the export folder")
                .clicked()
            {
                self.request_screenshot();
            }
            ui.toggle_value(&mut self.view.show_about, "ℹ what am I looking at?")
                .on_hover_text("a short explanation of the picture");
            ui.toggle_value(&mut self.view.show_help, "⌨ shortcuts")
                .on_hover_text("the keyboard and mouse shortcuts (H or ?)");
            if let Some((msg, at)) = &self.status
                && at.elapsed().as_secs_f64() < 8.0
            {
                ui.label(egui::RichText::new(msg).italics());
            }
        });
    }
}

/// The help windows, when open.
pub(super) fn windows(state: &mut AppState, ctx: &egui::Context) {
    let mut open = state.view.show_help;
    egui::Window::new("keyboard and mouse")
        .open(&mut open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                for (key, what) in SHORTCUTS {
                    ui.strong(*key);
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
    state.view.show_help = open;
    let mut open = state.view.show_about;
    egui::Window::new("what am I looking at?")
        .open(&mut open)
        .collapsible(false)
        .default_width(460.0)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            ui.label(ABOUT);
        });
    state.view.show_about = open;
}
