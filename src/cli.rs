//! Command-line definitions (clap) and the glue from flags to the headless functions.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};

use slidebase::dda::Integrator;
use slidebase::headless::run::{OUTPUT_HISTORY, run_setup, write_outputs};
use slidebase::headless::sweep::{SweepRequest, parse_list, parse_ratios, parse_shard, run_sweep};
use slidebase::model::friction::Friction;
use slidebase::model::scene::GroundKind;
use slidebase::post::output::Staged;
use slidebase::setup::{
    ExcitationSpec, Frequency, HistoryPlan, ModelKind, RunSpec, SceneRoles, VerticalSpec,
};

/// Buildings on a sliding (friction) base under earthquakes, computed with Discontinuous
/// Deformation Analysis and checked against the exact mass-spring solution.
#[derive(Debug, Parser)]
#[command(name = "slidebase", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run one simulation and print its peak responses.
    Run(RunArgs),
    /// Run both models over the paper's grid (Figs 4–9) and plot the comparison.
    Sweep(SweepArgs),
    /// Natural frequencies and mode shapes of a building scene (fixed base).
    Modes(ModesArgs),
    /// The paper's seismic case: sliding against fixed base, figures like Figs 10–18.
    Report(ReportArgs),
    /// Render the scene at one instant into a PNG, or a replay into an MP4/GIF (offscreen,
    /// the visualizer's renderer; --data also writes the plotted data as CSV).
    Render(RenderArgs),
    /// Error against run time: time step, integrator, penalty and ground model.
    Accuracy(AccuracyArgs),
    /// Stiff and extreme cases, each checked against a physical fact.
    Stability(StabilityArgs),
    /// Benchmarks: the paper's runs, the Figs 4–9 sweep and a scaling series.
    Bench(BenchArgs),
    /// Join the sweep.csv files of sweep shards (`sweep --shard I/N`) into one sweep.
    Merge(MergeArgs),
    /// List the built-in scenes and ground-motion records.
    List,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum ModelArg {
    /// Discontinuous Deformation Analysis of the blocks.
    Dda,
    /// The exact solution of the paper's mass-spring model (Appendix I).
    MassSpring,
}

impl From<ModelArg> for ModelKind {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Dda => ModelKind::Dda,
            ModelArg::MassSpring => ModelKind::MassSpring,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum GroundArg {
    /// The ground follows the record exactly (default; no finite-mass error).
    Prescribed,
    /// The paper's large ground mass driven by m_g·ü0 (eq. 4).
    LargeMass,
}

#[derive(Debug, clap::Args)]
struct RunArgs {
    /// Built-in scene (`two-block`, `three-storey`, `block`: Newmark's sliding block;
    /// `slidebase list` names them all), a generated one (`friction-pendulum`, `frame:N`,
    /// `wall:N`) or a scene TOML file.
    #[arg(long, default_value = "two-block")]
    scene: String,
    /// Mass ratio α = m/(M + m) of roof to total mass, in (0, 1) (two-block scenes;
    /// default: the scene's, 0.5).
    #[arg(long, allow_hyphen_values = true)]
    alpha: Option<f64>,
    /// Friction coefficient ρ of the sliding joint, in [0, 1000] (default: the scene's).
    #[arg(long, allow_hyphen_values = true)]
    friction: Option<f64>,
    /// Friction law of the sliding joint: coulomb:MU | static-kinetic:MU_S,MU_K |
    /// velocity:MU_SLOW,MU_FAST,RATE (μ(v) = MU_FAST − (MU_FAST − MU_SLOW)·exp(−RATE·|v|),
    /// v in m/s, RATE in s/m); DDA and the exact model alike (default: the scene's). See
    /// docs/friction-laws.md.
    #[arg(long = "friction-law", conflicts_with = "friction")]
    friction_law: Option<Friction>,
    /// Excitation frequency over the structure frequency, Ω/ω (two-block scenes; default:
    /// the scene's, 1).
    #[arg(
        long = "freq-ratio",
        allow_hyphen_values = true,
        conflicts_with = "record"
    )]
    freq_ratio: Option<f64>,
    /// Amplitude of the harmonic ground acceleration, g (default: the scene's, 0.3).
    #[arg(
        long = "amplitude-g",
        allow_hyphen_values = true,
        conflicts_with = "record"
    )]
    amplitude_g: Option<f64>,
    #[command(flatten)]
    stepping: Stepping,
    /// Which model computes the response.
    #[arg(long, value_enum, default_value = "dda")]
    model: ModelArg,
    /// Fix the base: the sliding joint never slides.
    #[arg(long, conflicts_with_all = ["friction", "friction_law"])]
    fixed_base: bool,
    /// Ground-motion record (built-in name or AT2/CSV file) instead of harmonic input.
    #[arg(long)]
    record: Option<String>,
    /// Shake the ground vertically too, by this record (a vertical component, up
    /// positive: `el-centro-up`, or an AT2/CSV file; default: the scene's, if any). The
    /// normal force, and with it the friction capacity, follows N = m(g + a_v).
    #[arg(long)]
    vertical_record: Option<String>,
    /// Factor on the vertical record's accelerations (default 1).
    #[arg(long, requires = "vertical_record", allow_hyphen_values = true)]
    vertical_scale: Option<f64>,
    /// Structural damping ratio ζ, e.g. 0.05, in DDA and the exact model alike; sliding is
    /// never damped. Two-block scenes: a dashpot c = 2ζ√(k m) beside the spring. Frames
    /// (three-storey, frame:N): Rayleigh damping, ζ at the first two fixed-base modes.
    #[arg(long, allow_hyphen_values = true)]
    damping: Option<f64>,
    /// The bearing under a frame's base slab: flat (the paper's Coulomb joint, default) or
    /// pendulum:R (two friction-pendulum bearings of effective radius R m, 0.5 to 20; the
    /// exact model is then the linearised bearing, a restoring force W·x/R).
    #[arg(long, value_name = "flat|pendulum:R")]
    bearing: Option<String>,
    /// Effective radius R of the friction pendulum's dish, m (`--scene friction-pendulum`
    /// only; default 2): the radius the slider's centroid travels on, so that its small
    /// free oscillations take 2π√(R/g).
    #[arg(long, allow_hyphen_values = true)]
    radius: Option<f64>,
    /// Ground model of the DDA run (default: the scene's).
    #[arg(long, value_enum)]
    ground: Option<GroundArg>,
    /// Write time histories (CSV) and the summary (JSON) into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
}

/// The time stepping of runs (`run` and `sweep`).
#[derive(Debug, clap::Args)]
struct Stepping {
    /// Duration of a run, s (default: 100 s for harmonic input, as every sweep's; for a
    /// `run` on a record, the record's length).
    #[arg(long, allow_hyphen_values = true)]
    duration: Option<f64>,
    /// Time step of the DDA model, s (default 1e-3).
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// DDA integrator: classic | trapezoidal | hht[:α] | generalized-alpha[:ρ∞] (default:
    /// the scene's — generalized-alpha:0.5 for two-block, generalized-alpha:0 otherwise).
    #[arg(long)]
    integrator: Option<String>,
    /// Run even if a run is larger than the limit of 1e8 steps.
    #[arg(long)]
    confirm_large: bool,
}

impl Stepping {
    /// The integrator, parsed.
    fn integrator(&self) -> Result<Option<Integrator>> {
        self.integrator
            .as_deref()
            .map(|text| Integrator::parse(text).with_context(|| format!("--integrator {text}")))
            .transpose()
    }
}

#[derive(Debug, clap::Args)]
struct StabilityArgs {
    /// Output folder.
    #[arg(long, default_value = "out/stability")]
    out: PathBuf,
    /// Leave out the slow cases (the 1000 s run).
    #[arg(long)]
    quick: bool,
}

#[derive(Debug, clap::Args)]
struct AccuracyArgs {
    /// Output folder.
    #[arg(long, default_value = "out/accuracy")]
    out: PathBuf,
    /// A small version of the study (seconds instead of minutes).
    #[arg(long)]
    quick: bool,
}

#[derive(Debug, clap::Args)]
struct RenderArgs {
    /// Scene (built-in name, frame:N, wall:N or a TOML file).
    #[arg(long, default_value = "three-storey")]
    scene: String,
    /// Record (built-in name or file; default: the scene's).
    #[arg(long)]
    record: Option<String>,
    /// Scale the record to this peak ground acceleration, g.
    #[arg(long, allow_hyphen_values = true)]
    pga: Option<f64>,
    /// Friction coefficient of the sliding joint.
    #[arg(long, allow_hyphen_values = true)]
    friction: Option<f64>,
    /// Also show the sliding model with these friction coefficients (comma-separated).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    compare_friction: Vec<f64>,
    /// Simulated time to show in a picture, s.
    #[arg(long, allow_hyphen_values = true)]
    time: Option<f64>,
    /// A replay (--out .mp4 or .gif): first frame, simulated s.
    #[arg(long, allow_hyphen_values = true)]
    from: Option<f64>,
    /// A replay: last frame, simulated s (default: the end of the record).
    #[arg(long, allow_hyphen_values = true)]
    to: Option<f64>,
    /// A replay: frames per simulated second (played back in real time).
    #[arg(long, allow_hyphen_values = true)]
    fps: Option<f64>,
    /// Output: a PNG picture, or a replay (.mp4 through ffmpeg, else .gif).
    #[arg(long, default_value = "frame.png")]
    out: PathBuf,
    /// Also write the plots' data at the time shown: DIR/series.csv and DIR/spectrum.csv.
    #[arg(long)]
    data: Option<PathBuf>,
    /// Width, pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Height, pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Deformation exaggeration factor (default: automatic, as in the window).
    #[arg(long, allow_hyphen_values = true)]
    exaggeration: Option<f64>,
    /// Only the sliding model (no fixed-base panel beside it).
    #[arg(long)]
    single: bool,
    /// No joint close-ups under the models.
    #[arg(long)]
    no_close_ups: bool,
}

#[derive(Debug, clap::Args)]
struct ReportArgs {
    /// Building scene (built-in name or TOML file).
    #[arg(long, default_value = "three-storey")]
    scene: String,
    /// Ground-motion record (default: the scene's, El Centro 1940 NS).
    #[arg(long)]
    record: Option<String>,
    /// Friction coefficient of the sliding joint (default: the scene's, 0.01).
    #[arg(long, allow_hyphen_values = true)]
    friction: Option<f64>,
    /// Time step, s (default 1e-3).
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// Duration, s (default: the record's length).
    #[arg(long, allow_hyphen_values = true)]
    duration: Option<f64>,
    /// Output folder.
    #[arg(long, default_value = "out/report")]
    out: PathBuf,
    /// Run even if a run is larger than the limit of 1e8 steps.
    #[arg(long)]
    confirm_large: bool,
}

#[derive(Debug, clap::Args)]
struct ModesArgs {
    /// Built-in scene name or a scene TOML file (a building scene).
    #[arg(long, default_value = "three-storey")]
    scene: String,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct SweepArgs {
    /// Mass ratios α, comma-separated.
    #[arg(long, default_value = "0.1,0.5,0.9", allow_hyphen_values = true)]
    alpha: String,
    /// Friction coefficients ρ, comma-separated.
    #[arg(long, default_value = "0.01,0.05,0.1,0.25", allow_hyphen_values = true)]
    friction: String,
    /// Frequency ratios: `paper` (the paper's 25 log-spaced ratios from 0.1 to 10, with the
    /// three nearest to 0.5, 2 and 5 moved onto them), `lo:hi:n` (log-spaced) or a
    /// comma-separated list.
    #[arg(long = "freq-ratios", default_value = "paper")]
    freq_ratios: String,
    /// Amplitude of the harmonic ground acceleration, g.
    #[arg(
        long = "amplitude-g",
        default_value_t = 0.3,
        allow_hyphen_values = true
    )]
    amplitude_g: f64,
    /// Structural damping ratio ζ of every run, 0 to 0.99: a dashpot c = 2ζ√(k m) beside
    /// the structure's spring, in DDA and in the exact model alike (the sliding is never
    /// damped).
    #[arg(long, allow_hyphen_values = true)]
    damping: Option<f64>,
    #[command(flatten)]
    stepping: Stepping,
    /// Output folder for sweep.csv and the figures.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Run only slice I of N of the grid (e.g. `--shard $SLURM_ARRAY_TASK_ID/16`); join
    /// the slices' sweep.csv files with `slidebase merge`.
    #[arg(long)]
    shard: Option<String>,
}

#[derive(Debug, clap::Args)]
struct BenchArgs {
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
    /// Fewer repeats, shorter windows, a smaller scaling series and sweep (about a minute).
    #[arg(long)]
    quick: bool,
    /// Repeats of each timed run, 1 to 1000 (the median is reported; default 5, 3 with
    /// --quick).
    #[arg(long)]
    repeat: Option<usize>,
    /// Threads for the sweep (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Leave out the Figs 4–9 sweep.
    #[arg(long)]
    no_sweep: bool,
    /// Leave out the scaling series.
    #[arg(long)]
    no_scaling: bool,
    /// Also write bench.json, scaling.csv and scaling.png here.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct MergeArgs {
    /// The shards' sweep.csv files.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output folder for the joined sweep.csv, the figures and errors.md.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
}

/// Entry point of the binary.
pub fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Some(Command::Run(args)) => cmd_run(args),
        Some(Command::Sweep(args)) => cmd_sweep(args),
        Some(Command::Modes(args)) => cmd_modes(args),
        Some(Command::Report(args)) => cmd_report(args),
        Some(Command::Render(args)) => cmd_render(args),
        Some(Command::Accuracy(args)) => cmd_accuracy(args),
        Some(Command::Stability(args)) => cmd_stability(args),
        Some(Command::Bench(args)) => cmd_bench(args),
        Some(Command::Merge(args)) => cmd_merge(args),
        Some(Command::List) => cmd_list(),
        None => cmd_default(),
    }
}

/// Prints a line to stdout, treating a closed pipe (`| head`) as the end of output.
fn out(line: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match writeln!(stdout, "{line}") {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.context("writing to stdout"),
    }
}

/// The scene `--scene` names, with the friction pendulum's `--radius` applied.
fn scene_name(args: &RunArgs) -> Result<String> {
    let Some(radius) = args.radius else {
        return Ok(args.scene.clone());
    };
    if args.scene != slidebase::model::pendulum::NAME {
        return Err(slidebase::Error::invalid(
            "--radius",
            format!(
                "sets the dish radius of --scene {name} (or spell the scene {name}:R); \
                 '{}' is not that scene",
                args.scene,
                name = slidebase::model::pendulum::NAME
            ),
        )
        .into());
    }
    Ok(format!("{}:{radius}", args.scene))
}

/// The run specification of `run`'s flags (every check is the set-up's, shared with the
/// visualizer and the studies).
fn run_spec(args: &RunArgs) -> Result<RunSpec> {
    let integrator = args.stepping.integrator()?;
    let excitation = match &args.record {
        Some(name) => ExcitationSpec::record(name.clone()),
        None if args.amplitude_g.is_some() || args.freq_ratio.is_some() => {
            ExcitationSpec::Harmonic {
                amplitude_g: args.amplitude_g,
                frequency: args.freq_ratio.map(Frequency::Ratio),
            }
        }
        None => ExcitationSpec::Scene,
    };
    Ok(RunSpec {
        scene: scene_name(args)?.into(),
        model: args.model.into(),
        excitation,
        vertical: args.vertical_record.as_ref().map(|source| VerticalSpec {
            source: source.clone(),
            scale: args.vertical_scale.unwrap_or(1.0),
        }),
        alpha: args.alpha,
        friction: args.friction,
        friction_law: args.friction_law,
        fixed_base: args.fixed_base,
        damping: args.damping,
        bearing: args
            .bearing
            .as_deref()
            .map(slidebase::model::bearing::Bearing::parse)
            .transpose()?,
        pga_g: None,
        ground: args.ground.map(|g| match g {
            GroundArg::Prescribed => GroundKind::Prescribed,
            GroundArg::LargeMass => GroundKind::LargeMass,
        }),
        duration: args.stepping.duration,
        dt: args.stepping.dt,
        integrator,
        history: HistoryPlan::PeaksOnly,
        confirm_large: args.stepping.confirm_large,
    })
}

fn cmd_run(args: RunArgs) -> Result<()> {
    let mut setup = run_spec(&args)?.prepare()?;
    // A run that takes a while says how far it has come (on stderr: the results and the
    // JSON stay alone on stdout).
    setup.progress = Some(slidebase::setup::ProgressReporter::new(5.0, 5.0, |p| {
        eprintln!("run: {p}");
    }));
    // The set-up's warnings (a ground too fast for the step, a coarse Δt…) come before the
    // run, which they may make long; the summary (and the JSON) carries them too.
    warn(&setup.warnings);
    if let Some(dir) = &args.out {
        // A bad folder is reported now, not after the run.
        slidebase::post::output::prepare_outputs(
            dir,
            "--out",
            &slidebase::headless::run::OUTPUT_FILES,
        )?;
        setup.history = if setup.two_block().is_some() {
            OUTPUT_HISTORY
        } else {
            HistoryPlan::EverySteps(1)
        };
    }
    match setup.roles {
        SceneRoles::TwoBlock { .. } => {}
        SceneRoles::Building(_) => return cmd_run_frame(&args, &setup),
        SceneRoles::Block(_) => return cmd_run_block(&args, &setup),
    }
    let outcome = run_setup(&setup)?;
    if let Some(dir) = &args.out {
        let overlays = slidebase::headless::run::standard_overlays(&setup)?;
        list_written(write_outputs(&outcome, &overlays, dir)?, args.json)?;
    }
    let s = &outcome.summary;
    if args.json {
        return out(&serde_json::to_string(s)?);
    }
    warn_after_run(&s.warnings, &setup.warnings);
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.4}"));
    out(&format!(
        "{} ({}), α = {}, {}, {}{}, {} s",
        s.scene,
        s.model,
        s.alpha,
        match (&s.friction_law, s.friction) {
            (Some(law), _) => format!("friction {law}"),
            (None, Some(f)) => format!("ρ = {f}"),
            (None, None) => "ρ = ∞ (fixed base)".into(),
        },
        s.excitation,
        with_vertical(
            &s.freq_ratio
                .map_or(String::new(), |r| format!(" Ω/ω = {r:.4}")),
            s.vertical_record.as_deref()
        ),
        seconds(s.duration_s)
    ))?;
    out(&format!(
        "  |u_s|max/D        {}   ({:.4e} m)",
        opt(s.us_max_over_d),
        s.us_max_m
    ))?;
    out(&format!(
        "  |u_r|max/D        {}   ({:.4e} m)",
        opt(s.ur_max_over_d),
        s.ur_max_m
    ))?;
    out(&format!(
        "  |a_base|max/a_g   {}",
        opt(s.abase_over_aground)
    ))?;
    out(&format!(
        "  |a_roof|max/a_g   {}",
        opt(s.aroof_over_aground)
    ))?;
    out(&format!("  residual slip     {:.4e} m", s.residual_slip_m))?;
    out(&match &s.solver {
        Some(c) => format!(
            "  {} steps, {} open-close passes, {} Δt cuts, max penetration {:.2e} of size",
            s.steps, c.open_close_passes, c.dt_cuts, c.max_penetration_ratio
        ),
        None => format!("  {} propagation steps", s.steps),
    })?;
    out(&format!(
        "  energy: input {:.4e} J/m, friction {:.4e} J/m, residual {:.2e} (relative)",
        s.input_work_j, s.friction_dissipated_j, s.energy_residual_rel
    ))?;
    out(&format!("  wall time {:.3} s", s.wall_time_s))
}

/// The thread count of `--jobs`: 1 to [`MAX_JOBS`], or all cores when not given.
fn jobs(jobs: Option<usize>) -> Result<usize> {
    use slidebase::limits::MAX_JOBS;
    match jobs {
        None => Ok(0),
        Some(n) if (1..=MAX_JOBS).contains(&n) => Ok(n),
        Some(n) => bail!("invalid --jobs: {n} threads; give 1 to {MAX_JOBS}"),
    }
}

/// The sweep of `sweep`'s flags.
fn sweep_request(args: &SweepArgs) -> Result<SweepRequest> {
    Ok(SweepRequest {
        alphas: parse_list("--alpha", &args.alpha)?,
        frictions: parse_list("--friction", &args.friction)?,
        freq_ratios: parse_ratios("--freq-ratios", &args.freq_ratios)?,
        amplitude_g: args.amplitude_g,
        damping: args.damping,
        duration: args.stepping.duration,
        dt: args.stepping.dt,
        integrator: args.stepping.integrator()?,
        confirm_large: args.stepping.confirm_large,
        models: vec![ModelKind::MassSpring, ModelKind::Dda],
        shard: args.shard.as_deref().map(parse_shard).transpose()?,
    })
}

fn cmd_sweep(args: SweepArgs) -> Result<()> {
    let req = sweep_request(&args)?;
    let threads = jobs(args.jobs)?;
    // Every value and the output folder are checked before the first run.
    req.validate()?;
    slidebase::post::output::prepare_outputs(&args.out, "--out", &["sweep.csv", "errors.md"])?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let total = req.jobs().len() as u64;
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let (rows, failures) = pool.install(|| run_sweep(&req, &|| bar.inc(1)));
    bar.finish_and_clear();
    match req.shard {
        Some((i, n)) => {
            let mut staged = Staged::new(&args.out)?;
            slidebase::post::sweep::write_sweep_csv(&staged.path("sweep.csv"), &rows)?;
            staged.commit()?;
            let csv = args.out.join("sweep.csv");
            out(&format!(
                "wrote {} (shard {i}/{n}: {} in {}); join the shards with \
                 `slidebase merge --out DIR SHARD/sweep.csv…`",
                csv.display(),
                count(rows.len(), "run"),
                elapsed(start)
            ))?;
            if total == 0 {
                out(&format!(
                    "note: the grid has {} (both models), fewer than the {n} shards: this \
                     shard's table has only its header, and merge takes it as it is",
                    count(req.grid_runs(), "run")
                ))?;
            }
        }
        None => {
            write_sweep_outputs(&rows, &args.out)?;
            out(&format!(
                "{} in {}",
                count(rows.len(), "run"),
                elapsed(start)
            ))?;
        }
    }
    if !failures.is_empty() {
        for f in &failures {
            eprintln!(
                "failed: {} α={} ρ={} Ω/ω={:.4}: {}",
                f.model.label(),
                f.alpha,
                f.friction,
                f.freq_ratio,
                f.message
            );
        }
        bail!("{} of {} runs failed", failures.len(), total);
    }
    Ok(())
}

/// "1 run", "4 runs".
fn count(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

/// The time since `start` as a reader wants it: "0.024 s", "3.41 s", "75.2 s" (a quick
/// sweep is not "0.0 s").
fn elapsed(start: std::time::Instant) -> String {
    let t = start.elapsed().as_secs_f64();
    match t {
        t if t < 1.0 => format!("{t:.3} s"),
        t if t < 10.0 => format!("{t:.2} s"),
        t => format!("{t:.1} s"),
    }
}

/// Writes sweep.csv, the paper's figures and errors.md for a finished sweep (all or
/// nothing).
fn write_sweep_outputs(rows: &[slidebase::post::sweep::SweepRow], dir: &Path) -> Result<()> {
    let zeta = slidebase::post::sweep::common_damping(rows).map_err(|e| anyhow!(e))?;
    let mut staged = Staged::new(dir)?;
    slidebase::post::sweep::write_sweep_csv(&staged.path("sweep.csv"), rows)?;
    slidebase::post::sweep::plot_paper_figures(rows, &mut staged)?;
    let table = slidebase::post::sweep::error_table(rows, 0.01);
    let heading = if zeta > 0.0 {
        format!("Structural damping ζ = {zeta} in both models.\n\n")
    } else {
        String::new()
    };
    staged.write("errors.md", format!("{heading}{table}"))?;
    for f in staged.commit()? {
        out(&format!("wrote {}", f.display()))?;
    }
    out(&format!(
        "\nDDA against the exact mass-spring model (relative errors, floor 0.01, {} runs{}):\n{table}",
        rows.len(),
        if zeta > 0.0 {
            format!(", ζ = {zeta}")
        } else {
            String::new()
        }
    ))
}

fn cmd_merge(args: MergeArgs) -> Result<()> {
    slidebase::post::output::prepare_dir(&args.out)?;
    let mut rows = Vec::new();
    for path in &args.inputs {
        rows.extend(slidebase::post::sweep::read_sweep_csv(path)?);
    }
    if rows.is_empty() {
        bail!("invalid merge: the inputs have no rows (only headers); nothing to join");
    }
    // The same grid point from two shards means the shards overlap (or a file was given
    // twice): say so rather than plot it twice.
    slidebase::post::sweep::common_damping(&rows).map_err(|e| anyhow!("invalid merge: {e}"))?;
    slidebase::post::sweep::common_run(&rows).map_err(|e| anyhow!("invalid merge: {e}"))?;
    let mut seen = std::collections::HashSet::new();
    for r in &rows {
        let key = (
            r.model.clone(),
            r.alpha.to_bits(),
            r.friction.to_bits(),
            r.freq_ratio.to_bits(),
        );
        if !seen.insert(key) {
            bail!(
                "invalid merge: {} α={} ρ={} Ω/ω={} appears in more than one input",
                r.model,
                r.alpha,
                r.friction,
                r.freq_ratio
            );
        }
    }
    slidebase::post::sweep::whole_grid(&rows).map_err(|e| anyhow!("invalid merge: {e}"))?;
    write_sweep_outputs(&rows, &args.out)
}

/// Repeats of a benchmark: `--repeat` when given (also with `--quick`), else 5, or 3
/// with `--quick`.
fn bench_repeats(quick: bool, repeat: Option<usize>) -> Result<usize> {
    use slidebase::limits::MAX_REPEATS;
    match repeat {
        None if quick => Ok(3),
        None => Ok(5),
        Some(n) if (1..=MAX_REPEATS).contains(&n) => Ok(n),
        Some(n) => bail!("invalid --repeat: {n}; give 1 to {MAX_REPEATS}"),
    }
}

fn cmd_bench(args: BenchArgs) -> Result<()> {
    use slidebase::headless::bench::{BenchOptions, report_text, run_bench, write_bench};
    let repeats = bench_repeats(args.quick, args.repeat)?;
    if args.no_sweep && args.jobs.is_some() {
        bail!("invalid --jobs: it sets the sweep's threads, and --no-sweep leaves the sweep out");
    }
    if let Some(dir) = &args.out {
        slidebase::post::output::prepare_dir(dir)?;
    }
    let options = BenchOptions {
        quick: args.quick,
        repeats,
        jobs: jobs(args.jobs)?,
        sweep: !args.no_sweep,
        scaling: !args.no_scaling,
    };
    let progress = |what: &str| eprintln!("bench: {what}");
    let report = run_bench(&options, &progress)?;
    if args.json {
        out(&serde_json::to_string(&report)?)?;
    } else {
        out(&report_text(&report))?;
    }
    if let Some(dir) = &args.out {
        for f in write_bench(&report, dir)? {
            eprintln!("wrote {}", f.display());
        }
        // Without the series the old plot stays beside a bench.json that has none: say
        // so rather than delete files a user may have kept on purpose.
        let stale: Vec<_> = ["scaling.csv", "scaling.png"]
            .map(|f| dir.join(f))
            .into_iter()
            .filter(|f| report.scaling.is_empty() && f.exists())
            .collect();
        if !stale.is_empty() {
            eprintln!(
                "note: {} {} from an earlier bench: this one ran without the scaling \
                 series (--no-scaling), and its bench.json has none",
                stale
                    .iter()
                    .map(|f| f.display().to_string())
                    .collect::<Vec<_>>()
                    .join(" and "),
                if stale.len() == 1 { "is" } else { "are" }
            );
        }
    }
    Ok(())
}

/// Lists the files a run wrote (not with `--json`, whose stdout is the one object).
fn list_written(files: Vec<std::path::PathBuf>, json: bool) -> Result<()> {
    if !json {
        for f in files {
            out(&format!("wrote {}", f.display()))?;
        }
    }
    Ok(())
}

/// A duration in a header: to the microsecond, without trailing zeros (a 1.5 ms run is
/// not "0.0 s", and 31.18 s is not 31.179999999999996).
fn seconds(t: f64) -> String {
    let text = format!("{t:.6}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The first line of a building or block run's text summary.
fn run_header(
    scene: &str,
    model: &str,
    integrator: Option<&str>,
    record: &str,
    friction: Option<String>,
    duration_s: f64,
) -> String {
    let integrator = integrator.map_or(String::new(), |i| format!(", {i}"));
    let friction = friction.unwrap_or_else(|| "fixed base".into());
    format!(
        "{scene} ({model}{integrator}), {record}, {friction}, {} s",
        seconds(duration_s)
    )
}

/// The horizontal excitation's label with the vertical record's, if the run has one (so
/// that the summary says it was applied: the results alone do not show it).
fn with_vertical(horizontal: &str, vertical: Option<&str>) -> String {
    match vertical {
        Some(v) => format!("{horizontal} + vertical {v}"),
        None => horizontal.to_string(),
    }
}

/// Prints a run's warnings on stderr (the JSON carries them too).
fn warn(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// The warnings of a finished run that were not already printed before it (those of its
/// set-up, see [`cmd_run`]).
fn warn_after_run(warnings: &[String], before: &[String]) {
    let fresh: Vec<String> = (warnings.iter())
        .filter(|w| !before.contains(w))
        .cloned()
        .collect();
    warn(&fresh);
}

fn cmd_run_frame(args: &RunArgs, setup: &slidebase::setup::RunSetup) -> Result<()> {
    let outcome = slidebase::headless::frame::run_building_setup(setup)?;
    if let Some(dir) = &args.out {
        list_written(
            slidebase::headless::frame::write_outputs(&outcome, dir)?,
            args.json,
        )?;
    }
    let s = &outcome.summary;
    if args.json {
        return out(&serde_json::to_string(s)?);
    }
    warn_after_run(&s.warnings, &setup.warnings);
    let friction = match (&s.friction_law, s.friction) {
        (Some(law), _) => Some(format!("friction {law}")),
        (None, f) => f.map(|f| format!("ρ = {f}")),
    };
    out(&run_header(
        &s.scene,
        &s.model,
        s.integrator.as_deref(),
        &with_vertical(&s.record, s.vertical_record.as_deref()),
        friction,
        s.duration_s,
    ))?;
    if let Some(b) = &s.bearing {
        out(&format!("  bearing               {b} (friction pendulum)"))?;
    }
    out(&format!(
        "  max slip              {:.4} m (residual {:.4} m)",
        s.max_slip_m, s.residual_slip_m
    ))?;
    out(&format!(
        "  peak roof accel       {:.4} g",
        s.peak_roof_accel_g
    ))?;
    out(&format!(
        "  peak base accel       {:.4} g  (ground {:.4} g)",
        s.peak_base_accel_g, s.peak_ground_accel_g
    ))?;
    if let (Some(roof), Some(base)) = (s.peak_roof_accel_25hz_g, s.peak_base_accel_25hz_g) {
        out(&format!(
            "  low-passed at 25 Hz   roof {roof:.4} g, base {base:.4} g"
        ))?;
    }
    out(&format!(
        "  peak roof drift       {:.4e} m",
        s.peak_roof_drift_m
    ))?;
    if let Some(f) = s.base_accel_peak_freq_hz {
        out(&format!("  base accel spectrum   peak at {f:.3} Hz"))?;
    }
    out(&format!(
        "  {}, energy residual {:.2e}, wall {:.2} s",
        steps_and_counts(s.steps, s.solver.as_ref()),
        s.energy_residual_rel,
        s.wall_time_s
    ))?;
    if let Some(c) = s.solver.filter(|c| c.dt_cuts > 0) {
        let why = c.dt_cut_reasons;
        out(&format!(
            "  Δt cuts: {} because a held contact contradicted its gap, {} because contacts \
             still changed state, {} because friction forces still moved (at the last open-close \
             pass), {} because a vertex moved too far in one step",
            why.contradicted, why.states_changing, why.friction_changing, why.too_far
        ))?;
    }
    Ok(())
}

fn cmd_run_block(args: &RunArgs, setup: &slidebase::setup::RunSetup) -> Result<()> {
    use slidebase::headless::block;
    let outcome = block::run_block_setup(setup)?;
    if let Some(dir) = &args.out {
        let overlays = block::standard_overlays(setup)?;
        list_written(
            block::write_outputs(setup, &outcome, &overlays, dir)?,
            args.json,
        )?;
    }
    let s = &outcome.summary;
    if args.json {
        return out(&serde_json::to_string(s)?);
    }
    warn_after_run(&s.warnings, &setup.warnings);
    let friction = s.friction_law.as_ref().map(|f| format!("friction {f}"));
    out(&run_header(
        &s.scene,
        &s.model,
        s.integrator.as_deref(),
        &with_vertical(&s.record, s.vertical_record.as_deref()),
        friction,
        s.duration_s,
    ))?;
    out(&format!(
        "  max slip              {:.4} m (residual {:.4} m)",
        s.max_slip_m, s.residual_slip_m
    ))?;
    out(&format!(
        "  peak block accel      {:.4} g  (ground {:.4} g)",
        s.peak_base_accel_g, s.peak_ground_accel_g
    ))?;
    out(&format!(
        "  {}, energy residual {:.2e}, wall {:.2} s",
        steps_and_counts(s.steps, s.solver.as_ref()),
        s.energy_residual_rel,
        s.wall_time_s
    ))
}

/// "N steps, P passes, C Δt cuts" of a DDA run; an exact model's steps alone (it has no
/// passes or cuts to report).
fn steps_and_counts(
    steps: u64,
    solver: Option<&slidebase::headless::simulate::SolverCounts>,
) -> String {
    match solver {
        Some(c) => format!(
            "{steps} steps, {} passes, {} Δt cuts",
            c.open_close_passes, c.dt_cuts
        ),
        None => format!("{steps} steps"),
    }
}

/// The picture flags of `render` in their ranges (a 10⁵ × 10⁵ picture is 40 GB) and what
/// its `--out` asks for (a picture, or a replay's format), checked before anything is run
/// (and in a build without the window too).
fn check_picture(args: &RenderArgs) -> Result<Option<slidebase::post::output::VideoFormat>> {
    use slidebase::limits::{MAX_IMAGE_SIDE, MIN_IMAGE_SIDE};
    let video = slidebase::post::output::render_target(&args.out)?;
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        if let Some(v) = v
            && !(MIN_IMAGE_SIDE..=MAX_IMAGE_SIDE).contains(&v)
        {
            bail!("invalid {flag}: {v} pixels; give {MIN_IMAGE_SIDE} to {MAX_IMAGE_SIDE}");
        }
    }
    if let Some(f) = args.exaggeration {
        let (lo, hi) = slidebase::limits::EXAGGERATION_RANGE;
        slidebase::error::require_range("--exaggeration", f, lo, hi, "(1: true scale)")?;
    }
    Ok(video)
}

#[cfg(feature = "gui")]
fn cmd_render(args: RenderArgs) -> Result<()> {
    use slidebase::export::{PictureOptions, VideoFormat, render_picture, render_video};
    use slidebase::sim::{Excitation, SimConfig};
    let video = check_picture(&args)?;
    slidebase::post::output::prepare_file_for(&args.out, "--out")?;
    if let Some(dir) = &args.data {
        slidebase::post::output::prepare_dir_for(dir, "--data")?;
    }
    let config = SimConfig {
        scene: args.scene,
        friction: args.friction,
        excitation: args.record.map_or(Excitation::Scene, Excitation::Record),
        compare_fixed: !args.single,
        compare_friction: args.compare_friction,
        pga_g: args.pga,
        ..SimConfig::default()
    };
    let default_size = match video {
        Some(VideoFormat::Gif) => (800, 450),
        _ => (1280, 720),
    };
    let options = PictureOptions {
        width: args.width.unwrap_or(default_size.0),
        height: args.height.unwrap_or(default_size.1),
        // In range (checked above), so single precision holds it.
        exaggeration: args.exaggeration.map(|f| f as f32),
        close_ups: !args.no_close_ups,
    };
    let info = match video {
        Some(_) => {
            if args.time.is_some() {
                bail!(
                    "--time is for a picture; a replay (--out {}) takes --from, --to and --fps",
                    args.out.display()
                );
            }
            let end = slidebase::sim::prepare(&config)?.duration;
            let from = args.from.unwrap_or(0.0);
            within_run("--from", from, end)?;
            let to = args.to.unwrap_or(end);
            within_run("--to", to, end)?;
            render_video(
                &config,
                from,
                to,
                args.fps.unwrap_or(25.0),
                &options,
                &args.out,
                args.data.as_deref(),
            )?
        }
        None => {
            for (flag, given) in [
                ("--from", args.from.is_some()),
                ("--to", args.to.is_some()),
                ("--fps", args.fps.is_some()),
            ] {
                if given {
                    bail!(
                        "{flag} is for a replay (--out replay.mp4 or replay.gif), not for a picture ({})",
                        args.out.display()
                    );
                }
            }
            let time = args.time.unwrap_or(5.0);
            within_run("--time", time, slidebase::sim::prepare(&config)?.duration)?;
            render_picture(&config, time, &options, &args.out, args.data.as_deref())?
        }
    };
    if let Some(note) = &info.note {
        eprintln!("note: {note}");
    }
    let files: Vec<String> = info.files.iter().map(|f| f.display().to_string()).collect();
    out(&format!(
        "wrote {} ({}, {}; simulated in {:.2} s, rendered in {:.2} s)",
        files.join(", "),
        count(info.frames, "frame"),
        info.adapter,
        info.simulate_s,
        info.render_s
    ))
}

/// Refuses a time (named by `flag`) after the end of the run (`end`, s): the picture
/// would show the run's last instant under a label it does not have.
#[cfg(feature = "gui")]
fn within_run(flag: &str, time: f64, end: f64) -> Result<()> {
    // A millionth of a step's slack: `--to` is often the duration itself, as printed.
    if time > end + 1e-9 * end.max(1.0) {
        bail!(
            "invalid {flag}: {} s is after the end of the run ({end} s); give a time in [0, {end}]",
            slidebase::error::show(time)
        );
    }
    Ok(())
}

#[cfg(not(feature = "gui"))]
fn cmd_render(args: RenderArgs) -> Result<()> {
    check_picture(&args)?;
    bail!(
        "this slidebase was built without the `gui` feature, which `render` needs (build with default features)"
    )
}

fn cmd_stability(args: StabilityArgs) -> Result<()> {
    use slidebase::headless::stability::{run_stability, write_stability};
    slidebase::post::output::prepare_dir(&args.out)?;
    let rows = run_stability(!args.quick, &|r| {
        let mark = if r.passed { "ok " } else { "FAIL" };
        eprintln!(
            "{mark} {:<40} {}",
            r.case,
            if r.finished {
                r.detail.clone()
            } else {
                r.error.clone()
            }
        );
    });
    for f in write_stability(&rows, &args.out)? {
        out(&format!("wrote {}", f.display()))?;
    }
    let failed = rows.iter().filter(|r| !r.passed).count();
    if failed > 0 {
        bail!(
            "{failed} of {} cases failed their check (see {})",
            rows.len(),
            args.out.join("report.md").display()
        );
    }
    Ok(())
}

fn cmd_accuracy(args: AccuracyArgs) -> Result<()> {
    use slidebase::headless::accuracy::{run_accuracy, write_accuracy};
    slidebase::post::output::prepare_dir(&args.out)?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let rows = run_accuracy(args.quick, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let rows = rows?;
    for f in write_accuracy(&rows, &args.out)? {
        out(&format!("wrote {}", f.display()))?;
    }
    out(&std::fs::read_to_string(args.out.join("report.md")).unwrap_or_default())
}

fn cmd_report(args: ReportArgs) -> Result<()> {
    use slidebase::headless::report::{ReportRequest, run_all, write_report};
    let req = ReportRequest {
        scene: args.scene,
        record: args.record,
        friction: args.friction,
        dt: args.dt,
        duration: args.duration,
        confirm_large: args.confirm_large,
    };
    // The runs' set-up and the output folder are checked before the first run.
    req.check()?;
    slidebase::post::output::prepare_dir(&args.out)?;
    let bar = ProgressBar::new_spinner();
    bar.set_message("running sliding and fixed base (DDA, two integrators) and the MDOF model…");
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let runs = run_all(&req);
    bar.finish_and_clear();
    let runs = runs?;
    for f in write_report(&req, &runs, &args.out)? {
        out(&format!("wrote {}", f.display()))?;
    }
    out(&std::fs::read_to_string(args.out.join("summary.md")).unwrap_or_default())
}

fn cmd_modes(args: ModesArgs) -> Result<()> {
    use slidebase::headless::frame::{
        MDOF_FIT_TOLERANCE, equivalent_mdof_with, mdof_fit_warning, modes, paper_frequencies_for,
    };
    let scene = slidebase::model::presets::resolve_scene(&args.scene)?;
    let report = modes(&scene)?;
    // The frequencies are reported even when no shear building matches them.
    let (mdof, report, warning) = match equivalent_mdof_with(&scene, report.clone()) {
        Ok((building, report)) => {
            let warning = report
                .mdof_fit_error
                .filter(|&e| e > MDOF_FIT_TOLERANCE)
                .map(mdof_fit_warning);
            (Some(building), report, warning)
        }
        Err(e) => (None, report, Some(format!("no equivalent MDOF model: {e}"))),
    };
    let paper = paper_frequencies_for(&args.scene);
    // A scene file is named by its path beside the name inside it.
    let title = if args.scene == scene.name {
        scene.name.clone()
    } else {
        format!("{} ({})", scene.name, args.scene)
    };
    if args.json {
        let mut v = serde_json::json!({
            "scene": report.scene,
            "scene_source": args.scene,
            "frequencies_hz": report.frequencies_hz,
            "shapes": report.shapes,
            "levels": report.levels,
            "warnings": warning.iter().collect::<Vec<_>>(),
        });
        if let Some(p) = paper {
            v["paper_frequencies_hz"] = serde_json::json!(p);
        }
        if let Some(b) = &mdof {
            v["mdof"] = serde_json::json!({
                "raft_mass_kg": b.raft_mass, "storey_masses_kg": b.storey_masses,
                "storey_stiffnesses_n_per_m": b.storey_stiffnesses,
                "fit_max_rel_error": report.mdof_fit_error.unwrap_or(0.0) });
        }
        return out(&serde_json::to_string(&v)?);
    }
    if let Some(w) = &warning {
        eprintln!("warning: {w}");
    }
    out(&format!(
        "{title}: fixed-base natural frequencies (DDA stiffness and mass)"
    ))?;
    for (k, f) in report.frequencies_hz.iter().enumerate() {
        let paper = paper
            .and_then(|p| p.get(k).copied())
            .map_or(String::new(), |p| {
                format!("   paper {p:.3} Hz ({:+.2} %)", 100.0 * (f / p - 1.0))
            });
        let shape: Vec<String> = report.shapes[k]
            .iter()
            .map(|x| format!("{x:+.3}"))
            .collect();
        out(&format!(
            "  mode {}: {:.4} Hz{}   shape [{}]",
            k + 1,
            f,
            paper,
            shape.join(", ")
        ))?;
    }
    out(&format!("  levels: {}", report.levels.join(", ")))?;
    let Some(building) = mdof else {
        return Ok(());
    };
    out(&format!(
        "equivalent MDOF: raft {:.4e} kg, floors {:?} kg, storey stiffness {:?} N/m",
        building.raft_mass,
        building
            .storey_masses
            .iter()
            .map(|m| format!("{m:.4e}"))
            .collect::<Vec<_>>(),
        building
            .storey_stiffnesses
            .iter()
            .map(|k| format!("{k:.4e}"))
            .collect::<Vec<_>>()
    ))
}

fn cmd_list() -> Result<()> {
    out("scenes:")?;
    for s in slidebase::model::presets::builtin_names() {
        out(&format!("  {s}"))?;
    }
    out("generated scenes:")?;
    let frame = format!(
        "frame:N (the paper's frame with N storeys, 1 to {})",
        slidebase::model::generated::MAX_FRAME_STOREYS
    );
    let wall = format!(
        "wall:N (N courses of dry-stacked blocks, 1 to {})",
        slidebase::model::generated::MAX_WALL
    );
    for s in [
        "friction-pendulum (--radius R, or friction-pendulum:R)",
        &frame,
        &wall,
    ] {
        out(&format!("  {s}"))?;
    }
    out("records:")?;
    for r in slidebase::ground_motion::builtin_names() {
        out(&format!("  {r}"))?;
    }
    Ok(())
}

/// With no subcommand: the default scene, both models side by side.
#[cfg(feature = "gui")]
fn cmd_default() -> Result<()> {
    slidebase::app::run_app()?;
    Ok(())
}

/// Without the visualizer: the default two-block scene, both models side by side.
#[cfg(not(feature = "gui"))]
fn cmd_default() -> Result<()> {
    out("slidebase: two-block scene (paper Fig. 2), α = 0.5, ρ = 0.1, Ω/ω = 1, 0.3 g, 20 s")?;
    out("           DDA (generalised-α) against the exact mass-spring model\n")?;
    let mut rows = Vec::new();
    for model in [ModelKind::MassSpring, ModelKind::Dda] {
        let spec = RunSpec {
            model,
            duration: Some(20.0),
            ..RunSpec::default()
        };
        rows.push(slidebase::headless::run::run(&spec)?.summary);
    }
    out(&format!("  {:<22}{:>14}{:>14}", "", "mass-spring", "DDA"))?;
    let line = |name: &str, f: &dyn Fn(&slidebase::headless::run::RunSummary) -> f64| {
        format!("  {:<22}{:>14.4}{:>14.4}", name, f(&rows[0]), f(&rows[1]))
    };
    out(&line("|u_s|max/D", &|s| {
        s.us_max_over_d.unwrap_or(f64::NAN)
    }))?;
    out(&line("|u_r|max/D", &|s| {
        s.ur_max_over_d.unwrap_or(f64::NAN)
    }))?;
    out(&line("|a_base|max/a_g", &|s| {
        s.abase_over_aground.unwrap_or(f64::NAN)
    }))?;
    out(&line("|a_roof|max/a_g", &|s| {
        s.aroof_over_aground.unwrap_or(f64::NAN)
    }))?;
    out(&line("wall time (s)", &|s| s.wall_time_s))?;
    out("\nMore: `slidebase run --help`, `slidebase sweep --help`, `slidebase list`.")
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use slidebase::testing::{Rng, property_cases};

    const NUMBERS: &[&str] = &[
        "0",
        "-1",
        "0.5",
        "0.1",
        "1",
        "3",
        "1e300",
        "-1e300",
        "1e-300",
        "nan",
        "inf",
        "-inf",
        "1e-12",
        "1e9",
        "10",
        "0.01",
        "0.005",
        "0.02",
        "0.2",
        "x",
        "",
        "18446744073709551615",
    ];

    /// A random `run` or `sweep` command line from the flags' vocabulary.
    fn command_line(rng: &mut Rng) -> Vec<String> {
        let sweep = rng.chance(8);
        let mut args = vec!["slidebase".to_string()];
        args.push(if sweep { "sweep" } else { "run" }.into());
        let flags: &[&str] = if sweep {
            &[
                "--alpha",
                "--friction",
                "--freq-ratios",
                "--amplitude-g",
                "--damping",
                "--duration",
                "--dt",
                "--integrator",
                "--jobs",
                "--shard",
                "--confirm-large",
            ]
        } else {
            &[
                "--scene",
                "--alpha",
                "--friction",
                "--freq-ratio",
                "--amplitude-g",
                "--duration",
                "--duration",
                "--dt",
                "--integrator",
                "--model",
                "--fixed-base",
                "--record",
                "--ground",
                "--json",
                "--confirm-large",
                "--bogus",
            ]
        };
        for _ in 0..rng.below(6) {
            let flag = rng.pick(flags);
            args.push(flag.into());
            let value = match flag {
                "--fixed-base" | "--json" | "--confirm-large" => continue,
                "--scene" => rng.pick(&[
                    "two-block",
                    "three-storey",
                    "frame:2",
                    "frame:0",
                    "frame:101",
                    "wall:2",
                    "wall:x",
                    "missing.toml",
                    "/dev/zero",
                ]),
                "--integrator" => rng.pick(&[
                    "classic",
                    "trapezoidal",
                    "hht:0.1",
                    "hht:5",
                    "generalized-alpha:0.5",
                    "gen-alpha:x",
                    "euler",
                ]),
                "--model" => rng.pick(&["dda", "mass-spring", "fem"]),
                "--record" => rng.pick(&[
                    "el-centro",
                    "el-centro-up",
                    "kobe-nishi-akashi-000",
                    "/dev/zero",
                    "missing.AT2",
                ]),
                "--ground" => rng.pick(&["prescribed", "large-mass", "x"]),
                "--freq-ratios" => rng.pick(&["0.1:10:3", "1:1:1", "0:1:2", "0.5,2", "1:10:1e11"]),
                "--shard" => rng.pick(&["1/2", "0/2", "3/2", "x", "1/18446744073709551615"]),
                "--jobs" => rng.pick(&["1", "0", "99999", "x"]),
                "--alpha" | "--friction" if sweep => {
                    rng.pick(&["0.1,0.5", "0.5", "-1", "inf", "", "x"])
                }
                _ => rng.pick(NUMBERS),
            };
            args.push(value.into());
        }
        args
    }

    /// Every command line is refused cleanly or prepares a run; the small ones run, and
    /// their summaries are finite (no `null` in the JSON). In-process: the same code as
    /// the binary without spawning it ten thousand times.
    #[test]
    fn command_lines_are_refused_cleanly_or_run_finitely() {
        let cases = property_cases();
        let (mut prepared, mut ran) = (0, 0);
        for case in 0..cases {
            let mut rng = Rng::for_case(0xc11, case);
            let args = command_line(&mut rng);
            let result = std::panic::catch_unwind(|| -> Result<Option<bool>> {
                let Ok(cli) = Cli::try_parse_from(&args) else {
                    return Ok(None);
                };
                match cli.command {
                    Some(Command::Run(a)) => {
                        let setup = run_spec(&a)?.prepare()?;
                        let small =
                            setup.duration / setup.dt <= 100.0 && setup.scene.blocks.len() <= 3;
                        if !small {
                            return Ok(Some(false));
                        }
                        let json = match setup.roles {
                            SceneRoles::TwoBlock { .. } => {
                                serde_json::to_string(&run_setup(&setup)?.summary)?
                            }
                            SceneRoles::Building(_) => {
                                let o = slidebase::headless::frame::run_building_setup(&setup)?;
                                serde_json::to_string(&o.summary)?
                            }
                            SceneRoles::Block(_) => {
                                let o = slidebase::headless::block::run_block_setup(&setup)?;
                                serde_json::to_string(&o.summary)?
                            }
                        };
                        assert!(!json.contains("null"), "{args:?}: {json}");
                        Ok(Some(true))
                    }
                    Some(Command::Sweep(a)) => {
                        let req = sweep_request(&a)?;
                        jobs(a.jobs)?;
                        req.validate()?;
                        Ok(Some(false))
                    }
                    _ => Ok(None),
                }
            });
            match result {
                Err(_) => panic!("case {case} panicked: {args:?}"),
                Ok(Err(e)) => assert!(!e.to_string().is_empty(), "{args:?}"),
                Ok(Ok(Some(r))) => {
                    prepared += 1;
                    ran += usize::from(r);
                }
                Ok(Ok(None)) => {}
            }
        }
        println!("{cases} command lines: {prepared} prepared, {ran} run");
    }

    #[test]
    fn repeat_is_honoured_with_quick_and_bounded() {
        assert_eq!(bench_repeats(true, None).unwrap(), 3);
        assert_eq!(bench_repeats(true, Some(7)).unwrap(), 7);
        assert_eq!(bench_repeats(false, None).unwrap(), 5);
        assert!(bench_repeats(false, Some(0)).is_err());
        assert!(bench_repeats(false, Some(usize::MAX)).is_err());
    }
}
