//! The cat and its schedules in a simulator's own terms: a URDF (pyBullet,
//! as the seed used, and MuJoCo), an MJCF (MuJoCo), and per schedule the
//! joint positions, velocities and actuator torques at the simulator's time
//! step, so that a schedule replays unedited.
//!
//! Frames follow docs/model.md: the rear half A's frame sits at its centre of mass
//! with `z` towards the joint at `(0, 0, l/2)`; the front half B's centre of
//! mass is `l/2` beyond the joint along its own `z`. `universal`: motor 1
//! about A's `x`, then motor 2 about the rotated `y` (`R = Rx(q1) Ry(q2)`).
//! `no-twist`: a ball joint whose relative rotation is `exp(hat(q1, q2, 0))`,
//! driven by three motors about the front half's own axes (see [`controls`]).

mod common;
pub mod controls;
pub mod mjcf;
pub mod start;
pub mod urdf;

pub use common::{Shape, halves, shapes};

pub use mjcf::mjcf;
pub use urdf::urdf;

use crate::config::Config;
use crate::design::plan::ShapePlan;
use crate::output::Output;

/// Everything `catflip run` writes for the simulators: both models and, per
/// method, the MuJoCo and pyBullet controls (`<method>.mujoco.csv`,
/// `<method>.pybullet.csv`).
pub fn add_simulator_files(cfg: &Config, out: &mut Output, methods: &[(&str, &dyn ShapePlan)]) {
    out.add(format!("{}.mjcf.xml", cfg.name), mjcf(cfg));
    out.add(format!("{}.urdf", cfg.name), urdf(cfg));
    for (name, plan) in methods {
        for sim in [controls::Simulator::Mujoco, controls::Simulator::Pybullet] {
            let c = controls::Controls::sample(cfg, *plan, sim);
            out.add(format!("{name}.{}.csv", sim.name()), c.to_csv(cfg, name));
        }
    }
}

/// What `export --schedule` writes beside the model: the schedule's
/// controls for `sim` at its time step (`<stem>.<sim>.csv`) and the closed
/// loop's gains along it (`<stem>.tvlqr.csv`); and a warning, also at the
/// top of the gains, when their nominal lands off belly-down
/// ([`crate::control::export::Gains::drifts`]).
pub fn add_schedule_files(
    cfg: &Config,
    out: &mut Output,
    schedule: &crate::design::plan::Schedule,
    stem: &str,
    sim: controls::Simulator,
) -> Option<String> {
    let c = controls::Controls::sample(cfg, schedule, sim);
    out.add(format!("{stem}.{}.csv", sim.name()), c.to_csv(cfg, stem));
    let g = crate::control::export::gains(cfg, schedule);
    let warning = g.drifts().then(|| {
        let per_phase = (schedule.rows.len() / 3).saturating_sub(1);
        format!(
            "the TVLQR's nominal (this schedule's feed-forward alone, catflip's model) lands {:.3} deg off \
             belly-down, the open loop's (joint PD on the planned shape) {:.3} deg: the TVLQR holds the \
             flight to its nominal, so it lands no closer. The schedule's {per_phase} rows a phase smooth \
             the design's torque between them; written with more (`--set simulate.samples_per_phase=2000` \
             where it is designed) the nominal follows the design more closely (docs/control.md, \
             \"Time-varying LQR\")",
            g.nominal_tvlqr_deg, g.nominal_open_loop_deg
        )
    });
    let csv = match &warning {
        Some(w) => format!("# warning: {w}.\n{}", g.csv),
        None => g.csv,
    };
    out.add(format!("{stem}.tvlqr.csv"), csv);
    warning
}
