//! Command-line definitions (clap) and the glue from flags to the headless functions.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};

use slidebase::dda::Integrator;
use slidebase::headless::run::{RunRequest, run, write_outputs};
use slidebase::headless::sweep::{SweepRequest, parse_list, parse_ratios, parse_shard, run_sweep};
use slidebase::headless::two_block::ModelKind;
use slidebase::model::scene::GroundKind;

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
    /// Render the scene at one instant into a PNG (offscreen, the visualizer's renderer).
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
    /// Built-in scene name or a scene TOML file.
    #[arg(long, default_value = "two-block")]
    scene: String,
    /// Mass ratio α = m/(M + m) of roof to total mass, in (0, 1) (two-block; default 0.5).
    #[arg(long, allow_hyphen_values = true)]
    alpha: Option<f64>,
    /// Friction coefficient ρ of the sliding joint, ≥ 0 (default: 0.1 two-block, the scene's otherwise).
    #[arg(long, allow_hyphen_values = true)]
    friction: Option<f64>,
    /// Excitation frequency over the structure frequency, Ω/ω (two-block; default 1).
    #[arg(long = "freq-ratio", allow_hyphen_values = true)]
    freq_ratio: Option<f64>,
    /// Amplitude of the harmonic ground acceleration, g.
    #[arg(
        long = "amplitude-g",
        default_value_t = 0.3,
        allow_hyphen_values = true
    )]
    amplitude_g: f64,
    /// Duration, s (default: 100 s for harmonic input, the record's length for a record).
    #[arg(long, allow_hyphen_values = true)]
    duration: Option<f64>,
    /// Time step, s.
    #[arg(long, default_value_t = 1e-3, allow_hyphen_values = true)]
    dt: f64,
    /// classic | trapezoidal | hht[:α] | generalized-alpha[:ρ∞].
    #[arg(long, default_value = "generalized-alpha")]
    integrator: String,
    /// Which model computes the response.
    #[arg(long, value_enum, default_value = "dda")]
    model: ModelArg,
    /// Fix the base: the sliding joint never slides.
    #[arg(long)]
    fixed_base: bool,
    /// Ground-motion record (built-in name or AT2/CSV file) instead of harmonic input.
    #[arg(long)]
    record: Option<String>,
    /// Ground model of the DDA run.
    #[arg(long, value_enum)]
    ground: Option<GroundArg>,
    /// Write time histories (CSV) and the summary (JSON) into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
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
    exaggeration: Option<f32>,
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
    /// Time step, s.
    #[arg(long, default_value_t = 1e-3, allow_hyphen_values = true)]
    dt: f64,
    /// Duration, s (default: the record's length).
    #[arg(long, allow_hyphen_values = true)]
    duration: Option<f64>,
    /// Output folder.
    #[arg(long, default_value = "out/report")]
    out: PathBuf,
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
    /// Frequency ratios: `lo:hi:n` (log-spaced) or a comma-separated list.
    #[arg(long = "freq-ratios", default_value = "0.1:10:25")]
    freq_ratios: String,
    /// Amplitude of the harmonic ground acceleration, g.
    #[arg(
        long = "amplitude-g",
        default_value_t = 0.3,
        allow_hyphen_values = true
    )]
    amplitude_g: f64,
    /// Duration of each run, s.
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    duration: f64,
    /// DDA time step, s.
    #[arg(long, default_value_t = 1e-3, allow_hyphen_values = true)]
    dt: f64,
    /// DDA integrator.
    #[arg(long, default_value = "generalized-alpha")]
    integrator: String,
    /// Output folder for sweep.csv and the figures.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Worker threads (default: all cores).
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
    /// Repeats of each timed run (the median is reported).
    #[arg(long, default_value_t = 5)]
    repeat: usize,
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

fn cmd_run(args: RunArgs) -> Result<()> {
    let integrator = Integrator::parse(&args.integrator)?;
    let scene = slidebase::model::presets::resolve_scene(&args.scene)?;
    if scene.structure.is_some() {
        return cmd_run_frame(args, integrator);
    }
    let req = RunRequest {
        scene: args.scene,
        alpha: args.alpha.unwrap_or(0.5),
        friction: args.friction.unwrap_or(0.1),
        freq_ratio: args.freq_ratio.unwrap_or(1.0),
        amplitude_g: args.amplitude_g,
        duration: args.duration,
        dt: args.dt,
        integrator,
        model: args.model.into(),
        fixed_base: args.fixed_base,
        record: args.record,
        ground: args.ground.map(|g| match g {
            GroundArg::Prescribed => GroundKind::Prescribed,
            GroundArg::LargeMass => GroundKind::LargeMass,
        }),
        record_every: 10,
    };
    let outcome = run(&req)?;
    if let Some(dir) = &args.out {
        let files = write_outputs(&outcome, dir)?;
        if !args.json {
            for f in files {
                out(&format!("wrote {}", f.display()))?;
            }
        }
    }
    let s = &outcome.summary;
    if args.json {
        return out(&serde_json::to_string(s)?);
    }
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{x:.4}"));
    out(&format!(
        "{} ({}), α = {}, ρ = {}, {}{}, {:.1} s",
        s.scene,
        s.model,
        s.alpha,
        s.friction
            .map_or("∞ (fixed base)".into(), |f| f.to_string()),
        s.excitation,
        s.freq_ratio
            .map_or(String::new(), |r| format!(" Ω/ω = {r:.4}")),
        s.duration_s
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
    out(&format!("  |a_base|max/a_g   {:.4}", s.abase_over_aground))?;
    out(&format!("  |a_roof|max/a_g   {:.4}", s.aroof_over_aground))?;
    out(&format!("  residual slip     {:.4e} m", s.residual_slip_m))?;
    out(&format!(
        "  {} steps, {} open-close passes, {} Δt cuts, max penetration {:.2e} of size",
        s.steps, s.open_close_passes, s.dt_cuts, s.max_penetration_ratio
    ))?;
    out(&format!(
        "  energy: input {:.4e} J/m, friction {:.4e} J/m, residual {:.2e} (relative)",
        s.input_work_j, s.friction_dissipated_j, s.energy_residual_rel
    ))?;
    out(&format!("  wall time {:.3} s", s.wall_time_s))
}

fn cmd_sweep(args: SweepArgs) -> Result<()> {
    let req = SweepRequest {
        alphas: parse_list("--alpha", &args.alpha)?,
        frictions: parse_list("--friction", &args.friction)?,
        freq_ratios: parse_ratios("--freq-ratios", &args.freq_ratios)?,
        amplitude_g: args.amplitude_g,
        duration: args.duration,
        dt: args.dt,
        integrator: Integrator::parse(&args.integrator)?,
        models: vec![ModelKind::MassSpring, ModelKind::Dda],
        shard: args.shard.as_deref().map(parse_shard).transpose()?,
    };
    for &a in &req.alphas {
        if !(a > 0.0 && a < 1.0) {
            bail!("invalid --alpha: {a} is outside (0, 1)");
        }
    }
    for &f in &req.frictions {
        if f.is_nan() || f < 0.0 {
            bail!("invalid --friction: {f} is negative");
        }
    }
    slidebase::error::require_positive("--dt", args.dt)?;
    slidebase::error::require_positive("--duration", args.duration)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
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
            std::fs::create_dir_all(&args.out)
                .with_context(|| format!("creating {}", args.out.display()))?;
            let csv = args.out.join("sweep.csv");
            slidebase::post::sweep::write_sweep_csv(&csv, &rows)?;
            out(&format!(
                "wrote {} (shard {i}/{n}: {} runs in {:.1} s); join the shards with \
                 `slidebase merge --out DIR SHARD/sweep.csv…`",
                csv.display(),
                rows.len(),
                start.elapsed().as_secs_f64()
            ))?;
        }
        None => {
            write_sweep_outputs(&rows, &args.out)?;
            out(&format!(
                "{} runs in {:.1} s",
                rows.len(),
                start.elapsed().as_secs_f64()
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

/// Writes sweep.csv, the paper's figures and errors.md for a finished sweep.
fn write_sweep_outputs(rows: &[slidebase::post::sweep::SweepRow], dir: &PathBuf) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let csv = dir.join("sweep.csv");
    slidebase::post::sweep::write_sweep_csv(&csv, rows)?;
    out(&format!("wrote {} ({} runs)", csv.display(), rows.len()))?;
    for f in slidebase::post::sweep::plot_paper_figures(rows, dir)? {
        out(&format!("wrote {}", f.display()))?;
    }
    let table = slidebase::post::sweep::error_table(rows, 0.01);
    out(&format!(
        "\nDDA against the exact mass-spring model (relative errors, floor 0.01):\n{table}"
    ))?;
    let report = dir.join("errors.md");
    std::fs::write(&report, table.to_string())
        .with_context(|| format!("writing {}", report.display()))?;
    Ok(())
}

fn cmd_merge(args: MergeArgs) -> Result<()> {
    let mut rows = Vec::new();
    for path in &args.inputs {
        rows.extend(slidebase::post::sweep::read_sweep_csv(path)?);
    }
    // The same grid point from two shards means the shards overlap (or a file was given
    // twice): say so rather than plot it twice.
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
    write_sweep_outputs(&rows, &args.out)
}

fn cmd_bench(args: BenchArgs) -> Result<()> {
    use slidebase::headless::bench::{BenchOptions, report_text, run_bench, write_bench};
    let options = BenchOptions {
        quick: args.quick,
        repeats: args.repeat.max(1),
        jobs: args.jobs.unwrap_or(0),
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
    }
    Ok(())
}

fn cmd_run_frame(args: RunArgs, integrator: Integrator) -> Result<()> {
    use slidebase::headless::frame::{FrameRequest, run_frame, run_mdof};
    if args.alpha.is_some() || args.freq_ratio.is_some() {
        bail!(
            "invalid --alpha/--freq-ratio: they set up the two-block scene, not '{}'",
            args.scene
        );
    }
    let req = FrameRequest {
        scene: args.scene,
        record: args.record,
        friction: args.friction,
        fixed_base: args.fixed_base,
        dt: args.dt,
        integrator,
        duration: args.duration,
    };
    let outcome = match args.model {
        ModelArg::Dda => run_frame(&req)?,
        ModelArg::MassSpring => run_mdof(&req)?,
    };
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        outcome.history.write_csv(&dir.join("history.csv"))?;
        std::fs::write(
            dir.join("summary.json"),
            serde_json::to_string_pretty(&outcome.summary)?,
        )
        .with_context(|| format!("writing {}", dir.display()))?;
    }
    let s = &outcome.summary;
    if args.json {
        return out(&serde_json::to_string(s)?);
    }
    out(&format!(
        "{} ({}, {}), {}, {}, {:.2} s",
        s.scene,
        s.model,
        s.integrator,
        s.record,
        s.friction
            .map_or("fixed base".into(), |f| format!("ρ = {f}")),
        s.duration_s
    ))?;
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
    out(&format!(
        "  peak roof drift       {:.4e} m",
        s.peak_roof_drift_m
    ))?;
    out(&format!(
        "  base accel spectrum   peak at {:.3} Hz",
        s.base_accel_peak_freq_hz
    ))?;
    out(&format!(
        "  {} steps, {} passes, {} Δt cuts, energy residual {:.2e}, wall {:.2} s",
        s.steps, s.open_close_passes, s.dt_cuts, s.energy_residual_rel, s.wall_time_s
    ))
}

#[cfg(feature = "gui")]
fn cmd_render(args: RenderArgs) -> Result<()> {
    use slidebase::export::{PictureOptions, VideoFormat, render_picture, render_video};
    use slidebase::sim::{Excitation, SimConfig};
    let config = SimConfig {
        scene: args.scene,
        friction: args.friction,
        excitation: args.record.map_or(Excitation::Scene, Excitation::Record),
        compare_fixed: !args.single,
        compare_friction: args.compare_friction,
        pga_g: args.pga,
        ..SimConfig::default()
    };
    let video = VideoFormat::of(&args.out);
    let default_size = match video {
        Some(VideoFormat::Gif) => (800, 450),
        _ => (1280, 720),
    };
    let options = PictureOptions {
        width: args.width.unwrap_or(default_size.0),
        height: args.height.unwrap_or(default_size.1),
        exaggeration: args.exaggeration,
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
            let to = match args.to {
                Some(t) => t,
                None => slidebase::sim::prepare(&config)?.duration,
            };
            render_video(
                &config,
                args.from.unwrap_or(0.0),
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
            render_picture(
                &config,
                args.time.unwrap_or(5.0),
                &options,
                &args.out,
                args.data.as_deref(),
            )?
        }
    };
    if let Some(note) = &info.note {
        eprintln!("note: {note}");
    }
    let files: Vec<String> = info.files.iter().map(|f| f.display().to_string()).collect();
    out(&format!(
        "wrote {} ({} frame{}, {}; simulated in {:.2} s, rendered in {:.2} s)",
        files.join(", "),
        info.frames,
        if info.frames == 1 { "" } else { "s" },
        info.adapter,
        info.simulate_s,
        info.render_s
    ))
}

#[cfg(not(feature = "gui"))]
fn cmd_render(_args: RenderArgs) -> Result<()> {
    bail!(
        "this slidebase was built without the `gui` feature, which `render` needs (build with default features)"
    )
}

fn cmd_stability(args: StabilityArgs) -> Result<()> {
    use slidebase::headless::stability::{run_stability, write_stability};
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
    };
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
    use slidebase::headless::frame::{PAPER_FREQUENCIES_HZ, equivalent_mdof};
    let scene = slidebase::model::presets::resolve_scene(&args.scene)?;
    let (building, report) = equivalent_mdof(&scene)?;
    if args.json {
        let v = serde_json::json!({
            "scene": report.scene,
            "frequencies_hz": report.frequencies_hz,
            "shapes": report.shapes,
            "levels": report.levels,
            "paper_frequencies_hz": PAPER_FREQUENCIES_HZ,
            "mdof": { "raft_mass_kg": building.raft_mass, "storey_masses_kg": building.storey_masses,
                      "storey_stiffnesses_n_per_m": building.storey_stiffnesses },
        });
        return out(&serde_json::to_string(&v)?);
    }
    out(&format!(
        "{}: fixed-base natural frequencies (DDA stiffness and mass)",
        report.scene
    ))?;
    for (k, f) in report.frequencies_hz.iter().enumerate() {
        let paper = PAPER_FREQUENCIES_HZ.get(k).map_or(String::new(), |p| {
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
        let req = RunRequest {
            model,
            duration: Some(20.0),
            record_every: 0,
            ..RunRequest::default()
        };
        rows.push(run(&req)?.summary);
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
    out(&line("|a_base|max/a_g", &|s| s.abase_over_aground))?;
    out(&line("|a_roof|max/a_g", &|s| s.aroof_over_aground))?;
    out(&line("wall time (s)", &|s| s.wall_time_s))?;
    out("\nMore: `slidebase run --help`, `slidebase sweep --help`, `slidebase list`.")
}
