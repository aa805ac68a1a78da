//! The paper's seismic case (Figs 10–18): the three-storey frame of blocks and connection
//! elements on El Centro 1940, sliding against fixed base, DDA against the equivalent MDOF
//! mass-spring model.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::headless::frame::{
    PAPER_FREQUENCIES_HZ, equivalent_mdof, free_vibration_frequencies, modes, run_frame, run_mdof,
};
use slidebase::model::presets::resolve_scene;
use slidebase::setup::{ExcitationSpec, RunSpec};

/// The fixed-base frame has the paper's natural frequencies 0.638, 1.788 and 2.583 Hz
/// (each within 2 %), from the DDA tangent stiffness and mass.
#[test]
fn natural_frequencies_match_the_paper() {
    let scene = resolve_scene("three-storey").unwrap();
    let m = modes(&scene).unwrap();
    assert_eq!(m.frequencies_hz.len(), 3);
    for (f, p) in m.frequencies_hz.iter().zip(PAPER_FREQUENCIES_HZ) {
        assert!(
            (f / p - 1.0).abs() < 0.02,
            "{f} Hz against the paper's {p} Hz"
        );
    }
    // First mode: all floors move together, increasing with height.
    let s = &m.shapes[0];
    assert!(s[1] > 0.0 && s[2] > s[1] && s[3] > s[2], "{s:?}");
}

/// Independent confirmation: every modal frequency has a Fourier peak of a free-vibration
/// run of the fixed-base frame (trapezoidal rule, no numerical damping) within 1 %.
#[test]
fn free_vibration_confirms_the_modes() {
    let scene = resolve_scene("three-storey").unwrap();
    let modal = modes(&scene).unwrap().frequencies_hz;
    // The six highest spectral peaks: the sway modes and whatever else the kick excites.
    let measured = free_vibration_frequencies(&scene, 120.0, 0.005, 6).unwrap();
    for f in &modal {
        let nearest = measured
            .iter()
            .copied()
            .min_by(|a, b| (a - f).abs().total_cmp(&(b - f).abs()))
            .unwrap();
        assert!(
            (nearest / f - 1.0).abs() < 0.01,
            "modal {f} Hz: nearest FFT peak {nearest} Hz ({measured:?})"
        );
    }
}

/// The equivalent MDOF model keeps the frame's mass and has its frequencies.
#[test]
fn equivalent_mdof_has_the_frame_mass_and_frequencies() {
    let scene = resolve_scene("three-storey").unwrap();
    let (b, report) = equivalent_mdof(&scene).unwrap();
    let total: f64 = b.raft_mass + b.storey_masses.iter().sum::<f64>();
    let dda_mass: f64 = scene
        .blocks
        .iter()
        .filter(|blk| blk.name != "ground")
        .map(|blk| {
            blk.material.density
                * slidebase::model::geometry::moments(&blk.vertices, &blk.name)
                    .unwrap()
                    .area
        })
        .sum();
    // 4e-4: DDA's mass is density × current area, and the settled blocks are compressed.
    assert!(
        (total / dda_mass - 1.0).abs() < 1e-3,
        "{total} vs {dda_mass}"
    );
    for (f, g) in b
        .fixed_base_frequencies_hz()
        .iter()
        .zip(&report.frequencies_hz)
    {
        assert!((f / g - 1.0).abs() < 1e-6);
    }
}

/// Sliding base (ρ = 0.01) on El Centro: DDA (generalised-α) and the MDOF model agree on
/// the maximum slip and the peak roof acceleration within 10 %. The residual slip is
/// ill-conditioned — the MDOF model's own changes by 12 % when its storey stiffness moves
/// by 1 % — and the two differ by about 22 %, from one episode near 12 s (see
/// docs/three-storey.md); it is checked within 30 %.
#[test]
fn sliding_frame_matches_the_mdof_model() {
    let req = RunSpec::scene("three-storey");
    let dda = run_frame(&req).unwrap().summary;
    let mdof = run_mdof(&req).unwrap().summary;
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(
        rel(dda.max_slip_m, mdof.max_slip_m) < 0.10,
        "max slip {} vs {}",
        dda.max_slip_m,
        mdof.max_slip_m
    );
    assert!(
        rel(dda.peak_roof_accel_g, mdof.peak_roof_accel_g) < 0.10,
        "roof {} vs {}",
        dda.peak_roof_accel_g,
        mdof.peak_roof_accel_g
    );
    assert!(
        rel(dda.residual_slip_m, mdof.residual_slip_m) < 0.30,
        "residual {} vs {}",
        dda.residual_slip_m,
        mdof.residual_slip_m
    );
    // Isolation: the sliding roof feels a fraction of the ground's peak.
    assert!(dda.peak_roof_accel_g < 0.5 * dda.peak_ground_accel_g);
    // The roof's acceleration has no step-wide spikes to smooth away: low-passed at 25 Hz
    // its peak stays within 1 % (the Gaussian's gain at the frame's highest mode, 2.6 Hz,
    // is 0.997), and never above the raw one.
    let low = dda.peak_roof_accel_25hz_g.unwrap();
    assert!(
        low <= dda.peak_roof_accel_g && low > 0.99 * dda.peak_roof_accel_g,
        "low-passed roof {low} g against {} g",
        dda.peak_roof_accel_g
    );
    // The friction of a sliding joint starts each step from the extrapolated normal force,
    // so the open-close iteration settles in about one pass per step (1.02 measured; 1.40
    // when it started from the force at the step start and needed a pass to correct it).
    let passes = dda.solver.expect("a DDA run's counters").open_close_passes;
    let passes_per_step = passes as f64 / dda.steps as f64;
    assert!(passes_per_step < 1.1, "{passes_per_step} passes per step");
    // Issue 13's target for the energy balance (measured −3.6e-8).
    assert!(
        dda.energy_residual_rel.abs() < 1e-6,
        "energy residual {}",
        dda.energy_residual_rel
    );
}

/// Fixed base: DDA and MDOF peak roof accelerations agree within 6 % (5.5 % measured: the
/// frame's third mode is not exactly a shear-building mode) and the roof drifts within 2 %.
#[test]
fn fixed_base_frame_matches_the_mdof_model() {
    let req = RunSpec {
        fixed_base: true,
        ..RunSpec::scene("three-storey")
    };
    let dda = run_frame(&req).unwrap().summary;
    let mdof = run_mdof(&req).unwrap().summary;
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(
        rel(dda.peak_roof_accel_g, mdof.peak_roof_accel_g) < 0.06,
        "roof {} vs {}",
        dda.peak_roof_accel_g,
        mdof.peak_roof_accel_g
    );
    assert!(
        rel(dda.peak_roof_drift_m, mdof.peak_roof_drift_m) < 0.02,
        "drift {} vs {}",
        dda.peak_roof_drift_m,
        mdof.peak_roof_drift_m
    );
    assert!(
        dda.max_slip_m < 1e-3,
        "a bonded joint does not slide: {}",
        dda.max_slip_m
    );
    // Issue 13's target (measured −1.2e-11; 5e-6 before the bonded corners' lift by the
    // exact rotation update was booked and the kept factor's solves refined).
    assert!(
        dda.energy_residual_rel.abs() < 1e-6,
        "energy residual {}",
        dda.energy_residual_rel
    );
}

/// Issue 13: with the non-dissipative trapezoidal rule at Δt = 1 ms the energy balance
/// closes to 1e-6 of the energy through the frame on every shipped horizontal record,
/// sliding and fixed base (measured: at most 7.5e-8 sliding, 1.8e-9 fixed). Slow:
/// `cargo test --release -- --ignored`. A balance that closes cannot see a structure
/// that turns its weight's work into strain for the wrong reason (the Chi-Chi sag of
/// stop 30, where the strain energy took the gravity work): the frame's height is
/// checked by `the_frame_keeps_its_height_on_long_strong_records`.
#[test]
#[ignore]
fn the_energy_balance_closes_on_every_shipped_record() {
    use slidebase::dda::Integrator;
    for name in slidebase::ground_motion::builtin_names() {
        let record = slidebase::ground_motion::builtin_record(name).unwrap();
        if record.is_vertical() {
            continue;
        }
        for fixed_base in [false, true] {
            let req = RunSpec {
                excitation: ExcitationSpec::record(name),
                integrator: Some(Integrator::Trapezoidal),
                fixed_base,
                ..RunSpec::scene("three-storey")
            };
            let s = run_frame(&req).unwrap().summary;
            println!(
                "{name}, fixed base {fixed_base}: energy residual {:.2e}",
                s.energy_residual_rel
            );
            assert!(
                s.energy_residual_rel.abs() < 1e-6,
                "{name}, fixed base {fixed_base}: energy residual {:.2e}",
                s.energy_residual_rel
            );
        }
    }
}

/// A frame settled under its own weight is in equilibrium: a dynamic run under the same
/// load, with no earthquake, leaves it at rest (trapezoidal rule, 2 s), fixed base and on
/// its sliding joint. Gravity does no work and nothing moves but round-off. The
/// connections' strain is read from their nodes' positions (stop 31), whose round-off,
/// ε·H for a frame of height H, walks at random over the N steps: a settlement of
/// ε·H·√N ≈ 1e-13 m, 5e-5 J of the floors' weight (5e8 N); the work is held to ten
/// times that (measured 4.2e-5 J fixed base). (Before the settled
/// state was refined to the forces of its own geometry, and before each step's
/// accelerations were made to balance the forces of the geometry it moved to, the frame
/// crept: 6.6e4 J of gravity work and 131 J of kinetic energy in 10 s.)
#[test]
fn a_settled_frame_stays_at_rest_under_gravity() {
    use slidebase::dda::{Dda, Integrator, SolverParams};
    for fixed_base in [true, false] {
        let mut scene = resolve_scene("three-storey").unwrap();
        for c in &mut scene.contacts {
            c.bonded = fixed_base;
        }
        let params = SolverParams {
            integrator: Integrator::Trapezoidal,
            ..Default::default()
        };
        let mut dda = Dda::new(&scene, None, params).unwrap();
        let free = || dda.blocks().iter().filter(|b| b.name != "ground");
        let weight: f64 = free().map(|b| b.total_mass() * 9.80665).sum();
        let height = free()
            .flat_map(|b| b.vertices.iter().map(|v| v[1]))
            .fold(0.0_f64, f64::max);
        let steps = 2.0 / dda.params().dt;
        let round_off_work = 10.0 * weight * f64::EPSILON * height * steps.sqrt();
        let mut fastest = 0.0_f64;
        dda.run_until(2.0, |d, _| {
            for b in d.blocks() {
                fastest = fastest.max(b.velocity[0].hypot(b.velocity[1]));
            }
        })
        .unwrap();
        let e = dda.energy();
        assert!(
            fastest < 1e-9,
            "fixed base {fixed_base}: a block moved at {fastest:.2e} m/s"
        );
        assert!(
            e.external_work.abs() < round_off_work
                && e.kinetic < 1e-12
                && e.residual().abs() < 1e-6,
            "fixed base {fixed_base}: {e:?}, round-off bound {round_off_work:.2e} J"
        );
    }
}

/// Robustness: the frame on every shipped horizontal record (up to the 1.2 g Pacoima Dam)
/// runs to the end, without NaN, with an energy residual below 1 %. Slow: `cargo test --release -- --ignored`.
#[test]
#[ignore]
fn every_shipped_record_runs_to_the_end() {
    for name in slidebase::ground_motion::builtin_names() {
        let req = RunSpec {
            excitation: ExcitationSpec::record(name),
            ..RunSpec::scene("three-storey")
        };
        // A vertical component is not a horizontal ground motion: refused, not run.
        if slidebase::ground_motion::builtin_record(name)
            .unwrap()
            .is_vertical()
        {
            let e = run_frame(&req).unwrap_err().to_string();
            assert!(e.contains("vertical"), "{name}: {e}");
            continue;
        }
        let s = run_frame(&req)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .summary;
        for v in [
            s.max_slip_m,
            s.residual_slip_m,
            s.peak_roof_accel_g,
            s.peak_base_accel_g,
            s.energy_residual_rel,
        ] {
            assert!(v.is_finite(), "{name}: {s:?}");
        }
        assert!(
            s.energy_residual_rel.abs() < 0.01,
            "{name}: energy residual {}",
            s.energy_residual_rel
        );
        println!(
            "{name}: slip {:.3} m, roof {:.3} g, energy residual {:.2e}",
            s.max_slip_m, s.peak_roof_accel_g, s.energy_residual_rel
        );
    }
}

/// The frame keeps its height: under the trapezoidal rule its roof's mean height over the
/// last 8 s of the record stays within the drop its sway explains by geometry alone — a
/// storey that leans by its drift D lowers its top by D²/2h at most (h the storey
/// height; D is the roof's peak drift, so the bound counts all the drift in one storey).
/// On the 90 s Chi-Chi record the connections' summed strains once lost the area the
/// columns' step-to-step shear took (Δγ²/4 per step) with no stress to resist it, and the
/// floors sank 8.8 cm (bound 0.2 mm), gravity doing 34 MJ of work against 3.5 MJ of input;
/// the energy balance closed all the same. Kobe is the strongest shipped record. Slow:
/// `cargo test --release -- --ignored`.
#[test]
#[ignore]
fn the_frame_keeps_its_height_on_long_strong_records() {
    use slidebase::dda::Integrator;
    for name in ["chi-chi-tcu045-n", "kobe-nishi-akashi-000"] {
        for fixed_base in [false, true] {
            let req = RunSpec {
                excitation: ExcitationSpec::record(name),
                integrator: Some(Integrator::Trapezoidal),
                fixed_base,
                ..RunSpec::scene("three-storey")
            };
            let setup = req.prepare().unwrap();
            let (mut dda, probe) = setup
                .build_dda(&setup.scene, setup.solver_params())
                .unwrap();
            let column = dda.block_index("column-1-left").unwrap();
            let ys = dda.blocks()[column].vertices.iter().map(|v| v[1]);
            let storey = ys.clone().fold(f64::MIN, f64::max) - ys.fold(f64::MAX, f64::min);
            let height = |d: &slidebase::dda::Dda| d.blocks()[probe.roof].moments.centroid[1];
            let drift = |d: &slidebase::dda::Dda| {
                d.blocks()[probe.roof].centroid_displacement()[0]
                    - d.blocks()[probe.base].centroid_displacement()[0]
            };
            let settled = height(&dda);
            let (mut peak_drift, mut sum, mut samples) = (0.0_f64, 0.0, 0);
            let window_start = setup.duration - 8.0;
            dda.run_until(setup.duration, |d, _| {
                peak_drift = peak_drift.max(drift(d).abs());
                if d.time() > window_start {
                    sum += height(d) - settled;
                    samples += 1;
                }
            })
            .unwrap();
            let mean_rise = sum / samples as f64;
            let bound = peak_drift * peak_drift / (2.0 * storey);
            println!(
                "{name}, fixed base {fixed_base}: mean rise {mean_rise:.3e} m, bound {bound:.3e} m"
            );
            assert!(
                mean_rise.abs() < bound,
                "{name}, fixed base {fixed_base}: the roof's mean height moved by \
                 {mean_rise:.3e} m, more than the sway's {bound:.3e} m"
            );
        }
    }
}
