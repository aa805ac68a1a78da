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
    // The friction of a sliding joint starts each step from the extrapolated normal force,
    // so the open-close iteration settles in about one pass per step (1.02 measured; 1.40
    // when it started from the force at the step start and needed a pass to correct it).
    let passes_per_step = dda.open_close_passes as f64 / dda.steps as f64;
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
/// `cargo test --release -- --ignored`. Known blind spot: on Chi-Chi the sliding frame
/// sags in the record's last 30 s under this rule (a growing Nyquist shear oscillation of
/// the columns; see NOTES-issue-13.md, stop 30), which this balance cannot see because
/// the strain energy takes the gravity work; a change of rounding can tip that run into a
/// bad impact and fail this test.
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
/// its sliding joint. Gravity does no work and nothing moves but round-off: the floors'
/// weight is 5e8 N, and 1e-6 J of work is a settlement of 2e-15 m. (Before the settled
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
            e.external_work.abs() < 1e-6 && e.kinetic < 1e-12 && e.residual().abs() < 1e-6,
            "fixed base {fixed_base}: {e:?}"
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
