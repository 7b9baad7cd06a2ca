//! Which way round to turn from another start.
//!
//! The seeds (the analytic and phased schedules) turn the body half a turn
//! about its spine one way. From a start rolled or spinning about the spine
//! the landing (belly-down, any heading) is nearer one way round than the
//! other, and the free-form design keeps the way its seed turns: from a
//! start rolled 20 deg it would turn 200 deg where 160 deg do. The mirror
//! image of a seed in the plane of the spine and the belly (A's `x-z`
//! plane) turns the other way: the reflection `P = diag(1, -1, 1)` maps a
//! rotation about `a` by `q` to one about `-P a` by `q`, so a shape
//! coordinate about an axis in that plane changes sign and one about `y`
//! keeps it (MODEL.md section 2: the no-twist joint's `q1`, the universal
//! joint's motor about `x`). The free-form design starts from whichever of
//! the two leaves the smaller turn about the spine.

use crate::design::plan::{ShapePlan, ShapeState};
use crate::design::spec::DesignSpec;
use crate::model::momentum::rigid_turn;
use nalgebra::{Matrix3, UnitQuaternion};

/// The suffix of a seed's name where the design started from its mirror
/// image (`phased (mirrored)`).
pub const MIRRORED: &str = " (mirrored)";

/// The suffix of a seed's name where the design started from the seed
/// turned only as far as the start needs ([`scaled_to_the_turn`]), before
/// any [`MIRRORED`].
pub const SCALED: &str = " (scaled to the turn)";

/// Where the turn a start leaves is under this fraction of the seed's own
/// half turn, the seed is scaled to it ([`scaled_to_the_turn`]): from a
/// start rolled 176 deg, the seed's half turn is 176 deg from the 4 deg
/// needed, and the design from it ended turning 356 deg at twenty times
/// the peak of the 4 deg turn.
const SCALE_BELOW: f64 = 0.5;

/// A plan reflected through the plane of the spine and the belly: each
/// shape coordinate multiplied by its sign ([`signs`]). For a body
/// symmetric about that plane (the cylinders) it makes the same turn the
/// other way; for another it is a start the design corrects.
pub struct Mirrored<'a> {
    pub plan: Box<dyn ShapePlan + 'a>,
    pub signs: [f64; 2],
}

impl ShapePlan for Mirrored<'_> {
    fn phase_bounds(&self) -> Vec<f64> {
        self.plan.phase_bounds()
    }

    fn state_in(&self, i: usize, t: f64) -> ShapeState {
        let s = self.plan.state_in(i, t);
        let k = self.signs;
        let by = |v: [f64; 2]| [k[0] * v[0], k[1] * v[1]];
        ShapeState {
            q: by(s.q),
            qd: by(s.qd),
            qdd: by(s.qdd),
            phase: s.phase,
        }
    }

    fn breaks(&self) -> Vec<f64> {
        self.plan.breaks()
    }

    fn turn_scaled(&self, k: f64) -> Option<Box<dyn ShapePlan>> {
        let plan = self.plan.turn_scaled(k)?;
        Some(Box::new(Mirrored {
            plan,
            signs: self.signs,
        }))
    }
}

/// The signs that reflect `spec`'s shape coordinates through A's `x-z`
/// plane: `[-1, 1]` for the no-twist joint; for the universal joint `-1`
/// for a motor axis in that plane and `1` for one along `y`. `None` when a
/// motor axis is oblique (no reflection of the shape exists) or the
/// reflection leaves every coordinate as it is.
pub fn signs(spec: &DesignSpec) -> Option<[f64; 2]> {
    let signs = match spec.cat.joint {
        crate::model::Joint::NoTwist => [-1.0, 1.0],
        crate::model::Joint::Universal => {
            let h = spec.cat.halves();
            let sign = |a: [f64; 3]| {
                if a[1].abs() < 1e-12 {
                    Some(-1.0)
                } else if a[0].abs() < 1e-12 && a[2].abs() < 1e-12 {
                    Some(1.0)
                } else {
                    None
                }
            };
            [sign(h.rear.axis)?, sign(h.front.axis)?]
        }
    };
    (signs != [1.0, 1.0]).then_some(signs)
}

/// `plan`'s mirror image for `spec`, if the shape has one ([`signs`]).
pub fn mirrored<'a>(spec: &DesignSpec, plan: &'a dyn ShapePlan) -> Option<Mirrored<'a>> {
    signs(spec).map(|signs| Mirrored {
        plan: Box::new(plan),
        signs,
    })
}

/// Whether the free-form design from `spec`'s start should start from
/// `mirror`, `plan`'s mirror image: the way round that leaves the smaller
/// turn about the spine (each way flown kinematically from the start to
/// touchdown: its own half turn from rest, signed, plus the roll that would
/// then point the belly down). At the default start both ways are the same
/// half turn: no.
pub fn mirror_is_nearer(spec: &DesignSpec, plan: &dyn ShapePlan, mirror: &Mirrored) -> bool {
    if spec.is_default_start() {
        return false;
    }
    let (Some(own), Some(other)) = (left_to_turn(spec, plan), left_to_turn(spec, mirror)) else {
        return false;
    };
    // (a margin against rounding: a tie keeps the seed)
    other.abs() < own.abs() - 1e-6
}

/// Whether a design that lands from `spec`'s start went the long way round:
/// its turn about the spine more than half a turn ([`left_to_turn`]), where
/// the other way round may do with less.
pub fn goes_the_long_way(spec: &DesignSpec, plan: &dyn ShapePlan) -> bool {
    left_to_turn(spec, plan).is_some_and(|t| t.abs() > std::f64::consts::PI + 1e-3)
}

/// The turn about the spine, rad, that `plan` leaves to the design from
/// `spec`'s start: `plan`'s own turn from rest (signed) plus the roll that
/// points the belly down at touchdown after flying it (for a design that
/// lands, its own turn). `None` when a flight fails.
pub fn left_to_turn(spec: &DesignSpec, plan: &dyn ShapePlan) -> Option<f64> {
    turns(spec, plan).map(|(_, left)| left)
}

/// `plan`'s own turn from rest and the turn it leaves from `spec`'s start
/// ([`left_to_turn`]), rad.
fn turns(spec: &DesignSpec, plan: &dyn ShapePlan) -> Option<(f64, f64)> {
    let own = own_turn(spec, plan)?;
    let flown = crate::verify::simulate::kinematic_spec(spec, plan).ok()?;
    let [w, x, y, z] = flown.final_attitude;
    let end: Matrix3<f64> = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
        .to_rotation_matrix()
        .into_inner();
    let touchdown = rigid_turn(&spec.cat, &end, flown.final_body_momentum, spec.fall.margin);
    Some((own, own + roll_to_belly_down(&touchdown)))
}

/// `plan`'s own turn about the spine from rest, rad (signed, flown
/// kinematically).
fn own_turn(spec: &DesignSpec, plan: &dyn ShapePlan) -> Option<f64> {
    let at_rest = DesignSpec {
        start: None,
        ..spec.clone()
    };
    let own = crate::verify::simulate::kinematic_spec(&at_rest, plan).ok()?;
    Some(own.flip_deg.to_radians())
}

/// `plan` turned only as far as `spec`'s start needs this way round
/// ([`left_to_turn`]) where that is under [`SCALE_BELOW`] of its own turn
/// and its form allows ([`ShapePlan::turn_scaled`]): its twist scaled,
/// exactly for a no-twist cat at constant bend (F1), once more by the
/// turn's ratio where the flight says otherwise (the universal joint, F4).
/// `None` where the seed serves as it is.
pub fn scaled_to_the_turn(spec: &DesignSpec, plan: &dyn ShapePlan) -> Option<Box<dyn ShapePlan>> {
    let (own, left) = turns(spec, plan)?;
    if left * own <= 0.0 || left.abs() >= SCALE_BELOW * own.abs() {
        return None;
    }
    let k = left / own;
    let scaled = plan.turn_scaled(k)?;
    match own_turn(spec, scaled.as_ref()) {
        Some(t) if t * left > 0.0 && (t / left - 1.0).abs() > 1e-3 => {
            plan.turn_scaled(k * left / t)
        }
        _ => Some(scaled),
    }
}

/// The roll about the body's spine (A's `z`), in `(-pi, pi]`, after which
/// the belly (A's `+x`) of attitude `r` points as nearly straight down
/// (world `-x`) as a roll can make it: `r Rz(d) e_x` has the least world `x`
/// component at `d = atan2(-r_01, -r_00)`.
pub fn roll_to_belly_down(r: &Matrix3<f64>) -> f64 {
    (-r[(0, 1)]).atan2(-r[(0, 0)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::so3;
    use nalgebra::Vector3;

    /// The reflection's signs follow the joint's axes: the no-twist joint
    /// and the universal joint's motor about `x` change sign, a motor about
    /// `y` keeps it, an oblique one has no mirror image.
    #[test]
    fn the_mirror_negates_the_coordinates_about_axes_in_the_spines_plane() {
        let seed = |sets: &[String]| crate::test_support::spec_at("configs/seed.toml", sets);
        assert_eq!(signs(&seed(&[])), Some([-1.0, 1.0]));
        let universal = seed(&["cat.joint=\"universal\"".to_string()]);
        assert_eq!(signs(&universal), Some([-1.0, 1.0]));
        let body = |rear: &str, front: &str| {
            let text = format!(
                "name = \"b\"\n[cat]\njoint = \"universal\"\n[body.rear]\nmass = 0.6\ncom = [0, 0, 0]\ninertia = [0.002, 0.002, 0.001, 0, 0, 0]\njoint = [0, 0, 0.09]\naxis = {rear}\n[body.front]\nmass = 0.4\ncom = [0, 0, 0.07]\ninertia = [0.001, 0.001, 0.0005, 0, 0, 0]\njoint = [0, 0, 0]\naxis = {front}\n[fall]\nheight = 2.0\n"
            );
            crate::test_support::spec_of(&text, "test body", &[])
        };
        assert_eq!(signs(&body("[0, 1, 0]", "[1, 0, 0]")), Some([1.0, -1.0]));
        assert_eq!(signs(&body("[0.6, 0.8, 0]", "[0, 1, 0]")), None);
        assert_eq!(signs(&body("[0, 1, 0]", "[0, 0, 1]")), Some([1.0, -1.0]));
    }

    /// F1: at constant bend the no-twist cat turns in proportion to the
    /// twist, so the seed's twist scaled by `k` turns `k` half turns; the
    /// seed scaled for a start rolled -170 deg turns the 10 deg left.
    #[test]
    fn a_scaled_twist_turns_in_proportion() {
        let seed = |sets: &[String]| crate::test_support::spec_at("configs/seed.toml", sets);
        let spec = seed(&[]);
        let plan = crate::design::analytic::analytic_plan(&spec);
        for k in [0.05, 0.3, 1.0] {
            let turn = own_turn(&spec, &plan.twist_scaled(k)).unwrap();
            assert!(
                (turn.abs() - k * std::f64::consts::PI).abs() < 1e-7,
                "{k}: {turn}"
            );
        }
        // (rolled -170 deg the seed's own way is the nearer: 10 deg)
        let rolled = seed(&["start.rotation_deg=[0, 0, -170]".to_string()]);
        assert!(scaled_to_the_turn(&spec, &plan).is_none());
        let scaled = scaled_to_the_turn(&rolled, &plan).expect("a smaller turn");
        let own = own_turn(&rolled, scaled.as_ref()).unwrap().to_degrees();
        let left = left_to_turn(&rolled, scaled.as_ref()).unwrap().to_degrees();
        // its own turn is the whole turn: nothing left to roll after it
        assert!((own.abs() - 10.0).abs() < 1e-5, "{own}");
        assert!((left - own).abs() < 1e-5, "{left} {own}");
    }

    /// The roll found points the belly down for a body only rolled, and
    /// is the smaller way round.
    #[test]
    fn the_roll_to_belly_down_undoes_a_roll_the_shorter_way() {
        for deg in [-170.0f64, -90.0, -20.0, 1.0, 20.0, 90.0, 179.0] {
            let r = so3::exp(&(Vector3::z() * deg.to_radians()));
            let d = roll_to_belly_down(&r);
            let turned = r * so3::exp(&(Vector3::z() * d));
            // belly straight down: landing error zero
            assert!(
                crate::model::momentum::landing_error(&turned) < 1e-12,
                "{deg}"
            );
            // from a roll a, the belly is down at a + d = 180 deg (mod 360)
            let want = 180.0 - deg;
            let want = if want > 180.0 { want - 360.0 } else { want };
            assert!(
                (d.to_degrees() - want).abs() < 1e-9,
                "{deg}: {}",
                d.to_degrees()
            );
        }
    }
}
