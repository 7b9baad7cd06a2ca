//! Sweeps: continuation chunks, shards through the real binary, progress.

use crate::util;

use catflip::console::sweep::progress_line;
use catflip::sweep::{CHUNK, Shard};
use util::{bin, configs, run_written, temp_dir};

#[test]
fn shards_partition_the_grid_into_whole_contiguous_chunks() {
    for total in 0..50 {
        for count in 1..8 {
            let mut next = 0;
            for index in 1..=count {
                let r = Shard { index, count }.points(total);
                assert_eq!(r.start, next, "{total} points, {index}/{count}");
                assert!(r.start.is_multiple_of(CHUNK) || r.start == total);
                next = r.end;
            }
            assert_eq!(next, total, "{total} points in {count} shards");
        }
    }
    for bad in ["0/3", "4/3", "3", "a/b", "1/0"] {
        assert!(bad.parse::<Shard>().is_err(), "{bad}");
    }
    assert_eq!(
        "2/5".parse::<Shard>().unwrap(),
        Shard { index: 2, count: 5 }
    );
}

#[test]
fn progress_line_estimates_the_time_left_from_the_mean_time_per_point() {
    // 10 of 40 points in 20 s: 2 s a point, 30 points left
    let l = progress_line("fall.height", 10, 40, 20.0);
    assert!(l.contains("10/40") && l.contains("ETA 60 s"), "{l}");
    assert!(
        l.contains(&format!("[{}{}]", "#".repeat(6), ".".repeat(18))),
        "{l}"
    );
    assert!(progress_line("k", 0, 3, 0.0).contains("ETA -"));
}

/// The shards' CSVs, joined with one header, are byte for byte the
/// single-machine CSV (continuation included: 11 points are two chunks).
#[test]
fn sharded_sweep_concatenates_into_the_single_machine_result() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let c = cfg.to_str().unwrap();
    let common = [
        "sweep",
        c,
        "--set-range",
        "cat.radius=0.06:0.14:11",
        "--methods",
        "phased,free",
        "--set",
        "free.nodes=10",
        "--set",
        "phased.nodes=12",
    ];
    let mut args = common.to_vec();
    args.extend(["--threads", "2", "--out", "full"]);
    let (ok, _, err) = run_written(&args, dir.path());
    assert!(ok, "{err}");
    let full = std::fs::read_to_string(
        dir.path()
            .join("full/seed/sweep-cat_radius@free.nodes=10,phased.nodes=12/sweep-cat_radius.csv"),
    )
    .unwrap();
    assert_eq!(full.lines().count(), 12);
    // the sweep's page: a row a point, its value first, and the figure captioned
    let page = std::fs::read_to_string(
        dir.path()
            .join("full/seed/sweep-cat_radius@free.nodes=10,phased.nodes=12/index.html"),
    )
    .unwrap();
    assert_eq!(page.matches("<tr><td>").count(), 11, "{page}");
    for line in full.lines().skip(1) {
        let value = line.split(',').next().unwrap();
        assert!(
            page.contains(&format!("<tr><td>{value}</td>")),
            "{value}: {page}"
        );
    }
    assert!(page.contains("<img src=\"sweep-cat_radius.svg\"") && page.contains("<figcaption>"));
    let mut joined = String::new();
    for k in 1..=3 {
        let mut args = common.to_vec();
        let shard = format!("{k}/3");
        args.extend(["--threads", "1", "--shard", &shard, "--out", "shards"]);
        let (ok, _, err) = run_written(&args, dir.path());
        assert!(ok, "{err}");
        // 11 points are two chunks of 10: the first of three shards is empty, and says so
        assert_eq!(err.contains("holds no points"), k == 1, "{k}: {err}");
        // and so does its page, which a job array's log reader opens
        let page = std::fs::read_to_string(dir.path().join(format!(
            "shards/seed/sweep-cat_radius.shard-{k}-of-3@free.nodes=10,phased.nodes=12/index.html"
        )))
        .unwrap();
        assert_eq!(
            page.contains(&format!(
                "Shard {k}/3 holds no points of the grid cat.radius=0.06:0.14:11: shards take whole continuation chunks of 10 points, so use at most 2 shards. Nothing failed"
            )),
            k == 1,
            "{k}: {page}"
        );
        let part = std::fs::read_to_string(dir.path().join(format!(
            "shards/seed/sweep-cat_radius.shard-{k}-of-3@free.nodes=10,phased.nodes=12/sweep-cat_radius.shard-{k}-of-3.csv"
        )))
        .unwrap();
        let skip = if k == 1 { 0 } else { 1 };
        for line in part.lines().skip(skip) {
            joined.push_str(line);
            joined.push('\n');
        }
    }
    assert_eq!(joined, full);
    // every point converged or its failure recorded
    for line in full.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let (status, error) = (cells[cells.len() - 2], cells[cells.len() - 1]);
        assert!(!status.is_empty() || !error.is_empty(), "{line}");
    }
    let (ok, _, err) = run_written(&[&common[..], &["--shard", "4/3"]].concat(), dir.path());
    assert!(!ok && err.contains("--shard"), "{err}");
}

/// A phased sweep of `key` over `range` (12 nodes per phase) on the seed:
/// per point `(value, swept peak, swept bend, peak designed afresh at that
/// value)`.
fn phased_sweep_against_fresh_designs(key: &str, range: &str) -> Vec<(f64, f64, f64, f64)> {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let set_range = format!("{key}={range}");
    let args = [
        "sweep",
        cfg.to_str().unwrap(),
        "--set-range",
        &set_range,
        "--methods",
        "phased",
        "--set",
        "phased.nodes=12",
        "--out",
        "out",
    ];
    let (ok, _, err) = run_written(&args, dir.path());
    assert!(ok, "{err}");
    let name = format!("sweep-{}", key.replace('.', "_"));
    let csv = std::fs::read_to_string(
        dir.path()
            .join(format!("out/seed/{name}@phased.nodes=12/{name}.csv")),
    )
    .unwrap();
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (peak, bend) = (col("phased_peak_nm"), col("phased_bend_deg"));
    csv.lines()
        .skip(1)
        .map(|line| {
            let cells: Vec<f64> = line
                .split(',')
                .map(|c| c.parse().unwrap_or(f64::NAN))
                .collect();
            let value = cells[0];
            let fresh = catflip::design::phased::optimize(
                &catflip::Config::load(&cfg, &["phased.nodes=12".into(), format!("{key}={value}")])
                    .unwrap()
                    .design_spec(),
                |_| {},
            )
            .unwrap()
            .peak_torque_nm;
            (value, cells[peak], cells[bend], fresh)
        })
        .collect()
}

/// A sweep of the drop height reuses each chunk's first phased design,
/// scaled by F3: its peaks must be the phased designs computed afresh at
/// every height.
#[test]
fn a_height_sweep_scales_the_phased_design_exactly() {
    for (h, swept, _, direct) in phased_sweep_against_fresh_designs("fall.height", "1:9:9") {
        assert!(
            (swept - direct).abs() < 1e-6 * direct,
            "h = {h}: swept {swept} vs direct {direct}"
        );
    }
}

#[test]
fn a_cat_sweep_starts_each_bend_search_at_the_neighbours_and_finds_the_scans_optimum() {
    // the radius changes the cat: each point's phased design is a local
    // search from the chunk's previous bends; it must find the optimum the
    // full scan finds at that radius (to the bend tolerance, where the peak
    // is flat: 1e-4)
    let points = phased_sweep_against_fresh_designs("cat.radius", "0.04:0.2:6");
    for &(r, swept, _, direct) in &points {
        assert!(
            (swept - direct).abs() < 1e-4 * direct,
            "r = {r}: swept {swept} vs direct {direct}"
        );
    }
    // the optimum moves with the radius (the local search had to follow it)
    let bends: Vec<f64> = points.iter().map(|p| p.2).collect();
    assert!(bends.windows(2).all(|w| w[1] > w[0] + 1.0), "{bends:?}");
}

/// The robot's config path and its sweep over `range` (`KEY=FROM:TO:N`)
/// with the phased and free-form methods, whose least heights the sweep
/// gives, in one chunk (one thread: every point after the first continues).
fn robot_least_heights(range: &str) -> (std::path::PathBuf, Vec<catflip::sweep::SweepPoint>) {
    robot_sweep(range, true)
}

/// [`robot_least_heights`], with the phased method or without it.
fn robot_sweep(range: &str, phased: bool) -> (std::path::PathBuf, Vec<catflip::sweep::SweepPoint>) {
    let path = configs().join("robot-universal.toml");
    let spec: catflip::sweep::SweepSpec = range.parse().unwrap();
    let methods = catflip::sweep::Methods {
        analytic: false,
        phased,
        free: true,
        peaks: true,
    };
    let points = catflip::sweep::sweep(&path, &[], &spec, methods, 1, |_, _| {}).unwrap();
    (path, points)
}

/// A torque-speed line does not scale with the fall (F7 holds for a torque
/// limit alone): a sweep of the robot must give the least heights `run`
/// answers with, from the time designs inside the envelope (the F7 scaling
/// of the peak said 0.2 m where `run` says 3.5). A chunk's first point is
/// `run`'s answer to the bit; the points after it continue from their
/// neighbour's designs, within the stated 0.5 % of `run`'s cold answer,
/// and a weaker motor never needs less height. (The motor's no-load speed
/// moves the least height by 3 % a step here; the body's mass, swept before,
/// by under 0.1 % over 0.45 to 0.47 kg, below the designs' convergence.)
/// The peak columns, designed without the motor limits, are one problem at
/// every point of a sweep of a motor limit: the chunk's first point's
/// designs, to the bit (designed again from a neighbour's, the free-form
/// peak moved by up to 5e-4 of itself).
#[test]
fn a_robot_sweeps_least_heights_are_the_ones_run_answers_with() {
    let (path, points) = robot_least_heights("limits.no_load_speed=6.1:5.9:3");
    let peaks = |p: &catflip::sweep::SweepPoint| {
        (
            p.phased_peak_nm,
            p.phased_bend_deg,
            p.free_peak_nm,
            p.free_bend_deg,
            p.free_status,
        )
    };
    assert!(peaks(&points[0]).2.is_some());
    assert!(
        points.iter().all(|p| peaks(p) == peaks(&points[0])),
        "{points:?}"
    );
    let mut last = 0.0;
    for (i, p) in points.iter().enumerate() {
        let cfg =
            catflip::Config::load(&path, &[format!("limits.no_load_speed={}", p.value)]).unwrap();
        let mut skipped = 0;
        let summary = catflip::run::run(&cfg, |p| {
            if let catflip::run::Progress::StageSkipped { reason } = p {
                assert!(reason.contains("fall.height"), "{reason}");
                skipped += 1;
            }
        })
        .unwrap()
        .summary;
        // not possible from 2 m: the summary says so as its outcome (exit 4),
        // and the phased and free-form stages say they were not attempted
        assert_eq!(summary.outcome, catflip::run::Outcome::Impossible);
        assert_eq!(skipped, 2);
        let answer = summary.answer.unwrap();
        let (phased, free) = (
            p.least_height_phased_m.unwrap(),
            p.least_height_free_m.unwrap(),
        );
        let swept = phased.min(free);
        let tolerance = if i == 0 { 1e-9 } else { 5e-3 };
        assert!(
            (swept - answer.least_height_m).abs() < tolerance * answer.least_height_m,
            "no-load speed {}: sweep {phased} / {free} m, run {} m",
            p.value,
            answer.least_height_m
        );
        assert!(!answer.possible && answer.least_height_m > cfg.fall.height);
        assert!(
            swept > last,
            "no-load speed {}: {swept} m after {last} m",
            p.value
        );
        last = swept;
    }
}

/// A higher hard speed limit only grows the motor envelope (docs/model.md,
/// section 5): along a chunk of a sweep of it the least height never rises,
/// a point keeping the last answer's design where that flies and is faster
/// than its own continued one (on this grid the continued design of the
/// third point was once 2e-5 above the second's answer).
#[test]
fn a_higher_speed_limit_never_needs_more_height_along_a_chunk() {
    let (_, points) = robot_sweep("limits.max_speed=7.0256410256:7.1794871795:4", false);
    let h: Vec<f64> = points
        .iter()
        .map(|p| p.least_height_free_m.unwrap())
        .collect();
    assert!(h.windows(2).all(|w| w[1] <= w[0]), "{h:?}");
}

/// The least height does not depend on the height the question is asked
/// from: a sweep of `fall.height` gives every point the same answer, the
/// one the least-height stage gives from the config's own 2 m (continued
/// from their neighbours, the points after the first once drifted by up
/// to 0.2 %, a different answer to the same question at each).
#[test]
fn a_sweep_of_the_fall_height_gives_one_least_height_at_every_point() {
    let (path, points) = robot_least_heights("fall.height=4:8:3");
    let cfg = catflip::Config::load(&path, &[]).unwrap();
    let h = crate::util::least(&cfg);
    let free = catflip::design::envelope::height_for(
        &cfg.design_spec(),
        h.free.as_ref().unwrap().manoeuvre_time_s,
    );
    assert_eq!(points.len(), 3);
    for p in &points {
        assert_eq!(p.least_height_phased_m, Some(h.phased_m), "{}", p.value);
        assert_eq!(p.least_height_free_m, Some(free), "{}", p.value);
    }
}

/// Without the phased column a sweep makes no phased least-height design
/// where a free-form one verifies (a third of a continued point's work):
/// its free-form least heights are the ones of the sweep with both
/// methods, to the bit, at the chunk's cold first point and the continued
/// points after it. So are those of the real binary's sweep of the least
/// heights alone (`--least-height-only`), which leaves the peak columns
/// empty and draws no peak figure.
#[test]
fn a_sweep_without_the_phased_method_gives_the_same_free_least_heights() {
    let range = "limits.no_load_speed=6.1:5.9:3";
    let (_, both) = robot_sweep(range, true);
    let (path, free) = robot_sweep(range, false);
    assert_eq!(free.len(), 3);
    for (b, f) in both.iter().zip(&free) {
        assert!(f.least_height_free_m.is_some(), "{f:?}");
        assert_eq!(f.least_height_free_m, b.least_height_free_m, "{}", f.value);
        assert_eq!(f.free_peak_nm, b.free_peak_nm, "{}", f.value);
        assert_eq!(f.least_height_phased_m, None);
        assert_eq!(f.error, None);
    }
    let dir = temp_dir();
    let (ok, out, err) = run_written(
        &[
            "sweep",
            path.to_str().unwrap(),
            "--set-range",
            range,
            "--methods",
            "free",
            "--least-height-only",
            "--threads",
            "1",
            "--json",
        ],
        dir.path(),
    );
    assert!(ok, "{err}");
    let alone: Vec<catflip::sweep::SweepPoint> = serde_json::from_str(&out).unwrap();
    assert_eq!(alone.len(), 3);
    for (a, f) in alone.iter().zip(&free) {
        assert_eq!(a.least_height_free_m, f.least_height_free_m, "{}", a.value);
        assert_eq!(
            (a.free_peak_nm, a.free_bend_deg, a.free_status),
            (None, None, None)
        );
        assert_eq!(a.error, None);
    }
    let set = dir
        .path()
        .join("output/robot-universal/sweep-limits_no_load_speed");
    assert!(
        set.join("sweep-limits_no_load_speed-least-height.svg")
            .exists()
    );
    assert!(!set.join("sweep-limits_no_load_speed.svg").exists());
    let page = std::fs::read_to_string(set.join("index.html")).unwrap();
    assert!(page.contains("(--least-height-only)"), "{page}");
    // the table shows the column that has numbers, not the empty ones
    assert!(page.contains("<th>least height, free, m</th>"), "{page}");
    for empty in [
        "peak N m",
        "least height, phased, m",
        "free status",
        "error",
    ] {
        assert!(!page.contains(&format!("{empty}</th>")), "{empty}: {page}");
    }
    // a resume names the flag it was made with; another --set names
    // another folder, and the refusal names the one beside it
    for (extra, words) in [
        (
            ["--methods", "free"],
            "--least-height-only given (now not given)",
        ),
        (
            ["--set", "fall.height=3"],
            "Published beside it: sweep-limits_no_load_speed (a folder's name after `@`",
        ),
    ] {
        let mut args = vec![
            "sweep",
            path.to_str().unwrap(),
            "--set-range",
            range,
            "--resume",
        ];
        args.extend(extra);
        let (code, _, err) = util::run(&args, dir.path());
        assert_eq!(code, Some(2), "{extra:?}: {err}");
        assert!(err.contains(words), "{extra:?}: {err}");
    }
}

/// A sweep of the stall torque itself, from a config without one: the
/// peak columns (without the motor limits) are one problem, taken from the
/// chunk's first point, while each point's least heights (F7 from those
/// peaks) are its own torque's, those of a sweep of that point alone to the
/// bit; the page draws the least heights and does not call the sweep
/// unlimited.
#[test]
fn a_sweep_of_the_stall_torque_gives_each_point_its_own_least_height() {
    let seed = util::seed_toml();
    let sweep = |range: &str, dir: &std::path::Path| -> Vec<catflip::sweep::SweepPoint> {
        let (ok, out, err) = run_written(
            &[
                "sweep",
                seed.to_str().unwrap(),
                "--set-range",
                range,
                "--least-height-only",
                "--json",
            ],
            dir,
        );
        assert!(ok, "{range}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    let dir = temp_dir();
    let points = sweep("limits.max_torque=0.5:0.7:3", dir.path());
    assert_eq!(points.len(), 3);
    let peaks = |p: &catflip::sweep::SweepPoint| (p.phased_peak_nm, p.free_peak_nm);
    for (i, p) in points.iter().enumerate() {
        assert!(
            p.free_peak_nm.is_some() && p.analytic_peak_nm.is_none(),
            "{p:?}"
        );
        assert_eq!(peaks(p), peaks(&points[0]), "{}", p.value);
        if i > 0 {
            let alone = &sweep(
                &format!("limits.max_torque={0}:{0}:1", p.value),
                temp_dir().path(),
            )[0];
            assert_eq!(
                p.least_height_phased_m, alone.least_height_phased_m,
                "{}",
                p.value
            );
            assert_eq!(
                p.least_height_free_m, alone.least_height_free_m,
                "{}",
                p.value
            );
            assert!(p.least_height_free_m < points[i - 1].least_height_free_m);
        }
    }
    let set = dir.path().join("output/seed/sweep-limits_max_torque");
    assert!(
        set.join("sweep-limits_max_torque-least-height.svg")
            .exists()
    );
    let page = std::fs::read_to_string(set.join("index.html")).unwrap();
    assert!(!page.contains("(no motor limits)"), "{page}");
}

/// Least heights alone need a stall torque at every point and a method
/// that has least heights: refused before any work, with the flag, the
/// key and what to change, and nothing written.
#[test]
fn a_sweep_of_least_heights_alone_refuses_what_has_none() {
    let seed = util::seed_toml();
    for (args, words) in [
        (
            vec!["--set-range", "cat.length=0.2:0.3:3"],
            "--least-height-only: the config sets no stall torque (limits.max_torque)",
        ),
        (
            vec![
                "--set-range",
                "cat.length=0.2:0.3:3",
                "--set",
                "limits.max_torque=0.5",
                "--methods",
                "analytic",
            ],
            "--methods names neither; add phased or free to --methods",
        ),
    ] {
        let dir = temp_dir();
        let mut all = vec!["sweep", seed.to_str().unwrap(), "--least-height-only"];
        all.extend(args.iter().copied());
        let (code, _, err) = util::run(&all, dir.path());
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(words), "{args:?}: {err}");
        assert!(!dir.path().join("output").exists(), "{args:?}");
    }
}

/// A grid with whole ends and a whole step is whole at every point (the
/// step was once formed before multiplying: 0:22:23 gave 14.999999999999998).
#[test]
fn whole_ends_and_steps_give_whole_grid_values() {
    for (from, to) in [(0, 22), (0, 29), (3, 30), (-20, 40)] {
        for count in 2..=(to - from + 1) as usize {
            if !((to - from) as usize).is_multiple_of(count - 1) {
                continue;
            }
            let spec: catflip::sweep::SweepSpec =
                format!("phased.nodes={from}:{to}:{count}").parse().unwrap();
            let values = spec.values();
            assert!(values.iter().all(|v| v.fract() == 0.0), "{values:?}");
            assert_eq!((values[0], values[count - 1]), (from as f64, to as f64));
        }
    }
}

/// A grid of decimal ends and a decimal step holds the decimals as typed,
/// within a rounding of the exact grid (the CSV's value column once read
/// 0.16999999999999998 in a `cat.length` sweep).
#[test]
fn decimal_ends_and_steps_give_the_decimals_as_typed() {
    for (range, longest) in [
        ("cat.length=0.15:0.25:11", 4),
        ("cat.length=0.18:0.24:7", 4),
        ("fall.height=0.5:10:20", 3),
        ("cat.radius=-0.3:0.3:13", 4),
        ("cat.radius=-1.1:0.1:13", 4),
        ("cat.radius=-0.9:0.3:5", 4),
    ] {
        let spec: catflip::sweep::SweepSpec = range.parse().unwrap();
        let (values, count) = (spec.values(), spec.count);
        let step = (spec.to - spec.from) / (count - 1) as f64;
        for (i, v) in values.iter().enumerate() {
            let exact = spec.from + step * i as f64;
            assert!(
                (v - exact).abs() <= 1e-12 * exact.abs().max(1.0),
                "{range}: {v} vs {exact}"
            );
            assert!(
                format!("{v}").len() <= longest + 2,
                "{range}: point {i} prints {v}"
            );
        }
    }
    // the ends as typed, and no rounding that merges, overflows or moves a
    // point by more than a rounding, whatever the scale
    for range in [
        "cat.radius=1.0000000000001:2:3",
        "cat.radius=1e-300:2e-300:3",
        "cat.radius=-1e-300:1e-300:3",
        "cat.radius=1:1.00000000001:11",
        "cat.radius=1e300:2e300:3",
        "cat.radius=123456789012345:223456789012345:3",
    ] {
        let spec: catflip::sweep::SweepSpec = range.parse().unwrap();
        let values = spec.values();
        let n = spec.count;
        assert_eq!((values[0], values[n - 1]), (spec.from, spec.to), "{range}");
        let step = (spec.to - spec.from) / (n - 1) as f64;
        for (i, v) in values.iter().enumerate() {
            let exact = spec.from + step * i as f64;
            assert!(v.is_finite(), "{range}: {values:?}");
            assert!(
                (v - exact).abs() <= 1e-11 * exact.abs(),
                "{range}: {v} vs {exact}"
            );
        }
        assert!(
            values.windows(2).all(|w| w[0] < w[1]),
            "{range}: {values:?}"
        );
    }
}

/// A phased sweep of the seed over `range`, writing into `dir/out`.
fn seed_sweep(dir: &std::path::Path, range: &str) -> std::process::Output {
    let cfg = configs().join("seed.toml");
    bin()
        .args(["sweep", cfg.to_str().unwrap(), "--set-range", range])
        .args(["--methods", "phased", "--out", "out"])
        .current_dir(dir)
        .output()
        .unwrap()
}

/// [`seed_sweep`] refused as bad input before any work (exit 2, nothing
/// written): its stderr.
fn refused_sweep(dir: &std::path::Path, range: &str) -> String {
    let o = seed_sweep(dir, range);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{range}: {err}");
    assert!(!dir.join("out").exists(), "{range}: nothing written");
    err
}

/// A key that takes whole numbers on a grid with fractions fails as bad
/// input before any work, naming the key and the value; a whole grid runs.
#[test]
fn a_whole_number_key_on_a_fractional_grid_is_bad_input() {
    let dir = temp_dir();
    let err = refused_sweep(dir.path(), "phased.nodes=10.5:20:2");
    assert!(
        err.contains("phased.nodes takes whole numbers") && err.contains("10.5"),
        "{err}"
    );
    let o = seed_sweep(dir.path(), "phased.nodes=10:20:3");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A key that takes a name (`cat.joint`) or a list (`analytic.split`)
/// cannot be swept: the sweep fails as bad input before any work, saying
/// what the key takes; a numeric key
/// whose every point is out of range is told apart from it.
#[test]
fn sweeping_a_key_that_takes_no_number_is_bad_input_that_says_what_it_takes() {
    let dir = temp_dir();
    let err = refused_sweep(dir.path(), "cat.joint=1:2:2");
    assert!(
        err.contains("`cat.joint` takes a name, not a number"),
        "{err}"
    );
    let err = refused_sweep(dir.path(), "analytic.split=1:2:2");
    assert!(
        err.contains("`analytic.split` takes a list, not a number") && !err.contains("sequence"),
        "{err}"
    );
    let err = refused_sweep(dir.path(), "cat.mass=-2:-1:2");
    assert!(
        err.contains("every point is invalid") && !err.contains("takes a name"),
        "{err}"
    );
}

/// With a torque limit the peak columns are the least-peak designs without
/// the torque and speed limits: below the least height they
/// are those of the same body without any limit (not empty, with an error),
/// and the least heights come from the limited motor.
#[test]
fn peak_columns_under_a_speed_limit_are_the_unlimited_designs() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let sweep = |sets: &[&str]| -> serde_json::Value {
        let mut args = vec!["sweep", cfg.to_str().unwrap()];
        for s in sets {
            args.extend(["--set", s]);
        }
        args.extend(["--set-range", "fall.height=5:5:1", "--json", "--out", "out"]);
        let (code, out, err) = util::run(&args, dir.path());
        assert_eq!(code, Some(0), "{sets:?}: {err}");
        serde_json::from_str::<serde_json::Value>(&out).unwrap()[0].clone()
    };
    let limited = sweep(&["limits.max_torque=0.5", "limits.max_speed=6"]);
    let free = sweep(&[]);
    assert!(limited["error"].is_null(), "{limited}");
    for col in ["analytic_peak_nm", "phased_peak_nm", "free_peak_nm"] {
        let (a, b) = (limited[col].as_f64(), free[col].as_f64());
        assert!(a.is_some() && a == b, "{col}: {a:?} against {b:?}");
    }
    // the motor's least height is above the question's 5 m, and only the
    // limited sweep has one
    let h = limited["least_height_free_m"].as_f64().unwrap();
    assert!(h > 5.0, "{h}");
    assert!(free["least_height_free_m"].is_null(), "{free}");
}
