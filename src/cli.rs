//! Arguments parsed into a checked invocation, then each command's call
//! into the library; the tables and progress lines are the library's
//! ([`catflip::console`]).

use crate::common::{Common, Progress, Status, flag, load, publisher, say, say_lines};
use anyhow::Result;
use catflip::console;
use catflip::output::Output;
use catflip::pipeline::{Design, Method};
use catflip::sweep::{Methods, Shard, SweepSpec};
use catflip::verdict::{self, Grade, with_verdict};
use catflip::verify::analyze::{analyze, verify};
use clap::{Parser, Subcommand};
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
        #[arg(long = "set-range", value_name = "KEY=FROM:TO:COUNT", value_parser = parsed::<SweepSpec>)]
        range: SweepSpec,
        /// Methods to compute, comma separated (default all three).
        #[arg(
            long,
            value_enum,
            value_delimiter = ',',
            default_value = "analytic,phased,free"
        )]
        methods: Vec<MethodArg>,
        /// Points computed at once, at least 1 (default: the machine's cores).
        #[arg(long, value_parser = thread_count, allow_negative_numbers = true)]
        threads: Option<u32>,
        /// K/N: compute only the K-th of N disjoint slices of the grid (for a
        /// batch scheduler's job array); the shards' CSVs concatenate into the
        /// whole sweep's.
        #[arg(long, value_name = "K/N", value_parser = parsed::<Shard>)]
        shard: Option<Shard>,
        /// Continue an interrupted sweep (same range, shard, methods,
        /// --least-height-only and config) from the partial set it published.
        #[arg(long)]
        resume: bool,
        /// Compute only the least drop heights (the robot builder's
        /// question): inside a motor envelope not the peak columns (each
        /// method's design without the motor limits), from which a stall
        /// torque alone takes them (F7); needs limits.max_torque.
        #[arg(long)]
        least_height_only: bool,
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
    /// Monte Carlo study of the closed loop: open loop with joint PD, TVLQR and replanning, perturbations from `[robustness]`.
    Robustness {
        #[command(flatten)]
        common: Common,
        /// Trials (at most 1000000).
        #[arg(long, default_value_t = 1000, value_parser = trials, allow_negative_numbers = true)]
        trials: usize,
        /// Seed of the study: each trial's draws follow from it and the trial's index.
        #[arg(long, default_value_t = 1, value_parser = study_seed, allow_negative_numbers = true)]
        seed: u64,
        /// Trials flown at once, at least 1 (default: the machine's cores).
        #[arg(long, value_parser = thread_count, allow_negative_numbers = true)]
        threads: Option<u32>,
        /// K/N: fly only the K-th of N contiguous slices of the trials; the
        /// shards' CSVs concatenate into the whole study's.
        #[arg(long, value_name = "K/N", value_parser = parsed::<Shard>)]
        shard: Option<Shard>,
        /// Continue an interrupted study (same trials, seed, shard and
        /// config) from the partial set it published.
        #[arg(long)]
        resume: bool,
        /// Drop a replan that takes longer than this wall time, ms, as a
        /// robot's controller would (the plan in use continues): the rates
        /// then depend on this machine's speed and load. Default: every
        /// replan is used (a deterministic study).
        #[arg(long, value_name = "MS", value_parser = budget_ms, allow_negative_numbers = true)]
        replan_budget_ms: Option<f64>,
        /// Fly only trial K of the study again (its index in robustness.csv,
        /// below --trials), under each controller (at once with --threads 2
        /// or more): its landings, flights (CSV, figures) and draws, in
        /// `robustness-trial-K/`.
        #[arg(long, value_name = "K", value_parser = trial_index, allow_negative_numbers = true, conflicts_with_all = ["shard", "resume"])]
        trial: Option<usize>,
    },
    /// The motors needed for a drop height: the stall torque against no-load speed that just makes the flip, and the configured motor's best gear ratio.
    Size {
        #[command(flatten)]
        common: Common,
        /// The drop height to size the motors for, m (the config's fall.height is not used).
        #[arg(long, allow_negative_numbers = true)]
        height: f64,
        /// Points on the curve (2 to 40), each one least-time design (two when its first guess is off).
        #[arg(long, default_value_t = catflip::size::SizeSettings::default().points, allow_negative_numbers = true)]
        points: usize,
        /// Least-time designs the gear-ratio search adds (0 to 20).
        #[arg(long, default_value_t = catflip::size::SizeSettings::default().gear_evaluations, allow_negative_numbers = true)]
        gear_evaluations: usize,
    },
    /// Recovery map: from which spins and tilts at release the body, its motors and its height still land belly-down.
    Recovery {
        #[command(flatten)]
        common: Common,
        /// Axis angles per plane, evenly over the turn (1 to 24; default 4).
        #[arg(long, allow_negative_numbers = true)]
        axes: Option<usize>,
        /// Spin magnitudes per axis after zero (1 to 20; default 2).
        #[arg(long, allow_negative_numbers = true)]
        spins: Option<usize>,
        /// Largest spin of the grid, rad/s (over 0, up to 50; default 1).
        #[arg(long = "max-spin", value_name = "W", allow_negative_numbers = true)]
        max_spin: Option<f64>,
        /// Tilt angles per axis after zero, 0 for none (0 to 20; default 2).
        #[arg(long, allow_negative_numbers = true)]
        tilts: Option<usize>,
        /// Largest tilt of the grid, degrees (over 0, up to 180; default 30).
        #[arg(long = "max-tilt", value_name = "DEG", allow_negative_numbers = true)]
        max_tilt: Option<f64>,
        /// Bisection steps of the largest recoverable spin per axis (0 to 12; default 3).
        #[arg(long, allow_negative_numbers = true)]
        bisect: Option<usize>,
        /// SCP iteration limit of each design of the map (5 to 1000; default 40).
        #[arg(long = "max-iterations", allow_negative_numbers = true)]
        max_iterations: Option<usize>,
        /// Lines designed at once, at least 1 (default: the machine's cores).
        #[arg(long, value_parser = thread_count, allow_negative_numbers = true)]
        threads: Option<u32>,
        /// K/N: only the K-th of N contiguous runs of whole lines; the
        /// shards' CSVs concatenate into the whole map's.
        #[arg(long, value_name = "K/N", value_parser = parsed::<Shard>)]
        shard: Option<Shard>,
    },
    /// Optimise the torque schedule: `phased` (certified fold / twist / unfold) or `free`.
    Optimize {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "phased")]
        mode: Mode,
        /// Seed of the free-form optimiser (default: phased; where no phased schedule fits the motors in this fall, and for the least time, the least-height answer's shortest manoeuvre, as `run`; only with `--mode free`).
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

/// `--trials`: a count in `[1, MAX_TRIALS]`.
fn trials(s: &str) -> Result<usize, String> {
    let max = catflip::config::MAX_TRIALS;
    match s.parse::<usize>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("{s}: must be in [1, {max}], a whole number")),
    }
}

/// `--seed`: the study's seed, a whole number from 0.
fn study_seed(s: &str) -> Result<u64, String> {
    s.parse::<u64>().map_err(|_| {
        format!(
            "{s}: must be a whole number from 0 to {} (any one: the trials' draws follow from it)",
            u64::MAX
        )
    })
}

/// `--trial`: a trial's index, 0 or more.
fn trial_index(s: &str) -> Result<usize, String> {
    s.parse::<usize>().map_err(|_| {
        format!(
            "{s}: must be a trial's index, a whole number from 0 (robustness.csv's `trial` column)"
        )
    })
}

/// `--replan-budget-ms`: a wall time, ms, positive and at most a second.
fn budget_ms(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(b) if b > 0.0 && b <= 1000.0 => Ok(b),
        _ => Err(format!(
            "{s}: must be in (0, 1000] ms, a replan's wall-clock budget (e.g. the control period, 10 ms at 100 Hz); leave it out to use every replan"
        )),
    }
}

/// `--threads`: a whole number, at least 1.
fn thread_count(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        Ok(_) => Err(format!(
            "{s}: at least one thread; give 1 or more, or leave --threads out for one per core"
        )),
        Err(_) => Err(format!(
            "{s}: expected a whole number of threads, 1 or more"
        )),
    }
}

/// A `--set` of the key that another option sets (a sweep's key, the size's
/// height) would be overwritten silently, yet name the output set: refused.
pub(crate) fn refuse_set_of(c: &Common, key: &str, by: &str) -> Result<()> {
    if let Some(s) = c.set.iter().find(|s| crate::common::set_key(s) == key) {
        return Err(catflip::Error::Usage(format!(
            "--set {s} conflicts with {by}, which sets {key} itself; leave the --set out"
        ))
        .into());
    }
    Ok(())
}

/// Threads to use: as asked, else one per core.
pub(crate) fn threads_or_cores(threads: Option<u32>) -> usize {
    threads.map(|t| t as usize).unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    })
}

/// What `optimize` designs: the phased design, or the free-form one from a seed.
#[derive(Clone, Copy)]
enum Optimizer {
    Phased,
    /// The free-form design from the named seed; none named: where `run`
    /// starts it (`pipeline::free_start`).
    Free(Option<catflip::design::free::Seed>),
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
            (Mode::Free, seed) => Ok(Optimizer::Free(seed.map(Into::into))),
        }
    }
}

pub fn run() -> Result<Status> {
    let cli = Cli::parse();
    // a sweep, a study or a recovery map catch the signals themselves to
    // publish what they finished; any other command stops with nothing
    // half-written
    let studies = matches!(
        cli.command,
        Command::Sweep { .. } | Command::Recovery { .. } | Command::Robustness { trial: None, .. }
    );
    let _exit = if studies {
        None
    } else {
        Some(catflip::interrupt::ExitOnSignal::install()?)
    };
    match cli.command {
        Command::Run(c) => cmd_run(&c),
        Command::Sweep {
            common,
            range,
            methods,
            threads,
            shard,
            resume,
            least_height_only,
        } => cmd_sweep(
            &common,
            &range,
            Methods {
                analytic: methods.contains(&MethodArg::Analytic),
                phased: methods.contains(&MethodArg::Phased),
                free: methods.contains(&MethodArg::Free),
                peaks: !least_height_only,
            },
            threads_or_cores(threads),
            shard.unwrap_or(Shard::ALL),
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
            replan_budget_ms,
            trial,
        } => {
            let args = crate::robustness::StudyArgs {
                trials,
                seed,
                threads: threads_or_cores(threads),
                shard: shard.unwrap_or(Shard::ALL),
                resume,
                replan_budget_ms,
            };
            match trial {
                Some(k) => crate::robustness::cmd_trial(&common, args, k),
                None => crate::robustness::cmd_robustness(&common, args),
            }
        }
        Command::Size {
            common,
            height,
            points,
            gear_evaluations,
        } => crate::size_cli::cmd_size(
            &common,
            height,
            catflip::size::SizeSettings {
                points,
                gear_evaluations,
            },
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
            crate::recovery_cli::cmd_recovery(&common, grid, threads_or_cores(threads), shard)
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

fn cmd_analyze(c: &Common) -> Result<Status> {
    let cfg = load(c)?;
    let publisher = publisher(c, &cfg, "analyze")?;
    let spec = cfg.design_spec();
    let a = analyze(&spec, &cfg.name)?;
    let (sched, verdict) = catflip::pipeline::judge_analysis(&spec, &a);
    let reason = verdict.reason();
    let mut v = serde_json::to_value(&a)?;
    catflip::output::ensure_finite(&v, &[])?;
    with_verdict(&mut v, verdict.grade(), reason.clone());
    let json = serde_json::to_string_pretty(&v)?;
    let mut out = Output::default();
    sched.add_to(&mut out, "analytic");
    out.add("analyze.json", json.clone());
    let written = publisher.publish(out)?;
    // the analysis is what was asked: a miss is flagged in it, not a partial result
    flag("the seed's schedule", reason);
    if c.json {
        say!("{json}");
    } else {
        say_lines(console::design::analysis(&a, &written).lines());
    }
    Ok(Status::Ok)
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

/// The text of `--schedule`, read before any work (bad input: exit 2).
fn schedule_text(schedule: Option<&Path>) -> Result<Option<String>> {
    Ok(match schedule {
        Some(p) => Some(read_bounded(p).map_err(|e| {
            catflip::Error::Usage(format!("cannot read schedule {}: {e}", p.display()))
        })?),
        None => None,
    })
}

fn cmd_simulate(c: &Common, schedule: Option<&Path>) -> Result<Status> {
    let cfg = load(c)?;
    let text = schedule_text(schedule)?;
    let publisher = publisher(c, &cfg, "simulate")?;
    let (source, report) = match (schedule, text) {
        (Some(p), Some(text)) => {
            let s = catflip::verify::simulate::read_schedule(
                &cfg.design_spec(),
                &cfg.name,
                &text,
                &p.display().to_string(),
            )?;
            (p.display().to_string(), verify(&cfg.design_spec(), &s)?)
        }
        _ => {
            let spec = cfg.design_spec();
            let plan = catflip::design::analytic::analytic_plan(&spec);
            ("analytic schedule".to_string(), verify(&spec, &plan)?)
        }
    };
    // the landing too, from another start, as `run` judges it
    let reason = verdict::flight_reason(
        &verdict::Targets::of(&cfg.design_spec()),
        &verdict::Simulated::of(Ok(&report)),
    );
    catflip::output::ensure_finite(&serde_json::to_value(&report)?, &[])?;
    let mut out = Output::default();
    out.add("simulation.csv", report.trace_csv());
    let written = publisher.publish(out)?;
    let partial = flag("the simulated schedule", reason.clone());
    if c.json {
        let mut v = serde_json::to_value(&report)?;
        v["source"] = serde_json::Value::String(source);
        let grade = if partial { Grade::Flagged } else { Grade::Ok };
        with_verdict(&mut v, grade, reason);
        say!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let title = console::design::simulation_title(&cfg, &source);
        let mut t = console::design::simulation(&title, &report);
        t.wrote(&written);
        say_lines(t.lines());
    }
    Ok(Status::of(partial))
}

fn cmd_optimize(c: &Common, optimizer: Optimizer, verbose: bool) -> Result<Status> {
    let cfg = load(c)?;
    // each named seed its own set: a design from `--seed` does not replace
    // the one without (`pipeline::free_start`'s, which may start elsewhere)
    let set = match optimizer {
        Optimizer::Phased => "optimize-phased",
        Optimizer::Free(None) => "optimize-free",
        Optimizer::Free(Some(catflip::design::free::Seed::Phased)) => "optimize-free-phased",
        Optimizer::Free(Some(catflip::design::free::Seed::Analytic)) => "optimize-free-analytic",
    };
    let publisher = publisher(c, &cfg, set)?;
    let spec = cfg.design_spec();
    let design = match optimizer {
        Optimizer::Phased => Design::Phased(catflip::design::phased::optimize(&spec, |e| {
            if verbose {
                eprintln!("{}", console::progress::bend_line(e));
            }
        })?),
        Optimizer::Free(seed) => {
            // (from any seed the SCP would only fail at such a torque scale)
            if let Some(e) = catflip::design::least_height::beyond_any_fall(&spec)
                .as_ref()
                .and_then(catflip::pipeline::out_of_reach)
            {
                return Err(e.into());
            }
            let mut table =
                console::progress::IterationTable::new(verbose, cfg.design.objective.short_name());
            Design::Free(catflip::pipeline::free_design(
                &spec,
                seed,
                |n| eprintln!("note: {n}"),
                &mut table,
                catflip::pipeline::LEAST_HEIGHT_FROM_RUN,
            )?)
        }
    };
    // the same stage as `run`: schedule, verdict, files
    let judged = catflip::pipeline::stage(&spec, design, 0.0);
    let method = judged.design.method();
    let reason = judged.verdict.reason();
    let what = match method {
        Method::Free => "the free-form design",
        _ => "the phased design",
    };
    // a failed flight or a number that is not finite is the error
    let mut json = judged.design_json(&spec)?;
    let partial = flag(what, reason.clone());
    let grade = judged.verdict.grade();
    with_verdict(&mut json, grade, reason);
    let json = serde_json::to_string_pretty(&json)?;
    let mut out = Output::default();
    judged.add_files(&mut out);
    out.add(format!("{}.json", method.name()), json.clone());
    let written = publisher.publish(out)?;
    if c.json {
        say!("{json}");
        return Ok(Status::of(partial));
    }
    // (flown: `design_json` returns the failed flight's error)
    if let Ok(sim) = &judged.sim {
        match &judged.design {
            Design::Phased(r) => {
                say_lines(console::design::phased(&cfg, r, sim, &written, grade).lines())
            }
            Design::Free(r) => {
                say_lines(console::design::free(&cfg, r, sim, &written, grade).lines())
            }
            Design::Analytic(_) | Design::LeastHeight(_) => {}
        }
    }
    Ok(Status::of(partial))
}

fn cmd_run(c: &Common) -> Result<Status> {
    let cfg = load(c)?;
    let publisher = publisher(c, &cfg, "run")?;
    let dir = publisher.link();
    let mut r = catflip::run::run(&cfg, console::progress::stages(c.json))?;
    let outcome = r.summary.outcome;
    // the sizing advice names this config and the `--set`s `size` takes, on
    // the terminal and in the report
    const ADVICE: &str = "catflip size CONFIG --height";
    let sizing = crate::size_cli::advised(c, cfg.fall.height);
    r.output
        .replace_in("index.html", ADVICE, &catflip::report::esc(&sizing));
    let written = publisher.publish(r.output)?;
    if c.json {
        say!("{}", serde_json::to_string_pretty(&r.summary)?);
        return Ok(outcome.into());
    }
    let mut lines = console::run::summary(&r.summary, &dir.join("index.html"), written.len());
    for l in &mut lines {
        *l = l.replace(ADVICE, &sizing);
    }
    say_lines(lines);
    if let Some(word) = console::run::closing(&r.summary) {
        eprintln!("{word}");
    }
    Ok(outcome.into())
}

fn cmd_sweep(
    c: &Common,
    spec: &SweepSpec,
    m: Methods,
    threads: usize,
    shard: Shard,
    resume: bool,
) -> Result<Status> {
    refuse_set_of(c, &spec.key, &format!("--set-range {}", spec.arg()))?;
    let cfg = load(c)?;
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
    let publisher = publisher(c, &cfg, &format!("sweep-{key}"))?;
    let progress = Progress::new(quiet);
    let clock = std::time::Instant::now();
    let state = catflip::sweep::resume::SweepState::new(spec, shard, m, &cfg);
    if state.points.is_empty() {
        // a job array wider than the grid: legitimate, but worth a word
        eprintln!(
            "warning: {}",
            console::sweep::empty_shard(&state.shard, &state.range, spec.count)
        );
    }
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
            let run = catflip::sweep::SweepRun {
                path: &config,
                overrides: &set,
                spec: &spec,
                methods: m,
                threads,
                shard,
            };
            run.into_store(&store, |done, total| {
                progress.show(&catflip::console::sweep::progress_line(
                    &spec.key,
                    done,
                    total,
                    clock.elapsed().as_secs_f64(),
                ))
            })
        }
    };
    let outcome = catflip::interrupt::supervise(&interrupt, work);
    progress.finish();
    let slots = store.lock().unwrap_or_else(|p| p.into_inner()).clone();
    let state = state.with_points(slots);
    let points = state.finished();
    if let catflip::interrupt::Outcome::Finished(r) = outcome {
        r?;
    } else {
        // published as a partial set, the unfinished points left running
        let dir = publisher.link();
        publisher.publish(state.output(&key, &spec.key, true)?)?;
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
    let written = publisher.publish(state.output(&key, &spec.key, false)?)?;
    let warning = console::sweep::partial_warning(&points);
    if let Some(w) = &warning {
        eprintln!("{w}");
    }
    if c.json {
        say!("{}", serde_json::to_string_pretty(&points)?);
    } else {
        say_lines(console::sweep::points(
            &cfg.name, spec, &points, threads, &written,
        ));
        if let Some(note) = console::sweep::from_another_start(&cfg.start, &state.methods) {
            say!("  {note}");
        }
    }
    Ok(Status::of(warning.is_some()))
}

fn cmd_export(c: &Common, format: ExportFormat, schedule: Option<&Path>) -> Result<Status> {
    use catflip::export::controls::Simulator;
    let cfg = load(c)?;
    let set = match format {
        ExportFormat::Urdf => "export-urdf",
        ExportFormat::Mjcf => "export-mjcf",
    };
    let text = schedule_text(schedule)?;
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
        let s = catflip::verify::simulate::read_schedule(
            &cfg.design_spec(),
            &cfg.name,
            &text,
            &p.display().to_string(),
        )?;
        // `free.schedule.json` names the same schedule as `free.csv`
        let stem = p
            .file_stem()
            .and_then(|s| s.to_str())
            .map(|s| s.strip_suffix(".schedule").unwrap_or(s))
            .unwrap_or("schedule")
            .to_string();
        // flown first, as `simulate` flies it: a schedule the model cannot
        // follow gives no controls or gains (it wrote NaN gains)
        catflip::verify::simulate::dynamic_spec(&cfg.design_spec(), &s)?;
        catflip::export::add_schedule_files(&cfg, &mut out, &s, &stem, sim)?;
    }
    for w in publisher.publish(out)? {
        say!("wrote {}", w.display());
    }
    Ok(Status::Ok)
}
