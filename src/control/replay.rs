//! One trial of a study flown again (`catflip robustness --trial K`): what
//! each controller did in it, as a table, a CSV of the flights and figures,
//! so that a trial a study missed can be looked at, not only counted.

use super::closed_loop::{Log, to_sim};
use super::plant::attitude;
use super::robustness::{CONTROLLERS, Draw, Replay};
use crate::error::Result;
use crate::model::momentum::landing_error;
use serde::Serialize;

/// The flights' CSV header: a row per logged state of each controller's
/// flight, the state in the simulators' world (the exported gains'
/// convention, docs/control.md).
pub const HEADER: &str = "controller,t_s,belly_from_down_deg,w,x,y,z,lambda_x,lambda_y,lambda_z,q1_rad,q2_rad,q1_dot_rad_s,q2_dot_rad_s,tau1_nm,tau2_nm";

/// The simulator steps between logged states: one a millisecond, or every
/// step when the simulator is slower.
pub fn every(h: f64) -> usize {
    (1e-3 / h).floor().max(1.0) as usize
}

/// The times of a flight's logged states, s.
fn times(log: &Log, h: f64) -> Vec<f64> {
    log.samples.iter().map(|p| p.step as f64 * h).collect()
}

/// The belly's angle from straight down, deg, of a state.
fn belly_deg(y: &super::plant::Y) -> f64 {
    landing_error(attitude(y).to_rotation_matrix().matrix()).to_degrees()
}

/// The flights as CSV ([`HEADER`]), the controllers in [`CONTROLLERS`]' order.
pub fn to_csv(r: &Replay) -> String {
    let mut s = String::from(HEADER);
    s.push('\n');
    for (name, (_, log)) in CONTROLLERS.iter().zip(&r.flights) {
        for p in &log.samples {
            let sim = to_sim(&p.state);
            let cells: Vec<String> = [p.step as f64 * r.h, belly_deg(&p.state)]
                .into_iter()
                .chain(sim)
                .chain(p.torque)
                .map(|v| format!("{v:e}"))
                .collect();
            s.push_str(&format!("{name},{}\n", cells.join(",")));
        }
    }
    s
}

/// A controller's flight in [`Summary`].
#[derive(Debug, Clone, Serialize)]
pub struct Flown {
    pub name: &'static str,
    /// The belly's angle from straight down at touchdown, deg (NaN, written
    /// `null`: the flight diverged).
    pub landing_error_deg: f64,
    pub landed: bool,
    /// Largest correction on top of the feed-forward, N m (the motor norm).
    pub max_correction_nm: f64,
    /// Commands the controller sent.
    pub commands: usize,
    /// Replans made and taken (replanning only; 0 otherwise).
    pub replans: usize,
    pub replans_taken: usize,
}

impl Flown {
    /// "yes" or "no", for the tables.
    pub fn landed_text(&self) -> &'static str {
        if self.landed { "yes" } else { "no" }
    }

    /// "12 (3 taken)", empty for a controller that does not replan.
    pub fn replans_text(&self) -> String {
        if self.replans > 0 {
            format!("{} ({} taken)", self.replans, self.replans_taken)
        } else {
            String::new()
        }
    }
}

/// `trial.json`: the trial, its draws and each controller's landing.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub trial: usize,
    pub seed: u64,
    pub max_tilt_deg: f64,
    pub draw: Draw,
    pub controllers: Vec<Flown>,
}

/// The replay's summary against the landing tolerance `max_tilt_deg`.
pub fn summary(r: &Replay, seed: u64, max_tilt_deg: f64) -> Summary {
    let controllers = CONTROLLERS
        .iter()
        .zip(&r.flights)
        .map(|(&name, (landing, log))| Flown {
            name,
            landing_error_deg: landing.error_deg,
            // a diverged flight (NaN) never lands
            landed: landing.error_deg <= max_tilt_deg,
            max_correction_nm: landing.max_correction_nm,
            commands: log.commands.len(),
            replans: landing.replans.len(),
            replans_taken: landing
                .replans
                .iter()
                .filter(|p| p.outcome == super::replanning::Outcome::Taken)
                .count(),
        })
        .collect();
    Summary {
        trial: r.draw.trial,
        seed,
        max_tilt_deg,
        draw: r.draw,
        controllers,
    }
}

/// The draws in words, for the console and the page.
pub fn draws(d: &Draw) -> String {
    // (a draw of a size configured 0 may be -0: shown as 0)
    let pct = |e: [f64; 2]| format!("{:+.1} / {:+.1} %", 100.0 * e[0] + 0.0, 100.0 * e[1] + 0.0);
    format!(
        "spin at release [{:.3}, {:.3}, {:.3}] rad/s (rear half's axes), tilt {:.2} deg about the horizontal axis at {:.1} deg; errors rear / front: mass {}, inertia {}, length {}; PD gains x {:.3}",
        d.spin_rad_s[0],
        d.spin_rad_s[1],
        d.spin_rad_s[2],
        d.tilt_deg,
        d.tilt_axis_deg,
        pct(d.mass_error),
        pct(d.inertia_error),
        pct(d.length_error),
        d.pd_gain_factor,
    )
}

/// One series a controller of the logged flights: `value` of each sample.
fn series(r: &Replay, value: impl Fn(&super::closed_loop::Sample) -> f64) -> Vec<Vec<f64>> {
    r.flights
        .iter()
        .map(|(_, log): &(_, Log)| log.samples.iter().map(&value).collect())
        .collect()
}

/// The figure of the belly's angle from straight down against time, a line
/// a controller and the landing tolerance.
pub fn belly_figure(r: &Replay, max_tilt_deg: f64) -> Result<String> {
    let (t, ys) = aligned(r, series(r, |p| belly_deg(&p.state)));
    let mut named: Vec<(String, Vec<f64>)> =
        CONTROLLERS.iter().map(|n| n.to_string()).zip(ys).collect();
    named.push((
        format!("landing tolerance, {max_tilt_deg} deg"),
        vec![max_tilt_deg; t.len()],
    ));
    crate::report::lines_styled(
        &format!(
            "Trial {}: the belly's angle from straight down",
            r.draw.trial
        ),
        "time from release, s",
        "belly from down, deg",
        &t,
        &named,
        |_, i| crate::report::distinct_style(i),
    )
}

/// The figure of the joint torques against time under controller `c` (an
/// index of [`CONTROLLERS`]), a line a joint: a figure each, as one
/// controller's torque can be a thousand times another's (the open loop's
/// PD ringing under a delay).
pub fn torque_figure(r: &Replay, c: usize) -> Result<String> {
    let (_, log) = &r.flights[c];
    let t = times(log, r.h);
    let named: Vec<(String, Vec<f64>)> = (0..2)
        .map(|j| {
            let y = log.samples.iter().map(|p| p.torque[j]).collect();
            (format!("joint {}", j + 1), y)
        })
        .collect();
    crate::report::lines_styled(
        &format!(
            "Trial {}: joint torques under {} (after the motor's limits)",
            r.draw.trial, CONTROLLERS[c]
        ),
        "time from release, s",
        "torque, N m",
        &t,
        &named,
        |_, i| crate::report::distinct_style(i),
    )
}

/// The file of [`torque_figure`] for controller `c`.
pub fn torque_file(c: usize) -> String {
    format!("torque-{}.svg", CONTROLLERS[c])
}

/// The controllers' series on one time axis (the longest flight's; a
/// flight that diverged ends early and is padded with NaN, not drawn).
fn aligned(r: &Replay, ys: Vec<Vec<f64>>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let longest: Vec<f64> = r
        .flights
        .iter()
        .max_by_key(|(_, l)| l.samples.len())
        .map(|(_, l)| times(l, r.h))
        .unwrap_or_default();
    let n = longest.len();
    let ys = ys
        .into_iter()
        .map(|mut y| {
            y.resize(n, f64::NAN);
            y
        })
        .collect();
    (longest, ys)
}

/// The index.html caption of a replay's figures.
pub fn caption(file: &str) -> Option<&'static str> {
    match file {
        "belly.svg" => Some(
            "The belly's angle from straight down against time under each controller, from release (about 180 deg: belly up) to touchdown, with the landing tolerance: a flight lands when its line ends below it.",
        ),
        f if f.starts_with("torque-") => Some(
            "Each joint's torque under the controller named in the title: the feed-forward plus the controller's correction and the trial's torque noise, after the motor's saturation and back-EMF (a figure a controller: their scales can differ a thousandfold).",
        ),
        _ => None,
    }
}
