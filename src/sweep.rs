//! Parameter sweeps: any numeric config key over a range, every point
//! designed by each method.
//!
//! Continuation: the grid is cut into fixed chunks of [`CHUNK`] consecutive
//! points (a function of the grid only). Within a chunk the points run in
//! order and each free-form design starts from its neighbour's solution (in
//! the optimiser's dimensionless units, so a change of height or time is no
//! change at all, F3; a least-time design from its neighbour's schedule in
//! seconds, its answer); the first point of a chunk starts from its phased
//! design. The least heights inside a motor envelope continue the same way
//! (`HeightChain`): the chunk's first point is `run`'s answer, and in a
//! sweep of the motors or the fall a point keeps the last answer's design
//! where it flies there and is faster than its own (where the feasible set
//! grows, a chunk's least heights never rise). Chunks run
//! in parallel, and `--shard K/N` computes a contiguous
//! run of whole chunks, so every point's result is the same whether the
//! sweep runs on one machine or on many.

use crate::config::Config;
use crate::design::analytic::analytic_plan;
use crate::design::free::FreeResult;
use crate::design::least_height::{Families, Heights, Near, heights, heights_near};
use crate::design::phased::BendHint;
use crate::design::phased::least_height;
use crate::design::spec::DesignSpec;
use crate::error::{Error, Result, ValueKind};
use crate::verdict::{Simulated, Status};
use crate::verify::analyze::peak_along;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub mod resume;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `key=from:to:count`, e.g. `fall.height=0.5:10:40`.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSpec {
    pub key: String,
    pub from: f64,
    pub to: f64,
    pub count: usize,
}

impl std::str::FromStr for SweepSpec {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = |m: &str| Error::Range {
            arg: s.into(),
            message: format!("{m}; expected KEY=FROM:TO:COUNT, e.g. fall.height=0.5:10:40"),
        };
        let (key, range) = s.split_once('=').ok_or_else(|| bad("no `=`"))?;
        let parts: Vec<&str> = range.split(':').collect();
        if parts.len() != 3 {
            return Err(bad("the range needs three fields"));
        }
        let num = |x: &str| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| bad(&format!("`{x}` is not a number")))
        };
        let (from, to) = (num(parts[0])?, num(parts[1])?);
        let count: usize = parts[2]
            .trim()
            .parse()
            .map_err(|_| bad("COUNT must be a whole number of points, 1 or more"))?;
        if count < 1 || !from.is_finite() || !to.is_finite() || !(to - from).is_finite() {
            return Err(bad("COUNT must be at least 1 and the ends finite"));
        }
        if count == 1 && from != to {
            return Err(bad(&format!(
                "COUNT 1 computes FROM alone, not the range to {to}: give {from}:{from}:1 for one point, or a COUNT of 2 or more"
            )));
        }
        if count > 1 && from == to {
            return Err(bad(&format!(
                "FROM and TO are both {from}: the {count} points would be one point designed {count} times; give {from}:{from}:1, or another TO"
            )));
        }
        if count > MAX_POINTS {
            return Err(bad(&format!(
                "COUNT {count} is more than the {MAX_POINTS} points a sweep may have; split the range into several sweeps"
            )));
        }
        Ok(SweepSpec {
            key: key.trim().into(),
            from,
            to,
            count,
        })
    }
}

/// Most points a sweep may have: each point runs whole optimisations, so
/// more would take days; the bound also keeps the result table in memory.
pub const MAX_POINTS: usize = 10_000;

impl SweepSpec {
    /// The argument as the user would write it, for messages.
    pub fn arg(&self) -> String {
        format!("{}={}:{}:{}", self.key, self.from, self.to, self.count)
    }

    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.from];
        }
        // by a step: exact for whole ends and steps (`i / (count - 1)`
        // first made 0:22:23's 16th point 14.999999999999998); the last
        // point is TO itself
        let step = (self.to - self.from) / (self.count - 1) as f64;
        // the ends as typed; between them each point to 12 significant
        // digits, a rounding's distance, so that a decimal grid prints as
        // typed (0.17, not 0.16999999999999998) and crosses zero at 0; not
        // where that would merge neighbours (a step below 1e-10 of a point)
        let scale = self.from.abs().max(self.to.abs());
        (0..self.count)
            .map(|i| {
                if i == 0 {
                    return self.from;
                }
                if i == self.count - 1 {
                    return self.to;
                }
                let v = self.from + step * i as f64;
                if v.abs() <= 1e-12 * scale {
                    0.0
                } else if step.abs() > 1e-10 * v.abs() {
                    format!("{v:.11e}").parse().unwrap_or(v)
                } else {
                    v
                }
            })
            .collect()
    }
}

/// Which designs a sweep computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Methods {
    pub analytic: bool,
    pub phased: bool,
    pub free: bool,
    /// The peak columns: each method's least-peak design without the motor
    /// limits. Off (`--least-height-only`), a point computes its least
    /// heights alone where they are designed inside the motor envelope
    /// ([`designs_least_heights`]); under a stall torque alone they come
    /// from the phased and free-form peaks (F7), which are then computed.
    pub peaks: bool,
}

impl Methods {
    /// Every method, every column (the command line's default).
    pub const ALL: Methods = Methods {
        analytic: true,
        phased: true,
        free: true,
        peaks: true,
    };

    /// Why these columns cannot be computed on `configs` (the sweep's
    /// points, `arg` naming the sweep), before any work: least heights
    /// alone need a method that has them and a stall torque at every point.
    fn check(&self, arg: &str, configs: &[Result<Config>]) -> Result<()> {
        if self.peaks {
            return Ok(());
        }
        let usage = |m: String| Err(Error::Usage(format!("--least-height-only: {m}")));
        if !self.phased && !self.free {
            return usage(
                "only the phased and free-form designs have least heights, and --methods names neither; add phased or free to --methods".into(),
            );
        }
        let unlimited = configs
            .iter()
            .flatten()
            .filter(|c| c.limits.max_torque.is_none())
            .count();
        if unlimited > 0 {
            let which = if unlimited == configs.len() {
                "the config sets".to_string()
            } else {
                format!("{unlimited} of the {} points of {arg} set", configs.len())
            };
            return usage(format!(
                "{which} no stall torque (limits.max_torque), and a sweep's least drop heights are those of a stall torque; set limits.max_torque, or sweep without --least-height-only"
            ));
        }
        Ok(())
    }
}

/// One point of a sweep. Peaks are computed without the torque limit; with a
/// limit, the least drop height at which each design meets it (F7) is given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SweepPoint {
    pub value: f64,
    pub analytic_peak_nm: Option<f64>,
    pub phased_peak_nm: Option<f64>,
    pub free_peak_nm: Option<f64>,
    pub phased_bend_deg: Option<f64>,
    pub free_bend_deg: Option<f64>,
    pub least_height_phased_m: Option<f64>,
    pub least_height_free_m: Option<f64>,
    /// The free-form optimiser's end status (converged, iteration limit, ...).
    pub free_status: Option<Status>,
    pub error: Option<String>,
}

/// Points per continuation chunk (fixed, so results do not depend on the
/// number of threads or shards). Ten: a chunk's first point costs several
/// continued ones, so chunks are long, and a 40-point sweep splits into
/// four chunks, two per core on a 2-core machine (eight would leave one
/// core with three of five chunks; measured: docs/benchmarks.md, "Design
/// settings: the measurements behind them").
pub const CHUNK: usize = 10;

/// `K/N`: the K-th (1-based) of N disjoint slices of a sweep's grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Indices of the grid points of this shard: whole chunks, contiguous.
    pub fn points(&self, total: usize) -> std::ops::Range<usize> {
        let chunks = total.div_ceil(CHUNK);
        let (a, b) = (
            chunks * (self.index - 1) / self.count,
            chunks * self.index / self.count,
        );
        (a * CHUNK).min(total)..(b * CHUNK).min(total)
    }

    /// File-name suffix, `""` for the whole grid, else `.shard-K-of-N` with
    /// K zero-padded so that the shards' files sort in grid order.
    pub fn suffix(&self) -> String {
        if *self == Shard::ALL {
            return String::new();
        }
        let w = self.count.to_string().len();
        format!(".shard-{:0w$}-of-{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            Error::Usage(format!(
                "--shard {s}: expected K/N with 1 <= K <= N, e.g. 3/10 (the 3rd of 10 slices)"
            ))
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            k.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if index < 1 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// Keys that change only the fall (its duration), not the cat, the motors or
/// the design: the phased peak design is the same path at every value.
const FALL_ONLY: [&str; 3] = ["fall.height", "fall.gravity", "fall.margin"];

/// What one chunk carries from point to point (continuation): the last
/// two free-form designs when they are consecutive points (the start and
/// the secant predictor), the chunk's first phased design in a sweep of the
/// fall alone (F3 time scaling) and the chunk's solved phased bends, in
/// order (the bend search's hint).
#[derive(Default)]
struct Continuation {
    free: Neighbours,
    /// The last point's peak columns, taken by a point whose peak designs
    /// are the same problem.
    peaks: Option<PeakColumns>,
    /// `Some` in a sweep of the fall alone: the chunk's first phased design
    /// and its manoeuvre time, once computed.
    phased: Option<Option<(f64, crate::design::phased::PhasedResult)>>,
    bends: Vec<f64>,
    height: HeightChain,
}

/// A point's peak columns (its `SweepPoint`'s peaks, bends and free-form
/// status, and their `error` words), the free-form design it continues
/// from, and the problem they were designed for: the least-peak problem
/// without the motor limits, which a sweep of a motor limit leaves the
/// same at every point. A point whose problem equals it takes these
/// columns instead of designing them again (the same problem, the same
/// answer, to the bit; designed again from a neighbour's design, the same
/// problem moved the robot's free-form peak by up to 5e-4 of itself). A
/// point that takes them passes their free-form design on as its own.
struct PeakColumns {
    spec: DesignSpec,
    columns: SweepPoint,
    errors: Vec<String>,
    free: Option<FreeResult>,
}

/// The peak columns' problem, as [`PeakColumns`] compares it: `spec`
/// without its no-load speed, which draws no line without a stall torque
/// (the designs keep it: it sets the envelope program's units).
fn peak_problem(spec: &DesignSpec) -> DesignSpec {
    let mut p = spec.clone();
    if p.motor.max_torque.is_none() {
        p.motor.no_load_speed = None;
    }
    p
}

/// A chunk's last two free-form designs of consecutive points (the start
/// and the secant predictor): a failed point leaves the last good design
/// as the start, and no secant until two consecutive points have designs
/// again.
#[derive(Default)]
struct Neighbours {
    warm: Option<FreeResult>,
    before: Option<FreeResult>,
    /// Whether the point before produced a design (`warm`).
    last_ok: bool,
}

impl Neighbours {
    /// After a point: its design, if it produced one.
    fn advance(&mut self, fr: Option<FreeResult>) {
        let produced = fr.is_some();
        let last = fr.and_then(|fr| self.warm.replace(fr));
        self.before = last.filter(|_| self.last_ok);
        self.last_ok = produced;
    }

    /// A point whose config is invalid: no secant across it.
    fn skip(&mut self) {
        self.before = None;
        self.last_ok = false;
    }
}

/// What the least-height stage carries from point to point: its free-form
/// `time` designs and the phased `time` designs' bends of consecutive
/// points; in a sweep of `fall.height` the grid's first answer.
#[derive(Default)]
struct HeightChain {
    designs: Neighbours,
    /// The last answer's free-form design, kept (`keeps_best`) in a sweep
    /// of the motors, the bend limit or the fall (`limits.*`, `fall.*`: the
    /// same body, start and settings at every point), where the next point
    /// takes it when it flies there and is faster than its own.
    best: Option<FreeResult>,
    keeps_best: bool,
    bends: Vec<f64>,
    /// Every point's answer, in a sweep of `fall.height` from a start at
    /// rest: the least heights do not depend on it (the designs are made
    /// for a reference drop, [`reference`]), so every point has the answer
    /// at the whole grid's first point, which is `run`'s, made once before
    /// the chunks start ([`compute_into`]). (Its `answer.height_m` and
    /// `answer.possible` are that point's: a point reads the heights and the
    /// designs only.)
    ///
    /// [`reference`]: crate::design::least_height::reference
    same_answer: Option<Heights>,
}

impl HeightChain {
    /// The least heights at this point: continued from the chunk's last
    /// least-height design when there is one, else the cold stage (so the
    /// chunk's first point answers as `run` does).
    fn heights(&mut self, spec: &DesignSpec, families: Families) -> Result<Option<Heights>> {
        if let Some(h) = &self.same_answer {
            return Ok(Some(h.clone()));
        }
        let d = &self.designs;
        let best = self.best.as_ref();
        let near = match (&d.warm, families.free()) {
            (Some(prev), true) => heights_near(
                spec,
                prev,
                d.before.as_ref(),
                best,
                BendHint::from_chain(&self.bends),
                families,
            ),
            _ => heights(spec, families, |_| {}).map(|h| h.map(Near::cold)),
        };
        let (h, continued) = match near {
            Ok(Some(Near { heights, continued })) => (Ok(Some(heights)), continued),
            Ok(None) => (Ok(None), None),
            Err(e) => (Err(e), None),
        };
        // (a bend is known only where the phased design was made)
        match &h {
            Ok(Some(h)) if h.phased_bend.is_finite() => self.bends.push(h.phased_bend),
            _ => self.bends.clear(),
        }
        if let Ok(Some(Heights { free: Some(fr), .. })) = &h
            && self.keeps_best
        {
            self.best = Some(fr.clone());
        }
        self.designs.advance(continued);
        h
    }

    fn skip(&mut self) {
        self.designs.skip();
        self.bends.clear();
    }
}

impl Continuation {
    /// A chunk's continuation in a sweep of `key`.
    fn new(key: &str) -> Self {
        Continuation {
            phased: FALL_ONLY.contains(&key).then_some(None),
            height: HeightChain {
                keeps_best: key.starts_with("limits.") || key.starts_with("fall."),
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// The point at `value`, continued from the chunk's points before it.
    fn point(&mut self, cfg: &Config, value: f64, methods: Methods) -> SweepPoint {
        let (p, fr) = point(cfg, value, methods, self);
        self.free.advance(fr);
        p
    }

    /// A point whose config is invalid: the next scans its bend afresh.
    fn skip(&mut self) {
        self.bends.clear();
        self.free.skip();
        self.height.skip();
    }
}

/// One sweep point; `warm` is the last free-form design in the same chunk
/// (continuation) and `before` the one at the point before it, when both
/// points are consecutive (the secant predictor); `bends` the chunk's
/// solved phased bends so far, consecutive (the bend search's hint), to
/// which this point's is added. The point's own free-form design is
/// returned for the next.
fn point(
    cfg: &Config,
    value: f64,
    methods: Methods,
    chain: &mut Continuation,
) -> (SweepPoint, Option<FreeResult>) {
    let Continuation {
        free,
        peaks: last_peaks,
        phased: phased_warm,
        bends,
        height,
    } = chain;
    let (warm, before) = (free.warm.as_ref(), free.before.as_ref());
    let mut p = SweepPoint {
        value,
        ..Default::default()
    };
    let mut kept = None;
    let limit = cfg.limits.max_torque;
    let envelope = designs_least_heights(cfg);
    // the peaks are computed where asked, and where the least heights are theirs (F7)
    let peaks = methods.peaks || !envelope;
    let limited_cfg = cfg;
    let mut cfg = cfg.clone();
    // the peak columns are the least-peak designs without the torque and
    // speed limits (a speed limit left alone would leave them empty below
    // the least height); the limits enter through the least heights. The
    // no-load speed stays: without the stall torque it draws no line
    if cfg.limits.max_torque.take().is_some() {
        cfg.limits.max_speed = None;
    }
    let spec = cfg.design_spec();
    let t2 = cfg.available_time().powi(2);
    let problem = peak_problem(&spec);
    let same = last_peaks.as_ref().filter(|m| peaks && m.spec == problem);
    if methods.analytic && methods.peaks && same.is_none() {
        p.analytic_peak_nm = Some(
            peak_along(
                &spec,
                &analytic_plan(&spec),
                crate::verify::analyze::dense_samples(&spec),
            )
            .0,
        );
    }
    // a method that fails leaves its columns empty and its reason in `error`;
    // the other methods' numbers are kept
    let mut errors = Vec::new();
    if let Some(m) = same {
        let c = &m.columns;
        (p.analytic_peak_nm, p.phased_peak_nm, p.phased_bend_deg) =
            (c.analytic_peak_nm, c.phased_peak_nm, c.phased_bend_deg);
        (p.free_peak_nm, p.free_bend_deg, p.free_status) =
            (c.free_peak_nm, c.free_bend_deg, c.free_status);
        errors.clone_from(&m.errors);
        kept.clone_from(&m.free);
    } else if peaks && (methods.phased || methods.free) {
        // within a chunk the free-form design continues from its neighbour
        // and needs no phased seed
        let reuse = phased_warm
            .as_ref()
            .and_then(|w| w.as_ref())
            .filter(|_| !cfg.uses_envelope());
        let ph = if let Some((t_prev, prev)) = reuse {
            // a sweep of the fall alone (height, gravity, margin): the same
            // path, slowed down (F2, F3), so the neighbour's peak design
            // scales by (T_prev / T)^2 and flips the same
            let mut r = prev.clone();
            let k = (t_prev / cfg.available_time()).powi(2);
            r.peak_torque_nm *= k;
            r.socp_peak_torque_nm = r.socp_peak_torque_nm.map(|p| p * k);
            r.objective_value *= k;
            Ok(r)
        } else if methods.phased || warm.is_none() {
            // the chunk's previous bends predict this one's (continuation)
            let r =
                crate::design::phased::optimize_near(&spec, BendHint::from_chain(bends), |_| {});
            // only a solved design at the point just before predicts this
            // one: after a failure the next point scans afresh
            match &r {
                Ok(r) if r.status == crate::design::conic::SolveStatus::Solved => {
                    bends.push(r.bend_deg.to_radians())
                }
                _ => bends.clear(),
            }
            r
        } else {
            Err(Error::Unreachable {
                reason: "not computed".into(),
            })
        };
        if let (Ok(r), Some(slot)) = (&ph, phased_warm.as_mut())
            && slot.is_none()
        {
            *slot = Some((cfg.available_time(), r.clone()));
        }
        match &ph {
            Ok(ph) if methods.phased => {
                errors.extend(flagged(
                    "phased",
                    &spec,
                    ph.status.into(),
                    ph.peak_torque_nm,
                    ph.bend_deg,
                    &ph.plan,
                ));
                p.phased_peak_nm = Some(ph.peak_torque_nm);
                p.phased_bend_deg = Some(ph.bend_deg);
            }
            Err(e) if methods.phased => errors.push(format!("phased: {e}")),
            _ => {}
        }
        if methods.free {
            // seeded by the phased design, or by the analytic plan when that failed
            let afresh = || match &ph {
                Ok(ph) => crate::design::free::FreeDesign::new(&spec)
                    .from_plan(&ph.plan, "phased")
                    .solve(),
                Err(_) => crate::design::free::FreeDesign::new(&spec)
                    .from_plan(&analytic_plan(&spec), "analytic")
                    .solve(),
            };
            let fr = match warm {
                Some(w) => {
                    let continued = crate::design::free::FreeDesign::new(&spec)
                        .warm(w, before)
                        .solve();
                    // from another start the neighbour's way round may be
                    // the long one here, or miss: designed afresh too (the
                    // nearer way, `design::mirror`), the better kept
                    let short = continued
                        .as_ref()
                        .is_ok_and(|r| crate::design::free::lands_the_short_way(&spec, r));
                    if spec.is_default_start() || short {
                        continued
                    } else {
                        crate::design::free::better(&spec, continued, afresh())
                    }
                }
                None => afresh(),
            };
            match fr {
                Ok(fr) => {
                    errors.extend(flagged(
                        "free",
                        &spec,
                        fr.status.into(),
                        fr.peak_torque_nm,
                        fr.bend_deg,
                        &fr.plan,
                    ));
                    p.free_peak_nm = Some(fr.peak_torque_nm);
                    p.free_bend_deg = Some(fr.bend_deg);
                    p.free_status = Some(fr.status.into());
                    kept = Some(fr);
                }
                Err(e) => errors.push(format!("free: {e}")),
            }
        }
    }
    if peaks && same.is_none() {
        *last_peaks = Some(PeakColumns {
            spec: problem,
            columns: p.clone(),
            errors: errors.clone(),
            free: kept.clone(),
        });
    }
    // F7: under a stall torque alone the least height is the peak's
    if let Some(l) = limit.filter(|_| !envelope) {
        let f7 = |peak: f64| least_height(&spec, peak * t2, l);
        p.least_height_phased_m = p.phased_peak_nm.map(f7);
        p.least_height_free_m = p.free_peak_nm.map(f7);
    }
    if let Some(families) = height_families(limited_cfg, methods) {
        let limited = limited_cfg.design_spec();
        match height.heights(&limited, families) {
            Ok(Some(h)) => {
                if let (true, Some(e)) = (methods.phased, &h.phased_error) {
                    errors.push(format!("phased least height: {e}"));
                } else if methods.phased {
                    p.least_height_phased_m = Some(h.phased_m);
                    if !h.phased_verified {
                        errors.push(
                            "phased least height: its time design misses the flip in the simulation (the phased family's number, not a verified height)"
                                .into(),
                        );
                    }
                }
                if methods.free {
                    p.least_height_free_m = h
                        .free
                        .as_ref()
                        .map(|f| crate::design::envelope::height_for(&limited, f.manoeuvre_time_s));
                    if h.free.is_none() {
                        errors.push("free least height: no free-form time design verified".into());
                    }
                }
            }
            Ok(None) => {}
            Err(e) => errors.push(format!("least height: {e}")),
        }
    }
    if !errors.is_empty() {
        p.error = Some(errors.join("; "));
    }
    (p, kept)
}

/// Whether a point's least heights are designed: F7 (the least height
/// from the peak by time scaling) holds for a torque limit alone, and a
/// torque-speed line or a speed limit does not scale with the fall, so
/// there each least height is its family's `time` design inside the
/// envelope, as `run` finds it.
fn designs_least_heights(cfg: &Config) -> bool {
    cfg.limits.max_torque.is_some() && (cfg.motor().slope() > 0.0 || cfg.limits.max_speed.is_some())
}

/// The families whose least heights a point gives where they are designed
/// ([`designs_least_heights`]; without the phased column its design is
/// made only where no free-form design verifies).
fn height_families(cfg: &Config, methods: Methods) -> Option<Families> {
    Some(match (methods.phased, methods.free) {
        _ if !designs_least_heights(cfg) => return None,
        (true, true) => Families::Both,
        (true, false) => Families::Phased,
        (false, true) => Families::Free,
        (false, false) => return None,
    })
}

/// A kept design that misses a target (unconverged, flip missed, bend
/// limit broken) is named in the point's `error` column beside its numbers
/// ([`crate::pipeline::judge`], the flip from `plan` flown under the motor
/// model; a sweep's peaks are computed without the torque limit and
/// samples no schedule, so speed and envelope are not judged here). From
/// another start the phased design, made for the start at rest, is not
/// judged by its landing (`run` does not count that miss either).
fn flagged(
    method: &str,
    spec: &DesignSpec,
    status: Status,
    peak_torque_nm: f64,
    bend_deg: f64,
    plan: &dyn crate::design::plan::ShapePlan,
) -> Option<String> {
    let simulated = Simulated::of(crate::verify::simulate::dynamic_spec(spec, plan).as_ref());
    let mut v = crate::pipeline::judge(spec, status, (peak_torque_nm, bend_deg), None, &simulated);
    if method == "phased" && !spec.is_default_start() {
        v.misses
            .retain(|m| !matches!(m, crate::verdict::Miss::Landing { .. }));
    }
    let why = v.reasons();
    (!why.is_empty()).then(|| format!("{method} FLAGGED: {}", why.join(", ")))
}

/// Runs a sweep on the config at `path` (with `overrides`), `threads` chunks at a time.
pub fn sweep(
    path: &Path,
    overrides: &[String],
    spec: &SweepSpec,
    methods: Methods,
    threads: usize,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Vec<SweepPoint>> {
    SweepRun {
        path,
        overrides,
        spec,
        methods,
        threads,
        shard: Shard::ALL,
    }
    .points(progress)
}

/// One sweep's inputs: the config at `path` with `overrides`, the key and
/// its grid, the methods, the chunks computed at once, and the shard of
/// the grid it computes ([`Shard::points`]).
#[derive(Debug, Clone, Copy)]
pub struct SweepRun<'a> {
    pub path: &'a Path,
    pub overrides: &'a [String],
    pub spec: &'a SweepSpec,
    pub methods: Methods,
    pub threads: usize,
    pub shard: Shard,
}

impl SweepRun<'_> {
    /// The shard's points, in order.
    pub fn points(&self, progress: impl Fn(usize, usize) + Sync) -> Result<Vec<SweepPoint>> {
        let store = Mutex::new(Vec::new());
        self.into_store(&store, progress)?;
        Ok(store
            .into_inner()
            .unwrap()
            .into_iter()
            .map(|p| p.expect("every point ran"))
            .collect())
    }

    /// The shard's points into `store`, one slot a point, which the caller
    /// may read while it runs (an interrupted sweep publishes the points
    /// finished so far, [`crate::interrupt`]). Slots already filled (a
    /// resumed sweep, [`resume`]) are kept: a chunk whose every point is
    /// filled is skipped, a chunk filled in part is computed again from its
    /// start, so that each point has the same continuation as in an
    /// uninterrupted sweep.
    pub fn into_store(
        &self,
        store: &Mutex<Vec<Option<SweepPoint>>>,
        progress: impl Fn(usize, usize) + Sync,
    ) -> Result<()> {
        let SweepRun {
            path,
            overrides,
            spec,
            methods,
            threads,
            shard,
        } = *self;
        let all = spec.values();
        let range = shard.points(all.len());
        let values = &all[range.clone()];
        let load = |v: f64| {
            let mut ov = overrides.to_vec();
            ov.push(format!("{}={}", spec.key, v));
            Config::load(path, &ov)
        };
        // a key that takes whole numbers fails as a whole on a grid with
        // fractions (checked over the whole grid, so that every shard agrees)
        if let Some(v) = all.iter().find(|v| v.fract() != 0.0)
            && load(*v).is_err_and(|e| e.to_string().contains("expected a whole number"))
        {
            return Err(Error::Range {
                arg: spec.arg(),
                message: format!(
                    "{} takes whole numbers, and this grid has {v}: choose whole FROM and TO and a COUNT for which (TO - FROM) / (COUNT - 1) is whole",
                    spec.key
                ),
            });
        }
        let configs = checked_configs(&spec.key, &spec.arg(), "FROM and TO", &all, load)?;
        methods.check(&spec.arg(), &configs)?;
        let never = std::sync::atomic::AtomicBool::new(false);
        let grid = Grid {
            values,
            first: configs.first().and_then(|c| c.as_ref().ok()),
            configs: &configs[range],
            stop: &never,
        };
        compute_into(&spec.key, grid, methods, threads, store, progress)
    }
}

/// The configs at `values`, or the sweep's error before any work: a point
/// whose config is invalid (outside the key's range) fails the whole sweep,
/// over the whole grid so that every shard agrees; the error asks to choose
/// `what` (the range's `FROM and TO`, a caller's `the values`) inside it.
fn checked_configs(
    key: &str,
    arg: &str,
    what: &str,
    values: &[f64],
    load: impl Fn(f64) -> Result<Config>,
) -> Result<Vec<Result<Config>>> {
    let loaded: Vec<Result<Config>> = values.iter().map(|&v| load(v)).collect();
    // a key that takes no number: every point fails with the same kind
    let kinds: Vec<Option<ValueKind>> = loaded
        .iter()
        .map(|c| match c {
            Err(Error::Override { expects, .. }) => *expects,
            _ => None,
        })
        .collect();
    let takes = kinds
        .first()
        .copied()
        .flatten()
        .filter(|k| *k != ValueKind::Number && kinds.iter().all(|x| *x == Some(*k)));
    let configs: Vec<Result<Config>> = loaded
        .into_iter()
        .zip(values)
        .map(|(c, v)| {
            c.map_err(|e| Error::Range {
                arg: arg.into(),
                message: match e {
                    // the override is internal: name the point, not a `--set`
                    Error::Override { message, .. } => format!("at {key} = {v}: {message}"),
                    e => format!("at {key} = {v}: {e}"),
                },
            })
        })
        .collect();
    let bad = configs.iter().filter(|c| c.is_err()).count();
    if let Some(Err(first)) = configs.iter().find(|c| c.is_err()) {
        let message = match first {
            Error::Range { message, .. } => message.clone(),
            e => e.to_string(),
        };
        return Err(Error::Range {
            arg: arg.into(),
            message: if let Some(kind) = takes {
                format!(
                    "`{key}` takes {}, not a number: a sweep varies a numeric key ({message})",
                    kind.words()
                )
            } else if bad == configs.len() {
                format!("every point is invalid; {message}")
            } else {
                format!(
                    "{bad} of {} points {} invalid, the first {message}; choose {what} inside the key's range",
                    configs.len(),
                    if bad == 1 { "is" } else { "are" }
                )
            },
        });
    }
    Ok(configs)
}

/// The points of a sweep of `key` over `values` (any values, in order; the
/// chunks of [`CHUNK`] continue along them), `load` giving the config at a
/// value (messages name the sweep as `KEY=[v1, v2, ...]`): what a caller
/// with its own values (the Python package) calls. Once `stop` is set no
/// point starts; the points computed by then are returned (`None` for the
/// others).
pub fn sweep_values(
    key: &str,
    values: &[f64],
    load: impl Fn(f64) -> Result<Config>,
    methods: Methods,
    threads: usize,
    stop: &std::sync::atomic::AtomicBool,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Vec<Option<SweepPoint>>> {
    let arg = format!(
        "{key}=[{}]",
        values
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let configs = checked_configs(key, &arg, "the values", values, load)?;
    methods.check(&arg, &configs)?;
    let store = Mutex::new(Vec::new());
    let grid = Grid {
        values,
        configs: &configs,
        first: configs.first().and_then(|c| c.as_ref().ok()),
        stop,
    };
    compute_into(key, grid, methods, threads, &store, progress)?;
    Ok(store.into_inner().unwrap())
}

/// The points a sweep computes: their values and configs, and the flag after
/// which no point starts (a caller's stop; the CLI ends the process instead).
struct Grid<'a> {
    values: &'a [f64],
    configs: &'a [Result<Config>],
    /// The config at the whole grid's first point (every shard's): in a
    /// sweep of `fall.height` its least height is every point's.
    first: Option<&'a Config>,
    stop: &'a std::sync::atomic::AtomicBool,
}

/// Computes the grid's points into `store`, chunk by chunk; chunks whose
/// every slot is filled are skipped.
fn compute_into(
    key: &str,
    grid: Grid<'_>,
    methods: Methods,
    threads: usize,
    store: &Mutex<Vec<Option<SweepPoint>>>,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<()> {
    let Grid {
        values,
        configs,
        first,
        stop,
    } = grid;
    // shards start on chunk boundaries, so local chunks are global chunks
    let results = store;
    let chunks: Vec<std::ops::Range<usize>> = {
        let mut kept = results.lock().unwrap();
        kept.resize(values.len(), None);
        (0..values.len())
            .step_by(CHUNK)
            .map(|a| a..(a + CHUNK).min(values.len()))
            .filter(|c| kept[c.clone()].iter().any(|p| p.is_none()))
            .collect()
    };
    // in a sweep of `fall.height` from rest every point's least height is
    // the grid's first (the designs are made for a reference drop): made
    // once, not once a chunk
    let same_answer = first
        .filter(|_| key == "fall.height" && !chunks.is_empty())
        .and_then(|cfg| {
            let spec = cfg.design_spec();
            let families = height_families(cfg, methods).filter(|_| spec.is_default_start())?;
            heights(&spec, families, |_| {}).ok().flatten()
        });
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(values.len() - chunks.iter().map(|c| c.len()).sum::<usize>());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1).min(chunks.len()) {
            s.spawn(|| {
                loop {
                    let c = next.fetch_add(1, Ordering::SeqCst);
                    if c >= chunks.len() {
                        break;
                    }
                    let mut chain = Continuation::new(key);
                    if let Some(h) = &same_answer {
                        chain.height.same_answer = Some(h.clone());
                    }
                    for i in chunks[c].clone() {
                        if stop.load(Ordering::SeqCst) {
                            return;
                        }
                        let p = match &configs[i] {
                            Ok(cfg) => chain.point(cfg, values[i], methods),
                            Err(e) => {
                                chain.skip();
                                SweepPoint {
                                    value: values[i],
                                    error: Some(e.to_string()),
                                    ..Default::default()
                                }
                            }
                        };
                        results.lock().unwrap()[i] = Some(p);
                        progress(done.fetch_add(1, Ordering::SeqCst) + 1, values.len());
                    }
                }
            });
        }
    });
    Ok(())
}

fn cell(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.9e}")).unwrap_or_default()
}

/// CSV of a sweep: the swept value first.
pub fn to_csv(key: &str, points: &[SweepPoint]) -> String {
    let mut s = format!(
        "{key},analytic_peak_nm,phased_peak_nm,free_peak_nm,phased_bend_deg,free_bend_deg,least_height_phased_m,least_height_free_m,free_status,error\n"
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            p.value,
            cell(p.analytic_peak_nm),
            cell(p.phased_peak_nm),
            cell(p.free_peak_nm),
            cell(p.phased_bend_deg),
            cell(p.free_bend_deg),
            cell(p.least_height_phased_m),
            cell(p.least_height_free_m),
            p.free_status.map_or("", Status::name),
            crate::output::csv_field(p.error.as_deref().unwrap_or(""))
        ));
    }
    s
}

/// The least-height figure's line of the configured drop.
const FALL_HEIGHT_SERIES: &str = "fall.height (the drop asked)";

/// The motor limits of a sweep's config (its `[limits]` as JSON) in words,
/// for the least-height figure's title: every limit that bounds the answer
/// (a speed-limited robot's answer is its no-load speed's, not its stall
/// torque's), but the swept `key`, which the axis gives.
pub fn motor_words(limits: &serde_json::Value, key: &str) -> String {
    [
        ("max_torque", "stall torque", "N m"),
        ("no_load_speed", "no-load speed", "rad/s"),
        ("max_speed", "speed limit", "rad/s"),
    ]
    .iter()
    .filter(|(k, ..)| key.strip_prefix("limits.") != Some(k))
    .filter_map(|(k, what, unit)| Some(format!("{what} {} {unit}", limits[*k].as_f64()?)))
    .collect::<Vec<_>>()
    .join(", ")
}

/// The index.html caption of a sweep's figure, by file name.
pub fn caption(file: &str) -> Option<&'static str> {
    if !file.starts_with("sweep-") || !file.ends_with(".svg") {
        return None;
    }
    Some(if file.ends_with("-least-height.svg") {
        "The least drop height within the motor limits against the swept key: the phased and the free-form time designs' (the answer is the lower of the two that verify); a gap is a point without one. The grey dashed line is the configured drop (fall.height): where the answer is below it, the flip is possible."
    } else {
        "Each method's peak joint torque (in the configured norm) against the swept key, without the motor limits (with them, the least drop heights below say what the motors can do); a gap is a point where the method failed (its error is in the table)."
    })
}

/// Peak against the swept value, one line per method (no figure without a
/// peak: a sweep of the least heights alone, or every method failed); and,
/// with motor limits (`motor`, in words: [`motor_words`]), the least drop
/// height. `file_key` names the files, `key` labels the axes.
pub fn figures(
    file_key: &str,
    key: &str,
    points: &[SweepPoint],
    motor: Option<&str>,
    fall_height: f64,
) -> Result<Vec<(String, String)>> {
    let x: Vec<f64> = points.iter().map(|p| p.value).collect();
    let col = |f: &dyn Fn(&SweepPoint) -> Option<f64>| {
        points
            .iter()
            .map(|p| f(p).unwrap_or(f64::NAN))
            .collect::<Vec<_>>()
    };
    let mut series = Vec::new();
    for (name, f) in [
        (
            "analytic",
            &(|p: &SweepPoint| p.analytic_peak_nm) as &dyn Fn(&SweepPoint) -> Option<f64>,
        ),
        ("phased", &|p: &SweepPoint| p.phased_peak_nm),
        ("free", &|p: &SweepPoint| p.free_peak_nm),
    ] {
        let ys = col(f);
        if ys.iter().any(|y| y.is_finite()) {
            series.push((name.to_string(), ys));
        }
    }
    let xdesc = crate::config::key_label(key);
    let mut figs = Vec::new();
    if !series.is_empty() {
        figs.push((
            format!("sweep-{file_key}.svg"),
            crate::report::lines(
                &format!("Peak joint torque against {key}"),
                &xdesc,
                "peak torque (N m)",
                &x,
                &series,
            )?,
        ));
    }
    if let Some(motor) = motor {
        let mut hs = Vec::new();
        for (name, f) in [
            (
                "phased",
                &(|p: &SweepPoint| p.least_height_phased_m) as &dyn Fn(&SweepPoint) -> Option<f64>,
            ),
            ("free", &|p: &SweepPoint| p.least_height_free_m),
        ] {
            let ys = col(f);
            if ys.iter().any(|y| y.is_finite()) {
                hs.push((name.to_string(), ys));
            }
        }
        // the question's own height: below it the flip is possible (a sweep
        // of the height itself: the diagonal)
        let asked: Vec<f64> = if key == "fall.height" {
            x.clone()
        } else {
            vec![fall_height; x.len()]
        };
        hs.push((FALL_HEIGHT_SERIES.to_string(), asked));
        figs.push((
            format!("sweep-{file_key}-least-height.svg"),
            crate::report::lines_styled(
                &if motor.is_empty() {
                    format!("Least drop height within the motor limits against {key}")
                } else {
                    format!("Least drop height within the motor limits ({motor}) against {key}")
                },
                &xdesc,
                "least drop height (m)",
                &x,
                &hs,
                |name, i| {
                    if name == FALL_HEIGHT_SERIES {
                        crate::report::style_of("analytic", i)
                    } else {
                        crate::report::style_of(name, i)
                    }
                },
            )?,
        ));
    }
    Ok(figs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The least-height figure's title names each motor limit but the
    /// swept one.
    #[test]
    fn the_least_height_figures_title_names_every_motor_limit() {
        let limits = serde_json::json!({"max_torque": 1.4, "no_load_speed": 5.969});
        let words = motor_words(&limits, "cat.length");
        assert_eq!(words, "stall torque 1.4 N m, no-load speed 5.969 rad/s");
        assert_eq!(
            motor_words(
                &serde_json::json!({"max_torque": 2.0, "max_speed": 3.0}),
                "fall.height"
            ),
            "stall torque 2 N m, speed limit 3 rad/s"
        );
        // the swept limit is the axis's, not the config's one value
        assert_eq!(
            motor_words(&limits, "limits.no_load_speed"),
            "stall torque 1.4 N m"
        );
        let points = [SweepPoint {
            value: 0.2,
            least_height_free_m: Some(3.0),
            ..Default::default()
        }];
        let figs = figures("k", "cat.length", &points, Some(&words), 2.0).unwrap();
        let svg = least_height_svg(&figs).expect("a least-height figure");
        assert!(
            svg.contains(
                "Least drop height within the motor limits (stall torque 1.4 N m, no-load speed 5.969 rad/s)"
            ),
            "{svg}"
        );
    }

    /// The least-height figure draws the question's height: a level line
    /// at the configured drop, the diagonal in a sweep of the drop itself;
    /// without a motor limit there is no such figure.
    #[test]
    fn the_least_height_figure_draws_the_questions_height() {
        let points: Vec<SweepPoint> = [2.0, 3.0, 4.0]
            .iter()
            .map(|&v| SweepPoint {
                value: v,
                least_height_free_m: Some(3.0),
                ..Default::default()
            })
            .collect();
        // the level line's y in pixels equals across the points; the diagonal's rises
        let line_ys = |key: &str| -> Vec<f64> {
            let figs = figures("k", key, &points, Some("stall torque 1.4 N m"), 2.5).unwrap();
            let svg = least_height_svg(&figs).expect("a least-height figure");
            assert!(svg.contains(FALL_HEIGHT_SERIES), "{key}");
            // the line's dashes, in its style's colour (the legend's sample last)
            let colour = format!(
                "stroke=\"#{:02X}{:02X}{:02X}\" stroke-width=\"2\"",
                crate::report::style_of("analytic", 0).color.0,
                crate::report::style_of("analytic", 0).color.1,
                crate::report::style_of("analytic", 0).color.2
            );
            svg.split("<polyline")
                .filter(|p| p.contains(&colour))
                .flat_map(|p| {
                    let pts = p
                        .split("points=\"")
                        .nth(1)
                        .unwrap()
                        .split('"')
                        .next()
                        .unwrap();
                    pts.split_whitespace()
                        .map(|p| p.split(',').nth(1).unwrap().parse::<f64>().unwrap())
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        let level = line_ys("cat.length");
        assert!(level.len() > 4, "the line is drawn: {level:?}");
        let mut ys = level.clone();
        ys.dedup();
        assert!(ys.len() <= 2, "a level line and its legend sample: {ys:?}");
        let diagonal = line_ys("fall.height");
        let (lo, hi) = diagonal
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(*y), b.max(*y)));
        assert!(hi - lo > 100.0, "the diagonal spans the plot: {diagonal:?}");
        assert!(
            least_height_svg(&figures("k", "cat.length", &points, None, 2.5).unwrap()).is_none()
        );
    }

    /// `figures`' least-height figure, by its file name.
    fn least_height_svg(figs: &[(String, String)]) -> Option<&str> {
        figs.iter()
            .find(|(name, _)| name.ends_with("-least-height.svg"))
            .map(|(_, svg)| svg.as_str())
    }

    /// A sweep of the least heights alone draws no empty peak figure; a
    /// point with a peak draws it.
    #[test]
    fn the_peak_figure_is_drawn_where_a_point_has_a_peak() {
        let names = |points: &[SweepPoint]| -> Vec<String> {
            figures("k", "cat.length", points, Some("stall torque 1.4 N m"), 2.5)
                .unwrap()
                .into_iter()
                .map(|(name, _)| name)
                .collect()
        };
        let mut points = vec![
            SweepPoint {
                value: 0.2,
                least_height_free_m: Some(3.0),
                ..Default::default()
            };
            2
        ];
        assert_eq!(names(&points), ["sweep-k-least-height.svg"]);
        points[1].free_peak_nm = Some(0.5);
        assert_eq!(names(&points), ["sweep-k.svg", "sweep-k-least-height.svg"]);
    }

    /// A point's error sentence holds commas, quotes and a line break: the
    /// row still has the header's columns, and the sentence reads back whole.
    #[test]
    fn an_error_with_commas_stays_one_csv_field() {
        let error = "phased: needs 1,000 m; free: \"stalled\", then\nfailed";
        let points = [
            SweepPoint {
                value: 0.2,
                free_peak_nm: Some(0.5),
                error: Some(error.into()),
                ..Default::default()
            },
            SweepPoint {
                value: 0.3,
                ..Default::default()
            },
        ];
        let records = crate::test_support::csv_records(&to_csv("cat.length", &points));
        assert_eq!(records.len(), 3, "{records:?}");
        assert!(
            records.iter().all(|r| r.len() == records[0].len()),
            "{records:?}"
        );
        assert_eq!(records[1][0], "0.2");
        assert_eq!(records[1].last().unwrap(), error);
        assert_eq!(records[2].last().unwrap(), "");
    }
}
