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
