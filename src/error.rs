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
    /// A `--set` that does not fit the config; `expects` is the kind of
    /// value the key takes when the value's type was wrong.
    /// A key a command needs that the config does not set.
    #[error("config key `{key}` is not set: {why}")]
    Missing { key: String, why: String },
    #[error("`--set {arg}`: {message}")]
    Override {
        arg: String,
        message: String,
        expects: Option<ValueKind>,
    },
    #[error("`--set-range {arg}`: {message}")]
    Range { arg: String, message: String },
    /// A bad command-line argument other than `--set` and `--set-range`.
    #[error("{0}")]
    Usage(String),
    #[error("schedule {file}, line {line}: {message}")]
    Schedule {
        file: String,
        line: usize,
        message: String,
    },
    /// A robot description (`body.urdf`, `body.mjcf`) catflip cannot read or model.
    #[error("{file}, line {line}, {element}: {message}")]
    Import {
        file: String,
        line: usize,
        element: String,
        message: String,
    },
    #[error("{what}: the solver stopped with status {status}. {hint}")]
    Solver {
        what: String,
        status: String,
        hint: String,
    },
    #[error("not possible as configured: {reason}")]
    Unreachable { reason: String },
    /// The motors cannot do it in the configured fall (exit status 4): the
    /// reason names the drop height, or the motor, that would do.
    #[error("not possible with these motors in this fall: {reason}")]
    BeyondMotors { reason: String },
    /// A design that found no schedule inside the motor limits in a fall the
    /// least-height answer says the motors can do (its own design does it):
    /// this design's failure, not the motors' (exit status 1, not 4).
    #[error(
        "the {what} design, started from the least-height design, found no schedule inside the motor limits in the fall from {height_m} m, {:.1} % above the least drop height found ({least_height_m:.3} m): the flip is possible, the least-height schedule does it ({where_}); a higher fall.height leaves this design more room",
        100.0 * (height_m / least_height_m - 1.0)
    )]
    ShortOfAnswer {
        what: String,
        height_m: f64,
        least_height_m: f64,
        /// Where the caller's user finds that schedule.
        where_: String,
    },
    /// The phased seed of a free-form design is impossible where the
    /// free-form design may not be.
    #[error(
        "the phased seed does not fit: {reason}; the free-form design may still fit: `--seed analytic` starts it without the phased design, and `catflip run` finds the least drop height"
    )]
    SeedUnfit { reason: String },
    #[error("every method failed: {0}")]
    AllFailed(String),
    #[error("simulation failed: {0}")]
    Simulation(String),
    /// A result that would be published with a NaN or infinite number (null
    /// in JSON): refused rather than reported as a success.
    #[error("the computation gave no finite number for {fields}; nothing was written")]
    NonFinite { fields: String },
    #[error("drawing a figure failed: {0}")]
    Report(String),
    /// The output folder cannot take the results (checked before computing).
    #[error("cannot write to {path}: {message}; choose another --out")]
    OutputDir { path: PathBuf, message: String },
    #[error("cannot write {path}: {message}")]
    Write { path: PathBuf, message: String },
}

impl Error {
    /// Whether the motors cannot do it in the configured fall: the answer
    /// to the robot question, not a failure (exit status 4).
    pub fn is_beyond_motors(&self) -> bool {
        matches!(self, Error::BeyondMotors { .. })
    }

    /// True when the user's input is at fault (config, arguments, files given,
    /// output folder) rather than a computation: the CLI exits with 2.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            Error::ConfigRead { .. }
                | Error::ConfigParse { .. }
                | Error::Invalid { .. }
                | Error::Missing { .. }
                | Error::Override { .. }
                | Error::Range { .. }
                | Error::Usage(_)
                | Error::Schedule { .. }
                | Error::Import { .. }
                | Error::OutputDir { .. }
        )
    }
}

pub type Result<T> = std::result::Result<T, Error>;

/// The kind of value a config key takes, as far as a wrong value tells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ValueKind {
    /// A number (or a whole number).
    Number,
    /// A name, such as `universal`.
    Name,
    /// A list, such as `[0.25, 0.5, 0.25]`.
    List,
    /// `true` or `false`.
    Switch,
}

impl ValueKind {
    /// The kind in words, with an article: "a name".
    pub fn words(self) -> &'static str {
        match self {
            ValueKind::Number => "a number",
            ValueKind::Name => "a name",
            ValueKind::List => "a list",
            ValueKind::Switch => "true or false",
        }
    }
}

/// A number as the user would read it: `1e308`, not 309 digits.
pub fn show(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `Ok` when `ok` holds and `value` is finite, else the [`Error::Invalid`]
/// that names `key`, the value and what was `expected`.
pub fn check(key: &str, value: f64, ok: bool, expected: &str) -> Result<()> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(Error::Invalid {
            key: key.into(),
            value: show(value),
            expected: expected.into(),
        })
    }
}
