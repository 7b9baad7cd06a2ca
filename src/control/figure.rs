//! The study's figure: each controller's success rate against the size of
//! each perturbation, as a fraction of its largest configured value (trials
//! binned by that one perturbation, the others drawn as they fell).

use super::robustness::{CONTROLLERS, TrialResult};
use crate::config::Config;
use crate::error::Result;

/// Bins along each perturbation's size.
const BINS: usize = 5;

/// The index.html caption of the study's figure (any shard's).
pub fn caption(file: &str) -> Option<&'static str> {
    (file.starts_with("robustness") && file.ends_with(".svg")).then_some(
        "Each controller's success rate against the size of each perturbation (spin, tilt, inertia error), as a fraction of its largest value in [robustness]: the trials binned by that one perturbation, the others as they fell. A colour per controller, a dash and marker per perturbation; a bin without trials is left out.",
    )
}

/// The SVG, or `None` when no perturbation varies.
pub fn success_by_size(
    cfg: &Config,
    results: &[TrialResult],
    max_tilt_deg: f64,
) -> Result<Option<String>> {
    let p = &cfg.robustness;
    let spin_max = p.spin_rad_s.iter().copied().fold(0.0, f64::max);
    type Size = fn(&TrialResult) -> f64;
    let sizes: [(&str, f64, Size); 3] = [
        ("spin", spin_max, |r| {
            let w = r.draw.spin_rad_s;
            (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
        }),
        ("tilt", p.tilt_deg, |r| r.draw.tilt_deg),
        ("inertia", p.inertia_error, |r| {
            r.draw.inertia_error[0]
                .abs()
                .max(r.draw.inertia_error[1].abs())
        }),
    ];
    let x: Vec<f64> = (0..BINS).map(|b| (b as f64 + 0.5) / BINS as f64).collect();
    let mut series = Vec::new();
    for (what, max, size) in sizes {
        if max <= 0.0 {
            continue;
        }
        for (c, name) in CONTROLLERS.iter().enumerate() {
            let mut hits = [(0usize, 0usize); BINS];
            for r in results {
                let b = ((size(r) / max * BINS as f64) as usize).min(BINS - 1);
                hits[b].1 += 1;
                if r.landing_error_deg[c] <= max_tilt_deg {
                    hits[b].0 += 1;
                }
            }
            let ys = hits
                .iter()
                .map(|&(k, n)| {
                    if n == 0 {
                        f64::NAN
                    } else {
                        k as f64 / n as f64
                    }
                })
                .collect();
            series.push((format!("{name}: {what}"), ys));
        }
    }
    if series.is_empty() || results.is_empty() {
        return Ok(None);
    }
    Ok(Some(crate::report::lines_styled(
        &format!("Landing within {max_tilt_deg} deg against each perturbation's size"),
        "size, fraction of its largest value in [robustness]",
        "success rate",
        &x,
        &series,
        series_style,
    )?))
}

/// A series' style from its name `controller: perturbation`: the colour
/// tells the controller, the dash and marker the perturbation (nine series:
/// the report's four styles would repeat), both from
/// [`crate::report::distinct_style`].
fn series_style(name: &str, _: usize) -> crate::report::Style {
    use crate::report::distinct_style;
    let (controller, what) = name.split_once(": ").unwrap_or((name, ""));
    let c = CONTROLLERS
        .iter()
        .position(|&n| n == controller)
        .unwrap_or(0);
    let p = ["spin", "tilt", "inertia"]
        .iter()
        .position(|&n| n == what)
        .unwrap_or(0);
    crate::report::Style {
        color: distinct_style(c).color,
        ..distinct_style(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The study's nine series are drawn nine ways: one colour a
    /// controller, one dash and marker a perturbation.
    #[test]
    fn every_series_of_the_study_has_its_own_style() {
        let mut seen = Vec::new();
        for what in ["spin", "tilt", "inertia"] {
            for c in CONTROLLERS {
                let st = series_style(&format!("{c}: {what}"), 0);
                let key = (
                    (st.color.0, st.color.1, st.color.2),
                    st.dash,
                    format!("{:?}", st.marker),
                );
                assert!(!seen.contains(&key), "{c}: {what} repeats {key:?}");
                seen.push(key);
            }
        }
        // a controller keeps its colour across perturbations
        let color = |n: &str| series_style(n, 0).color.0;
        assert_eq!(color("tvlqr: spin"), color("tvlqr: inertia"));
        assert_ne!(color("tvlqr: spin"), color("replan: spin"));
    }
}
