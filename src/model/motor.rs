//! The joint's motors: a torque limit, the linear DC-motor torque-speed line
//! and a hard speed limit, any subset of them.
//!
//! A voltage-limited DC motor with stall torque `T` and no-load speed `w0`
//! gives `-T - k w <= tau <= T - k w` at speed `w`, `k = T / w0`, i.e.
//! `|tau + k w| <= T`: when motoring the torque available falls linearly to 0
//! at `w0`; when braking the back-EMF helps. The norm says how this applies to
//! the joint's two torque components:
//! - `per-motor` (two motors, one per axis; the universal joint's default):
//!   `|tau_i + k qd_i| <= T` and `|qd_i| <= w_max` for each motor `i`;
//! - `euclidean` (one actuator that pushes in any direction; the no-twist
//!   joint's default): `|tau + k qd|_2 <= T` and `|qd|_2 <= w_max`, the disc of
//!   radius `T` about `-k qd` (the same line in every direction of the bend).
//!
//! Both are convex in `(tau, qd)` jointly.

use crate::model::TorqueNorm;
use serde::Serialize;

/// Motor limits of a joint; `None` means unlimited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Motor {
    /// Stall torque `T`, N m.
    pub max_torque: Option<f64>,
    /// No-load speed `w0`, rad/s (needs `max_torque`).
    pub no_load_speed: Option<f64>,
    /// Hard joint speed limit, rad/s.
    pub max_speed: Option<f64>,
    pub norm: TorqueNorm,
}

impl Motor {
    /// No limits at all.
    pub fn unlimited(norm: TorqueNorm) -> Motor {
        Motor {
            max_torque: None,
            no_load_speed: None,
            max_speed: None,
            norm,
        }
    }

    /// Whether any limit is set.
    pub fn is_limited(&self) -> bool {
        self.max_torque.is_some() || self.max_speed.is_some()
    }

    /// Slope `k = T / w0` of the torque-speed line, N m s (0 without one).
    pub fn slope(&self) -> f64 {
        match (self.max_torque, self.no_load_speed) {
            (Some(t), Some(w0)) => t / w0,
            _ => 0.0,
        }
    }

    /// Joint speed in the motor norm, rad/s.
    pub fn speed(&self, qd: [f64; 2]) -> f64 {
        self.norm.of(qd)
    }

    /// The torque the motor actually gives when `tau` is asked at speed `qd`:
    /// `tau` moved onto the envelope (per motor: clamped; Euclidean: projected
    /// onto the disc) when outside it.
    pub fn clip(&self, tau: [f64; 2], qd: [f64; 2]) -> [f64; 2] {
        let Some(t) = self.max_torque else {
            return tau;
        };
        let k = self.slope();
        // (without a torque-speed line the speed does not move the envelope,
        // even one that is not finite)
        let c = if k == 0.0 {
            [0.0; 2]
        } else {
            [-k * qd[0], -k * qd[1]]
        };
        match self.norm {
            // (a speed that is not a number has no envelope: NaN for that
            // motor, not a panic; the other keeps its own)
            TorqueNorm::PerMotor => [0, 1].map(|i| {
                if c[i].is_nan() {
                    f64::NAN
                } else {
                    tau[i].clamp(c[i] - t, c[i] + t)
                }
            }),
            TorqueNorm::Euclidean => {
                let e = [tau[0] - c[0], tau[1] - c[1]];
                let n = e[0].hypot(e[1]);
                if n <= t {
                    tau
                } else {
                    [c[0] + e[0] * t / n, c[1] + e[1] * t / n]
                }
            }
        }
    }

    /// Smallest relative margin of `(tau, qd)` over the limits that are set:
    /// `1 - |tau + k qd| / T` and `1 - speed / w_max` (per motor: the worse
    /// motor). 1 means unused, 0 on the envelope, negative outside it
    /// (violated); `None` when nothing is limited.
    pub fn margin(&self, tau: [f64; 2], qd: [f64; 2]) -> Option<f64> {
        let torque = self.line_margin(tau, qd);
        let speed = self.max_speed.map(|w| 1.0 - self.speed(qd) / w);
        match (torque, speed) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The torque part of [`Motor::margin`]: `1 - |tau + k qd| / T` (the
    /// stall torque alone without a torque-speed line), `None` without a
    /// torque limit. A verdict names the line from it even where a speed
    /// limit is broken worse.
    pub fn line_margin(&self, tau: [f64; 2], qd: [f64; 2]) -> Option<f64> {
        let k = self.slope();
        self.max_torque
            .map(|t| 1.0 - self.norm.of([tau[0] + k * qd[0], tau[1] + k * qd[1]]) / t)
    }
}

/// How a torque schedule uses the motors: largest speed and smallest margin
/// over its rows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotorUse {
    /// Largest joint speed, rad/s (in the motor norm).
    pub max_speed_rad_s: f64,
    /// Smallest [`Motor::margin`] over the rows (`None` without limits).
    pub min_margin: Option<f64>,
    /// Smallest [`Motor::line_margin`] over the rows (`None` without a
    /// torque limit).
    pub min_line_margin: Option<f64>,
}

impl Motor {
    /// Largest speed and smallest margin over `(tau, qd)` samples.
    pub fn usage(&self, rows: impl IntoIterator<Item = ([f64; 2], [f64; 2])>) -> MotorUse {
        let mut u = MotorUse {
            max_speed_rad_s: 0.0,
            min_margin: None,
            min_line_margin: None,
        };
        let least = |x: Option<f64>, m: f64| Some(x.map_or(m, |x: f64| x.min(m)));
        for (tau, qd) in rows {
            u.max_speed_rad_s = u.max_speed_rad_s.max(self.speed(qd));
            if let Some(m) = self.margin(tau, qd) {
                u.min_margin = least(u.min_margin, m);
            }
            if let Some(m) = self.line_margin(tau, qd) {
                u.min_line_margin = least(u.min_line_margin, m);
            }
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn servo(norm: TorqueNorm) -> Motor {
        Motor {
            max_torque: Some(1.4),
            no_load_speed: Some(6.0),
            max_speed: Some(5.0),
            norm,
        }
    }

    /// A speed that is not a number has no envelope: the torque given is
    /// NaN, never a panic (a diverged state fed to a controller reached
    /// `f64::clamp`'s); per motor only that motor's (the other's limits are
    /// its own), under the Euclidean norm both (one disc holds them).
    #[test]
    fn a_speed_that_is_not_a_number_gives_nan_not_a_panic() {
        let t = servo(TorqueNorm::PerMotor).clip([0.5, 2.0], [f64::NAN, 0.0]);
        assert!(t[0].is_nan(), "{t:?}");
        assert_eq!(
            t[1],
            servo(TorqueNorm::PerMotor).clip([0.5, 2.0], [0.0, 0.0])[1]
        );
        for norm in [TorqueNorm::PerMotor, TorqueNorm::Euclidean] {
            let t = servo(norm).clip([0.5, 0.5], [f64::NAN, 0.0]);
            assert!(t[0].is_nan(), "{norm:?}: {t:?}");
            if norm == TorqueNorm::Euclidean {
                assert!(t[1].is_nan(), "{t:?}");
            }
            // a stall torque alone: the speed does not matter, whatever it is
            let stall = Motor {
                no_load_speed: None,
                ..servo(norm)
            };
            for w in [f64::NAN, f64::INFINITY] {
                assert_eq!(
                    stall.clip([0.5, 2.0], [w, 0.0]),
                    stall.clip([0.5, 2.0], [0.0, 0.0])
                );
            }
        }
    }

    #[test]
    fn per_motor_envelope_is_the_dc_motor_line() {
        let m = servo(TorqueNorm::PerMotor);
        let k = 1.4 / 6.0;
        // motoring at 3 rad/s: at most T - 3k; braking: down to -T - 3k
        let c = m.clip([10.0, -10.0], [3.0, 3.0]);
        assert!((c[0] - (1.4 - 3.0 * k)).abs() < 1e-15);
        assert!((c[1] - (-1.4 - 3.0 * k)).abs() < 1e-15);
        // on the line the margin is 0; at rest with no torque it is 1 (speed unused too)
        assert!(m.margin(c, [3.0, 3.0]).unwrap().abs() < 1e-12);
        assert!((m.margin([0.0, 0.0], [0.0, 0.0]).unwrap() - 1.0).abs() < 1e-15);
        // at the no-load speed no motoring torque is left
        assert!(m.clip([1.0, 0.0], [6.0, 0.0])[0].abs() < 1e-15);
        // a speed past the limit is a negative margin, the line's still positive
        assert!(m.margin([0.0, 0.0], [5.5, 0.0]).unwrap() < 0.0);
        assert!(m.line_margin([0.0, 0.0], [5.5, 0.0]).unwrap() > 0.0);
        // over rows: the line's smallest margin apart from the speed's
        let u = m.usage([([0.0, 0.0], [5.5, 0.0]), ([1.5, 0.0], [0.0, 0.0])]);
        assert!((u.min_margin.unwrap() - (1.0 - 5.5 / 5.0)).abs() < 1e-15);
        assert!((u.min_line_margin.unwrap() - (1.0 - 1.5 / 1.4)).abs() < 1e-15);
    }

    #[test]
    fn euclidean_envelope_is_a_disc_about_minus_k_qd() {
        let m = servo(TorqueNorm::Euclidean);
        let k = 1.4 / 6.0;
        let qd = [1.0, 2.0];
        let c = m.clip([5.0, -3.0], qd);
        let e = [c[0] + k * qd[0], c[1] + k * qd[1]];
        assert!((e[0].hypot(e[1]) - 1.4).abs() < 1e-12);
        // inside stays put
        assert_eq!(m.clip([0.1, 0.1], qd), [0.1, 0.1]);
        assert!(m.margin(c, qd).unwrap().abs() < 1e-12);
    }

    /// Whether `(tau, qd)` is inside `m`'s envelope.
    fn inside(m: &Motor, tau: [f64; 2], qd: [f64; 2]) -> bool {
        m.margin(tau, qd).is_none_or(|x| x >= 0.0)
    }

    /// docs/model.md, section 5: a higher voltage (`T` and `w0` together,
    /// the same `k`) or a higher speed limit contains the weaker envelope
    /// everywhere; a larger `T` at the same `w0` only below `w0`, above
    /// which it brakes harder; per motor and as the disc.
    #[test]
    fn a_stronger_motor_contains_the_weaker_envelope_unless_it_brakes_harder_past_w0() {
        for norm in [TorqueNorm::PerMotor, TorqueNorm::Euclidean] {
            let weak = servo(norm);
            let with = |t: f64, w0: f64, w: f64| Motor {
                max_torque: Some(t),
                no_load_speed: Some(w0),
                max_speed: Some(w),
                ..weak
            };
            let voltage = with(2.8, 12.0, 5.0);
            let faster = with(1.4, 6.0, 6.5);
            let stall = with(2.8, 6.0, 10.0);
            let weak_unbounded = with(1.4, 6.0, 10.0);
            let mut past_w0 = 0;
            for i in -40..=40 {
                for j in -40..=40 {
                    let (tau, qd) = ([0.1 * i as f64, 0.3], [0.25 * j as f64, 1.0]);
                    if inside(&weak, tau, qd) {
                        assert!(inside(&voltage, tau, qd), "{norm:?} {tau:?} {qd:?}");
                        assert!(inside(&faster, tau, qd), "{norm:?} {tau:?} {qd:?}");
                    }
                    if inside(&weak_unbounded, tau, qd) && !inside(&stall, tau, qd) {
                        assert!(norm.of(qd) > 6.0, "{norm:?} {tau:?} {qd:?}");
                        past_w0 += 1;
                    }
                }
            }
            assert!(past_w0 > 0, "{norm:?}");
        }
        // at 7 rad/s the weak motor gives at most -0.23 N m (braking); the
        // larger stall torque at least 0.47 N m of braking
        let (weak, stall) = (
            Motor {
                max_speed: None,
                ..servo(TorqueNorm::PerMotor)
            },
            Motor {
                max_torque: Some(2.8),
                max_speed: None,
                ..servo(TorqueNorm::PerMotor)
            },
        );
        assert!(inside(&weak, [-0.3, 0.0], [7.0, 0.0]));
        assert!(!inside(&stall, [-0.3, 0.0], [7.0, 0.0]));
    }

    #[test]
    fn unlimited_motor_changes_nothing() {
        let m = Motor::unlimited(TorqueNorm::PerMotor);
        assert_eq!(m.clip([3.0, -4.0], [9.0, 9.0]), [3.0, -4.0]);
        assert_eq!(m.margin([3.0, -4.0], [9.0, 9.0]), None);
    }
}
