//! `slidebase render` as a user runs it: a picture with its data files, a replay that
//! falls back to an animated GIF when ffmpeg is not on PATH, and flags that do not apply
//! refused. Pictures need a graphics adapter (Mesa's software drivers do): in CI (`CI`
//! set) a missing one fails these tests; elsewhere they say SKIPPED, loudly.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::{Command, Output};

fn slidebase(args: &[&str], path_env: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_slidebase"));
    cmd.args(args);
    if let Some(p) = path_env {
        cmd.env("PATH", p);
    }
    cmd.output().unwrap()
}

/// False (and a loud SKIPPED line) when the command failed for want of an adapter outside
/// CI; panics in CI.
fn had_adapter(out: &Output, test: &str) -> bool {
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("no graphics adapter") {
        if std::env::var_os("CI").is_some() {
            panic!("CI must have a graphics adapter: {stderr}");
        }
        eprintln!("\n*** SKIPPED {test}: no graphics adapter on this machine ({stderr}) ***\n");
        return false;
    }
    true
}

fn png_size(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

#[test]
fn a_picture_with_its_plot_data() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("frame.png");
    let data = dir.path().join("data");
    let out = slidebase(
        &[
            "render",
            "--scene",
            "two-block",
            "--time",
            "1.0",
            "--width",
            "480",
            "--height",
            "270",
            "--out",
            png.to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
        ],
        None,
    );
    if !had_adapter(&out, "a_picture_with_its_plot_data") {
        return;
    }
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (w, h, px) = png_size(&png);
    assert_eq!((w, h), (480, 270));
    // Not blank: sky, ground, blocks and text give many colours.
    let mut colours: Vec<[u8; 3]> = px.chunks(4).map(|p| [p[0], p[1], p[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 40, "{} colours", colours.len());
    let mut series = csv::Reader::from_path(data.join("series.csv")).unwrap();
    let names: Vec<String> = series.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(&names[..2], ["time_s", "ground_accel_g"]);
    assert!(
        names.contains(&"slip_m (sliding base, ρ = 0.1)".to_string()),
        "{names:?}"
    );
    let rows: Vec<csv::StringRecord> = series.records().map(Result::unwrap).collect();
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert!(
        (last - 1.0).abs() < 1e-6,
        "series up to the time shown, not {last}"
    );
    let mut spectrum = csv::Reader::from_path(data.join("spectrum.csv")).unwrap();
    let names: Vec<String> = spectrum
        .headers()
        .unwrap()
        .iter()
        .map(String::from)
        .collect();
    assert_eq!(names[0], "frequency_hz");
    assert_eq!(names[1], "ground");
    assert!(names.iter().any(|n| n == "base, fixed base"), "{names:?}");
}

/// On a headless machine (no `XDG_RUNTIME_DIR`, as in containers and CI) a picture is
/// made without a word on stderr: Mesa's device-select layer used to have libwayland print
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice although
/// nothing failed.
#[test]
fn a_headless_picture_prints_no_errors() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("quiet.png");
    let out = Command::new(env!("CARGO_BIN_EXE_slidebase"))
        .args(["render", "--scene", "two-block", "--time", "0.5"])
        .args(["--width", "240", "--height", "136", "--out"])
        .arg(&png)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    if !had_adapter(&out, "a_headless_picture_prints_no_errors") {
        return;
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("error"), "stderr: {stderr}");
}

#[test]
fn a_replay_without_ffmpeg_is_an_animated_gif() {
    let dir = tempfile::tempdir().unwrap();
    let mp4 = dir.path().join("replay.mp4");
    // No PATH: ffmpeg cannot be found.
    let out = slidebase(
        &[
            "render",
            "--scene",
            "two-block",
            "--single",
            "--from",
            "0.2",
            "--to",
            "0.6",
            "--fps",
            "10",
            "--width",
            "240",
            "--height",
            "136",
            "--out",
            mp4.to_str().unwrap(),
        ],
        Some(""),
    );
    if !had_adapter(&out, "a_replay_without_ffmpeg_is_an_animated_gif") {
        return;
    }
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("ffmpeg is not on PATH"));
    let gif_path = dir.path().join("replay.gif");
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif_path).unwrap())
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (240, 136));
    let mut frames = 0;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!(
            frame.delay, 10,
            "10 frames per simulated second, in real time"
        );
        frames += 1;
    }
    // 0.2, 0.3, 0.4, 0.5, 0.6 s: evenly spaced in simulated time.
    assert_eq!(frames, 5);
}

#[test]
fn flags_that_do_not_apply_are_refused() {
    let out = slidebase(&["render", "--from", "1", "--out", "x.png"], None);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--from") && e.contains("replay"), "{e}");
    let out = slidebase(&["render", "--time", "1", "--out", "x.gif"], None);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--time") && e.contains("--fps"), "{e}");
    let out = slidebase(
        &["render", "--from", "3", "--to", "1", "--out", "x.gif"],
        None,
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--to"));
}
