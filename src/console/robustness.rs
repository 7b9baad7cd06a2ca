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
    if let Some(note) = nearest_rank(trials) {
        lines.push(format!("  {note}"));
    }
    if let Some(note) = diverged(summary) {
        lines.push(format!("  {note}"));
    }
    if let Some(line) = replans(timing) {
        lines.push(format!("  {line}"));
    }
    for p in written {
        lines.push(format!("  wrote {}", p.display()));
    }
    lines
}

/// The flights that diverged, per controller, when any did: they count as
/// 180 deg, which alone cannot tell them from a landing upside down.
pub fn diverged(summary: &Summary) -> Option<String> {
    let by: Vec<String> = summary
        .controllers
        .iter()
        .filter(|c| c.diverged > 0)
        .map(|c| format!("{} {}", c.name, c.diverged))
        .collect();
    (!by.is_empty()).then(|| {
        format!(
            "Flights that diverged (counted as 180 deg): {}.",
            by.join(", ")
        )
    })
}

/// What the percentiles of a study of `trials` are, when p99 is its largest
/// landing error (fewer than 100 trials, nearest rank): a sentence.
pub fn nearest_rank(trials: usize) -> Option<String> {
    (0 < trials && trials < 100).then(|| {
        format!(
            "Percentiles by nearest rank: of {trials} trials, p99 is the largest landing error{}.",
            if trials < 10 { ", and p90 too" } else { "" }
        )
    })
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
            f.landed_text(),
            f.max_correction_nm,
            f.commands,
            f.replans_text()
        ));
    }
    for p in written {
        lines.push(format!("  wrote {}", p.display()));
    }
    lines
}

/// The warning a study's replans earn when their p99 wall time is over the
/// control period without a budget: the replanning rate is then not one a
/// robot's processor like this machine would reach.
pub fn late_replans(timing: &ReplanTiming, budget_ms: Option<f64>) -> Option<String> {
    (budget_ms.is_none() && timing.replans > 0 && timing.p99_s > timing.period_s).then(|| {
        format!(
            "{} of {} replans took longer than the {:.1} ms control period (p99 {:.1} ms) on this machine: the replanning rate assumes each was in time; with --replan-budget-ms {:.0} a late replan is dropped, as on a robot with this processor",
            timing.over_period,
            timing.replans,
            1e3 * timing.period_s,
            1e3 * timing.p99_s,
            1e3 * timing.period_s,
        )
    })
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
        ) + &if timing.trials_timed < timing.trials {
            format!(
                "; timed over {} of the {} (a --resume times the trials it flies, not those it kept)",
                timing.trials_timed, timing.trials
            )
        } else {
            String::new()
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(p99_ms: f64, over: usize) -> ReplanTiming {
        ReplanTiming {
            trials_timed: 10,
            trials: 10,
            replans: 500,
            taken: 40,
            failed: 0,
            late: 0,
            worse: 3,
            median_s: 3e-3,
            p99_s: 1e-3 * p99_ms,
            max_s: 30e-3,
            solve_median_s: 2e-3,
            solve_p99_s: 1e-3 * p99_ms,
            solve_max_s: 29e-3,
            period_s: 10e-3,
            over_period: over,
        }
    }

    /// Replans whose p99 is over the control period are a warning, with
    /// their count and the budget that would drop them; not when a budget
    /// already dropped them, nor when the p99 is in time.
    #[test]
    fn late_replans_are_a_warning_unless_a_budget_dropped_them() {
        let w = late_replans(&timing(22.0, 16), None).unwrap();
        assert!(
            w.starts_with(
                "16 of 500 replans took longer than the 10.0 ms control period (p99 22.0 ms)"
            ) && w.contains("--replan-budget-ms 10"),
            "{w}"
        );
        assert_eq!(late_replans(&timing(22.0, 16), Some(10.0)), None);
        assert_eq!(late_replans(&timing(6.0, 2), None), None);
    }

    /// Nearest rank: of n trials p99 is the largest below 100 (the rank
    /// ceil(0.99 n) is n), p90 too below 10; a study of 100 or more is not noted.
    #[test]
    fn a_small_studys_p99_is_said_to_be_its_largest() {
        use crate::control::robustness::{Draw, TrialResult, summarise};
        let cfg =
            crate::Config::from_toml(include_str!("../../configs/seed.toml"), "seed", &[]).unwrap();
        for n in [5usize, 50, 99, 100, 120] {
            let results: Vec<TrialResult> = (0..n)
                .map(|t| TrialResult {
                    draw: Draw::new(&cfg, 1, t),
                    landing_error_deg: [t as f64; 3],
                    replans: Vec::new(),
                })
                .collect();
            let s = summarise(&results, 1, 10.0, 3);
            let p = &s.controllers[0].landing_error_deg;
            let note = nearest_rank(n);
            assert_eq!(p.p99 == p.max, note.is_some(), "{n}");
            assert_eq!(
                p.p90 == p.max,
                note.as_deref().is_some_and(|t| t.contains("p90 too")),
                "{n}"
            );
        }
    }
}
