//! Time-varying LQR along a design: the discretised dynamics linearised
//! over each control period, a backward Riccati recursion, one gain per
//! control step.
//!
//! The correction `u_k = -K_k x(s_k)` is held from `s_k = d + k p` to
//! `s_{k+1}` (`d` the delay and `p` the period, in simulator steps), on top
//! of the feed-forward; `x` is the error state of [`super::plant::X`] about
//! the nominal. The period's map is linearised by central differences of the
//! very RK4 steps the simulator takes (checked against a second-order
//! expansion in the tests).
//!
//! Cost: `sum_k x'Q_k x + u'R_k u + x_N' Q_f x_N` in units scaled by the
//! design (rad, the straight cat's momentum per turn over the fall, rad per
//! fall time, the design's peak torque); the attitude enters only through the
//! belly's direction (the heading is free), at touchdown with
//! `control.landing_weight`.

use super::plant::{NX, X, Y, error, perturb, rk4};
use super::reference::Reference;
use crate::config::ControlConfig;
use crate::model::momentum::straight_inertias;
use crate::model::motor::Motor;
use crate::model::so3::hat;
use nalgebra::{SMatrix, SVector, Vector3};

pub type A = SMatrix<f64, NX, NX>;
pub type B = SMatrix<f64, NX, 2>;
pub type Gain = SMatrix<f64, 2, NX>;

/// The gains along one design.
#[derive(Debug, Clone)]
pub struct Tvlqr {
    /// Control period and the delay the controller predicts over, in simulator steps.
    pub period_steps: usize,
    pub delay_steps: usize,
    /// Step at which correction `k` starts to act; it acts until the next
    /// one (the last until touchdown).
    pub starts: Vec<usize>,
    pub a: Vec<A>,
    pub b: Vec<B>,
    pub gains: Vec<Gain>,
    /// Cost-to-go `P_k` at `starts[k]`, and `P_N = Q_f` last.
    pub cost_to_go: Vec<A>,
    /// Running state cost of each period.
    pub q: Vec<A>,
    pub r: Vec<SMatrix<f64, 2, 2>>,
    /// Scale of each error component (rad, N m s, rad, rad/s) and of the torque, N m.
    pub scale: SVector<f64, NX>,
    pub torque_scale: f64,
    /// Largest correction, N m (in the motor norm).
    pub max_correction: f64,
}

/// Steps of `seconds` at step `h`, rounded.
pub fn steps_of(seconds: f64, h: f64) -> usize {
    (seconds / h).round() as usize
}

/// The map of the model over steps `[a, b)` from error `x` under a held
/// correction `u`, as an error at `b`.
pub fn period_map(r: &Reference, a: usize, b: usize, x: &X, u: [f64; 2]) -> X {
    let mut y = perturb(&r.nominal[a], x);
    for j in a..b {
        y = rk4(&r.cat, &y, r.h, |s, _| {
            let f = r.ff_at(j, s);
            [f[0] + u[0], f[1] + u[1]]
        });
    }
    error(&y, &r.nominal[b])
}

/// `(A, B)` of the period `[a, b)` by central differences, steps scaled to each component.
pub fn linearise(r: &Reference, a: usize, b: usize, scale: &SVector<f64, NX>, us: f64) -> (A, B) {
    let mut am = A::zeros();
    let mut bm = B::zeros();
    for i in 0..NX {
        let e = 1e-5 * scale[i];
        let mut x = X::zeros();
        x[i] = e;
        let d =
            (period_map(r, a, b, &x, [0.0; 2]) - period_map(r, a, b, &(-x), [0.0; 2])) / (2.0 * e);
        am.set_column(i, &d);
    }
    for i in 0..2 {
        let e = 1e-5 * us;
        let mut u = [0.0; 2];
        u[i] = e;
        let d = (period_map(r, a, b, &X::zeros(), u)
            - period_map(r, a, b, &X::zeros(), u.map(|v| -v)))
            / (2.0 * e);
        bm.set_column(i, &d);
    }
    (am, bm)
}

/// Rows that map an attitude error to the belly's move off its nominal
/// direction, across that direction (`(I - b b') (-R hat(e_x))`): the tilt,
/// the heading left free.
fn belly(nom: &super::plant::Y) -> SMatrix<f64, 3, 3> {
    let r = *super::plant::attitude(nom).to_rotation_matrix().matrix();
    let b = r.column(0).into_owned();
    (SMatrix::<f64, 3, 3>::identity() - b * b.transpose()) * (-r * hat(&Vector3::x()))
}

/// Places a 3x3 block at the attitude corner.
fn attitude_cost(c: &SMatrix<f64, 3, 3>, w: f64) -> A {
    let mut m = A::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(c.transpose() * c * w));
    m
}

impl Tvlqr {
    pub fn new(r: &Reference, cfg: &ControlConfig) -> Tvlqr {
        let period_steps = steps_of(cfg.period(), r.h).max(1);
        let delay_steps = steps_of(cfg.delay_ms * 1e-3, r.h);
        let starts: Vec<usize> = (0..)
            .map(|k| delay_steps + k * period_steps)
            .take_while(|&s| s < r.steps)
            .collect();
        let t = r.duration();
        let (_, i1) = straight_inertias(&r.cat);
        let scale = SVector::<f64, NX>::from_column_slice(&[
            1.0,
            1.0,
            1.0,
            i1 / t,
            i1 / t,
            i1 / t,
            1.0,
            1.0,
            1.0 / t,
            1.0 / t,
        ]);
        let torque_scale = if r.peak_torque > 0.0 {
            r.peak_torque
        } else {
            i1 / (t * t)
        };
        // shape and shape-rate weights in scaled units
        let shape_cost = |ws: f64, wr: f64| {
            let mut m = A::zeros();
            for i in 6..8 {
                m[(i, i)] = ws / scale[i].powi(2);
            }
            for i in 8..10 {
                m[(i, i)] = wr / scale[i].powi(2);
            }
            m
        };
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut q = Vec::new();
        let mut rr = Vec::new();
        for (k, &s) in starts.iter().enumerate() {
            let e = starts.get(k + 1).copied().unwrap_or(r.steps);
            let (am, bm) = linearise(r, s, e, &scale, torque_scale);
            a.push(am);
            b.push(bm);
            let dt = (e - s) as f64 * r.h / t;
            q.push(
                (shape_cost(cfg.shape_weight, cfg.rate_weight)
                    + attitude_cost(&belly(&r.nominal[s]), cfg.attitude_weight))
                    * dt,
            );
            rr.push(
                SMatrix::<f64, 2, 2>::identity() * (dt * cfg.torque_weight / torque_scale.powi(2)),
            );
        }
        let qf = attitude_cost(&belly(&r.nominal[r.steps]), cfg.landing_weight)
            + shape_cost(cfg.final_shape_weight, cfg.final_shape_weight);
        let n = starts.len();
        let mut p = vec![A::zeros(); n + 1];
        p[n] = qf;
        let mut gains = vec![Gain::zeros(); n];
        for k in (0..n).rev() {
            let (am, bm, pn) = (&a[k], &b[k], &p[k + 1]);
            let s = rr[k] + bm.transpose() * pn * bm;
            let kk = s
                .try_inverse()
                .expect("R is positive definite, so R + B'PB is invertible")
                * bm.transpose()
                * pn
                * am;
            let acl = am - bm * kk;
            // Joseph form: symmetric and positive semi-definite by construction
            let pk = q[k] + kk.transpose() * rr[k] * kk + acl.transpose() * pn * acl;
            p[k] = 0.5 * (pk + pk.transpose());
            gains[k] = kk;
        }
        Tvlqr {
            period_steps,
            delay_steps,
            starts,
            a,
            b,
            gains,
            cost_to_go: p,
            q,
            r: rr,
            scale,
            torque_scale,
            max_correction: cfg.max_correction * torque_scale,
        }
    }

    /// Index of the correction acting at simulator step `j`, if any.
    pub fn interval_at(&self, j: usize) -> Option<usize> {
        (j >= self.delay_steps)
            .then(|| ((j - self.delay_steps) / self.period_steps).min(self.starts.len() - 1))
    }

    /// The closed-loop transition of period `k`, `A_k - B_k K_k`.
    pub fn closed_loop(&self, k: usize) -> A {
        self.a[k] - self.b[k] * self.gains[k]
    }
}

/// The model's state at step `to` from the measurement `m` at step `from`,
/// under the feed-forward of `r` and the corrections `issued` acting as the
/// TVLQR `tv` sends them (in the motor envelope at the predicted speed).
pub fn predict(
    r: &Reference,
    tv: &Tvlqr,
    motor: &Motor,
    issued: &[[f64; 2]],
    from: usize,
    to: usize,
    m: &Y,
) -> Y {
    let mut yp = *m;
    for i in from..to {
        let u = tv
            .interval_at(i)
            .and_then(|c| issued.get(c))
            .copied()
            .unwrap_or([0.0; 2]);
        yp = rk4(&r.cat, &yp, r.h, |st, ys| {
            let ff = r.ff_at(i, st);
            motor.clip([ff[0] + u[0], ff[1] + u[1]], [ys[6], ys[7]])
        });
    }
    yp
}

/// The TVLQR's correction `k` from the measurement `m` taken `delay` steps
/// before it acts: the model predicts the state over the delay under the
/// corrections already sent, the gain acts on the predicted error, and the
/// sum with the feed-forward is held inside the motor envelope at the
/// predicted joint speed.
pub fn tvlqr_command(
    r: &Reference,
    tv: &Tvlqr,
    motor: &Motor,
    issued: &[[f64; 2]],
    k: usize,
    m: &Y,
) -> [f64; 2] {
    let s = tv.starts[k];
    let yp = predict(r, tv, motor, issued, s - tv.delay_steps, s, m);
    let x = error(&yp, &r.nominal[s]);
    let mut u = -(tv.gains[k] * x);
    let size = motor.norm.of([u[0], u[1]]);
    if size > tv.max_correction {
        u *= tv.max_correction / size;
    }
    let ff = r.ff_at(s, 0);
    let total = motor.clip([ff[0] + u[0], ff[1] + u[1]], [yp[6], yp[7]]);
    [total[0] - ff[0], total[1] - ff[1]]
}
