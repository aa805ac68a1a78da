//! The simulation thread: it owns the solvers, runs them ahead of the display and posts
//! compact frames over a channel; commands come back on a second channel. The UI never
//! waits on the solver and the solver never waits on the UI.
//!
//! A run is the sliding model and, for comparison, the same scene with a bonded joint
//! (fixed base), advanced in lockstep. Every frame ever computed is posted, so the UI can
//! keep them all and scrub the timeline.

pub mod frame;
pub mod replay;

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use frame::{Attached, BlockFrame, ContactFrame, Extractor, ModelFrame, Probes, Samples};

use crate::Result;
use crate::analytic::{ExactOptions, ShearBuilding, SteppedOptions, simulate, simulate_stepped};
use crate::dda::{Dda, Integrator};
use crate::ground_motion::GroundMotion;
use crate::model::Scene;
use crate::model::bearing::Bearing;
use crate::setup::{ExcitationSpec, Frequency, RemainingTime, RunSetup, RunSpec, VerticalSpec};

/// The ground motion of a run.
#[derive(Debug, Clone, PartialEq)]
pub enum Excitation {
    /// The scene's own excitation.
    Scene,
    /// A record: built-in name or file path.
    Record(String),
    /// Harmonic, amplitude in g, frequency as a ratio of the structure's (two-block) or in Hz.
    Harmonic {
        /// Amplitude, g.
        amplitude_g: f64,
        /// Ω/ω for a two-block scene, Hz otherwise.
        frequency: f64,
    },
}

/// Everything that defines a run; changing any of it restarts the run from t = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Built-in scene name or TOML path.
    pub scene: String,
    /// Friction coefficient of the sliding joint (None: the scene's).
    pub friction: Option<f64>,
    /// Friction law of the sliding joint (None: Coulomb's with `friction`); replaces
    /// `friction` when given.
    pub friction_law: Option<crate::model::friction::Friction>,
    /// Mass ratio α (two-block scenes).
    pub alpha: Option<f64>,
    /// Ground motion.
    pub excitation: Excitation,
    /// Integrator (None: the scene's choice, see [`crate::model::Scene::integrator`]).
    pub integrator: Option<Integrator>,
    /// Time step, s.
    pub dt: f64,
    /// Also run the fixed-base comparison.
    pub compare_fixed: bool,
    /// Also run the sliding model with each of these friction coefficients (a side-by-side
    /// comparison of friction values), after the main model and before the fixed base.
    pub compare_friction: Vec<f64>,
    /// Scale the ground motion to this peak ground acceleration, g (None: as recorded).
    pub pga_g: Option<f64>,
    /// Duration, s (None: the record's length, or the default of harmonic input,
    /// [`crate::setup::defaults::HARMONIC_DURATION_S`]).
    pub duration: Option<f64>,
    /// Simulated time between published frames, s.
    pub frame_dt: f64,
    /// Structural damping ratio ζ (two-block and frame scenes; None: undamped).
    pub damping: Option<f64>,
    /// Vertical ground motion: a built-in `-up` record or a file (None: horizontal only).
    pub vertical: Option<String>,
    /// The bearing under a frame's base slab (None: the scene's flat joint).
    pub bearing: Option<Bearing>,
    /// With pendulum bearings: also run the same frame on the flat joint, second from the
    /// left (the recentring comparison).
    pub compare_flat: bool,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            scene: "three-storey".into(),
            friction: None,
            friction_law: None,
            alpha: None,
            excitation: Excitation::Scene,
            integrator: None,
            dt: crate::setup::defaults::DT,
            compare_fixed: true,
            compare_friction: Vec::new(),
            pga_g: None,
            duration: None,
            // 100 frames per simulated second: smooth replay at up to 2× speed at 60 Hz,
            // and about 6 MB for a 30 s three-storey run.
            frame_dt: 0.01,
            damping: None,
            vertical: None,
            bearing: None,
            compare_flat: false,
        }
    }
}

/// A prepared run: the models, the motion and the metadata the UI needs.
pub struct PreparedRun {
    /// The scene as run (after parameters were applied).
    pub scene: Scene,
    /// Ground motion.
    pub motion: GroundMotion,
    /// Duration, s.
    pub duration: f64,
    /// The sliding model, the friction comparisons and, if requested, the fixed-base one.
    pub models: Vec<(Dda, Extractor)>,
    /// One label per model ("sliding base, ρ = 0.01", "fixed base").
    pub labels: Vec<String>,
    /// What the ground motion is (for the panel and picture titles).
    pub motion_info: MotionInfo,
    /// For two-block scenes: the exact mass-spring solution (time, slip, drift, base accel,
    /// roof accel), for overlaying on the DDA curves.
    pub exact: Option<ExactOverlay>,
    /// What the user should know about the run (e.g. a time step that barely resolves the
    /// excitation), from the shared set-up's checks.
    pub warnings: Vec<String>,
    /// Which model each is (what it depends on besides the run's shared settings).
    pub roles: Vec<replay::ModelRole>,
    /// Per model, the recording it is played back from instead of computed (see
    /// [`replay`]; empty: all computed).
    pub replays: Vec<Option<replay::Replay>>,
}

/// A description of a run's ground motion for people: name, source, peak, sampling.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionInfo {
    /// Name ("el-centro", "harmonic 0.30 g, 1.00 Hz").
    pub name: String,
    /// Where it comes from (a record's provenance; empty for harmonic input).
    pub source: String,
    /// Peak ground acceleration as run (after any scaling), g.
    pub pga_g: f64,
    /// Sample interval of a record, s (None: harmonic).
    pub dt: Option<f64>,
    /// Length of a record, s (None: harmonic).
    pub duration: Option<f64>,
    /// Factor applied to the record to reach the chosen PGA (1: as recorded).
    pub scale: f64,
    /// The vertical component shaken with it, and its peak, g (None: horizontal only).
    pub vertical: Option<(String, f64)>,
}

impl MotionInfo {
    fn of(
        motion: &GroundMotion,
        vertical: Option<&GroundMotion>,
        duration: f64,
        scale: f64,
    ) -> Self {
        let g = crate::ground_motion::STANDARD_GRAVITY;
        let (source, dt, length) = match motion {
            GroundMotion::Record(r) => (r.provenance.clone(), Some(r.dt), Some(r.duration())),
            _ => (String::new(), None, None),
        };
        Self {
            name: motion.label(),
            source,
            pga_g: motion.peak_accel(duration) / g,
            dt,
            duration: length,
            scale,
            vertical: vertical.map(|v| (v.label(), v.peak_accel(duration) / g)),
        }
    }
}

/// The label of a sliding model with joint friction `friction`.
fn sliding_label(friction: f64) -> String {
    format!("sliding base, ρ = {}", crate::post::format_number(friction))
}

/// The exact mass-spring solution of a two-block run, sampled for plotting.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExactOverlay {
    /// Times, s.
    pub time: Vec<f64>,
    /// Slip, m.
    pub slip: Vec<f64>,
    /// Roof drift, m.
    pub drift: Vec<f64>,
    /// Absolute base acceleration, m/s².
    pub base_accel: Vec<f64>,
    /// Absolute roof acceleration, m/s².
    pub roof_accel: Vec<f64>,
}

impl SimConfig {
    /// The run specification of this configuration (the shared set-up path of the command
    /// line and the studies). A harmonic frequency is Ω/ω on a two-block scene and Hz on a
    /// building, so the scene is loaded here once and handed over.
    pub fn spec(&self) -> Result<RunSpec> {
        crate::error::require_positive("frame interval", self.frame_dt)?;
        let scene = crate::model::presets::resolve_scene(&self.scene)?;
        let excitation = match &self.excitation {
            Excitation::Scene => ExcitationSpec::Scene,
            Excitation::Record(name) => ExcitationSpec::record(name.clone()),
            Excitation::Harmonic {
                amplitude_g,
                frequency,
            } => ExcitationSpec::Harmonic {
                amplitude_g: Some(*amplitude_g),
                frequency: Some(if scene.two_block.is_some() {
                    Frequency::Ratio(*frequency)
                } else {
                    Frequency::Hz(*frequency)
                }),
            },
        };
        Ok(RunSpec {
            scene: scene.into(),
            excitation,
            alpha: self.alpha,
            friction: if self.friction_law.is_some() {
                None
            } else {
                self.friction
            },
            friction_law: self.friction_law,
            duration: self.duration,
            dt: Some(self.dt),
            integrator: self.integrator,
            pga_g: self.pga_g,
            damping: self.damping,
            bearing: self.bearing,
            vertical: self.vertical.as_ref().map(|source| VerticalSpec {
                source: source.clone(),
                scale: 1.0,
            }),
            ..RunSpec::default()
        })
    }
}

/// Builds the models of a configuration (shared by the thread, the render command and
/// tests), through the same set-up as the command line ([`RunSpec::prepare`]).
pub fn prepare(config: &SimConfig) -> Result<PreparedRun> {
    let setup = config.spec()?.prepare()?;
    let exact = exact_overlay(&setup, config.frame_dt)?;
    let motion_info = MotionInfo::of(
        &setup.motion,
        setup.vertical.as_ref(),
        setup.duration,
        setup.motion_scale,
    );
    // The models: the main one, the friction comparisons, the fixed base; each a variant
    // of the one set-up's scene.
    let radius = setup.bearing_radius;
    let main_label = match radius {
        Some(r) => format!(
            "pendulum bearings R = {} m, ρ = {}",
            crate::post::format_number(r),
            crate::post::format_number(setup.friction)
        ),
        None => sliding_label(setup.friction),
    };
    let (friction, law) = (config.friction, config.friction_law);
    let mut scenes = vec![(
        setup.scene.clone(),
        main_label,
        replay::ModelRole::Main(friction, law),
    )];
    if config.compare_flat && radius.is_some() {
        let flat = RunSpec {
            bearing: None,
            ..config.spec()?
        }
        .prepare()?;
        let label = format!(
            "flat joint, ρ = {}",
            crate::post::format_number(setup.friction)
        );
        scenes.push((flat.scene, label, replay::ModelRole::Flat(friction, law)));
    }
    for &f in &config.compare_friction {
        let scene = setup.friction_variant_scene(f)?;
        scenes.push((
            scene,
            sliding_label(f),
            replay::ModelRole::ComparedFriction(f),
        ));
    }
    if config.compare_fixed {
        let scene = setup.fixed_base_scene();
        scenes.push((
            scene,
            "fixed base".to_string(),
            replay::ModelRole::FixedBase,
        ));
    }
    let mut models = Vec::new();
    let mut labels = Vec::new();
    let mut roles = Vec::new();
    for (scene, label, role) in scenes {
        roles.push(role);
        let (dda, probe) = setup.build_dda(&scene, setup.solver_params())?;
        let ex = Extractor::new(&dda, probe.base, probe.roof);
        labels.push(label);
        models.push((dda, ex));
    }
    Ok(PreparedRun {
        scene: setup.scene,
        motion: setup.motion,
        duration: setup.duration,
        models,
        labels,
        motion_info,
        exact,
        warnings: setup.warnings,
        roles,
        replays: Vec::new(),
    })
}

/// What [`PreparedRun::advance_frames`] returns.
#[derive(Debug, Clone)]
pub struct AdvancedFrames {
    /// One frame set per frame time.
    pub frames: Vec<FrameSet>,
    /// CPU time to copy one frame set out of the solvers (all models), s.
    pub copy_s_per_frame: f64,
}

impl PreparedRun {
    /// The models' state now, as a frame set.
    pub fn frame_set(&self) -> FrameSet {
        FrameSet {
            time: self.models.first().map_or(0.0, |(d, _)| d.time()),
            models: self
                .models
                .iter()
                .map(|(d, ex)| ex.extract(d, Some(&self.motion)))
                .collect(),
        }
    }

    /// Full-rate samples holding the state now (the first row of a run).
    pub fn initial_samples(&self) -> Vec<Samples> {
        self.models
            .iter()
            .map(|(d, ex)| {
                let mut s = Samples::default();
                ex.sample(d, Some(&self.motion), &mut s);
                s
            })
            .collect()
    }

    /// Advances every model to time `t`, appending one row per solver step to `samples`.
    /// The models are independent, so each runs on its own thread; the first model's
    /// error in scene order is returned.
    pub fn advance_to(&mut self, t: f64, samples: &mut [Samples]) -> Result<()> {
        if self.replays.iter().any(Option::is_some) {
            return Err(crate::Error::Scene(
                "a run that plays a model back advances by frames only".into(),
            ));
        }
        self.on_each_model(samples, |dda, ex, s, motion| {
            dda.run_until(t, |d, _| ex.sample(d, Some(motion), s))
        })?;
        Ok(())
    }

    /// Advances every model through the frame times `times` (increasing), appending one
    /// row per solver step to `samples`, and returns a frame set at each time. Each model
    /// runs through all of them on its own thread: the threads meet once per call, not
    /// once per frame (the default scene's two frames on two cores, against one after the
    /// other: 1.4× faster with a meeting per frame, 1.8× with one per 64 frames;
    /// docs/performance-log.md).
    pub fn advance_frames(
        &mut self,
        times: &[f64],
        samples: &mut [Samples],
    ) -> Result<AdvancedFrames> {
        let per_model = self.on_each_model(samples, |dda, ex, s, motion| {
            let mut frames = Vec::with_capacity(times.len());
            let mut copy_s = 0.0;
            for &t in times {
                dda.run_until(t, |d, _| ex.sample(d, Some(motion), s))?;
                let copy = Instant::now();
                frames.push((dda.time(), ex.extract(dda, Some(motion))));
                copy_s += copy.elapsed().as_secs_f64();
            }
            Ok((frames, copy_s))
        })?;
        let per_model: Vec<_> = per_model
            .into_iter()
            .zip(samples.iter_mut())
            .enumerate()
            .map(
                |(m, (computed, s))| match (computed, self.replays.get_mut(m)) {
                    (Some(computed), _) => Ok(computed),
                    (None, Some(Some(replay))) => {
                        let frames = times.iter().map(|&t| {
                            let frame = replay.next(t, s)?;
                            Ok((frame.time, frame))
                        });
                        Ok((frames.collect::<Result<Vec<_>>>()?, 0.0))
                    }
                    (None, _) => Ok((Vec::new(), 0.0)),
                },
            )
            .collect::<Result<_>>()?;
        let copy_s: f64 = per_model.iter().map(|(_, s)| s).sum();
        let mut columns: Vec<_> = per_model
            .into_iter()
            .map(|(frames, _)| frames.into_iter())
            .collect();
        let frames = times
            .iter()
            .map(|&t| {
                let row: Vec<_> = columns.iter_mut().filter_map(Iterator::next).collect();
                FrameSet {
                    time: row.first().map_or(t, |r| r.0),
                    models: row.into_iter().map(|r| r.1).collect(),
                }
            })
            .collect();
        Ok(AdvancedFrames {
            frames,
            copy_s_per_frame: copy_s / times.len().max(1) as f64,
        })
    }

    /// Runs `work` on every model but those played back, each on its own scoped thread
    /// (the first on this one), and returns the results in scene order (None for those
    /// played back), or the first model's error in that order.
    fn on_each_model<R: Send>(
        &mut self,
        samples: &mut [Samples],
        work: impl Fn(&mut Dda, &mut Extractor, &mut Samples, &GroundMotion) -> Result<R> + Sync,
    ) -> Result<Vec<Option<R>>> {
        let motion = &self.motion;
        let work = &work;
        let replays = &self.replays;
        let played = |m: usize| replays.get(m).is_some_and(Option::is_some);
        let mut pairs = self
            .models
            .iter_mut()
            .zip(samples.iter_mut())
            .enumerate()
            .map(|(m, pair)| (!played(m)).then_some(pair));
        let Some(first) = pairs.next() else {
            return Ok(Vec::new());
        };
        std::thread::scope(|scope| {
            let others: Vec<_> = pairs
                .map(|pair| {
                    pair.map(|((dda, ex), s)| scope.spawn(move || work(dda, ex, s, motion)))
                })
                .collect();
            let mut results = vec![first.map(|((dda, ex), s)| work(dda, ex, s, motion))];
            for handle in others {
                results.push(handle.map(|h| {
                    h.join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                }));
            }
            results.into_iter().map(Option::transpose).collect()
        })
    }

    /// The message that announces this run to a UI (takes the exact overlay).
    pub fn started_message(&mut self, generation: u64, config: &SimConfig) -> SimMessage {
        SimMessage::Started {
            generation,
            config: Box::new(config.clone()),
            duration: self.duration,
            labels: self.labels.clone(),
            motion: Box::new(self.motion_info.clone()),
            exact: self.exact.take().map(Box::new),
            first: Box::new(self.frame_set()),
        }
    }
}

/// Runs a configuration to `until` (at most its duration) on this thread and returns what
/// the simulation thread would have posted: started, all frames (every `frame_dt`) with
/// their samples, finished. Pictures and videos are drawn from it as the window would.
pub fn run_to_messages(config: &SimConfig, until: f64) -> Result<Vec<SimMessage>> {
    let start = Instant::now();
    let mut run = prepare(config)?;
    let end = until.min(run.duration);
    let mut samples = run.initial_samples();
    let mut messages = vec![run.started_message(1, config)];
    let mut frames = Vec::new();
    let mut k = 1u64;
    loop {
        let t = (k as f64 * config.frame_dt).min(end);
        run.advance_to(t, &mut samples)?;
        frames.push(run.frame_set());
        if t >= end - 1e-12 {
            break;
        }
        k += 1;
    }
    messages.push(SimMessage::Frames {
        generation: 1,
        frames,
        samples,
        speed: end / start.elapsed().as_secs_f64().max(1e-9),
        time_left: None,
        extract_us: 0.0,
    });
    messages.push(SimMessage::Finished {
        generation: 1,
        wall_time_s: start.elapsed().as_secs_f64(),
        replayed_models: 0,
    });
    Ok(messages)
}

/// The exact mass-spring solution of a two-block run, sampled every `frame_dt` seconds.
fn exact_overlay(setup: &RunSetup, frame_dt: f64) -> Result<Option<ExactOverlay>> {
    let Some((roles, alpha, _)) = setup.two_block() else {
        return Ok(None);
    };
    // Damping, vertical shaking or another friction law: the stepped exact solution.
    if setup.needs_stepped_exact()
        && let Some(structure) = setup.two_block_structure()
    {
        let r = simulate_stepped(
            &structure?,
            setup.duration,
            frame_dt,
            &SteppedOptions::default(),
        )?;
        return Ok(Some(ExactOverlay {
            slip: r.slip,
            drift: r.roof_drift,
            base_accel: r.raft_accel,
            roof_accel: r.roof_accel,
            time: r.time,
        }));
    }
    let b = ShearBuilding::two_mass(alpha, roles.structure_frequency_hz, setup.friction)?;
    let r = simulate(
        &b,
        &setup.motion,
        setup.duration,
        frame_dt,
        &ExactOptions::default(),
    )?;
    Ok(Some(ExactOverlay {
        slip: r.slip.clone(),
        drift: r.storey_drift[0].clone(),
        base_accel: r.raft_accel.clone(),
        roof_accel: r.storey_accel[0].clone(),
        time: r.time,
    }))
}

/// A frame of the run: the sliding model and, if run, the fixed-base one, at the same time.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSet {
    /// Simulated time, s.
    pub time: f64,
    /// One frame per model (sliding first).
    pub models: Vec<ModelFrame>,
}

/// The wall-clock time a computing run has still to go, as the command line's progress
/// line estimates it (see [`RemainingTime`]): from the pace so far and how hard the ground
/// still has to shake.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeLeft {
    /// Seconds still to go.
    pub seconds: f64,
    /// The ground has still to shake much harder than it has so far: `seconds` is the
    /// pace so far, which the run will likely exceed (not a bound).
    pub likely_more: bool,
}

/// Messages from the simulation thread. Each carries the generation of the run it belongs
/// to, so that a UI can drop frames of a run it has already replaced.
#[derive(Debug, Clone)]
pub enum SimMessage {
    /// A run has started.
    Started {
        /// Run generation.
        generation: u64,
        /// Its configuration.
        config: Box<SimConfig>,
        /// Duration, s.
        duration: f64,
        /// Model labels ("sliding base, ρ = 0.01", "fixed base").
        labels: Vec<String>,
        /// The ground motion as run.
        motion: Box<MotionInfo>,
        /// The exact mass-spring overlay (two-block scenes).
        exact: Option<Box<ExactOverlay>>,
        /// The first frame (t = 0).
        first: Box<FrameSet>,
    },
    /// New frames, in time order.
    Frames {
        /// Run generation.
        generation: u64,
        /// Frames.
        frames: Vec<FrameSet>,
        /// Full-rate samples since the last message, one set per model.
        samples: Vec<Samples>,
        /// Simulated seconds per wall-clock second so far.
        speed: f64,
        /// The wall-clock time the run has still to go, once it has run long enough to
        /// tell (see [`TimeLeft`]).
        time_left: Option<TimeLeft>,
        /// Mean time to copy one frame set out of the solvers, µs.
        extract_us: f64,
    },
    /// The run reached its end.
    Finished {
        /// Run generation.
        generation: u64,
        /// Wall-clock time of the run, s.
        wall_time_s: f64,
        /// How many of the models were played back from the last run rather than
        /// computed (nothing they depend on changed; see [`replay`]).
        replayed_models: usize,
    },
    /// The run could not start or stopped with an error.
    Failed {
        /// Run generation.
        generation: u64,
        /// What went wrong.
        message: String,
    },
}

/// Commands to the simulation thread.
#[derive(Debug, Clone)]
pub enum SimCommand {
    /// Start (or restart) a run with this configuration.
    Run(Box<SimConfig>),
    /// Stop the thread.
    Quit,
}

/// Why the simulation thread wakes a UI after posting a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// A run started or computed more frames: worth showing at the UI's own pace.
    Progress,
    /// A run finished or failed: its whole replay (or its error) is worth showing at once.
    RunEnded,
}

/// Called by the simulation thread after it posts a message (a UI wakes up to show it).
pub type Waker = Box<dyn Fn(Wake) + Send>;

/// The UI's end of the simulation thread.
pub struct SimHandle {
    commands: Sender<SimCommand>,
    /// Messages from the thread.
    pub messages: Receiver<SimMessage>,
    thread: Option<JoinHandle<()>>,
}

impl SimHandle {
    /// Spawns the thread, idle until a [`SimCommand::Run`].
    pub fn spawn() -> Self {
        Self::spawn_with_waker(Box::new(|_| {}))
    }

    /// Spawns the thread; it calls `waker` after each message it posts, so that a UI
    /// that only repaints on demand shows new frames at once.
    pub fn spawn_with_waker(waker: Waker) -> Self {
        let (commands, command_rx) = channel();
        let (message_tx, messages) = channel();
        let thread = std::thread::Builder::new()
            .name("slidebase-sim".into())
            .spawn(move || {
                sim_thread(
                    command_rx,
                    Outbox {
                        tx: message_tx,
                        waker,
                    },
                )
            })
            .ok();
        Self {
            commands,
            messages,
            thread,
        }
    }

    /// Sends a command; returns false if the thread is gone.
    pub fn send(&self, command: SimCommand) -> bool {
        self.commands.send(command).is_ok()
    }
}

impl Drop for SimHandle {
    fn drop(&mut self) {
        let _ = self.commands.send(SimCommand::Quit);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The thread's end of the message channel.
struct Outbox {
    tx: Sender<SimMessage>,
    waker: Waker,
}

impl Outbox {
    fn send(&self, msg: SimMessage) -> std::result::Result<(), ()> {
        let wake = match msg {
            SimMessage::Finished { .. } | SimMessage::Failed { .. } => Wake::RunEnded,
            SimMessage::Started { .. } | SimMessage::Frames { .. } => Wake::Progress,
        };
        let sent = self.tx.send(msg).map_err(|_| ());
        (self.waker)(wake);
        sent
    }
}

fn sim_thread(commands: Receiver<SimCommand>, out: Outbox) {
    let mut generation = 0u64;
    let mut pending: Option<SimConfig> = None;
    let mut kept = KeptModels::default();
    loop {
        let config = match pending.take() {
            Some(c) => c,
            None => match commands.recv() {
                Ok(SimCommand::Run(c)) => *c,
                Ok(SimCommand::Quit) | Err(_) => return,
            },
        };
        generation += 1;
        match run_one(generation, &config, &commands, &out, &mut kept) {
            RunEnd::Finished | RunEnd::Failed => {}
            RunEnd::Replaced(next) => pending = Some(*next),
            RunEnd::Quit => return,
        }
    }
}

/// The models of the last finished run, by what each depends on (see [`replay`]).
#[derive(Default)]
struct KeptModels {
    kept: Vec<(replay::ModelKey, Arc<replay::Recording>)>,
}

impl KeptModels {
    /// Sets `run` to play back each model kept under its key, and returns, per model, a
    /// recording to fill as it is computed (None for those played back).
    fn apply(&self, config: &SimConfig, run: &mut PreparedRun) -> Vec<Option<replay::Recording>> {
        let keys = run
            .roles
            .iter()
            .map(|r| replay::ModelKey::new(config, r.clone()));
        run.replays = keys
            .map(|key| {
                let kept = self.kept.iter().find(|(k, _)| *k == key);
                kept.map(|(_, recording)| replay::Replay::new(Arc::clone(recording)))
            })
            .collect();
        run.replays
            .iter()
            .map(|r| r.is_none().then(replay::Recording::default))
            .collect()
    }

    /// Keeps the models of a finished run of `config`: those played back and those
    /// recorded in full.
    fn keep(
        &mut self,
        config: &SimConfig,
        run: &PreparedRun,
        recordings: Vec<Option<replay::Recording>>,
    ) {
        let models = run.roles.iter().zip(&run.replays).zip(recordings);
        self.kept = models
            .filter_map(|((role, played), recorded)| {
                let recording = match (played, recorded) {
                    (Some(replay), _) => Arc::clone(replay.recording()),
                    (None, Some(recorded)) => Arc::new(recorded),
                    (None, None) => return None,
                };
                Some((replay::ModelKey::new(config, role.clone()), recording))
            })
            .collect();
    }
}

/// The time left of a run in the window: [`RemainingTime`] fed every
/// [`TimeLeftEstimate::EVERY_S`] from [`TimeLeftEstimate::FIRST_AFTER_S`] on, timed from the
/// first step (the set-up before it, seconds for a large wall settling under gravity, is no
/// part of the pace).
struct TimeLeftEstimate {
    stepping_since: Instant,
    next_observation_s: f64,
    /// Built at the first observation: a short run never samples its motion.
    remaining: Option<RemainingTime>,
    last: Option<TimeLeft>,
}

impl TimeLeftEstimate {
    /// Wall-clock time a run must have taken before its time left is estimated, s: a
    /// shorter run is over before an estimate would help.
    const FIRST_AFTER_S: f64 = 2.0;
    /// How often the estimate takes in the run's pace, s of wall-clock time.
    const EVERY_S: f64 = 1.0;

    fn new(stepping_since: Instant) -> Self {
        Self {
            stepping_since,
            next_observation_s: Self::FIRST_AFTER_S,
            remaining: None,
            last: None,
        }
    }

    /// The time left with the run at simulated time `t` (the last estimate between
    /// observations).
    fn observe(&mut self, run: &PreparedRun, t: f64) -> Option<TimeLeft> {
        let elapsed_s = self.stepping_since.elapsed().as_secs_f64();
        if elapsed_s < self.next_observation_s || t >= run.duration {
            return self.last.filter(|_| t < run.duration);
        }
        self.next_observation_s = elapsed_s + Self::EVERY_S;
        let remaining = self
            .remaining
            .get_or_insert_with(|| RemainingTime::new(&run.motion, run.duration));
        self.last = remaining.observe(t, elapsed_s).map(|seconds| TimeLeft {
            seconds,
            likely_more: remaining.harder_shaking_ahead(t),
        });
        self.last
    }
}

enum RunEnd {
    Finished,
    Failed,
    Replaced(Box<SimConfig>),
    Quit,
}

fn run_one(
    generation: u64,
    config: &SimConfig,
    commands: &Receiver<SimCommand>,
    out: &Outbox,
    kept: &mut KeptModels,
) -> RunEnd {
    let start = Instant::now();
    let mut run = match prepare(config) {
        Ok(r) => r,
        Err(e) => {
            let _ = out.send(SimMessage::Failed {
                generation,
                message: e.to_string(),
            });
            return RunEnd::Failed;
        }
    };
    let mut recordings = kept.apply(config, &mut run);
    let replayed = run.replays.iter().filter(|r| r.is_some()).count();
    let mut samples = run.initial_samples();
    let _ = out.send(run.started_message(generation, config));
    let mut batch = Vec::new();
    let mut last_send = Instant::now();
    let (mut copy_total, mut copies) = (0.0, 0u64);
    let mut next_frame = 1u64;
    let mut chunk = FrameChunk::new();
    let mut time_left = TimeLeftEstimate::new(Instant::now());
    loop {
        // Commands first: a new run replaces this one at once.
        match commands.try_recv() {
            Ok(SimCommand::Run(c)) => return RunEnd::Replaced(c),
            Ok(SimCommand::Quit) | Err(TryRecvError::Disconnected) => return RunEnd::Quit,
            Err(TryRecvError::Empty) => {}
        }
        let times = chunk.times(next_frame, config.frame_dt, run.duration);
        let t_chunk = Instant::now();
        match run.advance_frames(&times, &mut samples) {
            Ok(advanced) => {
                for (m, recording) in recordings.iter_mut().enumerate() {
                    if recording
                        .as_mut()
                        .is_some_and(|r| !r.add_frames(&advanced.frames, m))
                    {
                        *recording = None;
                    }
                }
                batch.extend(advanced.frames);
                copy_total += advanced.copy_s_per_frame;
                copies += 1;
            }
            Err(e) => {
                let _ = out.send(SimMessage::Failed {
                    generation,
                    message: e.to_string(),
                });
                return RunEnd::Failed;
            }
        }
        chunk.took(t_chunk.elapsed());
        next_frame += times.len() as u64;
        let target = times.last().copied().unwrap_or(run.duration);
        let done = target >= run.duration - 1e-12;
        if done || last_send.elapsed() > Duration::from_millis(30) {
            let speed = target / start.elapsed().as_secs_f64().max(1e-9);
            let left = time_left.observe(&run, target);
            let extract_us = 1e6 * copy_total / copies.max(1) as f64;
            let frames = std::mem::take(&mut batch);
            let fresh: Vec<Samples> = samples.iter_mut().map(std::mem::take).collect();
            for (recording, rows) in recordings.iter_mut().zip(&fresh) {
                if let Some(r) = recording {
                    r.add_samples(rows);
                }
            }
            if out
                .send(SimMessage::Frames {
                    generation,
                    frames,
                    samples: fresh,
                    speed,
                    time_left: left,
                    extract_us,
                })
                .is_err()
            {
                return RunEnd::Quit;
            }
            last_send = Instant::now();
        }
        if done {
            kept.keep(config, &run, recordings);
            let _ = out.send(SimMessage::Finished {
                generation,
                wall_time_s: start.elapsed().as_secs_f64(),
                replayed_models: replayed,
            });
            return RunEnd::Finished;
        }
    }
}

/// How many frames the simulation thread computes between two looks at its commands:
/// the models' threads meet once per chunk, so a chunk should be long enough that the
/// meeting costs little, and short enough that a new run (a slider dragged) replaces this
/// one within a few hundredths of a second. Adapted to the measured time of the last one.
struct FrameChunk {
    frames: u64,
}

impl FrameChunk {
    /// A chunk of at most this long, s (the UI's batch interval).
    const TARGET: Duration = Duration::from_millis(20);
    /// Frames per chunk at most (a model that computes fast).
    const MAX_FRAMES: u64 = 64;

    fn new() -> Self {
        Self { frames: 1 }
    }

    /// The frame times of the next chunk, from frame number `first` (1-based, frame k at
    /// k·`frame_dt`), the last one clipped to `duration`.
    fn times(&self, first: u64, frame_dt: f64, duration: f64) -> Vec<f64> {
        let mut times = Vec::with_capacity(self.frames as usize);
        for k in first..first + self.frames {
            let t = (k as f64 * frame_dt).min(duration);
            times.push(t);
            if t >= duration - 1e-12 {
                break;
            }
        }
        times
    }

    /// Grows the chunk while chunks take less than half the target, shrinks it while
    /// they take more than the target.
    fn took(&mut self, elapsed: Duration) {
        if elapsed < Self::TARGET / 2 {
            self.frames = (self.frames * 2).min(Self::MAX_FRAMES);
        } else if elapsed > Self::TARGET {
            self.frames = (self.frames / 2).max(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_chunks_grow_when_fast_shrink_when_slow_and_stop_at_the_end() {
        let mut chunk = FrameChunk::new();
        assert_eq!(chunk.times(1, 0.01, 10.0), vec![0.01]);
        for _ in 0..10 {
            chunk.took(Duration::from_millis(1));
        }
        assert_eq!(chunk.frames, FrameChunk::MAX_FRAMES);
        chunk.took(Duration::from_millis(50));
        assert_eq!(chunk.frames, FrameChunk::MAX_FRAMES / 2);
        // Frame k at k·Δt (not a running sum); the last one clipped to the duration.
        let times = chunk.times(995, 0.01, 10.0);
        assert_eq!(times.len(), 6);
        assert_eq!(times[0], 995.0 * 0.01);
        assert_eq!(*times.last().unwrap(), 10.0);
    }

    /// A UI is woken after every message: at its own pace for a start or new frames, at
    /// once for the end of a run (a finished replay should not wait for the next paced
    /// frame).
    #[test]
    fn the_end_of_a_run_wakes_at_once_and_progress_at_the_ui_pace() {
        let (wake_tx, wakes) = channel();
        let handle = SimHandle::spawn_with_waker(Box::new(move |wake| {
            let _ = wake_tx.send(wake);
        }));
        let config = SimConfig {
            scene: "two-block".into(),
            duration: Some(0.3),
            frame_dt: 0.05,
            ..SimConfig::default()
        };
        assert!(handle.send(SimCommand::Run(Box::new(config))));
        let mut expected = Vec::new();
        loop {
            let msg = handle
                .messages
                .recv_timeout(Duration::from_secs(60))
                .unwrap();
            let ended = matches!(msg, SimMessage::Finished { .. } | SimMessage::Failed { .. });
            expected.push(if ended {
                Wake::RunEnded
            } else {
                Wake::Progress
            });
            if ended {
                break;
            }
        }
        let woken: Vec<Wake> = (0..expected.len())
            .map(|_| wakes.recv_timeout(Duration::from_secs(60)).unwrap())
            .collect();
        assert_eq!(woken, expected);
        assert!(
            expected.len() >= 3,
            "a start, frames and the end: {expected:?}"
        );
    }

    /// The thread publishes a started message, frames in time order up to the duration,
    /// and a finished message; a new Run replaces the current one.
    #[test]
    fn thread_runs_and_restarts() {
        let handle = SimHandle::spawn();
        let config = SimConfig {
            scene: "two-block".into(),
            excitation: Excitation::Harmonic {
                amplitude_g: 0.3,
                frequency: 1.0,
            },
            duration: Some(0.5),
            frame_dt: 0.05,
            ..SimConfig::default()
        };
        assert!(handle.send(SimCommand::Run(Box::new(config.clone()))));
        let mut times = Vec::new();
        let mut started = false;
        loop {
            match handle
                .messages
                .recv_timeout(Duration::from_secs(60))
                .unwrap()
            {
                SimMessage::Started {
                    generation,
                    first,
                    labels,
                    exact,
                    ..
                } => {
                    assert_eq!(generation, 1);
                    assert_eq!(labels.len(), 2);
                    assert!(exact.is_some());
                    assert_eq!(first.time, 0.0);
                    started = true;
                }
                SimMessage::Frames { frames, .. } => times.extend(frames.iter().map(|f| f.time)),
                SimMessage::Finished { .. } => break,
                SimMessage::Failed { message, .. } => panic!("{message}"),
            }
        }
        assert!(started);
        assert_eq!(times.len(), 10);
        assert!((times[9] - 0.5).abs() < 1e-9);
        assert!(times.windows(2).all(|w| w[1] > w[0]));
        // A bad configuration is reported, not a panic.
        let bad = SimConfig {
            friction: Some(-1.0),
            ..config
        };
        assert!(handle.send(SimCommand::Run(Box::new(bad))));
        match handle
            .messages
            .recv_timeout(Duration::from_secs(60))
            .unwrap()
        {
            SimMessage::Failed {
                generation,
                message,
            } => {
                assert_eq!(generation, 2);
                assert!(message.contains("friction"));
            }
            other => panic!("expected a failure, got {other:?}"),
        }
    }

    /// Everything a finished run posted: its frames, each model's samples (the first row
    /// included) and how many models were played back.
    fn posted(handle: &SimHandle, config: &SimConfig) -> (Vec<FrameSet>, Vec<Samples>, usize) {
        assert!(handle.send(SimCommand::Run(Box::new(config.clone()))));
        let (mut frames, mut samples) = (Vec::new(), Vec::new());
        loop {
            match handle
                .messages
                .recv_timeout(Duration::from_secs(120))
                .unwrap()
            {
                SimMessage::Started { .. } => {}
                SimMessage::Frames {
                    frames: f,
                    samples: mut s,
                    ..
                } => {
                    frames.extend(f);
                    samples.resize_with(s.len(), Samples::default);
                    for (all, new) in samples.iter_mut().zip(&mut s) {
                        all.append(new);
                    }
                }
                SimMessage::Finished {
                    replayed_models, ..
                } => return (frames, samples, replayed_models),
                SimMessage::Failed { message, .. } => panic!("{message}"),
            }
        }
    }

    /// Runs `config` on the thread and checks that every model's frames and samples are
    /// what computing the run on its own gives, to the bit; returns how many models the
    /// thread played back.
    fn played_back(handle: &SimHandle, config: &SimConfig) -> usize {
        let (frames, samples, replayed) = posted(handle, config);
        let computed = run_to_messages(config, f64::INFINITY).unwrap();
        let Some(SimMessage::Frames {
            frames: own_frames,
            samples: own_samples,
            ..
        }) = computed.into_iter().nth(1)
        else {
            panic!("no frames");
        };
        assert_eq!(frames.len(), 12, "{config:?}");
        for (posted, own) in frames.iter().zip(&own_frames) {
            assert!(
                posted.models == own.models,
                "frames differ at {}: {config:?}",
                own.time
            );
        }
        assert!(samples == own_samples, "samples differ: {config:?}");
        replayed
    }

    /// A model is played back from the last run when nothing it depends on changed —
    /// the fixed base when a friction changes, a compared friction's model when the main
    /// friction changes — and what the UI gets is what computing the run gives, to the
    /// bit: every frame of every model and the samples of every step. A change of the
    /// shared settings (the record's scale) computes every model again.
    #[test]
    fn models_are_played_back_when_nothing_they_depend_on_changed() {
        let handle = SimHandle::spawn();
        let first = SimConfig {
            duration: Some(0.6),
            frame_dt: 0.05,
            ..SimConfig::default()
        };
        assert_eq!(played_back(&handle, &first), 0, "nothing to play back yet");
        let other_friction = SimConfig {
            friction: Some(0.05),
            ..first.clone()
        };
        assert_eq!(played_back(&handle, &other_friction), 1, "the fixed base");
        let other_law = SimConfig {
            friction_law: Some(crate::model::friction::Friction::StaticKinetic {
                stick: 0.15,
                slide: 0.1,
            }),
            ..first.clone()
        };
        assert_eq!(played_back(&handle, &other_law), 1, "the fixed base");
        let scaled = SimConfig {
            pga_g: Some(0.3),
            ..other_friction
        };
        assert_eq!(played_back(&handle, &scaled), 0, "a new scale");
        let compared = SimConfig {
            compare_friction: vec![0.05, 0.2],
            ..first.clone()
        };
        assert_eq!(played_back(&handle, &compared), 0, "new shared settings");
        let main_dragged = SimConfig {
            friction: Some(0.02),
            ..compared.clone()
        };
        assert_eq!(
            played_back(&handle, &main_dragged),
            3,
            "all but the main model"
        );
        let compared_dragged = SimConfig {
            compare_friction: vec![0.05, 0.3],
            ..main_dragged
        };
        assert_eq!(
            played_back(&handle, &compared_dragged),
            3,
            "all but ρ = 0.3's"
        );
    }
}
