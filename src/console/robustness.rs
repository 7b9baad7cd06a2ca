//! `robustness`'s table: each controller's success rate, its confidence
//! interval and landing-error percentiles; and the study's progress bar.

use crate::control::robustness::{ReplanTiming, Summary};
use std::path::PathBuf;

/// The study's table over `trials` trials `range` of `total`, `seed` its seed.
pub fn study(
    summary: &Summary,
    timing: &ReplanTiming,
    trials: usize,
    range: std::ops::Range<usize>,
    total: usize,
    seed: u64,
    written: &[PathBuf],
) -> Vec<String> {
    let mut lines = vec![
        format!(
            "catflip robustness: {} {}..{} of {total} (seed {seed}), landing within {} deg of belly-down",
            super::count(trials, "trial"),
            range.start,
            range.end,
            summary.max_tilt_deg
        ),
        format!(
            "  {:<10} {:>9} {:>17} {:>9} {:>9} {:>9}",
            "controller", "success", "95 % CI", "p50 deg", "p99 deg", "max deg"
        ),
    ];
    if trials == 0 {
        lines.push("  (no trials in this shard: nothing to rate)".into());
    }
    for s in summary.controllers.iter().filter(|_| trials > 0) {
        lines.push(format!(
            "  {:<10} {:>8.1}% {:>7.1}%-{:>6.1}% {:>9.3} {:>9.3} {:>9.3}",
            s.name,
            100.0 * s.success_rate,
            100.0 * s.ci95[0],
            100.0 * s.ci95[1],
            s.landing_error_deg.p50,
            s.landing_error_deg.p99,
            s.landing_error_deg.max
        ));
    }
    if let Some(line) = replans(timing) {
        lines.push(format!("  {line}"));
    }
    for p in written {
        lines.push(format!("  wrote {}", p.display()));
    }
    lines
}

/// A replayed trial's table: its draws, then each controller's landing.
pub fn trial(s: &crate::control::replay::Summary, written: &[PathBuf]) -> Vec<String> {
    let mut lines = vec![
        format!(
            "catflip robustness: trial {} of the study seeded {}, flown again; landing within {} deg of belly-down",
            s.trial, s.seed, s.max_tilt_deg
        ),
        format!("  {}", crate::control::replay::draws(&s.draw)),
        format!(
            "  {:<10} {:>12} {:>7} {:>24} {:>9} {:>9}",
            "controller", "landing deg", "landed", "largest correction N m", "commands", "replans"
        ),
    ];
    for f in &s.controllers {
        lines.push(format!(
            "  {:<10} {:>12.3} {:>7} {:>24.4} {:>9} {:>9}",
            f.name,
            f.landing_error_deg,
            if f.landed { "yes" } else { "no" },
            f.max_correction_nm,
            f.commands,
            if f.replans > 0 {
                format!("{} ({} taken)", f.replans, f.replans_taken)
            } else {
                String::new()
            }
        ));
    }
    for p in written {
        lines.push(format!("  wrote {}", p.display()));
    }
    lines
}

/// The replans' counts and wall times, when there were any.
pub fn replans(timing: &ReplanTiming) -> Option<String> {
    (timing.replans > 0).then(|| {
        format!(
            "replans: {} ({} taken, {} worse than the plan in use, {} failed, {} dropped over their budget); wall time median {:.2} ms, p99 {:.2} ms, worst {:.2} ms (the solve: {:.2}, {:.2}, {:.2} ms); {} took longer than the {:.1} ms control period",
            timing.replans,
            timing.taken,
            timing.worse,
            timing.failed,
            timing.late,
            1e3 * timing.median_s,
            1e3 * timing.p99_s,
            1e3 * timing.max_s,
            1e3 * timing.solve_median_s,
            1e3 * timing.solve_p99_s,
            1e3 * timing.solve_max_s,
            timing.over_period,
            1e3 * timing.period_s
        )
    })
}
