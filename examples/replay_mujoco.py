#!/usr/bin/env python3
"""Replay catflip's schedules in MuJoCo, unedited.

    catflip run configs/seed.toml
    python examples/replay_mujoco.py output/seed/run

or, with the catflip Python package installed (pip install ./python), from the
config, designed in-process (the same files, so the same output):

    python examples/replay_mujoco.py configs/seed.toml [--set KEY=VALUE]

Loads output/<name>/run/<name>.mjcf.xml and each output/<name>/run/<method>.mujoco.csv
as catflip wrote them, steps MuJoCo at the model's time step (the CSV's), and
holds each row's torque over its step: once feed-forward only, once
feed-forward plus catflip's PD (gains and torque limit from the CSV header).
With a torque-speed line on a universal joint the MJCF's actuators are DC
motors (force = ctrl - k qd, ctrl limited to the stall torque) and the CSV's
ctrl is the command tau + k qd; otherwise this script clips to the envelope
at each step's start.
Prints flip, tilt, final shape error and peak torque beside catflip's
summary.json; exits non-zero on a mismatch. Also checks that the URDF loads in
MuJoCo (universal joint) with the same masses and inertias.
Needs: pip install mujoco numpy
"""

import math
import pathlib
import sys

try:
    import mujoco
    import numpy as np
except ModuleNotFoundError as missing:
    sys.exit(f"this script needs the `{missing.name}` Python package: "
             "python3 -m venv venv && venv/bin/pip install mujoco pybullet numpy (docs/replay.md)")

from replay_common import (FlipTracker, finish, limit_catflip_torque, load_summary, parse_args, pd_tolerance,
                           peak_of, quat_log, read_controls, reference, report, right_jacobian,
                           run_folder, RIDING_FACTOR)


def is_dc_motor(model):
    """Whether the actuators are catflip's DC motors: force = ctrl - k qd (affine bias)."""
    return model.nu > 0 and model.actuator_biastype[0] == mujoco.mjtBias.mjBIAS_AFFINE


def replay(model, c, pd):
    """One replay; returns flip, tilt, final shape error and peak catflip-coordinate torque."""
    data = mujoco.MjData(model)
    # the start: the MJCF's keyframe "start" (attitude and release velocities)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, model.key("start").id)
        check_start(model, data, c)
    elif model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and c["start_base_quat"].size:
        # the URDF freed in memory has no keyframe: the controls' header gives the start
        data.qpos[3:7] = c["start_base_quat"]
        data.qvel[0:3] = c["start_base_linear_velocity"]
        data.qvel[3:6] = c["start_base_angular_velocity"]
    mujoco.mj_forward(model, data)
    ball = model.jnt_type[1] == mujoco.mjtJoint.mjJNT_BALL
    dc = is_dc_motor(model)
    if dc != any(col.startswith("ctrl_cmd") for col in c["cols"]):
        raise SystemExit("the controls' ctrl columns do not match the model's actuators "
                         "(ctrl_cmd = DC-motor command, ctrl_tau = torque)")
    qa, va = model.jnt_qposadr[1], model.jnt_dofadr[1]
    rear = model.body("rear").id
    tracker = FlipTracker(data.xquat[rear].copy(), c["start_attitude"])
    pos, vel, ff = c["pick"]("qpos"), c["pick"]("qvel"), c["pick"]("ctrl")
    peak = 0.0
    # step index, its start time and feed-forward torque, for the control callback
    stage = np.zeros(4)

    def control(m, d):
        k, t0 = int(stage[0]), stage[1]
        q_ref, qd_ref = reference(pos, vel, k, (d.time - t0) / c["dt"], c["dt"])
        q, qd = d.qpos[qa:qa + 2], d.qvel[va:va + 2]
        tau = stage[2:] + c["kp"] * (q_ref - q) + c["kd"] * (qd_ref - qd)
        d.ctrl[:] = tau + c["slope"] * qd

    if dc and pd:
        mujoco.set_mjcb_control(control)
    try:
        return run_steps(model, data, c, pd, ball, dc, stage, qa, va, rear, tracker, pos, vel, ff)
    finally:
        mujoco.set_mjcb_control(None)
        model.opt.timestep = c["dt"]


def run_steps(model, data, c, pd, ball, dc, stage, qa, va, rear, tracker, pos, vel, ff):
    # the peak applied, and the peak of the exported feed-forward alone (the schedule's
    # mean over each control step)
    peak = ff_peak = 0.0
    for k in range(c["steps"]):
        if ball:
            v = quat_log(data.qpos[qa:qa + 4])
            jr = right_jacobian(v)
            vd = np.linalg.solve(jr, data.qvel[va:va + 3])
            v_ref = quat_log(pos[k])
            vd_ref = np.linalg.solve(right_jacobian(v_ref), vel[k])
            # catflip's PD acts on the rotation-vector coordinates; the twist v3 is held at 0
            tau_v = jr.T @ ff[k]
            ff_peak = max(ff_peak, peak_of(tau_v, c["norm"]))
            if pd:
                tau_v = tau_v + c["kp"] * (v_ref - v) + c["kd"] * (vd_ref - vd)
            tau_v = limit_catflip_torque(tau_v, vd, c)
            data.ctrl[:] = np.linalg.solve(jr.T, tau_v)
        elif dc:
            # DC-motor actuators: force = clamp(ctrl, -T, T) - k qd, MuJoCo recomputing the
            # back-EMF at every RK4 stage. Feed-forward only: the CSV's command, held.
            # With feedback: catflip's controller, run at every integrator stage by the control
            # callback: the held feed-forward torque plus PD on the planned state at that
            # instant, ctrl = tau + k qd, so the motor gives catflip's clip at the stage's speed.
            q, qd = data.qpos[qa:qa + 2], data.qvel[va:va + 2]
            ff_tau = ff[k] - c["slope"] * (pos[k + 1] - pos[k]) / c["dt"]
            ff_peak = max(ff_peak, peak_of(ff_tau, c["norm"]))
            if pd:
                stage[:] = [k, data.time, *ff_tau]
                tau_v = limit_catflip_torque(
                    ff_tau + c["kp"] * (pos[k] - q) + c["kd"] * (vel[k] - qd), qd, c)
            else:
                data.ctrl[:] = ff[k]
                tau_v = limit_catflip_torque(ff_tau, qd, c)
        else:
            q, qd = data.qpos[qa:qa + 2], data.qvel[va:va + 2]
            tau_v = ff[k].copy()
            ff_peak = max(ff_peak, peak_of(tau_v, c["norm"]))
            if pd:
                tau_v = tau_v + c["kp"] * (pos[k] - q) + c["kd"] * (vel[k] - qd)
            tau_v = limit_catflip_torque(tau_v, qd, c)
            data.ctrl[:] = tau_v
        peak = max(peak, peak_of(tau_v, c["norm"]))
        if k == c["steps"] - c["margin_steps"]:
            model.opt.timestep = c["margin_dt"]
        mujoco.mj_step(model, data)
        tracker.push(data.xquat[rear])
        if k == c["steps"] - c["margin_steps"] - 1:
            # the flip and tilt at the end of the manoeuvre (catflip's); the landing at touchdown
            flip, tilt = tracker.acc, tracker.tilt
    if ball:
        shape = np.linalg.norm(quat_log(data.qpos[qa:qa + 4]))
    else:
        shape = np.linalg.norm(data.qpos[qa:qa + 2])
    return {
        "flip_deg": math.degrees(flip),
        "tilt_deg": math.degrees(tilt),
        "landing_deg": tracker.landing,
        "shape_error_rad": float(shape),
        "peak_nm": peak,
        "ff_peak_nm": ff_peak,
        "spinning": bool(np.any(c["start_body_rate"] != 0)),
    }


def check_start(model, data, c):
    """The keyframe is the start the controls' header states."""
    want = c["start_base_quat"]
    got = data.qpos[3:7]
    if want.size and min(np.abs(got - want).max(), np.abs(got + want).max()) > 1e-12:
        raise SystemExit(f"the MJCF's start attitude {got} is not the controls' {want}")
    w = c["start_base_angular_velocity"]
    if np.abs(data.qvel[3:6] - w).max() > 1e-12:
        raise SystemExit(f"the MJCF's start rate {data.qvel[3:6]} is not the controls' {w}")


def check_urdf(out, name, model, controls, mjcf_flips):
    """The URDF loads in MuJoCo unedited with the MJCF's masses and inertias.
    MuJoCo fixes a URDF's root link to the world, so to measure the effect of
    the universal joint's near-massless `cross` link the script then frees the
    root and adds the two motors in memory, and replays the PD schedules."""
    path = out / f"{name}.urdf"
    try:
        u = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as e:
        return [f"{path.name} does not load in MuJoCo: {e}"]
    fails = []
    for body in ("rear", "front"):
        a, b = model.body(body), u.body(body)
        if abs(a.mass[0] - b.mass[0]) > 1e-9 or np.abs(np.sort(a.inertia) - np.sort(b.inertia)).max() > 1e-9:
            fails.append(f"{path.name}: body {body} mass/inertia {b.mass}, {b.inertia} differ from the MJCF's {a.mass}, {a.inertia}")
    print(f"  {path.name} loads in MuJoCo: bodies "
          + ", ".join(f"{u.body(i).name} {u.body_mass[i]:.6g} kg" for i in range(1, u.nbody)))
    spec = mujoco.MjSpec.from_file(str(path))
    spec.body("rear").add_freejoint()
    for i, j in enumerate(("motor1", "motor2")):
        a = spec.add_actuator(name=j, target=j, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        if is_dc_motor(model):
            # the MJCF's DC motor, as it is
            a.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            a.biasprm = model.actuator_biasprm[i]
            a.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            a.ctrlrange = model.actuator_ctrlrange[i]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    # the rear and front cylinders touch at the joint and are not parent and child here
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    free = spec.compile()
    for method, c in controls:
        free.opt.timestep = c["dt"]
        r = replay(free, c, True)
        d = r["flip_deg"] - mjcf_flips[method]
        print(f"  {method}: URDF (with its cross link) freed, PD replay: flip {r['flip_deg']:.9f} deg, "
              f"{d:+.2e} deg from the MJCF's (the cross link's effect)")
        if abs(d) > 1e-5:
            fails.append(f"{method}: the URDF's cross link moves the flip by {d:.3e} deg (> 1e-5)")
    return fails


def main():
    args = parse_args("MuJoCo", 1e-3)
    out = run_folder(args.output, args.overrides)
    summary = load_summary(out)
    name = summary["name"]
    model = mujoco.MjModel.from_xml_path(str(out / f"{name}.mjcf.xml"))
    # every method that produced a schedule (a failed one, or one the motors cannot do
    # in this fall, has none; the least-height schedule is one)
    methods = args.methods.split(",") if args.methods else [
        m["method"] for m in summary["methods"] if m.get("schedule_csv")]
    results, fails, controls = [], [], []
    for method in methods:
        c = read_controls(out / f"{method}.mujoco.csv")
        controls.append((method, c))
        if abs(c["dt"] - model.opt.timestep) > 1e-12 * c["dt"]:
            # a schedule of another duration (export --schedule): its own step tiles it
            print(f"  note: {method} uses its CSV's time step {c['dt']:.9e} s (model: {model.opt.timestep:.9e} s)")
            model.opt.timestep = c["dt"]
        for mode in ("ff", "pd"):
            results.append((method, mode, replay(model, c, mode == "pd")))
    pd_tol = {"pd": lambda m: pd_tolerance(args.tol_deg, args.default_tol_deg, m, RIDING_FACTOR)}
    fails += report("MuJoCo", summary, results, pd_tol, args.ff_tol_deg,
                    args.land_tol_deg, args.land_methods.split(","))
    if summary["joint"] == "universal":
        pd_flips = {m: r["flip_deg"] for m, mode, r in results if mode == "pd"}
        fails += check_urdf(out, name, model, controls, pd_flips)
    finish(fails)


if __name__ == "__main__":
    main()
