//! The comparison table of the methods, shared by the terminal
//! (`catflip run`'s table) and the report (index.html, the animation's
//! captions): its columns, one line per method, and a verdict in words.

use crate::pipeline::MethodSummary;
use crate::verdict::Grade;

/// Columns of the comparison table (terminal and index.html).
pub const TABLE_HEADER: [&str; 12] = [
    "method",
    "status",
    "peak N m",
    "energy (N m)^2 s",
    "bend deg",
    "durations s",
    "flip error rad",
    "tilt deg",
    "landing deg",
    "sim peak N m",
    "solve s",
    "verdict",
];

/// A number in the table to 3 significant digits: `0` for exact zero,
/// plain from a thousandth to a thousand (a landing 154 deg off read
/// `1.54e2`), otherwise in scientific notation (`-1.75e-4`).
pub fn three_digits(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-3..999.5).contains(&a) {
        return format!("{x:.2e}");
    }
    // digits after the point for 3 significant ones, from the rounded value
    let magnitude = format!("{a:.2e}")
        .split_once('e')
        .and_then(|(_, e)| e.parse::<i32>().ok())
        .unwrap_or(0);
    format!("{x:.*}", (2 - magnitude).max(0) as usize)
}

/// A verdict as the table words it: `ok`, `FLAGGED: <why>`, `FAILED: <why>`,
/// `not possible: <why>` (the motors cannot do it in this fall: an answer,
/// not an error).
pub fn verdict_text(grade: Grade, reason: Option<&str>) -> String {
    match grade {
        Grade::Ok => "ok".to_string(),
        Grade::Flagged => format!("FLAGGED: {}", reason.unwrap_or("")),
        Grade::Failed => format!("FAILED: {}", reason.unwrap_or("")),
        Grade::Impossible => format!("not possible: {}", reason.unwrap_or("")),
    }
}

/// A method's verdict in words, a reference not counted said to be one.
fn method_verdict(m: &MethodSummary) -> String {
    let text = verdict_text(m.verdict, m.reason.as_deref());
    match m.reference_note() {
        Some(note) => format!("{text} ({note})"),
        None => text,
    }
}

/// One line of the comparison table; a failed method shows `-` for its numbers.
pub fn table_row(m: &MethodSummary) -> Vec<String> {
    let mut row = vec![m.method.to_string(), m.status.to_string()];
    match &m.result {
        Some(n) => {
            let d = n.phase_durations_s;
            row.extend([
                format!("{:.5}", n.peak_torque_nm),
                format!("{:.4e}", n.energy_n2m2s),
                format!("{:.2}", n.bend_deg),
                format!("{:.3}/{:.3}/{:.3}", d[0], d[1], d[2]),
                three_digits(n.flight.flip_error_rad),
                three_digits(n.flight.tilt_deg),
                three_digits(n.flight.landing_error_deg),
                format!("{:.5}", n.flight.sim_peak_torque_nm),
                format!("{:.3}", n.solve_time_s),
            ]);
        }
        None => row.extend(std::iter::repeat_n("-".to_string(), 9)),
    }
    row.push(method_verdict(m));
    row
}

/// The peak ratios that exist, in words (`free-form / phased peak 0.595,
/// phased / analytic 0.032`); a ratio whose method is missing is left out,
/// and with neither the text is empty.
pub fn peak_ratios(free_over_phased: Option<f64>, phased_over_analytic: Option<f64>) -> String {
    [
        free_over_phased.map(|r| format!("free-form / phased peak {r:.3}")),
        phased_over_analytic.map(|r| format!("phased / analytic {r:.3}")),
    ]
    .into_iter()
    .flatten()
    .collect::<Vec<_>>()
    .join(", ")
}

/// The suffix of a seed's name taken as its mirror image.
const MIRRORED: &str = crate::design::mirror::MIRRORED;

/// The suffix of a seed's name taken turning only as far as the start needs.
const SCALED: &str = crate::design::mirror::SCALED;

/// How the free-form design went, for the lines under the table: its
/// meshes and iterations and what it started from (`seed`), or that it was
/// not attempted.
pub fn free_design_text(
    methods: &[MethodSummary],
    mesh_levels: &[crate::design::free::MeshLevel],
    seed: Option<&str>,
) -> String {
    let free = methods.iter().find(|m| m.method == "free");
    if free.is_some_and(|m| m.verdict == Grade::Impossible) {
        "not attempted (the motors cannot do it in this fall), see its row".into()
    } else {
        // (a seed made for the start at rest may be taken mirrored, the
        // other way round: `design::mirror`)
        let mirrored = seed.is_some_and(|s| s.ends_with(MIRRORED));
        let seed = seed.map(|s| s.trim_end_matches(MIRRORED));
        // (and scaled to the turn the start leaves)
        let scaled = seed.is_some_and(|s| s.ends_with(SCALED));
        let from = match seed.map(|s| s.trim_end_matches(SCALED)) {
            Some("phased") => "from the phased design",
            Some(crate::pipeline::FREE_LEAST_TIME) => "from the least-height design",
            Some("analytic") => "from the analytic schedule",
            _ => "",
        };
        let from = match (from.is_empty(), mirrored) {
            (true, _) => String::new(),
            (false, true) => format!("{from} mirrored (the other way round)"),
            (false, false) => from.to_string(),
        };
        let from = match (from.is_empty(), scaled) {
            (true, _) => from,
            (false, true) => format!("{from}, its twist scaled to the turn the start leaves, "),
            (false, false) => format!("{from}, "),
        };
        format!(
            "{from}{}",
            crate::design::free::iterations_text(mesh_levels)
        )
    }
}

/// A method's warning line (flagged or failed): its name and reasons.
pub fn warning(m: &MethodSummary) -> Option<String> {
    let why = m.reason.as_ref()?;
    Some(match m.reference_note() {
        Some(note) => format!("{}: {why} ({note})", m.method),
        None => format!("{}: {why}", m.method),
    })
}

/// The animation's caption of a method: its status and verdict.
pub fn track_status(m: &MethodSummary) -> String {
    format!("{}; {}", m.status, method_verdict(m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three significant digits, plain where a reader reads them plainly.
    #[test]
    fn table_numbers_are_plain_from_a_thousandth_to_a_thousand() {
        let cases = [
            (0.0, "0"),
            (154.2, "154"),
            (-2.695, "-2.69"),
            (2.7, "2.70"),
            (0.0923, "0.0923"),
            (0.00649, "0.00649"),
            (0.01, "0.0100"),
            (9.996, "10.0"),
            (0.0009996, "1.00e-3"),
            (-1.75e-4, "-1.75e-4"),
            (999.4, "999"),
            (999.6, "1.00e3"),
            (12345.0, "1.23e4"),
        ];
        for (x, text) in cases {
            assert_eq!(three_digits(x), text, "{x}");
        }
    }

    /// The ratios that exist are named, the missing ones left out.
    #[test]
    fn peak_ratios_name_only_the_ratios_that_exist() {
        assert_eq!(
            peak_ratios(Some(0.5951), Some(0.0321)),
            "free-form / phased peak 0.595, phased / analytic 0.032"
        );
        assert_eq!(peak_ratios(None, Some(0.0321)), "phased / analytic 0.032");
        assert_eq!(
            peak_ratios(Some(0.5951), None),
            "free-form / phased peak 0.595"
        );
        assert_eq!(peak_ratios(None, None), "");
    }

    #[test]
    fn a_verdict_reads_as_the_grade_and_its_reason() {
        assert_eq!(verdict_text(Grade::Ok, Some("ignored")), "ok");
        assert_eq!(verdict_text(Grade::Flagged, Some("x")), "FLAGGED: x");
        assert_eq!(verdict_text(Grade::Failed, None), "FAILED: ");
        assert_eq!(
            verdict_text(Grade::Impossible, Some("needs 3 m")),
            "not possible: needs 3 m"
        );
    }
}
