//! Adaptive Dormand-Prince 5(4) integrator with a projection hook.
//!
//! The projection (unit-quaternion renormalisation) runs after every accepted
//! step, which keeps the attitude on SO(3) without affecting the order.

/// Tolerances and limits of one integration. Defaults are in the doc of each field.
#[derive(Debug, Clone, Copy)]
pub struct OdeSettings {
    /// Relative tolerance (default 1e-10).
    pub rtol: f64,
    /// Absolute tolerance (default 1e-12).
    pub atol: f64,
    /// Largest step, s (default: no limit).
    pub max_step: f64,
    /// Step budget per call (default 1_000_000).
    pub max_steps: usize,
}

impl Default for OdeSettings {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OdeStatus {
    Done,
    StepBudget,
    NonFinite,
    /// `observe` asked to stop (e.g. the state left the model's domain).
    Stopped,
}

const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
const CN: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// 5th-order weights minus 4th-order weights (error estimate).
const E: [f64; 7] = [
    35.0 / 384.0 - 5179.0 / 57600.0,
    0.0,
    500.0 / 1113.0 - 7571.0 / 16695.0,
    125.0 / 192.0 - 393.0 / 640.0,
    -2187.0 / 6784.0 + 92097.0 / 339200.0,
    11.0 / 84.0 - 187.0 / 2100.0,
    -1.0 / 40.0,
];

/// Integrates `y' = f(t, y)` from `t0` to `t1`, calling `observe(t, y)` after
/// the start and every accepted step (it returns false to stop), and
/// `project(y)` after every step.
pub fn integrate<const N: usize>(
    mut f: impl FnMut(f64, &[f64; N]) -> [f64; N],
    mut project: impl FnMut(&mut [f64; N]),
    t0: f64,
    y0: [f64; N],
    t1: f64,
    settings: &OdeSettings,
    mut observe: impl FnMut(f64, &[f64; N]) -> bool,
) -> ([f64; N], OdeStatus) {
    let mut t = t0;
    let mut y = y0;
    if !observe(t, &y) {
        return (y, OdeStatus::Stopped);
    }
    if t1 <= t0 {
        return (y, OdeStatus::Done);
    }
    let span = t1 - t0;
    let mut h = (span * 1e-3).min(settings.max_step);
    let mut k = [[0.0; N]; 7];
    k[0] = f(t, &y);
    for _ in 0..settings.max_steps {
        if t1 - t <= 1e-14 * span {
            return (y, OdeStatus::Done);
        }
        let last = t + h >= t1;
        if last {
            h = t1 - t;
        }
        let mut yt = [0.0; N];
        for s in 1..7 {
            for i in 0..N {
                let mut acc = y[i];
                for (j, kj) in k.iter().enumerate().take(s) {
                    acc += h * A[s - 1][j] * kj[i];
                }
                yt[i] = acc;
            }
            k[s] = f(t + CN[s] * h, &yt);
        }
        // yt is the 5th-order solution (FSAL: k[6] = f(t+h, yt))
        let mut err = 0.0f64;
        for i in 0..N {
            let mut e = 0.0;
            for (s, ks) in k.iter().enumerate() {
                e += E[s] * ks[i];
            }
            let sc = settings.atol + settings.rtol * y[i].abs().max(yt[i].abs());
            err = err.max((h * e / sc).abs());
        }
        if !err.is_finite() {
            return (y, OdeStatus::NonFinite);
        }
        if err <= 1.0 {
            t = if last { t1 } else { t + h };
            y = yt;
            project(&mut y);
            k[0] = if y == yt { k[6] } else { f(t, &y) };
            if !observe(t, &y) {
                return (y, OdeStatus::Stopped);
            }
        }
        let fac = if err == 0.0 {
            5.0
        } else {
            (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
        };
        h = (h * fac).min(settings.max_step);
    }
    (y, OdeStatus::StepBudget)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_oscillator_to_tolerance() {
        let s = OdeSettings {
            rtol: 1e-11,
            atol: 1e-13,
            ..Default::default()
        };
        let (y, st) = integrate(
            |_, y: &[f64; 2]| [y[1], -y[0]],
            |_| {},
            0.0,
            [1.0, 0.0],
            10.0,
            &s,
            |_, _| true,
        );
        assert_eq!(st, OdeStatus::Done);
        assert!((y[0] - 10f64.cos()).abs() < 1e-9);
        assert!((y[1] + 10f64.sin()).abs() < 1e-9);
    }

    #[test]
    fn fifth_order_convergence_on_fixed_step() {
        // with a huge tolerance and max_step the method runs at fixed h: halving h
        // must shrink the error by about 2^5.
        let run = |h: f64| {
            let s = OdeSettings {
                rtol: 1e3,
                atol: 1e3,
                max_step: h,
                max_steps: 100_000,
            };
            let (y, _) = integrate(
                |t, y: &[f64; 1]| [y[0] * t.cos()],
                |_| {},
                0.0,
                [1.0],
                2.0,
                &s,
                |_, _| true,
            );
            (y[0] - 2f64.sin().exp()).abs()
        };
        let r = run(0.1) / run(0.05);
        assert!(r > 20.0 && r < 45.0, "ratio {r}");
    }
}
