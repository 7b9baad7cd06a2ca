//! What an interrupted sweep leaves for `--resume`: beside its CSV, the
//! set holds `sweep-<key>.state.json` with the sweep's identity (range,
//! shard, methods, the resolved config) and every grid point's result so
//! far, `null` for those not finished. A finished sweep writes the same file
//! with `"status": "complete"`.

use super::{Methods, Shard, SweepPoint, SweepSpec};
use crate::config::Config;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Whether a published sweep has every point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SweepStatus {
    /// Interrupted: some points are missing; `--resume` computes them.
    Partial,
    Complete,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepState {
    pub status: SweepStatus,
    /// `KEY=FROM:TO:COUNT`.
    pub range: String,
    /// `K/N`.
    pub shard: String,
    pub methods: Vec<String>,
    /// Whether only the least heights were computed (`--least-height-only`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub least_height_only: bool,
    /// The config the points were computed from, as resolved (file and `--set`).
    pub config: serde_json::Value,
    /// One slot a point of the shard, in grid order.
    pub points: Vec<Option<SweepPoint>>,
}

/// What differs between two resolved configs, key by key: `fall.height 2
/// (now 4)`, a key only one has as `(none)`. For a refused `--resume`.
pub fn config_differences(old: &serde_json::Value, new: &serde_json::Value) -> Vec<String> {
    fn walk(
        at: &str,
        a: Option<&serde_json::Value>,
        b: Option<&serde_json::Value>,
        out: &mut Vec<String>,
    ) {
        use serde_json::Value::Object;
        match (a, b) {
            (Some(Object(x)), Some(Object(y))) => {
                let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
                keys.sort();
                keys.dedup();
                for k in keys {
                    let path = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    walk(&path, x.get(k), y.get(k), out);
                }
            }
            (a, b) if a != b => {
                let show =
                    |v: Option<&serde_json::Value>| v.map_or("(none)".into(), |v| v.to_string());
                out.push(format!("{at} {} (now {})", show(a), show(b)));
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk("", Some(old), Some(new), &mut out);
    out
}

/// The sweeps of the same key (and shard) published beside `set_dir`, for
/// a `--resume` that finds none there: each `--set` names its own folder.
fn others_beside(set_dir: &Path, file_key: &str) -> String {
    let prefix = format!("sweep-{file_key}");
    let Some(Ok(entries)) = set_dir.parent().map(std::fs::read_dir) else {
        return String::new();
    };
    let mut names: Vec<String> = entries
        .flatten()
        .filter(|e| e.path().join(SweepState::file_name(file_key)).is_file())
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n == &prefix || n.starts_with(&format!("{prefix}@")))
        .collect();
    if names.is_empty() {
        return String::new();
    }
    names.sort();
    format!(
        ". Published beside it: {} (a folder's name after `@` gives the --set it was made with: give the same to resume it)",
        names.join(", ")
    )
}

/// A flag's presence, for [`differences`].
fn given(on: bool) -> String {
    if on { "given" } else { "not given" }.into()
}

/// A refused `--resume`'s list (a sweep's or a study's): each setting that
/// differs, with its value then and now (`--seed 1 (now 2)`), the config key
/// by key.
pub fn differences(
    settings: &[(&str, String, String)],
    old: &serde_json::Value,
    new: &serde_json::Value,
) -> String {
    let mut out: Vec<String> = settings
        .iter()
        .filter(|(_, a, b)| a != b)
        .map(|(flag, a, b)| format!("{flag} {a} (now {b})"))
        .collect();
    let keys = config_differences(old, new);
    if !keys.is_empty() {
        out.push(format!("the config (file or --set): {}", keys.join(", ")));
    }
    out.join("; ")
}

impl Methods {
    /// `analytic`, `phased`, `free`: those computed.
    pub fn names(&self) -> Vec<String> {
        [
            ("analytic", self.analytic),
            ("phased", self.phased),
            ("free", self.free),
        ]
        .iter()
        .filter(|(_, on)| *on)
        .map(|(n, _)| n.to_string())
        .collect()
    }
}

impl SweepState {
    /// A sweep's identity with no point finished.
    pub fn new(spec: &SweepSpec, shard: Shard, methods: Methods, cfg: &Config) -> SweepState {
        SweepState {
            status: SweepStatus::Partial,
            range: spec.arg(),
            shard: format!("{}/{}", shard.index, shard.count),
            methods: methods.names(),
            least_height_only: !methods.peaks,
            config: serde_json::to_value(cfg).expect("a config serialises"),
            points: vec![None; shard.points(spec.count).len()],
        }
    }

    /// `sweep-<file_key>.state.json`.
    pub fn file_name(file_key: &str) -> String {
        format!("sweep-{file_key}.state.json")
    }

    /// The points finished, in grid order.
    pub fn finished(&self) -> Vec<SweepPoint> {
        self.points.iter().flatten().cloned().collect()
    }

    /// This state with `points` and the status they imply.
    pub fn with_points(&self, points: Vec<Option<SweepPoint>>) -> SweepState {
        let status = if points.iter().all(|p| p.is_some()) {
            SweepStatus::Complete
        } else {
            SweepStatus::Partial
        };
        SweepState {
            status,
            points,
            ..self.clone()
        }
    }

    /// The files a sweep publishes: `sweep-<file_key>.csv` of the finished
    /// points, their figures (left out of an interrupted sweep with none
    /// finished) and this state; `key` labels the columns and axes.
    pub fn output(
        &self,
        file_key: &str,
        key: &str,
        interrupted: bool,
    ) -> Result<crate::output::Output> {
        let points = self.finished();
        let mut out = crate::output::Output::default();
        out.add(format!("sweep-{file_key}.csv"), super::to_csv(key, &points));
        if !(interrupted && points.is_empty()) {
            let mut names = Vec::new();
            let height = self.config["fall"]["height"].as_f64().unwrap_or(f64::NAN);
            let motor = self
                .limited(key)
                .then(|| super::motor_words(&self.config["limits"], key));
            for (name, svg) in super::figures(file_key, key, &points, motor.as_deref(), height)? {
                names.push(name.clone());
                out.add(name, svg);
            }
            out.add(
                "index.html",
                self.page(file_key, key, &points, &names, height),
            );
        }
        out.add(Self::file_name(file_key), self.to_json());
        Ok(out)
    }

    /// Whether the points have a stall torque (the config's, or the swept
    /// one), and so least drop heights.
    fn limited(&self, key: &str) -> bool {
        key == "limits.max_torque" || self.config["limits"]["max_torque"].is_number()
    }

    /// The sweep's page: a row a finished point, and the figures.
    fn page(
        &self,
        file_key: &str,
        key: &str,
        points: &[SweepPoint],
        figures: &[String],
        height: f64,
    ) -> String {
        let cell =
            |x: Option<f64>, digits: usize| x.map_or(String::new(), |x| format!("{x:.digits$}"));
        // the numeric columns some point has a number in, then the free-form
        // status and the error where some point has one
        let columns = crate::console::sweep::columns(points);
        let status = points.iter().any(|p| p.free_status.is_some());
        let errors = points.iter().any(|p| p.error.is_some());
        let rows: Vec<Vec<String>> = points
            .iter()
            .map(|p| {
                let mut row = vec![format!("{}", p.value)];
                for c in &columns {
                    row.push(cell((c.get)(p), c.digits));
                }
                if status {
                    row.push(
                        p.free_status
                            .map_or("", crate::verdict::Status::name)
                            .to_string(),
                    );
                }
                if errors {
                    row.push(p.error.clone().unwrap_or_default());
                }
                row
            })
            .collect();
        let mut header = vec![key];
        header.extend(columns.iter().map(|c| c.page));
        if status {
            header.push("free status");
        }
        if errors {
            header.push("error");
        }
        let name = self.config["name"].as_str().unwrap_or("config");
        let limited = self.limited(key);
        let what = if limited && self.least_height_only {
            format!(
                "only the least drop heights were asked for (--least-height-only): inside a motor envelope they are those of the phased and free-form time designs, each point's answer being the lower one that verifies, and the peak columns are left out (empty in the CSV); under a stall torque alone they come from the peaks (F7), which are then given. Where a point's least height is below the configured {height} m (fall.height), the flip is possible from that height"
            )
        } else if limited {
            format!(
                "the peak columns are the least-peak designs without the motor limits (the torque each method needs); the motors enter through the least drop heights, those of the phased and free-form time designs inside the motor envelope, each point's answer being the lower one that verifies: where it is below the configured {height} m (fall.height), the flip is possible from that height. A continued point may find a lower least height than `catflip run` (another local optimum; within 0.5 %, docs/usage.md)"
            )
        } else {
            "each point designed by each method as `catflip run` designs it (no motor limits)"
                .to_string()
        };
        let mut notes = vec![format!(
            "{}{} of {key} ({}, shard {}), methods {}: {what}. sweep-{file_key}.csv has every number; docs/outputs.md the columns.",
            if self.status == SweepStatus::Partial {
                "Partial sweep: "
            } else {
                ""
            },
            if points.len() == 1 {
                "1 point".to_string()
            } else {
                format!("{} points", points.len())
            },
            self.range,
            self.shard,
            self.methods.join(", "),
        )];
        let start = serde_json::from_value(self.config["start"].clone()).unwrap_or_default();
        notes.extend(crate::console::sweep::from_another_start(
            &start,
            &self.methods,
        ));
        if points.iter().any(|p| p.error.is_some()) {
            notes.push(
                "A row's error names what failed there; a point whose method failed keeps the other methods' numbers."
                    .into(),
            );
        }
        // a shard of a job array wider than the grid: nothing failed here
        let warnings: Vec<String> = self
            .points
            .is_empty()
            .then(|| {
                let count = self.range.rsplit(':').next().and_then(|c| c.parse().ok());
                let mut w = crate::console::sweep::empty_shard(
                    &self.shard,
                    &self.range,
                    count.unwrap_or(0),
                );
                w[..1].make_ascii_uppercase();
                format!("{w}. Nothing failed; the other shards hold the points.")
            })
            .into_iter()
            .collect();
        let figs: Vec<&str> = figures.iter().map(String::as_str).collect();
        crate::report::index_html(&crate::report::Page {
            title: &format!("catflip sweep: {name}, {key}"),
            lead: None,
            header: &header,
            rows: &rows,
            notes: &notes,
            warnings: &warnings,
            animation: "",
            figures: &figs,
            captions: super::caption,
            glossary: false,
        })
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a sweep state serialises")
    }

    /// The published state in `set_dir` to resume from, checked to be the
    /// same sweep as `self` (same grid, shard, methods and config).
    pub fn resume_from(&self, set_dir: &Path, file_key: &str) -> Result<SweepState> {
        let path = set_dir.join(Self::file_name(file_key));
        let usage = |m: String| Error::Usage(format!("--resume: {m}"));
        let text = std::fs::read_to_string(&path).map_err(|e| {
            usage(format!(
                "no sweep to resume at {} ({e}); run the sweep without --resume{}",
                path.display(),
                others_beside(set_dir, file_key)
            ))
        })?;
        let old: SweepState = serde_json::from_str(&text).map_err(|e| {
            usage(format!(
                "{} is not a sweep state catflip wrote ({e}); run the sweep without --resume",
                path.display()
            ))
        })?;
        let what = differences(
            &[
                ("--set-range", old.range.clone(), self.range.clone()),
                ("--shard", old.shard.clone(), self.shard.clone()),
                ("--methods", old.methods.join(","), self.methods.join(",")),
                (
                    "--least-height-only",
                    given(old.least_height_only),
                    given(self.least_height_only),
                ),
                (
                    "points",
                    old.points.len().to_string(),
                    self.points.len().to_string(),
                ),
            ],
            &old.config,
            &self.config,
        );
        if !what.is_empty() {
            return Err(usage(format!(
                "the sweep at {} was made with other settings: {what}; give the same ones, or run without --resume to start afresh",
                path.display(),
            )));
        }
        Ok(old)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refused resume names each key that differs, then and now, a key
    /// only one config has as `(none)`, and nothing for equal configs.
    #[test]
    fn config_differences_name_each_key_then_and_now() {
        let old = serde_json::json!({"fall": {"height": 2.0, "margin": 0.1}, "name": "r"});
        let new = serde_json::json!({"fall": {"height": 4.0, "margin": 0.1}, "name": "r", "limits": {"max_torque": 1.4}});
        assert_eq!(
            config_differences(&old, &new),
            [
                "fall.height 2.0 (now 4.0)",
                "limits (none) (now {\"max_torque\":1.4})"
            ]
        );
        assert!(config_differences(&old, &old).is_empty());
        let listed = differences(
            &[
                ("--seed", "1".into(), "1".into()),
                ("--trials", "40".into(), "41".into()),
            ],
            &old,
            &new,
        );
        assert_eq!(
            listed,
            "--trials 40 (now 41); the config (file or --set): fall.height 2.0 (now 4.0), limits (none) (now {\"max_torque\":1.4})"
        );
    }
}
