//! The robot builder's answer is one answer: the least drop height does not
//! depend on the height the question is asked from, a weaker motor never
//! needs less, and the lower bound beside it is below it.
use crate::util::least;
use catflip::Config;
use catflip::design::envelope::{least_stretch, usage_of};
use catflip::design::least_height::{Heights, reference};

fn robot(set: &[&str]) -> Config {
    crate::util::config("robot-universal", set)
}

/// The answers from 1, 2, 6 and 10 m agree: every design of the answer is
/// made for the reference drop, which depends on the body and motors only
/// (the stated tolerance is rounding, 1e-9 relative; the designs are the
/// same to the bit). The question's height only decides `possible`.
#[test]
fn the_least_height_is_the_same_from_any_question_height() {
    let at = |h: f64| robot(&[&format!("fall.height={h}")]);
    for h in [1.0, 6.0, 10.0] {
        assert_eq!(
            reference(&at(h).design_spec()).fall.height,
            reference(&at(2.0).design_spec()).fall.height,
            "reference drop from {h} m"
        );
    }
    let answers: Vec<(f64, Heights)> = [1.0, 2.0, 6.0, 10.0]
        .into_iter()
        .map(|h| (h, least(&at(h))))
        .collect();
    let first = &answers[0].1.answer;
    for (h, a) in &answers {
        let a = &a.answer;
        assert!(
            (a.least_height_m - first.least_height_m).abs() <= 1e-9 * first.least_height_m,
            "from {h} m: {} m, from 1 m: {} m",
            a.least_height_m,
            first.least_height_m
        );
        assert_eq!(
            a.possible,
            a.least_height_m <= *h * (1.0 + 1e-9),
            "from {h} m"
        );
        assert_eq!(a.height_m, *h);
        // the bound is below the answer, and named in the JSON and the sentence
        let bound = a
            .least_height_lower_bound_m
            .expect("a stall torque bounds it");
        assert!(
            bound > 0.0 && bound < a.least_height_m,
            "{bound} vs {}",
            a.least_height_m
        );
        let json = serde_json::to_value(a).unwrap();
        assert_eq!(json["least_height_lower_bound_m"].as_f64(), Some(bound));
        assert!(
            a.sentence()
                .contains(&format!("(at least {bound:.3} m within the stall torque")),
            "{}",
            a.sentence()
        );
        // far below the answer (the robot's speed is what it lacks) the gap is named
        assert_eq!(
            a.sentence()
                .contains("the motor's speed, not its torque, needs the rest"),
            bound < 0.5 * a.least_height_m,
            "{}",
            a.sentence()
        );
    }
}

/// A motor with 0.8 times the no-load speed never needs less height (the
/// stated tolerance: 1e-3 relative; the robot's answer is limited by the
/// speed, so it needs much more).
#[test]
fn a_weaker_motor_never_needs_less_height() {
    let base = robot(&[]);
    let w0 = base.limits.no_load_speed.unwrap();
    let weak = robot(&[&format!("limits.no_load_speed={}", 0.8 * w0)]);
    let (a, b) = (least(&base).answer, least(&weak).answer);
    assert!(
        b.least_height_m >= a.least_height_m * (1.0 - 1e-3),
        "0.8 x no-load speed: {} m, the servo: {} m",
        b.least_height_m,
        a.least_height_m
    );
}

/// A far stronger motor (1000 N m of stall torque, the servo's no-load
/// speed) needs no more height than the servo: its torque time alone would
/// make a reference drop of 7 cm, from which every free-form start failed
/// and the answer was the phased design's 5.07 m (the servo's: 3.49 m);
/// the reference is held to a tenth of the speed's time.
#[test]
fn a_far_stronger_motor_needs_no_more_height_than_the_servo() {
    let servo = least(&robot(&[])).answer;
    let cfg = robot(&["limits.max_torque=1000"]);
    let strong = least(&cfg).answer;
    assert!(reference(&cfg.design_spec()).fall.height > 0.5);
    assert_eq!(strong.method, "free");
    assert!(
        strong.least_height_m <= servo.least_height_m * (1.0 + 1e-3),
        "1000 N m: {} m, the servo: {} m",
        strong.least_height_m,
        servo.least_height_m
    );
}

/// The slow-down of a schedule that leaves the envelope is the least one:
/// the plan stretched by it is inside at every dense sample (the written
/// rows among them), and 1e-6 less is not.
#[test]
fn the_least_stretch_is_inside_and_no_less_would_do() {
    let cfg = robot(&[]);
    let plan = catflip::design::analytic::analytic_plan(&cfg.design_spec());
    let margin = |k: f64| {
        let mut p = plan.clone();
        p.durations = p.durations.map(|d| d * k);
        // on the dense samples the verdict reads (the written rows among them)
        let dense = catflip::verify::analyze::dense_samples(&cfg.design_spec());
        let rows = catflip::design::plan::Schedule::sample(&cfg.cat(), &p, dense).rows;
        let dense_margin = cfg
            .motor()
            .usage(rows.iter().map(|r| (r.tau, r.qd)))
            .min_margin
            .unwrap();
        assert!(dense_margin <= usage_of(&cfg.design_spec(), &p).min_margin.unwrap());
        dense_margin
    };
    assert!(
        margin(1.0) < 0.0,
        "the seed's schedule breaks the robot's limits"
    );
    let k = least_stretch(&cfg.design_spec(), &plan);
    assert!(k > 1.0);
    assert!(margin(k) >= -1e-12, "{}", margin(k));
    assert!(
        margin(k * (1.0 - 1e-6)) < 0.0,
        "{}",
        margin(k * (1.0 - 1e-6))
    );
    // a plan inside already is not slowed
    let mut slow = plan.clone();
    slow.durations = slow.durations.map(|d| d * 1.01 * k);
    assert_eq!(least_stretch(&cfg.design_spec(), &slow), 1.0);
}

/// The stall-only bound is the peak design time-scaled to the stall torque
/// (F3), which holds at zero momentum only (F9): from a spinning start the
/// answer gives no bound, and its sentence none.
#[test]
fn a_spinning_start_has_no_stall_only_bound() {
    let a = least(&robot(&[
        "start.angular_velocity=[0, 0, 0.3]",
        "free.nodes=20",
    ]))
    .answer;
    assert!(a.from_start);
    assert!(a.least_height_m.is_finite());
    assert_eq!(a.least_height_lower_bound_m, None);
    assert!(!a.sentence().contains("at least"), "{}", a.sentence());
}

/// Under a stall torque alone the least time is the peak optimum's time
/// scaled until its peak is the limit (F3, F7): the answer is that of
/// `optimize`'s own peak design at the same height to within its continuous
/// torque's cost (the peak design steps at its nodes, about 0.3 %), and the
/// stall-only design, the answer's own problem, is no lower bound of it.
#[test]
fn under_a_stall_torque_alone_the_answer_is_near_the_peak_optimum_scaled_and_has_no_bound() {
    use catflip::design::free::{FreeDesign, Seed};
    use catflip::model::motor::Motor;
    let limit = 0.3;
    let cfg = crate::util::seed(&[&format!("limits.max_torque={limit}")]);
    let spec = cfg.design_spec();
    let a = least(&cfg).answer;
    assert_eq!(a.least_height_lower_bound_m, None, "{}", a.sentence());
    assert!(!a.sentence().contains("at least"), "{}", a.sentence());
    // optimize's design: the peak optimum without the limit, from its seed
    let peak = spec.with_motor(Motor::unlimited(spec.motor.norm));
    let r = FreeDesign::new(&peak).seed(Seed::Phased).solve().unwrap();
    let scaled = r.manoeuvre_time_s * (r.peak_torque_nm / limit).sqrt();
    assert!(
        a.least_time_s <= scaled * (1.0 + 5e-3),
        "least time {} s against the scaled peak optimum's {scaled} s",
        a.least_time_s
    ); // from the configured 10 m the torque F7 names is the peak optimum's
    // there (the peak design made for this fall), to the answer's accuracy
    let t = a
        .torque_alone_for_height_nm
        .expect("F7's torque for the height");
    assert!(
        (t / r.peak_torque_nm - 1.0).abs() < 5e-3,
        "{t} N m against the peak optimum's {}",
        r.peak_torque_nm
    );
    assert!(
        a.sentence()
            .contains(&format!("a stall torque of {t:.4} N m"))
    );
}

/// A motor too weak for any fall catflip designs (30 s) is answered at
/// once, with no schedule to simulate or export (a 1e-9 N m motor ran 25 s
/// of designs for a 37,000 s manoeuvre, then ran out of memory writing its
/// simulator controls); a manoeuvre that fits the longest fall is still the
/// answer, with its schedule.
#[test]
fn a_motor_too_weak_for_any_fall_is_answered_without_a_schedule() {
    use crate::util::{method_line, run_summary};
    let dir = crate::util::temp_dir();
    let (code, s, base, err) = run_summary("seed", &["limits.max_torque=1e-9"], dir.path());
    assert_eq!(code, Some(4), "{err}");
    let a = &s["answer"];
    assert_eq!(a["beyond_longest_fall"], true, "{a}");
    assert_eq!(a["possible"], false, "{a}");
    // the analytic schedule within the motors, by F7: t = T0 sqrt(peak / limit)
    let an = method_line(&s, "analytic");
    let t0 = s["analytic"]["available_time_s"].as_f64().unwrap();
    let t = t0 * (an["peak_torque_nm"].as_f64().unwrap() / 1e-9).sqrt();
    let least = a["least_time_s"].as_f64().unwrap();
    assert!(
        (least / t - 1.0).abs() < 1e-2,
        "{least} s against F7's {t} s"
    );
    assert!(
        s["methods"]
            .as_array()
            .unwrap()
            .iter()
            .all(|m| m["method"] != "least-height"),
        "{s}"
    );
    assert!(!base.join("least-height.csv").exists());
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    assert!(html.contains("nor from any drop catflip designs"), "{html}");
    // optimize's phased design names no height beyond the longest fall either
    let cfg = crate::util::config_arg("seed");
    let (code, _, err) = crate::util::run(
        &[
            "optimize",
            &cfg,
            "--set",
            "limits.max_torque=1e-9",
            "--out",
            ".",
        ],
        dir.path(),
    );
    assert_eq!(code, Some(4), "{err}");
    assert!(err.contains("longer than any catflip designs"), "{err}");
    assert!(!err.contains("drop the cat from at least"), "{err}");
    // and the free-form design says the same from any seed, at once (its SCP
    // failed numerically at this torque's scale)
    for seed in [None, Some("analytic")] {
        let mut args = vec!["optimize", &cfg, "--mode", "free"];
        args.extend(seed.map(|s| ["--seed", s]).into_iter().flatten());
        args.extend(["--set", "limits.max_torque=1e-9", "--out", "."]);
        let (code, _, err) = crate::util::run(&args, dir.path());
        assert_eq!(code, Some(4), "{seed:?}: {err}");
        assert!(
            err.contains("nor in any fall catflip designs"),
            "{seed:?}: {err}"
        );
    }
    // 1e-3 N m: the free-form design's 28.7 s manoeuvre fits the 30 s fall
    // (the phased one, 37 s, does not): it answers, with its schedule
    let (code, s, base, err) = run_summary("seed", &["limits.max_torque=1e-3"], dir.path());
    assert_eq!(code, Some(4), "{err}");
    let a = &s["answer"];
    assert!(a.get("beyond_longest_fall").is_none(), "{a}");
    assert!(a["least_time_s"].as_f64().unwrap() <= 30.0, "{a}");
    assert_eq!(method_line(&s, "least-height")["verdict"], "ok");
    assert!(base.join("least-height.csv").exists());
}

/// Just above the least height the free-form design starts from the
/// least-height design and carries that height, so that a failure there is
/// the design's own, not "not possible" (`pipeline::short_of_answer`);
/// below it there is no start: the answer is the error.
#[test]
fn the_start_just_above_the_least_height_carries_that_height() {
    use catflip::pipeline::{FREE_LEAST_TIME, free_start};
    let s = free_start(&robot(&["fall.height=3.5"]).design_spec(), |_| {}).unwrap();
    assert_eq!(s.name, FREE_LEAST_TIME);
    let found = least(&robot(&[])).answer.least_height_m;
    assert_eq!(s.least_height_m, Some(found));
    assert!(found < 3.5, "{found}");
    let below = free_start(&robot(&["fall.height=2"]).design_spec(), |_| {});
    assert!(below.is_err_and(|e| e.is_beyond_motors()));
}

/// A least-time design answers the least-height stage's own question (a
/// time design has no budget, so the drop the stage designs for does not
/// bind): `run`'s free-form row and `optimize`'s default design continue
/// from the stage's shortest design, in a few iterations, to the same
/// design, no slower than the stage's, and `run`'s answer is that design
/// (one least time). From the phased seed the robot's design from 6 m took
/// 95 iterations to a least time 0.09 % longer. The phased row is the
/// stage's phased time design found again from its bend.
#[test]
fn a_least_time_design_continues_from_the_least_height_answer() {
    let dir = crate::util::temp_dir();
    let sets = ["fall.height=6", "design.objective=time"];
    let (code, s, _, err) = crate::util::run_summary("robot-universal", &sets, dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(s["free_seed"], catflip::pipeline::FREE_LEAST_TIME, "{s}");
    assert!(s["scp_iterations"].as_u64().unwrap() <= 10, "{s}");
    let manoeuvre = |method: &str| -> f64 {
        crate::util::method_line(&s, method)["phase_durations_s"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_f64().unwrap())
            .sum()
    };
    let (free, answer) = (manoeuvre("free"), manoeuvre("least-height"));
    assert!(
        (free - answer).abs() <= 1e-12 * free,
        "{free} s, answer {answer} s"
    );
    let least = s["answer"]["least_time_s"].as_f64().unwrap();
    assert!(
        (least - free).abs() <= 1e-12 * free,
        "{free} s, answer {least} s"
    );
    let config = crate::util::config_path("robot-universal");
    let mut args = vec![
        "optimize",
        config.to_str().unwrap(),
        "--mode",
        "free",
        "--json",
    ];
    for set in sets {
        args.extend(["--set", set]);
    }
    let (code, out, err) = crate::util::run(&args, dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("a least-time design: finding the least drop height first"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["seed"], catflip::pipeline::FREE_LEAST_TIME, "{v}");
    let t = v["manoeuvre_time_s"].as_f64().unwrap();
    assert!(
        (t - free).abs() <= 1e-12 * free,
        "optimize {t} s, run {free} s"
    );
    // the phased row's bend search starts at the stage's phased time design
    // (a local bracket, not the scan): the design `optimize` finds with the
    // whole scan, to the bit
    args[3] = "phased";
    let (code, out, err) = crate::util::run(&args, dir.path());
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let ph = crate::util::method_line(&s, "phased");
    assert_eq!(ph["bend_deg"], v["bend_deg"], "{ph} {v}");
    assert_eq!(manoeuvre("phased"), v["manoeuvre_time_s"].as_f64().unwrap());
}

/// A least-time design continued at a neighbour with another reference
/// drop (a sweep of the motors moves it with the stall torque) starts from
/// the neighbour's schedule in seconds, its answer: at the servo's body and
/// motors with a reference drop twice as high, the servo's answer comes
/// back, no slower, in a few iterations (started from it stretched to the
/// new drop's time, the continued design took 50 and ended slower).
#[test]
fn a_time_design_continues_from_its_neighbours_schedule_in_seconds() {
    let cfg = robot(&[]);
    let prev = least(&cfg).free.expect("a free-form answer");
    let r = reference(&cfg.design_spec());
    let other = r.with_height(2.0 * r.fall.height);
    let fr = catflip::design::free::FreeDesign::new(&other)
        .warm(&prev, None)
        .solve()
        .unwrap();
    let change = fr.manoeuvre_time_s / prev.manoeuvre_time_s - 1.0;
    assert!(
        (-1e-3..=1e-9).contains(&change),
        "{} s, the neighbour's {} s",
        fr.manoeuvre_time_s,
        prev.manoeuvre_time_s
    );
    assert!(fr.scp_iterations <= 15, "{} iterations", fr.scp_iterations);
}

/// A failure of the phased family keeps the free-form answer: a robot whose
/// second motor turns its front half about its own long axis (the phased
/// design's bend-and-twist path cannot use it: its twist search's flight
/// fails) got no answer at all, the least-height stage failing with the
/// phased design's error. Now the free-form time design answers, verified
/// by its flight, and only the phased row fails.
#[test]
fn a_failed_phased_family_keeps_the_free_form_answer() {
    let dir = crate::util::temp_dir();
    let config = dir.path().join("twist.toml");
    std::fs::write(
        &config,
        "name = \"twist\"\n[cat]\njoint = \"universal\"\n\
         [body.rear]\nmass = 0.6\ncom = [0.0, 0.0, 0.0]\ninertia = [1.2e-3, 1.1e-3, 3.0e-4, 0.0, 0.0, 0.0]\njoint = [0.0, 0.0, 0.11]\naxis = [1.0, 0.0, 0.0]\n\
         [body.front]\nmass = 0.35\ncom = [0.0, 0.0, 0.08]\ninertia = [5.0e-4, 4.5e-4, 1.5e-4, 0.0, 0.0, 0.0]\njoint = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 1.0]\n\
         [fall]\nheight = 1.5\nmargin = 0.1\n[limits]\nmax_torque = 1.5\nno_load_speed = 6.3\n",
    )
    .unwrap();
    let (code, out, err) = crate::util::run(
        &["run", config.to_str().unwrap(), "--json", "--out", "o"],
        dir.path(),
    );
    // not possible from 1.5 m, and said so with the height it is possible from
    assert_eq!(code, Some(4), "{err}");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    let answer = &summary["answer"];
    let least = answer["least_height_m"].as_f64().unwrap_or(f64::NAN);
    assert!(least.is_finite() && least > 1.5, "{answer}");
    assert_eq!(answer["possible"], false, "{answer}");
    assert_eq!(
        crate::util::method_line(&summary, "phased")["verdict"],
        "failed"
    );
}
