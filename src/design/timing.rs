//! Least-peak-torque timing of one rest-to-rest phase along a fixed path:
//! a second-order cone program in the path-timing variables (Verscheure et
//! al., IEEE TAC 2009; docs/model.md F5), peak torque minimised under a unit time
//! budget instead of time under a torque bound.
//!
//! Along `q(s)`, `s` in `[0, 1]`: `q_dot = q' s_dot`, `q_ddot = q' s_ddot + q'' s_dot^2`,
//! so with `a = s_ddot` and `beta = s_dot^2` the torque is linear:
//! `tau(s) = m(s) a + c(s) beta`, `m = M q'`, `c = M q'' + Gamma(q', q')`.
//! On a grid of `K` intervals `a` is continuous and piecewise linear, so
//! `beta` is piecewise quadratic with `beta_{k+1} - beta_k = ds (a_k + a_{k+1})`
//! (exact). Interval time is approximated by `2 ds / (sqrt(beta_k) + sqrt(beta_{k+1}))`
//! (exact for linear `beta`), made convex with `c_k <= sqrt(beta_k)` (SOC) and
//! `d_k >= 1 / (c_k + c_{k+1})` (hyperbolic SOC); `sum 2 ds d_k <= 1`. The
//! reconstruction integrates the true time and rescales to 1 s, and the peak is
//! rescaled with it (F3). The torque is bounded at every grid point and every
//! interval midpoint, where `a = (a_k + a_{k+1})/2` and
//! `beta = beta_k + ds (3 a_k + a_{k+1}) / 4`: the torque is then continuous
//! and the bound holds between points to second order in `ds`.

use crate::design::conic::{
    Cone, ConicData, ConicSettings, ConicSolver, SolveStatus, solve_reusing_with,
};
use crate::design::path::{GridTiming, Path};
use crate::error::{Error, Result};
use crate::model::dynamics::christoffel;
use crate::model::{Cat, ShapeTerms, TorqueNorm};

/// Result of one phase: unit-time least peak and the timing that attains it.
#[derive(Debug, Clone)]
pub struct PhaseTiming {
    /// Least peak joint torque when the phase takes 1 s, N m s^2 (F3: divide by `T^2`):
    /// the SOCP's bound after the reconstruction's exact rescaling to 1 s.
    pub unit_peak: f64,
    /// The SOCP's objective itself (its time model is second-order accurate).
    pub socp_peak: f64,
    pub timing: GridTiming,
    pub status: SolveStatus,
}

/// The phase SOCP on a fixed grid; its solvers (one per phase solved at
/// once) are reused across paths and bends.
pub struct TimingProblem {
    socp: PhaseSocp,
    solvers: Vec<Option<ConicSolver>>,
}

/// The grid, norm and solver settings of the phase SOCP.
#[derive(Debug, Clone, Copy)]
struct PhaseSocp {
    k: usize,
    norm: TorqueNorm,
    settings: ConicSettings,
}

struct Index {
    k: usize,
}

impl Index {
    fn beta(&self, i: usize) -> usize {
        i
    }
    fn a(&self, i: usize) -> usize {
        self.k + 1 + i
    }
    fn c(&self, i: usize) -> usize {
        2 * self.k + 2 + i
    }
    fn d(&self, i: usize) -> usize {
        3 * self.k + 3 + i
    }
    fn t(&self) -> usize {
        4 * self.k + 3
    }
    fn n(&self) -> usize {
        4 * self.k + 4
    }
}

/// `m(s) = M q'` and `c(s) = M q'' + Gamma(q', q')` at `s`.
pub fn path_coefficients(cat: &Cat, path: &Path, s: f64) -> ([f64; 2], [f64; 2]) {
    let [q, d1, d2] = path.eval(s);
    let t = ShapeTerms::first(cat, q);
    let g = christoffel(&t);
    let mut m = [0.0; 2];
    let mut c = [0.0; 2];
    for i in 0..2 {
        for j in 0..2 {
            m[i] += t.m[i][j] * d1[j];
            c[i] += t.m[i][j] * d2[j];
            for k in 0..2 {
                c[i] += g[i][j][k] * d1[j] * d1[k];
            }
        }
    }
    (m, c)
}

impl TimingProblem {
    /// `k` grid intervals; `norm` picks SOC rows (Euclidean) or linear rows (per motor).
    pub fn new(k: usize, norm: TorqueNorm) -> Self {
        Self {
            socp: PhaseSocp {
                k,
                norm,
                settings: ConicSettings::default(),
            },
            solvers: Vec::new(),
        }
    }

    /// The same problem solved for a search ([`ConicSettings::SEARCH`]): its
    /// values rank bends; the chosen one is solved again by [`Self::new`]'s.
    pub fn for_search(&self) -> Self {
        Self {
            socp: PhaseSocp {
                settings: ConicSettings::SEARCH,
                ..self.socp
            },
            solvers: Vec::new(),
        }
    }

    /// Solves the phase along `path` in unit time.
    pub fn solve(&mut self, cat: &Cat, path: &Path) -> Result<PhaseTiming> {
        Ok(self.solve_all(cat, &[path])?.remove(0))
    }

    /// Solves the phases along `paths` in unit time, each on its own thread:
    /// the phases of a bend are independent SOCPs (a bend's two or three
    /// SOCPs take the time of the longest on two cores).
    pub fn solve_all(&mut self, cat: &Cat, paths: &[&Path]) -> Result<Vec<PhaseTiming>> {
        if self.solvers.len() < paths.len() {
            self.solvers.resize_with(paths.len(), || None);
        }
        solve_paths(self.socp, &mut self.solvers, cat, paths)
    }

    /// Solves the phase along `first` on its own thread while `rest` finds
    /// the other phases' paths on this one (the twist root-find, which the
    /// fold does not wait for), then those as [`Self::solve_all`] does; the
    /// results in that order. A bend has three phases: `rest` gives at most
    /// two paths.
    pub fn solve_alongside(
        &mut self,
        cat: &Cat,
        first: &Path,
        rest: impl FnOnce() -> Result<Vec<Path>>,
    ) -> Result<Vec<PhaseTiming>> {
        let socp = self.socp;
        if self.solvers.len() < 3 {
            self.solvers.resize_with(3, || None);
        }
        let (head, tail) = self.solvers.split_at_mut(1);
        std::thread::scope(|scope| {
            let fold = scope.spawn(|| socp.solve(&mut head[0], cat, first));
            let others = rest().and_then(|paths| {
                let refs: Vec<&Path> = paths.iter().collect();
                solve_paths(socp, tail, cat, &refs)
            });
            let fold = fold.join().expect("a phase SOCP thread panicked");
            let mut out = vec![fold?];
            out.extend(others?);
            Ok(out)
        })
    }
}

/// The phases along `paths`, with the solver slots in that order (at least
/// one per path), the first on this thread and the others on their own.
fn solve_paths(
    socp: PhaseSocp,
    slots: &mut [Option<ConicSolver>],
    cat: &Cat,
    paths: &[&Path],
) -> Result<Vec<PhaseTiming>> {
    assert!(slots.len() >= paths.len(), "a solver slot per phase");
    let Some((&first_path, rest_paths)) = paths.split_first() else {
        return Ok(Vec::new());
    };
    let (first, rest) = slots.split_first_mut().expect("a solver slot per phase");
    std::thread::scope(|scope| {
        let others: Vec<_> = rest_paths
            .iter()
            .zip(rest.iter_mut())
            .map(|(&path, slot)| scope.spawn(move || socp.solve(slot, cat, path)))
            .collect();
        let mut out = vec![socp.solve(first, cat, first_path)];
        out.extend(
            others
                .into_iter()
                .map(|h| h.join().expect("a phase SOCP thread panicked")),
        );
        out.into_iter().collect()
    })
}

impl PhaseSocp {
    fn build(&self, cat: &Cat, path: &Path) -> ConicData {
        let k = self.k;
        let ix = Index { k };
        let ds = 1.0 / k as f64;
        // coefficients at grid points (even entries) and midpoints (odd entries)
        let coef: Vec<_> = (0..=2 * k)
            .map(|i| path_coefficients(cat, path, i as f64 * ds / 2.0))
            .collect();
        let mut d = ConicData::new(ix.n());
        d.q[ix.t()] = 1.0;
        // rest to rest, and beta' = 2 a with a piecewise linear
        d.row(&[(ix.beta(0), 1.0)], 0.0);
        d.row(&[(ix.beta(k), 1.0)], 0.0);
        for i in 0..k {
            d.row(
                &[
                    (ix.beta(i + 1), 1.0),
                    (ix.beta(i), -1.0),
                    (ix.a(i), -ds),
                    (ix.a(i + 1), -ds),
                ],
                0.0,
            );
        }
        d.cone(Cone::Zero(k + 2));
        // time budget
        let row: Vec<_> = (0..k).map(|i| (ix.d(i), 2.0 * ds)).collect();
        d.row(&row, 1.0);
        d.cone(Cone::Nonneg(1));
        // torque at point p (grid point p/2 if even, midpoint of interval p/2 if odd):
        // tau_j = sum of (variable, coefficient)
        let torque_row = |p: usize, j: usize| -> Vec<(usize, f64)> {
            let (m, c) = coef[p];
            let i = p / 2;
            if p.is_multiple_of(2) {
                vec![(ix.a(i), m[j]), (ix.beta(i), c[j])]
            } else {
                vec![
                    (ix.a(i), 0.5 * m[j] + 0.75 * ds * c[j]),
                    (ix.a(i + 1), 0.5 * m[j] + 0.25 * ds * c[j]),
                    (ix.beta(i), c[j]),
                ]
            }
        };
        let points = 2 * k + 1;
        match self.norm {
            TorqueNorm::PerMotor => {
                for p in 0..points {
                    for j in 0..2 {
                        let mut up = torque_row(p, j);
                        let mut down: Vec<_> = up.iter().map(|&(v, x)| (v, -x)).collect();
                        up.push((ix.t(), -1.0));
                        down.push((ix.t(), -1.0));
                        d.row(&up, 0.0);
                        d.row(&down, 0.0);
                    }
                }
                d.cone(Cone::Nonneg(4 * points));
            }
            TorqueNorm::Euclidean => {
                for p in 0..points {
                    d.row(&[(ix.t(), -1.0)], 0.0);
                    for j in 0..2 {
                        let row: Vec<_> = torque_row(p, j).iter().map(|&(v, x)| (v, -x)).collect();
                        d.row(&row, 0.0);
                    }
                    d.cone(Cone::Soc(3));
                }
            }
        }
        // c_i <= sqrt(beta_i): ||(2 c, beta - 1)|| <= beta + 1
        for i in 0..=k {
            d.row(&[(ix.beta(i), -1.0)], 1.0);
            d.row(&[(ix.c(i), -2.0)], 0.0);
            d.row(&[(ix.beta(i), -1.0)], -1.0);
            d.cone(Cone::Soc(3));
        }
        // d_i (c_i + c_{i+1}) >= 1: ||(2, d - u)|| <= d + u
        for i in 0..k {
            d.row(
                &[(ix.d(i), -1.0), (ix.c(i), -1.0), (ix.c(i + 1), -1.0)],
                0.0,
            );
            d.row(&[], 2.0);
            d.row(&[(ix.d(i), -1.0), (ix.c(i), 1.0), (ix.c(i + 1), 1.0)], 0.0);
            d.cone(Cone::Soc(3));
        }
        d
    }

    /// Solves the phase along `path` in unit time with the solver in `slot`.
    fn solve(&self, slot: &mut Option<ConicSolver>, cat: &Cat, path: &Path) -> Result<PhaseTiming> {
        let data = self.build(cat, path);
        let reused = slot.is_some();
        let (mut status, mut x, _) = solve_reusing_with(slot, &data, self.settings)?;
        if !status.ok() && reused {
            // a reused solver keeps the scaling of the program it was set up
            // for: after a bend far from this one (a tenth of a degree, whose
            // peak is a million times the optimum's) that scaling failed
            // the bends after it; a solver set up for this program
            *slot = None;
            (status, x, _) = solve_reusing_with(slot, &data, self.settings)?;
        }
        if !status.ok() {
            // (nor is a failed program's scaling one to keep)
            *slot = None;
            return Err(Error::Solver {
                what: format!("path-timing SOCP ({} intervals)", self.k),
                status: format!("{status:?}"),
                hint: "try a different phased.nodes or bend range (phased.bend_min_deg / bend_max_deg)".into(),
            });
        }
        let ix = Index { k: self.k };
        let s: Vec<f64> = (0..=self.k).map(|i| i as f64 / self.k as f64).collect();
        let beta: Vec<f64> = (0..=self.k).map(|i| x[ix.beta(i)].max(0.0)).collect();
        let a: Vec<f64> = (0..=self.k).map(|i| x[ix.a(i)]).collect();
        let mut beta_fixed = beta;
        beta_fixed[0] = 0.0;
        beta_fixed[self.k] = 0.0;
        let timing = GridTiming::new(s, beta_fixed, a);
        // (a, beta) were scaled by T0^2 to reach unit time; torque is linear in them
        let socp_peak = x[ix.t()];
        Ok(PhaseTiming {
            unit_peak: socp_peak * timing.raw_time.powi(2),
            socp_peak,
            timing,
            status,
        })
    }
}
