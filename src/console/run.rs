//! `run`'s table: the methods compared, their ratios, the robot's answer
//! and where the report is; and the closing word on stderr.

use crate::run::{Outcome, RunSummary};
use crate::verdict::Grade;
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
    let rows = s.methods.iter().map(crate::table::table_row).collect();
    lines.extend(super::Columns::new(&crate::table::TABLE_HEADER, rows).lines());
    let ratios = crate::table::peak_ratios(s.free_over_phased, s.phased_over_analytic);
    lines.push(format!(
        "  {ratios}{}free-form design: {}",
        if ratios.is_empty() { "" } else { "; " },
        crate::table::free_design_text(&s.methods, &s.mesh_levels, s.free_seed.as_deref())
    ));
    if let Some(note) = braking_note(s) {
        lines.push(note);
    }
    if let Some(a) = &s.answer {
        lines.push(format!("  {}", a.sentence()));
    }
    lines.push(format!("  report: {} ({files} files)", report.display()));
    lines
}

/// Why a sound design's peak can be above the stall torque: a DC motor
/// driven against its speed brakes with more (`T + k |w|`, the torque-speed
/// line), which a table of peaks alone would read as a broken limit.
fn braking_note(s: &RunSummary) -> Option<String> {
    above_stall(
        s.max_torque_nm,
        s.methods.iter().map(|m| (m.method, m.verdict, m.peak())),
    )
}

/// [`braking_note`] on the stall torque and each method's name, verdict and
/// peak: a note for the sound ones (verdict ok) above the stall torque.
fn above_stall<'a>(
    stall: Option<f64>,
    methods: impl Iterator<Item = (&'a str, Grade, Option<f64>)>,
) -> Option<String> {
    let stall = stall?;
    let above: Vec<&str> = methods
        .filter(|(_, verdict, peak)| {
            *verdict == Grade::Ok && peak.is_some_and(|p| p > stall * (1.0 + 1e-6))
        })
        .map(|(name, _, _)| name)
        .collect();
    (!above.is_empty()).then(|| {
        format!(
            "  {}: peak above the {stall} N m stall torque while braking, which the motor's torque-speed line allows (T + k |w| against the speed; docs/model.md, section 5)",
            above.join(", ")
        )
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Only a sound design above the stall torque gets the note: a flagged
    /// one breaks its limit (its reason says so), and without a stall
    /// torque there is nothing to be above.
    #[test]
    fn the_braking_note_names_the_sound_designs_above_the_stall_torque() {
        let rows = [
            ("analytic", Grade::Flagged, Some(3.0)),
            ("free", Grade::Ok, Some(1.2)),
            ("least-height", Grade::Ok, Some(2.0)),
            ("phased", Grade::Impossible, None),
        ];
        let note = above_stall(Some(1.4), rows.into_iter()).expect("a note");
        assert!(
            note.starts_with("  least-height: peak above the 1.4 N m"),
            "{note}"
        );
        assert!(
            !note.contains("analytic") && !note.contains("free"),
            "{note}"
        );
        assert_eq!(above_stall(None, rows.into_iter()), None);
        assert_eq!(above_stall(Some(3.5), rows.into_iter()), None);
        // at the stall torque to rounding: no note
        assert_eq!(
            above_stall(
                Some(2.0),
                [("free", Grade::Ok, Some(2.0 * (1.0 + 1e-9)))].into_iter()
            ),
            None
        );
    }
}
