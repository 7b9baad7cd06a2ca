//! `catflip size`: the inverse of the robot builder's question. Not "from
//! what height can these motors flip it?" but "which motors flip it from
//! height `H`?": the Pareto curve of stall torque against no-load speed that
//! just makes the flip, and for the configured motor the gear ratio that
//! needs the least height.
//!
//! Every number comes from the library's least-height designs
//! ([`crate::design::least_height::heights`]: the phased and free-form `time`
//! designs inside the DC-motor envelope of [`crate::model::motor`]), run at
//! the question's fall. What makes the curve cheap is time scaling (F3,
//! F9 with zero momentum): a schedule that fits the envelope `(T, w0)` in
//! time `t`, run `k` times faster, fits `(k^2 T, k w0)` in `t / k`. So the
//! least time is `t*(T, w0) = f(T / w0^2) / w0` with `f` a function of the
//! one ratio `u = T / w0^2` (N m s^2), and ONE least-time design at any motor
//! of ratio `u` gives the exact point of the curve with that ratio: the
//! motor scaled by `k = t* / t_H` (`t_H` the manoeuvre time the fall from
//! `H` leaves). No bisection: a stated number of points ([`SizeSettings`]),
//! each one design (a second, at the scaled motor, when the first guess
//! was more than [`RESCALE`] off, so that every point is designed at the
//! question's own numbers).
//!
//! A gear of ratio `N` moves the motor along `u = N^3 u0`, so the curve's
//! designs also sample the least height against `N`; a golden-section
//! search of at most [`SizeSettings::gear_evaluations`] designs refines the
//! best ratio between the curve's neighbours.
//!
//! The curve's ends are closed forms of two more designs: no motor with
//! less stall torque than the least peak torque without a speed limit
//! (`torque_asymptote_nm`, F7) and none slower than the least speed limit
//! without a torque limit (`speed_asymptote_rad_s`) can do it, whatever the
//! other number.

use crate::config::Config;
use crate::design::free::FreeDesign;
use crate::design::least_height::{Families, heights};
use crate::design::objective::Objective;
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result};
use crate::model::motor::Motor;
use crate::verdict::Status;
use serde::Serialize;
use std::time::Instant;

/// How much work the curve and the gear search may do.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SizeSettings {
    /// Points on the curve (default 8): each one least-time design, two
    /// when the first guess is more than [`RESCALE`] off.
    pub points: usize,
    /// Least-time designs the gear-ratio search may add to the curve's
    /// (default 6).
    pub gear_evaluations: usize,
}

impl Default for SizeSettings {
    fn default() -> Self {
        Self {
            points: 8,
            gear_evaluations: 6,
        }
    }
}

impl SizeSettings {
    /// Most points a curve may have.
    pub const MAX_POINTS: usize = 40;

    pub fn validate(&self) -> Result<()> {
        if !(2..=Self::MAX_POINTS).contains(&self.points) {
            return Err(Error::Usage(format!(
                "--points {}: the curve needs 2 to {} points (each is one least-time design)",
                self.points,
                Self::MAX_POINTS
            )));
        }
        if self.gear_evaluations > 20 {
            return Err(Error::Usage(format!(
                "--gear-evaluations {}: at most 20 (the search narrows the ratio by 0.618 a design)",
                self.gear_evaluations
            )));
        }
        Ok(())
    }
}

/// When a point's design lands more than this far (relative) from the
/// question's manoeuvre time, the point is designed again at the scaled
/// motor: the designs' local optima move a little with the problem's
/// numbers (measured: docs/benchmarks.md, "Design settings: the
/// measurements behind them"), so the curve is designed where it is read.
pub const RESCALE: f64 = 0.03;

/// How close (relative) a motor on the curve comes to needing exactly the
/// height when designed afresh: the least-time designs are local optima
/// whose value moves a little with the problem's numbers (a point is the
/// design of a motor within [`RESCALE`] of it, scaled), so the tests allow
/// this much.
pub const HEIGHT_TOLERANCE: f64 = 0.01;

/// The span of the curve in the ratio `u = T / w0^2`, in decades about the
/// asymptotes' corner `u_c = T_inf / w_min^2`: from `10^-2 u_c` (the
/// torque-limited end, no-load speeds about ten times `w_min`) to `10 u_c`
/// (the speed-limited end, stall torques about ten times `T_inf`).
pub const SPAN_DECADES: (f64, f64) = (-2.0, 1.0);

/// One least-time design of one motor at the question's fall.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotorDesign {
    /// Stall torque, N m.
    pub stall_torque_nm: f64,
    /// No-load speed, rad/s.
    pub no_load_speed_rad_s: f64,
    /// The shortest manoeuvre inside the motor envelope, s.
    pub least_time_s: f64,
    /// The least drop height it needs, m (`g (t + fall.margin)^2 / 2`).
    pub least_height_m: f64,
    /// The design that settles it: `phased` or `free`.
    pub method: &'static str,
    pub status: Status,
}

/// A point of the curve: a motor that just makes the flip from the height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// No-load speed, rad/s.
    pub no_load_speed_rad_s: f64,
    /// The least stall torque at that no-load speed, N m.
    pub stall_torque_nm: f64,
    /// `stall_torque / no_load_speed^2`, N m s^2: the one number time
    /// scaling leaves of a motor.
    pub ratio_nms2: f64,
    /// The design the point is scaled from (its motor, least time and
    /// solver); `scale` = its least time over the question's manoeuvre time.
    pub design: MotorDesign,
    pub scale: f64,
}

/// The configured motor geared by `N`: torque times `N`, speed over `N`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GearPoint {
    pub gear_ratio: f64,
    pub design: MotorDesign,
}

/// The gear-ratio answer for the configured motor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GearAnswer {
    /// The ratio with the least height found (1 is the motor as configured).
    pub best_ratio: f64,
    /// The geared motor's stall torque and no-load speed, N m and rad/s.
    pub stall_torque_nm: f64,
    pub no_load_speed_rad_s: f64,
    /// Its least drop height and manoeuvre time, m and s.
    pub least_height_m: f64,
    pub least_time_s: f64,
    /// The configured ratio's (N = 1) least height, m, and whether it fits `H`.
    pub configured_least_height_m: f64,
    pub configured_possible: bool,
    /// Whether the best ratio flips the robot from `H`.
    pub possible: bool,
    /// The ratios the search ended between, `[low, high]`: the optimum lies
    /// there when the least height is unimodal in `log N` (a wide bracket
    /// says the curve or the search was too coarse to place it; equal ends
    /// when nothing was searched).
    pub bracket: [f64; 2],
    /// Every ratio designed, in increasing order.
    pub evaluations: Vec<GearPoint>,
    /// The least heights the curve's designs predict for the ratios whose
    /// `T / w0^2` they share (`N = (u / u0)^(1/3)`, F3), by increasing ratio.
    pub predicted: Vec<GearPrediction>,
    /// The ratios that make it from the question's height, from the designed
    /// and the predicted ones ([`working_range`]); absent from the JSON
    /// when none makes it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub working_range: Option<GearRange>,
}

/// The gear ratios that make the flip from the question's height: the
/// run of designed ratios around the best that fit it, its ends placed
/// between the last ratio that fits and the first that does not,
/// interpolating the least height linearly in `log N`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GearRange {
    pub low: f64,
    pub high: f64,
    /// The end is the smallest (largest) ratio designed or predicted from
    /// the curve: smaller (larger) ratios were not tried and may make it too.
    pub low_untried_beyond: bool,
    pub high_untried_beyond: bool,
}

/// [`GearRange`] of the designed `(ratio, least height)` pairs against
/// `height`, `None` when none of them fits it.
pub fn working_range(pairs: &[(f64, f64)], height: f64) -> Option<GearRange> {
    let mut p: Vec<(f64, f64)> = pairs
        .iter()
        .filter(|(n, h)| *n > 0.0 && h.is_finite())
        .map(|&(n, h)| (n.ln(), h))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let best = p
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .map(|(i, _)| i)?;
    if p[best].1 > height {
        return None;
    }
    let (mut lo, mut hi) = (best, best);
    while lo > 0 && p[lo - 1].1 <= height {
        lo -= 1;
    }
    while hi + 1 < p.len() && p[hi + 1].1 <= height {
        hi += 1;
    }
    // where the height crosses `height` between a fitting pair and the next
    let cross = |a: (f64, f64), b: (f64, f64)| a.0 + (height - a.1) / (b.1 - a.1) * (b.0 - a.0);
    Some(GearRange {
        low: if lo > 0 {
            cross(p[lo], p[lo - 1])
        } else {
            p[0].0
        }
        .exp(),
        high: if hi + 1 < p.len() {
            cross(p[hi], p[hi + 1])
        } else {
            p[hi].0
        }
        .exp(),
        low_untried_beyond: lo == 0,
        high_untried_beyond: hi + 1 == p.len(),
    })
}

/// A gear ratio's least height as a curve point's design predicts it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GearPrediction {
    pub gear_ratio: f64,
    pub least_time_s: f64,
    pub least_height_m: f64,
}

/// What `catflip size` answers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SizeAnswer {
    pub name: String,
    pub joint: &'static str,
    pub peak_norm: crate::model::TorqueNorm,
    /// The question's drop height, m, and the manoeuvre time it leaves, s.
    pub height_m: f64,
    pub manoeuvre_time_s: f64,
    /// The least stall torque at an unlimited no-load speed, N m (the
    /// free-form peak design without limits): no weaker motor was found to.
    pub torque_asymptote_nm: f64,
    /// The least no-load speed at an unlimited stall torque, rad/s (the
    /// least-time design under the speed limit alone): no slower motor was
    /// found to (a local optimum, which the curve's points may pass).
    pub speed_asymptote_rad_s: f64,
    /// The configured hard speed limit over the no-load speed, which every
    /// motor of the curve and the gear search keeps (none without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_limit_ratio: Option<f64>,
    /// The curve, by increasing no-load speed.
    pub curve: Vec<CurvePoint>,
    /// Points whose design failed, with the reason (the curve has a gap there).
    pub failed: Vec<String>,
    pub gear: GearAnswer,
    pub settings: SizeSettings,
    /// Least-time and peak designs run, and the wall time, s.
    pub designs: usize,
    pub solve_time_s: f64,
}

impl SizeAnswer {
    /// The `--set` keys that give `catflip run` the motor (stall torque,
    /// no-load speed), with the hard speed limit in its configured ratio.
    pub fn motor_keys(&self, torque: f64, no_load: f64) -> String {
        let mut keys =
            format!("--set limits.max_torque={torque:.4} --set limits.no_load_speed={no_load:.3}");
        if let Some(r) = self.speed_limit_ratio {
            keys += &format!(" --set limits.max_speed={:.3}", r * no_load);
        }
        keys
    }

    /// Whether some design failed (exit status 3).
    pub fn is_partial(&self) -> bool {
        !self.failed.is_empty()
    }
}

/// Checks that the config describes a DC motor (`catflip size` scales its
/// line) and sets the question's height: a bad one names `--height`.
pub fn question(cfg: &Config, height: f64) -> Result<Config> {
    let l = &cfg.limits;
    for (key, set, what) in [
        ("limits.max_torque", l.max_torque, "stall torque, N m"),
        (
            "limits.no_load_speed",
            l.no_load_speed,
            "no-load speed, rad/s",
        ),
    ] {
        if set.is_none() {
            return Err(Error::Missing {
                key: key.into(),
                why: format!(
                    "catflip size scales the motors' torque-speed line, so it needs limits.max_torque and limits.no_load_speed: set {key} ({what}) to your motor's, in the config's [limits] or with --set {key}=VALUE"
                ),
            });
        }
    }
    if cfg.start.angular_velocity.iter().any(|w| *w != 0.0) {
        // F9: with momentum, a sped-up schedule needs the momentum scaled too
        return Err(Error::Invalid {
            key: "start.angular_velocity".into(),
            value: format!("{:?}", cfg.start.angular_velocity),
            expected: "catflip size rests on time scaling, which holds for a release without angular momentum only (F9 scales the momentum with the speed): size the motors for a release at rest (start.angular_velocity = [0, 0, 0]) and check the spin with catflip run".into(),
        });
    }
    let mut q = cfg.clone();
    q.fall.height = height;
    q.validate().map_err(|e| height_error(height, e))?;
    if !(height.is_finite() && q.available_time() > 0.0) {
        return Err(Error::Usage(format!(
            "--height {height}: the fall leaves no time for the manoeuvre after fall.margin = {} s; give a greater height",
            cfg.fall.margin
        )));
    }
    Ok(q)
}

/// A check of `fall.height` or `fall.margin` that failed on the question's
/// height `--height H`, worded as that flag's (the configured drop is not
/// used); any other error as it is.
pub fn height_error(height: f64, e: Error) -> Error {
    match e {
        Error::Invalid { key, expected, .. } if key == "fall.height" || key == "fall.margin" => {
            Error::Usage(format!("--height {height}: {expected} (checked as {key})"))
        }
        Error::Override { arg, message, .. } if arg.starts_with("fall.height=") => {
            Error::Usage(format!("--height {height}: {message}"))
        }
        e => e,
    }
}

/// The configured motor with `torque` and `no_load` in place of its line;
/// a hard speed limit keeps its ratio to the no-load speed (a gear or a
/// scaled motor scales it alike).
fn with_motor(
    q: &Config,
    torque: Option<f64>,
    no_load: Option<f64>,
    speed: Option<f64>,
) -> DesignSpec {
    q.design_spec().with_motor(Motor {
        max_torque: torque,
        no_load_speed: no_load,
        max_speed: speed,
        norm: q.norm(),
    })
}

/// The hard speed limit over the no-load speed of the configured motor.
fn speed_ratio(q: &Config) -> Option<f64> {
    match (q.limits.max_speed, q.limits.no_load_speed) {
        (Some(w), Some(w0)) => Some(w / w0),
        _ => None,
    }
}

/// The least-time design of a motor (stall torque, no-load speed) at the
/// question's fall: the least-height answer of [`heights`].
pub fn design_motor(q: &Config, torque: f64, no_load: f64) -> Result<MotorDesign> {
    let speed = speed_ratio(q).map(|r| r * no_load);
    let spec = with_motor(q, Some(torque), Some(no_load), speed);
    let h = heights(&spec, Families::Both, |_| {})?.expect("a limited motor has an answer");
    let a = &h.answer;
    if !a.from_start {
        // a tilted release: only a free-form design from the start answers
        return Err(Error::Unreachable {
            reason: format!(
                "no design of the motor ({torque} N m, {no_load} rad/s) lands belly-down from the configured [start]"
            ),
        });
    }
    Ok(MotorDesign {
        stall_torque_nm: torque,
        no_load_speed_rad_s: no_load,
        least_time_s: a.least_time_s,
        least_height_m: a.least_height_m,
        method: a.method,
        status: a.status,
    })
}

/// The two ends of the curve: `(T_inf, w_min)`.
fn asymptotes(q: &Config) -> Result<(f64, f64)> {
    // unlimited speed: the least peak torque within the manoeuvre time
    let peak = with_motor(q, None, None, None).with_objective(Objective::PeakTorque);
    let phased = crate::design::phased::optimize(&peak, |_| {})?.peak_torque_nm;
    let torque = match FreeDesign::new(&peak).solve() {
        Ok(fr) if Status::from(fr.status).is_proven() => fr.peak_torque_nm.min(phased),
        _ => phased,
    };
    // unlimited torque: |qd| <= w0 in the motor norm (the line's limit as
    // T grows), or the hard limit when it is lower; designed at the
    // configured no-load speed and scaled (F3)
    let w0 = q.limits.no_load_speed.expect("checked by question");
    let w = w0 * speed_ratio(q).unwrap_or(1.0).min(1.0);
    let speed = with_motor(q, None, None, Some(w));
    let h = heights(&speed, Families::Both, |_| {})?.expect("a speed limit has an answer");
    let speed = w0 * h.answer.least_time_s / q.available_time();
    Ok((torque, speed))
}

/// Answers `catflip size` for the question `q` ([`question`]);
/// `progress(done, total)` counts its steps: the asymptotes, each point of
/// the curve, the gear-ratio search.
pub fn size(
    q: &Config,
    settings: &SizeSettings,
    mut progress: impl FnMut(usize, usize),
) -> Result<SizeAnswer> {
    settings.validate()?;
    let clock = Instant::now();
    let t_h = q.available_time();
    let steps = settings.points + 2;
    progress(0, steps);
    let (t_inf, w_min) = asymptotes(q)?;
    progress(1, steps);
    let mut designs = 4; // two each
    let u_c = t_inf / (w_min * w_min);
    let n = settings.points;
    let mut curve = Vec::new();
    let mut failed = Vec::new();
    for i in 0..n {
        let decade = SPAN_DECADES.0 + (SPAN_DECADES.1 - SPAN_DECADES.0) * i as f64 / (n - 1) as f64;
        let u = u_c * 10f64.powf(decade);
        // guess from the asymptotes: T_inf / T + (w_min / w0)^2 = 1
        let mut w = (t_inf / u + w_min * w_min).sqrt();
        let mut point = None;
        for _ in 0..2 {
            designs += 1;
            match design_motor(q, u * w * w, w) {
                Ok(d) => {
                    let k = d.least_time_s / t_h;
                    let p = CurvePoint {
                        no_load_speed_rad_s: k * w,
                        stall_torque_nm: k * k * u * w * w,
                        ratio_nms2: u,
                        design: d,
                        scale: k,
                    };
                    point = Some(Ok(p));
                    if (k - 1.0).abs() <= RESCALE {
                        break;
                    }
                    w *= k;
                }
                Err(e) => {
                    point = Some(Err(e));
                    break;
                }
            }
        }
        match point.expect("one design at least") {
            Ok(p) => curve.push(p),
            Err(e) => failed.push(format!("ratio {u:.4e} N m s^2: {e}")),
        }
        progress(2 + i, steps);
    }
    curve.sort_by(|a, b| a.no_load_speed_rad_s.total_cmp(&b.no_load_speed_rad_s));
    let (gear, gear_designs) = gear_search(q, &curve, settings)?;
    designs += gear_designs;
    progress(steps, steps);
    Ok(SizeAnswer {
        name: q.name.clone(),
        joint: q.cat.joint.name(),
        peak_norm: q.norm(),
        height_m: q.fall.height,
        manoeuvre_time_s: t_h,
        torque_asymptote_nm: t_inf,
        speed_asymptote_rad_s: w_min,
        speed_limit_ratio: speed_ratio(q),
        curve,
        failed,
        gear,
        settings: *settings,
        designs,
        solve_time_s: clock.elapsed().as_secs_f64(),
    })
}

/// The least height of the configured motor geared by `ratio`.
fn gear_at(q: &Config, ratio: f64) -> Result<GearPoint> {
    let (t0, w0) = (
        q.limits.max_torque.expect("checked by question"),
        q.limits.no_load_speed.expect("checked by question"),
    );
    Ok(GearPoint {
        gear_ratio: ratio,
        design: design_motor(q, t0 * ratio, w0 / ratio)?,
    })
}

/// A search bracket wider than this ratio of its ends does not place the
/// best gear ratio (the defaults end within about 6 %).
const GEAR_BRACKET_WIDE: f64 = 1.25;

/// The best gear ratio: the curve's points predict the least time at
/// `N = (u / u0)^(1/3)` (`t = N f(u) / w0`, `f(u) = t_H w0_point`); the search
/// designs the configured ratio, then golden-section in `log N` between the
/// best prediction's neighbours. Returns the answer and the designs run.
fn gear_search(
    q: &Config,
    curve: &[CurvePoint],
    settings: &SizeSettings,
) -> Result<(GearAnswer, usize)> {
    let (t0, w0) = (
        q.limits.max_torque.expect("checked by question"),
        q.limits.no_load_speed.expect("checked by question"),
    );
    let u0 = t0 / (w0 * w0);
    let t_h = q.available_time();
    let configured = gear_at(q, 1.0)?;
    let mut evals = vec![configured];
    let mut designs = 1;
    // predicted least time against log N from the curve, by increasing N
    let mut predicted: Vec<(f64, f64)> = curve
        .iter()
        .map(|p| {
            let n = (p.ratio_nms2 / u0).cbrt();
            (n.ln(), n * t_h * p.no_load_speed_rad_s / w0)
        })
        .collect();
    let mut predictions: Vec<GearPrediction> = predicted
        .iter()
        .map(|&(ln_n, t)| GearPrediction {
            gear_ratio: ln_n.exp(),
            least_time_s: t,
            least_height_m: crate::design::envelope::height_for(&q.design_spec(), t),
        })
        .collect();
    predictions.sort_by(|a, b| a.gear_ratio.total_cmp(&b.gear_ratio));
    predicted.push((0.0, configured.design.least_time_s));
    predicted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let best = predicted
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let step = if predicted.len() > 1 {
        (predicted[predicted.len() - 1].0 - predicted[0].0) / (predicted.len() - 1) as f64
    } else {
        0.5
    };
    let lo = if best > 0 {
        predicted[best - 1].0
    } else {
        predicted[0].0 - step
    };
    let hi = if best + 1 < predicted.len() {
        predicted[best + 1].0
    } else {
        predicted[best].0 + step
    };
    // golden section on [lo, hi] in log N
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo, hi);
    let mut x1 = b - phi * (b - a);
    let mut x2 = a + phi * (b - a);
    let f = |x: f64, evals: &mut Vec<GearPoint>, designs: &mut usize| -> Result<f64> {
        let g = gear_at(q, x.exp())?;
        *designs += 1;
        let t = g.design.least_time_s;
        evals.push(g);
        Ok(t)
    };
    let budget = settings.gear_evaluations;
    if budget >= 2 {
        let mut f1 = f(x1, &mut evals, &mut designs)?;
        let mut f2 = f(x2, &mut evals, &mut designs)?;
        for _ in 2..budget {
            if f1 <= f2 {
                b = x2;
                x2 = x1;
                f2 = f1;
                x1 = b - phi * (b - a);
                f1 = f(x1, &mut evals, &mut designs)?;
            } else {
                a = x1;
                x1 = x2;
                f1 = f2;
                x2 = a + phi * (b - a);
                f2 = f(x2, &mut evals, &mut designs)?;
            }
        }
        // the last comparison narrows the bracket once more
        if f1 <= f2 {
            b = x2;
        } else {
            a = x1;
        }
    } else if budget == 1 {
        f(predicted[best].0, &mut evals, &mut designs)?;
    } else {
        (a, b) = (0.0, 0.0);
    }
    evals.sort_by(|a, b| a.gear_ratio.total_cmp(&b.gear_ratio));
    let top = *evals
        .iter()
        .min_by(|a, b| a.design.least_time_s.total_cmp(&b.design.least_time_s))
        .expect("the configured ratio at least");
    let spec = q.design_spec();
    let fits = |h: f64| crate::design::least_height::fits(&spec, h);
    let pairs: Vec<(f64, f64)> = evals
        .iter()
        .map(|g| (g.gear_ratio, g.design.least_height_m))
        .chain(predictions.iter().map(|p| (p.gear_ratio, p.least_height_m)))
        .collect();
    let working_range = working_range(&pairs, q.fall.height);
    Ok((
        GearAnswer {
            best_ratio: top.gear_ratio,
            stall_torque_nm: top.design.stall_torque_nm,
            no_load_speed_rad_s: top.design.no_load_speed_rad_s,
            least_height_m: top.design.least_height_m,
            least_time_s: top.design.least_time_s,
            configured_least_height_m: configured.design.least_height_m,
            configured_possible: fits(configured.design.least_height_m),
            possible: fits(top.design.least_height_m),
            bracket: [a.exp(), b.exp()],
            evaluations: evals,
            predicted: predictions,
            working_range,
        },
        designs,
    ))
}

/// The file names `catflip size` writes (docs/outputs.md).
pub mod files {
    pub const CURVE_CSV: &str = "size.csv";
    pub const GEAR_CSV: &str = "size-gear.csv";
    pub const JSON: &str = "size.json";
    pub const CURVE_SVG: &str = "size.svg";
    pub const GEAR_SVG: &str = "size-gear.svg";
}

/// The curve as CSV, one point a row, by increasing no-load speed.
pub fn curve_csv(a: &SizeAnswer) -> String {
    let mut s = String::from(
        "no_load_speed_rad_s,stall_torque_nm,ratio_nms2,design_no_load_speed_rad_s,design_stall_torque_nm,design_least_time_s,scale,method,status\n",
    );
    for p in &a.curve {
        s.push_str(&format!(
            "{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9},{},{}\n",
            p.no_load_speed_rad_s,
            p.stall_torque_nm,
            p.ratio_nms2,
            p.design.no_load_speed_rad_s,
            p.design.stall_torque_nm,
            p.design.least_time_s,
            p.scale,
            p.design.method,
            p.design.status.name()
        ));
    }
    s
}

/// The gear ratios designed, one a row, by increasing ratio.
pub fn gear_csv(a: &SizeAnswer) -> String {
    let mut s = String::from(
        "gear_ratio,stall_torque_nm,no_load_speed_rad_s,least_time_s,least_height_m,method,status\n",
    );
    for g in &a.gear.evaluations {
        let d = &g.design;
        s.push_str(&format!(
            "{:.9},{:.9e},{:.9e},{:.9e},{:.9e},{},{}\n",
            g.gear_ratio,
            d.stall_torque_nm,
            d.no_load_speed_rad_s,
            d.least_time_s,
            d.least_height_m,
            d.method,
            d.status.name()
        ));
    }
    s
}

impl SizeAnswer {
    /// The answer in plain sentences, for the terminal and the report: the
    /// curve's ends, the configured motor, the best gear ratio.
    pub fn sentences(&self) -> Vec<String> {
        let g = &self.gear;
        let can = |ok: bool| if ok { "makes it" } else { "does not make it" };
        // the ends are designs too (local optima): a point of the curve may
        // pass one, and then the curve, not the end's design, is the bound
        let least =
            |f: fn(&CurvePoint) -> f64| self.curve.iter().map(f).fold(f64::INFINITY, f64::min);
        let (torque_end, speed_end) = (
            self.torque_asymptote_nm.min(least(|p| p.stall_torque_nm)),
            self.speed_asymptote_rad_s
                .min(least(|p| p.no_load_speed_rad_s)),
        );
        let passed = |end: f64, found: f64, what: &str, unit: &str| {
            if found < end * (1.0 - HEIGHT_TOLERANCE) {
                format!(
                    " (The {what} end is the curve's point at {found:.4} {unit}: the {what}-only design found a worse local optimum, {end:.4} {unit}.)"
                )
            } else {
                String::new()
            }
        };
        let mut ends = format!(
            "No motor weaker than {torque_end:.4} N m stall torque (at any no-load speed) or slower than {speed_end:.3} rad/s no-load speed (at any stall torque) flips it from {} m, in catflip's designs (local optima, not a proof).",
            self.height_m
        );
        ends += &passed(
            self.torque_asymptote_nm,
            least(|p| p.stall_torque_nm),
            "torque",
            "N m",
        );
        ends += &passed(
            self.speed_asymptote_rad_s,
            least(|p| p.no_load_speed_rad_s),
            "speed",
            "rad/s",
        );
        if let Some(r) = self.speed_limit_ratio {
            // (this sentence is read last: [`Self::lead`])
            let keys = if g.evaluations.len() > 1 {
                "the best gear ratio's sentence above gives them"
            } else {
                "limits.max_speed in that ratio"
            };
            ends += &format!(
                " Each motor keeps the configured hard speed limit's ratio to its no-load speed (limits.max_speed = {r:.4} times limits.no_load_speed): to check a motor with `catflip run`, set all three keys ({keys})."
            );
        }
        let range = match g.working_range {
            Some(r) => format!(
                " Gear ratios from N = {:.4}{} to {:.4}{} make it from {} m (between the ratios designed or predicted from the curve, the least height interpolated in log N).",
                r.low,
                if r.low_untried_beyond {
                    " or less (the lowest ratio designed or predicted)"
                } else {
                    ""
                },
                r.high,
                if r.high_untried_beyond {
                    " or more (the highest ratio designed or predicted)"
                } else {
                    ""
                },
                self.height_m
            ),
            None => format!(" No gear ratio designed makes it from {} m.", self.height_m),
        };
        vec![
            ends,
            format!(
                "The configured motor ({:.4} N m, {:.3} rad/s, gear ratio 1) needs {:.3} m: it {} from {} m.",
                g.evaluations
                    .iter()
                    .find(|e| e.gear_ratio == 1.0)
                    .map_or(f64::NAN, |e| e.design.stall_torque_nm),
                g.evaluations
                    .iter()
                    .find(|e| e.gear_ratio == 1.0)
                    .map_or(f64::NAN, |e| e.design.no_load_speed_rad_s),
                g.configured_least_height_m,
                can(g.configured_possible),
                self.height_m
            ),
            if g.evaluations.len() > 1 {
                let [lo, hi] = g.bracket;
                format!(
                    "The configured motor's best gear ratio is N = {:.4}{} (torque x N, speed / N: {:.4} N m, {:.3} rad/s): {:.3} m ({:.4} s of manoeuvre), so it {} from {} m ({}). The search ended between N = {:.4} and {:.4}{}.",
                    g.best_ratio,
                    // (N < 1: the speed is what the flip lacks)
                    if g.best_ratio < 1.0 {
                        format!(
                            ", a speed-up of {:.2} times the configured gearing",
                            1.0 / g.best_ratio
                        )
                    } else {
                        format!(
                            ", a reduction of {:.2} times the configured gearing",
                            g.best_ratio
                        )
                    },
                    g.stall_torque_nm,
                    g.no_load_speed_rad_s,
                    g.least_height_m,
                    g.least_time_s,
                    can(g.possible),
                    self.height_m,
                    self.motor_keys(g.stall_torque_nm, g.no_load_speed_rad_s),
                    lo,
                    hi,
                    if hi > GEAR_BRACKET_WIDE * lo {
                        ": too coarse to place the optimum (more --points or --gear-evaluations narrow it)"
                    } else {
                        ""
                    }
                )
            } else {
                // no search (--gear-evaluations 0): only the configured ratio was designed
                let best = g
                    .predicted
                    .iter()
                    .min_by(|a, b| a.least_height_m.total_cmp(&b.least_height_m));
                format!(
                    "No gear ratio but the configured one was designed (no gear search){}.",
                    best.map_or(String::new(), |p| format!(
                        "; the curve's designs predict that N = {:.4} needs {:.3} m",
                        p.gear_ratio, p.least_height_m
                    ))
                )
            } + &range,
        ]
    }

    /// [`Self::sentences`] in the order the answer is read, on the terminal
    /// and the page: the headline, the sentence after it, then the curve's
    /// ends. The best gear ratio leads where it alone makes it (after "the
    /// configured motor does not make it", a possible answer read as a
    /// contradiction); otherwise the configured motor does.
    pub fn lead(&self) -> [String; 3] {
        let [ends, configured, gear]: [String; 3] =
            self.sentences().try_into().expect("three sentences");
        if self.gear.possible && !self.gear.configured_possible {
            [gear, configured, ends]
        } else {
            [configured, gear, ends]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A least height linear in `log N` either side of its minimum: the
    /// ends are its crossings exactly; the run stops at the first ratio
    /// that does not fit; at the designed span's ends it says so; nothing
    /// fitting gives none.
    #[test]
    fn the_working_range_is_where_the_heights_cross() {
        // h = 1 + |ln N - ln 0.2|, crossing 1.5 at ln N = ln 0.2 -+ 0.5
        let h = |n: f64| 1.0 + (n.ln() - 0.2f64.ln()).abs();
        let pairs: Vec<(f64, f64)> = (0..12)
            .map(|i| 0.05 * 1.3f64.powi(i))
            .map(|n| (n, h(n)))
            .collect();
        let r = working_range(&pairs, 1.5).unwrap();
        assert!(
            (r.low / (0.2 * (-0.5f64).exp()) - 1.0).abs() < 1e-12,
            "{r:?}"
        );
        assert!((r.high / (0.2 * 0.5f64.exp()) - 1.0).abs() < 1e-12, "{r:?}");
        assert!(!r.low_untried_beyond && !r.high_untried_beyond);
        // another dip that fits, beyond a ratio that does not, is not joined
        let mut dipped = pairs.clone();
        dipped.push((5.0, 1.2));
        assert_eq!(working_range(&dipped, 1.5), Some(r));
        // everything fits: the designed span, open at both ends
        let all = working_range(&pairs, 10.0).unwrap();
        assert!(all.low_untried_beyond && all.high_untried_beyond);
        assert!((all.low - 0.05).abs() < 1e-15 && (all.high / pairs[11].0 - 1.0).abs() < 1e-12);
        assert_eq!(working_range(&pairs, 0.5), None);
        assert_eq!(working_range(&[], 1.0), None);
    }
}
