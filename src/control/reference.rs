//! The nominal motion a controller tracks: a design's feed-forward torque
//! on the fixed-step grid of the closed-loop simulator, and the state the
//! model reaches under it from the config's start, through `fall.margin`
//! (straight, no torque) to touchdown. The feed-forward also holds the
//! planned shape ([`Reference::new`]).

use super::plant::{Y, rk4};
use crate::config::Config;
use crate::design::plan::ShapePlan;
use crate::model::Cat;
use crate::model::momentum::Start;
use crate::model::motor::Motor;
use std::sync::Arc;

/// A design sampled for the closed loop.
#[derive(Debug, Clone)]
pub struct Reference {
    /// The model the design was made for.
    pub cat: Cat,
    /// Simulator step, s: touchdown at `steps * h` exactly.
    pub h: f64,
    pub steps: usize,
    /// Feed-forward torque at every half step, `2 * steps + 1` values (with
    /// the holding torque of a held nominal).
    pub ff: Vec<[f64; 2]>,
    /// Planned shape `(q, q_dot)` at every step (the joint PD's reference).
    pub shape: Vec<([f64; 2], [f64; 2])>,
    /// The model's state under the feed-forward alone at every step.
    pub nominal: Vec<Y>,
    /// Largest feed-forward torque (in the config's norm), N m: the torque scale.
    pub peak_torque: f64,
    /// `nominal` holds from `flown` on only once [`Reference::extend_nominal`]
    /// has flown it there (a replan's plan is flown a few periods at a time).
    pub flown: usize,
    /// The envelope the rest of the nominal is flown inside.
    pending_motor: Option<Motor>,
    /// `ff` holds up to this half step (and `shape` up to half of it); the
    /// rest is `pending`'s, sampled by [`Reference::ff_value`] and filled
    /// by [`Reference::extend_nominal`] as the nominal is flown.
    pub ff_filled: usize,
    pending: Option<Pending>,
    /// Where `nominal` is not flown yet: the model's state on the control
    /// steps as a flight on long steps estimates it (a comparison's nominal).
    pub rough: Vec<Option<Y>>,
    /// The design's nominal flown held ([`Reference::fly_held`]): `ff`
    /// carries the holding torque too.
    held: bool,
}

/// A plan whose samples are taken as they are needed: its time 0 at step `from`.
#[derive(Clone)]
struct Pending {
    plan: Arc<dyn ShapePlan + Send + Sync>,
    from: usize,
}

impl std::fmt::Debug for Pending {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pending")
            .field("from", &self.from)
            .finish_non_exhaustive()
    }
}

/// The integrator state of a straight, rigid release.
pub fn release(cat: &Cat, start: &Start) -> Y {
    let (a, l) = (start.attitude, start.body_momentum(cat));
    [a[0], a[1], a[2], a[3], 0.0, 0.0, 0.0, 0.0, l[0], l[1], l[2]]
}

impl Reference {
    /// The design's nominal for a full-state feedback: held on the planned
    /// shape ([`Reference::fly_held`]; the feed-forward's flight without
    /// PD gains).
    pub fn new(cfg: &Config, plan: &dyn ShapePlan) -> Reference {
        Self::build(cfg, plan, true)
    }

    /// [`Reference::new`], refused where its nominal diverges: a simulator
    /// step too coarse for the joint PD that holds it (at 100 Hz the held
    /// seed flies to NaN, and so would every gain and trial along it).
    pub fn checked(cfg: &Config, plan: &dyn ShapePlan) -> crate::Result<Reference> {
        let r = Self::new(cfg, plan);
        if r.nominal.iter().flatten().all(|v| v.is_finite()) {
            return Ok(r);
        }
        Err(crate::Error::Invalid {
            key: "control.sim_rate_hz".into(),
            value: format!("{}", cfg.control.sim_rate_hz),
            expected: format!(
                "the design's nominal flight diverges at this step ({:.3} ms) under the joint PD that \
                 holds it (simulate.pd_bandwidth_hz = {} Hz); raise control.sim_rate_hz (default 4000 Hz) \
                 or lower simulate.pd_bandwidth_hz",
                1e3 * r.h,
                cfg.simulate.pd_bandwidth_hz
            ),
        })
    }

    /// The feed-forward's flight from any start, never held: what the joint
    /// PD of the open loop adds its correction to (a held feed-forward would
    /// carry a second PD).
    pub fn unheld(cfg: &Config, plan: &dyn ShapePlan) -> Reference {
        Self::build(cfg, plan, false)
    }

    /// The open loop's reference for `plan` (this one made by
    /// [`Reference::new`] from it): itself, or its unheld twin when held.
    pub fn for_open_loop(&self, cfg: &Config, plan: &dyn ShapePlan) -> Reference {
        if self.held {
            Self::unheld(cfg, plan)
        } else {
            self.clone()
        }
    }

    /// Whether the design's nominal was flown held ([`Reference::fly_held`];
    /// a replan's plan, spliced in later, is not).
    pub fn is_held(&self) -> bool {
        self.held
    }

    fn build(cfg: &Config, plan: &dyn ShapePlan, hold: bool) -> Reference {
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
            flown: steps,
            pending_motor: None,
            ff_filled: 2 * steps,
            pending: None,
            rough: Vec::new(),
            held: false,
        };
        let spec = cfg.design_spec();
        let y0 = release(&cat, &spec.release());
        let pd = crate::verify::simulate::Controller::from_spec(&spec);
        if hold && (pd.kp, pd.kd) != (0.0, 0.0) {
            r.replace_plan(0, plan);
            r.fly_held(y0, pd.kp, pd.kd, &cfg.motor());
        } else {
            r.splice(0, y0, plan);
        }
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
        self.pending = None;
        self.ff_filled = 2 * self.steps;
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

    /// [`Reference::replace_plan`] deferred: the samples from step `from`
    /// on are `plan`'s, taken as they are needed, the same numbers to the bit.
    pub fn replace_plan_lazily(&mut self, from: usize, plan: Arc<dyn ShapePlan + Send + Sync>) {
        self.pending = Some(Pending { plan, from });
        self.ff_filled = (2 * from).saturating_sub(1);
    }

    /// The pending plan's sample at half step `j` and its shape at step `j / 2`.
    fn sample(&self, p: &Pending, j: usize) -> [f64; 2] {
        let t0 = self.h * p.from as f64;
        let end = p.plan.duration();
        let t = 0.5 * self.h * j as f64 - t0;
        if t >= end {
            [0.0; 2]
        } else {
            let b = p.plan.phase_bounds();
            let phase = (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
            p.plan.torque_in(&self.cat, phase, t)
        }
    }

    /// The feed-forward at half step `j`, filled or not.
    pub fn ff_value(&self, j: usize) -> [f64; 2] {
        match &self.pending {
            Some(p) if j > self.ff_filled => self.sample(p, j),
            _ => self.ff[j],
        }
    }

    /// Fills the feed-forward up to half step `to` (and the shape to `to / 2`).
    pub fn fill_ff(&mut self, to: usize) {
        let Some(p) = self.pending.clone() else {
            return;
        };
        let to = to.min(2 * self.steps);
        let (h, end) = (self.h, p.plan.duration());
        let t0 = h * p.from as f64;
        for j in self.ff_filled + 1..=to {
            self.ff[j] = self.sample(&p, j);
            if j % 2 == 0 && j / 2 >= p.from {
                let s = p.plan.state((h * (j / 2) as f64 - t0).min(end));
                self.shape[j / 2] = (s.q, s.qd);
            }
        }
        self.ff_filled = self.ff_filled.max(to);
        if self.ff_filled == 2 * self.steps {
            self.pending = None;
        }
    }

    /// The nominal from step `from` on: the model flown from `y` there under
    /// the feed-forward, inside `motor`'s envelope when given (a replan's plan
    /// may leave it by what one SCP iteration leaves unmet; a design does not).
    pub fn fly_from(&mut self, from: usize, y: Y, motor: Option<&Motor>) {
        self.fly_lazily(from, y, motor);
        self.extend_nominal(self.steps);
    }

    /// The nominal from the release `y`, the planned shape held by the
    /// joint PD (`kp`, `kd`, from the state at each step's start: its torque
    /// acts from the step's end, the mean of the last and the new one at the
    /// step's middle), inside `motor`'s envelope, its torque folded into the
    /// feed-forward, so that the feed-forward flown alone is the nominal
    /// still. From a start with momentum the flight under the plan's
    /// feed-forward alone is unstable and loses the design; from one at rest
    /// it drifts from the design by what the transcription leaves between
    /// its nodes: the nominal, and the TVLQR about it, must be the design's
    /// motion.
    fn fly_held(&mut self, y: Y, kp: f64, kd: f64, motor: &Motor) {
        self.nominal[0] = y;
        let (cat, h) = (self.cat, self.h);
        let mut hold = [0.0; 2];
        for j in 0..self.steps {
            let (q, qd) = self.shape[j];
            let x = &self.nominal[j];
            let next = [0, 1].map(|i| kp * (q[i] - x[4 + i]) + kd * (qd[i] - x[6 + i]));
            for i in 0..2 {
                self.ff[2 * j + 1][i] += 0.5 * (hold[i] + next[i]);
                self.ff[2 * j + 2][i] += next[i];
            }
            hold = next;
            let ff = &self.ff;
            self.nominal[j + 1] = rk4(&cat, &self.nominal[j], h, |s, ys| {
                motor.clip(ff[2 * j + s], [ys[6], ys[7]])
            });
        }
        self.flown = self.steps;
        self.held = true;
    }

    /// [`Reference::fly_from`] deferred: the nominal from `from` on is flown
    /// by [`Reference::extend_nominal`] as far as it is asked for, the same
    /// numbers to the bit.
    pub fn fly_lazily(&mut self, from: usize, y: Y, motor: Option<&Motor>) {
        self.nominal[from] = y;
        self.flown = from;
        self.pending_motor = motor.copied();
        self.rough.clear();
    }

    /// Flies the nominal on to step `to` (at most touchdown).
    pub fn extend_nominal(&mut self, to: usize) {
        self.fill_ff(2 * to.min(self.steps));
        let (cat, h) = (self.cat, self.h);
        let motor = self.pending_motor;
        for j in self.flown..to.min(self.steps) {
            let ff = &self.ff;
            self.nominal[j + 1] = rk4(&cat, &self.nominal[j], h, |s, ys| {
                motor.map_or(ff[2 * j + s], |m| m.clip(ff[2 * j + s], [ys[6], ys[7]]))
            });
            self.flown = j + 1;
        }
    }

    /// A copy with the feed-forward, the shape and the nominal all filled in
    /// (this one's later flight unchanged: its comparisons read its rough estimate).
    pub fn completed(&self) -> Reference {
        let mut r = self.clone();
        r.extend_nominal(r.steps);
        r
    }

    /// The nominal at step `j` if flown, else its rough estimate (if any).
    pub fn nominal_or_rough(&self, j: usize) -> Option<&Y> {
        if j <= self.flown {
            Some(&self.nominal[j])
        } else {
            self.rough.get(j).and_then(|y| y.as_ref())
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
