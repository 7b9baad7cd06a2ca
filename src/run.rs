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
    /// The limits the designs were held to, as resolved from the config and
    /// its robot file.
    pub limits: LimitsUsed,
    /// `ok` when every method is ok, `partial` when some are flagged or
    /// failed, `impossible` when the motors cannot flip the cat from
    /// `fall.height` (exit 4; `answer` says from what height they can).
    pub outcome: Outcome,
    pub methods: Vec<MethodSummary>,
    /// Peak ratios between methods (absent when either failed).
    pub phased_over_analytic: Option<f64>,
    pub free_over_phased: Option<f64>,
    /// The free-form design's SCP iterations, every mesh (absent when it
    /// was not attempted or failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scp_iterations: Option<usize>,
    pub nodes: usize,
    /// The free-form design's meshes (mesh continuation), coarse to fine.
    pub mesh_levels: Vec<crate::design::free::MeshLevel>,
    /// What the free-form design started from: `phased` (the phased
    /// design), `free least-time` (the least-height stage's design, where no
    /// phased one fits this fall) or `analytic` (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub free_seed: Option<String>,
    pub analytic: ClosedForms,
    pub figures: Vec<String>,
    /// With motor limits: can the motors flip the cat from `fall.height`, and
    /// the least drop height at which they can (absent without limits).
    pub answer: Option<HeightAnswer>,
}

/// The motor and bend limits a run's designs were held to, and where a robot
/// file gave them (`summary.json`'s `limits`).
#[derive(Debug, Clone, Serialize)]
pub struct LimitsUsed {
    pub max_torque_nm: Option<f64>,
    pub no_load_speed_rad_s: Option<f64>,
    pub max_speed_rad_s: Option<f64>,
    pub max_bend_deg: Option<f64>,
    /// `body.urdf` or `body.mjcf` when it gave any of them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<&'static str>,
    /// The `limits.*` keys the file gave (`max_torque`, ...).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub from_file: Vec<&'static str>,
}

impl LimitsUsed {
    pub fn of(cfg: &Config) -> Self {
        let l = &cfg.limits;
        let origin = cfg.limits_from();
        Self {
            max_torque_nm: l.max_torque,
            no_load_speed_rad_s: l.no_load_speed,
            max_speed_rad_s: l.max_speed,
            max_bend_deg: l.max_bend_deg,
            file: origin.file.filter(|_| !origin.keys.is_empty()),
            from_file: origin.keys,
        }
    }

    /// One line for the terminal (`None` without limits): each limit, the
    /// file's marked.
    pub fn line(&self) -> Option<String> {
        let mark = |key: &str| {
            if self.from_file.contains(&key) {
                format!(" (from {})", self.file.unwrap_or("the robot file"))
            } else {
                String::new()
            }
        };
        let parts: Vec<String> = [
            ("max_torque", "stall torque", self.max_torque_nm, "N m"),
            (
                "no_load_speed",
                "no-load speed",
                self.no_load_speed_rad_s,
                "rad/s",
            ),
            ("max_speed", "speed limit", self.max_speed_rad_s, "rad/s"),
            ("max_bend_deg", "bend limit", self.max_bend_deg, "deg"),
        ]
        .into_iter()
        .filter_map(|(key, what, v, unit)| {
            Some(format!("{what} {} {unit}{}", significant(v?, 7), mark(key)))
        })
        .collect();
        (!parts.is_empty()).then(|| format!("limits: {}", parts.join(", ")))
    }
}

/// `x` to `digits` significant digits, without trailing zeros: a limit as
/// typed (1.4, 5.969) stays as typed, one converted from a robot file's
/// radians (114.59155902616465 deg) is shown as 114.5916.
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).clamp(0, 15) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

impl RunSummary {
    /// Why a sound design's peak can be above the stall torque: a DC motor
    /// driven against its speed brakes with more (`T + k |w|`, the torque-speed
    /// line), which a table of peaks alone would read as a broken limit.
    pub fn braking_note(&self) -> Option<String> {
        above_stall(
            self.max_torque_nm,
            self.methods.iter().map(|m| (m.method, m.verdict, m.peak())),
        )
    }

    /// What makes the run partial: each method that counts against it and
    /// why, e.g. `phased not possible in this fall` (empty when none does).
    pub fn against(&self) -> Vec<String> {
        self.methods
            .iter()
            .filter(|m| m.counts_against())
            .map(|m| {
                let why = match m.verdict {
                    Grade::Flagged => "FLAGGED",
                    Grade::Failed => "FAILED",
                    Grade::Impossible => "not possible in this fall",
                    Grade::Ok => "ok",
                };
                format!("{} {why}", m.method)
            })
            .collect()
    }
}

/// A finished run: its summary and the files to write.
pub struct RunResult {
    pub summary: RunSummary,
    pub output: Output,
    pub traces: Vec<MethodTrace>,
    pub iterations: Vec<ScpIteration>,
}

impl RunResult {
    /// True when the run is partial (exit status 3): some design is flagged
    /// or failed in a fall the motors can do. Not when the flip is
    /// impossible ([`RunResult::is_impossible`], exit 4): there the designs
    /// that could not fit are the answer, not failures.
    pub fn is_partial(&self) -> bool {
        self.summary.outcome == Outcome::Partial
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
/// when every method fails is the run an error. The steps: the analytic
/// schedule, the robot question (with motor limits), the phased and the
/// free-form designs, the answer's schedule as a method, the report.
pub fn run(cfg: &Config, progress: impl FnMut(Progress)) -> Result<RunResult> {
    let spec = cfg.design_spec();
    let limited = spec.motor.is_limited();
    let mut stages = Stages {
        index: 0,
        total: if limited { 5 } else { 4 },
        progress,
    };
    let mut done = Methods::default();
    done.analytic(&spec, &cfg.name, &mut stages);
    // the robot question first: when the motors cannot flip the cat in
    // this fall, no design at this height is attempted
    let mut question = if limited {
        Question::asked(&spec, &mut stages)
    } else {
        Question::default()
    };
    done.phased(
        &spec,
        question.phased_impossible(&spec),
        question.phased_hint(&spec),
        &mut stages,
    );
    done.free(&spec, &question, &mut stages);
    question.settle(&spec, &mut done);
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
    let result = report_of(cfg, &spec, done, question);
    stages.end(clock, None);
    Ok(result)
}

/// The robot question's step: the answer, the shortest free-form time
/// design (a seed when no phased design fits), the phased least height
/// when no phased schedule fits this fall (and whether its time design
/// flips in the simulation), and the notes it leaves.
#[derive(Default)]
struct Question {
    answer: Option<HeightAnswer>,
    fastest_free: Option<crate::design::free::FreeResult>,
    phased_short: Option<(f64, bool)>,
    /// The bend of the stage's phased time design, rad.
    phased_bend: Option<f64>,
    seconds: f64,
    notes: Vec<String>,
}

impl Question {
    /// The least-height stage (motors limited).
    fn asked<F: FnMut(Progress)>(spec: &DesignSpec, stages: &mut Stages<F>) -> Question {
        let clock =
            stages.begin("least drop height (shortest manoeuvre inside the motor envelope)");
        let progress = &mut stages.progress;
        let heights = crate::design::least_height::heights(
            spec,
            crate::design::least_height::Families::Both,
            |it| progress(Progress::Scp(it)),
        );
        let mut q = Question {
            seconds: clock.elapsed().as_secs_f64(),
            ..Question::default()
        };
        stages.end(clock, heights.as_ref().err());
        match heights {
            Ok(Some(h)) => {
                // (a failed phased family: its own stage says why)
                q.phased_short = (h.phased_error.is_none()
                    && !crate::design::least_height::fits(spec, h.phased_m))
                .then_some((h.phased_m, h.phased_verified));
                q.fastest_free = h.free;
                q.phased_bend = Some(h.phased_bend);
                // its schedule becomes the least-height method (`settle`)
                q.answer = Some(h.answer);
            }
            Ok(None) => {}
            Err(e) => q
                .notes
                .push(format!("The least drop height could not be found: {e}")),
        }
        q
    }

    /// Why the phased design is not attempted, if no phased schedule fits.
    /// Where the phased least-time design's bend search starts: at the
    /// least-height stage's phased time design, which answers the same
    /// question (no other objective's).
    fn phased_hint(&self, spec: &DesignSpec) -> Option<crate::design::phased::BendHint> {
        let time = spec.objective == crate::design::objective::Objective::Time;
        self.phased_bend
            .filter(|b| time && b.is_finite())
            .and_then(|b| crate::design::phased::BendHint::from_chain(&[b]))
    }

    fn phased_impossible(&self, spec: &DesignSpec) -> Option<String> {
        if let Some(a) = self.answer.as_ref().filter(|a| a.beyond_longest_fall) {
            return Some(crate::pipeline::beyond_reach(a));
        }
        self.phased_short.map(|(least, verified)| {
            // (a lopsided body: the phased family tilts its spine, and its
            // time design can miss the flip, as a sweep's column says)
            let unverified = if verified {
                ""
            } else {
                ", though that design misses the flip in the simulation (not a verified height)"
            };
            format!(
                "no phased schedule fits the motors in the fall from {} m (fall.height); the phased time-optimal design needs at least {least:.3} m{unverified}",
                spec.fall.height
            )
        })
    }

    /// Why the free-form design is not attempted, if no schedule found fits.
    fn free_impossible(&self) -> Option<String> {
        // an unverified answer shows nothing either way: the free-form
        // design is tried in the configured fall
        self.answer
            .as_ref()
            .filter(|a| !a.possible && (a.verified || a.beyond_longest_fall))
            .map(|a| {
                let written = if a.beyond_longest_fall {
                    ""
                } else {
                    ", least-height.csv"
                };
                format!("{}{written}", crate::pipeline::beyond_reach(a))
            })
    }

    /// After the designs: a verified free-form schedule inside the envelope
    /// settles the question, and the answer's schedule becomes a method like
    /// the others (judged, written, drawn, animated and exported; it needs
    /// its own, longer fall).
    fn settle(&mut self, spec: &DesignSpec, done: &mut Methods) {
        // a least-time design continued from the answer's, shorter, inside
        // the envelope and flipping, is the answer: one least time
        if let Some(a) = self.answer.as_mut()
            && let Some(j) = done
                .judged
                .iter()
                .find(|j| matches!(j.design, Design::Free(_)) && j.verdict.is_ok())
            && let (Design::Free(fr), Ok(sim)) = (&j.design, &j.sim)
            && fr.objective == crate::design::objective::Objective::Time
            && fr.seed == crate::pipeline::FREE_LEAST_TIME
        {
            a.improve_with(spec, fr, sim);
        }
        if let Some(a) = self.answer.as_mut().filter(|a| !a.possible)
            && let Some(m) = done
                .lines
                .iter()
                .find(|m| m.method == "free" && m.verdict == Grade::Ok)
        {
            // (an unverified answer stays so: its least height is still
            // the unverified design's, which the sentence says)
            a.possible = true;
            a.method = m.method;
        }
        // (beyond the longest fall there is no schedule to show)
        if let Some(a) = self.answer.as_ref().filter(|a| !a.beyond_longest_fall) {
            let design = Design::LeastHeight(crate::pipeline::LeastHeightDesign::of(spec, a));
            done.add(spec, Method::LeastHeight, Ok((design, self.seconds)));
        }
    }
}

impl Methods {
    /// [`Methods::add`], then the end of its stage line: the line's time
    /// includes the stage's flight of the design (a failure ends the line
    /// first, with its reason).
    fn add_ending<F: FnMut(Progress)>(
        &mut self,
        spec: &DesignSpec,
        method: Method,
        design: Result<(Design, f64)>,
        stages: &mut Stages<F>,
        clock: Instant,
    ) {
        match design {
            Ok(d) => {
                self.add(spec, method, Ok(d));
                stages.end(clock, None);
            }
            Err(e) => {
                stages.end(clock, Some(&e));
                self.add(spec, method, Err(e));
            }
        }
    }

    /// The analytic step: the kinematic check is part of the analysis; a
    /// failed dynamic simulation (e.g. under a saturating torque limit)
    /// only flags the schedule.
    fn analytic<F: FnMut(Progress)>(
        &mut self,
        spec: &DesignSpec,
        name: &str,
        stages: &mut Stages<F>,
    ) {
        let clock = stages.begin("analytic schedule (seed closed forms, errata corrected)");
        let analytic = analyze(spec, name);
        let seconds = clock.elapsed().as_secs_f64();
        let design = analytic.map(|a| (Design::Analytic(a), seconds));
        self.add_ending(spec, Method::Analytic, design, stages, clock);
    }

    /// The phased step, or why it is not attempted (`impossible`).
    fn phased<F: FnMut(Progress)>(
        &mut self,
        spec: &DesignSpec,
        impossible: Option<String>,
        hint: Option<crate::design::phased::BendHint>,
        stages: &mut Stages<F>,
    ) {
        let clock = stages.begin("phased optimiser (path-timing SOCPs, bend search)");
        if let Some(reason) = impossible {
            (stages.progress)(Progress::StageSkipped { reason: &reason });
            self.skip(Method::Phased, &reason);
            return;
        }
        let mut evaluations = 0;
        let progress = &mut stages.progress;
        let phased = crate::design::phased::optimize_near(spec, hint, |e| {
            evaluations += 1;
            progress(Progress::Bend {
                evaluations,
                bend_deg: e.bend_deg,
                peak_nm: e.peak_nm,
            });
        });
        let design = phased.map(|ph| {
            let t = ph.solve_time_s;
            (Design::Phased(ph), t)
        });
        self.add_ending(spec, Method::Phased, design, stages, clock);
    }

    /// The free-form step: seeded by the phased design, or by the free-form
    /// least-time design when no phased one fits, or by the analytic plan
    /// when that failed; not attempted when no schedule found fits. A
    /// least-time design continues from the least-height stage's shortest
    /// one, which answers the same question.
    fn free<F: FnMut(Progress)>(
        &mut self,
        spec: &DesignSpec,
        q: &Question,
        stages: &mut Stages<F>,
    ) {
        let clock = stages.begin(
            if spec.objective == crate::design::objective::Objective::Time {
                "free-form optimiser (collocation + SCP, continued from the least-height design, else seeded by the phased design, else by the analytic schedule)"
            } else {
                "free-form optimiser (collocation + SCP, seeded by the phased design, else by the least-height design, else by the analytic schedule)"
            },
        );
        if let Some(reason) = q.free_impossible() {
            (stages.progress)(Progress::StageSkipped { reason: &reason });
            self.skip(Method::Free, &reason);
            return;
        }
        let analytic_seed;
        let time = spec.objective == crate::design::objective::Objective::Time;
        let least_time = crate::pipeline::FREE_LEAST_TIME;
        let design = crate::design::free::FreeDesign::new(spec);
        let (design, seed_name) = match (self.design(Method::Phased), &q.fastest_free) {
            // the least time: the least-height stage's shortest design answers
            // the same question (a time design has no budget, so the reference
            // drop it was made for does not bind); continued from that design
            // itself, on its mesh, with its check points, weight and radius
            (_, Some(fr)) if time => (design.warm(fr, None).named(least_time), least_time),
            (Some(ph), _) => (design.from_plan(ph.plan(), "phased"), "phased"),
            (None, Some(fr)) => (design.from_plan(&fr.plan, least_time), least_time),
            (None, None) => {
                analytic_seed = crate::design::analytic::analytic_plan(spec);
                (design.from_plan(&analytic_seed, "analytic"), "analytic")
            }
        };
        let progress = &mut stages.progress;
        let free = design
            .on_iteration(&mut |it| progress(Progress::Scp(it)))
            .solve();
        // from the least-height design, in a fall the answer says it does:
        // the failure is this design's, and the user's schedule is that one
        let least = q
            .answer
            .as_ref()
            .filter(|a| seed_name == crate::pipeline::FREE_LEAST_TIME && a.possible)
            .map(|a| a.least_height_m);
        let free = crate::pipeline::short_of_answer(spec, least, free, "its row, least-height.csv");
        let design = free.map(|fr| {
            let t = fr.solve_time_s;
            (Design::Free(fr), t)
        });
        self.add_ending(spec, Method::Free, design, stages, clock);
    }
}

/// The report step: simulator files, figures, the summary, the page.
fn report_of(cfg: &Config, spec: &DesignSpec, done: Methods, question: Question) -> RunResult {
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
    let traces: Vec<MethodTrace> = judged.iter().map(|j| j.trace(spec, 300)).collect();
    let free = judged.iter().find_map(|j| match &j.design {
        Design::Free(fr) => Some(fr),
        _ => None,
    });
    let iterations = free.map(|fr| fr.iterations.clone()).unwrap_or_default();
    // none when the free-form design failed
    let mesh_levels = free.map(|fr| fr.mesh_levels.clone()).unwrap_or_default();
    let free_seed = free.map(|fr| fr.seed.clone());
    let mut notes = question.notes;
    let figures = figures(cfg, &traces, &iterations, &mesh_levels, &mut notes);
    let peak = |name: &str| methods.iter().find(|m| m.method == name)?.peak();
    let ratio = |a: &str, b: &str| Some(peak(a)? / peak(b)?);
    let scp_iterations = free.map(|fr| fr.scp_iterations);
    let nodes = free.map_or(cfg.free.nodes, |fr| fr.nodes);
    let answer = question.answer;
    let summary = RunSummary {
        name: cfg.name.clone(),
        joint: cfg.cat.joint.name(),
        peak_norm: cfg.norm(),
        max_torque_nm: cfg.limits.max_torque,
        limits: LimitsUsed::of(cfg),
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
        free_seed,
        analytic: crate::design::analytic::closed_forms(spec),
        figures: figures.iter().map(|f| f.0.to_string()).collect(),
        answer,
    };
    page_notes(cfg, &summary, &mut notes);
    let figure_names: Vec<&str> = figures.iter().map(|f| f.0).collect();
    let tracks: Vec<_> = judged.iter().map(|j| j.track(spec)).collect();
    let html = page(cfg, &summary, &notes, tracks, &figure_names);
    output.add("index.html", html);
    for (name, svg) in figures {
        output.add(name, svg);
    }
    output.add(
        "summary.json",
        serde_json::to_string_pretty(&summary).expect("summary serialises"),
    );
    RunResult {
        summary,
        output,
        traces,
        iterations,
    }
}

/// The run's figures; one that cannot be drawn is left out with a note.
fn figures(
    cfg: &Config,
    traces: &[MethodTrace],
    iterations: &[ScpIteration],
    mesh_levels: &[crate::design::free::MeshLevel],
    notes: &mut Vec<String>,
) -> Vec<(&'static str, String)> {
    let norm_name = cfg.norm().name();
    let mut figures = vec![
        ("angles.svg", report::angles(traces)),
        (
            "torque.svg",
            report::torque(traces, norm_name, &cfg.motor()),
        ),
        (
            report::TORQUE_SPEED_SVG,
            report::torque_speed(traces, &cfg.motor()),
        ),
        ("flip.svg", report::flip(traces)),
        ("shape_path.svg", report::shape_path(traces)),
    ];
    if !iterations.is_empty() {
        figures.push((
            "convergence.svg",
            report::convergence(iterations, mesh_levels, cfg.design.objective),
        ));
    }
    figures
        .into_iter()
        .filter_map(|(name, svg)| match svg {
            Ok(svg) => Some((name, svg)),
            Err(e) => {
                notes.push(format!("Figure {name} is missing: {e}"));
                None
            }
        })
        .collect()
}

/// The page's notes above the figures: the comparison in a sentence, where
/// the flip comes from, and the partial result first when it is one.
fn page_notes(cfg: &Config, summary: &RunSummary, notes: &mut Vec<String>) {
    let ratios = crate::table::peak_ratios(summary.free_over_phased, summary.phased_over_analytic);
    notes.insert(
        0,
        format!(
            "{} joint, peak norm {}; dropped from {} m (fall.height): fall time {:.4} s, manoeuvre {:.4} s. {}{}Free-form design: {}.",
            summary.joint,
            cfg.norm().name(),
            cfg.fall.height,
            summary.analytic.fall_time_s,
            summary.analytic.available_time_s,
            // (the ratios' own words start lower case: a sentence here)
            ratios.get(..1).map(str::to_uppercase).unwrap_or_default() + ratios.get(1..).unwrap_or(""),
            if ratios.is_empty() { "" } else { ". " },
            crate::table::free_design_text(
                &summary.methods,
                &summary.mesh_levels,
                summary.free_seed.as_deref()
            )
        ),
    );
    notes.insert(
        1,
        format!(
            "Flip and tilt come from the dynamic forward simulation of each schedule ({}{}).",
            if cfg.simulate.pd {
                "feed-forward torque plus PD tracking"
            } else {
                "feed-forward torque only, simulate.pd = false"
            },
            if cfg.motor().is_limited() {
                ", torque clipped to the motor envelope"
            } else {
                "; no motor limits are configured"
            }
        ),
    );
    // the answer says from what height; this says what to fly from this one
    if let Some(a) = summary.answer.as_ref().filter(|a| a.possible)
        && let Some((m, peak)) = ["free", "phased"].into_iter().find_map(|name| {
            summary
                .methods
                .iter()
                .find(|m| m.method == name && m.verdict == Grade::Ok)
                .and_then(|m| m.peak().map(|p| (m.method, p)))
        })
    {
        // the free-form design is the optimum of the objective; the phased
        // one the certified family's
        notes.insert(
            0,
            format!(
                "To fly from {} m: {m}.csv ({m}.mujoco.csv and {m}.pybullet.csv for the simulators), the {} design for design.objective = {} (peak {peak:.4} N m); least-height.csv is made for its own {:.3} m drop.",
                a.height_m,
                if m == "free" { "free-form" } else { "phased" },
                cfg.design.objective.name(),
                a.least_height_m
            ),
        );
    }
    // a sound design above the stall torque: as the terminal says it
    if let Some(n) = summary.braking_note() {
        notes.insert(2, n);
    }
    if summary.outcome == Outcome::Partial {
        notes.insert(
            0,
            format!(
                "PARTIAL RESULT: {}; the verdict column says why.{}",
                summary.against().join(", "),
                if summary
                    .methods
                    .iter()
                    .any(|m| m.counts_against() && m.verdict == Grade::Flagged)
                {
                    " A flagged method's schedule is written but misses a target."
                } else {
                    ""
                }
            ),
        );
    }
}

/// `index.html`: the answer, the table, warnings, notes, the animation of
/// each simulated method (with its table status and verdict), the figures.
fn page(
    cfg: &Config,
    summary: &RunSummary,
    notes: &[String],
    mut tracks: Vec<report::animation::Track>,
    figure_names: &[&str],
) -> String {
    let rows: Vec<Vec<String>> = summary.methods.iter().map(table_row).collect();
    for t in &mut tracks {
        if let Some(m) = summary.methods.iter().find(|m| m.method == t.name) {
            t.status = track_status(m);
            // its own drop, not the configured one
            if m.method == Method::LeastHeight.name()
                && let Some(a) = &summary.answer
            {
                t.status = format!("for a drop from {:.3} m; {}", a.least_height_m, t.status);
            }
        }
    }
    tracks.retain(|t| t.frames.len() > 1);
    let cat = cfg.cat();
    let scene = report::animation::Scene {
        rear: cat.rear,
        front: cat.front,
        joint: summary.joint,
        boxes: report::animation::boxes(&cat),
        norm: cfg.norm().name().to_string(),
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
    // what to fly from this height leads with the answer (it read after the table)
    let fly = notes.iter().position(|n| n.starts_with("To fly from "));
    let lead = summary
        .answer
        .as_ref()
        .map(|a| report::answer::lead_with(a, fly.map(|i| notes[i].as_str())));
    let notes: Vec<String> = notes
        .iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != fly)
        .map(|(_, n)| n.clone())
        .collect();
    report::index_html(&report::Page {
        // (the height tells apart the pages of one body asked from two)
        title: &format!(
            "catflip report: {}, dropped from {} m",
            cfg.name, cfg.fall.height
        ),
        lead: lead.as_deref(),
        header: &TABLE_HEADER,
        rows: &rows,
        notes: &notes,
        warnings: &warnings,
        animation: &report::animation::section(&scene),
        figures: figure_names,
        captions: if cfg.motor().is_limited() {
            report::caption
        } else {
            report::caption_without_limits
        },
        glossary: true,
    })
}

/// A method's summary line: see [`crate::pipeline`] (its table: [`crate::table`]).
pub use crate::pipeline::{MethodNumbers, MethodSummary};

/// [`RunSummary::braking_note`] on the stall torque and each method's name, verdict and
/// peak: a note for the sound ones (verdict ok) above the stall torque.
fn above_stall<'a>(
    stall: Option<f64>,
    methods: impl Iterator<Item = (&'a str, Grade, Option<f64>)>,
) -> Option<String> {
    let stall = stall?;
    let above: Vec<&str> = methods
        .filter(|&(_, verdict, peak)| sound_above(stall, verdict, peak))
        .map(|(name, _, _)| name)
        .collect();
    (!above.is_empty()).then(|| format!("{}: {}", above.join(", "), braking_words(stall)))
}

/// Whether a design judged `verdict` is a sound one whose `peak` is above
/// the `stall` torque (beyond rounding): braking inside the torque-speed line.
pub fn sound_above(stall: f64, verdict: Grade, peak: Option<f64>) -> bool {
    verdict == Grade::Ok && peak.is_some_and(|p| p > stall * (1.0 + 1e-6))
}

/// The braking note's words, after the names of the designs it is about
/// (`run`'s note; `optimize`'s peak row).
pub fn braking_words(stall: f64) -> String {
    format!(
        "peak above the {stall} N m stall torque while braking, which the motor's torque-speed line allows (T + k |w| against the speed; docs/model.md, section 5)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Limits print as typed, or to 7 significant digits when converted.
    #[test]
    fn a_limit_prints_as_typed_or_to_seven_digits() {
        assert_eq!(significant(1.4, 7), "1.4");
        assert_eq!(significant(5.969, 7), "5.969");
        assert_eq!(significant(114.59155902616465, 7), "114.5916");
        assert_eq!(significant(175.0, 7), "175");
        assert_eq!(significant(2.5e-4, 7), "0.00025");
    }

    /// Only a sound design above the stall torque gets the note: a flagged
    /// one breaks its limit (its reason says so), and without a stall
    /// torque there is nothing to be above.
    #[test]
    fn the_braking_note_names_the_sound_designs_above_the_stall_torque() {
        let rows = [
            ("analytic", Grade::Flagged, Some(3.0)),
            ("free", Grade::Ok, Some(1.2)),
            ("least-height", Grade::Ok, Some(2.0)),
            ("phased", Grade::Impossible, None),
        ];
        let note = above_stall(Some(1.4), rows.into_iter()).expect("a note");
        assert!(
            note.starts_with("least-height: peak above the 1.4 N m"),
            "{note}"
        );
        assert!(
            !note.contains("analytic") && !note.contains("free"),
            "{note}"
        );
        assert_eq!(above_stall(None, rows.into_iter()), None);
        assert_eq!(above_stall(Some(3.5), rows.into_iter()), None);
        // at the stall torque to rounding: no note
        assert_eq!(
            above_stall(
                Some(2.0),
                [("free", Grade::Ok, Some(2.0 * (1.0 + 1e-9)))].into_iter()
            ),
            None
        );
    }
}
