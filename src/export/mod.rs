//! The cat as a URDF (pyBullet, as the seed used) and as an MJCF (MuJoCo),
//! with the model's masses and inertias, so that a schedule can be replayed
//! in those simulators.
//!
//! Frames follow MODEL.md: the rear half A's frame sits at its centre of mass
//! with `z` towards the joint at `(0, 0, l/2)`; the front half B's centre of
//! mass is `l/2` beyond the joint along its own `z`. `universal`: motor 1
//! about A's `x`, then motor 2 about the rotated `y` (`R = Rx(q1) Ry(q2)`).
//! `no-twist`: the Kane & Scher joint is a ball joint whose relative rotation
//! is `exp(hat(q1, q2, 0))`; both formats carry it as a ball / spherical joint.

use crate::config::Config;
use crate::model::Joint;

fn f(x: f64) -> String {
    format!("{x:.9}")
}

/// URDF text of the cat of `cfg`.
pub fn urdf(cfg: &Config) -> String {
    let cat = cfg.cat();
    let h = cat.rear.half_length();
    let link = |name: &str, z: f64, half: &crate::model::Half| {
        let (m, l, r, it, ia) = (half.mass, half.length, half.radius, half.i_t(), half.i_a());
        format!(
            r#"  <link name="{name}">
    <inertial>
      <origin xyz="0 0 {z}" rpy="0 0 0"/>
      <mass value="{m}"/>
      <inertia ixx="{it}" ixy="0" ixz="0" iyy="{it}" iyz="0" izz="{ia}"/>
    </inertial>
    <visual><origin xyz="0 0 {z}"/><geometry><cylinder radius="{r}" length="{l}"/></geometry></visual>
    <collision><origin xyz="0 0 {z}"/><geometry><cylinder radius="{r}" length="{l}"/></geometry></collision>
  </link>
"#,
            z = f(z),
            m = f(m),
            it = f(it),
            ia = f(ia),
            r = f(r),
            l = f(l)
        )
    };
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<!-- catflip: {} ({} joint). Masses and inertias as in the model (MODEL.md); angles in rad, torques in N m. -->\n<robot name=\"{}\">\n",
        cfg.name,
        cat.joint.name(),
        cfg.name
    );
    s.push_str(&link("rear", 0.0, &cat.rear));
    match cat.joint {
        Joint::Universal => {
            s.push_str("  <link name=\"cross\"/>\n");
            s.push_str(&format!(
                "  <joint name=\"motor1\" type=\"revolute\">\n    <parent link=\"rear\"/>\n    <child link=\"cross\"/>\n    <origin xyz=\"0 0 {}\"/>\n    <axis xyz=\"1 0 0\"/>\n    <limit lower=\"-3.14159\" upper=\"3.14159\" effort=\"{}\" velocity=\"100\"/>\n  </joint>\n",
                f(h),
                f(cfg.limits.max_torque.unwrap_or(1e3))
            ));
            s.push_str(&format!(
                "  <joint name=\"motor2\" type=\"revolute\">\n    <parent link=\"cross\"/>\n    <child link=\"front\"/>\n    <origin xyz=\"0 0 0\"/>\n    <axis xyz=\"0 1 0\"/>\n    <limit lower=\"-3.14159\" upper=\"3.14159\" effort=\"{}\" velocity=\"100\"/>\n  </joint>\n",
                f(cfg.limits.max_torque.unwrap_or(1e3))
            ));
        }
        Joint::NoTwist => {
            s.push_str(&format!(
                "  <!-- Kane & Scher no-twist joint: relative rotation exp(hat(q1, q2, 0)) -->\n  <joint name=\"spine\" type=\"spherical\">\n    <parent link=\"rear\"/>\n    <child link=\"front\"/>\n    <origin xyz=\"0 0 {}\"/>\n  </joint>\n",
                f(h)
            ));
        }
    }
    s.push_str(&link("front", cat.front.half_length(), &cat.front));
    s.push_str("</robot>\n");
    s
}

/// MJCF (MuJoCo) text of the cat of `cfg`, dropped from the config's height.
pub fn mjcf(cfg: &Config) -> String {
    let cat = cfg.cat();
    let (a, b) = (&cat.rear, &cat.front);
    let joints = match cat.joint {
        Joint::Universal => "        <joint name=\"motor1\" type=\"hinge\" axis=\"1 0 0\"/>\n        <joint name=\"motor2\" type=\"hinge\" axis=\"0 1 0\"/>\n".to_string(),
        Joint::NoTwist => "        <!-- Kane & Scher no-twist joint: relative rotation exp(hat(q1, q2, 0)) -->\n        <joint name=\"spine\" type=\"ball\"/>\n".to_string(),
    };
    let actuators = match cat.joint {
        Joint::Universal => {
            "    <motor name=\"tau1\" joint=\"motor1\" gear=\"1\"/>\n    <motor name=\"tau2\" joint=\"motor2\" gear=\"1\"/>\n"
        }
        Joint::NoTwist => {
            "    <motor name=\"tau_x\" joint=\"spine\" gear=\"1 0 0 0 0 0\"/>\n    <motor name=\"tau_y\" joint=\"spine\" gear=\"0 1 0 0 0 0\"/>\n"
        }
    };
    format!(
        r#"<!-- catflip: {name} ({joint} joint). Masses and inertias as in the model (MODEL.md). -->
<mujoco model="{name}">
  <option gravity="0 0 -{g}" timestep="0.0005" integrator="RK4"/>
  <worldbody>
    <!-- spine (the rear half's z axis) horizontal along world x; rotate about it to set the initial roll -->
    <body name="rear" pos="0 0 {height}" euler="0 90 0">
      <freejoint name="fall"/>
      <inertial pos="0 0 0" mass="{ma}" diaginertia="{ita} {ita} {iaa}"/>
      <geom type="cylinder" size="{ra} {ha}" mass="0"/>
      <body name="front" pos="0 0 {ha}">
{joints}        <inertial pos="0 0 {hb}" mass="{mb}" diaginertia="{itb} {itb} {iab}"/>
        <geom type="cylinder" size="{rb} {hb}" pos="0 0 {hb}" mass="0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
{actuators}  </actuator>
</mujoco>
"#,
        name = cfg.name,
        joint = cat.joint.name(),
        g = f(cfg.fall.gravity),
        height = f(cfg.fall.height),
        ma = f(a.mass),
        ita = f(a.i_t()),
        iaa = f(a.i_a()),
        ra = f(a.radius),
        ha = f(a.half_length()),
        mb = f(b.mass),
        itb = f(b.i_t()),
        iab = f(b.i_a()),
        rb = f(b.radius),
        hb = f(b.half_length()),
    )
}
