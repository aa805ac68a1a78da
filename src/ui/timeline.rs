//! The timeline at the bottom: play/pause and stepping buttons, a time rail that uses the
//! whole width (a press anywhere moves the cursor there, dragging scrubs, the computed part
//! is shaded), the time, speed and loop.

use super::{AppState, Timeline};
use crate::sim::TimeLeft;

/// Height of the rail, points.
const RAIL_HEIGHT: f32 = 34.0;

impl AppState {
    pub(super) fn timeline_ui(&mut self, ui: &mut egui::Ui) {
        ui.add_space(2.0);
        ui.horizontal(|ui| {
            let play = if self.playing {
                "⏸ pause"
            } else {
                "▶ play"
            };
            if ui
                .add_sized([78.0, 24.0], egui::Button::new(play))
                .on_hover_text("play or pause the replay (Space); at the end, play starts again")
                .clicked()
            {
                self.toggle_play();
            }
            if ui
                .button("⏮")
                .on_hover_text("back to the start (Home)")
                .clicked()
            {
                self.seek(0.0);
            }
            if ui
                .button("◀")
                .on_hover_text("one frame (10 ms) back (Left arrow; with Shift one second)")
                .clicked()
            {
                self.step_frames(-1);
            }
            if ui
                .button("▶")
                .on_hover_text("one frame (10 ms) on (Right arrow; with Shift one second)")
                .clicked()
            {
                self.step_frames(1);
            }
            let t = self.play_time;
            ui.add(egui::Label::new(
                egui::RichText::new(format!("{t:6.2} s"))
                    .monospace()
                    .size(16.0)
                    .strong(),
            ))
            .on_hover_text("the time shown, simulated seconds from the start of the record");
            // Right to left: the status, loop and speed keep their room at any width (a
            // fixed reservation clipped "computing 23.0 / 31.2 s"), the rail takes the rest.
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                ui.label(run_status(&self.timeline)).on_hover_text(
                    "how much of the run the simulation has computed (it runs ahead in the \
                     background) and, on a long run, the time it has still to go: from its \
                     pace so far and how hard the ground still has to shake. Before a \
                     record's strong motion the pace so far is all there is to go by, and the \
                     strong motion likely takes longer: \"likely over\"",
                );
                ui.checkbox(&mut self.looping, "loop")
                    .on_hover_text("start again at the end");
                egui::ComboBox::from_id_salt("speed")
                    .selected_text(format!("{}×", self.speed))
                    .width(58.0)
                    .show_ui(ui, |ui| {
                        for s in [0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0] {
                            ui.selectable_value(&mut self.speed, s, format!("{s}×"));
                        }
                    })
                    .response
                    .on_hover_text("playback speed: simulated seconds per second");
                let width = (ui.available_width() - 12.0).max(120.0);
                ui.with_layout(egui::Layout::left_to_right(egui::Align::Center), |ui| {
                    self.rail(ui, width);
                });
            });
        });
        ui.add_space(2.0);
    }

    /// The time rail: the full run, the computed part shaded, a tick every second (labels
    /// every 5 or 10 s), the cursor; press or drag anywhere to move the cursor.
    fn rail(&mut self, ui: &mut egui::Ui, width: f32) {
        let (rect, response) = ui.allocate_exact_size(
            egui::vec2(width, RAIL_HEIGHT),
            egui::Sense::click_and_drag(),
        );
        self.widget_rects.insert("time", rect);
        let response = response.on_hover_text(
            "the replay: press or drag to move the time cursor; the shaded part is computed",
        );
        let total = self.timeline.duration.max(1e-3);
        let x_of = |t: f64| rect.left() + (t / total).clamp(0.0, 1.0) as f32 * rect.width();
        if (response.is_pointer_button_down_on() || response.clicked() || response.dragged())
            && let Some(pos) = response.interact_pointer_pos()
        {
            let t = ((pos.x - rect.left()) / rect.width()).clamp(0.0, 1.0) as f64 * total;
            // Snap to the frame grid so that the cursor lands exactly on a frame.
            let dt = self.timeline.frame_dt();
            self.seek((t / dt).round() * dt);
        }
        let painter = ui.painter_at(rect.expand(2.0));
        let visuals = ui.visuals();
        // The track in the upper part, the seconds under it (inside the rail, unclipped).
        let track_y = rect.top() + 10.0;
        let track = egui::Rect::from_min_max(
            egui::pos2(rect.left(), track_y - 4.0),
            egui::pos2(rect.right(), track_y + 4.0),
        );
        painter.rect_filled(track, 3.0, visuals.extreme_bg_color);
        let computed = egui::Rect::from_min_max(
            track.min,
            egui::pos2(x_of(self.timeline.available()), track.max.y),
        );
        painter.rect_filled(computed, 3.0, visuals.widgets.inactive.bg_fill);
        // Up to what has been computed: a cursor waiting ahead of the computation (a
        // changed run computing up to it) leaves the computed part visible.
        let played_to = self.play_time.min(self.timeline.available());
        let played = egui::Rect::from_min_max(track.min, egui::pos2(x_of(played_to), track.max.y));
        painter.rect_filled(played, 3.0, visuals.selection.bg_fill);
        // Ticks: every second if there is room, labels every 5 or 10 s.
        let px_per_s = rect.width() / total as f32;
        let label_every = if px_per_s * 5.0 >= 40.0 { 5 } else { 10 };
        for s in 0..=(total.floor() as i64) {
            let x = x_of(s as f64);
            let major = s % label_every == 0;
            if !major && px_per_s < 6.0 {
                continue;
            }
            let h = if major { 6.0 } else { 3.0 };
            painter.line_segment(
                [egui::pos2(x, track.max.y), egui::pos2(x, track.max.y + h)],
                egui::Stroke::new(1.0, visuals.weak_text_color()),
            );
            if major && x + 20.0 < rect.right() {
                painter.text(
                    egui::pos2(x, track.max.y + h + 1.0),
                    // The first label starts at the rail's left end (centred, it was cut).
                    if s == 0 {
                        egui::Align2::LEFT_TOP
                    } else {
                        egui::Align2::CENTER_TOP
                    },
                    format!("{s} s"),
                    egui::FontId::proportional(12.0),
                    visuals.text_color(),
                );
            }
        }
        let x = x_of(self.play_time);
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, track.max.y + 6.0)],
            egui::Stroke::new(3.0, visuals.strong_text_color()),
        );
        if let Some(target) = self.resume_at {
            let xt = x_of(target);
            painter.circle_stroke(
                egui::pos2(xt, track_y),
                6.0,
                egui::Stroke::new(2.0, visuals.warn_fg_color),
            );
        }
    }
}

/// The run's state at the right of the timeline: its length once finished; while it
/// computes, how far it has come and, on a long run, the time it has still to go.
pub fn run_status(timeline: &Timeline) -> String {
    let total = timeline.duration;
    if timeline.finished {
        return format!("run {total:.1} s");
    }
    let computed = timeline.available();
    match &timeline.time_left {
        Some(left) => format!(
            "computing {computed:.1} / {total:.1} s, {}",
            time_left_words(left)
        ),
        None => format!("computing {computed:.1} / {total:.1} s"),
    }
}

/// "about 3 min left"; "likely over 40 s left" while the ground has still to shake much
/// harder than so far (the pace so far, which the strong motion likely exceeds).
pub fn time_left_words(left: &TimeLeft) -> String {
    let s = left.seconds.max(0.0);
    if s < 0.5 {
        return "under a second left".into();
    }
    let span = if s < 90.0 {
        format!("{s:.0} s")
    } else if s < 90.0 * 60.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        let minutes = (s / 60.0).round() as u64;
        format!("{} h {:02} min", minutes / 60, minutes % 60)
    };
    if left.likely_more {
        format!("likely over {span} left")
    } else {
        format!("about {span} left")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn left(seconds: f64, likely_more: bool) -> TimeLeft {
        TimeLeft {
            seconds,
            likely_more,
        }
    }

    #[test]
    fn the_time_left_reads_in_seconds_minutes_and_hours() {
        assert_eq!(time_left_words(&left(0.2, false)), "under a second left");
        assert_eq!(time_left_words(&left(42.4, false)), "about 42 s left");
        assert_eq!(time_left_words(&left(200.0, false)), "about 3 min left");
        assert_eq!(
            time_left_words(&left(200.0, true)),
            "likely over 3 min left"
        );
        assert_eq!(
            time_left_words(&left(7500.0, false)),
            "about 2 h 05 min left"
        );
    }

    #[test]
    fn the_status_tells_how_far_and_how_long_to_go() {
        let mut t = Timeline {
            duration: 41.0,
            ..Default::default()
        };
        assert_eq!(run_status(&t), "computing 0.0 / 41.0 s");
        t.time_left = Some(left(500.0, false));
        assert_eq!(run_status(&t), "computing 0.0 / 41.0 s, about 8 min left");
        t.finished = true;
        assert_eq!(run_status(&t), "run 41.0 s");
    }
}
