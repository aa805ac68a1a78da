//! The sweep table (one row per model and grid point), the error table of DDA against the
//! exact model, and the figures laid out like the paper's Figs 4–9.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::output::Staged;
use super::plot::{Figure, Series};
use crate::{Error, Result};

/// One run of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// `mass-spring` or `dda`.
    pub model: String,
    /// Mass ratio α.
    pub alpha: f64,
    /// Friction coefficient ρ.
    pub friction: f64,
    /// Ω/ω.
    pub freq_ratio: f64,
    /// Structural damping ratio ζ (0: undamped; tables written before `sweep --damping`
    /// have no such column and read as 0).
    #[serde(default)]
    pub damping: f64,
    /// max|u_s|/D.
    pub us_max_over_d: f64,
    /// max|u_r|/D.
    pub ur_max_over_d: f64,
    /// max|a_base|/a_g.
    pub abase_over_aground: f64,
    /// max|a_roof|/a_g.
    pub aroof_over_aground: f64,
    /// Time steps of the run.
    pub steps: u64,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// Relative energy residual.
    pub energy_residual_rel: f64,
    /// The run's harmonic amplitude, g (tables written before these run columns have
    /// none; `merge` compares what the rows have).
    #[serde(default)]
    pub amplitude_g: Option<f64>,
    /// The run's duration, s.
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// The DDA run's time step, s (empty for the exact model, which has none).
    #[serde(default)]
    pub dt_s: Option<f64>,
    /// The DDA run's integrator (empty for the exact model).
    #[serde(default)]
    pub integrator: Option<String>,
    /// Runs of the whole grid this row's sweep ran (or ran a shard of): the same in every
    /// row of one sweep, so that `merge` can tell a shard that was not given (empty in
    /// tables from before this column).
    #[serde(default)]
    pub grid_runs: Option<u64>,
}

/// The four metrics by name, in the paper's order.
pub const METRICS: [&str; 4] = [
    "us_max_over_d",
    "ur_max_over_d",
    "abase_over_aground",
    "aroof_over_aground",
];

impl SweepRow {
    /// The columns of `sweep.csv`, in order.
    pub const COLUMNS: [&'static str; 17] = [
        "model",
        "alpha",
        "friction",
        "freq_ratio",
        "damping",
        "us_max_over_d",
        "ur_max_over_d",
        "abase_over_aground",
        "aroof_over_aground",
        "steps",
        "wall_time_s",
        "energy_residual_rel",
        "amplitude_g",
        "duration_s",
        "dt_s",
        "integrator",
        "grid_runs",
    ];

    /// The run columns, added after `energy_residual_rel` (tables from before them end
    /// there).
    const RUN_COLUMNS: [&'static str; 4] = ["amplitude_g", "duration_s", "dt_s", "integrator"];

    /// The last column, added after the run columns (tables from before it end at
    /// `integrator`).
    const GRID_COLUMN: &'static str = "grid_runs";

    /// The ranges a row must be in to be used: known model, α ∈ (0, 1), finite ρ ≥ 0,
    /// finite Ω/ω > 0, finite metrics ≥ 0, at least one step, finite wall time and energy
    /// residual.
    pub fn check(&self) -> std::result::Result<(), String> {
        if !matches!(self.model.as_str(), "mass-spring" | "dda") {
            return Err(format!(
                "unknown model '{}' (known: mass-spring, dda)",
                self.model
            ));
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(format!("alpha {} is outside (0, 1)", self.alpha));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(format!(
                "friction {} must be finite and >= 0",
                self.friction
            ));
        }
        if !(0.0..1.0).contains(&self.damping) {
            return Err(format!("damping {} is outside [0, 1)", self.damping));
        }
        if !(self.freq_ratio.is_finite() && self.freq_ratio > 0.0) {
            return Err(format!(
                "freq_ratio {} must be finite and > 0",
                self.freq_ratio
            ));
        }
        for (k, name) in METRICS.iter().enumerate() {
            let v = self.metric(k);
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} {v} must be finite and >= 0"));
            }
        }
        if self.steps == 0 {
            return Err("steps must be at least 1".into());
        }
        if !(self.wall_time_s.is_finite() && self.wall_time_s >= 0.0) {
            return Err(format!(
                "wall_time_s {} must be finite and >= 0",
                self.wall_time_s
            ));
        }
        if !self.energy_residual_rel.is_finite() {
            return Err(format!(
                "energy_residual_rel {} must be finite",
                self.energy_residual_rel
            ));
        }
        Ok(())
    }

    /// A metric by its name in [`METRICS`].
    pub fn metric(&self, k: usize) -> f64 {
        match k {
            0 => self.us_max_over_d,
            1 => self.ur_max_over_d,
            2 => self.abase_over_aground,
            _ => self.aroof_over_aground,
        }
    }
}

/// Writes the rows as CSV with a header.
pub fn write_sweep_csv(path: &Path, rows: &[SweepRow]) -> Result<()> {
    let csv_error = |e: csv::Error| Error::output(path, format!("cannot write the table: {e}"));
    let mut w = csv::Writer::from_path(path).map_err(csv_error)?;
    if rows.is_empty() {
        // An empty table still has its header, so that `merge` can read it.
        w.write_record(SweepRow::COLUMNS).map_err(csv_error)?;
    }
    for r in rows {
        w.serialize(r).map_err(csv_error)?;
    }
    w.flush().map_err(|e| Error::io(path, e))
}

/// A row's deserialisation error named by its column and the value found there (the CSV
/// reader's own says "field 2").
fn field_error(e: &csv::Error, headers: &csv::StringRecord, rec: &csv::StringRecord) -> String {
    let csv::ErrorKind::Deserialize { err, .. } = e.kind() else {
        return e.to_string();
    };
    match err.field().map(|i| i as usize) {
        Some(i) => format!(
            "column '{}': {} (got '{}')",
            headers.get(i).unwrap_or("?"),
            err.kind(),
            rec.get(i).unwrap_or("")
        ),
        None => err.to_string(),
    }
}

/// Reads a sweep CSV and checks every row (known model, α in (0, 1), finite ρ ≥ 0 and
/// Ω/ω > 0, finite non-negative metrics); errors name the file and line. A table with
/// only its header (an empty shard) has no rows; a file without the header is refused.
pub fn read_sweep_csv(path: &Path) -> Result<Vec<SweepRow>> {
    let text = crate::limits::read_text(path, crate::limits::MAX_TABLE_FILE_BYTES, "sweep table")?;
    let label = path.display().to_string();
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    // The reader counts a CRLF row's line wrongly (a spreadsheet's or Python's table was
    // reported at line 1 for its second row): read every row ending as a newline.
    let text = text.replace("\r\n", "\n");
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = r
        .headers()
        .map_err(|e| Error::parse(&label, 1, e.to_string()))?
        .iter()
        .map(str::to_string)
        .collect();
    // Tables from before the grid column are read without it, those from before the
    // run columns without them, and those from before the damping column as undamped.
    let without_grid = || {
        SweepRow::COLUMNS
            .iter()
            .filter(|c| **c != SweepRow::GRID_COLUMN)
    };
    let without_run = || without_grid().filter(|c| !SweepRow::RUN_COLUMNS.contains(c));
    let undamped = || without_run().filter(|c| **c != "damping");
    if header != SweepRow::COLUMNS
        && !header.iter().eq(without_grid())
        && !header.iter().eq(without_run())
        && !header.iter().eq(undamped())
    {
        return Err(Error::parse(
            &label,
            1,
            format!(
                "not a sweep table: the header must be '{}', got '{}'",
                SweepRow::COLUMNS.join(","),
                header.join(",")
            ),
        ));
    }
    let headers = csv::StringRecord::from(header);
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line() as usize);
            Error::parse(&label, line, e.to_string())
        })?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let row: SweepRow = rec
            .deserialize(Some(&headers))
            .map_err(|e| Error::parse(&label, line, field_error(&e, &headers, &rec)))?;
        row.check().map_err(|m| Error::parse(&label, line, m))?;
        rows.push(row);
    }
    Ok(rows)
}

/// Statistics of one metric's relative errors.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MetricErrors {
    /// Metric name.
    pub name: String,
    /// Matched grid points.
    pub count: usize,
    /// Median relative error.
    pub median: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Largest.
    pub max: f64,
    /// Where the largest occurred: (α, ρ, Ω/ω).
    pub worst: (f64, f64, f64),
}

/// DDA against the exact model over a sweep.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ErrorTable {
    /// One entry per metric.
    pub metrics: Vec<MetricErrors>,
    /// The floor used in the relative errors (normalised units).
    pub floor: f64,
    /// Grid points with a DDA row but no mass-spring row, or the reverse.
    pub unmatched: usize,
}

type Key = (u64, u64, u64, u64);

fn key(r: &SweepRow) -> Key {
    (
        r.alpha.to_bits(),
        r.friction.to_bits(),
        r.freq_ratio.to_bits(),
        r.damping.to_bits(),
    )
}

/// The one damping ratio of a sweep's rows; an error naming both when the rows mix two
/// (the figures and the error table are of one structure: shards of different sweeps
/// must not be merged into one).
pub fn common_damping(rows: &[SweepRow]) -> std::result::Result<f64, String> {
    let first = rows.first().map_or(0.0, |r| r.damping);
    match rows.iter().find(|r| r.damping != first) {
        Some(r) => Err(format!(
            "the rows mix damping ratios {first} and {}; a sweep table is of one ζ",
            r.damping
        )),
        None => Ok(first),
    }
}

/// Checks that the rows come from runs of one set-up: the same amplitude and duration,
/// and per model the same time step and integrator (shards of one sweep share them; a
/// shard run with another `--duration` or `--dt` would otherwise be merged without a
/// word). Rows without the run columns (older tables) are not compared.
pub fn common_run(rows: &[SweepRow]) -> std::result::Result<(), String> {
    fn same<T: PartialEq + std::fmt::Debug>(
        rows: &[SweepRow],
        what: &str,
        value: impl Fn(&SweepRow) -> Option<T>,
    ) -> std::result::Result<(), String> {
        let mut values = rows.iter().filter_map(|r| value(r).map(|v| (r, v)));
        let Some((_, first)) = values.next() else {
            return Ok(());
        };
        match values.find(|(_, v)| *v != first) {
            Some((r, v)) => Err(format!(
                "the rows mix runs of {what} {first:?} and {v:?} ({} α={} ρ={} Ω/ω={}); the \
                 shards of one sweep share --amplitude-g, --duration, --dt and --integrator",
                r.model, r.alpha, r.friction, r.freq_ratio
            )),
            None => Ok(()),
        }
    }
    same(rows, "amplitude_g", |r| r.amplitude_g)?;
    same(rows, "duration_s", |r| r.duration_s)?;
    for model in ["dda", "mass-spring"] {
        let of_model: Vec<SweepRow> = rows.iter().filter(|r| r.model == model).cloned().collect();
        same(&of_model, "dt_s", |r| r.dt_s)?;
        same(&of_model, "integrator", |r| r.integrator.clone())?;
    }
    Ok(())
}

/// Checks that the rows (distinct grid points, see `merge`) are every run of their grid:
/// all of a sweep's rows carry its grid's size, so a shard that was not given, or a shard
/// whose runs failed, shows as rows missing. Rows without the column (older tables) are
/// not checked.
pub fn whole_grid(rows: &[SweepRow]) -> std::result::Result<(), String> {
    let sizes: std::collections::BTreeSet<u64> = rows.iter().filter_map(|r| r.grid_runs).collect();
    if sizes.len() > 1 {
        return Err(format!(
            "the rows come from grids of different sizes ({} runs): shards of one sweep share \
             its --alpha, --friction and --freq-ratios",
            sizes
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    match sizes.first() {
        Some(&size) if rows.iter().all(|r| r.grid_runs.is_some()) && rows.len() as u64 != size => {
            Err(format!(
                "the inputs hold {} of the grid's {size} runs: a shard is missing (or some of \
                 its runs failed); give every shard's sweep.csv",
                rows.len()
            ))
        }
        _ => Ok(()),
    }
}

/// " (ζ = 2 %)" for a damped sweep, "" for an undamped one: added to figure titles.
fn damping_label(zeta: f64) -> String {
    if zeta > 0.0 {
        format!(", ζ = {} %", 100.0 * zeta)
    } else {
        String::new()
    }
}

/// Value at quantile q of sorted data (linear interpolation).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

/// Relative errors |dda − exact| / max(|exact|, floor) at every matched grid point.
pub fn error_table(rows: &[SweepRow], floor: f64) -> ErrorTable {
    let exact: BTreeMap<Key, &SweepRow> = rows
        .iter()
        .filter(|r| r.model == "mass-spring")
        .map(|r| (key(r), r))
        .collect();
    let dda: BTreeMap<Key, &SweepRow> = rows
        .iter()
        .filter(|r| r.model == "dda")
        .map(|r| (key(r), r))
        .collect();
    let unmatched = exact.keys().filter(|k| !dda.contains_key(k)).count()
        + dda.keys().filter(|k| !exact.contains_key(k)).count();
    let mut metrics = Vec::new();
    for (m, name) in METRICS.iter().enumerate() {
        let mut errs: Vec<(f64, (f64, f64, f64))> = Vec::new();
        for (k, d) in &dda {
            if let Some(e) = exact.get(k) {
                let (a, b) = (d.metric(m), e.metric(m));
                let err = (a - b).abs() / b.abs().max(floor);
                errs.push((
                    if err.is_finite() { err } else { f64::INFINITY },
                    (d.alpha, d.friction, d.freq_ratio),
                ));
            }
        }
        let mut sorted: Vec<f64> = errs.iter().map(|e| e.0).collect();
        sorted.sort_by(f64::total_cmp);
        let worst = errs
            .iter()
            .copied()
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or((f64::NAN, f64::NAN, f64::NAN), |e| e.1);
        metrics.push(MetricErrors {
            name: name.to_string(),
            count: sorted.len(),
            median: quantile(&sorted, 0.5),
            p90: quantile(&sorted, 0.9),
            max: sorted.last().copied().unwrap_or(f64::NAN),
            worst,
        });
    }
    ErrorTable {
        metrics,
        floor,
        unmatched,
    }
}

impl fmt::Display for ErrorTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "| metric | points | median | 90th pct | max | worst at (α, ρ, Ω/ω) |"
        )?;
        writeln!(f, "|---|---:|---:|---:|---:|---|")?;
        for m in &self.metrics {
            if m.count == 0 {
                writeln!(f, "| {} | 0 | – | – | – | – |", m.name)?;
                continue;
            }
            writeln!(
                f,
                "| {} | {} | {:.3} % | {:.3} % | {:.3} % | ({}, {}, {:.3}) |",
                m.name,
                m.count,
                100.0 * m.median,
                100.0 * m.p90,
                100.0 * m.max,
                m.worst.0,
                m.worst.1,
                m.worst.2
            )?;
        }
        writeln!(
            f,
            "\nRelative errors |DDA − exact| / max(|exact|, {}).",
            self.floor
        )?;
        if self.unmatched > 0 {
            writeln!(
                f,
                "{} grid points had only one of the two models.",
                self.unmatched
            )?;
        }
        Ok(())
    }
}

/// Writes figures laid out like the paper's Figs 4–9: per α, a displacement figure
/// ((a) |u_s|/D, (b) |u_r|/D) and an acceleration figure ((a) |a_base|/a_g, (b) |a_roof|/a_g)
/// against Ω/ω on log axes; exact model as lines, DDA as markers, one colour per ρ.
pub fn plot_paper_figures(rows: &[SweepRow], out: &mut Staged) -> Result<()> {
    let zeta = damping_label(rows.first().map_or(0.0, |r| r.damping));
    let mut alphas: Vec<f64> = rows.iter().map(|r| r.alpha).collect();
    alphas.sort_by(f64::total_cmp);
    alphas.dedup();
    let mut frictions: Vec<f64> = rows.iter().map(|r| r.friction).collect();
    frictions.sort_by(f64::total_cmp);
    frictions.dedup();
    for &alpha in &alphas {
        // The paper's figure numbers for its three mass ratios; other α get their own names.
        let paper_fig = [(0.1, 4), (0.5, 6), (0.9, 8)]
            .iter()
            .find(|(a, _)| (a - alpha).abs() < 1e-12)
            .map(|p| p.1);
        for (kind, metrics, labels) in [
            (
                "displacements",
                [0usize, 1],
                ["(a) |u_s|max / D", "(b) |u_r|max / D"],
            ),
            (
                "accelerations",
                [2, 3],
                ["(a) |a_base|max / a_g", "(b) |a_roof|max / a_g"],
            ),
        ] {
            let (prefix, title) = match paper_fig {
                Some(f) => {
                    let n = if kind == "displacements" { f } else { f + 1 };
                    (format!("fig{n}_"), format!("Fig. {n}: "))
                }
                None => (String::new(), String::new()),
            };
            let mut fig = Figure::new(
                format!(
                    "{title}α = {alpha}{zeta}, DDA (markers) against the exact mass-spring model \
                     (lines)"
                ),
                1,
                2,
            );
            for (pi, &m) in metrics.iter().enumerate() {
                let panel = &mut fig.panels[pi];
                panel.title = labels[pi].to_string();
                panel.x_label = "Ω/ω".into();
                panel.y_label = labels[pi].split_once(' ').map_or("", |s| s.1).to_string();
                panel.x_log = true;
                panel.y_log = true;
                for (fi, &rho) in frictions.iter().enumerate() {
                    for (model, line) in [("mass-spring", true), ("dda", false)] {
                        let mut pts: Vec<(f64, f64)> = rows
                            .iter()
                            .filter(|r| r.alpha == alpha && r.friction == rho && r.model == model)
                            .map(|r| (r.freq_ratio, r.metric(m)))
                            .collect();
                        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                        let (x, y): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
                        if x.is_empty() {
                            continue;
                        }
                        panel.series.push(if line {
                            Series::line(format!("ρ = {rho}"), x, y, fi)
                        } else {
                            Series::markers("", x, y, fi)
                        });
                    }
                }
            }
            let path = out.path(&format!("{prefix}alpha{alpha}_{kind}.png"));
            fig.save_png(&path, 1400, 600)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(model: &str, ratio: f64, v: f64) -> SweepRow {
        SweepRow {
            model: model.into(),
            alpha: 0.5,
            friction: 0.1,
            freq_ratio: ratio,
            damping: 0.0,
            us_max_over_d: v,
            ur_max_over_d: v,
            abase_over_aground: v,
            aroof_over_aground: v,
            steps: 1,
            wall_time_s: 0.0,
            energy_residual_rel: 0.0,
            amplitude_g: Some(0.3),
            duration_s: Some(100.0),
            dt_s: (model == "dda").then_some(1e-3),
            integrator: (model == "dda").then(|| "generalized-alpha:0.5".into()),
            grid_runs: Some(2),
        }
    }

    /// Rows that are not their whole grid (a shard not given) are refused, as are rows
    /// of grids of different sizes; older rows without the column are not judged.
    #[test]
    fn a_missing_shard_is_told() {
        let rows = [row("mass-spring", 1.0, 1.0), row("dda", 1.0, 1.0)];
        assert!(whole_grid(&rows).is_ok());
        let half = |r: &SweepRow| SweepRow {
            grid_runs: Some(4),
            ..r.clone()
        };
        let e = whole_grid(&rows.iter().map(half).collect::<Vec<_>>()).unwrap_err();
        assert!(e.contains("2 of the grid's 4 runs"), "{e}");
        let mixed = [rows[0].clone(), half(&rows[1])];
        assert!(whole_grid(&mixed).unwrap_err().contains("different sizes"));
        let old = |r: &SweepRow| SweepRow {
            grid_runs: None,
            ..r.clone()
        };
        assert!(whole_grid(&[old(&rows[0])]).is_ok());
    }

    #[test]
    fn rows_of_other_run_set_ups_are_told_apart() {
        let rows = vec![row("dda", 1.0, 1.0), row("mass-spring", 1.0, 1.0)];
        assert_eq!(common_run(&rows), Ok(()));
        for change in [
            |r: &mut SweepRow| r.amplitude_g = Some(1.0),
            |r: &mut SweepRow| r.duration_s = Some(5.0),
            |r: &mut SweepRow| r.dt_s = Some(2e-3),
            |r: &mut SweepRow| r.integrator = Some("trapezoidal".into()),
        ] {
            let mut other = row("dda", 2.0, 1.0);
            change(&mut other);
            let mut mixed = rows.clone();
            mixed.push(other);
            assert!(common_run(&mixed).is_err());
        }
        // An older table's rows (no run columns) are not compared.
        let mut old = row("dda", 2.0, 1.0);
        (old.amplitude_g, old.duration_s, old.dt_s, old.integrator) = (None, None, None, None);
        assert_eq!(common_run(&[rows[0].clone(), old]), Ok(()));
    }

    #[test]
    fn error_table_statistics() {
        // Ten points with errors 1 %, 2 %, …, 10 %.
        let mut rows = Vec::new();
        for k in 1..=10 {
            let r = k as f64;
            rows.push(row("mass-spring", r, 1.0));
            rows.push(row("dda", r, 1.0 + 0.01 * r));
        }
        rows.push(row("dda", 99.0, 1.0));
        let t = error_table(&rows, 0.01);
        let m = &t.metrics[0];
        assert_eq!(m.count, 10);
        assert!((m.median - 0.055).abs() < 1e-12);
        assert!((m.p90 - 0.091).abs() < 1e-12);
        assert!((m.max - 0.10).abs() < 1e-12 && m.worst.2 == 10.0);
        assert_eq!(t.unmatched, 1);
        // The floor: an exact value of 0 against 0.005 is a 50 % error with floor 0.01.
        let t = error_table(
            &[row("mass-spring", 1.0, 0.0), row("dda", 1.0, 0.005)],
            0.01,
        );
        assert!((t.metrics[0].median - 0.5).abs() < 1e-12);
    }

    /// A table written before the damping column reads as undamped; a table mixing two
    /// damping ratios is refused by the checks of merge and plotting.
    #[test]
    fn damping_column_old_tables_and_mixes() {
        let dir = std::env::temp_dir().join(format!("slidebase-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let old = dir.join("old.csv");
        let header: Vec<&str> = SweepRow::COLUMNS
            .iter()
            .copied()
            .filter(|c| {
                *c != "damping" && !SweepRow::RUN_COLUMNS.contains(c) && *c != SweepRow::GRID_COLUMN
            })
            .collect();
        std::fs::write(
            &old,
            format!(
                "{}\ndda,0.5,0.1,2.0,1.0,1.0,1.0,1.0,10,0.1,0.0\n",
                header.join(",")
            ),
        )
        .unwrap();
        let rows = read_sweep_csv(&old).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].damping, 0.0);
        assert_eq!(rows[0].duration_s, None);
        // A table from before the grid column reads without it (merge does not judge it).
        let before_grid = dir.join("before-grid.csv");
        let header = &SweepRow::COLUMNS[..SweepRow::COLUMNS.len() - 1];
        std::fs::write(
            &before_grid,
            format!(
                "{}\ndda,0.5,0.1,2.0,0,1.0,1.0,1.0,1.0,10,0.1,0.0,0.3,100,0.001,hht\n",
                header.join(",")
            ),
        )
        .unwrap();
        let rows = read_sweep_csv(&before_grid).unwrap();
        assert_eq!((rows[0].grid_runs, rows[0].duration_s), (None, Some(100.0)));
        let new = dir.join("new.csv");
        let mut damped = row("dda", 2.0, 1.0);
        damped.damping = 0.05;
        write_sweep_csv(&new, std::slice::from_ref(&damped)).unwrap();
        assert_eq!(read_sweep_csv(&new).unwrap(), vec![damped.clone()]);
        assert_eq!(common_damping(std::slice::from_ref(&damped)), Ok(0.05));
        let err = common_damping(&[damped, row("dda", 1.0, 1.0)]).unwrap_err();
        assert!(err.contains("0.05") && err.contains("mix"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
