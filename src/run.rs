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
    /// What to look at before using this schedule: `over-limit` (the schedule
    /// needs more than `limits.max_torque`), `not-converged` (the optimiser
    /// stopped early), `flip-missed` (the simulated flip or tilt is off by
    /// more than [`FLIP_TOLERANCE_RAD`]). Empty when all is well.
    pub flags: Vec<String>,
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
        flags: Vec::new(),
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
    let mut methods = vec![
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
            json_name(&ph.status),
            ph.peak_torque_nm,
            (ph.bend_deg, ph.twist_rad, ph.phase_durations_s),
            ph_sim,
            usage(&ph_sched),
            ph.solve_time_s,
        ),
        summarize(
            "free",
            json_name(&fr.status),
            fr.peak_torque_nm,
            (fr.bend_deg, fr.twist_rad, fr.phase_durations_s),
            fr_sim,
            usage(&fr_sched),
            fr.solve_time_s,
        ),
    ];
    let converged = [
        true,
        ph.status == crate::design::conic::SolveStatus::Solved,
        fr.status == crate::design::scp::ScpStatus::Converged,
    ];
    for (m, ok) in methods.iter_mut().zip(converged) {
        m.flags = flags(m, ok, cfg.limits.max_torque);
    }
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
    let norm_name = json_name(&cfg.norm());
    let figures = vec![
        ("angles.svg", report::angles(&traces)?),
        (
            "torque.svg",
            report::torque(&traces, &norm_name, cfg.limits.max_torque)?,
        ),
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
    let sims = [&a_sim, ph_sim, fr_sim];
    let scene = report::animation::Scene {
        rear: cat.rear,
        front: cat.front,
        joint: summary.joint,
        norm: norm_name.clone(),
        max_torque_nm: cfg.limits.max_torque,
        tracks: summary
            .methods
            .iter()
            .zip(sims)
            .map(|(m, sim)| {
                let status = table_row(m)[1].clone();
                report::animation::track(
                    &cat,
                    cfg.norm(),
                    m.method,
                    &status,
                    sim,
                    report::animation::FRAMES,
                )
            })
            .collect(),
    };
    let warnings: Vec<String> = summary
        .methods
        .iter()
        .flat_map(|m| warnings(m, cfg.limits.max_torque))
        .collect();
    output.add(
        "index.html",
        report::index_html(
            &format!("catflip report: {}", cfg.name),
            &header,
            &rows,
            &notes,
            &warnings,
            &report::animation::section(&scene),
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

/// A simulated flip or tilt farther than this from a clean half turn is a
/// miss, rad (0.57 deg: well above the designs' integration and tracking
/// errors, well below what a landing notices).
pub const FLIP_TOLERANCE_RAD: f64 = 1e-2;

/// The name serde gives a unit enum value (`per-motor`, `iteration-limit`),
/// so the terminal says what the JSON says.
pub fn json_name<T: Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}

/// The flags of a method (see [`MethodSummary::flags`]).
pub fn flags(m: &MethodSummary, converged: bool, limit: Option<f64>) -> Vec<String> {
    let mut f = Vec::new();
    if limit.is_some_and(|l| m.peak_torque_nm > l * (1.0 + 1e-9)) {
        f.push("over-limit".to_string());
    }
    if !converged {
        f.push("not-converged".to_string());
    }
    if m.flip_error_rad.abs() > FLIP_TOLERANCE_RAD
        || m.tilt_deg.to_radians().abs() > FLIP_TOLERANCE_RAD
    {
        f.push("flip-missed".to_string());
    }
    f
}

/// One sentence per flag of a method, for the report and the terminal.
pub fn warnings(m: &MethodSummary, limit: Option<f64>) -> Vec<String> {
    m.flags
        .iter()
        .map(|f| match f.as_str() {
            "over-limit" => format!(
                "{}: the schedule needs {:.4} N m, over the {} N m torque limit; the simulation saturates at the limit.",
                m.method,
                m.peak_torque_nm,
                limit.unwrap_or(f64::NAN)
            ),
            "not-converged" => format!(
                "{}: the optimiser stopped without converging (status {}); the schedule is its last iterate.",
                m.method, m.status
            ),
            _ => format!(
                "{}: the simulated motion misses the half turn: flip {:.3} deg (error {:.3e} rad), tilt {:.3} deg.",
                m.method, m.flip_deg, m.flip_error_rad, m.tilt_deg
            ),
        })
        .collect()
}

/// A small number in the table: `0` for exact zero, else 3 significant digits.
fn small(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}

/// One line of the comparison table.
pub fn table_row(m: &MethodSummary) -> Vec<String> {
    let d = m.phase_durations_s;
    let status = if m.flags.is_empty() {
        m.status.clone()
    } else {
        format!("{} [{}]", m.status, m.flags.join(", "))
    };
    vec![
        m.method.to_string(),
        status,
        format!("{:.5}", m.peak_torque_nm),
        format!("{:.2}", m.bend_deg),
        format!("{:.3}/{:.3}/{:.3}", d[0], d[1], d[2]),
        small(m.flip_error_rad),
        small(m.tilt_deg),
        format!("{:.5}", m.sim_peak_torque_nm),
        format!("{:.3}", m.solve_time_s),
    ]
}
