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
/// loop's gains along it (`<stem>.tvlqr.csv`).
pub fn add_schedule_files(
    cfg: &Config,
    out: &mut Output,
    schedule: &crate::design::plan::Schedule,
    stem: &str,
    sim: controls::Simulator,
) -> crate::Result<()> {
    let c = controls::Controls::sample(cfg, schedule, sim);
    out.add(format!("{stem}.{}.csv", sim.name()), c.to_csv(cfg, stem));
    out.add(
        format!("{stem}.tvlqr.csv"),
        crate::control::export::gains_csv(cfg, schedule)?,
    );
    Ok(())
}
