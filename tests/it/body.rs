//! Unequal halves (`[cat.front]`): the reduced model against the bodies'
//! own velocities, the relabelling symmetry, and identical halves as before.

use crate::util;

use catflip::design::phased::optimize;
use catflip::model::dynamics::kinetic_energy;
use catflip::model::{Cat, Half};
use nalgebra::{Matrix3, Rotation3, Vector3};
use util::seed;

/// Heavy short rear, light long thin front.
const UNEQUAL: [&str; 3] = [
    "cat.front.mass=0.4",
    "cat.front.length=1.4",
    "cat.front.radius=0.05",
];

fn rel(cat: &Cat, q: [f64; 2]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| cat.rel_rotation::<f64>(q)[i][j])
}

fn inertia(h: &Half) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(h.i_t(), h.i_t(), h.i_a()))
}

/// World poses of both halves at time `t` after an instant where the shape is
/// `q`, its rate `qd` and A's body rate `w_a` (A starts at the identity):
/// rotations and centre-of-mass positions about the common centre of mass,
/// computed from the geometry alone (not from the model's locked inertia).
fn poses(
    cat: &Cat,
    q: [f64; 2],
    qd: [f64; 2],
    w_a: Vector3<f64>,
    t: f64,
) -> [(Matrix3<f64>, Vector3<f64>); 2] {
    let ra = *Rotation3::new(w_a * t).matrix();
    let qt = [q[0] + qd[0] * t, q[1] + qd[1] * t];
    let rr = rel(cat, qt);
    let (a, b) = (cat.rear.length / 2.0, cat.front.length / 2.0);
    let d = Vector3::new(0.0, 0.0, a) + rr * Vector3::new(0.0, 0.0, b);
    let m = cat.rear.mass + cat.front.mass;
    [
        (ra, ra * d * (-cat.front.mass / m)),
        (ra * rr, ra * d * (cat.rear.mass / m)),
    ]
}

/// Kinetic energy and angular momentum from the bodies' velocities (central differences in time).
fn from_bodies(cat: &Cat, q: [f64; 2], qd: [f64; 2], w_a: Vector3<f64>) -> (f64, Vector3<f64>) {
    let h = 1e-6;
    let (p, m) = (poses(cat, q, qd, w_a, h), poses(cat, q, qd, w_a, -h));
    let now = poses(cat, q, qd, w_a, 0.0);
    let mut energy = 0.0;
    let mut momentum = Vector3::zeros();
    for (i, half) in [&cat.rear, &cat.front].into_iter().enumerate() {
        let v = (p[i].1 - m[i].1) / (2.0 * h);
        let wm = (p[i].0 - m[i].0) / (2.0 * h) * now[i].0.transpose();
        let w = Vector3::new(wm[(2, 1)], wm[(0, 2)], wm[(1, 0)]);
        let iw = now[i].0 * inertia(half) * now[i].0.transpose() * w;
        energy += 0.5 * half.mass * v.norm_squared() + 0.5 * w.dot(&iw);
        momentum += half.mass * now[i].1.cross(&v) + iw;
    }
    (energy, momentum)
}

#[test]
fn unequal_halves_zero_momentum_and_kinetic_energy_from_the_bodies() {
    for joint in ["no-twist", "universal"] {
        let mut ov = UNEQUAL.to_vec();
        let j = format!("cat.joint={joint}");
        ov.push(&j);
        let cat = seed(&ov).cat();
        for (q, qd) in [([0.7, -0.4], [1.3, 2.1]), ([1.9, 0.8], [-0.6, 0.9])] {
            let w_a = Vector3::from(cat.body_rate(q, qd));
            let (energy, momentum) = from_bodies(&cat, q, qd, w_a);
            let reduced = kinetic_energy(&cat, q, qd);
            assert!(
                (energy - reduced).abs() < 1e-7 * reduced,
                "{joint}: bodies {energy} vs reduced {reduced}"
            );
            assert!(momentum.norm() < 1e-7 * reduced, "{joint}: L = {momentum}");
            // a wrong body rate shows up in the momentum
            let (_, off) = from_bodies(&cat, q, qd, w_a + Vector3::new(0.0, 0.05, 0.0));
            assert!(off.norm() > 1e-4, "{joint}: the check must be able to fail");
        }
    }
}

// power balance with unequal halves: tests/it/foundation.rs, power_balance_dt_dt_equals_tau_dot_qdot

#[test]
fn identical_front_table_reproduces_the_symmetric_cat() {
    let plain = seed(&[]);
    let same = seed(&["cat.front.mass=1.0", "cat.front.length=1.0"]);
    assert_eq!(plain.cat(), same.cat());
    let (a, b) = (
        optimize(&plain.design_spec(), |_| {}).unwrap(),
        optimize(&same.design_spec(), |_| {}).unwrap(),
    );
    assert!((a.peak_torque_nm - b.peak_torque_nm).abs() <= 1e-12 * a.peak_torque_nm);
}

#[test]
fn no_twist_swapping_the_halves_keeps_the_optimal_peak() {
    // Relabelling: the front half seen from the rear is exp(hat(v)), the rear
    // seen from the front exp(hat(-v)), again a no-twist shape; so the heavy
    // rear and the heavy front cats have the same optimum.
    let heavy_rear = seed(&["cat.mass=2.0", "cat.front.mass=0.5", "cat.front.length=1.3"]);
    let heavy_front = seed(&[
        "cat.mass=0.5",
        "cat.length=1.3",
        "cat.front.mass=2.0",
        "cat.front.length=1.0",
    ]);
    let (a, b) = (
        optimize(&heavy_rear.design_spec(), |_| {}).unwrap(),
        optimize(&heavy_front.design_spec(), |_| {}).unwrap(),
    );
    let rel = (a.peak_torque_nm - b.peak_torque_nm).abs() / a.peak_torque_nm;
    assert!(
        rel < 1e-6,
        "heavy rear {} vs heavy front {}",
        a.peak_torque_nm,
        b.peak_torque_nm
    );
    // the designs really are for different bodies: the unequal cat differs from the seed
    let seed_peak = optimize(&seed(&[]).design_spec(), |_| {})
        .unwrap()
        .peak_torque_nm;
    assert!((a.peak_torque_nm - seed_peak).abs() > 1e-3 * seed_peak);
    // and both flip by pi in the dynamic simulation (the twist is root-found)
    for (r, c) in [(&a, &heavy_rear), (&b, &heavy_front)] {
        let r = util::flown(&c.design_spec(), &r.plan);
        assert!(r.flip_error_rad.abs() < 1e-6, "{}", r.flip_error_rad);
    }
}
