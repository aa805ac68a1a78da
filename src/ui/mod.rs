//! The egui side of the visualizer: the controls, the timeline, the plots and the scene
//! with its overlays. All state lives in [`AppState`], which knows nothing about windows:
//! it takes simulation messages in and gives commands out (and requests such as
//! "screenshot" or "quit" to the shell), so its logic is tested with egui_kittest and no
//! window.
//!
//! Layout: a top bar (presets, the headline result, buttons), the controls on the left, the
//! plots on the right, the timeline at the bottom and the scene in the middle. Panels
//! collapse (and start collapsed in small windows); the full-screen scene mode hides them.

mod controls;
mod help;
mod plots;
pub mod presets;
pub mod scene;
mod timeline;

use std::time::Instant;

use crate::dda::Integrator;
use crate::model::bearing::Bearing;
use crate::model::friction::Friction;
use crate::render::{Camera, ColorBy, Fit, Layers};
use crate::sim::{
    ExactOverlay, Excitation, FrameSet, MotionInfo, Samples, SimCommand, SimConfig, SimMessage,
    TimeLeft,
};

pub use plots::{
    Curve, MODEL_COLORS, PlotCache, PlotData, accel_legend, model_color, spectrum_of,
    write_plot_data,
};

/// The scenes offered in the panel.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneChoice {
    /// The paper's three-storey frame.
    ThreeStorey,
    /// The paper's two-mass model (Fig. 2).
    TwoBlock,
    /// Newmark's sliding block: one rigid block on the joint (`block`).
    Block,
    /// A thin slider in a concave dish (`friction-pendulum`).
    FrictionPendulum,

    /// The paper's frame with N storeys (`frame:N`).
    Frame(u32),
    /// A dry-stacked wall of N courses on a sliding slab (`wall:N`).
    Wall(u32),
    /// A scene file.
    File(String),
}

impl SceneChoice {
    /// The scene name the simulation understands.
    pub fn name(&self) -> String {
        match self {
            SceneChoice::ThreeStorey => "three-storey".into(),
            SceneChoice::TwoBlock => "two-block".into(),
            SceneChoice::Block => "block".into(),
            SceneChoice::FrictionPendulum => "friction-pendulum".into(),
            SceneChoice::Frame(n) => format!("frame:{n}"),
            SceneChoice::Wall(n) => format!("wall:{n}"),
            SceneChoice::File(p) => p.clone(),
        }
    }

    /// The choice a built-in or generated scene's name (`wall:8`, `three-storey`) stands
    /// for in the window; `None` for any other text (a file's path), an error in words
    /// for a size the window does not run (see [`WINDOW_MAX_STOREYS`]).
    pub fn from_name(name: &str) -> Option<std::result::Result<SceneChoice, String>> {
        let fixed = [
            SceneChoice::ThreeStorey,
            SceneChoice::TwoBlock,
            SceneChoice::Block,
            SceneChoice::FrictionPendulum,
        ];
        if let Some(choice) = fixed.into_iter().find(|c| c.name() == name) {
            return Some(Ok(choice));
        }
        let (kind, size) = name.split_once(':')?;
        // What the size counts, the window's range of it, the command line's largest.
        let (what, low, window_max, cli_max, choice): (_, u32, u32, usize, fn(u32) -> _) =
            match kind {
                "frame" => (
                    "storeys",
                    1,
                    WINDOW_MAX_STOREYS,
                    crate::model::generated::MAX_FRAME_STOREYS,
                    SceneChoice::Frame,
                ),
                "wall" => (
                    "courses",
                    2,
                    WINDOW_MAX_COURSES,
                    crate::model::generated::MAX_WALL,
                    SceneChoice::Wall,
                ),
                _ => return None,
            };
        Some(match size.trim().parse::<u32>() {
            Ok(n) if (low..=window_max).contains(&n) => Ok(choice(n)),
            Ok(n) if n as usize <= cli_max && n >= low => Err(format!(
                "{name}: the window runs {low} to {window_max} {what} (it keeps every frame of \
                 both models for the replay); the command line runs up to {kind}:{cli_max}: \
                 slidebase run --scene {name}"
            )),
            _ => Err(format!(
                "{name}: give {low} to {window_max} {what} here (the command line: up to \
                 {kind}:{cli_max})"
            )),
        })
    }

    /// A label for people.
    pub fn label(&self) -> String {
        match self {
            SceneChoice::ThreeStorey => "three-storey frame (paper Fig. 3)".into(),
            SceneChoice::TwoBlock => "two-mass model (paper Fig. 2)".into(),
            SceneChoice::Block => "sliding block (Newmark)".into(),
            SceneChoice::FrictionPendulum => "friction pendulum (slider in a dish)".into(),
            SceneChoice::Frame(n) => format!("frame of {n} storeys"),
            SceneChoice::Wall(n) => format!("dry-stacked wall, {n} courses"),
            SceneChoice::File(p) => file_name(p),
        }
    }
}

/// Most storeys of a generated frame in the window, and courses of a generated wall: the
/// replay keeps every frame of both models (a 12-course wall under the 41 s of Kobe holds
/// ~1.2 GB); the command line runs up to `frame:20` and `wall:40`.
pub const WINDOW_MAX_STOREYS: u32 = 10;
/// See [`WINDOW_MAX_STOREYS`].
pub const WINDOW_MAX_COURSES: u32 = 12;

/// The last component of a path (long paths are shown by their file name).
pub fn file_name(path: &str) -> String {
    std::path::Path::new(path)
        .file_name()
        .map_or_else(|| path.to_string(), |n| n.to_string_lossy().into_owned())
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

/// What the model is compared with, side by side.
#[derive(Debug, Clone, PartialEq)]
pub enum Comparison {
    /// Nothing: the sliding model alone.
    None,
    /// The same structure with its base fixed to the ground.
    FixedBase,
    /// The sliding model with other friction coefficients.
    Friction(Vec<f64>),
    /// Other friction coefficients and the fixed base.
    FrictionAndFixed(Vec<f64>),
    /// The same frame on the flat joint (when it stands on pendulum bearings).
    FlatJoint,
}

/// What the user has set in the panel: the physics of a run. Any change restarts the run
/// (keeping the time cursor); view settings and text being typed are elsewhere.
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
    /// Scale the record to this peak ground acceleration, g (None: as recorded).
    pub pga_g: Option<f64>,
    /// Friction coefficient of the sliding joint.
    pub friction: f64,
    /// Mass ratio α (two-block scene).
    pub alpha: f64,
    /// Integrator (None: the scene's choice).
    pub integrator: Option<Integrator>,
    /// Time step, s.
    pub dt: f64,
    /// What runs beside the model.
    pub comparison: Comparison,
    /// Structural damping ratio ζ (two-block and frame scenes; 0: undamped).
    pub damping: f64,
    /// Shake the ground vertically too, with the record's own vertical component
    /// ([`VERTICAL_RECORD`]; El Centro records only).
    pub vertical: bool,
    /// Effective radius of the frame's friction-pendulum bearings, m (None: the flat
    /// joint; frames only).
    pub bearing_radius: Option<f64>,
    /// The sliding joint's friction law, built on `friction` (see [`LawChoice`]).
    pub law: LawChoice,
}

/// The friction law of the panel. `friction` (the ρ slider) is its sliding coefficient at
/// rest: Coulomb's ρ, the kinetic μ_k, the velocity law's μ_slow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawChoice {
    /// One coefficient for sticking and sliding.
    Coulomb,
    /// Sticks up to μ_s = `stick`, slides at μ_k = ρ.
    StaticKinetic {
        /// Static coefficient μ_s.
        stick: f64,
    },
    /// μ(v) = μ_fast − (μ_fast − ρ)·exp(−rate·|v|).
    Velocity {
        /// μ_fast.
        fast: f64,
        /// Rate, s/m.
        rate: f64,
    },
}

impl LawChoice {
    /// The law with sliding coefficient at rest `friction` (None: Coulomb's, which the
    /// friction coefficient alone says). A μ_s below μ_k, or a μ_fast below μ_slow, is
    /// raised to it (the sliders move independently).
    pub fn law(&self, friction: f64) -> Option<Friction> {
        match *self {
            LawChoice::Coulomb => None,
            LawChoice::StaticKinetic { stick } => Some(Friction::StaticKinetic {
                stick: stick.max(friction),
                slide: friction,
            }),
            LawChoice::Velocity { fast, rate } => Some(Friction::Velocity {
                slow: friction,
                fast: fast.max(friction),
                rate,
            }),
        }
    }
}

/// The vertical component the "vertical shaking" toggle adds (the only built-in one).
pub const VERTICAL_RECORD: &str = "el-centro-up";

impl Default for Controls {
    fn default() -> Self {
        Self {
            scene: SceneChoice::ThreeStorey,
            record: RecordChoice::Builtin("el-centro".into()),
            amplitude_g: 0.3,
            frequency: 1.0,
            pga_g: None,
            friction: 0.01,
            alpha: 0.5,
            integrator: None,
            dt: 1e-3,
            comparison: Comparison::FixedBase,
            damping: 0.0,
            vertical: false,
            bearing_radius: None,
            law: LawChoice::Coulomb,
        }
    }
}

impl Controls {
    /// Whether the vertical toggle applies: a built-in El Centro horizontal component,
    /// whose station recorded the vertical one the toggle adds.
    pub fn vertical_available(&self) -> bool {
        matches!(&self.record, RecordChoice::Builtin(n)
            if n.starts_with("el-centro") && !n.ends_with("-up"))
    }

    /// Whether the damping slider applies: the two-block scene (a dashpot beside its
    /// spring) and the frames (Rayleigh damping); not a wall of loose blocks.
    pub fn damping_applies(&self) -> bool {
        matches!(
            self.scene,
            SceneChoice::TwoBlock | SceneChoice::ThreeStorey | SceneChoice::Frame(_)
        )
    }

    /// Whether the bearing choice applies: the frames (their base slab can stand on
    /// friction-pendulum bearings).
    pub fn bearing_applies(&self) -> bool {
        matches!(self.scene, SceneChoice::ThreeStorey | SceneChoice::Frame(_))
    }

    /// The frame's bearings as run (None: the flat joint).
    pub fn bearing(&self) -> Option<Bearing> {
        self.bearing_radius
            .filter(|_| self.bearing_applies())
            .map(|radius| Bearing::Pendulum { radius })
    }

    /// The simulation configuration these controls describe.
    pub fn config(&self) -> SimConfig {
        let two_block = self.scene == SceneChoice::TwoBlock;
        let (compare_friction, compare_fixed) = match &self.comparison {
            Comparison::None => (Vec::new(), false),
            Comparison::FixedBase => (Vec::new(), true),
            Comparison::Friction(f) => (f.clone(), false),
            Comparison::FrictionAndFixed(f) => (f.clone(), true),
            Comparison::FlatJoint => (Vec::new(), false),
        };
        let bearing = self.bearing();
        SimConfig {
            scene: self.scene.name(),
            friction: Some(self.friction),
            friction_law: self.law.law(self.friction),
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
            compare_fixed,
            compare_friction,
            pga_g: match self.record {
                RecordChoice::Harmonic => None,
                _ => self.pga_g,
            },
            duration: None,
            damping: (self.damping_applies() && self.damping > 0.0).then_some(self.damping),
            vertical: (self.vertical && self.vertical_available())
                .then(|| VERTICAL_RECORD.to_string()),
            bearing,
            compare_flat: bearing.is_some() && self.comparison == Comparison::FlatJoint,
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
    /// Full-rate samples so far, one set per model.
    pub samples: Vec<Samples>,
    /// Duration of the run, s.
    pub duration: f64,
    /// Exact mass-spring overlay (two-block).
    pub exact: Option<ExactOverlay>,
    /// The ground motion as run.
    pub motion: MotionInfo,
    /// Simulated seconds per wall second.
    pub sim_speed: f64,
    /// The wall-clock time the run has still to go, while it computes and once it has
    /// run long enough to tell.
    pub time_left: Option<TimeLeft>,
    /// The run reached its end.
    pub finished: bool,
    /// How many models were played back from the last run (nothing they depend on
    /// changed) rather than computed again.
    pub replayed_models: usize,
    /// The configuration of this run.
    pub config: Option<SimConfig>,
}

impl Timeline {
    /// What the plots and readouts call the top of the structure: "roof", or "block" when
    /// the structure is a lone block (its own base and roof).
    pub fn top_name(&self) -> &'static str {
        if self.single_body() { "block" } else { "roof" }
    }

    /// Whether the run's structure is a lone block (see [`ModelFrame::single_body`]).
    pub fn single_body(&self) -> bool {
        self.frames
            .first()
            .and_then(|f| f.models.first())
            .is_some_and(|m| m.single_body)
    }

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

    /// Simulated time between frames, s.
    pub fn frame_dt(&self) -> f64 {
        self.config.as_ref().map_or(0.01, |c| c.frame_dt)
    }

    /// The largest |drift| of any model computed so far, m (what the automatic
    /// exaggeration and the readouts' drift unit are chosen from).
    pub fn peak_drift(&self) -> f64 {
        (0..self.samples.len())
            .map(|m| self.peak(m, f64::INFINITY, |s| &s.drift))
            .fold(0.0, f64::max)
    }

    /// Largest |value| of a sample column of model `m` up to time `t`.
    pub fn peak(&self, m: usize, t: f64, column: fn(&Samples) -> &Vec<f64>) -> f64 {
        self.samples.get(m).map_or(0.0, |s| {
            column(s)[..s.count_until(t)]
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()))
        })
    }
}

/// How much deformation is magnified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exaggeration {
    /// Chosen so that the largest drift of the run is drawn as ~8 % of the height.
    Auto,
    /// This factor.
    Fixed(f32),
}

/// What the user has set about the view (changing it never restarts a run).
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSettings {
    /// Layers drawn.
    pub layers: Layers,
    /// Deformation exaggeration.
    pub exaggeration: Exaggeration,
    /// Block colouring.
    pub color_by: ColorBy,
    /// The camera of the model panels.
    pub camera: Camera,
    /// Show the joint close-ups.
    pub close_ups: bool,
    /// Full-screen scene mode (panels hidden).
    pub full_screen: bool,
    /// Show the controls panel.
    pub show_controls: bool,
    /// Show the plots panel.
    pub show_plots: bool,
    /// The keyboard shortcuts overlay.
    pub show_help: bool,
    /// The "what am I looking at" window.
    pub show_about: bool,
    /// Developer diagnostics in the controls panel.
    pub show_diagnostics: bool,
    /// Spectra of the samples up to the time cursor (else of the whole run computed).
    pub spectrum_to_cursor: bool,
    /// Dark theme (else light, for projectors).
    pub dark: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            layers: Layers::default(),
            exaggeration: Exaggeration::Auto,
            color_by: ColorBy::Strain,
            camera: Camera::default(),
            close_ups: true,
            full_screen: false,
            show_controls: true,
            show_plots: true,
            show_help: false,
            show_about: false,
            show_diagnostics: false,
            spectrum_to_cursor: false,
            dark: false,
        }
    }
}

/// Something only the window shell can do, asked for by the UI.
#[derive(Debug, Clone, PartialEq)]
pub enum ShellRequest {
    /// Save a screenshot of the window to this PNG file.
    Screenshot(std::path::PathBuf),
    /// Close the window.
    Quit,
    /// Enter or leave the window's full-screen state.
    FullScreen(bool),
}

/// The whole visualizer state.
pub struct AppState {
    /// Panel controls (the physics).
    pub controls: Controls,
    /// The path typed in the file field (loaded only with "load").
    pub path_input: String,
    /// View settings.
    pub view: ViewSettings,
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
    /// After a parameter change: the time the cursor returns to once the new run has
    /// computed it.
    pub resume_at: Option<f64>,
    /// A run was asked for and has not started yet: until it does, the frames and the end
    /// of the run it replaces (still arriving) must not take `resume_at` for theirs.
    awaiting_start: bool,
    /// The generated frame's storeys and wall's courses last chosen: picking the scene
    /// again after another one brings them back (a 12-course wall stays 12 courses).
    generated_sizes: (u32, u32),
    /// Errors to show (bad file, solver stopped…).
    pub error: Option<String>,
    /// A short message (file saved…), with when it was posted.
    pub status: Option<(String, Instant)>,
    /// Folder exports are written to.
    pub export_dir: String,
    /// Smoothed frame time, ms.
    pub frame_ms: f64,
    /// Time to take in one batch of frames from the channel, µs (the state hand-off).
    pub handoff_us: f64,
    /// Mean time the simulation thread takes to copy a frame out of the solvers, µs.
    pub extract_us: f64,
    /// Where the named widgets were last drawn (for automation that clicks them).
    pub widget_rects: std::collections::HashMap<&'static str, egui::Rect>,
    /// The preset last chosen (its name), until the controls change.
    pub preset: Option<&'static str>,
    fits: Option<(u64, usize, f32, Vec<Fit>)>,
    /// The plots' curves, kept between frames (see [`PlotCache`]).
    plot_cache: PlotCache,
    /// [`AppState::color_max`] of (run generation, colour measure) over the first frames.
    color_max: Option<((u64, crate::render::geometry::ColorBy), usize, f32)>,
    laid_out: bool,
    outbox: Vec<SimCommand>,
    requests: Vec<ShellRequest>,
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
            path_input: String::new(),
            view: ViewSettings::default(),
            timeline: Timeline::default(),
            play_time: 0.0,
            playing: true,
            speed: 1.0,
            looping: true,
            resume_at: None,
            awaiting_start: false,
            generated_sizes: (5, 6),
            error: None,
            status: None,
            export_dir: "slidebase-export".into(),
            frame_ms: 0.0,
            handoff_us: 0.0,
            extract_us: 0.0,
            widget_rects: Default::default(),
            preset: None,
            fits: None,
            plot_cache: PlotCache::default(),
            color_max: None,
            laid_out: false,
            outbox: Vec::new(),
            requests: Vec::new(),
        };
        s.restart();
        s
    }

    /// Queues a run with the current controls, in the background. The time cursor stays
    /// where it is: the new run is shown there as soon as it has been computed that far.
    pub fn restart(&mut self) {
        self.error = None;
        if self.timeline.generation > 0 {
            self.resume_at = Some(self.play_time);
            self.awaiting_start = true;
        }
        self.outbox
            .push(SimCommand::Run(Box::new(self.controls.config())));
    }

    /// Commands for the simulation thread since the last call.
    pub fn take_commands(&mut self) -> Vec<SimCommand> {
        std::mem::take(&mut self.outbox)
    }

    /// Requests for the window shell since the last call.
    pub fn take_requests(&mut self) -> Vec<ShellRequest> {
        std::mem::take(&mut self.requests)
    }

    /// Posts a short message in the top bar.
    pub fn say(&mut self, message: impl Into<String>) {
        self.status = Some((message.into(), Instant::now()));
    }

    /// Takes in a message from the simulation thread.
    pub fn ingest(&mut self, msg: SimMessage) {
        let t0 = Instant::now();
        match msg {
            SimMessage::Started {
                generation,
                config,
                duration,
                labels,
                motion,
                exact,
                first,
            } => {
                let models = first.models.len();
                self.awaiting_start = false;
                self.timeline = Timeline {
                    generation,
                    labels,
                    frames: vec![*first],
                    samples: vec![Samples::default(); models],
                    duration,
                    exact: exact.map(|e| *e),
                    motion: *motion,
                    sim_speed: 0.0,
                    time_left: None,
                    finished: false,
                    replayed_models: 0,
                    config: Some(*config),
                };
                self.play_time = match self.resume_at {
                    Some(t) => t.min(duration),
                    None => 0.0,
                };
                self.fits = None;
            }
            SimMessage::Frames {
                generation,
                frames,
                mut samples,
                speed,
                time_left,
                extract_us,
            } if generation == self.timeline.generation => {
                self.timeline.frames.extend(frames);
                for (mine, new) in self.timeline.samples.iter_mut().zip(samples.iter_mut()) {
                    mine.append(new);
                }
                self.timeline.sim_speed = speed;
                self.timeline.time_left = time_left;
                self.extract_us = extract_us;
                self.handoff_us = 0.9 * self.handoff_us + 0.1 * t0.elapsed().as_secs_f64() * 1e6;
                if let Some(t) = self.resume_at
                    && !self.awaiting_start
                    && self.timeline.available() >= t.min(self.timeline.duration) - 1e-9
                {
                    self.resume_at = None;
                }
            }
            SimMessage::Finished {
                generation,
                replayed_models,
                ..
            } if generation == self.timeline.generation => {
                self.timeline.finished = true;
                self.timeline.replayed_models = replayed_models;
                if !self.awaiting_start {
                    self.resume_at = None;
                }
            }
            SimMessage::Failed { message, .. } => {
                self.error = Some(message);
                self.resume_at = None;
            }
            _ => {}
        }
    }

    /// Whether the picture changes without input: playing, or a run still computing.
    pub fn animating(&self) -> bool {
        (self.playing && !self.at_end()) || !self.timeline.finished
    }

    fn at_end(&self) -> bool {
        self.timeline.finished && self.play_time >= self.timeline.duration - 1e-9
    }

    /// A note for the picture's header: the time a changed run is being computed up to,
    /// or that the replay waits for a computation slower than the playback (on a long run
    /// it would otherwise look like slow motion).
    pub fn picture_note(&self) -> Option<String> {
        if let Some(t) = self.resume_at {
            return Some(format!("computing up to {t:.2} s…"));
        }
        // Within a second of the computed front: frames arrive in batches (two a second
        // on a software rasteriser), so a held replay is mostly a little behind the front.
        let timeline = &self.timeline;
        let held = self.playing
            && !timeline.finished
            && self.play_time >= timeline.available() - HELD_WITHIN_S
            && timeline.sim_speed < self.speed;
        held.then(|| {
            format!(
                "the replay waits for the computation ({} real time)",
                speed_words(timeline.sim_speed)
            )
        })
    }

    /// Advances the playback clock by `wall_dt` seconds of wall time.
    pub fn advance(&mut self, wall_dt: f64) {
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * wall_dt * 1e3;
        if !self.playing || self.resume_at.is_some() {
            return;
        }
        let available = self.timeline.available();
        self.play_time += wall_dt * self.speed;
        if self.play_time >= self.timeline.duration - 1e-9 && self.timeline.finished {
            if self.looping {
                self.play_time = 0.0;
            } else {
                self.play_time = self.timeline.duration;
                self.playing = false;
            }
        } else if self.play_time > available {
            // Wait for the simulation (it runs ahead of real time on this machine).
            self.play_time = available;
        }
    }

    /// Starts or pauses playback; play at the end starts again from the beginning.
    pub fn toggle_play(&mut self) {
        if !self.playing && self.at_end() {
            self.play_time = 0.0;
        }
        self.playing = !self.playing;
    }

    /// Moves the time cursor to `t` (clamped to what has been computed) and pauses.
    pub fn seek(&mut self, t: f64) {
        self.play_time = t.clamp(0.0, self.timeline.available());
        self.resume_at = None;
        self.playing = false;
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
        self.resume_at = None;
        self.playing = false;
    }

    /// The exaggeration factor in force.
    pub fn exaggeration(&self) -> f32 {
        match self.view.exaggeration {
            Exaggeration::Fixed(f) => f,
            Exaggeration::Auto => auto_exaggeration(&self.timeline),
        }
    }

    /// Largest colour measure over all frames so far (a stable colour scale). Frames are
    /// only added to a run, so the maximum is kept and only the new frames are scanned:
    /// scanning all of them at every redraw (tens of thousands of blocks once a run is
    /// in) was 2 % of the window's CPU under a software rasteriser.
    pub fn color_max(&mut self) -> f32 {
        let by = self.view.color_by;
        let key = (self.timeline.generation, by);
        let (scanned, mut m) = match self.color_max {
            Some((k, n, m)) if k == key && n <= self.timeline.frames.len() => (n, m),
            _ => (0, crate::render::geometry::color_scale_floor(by)),
        };
        for f in &self.timeline.frames[scanned..] {
            for model in &f.models {
                for b in model.blocks.iter().filter(|b| !b.is_ground) {
                    m = m.max(crate::render::geometry::color_measure(
                        by, &b.stress, &b.strain,
                    ));
                }
            }
        }
        self.color_max = Some((key, self.timeline.frames.len(), m));
        m
    }

    /// The boxes that frame the models (as drawn with the current exaggeration), over all
    /// frames computed when first asked; `refit` recomputes them over all frames now.
    pub fn fits(&mut self, refit: bool) -> Vec<Fit> {
        let f = self.exaggeration();
        let key = (self.timeline.generation, f);
        let stale = match &self.fits {
            Some((g, n, e, _)) => {
                refit
                    || (*g, *e) != key
                    // Until the run has a few seconds, keep taking the new frames in.
                    || (*n < 400 && self.timeline.frames.len() > *n + 25)
            }
            None => true,
        };
        if stale {
            let models = self.timeline.frames.first().map_or(0, |f| f.models.len());
            let fits = (0..models)
                .map(|m| {
                    Fit::of_frames(
                        self.timeline
                            .frames
                            .iter()
                            .filter_map(|fs| fs.models.get(m)),
                        f,
                    )
                })
                .collect();
            self.fits = Some((key.0, self.timeline.frames.len(), key.1, fits));
        }
        self.fits.as_ref().map(|x| x.3.clone()).unwrap_or_default()
    }

    /// Draws the whole UI.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        if !self.laid_out {
            // A small window starts with the controls folded away: the scene needs the room.
            self.laid_out = true;
            if ui.ctx().content_rect().width() < 1280.0 {
                self.view.show_controls = false;
            }
        }
        self.keyboard(ui.ctx());
        let full = self.view.full_screen;
        if !full {
            egui::Panel::top("top")
                .frame(unfilled_panel(ui.style()))
                .show(ui, |ui| self.top_bar(ui));
        }
        egui::Panel::bottom("timeline")
            .frame(unfilled_panel(ui.style()))
            .show(ui, |ui| self.timeline_ui(ui));
        let width = ui.ctx().content_rect().width();
        if !full && self.view.show_controls {
            egui::Panel::left("controls")
                .frame(unfilled_panel(ui.style()))
                .resizable(true)
                .default_size((0.2 * width).clamp(230.0, 300.0))
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| self.controls_ui(ui));
                });
        }
        if !full && self.view.show_plots {
            egui::Panel::right("plots")
                .frame(unfilled_panel(ui.style()))
                .resizable(true)
                .default_size((0.3 * width).clamp(300.0, 620.0))
                .show(ui, |ui| {
                    // Not shrunk to the content: with every plot folded the panel kept
                    // shrinking, and unfolding them then gave plots 150 px wide.
                    egui::ScrollArea::vertical()
                        .auto_shrink([false, false])
                        .show(ui, |ui| plots::plots_ui(self, ui));
                });
        }
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| scene::scene_ui(self, ui));
        help::windows(self, ui.ctx());
    }

    fn keyboard(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        // Every key press counts, also several in one frame (fast tapping).
        let mut keys = Vec::new();
        let mut question = false;
        ctx.input(|i| {
            for e in &i.events {
                match e {
                    egui::Event::Key {
                        key,
                        pressed: true,
                        modifiers,
                        ..
                    } => keys.push((*key, *modifiers)),
                    egui::Event::Text(t) if t == "?" => question = true,
                    _ => {}
                }
            }
        });
        if question {
            self.view.show_help = !self.view.show_help;
        }
        let second = (1.0 / self.timeline.frame_dt()).round() as i64;
        for (key, m) in keys {
            use egui::Key;
            match key {
                Key::Space => self.toggle_play(),
                Key::ArrowLeft if m.shift => self.step_frames(-second),
                Key::ArrowRight if m.shift => self.step_frames(second),
                Key::ArrowLeft => self.step_frames(-1),
                Key::ArrowRight => self.step_frames(1),
                Key::Home => self.seek(0.0),
                Key::End => self.seek(self.timeline.available()),
                Key::F if !m.command => self.view.camera.fit(),
                Key::H if !m.command => self.view.show_help = !self.view.show_help,
                Key::Q if m.command => self.requests.push(ShellRequest::Quit),
                Key::F11 => self.set_full_screen(!self.view.full_screen),
                Key::Escape => {
                    if self.view.show_help || self.view.show_about {
                        self.view.show_help = false;
                        self.view.show_about = false;
                    } else if self.view.full_screen {
                        self.set_full_screen(false);
                    }
                }
                _ => {}
            }
        }
    }

    /// Enters or leaves the full-screen scene mode.
    pub fn set_full_screen(&mut self, on: bool) {
        self.view.full_screen = on;
        self.requests.push(ShellRequest::FullScreen(on));
    }

    /// Asks the shell for a screenshot of the window into the export folder.
    pub fn request_screenshot(&mut self) {
        let path = std::path::Path::new(&self.export_dir).join(format!(
            "slidebase-t{:06.2}s-{}.png",
            self.play_time,
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs())
        ));
        self.requests.push(ShellRequest::Screenshot(path));
    }

    /// Loads the path typed in the file field: a TOML scene or a record file. Errors are
    /// shown in the panel; nothing crashes.
    pub fn load_path(&mut self) {
        let path = self.path_input.trim().to_string();
        if path.is_empty() {
            self.error = Some("type the path of an AT2/CSV record or a TOML scene first".into());
            return;
        }
        // A scene's name rather than a file's: the window's own choice, or why not.
        if !std::path::Path::new(&path).exists()
            && let Some(choice) = SceneChoice::from_name(&path)
        {
            match choice {
                Ok(choice) => {
                    self.controls.scene = choice;
                    self.restart();
                }
                Err(why) => self.error = Some(why),
            }
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

    /// The headline comparison: the main model's peak roof acceleration against the
    /// second model's, up to the time cursor ("−89 % against fixed base").
    pub fn headline(&self) -> Option<(String, f64)> {
        let labels = &self.timeline.labels;
        if labels.len() < 2 {
            return None;
        }
        let other = labels.len() - 1;
        let t = self.play_time;
        let main = self.timeline.peak(0, t, |s| &s.roof_accel);
        let cmp = self.timeline.peak(other, t, |s| &s.roof_accel);
        if cmp <= 0.0 {
            return None;
        }
        let change = 100.0 * (main - cmp) / cmp;
        let g = crate::ground_motion::STANDARD_GRAVITY;
        Some((
            format!(
                "peak {} acceleration {:.2} g against {:.2} g with the {}: {:+.0} %",
                self.timeline.top_name(),
                main / g,
                cmp / g,
                labels[other],
                change
            ),
            change,
        ))
    }
}

/// The automatic exaggeration: the largest storey drift computed so far drawn as about
/// 8 % of the structure's height, rounded down to 1, 2 or 5 × 10ⁿ, between 1 and 1000.
pub fn auto_exaggeration(timeline: &Timeline) -> f32 {
    let Some(first) = timeline.frames.first() else {
        return 1.0;
    };
    let height = first
        .models
        .first()
        .map_or(1.0, |m| {
            m.blocks
                .iter()
                .filter(|b| !b.is_ground)
                .flat_map(|b| b.vertices.iter().map(|v| v[1]))
                .fold(0.0f32, f32::max)
        })
        .max(0.1);
    let drift = timeline.peak_drift() as f32;
    if drift.is_nan() || drift <= 0.0 {
        return 50.0;
    }
    let raw = (0.08 * height / drift).clamp(1.0, 1000.0);
    let p = 10f32.powf(raw.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s <= raw)
        .unwrap_or(p)
}

/// A side or top panel's frame without its fill: the window is cleared with the panel
/// colour already (`App::clear_color`), and a software rasteriser (Mesa's llvmpipe on a
/// machine without a GPU) spends ~60 ns of CPU per pixel on egui's textured fill — the
/// panels' fills cost more than everything else drawn.
pub fn unfilled_panel(style: &egui::Style) -> egui::Frame {
    egui::Frame::side_top_panel(style).fill(egui::Color32::TRANSPARENT)
}

/// How close to the computed front (simulated s) a playing replay that outruns the
/// computation counts as held by it (see [`AppState::picture_note`]).
const HELD_WITHIN_S: f64 = 1.0;

/// A simulation speed for people: "0.31×", "12×" (two decimals below 10×).
fn speed_words(speed: f64) -> String {
    if speed < 10.0 {
        format!("{:.2}×", speed)
    } else {
        format!("{speed:.0}×")
    }
}
