//! Issue 31 through the real binary: bounded work, unit slips, interrupted
//! sweeps, reports that copy, and the small inconsistencies.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_catflip"))
}

fn config(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("configs")
        .join(name)
        .display()
        .to_string()
}

fn run(args: &[&str], dir: &Path) -> Output {
    bin()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every file and folder under `dir`, hidden ones included.
fn tree(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(rd) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in rd.flatten() {
        let p = e.path();
        out.push(p.clone());
        if p.is_dir() && !p.is_symlink() {
            out.extend(tree(&p));
        }
    }
    out
}

/// Bad input: exit 2, a message naming `needles`, nothing written.
fn refused(args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let o = run(args, dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{err}` should name `{n}`");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        tree(dir.path()).is_empty(),
        "{args:?} wrote {:?}",
        tree(dir.path())
    );
}

#[test]
fn work_is_bounded_up_front_by_each_keys_range() {
    let robot = config("robot-universal.toml");
    let seed = config("seed.toml");
    // the cases: a 4 h fall (was 12.8 GB and a kill), a 10 km fall
    // (was 179 MB of output), and an overflowing fall time (was exit 0 with nulls)
    refused(
        &["run", &robot, "--set", "fall.height=1e9"],
        &["fall.height", "1e9", "30 s"],
    );
    refused(
        &["run", &robot, "--set", "fall.height=1e4"],
        &["fall.height", "30 s"],
    );
    refused(
        &["analyze", &seed, "--set", "fall.height=1e308"],
        &["fall.height", "1e308"],
    );
    refused(
        &["analyze", &seed, "--set", "fall.height=1e-300"],
        &["fall.height", "0.001 s"],
    );
    refused(
        &["analyze", &seed, "--set", "fall.gravity=1e-300"],
        &["fall.gravity"],
    );
    // every documented range, just outside each end
    for r in catflip::config::ranges::RANGES {
        let key = r.key;
        let mut base = vec!["analyze", &seed];
        let needs_torque = key.starts_with("limits.no_load");
        if needs_torque {
            base.extend(["--set", "limits.max_torque=1"]);
        }
        if key == "cat.front.length" {
            // a radius that fits the shortest length tried
            base.extend(["--set", "cat.front.radius=1e-6"]);
        }
        let above = if key == "free.max_iterations" {
            format!("{key}={}", r.max as u64 + 1)
        } else {
            format!("{key}={:e}", r.max * 10.0)
        };
        let mut args = base.clone();
        args.extend(["--set", &above]);
        refused(&args, &[key]);
        if r.min > 0.0 && key != "free.max_iterations" {
            let below = format!("{key}={:e}", r.min / 10.0);
            let mut args = base.clone();
            args.extend(["--set", &below]);
            refused(&args, &[key]);
        }
    }
    refused(
        &[
            "analyze",
            &seed,
            "--set",
            "analytic.split=[0.001, 0.5, 0.499]",
        ],
        &["analytic.split[0]"],
    );
    refused(
        &["analyze", &seed, "--set", "cat.radius=1e-9"],
        &["cat.radius"],
    );
    refused(
        &["analyze", &seed, "--set", "analytic.theta_deg=179.99999"],
        &["analytic.theta_deg", "turns"],
    );
    // a sweep's grid is capped too
    refused(
        &["sweep", &seed, "--set-range", "fall.height=1:2:100000"],
        &["--set-range", "10000"],
    );
}

#[test]
fn the_longest_accepted_fall_gives_finite_numbers_only() {
    let seed = config("seed.toml");
    let dir = tempfile::tempdir().unwrap();
    // 30 s at 9.8 m/s^2 is 4410 m
    for (h, ok) in [("4409", true), ("4411", false)] {
        let set = format!("fall.height={h}");
        let o = run(&["analyze", &seed, "--set", &set, "--json"], dir.path());
        assert_eq!(o.status.success(), ok, "{h}: {}", stderr(&o));
        if ok {
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            assert!(catflip::output::null_numbers(&v).is_empty(), "{v}");
            assert!(v["fall_time_s"].as_f64().unwrap() <= 30.0);
        }
    }
}

/// A warning on stderr that names the key and the slip, and the command runs.
fn warns(args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let o = run(args, dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("warning:") && needles.iter().all(|n| l.contains(n)))
        .unwrap_or_else(|| panic!("{args:?}: no warning naming {needles:?} in `{err}`"));
    assert!(line.contains('?'), "the slip is asked about: {line}");
}

#[test]
fn unit_slips_are_warned_about_and_impossible_cats_refused() {
    let robot = config("robot-universal.toml");
    let seed = config("seed.toml");
    warns(
        &["analyze", &robot, "--set", "limits.no_load_speed=46"],
        &["limits.no_load_speed", "rev/min", "4.8171 rad/s"],
    );
    warns(
        &["analyze", &seed, "--set", "analytic.theta_deg=0.785"],
        &["analytic.theta_deg", "radians", "44.98 deg"],
    );
    warns(
        &["analyze", &seed, "--set", "cat.radius=0.6"],
        &["cat.radius", "wider", "diameter"],
    );
    warns(
        &["analyze", &seed, "--set", "cat.mass=350"],
        &["cat.mass", "grams", "0.35 kg"],
    );
    warns(
        &["analyze", &seed, "--set", "cat.length=23"],
        &["cat.length", "centimetres"],
    );
    warns(
        &["analyze", &seed, "--set", "fall.gravity=981"],
        &["fall.gravity", "cm/s^2"],
    );
    warns(
        &["analyze", &seed, "--set", "fall.gravity=32.2"],
        &["fall.gravity", "ft/s^2"],
    );
    // the shipped configs are plausible: no slip warnings
    for c in ["seed.toml", "robot-universal.toml", "domestic-cat.toml"] {
        let dir = tempfile::tempdir().unwrap();
        let o = run(&["analyze", &config(c)], dir.path());
        let err = stderr(&o);
        assert!(
            !err.contains("typed as") && !err.contains("pass through"),
            "{c}: {err}"
        );
    }
    // physically impossible: a radius above the length, halves that
    // intersect at the bend limit (the seed's halves allow 168.46 deg)
    refused(
        &["analyze", &seed, "--set", "cat.radius=1.5"],
        &["cat.radius", "cat.length"],
    );
    refused(
        &["analyze", &seed, "--set", "limits.max_bend_deg=175"],
        &["limits.max_bend_deg", "into each other", "168.46"],
    );
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &["analyze", &seed, "--set", "limits.max_bend_deg=168"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The sweep of the interrupt tests: 20 points, two continuation chunks,
/// one thread, so that the chunks run in order (about 0.2 s a point).
fn sweep_args(out: &str) -> Vec<String> {
    [
        "sweep",
        &config("seed.toml"),
        "--set-range",
        "cat.mass=0.5:2.4:20",
        "--methods",
        "analytic,phased",
        "--threads",
        "1",
        "--set",
        "phased.nodes=10",
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}

/// Starts the sweep, waits for the progress line that shows `points` done,
/// sends `signal`; returns the exit status, the time from the signal to the
/// exit, and stderr.
fn interrupt_after(
    dir: &Path,
    args: &[String],
    points: usize,
    signal: &str,
) -> (Option<i32>, std::time::Duration, String) {
    use std::io::BufRead;
    let mut child = bin()
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut text = String::new();
    let needle = format!(" {points}/");
    loop {
        let mut line = String::new();
        assert!(err.read_line(&mut line).unwrap() > 0, "ended early: {text}");
        text.push_str(&line);
        if line.contains(&needle) {
            break;
        }
    }
    let sent = std::time::Instant::now();
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args([signal, &pid])
            .status()
            .unwrap()
            .success()
    );
    let status = child.wait().unwrap();
    let took = sent.elapsed();
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    (status.code(), took, text + &rest)
}

fn read(p: PathBuf) -> String {
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn an_interrupted_sweep_publishes_its_finished_points_and_resumes_to_the_same_results() {
    let dir = tempfile::tempdir().unwrap();
    let set = |out: &str| dir.path().join(out).join("seed/sweep-cat_mass");
    let o = run(
        &sweep_args("whole")
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>(),
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = read(set("whole").join("sweep-cat_mass.csv"));
    // SIGINT after the first chunk (10 points) and one more point
    let args = sweep_args("part");
    let (code, took, err) = interrupt_after(dir.path(), &args, 11, "-INT");
    assert_eq!(code, Some(130), "{err}");
    assert!(
        took < std::time::Duration::from_secs(1),
        "stopped after {took:?}"
    );
    assert!(
        err.contains("interrupted") && err.contains("--resume"),
        "{err}"
    );
    let csv = read(set("part").join("sweep-cat_mass.csv"));
    let state: serde_json::Value =
        serde_json::from_str(&read(set("part").join("sweep-cat_mass.state.json"))).unwrap();
    assert_eq!(state["status"], "partial");
    let done = state["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| !p.is_null())
        .count();
    assert!((11..20).contains(&done), "{done}");
    assert_eq!(csv.lines().count(), done + 1);
    // the finished points are the uninterrupted sweep's, row for row
    for row in csv.lines() {
        assert!(whole.lines().any(|w| w == row), "{row}");
    }
    // no staging folder or lock left behind
    let leftovers: Vec<PathBuf> = tree(&dir.path().join("part"))
        .into_iter()
        .filter(|p| {
            p.to_string_lossy().ends_with(".lock") || p.to_string_lossy().ends_with(".link")
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // a resume with another grid is refused, and leaves the partial set
    let mut other = args.clone();
    other[3] = "cat.mass=0.5:2.4:21".into();
    other.push("--resume".into());
    let o = run(
        &other.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("other settings") && stderr(&o).contains("the range"),
        "{}",
        stderr(&o)
    );
    let mut same = args.clone();
    same.extend(["--set".into(), "cat.radius=0.11".into(), "--resume".into()]);
    let o = run(
        &same.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("the config"), "{}", stderr(&o));
    // --resume computes the rest only, and the result is the whole sweep's
    let mut resume = args.clone();
    resume.push("--resume".into());
    let o = run(
        &resume.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        dir.path(),
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("resuming: {done} of 20 points kept")),
        "{err}"
    );
    assert!(
        !err.contains(" 1/20 points"),
        "recomputed the kept chunk: {err}"
    );
    assert_eq!(read(set("part").join("sweep-cat_mass.csv")), whole);
    let state: serde_json::Value =
        serde_json::from_str(&read(set("part").join("sweep-cat_mass.state.json"))).unwrap();
    assert_eq!(state["status"], "complete");
}

#[test]
fn sigterm_stops_a_sweep_too() {
    let dir = tempfile::tempdir().unwrap();
    let (code, took, err) = interrupt_after(dir.path(), &sweep_args("t"), 1, "-TERM");
    assert_eq!(code, Some(130), "{err}");
    assert!(
        took < std::time::Duration::from_secs(1),
        "stopped after {took:?}"
    );
    let state = read(
        dir.path()
            .join("t/seed/sweep-cat_mass/sweep-cat_mass.state.json"),
    );
    assert!(state.contains("\"partial\""), "{state}");
}
