"""catflip: torque schedules that turn a falling two-body cat right side up.

The Python face of the catflip Rust library (the same code as the ``catflip``
command line, called in-process): configs with the CLI's keys and checks,
the analytic, phased and free-form designs as numpy arrays, their forward
simulation, the robot's least drop height, sweeps, the MuJoCo / pyBullet
models and controls, and the closed-loop controllers (``Controller``). Every
solve releases the GIL; every object is safe to share between threads. See docs/python.md.
"""

from ._catflip import (
    CatflipError,
    Config,
    ConfigError,
    Controller,
    Controls,
    Design,
    DesignError,
    Flight,
    ImpossibleError,
    LeastHeight,
    Run,
    Simulation,
    UnitSlipWarning,
    controls,
    design,
    export_mjcf,
    export_urdf,
    least_height,
    robustness,
    run,
    simulate,
    size,
)
from ._catflip import __version__
from ._catflip import sweep_columns as _sweep_columns

from typing import Any as _Any, Literal as _Literal, Sequence as _Sequence, Union as _Union

import numpy as _np
import numpy.typing as _npt

# The stubs' type aliases, here too so that annotations may name them
# (``m: catflip.Method = "free"``); catflip/__init__.pyi has the same.
F64 = _npt.NDArray[_np.float64]
Method = _Literal["free", "phased", "analytic"]
Objective = _Literal["peak-torque", "time", "energy"]
Seed = _Literal["phased", "analytic"]
SimulatorName = _Literal["mujoco", "pybullet"]
Value = _Union[bool, int, float, str, _Sequence[_Any], _np.generic, _npt.NDArray[_Any]]
ControllerKind = _Literal["tvlqr", "open-loop", "replan"]
ArrayLike = _Union[_Sequence[float], F64]

__all__ = [
    "CatflipError",
    "Config",
    "ConfigError",
    "Controller",
    "Controls",
    "Design",
    "DesignError",
    "Flight",
    "ImpossibleError",
    "LeastHeight",
    "Run",
    "Simulation",
    "UnitSlipWarning",
    "controls",
    "design",
    "export_mjcf",
    "export_urdf",
    "least_height",
    "robustness",
    "run",
    "simulate",
    "size",
    "sweep",
]

SWEEP_METHODS = ("analytic", "phased", "free")


def _restore_config(text, origin, overrides, base):
    """Unpickles a ``Config`` (its ``__reduce__``): the text read and checked again."""
    return Config._from_state(text, origin, overrides, base)


def sweep(
    config,
    key,
    values,
    methods=SWEEP_METHODS,
    threads=None,
    frame=None,
    least_height_only=False,
):
    """Sweeps the numeric config key ``key`` over ``values``, as ``catflip sweep``.

    ``methods`` is a list, or one comma-separated string (``"phased,free"``).
    Each value is set on ``config`` as ``config.set(key, value)`` would (the
    same checks, all before any point is computed: a value the key refuses is
    a ``ConfigError`` naming how many are invalid and the first one), and
    every point is designed by each of ``methods``.
    Neighbouring points continue from each other in chunks of 10, computed
    ``threads`` chunks at a time (default: one per core), with the GIL released.

    Returns the CSV's columns: ``value``, ``analytic_peak_nm``,
    ``phased_peak_nm``, ``free_peak_nm``, ``phased_bend_deg``,
    ``free_bend_deg``, ``least_height_phased_m``, ``least_height_free_m``
    (float64 arrays of shape ``(len(values),)``, NaN where a method gave no
    number), ``free_status`` and ``error`` (lists of str or None). As a
    ``pandas.DataFrame`` when pandas is installed and ``frame`` is not False
    (``frame=True`` requires pandas), else as a dict of those columns; the
    dict also holds ``"csv"``, the text of the CLI's ``sweep-<key>.csv``.

    Under motor limits the peak columns are the least-peak designs *without*
    the limits (the torque each method needs), as in the CLI's sweep; whether
    the motors can do it at a point is read from the least-height columns
    (where the lower is below the point's ``fall.height``), not from
    ``free_status``. With ``least_height_only=True`` (``--least-height-only``)
    only the least heights are computed: inside a motor envelope the peak
    columns are then NaN (under a stall torque alone the least heights come
    from the peaks, which are given); a config without ``limits.max_torque``
    is a ``ConfigError``.
    """
    import numpy as np

    if isinstance(methods, str):
        methods = [m.strip() for m in methods.split(",")]
    if values is None or isinstance(values, (str, bytes)):
        # (numpy reads None as NaN, which the key would refuse as a value)
        raise TypeError(f"values = {values!r}: give the values to sweep, a sequence of numbers")
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as e:
        raise ConfigError(
            f"{key}: values = {values!r} are not numbers ({e}): sweep takes a numeric key and its values"
        ) from None
    if array.ndim != 1:
        raise ConfigError(
            f"{key}: values = {values!r} are not one sequence of numbers: sweep takes a numeric key, one value a point"
        )
    values = [float(v) for v in array]
    columns, csv = _sweep_columns(
        config, key, values, list(methods), threads, bool(least_height_only)
    )
    if frame is None or frame:
        try:
            import pandas as pd
        except ImportError:
            if frame:
                raise
        else:
            return pd.DataFrame(columns)
    columns["csv"] = csv
    return columns
