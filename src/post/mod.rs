//! Post-processing: recorded time histories, spectra, the sweep table and figures.

pub mod history;
pub mod plot;
pub mod spectrum;
pub mod sweep;
