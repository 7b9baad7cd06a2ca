//! The cat as an MJCF model for MuJoCo.

use super::common::{Half, dc_motor, f, halves, torque_limit};
use super::controls::{Simulator, time_step};
use crate::config::Config;
use crate::model::Joint;

/// `<inertial>` and `<geom>` of one half whose centre of mass is at `z` on its own axis.
fn body_parts(h: &Half, z: f64) -> String {
    format!(
        "      <inertial pos=\"0 0 {z}\" mass=\"{m}\" diaginertia=\"{it} {it} {ia}\"/>\n      <geom type=\"cylinder\" size=\"{r} {hl}\" pos=\"0 0 {z}\" mass=\"0\"/>\n",
        z = f(z),
        m = f(h.mass),
        it = f(h.i_t()),
        ia = f(h.i_a()),
        r = f(h.radius),
        hl = f(h.length / 2.0),
    )
}

/// The motor envelope in words, for the model files' header comments.
pub(crate) fn motor_note(cfg: &Config) -> String {
    let m = cfg.motor();
    let mut s = String::new();
    if let Some(t) = m.max_torque {
        s.push_str(&format!("\n     Motor: stall torque {t} N m"));
        if m.slope() > 0.0 {
            s.push_str(&format!(
                ", torque-speed line |tau + {k} w| <= {t}",
                k = m.slope()
            ));
            if cfg.cat.joint == Joint::Universal {
                s.push_str(
                    ": each motor is a DC motor, force = ctrl - k qd with ctrl (the voltage, in N m)
     limited to the stall torque; the *.mujoco.csv ctrl is tau + k qd",
                );
            } else {
                s.push_str(" (a disc in catflip's rotation-vector coordinates, not expressible here: apply it to the command)");
            }
        }
        s.push('.');
    }
    if let Some(w) = super::common::speed_limit(cfg) {
        let why = if cfg.limits.max_speed.is_some() {
            "limits.max_speed"
        } else {
            "the no-load speed: the motor cannot drive faster"
        };
        s.push_str(&format!("\n     Joint speed limit {w} rad/s ({why})."));
    }
    s
}

/// MJCF (MuJoCo) text of the cat of `cfg`, dropped from the config's height.
///
/// The time step tiles the config's manoeuvre time (at most 0.5 ms), the step
/// of the `*.mujoco.csv` controls. The torque limit becomes `ctrlrange` and
/// `forcerange` of every motor (unless a torque-speed line makes it speed
/// dependent, which MJCF motors cannot say; the header comment then states it).
pub fn mjcf(cfg: &Config) -> String {
    let [rear, front] = halves(cfg);
    let (dt, _) = time_step(cfg.available_time(), Simulator::Mujoco.target_step());
    // A box on the torque is exact only without a torque-speed line; with one
    // (|tau + k w| <= T) the replay clips to the envelope itself.
    let limit = torque_limit(cfg)
        .filter(|_| cfg.motor().slope() == 0.0)
        .map(|l| {
            format!(
                " ctrllimited=\"true\" ctrlrange=\"{a} {b}\" forcelimited=\"true\" forcerange=\"{a} {b}\"",
                a = f(-l),
                b = f(l)
            )
        })
        .unwrap_or_default();
    let (joints, actuators) = match cfg.cat.joint {
        Joint::Universal => (
            "      <!-- universal joint: motor1 about the rear's x, then motor2 about the rotated y -->\n      <joint name=\"motor1\" type=\"hinge\" axis=\"1 0 0\"/>\n      <joint name=\"motor2\" type=\"hinge\" axis=\"0 1 0\"/>\n".to_string(),
            match dc_motor(cfg) {
                Some(dc) => format!(
                    "    <!-- DC motors: force = ctrl - k qd (back-EMF), ctrl limited to the stall torque -->\n    <general name=\"tau1\" joint=\"motor1\"{dc}/>\n    <general name=\"tau2\" joint=\"motor2\"{dc}/>\n"
                ),
                None => format!(
                    "    <motor name=\"tau1\" joint=\"motor1\" gear=\"1\"{limit}/>\n    <motor name=\"tau2\" joint=\"motor2\" gear=\"1\"{limit}/>\n"
                ),
            },
        ),
        Joint::NoTwist => (
            "      <!-- Kane & Scher no-twist joint as a ball: qpos is the quaternion of exp(hat(q1, q2, 0)),\n           qvel the relative rate in this (front) body's frame; the twist is held by the third motor -->\n      <joint name=\"spine\" type=\"ball\"/>\n".to_string(),
            format!(
                "    <!-- torques about the front half's own axes: ctrl = J_r(v)^-T (tau1, tau2, tau3), see *.mujoco.csv -->\n    <motor name=\"tau_x\" joint=\"spine\" gear=\"1 0 0\"{limit}/>\n    <motor name=\"tau_y\" joint=\"spine\" gear=\"0 1 0\"{limit}/>\n    <motor name=\"tau_z\" joint=\"spine\" gear=\"0 0 1\"{limit}/>\n"
            ),
        ),
    };
    let start = super::start::base_start(cfg);
    let (shape_pos, shape_vel) = match cfg.cat.joint {
        Joint::Universal => ("0 0", "0 0"),
        Joint::NoTwist => ("1 0 0 0", "0 0 0"),
    };
    let mut qpos: Vec<String> = [0.0, 0.0, cfg.fall.height]
        .iter()
        .chain(&start.quat)
        .map(|x| f(*x))
        .collect();
    qpos.push(shape_pos.into());
    let mut qvel: Vec<String> = start
        .linear_velocity
        .iter()
        .chain(&start.angular_velocity_body)
        .map(|x| f(*x))
        .collect();
    qvel.push(shape_vel.into());
    format!(
        r#"<!-- catflip: {name} ({joint} joint). Masses and inertias as in catflip's docs/model.md;
     SI units, angles in rad. Time step {dt:.9e} s = the manoeuvre time / an integer, the
     step of catflip's *.mujoco.csv controls (torque held over each step).{motor_note} -->
<mujoco model="{name}">
  <option gravity="0 0 -{g}" timestep="{dt:.15e}" integrator="RK4"/>
  <worldbody>
    <!-- the start (catflip's [start]): the rear half at W R0, spine along world x in the reference
         pose, belly (its x) up; the keyframe "start" adds the release velocities -->
    <body name="rear" pos="0 0 {height}" quat="{quat}">
      <freejoint name="fall"/>
{rear_parts}      <body name="front" pos="0 0 {joint_z}">
{joints}{front_parts}      </body>
    </body>
  </worldbody>
  <actuator>
{actuators}  </actuator>
  <keyframe>
    <!-- release: free joint at W R0 with A's velocity (world) and rate (A's frame), shape straight -->
    <key name="start" qpos="{qpos}" qvel="{qvel}"/>
  </keyframe>
</mujoco>
"#,
        quat = start.quat.map(f).join(" "),
        qpos = qpos.join(" "),
        qvel = qvel.join(" "),
        name = cfg.name,
        joint = cfg.cat.joint.name(),
        g = f(cfg.fall.gravity),
        height = f(cfg.fall.height),
        joint_z = f(rear.length / 2.0),
        motor_note = motor_note(cfg),
        rear_parts = body_parts(&rear, 0.0),
        front_parts = body_parts(&front, front.length / 2.0),
    )
}
