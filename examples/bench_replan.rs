//! Benchmark: replanning in flight (issue 27) on one core (run it under
//! `taskset -c 0`), against the control period `1 / control.rate_hz`.
//!
//! `cargo run --release --example bench_replan -- [CONFIG] [NODES] [ITERATIONS] [KEY=VALUE ...] [--quick]`
//! (CONFIG a bundled config's name or a path, default `seed`; 10 nodes per
//! phase, 1 SCP iteration; the overrides as `--set` takes them, e.g.
//! `fall.height=4.25`; `--quick`: the flight knocked at 30 % alone, for a
//! profiler). Two measurements:
//!
//! - single replans: [`replan`] from the design's state every 10th control
//!   period, the joints' rates knocked (each replan alone, set-up included);
//! - real-time iteration: flights knocked at 10, 30 and 50 % of the
//!   manoeuvre (joint rates +0.4 and -0.3 rad/s, a spin of 0.4 rad/s about
//!   the release's spine), replanned every control period by one
//!   [`Replanner`] from the model's state under the latest plan (the model is
//!   the plant: a perfect prediction of the state over the replan's period).
//!   Reported: the replans' wall times, the landing error flown (against the
//!   old plan's, open loop) and the flown torques' motor margin.
use catflip::Config;
use catflip::control::plant::{Y, attitude, rk4};
use catflip::control::reference::Reference;
use catflip::design::free::{FreeDesign, Replanner, Seed, replan};
use catflip::design::plan::ShapePlan;
use catflip::design::scp::ScpStatus;
use catflip::model::momentum::{landing_error, straight_inertias};

fn main() -> anyhow::Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    args.retain(|a| a != "--quick");
    // the old form `bench_replan NODES ITERATIONS` still works
    let (name, rest) = match args.first() {
        Some(a) if a.parse::<usize>().is_err() && !a.contains('=') => (a.as_str(), &args[1..]),
        _ => ("seed", &args[..]),
    };
    let numbers: Vec<usize> = rest.iter().map_while(|s| s.parse().ok()).collect();
    let overrides: Vec<String> = rest[numbers.len()..].to_vec();
    let nodes = numbers.first().copied().unwrap_or(10);
    let iterations = numbers.get(1).copied().unwrap_or(1);
    let root = env!("CARGO_MANIFEST_DIR");
    let path = if name.ends_with(".toml") {
        name.to_string()
    } else {
        format!("{root}/configs/{name}.toml")
    };
    let cfg = Config::load(std::path::Path::new(&path), &overrides)?;
    // the robot near its least height: the phased seed does not fit, the analytic one starts it
    let d = FreeDesign::new(&cfg.design_spec()).solve().or_else(|_| {
        FreeDesign::new(&cfg.design_spec())
            .seed(Seed::Analytic)
            .solve()
    })?;
    let period = 1.0 / cfg.control.rate_hz;
    println!(
        "{name} {}: design {:.4} N m peak, manoeuvre {:.4} s; {nodes} nodes per phase, at most {iterations} SCP iterations; control period {period:.4} s",
        overrides.join(" "),
        d.peak_torque_nm,
        d.plan.duration()
    );
    if !quick {
        single_replans(&cfg, &d.plan, nodes, iterations, period)?;
    }
    let mut times = Vec::new();
    for at in if quick {
        vec![0.3]
    } else {
        vec![0.1, 0.3, 0.5]
    } {
        let f = flight(&cfg, &d.plan, at, nodes, iterations, period)?;
        println!(
            "  RTI, knocked at {:.0} %: {} replans ({} converged, {} failed), landing error {:.2e} deg (old plan open loop {:.3} deg), last plan's own {:.2e} deg, least motor margin {}",
            100.0 * at,
            f.times.len(),
            f.converged,
            f.failed,
            f.landing_deg,
            f.open_loop_deg,
            f.own_deg,
            f.margin
                .map_or("none (no limits)".into(), |m| format!("{m:.4}")),
        );
        times.extend(f.times);
    }
    println!("  RTI, all flights: {}", summary(times, period));
    Ok(())
}

/// Median, p99 and worst of the times, and the share over the period.
fn summary(mut times: Vec<f64>, period: f64) -> String {
    times.sort_by(f64::total_cmp);
    let at = |p: f64| times[((times.len() - 1) as f64 * p).round() as usize];
    let over = times.iter().filter(|&&t| t > period).count();
    format!(
        "{} replans, median {:.4} s, p99 {:.4} s, worst {:.4} s; {over} over the period",
        times.len(),
        at(0.5),
        at(0.99),
        times[times.len() - 1]
    )
}

/// Replans from the design's state every 10th control period, the joints'
/// rates knocked, each alone (the free function: set-up included).
fn single_replans(
    cfg: &Config,
    plan: &dyn ShapePlan,
    nodes: usize,
    iterations: usize,
    period: f64,
) -> anyhow::Result<()> {
    let r = Reference::new(cfg, plan);
    let mut times = Vec::new();
    let mut converged = 0;
    let mut t = 0.05;
    while t < 0.95 * plan.duration() {
        let j = (t / r.h) as usize;
        let mut y = r.nominal[j];
        y[6] += 0.2;
        y[7] -= 0.1;
        let re = replan(
            &cfg.design_spec(),
            plan,
            j as f64 * r.h,
            &y,
            nodes,
            iterations,
        )?;
        converged += usize::from(re.status == ScpStatus::Converged);
        times.push(re.seconds);
        t += 10.0 * period;
    }
    println!(
        "  single replans: {}; {converged} converged",
        summary(times, period)
    );
    Ok(())
}

/// What a replanned flight reports.
struct Flight {
    times: Vec<f64>,
    converged: usize,
    failed: usize,
    landing_deg: f64,
    open_loop_deg: f64,
    own_deg: f64,
    margin: Option<f64>,
}

/// Integration steps per control period.
const STEPS: usize = 20;

/// Replanning stops this many control periods before the manoeuvre's end
/// (the last plan is flown out).
const LAST: f64 = 2.0;

/// A flight knocked at the fraction `at` of the manoeuvre, replanned every
/// period by one [`Replanner`] (see the module doc).
fn flight(
    cfg: &Config,
    design: &catflip::design::collocation_plan::CollocationPlan,
    at: f64,
    nodes: usize,
    iterations: usize,
    period: f64,
) -> anyhow::Result<Flight> {
    let cat = cfg.cat();
    let end = design.duration();
    let knock = at * end;
    let kick = |y: &mut Y| {
        y[6] += 0.4;
        y[7] -= 0.3;
        let spin = 0.4 * straight_inertias(&cat).0;
        let dl = attitude(y).inverse() * nalgebra::Vector3::new(0.0, 0.0, spin);
        for c in 0..3 {
            y[8 + c] += dl[c];
        }
    };
    let start = catflip::control::reference::release(&cat, &cfg.start.start());
    let mut replanner = Replanner::new(&cfg.design_spec(), nodes)?.real_time();
    let mut plan = design.clone();
    let mut origin = 0.0;
    let mut y = start;
    let mut t = 0.0;
    let mut rows = Vec::new();
    let mut f = Flight {
        times: Vec::new(),
        converged: 0,
        failed: 0,
        landing_deg: 0.0,
        open_loop_deg: 0.0,
        own_deg: 0.0,
        margin: None,
    };
    let mut knocked = false;
    let mut k = 0usize;
    while t < cfg.fall_time() - 1e-12 {
        if !knocked && t >= knock - 1e-12 {
            kick(&mut y);
            knocked = true;
            f.open_loop_deg = open_loop(cfg, &plan, origin, y, t);
        }
        if k > 0 && t < origin + plan.duration() - LAST * period {
            match replanner.replan(&plan, origin, t, &y, iterations) {
                Ok(re) => {
                    f.times.push(re.seconds);
                    f.converged += usize::from(re.status == ScpStatus::Converged);
                    f.own_deg = re.landing_error_rad.to_degrees();
                    plan = re.plan;
                    origin = t;
                }
                // the previous plan continues
                Err(_) => f.failed += 1,
            }
        }
        let next = (period * (k + 1) as f64).min(cfg.fall_time());
        // knocked within this period: fly to the knock first
        let stop = if knocked { next } else { next.min(knock) };
        y = fly_span(cfg, &plan, origin, y, t, stop, Some(&mut rows));
        if stop < next {
            t = stop;
            continue;
        }
        t = next;
        k += 1;
    }
    f.landing_deg = landing_error(attitude(&y).to_rotation_matrix().matrix()).to_degrees();
    f.margin = cfg.motor().usage(rows).min_margin;
    Ok(f)
}

/// The landing error, deg, when `plan` is flown open loop from `y` at `t`.
fn open_loop(cfg: &Config, plan: &dyn ShapePlan, origin: f64, y: Y, t: f64) -> f64 {
    let y = fly_span(cfg, plan, origin, y, t, cfg.fall_time(), None);
    landing_error(attitude(&y).to_rotation_matrix().matrix()).to_degrees()
}

/// Flies `plan` (time 0 at flight time `origin`) from `y` at `a` to `b`:
/// RK4 at most a period / [`STEPS`] long, split at the plan's phase bounds
/// (its acceleration jumps there) and its end, no torque after it. The
/// `(torque, joint rate)` at each step's start go to `rows`.
fn fly_span(
    cfg: &Config,
    plan: &dyn ShapePlan,
    origin: f64,
    mut y: Y,
    a: f64,
    b: f64,
    mut rows: Option<&mut Vec<([f64; 2], [f64; 2])>>,
) -> Y {
    let cat = cfg.cat();
    let bounds: Vec<f64> = plan.phase_bounds().iter().map(|x| x + origin).collect();
    let mut cuts = vec![a];
    cuts.extend(bounds.iter().copied().filter(|&x| x > a && x < b));
    cuts.push(b);
    let hmax = 1.0 / cfg.control.rate_hz / STEPS as f64;
    for w in cuts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        if t1 <= t0 {
            continue;
        }
        let mid = 0.5 * (t0 + t1);
        let phase = (0..3).find(|&i| mid < bounds[i + 1]);
        let n = ((t1 - t0) / hmax).ceil() as usize;
        let h = (t1 - t0) / n as f64;
        for s in 0..n {
            let ts = t0 + h * s as f64;
            let tau = |stage: usize| match phase {
                Some(i) => plan.torque_in(&cat, i, ts + 0.5 * h * stage as f64 - origin),
                None => [0.0; 2],
            };
            if let Some(r) = rows.as_deref_mut() {
                r.push((tau(0), [y[6], y[7]]));
            }
            y = rk4(&cat, &y, h, |stage, _| tau(stage));
        }
    }
    y
}
