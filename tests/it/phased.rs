//! The phased optimiser against independent code paths.

use crate::util;

use catflip::design::analytic::plan as cosine_plan;
use catflip::design::path::Path;
use catflip::design::phased::{design_at, optimize, twist_for};
use catflip::design::plan::ShapePlan;
use catflip::design::timing::TimingProblem;
use catflip::error::Error;
use catflip::model::Joint;
use catflip::verify::analyze::peak_along;
use catflip::verify::simulate::kinematic;
// the bundled configs as peak-torque problems (the robot under its stall torque alone)
use util::stall_torque_only as cfg;

#[test]
fn socp_peak_matches_inverse_dynamics_along_the_reconstruction_and_converges_in_k() {
    // Euclidean norm: SOCP and reconstruction agree to 0.2 % at K = 40 and
    // doubling K moves the peak by less than 0.1 %.
    for (name, bend) in [("seed", 0.6), ("seed", 2.0), ("domestic-cat", 1.4)] {
        let c = cfg(name, &[]);
        let cat = c.cat();
        let mut peaks = Vec::new();
        for k in [40, 80] {
            let mut prob = TimingProblem::new(k, c.norm());
            let d = design_at(&cat, &mut prob, bend).unwrap();
            let t = c.available_time();
            let dur = d.durations(t);
            let plan = d.plan(dur);
            let (_, per_phase) = peak_along(&c.design_spec(), &plan, 20 * k);
            for i in 0..3 {
                let socp = d.phases[i].unit_peak / dur[i].powi(2);
                let rel = (per_phase[i] - socp).abs() / socp;
                assert!(
                    rel < 2e-3,
                    "{name} bend {bend} K {k} phase {i}: SOCP {socp} vs inverse dynamics {}",
                    per_phase[i]
                );
            }
            peaks.push(d.unit_peak());
        }
        let change = (peaks[0] - peaks[1]).abs() / peaks[1];
        assert!(
            change < 1e-3,
            "{name} bend {bend}: doubling K changes the peak by {change}"
        );
    }
}

#[test]
fn per_motor_gap_between_socp_and_reconstruction_closes_at_second_order() {
    // Per-motor peaks switch between motors, so the linear-in-s acceleration
    // leaves a larger (still second-order) gap between evaluation points.
    let c = cfg("robot-universal", &[]);
    let cat = c.cat();
    let mut gaps = Vec::new();
    for k in [40, 80] {
        let mut prob = TimingProblem::new(k, c.norm());
        let d = design_at(&cat, &mut prob, 1.0).unwrap();
        let dur = d.durations(1.0);
        let (dense, _) = peak_along(&c.design_spec(), &d.plan(dur), 20 * k);
        let socp = d.unit_peak();
        assert!(
            dense >= socp * (1.0 - 1e-6),
            "the dense peak cannot be below the bound at the points"
        );
        gaps.push((dense - socp) / socp);
    }
    assert!(gaps[0] < 0.03 && gaps[1] < gaps[0] / 2.5, "gaps {gaps:?}");
}

#[test]
fn no_twist_unfold_equals_the_reversed_fold() {
    let c = cfg("seed", &[]);
    let cat = c.cat();
    let mut prob = TimingProblem::new(30, c.norm());
    let paths = Path::phased(1.3, 4.0);
    let fold = prob.solve(&cat, &paths[0]).unwrap();
    let unfold = prob.solve(&cat, &paths[2]).unwrap();
    assert!(
        (fold.unit_peak - unfold.unit_peak).abs() < 2e-5 * fold.unit_peak,
        "{} {}",
        fold.unit_peak,
        unfold.unit_peak
    );
}

#[test]
fn f3_halving_the_time_multiplies_the_optimum_by_four() {
    // height / 4 halves the fall time; compare the reconstructed schedules' dense peaks
    let a = optimize(&cfg("seed", &[]).design_spec(), |_| {}).unwrap();
    let b = optimize(&cfg("seed", &["fall.height=2.5"]).design_spec(), |_| {}).unwrap();
    let ratio = b.peak_torque_nm / a.peak_torque_nm;
    assert!((ratio - 4.0).abs() < 4e-6, "ratio {ratio}");
    assert!((a.bend_deg - b.bend_deg).abs() < 1e-9);
}

#[test]
fn optimum_never_exceeds_the_cosine_schedule_at_the_same_bend_and_split() {
    for name in ["seed", "domestic-cat", "robot-universal"] {
        let c = cfg(name, &[]);
        let cat = c.cat();
        let t = c.available_time();
        let split = c.analytic.split.map(|f| f * t);
        let mut prob = TimingProblem::new(c.phased.nodes, c.norm());
        for bend in [0.4, 1.2, 2.4] {
            let d = design_at(&cat, &mut prob, bend).unwrap();
            let opt = d.peak_with(split);
            let (cos, _) = peak_along(&c.design_spec(), &cosine_plan(bend, d.twist, split), 2000);
            assert!(
                opt <= cos,
                "{name} bend {bend}: optimum {opt} > cosine {cos}"
            );
        }
        let r = optimize(&c.design_spec(), |_| {}).unwrap();
        assert!(
            r.improvement_factor > 1.0,
            "{name}: {}",
            r.improvement_factor
        );
        assert!(r.optimum_same_split_nm.unwrap() <= r.analytic_peak_same_bend_nm);
        let sim = util::flown(&c.design_spec(), &r.plan);
        assert!(
            sim.flip_error_rad.abs() < 1e-5,
            "{name}: flip error {}",
            sim.flip_error_rad
        );
        assert!(
            (sim.peak_torque_nm - r.peak_torque_nm).abs() < 0.005 * r.peak_torque_nm,
            "{name}"
        );
    }
}

#[test]
fn universal_twist_is_found_from_the_integrated_attitude() {
    let c = cfg("robot-universal", &[]);
    let cat = c.cat();
    assert_eq!(cat.joint, Joint::Universal);
    for bend in [0.5, 1.5] {
        let tw = twist_for(&cat, bend).unwrap();
        let r = kinematic(
            &cat,
            &cosine_plan(bend, tw, [0.2, 0.5, 0.3]),
            &Default::default(),
        )
        .unwrap();
        assert!(
            r.flip_error_rad.abs() < 1e-8,
            "bend {bend}: {}",
            r.flip_error_rad
        );
        // the root differs from the no-twist pi / C (F4)
        let mut nt = cat;
        nt.joint = Joint::NoTwist;
        assert!((twist_for(&nt, bend).unwrap() - tw).abs() > 1e-3);
    }
    // the free-form design's phased seed root-finds its twist more loosely
    // (to 1e-8 rad) and still flips, to its 20-interval timing's own error
    // (2.3e-6 rad with either tolerance)
    let seed = catflip::design::phased::seed_plan(&c.design_spec()).unwrap();
    let r = kinematic(&cat, &seed, &Default::default()).unwrap();
    assert!(r.flip_error_rad.abs() < 1e-5, "{}", r.flip_error_rad);
}

#[test]
fn torque_limit_below_the_optimum_names_the_least_drop_height() {
    let c = cfg("seed", &["limits.max_torque=0.3"]);
    let e = optimize(&c.design_spec(), |_| {}).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::BeyondMotors { .. }), "{msg}");
    let h = crate::util::number_after(&msg, "at least ");
    assert!(h > 10.0);
    // F7: from a little higher it works, within the limit
    let ok_cfg = cfg(
        "seed",
        &[
            "limits.max_torque=0.3",
            &format!("fall.height={}", h * 1.01),
        ],
    );
    let ok = optimize(&ok_cfg.design_spec(), |_| {}).unwrap();
    assert!(
        ok.peak_torque_nm <= 0.3 && ok.peak_torque_nm > 0.29,
        "{}",
        ok.peak_torque_nm
    );
    assert!(util::flown(&ok_cfg.design_spec(), &ok.plan).peak_torque_nm <= 0.3 + 1e-9);
}

#[test]
fn a_broken_phase_problem_surfaces_as_a_solver_status() {
    let c = cfg("seed", &[]);
    let mut prob = TimingProblem::new(10, c.norm());
    let bad = Path::Arc {
        bend: f64::NAN,
        phi0: 0.0,
        dphi: 1.0,
    };
    match prob.solve(&c.cat(), &bad) {
        Err(Error::Solver { status, .. }) => assert!(!status.is_empty()),
        other => panic!("expected a solver error, got {other:?}"),
    }
    // and the solver still works after a failure
    let good = prob.solve(&c.cat(), &Path::phased(1.0, 3.5)[1]).unwrap();
    assert!(good.unit_peak > 0.0);
    let _ = good.timing.t.len();
    let _ = ShapePlan::duration(&cosine_plan(1.0, 1.0, [1.0; 3]));
}

/// A bend search from a bend of almost nothing (whose program needs
/// thousands of twist turns and fails, or succeeds at a million times the
/// optimum's peak) finds the design the default range finds: the failed
/// bends are passed over, and the solver set up for that extreme program
/// does not carry its scaling to the next (every bend after it failed:
/// NumericalError for `phased.bend_min_deg = 0.1` and below).
#[test]
fn a_bend_range_from_almost_nothing_finds_the_default_ranges_design() {
    let optimum = optimize(&cfg("seed", &[]).design_spec(), |_| {}).unwrap();
    for low in ["1e-300", "1e-4", "0.01", "0.1"] {
        let c = cfg("seed", &[&format!("phased.bend_min_deg={low}")]);
        let r = optimize(&c.design_spec(), |_| {}).unwrap_or_else(|e| panic!("{low}: {e}"));
        assert!(
            (r.peak_torque_nm / optimum.peak_torque_nm - 1.0).abs() < 1e-5,
            "{low}: {} against {} N m at {} deg",
            r.peak_torque_nm,
            optimum.peak_torque_nm,
            r.bend_deg
        );
        assert!(
            (r.bend_deg - optimum.bend_deg).abs() < 0.1,
            "{low}: {} deg",
            r.bend_deg
        );
    }
}

#[test]
fn the_fold_solved_alongside_the_twist_root_find_is_the_same_design() {
    // the robot (universal joint): its fold is solved on its own thread
    // while the twist is found; the three phases must come back in order and
    // equal the phases solved together, and a failed root-find must fail
    // the bend (after the fold's thread is joined)
    let c = cfg("robot-universal", &[]);
    let cat = c.cat();
    let bend = 1.2;
    let twist = twist_for(&cat, bend).unwrap();
    let [fold, arc, unfold] = Path::phased(bend, twist);
    let mut together = TimingProblem::new(20, c.norm());
    let all = together.solve_all(&cat, &[&fold, &arc, &unfold]).unwrap();
    let mut apart = TimingProblem::new(20, c.norm());
    let alongside = apart
        .solve_alongside(&cat, &fold, || Ok(vec![arc, unfold]))
        .unwrap();
    assert_eq!(alongside.len(), 3);
    for (a, b) in all.iter().zip(&alongside) {
        assert_eq!(a.unit_peak, b.unit_peak);
        assert_eq!(a.timing, b.timing);
    }
    // the twist phase differs from the fold: the order is checked, not assumed
    assert_ne!(all[0].unit_peak, all[1].unit_peak);
    let failed = apart.solve_alongside(&cat, &fold, || {
        Err(Error::Unreachable {
            reason: "no twist".into(),
        })
    });
    assert!(matches!(failed, Err(Error::Unreachable { .. })));
}
