//! The robot builder's question: with this body and these motors, can it
//! right itself from the configured height, and if not, from what height?
//!
//! The least drop height is the `time` design inside the motor envelope:
//! `h_min = g (T_min + margin)^2 / 2` (F7 when only the torque is limited).

use crate::design::free::{self, FreeResult};
use crate::design::objective::Objective;
use crate::design::phased::BendHint;
use crate::design::plan::Schedule;
use crate::design::scp::ScpIteration;
use crate::design::spec::DesignSpec;
use crate::error::Result;
use crate::model::motor::Motor;
use crate::verdict::{DesignNumbers, Simulated, Status, Targets, verdict};
use crate::verify::simulate::SimReport;
use serde::Serialize;

/// The answer, and the schedule that achieves the least height.
#[derive(Debug, Clone, Serialize)]
pub struct HeightAnswer {
    /// Whether the flip fits in the fall from `fall.height`.
    pub possible: bool,
    /// The configured drop height, m.
    pub height_m: f64,
    /// The least drop height found for the motors, m: the better of the
    /// phased and free-form `time` designs (an upper bound on the true least
    /// height).
    pub least_height_m: f64,
    /// The shortest manoeuvre inside the motor envelope, s.
    pub least_time_s: f64,
    /// Which design settles the answer: the one with the least height
    /// (`phased` or `free`), or `free` when a verified free-form schedule
    /// fits although no phased one does.
    pub method: &'static str,
    /// The status of that design's solver (`solved`, `converged`, or e.g.
    /// `iteration-limit` for a verified free-form schedule that is not
    /// proven the shortest).
    pub status: Status,
    /// A lower bound on the least drop height, m: the least time found
    /// with the stall torque alone ([`stall_only`], a local optimum, so an
    /// estimate; absent without a torque limit, before the free-form
    /// designs, from a start with momentum, where its time scaling does not
    /// hold, and where it is not below the answer).
    pub least_height_lower_bound_m: Option<f64>,
    /// Flip error of the least-height schedule in the motor-model simulation, rad.
    pub flip_error_rad: f64,
    /// Whether that schedule flips in the simulation within
    /// `simulate.flip_tolerance` (a free-form design: also lands from
    /// another start, as [`verified`] checks). A phased design that
    /// fits the motors but misses the flip (its grid too coarse for many
    /// twist turns under a tight bend limit) answers nothing: `possible` is
    /// then false and the sentence says no verified design was found.
    pub verified: bool,
    /// Whether the answer is a design from the configured start (always at
    /// the default start). From another start only a free-form design that
    /// lands answers; without one the numbers are the start at rest's and
    /// `possible` is false.
    pub from_start: bool,
    /// Whether the shortest manoeuvre found needs a fall longer than any
    /// catflip designs ([`crate::config::ranges::MAX_FALL_TIME_S`]): the
    /// flip is then not possible from any height catflip answers for, and
    /// there is no schedule (its simulations and simulator controls would
    /// grow with that fall).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub beyond_longest_fall: bool,
    /// The least-height schedule.
    #[serde(skip)]
    pub schedule: Schedule,
    /// The `[limits]` keys `catflip size` needs that the motor lacks (a DC
    /// motor's stall torque and no-load speed), `None` when it has both.
    #[serde(skip)]
    pub size_needs: Option<&'static str>,
    /// Under a stall torque alone, at rest: the stall torque that would do
    /// it from `height_m`, N m (F7: the least-height schedule stretched to
    /// that fall needs `T (T_min / T_H)^2`), which `catflip size` cannot give
    /// without a torque-speed line.
    #[serde(skip)]
    pub torque_alone_for_height_nm: Option<f64>,
}

/// Answers the question when the motors are limited (`None` otherwise: an
/// unlimited motor flips the cat from any height), with the phased `time`
/// design made for the [`reference`](fn@reference) drop.
pub fn answer(spec: &DesignSpec) -> Result<Option<HeightAnswer>> {
    if !spec.motor.is_limited() {
        return Ok(None);
    }
    if let Some(far) = beyond_any_fall(spec) {
        return Ok(Some(far));
    }
    answer_for(spec, &reference(spec), None).map(|(a, _)| Some(a))
}

/// How far past the longest fall the analytic schedule's least time under
/// the motors may be before no design is tried: the seed's analytic
/// schedule needs 65 times the free-form design's peak torque under a
/// stall torque alone, 8 times its time (F7); the robot's 0.94 s against
/// 0.74 s.
const FAR: f64 = 20.0;

/// The answer without a design when even a [`FAR`]th of the analytic
/// schedule's least time under the motors ([`reference_time`]) needs a fall
/// longer than catflip designs: a design made for such a fall would only
/// show what the answer already says, at the cost of simulating it (a
/// 1e-9 N m motor: a 37,000 s manoeuvre, 25 s of designs and a report that
/// ran out of memory).
pub fn beyond_any_fall(spec: &DesignSpec) -> Option<HeightAnswer> {
    if !spec.motor.is_limited() {
        return None;
    }
    let t = reference_time(spec)?;
    crate::config::ranges::beyond_longest_fall(t / FAR + spec.fall.margin).then(|| HeightAnswer {
        least_height_m: crate::design::envelope::height_for(spec, t),
        least_time_s: t,
        method: "analytic",
        status: Status::ClosedForm,
        from_start: true,
        beyond_longest_fall: true,
        ..HeightAnswer::blank(spec)
    })
}

/// The `[limits]` keys of a DC motor that `catflip size` needs and `spec`'s
/// `motor` lacks ([`HeightAnswer::size_needs`]).
fn size_needs(motor: &Motor) -> Option<&'static str> {
    match (motor.max_torque, motor.no_load_speed) {
        (Some(_), Some(_)) => None,
        (Some(_), None) => Some("no-load speed (limits.no_load_speed)"),
        (None, Some(_)) => Some("stall torque (limits.max_torque)"),
        (None, None) => {
            Some("stall torque and no-load speed (limits.max_torque, limits.no_load_speed)")
        }
    }
}

/// [`answer`] with the phased `time` design made for `reference`, its bend
/// search started at `hint` when given; and that design's bend, rad.
fn answer_for(
    spec: &DesignSpec,
    reference: &DesignSpec,
    hint: Option<BendHint>,
) -> Result<(HeightAnswer, f64)> {
    let r = crate::design::phased::optimize_near(reference, hint, |_| {})?;
    let sim = crate::verify::simulate::dynamic_spec(reference, &r.plan)?;
    let least = crate::design::envelope::height_for(spec, r.manoeuvre_time_s);
    let verified = crate::verdict::flip_misses(
        sim.flip_error_rad,
        sim.tilt_deg,
        spec.simulate.flip_tolerance,
    )
    .is_empty();
    let mut answer = HeightAnswer {
        possible: verified && fits(spec, least),
        verified,
        height_m: spec.fall.height,
        least_height_m: least,
        least_time_s: r.manoeuvre_time_s,
        method: "phased",
        status: r.status.into(),
        least_height_lower_bound_m: None,
        flip_error_rad: sim.flip_error_rad,
        from_start: spec.is_default_start(),
        beyond_longest_fall: false,
        schedule: Schedule::sample(&spec.cat, &r.plan, spec.simulate.samples_per_phase),
        size_needs: size_needs(&spec.motor),
        torque_alone_for_height_nm: None,
    };
    answer.bound(spec);
    answer.torque_alone(spec);
    Ok((answer, r.bend_deg.to_radians()))
}

/// Whether a drop from `height` is within the configured one (to rounding).
pub fn fits(spec: &DesignSpec, height: f64) -> bool {
    height <= spec.fall.height * (1.0 + crate::verdict::tolerance::HEIGHT)
}

/// The least drop heights of both design families, each from its `time`
/// design inside the motor envelope.
#[derive(Clone)]
pub struct Heights {
    /// The better of the two (see [`HeightAnswer::improve_with`]).
    pub answer: HeightAnswer,
    /// The phased time design's least height, m, and its bend, rad.
    pub phased_m: f64,
    pub phased_bend: f64,
    /// Whether that phased design flips in the simulation (see
    /// [`HeightAnswer::verified`]): otherwise `phased_m` is the phased
    /// family's number, not a height it is shown to flip from.
    pub phased_verified: bool,
    /// The shortest free-form time design that verifies ([`verified`]).
    pub free: Option<FreeResult>,
    /// Why the phased time design failed where a free-form design answers
    /// instead (`phased_m` is then NaN): a failure of one family keeps the
    /// other's answer.
    pub phased_error: Option<String>,
}

/// The question's own height must not steer the answer: every design of
/// the least height is made for this config with `fall.height` replaced by
/// a reference drop that depends on the body and the motors alone (the
/// analytic schedule's least time under the limits, F3/F7, rounded to three
/// digits so that the reference is the same to the last bit from any
/// height), with the `time` objective.
///
/// From a start with angular momentum the body turns all through the fall,
/// so the fall itself is part of the question: there the reference is the
/// config's own drop.
pub fn reference(spec: &DesignSpec) -> DesignSpec {
    let Some(least) = reference_time(spec) else {
        return spec.with_objective(Objective::Time);
    };
    // (a design for a fall catflip does not design would be simulated over it)
    let longest = crate::config::ranges::MAX_FALL_TIME_S - spec.fall.margin;
    let least = if least > longest {
        round_down_to_digits(longest, 3)
    } else {
        least
    };
    spec.with_height(0.5 * spec.fall.gravity * (least + spec.fall.margin).powi(2))
        .with_objective(Objective::Time)
}

/// The reference drop's manoeuvre time, s ([`reference`](fn@reference)); `None` from a
/// start with momentum, where the reference is the config's own drop.
fn reference_time(spec: &DesignSpec) -> Option<f64> {
    if !spec.is_default_start() {
        return None;
    }
    let plan = crate::design::analytic::analytic_plan(spec);
    let t0 = spec.available_time();
    let motor = spec.motor;
    // the torque alone when there is one: a start that is too fast for the
    // line (the SCP slows it down) found the shorter manoeuvres; with the
    // no-load speed in the reference every start ended in a slower one
    // (measured: docs/benchmarks.md, "Design settings: the measurements
    // behind them")
    // the analytic plan slowed until its top speed is the motor's
    let speed = motor
        .max_speed
        .into_iter()
        .chain(motor.no_load_speed)
        .reduce(f64::min)
        .map(|w| t0 * crate::design::envelope::usage_of(spec, &plan).max_speed_rad_s / w);
    let least = match (motor.max_torque, speed) {
        (Some(t), speed) => {
            let dense = crate::verify::analyze::dense_samples(spec);
            let (peak, _) = crate::verify::analyze::peak_along(spec, &plan, dense);
            // a strong motor's torque time alone is far too fast for its
            // speed: every start from so short a reference drop failed
            // (measured: docs/benchmarks.md, "Design settings: the
            // measurements behind them")
            (t0 * (peak / t).sqrt()).max(SPEED_FLOOR * speed.unwrap_or(0.0))
        }
        (None, Some(s)) => s,
        (None, None) => t0,
    };
    Some(round_to_digits(least.max(1e-3), 3))
}

/// The least reference manoeuvre as a fraction of the analytic plan's time
/// at the motor's top speed: the robots' answers are 0.19 (servo robot) and
/// 0.27 (box robot) of that time, their torque times 0.16 and 0.14.
const SPEED_FLOOR: f64 = 0.1;

/// `x` rounded to `digits` significant digits.
fn round_to_digits(x: f64, digits: i32) -> f64 {
    let e = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * e).round() / e
}

/// `x` (positive) rounded down to `digits` significant digits.
fn round_down_to_digits(x: f64, digits: i32) -> f64 {
    let e = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * e).floor() / e
}

/// The least time with the stall torque alone (no torque-speed line, no
/// speed limit), s, and its design: the free-form peak-torque design at the
/// reference drop, time-scaled until its peak is the stall torque (F3, F7:
/// exact for a torque bound alone): the least time of a motor that never
/// gives more than its stall torque. The torque-speed line takes torque
/// from a motor that is speeding up but gives more while braking
/// (`T + k |w|`), and a joint can outrun the no-load speed through the
/// other's reaction, so under the line this is a bound only for designs
/// that stay within the stall torque (the robot's answer brakes with 1.69 N m
/// against 1.4; it is 7 times this time); the design is a local optimum,
/// the bound the best one found. Its torque is continuous (`free.torque_jumps` off): it
/// seeds the time design, whose grid is continuous (seeded by a design with
/// steps, the time design ended higher and slower on the box robot).
pub fn stall_only(reference: &DesignSpec) -> Result<Option<(f64, FreeResult)>> {
    stall_only_on(reference, reference.free.nodes)
}

/// [`stall_only`] on a mesh of `nodes` per phase.
fn stall_only_on(reference: &DesignSpec, nodes: usize) -> Result<Option<(f64, FreeResult)>> {
    let Some(stall) = reference.motor.max_torque else {
        return Ok(None);
    };
    let peak = reference
        .with_objective(Objective::PeakTorque)
        .with_motor(Motor::unlimited(reference.motor.norm))
        .without_torque_jumps();
    let plan = crate::design::analytic::analytic_plan(&peak);
    let r = free::FreeDesign::new(&peak)
        .from_plan(&plan, "analytic")
        .nodes(nodes)
        .solve()?;
    let least = r.manoeuvre_time_s * (r.peak_torque_nm / stall).sqrt();
    Ok(Some((least, r)))
}

/// A plan's durations multiplied by `k` (the same path, F3).
fn stretched(
    plan: &crate::design::collocation_plan::CollocationPlan,
    k: f64,
) -> crate::design::collocation_plan::CollocationPlan {
    let mut p = plan.clone();
    for i in 0..p.tr.phases {
        let d = p.tr.duration(i);
        p.z[d] *= k;
    }
    p
}

/// Nodes per phase of the stall-only design that starts [`heights`]'s
/// chain and gives its bound: it only starts the envelope's coarse mesh
/// (half the design's nodes), which it reaches in a third of the time of
/// a design on the full mesh (the full mesh where this one fails).
const STALL_ONLY_NODES: usize = 20;

/// Which design families answer the least height ([`heights`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Families {
    /// The phased `time` design alone.
    Phased,
    /// The free-form `time` designs; the phased design only when none of
    /// them verifies (a sweep without the phased column: its least height
    /// is the free-form design's whichever answers).
    Free,
    /// Both: the answer is the better one.
    Both,
}

impl Families {
    /// Whether the phased design is made whatever the free-form ones do.
    pub fn phased(self) -> bool {
        self != Families::Free
    }

    /// Whether the free-form designs are made.
    pub fn free(self) -> bool {
        self != Families::Phased
    }
}

/// [`answer`], improved by the free-form time designs from two starts, both
/// made for the [`reference`](fn@reference) drop so that neither depends on
/// `fall.height`: the stall-only design ([`stall_only`], on [`STALL_ONLY_NODES`]) at the stall-only
/// least time (too fast for the line: the SCP slows it down), and the
/// analytic plan. Both are solved on the coarse mesh and the better one
/// finished ([`finished`]). Two other starts, the phased time design and
/// the stall-only design slowed into the envelope, were tried and ended in
/// slower designs (measured: docs/benchmarks.md, "Design settings: the
/// measurements behind them").
/// `observe` sees the stall-only start's coarse iterations, then the fine
/// iterations of the start finished first. The stall-only least time is the
/// answer's lower bound where the motor has a torque-speed line or a speed
/// limit (under its stall torque alone it is the answer's own problem, and
/// bounds nothing). `families` says which designs are made.
pub fn heights(
    spec: &DesignSpec,
    families: Families,
    mut observe: impl FnMut(&ScpIteration),
) -> Result<Option<Heights>> {
    if !spec.motor.is_limited() {
        return Ok(None);
    }
    if let Some(answer) = beyond_any_fall(spec) {
        return Ok(Some(Heights {
            phased_m: answer.least_height_m,
            phased_bend: f64::NAN,
            phased_verified: false,
            answer,
            free: None,
            phased_error: None,
        }));
    }
    let reference = reference(spec);
    if !families.free() {
        let (answer, phased_bend) = answer_for(spec, &reference, None)?;
        return Ok(Some(Heights {
            phased_m: answer.least_height_m,
            phased_bend,
            phased_verified: answer.verified,
            answer,
            free: None,
            phased_error: None,
        }));
    }
    let analytic_plan = crate::design::analytic::analytic_plan(&reference);
    // two threads: the analytic start's coarse mesh then the phased design
    // on one, the stall-only chain and the finish on this one
    let (phased, bound, candidates) = std::thread::scope(|s| {
        let (sent, received) = std::sync::mpsc::channel();
        let (reference, analytic_plan) = (&reference, &analytic_plan);
        let other = s.spawn(move || {
            let staged = free::FreeDesign::new(reference)
                .from_plan(analytic_plan, "analytic")
                .coarse_stage();
            // (the receiver waits for it: it is never gone before this)
            let _ = sent.send(staged);
            families.phased().then(|| answer_for(spec, reference, None))
        });
        let coarse = STALL_ONLY_NODES.min(reference.free.nodes);
        let stall = stall_only_on(reference, coarse).or_else(|_| stall_only(reference));
        let (bound, from_stall) = match stall {
            Ok(Some((least, sr))) => {
                let plan = stretched(&sr.plan, least / sr.manoeuvre_time_s);
                let staged = free::FreeDesign::new(reference)
                    .from_plan(&plan, "stall-only")
                    .on_iteration(&mut observe)
                    .coarse_stage();
                (Some(least), Some(staged))
            }
            _ => (None, None),
        };
        let from_analytic = match received.recv() {
            Ok(staged) => staged,
            // the thread panicked before sending: its panic goes on
            Err(_) => std::panic::resume_unwind(other.join().expect_err("a panicked thread")),
        };
        // the stall-only start first: of equal times the first is kept
        let staged: Vec<free::Staged> = from_stall
            .into_iter()
            .chain([from_analytic])
            .filter_map(|r| r.ok())
            .collect();
        let candidates = finished(reference, staged, &mut observe);
        let phased = other
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (phased, bound, candidates)
    });
    let mut phased_error = None;
    let (mut answer, phased_bend) = match phased {
        Some(Ok(phased)) => phased,
        // the phased family failed (its twist search, a flight): a
        // free-form design that verifies still answers
        Some(Err(e)) if candidates.iter().any(|c| c.1.is_some()) => {
            phased_error = Some(e.to_string());
            (HeightAnswer::blank(spec), f64::NAN)
        }
        Some(Err(e)) => return Err(e),
        None => unless_verified(spec, &reference, &candidates)?,
    };
    // (the stall-only design's time scaling, F3, holds at zero momentum only:
    // F9; under the stall torque alone it is the answer's own problem, whose
    // local optimum bounds nothing)
    let torque_alone = spec.motor.no_load_speed.is_none() && spec.motor.max_speed.is_none();
    answer.least_height_lower_bound_m = bound
        .filter(|_| !spec.has_momentum() && !torque_alone)
        .map(|t| crate::design::envelope::height_for(spec, t));
    let mut heights = concluded(spec, (answer, phased_bend), candidates);
    heights.phased_error = phased_error;
    // the stall-only design is a local optimum too (on a coarse mesh): where
    // it is not below the answer it bounds nothing, and is not given
    let a = &mut heights.answer;
    a.least_height_lower_bound_m = a
        .least_height_lower_bound_m
        .filter(|&b| b < a.least_height_m);
    a.torque_alone(spec);
    Ok(Some(heights))
}

/// A free-form design and its flight, when it verifies ([`verified`]).
type Candidate = (FreeResult, Option<SimReport>);

/// `fr` with its flight ([`verified`]).
fn flown(reference: &DesignSpec, fr: FreeResult) -> Candidate {
    let sim = verified(reference, &fr);
    (fr, sim)
}

/// The staged starts finished on the fine mesh, in their order, each with
/// its flight: the better start alone ([`rank`]); the others too when it
/// fails or does not verify, or when the starts cannot be ranked (then in
/// parallel, the first one seen by `observe`).
fn finished(
    reference: &DesignSpec,
    staged: Vec<free::Staged>,
    observe: &mut dyn free::Observer,
) -> Vec<Candidate> {
    let outcomes: Vec<_> = staged.iter().map(|s| s.coarse()).collect();
    let mut staged: Vec<Option<free::Staged>> = staged.into_iter().map(Some).collect();
    let run = |st: free::Staged, observe: &mut dyn free::Observer| {
        st.finish(reference, observe)
            .ok()
            .map(|fr| flown(reference, fr))
    };
    let mut out = Vec::new();
    if let Finish::One(i) = rank(&outcomes) {
        let c = run(staged[i].take().expect("a ranked start"), observe);
        let landed = c.as_ref().is_some_and(|c| c.1.is_some());
        out.extend(c);
        if landed {
            return out;
        }
    }
    let mut rest = staged.into_iter().flatten();
    let first = rest.next();
    std::thread::scope(|s| {
        let others: Vec<_> = rest
            .map(|st| s.spawn(move || run(st, &mut |_: &ScpIteration| {})))
            .collect();
        out.extend(first.and_then(|st| run(st, observe)));
        for h in others {
            out.extend(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        }
    });
    out
}

/// Which staged starts to finish on the fine mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Finish {
    /// This one alone (the others only if it fails or does not verify).
    One(usize),
    /// Every one: they cannot be ranked on the coarse mesh.
    All,
}

/// The start whose coarse design met its constraints in the shortest time;
/// [`Finish::All`] when one has no coarse design, when none met its
/// constraints, or when the best two are within [`START_TIE`].
fn rank(outcomes: &[Option<free::CoarseOutcome>]) -> Finish {
    let Some(outcomes) = outcomes.iter().copied().collect::<Option<Vec<_>>>() else {
        return Finish::All;
    };
    let mut order: Vec<usize> = (0..outcomes.len()).collect();
    order.sort_by(|&a, &b| {
        let (oa, ob) = (outcomes[a], outcomes[b]);
        ob.feasible
            .cmp(&oa.feasible)
            .then(oa.objective.total_cmp(&ob.objective))
    });
    let Some(&best) = order.first().filter(|&&b| outcomes[b].feasible) else {
        return Finish::All;
    };
    match order.get(1).map(|&i| outcomes[i]) {
        Some(next)
            if next.feasible && next.objective <= outcomes[best].objective * (1.0 + START_TIE) =>
        {
            Finish::All
        }
        _ => Finish::One(best),
    }
}

/// Coarse times closer than this (relative) do not rank two starts: the
/// fine mesh can reorder starts that close. Wider, it finishes both more
/// often for little (measured: docs/benchmarks.md, "Design settings: the
/// measurements behind them"). A start ranked wrongly costs at most the
/// gap, not the answer: a failed or unverified one has the others finished.
const START_TIE: f64 = 2e-3;

/// [`heights`] at a point next to one already answered (a sweep's
/// continuation): one free-form `time` design, started from the
/// neighbour's (`prev`, and the secant through `before`), beside the
/// phased design, whose bend search starts at `hint` (the neighbour's). A
/// neighbour's optimum is a few iterations from this one, where the cold
/// starts take dozens each; without the stall-only design the answer
/// carries no lower bound. When the continued design does not verify, the
/// cold stage answers. `best`, the last answer's design where only the
/// motors, the bend limit or the fall changed since (the caller's to
/// know), answers instead when it still flies here and is faster, so that
/// where the feasible set grows the answers of consecutive points never
/// rise; it keeps its own status (a sweep reads its time).
pub fn heights_near(
    spec: &DesignSpec,
    prev: &FreeResult,
    before: Option<&FreeResult>,
    best: Option<&FreeResult>,
    hint: Option<BendHint>,
    families: Families,
) -> Result<Option<Near>> {
    if !spec.motor.is_limited() {
        return Ok(None);
    }
    let reference = reference(spec);
    let continued = free::FreeDesign::new(&reference)
        .warm(prev, before)
        .solve()
        .ok()
        .map(|fr| flown(&reference, fr))
        .filter(|c| c.1.is_some());
    let Some(own) = continued else {
        let Some(mut cold) = heights(spec, families, |_| {})? else {
            return Ok(None);
        };
        // (the next point continues from the cold design, not from `best`)
        let continued = cold.free.clone();
        if let Some(best) = best {
            keep_if_faster(spec, &reference, &mut cold, best);
        }
        return Ok(Some(Near {
            heights: cold,
            continued,
        }));
    };
    let continued = own.0.clone();
    let answer = if families.phased() {
        answer_for(spec, &reference, hint)?
    } else {
        (HeightAnswer::blank(spec), f64::NAN)
    };
    let mut heights = concluded(spec, answer, [own]);
    if let Some(best) = best {
        keep_if_faster(spec, &reference, &mut heights, best);
    }
    // (where the answer is `best`, the next point still continues from
    // this point's own design: a chain held at one design finds no other)
    Ok(Some(Near {
        heights,
        continued: Some(continued),
    }))
}

/// `best` (an earlier point's design) as `h`'s free-form answer when it is
/// faster than `h`'s and flies under `reference`'s motors (its numbers are
/// its schedule's on the same body; the flight judges it here).
fn keep_if_faster(spec: &DesignSpec, reference: &DesignSpec, h: &mut Heights, best: &FreeResult) {
    if h.free
        .as_ref()
        .is_some_and(|f| f.manoeuvre_time_s <= best.manoeuvre_time_s)
    {
        return;
    }
    if let Some(sim) = verified(reference, best) {
        h.answer.improve_with(spec, best, &sim);
        h.free = Some(best.clone());
    }
}

/// [`heights_near`]'s answer, and the design the next point continues
/// from: this point's own design (continued, or the cold stage's), which is
/// not the answer's where the answer is an earlier point's.
pub struct Near {
    pub heights: Heights,
    pub continued: Option<FreeResult>,
}

impl Near {
    /// The cold stage's answer, continued from its own design.
    pub fn cold(heights: Heights) -> Near {
        let continued = heights.free.clone();
        Near { heights, continued }
    }
}

/// The phased answer ([`answer_for`]) when no free-form design in
/// `candidates` verifies; otherwise a blank one ([`HeightAnswer::blank`])
/// that the fastest of them settles ([`concluded`]), its bend NaN.
fn unless_verified(
    spec: &DesignSpec,
    reference: &DesignSpec,
    candidates: &[Candidate],
) -> Result<(HeightAnswer, f64)> {
    if !candidates.iter().any(|c| c.1.is_some()) {
        return answer_for(spec, reference, None);
    }
    Ok((HeightAnswer::blank(spec), f64::NAN))
}

/// The answer from the phased one (`answer`) and the free-form `time`
/// designs with their flights: the shortest that verifies improves it (the
/// first of equal times).
fn concluded(
    spec: &DesignSpec,
    (mut answer, phased_bend): (HeightAnswer, f64),
    designs: impl IntoIterator<Item = Candidate>,
) -> Heights {
    let (phased_m, phased_verified) = (answer.least_height_m, answer.verified);
    let mut fastest: Option<(FreeResult, SimReport)> = None;
    for (fr, sim) in designs {
        if let Some(sim) = sim
            && fastest
                .as_ref()
                .is_none_or(|(f, _)| fr.manoeuvre_time_s < f.manoeuvre_time_s)
        {
            fastest = Some((fr, sim));
        }
    }
    if let Some((fr, sim)) = &fastest {
        if !spec.is_default_start() {
            // the phased design is made for the start at rest: from another
            // start it only seeds the free-form one, which answers
            answer.least_time_s = f64::INFINITY;
        }
        answer.improve_with(spec, fr, sim);
    } else if !spec.is_default_start() {
        answer.possible = false;
    }
    Heights {
        answer,
        phased_m,
        phased_bend,
        phased_verified,
        free: fastest.map(|(fr, _)| fr),
        phased_error: None,
    }
}

/// Whether a free-form design can answer the robot question: its
/// constraints met (the SCP's violation within `free.attitude_tolerance`),
/// inside the motor envelope at every written row, and flipping under the
/// motor model within `simulate.flip_tolerance`. Optimality is not needed:
/// any schedule that does this shows the flip possible from its height (the
/// least height found is an upper bound either way), so a design that ran
/// out of iterations still counts, and says so in its status. The
/// simulation that verifies it, or `None`.
pub fn verified(spec: &DesignSpec, fr: &FreeResult) -> Option<SimReport> {
    // (checked first, as `verifies` checks it: a design that breaks its
    // constraints is not flown)
    if fr.certificate.constraint_violation > spec.free.attitude_tolerance {
        return None;
    }
    let sim = crate::verify::simulate::dynamic_spec(spec, &fr.plan).ok()?;
    verifies(spec, fr, &sim).then_some(sim)
}

/// [`verified`] for a design already flown as `sim`.
pub fn verifies(spec: &DesignSpec, fr: &FreeResult, sim: &SimReport) -> bool {
    fr.certificate.constraint_violation <= spec.free.attitude_tolerance && flies(spec, fr, sim)
}

/// Whether a design flown as `sim` flips (from another start: lands)
/// within every motor and bend limit (the envelope at every written row),
/// whatever the SCP's own residual at its last point: the
/// simulation judges the flight.
pub fn flies(spec: &DesignSpec, fr: &FreeResult, sim: &SimReport) -> bool {
    let usage = crate::design::envelope::usage_of(spec, &fr.plan);
    let v = verdict(
        &Targets::of(spec),
        &DesignNumbers {
            status: fr.status.into(),
            peak_torque_nm: fr.peak_torque_nm,
            bend_deg: fr.bend_deg,
            max_speed_rad_s: Some(usage.max_speed_rad_s),
            envelope_margin: usage.min_margin,
            line_margin: usage.min_line_margin,
        },
        &Simulated::Landing {
            flip_error_rad: sim.flip_error_rad,
            tilt_deg: sim.tilt_deg,
            landing_error_deg: sim.landing_error_deg,
        },
    );
    v.within_limits() && v.flips()
}

impl HeightAnswer {
    /// No answer yet: not verified, no design, an infinite least time (so
    /// that any verified free-form design improves it,
    /// [`HeightAnswer::improve_with`]).
    fn blank(spec: &DesignSpec) -> HeightAnswer {
        HeightAnswer {
            possible: false,
            verified: false,
            height_m: spec.fall.height,
            least_height_m: f64::NAN,
            least_time_s: f64::INFINITY,
            method: "free",
            status: Status::Converged,
            least_height_lower_bound_m: None,
            flip_error_rad: f64::NAN,
            from_start: spec.is_default_start(),
            beyond_longest_fall: false,
            schedule: Schedule { rows: Vec::new() },
            size_needs: size_needs(&spec.motor),
            torque_alone_for_height_nm: None,
        }
    }

    /// Takes a verified free-form `time` design (`fr`, flown as `sim`:
    /// inside the envelope and flipping; designs that stopped at the
    /// iteration limit count too) when it is shorter than the answer's.
    pub fn improve_with(&mut self, spec: &DesignSpec, fr: &FreeResult, sim: &SimReport) {
        if self.verified && fr.manoeuvre_time_s >= self.least_time_s {
            return;
        }
        self.verified = true;
        self.least_time_s = fr.manoeuvre_time_s;
        self.least_height_m = crate::design::envelope::height_for(spec, fr.manoeuvre_time_s);
        self.possible = fits(spec, self.least_height_m);
        self.method = "free";
        self.status = fr.status.into();
        self.flip_error_rad = sim.flip_error_rad;
        self.from_start = true;
        self.schedule = Schedule::sample(&spec.cat, &fr.plan, spec.simulate.samples_per_phase);
        self.bound(spec);
    }

    /// The answer with [`HeightAnswer::beyond_longest_fall`] decided: a
    /// manoeuvre longer than the longest fall is no answer catflip gives.
    fn bound(&mut self, spec: &DesignSpec) {
        self.beyond_longest_fall =
            crate::config::ranges::beyond_longest_fall(self.least_time_s + spec.fall.margin);
        if self.beyond_longest_fall {
            self.possible = false;
            self.schedule = Schedule { rows: Vec::new() };
        }
    }

    /// Sets [`HeightAnswer::torque_alone_for_height_nm`] for `spec`'s
    /// fall (none but under a stall torque alone, at rest, with a verified
    /// least time).
    fn torque_alone(&mut self, spec: &DesignSpec) {
        let m = spec.motor;
        let fall = spec.available_time();
        self.torque_alone_for_height_nm = match m.max_torque {
            Some(t)
                if m.no_load_speed.is_none()
                    && m.max_speed.is_none()
                    && !spec.has_momentum()
                    && self.verified
                    && self.least_time_s.is_finite()
                    && fall > 0.0 =>
            {
                Some(t * (self.least_time_s / fall).powi(2))
            }
            _ => None,
        };
    }

    /// What a manoeuvre beyond the longest fall takes, and what to change.
    pub fn beyond_text(&self) -> String {
        let seconds = if self.least_time_s < 1e4 {
            format!("{:.4} s", self.least_time_s)
        } else {
            format!("{:.3e} s", self.least_time_s)
        };
        format!(
            "{} takes {seconds}, a drop of {:.3e} m; stronger or faster motors would do (catflip size names them for a height).",
            if self.method == "analytic" {
                "the seed's analytic schedule within these motors".to_string()
            } else {
                format!(
                    "the shortest manoeuvre found (the {} time design)",
                    self.method
                )
            },
            self.least_height_m
        )
    }

    /// One plain sentence for the terminal and the report.
    /// Where to ask for the motors that would flip it from this height.
    pub fn sizing(&self) -> String {
        match self.size_needs {
            None => format!(
                "The motors (or the gear ratio) that would do it from {} m: catflip size CONFIG --height {}.",
                self.height_m, self.height_m
            ),
            Some(keys) => {
                // under a torque alone F7 answers it without a torque-speed line
                let alone = self.torque_alone_for_height_nm.map_or(String::new(), |t| {
                    format!(
                        "a stall torque of {t:.4} N m, with no speed limit (F7: this least-height schedule stretched to that fall needs its torque times (T_min / T)^2); for a DC motor, "
                    )
                });
                format!(
                    "The motors that would do it from {} m: {alone}catflip size CONFIG --height {}, once the config gives a DC motor's {keys} (catflip size scales its torque-speed line).",
                    self.height_m, self.height_m
                )
            }
        }
    }

    pub fn sentence(&self) -> String {
        let what = if self.status.is_proven() {
            format!("the {} time-optimal schedule", self.method)
        } else {
            format!(
                "the {} time design, verified but not proven shortest ({})",
                self.method, self.status
            )
        };
        // far below the answer the bound reads as a range: say what the gap is
        let bound = self
            .least_height_lower_bound_m
            .map(|b| {
                let gap = if b < 0.5 * self.least_height_m {
                    "; the motor's speed, not its torque, needs the rest"
                } else {
                    ""
                };
                format!(" (at least {b:.3} m within the stall torque, estimated{gap})")
            })
            .unwrap_or_default();
        if self.beyond_longest_fall {
            format!(
                "The flip is NOT possible from {} m with these motors, nor from any drop catflip designs (falls up to {} s): {}",
                self.height_m,
                crate::config::ranges::MAX_FALL_TIME_S,
                self.beyond_text()
            )
        } else if !self.verified && self.from_start && self.possible {
            format!(
                "The flip is possible from {} m: the {} design fits the motors in this fall; no verified least drop height was found (the phased time design fits them from {:.3} m but misses the flip; see the least-height row).",
                self.height_m, self.method, self.least_height_m
            )
        } else if !self.verified && self.from_start {
            format!(
                "No verified design found: the phased time design fits the motors from {:.3} m but misses the flip in the simulation (see the least-height row).",
                self.least_height_m
            )
        } else if !self.from_start && self.possible {
            format!(
                "The flip is possible from {} m: the {} design made for this start fits the motors; the least drop height was found for the start at rest only ({:.3} m there, the least-height row).",
                self.height_m, self.method, self.least_height_m
            )
        } else if !self.from_start {
            format!(
                "No design found lands belly-down from this start in the fall from {} m (at rest the motors would need {:.3} m).",
                self.height_m, self.least_height_m
            )
        } else if self.possible && self.least_height_m > self.height_m {
            format!(
                "The flip is possible from {} m: the {} design fits the motors, although the phased least-height design needs {:.3} m.",
                self.height_m, self.method, self.least_height_m
            )
        } else if self.possible {
            format!(
                "The flip is possible from {} m: the motors need at most {:.3} m{bound} ({:.4} s of manoeuvre, {what} in least-height.csv).",
                self.height_m, self.least_height_m, self.least_time_s
            )
        } else {
            format!(
                "The flip is NOT possible from {} m with these motors: from {:.3} m{bound} it is ({:.4} s of manoeuvre, {what} in least-height.csv). {}",
                self.height_m,
                self.least_height_m,
                self.least_time_s,
                self.sizing()
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An answer whose design misses the flip in the simulation says that no
    /// verified design was found, not that the flip is possible from its
    /// height; once a verified design improves it, it answers as usual.
    #[test]
    fn an_unverified_answer_claims_no_height() {
        let mut a = HeightAnswer {
            possible: false,
            height_m: 20.0,
            least_height_m: 62.514,
            least_time_s: 3.47,
            method: "phased",
            status: Status::Solved,
            least_height_lower_bound_m: Some(1.7),
            flip_error_rad: 5e-4,
            verified: false,
            from_start: true,
            beyond_longest_fall: false,
            schedule: Schedule { rows: Vec::new() },
            size_needs: None,
            torque_alone_for_height_nm: None,
        };
        let s = a.sentence();
        assert!(s.starts_with("No verified design found"), "{s}");
        assert!(!s.contains("it is ("), "{s}");
        a.verified = true;
        assert!(
            a.sentence()
                .contains("from 62.514 m (at least 1.700 m within the stall torque, estimated; the motor's speed, not its torque, needs the rest) it is")
        );
        assert!(a.sentence().ends_with(
            "The motors (or the gear ratio) that would do it from 20 m: catflip size CONFIG --height 20."
        ));
        // a motor catflip size cannot scale: the sentence says what it needs
        a.size_needs = size_needs(&Motor {
            max_torque: Some(1.4),
            ..Motor::unlimited(crate::model::TorqueNorm::PerMotor)
        });
        assert!(
            a.sentence().ends_with("catflip size CONFIG --height 20, once the config gives a DC motor's no-load speed (limits.no_load_speed) (catflip size scales its torque-speed line)."),
            "{}",
            a.sentence()
        );
        // under the stall torque alone F7 gives the torque for the height
        a.torque_alone_for_height_nm = Some(2.5);
        assert!(
            a.sentence()
                .contains("from 20 m: a stall torque of 2.5000 N m, with no speed limit (F7"),
            "{}",
            a.sentence()
        );
    }

    /// The start finished is the feasible coarse design with the shorter
    /// time; starts that cannot be ranked (one without a coarse design, none
    /// feasible, or two feasible ones within the tie) are all finished.
    #[test]
    fn the_better_coarse_start_is_the_feasible_shorter_one_unless_they_tie() {
        let o = |objective: f64, feasible: bool| {
            Some(free::CoarseOutcome {
                objective,
                feasible,
            })
        };
        let tie = 1.0 + START_TIE;
        let cases: &[(&[Option<free::CoarseOutcome>], Finish)] = &[
            (&[o(0.74, true), o(0.75, true)], Finish::One(0)),
            (&[o(0.75, true), o(0.74, true)], Finish::One(1)),
            // a shorter coarse design that breaks its constraints loses
            (&[o(0.7437, false), o(0.7427, true)], Finish::One(1)),
            (&[o(0.7427, true), o(0.7437, false)], Finish::One(0)),
            // none feasible: not ranked
            (&[o(0.70, false), o(0.74, false)], Finish::All),
            // within the tie: both finished
            (
                &[o(0.7437, true), o(0.7437 * tie * 0.9999, true)],
                Finish::All,
            ),
            (
                &[o(0.7437 * tie * 0.9999, true), o(0.7437, true)],
                Finish::All,
            ),
            // just outside it: ranked
            (
                &[o(0.7437, true), o(0.7437 * tie * 1.0001, true)],
                Finish::One(0),
            ),
            // an infeasible runner-up does not tie
            (&[o(0.7437, true), o(0.7437, false)], Finish::One(0)),
            // one start without a coarse design: not ranked
            (&[o(0.74, true), None], Finish::All),
            (&[o(0.74, true)], Finish::One(0)),
            (&[], Finish::All),
        ];
        for (outcomes, want) in cases {
            assert_eq!(rank(outcomes), *want, "{outcomes:?}");
        }
    }
}
