//! `run`'s table: the methods compared, their ratios, the robot's answer
//! and where the report is; and the closing word on stderr.

use crate::run::{Outcome, RunSummary};
use std::path::Path;

/// The lines `run` prints on stdout (a blank line after the stage lines).
pub fn summary(s: &RunSummary, report: &Path, files: usize) -> Vec<String> {
    let mut lines = vec![
        String::new(),
        format!(
            "catflip run: {} ({} joint, peak norm {})",
            s.name,
            s.joint,
            s.peak_norm.name()
        ),
    ];
    lines.extend(s.limits.line().map(|l| format!("  {l}")));
    let rows = s.methods.iter().map(crate::table::table_row).collect();
    lines.extend(super::Columns::new(&crate::table::TABLE_HEADER, rows).lines());
    let ratios = crate::table::peak_ratios(s.free_over_phased, s.phased_over_analytic);
    lines.push(format!(
        "  {ratios}{}free-form design: {}",
        if ratios.is_empty() { "" } else { "; " },
        crate::table::free_design_text(&s.methods, &s.mesh_levels, s.free_seed.as_deref())
    ));
    if let Some(note) = s.braking_note() {
        lines.push(format!("  {note}"));
    }
    if let Some(a) = &s.answer {
        lines.push(format!("  {}", a.sentence()));
    }
    lines.push(format!("  report: {} ({files} files)", report.display()));
    lines
}

/// What `run` says on stderr at the end about its exit status, if anything:
/// for a partial result, which methods make it so and why.
pub fn closing(s: &RunSummary) -> Option<String> {
    match s.outcome {
        Outcome::Ok => None,
        Outcome::Impossible => {
            Some("the flip is not possible from this height: exit status 4".into())
        }
        Outcome::Partial => Some(format!(
            "warning: partial result: {} (see the verdict column); exit status 3",
            s.against().join(", ")
        )),
    }
}
