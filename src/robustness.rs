//! `catflip robustness`: the command-line face of [`catflip::control::robustness`].

use crate::cli::{Common, Status, load, publisher};
use anyhow::Result;
use catflip::control::robustness::{Study, shard_range, summarise, to_csv};
use catflip::output::Output;

pub fn cmd_robustness(
    c: &Common,
    trials: usize,
    seed: u64,
    threads: Option<usize>,
    shard: Option<&str>,
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
    let design = catflip::control::robustness::design(&cfg)?;
    let study = Study::new(&cfg, &design.plan, seed);
    let range = shard_range(trials, shard.index, shard.count);
    let quiet = c.json;
    let live = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let clock = std::time::Instant::now();
    let results = study.run(range.clone(), threads, |done, total| {
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
    if !quiet && live {
        eprintln!();
    }
    let summary = summarise(
        &results,
        seed,
        study.max_tilt_deg(),
        cfg.robustness.worst_kept,
    );
    let json = serde_json::to_string_pretty(&summary)?;
    let mut out = Output::default();
    out.add(
        format!("robustness{suffix}.csv"),
        to_csv(&results, range.start == 0),
    );
    out.add(format!("robustness{suffix}.json"), json.clone());
    if let Some(svg) =
        catflip::control::figure::success_by_size(&cfg, &results, study.max_tilt_deg())?
    {
        out.add(format!("robustness{suffix}.svg"), svg);
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
