//! `catflip size`: the motors a drop height needs (issue 30, item 5).
//!
//! The expensive checks share one sizing of the robot from 2 m ([`answer`]);
//! each then designs a few motors itself with the library's least-height
//! designs, independently of the curve's own arithmetic.

use crate::util;

use catflip::size::{HEIGHT_TOLERANCE, SizeAnswer, SizeSettings, design_motor, question, size};
use std::sync::OnceLock;

const HEIGHT: f64 = 2.0;

/// The robot's question from `height`, on a 30-node mesh: what these tests
/// check (the curve's order and asymptotes, F3, the gear ratio's optimum, a
/// motor on the curve just making it) holds on any mesh, and the sizing's
/// dozen least-height designs take about 60 % of the time they take at the
/// config's 60 nodes.
fn robot_question(height: f64) -> catflip::Config {
    question(&util::config("robot-universal", &["free.nodes=30"]), height).unwrap()
}

/// The robot sized from 2 m with a small curve (4 points, 3 gear designs);
/// its progress counts each step once, in order, to the end.
fn answer() -> &'static SizeAnswer {
    static ANSWER: OnceLock<SizeAnswer> = OnceLock::new();
    ANSWER.get_or_init(|| {
        let mut seen = Vec::new();
        let a = size(
            &robot_question(HEIGHT),
            &SizeSettings {
                points: 4,
                gear_evaluations: 3,
            },
            |done, total| seen.push((done, total)),
        )
        .unwrap();
        assert_eq!(seen, (0..=6).map(|d| (d, 6)).collect::<Vec<_>>());
        a
    })
}

/// The question's motor: its stall torque and no-load speed (gear ratio 1).
fn configured_motor(q: &catflip::Config) -> (f64, f64) {
    (
        q.limits.max_torque.unwrap(),
        q.limits.no_load_speed.unwrap(),
    )
}

/// The point nearest the curve's knee (geometric middle of its ratios),
/// where both the torque and the speed matter.
fn knee(a: &SizeAnswer) -> catflip::size::CurvePoint {
    let corner = a.torque_asymptote_nm / a.speed_asymptote_rad_s.powi(2);
    *a.curve
        .iter()
        .min_by(|p, q| {
            let d = |x: &catflip::size::CurvePoint| (x.ratio_nms2 / corner).ln().abs();
            d(p).total_cmp(&d(q))
        })
        .unwrap()
}

#[test]
fn a_motor_on_the_curve_just_makes_it_and_a_weaker_one_does_not() {
    let a = answer();
    assert!(a.failed.is_empty(), "{:?}", a.failed);
    let p = knee(a);
    let q = robot_question(HEIGHT);
    let on = design_motor(&q, p.stall_torque_nm, p.no_load_speed_rad_s).unwrap();
    let rel = on.least_height_m / HEIGHT - 1.0;
    assert!(
        rel.abs() <= HEIGHT_TOLERANCE,
        "the curve's motor ({} N m, {} rad/s) needs {} m, not {HEIGHT} m",
        p.stall_torque_nm,
        p.no_load_speed_rad_s,
        on.least_height_m
    );
    // 5 % less stall torque at the same no-load speed: below the curve
    let weak = design_motor(&q, 0.95 * p.stall_torque_nm, p.no_load_speed_rad_s).unwrap();
    assert!(
        weak.least_height_m > HEIGHT,
        "5 % weaker ({} N m) still makes it: {} m",
        0.95 * p.stall_torque_nm,
        weak.least_height_m
    );
    assert!(weak.least_height_m > on.least_height_m);
    eprintln!(
        "on the curve: {} m ({:+.3} %); 5 % weaker: {} m",
        on.least_height_m,
        100.0 * rel,
        weak.least_height_m
    );
}

#[test]
fn more_speed_never_needs_more_torque_and_no_point_passes_the_asymptotes() {
    let a = answer();
    assert!(a.curve.len() >= 4, "{}", a.curve.len());
    for w in a.curve.windows(2) {
        assert!(w[1].no_load_speed_rad_s > w[0].no_load_speed_rad_s);
        assert!(
            w[1].stall_torque_nm <= w[0].stall_torque_nm,
            "{:?} then {:?}",
            (w[0].no_load_speed_rad_s, w[0].stall_torque_nm),
            (w[1].no_load_speed_rad_s, w[1].stall_torque_nm)
        );
    }
    // no motor weaker than the stall-only least peak or slower than the
    // speed-only least speed (within the designs' tolerance)
    for p in &a.curve {
        assert!(p.stall_torque_nm >= a.torque_asymptote_nm * (1.0 - HEIGHT_TOLERANCE));
        assert!(p.no_load_speed_rad_s >= a.speed_asymptote_rad_s * (1.0 - HEIGHT_TOLERANCE));
        // each point is exactly its design scaled (F3): T / w0^2 kept
        let d = &p.design;
        assert!(
            (d.stall_torque_nm / d.no_load_speed_rad_s.powi(2) / p.ratio_nms2 - 1.0).abs() < 1e-12
        );
        assert!(
            (p.stall_torque_nm / p.no_load_speed_rad_s.powi(2) / p.ratio_nms2 - 1.0).abs() < 1e-12
        );
        assert!((d.least_time_s / p.scale - a.manoeuvre_time_s).abs() < 1e-12);
    }
    // the ends: the torque-limited end near the torque asymptote, the
    // speed-limited end near the speed asymptote
    let (first, last) = (a.curve[0], a.curve[a.curve.len() - 1]);
    assert!(first.no_load_speed_rad_s < 1.2 * a.speed_asymptote_rad_s);
    assert!(last.stall_torque_nm < 1.2 * a.torque_asymptote_nm);
}

#[test]
fn the_best_gear_ratio_is_a_stationary_point_of_the_least_height() {
    let a = answer();
    let g = &a.gear;
    let q = robot_question(HEIGHT);
    let (t0, w0) = configured_motor(&q);
    // the search's own designs: none better than the best
    for e in &g.evaluations {
        assert!(e.design.least_height_m >= g.least_height_m);
        assert!((e.design.stall_torque_nm / e.gear_ratio / t0 - 1.0).abs() < 1e-12);
        assert!((e.design.no_load_speed_rad_s * e.gear_ratio / w0 - 1.0).abs() < 1e-12);
    }
    // the search's bracket holds its best ratio (or the best is the
    // configured one), and a bracket as wide as 4 points and 3 designs
    // leave is called too coarse to place the optimum
    let [lo, hi] = g.bracket;
    assert!(lo < hi, "{lo} {hi}");
    assert!(g.best_ratio == 1.0 || (lo..=hi).contains(&g.best_ratio));
    let said = a.sentences().join(" ");
    assert_eq!(
        hi > 1.25 * lo,
        said.contains("too coarse"),
        "{lo} {hi}: {said}"
    );
    assert!(
        said.contains(&format!("between N = {lo:.4} and {hi:.4}")),
        "{said}"
    );
    // which way the gearing goes, in words (N < 1 is a speed-up)
    let way = if g.best_ratio < 1.0 {
        format!("a speed-up of {:.2} times", 1.0 / g.best_ratio)
    } else {
        format!("a reduction of {:.2} times", g.best_ratio)
    };
    assert!(said.contains(&way), "{way}: {said}");
    // the configured ratio (N = 1) is among them, and no better
    assert!(g.evaluations.iter().any(|e| e.gear_ratio == 1.0));
    assert!(g.least_height_m <= g.configured_least_height_m);
    // neighbours 10 % either side, designed afresh, are no better (within
    // the designs' tolerance: the least height is flat at a minimum)
    for f in [1.1, 1.0 / 1.1] {
        let n = g.best_ratio * f;
        let d = design_motor(&q, t0 * n, w0 / n).unwrap();
        eprintln!(
            "N = {n}: {} m (best N = {}: {} m)",
            d.least_height_m, g.best_ratio, g.least_height_m
        );
        assert!(
            d.least_height_m >= g.least_height_m * (1.0 - HEIGHT_TOLERANCE),
            "N = {n}: {} m, better than the best N = {}: {} m",
            d.least_height_m,
            g.best_ratio,
            g.least_height_m
        );
    }
}

/// The gear ratios that make it: around the best, their ends where the
/// designed least heights cross the question's; a ratio designed afresh
/// well inside makes it, one well outside each finite end does not.
#[test]
fn the_gear_ratios_that_make_it_are_named_and_hold() {
    let a = answer();
    let g = &a.gear;
    let q = robot_question(HEIGHT);
    let (t0, w0) = configured_motor(&q);
    let r = g.working_range.expect("the best ratio makes it from 2 m");
    assert!(
        g.possible && r.low < g.best_ratio && g.best_ratio < r.high,
        "{r:?}"
    );
    // an end past which no ratio was tried says so after its number
    let said = a.sentences()[2].clone();
    let end = |n: f64, untried: bool, beyond: &str| {
        format!("{n:.4}{}", if untried { beyond } else { "" })
    };
    let range = format!(
        "N = {} to {} make it from 2 m",
        end(
            r.low,
            r.low_untried_beyond,
            " or less (the lowest ratio designed or predicted)"
        ),
        end(
            r.high,
            r.high_untried_beyond,
            " or more (the highest ratio designed or predicted)"
        )
    );
    assert!(said.contains(&range), "{said}\n{range}");
    let design = |n: f64| design_motor(&q, t0 * n, w0 / n).unwrap().least_height_m;
    let inside = (r.low * r.high).sqrt();
    assert!(
        design(inside) <= HEIGHT * (1.0 + HEIGHT_TOLERANCE),
        "N = {inside}"
    );
    if !r.low_untried_beyond {
        assert!(design(r.low / 1.5) > HEIGHT, "N = {}", r.low / 1.5);
    }
    if !r.high_untried_beyond {
        assert!(design(r.high * 1.5) > HEIGHT, "N = {}", r.high * 1.5);
    }
}

#[test]
fn the_curve_scales_with_the_fall_time_f3() {
    // a motor that just makes it from 2 m, sped up by k = t(2 m) / t(H'),
    // is k^2 the torque and k the speed: it just makes it from H' (F3).
    let a = answer();
    let p = knee(a);
    let other = 4.0;
    let q = robot_question(other);
    let k = a.manoeuvre_time_s / q.available_time();
    let d = design_motor(&q, k * k * p.stall_torque_nm, k * p.no_load_speed_rad_s).unwrap();
    eprintln!("scaled to {other} m: {} m", d.least_height_m);
    assert!(
        (d.least_height_m / other - 1.0).abs() <= HEIGHT_TOLERANCE,
        "scaled to {other} m: needs {} m",
        d.least_height_m
    );
}

#[test]
fn a_config_without_a_torque_speed_line_names_the_keys_to_set() {
    let dir = util::temp_dir();
    let cfg = util::seed_toml();
    let out = util::output(
        &[
            "size",
            cfg.to_str().unwrap(),
            "--height",
            "2",
            "--out",
            "out",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`limits.max_torque` is not set") && !err.contains("unset"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
    // a stall torque alone: the no-load speed is named
    let out = util::output(
        &[
            "size",
            cfg.to_str().unwrap(),
            "--height",
            "2",
            "--set",
            "limits.max_torque=0.5",
            "--out",
            "out",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("limits.no_load_speed"), "{err}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_height_out_of_range_or_a_bad_point_count_is_refused_and_nothing_written() {
    let dir = util::temp_dir();
    let cfg = util::config_path("robot-universal");
    for (args, word) in [
        (vec!["--height", "0"], "--height"),
        // a negative number is the height's value, not a flag
        (vec!["--height", "-1"], "--height -1: must be > 0 m"),
        (vec!["--height", "1e9"], "--height"),
        // NaN as Rust and Python print it, checked as the height it is
        (vec!["--height", "nan"], "--height NaN: must be > 0 m"),
        // a fall shorter than the 0.1 s landing margin
        (vec!["--height", "0.04"], "--height"),
        (vec!["--height", "2", "--points", "1"], "--points"),
        (vec!["--height", "2", "--points", "41"], "--points"),
        // the configured fall.height is not used, and a --set of it conflicts
        // with --height (it would name the output set, yet change nothing);
        // the margin is judged against --height's fall
        (
            vec!["--height", "1", "--set", "fall.height=-3", "--points", "1"],
            "--set fall.height=-3 conflicts with --height 1",
        ),
        (
            vec!["--height", "1", "--set", "fall.margin=5"],
            "(0.4515 s from this height)",
        ),
        // a spinning release: time scaling needs the momentum scaled too (F9)
        (
            vec!["--height", "2", "--set", "start.angular_velocity=[0, 0, 1]"],
            "start.angular_velocity",
        ),
    ] {
        let mut all = vec!["size", cfg.to_str().unwrap(), "--out", "out"];
        all.extend(&args);
        let out = util::output(&all, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(word), "{args:?}: {err}");
        assert!(!dir.path().join("out").exists(), "{args:?}");
    }
}

#[test]
fn size_writes_the_curve_the_gear_ratios_the_json_and_the_report() {
    // the seed's body with a DC motor: a cheap sizing (2 points, no gear
    // search); its file asks for an objective size does not use, and is
    // told so
    let dir = util::temp_dir();
    let cfg = dir.path().join("seed.toml");
    std::fs::write(
        &cfg,
        util::config_text("seed") + "\n[design]\nobjective = \"energy\"\n",
    )
    .unwrap();
    let args = [
        "size",
        cfg.to_str().unwrap(),
        "--height",
        "10",
        "--set",
        "limits.max_torque=0.5",
        "--set",
        "limits.no_load_speed=4",
        "--set",
        "limits.max_speed=3.5",
        "--points",
        "2",
        "--gear-evaluations",
        "0",
        "--out",
        "out",
        "--json",
    ];
    let out = util::output(&args, dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("sets design.objective = \"energy\", which `catflip size` does not use"),
        "{err}"
    );
    let set = dir.path().join(
        "out/seed/size-10m@limits.max_torque=0.5,limits.no_load_speed=4,limits.max_speed=3.5",
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(set.join("size.json")).unwrap()).unwrap();
    // --json prints what size.json holds
    let printed: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json, printed);
    for key in [
        "height_m",
        "manoeuvre_time_s",
        "torque_asymptote_nm",
        "speed_asymptote_rad_s",
        "curve",
        "failed",
        "gear",
        "settings",
        "designs",
        "solve_time_s",
    ] {
        assert!(json.get(key).is_some(), "size.json has no {key}");
    }
    assert_eq!(json["height_m"], 10.0);
    let curve = json["curve"].as_array().unwrap();
    assert_eq!(curve.len(), 2);
    for key in [
        "best_ratio",
        "stall_torque_nm",
        "no_load_speed_rad_s",
        "least_height_m",
        "least_time_s",
        "configured_least_height_m",
        "configured_possible",
        "possible",
        "evaluations",
    ] {
        assert!(json["gear"].get(key).is_some(), "gear has no {key}");
    }
    // the configured ratio alone was designed: it is the best one, and
    // nothing was searched
    assert_eq!(json["gear"]["best_ratio"], 1.0);
    assert_eq!(json["gear"]["bracket"], serde_json::json!([1.0, 1.0]));
    assert_eq!(
        json["gear"]["least_height_m"],
        json["gear"]["configured_least_height_m"]
    );
    // the CSV rows are the JSON's points, to their printed digits
    let csv = std::fs::read_to_string(set.join("size.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("no_load_speed_rad_s,stall_torque_nm,")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').take(2).map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    for (r, p) in rows.iter().zip(curve) {
        let w = p["no_load_speed_rad_s"].as_f64().unwrap();
        let t = p["stall_torque_nm"].as_f64().unwrap();
        assert!((r[0] / w - 1.0).abs() < 1e-8 && (r[1] / t - 1.0).abs() < 1e-8);
    }
    let gear = std::fs::read_to_string(set.join("size-gear.csv")).unwrap();
    assert!(gear.starts_with("gear_ratio,"));
    assert_eq!(gear.lines().count(), 2);
    for f in ["size.svg", "size-gear.svg"] {
        let svg = std::fs::read_to_string(set.join(f)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"), "{f}");
    }
    let html = std::fs::read_to_string(set.join("index.html")).unwrap();
    assert!(html.contains("size.svg") && html.contains("size-gear.svg"));
    assert!(html.contains("No motor weaker than"));
    // the hard speed limit kept in its ratio, and with no gear search no
    // sentence that names the keys: the ratio does
    assert!(
        html.contains("limits.max_speed = 0.8750 times limits.no_load_speed")
            && html.contains("set all three keys (limits.max_speed in that ratio)"),
        "{html}"
    );
    // the answer leads: its block above the curve's table
    let (block, table) = (
        html.find("id=\"answer\"").unwrap(),
        html.find("<table").unwrap(),
    );
    assert!(block < table, "the answer comes after the table");
    // with no gear search, no ratio is called the best: the prediction is named as one
    let best = json["gear"]["predicted"]
        .as_array()
        .unwrap()
        .iter()
        .min_by(|a, b| {
            a["least_height_m"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["least_height_m"].as_f64().unwrap())
        })
        .unwrap()
        .clone();
    assert!(
        !html.contains("best gear ratio is"),
        "no search, no best ratio"
    );
    assert!(
        html.contains(&format!(
            "the curve's designs predict that N = {:.4} needs {:.3} m",
            best["gear_ratio"].as_f64().unwrap(),
            best["least_height_m"].as_f64().unwrap()
        )),
        "the prediction named"
    );
}

/// The curve's ends are designs too: where a point of the curve passes one,
/// that point is the end the answer states (not the worse design's, which a
/// motor of its own curve contradicts), and the answer says so; with a hard
/// speed limit the gear ratio's motor comes as `--set` keys `run` takes,
/// the limit in its ratio to the no-load speed.
#[test]
fn the_ends_are_named_as_designs_and_a_point_past_one_is_said() {
    let a = answer();
    let plain = a.sentences()[0].clone();
    assert!(plain.contains("local optima, not a proof"), "{plain}");
    // read in the answer's order, on the terminal and the page: the best
    // gear ratio first where it alone makes it, else the configured motor;
    // the ends last
    let said = a.sentences();
    let order = |x: &SizeAnswer| -> Vec<usize> {
        let said = x.sentences();
        x.lead()
            .iter()
            .map(|l| said.iter().position(|s| s == l).unwrap())
            .collect()
    };
    assert!(!a.gear.configured_possible && a.gear.possible, "{said:?}");
    assert_eq!(order(a), [2, 1, 0]);
    let mut configured = a.clone();
    configured.gear.configured_possible = true;
    assert_eq!(order(&configured), [1, 2, 0]);
    assert!(!plain.contains("the curve's point at"), "{plain}");
    let slowest = a.curve[0].no_load_speed_rad_s;
    let mut past = a.clone();
    // an end's design that stopped above the curve's slowest point
    past.speed_asymptote_rad_s = 1.2 * slowest;
    past.speed_limit_ratio = Some(1.5);
    let said = past.sentences();
    assert!(
        said[0].contains(&format!("or slower than {slowest:.3} rad/s no-load speed"))
            && said[0].contains(&format!(
                "The speed end is the curve's point at {slowest:.4} rad/s: the speed-only design found a worse local optimum, {:.4} rad/s",
                1.2 * slowest
            )),
        "{}",
        said[0]
    );
    assert!(!said[0].contains("The torque end"), "{}", said[0]);
    let g = &a.gear;
    let keys = format!(
        "--set limits.max_torque={:.4} --set limits.no_load_speed={:.3} --set limits.max_speed={:.3}",
        g.stall_torque_nm,
        g.no_load_speed_rad_s,
        1.5 * g.no_load_speed_rad_s
    );
    assert!(said[2].contains(&keys), "{}", said[2]);
    // the keys run takes: the motor they set is the gear ratio's
    let cfg = util::config(
        "robot-universal",
        &keys
            .split("--set ")
            .map(str::trim)
            .filter(|k| !k.is_empty())
            .collect::<Vec<_>>(),
    );
    assert_eq!(
        cfg.limits.max_torque,
        Some(format!("{:.4}", g.stall_torque_nm).parse().unwrap())
    );
}

/// Where only a gear ratio of the configured motor makes it, the report's
/// green answer box leads with that ratio, not with "the configured motor
/// does not make it" (a green box under that read as a contradiction).
#[test]
fn the_page_leads_with_what_makes_it() {
    let a = answer();
    let g = &a.gear;
    assert!(
        g.possible && !g.configured_possible,
        "the robot from 2 m: {g:?}"
    );
    let page = catflip::report::size::page(a);
    let headline = page
        .split("<p class=\"headline\">")
        .nth(1)
        .and_then(|h| h.split("</p>").next())
        .unwrap();
    assert!(page.contains("<section id=\"answer\" class=\"possible\">"));
    assert!(
        headline.starts_with("The configured motor's best gear ratio is N = "),
        "{headline}"
    );
    // one sentence: the search and the working ratios follow in the text
    assert!(
        headline.ends_with('.') && !headline.contains(". "),
        "{headline}"
    );
    let rest = &a.lead()[0][headline.len()..];
    assert!(rest.contains("The search ended between N = "), "{rest}");
    assert!(page.contains(rest.trim()), "the rest follows: {rest}");
    assert!(
        page.contains("The configured motor ("),
        "the configured motor still said"
    );
}
