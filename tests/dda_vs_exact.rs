//! The DDA model of the paper's two-mass system (Fig. 2) against the exact solution of the
//! mass-spring model (Appendix I): the paper's validation (Figs 4–9), with the issue's
//! acceptance thresholds on the relative errors of the four normalised peak responses.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::dda::{ContactEnforcement, Integrator, SolverParams};
use slidebase::headless::run::run;
use slidebase::headless::simulate::{ModelRun, run_dda, run_exact_two_block};
use slidebase::headless::sweep::{SweepRequest, paper_ratios, run_sweep};
use slidebase::post::sweep::error_table;
use slidebase::setup::{ExcitationSpec, ModelKind, RunSpec};

fn sweep(
    alphas: Vec<f64>,
    frictions: Vec<f64>,
    ratios: Vec<f64>,
    duration: f64,
) -> slidebase::post::sweep::ErrorTable {
    sweep_with(alphas, frictions, ratios, duration, None).0
}

/// The sweep's error table and the DDA rows' energy residuals.
fn sweep_with(
    alphas: Vec<f64>,
    frictions: Vec<f64>,
    ratios: Vec<f64>,
    duration: f64,
    integrator: Option<Integrator>,
) -> (slidebase::post::sweep::ErrorTable, Vec<f64>) {
    let req = SweepRequest {
        alphas,
        frictions,
        freq_ratios: ratios,
        amplitude_g: 0.3,
        damping: None,
        duration: Some(duration),
        dt: Some(1e-3),
        integrator,
        confirm_large: false,
        models: vec![ModelKind::MassSpring, ModelKind::Dda],
        shard: None,
    };
    let (rows, failures) = run_sweep(&req, &|| {});
    assert!(failures.is_empty(), "failed runs: {failures:?}");
    let residuals = rows
        .iter()
        .filter(|r| r.model == "dda")
        .map(|r| r.energy_residual_rel.abs())
        .collect();
    (error_table(&rows, 0.01), residuals)
}

/// A dozen representative points (light and heavy raft, low and high friction, below, at
/// and above resonance) over 30 s: every metric within the acceptance bounds.
#[test]
fn dda_matches_the_exact_model_on_representative_points() {
    let mut rows = Vec::new();
    let points = [
        (0.1, 0.01, 0.1),
        (0.1, 0.25, 1.0),
        (0.1, 0.05, 10.0),
        (0.5, 0.1, 0.3),
        (0.5, 0.1, 1.0),
        (0.5, 0.25, 3.16),
        (0.5, 0.01, 10.0),
        (0.9, 0.25, 0.5),
        (0.9, 0.05, 1.0),
        (0.9, 0.1, 2.15),
        (0.9, 0.01, 6.8),
        (0.3, 0.05, 1.47),
    ];
    for &(alpha, friction, ratio) in &points {
        let t = sweep(vec![alpha], vec![friction], vec![ratio], 30.0);
        rows.push(((alpha, friction, ratio), t));
    }
    for ((a, f, r), t) in &rows {
        for (k, m) in t.metrics.iter().enumerate() {
            // Displacements and roof acceleration: 3 % (the 90th-percentile bound) at any
            // single point; base acceleration: 10 %.
            let bound = if k == 2 { 0.10 } else { 0.03 };
            assert!(
                m.max <= bound,
                "α={a} ρ={f} Ω/ω={r}: {} error {:.3} %",
                m.name,
                100.0 * m.max
            );
        }
    }
}

/// The full Figs 4–9 grid (3 α × 4 ρ × the paper's 25 ratios, which include 0.5, 2 and 5;
/// 100 s, 0.3 g, Δt = 1 ms) against issue 13's targets for every metric: median ≤ 0.1 %,
/// 90th percentile ≤ 0.5 %, largest ≤ 2 %.
///
/// - The trapezoidal rule (non-dissipative) meets all of them, and its energy balance
///   closes: residual median ≤ 1e-8, largest ≤ 1e-6 of the energy that passed through.
/// - So does the scene's default, generalised-α with ρ∞ = 0.5 (the two-block scene asks
///   for it: rigid blocks, nothing to annihilate). The solver's default for deformable
///   scenes, ρ∞ = 0, has a 5× larger error constant on the resolved motion: its largest
///   slip error is 6.2 % at (0.9, 0.05, 10) — second order, 0.2 % at Δt = 0.25 ms — so
///   the two-block scene does not use it; its energy is checked here, its errors are not.
///
/// Slow (≈ 4 min in release): run with `cargo test --release -- --ignored`.
#[test]
#[ignore]
fn full_paper_grid_meets_the_targets() {
    for integrator in [None, Some("trapezoidal"), Some("generalized-alpha:0")] {
        let (t, residuals) = sweep_with(
            vec![0.1, 0.5, 0.9],
            vec![0.01, 0.05, 0.1, 0.25],
            paper_ratios(),
            100.0,
            integrator.map(|i| Integrator::parse(i).unwrap()),
        );
        let integrator = integrator.unwrap_or("the scene's default");
        println!("{integrator}:\n{t}");
        // ρ∞ = 0's errors are reported (docs/validation.md), not asserted.
        let annihilating = integrator == "generalized-alpha:0";
        for m in t.metrics.iter().filter(|_| !annihilating) {
            assert_eq!(m.count, 300);
            assert!(
                m.median <= 1e-3 && m.p90 <= 5e-3 && m.max <= 0.02,
                "{integrator}, {}: median {:.3} %, 90th {:.3} %, max {:.3} % at {:?}",
                m.name,
                100.0 * m.median,
                100.0 * m.p90,
                100.0 * m.max,
                m.worst
            );
        }
        let mut r = residuals.clone();
        r.sort_by(f64::total_cmp);
        let (median, max) = (r[r.len() / 2], r[r.len() - 1]);
        assert!(
            median <= 1e-8 && max <= 1e-6,
            "{integrator}: energy residual median {median:.1e}, max {max:.1e}"
        );
    }
}

/// Fixed base: the DDA roof follows the undamped SDOF closed form (ρ → ∞) — the bonded
/// joint, the bolt spring and the integrator reproduce ω = 2π rad/s.
#[test]
fn fixed_base_dda_is_the_sdof_oscillator() {
    for &ratio in &[0.5, 2.0] {
        let req = RunSpec {
            fixed_base: true,
            excitation: ExcitationSpec::ratio(ratio),
            duration: Some(10.0),
            ..RunSpec::default()
        };
        let dda = run(&req).unwrap();
        let exact = run(&RunSpec {
            model: ModelKind::MassSpring,
            ..req
        })
        .unwrap();
        let (a, b) = (
            dda.summary.ur_max_over_d.unwrap(),
            exact.summary.ur_max_over_d.unwrap(),
        );
        assert!(
            (a - b).abs() < 1e-3 * b,
            "Ω/ω = {ratio}: DDA {a} vs exact {b}"
        );
        assert!(
            dda.summary.us_max_m < 1e-6,
            "a fixed base does not slip: {}",
            dda.summary.us_max_m
        );
    }
}

/// Frictionless joint: nothing reaches the roof (u_r ≈ 0) and the slip is the ground's own
/// displacement, ΩT − sin ΩT in units of D.
#[test]
fn frictionless_dda_raft_stays_put() {
    let req = RunSpec {
        friction: Some(0.0),
        excitation: ExcitationSpec::ratio(1.0),
        duration: Some(10.0),
        ..RunSpec::default()
    };
    let s = run(&req).unwrap().summary;
    let omega_t = 2.0 * std::f64::consts::PI * 10.0;
    let expected = omega_t - omega_t.sin();
    assert!(
        (s.us_max_over_d.unwrap() - expected).abs() < 1e-4 * expected,
        "{:?} vs {expected}",
        s.us_max_over_d
    );
    assert!(
        s.ur_max_over_d.unwrap() < 1e-4,
        "u_r/D = {:?}",
        s.ur_max_over_d
    );
}

/// The DDA run of `spec` with `params` adjusted, and the exact model of the same point.
fn dda_and_exact(
    spec: RunSpec,
    adjust: impl FnOnce(SolverParams) -> SolverParams,
) -> (ModelRun, ModelRun) {
    let setup = spec.prepare().unwrap();
    let run = run_dda(&setup, &setup.scene, adjust(setup.solver_params())).unwrap();
    let exact = run_exact_two_block(&setup, 0.0).unwrap();
    (run, exact)
}

/// With 0 < ρ∞ < 1 the generalised-α scheme once balanced the forces at its α point: a
/// contact's force was then an average over two instants, the first slip of a light raft
/// at Ω/ω = 10 was found 1/(1 − αf) late (0.88 ms instead of 0.59 ms at ρ∞ = 0.5), with
/// the stuck base's acceleration past what friction can hold (a_base +35 % at ρ∞ = 0.5,
/// +53 % at 0.8), and the friction work booked at the end did not match the force
/// applied (energy residual −5e-4). Balanced at the step's end (Arnold and Brüls' form),
/// every scheme of the family finds the exact model's peak base acceleration within
/// 0.1 % (it is reached at the first slip, where friction lets go), and the ledger
/// closes to round-off.
#[test]
fn every_generalised_alpha_scheme_finds_the_first_slip() {
    for integrator in ["generalized-alpha:0.5", "generalized-alpha:0.8", "hht:0.1"] {
        let spec = RunSpec {
            alpha: Some(0.1),
            friction: Some(0.01),
            excitation: ExcitationSpec::ratio(10.0),
            duration: Some(2.0),
            integrator: Some(Integrator::parse(integrator).unwrap()),
            ..RunSpec::default()
        };
        let (run, exact) = dda_and_exact(spec, |p| p);
        let error = (run.peaks.base_accel - exact.peaks.base_accel).abs() / exact.peaks.base_accel;
        assert!(
            error < 1e-3,
            "{integrator}: a_base {} vs exact {} (error {error:.1e})",
            run.peaks.base_accel,
            exact.peaks.base_accel
        );
        assert!(
            run.energy_residual_rel.abs() < 1e-8,
            "{integrator}: energy residual {:.1e}",
            run.energy_residual_rel
        );
    }
}

/// `restart_after_events = false` once spun forever at t ≈ 14.2 s of the default run (an
/// event at a step's start asked for a restart that never came). Every step must end, and
/// without restarts the run must still be the same physics: the slip within 2 % of the
/// exact model's (the event resolution only sharpens the transitions).
#[test]
fn runs_without_event_restarts_finish_and_agree() {
    let spec = RunSpec {
        duration: Some(20.0),
        ..RunSpec::default()
    };
    let (run, exact) = dda_and_exact(spec, |p| SolverParams {
        restart_after_events: false,
        ..p
    });
    assert!(run.steps >= 20_000, "{} steps", run.steps);
    let error = (run.peaks.slip_m - exact.peaks.slip_m).abs() / exact.peaks.slip_m;
    assert!(
        error < 0.02,
        "slip {} vs exact {} (error {error:.1e})",
        run.peaks.slip_m,
        exact.peaks.slip_m
    );
}

/// Issue 13, item 1: with penalty springs a stuck joint is an oscillator, and at Δt = 1e-4
/// with the (non-dissipative) trapezoidal rule its ringing after every re-stick put
/// a_base/a_g 30 % above the exact model's at (α 0.5, ρ 0.1, Ω/ω 2). With the augmented
/// Lagrangian the stuck joint is an exact constraint: every peak within 0.5 % (the
/// issue's p90 target), at the step size where the penalty method is worst.
#[test]
#[ignore = "1e-4 s steps: run in release (cargo test --release -- --ignored)"]
fn augmented_lagrangian_contacts_do_not_ring_at_fine_steps() {
    let spec = RunSpec {
        alpha: Some(0.5),
        friction: Some(0.1),
        excitation: ExcitationSpec::ratio(2.0),
        duration: Some(20.0),
        dt: Some(1e-4),
        integrator: Some(Integrator::Trapezoidal),
        ..RunSpec::default()
    };
    let (run, exact) = dda_and_exact(spec, |p| SolverParams {
        contact_enforcement: ContactEnforcement::AugmentedLagrangian,
        ..p
    });
    let (p, e) = (&run.peaks, &exact.peaks);
    for (name, dda, reference) in [
        ("slip", p.slip_m, e.slip_m),
        ("drift", p.drift_m, e.drift_m),
        ("a_base", p.base_accel, e.base_accel),
        ("a_roof", p.roof_accel, e.roof_accel),
    ] {
        let error = (dda - reference).abs() / reference.abs();
        assert!(
            error < 5e-3,
            "{name}: {dda} vs exact {reference} (error {error:.1e})"
        );
    }
}

/// The paper's large-mass ground (eq. 4) gives the exact model's answer within its recoil
/// error, O(m_structure / m_g) = 1e-4 at the default ratio. It once gave a_base +5 % at
/// every mass ratio: the ground block was deformable, its strain unknowns made the raft's
/// two stuck corners independent constraints, and the event projection split the stick
/// force between them by the ground's strain inertia (+1374 N and −3094 N where the
/// prescribed ground gives −885 N and −836 N) — past friction at each corner, so the raft
/// chattered instead of sticking. The ground is rigid now, as the paper's mass is.
#[test]
fn the_large_mass_ground_is_the_prescribed_ground() {
    use slidebase::model::scene::GroundKind;
    let spec = RunSpec {
        duration: Some(30.0),
        ground: Some(GroundKind::LargeMass),
        ..RunSpec::default()
    };
    let dda = run(&spec).unwrap().summary;
    let exact = run(&RunSpec {
        model: ModelKind::MassSpring,
        ground: None,
        ..spec
    })
    .unwrap()
    .summary;
    for (name, d, e) in [
        ("a_base", dda.abase_over_aground, exact.abase_over_aground),
        ("u_s", dda.us_max_over_d, exact.us_max_over_d),
        ("u_r", dda.ur_max_over_d, exact.ur_max_over_d),
    ] {
        let (d, e) = (d.unwrap(), e.unwrap());
        assert!((d - e).abs() < 1e-3 * e, "{name}: DDA {d} vs exact {e}");
    }
}

/// A ground too fast for Δt (20 g at Ω/ω = 0.2: it reaches 2A/Ω ≈ 312 m/s, and a base it
/// drags would cross the displacement limit, 1 % of the size, ten times over in 1 ms):
/// the steps shrink to the limit and stay there, cut only on the way down (a step grown
/// blindly back towards Δt was cut every third step: 13 727 cuts in 41 841 steps), and
/// the slip is the exact model's to 1e-5 (the steps average ~0.2 ms, five times finer
/// than the 1 ms that meets the paper's 1 % everywhere).
#[test]
fn a_ground_too_fast_for_the_step_is_followed_without_repeated_cuts() {
    let spec = |model| RunSpec {
        model,
        excitation: ExcitationSpec::Harmonic {
            amplitude_g: Some(20.0),
            frequency: Some(slidebase::setup::Frequency::Ratio(0.2)),
        },
        duration: Some(5.0),
        ..RunSpec::default()
    };
    let dda = run(&spec(ModelKind::Dda)).unwrap().summary;
    let exact = run(&spec(ModelKind::MassSpring)).unwrap().summary;
    // 5 000 steps of Δt: the limit holds the steps to a fifth of it on average.
    assert!(
        dda.steps > 5 * 5000,
        "steps were not shortened: {}",
        dda.steps
    );
    let cuts = dda.solver.expect("a DDA run has solver counters").dt_cuts;
    assert!(cuts * 100 < dda.steps, "{cuts} cuts in {} steps", dda.steps);
    // The exact model has no passes, cuts or factorisations: its JSON leaves them out
    // rather than report zeros.
    assert!(exact.solver.is_none());
    let json = serde_json::to_value(&exact).unwrap();
    let dda_json = serde_json::to_value(&dda).unwrap();
    for key in [
        "open_close_passes",
        "dt_cuts",
        "dt_cut_reasons",
        "factorizations",
    ] {
        assert!(json.get(key).is_none(), "exact model's JSON has {key}");
        assert!(dda_json.get(key).is_some(), "DDA's JSON lacks {key}");
    }
    let (d, e) = (dda.us_max_over_d.unwrap(), exact.us_max_over_d.unwrap());
    assert!((d - e).abs() < 1e-5 * e, "slip {d} against the exact {e}");
}
