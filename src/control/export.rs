//! The TVLQR gains as a CSV beside a schedule's controls, in the
//! simulators' world (gravity along `-z`, [`crate::export::start::world_map`]).

use super::closed_loop::{Feedback, Flight, fly};
use super::reference::Reference;
use super::tvlqr::Tvlqr;
use crate::config::Config;
use crate::design::plan::ShapePlan;
use crate::export::start::world_map;
use crate::model::Joint;

/// The design's gains, one row per control step, and in the header the
/// nominal's landing under the TVLQR and under the open loop.
pub fn gains_csv(cfg: &Config, plan: &dyn ShapePlan) -> crate::Result<String> {
    let r = Reference::checked(cfg, plan)?;
    let tv = Tvlqr::new(&r, &cfg.control);
    let shape = match cfg.cat.joint {
        Joint::Universal => "q = the two hinge angles (qpos of the hinges), qd their rates",
        Joint::NoTwist => {
            "q = (v1, v2), the ball joint's rotation vector (v3 = 0), qd = dv/dt (not the ball's angular velocity)"
        }
    };
    let mut s = format!(
        "# catflip TVLQR gains for {name}: u = -K (x_measured - x_nominal), held from t_apply_s to the next row's,\n\
         # added to the schedule's feed-forward torque (catflip's tau, hinge torques for universal),\n\
         # measured delay_s = {delay:.6e} s before t_apply_s and predicted over the delay with the model (catflip's rigid\n\
         # two-body model, docs/model.md) under the corrections already sent. t = 0 is the release; touchdown is steps * step_s.\n\
         # Feed-forward: the schedule's tau_nm, linear between its rows (<stem>.mujoco.csv holds it a simulator step at a time,\n\
         # as the DC command tau + k qd where the motor has a torque-speed line); u is capped at max_correction_nm and\n\
         # tau + u kept inside the motor envelope at the joint speed. Units: s, rad, rad/s, N m s (lambda), N m (u, tau),\n\
         # K_i_j in N m per unit of x_j. Columns: qnom_w..qnom_z the nominal attitude, lnom_* its lambda, qnom_1, qnom_2 its q,\n\
         # qdnom_* its qd.\n\
         # x = [dtheta (3), dlambda (3), dq (2), dqd (2)]: dtheta = log(R_nom' R) of the rear half in its own frame\n\
         # (the same in catflip's world and the simulator's: R_sim = W R), lambda = R' L the momentum about the\n\
         # common centre of mass in the rear half's frame, N m s; {shape}.\n\
         # Nominal attitude qnom_* = W R_nom, [w x y z], the simulator's world (gravity -z). K_i_j: row i (torque), column j (x).\n\
         # control.rate_hz = {rate} (a correction every period_steps = {p} simulator steps: {applied:.6} Hz), control.delay_ms = {dms}, simulator step {h:.9e} s.\n",
        name = cfg.name,
        delay = tv.delay_steps as f64 * r.h,
        rate = cfg.control.rate_hz,
        p = tv.period_steps,
        applied = 1.0 / (tv.period_steps as f64 * r.h),
        dms = cfg.control.delay_ms,
        h = r.h,
    );
    // what a controller run from this file needs, one `# key = value` a line
    let motor = cfg.motor();
    let pd = crate::verify::simulate::Controller::from_spec(&cfg.design_spec());
    let nominal = |r: &Reference, fb| fly(r, fb, &motor, Flight::nominal(r)).error_deg;
    let open = r.for_open_loop(cfg, plan);
    let (nominal_tvlqr_deg, nominal_open_loop_deg) = (
        nominal(&r, Feedback::Tvlqr(&tv)),
        nominal(
            &open,
            Feedback::JointPd {
                kp: pd.kp,
                kd: pd.kd,
            },
        ),
    );
    let keys = [
        ("step_s", r.h),
        ("steps", r.steps as f64),
        ("period_steps", tv.period_steps as f64),
        ("delay_steps", tv.delay_steps as f64),
        ("max_correction_nm", tv.max_correction),
        ("peak_torque_nm", r.peak_torque),
        ("pd_kp", pd.kp),
        ("pd_kd", pd.kd),
        ("nominal_held", if r.is_held() { 1.0 } else { 0.0 }),
        ("nominal_landing_error_deg_tvlqr", nominal_tvlqr_deg),
        ("nominal_landing_error_deg_open_loop", nominal_open_loop_deg),
    ];
    if r.is_held() {
        s.push_str(
            "# The nominal holds the planned shape (nominal_held = 1): catflip flies it under the schedule's torque plus the\n\
             # joint PD (pd_kp, pd_kd) on the planned shape along the nominal. The schedule's controls lack that holding torque\n\
             # (the Python package's Controller.feedforward has it); run from these files, u supplies it as feedback.\n",
        );
    }
    s.push_str(
        "# The closed loop's grid (touchdown at steps * step_s), the correction's cap, the PD gains and\n\
         # catflip's landing error of the nominal flight (the model, no delay or noise) under each controller:\n",
    );
    for (k, v) in keys {
        s.push_str(&format!("# {k} = {v:.17e}\n"));
    }
    let mut cols = vec![
        "t_apply_s".to_string(),
        "qnom_w".into(),
        "qnom_x".into(),
        "qnom_y".into(),
        "qnom_z".into(),
        "lnom_1".into(),
        "lnom_2".into(),
        "lnom_3".into(),
        "qnom_1".into(),
        "qnom_2".into(),
        "qdnom_1".into(),
        "qdnom_2".into(),
    ];
    for i in 0..2 {
        for j in 0..10 {
            cols.push(format!("K_{i}_{j}"));
        }
    }
    s.push_str(&cols.join(","));
    s.push('\n');
    let w = world_map();
    for (k, &a) in tv.starts.iter().enumerate() {
        let y = r.nominal[a];
        let q = w * super::plant::attitude(&y);
        let mut v = vec![a as f64 * r.h, q.w, q.i, q.j, q.k];
        v.extend_from_slice(&[y[8], y[9], y[10], y[4], y[5], y[6], y[7]]);
        let g = &tv.gains[k];
        for i in 0..2 {
            for j in 0..10 {
                v.push(g[(i, j)]);
            }
        }
        let v: Vec<String> = v.iter().map(|x| format!("{x:.17e}")).collect();
        s.push_str(&v.join(","));
        s.push('\n');
    }
    Ok(s)
}
