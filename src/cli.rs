//! Argument parsing into a checked configuration, and the terminal tables.

use anyhow::Result;
use catflip::Config;
use catflip::output::{Output, Publisher};
use catflip::pipeline::{Design, Method};
use catflip::sweep::Methods;
use catflip::verdict;
use catflip::verify::analyze::{analyze, verify};
use catflip::verify::simulate::SimReport;
use clap::{Args, Parser, Subcommand};
use std::path::{Path, PathBuf};

/// Set once stdout turned out to be a closed pipe: later lines are dropped.
static STDOUT_GONE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// `println!` that stops printing, instead of panicking, when stdout is a
/// closed pipe (`catflip ... --json | head`); the command still finishes
/// and exits with its own status (3 partial, 4 impossible), which a
/// `pipefail` script needs.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        use std::sync::atomic::Ordering;
        if !STDOUT_GONE.load(Ordering::Relaxed) {
            if let Err(e) = writeln!(std::io::stdout(), $($t)*) {
                if e.kind() != std::io::ErrorKind::BrokenPipe {
                    eprintln!("error: writing to stdout: {e}");
                }
                STDOUT_GONE.store(true, Ordering::Relaxed);
            }
        }
    }};
}

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
pub(crate) struct Common {
    /// TOML configuration (see configs/).
    pub(crate) config: PathBuf,
    /// Override a config key, e.g. `--set cat.joint=universal` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) set: Vec<String>,
    /// Print JSON instead of the table: one object (`sweep`: an array of
    /// its points; `export` has no table and lists the files it wrote
    /// either way).
    #[arg(long)]
    pub(crate) json: bool,
    /// Folder that receives `<name>/`.
    #[arg(long, default_value = "output")]
    pub(crate) out: PathBuf,
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
        /// Schedule to apply, as catflip writes it: `<method>.csv` or the same
        /// rows as `<method>.schedule.json`; its torque is the feed-forward.
        #[arg(long)]
        schedule: Option<PathBuf>,
    },
    /// Sweep a numeric config key over a range; every point designed by each method, in parallel.
    Sweep {
        #[command(flatten)]
        common: Common,
        /// KEY=FROM:TO:COUNT, e.g. fall.height=0.5:10:40.
        #[arg(long = "set-range", value_name = "KEY=FROM:TO:COUNT", value_parser = parsed::<catflip::sweep::SweepSpec>)]
        range: catflip::sweep::SweepSpec,
        /// Methods to compute, comma separated (default all three).
        #[arg(
            long,
            value_enum,
            value_delimiter = ',',
            default_value = "analytic,phased,free"
        )]
        methods: Vec<MethodArg>,
        /// Points computed at once, at least 1 (default: the machine's cores).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        threads: Option<u32>,
        /// K/N: compute only the K-th of N disjoint slices of the grid (for a
        /// batch scheduler's job array); the shards' CSVs concatenate into the
        /// whole sweep's.
        #[arg(long, value_name = "K/N", value_parser = parsed::<catflip::sweep::Shard>)]
        shard: Option<catflip::sweep::Shard>,
        /// Continue an interrupted sweep (same range, shard, methods and
        /// config) from the partial set it published.
        #[arg(long)]
        resume: bool,
    },
    /// Write the cat as a URDF (pyBullet) or MJCF (MuJoCo) model, and a schedule's controls for it.
    Export {
        #[arg(value_enum)]
        format: ExportFormat,
        #[command(flatten)]
        common: Common,
        /// Schedule CSV (as written by catflip) to write as `<stem>.mujoco.csv` (mjcf)
        /// or `<stem>.pybullet.csv` (urdf) at the simulator's time step.
        #[arg(long)]
        schedule: Option<PathBuf>,
    },
    /// Monte Carlo study of the closed loop: open loop with joint PD against TVLQR, perturbations from `[robustness]`.
    Robustness {
        #[command(flatten)]
        common: Common,
        /// Trials (at most 1000000).
        #[arg(long, default_value_t = 1000)]
        trials: usize,
        /// Seed of the study: each trial's draws follow from it and the trial's index.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Trials flown at once (default: the machine's cores).
        #[arg(long)]
        threads: Option<usize>,
        /// K/N: fly only the K-th of N contiguous slices of the trials; the
        /// shards' CSVs concatenate into the whole study's.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// Continue an interrupted study (same trials, seed, shard and
        /// config) from the partial set it published.
        #[arg(long)]
        resume: bool,
    },
    /// Recovery map: from which spins and tilts at release the body, its motors and its height still land belly-down.
    Recovery {
        #[command(flatten)]
        common: Common,
        /// Axis angles per plane, evenly over the turn (1 to 24; default 4).
        #[arg(long)]
        axes: Option<usize>,
        /// Spin magnitudes per axis after zero (1 to 20; default 2).
        #[arg(long)]
        spins: Option<usize>,
        /// Largest spin of the grid, rad/s (0 to 50; default 1).
        #[arg(long = "max-spin", value_name = "W")]
        max_spin: Option<f64>,
        /// Tilt angles per axis after zero, 0 for none (0 to 20; default 2).
        #[arg(long)]
        tilts: Option<usize>,
        /// Largest tilt of the grid, degrees (0 to 180; default 30).
        #[arg(long = "max-tilt", value_name = "DEG")]
        max_tilt: Option<f64>,
        /// Bisection steps of the largest recoverable spin per axis (0 to 12; default 3).
        #[arg(long)]
        bisect: Option<usize>,
        /// SCP iteration limit of each design of the map (5 to 1000; default 40).
        #[arg(long = "max-iterations")]
        max_iterations: Option<usize>,
        /// Lines designed at once (default: the machine's cores).
        #[arg(long)]
        threads: Option<usize>,
        /// K/N: only the K-th of N contiguous runs of whole lines; the
        /// shards' CSVs concatenate into the whole map's.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
    },
    /// Optimise the torque schedule: `phased` (certified fold / twist / unfold) or `free`.
    Optimize {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "phased")]
        mode: Mode,
        /// Seed of the free-form optimiser (default: phased; only with `--mode free`).
        #[arg(long, value_enum)]
        seed: Option<SeedArg>,
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

impl From<SeedArg> for catflip::design::free::Seed {
    fn from(s: SeedArg) -> Self {
        match s {
            SeedArg::Phased => catflip::design::free::Seed::Phased,
            SeedArg::Analytic => catflip::design::free::Seed::Analytic,
        }
    }
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
enum MethodArg {
    Analytic,
    Phased,
    Free,
}

/// A value parser from the library's own `FromStr` (its message names the
/// argument and the remedy; clap adds the flag and exits with status 2).
fn parsed<T: std::str::FromStr<Err = catflip::Error>>(s: &str) -> Result<T, String> {
    s.parse().map_err(|e: catflip::Error| e.to_string())
}

/// What `optimize` designs: the phased design, or the free-form one from a seed.
#[derive(Clone, Copy)]
enum Optimizer {
    Phased,
    Free(catflip::design::free::Seed),
}

impl Optimizer {
    /// `--mode` and `--seed`, checked: a seed belongs to the free-form design.
    fn of(mode: Mode, seed: Option<SeedArg>) -> Result<Optimizer> {
        match (mode, seed) {
            (Mode::Phased, Some(_)) => Err(catflip::Error::Usage(
                "--seed applies to --mode free (the phased design has no seed); add --mode free or leave --seed out".into(),
            )
            .into()),
            (Mode::Phased, None) => Ok(Optimizer::Phased),
            (Mode::Free, seed) => Ok(Optimizer::Free(seed.unwrap_or(SeedArg::Phased).into())),
        }
    }
}

/// Loads and checks the config; likely unit slips are warned about on stderr.
pub(crate) fn load(c: &Common) -> Result<Config> {
    let cfg = Config::load(&c.config, &c.set)?;
    for s in cfg.slips() {
        eprintln!("warning: {s}");
    }
    Ok(cfg)
}

fn out_dir(c: &Common, cfg: &Config) -> PathBuf {
    c.out.join(&cfg.name)
}

/// Starts the command's output set `<out>/<name>/<set>` before any work, so
/// that an unwritable `--out` fails at once. With `--set` overrides the set
/// is named after them too ([`catflip::output::set_name`]).
pub(crate) fn publisher(c: &Common, cfg: &Config, set: &str) -> Result<Publisher> {
    Ok(Publisher::begin(
        &out_dir(c, cfg),
        &catflip::output::set_name(set, &c.set),
    )?)
}

/// How a command that finished ended: the exit status tells them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Every result meets its targets (exit 0).
    Ok,
    /// Results were written, but some are flagged or failed (exit 3).
    Partial,
    /// The motors cannot flip the cat from the configured height; the least
    /// height and its schedule were written (exit 4).
    Impossible,
    /// A signal stopped the command; what it finished was published as a
    /// partial set (exit 130).
    Interrupted,
}

fn status_of(partial: bool) -> Status {
    if partial { Status::Partial } else { Status::Ok }
}

/// Prints a flagged verdict on stderr and says whether there was one.
fn flag(what: &str, reason: Option<String>) -> bool {
    if let Some(r) = &reason {
        eprintln!("warning: {what} is FLAGGED: {r}");
    }
    reason.is_some()
}

pub fn run() -> Result<Status> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(c) => cmd_run(&c),
        Command::Sweep {
            common,
            range,
            methods,
            threads,
            shard,
            resume,
        } => cmd_sweep(
            &common,
            &range,
            Methods {
                analytic: methods.contains(&MethodArg::Analytic),
                phased: methods.contains(&MethodArg::Phased),
                free: methods.contains(&MethodArg::Free),
            },
            threads.map(|t| t as usize),
            shard.unwrap_or(catflip::sweep::Shard::ALL),
            resume,
        ),
        Command::Export {
            format,
            common,
            schedule,
        } => cmd_export(&common, format, schedule.as_deref()),
        Command::Analyze(c) => cmd_analyze(&c),
        Command::Robustness {
            common,
            trials,
            seed,
            threads,
            shard,
            resume,
        } => crate::robustness::cmd_robustness(
            &common,
            trials,
            seed,
            threads,
            shard.as_deref(),
            resume,
        ),
        Command::Recovery {
            common,
            axes,
            spins,
            max_spin,
            tilts,
            max_tilt,
            bisect,
            max_iterations,
            threads,
            shard,
        } => {
            let d = catflip::recovery::Grid::default();
            let grid = catflip::recovery::Grid {
                axes: axes.unwrap_or(d.axes),
                spins: spins.unwrap_or(d.spins),
                max_spin: max_spin.unwrap_or(d.max_spin),
                tilts: tilts.unwrap_or(d.tilts),
                max_tilt_deg: max_tilt.unwrap_or(d.max_tilt_deg),
                bisect: bisect.unwrap_or(d.bisect),
                max_iterations: max_iterations.unwrap_or(d.max_iterations),
            };
            crate::recovery_cli::cmd_recovery(&common, grid, threads, shard.as_deref())
        }
        Command::Simulate { common, schedule } => cmd_simulate(&common, schedule.as_deref()),
        Command::Optimize {
            common,
            mode,
            seed,
            verbose,
        } => cmd_optimize(&common, Optimizer::of(mode, seed)?, verbose),
    }
}

/// A number that may be absent, to `digits` decimals, else `-`.
fn maybe(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

fn row(label: &str, value: String) {
    say!("  {label:<34} {value}");
}

fn cmd_analyze(c: &Common) -> Result<Status> {
    let cfg = load(c)?;
    let publisher = publisher(c, &cfg, "analyze")?;
    let a = analyze(&cfg)?;
    let (sched, verdict) = catflip::pipeline::judge_analysis(&cfg, &a);
    let reason = verdict.reason();
    let mut v = serde_json::to_value(&a)?;
    catflip::output::ensure_finite(&v, &[])?;
    v["verdict"] = serde_json::to_value(verdict.grade())?;
    if let Some(r) = &reason {
        v["reason"] = r.clone().into();
    }
    let json = serde_json::to_string_pretty(&v)?;
    let mut out = Output::default();
    sched.add_to(&mut out, "analytic");
    out.add("analyze.json", json.clone());
    let written = publisher.publish(out)?;
    // the analysis is what was asked: a miss is flagged in it, not a partial result
    flag("the seed's schedule", reason);
    if c.json {
        say!("{json}");
        return Ok(Status::Ok);
    }
    let cf = &a.closed;
    say!("catflip analyze: {} ({} joint)", a.name, a.joint);
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
    Ok(Status::Ok)
}

fn print_sim(title: &str, r: &SimReport) {
    say!("{title}");
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

/// Reads a schedule file, refusing one far larger than any schedule that
/// [`catflip::verify::simulate::MAX_SCHEDULE_ROWS`] admits before reading it.
fn read_bounded(p: &Path) -> std::io::Result<String> {
    let limit = 500 * catflip::verify::simulate::MAX_SCHEDULE_ROWS as u64;
    let len = std::fs::metadata(p)?.len();
    if len > limit {
        return Err(std::io::Error::other(format!(
            "{len} bytes, more than a schedule of {} rows can have; resample it more coarsely",
            catflip::verify::simulate::MAX_SCHEDULE_ROWS
        )));
    }
    std::fs::read_to_string(p)
}

fn cmd_simulate(c: &Common, schedule: Option<&Path>) -> Result<Status> {
    let cfg = load(c)?;
    let text = match schedule {
        Some(p) => Some(read_bounded(p).map_err(|e| {
            catflip::Error::Usage(format!("cannot read schedule {}: {e}", p.display()))
        })?),
        None => None,
    };
    let publisher = publisher(c, &cfg, "simulate")?;
    let (source, report) = match (schedule, text) {
        (Some(p), Some(text)) => {
            let s =
                catflip::verify::simulate::read_schedule(&cfg, &text, &p.display().to_string())?;
            (p.display().to_string(), verify(&cfg, &s)?)
        }
        _ => {
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
    let reason = verdict::flip_reason(
        report.flip_error_rad,
        report.tilt_deg,
        cfg.simulate.flip_tolerance,
    );
    catflip::output::ensure_finite(&serde_json::to_value(&report)?, &[])?;
    let mut out = Output::default();
    out.add("simulation.csv", trace);
    let written = publisher.publish(out)?;
    let partial = flag("the simulated schedule", reason.clone());
    if c.json {
        let mut v = serde_json::to_value(&report)?;
        v["source"] = serde_json::Value::String(source);
        v["verdict"] = (if partial { "flagged" } else { "ok" }).into();
        if let Some(r) = reason {
            v["reason"] = r.into();
        }
        say!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_sim(
            &format!(
                "catflip simulate: {} ({source}, dynamic, {})",
                cfg.name,
                if cfg.simulate.pd {
                    "feed-forward + PD"
                } else {
                    "feed-forward only"
                }
            ),
            &report,
        );
        for w in written {
            row("wrote", w.display().to_string());
        }
    }
    Ok(status_of(partial))
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

/// The name serde gives a unit enum value (`criticality`), for display only.
fn shown<T: serde::Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}

/// `--verbose`: one line per SCP iteration, and a line where each mesh
/// begins (mesh continuation: the trust radius starts again there).
struct IterationTable {
    verbose: bool,
}

impl catflip::design::free::Observer for IterationTable {
    fn iteration(&mut self, it: &catflip::design::scp::ScpIteration) {
        if self.verbose {
            eprintln!(
                "  {:4} {:10.5} {:10.5} {:10.2e} {:10.2e} {:10.3} {:>5} {:5.1}",
                it.iteration,
                it.merit,
                it.objective,
                it.infeasibility,
                it.radius,
                it.rho,
                if it.accepted {
                    "ok"
                } else if it.tentative {
                    "try"
                } else {
                    "rej"
                },
                it.solve_ms
            );
        }
    }
    fn mesh(&mut self, nodes: usize) {
        if self.verbose {
            eprintln!("  -- {nodes} nodes per phase");
        }
    }
}

fn cmd_optimize(c: &Common, optimizer: Optimizer, verbose: bool) -> Result<Status> {
    let cfg = load(c)?;
    let set = match optimizer {
        Optimizer::Phased => "optimize-phased",
        Optimizer::Free(_) => "optimize-free",
    };
    let publisher = publisher(c, &cfg, set)?;
    let design = match optimizer {
        Optimizer::Phased => Design::Phased(catflip::design::phased::optimize(&cfg, |e| {
            if verbose {
                eprintln!(
                    "  bend {:8.3} deg   unit peak {:>10} N m s^2   peak {:>9} N m",
                    e.bend_deg,
                    maybe(e.unit_peak, 5),
                    maybe(e.peak_nm, 5)
                );
            }
        })?),
        Optimizer::Free(seed) => {
            if verbose {
                let objective = cfg.design.objective.short_name();
                eprintln!(
                    "  iter      merit {objective:>10}     infeas     radius        rho  step   ms"
                );
            }
            Design::Free(
                catflip::design::free::FreeDesign::new(&cfg)
                    .seed(seed)
                    .check_mesh()
                    .observe(&mut IterationTable { verbose })
                    .solve()?,
            )
        }
    };
    // the same stage as `run`: schedule, verdict, files
    let judged = catflip::pipeline::stage(&cfg, design, 0.0);
    let method = judged.design.method();
    let reason = judged.verdict.reason();
    let what = match method {
        Method::Free => "the free-form design",
        _ => "the phased design",
    };
    let partial = flag(what, reason.clone());
    let mut json = match &judged.design {
        Design::Phased(r) => serde_json::to_value(r)?,
        Design::Free(r) => serde_json::to_value(r)?,
        Design::Analytic(a) => serde_json::to_value(a)?,
    };
    // a number that is not finite is refused, not written as null
    catflip::output::ensure_finite(
        &json,
        &[
            "peak_torque_nm",
            "bend_deg",
            "flip_deg",
            "tilt_deg",
            "sim_peak_torque_nm",
            "phase_durations_s",
        ],
    )?;
    json["verdict"] = serde_json::to_value(judged.verdict.grade())?;
    if let Some(r) = reason {
        json["reason"] = r.into();
    }
    let json = serde_json::to_string_pretty(&json)?;
    let mut out = Output::default();
    judged.add_files(&mut out);
    out.add(format!("{}.json", method.name()), json.clone());
    let written = publisher.publish(out)?;
    if c.json {
        say!("{json}");
        return Ok(status_of(partial));
    }
    match &judged.design {
        Design::Phased(r) => print_phased(&cfg, r, written),
        Design::Free(r) => print_free(&cfg, r, written),
        Design::Analytic(_) => {}
    }
    Ok(status_of(partial))
}

/// `optimize --mode phased`'s table.
fn print_phased(cfg: &Config, r: &catflip::design::phased::PhasedResult, written: Vec<PathBuf>) {
    say!(
        "catflip optimize --mode phased: {} ({} joint), status {}",
        cfg.name,
        cfg.cat.joint.name(),
        verdict::Status::from(r.status)
    );
    row(
        "peak torque",
        format!(
            "{:.5} N m (SOCP bound {})",
            r.peak_torque_nm,
            maybe(r.socp_peak_torque_nm, 5)
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

/// `optimize --mode free`'s table.
fn print_free(cfg: &Config, r: &catflip::design::free::FreeResult, written: Vec<PathBuf>) {
    say!(
        "catflip optimize --mode free: {} ({} joint), status {}, seed {}",
        cfg.name,
        cfg.cat.joint.name(),
        verdict::Status::from(r.status),
        r.seed
    );
    row(
        &format!("objective ({})", r.objective.name()),
        format!(
            "{:.6} {} (manoeuvre {:.4} s)",
            r.objective_value,
            r.objective.unit(),
            r.manoeuvre_time_s
        ),
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
    let cert = &r.certificate;
    row(
        "certificate",
        format!(
            "step {:.2e}, constraint violation {:.2e} rad, criticality {:.2e} (stop: {})",
            cert.step,
            cert.constraint_violation,
            cert.criticality,
            shown(&cert.rule)
        ),
    );
    if let Some(m) = &r.mesh_check {
        row(
            "mesh check (N vs 2N)",
            format!(
                "{:.5} {} at {} nodes per phase ({:+.2} %), {}",
                m.objective_value,
                r.objective.unit(),
                m.nodes,
                100.0 * m.relative_change,
                verdict::Status::from(m.status)
            ),
        );
    }
    design_rows(
        r.phase_durations_s,
        (
            r.flip_deg,
            r.flip_error_rad,
            r.tilt_deg,
            r.sim_peak_torque_nm,
        ),
        format!(
            "{:.3} s ({})",
            r.solve_time_s,
            catflip::design::free::iterations_text(&r.mesh_levels)
        ),
        written,
    );
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
            Progress::StageFailed { seconds, reason } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " FAILED after {seconds:.2} s: {reason}");
            }
            Progress::StageSkipped { reason } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " not attempted: {reason}");
            }
            Progress::Bend {
                evaluations,
                bend_deg,
                peak_nm,
            } if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      bend evaluation {evaluations:3}: {bend_deg:7.2} deg -> {} N m",
                    maybe(peak_nm, 5)
                );
            }
            Progress::Scp(it) if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      SCP iteration {:3}: peak {:.5} N m, max |r| {:.1e}, radius {:.1e}",
                    it.iteration, it.objective, it.infeasibility, it.radius
                );
            }
            _ => {}
        }
        let _ = e.flush();
    }
}

fn cmd_run(c: &Common) -> Result<Status> {
    let cfg = load(c)?;
    let publisher = publisher(c, &cfg, "run")?;
    let dir = publisher.link();
    let r = catflip::run::run(&cfg, progress_display(c.json))?;
    let partial = r.is_partial();
    let status = if r.is_impossible() {
        Status::Impossible
    } else {
        status_of(partial)
    };
    let written = publisher.publish(r.output)?;
    if c.json {
        say!("{}", serde_json::to_string_pretty(&r.summary)?);
        return Ok(status);
    }
    let s = &r.summary;
    say!();
    say!(
        "catflip run: {} ({} joint, peak norm {})",
        s.name,
        s.joint,
        s.peak_norm.name()
    );
    let header = catflip::run::TABLE_HEADER;
    let rows: Vec<Vec<String>> = s.methods.iter().map(catflip::run::table_row).collect();
    // the last column (verdict) is left as is: it holds the reasons
    let widths: Vec<usize> = (0..header.len() - 1)
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
            .map(|(j, c)| match widths.get(j) {
                Some(w) => format!("{c:>w$}"),
                None => c.to_string(),
            })
            .collect();
        say!("  {}", parts.join("  "));
    };
    line(header.iter().map(|h| h.to_string()).collect());
    for row in rows {
        line(row);
    }
    let show = |x: Option<f64>| x.map(|v| format!("{v:.3}")).unwrap_or_else(|| "-".into());
    say!(
        "  free-form / phased peak {}, phased / analytic {}; free-form design: {}",
        show(s.free_over_phased),
        show(s.phased_over_analytic),
        catflip::design::free::iterations_text(&s.mesh_levels)
    );
    if let Some(a) = &s.answer {
        say!("  {}", a.sentence());
    }
    say!(
        "  report: {} ({} files)",
        dir.join("index.html").display(),
        written.len()
    );
    if status == Status::Impossible {
        eprintln!("the flip is not possible from this height: exit status 4");
    } else if partial {
        eprintln!(
            "warning: partial result: some methods are FLAGGED or FAILED (see the verdict column); exit status 3"
        );
    }
    Ok(status)
}

fn cmd_sweep(
    c: &Common,
    spec: &catflip::sweep::SweepSpec,
    m: Methods,
    threads: Option<usize>,
    shard: catflip::sweep::Shard,
    resume: bool,
) -> Result<Status> {
    let cfg = load(c)?;
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let quiet = c.json;
    // a file-name-safe key (an unknown key is refused below, but names the staging first)
    let key: String = spec
        .key
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let key = format!("{key}{}", shard.suffix());
    if shard.points(spec.count).is_empty() {
        // a job array wider than the grid: legitimate, but worth a word
        eprintln!(
            "warning: shard {}/{} holds no points: shards take whole continuation chunks of {} points, and the {} points make {}; use at most that many shards",
            shard.index,
            shard.count,
            catflip::sweep::CHUNK,
            spec.count,
            spec.count.div_ceil(catflip::sweep::CHUNK)
        );
    }
    let publisher = publisher(c, &cfg, &format!("sweep-{key}"))?;
    // a live bar on a terminal, plain lines otherwise
    let live = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let clock = std::time::Instant::now();
    let state = catflip::sweep::resume::SweepState::new(spec, shard, m, &cfg);
    let kept = if resume {
        let old = state.resume_from(&publisher.link(), &key)?;
        eprintln!(
            "resuming: {} of {} points kept from {}",
            old.finished().len(),
            old.points.len(),
            publisher.link().display()
        );
        old.points
    } else {
        state.points.clone()
    };
    // the points land in a store this thread reads when a signal stops the sweep
    let store = std::sync::Arc::new(std::sync::Mutex::new(kept));
    let interrupt = catflip::interrupt::Interrupt::catch()?;
    let work = {
        let (config, set, spec, store) =
            (c.config.clone(), c.set.clone(), spec.clone(), store.clone());
        move || {
            catflip::sweep::sweep_shard_into(
                &config,
                &set,
                &spec,
                m,
                threads,
                shard,
                &store,
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
            )
        }
    };
    let outcome = catflip::interrupt::supervise(&interrupt, work);
    if !quiet && live {
        eprintln!();
    }
    let slots = store.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let state = state.with_points(slots);
    if let catflip::interrupt::Outcome::Finished(r) = outcome {
        r?;
    } else {
        // published as a partial set, the unfinished points left running
        let points = state.finished();
        let mut out = Output::default();
        out.add(
            format!("sweep-{key}.csv"),
            catflip::sweep::to_csv(&spec.key, &points),
        );
        if !points.is_empty() {
            for (name, svg) in
                catflip::sweep::figures(&key, &spec.key, &points, cfg.limits.max_torque)?
            {
                out.add(name, svg);
            }
        }
        out.add(
            catflip::sweep::resume::SweepState::file_name(&key),
            state.to_json(),
        );
        let dir = publisher.link();
        publisher.publish(out)?;
        if c.json {
            say!("{}", serde_json::to_string_pretty(&points)?);
        }
        eprintln!(
            "interrupted: {} of {} points finished, published as a partial set in {} (its state file says \"status\": \"partial\"); the same command with --resume continues it; exit status 130",
            points.len(),
            state.points.len(),
            dir.display()
        );
        return Ok(Status::Interrupted);
    }
    let points = state.finished();
    let partial = points.iter().any(|p| p.error.is_some());
    let mut out = Output::default();
    out.add(
        format!("sweep-{key}.csv"),
        catflip::sweep::to_csv(&spec.key, &points),
    );
    for (name, svg) in catflip::sweep::figures(&key, &spec.key, &points, cfg.limits.max_torque)? {
        out.add(name, svg);
    }
    out.add(
        catflip::sweep::resume::SweepState::file_name(&key),
        state.to_json(),
    );
    let written = publisher.publish(out)?;
    if partial {
        eprintln!(
            "warning: partial result: {} of {} points have errors (see the error column); exit status 3",
            points.iter().filter(|p| p.error.is_some()).count(),
            points.len()
        );
    }
    if c.json {
        say!("{}", serde_json::to_string_pretty(&points)?);
        return Ok(status_of(partial));
    }
    let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    say!(
        "catflip sweep: {} over {} ({}, {} at a time)",
        cfg.name,
        spec.key,
        plural(points.len(), "point"),
        threads
    );
    let show = |x: Option<f64>| x.map(|v| format!("{v:.5}")).unwrap_or_else(|| "-".into());
    // the least drop heights, when a torque limit gives them
    let heights = points
        .iter()
        .any(|p| p.least_height_phased_m.is_some() || p.least_height_free_m.is_some());
    let mut head = format!(
        "  {:>12} {:>12} {:>12} {:>12}",
        spec.key, "analytic N m", "phased N m", "free N m"
    );
    if heights {
        head += &format!(" {:>14} {:>14}", "phased h_min m", "free h_min m");
    }
    say!("{head}");
    for p in &points {
        let mut line = format!(
            "  {:>12.5} {:>12} {:>12} {:>12}",
            p.value,
            show(p.analytic_peak_nm),
            show(p.phased_peak_nm),
            show(p.free_peak_nm),
        );
        if heights {
            line += &format!(
                " {:>14} {:>14}",
                show(p.least_height_phased_m),
                show(p.least_height_free_m)
            );
        }
        if let Some(e) = &p.error {
            line += &format!("  error: {e}");
        }
        say!("{line}");
    }
    for w in written {
        row("wrote", w.display().to_string());
    }
    Ok(status_of(partial))
}

fn cmd_export(c: &Common, format: ExportFormat, schedule: Option<&Path>) -> Result<Status> {
    use catflip::export::controls::{Controls, Simulator};
    let cfg = load(c)?;
    let set = match format {
        ExportFormat::Urdf => "export-urdf",
        ExportFormat::Mjcf => "export-mjcf",
    };
    let text = match schedule {
        Some(p) => Some(read_bounded(p).map_err(|e| {
            catflip::Error::Usage(format!("cannot read schedule {}: {e}", p.display()))
        })?),
        None => None,
    };
    let publisher = publisher(c, &cfg, set)?;
    let (name, text_model, sim) = match format {
        ExportFormat::Urdf => (
            format!("{}.urdf", cfg.name),
            catflip::export::urdf(&cfg),
            Simulator::Pybullet,
        ),
        ExportFormat::Mjcf => (
            format!("{}.mjcf.xml", cfg.name),
            catflip::export::mjcf(&cfg),
            Simulator::Mujoco,
        ),
    };
    let mut out = Output::default();
    out.add(name, text_model);
    if let (Some(p), Some(text)) = (schedule, text) {
        let s = catflip::verify::simulate::read_schedule(&cfg, &text, &p.display().to_string())?;
        let stem = p
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("schedule")
            .to_string();
        let controls = Controls::sample(&cfg, &s, sim);
        out.add(
            format!("{stem}.{}.csv", sim.name()),
            controls.to_csv(&cfg, &stem),
        );
        // the closed loop's gains along the same schedule (issue 27)
        out.add(
            format!("{stem}.tvlqr.csv"),
            catflip::control::export::gains_csv(&cfg, &s),
        );
    }
    for w in publisher.publish(out)? {
        say!("wrote {}", w.display());
    }
    Ok(Status::Ok)
}
