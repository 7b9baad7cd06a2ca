//! One closed-loop flight in catflip's fixed-step simulator: the robot
//! (possibly not the model: other inertias, another start, a delay, noisy
//! torques and sensors) under the design's feed-forward plus a feedback.

use super::plant::{Y, attitude, gyro, momentum_from_rates, rk4};
use super::reference::Reference;
use super::replanning::{InFlight, Record, Replanning};
use super::rng::Rng;
use super::tvlqr::{Tvlqr, tvlqr_command};
use crate::export::start::world_map;
use crate::model::Cat;
use crate::model::momentum::landing_error;
use crate::model::motor::Motor;
use nalgebra::{UnitQuaternion, Vector3};

/// A state in the simulators' world, the `<stem>.tvlqr.csv` columns:
/// `[w, x, y, z]` the rear half's attitude `W R` (gravity `-z`), `lambda`
/// (3, the momentum about the common centre of mass in the rear half's
/// frame, N m s), `q` (2), `q_dot` (2).
pub type SimState = [f64; 11];

/// catflip's integrator state of a simulator's state.
pub fn from_sim(s: &SimState) -> Y {
    let r = world_map().inverse() * crate::model::so3::quat_from(&[s[0], s[1], s[2], s[3]]);
    [
        r.w, r.i, r.j, r.k, s[7], s[8], s[9], s[10], s[4], s[5], s[6],
    ]
}

/// A simulator's state of catflip's integrator state (the inverse of [`from_sim`]).
pub fn to_sim(y: &Y) -> SimState {
    let r = world_map() * attitude(y);
    [
        r.w, r.i, r.j, r.k, y[8], y[9], y[10], y[4], y[5], y[6], y[7],
    ]
}

/// What closes the loop.
#[derive(Debug, Clone, Copy)]
pub enum Feedback<'a> {
    /// Today's joint PD on the planned shape, every simulator step.
    JointPd { kp: f64, kd: f64 },
    /// Time-varying LQR on the full state, at its control rate, predicting over its delay.
    Tvlqr(&'a Tvlqr),
    /// The TVLQR about a plan solved again in flight ([`super::replanning`]).
    Replan(&'a Tvlqr, &'a Replanning),
}

/// How the flight differs from the design's.
#[derive(Debug, Clone)]
pub struct Flight {
    /// The robot as built.
    pub plant: Cat,
    /// Its state at release.
    pub release: Y,
    /// Actuator delay, simulator steps.
    pub delay_steps: usize,
    /// Torque noise, standard deviation, N m, redrawn each `noise_steps`.
    pub torque_noise: f64,
    pub noise_steps: usize,
    /// Attitude (rad per axis) and rate (rad/s) sensor noise, standard deviations.
    pub attitude_noise: f64,
    pub rate_noise: f64,
    /// Stream of the noises.
    pub rng: Rng,
}

impl Flight {
    /// The design's own flight: the model, the nominal release, nothing added.
    pub fn nominal(r: &Reference) -> Flight {
        Flight {
            plant: r.cat,
            release: r.nominal[0],
            delay_steps: 0,
            torque_noise: 0.0,
            noise_steps: 1,
            attitude_noise: 0.0,
            rate_noise: 0.0,
            rng: Rng::new(0, 0, 0),
        }
    }
}

/// How a flight ended.
#[derive(Debug, Clone)]
pub struct Landing {
    /// The belly's angle from straight down at touchdown, deg (NaN: diverged).
    pub error_deg: f64,
    /// Largest correction on top of the feed-forward, N m (in the motor norm).
    pub max_correction_nm: f64,
    /// The state at touchdown.
    pub state: Y,
    /// The replans of the flight, in order (none but under [`Feedback::Replan`]).
    pub replans: Vec<Record>,
}

/// One command of a flight: what the controller measured at simulator step
/// `step` and the correction it sent (acting from `step` plus the plant's delay).
#[derive(Debug, Clone, Copy)]
pub struct Command {
    pub step: usize,
    pub measured: Y,
    pub correction: [f64; 2],
}

/// The true state at simulator step `step` and the joint torque acting
/// over that step (the motor's, after saturation and back-EMF).
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub step: usize,
    pub state: Y,
    pub torque: [f64; 2],
}

/// What a flight records beside its landing ([`fly_logged`]).
#[derive(Debug, Clone, Default)]
pub struct Log {
    /// Every command sent.
    pub commands: Vec<Command>,
    /// The true state every `every` steps and at touchdown (none when `every` is 0).
    pub samples: Vec<Sample>,
    pub every: usize,
}

impl Log {
    /// A log of the commands and of the state every `every` steps.
    pub fn every(every: usize) -> Log {
        Log {
            every,
            ..Log::default()
        }
    }
}

/// The joint PD's correction at step `j` from the measurement `m`.
pub fn pd_command(r: &Reference, kp: f64, kd: f64, j: usize, m: &Y) -> [f64; 2] {
    let (q, qd) = r.shape[j.min(r.steps)];
    [0, 1].map(|i| kp * (q[i] - m[4 + i]) + kd * (qd[i] - m[6 + i]))
}

/// What the sensors report: attitude, gyro and joint encoders, the momentum
/// estimated from them with the model's inertias.
fn measure(r: &Reference, f: &mut Flight, y: &Y) -> Y {
    let mut m = *y;
    if f.attitude_noise > 0.0 {
        let n = Vector3::new(f.rng.normal(), f.rng.normal(), f.rng.normal()) * f.attitude_noise;
        let a = attitude(y) * UnitQuaternion::from_scaled_axis(n);
        m[..4].copy_from_slice(&[a.w, a.i, a.j, a.k]);
    }
    let mut w = gyro(&f.plant, y);
    if f.rate_noise > 0.0 {
        for v in w.iter_mut().chain(m[6..8].iter_mut()) {
            *v += f.rate_noise * f.rng.normal();
        }
    }
    let l = momentum_from_rates(&r.cat, [m[4], m[5]], [m[6], m[7]], w);
    m[8..11].copy_from_slice(&l);
    m
}

/// Flies the design `r` under `fb` with the motor `motor` (saturation and
/// back-EMF at the actual joint speed).
pub fn fly(r: &Reference, fb: Feedback, motor: &Motor, f: Flight) -> Landing {
    fly_logged(r, fb, motor, f, None)
}

/// [`fly`], with every command appended to `log` (what a controller run
/// outside catflip, the Python package's, is checked against) and the true
/// state sampled ([`Log::every`]: what a replayed trial shows).
pub fn fly_logged(
    r: &Reference,
    fb: Feedback,
    motor: &Motor,
    mut f: Flight,
    mut log: Option<&mut Log>,
) -> Landing {
    let n = r.steps;
    // corrections by the step from which they act
    let mut queue: Vec<Option<[f64; 2]>> = vec![None; n + f.delay_steps + 2];
    let mut issued: Vec<[f64; 2]> = Vec::new();
    let (mut acting, mut noise) = ([0.0; 2], [0.0; 2]);
    let mut max_corr = 0.0f64;
    let mut y = f.release;
    // the full-state controllers act on the measurement as a simulator's world
    // gives it back (what `Online` is handed), to the last bit: a replan carries
    // those bits on, so the Python controller's flights are these
    let period = match fb {
        Feedback::Tvlqr(tv) | Feedback::Replan(tv, _) => tv.period_steps,
        Feedback::JointPd { .. } => 1,
    };
    // a replanning flight changes its own copy of the reference
    let mut replanned = match fb {
        Feedback::Replan(_, rp) => Some((r.clone(), InFlight::new(rp.design.clone()))),
        _ => None,
    };
    let finish = |y: Y, max_corr: f64, replanned: Option<(Reference, InFlight)>| {
        let error_deg = if y.iter().all(|v| v.is_finite()) {
            let rm = *attitude(&y).to_rotation_matrix().matrix();
            landing_error(&rm).to_degrees()
        } else {
            f64::NAN
        };
        Landing {
            error_deg,
            max_correction_nm: max_corr,
            state: y,
            replans: replanned.map(|(_, p)| p.records).unwrap_or_default(),
        }
    };
    for j in 0..n {
        if j % period == 0 {
            let u = match fb {
                Feedback::JointPd { kp, kd } => {
                    let m = measure(r, &mut f, &y);
                    Some((m, pd_command(r, kp, kd, j, &m)))
                }
                Feedback::Tvlqr(tv) => {
                    let k = j / period;
                    (k < tv.starts.len()).then(|| {
                        let m = measure(r, &mut f, &y);
                        let seen = from_sim(&to_sim(&m));
                        let u = tvlqr_command(r, tv, motor, &issued, k, &seen);
                        issued.push(u);
                        (m, u)
                    })
                }
                Feedback::Replan(tv, rp) => {
                    let k = j / period;
                    let (live, plan) = replanned.as_mut().expect("a replanning flight");
                    (k < tv.starts.len()).then(|| {
                        let m = measure(live, &mut f, &y);
                        let seen = from_sim(&to_sim(&m));
                        let u = tvlqr_command(live, tv, motor, &issued, k, &seen);
                        issued.push(u);
                        plan.replan(live, rp, tv, motor, &issued, k, &seen);
                        (m, u)
                    })
                }
            };
            if let Some((m, u)) = u {
                if let Some(log) = log.as_deref_mut() {
                    log.commands.push(Command {
                        step: j,
                        measured: m,
                        correction: u,
                    });
                }
                queue[j + f.delay_steps] = Some(u);
            }
        }
        if j % f.noise_steps == 0 && f.torque_noise > 0.0 {
            noise = [
                f.torque_noise * f.rng.normal(),
                f.torque_noise * f.rng.normal(),
            ];
        }
        if let Some(u) = queue[j] {
            acting = u;
            max_corr = max_corr.max(motor.norm.of(u));
        }
        let plant = f.plant;
        let live = replanned.as_ref().map_or(r, |(l, _)| l);
        let torque = |s: usize, ys: &Y| {
            let ff = live.ff_at(j, s);
            motor.clip([0, 1].map(|i| ff[i] + acting[i] + noise[i]), [ys[6], ys[7]])
        };
        // (the torque over the step from the state: only where it is logged)
        let sampling = log.as_deref_mut().filter(|l| l.every > 0);
        let acted = sampling.as_ref().map(|_| torque(0, &y));
        if let (Some(log), Some(t)) = (sampling, acted)
            && j % log.every == 0
        {
            log.samples.push(Sample {
                step: j,
                state: y,
                torque: t,
            });
        }
        y = rk4(&plant, &y, live.h, &torque);
        let diverged = !y.iter().all(|v| v.is_finite());
        if let (Some(log), Some(t), true) = (log.as_deref_mut(), acted, diverged || j + 1 == n) {
            log.samples.push(Sample {
                step: j + 1,
                state: y,
                torque: t,
            });
        }
        if diverged {
            return finish(y, max_corr, replanned);
        }
    }
    finish(y, max_corr, replanned)
}
