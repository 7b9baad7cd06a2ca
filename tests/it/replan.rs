//! Replanning in flight (issue 27): the free-form design re-solved from a
//! state measured mid-manoeuvre, checked by flying the new plan from that
//! state in the closed-loop simulator's fixed-step model.

use crate::util;

use catflip::control::plant::{Y, attitude, rk4};
use catflip::control::reference::Reference;
use catflip::design::free::{FreeDesign, Replanner, replan};
use catflip::design::plan::ShapePlan;
use catflip::design::scp::ScpStatus;
use catflip::model::momentum::landing_error;

/// Flies `plan`'s feed-forward from `y` (its time 0), then the margin with
/// no torque; the landing error, deg.
fn fly(cfg: &catflip::Config, plan: &dyn ShapePlan, y: Y) -> f64 {
    let cat = cfg.cat();
    let b = plan.phase_bounds();
    let mut y = y;
    let steps = 4000;
    for i in 0..3 {
        let h = (b[i + 1] - b[i]) / steps as f64;
        for k in 0..steps {
            let t0 = b[i] + h * k as f64;
            y = rk4(&cat, &y, h, |s, _| {
                plan.torque_in(&cat, i, t0 + 0.5 * h * s as f64)
            });
        }
    }
    let h = cfg.fall.margin / steps as f64;
    for _ in 0..steps {
        y = rk4(&cat, &y, h, |_, _| [0.0; 2]);
    }
    landing_error(attitude(&y).to_rotation_matrix().matrix()).to_degrees()
}

#[test]
fn a_replan_from_the_nominal_state_continues_the_design_and_lands() {
    let cfg = util::seed(&["design.objective=\"energy\""]);
    let d = FreeDesign::new(&cfg.design_spec()).solve().unwrap();
    let r = Reference::new(&cfg, &d.plan);
    let j = (0.4 * d.plan.duration() / r.h) as usize;
    let t = j as f64 * r.h;
    let re = replan(
        &cfg.design_spec(),
        &d.plan,
        t,
        &r.nominal[j],
        cfg.free.nodes,
        40,
    )
    .unwrap();
    assert_eq!(re.status, ScpStatus::Converged);
    // the rest of an energy optimum is the optimum of the rest (Bellman)
    let peak = r.peak_torque;
    let mut worst = 0.0f64;
    for k in 1..20 {
        let tau = re.plan.duration() * k as f64 / 20.0;
        let a = re.plan.torque_in(&cfg.cat(), phase_of(&re.plan, tau), tau);
        let b = d
            .plan
            .torque_in(&cfg.cat(), phase_of(&d.plan, t + tau), t + tau);
        worst = worst.max((a[0] - b[0]).hypot(a[1] - b[1]) / peak);
    }
    assert!(
        worst < 0.02,
        "the replan's torque differs by {worst:.3e} of the peak"
    );
    assert!((re.plan.duration() + t - d.plan.duration()).abs() < 1e-3 * d.plan.duration());
    let e = fly(&cfg, &re.plan, r.nominal[j]);
    assert!(e < 1e-2, "the replan lands {e} deg off");
}

fn phase_of(plan: &dyn ShapePlan, t: f64) -> usize {
    let b = plan.phase_bounds();
    (0..3).find(|&i| t < b[i + 1]).unwrap_or(2)
}

#[test]
fn a_replan_from_a_perturbed_state_lands_where_the_plan_would_not() {
    let cfg = util::seed(&[]);
    let d = FreeDesign::new(&cfg.design_spec()).solve().unwrap();
    let r = Reference::new(&cfg, &d.plan);
    let j = (0.3 * d.plan.duration() / r.h) as usize;
    let t = j as f64 * r.h;
    // knocked: the joints' rates off and a spin about the release's spine
    // (world z); a no-twist cat cannot undo a tilt of its spine at zero
    // momentum (docs/model.md, "What cannot be undone"), so none is added
    let mut y = r.nominal[j];
    y[6] += 0.4;
    y[7] -= 0.3;
    let dl = attitude(&y).inverse() * nalgebra::Vector3::new(0.0, 0.0, 0.004);
    for c in 0..3 {
        y[8 + c] += dl[c];
    }
    let plain = fly(&cfg, &Shifted(&d.plan, t), y);
    assert!(plain > 2.0, "the old plan would land {plain} deg off");
    let re = replan(&cfg.design_spec(), &d.plan, t, &y, cfg.free.nodes, 40).unwrap();
    let e = fly(&cfg, &re.plan, y);
    assert!(
        e < 1e-2,
        "the replan lands {e} deg off ({:?}, {} iterations, own {} rad)",
        re.status,
        re.scp_iterations,
        re.landing_error_rad
    );
    println!(
        "replan: {:?}, {} iterations, {:.3} s",
        re.status, re.scp_iterations, re.seconds
    );
}

/// A plan from `t0` on, its time 0 at `t0`.
struct Shifted<'a>(&'a dyn ShapePlan, f64);

impl ShapePlan for Shifted<'_> {
    fn phase_bounds(&self) -> Vec<f64> {
        let b = self.0.phase_bounds();
        let i = (0..3).find(|&i| self.1 < b[i + 1]).unwrap_or(2);
        let mut out = vec![0.0];
        for (k, x) in b.iter().enumerate().skip(1) {
            out.push(if k <= i { 0.0 } else { x - self.1 });
        }
        out
    }
    fn state_in(&self, i: usize, t: f64) -> catflip::design::plan::ShapeState {
        self.0.state_in(i, t + self.1)
    }
    fn torque_in(&self, cat: &catflip::model::Cat, i: usize, t: f64) -> [f64; 2] {
        self.0.torque_in(cat, i, t + self.1)
    }
}

/// Flies `plan` (its time 0 at flight time `origin`) from `y` at `a` to `b`
/// in RK4 steps of at most `h`, split at its phase bounds (the acceleration
/// jumps there), with no torque after its end.
fn fly_span(cfg: &catflip::Config, plan: &dyn ShapePlan, origin: f64, y: Y, a: f64, b: f64) -> Y {
    let cat = cfg.cat();
    let h = 5e-4;
    let bounds: Vec<f64> = plan.phase_bounds().iter().map(|x| x + origin).collect();
    let mut cuts = vec![a];
    cuts.extend(bounds.iter().copied().filter(|&x| x > a && x < b));
    cuts.push(b);
    let mut y = y;
    for w in cuts.windows(2) {
        let mid = 0.5 * (w[0] + w[1]);
        let phase = (0..3).find(|&i| mid < bounds[i + 1]);
        let n = ((w[1] - w[0]) / h).ceil().max(1.0) as usize;
        let step = (w[1] - w[0]) / n as f64;
        for s in 0..n {
            let t0 = w[0] + step * s as f64;
            y = rk4(&cat, &y, step, |stage, _| match phase {
                Some(i) => plan.torque_in(&cat, i, t0 + 0.5 * step * stage as f64 - origin),
                None => [0.0; 2],
            });
        }
    }
    y
}

#[test]
fn one_iteration_replans_every_control_period_land_a_knocked_flight() {
    // a real-time iteration: the flight knocked at 30 % of the manoeuvre
    // (as above), replanned every control period from the model's state
    // under the latest plan with one SCP iteration on a coarse mesh, each
    // replan started from the last one's plan and end state
    let cfg = util::seed(&[]);
    let d = FreeDesign::new(&cfg.design_spec()).solve().unwrap();
    let end = d.plan.duration();
    let period = 1.0 / cfg.control.rate_hz;
    let knock = (0.3 * end / period).round() * period;
    let mut y = catflip::control::reference::release(&cfg.cat(), &cfg.start.start());
    y = fly_span(&cfg, &d.plan, 0.0, y, 0.0, knock);
    y[6] += 0.4;
    y[7] -= 0.3;
    let dl = attitude(&y).inverse() * nalgebra::Vector3::new(0.0, 0.0, 0.004);
    for c in 0..3 {
        y[8 + c] += dl[c];
    }
    let old = fly_span(&cfg, &d.plan, 0.0, y, knock, cfg.fall_time());
    let old = landing_error(attitude(&old).to_rotation_matrix().matrix()).to_degrees();
    assert!(old > 2.0, "the old plan would land {old} deg off");
    let mut replanner = Replanner::new(&cfg.design_spec(), 10).unwrap().real_time();
    let (mut plan, mut origin, mut t) = (d.plan.clone(), 0.0, knock);
    let mut replans = 0;
    // replans up to two periods before the manoeuvre's end; the last plan is flown out
    while t < origin + plan.duration() - 2.0 * period {
        let re = replanner.replan(&plan, origin, t, &y, 1).unwrap();
        assert_eq!(re.scp_iterations, 1);
        assert!(t + re.plan.duration() <= cfg.available_time() * (1.0 + 1e-12));
        (plan, origin) = (re.plan, t);
        y = fly_span(&cfg, &plan, origin, y, t, t + period);
        t += period;
        replans += 1;
    }
    y = fly_span(&cfg, &plan, origin, y, t, cfg.fall_time());
    let e = landing_error(attitude(&y).to_rotation_matrix().matrix()).to_degrees();
    assert!(replans > 90, "{replans} replans");
    assert!(
        e < 1e-3,
        "the replanned flight lands {e} deg off (open loop {old} deg)"
    );
    println!("{replans} one-iteration replans: lands {e:.2e} deg off, open loop {old:.1} deg");
}
