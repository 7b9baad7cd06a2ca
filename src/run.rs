//! `catflip run`: the main job. Analytic schedule, phased and free-form
//! optimisation, forward verification of all three, and the report.

use crate::config::Config;
use crate::design::analytic::ClosedForms;
use crate::design::plan::{Schedule, ShapePlan};
use crate::design::scp::ScpIteration;
use crate::error::Result;
use crate::model::motor::MotorUse;
use crate::output::Output;
use crate::report::{self, MethodTrace};
use crate::verify::analyze::{analyze, peak_along};
use crate::verify::simulate::{SimReport, dynamic_cfg};
use serde::Serialize;
use std::time::Instant;

/// What a run reports to its progress display.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    Stage {
        index: usize,
        total: usize,
        name: &'a str,
    },
    StageDone {
        seconds: f64,
    },
    Bend {
        evaluations: usize,
        bend_deg: f64,
        peak_nm: f64,
    },
    Scp(&'a ScpIteration),
}

/// One method's line of the summary.
#[derive(Debug, Clone, Serialize)]
pub struct MethodSummary {
    pub method: &'static str,
    pub status: String,
    /// Peak joint torque of the schedule (inverse dynamics, dense), N m.
    pub peak_torque_nm: f64,
    pub bend_deg: f64,
    pub theta_deg: f64,
    pub twist_rad: f64,
    pub phase_durations_s: [f64; 3],
    /// Dynamic simulation (feed-forward + PD, torque limit if any).
    pub flip_deg: f64,
    pub flip_error_rad: f64,
    pub tilt_deg: f64,
    pub sim_peak_torque_nm: f64,
    pub momentum_drift_nms: f64,
    pub final_shape_error_rad: f64,
    /// Largest joint speed of the written schedule, rad/s (motor norm).
    pub max_speed_rad_s: f64,
    /// Smallest motor-envelope margin over the written rows (1 unused, 0 on
    /// the envelope, negative violated; absent without limits).
    pub min_envelope_margin: Option<f64>,
    pub solve_time_s: f64,
    pub schedule_csv: String,
    pub schedule_json: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    pub name: String,
    pub joint: &'static str,
    pub peak_norm: crate::model::TorqueNorm,
    pub max_torque_nm: Option<f64>,
    pub methods: Vec<MethodSummary>,
    /// Peak ratios between methods.
    pub phased_over_analytic: f64,
    pub free_over_phased: f64,
    pub scp_iterations: usize,
    pub nodes: usize,
    pub analytic: ClosedForms,
    pub figures: Vec<String>,
}

/// A finished run: its summary and the files to write.
pub struct RunResult {
    pub summary: RunSummary,
    pub output: Output,
    pub traces: Vec<MethodTrace>,
    pub iterations: Vec<ScpIteration>,
}

fn summarize(
    method: &'static str,
    status: String,
    peak: f64,
    path_numbers: (f64, f64, [f64; 3]),
    sim: &SimReport,
    motor: MotorUse,
    solve_time_s: f64,
) -> MethodSummary {
    let (bend, twist, durations) = path_numbers;
    MethodSummary {
        method,
        status,
        peak_torque_nm: peak,
        bend_deg: bend,
        theta_deg: 180.0 - bend,
        twist_rad: twist,
        phase_durations_s: durations,
        flip_deg: sim.flip_deg,
        flip_error_rad: sim.flip_error_rad,
        tilt_deg: sim.tilt_deg,
        sim_peak_torque_nm: sim.peak_torque_nm,
        momentum_drift_nms: sim.momentum_drift_nms,
        final_shape_error_rad: sim.final_shape_error_rad,
        max_speed_rad_s: motor.max_speed_rad_s,
        min_envelope_margin: motor.min_margin,
        solve_time_s,
        schedule_csv: format!("{method}.csv"),
        schedule_json: format!("{method}.schedule.json"),
    }
}

/// Curves of one method for the figures.
pub fn trace(
    cfg: &Config,
    name: &str,
    plan: &dyn ShapePlan,
    sim: &SimReport,
    per_phase: usize,
) -> MethodTrace {
    let cat = cfg.cat();
    let norm = cfg.norm();
    let b = plan.phase_bounds();
    let (mut t, mut q, mut tau) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..3 {
        for k in 0..=per_phase {
            let tt = b[i] + (b[i + 1] - b[i]) * k as f64 / per_phase as f64;
            t.push(tt);
            q.push(plan.state_in(i, tt).q);
            tau.push(norm.of(plan.torque_in(&cat, i, tt)));
        }
    }
    MethodTrace {
        name: name.into(),
        t,
        q,
        tau,
        phase_bounds: b,
        flip_t: sim.trace.iter().map(|p| p.t).collect(),
        flip_deg: sim.trace.iter().map(|p| p.flip.to_degrees()).collect(),
    }
}

/// Runs everything for one config.
pub fn run(cfg: &Config, mut progress: impl FnMut(Progress)) -> Result<RunResult> {
    let total = 4;
    let cat = cfg.cat();
    let per = cfg.simulate.samples_per_phase;
    let mut output = Output::default();

    progress(Progress::Stage {
        index: 1,
        total,
        name: "analytic schedule (seed closed forms, errata corrected)",
    });
    let clock = Instant::now();
    let a = analyze(cfg)?;
    let a_sim = dynamic_cfg(cfg, &a.plan)?;
    let a_time = clock.elapsed().as_secs_f64();
    let motor = cfg.motor();
    let usage = |s: &Schedule| motor.usage(s.rows.iter().map(|r| (r.tau, r.qd)));
    let a_sched = Schedule::sample(&cat, &a.plan, per);
    a_sched.add_to(&mut output, "analytic");
    progress(Progress::StageDone { seconds: a_time });

    progress(Progress::Stage {
        index: 2,
        total,
        name: "phased optimiser (path-timing SOCPs, bend search)",
    });
    let clock = Instant::now();
    let mut evaluations = 0;
    let ph = crate::design::phased::optimize(cfg, |e| {
        evaluations += 1;
        progress(Progress::Bend {
            evaluations,
            bend_deg: e.bend_deg,
            peak_nm: e.peak_nm,
        });
    })?;
    let ph_sched = Schedule::sample(&cat, &ph.plan, per);
    ph_sched.add_to(&mut output, "phased");
    progress(Progress::StageDone {
        seconds: clock.elapsed().as_secs_f64(),
    });

    progress(Progress::Stage {
        index: 3,
        total,
        name: "free-form optimiser (collocation + SCP, seeded by the phased design)",
    });
    let clock = Instant::now();
    let fr = crate::design::free::optimize_from(cfg, &ph.plan, "phased", cfg.free.nodes, |it| {
        progress(Progress::Scp(it))
    })?;
    let fr_sched = Schedule::sample(&cat, &fr.plan, per);
    fr_sched.add_to(&mut output, "free");
    progress(Progress::StageDone {
        seconds: clock.elapsed().as_secs_f64(),
    });

    progress(Progress::Stage {
        index: 4,
        total,
        name: "report (figures, summary)",
    });
    let clock = Instant::now();
    let ph_sim = ph
        .sim
        .as_ref()
        .expect("phased result carries its simulation");
    let fr_sim = &fr.sim;
    let (a_peak, _) = peak_along(cfg, &a.plan, crate::verify::analyze::dense_samples(cfg));
    let methods = vec![
        summarize(
            "analytic",
            "closed-form".into(),
            a_peak,
            (
                a.closed.bend_deg,
                a.closed.twist_rad,
                a.closed.phase_durations_s,
            ),
            &a_sim,
            usage(&a_sched),
            a_time,
        ),
        summarize(
            "phased",
            format!("{:?}", ph.status).to_lowercase(),
            ph.peak_torque_nm,
            (ph.bend_deg, ph.twist_rad, ph.phase_durations_s),
            ph_sim,
            usage(&ph_sched),
            ph.solve_time_s,
        ),
        summarize(
            "free",
            format!("{:?}", fr.status).to_lowercase(),
            fr.peak_torque_nm,
            (fr.bend_deg, fr.twist_rad, fr.phase_durations_s),
            fr_sim,
            usage(&fr_sched),
            fr.solve_time_s,
        ),
    ];
    crate::export::add_simulator_files(
        cfg,
        &mut output,
        &[
            ("analytic", &a.plan),
            ("phased", &ph.plan),
            ("free", &fr.plan),
        ],
    );
    let traces = vec![
        trace(cfg, "analytic", &a.plan, &a_sim, 300),
        trace(cfg, "phased", &ph.plan, ph_sim, 300),
        trace(cfg, "free", &fr.plan, fr_sim, 300),
    ];
    let norm_name = match cfg.norm() {
        crate::model::TorqueNorm::Euclidean => "Euclidean",
        crate::model::TorqueNorm::PerMotor => "per motor",
    };
    let figures = vec![
        ("angles.svg", report::angles(&traces)?),
        ("torque.svg", report::torque(&traces, norm_name)?),
        ("flip.svg", report::flip(&traces)?),
        ("shape_path.svg", report::shape_path(&traces)?),
        ("convergence.svg", report::convergence(&fr.iterations)?),
    ];
    let summary = RunSummary {
        name: cfg.name.clone(),
        joint: cfg.cat.joint.name(),
        peak_norm: cfg.norm(),
        max_torque_nm: cfg.limits.max_torque,
        phased_over_analytic: methods[1].peak_torque_nm / methods[0].peak_torque_nm,
        free_over_phased: methods[2].peak_torque_nm / methods[1].peak_torque_nm,
        methods,
        scp_iterations: fr.scp_iterations,
        nodes: fr.nodes,
        analytic: a.closed.clone(),
        figures: figures.iter().map(|f| f.0.to_string()).collect(),
    };
    let header = TABLE_HEADER;
    let rows: Vec<Vec<String>> = summary.methods.iter().map(table_row).collect();
    let notes = vec![
        format!(
            "{} joint, peak norm {norm_name}; fall time {:.4} s, manoeuvre {:.4} s. Free-form / phased peak: {:.3}; phased / analytic: {:.3}. Free-form: {} SCP iterations, {} nodes per phase.",
            summary.joint,
            summary.analytic.fall_time_s,
            summary.analytic.available_time_s,
            summary.free_over_phased,
            summary.phased_over_analytic,
            summary.scp_iterations,
            summary.nodes
        ),
        "Flip and tilt come from the dynamic forward simulation of each schedule (feed-forward torque plus PD tracking).".into(),
    ];
    let figure_names: Vec<&str> = figures.iter().map(|f| f.0).collect();
    output.add(
        "index.html",
        report::index_html(
            &format!("catflip report: {}", cfg.name),
            &header,
            &rows,
            &notes,
            &figure_names,
        ),
    );
    for (name, svg) in figures {
        output.add(name, svg);
    }
    output.add(
        "summary.json",
        serde_json::to_string_pretty(&summary).expect("summary serialises"),
    );
    progress(Progress::StageDone {
        seconds: clock.elapsed().as_secs_f64(),
    });
    Ok(RunResult {
        summary,
        output,
        traces,
        iterations: fr.iterations,
    })
}

/// Columns of the comparison table (terminal and index.html).
pub const TABLE_HEADER: [&str; 9] = [
    "method",
    "status",
    "peak N m",
    "bend deg",
    "durations s",
    "flip error rad",
    "tilt deg",
    "sim peak N m",
    "solve s",
];

/// One line of the comparison table.
pub fn table_row(m: &MethodSummary) -> Vec<String> {
    let d = m.phase_durations_s;
    vec![
        m.method.to_string(),
        m.status.clone(),
        format!("{:.5}", m.peak_torque_nm),
        format!("{:.2}", m.bend_deg),
        format!("{:.3}/{:.3}/{:.3}", d[0], d[1], d[2]),
        format!("{:.2e}", m.flip_error_rad),
        format!("{:.2e}", m.tilt_deg),
        format!("{:.5}", m.sim_peak_torque_nm),
        format!("{:.3}", m.solve_time_s),
    ]
}
