//! catflip: torque schedules that turn a falling two-body cat right side up.
//!
//! The physics contract is MODEL.md (shared with the project): two identical
//! cylinders joined at the middle, released at rest, zero angular momentum.
pub mod analytic;
pub mod analyze;
pub mod collocation;
pub mod config;
pub mod conic;
pub mod dynamics;
pub mod error;
pub mod export;
pub mod free;
pub mod model;
pub mod ode;
pub mod output;
pub mod path;
pub mod phased;
pub mod plan;
pub mod report;
pub mod run;
pub mod scp;
pub mod simulate;
pub mod small;
pub mod so3;
pub mod sweep;
pub mod timing;

pub use config::Config;
pub use error::{Error, Result};
