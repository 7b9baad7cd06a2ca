//! Specs for the library's unit tests, from the bundled configs, so that the
//! design modules' tests need not import the config.

use crate::config::Config;
use crate::design::spec::DesignSpec;

/// The spec of the config file at `path` with `overrides` (`key=value`).
pub fn spec_at(path: &str, overrides: &[String]) -> DesignSpec {
    Config::load(std::path::Path::new(path), overrides)
        .unwrap()
        .design_spec()
}

/// The spec of a config given as TOML text.
pub fn spec_of(text: &str, origin: &str, overrides: &[String]) -> DesignSpec {
    Config::from_toml(text, origin, overrides)
        .unwrap()
        .design_spec()
}

/// The records of a CSV text by RFC 4180 (fields in double quotes may hold
/// commas, line breaks and doubled quotes): what a spreadsheet or Python's
/// `csv` module reads from catflip's files.
pub fn csv_records(text: &str) -> Vec<Vec<String>> {
    let (mut records, mut record, mut field) = (Vec::new(), Vec::new(), String::new());
    let (mut quoted, mut chars) = (false, text.chars().peekable());
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') if field.is_empty() => quoted = true,
            (false, ',') => record.push(std::mem::take(&mut field)),
            (false, '\n') => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
            }
            (false, c) => field.push(c),
        }
    }
    if !field.is_empty() || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    records
}
