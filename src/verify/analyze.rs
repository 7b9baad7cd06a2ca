//! `catflip analyze`: the seed's closed forms beside the true dynamics of its
//! schedule.

use crate::design::analytic::{ClosedForms, analytic_plan, closed_forms};
use crate::design::path::PhasedPlan;
use crate::design::plan::{Schedule, ShapePlan};
use crate::design::spec::DesignSpec;
use crate::error::Result;
use crate::verify::simulate::{SimReport, dynamic_spec, kinematic_spec};
use serde::Serialize;

/// Samples per phase of the reported ("dense") peaks: at least 2000 and a
/// multiple of the written schedules' rows, so every written row is among them.
pub fn dense_samples(spec: &DesignSpec) -> usize {
    let n = spec.simulate.samples_per_phase;
    n * 2000usize.div_ceil(n)
}

/// The plan's joint torque (peak norm) at `per_phase + 1` evenly spaced
/// instants of each phase: `(phase, t, |tau|)`.
fn torques_along<'a>(
    spec: &'a DesignSpec,
    plan: &'a dyn ShapePlan,
    per_phase: usize,
) -> impl Iterator<Item = (usize, f64, f64)> + 'a {
    let pb = plan.phase_bounds();
    let b = [pb[0], pb[1], pb[2], pb[3]];
    let norm = spec.norm();
    (0..3).flat_map(move |i| {
        (0..=per_phase).map(move |k| {
            let t = b[i] + (b[i + 1] - b[i]) * k as f64 / per_phase as f64;
            (i, t, norm.of(plan.torque_in(&spec.cat, i, t)))
        })
    })
}

/// Peak joint torque along a plan, sampled densely in every phase, N m.
pub fn peak_along(spec: &DesignSpec, plan: &dyn ShapePlan, per_phase: usize) -> (f64, [f64; 3]) {
    let mut per = [0.0f64; 3];
    for (i, _, v) in torques_along(spec, plan, per_phase) {
        per[i] = per[i].max(v);
    }
    (per.iter().cloned().fold(0.0, f64::max), per)
}

/// Where [`peak_along`] finds the peak: the phase and the instant, s.
pub fn peak_instant(spec: &DesignSpec, plan: &dyn ShapePlan, per_phase: usize) -> (usize, f64) {
    let (i, t, _) =
        torques_along(spec, plan, per_phase).fold((0, f64::NAN, f64::NEG_INFINITY), |best, s| {
            if s.2 > best.2 { s } else { best }
        });
    (i, t)
}

#[derive(Debug, Clone, Serialize)]
pub struct Analysis {
    pub name: String,
    pub joint: &'static str,
    #[serde(flatten)]
    pub closed: ClosedForms,
    /// True inverse-dynamics peak along the seed's schedule, N m.
    pub peak_torque_nm: f64,
    pub phase_peak_torque_nm: [f64; 3],
    /// True peak over the seed's estimate (erratum E7).
    pub peak_over_seed_estimate: f64,
    /// Kinematic simulation of the schedule.
    pub flip_deg: f64,
    pub flip_error_rad: f64,
    pub tilt_deg: f64,
    /// The belly's angle from straight down at touchdown, deg: what the
    /// verdict judges (the heading is free).
    pub landing_error_deg: f64,
    pub momentum_drift_nms: f64,
    #[serde(skip)]
    pub plan: PhasedPlan,
    #[serde(skip)]
    pub kinematic: SimReport,
}

/// The analytic schedule of `spec` (the config `name`) and its closed forms.
pub fn analyze(spec: &DesignSpec, name: &str) -> Result<Analysis> {
    let closed = closed_forms(spec);
    let plan = analytic_plan(spec);
    let (peak, per) = peak_along(spec, &plan, dense_samples(spec));
    let kin = kinematic_spec(spec, &plan)?;
    Ok(Analysis {
        name: name.to_string(),
        joint: spec.cat.joint.name(),
        peak_over_seed_estimate: peak / closed.seed_torque_estimate_nm,
        closed,
        peak_torque_nm: peak,
        phase_peak_torque_nm: per,
        flip_deg: kin.flip_deg,
        flip_error_rad: kin.flip_error_rad,
        tilt_deg: kin.tilt_deg,
        landing_error_deg: kin.landing_error_deg,
        momentum_drift_nms: kin.momentum_drift_nms,
        plan,
        kinematic: kin,
    })
}

/// Schedule of the analytic plan, sampled for output.
pub fn analytic_schedule(spec: &DesignSpec, plan: &PhasedPlan) -> Schedule {
    Schedule::sample(&spec.cat, plan, spec.simulate.samples_per_phase)
}

/// Dynamic verification of any plan.
pub fn verify(spec: &DesignSpec, plan: &dyn ShapePlan) -> Result<SimReport> {
    dynamic_spec(spec, plan)
}
