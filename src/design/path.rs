//! The seed's family of shape paths (docs/model.md F5): fold in a plane, twist at
//! constant bend, unfold in a plane; and the rest-to-rest timings that run
//! along them. A phased plan is three (path, timing, duration) triples.

use crate::design::plan::{Phase, ShapePlan, ShapeState};
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

/// Path timing with `a = s_ddot` continuous and piecewise linear in `s`, so
/// `beta = s_dot^2` is piecewise quadratic (`beta' = 2 a`), as the phase SOCP
/// assumes. Scaled to unit total time; the phase duration scales it (F3).
///
/// `s(t)` has no closed form: the time of each grid interval is integrated by
/// Gauss-Legendre quadrature (with `v = w^2` substitutions that absorb the
/// `1/sqrt(beta)` singularity at a rest end), tabulated on sub-steps, and
/// inverted by cubic Hermite interpolation in time refined by Newton steps; `s_dot = sqrt(beta(s))`
/// and `s_ddot = a(s)` are then evaluated exactly at that `s`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridTiming {
    /// Grid in `s`, `s[0] = 0`, `s[K] = 1`.
    pub s: Vec<f64>,
    /// `s_dot^2` at the grid points, unit time.
    pub beta: Vec<f64>,
    /// `s_ddot` at the grid points, unit time.
    pub a: Vec<f64>,
    /// Unit-time instants of the grid points.
    pub t: Vec<f64>,
    /// Duration of the timing as given, before rescaling to 1 s.
    pub raw_time: f64,
    /// Sub-step table: (time, s) pairs, `SUB` per interval.
    #[serde(skip)]
    table: Vec<(f64, f64)>,
}

const SUB: usize = 8;
const GL_X: [f64; 6] = [
    -0.932_469_514_203_152,
    -0.661_209_386_466_264_5,
    -0.238_619_186_083_196_9,
    0.238_619_186_083_196_9,
    0.661_209_386_466_264_5,
    0.932_469_514_203_152,
];
const GL_W: [f64; 6] = [
    0.171_324_492_379_170_3,
    0.360_761_573_048_138_6,
    0.467_913_934_572_691,
    0.467_913_934_572_691,
    0.360_761_573_048_138_6,
    0.171_324_492_379_170_3,
];

impl GridTiming {
    /// From grid values of `beta` and `a` (any total time; rescaled to 1 s).
    pub fn new(s: Vec<f64>, beta: Vec<f64>, a: Vec<f64>) -> Self {
        let mut g = Self {
            s,
            beta: beta.iter().map(|b| b.max(0.0)).collect(),
            a,
            t: Vec::new(),
            raw_time: 0.0,
            table: Vec::new(),
        };
        g.tabulate();
        let total = g.table.last().unwrap().0;
        g.raw_time = total;
        // rescale to unit time: t' = t / T0, beta' = beta T0^2, a' = a T0^2
        let t2 = total * total;
        g.beta.iter_mut().for_each(|b| *b *= t2);
        g.a.iter_mut().for_each(|x| *x *= t2);
        g.tabulate();
        g
    }

    /// The same timing run backwards along the reversed path (`s -> 1 - s`).
    pub fn reversed(&self) -> Self {
        let s = self.s.iter().rev().map(|x| 1.0 - x).collect();
        let beta = self.beta.iter().rev().copied().collect();
        let a = self.a.iter().rev().map(|x| -x).collect();
        let mut g = Self {
            s,
            beta,
            a,
            t: Vec::new(),
            raw_time: self.raw_time,
            table: Vec::new(),
        };
        g.tabulate();
        g
    }

    fn interval(&self, s: f64) -> usize {
        let n = self.s.len() - 1;
        self.s
            .partition_point(|x| *x <= s)
            .saturating_sub(1)
            .min(n - 1)
    }

    /// `beta(s)` and `a(s)`.
    pub fn beta_a(&self, s: f64) -> (f64, f64) {
        let k = self.interval(s);
        let ds = self.s[k + 1] - self.s[k];
        let u = (s - self.s[k]).clamp(0.0, ds);
        let (a0, a1) = (self.a[k], self.a[k + 1]);
        let beta = self.beta[k] + 2.0 * a0 * u + (a1 - a0) * u * u / ds;
        (beta.max(0.0), a0 + (a1 - a0) * u / ds)
    }

    /// Time to go from `s0` to `s1` (same interval).
    fn seg_time(&self, s0: f64, s1: f64) -> f64 {
        let h = 0.5 * (s1 - s0);
        let w_max = h.sqrt();
        let mut sum = 0.0;
        for (x, w) in GL_X.iter().zip(GL_W) {
            let wv = 0.5 * w_max * (x + 1.0);
            let jac = 0.5 * w_max * w;
            for v in [s0 + wv * wv, s1 - wv * wv] {
                let (b, _) = self.beta_a(v);
                if b > 0.0 {
                    sum += jac * 2.0 * wv / b.sqrt();
                }
            }
        }
        sum
    }

    fn tabulate(&mut self) {
        let n = self.s.len() - 1;
        let mut table = vec![(0.0, 0.0)];
        let mut t = vec![0.0];
        let mut now = 0.0;
        for k in 0..n {
            for j in 0..SUB {
                let s0 = self.s[k] + (self.s[k + 1] - self.s[k]) * j as f64 / SUB as f64;
                let s1 = self.s[k] + (self.s[k + 1] - self.s[k]) * (j + 1) as f64 / SUB as f64;
                now += self.seg_time(s0, s1);
                table.push((now, s1));
            }
            t.push(now);
        }
        self.table = table;
        self.t = t;
    }

    /// `(s, s_dot, s_ddot)` at unit time `tau`.
    fn eval(&self, tau: f64) -> (f64, f64, f64) {
        let tb = &self.table;
        let n = tb.len() - 1;
        let j = tb
            .partition_point(|e| e.0 <= tau)
            .saturating_sub(1)
            .min(n - 1);
        let ((t0, s0), (t1, s1)) = (tb[j], tb[j + 1]);
        let h = t1 - t0;
        let x = ((tau - t0) / h).clamp(0.0, 1.0);
        let v0 = self.beta_a(s0).0.sqrt();
        let v1 = self.beta_a(s1).0.sqrt();
        let s = (2.0 * x * x * x - 3.0 * x * x + 1.0) * s0
            + (x * x * x - 2.0 * x * x + x) * h * v0
            + (-2.0 * x * x * x + 3.0 * x * x) * s1
            + (x * x * x - x * x) * h * v1;
        let mut s = s.clamp(s0, s1);
        // Newton on t(s) = tau, dt/ds = 1/sqrt(beta): makes s(t) consistent with
        // s_dot = sqrt(beta(s)) to quadrature accuracy
        for _ in 0..2 {
            let v = self.beta_a(s).0.sqrt();
            if s <= s0 || v <= 0.0 {
                break;
            }
            s = (s + (tau - t0 - self.seg_time(s0, s)) * v).clamp(s0, s1);
        }
        let (b, a) = self.beta_a(s);
        (s, b.sqrt(), a)
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

impl PhasedPlan {
    /// The same plan with its twist circulating the bend direction `k`
    /// times as far, on the same timing: at constant bend a no-twist cat
    /// turns about its spine in proportion (F1), so a seed made for the
    /// half turn becomes one for a smaller turn (`design::mirror`). The
    /// unfold starts where the twist ends.
    pub fn twist_scaled(&self, k: f64) -> PhasedPlan {
        let paths = self.paths.map(|p| match p {
            Path::Arc { bend, phi0, dphi } => Path::Arc {
                bend,
                phi0,
                dphi: k * dphi,
            },
            line => line,
        });
        let mut plan = PhasedPlan {
            paths,
            ..self.clone()
        };
        if let (Path::Arc { bend, phi0, dphi }, Path::Line { to, .. }) =
            (plan.paths[1], plan.paths[2])
        {
            let end = phi0 + dphi;
            plan.paths[2] = Path::Line {
                from: [bend * end.cos(), bend * end.sin()],
                to,
            };
        }
        plan
    }
}

impl ShapePlan for PhasedPlan {
    fn phase_bounds(&self) -> Vec<f64> {
        let d = self.durations;
        vec![0.0, d[0], d[0] + d[1], d[0] + d[1] + d[2]]
    }

    fn turn_scaled(&self, k: f64) -> Option<Box<dyn ShapePlan>> {
        Some(Box::new(self.twist_scaled(k)))
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
        // sqrt(beta) near a rest end turns one ulp of s into ~1e-8 of s_dot
        assert!(
            v0.abs() < 1e-7 && v1.abs() < 1e-7,
            "rest to rest: {v0} {v1}"
        );
    }

    #[test]
    fn timings_are_rest_to_rest_with_consistent_derivatives() {
        fd_check(&Timing::Cosine, 0.7);
        fd_check(&Timing::CosineRate, 1.3);
        // beta = s (1 - s), a = beta'/2 = 1/2 - s: accelerate then decelerate
        let k = 10;
        let s: Vec<f64> = (0..=k).map(|i| i as f64 / k as f64).collect();
        let beta: Vec<f64> = s.iter().map(|x| x * (1.0 - x)).collect();
        let a: Vec<f64> = s.iter().map(|x| 0.5 - x).collect();
        let g = GridTiming::new(s, beta, a);
        // exact: s_dot = sqrt(s (1 - s)) gives s = (1 - cos t)/2 in time pi, rescaled to 1
        for tau in [0.1, 0.37, 0.5, 0.81] {
            let (sv, _, _) = g.eval(tau);
            let want = 0.5 * (1.0 - (std::f64::consts::PI * tau).cos());
            assert!((sv - want).abs() < 1e-7, "{tau}: {sv} vs {want}");
        }
        fd_check(&Timing::Grid(g), 0.9);
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
