"""catflip from Python: design a flip, plot it, replay it in MuJoCo.

    pip install ./python matplotlib mujoco    # docs/python.md
    python examples/python/quickstart.py      # prints the flips, writes quickstart.png
"""
import math
import pathlib

import matplotlib
matplotlib.use("Agg")  # files, no window
import matplotlib.pyplot as plt
import mujoco

import catflip

config = catflip.Config.from_toml(pathlib.Path(__file__).parents[2] / "configs" / "seed.toml")
design = catflip.design(config)  # free-form, least peak torque: arrays t (N,), q and tau (N, 2)
print(design, "stopped by", design.certificate["rule"])

fig, (top, bottom) = plt.subplots(2, sharex=True)
top.plot(design.t, design.q, label=["q1", "q2"]), top.set_ylabel("joint angle, rad"), top.legend()
bottom.plot(design.t, design.tau), bottom.set(xlabel="t, s", ylabel="torque, N m")
fig.savefig("quickstart.png", dpi=120)

model = mujoco.MjModel.from_xml_string(catflip.export_mjcf(config))
controls = catflip.controls(design, "mujoco")  # one row per MuJoCo step, torques to hold
model.opt.timestep = controls.dt
data = mujoco.MjData(model)
mujoco.mj_forward(model, data)
rear = model.body("rear").id
w0, x0, y0, z0 = data.xquat[rear].copy()
flip = last = 0.0
for torque in controls.torque[:-1]:  # feed-forward only
    data.ctrl[:] = torque
    mujoco.mj_step(model, data)
    w, x, y, z = data.xquat[rear]  # rotation about the initial spine, unwrapped
    turn = 2 * math.atan2(w0 * z - x0 * y + y0 * x - z0 * w, w0 * w + x0 * x + y0 * y + z0 * z)
    flip, last = flip + (turn - last + math.pi) % (2 * math.pi) - math.pi, turn
print(f"MuJoCo flip {math.degrees(flip):.4f} deg, catflip's simulation {design.flip_deg:.4f} deg")
