//! The robot builder's question: with this body and these motors, can it
//! right itself from the configured height, and if not, from what height?
//!
//! The least drop height is the `time` design inside the motor envelope:
//! `h_min = g (T_min + margin)^2 / 2` (F7 when only the torque is limited).

use crate::config::Config;
use crate::design::free::{self, FreeResult};
use crate::design::objective::Objective;
use crate::design::plan::Schedule;
use crate::design::scp::ScpIteration;
use crate::error::Result;
use crate::verdict::{DesignNumbers, Simulated, Status, Targets, verdict};
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
    pub status: Status,
    /// Flip error of the least-height schedule in the motor-model simulation, rad.
    pub flip_error_rad: f64,
    /// Whether the answer is a design from the configured start (always at
    /// the default start). From another start only a free-form design that
    /// lands answers; without one the numbers are the start at rest's and
    /// `possible` is false.
    pub from_start: bool,
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
    let least = crate::design::envelope::height_for(cfg, r.manoeuvre_time_s);
    Ok(Some(HeightAnswer {
        possible: fits(cfg, least),
        height_m: cfg.fall.height,
        least_height_m: least,
        least_time_s: r.manoeuvre_time_s,
        method: "phased",
        status: r.status.into(),
        flip_error_rad: r.flip_error_rad,
        from_start: cfg.start.is_default(),
        schedule: Schedule::sample(&cfg.cat(), &r.plan, cfg.simulate.samples_per_phase),
    }))
}

/// Whether a drop from `height` is within the configured one (to rounding).
pub fn fits(cfg: &Config, height: f64) -> bool {
    height <= cfg.fall.height * (1.0 + crate::verdict::tolerance::HEIGHT)
}

/// The least drop heights of both design families, each from its `time`
/// design inside the motor envelope.
pub struct Heights {
    /// The better of the two (see [`HeightAnswer::improve_with`]).
    pub answer: HeightAnswer,
    /// The phased time design's least height, m.
    pub phased_m: f64,
    /// The shortest free-form time design that verifies ([`verified`]).
    pub free: Option<FreeResult>,
}

/// [`answer`], improved by the free-form time designs from the phased
/// schedule and from the analytic plan (a local method: each seed can end
/// in another optimum; on the robot 0.776 s and 0.750 s), run at once (the
/// robot's run: 12.4-13.7 s -> 8.5-9.5 s); `observe` sees the iterations of
/// the one from the phased schedule. Without `with_free`, the phased answer
/// alone.
pub fn heights(
    cfg: &Config,
    with_free: bool,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<Option<Heights>> {
    let Some(mut answer) = self::answer(cfg)? else {
        return Ok(None);
    };
    let phased_m = answer.least_height_m;
    if !with_free {
        return Ok(Some(Heights {
            answer,
            phased_m,
            free: None,
        }));
    }
    let mut timed = cfg.clone();
    timed.design.objective = Objective::Time;
    // the analytic plan and the problem's scaling are the configured fall's,
    // so the local method's optimum moves with the height: the robot's
    // shortest manoeuvre 0.7475 to 0.7578 s over drops of 1 to 10 m (and
    // 0.748 to 0.776 s between 5.6626 and 5.66263063 m). Started from the
    // phased least time instead, the answer stopped moving but landed at
    // 0.7828 s; the least height found is an upper bound either way
    let analytic_plan = crate::design::analytic::analytic_plan(cfg);
    let (from_phased, from_analytic) = std::thread::scope(|s| {
        let analytic = s.spawn(|| {
            free::FreeDesign::new(&timed)
                .from_plan(&analytic_plan, "analytic")
                .solve()
        });
        let phased = free::FreeDesign::new(&timed)
            .from_plan(&answer.schedule, "phased")
            .on_iteration(&mut observe)
            .solve();
        let analytic = analytic
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (phased, analytic)
    });
    let mut fastest: Option<FreeResult> = None;
    for fr in [from_phased, from_analytic].into_iter().flatten() {
        if verified(cfg, &fr)
            && fastest
                .as_ref()
                .is_none_or(|f| fr.manoeuvre_time_s < f.manoeuvre_time_s)
        {
            fastest = Some(fr);
        }
    }
    if let Some(fr) = &fastest {
        if !cfg.start.is_default() {
            // the phased design is made for the start at rest: from another
            // start it only seeds the free-form one, which answers
            answer.least_time_s = f64::INFINITY;
        }
        answer.improve_with(cfg, fr);
    } else if !cfg.start.is_default() {
        answer.possible = false;
    }
    Ok(Some(Heights {
        answer,
        phased_m,
        free: fastest,
    }))
}

/// Whether a free-form design can answer the robot question: its
/// constraints met (the SCP's violation within `free.attitude_tolerance`),
/// inside the motor envelope at every written row, and flipping under the
/// motor model within `simulate.flip_tolerance`. Optimality is not needed:
/// any schedule that does this shows the flip possible from its height (the
/// least height found is an upper bound either way), so a design that ran
/// out of iterations still counts, and says so in its status.
pub fn verified(cfg: &Config, fr: &FreeResult) -> bool {
    let usage = crate::design::envelope::usage_of(cfg, &fr.plan);
    let v = verdict(
        &Targets::of(cfg),
        &DesignNumbers {
            status: fr.status.into(),
            peak_torque_nm: fr.peak_torque_nm,
            bend_deg: fr.bend_deg,
            max_speed_rad_s: Some(usage.max_speed_rad_s),
            envelope_margin: usage.min_margin,
        },
        &if cfg.start.is_default() {
            Simulated::Flip {
                flip_error_rad: fr.flip_error_rad,
                tilt_deg: fr.tilt_deg,
            }
        } else {
            Simulated::Landing {
                flip_error_rad: fr.flip_error_rad,
                tilt_deg: fr.tilt_deg,
                landing_error_deg: fr.landing_error_deg,
            }
        },
    );
    fr.certificate.constraint_violation <= cfg.free.attitude_tolerance
        && v.within_envelope()
        && v.flips()
}

impl HeightAnswer {
    /// Takes a verified free-form `time` design (`fr`: inside the envelope
    /// and flipping; `run` also passes designs that stopped at the
    /// iteration limit) when it is shorter than the answer's.
    pub fn improve_with(&mut self, cfg: &Config, fr: &FreeResult) {
        if fr.manoeuvre_time_s >= self.least_time_s {
            return;
        }
        self.least_time_s = fr.manoeuvre_time_s;
        self.least_height_m = crate::design::envelope::height_for(cfg, fr.manoeuvre_time_s);
        self.possible = fits(cfg, self.least_height_m);
        self.method = "free";
        self.status = fr.status.into();
        self.flip_error_rad = fr.flip_error_rad;
        self.from_start = true;
        self.schedule = Schedule::sample(&cfg.cat(), &fr.plan, cfg.simulate.samples_per_phase);
    }

    /// One plain sentence for the terminal and the report.
    pub fn sentence(&self) -> String {
        let what = if self.status.is_proven() {
            format!("the {} time-optimal schedule", self.method)
        } else {
            format!(
                "the {} time design, verified but not proven shortest ({})",
                self.method, self.status
            )
        };
        if !self.from_start {
            format!(
                "No design found lands belly-down from this start in the fall from {} m (at rest the motors would need {:.3} m).",
                self.height_m, self.least_height_m
            )
        } else if self.possible && self.least_height_m > self.height_m {
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
