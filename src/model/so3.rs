//! Attitude helpers: flip and tilt of a final attitude, quaternion kinematics,
//! and the SO(3) maps the free-form optimiser linearises.

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

pub fn to_na(m: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j])
}

pub fn from_na(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]))
}

/// Flip (signed rotation about the initial spine, wrapped to `(-pi, pi]`) and
/// tilt (angle between final and initial spine) of an attitude, both in radians.
/// A run reports the flip unwrapped along its trajectory: see [`FlipTracker`].
///
/// Swing-twist decomposition `R = swing * Rz(flip)`; the twist angle of a unit
/// quaternion about z is `2 atan2(q_z, q_w)`.
pub fn flip_and_tilt(q: &UnitQuaternion<f64>) -> (f64, f64) {
    let flip = wrap(2.0 * q.k.atan2(q.w));
    let spine = q * Vector3::z();
    let tilt = spine.z.clamp(-1.0, 1.0).acos();
    (flip, tilt)
}

/// The one flip convention of catflip: the rotation about the initial spine,
/// positive counter-clockwise about A's initial `z` (right-hand rule), unwrapped
/// along the run so that a turn just past `-pi` reads `-180.x` deg, never `+179.x`.
///
/// Feed it every recorded attitude in time order (steps well under half a turn).
#[derive(Debug, Clone, Copy, Default)]
pub struct FlipTracker {
    last: f64,
    acc: f64,
}

impl FlipTracker {
    /// Adds the next attitude; returns the unwrapped flip and the tilt, rad.
    pub fn push(&mut self, q: &UnitQuaternion<f64>) -> (f64, f64) {
        let (f, tilt) = flip_and_tilt(q);
        self.acc += wrap(f - self.last);
        self.last = f;
        (self.acc, tilt)
    }

    /// The unwrapped flip so far, rad.
    pub fn flip(&self) -> f64 {
        self.acc
    }
}

/// Wraps an angle to `(-pi, pi]`.
pub fn wrap(a: f64) -> f64 {
    let mut x = a % (2.0 * std::f64::consts::PI);
    if x <= -std::f64::consts::PI {
        x += 2.0 * std::f64::consts::PI;
    } else if x > std::f64::consts::PI {
        x -= 2.0 * std::f64::consts::PI;
    }
    x
}

/// Distance of a flip from pi in either sense: `pi - |flip|`, radians.
pub fn flip_error(flip: f64) -> f64 {
    std::f64::consts::PI - flip.abs()
}

/// Quaternion stored as `[w, x, y, z]` in integrator states.
pub fn quat_from(y: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(y[0], y[1], y[2], y[3]))
}

/// `d/dt q = 1/2 q (0, w)` for a body-frame rate `w`.
pub fn quat_rate(y: &[f64], w: [f64; 3]) -> [f64; 4] {
    let (qw, qx, qy, qz) = (y[0], y[1], y[2], y[3]);
    [
        0.5 * (-qx * w[0] - qy * w[1] - qz * w[2]),
        0.5 * (qw * w[0] + qy * w[2] - qz * w[1]),
        0.5 * (qw * w[1] + qz * w[0] - qx * w[2]),
        0.5 * (qw * w[2] + qx * w[1] - qy * w[0]),
    ]
}

/// Renormalises the quaternion in `y[..4]`.
pub fn normalize_quat(y: &mut [f64]) {
    let n = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3]).sqrt();
    for x in y.iter_mut().take(4) {
        *x /= n;
    }
}

pub fn hat(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

pub fn exp(v: &Vector3<f64>) -> Matrix3<f64> {
    *Rotation3::new(*v).matrix()
}

/// Rotation vector of `r`: the angle from atan2 of the sine and cosine
/// parts (accurate near the identity); near a half turn, where the sine part
/// vanishes, the axis comes from the symmetric part `(r + r')/2 - c I =
/// (1 - c) a a'` and only its sign from the sine part. (nalgebra's
/// `scaled_axis` returns zero at exactly pi: the unmoved cat measured as a
/// perfect flip, and an SCP that "converged" on it without moving.)
pub fn log(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let (s, c) = (v.norm(), 0.5 * (r.trace() - 1.0));
    let theta = s.atan2(c);
    if c < -0.9 {
        let b = 0.5 * (r + r.transpose()) - c * Matrix3::identity();
        let k = (0..3)
            .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
            .expect("three columns");
        let mut a: Vector3<f64> = b.column(k) / (b[(k, k)] * (1.0 - c)).sqrt();
        if a.dot(&v) < 0.0 {
            a = -a;
        }
        return a * theta;
    }
    if s < 1e-300 {
        return v;
    }
    v * (theta / s)
}

/// Right Jacobian of SO(3): `exp(v + dv) = exp(v) exp(J_r(v) dv)` to first order.
pub fn right_jacobian(v: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = v.norm_squared();
    let h = hat(v);
    let (b, c) = if t2 < 1e-8 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    Matrix3::identity() - b * h + c * h * h
}

/// Inverse of the right Jacobian.
pub fn right_jacobian_inv(v: &Vector3<f64>) -> Matrix3<f64> {
    right_jacobian(v)
        .try_inverse()
        .unwrap_or_else(Matrix3::identity)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn flip_and_tilt_of_known_rotations() {
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2.5);
        let (f, t) = flip_and_tilt(&q);
        assert!((f - 2.5).abs() < 1e-14 && t.abs() < 1e-7);
        let q = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.3);
        let (f, t) = flip_and_tilt(&q);
        assert!(f.abs() < 1e-14 && (t - 0.3).abs() < 1e-12);
    }

    #[test]
    fn tracked_flip_past_minus_pi_stays_near_minus_180() {
        let mut tr = FlipTracker::default();
        let n = 400;
        let end = -std::f64::consts::PI - 0.02;
        let mut last = 0.0;
        for k in 0..=n {
            let a = end * k as f64 / n as f64;
            // a small tilt on the way, as in a real run
            let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a)
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 1e-3 * (k as f64).sin());
            let (f, _) = tr.push(&q);
            assert!((f - a).abs() < 1e-2, "{f} {a}");
            last = f;
        }
        assert!(
            (last.to_degrees() + 181.146).abs() < 0.01,
            "{}",
            last.to_degrees()
        );
        // the wrapped value alone would read +178.85 deg
        let (w, _) = flip_and_tilt(&UnitQuaternion::from_axis_angle(&Vector3::z_axis(), end));
        assert!(w > 0.0);
        // and the same path the other way round mirrors it
        let mut tr = FlipTracker::default();
        for k in 0..=n {
            tr.push(&UnitQuaternion::from_axis_angle(
                &Vector3::z_axis(),
                -end * k as f64 / n as f64,
            ));
        }
        assert!((tr.flip() + last).abs() < 1e-9);
    }

    #[test]
    fn log_inverts_exp_up_to_and_at_a_half_turn() {
        let axis = Vector3::new(0.3, -0.8, 0.52).normalize();
        for angle in [0.0, 1e-9, 0.7, 2.0, 2.9, PI - 1e-3, PI - 1e-9] {
            let v = axis * angle;
            let back = log(&exp(&v));
            assert!((back - v).norm() < 1e-9, "{angle}: {back:?} vs {v:?}");
        }
        // exactly a half turn: the axis up to its sign, the angle pi
        for a in [Vector3::z(), axis] {
            let back = log(&exp(&(a * PI)));
            assert!((back.norm() - PI).abs() < 1e-12, "{back:?}");
            assert!(back.normalize().cross(&a).norm() < 1e-7, "{back:?}");
        }
        let half = Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0));
        assert!((log(&half).norm() - PI).abs() < 1e-15);
    }

    #[test]
    fn right_jacobian_matches_finite_difference() {
        let v = Vector3::new(0.4, -1.1, 0.7);
        let jr = right_jacobian(&v);
        let h = 1e-6;
        for k in 0..3 {
            let mut dv = Vector3::zeros();
            dv[k] = h;
            let d = log(&(exp(&v).transpose() * exp(&(v + dv)))) / h;
            for i in 0..3 {
                assert!((d[i] - jr[(i, k)]).abs() < 1e-5, "{d} {jr}");
            }
        }
    }
}
