//! The cat as a URDF for pyBullet (the seed's simulator); the universal one
//! also loads in MuJoCo.

use super::common::{f, halves, speed_limit, torque_limit};
use crate::config::Config;
use crate::model::Half;
use crate::model::Joint;

/// Mass and inertia of the universal joint's `cross` link (massless in the
/// model) as fractions of a half's mass and axial inertia: simulators refuse
/// (MuJoCo) or replace with 1 kg (pyBullet) a moving link without mass. The
/// effect is linear in the fraction: in MuJoCo on the robot config, 1e-6 of a
/// half's mass and transverse inertia moved the flip by 2.6e-4 deg, 1e-4 by
/// 2.6e-2 deg; at 1e-8 of mass and axial inertia the URDF and the cross-less
/// MJCF flip within 1e-6 deg of each other (examples/replay_mujoco.py prints it).
pub const CROSS_FRACTION: f64 = 1e-8;

/// Speed limit written for joints when the config has none, rad/s (URDF needs one).
const NO_SPEED_LIMIT: f64 = 1e3;
/// Effort written when the config has no torque limit, N m.
const NO_TORQUE_LIMIT: f64 = 1e3;

fn inertial(m: f64, it: f64, ia: f64, z: f64) -> String {
    format!(
        "    <inertial>\n      <origin xyz=\"0 0 {z}\" rpy=\"0 0 0\"/>\n      <mass value=\"{m}\"/>\n      <inertia ixx=\"{it}\" ixy=\"0\" ixz=\"0\" iyy=\"{it}\" iyz=\"0\" izz=\"{ia}\"/>\n    </inertial>\n",
        z = f(z),
        m = f(m),
        it = f(it),
        ia = f(ia)
    )
}

fn link(name: &str, h: &Half, z: f64) -> String {
    let geometry = format!(
        "<origin xyz=\"0 0 {z}\"/><geometry><cylinder radius=\"{r}\" length=\"{l}\"/></geometry>",
        z = f(z),
        r = f(h.radius),
        l = f(h.length)
    );
    format!(
        "  <link name=\"{name}\">\n{}    <visual>{geometry}</visual>\n    <collision>{geometry}</collision>\n  </link>\n",
        inertial(h.mass, h.i_t(), h.i_a(), z)
    )
}

fn revolute(
    name: &str,
    parent: &str,
    child: &str,
    z: f64,
    axis: &str,
    (effort, speed): (f64, f64),
) -> String {
    format!(
        "  <joint name=\"{name}\" type=\"revolute\">\n    <parent link=\"{parent}\"/>\n    <child link=\"{child}\"/>\n    <origin xyz=\"0 0 {z}\"/>\n    <axis xyz=\"{axis}\"/>\n    <limit lower=\"{lo}\" upper=\"{hi}\" effort=\"{effort}\" velocity=\"{v}\"/>\n  </joint>\n",
        z = f(z),
        lo = f(-std::f64::consts::PI),
        hi = f(std::f64::consts::PI),
        effort = f(effort),
        v = f(speed),
    )
}

/// URDF text of the cat of `cfg`.
pub fn urdf(cfg: &Config) -> String {
    let [rear, front] = halves(cfg);
    // URDF's effort is one bound on |tau|: the stall torque, or with a
    // torque-speed line the most the envelope allows (braking at the speed limit).
    let speed = speed_limit(cfg).unwrap_or(NO_SPEED_LIMIT);
    let limits = (
        torque_limit(cfg).map_or(NO_TORQUE_LIMIT, |t| t + cfg.motor().slope() * speed),
        speed,
    );
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<!-- catflip: {name} ({joint} joint). Masses and inertias as in catflip's docs/model.md;\n     SI units, angles in rad. pyBullet: load with flags=p.URDF_USE_INERTIA_FROM_FILE, or it\n     recomputes the inertias from the collision cylinders (wrong for this model); set the\n     links' linearDamping and angularDamping to 0 (pyBullet's default is 0.04).\n     Joint effort = the config's torque limit ({lim}; with a torque-speed line, the most\n     it allows, when braking at the speed limit), velocity = its speed limit (else 1000).{note} -->\n<robot name=\"{name}\">\n",
        name = cfg.name,
        joint = cfg.cat.joint.name(),
        lim = torque_limit(cfg)
            .map(|l| format!("{l} N m"))
            .unwrap_or_else(|| "none: 1000 N m written".into()),
        note = super::mjcf::motor_note(cfg),
    );
    s.push_str(&link("rear", &rear, 0.0));
    match cfg.cat.joint {
        Joint::Universal => {
            let (m, i) = (CROSS_FRACTION * rear.mass, CROSS_FRACTION * rear.i_a());
            s.push_str(&format!(
                "  <!-- the universal joint's cross: massless in the model; a negligible mass and inertia ({CROSS_FRACTION:e}\n       of a half's mass and axial inertia) because simulators need every moving link massive -->\n  <link name=\"cross\">\n{}  </link>\n",
                inertial(m, i, i, 0.0)
            ));
            s.push_str(&revolute(
                "motor1",
                "rear",
                "cross",
                rear.length / 2.0,
                "1 0 0",
                limits,
            ));
            s.push_str(&revolute("motor2", "cross", "front", 0.0, "0 1 0", limits));
        }
        Joint::NoTwist => {
            s.push_str(&format!(
                "  <!-- Kane & Scher no-twist joint: relative rotation exp(hat(q1, q2, 0)). type=\"spherical\" is a\n       pyBullet extension (3 DoF, torque in the front link's frame, see *.pybullet.csv) -->\n  <joint name=\"spine\" type=\"spherical\">\n    <parent link=\"rear\"/>\n    <child link=\"front\"/>\n    <origin xyz=\"0 0 {}\"/>\n    <axis xyz=\"0 0 1\"/>\n  </joint>\n",
                f(rear.length / 2.0)
            ));
        }
    }
    s.push_str(&link("front", &front, front.length / 2.0));
    // MuJoCo reads this (pyBullet ignores it): keep the root link as a body of its own.
    s.push_str("  <mujoco><compiler fusestatic=\"false\" discardvisual=\"true\"/></mujoco>\n");
    s.push_str("</robot>\n");
    s
}
