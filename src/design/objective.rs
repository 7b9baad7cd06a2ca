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
    /// Refuses a least-time design with neither a torque nor a speed limit:
    /// without one the time goes to zero. `limited`: some limit is set.
    pub fn check_bounded(self, limited: bool) -> crate::error::Result<()> {
        if self == Objective::Time && !limited {
            return Err(crate::error::Error::Invalid {
                key: "design.objective".into(),
                value: "\"time\"".into(),
                expected:
                    "needs a limit to be finite: set limits.max_torque and/or limits.max_speed"
                        .into(),
            });
        }
        Ok(())
    }

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

#[cfg(test)]
mod tests {
    use super::Objective;

    /// Only a least-time design needs a limit, and its refusal names the key and the fix.
    #[test]
    fn a_least_time_design_without_a_limit_is_refused_under_its_key() {
        let e = Objective::Time
            .check_bounded(false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("design.objective") && e.contains("limits.max_torque"),
            "{e}"
        );
        assert!(Objective::Time.check_bounded(true).is_ok());
        for o in [Objective::PeakTorque, Objective::Energy] {
            assert!(o.check_bounded(false).is_ok(), "{o:?}");
        }
    }
}
