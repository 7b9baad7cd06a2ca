//! Library errors: each names the problem and what to change.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("cannot read config {path}: {message}")]
    ConfigRead { path: PathBuf, message: String },
    #[error("config {origin}: {message}")]
    ConfigParse { origin: String, message: String },
    #[error("config key `{key}` = {value} is invalid: {expected}")]
    Invalid {
        key: String,
        value: String,
        expected: String,
    },
    #[error("`--set {arg}`: {message}")]
    Override { arg: String, message: String },
    #[error("schedule {file}, line {line}: {message}")]
    Schedule {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{what}: the solver stopped with status {status}. {hint}")]
    Solver {
        what: String,
        status: String,
        hint: String,
    },
    #[error("the flip is impossible: {reason}")]
    Unreachable { reason: String },
    #[error("simulation failed: {0}")]
    Simulation(String),
    #[error("drawing a figure failed: {0}")]
    Report(String),
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

pub type Result<T> = std::result::Result<T, Error>;
