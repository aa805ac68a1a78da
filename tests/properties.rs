//! Property tests of the input contract: thousands of malformed and extreme scene files,
//! AT2 and CSV records, each either refused with a clean error or accepted with a result
//! that is finite and within the documented ranges — never a panic.
//!
//! The inputs come from a seeded generator (mutations of real files: numbers replaced by
//! extreme values, lines deleted, duplicated or swapped, junk inserted, text cut off), so
//! a failure is reproducible from the case number it prints. `SLIDEBASE_PROPERTY_CASES`
//! sets the number of cases per target (default 10 000; the README gives the time a
//! million take).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::panic::{AssertUnwindSafe, catch_unwind};

use slidebase::ground_motion::{STANDARD_GRAVITY, parse_at2, parse_text};
use slidebase::limits::{MAX_ACCEL_G, MAX_RECORD_SAMPLES, RECORD_DT_RANGE};
use slidebase::model::Scene;
use slidebase::setup::{RunSpec, SceneSource};
use slidebase::testing::{Rng, property_cases};

fn cases() -> usize {
    property_cases()
}

/// Runs `check` on `cases()` generated inputs; a panic fails with the case number.
fn for_cases(seed: u64, mut check: impl FnMut(&mut Rng, usize)) {
    let n = cases();
    for case in 0..n {
        let mut rng = Rng::for_case(seed, case);
        if catch_unwind(AssertUnwindSafe(|| check(&mut rng, case))).is_err() {
            panic!("case {case} of seed {seed:#x} panicked (rerun with the same seed to see it)");
        }
    }
}

/// Numbers a hostile user would type.
const NUMBERS: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1",
    "0.5",
    "3",
    "1e300",
    "-1e300",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "1e20",
    "1e9",
    "2e6",
    "1e-9",
    "0.001",
    "1000000",
    "-2000.0",
    "4000.0",
    "1.5D-03",
    "18446744073709551615",
    "1e308",
    "2.5",
    "0.1",
    "9.80665",
    "1e12",
];

/// Lines a hostile user would add to a scene.
const SCENE_JUNK: &[&str] = &[
    "[[block]]",
    "name = \"\"",
    "name = \"raft\"",
    "vertices = [[0.0, 0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]",
    "vertices = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]",
    "vertices = []",
    "material = { density = 1000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }",
    "[[contact]]",
    "blocks = [\"raft\", \"ground\"]",
    "blocks = [\"raft\", \"raft\"]",
    "friction = inf",
    "[structure]",
    "base = \"ground\"",
    "floors = []",
    "[two_block]",
    "[[fixed_point]]",
    "block = \"roof\"",
    "point = [1e300, 0.0]",
    "[[point_load]]",
    "force = [nan, 0.0]",
    "[excitation]",
    "kind = \"record\"",
    "record = \"/dev/zero\"",
    "record = \"el-centro-up\"",
    "kind = \"harmonic\"",
    "gravity = 0.0",
    "\u{feff}",
    "[[bolt]]",
    "points = [[0.0, 0.25]]",
    "\"unterminated",
    "= 3",
];

const TWO_BLOCK: &str = include_str!("../assets/scenes/two-block.toml");
const THREE_STOREY: &str = include_str!("../assets/scenes/three-storey.toml");

/// A mutated scene text.
fn mutate_scene(rng: &mut Rng, base: &str) -> String {
    let mut lines: Vec<String> = base.lines().map(str::to_string).collect();
    for _ in 0..1 + rng.below(4) {
        let k = rng.below(lines.len());
        match rng.below(7) {
            0 | 1 => {
                // A number replaced by an extreme value.
                let line = &lines[k];
                let starts: Vec<usize> = line
                    .char_indices()
                    .filter(|(i, c)| {
                        (c.is_ascii_digit() || *c == '-')
                            && (*i == 0 || !line.as_bytes()[i - 1].is_ascii_alphanumeric())
                    })
                    .map(|(i, _)| i)
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = line[s..]
                        .find(|c: char| {
                            !(c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+'))
                        })
                        .map_or(line.len(), |e| s + e);
                    lines[k] = format!("{}{}{}", &line[..s], rng.pick(NUMBERS), &line[e..]);
                }
            }
            2 => {
                lines.remove(k);
            }
            3 => {
                let l = lines[k].clone();
                lines.insert(k, l);
            }
            4 => {
                let j = rng.below(lines.len());
                lines.swap(k, j);
            }
            5 => lines.insert(k, rng.pick(SCENE_JUNK).to_string()),
            _ => {
                // A string value replaced.
                if let Some(q) = lines[k].find('"') {
                    let name = rng.pick(&["ground", "raft", "roof", "", "floor-3", "x"]);
                    lines[k] = format!("{}\"{name}\"", &lines[k][..q]);
                }
            }
        }
        if lines.is_empty() {
            break;
        }
    }
    let mut text = lines.join(if rng.chance(4) { "\r\n" } else { "\n" });
    if rng.chance(20) {
        let cut = rng.below(text.len());
        let cut = (0..=cut)
            .rev()
            .find(|&c| text.is_char_boundary(c))
            .unwrap_or(0);
        text.truncate(cut);
    }
    text
}

/// Scene files: parsed and checked, or refused; an accepted two-block variant also runs
/// five steps with a finite summary.
#[test]
fn scene_files_are_refused_cleanly_or_run_finitely() {
    let mut accepted = 0;
    let mut ran = 0;
    for_cases(0x5ce9e, |rng, _| {
        let base = if rng.chance(5) {
            THREE_STOREY
        } else {
            TWO_BLOCK
        };
        let text = mutate_scene(rng, base);
        match Scene::from_toml(&text, "fuzz.toml") {
            Err(e) => assert!(!e.to_string().is_empty()),
            Ok(scene) => {
                accepted += 1;
                scene.validate().unwrap();
                // Running costs ~1 ms per two-block case: every tenth accepted one.
                if scene.two_block.is_some() && accepted % 10 == 0 {
                    ran += 1;
                    let spec = RunSpec {
                        scene: SceneSource::Given(Box::new(scene)),
                        duration: Some(0.005),
                        ..RunSpec::default()
                    };
                    if let Ok(o) = slidebase::headless::run::run(&spec) {
                        let json = serde_json::to_string(&o.summary).unwrap();
                        assert!(!json.contains("null"), "{json}");
                    }
                }
            }
        }
    });
    println!("{} scene cases: {accepted} accepted, {ran} run", cases());
}

/// A record accepted by a reader is within the documented ranges.
fn assert_sane(r: &slidebase::ground_motion::Record) {
    let (lo, hi) = RECORD_DT_RANGE;
    assert!((lo..=hi).contains(&r.dt), "dt {}", r.dt);
    assert!((2..=MAX_RECORD_SAMPLES).contains(&r.samples().len()));
    assert!(
        r.samples()
            .iter()
            .all(|a| a.is_finite() && a.abs() <= MAX_ACCEL_G * STANDARD_GRAVITY)
    );
    for t in [0.0, r.dt * 0.5, r.duration(), 2.0 * r.duration()] {
        assert!(r.displacement(t).is_finite() && r.velocity(t).is_finite());
    }
}

/// Whether a reader accepted the record; an accepted one is sane, a refused one a
/// record error.
fn accepted_record(result: slidebase::Result<slidebase::ground_motion::Record>) -> bool {
    match result {
        Ok(r) => {
            assert_sane(&r);
            true
        }
        Err(e) => {
            assert!(
                matches!(e, slidebase::Error::Record { .. }),
                "not a record error: {e}"
            );
            false
        }
    }
}

/// A value token of a record file.
fn record_token(rng: &mut Rng) -> String {
    match rng.below(6) {
        0 => rng.pick(NUMBERS).to_string(),
        1 => rng
            .pick(&["x", "", "1.0-02", "1e", "--1", "0x10", "1,5", "NaN", "∞"])
            .into(),
        _ => format!("{:.6e}", (rng.next_u64() % 2000) as f64 / 1000.0 - 1.0),
    }
}

/// A separator between values.
fn separator(rng: &mut Rng) -> &'static str {
    rng.pick(&[" ", "  ", "\t", ",", ", ", ";"])
}

#[test]
fn at2_files_are_refused_cleanly_or_read_within_range() {
    let mut accepted = 0;
    for_cases(0xa72, |rng, _| {
        let n = rng.below(12);
        let npts = match rng.below(6) {
            0 => rng.pick(NUMBERS).to_string(),
            1 => (n + 1).to_string(),
            _ => n.to_string(),
        };
        let dt = if rng.chance(3) {
            rng.pick(NUMBERS).to_string()
        } else {
            ".0100".into()
        };
        let header = match rng.below(3) {
            0 => format!("NPTS= {npts}, DT= {dt} SEC"),
            1 => format!("  {npts}   {dt}   NPTS, DT"),
            _ => format!("NPTS={npts} DT={dt}"),
        };
        let mut text = String::new();
        if rng.chance(10) {
            text.push('\u{feff}');
        }
        let title = if rng.chance(10) {
            "Quake, STATION, UP"
        } else {
            "Quake, STATION, 090"
        };
        text.push_str(&format!("PEER NGA\n{title}\nUNITS OF G\n{header}\n"));
        for k in 0..n {
            text.push_str(&record_token(rng));
            text.push_str(if k % 5 == 4 { "\n" } else { separator(rng) });
        }
        if rng.chance(3) {
            text.push_str("\r\n\n  \n");
        }
        accepted += usize::from(accepted_record(parse_at2(&text, "fuzz.at2", "fuzz")));
    });
    println!("{} AT2 cases: {accepted} accepted", cases());
}

#[test]
fn csv_files_are_refused_cleanly_or_read_within_range() {
    let mut accepted = 0;
    for_cases(0xc5f, |rng, _| {
        let mut text = String::new();
        if rng.chance(8) {
            text.push('\u{feff}');
        }
        if rng.chance(3) {
            text.push_str("# comment: UP (vertical)\n");
        }
        if rng.chance(2) {
            text.push_str(rng.pick(&["time_s,accel_g\n", "t a\n", "1.0e,0.3\n", "\"t\",\"a\"\n"]));
        }
        let n = rng.below(10);
        let step = [0.01, 0.02, 0.005, 1e-9, 1e-300, 2.0][rng.below(6).min(rng.below(6))];
        let start = [0.0, step, 5.0][rng.below(3).min(rng.below(3))];
        let eol = if rng.chance(3) { "\r\n" } else { "\n" };
        for k in 0..n {
            let t = if rng.chance(60) {
                rng.pick(NUMBERS).to_string()
            } else {
                format!("{}", start + k as f64 * step)
            };
            text.push_str(&t);
            text.push_str(separator(rng));
            text.push_str(&record_token(rng));
            if rng.chance(60) {
                text.push_str(separator(rng));
                text.push('3');
            }
            text.push_str(eol);
        }
        accepted += usize::from(accepted_record(parse_text(&text, "fuzz.csv", "fuzz")));
    });
    println!("{} CSV cases: {accepted} accepted", cases());
}
