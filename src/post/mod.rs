//! Post-processing: recorded time histories, spectra, the sweep table, figures, and the
//! all-or-nothing output folders they are written to.

pub mod history;
pub mod output;
pub mod plot;
pub mod spectrum;
pub mod sweep;
