//! `[start]` and `[land]`: how the cat is let go and what counts as landing
//! (MODEL.md section 6). The defaults are today's problem: upside down, at
//! rest, and the flip judged by `simulate.flip_tolerance`.

use super::check;
use crate::error::Result;
use crate::model::momentum::Start;
use serde::{Deserialize, Serialize};

/// Largest release rate, rad/s: beyond about eight turns a second no
/// two-body cat of any proportions has the time to cancel the spin.
pub const MAX_START_RATE: f64 = 50.0;

/// `[start]`: the straight, rigid cat's attitude and rate at release.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct StartConfig {
    /// Rotation vector of the release attitude from the upside-down pose, degrees,
    /// world axes (x up, z the reference spine); its length is the angle, at most 180
    /// (default [0, 0, 0]).
    pub rotation_deg: [f64; 3],
    /// Body rate at release, rad/s, about the rear half's own axes (z the spine);
    /// at most 50 rad/s in magnitude (default [0, 0, 0]).
    pub angular_velocity: [f64; 3],
}

/// `[land]`: when a touchdown counts as belly-down.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LandConfig {
    /// Largest angle of the belly from straight down at touchdown, degrees
    /// (default: none, today's check: flip error and spine tilt within
    /// `simulate.flip_tolerance`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_tilt_deg: Option<f64>,
}

impl StartConfig {
    pub fn validate(&self) -> Result<()> {
        for (i, x) in self.rotation_deg.iter().enumerate() {
            check(
                &format!("start.rotation_deg[{i}]"),
                *x,
                true,
                "must be a finite number of degrees",
            )?;
        }
        let angle = norm(self.rotation_deg);
        check(
            "start.rotation_deg",
            angle,
            angle <= 180.0,
            "must be a rotation vector of at most 180 degrees (its length, shown, is the angle)",
        )?;
        for (i, x) in self.angular_velocity.iter().enumerate() {
            check(
                &format!("start.angular_velocity[{i}]"),
                *x,
                true,
                "must be a finite rate in rad/s",
            )?;
        }
        let w = norm(self.angular_velocity);
        check(
            "start.angular_velocity",
            w,
            w <= MAX_START_RATE,
            &format!(
                "its magnitude (the number shown, rad/s, from {:?}) must be at most {MAX_START_RATE} rad/s",
                self.angular_velocity
            ),
        )?;
        Ok(())
    }

    /// The model's start.
    pub fn start(&self) -> Start {
        Start::new(
            self.rotation_deg.map(f64::to_radians),
            self.angular_velocity,
        )
    }

    /// Whether this is today's start: upside down and at rest.
    pub fn is_default(&self) -> bool {
        *self == StartConfig::default()
    }
}

impl LandConfig {
    pub fn validate(&self) -> Result<()> {
        if let Some(t) = self.max_tilt_deg {
            check(
                "land.max_tilt_deg",
                t,
                t > 0.0 && t <= 90.0,
                "must be in (0, 90] degrees",
            )?;
        }
        Ok(())
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use crate::Config;

    const SEED: &str =
        "name = \"s\"\n[cat]\nmass = 1.0\nlength = 1.0\nradius = 0.1\n[fall]\nheight = 10.0\n";

    #[test]
    fn out_of_range_starts_are_refused_with_the_key_and_range() {
        for (set, key, range) in [
            (
                "start.rotation_deg=[0, 190, 0]",
                "start.rotation_deg",
                "at most 180",
            ),
            (
                "start.rotation_deg=[nan, 0, 0]",
                "start.rotation_deg[0]",
                "finite",
            ),
            (
                "start.angular_velocity=[0, 0, 60]",
                "start.angular_velocity",
                "at most 50",
            ),
            (
                "start.angular_velocity=[0, inf, 0]",
                "start.angular_velocity[1]",
                "finite",
            ),
            ("land.max_tilt_deg=0", "land.max_tilt_deg", "(0, 90]"),
            ("land.max_tilt_deg=91", "land.max_tilt_deg", "(0, 90]"),
            ("start.rotation_deg=[0, 1]", "rotation_deg", "3"),
            ("start.spin=1", "spin", "unknown"),
        ] {
            let e = Config::from_toml(SEED, "t", &[set.into()])
                .expect_err(set)
                .to_string();
            assert!(e.contains(key) && e.contains(range), "{set}: {e}");
        }
        let ok = Config::from_toml(
            SEED,
            "t",
            &[
                "start.rotation_deg=[0, 180, 0]".into(),
                "start.angular_velocity=[0, 0, 50]".into(),
                "land.max_tilt_deg=90".into(),
            ],
        )
        .unwrap();
        assert!(!ok.start.is_default());
        let d = Config::from_toml(SEED, "t", &[]).unwrap();
        assert!(d.start.is_default() && d.land.max_tilt_deg.is_none());
    }
}
