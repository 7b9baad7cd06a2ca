//! The robot builder's question: with this body and these motors, can it
//! right itself from the configured height, and if not, from what height?
//!
//! The least drop height is the `time` design inside the motor envelope:
//! `h_min = g (T_min + margin)^2 / 2` (F7 when only the torque is limited).

use crate::config::Config;
use crate::design::objective::Objective;
use crate::design::path::PhasedPlan;
use crate::error::Result;
use serde::Serialize;

/// The answer, and the schedule that achieves the least height.
#[derive(Debug, Clone, Serialize)]
pub struct HeightAnswer {
    /// Whether the flip fits in the fall from `fall.height`.
    pub possible: bool,
    /// The configured drop height, m.
    pub height_m: f64,
    /// The least drop height at which the motors can flip the cat, m.
    pub least_height_m: f64,
    /// The shortest manoeuvre inside the motor envelope, s.
    pub least_time_s: f64,
    /// Which design found it.
    pub method: &'static str,
    /// Flip error of the least-height schedule in the motor-model simulation, rad.
    pub flip_error_rad: f64,
    #[serde(skip)]
    pub plan: PhasedPlan,
}

/// Answers the question when the motors are limited (`None` otherwise: an
/// unlimited motor flips the cat from any height).
pub fn answer(cfg: &Config) -> Result<Option<HeightAnswer>> {
    if !cfg.motor().is_limited() {
        return Ok(None);
    }
    let mut timed = cfg.clone();
    timed.design.objective = Objective::Time;
    let r = crate::design::phased::optimize(&timed, |_| {})?;
    let least = 0.5 * cfg.fall.gravity * (r.manoeuvre_time_s + cfg.fall.margin).powi(2);
    Ok(Some(HeightAnswer {
        possible: least <= cfg.fall.height * (1.0 + 1e-9),
        height_m: cfg.fall.height,
        least_height_m: least,
        least_time_s: r.manoeuvre_time_s,
        method: "phased",
        flip_error_rad: r.flip_error_rad,
        plan: r.plan,
    }))
}

impl HeightAnswer {
    /// One plain sentence for the terminal and the report.
    pub fn sentence(&self) -> String {
        if self.possible {
            format!(
                "The flip is possible from {} m: the motors need at least {:.3} m ({:.4} s of manoeuvre, {}).",
                self.height_m, self.least_height_m, self.least_time_s, self.method
            )
        } else {
            format!(
                "The flip is NOT possible from {} m with these motors: drop it from at least {:.3} m ({:.4} s of manoeuvre, {} time-optimal schedule in least-height.csv).",
                self.height_m, self.least_height_m, self.least_time_s, self.method
            )
        }
    }
}
