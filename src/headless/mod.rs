//! Everything the program does without a window: single runs, sweeps, reports.
//!
//! These functions are what the command line calls; they return plain data and write files,
//! and never print (printing is the binary's job), so tests and other front ends can use them.

pub mod accuracy;
pub mod bench;
pub mod block;
pub mod frame;
pub mod friction_figure;
pub mod report;
pub mod run;
pub mod simulate;
pub mod stability;
pub mod sweep;
pub mod targets;
