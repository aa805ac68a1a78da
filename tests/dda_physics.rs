//! Physical facts the DDA solver must reproduce on small scenes with known answers.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::dda::{Dda, Integrator, SolverParams};
use slidebase::model::Scene;

mod common;
use common::incline_scene;

const G: f64 = 9.80665;

/// Along-slope (down-slope positive) displacement of the box after `t_end` seconds.
fn slide_down(theta_deg: f64, friction: f64, t_end: f64) -> (f64, Dda) {
    let scene = incline_scene(theta_deg, friction);
    let params = SolverParams {
        dt: 1e-3,
        duration: t_end,
        ..SolverParams::default()
    };
    let mut dda = Dda::new(&scene, None, params).unwrap();
    let b = dda.block_index("box").unwrap();
    dda.run_until(t_end, |_, _| {}).unwrap();
    let (s, c) = theta_deg.to_radians().sin_cos();
    let u = dda.blocks()[b].centroid_displacement();
    (-(u[0] * c + u[1] * s), dda)
}

/// A block on a 30° incline with μ = 0.3 slides with a = g(sin θ − μ cos θ): after 1 s it
/// has travelled ½at² (closed form) to within 1 %.
#[test]
fn block_slides_down_an_incline_with_coulomb_acceleration() {
    let theta: f64 = 30.0;
    let mu = 0.3;
    let (s, c) = theta.to_radians().sin_cos();
    let expected = 0.5 * G * (s - mu * c) * 1.0;
    let (travel, dda) = slide_down(theta, mu, 1.0);
    assert!(
        (travel - expected).abs() < 0.01 * expected,
        "travel {travel:.5} m, expected {expected:.5} m"
    );
    // Energy: gravity's work = kinetic + friction + elastic, up to numerical dissipation.
    let e = dda.energy();
    assert!(e.friction_dissipated > 0.0);
    assert!(
        dda.energy_residual_relative().abs() < 1e-3,
        "energy residual {}",
        dda.energy_residual_relative()
    );
}

/// With tan θ < μ the block stays where it is (friction holds it).
#[test]
fn block_stays_on_an_incline_when_friction_holds() {
    let (travel, dda) = slide_down(20.0, 0.5, 1.0);
    assert!(travel.abs() < 1e-6, "the block crept {travel:.3e} m");
    assert!(dda.counters().max_penetration_ratio < 1e-5);
}

/// A block resting on the ground stays at rest: after initial equilibrium nothing moves
/// and the contact penetration is far below the block size.
#[test]
fn block_at_rest_on_the_ground_stays_at_rest() {
    let text = r#"
name = "rest"
[[block]]
name = "ground"
vertices = [[-10.0, -1.0], [10.0, -1.0], [10.0, 0.0], [-10.0, 0.0]]
material = { density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }
[[block]]
name = "box"
vertices = [[-1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [-1.0, 1.0]]
material = { density = 2500.0, youngs_modulus = 3.0e10, poisson_ratio = 0.2 }
[ground]
block = "ground"
[[contact]]
blocks = ["box", "ground"]
friction = 0.6
"#;
    let scene = Scene::from_toml(text, "rest").unwrap();
    for integrator in [
        Integrator::Classic,
        Integrator::Trapezoidal,
        Integrator::default(),
    ] {
        let params = SolverParams {
            dt: 1e-3,
            duration: 2.0,
            integrator,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&scene, None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        dda.run_until(2.0, |_, _| {}).unwrap();
        let u = dda.blocks()[b].centroid_displacement();
        assert!(u[0].hypot(u[1]) < 1e-9, "{integrator:?}: box moved {u:?}");
        assert!(
            dda.counters().max_penetration_ratio < 1e-5,
            "penetration {}",
            dda.counters().max_penetration_ratio
        );
        assert!(dda.counters().cuts == 0);
    }
}

/// A free block thrown in space (no gravity, no contacts) moves as a rigid body: its
/// strains stay zero, its area is preserved and the trapezoidal rule keeps its kinetic
/// energy. Rigid-body motion produces no elastic force.
#[test]
fn rigid_body_motion_produces_no_strain() {
    let text = r#"
name = "free"
gravity = 0.0
[[block]]
name = "ground"
vertices = [[-10.0, -11.0], [10.0, -11.0], [10.0, -10.0], [-10.0, -10.0]]
material = { density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }
[[block]]
name = "box"
vertices = [[0.0, 0.0], [2.0, 0.3], [1.5, 1.2], [-0.2, 0.9]]
material = { density = 2500.0, youngs_modulus = 3.0e10, poisson_ratio = 0.2 }
[ground]
block = "ground"
[[point_load]]
block = "box"
point = [0.8, 0.6]
force = [0.0, 0.0]
"#;
    let scene = Scene::from_toml(text, "free").unwrap();
    let params = SolverParams {
        dt: 1e-3,
        duration: 1.0,
        integrator: Integrator::Trapezoidal,
        initial_equilibrium: false,
        ..SolverParams::default()
    };
    let mut dda = Dda::new(&scene, None, params).unwrap();
    let b = dda.block_index("box").unwrap();
    let area0 = dda.blocks()[b].moments.area;
    dda.set_velocity(b, [0.3, -0.2, 0.5, 0.0, 0.0, 0.0])
        .unwrap();
    let ke0 = dda.blocks()[b].kinetic_energy();
    dda.run_until(1.0, |_, _| {}).unwrap();
    let blk = &dda.blocks()[b];
    for e in blk.strain {
        assert!(e.abs() < 1e-12, "strain {e}");
    }
    assert!((blk.moments.area - area0).abs() < 1e-10 * area0);
    assert!((blk.kinetic_energy() - ke0).abs() < 1e-9 * ke0);
    assert!(
        (blk.rotation - 0.5).abs() < 1e-9,
        "rotation {}",
        blk.rotation
    );
}

/// A box dropped 5 mm onto the ground: with the joint's default `locate_events`, the step
/// in which it lands is shortened to the impact; with `locate_events = false` every step
/// keeps the nominal Δt (the impact is taken at the step end, as in classic DDA) and the
/// box still comes to rest on the ground. This is the switch the generated wall uses for
/// its internal joints.
#[test]
fn a_joint_that_does_not_locate_events_never_shortens_a_step() {
    let scene_text = |locate: bool| {
        format!(
            r#"
name = "drop"
[[block]]
name = "ground"
vertices = [[-10.0, -1.0], [10.0, -1.0], [10.0, 0.0], [-10.0, 0.0]]
material = {{ density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }}
[[block]]
name = "box"
vertices = [[-0.5, 0.005], [0.5, 0.005], [0.5, 1.005], [-0.5, 1.005]]
material = {{ density = 2500.0, youngs_modulus = 3.0e10, poisson_ratio = 0.2 }}
[ground]
block = "ground"
[[contact]]
blocks = ["box", "ground"]
friction = 0.6
locate_events = {locate}
"#
        )
    };
    let dt = 1e-3;
    for locate in [true, false] {
        let scene = Scene::from_toml(&scene_text(locate), "drop").unwrap();
        let params = SolverParams {
            dt,
            duration: 0.3,
            initial_equilibrium: false,
            ..SolverParams::default()
        };
        let mut dda = Dda::new(&scene, None, params).unwrap();
        let b = dda.block_index("box").unwrap();
        let mut shortest = f64::INFINITY;
        dda.run_until(0.3, |_, r| shortest = shortest.min(r.dt))
            .unwrap();
        if locate {
            assert!(shortest < 0.99 * dt, "no step landed on the impact");
        } else {
            assert!(
                (shortest - dt).abs() < 1e-12 * dt,
                "a step was shortened to {shortest}"
            );
        }
        // Fallen 5 mm (free fall takes 32 ms) and resting on the ground.
        let u = dda.blocks()[b].centroid_displacement();
        assert!((u[1] + 0.005).abs() < 1e-4, "locate {locate}: box at {u:?}");
        assert!(
            dda.blocks()[b].velocity[1].abs() < 1e-2,
            "locate {locate}: still moving"
        );
    }
}
