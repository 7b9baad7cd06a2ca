//! The SCP decision suite of issue 11: 16 free-form designs (the three
//! bundled configs, both norms, both seeds, and the seed config at 30 and
//! 50 nodes per phase), each run once, with its status, SCP iterations,
//! peak and time, and the totals. Iteration counts are deterministic;
//! the machine's instruction count is the steadier measure of the work:
//! `perf stat -e instructions cargo run --release --example bench_scp_suite`.
//! The SCP's settings and rules (conic accuracy, trust-region cut,
//! correction weight) were chosen on its totals. Each config's torque-speed
//! line is left out (issue 11's peak-torque cases: the stall torque alone),
//! and so is mesh continuation: the suite measures the SCP on one mesh.
use catflip::Config;
use catflip::design::free::Seed;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let root = env!("CARGO_MANIFEST_DIR");
    let mut cases = Vec::new();
    for file in ["seed", "domestic-cat", "robot-universal"] {
        for norm in ["euclidean", "per-motor"] {
            for seed in [Seed::Phased, Seed::Analytic] {
                cases.push((file, norm, None, seed));
            }
        }
    }
    for norm in ["euclidean", "per-motor"] {
        for nodes in [30, 50] {
            cases.push(("seed", norm, Some(nodes), Seed::Analytic));
        }
    }
    println!(
        "{:<16} {:<10} {:>5} {:<8} {:>10} {:>6} {:>10} {:>7}",
        "config", "norm", "nodes", "seed", "status", "iters", "peak N m", "s"
    );
    let (mut iterations, mut seconds) = (0, 0.0);
    for (file, norm, nodes, seed) in cases {
        let path = format!("{root}/configs/{file}.toml");
        let text = std::fs::read_to_string(&path)?.replace("no_load_speed", "# no_load_speed");
        let cfg = Config::from_toml(
            &text,
            &path,
            &[
                format!("limits.norm={norm}"),
                "free.mesh_continuation=false".into(),
            ],
        )?;
        let nodes = nodes.unwrap_or(cfg.free.nodes);
        let t = Instant::now();
        let plan = seed.plan(&cfg.design_spec())?;
        let r = catflip::design::free::FreeDesign::new(&cfg.design_spec())
            .from_plan(plan.as_ref(), seed.name())
            .nodes(nodes)
            .solve()?;
        let s = t.elapsed().as_secs_f64();
        println!(
            "{file:<16} {norm:<10} {nodes:>5} {:<8} {:>10} {:>6} {:>10.6} {s:>7.2}",
            seed.name(),
            format!("{:?}", r.status),
            r.scp_iterations,
            r.peak_torque_nm
        );
        iterations += r.scp_iterations;
        seconds += s;
    }
    println!("total: {iterations} SCP iterations, {seconds:.1} s");
    Ok(())
}
