//! The two-cylinder cat (docs/model.md): geometry, joint kinematics and the
//! locked inertia terms of the zero-momentum reduction, written once
//! generically so that num-dual evaluates exact first and second derivatives.
//!
//! Kinetic energy about the common centre of mass, all vectors in body A's
//! frame: with `w = S(q) q_dot` the relative angular velocity of B, `s =
//! R_rel (0,0,l_B/2)` the vector from the joint to B's centre of mass, `d = s +
//! (0,0,l_A/2)` the vector from A's to B's centre of mass, `I_A` and `I_B` the
//! halves' inertias (B's rotated into A's frame) and `mu = m_A m_B / (m_A + m_B)`
//! the reduced mass of the pair (the halves may differ, [`body`]):
//!
//! `T = 1/2 w_A' I_A w_A + 1/2 (w_A + w)' I_B (w_A + w) + 1/2 mu |w_A x d + w x s|^2`
//!   `= 1/2 w_A' J w_A + w_A' Kt w + 1/2 w' Nt w`
//!
//! with `J = I_A + I_B + mu hat(d)'hat(d)`, `Kt = I_B + mu hat(d)'hat(s)`,
//! `Nt = I_B + mu hat(s)'hat(s)` and `hat(a)'hat(b) = (a.b) I - b a'`.
//! Zero angular momentum gives `w_A = -J^-1 K q_dot` with `K = Kt S`, and the
//! reduced mass matrix is `M = S' Nt S - K' J^-1 K`.

pub mod body;
pub mod dynamics;
pub mod momentum;
pub mod motor;
pub mod rigid;
pub mod small;
pub mod so3;
pub mod twist;

pub use body::{Half, InertiaFormula};
pub use rigid::{Halves, Rigid};

use crate::model::small::*;
use nalgebra::{Const, U1};
use num_dual::{Derivative, Dual2SVec64, Dual64};
use serde::{Deserialize, Serialize};

/// How the two halves are joined (docs/model.md section 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Joint {
    /// Kane & Scher: `q` is the rotation vector of B relative to A in A's x-y plane.
    NoTwist,
    /// Two revolute motors: `R_rel = Rx(q1) Ry(q2)`.
    Universal,
}

impl Joint {
    pub fn name(self) -> &'static str {
        match self {
            Joint::NoTwist => "no-twist",
            Joint::Universal => "universal",
        }
    }
}

/// Which norm of the joint torque vector is the "peak" (docs/model.md section 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TorqueNorm {
    /// `|tau|_2`: one actuator that can push in any direction (default for no-twist).
    Euclidean,
    /// `max_i |tau_i|`: one motor per axis (default for universal).
    PerMotor,
}

impl TorqueNorm {
    pub fn of(self, tau: [f64; 2]) -> f64 {
        match self {
            TorqueNorm::Euclidean => tau[0].hypot(tau[1]),
            TorqueNorm::PerMotor => tau[0].abs().max(tau[1].abs()),
        }
    }
    /// The name the config and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            TorqueNorm::Euclidean => "euclidean",
            TorqueNorm::PerMotor => "per-motor",
        }
    }
    pub fn default_for(joint: Joint) -> Self {
        match joint {
            Joint::NoTwist => TorqueNorm::Euclidean,
            Joint::Universal => TorqueNorm::PerMotor,
        }
    }
}

/// The two halves joined at the middle: rear half A (whose frame is the
/// reference) and front half B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cat {
    /// The rear half's cylinder; with `general` halves, the equivalent
    /// cylinder ([`Rigid::equivalent_cylinder`]) for scales and drawings.
    pub rear: Half,
    pub front: Half,
    pub joint: Joint,
    /// General rigid halves (`[body]`); `None`: the cylinders `rear` and `front`.
    pub general: Option<Halves>,
}

impl Cat {
    /// Two identical halves (the seed's cat).
    pub fn symmetric(half: Half, joint: Joint) -> Cat {
        Cat {
            rear: half,
            front: half,
            joint,
            general: None,
        }
    }

    /// General rigid halves: `rear` and `front` become their equivalent cylinders.
    pub fn rigid(halves: Halves, joint: Joint) -> Cat {
        Cat {
            rear: halves.rear.equivalent_cylinder(),
            front: halves.front.equivalent_cylinder(),
            joint,
            general: Some(halves),
        }
    }

    /// The halves as rigid bodies: the general ones, or the cylinders' exactly.
    pub fn halves(&self) -> Halves {
        self.general
            .unwrap_or_else(|| Halves::of_cylinders(&self.rear, &self.front))
    }

    /// The same cat with the halves' roles exchanged (docs/model.md, relabelling).
    pub fn swapped(&self) -> Cat {
        let h = self.halves().swapped();
        Cat {
            rear: self.front,
            front: self.rear,
            joint: self.joint,
            general: Some(h),
        }
    }

    /// Whether the halves are mirror images, axisymmetric about the spine
    /// (the seed's identical cylinders): the seed's closed forms are exact only then.
    pub fn is_symmetric(&self) -> bool {
        match self.general {
            None => self.rear == self.front,
            Some(h) => h.is_mirror_pair(),
        }
    }

    /// Whether both halves are axisymmetric about the spine, so that the
    /// model is (`M(R q) = R M(q) R'` for the no-twist joint; docs/model.md).
    pub fn is_axisymmetric(&self) -> bool {
        self.general.is_none_or(|h| h.is_axisymmetric())
    }

    /// Transverse inertia of a half, `I_t` (for a general half the mean of
    /// `I_xx` and `I_yy`); with unequal halves, the mean of the two
    /// (used only by the seed's closed forms and as a scale).
    pub fn i_t(&self) -> f64 {
        let h = self.halves();
        let t = |r: &Rigid| 0.5 * (r.inertia[0][0] + r.inertia[1][1]);
        0.5 * (t(&h.rear) + t(&h.front))
    }

    /// Axial inertia of a half, `I_a` (`I_zz`); with unequal halves, the mean of the two.
    pub fn i_a(&self) -> f64 {
        let h = self.halves();
        0.5 * (h.rear.inertia[2][2] + h.front.inertia[2][2])
    }

    /// Total mass, kg.
    pub fn mass(&self) -> f64 {
        let h = self.halves();
        h.rear.mass + h.front.mass
    }

    /// Reduced mass of the pair, `m_A m_B / (m_A + m_B)`.
    pub fn reduced_mass(&self) -> f64 {
        let h = self.halves();
        h.rear.mass * h.front.mass / self.mass()
    }

    /// `M(0)`, the straight cat's mass matrix (a multiple of the identity by
    /// axisymmetry), in closed form: with `a = l_A/2`, `b = l_B/2`, `D = a + b`
    /// and `mu` the reduced mass,
    /// `M(0) = I_tB + mu b^2 - (I_tB + mu D b)^2 / (I_tA + I_tB + mu D^2)`,
    /// which is `I_t / 2` for identical halves. General halves break the
    /// axisymmetry and `M(0)` has two eigenvalues: their mean (a scale for
    /// units and gains).
    pub fn straight_inertia(&self) -> f64 {
        let h = self.halves();
        if !h.is_axisymmetric() {
            let (m, _) = self.locked_terms::<f64>([0.0, 0.0]);
            return 0.5 * (m[0][0] + m[1][1]);
        }
        let (ita, itb) = (h.rear.inertia[0][0], h.front.inertia[0][0]);
        let (a, b) = (h.rear.com_to_joint()[2], -h.front.com_to_joint()[2]);
        let (d, mu) = (a + b, self.reduced_mass());
        itb + mu * b * b - (itb + mu * d * b).powi(2) / (ita + itb + mu * d * d)
    }

    /// Rotation of B relative to A, in A's frame.
    pub fn rel_rotation<T: Real>(&self, q: [T; 2]) -> M3<T> {
        match self.joint {
            Joint::NoTwist => exp_so3([q[0], q[1], T::zero()]),
            Joint::Universal => {
                let h = self.halves();
                mat_mul(
                    &rot_about(h.rear.axis, q[0]),
                    &rot_about(h.front.axis, q[1]),
                )
            }
        }
    }

    /// Columns of `S(q)`: B's angular velocity relative to A is `S(q) q_dot` (A frame).
    pub fn rel_rate_jacobian<T: Real>(&self, q: [T; 2]) -> [V3<T>; 2] {
        match self.joint {
            Joint::NoTwist => {
                let jl = left_jacobian_columns([q[0], q[1], T::zero()]);
                [jl[0], jl[1]]
            }
            Joint::Universal => {
                // motor 1's axis is fixed in A; motor 2's turns with motor 1
                let h = self.halves();
                let (a1, a2) = (h.rear.axis.map(c::<T>), h.front.axis.map(c::<T>));
                [a1, mat_vec(&rot_about(h.rear.axis, q[0]), a2)]
            }
        }
    }

    /// Joint-to-B vector `s` and A-to-B vector `d` (centres of mass), both in A's frame.
    pub fn offsets<T: Real>(&self, rel: &M3<T>) -> (V3<T>, V3<T>) {
        let h = self.halves();
        let b = h.front.com_to_joint().map(|x| c::<T>(-x));
        let s = mat_vec(rel, b);
        let a = h.rear.com_to_joint();
        let d = std::array::from_fn(|i| s[i] + c::<T>(a[i]));
        (s, d)
    }

    /// Inertia tensor of a half about its centre of mass, in its own frame.
    pub fn body_inertia<T: Real>(half: &Rigid) -> M3<T> {
        half.inertia.map(|row| row.map(c::<T>))
    }

    /// Reduced mass matrix `M(q)` and connection `A(q) = J^-1 K` (body rate `w_A = -A q_dot`).
    pub fn locked_terms<T: Real>(&self, q: [T; 2]) -> ([[T; 2]; 2], [V3<T>; 2]) {
        self.locked_terms_of(&self.rel_rotation(q), self.rel_rate_jacobian(q))
    }

    /// [`Cat::locked_terms`] of the no-twist cat with its twist freed: `v` is the
    /// full rotation vector of B relative to A (a ball joint), so `M` is 3 x 3.
    /// At `v3 = 0` its upper-left 2 x 2 block is the no-twist `M`; its third row
    /// gives the torque that holds the twist at zero.
    pub fn ball_locked_terms<T: Real>(&self, v: [T; 3]) -> ([[T; 3]; 3], [V3<T>; 3]) {
        self.locked_terms_of(&exp_so3(v), left_jacobian_columns(v))
    }

    /// Locked inertia `J(q)` and the columns of `K(q)` (A frame): the body-frame
    /// angular momentum about the common centre of mass is `J w_A + K q_dot`.
    pub fn locked_inertia<T: Real>(&self, q: [T; 2]) -> (M3<T>, [V3<T>; 2]) {
        let (j, kt, _) = self.locked_parts_of(&self.rel_rotation(q));
        let sj = self.rel_rate_jacobian(q);
        (j, std::array::from_fn(|i| mat_vec(&kt, sj[i])))
    }

    /// `J`, `Kt` and `Nt` of the module doc for a relative rotation `rel`.
    fn locked_parts_of<T: Real>(&self, rel: &M3<T>) -> (M3<T>, M3<T>, M3<T>) {
        let (s, d) = self.offsets(rel);
        let mu = c::<T>(self.reduced_mass());
        let h = self.halves();
        let ic = Self::body_inertia::<T>(&h.rear);
        let ib = mat_mul(
            &mat_mul(rel, &Self::body_inertia::<T>(&h.front)),
            &transpose(rel),
        );
        let gram = |a: V3<T>, b: V3<T>| {
            // hat(a)' hat(b) = (a.b) I - b a'
            let mut m = mat_scale(dot(a, b), &eye3());
            let o = outer(b, a);
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] -= o[i][j];
                }
            }
            m
        };
        let j = mat_add(&mat_add(&ic, &ib), &mat_scale(mu, &gram(d, d)));
        let kt = mat_add(&ib, &mat_scale(mu, &gram(d, s)));
        let nt = mat_add(&ib, &mat_scale(mu, &gram(s, s)));
        (j, kt, nt)
    }

    /// Locked terms for any joint with relative rotation `rel` and rate columns `sj`.
    fn locked_terms_of<T: Real, const N: usize>(
        &self,
        rel: &M3<T>,
        sj: [V3<T>; N],
    ) -> ([[T; N]; N], [V3<T>; N]) {
        let (m, a, _) = self.locked_terms_and_inertia_of(rel, sj);
        (m, a)
    }

    /// [`Cat::locked_terms`] and the locked inertia `J(q)` of the same pass
    /// (the momentum terms need both: one pass instead of two).
    pub fn locked_terms_and_inertia<T: Real>(&self, q: [T; 2]) -> ([[T; 2]; 2], [V3<T>; 2], M3<T>) {
        self.locked_terms_and_inertia_of(&self.rel_rotation(q), self.rel_rate_jacobian(q))
    }

    fn locked_terms_and_inertia_of<T: Real, const N: usize>(
        &self,
        rel: &M3<T>,
        sj: [V3<T>; N],
    ) -> ([[T; N]; N], [V3<T>; N], M3<T>) {
        let (j, kt, nt) = self.locked_parts_of(rel);
        let k: [V3<T>; N] = std::array::from_fn(|i| mat_vec(&kt, sj[i]));
        let a: [V3<T>; N] = std::array::from_fn(|i| solve3(&j, k[i]));
        let mut m = [[T::zero(); N]; N];
        for r in 0..N {
            for cidx in 0..N {
                m[r][cidx] = dot(sj[r], mat_vec(&nt, sj[cidx])) - dot(k[r], a[cidx]);
            }
        }
        (m, a, j)
    }

    /// Body A's angular velocity (A frame) at zero total angular momentum.
    pub fn body_rate(&self, q: [f64; 2], qd: [f64; 2]) -> [f64; 3] {
        let (_, a) = self.locked_terms(q);
        [
            -(a[0][0] * qd[0] + a[1][0] * qd[1]),
            -(a[0][1] * qd[0] + a[1][1] * qd[1]),
            -(a[0][2] * qd[0] + a[1][2] * qd[1]),
        ]
    }
}

/// `exp(hat(v))` (Rodrigues).
fn exp_so3<T: Real>(v: V3<T>) -> M3<T> {
    let (a, b, _) = rodrigues_coefficients(dot(v, v));
    let h = hat(v);
    mat_add(
        &mat_add(&eye3(), &mat_scale(a, &h)),
        &mat_scale(b, &mat_mul(&h, &h)),
    )
}

/// Columns of the left Jacobian of SO(3): `R_dot R' = hat(J_l(v) v_dot)`.
fn left_jacobian_columns<T: Real>(v: V3<T>) -> [V3<T>; 3] {
    let (_, b, c) = rodrigues_coefficients(dot(v, v));
    let h = hat(v);
    let jl = mat_add(
        &mat_add(&eye3(), &mat_scale(b, &h)),
        &mat_scale(c, &mat_mul(&h, &h)),
    );
    [0, 1, 2].map(|k| [jl[0][k], jl[1][k], jl[2][k]])
}

/// Rotation by `a` about the unit axis `n`: the coordinate axes by their
/// own formulas (exactly the cylinders' numbers), any other by Rodrigues.
fn rot_about<T: Real>(n: [f64; 3], a: T) -> M3<T> {
    match n {
        [1.0, 0.0, 0.0] => rot_x(a),
        [0.0, 1.0, 0.0] => rot_y(a),
        _ => {
            let k = hat(n.map(c::<T>));
            mat_add(
                &mat_add(&eye3(), &mat_scale(a.sin(), &k)),
                &mat_scale(T::one() - a.cos(), &mat_mul(&k, &k)),
            )
        }
    }
}

fn rot_x<T: Real>(a: T) -> M3<T> {
    let (s, co) = (a.sin(), a.cos());
    let (z, o) = (T::zero(), T::one());
    [[o, z, z], [z, co, -s], [z, s, co]]
}

fn rot_y<T: Real>(a: T) -> M3<T> {
    let (s, co) = (a.sin(), a.cos());
    let (z, o) = (T::zero(), T::one());
    [[co, z, s], [z, o, z], [-s, z, co]]
}

/// `(sin t / t, (1 - cos t)/t^2, (t - sin t)/t^3)` as functions of `x = t^2`.
/// Series below `x = 1e-2` keep them (and their dual parts) finite at `t = 0`.
fn rodrigues_coefficients<T: Real>(x: T) -> (T, T, T) {
    if x.re() < 1e-2 {
        let series = |k: &[f64]| {
            let mut acc = T::zero();
            for &coef in k.iter().rev() {
                acc = acc * x + c::<T>(coef);
            }
            acc
        };
        (
            series(&[1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0]),
            series(&[
                0.5,
                -1.0 / 24.0,
                1.0 / 720.0,
                -1.0 / 40320.0,
                1.0 / 3628800.0,
            ]),
            series(&[
                1.0 / 6.0,
                -1.0 / 120.0,
                1.0 / 5040.0,
                -1.0 / 362880.0,
                1.0 / 39916800.0,
            ]),
        )
    } else {
        let t = x.sqrt();
        let (s, co) = (t.sin(), t.cos());
        (s / t, (T::one() - co) / x, (t - s) / (x * t))
    }
}

/// `M(q)`, `A(q)` and their exact derivatives at one shape.
///
/// `dm[k][i][j] = dM_ij/dq_k`, `d2m[k][l][i][j] = d2M_ij/dq_k dq_l`,
/// `a[j]` is column j of `A` (a 3-vector), `da[k][j] = dA_{.j}/dq_k`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ShapeTerms {
    pub m: [[f64; 2]; 2],
    pub dm: [[[f64; 2]; 2]; 2],
    pub d2m: [[[[f64; 2]; 2]; 2]; 2],
    pub a: [[f64; 3]; 2],
    pub da: [[[f64; 3]; 2]; 2],
}

impl ShapeTerms {
    /// Value and first derivatives (forward dynamics, path timing): one
    /// pass of scalar duals per direction, faster than one pass of
    /// num-dual's gradient type (`DualSVec64<2>`, whose derivative is an
    /// optional nalgebra vector) and the same numbers (measured:
    /// docs/benchmarks.md, "Design settings: the measurements behind them").
    pub fn first(cat: &Cat, q: [f64; 2]) -> Self {
        let pass = |k: usize| {
            let x = [0, 1].map(|i| Dual64::new(q[i], if i == k { 1.0 } else { 0.0 }));
            cat.locked_terms(x)
        };
        Self::of_passes(&[pass(0), pass(1)])
    }

    /// [`ShapeTerms::first`] and `J^-1 lambda` with its derivatives along
    /// the same passes (`u[k]`: the pass along `q_k`), the same numbers as
    /// the passes of the momentum module's `momentum_torque`.
    pub fn first_with_momentum(cat: &Cat, q: [f64; 2], lam: [f64; 3]) -> (Self, [[Dual64; 3]; 2]) {
        let pass = |k: usize| {
            let x = [0, 1].map(|i| Dual64::new(q[i], if i == k { 1.0 } else { 0.0 }));
            let (m, a, j) = cat.locked_terms_and_inertia(x);
            ((m, a), solve3(&j, lam.map(Dual64::from_re)))
        };
        let (p0, p1) = (pass(0), pass(1));
        (Self::of_passes(&[p0.0, p1.0]), [p0.1, p1.1])
    }

    #[allow(clippy::type_complexity)]
    fn of_passes(passes: &[([[Dual64; 2]; 2], [V3<Dual64>; 2]); 2]) -> Self {
        let mut t = ShapeTerms::default();
        for i in 0..2 {
            for j in 0..2 {
                t.m[i][j] = passes[0].0[i][j].re;
                for k in 0..2 {
                    t.dm[k][i][j] = passes[k].0[i][j].eps;
                }
            }
        }
        for j in 0..2 {
            for r in 0..3 {
                t.a[j][r] = passes[0].1[j][r].re;
                for k in 0..2 {
                    t.da[k][j][r] = passes[k].1[j][r].eps;
                }
            }
        }
        t
    }

    /// Value, first and second derivatives (torque linearisation).
    pub fn second(cat: &Cat, q: [f64; 2]) -> Self {
        let x = [
            Dual2SVec64::<2>::from_re(q[0]).derivative(0),
            Dual2SVec64::<2>::from_re(q[1]).derivative(1),
        ];
        let (m, a) = cat.locked_terms(x);
        let parts = |v: &Dual2SVec64<2>| -> ([f64; 2], [[f64; 2]; 2]) {
            let g = unwrap_row(&v.v1);
            let h = v.v2.unwrap_generic(Const::<2>, Const::<2>);
            (g, [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]])
        };
        let mut t = ShapeTerms::default();
        for i in 0..2 {
            for j in 0..2 {
                t.m[i][j] = m[i][j].re;
                let (gr, he) = parts(&m[i][j]);
                for k in 0..2 {
                    t.dm[k][i][j] = gr[k];
                    for l in 0..2 {
                        t.d2m[k][l][i][j] = he[k][l];
                    }
                }
            }
        }
        for j in 0..2 {
            for r in 0..3 {
                t.a[j][r] = a[j][r].re;
                let (gr, _) = parts(&a[j][r]);
                for k in 0..2 {
                    t.da[k][j][r] = gr[k];
                }
            }
        }
        t
    }

    /// Body rate `w_A = -A q_dot`.
    pub fn body_rate(&self, qd: [f64; 2]) -> [f64; 3] {
        let mut w = [0.0; 3];
        for (r, wr) in w.iter_mut().enumerate() {
            *wr = -(self.a[0][r] * qd[0] + self.a[1][r] * qd[1]);
        }
        w
    }

    /// `d w_A / d q_k` at rate `qd` (columns k = 0, 1).
    pub fn body_rate_dq(&self, qd: [f64; 2]) -> [[f64; 3]; 2] {
        let mut out = [[0.0; 3]; 2];
        for (k, col) in out.iter_mut().enumerate() {
            for (r, x) in col.iter_mut().enumerate() {
                *x = -(self.da[k][0][r] * qd[0] + self.da[k][1][r] * qd[1]);
            }
        }
        out
    }
}

fn unwrap_row(d: &Derivative<f64, U1, Const<2>>) -> [f64; 2] {
    let g = d.unwrap_generic(U1, Const::<2>);
    [g[0], g[1]]
}

#[cfg(test)]
mod tests {
    use super::*;

    pub fn seed_cat(joint: Joint) -> Cat {
        Cat::symmetric(
            Half {
                mass: 1.0,
                length: 1.0,
                radius: 0.1,
                inertia: InertiaFormula::SolidCylinder,
            },
            joint,
        )
    }

    /// A heavy short rear and a light long front.
    pub fn unequal_cat(joint: Joint) -> Cat {
        let mut cat = seed_cat(joint);
        cat.rear = Half {
            mass: 2.5,
            length: 0.6,
            radius: 0.15,
            inertia: InertiaFormula::SolidCylinder,
        };
        cat
    }

    #[test]
    fn straight_mass_matrix_of_unequal_halves_matches_its_closed_form() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            for cat in [unequal_cat(joint), {
                let c = unequal_cat(joint);
                Cat {
                    rear: c.front,
                    front: c.rear,
                    joint,
                    general: None,
                }
            }] {
                let t = ShapeTerms::second(&cat, [0.0, 0.0]);
                let m0 = cat.straight_inertia();
                assert!((t.m[0][0] - m0).abs() < 1e-14 * m0, "{:?} vs {m0}", t.m);
                assert!((t.m[1][1] - m0).abs() < 1e-14 * m0);
                assert!(t.m[0][1].abs() < 1e-14 * m0);
            }
            // and it reduces to I_t / 2 for identical halves
            let c = seed_cat(joint);
            assert!((c.straight_inertia() - c.i_t() / 2.0).abs() < 1e-15);
        }
    }

    #[test]
    fn straight_cat_mass_matrix_is_half_transverse_inertia() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let cat = seed_cat(joint);
            let t = ShapeTerms::second(&cat, [0.0, 0.0]);
            let half = cat.i_t() / 2.0;
            assert!((t.m[0][0] - half).abs() < 1e-14, "{joint:?} {:?}", t.m);
            assert!((t.m[1][1] - half).abs() < 1e-14);
            assert!(t.m[0][1].abs() < 1e-14);
            for x in
                t.dm.iter()
                    .flatten()
                    .flatten()
                    .chain(t.d2m.iter().flatten().flatten().flatten())
            {
                assert!(x.is_finite());
            }
        }
    }

    #[test]
    fn no_twist_rotation_is_exponential_map() {
        let cat = seed_cat(Joint::NoTwist);
        let q = [0.7, -0.4];
        let r = cat.rel_rotation::<f64>(q);
        let n = nalgebra::Rotation3::new(nalgebra::Vector3::new(q[0], q[1], 0.0));
        for i in 0..3 {
            for j in 0..3 {
                assert!((r[i][j] - n[(i, j)]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn rate_jacobian_matches_finite_difference_of_rotation() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let cat = seed_cat(joint);
            for q in [[0.7f64, -0.4], [0.01, 0.02], [2.0, 1.0]] {
                let sj = cat.rel_rate_jacobian::<f64>(q);
                let r = nalgebra::Matrix3::from_fn(|i, j| cat.rel_rotation::<f64>(q)[i][j]);
                for k in 0..2 {
                    let h = 1e-6;
                    let mut qp = q;
                    let mut qm = q;
                    qp[k] += h;
                    qm[k] -= h;
                    let rp = nalgebra::Matrix3::from_fn(|i, j| cat.rel_rotation::<f64>(qp)[i][j]);
                    let rm = nalgebra::Matrix3::from_fn(|i, j| cat.rel_rotation::<f64>(qm)[i][j]);
                    let w = (rp - rm) / (2.0 * h) * r.transpose();
                    let v = [w[(2, 1)], w[(0, 2)], w[(1, 0)]];
                    for i in 0..3 {
                        assert!((v[i] - sj[k][i]).abs() < 1e-8, "{joint:?} {q:?} {k}");
                    }
                }
            }
        }
    }

    #[test]
    fn dual_derivatives_match_finite_differences() {
        for joint in [Joint::NoTwist, Joint::Universal] {
            let cat = seed_cat(joint);
            for q in [[0.9, 0.3], [0.05, -0.08], [-1.7, 2.1]] {
                let t = ShapeTerms::second(&cat, q);
                let h = 1e-5;
                for k in 0..2 {
                    let mut qp = q;
                    let mut qm = q;
                    qp[k] += h;
                    qm[k] -= h;
                    let tp = ShapeTerms::first(&cat, qp);
                    let tm = ShapeTerms::first(&cat, qm);
                    for i in 0..2 {
                        for j in 0..2 {
                            let fd = (tp.m[i][j] - tm.m[i][j]) / (2.0 * h);
                            assert!((fd - t.dm[k][i][j]).abs() < 1e-8);
                            for l in 0..2 {
                                let fd2 = (tp.dm[l][i][j] - tm.dm[l][i][j]) / (2.0 * h);
                                assert!(
                                    (fd2 - t.d2m[k][l][i][j]).abs() < 1e-7,
                                    "{fd2} {}",
                                    t.d2m[k][l][i][j]
                                );
                            }
                        }
                        for r in 0..3 {
                            let fd = (tp.a[i][r] - tm.a[i][r]) / (2.0 * h);
                            assert!((fd - t.da[k][i][r]).abs() < 1e-8);
                        }
                    }
                }
            }
        }
    }
}
