//! Shape dynamics of the reduced Lagrangian `T = 1/2 q_dot' M(q) q_dot`
//! (docs/model.md section 3).
//!
//! `tau_i = sum_j M_ij q_ddot_j + sum_jk c_ijk q_dot_j q_dot_k` with the
//! Christoffel symbols of the first kind `c_ijk = dM_ij/dq_k - 1/2 dM_jk/dq_i`.
//! Their exact derivatives come from [`ShapeTerms`], so the torque Jacobians
//! below are exact too.

use crate::model::small::{add3, cross, mat_mul, mat_vec, scale3, transpose};
use crate::model::{Cat, ShapeTerms};
use num_dual::Dual64;

/// `c[i][j][k] = dM_ij/dq_k - 1/2 dM_jk/dq_i`.
pub fn christoffel(t: &ShapeTerms) -> [[[f64; 2]; 2]; 2] {
    let mut c = [[[0.0; 2]; 2]; 2];
    for (i, ci) in c.iter_mut().enumerate() {
        for (j, cij) in ci.iter_mut().enumerate() {
            for (k, x) in cij.iter_mut().enumerate() {
                *x = t.dm[k][i][j] - 0.5 * t.dm[i][j][k];
            }
        }
    }
    c
}

/// Velocity-product term `h(q, q_dot)` (centripetal and Coriolis torque).
pub fn bias(t: &ShapeTerms, qd: [f64; 2]) -> [f64; 2] {
    let c = christoffel(t);
    let mut h = [0.0; 2];
    for (i, hi) in h.iter_mut().enumerate() {
        for j in 0..2 {
            for k in 0..2 {
                *hi += c[i][j][k] * qd[j] * qd[k];
            }
        }
    }
    h
}

fn mat2_vec(m: &[[f64; 2]; 2], v: [f64; 2]) -> [f64; 2] {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

/// Inverse dynamics from precomputed terms.
pub fn torque_from(t: &ShapeTerms, qd: [f64; 2], qdd: [f64; 2]) -> [f64; 2] {
    let h = bias(t, qd);
    let mq = mat2_vec(&t.m, qdd);
    [mq[0] + h[0], mq[1] + h[1]]
}

/// Joint torque `tau = M(q) q_ddot + h(q, q_dot)`.
pub fn inverse_dynamics(cat: &Cat, q: [f64; 2], qd: [f64; 2], qdd: [f64; 2]) -> [f64; 2] {
    torque_from(&ShapeTerms::first(cat, q), qd, qdd)
}

/// Shape acceleration `q_ddot = M^-1 (tau - h)`.
pub fn forward_dynamics(cat: &Cat, q: [f64; 2], qd: [f64; 2], tau: [f64; 2]) -> [f64; 2] {
    let t = ShapeTerms::first(cat, q);
    let h = bias(&t, qd);
    solve2(&t.m, [tau[0] - h[0], tau[1] - h[1]])
}

pub fn solve2(m: &[[f64; 2]; 2], b: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [
        (m[1][1] * b[0] - m[0][1] * b[1]) / det,
        (m[0][0] * b[1] - m[1][0] * b[0]) / det,
    ]
}

/// Kinetic energy of the shape motion at zero angular momentum.
pub fn kinetic_energy(cat: &Cat, q: [f64; 2], qd: [f64; 2]) -> f64 {
    let (m, _) = cat.locked_terms(q);
    let mq = mat2_vec(&m, qd);
    0.5 * (qd[0] * mq[0] + qd[1] * mq[1])
}

/// Torque and its exact Jacobians with respect to `q`, `q_dot`, `q_ddot`
/// (each `[i][l] = d tau_i / d x_l`).
#[derive(Debug, Clone, Copy)]
pub struct TorqueLinearization {
    pub tau: [f64; 2],
    pub d_q: [[f64; 2]; 2],
    pub d_qd: [[f64; 2]; 2],
    pub d_qdd: [[f64; 2]; 2],
}

pub fn linearize_torque(t: &ShapeTerms, qd: [f64; 2], qdd: [f64; 2]) -> TorqueLinearization {
    let c = christoffel(t);
    let tau = torque_from(t, qd, qdd);
    let mut d_q = [[0.0; 2]; 2];
    let mut d_qd = [[0.0; 2]; 2];
    for i in 0..2 {
        for l in 0..2 {
            let mut s = 0.0;
            for k in 0..2 {
                s += (c[i][l][k] + c[i][k][l]) * qd[k];
            }
            d_qd[i][l] = s;
            let mut s = 0.0;
            for j in 0..2 {
                s += t.dm[l][i][j] * qdd[j];
                for k in 0..2 {
                    // d/dq_l of c_ijk
                    let dc = t.d2m[k][l][i][j] - 0.5 * t.d2m[i][l][j][k];
                    s += dc * qd[j] * qd[k];
                }
            }
            d_q[i][l] = s;
        }
    }
    TorqueLinearization {
        tau,
        d_q,
        d_qd,
        d_qdd: t.m,
    }
}

/// Total angular momentum about the common centre of mass, in the world frame,
/// recomputed from the two bodies' velocities.
///
/// This is deliberately a separate code path from [`Cat::locked_terms`]: it
/// differentiates the world poses of both bodies in time with a dual number
/// and sums `R I R' w + m r x r_dot` body by body. It shares only the joint's
/// rotation formula and the body geometry.
pub fn angular_momentum(
    cat: &Cat,
    r_a: &[[f64; 3]; 3],
    w_a: [f64; 3],
    q: [f64; 2],
    qd: [f64; 2],
) -> [f64; 3] {
    type D = Dual64;
    let lift = |m: &[[f64; 3]; 3]| m.map(|row| row.map(D::from));
    // R_A(t + e) = R_A (I + e hat(w_A)): exact to first order in e.
    let mut ra = lift(r_a);
    let rw = mat_vec(r_a, w_a);
    for i in 0..3 {
        // d/dt R_A = R_A hat(w_A) = hat(R_A w_A) R_A
        let dr = mat_mul(&crate::model::small::hat(rw), r_a);
        for j in 0..3 {
            ra[i][j].eps = dr[i][j];
        }
    }
    let qe = [D::new(q[0], qd[0]), D::new(q[1], qd[1])];
    let rel = cat.rel_rotation(qe);
    let (_, d) = cat.offsets(&rel);
    let rb = mat_mul(&ra, &rel);
    // centre-of-mass offsets from the common centre: -m_B/m R_A d and +m_A/m R_A d
    let d_world = mat_vec(&ra, d);
    let m = cat.mass();
    let mut l = [0.0; 3];
    let h = cat.halves();
    for (rot, half, share) in [
        (ra, &h.rear, -h.front.mass / m),
        (rb, &h.front, h.rear.mass / m),
    ] {
        let ic = Cat::body_inertia::<f64>(half);
        let r = scale3(D::from(share), d_world);
        let rv = r.map(|x| x.re);
        let vv = r.map(|x| x.eps);
        let rr = rot.map(|row| row.map(|x| x.re));
        let rdot = rot.map(|row| row.map(|x| x.eps));
        // world angular velocity: hat(w) = R_dot R'
        let wm = mat_mul(&rdot, &transpose(&rr));
        let w = [wm[2][1], wm[0][2], wm[1][0]];
        let iw = mat_vec(&mat_mul(&mat_mul(&rr, &ic), &transpose(&rr)), w);
        let orb = scale3(half.mass, cross(rv, vv));
        l = add3(l, add3(iw, orb));
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Half, InertiaFormula, Joint};

    fn cat(joint: Joint) -> Cat {
        Cat::symmetric(
            Half {
                mass: 1.3,
                length: 0.8,
                radius: 0.12,
                inertia: InertiaFormula::SolidCylinder,
            },
            joint,
        )
    }

    #[test]
    fn inverse_and_forward_dynamics_invert_each_other() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let c = cat(joint);
            let (q, qd, qdd) = ([0.8, -0.5], [1.5, 2.2], [-3.0, 4.0]);
            let tau = inverse_dynamics(&c, q, qd, qdd);
            let back = forward_dynamics(&c, q, qd, tau);
            for k in 0..2 {
                assert!((back[k] - qdd[k]).abs() < 1e-10, "{joint:?} {back:?}");
            }
        }
    }

    #[test]
    fn torque_jacobians_match_finite_differences() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let c = cat(joint);
            let (q, qd, qdd) = ([0.8, -0.5], [1.5, 2.2], [-3.0, 4.0]);
            let lin = linearize_torque(&ShapeTerms::second(&c, q), qd, qdd);
            let h = 1e-6;
            for l in 0..2 {
                let bump = |v: [f64; 2], s: f64| {
                    let mut w = v;
                    w[l] += s;
                    w
                };
                let fq = |s| inverse_dynamics(&c, bump(q, s), qd, qdd);
                let fv = |s| inverse_dynamics(&c, q, bump(qd, s), qdd);
                let fa = |s| inverse_dynamics(&c, q, qd, bump(qdd, s));
                for i in 0..2 {
                    let dq = (fq(h)[i] - fq(-h)[i]) / (2.0 * h);
                    let dv = (fv(h)[i] - fv(-h)[i]) / (2.0 * h);
                    let da = (fa(h)[i] - fa(-h)[i]) / (2.0 * h);
                    assert!(
                        (dq - lin.d_q[i][l]).abs() < 1e-6,
                        "{joint:?} dq {dq} {}",
                        lin.d_q[i][l]
                    );
                    assert!((dv - lin.d_qd[i][l]).abs() < 1e-6);
                    assert!((da - lin.d_qdd[i][l]).abs() < 1e-8);
                }
            }
        }
    }

    #[test]
    fn momentum_from_body_velocities_vanishes_at_the_reduced_body_rate() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let c = cat(joint);
            let r = nalgebra::Rotation3::new(nalgebra::Vector3::new(0.3, -1.1, 0.7));
            let ra = [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[(i, j)]));
            let (q, qd) = ([0.9, 0.4], [-2.0, 3.0]);
            let w = c.body_rate(q, qd);
            let l = angular_momentum(&c, &ra, w, q, qd);
            let n = l.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(n < 1e-13, "{l:?}");
            // and a wrong body rate shows up
            let l2 = angular_momentum(&c, &ra, [w[0] + 0.1, w[1], w[2]], q, qd);
            assert!(l2.iter().map(|x| x * x).sum::<f64>().sqrt() > 1e-3);
        }
    }
}
