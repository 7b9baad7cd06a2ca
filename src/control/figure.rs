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
        "Each controller's success rate against the size of each perturbation (spin, tilt, inertia error), as a fraction of its largest value in [robustness]: the trials binned by that one perturbation, the others as they fell. A colour per controller, a dash and marker per perturbation; a bin without trials is left out. The notes above give each bin's trials: a rate from few trials is uncertain.",
    )
}

/// One perturbation's trials in the figure's bins, a fifth of its largest
/// configured value each, smallest first.
#[derive(Debug, Clone, PartialEq)]
pub struct Bins {
    /// `spin` (the release rate's magnitude), `tilt` or `inertia` (the
    /// larger of the halves' errors).
    pub perturbation: &'static str,
    /// Trials in each bin.
    pub trials: [usize; BINS],
    /// Of them, the ones each controller ([`CONTROLLERS`]) landed.
    pub landed: [[usize; BINS]; CONTROLLERS.len()],
}

/// The bins of each perturbation the study varies (one whose largest value
/// is zero is left out).
pub fn bins(cfg: &Config, results: &[TrialResult], max_tilt_deg: f64) -> Vec<Bins> {
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
    sizes
        .into_iter()
        .filter(|s| s.1 > 0.0)
        .map(|(perturbation, max, size)| {
            let mut b = Bins {
                perturbation,
                trials: [0; BINS],
                landed: [[0; BINS]; CONTROLLERS.len()],
            };
            for r in results {
                let k = ((size(r) / max * BINS as f64) as usize).min(BINS - 1);
                b.trials[k] += 1;
                for (c, landed) in b.landed.iter_mut().enumerate() {
                    if r.landing_error_deg[c] <= max_tilt_deg {
                        landed[k] += 1;
                    }
                }
            }
            b
        })
        .collect()
}

/// The page's note on the bins' trials: "spin 205, 198, ...; tilt ...".
pub fn bins_note(bins: &[Bins]) -> Option<String> {
    (!bins.is_empty()).then(|| {
        let each: Vec<String> = bins
            .iter()
            .map(|b| {
                let n: Vec<String> = b.trials.iter().map(|n| n.to_string()).collect();
                format!("{} {}", b.perturbation, n.join(", "))
            })
            .collect();
        format!(
            "The figure's bins (a fifth of each perturbation's largest value each, smallest first) hold these trials: {}.",
            each.join("; ")
        )
    })
}

/// The SVG of the study's [`bins`], or `None` when no perturbation varies
/// or there are no trials.
pub fn success_by_size(bins: &[Bins], max_tilt_deg: f64) -> Result<Option<String>> {
    let x: Vec<f64> = (0..BINS).map(|b| (b as f64 + 0.5) / BINS as f64).collect();
    let mut series = Vec::new();
    for b in bins {
        for (name, landed) in CONTROLLERS.iter().zip(&b.landed) {
            let ys = landed
                .iter()
                .zip(&b.trials)
                .map(|(&k, &n)| {
                    if n == 0 {
                        f64::NAN
                    } else {
                        k as f64 / n as f64
                    }
                })
                .collect();
            series.push((format!("{name}: {}", b.perturbation), ys));
        }
    }
    if bins.iter().all(|b| b.trials.iter().sum::<usize>() == 0) {
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

    /// Every trial falls in one bin of each perturbation, by its own size:
    /// the counts add up to the trials, the landings never exceed them, and
    /// a perturbation the study does not vary has no bins.
    #[test]
    fn each_perturbations_bins_count_every_trial_once_by_its_size() {
        let cfg = Config::from_toml(
            include_str!("../../configs/seed.toml"),
            "seed",
            &["robustness.inertia_error=0".into()],
        )
        .unwrap();
        let results: Vec<TrialResult> = (0..200)
            .map(|t| {
                let draw = crate::control::robustness::Draw::new(&cfg, 7, t);
                // the open loop lands the small tilts, TVLQR every trial,
                // replanning none
                let open = if draw.tilt_deg < 0.5 * cfg.robustness.tilt_deg {
                    1.0
                } else {
                    50.0
                };
                TrialResult {
                    draw,
                    landing_error_deg: [open, 0.0, 180.0],
                    replans: Vec::new(),
                }
            })
            .collect();
        let b = bins(&cfg, &results, 10.0);
        let names: Vec<&str> = b.iter().map(|b| b.perturbation).collect();
        assert_eq!(names, ["spin", "tilt"]);
        for b in &b {
            assert_eq!(b.trials.iter().sum::<usize>(), 200, "{b:?}");
            assert_eq!(b.landed[1], b.trials, "TVLQR lands every trial");
            assert_eq!(b.landed[2], [0; BINS], "replanning lands none");
        }
        let tilt = &b[1];
        // tilts are uniform up to the largest: the open loop lands the
        // first two bins whole, half the middle one, none above
        assert_eq!(tilt.landed[0][..2], tilt.trials[..2]);
        assert!(0 < tilt.landed[0][2] && tilt.landed[0][2] < tilt.trials[2]);
        assert_eq!(tilt.landed[0][3..], [0, 0]);
        let tilt_by_hand = (0..BINS)
            .map(|k| {
                results
                    .iter()
                    .filter(|r| {
                        let f = r.draw.tilt_deg / cfg.robustness.tilt_deg;
                        ((f * BINS as f64) as usize).min(BINS - 1) == k
                    })
                    .count()
            })
            .collect::<Vec<_>>();
        assert_eq!(tilt.trials.to_vec(), tilt_by_hand);
        let note = bins_note(&b).unwrap();
        let listed: Vec<String> = tilt.trials.iter().map(|n| n.to_string()).collect();
        assert!(
            note.contains(&format!("tilt {}", listed.join(", "))),
            "{note}"
        );
        assert!(!note.contains("inertia"), "{note}");
        assert_eq!(bins_note(&[]), None);
    }

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
