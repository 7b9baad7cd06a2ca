//! Successive convexification for least-peak, least-squares and linear
//! objectives under nonlinear equalities and norm limits.
//!
//! A problem is: minimise a [`Cost`] (`max_k |f_k(z)|`, `sum_k |f_k(z)|^2` or
//! `c' z`; Euclidean or per-component norm of each term) subject to nonlinear
//! equalities `r(z) = 0`, nonlinear limits `|g_k(z)| <= L` and exact convex
//! constraints (linear rows and second-order cones on affine functions of
//! `z`). Each iteration linearises `f`, `g` and `r` about the current `z`, adds
//! virtual controls `nu = nu+ - nu-` to the linearised equalities (penalised
//! by `w |nu|_1`) and one elastic slack `sigma >= 0` to the limits
//! (`|g + G dz| / L <= 1 + sigma`, penalised by `w sigma`), which keep every
//! subproblem feasible, bounds the step by a scaled trust region, and solves
//! one conic program with Clarabel; the data pattern is the same every
//! iteration, so the solver is updated in place, except that limit rows that
//! cannot bind inside the trust region are left out ([`ScpSettings::screen`]),
//! a set that is kept while it still holds every row that can.
//!
//! Steps are judged on the exact penalty
//! `phi(z) = cost(z) + w (|r(z)|_1 + max(0, max_k |g_k(z)| / L - 1))`:
//! `rho = (phi(z) - phi(z + dz)) / (phi(z) - L(dz))` with `L` the subproblem's
//! model value. When `rho` falls short ([`Correction::below`]) a
//! second-order correction is tried and kept if it lowers `phi`: first the subproblem's own KKT system with the
//! rows' linearisation errors (one factorisation, see
//! [`sensitivity_correction`]), and when that recovers less than
//! [`Correction::sensitivity_accept`] of the predicted decrease, a conic one (one more conic solve, or two when the
//! bounded one fails, see [`correction`]); a cheap one that falls short
//! stands in only when the conic one fails. For a linear cost an accepted
//! step that leaves a violation above `feasibility` gets the first of these
//! too ([`Correction::accepted_steps`]). The model's Hessian is scaled by the steps' `rho`
//! ([`Multipliers::adapt_curvature`]). Accepted when `rho` exceeds
//! [`TrustRegion::accept`] (so an accepted step never increases `phi`); the
//! radius falls to a share of the model's step below it and grows above
//! [`TrustRegion::grow_above`], except right after a rejected step. For a
//! peak cost a step that would be rejected is first taken tentatively (the
//! watchdog, [`ScpSettings::watchdog`]): the next
//! step must then lower `phi` below the point before it, or both are undone.
//! Stop: criticality (the predicted decrease at unit radius relative to
//! `phi`, without removing a violation already within `feasibility`, see
//! [`ScpIteration::criticality_within`]) below `tolerance`, or a merit
//! that fell by less than `tolerance` (relative) per iteration on average
//! over the last `window` iterations, with `max |r| <= feasibility` (converged; the certificate
//! names the rule); the penalty grows when the model stalls while still
//! infeasible (and, for a linear cost, when the violation stagnates, see
//! [`Penalty::stagnation`]); an iteration limit, a penalty grown past
//! [`Penalty::infeasible`] or a collapsed trust region end the run.

use crate::design::conic::{Cone, ConicData, ConicSettings, ConicSolver, solve_reusing_with};
use crate::error::{Error, Result};
use crate::model::TorqueNorm;
use serde::Serialize;
use std::time::Instant;

/// Sparse Jacobian rows: `(row, column, value)`; the set of entries must not
/// depend on `z` (emit zeros too), so the conic pattern stays fixed.
pub type Triplets = Vec<(usize, usize, f64)>;

/// What a problem minimises.
#[derive(Debug, Clone, PartialEq)]
pub enum Cost {
    /// `max_k |f_k(z)|`, through an epigraph variable.
    Peak,
    /// `sum_k |f_k(z)|^2`, modelled by Gauss-Newton `|f + J dz|^2` (a convex
    /// quadratic, exact for affine terms).
    SumOfSquares,
    /// `c' z`, as sparse `(column, coefficient)`; the terms are unused.
    Linear(Vec<(usize, f64)>),
}

/// Values at one point, without derivatives (merit evaluation).
#[derive(Debug, Clone, Default)]
pub struct Values {
    /// `f_k(z)`, each of length `term_dim`, flattened (the cost's terms).
    pub terms: Vec<f64>,
    /// `g_k(z)`, each of length `term_dim`, flattened (limited by
    /// [`ScpProblem::limit`]).
    pub limited: Vec<f64>,
    /// `r(z)`.
    pub residual: Vec<f64>,
}

/// Values and Jacobians at one point.
#[derive(Debug, Clone, Default)]
pub struct Linearization {
    /// `f_k(z)`, each of length `term_dim`, flattened.
    pub terms: Vec<f64>,
    /// Jacobian of the flattened terms.
    pub terms_jac: Triplets,
    /// `g_k(z)` and its Jacobian.
    pub limited: Vec<f64>,
    pub limited_jac: Triplets,
    /// `r(z)`.
    pub residual: Vec<f64>,
    pub residual_jac: Triplets,
}

/// A problem the driver can convexify.
pub trait ScpProblem {
    /// Number of decision variables.
    fn dim(&self) -> usize;
    /// Length of each term `f_k` and `g_k`.
    fn term_dim(&self) -> usize;
    /// The norm of each term (cost and limits).
    fn norm(&self) -> TorqueNorm;
    /// What is minimised (default: the peak of the terms).
    fn cost(&self) -> Cost {
        Cost::Peak
    }
    fn evaluate(&self, z: &[f64]) -> Values;
    fn linearize(&self, z: &[f64]) -> Linearization;
    /// Adds the exact convex constraints in the step `dz = x[var(i)]`,
    /// i.e. in `z + dz`. The rows must have a fixed pattern.
    fn add_constraints(&self, data: &mut ConicData, z: &[f64], var: &dyn Fn(usize) -> usize);
    /// Trust-region scale of each variable (the radius is in these units).
    fn scales(&self) -> Vec<f64>;
    /// The bound `L` on each limited term's norm `|g_k(z)|` (none: no limits).
    fn limit(&self) -> Option<f64> {
        None
    }
    /// Whether the limited terms are the peak cost's terms themselves (a
    /// torque limit without a torque-speed line): the limit is then one row
    /// on the epigraph, `t <= L (1 + sigma)`, instead of a copy of every
    /// term's rows (default: no).
    fn limited_are_terms(&self) -> bool {
        false
    }
    /// Second-order information: a positive semidefinite approximation of
    /// `sum_r y_r Hess f_r(z) + sum_r u_r Hess g_r(z)` (`y` one multiplier
    /// per flattened term of a peak cost, zero otherwise; `u` one per
    /// flattened limited term), as upper-triangle triplets with a pattern
    /// that does not depend on `z`, `y` or `u` (with
    /// [`ScpProblem::limited_are_terms`], `u` is zero and `y` carries the
    /// limit's multiplier through the epigraph). The default (none) makes the
    /// method sequential linear programming (Gauss-Newton for a
    /// sum-of-squares cost); with it, the subproblem is an SQP step.
    fn hessian(&self, _z: &[f64], _y: &[f64], _u: &[f64]) -> Triplets {
        Vec::new()
    }
}

/// Declares a settings struct whose defaults sit on its fields
/// (`pub name: Type = default,`): the `Default` impl is made from them and
/// each field's doc ends with its default, so a default is written once.
macro_rules! settings {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $($(#[$doc:meta])* pub $field:ident: $ty:ty = $default:expr,)*
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $(
                $(#[$doc])*
                #[doc = ""]
                #[doc = concat!("Default: `", stringify!($default), "`.")]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    $($field: $default,)*
                }
            }
        }
    };
}

settings! {
    /// Driver settings: each field's default follows it, and
    /// [`ScpSettings::validate`] checks them before a solve. The groups hold
    /// the rules of the method's parts: the trust region, the penalty, the
    /// watchdog, the second-order correction and the model's curvature.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct ScpSettings {
        /// Iteration limit (failed subproblems and tentative steps count).
        pub max_iterations: usize = 150,
        /// Converged when the criticality (predicted decrease at unit trust
        /// radius relative to the merit, see
        /// [`ScpIteration::criticality_within`]) is below this, or when the
        /// merit fell by less than this (relative) per iteration on average
        /// over the last `window` iterations.
        pub tolerance: f64 = 1e-4,
        /// Largest violation accepted as feasible (`max |r|`, and the
        /// limits' `max |g| / L - 1`).
        pub feasibility: f64 = 1e-6,
        /// Iterations over which the merit must fall by `tolerance`
        /// (relative) per iteration on average to keep going.
        pub window: usize = 10,
        /// How the trust radius moves.
        pub trust: TrustRegion = TrustRegion::default(),
        /// The exact penalty's weight and when it grows.
        pub penalty: Penalty = Penalty::default(),
        /// Tentative steps for a peak cost.
        pub watchdog: Watchdog = Watchdog::default(),
        /// The second-order correction of a step the merit would reject.
        pub correction: Correction = Correction::default(),
        /// The scale of the model's Hessian.
        pub curvature: Curvature = Curvature::default(),
        /// How exactly the subproblems and corrections are solved.
        pub conic: ConicSettings = ConicSettings::MODEL,
        /// Leave out of each subproblem the limit rows that cannot bind
        /// inside its trust region ([`screen`]): the same solution from a
        /// smaller conic program.
        pub screen: bool = false,
        /// With `screen`, a row is also left out when it stays this far
        /// (relative to the limit) inside it, whatever the trust region;
        /// the solution is checked against the rows left out and solved
        /// again with any it breaks. Infinite: only the rows that cannot
        /// bind (1.0, the far side of every line, was no faster:
        /// docs/benchmarks.md).
        pub screen_band: f64 = f64::INFINITY,
    }
}

settings! {
    /// The trust region: steps are judged by `rho`, the merit's actual
    /// decrease over the model's predicted one.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct TrustRegion {
        /// Initial radius in scaled units (the problem's
        /// [`ScpProblem::scales`]).
        pub initial_radius: f64 = 0.5,
        /// A step is accepted when the model predicted a decrease and `rho`
        /// exceeds this (so an accepted step never increases the merit);
        /// below it the radius is cut.
        pub accept: f64 = 0.1,
        /// The radius grows when `rho` exceeds this, except right after a
        /// rejected step: the radius that was just cut would be grown back
        /// to one that failed.
        pub grow_above: f64 = 0.5,
        /// The factor by which the radius grows.
        pub growth: f64 = 2.0,
        /// The largest radius.
        pub max_radius: f64 = 1e3,
        /// After a rejection the radius is this share of the model's step (a
        /// radius still above an interior step would only give the same step
        /// again), or of the radius when the model predicted no decrease
        /// (its step says nothing).
        pub cut: f64 = 0.5,
        /// The least share of the radius that the model's step counts for in
        /// a cut (with `cut`, the radius falls at most twentyfold).
        pub least_cut: f64 = 0.1,
        /// A subproblem the conic solver could not finish (numerical
        /// trouble) is a rejected step whose radius is multiplied by this:
        /// a smaller trust region is a better-conditioned subproblem.
        pub failure_cut: f64 = 0.25,
        /// Failed subproblems in a row that are taken as rejections; the
        /// next one ends the solve at its last point
        /// ([`Termination::Unsolvable`]).
        pub max_failures: usize = 4,
        /// The run has stalled when the radius falls below this.
        pub min_radius: f64 = 1e-10,
        /// A neighbour's radius (a warm start) is used down to this.
        pub warm_floor: f64 = 1e-3,
    }
}

settings! {
    /// The exact penalty `phi = cost + w (|r|_1 + max(0, max_k |g_k| / L - 1))`
    /// and when its weight `w` grows.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct Penalty {
        /// The weight relative to the initial cost (for a peak cost at least
        /// the limit, which has its unit): the exact L1 penalty needs only
        /// `w > |multiplier|`; a larger one makes the merit's model more
        /// curved and the steps shorter.
        pub weight: f64 = 2.0,
        /// The factor of each raise of the weight.
        pub growth: f64 = 10.0,
        /// A neighbour's weight (a warm start) is kept up to this multiple
        /// of the start weight: its constraints' multipliers are nearly
        /// these, and a weight below them lets the merit trade violation for
        /// cost until the stopping rules raise it again.
        pub max_carried: f64 = 1e3,
        /// A peak cost's limit counts in the start weight's scale up to this
        /// multiple of the start's cost: a limit thousands of times the cost
        /// (a torque-speed line in a long fall, where it cannot bind) made
        /// the merit all penalty, and the design ran to its iteration limit.
        pub max_limit_scale: f64 = 1e3,
        /// Locally infeasible when the weight exceeds this multiple of the
        /// start weight `weight` (not of a carried one: from a weight
        /// carried `max_carried` times up, three raises are left).
        pub infeasible: f64 = 1e6,
        /// Violations up to this multiple of `feasibility` are nearly
        /// feasible: at a critical point the next steps remove them at this
        /// weight (raising it would only shrink the steps); above it the
        /// penalty is too weak and is raised.
        pub nearly_feasible: f64 = 100.0,
        /// Critical points in a row at a nearly feasible violation after
        /// which the weight is raised all the same.
        pub patience: usize = 3,
        /// For a linear cost (least time): iterations over which a violation
        /// above `nearly_feasible` that fell by less than `stagnation_fall`
        /// while the cost moved by less than `stagnation_cost` raises the
        /// weight (0: never). The cost has no curvature, so near the optimum
        /// it barely moves while a weight below the constraints' multipliers
        /// settles on an infeasible minimum of the merit. Peak and energy
        /// costs keep the criticality rule alone.
        pub stagnation: usize = 5,
        /// The share of its value a stagnating violation keeps over
        /// `stagnation` iterations (it fell by less than a fifth).
        pub stagnation_fall: f64 = 0.8,
        /// The relative change of the cost below which it stagnates.
        pub stagnation_cost: f64 = 1e-2,
        /// The stagnation rule raises the weight while it is below this
        /// multiple of its start (twice, with tenfold raises).
        pub stagnation_cap: f64 = 50.0,
    }
}

settings! {
    /// The watchdog: a step the merit would reject is taken once,
    /// tentatively, and the next step from there must bring the merit below
    /// the point before it; otherwise both are undone and the radius is cut
    /// as for a rejection. The merit's kinks (the peak's active set, the
    /// attitude's curvature) reject steps that the next linearisation would
    /// complete. Peak costs only; not at a converged point, where `rho` is
    /// noise; re-armed only by an accepted step.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct Watchdog {
        /// Whether tentative steps are taken.
        pub enabled: bool = true,
        /// The share of the point before a tentative step's predicted
        /// decrease that the next step must achieve from it.
        pub decrease: f64 = 0.1,
    }
}

settings! {
    /// The second-order correction of a step whose `rho` falls short: the
    /// sensitivity correction ([`sensitivity_correction`]) first, the conic
    /// one ([`correction`]) when it recovers too little and is enabled.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct Correction {
        /// A correction is tried when `rho` is below this.
        pub below: f64 = 0.75,
        /// Rounds of the sensitivity correction tried before the conic one
        /// (0: the conic correction alone).
        pub rounds: usize = 3,
        /// The share of the predicted decrease a sensitivity correction must
        /// recover to stand in for the conic correction (a weak cheap
        /// correction keeps the path off the better conic one).
        pub sensitivity_accept: f64 = 0.5,
        /// Weight of the conic correction's slacks against its scaled step
        /// `|dc|^2 / 2`. A residual component along a direction of scaled
        /// gain `s` is removed while it is below about `W s^2`: all of it
        /// where the constraints are well conditioned (`s ~ 0.5`), none
        /// along the attitude's tilt, whose first-order gain all but
        /// vanishes at the designs (`s ~ 1e-7`; a hard correction took a
        /// huge step there, or 70 to 200 interior-point iterations to find
        /// none).
        pub slack_weight: f64 = 10.0,
        /// Whether an accepted step of a linear cost (least time) whose
        /// trial point breaks the constraints by more than `feasibility` is
        /// corrected too (the sensitivity correction alone, `rounds` rounds
        /// or one, kept when it lowers the merit). Such a cost's steps run
        /// along the constraints, each leaving a violation of about its
        /// square, and without the correction every mesh round spent two
        /// more iterations removing it.
        pub accepted_steps: bool = true,
        /// Whether the conic correction is tried at all. A real-time
        /// iteration leaves it out: it is a second conic solve in a period
        /// that has room for one, and the next period goes on from the step.
        pub conic_enabled: bool = true,
    }
}

settings! {
    /// The scale of the model's Hessian, see [`Multipliers::adapt_curvature`].
    #[derive(Debug, Clone, Copy, PartialEq, Serialize)]
    pub struct Curvature {
        /// Whether the scale follows the steps' `rho`.
        pub adapt: bool = true,
        /// The least scale.
        pub min: f64 = 0.1,
        /// The least factor of one fall (after an accepted step with
        /// `rho > 1` the scale is multiplied by `2 - rho`, at least this).
        pub fall: f64 = 0.25,
        /// The factor of a rise after a rejected step (at most 1).
        pub rise: f64 = 2.0,
    }
}

impl ScpSettings {
    /// Checks every setting's range; the error names the setting.
    pub fn validate(&self) -> Result<()> {
        let (t, p, w, c, k) = (
            &self.trust,
            &self.penalty,
            &self.watchdog,
            &self.correction,
            &self.curvature,
        );
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let share = |x: f64| x.is_finite() && x > 0.0 && x < 1.0;
        let checks: [(&str, f64, bool, &str); 28] = [
            (
                "max_iterations",
                self.max_iterations as f64,
                self.max_iterations >= 1,
                "at least 1",
            ),
            (
                "tolerance",
                self.tolerance,
                share(self.tolerance),
                "in (0, 1)",
            ),
            (
                "feasibility",
                self.feasibility,
                positive(self.feasibility),
                "positive",
            ),
            ("window", self.window as f64, self.window >= 1, "at least 1"),
            (
                "trust.initial_radius",
                t.initial_radius,
                positive(t.initial_radius),
                "positive",
            ),
            ("trust.accept", t.accept, share(t.accept), "in (0, 1)"),
            (
                "trust.grow_above",
                t.grow_above,
                t.grow_above >= t.accept && t.grow_above < 1.0,
                "in [trust.accept, 1)",
            ),
            (
                "trust.growth",
                t.growth,
                t.growth.is_finite() && t.growth > 1.0,
                "above 1",
            ),
            (
                "trust.max_radius",
                t.max_radius,
                t.max_radius.is_finite() && t.max_radius >= t.initial_radius,
                "at least trust.initial_radius",
            ),
            ("trust.cut", t.cut, share(t.cut), "in (0, 1)"),
            (
                "screen_band",
                self.screen_band,
                self.screen_band > 0.0,
                "positive (infinite: only rows that cannot bind are left out)",
            ),
            (
                "trust.least_cut",
                t.least_cut,
                t.least_cut > 0.0 && t.least_cut <= 1.0,
                "in (0, 1]",
            ),
            (
                "trust.failure_cut",
                t.failure_cut,
                share(t.failure_cut),
                "in (0, 1)",
            ),
            (
                "trust.min_radius",
                t.min_radius,
                positive(t.min_radius) && t.min_radius < t.warm_floor.min(t.initial_radius),
                "positive, below trust.warm_floor and trust.initial_radius",
            ),
            (
                "trust.warm_floor",
                t.warm_floor,
                positive(t.warm_floor) && t.warm_floor <= t.initial_radius,
                "positive, at most trust.initial_radius",
            ),
            ("penalty.weight", p.weight, positive(p.weight), "positive"),
            (
                "penalty.growth",
                p.growth,
                p.growth.is_finite() && p.growth > 1.0,
                "above 1",
            ),
            (
                "penalty.max_carried",
                p.max_carried,
                p.max_carried >= 1.0,
                "at least 1",
            ),
            (
                "penalty.max_limit_scale",
                p.max_limit_scale,
                p.max_limit_scale.is_finite() && p.max_limit_scale >= 1.0,
                "at least 1",
            ),
            (
                "penalty.infeasible",
                p.infeasible,
                p.infeasible.is_finite() && p.infeasible > p.max_carried,
                "above penalty.max_carried",
            ),
            (
                "penalty.nearly_feasible",
                p.nearly_feasible,
                p.nearly_feasible >= 1.0,
                "at least 1",
            ),
            (
                "penalty.stagnation_fall",
                p.stagnation_fall,
                share(p.stagnation_fall),
                "in (0, 1)",
            ),
            (
                "penalty.stagnation_cost",
                p.stagnation_cost,
                share(p.stagnation_cost),
                "in (0, 1)",
            ),
            (
                "penalty.stagnation_cap",
                p.stagnation_cap,
                p.stagnation_cap >= 1.0,
                "at least 1",
            ),
            (
                "watchdog.decrease",
                w.decrease,
                share(w.decrease),
                "in (0, 1)",
            ),
            (
                "correction.below",
                c.below,
                c.below >= t.accept && c.below <= 1.0,
                "in [trust.accept, 1]",
            ),
            (
                "correction.sensitivity_accept",
                c.sensitivity_accept,
                c.sensitivity_accept > 0.0 && c.sensitivity_accept <= 1.0,
                "in (0, 1]",
            ),
            (
                "correction.slack_weight",
                c.slack_weight,
                positive(c.slack_weight),
                "positive",
            ),
        ];
        let curvature: [(&str, f64, bool, &str); 3] = [
            (
                "curvature.min",
                k.min,
                k.min > 0.0 && k.min <= 1.0,
                "in (0, 1]",
            ),
            (
                "curvature.fall",
                k.fall,
                k.fall > 0.0 && k.fall <= 1.0,
                "in (0, 1]",
            ),
            (
                "curvature.rise",
                k.rise,
                k.rise.is_finite() && k.rise > 1.0,
                "above 1",
            ),
        ];
        match checks.iter().chain(&curvature).find(|c| !c.2) {
            Some(&(key, value, _, expected)) => Err(Error::Invalid {
                key: format!("scp.{key}"),
                value: format!("{value}"),
                expected: expected.into(),
            }),
            None => Ok(()),
        }
    }
}

/// One iteration, as reported to the observer.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ScpIteration {
    pub iteration: usize,
    /// Merit before the step.
    pub merit: f64,
    /// The cost before the step (peak, sum of squares or `c' z`).
    pub objective: f64,
    /// Largest violation before the step: `max |r|` and the limits'
    /// `max |g| / L - 1`.
    pub infeasibility: f64,
    pub radius: f64,
    pub weight: f64,
    pub predicted: f64,
    pub actual: f64,
    pub rho: f64,
    pub accepted: bool,
    /// A step the merit rejected, taken tentatively (the watchdog, see
    /// [`ScpSettings::watchdog`]): the next iteration starts from its trial
    /// point and is judged against this one's start.
    pub tentative: bool,
    /// Merit after the iteration: equal to `merit` when rejected or
    /// tentative; the anchor's when this step undid a tentative one.
    pub merit_after: f64,
    /// Largest scaled component of the trial step `|dz_i| / scale_i`.
    pub step: f64,
    /// Largest scaled component of the subproblem's step (before the
    /// correction).
    pub model_step: f64,
    pub solve_ms: f64,
}

impl ScpIteration {
    /// Whether the trust region bounded the subproblem's step (its largest
    /// scaled component at the radius); when not, the model's minimum lies
    /// inside it.
    pub fn bounded(&self) -> bool {
        self.model_step >= 0.99 * self.radius
    }

    /// First-order criticality: the model decrease at unit trust radius,
    /// relative to the merit. When the trust region bounded the step it is
    /// bounded above by `predicted / min(radius, 1)` (the model's optimal
    /// value is convex in the radius, so the predicted decrease is concave
    /// in it), which does not vanish merely because the trust region has
    /// shrunk; when it did not, the model's minimum is inside the region and
    /// a larger radius predicts no more: it is `predicted` itself.
    pub fn criticality(&self) -> f64 {
        let per_radius = if self.bounded() {
            self.radius.min(1.0)
        } else {
            1.0
        };
        self.predicted.max(0.0) / self.merit.abs().max(1e-300) / per_radius
    }

    /// [`ScpIteration::criticality`] at a point whose violations are within
    /// `feasibility`: without the decrease the model predicts from removing
    /// them (the merit's penalty, `merit - objective`), which a converged
    /// point need not earn. At rounding level (the attitude's residual at
    /// 1e-9 rad) no step can remove it, and with a large penalty weight it
    /// made the criticality thousands while the merit could not fall.
    pub fn criticality_within(&self, feasibility: f64) -> f64 {
        if self.infeasibility > feasibility {
            return self.criticality();
        }
        let penalty = (self.merit - self.objective).max(0.0);
        ScpIteration {
            predicted: self.predicted - penalty,
            ..*self
        }
        .criticality()
    }

    /// The record with its cost-valued fields (merit, objective, decreases,
    /// weight) multiplied by `unit`: problems solved in scaled units report
    /// physical ones.
    pub fn in_units(mut self, unit: f64) -> Self {
        self.merit *= unit;
        self.objective *= unit;
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
    /// The constraints stayed violated while the penalty weight grew a
    /// millionfold: no point meets them near here (locally infeasible).
    Infeasible,
}

/// Why the user may trust the end point: the numbers the stopping rule
/// looked at, at the last iteration.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Certificate {
    /// Largest scaled component of the last step taken (`|dz_i| / scale_i`).
    pub step: f64,
    /// Largest equality-constraint violation `max |r(z)|` at the end point.
    pub constraint_violation: f64,
    /// The method's optimality measure,
    /// [`ScpIteration::criticality_within`] the feasibility tolerance, of the
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
    /// The cost at the end point.
    pub objective: f64,
    pub infeasibility: f64,
    pub iterations: Vec<ScpIteration>,
    pub certificate: Certificate,
    pub warm: WarmStart,
    /// Why the run ended (the status and the certificate's rule follow).
    pub termination: Termination,
    /// Wall time of the run, s.
    pub seconds: f64,
}

/// Largest norm over the terms (each of length `d`).
pub fn peak_of(terms: &[f64], d: usize, norm: TorqueNorm) -> f64 {
    terms
        .chunks(d)
        .map(|f| match norm {
            TorqueNorm::Euclidean => f.iter().map(|x| x * x).sum::<f64>().sqrt(),
            TorqueNorm::PerMotor => f.iter().fold(0.0f64, |m, x| m.max(x.abs())),
        })
        .fold(0.0, f64::max)
}

/// The cost of `p` at `z` from its values.
fn cost_of(p: &dyn ScpProblem, z: &[f64], v: &Values) -> f64 {
    match p.cost() {
        Cost::Peak => peak_of(&v.terms, p.term_dim(), p.norm()),
        Cost::SumOfSquares => v.terms.iter().map(|x| x * x).sum(),
        Cost::Linear(c) => c.iter().map(|&(i, a)| a * z[i]).sum(),
    }
}

/// `(phi, cost, infeasibility)`: the exact penalty, the cost, and the
/// largest violation (`max |r|`, and `max |g| / L - 1` for the limits).
fn merit(p: &dyn ScpProblem, z: &[f64], w: f64) -> Merit {
    merit_of(p, z, &evaluate(p, z), w)
}

/// `(phi, cost, infeasibility)` of [`merit`].
type Merit = (f64, f64, f64);

/// [`merit`] from the values at `z` (evaluated once, used twice).
fn merit_of(p: &dyn ScpProblem, z: &[f64], v: &Values, w: f64) -> Merit {
    let cost = cost_of(p, z, v);
    let l1: f64 = v.residual.iter().map(|x| x.abs()).sum();
    let mut inf = v.residual.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut over = 0.0;
    if p.limit().is_some() {
        over = (peak_of(&v.limited, p.term_dim(), p.norm()) - 1.0).max(0.0);
        inf = inf.max(over);
    }
    (cost + w * (l1 + over), cost, inf)
}

/// The limited terms relative to the limit, `g / L` (bounded by 1): the
/// penalty then weighs a relative violation against the cost, whatever the
/// limit's size (a torque-speed line can make `L` many times the cost).
fn relative(p: &dyn ScpProblem, limited: &mut [f64]) {
    if let Some(l) = p.limit() {
        limited.iter_mut().for_each(|x| *x /= l);
    }
}

/// [`ScpProblem::evaluate`] with relative limited terms.
fn evaluate(p: &dyn ScpProblem, z: &[f64]) -> Values {
    let mut v = p.evaluate(z);
    relative(p, &mut v.limited);
    v
}

/// [`ScpProblem::linearize`] with relative limited terms.
fn linearize(p: &dyn ScpProblem, z: &[f64]) -> Linearization {
    let mut lin = p.linearize(z);
    relative(p, &mut lin.limited);
    if let Some(l) = p.limit() {
        lin.limited_jac.iter_mut().for_each(|e| e.2 /= l);
    }
    lin
}

/// Rows of `norm(s) <= bound` for each term of `(values, jac)`, in the
/// subproblem's form `s = values + J dz`: one SOC per term (Euclidean) or
/// two linear rows per component (per motor). `bound` is the variable(s)
/// and constant on the bound side, e.g. `t` or `L + sigma`. Returns, for
/// each flattened term, the rows and signs with which their duals multiply
/// the term in the Lagrangian.
fn norm_rows(
    d: &mut ConicData,
    values: &[f64],
    jac: &Triplets,
    dim: usize,
    norm: TorqueNorm,
    bound: (&[(usize, f64)], f64),
) -> TermRows {
    norm_rows_kept(d, values, jac, dim, norm, bound, None)
}

/// Which rows of each flattened limited term a subproblem holds: bit
/// [`UPPER`] the row `g <= 1 + sigma`, bit [`LOWER`] the row
/// `-g <= 1 + sigma` (per motor); a Euclidean term's cone is held when any
/// of its components has a bit.
pub type Screen = Vec<u8>;

/// [`Screen`]'s bit of the upper row.
const UPPER: u8 = 1;
/// [`Screen`]'s bit of the lower row.
const LOWER: u8 = 2;

/// The limit rows that can bind anywhere inside the trust region
/// `|dz_i| <= radius scale_i`: a row whose value plus the most its
/// linearisation can move there (`sum_i |G_ri| radius scale_i`) stays
/// within the limit holds with `sigma = 0` at every step the subproblem
/// can take, so leaving it out changes neither the subproblem's solution
/// nor its value (its multiplier is zero). At the small radii of a design
/// near its optimum about half the rows of a torque-speed line are such
/// (its far side, 2 away, and the near side where the motor is well
/// inside). The reach is capped at `band`: a row left out by the cap may
/// bind, so the solution is checked against it ([`broken_rows`]).
fn screen(
    lin: &Linearization,
    scales: &[f64],
    radius: f64,
    band: f64,
    dim: usize,
    norm: TorqueNorm,
) -> Screen {
    let g = &lin.limited;
    let mut reach = vec![0.0; g.len()];
    for &(r, c, v) in &lin.limited_jac {
        reach[r] += v.abs() * radius * scales[c];
    }
    match norm {
        TorqueNorm::PerMotor => g
            .iter()
            .zip(&reach)
            .map(|(&v, &h)| {
                let h = h.min(band);
                (u8::from(v + h > 1.0) * UPPER) | (u8::from(-v + h > 1.0) * LOWER)
            })
            .collect(),
        TorqueNorm::Euclidean => {
            let norm2 = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
            g.chunks(dim)
                .zip(reach.chunks(dim))
                .flat_map(|(v, h)| {
                    let keep = norm2(v) + norm2(h).min(band) > 1.0;
                    std::iter::repeat_n(if keep { UPPER | LOWER } else { 0 }, v.len())
                })
                .collect()
        }
    }
}

/// Whether a subproblem may keep the rows of `held` when `need` are the
/// rows that can bind: all of them are held, and not many more (a held
/// set keeps the conic pattern, so the solver is updated in place rather
/// than set up again; a few idle rows cost less than a new set-up).
fn holds(held: &Screen, need: &Screen) -> bool {
    let count = |s: &Screen| s.iter().map(|b| b.count_ones() as usize).sum::<usize>();
    held.len() == need.len()
        && held.iter().zip(need).all(|(h, n)| n & !h == 0)
        && count(held) <= count(need) + count(need) / SCREEN_SLACK
}

/// The rows `held` leaves out that the subproblem's solution `x` breaks
/// (beyond rounding), as `(flattened term, bit)`.
fn broken_rows(
    lin: &Linearization,
    held: &Screen,
    x: &[f64],
    v: &Layout,
    norm: TorqueNorm,
    dim: usize,
) -> Vec<(usize, u8)> {
    let mut s = lin.limited.clone();
    for &(r, c, g) in &lin.limited_jac {
        s[r] += g * x[c];
    }
    let bound = 1.0 + v.slack(x) + SCREEN_CHECK;
    match norm {
        TorqueNorm::PerMotor => s
            .iter()
            .enumerate()
            .flat_map(|(r, &sr)| {
                [(UPPER, sr), (LOWER, -sr)]
                    .into_iter()
                    .filter(move |&(bit, x)| held[r] & bit == 0 && x > bound)
                    .map(move |(bit, _)| (r, bit))
            })
            .collect(),
        TorqueNorm::Euclidean => s
            .chunks(dim)
            .enumerate()
            .filter(|&(k, t)| {
                held[k * dim] == 0 && t.iter().map(|x| x * x).sum::<f64>().sqrt() > bound
            })
            .flat_map(|(k, _)| (k * dim..(k + 1) * dim).map(|r| (r, UPPER | LOWER)))
            .collect(),
    }
}

/// How far past its limit a left-out row may be at a subproblem's solution
/// (the solver's own feasibility tolerance is 1e-8).
const SCREEN_CHECK: f64 = 1e-7;

/// A held [`Screen`] is kept while it holds at most `1 / SCREEN_SLACK` more
/// rows than can bind.
const SCREEN_SLACK: usize = 4;

/// A new [`Screen`] holds the rows that can bind within this many trust
/// radii.
const SCREEN_MARGIN: f64 = 1.25;

/// [`norm_rows`] with only the rows `keep` names (all without it); a term
/// without rows gets no entry in the returned rows.
fn norm_rows_kept(
    d: &mut ConicData,
    values: &[f64],
    jac: &Triplets,
    dim: usize,
    norm: TorqueNorm,
    bound: (&[(usize, f64)], f64),
    keep: Option<&Screen>,
) -> TermRows {
    let kept = |r: usize, bit: u8| keep.is_none_or(|k| k[r] & bit != 0);
    let mut rows_of: TermRows = vec![Vec::new(); values.len()];
    let mut jr: Vec<Vec<(usize, f64)>> = vec![Vec::new(); values.len()];
    for &(r, c, v) in jac {
        jr[r].push((c, v));
    }
    let (bvars, bconst) = bound;
    let neg =
        |row: &[(usize, f64)]| -> Vec<(usize, f64)> { row.iter().map(|&(c, v)| (c, -v)).collect() };
    match norm {
        TorqueNorm::Euclidean => {
            for k in 0..values.len() / dim {
                if !(k * dim..(k + 1) * dim).any(|r| kept(r, UPPER | LOWER)) {
                    continue;
                }
                d.row(&neg(bvars), bconst);
                for j in 0..dim {
                    let r = k * dim + j;
                    // s = f + J dz: the Lagrangian holds -z_row f
                    rows_of[r].push((d.row(&neg(&jr[r]), values[r]), -1.0));
                }
                d.cone(Cone::Soc(dim + 1));
            }
        }
        TorqueNorm::PerMotor => {
            let mut count = 0;
            for r in 0..values.len() {
                if kept(r, UPPER) {
                    let mut up = jr[r].clone();
                    up.extend(neg(bvars));
                    rows_of[r].push((d.row(&up, bconst - values[r]), 1.0));
                    count += 1;
                }
                if kept(r, LOWER) {
                    let mut down = neg(&jr[r]);
                    down.extend(neg(bvars));
                    rows_of[r].push((d.row(&down, bconst + values[r]), -1.0));
                    count += 1;
                }
            }
            if count > 0 {
                d.cone(Cone::Nonneg(count));
            }
        }
    }
    rows_of
}

/// Whether the limit is the one epigraph row `t <= L (1 + sigma)` (see
/// [`ScpProblem::limited_are_terms`]) rather than rows of its own.
fn held_by_epigraph(p: &dyn ScpProblem) -> bool {
    p.limited_are_terms() && p.cost() == Cost::Peak
}

/// The subproblem's variables, in order: the step `dz` (one per decision
/// variable), the peak epigraph `t` (zero for other costs), the virtual
/// controls `nu+` and `nu-` (one each per residual) and, when the problem
/// has limits, their elastic slack `sigma`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Layout {
    /// Decision variables.
    n: usize,
    /// Residuals.
    m: usize,
    /// Whether `sigma` is present.
    limited: bool,
}

impl Layout {
    /// The layout of the subproblem of `p` linearised as `lin`.
    fn of(p: &dyn ScpProblem, lin: &Linearization) -> Self {
        Self {
            n: p.dim(),
            m: lin.residual.len(),
            limited: p.limit().is_some(),
        }
    }

    /// Number of variables.
    fn len(&self) -> usize {
        self.n + 1 + 2 * self.m + usize::from(self.limited)
    }

    /// Columns of the step `dz`.
    fn dz(&self) -> std::ops::Range<usize> {
        0..self.n
    }

    /// Column of the epigraph `t`.
    fn t(&self) -> usize {
        self.n
    }

    /// Column of `nu+` of residual `i`.
    fn nu_plus(&self, i: usize) -> usize {
        self.n + 1 + i
    }

    /// Column of `nu-` of residual `i`.
    fn nu_minus(&self, i: usize) -> usize {
        self.n + 1 + self.m + i
    }

    /// Columns of every virtual control, `nu+` then `nu-`.
    fn virtual_controls(&self) -> std::ops::Range<usize> {
        self.nu_plus(0)..self.nu_minus(self.m)
    }

    /// Column of the limits' slack `sigma` (only with limits).
    fn sigma(&self) -> usize {
        debug_assert!(self.limited, "no limits: no slack");
        self.n + 1 + 2 * self.m
    }

    /// The step `dz` in a solution `x`.
    fn step<'x>(&self, x: &'x [f64]) -> &'x [f64] {
        &x[self.dz()]
    }

    /// The epigraph `t` in a solution.
    fn epigraph(&self, x: &[f64]) -> f64 {
        x[self.t()]
    }

    /// The virtual control `nu+ - nu-` of residual `i` in a solution: the
    /// model's residual `r + J dz` there.
    fn virtual_control(&self, x: &[f64], i: usize) -> f64 {
        x[self.nu_plus(i)] - x[self.nu_minus(i)]
    }

    /// The limits' slack `sigma` in a solution (zero without limits).
    fn slack(&self, x: &[f64]) -> f64 {
        if self.limited { x[self.sigma()] } else { 0.0 }
    }
}

/// The convex subproblem at `z`, in the variables of [`Layout`]. Returns the data, the
/// model's constant (`cost(z)` for costs without an epigraph), and the rows
/// of the terms and of the limited terms.
#[allow(clippy::too_many_arguments)]
fn subproblem(
    p: &dyn ScpProblem,
    z: &[f64],
    lin: &Linearization,
    scales: &[f64],
    radius: f64,
    w: f64,
    hessian: &Triplets,
    keep: Option<&Screen>,
) -> (ConicData, f64, TermRows, TermRows) {
    let v = Layout::of(p, lin);
    let (n, m, t) = (v.n, v.m, v.t());
    let limit = p.limit();
    let mut d = ConicData::new(v.len());
    let cost = p.cost();
    for i in 0..m {
        d.q[v.nu_plus(i)] = w;
        d.q[v.nu_minus(i)] = w;
    }
    // a light proximal term keeps the step unique where the model is flat
    let mut p_diag = vec![0.0; d.n];
    for i in 0..n {
        p_diag[i] = 1e-9 / (scales[i] * scales[i]);
    }
    d.p_upper = hessian.clone();
    let mut constant = 0.0;
    match &cost {
        Cost::Peak => d.q[t] = 1.0,
        Cost::Linear(c) => {
            for &(i, a) in c {
                d.q[i] += a;
                constant += a * z[i];
            }
        }
        Cost::SumOfSquares => {
            // |f + J dz|^2 = |f|^2 + 2 f'J dz + dz' J'J dz: P = 2 J'J
            constant = lin.terms.iter().map(|x| x * x).sum();
            let mut jr: Vec<Vec<(usize, f64)>> = vec![Vec::new(); lin.terms.len()];
            for &(r, c, v) in &lin.terms_jac {
                jr[r].push((c, v));
                d.q[c] += 2.0 * lin.terms[r] * v;
            }
            for row in &jr {
                for &(a, va) in row {
                    for &(b, vb) in row {
                        if a < b {
                            d.p_upper.push((a, b, 2.0 * va * vb));
                        } else if a == b {
                            p_diag[a] += 2.0 * va * vb;
                        }
                    }
                }
            }
        }
    }
    d.p_diag = Some(p_diag);
    // linearised equalities with virtual control: r + J dz - nu+ + nu- = 0
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
    for &(r, c, v) in &lin.residual_jac {
        rows[r].push((c, v));
    }
    for (i, mut row) in rows.into_iter().enumerate() {
        row.push((v.nu_plus(i), -1.0));
        row.push((v.nu_minus(i), 1.0));
        d.row(&row, -lin.residual[i]);
    }
    if cost != Cost::Peak {
        // no epigraph: t = 0
        d.row(&[(t, 1.0)], 0.0);
    }
    d.cone(Cone::Zero(m + usize::from(cost != Cost::Peak)));
    p.add_constraints(&mut d, z, &|i| i);
    let dim = p.term_dim();
    let term_rows = if cost == Cost::Peak {
        norm_rows(
            &mut d,
            &lin.terms,
            &lin.terms_jac,
            dim,
            p.norm(),
            (&[(t, 1.0)], 0.0),
        )
    } else {
        Vec::new()
    };
    // limits with elastic slack, relative: |g + G dz| / L <= 1 + sigma
    let limit_rows = match limit {
        Some(l) if held_by_epigraph(p) => {
            // |f + F dz| <= t <= L (1 + sigma): the limit's multiplier
            // reaches the terms through t
            d.q[v.sigma()] = w;
            d.row(&[(t, 1.0), (v.sigma(), -l)], l);
            d.cone(Cone::Nonneg(1));
            Vec::new()
        }
        Some(_) => {
            d.q[v.sigma()] = w;
            norm_rows_kept(
                &mut d,
                &lin.limited,
                &lin.limited_jac,
                dim,
                p.norm(),
                (&[(v.sigma(), 1.0)], 1.0),
                keep,
            )
        }
        None => Vec::new(),
    };
    // nu >= 0, sigma >= 0, trust region
    for j in v.virtual_controls() {
        d.row(&[(j, -1.0)], 0.0);
    }
    if limit.is_some() {
        d.row(&[(v.sigma(), -1.0)], 0.0);
    }
    for i in v.dz() {
        d.row(&[(i, 1.0)], radius * scales[i]);
        d.row(&[(i, -1.0)], radius * scales[i]);
    }
    d.cone(Cone::Nonneg(2 * m + usize::from(limit.is_some()) + 2 * n));
    (d, constant, term_rows, limit_rows)
}

/// For each flattened term, the subproblem rows it appears in and the sign
/// with which the row's dual multiplies the term in the Lagrangian.
type TermRows = Vec<Vec<(usize, f64)>>;

/// Second-order correction at the trial point `z+ = z + dz`: the least
/// scaled-norm `dc` with `J dc = (r + J dz) - r(z+)` (back onto the model's
/// prediction of the residual) that keeps the exact constraints. This undoes
/// the curvature of `r` (here the attitude's, a holonomy that is quadratic in
/// the path) that would otherwise force tiny trust regions. With `bounds`,
/// the terms at `z+` are also brought back under the model's bounds,
/// `|f(z+) + F dc| <= t` (peak cost) and `|g(z+) + G dc| <= L + sigma`
/// (limits), the same curvature effect on the norm rows. Both are elastic
/// (slacks weighted by `slack_weight`, [`Correction::slack_weight`]), so
/// the correction always exists; the merit judges it. The solution's first
/// `n` entries are `dc`.
fn correction(
    p: &dyn ScpProblem,
    z_trial: &[f64],
    lin: &Linearization,
    target_minus_actual: &[f64],
    scales: &[f64],
    bounds: Option<(&Values, f64, f64)>,
    slack_weight: f64,
) -> ConicData {
    let n = p.dim();
    let m = target_minus_actual.len();
    // dc, then the residual's slacks s+ and s-, then the bounds' slack tau
    let extra = 2 * m + 1;
    let (sp, sm, tau) = (n, n + m, n + 2 * m);
    let mut d = ConicData::new(n + extra);
    let mut pd: Vec<f64> = scales.iter().map(|s| 1.0 / (s * s)).collect();
    pd.resize(n + extra, 0.0);
    d.p_diag = Some(pd);
    for i in n..n + extra {
        d.q[i] = slack_weight;
    }
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
    for &(r, c, v) in &lin.residual_jac {
        rows[r].push((c, v));
    }
    for (i, mut row) in rows.into_iter().enumerate() {
        row.push((sp + i, -1.0));
        row.push((sm + i, 1.0));
        d.row(&row, target_minus_actual[i]);
    }
    d.cone(Cone::Zero(m));
    p.add_constraints(&mut d, z_trial, &|i| i);
    let tau_e = [(tau, 1.0)];
    if let Some((at, t, l)) = bounds {
        let dim = p.term_dim();
        if p.cost() == Cost::Peak {
            norm_rows(
                &mut d,
                &at.terms,
                &lin.terms_jac,
                dim,
                p.norm(),
                (&tau_e, t),
            );
        }
        // limits that are the terms are held by `t`, which is at most the limit
        if !at.limited.is_empty() && !held_by_epigraph(p) {
            norm_rows(
                &mut d,
                &at.limited,
                &lin.limited_jac,
                dim,
                p.norm(),
                (&tau_e, l),
            );
        }
    }
    for i in n..n + extra {
        d.row(&[(i, -1.0)], 0.0);
    }
    d.cone(Cone::Nonneg(extra));
    d
}

/// One subproblem as built: its point, linearisation, data, the rows of
/// its terms and limits ([`subproblem`]'s), and the penalty weight.
struct Model<'a> {
    z: &'a [f64],
    lin: &'a Linearization,
    data: &'a ConicData,
    term_rows: &'a TermRows,
    limit_rows: &'a TermRows,
    w: f64,
}

impl Model<'_> {
    /// The change of the subproblem's `b` when its residuals, terms and
    /// limited terms change by `d`: [`subproblem`] puts the residuals first
    /// (`b = -r`), and a term with sign `s` in a row's Lagrangian has `-s`
    /// times its value in that row's `b` (what rebuilding the subproblem
    /// would give, without its matrix).
    fn rhs_change(&self, d: &Values) -> Vec<f64> {
        let mut db = vec![0.0; self.data.b.len()];
        for (b, r) in db.iter_mut().zip(&d.residual) {
            *b = -r;
        }
        for (rows, change) in [(self.term_rows, &d.terms), (self.limit_rows, &d.limited)] {
            for (rows, c) in rows.iter().zip(change) {
                for &(row, sign) in rows {
                    db[row] -= sign * c;
                }
            }
        }
        db
    }
}

/// Fletcher's second-order correction, to first order: the subproblem
/// again, with the constant of every nonlinear row (a peak's terms,
/// limits, residuals; a sum of squares' terms are in the objective, not in
/// the rows, and stay) shifted by its linearisation error at the trial point
/// `c(z + d) - c(z) - J d`, solved from the subproblem's solution with the
/// solution's own active set (one KKT solve with the interior point's final
/// scaling, [`ConicSolver::kkt_at_solution`]); repeated `rounds` times with
/// the error at the corrected point, the best merit kept. One
/// factorisation and a few triangular solves, where the conic correction
/// ([`correction`]) is a whole interior-point solve (about 20
/// factorisations).
fn sensitivity_correction(
    p: &dyn ScpProblem,
    model: &Model,
    step: &[f64],
    at: &Values,
    solver: &mut ConicSolver,
    rounds: usize,
) -> Option<(Vec<f64>, Merit)> {
    let kkt = solver.kkt_at_solution(model.data)?;
    let lin = model.lin;
    let mut d = step.to_vec();
    let mut at = at.clone();
    let mut best: Option<(Vec<f64>, Merit)> = None;
    for _ in 0..rounds {
        // each value's linearisation error at z + d, c(z + d) - c(z) - J d
        let error = |vals: &[f64], jac: &Triplets, actual: &[f64]| -> Vec<f64> {
            let mut error: Vec<f64> = actual.iter().zip(vals).map(|(a, v)| a - v).collect();
            for &(r, c, v) in jac {
                error[r] -= v * d[c];
            }
            error
        };
        let shift = Values {
            terms: error(&lin.terms, &lin.terms_jac, &at.terms),
            limited: error(&lin.limited, &lin.limited_jac, &at.limited),
            residual: error(&lin.residual, &lin.residual_jac, &at.residual),
        };
        let dx = kkt.primal_change(&model.rhs_change(&shift));
        if dx.iter().any(|v| !v.is_finite()) {
            break;
        }
        d = step.iter().zip(&dx).map(|(a, b)| a + b).collect();
        let corrected: Vec<f64> = model.z.iter().zip(&d).map(|(a, b)| a + b).collect();
        at = evaluate(p, &corrected);
        let m = merit_of(p, &corrected, &at, model.w);
        if best.as_ref().is_none_or(|b| m.0 < b.1.0) {
            best = Some((corrected, m));
        }
    }
    best
}

/// Largest scaled component `|d_i| / scale_i` of a step.
fn scaled_max(d: impl Iterator<Item = f64>, scales: &[f64]) -> f64 {
    d.zip(scales).fold(0.0, |m, (d, s)| m.max(d.abs() / s))
}

/// Fixed-pattern Clarabel solvers reused across iterations, and across the
/// runs of problems with one pattern ([`Executor::run_reusing`]: a replan's
/// subproblems are the last one's with other values).
#[derive(Default)]
pub struct Solvers {
    subproblem: Option<ConicSolver>,
    /// The limit rows the subproblem solver's pattern holds.
    screen: Option<Screen>,
    /// Rows left out that a subproblem's solution broke: held from then on.
    added: Screen,
    correction: Option<ConicSolver>,
    bounded_correction: Option<ConicSolver>,
}

/// The convex subproblem at the state's point, as built: its linearisation,
/// data, constant and rows ([`subproblem`]'s) and its variables.
struct Subproblem {
    lin: Linearization,
    hessian: Triplets,
    data: ConicData,
    constant: f64,
    term_rows: TermRows,
    limit_rows: TermRows,
    layout: Layout,
}

/// Where the SCP stands between iterations: the iterate and everything the
/// rules carry from one iteration to the next.
struct State {
    /// The iterate.
    z: Vec<f64>,
    /// The merit at `z` for `weight`.
    here: Merit,
    /// The trust radius (scaled units).
    radius: f64,
    /// The penalty weight, in the cost's unit.
    weight: f64,
    /// The weight at the start: the stagnation rule's raises count from it.
    weight_start: f64,
    /// The penalty's scale: the cost at the start; for a peak cost at least
    /// the limit. The weight's bounds are multiples of it.
    scale: f64,
    /// The multipliers and curvature scale of the next subproblem's Hessian.
    multipliers: Multipliers,
    solvers: Solvers,
    /// The watchdog's point before a tentative step.
    anchor: Option<Anchor>,
    /// Whether the watchdog may take a tentative step (re-armed by an
    /// accepted step).
    armed: bool,
    /// Whether the last step was rejected: the radius does not grow right
    /// after one.
    last_rejected: bool,
    /// Failed subproblems in a row.
    failures: usize,
    /// The merit after each judged iteration at this weight (the progress
    /// rule's window).
    merits: Vec<f64>,
    /// `(violation, cost)` after each judged iteration at this weight
    /// (rejected steps count: at an infeasible minimum of the merit the
    /// steps there are rejected while the radius shrinks).
    history: Vec<(f64, f64)>,
    /// Critical points in a row at a nearly feasible violation.
    nearly: usize,
    /// A raise of the weight the last iteration decided: applied before the
    /// next one (or at the end), so that the stopping rules see the
    /// iteration's own weight and history.
    raise: bool,
}

impl State {
    /// Back to the point before a tentative step.
    fn restore(&mut self, a: Anchor) {
        (self.z, self.here, self.radius, self.multipliers) = (a.z, a.merit, a.cut, a.multipliers);
    }
}

/// What one call of [`Scp::next_iter`] did.
enum Step {
    /// The subproblem failed and counts as a rejection (no record).
    Failed,
    /// The subproblem failed once more than the trust region's
    /// `max_failures`: the solve ends at its point.
    Unsolvable,
    /// A tentative step, or the step after it that undid both (see
    /// [`ScpSettings::watchdog`]): recorded, not judged by the stopping rules.
    Watchdog(ScpIteration),
    /// A step judged by the merit: recorded, then the stopping rules.
    Judged(ScpIteration),
}

/// Why a solve ended (argmin's termination reason).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Termination {
    /// Converged: the criticality fell below the tolerance at a feasible point.
    Criticality,
    /// Converged: the merit stopped falling (by the tolerance per iteration
    /// over the window) at a feasible point.
    Progress,
    /// The constraints stayed violated while the penalty weight outgrew its
    /// bound.
    Infeasible,
    /// The trust region collapsed without converging.
    Stalled,
    /// The subproblem could not be solved however the trust region shrank
    /// (its solver failed `max_failures + 1` times in a row).
    Unsolvable,
    /// The iteration limit.
    IterationLimit,
}

impl Termination {
    /// The reason in words.
    pub fn text(self) -> &'static str {
        match self {
            Termination::Criticality => "converged: criticality below the tolerance",
            Termination::Progress => "converged: the merit stopped falling",
            Termination::Infeasible => {
                "locally infeasible: the constraints stayed violated as the penalty grew"
            }
            Termination::Stalled => "stalled: the trust region collapsed",
            Termination::Unsolvable => {
                "stalled: the subproblem's solver failed however small the trust region"
            }
            Termination::IterationLimit => "the iteration limit",
        }
    }

    /// The run's status.
    pub fn status(self) -> ScpStatus {
        match self {
            Termination::Criticality | Termination::Progress => ScpStatus::Converged,
            Termination::Infeasible => ScpStatus::Infeasible,
            Termination::Stalled | Termination::Unsolvable => ScpStatus::Stalled,
            Termination::IterationLimit => ScpStatus::IterationLimit,
        }
    }

    /// The certificate's rule ([`StopRule::None`] unless converged).
    pub fn rule(self) -> StopRule {
        match self {
            Termination::Criticality => StopRule::Criticality,
            Termination::Progress => StopRule::Progress,
            _ => StopRule::None,
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.text())
    }
}

/// The SCP as a solver (argmin's `Solver`): [`Scp::next_iter`] is one
/// iteration on a [`State`], [`Scp::terminate`] its stopping rules; the
/// [`Executor`] runs the loop.
struct Scp<'a> {
    p: &'a dyn ScpProblem,
    s: &'a ScpSettings,
    scales: Vec<f64>,
    /// Whether the cost is linear (the stagnation rule's cost).
    linear_cost: bool,
}

impl<'a> Scp<'a> {
    fn new(p: &'a dyn ScpProblem, s: &'a ScpSettings) -> Self {
        Self {
            p,
            s,
            scales: p.scales(),
            linear_cost: matches!(p.cost(), Cost::Linear(_)),
        }
    }

    /// The state at `z0`, with a neighbour's weight, radius and multipliers.
    fn init(&self, z0: Vec<f64>, warm: Option<&WarmStart>) -> State {
        let (p, s) = (self.p, self.s);
        // the penalty's scale: the cost at the start; for a peak cost at
        // least the limit, which is in the cost's unit (a torque-speed line
        // can make it many times the cost), up to `max_limit_scale` times
        // the cost. A time or energy cost has
        // another unit: there the limit's size (torque) says nothing about
        // the multipliers, and a weight hundreds of times the cost makes the
        // merit all penalty
        let (_, cost0, _) = merit(p, &z0, 0.0);
        let scale = match p.cost() {
            Cost::Peak => cost0.abs().max(
                p.limit()
                    .unwrap_or(0.0)
                    .min(s.penalty.max_limit_scale * cost0.abs()),
            ),
            Cost::Linear(_) | Cost::SumOfSquares => cost0.abs(),
        }
        .max(1e-12);
        // at least a neighbour's weight (see Penalty::max_carried): a
        // weight below its multipliers lets the merit drift to violations
        // that the stopping rules must then raise it out of
        let start = s.penalty.weight * scale;
        let weight = start.max(
            warm.map_or(0.0, |ws| ws.weight)
                .min(s.penalty.max_carried * s.penalty.weight * scale),
        );
        let radius = warm.map_or(s.trust.initial_radius, |w| {
            w.radius.clamp(s.trust.warm_floor, s.trust.initial_radius)
        });
        let multipliers = warm.map_or_else(Multipliers::default, |w| Multipliers {
            // a neighbour's curvature scale belongs to its tail
            curvature: 1.0,
            ..w.multipliers.clone()
        });
        let here = merit(p, &z0, weight);
        State {
            z: z0,
            here,
            radius,
            weight,
            weight_start: weight,
            scale,
            multipliers,
            solvers: Solvers::default(),
            anchor: None,
            armed: true,
            last_rejected: false,
            failures: 0,
            merits: Vec::new(),
            history: Vec::new(),
            nearly: 0,
            raise: false,
        }
    }

    /// One iteration: a pending raise of the weight, the step, the
    /// watchdog, then (for a judged step) acceptance, the trust region, the
    /// history and the penalty's next weight.
    fn next_iter(&self, state: &mut State, iteration: usize) -> Result<Step> {
        self.raise_weight(state);
        let (mut rec, trial, there) = match self.step(state, iteration) {
            Ok(x) => {
                state.failures = 0;
                x
            }
            Err(Error::Solver { .. }) => {
                self.failed(state);
                return Ok(if state.failures <= self.s.trust.max_failures {
                    Step::Failed
                } else {
                    Step::Unsolvable
                });
            }
            Err(e) => return Err(e),
        };
        if let Some(a) = state.anchor.take() {
            // the step after a tentative one: judged against the anchor
            rec.accepted = rec.predicted > 0.0
                && a.merit.0 - there.0 >= self.s.watchdog.decrease * a.predicted;
            if !rec.accepted {
                self.undo(state, a, &mut rec);
                return Ok(Step::Watchdog(rec));
            }
        } else if self.tentative(state, &rec, &there) {
            rec.tentative = true;
            state.anchor = Some(Anchor {
                z: std::mem::replace(&mut state.z, trial),
                merit: std::mem::replace(&mut state.here, there),
                predicted: rec.predicted,
                cut: self.cut(&rec),
                multipliers: state.multipliers.clone(),
                bounded: rec.bounded(),
            });
            return Ok(Step::Watchdog(rec));
        }
        if rec.accepted {
            (state.z, state.here) = (trial, there);
            state.armed = true;
        }
        if self.s.curvature.adapt {
            state.multipliers.adapt_curvature(&rec, &self.s.curvature);
        }
        self.update_radius(state, &rec);
        let (phi, cost, inf) = state.here;
        state.merits.push(phi);
        state.history.push((inf, cost));
        self.decide_weight(state, &rec);
        Ok(Step::Judged(rec))
    }

    /// The convex model at the state's point.
    fn model(&self, state: &mut State) -> Subproblem {
        let (p, z, mult) = (self.p, &state.z, &mut state.multipliers);
        let lin = linearize(p, z);
        mult.terms.resize(lin.terms.len(), 0.0);
        mult.limited.resize(lin.limited.len(), 0.0);
        // the multipliers of the relative limits are L times the problem's
        let u_abs: Vec<f64> = mult
            .limited
            .iter()
            .map(|x| x / p.limit().unwrap_or(1.0))
            .collect();
        let mut hessian = p.hessian(z, &mult.terms, &u_abs);
        hessian.iter_mut().for_each(|e| e.2 *= mult.curvature);
        if self.screens() {
            let (dim, norm, sv) = (p.term_dim(), p.norm(), &mut state.solvers);
            let band = self.s.screen_band;
            let mut need = screen(&lin, &self.scales, state.radius, band, dim, norm);
            if sv.added.len() == need.len() {
                need.iter_mut().zip(&sv.added).for_each(|(n, a)| *n |= a);
            } else {
                sv.added = vec![0; need.len()];
            }
            if !sv.screen.as_ref().is_some_and(|h| holds(h, &need)) {
                // a little wider than needed, so that the next iterations'
                // rows fit in the same pattern
                let r = SCREEN_MARGIN * state.radius;
                let mut wide = screen(&lin, &self.scales, r, SCREEN_MARGIN * band, dim, norm);
                wide.iter_mut().zip(&need).for_each(|(w, n)| *w |= n);
                sv.screen = Some(wide);
            }
        }
        self.assemble(state, lin, hessian)
    }

    /// Whether the subproblems leave out limit rows ([`ScpSettings::screen`]).
    fn screens(&self) -> bool {
        self.s.screen && self.p.limit().is_some() && !held_by_epigraph(self.p)
    }

    /// The subproblem at the state's point from its linearisation and
    /// Hessian, with the limit rows of the held [`Screen`].
    fn assemble(&self, state: &State, lin: Linearization, hessian: Triplets) -> Subproblem {
        let p = self.p;
        let keep = state.solvers.screen.as_ref().filter(|_| self.screens());
        let (data, constant, term_rows, limit_rows) = subproblem(
            p,
            &state.z,
            &lin,
            &self.scales,
            state.radius,
            state.weight,
            &hessian,
            keep,
        );
        let layout = Layout::of(p, &lin);
        Subproblem {
            lin,
            hessian,
            data,
            constant,
            term_rows,
            limit_rows,
            layout,
        }
    }

    /// Solves the model: its solution, objective and solve time (ms); the
    /// terms' and limits' multipliers are kept for the next model's
    /// curvature.
    fn solve_model(
        &self,
        state: &mut State,
        sub: &Subproblem,
        iteration: usize,
    ) -> Result<(Vec<f64>, f64, f64)> {
        let clock = Instant::now();
        let (st, x, obj) =
            solve_reusing_with(&mut state.solvers.subproblem, &sub.data, self.s.conic)?;
        let solve_ms = clock.elapsed().as_secs_f64() * 1e3;
        if !st.ok() {
            return Err(Error::Solver {
                what: format!("SCP subproblem {iteration}"),
                status: format!("{st:?}"),
                hint: "try another seed (--seed), more free.nodes, or report the config".into(),
            });
        }
        let mult = &mut state.multipliers;
        if let Some(sv) = &state.solvers.subproblem {
            let dual = sv.duals();
            for (v, rows) in [
                (&mut mult.terms, &sub.term_rows),
                (&mut mult.limited, &sub.limit_rows),
            ] {
                for (yr, rows) in v.iter_mut().zip(rows) {
                    *yr = rows.iter().map(|&(row, sign)| sign * dual[row]).sum();
                }
            }
            if sub.limit_rows.is_empty() {
                // no rows of their own (none, or held by `t`): the terms'
                // multipliers carry the limit, and a neighbour's must not linger
                mult.limited.fill(0.0);
            }
        }
        Ok((x, obj, solve_ms))
    }

    /// One step from the state's point: the model, its solution, a
    /// second-order correction when the merit falls short of the model, and
    /// the record with `accepted` judged by `rho` (the watchdog may revise
    /// it). Returns the record, the trial point and its merit.
    fn step(&self, state: &mut State, iteration: usize) -> Result<(ScpIteration, Vec<f64>, Merit)> {
        let (p, s) = (self.p, self.s);
        let mut sub = self.model(state);
        let (mut x, mut obj, mut solve_ms) = self.solve_model(state, &sub, iteration)?;
        // rows left out that the solution breaks: held, and solved again,
        // so the solution is the whole subproblem's
        while let Some(held) = state.solvers.screen.as_mut().filter(|_| self.screens()) {
            let broken = broken_rows(&sub.lin, held, &x, &sub.layout, p.norm(), p.term_dim());
            if broken.is_empty() {
                break;
            }
            for &(r, bit) in &broken {
                held[r] |= bit;
                state.solvers.added[r] |= bit;
            }
            sub = self.assemble(state, sub.lin, sub.hessian);
            let (x2, obj2, ms) = self.solve_model(state, &sub, iteration)?;
            (x, obj, solve_ms) = (x2, obj2, solve_ms + ms);
        }
        let (phi, cost, inf) = state.here;
        let v = sub.layout;
        // model value: the cost's constant plus the solver's objective
        // (t or the cost's linear/quadratic model, w |nu|_1 + w sigma, 1/2 dz' P dz)
        let predicted = phi - (sub.constant + obj);
        let model_step = scaled_max(v.step(&x).iter().copied(), &self.scales);
        let mut trial: Vec<f64> = state.z.iter().zip(v.step(&x)).map(|(a, b)| a + b).collect();
        let at = evaluate(p, &trial);
        let mut there = merit_of(p, &trial, &at, state.weight);
        if predicted > 0.0 && phi - there.0 < s.correction.below * predicted {
            (trial, there) = self.correct(state, &sub, &x, predicted, trial, &at, there);
        } else if predicted > 0.0
            && self.linear_cost
            && s.correction.accepted_steps
            && there.2 > s.feasibility
            && let Some(polished) =
                self.sensitivity(state, &sub, &x, &at, s.correction.rounds.max(1))
            && polished.1.0 < there.0
        {
            (trial, there) = polished;
        }
        let step = scaled_max(trial.iter().zip(&state.z).map(|(a, b)| a - b), &self.scales);
        let actual = phi - there.0;
        let rho = if predicted > 0.0 {
            actual / predicted
        } else {
            0.0
        };
        // a trial point the model cannot evaluate (a non-finite merit) is a
        // rejection that cuts the radius, not a NaN that neither cuts nor grows it
        let rho = if rho.is_nan() { f64::NEG_INFINITY } else { rho };
        let accepted = predicted > 0.0 && rho > s.trust.accept;
        let rec = ScpIteration {
            iteration,
            merit: phi,
            objective: cost,
            infeasibility: inf,
            radius: state.radius,
            weight: state.weight,
            predicted,
            actual,
            rho,
            accepted,
            tentative: false,
            merit_after: if accepted { there.0 } else { phi },
            step,
            model_step,
            solve_ms,
        };
        Ok((rec, trial, there))
    }

    /// The second-order correction of the trial point `trial` (values `at`,
    /// merit `there`) of the model's solution `x`: the sensitivity
    /// correction first, the conic one (with the terms' bounds, then
    /// without when the solver fails on that one) when it recovers too
    /// little. A cheap correction that falls short is kept only when the
    /// conic one fails or is disabled: it took the path to worse points.
    /// Returns the point kept and its merit.
    // the trial's three parts (point, values, merit) travel together; the
    // SCP's own layout owns this signature
    #[allow(clippy::too_many_arguments)]
    fn correct(
        &self,
        state: &mut State,
        sub: &Subproblem,
        x: &[f64],
        predicted: f64,
        trial: Vec<f64>,
        at: &Values,
        there: Merit,
    ) -> (Vec<f64>, Merit) {
        let (p, s, v) = (self.p, self.s, sub.layout);
        let phi = state.here.0;
        // back onto the model's residual at the trial point, r + J dz = nu+ - nu-
        let rhs: Vec<f64> = (0..v.m)
            .map(|i| v.virtual_control(x, i) - at.residual[i])
            .collect();
        // the terms' bounds: t, L + sigma from the subproblem
        let has_bounds = p.cost() == Cost::Peak || p.limit().is_some();
        let sigma = 1.0 + v.slack(x);
        let cheap = (s.correction.rounds > 0)
            .then(|| self.sensitivity(state, sub, x, at, s.correction.rounds))
            .flatten();
        let mut best: Option<(Vec<f64>, Merit)> = None;
        let mut fallback = None;
        if let Some((corrected, at_c)) = cheap
            && at_c.0 < there.0
        {
            if phi - at_c.0 > s.correction.sensitivity_accept * predicted {
                best = Some((corrected, at_c));
            } else {
                fallback = Some((corrected, at_c));
            }
        }
        if best.is_none() && s.correction.conic_enabled {
            let tries = [
                (true, &mut state.solvers.bounded_correction),
                (false, &mut state.solvers.correction),
            ];
            for (with_bounds, slot) in tries {
                if with_bounds && !has_bounds {
                    continue;
                }
                let bounds = with_bounds.then_some((at, v.epigraph(x), sigma));
                let cd = correction(
                    p,
                    &trial,
                    &sub.lin,
                    &rhs,
                    &self.scales,
                    bounds,
                    s.correction.slack_weight,
                );
                if let Ok((cs, dc, _)) = solve_reusing_with(slot, &cd, s.conic)
                    && cs.ok()
                {
                    let corrected: Vec<f64> =
                        trial.iter().zip(&dc[..v.n]).map(|(a, b)| a + b).collect();
                    let at_c = merit(p, &corrected, state.weight);
                    if at_c.0 < there.0 {
                        best = Some((corrected, at_c));
                    }
                    fallback = None;
                    break;
                }
            }
        }
        best.or(fallback).unwrap_or((trial, there))
    }

    /// [`sensitivity_correction`] of the model's solution `x` (the trial's
    /// values `at`) on the subproblem's own solver, `rounds` rounds: the
    /// point and its merit.
    fn sensitivity(
        &self,
        state: &mut State,
        sub: &Subproblem,
        x: &[f64],
        at: &Values,
        rounds: usize,
    ) -> Option<(Vec<f64>, Merit)> {
        let solver = state.solvers.subproblem.as_mut()?;
        let model = Model {
            z: &state.z,
            lin: &sub.lin,
            data: &sub.data,
            term_rows: &sub.term_rows,
            limit_rows: &sub.limit_rows,
            w: state.weight,
        };
        sensitivity_correction(self.p, &model, sub.layout.step(x), at, solver, rounds)
    }

    /// A subproblem the conic solver could not finish: a rejected step (a
    /// smaller trust region is a better-conditioned subproblem); a
    /// tentative point the solver cannot step from is undone.
    fn failed(&self, state: &mut State) {
        state.failures += 1;
        state.radius *= self.s.trust.failure_cut;
        if let Some(a) = state.anchor.take() {
            state.restore(a);
            state.armed = false;
        }
        state.last_rejected = true;
        state.solvers.subproblem = None;
    }

    /// Whether the watchdog takes a step the merit would reject,
    /// tentatively: for a peak cost, when armed, for a finite trial merit,
    /// and not at a converged point, where `rho` is noise (the rules stop
    /// there).
    fn tentative(&self, state: &State, rec: &ScpIteration, there: &Merit) -> bool {
        let s = self.s;
        s.watchdog.enabled
            && self.p.cost() == Cost::Peak
            && state.armed
            && rec.predicted > 0.0
            && rec.rho < s.trust.accept
            && there.0.is_finite()
            && !(rec.criticality_within(s.feasibility) <= s.tolerance
                && state.here.2 <= s.feasibility)
    }

    /// The step after a tentative one fell short: both are undone (the
    /// record's `merit_after` is the anchor's, where the iterate is again),
    /// the radius cut as for the anchor's rejection, its curvature restored
    /// and scaled for that rejection.
    fn undo(&self, state: &mut State, a: Anchor, rec: &mut ScpIteration) {
        rec.merit_after = a.merit.0;
        let bounded = a.bounded;
        state.restore(a);
        state.armed = false;
        if self.s.curvature.adapt && !bounded {
            // the anchor's own step was the rejected one
            state.multipliers.reject_curvature(&self.s.curvature);
        }
        state.last_rejected = true;
    }

    /// The radius after rejecting `rec`'s step: a share of the model's step
    /// (see [`TrustRegion::cut`]).
    fn cut(&self, rec: &ScpIteration) -> f64 {
        let t = &self.s.trust;
        rec.radius
            * if rec.predicted > 0.0 {
                t.cut * (rec.model_step / rec.radius).clamp(t.least_cut, 1.0)
            } else {
                t.cut
            }
    }

    /// The trust region after a judged step: cut below
    /// [`TrustRegion::accept`], grown above [`TrustRegion::grow_above`]
    /// except right after a rejection.
    fn update_radius(&self, state: &mut State, rec: &ScpIteration) {
        let t = &self.s.trust;
        if rec.rho < t.accept {
            state.radius = self.cut(rec);
        } else if rec.rho > t.grow_above && !state.last_rejected {
            state.radius = (state.radius * t.growth).min(t.max_radius);
        }
        state.last_rejected = !rec.accepted;
    }

    /// Whether a linear cost's violation stagnates at this weight (see
    /// [`Penalty::stagnation`]).
    fn stagnates(&self, state: &State) -> bool {
        let (s, k) = (self.s, self.s.penalty.stagnation);
        let (_, cost_now, inf_now) = state.here;
        k > 0
            && self.linear_cost
            && state.history.len() > k
            && inf_now > s.penalty.nearly_feasible * s.feasibility
            && state.weight < s.penalty.stagnation_cap * state.weight_start
            && {
                let (inf_then, cost_then) = state.history[state.history.len() - 1 - k];
                inf_now > s.penalty.stagnation_fall * inf_then
                    && (cost_now - cost_then).abs() < s.penalty.stagnation_cost * cost_now.abs()
            }
    }

    /// Whether `rec`'s criticality is within the tolerance (and the
    /// violation does not stagnate).
    fn critical(&self, state: &State, rec: &ScpIteration) -> bool {
        !self.stagnates(state) && rec.criticality_within(self.s.feasibility) <= self.s.tolerance
    }

    /// Whether the merit fell by less than `tolerance` (relative) per
    /// iteration, on average over the window (and the violation does not
    /// stagnate).
    fn slow(&self, state: &State) -> bool {
        let (s, m) = (self.s, &state.merits);
        let phi_now = state.here.0;
        !self.stagnates(state)
            && m.len() > s.window
            && m[m.len() - 1 - s.window] - phi_now <= s.tolerance * s.window as f64 * phi_now.abs()
    }

    /// Whether the violation is within `feasibility`.
    fn feasible(&self, state: &State) -> bool {
        state.here.2 <= self.s.feasibility
    }

    /// The penalty after a judged step: raised when the violation
    /// stagnates, or when the model is critical while infeasible beyond
    /// [`Penalty::nearly_feasible`] or for longer than
    /// [`Penalty::patience`]; a nearly feasible critical point keeps the
    /// weight (the next steps remove a small violation at this weight, and
    /// raising it would only shrink the steps).
    fn decide_weight(&self, state: &mut State, rec: &ScpIteration) {
        let pen = &self.s.penalty;
        if self.critical(state, rec) || self.slow(state) {
            if self.feasible(state) {
                // converged: the rules stop here
                state.raise = false;
                return;
            }
            state.nearly += 1;
            state.raise = state.here.2 > pen.nearly_feasible * self.s.feasibility
                || state.nearly > pen.patience;
        } else {
            state.nearly = 0;
            state.raise = self.stagnates(state);
        }
    }

    /// Applies a raise of the weight decided by the last iteration: the
    /// merit at the new weight, a new history.
    fn raise_weight(&self, state: &mut State) {
        if !std::mem::take(&mut state.raise) {
            return;
        }
        state.weight *= self.s.penalty.growth;
        state.here = merit(self.p, &state.z, state.weight);
        state.merits.clear();
        state.history.clear();
        state.nearly = 0;
    }

    /// The stopping rules after a judged step, in order.
    fn terminate(&self, state: &State, rec: &ScpIteration) -> Option<Termination> {
        converged_by_criticality(self, state, rec)
            .or_else(|| converged_by_progress(self, state))
            .or_else(|| infeasible(self, state))
            .or_else(|| stalled(self, state))
    }

    /// The result at the end: a pending raise applied, a tentative step
    /// the run ended on undone.
    fn finish(
        &self,
        mut state: State,
        termination: Termination,
        iterations: Vec<ScpIteration>,
        seconds: f64,
    ) -> ScpResult {
        self.raise_weight(&mut state);
        if let Some(a) = state.anchor.take() {
            state.restore(a);
        }
        let (_, objective, infeasibility) = state.here;
        let last = iterations.last().copied();
        let certificate = Certificate {
            step: last.map_or(0.0, |l| l.step),
            constraint_violation: infeasibility,
            criticality: last.map_or(0.0, |l| l.criticality_within(self.s.feasibility)),
            radius: state.radius,
            weight: state.weight / state.scale,
            rule: termination.rule(),
        };
        ScpResult {
            z: state.z,
            status: termination.status(),
            termination,
            objective,
            infeasibility,
            iterations,
            certificate,
            warm: WarmStart {
                multipliers: state.multipliers,
                radius: state.radius,
                weight: state.weight,
            },
            seconds,
        }
    }
}

/// Converged by criticality: within the tolerance at a feasible point.
fn converged_by_criticality(scp: &Scp, state: &State, rec: &ScpIteration) -> Option<Termination> {
    (scp.critical(state, rec) && scp.feasible(state)).then_some(Termination::Criticality)
}

/// Converged by progress: the merit stopped falling at a feasible point.
fn converged_by_progress(scp: &Scp, state: &State) -> Option<Termination> {
    (scp.slow(state) && scp.feasible(state)).then_some(Termination::Progress)
}

/// Locally infeasible: the raise the iteration decided takes the weight past
/// [`Penalty::infeasible`] times its start.
fn infeasible(scp: &Scp, state: &State) -> Option<Termination> {
    let pen = &scp.s.penalty;
    (state.raise && state.weight * pen.growth > pen.infeasible * pen.weight * state.scale)
        .then_some(Termination::Infeasible)
}

/// Stalled: the trust radius fell below [`TrustRegion::min_radius`].
fn stalled(scp: &Scp, state: &State) -> Option<Termination> {
    (state.radius < scp.s.trust.min_radius).then_some(Termination::Stalled)
}

/// What a solve reports as it runs (argmin's observers): each iteration
/// and, for a problem solved on a sequence of meshes, where each begins.
/// Any `FnMut(&ScpIteration)` is an observer that ignores the meshes.
pub trait Observer {
    fn iteration(&mut self, it: &ScpIteration);
    /// The SCP begins on a mesh of `nodes` per phase (mesh continuation
    /// only: each coarse mesh, then the finest; again if the finest starts
    /// over from the seed, numbered on from the coarse meshes: the failed
    /// attempt is not on the record).
    fn mesh(&mut self, _nodes: usize) {}
}

impl<F: FnMut(&ScpIteration)> Observer for F {
    fn iteration(&mut self, it: &ScpIteration) {
        self(it)
    }
}

/// Runs the SCP (argmin's `Executor`): owns the loop, the iteration
/// numbers (numbered on from [`Executor::numbered_from`] across the solves
/// of one design: meshes, re-solves), the clock and the observer.
#[derive(Clone, Copy)]
pub struct Executor<'a> {
    settings: &'a ScpSettings,
    warm: Option<&'a WarmStart>,
    first: usize,
}

impl<'a> Executor<'a> {
    pub fn new(settings: &'a ScpSettings) -> Self {
        Self {
            settings,
            warm: None,
            first: 0,
        }
    }

    /// Starts from a neighbouring solve's multipliers, radius and weight.
    pub fn warm(self, warm: Option<&'a WarmStart>) -> Self {
        Self { warm, ..self }
    }

    /// Numbers the iterations from `first` (the iterations of the solves
    /// before this one).
    pub fn numbered_from(self, first: usize) -> Self {
        Self { first, ..self }
    }

    /// Solves `p` from `z0`, reporting each recorded iteration to
    /// `observer`. Every iteration counts towards the limit; the records are
    /// numbered on from `first` (a failed subproblem, unrecorded, takes no
    /// number), so that a design's records over several solves are
    /// numbered as they were shown.
    pub fn run(
        &self,
        p: &dyn ScpProblem,
        z0: Vec<f64>,
        observer: &mut dyn Observer,
    ) -> Result<ScpResult> {
        self.run_reusing(p, z0, observer, &mut Solvers::default())
    }

    /// [`Executor::run`] with the conic solvers of an earlier run (their
    /// setup and symbolic factorisation are kept where the pattern fits),
    /// left in `solvers` for the next.
    pub fn run_reusing(
        &self,
        p: &dyn ScpProblem,
        z0: Vec<f64>,
        observer: &mut dyn Observer,
        solvers: &mut Solvers,
    ) -> Result<ScpResult> {
        self.settings.validate()?;
        let clock = Instant::now();
        let scp = Scp::new(p, self.settings);
        let mut state = scp.init(z0, self.warm);
        state.solvers = std::mem::take(solvers);
        let mut iterations = Vec::new();
        let mut termination = Termination::IterationLimit;
        for _ in 0..self.settings.max_iterations {
            let rec = match scp.next_iter(&mut state, self.first + iterations.len())? {
                Step::Failed => continue,
                Step::Unsolvable => {
                    termination = Termination::Unsolvable;
                    break;
                }
                Step::Watchdog(rec) => {
                    observer.iteration(&rec);
                    iterations.push(rec);
                    continue;
                }
                Step::Judged(rec) => rec,
            };
            observer.iteration(&rec);
            iterations.push(rec);
            if let Some(reason) = scp.terminate(&state, &rec) {
                termination = reason;
                break;
            }
        }
        let seconds = clock.elapsed().as_secs_f64();
        *solvers = std::mem::take(&mut state.solvers);
        Ok(scp.finish(state, termination, iterations, seconds))
    }
}

/// Solves `p` from `z0` (see [`Executor`]), reporting each iteration to
/// `observe`.
pub fn solve(
    p: &dyn ScpProblem,
    z0: Vec<f64>,
    settings: &ScpSettings,
    observe: impl FnMut(&ScpIteration),
) -> Result<ScpResult> {
    solve_warm(p, z0, None, settings, observe)
}

/// [`solve`] with the multipliers, radius and weight of a neighbouring solve.
pub fn solve_warm(
    p: &dyn ScpProblem,
    z0: Vec<f64>,
    warm: Option<&WarmStart>,
    settings: &ScpSettings,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<ScpResult> {
    Executor::new(settings).warm(warm).run(p, z0, &mut observe)
}

/// The point before a tentative step (the watchdog).
struct Anchor {
    z: Vec<f64>,
    merit: Merit,
    /// Its model's predicted decrease.
    predicted: f64,
    /// The radius had its step been rejected.
    cut: f64,
    /// The multipliers of its subproblem (the curvature a rejection there
    /// would have passed on), and whether the trust region bounded its step
    /// (for the curvature scale's rule on an undo).
    multipliers: Multipliers,
    bounded: bool,
}

/// Multipliers of the terms of a peak cost and of the limited terms, and
/// the scale of their curvature: the next subproblem's Hessian.
#[derive(Debug, Clone)]
pub struct Multipliers {
    pub terms: Vec<f64>,
    pub limited: Vec<f64>,
    /// Scale of the model's Hessian, in `[Curvature::min, 1]` (see
    /// [`Multipliers::adapt_curvature`]).
    pub curvature: f64,
}

impl Default for Multipliers {
    fn default() -> Self {
        Self {
            terms: Vec::new(),
            limited: Vec::new(),
            curvature: 1.0,
        }
    }
}

impl Multipliers {
    /// The model's Hessian is the positive semidefinite part of the terms'
    /// curvature: it misses the attitude's (a holonomy, indefinite) and the
    /// negative curvature it clips, and along the steps it overstated the
    /// merit's curvature tenfold (`rho` near 2 in the tail, where a model
    /// whose minimum lies inside the trust region is `1/kappa` too curved
    /// for `rho = 2 - 1/kappa`: steps that fall short, converging linearly).
    /// After an accepted step inside the trust region with `rho > 1` the
    /// scale is multiplied by `2 - rho` (at least [`Curvature::fall`] per
    /// step, down to [`Curvature::min`]); after a rejected step inside it,
    /// multiplied by [`Curvature::rise`] (at most 1). `rho` is the
    /// iteration's, after any second-order correction (the correction
    /// removes the constraints' curvature, not the cost's). A warm start
    /// begins again at 1.
    fn adapt_curvature(&mut self, rec: &ScpIteration, c: &Curvature) {
        if rec.bounded() {
            return;
        }
        if rec.accepted && rec.rho > 1.0 {
            self.curvature = (self.curvature * (2.0 - rec.rho).max(c.fall)).max(c.min);
        } else if !rec.accepted {
            self.reject_curvature(c);
        }
    }

    /// A step inside the trust region was rejected: the model was too flat.
    fn reject_curvature(&mut self, c: &Curvature) {
        self.curvature = (self.curvature * c.rise).min(1.0);
    }
}

/// What a finished solve hands to a neighbouring problem (continuation):
/// its multipliers (the curvature of the first subproblem), its final
/// trust radius and its penalty weight.
#[derive(Debug, Clone, Default)]
pub struct WarmStart {
    pub multipliers: Multipliers,
    pub radius: f64,
    /// The penalty weight at the end, in the cost's unit (not relative to
    /// the solve's start, which differs between neighbours).
    pub weight: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The robot's subproblem at its analytic start inside the servo's
    /// torque-speed line (which the start breaks), per motor and
    /// Euclidean, at a wide and a narrow trust region: the screened one,
    /// with the rows its solution broke added back, holds fewer rows, has
    /// the whole one's optimal value, and its solution keeps every row of
    /// the whole one.
    #[test]
    fn a_screened_subproblem_has_the_whole_ones_optimum_and_keeps_every_row() {
        use crate::design::free::{FreeProblem, Seed};
        for norm in ["per-motor", "euclidean"] {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/robot-universal.toml");
            let set = [
                "fall.height=6".to_string(),
                "design.objective=time".to_string(),
                format!("limits.norm={norm}"),
            ];
            let cfg = crate::test_support::spec_at(path, &set);
            let nodes = cfg.free.nodes;
            let plan = Seed::Analytic.plan(&cfg).unwrap();
            let z0 = crate::design::collocation::Transcription::new(3, nodes).sample(plan.as_ref());
            let p = FreeProblem::new(&cfg, nodes, &z0);
            let z = p.project(&p.to_scaled(&z0)).unwrap();
            let lin = linearize(&p, &z);
            let scales = p.scales();
            let w = 2.0 * cost_of(&p, &z, &evaluate(&p, &z)).abs();
            let (dim, tn) = (p.term_dim(), p.norm());
            let layout = Layout::of(&p, &lin);
            for (radius, band) in [
                (0.5, f64::INFINITY),
                (0.05, f64::INFINITY),
                (0.5, 1.0),
                (0.05, 1.0),
            ] {
                let solve = |keep: Option<&Screen>| {
                    let (d, ..) = subproblem(&p, &z, &lin, &scales, radius, w, &Vec::new(), keep);
                    let (st, x, obj) =
                        solve_reusing_with(&mut None, &d, ConicSettings::MODEL).unwrap();
                    assert!(st.ok(), "{norm}, radius {radius}: {st:?}");
                    (d.m(), x, obj)
                };
                let (m_all, _, obj_all) = solve(None);
                let mut keep = screen(&lin, &scales, radius, band, dim, tn);
                let (mut m, mut x, mut obj) = solve(Some(&keep));
                loop {
                    let broken = broken_rows(&lin, &keep, &x, &layout, tn, dim);
                    if broken.is_empty() {
                        break;
                    }
                    for (r, bit) in broken {
                        keep[r] |= bit;
                    }
                    (m, x, obj) = solve(Some(&keep));
                }
                // a wide region reaches nearly every row; the band drops a
                // line's far side, but a disc has none
                let what = format!("{norm}, radius {radius}, band {band}");
                eprintln!("{what}: {m} rows of {m_all}");
                assert!(
                    (m as f64) < 0.95 * m_all as f64
                        || (radius > 0.1 && (band.is_infinite() || norm == "euclidean")),
                    "{what}: {m} rows of {m_all}"
                );
                assert!(
                    (obj - obj_all).abs() <= 1e-6 * obj_all.abs().max(1e-2),
                    "{what}: optimum {obj} screened, {obj_all} whole"
                );
                // every row of the whole subproblem at the screened solution
                let mut g = lin.limited.clone();
                for &(r, c, v) in &lin.limited_jac {
                    g[r] += v * x[c];
                }
                let worst = peak_of(&g, dim, tn) - 1.0 - layout.slack(&x);
                assert!(worst <= 1e-6, "{what}: a row broken by {worst}");
            }
        }
    }

    fn record(predicted: f64, radius: f64, bounded: bool) -> ScpIteration {
        ScpIteration {
            iteration: 0,
            merit: 2.0,
            objective: 2.0,
            infeasibility: 0.0,
            radius,
            weight: 1.0,
            predicted,
            actual: predicted,
            rho: 1.0,
            accepted: true,
            tentative: false,
            merit_after: 2.0 - predicted,
            step: radius,
            // at the radius when bounded, inside it when not
            model_step: if bounded { radius } else { 0.5 * radius },
            solve_ms: 0.0,
        }
    }

    #[test]
    fn criticality_scales_by_the_radius_only_when_the_trust_region_bound_the_step() {
        // bounded: the decrease at unit radius is at most predicted / radius
        assert!((record(1e-4, 0.01, true).criticality() - 5e-3).abs() < 1e-15);
        // the model's minimum inside the region: a larger one predicts no more
        assert!((record(1e-4, 0.01, false).criticality() - 5e-5).abs() < 1e-15);
        // radii above 1 never shrink it
        assert_eq!(
            record(1e-4, 8.0, true).criticality(),
            record(1e-4, 8.0, false).criticality()
        );
    }

    /// A two-unknown problem with a linear cost and residuals `r(z)` with
    /// their Jacobian, for the driver's and the correction's tests.
    struct Toy {
        cost: Vec<(usize, f64)>,
        r: fn(&[f64]) -> (Vec<f64>, Triplets),
    }

    impl ScpProblem for Toy {
        fn dim(&self) -> usize {
            2
        }
        fn term_dim(&self) -> usize {
            1
        }
        fn norm(&self) -> TorqueNorm {
            TorqueNorm::Euclidean
        }
        fn cost(&self) -> Cost {
            Cost::Linear(self.cost.clone())
        }
        fn evaluate(&self, z: &[f64]) -> Values {
            Values {
                residual: (self.r)(z).0,
                ..Default::default()
            }
        }
        fn linearize(&self, z: &[f64]) -> Linearization {
            let (residual, residual_jac) = (self.r)(z);
            Linearization {
                residual,
                residual_jac,
                ..Default::default()
            }
        }
        fn add_constraints(&self, _: &mut ConicData, _: &[f64], _: &dyn Fn(usize) -> usize) {}
        fn scales(&self) -> Vec<f64> {
            vec![1.0, 1.0]
        }
    }

    /// A toy with the Lagrangian's curvature at the circle's optimum (the
    /// identity: the multiplier 1/2 times the residual's Hessian `2 I`), so
    /// that its steps are SQP steps inside the trust region, as a design's
    /// are near its optimum.
    struct Curved(Toy);

    impl ScpProblem for Curved {
        fn dim(&self) -> usize {
            self.0.dim()
        }
        fn term_dim(&self) -> usize {
            self.0.term_dim()
        }
        fn norm(&self) -> TorqueNorm {
            self.0.norm()
        }
        fn cost(&self) -> Cost {
            self.0.cost()
        }
        fn evaluate(&self, z: &[f64]) -> Values {
            self.0.evaluate(z)
        }
        fn linearize(&self, z: &[f64]) -> Linearization {
            self.0.linearize(z)
        }
        fn add_constraints(&self, d: &mut ConicData, z: &[f64], var: &dyn Fn(usize) -> usize) {
            self.0.add_constraints(d, z, var)
        }
        fn scales(&self) -> Vec<f64> {
            self.0.scales()
        }
        fn hessian(&self, _: &[f64], _: &[f64], _: &[f64]) -> Triplets {
            vec![(0, 0, 1.0), (1, 1, 1.0)]
        }
    }

    /// Two residuals: `r0 = z0` (well conditioned) and `r1 = g z1` with a
    /// vanishing gain `g` (the tilt at a design: 1e-7), or a unit one.
    fn degenerate(tiny_gain: bool) -> Toy {
        Toy {
            cost: Vec::new(),
            r: if tiny_gain {
                |z| (vec![z[0], 1e-7 * z[1]], vec![(0, 0, 1.0), (1, 1, 1e-7)])
            } else {
                |z| (vec![z[0], z[1]], vec![(0, 0, 1.0), (1, 1, 1.0)])
            },
        }
    }

    /// Least "time" on a circle: maximise `z0` with `z0^2 + z1^2 = 1`
    /// (optimum `z0 = 1`, multiplier 1/2), a linear cost.
    fn circle() -> Toy {
        Toy {
            cost: vec![(0, -1.0)],
            r: |z| {
                (
                    vec![z[0] * z[0] + z[1] * z[1] - 1.0],
                    vec![(0, 0, 2.0 * z[0]), (0, 1, 2.0 * z[1])],
                )
            },
        }
    }

    #[test]
    fn a_penalty_below_the_multiplier_is_raised_when_a_linear_costs_violation_stagnates() {
        // weight 0.1 x |cost| = 0.06 < 1/2: the merit -z0 + w |z0^2 + z1^2 - 1|
        // is least at z0 = 1 / (2 w), far outside the circle
        let solve_with = |stagnation| {
            let settings = ScpSettings {
                penalty: Penalty {
                    weight: 0.1,
                    stagnation,
                    ..Default::default()
                },
                ..Default::default()
            };
            solve(&circle(), vec![0.6, 0.8], &settings, |_| {}).unwrap()
        };
        let (with, without) = (solve_with(5), solve_with(0));
        for r in [&with, &without] {
            assert_eq!(r.status, ScpStatus::Converged);
            assert!((r.z[0] - 1.0).abs() < 1e-5, "{:?}", r.z);
        }
        assert!(
            with.iterations.len() < without.iterations.len(),
            "{} vs {} iterations",
            with.iterations.len(),
            without.iterations.len()
        );
    }

    #[test]
    fn a_linear_costs_accepted_steps_are_corrected_back_onto_the_constraints() {
        // each step along the circle leaves a violation of about its square;
        // corrected, the iterates stay on it and converge in fewer iterations
        let solve_with = |accepted_steps| {
            let settings = ScpSettings {
                correction: Correction {
                    accepted_steps,
                    ..Default::default()
                },
                ..Default::default()
            };
            let mut left = Vec::new();
            let r = solve(&Curved(circle()), vec![0.6, 0.8], &settings, |it| {
                left.push(it.infeasibility)
            })
            .unwrap();
            (r, left)
        };
        let ((with, with_left), (without, without_left)) = (solve_with(true), solve_with(false));
        for r in [&with, &without] {
            assert_eq!(r.status, ScpStatus::Converged);
            assert!((r.z[0] - 1.0).abs() < 1e-5, "{:?}", r.z);
        }
        // the step from the second iterate leaves a hundredth of the violation
        assert!(
            with_left[2] < 1e-2 * without_left[2],
            "{with_left:?} vs {without_left:?}"
        );
        assert!(
            with.iterations.len() < without.iterations.len(),
            "{} vs {} iterations",
            with.iterations.len(),
            without.iterations.len()
        );
    }

    #[test]
    fn a_warm_start_keeps_the_neighbours_penalty_weight() {
        // the cold solve raises 0.1 x 0.6 past the multiplier 1/2; re-solved
        // from its optimum at the default weight, the merit would first
        // walk off the circle towards z0 = 1 / (2 w) = 5
        let settings = ScpSettings {
            penalty: Penalty {
                weight: 0.1,
                ..Default::default()
            },
            ..Default::default()
        };
        let first = solve(&circle(), vec![0.6, 0.8], &settings, |_| {}).unwrap();
        assert!(first.warm.weight > 0.5, "{}", first.warm.weight);
        let again = |warm: Option<&WarmStart>| {
            let mut worst = 0.0f64;
            let r = solve_warm(&circle(), first.z.clone(), warm, &settings, |it| {
                worst = worst.max(it.infeasibility)
            })
            .unwrap();
            (r, worst)
        };
        let (warm, warm_worst) = again(Some(&first.warm));
        let (cold, cold_worst) = again(None);
        for r in [&warm, &cold] {
            assert_eq!(r.status, ScpStatus::Converged);
            assert!((r.z[0] - 1.0).abs() < 1e-5, "{:?}", r.z);
        }
        assert!(
            warm_worst < 1e-6 && cold_worst > 0.1,
            "{warm_worst} vs {cold_worst}"
        );
        assert!(
            warm.iterations.len() < cold.iterations.len(),
            "{} vs {} iterations",
            warm.iterations.len(),
            cold.iterations.len()
        );
    }

    #[test]
    fn a_feasible_points_criticality_leaves_out_removing_its_tolerated_violation() {
        // merit 2 = cost 1.5 + penalty 0.5; the model predicts 0.6, of
        // which up to 0.5 is the penalty's removal
        let rec = ScpIteration {
            objective: 1.5,
            predicted: 0.6,
            ..record(0.6, 8.0, false)
        };
        assert!((rec.criticality() - 0.3).abs() < 1e-15);
        // within the tolerance: only the rest counts
        let feasible = ScpIteration {
            infeasibility: 1e-9,
            ..rec
        };
        assert!((feasible.criticality_within(1e-6) - 0.05).abs() < 1e-15);
        // a violation above it must still be removed: all of it counts
        let infeasible = ScpIteration {
            infeasibility: 1e-3,
            ..rec
        };
        assert_eq!(infeasible.criticality_within(1e-6), rec.criticality());
        // a prediction that is all penalty: nothing left
        let all_penalty = ScpIteration {
            predicted: 0.4,
            ..feasible
        };
        assert_eq!(all_penalty.criticality_within(1e-6), 0.0);
    }

    #[test]
    fn a_trial_point_that_cannot_be_evaluated_cuts_the_radius() {
        // minimise z0 from 1 where the residual is not a number below 0.9:
        // every step past it must shrink the trust region (a NaN rho
        // neither cut nor grew it: the same step again)
        let cliff = Toy {
            cost: vec![(0, 1.0)],
            r: |z| {
                let r = if z[0] < 0.9 { f64::NAN } else { 0.0 };
                (vec![r], vec![(0, 0, 0.0)])
            },
        };
        let r = solve(&cliff, vec![1.0, 0.0], &ScpSettings::default(), |_| {}).unwrap();
        let its = &r.iterations;
        assert!(
            its.iter()
                .any(|it| !it.merit_after.is_nan() && !it.accepted)
        );
        for pair in its.windows(2) {
            if !pair[0].accepted {
                assert!(pair[0].rho < 0.1, "{:?}", pair[0]);
                assert!(pair[1].radius < pair[0].radius, "{pair:?}");
            }
        }
        assert!(r.z[0] >= 0.9, "{:?}", r.z);
    }

    #[test]
    fn the_correction_removes_well_conditioned_residuals_and_leaves_degenerate_ones() {
        // the model's residual misses by 0.1 along r0 and by 1e-6 along r1:
        // a hard correction would move z1 by 1e-6 / gain = 10 (scaled)
        let p = degenerate(true);
        let z = [0.0, 0.0];
        let lin = p.linearize(&z);
        let weight = Correction::default().slack_weight;
        let d = correction(&p, &z, &lin, &[0.1, 1e-6], &p.scales(), None, weight);
        let (st, x, _) = ConicSolver::with_settings(&d, ConicSettings::MODEL)
            .unwrap()
            .solve();
        assert!(st.ok(), "{st:?}");
        assert!((x[0] - 0.1).abs() < 1e-6, "r0 removed: dc0 = {}", x[0]);
        assert!(x[1].abs() < 1e-3, "r1 left alone: dc1 = {}", x[1]);
        // with a gain the weight can afford, r1 is removed too
        let p = degenerate(false);
        let d = correction(
            &p,
            &z,
            &p.linearize(&z),
            &[0.1, 0.2],
            &p.scales(),
            None,
            weight,
        );
        let (_, x, _) = ConicSolver::with_settings(&d, ConicSettings::MODEL)
            .unwrap()
            .solve();
        assert!(
            (x[0] - 0.1).abs() < 1e-6 && (x[1] - 0.2).abs() < 1e-6,
            "{x:?}"
        );
    }

    /// Peak-cost terms and limited terms (two of dimension 2 each) and one
    /// residual, in either norm, the limits on rows of their own or on the
    /// epigraph: every kind of row whose `b` holds a value.
    struct Peaked {
        norm: TorqueNorm,
        on_epigraph: bool,
        limit: f64,
    }

    impl ScpProblem for Peaked {
        fn dim(&self) -> usize {
            2
        }
        fn term_dim(&self) -> usize {
            2
        }
        fn norm(&self) -> TorqueNorm {
            self.norm
        }
        fn evaluate(&self, z: &[f64]) -> Values {
            let l = self.linearize(z);
            Values {
                terms: l.terms,
                limited: l.limited,
                residual: l.residual,
            }
        }
        fn linearize(&self, z: &[f64]) -> Linearization {
            let (a, b) = (z[0], z[1]);
            Linearization {
                terms: vec![a * a, b, a * b, b * b],
                terms_jac: vec![
                    (0, 0, 2.0 * a),
                    (1, 1, 1.0),
                    (2, 0, b),
                    (2, 1, a),
                    (3, 1, 2.0 * b),
                ],
                limited: vec![a, b * b, a + b, a * b],
                limited_jac: vec![
                    (0, 0, 1.0),
                    (1, 1, 2.0 * b),
                    (2, 0, 1.0),
                    (2, 1, 1.0),
                    (3, 0, b),
                    (3, 1, a),
                ],
                residual: vec![a + b - 1.0],
                residual_jac: vec![(0, 0, 1.0), (0, 1, 1.0)],
            }
        }
        fn add_constraints(&self, _: &mut ConicData, _: &[f64], _: &dyn Fn(usize) -> usize) {}
        fn scales(&self) -> Vec<f64> {
            vec![1.0, 1.0]
        }
        fn limit(&self) -> Option<f64> {
            Some(self.limit)
        }
        fn limited_are_terms(&self) -> bool {
            self.on_epigraph
        }
    }

    #[test]
    fn a_limit_far_above_the_cost_counts_in_the_start_weight_up_to_its_cap() {
        let s = ScpSettings::default();
        let z0 = vec![0.3, 0.9];
        let problem = |limit: f64| Peaked {
            norm: TorqueNorm::PerMotor,
            on_epigraph: false,
            limit,
        };
        let weight = |limit: f64| Scp::new(&problem(limit), &s).init(z0.clone(), None).weight;
        let (_, cost0, _) = merit(&problem(2.0), &z0, 0.0);
        assert!(cost0 > 0.5 && cost0 < 2.0, "{cost0}");
        // a limit near the cost sets the scale
        assert_eq!(weight(2.0), s.penalty.weight * 2.0);
        // one far above it counts up to max_limit_scale times the cost
        let capped = s.penalty.weight * s.penalty.max_limit_scale * cost0;
        assert!(capped < s.penalty.weight * 1e9);
        assert_eq!(weight(1e9), capped);
        assert_eq!(weight(1e12), capped);
    }

    #[test]
    fn the_right_hand_side_change_is_what_rebuilding_the_subproblem_gives() {
        let z = [0.3, 0.9];
        let shift = Values {
            terms: vec![0.01, -0.02, 0.03, 0.005],
            limited: vec![-0.04, 0.015, 0.02, -0.01],
            residual: vec![0.07],
        };
        for norm in [TorqueNorm::Euclidean, TorqueNorm::PerMotor] {
            for on_epigraph in [false, true] {
                let p = Peaked {
                    norm,
                    on_epigraph,
                    limit: 2.0,
                };
                let lin = p.linearize(&z);
                let plus = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a + b).collect();
                let moved = Linearization {
                    terms: plus(&lin.terms, &shift.terms),
                    limited: plus(&lin.limited, &shift.limited),
                    residual: plus(&lin.residual, &shift.residual),
                    ..lin.clone()
                };
                let build = |l: &Linearization| {
                    subproblem(&p, &z, l, &p.scales(), 0.5, 3.0, &Vec::new(), None)
                };
                let (data, _, term_rows, limit_rows) = build(&lin);
                assert_eq!(limit_rows.is_empty(), on_epigraph);
                let rebuilt: Vec<f64> = build(&moved)
                    .0
                    .b
                    .iter()
                    .zip(&data.b)
                    .map(|(a, b)| a - b)
                    .collect();
                let model = Model {
                    z: &z,
                    lin: &lin,
                    data: &data,
                    term_rows: &term_rows,
                    limit_rows: &limit_rows,
                    w: 3.0,
                };
                let db = model.rhs_change(&shift);
                assert_eq!(db.len(), rebuilt.len());
                assert!(
                    rebuilt.iter().filter(|v| v.abs() > 1e-3).count() >= 5,
                    "{rebuilt:?}"
                );
                for (i, (a, b)) in db.iter().zip(&rebuilt).enumerate() {
                    assert!(
                        (a - b).abs() < 1e-15,
                        "{norm:?} epigraph {on_epigraph}, row {i}: {a} vs {b}"
                    );
                }
            }
        }
    }

    /// A real-time iteration leaves the conic correction out: a step off
    /// the circle, whose sensitivity correction is off too (no rounds),
    /// sets up the conic correction's solver only when it is on.
    #[test]
    fn the_conic_correction_runs_only_when_it_is_on() {
        let run = |conic: bool| {
            let settings = ScpSettings {
                max_iterations: 1,
                correction: Correction {
                    rounds: 0,
                    conic_enabled: conic,
                    ..Default::default()
                },
                ..Default::default()
            };
            let mut solvers = Solvers::default();
            let r = Executor::new(&settings)
                .run_reusing(
                    &circle(),
                    vec![0.6, 0.8],
                    &mut |_: &ScpIteration| {},
                    &mut solvers,
                )
                .unwrap();
            let first = r.iterations[0];
            (solvers.correction.is_some(), first)
        };
        let (with, on) = run(true);
        let (without, off) = run(false);
        assert!(
            with && !without,
            "conic solver set up: on {with}, off {without}"
        );
        // the same model step, corrected only when the conic correction is on
        assert_eq!(on.predicted, off.predicted);
        assert!(
            on.actual > off.actual,
            "merit decrease {} with the correction, {} without",
            on.actual,
            off.actual
        );
    }

    #[test]
    fn the_sensitivity_correction_puts_a_step_along_the_circle_back_on_it() {
        // from (0.6, 0.8) the linearised circle is a tangent line: the step
        // leaves the circle by |d|^2; the shifted model pulls it back
        let p = circle();
        let z = [0.6, 0.8];
        let lin = linearize(&p, &z);
        let scales = p.scales();
        let (w, radius) = (2.0, 0.3);
        let hessian = Triplets::new();
        let (data, _, term_rows, limit_rows) =
            subproblem(&p, &z, &lin, &scales, radius, w, &hessian, None);
        let mut solver = ConicSolver::with_settings(&data, ConicSettings::MODEL).unwrap();
        let (st, x, _) = solver.solve();
        assert!(st.ok(), "{st:?}");
        let trial: Vec<f64> = z.iter().zip(&x).map(|(a, b)| a + b).collect();
        let at = evaluate(&p, &trial);
        assert!(
            at.residual[0] > 0.05,
            "the step leaves the circle: {:?}",
            at.residual
        );
        let model = Model {
            z: &z,
            lin: &lin,
            data: &data,
            term_rows: &term_rows,
            limit_rows: &limit_rows,
            w,
        };
        let (corrected, m) =
            sensitivity_correction(&p, &model, &x[..2], &at, &mut solver, 3).unwrap();
        let r = evaluate(&p, &corrected).residual[0];
        assert!(
            r.abs() < 0.1 * at.residual[0],
            "back on the circle: {} -> {r}",
            at.residual[0]
        );
        // and the cost's progress is kept: z0 still moved toward 1
        assert!(corrected[0] > 0.75, "{corrected:?}");
        assert!(m.0 < merit(&p, &trial, w).0);
    }

    #[test]
    fn the_curvature_scale_follows_rho_inside_the_trust_region() {
        let c = Curvature::default();
        let min_curvature = c.min;
        let mut m = Multipliers::default();
        let mut rec = record(1e-3, 1.0, false);
        // rho 1.5: the model was twice as curved as the merit
        rec.rho = 1.5;
        m.adapt_curvature(&rec, &c);
        assert!((m.curvature - 0.5).abs() < 1e-15);
        // at most a quarter per step, never below the least scale
        rec.rho = 1.95;
        m.adapt_curvature(&rec, &c);
        assert!((m.curvature - 0.125).abs() < 1e-15);
        m.adapt_curvature(&rec, &c);
        assert_eq!(m.curvature, min_curvature);
        // a step the trust region bounded says nothing about the curvature
        let bounded = ScpIteration {
            rho: 1.9,
            ..record(1e-3, 1.0, true)
        };
        m.adapt_curvature(&bounded, &c);
        assert_eq!(m.curvature, min_curvature);
        // a rejected step inside the region: the model was too flat
        rec.accepted = false;
        rec.rho = 0.0;
        m.adapt_curvature(&rec, &c);
        assert!((m.curvature - 2.0 * min_curvature).abs() < 1e-15);
        for _ in 0..10 {
            m.adapt_curvature(&rec, &c);
        }
        assert_eq!(m.curvature, 1.0);
    }
    #[test]
    fn the_default_settings_are_valid_and_a_bad_one_is_named() {
        ScpSettings::default().validate().unwrap();
        let bad = [
            ScpSettings {
                tolerance: 0.0,
                ..Default::default()
            },
            ScpSettings {
                trust: TrustRegion {
                    grow_above: 0.05,
                    ..Default::default()
                },
                ..Default::default()
            },
            ScpSettings {
                penalty: Penalty {
                    infeasible: 10.0,
                    ..Default::default()
                },
                ..Default::default()
            },
            ScpSettings {
                curvature: Curvature {
                    min: 0.0,
                    ..Default::default()
                },
                ..Default::default()
            },
        ];
        let keys = [
            "scp.tolerance",
            "scp.trust.grow_above",
            "scp.penalty.infeasible",
            "scp.curvature.min",
        ];
        for (settings, key) in bad.iter().zip(keys) {
            match settings.validate() {
                Err(Error::Invalid { key: k, .. }) => assert_eq!(k, key),
                other => panic!("{key}: {other:?}"),
            }
        }
        // a solve checks them first
        let r = solve(&circle(), vec![0.6, 0.8], &bad[0], |_| {});
        assert!(matches!(r, Err(Error::Invalid { .. })));
    }

    #[test]
    fn the_layout_names_each_block_of_the_subproblems_variables() {
        let v = Layout {
            n: 3,
            m: 2,
            limited: true,
        };
        assert_eq!(v.len(), 3 + 1 + 2 * 2 + 1);
        assert_eq!(v.dz(), 0..3);
        assert_eq!(v.t(), 3);
        assert_eq!((v.nu_plus(0), v.nu_plus(1)), (4, 5));
        assert_eq!((v.nu_minus(0), v.nu_minus(1)), (6, 7));
        assert_eq!(v.virtual_controls(), 4..8);
        assert_eq!(v.sigma(), 8);
        let x: Vec<f64> = (0..v.len()).map(|i| (i * i) as f64).collect();
        assert_eq!(v.step(&x), &[0.0, 1.0, 4.0]);
        assert_eq!(v.epigraph(&x), 9.0);
        assert_eq!(v.virtual_control(&x, 1), 25.0 - 49.0);
        assert_eq!(v.slack(&x), 64.0);
        let free = Layout {
            limited: false,
            ..v
        };
        assert_eq!(free.len(), 8);
        assert_eq!(free.slack(&x[..8]), 0.0);
        // the subproblem is built on it: its variables and the step's bounds
        let p = Peaked {
            norm: TorqueNorm::Euclidean,
            on_epigraph: false,
            limit: 2.0,
        };
        let z = [0.3, 0.9];
        let lin = p.linearize(&z);
        let v = Layout::of(&p, &lin);
        assert_eq!((v.n, v.m, v.limited), (2, 1, true));
        let (data, ..) = subproblem(&p, &z, &lin, &p.scales(), 0.5, 3.0, &Vec::new(), None);
        assert_eq!(data.n, v.len());
        assert_eq!(data.q[v.nu_plus(0)], 3.0);
        assert_eq!(data.q[v.nu_minus(0)], 3.0);
        assert_eq!(data.q[v.sigma()], 3.0);
        assert_eq!(data.q[v.t()], 1.0);
    }
    /// The state on the circle at its optimum `(1, 0)`: feasible, merit
    /// -1 (the cost), weight 2 (the scale is the cost's size, 1).
    fn at_optimum(scp: &Scp) -> State {
        let state = scp.init(vec![1.0, 0.0], None);
        assert_eq!(state.here, (-1.0, -1.0, 0.0));
        assert_eq!((state.scale, state.weight), (1.0, 2.0));
        state
    }

    #[test]
    fn the_criticality_rule_stops_a_feasible_critical_point_only() {
        let (p, s) = (circle(), ScpSettings::default());
        let scp = Scp::new(&p, &s);
        let state = at_optimum(&scp);
        // criticality 1e-5 / 2 below the tolerance 1e-4
        let critical = record(1e-5, 1.0, false);
        assert_eq!(
            converged_by_criticality(&scp, &state, &critical),
            Some(Termination::Criticality)
        );
        // the model still predicts a decrease of 1 % of the merit
        assert_eq!(
            converged_by_criticality(&scp, &state, &record(2e-2, 1.0, false)),
            None
        );
        // critical, but the violation is above `feasibility`
        let infeasible = State {
            here: (-1.0, -1.0, 1e-3),
            ..at_optimum(&scp)
        };
        assert_eq!(converged_by_criticality(&scp, &infeasible, &critical), None);
    }

    #[test]
    fn the_progress_rule_stops_a_feasible_merit_that_stopped_falling() {
        let (p, s) = (circle(), ScpSettings::default());
        let scp = Scp::new(&p, &s);
        let flat = State {
            merits: vec![-1.0; s.window + 1],
            ..at_optimum(&scp)
        };
        assert_eq!(
            converged_by_progress(&scp, &flat),
            Some(Termination::Progress)
        );
        // a window too short to judge
        let short = State {
            merits: vec![-1.0; s.window],
            ..at_optimum(&scp)
        };
        assert_eq!(converged_by_progress(&scp, &short), None);
        // the merit fell by 10 % over the window: 1e-2 per iteration
        let mut falling = State {
            merits: vec![-1.0; s.window + 1],
            ..at_optimum(&scp)
        };
        falling.merits[0] = -0.9;
        assert_eq!(converged_by_progress(&scp, &falling), None);
        // flat but infeasible
        let infeasible = State {
            here: (-1.0, -1.0, 1e-3),
            ..flat
        };
        assert_eq!(converged_by_progress(&scp, &infeasible), None);
    }

    #[test]
    fn the_infeasibility_rule_stops_when_a_raise_would_pass_the_bound() {
        let (p, s) = (circle(), ScpSettings::default());
        let scp = Scp::new(&p, &s);
        // the bound: 1e6 times the start weight 2 (scale 1)
        let near = State {
            weight: 2e5,
            raise: true,
            ..at_optimum(&scp)
        };
        assert_eq!(infeasible(&scp, &near), None);
        let past = State {
            weight: 2e5 + 1.0,
            raise: true,
            ..at_optimum(&scp)
        };
        assert_eq!(infeasible(&scp, &past), Some(Termination::Infeasible));
        // no raise pending: the weight stays
        let kept = State {
            raise: false,
            ..past
        };
        assert_eq!(infeasible(&scp, &kept), None);
    }

    #[test]
    fn the_stall_rule_stops_a_collapsed_trust_region() {
        let (p, s) = (circle(), ScpSettings::default());
        let scp = Scp::new(&p, &s);
        let collapsed = State {
            radius: 0.5 * s.trust.min_radius,
            ..at_optimum(&scp)
        };
        assert_eq!(stalled(&scp, &collapsed), Some(Termination::Stalled));
        assert_eq!(stalled(&scp, &at_optimum(&scp)), None);
        // the rules in order: converged before stalled
        assert_eq!(
            scp.terminate(&collapsed, &record(1e-5, 1.0, false)),
            Some(Termination::Criticality)
        );
        assert_eq!(
            scp.terminate(&collapsed, &record(2e-2, 1.0, false)),
            Some(Termination::Stalled)
        );
        assert_eq!(
            scp.terminate(&at_optimum(&scp), &record(2e-2, 1.0, false)),
            None
        );
    }

    #[test]
    fn a_stagnating_violation_raises_the_weight_and_a_nearly_feasible_one_does_not() {
        let (p, s) = (circle(), ScpSettings::default());
        let scp = Scp::new(&p, &s);
        let k = s.penalty.stagnation;
        // a violation of 1e-3 (above 100x feasibility) that did not fall
        let stuck = State {
            here: (-1.0, -1.0, 1e-3),
            history: vec![(1e-3, -1.0); k + 1],
            ..at_optimum(&scp)
        };
        assert!(scp.stagnates(&stuck));
        // it also keeps the criticality rule from declaring a critical point
        let critical = ScpIteration {
            infeasibility: 1e-3,
            ..record(1e-5, 1.0, false)
        };
        assert!(!scp.critical(&stuck, &critical));
        let mut raised = stuck;
        scp.decide_weight(&mut raised, &record(2e-2, 1.0, false));
        assert!(raised.raise);
        scp.raise_weight(&mut raised);
        assert_eq!(raised.weight, 2.0 * s.penalty.growth);
        assert!(!raised.raise && raised.history.is_empty());
        // a violation that fell by half in the window does not stagnate
        let mut falling = State {
            here: (-1.0, -1.0, 1e-3),
            history: vec![(2e-3, -1.0); k + 1],
            ..at_optimum(&scp)
        };
        assert!(!scp.stagnates(&falling));
        scp.decide_weight(&mut falling, &record(2e-2, 1.0, false));
        assert!(!falling.raise);
        // critical at a nearly feasible violation: the weight is kept up to
        // `patience` times in a row, then raised
        let mut nearly = State {
            here: (-1.0, -1.0, 1e-5),
            ..at_optimum(&scp)
        };
        for _ in 0..s.penalty.patience {
            scp.decide_weight(&mut nearly, &critical);
            assert!(!nearly.raise);
        }
        scp.decide_weight(&mut nearly, &critical);
        assert!(nearly.raise);
    }

    /// A subproblem no solver can take (a NaN in its rows), however small
    /// the trust region: the solve ends at its start, stalled, after the
    /// failures the settings allow, instead of throwing its point away.
    #[test]
    fn a_subproblem_that_always_fails_ends_the_solve_at_its_point() {
        let broken = Toy {
            cost: vec![(0, 1.0)],
            r: |z| (vec![z[0] - 1.0], vec![(0, 0, f64::NAN)]),
        };
        let res = solve(&broken, vec![0.3, -0.2], &ScpSettings::default(), |_| {}).unwrap();
        assert_eq!(res.termination, Termination::Unsolvable);
        assert_eq!(res.status, ScpStatus::Stalled);
        assert_eq!(res.z, vec![0.3, -0.2]);
        assert!(res.iterations.is_empty());
        assert!(
            (res.infeasibility - 0.7).abs() < 1e-12,
            "{}",
            res.infeasibility
        );
    }

    #[test]
    fn each_termination_names_its_status_and_rule() {
        let all = [
            Termination::Criticality,
            Termination::Progress,
            Termination::Infeasible,
            Termination::Stalled,
            Termination::Unsolvable,
            Termination::IterationLimit,
        ];
        let status = all.map(|t| t.status());
        assert_eq!(
            status,
            [
                ScpStatus::Converged,
                ScpStatus::Converged,
                ScpStatus::Infeasible,
                ScpStatus::Stalled,
                ScpStatus::Stalled,
                ScpStatus::IterationLimit
            ]
        );
        assert_eq!(
            all.map(|t| t.rule())[..2],
            [StopRule::Criticality, StopRule::Progress]
        );
        assert!(all[2..].iter().all(|t| t.rule() == StopRule::None));
        let texts: std::collections::BTreeSet<_> = all.iter().map(|t| t.to_string()).collect();
        assert_eq!(texts.len(), all.len());
        // a solve reports its reason
        let r = solve(&circle(), vec![0.6, 0.8], &ScpSettings::default(), |_| {}).unwrap();
        assert_eq!(r.termination.status(), r.status);
        assert_eq!(r.termination.rule(), r.certificate.rule);
    }

    #[test]
    fn the_executor_numbers_iterations_on_from_its_first() {
        let settings = ScpSettings::default();
        let mut seen = Vec::new();
        let r = Executor::new(&settings)
            .numbered_from(7)
            .run(&circle(), vec![0.6, 0.8], &mut |it: &ScpIteration| {
                seen.push(it.iteration)
            })
            .unwrap();
        let recorded: Vec<usize> = r.iterations.iter().map(|it| it.iteration).collect();
        assert_eq!(seen, recorded);
        assert_eq!(recorded, (7..7 + recorded.len()).collect::<Vec<_>>());
        // the same solve from 0 (solve's numbering) otherwise
        let plain = solve(&circle(), vec![0.6, 0.8], &settings, |_| {}).unwrap();
        assert_eq!(plain.iterations.len(), recorded.len());
        assert_eq!(plain.z, r.z);
        assert!(r.seconds >= 0.0);
    }
}
