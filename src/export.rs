//! Pictures, replays and data for taking away: `slidebase render` draws the window's scene
//! (titles, time, ground acceleration, legend, colour bar, close-ups — the same code as the
//! window, through egui offscreen) into a PNG, or a series of frames evenly spaced in
//! simulated time into an MP4 (through `ffmpeg` when it is on PATH) or an animated GIF
//! (written here, with the `gif` crate); `--data DIR` writes the plots' data as CSV.
//!
//! Everything is computed the way the window computes it: the run goes through the same
//! messages into an [`AppState`], so fits, exaggeration, spectra and the headline are the
//! window's.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::limits::{MAX_IMAGE_SIDE, MIN_IMAGE_SIDE};
pub use crate::post::output::VideoFormat;
use crate::post::output::render_target;
use crate::render::offscreen::{Gpu, OffscreenUi, write_png};
use crate::sim::{SimConfig, run_to_messages};
use crate::ui::{AppState, Exaggeration, PlotData, scene::draw_scene};
use crate::{Error, Result};

/// How pictures are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PictureOptions {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Deformation exaggeration (None: automatic, as in the window).
    pub exaggeration: Option<f32>,
    /// Joint close-ups under the models.
    pub close_ups: bool,
}

impl Default for PictureOptions {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
            exaggeration: None,
            close_ups: true,
        }
    }
}

/// What was written.
#[derive(Debug, Clone)]
pub struct ExportInfo {
    /// The adapter used.
    pub adapter: String,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Frames drawn.
    pub frames: usize,
    /// Wall-clock time of the simulation, s.
    pub simulate_s: f64,
    /// Wall-clock time of drawing and writing, s.
    pub render_s: f64,
    /// Why an MP4 became a GIF, if it did.
    pub note: Option<String>,
}

/// The window's state after running `config` to `until`, with the view of `options`.
pub fn state_until(config: &SimConfig, until: f64, options: &PictureOptions) -> Result<AppState> {
    let mut state = AppState::default();
    state.take_commands();
    for msg in run_to_messages(config, until)? {
        state.ingest(msg);
    }
    if let Some(e) = state.error.take() {
        return Err(Error::Scene(e));
    }
    state.view.exaggeration = options
        .exaggeration
        .map_or(Exaggeration::Auto, Exaggeration::Fixed);
    state.view.close_ups = options.close_ups;
    state.playing = false;
    state.resume_at = None;
    Ok(state)
}

/// Draws the scene of `state` at its time cursor.
fn draw(
    ui_renderer: &mut OffscreenUi,
    state: &mut AppState,
    width: u32,
    height: u32,
) -> Result<Vec<u8>> {
    let Some(inputs) = crate::ui::scene::inputs_of(state) else {
        return Err(Error::Scene("nothing has been computed to draw".into()));
    };
    ui_renderer.render(width, height, |ui| {
        let rect = ui.max_rect();
        draw_scene(ui, rect, &inputs);
    })
}

/// Checks the sizes of a picture or video.
fn check_options(options: &PictureOptions) -> Result<()> {
    for (name, v) in [("--width", options.width), ("--height", options.height)] {
        if !(MIN_IMAGE_SIDE..=MAX_IMAGE_SIDE).contains(&v) {
            return Err(Error::invalid(
                name,
                format!("{v} pixels is outside {MIN_IMAGE_SIDE}…{MAX_IMAGE_SIDE}"),
            ));
        }
    }
    if let Some(f) = options.exaggeration {
        let (lo, hi) = crate::limits::EXAGGERATION_RANGE;
        crate::error::require_range("--exaggeration", f64::from(f), lo, hi, "(1: true scale)")?;
    }
    Ok(())
}

/// Renders the state of `config` at `time` into a PNG, and with `data` the plots' CSVs.
pub fn render_picture(
    config: &SimConfig,
    time: f64,
    options: &PictureOptions,
    path: &Path,
    data: Option<&Path>,
) -> Result<ExportInfo> {
    crate::error::require_non_negative("--time", time)?;
    check_options(options)?;
    if render_target(path)?.is_some() {
        return Err(Error::invalid(
            "--out",
            format!("{}: a picture is written as .png", path.display()),
        ));
    }
    // The run is checked (and computed) before the graphics adapter is looked for, so that
    // a bad flag is reported as such on any machine.
    let t0 = std::time::Instant::now();
    let mut state = state_until(config, time, options)?;
    state.play_time = time.min(state.timeline.available());
    let simulate_s = t0.elapsed().as_secs_f64();
    let gpu = Gpu::new()?;
    let t1 = std::time::Instant::now();
    let mut offscreen = OffscreenUi::new(&gpu);
    let pixels = draw(&mut offscreen, &mut state, options.width, options.height)?;
    write_png(path, &pixels, options.width, options.height)?;
    let mut files = vec![path.to_path_buf()];
    if let Some(dir) = data {
        files.extend(write_data(&state, dir)?);
    }
    Ok(ExportInfo {
        adapter: gpu.adapter_info,
        files,
        frames: 1,
        simulate_s,
        render_s: t1.elapsed().as_secs_f64(),
        note: None,
    })
}

/// Writes the plots' data of `state` at its cursor: `series.csv` and `spectrum.csv`.
pub fn write_data(state: &AppState, dir: &Path) -> Result<Vec<PathBuf>> {
    let data = PlotData::of(
        &state.timeline,
        state.play_time,
        state.view.spectrum_to_cursor,
    );
    crate::ui::write_plot_data(dir, &state.timeline, &data)?;
    Ok(vec![dir.join("series.csv"), dir.join("spectrum.csv")])
}

/// Whether `ffmpeg` can be run.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The times of a replay's frames: from `from` to `to` (inclusive) every `1/fps` s of
/// simulated time.
pub fn frame_times(from: f64, to: f64, fps: f64) -> Result<Vec<f64>> {
    crate::error::require_non_negative("--from", from)?;
    crate::error::require_positive("--fps", fps)?;
    if to.is_nan() || to <= from {
        return Err(Error::invalid(
            "--to",
            format!("must be after --from ({from} s), got {to} s"),
        ));
    }
    // A hair of tolerance: (0.6 − 0.2) × 10 is 3.9999… in floating point.
    let n = ((to - from) * fps + 1e-9).floor() as usize + 1;
    if n > 20_000 {
        return Err(Error::invalid(
            "--fps",
            format!("{n} frames is too many (at most 20000: shorten --from/--to or lower --fps)"),
        ));
    }
    Ok((0..n).map(|k| from + k as f64 / fps).collect())
}

/// Renders a replay of `config` from `from` to `to` s at `fps` frames per simulated second
/// (played back in real time) into an MP4 or a GIF, as `path`'s extension says. Without
/// ffmpeg an MP4 request writes a GIF next to it instead (and says so).
#[allow(clippy::too_many_arguments)]
pub fn render_video(
    config: &SimConfig,
    from: f64,
    to: f64,
    fps: f64,
    options: &PictureOptions,
    path: &Path,
    data: Option<&Path>,
) -> Result<ExportInfo> {
    check_options(options)?;
    let times = frame_times(from, to, fps)?;
    let Some(mut format) = render_target(path)? else {
        return Err(Error::invalid(
            "--out",
            format!("{}: a video is .mp4 or .gif", path.display()),
        ));
    };
    let mut path = path.to_path_buf();
    let mut note = None;
    if format == VideoFormat::Mp4 && !ffmpeg_available() {
        path.set_extension("gif");
        format = VideoFormat::Gif;
        note = Some(format!(
            "ffmpeg is not on PATH: wrote an animated GIF, {}",
            path.display()
        ));
    }
    let t0 = std::time::Instant::now();
    let mut state = state_until(config, to, options)?;
    let simulate_s = t0.elapsed().as_secs_f64();
    let gpu = Gpu::new()?;
    let t1 = std::time::Instant::now();
    // Even sizes: H.264 in yuv420p needs them.
    let (w, h) = (options.width & !1, options.height & !1);
    let mut offscreen = OffscreenUi::new(&gpu);
    let mut sink: Box<dyn FrameSink> = match format {
        VideoFormat::Mp4 => Box::new(Mp4Sink::start(&path, w, h, fps)?),
        VideoFormat::Gif => Box::new(GifSink::start(&path, w, h, fps)?),
    };
    for &t in &times {
        state.play_time = t.min(state.timeline.available());
        let pixels = draw(&mut offscreen, &mut state, w, h)?;
        sink.frame(pixels)?;
    }
    sink.finish()?;
    let mut files = vec![path.clone()];
    if let Some(dir) = data {
        files.extend(write_data(&state, dir)?);
    }
    Ok(ExportInfo {
        adapter: gpu.adapter_info,
        files,
        frames: times.len(),
        simulate_s,
        render_s: t1.elapsed().as_secs_f64(),
        note,
    })
}

/// Where video frames go.
trait FrameSink {
    fn frame(&mut self, rgba: Vec<u8>) -> Result<()>;
    fn finish(self: Box<Self>) -> Result<()>;
}

/// Frames piped into ffmpeg as raw RGBA.
struct Mp4Sink {
    child: std::process::Child,
    path: PathBuf,
}

impl Mp4Sink {
    fn start(path: &Path, w: u32, h: u32, fps: f64) -> Result<Self> {
        let child = Command::new("ffmpeg")
            .args([
                "-y",
                "-loglevel",
                "error",
                "-f",
                "rawvideo",
                "-pix_fmt",
                "rgba",
                "-s",
            ])
            .arg(format!("{w}x{h}"))
            .arg("-r")
            .arg(format!("{fps}"))
            .args([
                "-i",
                "-",
                "-c:v",
                "libx264",
                "-pix_fmt",
                "yuv420p",
                "-movflags",
                "+faststart",
            ])
            .arg(path)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .spawn()
            .map_err(|e| Error::Scene(format!("cannot start ffmpeg: {e}")))?;
        Ok(Self {
            child,
            path: path.to_path_buf(),
        })
    }
}

impl FrameSink for Mp4Sink {
    fn frame(&mut self, rgba: Vec<u8>) -> Result<()> {
        let stdin = self
            .child
            .stdin
            .as_mut()
            .ok_or_else(|| Error::Scene("ffmpeg's input closed".into()))?;
        stdin
            .write_all(&rgba)
            .map_err(|e| Error::Scene(format!("ffmpeg stopped taking frames: {e}")))
    }

    fn finish(mut self: Box<Self>) -> Result<()> {
        drop(self.child.stdin.take());
        let status = self
            .child
            .wait()
            .map_err(|e| Error::Scene(format!("ffmpeg: {e}")))?;
        if !status.success() {
            return Err(Error::Scene(format!(
                "ffmpeg could not write {} ({status})",
                self.path.display()
            )));
        }
        Ok(())
    }
}

/// An animated GIF (each frame quantised to its own 256-colour palette).
struct GifSink {
    encoder: gif::Encoder<std::io::BufWriter<std::fs::File>>,
    w: u16,
    h: u16,
    delay_cs: u16,
    path: PathBuf,
}

impl GifSink {
    fn start(path: &Path, w: u32, h: u32, fps: f64) -> Result<Self> {
        let (gw, gh) = (u16::try_from(w), u16::try_from(h));
        let (Ok(w), Ok(h)) = (gw, gh) else {
            return Err(Error::invalid(
                "--width/--height",
                "a GIF is at most 65535 pixels a side",
            ));
        };
        let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
        let gif_error = |e: gif::EncodingError| Error::Scene(format!("{}: {e}", path.display()));
        let mut encoder =
            gif::Encoder::new(std::io::BufWriter::new(file), w, h, &[]).map_err(gif_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(gif_error)?;
        Ok(Self {
            encoder,
            w,
            h,
            // GIF delays are in hundredths of a second.
            delay_cs: (100.0 / fps).round().clamp(2.0, 65535.0) as u16,
            path: path.to_path_buf(),
        })
    }
}

impl FrameSink for GifSink {
    fn frame(&mut self, mut rgba: Vec<u8>) -> Result<()> {
        let mut frame = gif::Frame::from_rgba_speed(self.w, self.h, &mut rgba, 10);
        frame.delay = self.delay_cs;
        self.encoder
            .write_frame(&frame)
            .map_err(|e| Error::Scene(format!("{}: {e}", self.path.display())))
    }

    fn finish(self: Box<Self>) -> Result<()> {
        self.encoder
            .into_inner()
            .map_err(|e| Error::Scene(format!("{}: {e}", self.path.display())))?
            .flush()
            .map_err(|e| Error::io(&self.path, e))
    }
}
