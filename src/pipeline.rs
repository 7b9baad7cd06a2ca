//! The per-method stage every command shares: a method's design is sampled
//! as the schedule that is written, simulated (designs do not fly
//! themselves), judged by [`crate::verdict`], and turned into its summary
//! line, its files, its figure curves and its animation track.
//! `run` passes each method through [`stage`]; `optimize` passes its one
//! design; `sweep` judges its points with [`judge`] (peaks only, no files).

use crate::design::free::FreeResult;
use crate::design::phased::PhasedResult;
use crate::design::plan::{Schedule, ShapePlan};
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};
use crate::output::Output;
use crate::report::MethodTrace;
use crate::report::animation::Track;
use crate::verdict::{DesignNumbers, Grade, Miss, Simulated, Status, Targets, Verdict, verdict};
use crate::verify::analyze::Analysis;
use crate::verify::simulate::{SimReport, dynamic_spec, kinematic_spec};
use serde::Serialize;

/// The design methods, in the order every table lists them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The seed's closed-form cosine schedule.
    Analytic,
    /// The certified fold / twist / unfold optimum.
    Phased,
    /// Collocation and successive convexification.
    Free,
    /// The robot answer's schedule: the shortest manoeuvre found inside the
    /// motor envelope, flown from the least drop height it needs.
    LeastHeight,
}

impl Method {
    /// The design methods a sweep or `optimize` can ask for.
    pub const ALL: [Method; 3] = [Method::Analytic, Method::Phased, Method::Free];

    /// The name of its files (`phased.csv`) and table rows.
    pub fn name(self) -> &'static str {
        match self {
            Method::Analytic => "analytic",
            Method::Phased => "phased",
            Method::Free => "free",
            Method::LeastHeight => "least-height",
        }
    }
}

/// The least-height answer's schedule as a method: the rows of
/// `least-height.csv` (a plan itself), the status of the time design that
/// made it, and the drop height it needs.
#[derive(Debug, Clone, Serialize)]
pub struct LeastHeightDesign {
    #[serde(skip)]
    pub schedule: Schedule,
    pub status: Status,
    /// The least drop height found, m.
    pub height_m: f64,
    /// Which time design it is (`phased` or `free`).
    pub design: &'static str,
    /// Peak joint torque over the rows, N m (the config's norm).
    pub peak_torque_nm: f64,
    /// Largest bend, deg, and twist of the bend direction, rad, over the rows.
    pub bend_deg: f64,
    pub twist_rad: f64,
    /// Whether it was designed from the configured start (else for the
    /// start at rest, as the phased time design is).
    #[serde(skip)]
    pub from_start: bool,
}

impl LeastHeightDesign {
    /// The answer's schedule, its numbers read off its rows.
    pub fn of(
        spec: &DesignSpec,
        a: &crate::design::least_height::HeightAnswer,
    ) -> LeastHeightDesign {
        let norm = spec.norm();
        let rows = &a.schedule.rows;
        let peak = rows.iter().map(|r| norm.of(r.tau)).fold(0.0, f64::max);
        let (mut bend, mut twist, mut last_phi) = (0.0f64, 0.0, None::<f64>);
        for r in rows {
            let b = r.q[0].hypot(r.q[1]);
            bend = bend.max(b);
            // the bend direction is defined away from straight (as the free-form design's)
            if b > 1e-3 {
                let phi = r.q[1].atan2(r.q[0]);
                if let Some(l) = last_phi {
                    twist += crate::model::so3::wrap(phi - l);
                }
                last_phi = Some(phi);
            }
        }
        LeastHeightDesign {
            schedule: a.schedule.clone(),
            status: a.status,
            height_m: a.least_height_m,
            design: a.method,
            peak_torque_nm: peak,
            bend_deg: bend.to_degrees(),
            twist_rad: twist,
            from_start: a.from_start,
        }
    }
}

/// A method's design, whatever made it (one per method and run: the
/// variants' sizes do not matter, so they are not boxed).
#[allow(clippy::large_enum_variant)]
pub enum Design {
    Analytic(Analysis),
    Phased(PhasedResult),
    Free(FreeResult),
    LeastHeight(LeastHeightDesign),
}

impl Design {
    pub fn method(&self) -> Method {
        match self {
            Design::Analytic(_) => Method::Analytic,
            Design::Phased(_) => Method::Phased,
            Design::Free(_) => Method::Free,
            Design::LeastHeight(_) => Method::LeastHeight,
        }
    }

    pub fn plan(&self) -> &dyn ShapePlan {
        match self {
            Design::Analytic(a) => &a.plan,
            Design::Phased(p) => &p.plan,
            Design::Free(f) => &f.plan,
            Design::LeastHeight(l) => &l.schedule,
        }
    }

    pub fn status(&self) -> Status {
        match self {
            Design::Analytic(_) => Status::ClosedForm,
            Design::Phased(p) => p.status.into(),
            Design::Free(f) => f.status.into(),
            Design::LeastHeight(l) => l.status,
        }
    }

    /// Dense peak joint torque of the schedule, N m.
    pub fn peak_torque_nm(&self) -> f64 {
        match self {
            Design::Analytic(a) => a.peak_torque_nm,
            Design::Phased(p) => p.peak_torque_nm,
            Design::Free(f) => f.peak_torque_nm,
            Design::LeastHeight(l) => l.peak_torque_nm,
        }
    }

    /// Largest bend (deg), twist of the bend direction (rad), phase durations (s).
    pub fn path_numbers(&self) -> (f64, f64, [f64; 3]) {
        match self {
            Design::Analytic(a) => (
                a.closed.bend_deg,
                a.closed.twist_rad,
                a.closed.phase_durations_s,
            ),
            Design::Phased(p) => (p.bend_deg, p.twist_rad, p.phase_durations_s),
            Design::Free(f) => (f.bend_deg, f.twist_rad, f.phase_durations_s),
            Design::LeastHeight(l) => {
                let b = l.schedule.phase_bounds();
                (l.bend_deg, l.twist_rad, [0, 1, 2].map(|i| b[i + 1] - b[i]))
            }
        }
    }
}

/// The verdict on a design with this status, dense peak and largest bend
/// (deg), written as `schedule` (the motor usage of its rows; `None`: not
/// judged on speed and envelope) and simulated as `simulated`.
pub fn judge(
    spec: &DesignSpec,
    status: Status,
    (peak_torque_nm, bend_deg): (f64, f64),
    schedule: Option<&Schedule>,
    simulated: &Simulated,
) -> Verdict {
    let motor = schedule.map(|s| usage(spec, s));
    verdict(
        &Targets::of(spec),
        &DesignNumbers {
            status,
            peak_torque_nm,
            bend_deg,
            max_speed_rad_s: motor.map(|m| m.max_speed_rad_s),
            envelope_margin: motor.and_then(|m| m.min_margin),
            line_margin: motor.and_then(|m| m.min_line_margin),
        },
        simulated,
    )
}

/// The seed's analytic schedule as written, and its verdict (closed form;
/// the flip from the analysis's kinematic simulation).
pub fn judge_analysis(spec: &DesignSpec, a: &Analysis) -> (Schedule, Verdict) {
    let schedule = crate::verify::analyze::analytic_schedule(spec, &a.plan);
    let mut v = judge(
        spec,
        Status::ClosedForm,
        (a.peak_torque_nm, a.closed.bend_deg),
        Some(&schedule),
        &Simulated::Landing {
            flip_error_rad: a.flip_error_rad,
            tilt_deg: a.tilt_deg,
            landing_error_deg: a.landing_error_deg,
        },
    );
    unfolded(&mut v);
    (schedule, v)
}

/// Whether a line from another start is made for the start at rest (the
/// analytic schedule, the phased design, a least-height design not made
/// from the start: `least_height_at_rest`) and misses nothing but the landing (a number:
/// a flight that diverged counts), beside the analytic reference's limits
/// (the phased designs are made for the motors: a broken limit counts).
fn made_for_rest_misses_only_the_landing(
    method: Method,
    least_height_at_rest: bool,
    misses: &[Miss],
) -> bool {
    let at_rest = match method {
        Method::Analytic | Method::Phased => true,
        Method::LeastHeight => least_height_at_rest,
        Method::Free => false,
    };
    at_rest
        && !misses.is_empty()
        && misses.iter().all(|m| match m {
            Miss::Landing { error_deg, .. } => error_deg.is_finite(),
            m => method == Method::Analytic && m.is_limit(),
        })
}

/// The analytic schedule's verdict without a fold through the halves: the
/// seed's schedule is the model's mathematics whatever the body (the fold
/// is the config's warning, `analytic.theta_deg`).
fn unfolded(v: &mut Verdict) {
    v.misses.retain(|m| !matches!(m, Miss::Folds { .. }));
}

/// How the motors are used by a written schedule's rows.
fn usage(spec: &DesignSpec, schedule: &Schedule) -> crate::model::motor::MotorUse {
    spec.motor
        .usage(schedule.rows.iter().map(|r| (r.tau, r.qd)))
}

/// A design through the stage: its schedule, simulation, verdict and line.
pub struct Judged {
    pub design: Design,
    pub schedule: Schedule,
    /// The dynamic simulation, or why it failed (the design is then kept,
    /// flagged, with NaN simulation numbers).
    pub sim: Result<SimReport>,
    pub verdict: Verdict,
    pub summary: MethodSummary,
}

/// The stage: sample, simulate, judge, summarise. `solve_time_s` is the
/// method's time (the analytic design's includes its simulation).
pub fn stage(spec: &DesignSpec, design: Design, solve_time_s: f64) -> Judged {
    let schedule = match &design {
        // already rows: written as they are
        Design::LeastHeight(l) => l.schedule.clone(),
        _ => Schedule::sample(&spec.cat, design.plan(), spec.simulate.samples_per_phase),
    };
    let sim = dynamic_spec(spec, design.plan());
    let method = design.method();
    let (bend, twist, durations) = design.path_numbers();
    let peak = design.peak_torque_nm();
    let failed_sim = SimReport::failed();
    let s = sim.as_ref().unwrap_or(&failed_sim);
    let motor = usage(spec, &schedule);
    let n = MethodNumbers {
        peak_torque_nm: peak,
        bend_deg: bend,
        theta_deg: 180.0 - bend,
        twist_rad: twist,
        phase_durations_s: durations,
        flight: Flight::of(s),
        final_shape_error_rad: s.final_shape_error_rad,
        max_speed_rad_s: motor.max_speed_rad_s,
        min_envelope_margin: motor.min_margin,
        energy_n2m2s: schedule.torque_squared_integral(),
        solve_time_s,
        schedule_csv: format!("{}.csv", method.name()),
        schedule_json: format!("{}.schedule.json", method.name()),
    };
    let mut verdict = judge(
        spec,
        design.status(),
        (peak, bend),
        Some(&schedule),
        &match &sim {
            Ok(s) => Simulated::Landing {
                flip_error_rad: s.flip_error_rad,
                tilt_deg: s.tilt_deg,
                landing_error_deg: s.landing_error_deg,
            },
            Err(e) => Simulated::Failed(e.to_string()),
        },
    );
    if method == Method::Analytic {
        unfolded(&mut verdict);
    }
    let summary = MethodSummary {
        method: method.name(),
        status: design.status(),
        verdict: verdict.grade(),
        reason: verdict.reason(),
        beyond_the_motors: method == Method::Analytic && verdict.misses.iter().any(Miss::is_limit),
        approximate_for_the_joint: method == Method::Analytic
            && (spec.cat.joint == crate::model::Joint::Universal || !spec.cat.is_symmetric())
            && !verdict.misses.is_empty()
            && verdict
                .misses
                .iter()
                .all(|m| matches!(m, Miss::Flip { .. } | Miss::Tilt { .. }) || m.is_limit()),
        unequal_halves: spec.cat.joint == crate::model::Joint::NoTwist && !spec.cat.is_symmetric(),
        for_the_start_at_rest: !spec.is_default_start()
            && made_for_rest_misses_only_the_landing(
                method,
                matches!(&design, Design::LeastHeight(l) if !l.from_start),
                &verdict.misses,
            ),
        result: Some(n),
    };
    Judged {
        design,
        schedule,
        sim,
        verdict,
        summary,
    }
}

impl Judged {
    /// The simulation, or the NaN report of a failed one.
    fn sim_or_failed(&self) -> std::borrow::Cow<'_, SimReport> {
        match &self.sim {
            Ok(s) => std::borrow::Cow::Borrowed(s),
            Err(_) => std::borrow::Cow::Owned(SimReport::failed()),
        }
    }

    /// The design's JSON (`optimize`'s `<method>.json`, the Python
    /// `Design.json`): its own numbers, and for an optimised design how it
    /// flew ([`Flown`]). A failed simulation is the error (the flight's own:
    /// it is flown again to return it), and so is a number of
    /// [`DESIGN_FINITE`] that is not finite (refused, not written as null).
    pub fn design_json(&self, spec: &DesignSpec) -> Result<serde_json::Value> {
        let mut json = match &self.design {
            Design::Phased(r) => serde_json::to_value(r),
            Design::Free(r) => serde_json::to_value(r),
            Design::Analytic(a) => serde_json::to_value(a),
            Design::LeastHeight(l) => serde_json::to_value(l),
        }
        .map_err(|e| Error::Report(e.to_string()))?;
        if let Design::Phased(_) | Design::Free(_) = self.design {
            let Ok(sim) = &self.sim else {
                return Err(dynamic_spec(spec, self.design.plan())
                    .err()
                    .unwrap_or_else(|| Error::Simulation("the flight failed".into())));
            };
            // the planned shape flown exactly, as the free-form design reported it
            let kin = match self.design {
                Design::Free(_) => Some(kinematic_spec(spec, self.design.plan())?),
                _ => None,
            };
            let flown = serde_json::to_value(Flown::of(sim, kin.as_ref()))
                .map_err(|e| Error::Report(e.to_string()))?;
            if let (serde_json::Value::Object(j), serde_json::Value::Object(f)) = (&mut json, flown)
            {
                j.extend(f);
                if let Some(h) = least_height_of_time_design(spec, self.design.plan().duration()) {
                    j.insert("least_height_m".into(), h.into());
                }
                // the written rows' motor use, as `run`'s summary gives it
                let motor = usage(spec, &self.schedule);
                j.insert("max_speed_rad_s".into(), motor.max_speed_rad_s.into());
                if let Some(m) = motor.min_margin {
                    j.insert("min_envelope_margin".into(), m.into());
                }
            }
            crate::output::ensure_finite(&json, &DESIGN_FINITE)?;
        }
        Ok(json)
    }

    /// `<method>.csv` and `<method>.schedule.json`.
    pub fn add_files(&self, out: &mut Output) {
        self.schedule.add_to(out, self.design.method().name());
    }

    /// Curves for the figures, `per_phase` samples a phase.
    pub fn trace(&self, spec: &DesignSpec, per_phase: usize) -> MethodTrace {
        trace(
            spec,
            self.design.method().name(),
            self.design.plan(),
            self.design.peak_torque_nm(),
            &self.sim_or_failed(),
            per_phase,
        )
    }

    /// The animation's track.
    pub fn track(&self, spec: &DesignSpec) -> Track {
        crate::report::animation::track(
            &spec.cat,
            spec.norm(),
            self.design.method().name(),
            &self.sim_or_failed(),
            (crate::report::animation::FRAMES, spec.fall.margin),
        )
    }
}

/// Curves of one method for the figures; `peak` is its dense peak torque,
/// the table's (the curve's samples may fall just short of it).
pub fn trace(
    spec: &DesignSpec,
    name: &str,
    plan: &dyn ShapePlan,
    peak: f64,
    sim: &SimReport,
    per_phase: usize,
) -> MethodTrace {
    let cat = &spec.cat;
    let norm = spec.norm();
    let b = plan.phase_bounds();
    let (mut t, mut q, mut tau) = (Vec::new(), Vec::new(), Vec::new());
    let (mut qd, mut tau_xy) = (Vec::new(), Vec::new());
    // the dense peak's own instant among the samples: evenly spaced ones
    // can straddle a narrow spike (a least-height design's 1.685 N m was
    // drawn and circled at 1.596)
    let (pi, pt) = crate::verify::analyze::peak_instant(
        spec,
        plan,
        crate::verify::analyze::dense_samples(spec),
    );
    for i in 0..3 {
        let mut times: Vec<f64> = (0..=per_phase)
            .map(|k| b[i] + (b[i + 1] - b[i]) * k as f64 / per_phase as f64)
            .collect();
        if i == pi && !times.contains(&pt) {
            let at = times.partition_point(|&x| x < pt);
            times.insert(at, pt);
        }
        for tt in times {
            t.push(tt);
            let s = plan.state_in(i, tt);
            q.push(s.q);
            qd.push(s.qd);
            let v = plan.torque_in(cat, i, tt);
            tau.push(norm.of(v));
            tau_xy.push(v);
        }
    }
    MethodTrace {
        name: name.into(),
        t,
        q,
        tau,
        qd,
        tau_xy,
        peak_nm: peak,
        over_limit: Targets::of(spec).over_torque(peak),
        phase_bounds: b,
        flip_t: sim.trace.iter().map(|p| p.t).collect(),
        flip_deg: sim.trace.iter().map(|p| p.flip.to_degrees()).collect(),
    }
}

/// The numbers of an optimised design's JSON that must be finite.
pub const DESIGN_FINITE: [&str; 6] = [
    "peak_torque_nm",
    "bend_deg",
    "flip_deg",
    "tilt_deg",
    "sim_peak_torque_nm",
    "phase_durations_s",
];

/// A schedule's flight under the motor model (the dynamic simulation:
/// feed-forward + PD, torque limit if any), as the JSON gives it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Flight {
    pub flip_deg: f64,
    pub flip_error_rad: f64,
    pub tilt_deg: f64,
    /// The belly's angle from straight down at touchdown (docs/model.md section 8), deg.
    pub landing_error_deg: f64,
    pub sim_peak_torque_nm: f64,
    pub momentum_drift_nms: f64,
}

impl Flight {
    pub fn of(sim: &SimReport) -> Flight {
        Flight {
            flip_deg: sim.flip_deg,
            flip_error_rad: sim.flip_error_rad,
            tilt_deg: sim.tilt_deg,
            landing_error_deg: sim.landing_error_deg,
            sim_peak_torque_nm: sim.peak_torque_nm,
            momentum_drift_nms: sim.momentum_drift_nms,
        }
    }
}

/// How an optimised design flew, as its `<method>.json` gives it beside
/// the design's own numbers.
#[derive(Debug, Clone, Serialize)]
pub struct Flown {
    #[serde(flatten)]
    pub flight: Flight,
    /// From the kinematic simulation of the planned shape (free-form
    /// designs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kinematic_flip_error_rad: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kinematic_tilt_deg: Option<f64>,
}

impl Flown {
    /// The numbers of the dynamic `sim` and the kinematic `kin` simulations.
    pub fn of(sim: &SimReport, kin: Option<&SimReport>) -> Flown {
        Flown {
            flight: Flight::of(sim),
            kinematic_flip_error_rad: kin.map(|k| k.flip_error_rad),
            kinematic_tilt_deg: kin.map(|k| k.tilt_deg),
        }
    }
}

/// One method's line of the summary.
#[derive(Debug, Clone, Serialize)]
pub struct MethodSummary {
    pub method: &'static str,
    /// Solver status (`closed-form`, `solved`, `converged`, ...), `failed`,
    /// or `not-attempted` (the motors cannot do it in this fall).
    pub status: Status,
    pub verdict: Grade,
    /// Why the method is flagged, failed or impossible (absent when ok).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The seed's analytic schedule is a reference, not a design for these
    /// motors: when it breaks their limits it is flagged and reported, but
    /// does not make the run partial (present, `true`, only then).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub beyond_the_motors: bool,
    /// Nor is it exact under the universal joint: there it misses the flip
    /// and tilts (F4, MODEL.md); reported, but no reason for a partial run
    /// (present, `true`, only when that is all it misses beside the limits).
    /// Also true for a no-twist cat of unequal halves, where the closed
    /// forms (F1, F6) are not exact either.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub approximate_for_the_joint: bool,
    /// Whether the body is a no-twist cat of unequal halves (which closed
    /// form is approximate, for the words).
    #[serde(skip)]
    pub unequal_halves: bool,
    /// Nor is it, or the phased design, made for another start: from one
    /// they miss the landing by what the start leaves (the free-form design
    /// is made for it); reported, but no reason for a partial run (present,
    /// `true`, only when that is all they miss, beside the analytic's limits).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub for_the_start_at_rest: bool,
    /// The numbers, absent when the method failed.
    #[serde(flatten)]
    pub result: Option<MethodNumbers>,
}

/// The numbers of a method that produced a schedule.
#[derive(Debug, Clone, Serialize)]
pub struct MethodNumbers {
    /// Peak joint torque of the schedule (inverse dynamics, dense), N m.
    pub peak_torque_nm: f64,
    pub bend_deg: f64,
    pub theta_deg: f64,
    pub twist_rad: f64,
    pub phase_durations_s: [f64; 3],
    #[serde(flatten)]
    pub flight: Flight,
    pub final_shape_error_rad: f64,
    /// Largest joint speed of the written schedule, rad/s (motor norm).
    pub max_speed_rad_s: f64,
    /// Smallest motor-envelope margin over the written rows (1 unused, 0 on
    /// the envelope, negative violated; absent without limits).
    pub min_envelope_margin: Option<f64>,
    /// `integral |tau|^2 dt` over the written rows, N^2 m^2 s (the energy
    /// objective; the peak and the durations give the other two).
    pub energy_n2m2s: f64,
    pub solve_time_s: f64,
    pub schedule_csv: String,
    pub schedule_json: String,
}

impl MethodSummary {
    /// The line of a method that produced no design.
    pub fn failed(method: Method, e: &Error) -> MethodSummary {
        MethodSummary {
            method: method.name(),
            status: Status::Failed,
            verdict: Grade::Failed,
            reason: Some(e.to_string()),
            beyond_the_motors: false,
            approximate_for_the_joint: false,
            unequal_halves: false,
            for_the_start_at_rest: false,
            result: None,
        }
    }

    /// The line of a method not attempted because the motors cannot do it
    /// in this fall; `why` says what height it needs.
    pub fn impossible(method: Method, why: &str) -> MethodSummary {
        MethodSummary {
            method: method.name(),
            status: Status::NotAttempted,
            verdict: Grade::Impossible,
            reason: Some(why.to_string()),
            beyond_the_motors: false,
            approximate_for_the_joint: false,
            unequal_halves: false,
            for_the_start_at_rest: false,
            result: None,
        }
    }

    /// Whether this line makes a run partial: flagged or failed, unless it
    /// is the reference beyond the motors or approximate for the joint.
    pub fn counts_against(&self) -> bool {
        match self.verdict {
            Grade::Ok => false,
            Grade::Flagged => self.reference_note().is_none(),
            Grade::Failed | Grade::Impossible => true,
        }
    }

    /// Why a flagged reference is not counted, in words (None for a design).
    pub fn reference_note(&self) -> Option<&'static str> {
        if self.beyond_the_motors && self.for_the_start_at_rest {
            Some("a reference beyond the motors, made for the start at rest, not counted")
        } else if self.beyond_the_motors && self.approximate_for_the_joint && self.unequal_halves {
            Some(
                "a reference beyond the motors, and the seed's closed form, exact only for identical halves (F1, F6): not counted",
            )
        } else if self.beyond_the_motors && self.approximate_for_the_joint {
            Some(
                "a reference beyond the motors, and the seed's closed form, approximate for the universal joint (F4): not counted",
            )
        } else if self.beyond_the_motors {
            Some("a reference beyond the motors, not counted")
        } else if self.approximate_for_the_joint && self.unequal_halves {
            Some("the seed's closed form, exact only for identical halves (F1, F6), not counted")
        } else if self.approximate_for_the_joint {
            Some("the seed's closed form, approximate for the universal joint (F4), not counted")
        } else if self.for_the_start_at_rest {
            Some("made for the start at rest, not counted")
        } else {
            None
        }
    }

    pub fn peak(&self) -> Option<f64> {
        self.result.as_ref().map(|r| r.peak_torque_nm)
    }
}

/// Where a free-form design starts when no seed is named (`optimize`, the
/// Python package, `recovery`'s design at rest): the
/// phased design; where no phased schedule fits the motors in this fall,
/// the least-height answer's shortest manoeuvre (`free least-time`, as
/// `run` seeds it); the analytic schedule where neither exists. When that
/// answer is that no schedule found fits this fall, it is the error
/// ([`Error::BeyondMotors`], naming the least drop height, [`beyond_reach`]),
/// as `run` does not attempt the design either: the SCP would only end
/// locally infeasible after many iterations. A phased seed the landing
/// rules out is [`Error::SeedUnfit`]. Unlike `run`, the phased seed is not
/// checked against a torque limit without a torque-speed line
/// ([`crate::design::phased::seed_plan`]): the free-form design meets the
/// limit or says from what height it would (F7). `note` is told, in words,
/// when the least height is sought and which start was taken.
pub fn free_start(spec: &DesignSpec, mut note: impl FnMut(&str)) -> Result<FreeStart> {
    use crate::design::free::Seed;
    let start = |plan, name| FreeStart {
        plan,
        name,
        least_height_m: None,
        design: None,
    };
    let phased = || match Seed::Phased.plan(spec) {
        Ok(plan) => Ok(Some(start(plan, Seed::Phased.name()))),
        Err(Error::BeyondMotors { .. }) => Ok(None),
        Err(Error::Unreachable { reason }) => Err(Error::SeedUnfit { reason }),
        Err(e) => Err(e),
    };
    // the least time is the least-height stage's own question (asked, as
    // in `run`, where the motors are limited)
    let time =
        spec.objective == crate::design::objective::Objective::Time && spec.motor.is_limited();
    if time {
        note(
            "a least-time design: finding the least drop height first, as `catflip run` does (its shortest manoeuvre answers the same question)",
        );
    } else {
        if let Some(s) = phased()? {
            return Ok(s);
        }
        note(
            "no phased schedule fits the motors in this fall: finding the least drop height first, as `catflip run` does",
        );
    }
    // (the least height failing leaves the analytic seed, as in `run`)
    if let Ok(Some(h)) = crate::design::least_height::heights(
        spec,
        crate::design::least_height::Families::Both,
        |_| {},
    ) {
        // (a least time answers "from what height", not "in this fall")
        if let Some(e) = out_of_reach(&h.answer).filter(|_| !time) {
            return Err(e);
        }
        let a = &h.answer;
        if let Some(fr) = h.free {
            note(&format!(
                "the least drop height found is {:.3} m; the free-form design starts from the shortest free-form manoeuvre found ({:.4} s)",
                a.least_height_m, fr.manoeuvre_time_s
            ));
            return Ok(FreeStart {
                plan: Box::new(fr.plan.clone()),
                name: FREE_LEAST_TIME,
                least_height_m: a.possible.then_some(a.least_height_m),
                design: time.then_some(fr),
            });
        }
    }
    if time && let Some(s) = phased()? {
        note("the free-form design starts from the phased design");
        return Ok(s);
    }
    note("the free-form design starts from the analytic schedule");
    Ok(start(Seed::Analytic.plan(spec)?, Seed::Analytic.name()))
}

/// Where a free-form design starts ([`free_start`]).
pub struct FreeStart {
    pub plan: Box<dyn ShapePlan>,
    /// The start's name in the result ([`FREE_LEAST_TIME`] for the
    /// least-height design).
    pub name: &'static str,
    /// The least drop height found, m, when the start is that answer's
    /// design and the flip is possible in this fall ([`short_of_answer`]'s
    /// `least_height_m`).
    pub least_height_m: Option<f64>,
    /// That design itself, for a least-time design: the same question, so
    /// the design continues from it ([`FreeStart::free_design`]).
    pub design: Option<crate::design::free::FreeResult>,
}

impl FreeStart {
    /// The free-form design from this start: continued from the
    /// least-height design itself where it answers the same question (on
    /// its mesh, with its check points, penalty weight and trust radius),
    /// else from the start's schedule.
    pub fn free_design<'a>(&'a self, spec: &'a DesignSpec) -> crate::design::free::FreeDesign<'a> {
        let d = crate::design::free::FreeDesign::new(spec);
        match &self.design {
            Some(fr) => d.warm(fr, None).named(self.name),
            None => d.from_plan(self.plan.as_ref(), self.name),
        }
    }
}

/// The free-form design `optimize` and Python's `design` make, with its
/// mesh check: from `seed`, or without one from the start `run` takes
/// ([`free_start`], `note` told how it was found), a failure from the
/// least-height design in a fall it does restated ([`short_of_answer`],
/// `where_` saying where that schedule is).
pub fn free_design(
    spec: &DesignSpec,
    seed: Option<crate::design::free::Seed>,
    note: impl FnMut(&str),
    observer: &mut dyn crate::design::free::Observer,
    where_: &str,
) -> Result<FreeResult> {
    if let Some(seed) = seed {
        return crate::design::free::FreeDesign::new(spec)
            .check_mesh()
            .seed(seed)
            .observe(observer)
            .solve();
    }
    let start = free_start(spec, note)?;
    let r = start
        .free_design(spec)
        .check_mesh()
        .observe(observer)
        .solve();
    short_of_answer(spec, start.least_height_m, r, where_)
}

/// Where `optimize` and `recovery` point to the least-height schedule
/// ([`short_of_answer`]).
pub const LEAST_HEIGHT_FROM_RUN: &str = "`catflip run` writes it as least-height.csv";

/// `r`, a free-form design's outcome; where it started from the least-height
/// design in a fall the answer says the motors can do (`least_height_m`,
/// the least drop height found), a design that found no schedule inside
/// the motor limits failed on its own ([`Error::ShortOfAnswer`], `where_`
/// saying where the least-height schedule is): the motors' answer stays
/// "possible", not exit status 4. Near the least height few schedules fit,
/// and the design can end locally infeasible.
pub fn short_of_answer(
    spec: &DesignSpec,
    least_height_m: Option<f64>,
    r: Result<FreeResult>,
    where_: &str,
) -> Result<FreeResult> {
    match (r, least_height_m) {
        (Err(Error::BeyondMotors { .. }), Some(least)) => Err(Error::ShortOfAnswer {
            what: format!("free-form {}", spec.objective.name()),
            height_m: spec.fall.height,
            least_height_m: least,
            where_: where_.to_string(),
        }),
        (r, _) => r,
    }
}

/// Why no free-form design is attempted in this fall: the least-height
/// answer `a` says no schedule found fits (`run`'s line and `optimize`'s
/// error).
pub fn beyond_reach(a: &crate::design::least_height::HeightAnswer) -> String {
    if a.beyond_longest_fall {
        return format!(
            "no schedule found fits the motors in the fall from {} m (fall.height), nor in any fall catflip designs (up to {} s): {}",
            a.height_m,
            crate::config::ranges::MAX_FALL_TIME_S,
            a.beyond_text().trim_end_matches('.')
        );
    }
    format!(
        "no schedule found fits the motors in the fall from {} m (fall.height); the least drop height found is {:.3} m (the {} time-optimal design)",
        a.height_m, a.least_height_m, a.method
    )
}

/// The error of a design made for this fall when the least-height answer
/// `a` is that no schedule found fits it (verified), naming the height.
pub fn out_of_reach(a: &crate::design::least_height::HeightAnswer) -> Option<Error> {
    if a.beyond_longest_fall {
        return Some(Error::BeyondMotors {
            reason: beyond_reach(a),
        });
    }
    (!a.possible && a.verified).then(|| Error::BeyondMotors {
        reason: format!(
            "{}; `catflip run` writes its schedule as least-height.csv",
            beyond_reach(a)
        ),
    })
}

/// The name of a free-form design's seed when it is the least-height
/// answer's shortest manoeuvre ([`free_start`], `run`).
pub const FREE_LEAST_TIME: &str = "free least-time";

/// A `time` design's least drop height, m: its manoeuvre plus `fall.margin`
/// (the time objective answers "from what height", not "within this fall").
/// None for other objectives, and from a start with momentum, whose design
/// lasts the whole fall.
pub fn least_height_of_time_design(spec: &DesignSpec, manoeuvre: f64) -> Option<f64> {
    (spec.objective == crate::design::objective::Objective::Time && !spec.has_momentum())
        .then(|| crate::design::envelope::height_for(spec, manoeuvre))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A design from the least-height design that cannot fit the motors, in
    /// a fall the answer says they can do, is this design's failure (exit
    /// status 1), naming how far above the least height the fall is; with
    /// no such answer, or another failure, the outcome is unchanged.
    #[test]
    fn a_failure_from_the_least_height_design_in_a_possible_fall_is_not_the_motors_answer() {
        let spec = crate::test_support::spec_of(
            include_str!("../configs/robot-universal.toml"),
            "robot",
            &["fall.height=3.5".into()],
        );
        let beyond = || {
            Err(Error::BeyondMotors {
                reason: "cannot keep inside".into(),
            })
        };
        let e = short_of_answer(&spec, Some(3.4832), beyond(), LEAST_HEIGHT_FROM_RUN).unwrap_err();
        assert!(!e.is_beyond_motors() && !e.is_bad_input(), "{e:?}");
        let text = e.to_string();
        for words in [
            "free-form peak-torque design",
            "from 3.5 m, 0.5 % above the least drop height found (3.483 m)",
            "the flip is possible, the least-height schedule does it (`catflip run` writes it as least-height.csv)",
        ] {
            assert!(text.contains(words), "{words:?} not in {text}");
        }
        assert!(
            short_of_answer(&spec, None, beyond(), LEAST_HEIGHT_FROM_RUN)
                .unwrap_err()
                .is_beyond_motors()
        );
        let solver = Err(Error::Solver {
            what: "SCP".into(),
            status: "NumericalError".into(),
            hint: String::new(),
        });
        assert!(matches!(
            short_of_answer(&spec, Some(3.4832), solver, LEAST_HEIGHT_FROM_RUN),
            Err(Error::Solver { .. })
        ));
    }

    /// Which lines make a run partial, over every grade and the reference
    /// flags: flagged or failed or impossible, unless the flagged line is the
    /// reference beyond the motors or approximate for the joint.
    /// From another start the schedules made for the start at rest are not
    /// counted for their landing alone; a phased design's broken limit, a
    /// failed or unproven solve, a diverged flight still count, and so does
    /// every miss of the free-form design.
    #[test]
    fn only_a_landing_missed_by_a_schedule_made_for_rest_is_not_counted() {
        let landing = |e: f64| Miss::Landing {
            error_deg: e,
            tolerance_deg: 0.5,
            key: "land.max_tilt_deg",
        };
        let torque = Miss::Torque {
            peak_nm: 3.0,
            limit: 1.0,
            name: "limits.max_torque".into(),
        };
        let bend = Miss::Bend {
            bend_deg: 100.0,
            limit: 90.0,
            name: "limits.max_bend_deg".into(),
        };
        let f = made_for_rest_misses_only_the_landing;
        use Method::*;
        for (method, phased_lh, misses, not_counted) in [
            (Analytic, false, vec![landing(7.0)], true),
            (Phased, false, vec![landing(7.0)], true),
            (LeastHeight, true, vec![landing(7.0)], true),
            (LeastHeight, false, vec![landing(7.0)], false),
            (Free, false, vec![landing(7.0)], false),
            (Analytic, false, vec![landing(7.0), torque.clone()], true),
            (Phased, false, vec![landing(7.0), bend.clone()], false),
            (
                Phased,
                false,
                vec![landing(7.0), Miss::Status(Status::Infeasible)],
                false,
            ),
            (
                Phased,
                false,
                vec![Miss::Simulation("diverged".into())],
                false,
            ),
            (Phased, false, vec![landing(f64::NAN)], false),
            (Phased, false, vec![], false),
        ] {
            assert_eq!(
                f(method, phased_lh, &misses),
                not_counted,
                "{method:?} {misses:?}"
            );
        }
    }

    #[test]
    fn a_line_counts_against_the_run_unless_ok_or_a_reference() {
        for (grade, beyond, approximate, at_rest, counts) in [
            (Grade::Ok, false, false, false, false),
            (Grade::Ok, true, false, false, false),
            (Grade::Flagged, false, false, false, true),
            (Grade::Flagged, true, false, false, false),
            (Grade::Flagged, false, true, false, false),
            (Grade::Flagged, true, true, false, false),
            (Grade::Flagged, false, false, true, false),
            (Grade::Failed, false, false, false, true),
            (Grade::Impossible, false, false, false, true),
        ] {
            let m = MethodSummary {
                method: "analytic",
                status: Status::ClosedForm,
                verdict: grade,
                reason: None,
                beyond_the_motors: beyond,
                approximate_for_the_joint: approximate,
                unequal_halves: false,
                for_the_start_at_rest: at_rest,
                result: None,
            };
            assert_eq!(
                m.counts_against(),
                counts,
                "{grade:?} beyond {beyond} approximate {approximate} at rest {at_rest}"
            );
            assert_eq!(
                m.reference_note().is_some(),
                beyond || approximate || at_rest
            );
        }
        let m = MethodSummary::impossible(Method::Phased, "needs 5 m");
        assert_eq!(
            (m.status, m.verdict),
            (Status::NotAttempted, Grade::Impossible)
        );
        assert!(!m.status.is_usable());
    }
}
