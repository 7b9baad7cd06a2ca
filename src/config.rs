//! Checked configuration: TOML in, validated [`Config`] out.
//!
//! Unknown keys are rejected (serde `deny_unknown_fields`); every number is
//! range-checked with a message that names the key, the value and the range.
//! `--set a.b=value` overrides are applied to the TOML tree before parsing, so
//! they go through the same checks.

use crate::design::spec::{
    AnalyticSettings, DesignSpec, Fall, FreeSettings, PhasedSettings, SimulateSettings,
};
use crate::error::{Error, Result, ValueKind, check};
use crate::model::{Cat, Half, InertiaFormula, Joint, TorqueNorm};
use serde::{Deserialize, Serialize};
use std::path::Path;

mod control;
pub mod ranges;
mod start;
pub use control::{ControlConfig, MAX_TRIALS, RobustnessConfig};
pub use start::{LandConfig, MAX_START_RATE, StartConfig};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Names the output folder `output/<name>/`.
    pub name: String,
    pub cat: CatConfig,
    pub fall: Fall,
    #[serde(default)]
    pub analytic: AnalyticSettings,
    #[serde(default)]
    pub limits: LimitsConfig,
    #[serde(default)]
    pub design: DesignConfig,
    #[serde(default)]
    pub simulate: SimulateSettings,
    #[serde(default)]
    pub phased: PhasedSettings,
    #[serde(default)]
    pub free: FreeSettings,
    /// `[body]`: general rigid halves, given or read from a URDF / MJCF
    /// (default: none, the cylinders of `[cat]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<crate::import::BodyConfig>,
    #[serde(default)]
    pub start: StartConfig,
    #[serde(default)]
    pub land: LandConfig,
    #[serde(default)]
    pub control: ControlConfig,
    #[serde(default)]
    pub robustness: RobustnessConfig,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CatConfig {
    /// kg, each half.
    pub mass: f64,
    /// m, each half.
    pub length: f64,
    /// m.
    pub radius: f64,
    /// `no-twist` (default) or `universal`.
    #[serde(default = "default_joint")]
    pub joint: Joint,
    /// `[cat.front]`: the front half where it differs from the rear (default: none,
    /// both halves as above).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub front: Option<FrontConfig>,
}

/// Front-half overrides; a missing key keeps the `[cat]` value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct FrontConfig {
    /// kg.
    pub mass: Option<f64>,
    /// m.
    pub length: Option<f64>,
    /// m.
    pub radius: Option<f64>,
}

fn default_joint() -> Joint {
    Joint::NoTwist
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct DesignConfig {
    /// What the optimisers minimise: `peak-torque` (default), `time` (the
    /// shortest manoeuvre inside the motor envelope, hence the least drop
    /// height) or `energy` (`integral |tau|^2 dt` inside the envelope).
    pub objective: crate::design::objective::Objective,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsConfig {
    /// N m, largest joint torque the motors can give (default: none).
    pub max_torque: Option<f64>,
    /// Degrees, largest bend the optimisers may use (default: none: the free-form design is then unbounded, while the phased design's bend search stops at `phased.bend_max_deg`, 175 at most).
    pub max_bend_deg: Option<f64>,
    /// Peak norm: `euclidean` or `per-motor` (default: euclidean for no-twist, per-motor for universal).
    pub norm: Option<TorqueNorm>,
    /// rad/s, no-load speed of the motors' linear torque-speed line (default: none).
    /// With `max_torque = T` and `k = T / no_load_speed` the motor gives
    /// `-T - k w <= tau <= T - k w` at joint speed `w` (docs/model.md, "Motors").
    pub no_load_speed: Option<f64>,
    /// rad/s, hard joint speed limit (default: none).
    pub max_speed: Option<f64>,
}

/// The parser's words for a value of the wrong type, the user's (TOML)
/// words for them, and the kind of value the key takes.
const TYPE_WORDS: &[(&str, &str, ValueKind)] = &[
    ("expected f64", "expected a number", ValueKind::Number),
    (
        "expected usize",
        "expected a whole number (0 or more)",
        ValueKind::Number,
    ),
    (
        "expected u64",
        "expected a whole number (0 or more)",
        ValueKind::Number,
    ),
    (
        "expected u32",
        "expected a whole number (0 or more)",
        ValueKind::Number,
    ),
    ("expected i64", "expected a whole number", ValueKind::Number),
    (
        "invalid type: unit variant, expected string only",
        "expected a name (a word such as `universal`), not a number, true/false or a list",
        ValueKind::Name,
    ),
    (
        "expected a string",
        "expected a name (text)",
        ValueKind::Name,
    ),
    (
        "expected a sequence",
        "expected a list such as [0.25, 0.5, 0.25]",
        ValueKind::List,
    ),
    (
        "expected an array of length 3",
        "expected a list of 3 numbers such as [0, 0, 0.5]",
        ValueKind::List,
    ),
    (
        "expected fewer elements in array",
        "expected a list of 3 numbers such as [0, 0, 0.5]",
        ValueKind::List,
    ),
    (
        "expected a boolean",
        "expected true or false",
        ValueKind::Switch,
    ),
];

/// The keys a config must give (every other has a default), by the field
/// name the parser's "missing field `height`" gives without its table.
const REQUIRED: [(&str, &str); 5] = [
    ("name", "name"),
    ("mass", "cat.mass"),
    ("length", "cat.length"),
    ("radius", "cat.radius"),
    ("height", "fall.height"),
];

/// The sections a config must give, by the parser's field name, and what
/// to add.
const REQUIRED_SECTIONS: [(&str, &str); 2] = [
    (
        "fall",
        "missing section `[fall]` (required): add it with `height`, the drop height in m",
    ),
    (
        "cat",
        "missing section `[cat]` (required unless `[body]` gives the halves): add it with `mass` (kg), `length` and `radius` (m), each half's",
    ),
];

/// The parser's messages name Rust's types ("expected f64") and a missing
/// field without its table; the user wrote TOML keys.
fn plain_types(message: &str) -> String {
    let mut m = TYPE_WORDS
        .iter()
        .fold(message.to_string(), |m, (rust, toml, _)| {
            m.replace(rust, toml)
        });
    // a section given a value: "expected struct CatConfig" names Rust's type
    if let Some(at) = m.find("expected struct ") {
        let end = m[at + 16..]
            .find(|c: char| !c.is_alphanumeric())
            .map_or(m.len(), |e| at + 16 + e);
        m.replace_range(at..end, "expected a table (a [section] of keys)");
    }
    let m = REQUIRED.iter().fold(m, |m, (field, key)| {
        m.replace(
            &format!("missing field `{field}`"),
            &format!("missing key `{key}` (required)"),
        )
    });
    REQUIRED_SECTIONS.iter().fold(m, |m, (field, what)| {
        m.replace(&format!("missing field `{field}`"), what)
    })
}

/// The kind of value the parser expected when a value's type was wrong
/// (read from its message, before [`plain_types`] rewords it).
fn expected_kind(message: &str) -> Option<ValueKind> {
    TYPE_WORDS
        .iter()
        .find(|(rust, _, _)| message.contains(rust))
        .map(|&(_, _, kind)| kind)
}

/// The longest `name`: the output folder's, with room for the set's
/// overrides in its own name (file systems stop at 255 bytes).
const MAX_NAME_LEN: usize = 100;

impl Config {
    /// Reads, overrides and validates a config file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Config> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::ConfigRead {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_toml_at(&text, &path.display().to_string(), overrides, base)
    }

    /// Parses the user's text, applies `--set` overrides and validates. An
    /// error in the file points at the file's own line; an error in an
    /// override names that `--set` argument.
    pub fn from_toml(text: &str, origin: &str, overrides: &[String]) -> Result<Config> {
        Self::from_toml_at(text, origin, overrides, Path::new("."))
    }

    /// [`Config::from_toml`] with `[body]`'s files relative to the folder `base`.
    pub fn from_toml_at(
        text: &str,
        origin: &str,
        overrides: &[String],
        base: &Path,
    ) -> Result<Config> {
        let file_err = |e: toml::de::Error| Error::ConfigParse {
            origin: origin.into(),
            // a missing key has no line: the parser would point at the file's first
            message: if e.message().starts_with("missing field") {
                plain_types(e.message().trim())
            } else {
                plain_types(&e.to_string())
            },
        };
        let mut table: toml::Table = toml::from_str(text).map_err(file_err)?;
        // the file alone, parsed from its own text: unknown keys and wrong
        // types carry the file's line; a missing key may come from an override
        // ([body] fills in [cat])
        if let Err(e) = toml::from_str::<Config>(text)
            && ((overrides.is_empty() && !table.contains_key("body"))
                || !e.message().starts_with("missing field"))
        {
            return Err(file_err(e));
        }
        // each override alone on a complete config, so that its error names it
        let template = toml::Table::try_from(Config::template()).expect("the template serialises");
        for arg in overrides {
            let mut t = template.clone();
            apply_override(&mut t, arg)?;
            if let Err(e) = t.try_into::<Config>() {
                let expects = expected_kind(e.message());
                return Err(Error::Override {
                    arg: arg.clone(),
                    message: plain_types(e.message().trim()) + &with_unit(arg, expects),
                    expects,
                });
            }
            apply_override(&mut table, arg)?;
        }
        let resolved = crate::import::resolve(&mut table, base, origin)?;
        // together: what is left is a key that neither gives
        let mut cfg: Config =
            table
                .try_into()
                .map_err(|e: toml::de::Error| Error::ConfigParse {
                    origin: if overrides.is_empty() {
                        origin.to_string()
                    } else {
                        format!("{origin} (with --set overrides)")
                    },
                    message: plain_types(e.message().trim()),
                })?;
        if let Some(b) = cfg.body.as_mut()
            && let Some((halves, from_file)) = resolved
        {
            b.halves = Some(halves);
            b.file_limits = from_file;
        }
        cfg.validate().map_err(|e| match e {
            // the user typed [body] keys or a file, not these
            Error::Invalid {
                key,
                value,
                expected,
            } if cfg.body.is_some() && key.starts_with("cat.") => Error::Invalid {
                expected: format!(
                    "{expected} (with [body], `{key}` is a half's equivalent cylinder, computed from body.rear / body.front or the robot file: change those{})",
                    if key == "cat.length" {
                        "; it is twice the halves' mean reach from centre of mass to joint, |body.rear.joint - body.rear.com| and |body.front.joint - body.front.com|, in metres"
                    } else {
                        ""
                    }
                ),
                key,
                value,
            },
            e => e,
        })?;
        Ok(cfg)
    }

    /// A complete valid config (the seed's cat), the base on which each
    /// `--set` is checked alone.
    fn template() -> Config {
        // parsed rather than built, so that sections added later come with their defaults
        toml::from_str(
            "name = \"template\"\n[cat]\nmass = 1.0\nlength = 1.0\nradius = 0.1\n[fall]\nheight = 10.0\n",
        )
        .expect("the template config parses")
    }

    pub fn validate(&self) -> Result<()> {
        if self.name.is_empty()
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.')
            || self.name.starts_with('.')
            || self.name.len() > MAX_NAME_LEN
        {
            return Err(Error::Invalid {
                key: "name".into(),
                value: format!("{:?}", self.name),
                expected: format!(
                    "a non-empty folder name of letters, digits, '-', '_' or '.', not starting with '.' (catflip keeps its sets in hidden folders), at most {MAX_NAME_LEN} characters"
                ),
            });
        }
        ranges::check_documented(self)?;
        let c = &self.cat;
        check(
            "cat.mass",
            c.mass,
            c.mass > 0.0,
            "must be > 0 kg (mass of each half)",
        )?;
        check(
            "cat.length",
            c.length,
            c.length > 0.0,
            "must be > 0 m (length of each half)",
        )?;
        check(
            "cat.radius",
            c.radius,
            c.radius > 0.0 && c.radius < c.length,
            "must be > 0 m and less than cat.length",
        )?;
        if let Some(fr) = &c.front {
            let front = self.cat().front;
            check(
                "cat.front.mass",
                front.mass,
                fr.mass.is_none_or(|m| m > 0.0),
                "must be > 0 kg (mass of the front half)",
            )?;
            check(
                "cat.front.length",
                front.length,
                fr.length.is_none_or(|l| l > 0.0),
                "must be > 0 m (length of the front half)",
            )?;
            check(
                "cat.front.radius",
                front.radius,
                front.radius > 0.0 && front.radius < front.length,
                "must be > 0 m and less than the front half's length",
            )?;
        }
        let f = &self.fall;
        check("fall.height", f.height, f.height > 0.0, "must be > 0 m")?;
        check(
            "fall.gravity",
            f.gravity,
            f.gravity > 0.0,
            "must be > 0 m/s^2",
        )?;
        ranges::check_fall_time(self)?;
        check("fall.margin", f.margin, f.margin >= 0.0, "must be >= 0 s")?;
        let ft = self.fall_time();
        check(
            "fall.margin",
            f.margin,
            f.margin < 0.95 * ft,
            &format!(
                "the landing margin must be under 95 % of the fall time ({ft:.4} s from this height), to leave time to move: lower fall.margin or raise the height"
            ),
        )?;
        self.analytic.validate()?;
        if let Some(t) = self.limits.max_torque {
            check("limits.max_torque", t, t > 0.0, "must be > 0 N m")?;
        }
        if let Some(w) = self.limits.no_load_speed {
            check(
                "limits.no_load_speed",
                w,
                w > 0.0,
                "must be > 0 rad/s (the speed at which the motor's torque falls to 0)",
            )?;
            if self.limits.max_torque.is_none() {
                // a robot file's joints may carry effort="0" or no <limit>:
                // read as no torque limit, which is why none is known
                let file = self.body.as_ref().and_then(|b| {
                    b.urdf
                        .as_ref()
                        .map(|_| "body.urdf")
                        .or(b.mjcf.as_ref().map(|_| "body.mjcf"))
                });
                return Err(Error::Invalid {
                    key: "limits.no_load_speed".into(),
                    value: format!("{w}"),
                    expected: format!(
                        "needs limits.max_torque too: the torque-speed line runs from max_torque at rest to 0 at no_load_speed{}",
                        file.map(|f| format!(" ({f} gives no torque limit: its joints' effort is 0 or missing, which catflip reads as none; set limits.max_torque to the motors' stall torque)")).unwrap_or_default()
                    ),
                });
            }
        }
        if let Some(w) = self.limits.max_speed {
            check("limits.max_speed", w, w > 0.0, "must be > 0 rad/s")?;
        }
        if let Some(b) = self.limits.max_bend_deg {
            check(
                "limits.max_bend_deg",
                b,
                b > 0.0 && b < 180.0,
                "must be in (0, 180) degrees",
            )?;
            // every command designs the phased schedule or seeds from it
            let from_file = if self.body.as_ref().is_some_and(|b| b.urdf.is_some()) {
                " (with [body], it comes from body.urdf's joint ranges unless the config sets it)"
            } else {
                ""
            };
            // a few "degrees" is most likely radians: asked before the advice
            // to lower the other key, which would keep the slip
            let radians = if b <= std::f64::consts::PI {
                format!(
                    "; if {b} is in radians, it is {:.2} deg: the key is in degrees",
                    b.to_degrees()
                )
            } else {
                String::new()
            };
            check(
                "limits.max_bend_deg",
                b,
                b > self.phased.bend_min_deg,
                &format!(
                    "must exceed phased.bend_min_deg = {} deg, the phased design's least bend{radians}; for a tighter limit, lower that key too{from_file}",
                    self.phased.bend_min_deg
                ),
            )?;
        }
        self.simulate.validate()?;
        self.phased.validate()?;
        self.free.validate()?;
        self.start.validate()?;
        self.land.validate()?;
        self.control.validate()?;
        self.robustness.validate()?;
        // a design without a limit has no least time: refused before any work
        self.design
            .objective
            .check_bounded(self.motor().is_limited())?;
        self.control
            .check_delay("robustness.delay_ms", self.robustness.delay_ms)?;
        ranges::check_derived(self)?;
        ranges::impossible(self)
    }

    /// Plausibility warnings (likely unit slips) for a valid config; see
    /// [`ranges::slips`].
    pub fn slips(&self) -> Vec<ranges::Slip> {
        ranges::slips(self)
    }

    /// The cat with the inertia formula the config asks for.
    pub fn cat(&self) -> Cat {
        let c = &self.cat;
        let rear = Half {
            mass: c.mass,
            length: c.length,
            radius: c.radius,
            inertia: if self.analytic.seed_inertia {
                InertiaFormula::Seed
            } else {
                InertiaFormula::SolidCylinder
            },
        };
        let fr = c.front.clone().unwrap_or_default();
        let front = Half {
            mass: fr.mass.unwrap_or(c.mass),
            length: fr.length.unwrap_or(c.length),
            radius: fr.radius.unwrap_or(c.radius),
            ..rear
        };
        Cat {
            rear,
            front,
            joint: c.joint,
            general: self.body.as_ref().and_then(|b| b.halves),
        }
    }

    /// `sqrt(2 h / g)`, s (see [`Fall::fall_time`]).
    pub fn fall_time(&self) -> f64 {
        self.fall.fall_time()
    }

    /// Time for the manoeuvre: fall time minus margin, s.
    pub fn available_time(&self) -> f64 {
        self.fall.available_time()
    }

    pub fn norm(&self) -> TorqueNorm {
        self.limits
            .norm
            .unwrap_or(TorqueNorm::default_for(self.cat.joint))
    }

    /// Whether the design needs the motor-envelope program (see
    /// [`DesignSpec::uses_envelope`]).
    pub fn uses_envelope(&self) -> bool {
        self.design.objective != crate::design::objective::Objective::PeakTorque
            || self.limits.max_speed.is_some()
            || self.limits.no_load_speed.is_some()
    }

    /// What the design code takes: the body, motors, fall, start, objective
    /// and the optimisers' settings.
    pub fn design_spec(&self) -> DesignSpec {
        DesignSpec {
            cat: self.cat(),
            motor: self.motor(),
            fall: self.fall,
            start: (!self.start.is_default()).then(|| self.start.start()),
            objective: self.design.objective,
            max_bend_deg: self.limits.max_bend_deg,
            max_tilt_deg: self.land.max_tilt_deg,
            analytic: self.analytic.clone(),
            simulate: self.simulate.clone(),
            phased: self.phased.clone(),
            free: self.free.clone(),
            limits_from: self.limits_from(),
        }
    }

    /// Where the motor limits came from: the keys, or the robot file that
    /// gave some of them.
    pub fn limits_from(&self) -> crate::design::spec::LimitOrigin {
        match &self.body {
            Some(b) if !b.file_limits.is_empty() => crate::design::spec::LimitOrigin {
                file: Some(if b.urdf.is_some() {
                    "body.urdf"
                } else {
                    "body.mjcf"
                }),
                keys: b.file_limits.clone(),
            },
            _ => Default::default(),
        }
    }

    /// The joint's motors as the limits describe them.
    pub fn motor(&self) -> crate::model::motor::Motor {
        crate::model::motor::Motor {
            max_torque: self.limits.max_torque,
            no_load_speed: self.limits.no_load_speed,
            max_speed: self.limits.max_speed,
            norm: self.norm(),
        }
    }

    /// Largest bend the phased design may use (and the free-form design's
    /// mesh must resolve), rad: the limit, or 175 deg without one.
    pub fn max_bend(&self) -> f64 {
        self.limits.max_bend_deg.unwrap_or(175.0).to_radians()
    }
}

/// Applies `a.b.c=value` to a TOML table; `value` is read as TOML, else as a string.
pub fn apply_override(table: &mut toml::Table, arg: &str) -> Result<()> {
    let err = |m: &str| Error::Override {
        arg: arg.into(),
        message: m.into(),
        expects: None,
    };
    let (key, raw) = arg
        .split_once('=')
        .ok_or_else(|| err("expected KEY=VALUE, e.g. cat.joint=universal"))?;
    let key = key.trim();
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(err("the key has an empty part"));
    }
    let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        Ok(mut t) => t.remove("v").expect("parsed key"),
        // how Rust and Python print a NaN (TOML's is `nan`): the key's own
        // check then names it
        Err(_) if ["NaN", "+NaN", "-NaN"].contains(&raw.trim()) => toml::Value::Float(f64::NAN),
        Err(_) => toml::Value::String(raw.trim().to_string()),
    };
    let mut cur = table;
    for p in &parts[..parts.len() - 1] {
        let entry = cur
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cur = entry
            .as_table_mut()
            .ok_or_else(|| err(&format!("`{p}` is not a table")))?;
    }
    cur.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}

/// For a number given with its unit (`fall.height=1.5m`): the advice to give
/// the number alone, in the key's unit ([`UNITS`]); empty otherwise.
fn with_unit(arg: &str, expects: Option<crate::error::ValueKind>) -> String {
    let Some((key, raw)) = arg.split_once('=') else {
        return String::new();
    };
    let raw = raw.trim();
    let number = raw
        .find(|c: char| c.is_alphabetic())
        .filter(|&i| i > 0 && raw[..i].trim().parse::<f64>().is_ok());
    match (expects, number) {
        (Some(crate::error::ValueKind::Number), Some(i)) => {
            let (number, typed) = (raw[..i].trim(), raw[i..].trim());
            match UNITS.iter().find(|(k, _)| *k == key.trim()) {
                Some((_, unit)) if *unit == typed => format!(
                    "; give the number alone: `{}={number}` (the key is in {unit})",
                    key.trim()
                ),
                Some((_, unit)) => format!(
                    "; give the number alone, converted to the key's unit, {unit} (`{raw}` is not read)"
                ),
                None => format!("; give the number alone (`{raw}` is not read)"),
            }
        }
        _ => String::new(),
    }
}

/// Unit of each numeric config key, for axis labels (`fall.height (m)`).
pub const UNITS: [(&str, &str); 53] = [
    ("cat.mass", "kg"),
    ("cat.length", "m"),
    ("cat.radius", "m"),
    ("cat.front.mass", "kg"),
    ("cat.front.length", "m"),
    ("cat.front.radius", "m"),
    ("fall.height", "m"),
    ("fall.gravity", "m/s^2"),
    ("fall.margin", "s"),
    ("analytic.theta_deg", "deg"),
    ("limits.max_torque", "N m"),
    ("limits.max_bend_deg", "deg"),
    ("limits.no_load_speed", "rad/s"),
    ("limits.max_speed", "rad/s"),
    ("simulate.rtol", "relative"),
    ("simulate.atol", "absolute"),
    ("simulate.pd_bandwidth_hz", "Hz"),
    ("simulate.pd_damping", "damping ratio"),
    ("simulate.samples_per_phase", "rows per phase"),
    ("simulate.flip_tolerance", "rad"),
    ("phased.nodes", "intervals per phase"),
    ("phased.bend_min_deg", "deg"),
    ("phased.bend_max_deg", "deg"),
    ("phased.scan_points", "count"),
    ("phased.bend_tol_deg", "deg"),
    ("free.nodes", "nodes per phase"),
    ("free.max_iterations", "count"),
    ("free.tolerance", "relative"),
    ("free.attitude_tolerance", "rad"),
    ("land.max_tilt_deg", "deg"),
    ("control.rate_hz", "Hz"),
    ("control.delay_ms", "ms"),
    ("control.sim_rate_hz", "Hz"),
    ("control.landing_weight", "weight"),
    ("control.final_shape_weight", "weight"),
    ("control.attitude_weight", "weight"),
    ("control.shape_weight", "weight"),
    ("control.rate_weight", "weight"),
    ("control.torque_weight", "weight"),
    ("control.max_correction", "design peak torques"),
    ("control.replan_nodes", "nodes per phase"),
    ("control.replan_iterations", "count"),
    ("control.replan_every", "control periods"),
    ("robustness.tilt_deg", "deg"),
    ("robustness.mass_error", "relative"),
    ("robustness.inertia_error", "relative"),
    ("robustness.length_error", "relative"),
    ("robustness.delay_ms", "ms"),
    ("robustness.torque_noise", "design peak torques"),
    ("robustness.attitude_noise_deg", "deg"),
    ("robustness.rate_noise_rad_s", "rad/s"),
    ("robustness.pd_gain_error", "relative"),
    ("robustness.worst_kept", "trials"),
];

/// A config key with its unit, e.g. `fall.height (m)`.
pub fn key_label(key: &str) -> String {
    match UNITS.iter().find(|(k, _)| *k == key) {
        Some((_, u)) => format!("{key} ({u})"),
        None => key.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEED: &str = r#"
name = "seed"
[cat]
mass = 1.0
length = 1.0
radius = 0.1
[fall]
height = 10.0
gravity = 9.8
"#;

    #[test]
    fn parses_and_overrides() {
        let c = Config::from_toml(
            SEED,
            "t",
            &["cat.joint=universal".into(), "analytic.theta_deg=60".into()],
        )
        .unwrap();
        assert_eq!(c.cat.joint, Joint::Universal);
        assert_eq!(c.analytic.theta_deg, 60.0);
        assert!((c.fall_time() - (20.0f64 / 9.8).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn messages_name_only_the_limits_the_config_sets() {
        let with = |ov: &[&str]| {
            let ov: Vec<String> = ov.iter().map(|s| s.to_string()).collect();
            Config::from_toml(SEED, "t", &ov)
                .unwrap()
                .design_spec()
                .envelope_keys()
        };
        assert_eq!(with(&[]), "");
        assert_eq!(with(&["limits.max_torque=1"]), "limits.max_torque");
        assert_eq!(
            with(&["limits.max_torque=1", "limits.no_load_speed=6"]),
            "limits.max_torque, limits.no_load_speed"
        );
        assert_eq!(with(&["limits.max_speed=3"]), "limits.max_speed");
    }

    #[test]
    fn a_missing_required_key_is_named_with_its_table() {
        let body = "name = \"b\"\n[body.rear]\nmass = 0.6\ncom = [0, 0, 0]\ninertia = [0.002, 0.002, 0.001, 0, 0, 0]\njoint = [0, 0, 0.09]\n[body.front]\nmass = 0.4\ncom = [0, 0, 0.07]\ninertia = [0.001, 0.001, 0.0005, 0, 0, 0]\njoint = [0, 0, 0]\n[fall]\nmargin = 0.1\n";
        let e = Config::from_toml(body, "t", &[]).unwrap_err().to_string();
        assert!(e.contains("missing key `fall.height`"), "{e}");
        assert!(!e.contains("missing field"), "{e}");
        let e = Config::from_toml(&SEED.replace("length = ", "# length = "), "t", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing key `cat.length`"), "{e}");
    }

    #[test]
    fn wrong_types_are_named_in_toml_words_not_rusts() {
        for (set, plain, kind) in [
            ("cat.mass=abc", "expected a number", ValueKind::Number),
            (
                "phased.nodes=10.5",
                "expected a whole number",
                ValueKind::Number,
            ),
            ("cat.joint=1", "expected a name", ValueKind::Name),
            ("cat.joint=true", "expected a name", ValueKind::Name),
            ("name=1", "expected a name", ValueKind::Name),
            ("analytic.split=1", "expected a list", ValueKind::List),
            (
                "start.angular_velocity=1",
                "expected a list of 3 numbers such as [0, 0, 0.5]",
                ValueKind::List,
            ),
            (
                "start.rotation_deg=[0, 0, 0, 1]",
                "invalid length 4, expected a list of 3 numbers",
                ValueKind::List,
            ),
            ("simulate.pd=1", "expected true or false", ValueKind::Switch),
        ] {
            let e = Config::from_toml(SEED, "t", &[set.into()]).unwrap_err();
            // the kind is typed, for callers such as the sweep
            assert!(
                matches!(e, Error::Override { expects: Some(k), .. } if k == kind),
                "{set}: {e:?}"
            );
            let e = e.to_string();
            assert!(e.contains(plain), "{set}: {e}");
            for rust in [
                "f64",
                "usize",
                "variant",
                "sequence",
                "expected a string",
                "array",
                "boolean",
            ] {
                assert!(!e.contains(rust), "{set}: {e}");
            }
        }
        let e = Config::from_toml(&SEED.replace("mass = 1.0", "mass = \"heavy\""), "t", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected a number") && !e.contains("f64"), "{e}");
    }

    #[test]
    fn rejects_each_kind_of_bad_input() {
        let cases: &[(&str, &[&str], &str)] = &[
            (SEED, &["cat.mass=-1"], "cat.mass"),
            (SEED, &["cat.masss=1"], "masss"),
            (SEED, &["cat.joint=hinge"], "hinge"),
            (SEED, &["analytic.split=[0.5, 0.6, 0.2]"], "analytic.split"),
            (SEED, &["fall.margin=5"], "fall.margin"),
            (SEED, &["cat.mass"], "KEY=VALUE"),
            ("name = \"x\"\n[cat]\nmass = 1", &[], "length"),
            ("name = \"x\" [", &[], "TOML"),
        ];
        for (text, ov, needle) in cases {
            let ov: Vec<String> = ov.iter().map(|s| s.to_string()).collect();
            let e = Config::from_toml(text, "t", &ov)
                .expect_err(needle)
                .to_string();
            assert!(e.contains(needle), "`{e}` should mention `{needle}`");
        }
    }

    /// Every numeric key of the config has a unit, and the table names no
    /// key the config lacks (sweep axes are labelled from it).
    #[test]
    fn every_numeric_key_has_a_unit() {
        let optional = [
            "limits.max_torque=1",
            "limits.max_bend_deg=90",
            "limits.no_load_speed=10",
            "limits.max_speed=20",
            "cat.front.mass=2",
            "cat.front.length=1",
            "cat.front.radius=0.1",
            "land.max_tilt_deg=5",
        ];
        let c = Config::from_toml(SEED, "t", &optional.map(String::from)).unwrap();
        fn walk(prefix: &str, t: &toml::Table, out: &mut Vec<String>) {
            for (k, x) in t {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                match x {
                    toml::Value::Table(inner) => walk(&key, inner, out),
                    x if x.is_integer() || x.is_float() => out.push(key),
                    _ => {}
                }
            }
        }
        let mut numeric = Vec::new();
        walk("", &toml::Table::try_from(&c).unwrap(), &mut numeric);
        for k in &numeric {
            assert_ne!(key_label(k), *k, "{k} has no unit in UNITS");
        }
        for (k, _) in UNITS {
            assert!(
                numeric.iter().any(|n| n == k),
                "UNITS names {k}, not a numeric key"
            );
        }
        assert_eq!(key_label("fall.height"), "fall.height (m)");
    }
}
