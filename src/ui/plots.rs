//! The plots (right panel), synchronised with the time cursor. Time histories and spectra
//! come from the full-rate samples (one per solver step), not from the 10 ms frames, so
//! peaks and spectra agree with `slidebase run --json`. Each plot has its legend above it
//! (never over the data), units on its axes, a hover readout of every curve at the time
//! under the pointer, and fits itself to the data. The same curves are written by
//! "plot data (CSV)" and by `slidebase render --data`.

use egui_plot::{Line, LineStyle, Plot, PlotPoints, VLine};

use super::AppState;
use crate::ground_motion::STANDARD_GRAVITY;
use crate::headless::simulate::SPECTRUM_DT;
use crate::post::filter::{self, CellAverages};
use crate::post::spectrum::{Spectrum, uniform_spectrum};
use crate::sim::Samples;
use crate::{Error, Result};

const G: f64 = STANDARD_GRAVITY;

/// At most about this many points per drawn line (the min and max of each bucket are kept,
/// so peaks survive).
const MAX_POINTS: usize = 1200;

/// Colours distinct on light and dark backgrounds and for colour-blind viewers (Okabe & Ito):
/// one per model, in model order.
pub const MODEL_COLORS: [egui::Color32; 4] = [
    egui::Color32::from_rgb(0, 114, 178), // blue: the main sliding model
    egui::Color32::from_rgb(213, 94, 0),  // vermillion: the second model
    egui::Color32::from_rgb(0, 158, 115), // bluish green: the third
    egui::Color32::from_rgb(204, 121, 167), // reddish purple: the fourth
];
/// The exact solution (dashed).
const EXACT: egui::Color32 = egui::Color32::from_rgb(230, 159, 0);
/// The vertical ground acceleration (Okabe & Ito grey, apart from the models' colours).
const VERTICAL_COLOR: egui::Color32 = egui::Color32::from_rgb(153, 153, 153);

/// The colour of model `k`.
pub fn model_color(k: usize) -> egui::Color32 {
    MODEL_COLORS[k % MODEL_COLORS.len()]
}

/// One plotted curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend name (also the CSV column name).
    pub name: String,
    /// Points (x, y).
    pub points: Vec<[f64; 2]>,
    /// Colour (None: the theme's text colour, for the ground).
    pub color: Option<egui::Color32>,
    /// Dashed, and drawn over the solid curves (the exact solution; the ground's
    /// spectrum).
    pub dashed: bool,
    /// Largest |y| (for the legend).
    pub peak: f64,
    /// Largest |y| low-passed at 25 Hz, for a model's acceleration (the peak `run --json`
    /// reports as `peak_roof_accel_25hz_g`; see [`crate::post::filter`]).
    pub low_passed_peak: Option<f64>,
}

/// A low-passed peak this far below the raw one is worth a mention in the legend: the
/// raw peak is then a spike one to three steps wide (an impact, a base that sticks), whose
/// height depends on the step size (docs/performance-log.md, stop 47). On the three-storey
/// the two differ by 1 %; on a block wall by a factor of two to five.
const SPIKY: f64 = 0.9;

/// Legend text of an acceleration curve, g: its peak, and the low-passed one when the raw
/// peak is a spike.
pub fn accel_legend(c: &Curve) -> String {
    match c.low_passed_peak {
        Some(low) if low < SPIKY * c.peak => {
            format!("(peak {:.3}; {low:.3} low-passed at 25 Hz)", c.peak)
        }
        _ => format!("(peak {:.3})", c.peak),
    }
}

/// The low-passed peak of a full-rate column, scaled by `scale`.
fn low_passed_peak(time: &[f64], y: &[f64], scale: f64) -> Option<f64> {
    let mut cells = CellAverages::new(filter::CELL_S, filter::MAX_CELLS);
    for (&t, &v) in time.iter().zip(y) {
        cells.push(t, v);
    }
    cells.low_passed_peak().map(|p| p * scale.abs())
}

/// The fourier spectrum of one sample column over [0, `until`] (resampled onto the uniform
/// grid `run --json` uses, [`SPECTRUM_DT`]).
pub fn spectrum_of(
    samples: &Samples,
    column: fn(&Samples) -> &Vec<f64>,
    until: f64,
) -> Result<Spectrum> {
    let n = samples.count_until(until);
    if n < 8 {
        return Err(Error::invalid("spectrum", "fewer than 8 samples so far"));
    }
    uniform_spectrum(&samples.time[..n], &column(samples)[..n], SPECTRUM_DT)
}

/// Everything the plots show at one time cursor, as curves.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotData {
    /// Accelerations, g, against time.
    pub accel: Vec<Curve>,
    /// Slip of the base, m, against time.
    pub slip: Vec<Curve>,
    /// Roof drift relative to the base, m, against time.
    pub drift: Vec<Curve>,
    /// Fourier amplitude spectra of the ground and base accelerations, m/s, against Hz.
    pub spectrum: Vec<Curve>,
    /// Frequency of each spectrum curve's highest peak (0.05–20 Hz, as `run --json`).
    pub spectrum_peaks: Vec<f64>,
}

/// Thins a full-rate column to at most about [`MAX_POINTS`] points, keeping each bucket's
/// minimum and maximum in time order.
fn thin(time: &[f64], y: &[f64], scale: f64) -> Vec<[f64; 2]> {
    let n = time.len().min(y.len());
    let bucket = n.div_ceil(MAX_POINTS / 2).max(1);
    let mut out = Vec::with_capacity(2 * n / bucket + 2);
    let mut k = 0;
    while k < n {
        let end = (k + bucket).min(n);
        if bucket <= 2 {
            out.extend((k..end).map(|i| [time[i], y[i] * scale]));
        } else {
            let (mut lo, mut hi) = (k, k);
            for i in k..end {
                if y[i] < y[lo] {
                    lo = i;
                }
                if y[i] > y[hi] {
                    hi = i;
                }
            }
            let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
            out.push([time[a], y[a] * scale]);
            if b != a {
                out.push([time[b], y[b] * scale]);
            }
        }
        k = end;
    }
    out
}

fn curve(name: String, points: Vec<[f64; 2]>, color: Option<egui::Color32>) -> Curve {
    let peak = points.iter().fold(0.0f64, |m, p| m.max(p[1].abs()));
    Curve {
        name,
        points,
        color,
        dashed: false,
        peak,
        low_passed_peak: None,
    }
}

impl PlotData {
    /// The curves of everything computed in `timeline` (the plots mark the cursor with a
    /// line); the spectra over everything computed or only up to `cursor` (`to_cursor`).
    pub fn of(timeline: &super::Timeline, cursor: f64, to_cursor: bool) -> Self {
        let mut d = Self::time_histories(timeline);
        d.add_spectra(timeline, cursor, to_cursor);
        d
    }

    /// The time histories alone (no spectra).
    fn time_histories(timeline: &super::Timeline) -> Self {
        let labels = &timeline.labels;
        let mut d = PlotData::default();
        let Some(main) = timeline.samples.first() else {
            return d;
        };
        let upto = |s: &Samples| s.len();
        let n0 = upto(main);
        d.accel.push(curve(
            "ground".into(),
            thin(&main.time[..n0], &main.ground_accel[..n0], 1.0 / G),
            None,
        ));
        if main.ground_vertical_accel.iter().any(|&a| a != 0.0) {
            d.accel.push(curve(
                "ground, vertical".into(),
                thin(&main.time[..n0], &main.ground_vertical_accel[..n0], 1.0 / G),
                Some(VERTICAL_COLOR),
            ));
        }
        let top = timeline.top_name();
        let single_body = timeline.single_body();
        for (k, s) in timeline.samples.iter().enumerate() {
            let n = upto(s);
            let label = labels.get(k).cloned().unwrap_or_default();
            let mut roof = curve(
                format!("{top}, {label}"),
                thin(&s.time[..n], &s.roof_accel[..n], 1.0 / G),
                Some(model_color(k)),
            );
            roof.low_passed_peak = low_passed_peak(&s.time[..n], &s.roof_accel[..n], 1.0 / G);
            d.accel.push(roof);
            if !label.starts_with("fixed") {
                d.slip.push(curve(
                    format!("slip, {label}"),
                    thin(&s.time[..n], &s.slip[..n], 1.0),
                    Some(model_color(k)),
                ));
            }
            // A lone block is its own roof: it has no drift to plot.
            if !single_body {
                d.drift.push(curve(
                    format!("drift, {label}"),
                    thin(&s.time[..n], &s.drift[..n], 1.0),
                    Some(model_color(k)),
                ));
            }
        }
        if let Some(e) = &timeline.exact {
            let computed = timeline.available();
            let n = e.time.partition_point(|&t| t <= computed + 1e-9);
            let series = |y: &[f64], scale: f64| -> Vec<[f64; 2]> {
                e.time[..n]
                    .iter()
                    .zip(&y[..n])
                    .map(|(t, v)| [*t, v * scale])
                    .collect()
            };
            let dashed = |mut c: Curve| {
                c.dashed = true;
                c
            };
            d.accel.push(dashed(curve(
                "roof, exact mass-spring".into(),
                series(&e.roof_accel, 1.0 / G),
                Some(EXACT),
            )));
            d.slip.push(dashed(curve(
                "slip, exact".into(),
                series(&e.slip, 1.0),
                Some(EXACT),
            )));
            d.drift.push(dashed(curve(
                "drift, exact".into(),
                series(&e.drift, 1.0),
                Some(EXACT),
            )));
        }
        d
    }

    /// Replaces the spectra: the ground's, then each model's base (over everything
    /// computed, or only up to `cursor`).
    fn add_spectra(&mut self, timeline: &super::Timeline, cursor: f64, to_cursor: bool) {
        self.spectrum.clear();
        self.spectrum_peaks.clear();
        let Some(main) = timeline.samples.first() else {
            return;
        };
        let until = if to_cursor { cursor } else { f64::INFINITY };
        let mut add_spectrum =
            |name: String, s: &Samples, col: fn(&Samples) -> &Vec<f64>, color| {
                if let Ok(sp) = spectrum_of(s, col, until) {
                    let peak = sp.peak(0.05, 20.0).map_or(f64::NAN, |p| p.0);
                    let pts = sp
                        .freq_hz
                        .iter()
                        .zip(&sp.amplitude)
                        .filter(|(f, _)| **f <= 10.0)
                        .map(|(f, a)| [*f, *a])
                        .collect();
                    let mut c = curve(name, pts, color);
                    // The ground's spectrum is the fixed base's (a bonded base moves with
                    // the ground): dashed and drawn on top, it stays visible.
                    c.dashed = color.is_none();
                    self.spectrum.push(c);
                    self.spectrum_peaks.push(peak);
                }
            };
        add_spectrum("ground".into(), main, |s| &s.ground_accel, None);
        for (k, s) in timeline.samples.iter().enumerate() {
            let label = timeline.labels.get(k).cloned().unwrap_or_default();
            add_spectrum(
                format!("base, {label}"),
                s,
                |s| &s.base_accel,
                Some(model_color(k)),
            );
        }
    }
}

/// What the plots' curves depend on: the run and how much of it has been computed
/// (samples are only ever appended to a run, frames too).
#[derive(Debug, Clone, PartialEq)]
struct DataKey {
    generation: u64,
    frames: usize,
    samples: Vec<usize>,
}

impl DataKey {
    fn of(timeline: &super::Timeline) -> Self {
        Self {
            generation: timeline.generation,
            frames: timeline.frames.len(),
            samples: timeline.samples.iter().map(Samples::len).collect(),
        }
    }
}

/// [`PlotData`] kept between frames: a replay redraws ~20–60 times a second, and every
/// redraw thinned each curve, low-passed each roof and transformed each spectrum again
/// (~1.9 ms for the default scene's two 31 s models, on the window's thread). Recomputed
/// only when the run has grown (or changed); the spectra also when they follow a moving
/// cursor.
#[derive(Debug, Default)]
pub struct PlotCache {
    key: Option<DataKey>,
    /// The cursor the spectra were cut at (`None`: over everything computed).
    spectra_until: Option<u64>,
    data: std::sync::Arc<PlotData>,
}

impl PlotCache {
    /// The same as [`PlotData::of`], from the kept data when nothing it depends on changed.
    pub fn get(
        &mut self,
        timeline: &super::Timeline,
        cursor: f64,
        to_cursor: bool,
    ) -> std::sync::Arc<PlotData> {
        let key = DataKey::of(timeline);
        let until = to_cursor.then_some(cursor.to_bits());
        if self.key.as_ref() != Some(&key) {
            self.data = std::sync::Arc::new(PlotData::of(timeline, cursor, to_cursor));
        } else if self.spectra_until != until {
            let data = std::sync::Arc::make_mut(&mut self.data);
            data.add_spectra(timeline, cursor, to_cursor);
        }
        self.key = Some(key);
        self.spectra_until = until;
        std::sync::Arc::clone(&self.data)
    }
}

/// A number with about three significant digits for tick labels (no "0.000000001"):
/// below 10⁻⁴ a step's ticks read "5e-10", "1.5e-6" (decimals would all read "0.000000").
fn tick(value: f64, step: f64) -> String {
    if value.abs() < 1e-3 * step.abs() {
        return "0".into();
    }
    if step.abs() < 1e-4 {
        let digits = (value.abs().log10().floor() - step.abs().log10().floor()).clamp(0.0, 6.0);
        return crate::post::trim_mantissa(&format!("{value:.prec$e}", prec = digits as usize));
    }
    let decimals = (-(step.abs().log10().floor()) as i64).clamp(0, 6) as usize;
    format!("{value:.decimals$}")
}

/// Grid lines at 1, 2 or 5 × 10ⁿ, about `lines` across the visible range (the default
/// powers of ten left a range of ±0.8 with a single "0" label).
fn nice_grid(lines: f64) -> impl Fn(egui_plot::GridInput) -> Vec<egui_plot::GridMark> {
    egui_plot::uniform_grid_spacer(move |input| {
        let range = (input.bounds.1 - input.bounds.0).abs().max(1e-12);
        let raw = range / lines;
        let p = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * p)
            .find(|&s| s >= raw)
            .unwrap_or(10.0 * p);
        [step / 5.0, step, 5.0 * step]
    })
}

/// Draws one plot: legend row, the plot with units, the cursor line, a hover readout.
fn plot(
    ui: &mut egui::Ui,
    id: &str,
    curves: &[Curve],
    units: (&str, &str),
    cursor: Option<(f64, f64)>,
    peak_fmt: &dyn Fn(&Curve) -> String,
    height: f32,
) {
    let text_color = ui.visuals().text_color();
    ui.horizontal_wrapped(|ui| {
        for c in curves {
            let color = c.color.unwrap_or(text_color);
            let (r, painter) = ui.allocate_painter(egui::vec2(18.0, 12.0), egui::Sense::hover());
            let y = r.rect.center().y;
            let stroke = egui::Stroke::new(2.5, color);
            if c.dashed {
                painter.add(egui::Shape::dashed_line(
                    &[egui::pos2(r.rect.left(), y), egui::pos2(r.rect.right(), y)],
                    stroke,
                    4.0,
                    3.0,
                ));
            } else {
                painter.line_segment(
                    [egui::pos2(r.rect.left(), y), egui::pos2(r.rect.right(), y)],
                    stroke,
                );
            }
            ui.label(egui::RichText::new(format!("{} {}", c.name, peak_fmt(c))).small());
        }
    });
    let (x_unit, y_unit) = (units.0.to_string(), units.1.to_string());
    let response = Plot::new(id)
        .height(height)
        .x_axis_label(x_unit.clone())
        .y_axis_label(y_unit.clone())
        .y_axis_min_width(44.0)
        .x_grid_spacer(nice_grid(6.0))
        .y_grid_spacer(nice_grid(4.0))
        .x_axis_formatter(|m, _| tick(m.value, m.step_size))
        .y_axis_formatter(|m, _| tick(m.value, m.step_size))
        .label_formatter(|_| None)
        .show_x(false)
        .show_y(false)
        .allow_scroll(false)
        .allow_zoom(false)
        .allow_drag(false)
        .allow_boxed_zoom(false)
        // No fill, only a frame: the panel colour shows through. Under a software
        // rasteriser egui's fill of the three open plots cost ~7 ms of the ~75 ms of CPU a
        // frame takes at 1600 × 900 (docs/performance-log.md, stop 56).
        .show_background(false)
        .auto_bounds(true)
        .include_x(0.0)
        .include_x(cursor.map_or(0.0, |c| c.1))
        .show(ui, |p| {
            let (solid, dashed): (Vec<&Curve>, Vec<&Curve>) =
                curves.iter().partition(|c| !c.dashed);
            for c in solid.into_iter().chain(dashed) {
                let mut line = Line::new(c.name.clone(), PlotPoints::new(c.points.clone()))
                    .color(c.color.unwrap_or(text_color))
                    .width(if c.color.is_none() { 1.0 } else { 1.5 });
                if c.dashed {
                    line = line.style(LineStyle::dashed_loose());
                }
                p.line(line);
            }
            if let Some((t, _)) = cursor {
                p.vline(
                    VLine::new("time cursor", t)
                        .color(egui::Color32::GRAY)
                        .width(1.0),
                );
            }
        });
    ui.painter().rect_stroke(
        *response.transform.frame(),
        2.0,
        ui.visuals().widgets.noninteractive.bg_stroke,
        egui::StrokeKind::Inside,
    );
    if let Some(pos) = response.response.hover_pos() {
        let x = response.transform.value_from_position(pos).x;
        response.response.on_hover_ui_at_pointer(|ui| {
            ui.label(egui::RichText::new(format!("{x:.3} {x_unit}")).strong());
            for c in curves {
                if let Some(y) = value_at(&c.points, x) {
                    ui.colored_label(
                        c.color.unwrap_or(text_color),
                        format!("{}: {} {y_unit}", c.name, crate::post::format_number(y)),
                    );
                }
            }
        });
    }
}

/// Linear interpolation of `points` (increasing x) at `x`.
fn value_at(points: &[[f64; 2]], x: f64) -> Option<f64> {
    let k = points.partition_point(|p| p[0] < x);
    if k == 0 || k >= points.len() {
        return None;
    }
    let (a, b) = (points[k - 1], points[k]);
    let w = if b[0] > a[0] {
        (x - a[0]) / (b[0] - a[0])
    } else {
        0.0
    };
    Some(a[1] + w * (b[1] - a[1]))
}

/// Draws every plot section.
pub fn plots_ui(state: &mut AppState, ui: &mut egui::Ui) {
    let t = state.play_time;
    let data = state
        .plot_cache
        .get(&state.timeline, t, state.view.spectrum_to_cursor);
    let cursor = Some((t, state.timeline.duration));
    let height = (ui.available_height() / 4.5).clamp(110.0, 220.0);
    let peak_m = |c: &Curve| format!("(peak {})", crate::post::format_number(c.peak));
    egui::CollapsingHeader::new("accelerations")
        .default_open(true)
        .show(ui, |ui| {
            plot(
                ui,
                "accel",
                &data.accel,
                ("s", "g"),
                cursor,
                &accel_legend,
                height,
            )
        });
    egui::CollapsingHeader::new("slip of the base")
        .default_open(true)
        .show(ui, |ui| {
            plot(ui, "slip", &data.slip, ("s", "m"), cursor, &peak_m, height)
        });
    // A lone block has no drift: no empty plot for it.
    if !data.drift.is_empty() {
        egui::CollapsingHeader::new("roof drift (relative to the base)")
            .default_open(true)
            .show(ui, |ui| {
                plot(
                    ui,
                    "drift",
                    &data.drift,
                    ("s", "m"),
                    cursor,
                    &peak_m,
                    height,
                )
            });
    }
    egui::CollapsingHeader::new("Fourier spectra of the accelerations")
        .default_open(false)
        .show(ui, |ui| {
            ui.checkbox(
                &mut state.view.spectrum_to_cursor,
                "only up to the time cursor",
            )
            .on_hover_text("the spectrum of the motion so far (else of the whole run computed)");
            let peaks = data.spectrum_peaks.clone();
            let names: Vec<String> = data.spectrum.iter().map(|c| c.name.clone()).collect();
            let peak_hz = move |c: &Curve| {
                names
                    .iter()
                    .position(|n| *n == c.name)
                    .and_then(|k| peaks.get(k))
                    .map_or(String::new(), |f| format!("(peak {f:.2} Hz)"))
            };
            plot(
                ui,
                "spectra",
                &data.spectrum,
                ("Hz", "m/s"),
                None,
                &peak_hz,
                height,
            );
        });
    egui::CollapsingHeader::new("friction force against slip (hysteresis)")
        .default_open(false)
        .show(ui, |ui| hysteresis(state, ui, height));
    egui::CollapsingHeader::new("where the energy goes")
        .default_open(false)
        .show(ui, |ui| energy(state, ui, height));
}

fn hysteresis(state: &AppState, ui: &mut egui::Ui, height: f32) {
    let t = state.play_time;
    let label = state.timeline.labels.first().cloned().unwrap_or_default();
    let pts: Vec<[f64; 2]> = state
        .timeline
        .frames
        .iter()
        .filter(|f| f.time <= t + 1e-9)
        .filter_map(|f| {
            f.models
                .first()
                .map(|m| [m.probes.slip, m.probes.joint_force / 1e3])
        })
        .collect();
    let c = curve(format!("joint force, {label}"), pts, Some(model_color(0)));
    let peak = |c: &Curve| format!("(peak {} kN/m)", crate::post::format_number(c.peak));
    ui.label(
        egui::RichText::new("the force the ground passes to the base (per metre of frame), against slip; flat tops = sliding at ρ × weight")
            .small()
            .weak(),
    );
    plot_xy(ui, "hysteresis", &[c], ("slip, m", "kN/m"), &peak, height);
}

/// A plot whose x axis is not time (no cursor line).
fn plot_xy(
    ui: &mut egui::Ui,
    id: &str,
    curves: &[Curve],
    units: (&str, &str),
    peak_fmt: &dyn Fn(&Curve) -> String,
    height: f32,
) {
    plot(ui, id, curves, units, None, peak_fmt, height);
}

fn energy(state: &AppState, ui: &mut egui::Ui, height: f32) {
    let t = state.play_time;
    let models = state.timeline.frames.first().map_or(0, |f| f.models.len());
    for m in 0..models {
        let label = state.timeline.labels.get(m).cloned().unwrap_or_default();
        let series = |f: fn(&crate::dda::EnergyTerms) -> f64| -> Vec<[f64; 2]> {
            state
                .timeline
                .frames
                .iter()
                .filter(|fs| fs.time <= t + 1e-9)
                .filter_map(|fs| {
                    fs.models
                        .get(m)
                        .map(|x| [fs.time, f(&x.probes.energy) / 1e3])
                })
                .collect()
        };
        let mut curves = vec![
            curve("input".into(), series(|x| x.input_work), None),
            curve(
                "kinetic".into(),
                series(|x| x.kinetic),
                Some(MODEL_COLORS[0]),
            ),
            curve("strain".into(), series(|x| x.strain), Some(MODEL_COLORS[2])),
            curve(
                "friction".into(),
                series(|x| x.friction_dissipated),
                Some(MODEL_COLORS[1]),
            ),
        ];
        let impacts = series(|x| x.impact_dissipated);
        if impacts.iter().any(|p| p[1] > 0.0) {
            curves.push(curve("impacts".into(), impacts, Some(MODEL_COLORS[3])));
        }
        curves.push(curve(
            "numerical".into(),
            series(|x| x.residual()),
            Some(egui::Color32::from_rgb(150, 150, 150)),
        ));
        ui.label(egui::RichText::new(label).strong());
        let peak = |c: &Curve| {
            format!(
                "({} kJ/m)",
                crate::post::format_number(c.points.last().map_or(0.0, |p| p[1]))
            )
        };
        plot(
            ui,
            &format!("energy{m}"),
            &curves,
            ("s", "kJ/m"),
            Some((t, state.timeline.duration)),
            &peak,
            height,
        );
    }
}

impl AppState {
    /// Writes what the plots show into the export folder: `series.csv` and `spectrum.csv`.
    pub fn export_data(&mut self) {
        let dir = std::path::PathBuf::from(&self.export_dir);
        let data = PlotData::of(&self.timeline, self.play_time, self.view.spectrum_to_cursor);
        match write_plot_data(&dir, &self.timeline, &data) {
            Ok(()) => self.say(format!(
                "wrote series.csv and spectrum.csv to {}",
                dir.display()
            )),
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

/// Writes `series.csv` (the full-rate time histories computed: time, ground acceleration,
/// and per model roof and base acceleration, slip and drift, named by model) and
/// `spectrum.csv` (`frequency_hz`, then one column per spectrum curve, named as in the
/// legend) into `dir`.
pub fn write_plot_data(
    dir: &std::path::Path,
    timeline: &super::Timeline,
    data: &PlotData,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut header = vec!["time_s".to_string(), "ground_accel_g".to_string()];
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let main = timeline.samples.first();
    let n = main.map_or(0, Samples::len);
    if let Some(s) = main {
        columns.push(s.time[..n].to_vec());
        columns.push(s.ground_accel[..n].iter().map(|a| a / G).collect());
    }
    let times = main.map_or(&[][..], |s| &s.time[..n]);
    for (k, s) in timeline.samples.iter().enumerate() {
        let label = timeline.labels.get(k).cloned().unwrap_or_default();
        for (name, col, scale) in [
            ("roof_accel_g", &s.roof_accel, 1.0 / G),
            ("base_accel_g", &s.base_accel, 1.0 / G),
            ("slip_m", &s.slip, 1.0),
            ("drift_m", &s.drift, 1.0),
        ] {
            header.push(format!("{name} ({label})"));
            // Models step at their own times (events, cuts): interpolate onto the first's.
            columns.push(
                crate::post::spectrum::interpolate(&s.time, col, times)
                    .into_iter()
                    .map(|v| v * scale)
                    .collect(),
            );
        }
    }
    let table = |names: Vec<String>, columns: Vec<Vec<f64>>| crate::post::history::History {
        names,
        columns,
    };
    table(header, columns).write_csv(&dir.join("series.csv"))?;
    // The spectra share one frequency grid (same samples, same resampling).
    let mut header = vec!["frequency_hz".to_string()];
    let mut columns = Vec::new();
    if let Some(first) = data.spectrum.first() {
        columns.push(first.points.iter().map(|p| p[0]).collect::<Vec<f64>>());
    }
    for c in &data.spectrum {
        header.push(c.name.clone());
        columns.push(c.points.iter().map(|p| p[1]).collect());
    }
    table(header, columns).write_csv(&dir.join("spectrum.csv"))
}

#[cfg(test)]
mod tests {
    use super::tick;

    /// A wall's slip of 5e-10 m had every tick read "0.000000".
    #[test]
    fn tiny_ticks_read_in_scientific_notation() {
        assert_eq!(tick(0.5, 0.5), "0.5");
        assert_eq!(tick(0.0002, 0.0001), "0.0002");
        assert_eq!(tick(1e-6, 5e-7), "1e-6");
        assert_eq!(tick(1.5e-6, 5e-7), "1.5e-6");
        assert_eq!(tick(-5e-10, 5e-10), "-5e-10");
        assert_eq!(tick(1e-20, 5e-10), "0");
    }
}
