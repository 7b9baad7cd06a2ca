//! The model with angular momentum (MODEL.md section 6, F8-F10) checked on
//! the library: conservation, power balance, the locked rigid body, time scaling.

use crate::util::seed;
use catflip::design::analytic::{analytic_plan, plan};
use catflip::design::plan::{Phase, ShapePlan, ShapeState};
use catflip::model::Cat;
use catflip::model::momentum::{
    Start, body_rate_with, inverse_dynamics_with, kinetic_energy_with, landing_error,
    momentum_torque, rigid_turn, straight_inertias,
};
use catflip::model::small::{Real, cross, dot, mat_mul, mat_vec, transpose};
use catflip::model::so3::{exp, quat_from};
use catflip::model::{Half, InertiaFormula};
use catflip::verify::ode::OdeSettings;
use catflip::verify::simulate::{
    Controller, SimReport, dynamic, dynamic_from, kinematic, kinematic_from,
};
use nalgebra::{Matrix3, Vector3};
use num_dual::{Dual, Dual64};

fn tight() -> OdeSettings {
    OdeSettings {
        rtol: 1e-12,
        atol: 1e-14,
        ..Default::default()
    }
}

/// The seed's cat and an unequal one, both joints.
fn cats() -> Vec<Cat> {
    let mut out = Vec::new();
    for joint in ["no-twist", "universal"] {
        let c = seed(&[&format!("cat.joint={joint}")]).cat();
        out.push(c);
        out.push(Cat {
            rear: Half {
                mass: 2.5,
                length: 0.6,
                radius: 0.15,
                inertia: InertiaFormula::SolidCylinder,
            },
            ..c
        });
    }
    out
}

fn norm(v: [f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

fn rot(r: &SimReport) -> Matrix3<f64> {
    *quat_from(&r.final_attitude).to_rotation_matrix().matrix()
}

/// Kinetic energy and A-frame angular momentum about the common centre of mass,
/// from the two bodies' own velocities: a path apart from the model's `J`, `K`, `M`
/// and its torque. The shape's time derivatives come from an inner dual number.
fn bodies<T: Real>(cat: &Cat, q: [T; 2], qd: [T; 2], w: [T; 3]) -> (T, [T; 3]) {
    let qe: [Dual<T>; 2] = std::array::from_fn(|i| Dual::new(q[i], qd[i]));
    let rel = cat.rel_rotation(qe);
    let (_, d) = cat.offsets(&rel);
    let re = |m: &[[Dual<T>; 3]; 3]| m.map(|r| r.map(|x| x.re));
    let (r, rdot) = (re(&rel), rel.map(|row| row.map(|x| x.eps)));
    let om = mat_mul(&rdot, &transpose(&r));
    let w_rel = [om[2][1], om[0][2], om[1][0]];
    let (dv, dd) = (d.map(|x| x.re), d.map(|x| x.eps));
    let m = cat.mass();
    let half = T::from(0.5);
    let mut e = T::zero();
    let mut l = [T::zero(); 3];
    let halves = cat.halves();
    for (share, h, rate, frame) in [
        (
            -cat.front.mass / m,
            &halves.rear,
            w,
            catflip::model::small::eye3::<T>(),
        ),
        (
            cat.rear.mass / m,
            &halves.front,
            [w[0] + w_rel[0], w[1] + w_rel[1], w[2] + w_rel[2]],
            r,
        ),
    ] {
        let pos = dv.map(|x| x * T::from(share));
        let vel: [T; 3] = {
            let c = cross(w, pos);
            std::array::from_fn(|i| c[i] + dd[i] * T::from(share))
        };
        let ib = mat_mul(
            &mat_mul(&frame, &Cat::body_inertia::<T>(h)),
            &transpose(&frame),
        );
        let iw = mat_vec(&ib, rate);
        e += half * (T::from(h.mass) * dot(vel, vel) + dot(rate, iw));
        let orb = cross(pos, vel);
        for i in 0..3 {
            l[i] += iw[i] + orb[i] * T::from(h.mass);
        }
    }
    (e, l)
}

/// `w_A = J^-1 (lambda - K q_dot)` carries exactly the momentum `lambda`, and the
/// model's energy `1/2 q_dot' M q_dot + 1/2 lambda' J^-1 lambda` is the bodies'.
#[test]
fn body_rate_carries_the_momentum_and_energy_is_the_bodies() {
    for cat in cats() {
        let (q, qd, lam): ([f64; 2], [f64; 2], [f64; 3]) =
            ([0.8, -0.6], [1.7, -0.9], [0.4, -0.25, 0.7]);
        let w = body_rate_with(&cat, q, qd, lam);
        let (e, l) = bodies(&cat, q, qd, w);
        for i in 0..3 {
            assert!((l[i] - lam[i]).abs() < 1e-14, "{l:?} {lam:?}");
        }
        let ke = kinetic_energy_with(&cat, q, qd, lam);
        assert!((e - ke).abs() < 1e-13 * ke, "{e} {ke}");
    }
}

/// Power balance, pointwise: with `q_ddot` from the forward dynamics under `tau`,
/// the bodies' kinetic energy changes at `tau . q_dot` (to round-off). This checks
/// every term of the momentum torque: a wrong sign or factor in any shows up.
#[test]
fn power_balance_holds_to_round_off() {
    for cat in cats() {
        for (q, qd, lam, tau) in [
            ([0.8, -0.6], [1.7, -0.9], [0.4, -0.25, 0.7], [0.3, -0.2]),
            ([0.1, 1.9], [-0.4, 2.2], [-1.1, 0.6, 0.2], [-0.05, 0.4]),
            ([1e-3, -2e-3], [0.5, 0.3], [0.0, 0.0, 1.5], [0.0, 0.0]),
        ] {
            let t = catflip::model::ShapeTerms::first(&cat, q);
            let qdd = catflip::model::momentum::forward_dynamics_from(&cat, &t, q, qd, tau, lam);
            // the torque back from the inverse dynamics
            let back = inverse_dynamics_with(&cat, q, qd, qdd, lam);
            for i in 0..2 {
                assert!((back[i] - tau[i]).abs() < 1e-12, "{back:?} {tau:?}");
            }
            let w = body_rate_with(&cat, q, qd, lam);
            let dl = cross(lam, w);
            let qe: [Dual64; 2] = std::array::from_fn(|i| Dual64::new(q[i], qd[i]));
            let qde: [Dual64; 2] = std::array::from_fn(|i| Dual64::new(qd[i], qdd[i]));
            let le: [Dual64; 3] = std::array::from_fn(|i| Dual64::new(lam[i], dl[i]));
            let we = body_rate_with(&cat, qe, qde, le);
            let (e, l) = bodies(&cat, qe, qde, we);
            let power = tau[0] * qd[0] + tau[1] * qd[1];
            let scale = e.re * (1.0 + norm(w)) + power.abs();
            eprintln!(
                "power balance: dE/dt - tau.qd = {:.2e} (dE/dt {:.4e})",
                e.eps - power,
                e.eps
            );
            assert!(
                (e.eps - power).abs() < 1e-13 * scale,
                "{cat:?}: dE/dt {} vs tau.qd {power}",
                e.eps
            );
            // and the A-frame momentum turns as lambda x w
            for i in 0..3 {
                assert!((l[i].eps - dl[i]).abs() < 1e-12 * (1.0 + norm(dl)));
            }
        }
    }
}

/// The power balance fails with the gyroscopic or the amended-potential term
/// dropped: the test above could fail.
#[test]
fn power_balance_sees_a_missing_term() {
    let cat = cats()[0];
    let (q, qd, lam): ([f64; 2], [f64; 2], [f64; 3]) =
        ([0.8, -0.6], [1.7, -0.9], [0.4, -0.25, 0.7]);
    let g = momentum_torque(&cat, q, qd, lam);
    assert!(g[0].abs() + g[1].abs() > 1e-3, "{g:?}");
    let zero = momentum_torque(&cat, q, qd, [0.0; 3]);
    assert_eq!(zero, [0.0; 2]);
}

fn spinning_starts() -> Vec<Start> {
    vec![
        Start::new([0.0; 3], [0.0, 0.0, 0.5]),
        Start::new([0.0; 3], [0.0, 0.5, 0.0]),
        Start::new([0.3, -0.2, 0.4], [0.3, -0.4, 0.6]),
    ]
}

/// L conserved to 1e-10 relative along dynamic and kinematic runs of the
/// seed's schedule from spinning starts, recomputed from the bodies' velocities.
#[test]
fn momentum_is_conserved_from_spinning_starts() {
    for joint in ["no-twist", "universal"] {
        let cfg = seed(&[&format!("cat.joint={joint}")]);
        let cat = cfg.cat();
        let p = analytic_plan(&cfg.design_spec());
        let ctrl = Controller::from_spec(&cfg.design_spec());
        for s in spinning_starts() {
            let l = norm(s.momentum(&cat));
            let k = kinematic_from(&cat, &p, &s, &tight()).unwrap();
            let d = dynamic_from(&cat, &p, &ctrl, &tight(), &s).unwrap();
            for r in [&k, &d] {
                eprintln!(
                    "{joint} {:?}: |L| {l:.4e}, drift/|L| {:.2e}",
                    s.body_rate,
                    r.momentum_drift_nms / l
                );
                assert!(
                    r.momentum_drift_nms < 1e-10 * l,
                    "{joint} {s:?}: drift {} of |L| {l}",
                    r.momentum_drift_nms
                );
            }
            // the spin changes the landing: the zero-momentum schedule misses
            assert!(d.landing_error_deg > 1.0, "{}", d.landing_error_deg);
        }
    }
}

/// A shape held straight for `t` seconds.
struct Straight(f64);

impl ShapePlan for Straight {
    fn phase_bounds(&self) -> Vec<f64> {
        vec![0.0, self.0 / 3.0, 2.0 * self.0 / 3.0, self.0]
    }
    fn state_in(&self, _: usize, _: f64) -> ShapeState {
        ShapeState {
            q: [0.0; 2],
            qd: [0.0; 2],
            qdd: [0.0; 2],
            phase: Phase::Twist,
        }
    }
}

/// F8: the locked straight cat is a torque-free axisymmetric rigid body, in
/// closed form, and F10: a spin about the spine alone turns it at |L| / I_3.
#[test]
fn f8_locked_straight_cat_is_a_torque_free_rigid_body() {
    for cat in cats() {
        let (i3, i1) = straight_inertias(&cat);
        let (a, b) = (cat.rear, cat.front);
        let d = 0.5 * (a.length + b.length);
        assert!((i3 - (a.i_a() + b.i_a())).abs() < 1e-15);
        assert!((i1 - (a.i_t() + b.i_t() + cat.reduced_mass() * d * d)).abs() < 1e-14);
        let t = 2.3;
        for s in spinning_starts() {
            let r = kinematic_from(&cat, &Straight(t), &s, &tight()).unwrap();
            let r0 = *s.rotation().to_rotation_matrix().matrix();
            let want = rigid_turn(&cat, &r0, s.body_momentum(&cat), t);
            // the closed form, written out: exp(t hat(L) / I_1) R0 exp(t alpha hat(e_z))
            let l = r0 * Vector3::from(s.body_momentum(&cat));
            let alpha = (i1 - i3) * s.body_rate[2] / i1;
            let explicit = exp(&(l * (t / i1))) * r0 * exp(&(Vector3::z() * (alpha * t)));
            assert!((want - explicit).norm() < 1e-14);
            let err = (rot(&r) - want).norm();
            eprintln!("F8 {:?}: |R - closed form| {err:.2e}", s.body_rate);
            assert!(err < 1e-10, "{cat:?} {s:?}: {err}");
            // the spin about the spine is constant
            let lam = r.final_body_momentum;
            assert!((lam[2] / i3 - s.body_rate[2]).abs() < 1e-12);
            // the transverse body rate turned by (I_3 - I_1) w_3 / I_1 * t in the body frame
            let w0 = Vector3::new(s.body_rate[0], s.body_rate[1], 0.0);
            if w0.norm() > 0.0 {
                let w1 = Vector3::new(lam[0] / i1, lam[1] / i1, 0.0);
                let turned = (w0.x * w1.y - w0.y * w1.x).atan2(w0.dot(&w1));
                let nu = (i3 - i1) * s.body_rate[2] / i1 * t;
                let wrap = |x: f64| {
                    (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI
                };
                assert!(wrap(turned - nu).abs() < 1e-9, "{turned} vs {nu}");
                // the spine cones about L at |L| / I_1: its angle to L is fixed
                let spine = |m: Matrix3<f64>| m * Vector3::z();
                let c0 = spine(r0).dot(&l.normalize());
                let c1 = spine(rot(&r)).dot(&l.normalize());
                assert!((c0 - c1).abs() < 1e-10);
            }
        }
        // F10: about the spine alone, a rotation about it at |L| / I_3
        let s = Start::new([0.0; 3], [0.0, 0.0, 0.7]);
        let r = kinematic_from(&cat, &Straight(t), &s, &tight()).unwrap();
        let want = exp(&(Vector3::z() * (0.7 * t)));
        assert!((rot(&r) - want).norm() < 1e-10);
    }
}

/// F9: the same shape path k times faster with k times the momentum ends in
/// the same attitude, with k^2 the torque at corresponding instants. And F10:
/// with momentum the timing of the same path changes the landing (F2 fails).
#[test]
fn f9_time_scaling_with_momentum() {
    for cat in cats() {
        let s = Start::new([0.2, -0.1, 0.3], [0.15, -0.2, 0.4]);
        let d = [0.4, 0.9, 0.5];
        let base = plan(1.1, 5.0, d);
        let r1 = kinematic_from(&cat, &base, &s, &tight()).unwrap();
        for k in [2.0, 0.5] {
            let fast = plan(1.1, 5.0, d.map(|x| x / k));
            let sk = Start {
                body_rate: s.body_rate.map(|w| w * k),
                ..s
            };
            let rk = kinematic_from(&cat, &fast, &sk, &tight()).unwrap();
            let err = (rot(&r1) - rot(&rk)).norm();
            eprintln!("F9 k {k}: |R_1 - R_k| {err:.2e}");
            assert!(err < 1e-9, "{cat:?} k {k}: {err}");
            for i in 0..3 {
                assert!((rk.final_body_momentum[i] - k * r1.final_body_momentum[i]).abs() < 1e-9);
            }
            // the torque at the same point of the path, with the body momentum there
            for (p, tb) in r1.trace.iter().zip(0..).filter(|(_, i)| i % 37 == 5) {
                let _ = tb;
                let st = base.state(p.t);
                let lam = body_lambda(&cat, &p.attitude, &s, &st);
                let tau1 = inverse_dynamics_with(&cat, st.q, st.qd, st.qdd, lam);
                let sf = fast.state(p.t / k);
                let tauk = inverse_dynamics_with(&cat, sf.q, sf.qd, sf.qdd, lam.map(|x| x * k));
                for j in 0..2 {
                    assert!(
                        (tauk[j] - k * k * tau1[j]).abs() < 1e-9 * (1.0 + tau1[j].abs()) * k * k,
                        "{tauk:?} {tau1:?}"
                    );
                }
            }
        }
        // F2 fails with momentum: the same path in another timing lands elsewhere
        let other = plan(1.1, 5.0, [0.7, 0.6, 0.5]);
        let r2 = kinematic_from(&cat, &other, &s, &tight()).unwrap();
        assert!((rot(&r1) - rot(&r2)).norm() > 1e-3);
        // while at zero momentum it does not
        let z = Start::new([0.2, -0.1, 0.3], [0.0; 3]);
        let (a, b) = (
            kinematic_from(&cat, &base, &z, &tight()).unwrap(),
            kinematic_from(&cat, &other, &z, &tight()).unwrap(),
        );
        assert!((rot(&a) - rot(&b)).norm() < 1e-9);
    }
}

/// `R_A' L` at a recorded instant.
fn body_lambda(cat: &Cat, att: &[f64; 4], s: &Start, _st: &ShapeState) -> [f64; 3] {
    let r = quat_from(att).to_rotation_matrix();
    let l = r.inverse() * Vector3::from(s.momentum(cat));
    [l.x, l.y, l.z]
}

/// At zero momentum a rotated release only rotates the whole run: the final
/// attitude is `R0 R(T)` of the upside-down run, and the default start is today's run.
#[test]
fn zero_momentum_runs_are_today_and_rotate_with_the_release() {
    for joint in ["no-twist", "universal"] {
        let cfg = seed(&[&format!("cat.joint={joint}")]);
        let cat = cfg.cat();
        let p = analytic_plan(&cfg.design_spec());
        let today = kinematic(&cat, &p, &tight()).unwrap();
        let same = kinematic_from(&cat, &p, &Start::default(), &tight()).unwrap();
        assert_eq!(today.flip_deg, same.flip_deg);
        assert_eq!(today.final_attitude, same.final_attitude);
        // the landing error of today's run is its flip error (the tilt is tiny for no-twist)
        if joint == "no-twist" {
            assert!(
                (today.landing_error_deg.to_radians() - today.flip_error_rad.abs()).abs() < 1e-9,
                "{} {}",
                today.landing_error_deg,
                today.flip_error_rad
            );
        }
        let s = Start::new([0.4, 0.7, -0.2], [0.0; 3]);
        let rotated = kinematic_from(&cat, &p, &s, &tight()).unwrap();
        let r0 = *s.rotation().to_rotation_matrix().matrix();
        assert!((rot(&rotated) - r0 * rot(&today)).norm() < 1e-12);
        let ctrl = Controller::from_spec(&cfg.design_spec());
        let d0 = dynamic(&cat, &p, &ctrl, &tight()).unwrap();
        let d1 = dynamic_from(&cat, &p, &ctrl, &tight(), &s).unwrap();
        assert!((rot(&d1) - r0 * rot(&d0)).norm() < 1e-12);
    }
}

/// A release tilted by 30 degrees about the vertical-free axis lands 30 deg off
/// with today's schedule; landing error is the belly's angle from down.
#[test]
fn tilted_release_lands_tilted_with_todays_schedule() {
    let cfg = seed(&["start.rotation_deg=[0, 30, 0]"]);
    let cat = cfg.cat();
    let r = kinematic_from(
        &cat,
        &analytic_plan(&cfg.design_spec()),
        &cfg.start.start(),
        &tight(),
    )
    .unwrap();
    // the belly is turned by the flip about the (tilted) spine: still 30 deg from down
    assert!(
        (r.landing_error_deg - 30.0).abs() < 1e-6,
        "{}",
        r.landing_error_deg
    );
    let m = Matrix3::identity();
    assert!((landing_error(&m) - std::f64::consts::PI).abs() < 1e-15);
}
