//! The nominal motion a controller tracks: a design's feed-forward torque
//! on the fixed-step grid of the closed-loop simulator, and the state the
//! model reaches under it from the config's start, through `fall.margin`
//! (straight, no torque) to touchdown.

use super::plant::{Y, rk4};
use crate::config::Config;
use crate::design::plan::ShapePlan;
use crate::model::Cat;
use crate::model::momentum::Start;

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
        let b = plan.phase_bounds();
        let end = plan.duration();
        let phase = |t: f64| (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
        let ff: Vec<[f64; 2]> = (0..=2 * steps)
            .map(|j| {
                let t = 0.5 * h * j as f64;
                if t >= end {
                    [0.0; 2]
                } else {
                    plan.torque_in(&cat, phase(t), t)
                }
            })
            .collect();
        let shape = (0..=steps)
            .map(|j| {
                let s = plan.state((h * j as f64).min(end));
                (s.q, s.qd)
            })
            .collect();
        let mut nominal = Vec::with_capacity(steps + 1);
        let mut y = release(&cat, &cfg.start.start());
        nominal.push(y);
        for j in 0..steps {
            y = rk4(&cat, &y, h, |s, _| ff[2 * j + s]);
            nominal.push(y);
        }
        let norm = cfg.norm();
        let peak_torque = ff.iter().map(|t| norm.of(*t)).fold(0.0, f64::max);
        Reference {
            cat,
            h,
            steps,
            ff,
            shape,
            nominal,
            peak_torque,
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
