//! Forward simulation in the full free-floating model.
//!
//! Kinematic: the shape follows a plan exactly; the attitude is integrated
//! from the zero-momentum body rate. Dynamic: a torque schedule (feed-forward,
//! optionally plus PD tracking and a torque limit, like a position-controlled
//! motor) drives the forward dynamics. Both use the adaptive Dormand-Prince
//! pair, restarted at phase boundaries, with the attitude quaternion
//! renormalised after each step.

use crate::config::Config;
use crate::design::plan::{Schedule, ShapePlan};
use crate::error::{Error, Result};
use crate::model::dynamics::{angular_momentum, bias, solve2};
use crate::model::motor::Motor;
use crate::model::so3::{FlipTracker, from_na, normalize_quat, quat_from, quat_rate};
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
    /// Largest `|L|` recomputed from the bodies' velocities, N m s.
    pub momentum_drift_nms: f64,
    /// Largest joint torque applied, N m (in the config's norm).
    pub peak_torque_nm: f64,
    pub steps: usize,
    #[serde(skip)]
    pub trace: Vec<TracePoint>,
}

impl SimReport {
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
            peak_torque_nm: f64::NAN,
            steps: 0,
            trace: Vec::new(),
        }
    }
}

fn settings(cfg: &Config) -> OdeSettings {
    OdeSettings {
        rtol: cfg.simulate.rtol,
        atol: cfg.simulate.atol,
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
        peak_torque_nm: 0.0,
        steps,
        trace,
    })
}

/// Records attitude, momentum and torque at every accepted step.
struct Recorder<'a> {
    cat: &'a Cat,
    trace: Vec<TracePoint>,
    flip: FlipTracker,
    steps: usize,
    drift: f64,
}

impl<'a> Recorder<'a> {
    fn new(cat: &'a Cat) -> Self {
        Self {
            cat,
            trace: Vec::new(),
            flip: FlipTracker::default(),
            steps: 0,
            drift: 0.0,
        }
    }

    /// `quat` is body A's attitude `[w, x, y, z]`; the body rate follows from `q`, `qd`.
    /// False when the state is no longer finite (the motion diverged).
    fn record(&mut self, t: f64, quat: &[f64], q: [f64; 2], qd: [f64; 2], tau: [f64; 2]) -> bool {
        self.steps += 1;
        let qa = quat_from(quat);
        let (flip, tilt) = self.flip.push(&qa);
        let ra = from_na(qa.to_rotation_matrix().matrix());
        let l = angular_momentum(self.cat, &ra, self.cat.body_rate(q, qd), q, qd);
        self.drift = self
            .drift
            .max((l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt());
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
            .all(|x| x.is_finite())
    }

    fn finish(
        mut self,
        quat: &[f64],
        status: OdeStatus,
        ode: &OdeSettings,
        limit: Option<f64>,
    ) -> Result<SimReport> {
        let (flip, tilt) = self.flip.push(&quat_from(quat));
        let mut r = finish(flip, tilt, self.trace, self.steps, status, ode, limit)?;
        r.momentum_drift_nms = self.drift;
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

/// Attitude along a prescribed shape trajectory.
pub fn kinematic(cat: &Cat, plan: &dyn ShapePlan, ode: &OdeSettings) -> Result<SimReport> {
    let mut rec = Recorder::new(cat);
    let (y, status) = over_phases(
        plan,
        [1.0, 0.0, 0.0, 0.0],
        ode,
        |i, t, y| {
            let s = plan.state_in(i, t);
            quat_rate(y, cat.body_rate(s.q, s.qd))
        },
        |i, t, y| {
            let s = plan.state_in(i, t);
            rec.record(t, y, s.q, s.qd, [0.0; 2])
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
    pub fn from_config(cfg: &Config) -> Controller {
        let m0 = cfg.cat().straight_inertia();
        let wn = 2.0 * std::f64::consts::PI * cfg.simulate.pd_bandwidth_hz;
        let (kp, kd) = if cfg.simulate.pd {
            (m0 * wn * wn, 2.0 * cfg.simulate.pd_damping * m0 * wn)
        } else {
            (0.0, 0.0)
        };
        Controller {
            kp,
            kd,
            motor: cfg.motor(),
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

/// Full forward dynamics under feed-forward torque plus PD tracking of the plan.
pub fn dynamic(
    cat: &Cat,
    plan: &dyn ShapePlan,
    ctrl: &Controller,
    ode: &OdeSettings,
) -> Result<SimReport> {
    let s0 = plan.state(plan.phase_bounds()[0]);
    let applied = |i: usize, t: f64, y: &[f64; 8]| {
        let s = plan.state_in(i, t);
        let ff = plan.torque_in(cat, i, t);
        (ctrl.apply(ff, [y[4], y[5]], [y[6], y[7]], s.q, s.qd), s.q)
    };
    let mut rec = Recorder::new(cat);
    let (mut peak, mut track) = (0.0f64, 0.0f64);
    let (y, status) = over_phases(
        plan,
        [1.0, 0.0, 0.0, 0.0, s0.q[0], s0.q[1], s0.qd[0], s0.qd[1]],
        ode,
        |i, t, y| {
            let (tau, _) = applied(i, t, y);
            let (q, qd) = ([y[4], y[5]], [y[6], y[7]]);
            let terms = ShapeTerms::first(cat, q);
            let h = bias(&terms, qd);
            let qdd = solve2(&terms.m, [tau[0] - h[0], tau[1] - h[1]]);
            let dq = quat_rate(y, terms.body_rate(qd));
            [dq[0], dq[1], dq[2], dq[3], qd[0], qd[1], qdd[0], qdd[1]]
        },
        |i, t, y| {
            let (tau, qref) = applied(i, t, y);
            let (q, qd) = ([y[4], y[5]], [y[6], y[7]]);
            peak = peak.max(ctrl.motor.norm.of(tau));
            let off = (q[0] - qref[0]).hypot(q[1] - qref[1]);
            track = track.max(off);
            // a shape a full turn away from the plan has left the schedule
            rec.record(t, y, q, qd, tau) && off <= MAX_TRACKING_ERROR
        },
    );
    let mut r = rec.finish(&y, status, ode, ctrl.motor.max_torque)?;
    r.peak_torque_nm = peak;
    r.max_tracking_error_rad = track;
    r.final_shape_error_rad = y[4].hypot(y[5]);
    r.final_rate_error_rad_s = y[6].hypot(y[7]);
    Ok(r)
}

/// Kinematic run with the config's tolerances.
pub fn kinematic_cfg(cfg: &Config, plan: &dyn ShapePlan) -> Result<SimReport> {
    kinematic(&cfg.cat(), plan, &settings(cfg))
}

/// Dynamic run with the config's tolerances, gains and limits.
pub fn dynamic_cfg(cfg: &Config, plan: &dyn ShapePlan) -> Result<SimReport> {
    dynamic(
        &cfg.cat(),
        plan,
        &Controller::from_config(cfg),
        &settings(cfg),
    )
}

/// Most rows a schedule file may have. Every row is a kink of the
/// feed-forward torque that the adaptive integrator must resolve, so the cost
/// grows with the rows; catflip's own schedules have at most
/// `3 * (30000 + 1)` rows (`simulate.samples_per_phase` <= 30000).
pub const MAX_SCHEDULE_ROWS: usize = 100_000;

/// Reads a schedule CSV for replay on `cfg`'s fall: bounded in size, and
/// lasting as long as the manoeuvre the config leaves (fall time minus margin).
pub fn read_schedule(cfg: &Config, text: &str, origin: &str) -> Result<Schedule> {
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
    let b = s.phase_bounds();
    let (start, end) = (b[0], b[3]);
    let want = cfg.available_time();
    let tol = 1e-6 * (1.0 + want);
    if start.abs() > tol || (end - want).abs() > tol {
        // a schedule from 0 fits one height; one that starts later, none
        let fits = if start.abs() <= tol {
            format!(
                "this one fits `--set fall.height={:.9}` at this fall.gravity and fall.margin",
                0.5 * cfg.fall.gravity * (end + cfg.fall.margin).powi(2)
            )
        } else {
            "this one does not start at 0, so no height fits it".into()
        };
        return Err(Error::Schedule {
            file: origin.into(),
            line: s.rows.len() + 1,
            message: format!(
                "the schedule runs from t = {start} s to {end} s, but config `{}` leaves {want:.6} s for the manoeuvre (fall time {:.6} s minus fall.margin {} s) and a schedule must start at 0 and end then; replay it with the config it was designed for ({fits}), or design one for this fall with `catflip optimize`",
                cfg.name,
                cfg.fall_time(),
                cfg.fall.margin,
            ),
        });
    }
    Ok(s)
}
