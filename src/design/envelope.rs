//! Phased designs inside the motor envelope, for every objective.
//!
//! Once the motors have a speed limit or a torque-speed line, time scaling
//! (F3) no longer separates the phases: a phase cannot simply be sped up. So
//! the three rest-to-rest phases of one bend go into ONE second-order cone
//! program in the path-timing variables of [`crate::design::timing`]
//! (`a = s_ddot` piecewise linear, `beta = s_dot^2`), sharing the time budget
//! (peak and energy objectives) or minimising the total time (`time`).
//!
//! What is exact and what is approximated (all at the grid points and the
//! interval midpoints):
//! - torque `tau = m a + c beta` is linear; a torque bound is exact (per motor:
//!   linear rows; Euclidean: a cone);
//! - a speed limit `|q'| sqrt(beta) <= w` is `beta <= w^2 / |q'|^2`: linear, exact;
//! - the torque-speed line `|tau + k q' sqrt(beta)| <= T` (`k = T / w0`,
//!   `q' sqrt(beta)` the joint speed) is NOT convex in `beta`: `sqrt` is
//!   concave. This is the ONLY approximation of the line, and it is made at
//!   the grid points and midpoints only. Per motor `i`, each side
//!   `sigma = +-1` is one row `sigma tau_i + g sqrt(beta) <= T` with
//!   `g = sigma k q'_i`:
//!   - `g <= 0` (braking side: the speed gives the motor torque back):
//!     `sqrt(beta)` is replaced by the SOC variable `c <= sqrt(beta)` (the
//!     time model's own); since `g c >= g sqrt(beta)` the row is at least as
//!     tight as the line: conservative, with gap `|g| (sqrt(beta) - c)`.
//!   - `g > 0` (motoring side: the speed eats the torque): `sqrt(beta)` is
//!     replaced by its tangent at a point `beta0`,
//!     `L(beta) = (beta + beta0) / (2 sqrt(beta0)) >= sqrt(beta)`:
//!     conservative, with gap `g (sqrt(beta) - sqrt(beta0))^2 / (2 sqrt(beta0))`,
//!     zero at `beta = beta0`. At the rest ends (`beta = 0`) the term is
//!     dropped: exact.
//!
//!   So every program's solution is inside the true line at its points. The
//!   first tangent is at the no-load speed (`beta0 = (w0 / |q'|)^2`, where the
//!   line matters; at rest it still leaves `T / 2`); then `beta0` is set to
//!   the last solution and the program solved again (a convex-concave
//!   procedure): each solution is feasible for the next program, so the
//!   objective never increases, and at the fixed point the tangent gap is
//!   zero at the solution's own speeds. It stops when the objective moves by
//!   less than [`EnvelopeProblem::tangent_tol`] (1e-5; 1e-3 while searching
//!   the bend). If the first program is infeasible for a tight budget, the
//!   tangent starts at the `time` design's speeds instead (which fits any
//!   budget at least as long). The tests check the bound and the fixed point.
//!   For the Euclidean disc the tangent enters inside the norm (each
//!   component with its own sign), which is NOT a bound in general: there
//!   the line holds exactly only at the converged point, and the dense check
//!   below enforces it.
//! - Between the points the torque is second-order accurate; every written
//!   row is then checked, and if any leaves the envelope the limits are backed
//!   off by the excess and the design solved again.
//! - Energy `integral |tau|^2 / sqrt(beta) ds` is the trapezoid rule over the
//!   grid points and midpoints with `|tau|^2 <= e c` (a rotated cone) and
//!   `c <= sqrt(beta)`, the two rest-end half intervals (where the integrand
//!   is singular) in closed form from rest at constant acceleration; time is the
//!   timing SOC model's `sum 2 ds / (c_k + c_{k+1})`.
//!
//! Units: the program is solved in a time unit `ts` (the fall time or an
//! estimate from the limits) and the torque unit `nu` (the stall torque for
//! a least-time design; for a peak or energy design a typical inertial
//! torque in the fall, when that is smaller), so its data are of order one
//! whatever the size of the cat and the length of the fall; each bend gets
//! a fresh Clarabel solver so that its equilibration matches the bend's data.

use crate::design::bend_search::{BendEvaluation, BendHint, bend_range, bend_scan};
use crate::design::bend_search::{Scored, bracket_then_brent, scan_then_brent};
use crate::design::conic::{Cone, ConicData, ConicSolver, SolveStatus, solve_reusing};
use crate::design::objective::Objective;
use crate::design::path::{GridTiming, Path, PhasedPlan, Timing};
use crate::design::plan::{Schedule, ShapePlan};
use crate::design::spec::DesignSpec;
use crate::design::timing::path_coefficients;
use crate::design::twist::twist_for;
use crate::error::{Error, Result};
use crate::model::motor::{Motor, MotorUse};
use crate::model::{Cat, TorqueNorm};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::Instant;

/// Work done by the envelope programs of this process (all threads), for
/// benchmarks: [`work`] reads it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    /// Conic programs solved.
    pub socps: usize,
    /// Clarabel interior-point iterations, summed.
    pub iterations: usize,
    /// Wall time inside Clarabel (setup and solves), s.
    pub solver_s: f64,
}

static SOCPS: AtomicUsize = AtomicUsize::new(0);
static IPM_ITERATIONS: AtomicUsize = AtomicUsize::new(0);
static SOLVER_NS: AtomicU64 = AtomicU64::new(0);

/// The work counted so far; subtract two readings to time one design.
pub fn work() -> Work {
    Work {
        socps: SOCPS.load(Ordering::Relaxed),
        iterations: IPM_ITERATIONS.load(Ordering::Relaxed),
        solver_s: SOLVER_NS.load(Ordering::Relaxed) as f64 * 1e-9,
    }
}

impl std::ops::Sub for Work {
    type Output = Work;
    fn sub(self, o: Work) -> Work {
        Work {
            socps: self.socps - o.socps,
            iterations: self.iterations - o.iterations,
            solver_s: self.solver_s - o.solver_s,
        }
    }
}

/// [`solve_reusing`], counted in [`work`].
fn counted_solve(
    slot: &mut Option<ConicSolver>,
    data: &ConicData,
) -> Result<(SolveStatus, Vec<f64>, f64)> {
    let t = Instant::now();
    let out = solve_reusing(slot, data)?;
    SOLVER_NS.fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
    SOCPS.fetch_add(1, Ordering::Relaxed);
    let it = slot.as_ref().map_or(0, |s| s.iterations() as usize);
    IPM_ITERATIONS.fetch_add(it, Ordering::Relaxed);
    Ok(out)
}

/// A linear expression: `(column, coefficient)` pairs.
type Expr = Vec<(usize, f64)>;

/// The three-phase timing program of one bend.
pub struct EnvelopeProblem {
    /// Grid intervals per phase.
    pub k: usize,
    pub motor: Motor,
    pub objective: Objective,
    /// Manoeuvre time available, s (`None` for the `time` objective).
    pub budget: Option<f64>,
    /// The tangent iteration stops when the objective moves by less than
    /// this, relative (default 1e-5; a bend search can rank bends with 1e-3).
    pub tangent_tol: f64,
    solver: Option<ConicSolver>,
}

/// Path data at one point of one phase: `m = M q'`, `c = M q'' + Gamma(q', q')`, `q'`.
#[derive(Debug, Clone, Copy)]
struct PointData {
    m: [f64; 2],
    c: [f64; 2],
    dq: [f64; 2],
}

/// The outcome at one bend.
#[derive(Debug, Clone)]
pub struct EnvelopeDesign {
    pub bend: f64,
    pub twist: f64,
    pub timings: Option<[GridTiming; 3]>,
    /// Phase durations, s.
    pub durations: [f64; 3],
    /// The program's objective value in physical units (see [`Objective::unit`]);
    /// infinite when no timing fits the envelope at this bend.
    pub value: f64,
    pub status: SolveStatus,
    /// Tangent updates of the torque-speed line.
    pub iterations: usize,
    /// `s_dot^2` at every point of each phase, 1/s^2 (a tangent point for
    /// another program on the same paths).
    point_betas: Option<[Vec<f64>; 3]>,
}

impl Scored for EnvelopeDesign {
    fn score(&self) -> f64 {
        self.value
    }
}

impl EnvelopeDesign {
    pub fn plan(&self) -> Option<PhasedPlan> {
        let t = self.timings.as_ref()?;
        Some(PhasedPlan {
            paths: Path::phased(self.bend, self.twist),
            timings: t.clone().map(Timing::Grid),
            durations: self.durations,
        })
    }
}

/// Column layout of the program.
struct Cols {
    k: usize,
    per: usize,
    energy: bool,
}

impl Cols {
    fn new(k: usize, objective: Objective) -> Self {
        let energy = objective == Objective::Energy;
        let per = (k + 1) * 2 + (2 * k + 1) + k + if energy { 2 * k + 1 } else { 0 };
        Self { k, per, energy }
    }
    fn beta(&self, p: usize, i: usize) -> usize {
        p * self.per + i
    }
    fn a(&self, p: usize, i: usize) -> usize {
        p * self.per + self.k + 1 + i
    }
    /// `c <= sqrt(beta)` at point `j` (grid point `j/2` or a midpoint).
    fn c(&self, p: usize, j: usize) -> usize {
        p * self.per + 2 * self.k + 2 + j
    }
    fn d(&self, p: usize, i: usize) -> usize {
        p * self.per + 4 * self.k + 3 + i
    }
    /// `e >= |tau|^2 / sqrt(beta)` at point `j`.
    fn e(&self, p: usize, j: usize) -> usize {
        debug_assert!(self.energy);
        p * self.per + 5 * self.k + 3 + j
    }
    /// The peak variable (peak objective only).
    fn t(&self) -> usize {
        3 * self.per
    }
    fn n(&self, objective: Objective) -> usize {
        3 * self.per + usize::from(objective == Objective::PeakTorque)
    }
    fn points(&self) -> usize {
        2 * self.k + 1
    }
    fn ds(&self) -> f64 {
        1.0 / self.k as f64
    }
    /// `beta` at point `j`: exact for the piecewise-quadratic `beta`.
    fn beta_at(&self, p: usize, j: usize) -> Expr {
        let i = j / 2;
        if j.is_multiple_of(2) {
            vec![(self.beta(p, i), 1.0)]
        } else {
            let ds = self.ds();
            vec![
                (self.beta(p, i), 1.0),
                (self.a(p, i), 0.75 * ds),
                (self.a(p, i + 1), 0.25 * ds),
            ]
        }
    }
    fn a_at(&self, p: usize, j: usize) -> Expr {
        let i = j / 2;
        if j.is_multiple_of(2) {
            vec![(self.a(p, i), 1.0)]
        } else {
            vec![(self.a(p, i), 0.5), (self.a(p, i + 1), 0.5)]
        }
    }
}

fn scaled(e: &Expr, s: f64) -> Expr {
    e.iter().map(|&(c, v)| (c, v * s)).collect()
}

fn plus(mut a: Expr, b: Expr) -> Expr {
    a.extend(b);
    a
}

/// `(beta, a)` of one phase at its grid points, from a solution vector.
fn grid_values(cols: &Cols, x: &[f64], p: usize) -> (Vec<f64>, Vec<f64>) {
    let beta = (0..=cols.k).map(|i| x[cols.beta(p, i)].max(0.0)).collect();
    let a = (0..=cols.k).map(|i| x[cols.a(p, i)]).collect();
    (beta, a)
}

/// `beta` at every point of one phase from a solution vector.
fn point_betas(cols: &Cols, x: &[f64], p: usize) -> Vec<f64> {
    (0..cols.points())
        .map(|j| {
            cols.beta_at(p, j)
                .iter()
                .map(|&(c, v)| v * x[c])
                .sum::<f64>()
                .max(0.0)
        })
        .collect()
}

/// Limits and units of one build.
#[derive(Debug, Clone, Copy)]
struct Scaled {
    /// Stall torque in torque units.
    torque: Option<f64>,
    /// Speed limit in 1/ts.
    speed: Option<f64>,
    /// Torque-speed slope in torque units per (1/ts).
    slope: f64,
    /// Budget in ts.
    budget: Option<f64>,
}

/// Joint `comp`'s torque at point `j` of phase `p`, linear in the point's
/// `a` and `beta` (`tau = m a + c beta`).
fn torque_at(cols: &Cols, data: &[Vec<PointData>; 3], p: usize, j: usize, comp: usize) -> Expr {
    let pd = &data[p][j];
    plus(
        scaled(&cols.a_at(p, j), pd.m[comp]),
        scaled(&cols.beta_at(p, j), pd.c[comp]),
    )
}

impl EnvelopeProblem {
    pub fn new(k: usize, motor: Motor, objective: Objective, budget: Option<f64>) -> Self {
        Self {
            k,
            motor,
            objective,
            budget,
            tangent_tol: 1e-5,
            solver: None,
        }
    }

    /// The SOCP of one linearisation: the objective, the path's kinematics,
    /// the limit rows and the cones, in that order (the row order is part of
    /// the problem Clarabel sees).
    fn build(&self, data: &[Vec<PointData>; 3], lim: &Scaled, beta0: &[Vec<f64>; 3]) -> ConicData {
        let cols = Cols::new(self.k, self.objective);
        let mut d = ConicData::new(cols.n(self.objective));
        self.objective_costs(&cols, &mut d);
        self.rest_to_rest(&cols, &mut d);
        self.limit_rows(&cols, data, lim, beta0, &mut d);
        self.cones(&cols, data, lim, beta0, &mut d);
        d
    }

    /// The objective's costs: the peak's bound, the durations, or the
    /// energy's quadrature weights.
    fn objective_costs(&self, cols: &Cols, d: &mut ConicData) {
        let (k, ds, np) = (self.k, cols.ds(), cols.points());
        match self.objective {
            Objective::PeakTorque => d.q[cols.t()] = 1.0,
            Objective::Time => {
                for p in 0..3 {
                    for i in 0..k {
                        d.q[cols.d(p, i)] = 2.0 * ds;
                    }
                }
            }
            Objective::Energy => {
                // trapezoid on the half grid between the first and last
                // midpoints; each rest-end half interval (where the integrand
                // has a 1/sqrt(s) singularity) from rest at constant
                // acceleration: it lasts ds / c_1, so its energy is
                // ds |tau_0|^2 / c_1
                for p in 0..3 {
                    for j in 0..np {
                        d.q[cols.e(p, j)] = if j == 0 || j == np - 1 {
                            ds
                        } else if j == 1 || j == np - 2 {
                            ds / 4.0
                        } else {
                            ds / 2.0
                        };
                    }
                }
            }
        }
    }

    /// Rest to rest, `beta' = 2 a` (the zero cone).
    fn rest_to_rest(&self, cols: &Cols, d: &mut ConicData) {
        let (k, ds) = (self.k, cols.ds());
        for p in 0..3 {
            d.row(&[(cols.beta(p, 0), 1.0)], 0.0);
            d.row(&[(cols.beta(p, k), 1.0)], 0.0);
            for i in 0..k {
                d.row(
                    &[
                        (cols.beta(p, i + 1), 1.0),
                        (cols.beta(p, i), -1.0),
                        (cols.a(p, i), -ds),
                        (cols.a(p, i + 1), -ds),
                    ],
                    0.0,
                );
            }
        }
        d.cone(Cone::Zero(3 * (k + 2)));
    }

    /// The linear inequalities (one nonnegative cone): the time budget,
    /// the speed limit, and per motor the peak's bound and the
    /// torque-speed line (its speed term linearised at `beta0`).
    fn limit_rows(
        &self,
        cols: &Cols,
        data: &[Vec<PointData>; 3],
        lim: &Scaled,
        beta0: &[Vec<f64>; 3],
        d: &mut ConicData,
    ) {
        let (k, ds, np) = (self.k, cols.ds(), cols.points());
        let mut rows = 0;
        if let Some(b) = lim.budget {
            let row: Expr = (0..3)
                .flat_map(|p| (0..k).map(move |i| (p, i)))
                .map(|(p, i)| (cols.d(p, i), 2.0 * ds))
                .collect();
            d.row(&row, b);
            rows += 1;
        }
        let per_motor = self.motor.norm == TorqueNorm::PerMotor;
        for p in 0..3 {
            for j in 0..np {
                let pd = &data[p][j];
                let rest = j == 0 || j == np - 1;
                if let Some(w) = lim.speed {
                    // |q'| sqrt(beta) <= w, with |q'| in the motor norm
                    let g = self.motor.norm.of(pd.dq);
                    if g > 1e-9 {
                        d.row(&cols.beta_at(p, j), (w / g).powi(2));
                    } else {
                        d.row(&scaled(&cols.beta_at(p, j), 0.0), 1.0);
                    }
                    rows += 1;
                }
                if !per_motor {
                    continue;
                }
                for comp in 0..2 {
                    let tau = torque_at(cols, data, p, j, comp);
                    for sign in [1.0, -1.0] {
                        let mut row = scaled(&tau, sign);
                        let mut rhs = 0.0;
                        if self.objective == Objective::PeakTorque {
                            row.push((cols.t(), -1.0));
                            d.row(&row, 0.0);
                            rows += 1;
                            row = scaled(&tau, sign);
                        }
                        let Some(t) = lim.torque else { continue };
                        // sign * (tau + k q' sqrt(beta)) <= T
                        let g = sign * lim.slope * pd.dq[comp];
                        let (cc, bb) = if g <= 0.0 {
                            (g, 0.0)
                        } else if rest {
                            // at rest the speed term is exactly zero (and a
                            // tangent at beta0 ~ 0 would be ill-conditioned)
                            (0.0, 0.0)
                        } else {
                            let b = beta0[p][j].max(1e-8);
                            rhs = -g * b.sqrt() / 2.0;
                            (0.0, g / (2.0 * b.sqrt()))
                        };
                        row.push((cols.c(p, j), cc));
                        row.extend(scaled(&cols.beta_at(p, j), bb));
                        d.row(&row, t + rhs);
                        rows += 1;
                    }
                }
            }
        }
        d.cone(Cone::Nonneg(rows));
    }

    /// The second-order cones: in the Euclidean norm the peak's bound and
    /// the torque-speed line, then `c <= sqrt(beta)`, the durations, and the
    /// energy's `|tau|^2 <= e c`.
    fn cones(
        &self,
        cols: &Cols,
        data: &[Vec<PointData>; 3],
        lim: &Scaled,
        beta0: &[Vec<f64>; 3],
        d: &mut ConicData,
    ) {
        let (k, np) = (self.k, cols.points());
        let per_motor = self.motor.norm == TorqueNorm::PerMotor;
        for p in 0..3 {
            for j in 0..np {
                let pd = &data[p][j];
                if !per_motor {
                    let tau = [
                        torque_at(cols, data, p, j, 0),
                        torque_at(cols, data, p, j, 1),
                    ];
                    if self.objective == Objective::PeakTorque {
                        d.row(&[(cols.t(), -1.0)], 0.0);
                        for t in &tau {
                            d.row(&scaled(t, -1.0), 0.0);
                        }
                        d.cone(Cone::Soc(3));
                    }
                    if let Some(t) = lim.torque {
                        // |tau + k q' L(beta)| <= T with L the tangent of sqrt
                        d.row(&[], t);
                        for comp in 0..2 {
                            let g = lim.slope * pd.dq[comp];
                            let b = beta0[p][j].max(1e-8);
                            let (bb, rhs) = if j == 0 || j == np - 1 {
                                (0.0, 0.0)
                            } else {
                                (g / (2.0 * b.sqrt()), g * b.sqrt() / 2.0)
                            };
                            let row =
                                plus(scaled(&tau[comp], -1.0), scaled(&cols.beta_at(p, j), -bb));
                            d.row(&row, rhs);
                        }
                        d.cone(Cone::Soc(3));
                    }
                }
                // c <= sqrt(beta): ||(2 c, beta - 1)|| <= beta + 1
                let b = cols.beta_at(p, j);
                d.row(&scaled(&b, -1.0), 1.0);
                d.row(&[(cols.c(p, j), -2.0)], 0.0);
                d.row(&scaled(&b, -1.0), -1.0);
                d.cone(Cone::Soc(3));
            }
            // d_i (c_i + c_{i+1}) >= 1 on the grid points: ||(2, d - u)|| <= d + u
            for i in 0..k {
                let (c0, c1, dd) = (cols.c(p, 2 * i), cols.c(p, 2 * i + 2), cols.d(p, i));
                d.row(&[(dd, -1.0), (c0, -1.0), (c1, -1.0)], 0.0);
                d.row(&[], 2.0);
                d.row(&[(dd, -1.0), (c0, 1.0), (c1, 1.0)], 0.0);
                d.cone(Cone::Soc(3));
            }
            if cols.energy {
                // |tau|^2 <= e c: ||(2 tau, e - c)|| <= e + c; the rest ends use
                // their neighbour's c (see the objective)
                for j in 0..np {
                    let jc = j.clamp(1, np - 2);
                    let (e, c) = (cols.e(p, j), cols.c(p, jc));
                    d.row(&[(e, -1.0), (c, -1.0)], 0.0);
                    for comp in 0..2 {
                        d.row(&scaled(&torque_at(cols, data, p, j, comp), -2.0), 0.0);
                    }
                    d.row(&[(e, -1.0), (c, 1.0)], 0.0);
                    d.cone(Cone::Soc(4));
                }
            }
        }
    }

    /// Designs the timing of the three paths of a bend; `shrink` (<= 1)
    /// tightens the torque and speed limits (the back-off of the dense check).
    pub fn solve(
        &mut self,
        cat: &Cat,
        bend: f64,
        twist: f64,
        shrink: f64,
    ) -> Result<EnvelopeDesign> {
        // a new bend has new units and data ranges: a fresh solver
        // equilibrates them (a reused one keeps the first bend's scaling,
        // which at the extreme bends of a scan made Clarabel fail)
        self.solver = None;
        let first = self.solve_from(cat, bend, twist, shrink, None)?;
        if first.timings.is_some() || self.budget.is_none() || self.motor.slope() == 0.0 {
            return Ok(first);
        }
        // The first tangent (at the no-load speed) can be too conservative
        // for a tight budget: start from the shortest manoeuvre instead,
        // which fits any budget at least as long as itself.
        let mut timed = EnvelopeProblem::new(self.k, self.motor, Objective::Time, None);
        timed.tangent_tol = self.tangent_tol;
        let fastest = timed.solve_from(cat, bend, twist, shrink, None)?;
        match fastest.point_betas {
            Some(b) if fastest.value <= self.budget.unwrap_or(0.0) => {
                self.solve_from(cat, bend, twist, shrink, Some(b))
            }
            _ => Ok(first),
        }
    }

    /// [`Self::solve`] from a given first tangent point (`s_dot^2` at every
    /// point, 1/s^2), or from the no-load speed.
    fn solve_from(
        &mut self,
        cat: &Cat,
        bend: f64,
        twist: f64,
        shrink: f64,
        start: Option<[Vec<f64>; 3]>,
    ) -> Result<EnvelopeDesign> {
        let paths = Path::phased(bend, twist);
        let cols = Cols::new(self.k, self.objective);
        let m0 = cat.straight_inertia();
        // Units (the program's conditioning depends on them: with data of
        // order one Clarabel needs about a third of the iterations). Time
        // unit: the budget, or the time to sweep the path at the speed limit
        // (the no-load speed counts as one) or torque limit, whichever is
        // slower.
        let ts = self.budget.unwrap_or_else(|| {
            let len = bend * (2.0 + twist.abs());
            let fastest = match (self.motor.max_speed, self.motor.no_load_speed) {
                (Some(w), Some(w0)) => Some(w.min(w0)),
                (w, w0) => w.or(w0),
            };
            let by_speed = fastest.map_or(0.0, |w| len / w);
            let by_torque = self.motor.max_torque.map_or(0.0, |t| (m0 * len / t).sqrt());
            by_speed.max(by_torque).max(1e-6)
        });
        // path data per unit `M(0)`
        let mut data: [Vec<PointData>; 3] = paths.each_ref().map(|path| {
            (0..cols.points())
                .map(|j| {
                    let s = j as f64 * cols.ds() / 2.0;
                    let (m, c) = path_coefficients(cat, path, s);
                    PointData {
                        m: m.map(|x| x / m0),
                        c: c.map(|x| x / m0),
                        dq: path.eval(s)[1],
                    }
                })
                .collect()
        });
        // torque unit `nu`: a typical inertial torque of a path point at a
        // typical phase's acceleration (36 / ts^2: a third of `ts`,
        // bang-bang in `s`), the scale of a peak or energy design's torques;
        // the stall torque when that is smaller (the bound the design lives
        // with) and for a least-time design, which rides the limits. In a
        // long fall the torques a budget needs are thousands of times below
        // the stall torque: in its units Clarabel's tolerances blurred the
        // objective and the bend search went astray (docs/benchmarks.md).
        let inertial = || {
            let mut ms: Vec<f64> = data
                .iter()
                .flatten()
                .map(|p| self.motor.norm.of(p.m))
                .collect();
            ms.sort_by(f64::total_cmp);
            (36.0 * m0 * ms[ms.len() / 2] / (ts * ts)).max(1e-300)
        };
        let nu = match (self.motor.max_torque, self.budget) {
            (Some(t), Some(_)) => t.min(inertial()),
            (Some(t), None) => t,
            (None, _) => inertial(),
        };
        let per_unit = m0 / (nu * ts * ts);
        for p in data.iter_mut().flatten() {
            p.m = p.m.map(|x| x * per_unit);
            p.c = p.c.map(|x| x * per_unit);
        }
        let lim = Scaled {
            torque: self.motor.max_torque.map(|t| shrink * t / nu),
            speed: self.motor.max_speed.map(|w| shrink * w * ts),
            slope: self.motor.slope() / (ts * nu),
            budget: self.budget.map(|b| b / ts),
        };
        self.objective
            .check_bounded(lim.torque.is_some() || lim.speed.is_some())?;
        let tangents = lim.torque.is_some() && lim.slope > 0.0;
        // first tangent of sqrt(beta) where the path runs at the no-load
        // speed: beyond it a motor can only brake, so this is where the line
        // matters, and the first program is already conservative
        let no_load = lim.torque.unwrap_or(0.0) / lim.slope.max(1e-300);
        let mut beta0: [Vec<f64>; 3] = match start {
            Some(b) => b.map(|v| v.iter().map(|x| x * ts * ts).collect()),
            None => data.each_ref().map(|pts| {
                pts.iter()
                    .map(|pd| {
                        (no_load / self.motor.norm.of(pd.dq).max(1e-9))
                            .powi(2)
                            .min(1e12)
                    })
                    .collect()
            }),
        };
        let mut out: Option<(SolveStatus, Vec<f64>, f64)> = None;
        let mut iterations = 0;
        for it in 0..40 {
            let prob = self.build(&data, &lim, &beta0);
            let (status, x, obj) = counted_solve(&mut self.solver, &prob)?;
            iterations = it;
            if !status.ok() {
                if out.is_none() {
                    return Ok(EnvelopeDesign {
                        bend,
                        twist,
                        timings: None,
                        durations: [f64::NAN; 3],
                        value: f64::INFINITY,
                        status,
                        iterations,
                        point_betas: None,
                    });
                }
                break;
            }
            let prev = out.as_ref().map_or(f64::INFINITY, |o| o.2);
            out = Some((status, x, obj));
            if !tangents || (prev - obj).abs() <= self.tangent_tol * obj.abs() {
                break;
            }
            let x = &out.as_ref().unwrap().1;
            beta0 = [0, 1, 2].map(|p| point_betas(&cols, x, p));
        }
        let (status, x, obj) = out.expect("a solved iterate");
        let timings = [0, 1, 2].map(|p| {
            let (beta, a) = grid_values(&cols, &x, p);
            let s = (0..=cols.k).map(|i| i as f64 * cols.ds()).collect();
            let mut beta = beta;
            beta[0] = 0.0;
            beta[cols.k] = 0.0;
            GridTiming::new(s, beta, a)
        });
        let durations = timings.each_ref().map(|g| g.raw_time * ts);
        let value = match self.objective {
            Objective::PeakTorque => obj * nu,
            Objective::Time => durations.iter().sum(),
            Objective::Energy => obj * nu * nu * ts,
        };
        let point_betas = [0, 1, 2].map(|p| {
            point_betas(&cols, &x, p)
                .iter()
                .map(|b| b / (ts * ts))
                .collect()
        });
        Ok(EnvelopeDesign {
            bend,
            twist,
            timings: Some(timings),
            durations,
            value,
            status,
            iterations,
            point_betas: Some(point_betas),
        })
    }
}

/// Designs at one bend, the twist chosen to flip by pi.
pub fn design_at(
    cat: &Cat,
    problem: &mut EnvelopeProblem,
    bend: f64,
    shrink: f64,
) -> Result<EnvelopeDesign> {
    let twist = twist_for(cat, bend)?;
    problem.solve(cat, bend, twist, shrink)
}

/// Bend search for the best design inside the envelope over `[lo, hi]` rad.
pub fn search(
    cat: &Cat,
    problem: &mut EnvelopeProblem,
    scan: Vec<f64>,
    tol: f64,
    mut observe: impl FnMut(&EnvelopeDesign),
) -> Result<EnvelopeDesign> {
    scan_then_brent(scan, tol, |b| {
        let d = design_at(cat, problem, b, 1.0)?;
        observe(&d);
        Ok(d)
    })
}

/// The motor usage of a plan at the rows a schedule would carry.
pub fn usage_of(spec: &DesignSpec, plan: &dyn ShapePlan) -> MotorUse {
    let sched = Schedule::sample(&spec.cat, plan, spec.simulate.samples_per_phase);
    spec.motor.usage(sched.rows.iter().map(|r| (r.tau, r.qd)))
}

/// The smallest motor-envelope margin ([`crate::model::motor::Motor::margin`];
/// 1 without limits) of a plan slowed down by `k` (F3: torque as `1 / k^2`,
/// speed as `1 / k`), on the dense samples the verdict reads the peak from
/// (a multiple of the written rows: inside at the rows alone, the torque
/// between them can still be outside); sampled once for every `k`.
pub fn dense_margin(spec: &DesignSpec, plan: &dyn ShapePlan) -> impl Fn(f64) -> f64 + use<> {
    let dense = crate::verify::analyze::dense_samples(spec);
    let sched = Schedule::sample(&spec.cat, plan, dense);
    let motor = spec.motor;
    move |k: f64| {
        let k2 = k * k;
        motor
            .usage(
                sched
                    .rows
                    .iter()
                    .map(|r| (r.tau.map(|x| x / k2), r.qd.map(|x| x / k))),
            )
            .min_margin
            .unwrap_or(1.0)
    }
}

/// The least factor `k >= 1` by which a plan's durations must grow for
/// every row a schedule would carry (and the dense samples between them)
/// to be inside the motor envelope: the
/// same path slowed down (F3: torque falls as `1 / k^2`, speed as `1 / k`),
/// found by bisection on the rows themselves to a relative `1e-9` (1 when
/// they are inside already). The returned factor is always inside, and no
/// larger than it needs to be: a first guess from the margin alone
/// overshot the least time (measured: docs/benchmarks.md, "Design
/// settings: the measurements behind them").
pub fn least_stretch(spec: &DesignSpec, plan: &dyn ShapePlan) -> f64 {
    least_stretch_of(&dense_margin(spec, plan))
}

/// [`least_stretch`] from a plan's [`dense_margin`].
pub fn least_stretch_of(margin: &impl Fn(f64) -> f64) -> f64 {
    let first = margin(1.0);
    if first >= 0.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (1.0, 1.0 - 1.5 * first);
    while margin(hi) < 0.0 && hi < 1e6 {
        (lo, hi) = (hi, 2.0 * hi);
    }
    while hi - lo > 1e-9 * hi {
        let mid = 0.5 * (lo + hi);
        if margin(mid) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// `integral |tau|^2 dt` along a plan (trapezoid on `per_phase` samples a phase), N^2 m^2 s.
pub fn torque_squared_integral(cat: &Cat, plan: &dyn ShapePlan, per_phase: usize) -> f64 {
    Schedule::sample(cat, plan, per_phase).torque_squared_integral()
}

/// Least drop height for a manoeuvre of `time` seconds, m.
pub fn height_for(spec: &DesignSpec, time: f64) -> f64 {
    0.5 * spec.fall.gravity * (time + spec.fall.margin).powi(2)
}

/// How far (relative) the program's time model may be from the integrated
/// time before the budget is corrected and the program solved again. Within
/// it the plan is only rescaled to the fall time: that costs the objective at
/// second order in the mismatch where time scaling (F3) holds, and the
/// envelope is checked after; near the least time, where the objective is
/// steep in the budget, a looser tolerance cost the peak design noticeably
/// (measured: docs/benchmarks.md, "Design settings: the measurements
/// behind them").
const ON_TIME: f64 = 1e-3;

/// Solves at `bend` and makes the result exact where the program is not:
/// the budget it is given is corrected until the reconstructed (integrated)
/// time is within [`ON_TIME`] of the fall's (then rescaled to it), and the limits are backed off until every
/// schedule row is inside the envelope. `None` when nothing fits.
fn verified_design(
    spec: &DesignSpec,
    problem: &mut EnvelopeProblem,
    bend: f64,
) -> Result<Option<(EnvelopeDesign, PhasedPlan)>> {
    let cat = spec.cat;
    let budget = problem.budget;
    let mut shrink = 1.0;
    for _ in 0..12 {
        let d = design_at(&cat, problem, bend, shrink)?;
        let Some(mut plan) = d.plan() else {
            problem.budget = budget;
            return Ok(None);
        };
        let mut on_time = true;
        if let (Some(want), Some(given)) = (budget, problem.budget) {
            let total: f64 = plan.durations.iter().sum();
            let ratio = want / total;
            on_time = (ratio - 1.0).abs() < ON_TIME;
            problem.budget = Some(given * ratio);
            plan.durations = plan.durations.map(|x| x * ratio);
        }
        let margin = usage_of(spec, &plan).min_margin.unwrap_or(1.0);
        if margin < -1e-7 {
            shrink *= 1.0 + 1.2 * margin;
        } else if on_time {
            problem.budget = budget;
            return Ok(Some((d, plan)));
        }
    }
    problem.budget = budget;
    Ok(None)
}

/// The tangent iteration's tolerance in the bend search: the search only
/// ranks bends (a tangent update after the second moves the objective by
/// about 1e-4 relative), the final design iterates to 1e-5.
const COARSE_TANGENT_TOL: f64 = 1e-3;

/// A phased design inside the motor envelope: the chosen bend's verified
/// design and plan (the phased optimiser reconstructs it; the pipeline flies it).
#[derive(Debug, Clone)]
pub struct EnvelopeResult {
    pub status: SolveStatus,
    pub objective: Objective,
    pub bend: f64,
    pub twist: f64,
    /// The verified plan, on time for the fall.
    pub plan: PhasedPlan,
    pub evaluations: Vec<BendEvaluation>,
    pub solve_time_s: f64,
}

/// The phased optimiser inside the motor envelope, for `design.objective`.
pub fn optimize(spec: &DesignSpec, observe: impl FnMut(&BendEvaluation)) -> Result<EnvelopeResult> {
    optimize_near(spec, None, observe)
}

/// [`optimize`] with the bend search started at a neighbour's bend (a
/// sweep's continuation, see [`bracket_then_brent`]); the whole scan when
/// no bend near it fits.
pub fn optimize_near(
    spec: &DesignSpec,
    hint: Option<BendHint>,
    mut observe: impl FnMut(&BendEvaluation),
) -> Result<EnvelopeResult> {
    let start = Instant::now();
    let cat = spec.cat;
    let objective = spec.objective;
    let budget = (objective != Objective::Time).then(|| spec.available_time());
    let (lo, hi) = bend_range(spec)?;
    let mut evals = Vec::new();
    // the bend is searched on a half-resolution grid (the optimum moves at
    // second order with the grid), the final design at full resolution
    let mut coarse = EnvelopeProblem::new(
        (spec.phased.nodes / 2).max(8),
        spec.motor,
        objective,
        budget,
    );
    coarse.tangent_tol = COARSE_TANGENT_TOL;
    let mut problem = EnvelopeProblem::new(spec.phased.nodes, spec.motor, objective, budget);
    let mut record = |d: &EnvelopeDesign| {
        let e = BendEvaluation {
            bend_deg: d.bend.to_degrees(),
            value: d.value,
            unit_peak: None,
            peak_nm: (objective == Objective::PeakTorque).then_some(d.value),
        };
        observe(&e);
        evals.push(e);
    };
    let scan = bend_scan(spec, lo, hi);
    let spacing = (hi - lo) / (scan.len().max(2) - 1) as f64;
    let tol = spec.phased.bend_tol_deg.to_radians();
    let near = match hint {
        Some(h) => bracket_then_brent(h.bend, h.step, (lo, hi), tol, |b| {
            let d = design_at(&cat, &mut coarse, b, 1.0)?;
            record(&d);
            Ok(d)
        })?
        .filter(|d| d.value.is_finite()),
        None => None,
    };
    let mut best = match near {
        Some(d) => d,
        None => search(&cat, &mut coarse, scan, tol, &mut record)?,
    };
    let mut fastest_bend = None;
    if !best.value.is_finite() && budget.is_some() {
        // a budget close to the least time leaves a narrow band of feasible
        // bends that the scan can miss: look around the time-optimal bend
        let mut timed = EnvelopeProblem::new(coarse.k, spec.motor, Objective::Time, None);
        timed.tangent_tol = COARSE_TANGENT_TOL;
        let fastest = search(&cat, &mut timed, bend_scan(spec, lo, hi), tol, |_| {})?;
        fastest_bend = fastest.value.is_finite().then_some(fastest.bend);
        let around: Vec<f64> = (-3..=3)
            .map(|i| (fastest.bend + spacing * i as f64 / 6.0).clamp(lo, hi))
            .collect();
        best = search(&cat, &mut coarse, around, tol, &mut record)?;
    }
    let mut found = if best.value.is_finite() {
        verified_design(spec, &mut problem, best.bend)?
    } else {
        None
    };
    if found.is_none()
        && let Some(bend) = fastest_bend
    {
        // the time design's bend, on the fine grid: its schedule slowed to
        // this fall stays inside the envelope (F3: the torque falls as k^2,
        // the speed as k, and the line allows more at a lower speed), so
        // the phased design fits wherever the least height it names does
        // (the coarse band of feasible bends around it can be narrower than
        // the look around: a user's robot from 25 m failed, naming 24.5 m)
        found = verified_design(spec, &mut problem, bend)?;
    }
    let Some((design, plan)) = found else {
        return Err(unreachable_here(spec, fastest_bend));
    };
    Ok(EnvelopeResult {
        status: design.status,
        objective,
        bend: design.bend,
        twist: design.twist,
        plan,
        evaluations: evals,
        solve_time_s: start.elapsed().as_secs_f64(),
    })
}

/// The error when nothing fits the envelope in the fall: it names the least
/// drop height (the `time` design) when that can be found.
///
/// `fastest_bend`: the `time` design's bend when the search already found it
/// (the same search `optimize` would run for `time`, so only its verified
/// design at that bend is left to do).
fn unreachable_here(spec: &DesignSpec, fastest_bend: Option<f64>) -> Error {
    let timed = spec.with_objective(Objective::Time);
    let least_time = if spec.objective == Objective::Time {
        None
    } else if let Some(bend) = fastest_bend {
        let mut problem =
            EnvelopeProblem::new(spec.phased.nodes, spec.motor, Objective::Time, None);
        verified_design(&timed, &mut problem, bend)
            .ok()
            .flatten()
            .map(|(_, plan)| plan.durations.iter().sum::<f64>())
    } else {
        optimize(&timed, |_| {})
            .ok()
            .map(|r| r.plan.durations.iter().sum::<f64>())
    };
    let least = least_time.map(|t| height_for(spec, t));
    match least {
        Some(h) => Error::BeyondMotors {
            reason: format!(
                "no phased {} schedule fits the motor envelope ({}) in the {:.4} s the fall from {} m leaves for the manoeuvre; the phased design needs a drop of at least {h:.3} m (fall.height) or stronger or faster motors; `catflip run` also tries the free-form design, which may need less",
                spec.objective.name(),
                spec.envelope_keys(),
                spec.available_time(),
                spec.fall.height
            ),
        },
        // no height helps: the time design itself found no schedule
        None => Error::Unreachable {
            reason: "no phased schedule fits the motor envelope at any bend; widen phased.bend_min_deg / bend_max_deg or relax the limits".into(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest exact envelope margin (the true torque-speed line, no
    /// approximation) at every point of the program's grid.
    fn margin_at_points(cat: &Cat, motor: &Motor, d: &EnvelopeDesign) -> f64 {
        let paths = Path::phased(d.bend, d.twist);
        let (timings, betas) = (d.timings.as_ref().unwrap(), d.point_betas.as_ref().unwrap());
        let mut worst = f64::INFINITY;
        for p in 0..3 {
            let g = &timings[p];
            let dur2 = d.durations[p].powi(2);
            let np = betas[p].len();
            for (j, &beta) in betas[p].iter().enumerate() {
                let s = j as f64 / (np - 1) as f64;
                let a = if j % 2 == 0 {
                    g.a[j / 2]
                } else {
                    0.5 * (g.a[j / 2] + g.a[j / 2 + 1])
                } / dur2;
                let (m, c) = path_coefficients(cat, &paths[p], s);
                let tau = [0, 1].map(|i| m[i] * a + c[i] * beta);
                let dq = paths[p].eval(s)[1];
                let qd = dq.map(|x| x * beta.sqrt());
                worst = worst.min(motor.margin(tau, qd).unwrap());
            }
        }
        worst
    }

    #[test]
    fn tangent_iteration_is_conservative_and_closes_the_gap_to_the_line() {
        // the robot's servo line, per motor: the time-optimal program must
        // stay inside the true line at its points at every tangent iterate,
        // improve from the first to the converged one, and end on the line
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/configs/robot-universal.toml"
        ))
        .unwrap();
        let spec = crate::test_support::spec_of(&text, "robot-universal.toml", &[]);
        let (cat, motor) = (spec.cat, spec.motor);
        assert!(motor.slope() > 0.0 && motor.norm == TorqueNorm::PerMotor);
        let bend = 0.7;
        let twist = twist_for(&cat, bend).unwrap();
        let solve = |tol: f64| {
            let mut p = EnvelopeProblem::new(20, motor, Objective::Time, None);
            p.tangent_tol = tol;
            p.solve(&cat, bend, twist, 1.0).unwrap()
        };
        // an infinite tolerance stops after the first program (tangent at
        // the no-load speed)
        let (first, converged) = (solve(f64::INFINITY), solve(1e-7));
        assert_eq!(first.iterations, 0);
        assert!(converged.iterations >= 2, "{}", converged.iterations);
        let (m_first, m_conv) = (
            margin_at_points(&cat, &motor, &first),
            margin_at_points(&cat, &motor, &converged),
        );
        // conservative: the approximated line never lets a point outside the true one
        assert!(m_first >= -1e-6 && m_conv >= -1e-6, "{m_first} {m_conv}");
        // the gap closes: every update improves on the first program, and
        // the converged timing is a fixed point (the tangent at its own
        // speeds touches the line there, so restarting from it moves nothing)
        assert!(
            converged.value < first.value * (1.0 - 1e-4),
            "converged {} s vs first {} s",
            converged.value,
            first.value
        );
        let mut again = EnvelopeProblem::new(20, motor, Objective::Time, None);
        again.tangent_tol = f64::INFINITY;
        let restart = again
            .solve_from(&cat, bend, twist, 1.0, converged.point_betas.clone())
            .unwrap();
        assert!(
            (restart.value - converged.value).abs() < 1e-5 * converged.value,
            "restart {} s vs converged {} s",
            restart.value,
            converged.value
        );
    }
}
