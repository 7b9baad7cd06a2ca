//! Recovery maps: from which starts can a body, its motors and its height
//! still land belly-down (MODEL.md section 6)?
//!
//! The starts lie on *lines*: a spin of growing magnitude about one axis
//! (in the rear half's y-z or x-z plane, at an angle from the spine `+z`),
//! or a tilt of growing angle about one horizontal world axis (in the world
//! y-z plane, at an angle from `+z`: 0 deg rolls about the spine, 90 deg
//! pitches end over end). Every line starts at the start at rest, whose
//! design is made once; along a line each free-form design continues from
//! its neighbour's ([`FreeDesign::warm`]), as a sweep's chunk does. A line
//! is the unit of work: lines run in parallel, `--shard K/N` computes a
//! contiguous run of whole lines, and each point's result is the same on
//! one machine or many.
//!
//! Along a line the magnitudes grow until the first start the design does
//! not land from; the larger ones are then judged by the open-loop schedule
//! alone (the design for the start at rest, replayed from that start): a
//! larger spin is taken to be no easier, which keeps the failing designs,
//! each costly (it runs to its iteration limit), to one a line. On a spin
//! line the largest recoverable spin is then bisected between the last
//! start that lands and the first that does not.

use crate::config::Config;
use crate::design::free::{FreeDesign, FreeResult};
use crate::design::plan::ShapePlan;
use crate::error::{Error, Result};
use crate::verdict::Status;
use crate::verify::ode::OdeSettings;
use crate::verify::simulate::SimReport;
use serde::{Deserialize, Serialize};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The grid of a map; every size has a range ([`Grid::validate`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// Axis angles per plane, evenly spaced over the full turn (`--axes`).
    pub axes: usize,
    /// Spin magnitudes per axis after zero, up to `max_spin` (`--spins`).
    pub spins: usize,
    /// Largest spin of the grid, rad/s (`--max-spin`).
    pub max_spin: f64,
    /// Tilt angles per axis after zero, up to `max_tilt_deg`; 0 maps no tilts (`--tilts`).
    pub tilts: usize,
    /// Largest tilt of the grid, degrees (`--max-tilt`).
    pub max_tilt_deg: f64,
    /// Bisection steps of the largest recoverable spin per axis (`--bisect`).
    pub bisect: usize,
    /// SCP iteration limit of each design of the map (`--max-iterations`):
    /// a start whose design has not landed by then counts as not landing.
    pub max_iterations: usize,
}

impl Default for Grid {
    fn default() -> Self {
        Grid {
            axes: 4,
            spins: 2,
            max_spin: 1.0,
            tilts: 2,
            max_tilt_deg: 30.0,
            bisect: 3,
            max_iterations: 40,
        }
    }
}

/// The range of each grid size: `(flag, lo, hi)`.
pub const RANGES: [(&str, f64, f64); 7] = [
    ("--axes", 1.0, 24.0),
    ("--spins", 1.0, 20.0),
    ("--max-spin", 0.0, crate::config::MAX_START_RATE),
    ("--tilts", 0.0, 20.0),
    ("--max-tilt", 0.0, 180.0),
    ("--bisect", 0.0, 12.0),
    ("--max-iterations", 5.0, 1000.0),
];

impl Grid {
    /// Refuses a size outside its range, naming the flag and the range.
    pub fn validate(&self) -> Result<()> {
        let values = [
            self.axes as f64,
            self.spins as f64,
            self.max_spin,
            self.tilts as f64,
            self.max_tilt_deg,
            self.bisect as f64,
            self.max_iterations as f64,
        ];
        for ((flag, lo, hi), v) in RANGES.iter().zip(values) {
            // the largest spin and tilt must be positive (a zero line is no line)
            let open = matches!(*flag, "--max-spin" | "--max-tilt");
            let ok = v.is_finite() && v <= *hi && if open { v > *lo } else { v >= *lo };
            if !ok {
                let (l, r) = if open { ("(", "]") } else { ("[", "]") };
                return Err(Error::Usage(format!(
                    "{flag} {v} is out of range: it must be in {l}{lo}, {hi}{r}; give a value inside it"
                )));
            }
        }
        Ok(())
    }

    /// The lines of the map, in order: spins in the y-z plane, spins in the
    /// x-z plane (without the spine axis, already in the y-z plane), tilts.
    pub fn lines(&self) -> Vec<Line> {
        let angle = |k: usize| 360.0 * k as f64 / self.axes as f64;
        let mut v: Vec<Line> = (0..self.axes)
            .map(|k| Line {
                family: Family::Spin,
                plane: Plane::Yz,
                axis_deg: angle(k),
            })
            .collect();
        v.extend(
            (0..self.axes)
                .map(angle)
                .filter(|a| a % 180.0 != 0.0)
                .map(|axis_deg| Line {
                    family: Family::Spin,
                    plane: Plane::Xz,
                    axis_deg,
                }),
        );
        if self.tilts > 0 {
            v.extend((0..self.axes).map(|k| Line {
                family: Family::Tilt,
                plane: Plane::Yz,
                axis_deg: angle(k),
            }));
        }
        v
    }

    /// The magnitudes along a line of `family`, zero first.
    pub fn magnitudes(&self, family: Family) -> Vec<f64> {
        let (n, max) = match family {
            Family::Spin => (self.spins, self.max_spin),
            Family::Tilt => (self.tilts, self.max_tilt_deg),
        };
        (0..=n)
            .map(|k| {
                if k == n {
                    max
                } else {
                    max * k as f64 / n as f64
                }
            })
            .collect()
    }
}

/// What a line varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// `start.angular_velocity`, rad/s about the rear half's axes.
    Spin,
    /// `start.rotation_deg`, degrees about the world axes.
    Tilt,
}

/// The plane an axis lies in: its angle is measured from `+z` towards `+y`
/// (`yz`) or `+x` (`xz`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Plane {
    Yz,
    Xz,
}

impl Plane {
    pub fn name(self) -> &'static str {
        match self {
            Plane::Yz => "yz",
            Plane::Xz => "xz",
        }
    }
}

/// One line of starts: a family about one axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Line {
    pub family: Family,
    pub plane: Plane,
    /// The axis's angle from `+z` in its plane, degrees.
    pub axis_deg: f64,
}

impl Line {
    /// The unit axis.
    pub fn axis(&self) -> [f64; 3] {
        let (s, c) = self.axis_deg.to_radians().sin_cos();
        // exact zeros on the coordinate axes (sin 180 deg is 1.2e-16)
        let clean = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
        match self.plane {
            Plane::Yz => [0.0, clean(s), clean(c)],
            Plane::Xz => [clean(s), 0.0, clean(c)],
        }
    }

    /// The config from `magnitude` along this line: `cfg` with its start replaced.
    pub fn config(&self, cfg: &Config, magnitude: f64, max_iterations: usize) -> Config {
        let mut c = cfg.clone();
        let v = self.axis().map(|a| a * magnitude);
        c.start = Default::default();
        match self.family {
            Family::Spin => c.start.angular_velocity = v,
            Family::Tilt => c.start.rotation_deg = v,
        }
        c.free.max_iterations = max_iterations;
        c
    }
}

/// How a start ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// The design from this start lands belly-down within the tolerance
    /// (and, with limited motors, inside their envelope).
    Lands,
    /// The design ends off the landing set (or outside the envelope).
    Misses,
    /// The design proved the start unlandable ("cannot land belly-down from
    /// this start"), or the optimiser failed from it.
    Unreachable,
    /// Beyond the first start along the line that does not land: not
    /// designed, judged by the open-loop schedule.
    Beyond,
}

impl Outcome {
    pub fn lands(self) -> bool {
        self == Outcome::Lands
    }

    pub fn name(self) -> &'static str {
        match self {
            Outcome::Lands => "lands",
            Outcome::Misses => "misses",
            Outcome::Unreachable => "unreachable",
            Outcome::Beyond => "beyond",
        }
    }
}

/// Where a point's landing error comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Source {
    /// The design from this start (its dynamic simulation).
    Design,
    /// The open-loop schedule: the design for the start at rest, replayed
    /// kinematically from this start.
    OpenLoop,
}

impl Source {
    pub fn name(self) -> &'static str {
        match self {
            Source::Design => "design",
            Source::OpenLoop => "open-loop",
        }
    }
}

/// One start of the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapPoint {
    pub family: Family,
    pub plane: Plane,
    pub axis_deg: f64,
    /// rad/s for a spin, degrees for a tilt.
    pub magnitude: f64,
    pub outcome: Outcome,
    /// The belly's angle from straight down at touchdown, deg: the design's
    /// when there is one, else the open-loop schedule's (`error_source`).
    pub landing_error_deg: f64,
    pub error_source: Source,
    /// The open-loop schedule's landing error from this start, deg (what
    /// today's schedule, made for the start at rest, leaves).
    pub open_loop_error_deg: f64,
    /// The design's solver status, when there is a design.
    pub design_status: Option<Status>,
    /// The design's dense peak torque, N m.
    pub peak_torque_nm: Option<f64>,
    /// With limited motors, for a designed start that does not land: the
    /// least drop height of a verified free-form time design from it, m.
    pub least_height_m: Option<f64>,
    pub note: Option<String>,
}

/// The largest recoverable spin about one axis at the configured height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bound {
    pub plane: Plane,
    pub axis_deg: f64,
    pub axis: [f64; 3],
    /// The largest spin found to land, rad/s (0 when none, not even at rest).
    pub largest_spin_rad_s: f64,
    /// The smallest spin found not to land, rad/s (`None`: every spin of
    /// the grid landed, the bound is at least `max_spin`).
    pub first_miss_rad_s: Option<f64>,
    /// Bisection steps taken.
    pub iterations: usize,
}

impl Bound {
    /// Whether every spin of the grid landed (the bound is a lower bound).
    pub fn at_least(&self) -> bool {
        self.first_miss_rad_s.is_none()
    }
}

/// One line's results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineResult {
    pub line: Line,
    pub points: Vec<MapPoint>,
    /// Spin lines only.
    pub bound: Option<Bound>,
}

/// `K/N` of the lines: contiguous runs of whole lines.
pub fn shard_lines(shard: crate::sweep::Shard, total: usize) -> std::ops::Range<usize> {
    total * (shard.index - 1) / shard.count..total * shard.index / shard.count
}

/// The landing tolerance, degrees: `land.max_tilt_deg`, by default
/// `simulate.flip_tolerance`, as the verdict judges a landing.
pub fn tolerance_deg(cfg: &Config) -> f64 {
    cfg.land
        .max_tilt_deg
        .unwrap_or(cfg.simulate.flip_tolerance.to_degrees())
}

/// What every line shares: the design from the start at rest and its schedule.
pub struct Origin {
    pub cfg: Config,
    pub grid: Grid,
    pub design: FreeResult,
}

impl Origin {
    /// Designs from the start at rest (`cfg` with its `[start]` cleared).
    pub fn new(cfg: &Config, grid: &Grid) -> Result<Origin> {
        grid.validate()?;
        let mut at_rest = cfg.clone();
        at_rest.start = Default::default();
        let spec = at_rest.design_spec();
        let start = crate::pipeline::free_start(&spec, |_| {})?;
        let design = start.free_design(&spec).solve();
        let design = crate::pipeline::short_of_answer(
            &spec,
            start.least_height_m,
            design,
            crate::pipeline::LEAST_HEIGHT_FROM_RUN,
        )?;
        Ok(Origin {
            cfg: at_rest,
            grid: grid.clone(),
            design,
        })
    }

    /// The open-loop schedule's landing error from the start of `cfg`, deg.
    fn open_loop_deg(&self, cfg: &Config) -> f64 {
        let cat = cfg.cat();
        crate::verify::simulate::kinematic_from(
            &cat,
            &self.design.plan as &dyn ShapePlan,
            &cfg.start.start(),
            &OdeSettings::default(),
        )
        .map(|mut r| {
            r.land(&cat, cfg.fall.margin);
            r.landing_error_deg
        })
        .unwrap_or(f64::NAN)
    }

    /// The point at `magnitude` along `line`, designed from `warm` (and the
    /// `before` it) unless `designed` is false; its design is returned for the next.
    fn point(
        &self,
        line: &Line,
        magnitude: f64,
        warm: &FreeResult,
        before: Option<&FreeResult>,
        designed: bool,
    ) -> (MapPoint, Option<FreeResult>) {
        let cfg = line.config(&self.cfg, magnitude, self.grid.max_iterations);
        let mut p = MapPoint {
            family: line.family,
            plane: line.plane,
            axis_deg: line.axis_deg,
            magnitude,
            outcome: Outcome::Beyond,
            landing_error_deg: f64::NAN,
            error_source: Source::OpenLoop,
            open_loop_error_deg: self.open_loop_deg(&cfg),
            design_status: None,
            peak_torque_nm: None,
            least_height_m: None,
            note: None,
        };
        if !designed {
            p.landing_error_deg = p.open_loop_error_deg;
            p.note = Some("beyond the first start along this axis that does not land".into());
            return (p, None);
        }
        let fr = if magnitude == 0.0 {
            Ok(self.design.clone())
        } else {
            FreeDesign::new(&cfg.design_spec())
                .warm(warm, before)
                .solve()
        };
        let mut flown = fr.and_then(|fr| flight(&cfg, &fr).map(|f| (fr, f)));
        if magnitude != 0.0 && !lands_the_short_way(&cfg, &flown) {
            // continued from its neighbour, the design keeps the neighbour's
            // way round: designed afresh it starts the nearer way
            // (`design::mirror`), and the better is kept
            let fresh = FreeDesign::new(&cfg.design_spec())
                .solve()
                .and_then(|fr| flight(&cfg, &fr).map(|f| (fr, f)));
            flown = better_flight(flown, fresh);
        }
        let kept = match flown {
            Ok((fr, (sim, landed))) => {
                p.outcome = if landed {
                    Outcome::Lands
                } else {
                    Outcome::Misses
                };
                p.landing_error_deg = sim.landing_error_deg;
                p.error_source = Source::Design;
                p.design_status = Some(fr.status.into());
                p.peak_torque_nm = Some(fr.peak_torque_nm);
                Some(fr)
            }
            Err(e) => {
                p.outcome = Outcome::Unreachable;
                p.landing_error_deg = p.open_loop_error_deg;
                p.note = Some(e.to_string());
                None
            }
        };
        if !p.outcome.lands() && cfg.motor().is_limited() {
            p.least_height_m = least_height(&cfg);
            if p.least_height_m.is_none() && p.note.is_none() {
                p.note = Some(
                    "no least drop height: no free-form time design from this start verified (landing within the motors) in any fall"
                        .into(),
                );
            }
        }
        (p, kept)
    }

    /// One line: its points, and on a spin line the bisected bound.
    pub fn line(&self, line: &Line) -> LineResult {
        let mut points = Vec::new();
        let mut warm = self.design.clone();
        let mut before: Option<FreeResult> = None;
        // the last start that landed (and its design) and the first that did not
        let mut landed: Option<(f64, FreeResult)> = None;
        let mut miss: Option<f64> = None;
        for m in self.grid.magnitudes(line.family) {
            let (p, fr) = self.point(line, m, &warm, before.as_ref(), miss.is_none());
            if miss.is_none() {
                if p.outcome.lands() {
                    let fr = fr.expect("a landing start has its design");
                    landed = Some((m, fr.clone()));
                    before = Some(std::mem::replace(&mut warm, fr));
                } else {
                    miss = Some(m);
                }
            }
            points.push(p);
        }
        let bound = (line.family == Family::Spin).then(|| self.bisect(line, landed, miss));
        LineResult {
            line: *line,
            points,
            bound,
        }
    }

    /// Bisects the largest recoverable spin between the last landing start
    /// and the first miss, each step continued from the last landing design.
    fn bisect(&self, line: &Line, landed: Option<(f64, FreeResult)>, miss: Option<f64>) -> Bound {
        let mut b = Bound {
            plane: line.plane,
            axis_deg: line.axis_deg,
            axis: line.axis(),
            largest_spin_rad_s: landed.as_ref().map_or(0.0, |l| l.0),
            first_miss_rad_s: miss,
            iterations: 0,
        };
        let (Some((mut lo, mut warm)), Some(mut hi)) = (landed, miss) else {
            return b;
        };
        for _ in 0..self.grid.bisect {
            let mid = 0.5 * (lo + hi);
            let cfg = line.config(&self.cfg, mid, self.grid.max_iterations);
            b.iterations += 1;
            match FreeDesign::new(&cfg.design_spec())
                .warm(&warm, None)
                .solve()
            {
                Ok(fr) if flight(&cfg, &fr).is_ok_and(|(_, landed)| landed) => {
                    lo = mid;
                    warm = fr;
                }
                _ => hi = mid,
            }
        }
        b.largest_spin_rad_s = lo;
        b.first_miss_rad_s = Some(hi);
        b
    }
}

/// A design and its flight ([`flight`]).
type Flown = Result<(FreeResult, (SimReport, bool))>;

/// Whether a flown design lands, turning at most half a turn about the
/// spine (one that went the long way round may have a shorter twin).
fn lands_the_short_way(cfg: &Config, flown: &Flown) -> bool {
    flown.as_ref().is_ok_and(|(fr, (_, landed))| {
        *landed && !crate::design::mirror::goes_the_long_way(&cfg.design_spec(), &fr.plan)
    })
}

/// The better of two flown designs of one start: one that lands over one
/// that does not, then the lower objective; a design over an error.
fn better_flight(a: Flown, b: Flown) -> Flown {
    // (landing first: `false` sorts before `true`)
    let key = |f: &Flown| {
        f.as_ref()
            .ok()
            .map(|(fr, (_, landed))| (!*landed, fr.objective_value))
    };
    match (key(&a), key(&b)) {
        (Some(ka), Some(kb)) if kb.0.cmp(&ka.0).then(kb.1.total_cmp(&ka.1)).is_lt() => b,
        (None, Some(_)) => b,
        _ => a,
    }
}

/// A design flown under the motor model, and whether it lands: inside the
/// motor envelope and within the landing tolerance in the simulation,
/// whether or not its SCP converged.
fn flight(cfg: &Config, fr: &FreeResult) -> Result<(SimReport, bool)> {
    let spec = cfg.design_spec();
    let sim = crate::verify::simulate::dynamic_spec(&spec, &fr.plan)?;
    // the flight decides, not the SCP's residual: a design that stopped at
    // the map's iteration limit and lands is a start that can be recovered
    let landed = sim.landing_error_deg <= tolerance_deg(cfg)
        && crate::design::least_height::flies(&spec, fr, &sim);
    Ok((sim, landed))
}

/// The least drop height from `cfg`'s start, m: the shortest verified
/// free-form `time` design inside the motor envelope (from the start at
/// rest the phased one counts too); `None` when none verifies.
fn least_height(cfg: &Config) -> Option<f64> {
    match crate::design::least_height::heights(
        &cfg.design_spec(),
        crate::design::least_height::Families::Both,
        |_| {},
    ) {
        Ok(Some(h)) if h.free.is_some() || cfg.start.is_default() => Some(h.answer.least_height_m),
        _ => None,
    }
}

/// Computes `lines` into `store` (one slot a line, filled as each ends),
/// `threads` lines at a time; `progress(done, total)` after each line.
pub fn compute_into(
    origin: &Origin,
    lines: &[Line],
    threads: usize,
    store: &Mutex<Vec<Option<LineResult>>>,
    progress: impl Fn(usize, usize) + Sync,
) {
    store.lock().unwrap().resize(lines.len(), None);
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..threads.max(1).min(lines.len()) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    if i >= lines.len() {
                        break;
                    }
                    let r = origin.line(&lines[i]);
                    store.lock().unwrap()[i] = Some(r);
                    progress(done.fetch_add(1, Ordering::SeqCst) + 1, lines.len());
                }
            });
        }
    });
}

/// The map of `cfg` over `grid`, its shard `shard` of the lines.
pub fn map(
    cfg: &Config,
    grid: &Grid,
    threads: usize,
    shard: crate::sweep::Shard,
) -> Result<Vec<LineResult>> {
    let origin = Origin::new(cfg, grid)?;
    let lines = grid.lines();
    let lines = &lines[shard_lines(shard, lines.len())];
    let store = Mutex::new(Vec::new());
    compute_into(&origin, lines, threads, &store, |_, _| {});
    Ok(store.into_inner().unwrap().into_iter().flatten().collect())
}

fn cell(x: Option<f64>) -> String {
    x.map(|v| format!("{v:.9e}")).unwrap_or_default()
}

/// The CSV header.
pub const CSV_HEADER: &str = "family,plane,axis_deg,axis_x,axis_y,axis_z,magnitude,outcome,landing_error_deg,error_source,open_loop_error_deg,design_status,peak_torque_nm,least_height_m,note\n";

/// The map's CSV: one row a start, lines in order, the header only with
/// `header` (the first shard), so that the shards' files concatenate into
/// the whole map's.
pub fn to_csv(lines: &[LineResult], header: bool) -> String {
    let mut s = if header {
        CSV_HEADER.to_string()
    } else {
        String::new()
    };
    for l in lines {
        let a = l.line.axis();
        for p in &l.points {
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                match p.family {
                    Family::Spin => "spin",
                    Family::Tilt => "tilt",
                },
                p.plane.name(),
                p.axis_deg,
                a[0],
                a[1],
                a[2],
                p.magnitude,
                p.outcome.name(),
                cell(Some(p.landing_error_deg)),
                p.error_source.name(),
                cell(Some(p.open_loop_error_deg)),
                p.design_status.map_or("", Status::name),
                cell(p.peak_torque_nm),
                cell(p.least_height_m),
                crate::output::csv_field(p.note.as_deref().unwrap_or(""))
            ));
        }
    }
    s
}

/// The index.html caption of a recovery figure, by file name.
pub fn caption(file: &str) -> Option<&'static str> {
    Some(match file {
        "recovery-spin.svg" => {
            "The largest spin at release from which the design still lands belly-down, about each axis of the map (its angle from the spine +z; a marker per plane of the rear half, y-z and x-z; nothing is known between the axes, so they are not joined): the marker is the largest spin found to land, the cross above it the smallest found to miss, bisected between them; where every spin of the grid landed, the bar is dashed upwards past the grid's largest spin (a lower bound: >= in the table)."
        }
        "recovery-landing-spin.svg" => {
            "Landing error (the belly's angle from straight down at touchdown) against the spin at release, a line per spin axis; each start's free-form design continues from its neighbour's, and past the first start it misses from, the open-loop schedule for the start at rest is replayed."
        }
        "recovery-landing-tilt.svg" => {
            "Landing error (the belly's angle from straight down at touchdown) against the tilt at release, a line per horizontal tilt axis (0 deg rolls about the spine, 90 deg pitches end over end); past the first tilt it misses from, the open-loop schedule for the start at rest is replayed."
        }
        _ => return None,
    })
}

/// The figures: the largest recoverable spin against its axis, one series a
/// plane, and the landing error against the magnitude, one series a line
/// (spins and tilts apart).
pub fn figures(lines: &[LineResult], grid: &Grid) -> Result<Vec<(String, String)>> {
    let mut figs = Vec::new();
    let bounds: Vec<&Bound> = lines.iter().filter_map(|l| l.bound.as_ref()).collect();
    if !bounds.is_empty() {
        // each axis once (one along the spine is listed in the yz plane)
        let series: Vec<(String, Vec<crate::report::Bracket>)> = [Plane::Yz, Plane::Xz]
            .iter()
            .map(|&plane| {
                let of: Vec<_> = bounds
                    .iter()
                    .filter(|b| b.plane == plane)
                    .map(|b| crate::report::Bracket {
                        x: b.axis_deg,
                        lo: b.largest_spin_rad_s,
                        hi: b.first_miss_rad_s,
                    })
                    .collect();
                (format!("axis in the {} plane", plane.name()), of)
            })
            .filter(|s| !s.1.is_empty())
            .collect();
        figs.push((
            "recovery-spin.svg".to_string(),
            crate::report::brackets(
                &format!(
                    "Largest recoverable spin about each axis (grid up to {} rad/s)",
                    grid.max_spin
                ),
                (
                    "axis angle from the spine +z (deg)",
                    "spin at release (rad/s)",
                ),
                &series,
                grid.max_spin,
                [
                    "the largest spin that landed",
                    "the smallest that missed",
                    "every spin tried landed",
                    "the grid's largest spin",
                ],
            )?,
        ));
    }
    for (family, file, unit) in [
        (Family::Spin, "recovery-landing-spin.svg", "spin (rad/s)"),
        (Family::Tilt, "recovery-landing-tilt.svg", "tilt (deg)"),
    ] {
        let of: Vec<&LineResult> = lines.iter().filter(|l| l.line.family == family).collect();
        if of.is_empty() {
            continue;
        }
        let x = grid.magnitudes(family);
        let series: Vec<(String, Vec<f64>)> = of
            .iter()
            .map(|l| {
                (
                    format!("{} {} deg", l.line.plane.name(), l.line.axis_deg),
                    l.points.iter().map(|p| p.landing_error_deg).collect(),
                )
            })
            .collect();
        figs.push((
            file.to_string(),
            // one style a release axis (the methods' four repeat past four)
            crate::report::lines_styled(
                &format!("Landing error against the {unit} at release, per axis"),
                unit,
                "landing error (deg)",
                &x,
                &series,
                |_, i| crate::report::distinct_style(i),
            )?,
        ));
    }
    Ok(figs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_sizes_are_refused_with_the_flag_and_range() {
        assert!(Grid::default().validate().is_ok());
        for (g, flag) in [
            (
                Grid {
                    axes: 0,
                    ..Default::default()
                },
                "--axes",
            ),
            (
                Grid {
                    max_spin: 0.0,
                    ..Default::default()
                },
                "--max-spin",
            ),
            (
                Grid {
                    max_spin: 51.0,
                    ..Default::default()
                },
                "--max-spin",
            ),
            (
                Grid {
                    bisect: 13,
                    ..Default::default()
                },
                "--bisect",
            ),
        ] {
            let e = g.validate().unwrap_err().to_string();
            assert!(e.contains(flag) && e.contains("out of range"), "{e}");
        }
    }

    #[test]
    fn the_lines_cover_both_planes_once_and_their_axes_are_unit() {
        let g = Grid {
            axes: 4,
            ..Default::default()
        };
        let lines = g.lines();
        // y-z: 0, 90, 180, 270; x-z: 90, 270 (the spine axes only once); tilts: 4
        assert_eq!(lines.len(), 10);
        for l in &lines {
            let a = l.axis();
            assert!(((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt() - 1.0).abs() < 1e-15);
        }
        assert_eq!(lines[2].axis(), [0.0, 0.0, -1.0]);
        let shards: Vec<_> = (1..=3)
            .map(|index| shard_lines(crate::sweep::Shard { index, count: 3 }, 10))
            .collect();
        assert_eq!((shards[0].start, shards[2].end), (0, 10));
        assert!(shards.windows(2).all(|w| w[0].end == w[1].start));
        assert_eq!(g.magnitudes(Family::Spin), [0.0, 0.5, 1.0]);
    }
}
