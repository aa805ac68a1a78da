//! Lecture presets: a few set-ups that each make one point, chosen from the top bar.

use super::{Comparison, Controls, RecordChoice, SceneChoice};

/// One lecture preset.
#[derive(Debug, Clone)]
pub struct Preset {
    /// Name in the menu.
    pub name: &'static str,
    /// What it shows, in a sentence (the tooltip).
    pub point: &'static str,
    /// The controls it sets.
    pub controls: Controls,
}

/// The presets, in lecture order.
pub fn presets() -> Vec<Preset> {
    let el_centro = Controls::default();
    vec![
        Preset {
            name: "El Centro: sliding base (ρ = 0.01) against fixed base",
            point: "the paper's three-storey frame under El Centro 1940: the base that slides \
                    passes a fraction of the acceleration up; the fixed one sways",
            controls: el_centro.clone(),
        },
        Preset {
            name: "What friction does: ρ = 0.01 / 0.05 / 0.2",
            point: "the same frame with three friction coefficients: more friction, less slip \
                    but more acceleration in the building",
            controls: Controls {
                comparison: Comparison::Friction(vec![0.05, 0.2]),
                ..el_centro.clone()
            },
        },
        Preset {
            name: "Friction pendulum against flat slider: recentring",
            point: "the frame on two friction-pendulum bearings (R = 2 m) beside the same frame \
                    on the flat joint, ρ = 0.01, El Centro: both slide about 20 cm, but the flat \
                    one stays 15 cm off while gravity in the dishes brings the other back to \
                    the middle (at the price of more sway: the dishes push back)",
            controls: Controls {
                bearing_radius: Some(2.0),
                comparison: Comparison::FlatJoint,
                ..el_centro.clone()
            },
        },
        Preset {
            name: "Resonance: harmonic ground motion at Ω/ω = 1",
            point: "the two-mass model shaken at its own frequency: the fixed base grows without \
                    bound, the sliding base caps the force at ρ × weight",
            controls: Controls {
                scene: SceneChoice::TwoBlock,
                record: RecordChoice::Harmonic,
                amplitude_g: 0.3,
                frequency: 1.0,
                friction: 0.1,
                alpha: 0.5,
                comparison: Comparison::FixedBase,
                ..el_centro.clone()
            },
        },
        Preset {
            name: "The paper's two-mass model with its exact solution",
            point: "DDA against the exact solution of the mass-spring model (dashed in the \
                    plots): α = 0.5, ρ = 0.1, Ω/ω = 2",
            controls: Controls {
                scene: SceneChoice::TwoBlock,
                record: RecordChoice::Harmonic,
                amplitude_g: 0.3,
                frequency: 2.0,
                friction: 0.1,
                alpha: 0.5,
                comparison: Comparison::None,
                ..el_centro
            },
        },
    ]
}
