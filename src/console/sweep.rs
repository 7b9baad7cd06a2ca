//! `sweep`'s table: a line per point with each method's peak (and least
//! drop heights under a torque limit), and its closing warnings.

use crate::sweep::{SweepPoint, SweepSpec};
use std::path::PathBuf;

/// The sweep's table, `threads` the chunks it may compute at once (each
/// chunk's points one after another, continued: fewer chunks than threads
/// leave threads idle).
pub fn points(
    name: &str,
    spec: &SweepSpec,
    points: &[SweepPoint],
    threads: usize,
    written: &[PathBuf],
) -> Vec<String> {
    let chunks = points.len().div_ceil(crate::sweep::CHUNK);
    // fewer chunks than threads leave threads idle: say why
    let why = if threads > chunks {
        format!(
            "; a chunk's up to {} points continue one from another on one thread",
            crate::sweep::CHUNK
        )
    } else {
        String::new()
    };
    let mut lines = vec![format!(
        "catflip sweep: {} over {} ({} in {}, {} at a time{why})",
        name,
        spec.key,
        super::count(points.len(), "point"),
        super::count(chunks, "chunk"),
        threads.min(chunks).max(1)
    )];
    let show = |x: Option<f64>| x.map(|v| format!("{v:.5}")).unwrap_or_else(|| "-".into());
    let columns = columns(points);
    // the key's column as wide as the key
    let kw = spec.key.len().max(12);
    let mut head = format!("  {:>kw$}", spec.key);
    for c in &columns {
        head += &format!(" {:>w$}", c.console, w = c.console.len().max(12));
    }
    lines.push(head);
    for p in points {
        let mut line = format!("  {:>kw$.5}", p.value);
        for c in &columns {
            line += &format!(" {:>w$}", show((c.get)(p)), w = c.console.len().max(12));
        }
        if let Some(e) = &p.error {
            line += &format!("  error: {e}");
        }
        lines.push(line);
    }
    let mut t = super::Rows::default();
    t.wrote(written);
    lines.extend(t.into_lines());
    lines
}

/// A numeric column of a sweep's table: its heading on the console and on
/// the page, and its number at a point.
pub struct Column {
    pub console: &'static str,
    pub page: &'static str,
    /// Decimals on the page (the terminal shows five).
    pub digits: usize,
    pub get: fn(&SweepPoint) -> Option<f64>,
}

/// The numeric columns of a sweep's tables (the console's and the page's;
/// the CSV keeps every column): those with a number at some point. A method
/// not asked for, the peaks under `--least-height-only` and the least
/// heights without a stall torque leave theirs empty everywhere.
pub fn columns(points: &[SweepPoint]) -> Vec<Column> {
    let all = [
        Column {
            console: "analytic N m",
            page: "analytic peak N m",
            digits: 5,
            get: |p| p.analytic_peak_nm,
        },
        Column {
            console: "phased N m",
            page: "phased peak N m",
            digits: 5,
            get: |p| p.phased_peak_nm,
        },
        Column {
            console: "free N m",
            page: "free peak N m",
            digits: 5,
            get: |p| p.free_peak_nm,
        },
        Column {
            console: "phased h_min m",
            page: "least height, phased, m",
            digits: 3,
            get: |p| p.least_height_phased_m,
        },
        Column {
            console: "free h_min m",
            page: "least height, free, m",
            digits: 3,
            get: |p| p.least_height_free_m,
        },
    ];
    all.into_iter()
        .filter(|c| points.iter().any(|p| (c.get)(p).is_some()))
        .collect()
}

/// What a sweep from a start other than upside down at rest says of its
/// columns: the analytic and phased designs (of `methods`; peaks and least
/// heights) are made for the start at rest and do not land from this one
/// (`run` does not count them), the free-form designs are made for it.
/// `None` at today's start.
pub fn from_another_start(
    start: &crate::config::StartConfig,
    methods: &[String],
) -> Option<String> {
    if start.is_default() {
        return None;
    }
    let rest: Vec<&str> = ["analytic", "phased"]
        .into_iter()
        .filter(|m| methods.iter().any(|x| x == m))
        .collect();
    let mut parts = vec![format!(
        "from start.rotation_deg = {:?}, start.angular_velocity = {:?} rad/s",
        start.rotation_deg, start.angular_velocity
    )];
    if !rest.is_empty() {
        parts.push(format!(
            "the {} columns are the designs made for the start at rest, which do not land from this start (`catflip run` does not count them)",
            rest.join(" and "),
        ));
    }
    if methods.iter().any(|x| x == "free") {
        parts.push("the free-form columns are designed for this start".into());
    }
    let mut note = parts.join("; ");
    note[..1].make_ascii_uppercase();
    Some(format!("{note} (docs/model.md, section 8)."))
}

/// The warning of a sweep some of whose points have errors.
pub fn partial_warning(points: &[SweepPoint]) -> Option<String> {
    let bad = points.iter().filter(|p| p.error.is_some()).count();
    (bad > 0).then(|| {
        format!(
            "warning: partial result: {bad} of {} points have errors (see the error column); exit status 3",
            points.len()
        )
    })
}

/// What a shard that holds no points of the grid `grid` (`KEY=FROM:TO:N`,
/// `count` points) says, on the console and on its page: a job array wider
/// than the grid is legitimate, and nothing failed.
pub fn empty_shard(shard: &str, grid: &str, count: usize) -> String {
    format!(
        "shard {shard} holds no points of the grid {grid}: shards take whole continuation chunks of {} points, so use at most {}",
        crate::sweep::CHUNK,
        super::count(count.div_ceil(crate::sweep::CHUNK), "shard")
    )
}

/// A sweep's progress line for `done` of `total` points after `elapsed`
/// seconds ([`super::progress::bar`]).
pub fn progress_line(key: &str, done: usize, total: usize, elapsed: f64) -> String {
    super::progress::bar(&format!("sweep {key}"), done, total, "points", elapsed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_leaves_out_the_columns_no_point_has_a_number_in() {
        let spec: SweepSpec = "limits.no_load_speed=5:6:2".parse().unwrap();
        let heights_only = SweepPoint {
            value: 5.0,
            least_height_free_m: Some(3.5),
            ..Default::default()
        };
        let lines = points("robot", &spec, std::slice::from_ref(&heights_only), 1, &[]);
        assert!(lines[1].ends_with(" free h_min m"), "{}", lines[1]);
        assert!(!lines[1].contains("N m"), "{}", lines[1]);
        assert!(lines[2].ends_with(" 3.50000"), "{}", lines[2]);
        // a column with a number at one point is shown, "-" at the others
        let every = SweepPoint {
            value: 6.0,
            analytic_peak_nm: Some(1.0),
            phased_peak_nm: Some(0.9),
            free_peak_nm: Some(0.8),
            least_height_phased_m: Some(4.0),
            least_height_free_m: Some(3.0),
            ..Default::default()
        };
        let lines = points("robot", &spec, &[heights_only, every], 1, &[]);
        let at: Vec<Option<usize>> = [
            "analytic N m",
            "phased N m",
            "free N m",
            "phased h_min m",
            "free h_min m",
        ]
        .iter()
        .map(|h| lines[1].find(h))
        .collect();
        assert!(
            at.iter().all(Option::is_some) && at.is_sorted(),
            "{}",
            lines[1]
        );
        assert_eq!(lines[2].split_whitespace().filter(|c| *c == "-").count(), 4);
    }

    #[test]
    fn the_header_counts_the_chunks_that_can_run_at_once() {
        let spec: SweepSpec = "cat.radius=0.05:0.06:3".parse().unwrap();
        let header = |n: usize, threads: usize| {
            let pts: Vec<SweepPoint> = (0..n)
                .map(|i| SweepPoint {
                    value: i as f64,
                    ..Default::default()
                })
                .collect();
            points("seed", &spec, &pts, threads, &[]).remove(0)
        };
        // a chunk's points run one after another: three points are one chunk
        assert!(header(3, 2).ends_with(
            "(3 points in 1 chunk, 1 at a time; a chunk's up to 10 points continue one from another on one thread)"
        ));
        assert!(header(25, 2).ends_with("(25 points in 3 chunks, 2 at a time)"));
        assert!(header(40, 8).ends_with(
            "(40 points in 4 chunks, 4 at a time; a chunk's up to 10 points continue one from another on one thread)"
        ));
        assert!(header(3, 1).ends_with("(3 points in 1 chunk, 1 at a time)"));
    }
}
