//! General rigid halves: each half a rigid body with any mass, centre of mass
//! and inertia tensor, and the joint anywhere on it.
//!
//! Each half has its own frame; the two frames are parallel in the straight
//! cat (`q = 0`), so a vector has the same coordinates in both there, and
//! `R_rel(q)` turns B's frame into A's. The origins are free (a URDF link's
//! origin, a cylinder's centre). The spine is A's `z` axis, the flip is
//! measured about it and the no-twist joint bends about axes normal to it.
//! The cylinder keys of `[cat]` fill these in exactly ([`Halves::of_cylinders`]).

use super::Half;
use super::body::InertiaFormula;
use serde::Serialize;

/// One half as a rigid body, in its own frame (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rigid {
    /// kg.
    pub mass: f64,
    /// Centre of mass, m.
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, kg m^2 (symmetric).
    pub inertia: [[f64; 3]; 3],
    /// Where the joint is, m.
    pub joint: [f64; 3],
    /// The universal joint's motor axis this half carries (unit): motor 1 on
    /// the rear, motor 2 on the front, `R_rel = Rot(a1, q1) Rot(a2, q2)`.
    /// Unused by the no-twist joint.
    pub axis: [f64; 3],
}

/// The rear half A and the front half B.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Halves {
    pub rear: Rigid,
    pub front: Rigid,
}

impl Rigid {
    /// A solid cylinder on its own `z` axis, centre of mass at the origin,
    /// the joint at `(0, 0, joint_z)`.
    pub fn cylinder(h: &Half, joint_z: f64, axis: [f64; 3]) -> Rigid {
        let (it, ia) = (h.i_t(), h.i_a());
        Rigid {
            mass: h.mass,
            com: [0.0; 3],
            inertia: [[it, 0.0, 0.0], [0.0, it, 0.0], [0.0, 0.0, ia]],
            joint: [0.0, 0.0, joint_z],
            axis,
        }
    }

    /// Vector from the centre of mass to the joint, m.
    pub fn com_to_joint(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.joint[i] - self.com[i])
    }

    /// Axisymmetric about a line parallel to the spine through the joint:
    /// transverse moments equal, no products of inertia, the centre of mass
    /// on the spine. Exact comparisons: they detect the cylinders (and
    /// bodies of revolution) for which the phased design's symmetries hold.
    pub fn is_axisymmetric(&self) -> bool {
        let i = &self.inertia;
        let cj = self.com_to_joint();
        i[0][0] == i[1][1]
            && [i[0][1], i[0][2], i[1][2], i[1][0], i[2][0], i[2][1]] == [0.0; 6]
            && cj[0] == 0.0
            && cj[1] == 0.0
    }

    /// Principal moments (ascending) and axes (columns) of the inertia tensor.
    pub fn principal(&self) -> ([f64; 3], nalgebra::Matrix3<f64>) {
        let m = nalgebra::Matrix3::from_fn(|r, c| self.inertia[r][c]);
        let e = nalgebra::SymmetricEigen::new(m);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
        let vals = idx.map(|k| e.eigenvalues[k]);
        let vecs = nalgebra::Matrix3::from_fn(|r, c| e.eigenvectors[(r, idx[c])]);
        (vals, vecs)
    }

    /// Edges of the uniform box with this mass and inertia, m, along the
    /// principal axes of [`Rigid::principal`]: `I_1 = m (b^2 + c^2) / 12` and
    /// so on (an edge is zero where the moments only just meet the triangle
    /// inequality).
    pub fn box_edges(&self) -> [f64; 3] {
        let (p, _) = self.principal();
        let s = p.iter().sum::<f64>();
        p.map(|pi| (6.0 * (s - 2.0 * pi) / self.mass).max(0.0).sqrt())
    }

    /// A cylinder with the same mass and axial inertia whose length is twice
    /// the distance from the centre of mass to the joint: the scales and the
    /// seed's closed forms of a general half (its [`Half`]).
    pub fn equivalent_cylinder(&self) -> Half {
        let cj = self.com_to_joint();
        let length = 2.0 * (cj[0] * cj[0] + cj[1] * cj[1] + cj[2] * cj[2]).sqrt();
        let radius = (2.0 * self.inertia[2][2] / self.mass).sqrt();
        Half {
            mass: self.mass,
            length,
            radius: radius.min(0.99 * length),
            inertia: InertiaFormula::SolidCylinder,
        }
    }

    /// Why this half cannot be modelled, if it cannot.
    pub fn problem(&self) -> Option<String> {
        self.problem_in().map(|(_, why)| why)
    }

    /// [`Rigid::problem`] with the field it lies in (`mass`, `com`,
    /// `inertia`, `joint` or `axis`): a config's key names it.
    pub fn problem_in(&self) -> Option<(&'static str, String)> {
        for (field, finite) in [
            ("mass", self.mass.is_finite()),
            ("com", self.com.iter().all(|x| x.is_finite())),
            ("joint", self.joint.iter().all(|x| x.is_finite())),
            ("axis", self.axis.iter().all(|x| x.is_finite())),
            (
                "inertia",
                self.inertia.iter().flatten().all(|x| x.is_finite()),
            ),
        ] {
            if !finite {
                return Some((field, "a number is not finite".into()));
            }
        }
        if self.mass <= 0.0 {
            return Some((
                "mass",
                format!(
                    "its mass {} kg must be > 0 (a massless moving link has no dynamics)",
                    self.mass
                ),
            ));
        }
        let i = &self.inertia;
        let scale = i[0][0].abs() + i[1][1].abs() + i[2][2].abs();
        for (r, c) in [(0, 1), (0, 2), (1, 2)] {
            if (i[r][c] - i[c][r]).abs() > 1e-12 * scale {
                return Some(("inertia", "its inertia tensor is not symmetric".into()));
            }
        }
        let (p, _) = self.principal();
        if p[0] <= 0.0 {
            return Some((
                "inertia",
                format!(
                    "its inertia tensor is not positive definite (principal moments {:.3e}, {:.3e}, {:.3e} kg m^2)",
                    p[0], p[1], p[2]
                ),
            ));
        }
        if p[0] + p[1] < p[2] * (1.0 - 1e-9) {
            return Some((
                "inertia",
                format!(
                    "its principal moments {:.3e}, {:.3e}, {:.3e} kg m^2 break the triangle inequality (no rigid body has them)",
                    p[0], p[1], p[2]
                ),
            ));
        }
        let n = self.axis.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-9 {
            return Some(("axis", format!("its joint axis has length {n}, not 1")));
        }
        None
    }
}

impl Halves {
    /// The cylinders of `[cat]` as general halves, exactly: A's frame at its
    /// centre with the joint at `(0, 0, l_A/2)`, B's at its centre with the
    /// joint at `(0, 0, -l_B/2)`; motor 1 about `x`, motor 2 about `y`.
    pub fn of_cylinders(rear: &Half, front: &Half) -> Halves {
        Halves {
            rear: Rigid::cylinder(rear, rear.half_length(), [1.0, 0.0, 0.0]),
            front: Rigid::cylinder(front, -front.half_length(), [0.0, 1.0, 0.0]),
        }
    }

    /// The same body with the halves' roles exchanged (B the reference, and
    /// the universal joint's motors in the other order).
    pub fn swapped(&self) -> Halves {
        Halves {
            rear: self.front,
            front: self.rear,
        }
    }

    /// Both halves axisymmetric about the spine ([`Rigid::is_axisymmetric`]).
    pub fn is_axisymmetric(&self) -> bool {
        self.rear.is_axisymmetric() && self.front.is_axisymmetric()
    }

    /// The halves are mirror images across the joint (same mass and inertia,
    /// the joint as far from each centre of mass): the seed's identical halves.
    pub fn is_mirror_pair(&self) -> bool {
        let (a, b) = (self.rear.com_to_joint(), self.front.com_to_joint());
        self.is_axisymmetric()
            && self.rear.mass == self.front.mass
            && self.rear.inertia == self.front.inertia
            && a[2] == -b[2]
    }

    /// Whether the universal joint's axes meet at one point and are not
    /// parallel: with the frames parallel at `q = 0`, both pass through the
    /// joint by construction, so only parallel axes are refused.
    pub fn axes_problem(&self) -> Option<String> {
        let (a, b) = (self.rear.axis, self.front.axis);
        let cr = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let s = cr.iter().map(|x| x * x).sum::<f64>().sqrt();
        (s < 1e-6).then(|| {
            "the universal joint's two axes are parallel: it would bend in one plane only".into()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_edges_reproduce_the_inertia_of_a_box() {
        let (m, e) = (2.0, [0.3, 0.1, 0.5]);
        let moment = |i: usize| {
            let (b, c) = (e[(i + 1) % 3], e[(i + 2) % 3]);
            m * (b * b + c * c) / 12.0
        };
        let r = Rigid {
            mass: m,
            com: [0.0; 3],
            inertia: [
                [moment(0), 0.0, 0.0],
                [0.0, moment(1), 0.0],
                [0.0, 0.0, moment(2)],
            ],
            joint: [0.0, 0.0, 0.25],
            axis: [1.0, 0.0, 0.0],
        };
        let mut got = r.box_edges();
        got.sort_by(f64::total_cmp);
        let mut want = e;
        want.sort_by(f64::total_cmp);
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-12, "{got:?} {want:?}");
        }
        assert!(r.problem().is_none());
    }

    #[test]
    fn impossible_halves_are_named() {
        let h = Half {
            mass: 1.0,
            length: 1.0,
            radius: 0.1,
            inertia: InertiaFormula::SolidCylinder,
        };
        let mut r = Rigid::cylinder(&h, 0.5, [1.0, 0.0, 0.0]);
        r.inertia[2][2] = 10.0;
        assert!(r.problem().unwrap().contains("triangle"));
        r = Rigid::cylinder(&h, 0.5, [1.0, 0.0, 0.0]);
        r.mass = 0.0;
        assert!(r.problem().unwrap().contains("massless"));
        let mut pair = Halves::of_cylinders(&h, &h);
        assert!(pair.is_mirror_pair() && pair.axes_problem().is_none());
        pair.front.axis = [1.0, 0.0, 0.0];
        assert!(pair.axes_problem().unwrap().contains("parallel"));
    }
}
