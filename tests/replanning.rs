//! The replanning controller of issue 27: the free-form design solved again
//! in flight from the predicted state, about which the design's TVLQR gains act.

mod util;

use catflip::control::closed_loop::{Feedback, Flight, fly};
use catflip::control::reference::Reference;
use catflip::control::replanning::{Outcome, Replanning, SharedPlan};
use catflip::control::robustness::trial_flight;
use catflip::control::tvlqr::Tvlqr;
use std::sync::Arc;

/// The seed's study design and gains, under a spin-only `[robustness]`
/// (no model error, delay or noise: the spin is all the TVLQR must undo).
fn spin_only() -> (catflip::Config, Reference, Tvlqr, SharedPlan) {
    let cfg = util::seed(&[
        "robustness.tilt_deg=0",
        "robustness.inertia_error=0",
        "robustness.delay_ms=0",
        "robustness.torque_noise=0",
        "control.delay_ms=0",
    ]);
    let plan: SharedPlan = Arc::new(catflip::control::robustness::design(&cfg).unwrap().plan);
    let r = Reference::new(&cfg, plan.as_ref());
    let tv = Tvlqr::new(&r, &cfg.control);
    (cfg, r, tv, plan)
}

#[test]
fn on_the_nominal_model_replanning_flies_the_design() {
    let (cfg, r, tv, plan) = spin_only();
    let motor = cfg.motor();
    let rp = Replanning {
        every: 5,
        ..Replanning::new(&cfg, plan)
    };
    let closed = fly(&r, Feedback::Tvlqr(&tv), &motor, Flight::nominal(&r));
    let re = fly(&r, Feedback::Replan(&tv, &rp), &motor, Flight::nominal(&r));
    assert!(!re.replans.is_empty());
    // a taken plan's nominal starts where the model is: nothing to correct
    assert!(
        re.max_correction_nm < 1e-9 * r.peak_torque,
        "correction {} N m on the nominal",
        re.max_correction_nm
    );
    // a plan is taken only where it lands the model better than the plan in use (to
    // the model's sensitivity over the rest of the fall: its first step is flown
    // again on the taken plan's first torque sample)
    assert!(
        re.error_deg <= closed.error_deg + 1e-3 && re.error_deg < 0.05,
        "replanning lands {} deg, the TVLQR {} deg",
        re.error_deg,
        closed.error_deg
    );
}

#[test]
fn a_replan_over_its_budget_leaves_the_plan_in_use_flying() {
    let (cfg, r, tv, plan) = spin_only();
    let motor = cfg.motor();
    let (_, flight) = trial_flight(&cfg, &r, &tv, 1, 4);
    let rp = Replanning {
        every: 4,
        budget_s: Some(0.0),
        ..Replanning::new(&cfg, plan)
    };
    let closed = fly(&r, Feedback::Tvlqr(&tv), &motor, flight.clone());
    let re = fly(&r, Feedback::Replan(&tv, &rp), &motor, flight);
    assert!(!re.replans.is_empty());
    assert!(re.replans.iter().all(|p| p.outcome == Outcome::Late));
    assert_eq!(re.error_deg.to_bits(), closed.error_deg.to_bits());
}

#[test]
fn replanning_lands_a_spin_the_tvlqr_alone_misses() {
    let (cfg, r, tv, plan) = spin_only();
    let motor = cfg.motor();
    // trial 4 of seed 1: a 0.26 rad/s spin, mostly about the rear half's x
    let (draw, flight) = trial_flight(&cfg, &r, &tv, 1, 4);
    assert!(draw.spin_rad_s.iter().map(|w| w * w).sum::<f64>().sqrt() > 0.2);
    let rp = Replanning::new(&cfg, plan);
    let closed = fly(&r, Feedback::Tvlqr(&tv), &motor, flight.clone());
    let re = fly(&r, Feedback::Replan(&tv, &rp), &motor, flight);
    let taken = re
        .replans
        .iter()
        .filter(|p| p.outcome == Outcome::Taken)
        .count();
    assert!(taken > 0, "no replan was taken");
    assert!(
        closed.error_deg > 10.0 && re.error_deg < 10.0 && re.error_deg < 0.5 * closed.error_deg,
        "TVLQR lands {} deg, replanning {} deg",
        closed.error_deg,
        re.error_deg
    );
}

#[test]
fn inside_the_robots_motor_envelope_replanning_corrects_nothing_on_the_nominal() {
    // the robot from 1.2 times its least height, its servo's torque-speed line binding
    let cfg = util::config("robot-universal", &["fall.height=4.25"]);
    let plan: SharedPlan = Arc::new(catflip::control::robustness::design(&cfg).unwrap().plan);
    let r = Reference::new(&cfg, plan.as_ref());
    let tv = Tvlqr::new(&r, &cfg.control);
    let motor = cfg.motor();
    let rp = Replanning {
        every: 3,
        ..Replanning::new(&cfg, plan)
    };
    let re = fly(&r, Feedback::Replan(&tv, &rp), &motor, Flight::nominal(&r));
    assert!(re.replans.iter().any(|p| p.outcome == Outcome::Taken));
    // a taken plan's nominal is flown inside the envelope, as the plant flies it; what
    // is left is the TVLQR keeping the plan's torque (one SCP iteration leaves it
    // outside by a little) in the envelope at the command's sample
    // (8e-4 N m, 1.1 % of the peak, before the nominal was flown inside it)
    assert!(
        re.max_correction_nm < 1e-3 * r.peak_torque,
        "correction {} N m on the nominal",
        re.max_correction_nm
    );
    assert!(re.error_deg < 0.05, "lands {} deg off", re.error_deg);
}
