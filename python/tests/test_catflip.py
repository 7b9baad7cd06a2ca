"""The Python package against the real catflip binary (the CLI's JSON, CSV
and messages), its documented shapes and exceptions, and the quickstart.

The binary is $CATFLIP_BIN, else target/release/catflip (CARGO_TARGET_DIR
honoured) at the repository root; build it with `cargo build --release`.
"""

import json
import math
import os
import pathlib
import re
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import catflip

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = sorted((ROOT / "configs").glob("*.toml"))
TARGET = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
BIN = pathlib.Path(os.environ.get("CATFLIP_BIN", TARGET / "release" / "catflip"))
# wall-clock numbers: the only fields that differ between two identical solves
TIMING = {"solve_time_s", "solve_ms"}


def cli(*args, out):
    """Runs the binary; returns (exit status, stdout, stderr)."""
    if not BIN.exists():
        pytest.fail(f"{BIN} is missing: run `cargo build --release` at the repository root")
    p = subprocess.run([str(BIN), *map(str, args), "--out", str(out)], capture_output=True, text=True,
                       cwd=ROOT, timeout=600)
    return p.returncode, p.stdout, p.stderr


def cli_error(stderr):
    """The CLI's message: its stderr from the `error: ` that starts a line, without the prefix
    (a TOML error spans several lines)."""
    at = 0 if stderr.startswith("error: ") else stderr.find("\nerror: ") + 1
    assert at > 0 or stderr.startswith("error: "), stderr
    return stderr[at + len("error: "):].rstrip("\n")


def message(e):
    return str(e.value).rstrip("\n")


# the CLI's advice as the package words it (python/src/lib.rs PYTHONIC)
PYTHONIC = [
    ("out of the config and its --set", "out of the config and its config.set calls"),
    ("--methods names neither", "methods names neither"),
    ("to --methods", "to methods"),
    ("or sweep without --least-height-only", "or sweep with least_height_only=False"),
    ("--least-height-only", "least_height_only=True"),
    ("another seed (--seed)", 'another seed (seed="analytic" or "phased")'),
    ("`--seed analytic` starts it", '`seed="analytic"` starts it'),
    ("`catflip run` finds the least drop height", "`catflip.least_height(config)` finds the least drop height"),
    ("`catflip run` writes its schedule as least-height.csv", "`catflip.least_height(config).to_csv()` gives its schedule"),
    (" in least-height.csv)", ": least_height(config).to_csv())"),
    ("`catflip run`", "`catflip.run(config)`"),
    ("(catflip size names them for a height)", "(catflip.size(config, height) names them)"),
]


def in_python_words(cli_message):
    for cli_words, py_words in PYTHONIC:
        cli_message = cli_message.replace(cli_words, py_words)
    # a key to set is set on the config
    cli_message = re.sub(r"with --set ([a-z_.]+)=([^\s,;)]*[^\s,;).])", r'with config.set("\1", \2)', cli_message)
    # the pointer to `catflip size` is the call here
    return re.sub(r"catflip size CONFIG --height ([0-9.e+-]*[0-9])", r"catflip.size(config, \1)", cli_message)


def assert_close(a, b, path="", tol=1e-12):
    """Same structure, same strings, numbers within tol (relative to their size)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (path, sorted(set(a) ^ set(b)))
        for k in a:
            if k not in TIMING:
                assert_close(a[k], b[k], f"{path}.{k}", tol)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), (path, len(a), len(b))
        for i, (x, y) in enumerate(zip(a, b)):
            assert_close(x, y, f"{path}[{i}]", tol)
    elif isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, (int, float)) and isinstance(b, (int, float)), (path, a, b)
        assert abs(a - b) <= tol * max(1.0, abs(a), abs(b)), (path, a, b)
    else:
        assert a == b, (path, a, b)


# each design through Python and through the CLI: the command and its files' folder and stem
METHODS = {
    ("free", None): (["optimize", "--mode", "free"], "optimize-free", "free"),
    ("free", "analytic"): (["optimize", "--mode", "free", "--seed", "analytic"], "optimize-free-analytic", "free"),
    ("phased", None): (["optimize", "--mode", "phased"], "optimize-phased", "phased"),
    ("analytic", None): (["analyze"], "analyze", "analytic"),
}


@pytest.mark.parametrize("config", CONFIGS, ids=lambda p: p.stem)
@pytest.mark.parametrize("method,seed", list(METHODS), ids=lambda x: str(x))
def test_every_bundled_design_equals_the_cli(config, method, seed, tmp_path):
    command, folder, stem = METHODS[(method, seed)]
    status, stdout, stderr = cli(command[0], config, *command[1:], "--json", out=tmp_path)
    cfg = catflip.Config.from_toml(config)
    if status in (0, 3):
        d = catflip.design(cfg, method, seed=seed)
        assert_close(json.loads(stdout), d.to_dict())
        # `analyze` exits 0 on a flagged schedule: the analysis is what was asked
        assert d.verdict == json.loads(stdout)["verdict"]
        assert method == "analytic" or (d.verdict == "ok") == (status == 0)
        files = tmp_path / cfg.name / folder
        # the same computation prints the same digits
        assert d.to_csv() == (files / f"{stem}.csv").read_text()
        assert d.schedule_json() == (files / f"{stem}.schedule.json").read_text()
        written = json.loads((files / ("analyze.json" if method == "analytic" else f"{stem}.json")).read_text())
        assert_close(written, json.loads(d.to_json()))
        assert d.peak == pytest.approx(written["peak_torque_nm"], rel=1e-12)
        assert list(d.durations) == pytest.approx(written["phase_durations_s"], rel=1e-12)
    else:
        # the CLI's exit reason, as the documented exception, with its message
        expected = {1: catflip.DesignError, 2: catflip.ConfigError, 4: catflip.ImpossibleError}[status]
        with pytest.raises(expected) as e:
            catflip.design(cfg, method, seed=seed)
        assert message(e) == in_python_words(cli_error(stderr))
        # exit 1 is a failure, not the motors' impossibility (exit 4)
        assert (status == 4) == isinstance(e.value, catflip.ImpossibleError)


@pytest.mark.parametrize("key,value,cli_value", [
    ("fall.height", -1, "-1"),
    ("cat.masss", 1, "1"),
    ("cat.joint", "hinge", "hinge"),
    ("cat.mass", "abc", "abc"),
    ("phased.nodes", 10.5, "10.5"),
    ("analytic.split", [0.5, 0.6, 0.2], "[0.5, 0.6, 0.2]"),
    ("fall.margin", 5, "5"),
])
def test_bad_keys_raise_config_error_with_the_cli_message(key, value, cli_value, tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, _, stderr = cli("analyze", seed, "--set", f"{key}={cli_value}", out=tmp_path)
    assert status == 2
    cfg = catflip.Config.from_toml(seed)
    before = cfg.to_dict()
    with pytest.raises(catflip.ConfigError) as e:
        cfg.set(key, value)
    assert message(e) == cli_error(stderr)
    assert cfg.to_dict() == before and cfg.overrides == []
    assert isinstance(e.value, catflip.CatflipError)


def test_a_whole_float_sets_a_whole_number_key_as_sweep_takes_it():
    seed = ROOT / "configs" / "seed.toml"
    by_int, by_float = catflip.Config.from_toml(seed), catflip.Config.from_toml(seed)
    by_int.set("phased.nodes", 40)
    by_float.set("phased.nodes", np.float64(40.0))
    assert by_float.to_dict() == by_int.to_dict()
    assert by_float.overrides == by_int.overrides == ["phased.nodes=40"]
    # a float key keeps its float, and a fraction is still refused
    by_float.set("fall.height", 4.0)
    assert by_float.to_dict()["fall"]["height"] == 4.0
    with pytest.raises(catflip.ConfigError, match="phased.nodes=40.5"):
        by_float.set("phased.nodes", 40.5)
    # a whole float the key refuses for its value says why, not its type
    with pytest.raises(catflip.ConfigError) as e:
        by_float.set("phased.nodes", 1.0)
    assert "`phased.nodes` = 1 is invalid: must be" in str(e.value), str(e.value)
    assert "floating point" not in str(e.value)


def test_bad_files_raise_config_error_with_the_cli_message(tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text('name = "x"\n[cat]\nmass = 1\n')
    for path in (tmp_path / "missing.toml", broken):
        status, _, stderr = cli("analyze", path, out=tmp_path)
        assert status == 2
        with pytest.raises(catflip.ConfigError) as e:
            catflip.Config.from_toml(path)
        assert message(e) == cli_error(stderr)


def test_the_version_is_the_packages():
    import importlib.metadata
    assert catflip.__version__ == importlib.metadata.version("catflip")


def test_the_exception_hierarchy():
    assert issubclass(catflip.ConfigError, catflip.CatflipError)
    assert issubclass(catflip.DesignError, catflip.CatflipError)
    assert issubclass(catflip.ImpossibleError, catflip.DesignError)
    assert issubclass(catflip.CatflipError, Exception)


def test_impossible_from_this_height(tmp_path):
    robot = ROOT / "configs" / "robot-universal.toml"
    status, _, stderr = cli("optimize", robot, "--mode", "phased", out=tmp_path)
    assert status == 4
    with pytest.raises(catflip.ImpossibleError) as e:
        catflip.design(catflip.Config.from_toml(robot), "phased")
    assert message(e) == in_python_words(cli_error(stderr))
    assert "at least 5.663 m" in str(e.value)


def test_a_design_just_above_the_least_height_that_finds_nothing_is_no_impossibility():
    # from 3.5 m, 0.5 % above the robot's least height (3.484 m), the free-form peak
    # design from the least-height design finds no schedule inside the motors (about
    # 30 s); the flip is possible, so the error is the design's, with the schedule's place
    robot = ROOT / "configs" / "robot-universal.toml"
    cfg = catflip.Config.from_toml(robot, ["fall.height=3.5"])
    with pytest.raises(catflip.DesignError) as e:
        catflip.design(cfg)
    assert not isinstance(e.value, catflip.ImpossibleError)
    assert "the flip is possible" in str(e.value)
    assert "catflip.least_height(config) gives it" in str(e.value)
    answer = catflip.least_height(cfg)
    assert answer.possible and answer.least_height_m < 3.5


def test_a_named_phased_seed_that_does_not_fit_is_no_impossibility(tmp_path):
    # from 4 m the robot flips (the least height is 3.484 m), but no phased schedule fits:
    # the named phased seed fails as the CLI's exit 1, not as the motors' impossibility
    robot = ROOT / "configs" / "robot-universal.toml"
    status, _, stderr = cli("optimize", robot, "--mode", "free", "--seed", "phased",
                            "--set", "fall.height=4", out=tmp_path)
    assert status == 1
    with pytest.raises(catflip.DesignError) as e:
        catflip.design(catflip.Config.from_toml(robot, ["fall.height=4"]), seed="phased")
    assert not isinstance(e.value, catflip.ImpossibleError)
    # the CLI's message, its advice in the package's words
    said = message(e)
    assert '`seed="analytic"` starts it' in said and "`catflip.least_height(config)`" in said, said
    assert "--seed" not in said and "`catflip run`" not in said, said
    assert said == in_python_words(cli_error(stderr))


def test_set_and_objective_apply_like_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, stdout, _ = cli("optimize", seed, "--mode", "phased", "--set", "fall.height=6",
                            "--set", "design.objective=energy", "--json", out=tmp_path)
    assert status == 0
    cfg = catflip.Config.from_toml(seed)
    cfg.set("fall.height", 6)
    assert cfg.overrides == ["fall.height=6"]
    assert cfg.fall_time == pytest.approx(math.sqrt(2 * 6 / 9.8), rel=1e-15)
    d = catflip.design(cfg, "phased", objective="energy")
    assert_close(json.loads(stdout), d.to_dict())
    # the design's objective did not change the config
    assert cfg.to_dict()["design"]["objective"] == "peak-torque"
    assert d.config.to_dict()["design"]["objective"] == "energy"
    with pytest.raises(catflip.ConfigError, match="seed applies to"):
        catflip.design(cfg, "phased", seed="analytic")
    # the analytic schedule optimises nothing: an objective is refused, not ignored
    with pytest.raises(catflip.ConfigError, match='objective="time" applies to the phased and free designs'):
        catflip.design(cfg, "analytic", objective="time")
    with pytest.raises(catflip.ConfigError, match="unknown method"):
        catflip.design(cfg, "fast")
    with pytest.raises(catflip.ConfigError, match='unknown objective `speed`; use "peak-torque"'):
        catflip.design(cfg, objective="speed")


def test_from_dict_and_from_text_read_as_the_file(monkeypatch):
    tomllib = pytest.importorskip("tomllib")
    seed = ROOT / "configs" / "seed.toml"
    a = catflip.Config.from_toml(seed)
    b = catflip.Config.from_dict(tomllib.loads(seed.read_text()))
    c = catflip.Config.from_text(seed.read_text())
    assert a.to_dict() == b.to_dict() == c.to_dict()
    assert catflip.Config.from_text(a.to_toml()).to_dict() == a.to_dict()
    with pytest.raises(catflip.ConfigError, match="masss"):
        catflip.Config.from_dict({**tomllib.loads(seed.read_text()), "cat": {"masss": 1}})
    # a dict's mistake is said of its key, not of a TOML line it never had
    base = tomllib.loads(seed.read_text())
    for fall, says in [({"heigth": 1}, "config dict: key `fall.heigth`: unknown key `heigth`, expected one of `height`"),
                       ({"height": "1.5m"}, 'config dict: key `fall.height`: invalid type: string "1.5m", expected a number')]:
        with pytest.raises(catflip.ConfigError) as e:
            catflip.Config.from_dict({**base, "fall": fall})
        assert str(e.value).startswith(says) and "line" not in str(e.value), str(e.value)
    without_fall = {k: v for k, v in base.items() if k != "fall"}
    with pytest.raises(catflip.ConfigError, match=r"missing section `\[fall\]`"):
        catflip.Config.from_dict(without_fall)
    # a relative robot file is read from the current folder, and a missing one
    # says that folder (not "the config file", which a dict has not)
    monkeypatch.chdir(ROOT)  # (the robot's URDF is in configs/)
    text = (ROOT / "configs" / "box-robot.toml").read_text()
    for make in (lambda: catflip.Config.from_dict(tomllib.loads(text)), lambda: catflip.Config.from_text(text)):
        with pytest.raises(catflip.ConfigError) as e:
            make()
        assert f"the path is relative to {ROOT}" in str(e.value), str(e.value)


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.stem)
def test_a_configs_keys_read_back_and_pickle(path, tmp_path, monkeypatch):
    import copy
    import pickle

    # loaded from a relative path: its robot file is found from where it was loaded
    monkeypatch.chdir(ROOT)
    a = catflip.Config.from_toml(path.relative_to(ROOT), "fall.height=7")
    pickled = pickle.dumps(a)
    monkeypatch.chdir(tmp_path)
    for b in (catflip.Config.from_dict(a.to_dict()), catflip.Config.from_text(a.to_toml()),
              pickle.loads(pickled), pickle.loads(pickle.dumps(a)), copy.deepcopy(a), copy.copy(a)):
        assert b.to_dict() == a.to_dict()
    assert pickle.loads(pickle.dumps(a)).overrides == a.overrides == ["fall.height=7"]


def test_a_cylinder_key_beside_a_body_is_refused_in_python_words():
    box = catflip.Config.from_toml(ROOT / "configs" / "box-robot.toml")
    with pytest.raises(catflip.ConfigError, match="leave them out of the config and its config.set calls"):
        box.set("cat.mass", 1.0)


def test_numpy_values_and_none_as_config_values():
    c = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    c.set("start.angular_velocity", np.array([0.0, 0.0, 0.5]))
    c.set("fall.height", np.float64(9.0))
    d = c.to_dict()
    assert d["start"]["angular_velocity"] == [0.0, 0.0, 0.5] and d["fall"]["height"] == 9.0
    d["start"]["angular_velocity"] = np.array([0.1, 0.0, 0.0])
    d["limits"]["max_torque"] = None  # unset, as to_dict gives it
    assert catflip.Config.from_dict(d).to_dict()["start"]["angular_velocity"] == [0.1, 0.0, 0.0]
    d["fall"]["height"] = float("nan")
    with pytest.raises(catflip.ConfigError, match="fall.height` = NaN is invalid"):
        catflip.Config.from_dict(d)
    # None is no value: a ConfigError that says how to unset, and the config unchanged
    with pytest.raises(catflip.ConfigError, match="None is no value.*Config.from_dict"):
        c.set("fall.height", None)
    assert c.to_dict()["fall"]["height"] == 9.0


def test_the_stubs_type_aliases_exist_at_runtime():
    # every top-level alias of the stubs (`Method = Literal[...]`) is also a name of the
    # package, the same type: an annotation that names one runs
    import re
    import typing

    stub = (ROOT / "python" / "catflip" / "__init__.pyi").read_text()
    names = re.findall(r"^([A-Z][A-Za-z0-9]*) = ", stub, flags=re.M)
    assert {"Method", "Seed", "Value", "ControllerKind", "ArrayLike"} <= set(names), names
    for name in names:
        assert hasattr(catflip, name), name
    assert catflip.Method == typing.Literal["free", "phased", "analytic"]
    assert set(typing.get_args(catflip.Seed)) == {"phased", "analytic"}
    assert np.generic in typing.get_args(catflip.Value)


def test_an_impossible_run_is_not_partial():
    # the robot from its configured 2 m: the motors cannot do it (exit 4); the flagged
    # analytic reference and the designs that could not fit do not make it partial (exit 3)
    r = catflip.run(catflip.Config.from_toml(ROOT / "configs" / "robot-universal.toml"))
    assert r.outcome == "impossible" and r.impossible and not r.partial
    assert r.summary["outcome"] == "impossible"


def test_a_design_is_simulated_only_in_a_fall_it_fits():
    seed = ROOT / "configs" / "seed.toml"
    d = catflip.design(catflip.Config.from_toml(seed), "phased")
    with pytest.raises(catflip.ConfigError, match="fly it with a config whose fall.height is at least"):
        catflip.simulate(catflip.Config.from_toml(seed, ["fall.height=0.5"]), d)
    # a longer fall, or another body in the same fall (model error), flies it
    for sets in (["fall.height=40"], ["cat.mass=2.2"]):
        assert catflip.simulate(catflip.Config.from_toml(seed, sets), d).t[-1] == pytest.approx(d.duration)
    # a least-time design ends before its fall does, and flies in its own config
    c = catflip.Config.from_toml(seed, ["limits.max_torque=0.5"])
    t = catflip.design(c, "free", objective="time")
    assert t.duration < c.manoeuvre_time
    assert catflip.simulate(t.config, t).verdict == "ok"


def test_ctrl_c_interrupts_a_long_call():
    import signal

    c = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        catflip.sweep(c, "cat.radius", np.linspace(0.05, 0.2, 400), threads=1, frame=False)
    # 400 points take minutes; the interrupt ends the call at the next look (50 ms)
    assert time.monotonic() - start < 10


def test_arrays_have_the_documented_shapes_and_dtypes():
    cfg = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    cfg.set("simulate.samples_per_phase", 10)
    d = catflip.design(cfg, "phased")
    n = 3 * (10 + 1)
    assert d.t.shape == (n,) and d.t.dtype == np.float64
    for a in (d.q, d.qd, d.qdd, d.tau):
        assert a.shape == (n, 2) and a.dtype == np.float64
    assert d.phase.shape == (n,) and d.phase.dtype == np.int64
    assert list(np.unique(d.phase)) == [0, 1, 2]
    assert d.t[0] == 0.0 and d.t[-1] == pytest.approx(cfg.manoeuvre_time, rel=1e-12)
    assert sum(d.durations) == pytest.approx(d.duration, rel=1e-12)
    # the peak is the dense one: at least the rows' Euclidean peak (the seed's norm)
    assert d.peak >= np.hypot(d.tau[:, 0], d.tau[:, 1]).max() * (1 - 1e-12)
    s = catflip.simulate(cfg, d)
    m = len(s.t)
    assert m > 10 and s.t.dtype == np.float64
    assert s.flip.shape == s.tilt.shape == (m,)
    assert s.q.shape == s.tau.shape == (m, 2) and s.attitude.shape == (m, 4)
    assert np.allclose(np.linalg.norm(s.attitude, axis=1), 1.0, atol=1e-9)
    for sim, width in (("mujoco", (4, 3)), ("pybullet", (4, 3))):
        c = catflip.controls(d, sim)
        rows = c.steps + 1
        assert c.t.shape == (rows,)
        assert c.pos.shape == (rows, width[0]) and c.vel.shape == (rows, width[1])
        assert c.torque.shape == (rows, width[1]) and c.pos.dtype == np.float64
        assert len(c.columns) == 1 + width[0] + 2 * width[1]
        assert c.dt * c.steps == pytest.approx(d.duration, rel=1e-12)
    robot = catflip.Config.from_toml(ROOT / "configs" / "robot-universal.toml")
    c = catflip.controls(catflip.design(robot, "analytic"), "mujoco")
    assert c.pos.shape == c.vel.shape == c.torque.shape == (c.steps + 1, 2) and c.slope > 0


def test_simulating_a_design_reproduces_its_own_flip(tmp_path):
    cfg = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    d = catflip.design(cfg, "free")
    s = catflip.simulate(cfg, d)
    assert s.flip_deg == pytest.approx(d.flip_deg, rel=1e-12)
    assert s.verdict == "ok"
    # a schedule file and no schedule, as `catflip simulate [--schedule FILE]`
    path = tmp_path / "free.csv"
    path.write_text(d.to_csv())
    for arg, extra in ((path, ["--schedule", path]), (None, [])):
        status, stdout, _ = cli("simulate", ROOT / "configs" / "seed.toml", *extra, "--json", out=tmp_path)
        assert status == 0
        s = catflip.simulate(cfg, arg)
        assert_close(json.loads(stdout), s.to_dict())
        assert s.to_csv() == (tmp_path / "seed" / "simulate" / "simulation.csv").read_text()


def test_run_and_controls_and_models_match_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, stdout, _ = cli("run", seed, "--json", out=tmp_path)
    assert status == 0
    cfg = catflip.Config.from_toml(seed)
    r = catflip.run(cfg)
    assert r.outcome == "ok" and not r.partial and not r.impossible
    assert_close(json.loads(stdout), r.summary)
    files = tmp_path / "seed" / "run"
    for name in ("free.csv", "phased.mujoco.csv", "seed.mjcf.xml", "seed.urdf"):
        assert r.file(name) == (files / name).read_text(), name
    assert catflip.export_mjcf(cfg) == (files / "seed.mjcf.xml").read_text()
    assert catflip.export_urdf(cfg) == (files / "seed.urdf").read_text()
    # the analytic and phased designs are run's own: their controls are its files
    for method in ("analytic", "phased"):
        d = catflip.design(cfg, method)
        for sim in ("mujoco", "pybullet"):
            assert catflip.controls(d, sim).to_csv() == (files / f"{method}.{sim}.csv").read_text()
    with pytest.raises(KeyError):
        r.file("nothing.csv")


def test_least_height_is_runs_answer():
    robot = catflip.Config.from_toml(ROOT / "configs" / "robot-universal.toml")
    h = catflip.least_height(robot)
    answer = catflip.run(robot).summary["answer"]
    assert not h.possible and not answer["possible"]
    assert h.least_height_m == pytest.approx(answer["least_height_m"], rel=1e-12)
    assert h.least_time_s == pytest.approx(answer["least_time_s"], rel=1e-12)
    assert h.least_height_lower_bound_m == pytest.approx(answer["least_height_lower_bound_m"], rel=1e-12)
    assert 0 < h.least_height_lower_bound_m < h.least_height_m
    # not possible from its 2 m: the sentence points to the call that sizes the motors for it
    assert h.sentence().endswith(" The motors (or the gear ratio) that would do it from 2 m: catflip.size(config, 2)."), \
        h.sentence()
    # and names the schedule as Python gives it (no file is written), as its repr does
    assert "schedule: least_height(config).to_csv())" in h.sentence(), h.sentence()
    assert repr(h) == f"LeastHeight({h.sentence()})"
    # F7's relation between the least time and height, with the robot's margin
    g, margin = robot.to_dict()["fall"]["gravity"], robot.to_dict()["fall"]["margin"]
    assert h.least_height_m == pytest.approx(g * (h.least_time_s + margin) ** 2 / 2, rel=1e-9)
    assert h.t.shape == (h.q.shape[0],) and h.tau.shape[1] == 2
    assert catflip.least_height(catflip.Config.from_toml(ROOT / "configs" / "seed.toml")) is None
    assert not h.beyond_longest_fall


def test_a_motor_too_weak_for_any_fall_has_no_schedule():
    weak = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    weak.set("limits.max_torque", 1e-9)
    h = catflip.least_height(weak)
    assert h.beyond_longest_fall and not h.possible
    assert h.least_time_s > 30 and h.t.shape == (0,)
    assert "nor from any drop catflip designs" in h.sentence()
    # the pointer to the motors that would do it, as this package's call
    assert "stronger or faster motors would do (catflip.size(config, height) names them)" in h.sentence()


def test_a_sweep_of_least_heights_alone_equals_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, _, err = cli("sweep", seed, "--set", "limits.max_torque=0.5", "--set-range", "fall.height=1:3:3",
                         "--least-height-only", out=tmp_path)
    assert status == 0, err
    cfg = catflip.Config.from_toml(seed)
    cfg.set("limits.max_torque", 0.5)
    cols = catflip.sweep(cfg, "fall.height", [1, 2, 3], least_height_only=True, frame=False)
    (written,) = (tmp_path / "seed").glob("sweep-fall_height*/sweep-fall_height.csv")
    assert cols["csv"] == written.read_text()
    # under a stall torque alone the least heights are the peaks' (F7); the analytic one has none
    assert np.isnan(cols["analytic_peak_nm"]).all()
    assert np.isfinite(cols["least_height_free_m"]).all()
    # F7: the least height does not depend on the drop
    assert cols["least_height_phased_m"][0] == pytest.approx(cols["least_height_phased_m"][2], rel=1e-9)
    with pytest.raises(catflip.ConfigError,
                       match=r"least_height_only=True: the config sets no stall torque.*least_height_only=False"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [1, 2], least_height_only=True, frame=False)
    with pytest.raises(catflip.ConfigError, match="methods names neither; add phased or free to methods"):
        catflip.sweep(cfg, "fall.height", [1, 2], methods=("analytic",), least_height_only=True, frame=False)


def test_sweep_equals_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, stdout, _ = cli("sweep", seed, "--set-range", "fall.height=1:3:3", "--methods", "analytic,phased",
                            "--json", out=tmp_path)
    assert status == 0
    points = json.loads(stdout)
    cols = catflip.sweep(catflip.Config.from_toml(seed), "fall.height", np.linspace(1, 3, 3),
                         methods=("analytic", "phased"), frame=False)
    assert cols["csv"] == (tmp_path / "seed" / "sweep-fall_height" / "sweep-fall_height.csv").read_text()
    for k in ("value", "analytic_peak_nm", "phased_peak_nm", "phased_bend_deg"):
        assert cols[k].shape == (3,) and cols[k].dtype == np.float64
        assert np.allclose(cols[k], [p[k] for p in points], rtol=1e-12, atol=0)
    assert np.isnan(cols["free_peak_nm"]).all() and cols["error"] == [None] * 3
    # F3: the phased peak scales as 1 / T^2, T = sqrt(2 h / g)
    peaks = cols["phased_peak_nm"]
    assert peaks[0] / peaks[2] == pytest.approx(3.0, rel=1e-9)
    with pytest.raises(catflip.ConfigError, match="every point is invalid"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [-1, -2], frame=False)
    # one invalid value refuses the whole sweep before any point, in Python's words
    with pytest.raises(catflip.ConfigError, match=r"^limits\.max_torque=\[-0\.5, 1\]: 1 of 2 points is invalid"):
        catflip.sweep(catflip.Config.from_toml(seed), "limits.max_torque", [-0.5, 1.0], frame=False)
    with pytest.raises(catflip.ConfigError, match="values is empty"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [], frame=False)
    # no values at all, and no methods (they gave a row of NaN, and a point at NaN)
    with pytest.raises(TypeError, match="values = None: give the values to sweep"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", None, frame=False)
    with pytest.raises(catflip.ConfigError, match="methods is empty"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [5], methods=[], frame=False)
    with pytest.raises(catflip.ConfigError, match="1 of 2 points is invalid.*choose the values"):
        catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [-1, 2], frame=False)
    try:
        import pandas  # noqa: F401
    except ImportError:
        assert isinstance(catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [2],
                                        methods=("analytic",)), dict)
    else:
        df = catflip.sweep(catflip.Config.from_toml(seed), "fall.height", [2], methods=("analytic",))
        assert list(df["value"]) == [2.0]


def test_solves_release_the_gil_and_objects_are_shared_by_threads():
    cfg = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    cfg.set("free.mesh_continuation", False)
    reference = catflip.design(cfg, "free").to_dict()
    results, ticks = [], 0
    workers = [threading.Thread(target=lambda: results.append(catflip.design(cfg, "free"))) for _ in range(2)]
    start = time.perf_counter()
    for w in workers:
        w.start()
    while any(w.is_alive() for w in workers):
        time.sleep(0.005)
        ticks += 1
    elapsed = time.perf_counter() - start
    # with the GIL held by a solve this thread would not wake until it ended
    assert ticks >= 0.2 * elapsed / 0.005, (ticks, elapsed)
    assert len(results) == 2
    for r in results:
        assert_close(reference, r.to_dict())
    # setting keys from many threads at once: every set applied once
    shared = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    setters = [threading.Thread(target=shared.set, args=("fall.height", 5 + i)) for i in range(8)]
    for s in setters:
        s.start()
    for s in setters:
        s.join()
    assert len(shared.overrides) == 8


def test_the_quickstart_runs(tmp_path):
    script = ROOT / "examples" / "python" / "quickstart.py"
    assert len(script.read_text().splitlines()) < 40
    env = {**os.environ, "MPLBACKEND": "Agg"}
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path,
                       env=env, timeout=600)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "quickstart.png").stat().st_size > 10_000
    assert "MuJoCo flip" in p.stdout


def test_unit_slips_warn_as_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    status, _, stderr = cli("analyze", seed, "--set", "cat.mass=500", out=tmp_path)
    assert status == 0
    cli_warnings = [l[len("warning: "):] for l in stderr.splitlines() if "typed as" in l]
    assert cli_warnings
    cfg = catflip.Config.from_toml(seed)
    with pytest.warns(catflip.UnitSlipWarning) as caught:
        cfg.set("cat.mass", 500)
    assert [str(w.message) for w in caught] == cli_warnings == cfg.slips


def test_everything_public_has_a_docstring_and_a_stub():
    import ast

    stub = ast.parse((pathlib.Path(catflip.__file__).parent / "__init__.pyi").read_text())
    stubbed = {n.name: n for n in stub.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    for name in catflip.__all__:
        obj = getattr(catflip, name)
        assert (obj.__doc__ or "").strip(), name
        assert name in stubbed, f"{name} has no stub"
        if isinstance(obj, type) and not issubclass(obj, BaseException):
            members = {n.name for n in stubbed[name].body if isinstance(n, ast.FunctionDef)}
            for attr in dir(obj):
                if attr.startswith("_"):
                    continue
                assert (getattr(obj, attr).__doc__ or "").strip(), f"{name}.{attr} has no docstring"
                assert attr in members, f"{name}.{attr} has no stub"


def test_simulate_from_another_start_equals_the_cli(tmp_path):
    seed = ROOT / "configs" / "seed.toml"
    cfg = catflip.Config.from_toml(seed)
    d = catflip.design(cfg, "phased")
    path = tmp_path / "phased.csv"
    path.write_text(d.to_csv())
    status, stdout, _ = cli("simulate", seed, "--schedule", path, "--set", "start.angular_velocity=[0,0,0.5]",
                            "--json", out=tmp_path)
    assert status in (0, 3)
    s = catflip.simulate(cfg, path, start={"angular_velocity": [0, 0, 0.5]})
    assert_close(json.loads(stdout), s.to_dict())
    # the spin changes the landing; the config itself is left at rest
    assert abs(s.flip_deg - catflip.simulate(cfg, path).flip_deg) > 1.0
    assert cfg.overrides == []
    with pytest.raises(catflip.ConfigError, match="start"):
        catflip.simulate(cfg, d, start={"angular_velocity": [0, 0, 500]})


def test_size_equals_the_cli(tmp_path):
    robot = ROOT / "configs" / "robot-universal.toml"
    status, stdout, stderr = cli("size", robot, "--height", 3, "--points", 2, "--gear-evaluations", 0, "--json",
                                 out=tmp_path)
    assert status == 0, stderr
    config = catflip.Config.from_toml(robot)
    ours = catflip.size(config, 3.0, points=2, gear_evaluations=0)
    assert_close(ours, json.loads(stdout))
    assert len(ours["curve"]) == 2 and ours["height_m"] == 3.0
    # each point is a designed motor scaled in time by F3 (torque by s^2, speed by s, the
    # manoeuvre by 1/s) onto the asked height: g (t + margin)^2 / 2 = 3 m
    fall = config.to_dict()["fall"]
    for p in ours["curve"]:
        d, s = p["design"], p["scale"]
        assert p["stall_torque_nm"] == pytest.approx(d["stall_torque_nm"] * s * s, rel=1e-12)
        assert p["no_load_speed_rad_s"] == pytest.approx(d["no_load_speed_rad_s"] * s, rel=1e-12)
        t = d["least_time_s"] / s
        assert fall["gravity"] * (t + fall["margin"]) ** 2 / 2 == pytest.approx(3.0, rel=1e-9)


@pytest.mark.parametrize("config, height, points, gear_evaluations", [
    ("robot-universal", -1.0, 8, 6),
    ("robot-universal", 3.0, 1, 6),
    ("robot-universal", 3.0, 8, 21),
    ("seed", 3.0, 8, 6),
])
def test_size_refuses_what_the_cli_refuses(config, height, points, gear_evaluations, tmp_path):
    path = ROOT / "configs" / f"{config}.toml"
    status, _, stderr = cli("size", path, "--height", height, "--points", points, "--gear-evaluations",
                            gear_evaluations, out=tmp_path)
    assert status == 2, stderr
    with pytest.raises(catflip.ConfigError) as e:
        catflip.size(catflip.Config.from_toml(path), height, points=points, gear_evaluations=gear_evaluations)
    said = in_python_words(cli_error(stderr))
    for flag, arg in [("--height ", "height="), ("--points ", "points="),
                      ("--gear-evaluations ", "gear_evaluations=")]:
        said = said.replace(flag, arg)
    assert message(e) == said
    assert not any(tmp_path.iterdir())


def test_a_least_time_design_continues_from_the_least_height_answer():
    # the least time is the least-height stage's own question: the design starts from that
    # answer's shortest manoeuvre (not the phased design) and ends no slower than it
    cfg = catflip.Config.from_toml(ROOT / "configs" / "robot-universal.toml", ["fall.height=6"])
    d = catflip.design(cfg, "free", objective="time")
    assert d.to_dict()["seed"] == "free least-time"
    answer = catflip.least_height(cfg)
    assert answer is not None and answer.possible
    assert d.duration <= answer.least_time_s * (1 + 1e-9)
    # a named seed still starts there
    assert catflip.design(cfg, "free", objective="time", seed="phased").to_dict()["seed"] == "phased"


def test_the_replays_allow_a_schedule_clipped_to_the_line_its_riding_tolerance():
    # a schedule beyond the motors (negative margin) is clipped to the line by both
    # simulators and rides it, as one at its edge does: five times the tolerance
    sys.path.insert(0, str(ROOT / "examples"))
    try:
        from replay_common import RIDING_MARGIN, pd_tolerance
    finally:
        sys.path.pop(0)
    tol = lambda margin, given=None: pd_tolerance(given, 1e-3, {"min_envelope_margin": margin}, 5.0)
    assert tol(None) == 1e-3
    assert tol(0.5) == 1e-3
    assert tol(RIDING_MARGIN / 2) == 5e-3
    assert tol(-29.6) == 5e-3
    assert tol(-29.6, given=2e-3) == 2e-3


def test_a_sweep_of_values_that_are_not_numbers_is_a_config_error():
    cfg = catflip.Config.from_toml(ROOT / "configs" / "seed.toml")
    with pytest.raises(catflip.ConfigError, match=r"cat.joint: values = \['universal'\] are not numbers"):
        catflip.sweep(cfg, "cat.joint", ["universal"], frame=False)
    with pytest.raises(catflip.ConfigError, match=r"\[\[0, 0, 20\], \[0, 0, -20\]\]"):
        catflip.sweep(cfg, "start.rotation_deg", [[0, 0, 20], [0, 0, -20]], frame=False)
