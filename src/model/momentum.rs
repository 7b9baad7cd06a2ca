//! Free fall with angular momentum (docs/model.md, "Any start"; MODEL.md section 6).
//!
//! The total angular momentum `L` (world frame) is constant; in A's frame it is
//! `lambda = R_A' L`, which turns as `lambda_dot = lambda x w_A`. Body A's rate is
//! `w_A = J(q)^-1 lambda - A(q) q_dot` and the shape obeys the horizontal
//! Lagrange-Poincare equation of the trivialised Lagrangian
//! `l(w_A, q, q_dot) = 1/2 w_A' J w_A + w_A' K q_dot + 1/2 q_dot' N q_dot`:
//!
//! `tau = M q_ddot + h(q, q_dot) + g(q, q_dot, lambda)`, with
//! `g_i = sum_j q_dot_j lambda . (dA_i/dq_j - dA_j/dq_i) + A_i . (lambda x w_A)
//!        + d/dq_i (1/2 lambda' J^-1 lambda)`
//!
//! (`A_i` the i-th column of `A = J^-1 K`): a gyroscopic term that does no work,
//! the change of the momentum's A-frame coordinates, and the gradient of the
//! amended potential. `g` vanishes exactly at `lambda = 0`, so the
//! zero-momentum model of [`super::dynamics`] is this one's special case, bit for bit.
//! Written generically over [`Real`]: inner dual numbers give the shape
//! derivatives, and outer ones differentiate the whole torque exactly.

use super::Cat;
use super::ShapeTerms;
use super::dynamics::{bias, solve2};
use super::small::*;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use num_dual::Dual;

/// How the cat is let go (MODEL.md section 6): straight and rigid, with
/// attitude `R0` (A's frame to world) and body rate `w0` (A's coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// `R0` as a unit quaternion `[w, x, y, z]`.
    pub attitude: [f64; 4],
    /// `w0`, rad/s, about A's own axes.
    pub body_rate: [f64; 3],
}

impl Default for Start {
    /// Upside down and at rest: today's problem.
    fn default() -> Self {
        Start {
            attitude: [1.0, 0.0, 0.0, 0.0],
            body_rate: [0.0; 3],
        }
    }
}

impl Start {
    /// From a rotation vector (rad, world axes) and a body rate (rad/s).
    pub fn new(rotation: [f64; 3], body_rate: [f64; 3]) -> Start {
        let q = UnitQuaternion::from_scaled_axis(Vector3::from(rotation));
        Start {
            attitude: [q.w, q.i, q.j, q.k],
            body_rate,
        }
    }

    pub fn rotation(&self) -> UnitQuaternion<f64> {
        crate::model::so3::quat_from(&self.attitude)
    }

    /// Body-frame momentum at release, `J(0) w0`, N m s.
    pub fn body_momentum(&self, cat: &Cat) -> [f64; 3] {
        let (j, _) = cat.locked_inertia::<f64>([0.0; 2]);
        mat_vec(&j, self.body_rate)
    }

    /// World-frame momentum `L = R0 J(0) w0`, N m s (constant in free fall).
    pub fn momentum(&self, cat: &Cat) -> [f64; 3] {
        let l = self.rotation() * Vector3::from(self.body_momentum(cat));
        [l.x, l.y, l.z]
    }
}

/// The momentum part `g(q, q_dot, lambda)` of the joint torque (module doc).
pub fn momentum_torque<T: Real>(cat: &Cat, q: [T; 2], qd: [T; 2], lam: [T; 3]) -> [T; 2] {
    // one inner dual pass per shape direction: A, dA/dq_k, J^-1 lambda and its derivative
    let pass = |k: usize| {
        let x: [Dual<T>; 2] =
            std::array::from_fn(|i| Dual::new(q[i], if i == k { T::one() } else { T::zero() }));
        let (j, kk) = cat.locked_inertia(x);
        let a = [solve3(&j, kk[0]), solve3(&j, kk[1])];
        let u = solve3(&j, lam.map(Dual::from_re));
        (a, u)
    };
    let p = [pass(0), pass(1)];
    let a: [V3<T>; 2] = std::array::from_fn(|j| p[0].0[j].map(|x| x.re));
    // da[k][j] = dA_j / dq_k
    let da: [[V3<T>; 2]; 2] =
        std::array::from_fn(|k| std::array::from_fn(|j| p[k].0[j].map(|x| x.eps)));
    let u = p[0].1.map(|x| x.re);
    let xi: V3<T> = std::array::from_fn(|r| u[r] - a[0][r] * qd[0] - a[1][r] * qd[1]);
    let turn = cross(lam, xi);
    let half = c::<T>(0.5);
    std::array::from_fn(|i| {
        let mut g = dot(a[i], turn) + half * dot(lam, p[i].1.map(|x| x.eps));
        for j in 0..2 {
            let curl: V3<T> = std::array::from_fn(|r| da[j][i][r] - da[i][j][r]);
            g += qd[j] * dot(lam, curl);
        }
        g
    })
}

/// The shape terms at `q` and the momentum torque `g` of [`momentum_torque`]
/// (zero at `lambda = 0`) from one pair of dual passes, the same numbers to
/// the bit: the simulators evaluate both every stage.
pub fn shape_and_momentum_torque(
    cat: &Cat,
    q: [f64; 2],
    qd: [f64; 2],
    lam: [f64; 3],
) -> (ShapeTerms, [f64; 2]) {
    if is_zero(lam) {
        return (ShapeTerms::first(cat, q), [0.0; 2]);
    }
    let (t, u) = ShapeTerms::first_with_momentum(cat, q, lam);
    let (a, da) = (t.a, t.da);
    let u0 = u[0].map(|x| x.re);
    let xi: V3<f64> = std::array::from_fn(|r| u0[r] - a[0][r] * qd[0] - a[1][r] * qd[1]);
    let turn = cross(lam, xi);
    let half = c::<f64>(0.5);
    let g = std::array::from_fn(|i| {
        let mut g = dot(a[i], turn) + half * dot(lam, u[i].map(|x| x.eps));
        for j in 0..2 {
            let curl: V3<f64> = std::array::from_fn(|r| da[j][i][r] - da[i][j][r]);
            g += qd[j] * dot(lam, curl);
        }
        g
    });
    (t, g)
}

/// Shape acceleration `M^-1 (tau - h - g)` from the terms of
/// [`shape_and_momentum_torque`]: [`forward_dynamics_from`]'s numbers.
pub fn forward_dynamics_with(
    t: &ShapeTerms,
    qd: [f64; 2],
    tau: [f64; 2],
    g: [f64; 2],
    lam: [f64; 3],
) -> [f64; 2] {
    let h = bias(t, qd);
    let mut f = [tau[0] - h[0], tau[1] - h[1]];
    if !is_zero(lam) {
        f = [f[0] - g[0], f[1] - g[1]];
    }
    solve2(&t.m, f)
}

/// Body A's rate `w_A = J^-1 lambda - A q_dot` (A frame), generic.
pub fn body_rate_with<T: Real>(cat: &Cat, q: [T; 2], qd: [T; 2], lam: [T; 3]) -> [T; 3] {
    let (j, k) = cat.locked_inertia(q);
    let rhs: V3<T> = std::array::from_fn(|r| lam[r] - k[0][r] * qd[0] - k[1][r] * qd[1]);
    solve3(&j, rhs)
}

fn is_zero(lam: [f64; 3]) -> bool {
    lam == [0.0; 3]
}

/// Body rate from precomputed shape terms: at `lambda = 0` exactly the
/// zero-momentum rate `-A q_dot` (the same floating-point operations).
pub fn body_rate_from(
    cat: &Cat,
    t: &ShapeTerms,
    q: [f64; 2],
    qd: [f64; 2],
    lam: [f64; 3],
) -> [f64; 3] {
    let w = t.body_rate(qd);
    if is_zero(lam) {
        return w;
    }
    let (j, _) = cat.locked_inertia(q);
    add3(w, solve3(&j, lam))
}

/// Body rate at a shape: at `lambda = 0` exactly [`Cat::body_rate`].
pub fn body_rate(cat: &Cat, q: [f64; 2], qd: [f64; 2], lam: [f64; 3]) -> [f64; 3] {
    let w = cat.body_rate(q, qd);
    if is_zero(lam) {
        return w;
    }
    let (j, _) = cat.locked_inertia(q);
    add3(w, solve3(&j, lam))
}

/// Joint torque with momentum, `M q_ddot + h + g`.
pub fn inverse_dynamics_with(
    cat: &Cat,
    q: [f64; 2],
    qd: [f64; 2],
    qdd: [f64; 2],
    lam: [f64; 3],
) -> [f64; 2] {
    let tau = super::dynamics::inverse_dynamics(cat, q, qd, qdd);
    if is_zero(lam) {
        return tau;
    }
    let g = momentum_torque(cat, q, qd, lam);
    [tau[0] + g[0], tau[1] + g[1]]
}

/// Shape acceleration with momentum from precomputed terms, `M^-1 (tau - h - g)`.
pub fn forward_dynamics_from(
    cat: &Cat,
    t: &ShapeTerms,
    q: [f64; 2],
    qd: [f64; 2],
    tau: [f64; 2],
    lam: [f64; 3],
) -> [f64; 2] {
    let h = bias(t, qd);
    let mut f = [tau[0] - h[0], tau[1] - h[1]];
    if !is_zero(lam) {
        let g = momentum_torque(cat, q, qd, lam);
        f = [f[0] - g[0], f[1] - g[1]];
    }
    solve2(&t.m, f)
}

/// Kinetic energy about the common centre of mass,
/// `1/2 q_dot' M q_dot + 1/2 lambda' J^-1 lambda`.
pub fn kinetic_energy_with(cat: &Cat, q: [f64; 2], qd: [f64; 2], lam: [f64; 3]) -> f64 {
    let shape = super::dynamics::kinetic_energy(cat, q, qd);
    let (j, _) = cat.locked_inertia(q);
    shape + 0.5 * dot(lam, solve3(&j, lam))
}

/// Axial and transverse inertia `(I_3, I_1)` of the locked straight cat (F8).
pub fn straight_inertias(cat: &Cat) -> (f64, f64) {
    let (j, _) = cat.locked_inertia::<f64>([0.0; 2]);
    (j[2][2], j[0][0])
}

/// Attitude of the locked straight cat after turning rigidly for `t` seconds
/// from `r` with body momentum `lam` (F8, closed form): `exp(t hat(L) / I_1) r
/// exp(t alpha hat(e_z))`, `L = r lam`, `alpha = (I_1 - I_3) w_3 / I_1`,
/// `w_3 = lam_3 / I_3`.
pub fn rigid_turn(cat: &Cat, r: &Matrix3<f64>, lam: [f64; 3], t: f64) -> Matrix3<f64> {
    if is_zero(lam) || t == 0.0 {
        return *r;
    }
    let (i3, i1) = straight_inertias(cat);
    let l = r * Vector3::from(lam);
    let alpha = (i1 - i3) * lam[2] / (i3 * i1);
    let so3 = |v: Vector3<f64>| crate::model::so3::exp(&v);
    so3(l * (t / i1)) * r * so3(Vector3::z() * (alpha * t))
}

/// Landing error of an attitude, rad: the belly's (A's `+x`) angle from
/// straight down (world `-x`), `acos(-(R e_x) . e_x)`.
pub fn landing_error(r: &Matrix3<f64>) -> f64 {
    // atan2 of the sine and cosine parts: exact near belly-down, where acos is not
    r[(1, 0)].hypot(r[(2, 0)]).atan2(-r[(0, 0)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Half, InertiaFormula, Joint};
    use num_dual::Dual64;

    fn cats() -> Vec<Cat> {
        let half = Half {
            mass: 1.3,
            length: 0.8,
            radius: 0.12,
            inertia: InertiaFormula::SolidCylinder,
        };
        let mut out = Vec::new();
        for joint in [Joint::NoTwist, Joint::Universal] {
            let sym = Cat::symmetric(half, joint);
            let mut un = sym;
            un.rear = Half {
                mass: 2.5,
                length: 0.6,
                radius: 0.15,
                ..half
            };
            out.extend([sym, un]);
        }
        out
    }

    /// `g` and the body rate differentiated by outer duals agree with central differences.
    #[test]
    fn momentum_terms_match_finite_differences() {
        let (q, qd, lam) = ([0.7, -0.4], [1.3, -2.1], [0.2, -0.35, 0.5]);
        let x: Vec<f64> = q.iter().chain(&qd).chain(&lam).copied().collect();
        for cat in cats() {
            let eval = |v: &[f64]| {
                let g = momentum_torque(&cat, [v[0], v[1]], [v[2], v[3]], [v[4], v[5], v[6]]);
                let w = body_rate_with(&cat, [v[0], v[1]], [v[2], v[3]], [v[4], v[5], v[6]]);
                [g[0], g[1], w[0], w[1], w[2]]
            };
            for k in 0..7 {
                let d: Vec<Dual64> = x
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| Dual64::new(v, if i == k { 1.0 } else { 0.0 }))
                    .collect();
                let g = momentum_torque(&cat, [d[0], d[1]], [d[2], d[3]], [d[4], d[5], d[6]]);
                let w = body_rate_with(&cat, [d[0], d[1]], [d[2], d[3]], [d[4], d[5], d[6]]);
                let exact = [g[0].eps, g[1].eps, w[0].eps, w[1].eps, w[2].eps];
                let h = 1e-6;
                let (mut p, mut m) = (x.clone(), x.clone());
                p[k] += h;
                m[k] -= h;
                let (fp, fm) = (eval(&p), eval(&m));
                for r in 0..5 {
                    let fd = (fp[r] - fm[r]) / (2.0 * h);
                    assert!(
                        (fd - exact[r]).abs() < 1e-7 * (1.0 + fd.abs()),
                        "{cat:?} d{r}/dx{k}: {fd} vs {}",
                        exact[r]
                    );
                }
            }
        }
    }

    /// The amended potential part of `g` is the gradient of `1/2 lambda' J^-1 lambda`,
    /// and at rest in shape `g` is that gradient plus `A' (lambda x w)`.
    #[test]
    fn momentum_torque_at_shape_rest_is_the_amended_potential_gradient_and_turning() {
        let (q, lam) = ([0.5, 0.9], [0.3, 0.1, -0.6]);
        for cat in cats() {
            let g = momentum_torque(&cat, q, [0.0; 2], lam);
            let v = |q: [f64; 2]| {
                let (j, _) = cat.locked_inertia(q);
                0.5 * dot(lam, solve3(&j, lam))
            };
            let (_, a) = cat.locked_terms(q);
            let w = body_rate_with(&cat, q, [0.0; 2], lam);
            let turn = cross(lam, w);
            let h = 1e-6;
            for i in 0..2 {
                let (mut p, mut m) = (q, q);
                p[i] += h;
                m[i] -= h;
                let want = (v(p) - v(m)) / (2.0 * h) + dot(a[i], turn);
                assert!((g[i] - want).abs() < 1e-8, "{} vs {want}", g[i]);
            }
        }
    }

    /// The fused passes give [`ShapeTerms::first`] and [`momentum_torque`] to the bit.
    #[test]
    fn fused_shape_and_momentum_terms_are_the_separate_ones_bit_for_bit() {
        let states = [
            ([0.7, -0.4], [1.3, -2.1], [0.2, -0.35, 0.5]),
            ([0.01, 0.02], [-0.3, 0.8], [1e-3, 0.0, -2e-3]),
            ([-1.9, 1.2], [4.0, 0.1], [-3.0, 1.5, 0.7]),
            ([0.3, 1.1], [-0.7, 0.4], [0.0; 3]),
        ];
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for cat in cats() {
            for (q, qd, lam) in states {
                let (t, g) = shape_and_momentum_torque(&cat, q, qd, lam);
                let t0 = ShapeTerms::first(&cat, q);
                let flat = |t: &ShapeTerms| {
                    let mut v: Vec<f64> = t.m.iter().flatten().copied().collect();
                    v.extend(t.dm.iter().flatten().flatten());
                    v.extend(t.a.iter().flatten());
                    v.extend(t.da.iter().flatten().flatten());
                    v
                };
                assert_eq!(bits(&flat(&t)), bits(&flat(&t0)), "{cat:?} {q:?}");
                assert_eq!(bits(&g), bits(&momentum_torque(&cat, q, qd, lam)));
                let tau = [0.3, -0.2];
                assert_eq!(
                    bits(&forward_dynamics_with(&t, qd, tau, g, lam)),
                    bits(&forward_dynamics_from(&cat, &t0, q, qd, tau, lam))
                );
            }
        }
    }

    #[test]
    fn zero_momentum_adds_exactly_nothing() {
        for cat in cats() {
            let (q, qd, qdd) = ([0.3, 1.1], [-0.7, 0.4], [2.0, -1.0]);
            let g = momentum_torque(&cat, q, qd, [0.0; 3]);
            assert_eq!(g, [0.0, 0.0]);
            let t = ShapeTerms::first(&cat, q);
            assert_eq!(
                body_rate_from(&cat, &t, q, qd, [0.0; 3]),
                cat.body_rate(q, qd)
            );
            assert_eq!(
                inverse_dynamics_with(&cat, q, qd, qdd, [0.0; 3]),
                super::super::dynamics::inverse_dynamics(&cat, q, qd, qdd)
            );
            // the general rate formula agrees with the zero-momentum one to round-off
            let w = body_rate_with(&cat, q, qd, [0.0; 3]);
            let w0 = cat.body_rate(q, qd);
            for r in 0..3 {
                assert!((w[r] - w0[r]).abs() < 1e-14);
            }
        }
    }
}
