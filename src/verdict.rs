//! One verdict for every design, whoever asks (`run`, `optimize`, `sweep`,
//! the least-height answer): how its solver ended ([`Status`]), and which
//! targets it misses ([`Miss`]), judged by [`verdict`] against one table of
//! tolerances ([`tolerance`]). Statuses become strings only when serialised.

use crate::design::conic::SolveStatus;
use crate::design::scp::ScpStatus;
use crate::design::spec::DesignSpec;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The tolerances of every judgement, in one place.
pub mod tolerance {
    /// A limit (torque, speed, bend) counts as broken only when the value
    /// exceeds it by more than this fraction. The phased design's SOCP
    /// certifies its bound on a grid, and the dense peak of the written
    /// schedule differs from it by the grid's error, so a design that sits
    /// on a limit reads a hair above it; 1e-6 is far below any motor's
    /// tolerance and far above rounding. The phased design refuses a peak
    /// beyond the torque limit with the same margin.
    pub const LIMIT: f64 = 1e-6;
    /// Smallest motor-envelope margin (1 unused, 0 on the envelope) a
    /// schedule may have, as a negative number: the same 1e-6.
    pub const ENVELOPE_MARGIN: f64 = 1e-6;
    /// A drop height fits the configured one when it exceeds it by at most
    /// this fraction (rounding of `g T^2 / 2`).
    pub const HEIGHT: f64 = 1e-9;
}

/// How a design's solver ended, for every method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// The analytic schedule: closed forms, nothing to converge.
    ClosedForm,
    /// The conic solver's optimum (phased designs).
    Solved,
    /// The conic solver's optimum to reduced accuracy.
    AlmostSolved,
    /// The SCP met its stopping rule (free-form designs).
    Converged,
    IterationLimit,
    /// The SCP's trust region shrank to nothing without converging.
    Stalled,
    Infeasible,
    Unbounded,
    NumericalError,
    /// No design: the method stopped with an error.
    Failed,
    /// No design tried: the motors cannot flip the cat in this fall (the
    /// least-height answer says so and from what height they can).
    NotAttempted,
}

impl Status {
    /// The solver certifies its result to full accuracy: the only statuses
    /// that leave a design unflagged.
    pub fn is_proven(self) -> bool {
        matches!(
            self,
            Status::ClosedForm | Status::Solved | Status::Converged
        )
    }

    /// A schedule exists (whether or not it is proven): it can be written,
    /// simulated and judged.
    pub fn is_usable(self) -> bool {
        !matches!(self, Status::Failed | Status::NotAttempted)
    }

    /// The name the JSON, CSV and tables use (`iteration-limit`).
    pub fn name(self) -> &'static str {
        match self {
            Status::ClosedForm => "closed-form",
            Status::Solved => "solved",
            Status::AlmostSolved => "almost-solved",
            Status::Converged => "converged",
            Status::IterationLimit => "iteration-limit",
            Status::Stalled => "stalled",
            Status::Infeasible => "infeasible",
            Status::Unbounded => "unbounded",
            Status::NumericalError => "numerical-error",
            Status::Failed => "failed",
            Status::NotAttempted => "not-attempted",
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl From<SolveStatus> for Status {
    fn from(s: SolveStatus) -> Self {
        match s {
            SolveStatus::Solved => Status::Solved,
            SolveStatus::AlmostSolved => Status::AlmostSolved,
            SolveStatus::Infeasible => Status::Infeasible,
            SolveStatus::Unbounded => Status::Unbounded,
            SolveStatus::IterationLimit => Status::IterationLimit,
            SolveStatus::NumericalError => Status::NumericalError,
        }
    }
}

impl From<ScpStatus> for Status {
    fn from(s: ScpStatus) -> Self {
        match s {
            ScpStatus::Converged => Status::Converged,
            ScpStatus::IterationLimit => Status::IterationLimit,
            ScpStatus::Stalled => Status::Stalled,
            ScpStatus::Infeasible => Status::Infeasible,
        }
    }
}

/// What a design is judged against: the motors' limits and the flip's
/// tolerance (from `[limits]` and `simulate.flip_tolerance`).
#[derive(Debug, Clone, PartialEq)]
pub struct Targets {
    pub max_torque: Option<f64>,
    /// With a torque-speed line a braking torque may exceed the stall
    /// torque: the envelope margin is the torque test then.
    pub no_load_speed: Option<f64>,
    pub max_speed: Option<f64>,
    pub max_bend_deg: Option<f64>,
    /// Without `limits.max_bend_deg`, the largest bend a two-cylinder cat
    /// allows, deg: bent further its halves pass through each other (the
    /// optimisers are free to, the body is not).
    pub geometric_bend_deg: Option<f64>,
    /// Largest flip error and spine tilt, rad.
    pub flip_tolerance: f64,
    /// Largest landing error, deg, when the landing is judged (`land.max_tilt_deg`,
    /// or any start other than today's: docs/model.md section 8), and the key that sets it.
    pub landing_tolerance: Option<(f64, &'static str)>,
    /// Whether the flip and tilt about the reference spine are judged: only
    /// from today's start (from another the landing decides).
    pub judge_flip: bool,
    /// The limit keys the config sets, for messages.
    pub envelope_keys: String,
    /// Where the limits came from (the keys, or a robot file), for messages.
    pub limits_from: crate::design::spec::LimitOrigin,
}

impl Targets {
    pub fn of(spec: &DesignSpec) -> Targets {
        Targets {
            max_torque: spec.motor.max_torque,
            no_load_speed: spec.motor.no_load_speed,
            max_speed: spec.motor.max_speed,
            max_bend_deg: spec.max_bend_deg,
            geometric_bend_deg: (spec.max_bend_deg.is_none() && spec.cat.general.is_none()).then(
                || 180.0 - crate::config::ranges::closest_theta_of_cat(&spec.cat).to_degrees(),
            ),
            flip_tolerance: spec.simulate.flip_tolerance,
            landing_tolerance: match spec.max_tilt_deg {
                Some(t) => Some((t, "land.max_tilt_deg")),
                None if !spec.is_default_start() => Some((
                    spec.simulate.flip_tolerance.to_degrees(),
                    "land.max_tilt_deg, by default simulate.flip_tolerance",
                )),
                None => None,
            },
            judge_flip: spec.is_default_start(),
            envelope_keys: spec.envelope_keys(),
            limits_from: spec.limits_from.clone(),
        }
    }

    /// Whether a dense peak breaks `limits.max_torque` (not with a
    /// torque-speed line: see [`Targets::no_load_speed`]).
    pub fn over_torque(&self, peak_torque_nm: f64) -> bool {
        self.no_load_speed.is_none()
            && self
                .max_torque
                .is_some_and(|lim| peak_torque_nm > lim * (1.0 + tolerance::LIMIT))
    }
}

/// The numbers of a design the verdict looks at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignNumbers {
    pub status: Status,
    /// Dense peak joint torque, N m.
    pub peak_torque_nm: f64,
    /// Largest bend, deg.
    pub bend_deg: f64,
    /// Fastest joint speed of the written schedule, rad/s.
    pub max_speed_rad_s: Option<f64>,
    /// Smallest motor-envelope margin of the written schedule.
    pub envelope_margin: Option<f64>,
    /// Smallest margin of its torque part alone (the torque-speed line):
    /// the envelope is named from it even where a speed limit is broken
    /// worse (`None`: not known, the envelope is named from its margin).
    pub line_margin: Option<f64>,
}

/// How the simulation of a design turned out, as the verdict needs it.
#[derive(Debug, Clone, PartialEq)]
pub enum Simulated {
    /// Flip error and spine tilt of the run.
    Flip { flip_error_rad: f64, tilt_deg: f64 },
    /// Flip error, spine tilt and landing error (deg) of a run from the
    /// configured start: the landing judged as [`Targets`] says.
    Landing {
        flip_error_rad: f64,
        tilt_deg: f64,
        landing_error_deg: f64,
    },
    /// The simulation itself failed, for this reason.
    Failed(String),
}

impl Simulated {
    pub fn of(
        sim: std::result::Result<&crate::verify::simulate::SimReport, &crate::Error>,
    ) -> Self {
        match sim {
            // the landing too: judged where the targets ask for it (from
            // another start, or with land.max_tilt_deg), as in `run`
            Ok(s) => Simulated::Landing {
                flip_error_rad: s.flip_error_rad,
                tilt_deg: s.tilt_deg,
                landing_error_deg: s.landing_error_deg,
            },
            Err(e) => Simulated::Failed(e.to_string()),
        }
    }
}

/// One target a design misses.
#[derive(Debug, Clone, PartialEq)]
pub enum Miss {
    /// The simulation failed (then nothing else about the flip is known).
    Simulation(String),
    /// The solver's result is not proven.
    Status(Status),
    /// Flip error beyond the tolerance (or NaN), rad.
    Flip { error_rad: f64, tolerance: f64 },
    /// Spine tilt beyond the tolerance (or NaN), deg.
    Tilt { tilt_deg: f64, tolerance: f64 },
    /// Above the torque limit; `name` says where the limit was set.
    Torque {
        peak_nm: f64,
        limit: f64,
        name: String,
    },
    Speed {
        speed_rad_s: f64,
        limit: f64,
        name: String,
    },
    /// Outside the motor envelope (the keys that set it); `line`: whether
    /// its torque part is broken (`None`: not known).
    Envelope {
        margin: f64,
        keys: String,
        line: Option<bool>,
    },
    Bend {
        bend_deg: f64,
        limit: f64,
        name: String,
    },
    /// Without a bend limit, bent past the bend at which the two-cylinder
    /// cat's halves meet (deg).
    Folds { bend_deg: f64, limit: f64 },
    /// The belly's angle from straight down at touchdown beyond the tolerance
    /// (or NaN), deg, and the key that sets the tolerance.
    Landing {
        error_deg: f64,
        tolerance_deg: f64,
        key: &'static str,
    },
}

impl Miss {
    /// A miss of the flip itself (simulation, flip error or tilt).
    pub fn is_flip(&self) -> bool {
        matches!(
            self,
            Miss::Simulation(_) | Miss::Flip { .. } | Miss::Tilt { .. } | Miss::Landing { .. }
        )
    }

    /// A broken motor or bend limit.
    pub fn is_limit(&self) -> bool {
        matches!(
            self,
            Miss::Torque { .. }
                | Miss::Speed { .. }
                | Miss::Envelope { .. }
                | Miss::Bend { .. }
                | Miss::Folds { .. }
        )
    }
}

impl fmt::Display for Miss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Miss::Simulation(e) => f.write_str(e),
            Miss::Status(s) => write!(f, "solver status {s}"),
            Miss::Flip {
                error_rad,
                tolerance,
            } => write!(
                f,
                "misses the flip by {} rad (simulate.flip_tolerance = {tolerance:e} rad)",
                crate::table::three_digits(*error_rad)
            ),
            Miss::Tilt {
                tilt_deg,
                tolerance,
            } => write!(
                f,
                "tilts the spine by {tilt_deg:.3} deg = {} rad (simulate.flip_tolerance = {tolerance:e} rad)",
                crate::table::three_digits(tilt_deg.to_radians())
            ),
            Miss::Torque {
                peak_nm,
                limit,
                name,
            } => write!(f, "needs {peak_nm:.4} N m, above {name} = {limit} N m"),
            Miss::Speed {
                speed_rad_s,
                limit,
                name,
            } => write!(
                f,
                "moves at {speed_rad_s:.4} rad/s, above {name} = {limit} rad/s"
            ),
            Miss::Envelope { margin, keys, .. } => write!(
                f,
                "leaves the motor envelope (smallest margin {margin:.3}; {keys})"
            ),
            Miss::Bend {
                bend_deg,
                limit,
                name,
            } => write!(f, "bends {bend_deg:.2} deg, above {name} = {limit} deg"),
            Miss::Folds { bend_deg, limit } => write!(
                f,
                "bends {bend_deg:.2} deg, past the {limit:.2} deg where this cat's halves meet; \
                 set limits.max_bend_deg to keep the designs inside it"
            ),
            Miss::Landing {
                error_deg,
                tolerance_deg,
                key,
            } => write!(
                f,
                "lands {error_deg:.3} deg from belly-down ({key} = {tolerance_deg:.4} deg)"
            ),
        }
    }
}

/// How a method ended, as the summary, the table and the exit status see it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Grade {
    /// A result that meets its targets.
    Ok,
    /// A result that misses a target (unconverged, flip missed, limit
    /// broken): kept and reported, with the reason.
    Flagged,
    /// No result: the method stopped with an error, given as the reason.
    Failed,
    /// No result, and none possible: the motors cannot do this method's
    /// manoeuvre in the configured fall. An answer, not an error; the reason
    /// says what height it needs.
    Impossible,
}

/// The judgement of one design: its status and every target it misses.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    pub status: Status,
    pub misses: Vec<Miss>,
    /// Why the method failed, when it did.
    pub error: Option<String>,
}

impl Verdict {
    /// A method that produced no design.
    pub fn failed(error: impl fmt::Display) -> Verdict {
        Verdict {
            status: Status::Failed,
            misses: Vec::new(),
            error: Some(error.to_string()),
        }
    }

    pub fn grade(&self) -> Grade {
        if self.error.is_some() {
            Grade::Failed
        } else if self.misses.is_empty() {
            Grade::Ok
        } else {
            Grade::Flagged
        }
    }

    /// Meets every target.
    pub fn is_ok(&self) -> bool {
        self.grade() == Grade::Ok
    }

    /// The simulated flip lands (whatever the status and limits).
    pub fn flips(&self) -> bool {
        self.error.is_none() && !self.misses.iter().any(Miss::is_flip)
    }

    /// Within every motor and bend limit ([`Miss::is_limit`]).
    pub fn within_limits(&self) -> bool {
        !self.misses.iter().any(Miss::is_limit)
    }

    /// Inside the motor envelope at every written row.
    pub fn within_envelope(&self) -> bool {
        !self
            .misses
            .iter()
            .any(|m| matches!(m, Miss::Envelope { .. }))
    }

    /// The misses worth naming: a simulation failure alone (nothing else is
    /// known then), else all of them, the envelope only when no torque or
    /// speed limit already explains it: a broken speed limit explains it
    /// when its torque line holds (where that is not known, when its margin
    /// is the speed's: below the speed's, the line is broken too).
    pub fn reasons(&self) -> Vec<String> {
        if let Some(e) = &self.error {
            return vec![e.clone()];
        }
        if let Some(m) = self
            .misses
            .iter()
            .find(|m| matches!(m, Miss::Simulation(_)))
        {
            return vec![m.to_string()];
        }
        let explained = |margin: f64, line: Option<bool>| {
            self.misses.iter().any(|m| match m {
                Miss::Torque { .. } => true,
                Miss::Speed {
                    speed_rad_s, limit, ..
                } => line.map_or(
                    margin >= (1.0 - speed_rad_s / limit) - tolerance::ENVELOPE_MARGIN,
                    |broken| !broken,
                ),
                _ => false,
            })
        };
        self.misses
            .iter()
            .filter(
                |m| !matches!(m, Miss::Envelope { margin, line, .. } if explained(*margin, *line)),
            )
            .map(Miss::to_string)
            .collect()
    }

    /// The reasons in one line (`None` when ok).
    pub fn reason(&self) -> Option<String> {
        let r = self.reasons();
        (!r.is_empty()).then(|| r.join("; "))
    }
}

/// Why a simulated flip misses (flip error or tilt beyond `tol`, rad; NaN
/// counts as a miss).
pub fn flip_misses(flip_error_rad: f64, tilt_deg: f64, tol: f64) -> Vec<Miss> {
    // NaN compares false: a failed number is a miss
    let beyond = |x: f64| x.is_nan() || x.abs() > tol;
    let mut why = Vec::new();
    if beyond(flip_error_rad) {
        why.push(Miss::Flip {
            error_rad: flip_error_rad,
            tolerance: tol,
        });
    }
    if beyond(tilt_deg.to_radians()) {
        why.push(Miss::Tilt {
            tilt_deg,
            tolerance: tol,
        });
    }
    why
}

/// Which limits a design breaks.
pub fn limit_misses(targets: &Targets, d: &DesignNumbers) -> Vec<Miss> {
    let mut why = Vec::new();
    if let Some(limit) = targets.max_torque
        && targets.over_torque(d.peak_torque_nm)
    {
        why.push(Miss::Torque {
            peak_nm: d.peak_torque_nm,
            limit,
            name: targets.limits_from.name("limits.max_torque"),
        });
    }
    if let (Some(limit), Some(s)) = (targets.max_speed, d.max_speed_rad_s)
        && s > limit * (1.0 + tolerance::LIMIT)
    {
        why.push(Miss::Speed {
            speed_rad_s: s,
            limit,
            name: targets.limits_from.name("limits.max_speed"),
        });
    }
    // NaN (a failed sample) is outside
    if let Some(m) = d.envelope_margin
        && (m.is_nan() || m < -tolerance::ENVELOPE_MARGIN)
    {
        let line = d
            .line_margin
            .map(|l| l.is_nan() || l < -tolerance::ENVELOPE_MARGIN);
        why.push(Miss::Envelope {
            // the line's own margin where it is the breach named
            margin: match (line, d.line_margin) {
                (Some(true), Some(l)) => l,
                _ => m,
            },
            keys: targets.envelope_keys.clone(),
            line,
        });
    }
    if let Some(limit) = targets.max_bend_deg
        && d.bend_deg > limit * (1.0 + tolerance::LIMIT)
    {
        why.push(Miss::Bend {
            bend_deg: d.bend_deg,
            limit,
            name: targets.limits_from.name("limits.max_bend_deg"),
        });
    }
    if let Some(limit) = targets.geometric_bend_deg
        && d.bend_deg > limit * (1.0 + tolerance::LIMIT)
    {
        why.push(Miss::Folds {
            bend_deg: d.bend_deg,
            // (shown to 0.01 deg: not above the limit by rounding up)
            limit: (limit * 100.0).floor() / 100.0,
        });
    }
    why
}

/// The verdict on a design: its status proven, its simulated flip within
/// the tolerance, its limits kept.
pub fn verdict(targets: &Targets, design: &DesignNumbers, simulation: &Simulated) -> Verdict {
    let mut misses = Vec::new();
    if let Simulated::Failed(e) = simulation {
        misses.push(Miss::Simulation(e.clone()));
    }
    if !design.status.is_proven() {
        misses.push(Miss::Status(design.status));
    }
    misses.extend(flight_misses(targets, simulation));
    misses.extend(limit_misses(targets, design));
    Verdict {
        status: design.status,
        misses,
        error: None,
    }
}

/// What a flight misses: the flip (at the default start) and the landing
/// (from another start, or with `land.max_tilt_deg`), as [`Targets`] say;
/// nothing for a failed simulation (the verdict names that).
pub fn flight_misses(targets: &Targets, simulation: &Simulated) -> Vec<Miss> {
    let mut misses = Vec::new();
    if let Simulated::Flip {
        flip_error_rad,
        tilt_deg,
    } = simulation
    {
        misses.extend(flip_misses(
            *flip_error_rad,
            *tilt_deg,
            targets.flip_tolerance,
        ));
    }
    if let Simulated::Landing {
        flip_error_rad,
        tilt_deg,
        landing_error_deg,
    } = simulation
    {
        if targets.judge_flip {
            misses.extend(flip_misses(
                *flip_error_rad,
                *tilt_deg,
                targets.flip_tolerance,
            ));
        }
        // NaN compares false: a failed number is a miss
        if let Some((tol, key)) = targets.landing_tolerance
            && (landing_error_deg.is_nan() || *landing_error_deg > tol)
        {
            misses.push(Miss::Landing {
                error_deg: *landing_error_deg,
                tolerance_deg: tol,
                key,
            });
        }
    }
    misses
}

/// [`flight_misses`] in one line (`None` when it lands): the verdict on a
/// replayed schedule, which has no solver and no limits of its own.
pub fn flight_reason(targets: &Targets, simulation: &Simulated) -> Option<String> {
    let why: Vec<String> = flight_misses(targets, simulation)
        .iter()
        .map(ToString::to_string)
        .collect();
    (!why.is_empty()).then(|| why.join("; "))
}

/// A result's JSON with its verdict (`"verdict": "ok" | "flagged" | ...`)
/// and, when it misses a target, `"reason"`.
pub fn with_verdict(v: &mut serde_json::Value, grade: Grade, reason: Option<String>) {
    v["verdict"] = serde_json::to_value(grade).expect("a grade serialises");
    if let Some(r) = reason {
        v["reason"] = r.into();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [Status; 10] = [
        Status::ClosedForm,
        Status::Solved,
        Status::AlmostSolved,
        Status::Converged,
        Status::IterationLimit,
        Status::Stalled,
        Status::Infeasible,
        Status::Unbounded,
        Status::NumericalError,
        Status::Failed,
    ];

    fn targets() -> Targets {
        Targets {
            max_torque: Some(2.0),
            no_load_speed: None,
            max_speed: Some(10.0),
            max_bend_deg: Some(90.0),
            geometric_bend_deg: None,
            flip_tolerance: 0.01,
            landing_tolerance: None,
            judge_flip: true,
            envelope_keys: "limits.max_torque, limits.max_speed".into(),
            limits_from: Default::default(),
        }
    }

    fn design(status: Status) -> DesignNumbers {
        DesignNumbers {
            status,
            peak_torque_nm: 1.0,
            bend_deg: 45.0,
            max_speed_rad_s: Some(5.0),
            envelope_margin: Some(0.5),
            line_margin: None,
        }
    }

    const FLIPS: Simulated = Simulated::Flip {
        flip_error_rad: 1e-4,
        tilt_deg: 1e-3,
    };

    #[test]
    fn every_status_has_its_serialised_name_and_predicates() {
        for s in ALL {
            let json = serde_json::to_value(s).unwrap();
            assert_eq!(json, s.name(), "{s:?}");
            let proven = matches!(s, Status::ClosedForm | Status::Solved | Status::Converged);
            assert_eq!(s.is_proven(), proven, "{s:?}");
            assert_eq!(s.is_usable(), s != Status::Failed, "{s:?}");
            // only a proven status leaves a design that meets its targets unflagged
            let v = verdict(&targets(), &design(s), &FLIPS);
            assert_eq!(v.is_ok(), proven, "{s:?}");
            assert!(v.flips(), "{s:?}");
            if !proven {
                assert_eq!(v.reason().unwrap(), format!("solver status {}", s.name()));
            }
        }
    }

    #[test]
    fn the_solver_statuses_map_onto_one_status() {
        use crate::design::conic::SolveStatus as C;
        use crate::design::scp::ScpStatus as S;
        for (c, s) in [
            (C::Solved, Status::Solved),
            (C::AlmostSolved, Status::AlmostSolved),
            (C::Infeasible, Status::Infeasible),
            (C::Unbounded, Status::Unbounded),
            (C::IterationLimit, Status::IterationLimit),
            (C::NumericalError, Status::NumericalError),
        ] {
            assert_eq!(Status::from(c), s);
            // the same name as the solver's own serialisation
            assert_eq!(serde_json::to_value(c).unwrap(), s.name());
        }
        for (c, s) in [
            (S::Converged, Status::Converged),
            (S::IterationLimit, Status::IterationLimit),
            (S::Stalled, Status::Stalled),
            (S::Infeasible, Status::Infeasible),
        ] {
            assert_eq!(Status::from(c), s);
            assert_eq!(serde_json::to_value(c).unwrap(), s.name());
        }
    }

    /// Each limit and flip case, just inside and just outside its tolerance
    /// (`k` is 1 - 1e-3 or 1 + 1e-3 of the tolerance band's edge).
    #[test]
    fn each_target_is_judged_at_its_tolerance() {
        fn limit(x: f64, k: f64) -> f64 {
            x * (1.0 + tolerance::LIMIT * k)
        }
        type Set = fn(&mut DesignNumbers, &mut Simulated, f64);
        let cases: [(&str, Set, &str); 6] = [
            (
                "torque",
                |d, _, k| d.peak_torque_nm = limit(2.0, k),
                "above limits.max_torque",
            ),
            (
                "speed",
                |d, _, k| d.max_speed_rad_s = Some(limit(10.0, k)),
                "above limits.max_speed",
            ),
            (
                "bend",
                |d, _, k| d.bend_deg = limit(90.0, k),
                "above limits.max_bend_deg",
            ),
            (
                "envelope",
                |d, _, k| d.envelope_margin = Some(-tolerance::ENVELOPE_MARGIN * k),
                "leaves the motor envelope",
            ),
            (
                "flip",
                |_, s, k| {
                    *s = Simulated::Flip {
                        flip_error_rad: 0.01 * (1.0 + 1e-3 * (k - 1.0)),
                        tilt_deg: 0.0,
                    }
                },
                "misses the flip",
            ),
            (
                "tilt",
                |_, s, k| {
                    *s = Simulated::Flip {
                        flip_error_rad: 0.0,
                        tilt_deg: 0.01f64.to_degrees() * (1.0 + 1e-3 * (k - 1.0)),
                    }
                },
                "tilts the spine",
            ),
        ];
        for (name, set, why) in cases {
            for (k, breaks) in [(1.0 - 1e-3, false), (1.0 + 1e-3, true)] {
                let (mut d, mut s) = (design(Status::Solved), FLIPS);
                set(&mut d, &mut s, k);
                let v = verdict(&targets(), &d, &s);
                assert_eq!(v.is_ok(), !breaks, "{name} at {k}: {v:?}");
                let grade = if breaks { Grade::Flagged } else { Grade::Ok };
                assert_eq!(v.grade(), grade, "{name}");
                if breaks {
                    let r = v.reason().unwrap();
                    assert!(r.contains(why), "{name}: {r}");
                    assert_eq!(v.misses.len(), 1, "{name}: {r}");
                    assert_eq!(v.flips(), !matches!(name, "flip" | "tilt"), "{name}");
                    assert_eq!(v.within_envelope(), name != "envelope", "{name}");
                    assert_eq!(v.misses[0].is_limit(), v.flips(), "{name}");
                }
            }
        }
    }

    #[test]
    fn nan_numbers_and_failures_are_misses() {
        let nan = Simulated::Flip {
            flip_error_rad: f64::NAN,
            tilt_deg: f64::NAN,
        };
        let v = verdict(&targets(), &design(Status::Converged), &nan);
        assert_eq!(v.misses.len(), 2);
        assert!(!v.flips());
        let mut d = design(Status::Converged);
        d.envelope_margin = Some(f64::NAN);
        assert!(!verdict(&targets(), &d, &FLIPS).within_envelope());
        // a failed simulation is the only reason given
        let failed = Simulated::Failed("the motion diverged".into());
        let v = verdict(&targets(), &design(Status::IterationLimit), &failed);
        assert_eq!(v.grade(), Grade::Flagged);
        assert_eq!(v.reason().as_deref(), Some("the motion diverged"));
        // no design at all
        let v = Verdict::failed("no twist angle flips the cat");
        assert_eq!((v.grade(), v.status), (Grade::Failed, Status::Failed));
        assert!(!v.status.is_usable());
    }

    #[test]
    fn a_torque_speed_line_judges_the_torque_by_the_envelope() {
        let mut t = targets();
        t.no_load_speed = Some(6.0);
        let mut d = design(Status::Solved);
        d.peak_torque_nm = 3.0; // a braking torque above the stall torque
        assert!(verdict(&t, &d, &FLIPS).is_ok());
        d.envelope_margin = Some(-0.1);
        let v = verdict(&t, &d, &FLIPS);
        assert_eq!(v.reasons().len(), 1);
        assert!(v.reasons()[0].contains("leaves the motor envelope"));
        // without the line the torque names the miss, and the envelope is not repeated
        t.no_load_speed = None;
        let v = verdict(&t, &d, &FLIPS);
        assert_eq!(v.reasons().len(), 1, "{:?}", v.reasons());
        assert!(v.reasons()[0].contains("above limits.max_torque"));
        assert!(!v.within_envelope());
        // above the speed limit: the envelope is named only where its margin
        // is below the speed's (the line broken too)
        t.no_load_speed = Some(6.0);
        d.max_speed_rad_s = Some(15.0); // the speed's margin: 1 - 15 / 10 = -0.5
        for (margin, named) in [(-0.5, false), (-0.5 - 1e-3, true), (-7.9, true)] {
            d.envelope_margin = Some(margin);
            let why = verdict(&t, &d, &FLIPS).reasons();
            assert!(why[0].contains("above limits.max_speed"), "{why:?}");
            assert_eq!(why.len(), 1 + usize::from(named), "{margin}: {why:?}");
            assert_eq!(
                why.iter().any(|w| w.contains("leaves the motor envelope")),
                named,
                "{margin}: {why:?}"
            );
        }
        // where the line's own margin is known, it decides: broken less than
        // the speed limit, the line is still named, with its margin
        d.envelope_margin = Some(-0.5);
        for (line, named) in [(0.2, false), (-1e-7, false), (-0.3, true)] {
            d.line_margin = Some(line);
            let why = verdict(&t, &d, &FLIPS).reasons();
            assert!(why[0].contains("above limits.max_speed"), "{why:?}");
            assert_eq!(why.len(), 1 + usize::from(named), "{line}: {why:?}");
            if named {
                assert!(why[1].contains("smallest margin -0.300"), "{why:?}");
            }
        }
    }

    /// From another start the landing is judged at its tolerance and the flip is not.
    #[test]
    fn the_landing_is_judged_from_another_start() {
        let t = Targets {
            landing_tolerance: Some((0.5, "land.max_tilt_deg")),
            judge_flip: false,
            ..targets()
        };
        let land = |e: f64| Simulated::Landing {
            flip_error_rad: 1.0,
            tilt_deg: 30.0,
            landing_error_deg: e,
        };
        assert!(verdict(&t, &design(Status::Converged), &land(0.4999)).is_ok());
        for e in [0.5001, f64::NAN] {
            let v = verdict(&t, &design(Status::Converged), &land(e));
            assert!(!v.flips(), "{e}");
            assert!(
                v.reason().unwrap().contains("land.max_tilt_deg"),
                "{:?}",
                v.reason()
            );
        }
        // today's start: the flip decides, the landing only when a tolerance is set
        let today = Targets {
            judge_flip: true,
            landing_tolerance: None,
            ..targets()
        };
        assert!(!verdict(&today, &design(Status::Converged), &land(0.1)).flips());
    }

    /// Without a bend limit a design past the bend at which the cylinders
    /// meet is flagged (the seed's: 168.46 deg, the config's own check);
    /// with a limit, the limit judges alone.
    #[test]
    fn a_bend_through_the_body_is_flagged_without_a_limit() {
        let seed =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml"))
                .unwrap();
        let spec = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            crate::test_support::spec_of(&seed, "seed.toml", &sets)
        };
        let t = Targets::of(&spec(&[]));
        let g = t.geometric_bend_deg.unwrap();
        assert!((g - 168.46).abs() < 0.005, "{g}");
        let mut d = design(Status::Converged);
        d.bend_deg = 168.0;
        assert!(limit_misses(&t, &d).is_empty());
        d.bend_deg = 175.86;
        let why: Vec<String> = limit_misses(&t, &d).iter().map(|m| m.to_string()).collect();
        assert_eq!(why.len(), 1, "{why:?}");
        assert_eq!(
            why[0],
            "bends 175.86 deg, past the 168.46 deg where this cat's halves meet; \
             set limits.max_bend_deg to keep the designs inside it"
        );
        let limited = Targets::of(&spec(&["limits.max_bend_deg=160"]));
        assert_eq!(limited.geometric_bend_deg, None);
        assert_eq!(limit_misses(&limited, &d).len(), 1);
    }

    /// A simulation's report is judged by its landing where the targets ask
    /// for it (`sweep` and `simulate` judged the flip and tilt alone, and
    /// flagged a design from a spinning start that `run` found landing).
    #[test]
    fn a_report_is_judged_by_its_landing_from_another_start() {
        let report = crate::verify::simulate::SimReport {
            flip_error_rad: 1e-8,
            tilt_deg: 44.5,
            landing_error_deg: 1e-6,
            ..crate::verify::simulate::SimReport::failed()
        };
        let from_a_start = Targets {
            landing_tolerance: Some((0.5, "land.max_tilt_deg")),
            judge_flip: false,
            ..targets()
        };
        let sim = Simulated::of(Ok(&report));
        assert_eq!(flight_reason(&from_a_start, &sim), None);
        let missed = crate::verify::simulate::SimReport {
            landing_error_deg: 3.0,
            ..report.clone()
        };
        let why = flight_reason(&from_a_start, &Simulated::of(Ok(&missed))).unwrap();
        assert!(
            why.contains("land.max_tilt_deg") && !why.contains("tilts"),
            "{why}"
        );
        // at today's start the tilt is the flip's, judged as before
        let why = flight_reason(&targets(), &sim).unwrap();
        assert!(why.contains("tilts the spine"), "{why}");
    }
}
