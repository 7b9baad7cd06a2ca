//! What catflip accepts beyond "a positive number": the caps on the work a
//! config implies, the geometry a cat can have, and the plausibility rules
//! that catch unit slips (docs/configuration.md lists them for users).
//!
//! Three kinds of rule, checked in this order by [`Config::validate`]:
//! - **ranges** ([`RANGES`]): each key's documented interval; values outside
//!   it would overflow, or make the work (integrator steps, samples, solver
//!   iterations, output rows) grow without bound;
//! - **impossible** inputs ([`impossible`]): a cat that cannot exist, or
//!   whose halves pass through each other at the configured bend limit;
//! - **slips** ([`slips`]): legal but implausible values, reported as
//!   warnings that name the likely slip (rev/min typed as rad/s, radians as
//!   degrees, centimetres as metres); the command still runs.

use super::Config;
use crate::error::{Error, Result};
use std::f64::consts::PI;

/// Longest fall, s. The simulations, the report's curves and the simulator
/// controls grow with the fall's duration (a 45 s fall wrote 179 MB and a
/// 4 h one ran out of memory); 30 s is a 4.4 km drop in Earth's gravity, far
/// beyond the model's own reach (it has no air drag, and a cat falls at its
/// terminal speed after a few seconds).
pub const MAX_FALL_TIME_S: f64 = 30.0;
/// Whether a fall of `fall_time_s` (manoeuvre plus margin) is longer than
/// any catflip designs (a NaN one too: no fall has it).
pub fn beyond_longest_fall(fall_time_s: f64) -> bool {
    fall_time_s.is_nan() || fall_time_s > MAX_FALL_TIME_S
}

/// Shortest fall, s: below it the torques (which grow as `1 / T^2`) leave
/// the range where the solvers' tolerances mean anything.
pub const MIN_FALL_TIME_S: f64 = 1e-3;
/// Most turns of the bend direction the analytic twist may take (`pi / C`):
/// a bend near the straight cat needs ever more turns, and the kinematic
/// check integrates every one of them.
pub const MAX_ANALYTIC_TURNS: f64 = 200.0;

/// One key's documented interval, inclusive at both ends unless marked.
#[derive(Debug, Clone, Copy)]
pub struct KeyRange {
    pub key: &'static str,
    pub min: f64,
    /// `min` itself is excluded (the value must be above it).
    pub min_open: bool,
    pub max: f64,
    pub unit: &'static str,
    /// Why the bound is where it is, for the message.
    pub why: &'static str,
}

const fn range(
    key: &'static str,
    min: f64,
    min_open: bool,
    max: f64,
    unit: &'static str,
    why: &'static str,
) -> KeyRange {
    KeyRange {
        key,
        min,
        min_open,
        max,
        unit,
        why,
    }
}

/// The ranges checked on top of each key's own rule in `validate` (which
/// stays the first message a user meets for a sign or type error).
pub const RANGES: &[KeyRange] = &[
    range("cat.mass", 1e-6, false, 1e4, "kg", "1 mg to 10 t a half"),
    range(
        "cat.front.mass",
        1e-6,
        false,
        1e4,
        "kg",
        "1 mg to 10 t a half",
    ),
    range(
        "cat.length",
        1e-4,
        false,
        100.0,
        "m",
        "0.1 mm to 100 m a half",
    ),
    range(
        "cat.front.length",
        1e-4,
        false,
        100.0,
        "m",
        "0.1 mm to 100 m a half",
    ),
    range(
        "fall.gravity",
        1e-3,
        false,
        1e3,
        "m/s^2",
        "1 mm/s^2 to 100 g",
    ),
    range("limits.max_torque", 1e-9, false, 1e9, "N m", "nN m to GN m"),
    range(
        "limits.no_load_speed",
        1e-6,
        false,
        1e5,
        "rad/s",
        "at most 1e5 rad/s (about 1 million rev/min)",
    ),
    range(
        "limits.max_speed",
        1e-6,
        false,
        1e5,
        "rad/s",
        "at most 1e5 rad/s (about 1 million rev/min)",
    ),
    range(
        "simulate.rtol",
        1e-14,
        false,
        1e-2,
        "relative",
        "below 1e-14 is below double precision, and the integrator's steps grow without bound",
    ),
    range(
        "simulate.pd_bandwidth_hz",
        0.0,
        true,
        100.0,
        "Hz",
        "the integrator resolves every PD period: at most 100 Hz, 3000 periods over the longest fall",
    ),
    range(
        "simulate.pd_damping",
        0.0,
        true,
        100.0,
        "damping ratio",
        "at most 100 (overdamped far beyond any servo; stiffer means more integrator steps)",
    ),
    range(
        "phased.bend_tol_deg",
        1e-4,
        false,
        10.0,
        "deg",
        "below 1e-4 deg the bend search only adds solves",
    ),
    range(
        "free.max_iterations",
        1.0,
        false,
        2000.0,
        "count",
        "each iteration is a conic solve; 2000 is 13 times the default",
    ),
];

impl KeyRange {
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite()
            && x <= self.max
            && (if self.min_open {
                x > self.min
            } else {
                x >= self.min
            })
    }

    /// `[1e-6, 1e4] kg` or `(0, 100] Hz`.
    pub fn interval(&self) -> String {
        let open = if self.min_open { "(" } else { "[" };
        format!("{open}{:e}, {:e}] {}", self.min, self.max, self.unit)
    }

    fn check(&self, x: f64) -> Result<()> {
        if self.contains(x) {
            return Ok(());
        }
        Err(Error::Invalid {
            key: self.key.into(),
            value: show(x),
            expected: format!("must be in {} ({})", self.interval(), self.why),
        })
    }
}

pub use crate::error::show;

fn invalid(key: &str, value: f64, expected: String) -> Error {
    Error::Invalid {
        key: key.into(),
        value: show(value),
        expected,
    }
}

/// Every key of [`RANGES`] that the config sets within its documented
/// range: checked before the other checks, so that a value outside is told
/// its range, not only its sign.
pub fn check_documented(cfg: &Config) -> Result<()> {
    let c = &cfg.cat;
    let fr = c.front.clone().unwrap_or_default();
    let l = &cfg.limits;
    for r in RANGES {
        let v = match r.key {
            "cat.mass" => Some(c.mass),
            "cat.front.mass" => fr.mass,
            "cat.length" => Some(c.length),
            "cat.front.length" => fr.length,
            "fall.gravity" => Some(cfg.fall.gravity),
            "limits.max_torque" => l.max_torque,
            "limits.no_load_speed" => l.no_load_speed,
            "limits.max_speed" => l.max_speed,
            "simulate.rtol" => Some(cfg.simulate.rtol),
            "simulate.pd_bandwidth_hz" => Some(cfg.simulate.pd_bandwidth_hz),
            "simulate.pd_damping" => Some(cfg.simulate.pd_damping),
            "phased.bend_tol_deg" => Some(cfg.phased.bend_tol_deg),
            "free.max_iterations" => Some(cfg.free.max_iterations as f64),
            other => unreachable!("RANGES names {other}, which check_documented does not read"),
        };
        if let Some(v) = v {
            r.check(v)?;
        }
    }
    Ok(())
}

/// The ranges that depend on other keys: the radii against the lengths,
/// the analytic split's fractions.
pub fn check_derived(cfg: &Config) -> Result<()> {
    let cat = cfg.cat();
    for (key, h) in [("cat.radius", &cat.rear), ("cat.front.radius", &cat.front)] {
        // (h.length / 1000 as written: 1e-4 * 1e-3 rounds above 1e-7)
        if h.radius < h.length / 1000.0 * (1.0 - 1e-12) {
            return Err(invalid(
                key,
                h.radius,
                format!(
                    "must be at least a thousandth of the half's length ({:.4e} m): a thinner half has no axial inertia to twist with",
                    h.length / 1000.0
                ),
            ));
        }
    }
    for (i, x) in cfg.analytic.split.iter().enumerate() {
        if *x < 0.01 {
            return Err(invalid(
                &format!("analytic.split[{i}]"),
                *x,
                "each fraction must be at least 0.01 (a phase of 1 % of the manoeuvre; shorter ones need torques growing as 1 / fraction^2)".into(),
            ));
        }
    }
    Ok(())
}

/// `fall.height` and `fall.gravity` together: the fall's duration in
/// `[MIN_FALL_TIME_S, MAX_FALL_TIME_S]`, computed without overflow.
pub fn check_fall_time(cfg: &Config) -> Result<()> {
    let f = &cfg.fall;
    let t = cfg.fall_time();
    let g = f.gravity;
    // the heights that bound the fall at this gravity: g t^2 / 2
    let (lo, hi) = (
        0.5 * g * MIN_FALL_TIME_S.powi(2),
        0.5 * g * MAX_FALL_TIME_S.powi(2),
    );
    if t.is_finite() && (MIN_FALL_TIME_S..=MAX_FALL_TIME_S).contains(&t) {
        return Ok(());
    }
    let long = t.is_nan() || t >= MIN_FALL_TIME_S;
    let dur = if t.is_finite() {
        format!("a {t:.4e} s fall")
    } else {
        "a fall too long to represent".into()
    };
    Err(invalid(
        "fall.height",
        f.height,
        format!(
            "gives {dur} at fall.gravity = {g} m/s^2; catflip designs falls of {MIN_FALL_TIME_S} s to {MAX_FALL_TIME_S} s, here fall.height from {lo:.4e} m to {hi:.4} m ({}). Is the height in metres?",
            if long {
                "the simulations, curves and simulator controls grow with the fall's duration, and the model has no air drag"
            } else {
                "the torques grow as 1 / T^2"
            }
        ),
    ))
}

/// The angle between the halves at which the end of the shorter half
/// reaches the other half (`l sin(theta) = r_A + r_B`, `theta < 90 deg`),
/// rad: bent further, the halves pass through each other.
pub fn closest_theta(cfg: &Config) -> f64 {
    closest_theta_of_cat(&cfg.cat())
}

/// [`closest_theta`] of a cat's two cylinders.
pub fn closest_theta_of_cat(cat: &crate::model::Cat) -> f64 {
    closest_theta_of(
        cat.rear.length.min(cat.front.length),
        cat.rear.radius + cat.front.radius,
    )
}

/// [`closest_theta`] of halves whose shorter length is `l` and whose radii
/// sum to `r`.
pub fn closest_theta_of(l: f64, r: f64) -> f64 {
    if r >= l { PI / 2.0 } else { (r / l).asin() }
}

/// Values that no cat has: the halves intersecting at the configured bend
/// limit, a twist with more turns than the kinematic check can follow.
pub fn impossible(cfg: &Config) -> Result<()> {
    if let Some(b) = cfg.limits.max_bend_deg {
        let theta_min = closest_theta(cfg);
        let theta = PI - b.to_radians();
        if theta < theta_min {
            return Err(invalid(
                "limits.max_bend_deg",
                b,
                format!(
                    "folds the halves into each other: at {:.2} deg between them the end of the shorter half is within the radii (the halves' radii sum to {} m); the largest bend this cat allows is {:.2} deg",
                    theta.to_degrees(),
                    cfg.cat().rear.radius + cfg.cat().front.radius,
                    180.0 - theta_min.to_degrees()
                ),
            ));
        }
    }
    // the closed forms' twist (F1), without the design layer
    let cat = cfg.cat();
    let (_, c) = crate::model::twist::yy_inertia_and_c(
        cat.i_t(),
        cat.i_a(),
        cfg.analytic.theta_deg.to_radians(),
    );
    let turns = PI / c / (2.0 * PI);
    if !(c > 0.0 && turns.is_finite() && turns <= MAX_ANALYTIC_TURNS) {
        return Err(invalid(
            "analytic.theta_deg",
            cfg.analytic.theta_deg,
            format!(
                "needs {turns:.3e} turns of the bend direction (C = {:.3e}), more than {MAX_ANALYTIC_TURNS}: so nearly straight a cat barely turns by twisting; choose a smaller angle between the halves",
                c
            ),
        ));
    }
    Ok(())
}

/// A plausibility warning: the key, its value, and the likely slip.
#[derive(Debug, Clone, PartialEq)]
pub struct Slip {
    pub key: String,
    pub message: String,
}

impl std::fmt::Display for Slip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.key, self.message)
    }
}

const RPM: f64 = 2.0 * PI / 60.0;

/// A no-load or top speed above this, rad/s, is asked about as rev/min
/// typed as rad/s: servos' 40 to 120 rev/min are 40 to 120 "rad/s" then;
/// the lightly geared motors a `catflip size` speed-up gives stay below.
const SERVO_SPEED_SLIP: f64 = 40.0;

/// Radian values typed in place of degrees (`start.rotation_deg`): pi/6,
/// pi/4, pi/3, pi/2, pi and 2 pi.
const RADIAN_LIKE: [f64; 6] = [PI / 6.0, PI / 4.0, PI / 3.0, PI / 2.0, PI, 2.0 * PI];

/// A start spinning faster than a turn a second (rad/s) is asked about as
/// deg/s: the studies' spins are 0.5 rad/s.
const SPIN_SLIP: f64 = 2.0 * PI;

/// A flip tolerance above 10 deg (rad) is asked about as degrees.
const FLIP_TOLERANCE_SLIP: f64 = 0.1745;

/// A half's radius of gyration above this many times the body's span (the
/// halves' centres of mass through the joint) is asked about as kg cm^2 (a
/// long half's is about 0.3 of it).
const GYRATION_SLIP: f64 = 5.0;

/// A stall torque above this many times `m g L` (the whole body's weight at
/// its length) is asked about as N mm or kg cm typed as N m.
const TORQUE_SLIP: f64 = 10.0;

/// Legal but implausible values, each with the likely slip. Bounds are those
/// of the hardware catflip models (small animals, hobby and research robots).
pub fn slips(cfg: &Config) -> Vec<Slip> {
    let mut out = Vec::new();
    let mut warn = |key: &str, message: String| {
        out.push(Slip {
            key: key.into(),
            message,
        })
    };
    let c = cfg.cat();
    // with a [body] the cylinders are its equivalent ones, not typed keys:
    // its own masses are
    let typed = cfg.body.is_none();
    let masses: [(String, Option<f64>); 2] = match &cfg.body {
        None => [
            ("cat.mass".into(), Some(cfg.cat.mass)),
            (
                "cat.front.mass".into(),
                cfg.cat.front.as_ref().and_then(|f| f.mass),
            ),
        ],
        Some(b) => {
            // a mass typed in [body.rear] / [body.front], else the file's
            let file = b.urdf.as_ref().map_or("body.mjcf", |_| "body.urdf");
            let resolved = b.halves.map(|h| [h.rear.mass, h.front.mass]);
            let half = |i: usize, name: &str, typed: Option<f64>| match typed {
                Some(m) => (format!("body.{name}.mass"), Some(m)),
                None => (
                    format!("{file} ({name} half's mass)"),
                    resolved.map(|r| r[i]),
                ),
            };
            [
                half(0, "rear", b.rear.as_ref().and_then(|r| r.mass)),
                half(1, "front", b.front.as_ref().and_then(|r| r.mass)),
            ]
        }
    };
    for (key, m) in masses {
        let Some(m) = m else { continue };
        if m > 200.0 {
            warn(
                &key,
                format!(
                    "{m} kg a half is heavier than any cat or small robot: grams typed as kilograms? ({m} g = {} kg)",
                    m / 1000.0
                ),
            );
        }
    }
    // the front half's own keys only: one it inherits from [cat] is warned
    // about there, under the key the user typed
    let front = cfg.cat.front.as_ref();
    let front_length = typed && front.is_some_and(|f| f.length.is_some());
    let front_radius = typed && front.is_some_and(|f| f.radius.is_some() || f.length.is_some());
    for (key, h, (length, radius)) in [
        ("cat", &c.rear, (typed, typed)),
        ("cat.front", &c.front, (front_length, front_radius)),
    ] {
        if length && h.length > 5.0 {
            warn(
                &format!("{key}.length"),
                format!(
                    "{} m a half is longer than any cat or small robot: centimetres typed as metres? ({} cm = {} m)",
                    h.length,
                    h.length,
                    h.length / 100.0
                ),
            );
        }
        if radius && 2.0 * h.radius > h.length {
            warn(
                &format!("{key}.radius"),
                format!(
                    "{} m makes the half wider ({} m across) than long ({} m): the diameter typed as the radius? (the radius of a {} m wide half is {} m)",
                    h.radius,
                    2.0 * h.radius,
                    h.length,
                    h.radius,
                    h.radius / 2.0
                ),
            );
        }
    }
    let f = &cfg.fall;
    if f.height > 100.0 {
        warn(
            "fall.height",
            format!(
                "{} m: centimetres typed as metres? ({} cm = {} m); the model has no air drag, which dominates falls this long",
                f.height,
                f.height,
                f.height / 100.0
            ),
        );
    }
    if (30.0..34.0).contains(&f.gravity) {
        warn(
            "fall.gravity",
            format!(
                "{} m/s^2: feet per second squared? (Earth's 32.2 ft/s^2 = 9.81 m/s^2)",
                f.gravity
            ),
        );
    } else if f.gravity > 30.0 {
        warn(
            "fall.gravity",
            format!(
                "{} m/s^2 is more than any planet's surface gravity (Jupiter's 24.8): centimetres per second squared? ({} cm/s^2 = {} m/s^2)",
                f.gravity,
                f.gravity,
                f.gravity / 100.0
            ),
        );
    }
    // a speed the robot file gave is named there, not as a key the user never typed
    let origin = cfg.limits_from();
    for (key, w) in [
        ("limits.no_load_speed", cfg.limits.no_load_speed),
        ("limits.max_speed", cfg.limits.max_speed),
    ] {
        if let Some(w) = w
            && w > SERVO_SPEED_SLIP
        {
            warn(
                &origin.name(key),
                format!(
                    "{w} rad/s ({:.0} rev/min) is faster than the geared servos of small robots (5 to 15 rad/s): a datasheet's rev/min typed as rad/s? ({w} rev/min = {:.4} rad/s)",
                    w / RPM,
                    w * RPM
                ),
            );
        }
    }
    // a motor that could hold the whole body out at arm's length many times
    // over: N mm or kg cm typed as N m (a flip needs a fraction of m g L)
    if let Some(t) = cfg.limits.max_torque {
        let cat = cfg.cat();
        let mgl = (cat.rear.mass + cat.front.mass)
            * cfg.fall.gravity
            * (cat.rear.length + cat.front.length);
        if t > TORQUE_SLIP * mgl {
            warn(
                &origin.name("limits.max_torque"),
                format!(
                    "{t} N m is over {TORQUE_SLIP} times the torque that holds the whole body out at arm's length (m g L = {mgl:.3} N m): N mm or kg cm typed as N m? ({t} N mm = {:.4} N m, {t} kg cm = {:.4} N m)",
                    t * 1e-3,
                    t * 0.0980665
                ),
            );
        }
    }
    let degrees = [
        ("analytic.theta_deg", Some(cfg.analytic.theta_deg)),
        ("limits.max_bend_deg", cfg.limits.max_bend_deg),
    ];
    for (key, d) in degrees {
        if let Some(d) = d
            && d <= PI
        {
            warn(
                key,
                format!(
                    "{d} deg is a tiny angle: radians typed as degrees? ({d} rad = {:.2} deg)",
                    d.to_degrees()
                ),
            );
        }
    }
    let closest_rad = closest_theta(cfg);
    if cfg.analytic.theta_deg.to_radians() < closest_rad {
        let closest = closest_rad.to_degrees();
        let what = if cfg.body.is_some() { "body" } else { "cat" };
        warn(
            "analytic.theta_deg",
            format!(
                "the seed's analytic schedule folds to {} deg between the halves{}, where they pass through each other (the end of the shorter half is within the radii); the closest this {what} folds is {closest:.2} deg. That schedule (the analytic row, a reference) is still evaluated as the model's mathematics; set analytic.theta_deg = {} or more for one this {what} can fly (and limits.max_bend_deg for the designs)",
                cfg.analytic.theta_deg,
                if cfg.analytic.theta_deg
                    == crate::design::spec::AnalyticSettings::default().theta_deg
                {
                    " (analytic.theta_deg's default)"
                } else {
                    ""
                },
                closest.ceil(),
            ),
        );
    }
    // a rotation typed in radians: the usual radian values, not degrees anyone types
    for (i, d) in cfg.start.rotation_deg.iter().enumerate() {
        if RADIAN_LIKE.iter().any(|r| (d.abs() - r).abs() < 2e-3) {
            warn(
                &format!("start.rotation_deg[{i}]"),
                format!(
                    "{d} deg is a radian value: radians typed as degrees? ({d} rad = {:.2} deg)",
                    d.to_degrees()
                ),
            );
        }
    }
    let spin = cfg
        .start
        .angular_velocity
        .iter()
        .map(|w| w * w)
        .sum::<f64>()
        .sqrt();
    if spin > SPIN_SLIP {
        warn(
            "start.angular_velocity",
            format!(
                "{spin:.4} rad/s is over a turn a second ({:.2} turns/s): degrees per second typed as rad/s? ({spin:.4} deg/s = {:.4} rad/s)",
                spin / (2.0 * PI),
                spin.to_radians()
            ),
        );
    }
    let tol = cfg.simulate.flip_tolerance;
    if tol > FLIP_TOLERANCE_SLIP {
        warn(
            "simulate.flip_tolerance",
            format!(
                "{tol} rad is {:.1} deg, a loose flip tolerance (default 0.01 rad): degrees typed as radians? ({tol} deg = {:.4} rad); for a landing tolerance in degrees, land.max_tilt_deg",
                tol.to_degrees(),
                tol.to_radians()
            ),
        );
    }
    // an inertia in kg cm^2: a radius of gyration far beyond the body's
    // span, the two halves' centres of mass through the joint (a half's own
    // reach may be a centimetre: a motor block at the joint)
    if let Some(b) = &cfg.body {
        let reach = |h: &Option<crate::import::RigidConfig>| {
            let h = h.as_ref()?;
            let (com, joint) = (h.com?, h.joint?);
            Some(
                (0..3)
                    .map(|k| (joint[k] - com[k]).powi(2))
                    .sum::<f64>()
                    .sqrt(),
            )
        };
        if let (Some(a), Some(f)) = (reach(&b.rear), reach(&b.front)) {
            let span = a + f;
            for (name, half) in [("rear", &b.rear), ("front", &b.front)] {
                let Some((m, i)) = half.as_ref().and_then(|h| Some((h.mass?, h.inertia?))) else {
                    continue;
                };
                let largest = (0..3).map(|k| i[k][k]).fold(0.0, f64::max);
                let gyration = (largest / m).sqrt();
                if m > 0.0 && span > 0.0 && gyration > GYRATION_SLIP * span {
                    warn(
                        &format!("body.{name}.inertia"),
                        format!(
                            "its radius of gyration sqrt(I / m) = {gyration:.3} m is over {GYRATION_SLIP} times the body's {span:.3} m span (the centres of mass through the joint): kg cm^2 typed as kg m^2? ({largest} kg cm^2 = {:.3e} kg m^2)",
                            largest * 1e-4
                        ),
                    );
                }
            }
        }
    }
    for (key, delay_ms) in [
        ("control.delay_ms", cfg.control.delay_ms),
        ("robustness.delay_ms", cfg.robustness.delay_ms),
    ] {
        if let Some(message) = cfg.control.delay_slip(delay_ms) {
            warn(key, message);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    /// The radius's bound is the documented `length / 1000` to rounding:
    /// exactly on it passes (1e-4 * 1e-3 rounds above 1e-7), just under fails.
    #[test]
    fn a_radius_of_a_thousandth_of_the_length_is_accepted() {
        let at = |r: &str| {
            let sets = ["cat.length=1e-4".to_string(), format!("cat.radius={r}")];
            crate::config::Config::load(std::path::Path::new("configs/seed.toml"), &sets)
        };
        at("1e-7").expect("exactly a thousandth");
        let e = at("0.99e-7").unwrap_err().to_string();
        assert!(
            e.contains("a thousandth of the half's length (1.0000e-7 m)"),
            "{e}"
        );
    }
}
