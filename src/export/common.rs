//! What every export shares: the halves, the motors' limits as the model
//! files state them, and the numbers' text. The model writers and the
//! controls depend on this module, never on one another's internals.

use crate::config::Config;
pub(crate) use crate::model::Half;
use crate::model::Joint;

/// The rear (A) and front (B) halves, from the one place that knows them
/// (each half's mass, length, radius and inertia: [`Half`]).
pub fn halves(cfg: &Config) -> [Half; 2] {
    let cat = cfg.cat();
    [cat.rear, cat.front]
}

/// Largest joint torque the exports allow, N m (the config's stall torque).
pub(crate) fn torque_limit(cfg: &Config) -> Option<f64> {
    cfg.limits.max_torque
}

/// Joint speed limit for the model files, rad/s: the config's hard limit, else
/// the motor's no-load speed (it cannot drive faster), else none.
pub(crate) fn speed_limit(cfg: &Config) -> Option<f64> {
    cfg.limits.max_speed.or(cfg.limits.no_load_speed)
}

/// One half as the model files write it: the rigid body, and its cylinder
/// when the config gives cylinders (drawn as such; else the inertia box).
pub struct Shape {
    pub rigid: crate::model::Rigid,
    pub cylinder: Option<Half>,
}

impl Shape {
    /// The inertia-equivalent box: edges (m) and the roll-pitch-yaw of its
    /// principal axes in the half's frame.
    pub fn inertia_box(&self) -> ([f64; 3], [f64; 3]) {
        let (_, axes) = self.rigid.principal();
        let mut r = axes;
        if r.determinant() < 0.0 {
            r.column_mut(2).neg_mut();
        }
        let rot = nalgebra::Rotation3::from_matrix_unchecked(r);
        let (roll, pitch, yaw) = rot.euler_angles();
        (self.rigid.box_edges(), [roll, pitch, yaw])
    }
}

/// Both halves as [`Shape`]s.
pub fn shapes(cfg: &Config) -> [Shape; 2] {
    let cat = cfg.cat();
    let h = cat.halves();
    let cyl = |c: Half| cat.general.is_none().then_some(c);
    [
        Shape {
            rigid: h.rear,
            cylinder: cyl(cat.rear),
        },
        Shape {
            rigid: h.front,
            cylinder: cyl(cat.front),
        },
    ]
}

/// A vector as a model file writes it: `x y z`.
pub(crate) fn v3(v: [f64; 3]) -> String {
    format!("{} {} {}", f(v[0]), f(v[1]), f(v[2]))
}

/// Numbers in model files: the shortest text that reads back to the same f64.
pub(crate) fn f(x: f64) -> String {
    format!("{x}")
}

/// Attributes of a hinge's `<general>` actuator that is the linear DC motor
/// `|tau + k qd| <= T` (universal joint with a torque-speed line): gain 1,
/// affine bias `-k qd`, `ctrl` (the voltage in N m, `tau + k qd`) limited to
/// `[-T, T]`. MuJoCo recomputes the bias at each RK4 stage, so a saturated
/// motor follows `T - k qd` continuously as catflip's simulation does.
/// `None` without a torque-speed line (a plain `<motor>` then says it all).
pub(crate) fn dc_motor(cfg: &Config) -> Option<String> {
    let m = cfg.motor();
    let t = m.max_torque?;
    if m.slope() == 0.0 || cfg.cat.joint != Joint::Universal {
        return None;
    }
    Some(format!(
        " gaintype=\"fixed\" gainprm=\"1\" biastype=\"affine\" biasprm=\"0 0 {nk}\" ctrllimited=\"true\" ctrlrange=\"{a} {b}\"",
        nk = f(-m.slope()),
        a = f(-t),
        b = f(t)
    ))
}
