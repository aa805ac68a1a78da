//! Large models under strong shaking: the dry-stacked walls run to the end of the record.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::{Arc, Mutex};

use slidebase::dda::{ContactEnforcement, SolverParams};
use slidebase::headless::frame::{FrameSummary, run_frame};
use slidebase::model::generated::wall;
use slidebase::model::presets::resolve_scene;
use slidebase::setup::{ExcitationSpec, ProgressReporter, RunSpec};

fn wall_on_kobe(courses: usize, duration: Option<f64>) -> FrameSummary {
    let spec = RunSpec {
        excitation: ExcitationSpec::Record {
            source: "kobe-nishi-akashi-000".into(),
            scale: 1.0,
        },
        duration,
        ..RunSpec::scene(format!("wall:{courses}"))
    };
    run_frame(&spec).unwrap().summary
}

/// What any completed run of a wall must show: it reached the end, its Δt cuts are a
/// small part of its steps, each with its reason (the cut-back does not collapse into tiny steps), and its
/// energy ledger closes to a hundredth of a percent of the energy that passed through.
fn assert_ran_through(s: &FrameSummary, duration: f64) {
    let c = s.solver.expect("a DDA run reports its solver's counters");
    assert!(
        (s.duration_s - duration).abs() < 1e-6,
        "{}: ran {} s of {duration} s",
        s.scene,
        s.duration_s
    );
    assert!(
        (c.dt_cuts as f64) < 0.01 * s.steps as f64,
        "{}: {} Δt cuts in {} steps",
        s.scene,
        c.dt_cuts,
        s.steps
    );
    let why = c.dt_cut_reasons;
    assert_eq!(
        why.total(),
        c.dt_cuts,
        "{}: every cut has its reason",
        s.scene
    );
    assert!(
        s.energy_residual_rel.abs() < 1e-4,
        "{}: energy residual {:.2e}",
        s.scene,
        s.energy_residual_rel
    );
}

/// The walls' joints are penalty springs (their multipliers would be indeterminate), the
/// paper's scenes keep the exact (augmented Lagrangian) stick.
#[test]
fn walls_ask_for_penalty_springs_and_the_paper_scenes_do_not() {
    let params = SolverParams::for_scene(&wall(3).unwrap());
    assert_eq!(params.contact_enforcement, ContactEnforcement::Penalty);
    for name in ["two-block", "three-storey", "frame:2"] {
        let params = SolverParams::for_scene(&resolve_scene(name).unwrap());
        assert_eq!(
            params.contact_enforcement,
            ContactEnforcement::AugmentedLagrangian,
            "{name}"
        );
    }
}

/// A scene file names its contacts' enforcement; a misspelling is refused with its line
/// and the accepted values.
#[test]
fn a_scene_file_names_its_contact_enforcement() {
    let text = std::fs::read_to_string("assets/scenes/two-block.toml").unwrap();
    let with = |value: &str| {
        let line = format!("contact_enforcement = \"{value}\"\n");
        slidebase::model::Scene::from_toml(&format!("{line}{text}"), "test.toml")
    };
    let scene = with("penalty").unwrap();
    assert_eq!(scene.contact_enforcement, Some(ContactEnforcement::Penalty));
    let err = with("springs").unwrap_err().to_string();
    assert!(
        err.contains("test.toml:1") && err.contains("augmented-lagrangian"),
        "{err}"
    );
}

/// Kobe's strong motion (from 4.5 s) stopped a five-course wall at 5.7 s when its joints
/// were exact constraints; with penalty springs it runs on.
#[test]
fn a_dry_stacked_wall_runs_through_the_strong_motion_of_kobe() {
    let s = wall_on_kobe(5, Some(7.0));
    assert_ran_through(&s, 7.0);
}

/// The whole Kobe record (41 s) on walls of 5 and 10 courses (release: ~3 and ~13 s).
#[test]
#[ignore = "slow: release run of whole records"]
fn dry_stacked_walls_ride_out_the_whole_kobe_record() {
    for courses in [5, 10] {
        let s = wall_on_kobe(courses, None);
        assert_ran_through(&s, 40.95);
    }
}

/// A wall's acceleration peaks low-passed at 25 Hz are a property of the model, not of
/// the step: with Δt halved and the dissipative integrator swapped for the trapezoidal
/// rule they agree within 10 % (measured: 0.100 and 0.101 g at the base), while the raw
/// peaks, spikes of one to three steps at impacts and stick events, moved 0.22 → 0.37 g.
/// Each low-passed peak is at most its raw one (the filter's weights are positive).
#[test]
#[ignore = "slow: release runs of a wall under Kobe"]
fn a_walls_low_passed_peaks_hold_across_step_sizes_and_integrators() {
    use slidebase::dda::Integrator;
    let run = |dt: f64, integrator: Integrator| {
        let spec = RunSpec {
            excitation: ExcitationSpec::Record {
                source: "kobe-nishi-akashi-000".into(),
                scale: 1.0,
            },
            duration: Some(12.0),
            dt: Some(dt),
            integrator: Some(integrator),
            ..RunSpec::scene("wall:5")
        };
        run_frame(&spec).unwrap().summary
    };
    let coarse = run(1e-3, Integrator::GeneralizedAlpha { rho_inf: 0.0 });
    let fine = run(5e-4, Integrator::Trapezoidal);
    for s in [&coarse, &fine] {
        assert!(s.peak_base_accel_25hz_g.unwrap() <= s.peak_base_accel_g);
        assert!(s.peak_roof_accel_25hz_g.unwrap() <= s.peak_roof_accel_g);
    }
    for (name, a, b) in [
        (
            "base",
            coarse.peak_base_accel_25hz_g,
            fine.peak_base_accel_25hz_g,
        ),
        (
            "roof",
            coarse.peak_roof_accel_25hz_g,
            fine.peak_roof_accel_25hz_g,
        ),
    ] {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!((a / b - 1.0).abs() < 0.1, "{name}: {a} g against {b} g");
    }
}

/// A long run tells how far it has come: the reporter is called with times that grow to
/// the run's end.
#[test]
fn a_long_run_reports_its_progress() {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&seen);
    let mut setup = RunSpec {
        duration: Some(2.0),
        ..RunSpec::scene("three-storey")
    }
    .prepare()
    .unwrap();
    setup.progress = Some(ProgressReporter::new(0.0, 0.0, move |p| {
        sink.lock().unwrap().push(*p);
    }));
    slidebase::headless::frame::run_building_setup(&setup).unwrap();
    let seen = seen.lock().unwrap();
    assert!(seen.len() >= 2, "{} reports", seen.len());
    for pair in seen.windows(2) {
        assert!(pair[1].time_s > pair[0].time_s && pair[1].steps > pair[0].steps);
    }
    let last = seen.last().unwrap();
    assert!(last.time_s <= 2.0 && last.duration_s == 2.0 && last.fraction() > 0.8);
}

/// The paper's frame stands up to `MAX_FRAME_STOREYS` storeys (its first sway mode has a
/// positive frequency, though P-Δ has taken most of it: 0.634 Hz at 3 storeys), and one
/// storey more is refused with the reason, not left to fail in the settle.
#[test]
fn the_tallest_frame_stands_and_a_taller_one_is_refused() {
    use slidebase::model::generated::MAX_FRAME_STOREYS;
    let tallest = resolve_scene(&format!("frame:{MAX_FRAME_STOREYS}")).unwrap();
    let first = slidebase::headless::frame::modes(&tallest)
        .unwrap()
        .frequencies_hz[0];
    assert!(
        first > 0.01 && first < 0.634,
        "first sway frequency {first} Hz"
    );
    let taller = format!("frame:{}", MAX_FRAME_STOREYS + 1);
    let e = resolve_scene(&taller).unwrap_err().to_string();
    assert!(
        e.contains("--scene")
            && e.contains("buckles")
            && e.contains(&format!("frame:{MAX_FRAME_STOREYS}")),
        "{e}"
    );
}
