//! The cat as an MJCF model for MuJoCo.

use super::common::{Shape, dc_motor, f, shapes, torque_limit, v3};
use super::controls::{Simulator, time_step};
use crate::config::Config;
use crate::model::Joint;

/// `<inertial>` and `<geom>` of one half whose body frame has its origin at
/// `origin` (a point of the half's frame).
fn body_parts(shape: &Shape, origin: [f64; 3]) -> String {
    let r = &shape.rigid;
    let i = &r.inertia;
    let com = std::array::from_fn(|k| r.com[k] - origin[k]);
    let diagonal = [i[0][1], i[0][2], i[1][2]] == [0.0; 3];
    let inertia = if diagonal {
        format!(
            "diaginertia=\"{} {} {}\"",
            f(i[0][0]),
            f(i[1][1]),
            f(i[2][2])
        )
    } else {
        format!(
            "fullinertia=\"{} {} {} {} {} {}\"",
            f(i[0][0]),
            f(i[1][1]),
            f(i[2][2]),
            f(i[0][1]),
            f(i[0][2]),
            f(i[1][2])
        )
    };
    let geom = match shape.cylinder {
        Some(h) => format!(
            "type=\"cylinder\" size=\"{r} {hl}\" pos=\"{c}\"",
            r = f(h.radius),
            hl = f(h.length / 2.0),
            c = v3(com)
        ),
        None => {
            let (edges, rpy) = shape.inertia_box();
            let rot = nalgebra::Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
            let q = nalgebra::UnitQuaternion::from_rotation_matrix(&rot);
            format!(
                "type=\"box\" size=\"{h}\" pos=\"{c}\" quat=\"{w} {x} {y} {z}\"",
                h = v3(edges.map(|e| (e / 2.0).max(1e-6))),
                c = v3(com),
                w = f(q.w),
                x = f(q.i),
                y = f(q.j),
                z = f(q.k)
            )
        }
    };
    format!(
        "      <inertial pos=\"{c}\" mass=\"{m}\" {inertia}/>\n      <geom {geom} mass=\"0\"/>\n",
        c = v3(com),
        m = f(r.mass),
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
        if cfg.limits.max_speed.is_some() {
            s.push_str(&format!(
                "\n     Joint speed limit {w} rad/s (limits.max_speed)."
            ));
        } else {
            s.push_str(&format!(
                "\n     No-load speed {w} rad/s: the motor drives no faster, but brakes beyond it (a schedule that brakes hard may pass it)."
            ));
        }
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
    let [rear, front] = shapes(cfg);
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
            format!("      <!-- universal joint: motor1 about the rear's axis, then motor2 about the front's, turned by motor1 -->\n      <joint name=\"motor1\" type=\"hinge\" axis=\"{}\"/>\n      <joint name=\"motor2\" type=\"hinge\" axis=\"{}\"/>\n",
            v3(rear.rigid.axis), v3(front.rigid.axis)),
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
{rear_parts}      <body name="front" pos="{joint_at}">
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
        joint_at = v3(rear.rigid.joint),
        motor_note = motor_note(cfg),
        rear_parts = body_parts(&rear, [0.0; 3]),
        front_parts = body_parts(&front, front.rigid.joint),
    )
}
