//! The configured start in a simulator's world (MODEL.md section 6).
//!
//! catflip's world has the reference spine along `z` and "up" along `+x`; the
//! simulators' worlds have gravity along `-z`. The map `W` sends catflip's
//! `x` (up) to the simulator's `z`, its `z` (the reference spine) to the
//! simulator's `x` (the spine horizontal, as before) and its `y` to `-y`
//! (a rotation: half a turn about `(1, 0, 1) / sqrt 2`). The rear half's
//! attitude in the simulator is `W R0`.

use crate::config::Config;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// `W`: catflip's world to the simulators' (gravity along `-z`).
pub fn world_map() -> UnitQuaternion<f64> {
    let w = Matrix3::new(0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(w))
}

/// The rear half (A, the free body) at release, in a simulator's world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseStart {
    /// `W R0`, `[w, x, y, z]`.
    pub quat: [f64; 4],
    /// Velocity of A's centre of mass, world, m/s (the cat's common centre of
    /// mass starts at rest; A's circles it).
    pub linear_velocity: [f64; 3],
    /// A's angular velocity in the simulator's world, rad/s.
    pub angular_velocity_world: [f64; 3],
    /// The same in A's own frame (MuJoCo's free-joint `qvel`).
    pub angular_velocity_body: [f64; 3],
}

/// The configured start as the simulators take it.
pub fn base_start(cfg: &Config) -> BaseStart {
    let cat = cfg.cat();
    let s = cfg.start.start();
    let r = world_map() * s.rotation();
    let w = Vector3::from(s.body_rate);
    // A's centre of mass from the common one: -(m_B / m) d, with d from A's
    // to B's centre of mass in the straight cat; the free joint moves A's
    // frame origin, c_A from that centre (general halves, docs/model.md 3a)
    let h = cat.halves();
    let v3 = |a: [f64; 3]| Vector3::from(a);
    let d = v3(h.rear.com_to_joint()) - v3(h.front.com_to_joint());
    let r_a = d * (-h.front.mass / cat.mass()) - v3(h.rear.com);
    let v = r * w.cross(&r_a);
    let ww = r * w;
    BaseStart {
        quat: [r.w, r.i, r.j, r.k],
        linear_velocity: [v.x, v.y, v.z],
        angular_velocity_world: [ww.x, ww.y, ww.z],
        angular_velocity_body: s.body_rate,
    }
}

/// `# key = a b c` header lines of the controls: the start in catflip's world and
/// in the simulator's, and the landing margin (the replays continue for it).
pub fn header_lines(cfg: &Config, sim: super::controls::Simulator) -> String {
    let s = cfg.start.start();
    let b = base_start(cfg);
    let j = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.15e}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let (quat, ang, frame) = match sim {
        super::controls::Simulator::Mujoco => {
            (b.quat.to_vec(), b.angular_velocity_body, "rear frame")
        }
        super::controls::Simulator::Pybullet => (
            vec![b.quat[1], b.quat[2], b.quat[3], b.quat[0]],
            b.angular_velocity_world,
            "world",
        ),
    };
    format!(
        "# Start (docs/model.md section 8): catflip's world has x up and z the reference spine; the\n\
         # simulator's base (the rear half) starts at W R0 (W: catflip x -> z, z -> x, y -> -y),\n\
         # rotating rigidly, the shape straight; angular velocity in the {frame}.\n\
         # start_attitude_wxyz = {}\n# start_body_rate_rad_s = {}\n\
         # start_base_quat = {}\n# start_base_linear_velocity = {}\n\
         # start_base_angular_velocity = {}\n# margin_s = {:.15e}\n",
        j(&s.attitude),
        j(&s.body_rate),
        j(&quat),
        j(&b.linear_velocity),
        j(&ang),
        cfg.fall.margin,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The simulators' release state carries catflip's momentum: the common
    /// centre of mass at rest, the angular momentum `W L`, the belly up in the
    /// reference pose.
    #[test]
    fn base_start_carries_the_momentum_and_the_attitude() {
        let text = "name = \"s\"\n[cat]\nmass = 1.0\nlength = 1.0\nradius = 0.1\n[cat.front]\nmass = 1.7\nlength = 0.6\n[fall]\nheight = 10.0\n";
        let sets = [
            "start.angular_velocity=[0.2, -0.5, 0.7]".to_string(),
            "start.rotation_deg=[10, 30, -20]".to_string(),
        ];
        let cfg = Config::from_toml(text, "t", &sets).unwrap();
        let cat = cfg.cat();
        let b = base_start(&cfg);
        let r = crate::model::so3::quat_from(&b.quat);
        let w = Vector3::from(b.angular_velocity_world);
        assert!((r * Vector3::from(b.angular_velocity_body) - w).norm() < 1e-15);
        let d = 0.5 * (cat.rear.length + cat.front.length);
        let (ma, mb) = (cat.rear.mass, cat.front.mass);
        let ra = r * Vector3::new(0.0, 0.0, -mb / (ma + mb) * d);
        let rb = r * Vector3::new(0.0, 0.0, ma / (ma + mb) * d);
        let va = Vector3::from(b.linear_velocity);
        let vb = va + w.cross(&(rb - ra));
        assert!((ma * va + mb * vb).norm() < 1e-15);
        // angular momentum about the common centre of mass
        let inertia = |h: &crate::model::Half| {
            r.to_rotation_matrix().matrix()
                * Matrix3::from_diagonal(&Vector3::new(h.i_t(), h.i_t(), h.i_a()))
                * r.to_rotation_matrix().matrix().transpose()
        };
        let l = inertia(&cat.rear) * w
            + inertia(&cat.front) * w
            + ma * ra.cross(&va)
            + mb * rb.cross(&vb);
        let want = world_map() * Vector3::from(cfg.start.start().momentum(&cat));
        assert!((l - want).norm() < 1e-14, "{l} {want}");
        // reference pose: belly (x) up, spine (z) along the simulator's x
        let wm = world_map();
        assert!((wm * Vector3::x() - Vector3::z()).norm() < 1e-15);
        assert!((wm * Vector3::z() - Vector3::x()).norm() < 1e-15);
    }
}
