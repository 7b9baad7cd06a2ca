//! Benchmark: the robot builder's question on the bundled robots with their
//! real servo (stall torque and torque-speed line), median of several runs,
//! wall and CPU time (the CPU time of all threads is the steadier measure on
//! a shared machine; run under `valgrind --tool=callgrind` for instruction
//! counts).
//!
//! `cargo run --release --example bench_robot [-- RUNS [CASE...] [KEY=VALUE...]]`
//! (default 3 runs, every case; the overrides as `--set` takes them, for
//! every case, e.g. `free.screen_limits=true`). Cases:
//! - `run:CONFIG`: `catflip run`'s pipeline (analytic, least height, phased,
//!   free-form, report; files not written), e.g. `run:robot-universal`;
//! - `height:CONFIG`: the least-height stage alone, with its answer;
//! - `parts:CONFIG`: the least-height stage's four designs one after the
//!   other in one thread, each timed (wall/CPU s);
//! - `free:CONFIG:OBJECTIVE:SEED`: the free-form design inside the motor
//!   envelope from 6 m (`peak-torque`, `time`, `energy`; `phased`,
//!   `analytic`, the seeding design not counted; or `default`, the start
//!   `optimize --mode free` takes without `--seed`, counted);
//! - `sweep:CONFIG:KEY:FROM:TO:COUNT`: `catflip sweep CONFIG --set-range
//!   KEY=FROM:TO:COUNT --threads 2` with every method (files not written),
//!   e.g. `sweep:robot-universal:cat.length:0.18:0.24:40`.
//!
//! The default cases: `run` and `height` on `robot-universal` and
//! `box-robot`, and the six free-form designs of `robot-universal`.
use catflip::Config;
use catflip::design::free::{FreeDesign, Seed};
use std::time::Instant;

#[path = "common/mod.rs"]
mod common;
use common::median;

/// CPU time of the whole process (every thread), s.
fn cpu_s() -> f64 {
    // SAFETY: getrusage only writes the struct it is given
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

fn config(name: &str, set: &[String], extra: &[String]) -> anyhow::Result<Config> {
    let path = format!("{}/configs/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let all: Vec<String> = set.iter().chain(extra).cloned().collect();
    Ok(Config::load(std::path::Path::new(&path), &all)?)
}

/// One case, timed once: what it printed and the work's wall and CPU seconds.
fn once(case: &str, extra: &[String]) -> anyhow::Result<(String, f64, f64)> {
    let parts: Vec<&str> = case.split(':').collect();
    let (t, c) = (Instant::now(), cpu_s());
    let text = match parts.as_slice() {
        ["run", name] => {
            let cfg = config(name, &[], extra)?;
            let r = catflip::run::run(&cfg, |_| {})?;
            let a = r.summary.answer.as_ref();
            format!(
                "outcome {:?}; {}",
                r.summary.outcome,
                a.map(|a| a.sentence()).unwrap_or_default()
            )
        }
        ["height", name] => {
            let cfg = config(name, &[], extra)?;
            let h = catflip::design::least_height::heights(
                &cfg.design_spec(),
                catflip::design::least_height::Families::Both,
                |_| {},
            )?
            .ok_or_else(|| anyhow::anyhow!("{name}: no motor limits"))?;
            format!(
                "least height {:.4} m ({} {:.5} s), phased {:.4} m",
                h.answer.least_height_m, h.answer.method, h.answer.least_time_s, h.phased_m
            )
        }
        ["parts", name] => {
            // the least-height stage's designs one by one, in one thread
            let cfg = config(name, &[], extra)?;
            let reference = catflip::design::least_height::reference(&cfg.design_spec());
            let mut out = Vec::new();
            let mut lap = |what: &str, text: String, t: &mut (Instant, f64)| {
                out.push(format!(
                    "{what} {:.3}/{:.3} s: {text}",
                    t.0.elapsed().as_secs_f64(),
                    cpu_s() - t.1
                ));
                *t = (Instant::now(), cpu_s());
            };
            let mut t = (Instant::now(), cpu_s());
            let ph = catflip::design::phased::optimize(&reference, |_| {})?;
            lap("phased", format!("{:.5} s", ph.manoeuvre_time_s), &mut t);
            let plan = catflip::design::analytic::analytic_plan(&reference);
            let fr = FreeDesign::new(&reference)
                .from_plan(&plan, "analytic")
                .solve()?;
            lap(
                "free(analytic)",
                format!(
                    "{:.5} s, {} it ({})",
                    fr.manoeuvre_time_s,
                    fr.scp_iterations,
                    catflip::design::free::iterations_text(&fr.mesh_levels)
                ),
                &mut t,
            );
            if let Some((least, sr)) = catflip::design::least_height::stall_only(&reference)? {
                lap(
                    "stall-only",
                    format!(
                        "{least:.5} s, {} it ({})",
                        sr.scp_iterations,
                        catflip::design::free::iterations_text(&sr.mesh_levels)
                    ),
                    &mut t,
                );
                let mut plan = sr.plan.clone();
                for i in 0..plan.tr.phases {
                    let d = plan.tr.duration(i);
                    plan.z[d] *= least / sr.manoeuvre_time_s;
                }
                let fr = FreeDesign::new(&reference)
                    .from_plan(&plan, "stall-only")
                    .solve()?;
                lap(
                    "free(stall-only)",
                    format!(
                        "{:.5} s, {} it ({})",
                        fr.manoeuvre_time_s,
                        fr.scp_iterations,
                        catflip::design::free::iterations_text(&fr.mesh_levels)
                    ),
                    &mut t,
                );
            }
            out.join("; ")
        }
        ["free", name, objective, seed] => {
            let cfg = config(
                name,
                &[
                    "fall.height=6".into(),
                    format!("design.objective={objective}"),
                ],
                extra,
            )?;
            let spec = cfg.design_spec();
            // `default`: what `optimize --mode free` does without `--seed`,
            // its start (for the least time, the least-height stage) counted;
            // a named seed's making is not
            let seed = match *seed {
                "default" => None,
                "phased" => Some(Seed::Phased),
                "analytic" => Some(Seed::Analytic),
                s => anyhow::bail!("unknown seed {s}"),
            };
            let plan = seed.map(|s| s.plan(&spec)).transpose()?;
            let (t, c) = (Instant::now(), cpu_s());
            let r = match (seed, &plan) {
                (Some(seed), Some(plan)) => FreeDesign::new(&spec)
                    .from_plan(plan.as_ref(), seed.name())
                    .solve()?,
                _ => catflip::pipeline::free_start(&spec, |_| {})?
                    .free_design(&spec)
                    .solve()?,
            };
            return Ok((
                format!(
                    "{:.6} ({}), from {}, {} SCP iterations ({}), {}, SCP and envelope {:.3} s wall",
                    r.objective_value,
                    cfg.design.objective.name(),
                    r.seed,
                    r.scp_iterations,
                    catflip::design::free::iterations_text(&r.mesh_levels),
                    catflip::verdict::Status::from(r.status),
                    r.solve_time_s
                ),
                t.elapsed().as_secs_f64(),
                cpu_s() - c,
            ));
        }
        ["sweep", name, key, from, to, count] => {
            // `catflip sweep CONFIG --set-range KEY=FROM:TO:COUNT --threads 2`
            // (every method; files not written)
            let path = format!("{}/configs/{name}.toml", env!("CARGO_MANIFEST_DIR"));
            let spec: catflip::sweep::SweepSpec = format!("{key}={from}:{to}:{count}").parse()?;
            let methods = catflip::sweep::Methods::ALL;
            let points = catflip::sweep::sweep(
                std::path::Path::new(&path),
                extra,
                &spec,
                methods,
                2,
                |_, _| {},
            )?;
            let free: Vec<f64> = points
                .iter()
                .filter_map(|p| p.least_height_free_m)
                .collect();
            let falls = free.windows(2).filter(|w| w[1] < w[0]).count();
            format!(
                "{} points, {} free least heights ({:.4} to {:.4} m), {falls} of {} steps falling",
                points.len(),
                free.len(),
                free.first().copied().unwrap_or(f64::NAN),
                free.last().copied().unwrap_or(f64::NAN),
                free.len().saturating_sub(1)
            )
        }
        _ => anyhow::bail!(
            "unknown case {case} (run:CONFIG, height:CONFIG, parts:CONFIG, free:CONFIG:OBJECTIVE:SEED, sweep:CONFIG:KEY:FROM:TO:COUNT)"
        ),
    };
    Ok((text, t.elapsed().as_secs_f64(), cpu_s() - c))
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(3);
    // KEY=VALUE arguments are overrides for every case (as `--set` takes them)
    let (extra, mut cases): (Vec<String>, Vec<String>) = args.partition(|a| a.contains('='));
    if cases.is_empty() {
        for c in ["robot-universal", "box-robot"] {
            cases.push(format!("run:{c}"));
            cases.push(format!("height:{c}"));
        }
        for o in ["peak-torque", "time", "energy"] {
            for s in ["phased", "analytic"] {
                cases.push(format!("free:robot-universal:{o}:{s}"));
            }
        }
    }
    println!("{runs} runs per case: median (min) wall s, median CPU s");
    for case in cases {
        let (mut wall, mut cpu, mut text) = (Vec::new(), Vec::new(), String::new());
        for _ in 0..runs {
            let (t, w, c) = once(&case, &extra)?;
            wall.push(w);
            cpu.push(c);
            text = t;
        }
        let min = wall.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "{case:<40} {:>7.3} ({:.3}) {:>7.3}  {text}",
            median(wall),
            min,
            median(cpu)
        );
    }
    Ok(())
}
