//! The robot builder's question: with this body and these motors, can it
//! right itself from the configured height, and if not, from what height?
//!
//! The least drop height is the `time` design inside the motor envelope:
//! `h_min = g (T_min + margin)^2 / 2` (F7 when only the torque is limited).

use crate::config::Config;
use crate::design::objective::Objective;
use crate::design::plan::Schedule;
use crate::error::Result;
use serde::Serialize;

/// The answer, and the schedule that achieves the least height.
#[derive(Debug, Clone, Serialize)]
pub struct HeightAnswer {
    /// Whether the flip fits in the fall from `fall.height`.
    pub possible: bool,
    /// The configured drop height, m.
    pub height_m: f64,
    /// The least drop height found for the motors, m: the better of the
    /// phased and free-form `time` designs (an upper bound on the true least
    /// height).
    pub least_height_m: f64,
    /// The shortest manoeuvre inside the motor envelope, s.
    pub least_time_s: f64,
    /// Which design settles the answer: the one with the least height
    /// (`phased` or `free`), or `free` when a verified free-form schedule
    /// fits although no phased one does.
    pub method: &'static str,
    /// The status of that design's solver (`solved`, `converged`, or e.g.
    /// `iteration-limit` for a verified free-form schedule that is not
    /// proven the shortest).
    pub status: String,
    /// Flip error of the least-height schedule in the motor-model simulation, rad.
    pub flip_error_rad: f64,
    /// The least-height schedule.
    #[serde(skip)]
    pub schedule: Schedule,
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
        status: crate::run::json_name(&r.status),
        flip_error_rad: r.flip_error_rad,
        schedule: Schedule::sample(&cfg.cat(), &r.plan, cfg.simulate.samples_per_phase),
    }))
}

impl HeightAnswer {
    /// Takes a verified free-form `time` design (`fr`: inside the envelope
    /// and flipping; `run` also passes designs that stopped at the
    /// iteration limit) when it is shorter than the answer's.
    pub fn improve_with(&mut self, cfg: &Config, fr: &crate::design::free::FreeResult) {
        if fr.manoeuvre_time_s >= self.least_time_s {
            return;
        }
        self.least_time_s = fr.manoeuvre_time_s;
        self.least_height_m = crate::design::envelope::height_for(cfg, fr.manoeuvre_time_s);
        self.possible = self.least_height_m <= cfg.fall.height * (1.0 + 1e-9);
        self.method = "free";
        self.status = crate::run::json_name(&fr.status);
        self.flip_error_rad = fr.flip_error_rad;
        self.schedule = Schedule::sample(&cfg.cat(), &fr.plan, cfg.simulate.samples_per_phase);
    }

    /// One plain sentence for the terminal and the report.
    pub fn sentence(&self) -> String {
        let proven = matches!(
            self.status.as_str(),
            "solved" | "almost-solved" | "converged"
        );
        let what = if proven {
            format!("the {} time-optimal schedule", self.method)
        } else {
            format!(
                "the {} time design, verified but not proven shortest ({})",
                self.method, self.status
            )
        };
        if self.possible && self.least_height_m > self.height_m {
            format!(
                "The flip is possible from {} m: the {} design fits the motors, although the phased least-height design needs {:.3} m.",
                self.height_m, self.method, self.least_height_m
            )
        } else if self.possible {
            format!(
                "The flip is possible from {} m: the motors need at most {:.3} m ({:.4} s of manoeuvre, {what} in least-height.csv).",
                self.height_m, self.least_height_m, self.least_time_s
            )
        } else {
            format!(
                "The flip is NOT possible from {} m with these motors: from {:.3} m it is ({:.4} s of manoeuvre, {what} in least-height.csv).",
                self.height_m, self.least_height_m, self.least_time_s
            )
        }
    }
}
