//! catflip: torque schedules that turn a falling two-body cat right side up.
//!
//! The pipeline, one folder a stage (the physics is in `docs/model.md`):
//! - [`model`]: the two-cylinder cat, its zero-momentum shape dynamics and attitude maths;
//! - [`design`]: the analytic, phased and free-form torque schedules;
//! - [`verify`]: forward simulation of a schedule in the full model;
//! - [`report`] and [`export`]: figures and HTML, simulator models and controls.
//!
//! [`run`] and [`sweep`] drive the whole pipeline; [`config`] checks the input
//! and [`output`] writes a command's files all together or not at all;
//! [`table`] and [`console`] word the results for the report and the terminal.
// the docs are the developers' map: a module's doc names the private
// helpers that do its steps (`cargo doc --document-private-items` links them)
#![allow(rustdoc::private_intra_doc_links)]
pub mod config;
pub mod console;
pub mod control;
pub mod design;
pub mod error;
pub mod export;
pub mod import;
pub mod interrupt;
pub mod model;
pub mod output;
pub mod pipeline;
pub mod recovery;
pub mod report;
pub mod run;
pub mod size;
pub mod sweep;
pub mod table;
pub mod verdict;
pub mod verify;

#[cfg(test)]
mod test_support;

pub use config::Config;
pub use error::{Error, Result};
