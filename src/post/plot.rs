//! A small declarative figure library on plotters: every PNG the program writes.
//!
//! Text is drawn with an embedded DejaVu Sans (registered once with plotters' ab_glyph
//! support), so figures render on machines without fonts or fontconfig. Log axes are drawn
//! as linear axes of log10 values with decade labels, which keeps a single code path.

use std::path::Path;
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::{Error, Result};

static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
const FONT: &str = "dejavu";

fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(Error::Scene(
            "the embedded plot font could not be loaded".into(),
        ))
    }
}

/// Colours for series, chosen to stay distinct in print and for colour-blind readers
/// (Okabe–Ito palette).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline.
    Line,
    /// Circles at the points.
    Markers,
    /// Cross markers at the points.
    Crosses,
}

/// One data series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label (empty: not in the legend).
    pub label: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// Line or markers.
    pub style: Style,
    /// Index into [`PALETTE`].
    pub color: usize,
}

impl Series {
    /// A line series.
    pub fn line(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, color: usize) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style: Style::Line,
            color,
        }
    }

    /// A marker series.
    pub fn markers(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, color: usize) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style: Style::Markers,
            color,
        }
    }
}

/// One panel (a set of axes).
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Title above the axes.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// Fixed x range (data units); automatic when `None`.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range (data units); automatic when `None`.
    pub y_range: Option<(f64, f64)>,
    /// Series.
    pub series: Vec<Series>,
    /// Horizontal reference lines (data units).
    pub hlines: Vec<f64>,
    /// Short notes written in the panel's top-left corner.
    pub notes: Vec<String>,
    /// Where the legend goes: it should cover the corner the data leave empty.
    pub legend: LegendCorner,
}

/// A corner of a panel, for its legend.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LegendCorner {
    /// Top right (the default: most responses decay or stay level).
    #[default]
    UpperRight,
    /// Top left (for data that rise to the right, like cost against size).
    UpperLeft,
}

/// A figure: a title and a grid of panels.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title across the top.
    pub title: String,
    /// Rows of panels.
    pub rows: usize,
    /// Columns of panels.
    pub cols: usize,
    /// Panels, row-major.
    pub panels: Vec<Panel>,
}

fn transform(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() {
        return None;
    }
    if log {
        if v > 0.0 { Some(v.log10()) } else { None }
    } else {
        Some(v)
    }
}

/// Range of the transformed data with some padding; log ranges snap to decades.
fn axis_range(
    values: impl Iterator<Item = f64>,
    log: bool,
    fixed: Option<(f64, f64)>,
) -> (f64, f64) {
    if let Some((a, b)) = fixed {
        let (a, b) = if log {
            (a.max(1e-300).log10(), b.max(1e-300).log10())
        } else {
            (a, b)
        };
        return (a, b);
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if log {
        let (a, b) = (lo.floor(), hi.ceil());
        return if b > a { (a, b) } else { (a - 1.0, b + 1.0) };
    }
    if hi - lo < 1e-12 * (1.0 + hi.abs()) {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

fn tick_label(v: f64, log: bool) -> String {
    if log {
        let p = 10f64.powf(v);
        if (0.01..1e4).contains(&p) {
            format!("{}", (p * 1e6).round() / 1e6)
        } else {
            format!("1e{}", v.round())
        }
    } else {
        let a = v.abs();
        // Ticks computed as sums of floats land on ±1e-17 instead of 0.
        if a < 1e-12 {
            return "0".into();
        }
        if a != 0.0 && !(1e-3..1e5).contains(&a) {
            format!("{v:.1e}")
        } else {
            format!("{}", (v * 1e6).round() / 1e6)
        }
    }
}

impl Figure {
    /// A figure with `rows × cols` empty panels.
    pub fn new(title: impl Into<String>, rows: usize, cols: usize) -> Self {
        Self {
            title: title.into(),
            rows,
            cols,
            panels: vec![Panel::default(); rows * cols],
        }
    }

    /// Draws the figure into a PNG file of `width × height` pixels.
    pub fn save_png(&self, path: &Path, width: u32, height: u32) -> Result<()> {
        register_font()?;
        let plot_err = |e: &dyn std::fmt::Display| {
            Error::output(path, format!("cannot draw or write the figure: {e}"))
        };
        if let Some(parent) = path.parent()
            && !parent.as_os_str().is_empty()
        {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        let root = BitMapBackend::new(path, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(&e))?;
        let root = root
            .titled(&self.title, (FONT, 22).into_font())
            .map_err(|e| plot_err(&e))?;
        let areas = root.split_evenly((self.rows.max(1), self.cols.max(1)));
        for (panel, area) in self.panels.iter().zip(areas.iter()) {
            draw_panel(panel, area).map_err(|e| plot_err(&e))?;
        }
        root.present().map_err(|e| plot_err(&e))?;
        Ok(())
    }
}

fn draw_panel<DB: DrawingBackend>(
    p: &Panel,
    area: &DrawingArea<DB, plotters::coord::Shift>,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let xs = p
        .series
        .iter()
        .flat_map(|s| s.x.iter().filter_map(|&v| transform(v, p.x_log)));
    let (x0, x1) = axis_range(xs, p.x_log, p.x_range);
    let ys = p
        .series
        .iter()
        .flat_map(|s| s.y.iter().filter_map(|&v| transform(v, p.y_log)))
        .chain(p.hlines.iter().filter_map(|&v| transform(v, p.y_log)));
    let (y0, y1) = axis_range(ys, p.y_log, p.y_range);
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, (FONT, 17).into_font())
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let x_ticks = if p.x_log {
        ((x1 - x0).round() as usize + 1).max(2)
    } else {
        8
    };
    let y_ticks = if p.y_log {
        ((y1 - y0).round() as usize + 1).max(2)
    } else {
        8
    };
    let (xl, yl) = (p.x_log, p.y_log);
    chart
        .configure_mesh()
        .x_labels(x_ticks)
        .y_labels(y_ticks)
        .x_label_formatter(&|v| tick_label(*v, xl))
        .y_label_formatter(&|v| tick_label(*v, yl))
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .label_style((FONT, 13).into_font())
        .axis_desc_style((FONT, 14).into_font())
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()?;
    for &h in &p.hlines {
        if let Some(hy) = transform(h, p.y_log) {
            chart.draw_series(LineSeries::new(
                vec![(x0, hy), (x1, hy)],
                RGBColor(150, 150, 150),
            ))?;
        }
    }
    let mut any_label = false;
    for s in &p.series {
        let color = PALETTE[s.color % PALETTE.len()];
        let pts: Vec<(f64, f64)> = s
            .x
            .iter()
            .zip(&s.y)
            .filter_map(|(&x, &y)| Some((transform(x, p.x_log)?, transform(y, p.y_log)?)))
            .filter(|&(x, y)| x >= x0 && x <= x1 && y >= y0 && y <= y1 || s.style == Style::Line)
            .collect();
        let anno = match s.style {
            // Thick polylines get miter spikes at sharp turns (dense, noisy histories):
            // draw those one pixel wide.
            Style::Line => {
                let width = if pts.len() > 300 { 1 } else { 2 };
                chart.draw_series(LineSeries::new(pts, color.stroke_width(width)))?
            }
            Style::Markers => chart.draw_series(
                pts.into_iter()
                    .map(|pt| Circle::new(pt, 4, color.stroke_width(2))),
            )?,
            Style::Crosses => chart.draw_series(
                pts.into_iter()
                    .map(|pt| Cross::new(pt, 4, color.stroke_width(2))),
            )?,
        };
        if !s.label.is_empty() {
            any_label = true;
            let style = s.style;
            anno.label(s.label.clone())
                .legend(move |(x, y)| match style {
                    Style::Line => {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                            .into_dyn()
                    }
                    Style::Markers => Circle::new((x + 9, y), 4, color.stroke_width(2)).into_dyn(),
                    Style::Crosses => Cross::new((x + 9, y), 4, color.stroke_width(2)).into_dyn(),
                });
        }
    }
    if any_label {
        chart
            .configure_series_labels()
            .position(match p.legend {
                LegendCorner::UpperRight => SeriesLabelPosition::UpperRight,
                LegendCorner::UpperLeft => SeriesLabelPosition::UpperLeft,
            })
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font((FONT, 12).into_font())
            .draw()?;
    }
    for (k, note) in p.notes.iter().enumerate() {
        let pos = chart.backend_coord(&(x0, y1));
        area.draw(&Text::new(
            note.clone(),
            (pos.0 + 8, pos.1 + 6 + 16 * k as i32),
            (FONT, 13).into_font(),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ranges_snap_to_decades_and_survive_bad_data() {
        let r = axis_range([0.05_f64.log10(), 7.0_f64.log10()].into_iter(), true, None);
        assert_eq!(r, (-2.0, 1.0));
        assert_eq!(axis_range(std::iter::empty(), false, None), (0.0, 1.0));
        let c = axis_range([3.0, 3.0].into_iter(), false, None);
        assert!(c.0 < 3.0 && c.1 > 3.0);
        assert_eq!(transform(-1.0, true), None);
        assert_eq!(transform(f64::NAN, false), None);
    }
}
