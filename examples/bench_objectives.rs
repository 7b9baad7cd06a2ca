//! Benchmark: each design objective on each bundled config (phased design,
//! bend search, envelope back-off and verification included), median of
//! several runs, with the work the envelope programs did (SOCPs solved,
//! Clarabel iterations, time inside Clarabel; all of the last run).
//! Each case's free-form design, seeded by the phased one, is timed once
//! (its SCP and verification; the seed's time not counted) and printed on
//! the next line with its ratio to the phased value.
//! `cargo run --release --example bench_objectives [-- RUNS]` (default 5)
//!
//! Cases: every config in `configs/` as it is, plus the robot dropped from 6 m
//! (its configured 2 m is too low for its servos, so from there the `peak` and
//! `energy` designs end in the least-height error after a search). `time`
//! needs a limit: configs without one get `limits.max_torque` 1.2 times the
//! config's own peak-torque optimum, so the least time is the fall time over
//! sqrt(1.2) (F7) and the numbers check each other.
use catflip::Config;
use catflip::design::envelope::work;
use catflip::design::phased::optimize;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(5)
        .max(1);
    println!("{runs} runs per case; median wall time of the whole phased design");
    println!(
        "{:<20} {:<12} {:>9} {:>9} {:>6} {:>7} {:>9} {:>13} {:>8} {:>9}",
        "config",
        "objective",
        "median s",
        "min s",
        "SOCPs",
        "IPM it",
        "Clarabel s",
        "value",
        "time s",
        "peak N m"
    );
    let cases: [(&str, &str, &[&str]); 4] = [
        ("seed", "seed", &[]),
        ("domestic-cat", "domestic-cat", &[]),
        ("robot-universal", "robot-universal", &[]),
        ("robot-universal", "robot from 6 m", &["fall.height=6"]),
    ];
    for (name, label, set) in cases {
        let path = format!("configs/{name}.toml");
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let base = Config::load(std::path::Path::new(&path), &set)?;
        let mut extra = set.clone();
        if base.limits.max_torque.is_none() {
            let p = optimize(&base.design_spec(), |_| {})?;
            extra.push(format!("limits.max_torque={}", 1.2 * p.peak_torque_nm));
        }
        for objective in ["peak-torque", "time", "energy"] {
            let mut ov = extra.clone();
            ov.push(format!("design.objective={objective}"));
            let cfg = Config::load(std::path::Path::new(&path), &ov)?;
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..runs {
                let w0 = work();
                let t = Instant::now();
                let r = optimize(&cfg.design_spec(), |_| {});
                times.push(t.elapsed().as_secs_f64());
                last = Some((r, work() - w0));
            }
            times.sort_by(f64::total_cmp);
            let median = times[times.len() / 2];
            let (r, w) = last.unwrap();
            let head = format!(
                "{:<20} {:<12} {:>9.3} {:>9.3} {:>6} {:>7} {:>9.3}",
                label, objective, median, times[0], w.socps, w.iterations, w.solver_s
            );
            match r {
                Ok(r) => {
                    println!(
                        "{head} {:>13.6} {:>8.4} {:>9.5}",
                        r.objective_value, r.manoeuvre_time_s, r.peak_torque_nm
                    );
                    // the free-form design seeded by it, once (its own time,
                    // the seed's not counted): never worse than the phased one
                    let t = Instant::now();
                    let fr = catflip::design::free::FreeDesign::new(&cfg.design_spec())
                        .from_plan(&r.plan, "phased")
                        .solve();
                    let s = t.elapsed().as_secs_f64();
                    match fr {
                        Ok(f) => println!(
                            "{:<20} {:<12} {:>9.3} {:>9} {:>6} {:>7} {:>9} {:>13.6} {:>8.4} {:>9.5}  free-form, 1 run, {} iterations, {}, free / phased {:.3}",
                            "",
                            "",
                            s,
                            "",
                            "",
                            "",
                            "",
                            f.objective_value,
                            f.manoeuvre_time_s,
                            f.peak_torque_nm,
                            f.scp_iterations,
                            catflip::verdict::Status::from(f.status),
                            f.objective_value / r.objective_value
                        ),
                        Err(e) => println!("{:<33} {s:>9.3}  free-form: {e}", ""),
                    }
                }
                Err(e) => println!("{head}  {e}"),
            }
        }
    }
    Ok(())
}
