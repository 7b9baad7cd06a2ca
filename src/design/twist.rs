//! The twist of the bend direction that flips the cat by exactly pi at a
//! given bend (docs/model.md F1, F4): closed form for the symmetric
//! `no-twist` cat, root-found on the integrated attitude otherwise.

use crate::design::analytic::{plan as cosine_plan, yy_inertia_and_c};
use crate::error::{Error, Result};
use crate::model::{Cat, Joint};
use crate::verify::ode::OdeSettings;
use crate::verify::simulate::kinematic;
use std::f64::consts::PI;

/// Twist of the bend direction that flips the cat by exactly pi.
///
/// `no-twist` with identical halves: `pi / C` (F1, exact). `universal` (F4)
/// or unequal halves: F1 is only approximate, so the twist is root-found on
/// the integrated attitude, starting from `pi / C` with the mean half; by F2
/// the timing is irrelevant and a unit-time cosine plan is used.
pub fn twist_for(cat: &Cat, bend: f64) -> Result<f64> {
    twist_to(cat, bend, TWIST_TOL)
}

/// The flip error (rad) [`twist_for`] root-finds the twist to, and the
/// relative tolerance of the attitude's integration.
pub const TWIST_TOL: f64 = 1e-11;

/// [`twist_for`] to the flip error `tol` (rad).
pub fn twist_to(cat: &Cat, bend: f64, tol: f64) -> Result<f64> {
    let (_, c) = yy_inertia_and_c(cat.i_t(), cat.i_a(), PI - bend);
    let guess = PI / c;
    if cat.joint == Joint::NoTwist && cat.is_symmetric() {
        return Ok(guess);
    }
    let ode = OdeSettings {
        rtol: tol,
        atol: 1e-2 * tol,
        ..Default::default()
    };
    let flip = |tw: f64| -> Result<f64> {
        let r = kinematic(cat, &cosine_plan(bend, tw, [1.0, 1.0, 1.0]), &ode)?;
        Ok(r.trace.last().map(|p| p.flip).unwrap_or(0.0))
    };
    let f0 = flip(guess)?;
    let target = PI * f0.signum();
    let (mut x0, mut y0) = (guess, f0 - target);
    let mut x1 = guess * target / f0;
    for _ in 0..30 {
        let y1 = flip(x1)? - target;
        if y1.abs() < tol {
            return Ok(x1);
        }
        let x2 = x1 - y1 * (x1 - x0) / (y1 - y0);
        (x0, y0, x1) = (x1, y1, x2);
    }
    Err(Error::Unreachable {
        reason: format!(
            "no twist angle flips the {} cat by pi at bend {:.2} deg; narrow phased.bend_min_deg / bend_max_deg",
            if cat.is_symmetric() {
                "universal-joint"
            } else {
                "unequal-halves"
            },
            bend.to_degrees()
        ),
    })
}
