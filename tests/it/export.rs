//! Simulator exports: the model files carry the model, and the controls are
//! the schedule in the simulator's coordinates. The engines themselves
//! (MuJoCo, pyBullet) check the replays in `.ci/run` (examples/replay_*.py).

use crate::util;

use catflip::export::controls::{Controls, Simulator, time_step};
use catflip::model::Joint;
use util::{config, configs, run_ok, temp_dir};

fn num(s: &str) -> f64 {
    s.parse()
        .unwrap_or_else(|_| panic!("`{s}` is not a number"))
}

fn close(s: &str, want: f64) -> bool {
    (num(s) - want).abs() <= 1e-12 * want.abs().max(1e-300)
}

/// Header keys and numeric rows of a controls CSV.
fn read_controls(
    text: &str,
) -> (
    std::collections::HashMap<String, String>,
    Vec<String>,
    Vec<Vec<f64>>,
) {
    let mut meta = std::collections::HashMap::new();
    let mut cols = Vec::new();
    let mut rows = Vec::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix('#') {
            if let Some((k, v)) = rest.split_once(" = ") {
                meta.insert(k.trim().to_string(), v.trim().to_string());
            }
        } else if cols.is_empty() {
            cols = line.split(',').map(String::from).collect();
        } else {
            rows.push(line.split(',').map(num).collect());
        }
    }
    (meta, cols, rows)
}

#[test]
fn models_carry_the_masses_inertias_limits_and_actuators() {
    let unequal = [
        "cat.front.mass=0.4",
        "cat.front.length=0.15",
        "cat.front.radius=0.02",
    ];
    for (name, set) in [
        ("seed", &[][..]),
        ("robot-universal", &[][..]),
        ("robot-universal", &unequal[..]),
        ("seed", &unequal[..2]),
        (
            "seed",
            &["limits.max_torque=2.5", "cat.joint=universal"][..],
        ),
        // a torque-speed line on the no-twist joint's ball
        (
            "seed",
            &["limits.max_torque=2.5", "limits.no_load_speed=8"][..],
        ),
    ] {
        let cfg = config(name, set);
        let cat = cfg.cat();
        let half = |link: &str| match link {
            "rear" => cat.rear,
            "front" => cat.front,
            other => panic!("unexpected link {other}"),
        };
        let limit = cfg.limits.max_torque;
        // URDF effort: the stall torque, or with a torque-speed line the most
        // the envelope allows (braking at the speed limit)
        let speed = cfg.limits.max_speed.or(cfg.limits.no_load_speed);
        let effort = limit.map(|t| t + cfg.motor().slope() * speed.unwrap_or(0.0));
        let torque_line = cfg.limits.no_load_speed.is_some();

        let urdf = catflip::export::urdf(&cfg);
        assert!(urdf.contains("URDF_USE_INERTIA_FROM_FILE"));
        let doc = roxmltree::Document::parse(&urdf).unwrap();
        for link in doc.descendants().filter(|n| n.has_tag_name("link")) {
            let lname = link.attribute("name").unwrap();
            let mass = link
                .descendants()
                .find(|n| n.has_tag_name("mass"))
                .unwrap_or_else(|| panic!("{name}: link {lname} has no mass"));
            let inertia = link
                .descendants()
                .find(|n| n.has_tag_name("inertia"))
                .unwrap();
            if lname == "cross" {
                // massive (simulators need it) but negligible
                let m = num(mass.attribute("value").unwrap());
                assert!(m > 0.0 && m < 1e-6 * cat.rear.mass, "{m}");
                let i = num(inertia.attribute("ixx").unwrap());
                assert!(i > 1e-15 && i < 1e-6 * cat.rear.i_a(), "{i}");
            } else {
                let h = half(lname);
                assert!(close(mass.attribute("value").unwrap(), h.mass));
                assert!(close(inertia.attribute("ixx").unwrap(), h.i_t()));
                assert!(close(inertia.attribute("iyy").unwrap(), h.i_t()));
                assert!(close(inertia.attribute("izz").unwrap(), h.i_a()));
                let cyl = link
                    .descendants()
                    .find(|n| n.has_tag_name("cylinder"))
                    .unwrap();
                assert!(close(cyl.attribute("length").unwrap(), h.length));
                assert!(close(cyl.attribute("radius").unwrap(), h.radius));
            }
        }
        let joints: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("joint"))
            .collect();
        match cat.joint {
            Joint::Universal => {
                assert_eq!(joints.len(), 2);
                for j in &joints {
                    assert_eq!(j.attribute("type"), Some("revolute"));
                    let lim = j.children().find(|n| n.has_tag_name("limit")).unwrap();
                    assert!(close(lim.attribute("effort").unwrap(), effort.unwrap()));
                }
            }
            Joint::NoTwist => {
                assert!(joints.len() == 1 && joints[0].attribute("type") == Some("spherical"))
            }
        }

        let mjcf = catflip::export::mjcf(&cfg);
        let doc = roxmltree::Document::parse(&mjcf).unwrap();
        let bodies: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("body"))
            .collect();
        assert_eq!(bodies.len(), 2);
        for b in bodies {
            let h = half(b.attribute("name").unwrap());
            let n = b.children().find(|n| n.has_tag_name("inertial")).unwrap();
            assert!(close(n.attribute("mass").unwrap(), h.mass));
            let d: Vec<&str> = n.attribute("diaginertia").unwrap().split(' ').collect();
            assert!(close(d[0], h.i_t()) && close(d[1], h.i_t()) && close(d[2], h.i_a()));
            // centre of mass l/2 along the half's own axis (the rear's at its origin)
            let z = n
                .attribute("pos")
                .unwrap()
                .split(' ')
                .nth(2)
                .map(num)
                .unwrap();
            let want = if b.attribute("name") == Some("rear") {
                0.0
            } else {
                h.length / 2.0
            };
            assert!((z - want).abs() < 1e-12);
        }
        // the joint sits at the rear's end face
        let front = doc
            .descendants()
            .find(|n| n.attribute("name") == Some("front"))
            .unwrap();
        let jz = front
            .attribute("pos")
            .unwrap()
            .split(' ')
            .nth(2)
            .map(num)
            .unwrap();
        assert!((jz - cat.rear.length / 2.0).abs() < 1e-12);
        // the model's step is the controls' step
        let opt = doc
            .descendants()
            .find(|n| n.has_tag_name("option"))
            .unwrap();
        let (dt, _) = time_step(cfg.available_time(), Simulator::Mujoco.target_step());
        assert!(close(opt.attribute("timestep").unwrap(), dt));
        // a universal joint with a torque-speed line has DC motors (`general`)
        let dc = torque_line && cat.joint == Joint::Universal;
        let motors: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name(if dc { "general" } else { "motor" }))
            .collect();
        match cat.joint {
            // a ball has three degrees of freedom: one motor about each child axis
            Joint::NoTwist => {
                let gears: Vec<_> = motors
                    .iter()
                    .map(|m| m.attribute("gear").unwrap())
                    .collect();
                assert_eq!(gears, ["1 0 0", "0 1 0", "0 0 1"]);
            }
            Joint::Universal => assert_eq!(motors.len(), 2),
        }
        if dc {
            // force = gain ctrl + biasprm . (0, length, velocity) = ctrl - k qd, the
            // command limited to the stall torque: |tau + k qd| <= T
            let (t, k) = (limit.unwrap(), cfg.motor().slope());
            for m in &motors {
                assert_eq!(m.attribute("biastype"), Some("affine"));
                let b: Vec<&str> = m.attribute("biasprm").unwrap().split(' ').collect();
                assert!(close(b[0], 0.0) && close(b[1], 0.0) && close(b[2], -k));
                assert!(close(m.attribute("gainprm").unwrap(), 1.0));
                let r: Vec<&str> = m.attribute("ctrlrange").unwrap().split(' ').collect();
                assert!(close(r[0], -t) && close(r[1], t));
                // braking beyond T is allowed: no force range
                assert!(m.attribute("forcerange").is_none());
            }
        } else if torque_line {
            // a ball's disc is not a box on its motors: no clipping range,
            // the header says so and the replays clip to the envelope
            assert!(motors.iter().all(|m| m.attribute("ctrlrange").is_none()));
            assert!(mjcf.contains("torque-speed"));
        }
        for m in motors.iter().filter(|_| !torque_line) {
            match limit {
                Some(l) => {
                    let r: Vec<&str> = m.attribute("ctrlrange").unwrap().split(' ').collect();
                    assert!(close(r[0], -l) && close(r[1], l));
                    assert_eq!(m.attribute("ctrllimited"), Some("true"));
                    assert!(m.attribute("forcerange").is_some());
                }
                None => assert!(m.attribute("ctrlrange").is_none()),
            }
        }
    }
}

/// The held torques carry the schedule's impulse exactly: the schedule's
/// torque is linear between rows, so its integral is the trapezoid rule.
#[test]
fn held_torques_carry_the_schedules_impulse() {
    let dir = temp_dir();
    let cfg_path = configs().join("robot-universal.toml");
    let c = cfg_path.to_str().unwrap();
    let (ok, _, err) = run_ok(&["analyze", c], dir.path());
    assert!(ok, "{err}");
    let sched = dir
        .path()
        .join("output/robot-universal/analyze/analytic.csv");
    let base = dir.path().join("output/robot-universal/export-mjcf");
    let (ok, out, err) = run_ok(
        &["export", "mjcf", c, "--schedule", sched.to_str().unwrap()],
        dir.path(),
    );
    assert!(ok, "{err}");
    assert!(out.contains("analytic.mujoco.csv"), "{out}");
    let written = std::fs::read_to_string(base.join("analytic.mujoco.csv")).unwrap();
    // its schedule JSON names the same files, with the same controls
    let json = sched.with_file_name("analytic.schedule.json");
    let (ok, out, err) = run_ok(
        &[
            "export",
            "mjcf",
            c,
            "--schedule",
            json.to_str().unwrap(),
            "--out",
            "json",
        ],
        dir.path(),
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("analytic.mujoco.csv") && !out.contains("analytic.schedule."),
        "{out}"
    );
    // (the same rows: the JSON's numbers carry more digits than the CSV's)
    let again = std::fs::read_to_string(
        dir.path()
            .join("json/robot-universal/export-mjcf/analytic.mujoco.csv"),
    )
    .unwrap();
    assert_eq!(again.lines().count(), written.lines().count());
    let (meta, cols, rows) =
        read_controls(&std::fs::read_to_string(base.join("analytic.mujoco.csv")).unwrap());
    let dt = num(&meta["dt_s"]);
    let steps: usize = meta["steps"].parse().unwrap();
    assert_eq!(rows.len(), steps + 1);
    assert!(steps >= catflip::export::controls::MIN_STEPS);
    let s = catflip::design::plan::Schedule::from_csv(
        &std::fs::read_to_string(&sched).unwrap(),
        "analytic.csv",
    )
    .unwrap();
    let duration = s.rows.last().unwrap().t - s.rows[0].t;
    assert!((dt * steps as f64 - duration).abs() < 1e-12);
    // the robot's servo has a torque-speed line: the MJCF's DC motors take the
    // command tau + k qd, whose held impulse is the torque's plus k times the
    // angle travelled
    let k = num(&meta["motor_slope_nm_s"]);
    assert!(k > 0.0);
    let i1 = cols.iter().position(|c| c == "ctrl_cmd1").unwrap();
    let iq = cols.iter().position(|c| c == "qpos_motor1").unwrap();
    for j in 0..2 {
        let travel = rows[steps][iq + j] - rows[0][iq + j];
        let held: f64 = rows[..steps].iter().map(|r| r[i1 + j] * dt).sum::<f64>() - k * travel;
        let exact: f64 = s
            .rows
            .windows(2)
            .map(|w| 0.5 * (w[0].tau[j] + w[1].tau[j]) * (w[1].t - w[0].t))
            .sum();
        assert!(
            (held - exact).abs()
                < 1e-12 * s.rows.iter().map(|r| r.tau[j].abs()).fold(0.0, f64::max),
            "motor {j}: {held} vs {exact}"
        );
    }
    // positions are the schedule's at each step start
    let mid = rows[steps / 3][0];
    let want = catflip::design::plan::ShapePlan::state(&s, mid).q;
    assert!((rows[steps / 3][iq] - want[0]).abs() < 1e-12);
}

/// A peak design's torque steps at its nodes (`free.torque_jumps`) survive
/// its written schedule: each is two rows of one instant, so the controls
/// exported from `free.schedule.json` are `run`'s own (made from the plan)
/// to 1e-3 N m, and the schedule replayed peaks at the design's peak. Before,
/// the rows held one side of a step and the linear torque between rows
/// smeared it: 3.5e-2 N m apart at a step, against a 0.40 N m peak.
#[test]
fn a_written_schedule_keeps_the_torque_steps_at_the_nodes() {
    let dir = temp_dir();
    let seed = configs().join("seed.toml");
    let c = seed.to_str().unwrap();
    let (ok, _, err) = run_ok(&["run", c], dir.path());
    assert!(ok, "{err}");
    let set = dir.path().join("output/seed/run");
    let sched = catflip::design::plan::Schedule::from_csv(
        &std::fs::read_to_string(set.join("free.csv")).unwrap(),
        "free.csv",
    )
    .unwrap();
    let steps = sched
        .rows
        .windows(2)
        .filter(|w| w[0].t == w[1].t && w[0].phase == w[1].phase)
        .filter(|w| (w[0].tau[0] - w[1].tau[0]).abs() > 1e-3)
        .count();
    assert!(steps > 20, "{steps} torque steps in the rows");
    let json = set.join("free.schedule.json");
    let (ok, _, err) = run_ok(
        &["export", "mjcf", c, "--schedule", json.to_str().unwrap()],
        dir.path(),
    );
    assert!(ok, "{err}");
    let (_, cols, own) =
        read_controls(&std::fs::read_to_string(set.join("free.mujoco.csv")).unwrap());
    let (_, _, read) = read_controls(
        &std::fs::read_to_string(dir.path().join("output/seed/export-mjcf/free.mujoco.csv"))
            .unwrap(),
    );
    assert_eq!(own.len(), read.len());
    let torque: Vec<usize> = (0..cols.len())
        .filter(|&j| cols[j].starts_with("ctrl"))
        .collect();
    let worst = own
        .iter()
        .zip(&read)
        .flat_map(|(a, b)| torque.iter().map(move |&j| (a[j] - b[j]).abs()))
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-3,
        "controls from the schedule {worst} N m from run's"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(set.join("summary.json")).unwrap()).unwrap();
    let peak = util::method_line(&summary, "free")["peak_torque_nm"]
        .as_f64()
        .unwrap();
    let written = sched.peak(catflip::model::TorqueNorm::Euclidean);
    assert!(
        (written / peak - 1.0).abs() < 1e-4,
        "{written} against {peak}"
    );
}

/// Where a regular sample falls on a node where the torque steps (here
/// every fifth sample: 200 a phase over 40 intervals) the step's two rows
/// take its place: the written schedule reads back and flies. Before, the
/// sample and the step, a rounding apart, printed as one instant three
/// times, and `simulate --schedule` refused catflip's own file.
#[test]
fn a_schedule_whose_samples_fall_on_its_steps_reads_back() {
    let dir = temp_dir();
    let seed = configs().join("seed.toml");
    let c = seed.to_str().unwrap();
    let nodes = "free.nodes=41";
    let (ok, _, err) = run_ok(&["run", c, "--set", nodes], dir.path());
    assert!(ok, "{err}");
    let csv = dir.path().join(format!("output/seed/run@{nodes}/free.csv"));
    let (ok, out, err) = run_ok(
        &[
            "simulate",
            c,
            "--set",
            nodes,
            "--schedule",
            csv.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(ok, "{out}{err}");
}

/// Ball joint: positions are unit quaternions and the velocity column is the
/// relative rate in the child frame, `2 Im(conj(q_k) q_k+1) / dt` between rows;
/// pyBullet's file holds the same numbers with the quaternion as x y z w.
#[test]
fn ball_controls_are_quaternions_and_child_frame_rates() {
    let cfg = config("seed", &[]);
    let plan = catflip::design::analytic::analytic_plan(&cfg.design_spec());
    let mj = Controls::sample(&cfg, &plan, Simulator::Mujoco);
    let n = mj.rows.len();
    let mut worst: f64 = 0.0;
    for k in (0..n - 1).step_by(7) {
        let (a, b) = (&mj.rows[k].pos, &mj.rows[k + 1].pos);
        let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-14);
        // conj(a) * b, imaginary part
        let im = [
            a[0] * b[1] - a[1] * b[0] - a[2] * b[3] + a[3] * b[2],
            a[0] * b[2] + a[1] * b[3] - a[2] * b[0] - a[3] * b[1],
            a[0] * b[3] - a[1] * b[2] + a[2] * b[1] - a[3] * b[0],
        ];
        for i in 0..3 {
            let fd = 2.0 * im[i] / mj.dt;
            let mean = 0.5 * (mj.rows[k].vel[i] + mj.rows[k + 1].vel[i]);
            worst = worst.max((fd - mean).abs());
        }
    }
    let scale = mj
        .rows
        .iter()
        .flat_map(|r| r.vel.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(worst < 1e-4 * scale, "{worst} vs {scale}");
    // the ball's twist rate is not zero: the third motor is needed
    assert!(mj.rows.iter().any(|r| r.vel[2].abs() > 1e-3 * scale));
    assert!(mj.rows.iter().any(|r| r.torque[2].abs() > 1e-3));

    let pb = Controls::sample(&cfg, &plan, Simulator::Pybullet);
    let (k, r) = (n / 2, &pb.rows[pb.rows.len() / 2]);
    if (pb.dt - mj.dt).abs() < 1e-15 {
        assert_eq!(
            r.pos,
            [
                mj.rows[k].pos[1],
                mj.rows[k].pos[2],
                mj.rows[k].pos[3],
                mj.rows[k].pos[0]
            ]
        );
    }
    let norm = r.pos.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() < 1e-14 && r.pos[3] > 0.0);
}

#[test]
fn export_with_a_bad_schedule_fails_and_writes_nothing() {
    let dir = temp_dir();
    let bad = dir.path().join("broken.csv");
    std::fs::write(&bad, "t_s,phase,q1_rad\n0,fold,0\n").unwrap();
    let cfg = configs().join("seed.toml");
    for sched in [bad.to_str().unwrap(), "missing.csv"] {
        let (ok, _, err) = run_ok(
            &["export", "mjcf", cfg.to_str().unwrap(), "--schedule", sched],
            dir.path(),
        );
        assert!(!ok, "{sched} should fail");
        assert!(
            err.contains("broken.csv") || err.contains("missing.csv"),
            "{err}"
        );
        assert!(
            !dir.path().join("output").exists(),
            "{sched}: wrote something"
        );
    }
}

/// Gains along a schedule read back from its rows are about the nominal
/// held on the planned shape: the rows smooth the design's torque between
/// them, so the feed-forward alone drifts from the plan (the seed's design
/// from 200 rows a phase lands 0.04 deg off that way; over a tenth before
/// the rows kept the torque's steps at the nodes), but
/// the held nominal lands where the open loop's PD on the planned shape
/// does, from 200 rows a phase as from 2000; the header says the nominal is
/// held.
#[test]
fn gains_along_a_read_back_schedule_hold_the_planned_shape() {
    use catflip::control::plant::attitude;
    use catflip::control::reference::Reference;
    use catflip::design::free::{FreeDesign, Seed};
    use catflip::design::plan::Schedule;
    use catflip::model::momentum::landing_error;
    let cfg = util::seed(&[]);
    let spec = cfg.design_spec();
    let fr = FreeDesign::new(&spec).seed(Seed::Analytic).solve().unwrap();
    for rows in [200, 2000] {
        let s = Schedule::sample(&spec.cat, &fr.plan, rows);
        let mut out = catflip::output::Output::default();
        catflip::export::add_schedule_files(&cfg, &mut out, &s, "free", Simulator::Mujoco).unwrap();
        let (_, gains) = out.files().find(|f| f.0 == "free.tvlqr.csv").unwrap();
        let gains = std::str::from_utf8(gains).unwrap();
        let key = |k: &str| {
            let line = gains
                .lines()
                .find(|l| l.starts_with(&format!("# {k} = ")))
                .unwrap();
            num(line.rsplit(' ').next().unwrap())
        };
        let (tv, open) = (
            key("nominal_landing_error_deg_tvlqr"),
            key("nominal_landing_error_deg_open_loop"),
        );
        assert_eq!(key("nominal_held"), 1.0);
        assert!(
            tv < 0.01 && (tv - open).abs() < 1e-3,
            "{rows} rows: TVLQR {tv} deg, open loop {open} deg"
        );
        if rows == 200 {
            let unheld = Reference::unheld(&cfg, &s);
            let last = unheld.nominal.last().unwrap();
            let drift = landing_error(attitude(last).to_rotation_matrix().matrix()).to_degrees();
            assert!(drift > 0.01 && drift > 10.0 * tv, "{drift} against {tv}");
        }
    }
}
