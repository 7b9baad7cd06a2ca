//! The free-form design from any start (MODEL.md section 6, docs/model.md
//! section 8): the attitude map with angular momentum, the momentum's part
//! of the joint torque, and the landing residual with the heading free.
//!
//! In the normalised time `s` of a phase of duration `T_p` (problem units)
//! the body rate is `w^ = J(q)^-1 mu - A(q) q^` with `mu = T_p R_A' l`, `l`
//! the world momentum times the time unit: the dynamics keep the form of
//! physical time with `(q^, mu)` for `(q_dot, lambda)` (the momentum torque
//! is homogeneous of degree two in them). Unlike the zero-momentum map the
//! rate depends on the attitude, so the unit quaternion is integrated with
//! classical Runge-Kutta (four stages, the interpolant exact at each) and its
//! derivative is the exact derivative of that discrete map, propagated
//! forward. The torque rows take the momentum at their check point from the
//! map; their linearisation holds the attitude there fixed (the momentum's
//! dependence on the earlier path would couple every row to every earlier
//! variable and make the subproblem dense), so the SCP's model of them is
//! exact in the local shape and duration and lagged in the attitude.

use crate::design::collocation::Transcription;
use crate::design::spec::DesignSpec;
use crate::model::Cat;
use crate::model::momentum::{body_rate_with, momentum_torque, straight_inertias};
use crate::model::small::Real;
use nalgebra::{Const, U1};
use num_dual::DualSVec64;

/// A release other than upside down at rest, in the problem's units.
#[derive(Debug, Clone, Copy)]
pub struct Release {
    /// `R0` as a quaternion `[w, x, y, z]`.
    pub attitude: [f64; 4],
    /// World momentum times the time unit, `l = T L` (kg m^2).
    pub momentum: [f64; 3],
    /// The straight cat's rigid turn before touchdown (`fall.margin`), in
    /// time units.
    pub tail: f64,
    /// Axial and transverse inertia of the straight cat (F8).
    pub inertias: (f64, f64),
}

/// Runge-Kutta sub-steps per collocation interval: the interval midpoint,
/// where the torque is checked too, is a sub-step boundary.
const SUB: usize = 2;

/// The attitude along the design: the momentum `mu` at each check point
/// (nodes and, with `midpoints`, interval midpoints, phases in order) and the
/// final quaternion with, if asked, its Jacobian (4 rows by `dim` columns).
pub struct Path {
    pub mu: Vec<[f64; 3]>,
    /// The quaternion at every sub-step's start (phases, intervals, sub-steps in order).
    pub knots: Vec<[f64; 4]>,
    pub end: [f64; 4],
    pub end_jac: Vec<[f64; 4]>,
}

/// A Runge-Kutta sub-step's inputs: the quaternion (4), then its interval's
/// eight node values (component 0 then 1) and the phase duration.
const INPUTS: usize = 13;

/// One sub-step's derivative: `dx[r][dir]`, the next quaternion's component
/// `r` in input `dir` ([`INPUTS`]), and the columns of `z` of the inputs
/// after the quaternion.
struct StepDerivative {
    dx: [[f64; INPUTS]; 4],
    columns: [usize; INPUTS - 4],
}

fn dual<const N: usize>(x: f64, i: usize) -> DualSVec64<N> {
    DualSVec64::<N>::from_re(x).derivative(i)
}

fn grad<const N: usize>(x: &DualSVec64<N>) -> [f64; N] {
    let e = x.eps.unwrap_generic(Const::<N>, U1);
    std::array::from_fn(|i| e[i])
}

/// `R(x)' v` for a quaternion `x = (s, u)`: `v - 2 s (u x v) + 2 u x (u x v)`.
fn rotate_back<T: Real>(x: [T; 4], v: [T; 3]) -> [T; 3] {
    let u = [x[1], x[2], x[3]];
    let uv = cross(u, v);
    let uuv = cross(u, uv);
    let two = T::from(2.0);
    std::array::from_fn(|i| v[i] - two * x[0] * uv[i] + two * uuv[i])
}

/// `R(x) v`.
fn rotate<T: Real>(x: [T; 4], v: [T; 3]) -> [T; 3] {
    rotate_back([x[0], -x[1], -x[2], -x[3]], v)
}

/// The rotation vector's `(y, z)` part from world `-x` to the unit vector
/// `b`: `theta (b_y, b_z) / s` with `s = |(b_y, b_z)| = sin theta`.
fn tilt<T: Real>(b: [T; 3]) -> [T; 2] {
    let s2 = b[1] * b[1] + b[2] * b[2];
    let f = if s2.re() < 1e-8 && b[0].re() < 0.0 {
        // asin(s) / s = 1 + s^2 / 6 + 3 s^4 / 40 + ...: smooth at belly-down
        T::one() + s2 / 6.0
    } else if s2.re() == 0.0 {
        // belly-up exactly: any horizontal axis
        return [T::from(std::f64::consts::PI), T::zero()];
    } else {
        let s = s2.sqrt();
        s.atan2(-b[0]) / s
    };
    [b[1] * f, b[2] * f]
}

fn cross<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl Release {
    /// `mu = T_p R(x)' l`.
    fn mu<T: Real>(&self, x: [T; 4], duration: T) -> [T; 3] {
        rotate_back(x, self.momentum.map(T::from)).map(|c| c * duration)
    }

    /// `dx/ds = x (0, w^) / 2`.
    fn rate<T: Real>(&self, cat: &Cat, x: [T; 4], q: [T; 2], v: [T; 2], duration: T) -> [T; 4] {
        let w = body_rate_with(cat, q, v, self.mu(x, duration));
        let u = [x[1], x[2], x[3]];
        let c = cross(u, w);
        let half = T::from(0.5);
        [
            -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) * half,
            (x[0] * w[0] + c[0]) * half,
            (x[0] * w[1] + c[1]) * half,
            (x[0] * w[2] + c[2]) * half,
        ]
    }

    /// The attitude map over the three phases of `z` (problem units), with
    /// the momentum at the check points (`midpoints`: at interval midpoints
    /// too) and, with `want_jac`, the final quaternion's Jacobian.
    pub fn path(
        &self,
        cat: &Cat,
        tr: &Transcription,
        z: &[f64],
        midpoints: bool,
        want_jac: bool,
    ) -> Path {
        let n = tr.nodes;
        let mut x = self.attitude;
        let hs = tr.h() / SUB as f64;
        let mut mu = Vec::new();
        let mut knots = Vec::new();
        // with `want_jac`, each sub-step's derivative in its own inputs
        // (reverse mode: the final quaternion's Jacobian is accumulated
        // backwards from these, a 4x4 product per step instead of a
        // forward sweep over every column)
        let mut steps: Vec<StepDerivative> = Vec::new();
        for p in 0..3 {
            let dur = z[tr.duration(p)];
            let dcol = tr.duration(p);
            for k in 0..n - 1 {
                let d = tr.interval(z, p, k);
                let cols = [0, 1].map(|c| tr.interval_columns(p, k, c));
                for j in 0..SUB {
                    if j == 0 || midpoints {
                        mu.push(self.mu(x, dur));
                    }
                    knots.push(x);
                    let c0 = j as f64 / SUB as f64;
                    let pts = [0.0, 0.5, 0.5, 1.0].map(|f| d.at(c0 + f / SUB as f64));
                    let a = [0.0, 0.5, 0.5, 1.0];
                    let mut ks = [[0.0; 4]; 4];
                    // dK_stage / d(x, local inputs), 4 rows by INPUTS
                    let mut dk = [[[0.0; INPUTS]; 4]; 4];
                    for stage in 0..4 {
                        let it = &pts[stage];
                        let xs: [f64; 4] = std::array::from_fn(|i| {
                            x[i] + if stage > 0 {
                                a[stage] * hs * ks[stage - 1][i]
                            } else {
                                0.0
                            }
                        });
                        if !want_jac {
                            ks[stage] = self.rate(cat, xs, it.q, it.v, dur);
                            continue;
                        }
                        let f = self.rate(
                            cat,
                            std::array::from_fn(|i| dual::<9>(xs[i], i)),
                            [dual(it.q[0], 4), dual(it.q[1], 5)],
                            [dual(it.v[0], 6), dual(it.v[1], 7)],
                            dual(dur, 8),
                        );
                        ks[stage] = f.map(|c| c.re);
                        let g: [[f64; 9]; 4] = f.map(|c| grad(&c));
                        // the stage state's derivative: identity in x plus a h dK_{stage-1}
                        let mut dxs = [[0.0; INPUTS]; 4];
                        for i in 0..4 {
                            dxs[i][i] = 1.0;
                            if stage > 0 {
                                for dir in 0..INPUTS {
                                    dxs[i][dir] += a[stage] * hs * dk[stage - 1][i][dir];
                                }
                            }
                        }
                        for r in 0..4 {
                            let row = &mut dk[stage][r];
                            for (dir, o) in row.iter_mut().enumerate() {
                                *o = (0..4).map(|i| g[r][i] * dxs[i][dir]).sum();
                            }
                            for comp in 0..2 {
                                for idx in 0..4 {
                                    row[4 + 4 * comp + idx] +=
                                        g[r][4 + comp] * it.dq[idx] + g[r][6 + comp] * it.dv[idx];
                                }
                            }
                            row[12] += g[r][8];
                        }
                    }
                    for i in 0..4 {
                        x[i] += hs / 6.0 * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i]);
                    }
                    if want_jac {
                        let mut dx = [[0.0; INPUTS]; 4];
                        for i in 0..4 {
                            dx[i][i] = 1.0;
                            for dir in 0..INPUTS {
                                dx[i][dir] += hs / 6.0
                                    * (dk[0][i][dir]
                                        + 2.0 * dk[1][i][dir]
                                        + 2.0 * dk[2][i][dir]
                                        + dk[3][i][dir]);
                            }
                        }
                        let mut columns = [dcol; INPUTS - 4];
                        columns[..4].copy_from_slice(&cols[0]);
                        columns[4..8].copy_from_slice(&cols[1]);
                        steps.push(StepDerivative { dx, columns });
                    }
                }
            }
            mu.push(self.mu(x, dur));
        }
        let mut end_jac = Vec::new();
        if want_jac {
            end_jac = vec![[0.0; 4]; tr.dim()];
            // psi = d end / d (the state after the step), from the end back
            let mut psi = [[0.0; 4]; 4];
            for (i, row) in psi.iter_mut().enumerate() {
                row[i] = 1.0;
            }
            for st in steps.iter().rev() {
                for (c, &col) in st.columns.iter().enumerate() {
                    for r in 0..4 {
                        end_jac[col][r] += (0..4).map(|i| psi[r][i] * st.dx[i][4 + c]).sum::<f64>();
                    }
                }
                let before = psi;
                for r in 0..4 {
                    for c in 0..4 {
                        psi[r][c] = (0..4).map(|i| before[r][i] * st.dx[i][c]).sum();
                    }
                }
            }
        }
        Path {
            mu,
            knots,
            end: x,
            end_jac,
        }
    }

    /// The belly's direction at touchdown (world), from the manoeuvre's
    /// final quaternion (normalised here): the straight cat turns rigidly
    /// for the tail (F8: `exp(t hat(L) / I_1) R exp(t alpha hat(e_z))`).
    fn belly<T: Real>(&self, x: [T; 4]) -> [T; 3] {
        let norm = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]).sqrt();
        let x = x.map(|c| c / norm);
        let l = self.momentum;
        let ln = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        if ln == 0.0 || self.tail == 0.0 {
            return rotate(x, [T::one(), T::zero(), T::zero()]);
        }
        let (i3, i1) = self.inertias;
        let lam = rotate_back(x, l.map(T::from));
        let phi = lam[2] * T::from((i1 - i3) / (i3 * i1) * self.tail);
        let b = rotate(x, [phi.cos(), phi.sin(), T::zero()]);
        // about l / |l| by |l| tail / I_1 (Rodrigues)
        let th = ln * self.tail / i1;
        let nv = l.map(|c| c / ln);
        let nt = nv.map(T::from);
        let nb = cross(nt, b);
        let ndb = nt[0] * b[0] + nt[1] * b[1] + nt[2] * b[2];
        let (c, s) = (T::from(th.cos()), T::from(th.sin()));
        std::array::from_fn(|i| b[i] * c + nb[i] * s + nt[i] * ndb * (T::one() - c))
    }

    /// Landing residual of the belly's direction `b` (zero when it points
    /// straight down, world `-x`, whatever the heading) and its gradient in
    /// the final quaternion: the tilt `theta (b_y, b_z) / |(b_y, b_z)|`, the
    /// rotation vector from straight down to `b`, whose length is the landing
    /// error. The horizontal components `(b_y, b_z)` alone vanish belly-up
    /// too, where the SCP could end; the tilt is `pi` long there.
    pub fn landing(&self, end: [f64; 4]) -> ([f64; 2], [[f64; 4]; 2]) {
        let r = tilt(self.belly(std::array::from_fn(|i| dual::<4>(end[i], i))));
        ([r[0].re, r[1].re], [grad(&r[0]), grad(&r[1])])
    }

    /// Landing error, rad: the belly's angle from straight down.
    pub fn landing_error(&self, end: [f64; 4]) -> f64 {
        let b = self.belly(end);
        b[1].hypot(b[2]).atan2(-b[0])
    }

    /// The momentum part of the normalised torque `g(q, q^, mu)` at a check
    /// point and its gradient in `(q, q^)` (the momentum held fixed).
    pub fn torque(cat: &Cat, q: [f64; 2], v: [f64; 2], mu: [f64; 3]) -> ([f64; 2], [[f64; 4]; 2]) {
        let g = momentum_torque(
            cat,
            [dual::<4>(q[0], 0), dual(q[1], 1)],
            [dual(v[0], 2), dual(v[1], 3)],
            mu.map(DualSVec64::<4>::from_re),
        );
        (g.map(|c| c.re), g.map(|c| grad(&c)))
    }

    /// The momentum part `g(q, q^, mu)` alone, in plain `f64` (a value
    /// without its gradient: a fifth of [`Release::torque`]'s work).
    pub fn torque_value(cat: &Cat, q: [f64; 2], v: [f64; 2], mu: [f64; 3]) -> [f64; 2] {
        momentum_torque(cat, q, v, mu)
    }

    /// `d g / d mu` at a check point (3 columns per torque component).
    pub fn torque_dmu(cat: &Cat, q: [f64; 2], v: [f64; 2], mu: [f64; 3]) -> [[f64; 3]; 2] {
        let g = momentum_torque(
            cat,
            q.map(DualSVec64::<3>::from_re),
            v.map(DualSVec64::<3>::from_re),
            [dual(mu[0], 0), dual(mu[1], 1), dual(mu[2], 2)],
        );
        g.map(|c| grad(&c))
    }
}

/// The attitude along a written design (physical units): the body-frame
/// momentum at any instant, for the feed-forward torque's momentum part, from
/// the design's own map (one partial Runge-Kutta step from the nearest knot).
#[derive(Debug, Clone)]
pub struct Track {
    /// The release in SI units (time unit 1 s).
    pub release: Release,
    pub knots: Vec<[f64; 4]>,
}

impl Track {
    /// The track of the plan `z` (physical units, durations in s).
    pub fn new(release: Release, cat: &Cat, tr: &Transcription, z: &[f64]) -> Track {
        let knots = release.path(cat, tr, z, true, false).knots;
        Track { release, knots }
    }

    /// Body-frame momentum `R_A' L` (N m s) at normalised time `s` of phase
    /// `p` of `z`.
    pub fn body_momentum(
        &self,
        cat: &Cat,
        tr: &Transcription,
        z: &[f64],
        p: usize,
        s: f64,
    ) -> [f64; 3] {
        let h = tr.h();
        let k = ((s / h).floor() as usize).min(tr.nodes - 2);
        let c = ((s - k as f64 * h) / h).clamp(0.0, 1.0);
        let j = ((c * SUB as f64).floor() as usize).min(SUB - 1);
        let c0 = j as f64 / SUB as f64;
        let x = self.knots[(p * (tr.nodes - 1) + k) * SUB + j];
        let d = tr.interval(z, p, k);
        let dur = z[tr.duration(p)];
        let x = self.release.step(cat, &d, c0, c, x, dur, h);
        self.release.mu(x, 1.0)
    }
}

impl Release {
    /// One Runge-Kutta step of the attitude over interval coordinates `c0..c1`
    /// of the interval `d` (interval length `h` in normalised time).
    #[allow(clippy::too_many_arguments)]
    fn step(
        &self,
        cat: &Cat,
        d: &crate::design::collocation::IntervalData,
        c0: f64,
        c1: f64,
        x: [f64; 4],
        dur: f64,
        h: f64,
    ) -> [f64; 4] {
        let hs = (c1 - c0) * h;
        if hs == 0.0 {
            return x;
        }
        let a = [0.0, 0.5, 0.5, 1.0];
        let mut ks = [[0.0; 4]; 4];
        for stage in 0..4 {
            let it = d.at(c0 + a[stage] * (c1 - c0));
            let xs: [f64; 4] = std::array::from_fn(|i| {
                x[i] + if stage > 0 {
                    a[stage] * hs * ks[stage - 1][i]
                } else {
                    0.0
                }
            });
            ks[stage] = self.rate(cat, xs, it.q, it.v, dur);
        }
        std::array::from_fn(|i| {
            x[i] + hs / 6.0 * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i])
        })
    }

    /// The same release in SI units (time unit 1 s) from one in units of `time_unit`.
    pub fn in_seconds(&self, time_unit: f64) -> Release {
        Release {
            momentum: self.momentum.map(|c| c / time_unit),
            tail: self.tail * time_unit,
            ..*self
        }
    }

    /// The release of `spec`'s start in the units of a problem whose time
    /// unit is `time_unit`; `None` for today's start (upside down at rest).
    pub fn of(spec: &DesignSpec, time_unit: f64) -> Option<Release> {
        if spec.is_default_start() {
            return None;
        }
        let cat = spec.cat;
        let start = spec.release();
        let l = start.momentum(&cat);
        Some(Release {
            attitude: start.attitude,
            momentum: l.map(|c| c * time_unit),
            tail: spec.fall.margin / time_unit,
            inertias: straight_inertias(&cat),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::free::FreeProblem;
    use crate::design::scp::ScpProblem;

    const SEED: &str = include_str!("../../configs/seed.toml");

    fn config(sets: &[&str]) -> DesignSpec {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        crate::test_support::spec_of(SEED, "seed", &sets)
    }

    /// A smooth, bent, moving path on `nodes` per phase (not a flip: the
    /// derivatives do not need one).
    fn wavy(tr: &Transcription) -> Vec<f64> {
        let mut z = vec![0.0; tr.dim()];
        for p in 0..3 {
            for k in 0..tr.nodes {
                let s = (p * tr.nodes + k) as f64 * 0.37;
                for j in 0..2 {
                    let f = 1.0 + j as f64;
                    z[tr.q(p, k) + j] = 0.6 * (f * s).sin();
                    z[tr.v(p, k) + j] = 0.9 * (f * s + 0.4).cos();
                    z[tr.a(p, k) + j] = -1.1 * (f * s - 0.2).sin();
                }
            }
            z[tr.duration(p)] = [0.3, 0.45, 0.25][p];
        }
        z
    }

    const SPUN: [&str; 2] = [
        "start.angular_velocity=[0.4, -0.3, 0.5]",
        "start.rotation_deg=[5, 12, -7]",
    ];

    #[test]
    fn the_landing_residual_has_the_derivative_of_its_own_map() {
        let spec = config(&SPUN);
        let tr = Transcription::new(3, 8);
        let z = wavy(&tr);
        let problem = FreeProblem::new(&spec, 8, &z);
        assert!(problem.release.is_some());
        let lin = problem.linearize(&z);
        let m = lin.residual.len();
        let mut jac = vec![vec![0.0; tr.dim()]; m];
        for &(r, c, v) in &lin.residual_jac {
            jac[r][c] += v;
        }
        let mut worst = 0.0f64;
        for col in 0..tr.dim() {
            let h = 1e-6;
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[col] += h;
            zm[col] -= h;
            let (rp, rm) = (
                problem.evaluate(&zp).residual,
                problem.evaluate(&zm).residual,
            );
            for r in m - 2..m {
                let fd = (rp[r] - rm[r]) / (2.0 * h);
                worst = worst.max((fd - jac[r][col]).abs());
            }
        }
        assert!(worst < 1e-7, "worst landing-derivative error {worst:e}");
    }

    /// The residual vanishes belly-down only (not belly-up, where the
    /// horizontal components vanish too), its length is the landing error
    /// and it points along the belly's horizontal part,
    /// and its derivative matches differences in the series near straight
    /// down and in the closed form.
    #[test]
    fn the_landing_residual_is_the_tilt_from_straight_down() {
        let rel = Release {
            attitude: [1.0, 0.0, 0.0, 0.0],
            momentum: [0.0; 3],
            tail: 0.0,
            inertias: (1.0, 2.0),
        };
        // belly = R e_x; about z by angle a: (cos a, sin a, 0)
        let about = |axis: [f64; 3], a: f64| {
            let h = 0.5 * a;
            [
                h.cos(),
                axis[0] * h.sin(),
                axis[1] * h.sin(),
                axis[2] * h.sin(),
            ]
        };
        let pi = std::f64::consts::PI;
        for (axis, a) in [
            ([0.0, 0.0, 1.0], pi),
            ([0.0, 1.0, 0.0], pi - 1e-5),
            ([0.0, 0.6, 0.8], pi - 0.3),
            ([0.0, 0.0, 1.0], 0.0),
            ([0.0, 1.0, 0.0], 1e-3),
        ] {
            let x = about(axis, a);
            let (r, dr) = rel.landing(x);
            let tilt = r[0].hypot(r[1]);
            // straight down is a turn of pi from the belly's rest direction
            let want = pi - a;
            assert!((tilt - want).abs() < 1e-9, "{a}: tilt {tilt}, want {want}");
            assert!((rel.landing_error(x) - want).abs() < 1e-9);
            // along the belly's horizontal part, not against it
            let b = rotate(x, [1.0, 0.0, 0.0]);
            let s = b[1].hypot(b[2]);
            if s > 0.0 {
                let along = (r[0] * b[1] + r[1] * b[2]) / s;
                assert!((along - tilt).abs() < 1e-9, "{a}: {r:?} against {b:?}");
            }
            if a == 0.0 {
                continue; // belly-up exactly: the direction is undefined
            }
            let h = 1e-7;
            for c in 0..4 {
                let (mut xp, mut xm) = (x, x);
                xp[c] += h;
                xm[c] -= h;
                for i in 0..2 {
                    let fd = (rel.landing(xp).0[i] - rel.landing(xm).0[i]) / (2.0 * h);
                    let exact = dr[i][c];
                    assert!(
                        (fd - exact).abs() < 1e-6 * (1.0 + exact.abs()),
                        "{a} {c} {i}: {fd} {exact}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_momentum_torque_gradients_match_differences() {
        let cat = config(&[]).cat;
        let (q, v, mu) = ([0.4, -0.7], [1.3, 0.6], [0.02, -0.05, 0.03]);
        let (g, dg) = Release::torque(&cat, q, v, mu);
        let dmu = Release::torque_dmu(&cat, q, v, mu);
        let h = 1e-6;
        for i in 0..7 {
            let shift = |s: f64| {
                let mut x = [q[0], q[1], v[0], v[1], mu[0], mu[1], mu[2]];
                x[i] += s;
                momentum_torque(&cat, [x[0], x[1]], [x[2], x[3]], [x[4], x[5], x[6]])
            };
            let (p, m) = (shift(h), shift(-h));
            for c in 0..2 {
                let fd = (p[c] - m[c]) / (2.0 * h);
                let exact = if i < 4 { dg[c][i] } else { dmu[c][i - 4] };
                assert!(
                    (fd - exact).abs() < 1e-7 * (1.0 + exact.abs()),
                    "{i} {c}: {fd} {exact}"
                );
            }
        }
        assert_eq!(g, momentum_torque(&cat, q, v, mu));
    }
}
