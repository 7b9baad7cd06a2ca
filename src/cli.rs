//! Argument parsing into a checked configuration, and the terminal tables.

use anyhow::{Context, Result};
use catflip::Config;
use catflip::design::plan::Schedule;
use catflip::output::Output;
use catflip::verify::analyze::{analytic_schedule, analyze, verify};
use catflip::verify::simulate::SimReport;
use clap::{Args, Parser, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Parser)]
#[command(
    name = "catflip",
    version,
    about = "Joint-torque schedules that turn a falling two-body cat right side up"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args, Clone)]
struct Common {
    /// TOML configuration (see configs/).
    config: PathBuf,
    /// Override a config key, e.g. `--set cat.joint=universal` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Folder that receives `<name>/` (default `output`).
    #[arg(long, default_value = "output")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum Command {
    /// The main job: analytic, phased and free-form schedules, verified by simulation, with a report.
    Run(Common),
    /// The seed's closed forms and its cosine schedule, evaluated with the true dynamics.
    Analyze(Common),
    /// Forward-simulate a torque schedule (default: the analytic one) in the full model.
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Schedule CSV to apply (as written by catflip); its torque is the feed-forward.
        #[arg(long)]
        schedule: Option<PathBuf>,
    },
    /// Sweep a numeric config key over a range; every point designed by each method, in parallel.
    Sweep {
        #[command(flatten)]
        common: Common,
        /// KEY=FROM:TO:COUNT, e.g. fall.height=0.5:10:40.
        #[arg(long = "set-range", value_name = "KEY=FROM:TO:COUNT")]
        range: String,
        /// Methods to compute, comma separated (default all three).
        #[arg(long, value_delimiter = ',', default_value = "analytic,phased,free")]
        methods: Vec<String>,
        /// Points computed at once (default: the machine's cores).
        #[arg(long)]
        threads: Option<usize>,
        /// K/N: compute only the K-th of N disjoint slices of the grid (for a
        /// batch scheduler's job array); the shards' CSVs concatenate into the
        /// whole sweep's.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
    },
    /// Write the cat as a URDF (pyBullet) or MJCF (MuJoCo) model.
    Export {
        #[arg(value_enum)]
        format: ExportFormat,
        #[command(flatten)]
        common: Common,
    },
    /// Optimise the torque schedule: `phased` (certified fold / twist / unfold) or `free`.
    Optimize {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "phased")]
        mode: Mode,
        /// Seed of the free-form optimiser.
        #[arg(long, value_enum, default_value = "phased")]
        seed: SeedArg,
        /// Print each iteration (bend evaluations, SCP iterations).
        #[arg(long)]
        verbose: bool,
    },
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
enum ExportFormat {
    /// URDF for pyBullet (as the seed used).
    Urdf,
    /// MJCF for MuJoCo.
    Mjcf,
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Phased,
    Free,
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
enum SeedArg {
    Phased,
    Analytic,
}

fn load(c: &Common) -> Result<Config> {
    Ok(Config::load(&c.config, &c.set)?)
}

fn out_dir(c: &Common, cfg: &Config) -> PathBuf {
    c.out.join(&cfg.name)
}

pub fn run() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(c) => cmd_run(&c),
        Command::Sweep {
            common,
            range,
            methods,
            threads,
            shard,
        } => cmd_sweep(&common, &range, &methods, threads, shard.as_deref()),
        Command::Export { format, common } => cmd_export(&common, format),
        Command::Analyze(c) => cmd_analyze(&c),
        Command::Simulate { common, schedule } => cmd_simulate(&common, schedule.as_deref()),
        Command::Optimize {
            common,
            mode,
            seed,
            verbose,
        } => cmd_optimize(&common, mode, seed, verbose),
    }
}

fn row(label: &str, value: String) {
    println!("  {label:<34} {value}");
}

fn cmd_analyze(c: &Common) -> Result<()> {
    let cfg = load(c)?;
    let a = analyze(&cfg)?;
    let sched = analytic_schedule(&cfg, &a.plan);
    let json = serde_json::to_string_pretty(&a)?;
    let mut out = Output::default();
    sched.add_to(&mut out, "analytic");
    out.add("analyze.json", json.clone());
    let written = out.commit(&out_dir(c, &cfg))?;
    if c.json {
        println!("{json}");
        return Ok(());
    }
    let cf = &a.closed;
    println!("catflip analyze: {} ({} joint)", a.name, a.joint);
    row(
        "fall time",
        format!(
            "{:.4} s (manoeuvre {:.4} s)",
            cf.fall_time_s, cf.available_time_s
        ),
    );
    row(
        "theta / bend",
        format!("{:.3} / {:.3} deg", cf.theta_deg, cf.bend_deg),
    );
    row(
        "I_t, I_a, I_yy",
        format!("{:.6}, {:.6}, {:.6} kg m^2", cf.i_t, cf.i_a, cf.i_yy),
    );
    row("C", format!("{:.6}", cf.c));
    row("twist pi/C", format!("{:.6} rad", cf.twist_rad));
    row(
        "omega0 (twist phase)",
        format!("{:.4} rad/s", cf.omega0_rad_s),
    );
    row(
        "one-turn theta (F6)",
        format!("{:.3} deg", cf.one_turn_theta_deg),
    );
    row(
        "phase durations",
        format!(
            "{:.4} / {:.4} / {:.4} s",
            cf.phase_durations_s[0], cf.phase_durations_s[1], cf.phase_durations_s[2]
        ),
    );
    row(
        "seed I* estimate (E7)",
        format!("{:.4} N m", cf.seed_torque_estimate_nm),
    );
    row(
        "true peak torque",
        format!(
            "{:.4} N m (fold {:.4}, twist {:.4}, unfold {:.4}; {:.2}x the estimate)",
            a.peak_torque_nm,
            a.phase_peak_torque_nm[0],
            a.phase_peak_torque_nm[1],
            a.phase_peak_torque_nm[2],
            a.peak_over_seed_estimate
        ),
    );
    row(
        "flip (kinematic sim)",
        format!("{:.9} deg (error {:.2e} rad)", a.flip_deg, a.flip_error_rad),
    );
    row("tilt", format!("{:.3e} deg", a.tilt_deg));
    row(
        "momentum drift",
        format!("{:.2e} N m s", a.momentum_drift_nms),
    );
    for w in written {
        row("wrote", w.display().to_string());
    }
    Ok(())
}

fn print_sim(title: &str, r: &SimReport) {
    println!("{title}");
    row(
        "flip",
        format!("{:.6} deg (error {:.2e} rad)", r.flip_deg, r.flip_error_rad),
    );
    row("tilt", format!("{:.3e} deg", r.tilt_deg));
    row(
        "final shape / rate error",
        format!(
            "{:.2e} rad / {:.2e} rad/s",
            r.final_shape_error_rad, r.final_rate_error_rad_s
        ),
    );
    row(
        "max tracking error",
        format!("{:.2e} rad", r.max_tracking_error_rad),
    );
    row(
        "peak applied torque",
        format!("{:.4} N m", r.peak_torque_nm),
    );
    row(
        "momentum drift",
        format!("{:.2e} N m s", r.momentum_drift_nms),
    );
    row("accepted steps", format!("{}", r.steps));
}

fn cmd_simulate(c: &Common, schedule: Option<&Path>) -> Result<()> {
    let cfg = load(c)?;
    let (source, report) = match schedule {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("cannot read schedule {}", p.display()))?;
            let s = Schedule::from_csv(&text, &p.display().to_string())?;
            (p.display().to_string(), verify(&cfg, &s)?)
        }
        None => {
            let plan = catflip::design::analytic::analytic_plan(&cfg);
            ("analytic schedule".to_string(), verify(&cfg, &plan)?)
        }
    };
    let mut trace = String::from("t_s,flip_rad,tilt_rad,q1_rad,q2_rad,tau1_nm,tau2_nm\n");
    for p in &report.trace {
        trace.push_str(&format!(
            "{:.9},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}\n",
            p.t, p.flip, p.tilt, p.q[0], p.q[1], p.tau[0], p.tau[1]
        ));
    }
    let mut out = Output::default();
    out.add("simulation.csv", trace);
    let written = out.commit(&out_dir(c, &cfg))?;
    if c.json {
        let mut v = serde_json::to_value(&report)?;
        v["source"] = serde_json::Value::String(source);
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_sim(
            &format!(
                "catflip simulate: {} ({source}, dynamic, feed-forward + PD)",
                cfg.name
            ),
            &report,
        );
        for w in written {
            row("wrote", w.display().to_string());
        }
    }
    Ok(())
}

/// Writes `<stem>.csv` and `<stem>.json`; prints the JSON and returns `None` with `--json`.
fn write_design(
    c: &Common,
    cfg: &Config,
    stem: &str,
    plan: &dyn catflip::design::plan::ShapePlan,
    json: String,
) -> Result<Option<Vec<PathBuf>>> {
    let sched = Schedule::sample(&cfg.cat(), plan, cfg.simulate.samples_per_phase);
    let mut out = Output::default();
    sched.add_to(&mut out, stem);
    out.add(format!("{stem}.json"), json.clone());
    let written = out.commit(&out_dir(c, cfg))?;
    if c.json {
        println!("{json}");
        return Ok(None);
    }
    Ok(Some(written))
}

/// The rows both optimisers print: timing, verification, solve time, files.
fn design_rows(
    durations: [f64; 3],
    sim: (f64, f64, f64, f64),
    solve: String,
    written: Vec<PathBuf>,
) {
    let d = durations;
    row(
        "phase durations",
        format!("{:.4} / {:.4} / {:.4} s", d[0], d[1], d[2]),
    );
    row(
        "flip (dynamic sim)",
        format!("{:.6} deg (error {:.2e} rad)", sim.0, sim.1),
    );
    row("tilt", format!("{:.3e} deg", sim.2));
    row("sim peak torque", format!("{:.5} N m", sim.3));
    row("solve time", solve);
    for w in written {
        row("wrote", w.display().to_string());
    }
}

fn cmd_optimize(c: &Common, mode: Mode, seed: SeedArg, verbose: bool) -> Result<()> {
    let cfg = load(c)?;
    match mode {
        Mode::Phased => {
            let r = catflip::design::phased::optimize(&cfg, |e| {
                if verbose {
                    eprintln!(
                        "  bend {:8.3} deg   unit peak {:10.5} N m s^2   peak {:9.5} N m",
                        e.bend_deg, e.unit_peak, e.peak_nm
                    );
                }
            })?;
            let Some(written) = write_design(
                c,
                &cfg,
                "phased",
                &r.plan,
                serde_json::to_string_pretty(&r)?,
            )?
            else {
                return Ok(());
            };
            println!(
                "catflip optimize --mode phased: {} ({} joint), status {:?}",
                cfg.name,
                cfg.cat.joint.name(),
                r.status
            );
            row(
                "peak torque",
                format!(
                    "{:.5} N m (SOCP bound {:.5})",
                    r.peak_torque_nm, r.socp_peak_torque_nm
                ),
            );
            row(
                "bend / theta",
                format!("{:.3} / {:.3} deg", r.bend_deg, r.theta_deg),
            );
            row("twist", format!("{:.6} rad", r.twist_rad));
            row(
                "seed cosine schedule, same bend",
                format!(
                    "{:.5} N m ({:.2}x the optimum)",
                    r.analytic_peak_same_bend_nm, r.improvement_factor
                ),
            );
            design_rows(
                r.phase_durations_s,
                (
                    r.flip_deg,
                    r.flip_error_rad,
                    r.tilt_deg,
                    r.sim_peak_torque_nm,
                ),
                format!(
                    "{:.3} s ({} bend evaluations)",
                    r.solve_time_s,
                    r.evaluations.len()
                ),
                written,
            );
        }
        Mode::Free => {
            let seed = match seed {
                SeedArg::Phased => catflip::design::free::Seed::Phased,
                SeedArg::Analytic => catflip::design::free::Seed::Analytic,
            };
            if verbose {
                eprintln!(
                    "  iter      merit       peak     infeas     radius        rho  step   ms"
                );
            }
            let r = catflip::design::free::optimize(&cfg, seed, |it| {
                if verbose {
                    eprintln!(
                        "  {:4} {:10.5} {:10.5} {:10.2e} {:10.2e} {:10.3} {:>5} {:5.1}",
                        it.iteration,
                        it.merit,
                        it.peak,
                        it.infeasibility,
                        it.radius,
                        it.rho,
                        if it.accepted { "ok" } else { "rej" },
                        it.solve_ms
                    );
                }
            })?;
            let Some(written) =
                write_design(c, &cfg, "free", &r.plan, serde_json::to_string_pretty(&r)?)?
            else {
                return Ok(());
            };
            println!(
                "catflip optimize --mode free: {} ({} joint), status {:?}, seed {}",
                cfg.name,
                cfg.cat.joint.name(),
                r.status,
                r.seed
            );
            row(
                "peak torque",
                format!(
                    "{:.5} N m (at check points {:.5})",
                    r.peak_torque_nm, r.node_peak_torque_nm
                ),
            );
            row(
                "largest bend / theta",
                format!("{:.3} / {:.3} deg", r.bend_deg, r.theta_deg),
            );
            row("twist of bend direction", format!("{:.4} rad", r.twist_rad));
            design_rows(
                r.phase_durations_s,
                (
                    r.flip_deg,
                    r.flip_error_rad,
                    r.tilt_deg,
                    r.sim_peak_torque_nm,
                ),
                format!(
                    "{:.3} s ({} SCP iterations, {} nodes per phase)",
                    r.solve_time_s, r.scp_iterations, r.nodes
                ),
                written,
            );
        }
    }
    Ok(())
}

/// Stage lines on stderr; live iteration counters when stderr is a terminal.
fn progress_display(quiet: bool) -> impl FnMut(catflip::run::Progress) {
    use catflip::run::Progress;
    use std::io::{IsTerminal, Write};
    let live = std::io::stderr().is_terminal() && !quiet;
    move |p| {
        if quiet {
            return;
        }
        let mut e = std::io::stderr();
        match p {
            Progress::Stage { index, total, name } => {
                let _ = write!(e, "[{index}/{total}] {name} ...");
                if live {
                    let _ = writeln!(e);
                }
            }
            Progress::StageDone { seconds } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " done in {seconds:.2} s");
            }
            Progress::Bend {
                evaluations,
                bend_deg,
                peak_nm,
            } if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      bend evaluation {evaluations:3}: {bend_deg:7.2} deg -> {peak_nm:.5} N m"
                );
            }
            Progress::Scp(it) if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      SCP iteration {:3}: peak {:.5} N m, max |r| {:.1e}, radius {:.1e}",
                    it.iteration, it.peak, it.infeasibility, it.radius
                );
            }
            _ => {}
        }
        let _ = e.flush();
    }
}

fn cmd_run(c: &Common) -> Result<()> {
    let cfg = load(c)?;
    let r = catflip::run::run(&cfg, progress_display(c.json))?;
    let dir = out_dir(c, &cfg);
    let written = r.output.commit(&dir)?;
    if c.json {
        println!("{}", serde_json::to_string_pretty(&r.summary)?);
        return Ok(());
    }
    let s = &r.summary;
    println!();
    println!(
        "catflip run: {} ({} joint, peak norm {:?})",
        s.name, s.joint, s.peak_norm
    );
    let header = catflip::run::TABLE_HEADER;
    let rows: Vec<Vec<String>> = s.methods.iter().map(catflip::run::table_row).collect();
    let widths: Vec<usize> = (0..header.len())
        .map(|j| {
            rows.iter()
                .map(|r| r[j].len())
                .chain([header[j].len()])
                .max()
                .unwrap()
        })
        .collect();
    let line = |cells: Vec<String>| {
        let parts: Vec<String> = cells
            .iter()
            .enumerate()
            .map(|(j, c)| format!("{c:>w$}", w = widths[j]))
            .collect();
        println!("  {}", parts.join("  "));
    };
    line(header.iter().map(|h| h.to_string()).collect());
    for row in rows {
        line(row);
    }
    println!(
        "  free-form / phased peak {:.3}, phased / analytic {:.3}; {} SCP iterations at {} nodes per phase",
        s.free_over_phased, s.phased_over_analytic, s.scp_iterations, s.nodes
    );
    println!(
        "  report: {} ({} files)",
        dir.join("index.html").display(),
        written.len()
    );
    Ok(())
}

fn cmd_sweep(
    c: &Common,
    range: &str,
    methods: &[String],
    threads: Option<usize>,
    shard: Option<&str>,
) -> Result<()> {
    let cfg = load(c)?;
    let spec: catflip::sweep::SweepSpec = range.parse()?;
    let shard = match shard {
        Some(s) => s.parse()?,
        None => catflip::sweep::Shard::ALL,
    };
    let mut m = catflip::sweep::Methods {
        analytic: false,
        phased: false,
        free: false,
    };
    for name in methods {
        match name.trim() {
            "analytic" => m.analytic = true,
            "phased" => m.phased = true,
            "free" => m.free = true,
            other => anyhow::bail!(
                "unknown method `{other}` in --methods; use analytic, phased and/or free"
            ),
        }
    }
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let quiet = c.json;
    // a live bar on a terminal, plain lines otherwise
    let live = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let clock = std::time::Instant::now();
    let points = catflip::sweep::sweep_shard(
        &c.config,
        &c.set,
        &spec,
        m,
        threads,
        shard,
        |done, total| {
            if quiet {
                return;
            }
            let line = catflip::sweep::progress_line(
                &spec.key,
                done,
                total,
                clock.elapsed().as_secs_f64(),
            );
            if live {
                eprint!("\r  {line}");
            } else {
                eprintln!("  {line}");
            }
        },
    )?;
    if !quiet && live {
        eprintln!();
    }
    let key = format!("{}{}", spec.key.replace('.', "_"), shard.suffix());
    let mut out = Output::default();
    out.add(
        format!("sweep-{key}.csv"),
        catflip::sweep::to_csv(&spec.key, &points),
    );
    for (name, svg) in catflip::sweep::figures(&key, &spec.key, &points, cfg.limits.max_torque)? {
        out.add(name, svg);
    }
    let written = out.commit(&out_dir(c, &cfg))?;
    if c.json {
        println!("{}", serde_json::to_string_pretty(&points)?);
        return Ok(());
    }
    println!(
        "catflip sweep: {} over {} ({} points, {threads} at a time)",
        cfg.name,
        spec.key,
        points.len()
    );
    let show = |x: Option<f64>| x.map(|v| format!("{v:.5}")).unwrap_or_else(|| "-".into());
    println!(
        "  {:>12} {:>12} {:>12} {:>12} {:>12}",
        spec.key, "analytic N m", "phased N m", "free N m", "least h (m)"
    );
    for p in &points {
        let h = p.least_height_free_m.or(p.least_height_phased_m);
        println!(
            "  {:>12.5} {:>12} {:>12} {:>12} {:>12}{}",
            p.value,
            show(p.analytic_peak_nm),
            show(p.phased_peak_nm),
            show(p.free_peak_nm),
            show(h),
            p.error
                .as_ref()
                .map(|e| format!("  error: {e}"))
                .unwrap_or_default()
        );
    }
    for w in written {
        row("wrote", w.display().to_string());
    }
    Ok(())
}

fn cmd_export(c: &Common, format: ExportFormat) -> Result<()> {
    let cfg = load(c)?;
    let (name, text) = match format {
        ExportFormat::Urdf => (format!("{}.urdf", cfg.name), catflip::export::urdf(&cfg)),
        ExportFormat::Mjcf => (
            format!("{}.mjcf.xml", cfg.name),
            catflip::export::mjcf(&cfg),
        ),
    };
    let mut out = Output::default();
    out.add(name, text);
    for w in out.commit(&out_dir(c, &cfg))? {
        println!("wrote {}", w.display());
    }
    Ok(())
}
