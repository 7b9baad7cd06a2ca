//! `catflip run`: the main job. Analytic schedule, phased and free-form
//! optimisation, forward verification of all three, and the report.

use crate::config::Config;
use crate::design::analytic::ClosedForms;
use crate::design::least_height::HeightAnswer;
use crate::design::plan::{Schedule, ShapePlan};
use crate::design::scp::ScpIteration;
use crate::error::{Error, Result};
use crate::output::Output;
use crate::report::{self, MethodTrace};
use crate::verdict::{DesignNumbers, Grade, Simulated, Status, Targets, verdict};
use crate::verify::analyze::analyze;
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
    /// The stage's method failed; the run goes on with the others.
    StageFailed {
        seconds: f64,
        reason: &'a str,
    },
    /// The stage's method was not attempted: the motors cannot flip the
    /// cat from this height (the least-height stage found it).
    StageSkipped {
        reason: &'a str,
    },
    Bend {
        evaluations: usize,
        bend_deg: f64,
        /// Absent for an objective other than the peak.
        peak_nm: Option<f64>,
    },
    Scp(&'a ScpIteration),
}

/// One method's line of the summary.
#[derive(Debug, Clone, Serialize)]
pub struct MethodSummary {
    pub method: &'static str,
    /// Solver status (`closed-form`, `solved`, `converged`, ...), or `failed`.
    pub status: Status,
    pub verdict: Grade,
    /// Why the method is flagged or failed (absent when ok).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The numbers, absent when the method failed.
    #[serde(flatten)]
    pub result: Option<MethodNumbers>,
}

/// The numbers of a method that produced a schedule.
#[derive(Debug, Clone, Serialize)]
pub struct MethodNumbers {
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
    /// The belly's angle from straight down at touchdown (docs/model.md section 8), deg.
    pub landing_error_deg: f64,
    pub sim_peak_torque_nm: f64,
    pub momentum_drift_nms: f64,
    pub final_shape_error_rad: f64,
    /// Largest joint speed of the written schedule, rad/s (motor norm).
    pub max_speed_rad_s: f64,
    /// Smallest motor-envelope margin over the written rows (1 unused, 0 on
    /// the envelope, negative violated; absent without limits).
    pub min_envelope_margin: Option<f64>,
    /// `integral |tau|^2 dt` over the written rows, N^2 m^2 s (the energy
    /// objective; the peak and the durations give the other two).
    pub energy_n2m2s: f64,
    pub solve_time_s: f64,
    pub schedule_csv: String,
    pub schedule_json: String,
}

impl MethodSummary {
    fn failed(method: &'static str, e: &crate::Error) -> MethodSummary {
        MethodSummary {
            method,
            status: Status::Failed,
            verdict: Grade::Failed,
            reason: Some(e.to_string()),
            result: None,
        }
    }

    pub fn peak(&self) -> Option<f64> {
        self.result.as_ref().map(|r| r.peak_torque_nm)
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    pub name: String,
    pub joint: &'static str,
    pub peak_norm: crate::model::TorqueNorm,
    pub max_torque_nm: Option<f64>,
    /// `ok` when every method is ok, `partial` when some are flagged or
    /// failed, `impossible` when the motors cannot flip the cat from
    /// `fall.height` (exit 4; `answer` says from what height they can).
    pub outcome: &'static str,
    pub methods: Vec<MethodSummary>,
    /// Peak ratios between methods (absent when either failed).
    pub phased_over_analytic: Option<f64>,
    pub free_over_phased: Option<f64>,
    pub scp_iterations: usize,
    pub nodes: usize,
    /// The free-form design's meshes (mesh continuation), coarse to fine.
    pub mesh_levels: Vec<crate::design::free::MeshLevel>,
    pub analytic: ClosedForms,
    pub figures: Vec<String>,
    /// With motor limits: can the motors flip the cat from `fall.height`, and
    /// the least drop height at which they can (absent without limits).
    pub answer: Option<HeightAnswer>,
}

/// A finished run: its summary and the files to write.
pub struct RunResult {
    pub summary: RunSummary,
    pub output: Output,
    pub traces: Vec<MethodTrace>,
    pub iterations: Vec<ScpIteration>,
}

impl RunResult {
    /// True when some method is flagged or failed (always so when the flip
    /// is impossible: [`RunResult::is_impossible`] comes first).
    pub fn is_partial(&self) -> bool {
        self.summary.outcome != "ok"
    }

    /// True when the motors cannot flip the cat from the configured height.
    pub fn is_impossible(&self) -> bool {
        self.summary.answer.as_ref().is_some_and(|a| !a.possible)
    }
}

/// How the motors are used by a written schedule's rows.
fn usage(cfg: &Config, schedule: &Schedule) -> crate::model::motor::MotorUse {
    cfg.motor()
        .usage(schedule.rows.iter().map(|r| (r.tau, r.qd)))
}

/// The verdict on a design with this status, dense peak and largest bend
/// (deg), written as `schedule` and simulated as `simulated`: the one
/// judgement `run`, `optimize` and `analyze` make.
pub fn judge(
    cfg: &Config,
    status: Status,
    peak_torque_nm: f64,
    bend_deg: f64,
    schedule: &Schedule,
    simulated: &Simulated,
) -> crate::verdict::Verdict {
    let motor = usage(cfg, schedule);
    verdict(
        &Targets::of(cfg),
        &DesignNumbers {
            status,
            peak_torque_nm,
            bend_deg,
            max_speed_rad_s: Some(motor.max_speed_rad_s),
            envelope_margin: motor.min_margin,
        },
        simulated,
    )
}

/// A method's line; `sim` is its dynamic simulation, or why that failed
/// (then the schedule is kept, flagged, with NaN simulation numbers).
fn summarize(
    cfg: &Config,
    method: &'static str,
    status: Status,
    peak: f64,
    path_numbers: (f64, f64, [f64; 3]),
    sim: std::result::Result<&SimReport, &Error>,
    schedule: &Schedule,
    solve_time_s: f64,
) -> MethodSummary {
    let motor = usage(cfg, schedule);
    let (bend, twist, durations) = path_numbers;
    let failed_sim;
    let (sim, sim_error) = match sim {
        Ok(s) => (s, None),
        Err(e) => {
            failed_sim = SimReport::failed();
            (&failed_sim, Some(e.to_string()))
        }
    };
    let n = MethodNumbers {
        peak_torque_nm: peak,
        bend_deg: bend,
        theta_deg: 180.0 - bend,
        twist_rad: twist,
        phase_durations_s: durations,
        flip_deg: sim.flip_deg,
        flip_error_rad: sim.flip_error_rad,
        tilt_deg: sim.tilt_deg,
        landing_error_deg: sim.landing_error_deg,
        sim_peak_torque_nm: sim.peak_torque_nm,
        momentum_drift_nms: sim.momentum_drift_nms,
        final_shape_error_rad: sim.final_shape_error_rad,
        max_speed_rad_s: motor.max_speed_rad_s,
        min_envelope_margin: motor.min_margin,
        energy_n2m2s: schedule.torque_squared_integral(),
        solve_time_s,
        schedule_csv: format!("{method}.csv"),
        schedule_json: format!("{method}.schedule.json"),
    };
    let simulated = match sim_error {
        Some(e) => Simulated::Failed(e),
        None => Simulated::Landing {
            flip_error_rad: n.flip_error_rad,
            tilt_deg: n.tilt_deg,
            landing_error_deg: n.landing_error_deg,
        },
    };
    let v = judge(cfg, status, peak, bend, schedule, &simulated);
    MethodSummary {
        method,
        status,
        verdict: v.grade(),
        reason: v.reason(),
        result: Some(n),
    }
}

/// Curves of one method for the figures; `peak` is its dense peak torque,
/// the table's (the curve's samples may fall just short of it).
pub fn trace(
    cfg: &Config,
    name: &str,
    plan: &dyn ShapePlan,
    peak: f64,
    sim: &SimReport,
    per_phase: usize,
) -> MethodTrace {
    let cat = cfg.cat();
    let norm = cfg.norm();
    let b = plan.phase_bounds();
    let (mut t, mut q, mut tau) = (Vec::new(), Vec::new(), Vec::new());
    let (mut qd, mut tau_xy) = (Vec::new(), Vec::new());
    for i in 0..3 {
        for k in 0..=per_phase {
            let tt = b[i] + (b[i + 1] - b[i]) * k as f64 / per_phase as f64;
            t.push(tt);
            let s = plan.state_in(i, tt);
            q.push(s.q);
            qd.push(s.qd);
            let v = plan.torque_in(&cat, i, tt);
            tau.push(norm.of(v));
            tau_xy.push(v);
        }
    }
    MethodTrace {
        name: name.into(),
        t,
        q,
        tau,
        qd,
        tau_xy,
        peak_nm: peak,
        over_limit: Targets::of(cfg).over_torque(peak),
        phase_bounds: b,
        flip_t: sim.trace.iter().map(|p| p.t).collect(),
        flip_deg: sim.trace.iter().map(|p| p.flip.to_degrees()).collect(),
    }
}

/// Runs everything for one config. A method that fails does not stop the
/// others: its status and reason go into the summary, table and report. Only
/// when every method fails is the run an error.
pub fn run(cfg: &Config, mut progress: impl FnMut(Progress)) -> Result<RunResult> {
    let limited = cfg.motor().is_limited();
    let total = if limited { 5 } else { 4 };
    let cat = cfg.cat();
    let per = cfg.simulate.samples_per_phase;
    let mut output = Output::default();
    let mut methods = Vec::new();
    let mut traces = Vec::new();
    let mut tracks = Vec::new();
    let track = |name: &str, sim: &SimReport| {
        report::animation::track(&cat, cfg.norm(), name, sim, report::animation::FRAMES)
    };
    let mut notes_early: Vec<String> = Vec::new();
    let stage_end = |progress: &mut dyn FnMut(Progress), clock: Instant, err: Option<&Error>| {
        let seconds = clock.elapsed().as_secs_f64();
        match err {
            None => progress(Progress::StageDone { seconds }),
            Some(e) => progress(Progress::StageFailed {
                seconds,
                reason: &e.to_string(),
            }),
        }
    };

    progress(Progress::Stage {
        index: 1,
        total,
        name: "analytic schedule (seed closed forms, errata corrected)",
    });
    let clock = Instant::now();
    // the kinematic check is part of the analysis; a failed dynamic
    // simulation (e.g. under a saturating torque limit) only flags the schedule
    let analytic = analyze(cfg).map(|a| {
        let sim = dynamic_cfg(cfg, &a.plan);
        (a, sim)
    });
    let a_time = clock.elapsed().as_secs_f64();
    match &analytic {
        Ok((a, a_sim)) => {
            let a_sched = Schedule::sample(&cat, &a.plan, per);
            a_sched.add_to(&mut output, "analytic");
            methods.push(summarize(
                cfg,
                "analytic",
                Status::ClosedForm,
                a.peak_torque_nm,
                (
                    a.closed.bend_deg,
                    a.closed.twist_rad,
                    a.closed.phase_durations_s,
                ),
                a_sim.as_ref(),
                &a_sched,
                a_time,
            ));
            let failed_sim = SimReport::failed();
            let sim = a_sim.as_ref().unwrap_or(&failed_sim);
            traces.push(trace(cfg, "analytic", &a.plan, a.peak_torque_nm, sim, 300));
            tracks.push(track("analytic", sim));
        }
        Err(e) => methods.push(MethodSummary::failed("analytic", e)),
    }
    stage_end(&mut progress, clock, analytic.as_ref().err());

    // the robot question first: when the motors cannot flip the cat in
    // this fall, no design at this height is attempted
    let mut answer = None;
    let mut fastest_free: Option<crate::design::free::FreeResult> = None;
    // the phased least height, when no phased schedule fits this fall
    let mut phased_short: Option<f64> = None;
    if limited {
        progress(Progress::Stage {
            index: 2,
            total,
            name: "least drop height (shortest manoeuvre inside the motor envelope)",
        });
        let clock = Instant::now();
        let a = crate::design::least_height::heights(cfg, true, |it| progress(Progress::Scp(it)))
            .map(|h| {
                h.map(|h| {
                    phased_short =
                        (!crate::design::least_height::fits(cfg, h.phased_m)).then_some(h.phased_m);
                    fastest_free = h.free;
                    h.answer
                })
            });
        stage_end(&mut progress, clock, a.as_ref().err());
        match a {
            Ok(Some(a)) => {
                a.schedule.add_to(&mut output, "least-height");
                answer = Some(a);
            }
            Ok(None) => {}
            Err(e) => notes_early.push(format!("The least drop height could not be found: {e}")),
        }
    }
    let impossible = phased_short.map(|least| {
        format!(
            "no phased schedule fits the motors in the fall from {} m (fall.height); the phased time-optimal design needs at least {least:.3} m",
            cfg.fall.height
        )
    });
    let free_impossible = answer.as_ref().filter(|a| !a.possible).map(|a| {
        format!(
            "no schedule found fits the motors in the fall from {} m (fall.height); the least height found is {:.3} m (the {} time design, least-height.csv)",
            a.height_m, a.least_height_m, a.method
        )
    });
    let skipped = |reason: &String| Error::Unreachable {
        reason: reason.clone(),
    };
    let stage = |i: usize| if limited { i + 1 } else { i };

    progress(Progress::Stage {
        index: stage(2),
        total,
        name: "phased optimiser (path-timing SOCPs, bend search)",
    });
    let clock = Instant::now();
    let mut evaluations = 0;
    let phased = match &impossible {
        Some(r) => Err(skipped(r)),
        None => crate::design::phased::optimize(cfg, |e| {
            evaluations += 1;
            progress(Progress::Bend {
                evaluations,
                bend_deg: e.bend_deg,
                peak_nm: e.peak_nm,
            });
        }),
    };
    match &phased {
        Ok(ph) => {
            let ph_sched = Schedule::sample(&cat, &ph.plan, per);
            ph_sched.add_to(&mut output, "phased");
            let ph_sim = ph
                .sim
                .as_ref()
                .expect("phased result carries its simulation");
            methods.push(summarize(
                cfg,
                "phased",
                ph.status.into(),
                ph.peak_torque_nm,
                (ph.bend_deg, ph.twist_rad, ph.phase_durations_s),
                Ok(ph_sim),
                &ph_sched,
                ph.solve_time_s,
            ));
            traces.push(trace(
                cfg,
                "phased",
                &ph.plan,
                ph.peak_torque_nm,
                ph_sim,
                300,
            ));
            tracks.push(track("phased", ph_sim));
        }
        Err(e) => methods.push(MethodSummary::failed("phased", e)),
    }
    match &impossible {
        Some(reason) => progress(Progress::StageSkipped { reason }),
        None => stage_end(&mut progress, clock, phased.as_ref().err()),
    }

    progress(Progress::Stage {
        index: stage(3),
        total,
        name: "free-form optimiser (collocation + SCP, seeded by the phased design, or the analytic one if that failed)",
    });
    let clock = Instant::now();
    // seeded by the phased design, or by the free-form least-time design
    // when no phased one fits, or by the analytic plan when that failed
    let analytic_seed;
    let (seed_plan, seed_name): (&dyn ShapePlan, &str) = match (&phased, &fastest_free) {
        (Ok(ph), _) => (&ph.plan, "phased"),
        (Err(_), Some(fr)) => (&fr.plan, "free least-time"),
        (Err(_), None) => {
            analytic_seed = crate::design::analytic::analytic_plan(cfg);
            (&analytic_seed, "analytic")
        }
    };
    let free = match &free_impossible {
        Some(r) => Err(skipped(r)),
        None => crate::design::free::FreeDesign::new(cfg)
            .from_plan(seed_plan, seed_name)
            .on_iteration(&mut |it| progress(Progress::Scp(it)))
            .solve(),
    };
    match &free {
        Ok(fr) => {
            let fr_sched = Schedule::sample(&cat, &fr.plan, per);
            fr_sched.add_to(&mut output, "free");
            methods.push(summarize(
                cfg,
                "free",
                fr.status.into(),
                fr.peak_torque_nm,
                (fr.bend_deg, fr.twist_rad, fr.phase_durations_s),
                Ok(&fr.sim),
                &fr_sched,
                fr.solve_time_s,
            ));
            traces.push(trace(
                cfg,
                "free",
                &fr.plan,
                fr.peak_torque_nm,
                &fr.sim,
                300,
            ));
            tracks.push(track("free", &fr.sim));
        }
        Err(e) => methods.push(MethodSummary::failed("free", e)),
    }
    match &free_impossible {
        Some(reason) => progress(Progress::StageSkipped { reason }),
        None => stage_end(&mut progress, clock, free.as_ref().err()),
    }

    if let Some(a) = answer.as_mut().filter(|a| !a.possible)
        && let Some(m) = methods
            .iter()
            .find(|m| m.method == "free" && m.verdict == Grade::Ok)
    {
        // a verified free-form schedule inside the envelope settles it
        a.possible = true;
        a.method = m.method;
    }
    if methods.iter().all(|m| m.verdict == Grade::Failed) {
        let reasons: Vec<String> = methods
            .iter()
            .map(|m| format!("{}: {}", m.method, m.reason.as_deref().unwrap_or("")))
            .collect();
        return Err(Error::AllFailed(reasons.join("; ")));
    }

    progress(Progress::Stage {
        index: stage(4),
        total,
        name: "report (figures, summary)",
    });
    let clock = Instant::now();
    // the simulator models and each kept method's controls for them
    let mut plans: Vec<(&str, &dyn ShapePlan)> = Vec::new();
    if let Ok((a, _)) = &analytic {
        plans.push(("analytic", &a.plan));
    }
    if let Ok(ph) = &phased {
        plans.push(("phased", &ph.plan));
    }
    if let Ok(fr) = &free {
        plans.push(("free", &fr.plan));
    }
    crate::export::add_simulator_files(cfg, &mut output, &plans);
    let norm_name = cfg.norm().name().to_string();
    let iterations = free
        .as_ref()
        .map(|fr| fr.iterations.clone())
        .unwrap_or_default();
    // none when the free-form design failed
    let mesh_levels = free
        .as_ref()
        .map_or_else(|_| Vec::new(), |fr| fr.mesh_levels.clone());
    let mut figures = vec![
        ("angles.svg", report::angles(&traces)),
        (
            "torque.svg",
            report::torque(&traces, &norm_name, &cfg.motor()),
        ),
        (
            report::TORQUE_SPEED_SVG,
            report::torque_speed(&traces, &cfg.motor()),
        ),
        ("flip.svg", report::flip(&traces)),
        ("shape_path.svg", report::shape_path(&traces)),
    ];
    if !iterations.is_empty() {
        figures.push((
            "convergence.svg",
            report::convergence(&iterations, &mesh_levels, cfg.design.objective),
        ));
    }
    let mut notes = notes_early;
    let figures: Vec<(&str, String)> = figures
        .into_iter()
        .filter_map(|(name, svg)| match svg {
            Ok(svg) => Some((name, svg)),
            Err(e) => {
                notes.push(format!("Figure {name} is missing: {e}"));
                None
            }
        })
        .collect();
    let peak = |name: &str| methods.iter().find(|m| m.method == name)?.peak();
    let ratio = |a: &str, b: &str| Some(peak(a)? / peak(b)?);
    let (scp_iterations, nodes) = free
        .as_ref()
        .map(|fr| (fr.scp_iterations, fr.nodes))
        .unwrap_or((0, cfg.free.nodes));
    let summary = RunSummary {
        name: cfg.name.clone(),
        joint: cfg.cat.joint.name(),
        peak_norm: cfg.norm(),
        max_torque_nm: cfg.limits.max_torque,
        outcome: if answer.as_ref().is_some_and(|a| !a.possible) {
            "impossible"
        } else if methods.iter().all(|m| m.verdict == Grade::Ok) {
            "ok"
        } else {
            "partial"
        },
        phased_over_analytic: ratio("phased", "analytic"),
        free_over_phased: ratio("free", "phased"),
        methods,
        scp_iterations,
        nodes,
        mesh_levels,
        analytic: crate::design::analytic::closed_forms(cfg),
        figures: figures.iter().map(|f| f.0.to_string()).collect(),
        answer,
    };
    let header = TABLE_HEADER;
    let rows: Vec<Vec<String>> = summary.methods.iter().map(table_row).collect();
    let show = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_else(|| "-".into());
    notes.insert(
        0,
        format!(
            "{} joint, peak norm {norm_name}; fall time {:.4} s, manoeuvre {:.4} s. Free-form / phased peak: {}; phased / analytic: {}. Free-form design: {}.",
            summary.joint,
            summary.analytic.fall_time_s,
            summary.analytic.available_time_s,
            show(summary.free_over_phased),
            show(summary.phased_over_analytic),
            crate::design::free::iterations_text(&summary.mesh_levels)
        ),
    );
    notes.insert(
        1,
        format!(
            "Flip and tilt come from the dynamic forward simulation of each schedule ({}, torque clipped to the motor envelope).",
            if cfg.simulate.pd {
                "feed-forward torque plus PD tracking"
            } else {
                "feed-forward torque only, simulate.pd = false"
            }
        ),
    );
    if let Some(a) = &summary.answer {
        notes.insert(0, a.sentence());
    }
    if summary.outcome == "partial" {
        notes.insert(
            0,
            "PARTIAL RESULT: some methods are flagged or failed; the verdict column says why. Their schedules, if any, are written but miss a target.".into(),
        );
    }
    let figure_names: Vec<&str> = figures.iter().map(|f| f.0).collect();
    // the animation: each simulated method, with its table status and verdict
    for t in &mut tracks {
        if let Some(m) = summary.methods.iter().find(|m| m.method == t.name) {
            let row = table_row(m);
            t.status = format!("{}; {}", row[1], row[row.len() - 1]);
        }
    }
    tracks.retain(|t| t.frames.len() > 1);
    let scene = report::animation::Scene {
        rear: cat.rear,
        front: cat.front,
        joint: summary.joint,
        boxes: report::animation::boxes(&cat),
        norm: norm_name.clone(),
        max_torque_nm: cfg.limits.max_torque,
        tracks,
    };
    let warnings: Vec<String> = summary
        .methods
        .iter()
        .filter_map(|m| Some(format!("{}: {}", m.method, m.reason.as_ref()?)))
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
    stage_end(&mut progress, clock, None);
    Ok(RunResult {
        summary,
        output,
        traces,
        iterations,
    })
}

/// Columns of the comparison table (terminal and index.html).
pub const TABLE_HEADER: [&str; 11] = [
    "method",
    "status",
    "peak N m",
    "energy N2m2s",
    "bend deg",
    "durations s",
    "flip error rad",
    "tilt deg",
    "sim peak N m",
    "solve s",
    "verdict",
];

/// A small number in the table: `0` for exact zero, else 3 significant digits.
fn small(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}

/// One line of the comparison table; a failed method shows `-` for its numbers.
pub fn table_row(m: &MethodSummary) -> Vec<String> {
    let verdict = match (m.verdict, &m.reason) {
        (Grade::Ok, _) => "ok".to_string(),
        (Grade::Flagged, r) => format!("FLAGGED: {}", r.as_deref().unwrap_or("")),
        (Grade::Failed, r) => format!("FAILED: {}", r.as_deref().unwrap_or("")),
    };
    let mut row = vec![m.method.to_string(), m.status.to_string()];
    match &m.result {
        Some(n) => {
            let d = n.phase_durations_s;
            row.extend([
                format!("{:.5}", n.peak_torque_nm),
                format!("{:.4e}", n.energy_n2m2s),
                format!("{:.2}", n.bend_deg),
                format!("{:.3}/{:.3}/{:.3}", d[0], d[1], d[2]),
                small(n.flip_error_rad),
                small(n.tilt_deg),
                format!("{:.5}", n.sim_peak_torque_nm),
                format!("{:.3}", n.solve_time_s),
            ]);
        }
        None => row.extend(std::iter::repeat_n("-".to_string(), 8)),
    }
    row.push(verdict);
    row
}
