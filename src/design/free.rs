//! The free-form optimiser: multi-phase direct collocation of the shape with
//! successive convexification ([`crate::design::scp`]) on Clarabel.
//!
//! Decision variables: `q, dq/ds, d2q/ds2` at `N` nodes in each of the three
//! phases (normalised time `s`) and the three phase durations
//! ([`Transcription`], first-order-hold acceleration). Objective
//! (`design.objective`): the peak joint torque at the check points (each
//! node and the quarter points of each interval, [`CHECKS_PER_INTERVAL`]),
//! `tau = tau^(q, q^, q^^) / T_p^2` with `tau^` the exact inverse dynamics
//! in normalised time (F3); the manoeuvre time (sum of the
//! durations); or the energy `integral |tau|^2 dt` (Simpson weights). Exact
//! constraints (linear rows and cones of the subproblem): straight and at rest
//! at both ends, continuity of `q` across phases, the collocation defects
//! (linear), total time within the fall (not for `time`), each phase at least
//! a minimum, and the optional speed and bend limits. Nonlinear limit: the
//! torque (with the torque-speed line) at the check points. Penalised
//! equalities (virtual control): continuity of the physical rate across
//! phases (`q^_p / T_p = q^_{p+1} / T_{p+1}`) and the final-attitude error
//! `log(Rz(pi)' R_A(T))` (flip and tilt together, on SO(3)).
//!
//! The attitude map integrates `dR_A/ds = R_A hat(w^)`, `w^ = -A(q) q^`, along
//! the interpolant with the fourth-order Magnus method (two Gauss points, `S`
//! sub-steps per interval); by F2 it does not depend on the durations. Its
//! derivative is the exact derivative of that discrete map: a perturbation
//! `dOmega_j` of step `j` moves the final attitude by `R_{j+1} J_r(Omega_j) dOmega_j`
//! in the world frame.
//!
//! From a seed, a peak-torque design without a torque-speed line or speed
//! limit is solved on coarser meshes first (a third of the nodes, or half,
//! and so on while 20 or more remain per phase), loosely, and each starts
//! the next ([`coarse_start`], mesh continuation); the coarsest is also
//! solved from the analytic schedule ([`other_starts`]) and the lower
//! design continued. Any other design (`DesignSpec::uses_envelope`: a
//! time or energy design, or one under a torque-speed line or speed limit)
//! is solved at half the nodes first, and the fine mesh continues from it
//! with its penalty weight and trust radius ([`envelope_coarse_start`]).

use crate::design::collocation::Transcription;
use crate::design::collocation_plan::CollocationPlan;
use crate::design::conic::{Cone, ConicData, ConicSettings};
use crate::design::objective::Objective;
use crate::design::plan::ShapePlan;
use crate::design::release::Release;
use crate::design::scp::{
    Certificate, Cost, Executor, Linearization, ScpIteration, ScpProblem, ScpSettings, ScpStatus,
    Triplets, Values, WarmStart,
};
use crate::design::spec::DesignSpec;
use crate::error::Result;
use crate::model::dynamics::{christoffel, linearize_torque, torque_from};
use crate::model::so3::{exp, hat, log, right_jacobian, right_jacobian_inv};
use crate::model::{Cat, ShapeTerms, TorqueNorm};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

mod replanning;
pub use replanning::{Replan, Replanner, replan};

/// A torque check point: interval index, normalised `(q, q^, q^^)`, and the
/// interpolation coefficients of `q`, `q^`, `q^^` on the interval's node values.
type CheckPoint = (usize, [f64; 2], [f64; 2], [f64; 2], [[f64; 4]; 3]);

/// Trust-region scale of the phase durations relative to the start's
/// manoeuvre: the cost of the `time` objective is linear in them, so their
/// steps are bounded by the trust region alone, and a wide scale lets a
/// least-time design move its durations in fewer iterations without
/// costing the peak designs any (measured: docs/benchmarks.md, "Design
/// settings: the measurements behind them").
const DURATION_SCALE: f64 = 0.3;

/// Magnus sub-steps per collocation interval.
const SUB: usize = 2;

/// The free-form problem for one config, in dimensionless units: durations
/// in units of the available time `T` and torques in units of `I_t / T^2`
/// (F3), so that the conic data are O(1) for any cat, drop height or limit.
/// [`FreeProblem::to_scaled`] / [`FreeProblem::to_physical`] convert `z`.
pub struct FreeProblem {
    pub cat: Cat,
    pub tr: Transcription,
    pub norm: TorqueNorm,
    /// Available time, s (the unit of the durations).
    pub time_unit: f64,
    /// `I_t / T^2`, N m (the unit of the peak terms).
    pub torque_unit: f64,
    /// Shortest phase, in units of the available time.
    pub min_phase: f64,
    pub max_bend: Option<f64>,
    /// Torque limit `T` in units of `torque_unit` (see [`LIMIT_CAP`]).
    pub max_torque: Option<f64>,
    /// Slope of the torque-speed line in the problem's units: the limited
    /// term is `tau + slope q^ / T_p` (physical `tau + k qd`).
    pub slope: f64,
    /// Hard joint-speed limit in units of the rate `q^` per unit duration.
    pub max_speed: Option<f64>,
    pub objective: Objective,
    scales: Vec<f64>,
    /// The check points' shape terms (with second derivatives) of the last
    /// linearisation, in [`FreeProblem::check_points`] order: the Hessian at
    /// the same point reads them instead of evaluating them again.
    second_terms: std::cell::RefCell<Vec<([f64; 2], ShapeTerms)>>,
    /// Torque check points per interval, evenly spaced from its first node
    /// ([`CHECKS_PER_INTERVAL`]; one, the node, on a coarse mesh of the
    /// continuation, [`FreeProblem::at_nodes_only`]).
    checks: usize,
    /// Check points added between the regular ones, per phase (interval,
    /// fraction of it), where the torque there broke the limit or rose
    /// above the checked peak ([`refine_checks`]); after each phase's
    /// regular points.
    extra: [Vec<(usize, f64)>; 3],
    /// A start other than upside down at rest: the attitude map with
    /// momentum and the landing set (belly down, heading free) instead of
    /// the final attitude `Rz(pi)`.
    pub release: Option<Release>,
    /// The shape `q` (rad) and its rate `q_dot` (rad/s) at the start, when
    /// not straight and at rest (a replan from a measured state in flight).
    pub initial: Option<([f64; 2], [f64; 2])>,
    /// Whether the manoeuvre lasts the whole time the fall leaves: with
    /// angular momentum the straight cat goes on turning after it (F8), and
    /// its landing, judged `fall.margin` after the manoeuvre's end, is the
    /// one at touchdown only if nothing is left between. Set for a design
    /// from a start with momentum, unless the time is minimised (there the
    /// drop is the least one, touchdown right after the margin).
    pub fills_the_fall: bool,
}

/// Torque check points per interval on the design's own mesh: the node and
/// the quarter points. With the node and midpoint only, the torque between
/// them broke the limits by the mesh's second-order error, enough to raise
/// the peak above its check points and to stretch a least-time design to
/// bring its written rows back inside the torque-speed line. Four (a
/// spacing of `h / 4`, the five points a quarter apart of an IPOPT
/// reference) cut that excess sixteen-fold from the node's spacing
/// (measured: docs/benchmarks.md, "Design settings: the measurements
/// behind them").
pub const CHECKS_PER_INTERVAL: usize = 4;

/// A torque limit above this many torque units (`I_t / T^2`) is dropped
/// without a torque-speed line: no schedule that flips the cat comes near it
/// (the cosine schedule needs about 10), and a huge bound would only wreck
/// the conic solver's scaling. With a line it is kept: the limited terms
/// are divided by it ([`crate::design::scp`]), and clamping it would have
/// lowered the line's no-load speed `T / k` with it.
pub const LIMIT_CAP: f64 = 1e4;

/// One flattened torque row at a check point: its value and its gradient in
/// the interval's eight node values and the phase duration.
#[derive(Clone, Copy)]
struct TorqueRow {
    value: f64,
    grad: [f64; 9],
}

impl FreeProblem {
    /// The problem at `nodes` per phase; `z0` (any units of duration) sets
    /// the trust-region scales of the shape variables.
    pub fn new(spec: &DesignSpec, nodes: usize, z0: &[f64]) -> Self {
        Self::on(spec, Transcription::new(3, nodes), z0)
    }

    /// The problem on a given grid (`z0` in its layout).
    pub fn on(spec: &DesignSpec, tr: Transcription, z0: &[f64]) -> Self {
        let nodes = tr.nodes;
        let time_unit = spec.available_time();
        let cat = spec.cat;
        let torque_unit = cat.i_t() / (time_unit * time_unit);
        let mut sq = 0.1f64;
        let mut sv = 0.1f64;
        let mut sa = 0.1f64;
        for p in 0..3 {
            for k in 0..nodes {
                for j in 0..2 {
                    sq = sq.max(z0[tr.q(p, k) + j].abs());
                    sv = sv.max(z0[tr.v(p, k) + j].abs());
                    sa = sa.max(z0[tr.a(p, k) + j].abs());
                }
            }
        }
        let fills_the_fall = spec.objective != Objective::Time && spec.has_momentum();
        // (a manoeuvre that fills the fall is stretched to it before the solve)
        let manoeuvre = if fills_the_fall {
            1.0
        } else {
            ((0..3).map(|p| z0[tr.duration(p)]).sum::<f64>() / time_unit).clamp(1e-3, 1.0)
        };
        let mut scales = vec![0.0; tr.dim()];
        for p in 0..3 {
            for k in 0..nodes {
                for j in 0..2 {
                    scales[tr.q(p, k) + j] = sq;
                    scales[tr.v(p, k) + j] = sv;
                    scales[tr.a(p, k) + j] = sa;
                    scales[tr.a_in(p, k) + j] = sa;
                }
            }
            // DURATION_SCALE of the start's manoeuvre (in units of the
            // available time): slowing the whole problem down scales every step alike
            scales[tr.duration(p)] = DURATION_SCALE * manoeuvre;
        }
        Self {
            cat,
            tr,
            norm: spec.norm(),
            time_unit,
            torque_unit,
            min_phase: 0.02 * manoeuvre,
            max_bend: spec.max_bend_deg.map(f64::to_radians),
            // without a torque-speed line, a limit above the cap can never
            // bind; with one it is kept whole, since `T / k` is the line's
            // no-load speed, which a fast enough design meets in any fall
            max_torque: spec
                .motor
                .max_torque
                .map(|l| l / torque_unit)
                .filter(|&l| l < LIMIT_CAP || spec.motor.slope() > 0.0),
            slope: spec.motor.slope() / (torque_unit * time_unit),
            max_speed: spec.motor.max_speed.map(|w| w * time_unit),
            objective: spec.objective,
            scales,
            second_terms: Default::default(),
            release: Release::of(spec, time_unit),
            initial: None,
            fills_the_fall,
            checks: CHECKS_PER_INTERVAL,
            extra: Default::default(),
        }
        .with_checks(CHECKS_PER_INTERVAL)
    }

    /// The problem with the torque checked at the nodes only: half the
    /// torque rows, for a coarse mesh of the continuation, whose design only
    /// starts the finer one (which checks the midpoints again), so the
    /// limits between its nodes are left to the finer mesh. That saves
    /// work, and the finer meshes then end in other local optima of the
    /// peak, mostly lower (measured: docs/benchmarks.md, "Design settings:
    /// the measurements behind them").
    pub fn at_nodes_only(mut self) -> Self {
        self.checks = 1;
        self
    }

    /// [`ShapeTerms::second`] at check point `i` (phases in order) at shape
    /// `q`: the last linearisation's, if it was at the same shape.
    fn second_at(&self, i: usize, q: [f64; 2]) -> ShapeTerms {
        match self.second_terms.borrow().get(i) {
            Some(&(at, t)) if at == q => t,
            _ => ShapeTerms::second(&self.cat, q),
        }
    }

    /// Number of flattened torque rows (two per check point).
    pub fn torques_len(&self) -> usize {
        2 * (0..3).map(|p| self.points_in(p)).sum::<usize>()
    }

    /// Regular torque check points per phase: every node and, on each
    /// interval, the points between ([`FreeProblem::check_points`]).
    fn points_per_phase(&self) -> usize {
        if self.tr.jumps {
            (self.checks + 1) * (self.tr.nodes - 1)
        } else {
            self.checks * (self.tr.nodes - 1) + 1
        }
    }

    /// Check points of phase `p`, the added ones included.
    fn points_in(&self, p: usize) -> usize {
        self.points_per_phase() + self.extra[p].len()
    }

    /// Index of phase `p`'s first check point (phases in order).
    fn first_point(&self, p: usize) -> usize {
        (0..p).map(|q| self.points_in(q)).sum()
    }

    /// The problem with check points added between the regular ones (per
    /// phase: interval, fraction in `(0, 1)`); not from a spinning start,
    /// whose attitude map knows the momentum at its sub-steps only.
    fn with_extra_checks(mut self, extra: [Vec<(usize, f64)>; 3]) -> Self {
        if !self.spins() {
            self.extra = extra;
        }
        self
    }

    /// Check points per interval ([`CHECKS_PER_INTERVAL`]), at least one;
    /// at most two from a spinning start, whose momentum the attitude map
    /// knows at its sub-steps only (nodes and midpoints, [`Release::path`]).
    pub fn with_checks(mut self, checks: usize) -> Self {
        let most = if self.spins() { 2 } else { usize::MAX };
        self.checks = checks.clamp(1, most);
        self
    }

    /// Whether the start has angular momentum: then the torque at a check
    /// point depends on the attitude there, which the attitude map gives at
    /// its sub-steps only. From a start at rest (tilted or rolled) the torque
    /// is the shape's alone, checked as from today's start.
    fn spins(&self) -> bool {
        self.release
            .is_some_and(|r| r.momentum.iter().any(|&c| c != 0.0))
    }

    /// Whether the interval midpoints are check points (for the attitude
    /// map's momentum at them, [`Release::path`]).
    fn midpoints(&self) -> bool {
        self.checks > 1
    }

    /// The objective's unit in physical terms: N m (peak), s (time) or
    /// N^2 m^2 s (energy).
    pub fn objective_unit(&self) -> f64 {
        match self.objective {
            Objective::PeakTorque => self.torque_unit,
            Objective::Time => self.time_unit,
            Objective::Energy => self.torque_unit * self.torque_unit * self.time_unit,
        }
    }

    /// Physical `z` (durations in s) to the problem's units.
    pub fn to_scaled(&self, z: &[f64]) -> Vec<f64> {
        self.with_durations_times(z, 1.0 / self.time_unit)
    }

    /// The problem's `z` to physical units (durations in s).
    pub fn to_physical(&self, z: &[f64]) -> Vec<f64> {
        self.with_durations_times(z, self.time_unit)
    }

    /// The point nearest to `z` (in the trust-region scales) that meets the
    /// exact constraints: one small QP, so that a sampled seed (or a
    /// neighbour's solution) is a feasible start.
    pub fn project(&self, z: &[f64]) -> Result<Vec<f64>> {
        let d = self.projection_data(z);
        let (st, dz, _) = crate::design::conic::ConicSolver::new(&d)?.solve();
        if !st.ok() {
            return Err(Self::projection_failed(st));
        }
        Ok(z.iter().zip(&dz).map(|(a, b)| a + b).collect())
    }

    /// The projection's program: the least scaled step onto the exact constraints.
    fn projection_data(&self, z: &[f64]) -> ConicData {
        let mut d = ConicData::new(self.dim());
        d.p_diag = Some(self.scales.iter().map(|s| 1.0 / (s * s)).collect());
        self.add_constraints(&mut d, z, &|i| i);
        d
    }

    fn projection_failed(st: crate::design::conic::SolveStatus) -> crate::error::Error {
        crate::error::Error::Solver {
            what: "projecting the free-form seed onto the constraints".into(),
            status: format!("{st:?}"),
            hint: "check limits.max_bend_deg and fall.margin (the seed cannot be made to fit them)"
                .into(),
        }
    }

    fn with_durations_times(&self, z: &[f64], k: f64) -> Vec<f64> {
        let mut z = z.to_vec();
        for p in 0..self.tr.phases {
            z[self.tr.duration(p)] *= k;
        }
        z
    }

    /// Final attitude of body A and, if asked, the world-frame Jacobian
    /// `dW / dz` (3 rows, one column per variable).
    pub fn attitude(&self, z: &[f64], want_jac: bool) -> (Matrix3<f64>, Vec<Vector3<f64>>) {
        let tr = &self.tr;
        let n = tr.nodes;
        let mut r = Matrix3::identity();
        let mut g = if want_jac {
            vec![Vector3::zeros(); tr.dim()]
        } else {
            Vec::new()
        };
        let s3 = 3f64.sqrt();
        let cm = s3 / 12.0;
        let hs = tr.h() / SUB as f64;
        for p in 0..3 {
            for k in 0..n - 1 {
                let d = tr.interval(z, p, k);
                for j in 0..SUB {
                    let cs = [
                        (j as f64 + 0.5 - s3 / 6.0) / SUB as f64,
                        (j as f64 + 0.5 + s3 / 6.0) / SUB as f64,
                    ];
                    let pts = cs.map(|c| d.at(c));
                    // the rate alone needs no derivatives (plain f64, a
                    // twentieth of the cost)
                    let terms = want_jac
                        .then(|| pts.each_ref().map(|it| ShapeTerms::first(&self.cat, it.q)));
                    let w = [0, 1].map(|i| {
                        Vector3::from(match &terms {
                            Some(t) => t[i].body_rate(pts[i].v),
                            None => self.cat.body_rate(pts[i].q, pts[i].v),
                        })
                    });
                    let omega = hs / 2.0 * (w[0] + w[1]) + cm * hs * hs * w[0].cross(&w[1]);
                    r *= exp(&omega);
                    let Some(terms) = &terms else {
                        continue;
                    };
                    let m = r * right_jacobian(&omega);
                    let dpdw = [
                        hs / 2.0 * Matrix3::identity() - cm * hs * hs * hat(&w[1]),
                        hs / 2.0 * Matrix3::identity() + cm * hs * hs * hat(&w[0]),
                    ];
                    for i in 0..2 {
                        let it = &pts[i];
                        let wq = terms[i].body_rate_dq(it.v);
                        let wv = [0, 1].map(|c| -Vector3::from(terms[i].a[c]));
                        let pm = m * dpdw[i];
                        for c in 0..2 {
                            let wqc = Vector3::from(wq[c]);
                            let cols = tr.interval_columns(p, k, c);
                            for (idx, col) in cols.into_iter().enumerate() {
                                g[col] += pm * (wqc * it.dq[idx] + wv[c] * it.dv[idx]);
                            }
                        }
                    }
                }
            }
        }
        (r, g)
    }

    /// The optimiser's own terminal error, rad: the attitude error's norm,
    /// or from another start the landing error.
    pub fn terminal_error(&self, z: &[f64]) -> f64 {
        match &self.release {
            Some(rel) => rel.landing_error(
                rel.path(&self.cat, &self.tr, z, self.midpoints(), false)
                    .end,
            ),
            None => Self::attitude_error(&self.attitude(z, false).0).norm(),
        }
    }

    /// Attitude error `log(Rz(pi)' R)`, rad.
    pub fn attitude_error(r: &Matrix3<f64>) -> Vector3<f64> {
        let target = Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0));
        log(&(target.transpose() * r))
    }

    /// Normalised-time state at the torque check points of phase `p`: every
    /// node and the points between, evenly spaced ([`CHECKS_PER_INTERVAL`];
    /// none [`FreeProblem::at_nodes_only`]), with the interpolation coefficients on
    /// `(q_k, q^_k, q^^_k, q^^_{k+1})` of interval `k`.
    fn check_points(&self, z: &[f64], p: usize) -> Vec<CheckPoint> {
        let tr = &self.tr;
        let mut out = Vec::with_capacity(self.points_per_phase());
        for k in 0..tr.nodes {
            let kk = k.min(tr.nodes - 2);
            let d = tr.interval(z, p, kk);
            let m = self.checks;
            // with jumps every interval's end is checked (a node's left limit)
            let end = tr.jumps || k == tr.nodes - 2;
            for c in if k < tr.nodes - 1 {
                (0..m)
                    .map(|j| j as f64 / m as f64)
                    .chain(end.then_some(1.0))
                    .collect()
            } else {
                vec![]
            } {
                let it = d.at(c);
                out.push((kk, it.q, it.v, it.a, [it.dq, it.dv, [0.0, 0.0, 1.0 - c, c]]));
            }
        }
        for &(k, c) in &self.extra[p] {
            let it = tr.interval(z, p, k).at(c);
            out.push((k, it.q, it.v, it.a, [it.dq, it.dv, [0.0, 0.0, 1.0 - c, c]]));
        }
        out
    }

    /// Simpson weights of one phase's check points (in [`Self::check_points`]
    /// order) for `integral_0^1 f ds`; trapezoid weights at the nodes only
    /// (an energy design's coarse mesh inside the envelope).
    fn quadrature(&self) -> Vec<f64> {
        let h = self.tr.h();
        let m = self.checks;
        let mut w = Vec::with_capacity(self.points_per_phase());
        if self.tr.jumps {
            // each interval on its own (its points, both ends included)
            let step = h / m as f64;
            for _ in 0..self.tr.nodes - 1 {
                w.extend((0..=m).map(|j| match (m % 2, j) {
                    (1, 0) => step / 2.0,
                    (1, j) if j == m => step / 2.0,
                    (1, _) => step,
                    (_, 0) => step / 3.0,
                    (_, j) if j == m => step / 3.0,
                    (_, j) if j % 2 == 1 => 4.0 * step / 3.0,
                    _ => 2.0 * step / 3.0,
                }));
            }
            return w;
        }
        if m % 2 == 1 {
            // trapezoid on the points (h / m apart)
            let (step, last) = (h / m as f64, self.points_per_phase() - 1);
            w.extend((0..=last).map(|i| {
                if i == 0 || i == last {
                    step / 2.0
                } else {
                    step
                }
            }));
            return w;
        }
        // composite Simpson on the points: (h / m) / 3 [1, 4, 2, 4, ..., 4, 1]
        let third = h / m as f64 / 3.0;
        for k in 0..self.tr.nodes - 1 {
            w.push(if k == 0 { third } else { 2.0 * third });
            for j in 1..m {
                w.push(if j % 2 == 1 { 4.0 * third } else { 2.0 * third });
            }
        }
        w.push(third);
        w
    }

    /// The torque (in units of `torque_unit`) at every check point, phases
    /// in order, with gradients when asked; the point's phase, interval,
    /// rate `q^` and its interpolation coefficients, and quadrature weight.
    fn torque_points(&self, z: &[f64], want_grad: bool) -> Vec<TorquePoint> {
        let tr = &self.tr;
        let it = self.cat.i_t();
        let weights = self.quadrature();
        let mut out = Vec::with_capacity(3 * self.points_per_phase());
        let mut seconds = self.second_terms.borrow_mut();
        if want_grad {
            seconds.clear();
        }
        let mus = self
            .release
            .filter(|_| self.spins())
            .map(|r| r.path(&self.cat, tr, z, self.midpoints(), false).mu);
        let mut point = 0;
        for p in 0..3 {
            let t = z[tr.duration(p)];
            let (s2, s3) = (1.0 / (t * t * it), -2.0 / (t * t * t * it));
            // an added check point has no quadrature weight
            let weights = weights.iter().chain(std::iter::repeat(&0.0));
            for ((k, q, v, a, coef), &weight) in self.check_points(z, p).into_iter().zip(weights) {
                let mu = mus.as_ref().map(|m| m[point]);
                point += 1;
                let mut rows = if want_grad {
                    // normalised-time inverse dynamics; physical torque = tau^ / T^2
                    let terms = ShapeTerms::second(&self.cat, q);
                    seconds.push((q, terms));
                    let lin = linearize_torque(&terms, v, a);
                    [0, 1].map(|i| {
                        let mut grad = [0.0; 9];
                        for l in 0..2 {
                            for idx in 0..4 {
                                grad[4 * l + idx] = (lin.d_q[i][l] * coef[0][idx]
                                    + lin.d_qd[i][l] * coef[1][idx]
                                    + lin.d_qdd[i][l] * coef[2][idx])
                                    * s2;
                            }
                        }
                        grad[8] = lin.tau[i] * s3;
                        TorqueRow {
                            value: lin.tau[i] * s2,
                            grad,
                        }
                    })
                } else {
                    let tau = torque_from(&ShapeTerms::first(&self.cat, q), v, a);
                    tau.map(|x| TorqueRow {
                        value: x * s2,
                        grad: [0.0; 9],
                    })
                };
                if let Some(mu) = mu {
                    // the momentum's part g(q, q^, mu), mu = T_p R' l: exact in
                    // the local shape and the duration, lagged in the attitude
                    let (g, dg) = if want_grad {
                        Release::torque(&self.cat, q, v, mu)
                    } else {
                        (Release::torque_value(&self.cat, q, v, mu), [[0.0; 4]; 2])
                    };
                    let dmu = want_grad.then(|| Release::torque_dmu(&self.cat, q, v, mu));
                    for i in 0..2 {
                        let row = &mut rows[i];
                        if let Some(dmu) = dmu {
                            for l in 0..2 {
                                for idx in 0..4 {
                                    row.grad[4 * l + idx] += (dg[i][l] * coef[0][idx]
                                        + dg[i][2 + l] * coef[1][idx])
                                        * s2;
                                }
                            }
                            let along: f64 = (0..3).map(|c| dmu[i][c] * mu[c] / t).sum();
                            row.grad[8] += g[i] * s3 + along * s2;
                        }
                        row.value += g[i] * s2;
                    }
                }
                out.push(TorquePoint {
                    phase: p,
                    interval: k,
                    duration: t,
                    rate: v,
                    rate_coef: coef[1],
                    weight,
                    rows,
                });
            }
        }
        out
    }

    /// The torques at the check points, flattened.
    fn torques(&self, z: &[f64]) -> Vec<f64> {
        self.torque_points(z, false)
            .iter()
            .flat_map(|pt| pt.rows.iter().map(|r| r.value))
            .collect()
    }

    /// The variables a torque on interval `k` of phase `p` depends on (a
    /// point's gradient, an interval's Hessian block): the interval's eight
    /// node values (component 0 then 1) and the phase duration.
    fn interval_columns(&self, p: usize, k: usize) -> [usize; 9] {
        let mut cols = [0usize; 9];
        for l in 0..2 {
            let ic = self.tr.interval_columns(p, k, l);
            cols[4 * l..4 * l + 4].copy_from_slice(&ic);
        }
        cols[8] = self.tr.duration(p);
        cols
    }

    /// The cost's terms and the limited terms from the torque points, with
    /// gradients (in the points' nine columns) when the points carry them.
    /// Peak: the torque. Energy: `sqrt(w T_p) tau` (quadrature weight `w`), so
    /// that the sum of squares is `integral |tau|^2 dt`. Time: none. Limited:
    /// `tau + slope q^ / T_p` (the torque-speed line), when there is a limit.
    fn terms_of(&self, pts: &[TorquePoint]) -> (Vec<TorqueRow>, Vec<TorqueRow>) {
        let mut terms = Vec::new();
        let mut limited = Vec::new();
        for pt in pts {
            let t = pt.duration;
            for (i, row) in pt.rows.iter().enumerate() {
                match self.objective {
                    Objective::PeakTorque => terms.push(*row),
                    Objective::Energy => {
                        let c = (pt.weight * t).sqrt();
                        let mut grad = row.grad.map(|g| c * g);
                        grad[8] += row.value * 0.5 * (pt.weight / t).sqrt();
                        terms.push(TorqueRow {
                            value: c * row.value,
                            grad,
                        });
                    }
                    Objective::Time => {}
                }
                if self.max_torque.is_some() {
                    let mut grad = row.grad;
                    for idx in 0..4 {
                        grad[4 * i + idx] += self.slope / t * pt.rate_coef[idx];
                    }
                    grad[8] -= self.slope * pt.rate[i] / (t * t);
                    limited.push(TorqueRow {
                        value: row.value + self.slope * pt.rate[i] / t,
                        grad,
                    });
                }
            }
        }
        (terms, limited)
    }

    /// Physical rate continuity across the two junctions, in radians (the
    /// rate jump times the two phases' mean duration, so that the residual
    /// does not change when the whole manoeuvre is slowed down):
    /// `m (q^_{p,end} / T_p - q^_{p+1,0} / T_{p+1})`, `m = (T_p + T_{p+1}) / 2`,
    /// with its Jacobian.
    fn rate_continuity(&self, z: &[f64], row0: usize, jac: Option<&mut Triplets>) -> Vec<f64> {
        let tr = &self.tr;
        let n = tr.nodes;
        let mut r = Vec::with_capacity(4);
        let mut jac = jac;
        for p in 0..2 {
            let (ta, tb) = (z[tr.duration(p)], z[tr.duration(p + 1)]);
            let m = 0.5 * (ta + tb);
            for j in 0..2 {
                let (ia, ib) = (tr.v(p, n - 1) + j, tr.v(p + 1, 0) + j);
                let row = row0 + r.len();
                let jump = z[ia] / ta - z[ib] / tb;
                r.push(m * jump);
                if let Some(jac) = jac.as_deref_mut() {
                    jac.push((row, ia, m / ta));
                    jac.push((row, ib, -m / tb));
                    jac.push((row, tr.duration(p), 0.5 * jump - m * z[ia] / (ta * ta)));
                    jac.push((row, tr.duration(p + 1), 0.5 * jump + m * z[ib] / (tb * tb)));
                }
            }
        }
        r
    }
}

/// Samples of an interval searched between its check points
/// ([`FreeProblem::between_checks`]).
const BETWEEN_SAMPLES: usize = 32;

/// The share of `limits.max_bend_deg` the free-form design keeps inside at
/// its check points, so that the bend between them (a cubic) stays within
/// the limit.
const BEND_MARGIN: f64 = 1e-3;

impl FreeProblem {
    /// Where the limited term between the check points of `z` (problem
    /// units) is above the torque limit by more than `tol` (relative): per
    /// phase, the worst of [`BETWEEN_SAMPLES`] samples of each interval that
    /// is (interval, fraction); none without a limit or from a spinning
    /// start ([`FreeProblem::with_extra_checks`]).
    fn between_checks(&self, z: &[f64], tol: f64) -> [Vec<(usize, f64)>; 3] {
        let mut out: [Vec<(usize, f64)>; 3] = Default::default();
        let Some(limit) = self.max_torque.filter(|_| !self.spins()) else {
            return out;
        };
        let tr = &self.tr;
        for (p, found) in out.iter_mut().enumerate() {
            let t = z[tr.duration(p)];
            let s2 = 1.0 / (t * t * self.cat.i_t());
            for k in 0..tr.nodes - 1 {
                let d = tr.interval(z, p, k);
                let mut worst = (tol, None);
                // the regular check points are where j checks / samples is whole
                for j in (1..BETWEEN_SAMPLES)
                    .filter(|j| !(j * self.checks).is_multiple_of(BETWEEN_SAMPLES))
                {
                    let c = j as f64 / BETWEEN_SAMPLES as f64;
                    let it = d.at(c);
                    let tau = torque_from(&ShapeTerms::first(&self.cat, it.q), it.v, it.a)
                        .map(|x| x * s2);
                    let limited = [0, 1].map(|i| tau[i] + self.slope * it.v[i] / t);
                    let excess = self.norm.of(limited) / limit - 1.0;
                    if excess > worst.0 {
                        worst = (excess, Some(c));
                    }
                }
                if let Some(c) = worst.1 {
                    found.push((k, c));
                }
            }
        }
        out
    }

    /// A neighbour's multipliers of the torque rows (`m`, two per check
    /// point of `from`) laid out on this problem's check points: the added
    /// ones start at zero.
    fn padded(&self, from: &FreeProblem, m: &[f64]) -> Vec<f64> {
        if m.is_empty() {
            return Vec::new();
        }
        let mut out = Vec::with_capacity(self.torques_len());
        for p in 0..3 {
            let start = 2 * from.first_point(p);
            out.extend_from_slice(&m[start..start + 2 * from.points_in(p)]);
            out.resize(out.len() + 2 * (self.points_in(p) - from.points_in(p)), 0.0);
        }
        out
    }
}

/// The torque at one check point (see [`FreeProblem::torque_points`]).
struct TorquePoint {
    phase: usize,
    interval: usize,
    /// Phase duration (problem units).
    duration: f64,
    /// `q^` at the point and its coefficients on the interval's values.
    rate: [f64; 2],
    rate_coef: [f64; 4],
    /// Quadrature weight in normalised time ([`FreeProblem::quadrature`]).
    weight: f64,
    rows: [TorqueRow; 2],
}

/// `d tau_i / d(q, q^, q^^)` as one row of six.
fn torque_gradients(cat: &Cat, x: &[f64; 6], terms: Option<&ShapeTerms>) -> [[f64; 6]; 2] {
    let q = [x[0], x[1]];
    let owned;
    let t = match terms {
        Some(t) => t,
        None => {
            owned = ShapeTerms::second(cat, q);
            &owned
        }
    };
    let l = linearize_torque(t, [x[2], x[3]], [x[4], x[5]]);
    [0, 1].map(|i| {
        [
            l.d_q[i][0],
            l.d_q[i][1],
            l.d_qd[i][0],
            l.d_qd[i][1],
            l.d_qdd[i][0],
            l.d_qdd[i][1],
        ]
    })
}

/// `sum_i y_i Hess tau_i` in `(q, q^, q^^)`, from the structure of the
/// inverse dynamics `tau_i = M_ij(q) a_j + c_ijk(q) v_j v_k`: the rate block is
/// the exact `c_ilk + c_ikl`, the acceleration blocks with rate and
/// acceleration are zero, and the rows in `q` (hence, by symmetry, the
/// mixed blocks) are forward differences of the exact gradients in `q`
/// alone (the shape terms' third derivatives are not formed; two
/// evaluations instead of a central difference's four, with a relative
/// error about 1e-6 in a model that is scaled and clipped anyway). `base`
/// holds the shape terms at `q` and `g0` the gradients there
/// ([`torque_gradients`]).
fn weighted_torque_hessian(
    cat: &Cat,
    base: &ShapeTerms,
    g0: &[[f64; 6]; 2],
    x: [f64; 6],
    y: [f64; 2],
) -> [[f64; 6]; 6] {
    let mut g = [[0.0; 6]; 6];
    for m in 0..2 {
        let h = 1e-7 * (1.0 + x[m].abs());
        let mut xp = x;
        xp[m] += h;
        let h = xp[m] - x[m];
        let gp = torque_gradients(cat, &xp, None);
        for c in 0..6 {
            g[m][c] = (0..2).map(|i| y[i] * (gp[i][c] - g0[i][c]) / h).sum();
        }
    }
    // the q rows give the mixed blocks; their own 2x2 block is symmetrised
    let v = 0.5 * (g[0][1] + g[1][0]);
    (g[0][1], g[1][0]) = (v, v);
    for m in 0..2 {
        for c in 2..6 {
            g[c][m] = g[m][c];
        }
    }
    let ch = christoffel(base);
    for l in 0..2 {
        for k in 0..2 {
            g[2 + l][2 + k] = (0..2).map(|i| y[i] * (ch[i][l][k] + ch[i][k][l])).sum();
        }
    }
    g
}

/// The nearest positive semidefinite matrix (negative eigenvalues clipped).
fn psd_part(h: nalgebra::SMatrix<f64, 9, 9>) -> nalgebra::SMatrix<f64, 9, 9> {
    let e = nalgebra::SymmetricEigen::new(h);
    let d = e.eigenvalues.map(|x| x.max(0.0));
    e.eigenvectors * nalgebra::SMatrix::<f64, 9, 9>::from_diagonal(&d) * e.eigenvectors.transpose()
}

/// Multipliers below this fraction of the largest carry no curvature into
/// the SCP's model ([`FreeProblem::hessian`]).
const NEGLIGIBLE_MULTIPLIER: f64 = 1e-6;

impl FreeProblem {
    /// Phase `p`'s share of [`ScpProblem::hessian`]: `y` holds its check
    /// points' multipliers (two per point); those at most `cut` are skipped.
    /// Every interval's block is emitted (zeros too: a fixed pattern).
    fn phase_hessian(&self, z: &[f64], p: usize, y: &[f64], cut: f64) -> Triplets {
        let tr = &self.tr;
        let n = tr.nodes;
        let it = self.cat.i_t();
        let t = z[tr.duration(p)];
        let (s2, s3, s4) = (
            1.0 / (t * t * it),
            -2.0 / (t * t * t * it),
            6.0 / (t.powi(4) * it),
        );
        let mut blocks = vec![nalgebra::SMatrix::<f64, 9, 9>::zeros(); n - 1];
        let first = self.first_point(p);
        for (i, ((k, q, v, a, coef), w)) in self
            .check_points(z, p)
            .into_iter()
            .zip(y.chunks(2))
            .enumerate()
        {
            let w = [w[0], w[1]];
            if w[0].abs().max(w[1].abs()) <= cut {
                continue;
            }
            let x = [q[0], q[1], v[0], v[1], a[0], a[1]];
            let base = self.second_at(first + i, q);
            let gr = torque_gradients(&self.cat, &x, Some(&base));
            let g6 = weighted_torque_hessian(&self.cat, &base, &gr, x, w);
            let tau = torque_from(&base, v, a);
            // C: local inputs (kind, component) from the interval's 8 values (component, idx)
            let mut c = nalgebra::SMatrix::<f64, 6, 8>::zeros();
            for kind in 0..3 {
                for l in 0..2 {
                    for idx in 0..4 {
                        c[(2 * kind + l, 4 * l + idx)] = coef[kind][idx];
                    }
                }
            }
            let g = nalgebra::SMatrix::<f64, 6, 6>::from_fn(|i, j| g6[i][j]);
            let hx = c.transpose() * g * c * s2;
            let grad6 =
                nalgebra::SVector::<f64, 6>::from_fn(|i, _| w[0] * gr[0][i] + w[1] * gr[1][i]);
            let gx = c.transpose() * grad6 * s3;
            let b = &mut blocks[k];
            for i in 0..8 {
                for j in 0..8 {
                    b[(i, j)] += hx[(i, j)];
                }
                b[(i, 8)] += gx[i];
                b[(8, i)] += gx[i];
            }
            b[(8, 8)] += (w[0] * tau[0] + w[1] * tau[1]) * s4;
        }
        let mut out = Vec::with_capacity((n - 1) * 45);
        for (k, b) in blocks.into_iter().enumerate() {
            let b = if b == nalgebra::SMatrix::<f64, 9, 9>::zeros() {
                b
            } else {
                psd_part(b)
            };
            let cols = self.interval_columns(p, k);
            for i in 0..9 {
                for j in 0..9 {
                    if cols[i] <= cols[j] {
                        out.push((cols[i], cols[j], b[(i, j)]));
                    }
                }
            }
        }
        out
    }
}

impl ScpProblem for FreeProblem {
    /// Curvature of the peak terms, interval by interval: each check point's
    /// `y . tau / (I_t T_p^2)` is a function of its interval's eight node
    /// values and the phase duration; the 9x9 Hessian of the interval's sum
    /// is clipped to its PSD part (the attitude's curvature is left to the
    /// driver's second-order correction).
    fn hessian(&self, z: &[f64], y_terms: &[f64], u: &[f64]) -> Triplets {
        // the torque's curvature, weighted by the multipliers of the rows it
        // appears in: peak terms (peak cost) and limited terms (whose
        // rate part is linear in q^; its 1/T_p curvature is left out)
        let y: Vec<f64> = (0..self.torques_len())
            .map(|r| {
                let a = if self.objective == Objective::PeakTorque {
                    y_terms.get(r).copied().unwrap_or(0.0)
                } else {
                    0.0
                };
                a + u.get(r).copied().unwrap_or(0.0)
            })
            .collect();
        // an interior-point dual of an inactive row is tiny, not zero: its
        // curvature is left out (it costs work, and leaving it out changes
        // neither the iterations nor the peaks; measured: docs/benchmarks.md,
        // "Design settings: the measurements behind them")
        let cut = NEGLIGIBLE_MULTIPLIER * y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut out = Vec::new();
        for p in 0..3 {
            let rows = 2 * self.first_point(p)..2 * self.first_point(p + 1);
            out.extend(self.phase_hessian(z, p, &y[rows], cut));
        }
        out
    }

    fn dim(&self) -> usize {
        self.tr.dim()
    }
    fn term_dim(&self) -> usize {
        2
    }
    fn norm(&self) -> TorqueNorm {
        self.norm
    }
    fn scales(&self) -> Vec<f64> {
        self.scales.clone()
    }
    fn limit(&self) -> Option<f64> {
        self.max_torque
    }
    fn limited_are_terms(&self) -> bool {
        self.objective == Objective::PeakTorque && self.slope == 0.0
    }
    fn cost(&self) -> Cost {
        match self.objective {
            Objective::PeakTorque => Cost::Peak,
            Objective::Energy => Cost::SumOfSquares,
            Objective::Time => Cost::Linear((0..3).map(|p| (self.tr.duration(p), 1.0)).collect()),
        }
    }

    fn evaluate(&self, z: &[f64]) -> Values {
        let mut r = self.rate_continuity(z, 0, None);
        match &self.release {
            Some(rel) => {
                let end = rel
                    .path(&self.cat, &self.tr, z, self.midpoints(), false)
                    .end;
                r.extend(rel.landing(end).0);
            }
            None => {
                let (rf, _) = self.attitude(z, false);
                r.extend(Self::attitude_error(&rf).iter());
            }
        }
        let (terms, limited) = self.terms_of(&self.torque_points(z, false));
        Values {
            terms: terms.iter().map(|t| t.value).collect(),
            limited: limited.iter().map(|t| t.value).collect(),
            residual: r,
        }
    }

    fn linearize(&self, z: &[f64]) -> Linearization {
        let mut rj: Triplets = Vec::new();
        let mut residual = self.rate_continuity(z, 0, Some(&mut rj));
        let row0 = residual.len();
        if let Some(rel) = &self.release {
            let path = rel.path(&self.cat, &self.tr, z, self.midpoints(), true);
            let (e, de) = rel.landing(path.end);
            residual.extend(e);
            for (col, sc) in path.end_jac.iter().enumerate() {
                for i in 0..2 {
                    let d: f64 = (0..4).map(|c| de[i][c] * sc[c]).sum();
                    if d != 0.0 {
                        rj.push((row0 + i, col, d));
                    }
                }
            }
        } else {
            let (rf, g) = self.attitude(z, true);
            let e = Self::attitude_error(&rf);
            let je = right_jacobian_inv(&e) * rf.transpose();
            residual.extend(e.iter());
            for (col, gc) in g.iter().enumerate() {
                let d = je * gc;
                for i in 0..3 {
                    rj.push((row0 + i, col, d[i]));
                }
            }
        }
        let pts = self.torque_points(z, true);
        let (terms, limited) = self.terms_of(&pts);
        // each point contributes two rows to each list, in point order
        let flatten = |rows: &[TorqueRow]| {
            let mut jac: Triplets = Vec::with_capacity(9 * rows.len());
            for (r, row) in rows.iter().enumerate() {
                let cols = self.interval_columns(pts[r / 2].phase, pts[r / 2].interval);
                jac.extend(cols.iter().zip(&row.grad).map(|(&c, &g)| (r, c, g)));
            }
            (rows.iter().map(|t| t.value).collect::<Vec<_>>(), jac)
        };
        let (terms, tj) = flatten(&terms);
        let (limited, lj) = flatten(&limited);
        Linearization {
            terms,
            terms_jac: tj,
            limited,
            limited_jac: lj,
            residual,
            residual_jac: rj,
        }
    }

    fn add_constraints(&self, d: &mut ConicData, z: &[f64], var: &dyn Fn(usize) -> usize) {
        let tr = &self.tr;
        let n = tr.nodes;
        // z + dz = 0 at both ends; continuity of q across phases
        let mut zero = 0;
        for (p, k) in [(0, 0), (2, n - 1)] {
            for base in [tr.q(p, k), tr.v(p, k)] {
                for j in 0..2 {
                    match self.initial.filter(|_| p == 0) {
                        // q + dq = q0; q^ + dq^ = q_dot0 T (T + dT) in problem units
                        Some((q0, _)) if base == tr.q(p, k) => {
                            d.row(&[(var(base + j), 1.0)], q0[j] - z[base + j]);
                        }
                        Some((_, qd0)) => {
                            let c = qd0[j] * self.time_unit;
                            let dur = tr.duration(0);
                            d.row(
                                &[(var(base + j), 1.0), (var(dur), -c)],
                                c * z[dur] - z[base + j],
                            );
                        }
                        None => {
                            d.row(&[(var(base + j), 1.0)], -z[base + j]);
                        }
                    }
                    zero += 1;
                }
            }
        }
        for p in 0..2 {
            for (a, b) in [(tr.q(p, n - 1), tr.q(p + 1, 0))] {
                for j in 0..2 {
                    d.row(
                        &[(var(a + j), 1.0), (var(b + j), -1.0)],
                        z[b + j] - z[a + j],
                    );
                    zero += 1;
                }
            }
        }
        // the collocation defects are linear: exact, D (z + dz) = 0
        let mut dj = Vec::new();
        let dz = tr.defects(z, 0, Some(&mut dj));
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); dz.len()];
        for (r, c, v) in dj {
            rows[r].push((var(c), v));
        }
        for (row, r) in rows.iter().zip(&dz) {
            d.row(row, -r);
        }
        zero += dz.len();
        // total time within the fall (unless the time is minimised), all
        // of it when the cat turns as a whole ([`FreeProblem::fills_the_fall`]);
        // each phase at least min_phase
        let durs: Vec<_> = (0..3).map(|p| (var(tr.duration(p)), 1.0)).collect();
        let total: f64 = (0..3).map(|p| z[tr.duration(p)]).sum();
        let fills = self.fills_the_fall;
        if fills {
            d.row(&durs, 1.0 - total);
            zero += 1;
        }
        d.cone(Cone::Zero(zero));
        let within = self.objective != Objective::Time && !fills;
        if within {
            d.row(&durs, 1.0 - total);
        }
        for p in 0..3 {
            d.row(
                &[(var(tr.duration(p)), -1.0)],
                z[tr.duration(p)] - self.min_phase,
            );
        }
        d.cone(Cone::Nonneg(3 + usize::from(within)));
        // speed limit |q^| <= w T_p everywhere: the rate is quadratic on an
        // interval, so it lies in the convex hull of its Bernstein points
        // q^_k, q^_k + h q^^_k / 2, q^_{k+1}; bounding them bounds it exactly
        if let Some(w) = self.max_speed {
            let h = tr.h();
            let mut nonneg = 0;
            for p in 0..3 {
                let dur = tr.duration(p);
                for k in 0..n {
                    for mid in [false, true] {
                        if mid && k == n - 1 {
                            continue;
                        }
                        // the point: q^_k (+ h/2 q^^_k)
                        let comp = |j: usize| {
                            let mut e = vec![(var(tr.v(p, k) + j), -1.0)];
                            let mut val = z[tr.v(p, k) + j];
                            if mid {
                                e.push((var(tr.a(p, k) + j), -h / 2.0));
                                val += h / 2.0 * z[tr.a(p, k) + j];
                            }
                            (e, val)
                        };
                        match self.norm {
                            TorqueNorm::Euclidean => {
                                d.row(&[(var(dur), -w)], w * z[dur]);
                                for j in 0..2 {
                                    let (e, val) = comp(j);
                                    d.row(&e, val);
                                }
                                d.cone(Cone::Soc(3));
                            }
                            TorqueNorm::PerMotor => {
                                for j in 0..2 {
                                    let (e, val) = comp(j);
                                    // w (T + dT) - (v + dv) >= 0 and w (T + dT) + (v + dv) >= 0
                                    let mut up: Vec<_> = e.iter().map(|&(c, x)| (c, -x)).collect();
                                    up.push((var(dur), -w));
                                    d.row(&up, w * z[dur] - val);
                                    let mut down = e.clone();
                                    down.push((var(dur), -w));
                                    d.row(&down, w * z[dur] + val);
                                    nonneg += 2;
                                }
                            }
                        }
                    }
                }
            }
            if nonneg > 0 {
                d.cone(Cone::Nonneg(nonneg));
            }
        }
        // bend limit |q| <= b_max (1 - BEND_MARGIN) at every check point
        // (the nodes and the points between them, where the torque is
        // checked): with the nodes alone, the cubic between them bent past
        // the limit
        if let Some(b) = self.max_bend.map(|b| b * (1.0 - BEND_MARGIN)) {
            for p in 0..3 {
                for (k, q, _, _, [dq, _, _]) in self.check_points(z, p) {
                    d.row(&[], b);
                    for (j, qj) in q.iter().enumerate() {
                        let e: Vec<(usize, f64)> = tr
                            .interval_columns(p, k, j)
                            .iter()
                            .zip(&dq)
                            .filter(|&(_, &c)| c != 0.0)
                            .map(|(&i, &c)| (var(i), -c))
                            .collect();
                        d.row(&e, *qj);
                    }
                    d.cone(Cone::Soc(3));
                }
            }
        }
    }
}

/// What the free-form optimiser reports.
#[derive(Debug, Clone, Serialize)]
pub struct FreeResult {
    pub mode: &'static str,
    pub status: ScpStatus,
    pub objective: Objective,
    /// The objective's value for the written schedule, in [`Objective::unit`]
    /// (dense peak torque N m, manoeuvre time s, or `integral |tau|^2 dt`
    /// N^2 m^2 s).
    pub objective_value: f64,
    /// Manoeuvre time of the schedule, s.
    pub manoeuvre_time_s: f64,
    /// Dense inverse-dynamics peak along the reconstructed schedule, N m.
    pub peak_torque_nm: f64,
    /// Peak at the collocation nodes and interval midpoints (the SCP objective), N m.
    pub node_peak_torque_nm: f64,
    /// Largest bend at the collocation nodes, and the angle between the
    /// halves there (the schedule between the nodes may bend a little more).
    pub bend_deg: f64,
    pub theta_deg: f64,
    /// Total rotation of the bend direction (unwrapped), rad.
    pub twist_rad: f64,
    pub phase_durations_s: [f64; 3],
    /// Final attitude error of the optimiser's own map, rad.
    pub attitude_error_rad: f64,
    pub seed: String,
    pub scp_iterations: usize,
    pub nodes: usize,
    pub solve_time_s: f64,
    /// The stopping rule's numbers at the end point.
    pub certificate: Certificate,
    /// The meshes the design was solved on, coarse to fine (mesh
    /// continuation; the last is `nodes`): `iterations` in that order.
    pub mesh_levels: Vec<MeshLevel>,
    /// Mesh-refinement check: the same design re-optimised at twice the nodes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_check: Option<MeshCheck>,
    pub iterations: Vec<ScpIteration>,
    /// The solution in the problem's units and the SCP's end state (a warm
    /// start for a neighbour).
    #[serde(skip)]
    pub z_scaled: Vec<f64>,
    #[serde(skip)]
    pub warm: WarmStart,
    /// The check points [`refine_checks`] added (per phase: interval,
    /// fraction): a neighbour on the same grid starts with them.
    #[serde(skip)]
    pub extra_checks: [Vec<(usize, f64)>; 3],
    #[serde(skip)]
    pub plan: CollocationPlan,
}

/// Which schedule seeds the SCP.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seed {
    Phased,
    Analytic,
}

impl Seed {
    pub fn name(self) -> &'static str {
        match self {
            Seed::Phased => "phased",
            Seed::Analytic => "analytic",
        }
    }

    /// The seed's schedule: the phased design's ([`crate::design::phased::seed_plan`])
    /// or the analytic cosine schedule (which costs nothing).
    pub fn plan(self, spec: &DesignSpec) -> Result<Box<dyn crate::design::plan::ShapePlan>> {
        Ok(match self {
            Seed::Phased => Box::new(crate::design::phased::seed_plan(spec)?),
            Seed::Analytic => Box::new(crate::design::analytic::analytic_plan(spec)),
        })
    }
}

/// What a free-form design reports as it runs: the SCP's observer (each
/// iteration and, with mesh continuation, the start of each mesh).
pub use crate::design::scp::Observer;

/// Runs the SCP from a seed plan at `nodes` per phase; a peak-torque design
/// first on coarser meshes ([`coarse_start`], `free.mesh_continuation`), a
/// design inside the motor envelope on one ([`envelope_coarse_start`]).
/// `iterations`, `scp_iterations` and `solve_time_s` cover every mesh, in
/// order (`mesh_levels`), numbered on by the SCP's [`Executor`] as the
/// observer sees them. A fine design the coarse one cannot start is solved
/// from the seed. The observer is also told where each mesh begins.
fn from_plan(
    spec: &DesignSpec,
    seed_plan: &dyn crate::design::plan::ShapePlan,
    seed: &str,
    nodes: usize,
    observe: &mut dyn Observer,
) -> Result<FreeResult> {
    let design = |plan: &dyn crate::design::plan::ShapePlan, observe: &mut dyn Observer| {
        stage(spec, plan, seed, nodes, observe).finish(spec, observe)
    };
    // (a design already made for this question, the least-height answer's,
    // is not turned round)
    if spec.is_default_start() || seed == crate::pipeline::FREE_LEAST_TIME {
        return design(seed_plan, observe);
    }
    // from another start, the seed turned the way that leaves less to turn
    // first; the other way where that design does not land (near
    // belly-down both ways are far, and either may end straight)
    let Some(mirrored) = crate::design::mirror::mirrored(spec, seed_plan) else {
        // (no mirror image of this shape: one way round)
        return design(seed_plan, observe);
    };
    let mut ways: [(&dyn crate::design::plan::ShapePlan, bool); 2] =
        [(seed_plan, false), (&mirrored, true)];
    if crate::design::mirror::mirror_is_nearer(spec, seed_plan, &mirrored) {
        ways.swap(0, 1);
    }
    // the nearer way only as far as the start needs (near belly-down)
    let scaled = crate::design::mirror::scaled_to_the_turn(spec, ways[0].0);
    if let Some(s) = &scaled {
        ways[0].0 = s.as_ref();
    }
    // the kept design names its seed as mirrored, and counts the time of
    // a design tried before it
    let kept = |r: Result<FreeResult>, mirrored: bool, before_s: f64| {
        r.map(|mut r| {
            if mirrored == ways[0].1 && scaled.is_some() {
                r.seed = format!("{}{}", r.seed, crate::design::mirror::SCALED);
            }
            if mirrored {
                r.seed = format!("{}{}", r.seed, crate::design::mirror::MIRRORED);
            }
            r.solve_time_s += before_s;
            r
        })
    };
    let clock = std::time::Instant::now();
    let mut nearer = Recorded::default();
    let first = design(ways[0].0, &mut nearer);
    let first_s = clock.elapsed().as_secs_f64();
    // a design that lands the short way is kept; one that went more than
    // half a turn (the SCP may cross to the long way) is kept only if the
    // other way does no better
    if first.as_ref().is_ok_and(|r| lands_the_short_way(spec, r)) {
        nearer.replay(observe);
        return kept(first, ways[0].1, 0.0);
    }
    let mut other = Recorded::default();
    let second = design(ways[1].0, &mut other);
    let second_s = clock.elapsed().as_secs_f64() - first_s;
    // the nearer way's outcome unless the other is better
    if is_better(spec, &first, &second) {
        other.replay(observe);
        return kept(second, ways[1].1, first_s);
    }
    nearer.replay(observe);
    kept(first, ways[0].1, second_s)
}

/// Whether a design meets its landing (the SCP's own constraints, within
/// `free.attitude_tolerance`) without turning past half a turn: a design
/// continued from a neighbour keeps the neighbour's way round, and where
/// this fails the caller designs afresh, the nearer way
/// ([`FreeDesign::from_plan`]), keeping the [`better`] of the two.
pub fn lands_the_short_way(spec: &DesignSpec, r: &FreeResult) -> bool {
    r.certificate.constraint_violation <= spec.free.attitude_tolerance
        && !crate::design::mirror::goes_the_long_way(spec, &r.plan)
}

/// Whether `b` is a better design than `a` for one problem: it meets its
/// landing where `a` does not, or both do and its objective is lower, or
/// neither does and it misses by less; a design is better than a failure.
fn is_better(spec: &DesignSpec, a: &Result<FreeResult>, b: &Result<FreeResult>) -> bool {
    let key = |r: &Result<FreeResult>| {
        r.as_ref().ok().map(|r| {
            let miss = r.certificate.constraint_violation;
            // (a violation that is not a number misses)
            let misses = miss.is_nan() || miss > spec.free.attitude_tolerance;
            (misses, if misses { miss } else { r.objective_value })
        })
    };
    match (key(a), key(b)) {
        (Some(ka), Some(kb)) => kb.0.cmp(&ka.0).then(kb.1.total_cmp(&ka.1)).is_lt(),
        (None, Some(_)) => true,
        _ => false,
    }
}

/// The better of two designs for one problem ([`is_better`]), `a` on a tie.
pub fn better(
    spec: &DesignSpec,
    a: Result<FreeResult>,
    b: Result<FreeResult>,
) -> Result<FreeResult> {
    if is_better(spec, &a, &b) { b } else { a }
}

/// An observer's events kept to be told later, to the observer of the
/// design that is kept ([`from_plan`]).
#[derive(Default)]
struct Recorded(Vec<Event>);

enum Event {
    Iteration(ScpIteration),
    Mesh(usize),
}

impl Observer for Recorded {
    fn iteration(&mut self, it: &ScpIteration) {
        self.0.push(Event::Iteration(*it));
    }

    fn mesh(&mut self, nodes: usize) {
        self.0.push(Event::Mesh(nodes));
    }
}

impl Recorded {
    fn replay(self, observe: &mut dyn Observer) {
        for e in self.0 {
            match e {
                Event::Iteration(it) => observe.iteration(&it),
                Event::Mesh(nodes) => observe.mesh(nodes),
            }
        }
    }
}

/// A free-form design from a schedule, its coarse meshes solved: the fine
/// mesh's start and what it carries ([`FreeDesign::coarse_stage`]). Two
/// starts can be ranked here and only the better one finished.
pub struct Staged {
    seed: String,
    nodes: usize,
    /// Time the coarse meshes took, s.
    before: f64,
    z0: Vec<f64>,
    /// The seed sampled on the fine mesh (the fallback when the fine design
    /// fails from the coarse one).
    seed_z: Vec<f64>,
    carried: Option<WarmStart>,
    from_coarse: bool,
    levels: Vec<Coarse>,
    coarse: Option<CoarseOutcome>,
}

/// How the coarse mesh of an envelope design ended: its objective (in its
/// physical unit) and whether it met the constraints there.
#[derive(Debug, Clone, Copy)]
pub struct CoarseOutcome {
    pub objective: f64,
    pub feasible: bool,
}

impl Staged {
    /// The coarse design's outcome: none without one to rank (a design
    /// outside the motor envelope, whose continuation is the peak's; no
    /// coarse mesh, as with `free.mesh_continuation = false` or a mesh too
    /// coarse for the bend's turns; or a coarse solve that failed).
    pub fn coarse(&self) -> Option<CoarseOutcome> {
        self.coarse
    }

    /// The fine mesh from the staged start.
    pub fn finish(self, spec: &DesignSpec, observe: &mut dyn Observer) -> Result<FreeResult> {
        let clock = std::time::Instant::now();
        let Staged {
            seed,
            nodes,
            mut before,
            z0,
            seed_z,
            carried,
            from_coarse,
            levels,
            ..
        } = self;
        let seed = seed.as_str();
        if !levels.is_empty() {
            observe.mesh(nodes);
        }
        // the fine mesh's iterations are numbered on from the coarse meshes'
        let first = recorded(&levels);
        let start = carried.as_ref().map_or(Carried::Nothing, Carried::Coarse);
        let mut r = match optimize_start(spec, &z0, start, seed, nodes, first, |it| {
            observe.iteration(it)
        }) {
            // a fine design the coarse one could not start: from the seed (the
            // coarse meshes stay on the record); not an impossible flip, which
            // the seed would only find again
            Err(e)
                if from_coarse
                    && !matches!(
                        e,
                        crate::error::Error::Unreachable { .. }
                            | crate::error::Error::BeyondMotors { .. }
                    ) =>
            {
                // the failed attempt's time is spent before the design too
                before += clock.elapsed().as_secs_f64();
                // the failed attempt is not on the record: its numbers are reused
                observe.mesh(nodes);
                optimize_start(spec, &seed_z, Carried::Nothing, seed, nodes, first, |it| {
                    observe.iteration(it)
                })?
            }
            r => r?,
        };
        if !levels.is_empty() {
            r.solve_time_s += before;
            let mut meshes: Vec<MeshLevel> = levels.iter().map(|l| l.0).collect();
            meshes.extend(r.mesh_levels.iter().copied());
            r.mesh_levels = meshes;
            let mut iterations: Vec<ScpIteration> = levels.into_iter().flat_map(|l| l.1).collect();
            iterations.append(&mut r.iterations);
            r.iterations = iterations;
            r.scp_iterations = r.iterations.len();
        }
        Ok(r)
    }
}

/// The first stage of [`from_plan`]: the coarse meshes.
fn stage(
    spec: &DesignSpec,
    seed_plan: &dyn crate::design::plan::ShapePlan,
    seed: &str,
    nodes: usize,
    observe: &mut dyn Observer,
) -> Staged {
    let clock = std::time::Instant::now();
    let seed_z = grid(spec, nodes, Mesh::Final).sample(seed_plan);
    let mut levels = Vec::new();
    // the fine mesh's start, what it carries from a coarse mesh, and
    // whether it starts from a coarse design (not the seed)
    let (z0, carried, from_coarse, coarse) = if !spec.free.mesh_continuation {
        (seed_z.clone(), None, false, None)
    } else if !spec.uses_envelope() {
        let (z, from_coarse) = coarse_start(
            spec,
            seed_plan,
            seed == "analytic",
            (nodes, Mesh::Final),
            observe,
            &mut levels,
        );
        (z, None, from_coarse, None)
    } else {
        let (z, warm, coarse) = envelope_coarse_start(spec, seed_plan, nodes, observe, &mut levels);
        let from_coarse = warm.is_some();
        (z, warm, from_coarse, coarse)
    };
    Staged {
        seed: seed.to_string(),
        nodes,
        before: clock.elapsed().as_secs_f64(),
        z0,
        seed_z,
        carried,
        from_coarse,
        levels,
        coarse,
    }
}

/// The coarsest mesh of the continuation, nodes per phase: a coarser one
/// saved no work and cost the robot's design more iterations (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
const COARSEST_NODES: usize = 20;

/// The mesh below `nodes` in the continuation: a third of the nodes while
/// that leaves [`COARSEST_NODES`], else half, else none. A coarse iteration
/// at a third costs about half one at a half, and the finer mesh still
/// takes only a few iterations from it, so a third costs less in all than
/// a half, a quarter, or going straight to the coarsest mesh, to about the
/// same peaks (measured: docs/benchmarks.md, "Design settings: the
/// measurements behind them").
fn coarser(nodes: usize) -> Option<usize> {
    [3, 2]
        .into_iter()
        .map(|k| nodes / k)
        .find(|&c| c >= COARSEST_NODES)
}

/// The stopping tolerance on the coarser meshes (the finest keeps
/// `free.tolerance`): a start needs no more. A looser one saves no work, a
/// tighter one costs more, and this one gave the lowest peaks (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
const COARSE_TOLERANCE: f64 = 1e-3;

/// Which mesh of the continuation a design is solved on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mesh {
    /// A coarser mesh, whose design only starts the next one: to
    /// [`COARSE_TOLERANCE`], at most [`COARSE_MAX_ITERATIONS`]
    /// ([`ENVELOPE_COARSE_MAX_ITERATIONS`] inside the envelope), subproblems
    /// to [`ConicSettings::COARSE`], the torque checked at the nodes only
    /// ([`FreeProblem::at_nodes_only`]).
    Coarse,
    /// The design's own mesh, to the config's `free.tolerance`.
    Final,
}

/// One mesh a design was solved on: nodes per phase, SCP iterations, and
/// whether it converged (one that did not still starts the next mesh when
/// it stopped at its iteration limit, or inside the envelope whenever its
/// solve returned; see [`coarse_start`], [`envelope_coarse_start`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MeshLevel {
    pub nodes: usize,
    /// The seed's start's iterations (the ones observed and recorded).
    pub scp_iterations: usize,
    pub converged: bool,
    /// Starts solved on this mesh, the seed's included ([`other_starts`]).
    pub starts: usize,
    /// Iterations of the other start the mesh continued from, when one
    /// beat the seed's (0 otherwise).
    pub other_iterations: usize,
}

impl MeshLevel {
    /// "20", or "20 (not converged)".
    pub fn nodes_label(&self) -> String {
        let failed = if self.converged {
            ""
        } else {
            " (not converged)"
        };
        format!("{}{failed}", self.nodes)
    }
}

/// The iteration limit of a coarse mesh: it only starts the finer one, and
/// most coarse meshes converge well below it (one that runs far past it is
/// on a poor path). A coarse design stopped by the limit still starts the
/// finer mesh: it is nearer than the seed, from which a fine iteration costs
/// about ten coarse ones (docs/benchmarks.md, `bench_robot`). A higher
/// limit made the box robot's least-height stage cheaper but, with the
/// added check points, its least time longer, so it stays at 25 (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
const COARSE_MAX_ITERATIONS: usize = 25;

/// "17 SCP iterations, 8 at 20 and 9 at 40 nodes per phase", or "9 SCP
/// iterations at 40 nodes per phase" on one mesh; "failed, see its row"
/// with none (a `run` whose free-form design failed).
pub fn iterations_text(levels: &[MeshLevel]) -> String {
    let total: usize = levels.iter().map(|l| l.scp_iterations).sum();
    match levels {
        [] => "failed, see its row".into(),
        [one] => format!("{total} SCP iterations at {} nodes per phase", one.nodes),
        _ => {
            let parts: Vec<String> = levels
                .iter()
                .map(|l| format!("{} at {}", l.scp_iterations, l.nodes_label()))
                .collect();
            format!(
                "{total} SCP iterations, {} nodes per phase",
                parts.join(" and ")
            )
        }
    }
}

/// A coarse mesh's summary and its iterations.
type Coarse = (MeshLevel, Vec<ScpIteration>);

/// The iterations recorded on the coarse meshes so far: the next mesh's
/// are numbered on from there.
fn recorded(levels: &[Coarse]) -> usize {
    levels.iter().map(|l| l.1.len()).sum()
}

/// Mesh continuation: the start at `nodes` per phase, the design on the
/// mesh below ([`coarser`], itself started the same way) solved to
/// [`COARSE_TOLERANCE`] and sampled on the finer mesh; for the peak-torque objective without a torque-speed line
/// or speed limit (`Config::uses_envelope`): the time and energy designs
/// took more iterations with it and the robot's least time rose, and
/// inside the envelope a peak design's coarse mesh did not converge and
/// the design took longer.
/// Designs inside the envelope have a coarse mesh of their own
/// ([`envelope_coarse_start`]). From the coarse design the fine one takes a
/// few iterations, and a coarse iteration costs a fraction of a fine one
/// (measured: docs/benchmarks.md, "Design settings: the measurements
/// behind them"). A coarse design that fails,
/// or ends neither converged nor at its iteration limit, leaves the seed
/// itself as the start. Returns the start and whether a coarse design
/// made it.
fn coarse_start(
    spec: &DesignSpec,
    seed_plan: &dyn crate::design::plan::ShapePlan,
    seed_is_analytic: bool,
    (nodes, mesh): (usize, Mesh),
    observe: &mut dyn Observer,
    levels: &mut Vec<Coarse>,
) -> (Vec<f64>, bool) {
    let tr = grid(spec, nodes, mesh);
    // (a mesh too coarse for the bend's turns is skipped, not recorded)
    let Some(coarse) = coarser(nodes).filter(|&c| check_resolvable(spec, c).is_ok()) else {
        return (tr.sample(seed_plan), false);
    };
    let (z0, _) = coarse_start(
        spec,
        seed_plan,
        seed_is_analytic,
        (coarse, Mesh::Coarse),
        observe,
        levels,
    );
    let mut its = Vec::new();
    observe.mesh(coarse);
    let first = recorded(levels);
    // the coarsest mesh also solves the other starts, beside the seed's
    let others = if coarser(coarse).is_none() {
        other_starts(spec, !seed_is_analytic)
    } else {
        Vec::new()
    };
    let (solved, other) = std::thread::scope(|scope| {
        let other = scope.spawn(|| {
            others
                .iter()
                .filter_map(|c| {
                    let z = grid(spec, coarse, Mesh::Coarse)
                        .sample(&crate::design::analytic::analytic_plan(c));
                    let mut n = 0;
                    let s = design(spec, &z, None, coarse, Mesh::Coarse, 0, |_| n += 1).ok()?;
                    (s.res.status == ScpStatus::Converged).then_some((s, n))
                })
                .min_by(|a, b| a.0.res.objective.total_cmp(&b.0.res.objective))
        });
        let solved = design(spec, &z0, None, coarse, Mesh::Coarse, first, |it| {
            observe.iteration(it);
            its.push(*it);
        });
        (
            solved,
            other
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e)),
        )
    });
    let mut converged = matches!(&solved, Ok(s) if s.res.status == ScpStatus::Converged);
    let mut other_iterations = 0;
    let solved = match (solved, other) {
        (Ok(s), Some((o, n))) if !converged || o.res.objective < s.res.objective => {
            converged = true;
            other_iterations = n;
            Ok(o)
        }
        (s, _) => s,
    };
    levels.push((
        MeshLevel {
            nodes: coarse,
            scp_iterations: its.len(),
            converged,
            starts: 1 + others.len(),
            other_iterations,
        },
        its,
    ));
    match solved {
        Ok(s) if converged || s.res.status == ScpStatus::IterationLimit => {
            (tr.sample(&s.plan), true)
        }
        // the finer mesh starts from the seed again
        _ => (tr.sample(seed_plan), false),
    }
}

/// The coarse mesh of a design inside the motor envelope
/// (`DesignSpec::uses_envelope`: a torque-speed line or a speed limit, or a
/// time or energy design under a torque limit): half the nodes per phase,
/// while that leaves [`COARSEST_NODES`] and resolves the bend's turns. The
/// design takes about as many SCP iterations there as on the fine mesh
/// (the envelope's rows, more than the start's distance, set their number),
/// each a third as costly, and the fine mesh then usually needs far fewer.
/// The fine mesh starts from the coarse design's last point whatever its
/// status (stopped by [`ENVELOPE_COARSE_MAX_ITERATIONS`] or judged
/// infeasible at the coarse mesh's resolution, it is still nearer than the
/// seed; the fine mesh judges), with its penalty weight and trust radius (a
/// fine mesh started at the cold weight wandered for dozens of iterations);
/// from the seed when the coarse solve failed. Returns the fine mesh's
/// start and what it carries.
fn envelope_coarse_start(
    spec: &DesignSpec,
    seed_plan: &dyn crate::design::plan::ShapePlan,
    nodes: usize,
    observe: &mut dyn Observer,
    levels: &mut Vec<Coarse>,
) -> (Vec<f64>, Option<WarmStart>, Option<CoarseOutcome>) {
    let fine = grid(spec, nodes, Mesh::Final);
    let coarse = nodes / 2;
    // (a mesh too coarse for the bend's turns is skipped, not recorded)
    if coarse < COARSEST_NODES || check_resolvable(spec, coarse).is_err() {
        return (fine.sample(seed_plan), None, None);
    }
    observe.mesh(coarse);
    let z = grid(spec, coarse, Mesh::Coarse).sample(seed_plan);
    let mut its = Vec::new();
    let solved = design(
        spec,
        &z,
        None,
        coarse,
        Mesh::Coarse,
        recorded(levels),
        |it| {
            observe.iteration(it);
            its.push(*it);
        },
    );
    levels.push((
        MeshLevel {
            nodes: coarse,
            scp_iterations: its.len(),
            converged: matches!(&solved, Ok(s) if s.res.status == ScpStatus::Converged),
            starts: 1,
            other_iterations: 0,
        },
        its,
    ));
    match solved {
        Ok(s) => {
            let outcome = CoarseOutcome {
                objective: s.res.objective,
                feasible: s.res.infeasibility <= spec.free.attitude_tolerance,
            };
            (fine.sample(&s.plan), Some(s.res.warm), Some(outcome))
        }
        Err(_) => (fine.sample(seed_plan), None, None),
    }
}

/// The iteration limit of [`envelope_coarse_start`]'s mesh: most of the
/// bundled robots' designs converge below it there
/// (docs/benchmarks.md, `bench_robot`), and one stopped by it still starts
/// the fine mesh.
const ENVELOPE_COARSE_MAX_ITERATIONS: usize = 60;

/// The other starts of the coarsest mesh: the configured analytic schedule
/// (`configured`, unless it is the seed), whose designs end in another
/// local optimum of the peak than the phased seed's. The lower coarse
/// design is continued, so the two seeds share a basin. More analytic
/// starts (other bends and splits) lowered the designs a little further
/// but made them several times slower, so there is one (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
fn other_starts(spec: &DesignSpec, configured: bool) -> Vec<DesignSpec> {
    if configured {
        vec![spec.clone()]
    } else {
        Vec::new()
    }
}

/// An SCP solution before verification.
struct Solved {
    /// With `z` in physical units and the objective in its physical unit.
    res: crate::design::scp::ScpResult,
    z_scaled: Vec<f64>,
    plan: CollocationPlan,
    attitude_error: f64,
    /// Peak at the check points, N m.
    node_peak: f64,
    /// The check points added to the grid's ([`FreeProblem::with_extra_checks`]).
    extra: [Vec<(usize, f64)>; 3],
}

impl FreeProblem {
    /// Whether a neighbour's multipliers fit this problem's rows.
    fn multipliers_fit(&self, m: &crate::design::scp::Multipliers) -> bool {
        let terms = if self.objective == Objective::Time {
            0
        } else {
            self.torques_len()
        };
        let limited = if self.max_torque.is_some() {
            self.torques_len()
        } else {
            0
        };
        m.terms.len() == terms && m.limited.len() == limited
    }
}

/// The SCP from a start `z0` in physical units (durations in s) at `nodes`
/// per phase: the durations are fitted into the available time (F3 time
/// scaling of the same path; not for the `time` objective, which has no
/// budget) and the start is projected onto the exact constraints (ends at
/// rest, continuity, defects, bend and speed limits), so that every
/// subproblem is feasible at `dz = 0`.
fn design(
    spec: &DesignSpec,
    z0: &[f64],
    warm: Option<&WarmStart>,
    nodes: usize,
    mesh: Mesh,
    first: usize,
    observe: impl FnMut(&ScpIteration),
) -> Result<Solved> {
    check_resolvable(spec, nodes)?;
    design_problem(
        spec,
        FreeProblem::on(spec, grid(spec, nodes, mesh), z0),
        z0,
        warm,
        mesh,
        first,
        observe,
    )
}

/// [`design`] of a given problem (its start may be another than `spec`'s: a replan).
fn design_problem(
    spec: &DesignSpec,
    problem: FreeProblem,
    z0: &[f64],
    warm: Option<&WarmStart>,
    mesh: Mesh,
    first: usize,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<Solved> {
    let tr = problem.tr;
    // what a mesh of the continuation means: its problem and SCP settings
    let (problem, max_iterations, tolerance, conic) = match mesh {
        Mesh::Coarse => (
            problem.at_nodes_only(),
            if spec.uses_envelope() {
                ENVELOPE_COARSE_MAX_ITERATIONS
            } else {
                COARSE_MAX_ITERATIONS
            }
            .min(spec.free.max_iterations),
            COARSE_TOLERANCE.max(spec.free.tolerance),
            ConicSettings::COARSE,
        ),
        Mesh::Final => (
            problem,
            spec.free.max_iterations,
            spec.free.tolerance,
            ConicSettings::MODEL,
        ),
    };
    problem
        .objective
        .check_bounded(problem.max_torque.is_some() || problem.max_speed.is_some())?;
    let mut z0 = problem.to_scaled(z0);
    let total: f64 = (0..3).map(|p| z0[tr.duration(p)]).sum();
    if (total > 1.0 && problem.objective != Objective::Time) || problem.fills_the_fall {
        for p in 0..3 {
            z0[tr.duration(p)] /= total;
        }
    }
    let z0 = problem.project(&z0)?;
    let settings = ScpSettings {
        max_iterations,
        tolerance,
        feasibility: spec.free.attitude_tolerance,
        conic,
        screen: spec.free.screen_limits,
        ..Default::default()
    };
    let unit = problem.objective_unit();
    // a neighbour's multipliers that do not fit this problem's rows (added
    // check points) are dropped; its weight and radius still hold
    let stripped;
    let warm = match warm {
        Some(w) if !problem.multipliers_fit(&w.multipliers) => {
            stripped = WarmStart {
                multipliers: Default::default(),
                ..w.clone()
            };
            Some(&stripped)
        }
        w => w,
    };
    let mut res = Executor::new(&settings)
        .warm(warm)
        .numbered_from(first)
        .run(&problem, z0, &mut |it: &ScpIteration| {
            observe(&it.in_units(unit))
        })?;
    for it in res.iterations.iter_mut() {
        *it = it.in_units(unit);
    }
    res.objective *= unit;
    let node_peak = crate::design::scp::peak_of(&problem.torques(&res.z), 2, problem.norm)
        * problem.torque_unit;
    let attitude_error = problem.terminal_error(&res.z);
    if res.termination == crate::design::scp::Termination::Unsolvable {
        // an error, as before the executor kept its point: the callers'
        // fallbacks (another seed, the plain start) key on it
        return Err(crate::error::Error::Solver {
            what: format!("SCP subproblem {}", first + res.iterations.len()),
            status: format!(
                "Unsolvable ({} failures in a row, however small the trust region)",
                settings.trust.max_failures + 1
            ),
            hint: format!(
                "The design's last point misses the landing by {:.3} deg. Try another seed (--seed), more free.nodes, or report the config",
                attitude_error.to_degrees()
            ),
        });
    }
    let z_scaled = std::mem::take(&mut res.z);
    res.z = problem.to_physical(&z_scaled);
    // (the momentum's torque needs the attitude: from a start at rest, none)
    let track = problem.release.filter(|_| problem.spins()).map(|r| {
        crate::design::release::Track::new(
            r.in_seconds(problem.time_unit),
            &problem.cat,
            &tr,
            &res.z,
        )
    });
    let plan = CollocationPlan {
        tr,
        z: res.z.clone(),
        track,
    };
    Ok(Solved {
        res,
        z_scaled,
        plan,
        attitude_error,
        node_peak,
        extra: problem.extra.clone(),
    })
}

/// Makes the solution exact where the check points are not: the torque
/// between check points may leave the envelope by the mesh's second-order
/// error, so while a written row is outside it the manoeuvre is slowed
/// down (the same path, F2: torque falls as `1 / s^2`, speed as `1 / s`),
/// when the fall leaves room (always for `time`), or else the problem is
/// solved again with the limit tightened by the excess.
fn inside_envelope(
    spec: &DesignSpec,
    mut solved: Solved,
    nodes: usize,
    first: usize,
    observe: &mut dyn FnMut(&ScpIteration),
) -> Result<Solved> {
    let motor = spec.motor;
    if motor.max_torque.is_none() {
        // the speed limit holds exactly (Bernstein bound)
        return Ok(solved);
    }
    let tr = solved.plan.tr;
    let mut tight = spec.clone();
    for _ in 0..8 {
        // on the dense samples, not the written rows alone: a design solved
        // again with a tightened limit is not searched between its check
        // points, and the simulators' steps fall between the rows
        let margins = crate::design::envelope::dense_margin(spec, &solved.plan);
        let margin = margins(1.0);
        if margin >= -1e-7 {
            break;
        }
        // the least slow-down that brings every sample inside (a guess from
        // the margin alone overshot the least time: docs/benchmarks.md)
        let stretch = crate::design::envelope::least_stretch_of(&margins);
        let total: f64 = solved.plan.phase_bounds()[3];
        // slowing the same path down keeps its attitude only at zero
        // momentum (F2; F10): from a spinning start the problem is solved again
        let room = (spec.objective == Objective::Time
            || total * stretch <= spec.available_time() * (1.0 + 1e-12))
            && !spec.has_momentum();
        if room {
            for p in 0..3 {
                let i = tr.duration(p);
                solved.plan.z[i] *= stretch;
                solved.res.z[i] *= stretch;
                solved.z_scaled[i] *= stretch;
            }
            solved.node_peak /= stretch * stretch;
        } else {
            // |tau + k qd| <= T tightened as a whole: T and the no-load
            // speed shrink together, k = T / w0 stays
            let f = 1.0 + 1.5 * margin;
            tight = tight.with_motor(crate::model::motor::Motor {
                max_torque: tight.motor.max_torque.map(|t| t * f),
                no_load_speed: tight.motor.no_load_speed.map(|w| w * f),
                ..tight.motor
            });
            let mut iterations = std::mem::take(&mut solved.res.iterations);
            let n0 = iterations.len();
            let again = design(
                &tight,
                &solved.plan.z,
                Some(&solved.res.warm),
                nodes,
                Mesh::Final,
                first + n0,
                |it: &ScpIteration| observe(it),
            )?;
            iterations.extend_from_slice(&again.res.iterations);
            solved = again;
            solved.res.iterations = iterations;
        }
    }
    Ok(solved)
}

/// Rounds of [`refine_checks`]: each cuts the excess between check points
/// about fourfold (a point added halfway between two).
const REFINE_ROUNDS: usize = 2;

/// The excess between check points [`refine_checks`] leaves (relative).
const BETWEEN_TOLERANCE: f64 = 1e-4;

/// Limits holding between the check points: where the torque between a
/// design's check points breaks the torque limit (with the torque-speed
/// line), a check point is added there and the design solved again from
/// itself ([`REFINE_ROUNDS`] at most). With the node and the quarter points
/// alone a least-time design can leave the torque-speed line between two
/// checks where a motor reverses, and would then be slowed down as a whole
/// to bring it inside. Not for the peak above its check points (the peak
/// cost without a binding limit): that gained little for more SCP
/// iterations, and the reported peak is the dense one either way
/// (measured: docs/benchmarks.md, "Design settings: the measurements
/// behind them").
fn refine_checks(
    spec: &DesignSpec,
    mut solved: Solved,
    nodes: usize,
    first: usize,
    observe: &mut dyn FnMut(&ScpIteration),
) -> Result<Solved> {
    let mut extra = solved.extra.clone();
    for _ in 0..REFINE_ROUNDS {
        if solved.res.status != ScpStatus::Converged {
            break;
        }
        let from = FreeProblem::on(spec, grid(spec, nodes, Mesh::Final), &solved.res.z)
            .with_extra_checks(extra.clone());
        let found = from.between_checks(&solved.z_scaled, BETWEEN_TOLERANCE);
        if found.iter().all(Vec::is_empty) {
            break;
        }
        for (e, f) in extra.iter_mut().zip(found) {
            e.extend(f);
        }
        let problem = FreeProblem::on(spec, grid(spec, nodes, Mesh::Final), &solved.res.z)
            .with_extra_checks(extra.clone());
        let old = &solved.res.warm;
        let warm = WarmStart {
            multipliers: crate::design::scp::Multipliers {
                terms: problem.padded(&from, &old.multipliers.terms),
                limited: problem.padded(&from, &old.multipliers.limited),
                ..old.multipliers.clone()
            },
            ..old.clone()
        };
        let n0 = solved.res.iterations.len();
        let z0 = solved.res.z.clone();
        let again = design_problem(
            spec,
            problem,
            &z0,
            Some(&warm),
            Mesh::Final,
            first + n0,
            |it: &ScpIteration| observe(it),
        );
        match again {
            Ok(mut again) if again.res.status == ScpStatus::Converged => {
                let mut iterations = std::mem::take(&mut solved.res.iterations);
                iterations.append(&mut again.res.iterations);
                solved = again;
                solved.res.iterations = iterations;
            }
            // the design without the added points stands
            _ => break,
        }
    }
    Ok(solved)
}

/// What a design carries into its SCP beside its start point.
#[derive(Clone, Copy)]
enum Carried<'a> {
    Nothing,
    /// A neighbour's design: its penalty weight, trust radius and
    /// multipliers (when they fit), and the check points it added.
    Neighbour(&'a FreeResult),
    /// The coarse mesh's penalty weight and trust radius (its multipliers
    /// do not fit the finer mesh's rows).
    Coarse(&'a WarmStart),
}

/// Runs the SCP from a start `z0` in physical units (see [`design`]) and
/// keeps the schedule inside the motor envelope (see [`inside_envelope`]);
/// the pipeline, not the design, flies it.
fn optimize_start(
    spec: &DesignSpec,
    z0: &[f64],
    carried: Carried,
    seed: &str,
    nodes: usize,
    first: usize,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<FreeResult> {
    let start = std::time::Instant::now();
    check_resolvable(spec, nodes)?;
    let tr = grid(spec, nodes, Mesh::Final);
    // a neighbour on the same grid hands on the check points it added, so
    // that the design does not find them again one round at a time
    let extra = match carried {
        Carried::Neighbour(p) if p.plan.tr == tr => p.extra_checks.clone(),
        _ => Default::default(),
    };
    let problem = FreeProblem::on(spec, tr, z0).with_extra_checks(extra);
    let warm = match carried {
        Carried::Nothing => None,
        Carried::Neighbour(p) => Some(&p.warm),
        Carried::Coarse(w) => Some(w),
    };
    let solved = design_problem(spec, problem, z0, warm, Mesh::Final, first, &mut observe)?;
    if solved.res.status == ScpStatus::Infeasible && !lands_anyway(spec, &solved) {
        return Err(infeasible(spec, &solved));
    }
    let solved = refine_checks(spec, solved, nodes, first, &mut observe)?;
    let solved = inside_envelope(spec, solved, nodes, first, &mut observe)?;
    if solved.res.status == ScpStatus::Infeasible && !lands_anyway(spec, &solved) {
        return Err(infeasible(spec, &solved));
    }
    let Solved {
        res,
        z_scaled,
        plan,
        attitude_error: att,
        node_peak,
        extra,
    } = solved;
    let tr = plan.tr;
    let solve_time = start.elapsed().as_secs_f64();
    let objective = spec.objective;
    let (peak, objective_value) = dense_objective(spec, &plan);
    let (mut bend, mut twist, mut last_phi) = (0.0f64, 0.0, None::<f64>);
    for p in 0..3 {
        for k in 0..nodes {
            let q = Transcription::get2(&res.z, tr.q(p, k));
            let b = q[0].hypot(q[1]);
            bend = bend.max(b);
            if b > 1e-3 {
                let phi = q[1].atan2(q[0]);
                if let Some(l) = last_phi {
                    twist += crate::model::so3::wrap(phi - l);
                }
                last_phi = Some(phi);
            }
        }
    }
    Ok(FreeResult {
        mode: "free",
        status: res.status,
        objective,
        objective_value,
        manoeuvre_time_s: plan.phase_bounds()[3],
        peak_torque_nm: peak,
        node_peak_torque_nm: node_peak,
        bend_deg: bend.to_degrees(),
        theta_deg: 180.0 - bend.to_degrees(),
        twist_rad: twist,
        phase_durations_s: [0, 1, 2].map(|p| res.z[tr.duration(p)]),
        attitude_error_rad: att,
        seed: seed.into(),
        scp_iterations: res.iterations.len(),
        nodes,
        solve_time_s: solve_time,
        certificate: res.certificate,
        mesh_check: None,
        mesh_levels: vec![MeshLevel {
            nodes,
            scp_iterations: res.iterations.len(),
            converged: res.status == ScpStatus::Converged,
            starts: 1,
            other_iterations: 0,
        }],
        z_scaled,
        warm: res.warm.clone(),
        extra_checks: extra,
        iterations: res.iterations,
        plan,
    })
}

/// Whether a design the SCP left infeasible from another start lands
/// within the landing's tolerance (`land.max_tilt_deg`, else
/// `simulate.flip_tolerance`) and keeps to the motors: the start may leave
/// nothing better (a no-twist cat cannot tilt its spine at zero momentum,
/// F1). Such a design is kept, its status `infeasible`, rather than
/// answered as unlandable; the verdict flags it, with any other limit it
/// breaks (a bend limit it could not keep is named there).
fn lands_anyway(spec: &DesignSpec, solved: &Solved) -> bool {
    if spec.is_default_start() {
        // today's problem: an infeasible design is the motors' answer
        return false;
    }
    let within_tolerance = crate::verdict::Targets::of(spec)
        .landing_tolerance
        .is_some_and(|(deg, _)| solved.attitude_error.to_degrees() <= deg);
    within_tolerance && keeps_to_motors(spec, solved)
}

/// Whether a design keeps to the motors at every written row: the
/// envelope's margin, else the peak against the stall torque.
fn keeps_to_motors(spec: &DesignSpec, solved: &Solved) -> bool {
    if spec.motor.no_load_speed.is_some() || spec.motor.max_speed.is_some() {
        crate::design::envelope::usage_of(spec, &solved.plan)
            .min_margin
            .is_none_or(|m| m >= -crate::verdict::tolerance::ENVELOPE_MARGIN)
    } else {
        spec.motor
            .max_torque
            .is_none_or(|t| solved.node_peak <= t * (1.0 + crate::verdict::tolerance::LIMIT))
    }
}

/// The error when the SCP cannot meet the motor limits in the fall: with a
/// torque limit alone, F7's least height for the design's peak; otherwise
/// the pointer to the `time` objective.
fn infeasible(spec: &DesignSpec, solved: &Solved) -> crate::error::Error {
    let node_peak = solved.node_peak;
    if !spec.is_default_start() && solved.attitude_error > spec.free.attitude_tolerance.max(1e-6) {
        let [w, x, y, z] = spec.release().attitude;
        // the spine's rise above level at release: `(R0 e_z) . e_x`
        let rise = 2.0 * (x * z + w * y);
        let spine_level = rise.abs() < 1e-9;
        if spec.cat.joint == crate::model::Joint::NoTwist && !spec.has_momentum() && spine_level {
            // a roll about a level spine is within reach (F1): under motor
            // limits theirs is the answer (below: the SCP trades the landing
            // for the limits, 120 deg off under 0.02 N m); without, the
            // optimiser's miss
            if !spec.motor.is_limited() {
                return crate::error::Error::Solver {
                    what: "the free-form design".into(),
                    status: "infeasible".into(),
                    hint: format!(
                        "It found no landing from this start: it still lands {:.3} deg from belly-down{}. At rest with a level spine the body can land (F1: its bend circulations turn it about the spine); from near belly-down the seeds' half turns are far from the small turn needed, and the design ended at a local optimum. Another seed may find it (`catflip optimize --mode free --seed analytic`, or `--seed phased`), as may a start rolled a little further",
                        solved.attitude_error.to_degrees(),
                        if spec.max_bend_deg.is_some() {
                            ", within the bend limit"
                        } else {
                            ""
                        }
                    ),
                };
            }
        } else {
            // the landing, not the motors: what the optimiser could not undo;
            // a pitched start is said, with its pitch (a rotation vector's
            // components mix: [10, 0, 15] pitches the spine 1.3 deg)
            let pitch = rise.clamp(-1.0, 1.0).asin().to_degrees();
            let pitched = if spine_level {
                String::new()
            } else {
                format!(
                    "The start pitches the spine {:.3} deg from level (start.rotation_deg is one rotation vector: components set together mix). ",
                    pitch.abs()
                )
            };
            let rate = spec.release().body_rate;
            let about_the_spine = rate[0] == 0.0 && rate[1] == 0.0;
            return crate::error::Error::Unreachable {
                reason: format!(
                    "cannot land belly-down from this start (start.rotation_deg, start.angular_velocity) in the fall from {} m: the free-form design still lands {:.3} deg from belly-down. {pitched}{}",
                    spec.fall.height,
                    solved.attitude_error.to_degrees(),
                    if spec.cat.joint == crate::model::Joint::NoTwist
                        && spec.has_momentum()
                        && about_the_spine
                        && !spine_level
                    {
                        // a spin about the spine does not tumble it (F10)
                        "A spin about the spine turns the body about it (F10); the design did not level the pitched spine with it, and at zero momentum a no-twist cat cannot tilt its spine at all (F1); a start whose spine is level; a universal joint (cat.joint = \"universal\") tilts it, but slowly (F4: the seed pitched 10 deg needs some 40 times the peak from rest)"
                    } else if spec.cat.joint == crate::model::Joint::NoTwist && !spec.has_momentum()
                    {
                        // no height helps: the spine's tilt is out of its reach
                        "At zero momentum a no-twist cat cannot tilt its spine (F1: every bend circulation turns it about the spine), from any height; a start whose spine is level; a universal joint (cat.joint = \"universal\") tilts it, but slowly (F4: the seed pitched 10 deg needs some 40 times the peak from rest)"
                    } else if spec.has_momentum() && about_the_spine {
                        // a spin about the spine tumbles nothing: the turn's timing failed
                        "A spin about the spine turns the body about it, at |L| / I_3 held straight and slower bent (F10), and the design could not time that turn to land belly-down in the time the fall leaves; try a higher fall.height, or another seed (`catflip optimize --mode free --seed analytic`)"
                    } else if spec.has_momentum() {
                        "An end-over-end spin tumbles the spine about the momentum at |L| / I_1 or faster whatever the shape (F8); try a start closer to upside down at rest or a higher fall.height"
                    } else if spec.max_bend_deg.is_some() {
                        // at rest, a universal joint: its reach, not a spin
                        "Within its bend limit, its motors and the time the fall leaves, the design could not turn the body that far; try a higher fall.height, a larger limits.max_bend_deg or a start closer to upside down"
                    } else {
                        "Within its motors and the time the fall leaves, the design could not turn the body that far; try a higher fall.height or a start closer to upside down"
                    }
                ),
            };
        }
    }
    let motor = spec.motor;
    if motor.no_load_speed.is_none()
        && motor.max_speed.is_none()
        && let Err(e) = crate::design::phased::check_limit(
            spec,
            node_peak * spec.available_time().powi(2),
            node_peak,
            "free-form design",
        )
    {
        return e;
    }
    crate::error::Error::BeyondMotors {
        reason: format!(
            "the free-form design cannot keep inside the motor limits in the fall from {} m; `catflip run` (or design.objective = \"time\") gives the least drop height",
            spec.fall.height
        ),
    }
}

/// Continuation: the free-form design for `spec` started from a neighbouring
/// design `prev` (another point of a sweep). The start is `prev`'s solution
/// in dimensionless units, so a change of drop height, margin or gravity
/// (F3) starts exactly at the optimum, and a change of the cat or limits
/// starts next to it; a least-time design's durations are kept in seconds
/// (its answer, which a change of the drop does not move). With the design
/// `before` `prev` (one grid step further back) the start is the secant
/// predictor `2 prev - before`, which moves it along the solution path as
/// well.
fn continue_from(
    spec: &DesignSpec,
    prev: &FreeResult,
    before: Option<&FreeResult>,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<FreeResult> {
    let nodes = spec.free.nodes;
    let tr = grid(spec, nodes, Mesh::Final);
    // the secant from two converged designs on this mesh, its durations
    // kept to at least half the last's; the plain start if it fails
    let same_grid = |r: &FreeResult| r.plan.tr == tr;
    let converged = |r: &FreeResult| same_grid(r) && r.status == ScpStatus::Converged;
    // a time design's durations are its answer, kept in seconds; the others'
    // relative to the fall (F3: a change of the fall alone is none at all)
    let seconds = spec.objective == Objective::Time;
    if let Some(b) = before.filter(|b| converged(b) && converged(prev)) {
        let mut z: Vec<f64> = prev
            .z_scaled
            .iter()
            .zip(&b.z_scaled)
            .map(|(p, b)| 2.0 * p - b)
            .collect();
        for p in 0..3 {
            let i = tr.duration(p);
            z[i] = if seconds {
                let (d, db) = (prev.phase_durations_s[p], b.phase_durations_s[p]);
                (2.0 * d - db).max(0.5 * d)
            } else {
                z[i].max(0.5 * prev.z_scaled[i]) * spec.available_time()
            };
        }
        if let Ok(r) = optimize_start(
            spec,
            &z,
            Carried::Neighbour(prev),
            "continuation",
            nodes,
            0,
            &mut observe,
        ) {
            return Ok(r);
        }
    }
    let mut z0 = if same_grid(prev) {
        prev.z_scaled.clone()
    } else {
        let mut z = tr.sample(&prev.plan);
        let total: f64 = (0..3).map(|p| z[tr.duration(p)]).sum();
        for p in 0..3 {
            z[tr.duration(p)] /= total;
        }
        z
    };
    for p in 0..3 {
        let i = tr.duration(p);
        z0[i] = if seconds {
            prev.phase_durations_s[p]
        } else {
            z0[i] * spec.available_time()
        };
    }
    optimize_start(
        spec,
        &z0,
        Carried::Neighbour(prev),
        "continuation",
        nodes,
        0,
        observe,
    )
}

/// The grid of a design at `nodes` per phase. For a peak-torque design the
/// acceleration may jump at the nodes of its own mesh (`free.torque_jumps`):
/// the peak optimum is bang-bang, and a continuous torque spends an
/// interval below the peak at each sign change. Not on the continuation's
/// coarse meshes (the fine mesh then ended in worse basins); not for the
/// least time or energy, nor inside a torque-speed line or speed limit
/// (slower, for little or no gain: docs/optimisers.md); not from a spinning
/// start, whose attitude map knows the momentum at the nodes and midpoints
/// only (a start at rest, tilted or rolled, has them).
fn grid(spec: &DesignSpec, nodes: usize, mesh: Mesh) -> Transcription {
    let tr = Transcription::new(3, nodes);
    // (`uses_envelope` holds for every objective but the peak torque)
    if spec.free.torque_jumps
        && mesh == Mesh::Final
        && !spec.uses_envelope()
        && !spec.has_momentum()
    {
        tr.with_jumps()
    } else {
        tr
    }
}

/// Turns of the bend direction the mesh resolves: sixteen nodes per turn.
const NODES_PER_TURN: f64 = 16.0;

/// Twist coefficient `C` of F1 at bend `b` (no-twist joint; for the
/// universal joint an estimate, F4).
fn twist_coefficient(cat: &Cat, b: f64) -> f64 {
    let (it, ia) = (cat.i_t(), cat.i_a());
    let (s, c) = ((b / 2.0).sin(), (b / 2.0).cos());
    1.0 - ia * c / (it * s * s + ia * c * c)
}

/// Fails fast when the bend limit is so small that the flip needs more
/// turns of the bend direction (F1, F6: `n = 1 / (2 C)`) than `nodes` per
/// phase can resolve, naming the bend (and the nodes) that would do.
pub fn check_resolvable(spec: &DesignSpec, nodes: usize) -> Result<()> {
    let cat = spec.cat;
    let b = spec.max_bend();
    let turns = 1.0 / (2.0 * twist_coefficient(&cat, b));
    let most = 3.0 * nodes as f64 / NODES_PER_TURN;
    if turns <= most {
        return Ok(());
    }
    // C grows with the bend: bisect for the bend at which `most` turns do
    let (mut lo, mut hi) = (b, std::f64::consts::PI * 0.99);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if 1.0 / (2.0 * twist_coefficient(&cat, mid)) > most {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Err(crate::error::Error::Unreachable {
        reason: format!(
            "at a largest bend of {:.3} deg the flip needs about {turns:.0} turns of the bend direction (F1, F6), more than {nodes} nodes per phase resolve ({most:.0}); set limits.max_bend_deg to at least {:.2} (or free.nodes to at least {:.0})",
            b.to_degrees(),
            (hi.to_degrees() * 100.0).ceil() / 100.0,
            (turns * NODES_PER_TURN / 3.0).ceil()
        ),
    })
}

/// The dense inverse-dynamics peak of a schedule, N m, and the objective's
/// value for it (in [`Objective::unit`]): the peak, the manoeuvre time, or
/// `integral |tau|^2 dt`.
fn dense_objective(spec: &DesignSpec, plan: &dyn ShapePlan) -> (f64, f64) {
    let dense = crate::verify::analyze::dense_samples(spec);
    let (peak, _) = crate::verify::analyze::peak_along(spec, plan, dense);
    let value = match spec.objective {
        Objective::PeakTorque => peak,
        Objective::Time => plan.phase_bounds()[3],
        Objective::Energy => {
            crate::design::envelope::torque_squared_integral(&spec.cat, plan, dense)
        }
    };
    (peak, value)
}

/// Mesh-refinement check: the design re-optimised at twice the nodes per
/// phase, started from the design itself.
#[derive(Debug, Clone, Serialize)]
pub struct MeshCheck {
    pub nodes: usize,
    pub status: ScpStatus,
    pub scp_iterations: usize,
    /// Dense peak of the refined design, N m.
    pub peak_torque_nm: f64,
    /// The objective's value for the refined design, in its unit (the
    /// peak, the manoeuvre time in s, or `integral |tau|^2 dt`).
    pub objective_value: f64,
    /// `(coarse - refined) / refined` of the objective's value.
    pub relative_change: f64,
}

/// Re-optimises `r` at twice its nodes per phase (warm start: the coarse
/// schedule sampled on the fine mesh, with its penalty weight and trust
/// radius, as on a continuation's finer mesh: from the cold weight a check
/// could wander into another basin, which measures the basin, not the
/// mesh).
pub fn mesh_check(spec: &DesignSpec, r: &FreeResult) -> Result<MeshCheck> {
    let nodes = 2 * r.nodes;
    let z0 = grid(spec, nodes, Mesh::Final).sample(&r.plan);
    let fine = design(spec, &z0, Some(&r.warm), nodes, Mesh::Final, 0, |_| {})?;
    let (peak, value) = dense_objective(spec, &fine.plan);
    Ok(MeshCheck {
        nodes,
        status: fine.res.status,
        scp_iterations: fine.res.iterations.len(),
        peak_torque_nm: peak,
        objective_value: value,
        relative_change: (r.objective_value - value) / value,
    })
}

/// Where a free-form design starts.
#[derive(Clone, Copy)]
pub enum Start<'a> {
    /// A seed the design makes itself (the phased design's schedule or the
    /// analytic one).
    Seed(Seed),
    /// A given schedule, named in the result (`phased`, `analytic`, ...).
    Plan(&'a dyn ShapePlan, &'a str),
    /// A neighbouring design (continuation, in the optimiser's
    /// dimensionless units; a least time's durations in seconds) and the one
    /// before it (the secant predictor).
    Warm(&'a FreeResult, Option<&'a FreeResult>),
}

/// The free-form optimiser, configured step by step:
/// `FreeDesign::new(&spec).seed(Seed::Analytic).observe(&mut table).solve()`.
/// By default it starts from the phased seed at `free.nodes` per phase,
/// without the mesh check.
pub struct FreeDesign<'a> {
    spec: &'a DesignSpec,
    start: Start<'a>,
    /// The start's name in the result, where the caller names it.
    named: Option<&'a str>,
    nodes: usize,
    mesh_check: bool,
    observer: Option<&'a mut dyn Observer>,
}

impl<'a> FreeDesign<'a> {
    pub fn new(spec: &'a DesignSpec) -> Self {
        FreeDesign {
            spec,
            start: Start::Seed(Seed::Phased),
            named: None,
            nodes: spec.free.nodes,
            mesh_check: false,
            observer: None,
        }
    }

    /// Start from a seed the design makes ([`Seed::plan`]).
    pub fn seed(mut self, seed: Seed) -> Self {
        self.start = Start::Seed(seed);
        self
    }

    /// Start from a given schedule, named `name` in the result.
    pub fn from_plan(mut self, plan: &'a dyn ShapePlan, name: &'a str) -> Self {
        self.start = Start::Plan(plan, name);
        self
    }

    /// Start from a neighbouring design, `before` the one before it
    /// (continuation; the mesh is always `free.nodes`).
    pub fn warm(mut self, prev: &'a FreeResult, before: Option<&'a FreeResult>) -> Self {
        self.start = Start::Warm(prev, before);
        self
    }

    /// The start's name in the result (`continuation` from
    /// [`FreeDesign::warm`], the seed's or the plan's name otherwise).
    pub fn named(mut self, name: &'a str) -> Self {
        self.named = Some(name);
        self
    }

    /// Collocation nodes per phase (default `free.nodes`).
    pub fn nodes(mut self, nodes: usize) -> Self {
        self.nodes = nodes;
        self
    }

    /// Re-optimise at twice the nodes as a check ([`mesh_check`]).
    pub fn check_mesh(mut self) -> Self {
        self.mesh_check = true;
        self
    }

    /// Who sees each iteration (and, with mesh continuation, each mesh).
    pub fn observe(mut self, observer: &'a mut dyn Observer) -> Self {
        self.observer = Some(observer);
        self
    }

    /// [`FreeDesign::observe`] with a closure that sees the iterations only.
    pub fn on_iteration<F: FnMut(&ScpIteration)>(self, f: &'a mut F) -> Self {
        self.observe(f)
    }

    /// The coarse meshes of a design from a given schedule
    /// ([`FreeDesign::from_plan`]), to be ranked and finished
    /// ([`Staged::finish`]); the observer sees the coarse iterations. The
    /// mesh check ([`FreeDesign::check_mesh`]) is not made.
    pub fn coarse_stage(self) -> Result<Staged> {
        let Start::Plan(plan, name) = self.start else {
            return Err(crate::error::Error::Usage(
                "a staged free-form design starts from a given schedule".into(),
            ));
        };
        check_resolvable(self.spec, self.nodes)?;
        let mut quiet = |_: &ScpIteration| {};
        let observe: &mut dyn Observer = match self.observer {
            Some(o) => o,
            None => &mut quiet,
        };
        // from another start, the way round that leaves less to turn (one
        // way only: the stages are ranked against each other)
        // (and only as far as the start needs: near belly-down)
        let mirrored = crate::design::mirror::mirrored(self.spec, plan)
            .filter(|m| crate::design::mirror::mirror_is_nearer(self.spec, plan, m));
        let way: &dyn ShapePlan = match &mirrored {
            Some(m) => m,
            None => plan,
        };
        let scaled = crate::design::mirror::scaled_to_the_turn(self.spec, way);
        let mut staged = match &scaled {
            Some(s) => stage(self.spec, s.as_ref(), name, self.nodes, observe),
            None => stage(self.spec, way, name, self.nodes, observe),
        };
        staged.seed = format!(
            "{name}{}{}",
            if scaled.is_some() {
                crate::design::mirror::SCALED
            } else {
                ""
            },
            if mirrored.is_some() {
                crate::design::mirror::MIRRORED
            } else {
                ""
            }
        );
        Ok(staged)
    }

    pub fn solve(self) -> Result<FreeResult> {
        let spec = self.spec;
        let mut quiet = |_: &ScpIteration| {};
        let observe: &mut dyn Observer = match self.observer {
            Some(o) => o,
            None => &mut quiet,
        };
        let mut r = match self.start {
            Start::Seed(seed) => {
                check_resolvable(spec, self.nodes)?;
                let plan = match seed.plan(spec) {
                    Ok(plan) => plan,
                    // the phased family's least height is not the free-form
                    // design's: say so rather than pass it on as the answer
                    Err(
                        crate::error::Error::Unreachable { reason }
                        | crate::error::Error::BeyondMotors { reason },
                    ) => return Err(crate::error::Error::SeedUnfit { reason }),
                    Err(e) => return Err(e),
                };
                from_plan(spec, plan.as_ref(), seed.name(), self.nodes, observe)?
            }
            Start::Plan(plan, name) => from_plan(spec, plan, name, self.nodes, observe)?,
            Start::Warm(prev, before) => {
                continue_from(spec, prev, before, |it| observe.iteration(it))?
            }
        };
        if let Some(name) = self.named {
            r.seed = name.to_string();
        }
        if self.mesh_check {
            r.mesh_check = Some(mesh_check(spec, &r)?);
        }
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_start_with_momentum_and_no_time_objective_fills_the_fall() {
        let spec = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            crate::test_support::spec_of(include_str!("../../configs/seed.toml"), "seed", &sets)
        };
        let fills = |s: &DesignSpec| {
            let tr = Transcription::new(3, 8);
            let z0 = tr.sample(&crate::design::analytic::analytic_plan(s));
            let p = FreeProblem::on(s, tr, &z0);
            // the durations' row: among the equalities exactly when it fills
            let d = p.projection_data(&p.to_scaled(&z0));
            let zeros: usize = d
                .cones
                .iter()
                .map(|c| match c {
                    Cone::Zero(k) => *k,
                    _ => 0,
                })
                .sum();
            (p.fills_the_fall, zeros)
        };
        let (rest, zeros) = fills(&spec(&[]));
        assert!(!rest);
        let spin = spec(&["start.angular_velocity=[0.1, 0, 0.3]"]);
        assert_eq!(fills(&spin), (true, zeros + 1));
        assert!(!fills(&spin.with_objective(Objective::Time)).0);
        assert!(!fills(&spec(&["start.rotation_deg=[0, 0, 20]"])).0);
        assert!(
            fills(&spec(&[
                "start.angular_velocity=[0, 0, 0.3]",
                "design.objective=\"energy\""
            ]))
            .0
        );
    }

    #[test]
    fn the_continuation_coarsens_by_a_third_then_a_half_down_to_twenty_nodes() {
        let chain = |mut n: usize| {
            let mut meshes = vec![n];
            while let Some(c) = coarser(n) {
                meshes.push(c);
                n = c;
            }
            meshes
        };
        assert_eq!(chain(40), [40, 20]);
        assert_eq!(chain(60), [60, 20]);
        assert_eq!(chain(120), [120, 40, 20]);
        assert_eq!(chain(80), [80, 26]);
        assert_eq!(chain(39), [39]);
        for n in 1..400 {
            let c = chain(n);
            assert!(c[1..].iter().all(|&m| m >= COARSEST_NODES), "{c:?}");
            assert!(
                c.windows(2).all(|w| w[1] == w[0] / 3 || w[1] == w[0] / 2),
                "{c:?}"
            );
        }
    }

    #[test]
    fn torque_hessian_matches_second_differences_of_the_inverse_dynamics() {
        for joint in [crate::model::Joint::NoTwist, crate::model::Joint::Universal] {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
            let spec = crate::test_support::spec_at(path, &[format!("cat.joint={}", joint.name())]);
            let cat = spec.cat;
            let x = [0.4, -0.3, 1.2, 0.7, -2.0, 3.0];
            let y = [0.8, -1.3];
            let base = ShapeTerms::second(&cat, [x[0], x[1]]);
            let g0 = torque_gradients(&cat, &x, Some(&base));
            let g = weighted_torque_hessian(&cat, &base, &g0, x, y);
            let f = |x: [f64; 6]| {
                let t = inverse_dynamics_at(&cat, x);
                y[0] * t[0] + y[1] * t[1]
            };
            let h = 1e-4;
            for i in 0..6 {
                for j in 0..6 {
                    let at = |si: f64, sj: f64| {
                        let mut z = x;
                        z[i] += si * h;
                        z[j] += sj * h;
                        f(z)
                    };
                    let fd = (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0))
                        / (4.0 * h * h);
                    assert!(
                        (fd - g[i][j]).abs() < 1e-5 * (1.0 + fd.abs()),
                        "{joint:?} ({i}, {j}): {fd} vs {}",
                        g[i][j]
                    );
                }
            }
        }
    }

    /// The nodes-only problem is the full one without its midpoints: the
    /// same torques and torque gradients at the nodes, the same Hessian
    /// when the midpoints' multipliers are zero, and a quadrature that
    /// integrates a linear function exactly.
    #[test]
    fn checking_at_the_nodes_only_drops_the_midpoints_and_nothing_else() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let spec = crate::test_support::spec_at(path, &["limits.norm=per-motor".into()]);
        let n = 8;
        let tr = Transcription::new(3, n);
        let z0 = tr.sample(&crate::design::analytic::analytic_plan(&spec));
        let full = FreeProblem::new(&spec, n, &z0).with_checks(2);
        let nodes = FreeProblem::new(&spec, n, &z0).at_nodes_only();
        let z = full.to_scaled(&z0);
        assert_eq!(nodes.torques_len(), 3 * 2 * n);
        assert_eq!(full.torques_len(), 3 * 2 * (2 * n - 1));
        // full point 2k of each phase is node k
        let node_of = |r: usize| {
            let (ph, rest) = (r / (2 * n), r % (2 * n));
            ph * 2 * (2 * n - 1) + 2 * 2 * (rest / 2) + rest % 2
        };
        let (lf, ln) = (full.linearize(&z), nodes.linearize(&z));
        assert_eq!(ln.terms.len(), nodes.torques_len());
        for (r, v) in ln.terms.iter().enumerate() {
            assert_eq!(*v, lf.terms[node_of(r)], "row {r}");
        }
        let grads = |jac: &Triplets, row: usize| {
            let mut g: Vec<(usize, f64)> = jac
                .iter()
                .filter(|e| e.0 == row)
                .map(|e| (e.1, e.2))
                .collect();
            g.sort_by_key(|e| e.0);
            g
        };
        for r in [0, 5, 2 * n + 3, 6 * n - 1] {
            assert_eq!(
                grads(&ln.terms_jac, r),
                grads(&lf.terms_jac, node_of(r)),
                "row {r}"
            );
        }
        // multipliers on the nodes only: the same curvature
        let y_nodes: Vec<f64> = (0..nodes.torques_len())
            .map(|i| (i % 5) as f64 - 2.0)
            .collect();
        let mut y_full = vec![0.0; full.torques_len()];
        for (r, y) in y_nodes.iter().enumerate() {
            y_full[node_of(r)] = *y;
        }
        let dense = |t: Triplets| {
            let mut m = std::collections::BTreeMap::new();
            for (i, j, v) in t {
                *m.entry((i, j)).or_insert(0.0) += v;
            }
            m.retain(|_, v: &mut f64| *v != 0.0);
            m
        };
        let (hf, hn) = (
            dense(full.hessian(&z, &y_full, &[])),
            dense(nodes.hessian(&z, &y_nodes, &[])),
        );
        assert!(!hn.is_empty());
        assert_eq!(hf.len(), hn.len());
        for (k, v) in &hn {
            assert!(
                (v - hf[k]).abs() <= 1e-12 * v.abs().max(1.0),
                "{k:?}: {v} vs {}",
                hf[k]
            );
        }
        // trapezoid weights: 1 and s integrate to 1 and 1/2
        let w = nodes.quadrature();
        assert_eq!(w.len(), n);
        let s_at = |k: usize| k as f64 / (n - 1) as f64;
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!((w.iter().enumerate().map(|(k, w)| w * s_at(k)).sum::<f64>() - 0.5).abs() < 1e-14);
    }

    /// A check point added between the regular ones is the regular point
    /// of a finer pattern at the same fraction: the same torque row, the
    /// same gradient, the same curvature; multipliers padded with zeros for
    /// it leave the Hessian as it was; and the search between check points
    /// finds only points above the torque limit, at least one on the
    /// analytic schedule's coarse mesh under a limit below its peak.
    #[test]
    fn an_added_check_point_is_a_finer_patterns_point_and_nothing_else() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let spec = crate::test_support::spec_at(path, &["limits.norm=per-motor".into()]);
        let n = 8;
        let tr = Transcription::new(3, n);
        let z0 = tr.sample(&crate::design::analytic::analytic_plan(&spec));
        let plain = FreeProblem::new(&spec, n, &z0);
        let fine = FreeProblem::new(&spec, n, &z0).with_checks(8);
        // (phase, interval, eighths)
        let added = [(1, 2, 1), (1, 4, 5), (2, 0, 3)];
        let mut extra: [Vec<(usize, f64)>; 3] = Default::default();
        for (p, k, j) in added {
            extra[p].push((k, j as f64 / 8.0));
        }
        let more = FreeProblem::new(&spec, n, &z0).with_extra_checks(extra);
        assert_eq!(more.torques_len(), plain.torques_len() + 2 * added.len());
        let z = plain.to_scaled(&z0);
        let (lm, lf) = (more.linearize(&z), fine.linearize(&z));
        let grads = |jac: &Triplets, row: usize| {
            let mut g: Vec<(usize, f64)> = jac
                .iter()
                .filter(|e| e.0 == row && e.2 != 0.0)
                .map(|e| (e.1, e.2))
                .collect();
            g.sort_by_key(|e| e.0);
            g
        };
        let dense = |t: Triplets| {
            let mut m = std::collections::BTreeMap::new();
            for (i, j, v) in t {
                *m.entry((i, j)).or_insert(0.0) += v;
            }
            m.retain(|_, v: &mut f64| *v != 0.0);
            m
        };
        let mut seen = [0usize; 3];
        for (p, k, j) in added {
            // the added point's index in `more` and the regular one's in `fine`
            let a = more.first_point(p) + more.points_per_phase() + seen[p];
            seen[p] += 1;
            let b = fine.first_point(p) + 8 * k + j;
            for i in 0..2 {
                assert!((lm.terms[2 * a + i] - lf.terms[2 * b + i]).abs() < 1e-14);
                assert_eq!(
                    grads(&lm.terms_jac, 2 * a + i),
                    grads(&lf.terms_jac, 2 * b + i)
                );
            }
            let mut ym = vec![0.0; more.torques_len()];
            let mut yf = vec![0.0; fine.torques_len()];
            (ym[2 * a], ym[2 * a + 1]) = (0.7, -1.3);
            (yf[2 * b], yf[2 * b + 1]) = (0.7, -1.3);
            let (hm, hf) = (
                dense(more.hessian(&z, &ym, &[])),
                dense(fine.hessian(&z, &yf, &[])),
            );
            assert!(!hm.is_empty());
            assert_eq!(hm.len(), hf.len());
            for (key, v) in &hm {
                assert!((v - hf[key]).abs() <= 1e-12 * v.abs().max(1.0), "{key:?}");
            }
        }
        // padded multipliers: the added points carry none
        let y: Vec<f64> = (0..plain.torques_len())
            .map(|i| (i % 7) as f64 - 3.0)
            .collect();
        let yp = more.padded(&plain, &y);
        assert_eq!(yp.len(), more.torques_len());
        let (hp, hm) = (
            dense(plain.hessian(&z, &y, &[])),
            dense(more.hessian(&z, &yp, &[])),
        );
        assert_eq!(hp.len(), hm.len());
        for (key, v) in &hp {
            assert!((v - hm[key]).abs() <= 1e-12 * v.abs().max(1.0), "{key:?}");
        }
        // the search, under a limit of nine tenths of the checked peak (the
        // analytic schedule's, at its phases' ends): every point found is
        // above the limit, and none without a limit
        assert!(plain.between_checks(&z, 1e-4).iter().all(Vec::is_empty));
        let peak = crate::design::scp::peak_of(&plain.torques(&z), 2, plain.norm);
        let limit = 0.9 * peak * plain.torque_unit;
        let limited = crate::test_support::spec_at(
            path,
            &[
                "limits.norm=per-motor".into(),
                format!("limits.max_torque={limit}"),
            ],
        );
        let found = FreeProblem::new(&limited, n, &z0)
            .at_nodes_only()
            .between_checks(&z, 1e-4);
        assert!(found.iter().any(|f| !f.is_empty()));
        for (p, f) in found.iter().enumerate() {
            for &(k, c) in f {
                let pt = FreeProblem::new(&spec, n, &z0).with_extra_checks({
                    let mut e: [Vec<(usize, f64)>; 3] = Default::default();
                    e[p].push((k, c));
                    e
                });
                let tau = pt.torques(&z);
                let i = 2 * (pt.first_point(p) + pt.points_per_phase());
                assert!(plain.norm.of([tau[i], tau[i + 1]]) > 0.9 * peak * (1.0 + 1e-4));
            }
        }
    }

    #[test]
    fn the_hessian_reads_the_linearisations_shape_terms_only_at_the_same_point() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let spec = crate::test_support::spec_at(path, &[]);
        let tr = Transcription::new(3, 8);
        let z0 = tr.sample(&crate::design::analytic::analytic_plan(&spec));
        let fresh = || FreeProblem::new(&spec, 8, &z0);
        let p = fresh();
        let z = p.to_scaled(&z0);
        let mut moved = z.clone();
        moved[tr.q(1, 3)] += 0.05;
        let y: Vec<f64> = (0..p.torques_len()).map(|i| (i % 7) as f64 - 3.0).collect();
        // without a linearisation (nothing cached) the shape terms are computed
        let want = fresh().hessian(&z, &y, &[]);
        let _ = p.linearize(&z);
        // the linearisation keeps every check point's terms under its shape,
        // in the order the Hessian indexes them (phase p's point i at
        // p (2N - 1) + i), so that the Hessian finds them
        let shapes: Vec<[f64; 2]> = (0..3)
            .flat_map(|ph| p.check_points(&z, ph).into_iter().map(|c| c.1))
            .collect();
        let kept: Vec<[f64; 2]> = p.second_terms.borrow().iter().map(|e| e.0).collect();
        assert_eq!(kept, shapes);
        assert_eq!(shapes.len(), 3 * (CHECKS_PER_INTERVAL * 7 + 1));
        assert_eq!(p.hessian(&z, &y, &[]), want, "cached at the same point");
        // a linearisation elsewhere must not stand in for this point
        let _ = p.linearize(&moved);
        assert_eq!(p.hessian(&z, &y, &[]), want, "cached elsewhere");
        assert_ne!(p.hessian(&moved, &y, &[]), want);
    }

    /// The design mesh's quadrature is composite Simpson on its check
    /// points: exact for cubics in `s`, and the points are evenly spaced.
    #[test]
    fn the_check_points_quarter_each_interval_and_integrate_cubics_exactly() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let spec = crate::test_support::spec_at(path, &[]);
        let n = 6;
        let tr = Transcription::new(3, n);
        let z0 = tr.sample(&crate::design::analytic::analytic_plan(&spec));
        let p = FreeProblem::new(&spec, n, &z0);
        assert_eq!(p.points_per_phase(), CHECKS_PER_INTERVAL * (n - 1) + 1);
        let w = p.quadrature();
        let s_at = |i: usize| i as f64 / (p.points_per_phase() - 1) as f64;
        for (k, exact) in [1.0, 0.5, 1.0 / 3.0, 0.25].into_iter().enumerate() {
            let q: f64 = w
                .iter()
                .enumerate()
                .map(|(i, w)| w * s_at(i).powi(k as i32))
                .sum();
            assert!((q - exact).abs() < 1e-14, "s^{k}: {q} vs {exact}");
        }
        // the points' normalised times, from their interval and coefficient
        let z = p.to_scaled(&z0);
        let h = tr.h();
        for (i, (k, q, ..)) in p.check_points(&z, 1).into_iter().enumerate() {
            let c = (s_at(i) - k as f64 * h) / h;
            let want = tr.interval(&z, 1, k).at(c).q;
            assert!(
                (q[0] - want[0]).abs() < 1e-12 && (q[1] - want[1]).abs() < 1e-12,
                "point {i}"
            );
        }
    }

    /// With jumps each interval checks both its ends (a node's left and
    /// right limits), and the quadrature is Simpson interval by interval:
    /// exact for a cubic that steps at a node.
    #[test]
    fn with_jumps_both_sides_of_each_node_are_checked_and_integrated() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let spec = crate::test_support::spec_at(path, &[]);
        let n = 6;
        let m = CHECKS_PER_INTERVAL;
        let tr = Transcription::new(3, n).with_jumps();
        let z0 = tr.sample(&crate::design::analytic::analytic_plan(&spec));
        let p = FreeProblem::on(&spec, tr, &z0);
        assert_eq!(p.points_per_phase(), (m + 1) * (n - 1));
        let z = p.to_scaled(&z0);
        let pts = p.check_points(&z, 1);
        let w = p.quadrature();
        assert_eq!(
            (pts.len(), w.len()),
            (p.points_per_phase(), p.points_per_phase())
        );
        let h = tr.h();
        for (k, exact) in [1.0, 0.5, 1.0 / 3.0, 0.25].into_iter().enumerate() {
            // s^k plus a unit step at node 2: its left limit is interval
            // 1's last point, its right limit interval 2's first
            let mut q = 0.0;
            for (i, (interval, _, _, _, coef)) in pts.iter().enumerate() {
                let c = coef[2][3];
                assert_eq!(*interval, i / (m + 1), "point {i}");
                assert!((c - (i % (m + 1)) as f64 / m as f64).abs() < 1e-15);
                let s = (*interval as f64 + c) * h;
                let step = if *interval >= 2 { 1.0 } else { 0.0 };
                q += w[i] * (s.powi(k as i32) + step);
            }
            let want = exact + 1.0 - 2.0 * h;
            assert!((q - want).abs() < 1e-14, "s^{k} + step: {q} vs {want}");
        }
    }

    /// Slowing a schedule down by `s` divides its torques by `s^2` and its
    /// speeds by `s` (F3), so the least stretch found on the rows is the
    /// least one for the slowed plan: inside the envelope at it, outside
    /// just below it.
    #[test]
    fn the_least_stretch_brings_the_slowed_schedule_just_inside_the_envelope() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml");
        let load = |extra: &[String]| {
            let mut o = vec!["limits.norm=per-motor".to_string()];
            o.extend_from_slice(extra);
            crate::test_support::spec_at(path, &o)
        };
        let spec = load(&[]);
        let tr = Transcription::new(3, 12);
        let plan = CollocationPlan::new(
            tr,
            tr.sample(&crate::design::analytic::analytic_plan(&spec)),
        );
        let rows = crate::design::plan::Schedule::sample(&spec.cat, &plan, 50).rows;
        let peak = rows
            .iter()
            .map(|r| r.tau[0].abs().max(r.tau[1].abs()))
            .fold(0.0, f64::max);
        let top = rows
            .iter()
            .map(|r| r.qd[0].abs().max(r.qd[1].abs()))
            .fold(0.0, f64::max);
        // a torque-speed line 20 % short of the schedule's peak
        let spec = load(&[
            format!("limits.max_torque={}", 0.8 * peak),
            format!("limits.no_load_speed={}", 4.0 * top),
            "simulate.samples_per_phase=50".into(),
        ]);
        let s = crate::design::envelope::least_stretch(&spec, &plan);
        assert!(s > 1.05 && s < 3.0, "{s}");
        let slowed = |f: f64| {
            let mut p = plan.clone();
            for ph in 0..3 {
                p.z[tr.duration(ph)] *= f;
            }
            let dense = crate::verify::analyze::dense_samples(&spec);
            let rows = crate::design::plan::Schedule::sample(&spec.cat, &p, dense).rows;
            spec.motor
                .usage(rows.iter().map(|r| (r.tau, r.qd)))
                .min_margin
                .unwrap()
        };
        assert!(slowed(s) >= -1e-9, "{}", slowed(s));
        assert!(slowed(s * (1.0 - 1e-6)) < 0.0);
        // nothing to do inside the envelope
        assert_eq!(
            crate::design::envelope::least_stretch(
                &load(&[format!("limits.max_torque={}", 2.0 * peak)]),
                &plan,
            ),
            1.0
        );
    }

    fn inverse_dynamics_at(cat: &Cat, x: [f64; 6]) -> [f64; 2] {
        crate::model::dynamics::inverse_dynamics(cat, [x[0], x[1]], [x[2], x[3]], [x[4], x[5]])
    }

    #[test]
    fn psd_part_clips_negative_curvature_only() {
        let a = nalgebra::SMatrix::<f64, 9, 9>::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 - 2.0);
        let sym = a + a.transpose();
        let p = psd_part(sym);
        let e = nalgebra::SymmetricEigen::new(p).eigenvalues;
        assert!(e.iter().all(|&v| v > -1e-12));
        // a PSD matrix is its own PSD part
        let q = a * a.transpose();
        assert!((psd_part(q) - q).norm() < 1e-10 * q.norm());
        // and the clipped part is PSD with sym - p negative semidefinite
        let n = nalgebra::SymmetricEigen::new(sym - p).eigenvalues;
        assert!(n.iter().all(|&v| v < 1e-12));
    }
}
