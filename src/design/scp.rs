//! Successive convexification for least-peak problems.
//!
//! A problem is: minimise `max_k |f_k(z)|` (Euclidean or per-component norm)
//! subject to nonlinear equalities `r(z) = 0` and exact convex constraints
//! (linear rows and second-order cones on affine functions of `z`). Each
//! iteration linearises `f` and `r` about the current `z`, adds virtual
//! controls `nu = nu+ - nu-` to the linearised equalities (penalised by `w |nu|_1`,
//! which keeps every subproblem feasible), bounds the step by a scaled trust
//! region, and solves one conic program with Clarabel; the data pattern is the
//! same every iteration, so the solver is updated in place.
//!
//! Steps are judged on the exact penalty `phi(z) = max_k |f_k(z)| + w |r(z)|_1`:
//! `rho = (phi(z) - phi(z + dz)) / (phi(z) - L(dz))` with `L` the subproblem's
//! model value. When `rho < 0.75` a second-order correction (one more conic
//! solve, see [`correction`]) is tried and kept if it lowers `phi`. Accepted
//! when `rho > 0.1` (so an accepted step never increases `phi`); the radius
//! halves when `rho < 0.1` and doubles when `rho > 0.5`.
//! Stop: criticality (the predicted decrease at unit radius relative to
//! `phi`, see [`ScpIteration::criticality`]) below `tolerance`, or a merit
//! that fell by less than `tolerance` (relative) per iteration on average
//! over the last `window` iterations, with `max |r| <= feasibility` (converged; the certificate
//! names the rule); the penalty grows tenfold when the
//! model stalls while still infeasible; an iteration limit or a collapsed
//! trust region (stalled) end the run.

use crate::design::conic::{Cone, ConicData, ConicSolver, SolveStatus, solve_reusing};
use crate::error::{Error, Result};
use crate::model::TorqueNorm;
use serde::Serialize;
use std::time::Instant;

/// Sparse Jacobian rows: `(row, column, value)`; the set of entries must not
/// depend on `z` (emit zeros too), so the conic pattern stays fixed.
pub type Triplets = Vec<(usize, usize, f64)>;

/// Values and Jacobians at one point.
#[derive(Debug, Clone, Default)]
pub struct Linearization {
    /// `f_k(z)`, each of length `term_dim`, flattened.
    pub terms: Vec<f64>,
    /// Jacobian of the flattened terms.
    pub terms_jac: Triplets,
    /// `r(z)`.
    pub residual: Vec<f64>,
    pub residual_jac: Triplets,
}

/// A least-peak problem the driver can convexify.
pub trait ScpProblem {
    /// Number of decision variables.
    fn dim(&self) -> usize;
    /// Length of each peak term `f_k`.
    fn term_dim(&self) -> usize;
    fn norm(&self) -> TorqueNorm;
    /// `(terms, residual)` without derivatives (merit evaluation).
    fn evaluate(&self, z: &[f64]) -> (Vec<f64>, Vec<f64>);
    fn linearize(&self, z: &[f64]) -> Linearization;
    /// Adds the exact convex constraints in the step `dz = x[var(i)]`,
    /// i.e. in `z + dz`. The rows must have a fixed pattern.
    fn add_constraints(&self, data: &mut ConicData, z: &[f64], var: &dyn Fn(usize) -> usize);
    /// Trust-region scale of each variable (the radius is in these units).
    fn scales(&self) -> Vec<f64>;
    /// Optional hard bound on the peak.
    fn peak_limit(&self) -> Option<f64> {
        None
    }
    /// Second-order information: a positive semidefinite approximation of
    /// `sum_r y_r Hess f_r(z)` (`y` one multiplier per flattened term), as
    /// upper-triangle triplets with a pattern that does not depend on `z` or
    /// `y`. The default (none) makes the method sequential linear
    /// programming; with it, the subproblem is an SQP step.
    fn hessian(&self, _z: &[f64], _y: &[f64]) -> Triplets {
        Vec::new()
    }
}

/// Driver settings; defaults in each field's doc.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ScpSettings {
    /// Iteration limit (default 150).
    pub max_iterations: usize,
    /// Converged when the criticality (predicted decrease at unit trust radius
    /// relative to the merit) is below this (default 1e-4).
    pub tolerance: f64,
    /// Largest `|r|` accepted as feasible (default 1e-6).
    pub feasibility: f64,
    /// Initial trust radius in scaled units (default 0.5).
    pub initial_radius: f64,
    /// Iterations over which the merit must fall by `tolerance` (relative)
    /// per iteration on average to keep going (default 10).
    pub window: usize,
    /// Penalty weight relative to the initial peak (default 2): the exact L1
    /// penalty needs only `w > |multiplier|`; a larger one makes the merit's
    /// model more curved and the steps shorter. It grows tenfold when needed.
    pub weight: f64,
}

impl Default for ScpSettings {
    fn default() -> Self {
        Self {
            max_iterations: 150,
            tolerance: 1e-4,
            feasibility: 1e-6,
            initial_radius: 0.5,
            window: 10,
            weight: 2.0,
        }
    }
}

/// One iteration, as reported to the observer.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ScpIteration {
    pub iteration: usize,
    /// Merit before the step.
    pub merit: f64,
    pub peak: f64,
    /// `max |r|` before the step.
    pub infeasibility: f64,
    pub radius: f64,
    pub weight: f64,
    pub predicted: f64,
    pub actual: f64,
    pub rho: f64,
    pub accepted: bool,
    /// Merit after the iteration (equal to `merit` when rejected).
    pub merit_after: f64,
    /// Largest scaled component of the trial step `|dz_i| / scale_i`.
    pub step: f64,
    pub solve_ms: f64,
}

impl ScpIteration {
    /// First-order criticality: the model decrease at unit trust radius,
    /// relative to the merit, bounded above by `predicted / min(radius, 1)`
    /// (the model's optimal value is convex in the radius, so the predicted
    /// decrease is concave in it). Unlike the raw predicted decrease it does
    /// not vanish merely because the trust region has shrunk.
    pub fn criticality(&self) -> f64 {
        self.predicted.max(0.0) / self.merit.abs().max(1e-300) / self.radius.min(1.0)
    }

    /// The record with its peak-valued fields (merit, peak, decreases,
    /// weight) multiplied by `unit`: problems solved in scaled units report
    /// physical ones.
    pub fn in_units(mut self, unit: f64) -> Self {
        self.merit *= unit;
        self.peak *= unit;
        self.weight *= unit;
        self.predicted *= unit;
        self.actual *= unit;
        self.merit_after *= unit;
        self
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScpStatus {
    Converged,
    IterationLimit,
    /// The trust region shrank to nothing without converging.
    Stalled,
}

/// Why the user may trust the end point: the numbers the stopping rule
/// looked at, at the last iteration.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Certificate {
    /// Largest scaled component of the last step taken (`|dz_i| / scale_i`).
    pub step: f64,
    /// Largest equality-constraint violation `max |r(z)|` at the end point.
    pub constraint_violation: f64,
    /// The method's optimality measure, [`ScpIteration::criticality`] of the
    /// last iteration (zero exactly at a KKT point of the penalised problem;
    /// converged below `tolerance`).
    pub criticality: f64,
    /// Trust-region radius at the end (scaled units).
    pub radius: f64,
    /// Penalty weight at the end, relative to the objective's scale.
    pub weight: f64,
    /// Which test ended a converged run.
    pub rule: StopRule,
}

/// The test that declared convergence (both need `max |r| <= feasibility`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopRule {
    /// Not converged.
    #[default]
    None,
    /// Criticality below `tolerance`: a first-order point of the model.
    Criticality,
    /// The merit fell by less than `tolerance` (relative) per iteration on
    /// average over the last `window` iterations: no further progress at
    /// this tolerance.
    Progress,
}

#[derive(Debug, Clone)]
pub struct ScpResult {
    pub z: Vec<f64>,
    pub status: ScpStatus,
    pub peak: f64,
    pub infeasibility: f64,
    pub iterations: Vec<ScpIteration>,
    pub certificate: Certificate,
    pub warm: WarmStart,
}

fn peak_of(terms: &[f64], d: usize, norm: TorqueNorm) -> f64 {
    terms
        .chunks(d)
        .map(|f| match norm {
            TorqueNorm::Euclidean => f.iter().map(|x| x * x).sum::<f64>().sqrt(),
            TorqueNorm::PerMotor => f.iter().fold(0.0f64, |m, x| m.max(x.abs())),
        })
        .fold(0.0, f64::max)
}

fn merit(p: &dyn ScpProblem, z: &[f64], w: f64) -> (f64, f64, f64) {
    let (terms, r) = p.evaluate(z);
    let peak = peak_of(&terms, p.term_dim(), p.norm());
    let l1: f64 = r.iter().map(|x| x.abs()).sum();
    let inf = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (peak + w * l1, peak, inf)
}

/// The convex subproblem at `z`: variables `[dz, t, nu+, nu-]`.
fn subproblem(
    p: &dyn ScpProblem,
    z: &[f64],
    lin: &Linearization,
    scales: &[f64],
    radius: f64,
    w: f64,
    phi: f64,
    y: &[f64],
) -> (ConicData, TermRows) {
    let n = p.dim();
    let m = lin.residual.len();
    let (t, np, nm) = (n, n + 1, n + 1 + m);
    let mut d = ConicData::new(n + 1 + 2 * m);
    d.q[t] = 1.0;
    for i in 0..m {
        d.q[np + i] = w;
        d.q[nm + i] = w;
    }
    // a light proximal term keeps the step unique where the model is flat
    let mut p_diag = vec![0.0; d.n];
    for i in 0..n {
        p_diag[i] = 1e-9 / (scales[i] * scales[i]);
    }
    d.p_diag = Some(p_diag);
    d.p_upper = p.hessian(z, y);
    let mut term_rows: TermRows = vec![Vec::new(); lin.terms.len()];
    // linearised equalities with virtual control: r + J dz - nu+ + nu- = 0
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
    for &(r, c, v) in &lin.residual_jac {
        rows[r].push((c, v));
    }
    for (i, mut row) in rows.into_iter().enumerate() {
        row.push((np + i, -1.0));
        row.push((nm + i, 1.0));
        d.row(&row, -lin.residual[i]);
    }
    d.cone(Cone::Zero(m));
    p.add_constraints(&mut d, z, &|i| i);
    // peak epigraph
    let dim = p.term_dim();
    let nterms = lin.terms.len() / dim;
    let mut jac: Vec<Vec<(usize, f64)>> = vec![Vec::new(); lin.terms.len()];
    for &(r, c, v) in &lin.terms_jac {
        jac[r].push((c, v));
    }
    match p.norm() {
        TorqueNorm::Euclidean => {
            for k in 0..nterms {
                d.row(&[(t, -1.0)], 0.0);
                for j in 0..dim {
                    let r = k * dim + j;
                    let row: Vec<_> = jac[r].iter().map(|&(c, v)| (c, -v)).collect();
                    // s = f + J dz: the Lagrangian holds -z_row f
                    term_rows[r].push((d.row(&row, lin.terms[r]), -1.0));
                }
                d.cone(Cone::Soc(dim + 1));
            }
        }
        TorqueNorm::PerMotor => {
            for r in 0..lin.terms.len() {
                let mut up = jac[r].clone();
                up.push((t, -1.0));
                term_rows[r].push((d.row(&up, -lin.terms[r]), 1.0));
                let mut down: Vec<_> = jac[r].iter().map(|&(c, v)| (c, -v)).collect();
                down.push((t, -1.0));
                term_rows[r].push((d.row(&down, lin.terms[r]), -1.0));
            }
            d.cone(Cone::Nonneg(2 * lin.terms.len()));
        }
    }
    // nu >= 0, trust region, peak limit
    for i in 0..2 * m {
        d.row(&[(np + i, -1.0)], 0.0);
    }
    for i in 0..n {
        d.row(&[(i, 1.0)], radius * scales[i]);
        d.row(&[(i, -1.0)], radius * scales[i]);
    }
    let mut rows = 2 * m + 2 * n;
    if let Some(lim) = p.peak_limit() {
        // dz = 0 is feasible with model value phi(z), so t <= phi(z) at the
        // subproblem's optimum: a bound above 10 phi never binds, and a huge
        // one (1e12) would only wreck the interior-point scaling
        d.row(&[(t, 1.0)], lim.min(10.0 * phi));
        rows += 1;
    }
    d.cone(Cone::Nonneg(rows));
    (d, term_rows)
}

/// For each flattened term, the subproblem rows it appears in and the sign
/// with which the row's dual multiplies the term in the Lagrangian.
type TermRows = Vec<Vec<(usize, f64)>>;

/// Second-order correction at the trial point `z+ = z + dz`: the least
/// scaled-norm `dc` with `J dc = (r + J dz) - r(z+)` (back onto the model's
/// prediction of the residual) that keeps the exact constraints. This undoes
/// the curvature of `r` (here the attitude's, a holonomy that is quadratic in
/// the path) that would otherwise force tiny trust regions.
fn correction(
    p: &dyn ScpProblem,
    z_trial: &[f64],
    lin: &Linearization,
    target_minus_actual: &[f64],
    scales: &[f64],
) -> ConicData {
    let n = p.dim();
    let m = target_minus_actual.len();
    let mut d = ConicData::new(n);
    d.p_diag = Some(scales.iter().map(|s| 1.0 / (s * s)).collect());
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
    for &(r, c, v) in &lin.residual_jac {
        rows[r].push((c, v));
    }
    for (i, row) in rows.into_iter().enumerate() {
        d.row(&row, target_minus_actual[i]);
    }
    d.cone(Cone::Zero(m));
    p.add_constraints(&mut d, z_trial, &|i| i);
    d
}

/// Fixed-pattern Clarabel solvers reused across iterations.
#[derive(Default)]
struct Solvers {
    subproblem: Option<ConicSolver>,
    correction: Option<ConicSolver>,
}

/// One SCP iteration at `z`: linearise, solve the convex subproblem, try a
/// second-order correction, and judge the trial point. Returns the record
/// (with `accepted` decided) and the trial point.
fn iterate(
    p: &dyn ScpProblem,
    z: &[f64],
    radius: f64,
    w: f64,
    iteration: usize,
    scales: &[f64],
    solvers: &mut Solvers,
    y: &mut Vec<f64>,
) -> Result<(ScpIteration, Vec<f64>)> {
    let (phi, peak, inf) = merit(p, z, w);
    let lin = p.linearize(z);
    y.resize(lin.terms.len(), 0.0);
    let (data, term_rows) = subproblem(p, z, &lin, scales, radius, w, phi, y);
    let clock = Instant::now();
    let (st, x, obj) = solve_reusing(&mut solvers.subproblem, &data)?;
    let solve_ms = clock.elapsed().as_secs_f64() * 1e3;
    if !st.ok() {
        if st == SolveStatus::Infeasible && p.peak_limit().is_some() {
            return Err(Error::Unreachable {
                reason: "the convexified problem has no solution within limits.max_torque: raise the limit or fall.height"
                    .into(),
            });
        }
        return Err(Error::Solver {
            what: format!("SCP subproblem {iteration}"),
            status: format!("{st:?}"),
            hint: "try another seed (--seed), more free.nodes, or report the config".into(),
        });
    }
    let (n, m) = (p.dim(), lin.residual.len());
    // the peak terms' multipliers, for the next subproblem's curvature
    if let Some(sv) = &solvers.subproblem {
        let dual = sv.duals();
        for (yr, rows) in y.iter_mut().zip(&term_rows) {
            *yr = rows.iter().map(|&(row, sign)| sign * dual[row]).sum();
        }
    }
    // model value: t + w |nu|_1 + 1/2 dz' P dz (the solver's objective)
    let predicted = phi - obj;
    let mut trial: Vec<f64> = z.iter().zip(&x[..n]).map(|(a, b)| a + b).collect();
    let (mut phi_t, _, _) = merit(p, &trial, w);
    if predicted > 0.0 && phi - phi_t < 0.75 * predicted {
        // back onto the model's residual at the trial point, r + J dz = nu+ - nu-
        let (_, r_trial) = p.evaluate(&trial);
        let rhs: Vec<f64> = (0..m)
            .map(|i| x[n + 1 + i] - x[n + 1 + m + i] - r_trial[i])
            .collect();
        let cd = correction(p, &trial, &lin, &rhs, scales);
        if let Ok((cs, dc, _)) = solve_reusing(&mut solvers.correction, &cd)
            && cs.ok()
        {
            let corrected: Vec<f64> = trial.iter().zip(&dc).map(|(a, b)| a + b).collect();
            let (phi_c, _, _) = merit(p, &corrected, w);
            if phi_c < phi_t {
                (trial, phi_t) = (corrected, phi_c);
            }
        }
    }
    let step = trial
        .iter()
        .zip(z)
        .zip(scales)
        .fold(0.0f64, |m, ((a, b), s)| m.max((a - b).abs() / s));
    let actual = phi - phi_t;
    let rho = if predicted > 0.0 {
        actual / predicted
    } else {
        0.0
    };
    let accepted = predicted > 0.0 && rho > 0.1;
    let rec = ScpIteration {
        iteration,
        merit: phi,
        peak,
        infeasibility: inf,
        radius,
        weight: w,
        predicted,
        actual,
        rho,
        accepted,
        merit_after: if accepted { phi_t } else { phi },
        step,
        solve_ms,
    };
    Ok((rec, trial))
}

/// The driver: runs [`iterate`] from `z0`, owns the trust radius, the penalty
/// weight and the stopping rules, and reports each iteration to `observe`.
pub fn solve(
    p: &dyn ScpProblem,
    z0: Vec<f64>,
    settings: &ScpSettings,
    observe: impl FnMut(&ScpIteration),
) -> Result<ScpResult> {
    solve_warm(p, z0, None, settings, observe)
}

/// What a finished solve hands to a neighbouring problem (continuation):
/// its peak-term multipliers (the curvature of the first subproblem) and its
/// final trust radius.
#[derive(Debug, Clone, Default)]
pub struct WarmStart {
    pub multipliers: Vec<f64>,
    pub radius: f64,
}

/// [`solve`] with the multipliers and radius of a neighbouring solve.
pub fn solve_warm(
    p: &dyn ScpProblem,
    z0: Vec<f64>,
    warm: Option<&WarmStart>,
    settings: &ScpSettings,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<ScpResult> {
    let scales = p.scales();
    let mut z = z0;
    let (_, peak0, _) = merit(p, &z, 0.0);
    let mut w = settings.weight * peak0.max(1e-12);
    let mut radius = warm.map_or(settings.initial_radius, |w| {
        w.radius.clamp(1e-3, settings.initial_radius)
    });
    let mut solvers = Solvers::default();
    let mut iterations = Vec::new();
    let mut status = ScpStatus::IterationLimit;
    let mut y = warm.map_or_else(Vec::new, |w| w.multipliers.clone());
    let mut window = Vec::new();
    let mut rule = StopRule::None;
    for it in 0..settings.max_iterations {
        let (rec, trial) = iterate(p, &z, radius, w, it, &scales, &mut solvers, &mut y)?;
        observe(&rec);
        iterations.push(rec);
        if rec.accepted {
            z = trial;
        }
        if rec.rho < 0.1 {
            radius *= 0.5;
        } else if rec.rho > 0.5 {
            radius = (radius * 2.0).min(1e3);
        }
        let (phi_now, _, inf_now) = merit(p, &z, w);
        window.push(phi_now);
        let critical = rec.criticality() <= settings.tolerance;
        // the merit fell by less than `tolerance` (relative) per iteration,
        // on average over the window
        let slow = window.len() > settings.window
            && window[window.len() - 1 - settings.window] - phi_now
                <= settings.tolerance * settings.window as f64 * phi_now.abs();
        if critical || slow {
            if inf_now <= settings.feasibility {
                status = ScpStatus::Converged;
                rule = if critical {
                    StopRule::Criticality
                } else {
                    StopRule::Progress
                };
                break;
            }
            // stuck infeasible: the penalty is too weak
            w *= 10.0;
            window.clear();
        }
        if radius < 1e-10 {
            status = ScpStatus::Stalled;
            break;
        }
    }
    let (_, peak, infeasibility) = merit(p, &z, w);
    let last = iterations.last().copied();
    let certificate = Certificate {
        step: last.map_or(0.0, |l| l.step),
        constraint_violation: infeasibility,
        criticality: last.map_or(0.0, |l| l.criticality()),
        radius,
        weight: w / peak0.max(1e-12),
        rule,
    };
    Ok(ScpResult {
        z,
        status,
        peak,
        infeasibility,
        iterations,
        certificate,
        warm: WarmStart {
            multipliers: y,
            radius,
        },
    })
}
