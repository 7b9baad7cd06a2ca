//! Phased designs inside the motor envelope (design/envelope.rs) against
//! F7, time scaling, the unit-time peak program, and the motor model.

use crate::util;

use catflip::design::envelope::{height_for, torque_squared_integral, usage_of};
use catflip::design::phased::optimize;
use catflip::design::plan::Schedule;
use util::seed;

#[test]
fn time_with_a_torque_limit_alone_is_f7() {
    // F7: T_min = sqrt(P / tau_max) with P the unit-time optimum of the peak design
    let tau_max = 0.8;
    let peak = optimize(&seed(&[]).design_spec(), |_| {}).unwrap();
    let t_f7 = (peak.unit_peak_nm_s2 / tau_max).sqrt();
    let timed = optimize(
        &seed(&[
            "design.objective=time",
            &format!("limits.max_torque={tau_max}"),
        ])
        .design_spec(),
        |_| {},
    )
    .unwrap();
    let rel = (timed.manoeuvre_time_s - t_f7).abs() / t_f7;
    assert!(rel < 5e-3, "time {} vs F7 {t_f7}", timed.manoeuvre_time_s);
    let cfg = seed(&[]);
    let (h, h_f7) = (
        height_for(&cfg.design_spec(), timed.manoeuvre_time_s),
        0.5 * cfg.fall.gravity * t_f7 * t_f7,
    );
    assert!((h - h_f7).abs() < 1e-2 * h_f7, "{h} vs {h_f7}");
    assert!(timed.peak_torque_nm <= tau_max * (1.0 + 1e-6));
}

#[test]
fn time_with_a_speed_limit_alone_scales_as_one_over_the_limit() {
    let t = |w: f64| {
        optimize(
            &seed(&["design.objective=time", &format!("limits.max_speed={w}")]).design_spec(),
            |_| {},
        )
        .unwrap()
        .manoeuvre_time_s
    };
    let (a, b) = (t(1.5), t(4.5));
    assert!((a / b - 3.0).abs() < 1e-4, "{a} / {b} = {}", a / b);
}

#[test]
fn envelope_path_with_no_binding_limit_matches_the_unit_time_peak_program() {
    // a speed limit far above anything the design reaches sends the design
    // through the three-phase envelope program; its optimum must be the
    // unit-time program's (two formulations of the same optimum)
    let plain = optimize(&seed(&[]).design_spec(), |_| {}).unwrap();
    let env = optimize(&seed(&["limits.max_speed=1000"]).design_spec(), |_| {}).unwrap();
    let rel = (env.peak_torque_nm - plain.peak_torque_nm).abs() / plain.peak_torque_nm;
    assert!(
        rel < 3e-3,
        "envelope {} vs unit-time {}",
        env.peak_torque_nm,
        plain.peak_torque_nm
    );
}

#[test]
fn every_row_inside_the_envelope_and_the_motor_model_flips() {
    let limits = [
        "limits.max_torque=1",
        "limits.no_load_speed=3",
        "fall.height=30",
        "phased.nodes=24",
    ];
    let mut results = Vec::new();
    for (objective, norm) in [
        ("time", "euclidean"),
        ("time", "per-motor"),
        ("peak-torque", "euclidean"),
        ("energy", "per-motor"),
    ] {
        let mut ov = limits.to_vec();
        let (o, n) = (
            format!("design.objective={objective}"),
            format!("limits.norm={norm}"),
        );
        ov.push(&o);
        ov.push(&n);
        let cfg = seed(&ov);
        let r = optimize(&cfg.design_spec(), |_| {}).unwrap();
        let u = usage_of(&cfg.design_spec(), &r.plan);
        assert!(
            u.min_margin.unwrap() >= -1e-6,
            "{objective} {norm}: margin {:?}",
            u.min_margin
        );
        // the motor model (torque clipped to the envelope) still flips by pi
        let flip_error = util::flown(&cfg.design_spec(), &r.plan).flip_error_rad;
        assert!(
            flip_error.abs() < 1e-3,
            "{objective} {norm}: flip error {flip_error}"
        );
        // within the fall: the program's time model is corrected to the fall time
        if objective != "time" {
            let sched = Schedule::sample(&cfg.cat(), &r.plan, cfg.simulate.samples_per_phase);
            let end = sched.rows.last().unwrap().t;
            assert!(
                (end - cfg.available_time()).abs() < 1e-3 * end,
                "{objective}: ends at {end} s, fall {}",
                cfg.available_time()
            );
        }
        results.push((objective, norm, cfg, r));
    }
    // each objective is best at its own measure (same norm: per-motor rows)
    let (_, _, cfg_e, energy) = &results[3];
    let mut ov = limits.to_vec();
    ov.push("limits.norm=per-motor");
    let peak = optimize(&seed(&ov).design_spec(), |_| {}).unwrap();
    let cat = cfg_e.cat();
    let (e_of_energy, e_of_peak) = (
        torque_squared_integral(&cat, &energy.plan, 2000),
        torque_squared_integral(&cat, &peak.plan, 2000),
    );
    assert!(
        e_of_energy <= e_of_peak * (1.0 + 1e-3),
        "energy design {e_of_energy} vs peak design {e_of_peak}"
    );
    assert!(peak.peak_torque_nm <= energy.peak_torque_nm * (1.0 + 1e-3));
}

/// The robot's servo in a 1000 m fall (14 s): the torques a peak or energy
/// design needs are thousands of times below the stall torque and its
/// speeds far below the no-load speed, so the torque-speed line cannot
/// bind, and each design must be the one under the stall torque alone,
/// which time scaling (F3) ties to every other fall. The phased programs
/// once worked in units of the stall torque, where the solver's tolerances
/// blurred the objective (bend 170 deg, flagged; the energy design "not
/// possible"), and the free-form design clamped the limit, and the line's
/// no-load speed with it, and ended at its iteration limit.
#[test]
fn a_servo_that_cannot_bind_in_a_long_fall_leaves_each_design_where_the_stall_torque_alone_does() {
    use catflip::design::envelope::usage_of;
    use catflip::design::free::FreeDesign;
    use catflip::design::scp::ScpStatus;
    let long = ["fall.height=1000"];
    let line = util::config("robot-universal", &long);
    let stall = util::stall_torque_only("robot-universal", &long);
    for objective in ["peak-torque", "energy"] {
        let o = format!("design.objective={objective}");
        let ov = [long[0], o.as_str()];
        let (a, b) = (
            util::config("robot-universal", &ov),
            util::stall_torque_only("robot-universal", &ov),
        );
        let (with_line, alone) = (
            optimize(&a.design_spec(), |_| {}).unwrap(),
            optimize(&b.design_spec(), |_| {}).unwrap(),
        );
        // the stall-only design keeps inside the line: it cannot bind
        let margin = usage_of(&a.design_spec(), &alone.plan).min_margin.unwrap();
        assert!(margin > 0.5, "{objective}: margin {margin} under the line");
        let rel = with_line.objective_value / alone.objective_value - 1.0;
        assert!(
            rel.abs() < 1e-3,
            "{objective}: {} with the line, {} under the stall torque alone (bend {} and {} deg)",
            with_line.objective_value,
            alone.objective_value,
            with_line.bend_deg,
            alone.bend_deg
        );
    }
    let free = |c: &catflip::Config| {
        let spec = c.design_spec();
        let seed = optimize(&spec, |_| {}).unwrap();
        let r = FreeDesign::new(&spec)
            .from_plan(&seed.plan, "phased")
            .solve()
            .unwrap();
        assert_eq!(r.status, ScpStatus::Converged, "{}", c.name);
        r.peak_torque_nm
    };
    let (with_line, alone) = (free(&line), free(&stall));
    // the same problem, reached by different meshes (30 and 20 nodes per
    // phase before the 60): the same optimum to the mesh's accuracy
    assert!(
        (with_line / alone - 1.0).abs() < 1e-2,
        "free-form peak {with_line} N m with the line, {alone} under the stall torque alone"
    );
}

/// The phased peak design fits every fall longer than the phased least
/// height that `run` names (the time design's schedule, slowed to the
/// fall, is inside the envelope): the box robot from 25.5 m failed, saying
/// the phased design needs 24.1 m, because the coarse bend scan's band of
/// feasible bends was narrower than its look around the fastest bend.
#[test]
fn the_phased_design_fits_a_fall_just_longer_than_the_phased_least_height() {
    let cfg = util::config("box-robot", &[]);
    let h = catflip::design::least_height::heights(
        &cfg.design_spec(),
        catflip::design::least_height::Families::Phased,
        |_| {},
    )
    .unwrap()
    .expect("the box robot has motor limits");
    for k in [1.02, 1.06] {
        let spec = cfg.design_spec().with_height(k * h.phased_m);
        let r = optimize(&spec, |_| {}).unwrap_or_else(|e| {
            panic!(
                "from {} m ({k} x the phased least height): {e}",
                k * h.phased_m
            )
        });
        assert!(
            catflip::verdict::Status::from(r.status).is_proven(),
            "{:?}",
            r.status
        );
        let u = usage_of(&spec, &r.plan);
        assert!(u.min_margin.unwrap() >= -1e-6, "{:?}", u.min_margin);
    }
}
