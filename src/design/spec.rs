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
    /// is unbounded and the phased bend search stops at 175 deg.
    pub max_bend_deg: Option<f64>,
    /// Largest angle of the belly from straight down at touchdown, deg
    /// (`None`: the flip judged by `simulate.flip_tolerance`).
    pub max_tilt_deg: Option<f64>,
    pub analytic: AnalyticSettings,
    pub simulate: SimulateSettings,
    pub phased: PhasedSettings,
    pub free: FreeSettings,
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
    /// Mesh continuation of peak-torque designs without a torque-speed
    /// line or speed limit (default true): from a
    /// seed, solve at a third of the nodes first (or half; again while that
    /// leaves at least 20 per phase), loosely, and refine; see
    /// `design::free::coarse_start`.
    pub mesh_continuation: bool,
}

impl Default for FreeSettings {
    fn default() -> Self {
        Self {
            nodes: 40,
            max_iterations: 150,
            tolerance: 1e-4,
            attitude_tolerance: 1e-6,
            mesh_continuation: true,
        }
    }
}

impl DesignSpec {
    /// The same problem dropped from `height`, m.
    pub fn with_height(&self, height: f64) -> DesignSpec {
        let mut s = self.clone();
        s.fall.height = height;
        s
    }

    /// The same problem with another objective.
    pub fn with_objective(&self, objective: Objective) -> DesignSpec {
        let mut s = self.clone();
        s.objective = objective;
        s
    }

    /// The same problem with other motors.
    pub fn with_motor(&self, motor: Motor) -> DesignSpec {
        let mut s = self.clone();
        s.motor = motor;
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
        .map(|(k, _)| *k)
        .collect::<Vec<_>>()
        .join(", ")
    }
}
