#!/usr/bin/env python3
"""catflip's closed-loop controllers in MuJoCo, under catflip's own robustness study.

    python examples/closed_loop_mujoco.py configs/seed.toml --trials 50 --seed 1
    python examples/closed_loop_mujoco.py configs/robot-universal.toml --set fall.height=4.25

Runs `catflip robustness CONFIG --trials N --seed S --json` (catflip's
simulator), then flies the same trials on catflip's exported MJCF in MuJoCo:
each trial's robot, start and noises are the study's (its draws read from
robustness.csv and checked against the same counter-based random streams
redrawn here; the torque and sensor noises redrawn from the trial's own
stream), applied to the MuJoCo model:

- each half's mass, inertia and length errors edited in the MjModel
  (body_mass, body_inertia, body_pos / body_ipos of the joint and the centre
  of mass: catflip's radius and length scaled by sqrt(1 + e));
- the release attitude (tilt about a horizontal axis) in qpos and the spin in
  the free joint's qvel, the common centre of mass at rest;
- the actuator delay: each command acts `robustness.delay_ms` after its
  measurement; torque noise redrawn each control period; attitude and rate
  noise on the sensors;
- the motor envelope (saturation, back-EMF) at every RK4 stage's joint speed,
  through the MJCF's actuators (DC motors where the MJCF has them).

Controllers: `open-loop` (feed-forward plus catflip's joint PD, every step)
and `tvlqr`. With the catflip Python package installed (pip install ./python)
they are `catflip.Controller` (the study's design, its feed-forward at every
RK4 stage); without it (or with --route csv) the TVLQR runs from the gains
CSV `catflip export mjcf --schedule` writes (`<stem>.tvlqr.csv`), predicting
over its delay with MuJoCo's own model of the robot, and the feed-forward is
the exported `<stem>.mujoco.csv`, which lacks the holding torque of catflip's
nominal (that route's TVLQR nominal lands about 1e-2 deg from catflip's and fails
the check below: docs/control.md).

Prints each controller's success rate (95 % Wilson interval) in MuJoCo beside
catflip's, and the per-trial landing errors' largest difference. Exits 1 when
a nominal trial (the model, the config's start, no delay or noise) lands more
than --nominal-tol-deg (default 1e-3 deg) away from catflip's simulator.
Needs: pip install mujoco numpy (and the catflip package for the package route).
"""

import argparse
import csv
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import time

try:
    import mujoco
    import numpy as np
except ModuleNotFoundError as missing:
    sys.exit(f"this script needs the `{missing.name}` Python package: "
             "python3 -m venv venv && venv/bin/pip install mujoco pybullet numpy (docs/replay.md)")

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from replay_common import landing_of, quat_conj, quat_log, quat_mul, right_jacobian  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
CONTROLLERS = ("open-loop", "tvlqr", "replan")
# W: catflip's world to the simulators' (catflip x -> z, z -> x, y -> -y), src/export/start.rs
W = np.array([0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5)])
MASK = (1 << 64) - 1


# --- catflip's random streams (src/control/rng.rs), bit for bit ----------------

def _mix(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


class Rng:
    """SplitMix64 over (study seed, trial, stream), Box-Muller normals: catflip's."""

    def __init__(self, seed, trial, stream):
        rot = ((stream << 32) | (stream >> 32)) & MASK
        self.state = _mix(((_mix(seed ^ 0x6A09E667F3BCC909) + trial) & MASK) ^ rot)
        self.spare = None

    def next_u64(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        return _mix(self.state)

    def uniform(self):
        return (self.next_u64() >> 11) * (1.0 / (1 << 53))

    def signed(self):
        return 2.0 * self.uniform() - 1.0

    def normal(self):
        if self.spare is not None:
            z, self.spare = self.spare, None
            return z
        u, v = 1.0 - self.uniform(), self.uniform()
        r = math.sqrt(-2.0 * math.log(u))
        a = 2.0 * math.pi * v
        self.spare = r * math.sin(a)
        return r * math.cos(a)

    def direction(self):
        while True:
            v = [self.normal(), self.normal(), self.normal()]
            n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
            if n > 1e-12:
                return [x / n for x in v]


def draw(p, seed, trial):
    """A trial's draws from `[robustness]` `p`, as src/control/robustness.rs Draw::new."""
    g = Rng(seed, trial, 0)
    d = g.direction()
    m = g.uniform()
    spin = [m * d[i] * p["spin_rad_s"][i] for i in range(3)]
    tilt = p["tilt_deg"] * g.uniform()
    axis = 360.0 * g.uniform()
    pair = lambda e: [e * g.signed(), e * g.signed()]
    mass, inertia, length = pair(p["mass_error"]), pair(p["inertia_error"]), pair(p["length_error"])
    return {"trial": trial, "spin_rad_s": spin, "tilt_deg": tilt, "tilt_axis_deg": axis,
            "mass_error": mass, "inertia_error": inertia, "length_error": length,
            "pd_gain_factor": 1.0 + p["pd_gain_error"] * g.signed()}


def draws_of_csv(path):
    """robustness.csv's rows as draws and catflip's landing errors."""
    out = []
    for row in csv.DictReader(open(path)):
        f = lambda k: float(row[k])
        out.append(({"trial": int(row["trial"]),
                     "spin_rad_s": [f("spin_x_rad_s"), f("spin_y_rad_s"), f("spin_z_rad_s")],
                     "tilt_deg": f("tilt_deg"), "tilt_axis_deg": f("tilt_axis_deg"),
                     "mass_error": [f("mass_error_rear"), f("mass_error_front")],
                     "inertia_error": [f("inertia_error_rear"), f("inertia_error_front")],
                     "length_error": [f("length_error_rear"), f("length_error_front")],
                     "pd_gain_factor": f("pd_gain_factor")},
                    {name: f(name.replace("-", "_") + "_landing_error_deg") for name in CONTROLLERS}))
    return out


def wilson(k, n):
    """Wilson score interval at 95 % (src/control/robustness.rs wilson)."""
    if n == 0:
        return [0.0, 1.0]
    z = 1.959963984540054
    p = k / n
    d = 1.0 + z * z / n
    c = (p + z * z / (2.0 * n)) / d
    h = z * math.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / d
    # exact at the ends, as catflip's (c - h rounds to 6e-17 at no success)
    return [0.0 if k == 0 else max(c - h, 0.0), 1.0 if k == n else min(c + h, 1.0)]


# --- rotations -----------------------------------------------------------------

def quat_exp(v):
    v = np.asarray(v, float)
    t = float(np.linalg.norm(v))
    if t < 1e-300:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[math.cos(t / 2)], v * (math.sin(t / 2) / t)])


def rotate(q, v):
    return quat_mul(quat_mul(q, np.concatenate([[0.0], v])), quat_conj(q))[1:]


def normalised(q):
    q = np.asarray(q, float)
    return q / np.linalg.norm(q)


# --- the robot in MuJoCo -----------------------------------------------------------

class Robot:
    """The exported MJCF, and copies of it with a trial's model errors."""

    def __init__(self, mjcf_text):
        self.xml = mjcf_text
        self.nominal = mujoco.MjModel.from_xml_string(mjcf_text)
        m = self.nominal
        self.ball = m.jnt_type[1] == mujoco.mjtJoint.mjJNT_BALL
        self.dc = m.nu > 0 and m.actuator_biastype[0] == mujoco.mjtBias.mjBIAS_AFFINE
        self.slope = -float(m.actuator_biasprm[0, 2]) if self.dc else 0.0
        self.qa, self.va = m.jnt_qposadr[1], m.jnt_dofadr[1]
        self.rear, self.front = m.body("rear").id, m.body("front").id
        # the halves as catflip's cylinders: radius and length from the geoms
        self.halves = []
        for b in (self.rear, self.front):
            g = [i for i in range(m.ngeom) if m.geom_bodyid[i] == b][0]
            if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_CYLINDER:
                raise SystemExit("closed_loop_mujoco.py edits cylinder halves (catflip's cat); "
                                 "this MJCF has another shape (an imported body)")
            r, l, mass = float(m.geom_size[g, 0]), 2.0 * float(m.geom_size[g, 1]), float(m.body_mass[b])
            it = mass * (3 * r * r + l * l) / 12.0
            seed_formula = mass * (r * r + l * l) / 12.0
            formula = "solid" if abs(m.body_inertia[b, 0] - it) <= 1e-12 * it else "seed"
            if formula == "seed" and abs(m.body_inertia[b, 0] - seed_formula) > 1e-12 * seed_formula:
                raise SystemExit(f"body {b}: inertia {m.body_inertia[b]} is neither cylinder formula")
            self.halves.append({"r": r, "l": l, "m": mass, "formula": formula})

    def model(self, d=None):
        """A fresh copy of the model with the draw's mass, inertia and length errors
        (catflip's Draw::plant: radius and length by sqrt(1 + e_inertia), length by
        1 + e_length, mass by 1 + e_mass; the inertias are the cylinder's again)."""
        m = mujoco.MjModel.from_xml_string(self.xml)
        if d is None:
            return m
        scale = []
        for i, b in enumerate((self.rear, self.front)):
            h = self.halves[i]
            g = math.sqrt(1.0 + d["inertia_error"][i])
            mass = h["m"] * (1.0 + d["mass_error"][i])
            r, l = h["r"] * g, h["l"] * g * (1.0 + d["length_error"][i])
            it = mass * ((3 if h["formula"] == "solid" else 1) * r * r + l * l) / 12.0
            m.body_mass[b] = mass
            m.body_inertia[b] = [it, it, mass * r * r / 2.0]
            scale.append(l / h["l"])
        # the joint at the rear's half length, the front's centre of mass at its own
        m.body_pos[self.front] = self.nominal.body_pos[self.front] * scale[0]
        m.body_ipos[self.front] = self.nominal.body_ipos[self.front] * scale[1]
        m.body_ipos[self.rear] = self.nominal.body_ipos[self.rear] * scale[0]
        mujoco.mj_setConst(m, mujoco.MjData(m))
        return m


def release(robot, m, data, start_quat_sim, body_rate):
    """The straight cat released at attitude `start_quat_sim` (rear half, simulator's
    world) rotating rigidly at `body_rate` (rear frame), its common centre of mass at rest."""
    mujoco.mj_resetData(m, data)
    data.qpos[0:3] = [0.0, 0.0, float(robot.nominal.body_pos[robot.rear, 2])]
    data.qpos[3:7] = start_quat_sim
    if robot.ball:
        data.qpos[robot.qa:robot.qa + 4] = [1, 0, 0, 0]
    data.qvel[:] = 0.0
    data.qvel[3:6] = body_rate
    mujoco.mj_kinematics(m, data)
    mujoco.mj_comPos(m, data)
    com = data.subtree_com[robot.rear].copy()
    w = rotate(start_quat_sim, np.asarray(body_rate, float))
    data.qvel[0:3] = np.cross(w, data.qpos[0:3] - com)
    mujoco.mj_forward(m, data)


def shape_of(robot, data):
    """catflip's q, q_dot: the hinge angles and rates, or the ball's rotation vector (v1, v2) and its rate."""
    if robot.ball:
        v = quat_log(data.qpos[robot.qa:robot.qa + 4])
        vd = np.linalg.solve(right_jacobian(v), data.qvel[robot.va:robot.va + 3])
        return v, vd
    return data.qpos[robot.qa:robot.qa + 2].copy(), data.qvel[robot.va:robot.va + 2].copy()


def ball_kinematics(v, w):
    """For the ball's rotation vector `v` and its relative rate `w` (child frame):
    J_r(v)^-1, the term J_r'(v) v_dot of the acceleration, and v_dot = J_r^-1 w
    (closed forms: J_r = I - b hat(v) + c hat(v)^2, b = (1 - cos t) / t^2,
    c = (t - sin t) / t^3, t = |v|)."""
    t2 = float(v @ v)
    if t2 < 1e-6:
        b, c = 0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0
        db, dc = -1.0 / 24.0 + t2 / 360.0, -1.0 / 120.0 + t2 / 2520.0
        e = 1.0 / 12.0 + t2 / 720.0
    else:
        t = math.sqrt(t2)
        co, si = math.cos(t), math.sin(t)
        b, c = (1.0 - co) / t2, (t - si) / (t2 * t)
        db = (t * si - 2.0 * (1.0 - co)) / (2.0 * t2 * t2)
        dc = ((1.0 - co) * t - 3.0 * (t - si)) / (2.0 * t2 * t2 * t)
        e = 1.0 / t2 - (1.0 + co) / (2.0 * t * si)
    h = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    hh = h @ h
    jri = I3 + 0.5 * h + e * hh
    vd = jri @ w
    # d/dt J_r along v_dot, applied to v_dot: -b' v x vd + c' v x (v x vd) + c vd x (v x vd)
    s = 2.0 * float(v @ vd)
    vxvd = h @ vd
    jdot = -db * s * vxvd + dc * s * (h @ vxvd) + c * np.array(
        [vd[1] * vxvd[2] - vd[2] * vxvd[1], vd[2] * vxvd[0] - vd[0] * vxvd[2], vd[0] * vxvd[1] - vd[1] * vxvd[0]])
    return jri, jdot, vd


I3 = np.eye(3)


class Stage:
    """What the control callback needs at each RK4 stage of step j."""
    j = 0
    t0 = 0.0
    h = 1.0
    extra = np.zeros(2)
    # the feed-forward of the plan in use, when it changes in flight (replanning)
    ff = None


# the stage the control callback works for: the flight's, or a prediction's inside a command
_STAGE = [None]


def make_callback(robot, ctl, stage):
    """ctrl at every RK4 stage: catflip's plant torque clip(ff(stage) + correction + noise)
    at the stage's joint speed, through the MJCF's actuators; for the no-twist ball the
    twist torque that holds v3 (MuJoCo's own mass matrix and bias forces)."""
    ff = ctl.feedforward
    va = robot.va
    nv = robot.nominal.nv
    rhs, sol = np.zeros((4, nv)), np.zeros((4, nv))
    if robot.ball:
        for i in range(3):
            rhs[1 + i, va + i] = 1.0

    _STAGE[0] = stage

    def control(m, d):
        stage = _STAGE[0]
        s = int(round(2.0 * (d.time - stage.t0) / stage.h))
        f = (ff if stage.ff is None else stage.ff)[2 * stage.j + min(max(s, 0), 2)]
        if robot.ball:
            v = quat_log(d.qpos[robot.qa:robot.qa + 4])
            jri, jdot_vd, vd = ball_kinematics(v, d.qvel[va:va + 3])
            tau = ctl.clip(f + stage.extra, vd[:2])
            # v_ddot = J_r^-1 (alpha - J_r' v_dot), alpha = M^-1 (bias + f_ball): hold v3'' = 0
            rhs[0] = d.qfrc_passive - d.qfrc_bias
            mujoco.mj_solveM(m, d, sol, rhs)
            b0 = sol[0, va:va + 3]
            g = sol[1:, va:va + 3].T
            b = jri @ (b0 - jdot_vd)
            a = jri @ g @ jri.T
            t3 = -(b[2] + a[2, 0] * tau[0] + a[2, 1] * tau[1]) / a[2, 2]
            d.ctrl[:] = jri.T @ np.array([tau[0], tau[1], t3])
        else:
            qd = d.qvel[va:va + 2]
            tau = ctl.clip(f + stage.extra, qd)
            d.ctrl[:] = tau + robot.slope * qd if robot.dc else tau

    return control


def measure(robot, ctl, data, rng, noise):
    """The sensors: the rear half's attitude (W R), the gyro on it, the joint encoders,
    with catflip's noises in its order (attitude, then gyro and joint rates)."""
    att = normalised(data.qpos[3:7])
    if noise["attitude"] > 0:
        n = np.array([rng.normal(), rng.normal(), rng.normal()]) * noise["attitude"]
        att = quat_mul(att, quat_exp(n))
    w = data.qvel[3:6].copy()
    q, qd = shape_of(robot, data)
    q, qd = np.array(q[:2]), np.array(qd[:2])
    if noise["rate"] > 0:
        for i in range(3):
            w[i] += noise["rate"] * rng.normal()
        for i in range(2):
            qd[i] += noise["rate"] * rng.normal()
    return ctl.sensed(att, q, qd, w)


def fly(robot, ctl, start_sim, body_rate, d=None, plant=None):
    """One flight in MuJoCo under controller `ctl`; `plant`: the trial's delay, noises
    and stream (None: the nominal flight). Returns the landing error, deg."""
    m = robot.model(d)
    m.opt.timestep = ctl.step
    data = mujoco.MjData(m)
    release(robot, m, data, start_sim, body_rate)
    n, period = ctl.steps, ctl.period_steps
    delay = plant["delay_steps"] if plant else 0
    noise = plant["noise"] if plant else {"attitude": 0.0, "rate": 0.0, "torque": 0.0, "steps": 1}
    rng = plant["rng"] if plant else Rng(0, 0, 0)
    gain = plant.get("gain", 1.0) if plant else 1.0
    queue = [None] * (n + delay + 2)
    acting, tnoise = np.zeros(2), np.zeros(2)
    stage = Stage()
    stage.h = ctl.step
    ctl.reset()
    mujoco.set_mjcb_control(make_callback(robot, ctl, stage))
    try:
        for j in range(n):
            if j % period == 0 and j // period < ctl.control_steps:
                meas = measure(robot, ctl, data, rng, noise)
                queue[j + delay] = gain * ctl.torque(j * ctl.step, meas)
                if ctl.replans:
                    # a replan changes the feed-forward from the instant its plan acts on
                    stage.ff = ctl.feedforward
            if j % noise["steps"] == 0 and noise["torque"] > 0:
                tnoise = np.array([noise["torque"] * rng.normal(), noise["torque"] * rng.normal()])
            if queue[j] is not None:
                acting = queue[j]
            stage.j, stage.t0, stage.extra = j, data.time, acting + tnoise
            mujoco.mj_step(m, data)
            if not np.all(np.isfinite(data.qpos)):
                return float("nan")
    finally:
        mujoco.set_mjcb_control(None)
    r = quat_mul(quat_conj(W), normalised(data.qpos[3:7]))
    return landing_of(r)


# --- controllers -------------------------------------------------------------------

class PackageController:
    """catflip.Controller: the study's design, its gains and feed-forward, exactly."""

    def __init__(self, c):
        self.c = c
        self.replans = c.kind == "replan"
        for k in ("step", "steps", "period_steps", "control_steps", "peak_torque"):
            setattr(self, k, getattr(self.c, k))
        self.sensed, self.clip, self.reset = self.c.sensed, self.c.clip, self.c.reset

    def torque(self, t, state):
        import catflip
        try:
            return self.c.torque(t, state)
        except catflip.DesignError:
            # the prediction over the delay diverged from a state far outside the
            # model: NaN, which loses the flight as catflip's own simulator does
            return np.full(2, np.nan)

    @property
    def feedforward(self):
        return self.c.feedforward

    def nominal_landing(self):
        return self.c.fly().landing_error_deg


# --- the study -----------------------------------------------------------------------

def run_catflip_study(args, out):
    cmd = [args.catflip, "robustness", args.config, "--trials", str(args.trials), "--seed", str(args.seed),
           "--json", "--out", str(out)] + sum((["--set", s] for s in args.overrides), [])
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stderr}")
    summary = json.loads(p.stdout)
    folder = next(pathlib.Path(out).rglob("robustness.csv")).parent
    state = json.loads((folder / "robustness.state.json").read_text())
    return summary, folder, state["config"], time.perf_counter() - t0


def trial_plant(cfg, ctl, d, seed, noise_steps):
    """The trial's delay and noises (src/control/robustness.rs trial_flight)."""
    p = cfg["robustness"]
    return {
        "delay_steps": int(round(p["delay_ms"] * 1e-3 / ctl.step)),
        "noise": {"attitude": math.radians(p["attitude_noise_deg"]), "rate": p["rate_noise_rad_s"],
                  "torque": p["torque_noise"] * ctl.peak_torque, "steps": noise_steps},
        "rng": Rng(seed, d["trial"], 1),
    }


def start_of(base, rate0, d):
    """The trial's release in the simulator's world (Draw::start): the configured start
    `base` (W R0, the MJCF's keyframe) tilted by the draw about catflip's horizontal axis
    (W tilt W' W R0), and the configured body rate `rate0` plus the draw's spin."""
    a, t = math.radians(d["tilt_axis_deg"]), math.radians(d["tilt_deg"])
    tilt = quat_exp([0.0, t * math.cos(a), t * math.sin(a)])
    return quat_mul(quat_mul(W, tilt), quat_mul(quat_conj(W), base)), rate0 + np.asarray(d["spin_rad_s"], float)


# what the trials of a study share (set before the worker processes fork)
_SHARED = {}


def _trial(work):
    """One trial in MuJoCo: (controller name, draw) -> landing error, deg."""
    name, d = work
    g = _SHARED
    c = g["ctls"][name]
    start, body_rate = start_of(g["base"], g["rate0"], d)
    plant = trial_plant(g["cfg"], c, d, g["seed"], g["tv_period"])
    # the open loop's PD gains are off by the draw's factor (the correction is linear in them)
    plant["gain"] = d["pd_gain_factor"] if name == "open-loop" else 1.0
    return fly(g["robot"], c, start, body_rate, d, plant)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--trials", type=int, default=50)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--catflip", default=str(pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
                                             / "release" / "catflip"))
    ap.add_argument("--out", default=None, help="folder under which catflip's study is written, in a "
                    "fresh subfolder (default: a temporary folder)")
    ap.add_argument("--nominal-tol-deg", type=float, default=1e-3)
    ap.add_argument("--route", choices=("auto", "package", "csv"), default="auto",
                    help="controllers from the catflip package (auto: where installed) or from the exported CSVs")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes (default: one per core)")
    ap.add_argument("--trials-csv", default=None, metavar="PATH",
                    help="also write each trial's landing error under each controller, catflip's and MuJoCo's, "
                         "to PATH (a row a trial)")
    args = ap.parse_args()
    main_with(args)


def main_with(args):
    # a fresh folder for this study's files (under --out when given)
    if args.out:
        pathlib.Path(args.out).mkdir(parents=True, exist_ok=True)
    out = pathlib.Path(tempfile.mkdtemp(prefix="study-", dir=args.out))
    summary, folder, cfg, t_catflip = run_catflip_study(args, out)
    rows = draws_of_csv(folder / "robustness.csv")
    # the study's draws are catflip's random streams, redrawn here bit for bit
    for d, _ in rows:
        mine = draw(cfg["robustness"], args.seed, d["trial"])
        if mine != d:
            raise SystemExit(f"trial {d['trial']}: the draws {mine} are not robustness.csv's {d}")
    route = args.route
    if route == "auto":
        try:
            import catflip  # noqa: F401
            route = "package"
        except ImportError:
            route = "csv"
    if route == "package":
        import catflip
        config = catflip.Config.from_toml(args.config, args.overrides)
        mjcf = catflip.export_mjcf(config)
        tvlqr = catflip.Controller(config, kind="tvlqr")
        ctls = {k: PackageController(tvlqr.with_kind(k)) for k in CONTROLLERS}
    else:
        ctls, mjcf = csv_route(args, out, cfg)
    tv_period = ctls["tvlqr"].period_steps
    robot = Robot(mjcf)
    key = robot.nominal.key("start").id
    base = robot.nominal.key_qpos[key, 3:7].copy()
    rate0 = robot.nominal.key_qvel[key, 3:6].copy()
    fails = []
    print(f"closed loop in MuJoCo {mujoco.__version__} on {cfg['name']} ({'ball' if robot.ball else 'hinges'}"
          f"{', DC motors' if robot.dc else ''}), route: {route}; {len(rows)} trials of catflip robustness "
          f"--seed {args.seed} ({t_catflip:.1f} s in catflip)")
    # the nominal trial: MuJoCo against catflip's simulator
    for name, c in ctls.items():
        t0 = time.perf_counter()
        mj = fly(robot, c, base, rate0)
        cf = c.nominal_landing()
        diff = mj - cf
        print(f"  nominal {name:<9}: MuJoCo lands {mj:.6f} deg, catflip {cf:.6f} deg, diff {diff:+.2e} deg "
              f"({time.perf_counter() - t0:.2f} s)")
        if not abs(diff) <= args.nominal_tol_deg:
            fails.append(f"nominal {name}: MuJoCo {mj:.6f} vs catflip {cf:.6f} deg (> {args.nominal_tol_deg:g})")
    tol = summary["max_tilt_deg"]
    if route == "csv":
        print("  (csv route: the study's design read back from the rows of free.csv and its controls, not the\n"
              "  design itself, so the per-trial differences below are larger; docs/control.md)")
    print(f"  success: the belly within {tol:g} deg of straight down at touchdown")
    print(f"  {'controller':<10} {'catflip':>8} {'95 % CI':>15} {'MuJoCo':>8} {'95 % CI':>15} "
          f"{'max |diff| deg':>14} {'disagree':>8} {'MuJoCo s':>9}")
    results = {}
    per_trial = {}
    _SHARED.update(robot=robot, ctls=ctls, base=base, rate0=rate0, cfg=cfg, seed=args.seed, tv_period=tv_period)
    jobs = max(1, min(args.jobs, len(rows)))
    for name, c in ctls.items():
        t0 = time.perf_counter()
        work = [(name, d) for d, _ in rows]
        if jobs > 1:
            import multiprocessing
            with multiprocessing.get_context("fork").Pool(jobs) as pool:
                mine = pool.map(_trial, work, chunksize=1)
        else:
            mine = [_trial(w) for w in work]
        errs, diffs, disagree = [], [], 0
        for e, (d, theirs) in zip(mine, rows):
            e = 180.0 if math.isnan(e) else e
            t = 180.0 if math.isnan(theirs[name]) else theirs[name]
            errs.append(e)
            diffs.append(abs(e - t))
            disagree += (e <= tol) != (t <= tol)
        per_trial[name] = [(theirs[name], e) for e, (_, theirs) in zip(mine, rows)]
        k = sum(e <= tol for e in errs)
        cs = next(x for x in summary["controllers"] if x["name"] == name)
        lo, hi = wilson(k, len(errs))
        results[name] = {"success_rate": k / len(errs), "ci95": [lo, hi]}
        print(f"  {name:<10} {cs['success_rate'] * 100:7.1f}% {cs['ci95'][0] * 100:6.1f}-{cs['ci95'][1] * 100:5.1f} % "
              f"{k / len(errs) * 100:7.1f}% {lo * 100:6.1f}-{hi * 100:5.1f} % {max(diffs):14.2e} {disagree:8d} "
              f"{time.perf_counter() - t0:9.1f}")
    if args.trials_csv:
        write_trials(args.trials_csv, [d["trial"] for d, _ in rows], per_trial)
    print(json.dumps({"trials": len(rows), "seed": args.seed, "mujoco": results,
                      "catflip": {c["name"]: {"success_rate": c["success_rate"], "ci95": c["ci95"]}
                                  for c in summary["controllers"]}}))
    if fails:
        for f in fails:
            print("MISMATCH:", f, file=sys.stderr)
        sys.exit(1)


def write_trials(path, trials, per_trial):
    """A row a trial: its index, then each controller's landing error (deg from belly-down at
    touchdown; nan: the flight diverged), catflip's and MuJoCo's."""
    names = list(per_trial)
    lines = [",".join(["trial"] + [f"{n}_{engine}_deg" for n in names for engine in ("catflip", "mujoco")])]
    for i, t in enumerate(trials):
        lines.append(",".join([str(t)] + [repr(float(x)) for n in names for x in per_trial[n][i]]))
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    print(f"  wrote {path}")


def run_cli(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def csv_route(args, out, cfg):
    """The controllers from the files catflip exports: the study's design as a schedule
    (`catflip optimize --mode free --seed phased`, or `--seed analytic` where the phased one
    cannot fit, as the study, its torque continuous, 2000 rows a phase), then `catflip export mjcf
    --schedule free.csv`: the MJCF, the controls `free.mujoco.csv` and the gains `free.tvlqr.csv`."""
    sets = sum((["--set", s] for s in args.overrides), [])
    # the study's design: a continuous torque, and rows enough that the feed-forward read back from
    # them flies as the design does (200 a phase smooth its torque: docs/control.md)
    design = sets + ["--set", "free.torque_jumps=false", "--set", "simulate.samples_per_phase=2000"]
    code, _, err = run_cli([args.catflip, "optimize", args.config, "--mode", "free", "--seed", "phased",
                            "--out", str(out)] + design)
    if code != 0:
        code, _, err = run_cli([args.catflip, "optimize", args.config, "--mode", "free", "--seed", "analytic",
                                "--out", str(out)] + design)
    if code not in (0, 3):
        raise SystemExit(f"catflip optimize --mode free: exit {code}\n{err}")
    schedule = next(pathlib.Path(out).rglob("free.csv"))
    code, _, err = run_cli([args.catflip, "export", "mjcf", args.config, "--schedule", str(schedule),
                            "--out", str(out)] + sets)
    if code != 0:
        raise SystemExit(f"catflip export mjcf --schedule: exit {code}\n{err}")
    folder = next(pathlib.Path(out).rglob("free.tvlqr.csv")).parent
    mjcf = next(folder.glob("*.mjcf.xml")).read_text()
    robot = Robot(mjcf)
    tv = CsvController(robot, folder / "free.tvlqr.csv", folder / "free.mujoco.csv", "tvlqr")
    return {"open-loop": tv.with_kind("open-loop"), "tvlqr": tv}, mjcf


def read_gains(path):
    """`<stem>.tvlqr.csv`: its `# key = value` lines and its rows."""
    meta, cols, rows = {}, None, []
    for line in pathlib.Path(path).read_text().splitlines():
        if line.startswith("#"):
            k, _, v = line[1:].partition(" = ")
            if v and " " not in k.strip() and " " not in v.strip():
                meta[k.strip()] = float(v)
        elif cols is None:
            cols = line.split(",")
        elif line.strip():
            rows.append([float(x) for x in line.split(",")])
    data = np.array(rows)
    col = lambda name: data[:, cols.index(name)]
    nominal = np.stack([col(c) for c in ("qnom_w", "qnom_x", "qnom_y", "qnom_z", "lnom_1", "lnom_2", "lnom_3",
                                         "qnom_1", "qnom_2", "qdnom_1", "qdnom_2")], axis=1)
    gains = np.stack([np.stack([col(f"K_{i}_{j}") for j in range(10)], axis=1) for i in range(2)], axis=1)
    return meta, col("t_apply_s"), nominal, gains


def momentum(robot, m, d):
    """lambda: the angular momentum about the common centre of mass in the rear half's frame."""
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_comVel(m, d)
    mujoco.mj_subtreeVel(m, d)
    return rotate(quat_conj(normalised(d.qpos[3:7])), d.subtree_angmom[robot.rear])


class CsvController:
    """The study's controllers from catflip's exported files, without the package: the
    TVLQR of `<stem>.tvlqr.csv` (predicting over its delay with MuJoCo's model of the
    robot), the PD on the planned shape of `<stem>.mujoco.csv`, whose held torques are
    the feed-forward."""

    # replanning needs the package: this route has the open loop and the TVLQR
    replans = False

    def __init__(self, robot, gains_csv, controls_csv, kind):
        from replay_common import read_controls
        self.robot, self.kind = robot, kind
        meta, self.t_apply, self.nom, self.k = read_gains(gains_csv)
        self.meta = meta
        self.step, self.steps = meta["step_s"], int(meta["steps"])
        self.delay_steps = int(meta["delay_steps"])
        self.tv_period = int(meta["period_steps"])
        self.period_steps = self.tv_period if kind == "tvlqr" else 1
        self.control_steps = len(self.t_apply) if kind == "tvlqr" else self.steps
        self.peak_torque, self.cap = meta["peak_torque_nm"], meta["max_correction_nm"]
        self.c = c = read_controls(controls_csv)
        pos, vel, ctrl = c["pick"]("qpos"), c["pick"]("qvel"), c["pick"]("ctrl")
        # catflip's coordinates: hinge angles, or the ball's rotation vector (v1, v2) and its rate
        if robot.ball:
            v = np.array([quat_log(p) for p in pos])
            jr = [right_jacobian(x) for x in v]
            self.q_plan = v[:, :2]
            self.qd_plan = np.array([np.linalg.solve(j, w) for j, w in zip(jr, vel)])[:, :2]
            held = np.array([(j.T @ u)[:2] for j, u in zip(jr, ctrl)])
        else:
            self.q_plan, self.qd_plan = pos, vel
            held = ctrl.copy()
            if c["slope"] > 0:
                # DC command tau + k qd, qd averaged over the step
                held[:-1] -= c["slope"] * (pos[1:] - pos[:-1]) / c["dt"]
        # the feed-forward at catflip's half steps: each held torque is the schedule's average
        # over its step, so its value at the step's middle to second order; linear between
        # the middles (a held torque switching inside an RK4 step would cost first order)
        n_rows = int(c["steps"]) - c["margin_steps"]
        mid = (np.arange(n_rows) + 0.5) * c["dt"]
        t = 0.5 * self.step * np.arange(2 * self.steps + 1)
        inside = t < n_rows * c["dt"] * (1 - 1e-12)
        self.feedforward = np.zeros((len(t), 2))
        for i in range(2):
            self.feedforward[inside, i] = np.interp(t[inside], mid, held[:n_rows, i])
        self.issued = []
        self.pred_model = robot.model(None)
        self.pred = mujoco.MjData(self.pred_model)

    def with_kind(self, kind):
        other = object.__new__(CsvController)
        other.__dict__.update(self.__dict__)
        other.kind = kind
        other.period_steps = self.tv_period if kind == "tvlqr" else 1
        other.control_steps = len(self.t_apply) if kind == "tvlqr" else self.steps
        other.issued = []
        other.pred = mujoco.MjData(self.pred_model)
        return other

    def nominal_landing(self):
        return self.meta["nominal_landing_error_deg_" + self.kind.replace("-", "_")]

    def reset(self):
        self.issued = []

    def clip(self, tau, qd):
        from replay_common import limit_catflip_torque
        return limit_catflip_torque(np.asarray(tau, float), np.asarray(qd, float), self.c)

    def _load(self, state, omega=None):
        """The predictor's MuJoCo state at `state` (attitude, lambda, q, qd); with `omega`,
        the rear half's rate instead of lambda."""
        r, m, d = self.robot, self.pred_model, self.pred
        d.qpos[0:3] = [0.0, 0.0, 10.0]
        d.qpos[3:7] = state[:4]
        d.qvel[:] = 0.0
        q, qd = np.asarray(state[7:9], float), np.asarray(state[9:11], float)
        if r.ball:
            v = np.array([q[0], q[1], 0.0])
            d.qpos[r.qa:r.qa + 4] = quat_exp(v)
            d.qvel[r.va:r.va + 3] = right_jacobian(v) @ np.array([qd[0], qd[1], 0.0])
        else:
            d.qpos[r.qa:r.qa + 2], d.qvel[r.va:r.va + 2] = q, qd
        if omega is None:
            # lambda = lambda_0 + A w: the rate that carries the state's momentum
            l0 = momentum(r, m, d)
            a = np.zeros((3, 3))
            for i in range(3):
                d.qvel[3:6] = np.eye(3)[i]
                a[:, i] = momentum(r, m, d) - l0
            omega = np.linalg.solve(a, np.asarray(state[4:7], float) - l0)
        d.qvel[3:6] = omega

    def sensed(self, att, q, qd, gyro):
        s = np.concatenate([att, np.zeros(3), q, qd])
        self._load(s, np.asarray(gyro, float))
        s[4:7] = momentum(self.robot, self.pred_model, self.pred)
        return s

    def torque(self, t, state):
        j = int(math.floor(t / self.step + 1e-9))
        k = j // self.period_steps
        if k >= self.control_steps:
            return self.issued[-1] if self.issued else np.zeros(2)
        self.issued = (self.issued + [np.zeros(2)] * k)[:k]
        if self.kind == "open-loop":
            u = self.c["kp"] * (self.q_plan_at(j)[0] - state[7:9]) + self.c["kd"] * (self.q_plan_at(j)[1] - state[9:11])
        else:
            u = self.tvlqr(k, state)
        self.issued.append(u)
        return u

    def q_plan_at(self, j):
        """The planned (q, qd) at step j (cubic Hermite between the controls' rows)."""
        from replay_common import reference
        t = j * self.step
        dt = self.c["dt"]
        last = len(self.q_plan) - 1
        row = min(int(math.floor(t / dt + 1e-9)), last)
        if row >= last:
            return self.q_plan[last], self.qd_plan[last]
        return reference(self.q_plan, self.qd_plan, row, t / dt - row, dt)

    def tvlqr(self, k, state):
        """The correction of control step k: predict over the delay with MuJoCo's model under
        the corrections sent, u = -K x of the predicted error, capped, the sum with the
        feed-forward inside the envelope at the predicted speed."""
        r, h = self.robot, self.step
        s = int(round(self.t_apply[k] / h))
        j0 = s - self.delay_steps
        self._load(state)
        d = self.pred
        d.time = j0 * h
        outer = _STAGE[0]
        stage = Stage()
        stage.h = h
        _STAGE[0] = stage
        try:
            for i in range(j0, s):
                c = min((i - self.delay_steps) // self.tv_period, len(self.issued) - 1) if i >= self.delay_steps else -1
                stage.j, stage.t0 = i, d.time
                stage.extra = self.issued[c] if c >= 0 else np.zeros(2)
                mujoco.mj_step(self.pred_model, d)
        finally:
            _STAGE[0] = outer
        att = normalised(d.qpos[3:7])
        lam = momentum(r, self.pred_model, d)
        q, qd = shape_of(r, d)
        n = self.nom[k]
        x = np.concatenate([quat_log(quat_mul(quat_conj(n[:4]), att)), lam - n[4:7], q[:2] - n[7:9], qd[:2] - n[9:11]])
        u = -self.k[k] @ x
        size = np.abs(u).max() if self.c["norm"] == "per-motor" else float(np.hypot(u[0], u[1]))
        if size > self.cap:
            u = u * (self.cap / size)
        ff = self.feedforward[2 * s]
        return self.clip(ff + u, qd[:2]) - ff


if __name__ == "__main__":
    main()
