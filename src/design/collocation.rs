//! Multi-phase transcription of a shape trajectory for direct collocation.
//!
//! One [`Transcription`] owns the grid (phases x nodes), the decision-variable
//! indexing and the phase durations. Each phase runs in its own normalised
//! time `s = t / T_p` in `[0, 1]`; each node carries `q`, `q^ = dq/ds` and
//! `q^^ = d2q/ds2` (2 each), and each phase has a free duration `T_p`. The
//! physical rates are `q_dot = q^ / T_p`, `q_ddot = q^^ / T_p^2`.
//!
//! Why normalised time: the defects become linear (exact constraints, no
//! penalty), the attitude depends on the path only (docs/model.md F2) and so not on
//! the durations, and the duration enters the torque only as `1 / T_p^2` (F3).
//!
//! Scheme: first-order-hold acceleration. `q^^` is linear on each interval of
//! `h = 1 / (N - 1)` and the double integrator is integrated exactly:
//! `q^_{k+1} - q^_k - h (q^^_k + q^^_{k+1}) / 2 = 0`,
//! `q_{k+1} - q_k - h q^_k - h^2 (2 q^^_k + q^^_{k+1}) / 6 = 0`;
//! the interpolation is the matching cubic in `q`, and the same interpolation
//! reconstructs the schedule.

use crate::design::plan::ShapePlan;

/// Grid and variable layout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transcription {
    pub phases: usize,
    /// Nodes per phase (both ends included).
    pub nodes: usize,
    /// Whether `q^^` may jump at the interior nodes ([`Transcription::with_jumps`]).
    pub jumps: bool,
}

/// Node values bounding one interval (normalised time).
#[derive(Debug, Clone, Copy)]
pub struct IntervalData {
    pub q0: [f64; 2],
    pub v0: [f64; 2],
    pub a0: [f64; 2],
    pub a1: [f64; 2],
    pub h: f64,
}

/// Interpolant at a fraction `c` of an interval, with the (scalar, per
/// component) coefficients of `q` and `q^` on `(q0, q^0, q^^0, q^^1)`.
pub struct Interp {
    pub q: [f64; 2],
    pub v: [f64; 2],
    pub a: [f64; 2],
    pub dq: [f64; 4],
    pub dv: [f64; 4],
}

impl IntervalData {
    pub fn at(&self, c: f64) -> Interp {
        let h = self.h;
        let tau = c * h;
        let (t2, c3h2) = (tau * tau, c * c * c * h * h);
        let dq = [1.0, tau, t2 / 2.0 - c3h2 / 6.0, c3h2 / 6.0];
        let dv = [0.0, 1.0, tau - c * c * h / 2.0, c * c * h / 2.0];
        let mut it = Interp {
            q: [0.0; 2],
            v: [0.0; 2],
            a: [0.0; 2],
            dq,
            dv,
        };
        for j in 0..2 {
            let x = [self.q0[j], self.v0[j], self.a0[j], self.a1[j]];
            it.q[j] = (0..4).map(|i| dq[i] * x[i]).sum();
            it.v[j] = (0..4).map(|i| dv[i] * x[i]).sum();
            it.a[j] = self.a0[j] + (self.a1[j] - self.a0[j]) * c;
        }
        it
    }
}

impl Transcription {
    pub const PER_NODE: usize = 6;

    pub fn new(phases: usize, nodes: usize) -> Self {
        assert!(nodes >= 2 && phases >= 1);
        Self {
            phases,
            nodes,
            jumps: false,
        }
    }

    /// The grid with the acceleration free to jump at each interior node:
    /// each interval has its own `q^^` at both ends (`a` at its first node,
    /// [`Transcription::a_in`] at its last), so the torque can switch sign
    /// at a node instead of ramping over an interval. The shape and its
    /// rate stay continuous.
    pub fn with_jumps(mut self) -> Self {
        self.jumps = true;
        self
    }

    /// Number of decision variables: node variables, the interior nodes'
    /// incoming accelerations (with jumps), one duration per phase.
    pub fn dim(&self) -> usize {
        self.durations_start() + self.phases
    }

    fn node_vars(&self) -> usize {
        self.phases * self.nodes * Self::PER_NODE
    }

    fn durations_start(&self) -> usize {
        self.node_vars()
            + if self.jumps {
                self.phases * (self.nodes - 2) * 2
            } else {
                0
            }
    }

    pub fn node(&self, p: usize, k: usize) -> usize {
        (p * self.nodes + k) * Self::PER_NODE
    }
    pub fn q(&self, p: usize, k: usize) -> usize {
        self.node(p, k)
    }
    pub fn v(&self, p: usize, k: usize) -> usize {
        self.node(p, k) + 2
    }
    /// `q^^` at node `k` as the interval starting there sees it (and at
    /// the last node, as the interval ending there sees it).
    pub fn a(&self, p: usize, k: usize) -> usize {
        self.node(p, k) + 4
    }
    /// `q^^` at node `k` as the interval ending there sees it: its own
    /// variable at an interior node with jumps, else [`Transcription::a`].
    pub fn a_in(&self, p: usize, k: usize) -> usize {
        if self.jumps && k > 0 && k < self.nodes - 1 {
            self.node_vars() + (p * (self.nodes - 2) + k - 1) * 2
        } else {
            self.a(p, k)
        }
    }
    pub fn duration(&self, p: usize) -> usize {
        self.durations_start() + p
    }

    /// Columns of `(q_k, q^_k, q^^_k, q^^_{k+1})`, component `j`: the variables
    /// an interval's interpolant depends on (order of [`Interp`] coefficients).
    pub fn interval_columns(&self, p: usize, k: usize, j: usize) -> [usize; 4] {
        [
            self.q(p, k) + j,
            self.v(p, k) + j,
            self.a(p, k) + j,
            self.a_in(p, k + 1) + j,
        ]
    }

    /// Normalised interval length `1 / (N - 1)`.
    pub fn h(&self) -> f64 {
        1.0 / (self.nodes - 1) as f64
    }

    pub fn get2(z: &[f64], i: usize) -> [f64; 2] {
        [z[i], z[i + 1]]
    }

    pub fn interval(&self, z: &[f64], p: usize, k: usize) -> IntervalData {
        IntervalData {
            q0: Self::get2(z, self.q(p, k)),
            v0: Self::get2(z, self.v(p, k)),
            a0: Self::get2(z, self.a(p, k)),
            a1: Self::get2(z, self.a_in(p, k + 1)),
            h: self.h(),
        }
    }

    /// Number of defect rows: 4 per interval.
    pub fn defect_count(&self) -> usize {
        4 * self.phases * (self.nodes - 1)
    }

    /// The defects `D z` (linear; radians in normalised time) and, if asked,
    /// their constant Jacobian with rows offset by `row0`.
    pub fn defects(
        &self,
        z: &[f64],
        row0: usize,
        jac: Option<&mut Vec<(usize, usize, f64)>>,
    ) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.defect_count());
        let mut jac = jac;
        self.for_each_defect(|row| {
            if let Some(j) = jac.as_deref_mut() {
                j.extend(row.iter().map(|&(i, c)| (row0 + out.len(), i, c)));
            }
            out.push(row.iter().map(|&(i, c)| c * z[i]).sum());
        });
        out
    }

    fn for_each_defect(&self, mut f: impl FnMut(&[(usize, f64)])) {
        let h = self.h();
        for p in 0..self.phases {
            for k in 0..self.nodes - 1 {
                for j in 0..2 {
                    let v = [
                        (self.v(p, k + 1) + j, 1.0),
                        (self.v(p, k) + j, -1.0),
                        (self.a(p, k) + j, -h / 2.0),
                        (self.a_in(p, k + 1) + j, -h / 2.0),
                    ];
                    let q = [
                        (self.q(p, k + 1) + j, 1.0),
                        (self.q(p, k) + j, -1.0),
                        (self.v(p, k) + j, -h),
                        (self.a(p, k) + j, -h * h / 3.0),
                        (self.a_in(p, k + 1) + j, -h * h / 6.0),
                    ];
                    f(&v);
                    f(&q);
                }
            }
        }
    }

    /// Samples a plan at the nodes (uniform in time within each phase).
    pub fn sample(&self, plan: &dyn ShapePlan) -> Vec<f64> {
        let b = plan.phase_bounds();
        let mut z = vec![0.0; self.dim()];
        for p in 0..self.phases {
            let t = b[p + 1] - b[p];
            for k in 0..self.nodes {
                let s = plan.state_in(p, b[p] + t * k as f64 * self.h());
                z[self.q(p, k)..self.q(p, k) + 2].copy_from_slice(&s.q);
                z[self.v(p, k)..self.v(p, k) + 2].copy_from_slice(&s.qd.map(|x| x * t));
                z[self.a(p, k)..self.a(p, k) + 2].copy_from_slice(&s.qdd.map(|x| x * t * t));
                if self.a_in(p, k) != self.a(p, k) {
                    // both one-sided limits: a plan with jumps of its own keeps them
                    let side = |d: f64| {
                        let st = plan.state_in(p, b[p] + t * (k as f64 * self.h() + d));
                        st.qdd.map(|x| x * t * t)
                    };
                    z[self.a(p, k)..self.a(p, k) + 2].copy_from_slice(&side(1e-9));
                    z[self.a_in(p, k)..self.a_in(p, k) + 2].copy_from_slice(&side(-1e-9));
                }
            }
            z[self.duration(p)] = t;
        }
        z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::collocation_plan::CollocationPlan;

    #[test]
    fn interpolant_satisfies_the_defects_exactly_and_has_consistent_derivatives() {
        let d = IntervalData {
            q0: [0.3, -0.2],
            v0: [1.0, 0.5],
            a0: [2.0, -1.0],
            a1: [-3.0, 4.0],
            h: 0.1,
        };
        let e = d.at(1.0);
        for j in 0..2 {
            let v1 = d.v0[j] + d.h * (d.a0[j] + d.a1[j]) / 2.0;
            let q1 = d.q0[j] + d.h * d.v0[j] + d.h * d.h * (2.0 * d.a0[j] + d.a1[j]) / 6.0;
            assert!((e.v[j] - v1).abs() < 1e-15 && (e.q[j] - q1).abs() < 1e-15);
        }
        let eps = 1e-7;
        for c in [0.2, 0.7] {
            let (p, m) = (d.at(c + eps), d.at(c - eps));
            for j in 0..2 {
                assert!(((p.q[j] - m.q[j]) / (2.0 * eps * d.h) - d.at(c).v[j]).abs() < 1e-6);
                assert!(((p.v[j] - m.v[j]) / (2.0 * eps * d.h) - d.at(c).a[j]).abs() < 1e-6);
            }
        }
    }

    /// With jumps, each interior node has its own incoming acceleration
    /// (nothing else shares its column), the ends keep one, and a schedule
    /// that jumps at the nodes satisfies the defects and is sampled back
    /// with its jumps.
    #[test]
    fn with_jumps_a_schedule_that_steps_at_the_nodes_reads_back_exactly() {
        let (phases, n) = (3, 7);
        let tr = Transcription::new(phases, n).with_jumps();
        assert_eq!(tr.dim(), phases * n * 6 + phases * (n - 2) * 2 + phases);
        let mut cols = Vec::new();
        for p in 0..phases {
            for k in 0..n {
                cols.extend([tr.q(p, k), tr.q(p, k) + 1, tr.v(p, k), tr.v(p, k) + 1]);
                cols.extend([tr.a(p, k), tr.a(p, k) + 1]);
                if k > 0 && k < n - 1 {
                    cols.extend([tr.a_in(p, k), tr.a_in(p, k) + 1]);
                } else {
                    assert_eq!(tr.a_in(p, k), tr.a(p, k));
                }
            }
            cols.push(tr.duration(p));
        }
        cols.sort();
        assert_eq!(cols, (0..tr.dim()).collect::<Vec<_>>(), "each column once");
        // integrate arbitrary per-interval accelerations exactly
        let mut z = vec![0.0; tr.dim()];
        let h = tr.h();
        for p in 0..phases {
            z[tr.duration(p)] = 0.3 + 0.1 * p as f64;
            for k in 0..n - 1 {
                for j in 0..2 {
                    let x = (p * n + k) as f64 + 0.5 * j as f64;
                    z[tr.a(p, k) + j] = (1.3 * x).sin() * 2.0;
                    z[tr.a_in(p, k + 1) + j] = (0.7 * x).cos() * 3.0;
                    let d = tr.interval(&z, p, k);
                    let (v1, q1) = (
                        d.v0[j] + h * (d.a0[j] + d.a1[j]) / 2.0,
                        d.q0[j] + h * d.v0[j] + h * h * (2.0 * d.a0[j] + d.a1[j]) / 6.0,
                    );
                    z[tr.v(p, k + 1) + j] = v1;
                    z[tr.q(p, k + 1) + j] = q1;
                }
            }
            if p + 1 < phases {
                for j in 0..2 {
                    z[tr.q(p + 1, 0) + j] = z[tr.q(p, n - 1) + j];
                    z[tr.v(p + 1, 0) + j] = z[tr.v(p, n - 1) + j];
                }
            }
        }
        assert!(tr.defects(&z, 0, None).iter().all(|d| d.abs() < 1e-14));
        let back = tr.sample(&CollocationPlan::new(tr, z.clone()));
        for (i, (a, b)) in z.iter().zip(&back).enumerate() {
            assert!(
                (a - b).abs() < 1e-6 * (1.0 + a.abs()),
                "variable {i}: {a} vs {b}"
            );
        }
        let jumps = (1..n - 1).filter(|&k| (z[tr.a(1, k)] - z[tr.a_in(1, k)]).abs() > 0.1);
        assert!(jumps.count() > n / 2, "the schedule does jump");
    }

    #[test]
    fn sampling_a_plan_and_reading_it_back_agree_at_the_nodes() {
        let plan = crate::design::analytic::plan(1.0, 3.0, [0.3, 0.5, 0.4]);
        let tr = Transcription::new(3, 7);
        let z = tr.sample(&plan);
        let cp = CollocationPlan::new(tr, z);
        for i in 0..3 {
            let b = plan.phase_bounds();
            // just after node 3, so that the interval starting there is used
            let t = b[i] + (b[i + 1] - b[i]) * (3.0 / 6.0 + 1e-12);
            let (x, y) = (plan.state_in(i, t), cp.state_in(i, t));
            for j in 0..2 {
                assert!((x.q[j] - y.q[j]).abs() < 1e-9 && (x.qd[j] - y.qd[j]).abs() < 1e-8);
                assert!((x.qdd[j] - y.qdd[j]).abs() < 1e-6);
            }
        }
    }
}
