//! # slidebase
//!
//! How a building on a sliding (friction) base responds to earthquakes, computed with
//! Discontinuous Deformation Analysis (DDA) and checked against the exact solution of the
//! classic mass-spring sliding model.
//!
//! The crate is laid out as a picture of its architecture:
//!
//! - [`ground_motion`]: harmonic input and recorded accelerograms (AT2/CSV readers).
//! - `model`: scenes as data: blocks, materials, contacts, joints, supports, excitation.
//! - `dda`: the solver: block matrices, contacts with Coulomb friction and the open-close
//!   iteration, bolts and connection elements, integrators, energy bookkeeping.
//! - `analytic`: the paper's mass-spring models, solved exactly (event-driven).
//! - `post`: time histories, metrics, spectra and plots.
//! - [`setup`]: the one way a run is specified, validated and set up (command line,
//!   visualizer and studies alike).
//!
//! The engine never depends on rendering; the visualizer lives behind the `gui` feature.

pub mod analytic;
#[cfg(feature = "gui")]
pub mod app;
pub mod dda;
pub mod error;
#[cfg(feature = "gui")]
pub mod export;
pub mod ground_motion;
pub mod headless;
pub mod limits;
pub mod linalg;
pub mod model;
pub mod post;
#[cfg(feature = "gui")]
pub mod render;
pub mod setup;
pub mod sim;
pub mod testing;
#[cfg(feature = "gui")]
pub mod ui;

pub use error::{Error, Result};
