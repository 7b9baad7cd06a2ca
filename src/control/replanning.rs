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

use super::plant::{Y, attitude};
use super::reference::Reference;
use super::tvlqr::{Tvlqr, predict};
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

/// How many control steps the screen's reference landing holds, and its
/// slack, rad: a plan whose landing on long steps is over twice the
/// reference plus the slack is dropped without the comparison.
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
        let clock = std::time::Instant::now();
        // a taken plan's nominal is flown a little ahead of the commands each
        // period (two periods' steps), not to touchdown at once
        let p = tv.period_steps;
        let need = tv.starts.get(k + 1).copied().unwrap_or(r.steps) + p;
        r.extend_nominal(need.max(r.flown + 2 * p));
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
                let cmp = Comparison {
                    from: s,
                    y,
                    motor,
                    tv,
                    in_use: breaks(r, self.plan.as_ref(), self.offset),
                    new: breaks(r, new.as_ref(), t),
                };
                let (cat, h) = (r.cat, r.h);
                let ff =
                    |j: usize| torque_of(new.as_ref(), &cat, 0.5 * h * (j as f64 - 2.0 * s as f64));
                // screened first against the last comparison's landing of the
                // plan in use: most one-iteration plans land far worse (the
                // solve's own landing error is a free first screen: its
                // one-iteration plans landed worse in the simulator than on
                // their own map in every case measured)
                let fresh = self.in_use.filter(|&(at, _)| k < at + REFRESH);
                let bar = fresh.map(|(_, est)| 2.0 * est + SCREEN_SLACK);
                let next_long = if bar.is_some_and(|b| own > b) {
                    f64::INFINITY
                } else {
                    cmp.new_plan(r, &ff, p)
                };
                let better = if bar.is_some_and(|b| next_long > b) {
                    None
                } else {
                    let (better, now) = cmp.decide(r, next_long);
                    self.in_use = Some((k, now));
                    Some(better)
                };
                if late(&clock) {
                    Outcome::Late
                } else if better == Some(true) {
                    r.replace_plan_lazily(s, new.clone());
                    r.fill_ff(2 * s);
                    let y = predict(r, tv, motor, issued, s - 1, s, &before);
                    // its nominal: flown ahead of the commands period by period,
                    // estimated on long steps meanwhile for the comparisons
                    r.fly_lazily(s, y, Some(motor));
                    let mut rough = vec![None; r.steps + 1];
                    let fine = breaks(r, new.as_ref(), t);
                    landing_on(
                        r,
                        s,
                        &y,
                        |j| r.ff_value(j),
                        None,
                        motor,
                        p,
                        &fine,
                        Some(&mut rough),
                    );
                    r.rough = rough;
                    r.extend_nominal(need.max(s + 2 * p));
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

/// The take-or-keep comparison of one replan: the model flown from the
/// predicted state `y` at step `from` to touchdown under the new plan's
/// feed-forward and under the plan in use with the TVLQR correcting about
/// its nominal.
///
/// Both are flown on long steps (one a control period), each long step
/// ending at the plans' torque jumps (phase junctions, nodes, the end),
/// which are taken on the simulator's own steps: there RK4 converges at its
/// order, so the long steps decide as the simulator's steps would except on
/// near ties (and where the motor envelope's kinks slow RK4's convergence),
/// where either plan lands about as well. A flight that blows up on the
/// long steps lands infinitely far off: the other plan wins.
pub struct Comparison<'a> {
    pub from: usize,
    pub y: Y,
    pub motor: &'a Motor,
    pub tv: &'a Tvlqr,
    /// Steps at the torque jumps of the plan in use and of the new plan.
    pub in_use: Vec<usize>,
    pub new: Vec<usize>,
}

impl Comparison<'_> {
    /// The new plan's landing error, rad, on steps of `stride`.
    pub fn new_plan(&self, r: &Reference, ff: &impl Fn(usize) -> [f64; 2], stride: usize) -> f64 {
        landing_on(
            r, self.from, &self.y, ff, None, self.motor, stride, &self.new, None,
        )
    }

    /// The plan in use's landing error under the TVLQR, rad, on steps of `stride`.
    pub fn in_use(&self, r: &Reference, stride: usize) -> f64 {
        let tv = Some(self.tv);
        landing_on(
            r,
            self.from,
            &self.y,
            |j| r.ff_value(j),
            tv,
            self.motor,
            stride,
            &self.in_use,
            None,
        )
    }

    /// Whether the new plan, landing `next` rad off on the long steps, lands
    /// the model at least as well as the plan in use, and the plan in use's
    /// landing error there.
    pub fn decide(&self, r: &mut Reference, next: f64) -> (bool, f64) {
        let p = self.tv.period_steps;
        // a nominal neither flown nor estimated that far: fly it
        let mut now = self.in_use(r, p);
        if now.is_nan() {
            r.extend_nominal(r.steps);
            now = self.in_use(r, p);
        }
        (next.is_finite() && next <= now, now)
    }

    /// The decision on the simulator's steps: what the long steps' decision
    /// is checked against (tests/it/replanning.rs), too slow for a period.
    pub fn exact(&self, r: &mut Reference, ff: &impl Fn(usize) -> [f64; 2]) -> (bool, f64) {
        r.extend_nominal(r.steps);
        let now = self.in_use(r, 1);
        (self.new_plan(r, ff, 1) <= now, now)
    }
}

/// The steps around the torque jumps of `plan` (time 0 at flight time
/// `offset`): the simulator's step in which each [`ShapePlan::breaks`] falls, sorted.
pub fn breaks(r: &Reference, plan: &dyn ShapePlan, offset: f64) -> Vec<usize> {
    let mut out: Vec<usize> = plan
        .breaks()
        .iter()
        .map(|b| ((offset + b) / r.h).floor() as usize)
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The feed-forward of `plan` at its time `t` (none after its end).
pub fn torque_of(plan: &dyn ShapePlan, cat: &Cat, t: f64) -> [f64; 2] {
    let b = plan.phase_bounds();
    if t >= b[3] {
        return [0.0; 2];
    }
    let i = (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
    plan.torque_in(cat, i, t.max(0.0))
}

/// The landing error, rad, of the model flown from `y` at step `from` to
/// touchdown under the feed-forward `ff(half step)` (inside `motor`'s
/// envelope) and, with `tvlqr`, its gains about the nominal of `r` (each
/// correction from the state at its start, no delay; beyond the nominal
/// flown, about its rough estimate), on steps of `stride` simulator steps
/// aligned with the control steps, the steps in `fine` (sorted) single, the
/// last one what remains; `rough` takes the state at each step's end.
/// A flight that blows up lands infinitely far off.
#[allow(clippy::too_many_arguments)]
pub fn landing_on(
    r: &Reference,
    from: usize,
    y: &Y,
    ff: impl Fn(usize) -> [f64; 2],
    tvlqr: Option<&Tvlqr>,
    motor: &Motor,
    stride: usize,
    fine: &[usize],
    mut rough: Option<&mut Vec<Option<Y>>>,
) -> f64 {
    // an RK4 step asks for its middle twice and starts where the last ended:
    // the last two samples serve both (a plan's sample costs its inverse dynamics)
    let mut memo = [(usize::MAX, [0.0; 2]); 2];
    let mut ff = |i: usize| match memo.iter().find(|m| m.0 == i) {
        Some(m) => m.1,
        None => {
            let v = ff(i);
            memo = [(i, v), memo[0]];
            v
        }
    };
    let mut y = *y;
    let mut j = from;
    let mut u = [0.0; 2];
    let mut f = fine.partition_point(|&b| b < j);
    while j < r.steps {
        while f < fine.len() && fine[f] < j {
            f += 1;
        }
        let next_fine = fine.get(f).copied().unwrap_or(usize::MAX);
        let aligned = from + ((j - from) / stride + 1) * stride;
        let n = if next_fine == j {
            1
        } else {
            (aligned - j).min(next_fine - j).min(r.steps - j)
        };
        if let Some(tv) = tvlqr
            && let Some(k) = tv.interval_at(j)
            && tv.starts[k] == j
        {
            let Some(nom) = r.nominal_or_rough(j) else {
                return f64::NAN;
            };
            let x = super::plant::error(&y, nom);
            let mut c = -(tv.gains[k] * x);
            let size = motor.norm.of([c[0], c[1]]);
            if size > tv.max_correction {
                c *= tv.max_correction / size;
            }
            u = [c[0], c[1]];
        }
        y = super::plant::rk4(&r.cat, &y, r.h * n as f64, |st, ys| {
            let f = ff(2 * j + n * st);
            let want = [f[0] + u[0], f[1] + u[1]];
            // (a long step may blow a wild plan's flight up: no envelope for NaN)
            if !(ys[6].is_finite() && ys[7].is_finite()) {
                return want;
            }
            motor.clip(want, [ys[6], ys[7]])
        });
        j += n;
        if !y.iter().all(|v| v.is_finite()) {
            return f64::INFINITY;
        }
        if let Some(rough) = rough.as_deref_mut() {
            rough[j] = Some(y);
        }
    }
    if !y.iter().all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    landing_error(attitude(&y).to_rotation_matrix().matrix())
}
