//! The one-dimensional search over the bend that every phased design uses:
//! a coarse scan, then golden-section refinement inside the best bracket.
//! Derivative-free, so it stays correct where the objective has kinks (a
//! phase taking over the peak); it assumes unimodality inside that bracket.

use crate::error::Result;

/// A design at one bend, ranked by its score (lower is better; `f64::INFINITY`
/// for a bend at which the design is impossible).
pub trait Scored {
    fn score(&self) -> f64;
}

/// Evaluates every bend of `scan` (sorted here), then refines the best
/// bracket to `tol` rad; returns the best design seen.
pub fn scan_then_golden<D: Scored>(
    mut scan: Vec<f64>,
    tol: f64,
    mut eval: impl FnMut(f64) -> Result<D>,
) -> Result<D> {
    scan.sort_by(f64::total_cmp);
    let mut designs = Vec::with_capacity(scan.len());
    for &x in &scan {
        designs.push(eval(x)?);
    }
    let best = (0..scan.len())
        .min_by(|&i, &j| designs[i].score().total_cmp(&designs[j].score()))
        .expect("a non-empty scan");
    let (mut a, mut b) = (
        scan[best.saturating_sub(1)],
        scan[(best + 1).min(scan.len() - 1)],
    );
    let mut best_d = designs.swap_remove(best);
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

#[cfg(test)]
mod tests {
    use super::*;

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
        let best = scan_then_golden(scan, 1e-6, f).unwrap();
        assert!((best.0 - 0.83).abs() < 2e-6, "{}", best.0);
    }
}
