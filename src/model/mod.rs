//! Scenes as data: geometry, materials, the scene description and the built-in presets.

pub mod bearing;
pub mod enforcement;
pub mod friction;
pub mod generated;
pub mod geometry;
pub mod integration;
pub mod material;
pub mod pendulum;
pub mod presets;
pub mod scene;
pub mod validate;

pub use scene::Scene;
