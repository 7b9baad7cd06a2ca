//! Benchmark: each design objective on each bundled config (phased design,
//! bend search, envelope back-off and verification included), median of
//! several runs. `cargo run --release --example bench_objectives [-- RUNS]`
//!
//! `time` needs a limit: configs without one get `limits.max_torque` 1.2 times
//! the config's own peak-torque optimum, so the least time is the fall time
//! over sqrt(1.2) (F7) and the numbers check each other.
use catflip::Config;
use catflip::design::phased::optimize;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(3);
    println!(
        "{:<28} {:<12} {:>10} {:>14} {:>10} {:>10}",
        "config", "objective", "median s", "value", "time s", "peak N m"
    );
    for name in ["seed", "domestic-cat", "robot-universal"] {
        let path = format!("configs/{name}.toml");
        let base = Config::load(std::path::Path::new(&path), &[])?;
        let mut extra = Vec::new();
        if base.limits.max_torque.is_none() {
            let p = optimize(&base, |_| {})?;
            extra.push(format!("limits.max_torque={}", 1.2 * p.peak_torque_nm));
        }
        for objective in ["peak-torque", "time", "energy"] {
            let mut ov = extra.clone();
            ov.push(format!("design.objective={objective}"));
            let cfg = Config::load(std::path::Path::new(&path), &ov)?;
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..runs {
                let t = Instant::now();
                let r = optimize(&cfg, |_| {});
                times.push(t.elapsed().as_secs_f64());
                last = Some(r);
            }
            times.sort_by(f64::total_cmp);
            let median = times[times.len() / 2];
            match last.unwrap() {
                Ok(r) => println!(
                    "{:<28} {:<12} {:>10.3} {:>14.6} {:>10.4} {:>10.5}",
                    name,
                    objective,
                    median,
                    r.objective_value,
                    r.manoeuvre_time_s,
                    r.peak_torque_nm
                ),
                Err(e) => println!("{name:<28} {objective:<12} {median:>10.3}  {e}"),
            }
        }
    }
    Ok(())
}
