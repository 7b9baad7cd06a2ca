//! `catflip robustness`: a Monte Carlo study of the closed loop. Each trial
//! draws a robot, a start and noises from `[robustness]` with its own random
//! stream ([`super::rng`]), so that the study is deterministic for a seed,
//! independent of threads, and its shards concatenate into the whole.

use super::closed_loop::{Feedback, Flight, Landing, Log, fly_logged};
use super::reference::{Reference, release};
use super::replanning::SharedPlan;
use super::replanning::{Outcome, Record, Replanning};
use super::rng::Rng;
use super::tvlqr::{Tvlqr, steps_of};
use crate::config::Config;
use crate::model::momentum::Start;
use crate::model::{Cat, Half};
use crate::verify::simulate::Controller;
use serde::{Deserialize, Serialize};

/// Landing tolerance of a study when `land.max_tilt_deg` is not set, deg.
pub const DEFAULT_MAX_TILT_DEG: f64 = 10.0;

/// The controllers a study compares, in the order of the CSV's columns.
pub const CONTROLLERS: [&str; 3] = ["open-loop", "tvlqr", "replan"];

/// The design a study flies: the free-form one from the phased seed, as
/// `run` makes a peak or energy design, or from the analytic seed where the
/// phased family cannot fit (not from the least-height answer's manoeuvre,
/// where `optimize` and `run` start a least time or a fall no phased
/// design fits: the replans from it left the motor envelope and were
/// corrected; measured: docs/benchmarks.md, "Design settings: the
/// measurements behind them"),
/// with a continuous torque (`free.torque_jumps` off): the replans are
/// solved on a grid whose acceleration is continuous, and must be able to
/// reproduce the plan in flight (with steps at the nodes, the replans of
/// the robot's nominal flight landed worse than the plan and were not taken).
///
/// When neither design fits the motors in this fall, the error is `run`'s
/// answer where that names the least drop height.
pub fn design(cfg: &Config) -> crate::Result<crate::design::free::FreeResult> {
    use crate::Error;
    use crate::design::free::{FreeDesign, Seed};
    let spec = cfg.design_spec().without_torque_jumps();
    match FreeDesign::new(&spec).solve() {
        Ok(r) => Ok(r),
        Err(e) => {
            // the phased seed cannot fit this fall: where `run`'s answer
            // (from its own spec: its time design's torque may step where
            // this design's does not) is that nothing found fits it, say
            // so before the analytic seed's long and futile solve
            if matches!(e, Error::SeedUnfit { .. } | Error::BeyondMotors { .. })
                && let Some(beyond) = crate::design::least_height::heights(
                    &cfg.design_spec(),
                    crate::design::least_height::Families::Both,
                    |_| {},
                )
                .ok()
                .flatten()
                .and_then(|h| crate::pipeline::out_of_reach(&h.answer))
            {
                return Err(beyond);
            }
            FreeDesign::new(&spec).seed(Seed::Analytic).solve()
        }
    }
}

/// One trial's draws.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Draw {
    pub trial: usize,
    /// Release body rate, rad/s (rear half's axes).
    pub spin_rad_s: [f64; 3],
    /// Release tilt of the spine, deg, about a horizontal axis at `tilt_axis_deg` from world y.
    pub tilt_deg: f64,
    pub tilt_axis_deg: f64,
    /// Relative errors `[rear, front]`.
    pub mass_error: [f64; 2],
    pub inertia_error: [f64; 2],
    pub length_error: [f64; 2],
    pub pd_gain_factor: f64,
}

impl Draw {
    pub fn new(cfg: &Config, seed: u64, trial: usize) -> Draw {
        let p = &cfg.robustness;
        let mut g = Rng::new(seed, trial as u64, 0);
        let d = g.direction();
        let m = g.uniform();
        let spin_rad_s = [0, 1, 2].map(|i| m * d[i] * p.spin_rad_s[i]);
        let tilt_deg = p.tilt_deg * g.uniform();
        let tilt_axis_deg = 360.0 * g.uniform();
        let mut pair = |e: f64| [e * g.signed(), e * g.signed()];
        let mass_error = pair(p.mass_error);
        let inertia_error = pair(p.inertia_error);
        let length_error = pair(p.length_error);
        let pd_gain_factor = 1.0 + p.pd_gain_error * g.signed();
        Draw {
            trial,
            spin_rad_s,
            tilt_deg,
            tilt_axis_deg,
            mass_error,
            inertia_error,
            length_error,
            pd_gain_factor,
        }
    }

    /// The robot as built: each half's mass, inertia (radii of gyration, the
    /// radius and length scaled by `sqrt(1 + e)`) and length off by the draws.
    pub fn plant(&self, cat: &Cat) -> Cat {
        let half = |h: Half, i: usize| {
            let g = (1.0 + self.inertia_error[i]).sqrt();
            Half {
                mass: h.mass * (1.0 + self.mass_error[i]),
                radius: h.radius * g,
                length: h.length * g * (1.0 + self.length_error[i]),
                ..h
            }
        };
        Cat {
            rear: half(cat.rear, 0),
            front: half(cat.front, 1),
            ..*cat
        }
    }

    pub fn start(&self, cfg: &Config) -> Start {
        let a = self.tilt_axis_deg.to_radians();
        let t = self.tilt_deg.to_radians();
        let tilt = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(
            0.0,
            t * a.cos(),
            t * a.sin(),
        ));
        let base = cfg.start.start().rotation();
        let r = tilt * base;
        let mut s = Start {
            attitude: [r.w, r.i, r.j, r.k],
            body_rate: cfg.start.start().body_rate,
        };
        for i in 0..3 {
            s.body_rate[i] += self.spin_rad_s[i];
        }
        s
    }
}

/// A trial flown again ([`Study::replay`]): its draws and, under each of
/// [`CONTROLLERS`], the landing and the flight's log.
#[derive(Debug, Clone)]
pub struct Replay {
    pub draw: Draw,
    /// The simulator's step, s.
    pub h: f64,
    pub flights: [(Landing, Log); 3],
}

/// A trial's outcome: the landing error under each of [`CONTROLLERS`].
#[derive(Debug, Clone, Serialize)]
pub struct TrialResult {
    pub draw: Draw,
    pub landing_error_deg: [f64; 3],
    /// The replanning controller's replans (wall times: not part of the
    /// study's deterministic files; empty for trials read back from a CSV).
    #[serde(skip)]
    pub replans: Vec<Record>,
}

/// Trial `trial` of the study seeded by `seed`: its draws and the flight
/// they make of the design `r` (gains `tv`: the torque noise is redrawn each
/// of their control periods).
pub fn trial_flight(
    cfg: &Config,
    r: &Reference,
    tv: &Tvlqr,
    seed: u64,
    trial: usize,
) -> (Draw, Flight) {
    let p = &cfg.robustness;
    let draw = Draw::new(cfg, seed, trial);
    let plant = draw.plant(&r.cat);
    let flight = Flight {
        plant,
        release: release(&plant, &draw.start(cfg)),
        delay_steps: steps_of(p.delay_ms * 1e-3, r.h),
        torque_noise: p.torque_noise * r.peak_torque,
        noise_steps: tv.period_steps,
        attitude_noise: p.attitude_noise_deg.to_radians(),
        rate_noise: p.rate_noise_rad_s,
        rng: Rng::new(seed, trial as u64, 1),
    };
    (draw, flight)
}

/// The open loop of a trial: today's joint PD, its gains off by the draw.
pub fn open_loop(pd: &Controller, draw: &Draw) -> Feedback<'static> {
    let f = draw.pd_gain_factor;
    Feedback::JointPd {
        kp: pd.kp * f,
        kd: pd.kd * f,
    }
}

/// The design and the gains a study flies.
pub struct Study<'a> {
    pub cfg: &'a Config,
    pub seed: u64,
    pub reference: Reference,
    /// The open loop's: the feed-forward never held ([`Reference::unheld`]).
    pub open_loop: Reference,
    pub tvlqr: Tvlqr,
    pub pd: Controller,
    pub replanning: Replanning,
}

impl<'a> Study<'a> {
    pub fn new(cfg: &'a Config, plan: SharedPlan, seed: u64) -> crate::Result<Study<'a>> {
        let reference = Reference::checked(cfg, plan.as_ref())?;
        let tvlqr = Tvlqr::new(&reference, &cfg.control);
        let open_loop = reference.for_open_loop(cfg, plan.as_ref());
        Ok(Study {
            cfg,
            seed,
            reference,
            open_loop,
            tvlqr,
            pd: Controller::from_spec(&cfg.design_spec()),
            replanning: Replanning::new(cfg, plan),
        })
    }

    /// Landing tolerance, deg.
    pub fn max_tilt_deg(&self) -> f64 {
        self.cfg.land.max_tilt_deg.unwrap_or(DEFAULT_MAX_TILT_DEG)
    }

    pub fn trial(&self, trial: usize) -> TrialResult {
        let (draw, [open, closed, replan]) = self.flights(trial, None, false);
        TrialResult {
            draw,
            landing_error_deg: [open.0.error_deg, closed.0.error_deg, replan.0.error_deg],
            replans: replan.0.replans,
        }
    }

    /// Trial `trial` flown again under each of [`CONTROLLERS`] (at once on
    /// three threads if `parallel`), each flight's commands and its true
    /// state every `every` simulator steps logged: the same landings as
    /// [`Study::trial`]'s.
    pub fn replay(&self, trial: usize, every: usize, parallel: bool) -> Replay {
        let (draw, flights) = self.flights(trial, Some(every.max(1)), parallel);
        Replay {
            draw,
            h: self.reference.h,
            flights: flights.map(|(landing, log)| (landing, log.unwrap_or_default())),
        }
    }

    /// The trial's draws and its landing under each controller, logged
    /// every `every` steps if given.
    fn flights(
        &self,
        trial: usize,
        every: Option<usize>,
        parallel: bool,
    ) -> (Draw, [(Landing, Option<Log>); 3]) {
        let (cfg, r) = (self.cfg, &self.reference);
        let (draw, flight) = trial_flight(cfg, r, &self.tvlqr, self.seed, trial);
        let motor = cfg.motor();
        let fly = |c: usize| {
            let (r, fb) = match c {
                0 => (&self.open_loop, open_loop(&self.pd, &draw)),
                1 => (r, Feedback::Tvlqr(&self.tvlqr)),
                _ => (r, Feedback::Replan(&self.tvlqr, &self.replanning)),
            };
            let mut log = every.map(Log::every);
            let landing = fly_logged(r, fb, &motor, flight.clone(), log.as_mut());
            (landing, log)
        };
        let flights = if parallel {
            std::thread::scope(|s| {
                let fly = &fly;
                let handles = [0, 1, 2].map(|c| s.spawn(move || fly(c)));
                handles.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            })
        } else {
            [0, 1, 2].map(fly)
        };
        (draw, flights)
    }

    /// Trials `range` on `threads` threads, in trial order; `progress(done, total)`.
    pub fn run(
        &self,
        range: std::ops::Range<usize>,
        threads: usize,
        progress: impl Fn(usize, usize) + Sync,
    ) -> Vec<TrialResult> {
        let store = std::sync::Mutex::new(vec![None; range.len()]);
        self.run_into(range, threads, &store, progress);
        store.into_inner().unwrap().into_iter().flatten().collect()
    }

    /// Flies the trials of `range` whose slot in `store` (one a trial, in
    /// trial order) is empty, filling each as it lands, so that a caller
    /// interrupted mid-study still holds every finished trial and a resumed
    /// study flies only the rest. `progress(done, total)` counts the kept ones.
    pub fn run_into(
        &self,
        range: std::ops::Range<usize>,
        threads: usize,
        store: &std::sync::Mutex<Vec<Option<TrialResult>>>,
        progress: impl Fn(usize, usize) + Sync,
    ) {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let total = range.len();
        let lock = || store.lock().unwrap_or_else(|p| p.into_inner());
        let todo: Vec<usize> = {
            let s = lock();
            assert_eq!(s.len(), total, "one slot a trial");
            (0..total).filter(|&i| s[i].is_none()).collect()
        };
        let next = AtomicUsize::new(0);
        let done = AtomicUsize::new(total - todo.len());
        std::thread::scope(|s| {
            for _ in 0..threads.max(1).min(todo.len().max(1)) {
                s.spawn(|| {
                    while let Some(&i) = todo.get(next.fetch_add(1, Ordering::Relaxed)) {
                        let r = self.trial(range.start + i);
                        lock()[i] = Some(r);
                        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    }
                });
            }
        });
    }
}

/// Wilson score interval at 95 % for `k` successes in `n` trials.
pub fn wilson(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054;
    let (n, p) = (n as f64, k as f64 / n as f64);
    let d = 1.0 + z * z / n;
    let c = (p + z * z / (2.0 * n)) / d;
    let h = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / d;
    // (exact at the ends: `c - h` rounds to 3e-17 at no success)
    let lo = if k == 0 { 0.0 } else { (c - h).max(0.0) };
    let hi = if k as f64 == n { 1.0 } else { (c + h).min(1.0) };
    [lo, hi]
}

/// A trial kept for replay: `catflip robustness --seed S` draws trial `trial` again.
#[derive(Debug, Clone, Serialize)]
pub struct Worst {
    pub trial: usize,
    pub seed: u64,
    pub landing_error_deg: f64,
}

/// One controller's line of the study.
#[derive(Debug, Clone, Serialize)]
pub struct ControllerSummary {
    pub name: &'static str,
    pub successes: usize,
    pub success_rate: f64,
    pub ci95: [f64; 2],
    /// Flights that diverged (their landing error is not a number).
    pub diverged: usize,
    /// Landing error percentiles, deg (a diverged flight counts as 180).
    pub landing_error_deg: Percentiles,
    pub worst: Vec<Worst>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Percentiles {
    pub p50: f64,
    pub p90: f64,
    pub p99: f64,
    pub max: f64,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
    sorted[i]
}

/// The study's JSON.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub trials: usize,
    pub seed: u64,
    pub max_tilt_deg: f64,
    pub controllers: Vec<ControllerSummary>,
}

/// A diverged flight (NaN) lands anywhere: 180 deg in the statistics.
fn error_or_worst(e: f64) -> f64 {
    if e.is_nan() { 180.0 } else { e }
}

pub fn summarise(results: &[TrialResult], seed: u64, max_tilt_deg: f64, keep: usize) -> Summary {
    let controllers = CONTROLLERS
        .iter()
        .enumerate()
        .map(|(c, &name)| {
            let errs: Vec<f64> = results
                .iter()
                .map(|r| error_or_worst(r.landing_error_deg[c]))
                .collect();
            let k = errs.iter().filter(|&&e| e <= max_tilt_deg).count();
            let mut sorted = errs.clone();
            sorted.sort_by(f64::total_cmp);
            let mut idx: Vec<usize> = (0..results.len()).collect();
            idx.sort_by(|&a, &b| errs[b].total_cmp(&errs[a]));
            ControllerSummary {
                name,
                successes: k,
                success_rate: if results.is_empty() {
                    f64::NAN
                } else {
                    k as f64 / results.len() as f64
                },
                ci95: wilson(k, results.len()),
                diverged: results
                    .iter()
                    .filter(|r| r.landing_error_deg[c].is_nan())
                    .count(),
                landing_error_deg: Percentiles {
                    p50: percentile(&sorted, 0.5),
                    p90: percentile(&sorted, 0.9),
                    p99: percentile(&sorted, 0.99),
                    max: sorted.last().copied().unwrap_or(f64::NAN),
                },
                worst: idx
                    .iter()
                    .take(keep)
                    .map(|&i| Worst {
                        trial: results[i].draw.trial,
                        seed,
                        landing_error_deg: errs[i],
                    })
                    .collect(),
            }
        })
        .collect();
    Summary {
        trials: results.len(),
        seed,
        max_tilt_deg,
        controllers,
    }
}

/// The replanning controller's replans over a study's flown trials: wall
/// times on this machine, so outside the study's deterministic files.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReplanTiming {
    /// Trials whose replans are timed here, of `trials`: those a `--resume`
    /// kept were flown before, their times not kept.
    pub trials_timed: usize,
    pub trials: usize,
    pub replans: usize,
    pub taken: usize,
    pub failed: usize,
    pub late: usize,
    pub worse: usize,
    /// Wall time of one replan, s (prediction, solve, comparison, splice).
    pub median_s: f64,
    pub p99_s: f64,
    pub max_s: f64,
    /// Of which the solve, s.
    pub solve_median_s: f64,
    pub solve_p99_s: f64,
    pub solve_max_s: f64,
    /// The control period, s, and the replans that took longer.
    pub period_s: f64,
    pub over_period: usize,
}

pub fn replan_timing(results: &[TrialResult], period_s: f64) -> ReplanTiming {
    let all: Vec<&Record> = results.iter().flat_map(|r| &r.replans).collect();
    let count = |o: Outcome| all.iter().filter(|r| r.outcome == o).count();
    let mut t: Vec<f64> = all.iter().map(|r| r.seconds).collect();
    t.sort_by(f64::total_cmp);
    let mut solve: Vec<f64> = all.iter().map(|r| r.solve_seconds).collect();
    solve.sort_by(f64::total_cmp);
    ReplanTiming {
        trials_timed: results.iter().filter(|r| !r.replans.is_empty()).count(),
        trials: results.len(),
        replans: all.len(),
        taken: count(Outcome::Taken),
        failed: count(Outcome::Failed),
        late: count(Outcome::Late),
        worse: count(Outcome::Worse),
        median_s: percentile(&t, 0.5),
        p99_s: percentile(&t, 0.99),
        max_s: t.last().copied().unwrap_or(f64::NAN),
        solve_median_s: percentile(&solve, 0.5),
        solve_p99_s: percentile(&solve, 0.99),
        solve_max_s: solve.last().copied().unwrap_or(f64::NAN),
        period_s,
        over_period: t.iter().filter(|&&x| x > period_s).count(),
    }
}

/// The CSV header: the draws, then each controller's landing error.
pub const CSV_HEADER: &str = "trial,spin_x_rad_s,spin_y_rad_s,spin_z_rad_s,tilt_deg,tilt_axis_deg,mass_error_rear,mass_error_front,inertia_error_rear,inertia_error_front,length_error_rear,length_error_front,pd_gain_factor,open_loop_landing_error_deg,tvlqr_landing_error_deg,replan_landing_error_deg";

/// Rows of `results`; with the header only for the first shard, so that
/// the shards' files concatenate into the whole study's.
pub fn to_csv(results: &[TrialResult], header: bool) -> String {
    let mut s = String::new();
    if header {
        s.push_str(CSV_HEADER);
        s.push('\n');
    }
    for r in results {
        let d = &r.draw;
        let v: Vec<String> = [
            d.spin_rad_s[0],
            d.spin_rad_s[1],
            d.spin_rad_s[2],
            d.tilt_deg,
            d.tilt_axis_deg,
            d.mass_error[0],
            d.mass_error[1],
            d.inertia_error[0],
            d.inertia_error[1],
            d.length_error[0],
            d.length_error[1],
            d.pd_gain_factor,
            r.landing_error_deg[0],
            r.landing_error_deg[1],
            r.landing_error_deg[2],
        ]
        .iter()
        // (+ 0.0: a negative zero is written as 0e0, not -0e0)
        .map(|x| format!("{:e}", x + 0.0))
        .collect();
        s.push_str(&format!("{},{}\n", d.trial, v.join(",")));
    }
    s
}

/// The trials of a CSV [`to_csv`] wrote (with or without its header): its
/// numbers are printed shortest-round-trip, so they read back exactly.
pub fn from_csv(text: &str) -> std::result::Result<Vec<TrialResult>, String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line == CSV_HEADER || line.is_empty() {
            continue;
        }
        let bad = |what: &str| format!("line {}: {what}: {line}", n + 1);
        let mut cells = line.split(',');
        let trial = cells
            .next()
            .and_then(|c| c.parse().ok())
            .ok_or_else(|| bad("no trial index"))?;
        let v: Vec<f64> = cells
            .map(|c| c.parse().map_err(|_| bad("not a number")))
            .collect::<std::result::Result<_, _>>()?;
        if v.len() != 15 {
            return Err(bad("not 16 columns"));
        }
        out.push(TrialResult {
            draw: Draw {
                trial,
                spin_rad_s: [v[0], v[1], v[2]],
                tilt_deg: v[3],
                tilt_axis_deg: v[4],
                mass_error: [v[5], v[6]],
                inertia_error: [v[7], v[8]],
                length_error: [v[9], v[10]],
                pd_gain_factor: v[11],
            },
            landing_error_deg: [v[12], v[13], v[14]],
            replans: Vec::new(),
        });
    }
    Ok(out)
}

/// Contiguous trials of shard `k` of `n` (1-based).
pub fn shard_range(trials: usize, k: usize, n: usize) -> std::ops::Range<usize> {
    trials * (k - 1) / n..trials * k / n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diverged flight (NaN) fails, counts as 180 deg, and is counted
    /// apart, per controller, with a sentence that says so.
    #[test]
    fn diverged_flights_are_counted_apart() {
        let row = |k: usize, open: &str| format!("{k},0,0,0,0,0,0,0,0,0,0,0,1,{open},0.5,0.5");
        let csv = [row(0, "NaN"), row(1, "1"), row(2, "NaN")].join("\n");
        let s = summarise(&from_csv(&csv).unwrap(), 1, 10.0, 2);
        let open = &s.controllers[0];
        assert_eq!((open.diverged, open.successes), (2, 1));
        assert_eq!(open.landing_error_deg.max, 180.0);
        assert_eq!(
            (s.controllers[1].diverged, s.controllers[1].successes),
            (0, 3)
        );
        let note = crate::console::robustness::diverged(&s).unwrap();
        assert!(
            note.contains("open-loop 2") && !note.contains("tvlqr"),
            "{note}"
        );
        let none = summarise(&from_csv(&row(0, "1")).unwrap(), 1, 10.0, 2);
        assert_eq!(crate::console::robustness::diverged(&none), None);
    }

    /// Wilson's interval against its closed form at the ends and a textbook value.
    #[test]
    fn wilson_interval() {
        // n = 10, k = 10: [n / (n + z^2), 1]
        let z2 = 1.959_963_984_540_054f64.powi(2);
        let [lo, hi] = wilson(10, 10);
        assert!((lo - 10.0 / (10.0 + z2)).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12);
        let [lo, hi] = wilson(0, 10);
        assert!(lo.abs() < 1e-12 && (hi - z2 / (10.0 + z2)).abs() < 1e-12);
        // exactly at the ends, where the rate is (a JSON `ci95` of
        // [2.8e-17, ...] for no success read as a positive bound)
        for n in 1..200 {
            assert_eq!((wilson(0, n)[0], wilson(n, n)[1]), (0.0, 1.0), "{n}");
        }
        // 50 of 100: 0.4038 to 0.5962 (Wilson 1927; Newcombe 1998, table I)
        let [lo, hi] = wilson(50, 100);
        assert!((lo - 0.4038).abs() < 1e-4 && (hi - 0.5962).abs() < 1e-4);
    }

    /// What `--resume` relies on: a CSV's trials read back bit for bit,
    /// awkward numbers and a diverged (NaN) flight included.
    #[test]
    fn csv_rows_read_back_exactly() {
        let cfg = Config::load(std::path::Path::new("configs/seed.toml"), &[]).unwrap();
        let results: Vec<TrialResult> = (3..9)
            .map(|t| TrialResult {
                draw: Draw::new(&cfg, 7, t),
                landing_error_deg: [
                    0.1 + 0.2 * t as f64,
                    if t == 5 { f64::NAN } else { 1e-300 / 3.0 },
                    std::f64::consts::PI * t as f64,
                ],
                replans: Vec::new(),
            })
            .collect();
        for header in [true, false] {
            let csv = to_csv(&results, header);
            let back = from_csv(&csv).unwrap();
            assert_eq!(to_csv(&back, header), csv);
            for (a, b) in results.iter().zip(&back) {
                assert_eq!(a.draw.trial, b.draw.trial);
                assert_eq!(a.draw.tilt_deg.to_bits(), b.draw.tilt_deg.to_bits());
                for c in 0..3 {
                    let (x, y) = (a.landing_error_deg[c], b.landing_error_deg[c]);
                    assert!(x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()));
                }
            }
        }
        assert!(from_csv("3,1,2\n").unwrap_err().contains("16 columns"));
        // a negative zero (an error that rounds to it) is written unsigned
        let mut zero = results[0].clone();
        zero.landing_error_deg = [-0.0, 0.0, 1.0];
        let csv = to_csv(&[zero], false);
        assert!(
            !csv.contains("-0e0") && csv.contains(",0e0,0e0,1e0"),
            "{csv}"
        );
    }

    #[test]
    fn shards_tile_the_trials() {
        for n in [0, 1, 7, 1000] {
            for count in 1..6 {
                let mut next = 0;
                for k in 1..=count {
                    let r = shard_range(n, k, count);
                    assert_eq!(r.start, next);
                    next = r.end;
                }
                assert_eq!(next, n);
            }
        }
    }
}
