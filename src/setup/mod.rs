//! One way to set up a run, shared by the command line, the visualizer and the studies.
//!
//! A [`RunSpec`] says what to run: the scene, the excitation, the model and the
//! parameters, each `None` meaning "the scene's own value or the default" (the defaults
//! are in [`defaults`], nowhere else). [`RunSpec::prepare`] checks the specification
//! against its scene and turns it into a [`RunSetup`]: the scene with the parameters
//! applied, the ground motion, the duration, the blocks the responses are measured on and
//! the warnings. The responses themselves (slip, drift, base and roof acceleration) are
//! defined once, in [`response`].

mod check;
pub mod defaults;
pub mod modes;
mod prepare;
mod progress;
pub mod response;
mod spec;

pub use check::{check_steps, exact_steps_for};
pub use prepare::{RunSetup, SceneRoles};
pub use progress::{ProgressReporter, RemainingTime, RunProgress};
pub use response::{Probe, Response};
pub use spec::{
    ExcitationSpec, Frequency, HistoryPlan, ModelKind, RunSpec, SceneSource, VerticalSpec,
};
