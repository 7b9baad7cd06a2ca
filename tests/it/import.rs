//! `[body] urdf = ...` / `mjcf = ...`: catflip's own exports read back give
//! the same model to round-off; what catflip cannot model is refused with
//! the element and its line, exit status 2, nothing written.

use crate::util;

use catflip::Config;
use catflip::export::{mjcf, urdf};
use catflip::model::{Cat, ShapeTerms};
use std::path::Path;
use util::{config, run, seed, temp_dir};

/// A body with products of inertia, off-axis centres of mass, an
/// off-centre joint and (universal) tilted motor axes, as `[body]` keys.
pub const LOPSIDED: &str = include_str!("../data/lopsided-body.toml");

pub fn lopsided(joint: &str, extra: &str) -> Config {
    let text = format!(
        "name = \"lopsided\"\n[cat]\njoint = \"{joint}\"\n[fall]\nheight = 10.0\n{extra}\n{LOPSIDED}"
    );
    Config::from_toml(&text, "lopsided", &[]).unwrap()
}

/// The config reading the robot from `file` (written into `dir`).
fn imported(dir: &Path, key: &str, file: &str, text: &str) -> catflip::Result<Config> {
    std::fs::write(dir.join(file), text).unwrap();
    let cfg = format!("name = \"imported\"\n[fall]\nheight = 10.0\n[body]\n{key} = \"{file}\"\n");
    std::fs::write(dir.join("robot.toml"), cfg).unwrap();
    Config::load(&dir.join("robot.toml"), &[])
}

/// Largest relative difference between the two models: masses, the
/// centre-of-mass-to-joint vectors, inertias, axes, and `M`, `A` at shapes.
fn model_difference(a: &Cat, b: &Cat) -> f64 {
    assert_eq!(a.joint, b.joint);
    let (ha, hb) = (a.halves(), b.halves());
    let mut worst: f64 = 0.0;
    let mut cmp = |x: f64, y: f64, scale: f64| {
        worst = worst.max((x - y).abs() / scale);
    };
    for (p, q) in [(ha.rear, hb.rear), (ha.front, hb.front)] {
        cmp(p.mass, q.mass, p.mass);
        let (cp, cq) = (p.com_to_joint(), q.com_to_joint());
        let len = cp.iter().map(|x| x * x).sum::<f64>().sqrt();
        let big = p
            .inertia
            .iter()
            .flatten()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..3 {
            cmp(cp[i], cq[i], len);
            if a.joint == catflip::model::Joint::Universal {
                cmp(p.axis[i], q.axis[i], 1.0);
            }
            for j in 0..3 {
                cmp(p.inertia[i][j], q.inertia[i][j], big);
            }
        }
    }
    for q in [[0.0, 0.0], [0.7, -0.4], [2.1, 1.3]] {
        let (ta, tb) = (ShapeTerms::first(a, q), ShapeTerms::first(b, q));
        let big = ta.m.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..2 {
            for j in 0..2 {
                cmp(ta.m[i][j], tb.m[i][j], big);
            }
            for r in 0..3 {
                cmp(ta.a[i][r], tb.a[i][r], 1.0);
            }
        }
    }
    worst
}

#[test]
fn export_then_import_gives_the_same_model() {
    let dir = temp_dir();
    let mut worst: f64 = 0.0;
    for (what, cfg) in [
        ("seed", seed(&[])),
        ("robot", config("robot-universal", &[])),
        (
            "unequal universal",
            seed(&[
                "cat.joint=universal",
                "cat.front.mass=0.4",
                "cat.front.length=1.4",
                "cat.front.radius=0.05",
                "limits.max_torque=3.0",
            ]),
        ),
        (
            "lopsided no-twist",
            lopsided("no-twist", "[limits]\nmax_torque = 2.0"),
        ),
        ("lopsided universal", lopsided("universal", "")),
    ] {
        for (key, text) in [("urdf", urdf(&cfg)), ("mjcf", mjcf(&cfg))] {
            let back = imported(dir.path(), key, &format!("robot.{key}"), &text)
                .unwrap_or_else(|e| panic!("{what} {key}: {e}"));
            let d = model_difference(&cfg.cat(), &back.cat());
            assert!(d < 1e-12, "{what} {key}: the model differs by {d:e}");
            worst = worst.max(d);
            // the motor limit comes back as [limits] (no torque-speed line here
            // but the robot's, whose URDF effort is the braking bound; the
            // URDF's spherical joint carries no <limit>)
            let spherical = key == "urdf" && cfg.cat.joint == catflip::model::Joint::NoTwist;
            if let Some(t) = cfg.limits.max_torque
                && cfg.limits.no_load_speed.is_none()
                && !spherical
            {
                assert_eq!(back.limits.max_torque, Some(t), "{what} {key}");
            }
        }
    }
    eprintln!("export -> import: largest relative model difference {worst:e}");
    // the check can fail: another body is told apart
    let other = seed(&["cat.front.mass=1.01"]);
    assert!(model_difference(&seed(&[]).cat(), &other.cat()) > 1e-4);
}

/// A universal joint's motor axis typed beside a robot file whose joint is
/// no-twist (a ball) was dropped unseen: refused, naming the key; named
/// no-twist in cat.joint, ignored knowingly.
#[test]
fn a_motor_axis_for_a_ball_joint_is_refused() {
    let dir = temp_dir();
    let cfg = seed(&[]);
    for (key, text) in [("urdf", urdf(&cfg)), ("mjcf", mjcf(&cfg))] {
        std::fs::write(dir.path().join(format!("r.{key}")), text).unwrap();
        let toml = |extra: &str| {
            let t = format!(
                "name = \"r\"\n{extra}[fall]\nheight = 3.0\n[body]\n{key} = \"r.{key}\"\n[body.front]\naxis = [0, 1, 0]\n"
            );
            std::fs::write(dir.path().join("r.toml"), t).unwrap();
            Config::load(&dir.path().join("r.toml"), &[])
        };
        let e = toml("").expect_err(key).to_string();
        assert!(
            e.contains("`body.front.axis` = [0.0, 1.0, 0.0] is invalid")
                && e.contains(
                    "the robot description's joint is no-twist (a ball joint): leave the axes out"
                ),
            "{key}: {e}"
        );
        assert!(toml("[cat]\njoint = \"no-twist\"\n").is_ok(), "{key}");
    }
}

#[test]
fn a_config_key_replaces_the_files_value_and_the_config_limits_win() {
    let dir = temp_dir();
    let cfg = config("robot-universal", &[]);
    std::fs::write(dir.path().join("r.urdf"), urdf(&cfg)).unwrap();
    let text = "name = \"r\"\n[fall]\nheight = 3.0\n[limits]\nmax_torque = 0.5\n[body]\nurdf = \"r.urdf\"\n[body.front]\nmass = 0.5\n";
    std::fs::write(dir.path().join("r.toml"), text).unwrap();
    let back = Config::load(&dir.path().join("r.toml"), &[]).unwrap();
    let h = back.cat().halves();
    assert_eq!(h.front.mass, 0.5);
    assert_eq!(h.rear.mass, cfg.cat().halves().rear.mass);
    assert_eq!(back.limits.max_torque, Some(0.5));
    assert_eq!(back.cat.joint, catflip::model::Joint::Universal);
}

/// A URDF's revolute joint ranges bound the bend (`limits.max_bend_deg`,
/// the disc inside their box: the smaller of `-lower` and `upper` over the
/// joints), unless the config sets it; a range wider than the halves' own
/// fold limit bounds nothing (catflip's exports write +-pi), and one that
/// does not reach both sides of the straight body is refused with its line,
/// as is one typed in degrees.
#[test]
fn a_urdf_joint_range_bounds_the_bend_unless_the_config_sets_it() {
    let dir = temp_dir();
    let exported = urdf(&config("robot-universal", &[]));
    let pi = format!(
        "lower=\"{}\" upper=\"{}\"",
        -std::f64::consts::PI,
        std::f64::consts::PI
    );
    assert_eq!(exported.matches(&pi).count(), 2, "{exported}");
    let ranged =
        |first: &str, second: &str| exported.replacen(&pi, first, 1).replacen(&pi, second, 1);
    let narrow = ranged(
        "lower=\"-0.5\" upper=\"0.7\"",
        "lower=\"-0.6\" upper=\"0.55\"",
    );
    let back = imported(dir.path(), "urdf", "r.urdf", &narrow).unwrap();
    let bend = back.limits.max_bend_deg.expect("the ranges bound the bend");
    assert!((bend - 0.5f64.to_degrees()).abs() < 1e-12, "{bend}");
    // catflip's own export (+-pi) bounds nothing, nor does a limit that
    // gives no range
    let wide = imported(dir.path(), "urdf", "r.urdf", &exported).unwrap();
    assert_eq!(wide.limits.max_bend_deg, None);
    let none = imported(dir.path(), "urdf", "r.urdf", &ranged("", "")).unwrap();
    assert_eq!(none.limits.max_bend_deg, None);
    // the config's own limit wins
    std::fs::write(dir.path().join("r.urdf"), &narrow).unwrap();
    let text = "name = \"r\"\n[fall]\nheight = 3.0\n[limits]\nmax_bend_deg = 20.0\n[body]\nurdf = \"r.urdf\"\n";
    std::fs::write(dir.path().join("own.toml"), text).unwrap();
    let own = Config::load(&dir.path().join("own.toml"), &[]).unwrap();
    assert_eq!(own.limits.max_bend_deg, Some(20.0));
    // a one-sided range is refused, naming the joint's line
    let one_sided = ranged("lower=\"0\" upper=\"0.7\"", "lower=\"-0.6\" upper=\"0.55\"");
    let e = imported(dir.path(), "urdf", "r.urdf", &one_sided)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("range [0, 0.7]") && e.contains("both sides"),
        "{e}"
    );
    // the joint element's line: the last `<joint` before its range
    let limit = line_of(&one_sided, "lower=\"0\"");
    let at = one_sided
        .lines()
        .take(limit)
        .enumerate()
        .filter(|(_, l)| l.contains("<joint"))
        .map(|(i, _)| i + 1)
        .last()
        .unwrap();
    assert!(e.contains(&format!("line {at}, ")), "line {at}: {e}");
    // a range typed in degrees is refused with its radians; a file's "no
    // limit" far past a full turn bounds nothing
    let degrees = ranged(
        "lower=\"-90\" upper=\"90\"",
        "lower=\"-0.6\" upper=\"0.55\"",
    );
    let e = imported(dir.path(), "urdf", "r.urdf", &degrees)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("range [-90, 90] rad") && e.contains("in radians") && e.contains("1.5708 rad"),
        "{e}"
    );
    let unlimited = ranged("lower=\"-1e9\" upper=\"1e9\"", "lower=\"-7\" upper=\"1e4\"");
    let back = imported(dir.path(), "urdf", "r.urdf", &unlimited);
    let e = back.unwrap_err().to_string();
    assert!(e.contains("range [-7, 10000] rad"), "{e}");
    let unlimited = ranged("lower=\"-1e9\" upper=\"1e9\"", "");
    let back = imported(dir.path(), "urdf", "r.urdf", &unlimited).unwrap();
    assert_eq!(back.limits.max_bend_deg, None);
}

/// A URDF of links and joints (a `<link>`'s inertial is `mass` kg, unit-ish inertia).
fn urdf_of(links: &[(&str, f64)], joints: &str) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<robot name=\"t\">\n");
    for (name, m) in links {
        if *m > 0.0 {
            s.push_str(&format!(
                "  <link name=\"{name}\">\n    <inertial><mass value=\"{m}\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.002\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>\n  </link>\n"
            ));
        } else {
            s.push_str(&format!("  <link name=\"{name}\"/>\n"));
        }
    }
    s.push_str(joints);
    s.push_str("</robot>\n");
    s
}

fn joint(name: &str, kind: &str, parent: &str, child: &str, xyz: &str, axis: &str) -> String {
    format!(
        "  <joint name=\"{name}\" type=\"{kind}\">\n    <parent link=\"{parent}\"/>\n    <child link=\"{child}\"/>\n    <origin xyz=\"{xyz}\"/>\n    <axis xyz=\"{axis}\"/>\n  </joint>\n"
    )
}

/// Line (1-based) of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn files_catflip_cannot_model_are_refused_with_the_element_and_its_line() {
    let two = |j: &str| {
        urdf_of(
            &[("rear", 1.0), ("cross", 0.0), ("front", 1.0), ("tail", 0.2)],
            j,
        )
    };
    let m1 = joint("m1", "revolute", "rear", "cross", "0 0 0.1", "1 0 0");
    let cases: Vec<(&str, String, &str, &str)> = vec![
        (
            "prismatic",
            urdf_of(
                &[("rear", 1.0), ("front", 1.0)],
                &joint("slider", "prismatic", "rear", "front", "0 0 0.1", "0 0 1"),
            ),
            "<joint name=\"slider\">",
            "prismatic",
        ),
        (
            "third link",
            two(&format!(
                "{m1}{}{}",
                joint("m2", "revolute", "cross", "front", "0 0 0", "0 1 0"),
                joint("wag", "revolute", "front", "tail", "0 0 0.1", "1 0 0")
            )),
            "<link name=\"tail\">",
            "third moving link",
        ),
        (
            "axes apart",
            two(&format!(
                "{m1}{}{}",
                joint("m2", "revolute", "cross", "front", "0 0 0.05", "0 1 0"),
                joint("fixtail", "fixed", "front", "tail", "0 0 0.1", "1 0 0")
            )),
            "<joint name=\"m2\">",
            "do not meet",
        ),
        (
            "massless half",
            urdf_of(
                &[("rear", 1.0), ("front", 0.0)],
                &joint("ball", "spherical", "rear", "front", "0 0 0.1", "0 0 1"),
            ),
            "<link name=\"front\">",
            "without mass",
        ),
        (
            // the cross is then not "heavier than a half": the half is massless
            "massless half across a universal joint",
            urdf_of(
                &[("rear", 1.0), ("cross", 1e-9), ("front", 0.0)],
                &format!(
                    "{m1}{}",
                    joint("m2", "revolute", "cross", "front", "0 0 0", "0 1 0")
                ),
            ),
            "<link name=\"front\">",
            "without mass",
        ),
        (
            "malformed",
            "<robot name=\"t\">\n  <link name=\"rear\">\n</robot>\n".to_string(),
            "the document",
            "not well-formed",
        ),
        (
            // (it was blamed on the rear link: "a number is not finite")
            "zero axis",
            two(&format!(
                "{m1}{}",
                joint("m2", "revolute", "cross", "front", "0 0 0", "0 0 0")
            ))
            .replace(
                "<axis xyz=\"0 0 0\"/>",
                "<axis name=\"m2axis\" xyz=\"0 0 0\"/>",
            ),
            "<axis name=\"m2axis\">",
            "`xyz` is all zeros",
        ),
        (
            "negative mass",
            urdf_of(
                // (the front first: its <mass> is the first, whose line is checked)
                &[("front", 0.2), ("rear", 1.0)],
                &joint("ball", "spherical", "rear", "front", "0 0 0.1", "0 0 1"),
            )
            .replace("<mass value=\"0.2\"/>", "<mass value=\"-0.2\"/>"),
            "<mass>",
            "value = -0.2 kg is negative",
        ),
        (
            "inertial without mass",
            urdf_of(
                &[("front", 0.2), ("rear", 1.0)],
                &joint("ball", "spherical", "rear", "front", "0 0 0.1", "0 0 1"),
            )
            .replace("<mass value=\"0.2\"/>", ""),
            "<inertial>",
            "without <mass>",
        ),
        // URDF requires the <inertia> and its six moments (urdfdom refuses
        // them missing): taken as 0 they made a link a point mass
        (
            "inertial without inertia",
            urdf_of(
                &[("front", 0.2), ("rear", 1.0)],
                &joint("ball", "spherical", "rear", "front", "0 0 0.1", "0 0 1"),
            )
            .replacen(
                "<inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.002\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>",
                "",
                1,
            ),
            "<inertial>",
            "without <inertia>",
        ),
        (
            "a misspelt moment",
            urdf_of(
                &[("front", 0.2), ("rear", 1.0)],
                &joint("ball", "spherical", "rear", "front", "0 0 0.1", "0 0 1"),
            )
            .replacen("<inertia ixx=", "<inertia ix=", 1),
            "<inertia>",
            "needs the attribute `ixx`",
        ),
        (
            "negative motor limit",
            std::fs::read_to_string(util::configs().join("box-robot.urdf"))
                .unwrap()
                .replacen("effort=\"1.4\"", "effort=\"-1\"", 1),
            "<limit>",
            "effort=\"-1\" is negative",
        ),
    ];
    for (what, text, element, why) in cases {
        let dir = temp_dir();
        std::fs::write(dir.path().join("robot.urdf"), &text).unwrap();
        std::fs::write(
            dir.path().join("robot.toml"),
            "name = \"bad\"\n[fall]\nheight = 3.0\n[body]\nurdf = \"robot.urdf\"\n",
        )
        .unwrap();
        let (code, out, err) = run(&["run", "robot.toml", "--out", "out"], dir.path());
        assert_eq!(code, Some(2), "{what}: {out} {err}");
        assert!(err.contains(element), "{what}: names {element}: {err}");
        assert!(err.contains(why), "{what}: says why ({why}): {err}");
        let line = if element == "the document" {
            3
        } else {
            line_of(&text, &element[..element.len() - 1])
        };
        assert!(
            err.contains(&format!("line {line},")),
            "{what}: names line {line}: {err}"
        );
        assert!(!dir.path().join("out").exists(), "{what}: nothing written");
    }
}

#[test]
fn mjcf_files_catflip_cannot_model_are_refused() {
    let cfg = config("robot-universal", &[]);
    let good = mjcf(&cfg);
    let dir = temp_dir();
    for (what, text, why) in [
        (
            "slide",
            good.replace(
                "type=\"hinge\" axis=\"0 1 0\"",
                "type=\"slide\" axis=\"0 1 0\"",
            ),
            "slide",
        ),
        (
            "parallel",
            good.replace("axis=\"0 1 0\"", "axis=\"1 0 0\""),
            "parallel",
        ),
        (
            "zero axis",
            good.replace("axis=\"0 1 0\"", "axis=\"0 0 0\""),
            "`axis` is all zeros",
        ),
        (
            "negative mass",
            good.replacen("mass=\"", "mass=\"-", 1),
            "kg is negative",
        ),
        // what MuJoCo itself refuses is refused, not read some other way
        (
            "reversed ctrlrange",
            good.replacen("ctrlrange=\"-1.4 1.4\"", "ctrlrange=\"1.4 -1.4\"", 1),
            "lower bound above its upper one",
        ),
        (
            "actuator on no joint",
            good.replacen("joint=\"motor2\"", "joint=\"motorX\"", 1),
            "joint=\"motorX\" names no joint of the model",
        ),
        (
            "two orientations",
            good.replacen(
                "<body name=\"front\" pos=\"0 0 0.1\"",
                "<body name=\"front\" pos=\"0 0 0.1\" quat=\"1 0 0 0\" euler=\"0 0 0\"",
                1,
            ),
            "quat and euler give its orientation twice",
        ),
        (
            "no inertial",
            good.replacen("<inertial", "<!-- <inertial", 2).replacen(
                "\"/>\n      <geom",
                "\"/> -->\n      <geom",
                2,
            ),
            "no <inertial>",
        ),
        // defaults would change elements that do not name them (a joint's
        // type): refused, unclassed or by class, wherever the class is used
        (
            "default",
            good.replacen(
                "<worldbody>",
                "<default><joint type=\"slide\"/></default>\n  <worldbody>",
                1,
            ),
            "<default>: catflip does not read MJCF defaults",
        ),
        (
            "class",
            good.replacen(
                "type=\"hinge\" axis=\"0 1 0\"",
                "type=\"hinge\" class=\"s\" axis=\"0 1 0\"",
                1,
            ),
            "`class`: catflip does not read MJCF default classes",
        ),
    ] {
        let e = imported(dir.path(), "mjcf", "robot.xml", &text)
            .expect_err(what)
            .to_string();
        assert!(e.contains(why) && e.contains("line "), "{what}: {e}");
    }
}

#[test]
fn the_bundled_box_robot_is_read_from_its_urdf_and_answered() {
    let cfg = config("box-robot", &[]);
    let cat = cfg.cat();
    let h = cat.halves();
    assert_eq!(cat.joint, catflip::model::Joint::Universal);
    // every part of each half, fixed to it in the URDF, is in its rigid body
    assert!((h.rear.mass - (0.22 + 0.11 + 0.057 + 2.0 * 0.018)).abs() < 1e-12);
    assert!((h.front.mass - (0.18 + 0.057 + 0.03 + 2.0 * 0.018)).abs() < 1e-12);
    // the battery puts the rear's centre of mass off the axis, and products of inertia in
    assert!(
        h.rear.com[0].hypot(h.rear.com[1]) > 4e-3,
        "{:?}",
        h.rear.com
    );
    assert!(h.rear.inertia[0][1].abs() > 1e-7 && h.front.inertia[0][2].abs() > 1e-7);
    assert!(!cat.is_axisymmetric());
    // the servos' limits from the file, the torque-speed line from the config
    assert_eq!(cfg.limits.max_torque, Some(1.4));
    assert_eq!(cfg.limits.max_speed, Some(5.969));
    assert_eq!(cfg.limits.no_load_speed, Some(5.969));
    // and `run` says so: summary.json's `limits`, and a line under the title
    let used = catflip::run::LimitsUsed::of(&cfg);
    assert_eq!(
        serde_json::to_value(&used).unwrap(),
        serde_json::json!({
            "max_torque_nm": 1.4,
            "no_load_speed_rad_s": 5.969,
            "max_speed_rad_s": 5.969,
            "max_bend_deg": null,
            "file": "body.urdf",
            "from_file": ["max_torque", "max_speed"],
        })
    );
    assert_eq!(
        used.line().unwrap(),
        "limits: stall torque 1.4 N m (from body.urdf), no-load speed 5.969 rad/s, speed limit 5.969 rad/s (from body.urdf)"
    );
    // the robot question: the phased family (made for symmetric halves)
    // flips this lopsided body but tilts its spine, so its answer alone
    // verifies nothing and claims no height
    let a = catflip::design::least_height::answer(&cfg.design_spec())
        .unwrap()
        .unwrap();
    assert!(!a.verified && !a.possible, "{}", a.sentence());
    assert!(a.least_height_m.is_finite() && a.flip_error_rad.abs() < 1e-6);
    assert!(a.sentence().starts_with("No verified design found"));
    // `run`'s answer: a verified free-form design, shorter; from its 2 m the
    // robot cannot, from 1.01 times the least height it can
    let h = crate::util::least(&cfg);
    let f = &h.answer;
    assert!(f.verified && f.method == "free", "{}", f.sentence());
    // (and a sweep says its phased column is not a verified height)
    assert!(!h.phased_verified);
    assert!(!f.possible && f.least_height_m > cfg.fall.height);
    assert!(f.least_height_m < a.least_height_m);
    let again = config(
        "box-robot",
        &[&format!("fall.height={}", 1.01 * f.least_height_m)],
    );
    assert!(
        catflip::design::least_height::fits(&again.design_spec(), f.least_height_m),
        "from 1.01 x its least height it can"
    );
}

/// `robot.toml` in `dir`, reading `robot.urdf`: the box robot's URDF
/// through `edit` (which must change it).
fn box_robot_with(dir: &Path, edit: impl Fn(&str) -> String) -> std::path::PathBuf {
    let urdf = std::fs::read_to_string(util::configs().join("box-robot.urdf")).unwrap();
    let edited = edit(&urdf);
    assert_ne!(edited, urdf, "the edit changes nothing");
    std::fs::write(dir.join("robot.urdf"), &edited).unwrap();
    let toml = dir.join("robot.toml");
    std::fs::write(
        &toml,
        "name = \"r\"\n[fall]\nheight = 3.0\n[body]\nurdf = \"robot.urdf\"\n",
    )
    .unwrap();
    toml
}

/// A URDF's `effort` and `velocity` of 0 (what exporters write for "not
/// given") set no motor limit; the config's own keys still do.
#[test]
fn zero_effort_and_velocity_in_a_urdf_mean_no_limit() {
    let dir = temp_dir();
    let toml = box_robot_with(dir.path(), |u| {
        u.replace(
            "effort=\"1.4\" velocity=\"5.969\"",
            "effort=\"0\" velocity=\"0\"",
        )
    });
    let cfg = Config::load(&toml, &[]).unwrap();
    assert_eq!(cfg.limits.max_torque, None);
    assert_eq!(cfg.limits.max_speed, None);
    let cfg = Config::load(&toml, &["limits.max_torque=1.2".into()]).unwrap();
    assert_eq!(cfg.limits.max_torque, Some(1.2));
}

/// A limit the robot file gave is named in a verdict's reasons by the file
/// and its attribute (the user never typed the key); the same limit typed
/// in the config is named by its key.
#[test]
fn a_verdict_names_a_limit_where_the_robot_file_gave_it() {
    use catflip::verdict::{DesignNumbers, Status, Targets, limit_misses};
    let dir = temp_dir();
    let toml = box_robot_with(dir.path(), |u| {
        u.replacen(
            "lower=\"-2.6\" upper=\"2.6\"",
            "lower=\"-0.5\" upper=\"0.7\"",
            1,
        )
    });
    let reasons = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let spec = Config::load(&toml, &sets).unwrap().design_spec();
        let over = DesignNumbers {
            status: Status::Solved,
            peak_torque_nm: 100.0,
            bend_deg: 170.0,
            max_speed_rad_s: Some(100.0),
            envelope_margin: None,
            line_margin: None,
        };
        limit_misses(&Targets::of(&spec), &over)
            .iter()
            .map(|m| m.to_string())
            .collect::<Vec<_>>()
    };
    let from_file = reasons(&[]);
    assert_eq!(from_file.len(), 3, "{from_file:?}");
    for (m, what) in from_file.iter().zip([
        "its joints' effort, read as limits.max_torque) = 1.4 N m",
        "its joints' velocity, read as limits.max_speed) = 5.969 rad/s",
        "its joints' lower and upper limits, read as limits.max_bend_deg) = ",
    ]) {
        assert!(m.contains(&format!("above body.urdf ({what}")), "{m}");
    }
    let typed = reasons(&["limits.max_speed=3"]);
    assert!(
        typed[1].contains("above limits.max_speed = 3 rad/s"),
        "{typed:?}"
    );
    assert!(
        typed[0].contains("body.urdf (its joints' effort"),
        "{typed:?}"
    );
}

/// A URDF whose joints give `effort="0"` (exporters' "not given") has no
/// torque limit, so a config that adds the torque-speed line's no-load
/// speed is refused: the message says the file gave no effort, not only
/// that the key is missing.
#[test]
fn a_urdf_without_effort_is_named_when_the_line_needs_the_stall_torque() {
    let dir = temp_dir();
    let text =
        std::fs::read_to_string(util::config_path("box-robot").with_file_name("box-robot.urdf"))
            .unwrap()
            .replace("effort=\"1.4\"", "effort=\"0\"");
    std::fs::write(dir.path().join("r.urdf"), text).unwrap();
    let cfg = "name = \"r\"\n[fall]\nheight = 3.0\n[limits]\nno_load_speed = 5.969\n[body]\nurdf = \"r.urdf\"\n";
    std::fs::write(dir.path().join("r.toml"), cfg).unwrap();
    let e = Config::load(&dir.path().join("r.toml"), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("limits.no_load_speed") && e.contains("needs limits.max_torque"),
        "{e}"
    );
    assert!(e.contains("body.urdf gives no torque limit"), "{e}");
}
