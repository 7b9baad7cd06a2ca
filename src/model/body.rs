//! One half of the cat: a solid cylinder with its own mass, length and radius.
//!
//! Real robots do not have two identical halves, so the rear half A and the
//! front half B are separate [`Half`]s; the seed's cat is the case of equal ones.

use serde::{Deserialize, Serialize};

/// Which transverse-inertia formula to use (erratum E1 of the seed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum InertiaFormula {
    /// Solid cylinder, `m (3 r^2 + l^2) / 12`.
    #[default]
    SolidCylinder,
    /// The seed's `m (r^2 + l^2) / 12` (erratum E1), only to reproduce its example.
    Seed,
}

/// A solid cylinder, its axis along its own `z`, centre of mass in the middle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Half {
    /// kg.
    pub mass: f64,
    /// m, along the spine.
    pub length: f64,
    /// m.
    pub radius: f64,
    pub inertia: InertiaFormula,
}

impl Half {
    /// Transverse inertia about the centre of mass, `I_t`.
    pub fn i_t(&self) -> f64 {
        let (m, r, l) = (self.mass, self.radius, self.length);
        match self.inertia {
            InertiaFormula::SolidCylinder => m * (3.0 * r * r + l * l) / 12.0,
            InertiaFormula::Seed => m * (r * r + l * l) / 12.0,
        }
    }

    /// Axial inertia, `I_a = m r^2 / 2`.
    pub fn i_a(&self) -> f64 {
        self.mass * self.radius * self.radius / 2.0
    }

    /// Distance from the centre of mass to the joint face, `l / 2`.
    pub fn half_length(&self) -> f64 {
        self.length / 2.0
    }
}
