//! Scenes shared by the integration tests (each test file that uses them declares
//! `mod common;`).

#![allow(clippy::unwrap_used, clippy::expect_used)]
// Each test crate that declares `mod common;` uses a subset of these helpers.
#![allow(dead_code)]

use slidebase::model::Scene;

/// A 1 m square box (ρ = 2000 kg/m³, E = 1 GPa) resting on a `theta_deg` incline 20 m
/// long, 10 m up it, with Coulomb friction `friction` on the joint.
pub fn incline_scene(theta_deg: f64, friction: f64) -> Scene {
    incline_scene_with_law(theta_deg, &friction.to_string())
}

/// The same incline with the joint's friction law written as in a scene file (a number,
/// or e.g. `static-kinetic:0.6,0.4`).
pub fn incline_scene_with_law(theta_deg: f64, law: &str) -> Scene {
    let friction = if law.parse::<f64>().is_ok() {
        law.to_string()
    } else {
        format!("\"{law}\"")
    };
    let (s, c) = theta_deg.to_radians().sin_cos();
    let l = 20.0;
    let a = 1.0;
    let x0 = 10.0;
    let p0 = [x0 * c, x0 * s];
    let v = [
        p0,
        [p0[0] + a * c, p0[1] + a * s],
        [p0[0] + a * c - a * s, p0[1] + a * s + a * c],
        [p0[0] - a * s, p0[1] + a * c],
    ];
    let fmt = |p: [f64; 2]| format!("[{:.15}, {:.15}]", p[0], p[1]);
    let text = format!(
        r#"
name = "incline"
[[block]]
name = "ground"
vertices = [[0.0, -1.0], [{lc}, -1.0], [{lc}, {ls}], [0.0, 0.0]]
material = {{ density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }}
[[block]]
name = "box"
vertices = [{v0}, {v1}, {v2}, {v3}]
material = {{ density = 2000.0, youngs_modulus = 1.0e9, poisson_ratio = 0.2 }}
[ground]
block = "ground"
[[contact]]
blocks = ["box", "ground"]
friction = {friction}
"#,
        lc = l * c,
        ls = l * s,
        v0 = fmt(v[0]),
        v1 = fmt(v[1]),
        v2 = fmt(v[2]),
        v3 = fmt(v[3]),
    );
    Scene::from_toml(&text, "incline").unwrap()
}

/// Runs a two-block specification with DDA and with the exact model and checks the
/// paper's four metrics agree within `tolerance` (relative); `label` names the case.
pub fn assert_two_block_models_agree(
    spec: impl Fn(slidebase::setup::ModelKind) -> slidebase::setup::RunSpec,
    tolerance: f64,
    label: &str,
) {
    use slidebase::headless::run::run;
    use slidebase::setup::ModelKind;
    let dda = run(&spec(ModelKind::Dda)).unwrap().summary;
    let exact = run(&spec(ModelKind::MassSpring)).unwrap().summary;
    for (what, d, e) in [
        ("u_s", dda.us_max_over_d, exact.us_max_over_d),
        ("u_r", dda.ur_max_over_d, exact.ur_max_over_d),
        ("a_base", dda.abase_over_aground, exact.abase_over_aground),
        ("a_roof", dda.aroof_over_aground, exact.aroof_over_aground),
    ] {
        let (d, e) = (d.unwrap(), e.unwrap());
        assert!(
            (d / e - 1.0).abs() < tolerance,
            "{label}, {what}: DDA {d}, exact {e}"
        );
    }
}
