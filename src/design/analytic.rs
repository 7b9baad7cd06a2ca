//! The seed's closed forms and its cosine schedule, errata corrected
//! (docs/model.md section 7), evaluated with the true dynamics elsewhere.

use crate::design::path::{Path, PhasedPlan, Timing};
use crate::design::spec::DesignSpec;
use serde::Serialize;
use std::f64::consts::PI;

pub use crate::model::twist::{turns_theta, yy_inertia_and_c};

/// Everything the seed computes in closed form, for one config.
#[derive(Debug, Clone, Serialize)]
pub struct ClosedForms {
    pub fall_time_s: f64,
    pub available_time_s: f64,
    pub theta_deg: f64,
    /// Bend `b = pi - theta`, degrees.
    pub bend_deg: f64,
    #[serde(rename = "I_t")]
    pub i_t: f64,
    #[serde(rename = "I_a")]
    pub i_a: f64,
    #[serde(rename = "I_yy")]
    pub i_yy: f64,
    #[serde(rename = "C")]
    pub c: f64,
    /// Twist of the bend direction, `pi / C`, rad.
    pub twist_rad: f64,
    /// Mean twist rate over the twist phase, `(pi/C) / T_twist` (erratum E8 corrected).
    pub omega0_rad_s: f64,
    /// Seed section 7: `pi / (Delta t C)`, the rate as if the twist had the whole fall.
    pub seed_omega_rad_s: f64,
    /// `theta` of the one-turn design (F6), degrees.
    pub one_turn_theta_deg: f64,
    /// Seed's `I* = I_t + m (l/2)^2` (erratum E7: not the free-fall inertia).
    pub i_star: f64,
    /// Seed section 8 estimates `pi^2/T1^2 I*`, `omega0 pi/T2 I*`, `pi^2/T3^2 I*`, N m.
    pub seed_phase_estimates_nm: [f64; 3],
    /// Largest of the three, N m.
    pub seed_torque_estimate_nm: f64,
    /// Seed section 7 example: `seed_omega pi / Delta t I*`, N m.
    pub seed_example_torque_nm: f64,
    pub phase_durations_s: [f64; 3],
}

pub fn closed_forms(spec: &DesignSpec) -> ClosedForms {
    let cat = spec.cat;
    let (i_t, i_a) = (cat.i_t(), cat.i_a());
    let theta = spec.analytic.theta_deg.to_radians();
    let (i_yy, c) = yy_inertia_and_c(i_t, i_a, theta);
    let fall = spec.fall_time();
    let avail = spec.available_time();
    let d = spec.analytic.split.map(|f| f * avail);
    let twist = PI / c;
    let omega0 = twist / d[1];
    // the seed swings the front half about the joint
    let i_star = cat.front.i_t() + cat.front.mass * cat.front.half_length().powi(2);
    let est = [
        PI * PI / (d[0] * d[0]) * i_star,
        omega0 * PI / d[1] * i_star,
        PI * PI / (d[2] * d[2]) * i_star,
    ];
    let seed_omega = PI / (fall * c);
    ClosedForms {
        fall_time_s: fall,
        available_time_s: avail,
        theta_deg: spec.analytic.theta_deg,
        bend_deg: 180.0 - spec.analytic.theta_deg,
        i_t,
        i_a,
        i_yy,
        c,
        twist_rad: twist,
        omega0_rad_s: omega0,
        seed_omega_rad_s: seed_omega,
        one_turn_theta_deg: turns_theta(i_t, i_a, 1.0).to_degrees(),
        i_star,
        seed_phase_estimates_nm: est,
        seed_torque_estimate_nm: est.iter().cloned().fold(0.0, f64::max),
        seed_example_torque_nm: seed_omega * PI / fall * i_star,
        phase_durations_s: d,
    }
}

/// The seed's schedule: cosine fold to bend `pi - theta` along `q1`, twist of
/// the bend direction by `twist` with rate `omega0 (1 - cos(2 pi t / T2))`,
/// cosine unfold.
pub fn plan(bend: f64, twist: f64, durations: [f64; 3]) -> PhasedPlan {
    PhasedPlan {
        paths: Path::phased(bend, twist),
        timings: [Timing::Cosine, Timing::CosineRate, Timing::Cosine],
        durations,
    }
}

/// The analytic plan of a config.
pub fn analytic_plan(spec: &DesignSpec) -> PhasedPlan {
    let cf = closed_forms(spec);
    plan(cf.bend_deg.to_radians(), cf.twist_rad, cf.phase_durations_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_turn_theta_gives_c_one_half_and_n_turns_one_over_2n() {
        for (i_t, i_a) in [(0.0858, 0.005), (0.3, 0.05), (1.0, 0.4)] {
            for n in [1.0, 2.0, 3.0] {
                let th = turns_theta(i_t, i_a, n);
                let (_, c) = yy_inertia_and_c(i_t, i_a, th);
                assert!(
                    (c - 1.0 / (2.0 * n)).abs() < 1e-12,
                    "{i_t} {i_a} {n}: C = {c}"
                );
            }
        }
    }
}
