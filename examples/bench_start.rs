//! Benchmark: the free-form design from a spinning or tilted start beside the
//! start at rest (issue 26), both norms and every objective, median of several
//! runs, seeding design included.
//! `cargo run --release --example bench_start [-- RUNS]` (default 3 runs).
use catflip::Config;
use catflip::design::free::FreeDesign;
use std::time::Instant;

#[path = "common/mod.rs"]
mod common;
use common::median;

fn main() -> anyhow::Result<()> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(3)
        .max(1);
    let root = env!("CARGO_MANIFEST_DIR");
    let path = format!("{root}/configs/seed.toml");
    let text = std::fs::read_to_string(&path)?;
    println!(
        "{runs} runs per case; seed from 10 m; median wall time of the free-form design (seed included)"
    );
    println!(
        "{:<10} {:<12} {:<22} {:>9} {:>6} {:>15} {:>12} {:>11}",
        "norm", "objective", "start", "median s", "iters", "status", "value", "landing deg"
    );
    let starts: [(&str, &[&str]); 3] = [
        ("at rest", &[]),
        (
            "0.5 rad/s about spine",
            &["start.angular_velocity=[0,0,0.5]"],
        ),
        ("roll 30 deg", &["start.rotation_deg=[0,0,30]"]),
    ];
    for norm in ["euclidean", "per-motor"] {
        // the time objective needs a limit: the peak design's at rest, rounded up
        for (objective, extra) in [
            ("peak-torque", None),
            ("energy", None),
            ("time", Some("limits.max_torque=0.45")),
        ] {
            for (label, start) in starts {
                let mut sets = vec![
                    format!("limits.norm={norm}"),
                    format!("design.objective={objective:?}"),
                ];
                sets.extend(extra.map(String::from));
                sets.extend(start.iter().map(|s| s.to_string()));
                let cfg = Config::from_toml(&text, &path, &sets)?;
                let mut times = Vec::new();
                let mut last = None;
                for _ in 0..runs {
                    let t = Instant::now();
                    let r = FreeDesign::new(&cfg.design_spec()).solve();
                    times.push(t.elapsed().as_secs_f64());
                    last = Some(r);
                }
                match last.expect("a run") {
                    Ok(r) => println!(
                        "{:<10} {:<12} {:<22} {:>9.3} {:>6} {:>15} {:>12.6} {:>11.2e}",
                        norm,
                        objective,
                        label,
                        median(times),
                        r.scp_iterations,
                        format!("{:?}", r.status),
                        r.objective_value,
                        catflip::verify::simulate::dynamic_spec(&cfg.design_spec(), &r.plan)
                            .map_or(f64::NAN, |s| s.landing_error_deg)
                    ),
                    Err(e) => println!("{norm:<10} {objective:<12} {label:<22} failed: {e}"),
                }
            }
        }
    }
    Ok(())
}
