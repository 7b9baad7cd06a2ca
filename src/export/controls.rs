//! A schedule in a simulator's own joint coordinates and actuators, one row
//! per simulator time step.
//!
//! `universal`: the two hinges' angles, rates and torques are catflip's
//! `q`, `q_dot`, `tau` (hinge generalized forces), unchanged.
//!
//! `no-twist` as a ball joint: position is the relative quaternion
//! `exp(hat(v))`, `v = (q1, q2, 0)`; velocity is the relative angular velocity
//! in the front half's (child's) frame, `w = J_r(v) v_dot`; the three motors
//! (about the child's x, y, z) give the torque whose power-dual is that
//! velocity. catflip's `(tau1, tau2)` is the generalized force in rotation-vector
//! coordinates, so the motor torque is `J_r(v)^-T (tau1, tau2, tau3)` where
//! `tau3` is the constraint torque that holds the twist `v3` at zero: the ball
//! has a third degree of freedom that the Kane & Scher joint does not.
//!
//! Torques are the average over each step (zero-order hold with the exact
//! impulse), so a simulator that holds `ctrl` over a step integrates the
//! schedule's impulse without interpolation error; positions and velocities are
//! the plan at the start of each step (the PD reference).

use crate::config::Config;
use crate::design::plan::{ShapePlan, ShapeState};
use crate::model::so3::right_jacobian;
use crate::model::{Cat, Joint};
use nalgebra::{Const, U1, Vector3};
use num_dual::DualSVec64;

/// The simulators catflip writes controls for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Simulator {
    /// MuJoCo: quaternion `w x y z`, `ctrl` of the exported motors; RK4 at the MJCF time step.
    Mujoco,
    /// pyBullet: quaternion `x y z w` as `getJointStateMultiDof` returns it, `force`
    /// for `setJointMotorControlMultiDof(..., TORQUE_CONTROL)`.
    Pybullet,
}

impl Simulator {
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Mujoco => "mujoco",
            Simulator::Pybullet => "pybullet",
        }
    }

    /// Largest time step, s; the step used tiles the schedule exactly and
    /// gives at least [`MIN_STEPS`] steps ([`time_step`]). pyBullet's integrator
    /// is first order, so it gets a finer step.
    pub fn target_step(self) -> f64 {
        match self {
            Simulator::Mujoco => 5e-4,
            Simulator::Pybullet => 2.5e-4,
        }
    }

    /// `dc`: the MJCF's DC-motor actuators, whose `ctrl` is `tau + k qd` ([`super::common::dc_motor`]).
    pub fn columns(self, joint: Joint, dc: bool) -> &'static str {
        match (self, joint) {
            (Simulator::Mujoco, Joint::NoTwist) => {
                "t_s,qpos_w,qpos_x,qpos_y,qpos_z,qvel_x,qvel_y,qvel_z,ctrl_tau_x,ctrl_tau_y,ctrl_tau_z"
            }
            (Simulator::Mujoco, Joint::Universal) if dc => {
                "t_s,qpos_motor1,qpos_motor2,qvel_motor1,qvel_motor2,ctrl_cmd1,ctrl_cmd2"
            }
            (Simulator::Mujoco, Joint::Universal) => {
                "t_s,qpos_motor1,qpos_motor2,qvel_motor1,qvel_motor2,ctrl_tau1,ctrl_tau2"
            }
            (Simulator::Pybullet, Joint::NoTwist) => {
                "t_s,pos_x,pos_y,pos_z,pos_w,vel_x,vel_y,vel_z,force_x,force_y,force_z"
            }
            (Simulator::Pybullet, Joint::Universal) => {
                "t_s,pos_motor1,pos_motor2,vel_motor1,vel_motor2,force_motor1,force_motor2"
            }
        }
    }
}

/// Fewest steps per schedule. A held torque misses the schedule's shape by
/// `O(dt^2)` over the run, so short manoeuvres get a finer step (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
pub const MIN_STEPS: usize = 4000;

/// `(dt, n)`: `n` equal steps, at least [`MIN_STEPS`], of at most `target`, covering `duration`.
pub fn time_step(duration: f64, target: f64) -> (f64, usize) {
    let n = ((duration / target - 1e-9).ceil() as usize).max(MIN_STEPS);
    (duration / n as f64, n)
}

/// The no-twist constraint torque `tau3`, N m: the generalized force on the
/// twist component of the rotation vector that keeps it at zero.
///
/// From the reduced Lagrangian of the ball-jointed cat
/// ([`Cat::ball_locked_terms`], `T = 1/2 v_dot' M3(v) v_dot`):
/// `tau3 = sum_j M3_3j qdd_j + sum_jk c_3jk qd_j qd_k` at `v3 = v3_dot = v3_ddot = 0`,
/// `c_3jk = dM3_3j/dv_k - 1/2 dM3_jk/dv_3`.
pub fn twist_constraint_torque(cat: &Cat, q: [f64; 2], qd: [f64; 2], qdd: [f64; 2]) -> f64 {
    let v: [DualSVec64<3>; 3] = [
        DualSVec64::<3>::from_re(q[0]).derivative(0),
        DualSVec64::<3>::from_re(q[1]).derivative(1),
        DualSVec64::<3>::from_re(0.0).derivative(2),
    ];
    let (m, _) = cat.ball_locked_terms(v);
    let grad = |x: &DualSVec64<3>| {
        let e = x.eps.unwrap_generic(Const::<3>, U1);
        [e[0], e[1], e[2]]
    };
    let mut tau = 0.0;
    for j in 0..2 {
        tau += m[2][j].re * qdd[j];
        for k in 0..2 {
            let c = grad(&m[2][j])[k] - 0.5 * grad(&m[j][k])[2];
            tau += c * qd[j] * qd[k];
        }
    }
    tau
}

/// Ball motor torques (child frame) for catflip's torque `tau` at state `s`.
pub fn ball_torque(cat: &Cat, s: &ShapeState, tau: [f64; 2]) -> [f64; 3] {
    let tau3 = twist_constraint_torque(cat, s.q, s.qd, s.qdd);
    let jr = right_jacobian(&Vector3::new(s.q[0], s.q[1], 0.0));
    let t = Vector3::new(tau[0], tau[1], tau3);
    let b = jr
        .transpose()
        .lu()
        .solve(&t)
        .expect("J_r is invertible below a full turn");
    [b[0], b[1], b[2]]
}

/// Relative quaternion `[w, x, y, z]` and child-frame rate of the ball at `s`.
pub fn ball_state(s: &ShapeState) -> ([f64; 4], [f64; 3]) {
    let v = Vector3::new(s.q[0], s.q[1], 0.0);
    let qu = nalgebra::UnitQuaternion::from_scaled_axis(v);
    let w = right_jacobian(&v) * Vector3::new(s.qd[0], s.qd[1], 0.0);
    ([qu.w, qu.i, qu.j, qu.k], [w[0], w[1], w[2]])
}

/// Actuator torques at an instant, in the simulator's actuator order.
fn actuator_torque(cat: &Cat, plan: &dyn ShapePlan, phase: usize, t: f64) -> Vec<f64> {
    let tau = plan.torque_in(cat, phase, t);
    match cat.joint {
        Joint::Universal => tau.to_vec(),
        Joint::NoTwist => ball_torque(cat, &plan.state_in(phase, t), tau).to_vec(),
    }
}

/// Average of the actuator torques over `[t0, t1]`: 4-point Gauss-Legendre
/// on each piece between the `cuts` (the plan's phase ends and breaks,
/// sorted: a torque may jump there, at a node of a design with torque steps),
/// so a held step carries the exact impulse. `b` are the phase bounds.
fn step_average(
    cat: &Cat,
    plan: &dyn ShapePlan,
    (b, cuts): (&[f64], &[f64]),
    t0: f64,
    t1: f64,
) -> Vec<f64> {
    const X: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const W: [f64; 4] = [
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ];
    let inside = &cuts[cuts.partition_point(|&c| c <= t0)..cuts.partition_point(|&c| c < t1)];
    let ends: Vec<f64> = std::iter::once(t0)
        .chain(inside.iter().copied())
        .chain([t1])
        .collect();
    let phase = |t: f64| (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
    let mut acc: Vec<f64> = Vec::new();
    for w in ends.windows(2) {
        let (a, c) = (w[0], w[1]);
        for (x, wt) in X.iter().zip(W) {
            let t = 0.5 * (a + c) + 0.5 * (c - a) * x;
            let tau = actuator_torque(cat, plan, phase(t), t);
            acc.resize(tau.len(), 0.0);
            for (s, v) in acc.iter_mut().zip(tau) {
                *s += 0.5 * (c - a) * wt * v;
            }
        }
    }
    acc.iter().map(|s| s / (t1 - t0)).collect()
}

/// One time step of controls.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlRow {
    /// Start of the step, s.
    pub t: f64,
    /// Planned joint position at `t` (simulator coordinates).
    pub pos: Vec<f64>,
    /// Planned joint velocity at `t`.
    pub vel: Vec<f64>,
    /// Actuator torque held over `[t, t + dt]` (step average), N m; zero on
    /// the final row. With [`Controls::slope`] `k > 0` the DC motor's command
    /// `tau + k qd`, both averaged over the step.
    pub torque: Vec<f64>,
}

/// A schedule sampled at a simulator's time step.
#[derive(Debug, Clone, PartialEq)]
pub struct Controls {
    pub simulator: Simulator,
    pub joint: Joint,
    pub dt: f64,
    /// `k` of a DC-motor actuator whose command is `tau + k qd` (0: the
    /// torque columns are the torque).
    pub slope: f64,
    /// `n + 1` rows: one per step, then the final planned state.
    pub rows: Vec<ControlRow>,
}

impl Controls {
    /// Samples `plan` at the simulator's step (see [`time_step`]).
    pub fn sample(cfg: &Config, plan: &dyn ShapePlan, sim: Simulator) -> Controls {
        let cat = cfg.cat();
        let b = plan.phase_bounds();
        let (dt, n) = time_step(b[3] - b[0], sim.target_step());
        // MuJoCo's DC-motor actuators take the command tau + k qd
        let slope = match (sim, super::common::dc_motor(cfg)) {
            (Simulator::Mujoco, Some(_)) => cfg.motor().slope(),
            _ => 0.0,
        };
        let phase_of = |t: f64| (0..3).find(|&i| t <= b[i + 1]).unwrap_or(2);
        let mut cuts: Vec<f64> = b.iter().copied().chain(plan.breaks()).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let rows = (0..=n)
            .map(|k| {
                let t = if k == n { b[3] } else { b[0] + k as f64 * dt };
                let s = if k == n {
                    plan.state_in(2, t)
                } else {
                    plan.state(t)
                };
                let (pos, vel) = match cat.joint {
                    Joint::Universal => (s.q.to_vec(), s.qd.to_vec()),
                    Joint::NoTwist => {
                        let (p, w) = ball_state(&s);
                        let p = match sim {
                            Simulator::Mujoco => p.to_vec(),
                            Simulator::Pybullet => vec![p[1], p[2], p[3], p[0]],
                        };
                        (p, w.to_vec())
                    }
                };
                let torque = if k == n {
                    vec![0.0; vel.len()]
                } else {
                    let t1 = (t + dt).min(b[3]);
                    let mut u = step_average(&cat, plan, (&b, &cuts), t, t1);
                    if slope > 0.0 {
                        // the DC motor's command: + k times the step's mean speed
                        let (q0, q1) = (s.q, plan.state_in(phase_of(t1), t1).q);
                        for j in 0..2 {
                            u[j] += slope * (q1[j] - q0[j]) / (t1 - t);
                        }
                    }
                    u
                };
                ControlRow {
                    t,
                    pos,
                    vel,
                    torque,
                }
            })
            .collect();
        Controls {
            simulator: sim,
            joint: cat.joint,
            dt,
            slope,
            rows,
        }
    }

    /// CSV with a `#` header that states the time step, the hold, the PD gains
    /// and the motor envelope catflip's own simulation clips to
    /// (`|tau + k qd| <= T` per motor or as a disc, `k` = `motor_slope_nm_s`).
    pub fn to_csv(&self, cfg: &Config, method: &str) -> String {
        let ctrl = crate::verify::simulate::Controller::from_spec(&cfg.design_spec());
        let n = self.rows.len() - 1;
        let mut s = format!(
            "# catflip controls for {sim}: config {name}, method {method}, {joint} joint\n\
             # One row per time step: position and velocity are the planned joint state at t_s\n\
             # (the PD reference); the torque is the schedule's average over [t_s, t_s + dt_s],\n\
             # to be held for the step (zero-order hold, exact impulse). The last row is the final\n\
             # planned state (torque 0). Units: s, rad, rad/s, N m.\n{joint_note}\
             # dt_s = {dt:.15e}\n# steps = {n}\n# pd_kp = {kp:.15e}\n# pd_kd = {kd:.15e}\n\
             # max_torque_nm = {lim}\n# motor_slope_nm_s = {slope:.15e}\n# peak_norm = {norm}\n{start}{cols}\n",
            start = super::start::header_lines(
                cfg,
                match self.simulator {
                    Simulator::Mujoco => super::start::BaseConvention::RearFrameWxyz,
                    Simulator::Pybullet => super::start::BaseConvention::WorldXyzw,
                },
            ),
            sim = self.simulator.name(),
            name = cfg.name,
            joint = self.joint.name(),
            joint_note = match self.joint {
                Joint::NoTwist =>
                    "# Ball joint: quaternion of the front half relative to the rear, velocity and torque\n\
                     # in the front half's frame; torque = J_r(v)^-T (tau1, tau2, tau3), tau3 holding the twist.\n",
                Joint::Universal if self.slope > 0.0 =>
                    "# Hinges motor1 (rear x) and motor2 (rotated y): catflip's q, q_dot. ctrl_cmd is the DC\n\
                     # motors' command tau + k q_dot (k = motor_slope_nm_s, both averaged over the step): the\n\
                     # MJCF's actuators give force = clamp(ctrl, -T, T) - k q_dot, catflip's motor model.\n",
                Joint::Universal =>
                    "# Hinges motor1 (rear x) and motor2 (rotated y): catflip's q, q_dot, tau.\n",
            },
            dt = self.dt,
            kp = ctrl.kp,
            kd = ctrl.kd,
            lim = ctrl
                .motor
                .max_torque
                .map(|l| format!("{l}"))
                .unwrap_or_else(|| "none".into()),
            slope = ctrl.motor.slope(),
            norm = match ctrl.motor.norm {
                crate::model::TorqueNorm::Euclidean => "euclidean",
                crate::model::TorqueNorm::PerMotor => "per-motor",
            },
            cols = self.simulator.columns(self.joint, self.slope > 0.0),
        );
        for r in &self.rows {
            s.push_str(&format!("{:.12}", r.t));
            for x in r.pos.iter().chain(&r.vel).chain(&r.torque) {
                s.push_str(&format!(",{x:.15e}"));
            }
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::plan::Phase;
    use crate::model::dynamics::inverse_dynamics;
    use crate::model::small::{add3, cross, mat_mul, mat_vec, scale3, transpose};
    use crate::model::{Half, InertiaFormula};
    use num_dual::Dual2_64;

    fn cat(joint: Joint) -> Cat {
        Cat::symmetric(
            Half {
                mass: 1.3,
                length: 0.8,
                radius: 0.12,
                inertia: InertiaFormula::SolidCylinder,
            },
            joint,
        )
    }

    /// A heavier, shorter, thicker rear half.
    fn unequal(joint: Joint) -> Cat {
        let mut c = cat(joint);
        c.rear = Half {
            mass: 2.5,
            length: 0.6,
            radius: 0.15,
            inertia: InertiaFormula::SolidCylinder,
        };
        c
    }

    fn state(q: [f64; 2], qd: [f64; 2], qdd: [f64; 2]) -> ShapeState {
        ShapeState {
            q,
            qd,
            qdd,
            phase: Phase::Twist,
        }
    }

    /// Newton-Euler on the front half B: the torque the joint applies to B,
    /// in B's frame, from B's accelerations alone (instant where A's frame is the
    /// world frame, free fall about the fixed common centre of mass).
    fn joint_torque_on_front(cat: &Cat, q: [f64; 2], qd: [f64; 2], qdd: [f64; 2]) -> [f64; 3] {
        type D = Dual2_64;
        let qe = [D::new(q[0], qd[0], qdd[0]), D::new(q[1], qd[1], qdd[1])];
        let qde = [D::new(qd[0], qdd[0], 0.0), D::new(qd[1], qdd[1], 0.0)];
        let rel = cat.rel_rotation(qe);
        let (s, d) = cat.offsets(&rel);
        let (_, a) = cat.locked_terms(qe);
        let sj = cat.rel_rate_jacobian(qe);
        let wa: [D; 3] = std::array::from_fn(|r| -(a[0][r] * qde[0] + a[1][r] * qde[1]));
        let wr: [D; 3] = std::array::from_fn(|r| sj[0][r] * qde[0] + sj[1][r] * qde[1]);
        let re = |x: &[D; 3]| x.map(|v| v.re);
        let d1 = |x: &[D; 3]| x.map(|v| v.v1);
        let d2 = |x: &[D; 3]| x.map(|v| v.v2);
        let (w, wd) = (re(&wa), d1(&wa));
        // B's centre of mass sits at m_A/(m_A + m_B) d from the common one; world
        // acceleration of an A-frame point x: w x (w x x) + wd x x + 2 w x x' + x''.
        let share = cat.rear.mass / cat.mass();
        let (x, xd, xdd) = (
            scale3(share, re(&d)),
            scale3(share, d1(&d)),
            scale3(share, d2(&d)),
        );
        let acc = add3(
            add3(cross(w, cross(w, x)), cross(wd, x)),
            add3(scale3(2.0, cross(w, xd)), xdd),
        );
        let force = scale3(cat.front.mass, acc);
        let wb = add3(w, re(&wr));
        let wbd = add3(wd, add3(cross(w, re(&wr)), d1(&wr)));
        let r = rel.map(|row| row.map(|v| v.re));
        let ib = mat_mul(
            &mat_mul(&r, &Cat::body_inertia::<f64>(&cat.halves().front)),
            &transpose(&r),
        );
        // I wd + w x I w = torque + (joint - B) x F, joint - B = -s
        let euler = add3(mat_vec(&ib, wbd), cross(wb, mat_vec(&ib, wb)));
        let tj = add3(euler, cross(re(&s), force));
        mat_vec(&transpose(&r), tj)
    }

    #[test]
    fn ball_torque_matches_newton_euler_on_the_front_half() {
        for c in [cat(Joint::NoTwist), unequal(Joint::NoTwist)] {
            for (q, qd, qdd) in [
                ([0.8, -0.5], [1.5, 2.2], [-3.0, 4.0]),
                ([0.02, 0.01], [0.3, -0.7], [5.0, 1.0]),
                ([-1.9, 1.2], [-2.5, 0.4], [0.5, -6.0]),
            ] {
                let tau = inverse_dynamics(&c, q, qd, qdd);
                let lagrange = ball_torque(&c, &state(q, qd, qdd), tau);
                let newton = joint_torque_on_front(&c, q, qd, qdd);
                for i in 0..3 {
                    assert!(
                        (lagrange[i] - newton[i]).abs() < 1e-10 * (1.0 + newton[i].abs()),
                        "{q:?}: {lagrange:?} vs {newton:?}"
                    );
                }
            }
        }
        // Unequal halves need a torque to hold the twist at zero.
        let (q, qd, qdd) = ([0.8, -0.5], [1.5, 2.2], [-3.0, 4.0]);
        assert!(twist_constraint_torque(&unequal(Joint::NoTwist), q, qd, qdd).abs() > 1e-3);
        let c = cat(Joint::NoTwist);
        // Identical halves: the twist needs no holding torque (the swap symmetry of
        // the halves), yet the ball's third motor carries a real share of the
        // bend torque through J_r^-T.
        assert!(twist_constraint_torque(&c, q, qd, qdd).abs() < 1e-14);
        let tb = ball_torque(&c, &state(q, qd, qdd), inverse_dynamics(&c, q, qd, qdd));
        assert!(tb[2].abs() > 0.05 * tb[0].hypot(tb[1]), "{tb:?}");
    }

    #[test]
    fn ball_power_equals_generalized_power() {
        let c = cat(Joint::NoTwist);
        let (q, qd, qdd) = ([0.9, 0.4], [-2.0, 3.0], [1.0, 2.0]);
        let s = state(q, qd, qdd);
        let tau = inverse_dynamics(&c, q, qd, qdd);
        let tb = ball_torque(&c, &s, tau);
        let (_, w) = ball_state(&s);
        let p_ball: f64 = (0..3).map(|i| tb[i] * w[i]).sum();
        let p_gen = tau[0] * qd[0] + tau[1] * qd[1];
        assert!((p_ball - p_gen).abs() < 1e-12 * p_gen.abs().max(1.0));
    }

    #[test]
    fn ball_mass_matrix_extends_the_no_twist_one() {
        let c = cat(Joint::NoTwist);
        let q = [0.7, -1.1];
        let (m3, a3) = c.ball_locked_terms::<f64>([q[0], q[1], 0.0]);
        let (m2, a2) = c.locked_terms(q);
        for i in 0..2 {
            for j in 0..2 {
                assert!((m3[i][j] - m2[i][j]).abs() < 1e-14);
            }
            for r in 0..3 {
                assert!((a3[i][r] - a2[i][r]).abs() < 1e-14);
            }
        }
        // twisting the straightened halves against each other: both axial inertias
        // about their common axis, halved (reduced pair), at the straight cat
        let (m0, _) = c.ball_locked_terms::<f64>([0.0; 3]);
        // (identical halves: the reduced pair's axial inertia, I_a / 2)
        assert!((m0[2][2] - c.i_a() / 2.0).abs() < 1e-15, "{m0:?}");
        assert!(m3[2][2] > 0.0);
    }

    #[test]
    fn steps_tile_the_duration() {
        let (dt, n) = time_step(2.4278, 5e-4);
        assert_eq!(n, 4856);
        assert!((dt * n as f64 - 2.4278).abs() < 1e-12 && dt <= 5e-4);
        let (dt, n) = time_step(3.0, 5e-4);
        assert_eq!(n, 6000);
        assert!((dt - 5e-4).abs() < 1e-15);
        let (dt, n) = time_step(0.5, 5e-4);
        assert_eq!(n, MIN_STEPS);
        assert!((dt - 0.5 / MIN_STEPS as f64).abs() < 1e-18);
    }
}
