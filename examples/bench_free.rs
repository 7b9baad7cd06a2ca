//! Benchmark: free-form SCP solve time and iterations on a config.
//! `cargo run --release --example bench_free [-- configs/seed.toml [nodes]]`
use catflip::Config;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "configs/seed.toml".into());
    let cfg = Config::load(std::path::Path::new(&path), &[])?;
    let nodes: usize = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(cfg.free.nodes);
    let t = Instant::now();
    let phased = catflip::design::phased::optimize(&cfg, |_| {})?;
    let seed_time = t.elapsed().as_secs_f64();
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..3 {
        let r = catflip::design::free::optimize_from(&cfg, &phased.plan, "phased", nodes, |_| {})?;
        best = best.min(r.solve_time_s);
        last = Some(r);
    }
    let r = last.unwrap();
    let mean_ms = r.iterations.iter().map(|i| i.solve_ms).sum::<f64>() / r.iterations.len() as f64;
    println!(
        "config {path}: {nodes} nodes per phase ({} in all), seed phased ({seed_time:.3} s)",
        3 * nodes
    );
    println!(
        "SCP: {:?} in {} iterations, best solve time {best:.3} s over 3 runs (target < 2 s), mean Clarabel subproblem {mean_ms:.1} ms",
        r.status, r.scp_iterations
    );
    println!(
        "peak {:.6} N m (phased {:.6} N m, ratio {:.3}); simulated flip error {:.2e} rad, tilt {:.2e} deg",
        r.peak_torque_nm,
        phased.peak_torque_nm,
        r.peak_torque_nm / phased.peak_torque_nm,
        r.flip_error_rad,
        r.tilt_deg
    );
    Ok(())
}
