//! The closed loop of issue 27: TVLQR along a design.

use catflip::Config;
use catflip::control::closed_loop::{Feedback, Flight, fly};
use catflip::control::plant::{X, error};
use catflip::control::reference::{Reference, release};
use catflip::control::tvlqr::{Tvlqr, linearise, period_map};
use catflip::model::momentum::Start;
use nalgebra::SMatrix;
use std::sync::OnceLock;

fn seed_cfg() -> Config {
    crate::util::seed(&[])
}

/// The seed's free-form design and its gains, made once for all tests.
fn design() -> &'static (Config, Reference, Tvlqr) {
    static D: OnceLock<(Config, Reference, Tvlqr)> = OnceLock::new();
    D.get_or_init(|| {
        let cfg = seed_cfg();
        let plan = catflip::control::robustness::design(&cfg).unwrap().plan;
        let r = Reference::new(&cfg, &plan);
        let tv = Tvlqr::new(&r, &cfg.control);
        (cfg, r, tv)
    })
}

/// The belly's tilt rows at touchdown (world y and z of the belly's move).
fn tilt(r: &Reference, x: &X) -> [f64; 2] {
    let rm = *catflip::control::plant::attitude(&r.nominal[r.steps])
        .to_rotation_matrix()
        .matrix();
    let d = -rm * catflip::model::so3::hat(&nalgebra::Vector3::x()) * x.fixed_rows::<3>(0);
    [d.y, d.z]
}

#[test]
fn tvlqr_on_the_nominal_model_reproduces_the_design() {
    let (cfg, r, tv) = design();
    let motor = cfg.motor();
    let open = fly(
        r,
        Feedback::JointPd { kp: 0.0, kd: 0.0 },
        &motor,
        Flight::nominal(r),
    );
    let closed = fly(r, Feedback::Tvlqr(tv), &motor, Flight::nominal(r));
    assert!(
        closed.max_correction_nm < 1e-9 * r.peak_torque,
        "correction {} N m on the nominal",
        closed.max_correction_nm
    );
    assert!((closed.error_deg - open.error_deg).abs() < 1e-9);
    // and the design lands: the nominal is belly-down
    assert!(
        open.error_deg < 0.05,
        "nominal lands {} deg off",
        open.error_deg
    );
}

#[test]
fn the_period_map_linearisation_is_its_derivative() {
    let (_, r, tv) = design();
    let k = tv.starts.len() / 2;
    let (a, b) = (tv.starts[k], tv.starts[k + 1]);
    let (am, bm) = linearise(r, a, b, &tv.scale, tv.torque_scale);
    let dir = X::from_fn(|i, _| tv.scale[i] * (0.3 + 0.1 * i as f64));
    let u = [0.2 * tv.torque_scale, -0.1 * tv.torque_scale];
    let rem = |e: f64| {
        let x = dir * e;
        let got = period_map(r, a, b, &x, [u[0] * e, u[1] * e]);
        let lin = am * x + bm * nalgebra::Vector2::new(u[0] * e, u[1] * e);
        (got - lin).norm()
    };
    // the remainder is second order: halving the step quarters it
    let (r1, r2) = (rem(1e-3), rem(5e-4));
    assert!(
        r1 > 0.0 && (r1 / r2 - 4.0).abs() < 0.4,
        "remainders {r1:e} {r2:e}"
    );
}

/// The cost-to-go is a Lyapunov function of the closed-loop linearisation:
/// `P_k - Acl' P_{k+1} Acl = Q_k + K' R K >= 0`, every period; with the
/// gain's sign flipped or the gain transposed onto the wrong state it is not.
#[test]
fn the_closed_loop_linearisation_is_stable_along_the_design() {
    let (_, r, tv) = design();
    let min_eig = |m: &SMatrix<f64, 10, 10>| {
        m.symmetric_eigen()
            .eigenvalues
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    };
    let (mut worst_ok, mut worst_flipped) = (f64::INFINITY, f64::INFINITY);
    for k in 0..tv.starts.len() {
        let (p, pn) = (&tv.cost_to_go[k], &tv.cost_to_go[k + 1]);
        let decrease = |acl: &SMatrix<f64, 10, 10>| {
            let d = p - acl.transpose() * pn * acl;
            min_eig(&(0.5 * (d + d.transpose()))) / p.norm().max(1e-300)
        };
        worst_ok = worst_ok.min(decrease(&tv.closed_loop(k)));
        let flipped = tv.a[k] + tv.b[k] * tv.gains[k];
        worst_flipped = worst_flipped.min(decrease(&flipped));
    }
    assert!(worst_ok > -1e-9, "cost-to-go grows: {worst_ok:e}");
    assert!(
        worst_flipped < -1e-6,
        "a flipped gain passed: {worst_flipped:e}"
    );
    // the landing's sensitivity to a start error: far smaller closed loop
    let n = tv.starts.len();
    let (mut phi_cl, mut phi_ol) = (SMatrix::<f64, 10, 10>::identity(), SMatrix::identity());
    for k in 0..n {
        phi_cl = tv.closed_loop(k) * phi_cl;
        phi_ol = tv.a[k] * phi_ol;
    }
    let landing = |phi: &SMatrix<f64, 10, 10>| {
        (0..10)
            .map(|i| {
                let x = phi.column(i).into_owned() * tv.scale[i];
                let t = tilt(r, &x);
                t[0].hypot(t[1])
            })
            .fold(0.0, f64::max)
    };
    let (cl, ol) = (landing(&phi_cl), landing(&phi_ol));
    eprintln!("largest landing tilt per scaled start error: closed {cl:.3e}, open {ol:.3e}");
    assert!(cl < 0.1 * ol, "closed {cl} vs open {ol}");
}

/// A small start error (spin end over end, tilt of the spine; the heading,
/// rotation about world x, is free) shrinks in the nonlinear closed loop by
/// the factor the linearisation predicts: the landing tilt closed loop over
/// open loop, simulated against `C Phi_cl x0 / C Phi_ol x0`.
#[test]
fn a_small_start_error_shrinks_as_the_linearisation_predicts() {
    let (cfg, r, tv) = design();
    let motor = cfg.motor();
    for (rot, w) in [
        ([0.0; 3], [0.0, 0.02, 0.0]),
        ([0.0; 3], [0.0, 0.01, 0.0]),
        ([0.0, 0.02, 0.0], [0.0; 3]),
        ([0.0, 0.0, 0.02], [0.0; 3]),
    ] {
        let y0 = release(&r.cat, &Start::new(rot, w));
        let mut f = Flight::nominal(r);
        f.release = y0;
        f.delay_steps = tv.delay_steps;
        let closed = fly(r, Feedback::Tvlqr(tv), &motor, f.clone());
        let open = fly(r, Feedback::JointPd { kp: 0.0, kd: 0.0 }, &motor, f);
        let (xc, xo) = (
            error(&closed.state, &r.nominal[r.steps]),
            error(&open.state, &r.nominal[r.steps]),
        );
        // linear prediction: open loop over the delay, then the closed loop
        let x0 = error(&y0, &r.nominal[0]);
        let (a0, _) = linearise(r, 0, tv.starts[0], &tv.scale, tv.torque_scale);
        let mut xl = a0 * x0;
        let mut xlo = xl;
        for k in 0..tv.starts.len() {
            xl = tv.closed_loop(k) * xl;
            xlo = tv.a[k] * xlo;
        }
        let norm = |t: [f64; 2]| t[0].hypot(t[1]);
        let (sim, lin) = (
            norm(tilt(r, &xc)) / norm(tilt(r, &xo)),
            norm(tilt(r, &xl)) / norm(tilt(r, &xlo)),
        );
        eprintln!(
            "start {rot:?} {w:?}: landing tilt open {:.4e} closed {:.4e} rad; shrink simulated {sim:.4}, predicted {lin:.4}",
            norm(tilt(r, &xo)),
            norm(tilt(r, &xc))
        );
        assert!(sim < 0.1, "no shrink: {sim}");
        assert!(
            (sim - lin).abs() < 0.05 * lin + 1e-3,
            "simulated {sim} vs predicted {lin}"
        );
    }
}

/// The study is deterministic for a seed, the same on any number of
/// threads, and its shards' CSVs concatenate into the whole study's.
#[test]
fn the_study_is_deterministic_and_its_shards_concatenate() {
    use catflip::control::robustness::{Study, shard_range, to_csv};
    // the replanning controller replans every 10th period here, to keep the test short
    let mut cfg = design().0.clone();
    cfg.control.replan_every = 10;
    let cfg = &cfg;
    let plan: catflip::control::replanning::SharedPlan =
        std::sync::Arc::new(catflip::control::robustness::design(cfg).unwrap().plan);
    let study = Study::new(cfg, plan.clone(), 7).unwrap();
    let n = 6;
    let whole = to_csv(&study.run(0..n, 2, |_, _| {}), true);
    let again = to_csv(&study.run(0..n, 1, |_, _| {}), true);
    assert_eq!(whole, again);
    let shards: String = (1..=4)
        .map(|k| {
            let range = shard_range(n, k, 4);
            to_csv(&study.run(range, 1, |_, _| {}), k == 1)
        })
        .collect();
    assert_eq!(whole, shards);
    // another seed draws other trials
    let other = Study::new(cfg, plan, 8).unwrap();
    assert_ne!(whole, to_csv(&other.run(0..n, 2, |_, _| {}), true));
}

/// A shard that holds no trials says so, and rates nothing (it printed NaN);
/// with more shards than trials the CSVs still concatenate into the whole
/// study's, the header in the first shard's alone (every shard whose
/// trials started at 0 wrote one).
#[test]
fn an_empty_shard_warns_and_rates_nothing() {
    let dir = crate::util::temp_dir();
    let seed = crate::util::config_arg("seed");
    let study = |shard: &[&str]| {
        let mut argv = vec!["robustness", &seed, "--trials", "2", "--out", "."];
        argv.extend(shard);
        let out = crate::util::output(&argv, dir.path());
        assert_eq!(out.status.code(), Some(0), "{}", crate::util::stderr(&out));
        out
    };
    study(&[]);
    let csv = |set: &str| {
        std::fs::read_to_string(dir.path().join(format!("seed/{set}/{set}.csv"))).unwrap()
    };
    let joined: String = (2..=3)
        .map(|k| {
            study(&["--shard", &format!("{k}/3")]);
            csv(&format!("robustness.shard-{k}-of-3"))
        })
        .collect();
    let out = study(&["--shard", "1/3"]);
    let first = csv("robustness.shard-1-of-3");
    assert_eq!(first.lines().count(), 1, "the header alone: {first}");
    assert_eq!(first + &joined, csv("robustness"));
    let (stdout, err) = crate::util::text(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("warning: shard 1/3 holds no trials: the study has 2 trials"),
        "{err}"
    );
    assert!(
        stdout.contains("no trials in this shard") && !stdout.contains("NaN"),
        "{stdout}"
    );
}

/// Bad input is refused with the key, the value and the range or why;
/// nothing is written.
#[test]
fn bad_input_is_refused_before_anything_is_written() {
    let dir = crate::util::temp_dir();
    let seed = crate::util::config_arg("seed");
    for (args, key, says) in [
        (
            vec!["--set", "control.delay_ms=-1"],
            "control.delay_ms",
            "must be in",
        ),
        (
            vec!["--set", "robustness.delay_ms=-5"],
            "robustness.delay_ms",
            "must be in",
        ),
        (
            vec!["--set", "control.delay_ms=1001"],
            "must be in [0, 1000] ms",
            "is invalid",
        ),
        // applied in whole 0.25 ms steps: it was no delay at all, reported as 0.1 ms
        (
            vec!["--set", "robustness.delay_ms=0.1"],
            "robustness.delay_ms",
            "this one would be no delay at all; use 0 or 0.25 ms",
        ),
        (
            vec!["--set", "control.delay_ms=0.1"],
            "control.delay_ms",
            "whole simulator steps of 0.25 ms",
        ),
        (
            vec!["--set", "control.rate_hz=5000"],
            "control.rate_hz",
            "must be in",
        ),
        (
            vec!["--set", "control.rate_hz=0"],
            "control.rate_hz",
            "at least one correction a second",
        ),
        // a period of 4/3 simulator steps would run every step, at 4 kHz
        (
            vec!["--set", "control.rate_hz=3000"],
            "control.rate_hz",
            "would run at 4000 Hz; use a rate that divides the simulator's evenly, e.g. 2000 or 4000 Hz",
        ),
        // the rates it suggests as a person would type them
        (
            vec!["--set", "control.rate_hz=1500"],
            "control.rate_hz",
            "would run at 1333.333 Hz; use a rate that divides the simulator's evenly, e.g. 1333.333 or 2000 Hz",
        ),
        (
            vec!["--set", "robustness.mass_error=1.0"],
            "robustness.mass_error",
            "makes a half massless",
        ),
        (
            vec!["--set", "robustness.length_error=-1"],
            "robustness.length_error",
            "its sign is drawn at random",
        ),
        (vec!["--trials", "1000001"], "--trials", "must be in"),
        (
            vec!["--seed", "-1"],
            "--seed",
            "must be a whole number from 0",
        ),
        // a step the key admits, too coarse for the PD that holds the
        // nominal: it flew to NaN, and every trial with it
        (
            vec![
                "--set",
                "control.sim_rate_hz=100",
                "--set",
                "control.delay_ms=10",
                "--set",
                "robustness.delay_ms=10",
            ],
            "control.sim_rate_hz",
            "nominal flight diverges at this step",
        ),
    ] {
        let mut argv = vec!["robustness", &seed, "--out", "."];
        argv.extend(&args);
        let out = crate::util::output(&argv, dir.path());
        let err = crate::util::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(key), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(
            !err.contains("1001") || !err.contains("never negative"),
            "{err}"
        );
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "{args:?} wrote files"
        );
    }
    // a rate within a few percent of whole steps is taken: 60 Hz runs every
    // 67 steps of the default 4 kHz, at 59.7 Hz
    let cfg = crate::util::seed(&["control.rate_hz=60"]);
    assert_eq!(cfg.control.rate_hz, 60.0);
    // a delay whole steps change by more than 5 % is taken, with a warning
    // naming what is applied; within 5 %, silently
    let slips = |sets: &[&str]| -> Vec<String> {
        crate::util::seed(sets)
            .slips()
            .iter()
            .map(|s| s.to_string())
            .filter(|s| s.contains("delay_ms"))
            .collect()
    };
    assert!(slips(&["control.delay_ms=4.9"]).is_empty());
    let w = slips(&["control.delay_ms=0.2"]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("control.delay_ms: applied in whole simulator steps of 0.25 ms")
            && w[0].contains("it is 0.25 ms"),
        "{w:?}"
    );
    // the exported gains too: no file of NaN gains (export exited 0 with one)
    let coarse = crate::util::seed(&[
        "control.sim_rate_hz=100",
        "control.delay_ms=10",
        "robustness.delay_ms=10",
    ]);
    let plan = catflip::design::analytic::analytic_plan(&coarse.design_spec());
    let e = catflip::control::export::gains_csv(&coarse, &plan).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("control.sim_rate_hz"),
        "{e}"
    );
    let fine = crate::util::seed(&["control.sim_rate_hz=2000"]);
    let gains = catflip::control::export::gains_csv(&fine, &plan).unwrap();
    assert!(!gains.contains("NaN"));
}

/// A design longer than the fall is refused before any flight, naming the
/// height it needs (its manoeuvre plus `fall.margin`, rounded up so that it
/// fits); the config it was made for takes it, and so does a higher drop.
#[test]
fn a_design_longer_than_the_fall_is_refused_with_the_height_it_needs() {
    use catflip::control::online::check_fits;
    let at = |h: f64| {
        crate::util::config(
            "robot-universal",
            &[&format!("fall.height={h}"), "design.objective=time"],
        )
    };
    let design = catflip::design::phased::optimize(&at(6.0).design_spec(), |_| {}).unwrap();
    let t: f64 = design.plan.durations.iter().sum();
    let e = check_fits(&at(2.0), &design.plan).unwrap_err();
    assert!(e.is_bad_input(), "{e}");
    let msg = e.to_string();
    let need = crate::util::number_after(&msg, "at least ");
    assert!(msg.contains(&format!("lasts {t:.4} s")), "{msg}");
    check_fits(&at(need), &design.plan).unwrap();
    check_fits(&at(6.0), &design.plan).unwrap();
    assert!(check_fits(&at(need - 0.01), &design.plan).is_err());
}

/// A controller that assumes another delay than the study's robot has is
/// said so on the console and the study's page, with both delays.
#[test]
fn the_page_says_when_the_controllers_assume_another_delay() {
    let dir = crate::util::temp_dir();
    let seed = crate::util::config_arg("seed");
    // the study, and a trial of it flown again, warn alike
    let study = [
        "robustness",
        &seed,
        "--trials",
        "1",
        "--set",
        "control.delay_ms=20",
    ];
    let warned = |args: &[&str]| {
        let (ok, out, err) = crate::util::run_ok(args, dir.path());
        assert!(ok, "{err}");
        assert!(
            err.contains("warning: the controllers predict over a delay of 20 ms (control.delay_ms) but the simulated robot's is 5 ms (robustness.delay_ms)"),
            "{err}"
        );
        out
    };
    warned(&[&study[..], &["--trial", "0"]].concat());
    let out = warned(&study);
    // the console names the design flown, as the page does
    assert!(
        out.contains(
            "the controllers fly the free-form peak-torque design seeded by the phased schedule"
        ),
        "{out}"
    );
    let page = std::fs::read_to_string(
        dir.path()
            .join("output/seed/robustness@control.delay_ms=20/index.html"),
    )
    .unwrap();
    assert!(
        page.contains("predict over a delay of 20 ms (control.delay_ms); the simulated robot's actuator delay is 5 ms (robustness.delay_ms): the controllers assume another delay than the robot has"),
        "{page}"
    );
}

/// `--replan-budget-ms` drops a replan over its wall time, as a robot's
/// controller would: with a budget no replan can meet (1 us), the replanning
/// controller flies its design's TVLQR, trial for trial to the bit; the page
/// and the state say so, `--resume` keeps to the budget, and a budget
/// outside (0, 1000] ms is refused.
#[test]
fn a_replan_budget_nothing_meets_leaves_the_tvlqr() {
    let dir = crate::util::temp_dir();
    let seed = crate::util::config_arg("seed");
    let study = [
        "robustness",
        &seed,
        "--trials",
        "2",
        "--threads",
        "1",
        "--replan-budget-ms",
        "0.001",
    ];
    let (ok, out, err) = crate::util::run_ok(&study, dir.path());
    assert!(ok, "{err}");
    assert!(
        out.contains("0 taken") && out.contains("dropped over their budget"),
        "{out}"
    );
    let set = dir.path().join("output/seed/robustness");
    let csv = std::fs::read_to_string(set.join("robustness.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (tv, rp) = (
        col("tvlqr_landing_error_deg"),
        col("replan_landing_error_deg"),
    );
    let mut rows = 0;
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells[tv], cells[rp], "{line}");
        rows += 1;
    }
    assert_eq!(rows, 2);
    let page = std::fs::read_to_string(set.join("index.html")).unwrap();
    assert!(
        page.contains(
            "A replan that took longer than 0.001 ms of wall time on this machine was dropped"
        ),
        "{page}"
    );
    let state = std::fs::read_to_string(set.join("robustness.state.json")).unwrap();
    assert!(state.contains("\"replan_budget_ms\": 0.001"), "{state}");
    // resumed without the budget: another study, refused
    let (ok, _, err) = crate::util::run_ok(&study[..6], dir.path());
    assert!(ok, "{err}");
    let (ok, _, err) = crate::util::run_ok(&[&study[..], &["--resume"]].concat(), dir.path());
    assert!(
        !ok && err.contains("--replan-budget-ms none (now 0.001)"),
        "{err}"
    );
    for bad in ["0", "-5", "1001", "nan"] {
        let out = crate::util::output(
            &[
                "robustness",
                &seed,
                "--replan-budget-ms",
                bad,
                "--out",
                "bad",
            ],
            dir.path(),
        );
        let err = crate::util::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("must be in (0, 1000] ms"), "{bad}: {err}");
        assert!(!dir.path().join("bad").exists(), "{bad}");
    }
}

/// `--trial K` flies trial K again under each controller: the landings
/// `robustness.csv` recorded for it, to the bit; each flight's logged
/// states start from the trial's release (belly 180 deg less its tilt from
/// straight down) and end at touchdown on the landing; a trial beyond
/// `--trials`, or with `--shard`, is refused before anything is written.
#[test]
fn a_replayed_trial_lands_as_the_study_recorded_it() {
    let dir = crate::util::temp_dir();
    let seed = crate::util::config_arg("seed");
    let study = [
        "robustness",
        &seed,
        "--trials",
        "3",
        "--seed",
        "7",
        "--threads",
        "1",
    ];
    let (ok, _, err) = crate::util::run_ok(&study, dir.path());
    assert!(ok, "{err}");
    let csv =
        std::fs::read_to_string(dir.path().join("output/seed/robustness/robustness.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let row: Vec<f64> = csv
        .lines()
        .nth(3)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    let cell = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
    let (ok, out, err) = crate::util::run_ok(
        &[&study[..6], &["--trial", "2", "--json"]].concat(),
        dir.path(),
    );
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["trial"], 2);
    let set = dir.path().join("output/seed/robustness-trial-2");
    let flights = std::fs::read_to_string(set.join("flight.csv")).unwrap();
    let fheader: Vec<&str> = flights.lines().next().unwrap().split(',').collect();
    let at = |name: &str| fheader.iter().position(|h| *h == name).unwrap();
    let tilt = cell("tilt_deg");
    for (i, c) in ["open-loop", "tvlqr", "replan"].iter().enumerate() {
        let flown = &json["controllers"][i];
        assert_eq!(flown["name"], *c);
        let recorded = cell(&format!("{}_landing_error_deg", c.replace('-', "_")));
        let landing = flown["landing_error_deg"].as_f64().unwrap();
        assert_eq!(landing, recorded, "{c}");
        assert_eq!(flown["landed"], landing <= 10.0, "{c}");
        let rows: Vec<Vec<&str>> = flights
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|r| r[0] == *c)
            .collect();
        let num = |r: &[&str], name: &str| r[at(name)].parse::<f64>().unwrap();
        let (first, last) = (&rows[0], rows.last().unwrap());
        assert_eq!(num(first, "t_s"), 0.0);
        let released = num(first, "belly_from_down_deg");
        assert!(
            (released - (180.0 - tilt)).abs() < 1e-9,
            "{c}: {released} against {tilt}"
        );
        assert_eq!(num(last, "belly_from_down_deg"), landing, "{c}");
        assert!(
            (num(last, "t_s")
                - catflip::Config::load(&crate::util::seed_toml(), &[])
                    .unwrap()
                    .fall_time())
            .abs()
                < 1e-9
        );
        // a row a millisecond
        assert!((num(&rows[1], "t_s") - 1e-3).abs() < 2e-4, "{c}");
    }
    for file in [
        "belly.svg",
        "torque-open-loop.svg",
        "torque-replan.svg",
        "index.html",
    ] {
        assert!(set.join(file).exists(), "{file}");
    }
    for (bad, says) in [
        (
            vec!["--trial", "3"],
            "--trial 3: the study has 3 trials (numbered 0 to 2)",
        ),
        (vec!["--trial", "-1"], "must be a trial's index"),
        (
            vec!["--trial", "0", "--shard", "1/2"],
            "cannot be used with",
        ),
    ] {
        let mut argv = study.to_vec();
        argv.extend(&bad);
        argv.extend(["--out", "bad"]);
        let out = crate::util::output(&argv, dir.path());
        let err = crate::util::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {err}");
        assert!(err.contains(says), "{bad:?}: {err}");
        assert!(!dir.path().join("bad").exists(), "{bad:?}");
    }
}
