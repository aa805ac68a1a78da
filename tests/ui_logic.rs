//! The visualizer's UI, driven like a person would through egui_kittest (no window, no
//! GPU): widgets found by their labels, clicked, dragged and typed into. Each test names
//! the behaviour it protects; several are regressions of issue 12's findings.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable as _;
use slidebase::sim::{FrameSet, SimCommand, SimConfig, SimMessage, TimeLeft};
use slidebase::ui::{AppState, SceneChoice};

fn runs(commands: &[SimCommand]) -> Vec<SimConfig> {
    commands
        .iter()
        .filter_map(|c| match c {
            SimCommand::Run(cfg) => Some((**cfg).clone()),
            SimCommand::Quit => None,
        })
        .collect()
}

/// A harness around the whole UI at a window size.
fn harness(state: AppState, w: f32, h: f32) -> Harness<'static, AppState> {
    let mut h = Harness::builder()
        .with_size(egui::vec2(w, h))
        .build_ui_state(|ui, state: &mut AppState| state.ui(ui), state);
    h.run_steps(2);
    h
}

/// Messages of a synthetic run of the two-block scene: frames every 10 ms up to
/// `duration`, each marked by its time in the slip probe, full-rate samples every 5 ms.
fn synthetic(generation: u64, duration: f64, upto: f64) -> Vec<SimMessage> {
    let run = slidebase::sim::prepare(&SimConfig {
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
    let n = (upto / 0.01).round() as usize;
    let mut samples = vec![slidebase::sim::Samples::default(); run.models.len()];
    for s in &mut samples {
        for k in 0..=2 * n {
            let t = k as f64 * 0.005;
            s.time.push(t);
            s.ground_accel.push((std::f64::consts::TAU * t).sin());
            s.base_accel.push(0.5 * (std::f64::consts::TAU * t).sin());
            s.roof_accel.push(0.4 * (std::f64::consts::TAU * t).sin());
            s.slip.push(0.1 * t);
            s.drift.push(0.01 * (std::f64::consts::TAU * t).sin());
        }
    }
    let mut msgs = vec![
        SimMessage::Started {
            generation,
            config: Box::default(),
            duration,
            labels: vec!["sliding base, ρ = 0.1".into(), "fixed base".into()],
            motion: Box::default(),
            exact: None,
            first: Box::new(frame(0.0)),
        },
        SimMessage::Frames {
            generation,
            frames: (1..=n).map(|k| frame(k as f64 * 0.01)).collect(),
            samples,
            speed: 10.0,
            time_left: None,
            extract_us: 1.0,
        },
    ];
    if upto >= duration - 1e-9 {
        msgs.push(SimMessage::Finished {
            generation,
            wall_time_s: 0.1,
            replayed_models: 0,
        });
    }
    msgs
}

/// The frames of [`synthetic`]'s run after its first `skip`, as one message (what arrives
/// once a run has been computed further than the frames already taken in).
fn later_frames(generation: u64, duration: f64, upto: f64, skip: usize) -> SimMessage {
    let SimMessage::Frames { frames, .. } = synthetic(generation, duration, upto).remove(1) else {
        panic!("the second message is the frames");
    };
    SimMessage::Frames {
        generation,
        frames: frames[skip..].to_vec(),
        samples: vec![Default::default(); 2],
        speed: 1.0,
        time_left: None,
        extract_us: 1.0,
    }
}

fn with_run(duration: f64) -> AppState {
    with_run_computed_to(duration, duration)
}

/// A state showing run 1 of `duration` computed up to `upto` (still computing if less).
fn with_run_computed_to(duration: f64, upto: f64) -> AppState {
    let mut state = AppState::default();
    state.take_commands();
    for m in synthetic(1, duration, upto) {
        state.ingest(m);
    }
    state
}

fn click_at(h: &Harness<'_, AppState>, pos: egui::Pos2) {
    h.event(egui::Event::PointerMoved(pos));
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        });
    }
}

/// Types `text` into the file field of a window showing a finished run, presses load,
/// and returns the harness and the error shown (there must be one).
fn load_through_the_field(text: &str) -> (Harness<'static, AppState>, String) {
    let mut state = with_run(1.0);
    state.path_input = text.into();
    let mut h = harness(state, 1600.0, 900.0);
    h.get_by_label("load").click();
    h.run_steps(2);
    let error = h.state().error.clone().expect("an error is shown");
    (h, error)
}

/// Issue 12, finding 4: typing one letter in the path field restarted the run and sent a
/// paused replay at 9.84 s back to 0.
#[test]
fn typing_a_path_restarts_nothing() {
    let mut state = with_run(12.0);
    state.seek(9.84);
    let mut h = harness(state, 1600.0, 900.0);
    let field = h.state().widget_rects["path"];
    click_at(&h, field.center());
    h.run_steps(2);
    for ch in ["q", "u", "a", "k", "e", ".", "a", "t", "2"] {
        h.event(egui::Event::Text(ch.into()));
        h.step();
    }
    let state = h.state_mut();
    assert_eq!(
        state.path_input, "quake.at2",
        "the text went into the field"
    );
    assert!(
        runs(&state.take_commands()).is_empty(),
        "typing starts no run"
    );
    assert!(
        (state.play_time - 9.84).abs() < 1e-9,
        "cursor at {}",
        state.play_time
    );
    assert!(!state.playing);
}

/// Issue 12, finding 10: every parameter change rewound to t = 0. Now the new run is
/// shown at the same time as soon as it has been computed that far.
#[test]
fn a_parameter_change_keeps_the_time_cursor() {
    let mut state = with_run(2.0);
    state.seek(1.5);
    let mut h = harness(state, 1600.0, 900.0);
    // Drag the friction slider's handle to the right.
    let r = h.state().widget_rects["friction"];
    let y = r.center().y;
    let x0 = r.left() + 0.3 * r.width() * 0.6;
    h.event(egui::Event::PointerMoved(egui::pos2(x0, y)));
    h.event(egui::Event::PointerButton {
        pos: egui::pos2(x0, y),
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: Default::default(),
    });
    h.step();
    h.event(egui::Event::PointerMoved(egui::pos2(x0 + 60.0, y)));
    h.step();
    h.event(egui::Event::PointerButton {
        pos: egui::pos2(x0 + 60.0, y),
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: Default::default(),
    });
    h.run_steps(2);
    let state = h.state_mut();
    let restarts = runs(&state.take_commands());
    assert!(!restarts.is_empty(), "moving the slider restarts the run");
    let f = restarts.last().unwrap().friction.unwrap();
    assert!((f - 0.01).abs() > 1e-4, "new friction {f}");
    assert_eq!(state.resume_at, Some(1.5));
    // The new run arrives, first computed to 0.5 s only: the cursor waits at 1.5 s.
    let mut msgs = synthetic(2, 2.0, 0.5);
    state.ingest(msgs.remove(0));
    state.ingest(msgs.remove(0));
    state.advance(0.1);
    assert!(
        (state.play_time - 1.5).abs() < 1e-9,
        "cursor {}",
        state.play_time
    );
    assert_eq!(state.resume_at, Some(1.5));
    // Once it has been computed past 1.5 s, the frame of 1.5 s is shown.
    state.ingest(later_frames(2, 2.0, 2.0, 50));
    assert_eq!(state.resume_at, None);
    let shown = state.current().unwrap();
    assert!((shown.time - 1.5).abs() < 1e-9, "shows {}", shown.time);
}

/// Issue 16's window pass: a change while the run is still computing, with the cursor
/// inside the part already computed, sent the cursor to 0 — the replaced run's frames,
/// still arriving before the new run started, were taken for the new run's.
#[test]
fn a_change_during_a_computing_run_keeps_the_time_cursor() {
    // Generation 1 has computed 3 s of 10 and goes on computing.
    let mut state = with_run_computed_to(10.0, 3.0);
    state.seek(2.0);
    state.controls.friction *= 2.0;
    state.restart();
    assert_eq!(state.resume_at, Some(2.0));
    // Frames of generation 1 up to 4 s arrive before generation 2 starts, then its end.
    let frames = synthetic(1, 10.0, 4.0).remove(1);
    state.ingest(frames);
    state.ingest(SimMessage::Finished {
        generation: 1,
        wall_time_s: 1.0,
        replayed_models: 0,
    });
    assert_eq!(
        state.resume_at,
        Some(2.0),
        "the old run's frames took the target"
    );
    // The new run starts and computes 1 s: the cursor waits at 2 s; past it, it shows 2 s.
    let mut msgs = synthetic(2, 10.0, 1.0);
    state.ingest(msgs.remove(0));
    state.ingest(msgs.remove(0));
    state.advance(0.1);
    assert!(
        (state.play_time - 2.0).abs() < 1e-9,
        "cursor {}",
        state.play_time
    );
    assert_eq!(state.resume_at, Some(2.0));
    state.ingest(later_frames(2, 10.0, 2.5, 100));
    assert_eq!(state.resume_at, None);
    assert!((state.current().unwrap().time - 2.0).abs() < 1e-9);
}

/// Issue 16's window pass: on a long run the replay caught up with the computation and
/// crawled at its pace while the speed box still said 1×; nothing said it was waiting.
#[test]
fn a_replay_held_by_a_slow_computation_says_so() {
    let mut state = with_run_computed_to(10.0, 1.0);
    // Computing at 10× real time: the replay at 1× does not wait, nothing is said.
    state.advance(2.0);
    assert!((state.play_time - 1.0).abs() < 1e-9);
    assert_eq!(state.picture_note(), None);
    // At 0.3× it waits, and says so.
    state.ingest(SimMessage::Frames {
        generation: 1,
        frames: Vec::new(),
        samples: vec![Default::default(); 2],
        speed: 0.3,
        time_left: Some(TimeLeft {
            seconds: 200.0,
            likely_more: false,
        }),
        extract_us: 1.0,
    });
    let note = state.picture_note().expect("a note");
    assert!(
        note.contains("waits for the computation (0.30× real time)"),
        "{note}"
    );
    assert_eq!(state.timeline.time_left.map(|t| t.seconds), Some(200.0));
    // Paused, it is not waiting.
    state.toggle_play();
    assert_eq!(state.picture_note(), None);
}

/// Issue 12, finding 7: ←/→ merged when pressed quickly, Shift did nothing, play at the end
/// did nothing with loop off, a quick click on the rail was ignored.
#[test]
fn keys_step_frames_and_seconds_and_the_rail_takes_a_click() {
    let mut state = with_run(3.0);
    state.seek(1.0);
    let mut h = harness(state, 1600.0, 900.0);
    // Two presses within one frame are two steps.
    h.key_press(egui::Key::ArrowRight);
    h.key_press(egui::Key::ArrowRight);
    h.step();
    assert!(
        (h.state().play_time - 1.02).abs() < 1e-9,
        "{}",
        h.state().play_time
    );
    h.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::ArrowRight);
    h.step();
    assert!(
        (h.state().play_time - 2.02).abs() < 1e-9,
        "{}",
        h.state().play_time
    );
    h.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::ArrowLeft);
    h.key_press(egui::Key::ArrowLeft);
    h.step();
    assert!(
        (h.state().play_time - 1.01).abs() < 1e-9,
        "{}",
        h.state().play_time
    );
    h.key_press(egui::Key::End);
    h.step();
    assert!((h.state().play_time - 3.0).abs() < 1e-9);
    // Play at the end (loop off) starts again.
    h.state_mut().looping = false;
    h.get_by_label("▶ play").click();
    h.step();
    assert!(h.state().playing && h.state().play_time < 1e-9, "restarted");
    // A quick click on the rail, three quarters along, moves the cursor there.
    let rail = h.state().widget_rects["time"];
    click_at(
        &h,
        egui::pos2(rail.left() + 0.75 * rail.width(), rail.center().y),
    );
    h.step();
    assert!(!h.state().playing);
    let t = h.state().play_time;
    assert!((t - 2.25).abs() < 0.02, "clicked to {t}");
    // The rail uses the width: more than half of a 1024-wide window.
    let h2 = harness(with_run(3.0), 1024.0, 600.0);
    assert!(h2.state().widget_rects["time"].width() > 450.0);
}

/// Space plays and pauses, H shows the shortcuts, F fits, Ctrl+Q asks to quit.
#[test]
fn shortcuts_work_and_are_listed() {
    let mut h = harness(with_run(1.0), 1600.0, 900.0);
    h.state_mut().playing = true;
    h.key_press(egui::Key::Space);
    h.step();
    assert!(!h.state().playing);
    h.key_press(egui::Key::H);
    h.run_steps(2);
    assert!(h.state().view.show_help);
    h.get_by_label("one second back / on");
    h.state_mut().view.camera.zoom = 3.0;
    h.key_press(egui::Key::F);
    h.step();
    assert_eq!(h.state().view.camera.zoom, 1.0);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    h.step();
    assert!(
        h.state_mut()
            .take_requests()
            .contains(&slidebase::ui::ShellRequest::Quit)
    );
}

/// Issue 16's window pass: a 12-course wall came back as 6 courses (and was computed again
/// from scratch at that size) after a look at another scene.
#[test]
fn a_generated_scene_keeps_its_size_when_picked_again() {
    let mut state = with_run(1.0);
    state.controls.scene = SceneChoice::Wall(10);
    let mut h = harness(state, 1600.0, 900.0);
    h.get_by_value("dry-stacked wall, 10 courses").click();
    h.run_steps(2);
    h.get_by_label("three-storey frame (paper Fig. 3)").click();
    h.run_steps(2);
    assert_eq!(h.state().controls.scene, SceneChoice::ThreeStorey);
    h.get_by_value("three-storey frame (paper Fig. 3)").click();
    h.run_steps(2);
    h.get_by_label("dry-stacked wall (generated)").click();
    h.run_steps(2);
    assert_eq!(h.state().controls.scene, SceneChoice::Wall(10));
}

/// A lecture preset sets up its comparison: three friction coefficients side by side.
#[test]
fn the_friction_preset_runs_three_frictions() {
    let mut h = harness(with_run(1.0), 1600.0, 900.0);
    h.get_by_value("lecture presets…").click();
    h.run_steps(2);
    h.get_by_label("What friction does: ρ = 0.01 / 0.05 / 0.2")
        .click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("the preset starts a run");
    assert_eq!(last.friction, Some(0.01));
    assert_eq!(last.compare_friction, vec![0.05, 0.2]);
    assert!(!last.compare_fixed);
}

#[test]
fn loading_a_bad_record_file_shows_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("quake.csv");
    std::fs::write(&path, "0,0\n0.01,0.2\n0.02,nan\n").unwrap();
    let (mut h, error) = load_through_the_field(&path.display().to_string());
    let state = h.state_mut();
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
    assert_eq!(runs(&state.take_commands()).len(), 1);
    assert!(state.error.is_none());
}

/// Issue 16's window pass: "wall:20" typed into the file field and loaded said "No such
/// file or directory", and the courses field silently turned 20 into 12. A scene's name
/// loads the window's own choice, and a size the window does not run says why and what
/// does.
#[test]
fn a_scene_name_loads_or_says_where_it_runs() {
    let (mut h, error) = load_through_the_field("wall:20");
    let state = h.state_mut();
    assert!(
        error.contains("the window runs 2 to 12 courses")
            && error.contains("slidebase run --scene wall:20"),
        "{error}"
    );
    assert!(runs(&state.take_commands()).is_empty());
    state.path_input = "wall:8".into();
    state.load_path();
    let started = runs(&state.take_commands());
    assert_eq!(started.len(), 1);
    assert_eq!(started[0].scene, "wall:8");
    assert!(state.error.is_none());
    state.path_input = "frame:50".into();
    state.load_path();
    let error = state.error.clone().expect("an error is shown");
    assert!(error.contains("up to frame:20"), "{error}");
}

/// Regression: the default view stopped itself at t ≈ 0.1 s (the old slider rounded the
/// playing time and that was taken for the user scrubbing).
#[test]
fn playback_runs_on_by_itself() {
    let mut h = harness(with_run(1.0), 1600.0, 900.0);
    h.state_mut().playing = true;
    h.state_mut().play_time = 0.0;
    for _ in 0..30 {
        h.state_mut().advance(0.0137);
        h.step();
    }
    assert!(h.state().playing, "nothing but the user pauses playback");
    let t = h.state().play_time;
    assert!((t - 30.0 * 0.0137).abs() < 1e-9, "played to {t}");
}

/// "plot data (CSV)" writes the series and spectra the plots show, well formed.
#[test]
fn plot_data_export_writes_well_formed_csv() {
    let dir = tempfile::tempdir().unwrap();
    let mut state = with_run(2.0);
    state.export_dir = dir.path().display().to_string();
    state.seek(1.0);
    let mut h = harness(state, 1600.0, 900.0);
    h.get_by_label("💾 plot data (CSV)").click();
    h.run_steps(2);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    let series = std::fs::read_to_string(dir.path().join("series.csv")).unwrap();
    let mut lines = series.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time_s,ground_accel_g,"), "{header}");
    assert!(
        header.contains("\"roof_accel_g (sliding base, ρ = 0.1)\""),
        "{header}"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // Everything computed (2 s) at the samples' 5 ms: 401 rows of 2 + 2 × 4 columns.
    assert_eq!(rows.len(), 401);
    assert!(
        rows.iter()
            .all(|r| r.len() == 10 && r.iter().all(|v| v.is_finite()))
    );
    assert!((rows[400][0] - 2.0).abs() < 1e-9);
    let mut spectrum = csv::Reader::from_path(dir.path().join("spectrum.csv")).unwrap();
    let names: Vec<String> = spectrum
        .headers()
        .unwrap()
        .iter()
        .map(String::from)
        .collect();
    assert_eq!(
        names,
        [
            "frequency_hz",
            "ground",
            "base, sliding base, ρ = 0.1",
            "base, fixed base"
        ]
    );
    let rows: Vec<csv::StringRecord> = spectrum.records().map(Result::unwrap).collect();
    assert!(rows.len() > 10 && rows.iter().all(|r| r.len() == 4));
}

/// Issue 15: the "vertical shaking" toggle adds El Centro's vertical component to the
/// run (and to nothing else); it is greyed out for input without one (a sine wave).
#[test]
fn the_vertical_toggle_adds_the_vertical_record() {
    let mut h = harness(AppState::default(), 1600.0, 900.0);
    h.state_mut().take_commands();
    h.get_by_label("vertical shaking").click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("the toggle restarts the run");
    assert_eq!(last.vertical.as_deref(), Some("el-centro-up"));
    assert_eq!(last.damping, None, "undamped unless the slider is moved");
    let run = slidebase::sim::prepare(last).expect("the vertical run sets up");
    let (name, peak) = run
        .motion_info
        .vertical
        .clone()
        .expect("the header names it");
    assert_eq!(name, "el-centro-up");
    assert!(
        (peak - 0.178).abs() < 0.01,
        "El Centro's vertical peak: {peak} g"
    );
    // A sine wave has no vertical component: the toggle does not apply.
    let mut controls = h.state().controls.clone();
    controls.record = slidebase::ui::RecordChoice::Harmonic;
    assert!(controls.vertical, "the choice is kept...");
    assert_eq!(controls.config().vertical, None, "...but not applied");
}

/// Issue 15: the two-block scene has a damping slider; a damped run's exact overlay is
/// the damped exact solution (it differs from the undamped one).
#[test]
fn the_two_block_scene_offers_damping() {
    let mut controls = slidebase::ui::Controls {
        scene: slidebase::ui::SceneChoice::TwoBlock,
        record: slidebase::ui::RecordChoice::Harmonic,
        ..Default::default()
    };
    let h = harness(AppState::new(controls.clone()), 1600.0, 900.0);
    assert!(h.query_all_by_label_contains("damping ζ").next().is_some());
    assert_eq!(controls.config().damping, None, "0 is undamped");
    let undamped = slidebase::sim::prepare(&controls.config()).unwrap();
    controls.damping = 0.05;
    assert_eq!(controls.config().damping, Some(0.05));
    let damped = slidebase::sim::prepare(&controls.config()).unwrap();
    let peak = |r: &slidebase::sim::PreparedRun| {
        let e = r
            .exact
            .as_ref()
            .expect("two-block runs have the exact overlay");
        e.drift.iter().fold(0.0_f64, |m, d| m.max(d.abs()))
    };
    assert!(
        peak(&damped) < 0.9 * peak(&undamped),
        "damped exact drift {} against undamped {}",
        peak(&damped),
        peak(&undamped)
    );
}

/// Issue 15: the frames have the damping slider too (Rayleigh damping), the wall of loose
/// blocks does not; a damped frame run sets up with the frame's Rayleigh coefficients.
#[test]
fn the_frames_offer_rayleigh_damping_and_the_wall_does_not() {
    let h = harness(AppState::default(), 1600.0, 900.0);
    assert!(h.query_all_by_label_contains("damping ζ").next().is_some());
    let mut controls = h.state().controls.clone();
    controls.damping = 0.05;
    let config = controls.config();
    assert_eq!(config.damping, Some(0.05));
    slidebase::sim::prepare(&config).expect("a damped frame sets up");
    let wall = slidebase::ui::Controls {
        scene: slidebase::ui::SceneChoice::Wall(4),
        damping: 0.05,
        ..Default::default()
    };
    assert_eq!(wall.config().damping, None, "a wall is not damped");
    let h = harness(AppState::new(wall), 1600.0, 900.0);
    assert!(h.query_all_by_label_contains("damping ζ").next().is_none());
}

/// Issue 15: the preset "friction pendulum against flat slider" runs the frame on
/// pendulum bearings beside the same frame on the flat joint; the two models set up with
/// their own grounds (dishes, flat) and labels that say which is which. Unticking the
/// bearings takes the flat-joint comparison away.
#[test]
fn the_pendulum_preset_runs_the_frame_on_both_bearings() {
    let mut h = harness(with_run(1.0), 1600.0, 900.0);
    h.get_by_value("lecture presets…").click();
    h.run_steps(2);
    h.get_by_label("Friction pendulum against flat slider: recentring")
        .click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("the preset starts a run").clone();
    assert_eq!(
        last.bearing,
        Some(slidebase::model::bearing::Bearing::Pendulum { radius: 2.0 })
    );
    assert!(last.compare_flat && !last.compare_fixed);
    let run = slidebase::sim::prepare(&last).expect("both models set up");
    assert_eq!(run.labels.len(), 2, "{:?}", run.labels);
    assert!(
        run.labels[0].starts_with("pendulum bearings R = 2 m"),
        "{:?}",
        run.labels
    );
    assert!(run.labels[1].starts_with("flat joint"), "{:?}", run.labels);
    let ground_vertices = |k: usize| {
        run.models[k].0.blocks()[run.models[k].0.ground()]
            .vertices
            .len()
    };
    assert!(
        ground_vertices(0) > 900,
        "the pendulum's ground has its dishes"
    );
    assert_eq!(ground_vertices(1), 4, "the flat joint's ground is a slab");
    // The bearing checkbox is there for the frame; unticking it drops the comparison.
    h.get_by_label("friction-pendulum bearings").click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("unticking restarts the run");
    assert_eq!(last.bearing, None);
    assert!(!last.compare_flat && last.compare_fixed);
}

/// Issue 15: the friction-law combo builds the law on the ρ slider (its coefficient at
/// rest) and the run gets it instead of Coulomb's ρ; the sliding block and the friction
/// pendulum are scenes of the panel, and set up.
#[test]
fn the_friction_law_and_the_block_scenes_are_in_the_panel() {
    use slidebase::model::friction::Friction;
    let mut h = harness(AppState::default(), 1600.0, 900.0);
    h.state_mut().take_commands();
    h.get_by_value("Coulomb (one ρ)").click();
    h.run_steps(2);
    h.get_by_label("velocity dependent").click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("a law change restarts the run");
    assert_eq!(
        last.friction_law,
        Some(Friction::Velocity {
            slow: 0.01,
            fast: 0.02,
            rate: 20.0
        })
    );
    assert!(h.query_all_by_label_contains("μ_fast").next().is_some());
    slidebase::sim::prepare(last).expect("the frame runs on the velocity law");
    for scene in [
        slidebase::ui::SceneChoice::Block,
        slidebase::ui::SceneChoice::FrictionPendulum,
    ] {
        let controls = slidebase::ui::Controls {
            scene: scene.clone(),
            law: slidebase::ui::LawChoice::StaticKinetic { stick: 0.08 },
            friction: 0.05,
            ..Default::default()
        };
        let config = controls.config();
        assert_eq!(
            config.friction_law,
            Some(Friction::StaticKinetic {
                stick: 0.08,
                slide: 0.05
            })
        );
        let run = slidebase::sim::prepare(&config).expect("the scene sets up");
        assert_eq!(run.models.len(), 2, "{scene:?} and its fixed base");
    }
}

/// The integrator combo starts on the scene's choice (the run asks for none, so the
/// two-block scene gets its ρ∞ = 0.5 and the frames their ρ∞ = 0), and a scheme picked in
/// it by name is the one the next run uses.
#[test]
fn the_integrator_is_the_scenes_until_one_is_picked() {
    let mut h = harness(AppState::default(), 1600.0, 900.0);
    assert_eq!(h.state().controls.config().integrator, None);
    let run = slidebase::sim::prepare(&h.state().controls.config()).expect("it sets up");
    assert_eq!(
        run.models[0].0.params().integrator,
        slidebase::dda::Integrator::default()
    );
    h.state_mut().take_commands();
    h.get_by_label("solver settings").click();
    h.run_steps(2);
    h.get_by_value("the scene's choice").click();
    h.run_steps(2);
    h.get_by_label("trapezoidal (no numerical damping)").click();
    h.run_steps(2);
    let r = runs(&h.state_mut().take_commands());
    let last = r.last().expect("picking a scheme restarts the run");
    assert_eq!(
        last.integrator,
        Some(slidebase::dda::Integrator::Trapezoidal)
    );
}
