//! What a design minimises (`design.objective`).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Objective {
    /// Peak joint torque within the fall (the default).
    #[default]
    PeakTorque,
    /// Duration of the manoeuvre inside the motor envelope, hence the least
    /// drop height `g (T + margin)^2 / 2`.
    Time,
    /// `integral |tau|^2 dt`, the motors' copper-loss proxy, inside the
    /// envelope within the fall time.
    Energy,
}

impl Objective {
    pub fn name(self) -> &'static str {
        match self {
            Objective::PeakTorque => "peak-torque",
            Objective::Time => "time",
            Objective::Energy => "energy",
        }
    }

    /// One word for a column or a legend: `peak`, `time` or `energy`.
    pub fn short_name(self) -> &'static str {
        match self {
            Objective::PeakTorque => "peak",
            Objective::Time => "time",
            Objective::Energy => "energy",
        }
    }

    /// Unit of the objective's value.
    pub fn unit(self) -> &'static str {
        match self {
            Objective::PeakTorque => "N m",
            Objective::Time => "s",
            Objective::Energy => "N^2 m^2 s",
        }
    }
}
