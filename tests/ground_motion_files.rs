//! Reading accelerograms: both AT2 header variants, two-column text, the shipped records,
//! and a clear error (file, line, what) for every kind of bad file.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use slidebase::Error;
use slidebase::ground_motion::{
    STANDARD_GRAVITY, builtin_names, builtin_record, parse_at2, parse_text, read_record_file,
    resolve_record,
};

const G: f64 = STANDARD_GRAVITY;

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/records")
        .join(name)
}

/// The error must be a record error at `line` whose message contains `fragment`.
fn assert_parse_error(
    result: slidebase::Result<slidebase::ground_motion::Record>,
    line: usize,
    fragment: &str,
) {
    match result {
        Err(Error::Record {
            line: l, message, ..
        }) => {
            assert_eq!(l, line, "wrong line for '{message}'");
            assert!(
                message.contains(fragment),
                "message '{message}' lacks '{fragment}'"
            );
        }
        other => panic!("expected a record error at line {line}, got {other:?}"),
    }
}

#[test]
fn nga_at2_header_and_values() {
    let r = read_record_file(&data("nga_sample.AT2")).unwrap();
    assert_eq!(r.samples().len(), 10);
    assert!((r.dt - 0.01).abs() < 1e-15);
    for (k, &a) in r.samples().iter().enumerate() {
        let expected = if k % 2 == 0 { -(k as f64) } else { k as f64 } * 0.01 * G;
        assert!(
            (a - expected).abs() < 1e-12,
            "sample {k}: {a} vs {expected}"
        );
    }
    assert_eq!(r.name, "nga_sample");
    assert!(r.provenance.contains("NGA header variant"));
}

#[test]
fn legacy_at2_header_and_fortran_exponents() {
    let r = read_record_file(&data("legacy_sample.at2")).unwrap();
    assert_eq!(r.samples().len(), 8);
    assert!((r.dt - 0.02).abs() < 1e-15);
    assert!((r.samples()[1] - 0.001 * G).abs() < 1e-12);
    assert!((r.samples()[4] + 0.004 * G).abs() < 1e-12);
    assert!(
        (r.accel(0.03) - 0.5 * (0.001 - 0.002) * G).abs() < 1e-12,
        "interpolated between samples"
    );
}

#[test]
fn text_variants() {
    let csv = "# a comment\ntime_s,accel_g\n0.00,0\n0.02,0.1\n0.04,-0.2\n";
    let r = parse_text(csv, "a.csv", "a").unwrap();
    assert_eq!(r.samples().len(), 3);
    assert!((r.samples()[2] + 0.2 * G).abs() < 1e-12);
    assert_eq!(r.provenance, "a comment");
    let ws = "0.005\t0.1\n0.010   0.2\n\n0.015 0.3\n";
    let r = parse_text(ws, "b.txt", "b").unwrap();
    assert_eq!(r.samples().len(), 4, "a zero sample is implied at t = 0");
    assert_eq!(r.samples()[0], 0.0);
    let semi = "0;0\n0.1;1e-2\n0.2;2E-2\n";
    assert_eq!(parse_text(semi, "c.csv", "c").unwrap().samples().len(), 3);
}

#[test]
fn bad_at2_files() {
    assert_parse_error(parse_at2("", "e.AT2", "e"), 0, "empty");
    assert_parse_error(parse_at2("a\nb\nc\n", "h.AT2", "h"), 3, "four header lines");
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 3\n1 2 3\n", "d.AT2", "d"),
        4,
        "DT",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nsomething else\n1 2 3\n", "x.AT2", "x"),
        4,
        "NPTS and DT",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 3, DT= 0.0 SEC\n1 2 3\n", "z.AT2", "z"),
        4,
        "time step 0 s is outside [1e-5, 1] s",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 4, DT= .01 SEC\n1 2\n3\n", "f.AT2", "f"),
        6,
        "NPTS = 4 but the file has 3",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 2, DT= .01 SEC\n1 2\n3\n", "m.AT2", "m"),
        6,
        "more values than NPTS",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 3, DT= .01 SEC\n1 x2 3\n", "n.AT2", "n"),
        5,
        "'x2' is not a number",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\nNPTS= 3, DT= .01 SEC\n1\nNaN\n3\n", "q.AT2", "q"),
        6,
        "not finite",
    );
    assert_parse_error(
        parse_at2("a\nb\nc\n 3  .01  NPTS, DT\n1 inf 3\n", "i.AT2", "i"),
        5,
        "not finite",
    );
    // Another unit or quantity than acceleration in g, declared in the header: refused
    // at the line that declares it (read as g, 15 cm/s² was 15 g).
    let body = "NPTS= 3, DT= .01 SEC\n1 2 3\n";
    for (third, fragment) in [
        (
            "ACCELERATION TIME SERIES IN UNITS OF CM/SEC/SEC",
            "UNITS OF CM/SEC/SEC",
        ),
        ("VELOCITY TIME SERIES IN UNITS OF CM/S", "VELOCITY"),
        ("DISPLACEMENT TIME SERIES IN UNITS OF CM", "DISPLACEMENT"),
    ] {
        let text = format!("PEER NGA STRONG MOTION DATABASE RECORD\nTest\n{third}\n{body}");
        assert_parse_error(parse_at2(&text, "u.AT2", "u"), 3, fragment);
    }
    let in_g = format!("PEER\nTest\nACCELERATION TIME SERIES IN UNITS OF G\n{body}");
    assert!(parse_at2(&in_g, "g.AT2", "g").is_ok());
}

#[test]
fn bad_text_files() {
    assert_parse_error(parse_text("", "e.csv", "e"), 0, "no data rows");
    assert_parse_error(
        parse_text("# only\n# comments\n", "c.csv", "c"),
        0,
        "no data rows",
    );
    assert_parse_error(parse_text("0,0\n0.01\n", "w.csv", "w"), 2, "two columns");
    assert_parse_error(
        parse_text("0,0\n0.01,abc\n", "n.csv", "n"),
        2,
        "'abc' is not a number",
    );
    assert_parse_error(parse_text("0,0\n0.01,nan\n", "n.csv", "n"), 2, "not finite");
    assert_parse_error(
        parse_text("0,0\n0.02,1\n0.01,2\n", "d.csv", "d"),
        3,
        "does not increase",
    );
    assert_parse_error(
        parse_text("0,0\n0.01,1\n0.01,2\n", "r.csv", "r"),
        3,
        "does not increase",
    );
    assert_parse_error(
        parse_text("0,0\n0.01,1\n0.03,2\n0.04,3\n", "u.csv", "u"),
        3,
        "not uniform",
    );
    assert_parse_error(
        parse_text("5,0\n5.01,1\n", "s.csv", "s"),
        1,
        "must start at t = 0",
    );
    assert_parse_error(
        parse_text("0,0.1\n", "one.csv", "one"),
        1,
        "at least two samples",
    );
    // A header naming another unit or quantity for the acceleration column.
    for header in [
        "time_s,accel_m_s2",
        "t,acc_cm_s2",
        "time;gal",
        "time_s,velocity",
    ] {
        let text = format!("# a record\n{header}\n0,0\n0.01,0.1\n");
        assert_parse_error(parse_text(&text, "h.csv", "h"), 2, "read in g");
    }
    for header in ["time_s,accel_g", "time,acceleration", "t,a"] {
        let text = format!("{header}\n0,0\n0.01,0.1\n");
        assert!(parse_text(&text, "g.csv", "g").is_ok(), "{header}");
    }
}

#[test]
fn missing_file_is_an_io_error_naming_the_path() {
    let e = read_record_file(Path::new("/nonexistent/quake.AT2")).unwrap_err();
    assert!(matches!(e, Error::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/quake.AT2"));
}

/// Every shipped record loads with the sample count, step and peak of its provenance table.
#[test]
fn shipped_records_match_their_provenance() {
    // name, samples, dt, PGA (g), time of PGA (s)
    let table = [
        ("el-centro", 1560, 0.02, 0.3188, 2.04),
        ("el-centro-peer-legacy", 4000, 0.01, 0.3129, 2.15),
        ("el-centro-ngawest2", 5372, 0.01, 0.2808, 2.18),
        ("el-centro-ew", 5346, 0.01, 0.2107, 11.51),
        ("el-centro-up", 5378, 0.01, 0.1781, 3.37),
        ("northridge-sylmar-032", 2000, 0.02, 0.7326, 4.18),
        ("northridge-sylmar-122", 2000, 0.02, 0.5951, 4.06),
        ("kobe-nishi-akashi-000", 4096, 0.01, 0.5093, 7.25),
        ("kobe-nishi-akashi-090", 4096, 0.01, 0.5027, 7.09),
        ("chi-chi-tcu045-n", 18000, 0.005, 0.5120, 44.87),
        ("chi-chi-tcu045-e", 18000, 0.005, 0.4744, 44.79),
        ("pacoima-dam-164", 4172, 0.01, 1.2190, 7.75),
        ("pacoima-dam-254", 4172, 0.01, 1.2383, 8.52),
    ];
    assert_eq!(builtin_names().len(), table.len());
    for (name, n, dt, pga, t_pga) in table {
        let r = builtin_record(name).unwrap();
        assert_eq!(r.samples().len(), n, "{name}");
        assert!((r.dt - dt).abs() < 1e-9, "{name}: dt {}", r.dt);
        let (k, peak) = r
            .samples()
            .iter()
            .enumerate()
            .fold(
                (0, 0.0_f64),
                |b, (k, a)| if a.abs() > b.1 { (k, a.abs()) } else { b },
            );
        assert!((peak / G - pga).abs() < 1e-4, "{name}: PGA {}", peak / G);
        assert!(
            (k as f64 * dt - t_pga).abs() <= dt + 1e-9,
            "{name}: PGA at {}",
            k as f64 * dt
        );
        assert!(!r.provenance.is_empty());
    }
}

/// The textbook El Centro integrates (without correction) to a PGD of about 21 cm.
#[test]
fn el_centro_peak_ground_displacement() {
    let r = builtin_record("el-centro").unwrap();
    let pgd = (0..=3118)
        .map(|k| r.displacement(k as f64 * 0.01).abs())
        .fold(0.0, f64::max);
    assert!((0.19..0.23).contains(&pgd), "PGD {pgd} m");
}

#[test]
fn resolve_by_name_path_or_error() {
    assert_eq!(resolve_record("el-centro").unwrap().samples().len(), 1560);
    assert_eq!(
        resolve_record(data("nga_sample.AT2").to_str().unwrap())
            .unwrap()
            .samples()
            .len(),
        10
    );
    let e = resolve_record("taft-1952").unwrap_err().to_string();
    assert!(
        e.contains("taft-1952") && e.contains("el-centro") && e.contains("pacoima-dam-164"),
        "{e}"
    );
}

/// Writing a record as CSV and as AT2 text and reading it back gives the same samples.
#[test]
fn round_trip_through_both_formats() {
    let r = builtin_record("kobe-nishi-akashi-090").unwrap();
    let g: Vec<f64> = r.samples().iter().map(|a| a / G).collect();
    let csv: String = g
        .iter()
        .enumerate()
        .map(|(k, a)| format!("{},{:.9e}\n", k as f64 * r.dt, a))
        .collect();
    let back = parse_text(&csv, "rt.csv", "rt").unwrap();
    let mut at2 = format!("h1\nh2\nh3\nNPTS= {}, DT= {} SEC\n", g.len(), r.dt);
    for chunk in g.chunks(5) {
        at2.push_str(
            &chunk
                .iter()
                .map(|a| format!("{a:15.7E}"))
                .collect::<Vec<_>>()
                .join(""),
        );
        at2.push('\n');
    }
    let back2 = parse_at2(&at2, "rt.AT2", "rt").unwrap();
    for k in 0..g.len() {
        assert!((back.samples()[k] - r.samples()[k]).abs() < 1e-8 * G);
        assert!((back2.samples()[k] - r.samples()[k]).abs() < 1e-7 * G);
    }
}
