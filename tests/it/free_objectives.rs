//! Free-form designs for every objective inside the motor envelope, against
//! F7, time scaling, the motor model and the phased designs.

use crate::util;

use catflip::Config;
use catflip::design::envelope::{height_for, usage_of};
use catflip::design::free::{FreeDesign, FreeResult};
use util::seed;

/// The free-form design seeded by the phased design of the same objective
/// (the mesh check left out).
fn free(cfg: &Config) -> FreeResult {
    let phased = catflip::design::phased::optimize(&cfg.design_spec(), |_| {}).unwrap();
    let r = FreeDesign::new(&cfg.design_spec())
        .from_plan(&phased.plan, "phased")
        .solve()
        .unwrap();
    assert_eq!(r.status, catflip::design::scp::ScpStatus::Converged);
    r
}

#[test]
fn free_time_with_a_torque_limit_alone_is_f7() {
    // F7 for the free-form optimum: the least-peak design P at the fall time
    // T_f gives T_min = T_f sqrt(P / tau_max) (F3 time scaling of one path);
    // the time design must find it
    let tau_max = 1.0;
    let open = seed(&[]);
    let peak = free(&open);
    let t_fall = open.available_time();
    let t_f7 = t_fall * (peak.peak_torque_nm / tau_max).sqrt();
    let timed_cfg = seed(&[
        "design.objective=time",
        &format!("limits.max_torque={tau_max}"),
    ]);
    let timed = free(&timed_cfg);
    let rel = (timed.manoeuvre_time_s - t_f7) / t_f7;
    assert!(
        rel.abs() < 5e-3,
        "time {} vs F7 {t_f7}",
        timed.manoeuvre_time_s
    );
    let (h, h_f7) = (
        height_for(&open.design_spec(), timed.manoeuvre_time_s),
        0.5 * open.fall.gravity * t_f7 * t_f7,
    );
    assert!((h - h_f7).abs() < 1e-2 * h_f7, "{h} vs {h_f7}");
    assert!(timed.peak_torque_nm <= tau_max * (1.0 + 1e-6));
    // the mesh check compares the objective, here the time (the peak sits
    // at the limit, 1 N m, about 10 % from this time in s)
    let m = catflip::design::free::mesh_check(&timed_cfg.design_spec(), &timed).unwrap();
    assert!(
        (m.objective_value - timed.manoeuvre_time_s).abs() < 2e-2 * timed.manoeuvre_time_s,
        "{m:?}"
    );
    let change = (timed.objective_value - m.objective_value) / m.objective_value;
    assert!((m.relative_change - change).abs() < 1e-12, "{m:?}");
}

#[test]
fn free_time_with_a_speed_limit_alone_scales_as_one_over_the_limit() {
    let t = |w: f64| {
        free(&seed(&[
            "design.objective=time",
            &format!("limits.max_speed={w}"),
        ]))
        .manoeuvre_time_s
    };
    // with the torque unbounded the least-time problem is degenerate (the
    // rate may jump), and the SCP stops on its progress rule at a
    // criticality near 0.1: the two ends agree to about 1 %, not to the
    // phased design's 1e-4
    let (a, b) = (t(5.0), t(10.0));
    assert!((a / b - 2.0).abs() < 2e-2 * 2.0, "{a} / {b} = {}", a / b);
}

#[test]
fn every_objective_stays_inside_the_envelope_flips_and_beats_the_phased_design() {
    // a DC motor line (1 N m stall, 8 rad/s no load) that binds for every objective
    for objective in ["peak-torque", "time", "energy"] {
        let cfg = seed(&[
            &format!("design.objective={objective}"),
            "limits.max_torque=1",
            "limits.no_load_speed=8",
        ]);
        let phased = catflip::design::phased::optimize(&cfg.design_spec(), |_| {}).unwrap();
        let r = FreeDesign::new(&cfg.design_spec())
            .from_plan(&phased.plan, "phased")
            .solve()
            .unwrap();
        assert_eq!(r.status, catflip::design::scp::ScpStatus::Converged);
        let margin = usage_of(&cfg.design_spec(), &r.plan).min_margin.unwrap();
        assert!(margin >= -1e-6, "{objective}: margin {margin}");
        // the dynamic simulation applies the motor model (clipped torque)
        let flip_error = util::flown(&cfg.design_spec(), &r.plan).flip_error_rad;
        assert!(
            flip_error.abs() < 1e-3,
            "{objective}: flip error {flip_error}"
        );
        assert!(
            r.objective_value <= phased.objective_value * (1.0 + 1e-6),
            "{objective}: free {} vs phased {}",
            r.objective_value,
            phased.objective_value
        );
        if objective != "time" {
            assert!(r.manoeuvre_time_s <= cfg.available_time() * (1.0 + 1e-9));
        }
    }
}

/// Limits holding between check points: the robot's least time under its
/// servo's torque-speed line, from either seed, inside the envelope on the
/// dense samples at the time the SCP itself ended (not slowed down
/// afterwards by what broke the line between check points: 1.05 % from the
/// phased seed with the quarter points alone, where the second motor
/// reverses in the twist); by default solved on 30 nodes per phase first
/// (mesh continuation inside the envelope), and then within 0.5 % of the
/// design the fine mesh alone finds.
#[test]
fn the_robots_least_time_holds_the_torque_speed_line_between_check_points() {
    let held = |cfg: &catflip::Config, r: &catflip::design::free::FreeResult, what: &str| {
        assert_eq!(
            r.status,
            catflip::design::scp::ScpStatus::Converged,
            "{what}"
        );
        let dense = catflip::verify::analyze::dense_samples(&cfg.design_spec());
        let sched = catflip::design::plan::Schedule::sample(&cfg.cat(), &r.plan, dense);
        let margin = cfg
            .motor()
            .usage(sched.rows.iter().map(|row| (row.tau, row.qd)))
            .min_margin
            .unwrap();
        assert!(margin >= -1e-7, "{what}: margin {margin}");
        let ended = r.iterations.last().unwrap().objective;
        assert!(
            r.manoeuvre_time_s <= ended * (1.0 + 1e-3),
            "{what}: written {} s, the SCP ended at {ended} s",
            r.manoeuvre_time_s
        );
    };
    let continued = util::config("robot-universal", &["design.objective=time"]);
    // on the fine mesh alone: the restart below is checked from the optimum
    // the fine mesh finds (a design continued from the coarse mesh stops
    // within the SCP's tolerances, where its restart moved by 5e-5)
    let cfg = util::config(
        "robot-universal",
        &["design.objective=time", "free.mesh_continuation=false"],
    );
    for seed in [
        catflip::design::free::Seed::Phased,
        catflip::design::free::Seed::Analytic,
    ] {
        let c = FreeDesign::new(&continued.design_spec())
            .seed(seed)
            .solve()
            .unwrap();
        held(&continued, &c, &format!("{seed:?}, continued"));
        let meshes: Vec<usize> = c.mesh_levels.iter().map(|l| l.nodes).collect();
        assert_eq!(meshes, [30, 60], "{seed:?}");
        let r = FreeDesign::new(&cfg.design_spec())
            .seed(seed)
            .solve()
            .unwrap();
        held(&cfg, &r, &format!("{seed:?}"));
        assert_eq!(r.mesh_levels.len(), 1, "{seed:?}");
        assert!(
            (c.manoeuvre_time_s - r.manoeuvre_time_s).abs() <= 5e-3 * r.manoeuvre_time_s,
            "{seed:?}: {} s continued, {} s on the fine mesh alone",
            c.manoeuvre_time_s,
            r.manoeuvre_time_s
        );
        // continued from itself (a sweep's next point at no change), the
        // design keeps the check points it added, its penalty weight and
        // trust radius, so it starts where it ended: a few iterations, and
        // no slower (with the weight reset, the steps wandered off the
        // optimum for dozens of iterations)
        let again = FreeDesign::new(&cfg.design_spec())
            .warm(&r, None)
            .solve()
            .unwrap();
        assert_eq!(again.status, catflip::design::scp::ScpStatus::Converged);
        assert!(
            r.extra_checks.iter().any(|e| !e.is_empty()),
            "{seed:?}: no added check points"
        );
        for (added, kept) in r.extra_checks.iter().zip(&again.extra_checks) {
            assert!(added.iter().all(|c| kept.contains(c)), "{seed:?}");
        }
        assert!(
            again.scp_iterations <= 10,
            "{seed:?}: {} iterations from its own optimum",
            again.scp_iterations
        );
        assert!(
            again.manoeuvre_time_s <= r.manoeuvre_time_s * (1.0 + 1e-6),
            "{seed:?}: {} s from {} s",
            again.manoeuvre_time_s,
            r.manoeuvre_time_s
        );
    }
}
