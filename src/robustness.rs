//! `catflip robustness`: the command-line face of [`catflip::control::robustness`].

use crate::common::{Common, Progress, Status, load, publish_partial, publisher, say, say_lines};
use anyhow::Result;
use catflip::control::resume::{Published, StudyState};
use catflip::control::robustness::{
    DEFAULT_MAX_TILT_DEG, Study, TrialResult, replan_timing, shard_range, summarise, to_csv,
};
use catflip::interrupt::{Outcome, supervise};
use catflip::output::Output;
use catflip::sweep::Shard;
use catflip::sweep::resume::SweepStatus;
use std::sync::{Arc, Mutex};

/// The study's checked arguments.
pub struct StudyArgs {
    /// In `[1, MAX_TRIALS]`.
    pub trials: usize,
    pub seed: u64,
    /// At least 1.
    pub threads: usize,
    pub shard: Shard,
    pub resume: bool,
    /// A replan over this wall time, ms, is dropped (None: every one counts).
    pub replan_budget_ms: Option<f64>,
}

pub fn cmd_robustness(c: &Common, args: StudyArgs) -> Result<Status> {
    let StudyArgs {
        trials,
        seed,
        threads,
        shard,
        resume,
        replan_budget_ms,
    } = args;
    let cfg = load(c)?;
    let suffix = shard.suffix();
    let publisher = publisher(c, &cfg, &format!("robustness{suffix}"))?;
    let range = shard_range(trials, shard.index, shard.count);
    if range.is_empty() {
        eprintln!(
            "warning: shard {}/{} holds no trials: the study has {}; use at most that many shards",
            shard.index,
            shard.count,
            catflip::console::count(trials, "trial")
        );
    }
    warn_of_delay_mismatch(&cfg);
    let state = StudyState {
        status: SweepStatus::Partial,
        trials,
        seed,
        shard: format!("{}/{}", shard.index, shard.count),
        replan_budget_ms,
        config: serde_json::to_value(&cfg)?,
    };
    let mut kept = vec![None; range.len()];
    if resume {
        let old = state.resume_from(&publisher.link(), &suffix, range.clone())?;
        eprintln!(
            "resuming: {} of {} kept from {}",
            old.len(),
            catflip::console::count(range.len(), "trial"),
            publisher.link().display()
        );
        for r in old {
            let i = r.draw.trial - range.start;
            kept[i] = Some(r);
        }
    }
    let max_tilt_deg = cfg.land.max_tilt_deg.unwrap_or(DEFAULT_MAX_TILT_DEG);
    let quiet = c.json;
    let progress = Progress::new(quiet);
    // the trials land in a store this thread reads when a signal stops the study
    let store = Arc::new(Mutex::new(kept));
    let interrupt = catflip::interrupt::Interrupt::catch()?;
    // what the page says of the design the controllers fly
    let flown = Arc::new(Mutex::new(None::<String>));
    let work = {
        let (cfg, store, range) = (cfg.clone(), store.clone(), range.clone());
        let flown = flown.clone();
        move || -> catflip::Result<()> {
            let design = catflip::control::robustness::design(&cfg)?;
            *flown.lock().unwrap_or_else(|p| p.into_inner()) = Some(described(&design));
            let mut study = Study::new(&cfg, Arc::new(design.plan), seed)?;
            study.replanning.budget_s = replan_budget_ms.map(|b| 1e-3 * b);
            // the trials' own clock: the design before them would make the
            // first trials' rate, and the time left, many times too long
            let clock = std::time::Instant::now();
            study.run_into(range, threads, &store, |done, total| {
                // a log gets a line per 5 % of the trials
                if progress.is_live() || done % (total / 20).max(1) == 0 || done == total {
                    progress.show(&catflip::console::progress::bar(
                        "robustness",
                        done,
                        total,
                        "trials",
                        clock.elapsed().as_secs_f64(),
                    ));
                }
            });
            Ok(())
        }
    };
    let outcome = supervise(&interrupt, work);
    progress.finish();
    let slots = store.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let interrupted = match outcome {
        Outcome::Finished(r) => {
            r?;
            false
        }
        Outcome::Interrupted => true,
    };
    let results: Vec<TrialResult> = slots.into_iter().flatten().collect();
    let flown = flown.lock().unwrap_or_else(|p| p.into_inner()).take();
    let state = StudyState {
        status: if interrupted {
            SweepStatus::Partial
        } else {
            SweepStatus::Complete
        },
        ..state
    };
    let summary = summarise(&results, seed, max_tilt_deg, cfg.robustness.worst_kept);
    let json = serde_json::to_string_pretty(&Published {
        status: state.status,
        summary: &summary,
    })?;
    let mut out = Output::default();
    out.add(
        format!("robustness{suffix}.csv"),
        to_csv(&results, shard.index == 1),
    );
    out.add(format!("robustness{suffix}.json"), json.clone());
    // wall times: beside the study's files, not in them (they differ run to run)
    let timing = replan_timing(&results, cfg.control.period());
    // a resume that flew no trial keeps the times of the run that did (it
    // would write none)
    let timing = match timing.trials_timed {
        0 if resume => std::fs::read_to_string(
            publisher
                .link()
                .join(format!("robustness{suffix}.timing.json")),
        )
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(timing),
        _ => timing,
    };
    out.add(
        format!("robustness{suffix}.timing.json"),
        serde_json::to_string_pretty(&timing)?,
    );
    let late = catflip::console::robustness::late_replans(&timing, replan_budget_ms);
    let figure = format!("robustness{suffix}.svg");
    let bins = catflip::control::figure::bins(&cfg, &results, max_tilt_deg);
    let drawn = if let Some(svg) = catflip::control::figure::success_by_size(&bins, max_tilt_deg)? {
        out.add(figure.clone(), svg);
        true
    } else {
        false
    };
    out.add(
        "index.html",
        page(
            &cfg,
            &summary,
            &timing,
            (&range, trials),
            interrupted,
            drawn.then_some((figure.as_str(), bins.as_slice())),
            (flown.as_deref(), replan_budget_ms, late.as_slice()),
        ),
    );
    out.add(
        StudyState::file_name(&suffix),
        serde_json::to_string_pretty(&state)?,
    );
    if interrupted {
        // published as a partial set, the trials in flight left unfinished
        return publish_partial(
            publisher,
            out,
            c.json.then_some(json.as_str()),
            &format!(
                "{} of {}",
                results.len(),
                catflip::console::count(range.len(), "trial")
            ),
            "; the same command with --resume continues it",
        );
    }
    let written = publisher.publish(out)?;
    if let Some(w) = &late {
        eprintln!("warning: {w}");
    }
    if c.json {
        say!("{json}");
    } else {
        let mut lines = catflip::console::robustness::study(
            &summary,
            &timing,
            results.len(),
            range,
            trials,
            seed,
            &written,
        );
        if let Some(d) = &flown {
            lines.insert(1, format!("  the controllers fly {d}"));
        }
        say_lines(lines);
    }
    Ok(Status::Ok)
}

/// Says on stderr when the controllers predict over another delay than the
/// simulated robot has (a study and a trial flown again alike).
fn warn_of_delay_mismatch(cfg: &catflip::config::Config) {
    if cfg.control.delay_ms != cfg.robustness.delay_ms {
        eprintln!(
            "warning: the controllers predict over a delay of {} ms (control.delay_ms) but the simulated robot's is {} ms (robustness.delay_ms); set both to your robot's delay to study it",
            cfg.control.delay_ms, cfg.robustness.delay_ms
        );
    }
}

/// `robustness --trial K`: trial `k` of the study `args` describes flown
/// again under each controller, its flights written and shown.
pub fn cmd_trial(c: &Common, args: StudyArgs, k: usize) -> Result<Status> {
    use catflip::control::replay;
    if k >= args.trials {
        return Err(catflip::Error::Usage(format!(
            "--trial {k}: the study has {} (numbered 0 to {}); give a trial below --trials, or a larger --trials",
            catflip::console::count(args.trials, "trial"),
            args.trials - 1
        ))
        .into());
    }
    let cfg = load(c)?;
    warn_of_delay_mismatch(&cfg);
    let publisher = publisher(c, &cfg, &format!("robustness-trial-{k}"))?;
    let design = catflip::control::robustness::design(&cfg)?;
    let flown = described(&design);
    let mut study = Study::new(&cfg, Arc::new(design.plan), args.seed)?;
    study.replanning.budget_s = args.replan_budget_ms.map(|b| 1e-3 * b);
    let r = study.replay(k, replay::every(study.reference.h), args.threads > 1);
    let max_tilt_deg = study.max_tilt_deg();
    let summary = replay::summary(&r, args.seed, max_tilt_deg);
    let json = serde_json::to_string_pretty(&summary)?;
    let mut out = Output::default();
    out.add("flight.csv", replay::to_csv(&r));
    out.add("trial.json", json.clone());
    out.add("belly.svg", replay::belly_figure(&r, max_tilt_deg)?);
    let mut figures = vec!["belly.svg".to_string()];
    for i in 0..r.flights.len() {
        figures.push(replay::torque_file(i));
        out.add(replay::torque_file(i), replay::torque_figure(&r, i)?);
    }
    out.add(
        "index.html",
        trial_page(&cfg, &summary, &figures, (&flown, args.replan_budget_ms)),
    );
    let written = publisher.publish(out)?;
    if c.json {
        say!("{json}");
    } else {
        let mut lines = catflip::console::robustness::trial(&summary, &written);
        lines.insert(1, format!("  the controllers fly {flown}"));
        say_lines(lines);
    }
    Ok(Status::Ok)
}

/// A replayed trial's page: each controller's landing, the draws, the
/// controllers and the figures.
fn trial_page(
    cfg: &catflip::Config,
    s: &catflip::control::replay::Summary,
    figures: &[String],
    (design, budget_ms): (&str, Option<f64>),
) -> String {
    let rows: Vec<Vec<String>> = s
        .controllers
        .iter()
        .map(|f| {
            vec![
                f.name.to_string(),
                format!("{:.3}", f.landing_error_deg),
                f.landed_text().to_string(),
                format!("{:.4}", f.max_correction_nm),
                f.commands.to_string(),
                f.replans_text(),
            ]
        })
        .collect();
    let notes = vec![
        format!(
            "Trial {} of the study seeded {}, dropped from {} m (fall.height): {}. It lands when the belly ends within {} deg of straight down (land.max_tilt_deg; 10 deg unless set). These are the landings robustness.csv records for this trial; flight.csv holds each flight's state (the simulators' world, docs/control.md) and torque every millisecond.",
            s.trial,
            s.seed,
            cfg.fall.height,
            catflip::control::replay::draws(&s.draw),
            s.max_tilt_deg,
        ),
        controllers(cfg, Some(design), budget_ms, false),
    ];
    let figures: Vec<&str> = figures.iter().map(String::as_str).collect();
    catflip::report::index_html(&catflip::report::Page {
        title: &format!("catflip robustness: {}, trial {}", cfg.name, s.trial),
        lead: None,
        header: &[
            "controller",
            "landing deg",
            "landed",
            "largest correction N m",
            "commands",
            "replans",
        ],
        rows: &rows,
        notes: &notes,
        warnings: &[],
        animation: "",
        figures: &figures,
        captions: catflip::control::replay::caption,
        glossary: false,
    })
}

/// The study's page: each controller's line, what was drawn and how to fly
/// a trial again, the controllers and the design they fly (and the replans'
/// budget, ms, if any), `warnings` first, and the figure with its bins'
/// trials; `range` is the trials of the study's `trials` on it.
fn page(
    cfg: &catflip::Config,
    s: &catflip::control::robustness::Summary,
    timing: &catflip::control::robustness::ReplanTiming,
    (range, trials): (&std::ops::Range<usize>, usize),
    interrupted: bool,
    figure: Option<(&str, &[catflip::control::figure::Bins])>,
    (design, budget_ms, warnings): (Option<&str>, Option<f64>, &[String]),
) -> String {
    let rows: Vec<Vec<String>> = s
        .controllers
        .iter()
        .map(|c| {
            vec![
                c.name.to_string(),
                format!("{:.1} %", 100.0 * c.success_rate),
                format!("{:.1} to {:.1} %", 100.0 * c.ci95[0], 100.0 * c.ci95[1]),
                format!("{:.3}", c.landing_error_deg.p50),
                format!("{:.3}", c.landing_error_deg.p99),
                format!("{:.3}", c.landing_error_deg.max),
                c.worst
                    .iter()
                    .map(|w| format!("{} ({:.1} deg)", w.trial, w.landing_error_deg))
                    .collect::<Vec<_>>()
                    .join(", "),
            ]
        })
        .collect();
    let p = &cfg.robustness;
    let mut notes = vec![
        format!(
            "{}{} (numbers {} to {} of the study's {trials}), seed {}, dropped from {} m (fall.height): a trial succeeds when the belly lands within {} deg of straight down (land.max_tilt_deg; 10 deg unless set). Each trial draws its perturbations from the seed and its index alone: a spin at release up to [{}, {}, {}] rad/s about the rear half's axes, a tilt up to {} deg about a random horizontal axis, each half's mass, inertia and length off by up to {} %, {} % and {} %, {} ms of actuator delay, torque noise of {} % of the design's peak, attitude noise {} deg and rate noise {} rad/s, the open loop's PD gains off by up to {} % ([robustness]).",
            if interrupted { "Partial study: " } else { "" },
            catflip::console::count(s.trials, "trial"),
            range.start,
            range.end.saturating_sub(1),
            s.seed,
            cfg.fall.height,
            s.max_tilt_deg,
            p.spin_rad_s[0],
            p.spin_rad_s[1],
            p.spin_rad_s[2],
            p.tilt_deg,
            100.0 * p.mass_error,
            100.0 * p.inertia_error,
            100.0 * p.length_error,
            p.delay_ms,
            100.0 * p.torque_noise,
            p.attitude_noise_deg,
            p.rate_noise_rad_s,
            100.0 * p.pd_gain_error,
        ),
        controllers(cfg, design, budget_ms, true),
        format!(
            "The success rate's interval is Wilson's 95 % interval; a flight that diverged counts as 180 deg. A trial flies again, with its flights written and drawn, by this command with --seed {} --trial K (and the study's --set keys), or from Python with catflip.Controller(config, kind=...).fly(trial=K, seed={}) (docs/control.md); robustness.csv has every trial's draws and landings.",
            s.seed, s.seed
        ),
    ];
    notes.extend(catflip::console::robustness::nearest_rank(s.trials));
    notes.extend(catflip::console::robustness::diverged(s));
    if let Some((_, bins)) = figure {
        notes.extend(catflip::control::figure::bins_note(bins));
    }
    notes.extend(catflip::console::robustness::replans(timing).map(|l| {
        let mut l = l;
        l[..1].make_ascii_uppercase();
        format!("{l}.")
    }));
    let figures: Vec<&str> = figure.into_iter().map(|f| f.0).collect();
    catflip::report::index_html(&catflip::report::Page {
        title: &format!("catflip robustness: {}", cfg.name),
        lead: None,
        header: &[
            "controller",
            "success",
            "95 % interval",
            "landing p50 deg",
            "p99 deg",
            "max deg",
            "worst trials (landing)",
        ],
        rows: &rows,
        notes: &notes,
        warnings,
        animation: "",
        figures: &figures,
        captions: catflip::control::figure::caption,
        glossary: false,
    })
}

/// The design a study's controllers fly, in words.
fn described(d: &catflip::design::free::FreeResult) -> String {
    format!(
        "the free-form {} design seeded by the {} schedule, with a continuous torque (status {}; peak {:.4} N m, manoeuvre {:.4} s; catflip optimize --mode free --seed {seed} --set free.torque_jumps=false --set simulate.samples_per_phase=2000, with the study's other --set keys, makes it with rows enough to export, and catflip export mjcf CONFIG --schedule on its free.csv writes its TVLQR gains: docs/control.md)",
        d.objective.name(),
        d.seed,
        catflip::verdict::Status::from(d.status).name(),
        d.peak_torque_nm,
        d.manoeuvre_time_s,
        seed = d.seed,
    )
}

/// The page's note on the controllers: the design they fly, their rate and
/// the delay they predict over beside the simulated robot's, and that a
/// replan is used whatever its wall time (`timed`: the page lists the
/// replans' times).
fn controllers(
    cfg: &catflip::Config,
    design: Option<&str>,
    budget_ms: Option<f64>,
    timed: bool,
) -> String {
    let (c, r) = (&cfg.control, &cfg.robustness);
    let mut s = format!(
        "The controllers fly {}. TVLQR and replanning correct it {} times a second (control.rate_hz) and predict over a delay of {} ms (control.delay_ms); the simulated robot's actuator delay is {} ms (robustness.delay_ms)",
        design.unwrap_or("the study's free-form design"),
        c.rate_hz,
        c.delay_ms,
        r.delay_ms,
    );
    if c.delay_ms != r.delay_ms {
        s.push_str(": the controllers assume another delay than the robot has");
    }
    match budget_ms {
        None => s.push_str(if timed {
            ". The study is deterministic: each replan is used whatever its wall time (the replans' times below say how many a robot's processor would have missed; --replan-budget-ms drops them as a robot would)."
        } else {
            ". The flight is deterministic: each replan is used whatever its wall time (--replan-budget-ms drops those over a budget as a robot would)."
        }),
        Some(b) => s.push_str(&format!(
            ". A replan that took longer than {b} ms of wall time on this machine was dropped, the plan in use going on (--replan-budget-ms): the replanning controller's rate depends on this machine's speed and load."
        )),
    }
    s
}
