//! The real binary on a temporary directory.

use crate::util;

use std::path::Path;
use util::{bin, configs, output, temp_dir, text};

#[test]
fn analyze_json_has_the_documented_keys_and_writes_a_schedule() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let o = output(&["analyze", cfg.to_str().unwrap(), "--json"], dir.path());
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for key in [
        "fall_time_s",
        "theta_deg",
        "bend_deg",
        "I_t",
        "I_a",
        "I_yy",
        "C",
        "omega0_rad_s",
        "twist_rad",
        "one_turn_theta_deg",
        "seed_torque_estimate_nm",
        "peak_torque_nm",
        "flip_deg",
        "tilt_deg",
        "phase_durations_s",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert!((v["flip_deg"].as_f64().unwrap().abs() - 180.0).abs() < 1e-6);
    let csv = std::fs::read_to_string(dir.path().join("output/seed/analyze/analytic.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("t_s,phase,"));
    // the CSV's peak agrees with the JSON's (the JSON samples more densely)
    let peak = lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').skip(8).map(|x| x.parse().unwrap()).collect();
            f[0].hypot(f[1])
        })
        .fold(0.0, f64::max);
    let jp = v["peak_torque_nm"].as_f64().unwrap();
    assert!(
        peak <= jp * (1.0 + 1e-9) && peak > 0.99 * jp,
        "{peak} vs {jp}"
    );
    assert_eq!(v["verdict"], "ok");
    // a torque limit below the schedule's peak is flagged in the analysis
    let limited = run_json(
        &[
            "analyze",
            cfg.to_str().unwrap(),
            "--set",
            "limits.max_torque=1",
            "--out",
            "limited",
        ],
        dir.path(),
    );
    assert_eq!(limited["verdict"], "flagged");
    let reason = limited["reason"].as_str().unwrap();
    assert!(
        reason.contains("limits.max_torque") && reason.contains(&format!("{jp:.4}")),
        "{reason}"
    );
}

/// `analyze` prints the seed's own example rate with erratum E2 named: the
/// seed's numbers (its inertia, 10 m) give 2.2587 rad/s with `sin(theta/2)`.
#[test]
fn analyze_names_the_seeds_rate_and_its_erratum() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let o = output(
        &[
            "analyze",
            cfg.to_str().unwrap(),
            "--set",
            "analytic.seed_inertia=true",
        ],
        dir.path(),
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let line = out
        .lines()
        .find(|l| l.contains("seed's omega"))
        .unwrap_or_else(|| panic!("no seed's omega line: {out}"));
    assert!(
        line.contains("2.2587 rad/s") && line.contains("E2"),
        "{line}"
    );
}

#[test]
fn simulate_replays_a_written_schedule() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let o = output(&["analyze", cfg.to_str().unwrap()], dir.path());
    assert!(o.status.success());
    let sched = dir.path().join("output/seed/analyze/analytic.csv");
    let o = output(
        &[
            "simulate",
            cfg.to_str().unwrap(),
            "--schedule",
            sched.to_str().unwrap(),
            "--json",
        ],
        dir.path(),
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["flip_error_rad"].as_f64().unwrap().abs() < 1e-6, "{out}");
    assert!(v["momentum_drift_nms"].as_f64().unwrap() < 1e-12);
    // from another height it is refused, with the height that fits it
    let replay = |height: &str| {
        let set = format!("fall.height={height}");
        output(
            &[
                "simulate",
                cfg.to_str().unwrap(),
                "--set",
                &set,
                "--schedule",
                sched.to_str().unwrap(),
            ],
            dir.path(),
        )
    };
    let o = replay("7.5");
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let fits = err
        .split("--set fall.height=")
        .nth(1)
        .and_then(|s| s.split('`').next())
        .unwrap_or_else(|| panic!("no height in: {err}"));
    let h: f64 = fits.parse().unwrap();
    assert!((h - 10.0).abs() < 1e-6, "{err}");
    assert!(replay(fits).status.success());
}

#[test]
fn bad_input_gives_a_clear_error_nonzero_exit_and_no_output() {
    let dir = temp_dir();
    let seed = std::fs::read_to_string(configs().join("seed.toml")).unwrap();
    let cases: Vec<(&str, String, Vec<&str>, &str)> = vec![
        (
            "negative mass",
            seed.replace("mass = 1.0", "mass = -1.0"),
            vec![],
            "cat.mass",
        ),
        (
            "unknown key",
            seed.replace("radius = 0.1", "radius = 0.1\nradus = 0.2"),
            vec![],
            "radus",
        ),
        (
            "malformed",
            seed.replace("[fall]", "[fall"),
            vec![],
            "TOML parse error",
        ),
        (
            "unknown joint",
            seed.replace("\"no-twist\"", "\"hinge\""),
            vec![],
            "hinge",
        ),
        (
            "bad split",
            seed.clone(),
            vec!["--set", "analytic.split=[0.2, 0.2, 0.2]"],
            "`analytic.split` = [0.2, 0.2, 0.2] is invalid: fractions that sum to 1 (these sum to 0.6)",
        ),
        (
            "bad override",
            seed.clone(),
            vec!["--set", "fall.height"],
            "KEY=VALUE",
        ),
    ];
    for (what, body, extra, needle) in cases {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, body).unwrap();
        let mut args = vec!["analyze", path.to_str().unwrap()];
        args.extend(extra);
        let o = output(&args, dir.path());
        let (_, err) = text(&o);
        assert!(!o.status.success(), "{what} should fail");
        assert!(
            err.contains(needle),
            "{what}: `{err}` should name `{needle}`"
        );
        assert!(
            !dir.path().join("output").exists(),
            "{what} left output behind"
        );
    }
    let o = output(&["analyze", "no-such.toml"], dir.path());
    assert!(!o.status.success() && text(&o).1.contains("no-such.toml"));
    // a seed for the phased design, which has none, is refused, not ignored
    let seed_cfg = configs().join("seed.toml");
    let o = output(
        &["optimize", seed_cfg.to_str().unwrap(), "--seed", "analytic"],
        dir.path(),
    );
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--mode free"), "{err}");
    assert!(!dir.path().join("output").exists());
    // a broken schedule names the file, the line and the column
    let cfg = configs().join("seed.toml");
    let sched = dir.path().join("s.csv");
    std::fs::write(
        &sched,
        "t_s,phase,q1_rad,q2_rad,qd1_rad_s,qd2_rad_s,tau1_nm,tau2_nm\n0,fold,0,0,0,0,x,0\n",
    )
    .unwrap();
    let o = output(
        &[
            "simulate",
            cfg.to_str().unwrap(),
            "--schedule",
            sched.to_str().unwrap(),
        ],
        dir.path(),
    );
    let (_, err) = text(&o);
    assert!(
        !o.status.success() && err.contains("line 2") && err.contains("tau1_nm"),
        "{err}"
    );
}

/// Keys the optimiser JSON must carry (issue: phased optimiser).
const OPTIMIZE_KEYS: [&str; 11] = [
    "mode",
    "status",
    "peak_torque_nm",
    "bend_deg",
    "theta_deg",
    "twist_rad",
    "phase_durations_s",
    "flip_deg",
    "tilt_deg",
    "sim_peak_torque_nm",
    "solve_time_s",
];

fn assert_keys(v: &serde_json::Value, keys: &[&str]) {
    for key in keys {
        assert!(v.get(key).is_some(), "missing {key}");
    }
}

/// Runs the binary with `--json`, asserts success and parses stdout.
fn run_json(args: &[&str], dir: &Path) -> serde_json::Value {
    let mut all = args.to_vec();
    all.push("--json");
    let o = output(&all, dir);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    serde_json::from_str(&out).unwrap()
}

/// Under motor limits `optimize`'s JSON gives the written rows' largest
/// speed and smallest envelope margin, as `run`'s summary gives them for
/// the same design (docs/configuration.md: every method reports them).
#[test]
fn optimize_reports_the_motor_use_as_run_does() {
    let dir = temp_dir();
    let cfg = configs().join("robot-universal.toml");
    let cfg = cfg.to_str().unwrap();
    let high = "fall.height=6";
    let v = run_json(
        &["optimize", cfg, "--mode", "phased", "--set", high],
        dir.path(),
    );
    let s = run_json(&["run", cfg, "--set", high], dir.path());
    let line = util::method_line(&s, "phased");
    for key in ["max_speed_rad_s", "min_envelope_margin"] {
        let (a, b) = (v[key].as_f64(), line[key].as_f64());
        assert!(a.is_some() && a == b, "{key}: optimize {a:?}, run {b:?}");
    }
}

#[test]
fn optimize_phased_writes_schedule_and_summary_with_the_documented_keys() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let v = run_json(
        &["optimize", cfg.to_str().unwrap(), "--mode", "phased"],
        dir.path(),
    );
    assert_keys(&v, &OPTIMIZE_KEYS);
    assert_eq!(v["mode"], "phased");
    assert_eq!(v["status"], "solved");
    let on_disk: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("output/seed/optimize-phased/phased.json"))
            .unwrap(),
    )
    .unwrap();
    assert_eq!(on_disk["peak_torque_nm"], v["peak_torque_nm"]);
    let csv =
        std::fs::read_to_string(dir.path().join("output/seed/optimize-phased/phased.csv")).unwrap();
    let last: Vec<&str> = csv.lines().last().unwrap().split(',').collect();
    let total: f64 = v["phase_durations_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .sum();
    assert!(
        (last[0].parse::<f64>().unwrap() - total).abs() < 1e-6,
        "schedule ends at the manoeuvre time"
    );
}

#[test]
fn impossible_limits_fail_with_a_clear_reason_and_write_nothing() {
    let dir = temp_dir();
    let optimize = |config: &str, extra: &[&str]| {
        let cfg = configs().join(config);
        let mut args = vec!["optimize", cfg.to_str().unwrap()];
        args.extend(extra);
        let o = output(&args, dir.path());
        assert!(!dir.path().join("output").exists());
        (o.status.code(), text(&o).1)
    };
    let (code, err) = optimize("seed.toml", &["--set", "limits.max_torque=0.1"]);
    assert_ne!(code, Some(0));
    assert!(
        err.contains("not possible") && err.contains("fall.height") && err.contains("at least"),
        "{err}"
    );
    // from 4 m the robot's phased family needs 5.66 m, while `run` flips it
    // from about 3.5 m with a free-form design: the named phased seed's height
    // is no answer for the free-form design (without `--seed` the design
    // starts from the analytic one instead, as a test below checks)
    let (code, err) = optimize(
        "robot-universal.toml",
        &[
            "--mode",
            "free",
            "--seed",
            "phased",
            "--set",
            "fall.height=4",
        ],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(!err.contains("not possible"), "{err}");
    assert!(
        err.contains("phased seed") && err.contains("--seed analytic"),
        "{err}"
    );
}

/// `optimize CONFIG --mode free --seed analytic`, then `extra`.
fn free_from_analytic<'a>(cfg: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["optimize", cfg, "--mode", "free", "--seed", "analytic"];
    args.extend_from_slice(extra);
    args
}

#[test]
fn optimize_free_reports_iterations_and_nodes() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let v = run_json(&free_from_analytic(cfg.to_str().unwrap(), &[]), dir.path());
    assert_keys(&v, &OPTIMIZE_KEYS);
    assert_keys(&v, &["scp_iterations", "nodes"]);
    assert_eq!(v["mode"], "free");
    assert_eq!(v["seed"], "analytic");
    assert_eq!(
        v["iterations"].as_array().unwrap().len() as u64,
        v["scp_iterations"].as_u64().unwrap()
    );
    // the analytic seed's design has its own set: it does not replace the
    // default seed's
    assert!(
        dir.path()
            .join("output/seed/optimize-free-analytic/free.csv")
            .exists()
    );
    assert!(!dir.path().join("output/seed/optimize-free").exists());
    // so has the phased seed's named: without --seed the design may start
    // elsewhere (the least time from the least-height answer)
    let mut phased = free_from_analytic(cfg.to_str().unwrap(), &[]);
    *phased.last_mut().unwrap() = "phased";
    let v = run_json(&phased, dir.path());
    assert_eq!(v["seed"], "phased");
    assert!(
        dir.path()
            .join("output/seed/optimize-free-phased/free.csv")
            .exists()
    );
    assert!(!dir.path().join("output/seed/optimize-free").exists());
}

#[test]
fn a_closed_stdout_pipe_ends_quietly_and_pd_off_is_labelled() {
    // `catflip simulate ... | head`: the reader is gone before catflip prints
    let dir = temp_dir();
    let mut child = bin()
        .args(["simulate"])
        .arg(configs().join("seed.toml"))
        .args(["--set", "simulate.pd=false", "--out"])
        .arg(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{:?}: {err}", o.status);
    assert!(!err.contains("panicked"), "{err}");
    // with the pipe open, the table says what was simulated
    let o = output(
        &[
            "simulate",
            configs().join("seed.toml").to_str().unwrap(),
            "--set",
            "simulate.pd=false",
        ],
        dir.path(),
    );
    let (out, _) = text(&o);
    assert!(
        out.lines().next().unwrap().contains("feed-forward only"),
        "{out}"
    );
}

#[test]
fn verbose_free_form_names_the_objective_column_and_prints_every_iteration() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let args = [
        "--verbose",
        "--set",
        "design.objective=energy",
        "--set",
        "free.nodes=10",
    ];
    let o = output(
        &free_from_analytic(cfg.to_str().unwrap(), &args),
        dir.path(),
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let header = err.lines().find(|l| l.contains("iter")).expect("header");
    let columns: Vec<&str> = header.split_whitespace().collect();
    assert_eq!(columns[..3], ["iter", "merit", "energy"], "{header}");
    // one line per iteration, numbered 0, 1, 2, ... as the summary counts them
    let numbers: Vec<usize> = err
        .lines()
        .filter_map(|l| l.split_whitespace().next()?.parse().ok())
        .collect();
    assert!(!numbers.is_empty());
    assert!(
        numbers.iter().enumerate().all(|(i, &n)| i == n),
        "{numbers:?}"
    );
    let count = format!("({} SCP iterations", numbers.len());
    assert!(out.contains(&count), "{count} in\n{out}");
}

/// `optimize --mode free` without `--seed` where no phased schedule fits
/// the motors in this fall (the robot from 4.5 m, whose least height is
/// about 3.5 m): it starts, as `run` does, from the least-height answer's
/// shortest manoeuvre, says so, and the design flips inside the envelope
/// (exit 0); its JSON names the seed.
#[test]
fn optimize_free_without_a_seed_starts_from_the_least_height_design_where_no_phased_fits() {
    let dir = temp_dir();
    let robot = util::config_arg("robot-universal");
    let (code, out, err) = util::run(
        &[
            "optimize",
            &robot,
            "--mode",
            "free",
            "--set",
            "fall.height=4.5",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{err}");
    // the notes say what it does while it seeks the least height, and name it
    assert!(
        err.contains("finding the least drop height first")
            && err.contains("the least drop height found is 3.4")
            && err.contains("starts from the shortest free-form manoeuvre found"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["seed"], "free least-time", "{v}");
    assert_eq!(v["verdict"], "ok", "{v}");
    // `run` starts its free-form design there too: the same design (the
    // run is partial, exit 3: the phased design it was asked for is not
    // possible in this fall)
    let (code, out, err) = util::run(
        &["run", &robot, "--set", "fall.height=4.5", "--json"],
        dir.path(),
    );
    assert_eq!(code, Some(3), "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["free_seed"], "free least-time", "{r}");
    let free = util::method_line(&r, "free");
    let phased = util::method_line(&r, "phased");
    assert_eq!(phased["verdict"], "impossible", "{phased}");
    let (a, b) = (
        v["peak_torque_nm"].as_f64().unwrap(),
        free["peak_torque_nm"].as_f64().unwrap(),
    );
    assert!((a - b).abs() <= 1e-9 * a, "optimize {a} N m, run {b} N m");
}

/// A sound design's peak above the stall torque (the robot's least time
/// brakes with up to `T + k |w|`) is explained on its table's peak row, as
/// `run`'s braking note explains it; a design within its stall torque, or
/// without one, gets no such words.
#[test]
fn optimize_says_why_a_sound_peak_is_above_the_stall_torque() {
    let dir = temp_dir();
    let robot = util::config_arg("robot-universal");
    let time = [
        "optimize",
        &robot,
        "--mode",
        "free",
        "--seed",
        "analytic",
        "--set",
        "design.objective=time",
        "--set",
        "fall.height=6",
    ];
    let (code, out, err) = util::run(&time, dir.path());
    assert_eq!(code, Some(0), "{err}");
    let row = out
        .lines()
        .find(|l| l.trim_start().starts_with("peak torque"))
        .unwrap();
    let peak: f64 = row.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(peak > 1.4, "{row}");
    assert!(
        row.contains("above the 1.4 N m stall torque while braking"),
        "{row}"
    );
    let seed = util::config_arg("seed");
    for args in [
        &[
            "optimize",
            &robot,
            "--mode",
            "phased",
            "--set",
            "fall.height=6",
        ][..],
        &["optimize", &seed, "--mode", "free"][..],
    ] {
        let (code, out, err) = util::run(args, dir.path());
        assert_eq!(code, Some(0), "{err}");
        assert!(!out.contains("while braking"), "{args:?}: {out}");
    }
}

/// A `time` design answers "from what height": its JSON and table give the
/// least drop height, F7's `g (T + margin)^2 / 2` of its own manoeuvre, and
/// the table says what the configured fall leaves.
#[test]
fn a_time_design_gives_its_least_drop_height() {
    let dir = temp_dir();
    let robot = util::config_arg("robot-universal");
    let args = [
        "optimize",
        &robot,
        "--mode",
        "phased",
        "--set",
        "design.objective=time",
        "--set",
        "fall.height=6",
    ];
    let (code, out, err) = util::run(&[&args[..], &["--json"]].concat(), dir.path());
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cfg = util::config("robot-universal", &[]);
    let t = v["manoeuvre_time_s"].as_f64().unwrap();
    let h = 0.5 * cfg.fall.gravity * (t + cfg.fall.margin).powi(2);
    assert!(
        (v["least_height_m"].as_f64().unwrap() - h).abs() < 1e-12 * h,
        "{} against {h}",
        v["least_height_m"]
    );
    let (code, out, err) = util::run(&args, dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert!(
        out.contains(&format!("least drop height                  {h:.3} m"))
            && out.contains("the fall from 6 m leaves"),
        "{out}"
    );
    // another objective has none
    let (_, out, _) = util::run(
        &[
            "optimize",
            &robot,
            "--mode",
            "phased",
            "--set",
            "fall.height=6",
            "--json",
        ],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v.get("least_height_m").is_none(), "{v}");
}

/// `optimize` under a torque limit below the phased optimum: the motors
/// cannot do it from this height. That is the answer, as `run`'s (exit 4),
/// not a failure: the message names the drop height that would do (F7: the
/// least height grows as the limit falls), and nothing is written.
#[test]
fn optimize_beyond_the_motors_exits_4_naming_the_height() {
    let dir = temp_dir();
    let seed = util::config_arg("seed");
    let least = |torque: f64| {
        let (code, out, err) = util::run(
            &[
                "optimize",
                &seed,
                "--mode",
                "phased",
                "--set",
                &format!("limits.max_torque={torque}"),
            ],
            dir.path(),
        );
        assert_eq!(code, Some(4), "{out}{err}");
        assert!(
            err.contains("not possible with these motors in this fall"),
            "{err}"
        );
        util::number_after(&err, "drop the cat from at least ")
    };
    let (h3, h2) = (least(0.3), least(0.2));
    let fall = util::seed(&[]).fall.height;
    assert!(
        fall < h3 && h3 < h2,
        "{fall} m, at 0.3 N m {h3} m, at 0.2 N m {h2} m"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );
}

/// The robot from its configured 2 m: the motors cannot do it. That is the
/// answer (exit 4), not a failure: the phased and free-form designs are not
/// attempted (not `failed`), and the least-height schedule is a method like
/// the others, judged, written with its simulator controls, replayable, and
/// the report leads with the answer.
#[test]
fn the_robot_from_2_m_exits_4_with_the_least_height_schedule_as_a_method() {
    use util::{controls_header, method_line, run_summary};
    let dir = temp_dir();
    let (code, s, base, err) = run_summary("robot-universal", &[], dir.path());
    assert_eq!(code, Some(4), "{err}");
    assert_eq!(s["outcome"], "impossible");
    let a = &s["answer"];
    let least = a["least_height_m"].as_f64().unwrap();
    assert!(a["possible"] == false && least > 2.0, "{a}");
    for m in ["phased", "free"] {
        let l = method_line(&s, m);
        assert_eq!(l["verdict"], "impossible", "{l}");
        assert_eq!(l["status"], "not-attempted", "{l}");
        assert!(l["peak_torque_nm"].is_null(), "{l}");
        assert!(l["reason"].as_str().unwrap().contains("fall.height"), "{l}");
    }
    // no free-form design, so no count of its iterations
    assert!(s.get("scp_iterations").is_none(), "{s}");
    // the reference: flagged beyond the motors
    let an = method_line(&s, "analytic");
    assert!(
        an["verdict"] == "flagged" && an["beyond_the_motors"] == true,
        "{an}"
    );
    // the least-height method: inside the envelope, flipping, as long as the answer says
    let lh = method_line(&s, "least-height");
    assert_eq!(lh["verdict"], "ok", "{lh}");
    assert!(lh["min_envelope_margin"].as_f64().unwrap() >= -1e-6, "{lh}");
    let duration: f64 = lh["phase_durations_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_f64().unwrap())
        .sum();
    let t = a["least_time_s"].as_f64().unwrap();
    assert!((duration - t).abs() < 1e-9 * t, "{duration} vs {t}");
    // its controls tile the same manoeuvre at the simulators' steps
    for sim in ["mujoco", "pybullet"] {
        let csv = std::fs::read_to_string(base.join(format!("least-height.{sim}.csv"))).unwrap();
        assert!(csv.contains("method least-height"), "{sim}");
        let dt: f64 = controls_header(&csv, "dt_s").unwrap().parse().unwrap();
        let steps: f64 = controls_header(&csv, "steps").unwrap().parse().unwrap();
        assert!(
            (dt * steps - t).abs() < 1e-9 * t,
            "{sim}: {dt} x {steps} vs {t}"
        );
    }
    // the written schedule replays from the height it needs, as the run simulated it
    let (code, out, err) = util::run(
        &[
            "simulate",
            util::config_path("robot-universal").to_str().unwrap(),
            "--schedule",
            base.join("least-height.csv").to_str().unwrap(),
            "--set",
            &format!("fall.height={least}"),
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{err}");
    let sim: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (f, g) = (
        sim["flip_deg"].as_f64().unwrap(),
        lh["flip_deg"].as_f64().unwrap(),
    );
    assert!((f - g).abs() < 1e-6, "simulate {f} vs run {g} deg");
    // the report leads with the answer, above the table, and nothing is FAILED
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    let lead = html
        .find("<section id=\"answer\" class=\"impossible\">")
        .expect("the answer");
    assert!(lead < html.find("<table>").unwrap());
    assert!(html.contains("Not possible from 2 m with these motors."));
    assert!(html.contains(&format!("{least:.3} m")));
    // the least-height design brakes above the stall torque: the page says
    // why that is sound, as the terminal does
    assert!(html.contains("least-height: peak above the 1.4 N m stall torque while braking"));
    // its animated track says from what drop it is (not the 2 m asked)
    assert!(html.contains(&format!("for a drop from {least:.3} m; ")));
    // the bound far below the answer says what it is, not a contradiction
    assert!(html.contains(
        "is the least height found for a motor that never gives more than its stall torque"
    ));
    assert!(html.contains("an estimate, not a proof"));
    // the sizing advice names this config, as the terminal does

    assert!(!html.contains("<td>FAILED: "), "nothing errored");
    assert!(html.contains("<td>least-height</td>"));
    // the answer links the schedule's files, which are beside the page
    for f in [
        "least-height.csv",
        "least-height.mujoco.csv",
        "least-height.pybullet.csv",
    ] {
        assert!(html.contains(&format!("<a href=\"{f}\">{f}</a>")), "{f}");
        assert!(base.join(f).is_file(), "{f}");
    }
    // and points to the command that answers the next question, the one to
    // type, on this config and its --set (on the terminal and the page)
    let sizing = |command: &str| {
        format!("The motors (or the gear ratio) that would do it from 2 m: {command} --height 2.")
    };
    let config = util::config_path("robot-universal");
    let config = config.to_str().unwrap();
    assert!(
        html.contains(&sizing(&format!("catflip size {config}"))),
        "{html}"
    );
    // (without the --sets `size` refuses: it sets the drop and the objective
    // itself)
    let (_, out, _) = util::run(
        &[
            "run",
            config,
            "--set",
            "fall.height=2",
            "--set",
            "cat.mass=0.46",
            "--set",
            "design.objective=time",
        ],
        dir.path(),
    );
    let command = format!("catflip size {config} --set cat.mass=0.46");
    assert!(out.contains(&sizing(&command)), "{out}");
    // which `size` takes as printed (given an impossible --height: refused
    // for the height alone, after its --sets were accepted)
    let printed = out
        .split("from 2 m: catflip ")
        .nth(1)
        .and_then(|l| l.split(" --height 2.").next())
        .unwrap();
    let mut args: Vec<&str> = printed.split(' ').collect();
    args.extend(["--height", "0"]);
    let (code, _, err) = util::run(&args, dir.path());
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--height") && !err.contains("conflicts"),
        "{err}"
    );
    let svg = std::fs::read_to_string(base.join("torque.svg")).unwrap();
    assert!(svg.contains("least-height"), "the torque figure draws it");
    // its curves reach the table's (dense) peak: one motor's largest torque
    // in the torque-speed figure is the per-motor peak (evenly spaced
    // samples straddled a spike, 1.596 against 1.685 N m)
    let peak = lh["peak_torque_nm"].as_f64().unwrap();
    let speed = std::fs::read_to_string(base.join("torque_speed.svg")).unwrap();
    assert!(
        speed.contains(&format!("least-height ({peak:.3} N m")),
        "{peak:.3} N m: {}",
        speed.matches("least-height (").count()
    );
}

/// The seed under the universal joint: its analytic schedule misses the
/// flip and tilts (F4) and is flagged, but as the seed's closed form, not a
/// design, it does not make the run partial; under the pin joint the same
/// schedule flips (F1) and carries no such note.
#[test]
fn under_the_universal_joint_the_analytic_reference_is_flagged_not_counted() {
    use util::{method_line, run_summary};
    let dir = temp_dir();
    let (code, s, base, err) = run_summary("seed", &["cat.joint=universal"], dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(s["outcome"], "ok");
    let an = method_line(&s, "analytic");
    assert_eq!(an["verdict"], "flagged", "{an}");
    assert!(an["flip_error_rad"].as_f64().unwrap() > 1e-2, "{an}");
    assert_eq!(an["approximate_for_the_joint"], true, "{an}");
    assert!(an.get("beyond_the_motors").is_none(), "{an}");
    for m in ["phased", "free"] {
        let l = method_line(&s, m);
        assert_eq!(l["verdict"], "ok", "{l}");
        assert!(l.get("approximate_for_the_joint").is_none(), "{l}");
    }
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    assert!(html.contains("approximate for the universal joint (F4), not counted"));
    // without motor limits there is no answer block: the page still says
    // from what height the cat was dropped
    assert!(
        html.contains("dropped from 10 m (fall.height)"),
        "the drop height"
    );
    let (code, s, _, err) = run_summary("seed", &[], dir.path());
    assert_eq!(code, Some(0), "{err}");
    let an = method_line(&s, "analytic");
    assert_eq!(an["verdict"], "ok", "{an}");
    assert!(an.get("approximate_for_the_joint").is_none(), "{an}");
    // a no-twist cat of unequal halves: the closed forms (F1, F6) are exact
    // only for identical ones, so the same holds (it exited 3 before)
    let (code, s, base, err) = run_summary("seed", &["cat.front.mass=2"], dir.path());
    assert_eq!(code, Some(0), "{err}");
    let an = method_line(&s, "analytic");
    assert_eq!(an["verdict"], "flagged", "{an}");
    assert!(an["flip_error_rad"].as_f64().unwrap() > 1e-2, "{an}");
    assert_eq!(an["approximate_for_the_joint"], true, "{an}");
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    assert!(html.contains("exact only for identical halves (F1, F6), not counted"));
}

/// The robot from 6 m: possible, its designs sound; the seed's analytic
/// schedule breaks the motors and is reported, but the run is not partial.
#[test]
fn the_robot_from_6_m_exits_0_its_analytic_reference_flagged() {
    use util::{method_line, run_summary};
    let dir = temp_dir();
    let (code, s, base, err) = run_summary("robot-universal", &["fall.height=6"], dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(s["outcome"], "ok");
    assert!(!err.contains("partial"), "{err}");
    let an = method_line(&s, "analytic");
    assert_eq!(an["verdict"], "flagged", "{an}");
    assert_eq!(an["beyond_the_motors"], true, "{an}");
    for m in ["phased", "free", "least-height"] {
        let l = method_line(&s, m);
        assert_eq!(l["verdict"], "ok", "{l}");
        assert!(l.get("beyond_the_motors").is_none(), "{l}");
    }
    assert_eq!(s["answer"]["possible"], true);
    // the free-form design's iterations, every mesh's
    let levels: u64 = s["mesh_levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["scp_iterations"].as_u64().unwrap())
        .sum();
    assert!(
        s["scp_iterations"]
            .as_u64()
            .is_some_and(|n| n > 0 && n >= levels),
        "{s}"
    );
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    let lead = html
        .find("<section id=\"answer\" class=\"possible\">")
        .expect("the answer");
    assert!(lead < html.find("<table>").unwrap());
    assert!(html.contains("Possible from 6 m with these motors."));
    // both reasons the universal joint's analytic row is a reference (it
    // named the first alone)
    assert_eq!(an["approximate_for_the_joint"], true, "{an}");
    assert!(html.contains(
        "a reference beyond the motors, and the seed's closed form, approximate for the universal joint (F4): not counted"
    ));
    // the phased design fits this fall: it seeds the free-form one, as the
    // summary and the page say
    assert_eq!(s["free_seed"], "phased");
    assert!(html.contains("Free-form design: from the phased design, "));
    // what to fly from 6 m, and that least-height.csv is not it: in the
    // answer's block, above the table (it came after it), the files linked
    let free = method_line(&s, "free")["peak_torque_nm"].as_f64().unwrap();
    let link = |f: &str| format!("<a href=\"{f}\">{f}</a>");
    let fly = format!(
        "To fly from 6 m: {} ({} and {} for the simulators), the free-form design for design.objective = peak-torque (peak {free:.4} N m); {} is made for its own",
        link("free.csv"),
        link("free.mujoco.csv"),
        link("free.pybullet.csv"),
        link("least-height.csv")
    );
    let at = html.find(&fly).unwrap_or_else(|| panic!("{html}"));
    assert!(lead < at && at < html.find("<table>").unwrap());
    assert_eq!(html.matches("To fly from").count(), 1);
    // the least-height schedule (1.7 N m for its 3.5 m drop) has its own
    // torque axes, apart from the 6 m designs' (under 0.1 N m)
    let torque = std::fs::read_to_string(base.join("torque.svg")).unwrap();
    for panel in [
        "analytic schedule",
        "optimised schedules",
        "the least-height schedule (for its own drop height)",
    ] {
        assert_eq!(torque.matches(panel).count(), 1, "{panel}");
    }
}
