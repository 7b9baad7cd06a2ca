//! Tiny fixed-size linear algebra generic over the scalar type.
//!
//! The model's kinematics are written once, generic over [`Real`], and evaluated
//! with `f64` for simulation and with num-dual's dual numbers for exact
//! derivatives. nalgebra's generic matrices would need `RealField` for the
//! inverse; the 3x3 cofactor solve below needs only field operations.

use num_dual::DualNum;

/// Scalar usable by the model: `f64` or a num-dual dual number over `f64`.
pub trait Real: DualNum<Primitive = f64> + Copy {}
impl<T: DualNum<Primitive = f64> + Copy> Real for T {}

pub type V3<T> = [T; 3];
pub type M3<T> = [[T; 3]; 3];

pub fn c<T: Real>(x: f64) -> T {
    T::from(x)
}

pub fn zero3<T: Real>() -> M3<T> {
    [[T::zero(); 3]; 3]
}

pub fn eye3<T: Real>() -> M3<T> {
    let mut m = zero3();
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = T::one();
    }
    m
}

pub fn hat<T: Real>(v: V3<T>) -> M3<T> {
    let z = T::zero();
    [[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]]
}

pub fn dot<T: Real>(a: V3<T>, b: V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn add3<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn scale3<T: Real>(s: T, a: V3<T>) -> V3<T> {
    [s * a[0], s * a[1], s * a[2]]
}

pub fn mat_add<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    let mut m = *a;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] += b[i][j];
        }
    }
    m
}

pub fn mat_scale<T: Real>(s: T, a: &M3<T>) -> M3<T> {
    let mut m = *a;
    for row in m.iter_mut() {
        for x in row.iter_mut() {
            *x *= s;
        }
    }
    m
}

pub fn mat_mul<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    let mut m = zero3();
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    m
}

pub fn transpose<T: Real>(a: &M3<T>) -> M3<T> {
    let mut m = *a;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[j][i];
        }
    }
    m
}

pub fn mat_vec<T: Real>(a: &M3<T>, v: V3<T>) -> V3<T> {
    [dot(a[0], v), dot(a[1], v), dot(a[2], v)]
}

/// `a b^T`
pub fn outer<T: Real>(a: V3<T>, b: V3<T>) -> M3<T> {
    let mut m = zero3();
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[i] * b[j];
        }
    }
    m
}

/// Solves `A x = b` for a 3x3 `A` by Cramer's rule (A is the locked inertia: SPD, well conditioned).
pub fn solve3<T: Real>(a: &M3<T>, b: V3<T>) -> V3<T> {
    let cof = [cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1])];
    // inverse = cof^T / det with cof rows being columns of adj
    let det = dot(a[0], cof[0]);
    let inv_det = det.recip();
    // x = adj(A) b / det, adj(A) = [cof0 cof1 cof2] as columns
    let mut x = [T::zero(); 3];
    for (k, xk) in x.iter_mut().enumerate() {
        *xk = (cof[0][k] * b[0] + cof[1][k] * b[1] + cof[2][k] * b[2]) * inv_det;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve3_inverts_matvec() {
        let a: M3<f64> = [[4.0, 1.0, 0.5], [1.0, 3.0, -0.2], [0.5, -0.2, 2.0]];
        let x: V3<f64> = [0.3, -1.2, 2.5];
        let b = mat_vec(&a, x);
        let y = solve3(&a, b);
        for k in 0..3 {
            assert!((x[k] - y[k]).abs() < 1e-14);
        }
    }

    #[test]
    fn hat_is_cross_product() {
        let a: V3<f64> = [0.3, -1.2, 2.5];
        let b: V3<f64> = [1.0, 0.4, -0.7];
        let h = mat_vec(&hat(a), b);
        let x = cross(a, b);
        for k in 0..3 {
            assert!((h[k] - x[k]).abs() < 1e-15);
        }
    }
}
