//! Discontinuous Deformation Analysis: the solver.
//!
//! Each block has six unknowns at its centroid (translation, rotation, three strains).
//! A step assembles inertia (through the time integrator), block elasticity, joints and
//! the contact penalty springs into one symmetric positive definite system, solves it,
//! re-judges every contact (open / locked / sliding) and repeats until no state changes
//! (the open-close iteration), cutting Δt when it does not settle. See
//! `dda-theory.md` for the equations.

pub mod assembly;
pub mod block;
pub mod contact;
pub mod energy;
pub mod integrator;
pub mod joints;
pub mod judge;
pub mod linear;
pub mod mat6;
pub mod memory;
pub mod params;
pub mod rayleigh;
pub mod solver;
pub mod surface;

pub use crate::model::friction::FrictionLaw;
pub use energy::EnergyTerms;
pub use params::{ContactEnforcement, Integrator, SolverParams};
pub use rayleigh::RayleighDamping;
pub use solver::{CutReasons, Dda, Modes, RunCounters, StepReport};
