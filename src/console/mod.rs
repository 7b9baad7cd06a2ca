//! What the terminal shows: each command's result table and the progress
//! lines of long stages. The functions return the lines; the binary prints
//! them (and stops printing when stdout is a closed pipe), so the text is
//! the library's and the same wherever it is shown.

pub mod design;
pub mod progress;
pub mod robustness;
pub mod run;
pub mod sweep;
pub mod table;

pub use table::{Columns, Rows};

/// `n` and the noun, plural unless `n` is one ("1 trial", "20 trials").
pub fn count(n: usize, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}
