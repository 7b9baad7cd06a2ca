//! A robustness study's state for `--resume`: what the study was (trials,
//! seed, shard, resolved config) and whether its CSV holds every trial.

use super::robustness::{Summary, TrialResult, from_csv};
use crate::sweep::resume::SweepStatus;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a study leaves beside its CSV for `--resume`: its identity (the
/// trials asked, seed, shard and resolved config) and whether the CSV holds
/// every trial. The finished trials themselves are the CSV's rows, which
/// read back exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyState {
    pub status: SweepStatus,
    pub trials: usize,
    pub seed: u64,
    /// `K/N`.
    pub shard: String,
    /// `--replan-budget-ms`, when given (a replan over it is dropped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replan_budget_ms: Option<f64>,
    pub config: serde_json::Value,
}

/// The study's JSON: its summary, marked whole or partial.
#[derive(Serialize)]
pub struct Published<'a> {
    pub status: SweepStatus,
    #[serde(flatten)]
    pub summary: &'a Summary,
}

impl StudyState {
    /// `robustness<suffix>.state.json`.
    pub fn file_name(suffix: &str) -> String {
        format!("robustness{suffix}.state.json")
    }

    /// The trials a published study in `set_dir` finished, checked to be
    /// the same study as `self` and to lie in `range`.
    pub fn resume_from(
        &self,
        set_dir: &Path,
        suffix: &str,
        range: std::ops::Range<usize>,
    ) -> crate::Result<Vec<TrialResult>> {
        let usage = |m: String| crate::Error::Usage(format!("--resume: {m}"));
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
        let what = crate::sweep::resume::differences(
            &[
                ("--trials", old.trials.to_string(), self.trials.to_string()),
                ("--seed", old.seed.to_string(), self.seed.to_string()),
                ("--shard", old.shard.clone(), self.shard.clone()),
                (
                    "--replan-budget-ms",
                    old.replan_budget_ms
                        .map_or("none".into(), |b| b.to_string()),
                    self.replan_budget_ms
                        .map_or("none".into(), |b| b.to_string()),
                ),
            ],
            &old.config,
            &self.config,
        );
        if !what.is_empty() {
            return Err(usage(format!(
                "the study at {} was made with other settings: {what}; give the same ones, or run without --resume to start afresh",
                path.display(),
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
