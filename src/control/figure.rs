//! The study's figure: each controller's success rate against the size of
//! each perturbation, in its own unit (trials binned by that one
//! perturbation, the others drawn as they fell), with the rate's 95 %
//! interval, so that a bin of few trials shows how little it says.

use super::robustness::{CONTROLLERS, TrialResult, wilson};
use crate::config::Config;
use crate::error::Result;
use crate::report::{Rate, RatePanel};

/// The most bins along each perturbation's size.
const MAX_BINS: usize = 5;

/// Trials a bin holds on average: a smaller study gets fewer bins (at
/// least two), so that its rates are not each a handful of trials.
const TRIALS_PER_BIN: usize = 20;

/// Bins along each perturbation's size for a study of `trials`.
pub fn bin_count(trials: usize) -> usize {
    (trials / TRIALS_PER_BIN).clamp(2, MAX_BINS)
}

/// The index.html caption of the study's figure (any shard's).
pub fn caption(file: &str) -> Option<&'static str> {
    (file.starts_with("robustness") && file.ends_with(".svg")).then_some(
        "Each controller's success rate against the size of each perturbation (spin, tilt, inertia error; a panel each, its axis in the perturbation's unit up to its largest value in [robustness]): the trials binned by that one perturbation, the others as they fell. A colour per controller; each bar is the rate's 95 % (Wilson) interval, wide where a bin holds few trials; a bin without trials is left out. The notes above give each bin's trials.",
    )
}

/// One perturbation's trials in the figure's bins ([`bin_count`] equal
/// parts of its largest configured value, smallest first).
#[derive(Debug, Clone, PartialEq)]
pub struct Bins {
    /// `spin` (the release rate's magnitude), `tilt` or `inertia` (the
    /// larger of the halves' errors).
    pub perturbation: &'static str,
    /// The size's axis: what it is and its unit.
    pub axis: &'static str,
    /// The largest size drawn, in the axis' unit: the bins split 0 to it.
    pub largest: f64,
    /// Trials in each bin.
    pub trials: Vec<usize>,
    /// Of them, the ones each controller ([`CONTROLLERS`]) landed.
    pub landed: [Vec<usize>; CONTROLLERS.len()],
}

impl Bins {
    /// Each bin's centre, in the axis' unit.
    pub fn centres(&self) -> Vec<f64> {
        let n = self.trials.len();
        (0..n)
            .map(|b| self.largest * (b as f64 + 0.5) / n as f64)
            .collect()
    }
}

/// The bins of each perturbation the study varies (one whose largest value
/// is zero is left out).
pub fn bins(cfg: &Config, results: &[TrialResult], max_tilt_deg: f64) -> Vec<Bins> {
    let p = &cfg.robustness;
    let spin_max = p.spin_rad_s.iter().copied().fold(0.0, f64::max);
    type Size = fn(&TrialResult) -> f64;
    // (the inertia error in % on its axis: a fraction reads as a rate)
    let sizes: [(&str, &str, f64, f64, Size); 3] = [
        ("spin", "spin at release, rad/s", spin_max, 1.0, |r| {
            let w = r.draw.spin_rad_s;
            (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
        }),
        ("tilt", "tilt at release, deg", p.tilt_deg, 1.0, |r| {
            r.draw.tilt_deg
        }),
        (
            "inertia",
            "inertia error (larger half), %",
            p.inertia_error,
            100.0,
            |r| {
                r.draw.inertia_error[0]
                    .abs()
                    .max(r.draw.inertia_error[1].abs())
            },
        ),
    ];
    sizes
        .into_iter()
        .filter(|s| s.2 > 0.0)
        .map(|(perturbation, axis, max, unit, size)| {
            let bins = bin_count(results.len());
            let mut b = Bins {
                perturbation,
                axis,
                largest: max * unit,
                trials: vec![0; bins],
                landed: std::array::from_fn(|_| vec![0; bins]),
            };
            for r in results {
                let k = ((size(r) / max * bins as f64) as usize).min(bins - 1);
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

/// The page's note on how many trials each bin holds: "spin 205, 198, ...;
/// tilt ..." (counts, not the trials' numbers the page lists elsewhere).
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
            "The figure's bins ({} equal parts of each perturbation's largest value, smallest first: at most {}, about {} trials each on average where the study has them) hold these numbers of trials, bin by bin: {}.",
            bins[0].trials.len(),
            MAX_BINS,
            TRIALS_PER_BIN,
            each.join("; ")
        )
    })
}

/// The SVG of the study's [`bins`], a panel a perturbation, or `None` when
/// no perturbation varies or there are no trials.
pub fn success_by_size(bins: &[Bins], max_tilt_deg: f64) -> Result<Option<String>> {
    if bins.iter().all(|b| b.trials.iter().sum::<usize>() == 0) {
        return Ok(None);
    }
    let panels: Vec<RatePanel> = bins.iter().map(panel).collect();
    Ok(Some(crate::report::rate_panels(
        &format!("Landing within {max_tilt_deg} deg against each perturbation's size"),
        "success rate",
        &panels,
        "95 % interval (Wilson)",
    )?))
}

/// One perturbation's panel: each controller's rate in each bin with its
/// Wilson interval (a `NaN` rate in an empty bin).
fn panel(b: &Bins) -> RatePanel {
    let series = CONTROLLERS
        .iter()
        .zip(&b.landed)
        .map(|(name, landed)| {
            let rates = b
                .centres()
                .into_iter()
                .zip(landed.iter().zip(&b.trials))
                .map(|(x, (&k, &n))| {
                    let [lo, hi] = wilson(k, n);
                    let rate = if n == 0 {
                        f64::NAN
                    } else {
                        k as f64 / n as f64
                    };
                    Rate { x, rate, lo, hi }
                })
                .collect();
            (name.to_string(), rates)
        })
        .collect();
    RatePanel {
        title: b.perturbation.to_string(),
        xdesc: b.axis.to_string(),
        xmax: b.largest,
        series,
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
            assert_eq!(b.landed[2], [0; 5], "replanning lands none");
        }
        let tilt = &b[1];
        // tilts are uniform up to the largest: the open loop lands the
        // first two bins whole, half the middle one, none above
        assert_eq!(tilt.landed[0][..2], tilt.trials[..2]);
        assert!(0 < tilt.landed[0][2] && tilt.landed[0][2] < tilt.trials[2]);
        assert_eq!(tilt.landed[0][3..], [0, 0]);
        let tilt_by_hand = (0..5)
            .map(|k| {
                results
                    .iter()
                    .filter(|r| {
                        let f = r.draw.tilt_deg / cfg.robustness.tilt_deg;
                        ((f * 5.0) as usize).min(4) == k
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

    /// A small study gets fewer bins, about twenty trials each (at least
    /// two, at most five), and each drawn rate carries the Wilson interval
    /// of its own bin's counts, which holds the rate.
    #[test]
    fn a_small_study_gets_fewer_bins_and_each_rate_its_interval() {
        assert_eq!(
            [1, 20, 50, 60, 99, 100, 1000].map(bin_count),
            [2, 2, 2, 3, 4, 5, 5]
        );
        let cfg = Config::from_toml(include_str!("../../configs/seed.toml"), "seed", &[]).unwrap();
        let results: Vec<TrialResult> = (0..30)
            .map(|t| TrialResult {
                draw: crate::control::robustness::Draw::new(&cfg, 3, t),
                // the open loop lands every third trial
                landing_error_deg: [if t % 3 == 0 { 1.0 } else { 40.0 }, 0.0, 180.0],
                replans: Vec::new(),
            })
            .collect();
        let b = bins(&cfg, &results, 10.0);
        assert_eq!(b.len(), 3);
        for b in &b {
            assert_eq!(b.trials.len(), 2, "{b:?}");
            let largest = match b.perturbation {
                "spin" => 0.5,
                "tilt" => 20.0,
                _ => 10.0,
            };
            assert!((b.largest - largest).abs() < 1e-12, "{b:?}");
            assert_eq!(b.centres(), [0.25 * b.largest, 0.75 * b.largest]);
            let p = panel(b);
            assert_eq!(p.title, b.perturbation);
            assert_eq!(p.xmax, b.largest);
            for ((name, rates), landed) in p.series.iter().zip(&b.landed) {
                for ((r, &k), &n) in rates.iter().zip(landed).zip(&b.trials) {
                    assert_eq!([r.lo, r.hi], wilson(k, n), "{name}");
                    if n == 0 {
                        assert!(r.rate.is_nan());
                    } else {
                        assert_eq!(r.rate, k as f64 / n as f64);
                        assert!(r.lo <= r.rate && r.rate <= r.hi, "{name}: {r:?}");
                        // a bin of a dozen trials says little: its interval
                        // is wider than a tenth unless the rate is certain
                        assert!(n > 100 || k == 0 || k == n || r.hi - r.lo > 0.1);
                    }
                }
            }
        }
        let svg = success_by_size(&b, 10.0).unwrap().unwrap();
        for what in [
            "spin at release, rad/s",
            "tilt at release, deg",
            "inertia error (larger half), %",
            "95 % interval (Wilson)",
            "open-loop",
        ] {
            assert!(svg.contains(what), "{what}");
        }
        assert!(bins_note(&b).unwrap().contains("(2 equal parts"));
    }
}
