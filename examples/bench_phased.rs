//! Benchmark: whole phased design time (bend search included) on a config.
//! `cargo run --release --example bench_phased [-- configs/seed.toml]`
use catflip::Config;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "configs/seed.toml".into());
    let cfg = Config::load(std::path::Path::new(&path), &[])?;
    let runs = 5;
    let mut times = Vec::new();
    let mut result = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = catflip::design::phased::optimize(&cfg.design_spec(), |_| {})?;
        times.push((t.elapsed().as_secs_f64(), r.solve_time_s));
        result = Some(r);
    }
    let r = result.unwrap();
    let best = times.iter().map(|t| t.1).fold(f64::INFINITY, f64::min);
    let median = {
        let mut v: Vec<f64> = times.iter().map(|t| t.1).collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        v[v.len() / 2]
    };
    println!(
        "config {path}: K = {} intervals per phase, {} bend evaluations",
        r.nodes,
        r.evaluations.len()
    );
    println!(
        "design time (bend search + all SOCPs): best {best:.3} s, median {median:.3} s over {runs} runs (target < 0.5 s)"
    );
    println!(
        "with reconstruction and verification: best {:.3} s",
        times.iter().map(|t| t.0).fold(f64::INFINITY, f64::min)
    );
    println!(
        "peak {:.6} N m at bend {:.3} deg",
        r.peak_torque_nm, r.bend_deg
    );
    Ok(())
}
