//! The command line as users and scripts see it: names of flags and JSON keys, files
//! written, and one-line errors with a non-zero exit code (never a panic).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn slidebase(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_slidebase"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The one JSON object a successful `--json` run prints.
fn json_of(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

#[test]
fn run_json_has_the_documented_keys() {
    let out = slidebase(&[
        "run",
        "--alpha",
        "0.5",
        "--friction",
        "0.1",
        "--freq-ratio",
        "2",
        "--duration",
        "5",
        "--json",
    ]);
    let v = json_of(&out);
    for key in [
        "us_max_over_d",
        "ur_max_over_d",
        "abase_over_aground",
        "aroof_over_aground",
        "steps",
        "wall_time_s",
        "energy_residual_rel",
    ] {
        assert!(
            v.get(key).is_some_and(|x| x.is_number()),
            "missing or non-numeric {key}: {v}"
        );
    }
    assert_eq!(v["steps"].as_u64().map(|s| s >= 5000), Some(true));
}

/// Runs `args` with `--out` into a new folder, checks that it succeeded and wrote the
/// history, the summary and the figure, and returns the folder.
fn run_with_out(args: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mut all = args.to_vec();
    all.extend(["--out", dir.path().to_str().unwrap()]);
    let out = slidebase(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["history.csv", "summary.json", "history.png"] {
        assert!(dir.path().join(f).exists(), "{args:?}: {f} missing");
    }
    dir
}

/// `--scene block` reports the slip and the block's acceleration under the documented
/// names, from both models, and refuses the two-block flags.
#[test]
fn block_scene_json_has_the_documented_keys() {
    for model in ["dda", "mass-spring"] {
        let v = json_of(&slidebase(&[
            "run",
            "--scene",
            "block",
            "--model",
            model,
            "--duration",
            "5",
            "--json",
        ]));
        for key in [
            "max_slip_m",
            "residual_slip_m",
            "peak_base_accel_g",
            "steps",
        ] {
            assert!(
                v.get(key).is_some_and(|x| x.is_number()),
                "{model}: missing or non-numeric {key}: {v}"
            );
        }
        assert_eq!(v["scene"], "block");
        assert_eq!(v["model"], model);
    }
    let dir = run_with_out(&[
        "run",
        "--scene",
        "block",
        "--duration",
        "5",
        "--vertical-record",
        "el-centro-up",
    ]);
    assert!(
        dir.path().join("friction.png").exists(),
        "a block run draws its friction hysteresis"
    );
    let out = slidebase(&["run", "--scene", "block", "--alpha", "0.5"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--alpha"));
}

#[test]
fn mass_spring_model_and_outputs() {
    let dir = run_with_out(&["run", "--model", "mass-spring", "--duration", "3"]);
    let csv = std::fs::read_to_string(dir.path().join("history.csv")).unwrap();
    assert!(csv.starts_with("time_s,ground_accel_m_s2,slip_m"));
    assert!(csv.lines().count() > 100);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["model"], "mass-spring");
}

#[test]
fn parameter_errors_are_one_line_and_non_zero() {
    for args in [
        vec!["run", "--alpha", "1.2"],
        vec!["run", "--alpha", "0"],
        vec!["run", "--friction", "-0.5"],
        vec!["run", "--dt", "0"],
        vec!["run", "--dt", "-1e-3"],
        vec!["run", "--scene", "no-such-scene"],
        vec!["run", "--record", "no-such-record"],
        vec!["run", "--integrator", "euler"],
        vec!["sweep", "--alpha", "0.5,1.5", "--out", "/tmp/never"],
        vec!["sweep", "--freq-ratios", "0:1:3", "--out", "/tmp/never"],
    ] {
        let out = slidebase(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: '{err}'");
        assert!(err.starts_with("error:"), "{args:?}: '{err}'");
    }
}

#[test]
fn bad_record_file_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.csv");
    std::fs::write(&path, "0,0\n0.01,0.1\n0.02,oops\n").unwrap();
    let out = slidebase(&["run", "--record", path.to_str().unwrap(), "--duration", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("broken.csv:3:") && err.contains("oops"),
        "{err}"
    );
}

#[test]
fn small_sweep_writes_table_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = slidebase(&[
        "sweep",
        "--alpha",
        "0.5",
        "--friction",
        "0.1",
        "--freq-ratios",
        "0.5:2:3",
        "--duration",
        "5",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = slidebase::post::sweep::read_sweep_csv(&dir.path().join("sweep.csv")).unwrap();
    assert_eq!(rows.len(), 6, "3 ratios × 2 models");
    for name in [
        "fig6_alpha0.5_displacements.png",
        "fig7_alpha0.5_accelerations.png",
    ] {
        let bytes = std::fs::read(dir.path().join(name)).unwrap();
        assert!(
            bytes.len() > 10_000 && bytes.starts_with(b"\x89PNG"),
            "{name}"
        );
    }
    assert!(String::from_utf8_lossy(&out.stdout).contains("us_max_over_d"));
}

/// `modes` compares with the paper's frequencies only for the built-in frame: a copy of
/// its file with other floors keeps the name "three-storey" inside, and was compared as if
/// the paper's frame were 24 % off. The file is named by its path.
#[test]
fn modes_compares_with_the_paper_only_for_the_built_in_frame() {
    let builtin = slidebase(&["modes", "--scene", "three-storey"]);
    let text = String::from_utf8_lossy(&builtin.stdout);
    assert!(
        builtin.status.success() && text.contains("paper 0.638 Hz"),
        "{text}"
    );
    let original = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/scenes/three-storey.toml"
    ))
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("heavier.toml");
    std::fs::write(&path, original.replace("1789400.0", "3000000.0")).unwrap();
    let copy = slidebase(&["modes", "--scene", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&copy.stdout);
    assert!(
        copy.status.success(),
        "{}",
        String::from_utf8_lossy(&copy.stderr)
    );
    assert!(!text.contains("paper"), "{text}");
    assert!(
        text.starts_with(&format!("three-storey ({})", path.display())),
        "{text}"
    );
}

/// `report`'s paper column holds the paper's own case only: beside `frame:5` it showed
/// the three-storey frame's 0.638 Hz, and beside a 1 s run the paper's ≈ 0.3 m slip.
#[test]
fn the_report_compares_with_the_paper_only_for_its_case() {
    let dir = tempfile::tempdir().unwrap();
    let out = slidebase(&[
        "report",
        "--scene",
        "frame:5",
        "--duration",
        "1",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    for paper_value in ["0.638", "≈ 0.3", "≈ 1.5"] {
        assert!(
            !summary.contains(paper_value),
            "{paper_value} in\n{summary}"
        );
    }
    assert!(
        summary.contains("filled only for its own case"),
        "{summary}"
    );
}

#[test]
fn modes_json_and_a_short_report() {
    let out = slidebase(&["modes", "--scene", "three-storey", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["frequencies_hz"].as_array().map(Vec::len), Some(3));
    let dir = tempfile::tempdir().unwrap();
    let out = slidebase(&[
        "report",
        "--duration",
        "3",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for k in 10..=18 {
        let found = std::fs::read_dir(dir.path()).unwrap().any(|e| {
            e.unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(&format!("fig{k}_"))
        });
        assert!(found, "fig{k} missing");
    }
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    assert!(summary.contains("max slip") && summary.contains("paper"));
    let json = slidebase(&[
        "run",
        "--scene",
        "three-storey",
        "--duration",
        "2",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    for key in [
        "max_slip_m",
        "residual_slip_m",
        "peak_roof_accel_g",
        "peak_base_accel_g",
        "peak_roof_drift_m",
        "base_accel_peak_freq_hz",
        "steps",
        "wall_time_s",
        "energy_residual_rel",
    ] {
        assert!(
            v.get(key).is_some_and(serde_json::Value::is_number),
            "{key}: {v}"
        );
    }
    // Two-block flags make no sense for a building scene.
    let bad = slidebase(&["run", "--scene", "three-storey", "--alpha", "0.5"]);
    assert!(!bad.status.success());
}

#[cfg(feature = "gui")]
#[test]
fn render_writes_a_png_or_names_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.png");
    let out = slidebase(&[
        "render",
        "--scene",
        "two-block",
        "--time",
        "0.5",
        "--width",
        "320",
        "--height",
        "180",
        "--out",
        path.to_str().unwrap(),
    ]);
    if out.status.success() {
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 1000);
    } else {
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(std::env::var_os("CI").is_none(), "CI must render: {err}");
        assert!(
            err.contains("mesa-vulkan-drivers"),
            "the error names the fix: {err}"
        );
        eprintln!("*** no graphics adapter here: {err}");
    }
}

/// A sweep cut into shards and merged again is the sweep: every grid point once, and a
/// shard given twice is refused.
#[test]
fn sweep_shards_merge_into_the_whole_grid() {
    let dir = tempfile::tempdir().unwrap();
    let grid = [
        "--alpha",
        "0.5",
        "--friction",
        "0.1,0.25",
        "--freq-ratios",
        "0.5,2",
        "--duration",
        "3",
    ];
    let mut shards = Vec::new();
    for i in 1..=3 {
        let out_dir = dir.path().join(format!("shard-{i}"));
        let shard = format!("{i}/3");
        let mut args = vec!["sweep"];
        args.extend(grid);
        args.extend(["--shard", &shard, "--out", out_dir.to_str().unwrap()]);
        let out = slidebase(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        shards.push(out_dir.join("sweep.csv"));
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["merge", "--out", merged.to_str().unwrap()];
    args.extend(shards.iter().map(|p| p.to_str().unwrap()));
    let out = slidebase(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = slidebase::post::sweep::read_sweep_csv(&merged.join("sweep.csv")).unwrap();
    // 2 models × 1 α × 2 ρ × 2 ratios.
    assert_eq!(rows.len(), 8);
    assert!(merged.join("errors.md").exists());
    let twice = slidebase(&[
        "merge",
        "--out",
        merged.to_str().unwrap(),
        shards[0].to_str().unwrap(),
        shards[0].to_str().unwrap(),
    ]);
    assert!(!twice.status.success());
    let err = String::from_utf8_lossy(&twice.stderr);
    assert!(
        err.contains("more than one input") && err.lines().count() == 1,
        "{err}"
    );
}

/// `--friction-law` runs a law other than Coulomb's on the sliding joint, and is refused
/// by name where it cannot be (a law that cannot be, or together with `--friction`); the
/// exact model runs it too.
#[test]
fn friction_law_runs_or_is_refused_by_name() {
    let out = slidebase(&[
        "run",
        "--friction-law",
        "static-kinetic:0.15,0.1",
        "--duration",
        "5",
        "--json",
    ]);
    let json = json_of(&out);
    assert!(json["us_max_m"].as_f64().unwrap() > 0.0);
    // The exact model takes every law too (its stepped solution).
    let exact = json_of(&slidebase(&[
        "run",
        "--friction-law",
        "static-kinetic:0.15,0.1",
        "--model",
        "mass-spring",
        "--duration",
        "5",
        "--json",
    ]));
    assert_eq!(exact["model"], "mass-spring");
    assert!(exact["us_max_m"].as_f64().unwrap() > 0.0);
    for (args, says) in [
        (
            vec!["--friction-law", "static-kinetic:0.1,0.15"],
            "must not exceed",
        ),
        (
            vec!["--friction-law", "stribeck:1"],
            "velocity:MU_SLOW,MU_FAST,RATE",
        ),
        (
            vec![
                "--friction-law",
                "velocity:0.05,0.1,20",
                "--friction",
                "0.1",
            ],
            "cannot be used with",
        ),
    ] {
        let out = slidebase(&[&["run"], args.as_slice()].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(
            err.contains("--friction-law") || err.contains("--model"),
            "{args:?}: {err}"
        );
        assert!(err.contains(says), "{args:?}: '{err}' lacks '{says}'");
    }
}

/// The text summary names the vertical record when the run has one: the numbers alone do
/// not show that it was applied, and a flag that seemed ignored would be re-run without.
#[test]
fn a_vertical_record_is_named_in_the_summary() {
    for scene in ["two-block", "three-storey", "block"] {
        let out = slidebase(&[
            "run",
            "--scene",
            scene,
            "--record",
            "el-centro",
            "--vertical-record",
            "el-centro-up",
            "--duration",
            "0.2",
        ]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{scene}: {out:?}");
        assert!(
            text.lines()
                .next()
                .is_some_and(|l| l.contains("+ vertical el-centro-up")),
            "{scene}: {text}"
        );
    }
}

/// `render` refuses an output name that is neither a picture (.png) nor a replay (.mp4,
/// .gif) before it computes anything: a `.txt` got a PNG's bytes.
#[test]
fn render_refuses_an_output_name_it_would_not_write() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["picture.txt", "picture"] {
        let path = dir.path().join(name);
        let out = slidebase(&["render", "--out", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}: {err}");
        assert!(
            err.contains("--out") && err.contains(".png") && err.contains(".mp4"),
            "{name}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(!path.exists(), "{name} was written");
    }
}
