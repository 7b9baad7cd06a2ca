//! Helpers shared by the integration tests: each module says
//! `use crate::util;` and takes what it needs, so a helper is written once.

use catflip::Config;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use tempfile::TempDir;

/// The repository's root, for its files (`configs/`, `docs/`).
pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The bundled configs' folder.
pub fn configs() -> PathBuf {
    repo().join("configs")
}

/// The path of a bundled config: `config_path("seed")` is `configs/seed.toml`.
pub fn config_path(name: &str) -> PathBuf {
    configs().join(format!("{name}.toml"))
}

/// A bundled config's path as a command-line argument.
pub fn config_arg(name: &str) -> String {
    config_path(name).display().to_string()
}

/// `configs/seed.toml`, the seed document's example.
pub fn seed_toml() -> PathBuf {
    config_path("seed")
}

/// A bundled config's text.
pub fn config_text(name: &str) -> String {
    std::fs::read_to_string(config_path(name)).expect("a bundled config reads")
}

fn strings(overrides: &[&str]) -> Vec<String> {
    overrides.iter().map(|s| s.to_string()).collect()
}

/// A bundled config with `--set`-style overrides, checked as the binary checks it.
pub fn config(name: &str, overrides: &[&str]) -> Config {
    Config::load(&config_path(name), &strings(overrides)).expect("a bundled config loads")
}

/// The seed's config with overrides.
pub fn seed(overrides: &[&str]) -> Config {
    config("seed", overrides)
}

/// A bundled config as a peak-torque problem: the robot's servo also has a
/// torque-speed line, which only the envelope designs handle
/// (tests/it/envelope.rs), so here it is the same body under its stall torque
/// alone. The other configs have no line and come as they are.
pub fn stall_torque_only(name: &str, overrides: &[&str]) -> Config {
    let path = config_path(name);
    let text = config_text(name).replace("no_load_speed", "# no_load_speed");
    Config::from_toml(&text, &path.display().to_string(), &strings(overrides))
        .expect("a bundled config loads")
}

/// A fresh temporary folder, removed when dropped.
pub fn temp_dir() -> TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

/// The built `catflip` binary, to be given arguments.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_catflip"))
}

/// Runs the binary with `args` in `dir` and waits for it.
pub fn output(args: &[&str], dir: &Path) -> Output {
    bin()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// A finished run's stdout and stderr as text.
pub fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A finished run's stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs the binary: its exit code (`None` when a signal ended it), stdout, stderr.
pub fn run(args: &[&str], dir: &Path) -> (Option<i32>, String, String) {
    let o = output(args, dir);
    let (out, err) = text(&o);
    (o.status.code(), out, err)
}

/// Runs the binary: whether it exited 0, stdout, stderr.
pub fn run_ok(args: &[&str], dir: &Path) -> (bool, String, String) {
    let (code, out, err) = run(args, dir);
    (code == Some(0), out, err)
}

/// Runs the binary: whether its files were written (exit 0, or 3 for a
/// partial result whose failures are recorded), stdout, stderr.
pub fn run_written(args: &[&str], dir: &Path) -> (bool, String, String) {
    let (code, out, err) = run(args, dir);
    (matches!(code, Some(0 | 3)), out, err)
}

/// The peak of a schedule CSV's torque columns in the given norm
/// (`per_motor`: the larger component; else the Euclidean norm), and its row
/// count; checks the header and that time never decreases.
pub fn schedule_peak(csv: &str, per_motor: bool) -> (f64, usize) {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    assert_eq!(header[0], "t_s");
    let i1 = header
        .iter()
        .position(|h| *h == "tau1_nm")
        .expect("a tau1_nm column");
    let mut last_t = f64::NEG_INFINITY;
    let mut peak = 0.0f64;
    let mut rows = 0;
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let t: f64 = f[0].parse().unwrap();
        assert!(t >= last_t, "time column must not decrease");
        last_t = t;
        let (a, b): (f64, f64) = (f[i1].parse().unwrap(), f[i1 + 1].parse().unwrap());
        peak = peak.max(if per_motor {
            a.abs().max(b.abs())
        } else {
            a.hypot(b)
        });
        rows += 1;
    }
    (peak, rows)
}

/// `run CONFIG --json` with `overrides` into `dir`: the exit code, the
/// summary it printed, and the folder of the run's files
/// (`<dir>/<name>/run[@<overrides>]`).
pub fn run_summary(
    name: &str,
    overrides: &[&str],
    dir: &Path,
) -> (Option<i32>, serde_json::Value, PathBuf, String) {
    let cfg = config_path(name);
    let mut args = vec!["run", cfg.to_str().unwrap(), "--json", "--out"];
    let out = dir.display().to_string();
    args.push(&out);
    for o in overrides {
        args.extend(["--set", o]);
    }
    let (code, stdout, err) = run(&args, dir);
    let summary: serde_json::Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("run {name} {overrides:?} printed no summary ({e}): {err}"));
    let set = if overrides.is_empty() {
        "run".to_string()
    } else {
        format!("run@{}", overrides.join(","))
    };
    let folder = dir.join(summary["name"].as_str().unwrap()).join(set);
    (code, summary, folder, err)
}

/// The line of `method` in a run's summary.
pub fn method_line<'a>(summary: &'a serde_json::Value, method: &str) -> &'a serde_json::Value {
    summary["methods"]
        .as_array()
        .expect("a methods array")
        .iter()
        .find(|m| m["method"] == method)
        .unwrap_or_else(|| panic!("no {method} line in {summary}"))
}

/// `# key = value` of a controls file's header.
pub fn controls_header(csv: &str, key: &str) -> Option<String> {
    csv.lines()
        .take_while(|l| l.starts_with('#'))
        .find_map(|l| {
            l[1..]
                .trim()
                .strip_prefix(&format!("{key} = "))
                .map(String::from)
        })
}

/// A design's schedule flown under the motor model (feed-forward + PD), as
/// the pipeline flies every design: designs do not carry their flight.
pub fn flown(
    spec: &catflip::design::spec::DesignSpec,
    plan: &dyn catflip::design::plan::ShapePlan,
) -> catflip::verify::simulate::SimReport {
    catflip::verify::simulate::dynamic_spec(spec, plan).expect("the design flies")
}

/// The planned shape flown exactly (kinematic simulation).
pub fn flown_kinematic(
    spec: &catflip::design::spec::DesignSpec,
    plan: &dyn catflip::design::plan::ShapePlan,
) -> catflip::verify::simulate::SimReport {
    catflip::verify::simulate::kinematic_spec(spec, plan).expect("the shape flies")
}

/// The number that follows `phrase` in a message (`drop the cat from at
/// least 12.4 m`: 12.4), up to the next space.
pub fn number_after(text: &str, phrase: &str) -> f64 {
    text.split(phrase)
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no number after `{phrase}` in {text}"))
}

/// The least-height stage's answer for `cfg` (both design families), as
/// `run` makes it; `cfg` must limit its motors. Made once per design
/// problem in the test run (the stage is deterministic: several tests ask
/// it of the same robot, about 2 s of CPU each time).
pub fn least(cfg: &Config) -> catflip::design::least_height::Heights {
    use catflip::design::least_height::{Families, Heights, heights};
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, OnceLock};
    type Slot = Arc<OnceLock<Heights>>;
    static MADE: OnceLock<Mutex<HashMap<String, Slot>>> = OnceLock::new();
    let spec = cfg.design_spec();
    // (the spec's every field is in its debug text: equal texts, equal problems)
    let slot: Slot = MADE
        .get_or_init(Default::default)
        .lock()
        .unwrap()
        .entry(format!("{spec:?}"))
        .or_default()
        .clone();
    slot.get_or_init(|| {
        heights(&spec, Families::Both, |_| {})
            .unwrap()
            .expect("a config with motor limits")
    })
    .clone()
}
