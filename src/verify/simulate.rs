//! Forward simulation in the full free-floating model.
//!
//! Kinematic: the shape follows a plan exactly; the attitude is integrated
//! from the zero-momentum body rate. Dynamic: a torque schedule (feed-forward,
//! optionally plus PD tracking and a torque limit, like a position-controlled
//! motor) drives the forward dynamics. Both use the adaptive Dormand-Prince
//! pair, restarted at phase boundaries, with the attitude quaternion
//! renormalised after each step.

use crate::design::plan::{Schedule, ShapePlan};
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};
use crate::model::dynamics::angular_momentum;
use crate::model::momentum::{
    Start, body_rate, body_rate_from, forward_dynamics_from, landing_error, rigid_turn,
};
use crate::model::motor::Motor;
use crate::model::small::cross;
use crate::model::so3::{FlipTracker, from_na, normalize_quat, quat_from, quat_rate, to_na};
use crate::model::{Cat, ShapeTerms};
use crate::verify::ode::{OdeSettings, OdeStatus, integrate};
use serde::Serialize;

/// One recorded instant of a simulation.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TracePoint {
    pub t: f64,
    /// Rotation about the initial spine, unwrapped, rad.
    pub flip: f64,
    pub tilt: f64,
    pub q: [f64; 2],
    pub tau: [f64; 2],
    /// Body A's attitude quaternion `[w, x, y, z]` (A frame to world); body
    /// B's is `R_A R_rel(q)`. The report animates both halves from it.
    pub attitude: [f64; 4],
}

/// What a simulation reports.
#[derive(Debug, Clone, Serialize)]
pub struct SimReport {
    /// Final rotation about the initial spine, unwrapped along the run
    /// ([`FlipTracker`], the one convention of tables, JSON, figures), degrees.
    pub flip_deg: f64,
    /// `pi - |flip|`, rad.
    pub flip_error_rad: f64,
    /// Angle between final and initial spine, degrees.
    pub tilt_deg: f64,
    /// `|q(T)|` and `|q_dot(T)|`: how far from straight and at rest the cat ends.
    pub final_shape_error_rad: f64,
    pub final_rate_error_rad_s: f64,
    /// Largest `|q - q_plan|` along the way, rad (zero for kinematic runs).
    pub max_tracking_error_rad: f64,
    /// Largest `|L - L(0)|`, `L` recomputed from the bodies' velocities, N m s
    /// (at zero momentum: the largest `|L|`).
    pub momentum_drift_nms: f64,
    /// The belly's angle from straight down at touchdown, the straight cat
    /// turning rigidly during `fall.margin` (MODEL.md section 6), degrees.
    pub landing_error_deg: f64,
    /// Body A's attitude `[w, x, y, z]` and body-frame momentum `R_A' L` (N m s)
    /// at the end of the manoeuvre.
    #[serde(skip)]
    pub final_attitude: [f64; 4],
    #[serde(skip)]
    pub final_body_momentum: [f64; 3],
    /// Largest joint torque applied, N m (in the config's norm).
    pub peak_torque_nm: f64,
    pub steps: usize,
    #[serde(skip)]
    pub trace: Vec<TracePoint>,
    /// The landing margin flown with the shape held straight, `t` from the
    /// manoeuvre's end (empty where the landing is the rigid turn of
    /// [`SimReport::land`]): the animation's way to touchdown.
    #[serde(skip)]
    pub landing_trace: Vec<TracePoint>,
}

impl SimReport {
    /// Sets the landing error for a landing `margin` seconds after the
    /// manoeuvre, the straight cat turning rigidly meanwhile (F8).
    pub fn land(&mut self, cat: &Cat, margin: f64) {
        let r = to_na(&from_na(
            quat_from(&self.final_attitude)
                .to_rotation_matrix()
                .matrix(),
        ));
        let r = rigid_turn(cat, &r, self.final_body_momentum, margin);
        self.landing_error_deg = landing_error(&r).to_degrees();
    }

    /// `simulation.csv`: the flown trace, a row per accepted step.
    pub fn trace_csv(&self) -> String {
        let mut csv = String::from("t_s,flip_rad,tilt_rad,q1_rad,q2_rad,tau1_nm,tau2_nm\n");
        for p in &self.trace {
            csv.push_str(&format!(
                "{:.9},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}\n",
                p.t, p.flip, p.tilt, p.q[0], p.q[1], p.tau[0], p.tau[1]
            ));
        }
        csv
    }

    /// The report of a simulation that failed: every number NaN (null in JSON).
    pub fn failed() -> SimReport {
        SimReport {
            flip_deg: f64::NAN,
            flip_error_rad: f64::NAN,
            tilt_deg: f64::NAN,
            final_shape_error_rad: f64::NAN,
            final_rate_error_rad_s: f64::NAN,
            max_tracking_error_rad: f64::NAN,
            momentum_drift_nms: f64::NAN,
            landing_error_deg: f64::NAN,
            final_attitude: [f64::NAN; 4],
            final_body_momentum: [f64::NAN; 3],
            peak_torque_nm: f64::NAN,
            steps: 0,
            trace: Vec::new(),
            landing_trace: Vec::new(),
        }
    }
}

fn settings(spec: &DesignSpec) -> OdeSettings {
    OdeSettings {
        rtol: spec.simulate.rtol,
        atol: spec.simulate.atol,
        ..Default::default()
    }
}

/// Why a run stopped early, in words that name the cause and the remedy.
fn failure(
    status: OdeStatus,
    trace: &[TracePoint],
    ode: &OdeSettings,
    limit: Option<f64>,
) -> Error {
    let cause = match limit {
        Some(l) => format!(
            "the schedule's torques do not fit this cat, or limits.max_torque = {l} N m holds the motors below what the schedule needs (check the torque units, N m, the config the schedule was designed for, and the limit)"
        ),
        None => "the schedule's torques do not fit this cat (check their units, N m, and the config the schedule was designed for)".to_string(),
    };
    let last = trace.last();
    let at = last.map(|p| p.t).unwrap_or(0.0);
    let peak = trace
        .iter()
        .map(|p| p.tau[0].hypot(p.tau[1]))
        .fold(0.0, f64::max);
    Error::Simulation(match status {
        OdeStatus::Stopped
            if last.is_some_and(|p| p.q.iter().chain(&p.tau).all(|x| x.is_finite())) =>
        {
            format!(
                "the motion diverged at t = {at:.6} s: the shape left the schedule by more than a full turn (applied torque up to {peak:.4e} N m); {cause}"
            )
        }
        OdeStatus::NonFinite | OdeStatus::Stopped => format!(
            "the motion diverged: the state became NaN or infinite at t = {at:.6} s (applied torque up to {peak:.4e} N m); {cause}"
        ),
        // with next to no torque the schedule is not what the integrator
        // cannot follow: the body is (halves of 1e4 and 1e-6 kg)
        OdeStatus::StepBudget if peak <= f64::MIN_POSITIVE.sqrt() => format!(
            "the integrator used its {} steps per phase by t = {at:.6} s with next to no torque applied ({peak:.4e} N m): the body itself is too stiff to integrate at a relative tolerance of {:e} (halves of very different masses, lengths or radii, or a motor that turns a half about its own long axis?); check the cat's keys (simulate.rtol sets the tolerance of the simulations; the phased design's twist search integrates at 1e-11 whatever it is)",
            ode.max_steps, ode.rtol
        ),
        OdeStatus::StepBudget => format!(
            "the integrator used its {} steps per phase by t = {at:.6} s (applied torque up to {peak:.4e} N m): the motion is too fast or too rough for simulate.rtol = {:e}; a schedule with very many rows or huge torques is the usual cause, and simulate.rtol = 1e-8 may help",
            ode.max_steps, ode.rtol
        ),
        OdeStatus::Done => unreachable!("a finished run is no failure"),
    })
}

/// Tracking error, rad, beyond which the simulated shape has left the
/// schedule for good: more than a full turn (a saturated motor lags by less).
const MAX_TRACKING_ERROR: f64 = 2.0 * std::f64::consts::PI;

fn finish(
    flip: f64,
    tilt: f64,
    trace: Vec<TracePoint>,
    steps: usize,
    status: OdeStatus,
    ode: &OdeSettings,
    limit: Option<f64>,
) -> Result<SimReport> {
    if status != OdeStatus::Done {
        return Err(failure(status, &trace, ode, limit));
    }
    Ok(SimReport {
        flip_deg: flip.to_degrees(),
        flip_error_rad: crate::model::so3::flip_error(flip),
        tilt_deg: tilt.to_degrees(),
        final_shape_error_rad: 0.0,
        final_rate_error_rad_s: 0.0,
        max_tracking_error_rad: 0.0,
        momentum_drift_nms: 0.0,
        landing_error_deg: f64::NAN,
        final_attitude: [f64::NAN; 4],
        final_body_momentum: [f64::NAN; 3],
        peak_torque_nm: 0.0,
        steps,
        trace,
        landing_trace: Vec::new(),
    })
}

/// Records attitude, momentum and torque at every accepted step.
struct Recorder<'a> {
    cat: &'a Cat,
    /// The world momentum at release, N m s.
    l0: [f64; 3],
    trace: Vec<TracePoint>,
    flip: FlipTracker,
    steps: usize,
    drift: f64,
}

impl<'a> Recorder<'a> {
    fn new(cat: &'a Cat, start: &Start) -> Self {
        Self {
            cat,
            l0: start.momentum(cat),
            trace: Vec::new(),
            flip: FlipTracker::default(),
            steps: 0,
            drift: 0.0,
        }
    }

    /// `quat` is body A's attitude `[w, x, y, z]`; the body rate follows from
    /// `q`, `qd` and the body-frame momentum `lam`.
    /// False when the state is no longer finite (the motion diverged).
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        t: f64,
        quat: &[f64],
        q: [f64; 2],
        qd: [f64; 2],
        tau: [f64; 2],
        lam: [f64; 3],
        w: [f64; 3],
    ) -> bool {
        self.steps += 1;
        let qa = quat_from(quat);
        let (flip, tilt) = self.flip.push(&qa);
        let ra = from_na(qa.to_rotation_matrix().matrix());
        let l = angular_momentum(self.cat, &ra, w, q, qd);
        let e = [0, 1, 2].map(|i| l[i] - self.l0[i]);
        self.drift = self
            .drift
            .max((e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt());
        self.trace.push(TracePoint {
            t,
            flip,
            tilt,
            q,
            tau,
            attitude: [qa.w, qa.i, qa.j, qa.k],
        });
        quat.iter()
            .chain(&q)
            .chain(&qd)
            .chain(&tau)
            .chain(&lam)
            .all(|x| x.is_finite())
    }

    /// `y` is the final state: attitude quaternion first, body-frame momentum last.
    fn finish(
        mut self,
        y: &[f64],
        status: OdeStatus,
        ode: &OdeSettings,
        limit: Option<f64>,
    ) -> Result<SimReport> {
        let (flip, tilt) = self.flip.push(&quat_from(y));
        let cat = self.cat;
        let mut r = finish(flip, tilt, self.trace, self.steps, status, ode, limit)?;
        r.momentum_drift_nms = self.drift;
        r.final_attitude = [y[0], y[1], y[2], y[3]];
        let n = y.len();
        r.final_body_momentum = [y[n - 3], y[n - 2], y[n - 1]];
        r.land(cat, 0.0);
        Ok(r)
    }
}

/// Integrates phase by phase (restarting at the boundaries, where the forcing
/// may jump); `rhs` and `observe` get the phase index.
fn over_phases<const N: usize>(
    plan: &dyn ShapePlan,
    y0: [f64; N],
    ode: &OdeSettings,
    rhs: impl Fn(usize, f64, &[f64; N]) -> [f64; N],
    mut observe: impl FnMut(usize, f64, &[f64; N]) -> bool,
) -> ([f64; N], OdeStatus) {
    let b = plan.phase_bounds();
    let mut y = y0;
    for i in 0..3 {
        if b[i + 1] <= b[i] {
            continue;
        }
        let (yy, st) = integrate(
            |t, y| rhs(i, t, y),
            |y| normalize_quat(y),
            b[i],
            y,
            b[i + 1],
            ode,
            |t, y| observe(i, t, y),
        );
        y = yy;
        if st != OdeStatus::Done {
            return (y, st);
        }
    }
    (y, OdeStatus::Done)
}

/// Attitude along a prescribed shape trajectory, from rest upside down.
pub fn kinematic(cat: &Cat, plan: &dyn ShapePlan, ode: &OdeSettings) -> Result<SimReport> {
    kinematic_from(cat, plan, &Start::default(), ode)
}

/// The state `[quaternion, lambda]` of an attitude-only run at release.
fn attitude_state(cat: &Cat, start: &Start) -> [f64; 7] {
    let (a, l) = (start.attitude, start.body_momentum(cat));
    [a[0], a[1], a[2], a[3], l[0], l[1], l[2]]
}

/// Rate of the attitude and of the body-frame momentum (`lambda x w`).
fn attitude_rate(y: &[f64], w: [f64; 3], lam: [f64; 3]) -> ([f64; 4], [f64; 3]) {
    (quat_rate(y, w), cross(lam, w))
}

/// Attitude along a prescribed shape trajectory from `start`: the body
/// rate `J^-1 lambda - A q_dot`, the body-frame momentum `lambda` turning as
/// `lambda x w` (its world value `R_A lambda` is the conserved `L`).
pub fn kinematic_from(
    cat: &Cat,
    plan: &dyn ShapePlan,
    start: &Start,
    ode: &OdeSettings,
) -> Result<SimReport> {
    let mut rec = Recorder::new(cat, start);
    let rate = |i: usize, t: f64, y: &[f64; 7]| {
        let s = plan.state_in(i, t);
        let lam = [y[4], y[5], y[6]];
        (s, lam, body_rate(cat, s.q, s.qd, lam))
    };
    let (y, status) = over_phases(
        plan,
        attitude_state(cat, start),
        ode,
        |i, t, y| {
            let (_, lam, w) = rate(i, t, y);
            let (dq, dl) = attitude_rate(y, w, lam);
            [dq[0], dq[1], dq[2], dq[3], dl[0], dl[1], dl[2]]
        },
        |i, t, y| {
            let (s, lam, w) = rate(i, t, y);
            rec.record(t, y, s.q, s.qd, [0.0; 2], lam, w)
        },
    );
    let mut r = rec.finish(&y, status, ode, None)?;
    let end = plan.state(plan.duration());
    r.final_shape_error_rad = end.q[0].hypot(end.q[1]);
    r.final_rate_error_rad_s = end.qd[0].hypot(end.qd[1]);
    Ok(r)
}

/// PD tracking of the plan, and the motor model: the commanded torque is
/// clipped to the motor envelope at the current joint speed.
#[derive(Debug, Clone, Copy)]
pub struct Controller {
    pub kp: f64,
    pub kd: f64,
    pub motor: Motor,
}

impl Controller {
    /// Gains from the config: natural frequency `2 pi f` about `M(0) = I_t / 2`.
    pub fn from_spec(spec: &DesignSpec) -> Controller {
        let m0 = spec.cat.straight_inertia();
        let wn = 2.0 * std::f64::consts::PI * spec.simulate.pd_bandwidth_hz;
        let (kp, kd) = if spec.simulate.pd {
            (m0 * wn * wn, 2.0 * spec.simulate.pd_damping * m0 * wn)
        } else {
            (0.0, 0.0)
        };
        Controller {
            kp,
            kd,
            motor: spec.motor,
        }
    }

    pub fn apply(
        &self,
        ff: [f64; 2],
        q: [f64; 2],
        qd: [f64; 2],
        q_ref: [f64; 2],
        qd_ref: [f64; 2],
    ) -> [f64; 2] {
        let mut tau = [0.0; 2];
        for j in 0..2 {
            tau[j] = ff[j] + self.kp * (q_ref[j] - q[j]) + self.kd * (qd_ref[j] - qd[j]);
        }
        self.motor.clip(tau, qd)
    }
}

/// Full forward dynamics under feed-forward torque plus PD tracking of the
/// plan, from rest upside down.
pub fn dynamic(
    cat: &Cat,
    plan: &dyn ShapePlan,
    ctrl: &Controller,
    ode: &OdeSettings,
) -> Result<SimReport> {
    dynamic_from(cat, plan, ctrl, ode, &Start::default())
}

/// Full forward dynamics from `start`: state `[quaternion, q, q_dot, lambda]`.
pub fn dynamic_from(
    cat: &Cat,
    plan: &dyn ShapePlan,
    ctrl: &Controller,
    ode: &OdeSettings,
    start: &Start,
) -> Result<SimReport> {
    let s0 = plan.state(plan.phase_bounds()[0]);
    let a0 = attitude_state(cat, start);
    let y0 = [
        a0[0], a0[1], a0[2], a0[3], s0.q[0], s0.q[1], s0.qd[0], s0.qd[1], a0[4], a0[5], a0[6],
    ];
    Ok(dynamic_state(cat, plan, ctrl, ode, start, y0)?.0)
}

/// [`dynamic_from`] from the state `y0` = `[quaternion, q, q_dot, lambda]`;
/// also returns the final state.
fn dynamic_state(
    cat: &Cat,
    plan: &dyn ShapePlan,
    ctrl: &Controller,
    ode: &OdeSettings,
    start: &Start,
    y0: [f64; 11],
) -> Result<(SimReport, [f64; 11])> {
    let applied = |i: usize, t: f64, y: &[f64; 11]| {
        let s = plan.state_in(i, t);
        let ff = plan.torque_in(cat, i, t);
        (ctrl.apply(ff, [y[4], y[5]], [y[6], y[7]], s.q, s.qd), s.q)
    };
    let mut rec = Recorder::new(cat, start);
    let (mut peak, mut track) = (0.0f64, 0.0f64);
    let (y, status) = over_phases(
        plan,
        y0,
        ode,
        |i, t, y| {
            let (tau, _) = applied(i, t, y);
            let (q, qd, lam) = ([y[4], y[5]], [y[6], y[7]], [y[8], y[9], y[10]]);
            let terms = ShapeTerms::first(cat, q);
            let qdd = forward_dynamics_from(cat, &terms, q, qd, tau, lam);
            let w = body_rate_from(cat, &terms, q, qd, lam);
            let (dq, dl) = attitude_rate(y, w, lam);
            [
                dq[0], dq[1], dq[2], dq[3], qd[0], qd[1], qdd[0], qdd[1], dl[0], dl[1], dl[2],
            ]
        },
        |i, t, y| {
            let (tau, qref) = applied(i, t, y);
            let (q, qd, lam) = ([y[4], y[5]], [y[6], y[7]], [y[8], y[9], y[10]]);
            peak = peak.max(ctrl.motor.norm.of(tau));
            let off = (q[0] - qref[0]).hypot(q[1] - qref[1]);
            track = track.max(off);
            let w = body_rate_from(cat, &ShapeTerms::first(cat, q), q, qd, lam);
            // a shape a full turn away from the plan has left the schedule
            rec.record(t, y, q, qd, tau, lam, w) && off <= MAX_TRACKING_ERROR
        },
    );
    let mut r = rec.finish(&y, status, ode, ctrl.motor.max_torque)?;
    r.peak_torque_nm = peak;
    r.max_tracking_error_rad = track;
    r.final_shape_error_rad = y[4].hypot(y[5]);
    r.final_rate_error_rad_s = y[6].hypot(y[7]);
    Ok((r, y))
}

/// A shape held straight for a while: the plan of the landing margin.
struct Straight(f64);

impl ShapePlan for Straight {
    fn phase_bounds(&self) -> Vec<f64> {
        vec![0.0, self.0 / 3.0, 2.0 * self.0 / 3.0, self.0]
    }
    fn state_in(&self, _: usize, _: f64) -> crate::design::plan::ShapeState {
        crate::design::plan::ShapeState {
            q: [0.0; 2],
            qd: [0.0; 2],
            qdd: [0.0; 2],
            phase: crate::design::plan::Phase::Unfold,
        }
    }
}

/// [`dynamic_from`], then the landing margin with the controller holding the
/// shape straight (no feed-forward), as the motors would: the landing error is
/// the attitude's at touchdown. The report's other numbers are the manoeuvre's.
pub fn dynamic_landing(
    cat: &Cat,
    plan: &dyn ShapePlan,
    ctrl: &Controller,
    ode: &OdeSettings,
    start: &Start,
    margin: f64,
) -> Result<SimReport> {
    let s0 = plan.state(plan.phase_bounds()[0]);
    let a0 = attitude_state(cat, start);
    let y0 = [
        a0[0], a0[1], a0[2], a0[3], s0.q[0], s0.q[1], s0.qd[0], s0.qd[1], a0[4], a0[5], a0[6],
    ];
    let (mut r, y) = dynamic_state(cat, plan, ctrl, ode, start, y0)?;
    if margin > 0.0 {
        let (held, _) = dynamic_state(cat, &Straight(margin), ctrl, ode, start, y)?;
        r.momentum_drift_nms = r.momentum_drift_nms.max(held.momentum_drift_nms);
        let m = to_na(&from_na(
            quat_from(&held.final_attitude)
                .to_rotation_matrix()
                .matrix(),
        ));
        r.landing_error_deg = landing_error(&m).to_degrees();
        r.landing_trace = held.trace;
    }
    Ok(r)
}

/// Kinematic run from the config's start with its tolerances; the landing
/// error after its `fall.margin`.
pub fn kinematic_spec(spec: &DesignSpec, plan: &dyn ShapePlan) -> Result<SimReport> {
    let cat = spec.cat;
    let mut r = kinematic_from(&cat, plan, &spec.release(), &settings(spec))?;
    r.land(&cat, spec.fall.margin);
    Ok(r)
}

/// Dynamic run from the config's start with its tolerances, gains and
/// limits; the landing error after its `fall.margin`, the motors holding the
/// shape straight meanwhile ([`dynamic_landing`]).
pub fn dynamic_spec(spec: &DesignSpec, plan: &dyn ShapePlan) -> Result<SimReport> {
    dynamic_landing(
        &spec.cat,
        plan,
        &Controller::from_spec(spec),
        &settings(spec),
        &spec.release(),
        spec.fall.margin,
    )
}

/// Most rows a schedule file may have. Every row is a kink of the
/// feed-forward torque that the adaptive integrator must resolve, so the cost
/// grows with the rows; catflip's own schedules have at most
/// `3 * (30000 + 1)` rows (`simulate.samples_per_phase` <= 30000).
pub const MAX_SCHEDULE_ROWS: usize = 100_000;

/// Reads a schedule CSV for replay on `spec`'s fall (the config `name`, for
/// messages): bounded in size, and lasting as long as the manoeuvre the fall
/// leaves (fall time minus margin).
pub fn read_schedule(spec: &DesignSpec, name: &str, text: &str, origin: &str) -> Result<Schedule> {
    let rows = text.lines().filter(|l| !l.trim().is_empty()).count();
    if rows > MAX_SCHEDULE_ROWS + 1 {
        return Err(Error::Schedule {
            file: origin.into(),
            line: MAX_SCHEDULE_ROWS + 2,
            message: format!(
                "{} rows, more than the {MAX_SCHEDULE_ROWS} a schedule may have; resample it more coarsely (catflip writes 3 * (simulate.samples_per_phase + 1) rows)",
                rows - 1
            ),
        });
    }
    let s = Schedule::from_csv(text, origin)?;
    if s.rows.len() > MAX_SCHEDULE_ROWS {
        return Err(Error::Schedule {
            file: origin.into(),
            line: 1,
            message: format!(
                "{} rows, more than the {MAX_SCHEDULE_ROWS} a schedule may have; resample it more coarsely",
                s.rows.len()
            ),
        });
    }
    let b = s.phase_bounds();
    if let Some(why) = span_mismatch(spec, name, b[0], b[3]) {
        return Err(Error::Schedule {
            file: origin.into(),
            line: s.rows.len() + 1,
            message: format!(
                "{why}; replay it with the config it was designed for, or design one for this fall with `catflip optimize`"
            ),
        });
    }
    Ok(s)
}

/// Why a schedule running from `start` to `end`, s, cannot be flown in the
/// fall of config `name` (`spec`): it must start at release and end when the
/// manoeuvre's time does, as every design made for that fall does. `None`
/// when it fits.
pub fn span_mismatch(spec: &DesignSpec, name: &str, start: f64, end: f64) -> Option<String> {
    let want = spec.available_time();
    let tol = 1e-6 * (1.0 + want);
    if start.abs() <= tol && (end - want).abs() <= tol {
        return None;
    }
    // a schedule from 0 fits one height; one that starts later, none
    let fall = end + spec.fall.margin;
    let fits = if start.abs() > tol {
        "it does not start at 0, so no height fits it".into()
    } else if crate::config::ranges::beyond_longest_fall(fall) {
        format!(
            "it would need a {fall:.4} s fall, longer than any catflip designs ({} s)",
            crate::config::ranges::MAX_FALL_TIME_S
        )
    } else {
        format!(
            "it fits `--set fall.height={:.9}` at this fall.gravity and fall.margin",
            0.5 * spec.fall.gravity * fall.powi(2)
        )
    };
    Some(format!(
        "the schedule runs from t = {start} s to {end} s, but config `{name}` leaves {want:.6} s for the manoeuvre (fall time {:.6} s minus fall.margin {} s) and a schedule must start at 0 and end then ({fits})",
        spec.fall_time(),
        spec.fall.margin,
    ))
}
