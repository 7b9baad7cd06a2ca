//! Replanning in flight: at each replan instant the free-form design is
//! solved again ([`crate::design::free::Replanner`], one per flight, warm
//! from replan to replan) from the state predicted
//! at the instant the new plan can act (one control period to compute it,
//! then the actuator delay), warm-started from the plan in use, over the
//! time the fall still leaves. The new plan's feed-forward and the nominal
//! the model flies under it from that state replace the old ones from then
//! on; the design's TVLQR gains keep acting about whichever nominal is in use.
//!
//! A replan is dropped, and the plan in use continues, when the solve fails,
//! when it took longer than its wall-clock budget (a robot's real-time
//! rule; catflip's own study sets none, so that it stays deterministic), or
//! when the model flown from the predicted state under the new plan would
//! land worse than under the plan in use (a single SCP iteration may).

use super::closed_loop::predict;
use super::plant::{Y, attitude};
use super::reference::Reference;
use super::tvlqr::Tvlqr;
use crate::config::Config;
use crate::design::free::Replanner;
use crate::design::plan::ShapePlan;
use crate::model::Cat;
use crate::model::momentum::landing_error;
use crate::model::motor::Motor;
use std::sync::Arc;

/// A plan shared between flights and threads.
pub type SharedPlan = Arc<dyn ShapePlan + Send + Sync>;

/// How a controller replans.
#[derive(Clone)]
pub struct Replanning {
    /// The configuration the design was made for (the fall, the motors, `[free]`).
    pub cfg: Config,
    /// The design the flight starts on.
    pub design: SharedPlan,
    /// Collocation nodes per phase of a replan (`control.replan_nodes`).
    pub nodes: usize,
    /// SCP iterations of a replan at most (`control.replan_iterations`).
    pub iterations: usize,
    /// Control periods from one replan to the next (`control.replan_every`).
    pub every: usize,
    /// Wall-clock budget of one replan, s (None: every finished replan counts).
    pub budget_s: Option<f64>,
}

impl std::fmt::Debug for Replanning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Replanning")
            .field("nodes", &self.nodes)
            .field("iterations", &self.iterations)
            .field("every", &self.every)
            .field("budget_s", &self.budget_s)
            .finish_non_exhaustive()
    }
}

impl Replanning {
    /// The replanning `[control]` of `cfg` describes, from `design`, without a budget.
    pub fn new(cfg: &Config, design: SharedPlan) -> Replanning {
        Replanning {
            cfg: cfg.clone(),
            design,
            nodes: cfg.control.replan_nodes,
            iterations: cfg.control.replan_iterations,
            every: cfg.control.replan_every,
            budget_s: None,
        }
    }
}

/// What became of one replan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The new plan flies from its instant on.
    Taken,
    /// The solve returned an error or no usable plan.
    Failed,
    /// The solve took longer than the budget.
    Late,
    /// The new plan would land the model worse than the plan in use.
    Worse,
}

/// One replan of a flight.
#[derive(Debug, Clone, Copy)]
pub struct Record {
    /// Control step whose measurement it started from.
    pub step: usize,
    /// Wall time of the replan, s: the prediction, the solve, the comparison
    /// of the two plans and the splice of the one taken.
    pub seconds: f64,
    /// Of which the solve (`Replanner::replan`), s.
    pub solve_seconds: f64,
    pub outcome: Outcome,
}

/// The plan a replanning flight is on, and the one its replans iterate on.
///
/// A replan of one SCP iteration improves on the plan it starts from
/// without converging, so its plans form a chain (each the next one's start,
/// the real-time iteration), and the flight switches to the chain's latest
/// plan when the model, flown from the predicted state, lands better under
/// it than under the plan in use.
pub struct InFlight {
    plan: SharedPlan,
    /// Flight time of the plan's time 0, s.
    offset: f64,
    /// The chain's latest plan and its offset, when not the plan in use.
    candidate: Option<(SharedPlan, f64)>,
    /// Replans in a row the chain has not been taken.
    misses: usize,
    /// The control step of the last full comparison and the landing error,
    /// rad, it found for the plan in use.
    in_use: Option<(usize, f64)>,
    pub records: Vec<Record>,
    /// The flight's solver state (made at its first replan), warm from replan to replan.
    replanner: Option<Replanner>,
}

impl Clone for InFlight {
    /// A copy starts its solver state afresh (the next replan makes it).
    fn clone(&self) -> Self {
        InFlight {
            plan: self.plan.clone(),
            offset: self.offset,
            candidate: self.candidate.clone(),
            misses: self.misses,
            in_use: self.in_use,
            records: self.records.clone(),
            replanner: None,
        }
    }
}

/// Replans in a row after which an untaken chain restarts from the plan in use.
const CHAIN_RESTART: usize = 8;

/// The screen's steps (simulator steps), how many control steps its
/// reference landing holds, and its slack, rad: a plan whose landing on the
/// screen's long steps is over twice the reference plus the slack is
/// dropped without the full comparison.
const SCREEN: usize = 4;
const REFRESH: usize = 5;
const SCREEN_SLACK: f64 = 0.02;

impl InFlight {
    pub fn new(design: SharedPlan) -> InFlight {
        InFlight {
            plan: design,
            offset: 0.0,
            candidate: None,
            misses: 0,
            in_use: None,
            records: Vec::new(),
            replanner: None,
        }
    }

    /// The replan of control step `k` from the measurement `m` (after its
    /// correction was issued): solved from the state predicted at the start
    /// of correction `k + 1`, and spliced into `r` from there when taken.
    #[allow(clippy::too_many_arguments)]
    pub fn replan(
        &mut self,
        r: &mut Reference,
        rp: &Replanning,
        tv: &Tvlqr,
        motor: &Motor,
        issued: &[[f64; 2]],
        k: usize,
        m: &Y,
    ) {
        if !k.is_multiple_of(rp.every.max(1)) || k + 1 >= tv.starts.len() {
            return;
        }
        let s = tv.starts[k + 1];
        let t = s as f64 * r.h;
        let (base, offset) = match &self.candidate {
            Some((p, o)) => (p.clone(), *o),
            None => (self.plan.clone(), self.offset),
        };
        // after the manoeuvre the shape is held straight: nothing to replan
        if t >= offset + base.duration() || s >= r.steps {
            return;
        }
        let clock = std::time::Instant::now();
        // (the step before `s` ends on the sample at `s`, which a plan taken replaces)
        let before = predict(r, tv, motor, issued, k * tv.period_steps, s - 1, m);
        let y = predict(r, tv, motor, issued, s - 1, s, &before);
        let solved = match &mut self.replanner {
            Some(p) => Ok(p),
            None => Replanner::new(&rp.cfg.design_spec(), rp.nodes)
                .map(|p| self.replanner.insert(p.real_time())),
        }
        .and_then(|p| p.replan(base.as_ref(), offset, t, &y, rp.iterations));
        let solve_seconds = solved.as_ref().map_or(0.0, |re| re.seconds);
        let late =
            |c: &std::time::Instant| rp.budget_s.is_some_and(|b| c.elapsed().as_secs_f64() > b);
        let outcome = match solved {
            Err(_) => Outcome::Failed,
            Ok(_) if late(&clock) => Outcome::Late,
            Ok(re) if !re.landing_error_rad.is_finite() => Outcome::Failed,
            Ok(re) => {
                let own = re.landing_error_rad;
                let new: SharedPlan = Arc::new(re.plan);
                let ff = |j: usize| {
                    torque_of(
                        new.as_ref(),
                        &r.cat,
                        0.5 * r.h * (j as f64 - 2.0 * s as f64),
                    )
                };
                // screened first on long steps against the last comparison's
                // landing of the plan in use: most one-iteration plans land far worse
                // (the solve's own landing error is a free first screen: its
                // one-iteration plans landed worse in the simulator than on
                // their own map in every case measured)
                let hopeless = self.in_use.is_some_and(|(at, est)| {
                    let bar = 2.0 * est + SCREEN_SLACK;
                    k < at + REFRESH
                        && (own > bar || landing_under(r, s, &y, ff, None, motor, SCREEN) > bar)
                });
                let (now, next) = if hopeless {
                    (0.0, f64::INFINITY)
                } else {
                    // the plan in use as the TVLQR flies it; the new one's nominal
                    // starts at the predicted state, so the TVLQR adds nothing to it
                    let now = landing_under(r, s, &y, |j| r.ff[j], Some(tv), motor, 1);
                    self.in_use = Some((k, now));
                    (now, landing_under(r, s, &y, ff, None, motor, 1))
                };
                if late(&clock) {
                    Outcome::Late
                } else if next <= now {
                    r.replace_plan(s, new.as_ref());
                    let y = predict(r, tv, motor, issued, s - 1, s, &before);
                    r.fly_from(s, y, Some(motor));
                    self.plan = new;
                    self.offset = t;
                    self.candidate = None;
                    self.misses = 0;
                    self.in_use = None;
                    Outcome::Taken
                } else {
                    self.misses += 1;
                    self.candidate = (self.misses < CHAIN_RESTART).then_some((new, t));
                    Outcome::Worse
                }
            }
        };
        if outcome != Outcome::Taken && outcome != Outcome::Worse {
            self.candidate = None;
        }
        self.records.push(Record {
            step: k,
            seconds: clock.elapsed().as_secs_f64(),
            solve_seconds,
            outcome,
        });
    }
}

/// The feed-forward of `plan` at its time `t` (none after its end).
fn torque_of(plan: &dyn ShapePlan, cat: &Cat, t: f64) -> [f64; 2] {
    let b = plan.phase_bounds();
    if t >= b[3] {
        return [0.0; 2];
    }
    let i = (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
    plan.torque_in(cat, i, t.max(0.0))
}

/// The landing error, rad, of the model flown from `y` at step `from` to
/// touchdown under the feed-forward `ff(half step)` (inside `motor`'s
/// envelope) and, with `tvlqr`, its
/// gains about the nominal of `r` (each correction from the state at its
/// start, no delay), on steps of `stride` simulator steps (the last ones
/// single): two plans are compared on the simulator's own steps (on steps
/// four times as long the comparison misjudged spinning flights, whose
/// landing is sensitive, and took plans that landed worse), the long steps
/// only screen.
fn landing_under(
    r: &Reference,
    from: usize,
    y: &Y,
    ff: impl Fn(usize) -> [f64; 2],
    tvlqr: Option<&Tvlqr>,
    motor: &Motor,
    stride: usize,
) -> f64 {
    let mut y = *y;
    let mut j = from;
    let mut u = [0.0; 2];
    while j < r.steps {
        let n = if j + stride <= r.steps { stride } else { 1 };
        if let Some(tv) = tvlqr
            && let Some(k) = tv.interval_at(j)
            && tv.starts[k] == j
        {
            let x = super::plant::error(&y, &r.nominal[j]);
            let mut c = -(tv.gains[k] * x);
            let size = motor.norm.of([c[0], c[1]]);
            if size > tv.max_correction {
                c *= tv.max_correction / size;
            }
            u = [c[0], c[1]];
        }
        y = super::plant::rk4(&r.cat, &y, r.h * n as f64, |st, ys| {
            let f = ff(2 * j + n * st);
            motor.clip([f[0] + u[0], f[1] + u[1]], [ys[6], ys[7]])
        });
        j += n;
    }
    if !y.iter().all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    landing_error(attitude(&y).to_rotation_matrix().matrix())
}
