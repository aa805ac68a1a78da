//! The desktop application on eframe (winit + egui-winit + egui-wgpu): it repaints only on
//! demand — while the replay plays (capped at 60 frames per second), while a run is being
//! computed, or on input — so a paused window costs nothing. The simulation runs on its own
//! thread (see [`crate::sim`]) and wakes the window when it posts frames. The scene is drawn
//! by [`crate::render::Renderer`] through an egui paint callback (see [`crate::ui::scene`]).
//! Where the frames are drawn in software the window's threads run below the
//! simulation's (see `software_frames_yield`).

use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use crate::render::Renderer;
use crate::sim::{SimHandle, Wake};
use crate::ui::{AppState, ShellRequest};
use crate::{Error, Result};

/// What to tell a user who starts the visualizer without a display.
pub const NO_DISPLAY_HELP: &str = "no display to open a window on; the same simulations run headless: \
    `slidebase run`, `slidebase report`, `slidebase render --out frame.png` (or start the visualizer \
    under a desktop, or `xvfb-run slidebase` for screenshots)";

/// The shortest time between two frames while playing (a 60 Hz cap).
const FRAME_INTERVAL: Duration = Duration::from_micros(16_667);

/// While a run is being computed the window redraws at most this often (10 frames a
/// second): its frames are drawn by the same cores that compute. The default run then
/// computes at 22–23× real time in the window instead of 17–18× at 30 frames a second
/// (docs/performance-log.md); the computation lasts a second or two.
const COMPUTING_FRAME_INTERVAL: Duration = Duration::from_millis(100);

/// The same where the frames are drawn in software (Mesa's llvmpipe, a machine without a
/// GPU): there a frame of the default layout at 1600×900 costs ~80–90 ms of CPU, taken
/// from the two simulations on the same cores. At 10 frames a second the run computed at
/// 17–18× real time under Xvfb, at 4 a second 24–29×, at 2 a second 26–31×
/// (docs/performance-log.md). Input still repaints at once, and the end of the run is shown
/// at once (see [`Wake`]); only the computing run's own progress frames are paced.
const SOFTWARE_COMPUTING_FRAME_INTERVAL: Duration = Duration::from_millis(500);

/// How much lower than the simulation the window's threads run where a software
/// rasteriser draws the frames (a nice value, added to the process's).
const SOFTWARE_WINDOW_NICENESS: i32 = 5;

/// Wakes the window when the simulation posts, once the window exists (`window` holds its
/// context and its pace of redraws while a run computes).
fn window_waker(window: Arc<OnceLock<(egui::Context, Duration)>>) -> crate::sim::Waker {
    Box::new(move |wake| {
        if let Some((ctx, computing_interval)) = window.get() {
            match wake {
                Wake::Progress => ctx.request_repaint_after(*computing_interval),
                // A finished run is shown at once, not at the computing pace.
                Wake::RunEnded => ctx.request_repaint(),
            }
        }
    })
}

/// Where the frames are drawn in software (Mesa's llvmpipe, a machine without a GPU),
/// the window's thread lowers its priority by [`SOFTWARE_WINDOW_NICENESS`] just before
/// it creates the device, so the rasteriser's threads, started from it, inherit the lower
/// priority. A frame there costs ~75 ms of CPU on the cores the two models compute on;
/// while a run computes the simulation then gets the larger share of both cores, and the
/// window still draws (a nice value shares the CPU, it does not starve). With a GPU nothing
/// changes. Linux only: there a nice value belongs to one thread (elsewhere
/// setpriority(2) would lower the whole process, the simulation with it).
fn software_frames_yield(
    mut options: egui_wgpu::WgpuConfiguration,
) -> egui_wgpu::WgpuConfiguration {
    if let egui_wgpu::WgpuSetup::CreateNew(create) = &mut options.wgpu_setup {
        let descriptor = create.device_descriptor.clone();
        create.device_descriptor = Arc::new(move |adapter: &wgpu::Adapter| {
            if draws_in_software(&adapter.get_info()) {
                lower_this_threads_priority(SOFTWARE_WINDOW_NICENESS);
            }
            descriptor(adapter)
        });
    }
    options
}

/// Adds `niceness` to the calling thread's nice value (best effort: a refusal leaves the
/// priority as it was).
#[cfg(target_os = "linux")]
fn lower_this_threads_priority(niceness: i32) {
    use rustix::process::{getpriority_process, setpriority_process};
    let thread = Some(rustix::thread::gettid());
    if let Ok(nice) = getpriority_process(thread) {
        let _ = setpriority_process(thread, nice + niceness);
    }
}

#[cfg(not(target_os = "linux"))]
fn lower_this_threads_priority(_niceness: i32) {}

/// Whether the adapter rasterises on the CPU (Mesa's llvmpipe, a machine without a GPU),
/// where a frame takes CPU from the simulation.
fn draws_in_software(adapter: &wgpu::AdapterInfo) -> bool {
    adapter.device_type == wgpu::DeviceType::Cpu
}

/// How often the window redraws while a run computes, for the adapter that draws it.
fn computing_frame_interval(adapter: &wgpu::AdapterInfo) -> Duration {
    if draws_in_software(adapter) {
        SOFTWARE_COMPUTING_FRAME_INTERVAL
    } else {
        COMPUTING_FRAME_INTERVAL
    }
}

struct App {
    state: AppState,
    sim: SimHandle,
    last_frame: Instant,
    /// The smoke test under Xvfb (SLIDEBASE_EXIT_AFTER), if one runs.
    smoke: Option<SmokeTest>,
    started: Instant,
    dark: Option<bool>,
    frames_drawn: u64,
    /// The pace of redraws while a run computes (see [`computing_frame_interval`]).
    computing_interval: Duration,
    /// Screenshots saved (or failed) on the render thread.
    shots_tx: std::sync::mpsc::Sender<std::result::Result<std::path::PathBuf, String>>,
    shots_rx: std::sync::mpsc::Receiver<std::result::Result<std::path::PathBuf, String>>,
}

/// Opens the visualizer on the default scene (three-storey on El Centro, sliding and fixed
/// base side by side) and runs until the window closes.
pub fn run_app() -> Result<()> {
    // SLIDEBASE_WINDOW=WIDTHxHEIGHT sets the initial size (screenshots, measurements).
    let (w, h) = std::env::var("SLIDEBASE_WINDOW")
        .ok()
        .and_then(|v| {
            v.split_once('x')
                .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        })
        .unwrap_or((1600.0, 900.0));
    // The simulation's thread first, at the process's priority: the window's thread is
    // lowered below it before it creates the device (see `software_frames_yield`), and
    // threads inherit the priority of the thread that starts them.
    let window: Arc<OnceLock<(egui::Context, Duration)>> = Arc::default();
    let sim = SimHandle::spawn_with_waker(window_waker(window.clone()));
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("slidebase — sliding-base structures under earthquakes (DDA)")
            .with_inner_size([w, h]),
        wgpu_options: software_frames_yield(eframe::NativeOptions::default().wgpu_options),
        ..Default::default()
    };
    eframe::run_native(
        "slidebase",
        options,
        Box::new(move |cc| {
            let render_state = cc.wgpu_render_state.as_ref().ok_or_else(|| {
                Box::<dyn std::error::Error + Send + Sync>::from(
                    crate::render::offscreen::NO_ADAPTER_HELP,
                )
            })?;
            render_state
                .renderer
                .write()
                .callback_resources
                .insert(Renderer::new(
                    &render_state.device,
                    render_state.target_format,
                ));
            let computing_interval = computing_frame_interval(&render_state.adapter.get_info());
            // The simulation wakes this window from now on.
            let _ = window.set((cc.egui_ctx.clone(), computing_interval));
            let (shots_tx, shots_rx) = std::sync::mpsc::channel();
            Ok(Box::new(App {
                state: AppState::default(),
                sim,
                last_frame: Instant::now(),
                smoke: std::env::var("SLIDEBASE_EXIT_AFTER")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .map(SmokeTest::new),
                started: Instant::now(),
                dark: None,
                frames_drawn: 0,
                computing_interval,
                shots_tx,
                shots_rx,
            }))
        }),
    )
    .map_err(|e| {
        let text = e.to_string();
        if text.to_lowercase().contains("adapter") {
            Error::Platform(format!(
                "{} ({text})",
                crate::render::offscreen::NO_ADAPTER_HELP
            ))
        } else {
            Error::Platform(format!("{NO_DISPLAY_HELP} ({text})"))
        }
    })
}

impl App {
    /// Carries out what the UI asked of the window.
    fn shell_requests(&mut self, ctx: &egui::Context) {
        for request in self.state.take_requests() {
            match request {
                ShellRequest::Quit => ctx.send_viewport_cmd(egui::ViewportCommand::Close),
                ShellRequest::FullScreen(on) => {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Fullscreen(on))
                }
                ShellRequest::Screenshot(path) => {
                    // The image arrives on the render thread after this frame is drawn.
                    let (tx, ctx2) = (self.shots_tx.clone(), ctx.clone());
                    ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(
                        egui::ScreenshotCallback::new(move |image| {
                            let saved = save_color_image(&path, &image)
                                .map(|()| path.clone())
                                .map_err(|e| e.to_string());
                            let _ = tx.send(saved);
                            ctx2.request_repaint();
                        }),
                    ));
                }
            }
        }
        while let Ok(saved) = self.shots_rx.try_recv() {
            match saved {
                Ok(path) => self.state.say(format!("saved {}", path.display())),
                Err(e) => self.state.error = Some(e),
            }
        }
    }
}

/// The smoke test (SLIDEBASE_EXIT_AFTER=seconds): the default run, then the same run
/// again in the warm window (what a user who moves a slider waits for), then quit with
/// one line of speeds. The first run shares the cores with the window's start (its
/// first frames compile shaders and lay out fonts); the rerun measures the steady state.
#[derive(Debug)]
struct SmokeTest {
    exit_after: f64,
    /// The runs so far: generation and speed (× real time), once each finished. The first
    /// computes both models while the window starts; the second changes only the
    /// friction (a slider drag: the fixed base is played back); the third changes the
    /// record's scale, so both models are computed again.
    runs: Vec<(u64, f64)>,
    /// The speeds were printed and the window asked to close: the frames drawn before
    /// it closes must not print them again (one line per check, for scripts to parse).
    reported: bool,
}

impl SmokeTest {
    fn new(exit_after: f64) -> Self {
        Self {
            exit_after,
            runs: Vec::new(),
            reported: false,
        }
    }

    /// The speeds so far, as printed.
    fn speeds(&self) -> String {
        let speed = |i: usize| {
            self.runs
                .get(i)
                .map_or("unfinished".to_string(), |r| format!("{:.1}×", r.1))
        };
        format!(
            "first run {} real time (while the window starts), friction changed {} real \
             time (the fixed base played back), both models again {} real time",
            speed(0),
            speed(1),
            speed(2)
        )
    }
}

impl App {
    /// Reruns as a user would once each run is done (see [`SmokeTest::runs`]), and quits
    /// when the time is up.
    fn smoke_test(&mut self, ctx: &egui::Context) {
        let Some(smoke) = self.smoke.as_mut() else {
            return;
        };
        let timeline = &self.state.timeline;
        let new = smoke.runs.last().is_none_or(|r| r.0 != timeline.generation);
        if timeline.finished && new && smoke.runs.len() < 3 {
            smoke.runs.push((timeline.generation, timeline.sim_speed));
            let controls = &mut self.state.controls;
            match smoke.runs.len() {
                1 => controls.friction *= 2.0,
                2 => controls.pga_g = Some(0.9 * timeline.motion.pga_g),
                _ => {}
            }
            if smoke.runs.len() < 3 {
                self.state.restart();
            }
        }
        let elapsed = self.started.elapsed().as_secs_f64();
        if smoke.reported {
            return;
        }
        if elapsed >= smoke.exit_after {
            smoke.reported = true;
            println!(
                "frame time {:.1} ms, simulation {}, frames drawn {}, frame copy-out {:.0} µs, batch take-in {:.1} µs",
                self.state.frame_ms,
                smoke.speeds(),
                self.frames_drawn,
                self.state.extract_us,
                self.state.handoff_us
            );
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else {
            ctx.request_repaint_after(Duration::from_secs_f64(smoke.exit_after - elapsed));
        }
    }
}

/// Writes an egui screenshot as PNG (creating its folder).
fn save_color_image(path: &std::path::Path, image: &egui::ColorImage) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let [w, h] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    crate::render::offscreen::write_png(path, &bytes, w as u32, h as u32)
}

impl eframe::App for App {
    /// The panel colour: the panels and the scene are drawn without their own fill (see
    /// `ui::unfilled_panel`).
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        if self.dark != Some(self.state.view.dark) {
            self.dark = Some(self.state.view.dark);
            ctx.set_theme(if self.state.view.dark {
                egui::Theme::Dark
            } else {
                egui::Theme::Light
            });
        }
        // Messages from the simulation: it never waits for us, we never wait for it.
        while let Ok(msg) = self.sim.messages.try_recv() {
            self.state.ingest(msg);
        }
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f64().min(0.25);
        self.last_frame = now;
        self.state.advance(dt);
        self.state.ui(ui);
        for cmd in self.state.take_commands() {
            self.sim.send(cmd);
        }
        self.shell_requests(&ctx);
        self.frames_drawn += 1;
        if self.state.playing && self.state.animating() {
            // Paced: the next frame no sooner than 1/60 s after this one began (slower
            // while the run is still being computed).
            let interval = if self.state.timeline.finished {
                FRAME_INTERVAL
            } else {
                self.computing_interval
            };
            ctx.request_repaint_after(interval.saturating_sub(now.elapsed()));
        }
        self.smoke_test(&ctx);
    }

    fn on_exit(&mut self) {
        self.sim.send(crate::sim::SimCommand::Quit);
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;
    use rustix::process::getpriority_process;

    /// The window lowers its own thread only: the simulation's thread, started before it,
    /// and the process's other threads keep their priority (a nice value is per thread on
    /// Linux), while a thread started after it inherits the lower one (llvmpipe's).
    #[test]
    fn lowering_the_window_thread_leaves_the_simulation_thread_alone() {
        fn nice(thread: rustix::thread::Pid) -> i32 {
            getpriority_process(Some(thread)).expect("getpriority")
        }
        let (tid_tx, tid_rx) = std::sync::mpsc::channel();
        let (go_tx, go_rx) = std::sync::mpsc::channel::<()>();
        // The "simulation": started first, it reports its thread and waits.
        let simulation = std::thread::spawn(move || {
            tid_tx.send(rustix::thread::gettid()).unwrap();
            go_rx.recv().ok();
        });
        let simulation_tid = tid_rx.recv().unwrap();
        let before = nice(simulation_tid);
        // The "window".
        let window = std::thread::spawn(move || {
            let own = rustix::thread::gettid();
            let start = nice(own);
            lower_this_threads_priority(SOFTWARE_WINDOW_NICENESS);
            // A rasteriser's thread, started by the window after it lowered itself.
            let started = std::thread::spawn(|| nice(rustix::thread::gettid()))
                .join()
                .unwrap();
            (start, nice(own), started)
        });
        let (start, lowered, started) = window.join().unwrap();
        // Nice values stop at 19: a test run under `nice -n 19` has nothing to lower.
        let expected = (start + SOFTWARE_WINDOW_NICENESS).min(19);
        assert_eq!(lowered, expected, "the window's thread is lowered");
        assert_eq!(
            started, expected,
            "threads it starts inherit the lower priority"
        );
        assert_eq!(
            nice(simulation_tid),
            before,
            "the simulation's thread is not"
        );
        go_tx.send(()).unwrap();
        simulation.join().unwrap();
    }
}
