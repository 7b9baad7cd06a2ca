"""MuJoCo's inverse dynamics of catflip's bodies against catflip's torques.

Reads what `cargo run --release --example inverse_dynamics -- DIR` wrote. For
each sample the robot floats freely with zero momentum: the base velocity
that cancels the base's generalised momentum, then the base acceleration that
leaves no force on the base (free fall), then the hinge forces MuJoCo needs,
compared with catflip's torque. Models: catflip's MJCF export, the bundled
configs/box-robot.urdf itself (a free joint added to its root), and catflip's
URDF export, whose cross link carries 1e-8 of a half's mass (CROSS_FRACTION in
src/export/urdf.rs), so it agrees only to about that.
`python examples/inverse_dynamics_mujoco.py DIR` exits 1 on a mismatch.
"""
import sys
from pathlib import Path

try:
    import mujoco
    import numpy as np
except ModuleNotFoundError as missing:
    sys.exit(f"this script needs the `{missing.name}` Python package: "
             "python3 -m venv venv && venv/bin/pip install mujoco pybullet numpy (docs/replay.md)")

TOL = 1e-9


def load(path):
    if path.suffix == ".urdf":
        spec = mujoco.MjSpec.from_file(str(path))
        root = spec.worldbody.first_body()
        root.add_freejoint()
        return spec.compile()
    return mujoco.MjModel.from_xml_path(str(path))


def worst_error(model, rows):
    data = mujoco.MjData(model)
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    assert len(hinges) == 2, f"expected two hinges, found {len(hinges)}"
    jd = [model.jnt_dofadr[j] for j in hinges]
    jq = [model.jnt_qposadr[j] for j in hinges]
    base = list(range(6))
    worst, scale = 0.0, max(np.abs(rows[:, 7:9]).max(), 1e-300)
    full = np.zeros((model.nv, model.nv))
    for r in rows:
        q, qd, qdd, tau = r[1:3], r[3:5], r[5:7], r[7:9]
        data.qpos[:] = model.qpos0
        data.qpos[3:7] = [1, 0, 0, 0]
        data.qpos[jq] = q
        data.qvel[:] = 0
        data.qvel[jd] = qd
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, full)
        mbb, mbj = full[np.ix_(base, base)], full[np.ix_(base, jd)]
        data.qvel[base] = -np.linalg.solve(mbb, mbj @ qd)
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, full)
        c = data.qfrc_bias.copy()
        mbb, mbj = full[np.ix_(base, base)], full[np.ix_(base, jd)]
        ab = -np.linalg.solve(mbb, mbj @ qdd + c[base])
        mjb, mjj = full[np.ix_(jd, base)], full[np.ix_(jd, jd)]
        tau_mj = mjb @ ab + mjj @ qdd + c[jd]
        worst = max(worst, np.abs(tau_mj - tau).max() / scale)
    return worst


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "target/ci-id")
    repo = Path(__file__).resolve().parent.parent
    fails = 0
    for name in ["box-robot", "lopsided"]:
        rows = np.loadtxt(out / f"{name}.csv", delimiter=",", skiprows=1)
        models = [(out / f"{name}.mjcf.xml", TOL), (out / f"{name}.urdf", 1e-6)]
        if name == "box-robot":
            models.insert(1, (repo / "configs" / "box-robot.urdf", TOL))
        for path, tol in models:
            err = worst_error(load(path), rows)
            ok = err <= tol
            fails += not ok
            print(f"{name}: {path.parent.name}/{path.name}: largest torque difference {err:.2e} of the peak "
                  f"({'ok' if ok else 'FAIL'}, tolerance {tol:g})")
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()
