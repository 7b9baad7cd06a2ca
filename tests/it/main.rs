//! catflip's integration tests, one binary: a module per capability, the
//! shared helpers in `util`. One binary links once, and its slow tests
//! (a robot design shared through a `OnceLock`, a robustness study) run
//! beside the quick ones instead of each file waiting for its slowest.
//!
//! Run one module with `cargo test --release --test it -- MODULE::`.

mod util;

mod any_start;
mod body;
mod browser;
mod cli;
mod configuration_doc;
mod control;
mod envelope;
mod export;
mod foundation;
mod free;
mod free_objectives;
mod fuzz;
mod import;
mod inputs;
mod least_height;
mod momentum;
mod phased;
mod recovery;
mod reliability;
mod replan;
mod replanning;
mod report;
mod rigid;
mod size;
mod sweep;
mod torque_speed;
mod verdict;
