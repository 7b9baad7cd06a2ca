//! The cat as a URDF for pyBullet (the seed's simulator); the universal one
//! also loads in MuJoCo.

use super::common::{Shape, f, shapes, speed_limit, torque_limit, v3};
use crate::config::Config;
use crate::model::Joint;

/// Mass and inertia of the universal joint's `cross` link (massless in the
/// model) as fractions of a half's mass and axial inertia: simulators refuse
/// (MuJoCo) or replace with 1 kg (pyBullet) a moving link without mass. The
/// effect on the flip is linear in the fraction, so a fraction this small
/// leaves the URDF and the cross-less MJCF flipping alike
/// (examples/replay_mujoco.py prints the difference; measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
pub const CROSS_FRACTION: f64 = 1e-8;

/// Speed limit written for joints when the config has none, rad/s (URDF needs one).
const NO_SPEED_LIMIT: f64 = 1e3;
/// Effort written when the config has no torque limit, N m.
const NO_TORQUE_LIMIT: f64 = 1e3;

fn inertial(m: f64, com: [f64; 3], i: &[[f64; 3]; 3]) -> String {
    format!(
        "    <inertial>\n      <origin xyz=\"{c}\" rpy=\"0 0 0\"/>\n      <mass value=\"{m}\"/>\n      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n    </inertial>\n",
        f(i[0][0]),
        f(i[0][1]),
        f(i[0][2]),
        f(i[1][1]),
        f(i[1][2]),
        f(i[2][2]),
        c = v3(com),
        m = f(m),
    )
}

/// One half's link, its frame's origin at `origin` (a point of the half's frame).
fn link(name: &str, shape: &Shape, origin: [f64; 3]) -> String {
    let r = &shape.rigid;
    let com = std::array::from_fn(|k| r.com[k] - origin[k]);
    let geometry = match shape.cylinder {
        Some(h) => format!(
            "<origin xyz=\"{c}\"/><geometry><cylinder radius=\"{r}\" length=\"{l}\"/></geometry>",
            c = v3(com),
            r = f(h.radius),
            l = f(h.length)
        ),
        None => {
            let (edges, rpy) = shape.inertia_box();
            format!(
                "<origin xyz=\"{c}\" rpy=\"{rpy}\"/><geometry><box size=\"{e}\"/></geometry>",
                c = v3(com),
                rpy = v3(rpy),
                e = v3(edges)
            )
        }
    };
    format!(
        "  <link name=\"{name}\">\n{}    <visual>{geometry}</visual>\n    <collision>{geometry}</collision>\n  </link>\n",
        inertial(r.mass, com, &r.inertia)
    )
}

fn revolute(
    name: &str,
    parent: &str,
    child: &str,
    at: [f64; 3],
    axis: [f64; 3],
    (effort, speed): (f64, f64),
) -> String {
    format!(
        "  <joint name=\"{name}\" type=\"revolute\">\n    <parent link=\"{parent}\"/>\n    <child link=\"{child}\"/>\n    <origin xyz=\"{at}\"/>\n    <axis xyz=\"{axis}\"/>\n    <limit lower=\"{lo}\" upper=\"{hi}\" effort=\"{effort}\" velocity=\"{v}\"/>\n  </joint>\n",
        at = v3(at),
        axis = v3(axis),
        lo = f(-std::f64::consts::PI),
        hi = f(std::f64::consts::PI),
        effort = f(effort),
        v = f(speed),
    )
}

/// URDF text of the cat of `cfg`.
pub fn urdf(cfg: &Config) -> String {
    let [rear, front] = shapes(cfg);
    let joint = rear.rigid.joint;
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
    s.push_str(&link("rear", &rear, [0.0; 3]));
    match cfg.cat.joint {
        Joint::Universal => {
            let (m, i) = (
                CROSS_FRACTION * rear.rigid.mass,
                CROSS_FRACTION * rear.rigid.inertia[2][2],
            );
            s.push_str(&format!(
                "  <!-- the universal joint's cross: massless in the model; a negligible mass and inertia ({CROSS_FRACTION:e}\n       of a half's mass and axial inertia) because simulators need every moving link massive -->\n  <link name=\"cross\">\n{}  </link>\n",
                inertial(m, [0.0; 3], &[[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]])
            ));
            s.push_str(&revolute(
                "motor1",
                "rear",
                "cross",
                joint,
                rear.rigid.axis,
                limits,
            ));
            s.push_str(&revolute(
                "motor2",
                "cross",
                "front",
                [0.0; 3],
                front.rigid.axis,
                limits,
            ));
        }
        Joint::NoTwist => {
            s.push_str(&format!(
                "  <!-- Kane & Scher no-twist joint: relative rotation exp(hat(q1, q2, 0)). type=\"spherical\" is a\n       pyBullet extension (3 DoF, torque in the front link's frame, see *.pybullet.csv) -->\n  <joint name=\"spine\" type=\"spherical\">\n    <parent link=\"rear\"/>\n    <child link=\"front\"/>\n    <origin xyz=\"{}\"/>\n    <axis xyz=\"0 0 1\"/>\n  </joint>\n",
                v3(joint)
            ));
        }
    }
    // the front link's frame: parallel to the rear's, its origin at the joint
    s.push_str(&link("front", &front, front.rigid.joint));
    // MuJoCo reads this (pyBullet ignores it): keep the root link as a body of its own.
    s.push_str("  <mujoco><compiler fusestatic=\"false\" discardvisual=\"true\"/></mujoco>\n");
    s.push_str("</robot>\n");
    s
}
