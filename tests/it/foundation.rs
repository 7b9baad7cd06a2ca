//! Physics facts of docs/model.md section 6 checked on the library.

use crate::util;

use catflip::design::analytic::{analytic_plan, closed_forms, plan, turns_theta, yy_inertia_and_c};
use catflip::design::plan::ShapePlan;
use catflip::model::Joint;
use catflip::model::dynamics::{inverse_dynamics, kinetic_energy};
use catflip::model::so3::flip_error;
use catflip::verify::ode::OdeSettings;
use catflip::verify::simulate::{Controller, dynamic, kinematic};
use std::f64::consts::PI;
use util::seed;

fn tight() -> OdeSettings {
    OdeSettings {
        rtol: 1e-12,
        atol: 1e-14,
        ..Default::default()
    }
}

#[test]
fn f1_seed_schedule_flips_by_pi_at_several_bends() {
    let cfg = seed(&[]);
    let cat = cfg.cat();
    let one_turn = turns_theta(cat.i_t(), cat.i_a(), 1.0).to_degrees();
    for theta in [30.0, 45.0, 90.0, 120.0, one_turn] {
        let cfg = seed(&[&format!("analytic.theta_deg={theta}")]);
        let r = kinematic(&cfg.cat(), &analytic_plan(&cfg.design_spec()), &tight()).unwrap();
        assert!(
            r.flip_error_rad.abs() < 1e-9,
            "theta {theta}: flip error {}",
            r.flip_error_rad
        );
        assert!(
            r.tilt_deg.to_radians() < 1e-8,
            "theta {theta}: tilt {}",
            r.tilt_deg
        );
        assert!(r.momentum_drift_nms < 1e-12);
    }
}

#[test]
fn f1_fold_and_unfold_alone_rotate_nothing() {
    let cfg = seed(&[]);
    for bend in [0.3, 1.5, 2.6] {
        let p = plan(bend, 0.0, [0.4, 0.3, 0.5]);
        let r = kinematic(&cfg.cat(), &p, &tight()).unwrap();
        assert!(
            r.flip_deg.abs() < 1e-9 && r.tilt_deg.abs() < 1e-9,
            "bend {bend}: {} {}",
            r.flip_deg,
            r.tilt_deg
        );
        // while the fold itself does pitch body A
        let mid = r.trace.iter().map(|p| p.tilt).fold(0.0, f64::max);
        assert!(mid > 1e-3 * bend);
    }
}

#[test]
fn f2_flip_depends_on_the_path_not_its_timing() {
    // universal joint: the flip is not exactly pi, so equality is informative
    let a = seed(&["cat.joint=universal"]);
    let b = seed(&[
        "cat.joint=universal",
        "analytic.split=[0.5, 0.3, 0.2]",
        "fall.height=3",
    ]);
    let (pa, pb) = (
        analytic_plan(&a.design_spec()),
        analytic_plan(&b.design_spec()),
    );
    assert_eq!(pa.paths, pb.paths);
    let ra = kinematic(&a.cat(), &pa, &tight()).unwrap();
    let rb = kinematic(&b.cat(), &pb, &tight()).unwrap();
    assert!(
        (ra.flip_deg - rb.flip_deg).abs() < 1e-8,
        "{} vs {}",
        ra.flip_deg,
        rb.flip_deg
    );
    assert!((ra.tilt_deg - rb.tilt_deg).abs() < 1e-8);
    // F4: the universal joint under-flips and tilts with the seed's schedule
    assert!(flip_error(ra.flip_deg.to_radians()) > 1e-3 && ra.tilt_deg > 1e-3);
}

#[test]
fn f3_time_scaling_multiplies_torque_by_k_squared() {
    let cfg = seed(&[]);
    let cat = cfg.cat();
    let d = [0.3, 0.8, 0.25];
    let k = 2.5;
    let slow = plan(2.0, 3.3, d);
    let fast = plan(2.0, 3.3, d.map(|x| x / k));
    for i in 0..3 {
        for j in 0..=10 {
            let t = d[i] * j as f64 / 10.0;
            let ts = slow.torque_in(&cat, i, slow.phase_bounds()[i] + t);
            let tf = fast.torque_in(&cat, i, fast.phase_bounds()[i] + t / k);
            for m in 0..2 {
                assert!(
                    (tf[m] - k * k * ts[m]).abs() < 1e-9 * (1.0 + tf[m].abs()),
                    "{tf:?} {ts:?}"
                );
            }
        }
    }
}

#[test]
fn power_balance_dt_dt_equals_tau_dot_qdot() {
    // identical halves, and unequal ones (a heavy short rear, a long thin front)
    let unequal = [
        "cat.front.mass=0.4",
        "cat.front.length=1.4",
        "cat.front.radius=0.05",
    ];
    for (joint, front) in [
        ("no-twist", &[][..]),
        ("universal", &[][..]),
        ("no-twist", &unequal[..]),
        ("universal", &unequal[..]),
    ] {
        let j = format!("cat.joint={joint}");
        let cfg = seed(&[&[j.as_str()][..], front].concat());
        let cat = cfg.cat();
        let p = analytic_plan(&cfg.design_spec());
        let b = p.phase_bounds();
        let h = 1e-6;
        for i in 0..3 {
            for j in 1..10 {
                let t = b[i] + (b[i + 1] - b[i]) * j as f64 / 10.0;
                let e = |t: f64| {
                    let s = p.state_in(i, t);
                    kinetic_energy(&cat, s.q, s.qd)
                };
                let dtdt = (e(t + h) - e(t - h)) / (2.0 * h);
                let s = p.state_in(i, t);
                let tau = inverse_dynamics(&cat, s.q, s.qd, s.qdd);
                let power = tau[0] * s.qd[0] + tau[1] * s.qd[1];
                assert!(
                    (dtdt - power).abs() < 1e-5 * (1.0 + power.abs()),
                    "{joint} phase {i}: {dtdt} vs {power}"
                );
            }
        }
    }
}

#[test]
fn seed_printed_example_with_its_own_inertia() {
    let cf = closed_forms(&seed(&["analytic.seed_inertia=true"]).design_spec());
    // the seed prints 1.428 for 1.42857 (truncated)
    assert!((cf.fall_time_s - 1.428).abs() < 1e-3, "{}", cf.fall_time_s);
    assert!((cf.i_yy - 0.0726).abs() < 5e-5, "{}", cf.i_yy);
    assert!((cf.i_star - 0.3342).abs() < 5e-5, "{}", cf.i_star);
    // erratum E2: with sin(theta/2) the seed's own numbers give 2.2587
    assert!(
        (cf.seed_omega_rad_s - 2.2587).abs() < 5e-5,
        "{}",
        cf.seed_omega_rad_s
    );
    // and the design inertia differs (E1)
    let right = closed_forms(&seed(&[]).design_spec());
    assert!((right.i_t - (3.0 * 0.01 + 1.0) / 12.0).abs() < 1e-15);
    assert!((right.i_yy - cf.i_yy).abs() > 1e-3);
}

#[test]
fn one_turn_bend_twists_once_for_the_flip() {
    let cfg = seed(&[]);
    let cat = cfg.cat();
    let th = turns_theta(cat.i_t(), cat.i_a(), 1.0);
    let (_, c) = yy_inertia_and_c(cat.i_t(), cat.i_a(), th);
    assert!((c - 0.5).abs() < 1e-12);
    let cfg = seed(&[&format!("analytic.theta_deg={}", th.to_degrees())]);
    assert!((closed_forms(&cfg.design_spec()).twist_rad - 2.0 * PI).abs() < 1e-9);
}

#[test]
fn dynamic_simulation_of_inverse_dynamics_torque_reproduces_the_plan() {
    for joint in [Joint::NoTwist, Joint::Universal] {
        let cfg = seed(&[&format!("cat.joint={}", joint.name())]);
        let cat = cfg.cat();
        let p = analytic_plan(&cfg.design_spec());
        let open_loop = Controller {
            kp: 0.0,
            kd: 0.0,
            motor: catflip::model::motor::Motor::unlimited(cfg.norm()),
        };
        let d = dynamic(&cat, &p, &open_loop, &tight()).unwrap();
        let k = kinematic(&cat, &p, &tight()).unwrap();
        let gap = catflip::model::so3::wrap((d.flip_deg - k.flip_deg).to_radians());
        assert!(
            gap.abs() < 1e-7,
            "{joint:?}: {} vs {}",
            d.flip_deg,
            k.flip_deg
        );
        assert!(d.final_shape_error_rad < 1e-7 && d.max_tracking_error_rad < 1e-6);
        assert!(d.momentum_drift_nms < 1e-12, "{}", d.momentum_drift_nms);
    }
}

#[test]
fn torque_limit_saturates_and_spoils_the_flip() {
    let cfg = seed(&["limits.max_torque=5"]);
    let r = catflip::verify::simulate::dynamic_spec(
        &cfg.design_spec(),
        &analytic_plan(&cfg.design_spec()),
    )
    .unwrap();
    assert!(r.peak_torque_nm <= 5.0 + 1e-9);
    assert!(r.max_tracking_error_rad > 1e-2);
}
