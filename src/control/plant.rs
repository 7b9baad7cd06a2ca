//! The closed loop's plant: the free-floating cat of MODEL.md section 6 as a
//! fixed-step RK4 map on `y = [quaternion w x y z, q, q_dot, lambda]`
//! (`lambda = R_A' L`, the body-frame momentum), and the error coordinates
//! the feedback works in.
//!
//! Fixed steps, not the adaptive pair of `verify::simulate`: a discrete
//! controller updates on a clock, delays are whole steps, and the
//! linearisation of one control period is then the derivative of exactly
//! the map the simulation applies.

use crate::model::momentum::{body_rate_from, forward_dynamics_with, shape_and_momentum_torque};
use crate::model::small::cross;
use crate::model::so3::{normalize_quat, quat_from, quat_rate};
use crate::model::{Cat, ShapeTerms};
use nalgebra::{SVector, UnitQuaternion, Vector3};

/// The integrator state `[qw, qx, qy, qz, q1, q2, qd1, qd2, l1, l2, l3]`.
pub type Y = [f64; 11];

/// The error state `[dtheta (3), dlambda (3), dq (2), dqd (2)]`: `dtheta` the
/// rotation vector of `R_nom' R_A` (A's frame), the rest plain differences.
pub type X = SVector<f64, 10>;

/// Dimension of [`X`].
pub const NX: usize = 10;

/// `dy/dt` under joint torque `tau`.
pub fn rhs(cat: &Cat, y: &Y, tau: [f64; 2]) -> Y {
    let (q, qd, lam) = ([y[4], y[5]], [y[6], y[7]], [y[8], y[9], y[10]]);
    let (terms, g) = shape_and_momentum_torque(cat, q, qd, lam);
    let qdd = forward_dynamics_with(&terms, qd, tau, g, lam);
    let w = body_rate_from(cat, &terms, q, qd, lam);
    let dq = quat_rate(y, w);
    let dl = cross(lam, w);
    [
        dq[0], dq[1], dq[2], dq[3], qd[0], qd[1], qdd[0], qdd[1], dl[0], dl[1], dl[2],
    ]
}

/// Body A's rate (A frame) in state `y`: what a gyro on the rear half reads.
pub fn gyro(cat: &Cat, y: &Y) -> [f64; 3] {
    let q = [y[4], y[5]];
    body_rate_from(
        cat,
        &ShapeTerms::first(cat, q),
        q,
        [y[6], y[7]],
        [y[8], y[9], y[10]],
    )
}

/// Body-frame momentum from a measured body rate and shape rate,
/// `lambda = J(q) w_A + K(q) q_dot` in `cat`'s inertias.
pub fn momentum_from_rates(cat: &Cat, q: [f64; 2], qd: [f64; 2], w: [f64; 3]) -> [f64; 3] {
    let (j, k) = cat.locked_inertia::<f64>(q);
    std::array::from_fn(|r| {
        j[r][0] * w[0] + j[r][1] * w[1] + j[r][2] * w[2] + k[0][r] * qd[0] + k[1][r] * qd[1]
    })
}

/// One RK4 step of length `h`; `tau(stage, y)` gives the torque at the
/// step's start (0), middle (1) and end (2).
pub fn rk4(cat: &Cat, y: &Y, h: f64, mut tau: impl FnMut(usize, &Y) -> [f64; 2]) -> Y {
    let add = |a: &Y, k: &Y, s: f64| -> Y { std::array::from_fn(|i| a[i] + s * k[i]) };
    let k1 = rhs(cat, y, tau(0, y));
    let y2 = add(y, &k1, 0.5 * h);
    let k2 = rhs(cat, &y2, tau(1, &y2));
    let y3 = add(y, &k2, 0.5 * h);
    let k3 = rhs(cat, &y3, tau(1, &y3));
    let y4 = add(y, &k3, h);
    let k4 = rhs(cat, &y4, tau(2, &y4));
    let mut out: Y =
        std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    normalize_quat(&mut out);
    out
}

pub fn attitude(y: &Y) -> UnitQuaternion<f64> {
    quat_from(y)
}

/// The error of `y` about the nominal `nom`.
pub fn error(y: &Y, nom: &Y) -> X {
    let d = (attitude(nom).inverse() * attitude(y)).scaled_axis();
    let mut x = X::zeros();
    for i in 0..3 {
        x[i] = d[i];
        x[3 + i] = y[8 + i] - nom[8 + i];
    }
    for i in 0..4 {
        x[6 + i] = y[4 + i] - nom[4 + i];
    }
    x
}

/// The state at error `x` about `nom` (the inverse of [`error`]).
pub fn perturb(nom: &Y, x: &X) -> Y {
    let r = attitude(nom) * UnitQuaternion::from_scaled_axis(Vector3::new(x[0], x[1], x[2]));
    let mut y = *nom;
    y[..4].copy_from_slice(&[r.w, r.i, r.j, r.k]);
    for i in 0..4 {
        y[4 + i] += x[6 + i];
    }
    for i in 0..3 {
        y[8 + i] += x[3 + i];
    }
    y
}
