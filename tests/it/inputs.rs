//! Issue 31 through the real binary: bounded work, unit slips, interrupted
//! sweeps, reports that copy, and the small inconsistencies.

use crate::util::{self, bin, config_arg as config, output as run, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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
    let dir = util::temp_dir();
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

/// A `--set` of the key a sweep or `size` sets itself would be overwritten
/// at every point, yet name the output set: refused, naming both options;
/// so is a `[cat]` cylinder key beside the `[body]` that gives the halves.
#[test]
fn a_set_of_the_key_another_option_sets_is_refused() {
    let (seed, robot) = (config("seed"), config("robot-universal"));
    refused(
        &[
            "sweep",
            &seed,
            "--set-range",
            "fall.height=1:5:3",
            "--set",
            "fall.height=2",
        ],
        &["--set fall.height=2", "--set-range fall.height=1:5:3"],
    );
    refused(
        &["size", &robot, "--height", "1", "--set", "fall.height = 5"],
        &["--set fall.height = 5", "--height 1"],
    );
    refused(
        &[
            "size",
            &robot,
            "--height",
            "1",
            "--set",
            "design.objective=energy",
        ],
        &[
            "--set design.objective=energy conflicts with `catflip size`, which sets design.objective itself",
        ],
    );
    // NaN as Rust and Python print it reaches the key's own check
    refused(
        &["analyze", &seed, "--set", "fall.height=NaN"],
        &["`fall.height` = NaN is invalid: must be > 0 m"],
    );
    // a [cat] cylinder key beside a [body], named with its value
    refused(
        &["analyze", &config("box-robot"), "--set", "cat.mass=1"],
        &[
            "`cat.mass` = 1 is invalid",
            "[body] gives the halves",
            "leave them out of the config and its --set",
            "set (or sweep) its own keys, e.g. body.front.mass",
        ],
    );
    // a bend limit below the phased design's least bend: refused before any
    // design, by `run` as by `optimize` (run wrote a report of FAILED rows)
    refused(
        &["run", &seed, "--set", "limits.max_bend_deg=1"],
        &[
            "`limits.max_bend_deg` = 1 is invalid",
            "must exceed phased.bend_min_deg = 5 deg",
        ],
    );
    // a name too long for a folder (it blamed --out), and a [body] half's
    // bad mass named as the [body] keys the user typed, not only [cat]'s
    let long = format!("name={}", "n".repeat(101));
    refused(
        &["analyze", &seed, "--set", &long],
        &["at most 100 characters"],
    );
    refused(
        &[
            "analyze",
            &config("box-robot"),
            "--set",
            "body.rear.mass=1e9",
        ],
        &[
            "`cat.mass` = 1e9 is invalid",
            "with [body]",
            "body.rear / body.front",
        ],
    );
    // an empty robot file path (it read "Is a directory")
    refused(
        &["analyze", &config("box-robot"), "--set", "body.urdf=\"\""],
        &["`body.urdf` = \"\" is invalid: an empty path"],
    );
    // no Rust in the words: a section given a number, a whole-number range
    refused(
        &["analyze", &seed, "--set", "cat=1"],
        &["--set cat=1", "expected a table (a [section] of keys)"],
    );
    refused(
        &["analyze", &seed, "--set", "free.nodes=3"],
        &["`free.nodes` = 3 is invalid: must be a whole number in [4, 400]"],
    );
    // one key twice: the last would win silently, both would name the set
    refused(
        &[
            "analyze",
            &seed,
            "--set",
            "cat.mass=1",
            "--set",
            " cat.mass = 2",
        ],
        &["--set  cat.mass = 2 gives the key of --set cat.mass=1 again"],
    );
}

/// The least time without a torque or speed limit is zero: a config that
/// asks for it is refused at load, before any design, not run into a report
/// of failed methods (exit 3).
#[test]
fn a_least_time_design_without_a_limit_is_refused_before_any_work() {
    let seed = config("seed");
    for cmd in ["run", "optimize", "analyze"] {
        refused(
            &[cmd, &seed, "--set", "design.objective=time"],
            &["design.objective", "limits.max_torque"],
        );
    }
    // a limit makes it finite
    let dir = util::temp_dir();
    let o = run(
        &[
            "analyze",
            &seed,
            "--set",
            "design.objective=time",
            "--set",
            "limits.max_torque=1",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn work_is_bounded_up_front_by_each_keys_range() {
    let robot = config("robot-universal");
    let seed = config("seed");
    // the issue's cases: a 4 h fall (was 12.8 GB and a kill), a 10 km fall
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
    let seed = config("seed");
    let dir = util::temp_dir();
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
    let dir = util::temp_dir();
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
    let robot = config("robot-universal");
    let seed = config("seed");
    warns(
        &["analyze", &robot, "--set", "limits.no_load_speed=46"],
        &["limits.no_load_speed", "rev/min", "4.8171 rad/s"],
    );
    // a speed-up of the servo (what `size` may suggest) is not a slip
    let d = util::temp_dir();
    let o = run(
        &["analyze", &robot, "--set", "limits.no_load_speed=35"],
        d.path(),
    );
    assert!(!stderr(&o).contains("rev/min"), "{}", stderr(&o));
    // 1500 N mm on a 0.7 kg, 0.4 m robot (m g L = 2.747 N m)
    warns(
        &["analyze", &robot, "--set", "limits.max_torque=1500"],
        &[
            "limits.max_torque",
            "m g L = 2.747 N m",
            "1.5000 N m",
            "147.0998 N m",
        ],
    );
    warns(
        &["analyze", &seed, "--set", "analytic.theta_deg=0.785"],
        &["analytic.theta_deg", "radians", "44.98 deg"],
    );
    warns(
        &["analyze", &seed, "--set", "start.rotation_deg=[0,0,3.14]"],
        &["start.rotation_deg[2]", "radians", "179.91 deg"],
    );
    warns(
        &["analyze", &seed, "--set", "start.angular_velocity=[0,0,30]"],
        &["start.angular_velocity", "deg/s", "0.5236 rad/s"],
    );
    warns(
        &["analyze", &seed, "--set", "simulate.flip_tolerance=1"],
        &["simulate.flip_tolerance", "57.3 deg", "0.0175 rad"],
    );
    // a plausible start in degrees and rad/s, a tight tolerance: no question
    let d = util::temp_dir();
    let o = run(
        &[
            "analyze",
            &seed,
            "--set",
            "start.rotation_deg=[0,15,3]",
            "--set",
            "start.angular_velocity=[0.5,0,0]",
            "--set",
            "simulate.flip_tolerance=0.1",
        ],
        d.path(),
    );
    let err = stderr(&o);
    assert!(
        !err.contains("warning: start.") && !err.contains("warning: simulate."),
        "{err}"
    );
    warns(
        &["analyze", &seed, "--set", "cat.radius=0.6"],
        &["cat.radius", "wider", "diameter"],
    );
    warns(
        &["analyze", &seed, "--set", "cat.mass=350"],
        &["cat.mass", "grams", "0.35 kg"],
    );
    // a robot body's own mass, under its own key
    warns(
        &[
            "analyze",
            &config("box-robot"),
            "--set",
            "body.rear.mass=500",
        ],
        &["body.rear.mass", "grams", "0.5 kg"],
    );
    // and a robot file's masses in grams, named by the file (the box
    // robot's URDF with every link 1000 times heavier: the rear half 423 kg)
    let grams = util::temp_dir();
    let urdf = std::fs::read_to_string(util::configs().join("box-robot.urdf")).unwrap();
    let heavy: String = urdf
        .split("<mass value=\"")
        .enumerate()
        .map(|(i, part)| {
            if i == 0 {
                return part.to_string();
            }
            let (value, rest) = part.split_once('"').unwrap();
            let m: f64 = value.parse().unwrap();
            format!("<mass value=\"{}\"{rest}", m * 1000.0)
        })
        .collect();
    // the box robot's config on another URDF, `name.urdf` in the folder
    let box_robot_on = |name: &str, text: &str| {
        std::fs::write(grams.path().join(format!("{name}.urdf")), text).unwrap();
        let toml =
            util::config_text("box-robot").replace("box-robot.urdf", &format!("{name}.urdf"));
        let path = grams.path().join(format!("{name}.toml"));
        std::fs::write(&path, toml).unwrap();
        path.to_str().unwrap().to_string()
    };
    warns(
        &["analyze", &box_robot_on("grams", &heavy)],
        &["body.urdf (rear half's mass)", "grams", "0.423 kg"],
    );
    // a joint velocity in rev/min, named by the file, not as a key never typed
    let rpm = urdf.replace("velocity=\"5.969\"", "velocity=\"57\"");
    warns(
        &["analyze", &box_robot_on("rpm", &rpm)],
        &[
            "body.urdf (its joints' velocity, read as limits.max_speed)",
            "rev/min",
            "5.9690 rad/s",
        ],
    );
    // the analytic reference folding a robot's halves through each other at
    // the default angle says it is the default, and what to set instead
    // (two boxes whose shorter half reaches the other at 48.33 deg)
    let boxes = grams.path().join("boxes.toml");
    std::fs::write(
        &boxes,
        r#"name = "boxes"
[cat]
joint = "universal"
[body.rear]
mass = 0.6
com = [0, 0, 0]
inertia = [[0.00212, 0, 0], [0, 0.00194, 0], [0, 0, 0.00082]]
joint = [0, 0, 0.09]
[body.front]
mass = 0.4
com = [0, 0, 0.07]
inertia = [0.000987, 0.000867, 0.000547, 0, 0, 0]
joint = [0, 0, 0]
[fall]
height = 2.0
"#,
    )
    .unwrap();
    let o = run(&["analyze", boxes.to_str().unwrap()], grams.path());
    let err = stderr(&o);
    // a real half's radius of gyration is within the body's span: no question,
    // even for a half whose centre of mass is 5 mm from the joint (a motor
    // block there: its own reach is 10 times less than its gyration)
    assert!(!err.contains("kg cm^2"), "{err}");
    let o = run(
        &[
            "analyze",
            boxes.to_str().unwrap(),
            "--set",
            "body.front.com=[0,0,0.005]",
        ],
        grams.path(),
    );
    assert!(!stderr(&o).contains("kg cm^2"), "{}", stderr(&o));
    // the same inertia in kg cm^2 (21.2 kg cm^2 for 0.00212 kg m^2) is asked about
    warns(
        &[
            "analyze",
            boxes.to_str().unwrap(),
            "--set",
            "body.rear.inertia=[21.2,19.4,8.2,0,0,0]",
        ],
        &["body.rear.inertia", "kg cm^2", "2.120e-3 kg m^2"],
    );
    let line = err
        .lines()
        .find(|l| l.starts_with("warning: analytic.theta_deg"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(
        line.contains("(analytic.theta_deg's default)")
            && line.contains("the closest this body folds")
            && line.contains("set analytic.theta_deg = "),
        "{line}"
    );
    // a universal joint's motor axis for a body whose joint is the default
    // no-twist (cat.joint left out) was dropped unseen: refused, naming the
    // key; with the joint named no-twist it is ignored knowingly
    let pinned = grams.path().join("pinned.toml");
    std::fs::write(
        &pinned,
        std::fs::read_to_string(&boxes)
            .unwrap()
            .replace("joint = \"universal\"\n", ""),
    )
    .unwrap();
    let pinned = pinned.to_str().unwrap();
    assert!(run(&["analyze", pinned], grams.path()).status.success());
    refused(
        &["analyze", pinned, "--set", "body.front.axis=[0, 1, 0]"],
        &[
            "`body.front.axis` = [0.0, 1.0, 0.0] is invalid",
            "set cat.joint = \"universal\" (or \"no-twist\" to ignore the axes)",
        ],
    );
    let named = [
        "analyze",
        pinned,
        "--set",
        "body.front.axis=[0, 1, 0]",
        "--set",
        "cat.joint=no-twist",
    ];
    assert!(run(&named, grams.path()).status.success());
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
    // the shipped configs are plausible: no slip warnings; nor is a robot
    // body whose equivalent cylinder is wider than long (its cat.* keys
    // are not typed: a warning named cat.radius there)
    let flat = "body.rear.inertia=[0.01, 0.01, 0.01, 0, 0, 0]";
    for (c, set) in [
        ("seed", None),
        ("robot-universal", None),
        ("domestic-cat", None),
        ("box-robot", Some(flat)),
    ] {
        let dir = util::temp_dir();
        let cfg = config(c);
        let mut args = vec!["analyze", &cfg];
        args.extend(set.iter().flat_map(|s| ["--set", s]));
        let o = run(&args, dir.path());
        let err = stderr(&o);
        assert!(
            !err.contains("typed as") && !err.contains("pass through"),
            "{c}: {err}"
        );
    }
    // a tolerance typed in degrees: refused, the radians it would be named
    refused(
        &["analyze", &seed, "--set", "simulate.flip_tolerance=5"],
        &["simulate.flip_tolerance", "degrees? 5 deg = 0.0873 rad"],
    );
    // a robot's joint typed in millimetres: refused under the equivalent
    // cylinder's key, with the [body] keys that make it
    let robot = config("box-robot");
    refused(
        &["analyze", &robot, "--set", "body.rear.joint=[0, 0, 110.0]"],
        &["cat.length", "body.rear.joint - body.rear.com", "in metres"],
    );
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
    let dir = util::temp_dir();
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
        &config("seed"),
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

/// Starts the command, waits for the line of stderr that holds `needle`
/// (a sweep's progress: `" 11/"`), sends `signal` `times` times; returns the
/// exit status, the time from the signal to the exit, and stderr.
fn interrupt_after(
    dir: &Path,
    args: &[String],
    needle: &str,
    signal: &str,
    times: usize,
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
    loop {
        let mut line = String::new();
        assert!(err.read_line(&mut line).unwrap() > 0, "ended early: {text}");
        text.push_str(&line);
        if line.contains(needle) {
            break;
        }
    }
    let sent = std::time::Instant::now();
    let pid = child.id().to_string();
    for _ in 0..times {
        assert!(
            Command::new("kill")
                .args([signal, &pid])
                .status()
                .unwrap()
                .success()
        );
    }
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
    let dir = util::temp_dir();
    let set = |out: &str| {
        dir.path()
            .join(out)
            .join("seed/sweep-cat_mass@phased.nodes=10")
    };
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
    let (code, took, err) = interrupt_after(dir.path(), &args, " 11/", "-INT", 1);
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
        stderr(&o).contains("other settings") && stderr(&o).contains("(now cat.mass=0.5:2.4:21)"),
        "{}",
        stderr(&o)
    );
    // another --set is another sweep (its own set): nothing to resume there
    let mut same = args.clone();
    same.extend(["--set".into(), "cat.radius=0.11".into(), "--resume".into()]);
    let o = run(
        &same.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no sweep to resume"), "{}", stderr(&o));
    // an edited config file is refused by the state's record of the config
    let edited = dir.path().join("seed.toml");
    let text = read(PathBuf::from(config("seed")));
    std::fs::write(&edited, text.replace("radius = 0.1 ", "radius = 0.11 ")).unwrap();
    let mut changed = args.clone();
    changed[1] = edited.display().to_string();
    changed.push("--resume".into());
    let o = run(
        &changed.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
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
    let dir = util::temp_dir();
    let (code, took, err) = interrupt_after(dir.path(), &sweep_args("t"), " 1/", "-TERM", 1);
    assert_eq!(code, Some(130), "{err}");
    assert!(
        took < std::time::Duration::from_secs(1),
        "stopped after {took:?}"
    );
    let state = read(
        dir.path()
            .join("t/seed/sweep-cat_mass@phased.nodes=10/sweep-cat_mass.state.json"),
    );
    assert!(state.contains("\"partial\""), "{state}");
}

/// Files under `dir` (relative, sorted) with their contents.
fn contents(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v: Vec<(PathBuf, Vec<u8>)> = tree(dir)
        .into_iter()
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.strip_prefix(dir).unwrap().to_path_buf(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_report_is_an_ordinary_folder_that_copies_and_runs_keep_their_own() {
    let dir = util::temp_dir();
    let seed = config("seed");
    let plain = ["run", &seed, "--set", "free.nodes=12"];
    let o = run(&plain, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let report = dir.path().join("output/seed/run@free.nodes=12");
    assert_eq!(
        report,
        dir.path()
            .join("output/seed")
            .join(catflip::output::set_name("run", &["free.nodes=12".into()]))
    );
    let meta = std::fs::symlink_metadata(&report).unwrap();
    assert!(meta.is_dir() && !meta.file_type().is_symlink(), "{meta:?}");
    // no hidden staging folder or lock left beside it
    let hidden: Vec<PathBuf> = tree(&dir.path().join("output/seed"))
        .into_iter()
        .filter(|p| p.parent() == Some(&dir.path().join("output/seed")))
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
    let original = contents(&report);
    assert!(original.iter().any(|(p, _)| p == Path::new("index.html")));
    // cp -r and tar give working copies: the same files, and every file the
    // page refers to is there
    let copy = dir.path().join("copy");
    assert!(
        Command::new("cp")
            .arg("-r")
            .arg(&report)
            .arg(&copy)
            .status()
            .unwrap()
            .success()
    );
    assert_eq!(contents(&copy), original);
    let html = read(copy.join("index.html"));
    for part in html.split("src=\"").skip(1) {
        let target = part.split('"').next().unwrap();
        if !target.starts_with("data:") && !target.contains("://") && !target.starts_with('#') {
            assert!(
                copy.join(target).is_file(),
                "index.html refers to missing {target}"
            );
        }
    }
    let tgz = dir.path().join("r.tgz");
    let ok = Command::new("tar")
        .arg("czf")
        .arg(&tgz)
        .arg("-C")
        .arg(dir.path().join("output/seed"))
        .arg("run@free.nodes=12")
        .status()
        .unwrap();
    assert!(ok.success());
    let x = dir.path().join("x");
    std::fs::create_dir(&x).unwrap();
    assert!(
        Command::new("tar")
            .arg("xzf")
            .arg(&tgz)
            .arg("-C")
            .arg(&x)
            .status()
            .unwrap()
            .success()
    );
    assert_eq!(contents(&x.join("run@free.nodes=12")), original);
    // the issue's item 5: a run with another override keeps its own report,
    // and the plain run's is untouched
    let twist = [
        "run",
        &seed,
        "--set",
        "free.nodes=12",
        "--set",
        "cat.joint=no-twist",
    ];
    let o = run(&twist, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let other = dir
        .path()
        .join("output/seed/run@free.nodes=12,cat.joint=no-twist");
    assert!(other.join("summary.json").is_file());
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .contains("run@free.nodes=12,cat.joint=no-twist/index.html")
    );
    assert_eq!(
        contents(&report),
        original,
        "the first run's report changed"
    );
    // running the same again replaces its own report whole (by exchange)
    let o = run(&plain, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&report).unwrap().is_dir());
    let names = |d: &Path| contents(d).into_iter().map(|(p, _)| p).collect::<Vec<_>>();
    assert_eq!(names(&report), names(&copy));
    // a folder catflip did not write is never replaced
    let mine = dir.path().join("output/seed/analyze");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let o = run(&["analyze", &seed], dir.path());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not a set published by catflip"),
        "{}",
        stderr(&o)
    );
    assert_eq!(read(mine.join("notes.txt")), "mine");
}

#[test]
fn the_small_inconsistencies_are_fixed() {
    let dir = util::temp_dir();
    let seed = config("seed");
    // a JSON schedule replays as its CSV does
    let o = run(&["analyze", &seed], dir.path());
    assert!(o.status.success());
    let base = dir.path().join("output/seed/analyze");
    let replay = |file: &str| {
        let path = base.join(file).display().to_string();
        let o = run(
            &[
                "simulate",
                &seed,
                "--schedule",
                &path,
                "--json",
                "--out",
                "sim",
            ],
            dir.path(),
        );
        assert!(o.status.success(), "{file}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["flip_error_rad"].as_f64().unwrap()
    };
    let (from_csv, from_json) = (replay("analytic.csv"), replay("analytic.schedule.json"));
    assert!(from_json.abs() < 1e-6, "{from_json}");
    // the CSV rounds to 12 digits, the JSON keeps every bit: the same flip to 1e-9
    assert!(
        (from_csv - from_json).abs() < 1e-9,
        "{from_csv} vs {from_json}"
    );
    // a broken JSON schedule names the row and points at the CSV
    let bad = dir.path().join("bad.schedule.json");
    let text = read(base.join("analytic.schedule.json")).replacen("\"fold\"", "\"folding\"", 1);
    std::fs::write(&bad, text).unwrap();
    let o = run(
        &[
            "simulate",
            &seed,
            "--schedule",
            bad.to_str().unwrap(),
            "--out",
            "bad",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("row 0") && stderr(&o).contains("folding"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("bad").exists());
    // one point of a range is refused, one point given as FROM:FROM:1 runs
    refused(
        &["sweep", &seed, "--set-range", "fall.height=1:10:1"],
        &["--set-range", "COUNT 1", "1:1:1"],
    );
    // and so is one point given several times (it designed each)
    refused(
        &["sweep", &seed, "--set-range", "fall.height=5:5:3"],
        &["--set-range", "one point designed 3 times", "5:5:1"],
    );
    let o = run(
        &[
            "sweep",
            &seed,
            "--set-range",
            "fall.height=1:1:1",
            "--methods",
            "analytic",
            "--out",
            "one",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // values outside the key's range are refused up front, like free.nodes=40:50:4
    refused(
        &["sweep", &seed, "--set-range", "fall.height=-1:10:4"],
        &[
            "--set-range",
            "fall.height=-1:10:4",
            "1 of 4 points",
            "fall.height = -1",
        ],
    );
    refused(
        &["sweep", &seed, "--set-range", "fall.height=1:1e4:3"],
        &["2 of 3 points", "fall.height", "30 s"],
    );
    // venv/ is ignored
    let ignore = read(util::repo().join(".gitignore"));
    assert!(
        ignore
            .lines()
            .any(|l| l.trim() == "/venv/" || l.trim() == "venv/"),
        "{ignore}"
    );
}

/// Virtual memory allowed to each command of the cap test, KB (1 GB). The
/// largest accepted run measured 133 MB resident; the rest of the margin is
/// thread stacks and allocator arenas, which count against `ulimit -v`.
const MEMORY_CAP_KB: u64 = 1 << 20;

/// Runs the binary under `ulimit -v MEMORY_CAP_KB`.
fn run_capped(args: &[&str], dir: &Path) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_CAP_KB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_catflip"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sh runs")
}

fn size(dir: &Path) -> u64 {
    tree(dir)
        .iter()
        .filter(|p| p.is_file())
        .map(|p| p.metadata().unwrap().len())
        .sum()
}

/// The largest inputs the ranges accept (the longest fall, the most rows, the
/// stiffest PD) finish under the memory cap, write at most the stated
/// amounts and report only finite numbers.
#[test]
fn the_largest_accepted_inputs_hold_the_memory_and_output_caps() {
    let dir = util::temp_dir();
    let robot = config("robot-universal");
    // 30 s at 9.81 m/s^2: 4414.5 m
    let longest = "fall.height=4414";
    let o = run_capped(
        &[
            "simulate",
            &robot,
            "--set",
            longest,
            "--set",
            "simulate.samples_per_phase=30000",
            "--set",
            "simulate.pd_bandwidth_hz=100",
            "--json",
            "--out",
            "s",
        ],
        dir.path(),
    );
    let err = stderr(&o);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{err}");
    assert!(
        !err.contains("memory allocation") && !err.contains("panicked"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(catflip::output::null_numbers(&v).is_empty(), "{v}");
    let o = run_capped(
        &[
            "analyze",
            &robot,
            "--set",
            longest,
            "--set",
            "simulate.samples_per_phase=30000",
            "--json",
            "--out",
            "a",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(catflip::output::null_numbers(&v).is_empty(), "{v}");
    assert!(
        size(&dir.path().join("s")) < 50_000_000,
        "{}",
        size(&dir.path().join("s"))
    );
    assert!(
        size(&dir.path().join("a")) < 50_000_000,
        "{}",
        size(&dir.path().join("a"))
    );
    // the issue's run, at the longest fall it accepts (the 1e9 m one is refused)
    let o = run_capped(&["run", &robot, "--set", longest, "--out", "r"], dir.path());
    let err = stderr(&o);
    assert!(
        matches!(o.status.code(), Some(0 | 3 | 4)),
        "{:?}: {err}",
        o.status
    );
    assert!(
        !err.contains("memory allocation") && !err.contains("panicked"),
        "{err}"
    );
    let written = size(&dir.path().join("r"));
    assert!(written < 100_000_000, "a run wrote {written} bytes");
}

/// The override of [`robustness_args`] (its set's folder carries it).
const REPLAN_EVERY: &str = "control.replan_every=10";

/// `catflip robustness` on the seed cat, `trials` trials on 2 threads, into
/// `out`, replanning every 10th control period (what is checked here is the
/// stop and the resume, not the controllers: a study of 40 trials then takes
/// 5 s, not 25).
fn robustness_args(out: &str, trials: usize) -> Vec<String> {
    [
        "robustness",
        &config("seed"),
        "--trials",
        &trials.to_string(),
        "--threads",
        "2",
        "--set",
        REPLAN_EVERY,
        "--out",
        out,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

#[test]
fn an_interrupted_robustness_study_publishes_its_finished_trials_and_resumes_to_the_same_results() {
    let dir = util::temp_dir();
    let set = |out: &str| {
        dir.path()
            .join(out)
            .join(format!("seed/robustness@{REPLAN_EVERY}"))
    };
    fn strs(a: &[String]) -> Vec<&str> {
        a.iter().map(|s| s.as_str()).collect()
    }
    let whole_args = robustness_args("whole", 40);
    let o = run(&strs(&whole_args), dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = read(set("whole").join("robustness.csv"));
    let whole_json = read(set("whole").join("robustness.json"));
    // the study's page: each controller's rate and interval as the JSON has
    // them, and the figure with its caption
    let page = read(set("whole").join("index.html"));
    let summary: serde_json::Value = serde_json::from_str(&whole_json).unwrap();
    for c in summary["controllers"].as_array().unwrap() {
        let pct = |x: &serde_json::Value| format!("{:.1}", 100.0 * x.as_f64().unwrap());
        let row = format!(
            "<td>{}</td><td>{} %</td><td>{} to {} %</td>",
            c["name"].as_str().unwrap(),
            pct(&c["success_rate"]),
            pct(&c["ci95"][0]),
            pct(&c["ci95"][1])
        );
        assert!(page.contains(&row), "{row}: {page}");
    }
    assert!(page.contains("<img src=\"robustness.svg\"") && page.contains("<figcaption>"));
    // the design flown, the controllers' rate and delay beside the robot's
    assert!(
        page.contains("The controllers fly the free-form peak-torque design seeded by the phased schedule")
            && page.contains("predict over a delay of 5 ms (control.delay_ms); the simulated robot's actuator delay is 5 ms (robustness.delay_ms). "),
        "{page}"
    );
    assert!(!page.contains("Partial study"));
    // each perturbation's bins (two for 40 trials), with the trials each
    // holds: all 40 of them
    let bins = page
        .split("hold these numbers of trials, bin by bin: ")
        .nth(1)
        .and_then(|t| t.split('.').next())
        .unwrap_or_else(|| panic!("no bins' trials on the page: {page}"));
    let counted: Vec<(&str, usize)> = bins
        .split("; ")
        .map(|b| {
            let (what, n) = b.split_once(' ').unwrap();
            let n: Vec<usize> = n.split(", ").map(|k| k.parse().unwrap()).collect();
            assert_eq!(n.len(), catflip::control::figure::bin_count(40), "{b}");
            (what, n.iter().sum())
        })
        .collect();
    assert_eq!(
        counted,
        [("spin", 40), ("tilt", 40), ("inertia", 40)],
        "{bins}"
    );
    // SIGINT once the progress shows 10 of the 40 trials (a line every 2),
    // twice at once, as GNU `timeout` sends it (to the command, then to its
    // process group): one request, the finished trials still published
    let args = robustness_args("part", 40);
    let (code, took, err) = interrupt_after(dir.path(), &args, " 10/", "-INT", 2);
    eprintln!("robustness stopped {took:?} after SIGINT");
    assert_eq!(code, Some(130), "{err}");
    assert!(
        took < std::time::Duration::from_secs(1),
        "stopped after {took:?}"
    );
    assert!(
        err.contains("interrupted") && err.contains("--resume"),
        "{err}"
    );
    let csv = read(set("part").join("robustness.csv"));
    let json: serde_json::Value =
        serde_json::from_str(&read(set("part").join("robustness.json"))).unwrap();
    assert_eq!(json["status"], "partial");
    assert!(read(set("part").join("index.html")).contains("Partial study: "));
    let state: serde_json::Value =
        serde_json::from_str(&read(set("part").join("robustness.state.json"))).unwrap();
    assert_eq!(state["status"], "partial");
    let done = csv.lines().count() - 1;
    assert!((10..40).contains(&done), "{done}");
    assert_eq!(json["trials"], done);
    // the finished trials are the uninterrupted study's, in trial order
    let index = |row: &str| row.split(',').next().unwrap().parse::<usize>().unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(rows.windows(2).all(|w| index(w[0]) < index(w[1])), "{csv}");
    for row in csv.lines() {
        assert!(whole.lines().any(|w| w == row), "{row}");
    }
    // no hidden staging folder or lock left behind
    let leftovers: Vec<PathBuf> = tree(&dir.path().join("part"))
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            name.starts_with('.') && name != ".catflip-set"
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // a resume of another study is refused, naming what differs, and keeps the partial set
    let mut other_seed = args.clone();
    other_seed.extend(["--seed".into(), "2".into()]);
    for (mut other, what) in [
        (other_seed, "--seed 1 (now 2)"),
        (robustness_args("part", 41), "--trials 40 (now 41)"),
    ] {
        other.push("--resume".into());
        let o = run(&strs(&other), dir.path());
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("other settings") && stderr(&o).contains(what),
            "{}",
            stderr(&o)
        );
    }
    assert_eq!(read(set("part").join("robustness.csv")), csv);
    // --resume flies the rest only, and the result is the whole study's, byte for byte
    let mut resume = args.clone();
    resume.push("--resume".into());
    let o = run(&strs(&resume), dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("resuming: {done} of 40 trials kept")),
        "{err}"
    );
    assert!(
        !err.contains(" 1/40 trials"),
        "flew the kept trials again: {err}"
    );
    assert_eq!(read(set("part").join("robustness.csv")), whole);
    assert_eq!(read(set("part").join("robustness.json")), whole_json);
    // (the page's table; its replans' wall times differ run to run)
    let table = |page: &str| {
        page[page.find("<table>").unwrap()..page.find("</table>").unwrap()].to_string()
    };
    assert_eq!(table(&read(set("part").join("index.html"))), table(&page));
    let state: serde_json::Value =
        serde_json::from_str(&read(set("part").join("robustness.state.json"))).unwrap();
    assert_eq!(state["status"], "complete");
    // the replans' times are those of the trials this run flew, and say so
    let timing = read(set("part").join("robustness.timing.json"));
    let t: serde_json::Value = serde_json::from_str(&timing).unwrap();
    assert_eq!(
        (t["trials_timed"].as_u64(), t["trials"].as_u64()),
        (Some(40 - done as u64), Some(40))
    );
    assert!(t["replans"].as_u64().unwrap() > 0, "{timing}");
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains(&format!("timed over {} of the 40 (a --resume", 40 - done)),
        "{said}"
    );
    // resumed when complete: nothing flown, the times kept (they read 0 replans)
    let o = run(&strs(&resume), dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(read(set("part").join("robustness.timing.json")), timing);
}

/// A command that publishes no partial set (`run`, `size`, the designs)
/// stopped by SIGINT mid-work exits 130 within a second and leaves nothing:
/// no staging folder, no lock, not even the output folder it created; a set
/// it published before stays.
#[test]
fn an_interrupted_run_leaves_nothing_half_written() {
    let dir = crate::util::temp_dir();
    let robot = crate::util::config_arg("robot-universal");
    let args: Vec<String> = ["run", &robot, "--out", "o"].map(String::from).to_vec();
    // the analytic schedule done, the least height (about 2 s) under way
    let (code, took, err) = interrupt_after(dir.path(), &args, "[1/5]", "-INT", 1);
    assert_eq!(code, Some(130), "{err}");
    assert!(took < std::time::Duration::from_secs(1), "{took:?}");
    assert!(err.contains("interrupted: "), "{err}");
    assert!(!dir.path().join("o").exists(), "{err}");
    // with a published set beside it: that set stays, the new one is not begun
    let seed = crate::util::config_arg("seed");
    let (ok, _, err) = crate::util::run_ok(&["analyze", &seed, "--out", "o"], dir.path());
    assert!(ok, "{err}");
    let (code, _, err) = interrupt_after(dir.path(), &args, "[1/5]", "-TERM", 1);
    assert_eq!(code, Some(130), "{err}");
    let left: Vec<String> = walk(&dir.path().join("o"));
    assert!(left.iter().all(|p| p.starts_with("seed")), "{left:?}");
    assert!(left.iter().any(|p| p.ends_with("analyze.json")), "{left:?}");
}

/// Every path under `root`, relative to it.
fn walk(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            out.push(p.strip_prefix(root).unwrap().display().to_string());
            if p.is_dir() && !p.is_symlink() {
                stack.push(p);
            }
        }
    }
    out
}

/// A config without a required key or section says which and what to add
/// (not the parser's "line 1, column 1" over the file's first comment),
/// exits 2 and writes nothing.
#[test]
fn a_missing_key_or_section_is_named_with_what_to_add() {
    let dir = util::temp_dir();
    let cat = "[cat]\nmass = 1.0\nlength = 0.2\nradius = 0.03\n";
    let fall = "[fall]\nheight = 2.0\n";
    for (text, says) in [
        (
            format!("# my robot\n{cat}{fall}"),
            "missing key `name` (required)",
        ),
        (
            format!("# my robot\nname = \"r\"\n{cat}"),
            "missing section `[fall]` (required): add it with `height`, the drop height in m",
        ),
        (
            format!("# my robot\nname = \"r\"\n{fall}"),
            "missing section `[cat]` (required unless `[body]` gives the halves)",
        ),
        (
            format!("# my robot\nname = \"r\"\n{cat}[fall]\nmargin = 0.1\n"),
            "missing key `fall.height` (required)",
        ),
    ] {
        let path = dir.path().join("mine.toml");
        std::fs::write(&path, &text).unwrap();
        let o = run(&["run", path.to_str().unwrap(), "--out", "out"], dir.path());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(says), "{text}: {err}");
        assert!(!err.contains("# my robot"), "{text}: {err}");
        assert!(!dir.path().join("out").exists(), "{text}");
    }
}

/// A number typed with its unit is refused with the number alone to give
/// (in the key's unit, or converted to it); a bend limit of a few "degrees"
/// is asked about as radians before the advice to lower the other key.
#[test]
fn a_number_with_its_unit_or_in_radians_is_refused_with_what_to_give() {
    let dir = util::temp_dir();
    let (seed, robot) = (config("seed"), config("robot-universal"));
    for (cfg, set, says) in [
        (
            &seed,
            "fall.height=1.5m",
            "give the number alone: `fall.height=1.5` (the key is in m)",
        ),
        (
            &seed,
            "cat.mass=350g",
            "give the number alone, converted to the key's unit, kg (`350g` is not read)",
        ),
        (
            &robot,
            "limits.max_bend_deg=2.5",
            "if 2.5 is in radians, it is 143.24 deg: the key is in degrees; for a tighter limit, lower that key too",
        ),
    ] {
        let o = run(&["run", cfg, "--set", set, "--out", "out"], dir.path());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(says), "{set}: {err}");
        assert!(!dir.path().join("out").exists(), "{set}");
    }
}

/// A slip in a key the front half inherits is warned about once, under the
/// key the user typed; the front half's own key, typed, under its own.
#[test]
fn an_inherited_slip_is_warned_about_under_the_typed_key() {
    let dir = util::temp_dir();
    let path = dir.path().join("r.toml");
    std::fs::write(
        &path,
        "name = \"r\"\n[cat]\nmass = 0.6\nlength = 0.12\nradius = 0.03\n[cat.front]\nmass = 0.4\n[fall]\nheight = 2.0\n",
    )
    .unwrap();
    let warnings = |set: &str| -> Vec<String> {
        let o = run(
            &["analyze", path.to_str().unwrap(), "--set", set],
            dir.path(),
        );
        stderr(&o)
            .lines()
            .filter(|l| l.starts_with("warning:") && l.contains("centimetres"))
            .map(String::from)
            .collect()
    };
    let w = warnings("cat.length=12");
    assert!(
        w.len() == 1 && w[0].starts_with("warning: cat.length: 12 m"),
        "{w:?}"
    );
    let w = warnings("cat.front.length=12");
    assert!(
        w.len() == 1 && w[0].starts_with("warning: cat.front.length: 12 m"),
        "{w:?}"
    );
}
