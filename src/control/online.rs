//! The study's controllers for a simulation loop catflip does not run
//! (MuJoCo, pyBullet, a robot): the same commands as [`super::closed_loop`]
//! computes inside its own flights, from a measurement handed in, with the
//! state in the simulators' world (the `<stem>.tvlqr.csv` convention).
//!
//! The TVLQR predicts over its delay under the corrections it already sent,
//! so the controller remembers them: a command at control step `k` drops
//! the history from `k` on (a command at step 0 starts a new flight).

use super::closed_loop::pd_command;
pub use super::closed_loop::{SimState, from_sim, to_sim};
use super::plant::{Y, momentum_from_rates};
use super::reference::Reference;
use super::replanning::{InFlight, Record, Replanning, SharedPlan};
use super::tvlqr::Tvlqr;
use super::tvlqr::tvlqr_command;
use crate::config::Config;
use crate::model::motor::Motor;
use crate::verify::simulate::Controller;

/// Which controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Today's joint PD on the planned shape, every simulator step (the study's `open-loop`).
    OpenLoop,
    /// The time-varying LQR at `control.rate_hz`, predicting over `control.delay_ms`.
    Tvlqr,
    /// The TVLQR about a plan solved again in flight ([`super::replanning`]).
    Replan,
}

impl Kind {
    /// The study's name of the controller.
    pub fn name(self) -> &'static str {
        match self {
            Kind::OpenLoop => "open-loop",
            Kind::Tvlqr => "tvlqr",
            Kind::Replan => "replan",
        }
    }
}

/// One controller along one design.
#[derive(Clone)]
pub struct Online {
    pub kind: Kind,
    /// The plan in use (replanning changes it in flight).
    pub reference: Reference,
    /// The design's, what a new flight starts on.
    pub design: Reference,
    /// The open loop's ([`Reference::unheld`]: the design's feed-forward
    /// without the holding torque, to which the open loop adds its PD).
    pub open_loop: Reference,
    pub tvlqr: Tvlqr,
    pub motor: Motor,
    /// Today's PD gains (the open loop's).
    pub pd: Controller,
    /// How the replanning controller replans (its budget: None unless set).
    pub replanning: Replanning,
    in_flight: InFlight,
    /// Corrections sent, by control step.
    issued: Vec<[f64; 2]>,
}

/// Whether a design can be flown under `cfg`: its manoeuvre must end within
/// the fall (a shorter one holds the straight shape to touchdown); a longer
/// one, made for a higher drop, would land wherever the ground cuts it off.
pub fn check_fits(cfg: &Config, plan: &dyn crate::design::plan::ShapePlan) -> crate::Result<()> {
    let spec = cfg.design_spec();
    let (t, available) = (plan.duration(), spec.available_time());
    if t > available * (1.0 + crate::verdict::tolerance::HEIGHT) {
        let least = crate::design::envelope::height_for(&spec, t);
        return Err(crate::Error::Usage(format!(
            "the design's manoeuvre lasts {t:.4} s, but the fall from {} m leaves {available:.4} s for it (the fall time minus fall.margin): fly it with a config whose fall.height is at least {:.3} m",
            cfg.fall.height,
            (least * 1e3).ceil() / 1e3
        )));
    }
    Ok(())
}

impl Online {
    pub fn new(cfg: &Config, plan: SharedPlan, kind: Kind) -> crate::Result<Online> {
        let design = Reference::checked(cfg, plan.as_ref())?;
        let tvlqr = Tvlqr::new(&design, &cfg.control);
        let open_loop = design.for_open_loop(cfg, plan.as_ref());
        Ok(Online {
            kind,
            reference: if kind == Kind::OpenLoop {
                open_loop.clone()
            } else {
                design.clone()
            },
            design,
            open_loop,
            tvlqr,
            motor: cfg.motor(),
            pd: Controller::from_spec(&cfg.design_spec()),
            in_flight: InFlight::new(plan.clone()),
            replanning: Replanning::new(cfg, plan),
            issued: Vec::new(),
        })
    }

    /// The replans of the flight so far.
    pub fn replans(&self) -> &[Record] {
        &self.in_flight.records
    }

    /// Simulator steps between two commands.
    pub fn period_steps(&self) -> usize {
        match self.kind {
            Kind::OpenLoop => 1,
            Kind::Tvlqr | Kind::Replan => self.tvlqr.period_steps,
        }
    }

    /// The delay the controller predicts over, simulator steps (the PD: none).
    pub fn delay_steps(&self) -> usize {
        match self.kind {
            Kind::OpenLoop => 0,
            Kind::Tvlqr | Kind::Replan => self.tvlqr.delay_steps,
        }
    }

    /// Number of control steps with a command of their own (the TVLQR's last
    /// correction acts until touchdown; the PD commands every step to touchdown).
    pub fn control_steps(&self) -> usize {
        match self.kind {
            Kind::OpenLoop => self.reference.steps,
            Kind::Tvlqr | Kind::Replan => self.tvlqr.starts.len(),
        }
    }

    /// The control step of a measurement at time `t`: the last one whose
    /// time (`k` periods) is at or before `t` (to a part in 10^9 of a step).
    pub fn step_at(&self, t: f64) -> usize {
        let p = self.period_steps() as f64 * self.reference.h;
        (t / p + 1e-9).floor().max(0.0) as usize
    }

    /// A simulator's state from what a robot's sensors give: the rear half's
    /// attitude `W R` (`[w, x, y, z]`), the joint angles and rates and the
    /// gyro on the rear half (rad/s, its own frame); `lambda = J(q) w + K(q) q_dot`
    /// with the model's inertias, as the closed loop's sensors estimate it.
    pub fn sensed(
        &self,
        attitude: [f64; 4],
        q: [f64; 2],
        qd: [f64; 2],
        gyro: [f64; 3],
    ) -> SimState {
        let l = momentum_from_rates(&self.reference.cat, q, qd, gyro);
        [
            attitude[0],
            attitude[1],
            attitude[2],
            attitude[3],
            l[0],
            l[1],
            l[2],
            q[0],
            q[1],
            qd[0],
            qd[1],
        ]
    }

    /// Forgets the corrections sent and the replans (a new flight, on the design).
    pub fn reset(&mut self) {
        self.issued.clear();
        self.reference = self.flight_reference().clone();
        self.in_flight = InFlight::new(self.replanning.design.clone());
    }

    /// What a new flight starts on: the design's nominal, or the open
    /// loop's for the open loop.
    pub fn flight_reference(&self) -> &Reference {
        match self.kind {
            Kind::OpenLoop => &self.open_loop,
            Kind::Tvlqr | Kind::Replan => &self.design,
        }
    }

    /// The corrections sent so far, by control step.
    pub fn issued(&self) -> &[[f64; 2]] {
        &self.issued
    }

    /// The correction, N m (catflip's joint torques), on top of the
    /// feed-forward, from the measurement `m` taken at control step `k`:
    /// what the closed loop of [`super::closed_loop::fly`] sends there.
    /// After the last control step the last correction holds.
    pub fn correction(&mut self, k: usize, m: &Y) -> [f64; 2] {
        if k >= self.control_steps() {
            return self.issued.last().copied().unwrap_or([0.0; 2]);
        }
        if k == 0 {
            self.reset();
        }
        // a step skipped sent nothing
        self.issued.resize(k, [0.0; 2]);
        let u = match self.kind {
            Kind::OpenLoop => pd_command(&self.reference, self.pd.kp, self.pd.kd, k, m),
            Kind::Tvlqr | Kind::Replan => tvlqr_command(
                &self.reference,
                &self.tvlqr,
                &self.motor,
                &self.issued,
                k,
                m,
            ),
        };
        self.issued.push(u);
        if self.kind == Kind::Replan {
            self.in_flight.replan(
                &mut self.reference,
                &self.replanning,
                &self.tvlqr,
                &self.motor,
                &self.issued,
                k,
                m,
            );
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_simulators_state_maps_back_exactly_enough() {
        let y: Y = {
            let q =
                nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(0.3, -1.1, 2.0));
            [q.w, q.i, q.j, q.k, 0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7]
        };
        let back = from_sim(&to_sim(&y));
        for i in 0..11 {
            assert!(
                (back[i] - y[i]).abs() < 1e-15,
                "{i}: {} vs {}",
                back[i],
                y[i]
            );
        }
        // W sends catflip's up (x) to the simulators' z
        let s = to_sim(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let w = crate::model::so3::quat_from(&[s[0], s[1], s[2], s[3]]);
        let up = w * nalgebra::Vector3::x();
        assert!((up - nalgebra::Vector3::z()).norm() < 1e-15);
    }
}
