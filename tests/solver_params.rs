//! One test per `SolverParams` switch that had none (issue 13: "every SolverParams switch
//! gets a test"): each runs a small scene with a known answer and checks what the switch
//! does — a closed form, the documented semantics of the switch, or a conservation law.
//! Each test is a few thousand steps of one or two blocks (milliseconds in debug).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::Error;
use slidebase::dda::{ContactEnforcement, Dda, Integrator, SolverParams, StepReport};
use slidebase::model::Scene;

mod common;

const G: f64 = 9.80665;

/// A 1 m × 1 m box whose bottom is `lift` above a long ground block, with no contact pair
/// declared (it flies or falls freely) when `contact` is None, or a frictional contact
/// with the given normal penalty (None: the default 100 E).
fn box_scene(lift: f64, gravity: f64, contact: Option<Option<f64>>) -> Scene {
    let contact = match contact {
        None => String::new(),
        Some(penalty) => format!(
            "[[contact]]\nblocks = [\"box\", \"ground\"]\nfriction = 0.6\n{}",
            penalty.map_or(String::new(), |p| format!("normal_penalty = {p:e}\n"))
        ),
    };
    let text = format!(
        r#"
name = "box"
gravity = {gravity}
[[block]]
name = "ground"
vertices = [[-10.0, -1.0], [10.0, -1.0], [10.0, 0.0], [-10.0, 0.0]]
material = {{ density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }}
[[block]]
name = "box"
vertices = [[-0.5, {y0}], [0.5, {y0}], [0.5, {y1}], [-0.5, {y1}]]
rigid = true
material = {{ density = 2500.0, youngs_modulus = 3.0e10, poisson_ratio = 0.2 }}
[ground]
block = "ground"
{contact}"#,
        y0 = lift,
        y1 = lift + 1.0,
    );
    Scene::from_toml(&text, "box").unwrap()
}

/// The 1 m deformable box on a 30° incline with μ = 0.3 (it slides: tan 30° > 0.3).
fn incline_scene() -> Scene {
    common::incline_scene(30.0, 0.3)
}

/// Runs the incline for 1 s; returns the step reports, the model, and the travel down the
/// slope relative to the closed form ½ g (sin θ − μ cos θ) t², minus one.
fn slide_down_incline(params: SolverParams) -> (Vec<StepReport>, Dda, f64) {
    let mut dda = Dda::new(&incline_scene(), None, params).unwrap();
    let mut reports = Vec::new();
    dda.run_until(1.0, |_, r| reports.push(*r)).unwrap();
    let (s, c) = 30f64.to_radians().sin_cos();
    let u = dda.blocks()[dda.block_index("box").unwrap()].centroid_displacement();
    let travel = -(u[0] * c + u[1] * s);
    let exact = 0.5 * G * (s - 0.3 * c);
    (reports, dda, travel / exact - 1.0)
}

/// The solver's reason for stopping, or a failure if it did not stop with a solver error.
fn solver_reason<T: std::fmt::Debug>(result: Result<T, Error>) -> (f64, String) {
    match result {
        Err(Error::Solver { time, reason }) => (time, reason),
        other => panic!("expected a solver error, got {other:?}"),
    }
}

/// A square spun at ω = 10 rad/s, Δt = 1 ms, through 5 rad in 500 steps (no gravity, no
/// contacts: nothing but the rotation acts). With `exact_rotation` every vertex lands on
/// the rigid rotation of its start and area and kinetic energy are kept to round-off.
/// The linear map of the step's rotation r₀ = ωΔt, [[1, −r₀], [r₀, 1]], is √(1 + r₀²)
/// times a rotation by atan r₀: after N steps the vertices are (1 + r₀²)^(N/2)·R(N atan r₀)
/// of their start, the area (1 + r₀²)^N ≈ 1.0513 of it and, ω being unchanged and the
/// block keeping its mass, the kinetic energy ½Iω² grows with I ∝ area — all checked
/// against these closed forms.
#[test]
fn exact_rotation_keeps_a_spinning_block_rigid_and_the_linear_map_inflates_it() {
    let (omega, dt, steps) = (10.0, 1e-3, 500);
    let r0: f64 = omega * dt;
    for exact in [true, false] {
        let params = SolverParams {
            dt,
            integrator: Integrator::Trapezoidal,
            initial_equilibrium: false,
            exact_rotation: exact,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&box_scene(0.5, 0.0, None), None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        let start = dda.blocks()[b].clone();
        dda.set_velocity(b, [0.0, 0.0, omega, 0.0, 0.0, 0.0])
            .unwrap();
        let kinetic0 = dda.blocks()[b].kinetic_energy();
        dda.run_until(steps as f64 * dt, |_, _| {}).unwrap();
        assert_eq!(dda.counters().steps, steps);
        let blk = &dda.blocks()[b];
        assert!(
            (blk.rotation - 5.0).abs() < 1e-12,
            "rotation {}",
            blk.rotation
        );

        let n = steps as f64;
        let (scale, angle) = if exact {
            (1.0, n * r0)
        } else {
            ((1.0 + r0 * r0).powf(n / 2.0), n * r0.atan())
        };
        let area_ratio = blk.moments.area / start.moments.area;
        assert!(
            (area_ratio - scale * scale).abs() < 1e-12,
            "exact {exact}: area ratio {area_ratio:.15}, closed form {:.15}",
            scale * scale
        );
        let kinetic_ratio = blk.kinetic_energy() / kinetic0;
        assert!(
            (kinetic_ratio - scale.powi(2)).abs() < 1e-10,
            "exact {exact}: kinetic energy ratio {kinetic_ratio:.15}, closed form {:.15}",
            scale.powi(2)
        );
        let (s, c) = angle.sin_cos();
        let centre = start.moments.centroid;
        for (p, p0) in blk.vertices.iter().zip(&start.vertices) {
            let (x, y) = (p0[0] - centre[0], p0[1] - centre[1]);
            let expected = [
                centre[0] + scale * (c * x - s * y),
                centre[1] + scale * (s * x + c * y),
            ];
            let miss = (p[0] - expected[0]).hypot(p[1] - expected[1]);
            assert!(
                miss < 1e-12,
                "exact {exact}: vertex at {p:?}, closed form {expected:?}"
            );
        }
    }
}

/// `max_open_close_passes` is the number of passes an attempt at a step may take before
/// Δt is cut. On the incline the attempts where the block starts to slide take up to 5
/// passes (an attempt that then lands on the stick-slip event is not the one reported, so
/// the accepted steps show at most 4). The least limit at which no step is cut, P, leaves
/// the run bit for bit as with the default 16; a limit of P − 1 cuts steps, never accepts a
/// step with more passes than the limit, and the block still slides as
/// ½ g (sin θ − μ cos θ) t² to 1e-3 (the travel error of starting the slide half a nominal
/// step late); with no cut allowed (`min_dt_fraction` = 1) the solver stops at the first
/// such step with an error saying why.
#[test]
fn max_open_close_passes_cuts_the_steps_that_need_more_passes() {
    let with_limit = |passes: usize| {
        slide_down_incline(SolverParams {
            max_open_close_passes: passes,
            ..SolverParams::default()
        })
    };
    let end = |d: &Dda| d.blocks()[d.block_index("box").unwrap()].vertices.clone();
    let (_, reference, error) = with_limit(SolverParams::default().max_open_close_passes);
    assert_eq!(reference.counters().cuts, 0);
    assert!(error.abs() < 1e-3, "travel error {error:e}");
    let mut least = SolverParams::default().max_open_close_passes;
    while least > 2 {
        let (_, run, _) = with_limit(least - 1);
        if run.counters().cuts > 0 {
            break;
        }
        assert_eq!(
            end(&run),
            end(&reference),
            "a limit never reached changed the run"
        );
        least -= 1;
    }
    assert!(
        least >= 3,
        "the scene no longer needs more than {least} passes"
    );

    let (reports, cut, cut_error) = with_limit(least - 1);
    assert!(cut.counters().cuts > 0);
    assert!(reports.iter().all(|r| r.passes < least));
    assert!(
        cut_error.abs() < 1e-3,
        "travel error {cut_error:e} with {} cuts",
        cut.counters().cuts
    );

    // The first step that was cut (from the run's counter: a cut made before the step
    // restarts at a contact event is not in that step's report).
    let mut first_cut = None;
    let params = SolverParams {
        max_open_close_passes: least - 1,
        ..SolverParams::default()
    };
    let mut again = Dda::new(&incline_scene(), None, params).unwrap();
    again
        .run_until(1.0, |d, r| {
            if first_cut.is_none() && d.counters().cuts > 0 {
                first_cut = Some(r.time - r.dt);
            }
        })
        .unwrap();
    let began = first_cut.unwrap();
    let no_cut_allowed = SolverParams {
        max_open_close_passes: least - 1,
        min_dt_fraction: 1.0,
        ..SolverParams::default()
    };
    let mut stopped = Dda::new(&incline_scene(), None, no_cut_allowed).unwrap();
    let (time, reason) = solver_reason(stopped.run_until(1.0, |_, _| {}));
    assert!(
        (time - began).abs() < 1e-12,
        "stopped at {time}, the first cut step began at {began}"
    );
    let expected = format!("did not settle in {} passes", least - 1);
    assert!(reason.contains(&expected), "reason: {reason}");
    assert!(reason.contains("Δt cut to 1.000e-3 s"), "reason: {reason}");
}

/// A block flying at v = 0.707 m/s (no gravity, no contacts) moves v·Δt = 50 times the
/// allowed 1e-5 structure sizes (1.414 m) per nominal step, so its first step is cut k
/// times, k the least with cut_factorᵏ ≤ 1/50, and is taken with Δt·cut_factorᵏ: 4 cuts
/// to 0.3⁴ Δt = 8.1 µs for 0.3, 6 cuts to 0.5⁶ Δt = 15.6 µs for 0.5.
#[test]
fn cut_factor_is_the_ratio_of_each_cut() {
    let dt = 1e-3;
    let limit = 1e-5;
    let v = 0.5_f64.sqrt();
    for cut_factor in [0.3, 0.5] {
        let params = SolverParams {
            dt,
            initial_equilibrium: false,
            max_displacement_ratio: limit,
            cut_factor,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&box_scene(0.5, 0.0, None), None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        dda.set_velocity(b, [0.0, -v, 0.0, 0.0, 0.0, 0.0]).unwrap();
        let excess = v * dt / (limit * dda.structure_size());
        let cuts = (excess.ln() / (1.0 / cut_factor).ln()).ceil() as usize;
        let report = dda.step(1.0).unwrap();
        assert_eq!(report.cuts, cuts, "cut factor {cut_factor}");
        let expected = dt * cut_factor.powi(cuts as i32);
        assert!(
            (report.dt - expected).abs() < 1e-12 * expected,
            "cut factor {cut_factor}: Δt {:e}, expected {expected:e}",
            report.dt
        );
        assert!(report.max_displacement_ratio <= limit);
    }
}

/// `min_dt_fraction` is the floor of the cuts. The flying block of the test above needs
/// 0.3⁴ = 0.0081 of Δt: with a floor of 0.008 the step is taken; with 0.009 the solver
/// stops at t = 0 with an error that names the vertex motion, its limit and the last Δt
/// it tried (0.3³ Δt = 27 µs); with 1 (no cut at all) the nominal Δt.
#[test]
fn min_dt_fraction_is_the_floor_of_the_cuts() {
    let run = |min_dt_fraction: f64| {
        let params = SolverParams {
            initial_equilibrium: false,
            max_displacement_ratio: 1e-5,
            min_dt_fraction,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&box_scene(0.5, 0.0, None), None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        dda.set_velocity(b, [0.0, -0.5_f64.sqrt(), 0.0, 0.0, 0.0, 0.0])
            .unwrap();
        dda.step(1.0)
    };
    let report = run(0.008).unwrap();
    assert_eq!(report.cuts, 4);
    assert!((report.dt - 8.1e-6).abs() < 1e-15);

    for (floor, last_dt) in [(0.009, "2.700e-5"), (1.0, "1.000e-3")] {
        let (time, reason) = solver_reason(run(floor));
        assert_eq!(time, 0.0);
        for part in [
            "a vertex moved".to_string(),
            "(limit 1.00e-5)".to_string(),
            format!("Δt cut to {last_dt} s"),
        ] {
            assert!(reason.contains(&part), "floor {floor}: reason: {reason}");
        }
    }
}

/// A block falling freely from rest moves v·Δt + ½gΔt² per step. With a limit of 1e-3
/// structure sizes (1.414 mm) the first cut falls on the first step whose full Δt would
/// exceed it (the step from t = 0.144 s, v = 1.412 m/s), no accepted step exceeds the
/// limit, and the cuts do not disturb the fall: ½gt² to 1e-12 (Newmark is exact for a
/// constant acceleration). With a generous limit (1) no step is cut. A limit that no Δt
/// above the floor can meet stops the solver with an error naming the vertex motion.
#[test]
fn max_displacement_ratio_bounds_every_accepted_step() {
    let (dt, t_end) = (1e-3, 0.3);
    for limit in [1e-3, 1.0] {
        let params = SolverParams {
            dt,
            initial_equilibrium: false,
            max_displacement_ratio: limit,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&box_scene(0.5, G, None), None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        let size = dda.structure_size();
        let mut reports = Vec::new();
        dda.run_until(t_end, |_, r| reports.push(*r)).unwrap();
        assert!(reports.iter().all(|r| r.max_displacement_ratio <= limit));
        let fall = dda.blocks()[b].centroid_displacement()[1];
        assert!(
            (fall + 0.5 * G * t_end * t_end).abs() < 1e-12,
            "limit {limit}: fell {fall}"
        );
        // The first step start t = k·Δt at which g·t·Δt + ½gΔt² exceeds limit·size.
        let k = ((limit * size - 0.5 * G * dt * dt) / (G * dt * dt)).floor() + 1.0;
        let first_cut = reports.iter().find(|r| r.cuts > 0);
        if k * dt < t_end {
            let r = first_cut.expect("no step was cut");
            let began = r.time - r.dt;
            assert!(
                (began - k * dt).abs() < 1e-9,
                "first cut at {began}, expected {}",
                k * dt
            );
            assert!(
                reports
                    .iter()
                    .take_while(|r| r.cuts == 0)
                    .all(|r| r.dt == dt)
            );
        } else {
            assert!(first_cut.is_none(), "limit {limit}: a step was cut");
        }
    }

    let params = SolverParams {
        initial_equilibrium: false,
        max_displacement_ratio: 1e-8,
        ..SolverParams::default()
    };
    let mut dda = Dda::new(&box_scene(0.5, 0.0, None), None, params).unwrap();
    let b = dda.block_index("box").unwrap();
    dda.set_velocity(b, [0.0, -1.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap();
    let (_, reason) = solver_reason(dda.step(1.0));
    assert!(
        reason.contains("a vertex moved") && reason.contains("(limit 1.00e-8)"),
        "reason: {reason}"
    );
}

/// A rigid box (2500 kg) released just touching the ground on two penalty springs of
/// 1e6 N/m (penalty contacts, trapezoidal rule): it sinks onto them and oscillates about
/// the static sag s = mg/2p at ω = √(2p/m). Undamped, every swing reaches 2s. With
/// `contact_damping` ζ (dashpots of 2ζ√(p·m/2) on each spring: ζ of critical for the
/// box) the swings decay with the logarithmic decrement 2πζ/√(1 − ζ²), and once they
/// have died out the dashpots have dissipated half the work of gravity, ½mgs (the rest
/// is stored in the springs). The ledger books it as `contact_damping`, and the balance
/// closes as well as without dashpots (their term within 0.1 % of the work they do).
#[test]
fn contact_damping_is_the_damping_ratio_of_the_contact_springs() {
    let (mass, penalty) = (2500.0, 1e6);
    let sag = mass * G / (2.0 * penalty);
    let run = |zeta: f64| {
        let params = SolverParams {
            duration: 5.0,
            integrator: Integrator::Trapezoidal,
            contact_enforcement: ContactEnforcement::Penalty,
            initial_equilibrium: false,
            contact_damping: zeta,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&box_scene(0.0, G, Some(Some(penalty))), None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        let mut heights = Vec::new();
        dda.run_until(5.0, |d, _| {
            heights.push(d.blocks()[b].centroid_displacement()[1])
        })
        .unwrap();
        // The deepest point of each swing, as its amplitude about the static sag.
        let swings: Vec<f64> = (1..heights.len() - 1)
            .filter(|&i| heights[i] < heights[i - 1] && heights[i] <= heights[i + 1])
            .map(|i| -heights[i] - sag)
            .collect();
        (dda, swings)
    };

    let (free, swings) = run(0.0);
    assert!(swings.len() > 20);
    for a in &swings {
        assert!(
            (a - sag).abs() < 1e-3 * sag,
            "undamped swing {a}, sag {sag}"
        );
    }
    assert_eq!(free.energy().contact_damping, 0.0);

    let zeta = 0.05;
    let (damped, swings) = run(zeta);
    let decrement = (swings[0] / swings[5]).ln() / 5.0;
    let expected = 2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt();
    assert!(
        (decrement - expected).abs() < 0.01 * expected,
        "logarithmic decrement {decrement}, expected {expected}"
    );
    let e = damped.energy();
    let half_work = 0.5 * mass * G * sag;
    assert!(
        (e.contact_damping - half_work).abs() < 1e-3 * half_work,
        "dashpots dissipated {} J, expected {half_work} J",
        e.contact_damping
    );
    let unbooked = |d: &Dda| d.energy().residual();
    assert!(
        (unbooked(&damped) - unbooked(&free)).abs() < 1e-3 * e.contact_damping,
        "residual {} J with dashpots, {} J without",
        unbooked(&damped),
        unbooked(&free)
    );
    assert!(damped.energy_residual_relative().abs() < 1e-3);
}

/// The augmented Lagrangian iterates until every closed contact's violation times its
/// penalty is below `constraint_tolerance` of the largest contact force. Checked on every
/// accepted step of the incline for the default 1e-10, 1e-6 and a loose 1e-2 (at 1e-6 the
/// event projection once waited for multipliers at round-off, 1e-8 N, gave up after 200
/// updates and left the velocities unprojected: travel error 1e-3): the penetration p·g
/// stays within the tolerance of the largest contact force; the loose tolerance takes
/// fewer constraint solves; and the slide still follows ½ g (sin θ − μ cos θ) t² within the
/// error the tolerance allows — friction off by at most tol of the two contacts' largest
/// force, 2·tol·μ cos θ/(sin θ − μ cos θ) of the acceleration — plus the 1e-5 the default
/// run is allowed.
#[test]
fn constraint_tolerance_trades_iterations_for_constraint_accuracy() {
    let mut iterations = Vec::new();
    for tolerance in [1e-10, 1e-6, 1e-2] {
        let params = SolverParams {
            constraint_tolerance: tolerance,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&incline_scene(), None, params).unwrap();
        let size = dda.structure_size();
        let mut worst = 0.0_f64;
        dda.run_until(1.0, |d, r| {
            let closed = d.contacts().iter().filter(|c| c.state.is_closed());
            let force = closed
                .clone()
                .map(|c| {
                    let (n, t) = d.contact_force(c);
                    n.abs().max(t.abs())
                })
                .fold(0.0, f64::max);
            let penalty = closed.map(|c| c.props.normal_penalty).fold(0.0, f64::max);
            if force > 0.0 {
                worst = worst.max(penalty * r.max_penetration_ratio * size / (tolerance * force));
            }
        })
        .unwrap();
        assert!(
            worst <= 1.0 + 1e-9,
            "tolerance {tolerance}: a violation reached {worst} × tolerance × force"
        );
        let (s, c) = 30f64.to_radians().sin_cos();
        let u = dda.blocks()[dda.block_index("box").unwrap()].centroid_displacement();
        let error = -(u[0] * c + u[1] * s) / (0.5 * G * (s - 0.3 * c)) - 1.0;
        let bound = 2.0 * tolerance * 0.3 * c / (s - 0.3 * c) + 1e-5;
        assert!(
            error.abs() < bound,
            "tolerance {tolerance}: travel error {error:e}, bound {bound:e}"
        );
        iterations.push(dda.counters().constraint_iterations);
    }
    assert!(
        iterations.windows(2).all(|w| w[1] <= w[0]) && iterations[2] < iterations[0],
        "constraint solves: {iterations:?}"
    );
}

/// A tolerance the multipliers cannot reach, or one that would let contacts leak, is
/// refused before the run, naming the field.
#[test]
fn constraint_tolerance_out_of_range_is_refused() {
    for bad in [-1e-6, 0.0, 1e-16, 0.5, f64::NAN] {
        let params = SolverParams {
            constraint_tolerance: bad,
            ..SolverParams::default()
        };
        let err = Dda::new(&incline_scene(), None, params)
            .unwrap_err()
            .to_string();
        assert!(err.contains("constraint_tolerance"), "{bad}: {err}");
    }
}
