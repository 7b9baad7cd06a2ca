//! The one-dimensional search over the bend that every phased design uses:
//! a coarse scan, then Brent refinement inside the best bracket; or, in a
//! sweep, a local bracket around the neighbours' bend
//! ([`bracket_then_brent`]). Derivative-free, so it stays correct where the
//! objective has kinks (a phase taking over the peak); it assumes
//! unimodality inside the bracket.

use crate::design::analytic::turns_theta;
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};
use serde::Serialize;
use std::f64::consts::PI;

/// One evaluation of the bend search, as reported to an observer: at the
/// search's accuracy ([`ConicSettings::SEARCH`](crate::design::conic::ConicSettings::SEARCH),
/// within about 1e-6 of the certified value the chosen bend is solved to).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct BendEvaluation {
    pub bend_deg: f64,
    /// The objective at this bend, in its unit (`design.objective`; infinite
    /// where no timing fits the motor envelope).
    pub value: f64,
    /// The peak if the manoeuvre took 1 s, N m s^2 (the unit-time peak
    /// program only: absent inside a motor envelope).
    pub unit_peak: Option<f64>,
    /// The peak at this bend, N m (absent for another objective).
    pub peak_nm: Option<f64>,
}

/// The coarse bend scan over `[lo, hi]` rad: `phased.scan_points` even
/// points plus the one-turn bend (F6) and the config's bend where inside.
pub fn bend_scan(spec: &DesignSpec, lo: f64, hi: f64) -> Vec<f64> {
    let cat = spec.cat;
    let n = spec.phased.scan_points;
    let mut xs: Vec<f64> = (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect();
    let one_turn = PI - turns_theta(cat.i_t(), cat.i_a(), 1.0);
    let seed_bend = PI - spec.analytic.theta_deg.to_radians();
    for b in [one_turn, seed_bend] {
        if b > lo && b < hi {
            xs.push(b);
        }
    }
    xs
}

/// The bend range the config allows, rad.
pub fn bend_range(spec: &DesignSpec) -> Result<(f64, f64)> {
    let lo = spec.phased.bend_min_deg.to_radians();
    let hi = spec.phased.bend_max_deg.to_radians().min(spec.max_bend());
    if hi <= lo {
        return Err(Error::Invalid {
            key: "limits.max_bend_deg".into(),
            value: format!("{}", spec.max_bend().to_degrees()),
            expected: format!(
                "must exceed phased.bend_min_deg = {}",
                spec.phased.bend_min_deg
            ),
        });
    }
    Ok((lo, hi))
}

/// Where a neighbouring design (a sweep's previous point) puts the best
/// bend: the local search starts there, `step` either side.
#[derive(Debug, Clone, Copy)]
pub struct BendHint {
    pub bend: f64,
    pub step: f64,
}

impl BendHint {
    /// The hint from a chain's bends of consecutive points, in order
    /// (none before the first).
    pub fn from_chain(bends: &[f64]) -> Option<Self> {
        let (&last, rest) = bends.split_last()?;
        Some(Self::from_neighbours(last, rest.last().copied()))
    }

    /// The prediction from the last two points' bends (linear
    /// extrapolation), its bracket half the last change and at least a
    /// fifth of a degree (the bracket widens when the bend lies outside);
    /// from the last alone, a degree either side.
    fn from_neighbours(last: f64, before: Option<f64>) -> Self {
        match before {
            Some(b) => BendHint {
                bend: 2.0 * last - b,
                step: (0.5 * (last - b).abs()).max(0.2f64.to_radians()),
            },
            None => BendHint {
                bend: last,
                step: 1f64.to_radians(),
            },
        }
    }
}

/// A design at one bend, ranked by its score (lower is better; `f64::INFINITY`
/// for a bend at which the design is impossible).
pub trait Scored {
    fn score(&self) -> f64;
}

/// Evaluates every bend of `scan` (sorted here); returns the best bend's
/// bracket `(left neighbour, best, right neighbour)` and its design.
fn scan_best<D: Scored>(
    scan: &mut [f64],
    eval: &mut impl FnMut(f64) -> Result<D>,
) -> Result<(f64, f64, f64, D)> {
    scan.sort_by(f64::total_cmp);
    let mut designs = Vec::with_capacity(scan.len());
    for &x in scan.iter() {
        designs.push(eval(x)?);
    }
    let best = (0..scan.len())
        .min_by(|&i, &j| designs[i].score().total_cmp(&designs[j].score()))
        .expect("a non-empty scan");
    Ok((
        scan[best.saturating_sub(1)],
        scan[best],
        scan[(best + 1).min(scan.len() - 1)],
        designs.swap_remove(best),
    ))
}

/// Evaluates every bend of `scan` (sorted here), then refines the best
/// bracket with Brent's method (parabolic steps through the three best
/// bends, a golden step when the parabola is not trusted), so a smooth
/// objective needs about half the evaluations of golden section; kinks and
/// impossible bends fall back to golden steps.
/// Stops when the bracket around the best bend is `tol` wide.
pub fn scan_then_brent<D: Scored>(
    mut scan: Vec<f64>,
    tol: f64,
    eval: impl FnMut(f64) -> Result<D>,
) -> Result<D> {
    let mut failed = None;
    let mut eval = tolerant(eval, &mut failed);
    let (a, x, b, best_d) = scan_best(&mut scan, &mut eval)?;
    let best = brent(a, x, b, best_d, tol, eval)?;
    best.0
        .ok_or_else(|| failed.expect("a bend the solver could not finish"))
}

/// A bend's design, or none where the solver could not finish its conic
/// program: an impossible bend (infinite score), as one where no timing
/// fits. A bend of a hundredth of a degree needs thousands of twist turns,
/// and its program ends in numerical trouble: the search goes on without it
/// (it used to end there, however good the other bends).
struct Tried<D>(Option<D>);

impl<D: Scored> Scored for Tried<D> {
    fn score(&self) -> f64 {
        self.0.as_ref().map_or(f64::INFINITY, Scored::score)
    }
}

/// `eval` with a solver's failure at a bend taken as an impossible bend
/// ([`Tried`]), the first such error kept in `failed`; other errors end the
/// search.
fn tolerant<'a, D>(
    mut eval: impl FnMut(f64) -> Result<D> + 'a,
    failed: &'a mut Option<Error>,
) -> impl FnMut(f64) -> Result<Tried<D>> + 'a {
    move |x| match eval(x) {
        Ok(d) => Ok(Tried(Some(d))),
        Err(e @ Error::Solver { .. }) => {
            failed.get_or_insert(e);
            Ok(Tried(None))
        }
        Err(e) => Err(e),
    }
}

/// A local search for a sweep, where the neighbouring point's best bend
/// predicts this one's: evaluates `center` and `center +- step`, steps
/// outward (doubling) while the best bend is at the bracket's edge and
/// inside `[lo, hi]`, then refines the bracket with Brent's method. Returns
/// `None` when no bend of the bracket is possible (the caller scans the
/// whole range instead).
pub fn bracket_then_brent<D: Scored>(
    center: f64,
    step: f64,
    range: (f64, f64),
    tol: f64,
    eval: impl FnMut(f64) -> Result<D>,
) -> Result<Option<D>> {
    let mut failed = None;
    let found = bracket_then_brent_tried(center, step, range, tol, tolerant(eval, &mut failed))?;
    Ok(found.and_then(|t| t.0))
}

/// [`bracket_then_brent`] on any scored design.
fn bracket_then_brent_tried<D: Scored>(
    center: f64,
    step: f64,
    (lo, hi): (f64, f64),
    tol: f64,
    mut eval: impl FnMut(f64) -> Result<D>,
) -> Result<Option<D>> {
    let center = center.clamp(lo, hi);
    let step = step.max(tol);
    let (a, b) = ((center - step).max(lo), (center + step).min(hi));
    let mut pa = (a, eval(a)?);
    let mut pm = (center, eval(center)?);
    let mut pb = (b, eval(b)?);
    let mut width = step;
    for _ in 0..40 {
        let f = |p: &(f64, D)| p.1.score();
        if !(f(&pa).is_finite() || f(&pm).is_finite() || f(&pb).is_finite()) {
            return Ok(None);
        }
        width *= 2.0;
        if f(&pa) < f(&pm) && pa.0 > lo {
            // the minimum lies below a: shift the bracket down
            let x = (pa.0 - width).max(lo);
            let new = (x, eval(x)?);
            pb = std::mem::replace(&mut pm, std::mem::replace(&mut pa, new));
        } else if f(&pb) < f(&pm) && pb.0 < hi {
            let x = (pb.0 + width).min(hi);
            let new = (x, eval(x)?);
            pa = std::mem::replace(&mut pm, std::mem::replace(&mut pb, new));
        } else {
            break;
        }
    }
    let (fa, fm, fb) = (pa.1.score(), pm.1.score(), pb.1.score());
    if fa < fm || fb < fm {
        // falling towards an end of the range: the minimum lies between
        // that end and the middle bend (Brent from the end, as after a scan)
        return if fa <= fb {
            brent(pa.0, pa.0, pm.0, pa.1, tol, eval)
        } else {
            brent(pm.0, pb.0, pb.0, pb.1, tol, eval)
        }
        .map(Some);
    }
    brent(pa.0, pm.0, pb.0, pm.1, tol, eval).map(Some)
}

/// Brent's method on the bracket `a <= x <= b` whose best bend so far is `x`
/// (with design `best_d`), to `tol` wide.
fn brent<D: Scored>(
    mut a: f64,
    mut x: f64,
    mut b: f64,
    mut best_d: D,
    tol: f64,
    mut eval: impl FnMut(f64) -> Result<D>,
) -> Result<D> {
    let mut fx = best_d.score();
    if !fx.is_finite() || b - a <= tol {
        return Ok(best_d);
    }
    const CGOLD: f64 = 0.381_966_011_250_105_1;
    let tol1 = tol / 4.0;
    let (mut w, mut v, mut fw, mut fv) = (x, x, fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..100 {
        let xm = 0.5 * (a + b);
        if (x - xm).abs() <= 2.0 * tol1 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // parabola through (x, fx), (w, fw), (v, fv)
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let etemp = e;
            if p.is_finite()
                && q.is_finite()
                && p.abs() < (0.5 * q * etemp).abs()
                && p > q * (a - x)
                && p < q * (b - x)
            {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < 2.0 * tol1 || b - u < 2.0 * tol1 {
                    d = tol1.copysign(xm - x);
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let du = eval(u)?;
        let fu = du.score();
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw) = (w, fw, x, fx);
            (x, fx) = (u, fu);
            best_d = du;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    Ok(best_d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Golden-section refinement after the same scan: the reference Brent
    /// is measured against.
    fn scan_then_golden<D: Scored>(
        mut scan: Vec<f64>,
        tol: f64,
        mut eval: impl FnMut(f64) -> Result<D>,
    ) -> Result<D> {
        let (mut a, _, mut b, mut best_d) = scan_best(&mut scan, &mut eval)?;
        if !best_d.score().is_finite() {
            return Ok(best_d);
        }
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let mut x1 = b - g * (b - a);
        let mut x2 = a + g * (b - a);
        let mut d1 = eval(x1)?;
        let mut d2 = eval(x2)?;
        while b - a > tol {
            if d1.score() <= d2.score() {
                b = x2;
                (x2, d2) = (x1, d1);
                x1 = b - g * (b - a);
                d1 = eval(x1)?;
            } else {
                a = x1;
                (x1, d1) = (x2, d2);
                x2 = a + g * (b - a);
                d2 = eval(x2)?;
            }
        }
        for d in [d1, d2] {
            if d.score() < best_d.score() {
                best_d = d;
            }
        }
        Ok(best_d)
    }

    struct S(f64, f64);
    impl Scored for S {
        fn score(&self) -> f64 {
            self.1
        }
    }

    #[test]
    fn finds_the_minimum_of_a_kinked_function_and_skips_impossible_bends() {
        // |x - 0.83| + 0.1, impossible below 0.3
        let f = |x: f64| {
            Ok(S(
                x,
                if x < 0.3 {
                    f64::INFINITY
                } else {
                    (x - 0.83).abs() + 0.1
                },
            ))
        };
        let scan: Vec<f64> = (0..12).map(|i| 0.1 + 2.9 * i as f64 / 11.0).collect();
        let best = scan_then_golden(scan.clone(), 1e-6, f).unwrap();
        assert!((best.0 - 0.83).abs() < 2e-6, "{}", best.0);
        let best = scan_then_brent(scan, 1e-6, f).unwrap();
        assert!((best.0 - 0.83).abs() < 2e-6, "{}", best.0);
    }

    #[test]
    fn a_bend_the_solver_cannot_finish_is_skipped_and_all_failing_is_the_error() {
        let fail = || Error::Solver {
            what: "path-timing SOCP".into(),
            status: "NumericalError".into(),
            hint: String::new(),
        };
        // (x - 0.83)^2 + 0.1, the solver failing below 0.3 and at 1.1
        let f = |x: f64| {
            if x < 0.3 || (x - 1.1).abs() < 1e-12 {
                Err(fail())
            } else {
                Ok(S(x, (x - 0.83).powi(2) + 0.1))
            }
        };
        let scan: Vec<f64> = (0..12).map(|i| 0.1 + 2.9 * i as f64 / 11.0).collect();
        let best = scan_then_brent(scan.clone(), 1e-6, f).unwrap();
        assert!((best.0 - 0.83).abs() < 2e-6, "{}", best.0);
        let near = bracket_then_brent(0.25, 0.05, (0.1, 3.0), 1e-6, f)
            .unwrap()
            .unwrap();
        assert!((near.0 - 0.83).abs() < 2e-6, "{}", near.0);
        // every bend failing: the solver's error, not a design
        let all = scan_then_brent(scan, 1e-6, |_| Err::<S, _>(fail()));
        assert!(matches!(all, Err(Error::Solver { .. })));
        assert!(
            bracket_then_brent(1.0, 0.1, (0.1, 3.0), 1e-6, |_| Err::<S, _>(fail()))
                .unwrap()
                .is_none()
        );
        // an error that is not the solver's still ends the search
        let usage = scan_then_brent(vec![0.5, 1.0], 1e-6, |_| {
            Err::<S, _>(Error::Usage("interrupted".into()))
        });
        assert!(matches!(usage, Err(Error::Usage(_))));
    }

    #[test]
    fn a_bracket_follows_the_minimum_from_a_poor_hint_and_stops_at_the_range_end() {
        let minimum = 0.7318;
        let f = |x: f64| {
            Ok(S(
                x,
                (x - minimum).powi(2) + 0.3 * (x - minimum).powi(4) + 1.0,
            ))
        };
        // a hint 0.5 away with a 0.05 bracket: the bracket walks to it
        let best = bracket_then_brent(0.2, 0.05, (0.1, 3.0), 1e-5, f)
            .unwrap()
            .unwrap();
        assert!((best.0 - minimum).abs() < 1e-5, "{}", best.0);
        // a good hint needs fewer evaluations than the scan and Brent
        let near = {
            let mut k = 0;
            bracket_then_brent(0.74, 0.02, (0.1, 3.0), 1e-5, |x: f64| {
                k += 1;
                Ok(S(x, (x - minimum).powi(2) + 1.0))
            })
            .unwrap()
            .unwrap();
            k
        };
        let mut k = 0;
        let scan: Vec<f64> = (0..12).map(|i| 0.1 + 2.9 * i as f64 / 11.0).collect();
        scan_then_brent(scan, 1e-5, |x: f64| {
            k += 1;
            Ok(S(x, (x - minimum).powi(2) + 1.0))
        })
        .unwrap();
        assert!(near < k, "bracket {near} vs scan {k} evaluations");
        // a minimum near the range's end, reached by walking the bracket
        // there: refined, not the end itself
        let near_end = bracket_then_brent(0.3, 0.02, (0.1, 3.0), 1e-5, |x: f64| {
            Ok(S(x, (x - 0.12).powi(2)))
        })
        .unwrap()
        .unwrap();
        assert!((near_end.0 - 0.12).abs() < 1e-5, "{}", near_end.0);
        // decreasing to the range's end: the end
        let end = bracket_then_brent(2.5, 0.1, (0.1, 3.0), 1e-5, |x: f64| Ok(S(x, -x)))
            .unwrap()
            .unwrap();
        assert_eq!(end.0, 3.0);
        // nothing possible in the bracket: the caller scans
        let none = bracket_then_brent(1.0, 0.1, (0.1, 3.0), 1e-5, |x: f64| Ok(S(x, f64::INFINITY)))
            .unwrap();
        assert!(none.is_none());
    }

    #[test]
    fn brent_needs_fewer_evaluations_than_golden_on_a_smooth_minimum() {
        // a smooth, non-quadratic bowl: both find its minimum to tol, Brent
        // with fewer evaluations
        let minimum = 0.7318;
        let count = |brent: bool| {
            let mut n = 0;
            let f = |x: f64| {
                n += 1;
                Ok(S(
                    x,
                    (x - minimum).powi(2) + 0.3 * (x - minimum).powi(4) + 1.0,
                ))
            };
            let scan: Vec<f64> = (0..12).map(|i| 0.1 + 2.9 * i as f64 / 11.0).collect();
            let best = if brent {
                scan_then_brent(scan, 1e-4, f)
            } else {
                scan_then_golden(scan, 1e-4, f)
            }
            .unwrap();
            assert!((best.0 - minimum).abs() < 1e-4, "{brent}: {}", best.0);
            n
        };
        let (golden, brent) = (count(false), count(true));
        assert!(
            brent < golden,
            "Brent {brent} vs golden {golden} evaluations"
        );
    }
}
