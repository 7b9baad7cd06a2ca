//! The nominal motion a controller tracks: a design's feed-forward torque
//! on the fixed-step grid of the closed-loop simulator, and the state the
//! model reaches under it from the config's start, through `fall.margin`
//! (straight, no torque) to touchdown.

use super::plant::{Y, rk4};
use crate::config::Config;
use crate::design::plan::ShapePlan;
use crate::model::Cat;
use crate::model::momentum::Start;
use crate::model::motor::Motor;

/// A design sampled for the closed loop.
#[derive(Debug, Clone)]
pub struct Reference {
    /// The model the design was made for.
    pub cat: Cat,
    /// Simulator step, s: touchdown at `steps * h` exactly.
    pub h: f64,
    pub steps: usize,
    /// Feed-forward torque at every half step, `2 * steps + 1` values.
    pub ff: Vec<[f64; 2]>,
    /// Planned shape `(q, q_dot)` at every step (the joint PD's reference).
    pub shape: Vec<([f64; 2], [f64; 2])>,
    /// The model's state under the feed-forward alone at every step.
    pub nominal: Vec<Y>,
    /// Largest feed-forward torque (in the config's norm), N m: the torque scale.
    pub peak_torque: f64,
}

/// The integrator state of a straight, rigid release.
pub fn release(cat: &Cat, start: &Start) -> Y {
    let (a, l) = (start.attitude, start.body_momentum(cat));
    [a[0], a[1], a[2], a[3], 0.0, 0.0, 0.0, 0.0, l[0], l[1], l[2]]
}

impl Reference {
    pub fn new(cfg: &Config, plan: &dyn ShapePlan) -> Reference {
        let cat = cfg.cat();
        let tf = cfg.fall_time();
        let steps = (tf * cfg.control.sim_rate_hz).ceil().max(1.0) as usize;
        let h = tf / steps as f64;
        let mut r = Reference {
            cat,
            h,
            steps,
            ff: vec![[0.0; 2]; 2 * steps + 1],
            shape: vec![([0.0; 2], [0.0; 2]); steps + 1],
            nominal: vec![[0.0; 11]; steps + 1],
            peak_torque: 0.0,
        };
        r.splice(0, release(&cat, &cfg.start.start()), plan);
        let norm = cfg.norm();
        r.peak_torque = r.ff.iter().map(|t| norm.of(*t)).fold(0.0, f64::max);
        r
    }

    /// Replaces the motion from step `from` on by `plan` (its time 0 at
    /// that step) flown by the model from the state `y`: what a replan in
    /// flight changes. The steps before keep their values, so does the
    /// torque scale; the sample at `from` itself (shared with the end of
    /// the step before) is the new plan's.
    pub fn splice(&mut self, from: usize, y: Y, plan: &dyn ShapePlan) {
        self.replace_plan(from, plan);
        self.fly_from(from, y, None);
    }

    /// The feed-forward and the planned shape from step `from` on: `plan`'s,
    /// its time 0 at that step.
    pub fn replace_plan(&mut self, from: usize, plan: &dyn ShapePlan) {
        let (cat, h, steps) = (self.cat, self.h, self.steps);
        let t0 = h * from as f64;
        let b = plan.phase_bounds();
        let end = plan.duration();
        let phase = |t: f64| (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
        for j in 2 * from..=2 * steps {
            let t = 0.5 * h * j as f64 - t0;
            self.ff[j] = if t >= end {
                [0.0; 2]
            } else {
                plan.torque_in(&cat, phase(t), t)
            };
        }
        for j in from..=steps {
            let s = plan.state((h * j as f64 - t0).min(end));
            self.shape[j] = (s.q, s.qd);
        }
    }

    /// The nominal from step `from` on: the model flown from `y` there under
    /// the feed-forward, inside `motor`'s envelope when given (a replan's plan
    /// may leave it by what one SCP iteration leaves unmet; a design does not).
    pub fn fly_from(&mut self, from: usize, y: Y, motor: Option<&Motor>) {
        let (cat, h, steps) = (self.cat, self.h, self.steps);
        self.nominal[from] = y;
        for j in from..steps {
            let ff = &self.ff;
            self.nominal[j + 1] = rk4(&cat, &self.nominal[j], h, |s, ys| {
                motor.map_or(ff[2 * j + s], |m| m.clip(ff[2 * j + s], [ys[6], ys[7]]))
            });
        }
    }

    /// The feed-forward at stage `s` (0 start, 1 middle, 2 end) of step `j`.
    pub fn ff_at(&self, j: usize, s: usize) -> [f64; 2] {
        self.ff[2 * j + s]
    }

    /// Touchdown time, s.
    pub fn duration(&self) -> f64 {
        self.h * self.steps as f64
    }
}
