//! Benchmark: the free-form design, seeding design included, median of
//! several runs, with iteration counts, on the three cases of issue 11,
//! from both seeds (phased, analytic).
//! `cargo run --release --example bench_free [-- RUNS]` (default 5 runs).
use catflip::Config;
use catflip::design::free::{FreeResult, Seed};
use std::time::Instant;

#[path = "common/mod.rs"]
mod common;
use common::median;

/// The seeding design (phased, or the analytic schedule, which costs
/// nothing) and the SCP, timed together, without the mesh check.
fn design(cfg: &Config, seed: Seed) -> anyhow::Result<(FreeResult, f64, f64)> {
    let t = Instant::now();
    let plan = seed.plan(&cfg.design_spec())?;
    let seed_s = t.elapsed().as_secs_f64();
    let r = catflip::design::free::FreeDesign::new(&cfg.design_spec())
        .from_plan(plan.as_ref(), seed.name())
        .solve()?;
    // the SCP's own time (without the verification simulations)
    Ok((r.clone(), seed_s, seed_s + r.solve_time_s))
}

fn main() -> anyhow::Result<()> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(5);
    let root = env!("CARGO_MANIFEST_DIR");
    let cases = [
        ("seed, Euclidean", "seed", "euclidean", 0.3),
        ("seed, per-motor", "seed", "per-motor", 0.5),
        ("robot-universal", "robot-universal", "per-motor", 0.5),
    ];
    println!(
        "{:<18} {:>8} {:>9} {:>9} {:>9} {:>6} {:>11} {:>12} {:>10}",
        "case",
        "seed",
        "median s",
        "seed s",
        "target s",
        "iters",
        "status",
        "peak N m",
        "criticality"
    );
    for ((name, file, norm, target), seed) in cases
        .into_iter()
        .flat_map(|c| [(c, Seed::Phased), (c, Seed::Analytic)])
    {
        // the robot is issue 11's peak-torque case: its body under the servo's
        // stall torque alone (the torque-speed line is bench_objectives' subject)
        let path = format!("{root}/configs/{file}.toml");
        let text = std::fs::read_to_string(&path)?.replace("no_load_speed", "# no_load_speed");
        let cfg = Config::from_toml(&text, &path, &[format!("limits.norm={norm}")])?;
        let (mut total, mut seed_s) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..runs {
            let (r, s, t) = design(&cfg, seed)?;
            seed_s.push(s);
            total.push(t);
            last = Some(r);
        }
        let r = last.expect("at least one run");
        println!(
            "{:<18} {:>8} {:>9.3} {:>9.3} {:>9.1} {:>6} {:>11} {:>12.6} {:>10.1e}",
            name,
            seed.name(),
            median(total),
            median(seed_s),
            target,
            r.scp_iterations,
            format!("{:?}", r.status),
            r.peak_torque_nm,
            r.certificate.criticality
        );
    }
    // issue 11's quality anchor: the per-motor seed design against the
    // exact-Hessian IPOPT optimum (Hermite-Simpson, 120 intervals), at the
    // default mesh and at 120 nodes per phase
    let ipopt = 0.31637;
    let path = format!("{root}/configs/seed.toml");
    for nodes in [40, 120] {
        let cfg = Config::load(
            std::path::Path::new(&path),
            &[
                "limits.norm=per-motor".into(),
                format!("free.nodes={nodes}"),
            ],
        )?;
        let (r, _, t) = design(&cfg, Seed::Analytic)?;
        println!(
            "quality: seed per-motor, {nodes} nodes per phase: dense peak {:.6} N m ({:+.2} % from IPOPT's {ipopt}), {} iterations, {:.2} s, {:?}",
            r.peak_torque_nm,
            100.0 * (r.peak_torque_nm - ipopt) / ipopt,
            r.scp_iterations,
            t,
            r.status
        );
    }
    Ok(())
}
