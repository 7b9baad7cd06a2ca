//! The seed's family of shape paths (MODEL.md F5): fold in a plane, twist at
//! constant bend, unfold in a plane; and the rest-to-rest timings that run
//! along them. A phased plan is three (path, timing, duration) triples.

use crate::plan::{Phase, ShapePlan, ShapeState};
use serde::Serialize;

/// A shape path `q(s)`, `s` in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Path {
    /// Straight line in shape space (a fold or unfold in a fixed plane).
    Line { from: [f64; 2], to: [f64; 2] },
    /// Circle of radius `bend` from angle `phi0` through `dphi` (twist at constant bend).
    Arc { bend: f64, phi0: f64, dphi: f64 },
}

impl Path {
    /// `(q, dq/ds, d2q/ds2)` at `s`.
    pub fn eval(&self, s: f64) -> [[f64; 2]; 3] {
        match *self {
            Path::Line { from, to } => {
                let d = [to[0] - from[0], to[1] - from[1]];
                [[from[0] + s * d[0], from[1] + s * d[1]], d, [0.0, 0.0]]
            }
            Path::Arc { bend, phi0, dphi } => {
                let p = phi0 + s * dphi;
                let (sn, cs) = p.sin_cos();
                [
                    [bend * cs, bend * sn],
                    [-bend * dphi * sn, bend * dphi * cs],
                    [-bend * dphi * dphi * cs, -bend * dphi * dphi * sn],
                ]
            }
        }
    }

    /// The three paths of a phased design: fold along `q1`, twist by `dphi`, unfold.
    pub fn phased(bend: f64, dphi: f64) -> [Path; 3] {
        [
            Path::Line {
                from: [0.0, 0.0],
                to: [bend, 0.0],
            },
            Path::Arc {
                bend,
                phi0: 0.0,
                dphi,
            },
            Path::Line {
                from: [bend * dphi.cos(), bend * dphi.sin()],
                to: [0.0, 0.0],
            },
        ]
    }
}

/// Rest-to-rest timing `s(t)` of one phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Timing {
    /// `s = (1 - cos(pi t / T)) / 2`: the seed's fold / unfold (erratum E4 corrected).
    Cosine,
    /// `s = t/T - sin(2 pi t / T) / (2 pi)`: the seed's twist rate
    /// `omega0 (1 - cos(2 pi t / T))` (erratum E3 corrected).
    CosineRate,
    /// Piecewise-constant `s_ddot` on a grid in `s` (the path-timing optimum).
    Grid(GridTiming),
}

/// Path timing with `beta = s_dot^2` linear in `s` on each interval
/// (constant `a = s_ddot`), as the phase SOCP assumes. Unit total time; the
/// phase duration scales it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridTiming {
    /// Grid in `s`, `s[0] = 0`, `s[K] = 1`.
    pub s: Vec<f64>,
    /// `s_dot^2` at the grid points in unit time.
    pub beta: Vec<f64>,
    /// Unit-time instants of the grid points.
    pub t: Vec<f64>,
}

impl GridTiming {
    pub fn new(s: Vec<f64>, beta: Vec<f64>) -> Self {
        let mut t = vec![0.0];
        for k in 0..s.len() - 1 {
            let ds = s[k + 1] - s[k];
            let denom = beta[k].max(0.0).sqrt() + beta[k + 1].max(0.0).sqrt();
            t.push(t[k] + 2.0 * ds / denom);
        }
        let total = *t.last().unwrap();
        // renormalise to unit time so that the phase duration scales exactly
        let scale = 1.0 / total;
        let beta = beta.iter().map(|b| b.max(0.0) / (scale * scale)).collect();
        let t = t.iter().map(|x| x * scale).collect();
        Self { s, beta, t }
    }

    /// `(s, s_dot, s_ddot)` at unit time `tau`.
    fn eval(&self, tau: f64) -> (f64, f64, f64) {
        let n = self.t.len() - 1;
        let k = match self.t.binary_search_by(|x| x.partial_cmp(&tau).unwrap()) {
            Ok(i) => i.min(n - 1),
            Err(i) => i.saturating_sub(1).min(n - 1),
        };
        let ds = self.s[k + 1] - self.s[k];
        let a = (self.beta[k + 1] - self.beta[k]) / (2.0 * ds);
        let v0 = self.beta[k].sqrt();
        let dt = (tau - self.t[k]).clamp(0.0, self.t[k + 1] - self.t[k]);
        let s = (self.s[k] + v0 * dt + 0.5 * a * dt * dt).min(self.s[k + 1]);
        ((s), (v0 + a * dt).max(0.0), a)
    }
}

impl Timing {
    /// `(s, s_dot, s_ddot)` at time `t` of a phase lasting `dur`.
    pub fn eval(&self, t: f64, dur: f64) -> (f64, f64, f64) {
        use std::f64::consts::PI;
        let tau = (t / dur).clamp(0.0, 1.0);
        match self {
            Timing::Cosine => {
                let w = PI / dur;
                (
                    0.5 * (1.0 - (PI * tau).cos()),
                    0.5 * w * (PI * tau).sin(),
                    0.5 * w * w * (PI * tau).cos(),
                )
            }
            Timing::CosineRate => {
                let x = 2.0 * PI * tau;
                (
                    tau - x.sin() / (2.0 * PI),
                    (1.0 - x.cos()) / dur,
                    2.0 * PI * x.sin() / (dur * dur),
                )
            }
            Timing::Grid(g) => {
                let (s, sd, sdd) = g.eval(tau);
                (s, sd / dur, sdd / (dur * dur))
            }
        }
    }
}

/// Fold, twist and unfold, each a path with a timing and a duration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhasedPlan {
    pub paths: [Path; 3],
    pub timings: [Timing; 3],
    pub durations: [f64; 3],
}

impl ShapePlan for PhasedPlan {
    fn phase_bounds(&self) -> Vec<f64> {
        let d = self.durations;
        vec![0.0, d[0], d[0] + d[1], d[0] + d[1] + d[2]]
    }

    fn state_in(&self, i: usize, t: f64) -> ShapeState {
        let b = self.phase_bounds();
        let (s, sd, sdd) = self.timings[i].eval(t - b[i], self.durations[i]);
        let [q, dq, d2q] = self.paths[i].eval(s);
        ShapeState {
            q,
            qd: [dq[0] * sd, dq[1] * sd],
            qdd: [
                dq[0] * sdd + d2q[0] * sd * sd,
                dq[1] * sdd + d2q[1] * sd * sd,
            ],
            phase: Phase::ALL[i],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fd_check(timing: &Timing, dur: f64) {
        let h = 1e-6;
        for i in 1..20 {
            let t = dur * (i as f64 + 0.37) / 20.5;
            let (_, sd, sdd) = timing.eval(t, dur);
            let (sp, sdp, _) = timing.eval(t + h, dur);
            let (sm, sdm, _) = timing.eval(t - h, dur);
            assert!(
                ((sp - sm) / (2.0 * h) - sd).abs() < 1e-6,
                "{timing:?} t={t} fd={} sd={sd}",
                (sp - sm) / (2.0 * h)
            );
            assert!(((sdp - sdm) / (2.0 * h) - sdd).abs() < 1e-4 * (1.0 + sdd.abs()));
        }
        let (s0, v0, _) = timing.eval(0.0, dur);
        let (s1, v1, _) = timing.eval(dur, dur);
        assert!(s0.abs() < 1e-12 && (s1 - 1.0).abs() < 1e-12);
        assert!(
            v0.abs() < 1e-12 && v1.abs() < 1e-9,
            "rest to rest: {v0} {v1}"
        );
    }

    #[test]
    fn timings_are_rest_to_rest_with_consistent_derivatives() {
        fd_check(&Timing::Cosine, 0.7);
        fd_check(&Timing::CosineRate, 1.3);
        // a triangular beta profile: accelerate then decelerate
        let k = 10;
        let s: Vec<f64> = (0..=k).map(|i| i as f64 / k as f64).collect();
        let beta: Vec<f64> = s.iter().map(|x| x.min(1.0 - x)).collect();
        fd_check(&Timing::Grid(GridTiming::new(s, beta)), 0.9);
    }

    #[test]
    fn path_derivatives_match_finite_differences() {
        for p in Path::phased(1.1, 3.5) {
            let h = 1e-6;
            for i in 0..=10 {
                let s = i as f64 / 10.0;
                let [_, d1, d2] = p.eval(s);
                let [qp, d1p, _] = p.eval(s + h);
                let [qm, d1m, _] = p.eval(s - h);
                for j in 0..2 {
                    assert!(((qp[j] - qm[j]) / (2.0 * h) - d1[j]).abs() < 1e-6);
                    assert!(((d1p[j] - d1m[j]) / (2.0 * h) - d2[j]).abs() < 1e-5);
                }
            }
        }
    }
}
