"""A typed use of the package's public names, checked by `mypy --strict` in .ci/run
against the stubs (catflip/__init__.pyi): a stub that disagrees with how the
package is used here (a missing name, a wrong return type) fails the check.
It also runs (`python python/typing/controller_usage.py`): the robot's TVLQR fed its
own nominal states, and a flight of the study."""

from typing import List

import numpy as np
import numpy.typing as npt

import catflip


def corrections(controller: catflip.Controller, states: npt.NDArray[np.float64]) -> List[float]:
    """The largest correction along `states`, one per control step, N m."""
    controller.reset()
    out: List[float] = []
    for k in range(controller.control_steps):
        u: npt.NDArray[np.float64] = controller.torque(k * controller.period, states[k * controller.period_steps])
        out.append(float(np.abs(u).max()))
    return out


def main() -> None:
    seed = catflip.Config.from_toml("configs/seed.toml")
    # numpy scalars and arrays are config values (the stub's `Value`)
    seed.set("fall.height", np.float32(10.0))
    seed.set("start.angular_velocity", np.zeros(3))
    method: catflip.Method = "free"
    along: catflip.Controller = catflip.Controller(seed, catflip.design(seed, method), kind="tvlqr")
    print(f"seed, along its free-form design: {along.control_steps} control steps")
    # the robot from 1.2 times its least height, along the study's own design
    config = catflip.Config.from_toml("configs/robot-universal.toml", ["fall.height=4.25"])
    tvlqr = catflip.Controller(config, kind="tvlqr")
    pd: catflip.Controller = tvlqr.with_kind("open-loop")
    flight: catflip.Flight = tvlqr.fly(trial=0, seed=1)
    landing: float = flight.landing_error_deg
    gains: npt.NDArray[np.float64] = tvlqr.gains
    ff = tvlqr.feedforward
    tau = tvlqr.clip(ff[0] + tvlqr.torque(0.0, tvlqr.nominal[0]), [0.0, 0.0])
    state = tvlqr.sensed([1.0, 0.0, 0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0, 0.1])
    largest = max(corrections(tvlqr, tvlqr.nominal))
    print(f"{tvlqr!r}: gains {gains.shape}, first torque {tau}, state {state.shape}, "
          f"nominal corrections <= {largest:.1e} N m, trial 0 lands {landing:.3f} deg, "
          f"PD every {pd.period:.2e} s")
    # the replanning controller on a robot's clock: a replan over the period is dropped
    replan = catflip.Controller(config, kind="replan", budget_s=tvlqr.period)
    kind: catflip.ControllerKind = replan.kind
    first: npt.NDArray[np.float64] = replan.torque(0.0, replan.nominal[0])
    print(f"{kind}: first correction {first}, feed-forward {replan.feedforward.shape}")


if __name__ == "__main__":
    main()
