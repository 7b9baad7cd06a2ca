//! The main job, sweeps and exports, through the real binary and the library.

use crate::util;

use util::{configs, run_ok, schedule_peak, temp_dir};

#[test]
fn run_writes_a_complete_consistent_report() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let (ok, out, err) = run_ok(&["run", cfg.to_str().unwrap()], dir.path());
    assert!(ok, "{err}");
    assert!(
        out.contains("analytic") && out.contains("phased") && out.contains("free"),
        "{out}"
    );
    let base = dir.path().join("output/seed/run");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(base.join("summary.json")).unwrap()).unwrap();
    let methods = summary["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 3);
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    // the heading names the height the question is asked from (the pages of
    // one body from 2 and 6 m shared one)
    assert!(
        html.contains("<h1>catflip report: seed, dropped from 10 m</h1>"),
        "{}",
        &html[..html.len().min(2000)]
    );
    // the glossary, folded, under the table: its words beside the columns that use them
    let terms = html
        .find("<details class=\"terms\">")
        .expect("the glossary's section");
    assert!(
        html.find("</table>").unwrap() < terms,
        "the glossary follows the table"
    );
    for word in [
        "<td>sim peak</td>",
        "<td>verdict</td>",
        "<code>|q|</code>, how far",
    ] {
        assert!(html[terms..].contains(word), "{word}");
    }
    for m in methods {
        let name = m["method"].as_str().unwrap();
        let peak = m["peak_torque_nm"].as_f64().unwrap();
        // the schedule file agrees with the JSON peak (the JSON samples more densely)
        let csv = std::fs::read_to_string(base.join(m["schedule_csv"].as_str().unwrap())).unwrap();
        let p = schedule_peak(&csv, false).0;
        assert!(
            p <= peak * (1.0 + 1e-6) && p >= 0.98 * peak,
            "{name}: CSV {p} vs JSON {peak}"
        );
        // the JSON schedule holds the same rows
        let js: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(base.join(m["schedule_json"].as_str().unwrap())).unwrap(),
        )
        .unwrap();
        let rows = js["rows"].as_array().unwrap();
        assert_eq!(rows.len(), csv.lines().count() - 1);
        let jp = rows
            .iter()
            .map(|r| {
                r["tau_nm"][0]
                    .as_f64()
                    .unwrap()
                    .hypot(r["tau_nm"][1].as_f64().unwrap())
            })
            .fold(0.0, f64::max);
        assert!(
            (jp - p).abs() < 1e-9 * p,
            "{name}: JSON schedule {jp} vs CSV {p}"
        );
        // the table shows the same number
        assert!(
            html.contains(&format!("{peak:.5}")),
            "{name} peak missing from index.html"
        );
        assert!(m["flip_error_rad"].as_f64().unwrap().abs() < 1e-3, "{name}");
        // one flip convention, unwrapped: every method turns the seed the same way
        let flip = m["flip_deg"].as_f64().unwrap();
        assert!((flip + 180.0).abs() < 1e-3, "{name}: flip {flip}");
        for sim in ["mujoco", "pybullet"] {
            assert!(
                base.join(format!("{name}.{sim}.csv")).exists(),
                "{name} {sim}"
            );
        }
    }
    assert!(base.join("seed.mjcf.xml").exists() && base.join("seed.urdf").exists());
    // without motor limits the captions describe no envelope, limit line or
    // least-height panel (none is drawn)
    assert!(html.contains("no motor limits are configured, so no envelope is drawn"));
    // (the glossary names every word of any report)
    let end = terms + html[terms..].find("</details>").unwrap();
    let page = format!("{}{}", &html[..terms], &html[end..]);
    for absent in [
        "grey band",
        "least-height",
        "torque limit is the black line",
    ] {
        assert!(!page.contains(absent), "{absent}");
    }
    let peaks: Vec<f64> = methods
        .iter()
        .map(|m| m["peak_torque_nm"].as_f64().unwrap())
        .collect();
    assert!(peaks[2] <= peaks[1] && peaks[1] <= peaks[0]);
    assert!((summary["free_over_phased"].as_f64().unwrap() - peaks[2] / peaks[1]).abs() < 1e-12);
    for fig in summary["figures"].as_array().unwrap() {
        let name = fig.as_str().unwrap();
        assert!(html.contains(name));
        let text = std::fs::read_to_string(base.join(name)).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        let texts: Vec<String> = doc
            .descendants()
            .filter(|n| n.tag_name().name() == "text")
            .map(|n| n.text().unwrap_or("").to_string())
            .collect();
        assert!(texts.len() > 5, "{name} has too little text");
        // legends sit beside the plot: every label naming a method lies right
        // of every point of every drawn curve (polylines of many points)
        let curve_right = doc
            .descendants()
            .filter(|n| n.tag_name().name() == "polyline")
            .filter_map(|n| n.attribute("points"))
            .map(|p| p.split_whitespace().collect::<Vec<_>>())
            .filter(|p| p.len() > 10)
            .flat_map(|p| {
                p.into_iter()
                    .map(|xy| xy.split(',').next().unwrap().parse::<f64>().unwrap())
            })
            .fold(0.0, f64::max);
        for t in doc.descendants().filter(|n| n.tag_name().name() == "text") {
            let label = t.text().unwrap_or("").trim();
            if ["analytic", "phased", "free"]
                .iter()
                .any(|m| label.starts_with(m))
            {
                let x: f64 = t.attribute("x").unwrap().parse().unwrap();
                assert!(
                    x > curve_right,
                    "{name}: legend `{label}` at x {x} within the curves (to {curve_right})"
                );
            }
        }
        assert!(
            texts.iter().any(|t| t.contains("time (s)")
                || t.contains("iteration")
                || t.contains("q1 (deg)")
                || t.contains("(rad/s)")),
            "{name}: {texts:?}"
        );
    }
    assert!(html.contains("<script type=\"application/json\" id=\"scene\">"));
    let torque = std::fs::read_to_string(base.join("torque.svg")).unwrap();
    // each legend gives the table's (dense) peak, not its curve's samples'
    for p in &peaks {
        assert!(
            torque.contains(&format!("peak {p:.4} N m")),
            "peak {p} missing from the torque figure's legends"
        );
    }
    // the optimised designs (under 1 N m) are flat under the analytic
    // schedule's 21 N m: a detail panel draws them, up to a quarter above
    // the larger, without the analytic's trajectory
    let speed = std::fs::read_to_string(base.join("torque_speed.svg")).unwrap();
    let optimised = peaks[1].max(peaks[2]);
    assert!(peaks[0] > 8.0 * optimised, "{peaks:?}");
    let detail = speed
        .find(", detail: |tau| up to ")
        .expect("a detail panel");
    let window: f64 = speed[detail..]
        .trim_start_matches(", detail: |tau| up to ")
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        window >= optimised && window <= 1.3 * optimised,
        "{window} N m"
    );
    assert!(
        !speed[detail..].contains("analytic ("),
        "the analytic is not in the detail"
    );
}

#[test]
fn sweep_agrees_with_single_runs() {
    let cfg_path = configs().join("seed.toml");
    let spec: catflip::sweep::SweepSpec = "fall.height=5:10:2".parse().unwrap();
    let methods = catflip::sweep::Methods::ALL;
    let points = catflip::sweep::sweep(&cfg_path, &[], &spec, methods, 2, |_, _| {}).unwrap();
    assert_eq!(points.len(), 2);
    for p in &points {
        let cfg = catflip::Config::load(&cfg_path, &[format!("fall.height={}", p.value)]).unwrap();
        let (a, _) = catflip::verify::analyze::peak_along(
            &cfg.design_spec(),
            &catflip::design::analytic::analytic_plan(&cfg.design_spec()),
            catflip::verify::analyze::dense_samples(&cfg.design_spec()),
        );
        let ph = catflip::design::phased::optimize(&cfg.design_spec(), |_| {}).unwrap();
        let fr = catflip::design::free::FreeDesign::new(&cfg.design_spec())
            .from_plan(&ph.plan, "phased")
            .solve()
            .unwrap();
        assert!((p.analytic_peak_nm.unwrap() - a).abs() <= 1e-12 * a);
        assert!((p.phased_peak_nm.unwrap() - ph.peak_torque_nm).abs() <= 1e-12 * a);
        // a sweep continues from its neighbour's free-form design, a single
        // run from the phased one: the same optimum to the optimiser's tolerance
        let rel = (p.free_peak_nm.unwrap() - fr.peak_torque_nm).abs() / fr.peak_torque_nm;
        assert!(
            rel <= 5e-3,
            "sweep {} vs single run {}",
            p.free_peak_nm.unwrap(),
            fr.peak_torque_nm
        );
        assert!(p.error.is_none());
    }
    // F3 across the sweep: peak ~ 1 / T^2 ~ 1 / height
    let r = points[0].phased_peak_nm.unwrap() / points[1].phased_peak_nm.unwrap();
    assert!((r - 2.0).abs() < 1e-6, "{r}");
}

#[test]
fn sweep_cli_writes_csv_and_plot_and_rejects_bad_ranges() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let c = cfg.to_str().unwrap();
    let (ok, _, err) = run_ok(
        &[
            "sweep",
            c,
            "--set-range",
            "cat.mass=0.5:1:2",
            "--methods",
            "analytic,phased",
            "--set",
            "limits.max_torque=0.5",
        ],
        dir.path(),
    );
    assert!(ok, "{err}");
    let csv = std::fs::read_to_string(
        dir.path()
            .join("output/seed/sweep-cat_mass@limits.max_torque=0.5/sweep-cat_mass.csv"),
    )
    .unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3);
    assert!(rows[0].starts_with("cat.mass,"));
    // with a torque limit, the least drop height of F7 is there
    assert!(
        dir.path()
            .join(
                "output/seed/sweep-cat_mass@limits.max_torque=0.5/sweep-cat_mass-least-height.svg"
            )
            .exists()
    );
    let h: f64 = rows[2].split(',').nth(6).unwrap().parse().unwrap();
    assert!(h > 10.0, "{h}");
    // the x axis carries the key's unit; peaks spanning more than a factor
    // 20 (the seed's schedule against the optimum) go on a log axis
    let svg = std::fs::read_to_string(
        dir.path()
            .join("output/seed/sweep-cat_mass@limits.max_torque=0.5/sweep-cat_mass.svg"),
    )
    .unwrap();
    assert!(svg.contains("cat.mass (kg)"));
    let peaks: Vec<f64> = rows[1..]
        .iter()
        .flat_map(|r| {
            r.split(',')
                .skip(1)
                .take(2)
                .map(|x| x.parse::<f64>().unwrap())
        })
        .collect();
    let spread =
        peaks.iter().cloned().fold(0.0, f64::max) / peaks.iter().cloned().fold(f64::MAX, f64::min);
    assert_eq!(svg.contains("log scale"), spread > 20.0, "spread {spread}");
    for bad in ["cat.mass=1:2", "cat.masss=1:2:3", "cat.mass=-1:2:3"] {
        let (ok, _, err) = run_ok(&["sweep", c, "--set-range", bad], dir.path());
        assert!(!ok && !err.is_empty(), "{bad} should fail");
    }
}

/// A run that goes wrong on purpose: a torque limit the seed's schedule
/// exceeds and a free-form optimiser cut off after 2 iterations a mesh (with
/// 3, the fine mesh converges from the stopped coarse design). Each
/// problem is shown where a user looks: table, page, figure, terminal names.
#[test]
fn run_shows_an_exceeded_limit_and_an_unconverged_optimiser() {
    let dir = temp_dir();
    let cfg = configs().join("seed.toml");
    let (_, out, err) = run_ok(
        &[
            "run",
            cfg.to_str().unwrap(),
            "--set",
            "limits.max_torque=5",
            "--set",
            "free.max_iterations=2",
        ],
        dir.path(),
    );
    let base = dir
        .path()
        .join("output/seed/run@limits.max_torque=5,free.max_iterations=2");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(base.join("summary.json"))
            .unwrap_or_else(|e| panic!("{e}: {err}")),
    )
    .unwrap();
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    let methods = summary["methods"].as_array().unwrap();
    // the seed's schedule needs more than 5 N m; the free-form run stopped early
    assert!(methods[0]["peak_torque_nm"].as_f64().unwrap() > 5.0);
    assert_eq!(methods[2]["status"], "iteration-limit");
    for m in &methods[..] {
        let name = m["method"].as_str().unwrap();
        if m["verdict"] == "flagged" {
            // the reason is a red note on the page and sits in the table
            let reason = m["reason"].as_str().unwrap();
            let note = format!("<p class=\"warn\">{name}: ");
            assert!(html.contains(&note), "{name}: no note for {reason}");
            assert!(
                out.contains(&format!("FLAGGED: {}", reason)),
                "{name}: {out}"
            );
        }
    }
    assert_eq!(methods[0]["verdict"], "flagged");
    assert_eq!(methods[2]["verdict"], "flagged");
    // the terminal says what the JSON says, not Rust's Debug names
    assert!(out.contains("iteration-limit") && !out.contains("IterationLimit"));
    assert!(out.contains("peak norm euclidean"), "{out}");
    let torque = std::fs::read_to_string(base.join("torque.svg")).unwrap();
    assert!(torque.contains("torque limit 5 N m") && torque.contains("OVER LIMIT"));
}

/// The animation frames: spread over the whole simulation, body B built from
/// body A and the shape. Oracles: the angle between the two spines is the
/// bend `|q|` (no-twist joint: `q` is a rotation about an axis normal to A's
/// spine), and at the end the straight cat's halves share one attitude.
#[test]
fn animation_frames_follow_the_simulation() {
    use catflip::report::animation::{FRAMES, track};
    use nalgebra::{Quaternion, UnitQuaternion, Vector3};
    // (the seed's margin is 0: a tenth of a second of it, to touchdown)
    let cfg =
        catflip::Config::load(&configs().join("seed.toml"), &["fall.margin=0.1".into()]).unwrap();
    let cat = cfg.cat();
    let plan = catflip::design::analytic::analytic_plan(&cfg.design_spec());
    let sim = catflip::verify::simulate::dynamic_spec(&cfg.design_spec(), &plan).unwrap();
    let margin = cfg.fall.margin;
    let tr = track(&cat, cfg.norm(), "analytic", &sim, (FRAMES, margin));
    let manoeuvre = sim.trace.last().unwrap().t;
    let (f, after): (Vec<_>, Vec<_>) = tr.frames.iter().cloned().partition(|fr| fr.t <= manoeuvre);
    assert!(f.len() > FRAMES / 2 && f.len() <= FRAMES, "{}", f.len());
    assert_eq!(f[0].t, sim.trace[0].t);
    assert_eq!(f.last().unwrap().t, manoeuvre);
    assert!(tr.frames.windows(2).all(|w| w[1].t > w[0].t));
    // then to touchdown: at zero momentum the straight cat holds its attitude
    assert!((tr.frames.last().unwrap().t - (manoeuvre + margin)).abs() < 1e-12);
    assert!(after.len() >= 2);
    let held = f.last().unwrap();
    for fr in &after {
        assert_eq!((fr.a, fr.b), (held.a, held.b), "t {}", fr.t);
        assert!((fr.flip_deg - held.flip_deg).abs() < 1e-9, "t {}", fr.t);
        assert!(fr.tau_nm < 1e-6 && fr.bend_deg < 1e-6, "t {}: {fr:?}", fr.t);
    }
    let f = &f;
    let uq = |q: [f64; 4]| UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let mut largest = 0.0f64;
    for fr in f {
        let (a, b) = (uq(fr.a), uq(fr.b));
        let (za, zb) = (a * Vector3::z(), b * Vector3::z());
        let spines = za.cross(&zb).norm().atan2(za.dot(&zb));
        // the page stores quaternions to 1e-7
        assert!(
            (spines.to_degrees() - fr.bend_deg).abs() < 1e-4,
            "t {}: spines {} deg, bend {} deg",
            fr.t,
            spines.to_degrees(),
            fr.bend_deg
        );
        largest = largest.max(fr.bend_deg);
    }
    assert!(
        (largest - 135.0).abs() < 1.0,
        "the seed bends 135 deg: {largest}"
    );
    let end = f.last().unwrap();
    assert!(uq(end.a).angle_to(&uq(end.b)) < 1e-6);
    // the embedded flip is the simulation's, whatever its sign convention
    let last = sim.trace.last().unwrap();
    assert_eq!(end.flip_deg, last.flip.to_degrees());
}

/// From a start with momentum the straight cat turns on during the margin:
/// the track's last frame is the touchdown whose belly angle the
/// simulation reports as its landing error.
#[test]
fn the_animation_ends_at_touchdown_on_the_landing() {
    use catflip::report::animation::{FRAMES, track};
    use nalgebra::{Quaternion, UnitQuaternion};
    let cfg = catflip::Config::load(
        &configs().join("seed.toml"),
        &[
            "start.angular_velocity=[0.3, 0.2, 0.5]".into(),
            "fall.margin=0.15".into(),
        ],
    )
    .unwrap();
    let spec = cfg.design_spec();
    let plan = catflip::design::analytic::analytic_plan(&spec);
    let sim = catflip::verify::simulate::dynamic_spec(&spec, &plan).unwrap();
    let tr = track(
        &cfg.cat(),
        cfg.norm(),
        "analytic",
        &sim,
        (FRAMES, cfg.fall.margin),
    );
    let manoeuvre = sim.trace.last().unwrap().t;
    let end = tr.frames.last().unwrap();
    assert!(
        (end.t - cfg.fall_time()).abs() < 1e-9,
        "{} against {}",
        end.t,
        cfg.fall_time()
    );
    let q = end.a;
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let belly =
        catflip::model::momentum::landing_error(r.to_rotation_matrix().matrix()).to_degrees();
    // the page stores quaternions to 1e-7
    assert!(
        (belly - sim.landing_error_deg).abs() < 1e-4,
        "{belly} against {}",
        sim.landing_error_deg
    );
    // and it moved over the margin
    let at_end = tr.frames.iter().rev().find(|f| f.t <= manoeuvre).unwrap();
    assert!(
        at_end.a != end.a && (end.flip_deg - at_end.flip_deg).abs() > 0.1,
        "{} {}",
        at_end.flip_deg,
        end.flip_deg
    );
}
