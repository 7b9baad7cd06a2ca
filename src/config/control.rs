//! `[control]` and `[robustness]`: the closed loop along a design and the
//! Monte Carlo study that perturbs it. The defaults are the closed loop's
//! target set: spin up to 0.5 rad/s about any axis, tilt up to 20 deg, +-10 %
//! inertia on each half, 5 ms actuator delay, 5 % torque noise.

use super::check;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// Most trials one study may run: 10^6 trials of the closed loop take hours
/// on one core, and the 95 % interval is then already narrower than 0.1 %.
pub const MAX_TRIALS: usize = 1_000_000;

/// `[control]`: the time-varying LQR along a design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlConfig {
    /// Rate of the feedback (and of replanning), Hz (default 100).
    pub rate_hz: f64,
    /// Actuator delay the controller predicts over, ms (default 5).
    pub delay_ms: f64,
    /// Step rate of catflip's fixed-step closed-loop simulator, Hz (default 4000).
    pub sim_rate_hz: f64,
    /// Terminal weight on the belly's tilt from down (per rad^2; default 1000).
    pub landing_weight: f64,
    /// Terminal weight on the shape and its rate (scaled: rad, rad per manoeuvre time; default 10).
    pub final_shape_weight: f64,
    /// Running weight on the attitude error per second of the manoeuvre time (default 1).
    pub attitude_weight: f64,
    /// Running weight on the shape error (default 10).
    pub shape_weight: f64,
    /// Running weight on the shape-rate error (default 0.1).
    pub rate_weight: f64,
    /// Running weight on the torque correction, in units of the design's peak torque (default 1).
    pub torque_weight: f64,
    /// Largest correction on top of the feed-forward, in units of the design's
    /// peak torque (default 2): far from the design a linear gain asks for
    /// torques no actuator has; the motor envelope, when set, clips as well.
    pub max_correction: f64,
    /// Collocation nodes per phase of a replan in flight (default 6: the
    /// replan's p99 well inside a 100 Hz period, see docs/control.md).
    pub replan_nodes: usize,
    /// SCP iterations of a replan at most (default 1: a real-time iteration,
    /// each replan warm-started from the last).
    pub replan_iterations: usize,
    /// Control periods from one replan to the next (default 1).
    pub replan_every: usize,
}

impl Default for ControlConfig {
    fn default() -> Self {
        Self {
            rate_hz: 100.0,
            delay_ms: 5.0,
            sim_rate_hz: 4000.0,
            landing_weight: 1000.0,
            final_shape_weight: 10.0,
            attitude_weight: 1.0,
            shape_weight: 10.0,
            rate_weight: 0.1,
            torque_weight: 1.0,
            max_correction: 2.0,
            replan_nodes: 6,
            replan_iterations: 1,
            replan_every: 1,
        }
    }
}

/// How far (relative) the rate the feedback runs at, a whole number of
/// simulator steps a period, may be from `control.rate_hz`: 60 Hz runs at
/// 59.7 on the default 4 kHz steps; 3000 Hz would run at 4000.
const RATE_TOLERANCE: f64 = 0.05;

/// `x` to three decimals, as a message suggests a value (1333.333, not
/// 1333.3333333333333).
fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

impl ControlConfig {
    /// A delay (`key`, ms) in [0, 1000] ms, and at least half a simulator
    /// step when not 0: the simulator and the prediction apply it in whole
    /// steps (0.1 ms at 4 kHz was no delay at all, reported as 0.1 ms). A
    /// delay further than [`RATE_TOLERANCE`] from whole steps is a warning
    /// ([`ControlConfig::delay_slip`]).
    pub fn check_delay(&self, key: &str, delay_ms: f64) -> Result<()> {
        check(
            key,
            delay_ms,
            (0.0..=1000.0).contains(&delay_ms),
            if delay_ms < 0.0 {
                "must be in [0, 1000] ms (a delay is never negative)"
            } else {
                "must be in [0, 1000] ms"
            },
        )?;
        let step_ms = 1e3 / self.sim_rate_hz;
        check(
            key,
            delay_ms,
            delay_ms == 0.0 || (delay_ms / step_ms).round() >= 1.0,
            &format!(
                "the delay is applied in whole simulator steps of {} ms (control.sim_rate_hz = {}): \
                 this one would be no delay at all; use 0 or {} ms, or raise control.sim_rate_hz",
                round3(step_ms),
                self.sim_rate_hz,
                round3(step_ms),
            ),
        )
    }

    /// A delay (`key`, ms) that whole simulator steps change by more than
    /// [`RATE_TOLERANCE`]: what is applied, in words (a warning).
    pub fn delay_slip(&self, delay_ms: f64) -> Option<String> {
        let step_ms = 1e3 / self.sim_rate_hz;
        let applied = (delay_ms / step_ms).round() * step_ms;
        ((applied - delay_ms).abs() > RATE_TOLERANCE * delay_ms).then(|| {
            format!(
                "applied in whole simulator steps of {} ms (control.sim_rate_hz = {}), it is {} ms; \
                 give a multiple of {} ms, or raise control.sim_rate_hz",
                round3(step_ms),
                self.sim_rate_hz,
                round3(applied),
                round3(step_ms),
            )
        })
    }

    pub fn validate(&self) -> Result<()> {
        check(
            "control.sim_rate_hz",
            self.sim_rate_hz,
            self.sim_rate_hz >= 100.0 && self.sim_rate_hz <= 1e6,
            "must be in [100, 1e6] Hz",
        )?;
        check(
            "control.rate_hz",
            self.rate_hz,
            self.rate_hz >= 1.0 && self.rate_hz <= self.sim_rate_hz,
            &format!(
                "must be in [1, control.sim_rate_hz = {}] Hz ({})",
                self.sim_rate_hz,
                if self.rate_hz.is_nan() || self.rate_hz < 1.0 {
                    "at least one correction a second"
                } else {
                    "the feedback cannot run faster than the simulator steps"
                }
            ),
        )?;
        let steps = (self.sim_rate_hz / self.rate_hz).round();
        let applied = self.sim_rate_hz / steps;
        check(
            "control.rate_hz",
            self.rate_hz,
            (applied / self.rate_hz - 1.0).abs() <= RATE_TOLERANCE,
            &format!(
                "the feedback acts every whole simulator step (control.sim_rate_hz = {}): this rate would run at {} Hz; \
                 use a rate that divides the simulator's evenly, e.g. {} or {} Hz, or set control.sim_rate_hz to a multiple of it",
                self.sim_rate_hz,
                round3(applied),
                round3(self.sim_rate_hz / (self.sim_rate_hz / self.rate_hz).ceil()),
                round3(self.sim_rate_hz / (self.sim_rate_hz / self.rate_hz).floor().max(1.0)),
            ),
        )?;
        self.check_delay("control.delay_ms", self.delay_ms)?;
        for (key, v) in [
            ("control.landing_weight", self.landing_weight),
            ("control.final_shape_weight", self.final_shape_weight),
            ("control.attitude_weight", self.attitude_weight),
            ("control.shape_weight", self.shape_weight),
            ("control.rate_weight", self.rate_weight),
        ] {
            check(key, v, (0.0..=1e12).contains(&v), "must be in [0, 1e12]")?;
        }
        check(
            "control.torque_weight",
            self.torque_weight,
            self.torque_weight > 0.0 && self.torque_weight <= 1e12,
            "must be in (0, 1e12]: a free torque correction has no optimum",
        )?;
        check(
            "control.max_correction",
            self.max_correction,
            self.max_correction > 0.0 && self.max_correction <= 1e6,
            "must be in (0, 1e6] times the design's peak torque",
        )?;
        check(
            "control.replan_nodes",
            self.replan_nodes as f64,
            (4..=100).contains(&self.replan_nodes),
            "must be in [4, 100] nodes per phase (a replan must fit a control period)",
        )?;
        check(
            "control.replan_iterations",
            self.replan_iterations as f64,
            (1..=100).contains(&self.replan_iterations),
            "must be in [1, 100] SCP iterations",
        )?;
        check(
            "control.replan_every",
            self.replan_every as f64,
            (1..=1000).contains(&self.replan_every),
            "must be in [1, 1000] control periods",
        )?;
        Ok(())
    }

    /// The control period, s.
    pub fn period(&self) -> f64 {
        1.0 / self.rate_hz
    }
}

/// `[robustness]`: the perturbations of `catflip robustness`, each drawn per
/// trial uniformly up to the given size (signs and axes at random).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RobustnessConfig {
    /// Largest initial body rate about each of the rear half's axes, rad/s;
    /// the rate is a random direction scaled by these (default [0.5, 0.5, 0.5]).
    pub spin_rad_s: [f64; 3],
    /// Largest initial tilt of the spine about a random horizontal axis, deg (default 20).
    pub tilt_deg: f64,
    /// Largest relative error of each half's mass (default 0).
    pub mass_error: f64,
    /// Largest relative error of each half's inertia, mass and length kept
    /// (the radii of gyration scaled; default 0.1).
    pub inertia_error: f64,
    /// Largest relative error of each half's length (default 0).
    pub length_error: f64,
    /// Actuator delay of the simulated robot, ms (default 5).
    pub delay_ms: f64,
    /// Torque noise, standard deviation as a fraction of the design's peak
    /// torque, drawn afresh each control period (default 0.05).
    pub torque_noise: f64,
    /// Attitude sensor noise, standard deviation per axis, deg (default 0).
    pub attitude_noise_deg: f64,
    /// Gyro and joint-rate noise, standard deviation, rad/s (default 0).
    pub rate_noise_rad_s: f64,
    /// Largest relative error of the joint PD gains of the open loop (default 0).
    pub pd_gain_error: f64,
    /// Worst trials kept with their seeds in the JSON (default 5).
    pub worst_kept: usize,
}

impl Default for RobustnessConfig {
    fn default() -> Self {
        Self {
            spin_rad_s: [0.5; 3],
            tilt_deg: 20.0,
            mass_error: 0.0,
            inertia_error: 0.1,
            length_error: 0.0,
            delay_ms: 5.0,
            torque_noise: 0.05,
            attitude_noise_deg: 0.0,
            rate_noise_rad_s: 0.0,
            pd_gain_error: 0.0,
            worst_kept: 5,
        }
    }
}

impl RobustnessConfig {
    pub fn validate(&self) -> Result<()> {
        for (i, w) in self.spin_rad_s.iter().enumerate() {
            check(
                &format!("robustness.spin_rad_s[{i}]"),
                *w,
                (0.0..=super::MAX_START_RATE).contains(w),
                &format!("must be in [0, {}] rad/s", super::MAX_START_RATE),
            )?;
        }
        check(
            "robustness.tilt_deg",
            self.tilt_deg,
            (0.0..=180.0).contains(&self.tilt_deg),
            "must be in [0, 180] deg",
        )?;
        for (key, v) in [
            ("robustness.mass_error", self.mass_error),
            ("robustness.inertia_error", self.inertia_error),
            ("robustness.length_error", self.length_error),
        ] {
            check(
                key,
                v,
                (0.0..1.0).contains(&v),
                if v < 0.0 {
                    "must be in [0, 1): the largest error drawn, a size (its sign is drawn at random)"
                } else {
                    "must be in [0, 1): an error of 1 or more makes a half massless or shapeless"
                },
            )?;
        }
        for (key, v, hi) in [
            ("robustness.torque_noise", self.torque_noise, 10.0),
            (
                "robustness.attitude_noise_deg",
                self.attitude_noise_deg,
                90.0,
            ),
            ("robustness.rate_noise_rad_s", self.rate_noise_rad_s, 100.0),
            ("robustness.pd_gain_error", self.pd_gain_error, 0.99),
        ] {
            check(
                key,
                v,
                (0.0..=hi).contains(&v),
                &format!("must be in [0, {hi}]"),
            )?;
        }
        check(
            "robustness.worst_kept",
            self.worst_kept as f64,
            self.worst_kept <= 1000,
            "must be in [0, 1000]",
        )?;
        Ok(())
    }
}
