//! Replanning in flight: the free-form design re-solved from a
//! state measured mid-flight over the time the fall still leaves, to the
//! landing set, seeded by the rest of the plan being flown.
//!
//! A [`Replanner`] holds what the replans of one flight share: the conic
//! solvers of the SCP and of the projection (at a fixed mesh every replan's
//! programs have one sparsity pattern, so Clarabel's setup, ordering and
//! symbolic factorisation are done once) and the SCP's end state
//! (multipliers, trust radius, penalty weight). Successive replans of one or
//! a few SCP iterations each then continue one another along the flight: a
//! real-time iteration (RTI), each period's replan starting from the last
//! one's plan, moved to the newly measured state.

use super::{FreeProblem, Objective, Release, Transcription};
use crate::design::collocation_plan::CollocationPlan;
use crate::design::conic::{Cone, ConicData, ConicSettings, ConicSolver, solve_reusing};
use crate::design::plan::ShapePlan;
use crate::design::scp::{Executor, ScpSettings, ScpStatus, Solvers, WarmStart};
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};

/// The rest of a plan from `t0`, as a plan of three phases starting at 0:
/// the phases still to come keep their bounds; when fewer than three remain,
/// the remaining time of the current one is split evenly (a replan's seed).
pub(super) struct Remainder<'a> {
    plan: &'a dyn ShapePlan,
    t0: f64,
    bounds: [f64; 4],
}

impl<'a> Remainder<'a> {
    pub(super) fn new(plan: &'a dyn ShapePlan, t0: f64) -> Self {
        let b = plan.phase_bounds();
        let end = b[3];
        let i = (0..3).find(|&i| t0 < b[i + 1]).unwrap_or(2);
        let cuts: Vec<f64> = match i {
            0 => vec![b[1], b[2]],
            1 => vec![0.5 * (t0 + b[2]), b[2]],
            _ => vec![t0 + (end - t0) / 3.0, t0 + 2.0 * (end - t0) / 3.0],
        };
        Remainder {
            plan,
            t0,
            bounds: [0.0, cuts[0] - t0, cuts[1] - t0, end - t0],
        }
    }
}

impl ShapePlan for Remainder<'_> {
    fn phase_bounds(&self) -> Vec<f64> {
        self.bounds.to_vec()
    }
    fn state_in(&self, i: usize, t: f64) -> crate::design::plan::ShapeState {
        let mut s = self.plan.state(self.t0 + t);
        s.phase = crate::design::plan::Phase::ALL[i.min(2)];
        s
    }
}

/// A replan: the free-form design from a state measured in flight.
#[derive(Debug, Clone)]
pub struct Replan {
    /// The new plan, from the measured instant (its time 0) to the end of the manoeuvre.
    pub plan: CollocationPlan,
    pub status: ScpStatus,
    pub scp_iterations: usize,
    /// The optimiser's own landing error, rad.
    pub landing_error_rad: f64,
    /// Wall time of the solve, s.
    pub seconds: f64,
}

/// The replans of one flight at a fixed mesh (see the module doc).
pub struct Replanner {
    spec: DesignSpec,
    nodes: usize,
    settings: ScpSettings,
    solvers: Solvers,
    projection: Option<ConicSolver>,
    warm: Option<WarmStart>,
}

impl Replanner {
    /// Replans of `spec`'s flight at `nodes` per phase, each SCP to the
    /// design's own tolerances (`free.tolerance`, `free.attitude_tolerance`).
    pub fn new(spec: &DesignSpec, nodes: usize) -> Result<Self> {
        if nodes < 3 {
            return Err(Error::Invalid {
                key: "replan nodes".into(),
                value: format!("{nodes}"),
                expected: "at least 3 nodes per phase".into(),
            });
        }
        spec.objective
            .check_bounded(spec.motor.max_torque.is_some() || spec.motor.max_speed.is_some())?;
        Ok(Self {
            spec: spec.clone(),
            nodes,
            settings: ScpSettings {
                tolerance: spec.free.tolerance,
                feasibility: spec.free.attitude_tolerance,
                conic: ConicSettings::MODEL,
                // a replan's subproblems keep the last one's pattern, so its
                // solver is updated in place, not set up again (not measured
                // with the screen)
                screen: false,
                ..Default::default()
            },
            solvers: Solvers::default(),
            projection: None,
            warm: None,
        })
    }

    /// For a real-time iteration (one or a few SCP iterations a control
    /// period): no tentative steps, whose follow-up the replan's iteration
    /// limit would cut off (undoing them: the step would be lost), and no
    /// conic correction (the sensitivity correction alone): a second conic
    /// solve in the period.
    pub fn real_time(mut self) -> Self {
        self.settings.watchdog.enabled = false;
        self.settings.correction.conic_enabled = false;
        self
    }

    /// Nodes per phase.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Re-solves the design from the state `y` measured at flight time `t`
    /// (since the release; `[quaternion, q, q_dot, lambda]`, the closed
    /// loop's: attitude, shape, shape rate, body-frame momentum) over the
    /// time the fall still leaves, seeded by the rest of `previous` (the plan
    /// being flown, whose time 0 is flight time `origin`), with at most
    /// `max_iterations` SCP iterations, started from the last replan's
    /// multipliers, trust radius and weight. The new plan's time 0 is `t`.
    pub fn replan(
        &mut self,
        previous: &dyn ShapePlan,
        origin: f64,
        t: f64,
        y: &[f64; 11],
        max_iterations: usize,
    ) -> Result<Replan> {
        let clock = std::time::Instant::now();
        let spec = &self.spec;
        let end = origin + previous.duration();
        let remaining = spec.available_time() - t;
        if !(t >= origin && t < end && remaining > 0.0) {
            return Err(Error::Invalid {
                key: "replan time".into(),
                value: format!("{t}"),
                expected: format!("within the manoeuvre, [{origin}, {end})"),
            });
        }
        let g = spec.fall.gravity;
        let rc = spec.with_height(0.5 * g * (remaining + spec.fall.margin).powi(2));
        let tr = Transcription::new(3, self.nodes);
        let z0 = tr.sample(&Remainder::new(previous, t - origin));
        let mut problem = FreeProblem::new(&rc, self.nodes, &z0);
        let cat = &problem.cat;
        let att = [y[0], y[1], y[2], y[3]];
        let lam = nalgebra::Vector3::new(y[8], y[9], y[10]);
        let l = crate::model::so3::quat_from(&att) * lam;
        let unit = problem.time_unit;
        problem.release = Some(Release {
            attitude: att,
            momentum: [l.x, l.y, l.z].map(|c| c * unit),
            tail: rc.fall.margin / unit,
            inertias: crate::model::momentum::straight_inertias(cat),
        });
        problem.initial = Some(([y[4], y[5]], [y[6], y[7]]));
        // a replan may end its manoeuvre early: its comparison flies every
        // plan to touchdown before one is taken (held to the whole time left,
        // the replans landed fewer of the seed's trials)
        problem.fills_the_fall = false;
        // the check points the attitude map knows the momentum at
        let checks = problem.checks;
        let problem = problem.with_checks(checks);
        // the seed's durations fitted into the time left (F3), then onto
        // the exact constraints (the measured shape and rate among them)
        let mut z0 = problem.to_scaled(&z0);
        let total: f64 = (0..3).map(|p| z0[tr.duration(p)]).sum();
        if total > 1.0 && problem.objective != Objective::Time {
            for p in 0..3 {
                z0[tr.duration(p)] /= total;
            }
        }
        let z0 = problem.project_reusing(&z0, &mut self.projection)?;
        let settings = ScpSettings {
            max_iterations,
            ..self.settings
        };
        let warm = self
            .warm
            .as_ref()
            .filter(|w| problem.multipliers_fit(&w.multipliers));
        let res = Executor::new(&settings).warm(warm).run_reusing(
            &problem,
            z0,
            &mut |_: &crate::design::scp::ScpIteration| {},
            &mut self.solvers,
        )?;
        let landing_error_rad = problem.terminal_error(&res.z);
        let z = problem.to_physical(&res.z);
        let release = problem.release.expect("set above");
        let track =
            crate::design::release::Track::new(release.in_seconds(unit), &problem.cat, &tr, &z);
        self.warm = Some(res.warm);
        Ok(Replan {
            plan: CollocationPlan {
                tr,
                z,
                track: Some(track),
            },
            status: res.status,
            scp_iterations: res.iterations.len(),
            landing_error_rad,
            seconds: clock.elapsed().as_secs_f64(),
        })
    }
}

impl FreeProblem {
    /// [`FreeProblem::project`] with the solver of an earlier projection of
    /// the same pattern (refilled in place).
    /// The inequalities rarely bind at the seed, so the equality-constrained
    /// step is tried first ([`least_step`]).
    fn project_reusing(&self, z: &[f64], slot: &mut Option<ConicSolver>) -> Result<Vec<f64>> {
        let d = self.projection_data(z);
        if let Some(dz) = least_step(&d) {
            return Ok(z.iter().zip(&dz).map(|(a, b)| a + b).collect());
        }
        let (st, dz, _) = solve_reusing(slot, &d)?;
        if !st.ok() {
            return Err(Self::projection_failed(st));
        }
        Ok(z.iter().zip(&dz).map(|(a, b)| a + b).collect())
    }
}

/// Violation of a cone row accepted by [`least_step`] (the problem's units
/// are O(1); Clarabel's own feasibility tolerance is 1e-8).
const ROW_TOLERANCE: f64 = 1e-10;

/// The least-distance program `min 1/2 x' diag(p) x` subject to `d`'s rows
/// (`A x + s = b`, `s` in the cones) solved directly: the equality rows and
/// the nonnegative rows found violated so far held as equalities,
/// `x = -D^-1 A_S' y` with `(A_S D^-1 A_S') y = -b_S` (one dense Cholesky
/// factorisation a round; a primal active set: a violated row joins the
/// set, a held one whose multiplier is negative leaves it). Its result is
/// the program's optimum when every other row holds there and the held
/// inequalities' multipliers are nonnegative (the KKT conditions); `None`
/// when that is not reached in a few rounds, a second-order cone row fails, or the rows are dependent
/// (the interior-point solver then takes the program).
fn least_step(d: &ConicData) -> Option<Vec<f64>> {
    let pd = d.p_diag.as_ref()?;
    if !d.p_upper.is_empty() || d.q.iter().any(|&x| x != 0.0) {
        return None;
    }
    // each row's cone: Zero, Nonneg or the start and size of its SOC
    let mut kind = Vec::with_capacity(d.m());
    for c in &d.cones {
        match *c {
            Cone::Zero(k) => kind.extend((0..k).map(|_| (0u8, 0, 0))),
            Cone::Nonneg(k) => kind.extend((0..k).map(|_| (1u8, 0, 0))),
            Cone::Soc(k) => {
                let first = kind.len();
                kind.extend((0..k).map(|_| (2u8, first, k)));
            }
        }
    }
    if kind.len() != d.m() {
        return None;
    }
    let mut by_row: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d.m()];
    for ((&r, &c), &v) in d.rows.iter().zip(&d.cols).zip(&d.vals) {
        by_row[r].push((c, v));
    }
    // the equalities and the inequalities that bind at x = 0 (the seed's
    // total time fills the time left)
    let mut held: Vec<usize> = (0..d.m())
        .filter(|&r| kind[r].0 == 0 || (kind[r].0 == 1 && d.b[r] <= ROW_TOLERANCE))
        .collect();
    for _ in 0..6 {
        let k = held.len();
        // A_S D^-1 A_S' from the columns' entries (duplicates add up)
        let mut by_col: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d.n];
        for (i, &r) in held.iter().enumerate() {
            for &(c, v) in &by_row[r] {
                by_col[c].push((i, v));
            }
        }
        let mut m = nalgebra::DMatrix::<f64>::zeros(k, k);
        for (c, entries) in by_col.iter().enumerate() {
            for &(i, a) in entries {
                for &(j, b) in entries {
                    m[(i, j)] += a * b / pd[c];
                }
            }
        }
        let rhs = nalgebra::DVector::from_iterator(k, held.iter().map(|&r| -d.b[r]));
        let Some(chol) = m.cholesky() else {
            // dependent rows: start again from the equalities alone
            if held.iter().any(|&r| kind[r].0 == 1) {
                held.retain(|&r| kind[r].0 == 0);
                continue;
            }
            return None;
        };
        let y = chol.solve(&rhs);
        let mut x = vec![0.0; d.n];
        for (c, entries) in by_col.iter().enumerate() {
            x[c] = -entries.iter().map(|&(i, a)| a * y[i]).sum::<f64>() / pd[c];
        }
        // a held inequality that pulls the wrong way is let go
        let pulling = held
            .iter()
            .zip(y.iter())
            .enumerate()
            .filter(|&(_, (&r, &yr))| kind[r].0 == 1 && yr < -ROW_TOLERANCE)
            .min_by(|a, b| a.1.1.total_cmp(b.1.1))
            .map(|(i, _)| i);
        if let Some(i) = pulling {
            held.remove(i);
            continue;
        }
        let slack = |r: usize| d.b[r] - by_row[r].iter().map(|&(c, v)| v * x[c]).sum::<f64>();
        let mut violated = Vec::new();
        for r in 0..d.m() {
            match kind[r] {
                (1, _, _) if !held.contains(&r) && slack(r) < -ROW_TOLERANCE => violated.push(r),
                (2, first, size) if r == first => {
                    let s: Vec<f64> = (first..first + size).map(slack).collect();
                    let tail = s[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
                    if s[0] < tail - ROW_TOLERANCE {
                        return None;
                    }
                }
                _ => {}
            }
        }
        if violated.is_empty() {
            return Some(x);
        }
        held.extend(violated);
    }
    None
}

/// Re-solves the free-form design of `spec` from the state `y` measured at
/// time `t` of the flight (`[quaternion, q, q_dot, lambda]`, the closed
/// loop's: attitude, shape, shape rate, body-frame momentum) over the time
/// the fall still leaves, to the landing set, seeded by the rest of
/// `previous` (whose time 0 is the release) and with at most
/// `max_iterations` SCP iterations on `nodes` per phase. The new plan's time
/// 0 is `t`. One replan alone; a flight's replans share a [`Replanner`].
pub fn replan(
    spec: &DesignSpec,
    previous: &dyn ShapePlan,
    t: f64,
    y: &[f64; 11],
    nodes: usize,
    max_iterations: usize,
) -> Result<Replan> {
    Replanner::new(spec, nodes)?.replan(previous, 0.0, t, y, max_iterations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::conic::ConicSolver;

    fn interior_point(d: &ConicData) -> Vec<f64> {
        let (st, x, _) = ConicSolver::new(d).unwrap().solve();
        assert!(st.ok(), "{st:?}");
        x
    }

    fn close(a: &[f64], b: &[f64], tol: f64) {
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst < tol, "{worst:e} apart: {a:?} {b:?}");
    }

    #[test]
    fn the_direct_least_step_is_the_programs_optimum_with_its_active_set() {
        // min 1/2 (x0^2 + 2 x1^2 + 3 x2^2 + 4 x3^2) with x0 + x1 = 1;
        // x2 <= -0.5 binds, x0 >= x1 binds at 0 but its multiplier would be
        // negative (it leaves the set), x3 <= 5 and x0 >= -1 have room
        let mut d = ConicData::new(4);
        d.p_diag = Some(vec![1.0, 2.0, 3.0, 4.0]);
        d.row(&[(0, 1.0), (1, 1.0)], 1.0);
        d.cone(Cone::Zero(1));
        d.row(&[(2, 1.0)], -0.5);
        d.row(&[(0, -1.0), (1, 1.0)], 0.0);
        d.row(&[(3, 1.0)], 5.0);
        d.row(&[(0, -1.0)], 1.0);
        d.cone(Cone::Nonneg(4));
        let x = least_step(&d).expect("solved directly");
        close(&x, &[2.0 / 3.0, 1.0 / 3.0, -0.5, 0.0], 1e-12);
        close(&x, &interior_point(&d), 1e-7);
        // an infeasible active set (x2 <= -0.5 and x2 >= 0) is left to the solver
        d.row(&[(2, -1.0)], 0.0);
        d.cone(Cone::Nonneg(1));
        assert!(least_step(&d).is_none());
    }

    #[test]
    fn a_replans_projection_is_solved_directly_and_agrees_with_clarabel() {
        let spec =
            crate::test_support::spec_of(include_str!("../../../configs/seed.toml"), "seed", &[]);
        let nodes = 8;
        let seed = crate::design::free::Seed::Analytic.plan(&spec).unwrap();
        let z0 = Transcription::new(3, nodes).sample(seed.as_ref());
        let mut problem = FreeProblem::new(&spec, nodes, &z0);
        problem.initial = Some(([0.2, -0.1], [0.4, -0.3]));
        let z = problem.to_scaled(&z0);
        let d = problem.projection_data(&z);
        let x = least_step(&d).expect("solved directly");
        close(&x, &interior_point(&d), 1e-6);
        // the measured shape and rate are met
        let tr = problem.tr;
        let moved: Vec<f64> = z.iter().zip(&x).map(|(a, b)| a + b).collect();
        close(&moved[tr.q(0, 0)..tr.q(0, 0) + 2], &[0.2, -0.1], 1e-12);
        let t0 = moved[tr.duration(0)] * problem.time_unit;
        close(
            &[moved[tr.v(0, 0)] / t0, moved[tr.v(0, 0) + 1] / t0],
            &[0.4, -0.3],
            1e-9,
        );
    }
}
