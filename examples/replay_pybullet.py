#!/usr/bin/env python3
"""Replay catflip's schedules in pyBullet, unedited.

    catflip run configs/seed.toml
    python examples/replay_pybullet.py output/seed/run

or, with the catflip Python package installed (pip install ./python), from the
config, designed in-process (the same files, so the same output):

    python examples/replay_pybullet.py configs/seed.toml [--set KEY=VALUE]

Loads output/<name>/run/<name>.urdf with URDF_USE_INERTIA_FROM_FILE (without it
pyBullet recomputes the inertias from the collision cylinders) and each
output/<name>/run/<method>.pybullet.csv as catflip wrote them; sets the links'
damping to zero (pyBullet's default is 0.04), steps at the CSV's time step
and holds each row's torque over its step: once feed-forward only, once
feed-forward plus catflip's PD. Prints flip, tilt, final shape error and peak
torque beside catflip's summary.json; exits non-zero on a mismatch.

pyBullet's integrator is first order (semi-implicit Euler), so its flip
differs from catflip's by its own integration error: measured against the
time step: the PD replay runs at the CSV's step and at half of it, and the flip
extrapolated to zero step must agree with catflip's.
Needs: pip install pybullet numpy
"""

import math
import pathlib
import sys

try:
    import pybullet as p
    import numpy as np
except ModuleNotFoundError as missing:
    sys.exit(f"this script needs the `{missing.name}` Python package: "
             "python3 -m venv venv && venv/bin/pip install mujoco pybullet numpy (docs/replay.md)")

from replay_common import (FlipTracker, finish, landing_of, limit_catflip_torque, load_summary, parse_args, pd_tolerance,
                           quat_conj, quat_mul,
                           peak_of, quat_log, read_controls, reference, report, right_jacobian,
                           run_folder)

# pyBullet integrates with semi-implicit Euler: its flip error is first order in
# the step (1 to 3 deg at catflip's 0.25 ms step on the seed and robot configs,
# halving with the step; MuJoCo's Euler integrator gives the same numbers). The
# PD replay at dt and dt/2 measures that error; with it removed (Richardson) the
# flip must agree with catflip's to this, deg.
PYBULLET_TOL_DEG = 2e-2


def xyzw_to_wxyz(q):
    return np.array([q[3], q[0], q[1], q[2]])


def replay(urdf, c, pd, substeps=1):
    """One replay; `substeps` > 1 splits each step (same held torque) to measure the integration error."""
    cid = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=cid)
        p.setPhysicsEngineParameter(fixedTimeStep=c["dt"] / substeps, numSubSteps=0,
                                    physicsClientId=cid)
        body = p.loadURDF(str(urdf), [0, 0, 10], flags=p.URDF_USE_INERTIA_FROM_FILE,
                          useFixedBase=False, physicsClientId=cid)
        for link in range(-1, p.getNumJoints(body, physicsClientId=cid)):
            p.changeDynamics(body, link, linearDamping=0.0, angularDamping=0.0,
                             jointDamping=0.0, physicsClientId=cid)
        joints = [j for j in range(p.getNumJoints(body, physicsClientId=cid))
                  if p.getJointInfo(body, j, physicsClientId=cid)[2] != p.JOINT_FIXED]
        ball = p.getJointInfo(body, joints[0], physicsClientId=cid)[2] == p.JOINT_SPHERICAL
        # switch off the default velocity motors so that torque control is all there is
        if ball:
            p.setJointMotorControlMultiDof(body, joints[0], p.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                           positionGain=0, velocityGain=0, force=[0, 0, 0],
                                           physicsClientId=cid)
        else:
            p.setJointMotorControlArray(body, joints, p.VELOCITY_CONTROL, forces=[0.0] * len(joints),
                                        physicsClientId=cid)
        # a universal joint with a torque-speed line: the clip depends on the speed
        dc = not ball and c["slope"] > 0
        # the start from the controls' header: attitude and release velocities (world)
        if c["start_base_quat"].size:
            p.resetBasePositionAndOrientation(body, [0, 0, 10], list(c["start_base_quat"]),
                                              physicsClientId=cid)
            p.resetBaseVelocity(body, list(c["start_base_linear_velocity"]),
                                list(c["start_base_angular_velocity"]), physicsClientId=cid)
        _, q0 = p.getBasePositionAndOrientation(body, physicsClientId=cid)
        tracker = FlipTracker(xyzw_to_wxyz(q0), c["start_attitude"])
        pos, vel, ff = c["pick"]("pos"), c["pick"]("vel"), c["pick"]("force")
        # the peak applied, and the peak of the exported feed-forward alone (the schedule's
        # mean over each control step)
        peak = ff_peak = 0.0
        for k in range(c["steps"]):
            if ball:
                st = p.getJointStateMultiDof(body, joints[0], physicsClientId=cid)
                v = quat_log(xyzw_to_wxyz(st[0]))
                jr = right_jacobian(v)
                vd = np.linalg.solve(jr, np.array(st[1]))
                v_ref = quat_log(xyzw_to_wxyz(pos[k]))
                vd_ref = np.linalg.solve(right_jacobian(v_ref), vel[k])
                tau_v = jr.T @ ff[k]
                ff_peak = max(ff_peak, peak_of(tau_v, c["norm"]))
                if pd:
                    tau_v = tau_v + c["kp"] * (v_ref - v) + c["kd"] * (vd_ref - vd)
                tau_v = limit_catflip_torque(tau_v, vd, c)
                u = np.linalg.solve(jr.T, tau_v)
            else:
                st = p.getJointStates(body, joints, physicsClientId=cid)
                q = np.array([s[0] for s in st])
                qd = np.array([s[1] for s in st])
                tau_v = ff[k].copy()
                ff_peak = max(ff_peak, peak_of(tau_v, c["norm"]))
                if pd:
                    tau_v = tau_v + c["kp"] * (pos[k] - q) + c["kd"] * (vel[k] - qd)
                tau_v = limit_catflip_torque(tau_v, qd, c)
                u = tau_v
            peak = max(peak, peak_of(tau_v, c["norm"]))
            if k == c["steps"] - c["margin_steps"]:
                p.setPhysicsEngineParameter(fixedTimeStep=c["margin_dt"] / substeps, numSubSteps=0,
                                            physicsClientId=cid)
            for sub in range(substeps):
                if dc and sub > 0:
                    # torque-speed line: catflip's controller at every pyBullet step, PD on the
                    # planned state at that instant and the clip at the current speed, so that
                    # the controller's hold is first order in pyBullet's step (Richardson)
                    st = p.getJointStates(body, joints, physicsClientId=cid)
                    q = np.array([s[0] for s in st])
                    qd = np.array([s[1] for s in st])
                    q_ref, qd_ref = reference(pos, vel, k, sub / substeps, c["dt"])
                    u = ff[k].copy()
                    if pd:
                        u = u + c["kp"] * (q_ref - q) + c["kd"] * (qd_ref - qd)
                    u = limit_catflip_torque(u, qd, c)
                if ball:
                    p.setJointMotorControlMultiDof(body, joints[0], p.TORQUE_CONTROL, force=list(u),
                                                   physicsClientId=cid)
                else:
                    p.setJointMotorControlArray(body, joints, p.TORQUE_CONTROL, forces=list(u),
                                                physicsClientId=cid)
                p.stepSimulation(physicsClientId=cid)
                _, qb = p.getBasePositionAndOrientation(body, physicsClientId=cid)
                tracker.push(xyzw_to_wxyz(qb))
            if k == c["steps"] - c["margin_steps"] - 1:
                # the flip and tilt at the end of the manoeuvre (catflip's); the landing at touchdown
                flip, tilt = tracker.acc, tracker.tilt
        if ball:
            st = p.getJointStateMultiDof(body, joints[0], physicsClientId=cid)
            shape = np.linalg.norm(quat_log(xyzw_to_wxyz(st[0])))
        else:
            shape = np.linalg.norm([s[0] for s in p.getJointStates(body, joints, physicsClientId=cid)])
        return {
            "flip_deg": math.degrees(flip),
            "tilt_deg": math.degrees(tilt),
            "landing_deg": tracker.landing,
            "attitude": tracker.r,
            "shape_error_rad": float(shape),
            "peak_nm": peak,
            "ff_peak_nm": ff_peak,
            "spinning": bool(np.any(c["start_body_rate"] != 0)),
        }
    finally:
        p.disconnect(cid)


def main():
    args = parse_args("pyBullet", PYBULLET_TOL_DEG)
    out = run_folder(args.output, args.overrides)
    summary = load_summary(out)
    urdf = out / f"{summary['name']}.urdf"
    # every method that produced a schedule (a failed one, or one the motors cannot do
    # in this fall, has none; the least-height schedule is one)
    methods = args.methods.split(",") if args.methods else [
        m["method"] for m in summary["methods"] if m.get("schedule_csv")]
    results = []
    for method in methods:
        c = read_controls(out / f"{method}.pybullet.csv")
        results.append((method, "ff", replay(urdf, c, False)))
        pd = replay(urdf, c, True)
        half = replay(urdf, c, True, substeps=2)
        # first-order integrator: error(dt) ~ 2 (flip(dt) - flip(dt/2)); remove it (Richardson)
        # (the peak torque too: 0.027 N m designs are off by 2.7 % at dt, 0.07 % extrapolated)
        extrapolated = dict(pd, flip_deg=2.0 * half["flip_deg"] - pd["flip_deg"],
                            # the attitude extrapolated (the landing is not linear in its error)
                            landing_deg=landing_of(quat_mul(half["attitude"], quat_mul(
                                quat_conj(pd["attitude"]), half["attitude"]))),
                            peak_nm=2.0 * half["peak_nm"] - pd["peak_nm"])
        results += [(method, "pd", pd), (method, "pd/2", half), (method, "pd-x", extrapolated)]
    # pyBullet's landing is checked on its step-error-free extrapolation (pd-x)
    pd_tol = {"pd-x": lambda m: pd_tolerance(args.tol_deg, args.default_tol_deg, m)}
    fails = report("pyBullet", summary, results, pd_tol, None,
                   args.land_tol_deg, args.land_methods.split(","), ("pd-x",))
    print("  pd/2 = the same rows with two pyBullet steps each (dt/2); pd-x = 2 pd/2 - pd, the flip and peak\n"
          "  with pyBullet's first-order integration error (2 (pd - pd/2)) removed: that one must agree with catflip.")
    finish(fails)


if __name__ == "__main__":
    main()
