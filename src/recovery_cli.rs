//! `catflip recovery`: the command-line face of [`catflip::recovery`].

use crate::common::{Common, Progress, Status, load, publish_partial, publisher, say};
use anyhow::Result;
use catflip::interrupt::{Outcome, supervise};
use catflip::output::Output;
use catflip::recovery::{Bound, Grid, LineResult, figures, shard_lines, to_csv, tolerance_deg};
use catflip::sweep::resume::SweepStatus;
use serde::Serialize;
use std::sync::{Arc, Mutex};

/// The map's JSON summary.
#[derive(Serialize)]
struct Summary<'a> {
    status: SweepStatus,
    name: &'a str,
    height_m: f64,
    landing_tolerance_deg: f64,
    motors_limited: bool,
    grid: &'a Grid,
    /// `K/N`.
    shard: String,
    /// Lines of the shard, and those finished.
    lines: usize,
    lines_finished: usize,
    starts: usize,
    starts_landing: usize,
    /// The largest recoverable spin per spin axis.
    bounds: Vec<&'a Bound>,
    results: &'a [LineResult],
}

pub fn cmd_recovery(
    c: &Common,
    grid: Grid,
    threads: usize,
    shard: Option<catflip::sweep::Shard>,
) -> Result<Status> {
    let cfg = load(c)?;
    grid.validate()?;
    let shard = shard.unwrap_or(catflip::sweep::Shard::ALL);
    let all = grid.lines();
    let range = shard_lines(shard, all.len());
    if range.is_empty() {
        eprintln!(
            "warning: shard {}/{} holds no lines: the map has {} lines (axes and families); use at most that many shards",
            shard.index,
            shard.count,
            all.len()
        );
    }
    let lines = all[range.clone()].to_vec();
    let suffix = shard.suffix();
    let publisher = publisher(c, &cfg, &format!("recovery{suffix}"))?;
    let quiet = c.json;
    let progress = Progress::new(quiet);
    let clock = std::time::Instant::now();
    let store = Arc::new(Mutex::new(vec![None; lines.len()]));
    let interrupt = catflip::interrupt::Interrupt::catch()?;
    let work = {
        let (cfg, grid, store, lines) = (cfg.clone(), grid.clone(), store.clone(), lines.clone());
        move || -> catflip::Result<()> {
            if !quiet {
                eprintln!("  recovery: designing from the start at rest ...");
            }
            let origin = catflip::recovery::Origin::new(&cfg, &grid)?;
            catflip::recovery::compute_into(&origin, &lines, threads, &store, |done, total| {
                progress.show(&catflip::console::progress::bar(
                    "recovery",
                    done,
                    total,
                    "lines",
                    clock.elapsed().as_secs_f64(),
                ));
            });
            Ok(())
        }
    };
    let outcome = supervise(&interrupt, work);
    progress.finish();
    let interrupted = match outcome {
        Outcome::Finished(r) => {
            r?;
            false
        }
        Outcome::Interrupted => true,
    };
    let results: Vec<LineResult> = store
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .clone()
        .into_iter()
        .flatten()
        .collect();
    let points = || results.iter().flat_map(|l| &l.points);
    let summary = Summary {
        status: if interrupted {
            SweepStatus::Partial
        } else {
            SweepStatus::Complete
        },
        name: &cfg.name,
        height_m: cfg.fall.height,
        landing_tolerance_deg: tolerance_deg(&cfg),
        motors_limited: cfg.motor().is_limited(),
        grid: &grid,
        shard: format!("{}/{}", shard.index, shard.count),
        lines: lines.len(),
        lines_finished: results.len(),
        starts: points().count(),
        starts_landing: points().filter(|p| p.outcome.lands()).count(),
        bounds: results.iter().filter_map(|l| l.bound.as_ref()).collect(),
        results: &results,
    };
    let json = serde_json::to_string_pretty(&summary)?;
    let mut out = Output::default();
    out.add(
        format!("recovery{suffix}.csv"),
        to_csv(&results, shard.index == 1),
    );
    out.add(format!("recovery{suffix}.json"), json.clone());
    let figs = figures(&results, &grid)?;
    let names: Vec<String> = figs.iter().map(|f| f.0.clone()).collect();
    for (name, svg) in figs {
        out.add(name, svg);
    }
    out.add("index.html", report(&cfg, &summary, &names));
    if interrupted {
        return publish_partial(
            publisher,
            out,
            c.json.then_some(json.as_str()),
            &format!("{} of {} lines", results.len(), lines.len()),
            "",
        );
    }
    let written = publisher.publish(out)?;
    if c.json {
        say!("{json}");
        return Ok(Status::Ok);
    }
    say!(
        "catflip recovery: {} from {} m, {} of {} starts land within {:.4} deg of belly-down ({:.1} s)",
        cfg.name,
        cfg.fall.height,
        summary.starts_landing,
        summary.starts,
        summary.landing_tolerance_deg,
        clock.elapsed().as_secs_f64()
    );
    say!(
        "  {:>5} {:>9} {:>24}",
        "plane",
        "axis deg",
        "largest spin rad/s"
    );
    for b in &summary.bounds {
        say!(
            "  {:>5} {:>9.1} {:>24}",
            b.plane.name(),
            b.axis_deg,
            bound_text(b)
        );
    }
    for p in written {
        say!("  wrote {}", p.display());
    }
    Ok(Status::Ok)
}

fn bound_text(b: &Bound) -> String {
    match b.first_miss_rad_s {
        None => format!(">= {:.4}", b.largest_spin_rad_s),
        Some(m) => format!("{:.4} (misses at {:.4})", b.largest_spin_rad_s, m),
    }
}

/// The set's report: the bounds, the counts, and the figures linked.
fn report(cfg: &catflip::Config, s: &Summary, figures: &[String]) -> String {
    let rows: Vec<Vec<String>> = s
        .bounds
        .iter()
        .map(|b| {
            vec![
                b.plane.name().to_string(),
                format!("{:.1}", b.axis_deg),
                bound_text(b),
            ]
        })
        .collect();
    let notes = vec![format!(
        "{} of {} starts land within {:.4} deg of belly-down (land.max_tilt_deg; unless set, simulate.flip_tolerance in degrees) from {} m (recovery{}.csv has every start; {} of the map's {} lines of starts, a spin or tilt axis each, finished).",
        s.starts_landing,
        s.starts,
        s.landing_tolerance_deg,
        cfg.fall.height,
        if s.shard == "1/1" {
            String::new()
        } else {
            format!(" shard {}", s.shard)
        },
        s.lines_finished,
        s.lines
    )];
    let figs: Vec<&str> = figures.iter().map(String::as_str).collect();
    catflip::report::index_html(&catflip::report::Page {
        title: &format!("Recovery map: {}", cfg.name),
        lead: None,
        header: &["plane", "axis deg", "largest recoverable spin rad/s"],
        rows: &rows,
        notes: &notes,
        warnings: &[],
        animation: "",
        figures: &figs,
        captions: catflip::recovery::caption,
        glossary: false,
    })
}
