//! The visualizer's UI logic, driven through egui with synthetic input and no window:
//! moving the friction slider restarts the simulation with the new value, scrubbing the
//! timeline shows the state of that time, and a bad record file shows an error.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::sim::{FrameSet, SimCommand, SimMessage};
use slidebase::ui::AppState;

/// Runs one UI pass with these input events.
fn pass(ctx: &egui::Context, state: &mut AppState, events: Vec<egui::Event>) {
    let input = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(1600.0, 900.0),
        )),
        events,
        ..Default::default()
    };
    let mut output = ctx.run_ui(input, |ui| {
        state.ui(ui);
    });
    // No GPU here: the font atlas updates are dropped on purpose.
    output.textures_delta.clear();
}

/// A press-drag-release from `a` to `b`.
fn drag(ctx: &egui::Context, state: &mut AppState, a: egui::Pos2, b: egui::Pos2) {
    let button = |pos, pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: Default::default(),
    };
    pass(ctx, state, vec![egui::Event::PointerMoved(a)]);
    pass(ctx, state, vec![button(a, true)]);
    pass(ctx, state, vec![egui::Event::PointerMoved(b)]);
    pass(ctx, state, vec![button(b, false)]);
    pass(ctx, state, vec![]);
}

fn runs(commands: &[SimCommand]) -> Vec<slidebase::sim::SimConfig> {
    commands
        .iter()
        .filter_map(|c| match c {
            SimCommand::Run(cfg) => Some((**cfg).clone()),
            SimCommand::Quit => None,
        })
        .collect()
}

#[test]
fn moving_the_friction_slider_restarts_with_the_new_value() {
    let ctx = egui::Context::default();
    let mut state = AppState::default();
    let first = runs(&state.take_commands());
    assert_eq!(first.len(), 1, "the default scene starts at once");
    assert_eq!(first[0].friction, Some(0.01));
    pass(&ctx, &mut state, vec![]);
    let rect = state.widget_rects["friction"];
    // Drag the slider's handle from its position to near the right end.
    let y = rect.center().y;
    let slider_left = rect.left() + 5.0;
    drag(
        &ctx,
        &mut state,
        egui::pos2(slider_left, y),
        egui::pos2(slider_left + 80.0, y),
    );
    let restarts = runs(&state.take_commands());
    assert!(!restarts.is_empty(), "moving the slider restarts the run");
    let f = restarts.last().unwrap().friction.unwrap();
    assert!((f - 0.01).abs() > 1e-6 && f > 0.0, "new friction {f}");
    assert_eq!(f, state.controls.friction);
}

fn synthetic_run(state: &mut AppState) {
    let run = slidebase::sim::prepare(&slidebase::sim::SimConfig {
        scene: "two-block".into(),
        duration: Some(1.0),
        ..Default::default()
    })
    .unwrap();
    let frame = |t: f64| FrameSet {
        time: t,
        models: run
            .models
            .iter()
            .map(|(d, ex)| {
                let mut f = ex.extract(d, Some(&run.motion));
                f.time = t;
                f.probes.slip = t; // a marker to recognise the frame
                f
            })
            .collect(),
    };
    state.ingest(SimMessage::Started {
        generation: 1,
        config: Box::default(),
        duration: 1.0,
        labels: vec!["sliding base".into(), "fixed base".into()],
        exact: None,
        first: Box::new(frame(0.0)),
    });
    state.ingest(SimMessage::Frames {
        generation: 1,
        frames: (1..=100).map(|k| frame(k as f64 * 0.01)).collect(),
        speed: 10.0,
        extract_us: 1.0,
    });
    state.ingest(SimMessage::Finished {
        generation: 1,
        wall_time_s: 0.1,
    });
    // Frames of an older run are ignored.
    state.ingest(SimMessage::Frames {
        generation: 0,
        frames: vec![frame(5.0)],
        speed: 1.0,
        extract_us: 1.0,
    });
}

#[test]
fn scrubbing_shows_the_state_of_that_time() {
    let ctx = egui::Context::default();
    let mut state = AppState::default();
    state.take_commands();
    synthetic_run(&mut state);
    assert_eq!(state.timeline.frames.len(), 101);
    pass(&ctx, &mut state, vec![]);
    let rect = state.widget_rects["time"];
    // Drag the time slider to about 60 % of its length.
    let y = rect.center().y;
    let track = rect.width() * 0.55; // the slider's track; its value box follows
    drag(
        &ctx,
        &mut state,
        egui::pos2(rect.left() + 4.0, y),
        egui::pos2(rect.left() + 0.6 * track, y),
    );
    assert!(!state.playing, "scrubbing pauses playback");
    let t = state.play_time;
    assert!(t > 0.1 && t < 1.0, "scrubbed to {t}");
    let shown = state.current().unwrap();
    assert!(
        (shown.time - t).abs() <= 0.01 + 1e-9,
        "frame {} for cursor {t}",
        shown.time
    );
    assert!(
        (shown.models[0].probes.slip - shown.time).abs() < 1e-12,
        "the frame of that time"
    );
    // Keyboard steps move one frame.
    let before = state.current().unwrap().time;
    state.step_frames(1);
    assert!((state.current().unwrap().time - before - 0.01).abs() < 1e-9);
    state.step_frames(-3);
    assert!((state.current().unwrap().time - before + 0.02).abs() < 1e-9);
}

#[test]
fn loading_a_bad_record_file_shows_an_error() {
    let ctx = egui::Context::default();
    let mut state = AppState::default();
    state.take_commands();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quake.csv");
    std::fs::write(&path, "0,0\n0.01,0.2\n0.02,nan\n").unwrap();
    state.controls.path_input = path.display().to_string();
    pass(&ctx, &mut state, vec![]);
    let rect = state.widget_rects["load"];
    let button = |pressed| egui::Event::PointerButton {
        pos: rect.center(),
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: Default::default(),
    };
    pass(
        &ctx,
        &mut state,
        vec![egui::Event::PointerMoved(rect.center())],
    );
    pass(&ctx, &mut state, vec![button(true)]);
    pass(&ctx, &mut state, vec![button(false)]);
    let error = state.error.clone().expect("an error is shown");
    assert!(
        error.contains("quake.csv:3") && error.contains("not finite"),
        "{error}"
    );
    assert!(
        runs(&state.take_commands()).is_empty(),
        "a bad file starts nothing"
    );
    // A good one restarts the run with it.
    std::fs::write(&path, "0,0\n0.01,0.2\n0.02,0.1\n").unwrap();
    state.load_path();
    let r = runs(&state.take_commands());
    assert_eq!(r.len(), 1);
    assert!(state.error.is_none());
}

/// Regression: the default view stopped itself at t ≈ 0.1 s. The time slider shows two
/// decimals and rounded the playing time to them, which egui reports as a change of the
/// slider; that was taken for the user scrubbing, which pauses playback.
#[test]
fn playback_runs_on_by_itself() {
    let ctx = egui::Context::default();
    let mut state = AppState::default();
    state.take_commands();
    synthetic_run(&mut state);
    assert!(state.playing, "the visualizer opens playing");
    for _ in 0..30 {
        state.advance(0.0137);
        pass(&ctx, &mut state, vec![]);
    }
    assert!(state.playing, "nothing but the user pauses playback");
    let t = state.play_time;
    assert!((t - 30.0 * 0.0137).abs() < 1e-9, "played to {t}");
}
