//! The certified least-peak-torque fold / twist / unfold design (docs/model.md F5).
//!
//! For a bend `b` each phase is a rest-to-rest traversal of a fixed path, so
//! its least peak in time `T_i` is `p_i(b) / T_i^2` (F3) with `p_i` from the
//! phase SOCP ([`crate::design::timing`]). The best split is `T_i ~ sqrt(p_i)` and the
//! phased peak is `(sum_i sqrt(p_i))^2 / T^2`. The bend is then searched by a
//! coarse scan (which includes the one-turn bend of F6 and the config's bend)
//! and Brent refinement inside the best bracket: derivative-free, so it stays
//! correct where the objective has kinks (a phase taking over the peak; Brent
//! falls back to golden steps there). In a sweep a neighbour's bend predicts
//! this point's ([`BendHint`]), and a local bracket replaces the scan.

use crate::design::analytic::plan as cosine_plan;
pub use crate::design::bend_search::{BendEvaluation, BendHint, bend_range, bend_scan};
use crate::design::bend_search::{Scored, bracket_then_brent, scan_then_brent};
use crate::design::conic::SolveStatus;
use crate::design::objective::Objective;
use crate::design::path::{Path, PhasedPlan, Timing};
use crate::design::spec::DesignSpec;
use crate::design::timing::{PhaseTiming, TimingProblem};
pub use crate::design::twist::twist_for;
use crate::design::twist::{TWIST_TOL, twist_to};
use crate::error::{Error, Result};
use crate::model::{Cat, Joint};
use crate::verify::analyze::peak_along;
use serde::Serialize;
use std::time::Instant;

/// A phased design at one bend.
#[derive(Debug, Clone)]
pub struct BendDesign {
    pub bend: f64,
    /// Rotation of the bend direction during the twist, rad.
    pub twist: f64,
    pub phases: [PhaseTiming; 3],
}

impl BendDesign {
    /// `(sum sqrt(p_i))^2`: the peak if the whole manoeuvre took 1 s.
    pub fn unit_peak(&self) -> f64 {
        self.phases
            .iter()
            .map(|p| p.unit_peak.sqrt())
            .sum::<f64>()
            .powi(2)
    }

    /// Optimal split of `total` seconds (`T_i ~ sqrt(p_i)`).
    pub fn durations(&self, total: f64) -> [f64; 3] {
        let r = self.phases.each_ref().map(|p| p.unit_peak.sqrt());
        let s: f64 = r.iter().sum();
        r.map(|x| total * x / s)
    }

    /// Least peak with a fixed split of `total`: `max_i p_i / T_i^2`.
    pub fn peak_with(&self, durations: [f64; 3]) -> f64 {
        (0..3)
            .map(|i| self.phases[i].unit_peak / durations[i].powi(2))
            .fold(0.0, f64::max)
    }

    pub fn plan(&self, durations: [f64; 3]) -> PhasedPlan {
        PhasedPlan {
            paths: Path::phased(self.bend, self.twist),
            timings: self
                .phases
                .each_ref()
                .map(|p| Timing::Grid(p.timing.clone())),
            durations,
        }
    }
}

/// The same for the free-form design's phased seed ([`seed_plan`]): the
/// free-form design corrects the attitude itself, so the seed's twist
/// (`universal` joint, root-found at every bend the search tries) need not
/// be found as tightly, which makes the seed cheaper (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them"). A
/// config with a motor envelope is seeded by the envelope design, which
/// keeps 1e-11.
const SEED_TWIST_TOL: f64 = 1e-8;

/// Designs the phases at one bend.
///
/// For the `no-twist` joint the unfold is the fold run backwards and rotated
/// about the spine: the model is axisymmetric (`M(R q) = R M(q) R'`, which
/// holds for unequal halves too, each being a cylinder about its own axis)
/// and the torque is invariant under time reversal, so the unfold reuses the
/// fold's timing reversed (the discrete SOCP has the same symmetry, tested).
/// General halves (`[body]`) break it: their unfold is solved on its own path.
pub fn design_at(cat: &Cat, problem: &mut TimingProblem, bend: f64) -> Result<BendDesign> {
    design_to(cat, problem, bend, TWIST_TOL)
}

/// [`design_at`] with the twist to the flip error `twist_tol` (rad).
fn design_to(
    cat: &Cat,
    problem: &mut TimingProblem,
    bend: f64,
    twist_tol: f64,
) -> Result<BendDesign> {
    // the fold does not depend on the twist: it is solved while the twist
    // is root-found
    let [fold_path, ..] = Path::phased(bend, 0.0);
    let mut twist = 0.0;
    let solved = problem.solve_alongside(cat, &fold_path, || {
        twist = twist_to(cat, bend, twist_tol)?;
        let [_, twist_path, unfold_path] = Path::phased(bend, twist);
        Ok(match cat.joint {
            Joint::NoTwist if cat.is_axisymmetric() => vec![twist_path],
            // general halves break the symmetry: the unfold is a program of its own
            _ => vec![twist_path, unfold_path],
        })
    })?;
    let mut solved = solved.into_iter();
    let (fold, twist_phase) = (solved.next().unwrap(), solved.next().unwrap());
    let unfold = solved.next().unwrap_or_else(|| PhaseTiming {
        timing: fold.timing.reversed(),
        ..fold.clone()
    });
    Ok(BendDesign {
        bend,
        twist,
        phases: [fold, twist_phase, unfold],
    })
}

/// Everything the phased optimiser reports.
#[derive(Debug, Clone, Serialize)]
pub struct PhasedResult {
    pub mode: &'static str,
    pub status: SolveStatus,
    pub objective: Objective,
    /// The objective's value for the written schedule, in [`Objective::unit`]
    /// (peak torque N m, manoeuvre time s, or `integral |tau|^2 dt` N^2 m^2 s).
    pub objective_value: f64,
    /// Manoeuvre time of the schedule, s.
    pub manoeuvre_time_s: f64,
    /// Peak joint torque of the written schedule (inverse dynamics, sampled
    /// densely), N m: what the motors must give.
    pub peak_torque_nm: f64,
    /// The SOCPs' certified bound on the grid and midpoints, N m; it differs from
    /// `peak_torque_nm` by the grid's second-order error (the unit-time peak
    /// program only: absent inside a motor envelope).
    pub socp_peak_torque_nm: Option<f64>,
    /// Peak if the manoeuvre took 1 s (F7: `T_min = sqrt(P / tau_max)`), N m s^2.
    pub unit_peak_nm_s2: f64,
    pub bend_deg: f64,
    pub theta_deg: f64,
    pub twist_rad: f64,
    pub phase_durations_s: [f64; 3],
    /// Each phase's peak if it took 1 s (unit-time program only).
    pub phase_unit_peaks_nm_s2: Option<[f64; 3]>,
    /// The seed's cosine schedule at the same bend and the config's split, N m.
    pub analytic_peak_same_bend_nm: f64,
    /// Least peak at the same bend with the config's split, N m
    /// (unit-time program only).
    pub optimum_same_split_nm: Option<f64>,
    /// `analytic_peak_same_bend_nm / peak_torque_nm`.
    pub improvement_factor: f64,
    pub nodes: usize,
    pub evaluations: Vec<BendEvaluation>,
    pub solve_time_s: f64,
    #[serde(skip)]
    pub plan: PhasedPlan,
    #[serde(skip)]
    pub design: Option<BendDesign>,
}

impl Scored for BendDesign {
    fn score(&self) -> f64 {
        self.unit_peak()
    }
}

/// Bend search: scan (with the one-turn and the config's bend), then Brent
/// refinement in the best bracket; with a `hint`, a bracket around it
/// instead of the scan (the scan when no bend of the bracket is possible,
/// one fails, or the one-turn or the config's bend is better).
pub fn search_bend(
    spec: &DesignSpec,
    problem: &mut TimingProblem,
    hint: Option<BendHint>,
    observe: impl FnMut(&BendEvaluation),
) -> Result<(BendDesign, Vec<BendEvaluation>)> {
    let tol = spec.phased.bend_tol_deg.to_radians();
    let (found, evals) = search_bend_to(spec, problem, hint, tol, TWIST_TOL, observe)?;
    Ok((certified(&spec.cat, problem, found), evals))
}

/// [`search_bend`] to the bend tolerance `tol` (rad), with every twist to
/// the flip error `twist_tol` (rad) and the winner at the search's
/// accuracy (not certified).
fn search_bend_to(
    spec: &DesignSpec,
    problem: &TimingProblem,
    hint: Option<BendHint>,
    tol: f64,
    twist_tol: f64,
    mut observe: impl FnMut(&BendEvaluation),
) -> Result<(BendDesign, Vec<BendEvaluation>)> {
    let cat = spec.cat;
    let t = spec.available_time();
    let (lo, hi) = bend_range(spec)?;
    let mut evals = Vec::new();
    let mut search = problem.for_search();
    let mut eval = |b: f64, evals: &mut Vec<BendEvaluation>| -> Result<BendDesign> {
        let d = design_to(&cat, &mut search, b, twist_tol)?;
        let e = BendEvaluation {
            bend_deg: b.to_degrees(),
            value: d.unit_peak() / (t * t),
            unit_peak: Some(d.unit_peak()),
            peak_nm: Some(d.unit_peak() / (t * t)),
        };
        observe(&e);
        evals.push(e);
        Ok(d)
    };
    let xs = bend_scan(spec, lo, hi);
    // the bracket's best, unless a bend of it fails, none is possible, or
    // one of the bends the scan always tries (one turn, F6, and the
    // config's) beats it: another basin, so the scan
    if let Some(h) = hint
        && let Ok(Some(d)) =
            bracket_then_brent(h.bend, h.step, (lo, hi), tol, |b| eval(b, &mut evals))
    {
        let mut beaten = false;
        for &b in &xs[spec.phased.scan_points..] {
            if let Ok(other) = eval(b, &mut evals) {
                beaten |= other.unit_peak() < d.unit_peak();
            }
        }
        if !beaten {
            return Ok((d, evals));
        }
    }
    let best_d = scan_then_brent(xs, tol, |b| eval(b, &mut evals))?;
    Ok((best_d, evals))
}

/// The search's winner solved again to Clarabel's defaults (the
/// certificate); the search's own solution if that solve fails.
fn certified(cat: &Cat, problem: &mut TimingProblem, found: BendDesign) -> BendDesign {
    design_at(cat, problem, found.bend).unwrap_or(found)
}

/// F7: least drop height at which `unit_peak / T^2 <= tau_max`, m.
pub fn least_height(spec: &DesignSpec, unit_peak: f64, tau_max: f64) -> f64 {
    let t_min = (unit_peak / tau_max).sqrt() + spec.fall.margin;
    0.5 * spec.fall.gravity * t_min * t_min
}

/// Checks a design's peak against `limits.max_torque`.
pub fn check_limit(spec: &DesignSpec, unit_peak: f64, peak: f64, what: &str) -> Result<()> {
    if let Some(lim) = spec.motor.max_torque
        && peak > lim * (1.0 + crate::verdict::tolerance::LIMIT)
    {
        let t = (unit_peak / lim).sqrt() + spec.fall.margin;
        let height = if crate::config::ranges::beyond_longest_fall(t) {
            format!(
                "at this torque it needs a {t:.4e} s fall (F7), longer than any catflip designs ({} s): raise limits.max_torque",
                crate::config::ranges::MAX_FALL_TIME_S
            )
        } else {
            format!(
                "drop the cat from at least {:.3} m (fall.height, F7) or raise limits.max_torque",
                least_height(spec, unit_peak, lim)
            )
        };
        return Err(Error::BeyondMotors {
            reason: format!(
                "the {what} needs {peak:.4} N m but limits.max_torque = {lim} N m; {height}"
            ),
        });
    }
    Ok(())
}

/// The phased optimiser: bend search, optimal split, reconstruction and
/// comparison (the pipeline flies the schedule).
pub fn optimize(spec: &DesignSpec, observe: impl FnMut(&BendEvaluation)) -> Result<PhasedResult> {
    optimize_near(spec, None, observe)
}

/// [`optimize`] with the bend search started at a neighbour's bend (a
/// sweep's continuation; see [`search_bend`]).
pub fn optimize_near(
    spec: &DesignSpec,
    hint: Option<BendHint>,
    observe: impl FnMut(&BendEvaluation),
) -> Result<PhasedResult> {
    if spec.uses_envelope() {
        return finish_envelope(
            spec,
            crate::design::envelope::optimize_near(spec, hint, observe)?,
        );
    }
    let start = Instant::now();
    let mut problem = TimingProblem::new(spec.phased.nodes, spec.norm());
    let (design, evals) = search_bend(spec, &mut problem, hint, observe)?;
    let solve_time = start.elapsed().as_secs_f64();
    finish(spec, design, evals, solve_time)
}

/// Grid intervals per phase of the free-form design's phased seed: the free-form
/// design resamples the plan on its own mesh and optimises every node, so
/// the seed needs the shape of the schedule, not its certified peak. Fewer
/// intervals make the seed cheaper, down to 15 with the same free-form
/// peaks. The SCP's iteration count moves with the seed's small
/// differences, and 14 and 16 raised a peak (measured: docs/benchmarks.md,
/// "Design settings: the measurements behind them").
pub const SEED_NODES: usize = 15;

/// Bend tolerance of the free-form design's phased seed, deg (the free-form
/// design bends the body freely; the phased design's default is 0.05).
pub const SEED_BEND_TOL_DEG: f64 = 0.5;

/// The phased design's schedule alone, as a seed for the free-form design:
/// the bend search and the optimal split, without [`finish`]'s dense peak
/// and comparison, which the free-form design does for its own result.
/// Nor does it check `limits.max_torque` ([`check_limit`]): a seed above the
/// limit still starts a free-form design, which meets the limit or reports
/// the least height itself. It is a start, not a certificate: at most
/// [`SEED_NODES`] grid intervals per phase, the bend to
/// [`SEED_BEND_TOL_DEG`], the twist to [`SEED_TWIST_TOL`], and the search's accuracy (a config with a motor
/// envelope gets the whole envelope design, whose torque-speed line needs
/// its own iteration).
pub fn seed_plan(spec: &DesignSpec) -> Result<PhasedPlan> {
    if spec.uses_envelope() {
        return Ok(crate::design::envelope::optimize(spec, |_| {})?.plan);
    }
    let problem = TimingProblem::new(spec.phased.nodes.min(SEED_NODES), spec.norm());
    let tol = spec.phased.bend_tol_deg.max(SEED_BEND_TOL_DEG).to_radians();
    let (design, _) = search_bend_to(spec, &problem, None, tol, SEED_TWIST_TOL, |_| {})?;
    Ok(design.plan(design.durations(spec.available_time())))
}

/// Reconstruction and comparison of a design inside the motor envelope.
fn finish_envelope(
    spec: &DesignSpec,
    r: crate::design::envelope::EnvelopeResult,
) -> Result<PhasedResult> {
    let plan = r.plan;
    let time: f64 = plan.durations.iter().sum();
    let dense = crate::verify::analyze::dense_samples(spec);
    let (peak, _) = peak_along(spec, &plan, dense);
    let value = match r.objective {
        Objective::PeakTorque => peak,
        Objective::Time => time,
        Objective::Energy => {
            crate::design::envelope::torque_squared_integral(&spec.cat, &plan, dense)
        }
    };
    let split = spec.analytic.split.map(|f| f * time);
    let (analytic_peak, _) = peak_along(spec, &cosine_plan(r.bend, r.twist, split), 2000);
    Ok(PhasedResult {
        mode: "phased",
        status: r.status,
        objective: r.objective,
        objective_value: value,
        manoeuvre_time_s: time,
        peak_torque_nm: peak,
        socp_peak_torque_nm: None,
        unit_peak_nm_s2: peak * time * time,
        bend_deg: r.bend.to_degrees(),
        theta_deg: 180.0 - r.bend.to_degrees(),
        twist_rad: r.twist,
        phase_durations_s: plan.durations,
        phase_unit_peaks_nm_s2: None,
        analytic_peak_same_bend_nm: analytic_peak,
        optimum_same_split_nm: None,
        improvement_factor: analytic_peak / peak,
        nodes: spec.phased.nodes,
        evaluations: r.evaluations,
        solve_time_s: r.solve_time_s,
        plan,
        design: None,
    })
}

/// Reconstruction and comparison of a chosen design.
pub fn finish(
    spec: &DesignSpec,
    design: BendDesign,
    evals: Vec<BendEvaluation>,
    solve_time: f64,
) -> Result<PhasedResult> {
    let t = spec.available_time();
    let durations = design.durations(t);
    let socp_peak = design.unit_peak() / (t * t);
    let plan = design.plan(durations);
    let (peak, _) = peak_along(spec, &plan, crate::verify::analyze::dense_samples(spec));
    check_limit(spec, peak * t * t, peak, "phased design")?;
    let split = spec.analytic.split.map(|f| f * t);
    let (analytic_peak, _) = peak_along(spec, &cosine_plan(design.bend, design.twist, split), 2000);
    let status = design
        .phases
        .iter()
        .map(|p| p.status)
        .find(|s| *s != SolveStatus::Solved)
        .unwrap_or(SolveStatus::Solved);
    Ok(PhasedResult {
        mode: "phased",
        status,
        objective: Objective::PeakTorque,
        objective_value: peak,
        manoeuvre_time_s: t,
        peak_torque_nm: peak,
        socp_peak_torque_nm: Some(socp_peak),
        unit_peak_nm_s2: peak * t * t,
        bend_deg: design.bend.to_degrees(),
        theta_deg: 180.0 - design.bend.to_degrees(),
        twist_rad: design.twist,
        phase_durations_s: durations,
        phase_unit_peaks_nm_s2: Some(design.phases.each_ref().map(|p| p.unit_peak)),
        analytic_peak_same_bend_nm: analytic_peak,
        optimum_same_split_nm: Some(design.peak_with(split)),
        improvement_factor: analytic_peak / peak,
        nodes: spec.phased.nodes,
        evaluations: evals,
        solve_time_s: solve_time,
        plan,
        design: Some(design),
    })
}
