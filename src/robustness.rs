//! `catflip robustness`: the command-line face of [`catflip::control::robustness`].

use crate::cli::{Common, Status, load, publisher};
use anyhow::Result;
use catflip::control::robustness::{
    DEFAULT_MAX_TILT_DEG, Study, Summary, TrialResult, from_csv, shard_range, summarise, to_csv,
};
use catflip::interrupt::{Outcome, supervise};
use catflip::output::Output;
use catflip::sweep::resume::SweepStatus;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// What a study leaves beside its CSV for `--resume`: its identity (the
/// trials asked, seed, shard and resolved config) and whether the CSV holds
/// every trial. The finished trials themselves are the CSV's rows, which
/// read back exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct StudyState {
    status: SweepStatus,
    trials: usize,
    seed: u64,
    /// `K/N`.
    shard: String,
    config: serde_json::Value,
}

/// The study's JSON: its summary, marked whole or partial.
#[derive(Serialize)]
struct Published<'a> {
    status: SweepStatus,
    #[serde(flatten)]
    summary: &'a Summary,
}

impl StudyState {
    /// `robustness<suffix>.state.json`.
    fn file_name(suffix: &str) -> String {
        format!("robustness{suffix}.state.json")
    }

    /// The trials a published study in `set_dir` finished, checked to be
    /// the same study as `self` and to lie in `range`.
    fn resume_from(
        &self,
        set_dir: &Path,
        suffix: &str,
        range: std::ops::Range<usize>,
    ) -> catflip::Result<Vec<TrialResult>> {
        let usage = |m: String| catflip::Error::Usage(format!("--resume: {m}"));
        let path = set_dir.join(Self::file_name(suffix));
        let text = std::fs::read_to_string(&path).map_err(|e| {
            usage(format!(
                "no study to resume at {} ({e}); run the study without --resume",
                path.display()
            ))
        })?;
        let old: StudyState = serde_json::from_str(&text).map_err(|e| {
            usage(format!(
                "{} is not a study state catflip wrote ({e}); run the study without --resume",
                path.display()
            ))
        })?;
        let differs = [
            ("the trials (--trials)", old.trials != self.trials),
            ("the seed (--seed)", old.seed != self.seed),
            ("the shard (--shard)", old.shard != self.shard),
            ("the config (file or --set)", old.config != self.config),
        ];
        let what: Vec<&str> = differs.iter().filter(|d| d.1).map(|d| d.0).collect();
        if !what.is_empty() {
            return Err(usage(format!(
                "the study at {} was made with other settings ({} differ: it has --trials {} --seed {} --shard {}); give the same ones, or run without --resume to start afresh",
                path.display(),
                what.join(", "),
                old.trials,
                old.seed,
                old.shard
            )));
        }
        let csv = set_dir.join(format!("robustness{suffix}.csv"));
        let bad = |e: String| {
            usage(format!(
                "{} is not the study's CSV ({e}); run the study without --resume",
                csv.display()
            ))
        };
        let results = from_csv(&std::fs::read_to_string(&csv).map_err(|e| bad(e.to_string()))?)
            .map_err(bad)?;
        if let Some(r) = results.iter().find(|r| !range.contains(&r.draw.trial)) {
            return Err(bad(format!(
                "trial {} is outside the shard's {}..{}",
                r.draw.trial, range.start, range.end
            )));
        }
        Ok(results)
    }
}

pub fn cmd_robustness(
    c: &Common,
    trials: usize,
    seed: u64,
    threads: Option<usize>,
    shard: Option<&str>,
    resume: bool,
) -> Result<Status> {
    let cfg = load(c)?;
    if trials == 0 || trials > catflip::config::MAX_TRIALS {
        return Err(catflip::Error::Invalid {
            key: "--trials".into(),
            value: trials.to_string(),
            expected: format!("must be in [1, {}]", catflip::config::MAX_TRIALS),
        }
        .into());
    }
    if threads == Some(0) {
        return Err(catflip::Error::Usage(
            "--threads 0: at least one trial must be flown at a time; give --threads 1 or more, or leave it out for one per core".into(),
        )
        .into());
    }
    let shard: catflip::sweep::Shard = match shard {
        Some(s) => s.parse()?,
        None => catflip::sweep::Shard::ALL,
    };
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let suffix = shard.suffix();
    let publisher = publisher(c, &cfg, &format!("robustness{suffix}"))?;
    let range = shard_range(trials, shard.index, shard.count);
    let state = StudyState {
        status: SweepStatus::Partial,
        trials,
        seed,
        shard: format!("{}/{}", shard.index, shard.count),
        config: serde_json::to_value(&cfg)?,
    };
    let mut kept = vec![None; range.len()];
    if resume {
        let old = state.resume_from(&publisher.link(), &suffix, range.clone())?;
        eprintln!(
            "resuming: {} of {} trials kept from {}",
            old.len(),
            range.len(),
            publisher.link().display()
        );
        for r in old {
            let i = r.draw.trial - range.start;
            kept[i] = Some(r);
        }
    }
    let max_tilt_deg = cfg.land.max_tilt_deg.unwrap_or(DEFAULT_MAX_TILT_DEG);
    let quiet = c.json;
    let live = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let clock = std::time::Instant::now();
    // the trials land in a store this thread reads when a signal stops the study
    let store = Arc::new(Mutex::new(kept));
    let interrupt = catflip::interrupt::Interrupt::catch()?;
    let work = {
        let (cfg, store, range) = (cfg.clone(), store.clone(), range.clone());
        move || -> catflip::Result<()> {
            let design = catflip::control::robustness::design(&cfg)?;
            let study = Study::new(&cfg, &design.plan, seed);
            study.run_into(range, threads, &store, |done, total| {
                if quiet || (!live && done % (total / 20).max(1) != 0 && done != total) {
                    return;
                }
                let w = 30;
                let filled = w * done / total.max(1);
                let line = format!(
                    "robustness [{}{}] {done}/{total} trials, {:.1} s",
                    "#".repeat(filled),
                    "-".repeat(w - filled),
                    clock.elapsed().as_secs_f64()
                );
                if live {
                    eprint!("\r  {line}");
                } else {
                    eprintln!("  {line}");
                }
            });
            Ok(())
        }
    };
    let outcome = supervise(&interrupt, work);
    if !quiet && live {
        eprintln!();
    }
    let slots = store.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let interrupted = match outcome {
        Outcome::Finished(r) => {
            r?;
            false
        }
        Outcome::Interrupted => true,
    };
    let results: Vec<TrialResult> = slots.into_iter().flatten().collect();
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
        to_csv(&results, range.start == 0),
    );
    out.add(format!("robustness{suffix}.json"), json.clone());
    if !results.is_empty()
        && let Some(svg) = catflip::control::figure::success_by_size(&cfg, &results, max_tilt_deg)?
    {
        out.add(format!("robustness{suffix}.svg"), svg);
    }
    out.add(
        StudyState::file_name(&suffix),
        serde_json::to_string_pretty(&state)?,
    );
    if interrupted {
        // published as a partial set, the trials in flight left unfinished
        let dir = publisher.link();
        publisher.publish(out)?;
        if c.json {
            println!("{json}");
        }
        eprintln!(
            "interrupted: {} of {} trials finished, published as a partial set in {} (its JSON says \"status\": \"partial\"); the same command with --resume continues it; exit status 130",
            results.len(),
            range.len(),
            dir.display()
        );
        return Ok(Status::Interrupted);
    }
    let written = publisher.publish(out)?;
    if c.json {
        println!("{json}");
        return Ok(Status::Ok);
    }
    println!(
        "catflip robustness: {} trials {}..{} of {trials} (seed {seed}), landing within {} deg of belly-down",
        results.len(),
        range.start,
        range.end,
        summary.max_tilt_deg
    );
    println!(
        "  {:<10} {:>9} {:>17} {:>9} {:>9} {:>9}",
        "controller", "success", "95 % CI", "p50 deg", "p99 deg", "max deg"
    );
    for s in &summary.controllers {
        println!(
            "  {:<10} {:>8.1}% {:>7.1}%-{:>6.1}% {:>9.3} {:>9.3} {:>9.3}",
            s.name,
            100.0 * s.success_rate,
            100.0 * s.ci95[0],
            100.0 * s.ci95[1],
            s.landing_error_deg.p50,
            s.landing_error_deg.p99,
            s.landing_error_deg.max
        );
    }
    for p in written {
        println!("  wrote {}", p.display());
    }
    Ok(Status::Ok)
}
