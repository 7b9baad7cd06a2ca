//! Benchmark: the closed-loop plant's model flight to touchdown (what the
//! replanning controller's take-or-keep comparison flies), on one core.
//!
//! `cargo run --release --example bench_rollout -- [CONFIG] [KEY=VALUE ...] [--quick]`
//! (CONFIG a bundled config's name or a path, default `seed`). Reports the
//! wall time of `plant::rhs` and of one RK4 flight of the design's
//! nominal from release to touchdown on the simulator's steps, medians of
//! repeated runs; `--quick`: one flight, for a profiler (callgrind).
use catflip::Config;
use catflip::control::plant::{rhs, rk4};
use catflip::control::reference::Reference;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    args.retain(|a| a != "--quick");
    let (name, overrides) = match args.first() {
        Some(a) if !a.contains('=') => (a.clone(), args[1..].to_vec()),
        _ => ("seed".to_string(), args.clone()),
    };
    let root = env!("CARGO_MANIFEST_DIR");
    let path = if name.ends_with(".toml") {
        name.clone()
    } else {
        format!("{root}/configs/{name}.toml")
    };
    let cfg = Config::load(std::path::Path::new(&path), &overrides)?;
    let design = catflip::control::robustness::design(&cfg)?;
    let r = Reference::new(&cfg, &design.plan);
    // a spinning start: the momentum terms are on
    let mut y0 = r.nominal[0];
    y0[8] += 0.02;
    y0[10] -= 0.01;
    let fly = || {
        let mut y = y0;
        for j in 0..r.steps {
            y = rk4(&r.cat, &y, r.h, |s, _| r.ff_at(j, s));
        }
        y
    };
    if quick {
        println!("{:?}", fly());
        return Ok(());
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut per_rhs = Vec::new();
    let mut sink = 0.0;
    for _ in 0..9 {
        let c = Instant::now();
        for j in 0..r.steps {
            sink += rhs(&r.cat, &r.nominal[j], r.ff_at(j, 0))[6];
        }
        per_rhs.push(c.elapsed().as_secs_f64() / r.steps as f64);
    }
    let mut per_flight = Vec::new();
    for _ in 0..9 {
        let c = Instant::now();
        sink += fly()[0];
        per_flight.push(c.elapsed().as_secs_f64());
    }
    let flight = median(per_flight);
    println!(
        "{name} {}: {} steps; rhs {:.3} us, RK4 step {:.3} us, flight {:.2} ms (medians of 9) [{sink:.3e}]",
        overrides.join(" "),
        r.steps,
        1e6 * median(per_rhs),
        1e6 * flight / r.steps as f64,
        1e3 * flight
    );
    Ok(())
}
