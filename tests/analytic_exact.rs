//! The built-in exact solver of the paper's mass-spring model (Appendix I) is the benchmark
//! of the DDA model, so it is checked against closed forms, conservation and itself.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::analytic::{
    ExactOptions, ShearBuilding, paper_metrics, sdof_harmonic_from_rest, simulate,
};
use slidebase::ground_motion::{GroundMotion, Harmonic, Record};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn harmonic(ratio: f64) -> (Harmonic, GroundMotion) {
    let h = Harmonic::from_g_hz(0.3, ratio).unwrap();
    (h, GroundMotion::Harmonic(h))
}

/// ρ → ∞: the raft never slips and u_r is the undamped SDOF response from rest, in closed
/// form, including resonance.
#[test]
fn infinite_friction_is_the_fixed_base_sdof_closed_form() {
    for &ratio in &[0.3, 1.0, 2.7] {
        let b = ShearBuilding::two_mass(0.5, 1.0, f64::INFINITY).unwrap();
        let (h, g) = harmonic(ratio);
        let r = simulate(&b, &g, 20.0, 0.01, &ExactOptions::default()).unwrap();
        let peak = r.peaks.roof_drift;
        let mut worst = 0.0_f64;
        for (k, &t) in r.time.iter().enumerate() {
            let (u, _) = sdof_harmonic_from_rest(TWO_PI, h.amplitude, h.omega, t);
            worst = worst.max((r.storey_drift[0][k] - u).abs());
        }
        assert!(
            worst < 1e-9 * peak,
            "Ω/ω = {ratio}: max error {worst:e} vs peak {peak:e}"
        );
        assert!(r.slip.iter().all(|&s| s == 0.0));
        assert_eq!(r.events.len(), 1);
    }
}

/// ρ = 0: the raft cannot pass any force, so u_r ≡ 0 and the raft stays put while the
/// ground moves under it: |u_s|max/D = ΩT − sin ΩT.
#[test]
fn frictionless_raft_isolates_completely() {
    for &ratio in &[0.1, 1.0, 10.0] {
        let b = ShearBuilding::two_mass(0.3, 1.0, 0.0).unwrap();
        let (h, g) = harmonic(ratio);
        let t_end = 100.0;
        let r = simulate(&b, &g, t_end, 0.05, &ExactOptions::default()).unwrap();
        let m = paper_metrics(&r, h.amplitude, h.omega);
        let expected = h.omega * t_end - (h.omega * t_end).sin();
        assert!(
            (m.us_max_over_d - expected).abs() < 1e-9 * expected,
            "{ratio}: {} vs {expected}",
            m.us_max_over_d
        );
        assert!(m.ur_max_over_d < 1e-12, "u_r = {}", m.ur_max_over_d);
    }
}

/// The energy balance (input work = kinetic + strain + friction dissipation) closes to
/// 1e-8 of the input work, for harmonic and recorded input.
#[test]
fn energy_balance_closes() {
    let cases = [
        (0.1, 0.05, 0.5),
        (0.5, 0.1, 1.0),
        (0.9, 0.05, 3.0),
        (0.5, 0.01, 10.0),
    ];
    for &(alpha, rho, ratio) in &cases {
        let b = ShearBuilding::two_mass(alpha, 1.0, rho).unwrap();
        let (_, g) = harmonic(ratio);
        let r = simulate(&b, &g, 100.0, 0.0, &ExactOptions::default()).unwrap();
        let e = r.energy;
        assert!(e.input_work > 0.0, "{alpha} {rho} {ratio}: {e:?}");
        assert!(
            e.residual.abs() < 1e-8 * e.input_work,
            "{alpha} {rho} {ratio}: residual {:e} of {:e}",
            e.residual,
            e.input_work
        );
    }
    // A synthetic record: a decaying chirp sampled at 0.01 s (piecewise linear).
    let samples: Vec<f64> = (0..3000)
        .map(|k| k as f64 * 0.01)
        .map(|t| 3.0 * (-0.1 * t).exp() * (TWO_PI * (0.5 + 0.1 * t) * t).sin())
        .collect();
    let g = GroundMotion::Record(std::sync::Arc::new(
        Record::new("chirp", 0.01, samples).unwrap(),
    ));
    let b = ShearBuilding::two_mass(0.6, 1.0, 0.08).unwrap();
    let r = simulate(&b, &g, 35.0, 0.0, &ExactOptions::default()).unwrap();
    assert!(r.events.len() > 4, "the record makes the raft slip");
    assert!(
        r.energy.residual.abs() < 1e-8 * r.energy.input_work,
        "record residual {:e}",
        r.energy.residual
    );
}

/// A slip that stops and at once slides on the same way once left the slip velocity at
/// the root's residual, possibly against the slip: no later stop was found and friction
/// pushed the raft along for the rest of the run (1794 m at (0.5, 0.05, 1.5)). The
/// metrics must equal an independent event-driven integration of the same equations
/// (`scripts/ref2dof.py 0.5 0.05 1.5`: Dormand–Prince 5(4) with bisection on events,
/// printed to 6 digits: u_s/D 4.457606, u_r/D 2.227570, a_b/a_g 1.007331), and the
/// energy balance must close.
#[test]
fn a_slip_that_continues_the_same_way_stops_later() {
    let b = ShearBuilding::two_mass(0.5, 1.0, 0.05).unwrap();
    let (h, g) = harmonic(1.5);
    let r = simulate(&b, &g, 100.0, 0.0, &ExactOptions::default()).unwrap();
    let p = paper_metrics(&r, h.amplitude, h.omega);
    for (name, value, reference) in [
        ("u_s/D", p.us_max_over_d, 4.457606),
        ("u_r/D", p.ur_max_over_d, 2.227570),
        ("a_b/a_g", p.abase_over_aground, 1.007331),
    ] {
        assert!(
            (value - reference).abs() < 2e-6 * reference,
            "{name} {value} vs independent reference {reference}"
        );
    }
    assert!(r.energy.residual.abs() < 1e-8 * r.energy.input_work);
}

/// Where the raft never slides the input work is ~0 (the ground gives back what it put
/// in); the residual was divided by it and came out as ±1. Relative to the energy that
/// passed through (the largest stored energy), the balance must close like anywhere else.
#[test]
fn energy_residual_is_defined_where_nothing_slides() {
    let b = ShearBuilding::two_mass(0.5, 1.0, 0.25).unwrap();
    let (_, g) = harmonic(10.0);
    let r = simulate(&b, &g, 100.0, 0.0, &ExactOptions::default()).unwrap();
    // The first event is the initial phase.
    assert_eq!(
        r.events.len(),
        1,
        "0.3 g against ρ = 0.25 at Ω/ω = 10 never slides"
    );
    let e = r.energy;
    assert!(e.scale > 1e3 * e.input_work.abs(), "{e:?}");
    assert!(e.residual_relative().abs() < 1e-8, "{e:?}");
}

/// Tightening every numerical tolerance does not change the paper's metrics.
#[test]
fn tighter_tolerances_change_nothing() {
    let tight = ExactOptions {
        steps_per_period: 128,
        quadrature_points: 14,
        samples_per_step: 8,
        root_tolerance: 1e-14,
        ..ExactOptions::default()
    };
    for &(alpha, rho, ratio) in &[(0.5, 0.1, 1.0), (0.1, 0.25, 0.3), (0.9, 0.05, 4.6)] {
        let b = ShearBuilding::two_mass(alpha, 1.0, rho).unwrap();
        let (h, g) = harmonic(ratio);
        let a = paper_metrics(
            &simulate(&b, &g, 60.0, 0.0, &ExactOptions::default()).unwrap(),
            h.amplitude,
            h.omega,
        );
        let c = paper_metrics(
            &simulate(&b, &g, 60.0, 0.0, &tight).unwrap(),
            h.amplitude,
            h.omega,
        );
        for (x, y) in [
            (a.us_max_over_d, c.us_max_over_d),
            (a.ur_max_over_d, c.ur_max_over_d),
            (a.abase_over_aground, c.abase_over_aground),
            (a.aroof_over_aground, c.aroof_over_aground),
        ] {
            assert!(
                (x - y).abs() < 1e-7 * y.abs().max(1e-3),
                "{alpha} {rho} {ratio}: {x} vs {y}"
            );
        }
    }
}

/// From rest, a nearly rigid structure (α tiny) starts to slip when |ü0| first reaches ρg:
/// at t = asin(ρg/A)/Ω.
#[test]
fn slip_starts_when_the_ground_exceeds_the_friction_limit() {
    let b = ShearBuilding::two_mass(1e-6, 1.0, 0.1).unwrap();
    let (h, g) = harmonic(0.5);
    let r = simulate(&b, &g, 2.0, 0.0, &ExactOptions::default()).unwrap();
    let expected = (0.1 * b.gravity / h.amplitude).asin() / h.omega;
    let first = r.events[1].time;
    assert!(
        (first - expected).abs() < 1e-6,
        "first slip at {first}, expected {expected}"
    );
}

/// A uniform three-storey shear building has fixed-base frequencies in the ratio
/// 1 : 2.802 : 4.049 — the paper's 0.638, 1.788 and 2.583 Hz with k/m ≈ 81.1 s⁻².
#[test]
fn uniform_three_storey_frequencies() {
    let b = ShearBuilding {
        storey_masses: vec![1.0; 3],
        storey_stiffnesses: vec![81.1; 3],
        raft_mass: 1.0,
        friction: 0.01,
        gravity: 9.80665,
    };
    let f = b.fixed_base_frequencies_hz();
    assert!(
        (f[0] - 0.638).abs() < 0.002
            && (f[1] - 1.788).abs() < 0.004
            && (f[2] - 2.583).abs() < 0.005,
        "{f:?}"
    );
    assert!((f[1] / f[0] - 2.802).abs() < 2e-3 && (f[2] / f[0] - 4.049).abs() < 2e-3);
}

/// The MDOF model: a three-storey building on a sliding raft closes its energy balance
/// under a record, and with ρ = 0 its storeys never deform (nothing reaches them).
#[test]
fn mdof_energy_and_isolation() {
    let samples: Vec<f64> = (0..2000)
        .map(|k| k as f64 * 0.01)
        .map(|t| 4.0 * (TWO_PI * 1.3 * t).sin() * (-0.15 * t).exp())
        .collect();
    let g = GroundMotion::Record(std::sync::Arc::new(
        Record::new("burst", 0.01, samples).unwrap(),
    ));
    let mut b = ShearBuilding {
        storey_masses: vec![1.0, 1.0, 0.8],
        storey_stiffnesses: vec![120.0, 100.0, 80.0],
        raft_mass: 1.2,
        friction: 0.05,
        gravity: 9.80665,
    };
    let r = simulate(&b, &g, 25.0, 0.0, &ExactOptions::default()).unwrap();
    assert!(r.events.len() > 4);
    assert!(
        r.energy.residual.abs() < 1e-8 * r.energy.input_work,
        "{:?}",
        r.energy
    );
    b.friction = 0.0;
    let r = simulate(&b, &g, 25.0, 0.0, &ExactOptions::default()).unwrap();
    assert!(
        r.peaks.roof_drift < 1e-12 && r.peaks.roof_accel < 1e-9,
        "{:?}",
        r.peaks
    );
}

/// Bad parameters are errors, not panics.
#[test]
fn bad_parameters_are_rejected() {
    assert!(ShearBuilding::two_mass(0.0, 1.0, 0.1).is_err());
    assert!(ShearBuilding::two_mass(0.5, 1.0, -0.1).is_err());
    assert!(ShearBuilding::two_mass(0.5, 1.0, f64::NAN).is_err());
    let b = ShearBuilding::two_mass(0.5, 1.0, 0.1).unwrap();
    let (_, g) = harmonic(1.0);
    assert!(simulate(&b, &g, -1.0, 0.0, &ExactOptions::default()).is_err());
}
