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
