//! Benchmark: replanning in flight (issue 27), the free-form design re-solved
//! from the nominal state at instants along the seed's design, perturbed, on
//! one core: median, p99 and worst wall time against the control period.
//! `cargo run --release --example bench_replan [-- NODES ITERATIONS]`
//! (default 20 nodes per phase, 5 SCP iterations).
use catflip::Config;
use catflip::control::reference::Reference;
use catflip::design::free::{FreeDesign, replan};
use catflip::design::plan::ShapePlan;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let nodes: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(20);
    let iterations: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(5);
    let root = env!("CARGO_MANIFEST_DIR");
    let path = format!("{root}/configs/seed.toml");
    let cfg = Config::from_toml(&std::fs::read_to_string(&path)?, &path, &[])?;
    let d = FreeDesign::new(&cfg).solve()?;
    let r = Reference::new(&cfg, &d.plan);
    let period = 1.0 / cfg.control.rate_hz;
    let mut times = Vec::new();
    let mut converged = 0;
    // every 10th control period of the manoeuvre, the joints' rates knocked
    let mut t = 0.05;
    while t < 0.95 * d.plan.duration() {
        let j = (t / r.h) as usize;
        let mut y = r.nominal[j];
        y[6] += 0.2;
        y[7] -= 0.1;
        let re = replan(&cfg, &d.plan, j as f64 * r.h, &y, nodes, iterations)?;
        converged += usize::from(re.status == catflip::design::scp::ScpStatus::Converged);
        times.push(re.seconds);
        t += 10.0 * period;
    }
    times.sort_by(f64::total_cmp);
    let at = |p: f64| times[((times.len() - 1) as f64 * p).round() as usize];
    println!(
        "{} replans at {nodes} nodes per phase, at most {iterations} SCP iterations: median {:.4} s, p99 {:.4} s, worst {:.4} s; control period {:.4} s; {converged} converged",
        times.len(),
        at(0.5),
        at(0.99),
        times[times.len() - 1],
        period
    );
    Ok(())
}
