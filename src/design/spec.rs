//! What the design code takes: the body, its motors, the fall, the start, the
//! objective and each optimiser's settings. `Config::design_spec`
//! makes one from a checked configuration; the design, verification and
//! verdict code read nothing else, so a library user (or a binding) can build
//! one without a TOML file. Variants (another drop height, another objective)
//! are made by the `with_*` methods.
//!
//! The settings structs are also the config's sections (`[analytic]`,
//! `[simulate]`, `[phased]`, `[free]`): their defaults sit on them, and
//! `Config::validate` checks their ranges.

use crate::design::objective::Objective;
use crate::error::{Error, Result, check};
use crate::model::momentum::Start;
use crate::model::motor::Motor;
use crate::model::{Cat, TorqueNorm};
use serde::{Deserialize, Serialize};

/// The design problem.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSpec {
    /// The two halves and their joint.
    pub cat: Cat,
    /// The joint's motors (torque, torque-speed line, speed, peak norm).
    pub motor: Motor,
    pub fall: Fall,
    /// The release; `None`: upside down and at rest (today's problem).
    pub start: Option<Start>,
    pub objective: Objective,
    /// Largest bend the optimisers may use, deg; `None`: the free-form design
    /// is unbounded and the phased bend search stops at `phased.bend_max_deg` (175 at most).
    pub max_bend_deg: Option<f64>,
    /// Largest angle of the belly from straight down at touchdown, deg
    /// (`None`: the flip judged by `simulate.flip_tolerance`).
    pub max_tilt_deg: Option<f64>,
    pub analytic: AnalyticSettings,
    pub simulate: SimulateSettings,
    pub phased: PhasedSettings,
    pub free: FreeSettings,
    /// Where the motor limits came from, so that a message names them as
    /// the user gave them.
    pub limits_from: LimitOrigin,
}

/// Where the motor limits came from: the `[limits]` keys, or a robot file
/// that gave some of them (their values were never typed in the config, so a
/// message naming only the key would send the user to a key they never set).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LimitOrigin {
    /// `body.urdf` or `body.mjcf`, when the file gave a limit.
    pub file: Option<&'static str>,
    /// The `[limits]` keys the file gave (`max_torque`, ...).
    pub keys: Vec<&'static str>,
}

impl LimitOrigin {
    /// How a message names the limit `key` (`limits.max_speed`, or bare
    /// `max_speed`): the key, or the file's attribute it was read from and
    /// the key that replaces it.
    pub fn name(&self, key: &str) -> String {
        let bare = key.strip_prefix("limits.").unwrap_or(key);
        let key = format!("limits.{bare}");
        let Some(file) = self.file.filter(|_| self.keys.contains(&bare)) else {
            return key;
        };
        let what = match (file, bare) {
            ("body.mjcf", _) => "its actuators' ctrlrange or forcerange",
            (_, "max_torque") => "its joints' effort",
            (_, "max_speed") => "its joints' velocity",
            (_, "max_bend_deg") => "its joints' lower and upper limits",
            _ => "its joints' limits",
        };
        format!("{file} ({what}, read as {key})")
    }
}

/// The drop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fall {
    /// m, drop height.
    pub height: f64,
    /// m/s^2 (default 9.81).
    #[serde(default = "default_gravity")]
    pub gravity: f64,
    /// s left free before landing (default 0).
    #[serde(default)]
    pub margin: f64,
}

fn default_gravity() -> f64 {
    9.81
}

impl Fall {
    /// `sqrt(2 h / g)`, s. A height near `f64::MAX` makes it infinite, which
    /// the config's fall-time range check refuses (kept in this form: the
    /// designs of the bundled configs depend on its last bit).
    pub fn fall_time(&self) -> f64 {
        (2.0 * self.height / self.gravity).sqrt()
    }

    /// Time for the manoeuvre: fall time minus margin, s.
    pub fn available_time(&self) -> f64 {
        self.fall_time() - self.margin
    }
}

/// `[analytic]`: the seed's closed-form schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AnalyticSettings {
    /// Angle between the halves during the twist, degrees (default 45, the seed's pi/4).
    pub theta_deg: f64,
    /// Fractions of the manoeuvre time for fold, twist, unfold (default 0.2, 0.6, 0.2).
    #[serde(deserialize_with = "three_fractions")]
    pub split: [f64; 3],
    /// Use the seed's transverse inertia `m (r^2 + l^2)/12` (erratum E1) to reproduce
    /// its printed example (default false).
    pub seed_inertia: bool,
}

/// `analytic.split`: exactly three numbers, no more, no fewer.
fn three_fractions<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> std::result::Result<[f64; 3], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    <[f64; 3]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::custom(format!(
            "analytic.split needs exactly 3 fractions (fold, twist, unfold), got {}",
            v.len()
        ))
    })
}

impl Default for AnalyticSettings {
    fn default() -> Self {
        Self {
            theta_deg: 45.0,
            split: [0.2, 0.6, 0.2],
            seed_inertia: false,
        }
    }
}

/// `[simulate]`: the forward simulation of every schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulateSettings {
    /// Relative tolerance of the adaptive integrator (default 1e-10).
    pub rtol: f64,
    /// Absolute tolerance (default 1e-12).
    pub atol: f64,
    /// Add PD tracking of the planned shape to the feed-forward torque (default true).
    pub pd: bool,
    /// PD bandwidth, Hz, about the straight cat's inertia (default 10).
    pub pd_bandwidth_hz: f64,
    /// PD damping ratio (default 1).
    pub pd_damping: f64,
    /// Rows per phase in written schedules (default 200).
    pub samples_per_phase: usize,
    /// Largest flip error and spine tilt of a simulated design, rad, beyond
    /// which the design is flagged as missing the flip (default 0.01).
    pub flip_tolerance: f64,
}

impl Default for SimulateSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            pd: true,
            pd_bandwidth_hz: 10.0,
            pd_damping: 1.0,
            samples_per_phase: 200,
            flip_tolerance: 0.01,
        }
    }
}

/// `[phased]`: the fold / twist / unfold optimiser.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhasedSettings {
    /// Grid intervals per phase of the path-timing SOCP (default 40).
    pub nodes: usize,
    /// Bend search range, degrees (default 5 to 170).
    pub bend_min_deg: f64,
    pub bend_max_deg: f64,
    /// Points of the coarse bend scan before refinement (default 12).
    pub scan_points: usize,
    /// Bend tolerance of the refinement, degrees (default 0.05).
    pub bend_tol_deg: f64,
}

impl Default for PhasedSettings {
    fn default() -> Self {
        Self {
            nodes: 40,
            bend_min_deg: 5.0,
            bend_max_deg: 170.0,
            scan_points: 12,
            bend_tol_deg: 0.05,
        }
    }
}

/// `[free]`: the free-form optimiser.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FreeSettings {
    /// Collocation nodes per phase (default 40).
    pub nodes: usize,
    /// SCP iteration limit (default 150).
    pub max_iterations: usize,
    /// Stop when the predicted improvement falls below this fraction of the merit (default 1e-4).
    pub tolerance: f64,
    /// Flip tolerance of the converged design, rad (default 1e-6).
    pub attitude_tolerance: f64,
    /// Mesh continuation (default true): a peak-torque design without a
    /// torque-speed line or speed limit is solved from its seed at a third
    /// of the nodes first (or half; again while that leaves at least 20 per
    /// phase), loosely, and refined (`design::free::coarse_start`); any
    /// other design (`DesignSpec::uses_envelope`) at half the nodes first,
    /// while that leaves at least 20 per phase
    /// (`design::free::envelope_coarse_start`).
    pub mesh_continuation: bool,
    /// Leave out of each SCP subproblem the torque-speed rows that cannot
    /// bind there (the subproblem's solution is the same, with fewer rows);
    /// see `design::scp::screen` and docs/configuration.md.
    pub screen_limits: bool,
    /// Let the torque of a peak-torque design step at its mesh's nodes
    /// (default true): each interval has its own acceleration at both ends;
    /// see `design::free::grid`.
    pub torque_jumps: bool,
}

impl Default for FreeSettings {
    fn default() -> Self {
        Self {
            nodes: 40,
            max_iterations: 150,
            tolerance: 1e-4,
            attitude_tolerance: 1e-6,
            mesh_continuation: true,
            screen_limits: true,
            torque_jumps: true,
        }
    }
}

impl AnalyticSettings {
    /// The ranges of `analytic.*` (docs/configuration.md).
    pub fn validate(&self) -> Result<()> {
        check(
            "analytic.theta_deg",
            self.theta_deg,
            self.theta_deg > 0.0 && self.theta_deg < 180.0,
            "must be in (0, 180) degrees",
        )?;
        for (i, x) in self.split.iter().enumerate() {
            check(
                &format!("analytic.split[{i}]"),
                *x,
                *x > 0.0,
                "each fraction must be > 0",
            )?;
        }
        let sum: f64 = self.split.iter().sum();
        if (sum - 1.0).abs() >= 1e-9 {
            return Err(Error::Invalid {
                key: "analytic.split".into(),
                value: format!("{:?}", self.split),
                expected: format!(
                    "fractions that sum to 1 (these sum to {})",
                    format!("{sum:.9}")
                        .trim_end_matches('0')
                        .trim_end_matches('.')
                ),
            });
        }
        Ok(())
    }
}

impl SimulateSettings {
    /// The ranges of `simulate.*` (docs/configuration.md).
    pub fn validate(&self) -> Result<()> {
        check(
            "simulate.rtol",
            self.rtol,
            self.rtol > 0.0 && self.rtol <= 1e-2,
            "must be in (0, 1e-2]",
        )?;
        check(
            "simulate.atol",
            self.atol,
            self.atol > 0.0 && self.atol <= 1e-2,
            "must be in (0, 1e-2]",
        )?;
        check(
            "simulate.pd_bandwidth_hz",
            self.pd_bandwidth_hz,
            self.pd_bandwidth_hz > 0.0,
            "must be > 0 Hz",
        )?;
        check(
            "simulate.pd_damping",
            self.pd_damping,
            self.pd_damping > 0.0,
            "must be > 0",
        )?;
        check(
            "simulate.flip_tolerance",
            self.flip_tolerance,
            self.flip_tolerance > 0.0 && self.flip_tolerance <= std::f64::consts::PI,
            &format!(
                "must be in (0, pi] rad{}",
                if self.flip_tolerance > std::f64::consts::PI {
                    format!(
                        " (degrees? {} deg = {:.4} rad)",
                        self.flip_tolerance,
                        self.flip_tolerance.to_radians()
                    )
                } else {
                    String::new()
                }
            ),
        )?;
        let n = self.samples_per_phase as f64;
        check(
            "simulate.samples_per_phase",
            n,
            (2.0..=30_000.0).contains(&n),
            "must be a whole number in [2, 30000]",
        )?;
        Ok(())
    }
}

impl PhasedSettings {
    /// The ranges of `phased.*` (docs/configuration.md).
    pub fn validate(&self) -> Result<()> {
        check(
            "phased.nodes",
            self.nodes as f64,
            (4..=2000).contains(&self.nodes),
            "must be a whole number in [4, 2000]",
        )?;
        check(
            "phased.bend_min_deg",
            self.bend_min_deg,
            self.bend_min_deg > 0.0,
            "must be > 0 degrees",
        )?;
        check(
            "phased.bend_max_deg",
            self.bend_max_deg,
            self.bend_max_deg > self.bend_min_deg && self.bend_max_deg < 180.0,
            "must exceed phased.bend_min_deg and be < 180 degrees",
        )?;
        check(
            "phased.scan_points",
            self.scan_points as f64,
            (3..=200).contains(&self.scan_points),
            "must be a whole number in [3, 200]",
        )?;
        check(
            "phased.bend_tol_deg",
            self.bend_tol_deg,
            self.bend_tol_deg > 0.0,
            "must be > 0 degrees",
        )?;
        Ok(())
    }
}

impl FreeSettings {
    /// The ranges of `free.*` (docs/configuration.md).
    pub fn validate(&self) -> Result<()> {
        check(
            "free.nodes",
            self.nodes as f64,
            (4..=400).contains(&self.nodes),
            "must be a whole number in [4, 400]",
        )?;
        check(
            "free.max_iterations",
            self.max_iterations as f64,
            self.max_iterations >= 1,
            "must be >= 1",
        )?;
        check(
            "free.tolerance",
            self.tolerance,
            self.tolerance > 0.0 && self.tolerance < 1.0,
            "must be in (0, 1)",
        )?;
        check(
            "free.attitude_tolerance",
            self.attitude_tolerance,
            self.attitude_tolerance > 0.0,
            "must be > 0 rad",
        )?;
        Ok(())
    }
}

impl DesignSpec {
    /// The settings' ranges, as `Config::validate` checks them (the body,
    /// fall, motors and start a spec from a config has already passed).
    pub fn validate(&self) -> Result<()> {
        self.analytic.validate()?;
        self.simulate.validate()?;
        self.phased.validate()?;
        self.free.validate()
    }

    /// The same problem dropped from `height`, m.
    pub fn with_height(&self, height: f64) -> DesignSpec {
        let mut s = self.clone();
        s.fall.height = height;
        s
    }

    /// The same problem with a continuous torque (`free.torque_jumps` off),
    /// for a design that seeds or is replanned on a continuous grid.
    pub fn without_torque_jumps(&self) -> DesignSpec {
        let mut s = self.clone();
        s.free.torque_jumps = false;
        s
    }

    /// The same problem with another objective.
    pub fn with_objective(&self, objective: Objective) -> DesignSpec {
        let mut s = self.clone();
        s.objective = objective;
        s
    }

    /// The same problem with other motors (their limits the caller's, not
    /// a robot file's).
    pub fn with_motor(&self, motor: Motor) -> DesignSpec {
        let mut s = self.clone();
        s.motor = motor;
        s.limits_from = LimitOrigin::default();
        s
    }

    /// The same problem with other free-form settings.
    pub fn with_free(&self, free: FreeSettings) -> DesignSpec {
        let mut s = self.clone();
        s.free = free;
        s
    }

    /// See [`Fall::fall_time`].
    pub fn fall_time(&self) -> f64 {
        self.fall.fall_time()
    }

    /// See [`Fall::available_time`].
    pub fn available_time(&self) -> f64 {
        self.fall.available_time()
    }

    /// How the two torque components make the peak torque.
    pub fn norm(&self) -> TorqueNorm {
        self.motor.norm
    }

    /// Whether the release is today's: upside down and at rest.
    pub fn is_default_start(&self) -> bool {
        self.start.is_none()
    }

    /// Whether the start has angular momentum (a spin; a tilt at rest has none).
    pub fn has_momentum(&self) -> bool {
        self.release().momentum(&self.cat).iter().any(|&c| c != 0.0)
    }

    /// The release (today's when none is given).
    pub fn release(&self) -> Start {
        self.start.unwrap_or_default()
    }

    /// Whether the design needs the motor-envelope program (a speed limit, a
    /// torque-speed line or an objective other than the peak torque) rather
    /// than the unit-time peak program with F3 scaling.
    pub fn uses_envelope(&self) -> bool {
        self.objective != Objective::PeakTorque
            || self.motor.max_speed.is_some()
            || self.motor.no_load_speed.is_some()
    }

    /// Largest bend the phased design may use (and the free-form design's
    /// mesh must resolve), rad: the limit, or 175 deg without one.
    pub fn max_bend(&self) -> f64 {
        self.max_bend_deg.unwrap_or(175.0).to_radians()
    }

    /// The motor limits that are set, as the config keys a user would
    /// change (`limits.max_torque, limits.no_load_speed`), for messages.
    pub fn envelope_keys(&self) -> String {
        let m = &self.motor;
        [
            ("limits.max_torque", m.max_torque.is_some()),
            ("limits.no_load_speed", m.no_load_speed.is_some()),
            ("limits.max_speed", m.max_speed.is_some()),
        ]
        .iter()
        .filter(|(_, set)| *set)
        .map(|(k, _)| self.limits_from.name(k))
        .collect::<Vec<_>>()
        .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// The defaults pass their own checks, and a setting out of range is
    /// refused under its config key.
    #[test]
    fn defaults_validate_and_a_bad_setting_names_its_key() {
        let seed = include_str!("../../configs/seed.toml");
        let spec = crate::test_support::spec_of(seed, "seed", &[]);
        spec.validate().unwrap();
        let key = |spec: &DesignSpec| match spec.validate() {
            Err(Error::Invalid { key, .. }) => key,
            other => panic!("{other:?}"),
        };
        let mut bad = spec.clone();
        bad.phased.bend_max_deg = bad.phased.bend_min_deg;
        assert_eq!(key(&bad), "phased.bend_max_deg");
        let mut bad = spec.clone();
        bad.free.tolerance = 1.0;
        assert_eq!(key(&bad), "free.tolerance");
        let mut bad = spec.clone();
        bad.simulate.samples_per_phase = 1;
        assert_eq!(key(&bad), "simulate.samples_per_phase");
        let mut bad = spec;
        bad.analytic.split = [0.5, 0.5, 0.5];
        assert_eq!(key(&bad), "analytic.split");
    }

    /// A variant changes its one part and keeps the rest.
    #[test]
    fn a_variant_changes_only_its_part() {
        let seed = include_str!("../../configs/seed.toml");
        let spec = crate::test_support::spec_of(seed, "seed", &[]);
        let high = spec.with_height(2.0 * spec.fall.height);
        assert_eq!(high.fall.height, 2.0 * spec.fall.height);
        assert!(high.available_time() > spec.available_time());
        assert_eq!(high.with_height(spec.fall.height), spec);
        let timed = spec.with_objective(Objective::Time);
        assert!(timed.uses_envelope() && !spec.uses_envelope());
        assert_eq!(timed.with_objective(spec.objective), spec);
    }
}
