"""Shared parts of replay_mujoco.py and replay_pybullet.py: reading catflip's
exported controls and summary (from a `catflip run` folder, or made in-process
by the catflip Python package from a config), rotation helpers, the flip
convention, and the comparison table. Needs numpy only (and the catflip
package for a config)."""

import argparse
import atexit
import json
import math
import pathlib
import shutil
import sys
import tempfile

import numpy as np


def read_controls(path):
    """Header keys (`# key = value` lines), column names and the rows of a
    `<method>.<simulator>.csv` written by catflip."""
    meta, cols, rows = {}, None, []
    for line in pathlib.Path(path).read_text().splitlines():
        if line.startswith("#"):
            if " = " in line:
                k, v = line[1:].split(" = ", 1)
                meta[k.strip()] = v.strip()
        elif cols is None:
            cols = line.split(",")
        elif line.strip():
            rows.append([float(x) for x in line.split(",")])
    data = np.array(rows)
    vec = lambda key, default: np.array([float(x) for x in meta[key].split()]) if key in meta \
        else np.array(default, float)
    dt = float(meta["dt_s"])
    # the landing margin: the replay goes on with the shape held straight (last row, at rest,
    # no feed-forward) until touchdown
    margin = float(meta.get("margin_s", "0"))
    # (steps of margin / extra each: the margin exactly, a spinning cat turns on during it)
    extra = int(math.ceil(margin / dt - 1e-9)) if margin > 0 else 0
    if extra > 0:
        last = data[-1].copy()
        for i, c in enumerate(cols):
            if c.startswith(("qvel", "vel", "ctrl", "force")):
                last[i] = 0.0
        tail = np.tile(last, (extra, 1))
        tail[:, 0] = data[-1, 0] + dt * np.arange(1, extra + 1)
        data = np.vstack([data, tail])
    pick = lambda prefix: data[:, [i for i, c in enumerate(cols) if c.startswith(prefix)]]
    limit = None if meta["max_torque_nm"] == "none" else float(meta["max_torque_nm"])
    return {
        "start_attitude": vec("start_attitude_wxyz", [1, 0, 0, 0]),
        "start_body_rate": vec("start_body_rate_rad_s", [0, 0, 0]),
        "start_base_quat": vec("start_base_quat", []),
        "start_base_linear_velocity": vec("start_base_linear_velocity", [0, 0, 0]),
        "start_base_angular_velocity": vec("start_base_angular_velocity", [0, 0, 0]),
        "margin_steps": extra,
        "margin_dt": margin / extra if extra else dt,
        "slope": float(meta.get("motor_slope_nm_s", "0")),
        "dt": dt,
        "steps": int(meta["steps"]) + extra,
        "kp": float(meta["pd_kp"]),
        "kd": float(meta["pd_kd"]),
        "limit": limit,
        "norm": meta["peak_norm"],
        "t": data[:, 0],
        "cols": cols,
        "data": data,
        "pick": pick,
    }


# --- rotations (quaternions as w, x, y, z) ---------------------------------

def quat_mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])


def quat_conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def quat_log(q):
    """Rotation vector of a unit quaternion (w, x, y, z)."""
    q = np.asarray(q, float)
    if q[0] < 0:
        q = -q
    s = np.linalg.norm(q[1:])
    if s < 1e-12:
        return 2.0 * q[1:]
    return q[1:] * (2.0 * math.atan2(s, q[0]) / s)


def hat(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def right_jacobian(v):
    """J_r(v): exp(v + dv) = exp(v) exp(J_r(v) dv); child-frame rate = J_r(v) v_dot."""
    t2 = float(v @ v)
    h = hat(v)
    if t2 < 1e-8:
        b, c = 0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0
    else:
        t = math.sqrt(t2)
        b, c = (1.0 - math.cos(t)) / t2, (t - math.sin(t)) / (t2 * t)
    return np.eye(3) - b * h + c * h @ h


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def landing_of(r):
    """The belly's (rear x) angle from straight down (catflip's -x), deg, of the
    rear half's attitude `r` (w, x, y, z) in catflip's world."""
    w, x, y, z = r
    belly = (1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y))
    return math.degrees(math.atan2(math.hypot(belly[1], belly[2]), -belly[0]))


class FlipTracker:
    """catflip's one flip convention (src/model/so3.rs FlipTracker): rotation
    about the reference spine (catflip's world z), right-handed, from the
    swing-twist split of the rear half's attitude in catflip's world, unwrapped
    along the run. Tilt: angle between the spine and the reference spine.
    `q0` is the simulator's attitude at release and `start` the release attitude
    in catflip's world (R0), so that the attitude in catflip's world is
    `R0 q0^-1 q`. Landing error: the belly's (rear x) angle from straight down
    (catflip's -x), docs/model.md section 8."""

    def __init__(self, q0, start=(1.0, 0.0, 0.0, 0.0)):
        self.q0 = quat_mul(np.asarray(q0, float), quat_conj(np.asarray(start, float)))
        self.last = 0.0
        self.acc = 0.0
        self.tilt = 0.0
        self.landing = float("nan")
        self.push(q0)

    def push(self, q):
        r = quat_mul(quat_conj(self.q0), np.asarray(q, float))
        self.r = r
        self.landing = landing_of(r)
        f = 2.0 * math.atan2(r[3], r[0])
        self.acc += wrap(f - self.last)
        self.last = f
        # spine z after rotation r: third component of R(r) e_z
        zz = 1.0 - 2.0 * (r[1] ** 2 + r[2] ** 2)
        self.tilt = math.acos(max(-1.0, min(1.0, zz)))
        return self.acc


def limit_catflip_torque(tau_v, qd, c):
    """catflip's motor envelope on its two joint torques at joint speed `qd`
    (src/model/motor.rs Motor::clip): |tau + k qd| <= T per motor, or the disc
    of radius T about -k qd for the Euclidean norm."""
    limit, k = c["limit"], c["slope"]
    if limit is None:
        return tau_v
    tau_v = np.array(tau_v, float)
    centre = -k * np.asarray(qd[:2], float)
    e = tau_v[:2] - centre
    if c["norm"] == "per-motor":
        e = np.clip(e, -limit, limit)
    else:
        n = math.hypot(e[0], e[1])
        if n > limit:
            e *= limit / n
    tau_v[:2] = centre + e
    return tau_v


def reference(pos, vel, k, x, dt):
    """The planned position and velocity a fraction `x` into step `k` (cubic Hermite
    between the rows, the schedule's own interpolation), for a controller that runs
    inside the step."""
    h00, h10, h01, h11 = 2 * x**3 - 3 * x**2 + 1, x**3 - 2 * x**2 + x, -2 * x**3 + 3 * x**2, x**3 - x**2
    g00, g10, g01, g11 = 6 * x**2 - 6 * x, 3 * x**2 - 4 * x + 1, -6 * x**2 + 6 * x, 3 * x**2 - 2 * x
    p0, p1, v0, v1 = pos[k], pos[k + 1], vel[k] * dt, vel[k + 1] * dt
    return h00 * p0 + h10 * v0 + h01 * p1 + h11 * v1, (g00 * p0 + g10 * v0 + g01 * p1 + g11 * v1) / dt


def peak_of(tau_v, norm):
    return max(abs(tau_v[0]), abs(tau_v[1])) if norm == "per-motor" else math.hypot(tau_v[0], tau_v[1])


# --- command line and report -----------------------------------------------

def parse_args(engine, default_tol):
    p = argparse.ArgumentParser(
        description=f"Replay catflip's exported schedules in {engine}, feed-forward only and "
        "feed-forward + PD, and compare with catflip's summary.json."
    )
    p.add_argument("output", help="catflip's output folder of one config, e.g. output/seed/run; or, "
                   "with the catflip Python package installed (pip install ./python), a config such "
                   "as configs/seed.toml, run in-process (the same files, not written)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="with a config: override a key, as catflip's --set (repeatable)")
    p.add_argument("--methods", default=None,
                   help="comma-separated methods (default: all in summary.json)")
    p.add_argument("--tol-deg", type=float, default=None,
                   help=f"largest |flip - catflip's flip| of the checked PD replay, deg (default {default_tol}"
                   + (f"; {RIDING_FACTOR * default_tol:g} for a schedule that rides the motors' torque-speed line)"
                      if engine == "MuJoCo" else ")"))
    p.add_argument("--ff-tol-deg", type=float, default=0.05,
                   help="largest |flip - catflip's flip| of the feed-forward-only replay of an "
                   "optimised, unsaturated schedule, deg (default 0.05)")
    p.add_argument("--land-tol-deg", type=float, default=None,
                   help="largest landing error (the belly's angle from straight down) of every replay, "
                   "feed-forward only and with PD, of the methods in --land-methods: for designs made "
                   "from the configured start (default: not checked)")
    p.add_argument("--land-methods", default="free",
                   help="comma-separated methods whose landing --land-tol-deg checks (default: free)")
    args = p.parse_args()
    args.default_tol_deg = default_tol
    return args


# A schedule whose envelope margin is below this rides the motors' torque-speed
# line, where MuJoCo's DC motors and catflip's saturated simulation part by more
# than elsewhere (docs/replay.md): MuJoCo's default tolerance is RIDING_FACTOR
# times its own there.
RIDING_MARGIN = 0.01
RIDING_FACTOR = 5.0


def pd_tolerance(tol_deg, default_deg, method, riding_factor=1.0):
    """The checked PD replay's tolerance for one method of summary.json, deg:
    --tol-deg when given, else the engine's default, `riding_factor` times that
    for a schedule that rides the torque-speed line or leaves it (a negative
    margin: both simulators clip it to the line, and ride it)."""
    if tol_deg is not None:
        return tol_deg
    margin = method.get("min_envelope_margin")
    riding = margin is not None and margin < RIDING_MARGIN
    return default_deg * (riding_factor if riding else 1.0)


def run_folder(arg, overrides):
    """The folder of `catflip run`'s files: `arg` itself (the CSV route), or for a
    `.toml` config the files of `catflip.run(config)`, made in-process by the Python
    package and put in a temporary folder, so that both routes read the same files."""
    path = pathlib.Path(arg)
    if path.suffix != ".toml":
        if overrides:
            raise SystemExit("--set applies to a config; a run folder is replayed as it was written")
        return path
    try:
        import catflip
    except ImportError:
        raise SystemExit(f"{arg} is a config: replaying it needs the catflip Python package "
                         "(pip install ./python, docs/python.md); or give the folder `catflip run` wrote")
    try:
        run = catflip.run(catflip.Config.from_toml(path, overrides))
    except catflip.CatflipError as e:
        raise SystemExit(f"error: {e}")
    folder = pathlib.Path(tempfile.mkdtemp(prefix="catflip-run-"))
    atexit.register(shutil.rmtree, folder, True)
    for name in run.names:
        (folder / name).write_text(run.file(name))
    print(f"{arg}: designed in-process by the catflip package (catflip.run, {run.outcome})", file=sys.stderr)
    return folder


def load_summary(out):
    """`catflip run`'s summary.json in `out`, or a plain exit naming what to give."""
    path = pathlib.Path(out) / "summary.json"
    if not pathlib.Path(out).is_dir():
        raise SystemExit(f"{out}: no such folder; give the folder `catflip run` wrote "
                         "(output/<name>/run) or a .toml config")
    if not path.is_file():
        raise SystemExit(f"{out} has no summary.json: it is not a folder `catflip run` wrote "
                         "(an `export` or `optimize` folder has no methods to compare); give "
                         "output/<name>/run, or a .toml config")
    return json.loads(path.read_text())


def report(engine, summary, results, flip_tol, ff_tol, land_tol=None, land_methods=(), land_modes=None):
    """Prints the table; returns the list of failures. `flip_tol` maps a mode to
    a function of the summary's method giving the largest |flip - catflip's|
    allowed, deg (`pd_tolerance`); `ff_tol` (or None) bounds the feed-forward-only
    flip of optimised, unsaturated schedules."""
    print(f"{engine} replay of {summary['name']} ({summary['joint']} joint); flip in catflip's convention")
    print(f"  {'method':<12} {'mode':<5} {'flip deg':>16} {'catflip deg':>16} {'diff deg':>10} {'tilt deg':>10} "
          f"{'landing deg':>12} {'catflip deg':>12} {'diff deg':>10} "
          f"{'shape err rad':>13} {'peak N m':>10} {'catflip N m':>11}")
    fails = []
    for name, mode, r in results:
        m = next(x for x in summary["methods"] if x["method"] == name)
        diff = r["flip_deg"] - m["flip_deg"]
        land = m.get("landing_error_deg", float("nan"))
        ldiff = r["landing_deg"] - land
        print(f"  {name:<12} {mode:<5} {r['flip_deg']:16.9f} {m['flip_deg']:16.9f} {diff:10.2e} "
              f"{r['tilt_deg']:10.2e} {r['landing_deg']:12.6f} {land:12.6f} {ldiff:10.2e} "
              f"{r['shape_error_rad']:13.2e} {r['peak_nm']:10.5f} {m['sim_peak_torque_nm']:11.5f}")
        if land_tol is not None and name in land_methods and (land_modes is None or mode in land_modes) \
                and not r["landing_deg"] <= land_tol:
            fails.append(f"{name}: {mode} replay lands {r['landing_deg']:.3e} deg from belly-down "
                         f"(> {land_tol:g}, --land-tol-deg)")
        tol = flip_tol[mode](m) if mode in flip_tol else None
        if tol is not None and not abs(ldiff) <= tol:
            fails.append(f"{name}: {mode} replay lands {ldiff:.3e} deg from catflip's landing (> {tol:g})")
        # a schedule that asks more than the motors give (a peak over the stall torque, or
        # outside the torque-speed envelope) runs saturated: open loop it drifts
        saturating = (summary.get("max_torque_nm") is not None
                      and m["peak_torque_nm"] > summary["max_torque_nm"]) \
            or (m.get("min_envelope_margin") is not None and m["min_envelope_margin"] < 0)
        if tol is not None and abs(diff) > tol:
            fails.append(f"{name}: {mode} replay flip differs by {diff:.3e} deg (> {tol:g})")
        # the checked feedback replay (MuJoCo: pd; pyBullet: pd-x, its step error removed)
        if mode in flip_tol:
            # the controls hold each step's mean torque: a peak narrower than a step (a torque
            # that jumps at a phase boundary and falls steeply) is below catflip's by as much
            # in the exported feed-forward itself, which any engine replays
            # (at most 5 % of it: more would be an export that asks too little)
            sim = m["sim_peak_torque_nm"]
            held = min(max(0.0, sim - r["ff_peak_nm"]), 0.05 * sim)
            if not sim * 0.98 - held <= r["peak_nm"] <= sim * 1.02:
                fails.append(f"{name}: PD replay peak torque {r['peak_nm']:.5f} vs catflip "
                             f"{sim:.5f} N m (> 2 %, {held:.5f} N m below it allowed for the "
                             f"controls' step means)")
            # as straight as catflip's own flight ends, to 1e-3 rad (the analytic reference
            # from a spinning start ends 1.6e-3 rad off in both)
            straight = 1e-3 + (m.get("final_shape_error_rad") or 0.0)
            if not saturating and r["shape_error_rad"] > straight:
                fails.append(f"{name}: PD replay ends {r['shape_error_rad']:.2e} rad from straight "
                             f"(catflip's flight {straight - 1e-3:.2e})")
        elif mode == "ff" and ff_tol is not None and name != "analytic" and not saturating \
                and not r.get("spinning") and abs(diff) > ff_tol:
            fails.append(f"{name}: feed-forward replay flip differs by {diff:.3e} deg (> {ff_tol:g})")
    print("  landing = the belly's angle from straight down at touchdown (after fall.margin); a spinning\n"
          "  start's feed-forward-only replay is not checked (a zero-momentum schedule drifts open loop).")
    print("  modes: ff = feed-forward only, pd = feed-forward + catflip's PD. catflip = summary.json: its own\n"
          "  simulation (feed-forward + PD, the config's torque limit); a saturating schedule is compared\n"
          "  with that saturated simulation.")
    return fails


def finish(fails):
    if fails:
        for f in fails:
            print("MISMATCH:", f, file=sys.stderr)
        sys.exit(1)
    print("  all replays agree with catflip")
