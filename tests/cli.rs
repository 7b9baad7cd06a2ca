//! The real binary on a temporary directory.

mod util;

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
            "analytic.split",
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
        err.contains("impossible") && err.contains("fall.height") && err.contains("at least"),
        "{err}"
    );
    // from 4 m the robot's phased family needs 5.66 m, while `run` flips it
    // from about 3.5 m with a free-form design: the phased seed's height is
    // no answer for the free-form design
    let (code, err) = optimize(
        "robot-universal.toml",
        &["--mode", "free", "--set", "fall.height=4"],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(!err.contains("flip is impossible"), "{err}");
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
    assert!(
        dir.path()
            .join("output/seed/optimize-free/free.csv")
            .exists()
    );
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
