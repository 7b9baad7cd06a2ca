//! Replanning in flight (issue 27): the free-form design re-solved from a
//! state measured mid-manoeuvre, checked by flying the new plan from that
//! state in the closed-loop simulator's fixed-step model.

mod util;

use catflip::control::plant::{Y, attitude, rk4};
use catflip::control::reference::Reference;
use catflip::design::free::{FreeDesign, replan};
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
    let d = FreeDesign::new(&cfg).solve().unwrap();
    let r = Reference::new(&cfg, &d.plan);
    let j = (0.4 * d.plan.duration() / r.h) as usize;
    let t = j as f64 * r.h;
    let re = replan(&cfg, &d.plan, t, &r.nominal[j], cfg.free.nodes, 40).unwrap();
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
    let d = FreeDesign::new(&cfg).solve().unwrap();
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
    let re = replan(&cfg, &d.plan, t, &y, cfg.free.nodes, 40).unwrap();
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
