//! General rigid halves (`[body]`): the cylinders given as tensors reproduce
//! today's numbers; a half with products of inertia and an off-axis centre
//! of mass keeps zero momentum and conserves energy in free fall; the
//! relabelling symmetry where it holds and where it does not.

use crate::util;

use catflip::Config;
use catflip::design::free::{FreeDesign, Seed};
use catflip::design::least_height;
use catflip::design::phased::optimize;
use catflip::model::dynamics::kinetic_energy;
use catflip::model::{Cat, Halves, Joint, ShapeTerms};
use nalgebra::{Matrix3, Rotation3, Vector3};
use util::{seed, stall_torque_only};

/// `cfg` with `[cat]`'s cylinders replaced by `[body]` tensors written out
/// from the cylinder formulas (`I_t = m (3 r^2 + l^2) / 12`, `I_a = m r^2 / 2`).
fn as_tensors(cfg: &Config) -> Config {
    let cat = cfg.cat();
    let mut table = toml::Table::try_from(cfg).unwrap();
    let c = table["cat"].as_table_mut().unwrap();
    for k in ["mass", "length", "radius", "front"] {
        c.remove(k);
    }
    let half = |h: &catflip::model::Half, joint_z: f64| {
        let (m, l, r) = (h.mass, h.length, h.radius);
        let (it, ia) = (m * (3.0 * r * r + l * l) / 12.0, m * r * r / 2.0);
        format!(
            "mass = {m:?}\ncom = [0.0, 0.0, 0.0]\ninertia = [{it:?}, {it:?}, {ia:?}, 0.0, 0.0, 0.0]\njoint = [0.0, 0.0, {joint_z:?}]\n"
        )
    };
    let text = format!(
        "{}\n[body.rear]\n{}\n[body.front]\n{}",
        toml::to_string(&table).unwrap(),
        half(&cat.rear, cat.rear.length / 2.0),
        half(&cat.front, -cat.front.length / 2.0)
    );
    Config::from_toml(&text, "tensors", &[]).unwrap()
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-12 * a.abs().max(1e-300),
        "{what}: cylinders {a} vs tensors {b}"
    );
}

#[test]
fn cylinders_given_as_general_tensors_reproduce_todays_numbers() {
    for (name, cfg) in [
        ("seed", seed(&[])),
        (
            "unequal universal",
            seed(&[
                "cat.joint=universal",
                "cat.front.mass=0.4",
                "cat.front.length=1.4",
                "cat.front.radius=0.05",
            ]),
        ),
        ("robot", stall_torque_only("robot-universal", &[])),
    ] {
        let general = as_tensors(&cfg);
        let (a, b) = (cfg.cat(), general.cat());
        assert!(b.general.is_some() && a.general.is_none(), "{name}");
        for q in [[0.0, 0.0], [0.7, -0.4], [2.1, 1.3]] {
            let (ta, tb) = (ShapeTerms::second(&a, q), ShapeTerms::second(&b, q));
            for i in 0..2 {
                for j in 0..2 {
                    close(ta.m[i][j], tb.m[i][j], name);
                    for k in 0..2 {
                        close(ta.dm[k][i][j], tb.dm[k][i][j], name);
                    }
                }
            }
            let qd = [0.3, -1.1];
            close(kinetic_energy(&a, q, qd), kinetic_energy(&b, q, qd), name);
        }
        close(a.straight_inertia(), b.straight_inertia(), name);
        // the phased design and its simulation
        let (pa, pb) = (
            optimize(&cfg.design_spec(), |_| {}).unwrap(),
            optimize(&general.design_spec(), |_| {}).unwrap(),
        );
        close(pa.peak_torque_nm, pb.peak_torque_nm, name);
        close(pa.unit_peak_nm_s2, pb.unit_peak_nm_s2, name);
        close(pa.bend_deg, pb.bend_deg, name);
        close(pa.twist_rad, pb.twist_rad, name);
        let (sa, sb) = (
            util::flown(&cfg.design_spec(), &pa.plan),
            util::flown(&general.design_spec(), &pb.plan),
        );
        close(sa.flip_deg, sb.flip_deg, name);
        close(sa.peak_torque_nm, sb.peak_torque_nm, name);
        close(sa.tilt_deg + 1.0, sb.tilt_deg + 1.0, name);
        // the least height (motors limited)
        if let (Some(ha), Some(hb)) = (
            least_height::answer(&cfg.design_spec()).unwrap(),
            least_height::answer(&general.design_spec()).unwrap(),
        ) {
            close(ha.least_height_m, hb.least_height_m, name);
            close(ha.least_time_s, hb.least_time_s, name);
        }
    }
    // the free-form design of the seed
    let cfg = seed(&["free.nodes=24"]);
    let (fa, fb) = (
        FreeDesign::new(&cfg.design_spec())
            .seed(Seed::Phased)
            .solve()
            .unwrap(),
        FreeDesign::new(&as_tensors(&cfg).design_spec())
            .seed(Seed::Phased)
            .solve()
            .unwrap(),
    );
    close(fa.peak_torque_nm, fb.peak_torque_nm, "free");
    let (sa, sb) = (
        util::flown(&cfg.design_spec(), &fa.plan),
        util::flown(&as_tensors(&cfg).design_spec(), &fb.plan),
    );
    close(sa.flip_deg, sb.flip_deg, "free");
    close(sa.peak_torque_nm, sb.peak_torque_nm, "free");
}

/// A rear half with products of inertia and an off-axis centre of mass, the
/// joint off-centre on both halves, a tilted universal joint.
pub fn lopsided(joint: Joint) -> Cat {
    let cfg = seed(&[]);
    let mut h: Halves = cfg.cat().halves();
    h.rear.com = [0.03, -0.02, 0.01];
    h.rear.inertia = [
        [0.09, 0.004, -0.003],
        [0.004, 0.08, 0.006],
        [-0.003, 0.006, 0.03],
    ];
    h.rear.joint = [0.01, 0.02, 0.5];
    h.front.mass = 0.7;
    h.front.com = [-0.02, 0.0, 0.04];
    h.front.inertia = [
        [0.05, -0.002, 0.0],
        [-0.002, 0.06, 0.001],
        [0.0, 0.001, 0.02],
    ];
    let s = 0.5f64.sqrt();
    h.rear.axis = [s, s, 0.0];
    h.front.axis = [-s, s, 0.0];
    assert!(h.rear.problem().is_none() && h.front.problem().is_none());
    Cat::rigid(h, joint)
}

/// Kinetic energy and angular momentum (A's frame at the instant) from the
/// bodies' own poses, differentiated in time: the general geometry written
/// out here with nalgebra, not the model's locked inertia.
fn from_bodies(cat: &Cat, q: [f64; 2], qd: [f64; 2], w_a: [f64; 3]) -> (f64, Vector3<f64>) {
    let h = cat.halves();
    let v3 = |a: [f64; 3]| Vector3::from(a);
    let poses = |t: f64| {
        let ra = *Rotation3::new(v3(w_a) * t).matrix();
        let qt = [q[0] + qd[0] * t, q[1] + qd[1] * t];
        let rr = Matrix3::from_fn(|i, j| cat.rel_rotation::<f64>(qt)[i][j]);
        let d = v3(h.rear.joint) - v3(h.rear.com) + rr * (v3(h.front.com) - v3(h.front.joint));
        let m = h.rear.mass + h.front.mass;
        [
            (ra, ra * d * (-h.front.mass / m)),
            (ra * rr, ra * d * (h.rear.mass / m)),
        ]
    };
    let dt = 1e-6;
    let (p, m, now) = (poses(dt), poses(-dt), poses(0.0));
    let (mut energy, mut momentum) = (0.0, Vector3::zeros());
    for (i, half) in [h.rear, h.front].iter().enumerate() {
        let v = (p[i].1 - m[i].1) / (2.0 * dt);
        let wm = (p[i].0 - m[i].0) / (2.0 * dt) * now[i].0.transpose();
        let w = Vector3::new(wm[(2, 1)], wm[(0, 2)], wm[(1, 0)]);
        let inertia = Matrix3::from_fn(|r, c| half.inertia[r][c]);
        let iw = now[i].0 * inertia * now[i].0.transpose() * w;
        energy += 0.5 * half.mass * v.norm_squared() + 0.5 * w.dot(&iw);
        momentum += half.mass * now[i].1.cross(&v) + iw;
    }
    (energy, momentum)
}

#[test]
fn general_halves_zero_momentum_and_kinetic_energy_from_the_bodies() {
    for joint in [Joint::NoTwist, Joint::Universal] {
        let cat = lopsided(joint);
        assert!(!cat.is_axisymmetric() && !cat.is_symmetric());
        for (q, qd) in [([0.7, -0.4], [1.3, 2.1]), ([1.9, 0.8], [-0.6, 0.9])] {
            let w = cat.body_rate(q, qd);
            let (energy, momentum) = from_bodies(&cat, q, qd, w);
            let reduced = kinetic_energy(&cat, q, qd);
            assert!(
                (energy - reduced).abs() < 1e-7 * reduced,
                "{joint:?}: bodies {energy} vs reduced {reduced}"
            );
            assert!(
                momentum.norm() < 1e-7 * reduced,
                "{joint:?}: L = {momentum}"
            );
            // a wrong body rate shows up in the momentum
            let (_, off) = from_bodies(&cat, q, qd, [w[0], w[1] + 0.05, w[2]]);
            assert!(
                off.norm() > 1e-4,
                "{joint:?}: the check must be able to fail"
            );
        }
    }
}

#[test]
fn general_halves_conserve_energy_when_no_torque_acts() {
    use catflip::model::dynamics::forward_dynamics;
    for joint in [Joint::NoTwist, Joint::Universal] {
        let cat = lopsided(joint);
        let f = |x: [f64; 4]| {
            let a = forward_dynamics(&cat, [x[0], x[1]], [x[2], x[3]], [0.0, 0.0]);
            [x[2], x[3], a[0], a[1]]
        };
        let mut x = [0.3, -0.2, 1.5, 0.8];
        let e0 = kinetic_energy(&cat, [x[0], x[1]], [x[2], x[3]]);
        let dt = 1e-3;
        for _ in 0..1000 {
            let k1 = f(x);
            let k2 = f(std::array::from_fn(|i| x[i] + 0.5 * dt * k1[i]));
            let k3 = f(std::array::from_fn(|i| x[i] + 0.5 * dt * k2[i]));
            let k4 = f(std::array::from_fn(|i| x[i] + dt * k3[i]));
            x = std::array::from_fn(|i| {
                x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        let e1 = kinetic_energy(&cat, [x[0], x[1]], [x[2], x[3]]);
        assert!((e1 - e0).abs() < 1e-9 * e0, "{joint:?}: {e0} -> {e1}");
        // and the shape really moved through unequal, lopsided configurations
        assert!((x[0] - 0.3).abs() > 0.1);
    }
}

#[test]
fn swapping_the_halves_is_the_same_body_and_keeping_the_motor_order_is_not() {
    use catflip::model::dynamics::inverse_dynamics;
    let rel = |a: f64, b: f64| (a - b).abs() / a.abs().max(b.abs()).max(1e-12);
    let (q, qd, qdd) = ([0.8, -0.5], [1.2, 0.7], [-2.0, 3.1]);
    // no-twist: B sees A at exp(hat(-q)), again a no-twist shape
    let cat = lopsided(Joint::NoTwist);
    let sw = cat.swapped();
    let neg = |v: [f64; 2]| [-v[0], -v[1]];
    let (m, msw) = (
        ShapeTerms::first(&cat, q).m,
        ShapeTerms::first(&sw, neg(q)).m,
    );
    let (t, tsw) = (
        inverse_dynamics(&cat, q, qd, qdd),
        inverse_dynamics(&sw, neg(q), neg(qd), neg(qdd)),
    );
    for i in 0..2 {
        assert!(
            rel(t[i], -tsw[i]) < 1e-10,
            "no-twist torque {t:?} vs {tsw:?}"
        );
        for j in 0..2 {
            assert!(
                rel(m[i][j], msw[i][j]) < 1e-12,
                "no-twist M {m:?} vs {msw:?}"
            );
        }
    }
    // universal: (Rot(a1, q1) Rot(a2, q2))' = Rot(a2, -q2) Rot(a1, -q1): the
    // motors change order, q' = (-q2, -q1)
    let cat = lopsided(Joint::Universal);
    let sw = cat.swapped();
    let p = |v: [f64; 2]| [-v[1], -v[0]];
    let (m, msw) = (ShapeTerms::first(&cat, q).m, ShapeTerms::first(&sw, p(q)).m);
    let (t, tsw) = (
        inverse_dynamics(&cat, q, qd, qdd),
        inverse_dynamics(&sw, p(q), p(qd), p(qdd)),
    );
    for i in 0..2 {
        assert!(
            rel(t[i], -tsw[1 - i]) < 1e-10,
            "universal torque {t:?} vs {tsw:?}"
        );
        for j in 0..2 {
            assert!(
                rel(m[i][j], msw[1 - j][1 - i]) < 1e-12,
                "universal M {m:?} vs {msw:?}"
            );
        }
    }
    // where it does not hold: the halves swapped but motor 1 still on the
    // (new) rear is another robot; no relabelling of q gives its M
    let mut h = cat.halves().swapped();
    (h.rear.axis, h.front.axis) = (h.front.axis, h.rear.axis);
    let other = Cat::rigid(h, Joint::Universal);
    let mo = ShapeTerms::first(&other, p(q)).m;
    let worst = (0..2)
        .flat_map(|i| (0..2).map(move |j| (i, j)))
        .map(|(i, j)| rel(m[i][j], mo[1 - j][1 - i]))
        .fold(0.0, f64::max);
    assert!(
        worst > 1e-3,
        "keeping the motor order should change M: {m:?} vs {mo:?}"
    );
    let mo2 = ShapeTerms::first(&other, q).m;
    assert!(rel(m[0][0], mo2[0][0]) > 1e-3 || rel(m[1][1], mo2[1][1]) > 1e-3);
}
