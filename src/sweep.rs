//! Parameter sweeps: any numeric config key over a range, every point
//! designed by each method, points evaluated in parallel.

use crate::config::Config;
use crate::design::analytic::analytic_plan;
use crate::design::phased::least_height;
use crate::error::{Error, Result};
use crate::verify::analyze::peak_along;
use serde::Serialize;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `key=from:to:count`, e.g. `fall.height=0.5:10:40`.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSpec {
    pub key: String,
    pub from: f64,
    pub to: f64,
    pub count: usize,
}

impl std::str::FromStr for SweepSpec {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = |m: &str| Error::Range {
            arg: s.into(),
            message: format!("{m}; expected KEY=FROM:TO:COUNT, e.g. fall.height=0.5:10:40"),
        };
        let (key, range) = s.split_once('=').ok_or_else(|| bad("no `=`"))?;
        let parts: Vec<&str> = range.split(':').collect();
        if parts.len() != 3 {
            return Err(bad("the range needs three fields"));
        }
        let num = |x: &str| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| bad(&format!("`{x}` is not a number")))
        };
        let (from, to) = (num(parts[0])?, num(parts[1])?);
        let count: usize = parts[2]
            .trim()
            .parse()
            .map_err(|_| bad("COUNT must be a whole number"))?;
        if count < 1 || !from.is_finite() || !to.is_finite() || !(to - from).is_finite() {
            return Err(bad("COUNT must be at least 1 and the ends finite"));
        }
        if count > MAX_POINTS {
            return Err(bad(&format!(
                "COUNT {count} is more than the {MAX_POINTS} points a sweep may have; split the range into several sweeps"
            )));
        }
        Ok(SweepSpec {
            key: key.trim().into(),
            from,
            to,
            count,
        })
    }
}

/// Most points a sweep may have: each point runs whole optimisations, so
/// more would take days; the bound also keeps the result table in memory.
pub const MAX_POINTS: usize = 10_000;

impl SweepSpec {
    /// The argument as the user would write it, for messages.
    pub fn arg(&self) -> String {
        format!("{}={}:{}:{}", self.key, self.from, self.to, self.count)
    }

    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.from];
        }
        (0..self.count)
            .map(|i| self.from + (self.to - self.from) * (i as f64 / (self.count - 1) as f64))
            .collect()
    }
}

/// Which designs a sweep computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Methods {
    pub analytic: bool,
    pub phased: bool,
    pub free: bool,
}

/// One point of a sweep. Peaks are computed without the torque limit; with a
/// limit, the least drop height at which each design meets it (F7) is given.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SweepPoint {
    pub value: f64,
    pub analytic_peak_nm: Option<f64>,
    pub phased_peak_nm: Option<f64>,
    pub free_peak_nm: Option<f64>,
    pub phased_bend_deg: Option<f64>,
    pub free_bend_deg: Option<f64>,
    pub least_height_phased_m: Option<f64>,
    pub least_height_free_m: Option<f64>,
    pub error: Option<String>,
}

fn point(cfg: &Config, value: f64, methods: Methods) -> Result<SweepPoint> {
    let mut p = SweepPoint {
        value,
        ..Default::default()
    };
    let limit = cfg.limits.max_torque;
    let mut cfg = cfg.clone();
    cfg.limits.max_torque = None;
    let t2 = cfg.available_time().powi(2);
    if methods.analytic {
        p.analytic_peak_nm = Some(
            peak_along(
                &cfg,
                &analytic_plan(&cfg),
                crate::verify::analyze::dense_samples(&cfg),
            )
            .0,
        );
    }
    // a method that fails leaves its columns empty and its reason in `error`;
    // the other methods' numbers are kept
    let mut errors = Vec::new();
    if methods.phased || methods.free {
        let ph = crate::design::phased::optimize(&cfg, |_| {});
        match &ph {
            Ok(ph) if methods.phased => {
                errors.extend(flagged(
                    "phased",
                    &format!("{:?}", ph.status),
                    ph.flip_error_rad,
                    ph.tilt_deg,
                    &cfg,
                ));
                p.phased_peak_nm = Some(ph.peak_torque_nm);
                p.phased_bend_deg = Some(ph.bend_deg);
                p.least_height_phased_m =
                    limit.map(|l| least_height(&cfg, ph.peak_torque_nm * t2, l));
            }
            Err(e) if methods.phased => errors.push(format!("phased: {e}")),
            _ => {}
        }
        if methods.free {
            // seeded by the phased design, or by the analytic plan when that failed
            let fr = match &ph {
                Ok(ph) => crate::design::free::optimize_from(
                    &cfg,
                    &ph.plan,
                    "phased",
                    cfg.free.nodes,
                    |_| {},
                ),
                Err(_) => crate::design::free::optimize_from(
                    &cfg,
                    &analytic_plan(&cfg),
                    "analytic",
                    cfg.free.nodes,
                    |_| {},
                ),
            };
            match fr {
                Ok(fr) => {
                    errors.extend(flagged(
                        "free",
                        &format!("{:?}", fr.status),
                        fr.flip_error_rad,
                        fr.tilt_deg,
                        &cfg,
                    ));
                    p.free_peak_nm = Some(fr.peak_torque_nm);
                    p.free_bend_deg = Some(fr.bend_deg);
                    p.least_height_free_m =
                        limit.map(|l| least_height(&cfg, fr.peak_torque_nm * t2, l));
                }
                Err(e) => errors.push(format!("free: {e}")),
            }
        }
    }
    if !errors.is_empty() {
        p.error = Some(errors.join("; "));
    }
    Ok(p)
}

/// A kept design that misses a target (unconverged, flip missed) is named in
/// the point's `error` column beside its numbers.
fn flagged(
    method: &str,
    status: &str,
    flip_error: f64,
    tilt_deg: f64,
    cfg: &Config,
) -> Option<String> {
    let mut why: Vec<String> = Vec::new();
    if !matches!(status, "Solved" | "Converged") {
        why.push(format!("solver status {}", status.to_lowercase()));
    }
    why.extend(crate::verify::simulate::misses_flip(
        flip_error,
        tilt_deg,
        cfg.simulate.flip_tolerance,
    ));
    (!why.is_empty()).then(|| format!("{method} FLAGGED: {}", why.join(", ")))
}

/// Runs a sweep on the config at `path` (with `overrides`), `threads` points at a time.
pub fn sweep(
    path: &Path,
    overrides: &[String],
    spec: &SweepSpec,
    methods: Methods,
    threads: usize,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Vec<SweepPoint>> {
    let values = spec.values();
    let load = |v: f64| {
        let mut ov = overrides.to_vec();
        ov.push(format!("{}={}", spec.key, v));
        Config::load(path, &ov)
    };
    // a point whose config is invalid is that point's failure; when every
    // point is invalid (e.g. an unknown key) the sweep fails before any work
    let configs: Vec<Result<Config>> = values
        .iter()
        .map(|&v| {
            load(v).map_err(|e| Error::Range {
                arg: spec.arg(),
                message: match e {
                    // the override is internal: name the point, not a `--set`
                    Error::Override { message, .. } => format!("at {} = {v}: {message}", spec.key),
                    e => format!("at {} = {v}: {e}", spec.key),
                },
            })
        })
        .collect();
    if let Some(Err(first)) = configs.first()
        && configs.iter().all(|c| c.is_err())
    {
        return Err(Error::Range {
            arg: spec.arg(),
            message: match first {
                Error::Range { message, .. } => format!("every point is invalid; {message}"),
                e => e.to_string(),
            },
        });
    }
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<SweepPoint>>> = Mutex::new(vec![None; values.len()]);
    std::thread::scope(|s| {
        for _ in 0..threads.max(1).min(values.len()) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    if i >= values.len() {
                        break;
                    }
                    let p = configs[i]
                        .as_ref()
                        .map_err(|e| e.to_string())
                        .and_then(|c| point(c, values[i], methods).map_err(|e| e.to_string()))
                        .unwrap_or_else(|e| SweepPoint {
                            value: values[i],
                            error: Some(e),
                            ..Default::default()
                        });
                    results.lock().unwrap()[i] = Some(p);
                    progress(done.fetch_add(1, Ordering::SeqCst) + 1, values.len());
                }
            });
        }
    });
    Ok(results
        .into_inner()
        .unwrap()
        .into_iter()
        .map(|p| p.expect("every point ran"))
        .collect())
}

fn cell(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.9e}")).unwrap_or_default()
}

/// CSV of a sweep: the swept value first.
pub fn to_csv(key: &str, points: &[SweepPoint]) -> String {
    let mut s = format!(
        "{key},analytic_peak_nm,phased_peak_nm,free_peak_nm,phased_bend_deg,free_bend_deg,least_height_phased_m,least_height_free_m,error\n"
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            p.value,
            cell(p.analytic_peak_nm),
            cell(p.phased_peak_nm),
            cell(p.free_peak_nm),
            cell(p.phased_bend_deg),
            cell(p.free_bend_deg),
            cell(p.least_height_phased_m),
            cell(p.least_height_free_m),
            p.error.as_deref().unwrap_or("").replace([',', '\n'], ";")
        ));
    }
    s
}

/// Peak against the swept value, one line per method; and, with a torque
/// limit, the least drop height.
/// `file_key` names the files, `key` labels the axes.
pub fn figures(
    file_key: &str,
    key: &str,
    points: &[SweepPoint],
    limit: Option<f64>,
) -> Result<Vec<(String, String)>> {
    let x: Vec<f64> = points.iter().map(|p| p.value).collect();
    let col = |f: &dyn Fn(&SweepPoint) -> Option<f64>| {
        points
            .iter()
            .map(|p| f(p).unwrap_or(f64::NAN))
            .collect::<Vec<_>>()
    };
    let mut series = Vec::new();
    for (name, f) in [
        (
            "analytic",
            &(|p: &SweepPoint| p.analytic_peak_nm) as &dyn Fn(&SweepPoint) -> Option<f64>,
        ),
        ("phased", &|p: &SweepPoint| p.phased_peak_nm),
        ("free", &|p: &SweepPoint| p.free_peak_nm),
    ] {
        let ys = col(f);
        if ys.iter().any(|y| y.is_finite()) {
            series.push((name.to_string(), ys));
        }
    }
    let xdesc = crate::config::key_label(key);
    let mut figs = vec![(
        format!("sweep-{file_key}.svg"),
        crate::report::lines(
            &format!("Peak joint torque against {key}"),
            &xdesc,
            "peak torque (N m)",
            &x,
            &series,
        )?,
    )];
    if let Some(l) = limit {
        let mut hs = Vec::new();
        for (name, f) in [
            (
                "phased",
                &(|p: &SweepPoint| p.least_height_phased_m) as &dyn Fn(&SweepPoint) -> Option<f64>,
            ),
            ("free", &|p: &SweepPoint| p.least_height_free_m),
        ] {
            let ys = col(f);
            if ys.iter().any(|y| y.is_finite()) {
                hs.push((name.to_string(), ys));
            }
        }
        figs.push((
            format!("sweep-{file_key}-least-height.svg"),
            crate::report::lines(
                &format!("Least drop height for {l} N m against {key}"),
                &xdesc,
                "least drop height (m)",
                &x,
                &hs,
            )?,
        ));
    }
    Ok(figs)
}
