"""Type stubs of catflip (the Python bindings of the catflip Rust library).

Long calls (``design``, ``run``, ``least_height``, ``size``, ``sweep``, ``robustness``,
``Controller(...)``) run with the GIL released and end at Ctrl-C with KeyboardInterrupt
within 50 ms (a sweep starts no new point, a study no new trials; other work finishes in
the background, its result dropped).

Shapes: N schedule rows (3 phases of ``simulate.samples_per_phase + 1``
samples; a phase junction appears twice), M simulation steps, n simulator
steps. Every array is a fresh float64 (``phase``: int64) numpy array.
"""

import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

# the type aliases below exist at runtime too (``catflip.Method``), for annotations
F64 = npt.NDArray[np.float64]
Method = Literal["free", "phased", "analytic"]
Objective = Literal["peak-torque", "time", "energy"]
Seed = Literal["phased", "analytic"]
SimulatorName = Literal["mujoco", "pybullet"]
# (numpy scalars and arrays are taken as the number or list they hold)
Value = Union[bool, int, float, str, Sequence[Any], np.generic, npt.NDArray[Any]]

SWEEP_METHODS: Tuple[str, str, str]

class CatflipError(Exception):
    """Base of catflip's errors."""

class ConfigError(CatflipError):
    """Bad input: config, key, value or file (the CLI's exit status 2). The message is the CLI's."""

class DesignError(CatflipError):
    """A computation failed: solver, simulation (the CLI's exit status 1). The message is the CLI's."""

class ImpossibleError(DesignError):
    """The motors cannot flip the cat from ``fall.height``; the message gives the least drop
    height, or says how to find it (``catflip run``; here ``least_height``) (``catflip optimize`` stops with it and
    ``catflip run`` reports it, both exit 4)."""

class UnitSlipWarning(UserWarning):
    """A config value that is valid but likely a unit slip (the CLI's ``warning:`` lines),
    warned when a config is read or set."""

class Config:
    """A checked catflip configuration: the CLI's TOML keys, defaults and checks.

    Safe to share between threads: ``set`` takes a lock, and every computation
    works on a copy taken when it starts. Copies (``copy``, ``copy.copy``,
    ``copy.deepcopy``) are independent; a pickled config is read and checked
    again when unpickled (a robot file from the same path)."""

    @staticmethod
    def from_toml(path: Union[str, os.PathLike[str]],
                  overrides: Union[str, Sequence[str], None] = None) -> Config:
        """Reads and checks a TOML config file with the CLI's ``--set KEY=VALUE`` ``overrides``
        (one string or a list; as ``catflip CMD FILE --set ...``); raises ConfigError."""
    @staticmethod
    def from_text(text: str, origin: str = "<string>") -> Config:
        """Checks a config given as TOML text; ``origin`` names it in messages. A relative
        robot file (``body.urdf``) is read from the current folder."""
    @staticmethod
    def from_dict(d: Dict[str, Any]) -> Config:
        """Checks a config given as a dict of the TOML's tables
        (``{"name": ..., "cat": {...}, "fall": {...}}``): numbers (numpy's too), true/false,
        strings, lists and numpy arrays; a key whose value is None is left unset, as
        ``to_dict`` gives it. A relative robot file (``body.urdf``) is read from the current
        folder."""
    def set(self, key: str, value: Value) -> None:
        """Sets one key, e.g. ``set("fall.height", 6)``, with the CLI's ``--set`` checks and
        messages (a whole float such as ``40.0`` sets a whole-number key, as ``sweep``
        takes its values); on a ConfigError the config is left as it was."""
    def copy(self) -> Config:
        """An independent copy (later ``set``s on either leave the other alone)."""
    def to_dict(self) -> Dict[str, Any]:
        """Every key that has a value, defaults included, as nested dicts (an optional key
        left unset is absent or None; None leaves a key unset in ``from_dict``);
        ``Config.from_dict`` reads it back. A robot file's path (``body.urdf``) is absolute."""
    def to_toml(self) -> str:
        """Every key with its value, defaults included, as TOML text (``Config.from_text``
        reads it back). A robot file's path (``body.urdf``) is absolute."""
    @property
    def name(self) -> str:
        """The config's ``name`` (the CLI's output folder ``output/<name>/``)."""
    @property
    def slips(self) -> List[str]:
        """The config's likely unit slips (the CLI's warnings), in words."""
    @property
    def overrides(self) -> List[str]:
        """The ``KEY=VALUE`` overrides applied so far (``from_toml``'s, then each ``set``), in order."""
    @property
    def fall_time(self) -> float:
        """``sqrt(2 h / g)``, s."""
    @property
    def manoeuvre_time(self) -> float:
        """Time for the manoeuvre: fall time minus ``fall.margin``, s."""

class Design:
    """A designed schedule: what ``catflip optimize --mode free|phased`` (or ``analyze``) writes.

    Immutable; the arrays are fresh copies on each access."""

    @property
    def method(self) -> Method:
        """``free``, ``phased`` or ``analytic``."""
    @property
    def status(self) -> str:
        """Solver status: ``converged``, ``iteration-limit``, ``stalled`` (free), ``solved``
        (phased), ``closed-form`` (analytic)."""
    @property
    def verdict(self) -> Literal["ok", "flagged"]:
        """``flagged`` when the design misses a target (solver status, flip or tilt, a limit)."""
    @property
    def reason(self) -> Optional[str]:
        """Why it is flagged, in the CLI's words; None when ok."""
    @property
    def peak(self) -> float:
        """Peak joint torque of the schedule (inverse dynamics, sampled densely), N m."""
    @property
    def energy(self) -> float:
        """``integral |tau|^2 dt`` over the rows, N^2 m^2 s."""
    @property
    def durations(self) -> Tuple[float, float, float]:
        """Phase durations (fold, twist, unfold), s."""
    @property
    def duration(self) -> float:
        """Manoeuvre time, s."""
    @property
    def certificate(self) -> Optional[Dict[str, Any]]:
        """The free-form optimiser's stopping certificate (``step``, ``constraint_violation``,
        ``criticality``, ``radius``, ``weight``, ``rule``); None for the other methods."""
    @property
    def flip_deg(self) -> float:
        """Flip of the design's flight, deg (dynamic for free and phased, as ``optimize`` flies it; kinematic for analytic)."""
    @property
    def config(self) -> Config:
        """The config the design was made with (with ``objective`` applied)."""
    @property
    def t(self) -> F64:
        """Sample times, s: shape (N,)."""
    @property
    def phase(self) -> npt.NDArray[np.int64]:
        """Phase of each row, 0 fold, 1 twist, 2 unfold: shape (N,)."""
    @property
    def q(self) -> F64:
        """Joint angles q1, q2, rad: shape (N, 2)."""
    @property
    def qd(self) -> F64:
        """Joint rates, rad/s: shape (N, 2)."""
    @property
    def qdd(self) -> F64:
        """Joint accelerations, rad/s^2: shape (N, 2)."""
    @property
    def tau(self) -> F64:
        """Joint torques tau1, tau2, N m: shape (N, 2)."""
    def to_dict(self) -> Dict[str, Any]:
        """The summary ``to_json()`` gives, as a dict."""
    def to_json(self) -> str:
        """The CLI's ``free.json`` / ``phased.json`` / ``analyze.json``, with ``verdict`` and ``reason``."""
    def to_csv(self) -> str:
        """The CLI's ``<method>.csv`` schedule."""
    def schedule_json(self) -> str:
        """The CLI's ``<method>.schedule.json``."""

def design(config: Config, method: Method = "free", objective: Optional[Objective] = None,
           seed: Optional[Seed] = None) -> Design:
    """Designs a torque schedule, as the CLI's ``optimize --mode METHOD [--seed SEED]``
    (``analyze`` for ``method="analytic"``), with the GIL released.

    ``objective`` overrides ``design.objective`` (phased and free only: the analytic schedule
    optimises nothing); ``seed`` (``"phased"``, ``"analytic"``;
    None: the phased design, or where no phased one fits the motors in this fall, and
    always for the ``"time"`` objective, the least-height answer's shortest manoeuvre, as
    ``run`` and ``optimize``) applies to
    ``method="free"`` only. Raises ConfigError, ImpossibleError
    (the motors cannot flip the cat from ``fall.height``) or DesignError (also a named phased
    seed that does not fit), with the CLI's messages."""

class Simulation:
    """A forward simulation in the full free-floating model (feed-forward, PD if ``simulate.pd``,
    the motor envelope), as ``catflip simulate``."""

    @property
    def flip_deg(self) -> float:
        """Final rotation about the initial spine, unwrapped, deg."""
    @property
    def flip_error_rad(self) -> float:
        """``pi - |flip|``, rad."""
    @property
    def tilt_deg(self) -> float:
        """Angle between the final and the initial spine, deg."""
    @property
    def final_shape_error_rad(self) -> float:
        """``|q(T)|``: how far from straight the cat ends, rad."""
    @property
    def momentum_drift_nms(self) -> float:
        """Largest angular momentum recomputed from the bodies' velocities, N m s."""
    @property
    def peak_torque_nm(self) -> float:
        """Largest joint torque applied, N m (the config's norm)."""
    @property
    def verdict(self) -> Literal["ok", "flagged"]:
        """``flagged`` when the flip or tilt misses ``simulate.flip_tolerance``."""
    @property
    def reason(self) -> Optional[str]:
        """Why it is flagged; None when ok."""
    @property
    def t(self) -> F64:
        """Step times, s: shape (M,)."""
    @property
    def flip(self) -> F64:
        """Flip at each step, rad: shape (M,)."""
    @property
    def tilt(self) -> F64:
        """Tilt at each step, rad: shape (M,)."""
    @property
    def q(self) -> F64:
        """Joint angles, rad: shape (M, 2)."""
    @property
    def tau(self) -> F64:
        """Applied joint torques, N m: shape (M, 2)."""
    @property
    def attitude(self) -> F64:
        """Rear half's attitude quaternion (w, x, y, z): shape (M, 4)."""
    def to_json(self) -> str:
        """The CLI's ``simulate --json``."""
    def to_dict(self) -> Dict[str, Any]:
        """``to_json()`` as a dict."""
    def to_csv(self) -> str:
        """The CLI's ``simulation.csv``."""

def simulate(config: Config, design: Union[Design, str, os.PathLike[str], None] = None,
             start: Optional[Dict[str, Value]] = None) -> Simulation:
    """Simulates ``design`` (a Design, a schedule CSV path, or None for the analytic schedule)
    on ``config``'s cat, as ``catflip simulate [--schedule FILE]``, with the GIL released.
    ``config`` may differ from the design's (model error), but not in its joint, and its
    fall must leave a Design its manoeuvre's time (a shorter manoeuvre, as a least-time
    design's, flies);
    ``start`` sets its ``[start]`` keys
    (``{"angular_velocity": [0, 0, 0.5], "rotation_deg": [0, 30, 0]}``) for this simulation,
    with the CLI's checks. Raises ConfigError, DesignError."""

class LeastHeight:
    """The robot builder's answer: can the motors flip the cat from ``fall.height``, and the
    least drop height found (``run``'s least-height stage)."""

    @property
    def possible(self) -> bool:
        """Whether the least height found is within ``fall.height``."""
    @property
    def height_m(self) -> float:
        """The configured drop height, m."""
    @property
    def least_height_m(self) -> float:
        """The least drop height found, m (an upper bound on the true one)."""
    @property
    def beyond_longest_fall(self) -> bool:
        """Whether the motors need a fall longer than any catflip designs (30 s): then not
        possible from any height, and the schedule is empty."""
    @property
    def least_height_lower_bound_m(self) -> Optional[float]:
        """A lower bound on the least drop height, m, or None (the answer's
        ``least_height_lower_bound_m``: the best stall-only design's, a local
        optimum, so an estimate; given only below the answer)."""
    @property
    def phased_least_height_m(self) -> float:
        """The phased time design's least height, m."""
    @property
    def least_time_s(self) -> float:
        """The shortest manoeuvre found inside the motor envelope, s."""
    @property
    def method(self) -> Literal["phased", "free", "analytic"]:
        """Which design settles the answer (``analytic``: none made, the motors far beyond the longest fall)."""
    @property
    def status(self) -> str:
        """That design's solver status."""
    @property
    def t(self) -> F64:
        """Times of the least-height schedule, s: shape (N,)."""
    @property
    def q(self) -> F64:
        """Its joint angles, rad: shape (N, 2)."""
    @property
    def tau(self) -> F64:
        """Its joint torques, N m: shape (N, 2)."""
    def sentence(self) -> str:
        """The answer in one sentence, as the CLI's table prints it."""
    def to_json(self) -> str:
        """The ``answer`` object of ``summary.json``."""
    def to_csv(self) -> str:
        """The schedule at the least height, as ``least-height.csv``."""

def least_height(config: Config) -> Optional[LeastHeight]:
    """The least drop height at which the config's motors flip the cat (the phased and
    free-form ``time`` designs inside the motor envelope), or None when the config sets no
    motor limit. GIL released."""

def size(config: Config, height: float, points: int = 8, gear_evaluations: int = 6) -> Dict[str, Any]:
    """The motors that would flip the cat from ``height`` m: ``catflip size CONFIG --height H
    --json`` in memory (nothing written), GIL released. The CLI's ``size.json`` as a dict:
    ``curve`` (stall torque against no-load speed that just makes it), ``gear`` (the best gear
    ratio for the config's motor, ``best_ratio``, and the least height it gives), the
    asymptotes. Needs ``limits.max_torque`` and ``limits.no_load_speed``; the config's
    ``design.objective`` is not used (least-time designs). A point whose design failed is
    left out of ``curve`` and named in ``failed`` (the CLI warns and exits 3). Raises
    ConfigError for a bad height, count or config."""

def sweep(config: Config, key: str, values: Union[Sequence[float], F64],
          methods: Union[str, Sequence[str]] = ..., threads: Optional[int] = None,
          frame: Optional[bool] = None, least_height_only: bool = False) -> Any:
    """Sweeps the numeric config key ``key`` over ``values``, as ``catflip sweep``
    (``methods``: a list, or one comma-separated string such as ``"phased,free"``).

    Returns the CSV's columns (float64 arrays of shape ``(len(values),)``, NaN where a method
    gave no number; ``free_status`` and ``error`` lists of str or None): a
    ``pandas.DataFrame`` when pandas is installed and ``frame`` is not False, else a dict that
    also holds ``"csv"``, the CLI's ``sweep-<key>.csv`` text. Under motor limits the peak
    columns are the least-peak designs *without* the limits (the torque each method needs),
    as in the CLI's sweep; whether the motors can do it at a point is read from the
    least-height columns (where the lower is below the point's ``fall.height``). With
    ``least_height_only=True`` only the least heights are computed (the peak columns NaN
    inside a motor envelope; a config without ``limits.max_torque`` is a ``ConfigError``)."""

class Run:
    """A whole ``catflip run``, kept in memory: the summary and every file it would write."""

    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json`` as a dict."""
    @property
    def outcome(self) -> Literal["ok", "partial", "impossible"]:
        """``ok``, ``partial`` (some method flagged or failed: the CLI's exit 3) or
        ``impossible`` (exit 4)."""
    @property
    def partial(self) -> bool:
        """Whether the run is partial (``outcome == "partial"``, the CLI's exit 3): some design
        is flagged or failed in a fall the motors can do; False when the flip is impossible."""
    @property
    def impossible(self) -> bool:
        """Whether the motors cannot flip the cat from ``fall.height``."""
    @property
    def names(self) -> List[str]:
        """Names of the files ``catflip run`` writes."""
    def file(self, name: str) -> str:
        """One of those files, as text; KeyError for another name."""

def robustness(config: Config, trials: int = 1000, seed: int = 1,
               threads: Optional[int] = None) -> Dict[str, Any]:
    """The Monte Carlo study of ``catflip robustness CONFIG --trials N --seed S [--threads T]
    --json``, in memory (nothing written), with the GIL released: the CLI's
    ``robustness.json`` as a dict (``trials``, ``controllers`` with each one's ``name``
    (``"open-loop"``, ``"tvlqr"``, ``"replan"``), ``success_rate`` and ``ci95``, ...) and
    ``"csv"``, the text of its ``robustness.csv``. ``trials`` 1 to 1,000,000; ``seed`` 0 to
    2**64 - 1; ``threads`` at least 1 (None: one per core). Ctrl-C stops it after the trials
    in flight. Raises ConfigError, DesignError; warns (RuntimeWarning, the CLI's ``warning:``
    line) when the replans' p99 wall time on this machine is over the control period."""

def run(config: Config) -> Run:
    """The CLI's main job, ``catflip run``, in memory (nothing written), with the GIL released.
    Raises DesignError when every method fails."""

def export_mjcf(config: Config) -> str:
    """The cat as MuJoCo MJCF text (``catflip export mjcf``)."""

def export_urdf(config: Config) -> str:
    """The cat as URDF text (``catflip export urdf``)."""

class Controls:
    """A design's controls at a simulator's time step: what ``<method>.mujoco.csv`` /
    ``<method>.pybullet.csv`` hold (n steps, n + 1 rows: the last is the final planned state)."""

    @property
    def simulator(self) -> SimulatorName:
        """``mujoco`` or ``pybullet``."""
    @property
    def dt(self) -> float:
        """Time step, s."""
    @property
    def steps(self) -> int:
        """Number of steps n."""
    @property
    def slope(self) -> float:
        """``k`` of MuJoCo's DC-motor actuators (the torque columns are then the command
        ``tau + k qd``); 0 otherwise."""
    @property
    def columns(self) -> List[str]:
        """The CSV's column names (``t_s``, then position, velocity and torque columns)."""
    @property
    def kp(self) -> float:
        """catflip's PD stiffness, N m/rad."""
    @property
    def kd(self) -> float:
        """catflip's PD damping, N m s/rad."""
    @property
    def max_torque(self) -> Optional[float]:
        """``limits.max_torque``, N m, or None."""
    @property
    def norm(self) -> Literal["euclidean", "per-motor"]:
        """Peak norm."""
    @property
    def t(self) -> F64:
        """Step start times, s: shape (n + 1,)."""
    @property
    def pos(self) -> F64:
        """Planned joint position: shape (n + 1, 4) for the no-twist ball (quaternion, MuJoCo
        w x y z, pyBullet x y z w) or (n + 1, 2) for the universal joint."""
    @property
    def vel(self) -> F64:
        """Planned joint velocity: shape (n + 1, 3) (ball) or (n + 1, 2)."""
    @property
    def torque(self) -> F64:
        """Torque (or DC command) held over each step, N m: shape (n + 1, 3) or (n + 1, 2);
        0 on the last row."""
    def to_csv(self, method: Optional[str] = None) -> str:
        """The CLI's ``<method>.<simulator>.csv`` (``method`` defaults to the design's)."""

def controls(design: Design, simulator: SimulatorName = "mujoco") -> Controls:
    """A design's controls for ``simulator``, in its joint coordinates and actuators, as
    ``catflip run`` writes them."""

ControllerKind = Literal["tvlqr", "open-loop", "replan"]
ArrayLike = Union[Sequence[float], F64]

class Controller:
    """One of ``catflip robustness``'s controllers along a design, for a simulation loop run
    outside catflip (MuJoCo, pyBullet, a robot): ``torque(t, state)`` is the correction
    catflip's own closed loop sends from that measurement (docs/control.md).

    The state (11 floats) is the ``<stem>.tvlqr.csv`` convention: the rear half's attitude
    ``W R`` as a quaternion ``w, x, y, z`` in the simulators' world (gravity ``-z``),
    ``lambda`` (3: the angular momentum about the common centre of mass in the rear half's
    frame, N m s), ``q`` (2) and ``q_dot`` (2): the hinge angles for the universal joint, the
    ball's rotation vector ``(v1, v2)`` and its rate for the no-twist joint. ``sensed`` builds
    it from a gyro. Torques are catflip's joint torques (hinge torques; rotation-vector
    torques for the no-twist joint).

    The TVLQR predicts over its delay under the corrections it already sent, so the
    controller remembers them: a command at control step ``k`` forgets those from ``k`` on,
    and one at ``t = 0`` starts a new flight. Safe to share between threads (a lock)."""

    def __init__(self, config: Config, design: Optional[Design] = None,
                 kind: ControllerKind = "tvlqr", budget_s: Optional[float] = None) -> None:
        """The controller ``kind`` along ``design`` (None: the study's own design, the free-form
        one from the phased seed that ``catflip robustness`` flies) on ``config``'s model and
        ``[control]`` keys; GIL released.

        ``"tvlqr"``: the time-varying LQR at ``control.rate_hz``, predicting over
        ``control.delay_ms``, its correction capped at ``control.max_correction`` times the
        design's peak torque and the sum with the feed-forward kept in the motor envelope at
        the predicted speed. ``"open-loop"``: today's joint PD (``simulate.pd_*``) on the
        planned shape, every simulator step. ``"replan"``: the same TVLQR about a plan solved
        again in flight each ``control.replan_every`` periods (``control.replan_nodes`` nodes,
        ``control.replan_iterations`` SCP iterations) from the state predicted where the new
        plan acts, taken when the model lands better under it; ``feedforward`` then changes
        from that instant on. ``budget_s``: a replan taking longer (wall clock) is dropped
        (None: none is, as in catflip's deterministic study; a robot sets its control period;
        ``kind="replan"`` only). Another kind, a negative budget, or a design made for the
        other joint raises ConfigError."""
    @property
    def kind(self) -> ControllerKind:
        """The study's name of the controller."""
    def torque(self, t: float, state: ArrayLike) -> F64:
        """The correction, N m: shape (2,), on top of the feed-forward, from ``state``
        measured at ``t`` (s since release): catflip's closed-loop command of the control step
        ``floor(t / period)``. It acts from ``t + delay`` until the next command; the motor is
        given ``clip(feedforward + correction + noise, qd)``. After the last control step the
        last correction holds. GIL released; ConfigError for a bad ``t`` or state (a value
        that is not finite, an attitude that is not a unit quaternion to 1 %); DesignError
        when the prediction over the delay diverges from a state far outside the model (the
        flight is then reset)."""
    def reset(self) -> None:
        """Forgets the corrections sent (a new flight)."""
    def sensed(self, attitude: ArrayLike, q: ArrayLike, qd: ArrayLike, gyro: ArrayLike) -> F64:
        """The state ``torque`` takes, shape (11,), from the rear half's attitude ``w x y z`` in
        the simulator's world, the joint angles and rates (2 each) and the gyro on the rear
        half (3, rad/s, its own frame): ``lambda = J(q) w + K(q) q_dot`` with the model's
        inertias, as the closed loop's sensors estimate it."""
    def clip(self, tau: ArrayLike, qd: ArrayLike) -> F64:
        """The motor envelope of ``[limits]`` (saturation, back-EMF line) on joint torques
        ``tau`` at joint speed ``qd``: shape (2,), as catflip's plant applies it; a speed that
        is not a number gives NaN under a torque-speed line (a diverged simulation's step)."""
    @property
    def step(self) -> float:
        """Simulator step h, s: touchdown is at ``steps * h``."""
    @property
    def steps(self) -> int:
        """Simulator steps from release to touchdown."""
    @property
    def duration(self) -> float:
        """Release to touchdown, s."""
    @property
    def period(self) -> float:
        """Time between two commands, s (``open-loop``: one step)."""
    @property
    def period_steps(self) -> int:
        """Simulator steps between two commands."""
    @property
    def delay(self) -> float:
        """The delay the controller predicts over, s (``open-loop``: 0)."""
    @property
    def control_steps(self) -> int:
        """Control steps with a command of their own."""
    @property
    def peak_torque(self) -> float:
        """The design's largest feed-forward torque, N m (the config's norm)."""
    @property
    def feedforward(self) -> F64:
        """The torque of the plan in use at every half step ``j h / 2``: shape (2 steps + 1, 2);
        an RK4 step ``j`` uses rows ``2j``, ``2j + 1``, ``2j + 2``. The design's, but for the
        replanning controller, whose replans change it from the instant their plan acts on."""
    @property
    def shape(self) -> F64:
        """The planned ``(q1, q2, qd1, qd2)`` at every step (the PD's reference): shape (steps + 1, 4)."""
    @property
    def nominal(self) -> F64:
        """The model's state under the feed-forward alone at every step, in ``torque``'s
        convention: shape (steps + 1, 11)."""
    @property
    def gains(self) -> F64:
        """The TVLQR gains ``K_k`` (``u = -K x``, ``x`` the error of docs/control.md): shape
        (control steps, 2, 10)."""
    @property
    def t_apply(self) -> F64:
        """When each TVLQR correction starts to act, s: shape (control steps,)."""
    @property
    def issued(self) -> F64:
        """The corrections sent since the last reset, by control step: shape (k, 2)."""
    def gains_csv(self) -> str:
        """The gains as ``<stem>.tvlqr.csv`` text. GIL released."""
    def with_kind(self, kind: ControllerKind) -> Controller:
        """The same design's controller of another ``kind``, its gains reused (no new design)."""
    def fly(self, trial: Optional[int] = None, seed: int = 1) -> Flight:
        """A flight of catflip's closed-loop simulator under this controller: the nominal
        (``trial=None``) or trial ``trial`` of ``catflip robustness --seed SEED`` (its draws,
        delay and noises), with every command sent. GIL released."""

class Flight:
    """A flight of catflip's closed-loop simulator, with every command the controller sent
    (K commands)."""

    @property
    def landing_error_deg(self) -> float:
        """The belly's angle from straight down at touchdown, deg (NaN: diverged)."""
    @property
    def max_correction_nm(self) -> float:
        """Largest correction sent, N m (the motor norm)."""
    @property
    def t(self) -> F64:
        """Measurement time of each command, s: shape (K,)."""
    @property
    def measured(self) -> F64:
        """What the controller measured (sensor noise included), ``Controller.torque``'s
        convention: shape (K, 11)."""
    @property
    def correction(self) -> F64:
        """The correction sent from each measurement, N m: shape (K, 2)."""
    @property
    def draw(self) -> Optional[Dict[str, Any]]:
        """The trial's draws as a dict, ``robustness.csv``'s draw columns grouped: ``trial``,
        ``spin_rad_s`` (x, y, z), ``tilt_deg``, ``tilt_axis_deg``, ``mass_error``,
        ``inertia_error``, ``length_error`` (rear, front each) and ``pd_gain_factor``; None
        for the nominal."""
