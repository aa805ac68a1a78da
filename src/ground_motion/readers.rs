//! Readers for accelerogram files: PEER `.AT2` (both header variants) and two-column text
//! (CSV or whitespace), with errors that name the file and line.

use std::path::Path;

use super::{Record, STANDARD_GRAVITY};
use crate::limits::{MAX_ACCEL_G, MAX_RECORD_FILE_BYTES, MAX_RECORD_SAMPLES, RECORD_DT_RANGE};
use crate::{Error, Result};

/// The text without a leading UTF-8 byte-order mark (spreadsheets write one).
fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// An acceleration in g from a record file, checked against [`MAX_ACCEL_G`].
fn accel_g(value: f64, file: &str, line: usize) -> Result<f64> {
    if value.abs() > MAX_ACCEL_G {
        return Err(Error::record(
            file,
            line,
            format!(
                "acceleration {} g is beyond ±{MAX_ACCEL_G} g (accelerations are in g; \
                 the largest ever recorded is about 4 g)",
                crate::error::show(value)
            ),
        ));
    }
    Ok(value * STANDARD_GRAVITY)
}

/// Checks a record's sample spacing against [`RECORD_DT_RANGE`].
fn check_dt(dt: f64, file: &str, line: usize) -> Result<()> {
    let (lo, hi) = RECORD_DT_RANGE;
    if !(dt.is_finite() && (lo..=hi).contains(&dt)) {
        return Err(Error::record(
            file,
            line,
            format!(
                "time step {} s is outside [{lo:e}, {hi}] s",
                crate::error::show(dt)
            ),
        ));
    }
    Ok(())
}

/// Parses a number as Fortran writes it (`-.123E-02`, `1.5D-03`), rejecting NaN and inf.
fn parse_number(token: &str) -> Option<f64> {
    let t = token.trim();
    let v: f64 = if t.contains(['D', 'd']) {
        t.replace(['D', 'd'], "E").parse().ok()?
    } else {
        t.parse().ok()?
    };
    v.is_finite().then_some(v)
}

/// Why a token is not a usable number: for the error message.
fn number_error(token: &str) -> String {
    match token.trim().replace(['D', 'd'], "E").parse::<f64>() {
        Ok(v) if !v.is_finite() => format!("value '{token}' is not finite"),
        _ => format!("'{token}' is not a number"),
    }
}

/// The number following `key` and an `=` sign on an upper-cased header line.
fn header_value(upper: &str, key: &str) -> Option<f64> {
    let start = upper.find(key)? + key.len();
    let rest = upper[start..].trim_start();
    let rest = rest.strip_prefix('=')?.trim_start();
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'E')))
        .unwrap_or(rest.len());
    parse_number(&rest[..end])
}

/// Refuses an AT2 file whose free header lines declare another quantity than acceleration
/// (a PEER `.VT2` or `.DT2` renamed) or another unit than g (`UNITS OF CM/SEC/SEC`): read
/// as g, 15 cm/s² became 15 g and a velocity ran as an acceleration without a word.
fn check_at2_quantity(header: &[&str], file: &str) -> Result<()> {
    for (k, line) in header.iter().enumerate() {
        let upper = line.trim().to_uppercase();
        let other_quantity = ["VELOCITY", "DISPLACEMENT"]
            .into_iter()
            .find(|q| upper.starts_with(q));
        let unit = upper
            .find("UNITS OF")
            .map(|at| upper[at + "UNITS OF".len()..].trim());
        let other_unit = unit.filter(|u| u.split_whitespace().next() != Some("G"));
        if other_quantity.is_some() || other_unit.is_some() {
            return Err(Error::record(
                file,
                k + 1,
                format!(
                    "the header declares '{}'; a record is read as ground acceleration in \
                     g (a PEER acceleration file says 'UNITS OF G'): convert it to g",
                    line.trim()
                ),
            ));
        }
    }
    Ok(())
}

/// Parses a PEER `.AT2` file: three free header lines, a fourth with the sample count and
/// step (`NPTS=  5372, DT=   .0100 SEC`, or the older `  4000   .01000   NPTS, DT`), then the
/// accelerations in g, any number per line. The first value is at t = 0.
pub fn parse_at2(text: &str, file_label: &str, name: &str) -> Result<Record> {
    let lines: Vec<&str> = without_bom(text).lines().collect();
    if lines.iter().all(|l| l.trim().is_empty()) {
        return Err(Error::record(file_label, 0, "the file is empty"));
    }
    if lines.len() < 4 {
        return Err(Error::record(
            file_label,
            lines.len(),
            "an AT2 file needs four header lines (the fourth gives NPTS and DT)",
        ));
    }
    check_at2_quantity(&lines[..3], file_label)?;
    let header = lines[3];
    let upper = header.to_uppercase();
    let (npts, dt) =
        if upper.contains("NPTS") && (upper.contains("NPTS=") || upper.contains("NPTS =")) {
            let npts = header_value(&upper, "NPTS").ok_or_else(|| {
                Error::record(
                    file_label,
                    4,
                    format!("cannot read NPTS from '{}'", header.trim()),
                )
            })?;
            let dt = header_value(&upper, "DT").ok_or_else(|| {
                Error::record(
                    file_label,
                    4,
                    format!("cannot read DT from '{}'", header.trim()),
                )
            })?;
            (npts, dt)
        } else if upper.contains("NPTS") {
            let tokens: Vec<&str> = header
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
                .collect();
            match (
                tokens.first().and_then(|t| parse_number(t)),
                tokens.get(1).and_then(|t| parse_number(t)),
            ) {
                (Some(n), Some(d)) => (n, d),
                _ => {
                    return Err(Error::record(
                        file_label,
                        4,
                        format!("expected 'count step NPTS, DT', got '{}'", header.trim()),
                    ));
                }
            }
        } else {
            return Err(Error::record(
                file_label,
                4,
                format!(
                    "the fourth header line must give NPTS and DT, got '{}'",
                    header.trim()
                ),
            ));
        };
    if !(npts >= 2.0 && npts.fract() == 0.0) {
        return Err(Error::record(
            file_label,
            4,
            format!("NPTS must be a whole number >= 2, got {npts}"),
        ));
    }
    // Checked before anything is allocated.
    if npts > MAX_RECORD_SAMPLES as f64 {
        return Err(Error::record(
            file_label,
            4,
            format!(
                "NPTS = {} is beyond the limit of {MAX_RECORD_SAMPLES} samples",
                crate::error::show(npts)
            ),
        ));
    }
    check_dt(dt, file_label, 4)?;
    let npts = npts as usize;
    // A header can promise more values than the file holds: reserve only what the text
    // could contain (each value takes at least two characters).
    let mut values = Vec::with_capacity(npts.min(text.len() / 2 + 1));
    for (k, line) in lines.iter().enumerate().skip(4) {
        for token in line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
        {
            let v = parse_number(token)
                .ok_or_else(|| Error::record(file_label, k + 1, number_error(token)))?;
            if values.len() == npts {
                return Err(Error::record(
                    file_label,
                    k + 1,
                    format!("more values than NPTS = {npts} (the header and the data disagree)"),
                ));
            }
            values.push(accel_g(v, file_label, k + 1)?);
        }
    }
    if values.len() != npts {
        return Err(Error::record(
            file_label,
            lines.len(),
            format!("NPTS = {npts} but the file has {} values", values.len()),
        ));
    }
    let provenance = lines[..3]
        .iter()
        .map(|l| l.trim())
        .collect::<Vec<_>>()
        .join(" / ");
    Ok(Record::new(name, dt, values)
        .map_err(|e| e.in_file(file_label))?
        .with_provenance(provenance)
        .with_source(file_label))
}

/// A header row: every field a word (a column name), none a number — so that a number
/// mistyped in the first row (`1.0e,0.3`) is an error, not a silently dropped sample.
fn is_header(fields: &[&str]) -> bool {
    !fields.is_empty()
        && fields.iter().all(|f| {
            let word = f.trim_matches(|c| c == '"' || c == '\'');
            word.chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
                && word.parse::<f64>().is_err()
        })
}

/// Refuses a header row whose acceleration column names another unit than g
/// (`accel_m_s2`, `acc_cm_s2`, `gal`) or another quantity (`velocity`, `disp_cm`): the
/// column is read in g, and `time_s,accel_m_s2` ran a record as 9.81 times itself.
fn check_column_units(fields: &[&str], file: &str, line: usize) -> Result<()> {
    let Some(column) = fields.get(1) else {
        return Ok(());
    };
    let lower = column
        .trim_matches(|c| c == '"' || c == '\'')
        .to_lowercase();
    // The name's words: `accel_m_s2` → accel, m, s2; `acc(cm/s^2)` → acc, cm, s, 2.
    let words: Vec<&str> = lower
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let has = |w: &str| words.contains(&w);
    let other_unit = has("m")
        || has("cm")
        || has("mm")
        || has("gal")
        || has("ft")
        || has("in")
        || has("ms2")
        || has("mps2");
    let other_quantity = words
        .iter()
        .any(|w| w.starts_with("vel") || w.starts_with("disp"));
    if other_unit || other_quantity {
        return Err(Error::record(
            file,
            line,
            format!(
                "the acceleration column is named '{column}'; it is read in g (a header such \
                 as `time_s,accel_g`): convert the record to g"
            ),
        ));
    }
    Ok(())
}

/// Parses two-column text: time (s) and acceleration (g), separated by commas, semicolons,
/// tabs or spaces; `#` comment lines (kept as provenance), blank lines and one header line
/// before the data are allowed. Times must increase uniformly from 0 (or from one step,
/// in which case a zero sample at t = 0 is implied).
pub fn parse_text(text: &str, file_label: &str, name: &str) -> Result<Record> {
    let mut comments = Vec::new();
    let mut rows: Vec<(usize, f64, f64)> = Vec::new();
    let mut header_seen = false;
    for (k, raw) in without_bom(text).lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() {
            continue;
        }
        if let Some(c) = line.strip_prefix('#') {
            comments.push(c.trim().to_string());
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .collect();
        if rows.is_empty() && !header_seen && is_header(&fields) {
            check_column_units(&fields, file_label, k + 1)?;
            header_seen = true;
            continue;
        }
        if fields.len() != 2 {
            return Err(Error::record(
                file_label,
                k + 1,
                format!(
                    "expected two columns (time, acceleration in g), found {}",
                    fields.len()
                ),
            ));
        }
        if rows.len() == MAX_RECORD_SAMPLES {
            return Err(Error::record(
                file_label,
                k + 1,
                format!("more than {MAX_RECORD_SAMPLES} samples, the limit of a record"),
            ));
        }
        let t = parse_number(fields[0])
            .ok_or_else(|| Error::record(file_label, k + 1, number_error(fields[0])))?;
        let a = parse_number(fields[1])
            .ok_or_else(|| Error::record(file_label, k + 1, number_error(fields[1])))?;
        let a = accel_g(a, file_label, k + 1)?;
        if let Some(&(_, tp, _)) = rows.last()
            && t <= tp
        {
            return Err(Error::record(
                file_label,
                k + 1,
                format!("time {t} does not increase (previous row: {tp})"),
            ));
        }
        rows.push((k + 1, t, a));
    }
    if rows.is_empty() {
        return Err(Error::record(file_label, 0, "the file has no data rows"));
    }
    if rows.len() < 2 {
        return Err(Error::record(
            file_label,
            rows[0].0,
            "a record needs at least two samples",
        ));
    }
    let t0 = rows[0].1;
    let first_step = rows[1].1 - t0;
    // Uniform sampling: every step within 1 % of the first one (times are often printed
    // with few digits, so exact equality is not expected).
    for w in rows.windows(2) {
        let step = w[1].1 - w[0].1;
        if (step - first_step).abs() > 0.01 * first_step {
            return Err(Error::record(
                file_label,
                w[1].0,
                format!(
                    "time step is not uniform: {step} s here, {first_step} s at the start (resample the record first)"
                ),
            ));
        }
    }
    // The mean step is the most accurate value when times carry rounding.
    let dt = (rows[rows.len() - 1].1 - t0) / (rows.len() - 1) as f64;
    check_dt(dt, file_label, rows[1].0)?;
    let mut accel: Vec<f64> = rows.iter().map(|r| r.2).collect();
    if t0.abs() > 0.01 * dt {
        if (t0 - dt).abs() <= 0.01 * dt {
            // The first sample is at one step: the record starts from rest at t = 0.
            accel.insert(0, 0.0);
        } else {
            return Err(Error::record(
                file_label,
                rows[0].0,
                format!(
                    "the record must start at t = 0 (or at one time step), but starts at {t0} s"
                ),
            ));
        }
    }
    Ok(Record::new(name, dt, accel)
        .map_err(|e| e.in_file(file_label))?
        .with_provenance(comments.join("\n"))
        .with_source(file_label))
}

/// Reads a record file: AT2 when the extension is `.at2` (any case) or the fourth line
/// mentions NPTS, two-column text otherwise. The record is named after the file stem.
pub fn read_record_file(path: &Path) -> Result<Record> {
    let text = crate::limits::read_text(path, MAX_RECORD_FILE_BYTES, "record")?;
    let label = path.display().to_string();
    let name = path
        .file_stem()
        .map_or_else(|| label.clone(), |s| s.to_string_lossy().to_string());
    let is_at2 = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("at2"))
        || text
            .lines()
            .nth(3)
            .is_some_and(|l| l.to_uppercase().contains("NPTS"));
    if is_at2 {
        parse_at2(&text, &label, &name)
    } else {
        parse_text(&text, &label, &name)
    }
}

/// The records shipped in `assets/records/` (embedded): (name, file, text).
const BUILTIN: &[(&str, &str, &str)] = &[
    (
        "el-centro",
        "el_centro_1940_ns.csv",
        include_str!("../../assets/records/el_centro_1940_ns.csv"),
    ),
    (
        "el-centro-peer-legacy",
        "el_centro_1940_ns_peer_legacy.csv",
        include_str!("../../assets/records/el_centro_1940_ns_peer_legacy.csv"),
    ),
    (
        "el-centro-ngawest2",
        "el_centro_1940_ns_ngawest2.csv",
        include_str!("../../assets/records/el_centro_1940_ns_ngawest2.csv"),
    ),
    (
        "el-centro-ew",
        "el_centro_1940_ew_ngawest2.csv",
        include_str!("../../assets/records/el_centro_1940_ew_ngawest2.csv"),
    ),
    (
        "el-centro-up",
        "el_centro_1940_up_ngawest2.csv",
        include_str!("../../assets/records/el_centro_1940_up_ngawest2.csv"),
    ),
    (
        "northridge-sylmar-032",
        "northridge_1994_sylmar_olive_view_032.csv",
        include_str!("../../assets/records/northridge_1994_sylmar_olive_view_032.csv"),
    ),
    (
        "northridge-sylmar-122",
        "northridge_1994_sylmar_olive_view_122.csv",
        include_str!("../../assets/records/northridge_1994_sylmar_olive_view_122.csv"),
    ),
    (
        "kobe-nishi-akashi-000",
        "kobe_1995_nishi_akashi_000.csv",
        include_str!("../../assets/records/kobe_1995_nishi_akashi_000.csv"),
    ),
    (
        "kobe-nishi-akashi-090",
        "kobe_1995_nishi_akashi_090.csv",
        include_str!("../../assets/records/kobe_1995_nishi_akashi_090.csv"),
    ),
    (
        "chi-chi-tcu045-n",
        "chi_chi_1999_tcu045_n.csv",
        include_str!("../../assets/records/chi_chi_1999_tcu045_n.csv"),
    ),
    (
        "chi-chi-tcu045-e",
        "chi_chi_1999_tcu045_e.csv",
        include_str!("../../assets/records/chi_chi_1999_tcu045_e.csv"),
    ),
    (
        "pacoima-dam-164",
        "san_fernando_1971_pacoima_dam_164.csv",
        include_str!("../../assets/records/san_fernando_1971_pacoima_dam_164.csv"),
    ),
    (
        "pacoima-dam-254",
        "san_fernando_1971_pacoima_dam_254.csv",
        include_str!("../../assets/records/san_fernando_1971_pacoima_dam_254.csv"),
    ),
];

/// Names of the built-in records.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN.iter().map(|b| b.0).collect()
}

/// A built-in record by name.
pub fn builtin_record(name: &str) -> Result<Record> {
    let (n, file, text) = BUILTIN
        .iter()
        .find(|b| b.0 == name)
        .ok_or_else(|| Error::Unknown {
            kind: "record",
            name: name.to_string(),
            known: builtin_names().join(", "),
        })?;
    parse_text(text, &format!("assets/records/{file}"), n)
}

/// A built-in record name, or else a record file path.
pub fn resolve_record(name_or_path: &str) -> Result<Record> {
    if BUILTIN.iter().any(|b| b.0 == name_or_path) {
        return builtin_record(name_or_path);
    }
    let path = Path::new(name_or_path);
    if path.exists() {
        return read_record_file(path);
    }
    if crate::error::meant_as_path(name_or_path) {
        let builtins = builtin_names().join(", ");
        return Err(Error::missing_file("record", name_or_path, &builtins));
    }
    Err(Error::Unknown {
        kind: "record",
        name: name_or_path.to_string(),
        known: format!(
            "{} — or a path to an .AT2/.csv file",
            builtin_names().join(", ")
        ),
    })
}
