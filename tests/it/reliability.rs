//! Every failure named, nothing half-written, no result thrown away.
//! Each test runs the real binary on a temporary folder.

use crate::util;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;
use util::{bin, run, schedule_peak, seed_toml, temp_dir};

/// A tiny deterministic generator (xorshift64*), so runs are repeatable.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// Reads an `analyze` set as one folder: opened once, its files read
/// through that handle (the folder's own, wherever a later writer moves its
/// name; in the link scheme, the link's target). `None` when there is no set
/// yet, or the set was superseded and removed while reading. Panics when a
/// file of the set still published is missing (the live set incomplete, or
/// deleted), or the files come from different runs. Returns the set's
/// `theta_deg`.
fn read_analyze_set(link: &Path) -> Option<f64> {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::io::AsRawFd;
    let handle = std::fs::File::open(link).ok()?;
    let ino = handle.metadata().ok()?.ino();
    let dir = PathBuf::from(format!("/proc/self/fd/{}", handle.as_raw_fd()));
    let superseded = || std::fs::metadata(link).map(|m| m.ino()).ok() != Some(ino);
    let read = |name: &str| match std::fs::read_to_string(dir.join(name)) {
        Ok(t) => Some(t),
        Err(_) if superseded() => None,
        Err(e) => panic!("{} (the published set) lost {name}: {e}", link.display()),
    };
    let json = read("analyze.json")?;
    let csv = read("analytic.csv")?;
    let sched = read("analytic.schedule.json")?;
    let v: serde_json::Value = serde_json::from_str(&json).expect("analyze.json parses");
    let s: serde_json::Value = serde_json::from_str(&sched).expect("schedule JSON parses");
    let (peak, rows) = schedule_peak(&csv, false);
    let jp = v["peak_torque_nm"].as_f64().unwrap();
    // the three files describe one schedule: same rows, same peak (the JSON samples more densely)
    assert_eq!(
        s["rows"].as_array().unwrap().len(),
        rows,
        "{}",
        dir.display()
    );
    assert!(
        peak <= jp * (1.0 + 1e-9) && peak > 0.99 * jp,
        "{}: CSV peak {peak} vs analyze.json {jp}: files of different runs",
        dir.display()
    );
    Some(v["theta_deg"].as_f64().unwrap())
}

/// Entries of `<out>/seed` other than hidden ones and published sets
/// (folders with catflip's marker, or links of the fallback scheme).
fn visible_non_sets(base: &Path) -> Vec<String> {
    let Ok(rd) = std::fs::read_dir(base) else {
        return vec![];
    };
    rd.filter_map(|e| {
        let e = e.ok()?;
        let name = e.file_name().into_string().ok()?;
        let set =
            e.file_type().ok()?.is_symlink() || e.path().join(catflip::output::MARKER).is_file();
        (!name.starts_with('.') && !set).then_some(name)
    })
    .collect()
}

/// The hidden folders a published set keeps: its link's target in the
/// fallback scheme, none for a folder published by exchange.
fn live_hidden(link: &Path) -> Vec<String> {
    std::fs::read_link(link)
        .map(|t| vec![t.to_string_lossy().into_owned()])
        .unwrap_or_default()
}

/// `analyze` of the seed at another angle between the halves, from a config
/// file of its own (the same name, so every angle publishes the same set;
/// with `--set` each would have its own).
fn analyze_cmd(dir: &Path, theta: f64) -> Command {
    let text = std::fs::read_to_string(seed_toml())
        .unwrap()
        .replace("theta_deg = 45.0", &format!("theta_deg = {theta:?}"));
    let cfg = dir.join(format!("seed-theta-{theta}.toml"));
    std::fs::write(&cfg, text).unwrap();
    let mut c = bin();
    c.args(["analyze", cfg.to_str().unwrap()])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// The set a command writes with these arguments' `--set` overrides.
fn set_of(base: &str, args: &[&str]) -> String {
    let sets: Vec<String> = args
        .windows(2)
        .filter(|w| w[0] == "--set")
        .map(|w| w[1].to_string())
        .collect();
    catflip::output::set_name(base, &sets)
}

#[test]
fn sigkill_at_random_moments_never_leaves_a_partial_set() {
    let dir = temp_dir();
    let base = dir.path().join("output/seed");
    let link = base.join("analyze");
    let mut rng = Rng(0x5eed_1234);
    let mut last_complete = None;
    for i in 0..16 {
        let theta = if i % 2 == 0 { 45.0 } else { 60.0 };
        let mut child = analyze_cmd(dir.path(), theta).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(rng.below(60)));
        let _ = child.kill(); // SIGKILL
        let status = child.wait().unwrap();
        // the published set, if any, is complete and from one run
        let got = read_analyze_set(&link);
        if status.success() {
            assert_eq!(got, Some(theta), "a finished run is published");
        }
        if got.is_some() {
            last_complete = got;
        }
        assert!(
            visible_non_sets(&base).is_empty(),
            "only published sets and hidden staging folders: {:?}",
            visible_non_sets(&base)
        );
    }
    // a finished run publishes and removes every leftover of the killed ones
    let (code, _, err) = run(&["analyze", seed_toml().to_str().unwrap()], dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(read_analyze_set(&link), Some(45.0));
    let hidden: Vec<String> = std::fs::read_dir(&base)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert_eq!(
        hidden,
        live_hidden(&link),
        "leftovers remain (last complete set before: {last_complete:?})"
    );
}

#[test]
fn concurrent_writers_publish_whole_sets_while_a_reader_watches() {
    let dir = temp_dir();
    let base = dir.path().join("output/seed");
    let link = base.join("analyze");
    let thetas = [40.0, 50.0, 60.0];
    let mut seen = 0;
    for _round in 0..4 {
        let mut children: Vec<_> = thetas
            .iter()
            .map(|&t| analyze_cmd(dir.path(), t).spawn().unwrap())
            .collect();
        loop {
            if let Some(t) = read_analyze_set(&link) {
                assert!(thetas.contains(&t));
                seen += 1;
            }
            if children.iter_mut().all(|c| c.try_wait().unwrap().is_some()) {
                break;
            }
        }
        for c in &mut children {
            assert!(c.wait().unwrap().success());
        }
        let t = read_analyze_set(&link).expect("a set is published");
        assert!(thetas.contains(&t));
    }
    // after the first round a set is always published: the reader read some
    assert!(seen > 0, "the reader never saw a whole set");
    // superseded sets are removed by the writers: at most the link's target
    let hidden: Vec<String> = std::fs::read_dir(&base)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert_eq!(hidden, live_hidden(&link), "{hidden:?}");
}

#[test]
fn commands_write_separate_sets_so_a_run_report_keeps_describing_its_files() {
    let dir = temp_dir();
    let c = seed_toml();
    let c = c.to_str().unwrap();
    let (code, _, err) = run(&["run", c, "--set", "free.nodes=12"], dir.path());
    assert_eq!(code, Some(0), "{err}");
    let run_dir = dir.path().join("output/seed/run@free.nodes=12");
    let before: Vec<(String, String)> = ["phased.csv", "analytic.csv", "free.csv", "summary.json"]
        .iter()
        .map(|f| {
            (
                f.to_string(),
                std::fs::read_to_string(run_dir.join(f)).unwrap(),
            )
        })
        .collect();
    // other designs of the same name land in their own sets
    for args in [
        vec!["optimize", c, "--set", "analytic.theta_deg=60"],
        vec!["analyze", c, "--set", "analytic.theta_deg=60"],
    ] {
        let (code, _, err) = run(&args, dir.path());
        assert_eq!(code, Some(0), "{err}");
    }
    for (f, text) in &before {
        assert_eq!(
            &std::fs::read_to_string(run_dir.join(f)).unwrap(),
            text,
            "{f} changed"
        );
    }
    assert!(
        dir.path()
            .join("output/seed/optimize-phased@analytic.theta_deg=60/phased.csv")
            .exists()
    );
    assert!(
        dir.path()
            .join("output/seed/analyze@analytic.theta_deg=60/analytic.csv")
            .exists()
    );
}

#[test]
fn unwritable_out_fails_before_computing_with_one_message() {
    let dir = temp_dir();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let (code, out, err) = run(
        &[
            "run",
            seed_toml().to_str().unwrap(),
            "--out",
            file.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(out.is_empty());
    assert!(!err.contains("[1/4]"), "a stage started: {err}");
    assert_eq!(err.matches("error:").count(), 1, "{err}");
    // the file given as --out is named, not the folder below it
    assert!(
        err.contains(&format!(
            "cannot write to {}: is a file, not a folder",
            file.display()
        )),
        "{err}"
    );
    assert!(err.contains("--out"), "{err}");
    // a read-only folder (not testable as root, who may write anywhere)
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    let mut perm = std::fs::metadata(&ro).unwrap().permissions();
    perm.set_readonly(true);
    std::fs::set_permissions(&ro, perm).unwrap();
    if std::fs::write(ro.join("probe"), "x").is_err() {
        let (code, _, err) = run(
            &[
                "run",
                seed_toml().to_str().unwrap(),
                "--out",
                ro.to_str().unwrap(),
            ],
            dir.path(),
        );
        assert_eq!(code, Some(2), "{err}");
        assert!(
            !err.contains("[1/4]") && err.matches("error:").count() == 1,
            "{err}"
        );
    }
}

#[test]
fn a_failed_method_keeps_the_others_reports_why_and_exits_partial() {
    // under a 0.5 N m limit from 12 m the phased optimum (0.565 N m) is
    // impossible, the analytic schedule saturates, the free-form design fits
    let seed = seed_toml();
    let args = [
        "run",
        seed.to_str().unwrap(),
        "--set",
        "limits.max_torque=0.5",
        "--set",
        "fall.height=12",
    ];
    let dir = temp_dir();
    let (code, out, err) = run(&[&args[..], &["--json"]].concat(), dir.path());
    assert_eq!(code, Some(3), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["outcome"], "partial");
    // the console's closing line names what makes it partial, and only that
    // (the analytic reference beyond the motors does not count)
    let console_run = temp_dir();
    let (code, _, err) = run(&args, console_run.path());
    assert_eq!(code, Some(3), "{err}");
    let closing = err.lines().last().unwrap_or_default();
    assert!(
        closing.contains("partial result: phased not possible in this fall")
            && !closing.contains("analytic"),
        "{closing}"
    );
    // the report's banner names the same, and no flagged schedule
    let page = std::fs::read_to_string(
        console_run
            .path()
            .join("output/seed/run@limits.max_torque=0.5,fall.height=12/index.html"),
    )
    .unwrap();
    let banner = page
        .split("PARTIAL RESULT: ")
        .nth(1)
        .and_then(|b| b.split('<').next())
        .unwrap_or_else(|| panic!("no banner in the report"));
    assert!(
        banner.starts_with("phased not possible in this fall;") && !banner.contains("flagged"),
        "{banner}"
    );
    let m = |name: &str| {
        v["methods"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == name)
            .unwrap()
            .clone()
    };
    let (a, p, f) = (m("analytic"), m("phased"), m("free"));
    // the phased family cannot do it in this fall: an answer (not attempted),
    // not an error, and still a design the run asked for that it lacks (exit 3)
    assert_eq!(p["verdict"], "impossible");
    assert_eq!(p["status"], "not-attempted");
    assert!(p["peak_torque_nm"].is_null());
    let reason = p["reason"].as_str().unwrap();
    assert!(
        reason.contains("fall.height") && reason.contains("at least"),
        "{reason}"
    );
    assert_eq!(a["verdict"], "flagged");
    assert!(a["reason"].as_str().unwrap().contains("limits.max_torque"));
    // the seed's schedule is a reference: beyond the motors, reported, not counted
    assert_eq!(a["beyond_the_motors"], true);
    assert_eq!(f["verdict"], "ok", "{f}");
    let base = dir
        .path()
        .join("output/seed/run@limits.max_torque=0.5,fall.height=12");
    // the kept design meets the limit on every written row
    let (peak, _) = schedule_peak(
        &std::fs::read_to_string(base.join("free.csv")).unwrap(),
        false,
    );
    assert!(peak <= 0.5 * (1.0 + 1e-6), "{peak}");
    assert!(!base.join("phased.csv").exists());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(base.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["methods"], v["methods"]);
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    assert!(
        html.contains("not possible: no phased schedule fits") && html.contains("<td>FLAGGED: ")
    );
    assert!(!html.contains("<td>FAILED: "), "nothing errored");
    // the answer comes from the free-form least-time design, which fits the
    // fall and keeps the limit on every written row
    let ans = &v["answer"];
    assert_eq!(ans["possible"], true, "{ans}");
    assert_eq!(ans["method"], "free", "{ans}");
    assert!(ans["least_height_m"].as_f64().unwrap() <= 12.0, "{ans}");
    let (lpeak, _) = schedule_peak(
        &std::fs::read_to_string(base.join("least-height.csv")).unwrap(),
        false,
    );
    assert!(lpeak <= 0.5 * (1.0 + 1e-6), "{lpeak}");
    // the time designs start from the analytic plan among others, all made
    // for the reference drop (the question's height is not a start): the
    // answer is no longer than the analytic seed's design alone from there
    let reference = catflip::design::least_height::reference(
        &catflip::Config::load(
            &seed_toml(),
            &["limits.max_torque=0.5".into(), "fall.height=12".into()],
        )
        .unwrap()
        .design_spec(),
    );
    let at_reference = format!("fall.height={}", reference.fall.height);
    let (code, out, err) = run(
        &[
            "optimize",
            seed_toml().to_str().unwrap(),
            "--mode",
            "free",
            "--seed",
            "analytic",
            "--set",
            "limits.max_torque=0.5",
            "--set",
            &at_reference,
            "--set",
            "design.objective=time",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{err}");
    let alone: serde_json::Value = serde_json::from_str(&out).unwrap();
    let alone = alone["manoeuvre_time_s"].as_f64().unwrap();
    let least = ans["least_time_s"].as_f64().unwrap();
    assert!(least <= alone * (1.0 + 1e-9), "{least} vs {alone}");
}

#[test]
fn an_unconverged_design_is_flagged_in_table_and_exit_status() {
    let dir = temp_dir();
    let (code, out, err) = run(
        &[
            "run",
            seed_toml().to_str().unwrap(),
            "--set",
            "free.max_iterations=2",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(3), "{err}");
    let free = out
        .lines()
        .find(|l| l.trim_start().starts_with("free"))
        .unwrap();
    assert!(
        free.contains("FLAGGED") && free.contains("iteration-limit"),
        "{out}"
    );
    assert!(err.contains("partial"), "{err}");
}

/// Writes the seed's analytic schedule (as `analyze` writes it) and returns its text.
fn analytic_csv(dir: &Path, extra: &[&str]) -> String {
    let c = seed_toml();
    let mut args = vec!["analyze", c.to_str().unwrap()];
    args.extend(extra);
    args.extend(["--out", "sched-src"]);
    let (code, _, err) = run(&args, dir);
    assert_eq!(code, Some(0), "{err}");
    let set = set_of("analyze", extra);
    std::fs::read_to_string(dir.join(format!("sched-src/seed/{set}/analytic.csv"))).unwrap()
}

/// Rewrites every data row of a schedule CSV with `f`.
fn map_rows(csv: &str, f: impl Fn(&mut Vec<f64>)) -> String {
    let mut lines = csv.lines();
    let mut s = format!("{}\n", lines.next().unwrap());
    for l in lines {
        let parts: Vec<&str> = l.split(',').collect();
        let mut x: Vec<f64> = parts
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != 1)
            .map(|(_, v)| v.parse().unwrap())
            .collect();
        f(&mut x);
        let mut cells: Vec<String> = x.iter().map(|v| format!("{v:e}")).collect();
        cells.insert(1, parts[1].to_string());
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

fn simulate(dir: &Path, schedule: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    let p = dir.join("schedule.csv");
    std::fs::write(&p, schedule).unwrap();
    let c = seed_toml();
    let mut args = vec![
        "simulate",
        c.to_str().unwrap(),
        "--schedule",
        p.to_str().unwrap(),
    ];
    args.extend(extra);
    run(&args, dir)
}

#[test]
fn huge_torques_fail_naming_the_divergence_and_write_nothing() {
    let dir = temp_dir();
    let csv = analytic_csv(dir.path(), &[]);
    // the unchanged schedule replays (control)
    let (code, _, err) = simulate(dir.path(), &csv, &["--json"]);
    assert_eq!(code, Some(0), "{err}");
    let big = map_rows(&csv, |x| {
        x[7] *= 1e6;
        x[8] *= 1e6;
    });
    let (code, out, err) = simulate(dir.path(), &big, &["--json"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(out.is_empty(), "no numbers on failure: {out}");
    assert!(
        err.contains("diverged") || err.contains("NaN"),
        "names the cause: {err}"
    );
    assert!(!err.to_lowercase().contains("nan deg"));
    // the control run's set stays; the failed run published nothing over it
    let sim = dir.path().join("output/seed/simulate/simulation.csv");
    let rows = std::fs::read_to_string(sim).unwrap();
    assert!(!rows.contains("NaN"));
    // export refuses it as simulate does (it wrote NaN gains and exited 0)
    let p = dir.path().join("schedule.csv");
    let c = seed_toml();
    let (code, out, err) = run(
        &[
            "export",
            "mjcf",
            c.to_str().unwrap(),
            "--schedule",
            p.to_str().unwrap(),
            "--out",
            "exported",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(err.contains("diverged") || err.contains("NaN"), "{err}");
    assert!(!dir.path().join("exported").exists(), "export wrote files");
}

/// A body the integrator cannot follow with next to no torque applied
/// (halves of 1e4 and 1e-6 kg) is named as the cause, not huge torques.
#[test]
fn a_stiff_body_is_blamed_not_the_torques() {
    let dir = temp_dir();
    let c = seed_toml();
    let (code, _, err) = run(
        &[
            "optimize",
            c.to_str().unwrap(),
            "--set",
            "cat.mass=1e4",
            "--set",
            "cat.front.mass=1e-6",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("with next to no torque applied") && err.contains("the body itself"),
        "{err}"
    );
    assert!(!err.contains("huge torques"), "{err}");
}

#[test]
fn a_million_row_resampling_is_refused_at_once_with_the_bound() {
    let dir = temp_dir();
    let csv = analytic_csv(dir.path(), &[]);
    // linear resampling of each phase to 333,334 rows: the same schedule, 1e6 rows
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let mut big = format!("{}\n", csv.lines().next().unwrap());
    for phase in ["fold", "twist", "unfold"] {
        let ph: Vec<Vec<f64>> = rows
            .iter()
            .filter(|r| r[1] == phase)
            .map(|r| {
                r.iter()
                    .enumerate()
                    .filter(|(i, _)| *i != 1)
                    .map(|(_, v)| v.parse().unwrap())
                    .collect()
            })
            .collect();
        let (t0, t1) = (ph[0][0], ph[ph.len() - 1][0]);
        let n = 333_334;
        let mut k = 0;
        for j in 0..n {
            let t = t0 + (t1 - t0) * j as f64 / (n - 1) as f64;
            while k + 2 < ph.len() && ph[k + 1][0] <= t {
                k += 1;
            }
            let w = ((t - ph[k][0]) / (ph[k + 1][0] - ph[k][0])).clamp(0.0, 1.0);
            let cells: Vec<String> = (1..9)
                .map(|c| format!("{:e}", ph[k][c] + w * (ph[k + 1][c] - ph[k][c])))
                .collect();
            big.push_str(&format!("{t:.9},{phase},{}\n", cells.join(",")));
        }
    }
    let (code, _, err) = simulate(dir.path(), &big, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("100000 rows") && err.contains("resample"),
        "{err}"
    );
}

#[test]
fn a_schedule_for_another_fall_is_refused_naming_both_durations() {
    let dir = temp_dir();
    // designed for a 1 m drop (0.452 s), replayed on the seed's 10 m drop (1.429 s)
    let short = analytic_csv(dir.path(), &["--set", "fall.height=1"]);
    let (code, _, err) = simulate(dir.path(), &short, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("0.45175") && err.contains("1.428571"), "{err}");
    // the seed's own schedule stretched twice in time fits a 40 m drop
    // (g t^2 / 2 at 9.8 m/s^2 and 2.857 s); 100 times, no fall catflip
    // designs (it named a 99,960 m drop, which the config refuses)
    let csv = analytic_csv(dir.path(), &[]);
    let slow = map_rows(&csv, |x| x[0] *= 2.0);
    let (code, _, err) = simulate(dir.path(), &slow, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("`--set fall.height=40.0000000"), "{err}");
    let slow = map_rows(&csv, |x| x[0] *= 100.0);
    let (code, _, err) = simulate(dir.path(), &slow, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("142.857") && err.contains("longer than any catflip designs (30 s)"),
        "{err}"
    );
    assert!(!err.contains("--set fall.height"), "{err}");
    assert!(!dir.path().join("output/seed/simulate").exists());
}

#[test]
fn analytic_split_needs_exactly_three_numbers() {
    let dir = temp_dir();
    let c = seed_toml();
    let c = c.to_str().unwrap();
    let (code, _, err) = run(
        &[
            "analyze",
            c,
            "--set",
            r#"analytic.split=[0.2,0.6,0.2,99,"x"]"#,
        ],
        dir.path(),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("analytic.split"), "{err}");
    let text = std::fs::read_to_string(seed_toml())
        .unwrap()
        .replace("split = [0.2, 0.6, 0.2]", "split = [0.2, 0.6, 0.2, -7.0]");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, text).unwrap();
    let (code, _, err) = run(&["analyze", bad.to_str().unwrap()], dir.path());
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("exactly 3") && err.contains("got 4"), "{err}");
    assert!(!dir.path().join("output").exists());
}

#[test]
fn config_errors_point_at_the_users_line_or_the_set_argument() {
    let dir = temp_dir();
    let text = std::fs::read_to_string(seed_toml()).unwrap();
    let line = |needle: &str, t: &str| t.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let cases = [
        (
            text.replace("radius = 0.1", "radius = 0.1\nradus = 0.2"),
            "radus",
        ),
        (text.replace("height = 10.0", "height = \"ten\""), "height"),
    ];
    for (body, key) in cases {
        let want = line(key, &body);
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, &body).unwrap();
        for extra in [
            vec![],
            vec!["--set", "cat.mass=2"],
            vec!["--set", "phased.nodes=30"],
        ] {
            let mut args = vec!["analyze", bad.to_str().unwrap()];
            args.extend(extra.iter().copied());
            let (code, _, err) = run(&args, dir.path());
            assert_eq!(code, Some(2), "{err}");
            assert!(
                err.contains(&format!("line {want},")) && err.contains(key),
                "{extra:?}: `{err}` should point at line {want} ({key})"
            );
        }
    }
    // an error in an override names the argument
    for arg in ["cat.masss=1", "cat.mass=heavy", "fall=3"] {
        let (code, _, err) = run(
            &["analyze", seed_toml().to_str().unwrap(), "--set", arg],
            dir.path(),
        );
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(&format!("`--set {arg}`")), "{err}");
        assert!(!err.contains("line"), "no unrelated line: {err}");
    }
}

#[test]
fn sweeps_bound_the_count_keep_good_points_and_check_threads() {
    let dir = temp_dir();
    let c = seed_toml();
    let c = c.to_str().unwrap();
    // a billion points is refused before any work
    let (code, _, err) = run(
        &[
            "sweep",
            c,
            "--set-range",
            "fall.height=1:2:1000000000",
            "--methods",
            "analytic",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--set-range") && err.contains("10000"),
        "{err}"
    );
    // no threads
    let (code, _, err) = run(
        &[
            "sweep",
            c,
            "--set-range",
            "cat.mass=1:2:2",
            "--threads",
            "0",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--threads"), "{err}");
    assert!(!dir.path().join("output").exists());
    // every command with --threads says the same, in words, before any work
    for cmd in ["sweep", "robustness", "recovery"] {
        let mut args = vec![cmd, c, "--threads", "0"];
        if cmd == "sweep" {
            args.extend(["--set-range", "cat.mass=1:2:2"]);
        }
        let (code, _, err) = run(&args, dir.path());
        assert_eq!(code, Some(2), "{cmd}: {err}");
        assert!(err.contains("at least one thread"), "{cmd}: {err}");
        assert!(!dir.path().join("output").exists(), "{cmd}");
    }
    // points outside the key's range are refused up front, naming the
    // first, before any work; a range inside is computed
    let (code, out, err) = run(
        &[
            "sweep",
            c,
            "--set-range",
            "cat.mass=-1:1:5",
            "--methods",
            "analytic",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.contains("--set-range cat.mass=-1:1:5")
            && err.contains("3 of 5 points")
            && err.contains("cat.mass = -1"),
        "{err}"
    );
    assert!(!err.contains("`--set "), "{err}");
    assert!(!dir.path().join("output").exists());
    let (code, out, err) = run(
        &[
            "sweep",
            c,
            "--set-range",
            "cat.mass=0.25:1.25:5",
            "--methods",
            "analytic",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(0), "{err}");
    let pts: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    assert_eq!(pts.len(), 5);
    // the analytic peak is linear in the mass (same path, inertia scales)
    let p = |i: usize| pts[i]["analytic_peak_nm"].as_f64().unwrap();
    assert!((p(3) - 2.0 * p(1)).abs() < 1e-9 * p(3), "{} {}", p(1), p(3));
    // every point invalid (an unknown key) is bad input
    let (code, _, err) = run(&["sweep", c, "--set-range", "cat.masss=1:2:3"], dir.path());
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--set-range cat.masss") && err.contains("masss"),
        "{err}"
    );
}

#[test]
fn a_sweep_keeps_every_method_and_flags_an_unconverged_one_per_point() {
    let dir = temp_dir();
    let (code, out, err) = run(
        &[
            "sweep",
            seed_toml().to_str().unwrap(),
            "--set-range",
            "fall.height=5:10:2",
            "--set",
            "free.max_iterations=2",
            "--methods",
            "phased,free",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(3), "{err}");
    let pts: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    for p in &pts {
        let e = p["error"].as_str().unwrap();
        assert!(
            e.contains("free FLAGGED") && e.contains("solver status iteration-limit"),
            "{e}"
        );
        assert!(!e.contains("phased"), "the phased design converged: {e}");
        assert!(p["free_peak_nm"].is_f64() && p["phased_peak_nm"].is_f64());
    }
    // F3: the same path in half the time squared: peak times 2 from 10 m to 5 m
    let ph = |i: usize| pts[i]["phased_peak_nm"].as_f64().unwrap();
    assert!((ph(0) / ph(1) - 2.0).abs() < 1e-4, "{} {}", ph(0), ph(1));
}
