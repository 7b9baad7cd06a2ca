//! The tables of the one-design commands: `analyze` (the seed's closed
//! forms), `simulate` (a schedule flown) and `optimize` (a phased or
//! free-form design).

use super::Rows;
use super::table::{maybe, shown};
use crate::config::Config;
use crate::design::free::FreeResult;
use crate::design::phased::PhasedResult;
use crate::verdict::{Grade, Status};
use crate::verify::analyze::Analysis;
use crate::verify::simulate::SimReport;
use std::path::PathBuf;

/// `analyze`'s table: the closed forms and the cosine schedule's numbers.
pub fn analysis(a: &Analysis, written: &[PathBuf]) -> Rows {
    let cf = &a.closed;
    let mut t = Rows::titled(format!("catflip analyze: {} ({} joint)", a.name, a.joint));
    t.row(
        "fall time",
        format!(
            "{:.4} s (manoeuvre {:.4} s)",
            cf.fall_time_s, cf.available_time_s
        ),
    )
    .row(
        "theta / bend",
        format!("{:.3} / {:.3} deg", cf.theta_deg, cf.bend_deg),
    )
    .row(
        "I_t, I_a, I_yy",
        format!("{:.6}, {:.6}, {:.6} kg m^2", cf.i_t, cf.i_a, cf.i_yy),
    )
    .row("C", format!("{:.6}", cf.c))
    .row("twist pi/C", format!("{:.6} rad", cf.twist_rad))
    .row(
        "omega0 (twist phase)",
        format!("{:.4} rad/s", cf.omega0_rad_s),
    )
    .row(
        "seed's omega (section 7)",
        format!(
            "{:.4} rad/s (E2 corrected: sin(theta/2), not the seed's sin^2; E8 kept, as the seed does: the whole fall as the twist's time)",
            cf.seed_omega_rad_s
        ),
    )
    .row(
        "one-turn theta (F6)",
        format!("{:.3} deg", cf.one_turn_theta_deg),
    )
    .row(
        "phase durations",
        format!(
            "{:.4} / {:.4} / {:.4} s",
            cf.phase_durations_s[0], cf.phase_durations_s[1], cf.phase_durations_s[2]
        ),
    )
    .row(
        "seed I* estimate (E7)",
        format!("{:.4} N m", cf.seed_torque_estimate_nm),
    )
    .row(
        "true peak torque",
        format!(
            "{:.4} N m (fold {:.4}, twist {:.4}, unfold {:.4}; {:.2}x the estimate)",
            a.peak_torque_nm,
            a.phase_peak_torque_nm[0],
            a.phase_peak_torque_nm[1],
            a.phase_peak_torque_nm[2],
            a.peak_over_seed_estimate
        ),
    )
    .row(
        "flip (kinematic sim)",
        format!("{:.9} deg (error {:.2e} rad)", a.flip_deg, a.flip_error_rad),
    )
    .row("tilt", format!("{:.3e} deg", a.tilt_deg))
    .row(
        "momentum drift",
        format!("{:.2e} N m s", a.momentum_drift_nms),
    )
    .wrote(written);
    t
}

/// `simulate`'s table: what the flown schedule did.
pub fn simulation(title: &str, r: &SimReport) -> Rows {
    let mut t = Rows::titled(title);
    t.row(
        "flip",
        format!("{:.6} deg (error {:.2e} rad)", r.flip_deg, r.flip_error_rad),
    )
    .row("tilt", format!("{:.3e} deg", r.tilt_deg));
    landing_row(&mut t, r);
    t.row(
        "final shape / rate error",
        format!(
            "{:.2e} rad / {:.2e} rad/s",
            r.final_shape_error_rad, r.final_rate_error_rad_s
        ),
    )
    .row(
        "max tracking error",
        format!("{:.2e} rad", r.max_tracking_error_rad),
    )
    .row(
        "peak applied torque",
        format!("{:.4} N m", r.peak_torque_nm),
    )
    .row(
        "momentum drift",
        format!("{:.2e} N m s", r.momentum_drift_nms),
    )
    .row("accepted steps", format!("{}", r.steps));
    t
}

/// `simulate`'s title: the config, the schedule's source and the controller.
pub fn simulation_title(cfg: &Config, source: &str) -> String {
    format!(
        "catflip simulate: {} ({source}, dynamic, {})",
        cfg.name,
        if cfg.simulate.pd {
            "feed-forward + PD"
        } else {
            "feed-forward only"
        }
    )
}

/// The belly's angle from straight down at touchdown, where the flight
/// has one: from another start it is the verdict's number (the tilt then
/// includes the heading's turn, which does not matter).
fn landing_row(t: &mut Rows, sim: &SimReport) {
    if sim.landing_error_deg.is_finite() {
        t.row(
            "landing",
            format!("{:.3e} deg from belly-down", sim.landing_error_deg),
        );
    }
}

/// The rows both optimisers print: timing, the flight, solve time, files.
fn design_rows(
    t: &mut Rows,
    durations: [f64; 3],
    sim: &SimReport,
    solve: String,
    written: &[PathBuf],
) {
    let d = durations;
    t.row(
        "phase durations",
        format!("{:.4} / {:.4} / {:.4} s", d[0], d[1], d[2]),
    )
    .row(
        "flip (dynamic sim)",
        format!(
            "{:.6} deg (error {:.2e} rad)",
            sim.flip_deg, sim.flip_error_rad
        ),
    )
    .row("tilt", format!("{:.3e} deg", sim.tilt_deg));
    landing_row(t, sim);
    t.row("sim peak torque", format!("{:.5} N m", sim.peak_torque_nm))
        .row("solve time", solve)
        .wrote(written);
}

/// The largest change of the objective at twice the nodes for which the
/// table calls a design resolved by its mesh (the bundled configs' designs
/// move by 0.03 to 0.3 %).
const MESH_RESOLVED: f64 = 0.01;

/// The mesh check's row: the objective at twice the nodes, its change, the
/// status of that SCP, and, where the change is above [`MESH_RESOLVED`],
/// that the design is not resolved by its mesh (just above the least
/// height few schedules fit, and the robot's peak moved by a third).
fn mesh_check(m: &crate::design::free::MeshCheck, unit: &str) -> String {
    let unresolved = if m.relative_change.abs() > MESH_RESOLVED {
        format!(
            "; the design moves with the mesh: try free.nodes = {}",
            m.nodes
        )
    } else {
        String::new()
    };
    format!(
        "{:.5} {unit} at {} nodes per phase ({:+.2} %), its SCP {}{unresolved}",
        m.objective_value,
        m.nodes,
        100.0 * m.relative_change,
        Status::from(m.status)
    )
}

/// Why a sound design's peak is above the stall torque, on its peak row:
/// `run`'s braking note ([`crate::run::RunSummary::braking_note`]) for a
/// design whose verdict is `grade`.
fn braking(cfg: &Config, peak: f64, grade: Grade) -> String {
    match cfg.limits.max_torque {
        Some(stall) if crate::run::sound_above(stall, grade, Some(peak)) => {
            format!("; {}", crate::run::braking_words(stall))
        }
        _ => String::new(),
    }
}

/// `optimize --mode phased`'s table, `grade` its verdict.
/// `sim`: the stage's flight of it.
pub fn phased(
    cfg: &Config,
    r: &PhasedResult,
    sim: &SimReport,
    written: &[PathBuf],
    grade: Grade,
) -> Rows {
    let mut t = Rows::titled(format!(
        "catflip optimize --mode phased: {} ({} joint), status {}",
        cfg.name,
        cfg.cat.joint.name(),
        Status::from(r.status)
    ));
    t.row(
        "peak torque",
        format!(
            "{:.5} N m (SOCP bound {}){}",
            r.peak_torque_nm,
            maybe(r.socp_peak_torque_nm, 5),
            braking(cfg, r.peak_torque_nm, grade)
        ),
    )
    .row(
        "bend / theta",
        format!("{:.3} / {:.3} deg", r.bend_deg, r.theta_deg),
    )
    .row("twist", format!("{:.6} rad", r.twist_rad))
    .row(
        "seed cosine schedule, same bend",
        format!(
            "{:.5} N m ({:.2}x the optimum)",
            r.analytic_peak_same_bend_nm, r.improvement_factor
        ),
    );
    least_height_row(&mut t, cfg, r.manoeuvre_time_s);
    design_rows(
        &mut t,
        r.phase_durations_s,
        sim,
        format!(
            "{:.3} s ({} bend evaluations)",
            r.solve_time_s,
            r.evaluations.len()
        ),
        written,
    );
    t
}

/// A `time` design's least drop height, with what the configured fall
/// leaves ([`crate::pipeline::least_height_of_time_design`]).
fn least_height_row(t: &mut Rows, cfg: &Config, manoeuvre_s: f64) {
    let spec = cfg.design_spec();
    if let Some(h) = crate::pipeline::least_height_of_time_design(&spec, manoeuvre_s) {
        t.row(
            "least drop height",
            format!(
                "{h:.3} m for this manoeuvre and fall.margin (the fall from {} m leaves {:.4} s)",
                cfg.fall.height,
                spec.available_time()
            ),
        );
    }
}

/// `optimize --mode free`'s table, `grade` its verdict.
/// `sim`: the stage's flight of it.
pub fn free(
    cfg: &Config,
    r: &FreeResult,
    sim: &SimReport,
    written: &[PathBuf],
    grade: Grade,
) -> Rows {
    let mut t = Rows::titled(format!(
        "catflip optimize --mode free: {} ({} joint), status {}, seed {}",
        cfg.name,
        cfg.cat.joint.name(),
        Status::from(r.status),
        r.seed
    ));
    t.row(
        &format!("objective ({})", r.objective.name()),
        format!(
            "{:.6} {} (manoeuvre {:.4} s)",
            r.objective_value,
            r.objective.unit(),
            r.manoeuvre_time_s
        ),
    )
    .row(
        "peak torque",
        format!(
            "{:.5} N m (at check points {:.5}){}",
            r.peak_torque_nm,
            r.node_peak_torque_nm,
            braking(cfg, r.peak_torque_nm, grade)
        ),
    )
    .row(
        "largest bend / theta",
        format!("{:.3} / {:.3} deg", r.bend_deg, r.theta_deg),
    )
    .row("twist of bend direction", format!("{:.4} rad", r.twist_rad));
    least_height_row(&mut t, cfg, r.manoeuvre_time_s);
    let cert = &r.certificate;
    t.row(
        "certificate",
        format!(
            "step {:.2e}, constraint violation {:.2e} rad, criticality {:.2e} (stop: {})",
            cert.step,
            cert.constraint_violation,
            cert.criticality,
            shown(&cert.rule)
        ),
    );
    if let Some(m) = &r.mesh_check {
        t.row("mesh check (N vs 2N)", mesh_check(m, r.objective.unit()));
    }
    design_rows(
        &mut t,
        r.phase_durations_s,
        sim,
        format!(
            "{:.3} s ({})",
            r.solve_time_s,
            crate::design::free::iterations_text(&r.mesh_levels)
        ),
        written,
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_check_that_moves_the_design_says_it_is_not_resolved() {
        let check = |change: f64| crate::design::free::MeshCheck {
            nodes: 120,
            status: crate::design::scp::ScpStatus::Converged,
            scp_iterations: 5,
            peak_torque_nm: 0.45,
            objective_value: 0.44972,
            relative_change: change,
        };
        let resolved = mesh_check(&check(3e-4), "N m");
        assert_eq!(
            resolved,
            "0.44972 N m at 120 nodes per phase (+0.03 %), its SCP converged"
        );
        // the robot's peak just above its least height moved by a third
        for change in [0.3147, -0.02] {
            let moved = mesh_check(&check(change), "N m");
            assert!(
                moved.ends_with("the design moves with the mesh: try free.nodes = 120"),
                "{moved}"
            );
        }
    }
}
