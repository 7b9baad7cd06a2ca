//! `catflip run`: the main job. Analytic schedule, phased and free-form
//! optimisation, forward verification of all three, and the report.

use crate::config::Config;
use crate::design::analytic::ClosedForms;
use crate::design::least_height::HeightAnswer;
use crate::design::plan::ShapePlan;
use crate::design::scp::ScpIteration;
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};
use crate::output::Output;
use crate::pipeline::{self, Design, Judged, Method};
use crate::report::{self, MethodTrace};
use crate::table::{TABLE_HEADER, table_row, track_status};
use crate::verdict::Grade;
use crate::verify::analyze::analyze;
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

/// How a run ended, as the summary and the exit status see it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// Every method meets its targets (exit 0).
    Ok,
    /// Some methods are flagged or failed; their reasons are in the summary (exit 3).
    Partial,
    /// The motors cannot flip the cat from `fall.height` (exit 4).
    Impossible,
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
    pub outcome: Outcome,
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
        self.summary.outcome != Outcome::Ok
    }

    /// True when the motors cannot flip the cat from the configured height.
    pub fn is_impossible(&self) -> bool {
        self.summary.outcome == Outcome::Impossible
    }
}

/// The stage lines a run reports: numbered, each done, failed or skipped.
struct Stages<F: FnMut(Progress)> {
    index: usize,
    total: usize,
    progress: F,
}

impl<F: FnMut(Progress)> Stages<F> {
    fn begin(&mut self, name: &str) -> Instant {
        self.index += 1;
        (self.progress)(Progress::Stage {
            index: self.index,
            total: self.total,
            name,
        });
        Instant::now()
    }

    fn end(&mut self, clock: Instant, err: Option<&Error>) {
        let seconds = clock.elapsed().as_secs_f64();
        match err {
            None => (self.progress)(Progress::StageDone { seconds }),
            Some(e) => (self.progress)(Progress::StageFailed {
                seconds,
                reason: &e.to_string(),
            }),
        }
    }
}

/// The methods so far: each one's summary line, its judged design (when
/// it produced one) and the files written so far.
#[derive(Default)]
struct Methods {
    output: Output,
    lines: Vec<MethodSummary>,
    judged: Vec<Judged>,
}

impl Methods {
    /// A method's design, `seconds` to make, through the pipeline stage;
    /// or why it failed.
    fn add(&mut self, spec: &DesignSpec, method: Method, design: Result<(Design, f64)>) {
        match design {
            Ok((d, seconds)) => {
                let j = pipeline::stage(spec, d, seconds);
                j.add_files(&mut self.output);
                self.lines.push(j.summary.clone());
                self.judged.push(j);
            }
            Err(e) => self.lines.push(MethodSummary::failed(method, &e)),
        }
    }

    /// A method not attempted: the motors cannot do it in this fall.
    fn skip(&mut self, method: Method, why: &str) {
        self.lines.push(MethodSummary::impossible(method, why));
    }

    fn design(&self, method: Method) -> Option<&Design> {
        self.judged
            .iter()
            .map(|j| &j.design)
            .find(|d| d.method() == method)
    }
}

/// Runs everything for one config. A method that fails does not stop the
/// others: its status and reason go into the summary, table and report. Only
/// when every method fails is the run an error.
pub fn run(cfg: &Config, progress: impl FnMut(Progress)) -> Result<RunResult> {
    let spec = cfg.design_spec();
    let limited = spec.motor.is_limited();
    let cat = cfg.cat();
    let mut stages = Stages {
        index: 0,
        total: if limited { 5 } else { 4 },
        progress,
    };
    let mut done = Methods::default();
    let mut notes_early: Vec<String> = Vec::new();

    let clock = stages.begin("analytic schedule (seed closed forms, errata corrected)");
    // the kinematic check is part of the analysis; a failed dynamic
    // simulation (e.g. under a saturating torque limit) only flags the schedule
    let analytic = analyze(&spec, &cfg.name);
    let seconds = clock.elapsed().as_secs_f64();
    match analytic {
        Ok(a) => {
            done.add(&spec, Method::Analytic, Ok((Design::Analytic(a), seconds)));
            stages.end(clock, None);
        }
        Err(e) => {
            stages.end(clock, Some(&e));
            done.add(&spec, Method::Analytic, Err(e));
        }
    }

    // the robot question first: when the motors cannot flip the cat in
    // this fall, no design at this height is attempted
    let mut answer = None;
    let mut fastest_free: Option<crate::design::free::FreeResult> = None;
    // the phased least height, when no phased schedule fits this fall
    let mut phased_short: Option<f64> = None;
    let mut least_seconds = 0.0;
    if limited {
        let clock =
            stages.begin("least drop height (shortest manoeuvre inside the motor envelope)");
        let progress = &mut stages.progress;
        let a = crate::design::least_height::heights(&spec, true, |it| progress(Progress::Scp(it)))
            .map(|h| {
                h.map(|h| {
                    phased_short = (!crate::design::least_height::fits(&spec, h.phased_m))
                        .then_some(h.phased_m);
                    fastest_free = h.free;
                    h.answer
                })
            });
        least_seconds = clock.elapsed().as_secs_f64();
        stages.end(clock, a.as_ref().err());
        match a {
            // its schedule becomes the least-height method below
            Ok(Some(a)) => answer = Some(a),
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

    let clock = stages.begin("phased optimiser (path-timing SOCPs, bend search)");
    match &impossible {
        Some(reason) => {
            (stages.progress)(Progress::StageSkipped { reason });
            done.skip(Method::Phased, reason);
        }
        None => {
            let mut evaluations = 0;
            let progress = &mut stages.progress;
            let phased = crate::design::phased::optimize(&spec, |e| {
                evaluations += 1;
                progress(Progress::Bend {
                    evaluations,
                    bend_deg: e.bend_deg,
                    peak_nm: e.peak_nm,
                });
            });
            stages.end(clock, phased.as_ref().err());
            done.add(
                &spec,
                Method::Phased,
                phased.map(|ph| {
                    let t = ph.solve_time_s;
                    (Design::Phased(ph), t)
                }),
            );
        }
    }

    let clock = stages.begin(
        "free-form optimiser (collocation + SCP, seeded by the phased design, or the analytic one if that failed)",
    );
    // seeded by the phased design, or by the free-form least-time design
    // when no phased one fits, or by the analytic plan when that failed
    let analytic_seed;
    let (seed_plan, seed_name): (&dyn ShapePlan, &str) =
        match (done.design(Method::Phased), &fastest_free) {
            (Some(ph), _) => (ph.plan(), "phased"),
            (None, Some(fr)) => (&fr.plan, "free least-time"),
            (None, None) => {
                analytic_seed = crate::design::analytic::analytic_plan(&spec);
                (&analytic_seed, "analytic")
            }
        };
    match &free_impossible {
        Some(reason) => {
            (stages.progress)(Progress::StageSkipped { reason });
            done.skip(Method::Free, reason);
        }
        None => {
            let progress = &mut stages.progress;
            let free = crate::design::free::FreeDesign::new(&spec)
                .from_plan(seed_plan, seed_name)
                .on_iteration(&mut |it| progress(Progress::Scp(it)))
                .solve();
            stages.end(clock, free.as_ref().err());
            done.add(
                &spec,
                Method::Free,
                free.map(|fr| {
                    let t = fr.solve_time_s;
                    (Design::Free(fr), t)
                }),
            );
        }
    }

    if let Some(a) = answer.as_mut().filter(|a| !a.possible)
        && let Some(m) = done
            .lines
            .iter()
            .find(|m| m.method == "free" && m.verdict == Grade::Ok)
    {
        // a verified free-form schedule inside the envelope settles it
        a.possible = true;
        a.method = m.method;
    }
    // the answer's schedule, a method like the others: judged, written,
    // drawn, animated and exported (it needs its own, longer fall)
    if let Some(a) = &answer {
        done.add(
            &spec,
            Method::LeastHeight,
            Ok((
                Design::LeastHeight(crate::pipeline::LeastHeightDesign::of(&spec, a)),
                least_seconds,
            )),
        );
    }
    if done.lines.iter().all(|m| m.verdict == Grade::Failed) {
        let reasons: Vec<String> = done
            .lines
            .iter()
            .map(|m| format!("{}: {}", m.method, m.reason.as_deref().unwrap_or("")))
            .collect();
        return Err(Error::AllFailed(reasons.join("; ")));
    }

    stages.begin("report (figures, summary)");
    let clock = Instant::now();
    let Methods {
        mut output,
        lines: methods,
        judged,
    } = done;
    // the simulator models and each kept method's controls for them
    let plans: Vec<(&str, &dyn ShapePlan)> = judged
        .iter()
        .map(|j| (j.design.method().name(), j.design.plan()))
        .collect();
    crate::export::add_simulator_files(cfg, &mut output, &plans);
    let traces: Vec<MethodTrace> = judged.iter().map(|j| j.trace(&spec, 300)).collect();
    let mut tracks: Vec<_> = judged.iter().map(|j| j.track(&spec)).collect();
    let free = judged.iter().find_map(|j| match &j.design {
        Design::Free(fr) => Some(fr),
        _ => None,
    });
    let norm_name = cfg.norm().name().to_string();
    let iterations = free.map(|fr| fr.iterations.clone()).unwrap_or_default();
    // none when the free-form design failed
    let mesh_levels = free.map(|fr| fr.mesh_levels.clone()).unwrap_or_default();
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
        .map(|fr| (fr.scp_iterations, fr.nodes))
        .unwrap_or((0, cfg.free.nodes));
    let summary = RunSummary {
        name: cfg.name.clone(),
        joint: cfg.cat.joint.name(),
        peak_norm: cfg.norm(),
        max_torque_nm: cfg.limits.max_torque,
        outcome: if answer.as_ref().is_some_and(|a| !a.possible) {
            Outcome::Impossible
        } else if methods.iter().any(MethodSummary::counts_against) {
            Outcome::Partial
        } else {
            Outcome::Ok
        },
        phased_over_analytic: ratio("phased", "analytic"),
        free_over_phased: ratio("free", "phased"),
        methods,
        scp_iterations,
        nodes,
        mesh_levels,
        analytic: crate::design::analytic::closed_forms(&spec),
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
            crate::table::free_design_text(&summary.methods, &summary.mesh_levels)
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
    if summary.outcome == Outcome::Partial {
        notes.insert(
            0,
            "PARTIAL RESULT: some methods are flagged or failed; the verdict column says why. Their schedules, if any, are written but miss a target.".into(),
        );
    }
    let figure_names: Vec<&str> = figures.iter().map(|f| f.0).collect();
    // the animation: each simulated method, with its table status and verdict
    for t in &mut tracks {
        if let Some(m) = summary.methods.iter().find(|m| m.method == t.name) {
            t.status = track_status(m);
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
    // (a method the motors cannot do in this fall is the answer, above, not a warning)
    let warnings: Vec<String> = summary
        .methods
        .iter()
        .filter(|m| m.verdict != Grade::Impossible)
        .filter_map(crate::table::warning)
        .collect();
    let lead = summary.answer.as_ref().map(report::answer::lead);
    output.add(
        "index.html",
        report::index_html(&report::Page {
            title: &format!("catflip report: {}", cfg.name),
            lead: lead.as_deref(),
            header: &header,
            rows: &rows,
            notes: &notes,
            warnings: &warnings,
            animation: &report::animation::section(&scene),
            figures: &figure_names,
        }),
    );
    for (name, svg) in figures {
        output.add(name, svg);
    }
    output.add(
        "summary.json",
        serde_json::to_string_pretty(&summary).expect("summary serialises"),
    );
    stages.end(clock, None);
    Ok(RunResult {
        summary,
        output,
        traces,
        iterations,
    })
}

/// A method's summary line: see [`crate::pipeline`] (its table: [`crate::table`]).
pub use crate::pipeline::{MethodNumbers, MethodSummary};
